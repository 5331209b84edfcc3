//! `stentkit study stability`: where each method fails and what the program does there (DESIGN §4, §6).
//!
//! Four maps, each a CSV, an SVG chart and a paragraph of `stability.md`:
//!
//! * **material** — one Maxwell branch (`E∞ = E₁ = 1`) after a unit strain jump, for `h/τ` from `1e-2` to
//!   `1e4`, with the rod's own integrators ([`crate::material::simulate_strain_history`]): (i) held at constant
//!   temperature for [`HOLD_STEPS`] steps; (ii) held at 90 °C for [`HOT_STEPS`] steps and then cooled at the
//!   paper's 58.5 K/s (PLA's WLF constants) with the paper's `h = 1e-3 s` until the branch freezes, `τ_G` chosen
//!   to give the `h/τ` at 90 °C. The exact branch stress `E₁ exp(−ξ(t)/τ_G)` (reduced time `ξ` by fine
//!   quadrature) is positive and decays; the map records the largest deviation from it (the *amplitude*, in
//!   units of `E₁ Δε`) and the sign changes of the computed branch stress (ringing).
//! * **bend45** — the elastic 45° bend (designs/bend45.yaml) with 1 to 20 load steps: whether Newton converges
//!   without cuts, cuts, failed attempts and iterations.
//! * **heating** — the circular arch (designs/circular_arch.yaml; loads and heating 31.5 → 90 °C together):
//!   fewer steps at the design's rate, and faster heating at a fixed step; temperature change per step against
//!   iterations and cuts.
//! * **release** — the release snap of a two-crown straight stent (designs/straight_stent.yaml with 2 crowns,
//!   run to 2 s, released at 1.75 s): step size and release-ramp length against cuts and iterations.

use crate::io::chart::{LineChart, Scale, Series};
use crate::io::design::{DesignOverrides, parse_design_with};
use crate::io::yaml_edit::set_yaml_many;
use crate::material::{
    Integrator, Material, Prony, PronyBranch, ReducedTimeQuadrature, Wlf, reduced_time_increment,
    simulate_strain_history,
};
use crate::math::Real;
use crate::solver::{NewtonReport, Observer, Simulation, StepReport};
use anyhow::Context;
use serde_yaml::Value;
use std::fmt::Write as _;
use std::num::NonZeroUsize;
use std::ops::ControlFlow;
use std::path::Path;
use std::time::Instant;

/// The three integrators, in the order of the maps.
pub const INTEGRATORS: [Integrator; 3] = [
    Integrator::Trapezoidal,
    Integrator::BackwardEuler,
    Integrator::Exponential,
];

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
pub fn material_map(ratios: &[Real]) -> anyhow::Result<Vec<MaterialPoint>> {
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

/// A temperature history \[°C\] as a function of time.
type TemperatureHistory = Box<dyn Fn(Real) -> Real>;

/// One run of the material map.
pub fn material_point(
    scenario: MaterialScenario,
    integrator: Integrator,
    ratio: Real,
) -> anyhow::Result<MaterialPoint> {
    anyhow::ensure!(
        ratio > 0.0 && ratio.is_finite(),
        "h/τ must be positive, got {ratio}"
    );
    let (from, to) = COOLING_FROM_TO;
    let (material, times, temperature): (Material, Vec<Real>, TemperatureHistory) = match scenario {
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
                times,
                Box::new(temperature),
            )
        }
    };
    let stress = simulate_strain_history(&material, integrator, &times, &|_| 1.0, &*temperature)?;
    // Exact branch stress E₁ exp(−ξ/τ_G) for a held unit strain, ξ by fine composite Gauss quadrature.
    let fine = ReducedTimeQuadrature {
        subintervals: NonZeroUsize::new(64).unwrap_or(NonZeroUsize::MIN),
    };
    let tau_g = material.prony().branches()[0].tau_g;
    let mut xi = 0.0;
    let mut exact = vec![1.0];
    for pair in times.windows(2) {
        xi += reduced_time_increment(&material, &fine, pair[0], pair[1], &*temperature)?;
        exact.push((-xi / tau_g).exp());
    }
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

