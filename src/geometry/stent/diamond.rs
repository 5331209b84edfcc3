//! The closed diamond-cell stent (`family: diamond`): sinusoidal rings whose neighbours meet crest to trough,
//! as in most balloon-expandable stents, so that every pair of consecutive rings closes a row of diamond cells
//! and no bridge is needed.
//!
//! # Construction
//!
//! The device has `N` rings of `m` crests, radius `R` and amplitude `h`, and `N + 1` rows of nodes at stations
//! `s_r = s_0 + 2 h r` (`r = 0 … N`) on the centreline, centred on a bounded one. Row `r` has its `m` nodes at
//! the angles `ϑ = q π/m` with `q ≡ r (mod 2)`; ring `k` runs between rows `k` (its troughs) and `k + 1` (its
//! crests), so a crest of ring `k` *is* a trough of ring `k + 1`: one node (a `JUNCTION`) where
//! four struts meet. Only the first row (troughs of ring 1) and the last (crests of ring `N`) are free.
//!
//! Strut `q` of ring `k` joins its nodes at `ϑ_q = q π/m` and `ϑ_{q+1}`; with `u ∈ [0, 1]` it is
//!
//! ```text
//! w(u) = (1 − cos π u)/2,   σ(u) = (1 − w) s_a + w s_b,   ϑ(u) = ϑ_q + u π/m,
//! P(u) = c_stent(σ) + R_stent(σ) · (0, R cos ϑ, R sin ϑ),
//! ```
//!
//! where `s_a, s_b` are the stations of its start and end nodes. Nodes are placed by the same formula
//! (`P = c_stent(s_r) + R_stent(s_r) · (0, R cos ϑ, R sin ϑ)`), and at `u = 0, 1` the strut evaluates exactly
//! the same numbers, so the joined ends coincide to the bit. On a straight centreline `σ − (s_k + h)` is
//! `h cos(m (ϑ − α_k))` with the crest phase `α_k = (k + 1) π/m`: ring `k` is the ring family's crown of
//! amplitude `h` turned by `π/m` per ring, spaced `2 h` (the ring family needs `d_c > 2 h_c` and bridges); on a
//! bent one the ring follows the axis between its two rows instead of lying in one section plane, which keeps
//! the junctions closed.
//!
//! **Symmetry.** Every node is joined to both nearest nodes of each neighbouring row, so the device is mirror
//! symmetric about every plane through the axis and a node angle; the planes `ϑ = 0, π` and (for even `m`)
//! `ϑ = ±π/2` are such planes, and no strut crosses one between nodes. The cuts are those of the ring family
//! ([`super::Symmetry`]); no strut lies in a plane.

use super::axis::Axis;
use super::checks::check_bend_radius;
use super::curve::{CurveKind, StentCurve};
use super::family::{FamilyCounts, StentFamily};
use super::sector::{Sector, check_axis_symmetry};
use super::temporary::{Placement, placement, temporary_axis};
use super::{
    CentrelineSpec, CrownShape, CrownSpec, GeneratedNode, GeneratedPatch, NodeKind,
    PLANARITY_TOLERANCE, PartKind, PatchRole, StentGeometry, StentParameter, Symmetry,
    TemporarySpec, WireEnd, invalid,
};
use crate::geometry::GeometryError;
use crate::math::{Real, Vec3};
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::sync::Arc;

/// The diamond family's free trough: a node of the first row (troughs of ring 1).
const TROUGH_END: NodeKind = NodeKind(0);
/// The diamond family's free crest: a node of the last row (crests of ring `N`).
const CREST_END: NodeKind = NodeKind(1);
/// The diamond family's junction: a crest of ring `k` that is a trough of ring `k + 1`, where four struts meet.
const JUNCTION: NodeKind = NodeKind(2);
/// The diamond family's strut, half a wave of a ring from a node of one row to the next node of the other.
const STRUT: PartKind = PartKind(0);

