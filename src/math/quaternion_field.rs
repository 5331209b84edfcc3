//! An objective, path-independent rotation field along a rod (issue 36). Each control point carries its rotation
//! from the reference configuration as a unit quaternion `ρ_a`; they are blended by the basis functions and
//! normalised, and the section's rotation is that blend applied to the reference frame:
//! ```text
//! ρ(s) = Σ_a N_a(s) ρ_a,      P(s) = R(ρ(s) / |ρ(s)|),      R(s) = P(s) R0(s),
//! ```
//! the normalised quaternion blend of Weeger, Narayanan & Dunn (*Nonlinear Dyn.* 2019; Weeger et al.,
//! *Isogeometric collocation methods for Cosserat rods and rod structures*, CMAME 316, 2017), here of the
//! rotations from the reference.
//!
//! **Why this one.** The paper (and Simo & Vu-Quoc) keep a rotation and a curvature at every collocation point and
//! update them by interpolated increments; the configuration that results depends on the increments that led to
//! it, and it is not objective (Crisfield & Jelenić, *Proc. R. Soc. A* 455, 1999): a rigid rotation of a deformed
//! rod strains it, an elastic load taken off in other steps leaves another end state. Here the field is a function
//! of the current `ρ_a` alone, so it is path-independent; a rigid rotation `Q` (a unit quaternion `r`) maps every
//! `ρ_a` to `r ρ_a`, hence `ρ(s)` to `r ρ(s)` and `R` to `Q R`, and leaves the material curvature `K` and shear
//! strain `Γ = Rᵀ c,s − E1` unchanged: objective. Blending the rotations *from the reference* rather than the
//! sections' own keeps the reference exact — `ρ_a = 1` gives `R = R0` and `K = K0`, the frames' own, to round-off
//! (a blend of the frames themselves would carry the spline's interpolation error into the reference curvature:
//! 2.6e-5 of a quarter ring's, p = 4, n = 12, where the rational patch is exact) — and a motion without rotation
//! (a ring's uniform contraction) rotates nothing. Crisfield & Jelenić's own remedy interpolates rotation vectors
//! relative to a reference rotation per element and fails where the rotation within it nears π; the normalised
//! blend needs no reference and keeps the spline's approximation order (`ρ` is a degree-p spline; the
//! normalisation is smooth where `|ρ| > 0`, which neighbouring control quaternions in one hemisphere guarantee,
//! `ρ_a · ρ_b > 0`: the increments turn them continuously from 1, and a patch rolled into a full circle turns
//! them by 2π/n apart).
//!
//! **Accuracy.** Keeping every `ρ_a` a unit quaternion costs accuracy: the spline of a smoothly turning field
//! has control quaternions longer than 1 (its control polygon lies outside the sphere), which unit ones cannot
//! match, and the normalised blend's error then decreases more slowly than the positions' (the 45° bend at
//! p = 8, n = 40: 3.2e-6 from the shooting reference against the paper's field's 1.9e-7). Interpolating the
//! rotation vectors `log(P_rᵀ P_a)` relative to one reference rotation per patch instead (Crisfield & Jelenić's
//! remedy) measured 7.8e-8 there, with the same accuracy as the paper's field at p = 6 (n = 20, 40, 80:
//! 6.63e-3, 2.82e-5, 2.28e-7 against 6.47e-3, 2.74e-5, 2.16e-7), but only its residual was tried, not its
//! tangent, and it needs the patch's rotation from its reference to stay below π (a reference per collocation
//! point instead measured 40 to 800 times further off). Issue 36.
//!
//! The functions here are those of the blend `P` alone (`q` below stands for `ρ`); `R0`, `K0` enter where the
//! solver puts them together (`crate::solver::state::State::sync_rotations` and the assembly's rotation basis).
//!
//! **Kinematics.** With `n = q·q` and the Hamilton product, the material rate of turn `ω = axial(Pᵀ P,s)` of the
//! blend and its arc-length derivative are (`Im` the vector part; `q̄,s ⊗ q,s` is real)
//! ```text
//! ω = 2 Im(q̄ ⊗ q,s) / n,      ω,s = 2 Im(q̄ ⊗ q,ss) / n − 2 n,s Im(q̄ ⊗ q,s) / n²,   n,s = 2 q·q,s.
//! ```
//!
//! **Linearisation.** A material increment of a control quaternion, `q_a ← q_a ⊗ exp(v_a / 2)` (first order:
//! `δq_a = q_a ⊗ (0, v_a/2)`), turns the blend at `s` by the material increment
//! ```text
//! δψ(s) = 2 Im(q̄ ⊗ δq) / n = Σ_a X_a(s) v_a,      X_a = N_a M(z_a),   z_a = q̄ ⊗ q_a / n,
//! ```
//! with `M(w, v) = w I + v̂` the matrix of `x ↦ Im((w, v) ⊗ (0, x))` (the part of `δq` along `q` only rescales it).
//! Where every `q_a` is equal, `z_a = 1` and `X_a = N_a I`: the paper's `δΘ = Σ N_a δθ_a`. The tangent needs
//! `δψ,s` and `δψ,ss` too, whose matrices are the derivatives of `X_a` ([`rotation_basis`]).

