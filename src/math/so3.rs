//! SO(3) maps for the rod kinematics: hat/vee, the exponential map (Rodrigues, with a small-angle series),
//! a logarithm robust near 0 and π, the right Jacobian `T(θ)`, its inverse, the left Jacobian, and the
//! arc-length derivative of `T(θ(s)) θ,s`.
//!
//! # Frame convention
//!
//! * A rotation's matrix **columns are the directors** `d1, d2, d3` in global coordinates: `R = [d1 d2 d3]`,
//!   so `R e_i = d_i` maps material (body) components to spatial ones, `v = R V`. `d1` is the rod axis.
//! * Increments are **material** (compose on the right): `R ← R exp(δΘ̃)`. Consequently the Jacobian that
//!   matters is the *right* one: for `R(s) = exp(θ̃(s))`, `axial(Rᵀ R,s) = T(θ) θ,s`, with
//!   `T(θ) = I − (1 − cos θ)/θ² θ̃ + (θ − sin θ)/θ³ θ̃²` (θ = |θ|).
//! * `θ̃ = hat(θ)` is the skew matrix with `θ̃ h = θ × h`; `vee`/`axial` is its inverse on skew matrices.
//! * Hand check (tested): `exp` of a 120° turn about `(1, 1, 1)/√3` maps `e1 → e2 → e3 → e1`, i.e. the
//!   directors of that rotation are `d1 = e2, d2 = e3, d3 = e1`.
//!
//! # Coefficient functions and small angles
//!
//! Every map here is written with scalar coefficient functions of `x = θ² = θ·θ` (never of `θ = √x`, whose
//! derivative is singular at 0):
//!
//! | name | closed form | series (`x → 0`) |
//! |---|---|---|
//! | `σ(x)` | `sin θ / θ` | `Σ (−x)^k / (2k+1)!` |
//! | `a(x)` | `(1 − cos θ)/θ² = ½ σ(x/4)²` | `½ − x/24 + …` |
//! | `b(x)` | `(θ − sin θ)/θ³` | `Σ (−x)^k / (2k+3)!` |
//! | `c(x)` | `1/θ² − (1 + cos θ)/(2θ sin θ) = −σ'(x/4) / (2σ(x/4))` | `1/12 + x/720 + …` |
//!
//! and the derivatives `σ' = dσ/dx`, `a' = ¼ σ(x/4) σ'(x/4)`, `b' = db/dx`. The half-angle form of `a`
//! has no cancellation; `σ'`, `b` and `b'` do (their closed forms subtract nearly equal terms for small θ),
//! so each switches to a truncated Taylor series below a named threshold. Each threshold is placed where
//! the closed form's rounding error has fallen to one or two ulps (measured), and the number of series
//! terms is the smallest for which the first omitted term is below a quarter ulp there (both are tested).
//! `σ` has no cancellation; its series only removes the `0/0` at θ = 0. Hence the two branches of every
//! coefficient agree to a few ulps at the switch, and everything is smooth (analytic) in `θ` through 0.
//!
//! # Sources
//!
//! * Rodrigues' formula, material updates and the rod strains: J. C. Simo & L. Vu-Quoc (1986),
//!   *A three-dimensional finite-strain rod model. Part II: Computational aspects*, CMAME 58, 79–116.
//! * The tangent operator `T(θ)` and its inverse: A. Ibrahimbegović, F. Frey & I. Kožar (1995),
//!   *Computational aspects of vector-like parametrization of three-dimensional finite rotations*,
//!   IJNME 38, 3653–3673 (there written for spatial increments, i.e. our left Jacobian `Tᵀ`); A. Cardona &
//!   M. Géradin (1988), *A beam finite element non-linear theory with finite rotations*, IJNME 26,
//!   2403–2438; T. D. Barfoot (2017), *State Estimation for Robotics*, CUP, ch. 7 (right/left Jacobians
//!   and their inverses in the `cot(θ/2)` form).
//! * The logarithm near π (axis from the symmetric part, largest diagonal pivot): the pivoting idea of
//!   S. W. Shepperd (1978), *Quaternion from rotation matrix*, J. Guidance and Control 1(3), 223–224, and
//!   F. L. Markley (2008), *Unit quaternion from rotation matrix*, J. Guidance, Control, and Dynamics
//!   31(2), 440–442.

use super::{Mat3, Real, Rot3, Vec3};

// ---------------------------------------------------------------------------------------------------------
// Series switch thresholds (in x = θ² [rad²]) and term counts.
//
// Measured in binary64 against 50-digit references over [0.98, 1.02]× the threshold angle (closed form)
// and [0.5, 1]× (series); "ulp" means 2⁻⁵² relative.
// ---------------------------------------------------------------------------------------------------------

/// Largest `x = θ²` for which `σ(x) = sin θ/θ` is evaluated by its Taylor series (θ ≤ 0.5 rad).
///
/// The closed form has no cancellation (≤ 0.6 ulp for every θ > 0); the series exists only to remove the
/// `0/0` at θ = 0 (and the underflow of `x` for θ ≲ 1e-154). 0.25 is a threshold at which
/// [`SINC_SERIES_TERMS`] terms already truncate below a quarter ulp, with a series error ≤ 0.5 ulp.
const SINC_SERIES_MAX_ANGLE_SQ: Real = 0.25;
/// Number of Taylor terms of `σ` (first omitted term `x⁷/15!` ≈ 0.22 ulp of `σ` at the threshold).
const SINC_SERIES_TERMS: usize = 7;

/// Largest `x = θ²` for which `σ'(x) = (θ cos θ − sin θ)/(2θ³)` is evaluated by its Taylor series
/// (θ ≤ 1.5 rad).
///
/// The closed form subtracts two terms of size `θ` to get `θ³/3`: its relative rounding error grows like
/// `ε·3/θ²` (≈ 1040 ulp at θ = 0.05, 9 ulp at 0.5, 2.5 ulp at 1). For θ ≥ π/2, `θ cos θ` and `−sin θ` have
/// the same sign and there is no cancellation at all; at θ = 1.5 the closed form is within 1.2 ulp. Below,
/// [`SINC_PRIME_SERIES_TERMS`] terms keep the series within 1 ulp.
const SINC_PRIME_SERIES_MAX_ANGLE_SQ: Real = 2.25;
/// Number of Taylor terms of `σ'` (first omitted term below a quarter ulp at the threshold).
const SINC_PRIME_SERIES_TERMS: usize = 10;

/// Largest `x = θ²` for which `b(x) = (θ − sin θ)/θ³` is evaluated by its Taylor series (θ ≤ 1.5 rad).
///
/// The closed form subtracts `sin θ ≈ θ` from `θ` to get `θ³/6`: relative rounding error `≈ ε·6/θ²`
/// (≈ 790 ulp at θ = 0.05, 2.3 ulp at θ = 1, 1.1 ulp at θ = 1.5). Below 1.5 rad
/// [`B_SERIES_TERMS`] terms keep the series within 0.8 ulp.
const B_SERIES_MAX_ANGLE_SQ: Real = 2.25;
/// Number of Taylor terms of `b` (first omitted term below a quarter ulp at the threshold).
const B_SERIES_TERMS: usize = 10;

