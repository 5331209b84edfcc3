//! Spline fits of analytic curves (DESIGN §5): the degree-`p` B-spline with `n` control points on a clamped
//! uniform knot vector that interpolates the curve at the Greville abscissae, parametrised by normalised arc
//! length (`u = s / L`), so the parametric speed of the fit is nearly constant — what collocation wants.
//! The largest deviation from the analytic curve is measured and reported.

use super::analytic::{ArcLengthTable, ParametricCurve};
use super::{GeometryError, Parameter};
use crate::math::{KnotVector, NurbsCurve, Real, Vec3, interp};

/// Settings of a fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSettings {
    /// Panels of the arc-length table of the analytic curve (see [`ArcLengthTable`]).
    pub arc_length_panels: usize,
    /// Sample points per knot span where the deviation is measured.
    pub samples_per_span: usize,
}

impl Default for FitSettings {
    /// 512 panels (arc length to round-off for crown wires and helices of a few turns) and 16 samples per
    /// span (the interpolation error of a smooth curve peaks once per span; 16 samples find its maximum to a
    /// few per cent).
    fn default() -> Self {
        Self {
            arc_length_panels: 512,
            samples_per_span: 16,
        }
    }
}

/// A fitted spline and how far it is from the curve it stands for.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// The analysis spline, `u ∈ [0, 1]`.
    pub curve: NurbsCurve,
    /// Largest distance between the fit and the analytic curve at equal arc-length parameter over the sample
    /// points (an upper bound of the geometric distance there) \[length\].
    pub max_deviation: Real,
    /// Length of the analytic curve \[length\].
    pub length: Real,
}

/// Fits `curve` by the degree-`degree` spline with `n` control points interpolating it at the Greville
/// abscissae of the clamped uniform knot vector, parametrised by normalised arc length.
pub fn fit_curve(
    curve: &dyn ParametricCurve,
    degree: usize,
    n: usize,
    settings: &FitSettings,
) -> Result<Fit, GeometryError> {
    let knots = KnotVector::clamped_uniform(degree, n)?;
    let table = ArcLengthTable::new(curve, settings.arc_length_panels);
    let length = table.length();
    if !(length > 0.0) || !length.is_finite() {
        return Err(GeometryError::InvalidParameter {
            what: Parameter::Curve,
            reason: format!("its length is {length}; it must be positive and finite"),
        });
    }
    let on_curve = |u: Real| curve.point(table.parameter_at(curve, u * length));
    let params = knots.greville();
    let points: Vec<_> = params.iter().map(|&u| on_curve(u)).collect();
    if let Some(k) = points.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
        return Err(GeometryError::InvalidParameter {
            what: Parameter::Curve,
            reason: format!("its point at u = {} is not finite", params[k]),
        });
    }
    let spline = interp::interpolate(knots, &params, &points)?;
    let breaks = spline.knots().breakpoints();
    let m = settings.samples_per_span.max(1);
    let mut max_deviation: Real = 0.0;
    for w in breaks.windows(2) {
        for k in 1..=m {
            let u = w[0] + (w[1] - w[0]) * (k as Real - 0.5) / m as Real;
            max_deviation = max_deviation.max((spline.point(u) - on_curve(u)).norm());
        }
    }
    Ok(Fit {
        curve: spline,
        max_deviation,
        length,
    })
}