/// Everything that defines a closed diamond-cell stent.
#[derive(Debug, Clone, PartialEq)]
pub struct DiamondSpec {
    /// Radius `R` of the cylinder the rings lie on \[length\], > 0.
    pub radius: Real,
    /// Amplitude `h` of each ring (a ring is `2 h` long, a cell `4 h`) \[length\], > 0.
    pub amplitude: Real,
    /// Crests `m` per ring (cells around the circumference), ≥ 2.
    pub peaks: usize,
    /// Number of rings `N`, ≥ 1 (`N − 1` rows of closed cells).
    pub rings: usize,
    /// The axis.
    pub centreline: CentrelineSpec,
    /// The symmetry of the device (the possible cuts).
    pub symmetry: Symmetry,
    /// Keep only the symmetry sector (`true`) or the whole device (`false`).
    pub cut: bool,
}

/// The counts of a diamond stent of `rings` rings of `peaks` crests modelled as one of `sectors` copies:
/// `2m` struts per ring, `m` nodes in each of the `N + 1` rows, no bridges.
pub fn diamond_counts(rings: usize, peaks: usize, sectors: usize) -> FamilyCounts {
    let (n, m) = (rings as Real, peaks as Real);
    FamilyCounts {
        crown_wires: n * 2.0 * m,
        bridges: 0.0,
        nodes: (n + 1.0) * m,
        sectors,
    }
}

