//! Global spline interpolation (after Piegl–Tiller A9.1) with a prescribed knot vector at prescribed
//! parameters, by default the Greville abscissae, which makes the collocation matrix well conditioned
//! (Schoenberg–Whitney holds).

use super::{KnotVector, MathError, NurbsCurve, Real, Vec3};

/// The B-spline curve with knot vector `knots` that passes through `points[i]` at `params[i]`.
/// Fails unless there is one point per basis function and the system is regular.
pub fn interpolate(
    knots: KnotVector,
    params: &[Real],
    points: &[Vec3],
) -> Result<NurbsCurve, MathError> {
    todo!("{knots:?} {params:?} {points:?}")
}

/// The B-spline curve with knot vector `knots` that passes through `points[i]` at the Greville abscissae.
pub fn interpolate_at_greville(
    knots: KnotVector,
    points: &[Vec3],
) -> Result<NurbsCurve, MathError> {
    let params = knots.greville();
    interpolate(knots, &params, points)
}
