//! The material map of the stability study: one Maxwell branch after a unit strain jump, integrated by each of
//! the rod's internal-variable updates ([`crate::material::simulate_strain_history`]) and compared with its
//! exact solution, for `h/τ` over many decades.
//!
//! Scenarios ([`MaterialScenario`]): (i) held at constant temperature for [`HOLD_STEPS`] steps; (ii) held at
//! 90 °C for [`HOT_STEPS`] steps and then cooled at the paper's 58.5 K/s (PLA's WLF constants) with the paper's
//! `h = 1e-3 s` until the branch freezes, `τ_G` chosen to give the `h/τ` at 90 °C.
//!
//! Reference ([`exact_branch_stress`]): for a strain held at `Δε = 1` from `t = 0` the branch stress of the
//! generalized Maxwell model is `σ₁(t) = E₁ Δε exp(−ξ(t)/τ_G)`, with the reduced time `ξ(t) = ∫₀ᵗ dt'/a_T(T(t'))`
//! (paper Eqs. for the Prony series with the WLF shift; DESIGN §4 "WLF"), positive and decaying. The map
//! records the largest deviation from it (the *amplitude*, in units of `E₁ Δε`) and the sign changes of the
//! computed branch stress (ringing: the trapezoidal rule is A- but not L-stable).

use super::INTEGRATORS;
use crate::material::{
    Integrator, Material, Prony, PronyBranch, ReducedTimeQuadrature, Wlf, reduced_time_increment,
    simulate_strain_history,
};
use crate::math::Real;
use crate::post::chart::{LineChart, Scale, Series};
use crate::study::StudyError;
use std::fmt::Write as _;
use std::num::NonZeroUsize;

/// Steps of the constant-temperature hold after the jump.
pub const HOLD_STEPS: usize = 40;
/// Steps at 90 °C before the cooling starts.
pub const HOT_STEPS: usize = 5;
/// Step of the cooling scenario \[s\] (the paper's).
pub const COOLING_STEP: Real = 1e-3;
/// Cooling rate \[K/s\] (the paper's cantilever).
pub const COOLING_RATE: Real = 58.5;
/// Hot and final temperatures of the cooling scenario \[°C\] (the final one is below PLA's `Tg − C2 = 21.57 °C`).
pub const COOLING_FROM_TO: (Real, Real) = (90.0, 20.0);
/// Branch stresses below this fraction of the jump's `E₁ Δε` are round-off, not ringing: the update
/// coefficients `β + γ + δ` sum to 1 only to a few ulps, so a relaxed branch hovers at `±1e-16`.
pub const NOISE_FLOOR: Real = 1e-12;
/// Amplitudes are charted on a log axis; an exact zero (the exponential rule is exact for a held strain) is
/// drawn at this floor.
pub const CHART_FLOOR: Real = 1e-17;

/// Equal parts per step of the reduced-time quadrature of [`exact_branch_stress`] (5-point Gauss–Legendre on
/// each): 32 times a run's default two, so that the reference's own quadrature error is far below the
/// integrators' deviations it measures.
pub const REFERENCE_SUBINTERVALS: NonZeroUsize = match NonZeroUsize::new(64) {
    Some(n) => n,
    None => NonZeroUsize::MIN,
};

/// The material scenarios.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MaterialScenario {
    /// Strain jump, then held at constant temperature.
    JumpHold,
    /// Strain jump at 90 °C, then held while cooling until the branch freezes.
    JumpCool,
}

impl MaterialScenario {
    /// Short name for the CSV and charts.
    pub fn name(&self) -> &'static str {
        match self {
            MaterialScenario::JumpHold => "jump-hold",
            MaterialScenario::JumpCool => "jump-cool",
        }
    }
}

/// One point of the material map.
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialPoint {
    /// The scenario.
    pub scenario: MaterialScenario,
    /// The integrator.
    pub integrator: Integrator,
    /// `h/τ` (at 90 °C for the cooling scenario) \[-\].
    pub ratio: Real,
    /// Largest `|σ_α − σ_α,exact|` over the steps after the jump, over `E₁ Δε` \[-\].
    pub amplitude: Real,
    /// Sign changes of the computed branch stress beyond [`NOISE_FLOOR`] (the exact one never changes sign).
    pub sign_changes: usize,
    /// Branch stress at the last step over `E₁ Δε` (the frozen-in stress after cooling) \[-\].
    pub last: Real,
    /// The exact value of `last` \[-\].
    pub last_exact: Real,
}