/// The rigid motion `x ↦ R x + t` that best maps the points `from` onto `to` in the weighted least-squares
/// sense, `min Σ w_i |R from_i + t − to_i|²` (Kabsch's algorithm: SVD of the weighted cross-covariance, with the
/// sign correction that keeps `det R = +1`; W. Kabsch, Acta Cryst. A32 (1976) 922). `None` when the weights do
/// not sum to a positive number or the slices differ in length.
pub fn best_fit_rigid(
    from: &[Vec3],
    to: &[Vec3],
    weights: &[Real],
) -> Option<(crate::math::Mat3, Vec3)> {
    use crate::math::{Mat3, Vec3};
    if from.len() != to.len() || from.len() != weights.len() {
        return None;
    }
    let total: Real = weights.iter().sum();
    if !(total > 0.0) {
        return None;
    }
    let cf = from.iter().zip(weights).map(|(p, w)| p * *w).sum::<Vec3>() / total;
    let ct = to.iter().zip(weights).map(|(p, w)| p * *w).sum::<Vec3>() / total;
    let h: Mat3 = from
        .iter()
        .zip(to)
        .zip(weights)
        .map(|((f, t), w)| (f - cf) * (t - ct).transpose() * *w)
        .sum();
    let svd = h.svd(true, true);
    let (u, v_t) = (svd.u?, svd.v_t?);
    let v = v_t.transpose();
    let d = (v * u.transpose()).determinant().signum();
    let r = v * Mat3::from_diagonal(&Vec3::new(1.0, 1.0, d)) * u.transpose();
    Some((r, ct - r * cf))
}

#[cfg(test)]
mod tests {
    //! The fits of the helix and the crown wire against independent measurements of their distance from the
    //! analytic curves, their convergence rate, and the arc-length parametrisation.

    use super::*;
    use crate::geometry::analytic::{Helix, RigidPlacement, SineWire};
    use crate::math::Vec3;
    use std::f64::consts::TAU;

    /// Helix, r = 1.5, pitch 2, 1.5 turns; its arc length is `s = t √(r² + c²)`, `c = pitch/2π`, so the point at
    /// normalised arc length `u` is `c(u · 3π)` in closed form.
    fn helix() -> Helix {
        Helix {
            radius: 1.5,
            pitch: 2.0,
            turns: 1.5,
            start_angle: 0.3,
            placement: RigidPlacement::identity(),
        }
    }

    /// Two waves of a crown wire, R = 1.5, h = 0.3, 6 waves per turn (curvature up to 4.8).
    fn crown_wire() -> SineWire {
        SineWire {
            radius: 1.5,
            amplitude: 0.3,
            waves: 6.0,
            phase: 0.0,
            from: 0.0,
            to: 2.0 * TAU / 6.0,
            placement: RigidPlacement::identity(),
        }
    }

    /// An independent arc-length inverse: cumulative Simpson's rule on `panels` panels of the parameter
    /// (error `O(panel⁴)`, ~10⁻¹⁶ here), inverted by linear interpolation (error ≤ Δt²|t''|/8 ≈ 10⁻¹² for
    /// 2·10⁵ panels). Not the code under test ([`ArcLengthTable`], Gauss–Legendre and Newton).
    struct SimpsonArcLength {
        params: Vec<Real>,
        lengths: Vec<Real>,
    }

    impl SimpsonArcLength {
        fn new(curve: &dyn ParametricCurve, panels: usize) -> Self {
            let (t0, t1) = curve.domain();
            let dt = (t1 - t0) / panels as Real;
            let speed = |t: Real| curve.derivative(t).norm();
            let mut params = vec![t0];
            let mut lengths = vec![0.0];
            for k in 0..panels {
                let a = t0 + dt * k as Real;
                let b = a + dt;
                let s = lengths[k] + dt / 6.0 * (speed(a) + 4.0 * speed(0.5 * (a + b)) + speed(b));
                params.push(b);
                lengths.push(s);
            }
            Self { params, lengths }
        }

        fn length(&self) -> Real {
            self.lengths[self.lengths.len() - 1]
        }

        fn parameter_at(&self, s: Real) -> Real {
            let k = self
                .lengths
                .partition_point(|&l| l <= s)
                .clamp(1, self.lengths.len() - 1);
            let (la, lb) = (self.lengths[k - 1], self.lengths[k]);
            let (ta, tb) = (self.params[k - 1], self.params[k]);
            ta + (tb - ta) * (s - la) / (lb - la)
        }
    }

