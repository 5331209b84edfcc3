//! Rotation-minimising section frames along a curve, and the reference kinematics the solver needs at any
//! parameter: `R0`, the reference curvature `K0` and its arc-length derivative `K0,s`, the parametric speed
//! `J = |c'(u)|` and its derivative.
//!
//! Frenet frames flip at the inflection points every sinusoidal wire has, so the section axes are transported
//! without twist by the double reflection method of Wang, Jüttler, Zheng & Liu, *Computation of rotation
//! minimizing frames*, ACM TOG 27 (2008) — fourth-order accurate in the step. The frame is integrated once on a
//! fine uniform grid in `u` ([`FrameSettings::steps`]) and, at any other parameter, by one more reflection step
//! from the nearest grid point below.
//!
//! For a twist-free frame `R0 = [t d2 d3]` the material curvature `K0 = axial(R0ᵀ R0,s)` is
//! `K0 = (0, −t,s·d3, t,s·d2)` and, because `d2,s = −(t,s·d2) t` and `t·t,s = 0`,
//! `K0,s = (0, −t,ss·d3, t,ss·d2)` (DESIGN §5). Both are evaluated from exact curve derivatives.

use super::GeometryError;
use crate::math::{Mat3, NurbsCurve, Real, Vec3};

/// Settings of the frame integration.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameSettings {
    /// Number of uniform double-reflection steps over the whole parameter domain. The method's global error
    /// is `O(steps⁻⁴)`; 2048 steps keep the twist error of a quarter circle or a crown wire near round-off.
    pub steps: usize,
}

impl Default for FrameSettings {
    fn default() -> Self {
        Self { steps: 2048 }
    }
}

/// The reference kinematics at one curve parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceFrame {
    /// Curve parameter `u`.
    pub u: Real,
    /// Position `c0(u)`.
    pub position: Vec3,
    /// Section rotation `R0 = [t d2 d3]`.
    pub rotation: Mat3,
    /// Material curvature `K0` [1/length].
    pub curvature: Vec3,
    /// Its arc-length derivative `K0,s` [1/length²].
    pub curvature_s: Vec3,
    /// Parametric speed `J = |c0'(u)|` \[length\].
    pub jacobian: Real,
    /// `J' = dJ/du` \[length\].
    pub jacobian_u: Real,
}

/// Arc-length derivatives of a curve at a parameter: `c,s = t`, `c,ss = t,s`, `c,sss = t,ss`, with `J`, `J'`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcLengthDerivatives {
    /// Unit tangent `t = c,s`.
    pub tangent: Vec3,
    /// `t,s = c,ss`.
    pub tangent_s: Vec3,
    /// `t,ss = c,sss`.
    pub tangent_ss: Vec3,
    /// Parametric speed `J = |c'|`.
    pub jacobian: Real,
    /// `J' = dJ/du`.
    pub jacobian_u: Real,
}

/// Converts the parametric derivatives `c', c'', c'''` to arc-length derivatives:
/// with `J = |c'|`, `J' = c'·c''/J`, `J'' = (c''·c'' + c'·c''')/J − J'²/J`,
/// `c,ss = (c'' − (J'/J) c')/J²` and `c,sss = [c'''/J² − 3J' c''/J³ + (3J'²/J⁴ − J''/J³) c']/J`.
pub fn arc_length_derivatives(
    d1: &Vec3,
    d2: &Vec3,
    d3: &Vec3,
    u: Real,
) -> Result<ArcLengthDerivatives, GeometryError> {
    let j = d1.norm();
    if !(j > 0.0) || !j.is_finite() {
        return Err(GeometryError::ZeroTangent { u });
    }
    let jp = d1.dot(d2) / j;
    let jpp = (d2.dot(d2) + d1.dot(d3)) / j - jp * jp / j;
    let tangent = d1 / j;
    let tangent_s = (d2 - d1 * (jp / j)) / (j * j);
    let tangent_ss = (d3 / (j * j) - d2 * (3.0 * jp / (j * j * j))
        + d1 * (3.0 * jp * jp / j.powi(4) - jpp / j.powi(3)))
        / j;
    Ok(ArcLengthDerivatives {
        tangent,
        tangent_s,
        tangent_ss,
        jacobian: j,
        jacobian_u: jp,
    })
}