/// The material map for the given `h/τ` ratios (both scenarios, every integrator).
pub fn material_map(ratios: &[Real]) -> Result<Vec<MaterialPoint>, StudyError> {
    let mut rows = Vec::new();
    for scenario in [MaterialScenario::JumpHold, MaterialScenario::JumpCool] {
        for integrator in INTEGRATORS {
            for &ratio in ratios {
                rows.push(material_point(scenario, integrator, ratio)?);
            }
        }
    }
    Ok(rows)
}

/// One run of the material map.
pub fn material_point(
    scenario: MaterialScenario,
    integrator: Integrator,
    ratio: Real,
) -> Result<MaterialPoint, StudyError> {
    if !(ratio > 0.0 && ratio.is_finite()) {
        return Err(StudyError::InvalidSetting {
            setting: "h/τ",
            value: ratio,
            expected: "positive and finite",
        });
    }
    let (from, to) = COOLING_FROM_TO;
    let (material, tau_g, times, temperature): (Material, Real, Vec<Real>, TemperatureHistory) =
        match scenario {
            MaterialScenario::JumpHold => {
                let prony = Prony::try_new(
                    1.0,
                    vec![PronyBranch {
                        modulus: 1.0,
                        tau_g: 1.0,
                    }],
                )?;
                let times = (0..=HOLD_STEPS).map(|k| k as Real * ratio).collect();
                (
                    Material::try_new(prony, 0.3, None)?,
                    1.0,
                    times,
                    Box::new(|_| 20.0),
                )
            }
            MaterialScenario::JumpCool => {
                let wlf = Wlf::van_manen_2021();
                // τ(90 °C) = τ_G / a(90 °C) = h / ratio.
                let tau_g = wlf.rate_factor(from) * COOLING_STEP / ratio;
                let prony = Prony::try_new(
                    1.0,
                    vec![PronyBranch {
                        modulus: 1.0,
                        tau_g,
                    }],
                )?;
                let hot = HOT_STEPS as Real * COOLING_STEP;
                let cooling = (from - to) / COOLING_RATE;
                let steps = HOT_STEPS + (cooling / COOLING_STEP).ceil() as usize;
                let times = (0..=steps).map(|k| k as Real * COOLING_STEP).collect();
                let temperature = move |t: Real| (from - COOLING_RATE * (t - hot).max(0.0)).max(to);
                (
                    Material::try_new(prony, 0.3, Some(wlf))?,
                    tau_g,
                    times,
                    Box::new(temperature),
                )
            }
        };
    let stress = simulate_strain_history(&material, integrator, &times, &|_| 1.0, &*temperature)?;
    let exact = exact_branch_stress(&material, tau_g, &times, &*temperature)?;
    // σ = E∞ ε + E₁ (ε − ε₁) with E∞ = 1, ε = 1: the branch stress is σ − 1.
    let branch: Vec<Real> = stress.iter().map(|s| s - 1.0).collect();
    let amplitude = branch
        .iter()
        .zip(&exact)
        .skip(1)
        .map(|(b, e)| (b - e).abs())
        .fold(0.0, Real::max);
    let signs: Vec<Real> = branch
        .iter()
        .filter(|b| b.abs() > NOISE_FLOOR)
        .map(|b| b.signum())
        .collect();
    let sign_changes = signs.windows(2).filter(|w| w[0] != w[1]).count();
    Ok(MaterialPoint {
        scenario,
        integrator,
        ratio,
        amplitude,
        sign_changes,
        last: branch.last().copied().unwrap_or(0.0),
        last_exact: exact.last().copied().unwrap_or(0.0),
    })
}

/// The exact branch stress over `E₁ Δε` of one Maxwell branch (relaxation time `tau_g` at the glass
/// transition \[time\], shifted by `material`'s WLF law) under a strain held from `t = times[0]`, at every
/// time of `times`: `exp(−ξ(t)/τ_G)` with the reduced time `ξ(t) = ∫ dt'/a_T(T(t'))` (DESIGN §4 "WLF"; Prony
/// series of the paper §2), `ξ` by composite Gauss–Legendre quadrature on [`REFERENCE_SUBINTERVALS`] parts per
/// step.
///
/// # Errors
/// [`crate::material::MaterialError`] when a step goes backwards or the temperature is not finite.
pub fn exact_branch_stress(
    material: &Material,
    tau_g: Real,
    times: &[Real],
    temperature: &dyn Fn(Real) -> Real,
) -> Result<Vec<Real>, crate::material::MaterialError> {
    let fine = ReducedTimeQuadrature {
        subintervals: REFERENCE_SUBINTERVALS,
    };
    let mut xi = 0.0;
    let mut exact = vec![1.0];
    for pair in times.windows(2) {
        xi += reduced_time_increment(material, &fine, pair[0], pair[1], temperature)?;
        exact.push((-xi / tau_g).exp());
    }
    Ok(exact)
}