/// Largest `x = θ²` for which `b'(x) = (3 sin θ − θ(2 + cos θ))/(2θ⁵)` is evaluated by its Taylor series
/// (θ ≤ 3 rad).
///
/// The closed form is the worst of all: terms of size `3θ` cancel to `θ⁵/60`, relative rounding error
/// `≈ ε·180/θ⁴` (≈ 230 ulp at θ = 1, 8 ulp at 2, 2.2 ulp at 3). The series converges fast enough to be
/// used that far: [`B_PRIME_SERIES_TERMS`] terms keep it within 0.8 ulp up to θ = 3.
const B_PRIME_SERIES_MAX_ANGLE_SQ: Real = 9.0;
/// Number of Taylor terms of `b'` (first omitted term below a quarter ulp at the threshold).
const B_PRIME_SERIES_TERMS: usize = 13;

/// `cos θ` below which [`log`] takes the rotation axis from the symmetric part of `R` instead of the skew
/// part (i.e. θ > π/2).
///
/// The skew part is `sin θ n`: with absolute rounding `ε` in the entries of `R` its direction is good to
/// `ε/sin θ`, which blows up as θ → π. The symmetric part is `cos θ I + (1 − cos θ) n nᵀ`: its direction is
/// good to `ε/(1 − cos θ)`. At `cos θ = 0` both amplifications are ≤ π/2, so switching there keeps the axis
/// within a couple of ulps on both sides.
const LOG_SYMMETRIC_AXIS_BELOW_COS: Real = 0.0;

// ---------------------------------------------------------------------------------------------------------
// Taylor coefficient tables, built at compile time from their defining formula.
// ---------------------------------------------------------------------------------------------------------

/// `n!` as a float (exact up to 22!, correctly rounded products beyond; only tiny coefficients use those).
const fn factorial(n: usize) -> Real {
    let mut f = 1.0;
    let mut i = 2;
    while i <= n {
        f *= i as Real;
        i += 1;
    }
    f
}

/// Coefficients `c_k = (−1)^k / (2k + p)!` of `F_p(x) = Σ_k (−x)^k / (2k + p)!`, `k = 0 … N−1`.
///
/// `F_1 = σ = sin θ/θ`, `F_2 = a = (1 − cos θ)/θ²`, `F_3 = b = (θ − sin θ)/θ³` with `x = θ²`.
const fn taylor_coefficients<const N: usize>(p: usize) -> [Real; N] {
    let mut c = [0.0; N];
    let mut k = 0;
    while k < N {
        let magnitude = 1.0 / factorial(2 * k + p);
        c[k] = if k % 2 == 0 { magnitude } else { -magnitude };
        k += 1;
    }
    c
}

/// Coefficients of `F_p'(x) = Σ_k (−1)^(k+1) (k + 1) x^k / (2k + 2 + p)!` (term-wise derivative of
/// [`taylor_coefficients`]).
const fn taylor_derivative_coefficients<const N: usize>(p: usize) -> [Real; N] {
    let mut c = [0.0; N];
    let mut k = 0;
    while k < N {
        let magnitude = (k + 1) as Real / factorial(2 * k + 2 + p);
        c[k] = if k % 2 == 0 { -magnitude } else { magnitude };
        k += 1;
    }
    c
}

const SINC_COEFFICIENTS: [Real; SINC_SERIES_TERMS] = taylor_coefficients(1);
const SINC_PRIME_COEFFICIENTS: [Real; SINC_PRIME_SERIES_TERMS] = taylor_derivative_coefficients(1);
const B_COEFFICIENTS: [Real; B_SERIES_TERMS] = taylor_coefficients(3);
const B_PRIME_COEFFICIENTS: [Real; B_PRIME_SERIES_TERMS] = taylor_derivative_coefficients(3);

/// `Σ_k c_k x^k` by Horner's rule.
fn horner(coefficients: &[Real], x: Real) -> Real {
    coefficients.iter().rev().fold(0.0, |acc, &ck| acc * x + ck)
}

// ---------------------------------------------------------------------------------------------------------
// Coefficient functions of x = θ², each as series branch, closed branch and dispatcher.
// ---------------------------------------------------------------------------------------------------------

fn sinc_series(x: Real) -> Real {
    horner(&SINC_COEFFICIENTS, x)
}

fn sinc_closed(x: Real) -> Real {
    let angle = x.sqrt();
    angle.sin() / angle
}

/// `σ(x) = sin θ / θ` with `x = θ²`.
fn sinc(x: Real) -> Real {
    if x <= SINC_SERIES_MAX_ANGLE_SQ {
        sinc_series(x)
    } else {
        sinc_closed(x)
    }
}

fn sinc_prime_series(x: Real) -> Real {
    horner(&SINC_PRIME_COEFFICIENTS, x)
}

fn sinc_prime_closed(x: Real) -> Real {
    let angle = x.sqrt();
    let (sin, cos) = angle.sin_cos();
    (angle * cos - sin) / (2.0 * x * angle)
}

/// `σ'(x) = dσ/dx = (θ cos θ − sin θ)/(2θ³)`.
fn sinc_prime(x: Real) -> Real {
    if x <= SINC_PRIME_SERIES_MAX_ANGLE_SQ {
        sinc_prime_series(x)
    } else {
        sinc_prime_closed(x)
    }
}

/// `a(x) = (1 − cos θ)/θ² = ½ σ(x/4)²` (half-angle form: `1 − cos θ = 2 sin²(θ/2)`, no cancellation).
fn coefficient_a(x: Real) -> Real {
    let half = sinc(0.25 * x);
    0.5 * half * half
}

/// `a'(x) = da/dx = ¼ σ(x/4) σ'(x/4)`.
fn coefficient_a_prime(x: Real) -> Real {
    0.25 * sinc(0.25 * x) * sinc_prime(0.25 * x)
}

fn coefficient_b_series(x: Real) -> Real {
    horner(&B_COEFFICIENTS, x)
}

fn coefficient_b_closed(x: Real) -> Real {
    let angle = x.sqrt();
    (angle - angle.sin()) / (x * angle)
}

/// `b(x) = (θ − sin θ)/θ³`.
fn coefficient_b(x: Real) -> Real {
    if x <= B_SERIES_MAX_ANGLE_SQ {
        coefficient_b_series(x)
    } else {
        coefficient_b_closed(x)
    }
}

fn coefficient_b_prime_series(x: Real) -> Real {
    horner(&B_PRIME_COEFFICIENTS, x)
}

fn coefficient_b_prime_closed(x: Real) -> Real {
    let angle = x.sqrt();
    let (sin, cos) = angle.sin_cos();
    (3.0 * sin - angle * (2.0 + cos)) / (2.0 * x * x * angle)
}

/// `b'(x) = db/dx = (3 sin θ − θ(2 + cos θ))/(2θ⁵)`.
fn coefficient_b_prime(x: Real) -> Real {
    if x <= B_PRIME_SERIES_MAX_ANGLE_SQ {
        coefficient_b_prime_series(x)
    } else {
        coefficient_b_prime_closed(x)
    }
}

/// `c(x) = 1/θ² − (1 + cos θ)/(2θ sin θ) = (1 − (θ/2) cot(θ/2))/θ²`, the `θ̃²` coefficient of `T⁻¹`.
///
/// Written as `−σ'(x/4) / (2σ(x/4))` (from `sin h − h cos h = −2h³σ'(h²)`, `h = θ/2`), which inherits the
/// cancellation-free branches of `σ` and `σ'`. Singular where `σ(x/4) = 0`, i.e. θ = 2π, 4π, ….
fn coefficient_c(x: Real) -> Real {
    let quarter = 0.25 * x;
    -sinc_prime(quarter) / (2.0 * sinc(quarter))
}

