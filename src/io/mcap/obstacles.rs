//! The obstacles of a model with contact in the recording: the `/obstacles` channel (an entity per obstacle at
//! every state — a cylinder as a translucent `CylinderPrimitive` whose diameter follows its schedule, a plane
//! as a large thin square `CubePrimitive` that moves with its offset) and which centreline samples touch an
//! obstacle (drawn in [`TOUCH_COLOR`] on `/centrelines`).
//!
//! **Extent.** A surface is unbounded; it is drawn over the device: a cylinder along its axis over the device's
//! reference control points projected on the axis, a plane as a square centred under their centroid, both
//! with a margin of [`MARGIN`] of the device's size (the diagonal of the control points' bounding box).
//!
//! **Touching.** A sample touches an obstacle when its gap (distance from the surface minus the wire radius)
//! is at most the law's half transition band `δ` plus the penetration tolerance: within the band the penalty
//! alone presses, and a point held by augmented Lagrange sits at zero gap within the tolerance. The samples are
//! the recorded centreline's (between the collocation points too); a mirrored copy of a rod shows the touches
//! of the rod it copies (the mirrored obstacle's, in a symmetry-reduced model).

use super::format::{Primitives, entity, push_point, scene_update_of};
use crate::math::{Real, Vec3};
use crate::model::{Model, Obstacle, Surface};

/// Colour of a centreline sample that touches an obstacle (`foxglove.Color`, opaque green).
pub(super) const TOUCH_COLOR: &str = r#"{"r":0.100,"g":0.850,"b":0.250,"a":1}"#;

/// Colour of the obstacles (translucent grey-blue).
const OBSTACLE_COLOR: &str = r#"{"r":0.45,"g":0.55,"b":0.75,"a":0.25}"#;

/// Margin of the drawn surfaces beyond the device, as a fraction of its size.
const MARGIN: Real = 0.25;

/// Thickness of a plane's square, as a fraction of its side.
const PLANE_THICKNESS: Real = 1e-3;

/// What is fixed in the drawing of each obstacle (module docs).
pub(super) struct ObstacleDrawing {
    obstacles: Vec<Obstacle>,
    /// Per obstacle: the centre of the drawn extent along a cylinder's axis (or the point a plane's square is
    /// centred under) and its length (or side) \[length\].
    extents: Vec<(Vec3, Real)>,
    /// Wire radius per patch \[length\].
    radius: Vec<Real>,
    /// The gap up to which a sample touches (module docs) \[length\].
    touch: Real,
}

