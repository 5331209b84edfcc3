//! `stentkit run`: simulate a design and write the run folder (DESIGN §7):
//!
//! ```text
//! DIR/history.csv             one row per step (io::history)
//! DIR/summary.json            what the run was and did (io::summary)
//! DIR/snapshots/step_NNNNN.{stl,obj}   the full device at the snapshot steps (io::snapshots)
//! DIR/run.mcap                the recording for Foxglove (io::mcap)
//! DIR/charts/*.svg            histories (io::run_charts)
//! ```
//!
//! The outputs are observers of the simulation, composed here with a progress bar (indicatif, on stderr,
//! hidden when stderr is not a terminal or with `--quiet`). Every file is finished whether the run completes,
//! fails, is interrupted (Ctrl-C stops it after the current step; a second Ctrl-C quits at once) or is
//! stopped by an output error: the MCAP recording is closed, the last state gets a snapshot and the summary
//! says where the run stopped.

use crate::io::design::{Design, load_design};
use crate::io::history::HistoryWriter;
use crate::io::mcap::{McapRecorder, RunInfo};
use crate::io::run_charts::RunCharts;
use crate::io::snapshots::SnapshotWriter;
use crate::io::summary::{
    FailureReport, Files, FinalState, RunStatus, RunSummaryFile, Timing, UnitsSummary,
    peak_memory_mib,
};
use crate::math::Real;
use crate::solver::{NewtonReport, Observer, Simulation, StepReport};
use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Set by the Ctrl-C handler: the run stops after the current step.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Installs the Ctrl-C handler: the first Ctrl-C asks the run to stop after the current step, a second one
/// quits at once (exit status 130) without finishing the files.
fn install_interrupt_handler() {
    // Only fails if a handler is already installed (a second run in the same process): keep that one.
    let _ = ctrlc::set_handler(|| {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    });
}

/// Stops the run once Ctrl-C was pressed.
struct Interrupt;

impl Observer for Interrupt {
    fn start(&mut self, _: &Simulation<'_>) -> ControlFlow<()> {
        self.check()
    }

    fn step(&mut self, _: &Simulation<'_>, _: &StepReport) -> ControlFlow<()> {
        self.check()
    }
}