// ---------------------------------------------------------------------------------------------------------
// Public maps.
// ---------------------------------------------------------------------------------------------------------

/// The skew matrix `ṽ` with `ṽ h = v × h`.
pub fn hat(v: &Vec3) -> Mat3 {
    Mat3::new(
        0.0, -v.z, v.y, //
        v.z, 0.0, -v.x, //
        -v.y, v.x, 0.0,
    )
}

/// The axial vector of the skew-symmetric part of `m` (`vee(hat(v)) = v`; `axial` in the docs).
///
/// `vee(m) = ½ (m₃₂ − m₂₃, m₁₃ − m₃₁, m₂₁ − m₁₂)`; the symmetric part of `m` is ignored.
pub fn vee(m: &Mat3) -> Vec3 {
    0.5 * Vec3::new(
        m[(2, 1)] - m[(1, 2)],
        m[(0, 2)] - m[(2, 0)],
        m[(1, 0)] - m[(0, 1)],
    )
}

/// `exp(θ̃)` by Rodrigues' formula (Simo & Vu-Quoc 1986),
/// `exp(θ̃) = I + (sin θ/θ) θ̃ + ((1 − cos θ)/θ²) θ̃²`, θ = |θ|.
///
/// Evaluated as `cos θ I + σ θ̃ + a θ θᵀ` (using `θ̃² = θθᵀ − θ² I`) with the coefficient functions of
/// `θ²` described in the module docs, so it is exact to rounding and smooth through θ = 0. The columns of
/// the result are the directors of the rotated frame; any angle is accepted (no reduction to `|θ| ≤ π`).
pub fn exp(theta: &Vec3) -> Rot3 {
    let x = theta.norm_squared();
    let sinc_angle = sinc(x);
    let a = coefficient_a(x);
    // cos θ = 1 − 2 sin²(θ/2) = 1 − a θ², consistent with the half-angle a in both branches.
    let cos = 1.0 - a * x;
    let m = Mat3::from_diagonal_element(cos)
        + hat(theta) * sinc_angle
        + (theta * theta.transpose()) * a;
    Rot3::from_matrix_unchecked(m)
}

/// The rotation vector `θ` with `|θ| ≤ π` and `exp(θ̃) = R`; robust near 0 and near π.
///
/// The angle is `atan2(|axial(R)|, (tr R − 1)/2)`, accurate to rounding for every angle (unlike `acos`
/// near 0 and π). The axis is taken
/// * for θ ≤ π/2 from the skew part, `axial(R) = sin θ n`, as `θ = axial(R)/σ(θ²)` (series near 0, exact
///   0 for the identity);
/// * for θ > π/2 from the symmetric part, `½(R + Rᵀ) − cos θ I = (1 − cos θ) n nᵀ`: its column with the
///   largest diagonal entry, normalised (Shepperd 1978; Markley 2008), with the sign chosen so that
///   `n · axial(R) ≥ 0`. For an exact half turn either sign is a valid logarithm; when `axial(R)` is
///   exactly zero the one returned has a non-negative component along the pivot axis.
///
/// `R` is assumed orthogonal to rounding (~1e-15); re-orthonormalisation is the caller's business.
/// Never returns NaN for finite input.
pub fn log(r: &Rot3) -> Vec3 {
    let m = r.matrix();
    let skew_axial = vee(m);
    let sin = skew_axial.norm();
    let cos = (0.5 * (m.trace() - 1.0)).clamp(-1.0, 1.0);
    let angle = sin.atan2(cos);
    if cos >= LOG_SYMMETRIC_AXIS_BELOW_COS {
        return skew_axial / sinc(angle * angle);
    }
    // (1 − cos θ) n nᵀ; with cos θ < 0 its largest diagonal entry is ≥ (1 − cos θ)/3 ≥ 1/3, so the pivot
    // column has norm ≥ 1/√3 and the division below is safe.
    let outer = 0.5 * (m + m.transpose()) - Mat3::from_diagonal_element(cos);
    let diagonal = outer.diagonal();
    let pivot = diagonal.imax();
    let column: Vec3 = outer.column(pivot).into_owned();
    let mut axis = column / column.norm();
    if axis.dot(&skew_axial) < 0.0 {
        axis = -axis;
    }
    angle * axis
}

/// The right Jacobian (material tangent operator)
/// `T(θ) = I − (1 − cos θ)/θ² θ̃ + (θ − sin θ)/θ³ θ̃²`, so that `axial(exp(θ̃)ᵀ d exp(θ̃)) = T(θ) dθ`
/// (Ibrahimbegović et al. 1995, transposed to material increments; Cardona & Géradin 1988).
///
/// For `R(s) = exp(θ̃(s))`: `axial(Rᵀ R,s) = T(θ) θ,s`. Properties: `T(θ) θ = θ`, `T(−θ) = T(θ)ᵀ`,
/// `exp(θ̃) T(θ) = T(θ)ᵀ`. Smooth through θ = 0 (`T(0) = I`).
pub fn right_jacobian(theta: &Vec3) -> Mat3 {
    let x = theta.norm_squared();
    let skew = hat(theta);
    Mat3::identity() - skew * coefficient_a(x) + skew * skew * coefficient_b(x)
}

/// The left (spatial) Jacobian `T(−θ) = T(θ)ᵀ = I + (1 − cos θ)/θ² θ̃ + (θ − sin θ)/θ³ θ̃²`:
/// `axial(d exp(θ̃) exp(θ̃)ᵀ) = T(θ)ᵀ dθ`, the operator for spatial increments `R ← exp(δθ̃) R`.
pub fn left_jacobian(theta: &Vec3) -> Mat3 {
    right_jacobian(&(-theta))
}

/// The inverse of the right Jacobian,
/// `T(θ)⁻¹ = I + ½ θ̃ + (1/θ² − (1 + cos θ)/(2θ sin θ)) θ̃²` (Cardona & Géradin 1988; Barfoot 2017,
/// ch. 7, in the equivalent form `(1 − (θ/2) cot(θ/2))/θ²`).
///
/// Maps a material angular velocity back to the rate of the rotation vector: `θ,s = T(θ)⁻¹ axial(Rᵀ R,s)`.
/// The `θ̃²` coefficient has a series branch near 0 (`1/12 + θ²/720 + …`, evaluated through the
/// cancellation-free `σ`, `σ'`).
///
/// **Singular as `|θ| → 2π`** (and at every multiple of 2π): there `T` itself is singular (`det T =
/// 2(1 − cos θ)/θ²`) and the coefficient blows up like `1/(2π − θ)`; the result is non-finite at exactly
/// 2π. Keep `|θ| < 2π` — any rotation vector from [`log`] (`|θ| ≤ π`) and any reasonable Newton increment is
/// far from it.
pub fn right_jacobian_inverse(theta: &Vec3) -> Mat3 {
    let x = theta.norm_squared();
    let skew = hat(theta);
    Mat3::identity() + skew * 0.5 + skew * skew * coefficient_c(x)
}

