//! Analytic curves that are not NURBS: the helix, the sinusoidal crown wire of the paper's appendix, point
//! lists (through their cubic interpolant) and any of them mapped by a placement
//! `P = c(s) + R(s) P_local` along a centreline. [`super::fit`] turns them into analysis splines.

use super::frame::{FrameField, FrameSettings};
use super::{GeometryError, Parameter};
use crate::math::{KnotVector, Mat3, NurbsCurve, Real, Vec3, interp};

/// Samples per unit of the parameter domain in [`ParametricCurve::tightest_bend`].
const BEND_SAMPLES: usize = 2000;

/// A smooth parametric curve `t ∈ [t0, t1] ↦ c(t)`.
pub trait ParametricCurve {
    /// The parameter interval `(t0, t1)`, `t0 < t1`.
    fn domain(&self) -> (Real, Real);

    /// The point `c(t)`.
    fn point(&self, t: Real) -> Vec3;

    /// The derivative `c'(t)`; by default a fourth-order finite difference of [`Self::point`] with step
    /// `1e-3` of the domain length (error `O(1e-12)` relative for curves smooth on that scale): the central
    /// five-point formula where its stencil fits in the domain, else the one-sided five-point formula pointing
    /// into it, so that [`Self::point`] is never evaluated outside `[t0, t1]`, where a curve need not be defined
    /// (a [`PlacedCurve`] clamps its carrier's arc length there).
    fn derivative(&self, t: Real) -> Vec3 {
        let (t0, t1) = self.domain();
        let h = 1e-3 * (t1 - t0);
        if t - 2.0 * h >= t0 && t + 2.0 * h <= t1 {
            (self.point(t - 2.0 * h) - self.point(t + 2.0 * h)
                + (self.point(t + h) - self.point(t - h)) * 8.0)
                / (12.0 * h)
        } else {
            // f'(t) = (−25 f(t) + 48 f(t+h) − 36 f(t+2h) + 16 f(t+3h) − 3 f(t+4h)) / 12h + O(h⁴),
            // with h < 0 at the upper end.
            let h = if t - 2.0 * h < t0 { h } else { -h };
            (self.point(t) * -25.0 + self.point(t + h) * 48.0 - self.point(t + 2.0 * h) * 36.0
                + self.point(t + 3.0 * h) * 16.0
                - self.point(t + 4.0 * h) * 3.0)
                / (12.0 * h)
        }
    }

    /// The smallest radius of curvature `|c'|³ / |c' × c''|` over `BEND_SAMPLES` + 1 evenly spaced
    /// parameters, and the parameter (as a fraction of the domain) where it is; `c''` is the central difference
    /// of [`Self::derivative`] at a step of 1e-5 of the domain (one-sided at the ends). Infinite for a straight
    /// curve.
    fn tightest_bend(&self) -> (Real, Real) {
        let (t0, t1) = self.domain();
        let h = 1e-5 * (t1 - t0);
        (0..=BEND_SAMPLES)
            .map(|k| {
                let f = k as Real / BEND_SAMPLES as Real;
                let t = t0 + f * (t1 - t0);
                let (a, b) = ((t - h).max(t0), (t + h).min(t1));
                let d1 = self.derivative(t);
                let d2 = (self.derivative(b) - self.derivative(a)) / (b - a);
                let speed = d1.norm();
                let bend = d1.cross(&d2).norm();
                let radius = if bend > 0.0 {
                    speed * speed * speed / bend
                } else {
                    Real::INFINITY
                };
                (radius, f)
            })
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .unwrap_or((Real::INFINITY, 0.0))
    }
}

/// An orthonormal frame from an axis (local z) and an optional reference direction for local x.
pub fn frame_from_axis(axis: &Vec3, x_hint: Option<Vec3>) -> Result<Mat3, GeometryError> {
    let n = axis.norm();
    if !(n > 0.0) || !n.is_finite() {
        return Err(GeometryError::InvalidParameter {
            what: Parameter::Axis,
            reason: format!("must be a non-zero finite vector, got {axis:?}"),
        });
    }
    let z = axis / n;
    let x = super::frame::normal_to(&z, x_hint);
    let y = z.cross(&x);
    Ok(Mat3::from_columns(&[x, y, z]))
}

