//! Single-point (1-D) drivers for verification and studies: the Prony solid under a prescribed strain or
//! stress history and a temperature history, with the rod's own step coefficients.
//!
//! Convention for both drivers: before `times[0]` the material is at rest and unstrained (all branch strains
//! zero); the prescribed value at `times[0]` is applied there instantaneously, so the response at `times[0]` is
//! glassy (`σ = E0 ε`). A strain or stress *step* is therefore expressed by a history that is already at its
//! held value at `times[0]`.

use super::{
    Integrator, Material, MaterialError, ReducedTimeQuadrature, StepCoefficients,
    step_coefficients_into,
};
use crate::math::Real;

/// The 1-D stress history `σ(t_k) = E∞ ε + Σ_α E_α (ε − ε_α)` \[stress\] under the strain history `strain`
/// \[-\] at the `times` \[time\] (finite, non-decreasing), with `temperature` \[°C\] as a function of time.
///
/// Errors: a backward or non-finite time step, a non-finite temperature or strain.
pub fn simulate_strain_history(
    material: &Material,
    integrator: Integrator,
    times: &[Real],
    strain: &dyn Fn(Real) -> Real,
    temperature: &dyn Fn(Real) -> Real,
) -> Result<Vec<Real>, MaterialError> {
    let prony = material.prony();
    let mut out = Vec::with_capacity(times.len());
    let Some(&t0) = times.first() else {
        return Ok(out);
    };
    let mut eps_n = evaluate("strain", strain, t0)?;
    let mut branches = vec![0.0; prony.num_branches()];
    out.push(prony.instantaneous_modulus() * eps_n);
    let mut coeffs = StepCoefficients::default();
    let quadrature = ReducedTimeQuadrature::default();
    for pair in times.windows(2) {
        let (t_n, t_np1) = (pair[0], pair[1]);
        step_coefficients_into(
            material,
            integrator,
            &quadrature,
            t_n,
            t_np1,
            temperature,
            &mut coeffs,
        )?;
        let eps = evaluate("strain", strain, t_np1)?;
        advance(&coeffs, eps, eps_n, &mut branches);
        out.push(stress(material, eps, &branches));
        eps_n = eps;
    }
    Ok(out)
}

/// The 1-D strain history \[-\] under the stress history `stress` \[stress\] at the `times` \[time\] (finite,
/// non-decreasing), with `temperature` \[°C\] as a function of time: each step solves the scalar affine
/// equation `σ^{n+1} = Ē ε^{n+1} − H` for `ε^{n+1}` (creep and recovery tests).
///
/// Errors: as [`simulate_strain_history`], plus [`MaterialError::SingularCompliance`] when `Ē = 0` (a Maxwell
/// fluid, `E∞ = 0`, relaxed completely within a step).
pub fn simulate_stress_history(
    material: &Material,
    integrator: Integrator,
    times: &[Real],
    stress: &dyn Fn(Real) -> Real,
    temperature: &dyn Fn(Real) -> Real,
) -> Result<Vec<Real>, MaterialError> {
    let prony = material.prony();
    let mut out = Vec::with_capacity(times.len());
    let Some(&t0) = times.first() else {
        return Ok(out);
    };
    let mut eps_n = evaluate("stress", stress, t0)? / prony.instantaneous_modulus();
    let mut branches = vec![0.0; prony.num_branches()];
    out.push(eps_n);
    let mut coeffs = StepCoefficients::default();
    let quadrature = ReducedTimeQuadrature::default();
    for pair in times.windows(2) {
        let (t_n, t_np1) = (pair[0], pair[1]);
        step_coefficients_into(
            material,
            integrator,
            &quadrature,
            t_n,
            t_np1,
            temperature,
            &mut coeffs,
        )?;
        let sigma = evaluate("stress", stress, t_np1)?;
        let e_bar = coeffs.effective_modulus(prony);
        // `≤ 0` rather than `== 0`, and NaN too (none is expected): never divide by a non-positive modulus.
        if e_bar.is_nan() || e_bar <= 0.0 {
            return Err(MaterialError::SingularCompliance {
                time: t_np1,
                modulus: e_bar,
            });
        }
        let history: Real = prony
            .branches()
            .iter()
            .zip(&branches)
            .enumerate()
            .map(|(i, (b, eps_a))| b.modulus * (coeffs.gamma[i] * eps_n + coeffs.delta[i] * eps_a))
            .sum();
        let eps = (sigma + history) / e_bar;
        advance(&coeffs, eps, eps_n, &mut branches);
        out.push(eps);
        eps_n = eps;
    }
    Ok(out)
}

