//! Least-squares spline approximation of points with the end points kept (Piegl–Tiller §9.4.1, Eqs. 9.63–9.69,
//! A9.7 without weights): for data `Q_0 … Q_m` at chord-length parameters `ū_k` and `n + 1` control points, the
//! knots are placed by Eq. 9.69 (every knot span holds data), `P_0 = Q_0`, `P_n = Q_m`, and the interior control
//! points minimise `Σ_k |C(ū_k) − Q_k|²` through the normal equations `(NᵀN) P = Nᵀ R` (Eq. 9.66).
//!
//! `NᵀN` is banded: a data point touches the `p + 1` basis functions non-zero at its parameter, so entry
//! `(i, j)` vanishes for `|i − j| > p`. It is assembled and factored by Cholesky in that band (`p + 1` entries a
//! row; de Boor's `BCHFAC`/`BCHSLV`, *A Practical Guide to Splines*, XIV): `O(m p² + n p²)` work and `O(n p)`
//! memory. (A dense matrix cost `O(n³)`: 10 000 control points took 167 s and 791 MB.)
use super::basis::{BasisTable, BasisWorkspace, bspline_basis_into};
use super::{KnotVector, MathError, NurbsCurve, Real, Vec3};

/// Smallest accepted pivot of the banded Cholesky factorisation, relative to the diagonal entry of `NᵀN` it
/// comes from. When every knot span holds data the pivots are positive; one that has lost all but 10⁻¹² of its
/// diagonal means a control point the data barely determine (spans of nearly one point each, the fit close to
/// interpolating noise): its value would carry round-off amplified 10¹², so the system is reported singular.
pub(crate) const MIN_RELATIVE_PIVOT: Real = 1e-12;

/// The degree-`degree` curve with `count` control points closest to `points` at `params` (increasing, from
/// 0 to 1) in the least-squares sense, through the first and last point.
///
/// # Errors
/// [`MathError::InvalidCurve`] unless `degree < count ≤ points.len()` and there is one parameter per point;
/// [`MathError::Singular`] when the normal equations are singular.
pub(crate) fn approximate(
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
    let last = points[m - 1];
    let mut control = vec![points[0]; count];
    control[n] = last;
    if n >= 2 {
        let unknowns = n - 1;
        let p = degree;
        // Lower band of NᵀN: row i holds columns i − p … i at [i (p + 1) + (j + p − i)].
        let width = p + 1;
        let mut band = vec![0.0; unknowns * width];
        let mut rhs = vec![Vec3::zeros(); unknowns];
        let (mut work, mut table) = (BasisWorkspace::new(), BasisTable::default());
        for k in 1..m - 1 {
            bspline_basis_into(&knots, params[k], 0, &mut work, &mut table);
            let values = &table.ders[0];
            let first = table.first;
            let value_of = |j: usize| {
                j.checked_sub(first)
                    .and_then(|i| values.get(i))
                    .copied()
                    .unwrap_or(0.0)
            };
            // R_k = Q_k − N_0 Q_0 − N_n Q_m (Eq. 9.63).
            let r = points[k] - value_of(0) * points[0] - value_of(n) * last;
            for (a, &na) in values.iter().enumerate() {
                let ja = first + a;
                if ja == 0 || ja == n {
                    continue;
                }
                rhs[ja - 1] += na * r;
                for (b, &nb) in values.iter().enumerate().take(a + 1) {
                    let jb = first + b;
                    if jb != 0 && jb != n {
                        band[(ja - 1) * width + (jb - 1) + p - (ja - 1)] += na * nb;
                    }
                }
            }
        }
        band_cholesky(&mut band, unknowns, p).map_err(|row| MathError::Singular {
            context: format!(
                "least-squares fit with {count} control points: control point {} of {count} is not determined by the data (pivot below {MIN_RELATIVE_PIVOT:e} of its diagonal)",
                row + 1
            ),
        })?;
        band_cholesky_solve(&band, unknowns, p, &mut rhs);
        control[1..n].copy_from_slice(&rhs);
    }
    NurbsCurve::try_new(knots, control, vec![1.0; count])
}