/// What one run of a design did, for the solver maps.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NewtonRun {
    /// The run reached its end time.
    pub completed: bool,
    /// Time reached \[time\].
    pub time: Real,
    /// Converged steps.
    pub steps: usize,
    /// Newton iterations of the converged steps.
    pub iterations: usize,
    /// Most Newton iterations in one converged step.
    pub max_step_iterations: usize,
    /// Step cuts (halvings after a failed attempt) of a completed run; 0 for a failed one (see
    /// `failed_attempts`).
    pub cuts: usize,
    /// Failed Newton attempts (cuts, plus retries without the reused factorisation).
    pub failed_attempts: usize,
    /// Target times of the failed attempts \[time\].
    pub failure_times: Vec<Real>,
    /// Smallest step taken or attempted \[time\].
    pub smallest_step: Real,
    /// Wall time \[s\].
    pub wall: Real,
    /// Why the run stopped early.
    pub failure: Option<String>,
    /// The solver's notices (e.g. the WLF freeze).
    pub notices: Vec<String>,
}

impl NewtonRun {
    /// Mean Newton iterations per converged step.
    pub fn iterations_per_step(&self) -> Real {
        self.iterations as Real / self.steps.max(1) as Real
    }

    /// `yes`, `cut` (completed with cuts) or `FAILED`.
    pub fn outcome(&self) -> &'static str {
        match (self.completed, self.cuts) {
            (false, _) => "FAILED",
            (true, 0) => "yes",
            (true, _) => "cut",
        }
    }
}

/// Counts what the solver does step by step.
struct Watch(NewtonRun);

impl Observer for Watch {
    fn step(&mut self, _: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        let r = &mut self.0;
        r.steps += 1;
        r.iterations += report.newton.iterations;
        r.max_step_iterations = r.max_step_iterations.max(report.newton.iterations);
        r.smallest_step = r.smallest_step.min(report.dt);
        r.time = report.time;
        ControlFlow::Continue(())
    }

    fn step_failed(&mut self, time: Real, dt: Real, _: &NewtonReport) {
        self.0.failed_attempts += 1;
        self.0.failure_times.push(time);
        self.0.smallest_step = self.0.smallest_step.min(dt);
    }
}

/// Runs `text` with `overrides` and records what the solver did; a solver failure is recorded, an invalid
/// design is an error.
pub fn newton_run(
    text: &str,
    path: &Path,
    overrides: &DesignOverrides,
) -> anyhow::Result<NewtonRun> {
    let design = parse_design_with(text, path, overrides)?;
    let model = &design.model;
    let started = Instant::now();
    let mut sim = Simulation::new(model)?;
    let mut watch = Watch(NewtonRun {
        smallest_step: Real::INFINITY,
        ..NewtonRun::default()
    });
    let result = sim.run(&mut [&mut watch]);
    let mut run = watch.0;
    run.wall = started.elapsed().as_secs_f64();
    run.notices = sim.notices().to_vec();
    match result {
        Ok(summary) => {
            run.completed = !summary.stopped;
            run.cuts = summary.cuts;
        }
        Err(e) => {
            // A failed run returns no summary: its cuts are not known apart from the retries with a fresh
            // factorisation, so they are reported as failed attempts only.
            run.cuts = 0;
            run.failure = Some(e.to_string());
        }
    }
    Ok(run)
}

/// The designs the solver maps use, embedded so that the command runs from any folder.
pub mod designs {
    /// designs/bend45.yaml.
    pub const BEND45: &str = include_str!("../../../designs/bend45.yaml");
    /// designs/circular_arch.yaml.
    pub const ARCH: &str = include_str!("../../../designs/circular_arch.yaml");
    /// designs/straight_stent.yaml.
    pub const STRAIGHT_STENT: &str = include_str!("../../../designs/straight_stent.yaml");
}

