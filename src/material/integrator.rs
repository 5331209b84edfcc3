//! Time integration of the branch strains: one affine update per branch and time step.
//!
//! Each branch strain obeys (paper Eq. `evol_f_m_thermal`, written with rates `λ_α = 1/τ_α`)
//!
//! ```text
//! ε̇_α = λ_α(T(t)) (ε − ε_α),        λ_α(T) = rate_factor(T) / τ_G,α,
//! ```
//!
//! for every component of `Γ_N` and `K_M` (and, with the same coefficients, of their s-derivatives). Over a step
//! `[t_n, t_{n+1}]`, `h = t_{n+1} − t_n`, every [`Integrator`] gives an update affine in the new total strain
//!
//! ```text
//! ε_α^{n+1} = β_α ε^{n+1} + γ_α ε^n + δ_α ε_α^n                                              (★)
//! ```
//!
//! with `β_α + γ_α + δ_α = 1` (a constant strain is a fixed point) and:
//!
//! | integrator | `β_α` | `γ_α` | `δ_α` |
//! |---|---|---|---|
//! | trapezoidal (paper) | `r₁/(1+r₁)` | `r₀/(1+r₁)` | `(1−r₀)/(1+r₁)` |
//! | backward Euler | `hλ₁/(1+hλ₁)` | `0` | `1/(1+hλ₁)` |
//! | exponential | `1 − φ(Δξ)` | `φ(Δξ) − e^{−Δξ}` | `e^{−Δξ}` |
//!
//! where `λ₀ = λ_α(T(t_n))`, `λ₁ = λ_α(T(t_{n+1}))`, `r₀ = hλ₀/2`, `r₁ = hλ₁/2`, `Δξ_α = ∫_{t_n}^{t_{n+1}}
//! λ_α(T(t)) dt` (reduced-time increment) and `φ(x) = (1 − e^{−x})/x`.
//!
//! * **Trapezoidal** — paper Eq. `evol_f_thermal_disc`, `(1 + r₁) ε_α^{n+1} = (1 − r₀) ε_α^n + r₀ ε^n +
//!   r₁ ε^{n+1}`. Second order, A-stable but not L-stable: for `hλ ≫ 1` the amplification `δ → −1`, so a strain
//!   jump leaves a branch ringing with alternating sign, decaying only like `((1 − r)/(1 + r))^n`. Worse,
//!   while the material cools the amplification `|δ| = (r₀ − 1)/(1 + r₁)` exceeds 1 whenever `r₀ − r₁ > 2`,
//!   so that ringing grows with the drop of the rate factor: a strain jump held at 90 °C in PLA, then cooled at
//!   the paper's rate and step (58.5 K/s, `h = 1e-3 s`), gives a spurious stress `3e8` times the true one
//!   before the branches freeze (test `trapezoidal_ringing_is_amplified_by_cooling`). Smooth loading is
//!   harmless (the overstress it leaves is `O(Δε/r)`, the size of the true one); load *jumps* while hot —
//!   including a switch from prescribed displacement to prescribed force — call for backward Euler or the
//!   exponential scheme.
//! * **Backward Euler** — `(1 + hλ₁) ε_α^{n+1} = ε_α^n + hλ₁ ε^{n+1}`. First order, L-stable (`δ → 0`).
//! * **Exponential** — exact solution of the ODE when `ε` is linear in reduced time over the step
//!   (in particular exact for piecewise-linear strain at constant temperature): with `s ∈ [0, Δξ]` the
//!   reduced time, `ε_α(Δξ) = e^{−Δξ} ε_α^n + ∫_0^{Δξ} e^{−(Δξ−s)} ε(s) ds` and `ε(s) = ε^n + (ε^{n+1} −
//!   ε^n) s/Δξ`. Second order for smooth strains, L-stable, with the right limits (`Δξ → 0`:
//!   `(0, 0, 1)`, no relaxation; `Δξ → ∞`: `(1, 0, 0)`, instantly relaxed). Because all branches share the rate factor, one quadrature
//!   `ξ = ∫ rate_factor(T(t)) dt` per step serves every branch: `Δξ_α = ξ/τ_G,α` ([`reduced_time_increment`]).
//!
//! # Correspondence with the paper (trapezoidal case)
//!
//! Insert (★) into `σ = E∞ ε + Σ E_α (ε − ε_α)` and multiply by the section shapes `S_N`, `S_M`
//! ([`super::SectionShape`]):
//!
//! ```text
//! N^{n+1} = C̄ Γ_N^{n+1} − H_N,    C̄ = S_N ⊙ (E∞ + Σ_α E_α (1 − β_α)),    H_N = S_N ⊙ Σ_α E_α (γ_α Γ_N^n + δ_α Γ_Nα^n).
//! ```
//!
//! With `λ = 1/τ` the trapezoidal coefficients are `β_α = h/(2τ_α^{n+1} + h)` and `γ_α ε^n + δ_α ε_α^n =
//! τ_α^{n+1}/(2τ_α^{n+1} + h) · Ψ_α^n` with `Ψ_α^n = (h/τ_α^n) ε^n + ((2τ_α^n − h)/τ_α^n) ε_α^n` — exactly
//! the paper's `C̄^{n+1} = C_0 − Σ C_α h/(2τ_α^{n+1}+h)` and history term `Σ C_α τ_α^{n+1}/(2τ_α^{n+1}+h)
//! Ψ_α^n` of Eqs. `N_constitutive_disc`, `M_constitutive_disc` (`Ψ` from Eqs. `evol_varPhi_thermal_1`,
//! `evol_varPhi_thermal_2`). The rate form needs no `τ = ∞` when relaxation is frozen (`λ = 0`, `(β, γ, δ) =
//! (0, 0, 1)`).
//!
//! # Saturation
//!
//! The dimensionless step rates `hλ` and `Δξ` are capped at [`MAX_STEP_RATE`] `= 1e100` before use, which
//! keeps `∞/∞ = NaN` out of the formulas when a tiny `τ_G` meets a huge rate factor. For `hλ ≳ 1e17` the
//! backward-Euler and exponential coefficients and the trapezoidal `β` have reached their limits to round-off,
//! so the cap changes nothing there; the trapezoidal `γ, δ` grow like `hλ₀` when the rate drops within a step
//! (the weakness described above), and the cap only keeps them finite.