/// The orthonormal right-handed basis (as columns) whose first axis is the unit vector `e1`, the second
/// [`normal_to`] it without a hint.
pub fn basis_from_unit_axis(e1: &Vec3) -> Mat3 {
    let e2 = normal_to(e1, None);
    Mat3::from_columns(&[*e1, e2, e1.cross(&e2)])
}

/// A unit vector normal to `t`, as close as possible to `hint` (or to the global axis least aligned with `t`
/// when no usable hint is given).
pub fn normal_to(t: &Vec3, hint: Option<Vec3>) -> Vec3 {
    // A hint closer than this (in sine of the angle) to the tangent is ignored: it would fix d2 poorly.
    const MIN_SINE: Real = 1e-3;
    if let Some(h) = hint {
        let n = h - t * t.dot(&h);
        let hn = h.norm();
        if hn > 0.0 && n.norm() > MIN_SINE * hn {
            return n.normalize();
        }
    }
    let axis = [Vec3::x(), Vec3::y(), Vec3::z()]
        .into_iter()
        .min_by(|a, b| t.dot(a).abs().total_cmp(&t.dot(b).abs()))
        .unwrap_or(Vec3::x());
    (axis - t * t.dot(&axis)).normalize()
}

/// One double-reflection step (Wang et al. 2008, Algorithm "double reflection"): transports the section
/// axis `r0` from `(x0, t0)` to `(x1, t1)` without twist; returns the new axis, orthonormal to `t1`.
pub(crate) fn double_reflection(x0: &Vec3, t0: &Vec3, r0: &Vec3, x1: &Vec3, t1: &Vec3) -> Vec3 {
    let v1 = x1 - x0;
    let c1 = v1.dot(&v1);
    let (r_l, t_l) = if c1 > 0.0 {
        (
            r0 - v1 * (2.0 / c1 * v1.dot(r0)),
            t0 - v1 * (2.0 / c1 * v1.dot(t0)),
        )
    } else {
        (*r0, *t0)
    };
    let v2 = t1 - t_l;
    let c2 = v2.dot(&v2);
    let r1 = if c2 > 0.0 {
        r_l - v2 * (2.0 / c2 * v2.dot(&r_l))
    } else {
        r_l
    };
    // Re-orthonormalise against round-off drift.
    (r1 - t1 * t1.dot(&r1)).normalize()
}

/// A rotation-minimising frame field along one curve.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameField {
    /// Grid parameters (uniform).
    params: Vec<Real>,
    /// Section axis `d2` at each grid parameter.
    normals: Vec<Vec3>,
}

impl FrameField {
    /// Integrates the rotation-minimising frame of `curve` starting from `d2(0)` = the normal closest to
    /// `normal_hint`.
    pub fn rotation_minimising(
        curve: &NurbsCurve,
        normal_hint: Option<Vec3>,
        settings: &FrameSettings,
    ) -> Result<Self, GeometryError> {
        let (u0, u1) = curve.knots().domain();
        let steps = settings.steps.max(1);
        let mut params = Vec::with_capacity(steps + 1);
        let mut normals = Vec::with_capacity(steps + 1);
        let mut x_prev = Vec3::zeros();
        let mut t_prev = Vec3::zeros();
        for k in 0..=steps {
            let u = u0 + (u1 - u0) * (k as Real) / (steps as Real);
            let d = curve.derivatives(u, 1);
            let speed = d[1].norm();
            if !(speed > 0.0) || !speed.is_finite() {
                return Err(GeometryError::ZeroTangent { u });
            }
            let t = d[1] / speed;
            let r = if k == 0 {
                normal_to(&t, normal_hint)
            } else {
                double_reflection(&x_prev, &t_prev, &normals[k - 1], &d[0], &t)
            };
            params.push(u);
            normals.push(r);
            x_prev = d[0];
            t_prev = t;
        }
        Ok(Self { params, normals })
    }

