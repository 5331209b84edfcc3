//! An objective, path-independent rotation field along a rod (issue 36). Each control point carries its rotation
//! from the reference configuration, `P_a` (stored as a unit quaternion `ρ_a`); within a patch they are
//! interpolated as rotation vectors relative to one reference rotation `P_r` of the patch, and the section's
//! rotation is that field applied to the reference frame:
//! ```text
//! θ_a = log(P_rᵀ P_a),   θ(s) = Σ_a N_a(s) θ_a,   P(s) = P_r exp(θ̃(s)),   R(s) = P(s) R0(s),
//! ```
//! Crisfield & Jelenić's interpolation of rotations relative to a reference rotation (*Proc. R. Soc. A* 455,
//! 1999), with the patch in place of their element.
//!
//! **Why this one.** The paper (and Simo & Vu-Quoc) keep a rotation and a curvature at every collocation point and
//! update them by interpolated increments; the configuration that results depends on the increments that led to
//! it, and it is not objective (Crisfield & Jelenić 1999): a rigid rotation of a deformed rod strains it, an
//! elastic load taken off in other steps leaves another end state. Here the field is a function of the current
//! `P_a` alone, so it is path-independent; a rigid rotation `Q` maps every `P_a` to `Q P_a`, leaves every
//! `P_rᵀ P_a` and so `θ(s)` unchanged, maps `P` to `Q P` and `R` to `Q R`, and leaves the material curvature `K`
//! and shear strain `Γ = Rᵀ c,s − E1` unchanged: objective. Interpolating the rotations *from the reference*
//! keeps the reference exact (`P_a = I` gives `R = R0`, `K = K0` to round-off) and a motion without rotation (a
//! ring's uniform contraction) rotates nothing.
//!
//! **The reference** is the rotation of the patch's middle control point, or for an even number of control points
//! the geodesic midpoint of its two middle ones, `P_r = P_m exp(½ φ̃)`, `φ = log(P_mᵀ P_m+1)`
//! (`crate::solver::discretisation::PatchRange::references`). Either is the same whichever end the patch starts
//! from, so a patch and its mirror image under a symmetry cut (which may run the other way) have mirror-image
//! fields, and a symmetry-reduced model matches the full device to round-off.
//!
//! **One reference per patch, not per element.** The field is a degree-p spline of rotation vectors in one chart
//! of SO(3), a smooth map of a smooth spline, so it keeps the spline's approximation order. A reference per
//! knot span or per collocation point changes the chart from point to point, and the control rotations then mean
//! different fields in neighbouring spans: measured on the 45° bend (p = 6, n = 40), a reference per collocation
//! point was 40 to 800 times further from the shooting solution than one per patch. The price is that every
//! collocation point of a patch depends on the reference's rotation: one or two dense block columns per patch,
//! which the block solver moves to its border with the patch ends (`crate::solver::block`).
//!
//! **Turning by more than π.** `log` returns `|θ_a| ≤ π`; a patch that turns by more than π from its middle (a
//! cantilever rolled into a full circle turns by π at each end) would jump there from one branch to the other.
//! The rotation vectors are therefore *unwrapped*: walking outward from the reference, each `θ_a` is the one of
//! the equivalent vectors `(|θ| + 2πk) θ/|θ|` nearest its inner neighbour's, so the chart holds while each side
//! of a patch turns by less than 2π from its middle (where `exp`'s differential, `T`, is singular; a patch
//! turning by 4π in all fails there: refine it into more patches).
//!
//! Before this field, a normalised blend of the control quaternions (Weeger et al., CMAME 316, 2017) was tried:
//! objective and local, but unit control quaternions cannot reproduce a turning field's spline, whose control
//! polygon lies outside the sphere, and its error fell more slowly than the positions' (the 45° bend at p = 8,
//! n = 40: 3.2e-6 from the shooting reference against the paper's field's 1.79e-7 and this field's 8.3e-8 to
//! 8.6e-8, near the round-off floor; the test `the_objective_field_converges_to_the_shooting_reference` has the
//! table).
//!
//! **Kinematics.** With `T` the right Jacobian (`crate::math::so3::right_jacobian`), the material rate of turn of
//! `P` is `ω = axial(Pᵀ P,s) = T(θ) θ,s` and `ω,s = d/ds[T(θ) θ,s]` (`crate::math::so3::right_jacobian_rate`).
//!
//! **Linearisation.** Under material increments of the control rotations, `P_a ← P_a exp(ṽ_a)`, the reference
//! turns by `v_r = A_m v_m + A_m+1 v_m+1` with (from `φ ← φ + T(φ)⁻¹ v_m+1 − T(−φ)⁻¹ v_m`)
//! ```text
//! A_m = exp(½ φ̃)ᵀ − ½ T(½ φ) T(−φ)⁻¹,   A_m+1 = ½ T(½ φ) T(φ)⁻¹      (A_m + A_m+1 = I for one middle point),
//! ```
//! `P_rᵀ P_a ← exp(−ṽ_r) exp(θ̃_a) exp(ṽ_a)`, so `δθ_a = T(θ_a)⁻¹ v_a − T(−θ_a)⁻¹ v_r`, and
//! `P(s) ← P_r exp(ṽ_r) exp(θ̃ + δθ̃)` turns the section at `s` by the material increment
//! ```text
//! δψ(s) = Σ_a X_a(s) v_a + Y(s) v_r,   X_a = N_a T(θ) T(θ_a)⁻¹,   Y = exp(θ̃)ᵀ − T(θ) Σ_a N_a T(−θ_a)⁻¹.
//! ```
//! The tangent needs `δψ,s` and `δψ,ss` too: the `s`-derivatives of `X_a` and `Y` ([`rotation_basis`]). At a patch
//! end (`N_a(0) = δ_a0`) `X_0 = I`, `Y = exp(θ̃_0)ᵀ − T(θ_0) T(θ_0)⁻¹ exp(θ̃_0)ᵀ = 0` (`T(−θ) = exp(θ̃) T(θ)`):
//! the end's section turns with its own control point alone.

