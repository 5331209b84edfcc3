//! The measures the studies share: the relative error of a sampled vector field against a reference, and the
//! least-squares slope of a log–log relation (an observed order of convergence, a growth exponent of a cost).

use crate::math::{Real, Vec3};

/// `‖a − b‖ / ‖b‖` over a grid of vectors (the discrete 2-norm of the paper's convergence study, Fig.
/// conv_circ: `err = ‖u_ref − u_h‖ / ‖u_ref‖`).
pub fn relative_error(a: &[Vec3], b: &[Vec3]) -> Real {
    let num: Real = a.iter().zip(b).map(|(x, y)| (x - y).norm_squared()).sum();
    let den: Real = b.iter().map(|y| y.norm_squared()).sum();
    (num / den).sqrt()
}

/// Least-squares slope of `log y` against `log x` over the points with `x, y > 0` and finite: the observed
/// order of an error `y ≈ C x^q` or the growth exponent of a cost. `None` with fewer than two such points or
/// no spread in `x`.
///
/// The slope of the ordinary least-squares line, `q = Σ (X − X̄)(Y − Ȳ) / Σ (X − X̄)²` with `X = ln x`,
/// `Y = ln y`.
pub fn fit_log_slope(points: &[(Real, Real)]) -> Option<Real> {
    let logs: Vec<(Real, Real)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if logs.len() < 2 {
        return None;
    }
    let n = logs.len() as Real;
    let (mx, my) = logs
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxx: Real = logs.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    let sxy: Real = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

#[cfg(test)]
mod tests {
    use super::*;

    // y = 3 x² exactly on four points gives slope 2 to round-off; the unusable points (zero, negative, NaN)
    // are skipped, and one usable point or no spread in x gives no slope.
    #[test]
    fn slope_of_a_power_law() {
        let mut points: Vec<(Real, Real)> = [0.5, 1.0, 2.0, 4.0]
            .iter()
            .map(|&x| (x, 3.0 * x * x))
            .collect();
        points.extend([(0.0, 1.0), (1.0, -1.0), (Real::NAN, 1.0)]);
        let q = fit_log_slope(&points).expect("a slope");
        assert!((q - 2.0).abs() < 1e-12, "{q}");
        assert_eq!(fit_log_slope(&[(1.0, 2.0)]), None);
        assert_eq!(fit_log_slope(&[(2.0, 1.0), (2.0, 3.0)]), None);
    }

    // |(1, 0, 0) − (2, 0, 0)| / |(2, 0, 0)| = 1/2 on a one-point grid.
    #[test]
    fn relative_error_by_hand() {
        let e = relative_error(&[Vec3::new(1.0, 0.0, 0.0)], &[Vec3::new(2.0, 0.0, 0.0)]);
        assert!((e - 0.5).abs() < 1e-15);
    }
}