    /// The section axis `d2` at parameter `u` (one reflection step from the grid point below).
    fn normal_at(&self, curve: &NurbsCurve, u: Real, x: &Vec3, t: &Vec3) -> Vec3 {
        let last = self.params.len() - 1;
        let (u0, u1) = (self.params[0], self.params[last]);
        let k = if u1 > u0 {
            (((u - u0) / (u1 - u0) * last as Real).floor().max(0.0) as usize).min(last)
        } else {
            0
        };
        if self.params[k] == u {
            return self.normals[k];
        }
        let d = curve.derivatives(self.params[k], 1);
        let tk = d[1].normalize();
        double_reflection(&d[0], &tk, &self.normals[k], x, t)
    }

    /// The reference kinematics (`R0`, `K0`, `K0,s`, `J`, `J'`) at parameter `u`.
    pub fn at(&self, curve: &NurbsCurve, u: Real) -> Result<ReferenceFrame, GeometryError> {
        let d = curve.derivatives(u, 3);
        let a = arc_length_derivatives(&d[1], &d[2], &d[3], u)?;
        let t = a.tangent;
        let d2 = self.normal_at(curve, u, &d[0], &t);
        let d3 = t.cross(&d2);
        let rotation = Mat3::from_columns(&[t, d2, d3]);
        let curvature = Vec3::new(0.0, -a.tangent_s.dot(&d3), a.tangent_s.dot(&d2));
        let curvature_s = Vec3::new(0.0, -a.tangent_ss.dot(&d3), a.tangent_ss.dot(&d2));
        Ok(ReferenceFrame {
            u,
            position: d[0],
            rotation,
            curvature,
            curvature_s,
            jacobian: a.jacobian,
            jacobian_u: a.jacobian_u,
        })
    }
}

#[cfg(test)]
mod tests {
    //! Verification of the rotation-minimising frames and of the reference kinematics `R0, K0, K0,s` against
    //! independent references: central differences along the arc length, the closed forms of the circle and
    //! the helix (Bishop 1975; Wang et al. 2008 §2: a rotation-minimising frame turns relative to the Frenet
    //! frame at minus the torsion), and the measured order of the double-reflection integration.

    use super::*;
    use crate::geometry::analytic::{Helix, ParametricCurve, RigidPlacement, SineWire};
    use crate::geometry::fit::{FitSettings, fit_curve};
    use crate::geometry::primitives::arc;
    use crate::math::so3::vee;
    use std::f64::consts::{PI, TAU};

    /// Relative tolerance of the finite-difference checks of `K0` and `K0,s`. With the step
    /// `h = FD_STEP · ℓ` (ℓ the smallest bending radius of the curve) the central difference has truncation
    /// error `(h²/6)|f'''|`, i.e. about `(h/ℓ)²/6 ≈ 2·10⁻⁹` relative for a curve whose curvature varies on the
    /// scale ℓ, and round-off `ε/(h/ℓ) ≈ 2·10⁻¹²` relative in `R0` (one more order in `K0,s`, whose `K0` carries
    /// third derivatives). Measured: 1.5·10⁻⁹ (arc, helix) and 1.6·10⁻⁸ (crown wire `K0,s`, whose curvature
    /// varies faster than ℓ: `|K0,s| ≈ 4|K0|/ℓ`). `10⁻⁶` leaves a factor of 60 over the worst and still
    /// catches any wrong term or sign, which would be O(1).
    const FD_TOLERANCE: Real = 1e-6;
    /// Finite-difference step in units of the smallest bending radius.
    const FD_STEP: Real = 1e-4;