/// One point of a solver map: its parameters (named) and the run.
#[derive(Debug, Clone, PartialEq)]
pub struct SolverPoint {
    /// Parameter values, in the map's column order.
    pub parameters: Vec<Real>,
    /// The run.
    pub run: NewtonRun,
}

/// A solver map: its name, parameter column names and points.
#[derive(Debug, Clone, PartialEq)]
pub struct SolverMap {
    /// Map name (file stem).
    pub name: &'static str,
    /// Names of the parameter columns (with units).
    pub columns: Vec<&'static str>,
    /// The runs.
    pub points: Vec<SolverPoint>,
}

/// The 45° bend with each number of equal load steps.
pub fn bend45_map(
    load_steps: &[usize],
    mut progress: impl FnMut(&str),
) -> anyhow::Result<SolverMap> {
    let mut points = Vec::new();
    for &n in load_steps {
        anyhow::ensure!(n > 0, "load steps must be positive");
        let overrides = DesignOverrides {
            step: Some(1.0 / n as Real),
            ..DesignOverrides::default()
        };
        let run = newton_run(designs::BEND45, Path::new("bend45.yaml"), &overrides)?;
        progress(&format!("bend45, {n} load steps: {}", describe(&run)));
        points.push(SolverPoint {
            parameters: vec![n as Real],
            run,
        });
    }
    Ok(SolverMap {
        name: "bend45",
        columns: vec!["load_steps"],
        points,
    })
}

/// Temperature change of the arch's heating \[K\] (31.5 → 90 °C).
const ARCH_HEATING: Real = 58.5;
/// The arch's load ramp and end time \[s\].
const ARCH_END: Real = 5.0;

/// The arch heated over `duration` (loads still ramp over 5 s) with step `h`: `(duration [s], h [s])` pairs.
pub fn heating_map(
    cases: &[(Real, Real)],
    mut progress: impl FnMut(&str),
) -> anyhow::Result<SolverMap> {
    let mut points = Vec::new();
    for &(duration, h) in cases {
        anyhow::ensure!(
            duration > 0.0 && duration <= ARCH_END && h > 0.0,
            "heating duration in (0, 5] s and a positive step"
        );
        let mut schedule = vec![vec![0.0, 31.5], vec![duration, 31.5 + ARCH_HEATING]];
        if duration < ARCH_END {
            schedule.push(vec![ARCH_END, 31.5 + ARCH_HEATING]);
        }
        let text = set_yaml_many(
            designs::ARCH,
            &[(&["temperature"], serde_yaml::to_value(schedule)?)],
        )?;
        let overrides = DesignOverrides {
            step: Some(h),
            ..DesignOverrides::default()
        };
        let run = newton_run(&text, Path::new("circular_arch.yaml"), &overrides)?;
        let per_step = ARCH_HEATING * h.min(duration) / duration;
        progress(&format!(
            "arch heated over {duration} s, h = {h}: ΔT = {per_step:.3} K per step: {}",
            describe(&run)
        ));
        points.push(SolverPoint {
            parameters: vec![duration, h, per_step],
            run,
        });
    }
    Ok(SolverMap {
        name: "heating",
        columns: vec!["heating_duration_s", "h_s", "dT_per_step_K"],
        points,
    })
}

/// Release time of the straight stent \[s\].
const RELEASE: Real = 1.75;
/// End of the release runs \[s\].
const RELEASE_END: Real = 2.0;