/// A rigid placement `P = origin + rotation · P_local`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidPlacement {
    /// Where the local origin goes.
    pub origin: Vec3,
    /// Columns: the local x, y, z axes in global coordinates.
    pub rotation: Mat3,
}

impl RigidPlacement {
    /// The identity placement.
    pub fn identity() -> Self {
        Self {
            origin: Vec3::zeros(),
            rotation: Mat3::identity(),
        }
    }

    /// Maps a local point.
    pub fn apply(&self, p: &Vec3) -> Vec3 {
        self.origin + self.rotation * p
    }
}

/// A circular helix about the local z axis: `c(t) = (r cos(φ0 + t), r sin(φ0 + t), pitch t / 2π)`,
/// `t ∈ [0, 2π turns]`, placed rigidly.
#[derive(Debug, Clone, PartialEq)]
pub struct Helix {
    /// Radius \[length\], > 0.
    pub radius: Real,
    /// Rise per turn \[length\] (negative for a left-handed helix).
    pub pitch: Real,
    /// Number of turns, > 0.
    pub turns: Real,
    /// Start angle φ0 \[rad\].
    pub start_angle: Real,
    /// Placement of the local frame.
    pub placement: RigidPlacement,
}

impl ParametricCurve for Helix {
    fn domain(&self) -> (Real, Real) {
        (0.0, std::f64::consts::TAU * self.turns)
    }

    fn point(&self, t: Real) -> Vec3 {
        let a = self.start_angle + t;
        let local = Vec3::new(
            self.radius * a.cos(),
            self.radius * a.sin(),
            self.pitch * t / std::f64::consts::TAU,
        );
        self.placement.apply(&local)
    }

    fn derivative(&self, t: Real) -> Vec3 {
        let a = self.start_angle + t;
        let local = Vec3::new(
            -self.radius * a.sin(),
            self.radius * a.cos(),
            self.pitch / std::f64::consts::TAU,
        );
        self.placement.rotation * local
    }
}

/// The sinusoidal crown wire of the paper's appendix, on the cylinder of radius `R` about the local z axis:
/// `c(ϑ) = (R cos ϑ, R sin ϑ, h sin(m ϑ + φ))`, `ϑ ∈ [ϑ0, ϑ1]`, where `m` is the number of waves (crests) per
/// full turn (the appendix's `n_w/2`). Placed rigidly.
#[derive(Debug, Clone, PartialEq)]
pub struct SineWire {
    /// Cylinder radius `R` \[length\], > 0.
    pub radius: Real,
    /// Amplitude `h` (half the crown height) \[length\].
    pub amplitude: Real,
    /// Waves per full turn `m`, > 0.
    pub waves: Real,
    /// Phase φ \[rad\].
    pub phase: Real,
    /// Start angle ϑ0 \[rad\].
    pub from: Real,
    /// End angle ϑ1 \[rad\], ≠ ϑ0.
    pub to: Real,
    /// Placement of the local frame.
    pub placement: RigidPlacement,
}

impl ParametricCurve for SineWire {
    fn domain(&self) -> (Real, Real) {
        (0.0, 1.0)
    }

    fn point(&self, t: Real) -> Vec3 {
        let a = self.from + (self.to - self.from) * t;
        let local = Vec3::new(
            self.radius * a.cos(),
            self.radius * a.sin(),
            self.amplitude * (self.waves * a + self.phase).sin(),
        );
        self.placement.apply(&local)
    }

    fn derivative(&self, t: Real) -> Vec3 {
        let da = self.to - self.from;
        let a = self.from + da * t;
        let local = Vec3::new(
            -self.radius * a.sin(),
            self.radius * a.cos(),
            self.amplitude * self.waves * (self.waves * a + self.phase).cos(),
        ) * da;
        self.placement.rotation * local
    }
}

/// A spline curve viewed as a parametric curve on its own domain.
impl ParametricCurve for NurbsCurve {
    fn domain(&self) -> (Real, Real) {
        self.knots().domain()
    }

    fn point(&self, t: Real) -> Vec3 {
        NurbsCurve::point(self, t)
    }