    /// The largest discrepancies of a frame field from central differences along the arc length, over
    /// `count` parameters in `[0.01, 0.99]`, each relative to its own scale:
    /// `(K0 vs axial(R0ᵀ ΔR0 / Δs), K0,s vs ΔK0 / Δs, d1 vs Δc / Δs)`.
    ///
    /// At parameter `u` with speed `J`, the neighbours are `u ± h/J`; their arc-length distance is `2h + O(h³)`,
    /// so dividing by `2h` keeps the difference central and second-order accurate.
    fn fd_discrepancies(curve: &NurbsCurve, field: &FrameField, count: usize) -> [Real; 3] {
        let frames: Vec<ReferenceFrame> = (0..count)
            .map(|k| 0.01 + 0.98 * (k as Real + 0.37) / count as Real)
            .map(|u| field.at(curve, u).unwrap())
            .collect();
        let k_max = frames
            .iter()
            .map(|f| f.curvature.norm())
            .fold(0.0, Real::max);
        let ks_max = frames
            .iter()
            .map(|f| f.curvature_s.norm())
            .fold(0.0, Real::max);
        let length = crate::geometry::analytic::ArcLengthTable::new(curve, 256).length();
        let radius = if k_max > 0.0 {
            (1.0 / k_max).min(length)
        } else {
            length
        };
        let h = FD_STEP * radius;
        let (k_scale, ks_scale) = (
            k_max + 1.0 / length,
            ks_max + k_max * k_max + 1.0 / length.powi(2),
        );
        let mut worst = [0.0; 3];
        for f in &frames {
            let du = h / f.jacobian;
            let plus = field.at(curve, f.u + du).unwrap();
            let minus = field.at(curve, f.u - du).unwrap();
            let k_fd =
                vee(&(f.rotation.transpose() * (plus.rotation - minus.rotation))) / (2.0 * h);
            let ks_fd = (plus.curvature - minus.curvature) / (2.0 * h);
            let t_fd = (plus.position - minus.position) / (2.0 * h);
            let errors = [
                (k_fd - f.curvature).norm() / k_scale,
                (ks_fd - f.curvature_s).norm() / ks_scale,
                (t_fd - f.rotation.column(0)).norm(),
            ];
            for (w, e) in worst.iter_mut().zip(errors) {
                *w = Real::max(*w, e);
            }
        }
        worst
    }

    /// Largest `|R0ᵀR0 − I|`, largest `|det R0 − 1|` and largest `|d1 − c'/|c'||` over `count` parameters.
    fn orthonormality(curve: &NurbsCurve, field: &FrameField, count: usize) -> Real {
        (0..=count)
            .map(|k| k as Real / count as Real)
            .map(|u| {
                let f = field.at(curve, u).unwrap();
                let r = f.rotation;
                let tangent = curve.derivatives(u, 1)[1].normalize();
                ((r.transpose() * r - Mat3::identity()).abs().max())
                    .max((r.determinant() - 1.0).abs())
                    .max((r.column(0) - tangent).norm())
            })
            .fold(0.0, Real::max)
    }

    /// Largest `|R0(u+ε) − R0(u−ε)|_F / (2ε J |K0|)` over the integration grid points `u` and steps ε.
    /// For a smooth field this is `|R0,s|_F / |K0| = |K̃0|_F / |K0| = √2`; a jump between the grid value and
    /// the extra reflection step used off the grid would make it blow up as ε shrinks.
    fn continuity_rate(curve: &NurbsCurve, field: &FrameField) -> Real {
        let steps = field.params.len() - 1;
        let mut worst: Real = 0.0;
        for k in 1..steps {
            let u = field.params[k];
            for eps in [1e-9, 1e-7, 1e-5] {
                let a = field.at(curve, u - eps).unwrap();
                let b = field.at(curve, u + eps).unwrap();
                let rate = (b.rotation - a.rotation).norm()
                    / (2.0 * eps * a.jacobian * a.curvature.norm().max(1e-300));
                worst = worst.max(rate);
            }
        }
        worst
    }

    /// A 90° arc of radius 2 about the tilted unit axis (1, 2, 2)/3, centre (1, −2, 0.5), exact NURBS (p = 4,
    /// n = 8), with the section axis d2 started on the arc's axis.
    fn tilted_arc() -> (NurbsCurve, Vec3) {
        let centre = Vec3::new(1.0, -2.0, 0.5);
        let axis = Vec3::new(1.0, 2.0, 2.0) / 3.0;
        let start = centre + Vec3::new(2.0, -2.0, 1.0) * (2.0 / 3.0);
        (arc(centre, start, axis, PI / 2.0, 4, 8).unwrap(), axis)
    }

