//! Least-squares spline approximation of points with the end points kept (Piegl–Tiller §9.4.1, Eqs. 9.63–9.69,
//! A9.7 without weights): for data `Q_0 … Q_m` at chord-length parameters `ū_k` and `n + 1` control points, the
//! knots are placed by Eq. 9.69 (every knot span holds data), `P_0 = Q_0`, `P_n = Q_m`, and the interior control
//! points minimise `Σ_k |C(ū_k) − Q_k|²` through the normal equations `(NᵀN) P = Nᵀ R` (Eq. 9.66), solved by
//! Cholesky (NᵀN is symmetric positive definite when every span holds data).

use super::basis::bspline_basis;
use super::{KnotVector, MathError, NurbsCurve, Real, Vec3};
use nalgebra::{DMatrix, DVector};

/// The degree-`degree` curve with `count` control points closest to `points` at `params` (increasing, from
/// 0 to 1) in the least-squares sense, through the first and last point.
///
/// # Errors
/// [`MathError::InvalidCurve`] unless `degree < count ≤ points.len()` and there is one parameter per point;
/// [`MathError::Singular`] when the normal equations are singular.
pub fn approximate(
    points: &[Vec3],
    params: &[Real],
    degree: usize,
    count: usize,
) -> Result<NurbsCurve, MathError> {
    let m = points.len();
    if !(degree < count && count <= m) || params.len() != m {
        return Err(MathError::InvalidCurve {
            reason: format!(
                "least squares with {count} control points of degree {degree} needs more than {degree} and at most {m} points (and one parameter per point)"
            ),
        });
    }
    let n = count - 1;
    // Eq. 9.69: d = (m+1)/(n−p+1); u_{p+j} = (1−α) ū_{i−1} + α ū_i, i = ⌊jd⌋, α = jd − i.
    let d = m as Real / (n - degree + 1) as Real;
    let interior: Vec<Real> = (1..=n - degree)
        .map(|j| {
            let jd = j as Real * d;
            let i = (jd.floor() as usize).clamp(1, m - 1);
            let alpha = jd - i as Real;
            (1.0 - alpha) * params[i - 1] + alpha * params[i]
        })
        .collect();
    let knots = KnotVector::clamped_with_interior(degree, &interior)?;
    let (first, last) = (points[0], points[m - 1]);
    let mut control = vec![first; count];
    control[n] = last;
    if n >= 2 {
        let unknowns = n - 1;
        let mut normal = DMatrix::<Real>::zeros(unknowns, unknowns);
        let mut rhs = [
            DVector::<Real>::zeros(unknowns),
            DVector::<Real>::zeros(unknowns),
            DVector::<Real>::zeros(unknowns),
        ];
        for k in 1..m - 1 {
            let basis = bspline_basis(&knots, params[k], 0);
            let values = &basis.ders[0];
            let value_of = |j: usize| {
                j.checked_sub(basis.first)
                    .and_then(|i| values.get(i))
                    .copied()
                    .unwrap_or(0.0)
            };
            // R_k = Q_k − N_0 Q_0 − N_n Q_m (Eq. 9.63).
            let r = points[k] - value_of(0) * first - value_of(n) * last;
            for (a, &na) in values.iter().enumerate() {
                let ja = basis.first + a;
                if ja == 0 || ja == n {
                    continue;
                }
                for c in 0..3 {
                    rhs[c][ja - 1] += na * r[c];
                }
                for (b, &nb) in values.iter().enumerate() {
                    let jb = basis.first + b;
                    if jb != 0 && jb != n {
                        normal[(ja - 1, jb - 1)] += na * nb;
                    }
                }
            }
        }
        let cholesky = normal.cholesky().ok_or_else(|| MathError::Singular {
            context: format!(
                "least-squares fit with {count} control points: a knot span holds no data"
            ),
        })?;
        let solved: Vec<DVector<Real>> = rhs.iter().map(|b| cholesky.solve(b)).collect();
        for j in 1..n {
            control[j] = Vec3::new(solved[0][j - 1], solved[1][j - 1], solved[2][j - 1]);
        }
    }
    NurbsCurve::try_new(knots, control, vec![1.0; count])
}

/// Chord-length parameters of `points`, normalised to `[0, 1]` (Piegl–Tiller Eq. 9.5); `None` when two
/// consecutive points coincide.
pub fn chord_parameters(points: &[Vec3]) -> Option<Vec<Real>> {
    let mut params = vec![0.0];
    for w in points.windows(2) {
        let d = (w[1] - w[0]).norm();
        if !(d > 0.0) {
            return None;
        }
        params.push(params[params.len() - 1] + d);
    }
    let total = *params.last()?;
    Some(params.into_iter().map(|t| t / total).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Source: a cubic reproduces any cubic polynomial curve exactly; with fewer control points than data
    /// the least-squares fit of points on a cubic is that cubic (to round-off), ends included.
    #[test]
    fn points_on_a_cubic_are_fitted_exactly() {
        let curve = |t: Real| Vec3::new(t, t * t - 0.5 * t, 2.0 * t * t * t - t);
        let params: Vec<Real> = (0..40).map(|k| k as Real / 39.0).collect();
        let points: Vec<Vec3> = params.iter().map(|&t| curve(t)).collect();
        let fit = approximate(&points, &params, 3, 7).expect("fits");
        for (&t, p) in params.iter().zip(&points) {
            assert!((fit.point(t) - p).norm() < 1e-12, "{t}");
        }
        assert_eq!(fit.point(0.0), points[0]);
        assert_eq!(fit.point(1.0), points[39]);
    }
}