    fn derivative(&self, t: Real) -> Vec3 {
        self.derivatives(t, 1)[1]
    }
}

/// The curve through a list of points: the cubic (or lower, for fewer than four points) spline that
/// interpolates them at chord-length parameters with averaged knots (Piegl–Tiller Eq. 9.5 and 9.8).
pub fn point_list_curve(points: &[Vec3]) -> Result<NurbsCurve, GeometryError> {
    if points.len() < 2 {
        return Err(GeometryError::InvalidParameter {
            what: Parameter::Points,
            reason: format!("need at least 2 points, got {}", points.len()),
        });
    }
    let mut params = Vec::with_capacity(points.len());
    params.push(0.0);
    for (k, w) in points.windows(2).enumerate() {
        let d = (w[1] - w[0]).norm();
        if !(d > 0.0) || !d.is_finite() {
            return Err(GeometryError::InvalidParameter {
                what: Parameter::Points,
                reason: format!("points {k} and {} coincide or are not finite", k + 1),
            });
        }
        params.push(params[k] + d);
    }
    let total = params[params.len() - 1];
    params.iter_mut().for_each(|t| *t /= total);
    let n = points.len();
    let p = 3.min(n - 1);
    // Knots by averaging (Piegl–Tiller Eq. 9.8): u_{j+p} = (1/p) Σ_{i=j}^{j+p−1} t_i, j = 1 … n−p−1.
    let interior: Vec<Real> = (1..n - p)
        .map(|j| params[j..j + p].iter().sum::<Real>() / p as Real)
        .collect();
    let knots = KnotVector::clamped_with_interior(p, &interior)?;
    Ok(interp::interpolate(knots, &params, points)?)
}

/// The arc length `s(t) = ∫_{t0}^{t} |c'|` of a parametric curve, tabulated on uniform panels (5-point
/// Gauss–Legendre each, exact for degree-9 integrands, so round-off accurate for smooth speeds) and inverted by
/// Newton's method.
#[derive(Debug, Clone, PartialEq)]
pub struct ArcLengthTable {
    t0: Real,
    t1: Real,
    /// Arc length at `t_k = t0 + k (t1 − t0) / panels`.
    lengths: Vec<Real>,
}

impl ArcLengthTable {
    /// Tabulates the arc length of `curve` on `panels` uniform panels.
    pub fn new(curve: &dyn ParametricCurve, panels: usize) -> Self {
        let (t0, t1) = curve.domain();
        let panels = panels.max(1);
        let mut lengths = vec![0.0; panels + 1];
        for k in 0..panels {
            let a = t0 + (t1 - t0) * k as Real / panels as Real;
            let b = t0 + (t1 - t0) * (k + 1) as Real / panels as Real;
            lengths[k + 1] = lengths[k] + gauss_legendre_5(a, b, |t| curve.derivative(t).norm());
        }
        Self { t0, t1, lengths }
    }

    /// Total length.
    pub fn length(&self) -> Real {
        self.lengths[self.lengths.len() - 1]
    }

    /// The parameter `t` at arc length `s` (clamped to `[0, L]`): linear guess in the panel, then Newton on
    /// `s(t) − s = 0`, which reaches round-off in a few iterations.
    pub fn parameter_at(&self, curve: &dyn ParametricCurve, s: Real) -> Real {
        // Newton iterations allowed; convergence is quadratic from the in-panel linear guess.
        const MAX_NEWTON: usize = 8;
        let panels = self.lengths.len() - 1;
        let s = s.clamp(0.0, self.length());
        let k = self.lengths.partition_point(|&l| l <= s).clamp(1, panels);
        let (la, lb) = (self.lengths[k - 1], self.lengths[k]);
        let dt = (self.t1 - self.t0) / panels as Real;
        let ta = self.t0 + dt * (k - 1) as Real;
        let mut t = ta + dt * if lb > la { (s - la) / (lb - la) } else { 0.0 };
        for _ in 0..MAX_NEWTON {
            let speed = curve.derivative(t).norm();
            if !(speed > 0.0) {
                break;
            }
            let f = la + gauss_legendre_5(ta, t, |v| curve.derivative(v).norm()) - s;
            let step = f / speed;
            t = (t - step).clamp(self.t0, self.t1);
            if step.abs() <= 4.0 * Real::EPSILON * (self.t1 - self.t0) {
                break;
            }
        }
        t
    }
}

