//! Rotation-minimising frames for a bare polyline ([`parallel_transport_frames`]): for deformed
//! centrelines drawn as tubes, where the circular section makes twist irrelevant. The reference frames of
//! the rod model, along spline curves, come from [`super::frame`].

use super::frame::{double_reflection, normal_to};
use super::tube::{TubeError, centreline_tangents};
use crate::math::{Mat3, Vec3};

/// Rotation-minimising (parallel-transport) frames along a polyline, by the double reflection method of
/// Wang, Jüttler, Zheng & Liu, *Computation of rotation minimizing frames*, ACM TOG 27(1), 2008, §4.
///
/// Frame `i` has columns `d1 = t_i` (unit tangent by chord-weighted central differences, second order,
/// see [`super::tube::sweep_tube`]), `d2 = r_i`, `d3 = t_i × r_i` (a proper rotation). The first reference
/// vector `r_0` is the coordinate axis least aligned with `t_0`, made orthogonal to it ([`normal_to`]). Each
/// next one is obtained by reflecting `(r_i, t_i)` in the bisector plane of `x_i, x_{i+1}` (normal
/// `v1 = x_{i+1} − x_i`) and then in the plane that maps the reflected tangent onto `t_{i+1}` (normal
/// `v2 = t_{i+1} − t_i^L`):
///
/// ```text
/// r_i^L = r_i − 2 (v1·r_i)/(v1·v1) v1,   t_i^L = t_i − 2 (v1·t_i)/(v1·v1) v1,
/// r_{i+1} = r_i^L − 2 (v2·r_i^L)/(v2·v2) v2   (no second reflection when v2 = 0),
/// ```
///
/// then made orthogonal to `t_{i+1}` and normalised against rounding drift: one step of `double_reflection`
/// in `geometry::frame`, the same step [`super::frame::FrameField`] integrates along spline curves.
///
/// With exact tangents the method is fourth-order accurate; here the tangents are second-order, which
/// limits the frames to second order. Meant for deformed centrelines drawn as tubes, where a circular
/// section makes the twist about `d1` invisible; the reference frames of the rod model come from
/// `geometry::frame`.
///
/// # Errors
/// [`TubeError::TooFewSamples`], [`TubeError::NonFinite`], [`TubeError::CoincidentSamples`] or
/// [`TubeError::ZeroTangent`] when the polyline cannot define tangents.
pub(crate) fn parallel_transport_frames(centre: &[Vec3]) -> Result<Vec<Mat3>, TubeError> {
    let tangents = centreline_tangents(centre)?;
    let t0 = tangents[0];
    // The coordinate axis least aligned with t0 is at least 54.7° away from it, so r0 is well conditioned.
    let mut r = normal_to(&t0, None);
    let mut frames = Vec::with_capacity(centre.len());
    frames.push(Mat3::from_columns(&[t0, r, t0.cross(&r)]));
    for i in 0..centre.len() - 1 {
        let t_next = tangents[i + 1];
        // v1 = x_{i+1} − x_i ≠ 0: coincident samples were rejected.
        r = double_reflection(&centre[i], &tangents[i], &r, &centre[i + 1], &t_next);
        frames.push(Mat3::from_columns(&[t_next, r, t_next.cross(&r)]));
    }
    Ok(frames)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::test_shapes::{helix, sci};
    use crate::math::Real;
    use std::f64::consts::PI;

    // Checks: the double-reflection frames on a helix are orthonormal proper rotations with d1 along the
    // exact tangent, and rotate about d1 exactly as a rotation-minimising frame must.
    // Reference: writing d2 = cos α N + sin α B in the Frenet frame, zero rotation about the tangent requires
    // α' = −τ (in arc length), so α(t) = α(0) − (h/c) t for the helix (R cos t, R sin t, h t), c = √(R²+h²),
    // τ = h/c², N = −(cos t, sin t, 0), B = (h sin t, −h cos t, R)/c.
    // Tolerance: with second-order tangents the drift is guaranteed O(Δt²) only; on this uniformly sampled
    // helix the central-difference tangent error is the same tilt at every sample (factor sin Δt/Δt on the
    // horizontal components), and the measured drift is fourth order: 8.0e-9 rad at Δt = 4π/400, 4.8e-10
    // at Δt/2 (ratio 16.6). Required: below 1e-7 rad and at least second order (ratio > 3.5).
    #[test]
    fn helix_frames_are_rotation_minimising() {
        let (big_r, h, turns): (Real, Real, Real) = (1.0, 0.3, 2.0);
        let c = (big_r * big_r + h * h).sqrt();
        let mut drifts = Vec::new();
        for n in [401, 801] {
            let centre = helix(big_r, h, turns, n);
            let frames = parallel_transport_frames(&centre).expect("valid helix");
            let mut max_drift: Real = 0.0;
            let mut alpha0 = None;
            for (i, f) in frames.iter().enumerate() {
                assert!((f.transpose() * f - Mat3::identity()).abs().max() < 1e-14);
                assert!((f.determinant() - 1.0).abs() < 1e-14);
                let t = turns * 2.0 * PI * i as Real / (n - 1) as Real;
                let tangent = Vec3::new(-big_r * t.sin(), big_r * t.cos(), h) / c;
                let normal = -Vec3::new(t.cos(), t.sin(), 0.0);
                let binormal = Vec3::new(h * t.sin(), -h * t.cos(), big_r) / c;
                assert!((f.column(0) - tangent).norm() < 1e-3, "tangent at {i}");
                let d2 = f.column(1);
                let alpha = d2.dot(&binormal).atan2(d2.dot(&normal));
                let a0 = *alpha0.get_or_insert(alpha);
                // Wrap the difference to (−π, π].
                let diff = alpha - (a0 - h / c * t);
                let wrapped = diff - 2.0 * PI * (diff / (2.0 * PI)).round();
                max_drift = max_drift.max(wrapped.abs());
            }
            drifts.push(max_drift);
        }
        eprintln!("helix RMF angle drift {}", sci(&drifts));
        assert!(drifts[0] < 1e-7, "{drifts:?}");
        assert!(
            drifts[0] / drifts[1] > 3.5,
            "less than second order: {drifts:?}"
        );
    }

    // Checks: on a planar curve with inflection points (a sine wave in the xy plane), the frames keep
    // d3 = +e_z at every sample, i.e. they do not flip at inflections as Frenet frames do.
    // Reference: the plane normal is parallel-transported unchanged along a planar curve; the start
    // tangent ∝ (1, 1.2, 0) has z as its least-aligned axis, so r0 = d2 = e_z and must stay e_z.
    // Tolerance 1e-12: reflections in vertical planes keep e_z exactly up to rounding.
    #[test]
    fn planar_curve_frames_keep_the_plane_normal() {
        let centre: Vec<Vec3> = (0..200)
            .map(|i| i as Real * 0.05)
            .map(|x| Vec3::new(x, 0.6 * (2.0 * x).sin(), 0.0))
            .collect();
        let frames = parallel_transport_frames(&centre).expect("valid curve");
        // Least-aligned axis of t0 ∝ (1, 1.2, 0) is z, so r0 = d2 = e_z all along.
        for (i, f) in frames.iter().enumerate() {
            assert!(
                (f.column(1) - Vec3::z()).norm() < 1e-12,
                "d2 at {i}: {:?}",
                f.column(1)
            );
        }
    }
}