    /// The geometric distance from `x` to `curve`: the nearest of the dense samples `table` (`(t, c(t))`) within
    /// `±WINDOW` entries of `guess`, refined by golden-section search on the neighbouring parameter interval.
    /// The window spans ±50 table spacings, far more than the distance of a fit from its curve.
    fn closest_distance(
        curve: &dyn ParametricCurve,
        table: &[(Real, Vec3)],
        guess: usize,
        x: &Vec3,
    ) -> Real {
        const WINDOW: usize = 50;
        let range = guess.saturating_sub(WINDOW)..(guess + WINDOW + 1).min(table.len());
        let nearest = range
            .min_by(|&a, &b| (table[a].1 - x).norm().total_cmp(&(table[b].1 - x).norm()))
            .unwrap();
        let (mut a, mut b) = (
            table[nearest.saturating_sub(1)].0,
            table[(nearest + 1).min(table.len() - 1)].0,
        );
        let golden = (5f64.sqrt() - 1.0) / 2.0;
        let f = |t: Real| (curve.point(t) - x).norm();
        for _ in 0..80 {
            let (c, d) = (b - golden * (b - a), a + golden * (b - a));
            if f(c) < f(d) {
                b = d;
            } else {
                a = c;
            }
        }
        f(0.5 * (a + b))
    }

    /// Dense measurements of a fit over `count + 1` uniform parameters: (largest distance at equal arc-length
    /// parameter, largest closest-point distance, largest `|J/L − 1|`).
    fn dense_measurements(
        curve: &dyn ParametricCurve,
        fit: &Fit,
        count: usize,
    ) -> (Real, Real, Real) {
        let arc = SimpsonArcLength::new(curve, 200_000);
        let (t0, t1) = curve.domain();
        let table: Vec<(Real, Vec3)> = (0..=20_000)
            .map(|k| t0 + (t1 - t0) * k as Real / 20_000.0)
            .map(|t| (t, curve.point(t)))
            .collect();
        let (mut equal, mut closest, mut speed): (Real, Real, Real) = (0.0, 0.0, 0.0);
        for k in 0..=count {
            let u = k as Real / count as Real;
            let x = fit.curve.point(u);
            let t = arc.parameter_at(u * arc.length());
            equal = equal.max((x - curve.point(t)).norm());
            let guess = ((t - t0) / (t1 - t0) * 20_000.0).round() as usize;
            closest = closest.max(closest_distance(curve, &table, guess, &x));
            speed = speed.max((fit.curve.derivatives(u, 1)[1].norm() / arc.length() - 1.0).abs());
        }
        (equal, closest, speed)
    }

    /// The slope `log(e_n / e_2n) / log(h_n / h_2n)`, `h = 1/(n − p)`, of the reported fit error.
    fn measured_order(curve: &dyn ParametricCurve, p: usize, n: usize) -> Real {
        let coarse = fit_curve(curve, p, n, &FitSettings::default()).unwrap();
        let fine = fit_curve(curve, p, 2 * n, &FitSettings::default()).unwrap();
        let h_ratio = (2 * n - p) as Real / (n - p) as Real;
        let slope = (coarse.max_deviation / fine.max_deviation).ln() / h_ratio.ln();
        println!(
            "p = {p}: e({n}) = {:.3e}, e({}) = {:.3e}, slope {slope:.3}",
            coarse.max_deviation,
            2 * n,
            fine.max_deviation
        );
        slope
    }

