//! Global spline interpolation (after Piegl–Tiller A9.1) with a prescribed knot vector at prescribed
//! parameters, by default the Greville abscissae, which makes the collocation matrix well conditioned
//! (Schoenberg–Whitney holds).
//!
//! The collocation matrix `A_ij = N_j(u_i)` of increasing sites is banded (a row touches only the `p + 1`
//! functions non-zero at its site) and totally positive, so Gaussian elimination *without pivoting* is
//! backward stable (de Boor & Pinkus, *Backward error analysis for totally positive linear systems*,
//! Numer. Math. 27, 1977) and keeps the band: `O(n p²)` work, as in de Boor's `SPLINT`/`BANFAC`.
//! [`Interpolator`] factors once and solves for any number of point sets.

use super::basis::{BasisTable, BasisWorkspace, bspline_basis_into};
use super::{KnotVector, MathError, NurbsCurve, Real, Vec3};

/// Smallest accepted pivot of the banded elimination, relative to the largest entry of its row (entries lie
/// in `[0, 1]`). With increasing sites that satisfy Schoenberg–Whitney every pivot is positive; a pivot below
/// this means the sites nearly violate the condition and the interpolant would be meaningless.
pub(crate) const MIN_RELATIVE_PIVOT: Real = 1e-14;

/// The factored collocation matrix of a knot vector at a set of sites (banded LU without pivoting, see the
/// module docs); [`Interpolator::curve`] then solves for the control points of any data.
#[derive(Debug, Clone)]
pub(crate) struct Interpolator {
    knots: KnotVector,
    /// Site order: `order[i]` is the index (in the caller's arrays) of the `i`-th smallest site.
    order: Vec<usize>,
    /// Band rows of the LU factors, `2p + 1` entries per row: entry `c − i + p` is column `c` of row `i`
    /// (U on and above the diagonal, the multipliers of L below it).
    band: Vec<Real>,
}

impl Interpolator {
    /// Builds and factors the collocation matrix `N_j(params[i])` (Piegl–Tiller Eq. 9.1 / A9.1, banded).
    ///
    /// Errors: [`MathError::InvalidCurve`] unless there is one parameter per basis function,
    /// [`MathError::OutOfDomain`] for a parameter outside the domain (or NaN), and [`MathError::Singular`] for
    /// repeated parameters or when the Schoenberg–Whitney condition `N_i(u_(i)) > 0` fails for the sorted
    /// sites `u_(i)` (the matrix is then singular).
    pub(crate) fn try_new(knots: KnotVector, params: &[Real]) -> Result<Self, MathError> {
        let n = knots.num_basis();
        let p = knots.degree();
        if params.len() != n {
            return Err(MathError::InvalidCurve {
                reason: format!(
                    "{} interpolation parameters for {n} basis functions",
                    params.len()
                ),
            });
        }
        let (lo, hi) = knots.domain();
        if let Some(&u) = params.iter().find(|&&u| !(u >= lo && u <= hi)) {
            return Err(MathError::OutOfDomain { u, lo, hi });
        }
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| params[a].total_cmp(&params[b]));
        if let Some(w) = order.windows(2).find(|w| params[w[0]] == params[w[1]]) {
            return Err(MathError::Singular {
                context: format!(
                    "interpolation: parameters {} and {} are equal ({})",
                    w[0], w[1], params[w[0]]
                ),
            });
        }

        // Assemble the band rows.
        let width = 2 * p + 1;
        let mut band = vec![0.0; n * width];
        let mut work = BasisWorkspace::new();
        let mut table = BasisTable::default();
        for (i, &idx) in order.iter().enumerate() {
            let u = params[idx];
            bspline_basis_into(&knots, u, 0, &mut work, &mut table);
            let first = table.first;
            let diagonal = i
                .checked_sub(first)
                .and_then(|j| table.ders[0].get(j))
                .copied();
            if !diagonal.is_some_and(|v| v > 0.0) {
                return Err(MathError::Singular {
                    context: format!(
                        "interpolation: Schoenberg–Whitney fails, basis function {i} vanishes at the {i}-th \
                         smallest parameter u = {u} (index {idx}); move the parameters towards the Greville \
                         abscissae"
                    ),
                });
            }
            // first ≤ i ≤ first + p, so the row's columns lie in [i − p, i + p].
            for (j, &v) in table.ders[0].iter().enumerate() {
                band[i * width + first + j + p - i] = v;
            }
        }