impl ObstacleDrawing {
    /// The drawing of `model`'s obstacles; `None` without contact.
    pub(super) fn new(model: &Model) -> Option<Self> {
        let contact = model.contact.as_ref()?;
        let points = crate::model::wires::reference_control(model);
        let (lo, hi) = points.iter().fold(
            (
                Vec3::repeat(Real::INFINITY),
                Vec3::repeat(Real::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.inf(p), hi.sup(p)),
        );
        let size = if points.is_empty() {
            1.0
        } else {
            (hi - lo).norm()
        };
        let centroid = points.iter().sum::<Vec3>() / (points.len().max(1) as Real);
        let extents = contact
            .obstacles
            .iter()
            .map(|o| match &o.surface {
                Surface::Cylinder { point, axis, .. } => {
                    let (a, b) = points
                        .iter()
                        .map(|p| axis.dot(&(p - point)))
                        .fold((Real::INFINITY, Real::NEG_INFINITY), |(a, b), s| {
                            (a.min(s), b.max(s))
                        });
                    let (a, b) = if a <= b { (a, b) } else { (0.0, 0.0) };
                    (point + axis * (0.5 * (a + b)), b - a + 2.0 * MARGIN * size)
                }
                Surface::Plane { .. } => (centroid, (1.0 + 2.0 * MARGIN) * size),
                // A vessel's lumen is drawn on `/vessel` already.
                Surface::Lumen(_) => (centroid, 0.0),
            })
            .collect();
        let settings = contact.settings;
        Some(Self {
            obstacles: contact.obstacles.clone(),
            extents,
            radius: model
                .patches
                .iter()
                .map(|p| 0.5 * model.sections[p.section].diameter())
                .collect(),
            touch: 0.5 * settings.regularisation + settings.tolerance,
        })
    }

    /// The `/obstacles` message: an entity `obstacle.<name>` per obstacle, its surface at time `t`.
    pub(super) fn message(&self, t: Real, log_time: u64, decimals: usize) -> String {
        let entities: Vec<String> = self
            .obstacles
            .iter()
            .zip(&self.extents)
            .filter_map(|(o, &(centre, length))| {
                let id = format!("obstacle.{}", super::path_key(&o.name));
                let (position, normal, size) = match &o.surface {
                    Surface::Cylinder { axis, radius, .. } => {
                        let d = 2.0 * radius.value(t);
                        (centre, *axis, Vec3::new(d, d, length))
                    }
                    Surface::Plane {
                        point,
                        normal,
                        offset,
                    } => {
                        let above = normal.dot(&(centre - point)) - offset.value(t);
                        let thick = PLANE_THICKNESS * length;
                        // The square's far face lies in the plane: it is drawn on the side away from the rods.
                        let position = centre - normal * (above + 0.5 * thick);
                        (position, *normal, Vec3::new(length, length, thick))
                    }
                    // A vessel's lumen is drawn on `/vessel` already.
                    Surface::Lumen(_) => return None,
                };
                let mut primitive = String::from(r#"{"pose":{"position":"#);
                push_point(&mut primitive, &position, decimals);
                let q = z_onto(&normal);
                primitive.push_str(&format!(
                    r#","orientation":{{"x":{},"y":{},"z":{},"w":{}}}}},"size":"#,
                    q[0], q[1], q[2], q[3]
                ));
                push_point(&mut primitive, &size, decimals);
                let primitives = match o.surface {
                    Surface::Cylinder { .. } => {
                        primitive.push_str(&format!(
                            r#","bottom_scale":1,"top_scale":1,"color":{OBSTACLE_COLOR}}}"#
                        ));
                        Primitives {
                            cylinders: &primitive,
                            ..Primitives::default()
                        }
                    }
                    Surface::Plane { .. } | Surface::Lumen(_) => {
                        primitive.push_str(&format!(r#","color":{OBSTACLE_COLOR}}}"#));
                        Primitives {
                            cubes: &primitive,
                            ..Primitives::default()
                        }
                    }
                };
                Some(entity(&id, log_time, &primitives))
            })
            .collect();
        scene_update_of(&entities)
    }

    /// Whether the sample `x` of patch `patch` touches an obstacle at time `t` (module docs).
    pub(super) fn touches(&self, patch: usize, x: &Vec3, t: Real) -> bool {
        self.obstacles.iter().any(|o| {
            o.surface
                .distance(x, t)
                .is_some_and(|d| d.value - self.radius[patch] <= self.touch)
        })
    }
}

/// The unit quaternion `[x, y, z, w]` that turns the z axis onto the unit vector `to` (a half-turn about x for
/// `to = −z`): `q = (z × to, 1 + z·to)` normalised (half the angle between them, about their normal).
fn z_onto(to: &Vec3) -> [Real; 4] {
    let (v, w) = (Vec3::z().cross(to), 1.0 + to.z);
    let norm = (v.norm_squared() + w * w).sqrt();
    if norm == 0.0 {
        return [1.0, 0.0, 0.0, 0.0];
    }
    [v.x / norm, v.y / norm, v.z / norm, w / norm]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Source: the rotation of a unit quaternion `(v, w)` maps `z` to `z + 2w (v × z) + 2 v × (v × z)`
    /// (Rodrigues' formula in quaternion form); it must land on the target, for axes in general position and
    /// for the two special ones (`±z`).
    #[test]
    fn the_orientation_turns_z_onto_the_axis() {
        for to in [
            Vec3::z(),
            -Vec3::z(),
            Vec3::x(),
            Vec3::new(1.0, -2.0, 0.5).normalize(),
            Vec3::new(0.0, 1e-6, -1.0).normalize(),
        ] {
            let q = z_onto(&to);
            let (v, w) = (Vec3::new(q[0], q[1], q[2]), q[3]);
            let z = Vec3::z();
            let turned = z + 2.0 * w * v.cross(&z) + 2.0 * v.cross(&v.cross(&z));
            assert!((turned - to).norm() < 1e-9, "{to:?} → {turned:?}");
            assert!((v.norm_squared() + w * w - 1.0).abs() < 1e-12);
        }
    }
}