use super::so3::{
    exp, hat, left_jacobian_inverse, right_jacobian, right_jacobian_along, right_jacobian_inverse,
    right_jacobian_rate,
};
use super::{Mat3, Real, Vec3};
use nalgebra::{Quaternion, UnitQuaternion};
use std::f64::consts::PI;

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

/// `q ⊗ exp(δθ / 2)`, normalised: a material increment `δθ` of a unit quaternion.
pub fn turned(q: &Quat, theta: &Vec3) -> Quat {
    let r = q * UnitQuaternion::from_scaled_axis(*theta).into_inner();
    r / r.norm()
}

/// The rotation vector (`|θ| ≤ π`) of the unit quaternion `q`.
fn rotation_vector(q: &Quat) -> Vec3 {
    let q = if q.w < 0.0 { -*q } else { *q };
    let v = q.imag();
    let s = v.norm();
    // θ = 2 atan2(s, w) v/s; for tiny s, 2 atan2(s, w)/s = 2/w to O(s²).
    if s < 1e-12 {
        v * (2.0 / q.w)
    } else {
        v * (2.0 * s.atan2(q.w) / s)
    }
}

/// The equivalent rotation vector of `theta` (`(|θ| + 2πk) θ/|θ|`, any integer `k`) nearest `near`.
fn unwrapped(theta: Vec3, near: &Vec3) -> Vec3 {
    let angle = theta.norm();
    // A turn by (almost) nothing: its other equivalents, multiples of 2π, are where `T` is singular anyway.
    if angle <= 1e-12 {
        return theta;
    }
    let axis = theta / angle;
    let turns = ((near.dot(&axis) - angle) / (2.0 * PI)).round();
    axis * (angle + 2.0 * PI * turns)
}