/// A two-crown straight stent run to 2 s (released at 1.75 s) with step `h`, release ramp `ramp` and `n`
/// control points per patch (degree by [`release_mesh`]): `(h [s], ramp [s], n)` triples.
pub fn release_map(
    cases: &[(Real, Real, usize)],
    mut progress: impl FnMut(&str),
) -> anyhow::Result<SolverMap> {
    let mut points = Vec::new();
    for &(h, ramp, n) in cases {
        anyhow::ensure!(h > 0.0 && ramp > 0.0, "positive step and ramp");
        let text = set_yaml_many(
            designs::STRAIGHT_STENT,
            &[
                (&["stent", "crowns"], Value::from(2)),
                (&["time", "release_ramp"], Value::from(ramp)),
            ],
        )?;
        let overrides = DesignOverrides {
            step: Some(h),
            end_time: Some(RELEASE_END),
            degree: Some(release_mesh(n)),
            points: Some(n),
            ..DesignOverrides::default()
        };
        let run = newton_run(&text, Path::new("straight_stent.yaml"), &overrides)?;
        let at_release = run
            .failure_times
            .iter()
            .filter(|&&t| t >= RELEASE && t <= RELEASE + ramp + h)
            .count();
        progress(&format!(
            "2-crown stent, p = {}, n = {n}, h = {h}, release ramp {ramp} s: {} ({at_release} failed attempts at the release)",
            release_mesh(n),
            describe(&run)
        ));
        points.push(SolverPoint {
            parameters: vec![h, ramp, n as Real, at_release as Real],
            run,
        });
    }
    Ok(SolverMap {
        name: "release",
        columns: vec![
            "h_s",
            "release_ramp_s",
            "n",
            "failed_attempts_in_release_window",
        ],
        points,
    })
}

/// The degree used with `n` control points in the release map: the design's `p = 6` at its `n = 20`, `p = 5`
/// on coarser meshes.
pub fn release_mesh(n: usize) -> usize {
    if n >= 20 { 6 } else { 5 }
}

/// One line about a run.
fn describe(run: &NewtonRun) -> String {
    let mut s = format!(
        "{} steps, {} iterations ({:.1}/step, max {}), {} cuts, {} failed attempts, {:.2} s",
        run.steps,
        run.iterations,
        run.iterations_per_step(),
        run.max_step_iterations,
        run.cuts,
        run.failed_attempts,
        run.wall
    );
    if let Some(f) = &run.failure {
        let _ = write!(s, "; FAILED at t = {}: {}", run.time, first_sentence(f));
    }
    s
}

/// The message up to its first colon after `min_step` (the residual list is long).
fn first_sentence(message: &str) -> &str {
    message.split(": after").next().unwrap_or(message)
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

/// A solver map as CSV.
pub fn solver_csv(map: &SolverMap, header: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# {header}");
    let _ = writeln!(
        s,
        "{},converged_without_cuts,completed,time_reached,steps,newton_iterations,iterations_per_step,max_step_iterations,cuts,failed_attempts,smallest_step,wall_s,failure",
        map.columns.join(",")
    );
    for p in &map.points {
        let r = &p.run;
        let params: Vec<String> = p.parameters.iter().map(|v| format!("{v}")).collect();
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{:.3},{},{},{},{:e},{:.3},{}",
            params.join(","),
            r.completed && r.cuts == 0,
            r.completed,
            r.time,
            r.steps,
            r.iterations,
            r.iterations_per_step(),
            r.max_step_iterations,
            r.cuts,
            r.failed_attempts,
            r.smallest_step,
            r.wall,
            r.failure
                .as_deref()
                .map(|f| first_sentence(f).replace([',', '\n'], " "))
                .unwrap_or_default()
        );
    }
    s
}