    #[test]
    fn fit_error_converges_at_order_p_plus_one() {
        // Interpolation by degree-p splines at the Greville points of a uniform knot vector has error
        // O(h^{p+1}), h = 1/(n − p) (de Boor, A Practical Guide to Splines, XII). The measured slope must be
        // within 10 % of p + 1 in the asymptotic range.
        // * Helix (n = 48 → 96): measured 4.01, 5.01, 6.02, 7.07 for p = 3 … 6.
        // * Crown wire: its k-th derivative grows like (6 waves/turn)^k, so at moderate n the higher-order
        //   terms dominate and the error falls *faster* than h^{p+1} (n = 96 → 192: 4.30, 6.17, 7.37, 9.29);
        //   the slope reaches p + 1 from above (n = 384 → 768: 4.02, 5.09, 6.09). p = 6 is at round-off there
        //   (e ≈ 7e-15), so only the pre-asymptotic bound applies to it.
        for p in 3..=6 {
            let slope = measured_order(&helix(), p, 48);
            assert!(
                (slope / (p + 1) as Real - 1.0).abs() < 0.1,
                "helix p = {p}: slope {slope}"
            );
            let slope = measured_order(&crown_wire(), p, 96);
            assert!(
                slope > 0.9 * (p + 1) as Real,
                "crown wire p = {p}: slope {slope}"
            );
        }
        for p in 3..=5 {
            let slope = measured_order(&crown_wire(), p, 384);
            assert!(
                (slope / (p + 1) as Real - 1.0).abs() < 0.1,
                "crown wire p = {p}: slope {slope}"
            );
        }
    }

    #[test]
    fn reported_deviation_agrees_with_dense_independent_measurements() {
        // References, over 4001 parameters (250 per knot span or more):
        // * the distance at equal arc-length parameter, with the arc length from `SimpsonArcLength` (for the
        //   helix also exact): the reported maximum samples the same function 16 times per span, so it must
        //   agree within 5 % (a smooth error peak sampled at 16 points is found to ~2 %);
        // * the geometric (closest-point) distance, which cannot exceed the equal-parameter one: the reported
        //   value is an upper bound of it up to the same 5 %. (For even p it is up to 5× smaller: there the
        //   interpolation error is largely along the curve.)
        // * the parametric speed: for an arc-length fit J = L(1 + O(h^p)); the estimate (p+1)(n−p)e/L of the
        //   derivative of the interpolation error, with a factor 3 margin.
        for p in [3, 4, 6] {
            for (name, curve, n) in [
                ("helix", &helix() as &dyn ParametricCurve, 48),
                ("crown wire", &crown_wire(), 96),
            ] {
                let fit = fit_curve(curve, p, n, &FitSettings::default()).unwrap();
                let (equal, closest, speed) = dense_measurements(curve, &fit, 4000);
                let e = fit.max_deviation;
                println!(
                    "{name} p = {p}, n = {n}: reported {e:.3e}, dense equal-parameter {equal:.3e}, \
                     closest-point {closest:.3e}, max |J/L − 1| {speed:.2e}"
                );
                assert!(
                    (e / equal - 1.0).abs() < 0.05,
                    "{name} p = {p}: {e:e} vs {equal:e}"
                );
                assert!(closest <= 1.05 * e, "{name} p = {p}: {closest:e} vs {e:e}");
                let speed_estimate = (p + 1) as Real * (n - p) as Real * e / fit.length;
                assert!(
                    speed < 3.0 * speed_estimate,
                    "{name} p = {p}: {speed:e} vs {speed_estimate:e}"
                );
            }
        }
        // The helix's arc length is linear in its parameter: the exact equal-parameter check.
        let h = helix();
        let fit = fit_curve(&h, 5, 48, &FitSettings::default()).unwrap();
        let t_end = h.domain().1;
        let exact = (0..=4000)
            .map(|k| k as Real / 4000.0)
            .map(|u| (fit.curve.point(u) - h.point(u * t_end)).norm())
            .fold(0.0, Real::max);
        assert!(
            (fit.max_deviation / exact - 1.0).abs() < 0.05,
            "{} vs {exact}",
            fit.max_deviation
        );
        let length = t_end * (h.radius.powi(2) + (h.pitch / TAU).powi(2)).sqrt();
        assert!((fit.length / length - 1.0).abs() < 1e-13);
    }