use super::{Material, MaterialError, Prony};
use crate::math::Real;
use std::num::NonZeroUsize;

/// Cap on the dimensionless step rates `hλ_α` and `Δξ_α` \[-\] (see the module docs, *Saturation*).
pub const MAX_STEP_RATE: Real = 1e100;

/// Below this reduced-time increment `β = 1 − φ(Δξ)` is summed from its Taylor series (the difference
/// `1 − φ` cancels catastrophically for small `Δξ`).
const EXP_SERIES_BELOW: Real = 0.5;

/// The scheme advancing the branch strains over a time step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub enum Integrator {
    /// Trapezoidal rule (paper Eq. `evol_f_thermal_disc`): second order, A- but not L-stable (fast branches
    /// ring after a jump). The default, as in the paper.
    #[default]
    Trapezoidal,
    /// Backward Euler: first order, L-stable.
    BackwardEuler,
    /// Exponential (exact for strain linear in reduced time over a step): second order, L-stable.
    Exponential,
}

impl Integrator {
    /// The design-file spelling: `trapezoidal`, `backward-euler`, `exponential`.
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Trapezoidal => "trapezoidal",
            Integrator::BackwardEuler => "backward-euler",
            Integrator::Exponential => "exponential",
        }
    }

    /// The asymptotic order of accuracy in `h` for smooth histories: 2, 1, 2.
    pub fn order(&self) -> u32 {
        match self {
            Integrator::Trapezoidal | Integrator::Exponential => 2,
            Integrator::BackwardEuler => 1,
        }
    }

    /// The companion whose update, compared with this one's over the same step, estimates the time error of
    /// adaptive stepping ([`crate::material::ConstitutiveLaw::companion_laws`]), or why there is none.
    ///
    /// The trapezoidal rule has backward Euler: the difference is then backward Euler's local error, `h²/2
    /// ε̈_α` for smooth histories — an over-estimate of the trapezoidal rule's own — and the trapezoidal rule's
    /// ringing for `hλ ≫ 1`, which backward Euler does not have. The other rules have none that keeps the
    /// *global* error below the tolerance, measured on the pure-bending shape-memory cycle against its stiff-ODE
    /// reference (test `error_controlled_steps_keep_the_bending_error_below_the_tolerance`): backward Euler
    /// with the trapezoidal companion ends 3–45 times above the tolerance (its first-order local errors add up
    /// over the run), and the exponential update with backward Euler 1.2–2.3 times (an error built up during
    /// the recovery's heating that the estimate does not see).
    pub fn companion(&self) -> Result<Integrator, &'static str> {
        match self {
            Integrator::Trapezoidal => Ok(Integrator::BackwardEuler),
            Integrator::BackwardEuler => Err(
                "backward Euler's first-order local errors add up over a run: error-controlled steps measured 3–45 times the tolerance on the pure-bending cycle",
            ),
            Integrator::Exponential => Err(
                "no companion estimate of the exponential update keeps its error below the tolerance: measured 1.2–2.3 times it on the pure-bending cycle",
            ),
        }
    }
}

/// Quadrature of the reduced time `ξ = ∫_{t_n}^{t_{n+1}} rate_factor(T(t)) dt` used by
/// [`Integrator::Exponential`]: composite 5-point Gauss–Legendre on `subintervals` equal parts of the step.
///
/// Accuracy: exact when `rate_factor(T(t))` is a polynomial of degree ≤ 9 on each part; the error of a part
/// of length `ℓ` is `ℓ^{11} (5!)⁴ / (11 (10!)³) · f^{(10)} ≈ 2.9e-15 ℓ^{11} f^{(10)}`. Along a temperature ramp
/// the integrand is `f = exp(k(t))` with `k' = ln 10 · C1 C2 Ṫ /(C2 + T − Tg)²`, so the relative error is about
/// `3e-15 (k'ℓ)^{10}`: at round-off while `k'ℓ ≲ 0.7` (the rate factor changes by less than a factor 2 per
/// part). Examples with PLA (van Manen): the paper's cantilever cools at 58.5 K/s, `k' ≈ 64 /s` near 60 °C;
/// at `h = 1e-3 s` (the paper's step) `k'ℓ = 0.03`, round-off; at a coarse `h = 0.05 s` with the default two
/// parts `k'ℓ = 1.6`, measured relative error 8e-13. A kink of the temperature schedule inside a step lowers
/// the accuracy to `O(ℓ²)` on that part: align steps with schedule breakpoints, or raise `subintervals`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReducedTimeQuadrature {
    /// Number of equal parts of the step, each integrated with 5-point Gauss–Legendre.
    pub subintervals: NonZeroUsize,
}