    /// Helix of radius r = 1.5, pitch 2, 1.5 turns: curvature `r/(r² + c²)` and torsion `c/(r² + c²)`,
    /// `c = pitch/2π`, length `2π·turns·√(r² + c²)` ≈ 14.45.
    fn helix() -> Helix {
        Helix {
            radius: 1.5,
            pitch: 2.0,
            turns: 1.5,
            start_angle: 0.3,
            placement: RigidPlacement::identity(),
        }
    }

    /// Two waves of a crown wire (R = 1.5, h = 0.3, 6 waves per turn): curvature between about 0.6 and 4.8,
    /// its Frenet normal swings from nearly +z to nearly −z at every crest.
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

    /// A planar sine `c(t) = (t, a sin(k t), 0)`, `t ∈ [0, 2π/k · 1.5]`: inflection points at `t = jπ/k`, where the
    /// Frenet normal flips. Signed curvature `κ(t) = −a k² sin(kt) / (1 + a²k² cos²(kt))^{3/2}`.
    struct PlanarSine {
        amplitude: Real,
        wavenumber: Real,
    }

    impl PlanarSine {
        fn signed_curvature(&self, t: Real) -> Real {
            let (a, k) = (self.amplitude, self.wavenumber);
            -a * k * k * (k * t).sin() / (1.0 + (a * k * (k * t).cos()).powi(2)).powf(1.5)
        }
    }

    impl ParametricCurve for PlanarSine {
        fn domain(&self) -> (Real, Real) {
            (0.0, 1.5 * TAU / self.wavenumber)
        }
        fn point(&self, t: Real) -> Vec3 {
            Vec3::new(t, self.amplitude * (self.wavenumber * t).sin(), 0.0)
        }
        fn derivative(&self, t: Real) -> Vec3 {
            let (a, k) = (self.amplitude, self.wavenumber);
            Vec3::new(1.0, a * k * (k * t).cos(), 0.0)
        }
    }

    #[test]
    fn arc_curvature_matches_finite_differences_and_the_circle() {
        // Exact 90° NURBS arc of radius R = 2 (tilted plane). Closed form, with d2 on the arc's axis a: a planar
        // rotation-minimising frame keeps d2 = a, d3 = t × a is the outward radial unit vector, and
        // t,s = −d3/R, so K0 = (0, −t,s·d3, t,s·d2) = (0, 1/R, 0) exactly and K0,s = 0. Round-off of the
        // rational third derivatives is ~10⁻¹⁴; 10⁻¹² relative is generous and still far below any real error.
        let (curve, axis) = tilted_arc();
        let field =
            FrameField::rotation_minimising(&curve, Some(axis), &FrameSettings::default()).unwrap();
        let [k, ks, t] = fd_discrepancies(&curve, &field, 199);
        println!("arc: FD discrepancies K0 {k:.2e}, K0,s {ks:.2e}, d1 {t:.2e}");
        assert!(
            k < FD_TOLERANCE && ks < FD_TOLERANCE && t < FD_TOLERANCE,
            "{k:e} {ks:e} {t:e}"
        );
        for j in 0..=100 {
            let f = field.at(&curve, j as Real / 100.0).unwrap();
            assert!(
                (f.curvature - Vec3::new(0.0, 0.5, 0.0)).norm() < 1e-12,
                "{:?}",
                f.curvature
            );
            assert!(f.curvature.x == 0.0);
            assert!((f.curvature.norm() - 0.5).abs() < 1e-12);
            assert!(f.curvature_s.norm() < 1e-12, "{:?}", f.curvature_s);
            assert!((f.rotation.column(1) - axis).norm() < 1e-12);
        }
        assert!(orthonormality(&curve, &field, 500) < 1e-13);
        // Any other start axis: still |K0| = 1/R and K0·e1 = 0; K0 is constant (the frame does not twist).
        let field =
            FrameField::rotation_minimising(&curve, None, &FrameSettings::default()).unwrap();
        let k0 = field.at(&curve, 0.0).unwrap().curvature;
        for j in 0..=100 {
            let f = field.at(&curve, j as Real / 100.0).unwrap();
            assert!((f.curvature.norm() - 0.5).abs() < 1e-12 && f.curvature.x == 0.0);
            assert!((f.curvature - k0).norm() < 1e-12);
        }
    }

