//! The crowns (module documentation of [`super`], "Crown"): their angular layout — the crest phases and the
//! numbering of the nodes from `ϑ = 0` — their nodes (crests and troughs) and their wires.

use super::axis::Axis;
use super::curve::{CurveKind, StentCurve};
use super::sector::Sector;
use super::{
    ANGLE_TOLERANCE, GeneratedNode, GeneratedPatch, NodeKind, PartKind, PatchRole, StentSpec,
};
use crate::math::{Real, Vec3};
use std::f64::consts::{PI, TAU};
use std::sync::Arc;

/// The ring family's crest: a node at `x = +h_c`, facing crown `k + 1`.
pub(super) const CREST: NodeKind = NodeKind(0);
/// The ring family's trough: a node at `x = −h_c`.
pub(super) const TROUGH: NodeKind = NodeKind(1);
/// The ring family's crown wire, from a node of a crown to the next.
pub(super) const WIRE: PartKind = PartKind(0);

/// Index of every crown node in the generated node list, `[crown][node]` (node `j` at `ϑ = α_k + j π/m`, even
/// `j` a crest), `None` where the symmetry cut removed it.
pub(super) type NodeIndex = Vec<Vec<Option<usize>>>;

/// The angles of the crowns: crown `k` has its crest `j = 0` at `ϑ = α_k = k α` and a node every half wave
/// `π/m`; its nodes are numbered (in names) by increasing angle from `ϑ = 0`, whatever the rotation.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Layout {
    /// Peaks `m` per crown.
    peaks: usize,
    /// Rotation `α` per crown \[rad\].
    rotation: Real,
    /// `π/m` \[rad\].
    half_wave: Real,
    /// Per crown, the node `j` at the smallest angle in `[0, 2π)` (an angle within [`ANGLE_TOLERANCE`] below
    /// `2π` counts as 0).
    first: Vec<usize>,
}

impl Layout {
    /// The layout of `spec`'s crowns.
    pub(super) fn new(spec: &StentSpec) -> Self {
        let m = spec.crown.peaks;
        let mut layout = Self {
            peaks: m,
            rotation: spec.rotation,
            half_wave: PI / m as Real,
            first: Vec::new(),
        };
        layout.first = (0..spec.crowns)
            .map(|k| {
                let key = |j: usize| {
                    let x = (layout.phase(k) + layout.half_wave * j as Real).rem_euclid(TAU);
                    if TAU - x <= ANGLE_TOLERANCE { 0.0 } else { x }
                };
                (0..2 * m)
                    .min_by(|&a, &b| key(a).total_cmp(&key(b)))
                    .unwrap_or(0)
            })
            .collect();
        layout
    }

    /// `π/m` \[rad\].
    pub(super) fn half_wave(&self) -> Real {
        self.half_wave
    }

    /// Nodes per crown, `2m`.
    pub(super) fn nodes_per_crown(&self) -> usize {
        2 * self.peaks
    }

    /// The phase `α_k` of crown `k` (the angle of its crest `j = 0`) \[rad\].
    pub(super) fn phase(&self, k: usize) -> Real {
        self.rotation * k as Real
    }

    /// The angle of node `j` of crown `k` \[rad\].
    pub(super) fn angle(&self, k: usize, j: usize) -> Real {
        self.phase(k) + self.half_wave * j as Real
    }

    /// The number (0-based, by increasing angle from `ϑ = 0`) of node `j` of crown `k`.
    pub(super) fn number(&self, k: usize, j: usize) -> usize {
        let m = self.peaks;
        (j + 2 * m - self.first[k]) % (2 * m)
    }

    /// The nodes `j` of crown `k` by increasing angle from `ϑ = 0`.
    pub(super) fn by_angle(&self, k: usize) -> impl Iterator<Item = usize> + '_ {
        let m = self.peaks;
        (0..2 * m).map(move |i| (i + self.first[k]) % (2 * m))
    }
}

/// Every crest and trough of every crown at its station, kept when in the sector, crown by crown and by
/// increasing angle; with the index of each in the list.
pub(super) fn crown_nodes(
    spec: &StentSpec,
    axis: &Axis,
    stations: &[Real],
    layout: &Layout,
    sector: &Sector,
) -> (Vec<GeneratedNode>, NodeIndex) {
    let h = spec.crown.amplitude;
    let mut nodes = Vec::new();
    let mut node_index = vec![vec![None; layout.nodes_per_crown()]; stations.len()];
    for (k, &s) in stations.iter().enumerate() {
        let (c, r) = axis.frame(s);
        let t = r.column(0).into_owned();
        let big_r = spec.radius_of(k);
        for j in layout.by_angle(k) {
            let a = layout.angle(k, j);
            if !sector.retained(a) {
                continue;
            }
            let (sa, ca) = a.sin_cos();
            let x = if j % 2 == 0 { h } else { -h };
            let radial = r * Vec3::new(0.0, ca, sa);
            node_index[k][j] = Some(nodes.len());
            nodes.push(GeneratedNode {
                name: format!("c{}_n{}", k + 1, layout.number(k, j) + 1),
                position: c + r * Vec3::new(x, big_r * ca, big_r * sa),
                ends: Vec::new(),
                crown: k,
                index: j,
                kind: if j % 2 == 0 { CREST } else { TROUGH },
                angle: a,
                station: s,
                axis_point: c,
                axis_tangent: t,
                radial,
                symmetry_plane: sector.plane_of(a),
                multiplicity: sector.multiplicity(a),
            });
        }
    }
    (nodes, node_index)
}

/// The wires of every crown (from each node to the next by angle), kept when their mid-angle is in the
/// sector, crown by crown.
pub(super) fn crown_wires(
    spec: &StentSpec,
    axis: &Arc<Axis>,
    stations: &[Real],
    layout: &Layout,
    sector: &Sector,
    node_index: &NodeIndex,
) -> Vec<GeneratedPatch> {
    let per_crown = layout.nodes_per_crown();
    let mut patches = Vec::new();
    for (k, &s) in stations.iter().enumerate() {
        let (_, r) = axis.frame(s);
        for j in layout.by_angle(k) {
            let from = layout.angle(k, j);
            let to = from + layout.half_wave();
            if !sector.retained(0.5 * (from + to)) {
                continue;
            }
            let (Some(a), Some(b)) = (node_index[k][j], node_index[k][(j + 1) % per_crown]) else {
                unreachable!("the ends of a retained wire are retained (cuts pass through nodes)");
            };
            let (sa, ca) = from.sin_cos();
            patches.push(GeneratedPatch {
                name: format!("c{}_w{}", k + 1, layout.number(k, j) + 1),
                role: PatchRole {
                    kind: WIRE,
                    crown: k,
                    index: j,
                },
                curve: StentCurve::new(
                    axis,
                    &spec.crown,
                    (spec.radius_of(k), spec.radius_of(k)),
                    CurveKind::Crown {
                        station: s,
                        phase: layout.phase(k),
                        from,
                        to,
                    },
                ),
                start_node: a,
                end_node: b,
                normal_hint: r * Vec3::new(0.0, ca, sa),
                in_plane: None,
            });
        }
    }
    patches
}