/// A solver map's chart: iterations per step, most iterations in a step and cuts against the parameter in
/// column `x` (log axis), one group of series per combination of the values in the columns `group`.
pub fn solver_chart(
    map: &SolverMap,
    title: &str,
    x: usize,
    x_label: &str,
    group: &[usize],
) -> LineChart {
    let mut chart = LineChart::new(title, x_label, "count");
    chart.x_scale = Scale::Log;
    let key = |p: &SolverPoint| -> Vec<Real> { group.iter().map(|&i| p.parameters[i]).collect() };
    let mut groups: Vec<Vec<Real>> = Vec::new();
    for p in &map.points {
        if !groups.contains(&key(p)) {
            groups.push(key(p));
        }
    }
    for (k, g) in groups.iter().enumerate() {
        let of: Vec<&SolverPoint> = map.points.iter().filter(|p| key(p) == *g).collect();
        let prefix: String = group
            .iter()
            .zip(g)
            .map(|(&i, v)| format!("{} = {v}: ", map.columns[i]))
            .collect();
        let line = |f: &dyn Fn(&NewtonRun) -> Real| -> Vec<(Real, Real)> {
            of.iter().map(|p| (p.parameters[x], f(&p.run))).collect()
        };
        chart.series.push(
            Series::new(
                format!("{prefix}iterations per step"),
                line(&|r| r.iterations_per_step()),
            )
            .with_markers()
            .with_color(3 * k),
        );
        chart.series.push(
            Series::new(
                format!("{prefix}max iterations in a step"),
                line(&|r| r.max_step_iterations as Real),
            )
            .dashed()
            .with_color(3 * k + 1),
        );
        chart.series.push(
            Series::new(format!("{prefix}cuts"), line(&|r| r.cuts as Real))
                .with_markers()
                .with_color(3 * k + 2),
        );
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

/// A solver map's paragraph of `stability.md`.
pub fn solver_summary(
    map: &SolverMap,
    title: &str,
    describe_point: impl Fn(&[Real]) -> String,
) -> String {
    let mut s = format!("## {title} ({0}.csv, {0}.svg)\n\n", map.name);
    for p in &map.points {
        let r = &p.run;
        let what = match (&r.failure, r.cuts) {
            (Some(f), _) => format!(
                "**failed** at t = {} after {} failed Newton attempts (step cut down to {:.3e}): {}",
                r.time,
                r.failed_attempts,
                r.smallest_step,
                first_sentence(f)
            ),
            (None, 0) => format!(
                "converged without cuts, {:.1} iterations per step (max {})",
                r.iterations_per_step(),
                r.max_step_iterations
            ),
            (None, c) => format!(
                "completed with {c} cuts ({} failed attempts, smallest step {:.3e}), {:.1} iterations per step (max {})",
                r.failed_attempts,
                r.smallest_step,
                r.iterations_per_step(),
                r.max_step_iterations
            ),
        };
        let _ = writeln!(s, "- {}: {what}.", describe_point(&p.parameters));
        for n in &r.notices {
            let _ = writeln!(s, "  - notice: {n}");
        }
    }
    s.push('\n');
    s
}

/// Settings of the stability study.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilityStudy {
    /// `h/τ` of the material map.
    pub ratios: Vec<Real>,
    /// Load steps of the 45° bend.
    pub load_steps: Vec<usize>,
    /// `(heating duration [s], h [s])` of the arch.
    pub heating: Vec<(Real, Real)>,
    /// `(h [s], release ramp [s], control points per patch)` of the two-crown stent.
    pub release: Vec<(Real, Real, usize)>,
}

impl Default for StabilityStudy {
    /// The default maps (about a minute on one core).
    fn default() -> Self {
        Self {
            ratios: (-4..=8).map(|k| 10f64.powf(k as Real / 2.0)).collect(),
            load_steps: vec![1, 2, 3, 4, 5, 10, 20],
            heating: vec![
                (5.0, 5.0),
                (5.0, 2.5),
                (5.0, 1.0),
                (5.0, 0.5),
                (5.0, 0.25),
                (5.0, 0.1),
                (2.0, 0.1),
                (0.5, 0.1),
                (0.1, 0.1),
            ],
            release: vec![
                (0.25, 0.001, 20),
                (0.25, 0.25, 20),
                (0.1, 0.001, 20),
                (0.1, 0.1, 20),
                (0.05, 0.05, 20),
                (0.05, 0.2, 20),
                (0.02, 0.001, 20),
                (0.02, 0.02, 20),
                (0.02, 0.2, 20),
                (0.01, 0.001, 20),
                (0.01, 0.01, 20),
                (0.01, 0.2, 20),
                (0.01, 0.01, 14),
                (0.01, 0.3, 14),
            ],
        }
    }
}

/// Runs every map of `study`, writes the CSVs, charts and `stability.md` into `output`, and returns the
/// summary text.
pub fn stability(
    study: &StabilityStudy,
    output: &Path,
    mut progress: impl FnMut(&str),
) -> anyhow::Result<String> {
    use crate::io::chart::write_svg;
    let write = |name: &str, text: &str| {
        let file = output.join(name);
        std::fs::write(&file, text).with_context(|| format!("cannot write {}", file.display()))
    };
    let mut summary = String::from(
        "# Stability map\n\nWhere each method fails and what stentkit does there (`stentkit study stability`).\n\n",
    );
    if !study.ratios.is_empty() {
        let rows = material_map(&study.ratios)?;
        write("material.csv", &material_csv(&rows))?;
        write_svg(&material_chart(&rows), &output.join("material.svg"))?;
        summary.push_str(&material_summary(&rows));
        progress("material map done");
    }
    for name in ["bend45", "heating", "release"] {
        let map = match name {
            "bend45" if !study.load_steps.is_empty() => {
                bend45_map(&study.load_steps, &mut progress)?
            }
            "heating" if !study.heating.is_empty() => heating_map(&study.heating, &mut progress)?,
            "release" if !study.release.is_empty() => release_map(&study.release, &mut progress)?,
            _ => continue,
        };
        let (header, chart, text) = match name {
            "bend45" => (
                "elastic 45-degree bend (designs/bend45.yaml), tip force 600 in equal load steps",
                solver_chart(
                    &map,
                    "45-degree bend: Newton against load steps",
                    0,
                    "load steps",
                    &[],
                ),
                solver_summary(
                    &map,
                    "bend45: load step size of the elastic 45° bend",
                    |p| format!("{} load steps", p[0]),
                ),
            ),
            "heating" => (
                "circular arch (designs/circular_arch.yaml): moments ramp over 5 s while heating 31.5 -> 90 C over the given duration, with step h",
                solver_chart(
                    &map,
                    "arch heated under load: Newton against temperature change per step",
                    2,
                    "temperature change per step [K]",
                    &[],
                ),
                solver_summary(
                    &map,
                    "heating: temperature change per step of the loaded arch",
                    |p| {
                        format!(
                            "heating over {} s, h = {} s (ΔT = {:.2} K per step)",
                            p[0], p[1], p[2]
                        )
                    },
                ),
            ),
            _ => (
                "two-crown straight stent (designs/straight_stent.yaml, crowns: 2) to t = 2 s, released at 1.75 s",
                solver_chart(
                    &map,
                    "release snap of a 2-crown stent: Newton against release ramp",
                    1,
                    "release ramp [s]",
                    &[2, 0],
                ),
                solver_summary(
                    &map,
                    "release: step size and release ramp of the stent's release snap",
                    |p| {
                        format!(
                            "p = {}, n = {}, h = {} s, release ramp {} s ({} failed attempts in [1.75 s, 1.75 s + ramp + h])",
                            release_mesh(p[2] as usize),
                            p[2],
                            p[0],
                            p[1],
                            p[3]
                        )
                    },
                ),
            ),
        };
        write(&format!("{name}.csv"), &solver_csv(&map, header))?;
        write_svg(&chart, &output.join(format!("{name}.svg")))?;
        summary.push_str(&text);
        if name == "release" {
            let _ = writeln!(
                summary,
                "Release at t = {RELEASE} s; the reaction of each released component is ramped to zero over the release ramp (time.release_ramp, default one step).\n"
            );
        }
    }
    write("stability.md", &summary)?;
    Ok(summary)
}