/// The material map as CSV.
pub fn material_csv(rows: &[MaterialPoint]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# one Maxwell branch (E_inf = E_1 = 1) after a unit strain jump; jump-hold: {HOLD_STEPS} steps at constant temperature; jump-cool: {HOT_STEPS} steps at {} C, then cooling at {COOLING_RATE} K/s to {} C with h = {COOLING_STEP} s (PLA WLF), h/tau at the hot temperature",
        COOLING_FROM_TO.0, COOLING_FROM_TO.1
    );
    let _ = writeln!(
        s,
        "# amplitude = max |sigma_branch - exact| / (E_1 d_eps) after the jump; sign_changes of the branch stress beyond {NOISE_FLOOR:e}"
    );
    let _ = writeln!(
        s,
        "scenario,integrator,h_over_tau,amplitude,sign_changes,last_branch_stress,last_exact"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{:e},{:.6e},{},{:.6e},{:.6e}",
            r.scenario.name(),
            r.integrator.name(),
            r.ratio,
            r.amplitude,
            r.sign_changes,
            r.last,
            r.last_exact
        );
    }
    s
}

/// The material map's chart: amplitude against `h/τ`, one series per scenario and integrator.
pub fn material_chart(rows: &[MaterialPoint]) -> LineChart {
    let mut chart = LineChart::new(
        "one Maxwell branch after a strain jump: deviation from the exact branch stress",
        "h / tau (tau at 90 C for cooling)",
        "max |branch stress - exact| / (E_1 jump)",
    );
    chart.x_scale = Scale::Log;
    chart.y_scale = Scale::Log;
    for (k, scenario) in [MaterialScenario::JumpHold, MaterialScenario::JumpCool]
        .into_iter()
        .enumerate()
    {
        for (c, integrator) in INTEGRATORS.into_iter().enumerate() {
            let points: Vec<(Real, Real)> = rows
                .iter()
                .filter(|r| r.scenario == scenario && r.integrator == integrator)
                .map(|r| (r.ratio, r.amplitude.max(CHART_FLOOR)))
                .collect();
            let mut series = Series::new(
                format!("{}, {}", integrator.name(), scenario.name()),
                points,
            )
            .with_markers()
            .with_color(c);
            if k == 1 {
                series = series.dashed();
            }
            chart.series.push(series);
        }
    }
    chart
}

/// The material map's paragraph of `stability.md`.
pub fn material_summary(rows: &[MaterialPoint]) -> String {
    let mut s = String::from(
        "## material: one Maxwell branch, h/τ (material.csv, material.svg)\n\n\
         A unit strain jump on one branch, then held (jump-hold) or held while cooling from 90 °C at 58.5 K/s \
         with h = 1e-3 s until the branch freezes (jump-cool; h/τ at 90 °C). Amplitude = largest deviation from \
         the exact branch stress over `E₁Δε`; ringing = sign changes of the branch stress (the exact one is \
         positive).\n\n",
    );
    for scenario in [MaterialScenario::JumpHold, MaterialScenario::JumpCool] {
        for integrator in INTEGRATORS {
            let of: Vec<&MaterialPoint> = rows
                .iter()
                .filter(|r| r.scenario == scenario && r.integrator == integrator)
                .collect();
            let rings = of.iter().find(|r| r.sign_changes > 0);
            let worst = of.iter().map(|r| r.amplitude).fold(0.0, Real::max);
            let at_100 =
                of.iter()
                    .find(|r| (r.ratio - 100.0).abs() < 1e-9)
                    .map_or(String::new(), |r| {
                        format!(
                            ", at h/τ = 100 amplitude {:.2e}, {} sign changes",
                            r.amplitude, r.sign_changes
                        )
                    });
            let ring = match rings {
                Some(r) => format!("rings from h/τ = {:.3}", r.ratio),
                None => "never changes sign".to_string(),
            };
            let _ = writeln!(
                s,
                "- {} / {}: {ring}; largest amplitude {worst:.2e}{at_100}.",
                scenario.name(),
                integrator.name()
            );
        }
    }
    s.push_str(
        "\nWhat the program does: nothing at run time — the ringing is a property of the trapezoidal rule (A- \
         but not L-stable), not a Newton failure; the rod solver converges on the wrong stresses. Use \
         `material.integrator: backward-euler` or `exponential` where a load or strain jumps while hot.\n\n",
    );
    s
}

/// A temperature history \[°C\] as a function of time.
type TemperatureHistory = Box<dyn Fn(Real) -> Real>;