impl Default for ReducedTimeQuadrature {
    /// Two parts (10 temperature evaluations per step).
    fn default() -> Self {
        Self {
            subintervals: NonZeroUsize::MIN.saturating_add(1),
        }
    }
}

/// Gauss–Legendre 5-point nodes on `[−1, 1]` and weights (Abramowitz & Stegun, Table 25.4).
const GAUSS5: [(Real, Real); 5] = [
    (-0.906179845938664, 0.2369268850561891),
    (-0.5384693101056831, 0.4786286704993665),
    (0.0, 0.5688888888888889),
    (0.5384693101056831, 0.4786286704993665),
    (0.906179845938664, 0.2369268850561891),
];

/// The coefficients `(β_α, γ_α, δ_α)` of (★) for every branch over one time step (index `α − 1`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StepCoefficients {
    /// `β_α` \[-\]: weight of the new total strain `ε^{n+1}`.
    pub beta: Vec<Real>,
    /// `γ_α` \[-\]: weight of the old total strain `ε^n`.
    pub gamma: Vec<Real>,
    /// `δ_α` \[-\]: weight of the old branch strain `ε_α^n` (the amplification factor).
    pub delta: Vec<Real>,
}

impl StepCoefficients {
    /// The coefficients of a step with no relaxation (`h = 0` or frozen): `(β, γ, δ) = (0, 0, 1)`.
    pub fn identity(num_branches: usize) -> Self {
        Self {
            beta: vec![0.0; num_branches],
            gamma: vec![0.0; num_branches],
            delta: vec![1.0; num_branches],
        }
    }

    /// Number of branches.
    pub fn num_branches(&self) -> usize {
        self.beta.len()
    }

    /// The step's effective modulus `Ē = E∞ + Σ_α E_α (1 − β_α)` \[stress\]: `C̄^{n+1} = S ⊙ Ē` (paper
    /// Eqs. `N_constitutive_disc`, `M_constitutive_disc`); between `E∞` and `E0`.
    #[track_caller]
    pub fn effective_modulus(&self, prony: &Prony) -> Real {
        assert_eq!(
            self.num_branches(),
            prony.num_branches(),
            "coefficients and Prony series differ in branches"
        );
        prony.e_inf()
            + prony
                .branches()
                .iter()
                .zip(&self.beta)
                .map(|(b, beta)| b.modulus * (1.0 - beta))
                .sum::<Real>()
    }

    fn resize(&mut self, num_branches: usize) {
        self.beta.resize(num_branches, 0.0);
        self.gamma.resize(num_branches, 0.0);
        self.delta.resize(num_branches, 1.0);
    }
}

/// Coefficients for one step `[t_n, t_{n+1}]` \[time\] of `material` with `integrator`, the temperature given
/// as a function of time \[°C\]; the allocating wrapper of [`step_coefficients_into`] with the default
/// [`ReducedTimeQuadrature`]. Called once per time step (not per point).
pub fn step_coefficients(
    material: &Material,
    integrator: Integrator,
    t_n: Real,
    t_np1: Real,
    temperature: &dyn Fn(Real) -> Real,
) -> Result<StepCoefficients, MaterialError> {
    let mut out = StepCoefficients::default();
    step_coefficients_into(
        material,
        integrator,
        &ReducedTimeQuadrature::default(),
        t_n,
        t_np1,
        temperature,
        &mut out,
    )?;
    Ok(out)
}

/// Fills `out` (resized to the number of branches; no allocation once sized) with the coefficients of (★)
/// for the step `[t_n, t_{n+1}]` \[time\]. The trapezoidal rule and backward Euler evaluate the temperature at
/// the step ends only; the exponential integrator integrates the rate factor with `quadrature`.
/// Temperatures are not evaluated at all for a material without WLF.
///
/// Errors: [`MaterialError::TimeStep`] unless `t_n ≤ t_{n+1}` are finite; [`MaterialError::NonFiniteInput`]
/// if the temperature is not finite where evaluated. On error `out` is left unspecified.
pub fn step_coefficients_into(
    material: &Material,
    integrator: Integrator,
    quadrature: &ReducedTimeQuadrature,
    t_n: Real,
    t_np1: Real,
    temperature: &dyn Fn(Real) -> Real,
    out: &mut StepCoefficients,
) -> Result<(), MaterialError> {
    let uniform = |t: Real| (temperature(t), 0.0);
    step_coefficients_with_slope_into(
        material, integrator, quadrature, t_n, t_np1, &uniform, out, None,
    )
}