use super::{Mat3, Real, Vec3};
use nalgebra::{Quaternion, UnitQuaternion};

/// A quaternion `(w, x, y, z)`.
pub type Quat = Quaternion<Real>;

/// The unit quaternion of the rotation matrix `rotation`.
pub fn quaternion_of(rotation: &Mat3) -> Quat {
    UnitQuaternion::from_matrix(rotation).into_inner()
}

/// The rotation matrix of a non-zero quaternion (normalised here).
pub fn rotation_of(q: &Quat) -> Mat3 {
    UnitQuaternion::new_normalize(*q)
        .to_rotation_matrix()
        .into_inner()
}

/// `q_a ⊗ exp(δθ / 2)`, normalised: a material increment `δθ` of a unit quaternion (module docs).
pub fn turned(q: &Quat, theta: &Vec3) -> Quat {
    let r = q * UnitQuaternion::from_scaled_axis(*theta).into_inner();
    r / r.norm()
}

/// The blend `q`, `q,s`, `q,ss` at a point of the control quaternions `quats` with the basis rows `basis`
/// (`[N, N,s, N,ss]` of each, in the same order).
pub fn blend(quats: &[Quat], basis: &[[Real; 3]]) -> [Quat; 3] {
    let mut out = [Quat::new(0.0, 0.0, 0.0, 0.0); 3];
    for (q, row) in quats.iter().zip(basis) {
        for (o, b) in out.iter_mut().zip(row) {
            *o += q * *b;
        }
    }
    out
}

/// The rotation `P`, material rate of turn `ω` and its derivative `ω,s` of the blend `[q, q,s, q,ss]` (module
/// docs, *Kinematics*).
pub fn kinematics(q: &[Quat; 3]) -> (Mat3, Vec3, Vec3) {
    let [q0, q1, q2] = q;
    let n = q0.dot(q0);
    let n_s = 2.0 * q0.dot(q1);
    let bar = q0.conjugate();
    let a = (bar * q1).imag();
    let kappa = a * (2.0 / n);
    let kappa_s = (bar * q2).imag() * (2.0 / n) - a * (2.0 * n_s / (n * n));
    (rotation_of(q0), kappa, kappa_s)
}

/// `M(w, v) = w I + v̂`, the matrix of `x ↦ Im((w, v) ⊗ (0, x))`.
fn product_matrix(z: &Quat) -> Mat3 {
    Mat3::identity() * z.w + super::so3::hat(&z.imag())
}