    #[test]
    fn fit_interpolates_the_curve_at_the_greville_points() {
        // By construction the fit passes through the analytic curve at its Greville abscissae (arc-length
        // parameters); the helix gives the points in closed form. Round-off of the banded solve and of the
        // arc-length inversion: ~1e-14 on coordinates of size 1.5; asserted 1e-12.
        let h = helix();
        let fit = fit_curve(&h, 4, 20, &FitSettings::default()).unwrap();
        let t_end = h.domain().1;
        for u in fit.curve.knots().greville() {
            assert!((fit.curve.point(u) - h.point(u * t_end)).norm() < 1e-12);
        }
        assert_eq!((fit.curve.degree(), fit.curve.num_points()), (4, 20));
        assert_eq!(fit.curve.knots().domain(), (0.0, 1.0));
    }

    // Reference: a known rigid motion (rotation of 0.7 rad about a tilted axis and a translation) applied to a
    // scattered point set is recovered exactly by Kabsch's algorithm (an exact fit has zero residual, so the
    // answer is unique); round-off only: 1e-12.
    #[test]
    fn best_fit_rigid_recovers_a_known_motion() {
        use crate::math::{Vec3, so3};
        let r = *so3::exp(&(Vec3::new(0.3, -0.5, 0.8).normalize() * 0.7)).matrix();
        let t = Vec3::new(1.5, -2.0, 0.25);
        let from: Vec<Vec3> = (0..9)
            .map(|k| Vec3::new((k as Real).sin(), (1.3 * k as Real).cos(), 0.2 * k as Real))
            .collect();
        let to: Vec<Vec3> = from.iter().map(|p| r * p + t).collect();
        let weights: Vec<Real> = (0..9).map(|k| 1.0 + k as Real).collect();
        let (rf, tf) = best_fit_rigid(&from, &to, &weights).expect("fit");
        assert!((rf - r).abs().max() < 1e-12);
        assert!((tf - t).norm() < 1e-12);
        assert!(best_fit_rigid(&from, &to, &[0.0; 9]).is_none());
    }
}

/// A smooth spline through noisy data and how far it strays from it.
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothFit {
    /// The cubic, `u ∈ [0, 1]` by chord length of the data.
    pub curve: NurbsCurve,
    /// Largest distance from a data point to the curve at its parameter \[length\] (an upper bound of the
    /// distance to the curve).
    pub max_deviation: Real,
    /// Control points used.
    pub control_points: usize,
}

/// Most control points a smoothing fit may use: 1000. A stent's centreline is smooth on the scale of its
/// crowns (millimetres): the aorta's 40 mm segment needs 8 control points at its `smoothing` of 0.2 mm, and a
/// 45° arc of radius 100 mm given as 400 points is within 1e-4 mm with 17; 1000 control points resolve wiggles
/// of a fraction of a millimetre over a metre of vessel. A fit that needs more is following the points'
/// noise, and near one control point per point the least-squares system loses its definiteness (before this
/// limit 10 000 noisy points drove the search to 10 000 control points, 167 s and 791 MB, and ended in
/// "singular system"). With it the search makes at most about `3 log2(1000) = 30` fits, each `O(points)`.
pub const MAX_SMOOTHING_CONTROL_POINTS: usize = 1000;