    #[test]
    fn helix_curvature_and_twist_relative_to_frenet_match_closed_forms() {
        // Fitted helix (p = 6, n = 60; reported fit error ≈ 6e-11). References:
        // * K0, K0,s against central differences of R0, K0 (independent of the fit quality);
        // * |K0| = κ = r/(r² + c²) (the rotation-minimising frame has K0·e1 = 0: no twist);
        // * the angle θ of d2 measured from the analytic Frenet normal N = −(cos φ, sin φ, 0) towards the
        //   binormal B = T × N obeys θ(s) − θ(0) = −τ s (Bishop 1975; Wang et al. 2008 Eq. 2), τ = c/(r² + c²);
        //   over the whole helix τL ≈ 1.96 rad, so a frame that followed Frenet would be off by 1.96 rad.
        // Tolerances follow from the fit: a spline interpolant with reported error e and knot spacing
        // h_s = L/(n − p) has tangent error ~ (p+1) e/h_s and curvature error ~ (p+1)² e/h_s²; ten times those.
        let (p, n) = (6, 60);
        let fit = fit_curve(&helix(), p, n, &FitSettings::default()).unwrap();
        let field =
            FrameField::rotation_minimising(&fit.curve, None, &FrameSettings::default()).unwrap();
        let [k, ks, t] = fd_discrepancies(&fit.curve, &field, 301);
        println!("helix: FD discrepancies K0 {k:.2e}, K0,s {ks:.2e}, d1 {t:.2e}");
        assert!(
            k < FD_TOLERANCE && ks < FD_TOLERANCE && t < FD_TOLERANCE,
            "{k:e} {ks:e} {t:e}"
        );
        assert!(orthonormality(&fit.curve, &field, 1000) < 1e-13);

        let h = helix();
        let c = h.pitch / TAU;
        let kappa = h.radius / (h.radius.powi(2) + c * c);
        let tau = c / (h.radius.powi(2) + c * c);
        let spacing = fit.length / (n - p) as Real;
        let (p1, e) = ((p + 1) as Real, fit.max_deviation);
        let angle_tolerance = 10.0 * p1 * e / spacing;
        let curvature_tolerance = 10.0 * p1 * p1 * e / (spacing * spacing);
        let t_end = h.domain().1;
        let mut theta0 = None;
        let (mut worst_angle, mut worst_curvature): (Real, Real) = (0.0, 0.0);
        for j in 0..=500 {
            let u = j as Real / 500.0;
            let f = field.at(&fit.curve, u).unwrap();
            assert_eq!(f.curvature.x, 0.0);
            assert!(
                (f.curvature.norm() - kappa).abs() < curvature_tolerance,
                "{u}: {:?}",
                f.curvature
            );
            // Arc-length parametrised fit: u = s/L; the helix parameter is proportional to s.
            let phi = h.start_angle + u * t_end;
            let normal = -Vec3::new(phi.cos(), phi.sin(), 0.0);
            let tangent = h.derivative(u * t_end).normalize();
            let binormal = tangent.cross(&normal);
            let d2 = f.rotation.column(1);
            let theta = d2.dot(&binormal).atan2(d2.dot(&normal));
            let theta0 = *theta0.get_or_insert(theta);
            let miss = (theta - theta0 + tau * u * fit.length + PI).rem_euclid(TAU) - PI;
            worst_angle = worst_angle.max(miss.abs());
            worst_curvature = worst_curvature.max((f.curvature.norm() - kappa).abs());
            assert!(
                miss.abs() < angle_tolerance,
                "u = {u}: θ off by {miss:e} rad"
            );
        }
        println!(
            "helix: |K0| − κ up to {worst_curvature:.2e} (tolerance {curvature_tolerance:.1e}), θ + τs up to \
             {worst_angle:.2e} rad (tolerance {angle_tolerance:.1e})"
        );
    }

