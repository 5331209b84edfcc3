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
    /// Parametric speed `J = |c0'(u)|` [length].
    pub jacobian: Real,
    /// `J' = dJ/du` [length].
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
fn double_reflection(x0: &Vec3, t0: &Vec3, r0: &Vec3, x1: &Vec3, t1: &Vec3) -> Vec3 {
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