impl Interrupt {
    fn check(&self) -> ControlFlow<()> {
        if INTERRUPTED.load(Ordering::SeqCst) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// Positions of the progress bar over the run (simulated time is mapped onto them).
const PROGRESS_RESOLUTION: u64 = 10_000;

/// Progress bar with ETA, simulated time, temperature and Newton iterations; prints the solver's notices.
struct Progress {
    bar: ProgressBar,
    end: Real,
    /// Notices already printed.
    said: usize,
    /// Print every failed Newton attempt.
    verbose: bool,
}

impl Progress {
    fn new(end: Real, quiet: bool, verbose: bool) -> Self {
        let bar = if quiet {
            ProgressBar::hidden()
        } else {
            // Hidden by indicatif itself when stderr is not a terminal.
            ProgressBar::with_draw_target(Some(PROGRESS_RESOLUTION), ProgressDrawTarget::stderr())
        };
        bar.set_style(
            ProgressStyle::with_template(
                "{elapsed_precise} [{bar:30}] {percent:>3}% ETA {eta:>4}  {msg}",
            )
            .expect("valid progress template")
            .progress_chars("=> "),
        );
        Self {
            bar,
            end,
            said: 0,
            verbose,
        }
    }

    fn notices(&mut self, sim: &Simulation<'_>) {
        for notice in &sim.notices()[self.said..] {
            self.bar.suspend(|| eprintln!("note: {notice}"));
        }
        self.said = sim.notices().len();
    }
}

impl Observer for Progress {
    fn start(&mut self, sim: &Simulation<'_>) -> ControlFlow<()> {
        self.notices(sim);
        ControlFlow::Continue(())
    }

    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        self.notices(sim);
        let fraction = if self.end > 0.0 {
            (report.time / self.end).clamp(0.0, 1.0)
        } else {
            1.0
        };
        self.bar
            .set_position((fraction * PROGRESS_RESOLUTION as Real).round() as u64);
        self.bar.set_message(format!(
            "t = {:.4}/{} s  T = {:.1} °C  step {}  {} it",
            report.time, self.end, report.temperature, report.step, report.newton.iterations
        ));
        ControlFlow::Continue(())
    }

    fn step_failed(&mut self, time: Real, dt: Real, newton: &NewtonReport) {
        if self.verbose {
            self.bar.suspend(|| {
                eprintln!(
                    "  step to t = {time} (dt = {dt:.3e}) failed after {} iterations; normalised residuals {:?}; increments {:?}",
                    newton.iterations, newton.residuals, newton.increments
                );
            });
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

/// An observer and the wall time spent in it.
struct Timed<'a, O: Observer> {
    inner: &'a mut O,
    spent: Duration,
}

impl<'a, O: Observer> Timed<'a, O> {
    fn new(inner: &'a mut O) -> Self {
        Self {
            inner,
            spent: Duration::ZERO,
        }
    }
}

impl<O: Observer> Observer for Timed<'_, O> {
    fn start(&mut self, sim: &Simulation<'_>) -> ControlFlow<()> {
        let t = Instant::now();
        let flow = self.inner.start(sim);
        self.spent += t.elapsed();
        flow
    }

    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        let t = Instant::now();
        let flow = self.inner.step(sim, report);
        self.spent += t.elapsed();
        flow
    }

    fn step_failed(&mut self, time: Real, dt: Real, newton: &NewtonReport) {
        self.inner.step_failed(time, dt, newton);
    }
}

/// The run folder for a design: `-o DIR` or `runs/<design name>`.
fn run_dir(output: Option<PathBuf>, name: &str) -> PathBuf {
    output.unwrap_or_else(|| Path::new("runs").join(name))
}

/// Files and folders a run writes, relative to the run folder (removed first under `--force`).
const OUTPUTS: [&str; 5] = [
    "history.csv",
    "summary.json",
    "run.mcap",
    SnapshotWriter::FOLDER,
    RunCharts::FOLDER,
];

/// Makes `dir` ready for a run: refuses a non-empty folder without `force`; with it, removes the outputs of
/// an earlier run (and nothing else).
fn prepare_dir(dir: &Path, force: bool) -> anyhow::Result<()> {
    let non_empty = dir.exists()
        && std::fs::read_dir(dir)
            .map(|mut d| d.next().is_some())
            .unwrap_or(true);
    if non_empty {
        if !force {
            bail!(
                "{} exists and is not empty; pass --force to overwrite it",
                dir.display()
            );
        }
        for name in OUTPUTS {
            let path = dir.join(name);
            let removed = if path.is_dir() {
                std::fs::remove_dir_all(&path)
            } else if path.exists() {
                std::fs::remove_file(&path)
            } else {
                Ok(())
            };
            removed.with_context(|| format!("cannot remove {}", path.display()))?;
        }
    }
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))
}