impl DiamondSpec {
    /// The numbers that must hold on their own.
    fn check_numbers(&self) -> Result<(), GeometryError> {
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return Err(invalid(
                StentParameter::Radius,
                format!("must be > 0, got {}", self.radius),
            ));
        }
        if !(self.amplitude.is_finite() && self.amplitude > 0.0) {
            return Err(invalid(
                StentParameter::Amplitude,
                format!("must be > 0, got {}", self.amplitude),
            ));
        }
        if self.peaks < 2 {
            return Err(invalid(
                StentParameter::Peaks,
                format!(
                    "a ring of diamond cells needs at least two crests (two cells around), got {}",
                    self.peaks
                ),
            ));
        }
        if self.rings == 0 {
            return Err(invalid(
                StentParameter::Crowns,
                "a stent needs at least one ring",
            ));
        }
        Ok(())
    }

    /// The stations of the `N + 1` rows of nodes on `axis`, `2 h` apart, centred on a bounded centreline.
    fn stations(&self, axis: &Axis) -> Result<Vec<Real>, GeometryError> {
        let spacing = 2.0 * self.amplitude;
        let span = spacing * self.rings as Real;
        let start = match axis.length() {
            None => 0.0,
            Some(l) if span > l * (1.0 + PLANARITY_TOLERANCE) => {
                return Err(invalid(
                    StentParameter::Crowns,
                    format!(
                        "{} rings of height 2 h = {spacing} span {span}, more than the centreline length {l}",
                        self.rings
                    ),
                ));
            }
            Some(l) => 0.5 * (l - span).max(0.0),
        };
        Ok((0..=self.rings)
            .map(|r| start + spacing * r as Real)
            .collect())
    }

    /// The device on `axis` with its rows at `stations`, every ring of radius `radius`; `checked`: refused where
    /// the permanent shape's limits are broken (bend radius, symmetry).
    fn generate_on(
        &self,
        axis: Arc<Axis>,
        stations: Vec<Real>,
        radius: Real,
        checked: bool,
    ) -> Result<StentGeometry, GeometryError> {
        if checked {
            check_bend_radius(radius, &axis)?;
            check_axis_symmetry(self.symmetry, self.peaks, &axis)?;
        }
        let sector = Sector::of(self.symmetry, self.cut);
        let symmetry_planes = sector.planes(&axis, stations[0]);
        let (m, n) = (self.peaks, self.rings);
        let half_wave = PI / m as Real;
        let angle = |q: usize| q as Real * half_wave;
        // Nodes row by row, by increasing angle; `index[r][q]` is the node at row r, angle q π/m.
        let mut nodes = Vec::new();
        let mut index = vec![vec![None; 2 * m]; n + 1];
        for (r, &s) in stations.iter().enumerate() {
            let (c, frame) = axis.frame(s);
            for q in (r % 2..2 * m).step_by(2) {
                let a = angle(q);
                if !sector.retained(a) {
                    continue;
                }
                let (sa, ca) = a.sin_cos();
                index[r][q] = Some(nodes.len());
                nodes.push(GeneratedNode {
                    name: format!("r{}_n{}", r + 1, q / 2 + 1),
                    position: c + frame * Vec3::new(0.0, radius * ca, radius * sa),
                    ends: Vec::new(),
                    crown: r.saturating_sub(1),
                    index: q,
                    kind: match r {
                        0 => TROUGH_END,
                        _ if r == n => CREST_END,
                        _ => JUNCTION,
                    },
                    angle: a,
                    station: s,
                    axis_point: c,
                    axis_tangent: frame.column(0).into_owned(),
                    radial: frame * Vec3::new(0.0, ca, sa),
                    symmetry_plane: sector.plane_of(a),
                    multiplicity: sector.multiplicity(a),
                });
            }
        }
        // The struts, ring by ring, by increasing angle: strut q of ring k from angle q π/m (on row k when q has
        // the parity of k, else on row k + 1) to the next node angle, on the other row.
        let crown = CrownSpec {
            radius,
            amplitude: self.amplitude,
            peaks: m,
            shape: CrownShape::Sinusoidal,
        };
        let mut patches = Vec::new();
        for k in 0..n {
            for q in 0..2 * m {
                if !sector.retained(angle(q) + 0.5 * half_wave) {
                    continue;
                }
                let (row_a, row_b) = if q % 2 == k % 2 {
                    (k, k + 1)
                } else {
                    (k + 1, k)
                };
                let next = (q + 1) % (2 * m);
                let (Some(start), Some(end)) = (index[row_a][q], index[row_b][next]) else {
                    unreachable!(
                        "the ends of a retained strut are retained (cuts pass through nodes)"
                    );
                };
                patches.push(GeneratedPatch {
                    name: format!("c{}_w{}", k + 1, q + 1),
                    role: PatchRole {
                        kind: STRUT,
                        crown: k,
                        index: q,
                    },
                    curve: StentCurve::new(
                        &axis,
                        &crown,
                        (radius, radius),
                        CurveKind::Strut {
                            from: (stations[row_a], angle(q)),
                            to: (stations[row_b], angle(next)),
                            turn: half_wave,
                        },
                    ),
                    start_node: start,
                    end_node: end,
                    normal_hint: nodes[start].radial,
                    in_plane: None,
                });
            }
        }
        for (p, patch) in patches.iter().enumerate() {
            nodes[patch.start_node].ends.push((p, WireEnd::Start));
            nodes[patch.end_node].ends.push((p, WireEnd::End));
        }
        let node_sets = node_sets(&nodes, n);
        Ok(StentGeometry {
            patches,
            nodes,
            node_sets,
            symmetry_planes,
            stations,
        })
    }
}

/// `all_joints`, `crown_<k>` (1-based: the nodes of ring `k`, its troughs and crests), `junctions` (where two
/// rings meet), `ends` (the free first and last rows) and `symmetry` (the nodes on a cut plane), each as
/// indices into `nodes` in increasing order.
fn node_sets(nodes: &[GeneratedNode], rings: usize) -> BTreeMap<String, Vec<usize>> {
    let select = |keep: &dyn Fn(&GeneratedNode) -> bool| -> Vec<usize> {
        (0..nodes.len()).filter(|&i| keep(&nodes[i])).collect()
    };
    // A node's rows: a junction belongs to ring `crown` (its crest) and `crown + 1` (its trough).
    let in_ring = |node: &GeneratedNode, k: usize| match node.kind {
        TROUGH_END => k == 0,
        CREST_END => k == node.crown,
        JUNCTION => k == node.crown || k == node.crown + 1,
        _ => false,
    };
    let mut sets = BTreeMap::new();
    sets.insert("all_joints".to_string(), select(&|_| true));
    for k in 0..rings {
        sets.insert(format!("crown_{}", k + 1), select(&|g| in_ring(g, k)));
    }
    sets.insert("junctions".into(), select(&|g| g.kind == JUNCTION));
    sets.insert("ends".into(), select(&|g| g.kind != JUNCTION));
    sets.insert("symmetry".into(), select(&|g| g.symmetry_plane.is_some()));
    sets
}