/// The inverse of the left Jacobian, `T(θ)⁻ᵀ = T(−θ)⁻¹ = I − ½ θ̃ + c(θ²) θ̃²`; singular as `|θ| → 2π`
/// like [`right_jacobian_inverse`].
pub fn left_jacobian_inverse(theta: &Vec3) -> Mat3 {
    right_jacobian_inverse(&(-theta))
}

/// `w = T(θ) θ,s` and its arc-length derivative `w,s = d/ds[T(θ(s)) θ,s]`, given `θ, θ,s, θ,ss` at a point.
///
/// With `x = θ·θ`, `u = θ × θ,s`, `v = θ × u = θ̃² θ,s` and the coefficients `a(x)`, `b(x)` of
/// [`right_jacobian`]:
/// ```text
/// w   = θ,s − a u + b v
/// w,s = θ,ss − a' x,s u − a θ × θ,ss + b' x,s v + b (θ,s × u + θ × (θ × θ,ss)),   x,s = 2 θ·θ,s
/// ```
/// (`θ,s × θ,s = 0` was used in `u,s = θ × θ,ss`). The derivatives `a' = da/dx`, `b' = db/dx` are taken with
/// respect to `θ²` and have their own series branches, so the result is exact to rounding also where
/// `θ(s)` passes through 0 — the case an axis–angle implementation gets wrong.
///
/// This feeds the curvature update `K,s ← Λᵀ K,s − w × (Λᵀ K) + w,s` after a Newton increment.
pub fn right_jacobian_rate(theta: &Vec3, theta_s: &Vec3, theta_ss: &Vec3) -> (Vec3, Vec3) {
    let x = theta.norm_squared();
    let x_s = 2.0 * theta.dot(theta_s);
    let a = coefficient_a(x);
    let b = coefficient_b(x);
    let a_prime = coefficient_a_prime(x);
    let b_prime = coefficient_b_prime(x);

    let u = theta.cross(theta_s);
    let v = theta.cross(&u);
    let u_s = theta.cross(theta_ss);
    let v_s = theta_s.cross(&u) + theta.cross(&u_s);

    let w = theta_s - u * a + v * b;
    let w_s = theta_ss - u * (a_prime * x_s) - u_s * a + v * (b_prime * x_s) + v_s * b;
    (w, w_s)
}

