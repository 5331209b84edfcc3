//! What the solver does on one run of a design, and the solver maps built from such runs: whether Newton
//! converges without cuts, how many iterations a step takes, where steps are cut or the run fails. The
//! scenarios that make the maps are in [`super::scenarios`].

use crate::math::Real;
use crate::model::Model;
use crate::post::chart::{LineChart, Scale, Series};
use crate::solver::simulation::NoObserver;
use crate::solver::{NewtonReport, Observer, Simulation, SolverError, StepReport};
use std::fmt::Write as _;
use std::ops::ControlFlow;
use std::time::Instant;

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
    /// The solver's notices (e.g. the WLF freeze) and the stabilisation's warnings.
    pub notices: Vec<String>,
    /// `(path parameter, load factor)` of every converged increment (arc-length runs; empty for time steps).
    pub load_path: Vec<(Real, Real)>,
    /// The displacement of the model's first probe at the end (or where the run stopped).
    pub final_probe: Option<crate::math::Vec3>,
    /// What automatic stabilisation did (runs with `solver.stabilisation`).
    pub stabilisation: Option<crate::solver::StabiliserState>,
    /// When the device's wires first passed through each other (`Simulation::wires_crossed`), if they did.
    pub wires_crossed: Option<Real>,
}

impl NewtonRun {
    /// Mean Newton iterations per converged step.
    pub fn iterations_per_step(&self) -> Real {
        self.iterations as Real / self.steps.max(1) as Real
    }

    /// The first extremum of the load factor along an arc-length path (a limit point in load; the path starts
    /// at λ = 0 and rises, so a maximum), refined between the samples ([`crate::post::path::load_extrema`]);
    /// `None` for time steps or a path whose load factor never turns.
    pub fn first_limit_load_factor(&self) -> Option<Real> {
        let mut path = vec![(0.0, 0.0)];
        path.extend_from_slice(&self.load_path);
        crate::post::path::load_extrema(&path)
            .first()
            .map(|&(_, l)| l)
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

/// Runs `model` and records what the solver did; a failure of the time stepping is recorded in the result.
///
/// # Errors
/// The solver's when the model cannot be discretised or analysed (before any step).
pub fn newton_run(model: &Model) -> Result<NewtonRun, SolverError> {
    newton_run_with(model, &mut NoObserver)
}

/// [`newton_run`], with `also` told of every step too (what a map records beyond Newton's counts).
///
/// # Errors
/// The solver's when the model cannot be discretised or analysed (before any step).
pub fn newton_run_with(model: &Model, also: &mut dyn Observer) -> Result<NewtonRun, SolverError> {
    let started = Instant::now();
    let mut sim = Simulation::new(model)?;
    let mut watch = Watch(NewtonRun {
        smallest_step: Real::INFINITY,
        ..NewtonRun::default()
    });
    let result = sim.run(&mut [&mut watch, also]);
    let mut run = watch.0;
    run.wall = started.elapsed().as_secs_f64();
    run.notices = sim.notices().to_vec();
    // The stabilisation's warnings and the point terms' (contact left above its penetration tolerance).
    run.notices.extend(sim.warnings());
    run.stabilisation = model.solver().stabilisation.map(|_| *sim.stabilisation());
    run.wires_crossed = sim.wires_crossed();
    run.final_probe = model
        .probes
        .first()
        .map(|p| sim.probe_displacement(&p.location));
    match result {
        Ok(summary) => {
            // An arc-length path that used its increments allowed before the end load factor did not complete.
            let short = model
                .solver()
                .path
                .arc_length()
                .is_some_and(|a| sim.load_factor() != Some(a.end_load_factor));
            run.completed = !summary.stopped && !short;
            run.cuts = summary.cuts;
            if short {
                run.failure = Some(format!(
                    "the path ended at load factor {:.6} after its increments allowed",
                    sim.load_factor().unwrap_or(0.0)
                ));
            }
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

/// One line about a run.
pub fn describe(run: &NewtonRun) -> String {
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
pub fn first_sentence(message: &str) -> &str {
    message.split(": after").next().unwrap_or(message)
}

/// A solver map as CSV.
pub fn solver_csv(map: &SolverMap, header: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# {header}");
    let _ = writeln!(
        s,
        "{},converged_without_cuts,completed,time_reached,steps,newton_iterations,iterations_per_step,max_step_iterations,cuts,failed_attempts,smallest_step,wall_s,first_limit_load_factor,damped_steps,dissipated_ratio,wires_crossed,failure",
        map.columns.join(",")
    );
    for p in &map.points {
        let r = &p.run;
        let params: Vec<String> = p.parameters.iter().map(|v| format!("{v}")).collect();
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{:.3},{},{},{},{:e},{:.3},{},{},{},{},{}",
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
            r.first_limit_load_factor()
                .map(|l| format!("{l:.6}"))
                .unwrap_or_default(),
            r.stabilisation
                .map(|s| s.damped_steps.to_string())
                .unwrap_or_default(),
            r.stabilisation
                .map(|s| format!("{:.3e}", s.ratio()))
                .unwrap_or_default(),
            r.wires_crossed.map(|t| t.to_string()).unwrap_or_default(),
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
        let damped = match r.stabilisation {
            Some(st) if st.damped_steps > 0 => format!(
                "; {} damped steps dissipated {:.2e} of the largest strain energy{}",
                st.damped_steps,
                st.ratio(),
                if st.ratio() > crate::model::StabilisationSettings::default().limit {
                    " (above the limit 0.05: not quasi-static)"
                } else if st.energy_limit_time.is_some() {
                    " (above the limit 0.05 for a while: see the notice)"
                } else {
                    ""
                }
            ),
            Some(_) => "; no step needed damping".to_string(),
            None => String::new(),
        };
        let _ = writeln!(s, "- {}: {what}{damped}.", describe_point(&p.parameters));
        for n in &r.notices {
            let _ = writeln!(s, "  - notice: {n}");
        }
    }
    s.push('\n');
    s
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
        r.load_path
            .extend(report.load_factor.map(|l| (report.time, l)));
        ControlFlow::Continue(())
    }

    fn step_failed(&mut self, time: Real, dt: Real, _: &NewtonReport) {
        self.0.failed_attempts += 1;
        self.0.failure_times.push(time);
        self.0.smallest_step = self.0.smallest_step.min(dt);
    }
}
