//! Exact NURBS primitives: straight lines and circular arcs, refined by degree elevation and knot insertion
//! to a patch's degree `p` and number of control points `n` (the geometry is unchanged by refinement).
//!
//! Both are built as a single Bézier segment on `[0, 1]` — a line as a degree-1 segment, an arc as the
//! rational quadratic segment of Piegl–Tiller §7.3 (Eq. 7.8: middle weight `cos(φ/2)`) — then passed to
//! [`NurbsCurve::refined`]: degree elevation (A5.9, homogeneous) followed by `n − p − 1` uniform simple knots
//! (A5.4). Elevation and insertion only form convex combinations of homogeneous control points, so the
//! result is the same line or circle to rounding, and it is `C^{p−1}` inside the patch, as collocation needs.

use crate::geometry::{GeometryError, Parameter};
use crate::math::{KnotVector, NurbsCurve, Real, Vec3};

/// Largest arc angle of one patch, in radians: 150°.
///
/// One rational quadratic segment spans at most a half circle, and it degrades long before: its middle
/// control point lies at distance `R / cos(φ/2)` from the centre (3.9 R at 150°, ∞ at 180°) with weight
/// `cos(φ/2)` (0.26 at 150°, 0 at 180°), and the parametric speed grows from the ends to the middle by
/// `1 / cos²(φ/4)` (1.59 at 150°, 2 at 180°). Far-away control points are poor unknowns for the rod
/// (they are the collocation degrees of freedom) and a vanishing weight makes the rational basis
/// ill-conditioned, so longer arcs must be split into several patches joined at nodes.
pub const MAX_ARC_ANGLE: Real = 5.0 * std::f64::consts::PI / 6.0;

/// Largest accepted `|(start − center) · axis| / |start − center|` for an arc (the start point must lie in
/// the plane through the centre normal to the axis). Inputs within this tolerance are projected onto the
/// plane: the circle is then exactly the one `start` describes about the axis line.
pub const PERPENDICULAR_TOLERANCE: Real = 1e-9;

/// Relative slack allowed above [`MAX_ARC_ANGLE`], so that `150.0_f64.to_radians()` (which may differ from
/// `5π/6` by an ulp) is accepted.
const ANGLE_SLACK: Real = 4.0 * Real::EPSILON;

/// Fails unless `degree ≥ min_degree` and `n ≥ degree + 1`.
fn check_refinement(degree: usize, n: usize, min_degree: usize) -> Result<(), GeometryError> {
    if degree < min_degree {
        return Err(GeometryError::InvalidParameter {
            what: Parameter::Degree,
            reason: format!("this primitive needs degree ≥ {min_degree}, got {degree}"),
        });
    }
    if n < degree + 1 {
        return Err(GeometryError::InvalidParameter {
            what: Parameter::ControlPoints,
            reason: format!(
                "degree {degree} needs at least {} control points, got {n}",
                degree + 1
            ),
        });
    }
    Ok(())
}

/// Fails unless every coordinate of `v` is finite.
fn check_finite(what: Parameter, v: &Vec3) -> Result<(), GeometryError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(GeometryError::InvalidParameter {
            what,
            reason: format!("({}, {}, {}) is not finite", v.x, v.y, v.z),
        })
    }
}

/// The straight segment from `a` to `b` as an exact B-spline of degree `degree ≥ 1` with `n ≥ degree + 1`
/// control points on `[0, 1]`, parametrised proportionally to arc length (`c(u) = a + u (b − a)`).
///
/// Built as the degree-1 Bézier segment `{a, b}`, then degree-elevated (Piegl–Tiller A5.9) and knot-refined
/// (A5.4) by [`NurbsCurve::refined`]; elevation of a linear segment spaces the control points uniformly, so
/// the parametrisation stays linear.
pub fn line(a: Vec3, b: Vec3, degree: usize, n: usize) -> Result<NurbsCurve, GeometryError> {
    check_refinement(degree, n, 1)?;
    check_finite(Parameter::LineStart, &a)?;
    check_finite(Parameter::LineEnd, &b)?;
    if a == b {
        return Err(GeometryError::InvalidParameter {
            what: Parameter::LineEnds,
            reason: format!("start and end coincide at ({}, {}, {})", a.x, a.y, a.z),
        });
    }
    let segment = NurbsCurve::try_bspline(KnotVector::clamped_uniform(1, 2)?, vec![a, b])?;
    Ok(segment.refined(degree, n)?)
}

