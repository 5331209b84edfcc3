//! The vessel beside the device: the closed tube of the lumen radius around the vessel's centreline (a stent
//! placed on a centreline read from a file, [`crate::model::Vessel`]).

use crate::geometry::frame::basis_from_unit_axis;
use crate::geometry::mesh::TriangleMesh;
use crate::geometry::tube::{TubeError, TubeSettings, sweep_tube_varying};
use crate::math::{Mat3, Vec3};
use crate::model::Vessel;

/// The lumen of `vessel` as a closed tube with `segments` vertices around, its sections carried along the
/// centreline by rotation-minimising frames (double reflection: Wang, Jüttler, Zheng & Liu, ACM TOG 27(1),
/// 2008, Algorithm 1); `None` when the vessel has no radius.
///
/// # Errors
/// [`TubeError`] for a centreline the tube cannot follow (coinciding points, a radius that is not positive).
pub fn lumen_mesh(vessel: &Vessel, segments: usize) -> Option<Result<TriangleMesh, TubeError>> {
    let radius = vessel.radius.as_ref()?;
    let points = &vessel.points;
    let tangent = |i: usize| {
        let (a, b) = (i.saturating_sub(1), (i + 1).min(points.len() - 1));
        (points[b] - points[a]).normalize()
    };
    let mut frames: Vec<Mat3> = Vec::with_capacity(points.len());
    frames.push(basis_from_unit_axis(&tangent(0)));
    for i in 1..points.len() {
        let previous = frames[i - 1];
        let (r0, t0) = (
            previous.column(1).into_owned(),
            previous.column(0).into_owned(),
        );
        let v1: Vec3 = points[i] - points[i - 1];
        let c1 = v1.dot(&v1);
        let (r_l, t_l) = if c1 > 0.0 {
            (
                r0 - (2.0 / c1) * v1.dot(&r0) * v1,
                t0 - (2.0 / c1) * v1.dot(&t0) * v1,
            )
        } else {
            (r0, t0)
        };
        let t1 = tangent(i);
        let v2 = t1 - t_l;
        let c2 = v2.dot(&v2);
        let r1 = if c2 > 0.0 {
            r_l - (2.0 / c2) * v2.dot(&r_l) * v2
        } else {
            r_l
        };
        let r1 = (r1 - r1.dot(&t1) * t1).normalize();
        frames.push(Mat3::from_columns(&[t1, r1, t1.cross(&r1)]));
    }
    let settings = TubeSettings {
        segments_around: segments,
        ..TubeSettings::default()
    };
    Some(sweep_tube_varying(points, &frames, radius, &settings))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Source: the volume of a cone frustum, π h (r₀² + r₀r₁ + r₁²)/3, against the closed tube of a straight
    /// vessel whose radius grows linearly; the polygon of 64 sides has sin(2π/64)/(2π/64) of the circle's area.
    #[test]
    fn a_straight_tapering_lumen_has_the_frustums_volume() {
        let n = 21;
        let vessel = Vessel {
            points: (0..n).map(|k| Vec3::new(0.0, 0.0, k as f64)).collect(),
            radius: Some((0..n).map(|k| 2.0 + 0.05 * k as f64).collect()),
        };
        let mesh = lumen_mesh(&vessel, 64).expect("a radius").expect("a tube");
        mesh.check_closed().expect("closed");
        let (r0, r1, h) = (2.0, 3.0, 20.0);
        let polygon =
            (2.0 * std::f64::consts::PI / 64.0).sin() / (2.0 * std::f64::consts::PI / 64.0);
        let expected = std::f64::consts::PI * h * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0 * polygon;
        assert!(
            (mesh.volume() - expected).abs() < 1e-9 * expected,
            "{} vs {expected}",
            mesh.volume()
        );
        assert!(
            lumen_mesh(
                &Vessel {
                    radius: None,
                    ..vessel
                },
                16
            )
            .is_none()
        );
    }
}