/// Cholesky factorisation `A = L Lᵀ` in place of the lower band of the symmetric positive definite `A`
/// (`size` rows, half-bandwidth `p`, layout of [`approximate`]); `Err(row)` at the first pivot below
/// [`MIN_RELATIVE_PIVOT`] of its diagonal entry.
fn band_cholesky(band: &mut [Real], size: usize, p: usize) -> Result<(), usize> {
    let width = p + 1;
    let at = |i: usize, j: usize| i * width + j + p - i;
    for i in 0..size {
        for j in i.saturating_sub(p)..=i {
            let mut sum = band[at(i, j)];
            for k in i.saturating_sub(p).max(j.saturating_sub(p))..j {
                sum -= band[at(i, k)] * band[at(j, k)];
            }
            if j == i {
                let diagonal = band[at(i, i)];
                if !(sum > MIN_RELATIVE_PIVOT * diagonal) {
                    return Err(i);
                }
                band[at(i, i)] = sum.sqrt();
            } else {
                band[at(i, j)] = sum / band[at(j, j)];
            }
        }
    }
    Ok(())
}

/// Solves `L Lᵀ x = b` in place of `b` with the factor of [`band_cholesky`].
fn band_cholesky_solve(band: &[Real], size: usize, p: usize, b: &mut [Vec3]) {
    let width = p + 1;
    let at = |i: usize, j: usize| i * width + j + p - i;
    for i in 0..size {
        let mut sum = b[i];
        for k in i.saturating_sub(p)..i {
            sum -= band[at(i, k)] * b[k];
        }
        b[i] = sum / band[at(i, i)];
    }
    for i in (0..size).rev() {
        let mut sum = b[i];
        for k in i + 1..(i + width).min(size) {
            sum -= band[at(k, i)] * b[k];
        }
        b[i] = sum / band[at(i, i)];
    }
}

/// Chord-length parameters of `points`, normalised to `[0, 1]` (Piegl–Tiller Eq. 9.5); `None` when two
/// consecutive points coincide.
pub(crate) fn chord_parameters(points: &[Vec3]) -> Option<Vec<Real>> {
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
    use crate::math::basis::bspline_basis;

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

    /// Source: the normal equations of Piegl–Tiller Eq. 9.66 assembled as a dense matrix from
    /// [`crate::math::basis::bspline_basis`] and solved by nalgebra's dense LU — not the banded Cholesky under
    /// test — on 300 points of a helix moved by a deterministic wiggle (so no curve fits them exactly), with 40
    /// and 200 control points. The two solutions agree to round-off of a system whose condition number is
    /// about 10⁴–10⁶: 1e-9 of the coordinates' size (3).
    #[test]
    fn the_banded_solve_agrees_with_dense_normal_equations() {
        use nalgebra::{DMatrix, DVector};
        let points: Vec<Vec3> = (0..300)
            .map(|k| {
                let t = k as Real / 299.0 * 12.0;
                Vec3::new(3.0 * t.cos(), 3.0 * t.sin(), 0.5 * t)
                    + Vec3::new(1.0, -0.5, 0.7) * (0.01 * (37.0 * k as Real).sin())
            })
            .collect();
        let params = chord_parameters(&points).expect("distinct points");
        for count in [40, 200] {
            let fit = approximate(&points, &params, 3, count).expect("fits");
            let n = count - 1;
            let knots = fit.knots().clone();
            let mut normal = DMatrix::<Real>::zeros(n - 1, n - 1);
            let mut rhs = DMatrix::<Real>::zeros(n - 1, 3);
            for k in 1..points.len() - 1 {
                let basis = bspline_basis(&knots, params[k], 0);
                let full: Vec<Real> = (0..=n)
                    .map(|j| {
                        j.checked_sub(basis.first)
                            .and_then(|i| basis.ders[0].get(i))
                            .copied()
                            .unwrap_or(0.0)
                    })
                    .collect();
                let r = points[k] - full[0] * points[0] - full[n] * points[points.len() - 1];
                for a in 1..n {
                    for c in 0..3 {
                        rhs[(a - 1, c)] += full[a] * r[c];
                    }
                    for b in 1..n {
                        normal[(a - 1, b - 1)] += full[a] * full[b];
                    }
                }
            }
            let lu = normal.lu();
            for c in 0..3 {
                let column: DVector<Real> = rhs.column(c).into_owned();
                let solved = lu.solve(&column).expect("non-singular");
                for j in 1..n {
                    let got = fit.points()[j][c];
                    assert!(
                        (got - solved[j - 1]).abs() < 1e-9 * 3.0,
                        "{count} control points, P{j}[{c}]: {got} vs {}",
                        solved[j - 1]
                    );
                }
            }
        }
    }
}