    #[test]
    fn crown_wire_curvature_matches_finite_differences() {
        // Fitted crown wire (p = 6, n = 60, reported fit error ≈ 2e-5): |K0| from 0.6 to 4.8, |K0,s| up to 21.
        // The references are central differences of the fitted spline's own R0 and K0, so the fit error does
        // not enter. The FD discrepancy must also be pure truncation: halving h divides it by 4 (±5 %).
        let fit = fit_curve(&crown_wire(), 6, 60, &FitSettings::default()).unwrap();
        let field =
            FrameField::rotation_minimising(&fit.curve, None, &FrameSettings::default()).unwrap();
        let [k, ks, t] = fd_discrepancies(&fit.curve, &field, 301);
        println!("crown wire: FD discrepancies K0 {k:.2e}, K0,s {ks:.2e}, d1 {t:.2e}");
        assert!(
            k < FD_TOLERANCE && ks < FD_TOLERANCE && t < FD_TOLERANCE,
            "{k:e} {ks:e} {t:e}"
        );
        assert!(orthonormality(&fit.curve, &field, 1000) < 1e-13);
        // h² convergence of the discrepancy at one parameter, with steps large enough that round-off is nil.
        let f = field.at(&fit.curve, 0.3).unwrap();
        let discrepancy = |h: Real| {
            let du = h / f.jacobian;
            let plus = field.at(&fit.curve, f.u + du).unwrap();
            let minus = field.at(&fit.curve, f.u - du).unwrap();
            let k_fd =
                vee(&(f.rotation.transpose() * (plus.rotation - minus.rotation))) / (2.0 * h);
            let ks_fd = (plus.curvature - minus.curvature) / (2.0 * h);
            ((k_fd - f.curvature).norm(), (ks_fd - f.curvature_s).norm())
        };
        let (coarse, fine) = (discrepancy(2e-3), discrepancy(1e-3));
        for ratio in [coarse.0 / fine.0, coarse.1 / fine.1] {
            assert!(
                (ratio - 4.0).abs() < 0.2,
                "FD discrepancy ratio {ratio} (coarse {coarse:?}, fine {fine:?})"
            );
        }
    }

    #[test]
    fn frame_stays_continuous_where_the_frenet_frame_flips() {
        // Planar sine through three inflection points. Its Frenet normal t,s/|t,s| reverses across each
        // inflection (checked on the fitted spline, ±10⁻³ in arc length); the rotation-minimising frame started
        // with d2 normal to the plane keeps d2 = e_z exactly (reflections preserve the plane), and K0 =
        // (0, κ, 0) follows the signed curvature continuously through zero. The curvature tolerance is ten times
        // the fit's curvature error estimate (p+1)² e/h_s², as in the helix test.
        let curve = PlanarSine {
            amplitude: 0.4,
            wavenumber: 2.0,
        };
        let (p, n) = (6, 80);
        let fit = fit_curve(&curve, p, n, &FitSettings::default()).unwrap();
        let field =
            FrameField::rotation_minimising(&fit.curve, Some(Vec3::z()), &FrameSettings::default())
                .unwrap();
        let [k, ks, t] = fd_discrepancies(&fit.curve, &field, 301);
        assert!(
            k < FD_TOLERANCE && ks < FD_TOLERANCE && t < FD_TOLERANCE,
            "{k:e} {ks:e} {t:e}"
        );
        let spacing = fit.length / (n - p) as Real;
        let curvature_tolerance =
            10.0 * ((p + 1) as Real).powi(2) * fit.max_deviation / spacing.powi(2);
        let table = crate::geometry::analytic::ArcLengthTable::new(&curve, 512);
        for j in 0..=400 {
            let u = j as Real / 400.0;
            let f = field.at(&fit.curve, u).unwrap();
            assert!((f.rotation.column(1) - Vec3::z()).norm() < 1e-12);
            let t_curve = table.parameter_at(&curve, u * fit.length);
            let kappa = curve.signed_curvature(t_curve);
            assert!(
                (f.curvature - Vec3::new(0.0, kappa, 0.0)).norm() < curvature_tolerance,
                "{u}: {:?} vs {kappa}",
                f.curvature
            );
        }
        let k = curve.wavenumber;
        let mut flips = 0;
        for j in 1..=2 {
            let s = table_arc_length(&table, &curve, j as Real * PI / k);
            let (before, after) = (s / fit.length - 1e-3, s / fit.length + 1e-3);
            let normal = |u: Real| {
                let d = fit.curve.derivatives(u, 2);
                let a = arc_length_derivatives(&d[1], &d[2], &Vec3::zeros(), u).unwrap();
                a.tangent_s.normalize()
            };
            if normal(before).dot(&normal(after)) < -0.99 {
                flips += 1;
            }
            let (fa, fb) = (
                field.at(&fit.curve, before).unwrap(),
                field.at(&fit.curve, after).unwrap(),
            );
            // |ΔR0|_F ≤ √2 max|K0| Δs ≈ 1.4 · 0.02 · 0.01 near the inflection: the frame barely moves.
            assert!((fa.rotation - fb.rotation).norm() < 1e-3);
        }
        assert_eq!(
            flips, 2,
            "the Frenet normal reverses at both interior inflections"
        );
    }