/// The cubic with the fewest control points whose least-squares fit (`crate::math::approx::approximate`,
/// through the first and last point) stays within `tolerance` of every point of `points`: the count doubles
/// from 4 until the fit is close enough, then bisection finds the smallest (the deviation falls with the count;
/// with as many control points as points the fit interpolates). The count is at most the number of points and
/// [`MAX_SMOOTHING_CONTROL_POINTS`]; a count whose least-squares system is singular (spans of too few points,
/// `crate::math::approx::MIN_RELATIVE_PIVOT`) lowers that ceiling, and the search goes on below it.
///
/// # Errors
/// [`GeometryError::InvalidParameter`] for fewer than two points, two consecutive points that coincide, or a
/// tolerance that is not positive; [`GeometryError::SmoothingTooTight`] when no count within the limits is
/// close enough, with the closest fit found and a tolerance that it meets.
pub fn smooth_points(points: &[Vec3], tolerance: Real) -> Result<SmoothFit, GeometryError> {
    let invalid = |reason: String| GeometryError::InvalidParameter {
        what: Parameter::Points,
        reason,
    };
    if points.len() < 2 {
        return Err(invalid(format!(
            "need at least 2 points, got {}",
            points.len()
        )));
    }
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return Err(invalid(format!(
            "smoothing tolerance {tolerance}: give a positive length"
        )));
    }
    let params = crate::math::approx::chord_parameters(points)
        .ok_or_else(|| invalid("two consecutive points coincide".into()))?;
    let m = points.len();
    let degree = 3.min(m - 1);
    let limit = m.min(MAX_SMOOTHING_CONTROL_POINTS).max(degree + 1);
    // The fit with `count` control points and the point farthest from it; `None` when its system is singular.
    let fit = |count: usize| -> Result<Option<(SmoothFit, usize)>, GeometryError> {
        let curve = match crate::math::approx::approximate(points, &params, degree, count) {
            Ok(curve) => curve,
            Err(crate::math::MathError::Singular { .. }) => return Ok(None),
            Err(e) => return Err(e.into()),
        };
        let (worst_point, max_deviation) = params
            .iter()
            .zip(points)
            .map(|(&u, p)| (curve.point(u) - p).norm())
            .enumerate()
            .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
        Ok(Some((
            SmoothFit {
                curve,
                max_deviation,
                control_points: count,
            },
            worst_point,
        )))
    };
    // The closest fit tried, for the error.
    let mut closest: Option<(SmoothFit, usize)> = None;
    let mut low = degree; // the largest count known to be too few (or below the minimum)
    let mut ceiling = limit; // counts above are beyond the limit or singular
    let mut count = (degree + 1).max(4).min(limit);
    // Doubling from `low`; a singular count lowers the ceiling and the search halves back towards `low`.
    let mut best = loop {
        let current = fit(count)?;
        if let Some((f, _)) = &current
            && closest
                .as_ref()
                .is_none_or(|c| f.max_deviation < c.0.max_deviation)
        {
            closest = current.clone();
        }
        match current {
            Some((f, _)) if f.max_deviation <= tolerance => break f,
            Some(_) => low = count,
            None => ceiling = count - 1,
        }
        if low >= ceiling {
            let Some((c, worst_point)) = closest else {
                return Err(invalid(format!(
                    "no least-squares cubic of up to {limit} control points is defined by these {m} points"
                )));
            };
            return Err(GeometryError::SmoothingTooTight {
                tolerance,
                points: m,
                closest: c.max_deviation,
                worst_point,
                control_points: c.control_points,
                enough: round_up_two_digits(c.max_deviation),
            });
        }
        count = if count == low {
            (2 * count).min(ceiling)
        } else {
            low + (ceiling - low).div_ceil(2)
        };
    };
    // Bisection between `low` (too few) and `count` (enough).
    let mut high = count;
    while high - low > 1 {
        let mid = (low + high) / 2;
        if mid <= degree {
            break;
        }
        match fit(mid)? {
            Some((f, _)) if f.max_deviation <= tolerance => {
                high = mid;
                best = f;
            }
            // Too far, or singular: the count found stands.
            _ => low = mid,
        }
    }
    Ok(best)
}

/// `x > 0` rounded up to two significant digits (a tolerance to suggest: at least `x`, and short to type),
/// the double nearest the decimal so that it prints as written.
fn round_up_two_digits(x: Real) -> Real {
    if !(x > 0.0 && x.is_finite()) {
        return x;
    }
    let exponent = x.log10().floor() as i32 - 1;
    let mut digits = (x / (10.0 as Real).powi(exponent)).ceil() as u64;
    loop {
        let value: Real = format!("{digits}e{exponent}").parse().unwrap_or(x);
        if value >= x {
            return value;
        }
        digits += 1;
    }
}
