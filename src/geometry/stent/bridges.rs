//! The bridges (module documentation of [`super`], "Bridges"): from a crest of crown `k` to the facing trough
//! of crown `k + 1`, at every `every`-th crest from `first`; their shape across the axis; and the check that
//! consecutive crowns do not overlap.

use super::axis::Axis;
use super::crowns::{CREST, Layout, NodeIndex, TROUGH};
use super::curve::{CurveKind, Offset, StentCurve};
use super::sector::Sector;
use super::{
    ANGLE_TOLERANCE, BridgeDirection, BridgeShape, BridgeSpec, GeneratedNode, GeneratedPatch,
    PartKind, PatchRole, StentParameter, StentSpec, Symmetry, invalid, same_angle,
};
use crate::geometry::GeometryError;
use crate::math::{Real, Vec3};
use std::sync::Arc;

/// The ring family's bridge, from a crest of crown `k` to the facing trough of crown `k + 1`.
pub(super) const BRIDGE: PartKind = PartKind(1);

/// The bridges between consecutive crowns that the sector keeps, pair by pair and by increasing angle, with
/// the nodes they end at (each once, sorted).
///
/// # Errors
/// [`GeometryError::InvalidStent`] when the bridges of a pair are not symmetric about a cut plane, a
/// circumferential bridge lies on one, or a crest faces no trough (a rotation beyond round-off's reach).
pub(super) fn bridges(
    spec: &StentSpec,
    bridges: &BridgeSpec,
    axis: &Arc<Axis>,
    stations: &[Real],
    layout: &Layout,
    sector: &Sector,
    node_index: &NodeIndex,
) -> Result<(Vec<GeneratedPatch>, Vec<usize>), GeometryError> {
    let m = spec.crown.peaks;
    let half_wave = layout.half_wave();
    let mut patches = Vec::new();
    let mut bridge_ends = Vec::new();
    for k in 0..stations.len().saturating_sub(1) {
        let mut crests: Vec<usize> = (0..m)
            .filter(|c| c % bridges.every == bridges.first)
            .collect();
        crests.sort_by_key(|&c| layout.number(k, 2 * c));
        let angles: Vec<Real> = crests
            .iter()
            .map(|&c| layout.phase(k) + 2.0 * half_wave * c as Real)
            .collect();
        spec.check_bridge_symmetry(k, &angles)?;
        let (_, r) = axis.frame(stations[k]);
        for (&c, &a) in crests.iter().zip(&angles) {
            if !sector.retained(a) {
                continue;
            }
            // The facing trough of crown k + 1.
            let q = (a - layout.phase(k + 1)) / half_wave;
            let j = (q.round() as i64).rem_euclid(2 * m as i64) as usize;
            debug_assert!(j % 2 == 1 && same_angle(a, layout.phase(k + 1) + half_wave * j as Real));
            // A rotation so large that angles lost their precision (found by fuzzing the designs:
            // `rotation_deg: 1e308`) can leave a crest facing no retained trough: an error, not a panic.
            let (Some(start), Some(end)) = (node_index[k][2 * c], node_index[k + 1][j]) else {
                return Err(invalid(
                    StentParameter::Rotation,
                    format!(
                        "the bridge from crown {} at ϑ = {:.6} rad finds no trough of crown {} facing it; give a rotation in degrees within (−360, 360)",
                        k + 1,
                        a,
                        k + 2
                    ),
                ));
            };
            let in_plane = sector.plane_of(a);
            let offset = offset(spec.symmetry, bridges.shape, a)?;
            let (sa, ca) = a.sin_cos();
            bridge_ends.extend([start, end]);
            patches.push(GeneratedPatch {
                name: format!("b{}_{}", k + 1, layout.number(k, 2 * c) + 1),
                role: PatchRole {
                    kind: BRIDGE,
                    crown: k,
                    index: c,
                },
                curve: StentCurve::new(
                    axis,
                    &spec.crown,
                    (spec.radius_of(k), spec.radius_of(k + 1)),
                    CurveKind::Bridge {
                        from: stations[k],
                        to: stations[k + 1],
                        angle: a,
                        offset,
                    },
                ),
                start_node: start,
                end_node: end,
                normal_hint: r * Vec3::new(0.0, ca, sa),
                in_plane,
            });
        }
    }
    bridge_ends.sort_unstable();
    bridge_ends.dedup();
    Ok((patches, bridge_ends))
}

impl StentSpec {
    /// Consecutive crowns must not overlap: at every retained crest the next crown's facing trough lies ahead
    /// along the axis (tight bends bring crowns together on the inside).
    pub(super) fn check_clearance(
        &self,
        axis: &Axis,
        stations: &[Real],
        nodes: &[GeneratedNode],
    ) -> Result<(), GeometryError> {
        for crest in nodes {
            if crest.kind != CREST || crest.crown + 1 >= stations.len() {
                continue;
            }
            let k = crest.crown;
            let (_, r) = axis.frame(0.5 * (stations[k] + stations[k + 1]));
            let facing = nodes
                .iter()
                .find(|q| q.crown == k + 1 && q.kind == TROUGH && same_angle(q.angle, crest.angle));
            if let Some(q) = facing
                && (q.position - crest.position).dot(&r.column(0)) <= 0.0
            {
                return Err(invalid(
                    StentParameter::Spacing,
                    format!(
                        "crowns {} and {} overlap at ϑ = {:.1}°: the bend is too tight for the crown height (increase the spacing or the bend radius)",
                        k + 1,
                        k + 2,
                        crest.angle.to_degrees()
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The shape across the axis of the bridge at crest angle `a`: a circumferential sine turns the way the
/// device's symmetry mirrors it (`sign sin ϑ₀` for half, `sign sin 2ϑ₀` for quarter symmetry, `+1` without).
///
/// # Errors
/// [`StentParameter::BridgesDirection`] for a circumferential sine on a symmetry plane (it cannot be symmetric
/// about it).
fn offset(symmetry: Symmetry, shape: BridgeShape, a: Real) -> Result<Offset, GeometryError> {
    Ok(match shape {
        BridgeShape::Straight => Offset::None,
        BridgeShape::Sinusoidal {
            amplitude,
            waves,
            direction: BridgeDirection::Radial,
        } => Offset::Radial { amplitude, waves },
        BridgeShape::Sinusoidal {
            amplitude,
            waves,
            direction: BridgeDirection::Circumferential,
        } => {
            let sign = match symmetry {
                Symmetry::None => 1.0,
                Symmetry::Half => a.sin(),
                Symmetry::Quarter => (2.0 * a).sin(),
            };
            if sign.abs() <= ANGLE_TOLERANCE {
                return Err(invalid(
                    StentParameter::BridgesDirection,
                    format!(
                        "the circumferential sinusoidal bridge at ϑ = {:.3}° lies on a symmetry plane and cannot be symmetric about it: use `direction: radial`, straight bridges, or crests off the plane (`every`, `first`)",
                        a.to_degrees()
                    ),
                ));
            }
            Offset::Circumferential {
                amplitude: amplitude * sign.signum(),
                waves,
            }
        }
    })
}