/// [`step_coefficients_into`] at a point where the temperature varies along the rod: `temperature(t)` gives
/// `(T, T,s)` \[°C, K/length\] there, and `out_ds`, when given, receives the derivatives `(β_α,s, γ_α,s, δ_α,s)` of the
/// coefficients along the reference arc length \[1/length\] — exact derivatives of the formulas of the module
/// docs through `λ_α,s = λ_α · d ln(rate_factor)/dT · T,s` ([`super::Wlf::log_rate_slope`]); zero where a
/// rate is capped ([`MAX_STEP_RATE`]) or frozen. They make the s-derivative of (★) exact (module docs of
/// `super::maxwell`, *Temperature that varies along the rod*).
///
/// Errors as [`step_coefficients_into`] (also for a non-finite `T,s`).
#[allow(clippy::too_many_arguments)]
pub fn step_coefficients_with_slope_into(
    material: &Material,
    integrator: Integrator,
    quadrature: &ReducedTimeQuadrature,
    t_n: Real,
    t_np1: Real,
    temperature: &dyn Fn(Real) -> (Real, Real),
    out: &mut StepCoefficients,
    mut out_ds: Option<&mut StepCoefficients>,
) -> Result<(), MaterialError> {
    let h = step_length(t_n, t_np1)?;
    let branches = material.prony().branches();
    out.resize(branches.len());
    if let Some(ds) = out_ds.as_deref_mut() {
        ds.resize(branches.len());
    }
    match integrator {
        Integrator::Trapezoidal => {
            let (rf0, rf0_s) = rate_factor_at(material, temperature, t_n)?;
            let (rf1, rf1_s) = rate_factor_at(material, temperature, t_np1)?;
            for (i, b) in branches.iter().enumerate() {
                let r0 = 0.5 * step_rate(h * rf0, b.tau_g);
                let r1 = 0.5 * step_rate(h * rf1, b.tau_g);
                let d = 1.0 + r1;
                out.beta[i] = r1 / d;
                out.gamma[i] = r0 / d;
                out.delta[i] = (1.0 - r0) / d;
                if let Some(ds) = out_ds.as_deref_mut() {
                    let r0_s = 0.5 * step_rate_slope(h * rf0, h * rf0_s, b.tau_g);
                    let r1_s = 0.5 * step_rate_slope(h * rf1, h * rf1_s, b.tau_g);
                    ds.beta[i] = r1_s / (d * d);
                    ds.gamma[i] = r0_s / d - r0 * r1_s / (d * d);
                    ds.delta[i] = -r0_s / d - (1.0 - r0) * r1_s / (d * d);
                }
            }
        }
        Integrator::BackwardEuler => {
            let (rf1, rf1_s) = rate_factor_at(material, temperature, t_np1)?;
            for (i, b) in branches.iter().enumerate() {
                let r = step_rate(h * rf1, b.tau_g);
                let d = 1.0 + r;
                out.beta[i] = r / d;
                out.gamma[i] = 0.0;
                out.delta[i] = 1.0 / d;
                if let Some(ds) = out_ds.as_deref_mut() {
                    let r_s = step_rate_slope(h * rf1, h * rf1_s, b.tau_g);
                    ds.beta[i] = r_s / (d * d);
                    ds.gamma[i] = 0.0;
                    ds.delta[i] = -r_s / (d * d);
                }
            }
        }
        Integrator::Exponential => {
            let (xi, xi_s) =
                reduced_time_increment_with_slope(material, quadrature, t_n, t_np1, temperature)?;
            for (i, b) in branches.iter().enumerate() {
                let x = step_rate(xi, b.tau_g);
                let (beta, gamma, delta) = exponential_coefficients(x);
                out.beta[i] = beta;
                out.gamma[i] = gamma;
                out.delta[i] = delta;
                if let Some(ds) = out_ds.as_deref_mut() {
                    let x_s = step_rate_slope(xi, xi_s, b.tau_g);
                    let (beta_x, gamma_x, delta_x) = exponential_coefficient_slopes(x);
                    ds.beta[i] = beta_x * x_s;
                    ds.gamma[i] = gamma_x * x_s;
                    ds.delta[i] = delta_x * x_s;
                }
            }
        }
    }
    Ok(())
}

/// The reduced-time increment `ξ = ∫_{t_n}^{t_{n+1}} rate_factor(T(t)) dt` \[time\] of the step, so that
/// `Δξ_α = ξ / τ_G,α`; by `quadrature` (exactly `h` without WLF). Finite: the integrand is in `[0, 10^{C1})`
/// (a step longer than ~`1e8` \[time\] at the hottest temperature could overflow to `∞`, which
/// [`MAX_STEP_RATE`] then caps).
///
/// Errors as [`step_coefficients_into`].
pub fn reduced_time_increment(
    material: &Material,
    quadrature: &ReducedTimeQuadrature,
    t_n: Real,
    t_np1: Real,
    temperature: &dyn Fn(Real) -> Real,
) -> Result<Real, MaterialError> {
    let uniform = |t: Real| (temperature(t), 0.0);
    reduced_time_increment_with_slope(material, quadrature, t_n, t_np1, &uniform).map(|(xi, _)| xi)
}

/// The reduced-time increment `ξ` and its s-derivative `ξ,s = ∫ rate_factor,s dt` \[time/length\] by the same
/// quadrature, for a temperature history `t ↦ (T, T,s)` at a point.
fn reduced_time_increment_with_slope(
    material: &Material,
    quadrature: &ReducedTimeQuadrature,
    t_n: Real,
    t_np1: Real,
    temperature: &dyn Fn(Real) -> (Real, Real),
) -> Result<(Real, Real), MaterialError> {
    let h = step_length(t_n, t_np1)?;
    if material.wlf().is_none() {
        return Ok((h, 0.0));
    }
    if h == 0.0 {
        return Ok((0.0, 0.0));
    }
    let parts = quadrature.subintervals.get();
    let part = h / parts as Real;
    let (mut xi, mut xi_s) = (0.0, 0.0);
    for k in 0..parts {
        let mid = t_n + (k as Real + 0.5) * part;
        let (mut sum, mut sum_s) = (0.0, 0.0);
        for &(node, weight) in &GAUSS5 {
            let (rf, rf_s) = rate_factor_at(material, temperature, mid + 0.5 * part * node)?;
            sum += weight * rf;
            sum_s += weight * rf_s;
        }
        xi += 0.5 * part * sum;
        xi_s += 0.5 * part * sum_s;
    }
    Ok((xi, xi_s))
}

