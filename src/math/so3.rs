//! SO(3) maps for the rod kinematics: hat/vee, the exponential map (Rodrigues, with a small-angle series),
//! a logarithm robust near 0 and π, the right Jacobian `T(θ)` and the arc-length derivative of `T(θ(s)) θ,s`.
//!
//! Convention: a rotation's matrix columns are the directors `d1, d2, d3` in global coordinates;
//! increments compose on the right (material), `R ← R exp(θ̃)`. For `R(s) = exp(θ̃(s))`,
//! `axial(Rᵀ R,s) = T(θ) θ,s` with `T(θ) = I − (1 − cos θ)/θ² θ̃ + (θ − sin θ)/θ³ θ̃²`.

use super::{Mat3, Real, Rot3, Vec3};

/// The skew matrix `ṽ` with `ṽ h = v × h`.
pub fn hat(v: &Vec3) -> Mat3 {
    todo!("{v}")
}

/// The axial vector of the skew-symmetric part of `m` (`vee(hat(v)) = v`).
pub fn vee(m: &Mat3) -> Vec3 {
    todo!("{m}")
}

/// `exp(θ̃)` by Rodrigues' formula, with Taylor branches in `θ²` for small angles.
pub fn exp(theta: &Vec3) -> Rot3 {
    todo!("{theta}")
}

/// The rotation vector `θ` with `|θ| ≤ π` and `exp(θ̃) = R`; robust near 0 and near π.
pub fn log(r: &Rot3) -> Vec3 {
    todo!("{r}")
}

/// The right Jacobian `T(θ)`: `axial(exp(θ̃)ᵀ d exp(θ̃)) = T(θ) dθ`.
pub fn right_jacobian(theta: &Vec3) -> Mat3 {
    todo!("{theta}")
}

/// `w = T(θ) θ,s` and its arc-length derivative `w,s = d/ds[T(θ(s)) θ,s]`, given `θ, θ,s, θ,ss` at a point.
pub fn right_jacobian_rate(theta: &Vec3, theta_s: &Vec3, theta_ss: &Vec3) -> (Vec3, Vec3) {
    todo!("{theta} {theta_s} {theta_ss}")
}