    /// Arc length of `curve` at parameter `t` (by bisection on the table's inverse).
    fn table_arc_length(
        table: &crate::geometry::analytic::ArcLengthTable,
        curve: &dyn ParametricCurve,
        t: Real,
    ) -> Real {
        let (mut lo, mut hi) = (0.0, table.length());
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if table.parameter_at(curve, mid) < t {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    #[test]
    fn frames_are_continuous_across_the_integration_grid() {
        // Off-grid frames take one more reflection step from the grid point below; across a grid point the
        // field must stay Lipschitz with the smooth rate |R0,s|_F/|K0| = √2 (0.1 % margin covers the O(ε²)
        // and round-off terms at ε ≥ 10⁻⁹).
        let fit = fit_curve(&helix(), 6, 40, &FitSettings::default()).unwrap();
        let field =
            FrameField::rotation_minimising(&fit.curve, None, &FrameSettings { steps: 256 })
                .unwrap();
        let rate = continuity_rate(&fit.curve, &field);
        assert!(
            (rate - 2f64.sqrt()).abs() < 1e-3 * 2f64.sqrt(),
            "rate {rate}"
        );
        let fit = fit_curve(&crown_wire(), 6, 40, &FitSettings::default()).unwrap();
        let field =
            FrameField::rotation_minimising(&fit.curve, None, &FrameSettings { steps: 256 })
                .unwrap();
        let rate = continuity_rate(&fit.curve, &field);
        assert!(rate < 2f64.sqrt() * (1.0 + 1e-3), "rate {rate}");
    }

    #[test]
    fn double_reflection_is_fourth_order() {
        // Error of d2 at u = 1 on the fitted helix (twisting: its Frenet-relative angle turns by 1.96 rad)
        // for N, 2N, 4N, … steps against a run with 2¹⁵ steps (whose own error is ~(128/32768)⁴ ≈ 4·10⁻¹⁰ of
        // the N = 128 error). Fourth order ⇒ each halving divides the error by 16; measured 16.09, 16.02,
        // 16.006 for N = 16 → 32 → 64 → 128; asserted within ±1.
        let fit = fit_curve(&helix(), 6, 40, &FitSettings::default()).unwrap();
        let d2_end = |steps| {
            let field = FrameField::rotation_minimising(&fit.curve, None, &FrameSettings { steps })
                .unwrap();
            field
                .at(&fit.curve, 1.0)
                .unwrap()
                .rotation
                .column(1)
                .into_owned()
        };
        let reference = d2_end(1 << 15);
        let errors: Vec<Real> = [16, 32, 64, 128]
            .iter()
            .map(|&n| (d2_end(n) - reference).norm())
            .collect();
        println!("double reflection: errors of d2(1) for 16, 32, 64, 128 steps: {errors:?}");
        for w in errors.windows(2) {
            let ratio = w[0] / w[1];
            assert!((ratio - 16.0).abs() < 1.0, "errors {errors:?}");
        }
        // The default resolution is at round-off on this curve.
        assert!((d2_end(FrameSettings::default().steps) - reference).norm() < 1e-11);
    }
}