/// The exponential integrator's coefficients `(β, γ, δ) = (1 − φ, φ − e^{−Δξ}, e^{−Δξ})`, `φ = (1 − e^{−Δξ})/Δξ`,
/// for a reduced-time increment `Δξ ≥ 0` \[-\], accurate to a few ulps for every `Δξ`:
///
/// * `β` from its Taylor series `Δξ Σ_{j≥0} (−Δξ)^j/(j+2)!` below `Δξ = 0.5` (there `1 − φ` cancels), else
///   `1 + expm1(−Δξ)/Δξ`;
/// * `γ = −expm1(−Δξ) − β` below `Δξ = 1` (subtracting about half), else `φ − e^{−Δξ}` (for large `Δξ`, `γ ≈
///   1/Δξ` must not come from `1 − β`);
/// * `δ = exp(−Δξ)` directly (not `1 + expm1`, which loses all digits once `e^{−Δξ} ≪ 1`).
///
/// Limits: `Δξ = 0` gives `(0, 0, 1)`, `Δξ = ∞` gives `(1, 0, 0)`.
pub fn exponential_coefficients(reduced_step: Real) -> (Real, Real, Real) {
    let x = reduced_step;
    if x == 0.0 {
        return (0.0, 0.0, 1.0);
    }
    if x == Real::INFINITY {
        return (1.0, 0.0, 0.0);
    }
    let em = (-x).exp_m1(); // e^{−x} − 1, accurate for small x
    let phi = -em / x;
    let beta = if x < EXP_SERIES_BELOW {
        // Alternating series with decreasing terms: stop when the term no longer changes the sum.
        let mut term: Real = 0.5; // (−x)^0 / 2!
        let mut sum: Real = term;
        let mut j = 0.0;
        while term.abs() > Real::EPSILON * sum.abs() {
            term *= -x / (j + 3.0);
            sum += term;
            j += 1.0;
        }
        x * sum
    } else {
        1.0 - phi
    };
    let gamma = if x < 1.0 {
        -em - beta
    } else {
        phi - (-x).exp()
    };
    (beta, gamma, (-x).exp())
}

/// The derivatives `(dβ/dΔξ, dγ/dΔξ, dδ/dΔξ)` of [`exponential_coefficients`]: with `φ' = (e^{−x}(1 + x) − 1)/x²`
/// (from its Taylor series `Σ_{j≥1} j (−x)^{j−1}(−1)/(j+1)!`, `−1/2` at 0, below `Δξ = 0.5`, where the closed form
/// cancels), `β' = −φ'`, `γ' = φ' + e^{−x}`, `δ' = −e^{−x}`; all zero at `Δξ = ∞`.
pub fn exponential_coefficient_slopes(reduced_step: Real) -> (Real, Real, Real) {
    let x = reduced_step;
    if x == Real::INFINITY {
        return (0.0, 0.0, 0.0);
    }
    let e = (-x).exp();
    let phi_x = if x < EXP_SERIES_BELOW {
        // φ' = Σ_{j≥1} (−1)^j j x^{j−1}/(j+1)!: alternating, decreasing terms.
        let mut power = 1.0; // x^{j−1}
        let mut factorial = 2.0; // (j+1)!
        let mut sum: Real = 0.0;
        let mut j = 1.0;
        loop {
            let term = j * power / factorial;
            let signed = if (j as i64) % 2 == 1 { -term } else { term };
            sum += signed;
            if term <= Real::EPSILON * sum.abs() {
                break;
            }
            j += 1.0;
            power *= x;
            factorial *= j + 1.0;
        }
        sum
    } else {
        (e * (1.0 + x) - 1.0) / (x * x)
    };
    (-phi_x, phi_x + e, -e)
}

/// `h = t_{n+1} − t_n ≥ 0`, or the error naming the step.
fn step_length(t_n: Real, t_np1: Real) -> Result<Real, MaterialError> {
    if t_n.is_finite() && t_np1.is_finite() && t_np1 >= t_n {
        Ok(t_np1 - t_n)
    } else {
        Err(MaterialError::TimeStep { t_n, t_np1 })
    }
}

/// The rate factor at time `t` and its s-derivative, from `temperature(t) = (T, T,s)` (evaluated only when the
/// material has a WLF shift): `rate_factor,s = rate_factor · d ln(rate_factor)/dT · T,s`.
fn rate_factor_at(
    material: &Material,
    temperature: &dyn Fn(Real) -> (Real, Real),
    t: Real,
) -> Result<(Real, Real), MaterialError> {
    let Some(wlf) = material.wlf() else {
        return Ok((1.0, 0.0));
    };
    let (temp, temp_s) = temperature(t);
    for (quantity, value) in [("temperature", temp), ("temperature gradient", temp_s)] {
        if !value.is_finite() {
            return Err(MaterialError::NonFiniteInput {
                quantity,
                time: t,
                value,
            });
        }
    }
    let rf = material.rate_factor(temp);
    let rf_s = if temp_s == 0.0 {
        0.0
    } else {
        rf * wlf.log_rate_slope(temp) * temp_s
    };
    Ok((rf, rf_s))
}