impl StentFamily for DiamondSpec {
    fn name(&self) -> &'static str {
        "diamond"
    }

    fn generate(&self) -> Result<StentGeometry, GeometryError> {
        self.check_numbers()?;
        let axis = Arc::new(Axis::new(&self.centreline)?);
        let stations = self.stations(&axis)?;
        self.generate_on(axis, stations, self.radius, true)
    }

    fn generate_temporary(
        &self,
        temporary: &TemporarySpec,
        shrink: Real,
    ) -> Result<StentGeometry, GeometryError> {
        self.check_numbers()?;
        let Placement {
            axis,
            stations,
            radii,
        } = placement(
            &self.centreline,
            |axis| self.stations(axis),
            temporary,
            [self.radius],
            shrink,
            "ring",
        )?;
        self.generate_on(Arc::new(axis), stations, radii[0], false)
    }

    fn temporary_node_positions(
        &self,
        geometry: &StentGeometry,
        temporary: &TemporarySpec,
    ) -> Result<Vec<Vec3>, GeometryError> {
        let axis = temporary_axis(Axis::new(&self.centreline)?, &geometry.stations, temporary)?;
        let radius = temporary.radius.unwrap_or(self.radius);
        Ok(geometry
            .nodes
            .iter()
            .map(|node| {
                let (c, frame) = axis.frame(node.station);
                let (sa, ca) = node.angle.sin_cos();
                c + frame * Vec3::new(0.0, radius * ca, radius * sa)
            })
            .collect())
    }

    fn radius_range(&self) -> (Real, Real) {
        (self.radius, self.radius)
    }

    fn axis_points(&self, s: &[Real]) -> Result<Vec<Vec3>, GeometryError> {
        super::axis::points(&self.centreline, s)
    }

    fn crowns(&self) -> usize {
        self.rings
    }

    fn is_connector(&self, _role: &PatchRole) -> bool {
        false
    }

    fn facing_nodes(&self, _geometry: &StentGeometry) -> Vec<(usize, usize)> {
        // Consecutive rings meet at their junctions: no gap between them to keep open.
        Vec::new()
    }

    fn counts(&self) -> FamilyCounts {
        diamond_counts(
            self.rings,
            self.peaks,
            if self.cut { self.symmetry.sectors() } else { 1 },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::analytic::ParametricCurve;

    fn diamond(symmetry: Symmetry, cut: bool) -> DiamondSpec {
        DiamondSpec {
            radius: 3.0,
            amplitude: 1.0,
            peaks: 6,
            rings: 3,
            centreline: CentrelineSpec::Straight {
                origin: Vec3::zeros(),
                direction: Vec3::x(),
                reference: Some(Vec3::y()),
            },
            symmetry,
            cut,
        }
    }

    // Closed cells: every strut starts and ends exactly (to the bit) at the node it is joined to, so a crest of
    // ring k and the trough of ring k + 1 it meets are one point; every junction joins four strut ends (two of
    // each ring), every free node two. On an arc centreline too, where the ring family's crowns would not meet.
    #[test]
    fn the_cells_are_closed_to_the_bit() {
        let mut bent = diamond(Symmetry::None, false);
        bent.centreline = CentrelineSpec::Arc {
            centre: Vec3::new(0.0, 0.0, -40.0),
            start: Vec3::zeros(),
            axis: Vec3::y(),
            angle: 0.5,
            reference: None,
        };
        for spec in [diamond(Symmetry::None, false), bent] {
            let g = spec.generate().unwrap();
            for p in &g.patches {
                assert_eq!(
                    p.curve.point(0.0),
                    g.nodes[p.start_node].position,
                    "{}",
                    p.name
                );
                assert_eq!(
                    p.curve.point(1.0),
                    g.nodes[p.end_node].position,
                    "{}",
                    p.name
                );
            }
            for node in &g.nodes {
                let rings: Vec<usize> = node
                    .ends
                    .iter()
                    .map(|&(p, _)| {
                        let role = g.patches[p].role;
                        assert_eq!(role.kind, STRUT, "no part but struts");
                        role.crown
                    })
                    .collect();
                match node.kind {
                    JUNCTION => {
                        assert_eq!(node.ends.len(), 4, "{}", node.name);
                        for k in [node.crown, node.crown + 1] {
                            assert_eq!(
                                rings.iter().filter(|&&r| r == k).count(),
                                2,
                                "{}",
                                node.name
                            );
                        }
                    }
                    _ => assert_eq!(node.ends.len(), 2, "{}", node.name),
                }
            }
        }
    }

    // On a straight centreline a ring is the sinusoid x = h cos(m (ϑ − α_k)) about its middle station, the
    // crown of the ring family (module docs): checked at interior points of every strut of ring 2.
    #[test]
    fn a_ring_on_a_straight_axis_is_the_crowns_sinusoid() {
        let spec = diamond(Symmetry::None, false);
        let g = spec.generate().unwrap();
        let (h, m) = (spec.amplitude, spec.peaks as Real);
        let (k, middle) = (1, 0.5 * (g.stations[1] + g.stations[2]));
        let phase = (k + 1) as Real * PI / m;
        for p in g.patches.iter().filter(|p| p.role.crown == k) {
            for t in [0.1, 0.3, 0.5, 0.8] {
                let x = p.curve.point(t);
                let a = x.z.atan2(x.y);
                let want = h * (m * (a - phase)).cos();
                assert!(
                    (x.x - middle - want).abs() < 1e-12,
                    "{}: {}",
                    p.name,
                    x.x - middle - want
                );
                assert!(((x.y * x.y + x.z * x.z).sqrt() - spec.radius).abs() < 1e-12);
            }
        }
    }

    // The counts the family reports without generating are what it generates: whole devices one for one; a cut
    // one weighted by the copies each part and node stands for (a node on a plane stands for half as many).
    #[test]
    fn reported_counts_are_the_generated_ones() {
        for (symmetry, cut) in [
            (Symmetry::None, false),
            (Symmetry::Half, true),
            (Symmetry::Quarter, true),
            (Symmetry::Quarter, false),
        ] {
            let spec = diamond(symmetry, cut);
            let counts = spec.counts();
            let g = spec.generate().unwrap();
            let sectors = counts.sectors;
            assert_eq!(sectors, if cut { symmetry.sectors() } else { 1 });
            let patches = (g.patches.len() * sectors) as Real;
            let nodes: usize = g.nodes.iter().map(|n| n.multiplicity).sum();
            assert_eq!(
                patches,
                counts.crown_wires + counts.bridges,
                "{symmetry:?} {cut}"
            );
            assert_eq!(nodes as Real, counts.nodes, "{symmetry:?} {cut}");
        }
        // 3 rings × 12 struts, 4 rows × 6 nodes, by hand.
        let whole = diamond(Symmetry::None, false).generate().unwrap();
        assert_eq!((whole.patches.len(), whole.nodes.len()), (36, 24));
        assert_eq!(whole.node_sets["junctions"].len(), 12);
        assert_eq!(whole.node_sets["crown_2"].len(), 12);
    }

    #[test]
    fn quarter_symmetry_needs_an_even_number_of_crests() {
        let mut spec = diamond(Symmetry::Quarter, true);
        spec.peaks = 5;
        assert!(matches!(
            spec.generate(),
            Err(GeometryError::InvalidStent {
                parameter: StentParameter::Symmetry,
                ..
            })
        ));
    }
}