        // Banded LU without pivoting (totally positive matrix).
        for k in 0..n {
            let pivot = band[k * width + p];
            let row_max = band[k * width..(k + 1) * width]
                .iter()
                .fold(0.0, |m: Real, v| m.max(v.abs()));
            if pivot.is_nan() || pivot <= MIN_RELATIVE_PIVOT * row_max {
                return Err(MathError::Singular {
                    context: format!(
                        "interpolation: pivot {pivot:e} at row {k} (parameters nearly violate \
                         Schoenberg–Whitney)"
                    ),
                });
            }
            for r in k + 1..(k + p + 1).min(n) {
                // Entry (r, k) sits at offset k − r + p.
                let off = k + p - r;
                let factor = band[r * width + off] / pivot;
                if factor == 0.0 {
                    continue;
                }
                band[r * width + off] = factor;
                for c in k + 1..(k + p + 1).min(n) {
                    band[r * width + c + p - r] -= factor * band[k * width + c + p - k];
                }
            }
        }
        Ok(Self { knots, order, band })
    }

    /// The B-spline curve through `points[i]` at the `i`-th parameter given to [`Interpolator::try_new`]
    /// (forward and back substitution with the banded factors).
    pub(crate) fn curve(&self, points: &[Vec3]) -> Result<NurbsCurve, MathError> {
        let n = self.knots.num_basis();
        let p = self.knots.degree();
        let width = 2 * p + 1;
        if points.len() != n {
            return Err(MathError::InvalidCurve {
                reason: format!(
                    "{} points to interpolate for {n} basis functions",
                    points.len()
                ),
            });
        }
        let mut x: Vec<Vec3> = self.order.iter().map(|&i| points[i]).collect();
        for r in 0..n {
            let row = &self.band[r * width..(r + 1) * width];
            let mut v = x[r];
            for c in r.saturating_sub(p)..r {
                v -= x[c] * row[c + p - r];
            }
            x[r] = v;
        }
        for r in (0..n).rev() {
            let row = &self.band[r * width..(r + 1) * width];
            let mut v = x[r];
            for c in r + 1..(r + p + 1).min(n) {
                v -= x[c] * row[c + p - r];
            }
            x[r] = v / row[p];
        }
        NurbsCurve::try_bspline(self.knots.clone(), x)
    }
}

/// The B-spline curve with knot vector `knots` that passes through `points[i]` at `params[i]`.
/// Fails unless there is one point per basis function and the system is regular.
///
/// Global interpolation after Piegl–Tiller A9.1 with the caller's knots and parameters, solved by the banded
/// LU of [`Interpolator`]; errors as for [`Interpolator::try_new`].
pub(crate) fn interpolate(
    knots: KnotVector,
    params: &[Real],
    points: &[Vec3],
) -> Result<NurbsCurve, MathError> {
    Interpolator::try_new(knots, params)?.curve(points)
}