/// The s-derivative of [`step_rate`]`(x, τ_G)` for `x,s = x_s`: `x_s/τ_G`, zero where the rate is capped.
fn step_rate_slope(x: Real, x_s: Real, tau_g: Real) -> Real {
    if x / tau_g < MAX_STEP_RATE {
        x_s / tau_g
    } else {
        0.0
    }
}

/// The capped dimensionless rate `min(x/τ_G, MAX_STEP_RATE)` for `x = h · rate_factor` or `ξ`.
fn step_rate(x: Real, tau_g: Real) -> Real {
    (x / tau_g).min(MAX_STEP_RATE)
}

#[cfg(test)]
mod tests {
    // References: (i) the exponential coefficients against 30-digit python/mpmath values of 1 − φ(x),
    // φ(x) − e^{−x}, e^{−x} (φ = −expm1(−x)/x) at x = 1e-12 … 1e3; the formulas avoid cancellation, so a few
    // ulps (tolerance 1e-14 relative) are expected where a naive 1 − φ would be wrong by ~1e-4 at x = 1e-12.
    // (ii) the paper's own trapezoidal formulas (Eqs. evol_f_thermal_disc, evol_varPhi_thermal_1,
    // N_constitutive_disc) written with τ's, compared to the rate form: same algebra, different rounding,
    // 1e-13 relative. (iii) the reduced-time quadrature against a 2000-part composite Gauss–Legendre reference
    // (error < 1e-15 relative by the bound in `ReducedTimeQuadrature`).
    use super::*;
    use crate::material::{PronyBranch, Wlf};

    fn one_branch(tau: Real, wlf: Option<Wlf>) -> Material {
        let prony = Prony::try_new(
            1.0,
            vec![PronyBranch {
                modulus: 2.0,
                tau_g: tau,
            }],
        )
        .expect("valid");
        Material::try_new(prony, 0.3, wlf).expect("valid")
    }

    #[test]
    fn exponential_coefficients_match_high_precision_values() {
        // (x, 1 − φ, φ − e^{−x}, e^{−x}) from mpmath at 30 digits.
        let table: [(Real, Real, Real, Real); 7] = [
            (
                1e-12,
                4.999999999998333e-13,
                4.999999999996667e-13,
                0.999999999999,
            ),
            (
                1e-6,
                4.99999833333375e-07,
                4.999996666667917e-07,
                0.9999990000005,
            ),
            (
                0.01,
                0.004983374916805358,
                0.004966791334026589,
                0.990049833749168,
            ),
            (
                0.5,
                0.21306131942526685,
                0.18040802086209973,
                0.6065306597126334,
            ),
            (
                1.0,
                0.36787944117144233,
                0.2642411176571154,
                0.36787944117144233,
            ),
            (
                30.0,
                0.9666666666666698,
                0.03333333333323664,
                9.357622968840175e-14,
            ),
            (1e3, 0.999, 1e-3, 0.0),
        ];
        for (x, b, g, d) in table {
            let (beta, gamma, delta) = exponential_coefficients(x);
            let rel = |a: Real, w: Real| {
                if w == 0.0 {
                    a.abs()
                } else {
                    ((a - w) / w).abs()
                }
            };
            assert!(rel(beta, b) < 1e-14, "β({x}) = {beta} vs {b}");
            assert!(rel(gamma, g) < 1e-14, "γ({x}) = {gamma} vs {g}");
            assert!(rel(delta, d) < 1e-14, "δ({x}) = {delta} vs {d}");
        }
        assert_eq!(exponential_coefficients(0.0), (0.0, 0.0, 1.0));
        assert_eq!(exponential_coefficients(Real::INFINITY), (1.0, 0.0, 0.0));
        let (b, g, d) = exponential_coefficients(MAX_STEP_RATE);
        assert_eq!((b, d), (1.0, 0.0));
        assert!((g - 1.0 / MAX_STEP_RATE).abs() < 1e-14 / MAX_STEP_RATE);
        // Continuity across the branch switches (series/direct at 0.5, γ formulas at 1).
        for x0 in [EXP_SERIES_BELOW, 1.0] {
            let lo = exponential_coefficients(x0 * (1.0 - 1e-15));
            let hi = exponential_coefficients(x0);
            assert!(
                (lo.0 - hi.0).abs() < 4e-16 && (lo.1 - hi.1).abs() < 4e-16,
                "jump at {x0}"
            );
        }
    }