/// A centreline with a rotation-minimising frame, evaluated by reference arc length: the carrier of
/// placements `P = c(s) + R(s) P_local` (paper §4.3).
#[derive(Debug, Clone)]
pub struct Centreline {
    curve: NurbsCurve,
    frames: FrameField,
    arc: ArcLengthTable,
}

/// Panels of a centreline's arc-length table (see [`ArcLengthTable`]).
const CENTRELINE_PANELS: usize = 256;

impl Centreline {
    /// A centreline along `curve` with the section axis at its start closest to `normal_hint`.
    pub fn new(curve: NurbsCurve, normal_hint: Option<Vec3>) -> Result<Self, GeometryError> {
        let frames =
            FrameField::rotation_minimising(&curve, normal_hint, &FrameSettings::default())?;
        let arc = ArcLengthTable::new(&curve, CENTRELINE_PANELS);
        Ok(Self { curve, frames, arc })
    }

    /// Total length.
    pub fn length(&self) -> Real {
        self.arc.length()
    }

    /// Position `c(s)` and rotation `R(s)` (columns: tangent, d2, d3) at arc length `s`.
    pub fn at(&self, s: Real) -> Result<(Vec3, Mat3), GeometryError> {
        let u = self.arc.parameter_at(&self.curve, s);
        let f = self.frames.at(&self.curve, u)?;
        Ok((f.position, f.rotation))
    }

    /// The derivatives `(c'(s), R'(s))` at arc length `s`: `c' = t` and `R' = R K̂` with the frame's curvature
    /// `K = (0, −t'·d3, t'·d2)` (a rotation-minimising frame does not twist about `t`).
    pub fn derivative_at(&self, s: Real) -> Result<(Vec3, Mat3), GeometryError> {
        let u = self.arc.parameter_at(&self.curve, s);
        let f = self.frames.at(&self.curve, u)?;
        Ok((
            f.rotation.column(0).into_owned(),
            f.rotation * f.curvature.cross_matrix(),
        ))
    }

    /// The underlying curve.
    pub fn curve(&self) -> &NurbsCurve {
        &self.curve
    }
}

/// 5-point Gauss–Legendre quadrature of `f` over `[a, b]`.
pub fn gauss_legendre_5(a: Real, b: Real, f: impl Fn(Real) -> Real) -> Real {
    const X: [Real; 5] = [
        -0.906_179_845_938_664,
        -0.538_469_310_105_683,
        0.0,
        0.538_469_310_105_683,
        0.906_179_845_938_664,
    ];
    const W: [Real; 5] = [
        0.236_926_885_056_189_08,
        0.478_628_670_499_366_47,
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_47,
        0.236_926_885_056_189_08,
    ];
    let (m, r) = (0.5 * (a + b), 0.5 * (b - a));
    X.iter()
        .zip(&W)
        .map(|(x, w)| w * f(m + r * x))
        .sum::<Real>()
        * r
}

/// How a local curve is carried by a [`Centreline`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Station {
    /// Rigidly at arc length `s0`: `P = c(s0) + R(s0) P_local` (the paper's crowns).
    Rigid(Real),
    /// Bent along the centreline: the local x coordinate is arc length from `s0`,
    /// `P = c(s0 + x) + R(s0 + x) (0, y, z)` (the local x axis follows the centreline tangent).
    Follow(Real),
}

/// A local curve mapped onto a centreline, `P = c(s) + R(s) P_local` (paper §4.3).
pub struct PlacedCurve<'a> {
    /// The curve in local coordinates (x along the centreline tangent, y and z across).
    pub local: &'a dyn ParametricCurve,
    /// The carrier.
    pub centreline: &'a Centreline,
    /// Where along the carrier.
    pub station: Station,
}