/// The matrices `[X_a, X_a,s, X_a,ss]` of the blend's material increment `δψ = Σ X_a v_a` and its arc-length
/// derivatives at a point with the blend `q` ([`blend`]) of the control quaternions `quats` and basis rows
/// `basis` (module docs, *Linearisation*).
pub fn rotation_basis(q: &[Quat; 3], quats: &[Quat], basis: &[[Real; 3]]) -> Vec<[Mat3; 3]> {
    let [q0, q1, q2] = q;
    let (b0, b1, b2) = (q0.conjugate(), q1.conjugate(), q2.conjugate());
    let n = q0.dot(q0);
    let n_s = 2.0 * q0.dot(q1);
    let n_ss = 2.0 * (q1.dot(q1) + q0.dot(q2));
    quats
        .iter()
        .zip(basis)
        .map(|(qa, row)| {
            // z = A / n with A = q̄ ⊗ q_a, and its derivatives.
            let (a0, a1, a2) = (b0 * qa, b1 * qa, b2 * qa);
            let z0 = a0 / n;
            let z1 = a1 / n - a0 * (n_s / (n * n));
            let z2 = a2 / n - a1 * (2.0 * n_s / (n * n)) - a0 * (n_ss / (n * n))
                + a0 * (2.0 * n_s * n_s / (n * n * n));
            let (m0, m1, m2) = (
                product_matrix(&z0),
                product_matrix(&z1),
                product_matrix(&z2),
            );
            let [n0, n1, n2] = *row;
            [
                m0 * n0,
                m0 * n1 + m1 * n0,
                m0 * n2 + m1 * (2.0 * n1) + m2 * n0,
            ]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::so3::exp;

    /// A smooth field of control quaternions: `q_a = exp((0.3 a, −0.2 a², 0.5) / 2)` turned by a fixed rotation.
    fn controls() -> Vec<Quat> {
        (0..4)
            .map(|a| {
                let a = a as Real;
                let r = exp(&Vec3::new(0.3 * a, -0.2 * a * a, 0.5));
                quaternion_of(r.matrix())
            })
            .collect()
    }

    /// Cubic Bernstein rows at parameter `t` (`s = t`: unit speed).
    fn bernstein(t: Real) -> Vec<[Real; 3]> {
        let u = 1.0 - t;
        vec![
            [u * u * u, -3.0 * u * u, 6.0 * u],
            [
                3.0 * t * u * u,
                3.0 * u * u - 6.0 * t * u,
                -12.0 * u + 6.0 * t,
            ],
            [
                3.0 * t * t * u,
                6.0 * t * u - 3.0 * t * t,
                6.0 * u - 12.0 * t,
            ],
            [t * t * t, 3.0 * t * t, 6.0 * t],
        ]
    }

    /// Source: the definition `K̂ = Rᵀ R,s` and its derivative, by central differences of the field in `s`
    /// (step 1e-5: truncation ~1e-10, round-off ~1e-11).
    #[test]
    fn the_curvature_is_the_fields_own_rate_of_turn() {
        let quats = controls();
        let at = |t: Real| kinematics(&blend(&quats, &bernstein(t)));
        let h = 1e-5;
        for t in [0.0, 0.3, 0.77, 1.0] {
            let (r, k, k_s) = at(t);
            let (rp, kp, _) = at(t + h);
            let (rm, km, _) = at(t - h);
            let dr = (rp - rm) / (2.0 * h);
            let numeric = crate::math::so3::vee(&(r.transpose() * dr));
            assert!((numeric - k).norm() < 1e-8, "t = {t}: {numeric} vs {k}");
            let numeric_s = (kp - km) / (2.0 * h);
            assert!(
                (numeric_s - k_s).norm() < 1e-7,
                "t = {t}: {numeric_s} vs {k_s}"
            );
        }
    }

    /// Source: the definition of `X_a` — the material increment of the section at `s` when control quaternion `a`
    /// turns by `ε δθ` is `δψ = vee(Pᵀ ∂P/∂ε)`, by central differences in `ε` (step 1e-5) — and `X_a,s`, `X_a,ss`
    /// as the `s`-derivatives of `X_a` and `X_a,s`, by central differences in `s` (step 1e-5; truncation ~1e-10).
    #[test]
    fn the_rotation_basis_is_the_derivative_of_the_field() {
        let quats = controls();
        let dtheta = Vec3::new(0.2, -0.7, 0.4);
        let h = 1e-5;
        let basis = |t: Real| rotation_basis(&blend(&quats, &bernstein(t)), &quats, &bernstein(t));
        for t in [0.0, 0.25, 0.6, 1.0] {
            let here = basis(t);
            let (after, before) = (basis(t + h), basis(t - h));
            let r = kinematics(&blend(&quats, &bernstein(t))).0;
            for (a, b) in here.iter().enumerate() {
                let turn = |e: Real| {
                    let mut q = quats.clone();
                    q[a] = turned(&q[a], &(dtheta * e));
                    kinematics(&blend(&q, &bernstein(t))).0
                };
                let d = crate::math::so3::vee(&(r.transpose() * (turn(h) - turn(-h)) / (2.0 * h)));
                assert!((b[0] * dtheta - d).norm() < 1e-8, "t = {t}, a = {a}: B");
                for i in 1..3 {
                    let numeric = (after[a][i - 1] - before[a][i - 1]) / (2.0 * h);
                    assert!(
                        (b[i] - numeric).norm() < 1e-7,
                        "t = {t}, a = {a}: derivative {i}"
                    );
                }
            }
        }
    }

    /// Source: objectivity (module docs): turning every control quaternion by the same rotation turns the field by
    /// it and leaves `K`, `K,s` unchanged, to round-off.
    #[test]
    fn a_rigid_rotation_turns_the_field_and_keeps_its_curvature() {
        let quats = controls();
        let r = quaternion_of(exp(&Vec3::new(1.1, -2.0, 0.4)).matrix());
        let turned: Vec<Quat> = quats.iter().map(|q| r * q).collect();
        for t in [0.0, 0.4, 1.0] {
            let (r0, k0, k0_s) = kinematics(&blend(&quats, &bernstein(t)));
            let (r1, k1, k1_s) = kinematics(&blend(&turned, &bernstein(t)));
            assert!((rotation_of(&r) * r0 - r1).norm() < 1e-14);
            assert!((k0 - k1).norm() < 1e-14 && (k0_s - k1_s).norm() < 1e-13);
        }
    }
}