/// `f(t)`, or the error naming the quantity if it is not finite.
fn evaluate(
    quantity: &'static str,
    f: &dyn Fn(Real) -> Real,
    time: Real,
) -> Result<Real, MaterialError> {
    let value = f(time);
    if value.is_finite() {
        Ok(value)
    } else {
        Err(MaterialError::NonFiniteInput {
            quantity,
            time,
            value,
        })
    }
}

/// `ε_α ← β_α ε^{n+1} + γ_α ε^n + δ_α ε_α` for every branch.
fn advance(coeffs: &StepCoefficients, eps: Real, eps_n: Real, branches: &mut [Real]) {
    for (i, eps_a) in branches.iter_mut().enumerate() {
        *eps_a = coeffs.beta[i] * eps + coeffs.gamma[i] * eps_n + coeffs.delta[i] * *eps_a;
    }
}

/// `σ = E∞ ε + Σ_α E_α (ε − ε_α)`.
fn stress(material: &Material, eps: Real, branches: &[Real]) -> Real {
    let prony = material.prony();
    prony.e_inf() * eps
        + prony
            .branches()
            .iter()
            .zip(branches)
            .map(|(b, eps_a)| b.modulus * (eps - eps_a))
            .sum::<Real>()
}

#[cfg(test)]
mod tests {
    // Verification of the single-point material against independent references; every test says which.
    // Errors are max-norm over the output times, in the stress (or strain) unit of the test. Printed numbers
    // are shown with `cargo test --lib material -- --nocapture`.
    use super::*;
    use crate::material::{Prony, PronyBranch, Wlf};

    const ALL: [Integrator; 3] = [
        Integrator::Trapezoidal,
        Integrator::BackwardEuler,
        Integrator::Exponential,
    ];

    fn material(e_inf: Real, branches: &[(Real, Real)], wlf: Option<Wlf>) -> Material {
        let branches = branches
            .iter()
            .map(|&(modulus, tau_g)| PronyBranch { modulus, tau_g })
            .collect();
        let prony = Prony::try_new(e_inf, branches).expect("valid Prony series");
        Material::try_new(prony, 0.33, wlf).expect("valid material")
    }

    fn grid(t_end: Real, steps: usize) -> Vec<Real> {
        (0..=steps)
            .map(|k| t_end * k as Real / steps as Real)
            .collect()
    }