impl ParametricCurve for PlacedCurve<'_> {
    fn domain(&self) -> (Real, Real) {
        self.local.domain()
    }

    fn point(&self, t: Real) -> Vec3 {
        let p = self.local.point(t);
        let (s, local) = match self.station {
            Station::Rigid(s0) => (s0, p),
            Station::Follow(s0) => (s0 + p.x, Vec3::new(0.0, p.y, p.z)),
        };
        // A frame failure can only come from a degenerate centreline, which `Centreline::new` rejected.
        match self.centreline.at(s) {
            Ok((c, r)) => c + r * local,
            Err(_) => Vec3::repeat(Real::NAN),
        }
    }
}

#[cfg(test)]
mod tests {
    //! Point lists, arc-length tables, centrelines and placements against closed forms.

    use super::*;
    use crate::geometry::primitives::{arc, line};
    use std::f64::consts::{FRAC_PI_2, PI, TAU};

    /// Round-off level for coordinates of order 1–10 after a few dozen floating-point operations.
    const ROUND_OFF: Real = 1e-12;

    fn helix() -> Helix {
        Helix {
            radius: 1.5,
            pitch: 2.0,
            turns: 1.5,
            start_angle: 0.3,
            placement: RigidPlacement::identity(),
        }
    }

    /// The tightest bend of a helix is its constant radius of curvature `(a² + b²)/a` with `a` the radius and
    /// `b` the pitch over 2π (closed form); the central difference of the exact derivative at a step of 1e-5 of
    /// the domain errs by ~1e-10 relative (truncation 1e-10, round-off 1e-16/1e-5): bound 1e-8. A straight line
    /// has none (infinite radius).
    #[test]
    fn the_tightest_bend_of_a_helix_is_its_radius_of_curvature() {
        let h = helix();
        let b = h.pitch / std::f64::consts::TAU;
        let exact = (h.radius * h.radius + b * b) / h.radius;
        let (radius, _) = h.tightest_bend();
        assert!(
            ((radius - exact) / exact).abs() < 1e-8,
            "{radius} against {exact}"
        );
        let line =
            crate::geometry::primitives::line(Vec3::zeros(), Vec3::x(), 3, 5).expect("a line");
        assert_eq!(line.tightest_bend().0, Real::INFINITY);
    }

    /// Chord-length parameters of a point list, normalised to [0, 1] (Piegl–Tiller Eq. 9.5), computed here
    /// independently of [`point_list_curve`].
    fn chord_parameters(points: &[Vec3]) -> Vec<Real> {
        let mut t = vec![0.0];
        for w in points.windows(2) {
            let last = t[t.len() - 1];
            t.push(last + (w[1] - w[0]).norm());
        }
        let total = t[t.len() - 1];
        t.iter().map(|x| x / total).collect()
    }

    #[test]
    fn point_list_curve_passes_through_its_points() {
        // Interpolation at chord-length parameters: c(t_i) = p_i to round-off, for the cubic case (9 points on
        // a helix) and the low-degree cases of 3 (quadratic) and 2 points (a line).
        let h = helix();
        for count in [2usize, 3, 4, 9] {
            let points: Vec<Vec3> = (0..count)
                .map(|k| h.point(h.domain().1 * k as Real / (count - 1) as Real))
                .collect();
            let curve = point_list_curve(&points).unwrap();
            assert_eq!(curve.degree(), 3.min(count - 1));
            for (p, t) in points.iter().zip(chord_parameters(&points)) {
                assert!(
                    (curve.point(t) - p).norm() < ROUND_OFF,
                    "{count} points, t = {t}"
                );
            }
        }
        // Coincident or too few points are data errors, not panics.
        let p = Vec3::new(1.0, 2.0, 3.0);
        assert!(point_list_curve(&[p, p, Vec3::zeros()]).is_err());
        assert!(point_list_curve(&[p]).is_err());
    }