/// The circular arc from `start` rotating by `angle` (radians) about the unit `axis` through `center` (sign by
/// the right-hand rule), as an exact NURBS of degree `degree ≥ 2` with `n ≥ degree + 1` control points on
/// `[0, 1]`.
///
/// One rational quadratic Bézier segment (Piegl–Tiller §7.3, Eq. 7.8): control points `start`, the
/// intersection of the end tangents `c + (r₀ + r₁)/(1 + cos φ)` and the end point `c + r₁`, weights
/// `(1, cos(φ/2), 1)`; then elevated (A5.9) and refined (A5.4) by [`NurbsCurve::refined`], which keeps the
/// circle and makes it `C^{p−1}` inside the patch. The parametrisation is not arc length (the speed varies by
/// `1/cos²(φ/4)`); the solver measures `s` through `|c'(u)|`.
///
/// Errors ([`GeometryError::InvalidParameter`]): non-finite input, zero axis, `start` on the axis or not in
/// the plane through `center` normal to `axis` (relative tolerance [`PERPENDICULAR_TOLERANCE`]), zero angle,
/// `|angle|` above [`MAX_ARC_ANGLE`] (150°: split the arc into several patches), `degree < 2` or
/// `n < degree + 1`.
pub fn arc(
    center: Vec3,
    start: Vec3,
    axis: Vec3,
    angle: Real,
    degree: usize,
    n: usize,
) -> Result<NurbsCurve, GeometryError> {
    check_refinement(degree, n, 2)?;
    check_finite(Parameter::ArcCentre, &center)?;
    check_finite(Parameter::ArcStart, &start)?;
    check_finite(Parameter::ArcAxis, &axis)?;
    if !angle.is_finite() || angle == 0.0 {
        return Err(GeometryError::InvalidParameter {
            what: Parameter::ArcAngle,
            reason: format!("must be finite and non-zero, got {angle}"),
        });
    }
    if angle.abs() > MAX_ARC_ANGLE * (1.0 + ANGLE_SLACK) {
        return Err(GeometryError::InvalidParameter {
            what: Parameter::ArcAngle,
            reason: format!(
                "|angle| = {:.3}° exceeds the {:.0}° one patch can represent well; split the arc into \
                 several patches (e.g. {} of {:.3}°)",
                angle.abs().to_degrees(),
                MAX_ARC_ANGLE.to_degrees(),
                (angle.abs() / MAX_ARC_ANGLE).ceil(),
                (angle.abs() / (angle.abs() / MAX_ARC_ANGLE).ceil()).to_degrees()
            ),
        });
    }
    let axis_norm = axis.norm();
    if axis_norm == 0.0 {
        return Err(GeometryError::InvalidParameter {
            what: Parameter::ArcAxis,
            reason: "the axis is zero".into(),
        });
    }
    let axis = axis / axis_norm;
    let offset = start - center;
    let along = offset.dot(&axis);
    let radial = offset - axis * along;
    let radius = radial.norm();
    if radius == 0.0 || along.abs() > PERPENDICULAR_TOLERANCE * offset.norm() {
        return Err(GeometryError::InvalidParameter {
            what: Parameter::ArcStart,
            reason: format!(
                "start − centre must be non-zero and perpendicular to the axis: its axial component is {along:e}, \
                 its radial length {radius:e}"
            ),
        });
    }
    // The circle's centre is the foot of `start` on the axis line.
    let foot = center + axis * along;
    let (sin, cos) = angle.sin_cos();
    let r1 = radial * cos + axis.cross(&radial) * sin;
    let corner = foot + (radial + r1) / (1.0 + cos);
    let points = vec![start, corner, foot + r1];
    let weights = vec![1.0, (0.5 * angle).cos(), 1.0];
    let segment = NurbsCurve::try_new(KnotVector::clamped_uniform(2, 3)?, points, weights)?;
    Ok(segment.refined(degree, n)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::basis::nurbs_basis;
    use crate::math::basis::tests::config;
    use proptest::prelude::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// Gauss–Legendre nodes and weights on [−1, 1] (Newton on the three-term recurrence for P_m; the
    /// classical construction, e.g. Numerical Recipes `gauleg`), accurate to a few ulps.
    fn gauss_legendre(m: usize) -> Vec<(Real, Real)> {
        (0..m)
            .map(|i| {
                let mut x = (PI * (i as Real + 0.75) / (m as Real + 0.5)).cos();
                let mut dp = 1.0;
                for _ in 0..100 {
                    let (mut p0, mut p1) = (1.0, x);
                    for k in 2..=m {
                        let p2 = ((2 * k - 1) as Real * x * p1 - (k - 1) as Real * p0) / k as Real;
                        p0 = p1;
                        p1 = p2;
                    }
                    dp = m as Real * (x * p1 - p0) / (x * x - 1.0);
                    let dx = p1 / dp;
                    x -= dx;
                    if dx.abs() < 1e-16 {
                        break;
                    }
                }
                (x, 2.0 / ((1.0 - x * x) * dp * dp))
            })
            .collect()
    }

    /// ∫|c'(u)| du over the domain, with an m-point Gauss rule on every knot span.
    fn arc_length(c: &NurbsCurve, m: usize) -> Real {
        let rule = gauss_legendre(m);
        c.knots()
            .breakpoints()
            .windows(2)
            .map(|w| {
                let (a, b) = (w[0], w[1]);
                rule.iter()
                    .map(|(x, wt)| {
                        wt * 0.5
                            * (b - a)
                            * c.derivatives(a + 0.5 * (b - a) * (x + 1.0), 1)[1].norm()
                    })
                    .sum::<Real>()
            })
            .sum()
    }

    /// Rounding scales `S_k = Σ_j |R_j^(k)(u)| |p_j|`, k = 0…nders: evaluating `c^(k) = Σ R_j^(k) p_j` in floating
    /// point has an error of a few ε·S_k (the condition number of the sum), whatever the size of `c^(k)`.
    fn rounding_scales(c: &NurbsCurve, u: Real, nders: usize) -> Vec<Real> {
        let t = nurbs_basis(c.knots(), c.weights(), u, nders);
        t.ders
            .iter()
            .map(|row| {
                row.iter()
                    .enumerate()
                    .map(|(j, r)| r.abs() * c.points()[t.first + j].norm())
                    .sum()
            })
            .collect()
    }

    /// Margin on ε·S_k for the handful of roundings in the basis recursion, the rational quotient rule and the
    /// identities formed from the results.
    const ROUNDING_MARGIN: Real = 100.0 * Real::EPSILON;

    fn vec3(v: &[Real]) -> Vec3 {
        Vec3::new(v[0], v[1], v[2])
    }

    // Checks the hand-known quarter circle (Piegl–Tiller Ex. 7.1 / Eq. 7.8): centre 0, start (1,0,0), axis z,
    // 90°, p = 2, n = 3 gives control points (1,0,0), (1,1,0), (0,1,0) and weights (1, √2/2, 1). O(1) values,
    // tolerance 1e-15.
    #[test]
    fn quarter_circle_control_net() {
        let c = arc(Vec3::zeros(), Vec3::x(), Vec3::z(), FRAC_PI_2, 2, 3).unwrap();
        let expect = [Vec3::x(), Vec3::new(1.0, 1.0, 0.0), Vec3::y()];
        for (p, e) in c.points().iter().zip(&expect) {
            assert!((p - e).norm() < 1e-15, "{p}");
        }
        assert!((c.weights()[1] - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15);
    }

    // Checks that the arc length of a 90° arc of radius 1 is π/2 (closed form), for several (p, n), by a
    // 24-point Gauss–Legendre rule per knot span. The speed is a smooth rational function on each span, so
    // the rule converges far beyond double precision; what remains is rounding (~1e-15). Tolerance 1e-12 as
    // required.
    #[test]
    fn quarter_arc_length_is_half_pi() {
        let axis = Vec3::new(1.0, 2.0, 2.0) / 3.0;
        let start = Vec3::new(2.0, -1.0, 0.0) / 5f64.sqrt();
        for (p, n) in [(2, 3), (2, 10), (3, 4), (3, 17), (5, 12), (8, 9), (8, 40)] {
            let c = arc(
                Vec3::new(0.3, -0.2, 1.0),
                Vec3::new(0.3, -0.2, 1.0) + start,
                axis,
                FRAC_PI_2,
                p,
                n,
            )
            .unwrap();
            let len = arc_length(&c, 24);
            assert!(
                (len - FRAC_PI_2).abs() < 1e-12,
                "p={p} n={n}: {len} vs π/2, error {:e}",
                len - FRAC_PI_2
            );
        }
    }

    // Checks error paths: every bad input returns InvalidParameter (or a wrapped math error), never panics.
    // The 150° limit is tested on both sides (with 150° given as to_radians(), which may differ by an ulp).
    #[test]
    fn invalid_inputs_are_errors() {
        let (o, x, z) = (Vec3::zeros(), Vec3::x(), Vec3::z());
        assert!(arc(o, x, z, 150f64.to_radians(), 3, 6).is_ok());
        assert!(arc(o, x, z, -150f64.to_radians(), 3, 6).is_ok());
        let err = arc(o, x, z, 151f64.to_radians(), 3, 6).unwrap_err();
        assert!(err.to_string().contains("split the arc"), "{err}");
        assert!(arc(o, x, z, PI, 3, 6).is_err());
        assert!(arc(o, x, z, 0.0, 3, 6).is_err());
        assert!(arc(o, x, z, Real::NAN, 3, 6).is_err());
        assert!(arc(o, o, z, 1.0, 3, 6).is_err());
        assert!(arc(o, z, z, 1.0, 3, 6).is_err());
        assert!(arc(o, Vec3::new(1.0, 0.0, 1e-3), z, 1.0, 3, 6).is_err());
        assert!(arc(o, x, o, 1.0, 3, 6).is_err());
        assert!(arc(o, x, Vec3::new(Real::NAN, 0.0, 1.0), 1.0, 3, 6).is_err());
        assert!(arc(o, x, z, 1.0, 1, 6).is_err());
        assert!(arc(o, x, z, 1.0, 3, 3).is_err());
        assert!(line(o, x, 1, 2).is_ok());
        assert!(line(o, x, 0, 2).is_err());
        assert!(line(o, x, 2, 2).is_err());
        assert!(line(x, x, 2, 5).is_err());
        assert!(line(o, Vec3::new(Real::INFINITY, 0.0, 0.0), 2, 5).is_err());
        // A start point off the plane within the tolerance is projected: the circle lies in the plane of
        // `start`, centred on the axis.
        let c = arc(o, Vec3::new(1.0, 0.0, 1e-12), z, 1.0, 3, 6).unwrap();
        let q = c.point(0.7);
        assert!(
            (q.z - 1e-12).abs() < 1e-15 && ((q.x * q.x + q.y * q.y).sqrt() - 1.0).abs() < 1e-15
        );
    }

    proptest! {
        #![proptest_config(config(200))]

        // Checks that `line` is exactly a + u(b − a): points (hence on the line, arc-length proportional),
        // c' = b − a and c'' = c''' = 0, for p = 1…8 and random n. The reference is the closed form. The control
        // points are convex combinations of a and b, so positions are exact to a few ulps of max(|a|, |b|)
        // (tolerance 1e-14 × that); a derivative c^(k) = Σ N_j^(k) p_j is a cancelling sum whose rounding is
        // ε·S_k with S_k = Σ|N_j^(k)||p_j| ~ (p/Δ)^k·max|p| (tolerance 100·ε·S_k).
        #[test]
        fn line_is_exact(
            a in proptest::collection::vec(-10.0..10.0f64, 3),
            b in proptest::collection::vec(-10.0..10.0f64, 3),
            p in 1usize..=8,
            extra in 0usize..=20,
        ) {
            let (a, b) = (vec3(&a), vec3(&b));
            prop_assume!((b - a).norm() > 1e-3);
            let c = line(a, b, p, p + 1 + extra).unwrap();
            prop_assert_eq!(c.degree(), p);
            prop_assert_eq!(c.num_points(), p + 1 + extra);
            prop_assert!(c.is_polynomial());
            let scale = a.norm().max(b.norm());
            for i in 0..=100 {
                let u = i as Real / 100.0;
                let d = c.derivatives(u, 3);
                let sk = rounding_scales(&c, u, 3);
                prop_assert!((d[0] - (a + (b - a) * u)).norm() <= 1e-14 * scale);
                prop_assert!((d[1] - (b - a)).norm() <= ROUNDING_MARGIN * sk[1]);
                prop_assert!(d[2].norm() <= ROUNDING_MARGIN * sk[2]);
                prop_assert!(d[3].norm() <= ROUNDING_MARGIN * sk[3]);
            }
        }

        // Checks that `arc` is exactly the circle, for random centre, radius (0.1…10), axis, start direction,
        // angle in ±[1°, 150°], p = 2…8, n: (1) |c(u) − centre| = R and (c − centre)·axis = 0 at 201
        // parameters, (2) the angle swept runs monotonically from 0 to φ, (3) the end points are start and
        // start rotated by φ (Rodrigues, independent of the construction), (4) the end tangents are
        // ±axis × radius (sign of φ), (5) the derivative identities of a circle, (c−m)·c' = 0 and
        // |c'|² + (c−m)·c'' = 0, hold. The refinement forms convex combinations of homogeneous points whose
        // size is ≲ 4R + |m| (middle control point at R/cos 75°), so positions are exact to a few ulps of that
        // scale: tolerance 1e-14·scale. Tangents and the identities involve derivatives, whose
        // rounding is 100·ε·S_k (see `rounding_scales`; small for a large arc, but dominant for a 1° arc far from
        // the origin), propagated through the products.
        #[test]
        fn arc_is_exact_circle(
            m in proptest::collection::vec(-10.0..10.0f64, 3),
            ax in proptest::collection::vec(-1.0..1.0f64, 3),
            dir in proptest::collection::vec(-1.0..1.0f64, 3),
            radius in 0.1..10.0f64,
            deg in 1.0..150.0f64,
            negative in proptest::bool::ANY,
            p in 2usize..=8,
            extra in 0usize..=20,
        ) {
            let (m, ax, dir) = (vec3(&m), vec3(&ax), vec3(&dir));
            prop_assume!(ax.norm() > 0.1);
            let axis = ax.normalize();
            let radial = dir - axis * dir.dot(&axis);
            prop_assume!(radial.norm() > 0.1);
            let r0 = radial.normalize() * radius;
            let phi = if negative { -deg.to_radians() } else { deg.to_radians() };
            let c = arc(m, m + r0, ax, phi, p, p + 1 + extra).unwrap();
            prop_assert_eq!(c.degree(), p);
            prop_assert_eq!(c.num_points(), p + 1 + extra);
            // C^{p−1} inside: every interior knot is simple.
            for b in c.knots().breakpoints() {
                if b > 0.0 && b < 1.0 { prop_assert_eq!(c.knots().multiplicity(b), 1); }
            }
            let scale = m.norm() + 4.0 * radius;
            let rotated = r0 * phi.cos() + axis.cross(&r0) * phi.sin()
                + axis * axis.dot(&r0) * (1.0 - phi.cos());
            prop_assert!((c.point(0.0) - (m + r0)).norm() <= 1e-14 * scale);
            prop_assert!((c.point(1.0) - (m + rotated)).norm() <= 1e-14 * scale);
            let sign = phi.signum();
            for (u, radius_vector) in [(0.0, r0), (1.0, rotated)] {
                let d1 = c.derivatives(u, 1)[1];
                let tol = 1e-14 + 2.0 * ROUNDING_MARGIN * rounding_scales(&c, u, 1)[1] / d1.norm();
                prop_assert!((d1.normalize() - axis.cross(&radius_vector).normalize() * sign).norm() <= tol);
            }
            let e1 = r0 / radius;
            let e2 = axis.cross(&e1);
            let mut previous = 0.0;
            for i in 0..=200 {
                let u = i as Real / 200.0;
                let d = c.derivatives(u, 2);
                let q = d[0] - m;
                prop_assert!((q.norm() - radius).abs() <= 1e-14 * scale, "radius error {}", q.norm() - radius);
                prop_assert!(q.dot(&axis).abs() <= 1e-14 * scale);
                let swept = sign * q.dot(&e2).atan2(q.dot(&e1));
                let angle_tol = 1e-14 * scale / radius;
                prop_assert!(swept >= previous - angle_tol && swept <= phi.abs() + angle_tol);
                previous = swept;
                let speed2 = d[1].norm_squared();
                let sk = rounding_scales(&c, u, 2);
                let e0 = 1e-14 * scale;
                let (e1, e2) = (ROUNDING_MARGIN * sk[1], ROUNDING_MARGIN * sk[2]);
                prop_assert!(q.dot(&d[1]).abs() <= e0 * d[1].norm() + radius * e1);
                prop_assert!((speed2 + q.dot(&d[2])).abs() <= 2.0 * d[1].norm() * e1 + e0 * d[2].norm() + radius * e2);
            }
        }

        // Checks arc derivatives of order 1–3 against central differences of the order below (the curve-level
        // test covers random NURBS; this one covers the refined primitives that the solver will use). Step
        // h = 1e-4 (domain [0, 1], spans ≥ 1/31): an arc's derivatives grow by at most ~(angle)·1.6 ≤ 5 per order,
        // so the relative truncation error (5h)²/6 is ~ 4e-8; the rounding error of the difference is
        // 2·(100·ε·S_{k−1})/h with S_k from `rounding_scales` (it dominates for a 10° arc, whose derivatives are
        // small next to its control points). Tolerance 1e-6·|c^(k)| plus that rounding term.
        #[test]
        fn arc_derivatives_match_central_differences(
            deg in 10.0..150.0f64,
            p in 2usize..=8,
            extra in 0usize..=30,
            t in 0.0..1.0f64,
        ) {
            let c = arc(Vec3::new(1.0, 2.0, 3.0), Vec3::new(3.0, 2.0, 3.0), Vec3::new(0.0, 1.0, 1.0),
                deg.to_radians(), p, p + 1 + extra).unwrap();
            let h = 1e-4;
            let u = t * (1.0 - 4.0 * h) + 2.0 * h;
            prop_assume!(c.knots().breakpoints().iter().all(|b| (u - b).abs() > 2.0 * h));
            let d = c.derivatives(u, 3);
            let dm = c.derivatives(u - h, 2);
            let dp = c.derivatives(u + h, 2);
            let sk = rounding_scales(&c, u, 2);
            for k in 1..=3 {
                let fd = (dp[k - 1] - dm[k - 1]) / (2.0 * h);
                let tol = 1e-6 * d[k].norm() + 2.0 * ROUNDING_MARGIN * sk[k - 1] / h;
                prop_assert!((fd - d[k]).norm() <= tol, "k={} fd={} exact={} tol={}", k, fd, d[k], tol);
            }
        }
    }
}