/// The reference rotation `P_r` (a unit quaternion) of a patch whose middle control points' rotations are
/// `first` and `second` (the same for an odd number of control points), their geodesic midpoint, and the
/// matrices `[A_m, A_m+1]` of its material increment (module docs, *The reference* and *Linearisation*).
pub fn reference_rotation(first: &Quat, second: &Quat) -> (Quat, [Mat3; 2]) {
    let phi = rotation_vector(&(first.conjugate() * second));
    let half = phi * 0.5;
    let t_half = right_jacobian(&half) * 0.5;
    let a_second = t_half * right_jacobian_inverse(&phi);
    let a_first = exp(&half).matrix().transpose() - t_half * left_jacobian_inverse(&phi);
    (turned(first, &half), [a_first, a_second])
}

/// The unwrapped rotation vectors `θ_a = log(P_rᵀ P_a)` of one patch's control rotations `quats` relative to
/// the reference rotation `reference` ([`reference_rotation`]), unwrapped outward from the control point at
/// index `middle` (module docs), written to `out`.
pub fn relative_rotations(quats: &[Quat], reference: &Quat, middle: usize, out: &mut [Vec3]) {
    let inverse = reference.conjugate();
    out[middle] = rotation_vector(&(inverse * quats[middle]));
    for a in middle + 1..quats.len() {
        out[a] = unwrapped(rotation_vector(&(inverse * quats[a])), &out[a - 1]);
    }
    for a in (0..middle).rev() {
        out[a] = unwrapped(rotation_vector(&(inverse * quats[a])), &out[a + 1]);
    }
}

/// `[θ, θ,s, θ,ss]` at a point from the rotation vectors `thetas` of its control points and their basis rows
/// `basis` (`[N, N,s, N,ss]` of each, in the same order).
pub fn interpolate(thetas: &[Vec3], basis: &[[Real; 3]]) -> [Vec3; 3] {
    let mut out = [Vec3::zeros(); 3];
    for (t, row) in thetas.iter().zip(basis) {
        for (o, b) in out.iter_mut().zip(row) {
            *o += t * *b;
        }
    }
    out
}

/// The rotation `P = P_r exp(θ̃)`, material rate of turn `ω` and its derivative `ω,s` at a point with
/// `[θ, θ,s, θ,ss]` ([`interpolate`]) and the patch's reference rotation `P_r` as the quaternion `reference`
/// ([`reference_rotation`]; module docs, *Kinematics*).
pub fn kinematics(reference: &Quat, theta: &[Vec3; 3]) -> (Mat3, Vec3, Vec3) {
    let (w, w_s) = right_jacobian_rate(&theta[0], &theta[1], &theta[2]);
    (rotation_of(reference) * exp(&theta[0]).matrix(), w, w_s)
}