    #[test]
    fn arc_length_of_a_quarter_circle_and_its_inverse() {
        // Exact NURBS quarter circle of radius 2: length π; the arc length to parameter t is R times the angle
        // of c(t), so parameter_at(s) must return the point at angle s/R. The speed of the rational arc is
        // smooth, so 5-point Gauss–Legendre on 64 panels is exact to round-off.
        let r = 2.0;
        let curve = arc(
            Vec3::zeros(),
            Vec3::new(r, 0.0, 0.0),
            Vec3::z(),
            FRAC_PI_2,
            3,
            6,
        )
        .unwrap();
        let table = ArcLengthTable::new(&curve, 64);
        assert!(
            (table.length() - PI).abs() < ROUND_OFF,
            "{}",
            table.length()
        );
        for k in 0..=100 {
            let s = table.length() * k as Real / 100.0;
            let t = table.parameter_at(&curve, s);
            let p = curve.point(t);
            assert!((r * p.y.atan2(p.x) - s).abs() < ROUND_OFF, "s = {s}");
        }
        assert_eq!(table.parameter_at(&curve, 0.0), 0.0);
        assert!((table.parameter_at(&curve, PI) - 1.0).abs() < ROUND_OFF);
        // Clamped outside [0, L].
        assert_eq!(table.parameter_at(&curve, -1.0), 0.0);
        assert!((table.parameter_at(&curve, 10.0) - 1.0).abs() < ROUND_OFF);
        // Helix: s = t √(r² + c²) exactly.
        let h = helix();
        let speed = (h.radius.powi(2) + (h.pitch / TAU).powi(2)).sqrt();
        let table = ArcLengthTable::new(&h, 64);
        assert!((table.length() - h.domain().1 * speed).abs() < ROUND_OFF);
        for k in 0..=50 {
            let s = table.length() * k as Real / 50.0;
            assert!((table.parameter_at(&h, s) - s / speed).abs() < ROUND_OFF);
        }
    }

    #[test]
    fn centreline_on_a_line_and_an_arc_matches_closed_forms() {
        // Line from a to b: c(s) = a + s e, R(s) constant with first column e.
        let a = Vec3::new(1.0, 2.0, 3.0);
        let e = Vec3::new(2.0, -1.0, 2.0) / 3.0;
        let b = a + 5.0 * e;
        let centreline = Centreline::new(line(a, b, 3, 5).unwrap(), None).unwrap();
        assert!((centreline.length() - 5.0).abs() < ROUND_OFF);
        let (_, r0) = centreline.at(0.0).unwrap();
        for k in 0..=20 {
            let s = 5.0 * k as Real / 20.0;
            let (c, r) = centreline.at(s).unwrap();
            assert!((c - (a + s * e)).norm() < ROUND_OFF);
            assert!((r - r0).norm() < ROUND_OFF);
            assert!((r.column(0) - e).norm() < ROUND_OFF);
            assert!((r.transpose() * r - Mat3::identity()).norm() < ROUND_OFF);
        }
        // Arc of radius 3 about z from (3, 0, 0) through 120°: c(s) = 3(cos φ, sin φ, 0), φ = s/3,
        // t = (−sin φ, cos φ, 0). A planar rotation-minimising frame keeps d2 = e_z when started there, and keeps
        // d2 radial (outward, (cos φ, sin φ, 0)) when started radial.
        let radius = 3.0;
        let angle = 120f64.to_radians();
        let curve = arc(
            Vec3::zeros(),
            Vec3::new(radius, 0.0, 0.0),
            Vec3::z(),
            angle,
            4,
            9,
        )
        .unwrap();
        let out_of_plane = Centreline::new(curve.clone(), Some(Vec3::z())).unwrap();
        let radial = Centreline::new(curve, Some(Vec3::x())).unwrap();
        assert!((out_of_plane.length() - radius * angle).abs() < ROUND_OFF);
        for k in 0..=24 {
            let s = radius * angle * k as Real / 24.0;
            let phi = s / radius;
            let (c, r) = out_of_plane.at(s).unwrap();
            assert!((c - radius * Vec3::new(phi.cos(), phi.sin(), 0.0)).norm() < ROUND_OFF);
            assert!((r.column(0) - Vec3::new(-phi.sin(), phi.cos(), 0.0)).norm() < ROUND_OFF);
            assert!((r.column(1) - Vec3::z()).norm() < ROUND_OFF);
            let (_, r) = radial.at(s).unwrap();
            assert!((r.column(1) - Vec3::new(phi.cos(), phi.sin(), 0.0)).norm() < ROUND_OFF);
            assert!((r.determinant() - 1.0).abs() < ROUND_OFF);
        }
    }