    #[test]
    fn coefficients_sum_to_one_and_are_finite_for_extreme_rates() {
        // A constant strain is a fixed point of every scheme: β + γ + δ = 1 (to round-off: 4 ulps). Checked
        // from hot (τ_G = 1e-10 s at 120 °C: hλ ≈ 1e19) through T → Tg − C2 (rate underflow) to frozen.
        let material = Material::pla_van_manen_2021();
        let frozen_at = Wlf::van_manen_2021().frozen_below();
        for integrator in [
            Integrator::Trapezoidal,
            Integrator::BackwardEuler,
            Integrator::Exponential,
        ] {
            for (t0, t1) in [
                (120.0, 120.0),
                (120.0, 31.5),
                (31.5, 120.0),
                (frozen_at + 1e-12, 90.0),
                (0.0, -10.0),
            ] {
                let temp = move |t: Real| t0 + (t1 - t0) * t;
                let c =
                    step_coefficients(&material, integrator, 0.0, 1.0, &temp).expect("valid step");
                for i in 0..c.num_branches() {
                    let (b, g, d) = (c.beta[i], c.gamma[i], c.delta[i]);
                    assert!(
                        b.is_finite() && g.is_finite() && d.is_finite(),
                        "{integrator:?} {t0}→{t1}: branch {i}"
                    );
                    let scale = 1.0 + g.abs() + d.abs();
                    assert!(
                        (b + g + d - 1.0).abs() <= 4.0 * Real::EPSILON * scale,
                        "{integrator:?} {t0}→{t1} branch {i}: {b} {g} {d}"
                    );
                }
                let e = c.effective_modulus(material.prony());
                assert!(
                    e >= material.prony().e_inf() * (1.0 - 1e-15)
                        && e <= material.prony().instantaneous_modulus() * (1.0 + 1e-15)
                );
            }
            // Frozen throughout: no relaxation at all.
            let c =
                step_coefficients(&material, integrator, 0.0, 1.0, &|_| -50.0).expect("valid step");
            assert_eq!(c, StepCoefficients::identity(15), "{integrator:?}");
        }
    }

    #[test]
    #[allow(non_snake_case)]
    fn trapezoidal_reproduces_the_papers_constitutive_update() {
        // Paper: Γ_α^{n+1} = h/(2τ1+h) Γ^{n+1} + τ1/(2τ1+h) Ψ, Ψ = (h/τ0) Γ^n + (2τ0 − h)/τ0 Γ_α^n (Eqs.
        // evol_f_thermal_disc, evol_varPhi_thermal_1); C̄ = C0 − Σ C_α h/(2τ1+h) (Eq. N_constitutive_disc).
        let wlf = Wlf::van_manen_2021();
        let material = one_branch(0.3, Some(wlf));
        let (t_n, h) = (0.2, 0.05);
        let temp = |t: Real| 60.0 + 40.0 * t; // 68 → 70 °C over the step
        let c = step_coefficients(&material, Integrator::Trapezoidal, t_n, t_n + h, &temp)
            .expect("valid step");
        let tau = |t: Real| 0.3 * Real::powf(10.0, wlf.log10_shift(temp(t)).expect("unfrozen"));
        let (tau0, tau1) = (tau(t_n), tau(t_n + h));
        let (G_n, G_a_n) = (0.013, -0.004);
        let Psi = h / tau0 * G_n + (2.0 * tau0 - h) / tau0 * G_a_n;
        let paper_history = tau1 / (2.0 * tau1 + h) * Psi;
        let ours_history = c.gamma[0] * G_n + c.delta[0] * G_a_n;
        assert!((ours_history - paper_history).abs() < 1e-13 * paper_history.abs());
        assert!((c.beta[0] - h / (2.0 * tau1 + h)).abs() < 1e-15);
        let paper_cbar = 3.0 - 2.0 * h / (2.0 * tau1 + h);
        assert!((c.effective_modulus(material.prony()) - paper_cbar).abs() < 1e-14 * paper_cbar);
    }

    #[test]
    fn reduced_time_quadrature_accuracy() {
        let material = Material::pla_van_manen_2021();
        let wlf = Wlf::van_manen_2021();
        // Constant temperature: ξ = h · rate_factor exactly (up to the weights' rounding).
        let xi = reduced_time_increment(
            &material,
            &ReducedTimeQuadrature::default(),
            1.0,
            1.25,
            &|_| 80.0,
        )
        .expect("valid step");
        assert!((xi - 0.25 * wlf.rate_factor(80.0)).abs() < 1e-15 * xi);
        // The paper's cantilever cools at 58.5 K/s; k' = ln10 C1 C2 Ṫ/(C2 + T − Tg)² ≈ 64 /s at 60 °C. With a
        // coarse h = 0.05 s (two parts, k'ℓ = 1.6) the estimate 3e-15 (k'ℓ)^10 gives 3e-13 — measured 8e-13
        // (k' grows along the step): tolerance 1e-11. With h = 0.01 s (k'ℓ = 0.3) round-off: 1e-14.
        let ramp = |t: Real| 60.0 + 58.5 * t;
        let fine = ReducedTimeQuadrature {
            subintervals: NonZeroUsize::new(2000).expect("non-zero"),
        };
        for (t_n, h, tol) in [(0.0, 0.05, 1e-11), (0.2, 0.05, 1e-11), (0.3, 0.01, 1e-14)] {
            let reference =
                reduced_time_increment(&material, &fine, t_n, t_n + h, &ramp).expect("valid");
            let got = reduced_time_increment(
                &material,
                &ReducedTimeQuadrature::default(),
                t_n,
                t_n + h,
                &ramp,
            )
            .expect("valid");
            let err = ((got - reference) / reference).abs();
            println!(
                "reduced time, ramp 58.5 K/s from {:.1} °C, h = {h}: relative error {err:.1e}",
                ramp(t_n)
            );
            assert!(err < tol, "t_n = {t_n}, h = {h}: relative error {err:e}");
        }
        // Without WLF the temperature is irrelevant (never evaluated).
        let plain = one_branch(1.0, None);
        assert_eq!(
            reduced_time_increment(&plain, &ReducedTimeQuadrature::default(), 0.0, 2.0, &|_| {
                Real::NAN
            }),
            Ok(2.0)
        );
    }