    fn max_abs_diff(a: &[Real], b: &[Real]) -> Real {
        assert_eq!(a.len(), b.len());
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, Real::max)
    }

    /// `[1.234e-5, …]`.
    fn sci(values: &[Real]) -> String {
        let items: Vec<String> = values.iter().map(|v| format!("{v:.3e}")).collect();
        format!("[{}]", items.join(", "))
    }

    /// Observed order from the two finest of a sequence of step halvings.
    fn orders(errors: &[Real]) -> Vec<Real> {
        errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
    }

    #[test]
    fn relaxation_after_a_strain_step() {
        // Reference: closed form of the generalized Maxwell solid under a strain step ε0 held at constant T,
        // σ(t) = ε0 (E∞ + Σ E_α e^{−t λ_α}), λ_α = rate_factor(T)/τ_G,α (Ferry 1980, ch. 3; paper Eq.
        // evol_f_m_thermal integrated at constant λ). Each scheme also has a discrete closed form: the branch
        // overstress ε − ε_α is multiplied by δ_α every step, so σ_n = ε0 (E∞ + Σ E_α δ_α^n) with
        // δ = (1 − hλ/2)/(1 + hλ/2) (trapezoidal), 1/(1 + hλ) (backward Euler), e^{−hλ} (exponential) — which
        // every scheme must reproduce to round-off (1e-13 relative to E0 ε0 over 100 steps). The exponential
        // scheme is exact for constant strain, so it also meets the continuous closed form to round-off.
        // Run twice: without WLF, and with van Manen's WLF at 75 °C (rate factor 10^{14.59·5/53.43} = 23.2;
        // τ_G scaled by 0.1 so that the fastest branch has hλ = 116: there the trapezoidal rule rings, and its
        // error against the continuous solution is O(1) — see the stability test).
        let eps0 = 0.01;
        let branches = [(2.0, 0.1), (3.0, 1.0), (1.5, 10.0)];
        let (t_end, steps) = (5.0, 100);
        let times = grid(t_end, steps);
        let h = t_end / steps as Real;
        for (wlf, temp, tau_scale) in [(None, 20.0, 1.0), (Some(Wlf::van_manen_2021()), 75.0, 0.1)]
        {
            let scaled: Vec<_> = branches
                .iter()
                .map(|&(e, tau)| (e, tau * tau_scale))
                .collect();
            let m = material(1.0, &scaled, wlf);
            let rf = m.rate_factor(temp);
            let e0 = m.prony().instantaneous_modulus();
            let exact: Vec<Real> = times
                .iter()
                .map(|&t| eps0 * m.prony().relaxation_modulus(t, rf))
                .collect();
            for integrator in ALL {
                let sigma = simulate_strain_history(&m, integrator, &times, &|_| eps0, &|_| temp)
                    .expect("runs");
                let discrete: Vec<Real> = (0..=steps)
                    .map(|n| {
                        let decay = |tau: Real| {
                            let x = h * rf / tau;
                            match integrator {
                                Integrator::Trapezoidal => (1.0 - x / 2.0) / (1.0 + x / 2.0),
                                Integrator::BackwardEuler => 1.0 / (1.0 + x),
                                Integrator::Exponential => (-x).exp(),
                            }
                        };
                        let sum: Real = scaled
                            .iter()
                            .map(|&(e, tau)| e * decay(tau).powi(n as i32))
                            .sum();
                        eps0 * (1.0 + sum)
                    })
                    .collect();
                let err_discrete = max_abs_diff(&sigma, &discrete) / (eps0 * e0);
                let err_exact = max_abs_diff(&sigma, &exact) / (eps0 * e0);
                println!(
                    "relaxation (WLF: {}) {integrator:?}: max |σ − σ_exact|/(E0 ε0) = {err_exact:.3e}, vs its discrete form {err_discrete:.1e}",
                    wlf.is_some()
                );
                assert!(err_discrete < 1e-13, "{integrator:?}: {err_discrete:e}");
                if integrator == Integrator::Exponential {
                    assert!(
                        err_exact < 1e-13,
                        "exponential must be exact: {err_exact:e}"
                    );
                } else {
                    assert!(err_exact > 1e-6, "{integrator:?} cannot be exact here");
                }
            }
        }
    }

    #[test]
    fn creep_of_a_standard_linear_solid() {
        // Reference: the standard linear solid (spring E∞ parallel to a Maxwell element E1, τ) under a stress
        // σ applied at t = 0 and held (Findley, Lai & Onaran, *Creep and Relaxation of Nonlinear Viscoelastic
        // Materials*, 1976, §5.2 "three-parameter solid"). Derivation: σ = E∞ ε + E1 (ε − ε1) held constant
        // gives ε1 = (E0 ε − σ)/E1, so ε̇1 = E0 ε̇/E1 = (ε − ε1)/τ = (σ − E∞ ε)/(E1 τ), i.e. ε̇ = (σ − E∞ ε)/(E0 τ)
        // with ε(0+) = σ/E0:  ε(t) = σ/E∞ − σ (1/E∞ − 1/E0) e^{−t/τ_c},  τ_c = τ E0/E∞.
        // The strain is not piecewise linear, so no scheme is exact: measured errors must fall at the
        // schemes' orders (±0.15) under step halving, h = τ/5 … τ/80, over t ∈ [0, 3 τ_c].
        let (e_inf, e1, tau, sigma) = (1.0, 3.0, 1.0, 0.02);
        let e0 = e_inf + e1;
        let tau_c = tau * e0 / e_inf;
        let m = material(e_inf, &[(e1, tau)], None);
        let t_end = 3.0 * tau_c;
        let exact = |t: Real| sigma / e_inf - sigma * (1.0 / e_inf - 1.0 / e0) * (-t / tau_c).exp();
        for integrator in ALL {
            let errors: Vec<Real> = [60, 120, 240, 480, 960]
                .iter()
                .map(|&n| {
                    let times = grid(t_end, n);
                    let eps =
                        simulate_stress_history(&m, integrator, &times, &|_| sigma, &|_| 20.0)
                            .expect("runs");
                    let reference: Vec<Real> = times.iter().map(|&t| exact(t)).collect();
                    max_abs_diff(&eps, &reference) / (sigma / e_inf)
                })
                .collect();
            let p = orders(&errors);
            println!(
                "creep {integrator:?}: relative errors {}, orders {p:.3?}",
                sci(&errors)
            );
            let last = p[p.len() - 1];
            assert!(
                (last - integrator.order() as Real).abs() < 0.15,
                "{integrator:?}: order {last}"
            );
        }
    }

    #[test]
    fn order_of_accuracy_sine_strain_constant_temperature() {
        // Reference: closed-form convolution for ε = ε0 sin ωt (ε(0) = 0, no jump) at constant temperature:
        // each branch overstress q = ε − ε_α solves q̇ = ε̇ − λ q, q(0) = 0, so
        // q(t) = ε0 ω [λ cos ωt + ω sin ωt − λ e^{−λt}]/(λ² + ω²), σ = E∞ ε + Σ E_α q_α.
        // Observed orders from the two finest of five halvings (h = 0.05 … 0.003125, hλ ≤ 0.5) must be
        // 2 (trapezoidal), 1 (backward Euler), 2 (exponential) within ±0.15.
        let eps0 = 0.01;
        let omega = 2.0 * std::f64::consts::PI;
        let branches = [(2.0, 0.1), (3.0, 0.5), (1.0, 3.0)];
        let m = material(1.0, &branches, None);
        let t_end = 2.0;
        let exact = |t: Real| {
            let eps = eps0 * (omega * t).sin();
            let q: Real = branches
                .iter()
                .map(|&(e, tau)| {
                    let l = 1.0 / tau;
                    e * eps0
                        * omega
                        * (l * (omega * t).cos() + omega * (omega * t).sin() - l * (-l * t).exp())
                        / (l * l + omega * omega)
                })
                .sum();
            eps + q
        };
        let scale = eps0 * m.prony().instantaneous_modulus();
        for integrator in ALL {
            let errors: Vec<Real> = [40, 80, 160, 320, 640]
                .iter()
                .map(|&n| {
                    let times = grid(t_end, n);
                    let strain = |t: Real| eps0 * (omega * t).sin();
                    let s = simulate_strain_history(&m, integrator, &times, &strain, &|_| 20.0)
                        .expect("runs");
                    let reference: Vec<Real> = times.iter().map(|&t| exact(t)).collect();
                    max_abs_diff(&s, &reference) / scale
                })
                .collect();
            let p = orders(&errors);
            println!(
                "sine, constant T, {integrator:?}: relative errors {}, orders {p:.3?}",
                sci(&errors)
            );
            let last = p[p.len() - 1];
            assert!(
                (last - integrator.order() as Real).abs() < 0.15,
                "{integrator:?}: order {last}"
            );
        }
    }

    /// Classical RK4 on ε̇_α = λ_α(t)(ε(t) − ε_α) for every branch, returning σ at every fine step.
    fn rk4_reference(
        m: &Material,
        t_end: Real,
        steps: usize,
        strain: &dyn Fn(Real) -> Real,
        temp: &dyn Fn(Real) -> Real,
    ) -> Vec<Real> {
        let prony = m.prony();
        let h = t_end / steps as Real;
        let rates = |t: Real| -> Vec<Real> {
            prony
                .branches()
                .iter()
                .map(|b| m.rate_factor(temp(t)) / b.tau_g)
                .collect()
        };
        let mut y = vec![0.0; prony.num_branches()];
        let sigma = |t: Real, y: &[Real]| {
            let e = strain(t);
            prony.e_inf() * e
                + prony
                    .branches()
                    .iter()
                    .zip(y)
                    .map(|(b, ya)| b.modulus * (e - ya))
                    .sum::<Real>()
        };
        let mut out = vec![sigma(0.0, &y)];
        for k in 0..steps {
            let t = k as Real * h;
            let f = |t: Real, y: &[Real]| -> Vec<Real> {
                let e = strain(t);
                rates(t).iter().zip(y).map(|(l, ya)| l * (e - ya)).collect()
            };
            let k1 = f(t, &y);
            let y2: Vec<Real> = y.iter().zip(&k1).map(|(a, k)| a + 0.5 * h * k).collect();
            let k2 = f(t + 0.5 * h, &y2);
            let y3: Vec<Real> = y.iter().zip(&k2).map(|(a, k)| a + 0.5 * h * k).collect();
            let k3 = f(t + 0.5 * h, &y3);
            let y4: Vec<Real> = y.iter().zip(&k3).map(|(a, k)| a + h * k).collect();
            let k4 = f(t + h, &y4);
            for i in 0..y.len() {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            out.push(sigma((k + 1) as Real * h, &y));
        }
        out
    }

    #[test]
    fn order_of_accuracy_sine_strain_through_tg() {
        // Reference: classical 4th-order Runge–Kutta on the branch ODEs (paper Eq. evol_f_m_thermal) with
        // 2^15 steps (hλ ≤ 1e-3: RK4 error ~ (hλ)^4 ≈ 1e-12, far below the coarse errors ≥ 1e-7), for
        // ε = ε0 sin 2πt and a temperature ramp 60 → 80 °C over t ∈ [0, 1] through van Manen's Tg = 70 °C
        // (rate factor 1.6e-4 → 314). Cross-checked against the exponential scheme at the same fine step.
        // Orders from the two finest of five halvings (h = 1/32 … 1/512) within ±0.15 of 2, 1, 2.
        let eps0 = 0.01;
        let m = material(
            1.0,
            &[(2.0, 10.0), (3.0, 100.0), (1.0, 1000.0)],
            Some(Wlf::van_manen_2021()),
        );
        let temp = |t: Real| 60.0 + 20.0 * t;
        let strain = |t: Real| eps0 * (2.0 * std::f64::consts::PI * t).sin();
        let fine = 1 << 15;
        let reference = rk4_reference(&m, 1.0, fine, &strain, &temp);
        let scale = eps0 * m.prony().instantaneous_modulus();
        let check = simulate_strain_history(
            &m,
            Integrator::Exponential,
            &grid(1.0, fine),
            &strain,
            &temp,
        )
        .expect("runs");
        let cross = max_abs_diff(&check, &reference) / scale;
        println!("through Tg: exponential at h = 2^-15 vs RK4: {cross:.2e}");
        assert!(cross < 1e-8, "fine exponential vs RK4: {cross:e}");
        for integrator in ALL {
            let errors: Vec<Real> = [32, 64, 128, 256, 512]
                .iter()
                .map(|&n| {
                    let times = grid(1.0, n);
                    let s = simulate_strain_history(&m, integrator, &times, &strain, &temp)
                        .expect("runs");
                    let sampled: Vec<Real> = (0..=n).map(|k| reference[k * (fine / n)]).collect();
                    max_abs_diff(&s, &sampled) / scale
                })
                .collect();
            let p = orders(&errors);
            println!(
                "sine, T ramp through Tg, {integrator:?}: relative errors {}, orders {p:.3?}",
                sci(&errors)
            );
            let last = p[p.len() - 1];
            assert!(
                (last - integrator.order() as Real).abs() < 0.15,
                "{integrator:?}: order {last}"
            );
        }
    }

    #[test]
    fn exponential_is_exact_for_strain_linear_in_reduced_time() {
        // Reference 1 (constant T): ramp ε = R t up to t1 = 0.6, then held; q = ε − ε_α solves q̇ = ε̇ − λq:
        // q = (R/λ)(1 − e^{−λt}) for t ≤ t1, q(t1) e^{−λ(t − t1)} after. The kink lies on the grid, so the
        // exponential scheme is exact (1e-13 relative to round-off over 20 steps with hλ up to 1).
        // Reference 2 (T ramp 60 → 80 °C): ε = k ξ(t), ξ(t) = ∫_0^t rate_factor(T) ds, is linear in every
        // branch's reduced time ξ/τ_G, so q_α = k τ_G,α (1 − e^{−ξ(t)/τ_G,α}) exactly; ξ(t) comes from a
        // 2000-part Gauss–Legendre quadrature (error < 1e-15), the scheme uses its default 2 parts per step
        // (error ~1e-11 of ξ per step at this ramp, h = 0.05): agreement to 1e-9 relative.
        let (rate, t1) = (0.02, 0.6);
        let branches = [(2.0, 0.05), (3.0, 0.3), (1.0, 2.0)];
        let m = material(1.0, &branches, None);
        let times = grid(2.0, 20);
        let strain = |t: Real| rate * t.min(t1);
        let exact = |t: Real| {
            let q: Real = branches
                .iter()
                .map(|&(e, tau)| {
                    let l = 1.0 / tau;
                    let q1 = rate / l * (1.0 - (-l * t.min(t1)).exp());
                    e * if t <= t1 {
                        q1
                    } else {
                        q1 * (-l * (t - t1)).exp()
                    }
                })
                .sum();
            strain(t) + q
        };
        let s = simulate_strain_history(&m, Integrator::Exponential, &times, &strain, &|_| 20.0)
            .expect("runs");
        let reference: Vec<Real> = times.iter().map(|&t| exact(t)).collect();
        let err = max_abs_diff(&s, &reference) / (rate * t1 * m.prony().instantaneous_modulus());
        println!("ramp-and-hold, exponential: {err:.2e}");
        assert!(err < 1e-13, "{err:e}");

        let wlf = Wlf::van_manen_2021();
        let branches = [(2.0, 10.0), (3.0, 100.0)];
        let m = material(1.0, &branches, Some(wlf));
        let temp = |t: Real| 60.0 + 20.0 * t;
        let fine = ReducedTimeQuadrature {
            subintervals: std::num::NonZeroUsize::new(2000).expect("non-zero"),
        };
        let xi = |t: Real| {
            crate::material::reduced_time_increment(&m, &fine, 0.0, t, &temp).expect("valid")
        };
        let k = 1e-4;
        let times = grid(1.0, 20);
        let xis: Vec<Real> = times.iter().map(|&t| xi(t)).collect();
        let strain = |t: Real| {
            let i = (t * 20.0).round() as usize; // the driver evaluates the strain at grid times only
            k * xis[i]
        };
        let s = simulate_strain_history(&m, Integrator::Exponential, &times, &strain, &temp)
            .expect("runs");
        let reference: Vec<Real> = xis
            .iter()
            .map(|&x| {
                k * x
                    + branches
                        .iter()
                        .map(|&(e, tau)| e * k * tau * (1.0 - (-x / tau).exp()))
                        .sum::<Real>()
            })
            .collect();
        let scale = reference.iter().fold(0.0, |a: Real, b| a.max(b.abs()));
        let err = max_abs_diff(&s, &reference) / scale;
        println!("strain linear in reduced time, T ramp, exponential: {err:.2e}");
        assert!(err < 1e-9, "{err:e}");
    }

    #[test]
    fn stability_of_a_held_strain_jump_with_h_100_tau() {
        // Reference: the discrete amplification factors of the three schemes for a fast branch
        // (E∞ = E1 = 1, τ = 1, h = 100 τ) after a strain jump ε = 1 held; the exact overstress
        // q = ε − ε1 = e^{−t/τ} is positive and decays monotonically (to e^{−100} after one step).
        //  * trapezoidal: q_n = ((1 − 50)/(1 + 50))^n = (−0.9608)^n — A-stable but not L-stable: it RINGS,
        //    alternating in sign and decaying only by 4 % per step (|q_20| ≈ 0.44 where the truth is 0);
        //  * backward Euler: q_n = (1/101)^n — positive, monotone, no ringing (L-stable);
        //  * exponential: q_n = e^{−100 n} — positive, monotone, exact.
        // q_n = (σ_n − E∞ ε)/E1 is read from the stress. Ratio check to 1e-12 (20 steps of round-off).
        let m = material(1.0, &[(1.0, 1.0)], None);
        let times = grid(2000.0, 20);
        for integrator in ALL {
            let s =
                simulate_strain_history(&m, integrator, &times, &|_| 1.0, &|_| 20.0).expect("runs");
            let q: Vec<Real> = s.iter().map(|sigma| sigma - 1.0).collect();
            println!(
                "h = 100τ, {integrator:?}: q_1..q_5 = {}, q_20 = {:.3e}",
                sci(&q[1..6]),
                q[20]
            );
            match integrator {
                Integrator::Trapezoidal => {
                    for n in 1..q.len() {
                        assert!(
                            q[n] * q[n - 1] < 0.0,
                            "trapezoidal must alternate in sign at step {n}"
                        );
                        assert!((q[n] / q[n - 1] + 49.0 / 51.0).abs() < 1e-12);
                    }
                    assert!(
                        q[20].abs() > 0.4,
                        "trapezoidal ringing decays only like 0.96^n"
                    );
                }
                Integrator::BackwardEuler | Integrator::Exponential => {
                    for n in 1..q.len() {
                        assert!(
                            q[n] >= 0.0 && q[n] <= q[n - 1],
                            "{integrator:?} must not ring (step {n})"
                        );
                    }
                    assert!(q[1] <= 1.0 / 101.0 * (1.0 + 1e-15));
                }
            }
        }
    }

    #[test]
    fn trapezoidal_ringing_is_amplified_by_cooling() {
        // The paper's programme with a load *jump*: PLA strain ε0 = 1e-3 applied at t = 0 at 90 °C and held,
        // cooling at 58.5 K/s from t = 0.5 s to 31.5 °C at t = 1.5 s, the paper's h = 1e-3 s.
        // Reference: closed form for a held strain at variable temperature, σ(t) = ε0 (E∞ + Σ E_α
        // exp(−ξ(t)/τ_G,α)), ξ(t) = ∫_0^t rate_factor(T) ds from a 40-part-per-step Gauss–Legendre quadrature
        // (round-off accurate). The exponential scheme is exact for a held strain up to its 2-part quadrature
        // (k'ℓ ≤ 0.04 here, round-off per step; measured 2e-14 over 2000 steps): 1e-12. Backward Euler is
        // first order on the branches that relax during cooling (measured 5e-4): 1e-2. The trapezoidal rule rings after the jump (fast branches have hλ up to 1e11 at
        // 90 °C, amplification ≈ −1), and while cooling its amplification (1 − r₀)/(1 + r₁) exceeds 1 in
        // magnitude whenever r₀ − r₁ > 2: the ringing grows with the drop of the rate factor, a spurious
        // stress many orders above the truth (measured 3e8×) before the branches freeze.
        let m = Material::pla_van_manen_2021();
        let eps0 = 1e-3;
        let temp = |t: Real| 90.0 - 58.5 * (t - 0.5).clamp(0.0, 1.0);
        let (t_end, steps) = (2.0, 2000);
        let times = grid(t_end, steps);
        let fine = ReducedTimeQuadrature {
            subintervals: std::num::NonZeroUsize::new(40).expect("non-zero"),
        };
        let mut xi = vec![0.0];
        for w in times.windows(2) {
            let d = crate::material::reduced_time_increment(&m, &fine, w[0], w[1], &temp)
                .expect("valid step");
            xi.push(xi[xi.len() - 1] + d);
        }
        let prony = m.prony();
        let exact: Vec<Real> = xi
            .iter()
            .map(|&x| {
                let sum: Real = prony
                    .branches()
                    .iter()
                    .map(|b| b.modulus * (-(x / b.tau_g)).exp())
                    .sum();
                eps0 * (prony.e_inf() + sum)
            })
            .collect();
        for integrator in ALL {
            let s =
                simulate_strain_history(&m, integrator, &times, &|_| eps0, &temp).expect("runs");
            // Relative error after the glassy first 0.1 s (the jump itself is resolved by no scheme at h).
            let worst = s
                .iter()
                .zip(&exact)
                .skip(100)
                .map(|(a, b)| ((a - b) / b).abs())
                .fold(0.0, Real::max);
            println!(
                "jump at 90 °C then cooling, h = 1e-3 s, {integrator:?}: max |σ − σ_exact|/σ_exact = {worst:.2e}, σ(1 s) = {:.4e} MPa (exact {:.4e})",
                s[1000], exact[1000]
            );
            match integrator {
                Integrator::Trapezoidal => {
                    assert!(worst > 1e3, "expected the cooling blow-up: {worst:e}")
                }
                Integrator::BackwardEuler => assert!(worst < 1e-2, "{worst:e}"),
                Integrator::Exponential => assert!(worst < 1e-12, "{worst:e}"),
            }
        }
    }

    #[test]
    fn pla_glassy_when_cold_rubbery_when_hot() {
        // Reference: paper Table PLA (E∞ = 80.59 MPa, 15 branches) with van Manen's WLF (Table aT_PLA);
        // closed-form relaxation modulus E(t) = E∞ + Σ E_α exp(−t · rate_factor/τ_G,α) evaluated with
        // python/mpmath: E0 = 2394.40 MPa; at 31.5 °C rate_factor = 2.707e-57, so E(1 s) = E0 to ~1e-45
        // (glassy: the program is fixed); at 90 °C rate_factor = 18374.33, E(1 s) = 81.18914768792568 MPa,
        // within 0.75 % of E∞ (rubbery: only the 1e5-s branch, τ(90 °C) = 5.44 s, and E∞ remain). The strain
        // step is held with h = 0.01 s; the exponential scheme is exact for it (1e-12 relative to E0: the
        // sum of 16 terms of size up to E0). The other two are shown for what they do to a jump on PLA:
        // trapezoidal rings on the branches with hλ ≫ 1 (τ(90 °C) down to 5e-15 s), backward Euler damps.
        let m = Material::pla_van_manen_2021();
        let e0 = m.prony().instantaneous_modulus();
        assert!((e0 - 2394.40).abs() < 1e-12 * e0);
        let times = grid(1.0, 100);
        let eps0 = 1e-3;
        for integrator in ALL {
            let cold = simulate_strain_history(&m, integrator, &times, &|_| eps0, &|_| 31.5)
                .expect("runs");
            let e_cold = cold[100] / eps0;
            assert!(
                (e_cold - e0).abs() < 1e-12 * e0,
                "{integrator:?} cold: {e_cold}"
            );
            let hot = simulate_strain_history(&m, integrator, &times, &|_| eps0, &|_| 90.0)
                .expect("runs");
            let e_hot = hot[100] / eps0;
            println!(
                "PLA {integrator:?}: E(1 s) at 31.5 °C = {e_cold:.6} MPa, at 90 °C = {e_hot:.6} MPa (E∞ = 80.59)"
            );
            if integrator == Integrator::Exponential {
                assert!((e_hot - 81.18914768792568).abs() < 1e-12 * e0, "{e_hot}");
            }
        }
        // At Tg (70 °C) after 1 s: the branches with τ_G ≤ 0.1 s have relaxed, the others not yet.
        let want = m.prony().relaxation_modulus(1.0, 1.0);
        let at_tg =
            simulate_strain_history(&m, Integrator::Exponential, &times, &|_| eps0, &|_| 70.0)
                .expect("runs");
        println!("PLA at Tg: E(1 s) = {:.4} MPa", at_tg[100] / eps0);
        assert!((at_tg[100] / eps0 - want).abs() < 1e-12 * e0);
    }

    #[test]
    fn shape_memory_cycle_and_errors() {
        // A programme in the paper's spirit (§4.2): hot 90 °C loading, cooling to 31.5 °C, unloading, reheating.
        // Reference: physics, not a closed form — the stress-controlled strain must (i) creep at 90 °C,
        // (ii) keep most of it after unloading cold (fixity), (iii) recover towards 0 on reheating. The
        // exponential scheme (accurate through the temperature ramps) is used; bounds are loose on purpose.
        let m = Material::pla_van_manen_2021();
        let sigma0 = 1.0; // MPa
        let stress = |t: Real| if t < 2.0 { sigma0 } else { 0.0 };
        let temp = |t: Real| {
            if t < 1.0 {
                90.0
            } else if t < 1.5 {
                90.0 - 117.0 * (t - 1.0)
            } else if t < 3.0 {
                31.5
            } else if t < 3.5 {
                31.5 + 117.0 * (t - 3.0)
            } else {
                90.0
            }
        };
        let times = grid(30.0, 3000);
        let eps = simulate_stress_history(&m, Integrator::Exponential, &times, &stress, &temp)
            .expect("runs");
        let at = |t: Real| eps[(t * 100.0).round() as usize];
        println!(
            "SMP cycle: ε(0) = {:.3e}, ε(1) = {:.3e}, ε(1.99) = {:.3e}, ε(2.5) = {:.3e}, ε(30) = {:.3e}",
            at(0.0),
            at(1.0),
            at(1.99),
            at(2.5),
            at(30.0)
        );
        assert!(at(1.0) > 20.0 * at(0.0), "creep at 90 °C");
        assert!(at(2.5) > 0.9 * at(1.99), "shape fixed when cold");
        assert!(at(30.0) < 0.1 * at(2.5), "shape recovered when reheated");

        // Errors carry the offending value.
        let err = simulate_strain_history(
            &m,
            Integrator::Trapezoidal,
            &[0.0, 1.0],
            &|t| if t > 0.5 { Real::NAN } else { 0.0 },
            &|_| 80.0,
        )
        .expect_err("NaN strain");
        assert!(
            matches!(err, MaterialError::NonFiniteInput { quantity: "strain", time, .. } if time == 1.0),
            "{err}"
        );
        let fluid = material(0.0, &[(1.0, 1e-3)], None);
        let err = simulate_stress_history(
            &fluid,
            Integrator::BackwardEuler,
            &[0.0, 1e110],
            &|_| 1.0,
            &|_| 20.0,
        )
        .expect_err("a Maxwell fluid relaxed within a step cannot carry a stress");
        assert!(
            matches!(err, MaterialError::SingularCompliance { .. }),
            "{err}"
        );
        assert_eq!(
            simulate_strain_history(&m, Integrator::Exponential, &[], &|_| 0.0, &|_| 20.0),
            Ok(vec![])
        );
    }
}