    #[test]
    fn placed_curves_on_a_straight_centreline_are_rigidly_moved() {
        // On a straight carrier c(s) = a + s e with constant frame R, both placements reduce to the rigid motion
        // P = c(s0) + R P_local (Follow: c(s0 + x) + R (0, y, z) = a + s0 e + R (x, y, z) because R e1 = e). The
        // points agree to round-off; derivatives to the accuracy of the default fourth-order finite difference
        // (~1e-11 here); lengths to that of the arc-length table.
        let a = Vec3::new(1.0, 2.0, 3.0);
        let e = Vec3::new(2.0, -1.0, 2.0) / 3.0;
        let centreline = Centreline::new(line(a, a + 5.0 * e, 3, 4).unwrap(), None).unwrap();
        let (_, r) = centreline.at(0.0).unwrap();
        // A wire bump along local x (x ∈ [0, 0.6]) and a helix about local x (x ∈ [0, 1]): both start at the
        // carrier's start when s0 = 0, where the finite-difference stencil must not leave the domain.
        let wire = SineWire {
            radius: 0.3,
            amplitude: 0.1,
            waves: 2.0,
            phase: 0.0,
            from: 0.0,
            to: PI,
            placement: RigidPlacement {
                origin: Vec3::new(0.3, 0.0, 0.0),
                rotation: Mat3::identity(),
            },
        };
        let coil = Helix {
            radius: 0.2,
            pitch: 1.0,
            turns: 1.0,
            start_angle: 0.0,
            placement: RigidPlacement {
                origin: Vec3::zeros(),
                rotation: frame_from_axis(&Vec3::x(), Some(Vec3::y())).unwrap(),
            },
        };
        for station in [
            Station::Rigid(1.2),
            Station::Follow(0.0),
            Station::Follow(0.7),
        ] {
            for local in [&wire as &dyn ParametricCurve, &coil] {
                let placed = PlacedCurve {
                    local,
                    centreline: &centreline,
                    station,
                };
                let (Station::Rigid(s0) | Station::Follow(s0)) = station;
                let (t0, t1) = local.domain();
                for k in 0..=100 {
                    let t = t0 + (t1 - t0) * k as Real / 100.0;
                    let expected = a + s0 * e + r * local.point(t);
                    assert!(
                        (placed.point(t) - expected).norm() < ROUND_OFF,
                        "{station:?} t = {t}"
                    );
                    let slope = r * local.derivative(t);
                    assert!(
                        (placed.derivative(t) - slope).norm() < 1e-9 * slope.norm(),
                        "{station:?} t = {t}: {:?} vs {slope:?}",
                        placed.derivative(t)
                    );
                }
                let (placed_length, local_length) = (
                    ArcLengthTable::new(&placed, 512).length(),
                    ArcLengthTable::new(local, 512).length(),
                );
                assert!(
                    (placed_length / local_length - 1.0).abs() < 1e-10,
                    "{station:?}"
                );
            }
        }
    }

    /// A curve defined only on its domain (NaN outside), as a carrier-clamped placement effectively is.
    struct OnlyOnDomain;

    impl ParametricCurve for OnlyOnDomain {
        fn domain(&self) -> (Real, Real) {
            (1.0, 2.0)
        }
        fn point(&self, t: Real) -> Vec3 {
            if (1.0..=2.0).contains(&t) {
                Vec3::new(t.sin(), t * t, t.exp())
            } else {
                Vec3::repeat(Real::NAN)
            }
        }
    }

    #[test]
    fn default_derivative_never_leaves_the_domain() {
        // Regression: the central stencil used to sample t ± 2h outside [t0, t1] near the ends. The one-sided
        // fourth-order formula has error (h⁴/5)|c⁽⁵⁾| ≈ 2e-13 relative at h = 1e-3; asserted 1e-10.
        let c = OnlyOnDomain;
        for t in [1.0_f64, 1.0005, 1.001, 1.5, 1.999, 2.0] {
            let exact = Vec3::new(t.cos(), 2.0 * t, t.exp());
            let d = c.derivative(t);
            assert!(
                (d - exact).norm() < 1e-10 * exact.norm(),
                "t = {t}: {d:?} vs {exact:?}"
            );
        }
    }
}