    #[test]
    fn bad_steps_and_temperatures_are_errors() {
        let material = Material::pla_van_manen_2021();
        for integrator in [
            Integrator::Trapezoidal,
            Integrator::BackwardEuler,
            Integrator::Exponential,
        ] {
            let err = step_coefficients(&material, integrator, 1.0, 0.5, &|_| 80.0)
                .expect_err("backwards");
            assert!(matches!(err, MaterialError::TimeStep { .. }), "{err}");
            let err = step_coefficients(&material, integrator, 0.0, Real::NAN, &|_| 80.0)
                .expect_err("NaN time");
            assert!(matches!(err, MaterialError::TimeStep { .. }), "{err}");
            let err = step_coefficients(&material, integrator, 0.0, 0.1, &|_| Real::NAN)
                .expect_err("NaN temperature");
            assert!(
                matches!(
                    err,
                    MaterialError::NonFiniteInput {
                        quantity: "temperature",
                        ..
                    }
                ),
                "{err}"
            );
            // A zero step is the identity.
            let c = step_coefficients(&material, integrator, 0.3, 0.3, &|_| 90.0).expect("h = 0");
            assert_eq!(c, StepCoefficients::identity(15));
        }
    }

    // Source: the slopes are derivatives. Along a rod with T(s, t) = T₀(t) + s·g(t), the coefficients at s are
    // those of the temperature history t ↦ T(s, t); their s-derivative at s = 0 is checked against central
    // differences in s (step 1e-4 K/g: truncation ~1e-8 relative for these smooth functions of T, round-off
    // ~1e-16/1e-4 = 1e-12), for PLA's 15 branches (rates over 15 decades, some capped, some frozen) over steps
    // while cooling through Tg and heating, for every integrator. Tolerance 1e-6 relative to the largest slope
    // of the step, plus 1e-10 absolute: far below a missing chain-rule factor (O(1)).
    #[test]
    fn coefficient_slopes_are_derivatives_along_the_rod() {
        let material = Material::pla_van_manen_2021();
        let base = |t: Real| 90.0 - 40.0 * t;
        let gradient = |t: Real| 5.0 + 3.0 * t; // K/length
        let quadrature = ReducedTimeQuadrature::default();
        let eps = 1e-4;
        for integrator in [
            Integrator::Trapezoidal,
            Integrator::BackwardEuler,
            Integrator::Exponential,
        ] {
            for (t_n, t_np1) in [(0.0, 0.01), (0.4, 0.45), (0.5, 0.6), (1.0, 1.2)] {
                let at = |s: Real| {
                    let f = move |t: Real| (base(t) + s * gradient(t), gradient(t));
                    let (mut c, mut ds) =
                        (StepCoefficients::default(), StepCoefficients::default());
                    step_coefficients_with_slope_into(
                        &material,
                        integrator,
                        &quadrature,
                        t_n,
                        t_np1,
                        &f,
                        &mut c,
                        Some(&mut ds),
                    )
                    .expect("valid step");
                    (c, ds)
                };
                let (c0, slope) = at(0.0);
                let (plus, _) = at(eps);
                let (minus, _) = at(-eps);
                // The value path is the uniform one's.
                let uniform = step_coefficients(&material, integrator, t_n, t_np1, &base)
                    .expect("valid step");
                assert_eq!(c0, uniform, "{integrator:?}: values as without a field");
                let pairs = [
                    (&slope.beta, &plus.beta, &minus.beta),
                    (&slope.gamma, &plus.gamma, &minus.gamma),
                    (&slope.delta, &plus.delta, &minus.delta),
                ];
                let scale = pairs
                    .iter()
                    .flat_map(|(s, _, _)| s.iter())
                    .fold(0.0_f64, |m, v| m.max(v.abs()));
                for (name, (exact, p, m)) in ["beta", "gamma", "delta"].iter().zip(pairs) {
                    for a in 0..exact.len() {
                        let fd = (p[a] - m[a]) / (2.0 * eps);
                        assert!(
                            (exact[a] - fd).abs() <= 1e-6 * scale + 1e-10,
                            "{integrator:?} step [{t_n}, {t_np1}] branch {}: {name},s {} against {fd}",
                            a + 1,
                            exact[a]
                        );
                    }
                }
            }
        }
        // The exponential coefficients' slopes on their own, across the series/closed-form switch.
        for x in [0.0_f64, 1e-8, 0.1, 0.4999, 0.5001, 2.0, 40.0] {
            let h = 1e-6 * x.max(1e-3);
            let (p, m) = (
                exponential_coefficients(x + h),
                exponential_coefficients((x - h).max(0.0)),
            );
            let width = x + h - (x - h).max(0.0);
            let (b, g, d) = exponential_coefficient_slopes(x);
            for (exact, fd) in [
                (b, (p.0 - m.0) / width),
                (g, (p.1 - m.1) / width),
                (d, (p.2 - m.2) / width),
            ] {
                assert!(
                    (exact - fd).abs() <= 1e-6,
                    "x = {x}: slope {exact} against {fd}"
                );
            }
        }
    }
}