/// `T(θ(s))` and its first two arc-length derivatives `[T, T,s, T,ss]` along a curve of rotation vectors given by
/// `[θ, θ,s, θ,ss]` at a point ([`right_jacobian`]; used where a rotation field is interpolated in rotation
/// vectors, `crate::math::quaternion_field`).
///
/// Written as `T = (1 − b x) I − a θ̃ + b θ θᵀ` (`θ̃² = θ θᵀ − x I`, `x = θ·θ`) and evaluated in second-order dual
/// numbers (`num_dual::Dual2`) carrying `d/ds` and `d²/ds²`, so the derivatives of `a(x)` and `b(x)` come
/// without hand-derived second derivatives. The coefficients are their Taylor series in `x` up to `x = 2.25`
/// (14 terms: the first omitted one is below 1e-24 there) and the closed forms beyond, where neither cancels.
pub fn right_jacobian_along(theta: &[Vec3; 3]) -> [Mat3; 3] {
    use num_dual::{Dual2_64, DualNum};
    let t: [Dual2_64; 3] =
        std::array::from_fn(|i| Dual2_64::new(theta[0][i], theta[1][i], theta[2][i]));
    let x = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
    let (a, b) = if x.re < 2.25 {
        // a = Σ (−x)ᵏ/(2k + 2)!, b = Σ (−x)ᵏ/(2k + 3)!, by Horner from the last term.
        let (mut a, mut b) = (Dual2_64::from_re(0.0), Dual2_64::from_re(0.0));
        for k in (0..14).rev() {
            a = a * (-x) + 1.0 / factorial(2 * k + 2);
            b = b * (-x) + 1.0 / factorial(2 * k + 3);
        }
        (a, b)
    } else {
        let angle = x.sqrt();
        (
            (-angle.cos() + 1.0) / x,
            (angle - angle.sin()) / (x * angle),
        )
    };
    let diagonal = -(b * x) + 1.0;
    let mut out = [Mat3::zeros(); 3];
    for i in 0..3 {
        for j in 0..3 {
            let mut e = b * t[i] * t[j];
            if i == j {
                e += diagonal;
            }
            // −a θ̃: θ̃_ij = −ε_ijk θ_k.
            let k = 3 - i - j;
            if i != j {
                let sign = if (i + 1) % 3 == j { 1.0 } else { -1.0 };
                e += a * t[k] * sign;
            }
            out[0][(i, j)] = e.re;
            out[1][(i, j)] = e.v1;
            out[2][(i, j)] = e.v2;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    const EPS: Real = Real::EPSILON;

    /// Unit vector from spherical coordinates (`z ∈ [−1, 1]`, `phi ∈ [0, 2π)`), uniform on the sphere.
    fn unit(z: Real, phi: Real) -> Vec3 {
        let rho = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(rho * phi.cos(), rho * phi.sin(), z)
    }

    /// Strategy: a unit vector, uniform on the sphere.
    fn unit_vector() -> impl Strategy<Value = Vec3> {
        (-1.0..=1.0f64, 0.0..(2.0 * PI)).prop_map(|(z, phi)| unit(z, phi))
    }

    /// Strategy: a vector with components in `[−r, r]`.
    fn vector(r: Real) -> impl Strategy<Value = Vec3> {
        prop::array::uniform3(-r..=r).prop_map(Vec3::from)
    }

    fn config() -> ProptestConfig {
        ProptestConfig {
            cases: 512,
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x5e47_50c3),
            ..ProptestConfig::default()
        }
    }

    fn max_abs(m: &Mat3) -> Real {
        m.abs().max()
    }

    #[test]
    fn exp_120_degrees_about_diagonal_permutes_axes() {
        // Checks the frame convention on the hand-checked example of STYLE.md: a 120° turn about
        // (1,1,1)/√3 maps e1 → e2 → e3 → e1, so the columns (directors) of R are e2, e3, e1.
        // Reference: by symmetry of the cube's diagonal, worked out by hand.
        // Tolerance 1e-15: the entries are sums of three O(1) terms (cos, sin/√3·…, (1−cos)/3) each with
        // half-ulp errors, so ~2e-16 is expected; 1e-15 leaves a margin of a few ulps.
        let theta = Vec3::new(1.0, 1.0, 1.0).normalize() * (2.0 * PI / 3.0);
        let r = exp(&theta);
        let expected = Mat3::from_columns(&[Vec3::y(), Vec3::z(), Vec3::x()]);
        assert!(
            max_abs(&(r.matrix() - expected)) <= 1e-15,
            "R = {}",
            r.matrix()
        );
        assert!((r * Vec3::x() - Vec3::y()).norm() <= 1e-15);
        assert!((r * Vec3::y() - Vec3::z()).norm() <= 1e-15);
        assert!((r * Vec3::z() - Vec3::x()).norm() <= 1e-15);
    }

    #[test]
    fn exp_and_log_of_zero() {
        // Checks the identity: exp(0) = I and log(I) = 0 exactly (series branches, no 0/0).
        // Reference: definition. Tolerance: exact, both are computed without rounding at 0.
        assert_eq!(*exp(&Vec3::zeros()).matrix(), Mat3::identity());
        assert_eq!(log(&Rot3::identity()), Vec3::zeros());
        assert_eq!(right_jacobian(&Vec3::zeros()), Mat3::identity());
        assert_eq!(right_jacobian_inverse(&Vec3::zeros()), Mat3::identity());
    }

    #[test]
    fn log_of_half_turns_about_axes() {
        // Checks the exact-π branch: R = diag(1,−1,−1) etc. are half turns about e1, e2, e3; log must return
        // ±π e_i without NaN (the skew part is exactly zero, so acos/sin-based formulas give 0/0).
        // Reference: definition of a half turn. Tolerance: a few ulps of π.
        for i in 0..3 {
            let mut d = Vec3::repeat(-1.0);
            d[i] = 1.0;
            let r = Rot3::from_matrix_unchecked(Mat3::from_diagonal(&d));
            let theta = log(&r);
            let mut expected = Vec3::zeros();
            expected[i] = PI;
            assert!(theta.iter().all(|t| t.is_finite()));
            assert!((theta - expected).norm() <= 4.0 * EPS * PI, "θ = {theta}");
            assert!(max_abs(&(exp(&theta).matrix() - r.matrix())) <= 4.0 * EPS);
        }
    }

    proptest! {
        #![proptest_config(config())]

        #[test]
        fn hat_vee_round_trip_and_cross_product(a in vector(10.0), b in vector(10.0)) {
            // Checks vee(hat(a)) = a (exact: only copies and ½(x − (−x)) = x) and hat(a) b = a × b.
            // Reference: definition of the cross product (nalgebra's cross). Tolerance: the same three
            // products per component, possibly in a different order: a few ulps of |a||b|.
            prop_assert_eq!(vee(&hat(&a)), a);
            let diff = (hat(&a) * b - a.cross(&b)).norm();
            prop_assert!(diff <= 4.0 * EPS * a.norm() * b.norm(), "diff {diff}");
            // vee ignores the symmetric part.
            let sym = hat(&a) * hat(&b) + (hat(&a) * hat(&b)).transpose();
            prop_assert!(vee(&sym).norm() <= EPS * max_abs(&sym));
        }

        #[test]
        fn exp_is_a_rotation(n in unit_vector(), angle in 0.0..10.0f64) {
            // Checks RᵀR = I and det R = 1 for angles up to 10 rad (beyond 2π, closed-form branches).
            // Reference: group property. Tolerance 16 ulps: an entry of R near θ ≈ 3 is cos θ + aθ_iθ_j with
            // both terms up to ~2 in size, so entries carry 2–3 ulps, and RᵀR and det sum three such
            // products; measured max over 2·10⁵ samples: 9 ulps (about the same as the unit-axis and
            // quaternion forms of Rodrigues' formula).
            let r = exp(&(n * angle));
            let m = r.matrix();
            prop_assert!(max_abs(&(m.transpose() * m - Mat3::identity())) <= 16.0 * EPS);
            prop_assert!((m.determinant() - 1.0).abs() <= 16.0 * EPS);
        }

        #[test]
        fn log_inverts_exp_below_pi(n in unit_vector(), angle in 0.0..(PI - 1e-4)) {
            // Checks log(exp(θ)) = θ for |θ| < π (generic angles, both log branches).
            // Reference: θ itself. Tolerance 4e-15·max(1, |θ|) (18 ulps): exp and log each contribute a few
            // ulps in the axis and the angle (atan2 is well conditioned everywhere); measured max 2.6 ulps
            // over 10⁵ samples.
            let theta = n * angle;
            let back = log(&exp(&theta));
            prop_assert!((back - theta).norm() <= 4e-15 * angle.max(1.0), "{back} vs {theta}");
        }

        #[test]
        fn log_inverts_exp_for_tiny_angles(n in unit_vector(), exponent in -12.0..-6.0f64) {
            // Checks log(exp(θ)) = θ for |θ| = 1e-12 … 1e-6 (series branches) to *relative* accuracy.
            // Reference: θ. Tolerance 4 ulps relative: the off-diagonal entries of R are σθ_k ± aθ_iθ_j,
            // each correctly rounded, and vee/σ add ~1 ulp (measured: exact over 10⁵ samples, since σ = 1
            // and aθ_iθ_j cancels exactly in the skew part).
            let theta = n * 10f64.powf(exponent);
            let back = log(&exp(&theta));
            prop_assert!((back - theta).norm() <= 4.0 * EPS * theta.norm(), "{back} vs {theta}");
        }

        #[test]
        fn log_inverts_exp_near_pi(n in unit_vector(), exponent in -8.0..-4.0f64) {
            // Checks log(exp(θ)) = θ for |θ| = π − δ, δ = 1e-8 … 1e-4, for the axis n and for −n: the sign
            // must be taken from the (tiny) skew part, so ±n must come back as ±n.
            // Reference: θ. Tolerance 1e-14 absolute (≈ 15 ulps of π): the symmetric-part axis is accurate
            // to a few ulps, the angle from atan2 to ~1 ulp of π (measured max 7.8 ulps = 1.7e-15 over 10⁵
            // samples); a sign error would give an error of ~2π.
            let angle = PI - 10f64.powf(exponent);
            for sign in [1.0, -1.0] {
                let theta = n * (sign * angle);
                let back = log(&exp(&theta));
                prop_assert!((back - theta).norm() <= 1e-14, "{back} vs {theta}");
            }
        }

        #[test]
        fn exp_inverts_log_for_random_rotations(q in prop::array::uniform4(-1.0..=1.0f64)) {
            // Checks exp(log R) = R and |log R| ≤ π for random rotations built independently of `exp` (from
            // a random quaternion by nalgebra).
            // Reference: R. Tolerance 1e-14 on the entries: a round trip through two maps each accurate to a
            // few ulps; measured max 5.8 ulps (1.3e-15) over 10⁵ samples.
            let quat = nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]);
            prop_assume!(quat.norm() > 0.1);
            let r = nalgebra::UnitQuaternion::from_quaternion(quat).to_rotation_matrix();
            let theta = log(&r);
            prop_assert!(theta.norm() <= PI + 4.0 * EPS);
            prop_assert!(max_abs(&(exp(&theta).matrix() - r.matrix())) <= 1e-14);
        }

        #[test]
        fn exp_inverts_log_for_exact_half_turns(n in unit_vector()) {
            // Checks exp(log R) = R for exact half turns R = 2nnᵀ − I (skew part zero to rounding), which
            // must give |log R| = π, no NaN, and either ±πn.
            // Reference: R and n. Tolerance 1e-14 on the entries and on |θ × n| (a few ulps of π): the axis
            // comes from the symmetric part 2nnᵀ, accurate to a few ulps.
            let r = Rot3::from_matrix_unchecked(2.0 * n * n.transpose() - Mat3::identity());
            let theta = log(&r);
            prop_assert!(theta.iter().all(|t| t.is_finite()));
            prop_assert!((theta.norm() - PI).abs() <= 4.0 * EPS * PI);
            prop_assert!(theta.cross(&n).norm() <= 1e-14);
            prop_assert!(max_abs(&(exp(&theta).matrix() - r.matrix())) <= 1e-14);
        }
    }

    /// Strategy: an angle magnitude [rad] drawn from the regimes that matter: tiny (series branches, ~1e-9),
    /// generic below π, and close to π (~3).
    fn angle_regimes() -> impl Strategy<Value = Real> {
        prop_oneof![1e-10..1e-8f64, 0.0..PI, 2.9..3.2f64]
    }

    /// `w(s) = T(θ(s)) θ,s(s)` for `θ(s) = t p + t² q + t³ r`, `t = s − s0`, evaluated through
    /// [`right_jacobian`] only (not [`right_jacobian_rate`]), with `θ, θ,s, θ,ss` returned as well.
    fn polynomial_path(p: &Vec3, q: &Vec3, r: &Vec3, t: Real) -> (Vec3, Vec3, Vec3) {
        let theta = p * t + q * (t * t) + r * (t * t * t);
        let theta_s = p + q * (2.0 * t) + r * (3.0 * t * t);
        let theta_ss = q * 2.0 + r * (6.0 * t);
        (theta, theta_s, theta_ss)
    }

    fn w_along_path(p: &Vec3, q: &Vec3, r: &Vec3, t: Real) -> Vec3 {
        let (theta, theta_s, _) = polynomial_path(p, q, r, t);
        right_jacobian(&theta) * theta_s
    }

    /// Fourth-order central difference `(f(t−2h) − 8f(t−h) + 8f(t+h) − f(t+2h))/(12h)` of `w` along the
    /// path.
    fn w_s_by_differences(p: &Vec3, q: &Vec3, r: &Vec3, t: Real, h: Real) -> Vec3 {
        let f = |tt: Real| w_along_path(p, q, r, tt);
        (f(t - 2.0 * h) - f(t - h) * 8.0 + f(t + h) * 8.0 - f(t + 2.0 * h)) / (12.0 * h)
    }

    /// Step of the fourth-order stencil above. Its error is truncation `h⁴|w⁽⁵⁾|/30` plus rounding
    /// `≈ 1.5 ε|w|/h` (w itself carries a few ulps). Measured on the fixed path at |θ| ≈ 1.2 (where
    /// `|w⁽⁵⁾|` ≈ 750): 2.5e-11 at h = 1e-3 (truncation, falling as h⁴), 1.3e-12 at h = 5e-4, and rounding
    /// taking over below (3e-12 at h = 2e-4).
    const PATH_STEP: Real = 5e-4;

    /// Absolute error allowed between `w,s` and its difference quotient, per unit of `max(1, |w,s|)`:
    /// about 8× the largest stencil error measured at [`PATH_STEP`] (2.7e-12 over 10⁵ random paths with
    /// |θ| ≤ 5). A wrong term in `w,s` (e.g. a missing `a'` or `b'` contribution) shows up at 1e-3 or above.
    const PATH_TOLERANCE: Real = 2e-11;

    #[test]
    fn right_jacobian_rate_through_zero_matches_differences() {
        // Checks w = T(θ)θ,s and w,s = d/ds[T(θ(s))θ,s] on a fixed cubic path θ(s) that passes through 0 at
        // t = s − s0 = 0 — the case DESIGN.md warns about (an axis–angle implementation returns wrong
        // derivatives there) — at t = 0, ±1e-9, ±1e-6 (series branches), ±1e-3, and at t = 0.5, 1 where
        // |θ| ≈ 1.2, 3.5 (closed branches).
        // Reference: a fourth-order central difference (step 1e-3) of w(s) computed from `right_jacobian`,
        // itself checked against differences of `exp` below.
        // Tolerance PATH_TOLERANCE·max(1, |w,s|) = 2e-11·max(1, |w,s|): the stencil's own error is
        // ~1e-12 (see PATH_STEP).
        let p = Vec3::new(0.9, -0.4, 0.3);
        let q = Vec3::new(-0.5, 1.1, 0.2);
        let r = Vec3::new(0.3, 0.2, -0.7);
        for t in [0.0, 1e-9, -1e-9, 1e-6, -1e-6, 1e-3, -1e-3, 0.5, 1.0] {
            let (theta, theta_s, theta_ss) = polynomial_path(&p, &q, &r, t);
            let (w, w_s) = right_jacobian_rate(&theta, &theta_s, &theta_ss);
            let w_ref = right_jacobian(&theta) * theta_s;
            assert!(
                (w - w_ref).norm() <= 4.0 * EPS * w_ref.norm(),
                "t = {t}: {w} vs {w_ref}"
            );
            let w_s_ref = w_s_by_differences(&p, &q, &r, t, PATH_STEP);
            let err = (w_s - w_s_ref).norm();
            assert!(
                err <= PATH_TOLERANCE * w_s_ref.norm().max(1.0),
                "t = {t}: w,s {w_s} vs {w_s_ref}, err {err:e}"
            );
        }
        // At θ = 0 exactly the formula reduces to w,s = θ,ss (all other terms carry a factor θ).
        let (_, w_s) = right_jacobian_rate(&Vec3::zeros(), &p, &(q * 2.0));
        assert_eq!(w_s, q * 2.0);
    }

    #[test]
    fn series_branches_truncate_below_a_quarter_ulp() {
        // Checks the documented choice of term counts: at each switch threshold the first *omitted* Taylor
        // term is below ε/4 relative to the function value (so truncation is below the rounding floor).
        // Reference: the defining series coefficients and the closed forms (accurate to ~2 ulps at the
        // thresholds, which is plenty for a bound on a term of size < ε/4).
        fn first_omitted<const M: usize>(coefficients: [Real; M], x: Real) -> Real {
            (coefficients[M - 1] * x.powi((M - 1) as i32)).abs()
        }
        let cases = [
            (
                "sinc",
                first_omitted(
                    taylor_coefficients::<{ SINC_SERIES_TERMS + 1 }>(1),
                    SINC_SERIES_MAX_ANGLE_SQ,
                ),
                sinc_closed(SINC_SERIES_MAX_ANGLE_SQ),
            ),
            (
                "sinc'",
                first_omitted(
                    taylor_derivative_coefficients::<{ SINC_PRIME_SERIES_TERMS + 1 }>(1),
                    SINC_PRIME_SERIES_MAX_ANGLE_SQ,
                ),
                sinc_prime_closed(SINC_PRIME_SERIES_MAX_ANGLE_SQ),
            ),
            (
                "b",
                first_omitted(
                    taylor_coefficients::<{ B_SERIES_TERMS + 1 }>(3),
                    B_SERIES_MAX_ANGLE_SQ,
                ),
                coefficient_b_closed(B_SERIES_MAX_ANGLE_SQ),
            ),
            (
                "b'",
                first_omitted(
                    taylor_derivative_coefficients::<{ B_PRIME_SERIES_TERMS + 1 }>(3),
                    B_PRIME_SERIES_MAX_ANGLE_SQ,
                ),
                coefficient_b_prime_closed(B_PRIME_SERIES_MAX_ANGLE_SQ),
            ),
        ];
        for (name, omitted, value) in cases {
            assert!(
                omitted <= 0.25 * EPS * value.abs(),
                "{name}: omitted term {omitted:e}, value {value}"
            );
        }
    }

    #[test]
    fn series_and_closed_forms_agree_at_thresholds() {
        // Checks continuity of every coefficient function across its switch (the series branch and the
        // closed form evaluated at the same x = threshold), so nothing jumps when |θ| crosses it.
        // Reference: the closed form (independent formula). Tolerance 6 ulps relative (≈ 1.3e-15):
        // measured 2.2 ulps closed-form error (b' at θ = 3) plus ≤ 1 ulp series error, with a margin.
        type Branches = (&'static str, fn(Real) -> Real, fn(Real) -> Real, Real);
        let pairs: [Branches; 4] = [
            ("sinc", sinc_series, sinc_closed, SINC_SERIES_MAX_ANGLE_SQ),
            (
                "sinc'",
                sinc_prime_series,
                sinc_prime_closed,
                SINC_PRIME_SERIES_MAX_ANGLE_SQ,
            ),
            (
                "b",
                coefficient_b_series,
                coefficient_b_closed,
                B_SERIES_MAX_ANGLE_SQ,
            ),
            (
                "b'",
                coefficient_b_prime_series,
                coefficient_b_prime_closed,
                B_PRIME_SERIES_MAX_ANGLE_SQ,
            ),
        ];
        for (name, series, closed, threshold) in pairs {
            for x in [
                threshold * (1.0 - 1e-12),
                threshold,
                threshold * (1.0 + 1e-12),
            ] {
                let (s, c) = (series(x), closed(x));
                assert!(
                    (s - c).abs() <= 6.0 * EPS * c.abs(),
                    "{name} at x = {x}: {s} vs {c}"
                );
            }
        }
        // End to end: the public maps at angles one ulp on either side of each switch (this also covers
        // a' and c, whose σ(x/4), σ'(x/4) switch at θ² = 4× their thresholds). Tolerance 8 ulps of the
        // result: the branch difference (≤ ~3 ulps, above) plus the change caused by the 2-ulp step in θ
        // itself; measured ≤ 4.5 ulps (w, w,s at θ = 3).
        let axis = Vec3::new(2.0, -1.0, 2.0) / 3.0;
        for threshold in [
            SINC_SERIES_MAX_ANGLE_SQ,
            SINC_PRIME_SERIES_MAX_ANGLE_SQ,
            4.0 * SINC_SERIES_MAX_ANGLE_SQ,
            4.0 * SINC_PRIME_SERIES_MAX_ANGLE_SQ,
            B_SERIES_MAX_ANGLE_SQ,
            B_PRIME_SERIES_MAX_ANGLE_SQ,
        ] {
            let angle = threshold.sqrt();
            let below = axis * (angle * (1.0 - EPS));
            let above = axis * (angle * (1.0 + EPS));
            assert!(below.norm_squared() <= threshold && above.norm_squared() > threshold);
            let theta_s = Vec3::new(0.3, 0.5, -0.2);
            let theta_ss = Vec3::new(-0.1, 0.4, 0.6);
            let (w_below, w_s_below) = right_jacobian_rate(&below, &theta_s, &theta_ss);
            let (w_above, w_s_above) = right_jacobian_rate(&above, &theta_s, &theta_ss);
            assert!((w_below - w_above).norm() <= 8.0 * EPS * w_above.norm());
            assert!((w_s_below - w_s_above).norm() <= 8.0 * EPS * w_s_above.norm());
            assert!(max_abs(&(exp(&below).matrix() - exp(&above).matrix())) <= 8.0 * EPS);
            let (t_below, t_above) = (right_jacobian(&below), right_jacobian(&above));
            assert!(max_abs(&(t_below - t_above)) <= 8.0 * EPS * max_abs(&t_above));
            let (i_below, i_above) = (
                right_jacobian_inverse(&below),
                right_jacobian_inverse(&above),
            );
            assert!(max_abs(&(i_below - i_above)) <= 8.0 * EPS * max_abs(&i_above));
        }
    }

    #[test]
    fn coefficient_functions_match_high_precision_values() {
        // Checks σ, σ', a, a', b, b', c against 20-digit references across both branches and the
        // thresholds (θ = 1e-3 … 6 rad).
        // Reference: mpmath at 40 digits, evaluated at θ = sqrt(x) with x = fl(θ·θ) exactly as here, then
        // rounded to the nearest double (`repr(float(value))`, ≤ ½ ulp):
        //   import mpmath as mp; mp.mp.dps = 40; x = float(t)*float(t); T = mp.sqrt(mp.mpf(x))
        //   σ = sin T/T, σ' = (T cos T − sin T)/(2T³), a = (1 − cos T)/T², a' = (T sin T − 2(1 − cos T))/(2T⁴),
        //   b = (T − sin T)/T³, b' = (3 sin T − T(2 + cos T))/(2T⁵), c = 1/T² − (1 + cos T)/(2T sin T).
        // Tolerance 5 ulps relative: ≤ 2.2 ulps for any single branch (module docs), products (a, a', c)
        // add one or two roundings, the rounded reference ½ ulp. c near 2π (θ = 6) is ill conditioned in θ itself, but x is bit-equal.
        #[rustfmt::skip]
        let table: [(Real, [Real; 7]); 9] = [
            (1e-3, [0.9999998333333416, -0.16666665000000058, 0.4999999583333347, -0.04166666388888896, 0.16666665833333352, -0.008333332936507945, 0.08333333472222225]),
            (0.3, [0.9850673555377986, -0.16517148006773646, 0.4962612319377109, -0.04141726854235112, 0.16591827180223795, -0.008297685938905468, 0.08345860179452762]),
            (1.0, [0.8414709848078965, -0.1505843394698784, 0.4596976941318603, -0.03896220172791203, 0.1585290151921035, -0.0079446757222251, 0.08475613914377404]),
            (1.5, [0.6649966577360363, -0.1320576569040741, 0.4130056881476876, -0.03578104856874198, 0.14889037433953942, -0.007481207749095708, 0.08663572826131866]),
            (2.0, [0.45464871341284085, -0.1088494437449979, 0.3540367091367856, -0.03167808810759129, 0.1363378216467898, -0.0068720944754479705, 0.08947684601641732]),
            (2.9, [0.08249976869447666, -0.06263126836171624, 0.2343588781390714, -0.022961830415200127, 0.10909634141563893, -0.005524978960038369, 0.09797721595839991]),
            (3.0, [0.04704000268662241, -0.05761291662705933, 0.2211102774000495, -0.021954475117415367, 0.10588444414593084, -0.005363503057652391, 0.09929197039400237]),
            (4.0, [-0.18920062382698205, -0.014513843657394682, 0.10335272630397574, -0.012372064888591673, 0.07432503898918638, -0.003738199708236981, 0.11970719429503572]),
            (6.0, [-0.04656924969982098, 0.013982493560419263, 0.0011063809263787217, -0.0006775279382302559, 0.029071368047217248, -0.0011959406002121254, 0.6123821570639889]),
        ];
        let names = ["σ", "σ'", "a", "a'", "b", "b'", "c"];
        for (angle, expected) in table {
            let x = angle * angle;
            let computed = [
                sinc(x),
                sinc_prime(x),
                coefficient_a(x),
                coefficient_a_prime(x),
                coefficient_b(x),
                coefficient_b_prime(x),
                coefficient_c(x),
            ];
            for ((name, got), want) in names.iter().zip(computed).zip(expected) {
                let ulps = ((got - want) / want).abs() / EPS;
                assert!(
                    ulps <= 5.0,
                    "{name}(θ = {angle}) = {got}, want {want} ({ulps:.1} ulp)"
                );
            }
        }
    }

    #[test]
    fn series_leading_coefficients() {
        // Checks the compile-time coefficient tables against the first terms written out by hand:
        // σ = 1 − x/6 + x²/120, σ' = −1/6 + x/60, b = 1/6 − x/120, b' = −1/120 + x/2520, and c(0) = 1/12.
        // Reference: the Taylor series of sin and cos. Tolerance: ½ ulp (each coefficient is a single
        // correctly rounded division of exact integers).
        let pairs = [
            (SINC_COEFFICIENTS[0], 1.0),
            (SINC_COEFFICIENTS[1], -1.0 / 6.0),
            (SINC_COEFFICIENTS[2], 1.0 / 120.0),
            (SINC_PRIME_COEFFICIENTS[0], -1.0 / 6.0),
            (SINC_PRIME_COEFFICIENTS[1], 1.0 / 60.0),
            (B_COEFFICIENTS[0], 1.0 / 6.0),
            (B_COEFFICIENTS[1], -1.0 / 120.0),
            (B_PRIME_COEFFICIENTS[0], -1.0 / 120.0),
            (B_PRIME_COEFFICIENTS[1], 1.0 / 2520.0),
            (coefficient_c(0.0), 1.0 / 12.0),
        ];
        for (got, want) in pairs {
            assert_relative_eq!(got, want, max_relative = 0.5 * EPS);
        }
    }

    proptest! {
        #![proptest_config(config())]

        #[test]
        fn right_jacobian_matches_differences_of_exp(
            n in unit_vector(),
            angle in angle_regimes(),
            direction in unit_vector(),
        ) {
            // Checks axial(exp(θ̃)ᵀ (exp(θ̃ + hδθ̃) − exp(θ̃ − hδθ̃))/(2h)) = T(θ) δθ, the defining property of
            // the right Jacobian, at |θ| ~ 1e-9 (series), generic, and ~3 (near π).
            // Reference: central difference of `exp` (checked above to be a rotation and inverse of log).
            // Tolerance 5e-10: truncation h²|d³exp|/6 and rounding ≈ ε/h, each ~1e-11…1e-10 for h = 1e-5
            // and |δθ| = 1; measured max 7e-11 over 10⁵ samples per regime.
            let h = 1e-5;
            let theta = n * angle;
            let r = exp(&theta);
            let difference =
                (exp(&(theta + direction * h)).matrix() - exp(&(theta - direction * h)).matrix()) / (2.0 * h);
            let reference = vee(&(r.matrix().transpose() * difference));
            let t = right_jacobian(&theta);
            let err = (t * direction - reference).norm();
            prop_assert!(err <= 5e-10, "θ = {theta}: err {err:e}");
        }

        #[test]
        fn jacobian_identities(n in unit_vector(), angle in angle_regimes()) {
            // Checks T(θ)θ = θ (the axis is fixed), left = T(−θ) = Tᵀ, and exp(θ̃) T(θ) = T(θ)ᵀ
            // (left Jacobian = R · right Jacobian).
            // Reference: the identities of the SO(3) Jacobians (Barfoot 2017, ch. 7).
            // Tolerance 8 ulps of the O(1) entries: each side has a handful of O(1) roundings.
            let theta = n * angle;
            let t = right_jacobian(&theta);
            prop_assert!((t * theta - theta).norm() <= 8.0 * EPS * angle.max(1e-300));
            let left = left_jacobian(&theta);
            prop_assert!(max_abs(&(left - t.transpose())) <= 8.0 * EPS);
            prop_assert!(max_abs(&(exp(&theta).matrix() * t - left)) <= 8.0 * EPS);
        }

        #[test]
        fn jacobian_inverses(n in unit_vector(), angle in prop_oneof![1e-10..1e-8f64, 0.0..5.5f64]) {
            // Checks T(θ) T⁻¹(θ) = I and Tᵀ T⁻ᵀ = I for |θ| up to 5.5 rad (T is singular at 2π) and tiny.
            // Reference: the identity. Tolerance 8ε(1 + |T⁻¹|): the product's rounding is bounded by
            // ε|T||T⁻¹| per term, |T| ≤ ~1.5; |T⁻¹| grows like 1/(2π − θ) (≈ 10 at 5.5 rad).
            let theta = n * angle;
            let inverse = right_jacobian_inverse(&theta);
            let bound = 8.0 * EPS * (1.0 + max_abs(&inverse));
            prop_assert!(max_abs(&(right_jacobian(&theta) * inverse - Mat3::identity())) <= bound);
            prop_assert!(max_abs(&(inverse * right_jacobian(&theta) - Mat3::identity())) <= bound);
            let left_inverse = left_jacobian_inverse(&theta);
            prop_assert!(max_abs(&(left_jacobian(&theta) * left_inverse - Mat3::identity())) <= bound);
        }

        #[test]
        fn right_jacobian_rate_matches_differences_on_random_paths(
            p in vector(1.0),
            q in vector(1.0),
            r in vector(1.0),
            t in prop_oneof![-1e-9..1e-9f64, -1e-4..1e-4f64, -1.0..1.0f64],
        ) {
            // Checks w,s = d/ds[T(θ(s)) θ,s] on random cubic paths θ(s) = t p + t² q + t³ r through 0 at
            // t = 0, evaluated near the zero (series branches) and up to |θ| ≈ 3 (closed branches).
            // Reference: the fourth-order central difference of w from `right_jacobian` (PATH_STEP).
            // Tolerance PATH_TOLERANCE·max(1, |w,s|), as in the fixed-path test.
            let (theta, theta_s, theta_ss) = polynomial_path(&p, &q, &r, t);
            let (_, w_s) = right_jacobian_rate(&theta, &theta_s, &theta_ss);
            let w_s_ref = w_s_by_differences(&p, &q, &r, t, PATH_STEP);
            let err = (w_s - w_s_ref).norm();
            prop_assert!(err <= PATH_TOLERANCE * w_s_ref.norm().max(1.0), "θ = {theta}: err {err:e}");
        }
    }

    /// Source: `right_jacobian_along` against `right_jacobian` for the value and against central differences of
    /// `right_jacobian` along the curve `θ(s) = θ + s θ,s + s²/2 θ,ss` for the derivatives (step 1e-4:
    /// truncation ~1e-8 relative, round-off ~1e-12), at angles below, near and above the series' end (x = 2.25)
    /// and near 0.
    #[test]
    fn the_jacobian_along_a_curve_has_the_curves_derivatives() {
        let d1 = Vec3::new(0.3, -0.8, 0.5);
        let d2 = Vec3::new(-0.4, 0.2, 0.9);
        for scale in [1e-9, 0.3, 1.49, 1.51, 3.0, 5.5] {
            let theta = Vec3::new(0.48, -0.6, 0.64) * scale;
            let along = right_jacobian_along(&[theta, d1, d2]);
            let at = |s: Real| right_jacobian(&(theta + d1 * s + d2 * (0.5 * s * s)));
            let h = 1e-4;
            assert!(max_abs(&(along[0] - at(0.0))) < 1e-14, "scale {scale}");
            let first = (at(h) - at(-h)) / (2.0 * h);
            let second = (at(h) - at(0.0) * 2.0 + at(-h)) / (h * h);
            assert!(
                max_abs(&(along[1] - first)) < 1e-7,
                "scale {scale}: {}",
                along[1] - first
            );
            assert!(
                max_abs(&(along[2] - second)) < 1e-5,
                "scale {scale}: {}",
                along[2] - second
            );
        }
    }
}