/// The B-spline curve with knot vector `knots` that passes through `points[i]` at the Greville abscissae.
#[cfg(test)]
fn interpolate_at_greville(knots: KnotVector, points: &[Vec3]) -> Result<NurbsCurve, MathError> {
    let params = knots.greville();
    interpolate(knots, &params, points)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::basis::tests::{config, knot_strategy, knot_vector};
    use proptest::prelude::*;

    /// `Σ_k a_k ((u − mid)/len)^k` by Horner, coefficient triples `a_k` taken from `coef`.
    fn polynomial(coef: &[Real], degree: usize, u: Real, mid: Real, len: Real) -> Vec3 {
        let x = (u - mid) / len;
        (0..=degree).rev().fold(Vec3::zeros(), |acc, k| {
            acc * x + Vec3::new(coef[3 * k], coef[3 * k + 1], coef[3 * k + 2])
        })
    }

    proptest! {
        #![proptest_config(config(300))]

        // Checks polynomial reproduction: any polynomial curve of degree q ≤ p lies in the
        // spline space, so interpolating its values at the Greville points must reproduce it everywhere (the
        // reference is the polynomial itself, evaluated by Horner). The error is the backward error ε times
        // the ∞-norm condition of the Greville collocation matrix, which for these random knots (spans
        // len/32 … len, p ≤ 8) stays below ~10²: tolerance 1e-12·max|c| at 201 parameters.
        #[test]
        fn reproduces_polynomials_at_greville(
            (p, raw, lo, len) in knot_strategy(),
            q in 0usize..=8,
            coef in proptest::collection::vec(-1.0..1.0f64, 27),
        ) {
            let q = q.min(p);
            let kv = knot_vector(p, &raw, lo, len);
            let mid = lo + 0.5 * len;
            let g = kv.greville();
            let pts: Vec<Vec3> = g.iter().map(|&u| polynomial(&coef, q, u, mid, len)).collect();
            let c = interpolate_at_greville(kv, &pts).unwrap();
            let scale = coef.iter().fold(1.0, |m: Real, v| m.max(v.abs())) * (q + 1) as Real;
            for i in 0..=200 {
                let u = lo + len * i as Real / 200.0;
                let err = (c.point(u) - polynomial(&coef, q, u, mid, len)).norm();
                prop_assert!(err <= 1e-12 * scale, "u={} err={}", u, err);
            }
        }

        // Checks the interpolation conditions themselves for random data at shuffled, non-Greville parameters
        // (Greville points moved by up to 30 % of their gap, then reversed): c(params[i]) = points[i]. The
        // reference is the data; tolerance 1e-12 for O(1) points (conditioning as above, a little worse off
        // the Greville points).
        #[test]
        fn passes_through_data_at_shuffled_parameters(
            (p, raw, lo, len) in knot_strategy(),
            shift in proptest::collection::vec(-0.3..0.3f64, 96),
            coords in proptest::collection::vec(-1.0..1.0f64, 3 * 96),
        ) {
            let kv = knot_vector(p, &raw, lo, len);
            let g = kv.greville();
            let n = g.len();
            let mut params: Vec<Real> = (0..n).map(|i| {
                if i == 0 || i == n - 1 { g[i] } else {
                    let gap = if shift[i] > 0.0 { g[i + 1] - g[i] } else { g[i] - g[i - 1] };
                    g[i] + shift[i] * gap
                }
            }).collect();
            params.reverse();
            let pts: Vec<Vec3> = (0..n).map(|j| Vec3::new(coords[3 * j], coords[3 * j + 1], coords[3 * j + 2])).collect();
            match interpolate(kv, &params, &pts) {
                Ok(c) => {
                    for (u, x) in params.iter().zip(&pts) {
                        prop_assert!((c.point(*u) - x).norm() < 1e-12);
                    }
                }
                // Moving a site off its Greville point may break Schoenberg–Whitney; that must be an error,
                // never a panic or a wrong curve.
                Err(MathError::Singular { .. }) => {}
                Err(e) => prop_assert!(false, "unexpected error {e}"),
            }
        }
    }

    // Checks the errors (no panics): wrong counts, NaN or out-of-domain parameters, repeated parameters, and a
    // Schoenberg–Whitney failure (all sites of a p = 2, n = 5 space in the first span, so N_3 and N_4 vanish
    // at the sites they are paired with). Exact checks.
    #[test]
    fn singular_and_invalid_inputs_are_errors() {
        let kv = KnotVector::clamped_uniform(2, 5).unwrap();
        let pts = vec![Vec3::zeros(); 5];
        assert!(matches!(
            interpolate(kv.clone(), &[0.0; 4], &pts),
            Err(MathError::InvalidCurve { .. })
        ));
        assert!(matches!(
            interpolate(kv.clone(), &[0.0, 0.2, 0.5, 0.8, 1.0], &pts[..4]),
            Err(MathError::InvalidCurve { .. })
        ));
        assert!(matches!(
            interpolate(kv.clone(), &[0.0, 0.2, Real::NAN, 0.8, 1.0], &pts),
            Err(MathError::OutOfDomain { .. })
        ));
        assert!(matches!(
            interpolate(kv.clone(), &[0.0, 0.2, 0.5, 0.8, 1.5], &pts),
            Err(MathError::OutOfDomain { .. })
        ));
        assert!(matches!(
            interpolate(kv.clone(), &[0.0, 0.2, 0.2, 0.8, 1.0], &pts),
            Err(MathError::Singular { .. })
        ));
        let err = interpolate(kv.clone(), &[0.0, 0.05, 0.1, 0.15, 0.2], &pts).unwrap_err();
        assert!(err.to_string().contains("Schoenberg–Whitney"), "{err}");
        assert!(interpolate_at_greville(kv, &pts).is_ok());
    }

    // Checks a hand-computed case: p = 1 interpolation is the polyline through the data, so the control
    // points equal the data at the Greville points (= the knots). Exact up to rounding of O(1) values.
    #[test]
    fn linear_interpolation_is_the_polyline() {
        let kv = KnotVector::clamped_with_interior(1, &[0.25, 0.5]).unwrap();
        let pts = vec![
            Vec3::new(0.0, 1.0, 2.0),
            Vec3::new(1.0, -1.0, 0.5),
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::x(),
        ];
        let c = interpolate_at_greville(kv, &pts).unwrap();
        for (a, b) in c.points().iter().zip(&pts) {
            assert!((a - b).norm() < 1e-15);
        }
        assert!((c.point(0.125) - (pts[0] + pts[1]) / 2.0).norm() < 1e-15);
    }
}
