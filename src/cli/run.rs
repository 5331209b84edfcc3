//! `stentkit run`: simulate a design and write the run folder.

use crate::io::design::load_design;
use crate::io::history::HistoryWriter;
use crate::math::Real;
use crate::solver::{NewtonReport, Observer, Simulation, StepReport};
use anyhow::{Context, bail};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Reports progress on stderr about once a second.
struct Progress {
    started: Instant,
    last: Instant,
    quiet: bool,
    /// Notices already printed.
    said: usize,
    /// Print every failed Newton attempt.
    verbose: bool,
}

impl Observer for Progress {
    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        for notice in &sim.notices()[self.said..] {
            eprintln!("note: {notice}");
        }
        self.said = sim.notices().len();
        if !self.quiet && self.last.elapsed().as_secs_f64() >= 1.0 {
            self.last = Instant::now();
            let end = sim.model().time.end;
            let elapsed = self.started.elapsed().as_secs_f64();
            let fraction = report.time / end;
            let eta = if fraction > 0.0 {
                elapsed * (1.0 - fraction) / fraction
            } else {
                0.0
            };
            eprintln!(
                "  t = {:.4} / {end} s ({:.0}%), T = {:.1} °C, step {}, {} Newton iterations, elapsed {elapsed:.0} s, ETA {eta:.0} s",
                report.time,
                100.0 * fraction,
                report.temperature,
                report.step,
                report.newton.iterations
            );
        }
        ControlFlow::Continue(())
    }

    fn step_failed(&mut self, time: Real, dt: Real, newton: &NewtonReport) {
        if self.verbose {
            eprintln!(
                "  step to t = {time} (dt = {dt:.3e}) failed after {} iterations; normalised residuals {:?}; increments {:?}",
                newton.iterations, newton.residuals, newton.increments
            );
        }
    }
}

/// Forwards every report to several observers; stops when any asks to.
struct Tee<'a>(Vec<&'a mut dyn Observer>);

impl Observer for Tee<'_> {
    fn start(&mut self, sim: &Simulation<'_>) -> ControlFlow<()> {
        let mut flow = ControlFlow::Continue(());
        for o in &mut self.0 {
            if o.start(sim).is_break() {
                flow = ControlFlow::Break(());
            }
        }
        flow
    }

    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        let mut flow = ControlFlow::Continue(());
        for o in &mut self.0 {
            if o.step(sim, report).is_break() {
                flow = ControlFlow::Break(());
            }
        }
        flow
    }

    fn step_failed(&mut self, time: Real, dt: Real, newton: &NewtonReport) {
        for o in &mut self.0 {
            o.step_failed(time, dt, newton);
        }
    }
}

/// The run folder for a design: `-o DIR` or `runs/<design name>`.
fn run_dir(output: Option<PathBuf>, name: &str) -> PathBuf {
    output.unwrap_or_else(|| Path::new("runs").join(name))
}

/// Simulates the design and writes the run folder.
pub fn run(
    design: &Path,
    output: Option<PathBuf>,
    force: bool,
    quiet: bool,
    verbose: bool,
) -> anyhow::Result<()> {
    let started = Instant::now();
    let design = load_design(design)?;
    let model = &design.model;
    for w in &design.warnings {
        eprintln!("warning: {w}");
    }
    let dir = run_dir(output, &model.name);
    if dir.exists()
        && std::fs::read_dir(&dir)
            .map(|mut d| d.next().is_some())
            .unwrap_or(true)
        && !force
    {
        bail!(
            "{} exists and is not empty; pass --force to overwrite it",
            dir.display()
        );
    }
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut sim = Simulation::new(model)?;
    if !quiet {
        eprintln!(
            "stentkit run: {} — {} patches, {} unknowns, {} steps of {} s to {} s → {}",
            model.name,
            model.patches.len(),
            model.num_unknowns(),
            model.num_time_steps(),
            model.time.step,
            model.time.end,
            dir.display()
        );
    }
    let history_path = dir.join("history.csv");
    let mut history = HistoryWriter::create(&history_path, &sim)
        .with_context(|| format!("cannot write {}", history_path.display()))?;
    let mut progress = Progress {
        started,
        last: Instant::now(),
        quiet,
        said: 0,
        verbose,
    };
    let result = sim.run(&mut Tee(vec![&mut history, &mut progress]));
    if let Some(e) = history.take_error() {
        return Err(e).with_context(|| format!("writing {}", history_path.display()));
    }
    let summary = result.with_context(|| {
        format!(
            "the run stopped at t = {} s; results up to there are in {}",
            sim.time(),
            dir.display()
        )
    })?;
    let wall = started.elapsed().as_secs_f64();
    println!(
        "{}: {} steps to t = {} s, {} Newton iterations ({:.2} per step), {} factorisations, {} step cuts, wall time {wall:.2} s → {}",
        model.name,
        summary.steps,
        summary.time,
        summary.iterations,
        summary.iterations as f64 / summary.steps.max(1) as f64,
        summary.factorisations,
        summary.cuts,
        dir.display()
    );
    Ok(())
}