/// The command line as typed, arguments with spaces quoted.
fn command_line() -> String {
    std::env::args()
        .map(|a| {
            if a.is_empty() || a.contains(char::is_whitespace) {
                format!("'{a}'")
            } else {
                a
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// What `run` was asked to do.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOptions {
    /// Run folder (default `runs/<design name>`).
    pub output: Option<PathBuf>,
    /// Overwrite a non-empty run folder.
    pub force: bool,
    /// No progress bar and no start line.
    pub quiet: bool,
    /// Report every failed Newton attempt.
    pub verbose: bool,
}

/// Simulates the design and writes the run folder.
pub fn run(design_path: &Path, options: RunOptions) -> anyhow::Result<()> {
    let started = Instant::now();
    let design = load_design(design_path)?;
    for w in &design.warnings {
        eprintln!("warning: {w}");
    }
    let dir = run_dir(options.output.clone(), &design.model.name);
    prepare_dir(&dir, options.force)?;
    run_in(&design, &dir, &options, started)
}

fn run_in(
    design: &Design,
    dir: &Path,
    options: &RunOptions,
    started: Instant,
) -> anyhow::Result<()> {
    let model = &design.model;
    let mut sim = Simulation::new(model)?;
    if !options.quiet {
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
    let info = RunInfo {
        version: env!("CARGO_PKG_VERSION").to_string(),
        command_line: command_line(),
    };
    let history_path = dir.join("history.csv");
    let mut history = HistoryWriter::create(&history_path, &sim)
        .with_context(|| format!("cannot write {}", history_path.display()))?;
    let mut snapshots = SnapshotWriter::create(dir, &design.output.snapshots, model)?;
    let mcap_path = dir.join("run.mcap");
    let mut recorder = McapRecorder::create(&mcap_path, design, &info, &design.output.snapshots)?;
    let mut charts = RunCharts::new(model);
    let mut progress = Progress::new(model.time.end, options.quiet, options.verbose);
    install_interrupt_handler();
    let setup = started.elapsed();

    let run_started = Instant::now();
    let mut recording = BTreeMap::new();
    let result = {
        let mut history = Timed::new(&mut history);
        let mut snapshots = Timed::new(&mut snapshots);
        let mut recorder = Timed::new(&mut recorder);
        let mut charts = Timed::new(&mut charts);
        let result = sim.run(&mut Tee(vec![
            &mut history,
            &mut snapshots,
            &mut recorder,
            &mut charts,
            &mut progress,
            &mut Interrupt,
        ]));
        for (name, spent) in [
            ("history", history.spent),
            ("snapshots", snapshots.spent),
            ("mcap", recorder.spent),
            ("charts", charts.spent),
        ] {
            recording.insert(name.to_string(), spent.as_secs_f64());
        }
        result
    };
    let run_time = run_started.elapsed();
    progress.bar.finish_and_clear();
    progress.notices(&sim);

    // Finish every output, whatever happened; report the first problem afterwards.
    let finish_started = Instant::now();
    let mut problems: Vec<anyhow::Error> = Vec::new();
    if let Some(e) = history.take_error() {
        problems.push(anyhow::Error::new(e).context(format!("writing {}", history_path.display())));
    }
    if let Some(e) = snapshots.take_error() {
        problems.push(e.into());
    }
    if let Err(e) = snapshots.finish(&sim) {
        problems.push(e.into());
    }
    if let Some(e) = recorder.take_error() {
        problems.push(e.into());
    }
    let mcap_bytes = match recorder.finish(&sim) {
        Ok(bytes) => bytes,
        Err(e) => {
            problems.push(e.into());
            0
        }
    };
    let chart_files = match charts.write(model, dir) {
        Ok(files) => files,
        Err(e) => {
            problems.push(e.into());
            Vec::new()
        }
    };
    let finish = finish_started.elapsed();

    let interrupted = INTERRUPTED.load(Ordering::SeqCst);
    let (status, error) = match (&result, problems.first()) {
        (Err(e), _) => (RunStatus::Failed, Some(format!("{e}"))),
        (Ok(s), None) if s.stopped && interrupted => (
            RunStatus::Interrupted,
            Some(format!(
                "interrupted (Ctrl-C) at t = {} s",
                short_time(sim.time())
            )),
        ),
        (Ok(s), Some(p)) if s.stopped => (RunStatus::Stopped, Some(format!("{p:#}"))),
        (Ok(_), Some(p)) => (RunStatus::Completed, Some(format!("{p:#}"))),
        (Ok(_), None) => (RunStatus::Completed, None),
    };
    let totals = result.as_ref().ok().cloned().unwrap_or_else(|| {
        // The solver failed: count what the observers saw.
        let samples = charts.samples();
        crate::solver::RunSummary {
            steps: samples.last().map_or(0, |s| s.step),
            iterations: samples.iter().map(|s| s.iterations).sum(),
            cuts: samples.iter().map(|s| s.cuts).sum(),
            time: sim.time(),
            stopped: true,
            ..Default::default()
        }
    });
    let wall = started.elapsed().as_secs_f64();
    let summary = RunSummaryFile {
        design: model.name.clone(),
        design_file: design.path.display().to_string(),
        stentkit_version: info.version.clone(),
        command_line: info.command_line.clone(),
        units: UnitsSummary::of(model),
        status,
        error,
        failure: result
            .as_ref()
            .err()
            .map(|e| FailureReport::of(e, totals.steps, sim.time())),
        wall_time_s: wall,
        peak_memory_mib: peak_memory_mib(),
        timing: Timing {
            setup_s: setup.as_secs_f64(),
            run_s: run_time.as_secs_f64(),
            recording,
            finish_s: finish.as_secs_f64(),
            solver: sim.timing().entries().into_iter().collect(),
        },
        steps: totals.steps,
        newton_iterations: totals.iterations,
        iterations_per_step: totals.iterations as Real / totals.steps.max(1) as Real,
        step_cuts: totals.cuts,
        final_time: sim.time(),
        end_time: model.time.end,
        time_step: model.time.step,
        patches: model.patches.len(),
        collocation_points: model.num_collocation_points(),
        unknowns: model.num_unknowns(),
        symmetry_planes: model.symmetry_planes.len(),
        snapshots: snapshots.snapshots().iter().map(Into::into).collect(),
        files: Files {
            history: "history.csv".into(),
            mcap: "run.mcap".into(),
            mcap_bytes,
            charts: chart_files
                .iter()
                .map(|p| p.display().to_string())
                .collect(),
        },
        final_state: charts.samples().last().map(|s| FinalState::of(model, s)),
        warnings: design.warnings.clone(),
        notices: sim.notices().to_vec(),
    };
    if let Some(failure) = &summary.failure {
        eprintln!("{}", failure_report(failure, &summary));
    }
    let summary_path = dir.join("summary.json");
    summary
        .write(&summary_path)
        .with_context(|| format!("cannot write {}", summary_path.display()))?;

    let totals = result.with_context(|| {
        format!(
            "the run stopped at t = {} s; results up to there are in {}",
            short_time(sim.time()),
            dir.display()
        )
    })?;
    if totals.stopped && interrupted {
        bail!(
            "interrupted at t = {} s after {} steps; results up to there are in {}",
            short_time(sim.time()),
            totals.steps,
            dir.display()
        );
    }
    if let Some(problem) = problems.into_iter().next() {
        return Err(problem.context(format!(
            "the run stopped at t = {} s; results up to there are in {}",
            short_time(sim.time()),
            dir.display()
        )));
    }
    println!(
        "{}: {} steps to t = {} s, {} Newton iterations ({:.2} per step), {} factorisations, {} step cuts, {} snapshots, run.mcap {}, wall time {wall:.2} s, peak memory {} → {}",
        model.name,
        totals.steps,
        totals.time,
        totals.iterations,
        totals.iterations as f64 / totals.steps.max(1) as f64,
        totals.factorisations,
        totals.cuts,
        summary.snapshots.len(),
        human_bytes(mcap_bytes),
        summary
            .peak_memory_mib
            .map_or("unknown".to_string(), |m| format!("{m:.0} MiB")),
        dir.display()
    );
    Ok(())
}

/// The failure report printed by a failed run (the same facts are in summary.json under `failure`).
fn failure_report(failure: &FailureReport, summary: &RunSummaryFile) -> String {
    let mut lines = vec!["failure report:".to_string()];
    match (failure.step, failure.time, failure.dt, failure.iterations) {
        (Some(step), Some(time), Some(dt), Some(iterations)) => {
            lines.push(format!(
                "  step {step} to t = {} s failed at the smallest step, dt = {dt:.3e} s",
                short_time(time)
            ));
            let residuals: Vec<String> = failure
                .residuals
                .iter()
                .map(|r| format!("{r:.3e}"))
                .collect();
            lines.push(format!(
                "  Newton: {iterations} iterations, normalised residuals [{}]",
                residuals.join(", ")
            ));
        }
        _ => lines.push(format!("  {} ({})", failure.message, failure.kind)),
    }
    if let Some(w) = &failure.diagnosis {
        lines.push(format!("  diagnosis: {w}"));
    }
    let snapshot = summary
        .snapshots
        .last()
        .filter(|s| s.step == failure.last_converged_step)
        .map(|s| format!(", snapshot {}", s.stl))
        .unwrap_or_default();
    lines.push(format!(
        "  last converged: step {}, t = {} s (history.csv and run.mcap end there{snapshot})",
        failure.last_converged_step,
        short_time(failure.last_converged_time)
    ));
    lines.join("\n")
}

/// A time for messages: at most 9 decimals, trailing zeros dropped (`0.1`, not `0.10000000000000005`).
fn short_time(t: Real) -> String {
    let s = format!("{t:.9}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// `1.2 MB`-style size.
fn human_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.2} GB", b / 1e9)
    } else if b >= 1e6 {
        format!("{:.1} MB", b / 1e6)
    } else if b >= 1e3 {
        format!("{:.0} kB", b / 1e3)
    } else {
        format!("{bytes} B")
    }
}