/// The matrices of the material increment `δψ = Σ_a X_a v_a + Y v_r` at a point and of its arc-length
/// derivatives (module docs, *Linearisation*): `[X_a, X_a,s, X_a,ss]` for each control point of the point's
/// support (rotation vectors `thetas`, basis rows `basis`) and `[Y, Y,s, Y,ss]` for the patch's reference,
/// given the point's `[θ, θ,s, θ,ss]` ([`interpolate`]).
pub fn rotation_basis(
    theta: &[Vec3; 3],
    thetas: &[Vec3],
    basis: &[[Real; 3]],
) -> (Vec<[Mat3; 3]>, [Mat3; 3]) {
    let [t0, t1, t2] = right_jacobian_along(theta);
    let mut l = [Mat3::zeros(); 3];
    let support = thetas
        .iter()
        .zip(basis)
        .map(|(ta, &[n0, n1, n2])| {
            let c = right_jacobian_inverse(ta);
            let la = left_jacobian_inverse(ta);
            l[0] += la * n0;
            l[1] += la * n1;
            l[2] += la * n2;
            [
                t0 * c * n0,
                (t0 * n1 + t1 * n0) * c,
                (t0 * n2 + t1 * (2.0 * n1) + t2 * n0) * c,
            ]
        })
        .collect();
    // exp(θ̃)ᵀ and its derivatives: (Λᵀ),s = −ω̃ Λᵀ, (Λᵀ),ss = (ω̃ ω̃ − ω̃,s) Λᵀ, with ω = T θ,s.
    let w = t0 * theta[1];
    let w_s = t1 * theta[1] + t0 * theta[2];
    let lt = exp(&theta[0]).matrix().transpose();
    let wt = hat(&w);
    let y = [
        lt - t0 * l[0],
        -wt * lt - t1 * l[0] - t0 * l[1],
        (wt * wt - hat(&w_s)) * lt - t2 * l[0] - t1 * l[1] * 2.0 - t0 * l[2],
    ];
    (support, y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::so3::vee;

    /// Control quaternions of a smoothly turning field: `q_a = exp((0.3 a, −0.2 a², 0.5 + 0.4 a) / 2)` turned
    /// by a fixed rotation, so their relative rotations exceed π/2 at the ends.
    fn controls() -> Vec<Quat> {
        (0..4)
            .map(|a| {
                let a = a as Real;
                let r = exp(&Vec3::new(0.3 * a, -0.2 * a * a, 0.5 + 0.4 * a));
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

    /// The two middle control points of the tests' four: the reference is their geodesic midpoint.
    const MIDDLE: [usize; 2] = [1, 2];

    /// The reference rotation of `quats` and the relative rotation vectors.
    fn relative(quats: &[Quat]) -> (Quat, [Mat3; 2], Vec<Vec3>) {
        let (reference, a) = reference_rotation(&quats[MIDDLE[0]], &quats[MIDDLE[1]]);
        let mut thetas = vec![Vec3::zeros(); quats.len()];
        relative_rotations(quats, &reference, MIDDLE[0], &mut thetas);
        (reference, a, thetas)
    }

    /// `P`, `ω`, `ω,s` at `t` of the field of `quats`.
    fn field(quats: &[Quat], t: Real) -> (Mat3, Vec3, Vec3) {
        let (reference, _, thetas) = relative(quats);
        kinematics(&reference, &interpolate(&thetas, &bernstein(t)))
    }

    /// Source: the definition `ω̃ = Pᵀ P,s` and its derivative, by central differences of the field in `s`
    /// (step 1e-5: truncation ~1e-10, round-off ~1e-11).
    #[test]
    fn the_curvature_is_the_fields_own_rate_of_turn() {
        let quats = controls();
        let h = 1e-5;
        for t in [0.0, 0.3, 0.77, 1.0] {
            let (r, k, k_s) = field(&quats, t);
            let (rp, kp, _) = field(&quats, t + h);
            let (rm, km, _) = field(&quats, t - h);
            let numeric = vee(&(r.transpose() * (rp - rm) / (2.0 * h)));
            assert!((numeric - k).norm() < 1e-8, "t = {t}: {numeric} vs {k}");
            let numeric_s = (kp - km) / (2.0 * h);
            assert!(
                (numeric_s - k_s).norm() < 1e-7,
                "t = {t}: {numeric_s} vs {k_s}"
            );
        }
    }

    /// Source: the field interpolates the control rotations at the ends of an open patch (`N_a(0) = δ_a0`):
    /// `P(0) = P_0`, `P(1) = P_3`, to round-off — the unwrapped rotation vectors name the same rotations.
    #[test]
    fn the_field_passes_through_its_end_control_rotations() {
        let quats = controls();
        for (t, a) in [(0.0, 0), (1.0, 3)] {
            let (p, _, _) = field(&quats, t);
            assert!((p - rotation_of(&quats[a])).norm() < 1e-14, "t = {t}");
        }
    }

    /// Source: the definition of `X_a` and `Y` — the material increment of the section at `s` when control
    /// rotation `a` turns by `ε δθ` is `δψ = vee(Pᵀ ∂P/∂ε)`, by central differences in `ε` (step 1e-5), to be
    /// `X_a δθ` (plus `Y δθ` for the reference) — and their `s`-derivatives, by central differences in `s`
    /// (step 1e-5; truncation ~1e-10).
    #[test]
    fn the_rotation_basis_is_the_derivative_of_the_field() {
        let quats = controls();
        let (_, a, thetas) = relative(&quats);
        let dtheta = Vec3::new(0.2, -0.7, 0.4);
        let h = 1e-5;
        // Per control point the three matrices of its column: X_a, plus Y A_m for the middle ones.
        let columns = |t: Real| -> Vec<[Mat3; 3]> {
            let basis = bernstein(t);
            let (mut x, y) = rotation_basis(&interpolate(&thetas, &basis), &thetas, &basis);
            for (m, am) in MIDDLE.iter().zip(&a) {
                for (xm, ym) in x[*m].iter_mut().zip(&y) {
                    *xm += ym * am;
                }
            }
            x
        };
        for t in [0.0, 0.25, 0.6, 1.0] {
            let here = columns(t);
            let (after, before) = (columns(t + h), columns(t - h));
            let p = field(&quats, t).0;
            for (a, b) in here.iter().enumerate() {
                let turn = |e: Real| {
                    let mut q = quats.clone();
                    q[a] = turned(&q[a], &(dtheta * e));
                    field(&q, t).0
                };
                let d = vee(&(p.transpose() * (turn(h) - turn(-h)) / (2.0 * h)));
                assert!((b[0] * dtheta - d).norm() < 1e-8, "t = {t}, a = {a}: X");
                for i in 1..3 {
                    let numeric = (after[a][i - 1] - before[a][i - 1]) / (2.0 * h);
                    assert!(
                        (b[i] - numeric).norm() < 1e-6,
                        "t = {t}, a = {a}: derivative {i}: {} against {numeric}",
                        b[i]
                    );
                }
            }
        }
    }

    /// Source: objectivity (module docs): turning every control rotation by the same rotation turns the field by
    /// it and leaves `ω`, `ω,s` unchanged, to round-off.
    #[test]
    fn a_rigid_rotation_turns_the_field_and_keeps_its_curvature() {
        let quats = controls();
        let r = quaternion_of(exp(&Vec3::new(1.1, -2.0, 0.4)).matrix());
        let turned: Vec<Quat> = quats.iter().map(|q| r * q).collect();
        for t in [0.0, 0.4, 1.0] {
            let (p0, k0, k0_s) = field(&quats, t);
            let (p1, k1, k1_s) = field(&turned, t);
            assert!((rotation_of(&r) * p0 - p1).norm() < 1e-14);
            assert!((k0 - k1).norm() < 1e-13 && (k0_s - k1_s).norm() < 1e-12);
        }
    }

    /// Source: a uniform turn about one axis by 2π over a patch — the rod rolled into a full circle — is the
    /// rotation-vector line `θ(s) = 2π (s − ½) e3` relative to the middle (the reference, the midpoint of the
    /// middle two control rotations at ∓π/3), whose ends (±π) `log` alone would put on either branch.
    /// Unwrapped, the relative rotation vectors lie on that line (to round-off) and the
    /// field's rate of turn is 2π everywhere; the control points are the line's own (a straight line's spline
    /// control points are its values at the Greville abscissae: 0, ⅓, ⅔, 1 for the cubic).
    #[test]
    fn a_patch_rolled_into_a_full_circle_keeps_its_chart() {
        let axis = Vec3::new(0.0, 0.0, 1.0);
        let at = |g: Real| 2.0 * PI * (g - 0.5);
        let greville = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0];
        let base = quaternion_of(exp(&Vec3::new(0.3, 0.1, -0.2)).matrix());
        let quats: Vec<Quat> = greville
            .iter()
            .map(|&g| base * quaternion_of(exp(&(axis * at(g))).matrix()))
            .collect();
        let (reference, _, thetas) = relative(&quats);
        assert!((rotation_of(&reference) - rotation_of(&base)).norm() < 1e-14);
        for (theta, g) in thetas.iter().zip(greville) {
            assert!((theta - axis * at(g)).norm() < 1e-12, "{theta}");
        }
        for t in [0.0, 0.5, 1.0] {
            let (_, w, w_s) = kinematics(&reference, &interpolate(&thetas, &bernstein(t)));
            assert!(
                (w - axis * 2.0 * PI).norm() < 1e-12 && w_s.norm() < 1e-11,
                "{w}"
            );
        }
    }
}
