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
//! The folder is taken through [`crate::io::run_folder`] (refusals, lock, manifest, `--force`). The outputs
//! are observers of the simulation, composed here with a progress bar (indicatif, on stderr, hidden when
//! stderr is not a terminal or with `--quiet`). `summary.json` exists from the start (`"status": "running"`)
//! and is rewritten every `HEARTBEAT` (2 s) with the last converged step, when the recording's chunk is also
//! closed, so that SIGKILL leaves a folder `stentkit repair` makes whole. Every file is finished whether the
//! run completes, fails, is interrupted by a signal ([`super::signals`]: the step in progress is abandoned at
//! its next Newton iteration) or is stopped by an output error (a full disk: the history is cut back to its
//! last complete row, the recording salvaged up to its last complete chunk, and the error lists which files
//! are complete): the last state gets a snapshot and the summary says where the run stopped.
//!
//! **Checkpoints and `--resume`.** Every `--checkpoint-every` seconds of wall time (default 60), right after a
//! heartbeat (so the recording's chunks hold every state up to it), and when a signal stops the run, the run
//! writes `checkpoint.bin` ([`crate::io::checkpoint`]: the simulation's [`crate::solver::Checkpoint`] and where
//! each output stood), atomically, listed in the manifest; a completed run removes it. `run DESIGN --resume
//! DIR` takes the folder of a killed or interrupted run ([`run_folder::check_resume`]), refuses another
//! design (model and output fingerprints), a run that completed or failed, a folder without a checkpoint and a
//! history shorter than the checkpoint's or missing (exit status 2; a refusal changes nothing, the summary
//! included, so the run can still be resumed once the cause is put right), restores the simulation and continues every output from the checkpoint: `history.csv` is
//! cut back to the checkpoint's row and continued; the snapshots after it are removed and written again as
//! their steps come; the recording (salvaged first if the run was killed) is copied up to the checkpoint's
//! last message into a new file built beside it, which then replaces it, and continues; the charts and the
//! summary's counts go on from the checkpoint's. The result is the uninterrupted run's: the same history.csv
//! byte for byte.

use super::signals;
use super::{BadInput, Interrupted, error_text, short_time};
use crate::io::checkpoint::{self, OutputsCheckpoint, RunCheckpoint};
use crate::io::design::size::human_bytes;
use crate::io::design::{Design, DesignOverrides, load_design_with};
use crate::io::history::HistoryWriter;
use crate::io::mcap::{McapRecorder, RunInfo};
use crate::io::mcap_salvage::{Salvage, salvage};
use crate::io::run_charts::RunCharts;
use crate::io::run_folder::{self, Manifest, RunFolder, RunFolderError};
use crate::io::snapshots::SnapshotWriter;
use crate::io::summary::{
    FailureReport, FinalState, OutputState, RunStatus, RunSummaryFile, peak_memory_mib,
};
use crate::math::{Real, Short};
use crate::solver::simulation::model_fingerprint;
use crate::solver::{NewtonReport, Observer, Simulation, SolverError, StepReport};
use anyhow::Context;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How often a run rewrites `summary.json` with its last converged step and closes the recording's current
/// chunk: what SIGKILL or a power loss can take is at most this much of the run (plus the step in progress).
/// Each chunk boundary costs a little compression; every 2 s is far below a percent of the recording.
const HEARTBEAT: Duration = Duration::from_secs(2);

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
    /// Step cuts so far (attempts retried shorter).
    cuts: usize,
    /// Failed Newton attempts so far (retried with a fresh tangent, damped, or shorter).
    failed: usize,
    /// The message of the last converged step, which a failed attempt's note is appended to.
    last: String,
    /// The model's cycle, for the phase of each step.
    phases: crate::model::cycle::Phases,
}

/// How often the progress bar is redrawn when nothing is reported (a step being cut): its elapsed time keeps
/// moving.
const PROGRESS_TICK: Duration = Duration::from_millis(250);

impl Progress {
    fn new(model: &crate::model::Model, quiet: bool, verbose: bool) -> Self {
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
        if !quiet {
            bar.enable_steady_tick(PROGRESS_TICK);
        }
        Self {
            bar,
            end: model.time.end,
            said: 0,
            verbose,
            cuts: 0,
            failed: 0,
            last: String::new(),
            phases: model.phases(),
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
        // The phase of the shape-memory cycle, when the model has one.
        let phase = self
            .phases
            .at(report.time)
            .map(|p| format!("{p}  "))
            .unwrap_or_default();
        self.cuts += report.cuts;
        let cuts = match self.cuts {
            0 => String::new(),
            n => format!("  {n} cut{}", if n == 1 { "" } else { "s" }),
        };
        self.last = format!(
            "{phase}t = {:.4}/{} s  T = {:.1} °C  step {}  {} it{cuts}",
            report.time, self.end, report.temperature, report.step, report.newton.iterations
        );
        self.bar.set_message(self.last.clone());
        ControlFlow::Continue(())
    }

    fn step_failed(&mut self, time: Real, dt: Real, newton: &NewtonReport) {
        self.failed += 1;
        self.bar.set_message(format!(
            "{}  retrying: the attempt to reach t = {time:.6} (dt = {dt:.2e}) failed ({} failed attempts)",
            self.last, self.failed
        ));
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

/// The outputs of a run, observing the simulation: history, snapshots, recording, charts, the progress bar,
/// and the running summary with the recording's chunk flushes every [`HEARTBEAT`].
struct Outputs {
    history: HistoryWriter,
    snapshots: SnapshotWriter,
    /// The recording, unless the design turns it off (`output.recording.enabled`).
    recorder: Option<McapRecorder>,
    charts: RunCharts,
    progress: Progress,
    /// Wall time spent in each output during the run, as named in [`Outputs::RECORDING`].
    spent: [Duration; 4],
    /// When the running summary was last written.
    beat: Instant,
    /// What the run did so far.
    totals: crate::solver::RunSummary,
    /// Materials' strain limits exceeded, as said.
    strain_warnings: Vec<String>,
    /// The design's warnings (the first of summary.json's `warnings`).
    design_warnings: Vec<String>,
}

impl Outputs {
    /// Names of the outputs timed in `spent` (summary.json `timing.recording`).
    const RECORDING: [&'static str; 4] = ["history", "snapshots", "mcap", "charts"];

    /// Calls every output (all of them, even after one asked to stop) with the time spent in each.
    fn observe(
        &mut self,
        mut call: impl FnMut(&mut dyn Observer) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let mut flow = ControlFlow::Continue(());
        let outputs: [&mut dyn Observer; 4] = [
            &mut self.history,
            &mut self.snapshots,
            &mut self.recorder,
            &mut self.charts,
        ];
        for (output, spent) in outputs.into_iter().zip(&mut self.spent) {
            let t = Instant::now();
            if call(output).is_break() {
                flow = ControlFlow::Break(());
            }
            *spent += t.elapsed();
        }
        if call(&mut self.progress).is_break() || signals::stop_requested() {
            flow = ControlFlow::Break(());
        }
        for warning in self.history.take_warnings() {
            self.progress
                .bar
                .suspend(|| eprintln!("warning: {warning}"));
            self.strain_warnings.push(warning);
        }
        flow
    }

    /// Where every output stands, for a checkpoint; `wall_time_s` is the run's wall time so far.
    fn checkpoint(&self, settings: u64, wall_time_s: Real) -> OutputsCheckpoint {
        OutputsCheckpoint {
            settings,
            history: self.history.position(),
            snapshots: self.snapshots.snapshots().to_vec(),
            snapshots_last: self.snapshots.last_seen(),
            recording: self
                .recorder
                .as_ref()
                .map(McapRecorder::position)
                .unwrap_or_default(),
            samples: self.charts.samples().to_vec(),
            totals: self.totals.clone(),
            spent: self.spent.map(|d| d.as_secs_f64()),
            wall_time_s,
        }
    }

    /// Puts what the run did so far into `s`: counts, the time reached, snapshots, the last state, notices and
    /// the solver's time split.
    fn fill(&self, s: &mut RunSummaryFile, sim: &Simulation<'_>) {
        let t = &self.totals;
        s.steps = t.steps;
        s.newton_iterations = t.iterations;
        s.iterations_per_step = t.iterations as Real / t.steps.max(1) as Real;
        s.step_cuts = t.cuts;
        if let Some(control) = &mut s.time_error_control {
            let steps = || self.charts.samples().iter().skip(1);
            control.accepted_steps = t.steps;
            control.rejected_steps = t.rejected;
            control.largest_estimate = steps()
                .filter_map(|x| x.error_estimate)
                .fold(0.0, Real::max);
            control.smallest_step = steps().map(|x| x.dt).fold(Real::INFINITY, Real::min);
            control.largest_step = steps().map(|x| x.dt).fold(0.0, Real::max);
            if t.steps == 0 {
                control.smallest_step = 0.0;
            }
        }
        if let (Some(summary), Some(settings)) =
            (&mut s.stabilisation, &sim.model().solver.stabilisation)
        {
            let st = sim.stabilisation();
            summary.damped_steps = st.damped_steps;
            summary.dissipated_energy = st.dissipated;
            summary.peak_strain_energy = st.peak_strain_energy;
            summary.ratio = st.ratio();
            summary.largest_step_ratio = st.largest_step_ratio;
            summary.largest_force_share = st.largest_force_share;
            summary.largest_force_share_time = st.largest_force_share_time;
            summary.steps_above_force_limit = st.steps_above_force_limit;
            summary.above_limit = st.above_limit(settings);
        }
        s.warnings.clone_from(&self.design_warnings);
        s.warnings.extend(sim.stabilisation_warnings());
        s.final_time = sim.time();
        s.snapshots = self.snapshots.snapshots().iter().map(Into::into).collect();
        s.final_state = self
            .charts
            .samples()
            .last()
            .map(|x| FinalState::of(sim.model(), x));
        s.notices = sim.notices().to_vec();
        s.peak_surface_strain = self.history.peak_surface_strain().cloned();
        s.strain_limit_warnings.clone_from(&self.strain_warnings);
        s.timing.solver = sim.timing().entries().into_iter().collect();
        s.timing.recording = Self::RECORDING
            .iter()
            .zip(&self.spent)
            .map(|(name, d)| (name.to_string(), d.as_secs_f64()))
            .collect();
    }
}

/// The observer of a run: the outputs, the running summary every [`HEARTBEAT`] and the checkpoints.
struct RunObserver<'a> {
    outputs: &'a mut Outputs,
    summary: &'a mut SummaryFile,
    checkpoints: &'a mut Checkpoints,
}

/// Writes the run's checkpoints (module docs).
struct Checkpoints {
    /// `DIR/checkpoint.bin`.
    path: PathBuf,
    /// Wall time between checkpoints.
    every: Duration,
    /// When the last was written (or the run started).
    last: Instant,
    /// Fingerprint of the design's output settings.
    settings: u64,
    /// Whether `checkpoint.bin` is listed in the manifest yet.
    claimed: bool,
    /// Checkpoints are no longer written (one could not be: said once).
    disabled: bool,
}

impl Checkpoints {
    /// Whether a checkpoint is due.
    fn due(&self) -> bool {
        !self.disabled && self.last.elapsed() >= self.every
    }

    /// Writes the checkpoint of `sim` and `outputs` now: listed in `manifest` first, written atomically. A
    /// failure is said once and ends the checkpoints, not the run.
    fn write(
        &mut self,
        sim: &Simulation<'_>,
        outputs: &Outputs,
        wall_time_s: Real,
        manifest: &Manifest,
    ) {
        self.last = Instant::now();
        let written = (|| -> std::io::Result<()> {
            if !self.claimed {
                manifest.claim(Path::new(checkpoint::FILE_NAME))?;
                self.claimed = true;
            }
            let file = RunCheckpoint {
                solver: sim.checkpoint(),
                outputs: outputs.checkpoint(self.settings, wall_time_s),
            };
            checkpoint::write(&self.path, &file)
        })();
        if let Err(e) = written {
            self.disabled = true;
            outputs.progress.bar.suspend(|| {
                eprintln!(
                    "warning: cannot write the checkpoint {}: {e}; the run goes on without checkpoints",
                    self.path.display()
                )
            });
        }
    }
}

impl RunObserver<'_> {
    /// Every [`HEARTBEAT`] (or now, with `now`): closes the recording's chunk and rewrites the running summary.
    fn heartbeat(&mut self, sim: &Simulation<'_>, now: bool) -> ControlFlow<()> {
        if !now && self.outputs.beat.elapsed() < HEARTBEAT {
            return ControlFlow::Continue(());
        }
        self.outputs.beat = Instant::now();
        if let Some(Err(e)) = self
            .outputs
            .recorder
            .as_mut()
            .map(McapRecorder::flush_chunk)
        {
            self.summary.problem = Some(anyhow::Error::new(e));
            return ControlFlow::Break(());
        }
        let outputs = &*self.outputs;
        if let Err(e) = self.summary.write(|s| outputs.fill(s, sim)) {
            self.summary.problem = Some(e);
            return ControlFlow::Break(());
        }
        ControlFlow::Continue(())
    }
}

impl Observer for RunObserver<'_> {
    fn start(&mut self, sim: &Simulation<'_>) -> ControlFlow<()> {
        let flow = self.outputs.observe(|o| o.start(sim));
        if self.heartbeat(sim, true).is_break() {
            return ControlFlow::Break(());
        }
        flow
    }

    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        let totals = &mut self.outputs.totals;
        totals.steps = report.step;
        totals.iterations += report.newton.iterations;
        totals.factorisations += report.newton.factorisations;
        totals.cuts += report.cuts;
        totals.time = report.time;
        let flow = self.outputs.observe(|o| o.step(sim, report));
        // A checkpoint follows a heartbeat: the recording's closed chunks then hold every state up to it.
        let checkpoint = flow.is_continue() && self.checkpoints.due();
        if self.heartbeat(sim, checkpoint).is_break() {
            return ControlFlow::Break(());
        }
        if checkpoint {
            let wall = self.summary.wall_time_s();
            let manifest = self.summary.manifest.clone();
            self.checkpoints.write(sim, self.outputs, wall, &manifest);
        }
        flow
    }

    fn step_failed(&mut self, time: Real, dt: Real, newton: &NewtonReport) {
        self.outputs.progress.step_failed(time, dt, newton);
    }

    fn interrupted(&self) -> bool {
        signals::stop_requested()
    }
}

/// `summary.json` of a run: the summary so far, rewritten atomically whenever it changes.
struct SummaryFile {
    path: PathBuf,
    summary: RunSummaryFile,
    /// The command's start.
    started: Instant,
    /// Wall time of the run before this command (a resumed run's, up to its checkpoint) \[s\].
    earlier_wall_s: Real,
    /// The run folder's manifest (for the checkpoints).
    manifest: Manifest,
    /// The first problem met while the run went on (writing the summary or closing a chunk).
    problem: Option<anyhow::Error>,
}

impl SummaryFile {
    /// The run's wall time so far, over every command that ran it \[s\].
    fn wall_time_s(&self) -> Real {
        self.earlier_wall_s + self.started.elapsed().as_secs_f64()
    }

    /// Updates the summary with `update` (and the time, wall time and peak memory) and writes it.
    fn write(&mut self, update: impl FnOnce(&mut RunSummaryFile)) -> anyhow::Result<()> {
        update(&mut self.summary);
        self.summary.updated = crate::io::run_folder::utc_timestamp(std::time::SystemTime::now());
        self.summary.wall_time_s = self.wall_time_s();
        self.summary.peak_memory_mib = peak_memory_mib();
        self.summary
            .write(&self.path)
            .with_context(|| format!("cannot write {}", self.path.display()))
    }
}

/// The run folder for a design: `-o DIR` or `runs/<design name>`.
fn run_dir(output: Option<PathBuf>, name: &str) -> PathBuf {
    output.unwrap_or_else(|| Path::new("runs").join(name))
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
    /// Replace an earlier run in the run folder (only the files it wrote are removed).
    pub force: bool,
    /// No progress bar and no start line.
    pub quiet: bool,
    /// Report every failed Newton attempt.
    pub verbose: bool,
    /// Continue the run in this folder from its checkpoint instead of starting one.
    pub resume: Option<PathBuf>,
    /// Wall time between checkpoints \[s\] (0: after every step; finite and ≥ 0, as `--checkpoint-every` is
    /// checked).
    pub checkpoint_every: Real,
    /// Error-controlled stepping at this time-error tolerance, replacing the design's (`--tol`).
    pub time_tolerance: Option<Real>,
    /// `--set PATH=VALUE` overrides of the design's fields.
    pub sets: Vec<crate::io::design::SetOverride>,
}

/// Simulates the design and writes the run folder.
///
/// # Errors
/// A [`BadInput`] or [`crate::io::design::DesignError`] for a design or folder refused before anything ran
/// (exit status 2), [`Interrupted`] for a run stopped by a signal (130), anything else for a failed run (1).
pub fn run(design_path: &Path, options: RunOptions) -> anyhow::Result<()> {
    let started = Instant::now();
    signals::install();
    // `--tol` and `--checkpoint-every` were checked with the arguments (`super::arguments`).
    let overrides = DesignOverrides {
        time_tolerance: options.time_tolerance,
        sets: options.sets.clone(),
        ..DesignOverrides::default()
    };
    let design = load_design_with(design_path, &overrides)?;
    for w in &design.warnings {
        eprintln!("warning: {w}");
    }
    if signals::stop_requested() {
        return Err(Interrupted(format!(
            "{} while reading the design: nothing was written",
            signals::first().unwrap_or("signal")
        ))
        .into());
    }
    if let Some(dir) = &options.resume {
        return resume(&design, dir, &options, started);
    }
    let dir = run_dir(options.output.clone(), &design.model.name);
    // Nothing is written before the folder and the disk are found fit for the run.
    let fit = run_folder::check(&dir, design_path, options.force).map_err(refused)?;
    super::disk::check_space(&design, &fit)?;
    let mut folder = fit.open()?;
    folder.clear_previous()?;
    run_in(&design, &folder, &options, started, None)
}

/// A folder refused for the run is bad input (exit status 2).
fn refused(e: RunFolderError) -> anyhow::Error {
    match e {
        RunFolderError::Refused { .. } => anyhow::Error::new(BadInput(e.to_string())),
        e => e.into(),
    }
}

/// `run DESIGN --resume DIR`: checks that `dir` holds a killed or interrupted run of this design with a
/// checkpoint, then continues it (module docs).
fn resume(
    design: &Design,
    dir: &Path,
    options: &RunOptions,
    started: Instant,
) -> anyhow::Result<()> {
    // The summary's word first: a completed run has no checkpoint left, and that is why.
    match previous_status(dir).as_deref() {
        Some("completed") => {
            return Err(BadInput(format!(
                "{}: the run there completed (summary.json says `completed`): there is nothing to resume",
                dir.display()
            ))
            .into());
        }
        Some("failed") => {
            return Err(BadInput(format!(
                "{}: the run there failed (summary.json says `failed`, with the reason); resuming would fail \
                 the same way: change the design and run it again with --force",
                dir.display()
            ))
            .into());
        }
        _ => {}
    }
    let fit = run_folder::check_resume(dir, Path::new(checkpoint::FILE_NAME)).map_err(refused)?;
    let file = dir.join(checkpoint::FILE_NAME);
    let saved = checkpoint::read(&file).map_err(|e| BadInput(e.to_string()))?;
    if saved.solver.model != model_fingerprint(&design.model) {
        return Err(BadInput(format!(
            "{}: its checkpoint is of another model than {} (another design, or this one since changed): \
             resume it with the design it was started with, or start this one with -o DIR --force",
            dir.display(),
            design.path.display()
        ))
        .into());
    }
    if saved.outputs.settings != checkpoint::settings_fingerprint(&design.output) {
        return Err(BadInput(format!(
            "{}: the run there wrote other outputs (the design's `output` settings changed): resume it with \
             the design it was started with",
            dir.display()
        ))
        .into());
    }
    let history = dir.join("history.csv");
    crate::io::history::check_resumable(&history, &saved.outputs.history).map_err(|e| {
        BadInput(format!(
            "{}; the run cannot be continued from its checkpoint at step {} without the rows before it \
             (nothing was changed: put the history back, or run the design again with --force)",
            e,
            saved.solver.step
        ))
    })?;
    // Every check passed: only now is anything written (the lock, stale temporaries removed).
    let folder = fit.open()?;
    if !options.quiet {
        eprintln!(
            "stentkit run: resuming {} from its checkpoint at step {} (t = {} s)",
            dir.display(),
            saved.solver.step,
            short_time(saved.solver.time)
        );
    }
    run_in(design, &folder, options, started, Some(saved))
}

/// The `status` of the run folder's `summary.json`, if it can be read.
fn previous_status(dir: &Path) -> Option<String> {
    let value: serde_json::Value = crate::io::input::read_json(&dir.join("summary.json")).ok()?;
    value.get("status")?.as_str().map(str::to_string)
}

fn run_in(
    design: &Design,
    folder: &RunFolder,
    options: &RunOptions,
    started: Instant,
    resumed: Option<RunCheckpoint>,
) -> anyhow::Result<()> {
    let model = &design.model;
    let dir = folder.dir();
    let manifest = folder.manifest();
    let info = RunInfo {
        version: env!("CARGO_PKG_VERSION").to_string(),
        command_line: command_line(),
    };
    manifest.claim(Path::new("summary.json"))?;
    let mut summary = SummaryFile {
        path: dir.join("summary.json"),
        summary: RunSummaryFile::start(
            model,
            &design.path.display().to_string(),
            &info.version,
            &info.command_line,
            design.warnings.clone(),
        ),
        started,
        earlier_wall_s: resumed.as_ref().map_or(0.0, |c| c.outputs.wall_time_s),
        manifest: manifest.clone(),
        problem: None,
    };
    if !design.overrides.is_empty() {
        summary.summary.overrides.clone_from(&design.overrides);
        summary.summary.resolved_design = Some(design.source.clone());
    }
    summary.write(|_| {})?;
    let reserve = folder.reserve(super::disk::FINISHING_RESERVE)?;
    let setup = (|| -> anyhow::Result<_> {
        let mut sim = Simulation::new(model)?;
        if let Some(saved) = &resumed {
            sim.restore(&saved.solver)
                .with_context(|| format!("cannot restore {}", checkpoint::FILE_NAME))?;
        }
        if !options.quiet {
            let plan = match model.solver.path {
                crate::model::PathControl::Time => format!(
                    "{} steps of {} s to {} s",
                    design.steps.total(),
                    model.time.step,
                    model.time.end
                ),
                crate::model::PathControl::ArcLength(a) => format!(
                    "arc-length path to load factor {} (at most {} increments)",
                    a.end_load_factor, a.max_increments
                ),
            };
            eprintln!(
                "stentkit run: {} — {} patches, {} unknowns, {plan} → {}",
                model.name,
                model.patches.len(),
                model.num_unknowns(),
                dir.display()
            );
        }
        let outputs = match &resumed {
            None => create_outputs(design, folder, &info, &sim, options)?,
            Some(saved) => resume_outputs(design, folder, &info, &sim, options, &saved.outputs)?,
        };
        Ok((sim, outputs))
    })();
    let (mut sim, mut outputs) = match setup {
        Ok(x) => x,
        Err(e) => {
            let failure = e
                .downcast_ref::<SolverError>()
                .map(|s| FailureReport::of(s, 0, 0.0));
            let text = error_text(&e);
            summary.write(|s| {
                s.status = RunStatus::Failed;
                s.error = Some(text);
                s.failure = failure;
            })?;
            return Err(e);
        }
    };
    if signals::stop_requested() {
        return interrupted_in_setup(&mut summary, &mut outputs, &sim, started);
    }
    summary.summary.timing.setup_s = started.elapsed().as_secs_f64();

    let mut checkpoints = Checkpoints {
        path: dir.join(checkpoint::FILE_NAME),
        every: Duration::from_secs_f64(options.checkpoint_every),
        last: Instant::now(),
        settings: checkpoint::settings_fingerprint(&design.output),
        claimed: false,
        disabled: false,
    };
    let run_started = Instant::now();
    let result = sim.run(&mut [&mut RunObserver {
        outputs: &mut outputs,
        summary: &mut summary,
        checkpoints: &mut checkpoints,
    }]);
    summary.summary.timing.run_s = run_started.elapsed().as_secs_f64();
    outputs.progress.bar.finish_and_clear();
    outputs.progress.notices(&sim);
    // What the result must be read with: the stabilisation above its limit, and a device that ended heated but
    // not recovered (a completed run only). Said here and in summary.json's `warnings`, whatever the status.
    let recovered = result
        .as_ref()
        .is_ok_and(|s| !s.stopped && sim.is_finished())
        .then(|| crate::post::recovery::recovery_warning(&sim))
        .flatten();
    for warning in sim.stabilisation_warnings().iter().chain(&recovered) {
        eprintln!("warning: {warning}");
    }

    // A run stopped by a signal keeps its last converged step as a checkpoint (before `finish` adds the final
    // snapshot and mesh, which an uninterrupted run does not have); a completed run needs its checkpoint no more.
    let interrupted = signals::stop_requested();
    let stopped = result.as_ref().is_ok_and(|s| s.stopped);
    if stopped && interrupted && sim.step_count() > 0 && !checkpoints.disabled {
        checkpoints.write(&sim, &outputs, summary.wall_time_s(), manifest);
    }
    if result.as_ref().is_ok_and(|s| !s.stopped) && sim.is_finished() {
        // Best effort: a checkpoint left behind is listed, and `--force` removes it.
        let _ = crate::io::no_follow::remove_inside(dir, Path::new(checkpoint::FILE_NAME));
    }

    let finish_started = Instant::now();
    reserve.release();
    let mut finished = finish(&mut outputs, &sim, dir, manifest);
    if let Some(p) = summary.problem.take() {
        finished.problems.insert(0, p);
    }
    summary.summary.timing.finish_s = finish_started.elapsed().as_secs_f64();

    let first_problem = finished.problems.first().map(error_text);
    let (status, error) = match (&result, first_problem) {
        (Err(e), _) => (RunStatus::Failed, Some(e.to_string())),
        (Ok(_), None) if stopped && interrupted => (
            RunStatus::Interrupted,
            Some(format!(
                "interrupted by {} at t = {} s",
                signals::first().unwrap_or("a signal"),
                short_time(sim.time())
            )),
        ),
        (Ok(_), Some(p)) if stopped => (RunStatus::Stopped, Some(p)),
        (Ok(_), p) => (RunStatus::Completed, p),
    };
    let failure = result.as_ref().err().map(|e| {
        let mut report = FailureReport::of(e, outputs.totals.steps, sim.time());
        report.suggestions = suggestions(model, &report);
        report
    });
    let mcap_bytes = finished.mcap_bytes;
    let write = summary.write(|s| {
        outputs.fill(s, &sim);
        s.warnings.extend(recovered.clone());
        s.status = status;
        s.error = error;
        s.failure = failure;
        s.files.mcap_bytes = mcap_bytes;
        s.files.charts = finished
            .charts
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        if !finished.problems.is_empty() {
            s.outputs = finished.states.clone();
        }
    });
    if let Some(failure) = &summary.summary.failure {
        eprintln!("{}", failure_report(failure, &summary.summary));
    }
    if let Err(e) = write {
        finished.states.push(OutputState {
            file: "summary.json".into(),
            complete: false,
            state: format!("not updated (it says `running`): {}", error_text(&e)),
        });
        finished.problems.push(e);
    }

    let files = file_report(&finished);
    let where_ = |what: &str| {
        format!(
            "{what} at t = {} s; results up to there are in {}",
            short_time(sim.time()),
            dir.display(),
        )
    };
    if !files.is_empty() && (result.is_err() || (stopped && interrupted)) {
        eprintln!("{}", files.trim_start_matches("; "));
    }
    if let Err(e) = result {
        // A step that did not converge is told in full by the failure report printed above: the error line only
        // points there (the residuals and the equation once, not twice).
        if let crate::solver::SolverError::StepFailed { time, step, .. } = &e {
            return Err(anyhow::anyhow!(
                "{}: no convergence in step {step} to t = {} s (the failure report above)",
                where_("the run failed"),
                short_time(*time)
            ));
        }
        return Err(anyhow::Error::new(e).context(where_("the run failed")));
    }
    if stopped && interrupted {
        return Err(Interrupted(where_(&format!(
            "interrupted by {} after {} steps",
            signals::first().unwrap_or("a signal"),
            outputs.totals.steps
        )))
        .into());
    }
    if let Some(problem) = finished.problems.first() {
        // The cause first, then where the run stopped and which files are complete.
        return Err(anyhow::anyhow!(
            "{}; {}{files}",
            error_text(problem),
            where_(if stopped {
                "the run stopped"
            } else {
                "the run ended"
            })
        ));
    }
    let totals = &outputs.totals;
    let reached = match sim.load_factor() {
        Some(lambda) => format!(
            "load factor {lambda} (path parameter {})",
            Short(totals.time)
        ),
        None => format!("t = {} s", Short(totals.time)),
    };
    println!(
        "{}: {} steps to {reached}, {} Newton iterations ({:.2} per step), {} factorisations, {} step cuts, {} snapshots, {}, folder {}, wall time {:.2} s, peak memory {} → {}",
        model.name,
        totals.steps,
        totals.iterations,
        totals.iterations as f64 / totals.steps.max(1) as f64,
        totals.factorisations,
        totals.cuts,
        summary.summary.snapshots.len(),
        if design.output.recording.enabled {
            format!("run.mcap {}", human_bytes(mcap_bytes as Real))
        } else {
            "no recording".to_string()
        },
        human_bytes(folder.written_bytes() as Real),
        summary.summary.wall_time_s,
        summary
            .summary
            .peak_memory_mib
            .map_or("unknown".to_string(), |m| format!("{m:.0} MiB")),
        dir.display()
    );
    Ok(())
}

/// Creates the writers of the run folder, each file listed in the manifest first.
fn create_outputs(
    design: &Design,
    folder: &RunFolder,
    info: &RunInfo,
    sim: &Simulation<'_>,
    options: &RunOptions,
) -> anyhow::Result<Outputs> {
    let model = &design.model;
    let dir = folder.dir();
    let manifest = folder.manifest();
    manifest.claim(Path::new("history.csv"))?;
    let history_path = dir.join("history.csv");
    let history = HistoryWriter::create(&history_path, sim, &design.output.strain_limits)
        .with_context(|| format!("cannot write {}", history_path.display()))?;
    let snapshots = SnapshotWriter::create(dir, &design.output.snapshots, model)?
        .with_manifest(manifest.clone());
    let recorder = if design.output.recording.enabled {
        manifest.claim(Path::new("run.mcap"))?;
        Some(McapRecorder::create(
            &dir.join("run.mcap"),
            design,
            info,
            &design.output.snapshots,
        )?)
    } else {
        None
    };
    Ok(Outputs {
        history,
        snapshots,
        recorder,
        charts: RunCharts::new(model),
        progress: Progress::new(model, options.quiet, options.verbose),
        spent: [Duration::ZERO; 4],
        beat: Instant::now(),
        totals: crate::solver::RunSummary::default(),
        strain_warnings: Vec::new(),
        design_warnings: design.warnings.clone(),
    })
}

/// The writers of a resumed run, each continued from the checkpoint's `saved` positions (module docs): the
/// history cut back and appended to, the snapshots after the checkpoint removed (they are written again), the
/// recording copied up to the checkpoint into a new file that replaces the old one, the charts' states and the
/// run's totals carried over.
fn resume_outputs(
    design: &Design,
    folder: &RunFolder,
    info: &RunInfo,
    sim: &Simulation<'_>,
    options: &RunOptions,
    saved: &OutputsCheckpoint,
) -> anyhow::Result<Outputs> {
    let model = &design.model;
    let dir = folder.dir();
    let manifest = folder.manifest();
    let history_path = dir.join("history.csv");
    let history = HistoryWriter::resume(&history_path, saved.history, &design.output.strain_limits)
        .with_context(|| format!("cannot continue {}", history_path.display()))?;
    // Snapshots the checkpoint does not list are from after it (or the final one of an interrupted run).
    let kept: std::collections::BTreeSet<&Path> = saved
        .snapshots
        .iter()
        .flat_map(|s| s.files.iter().map(PathBuf::as_path))
        .collect();
    for listed in manifest.listed() {
        if listed.starts_with(SnapshotWriter::FOLDER) && !kept.contains(listed.as_path()) {
            crate::io::no_follow::remove_inside(dir, &listed)
                .with_context(|| format!("cannot remove {}", dir.join(&listed).display()))?;
        }
    }
    let snapshots = SnapshotWriter::create(dir, &design.output.snapshots, model)?
        .with_manifest(manifest.clone())
        .resumed(saved.snapshots.clone(), saved.snapshots_last);
    let recorder = if design.output.recording.enabled {
        Some(resume_recording(design, dir, info, &saved.recording)?)
    } else {
        None
    };
    let mut progress = Progress::new(model, options.quiet, options.verbose);
    progress.said = sim.notices().len();
    Ok(Outputs {
        history,
        snapshots,
        recorder,
        charts: RunCharts::new(model).resumed(saved.samples.clone()),
        progress,
        spent: saved.spent.map(|s| Duration::from_secs_f64(s.max(0.0))),
        beat: Instant::now(),
        totals: saved.totals.clone(),
        strain_warnings: Vec::new(),
        design_warnings: design.warnings.clone(),
    })
}

/// The recording of a resumed run: the killed or interrupted run's `run.mcap` (salvaged, if it was cut short)
/// is copied up to the checkpoint's last message into a new recording built in a temporary file beside it,
/// which then replaces it. A recording that cannot be read is started afresh with a warning (its states before
/// the checkpoint are lost; the other outputs are whole).
fn resume_recording(
    design: &Design,
    dir: &Path,
    info: &RunInfo,
    position: &crate::io::mcap::RecordingPosition,
) -> anyhow::Result<McapRecorder> {
    let path = dir.join("run.mcap");
    let temporary = dir.join(crate::io::stl::temporary_name(std::ffi::OsStr::new(
        "run.mcap",
    )));
    let mut recorder = McapRecorder::create(&temporary, design, info, &design.output.snapshots)?;
    let previous = salvage(&path)
        .map_err(anyhow::Error::from)
        .and_then(|_| std::fs::read(&path).map_err(anyhow::Error::from));
    let copied = match previous {
        Ok(bytes) => recorder
            .resume(&bytes, &path, position)
            .map_err(|e| e.to_string()),
        Err(e) => Err(error_text(&e)),
    };
    match copied {
        Ok(n) if n as u64 == u64::from(position.sequence) => {}
        Ok(n) => eprintln!(
            "warning: {} kept {n} of the {} messages recorded up to the checkpoint; the recording has a gap before it",
            path.display(),
            position.sequence
        ),
        Err(e) => eprintln!(
            "warning: the recording {} cannot be continued ({e}); it holds the states from the checkpoint on",
            path.display()
        ),
    }
    recorder.flush_chunk()?;
    recorder
        .rename(&path)
        .with_context(|| format!("cannot replace {}", path.display()))?;
    Ok(recorder)
}

/// A signal arrived while the run was set up: the (empty) outputs are closed and the summary says so.
fn interrupted_in_setup(
    summary: &mut SummaryFile,
    outputs: &mut Outputs,
    sim: &Simulation<'_>,
    started: Instant,
) -> anyhow::Result<()> {
    if let Some(recorder) = &mut outputs.recorder {
        let _ = recorder.close();
    }
    let message = format!(
        "interrupted by {} during setup, before the first step",
        signals::first().unwrap_or("a signal")
    );
    let text = message.clone();
    summary.write(|s| {
        outputs.fill(s, sim);
        s.status = RunStatus::Interrupted;
        s.error = Some(text);
        s.timing.setup_s = started.elapsed().as_secs_f64();
    })?;
    Err(Interrupted(message).into())
}

/// What finishing the outputs did.
struct Finished {
    /// Every problem met, the first one first.
    problems: Vec<anyhow::Error>,
    /// Which outputs are complete (listed in the error and summary when there were problems).
    states: Vec<OutputState>,
    /// Size of the recording \[bytes\] (0 if it was removed).
    mcap_bytes: u64,
    /// The charts written.
    charts: Vec<PathBuf>,
}

/// Finishes every output, whatever happened: cuts the history back to its last complete row, closes the
/// recording (salvaging it if it cannot be closed, removing it only if even that fails: a full disk), writes
/// the final snapshot (skipped after a second signal, in the files and the recording) and the charts, and says
/// which files are complete.
fn finish(
    outputs: &mut Outputs,
    sim: &Simulation<'_>,
    dir: &Path,
    manifest: &Manifest,
) -> Finished {
    let hurry = signals::hurry();
    let mut problems: Vec<anyhow::Error> = Vec::new();
    let mut states = Vec::new();
    let mut state = |file: &str, complete: bool, state: String| {
        states.push(OutputState {
            file: file.into(),
            complete,
            state,
        })
    };

    let history_path = dir.join("history.csv");
    let upto = |t: Option<Real>| {
        t.map_or("the header only".to_string(), |t| {
            format!("t = {} s", short_time(t))
        })
    };
    match outputs.history.take_error() {
        Some(e) => {
            let e =
                anyhow::Error::new(e).context(format!("cannot write {}", history_path.display()));
            state(
                "history.csv",
                true,
                format!(
                    "complete up to {} ({} rows); later rows not written: {}",
                    upto(outputs.history.last_time()),
                    outputs.history.rows(),
                    error_text(&e)
                ),
            );
            problems.push(e);
        }
        None => state(
            "history.csv",
            true,
            format!("complete up to {}", upto(outputs.history.last_time())),
        ),
    }

    // The recording first: salvaging a recording cut short by a full disk frees the space of its broken chunk.
    let mcap_bytes = outputs.recorder.as_mut().map_or(0, |recorder| {
        finish_recording(recorder, sim, hurry, dir, &upto, &mut state, &mut problems)
    });

    let snapshot_error = outputs.snapshots.take_error().map(anyhow::Error::from);
    // After any output error (most often a full disk) the final snapshot is not attempted: the room left is
    // for the charts and the summary.
    let final_snapshot = if hurry || snapshot_error.is_some() || !problems.is_empty() {
        None
    } else {
        outputs.snapshots.finish(sim).err().map(anyhow::Error::from)
    };
    let written = outputs.snapshots.snapshots();
    let listed = written
        .last()
        .map(|s| {
            format!(
                ", the last at step {} (t = {} s)",
                s.step,
                short_time(s.time)
            )
        })
        .unwrap_or_default();
    match snapshot_error.or(final_snapshot) {
        Some(e) => {
            state(
                "snapshots/",
                false,
                format!(
                    "{} complete{listed}; the next not written: {}",
                    written.len(),
                    error_text(&e)
                ),
            );
            problems.push(e);
        }
        None if hurry => state(
            "snapshots/",
            true,
            format!(
                "{} complete{listed}; final snapshot skipped (second signal)",
                written.len()
            ),
        ),
        None => state(
            "snapshots/",
            true,
            format!("{} complete{listed}", written.len()),
        ),
    }

    let figures = outputs.snapshots.write_configuration_figures(sim.model());
    let charts = match outputs
        .charts
        .write(sim.model(), dir, Some(manifest))
        .and_then(|charts| figures.map(|figures| [charts, figures].concat()))
    {
        Ok(files) => {
            state("charts/", true, format!("{} complete", files.len()));
            files
        }
        Err(e) => {
            let e = anyhow::Error::from(e);
            state(
                "charts/",
                false,
                format!("not all drawn: {}", error_text(&e)),
            );
            problems.push(e);
            Vec::new()
        }
    };
    Finished {
        problems,
        states,
        mcap_bytes,
        charts,
    }
}

/// Finishes the recording (or, after a write error or a second signal, closes it and salvages what it holds),
/// says how it stands with `state`, and returns its size \[bytes\]; its error joins `problems`.
fn finish_recording(
    recorder: &mut McapRecorder,
    sim: &Simulation<'_>,
    hurry: bool,
    dir: &Path,
    upto: &dyn Fn(Option<Real>) -> String,
    state: &mut dyn FnMut(&str, bool, String),
    problems: &mut Vec<anyhow::Error>,
) -> u64 {
    let record_error = recorder.take_error().map(anyhow::Error::from);
    // A writer that failed once refuses every later write: only the salvage can finish the file.
    let closed = if record_error.is_some() || hurry {
        recorder.close()
    } else {
        recorder.finish(sim)
    };
    let mcap_path = dir.join("run.mcap");
    let complete_to = format!("complete up to {}", upto(recorder.last_time()));
    // The first error is the cause; closing after it fails for that reason too.
    let (closed_bytes, cause) = match closed {
        Ok(bytes) => (bytes, record_error),
        Err(e) => (0, Some(record_error.unwrap_or_else(|| e.into()))),
    };
    match cause {
        None => {
            state("run.mcap", true, complete_to);
            closed_bytes
        }
        Some(e) => {
            let bytes = match salvage(&mcap_path) {
                Ok(Salvage::Finished {
                    after,
                    last_log_time,
                    ..
                }) => {
                    let t = last_log_time.map(|ns| ns as Real * 1e-9);
                    state(
                        "run.mcap",
                        true,
                        format!(
                            "finalised up to {}; later states not recorded: {}",
                            upto(t),
                            error_text(&e)
                        ),
                    );
                    after
                }
                Ok(Salvage::AlreadyValid { bytes }) => {
                    state(
                        "run.mcap",
                        true,
                        format!(
                            "{complete_to}; later states not recorded: {}",
                            error_text(&e)
                        ),
                    );
                    bytes
                }
                Err(salvage_error) => {
                    let removed = crate::io::no_follow::remove_inside(dir, Path::new("run.mcap"))
                        .unwrap_or(false);
                    state(
                        "run.mcap",
                        false,
                        format!(
                            "incomplete ({}) and cannot be finished ({salvage_error}){}",
                            error_text(&e),
                            if removed { ": removed" } else { "" }
                        ),
                    );
                    0
                }
            };
            problems.push(e);
            bytes
        }
    }
}

/// The files' states for an error message, when some output could not be finished; empty otherwise.
fn file_report(finished: &Finished) -> String {
    if finished.problems.is_empty() {
        return String::new();
    }
    let lines: Vec<String> = finished
        .states
        .iter()
        .map(|s| {
            format!(
                "\n  {} {}: {}",
                if s.complete { "✓" } else { "✗" },
                s.file,
                s.state
            )
        })
        .collect();
    format!("; the run folder holds:{}", lines.concat())
}

/// What to change after a step that did not converge, most likely first: from the phase of the cycle it
/// failed in, the patch of the equation with the largest residual and the design's settings.
fn suggestions(model: &crate::model::Model, failure: &FailureReport) -> Vec<String> {
    use crate::model::cycle::Phase;
    let Some(time) = failure.time else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let h = model.time.step;
    match model.phase_at(time) {
        Some(Phase::Programming) => out.push(match &model.programme {
            Some(p) => format!(
                "a slower programme: its ramp over a longer time (`programme.ramp`, now {}–{} s), or a smaller `time.step` (now {} s)",
                short_time(p.ramp.0),
                short_time(p.ramp.1),
                short_time(h)
            ),
            None => format!(
                "slower loading, or a smaller `time.step` (now {} s)",
                short_time(h)
            ),
        }),
        Some(Phase::Releasing | Phase::Released) => out.push(format!(
            "a gentler release: a longer `time.release_ramp` (now {} s) lets the step cuts follow the springback",
            short_time(model.time.release_ramp)
        )),
        _ => out.push(format!(
            "a smaller `time.step` (now {} s) or a smaller `time.min_step` (now {} s)",
            short_time(h),
            short_time(model.time.min_step)
        )),
    }
    // The patch of the worst equation, as `describe_row` quotes it.
    let patch = failure.worst_equation.as_deref().and_then(|w| {
        model
            .patches
            .iter()
            .find(|p| w.contains(&format!("`{}`", p.name)))
    });
    if let Some(patch) = patch {
        let d = model.sections[patch.section].diameter();
        if patch
            .fit_error
            .is_some_and(|e| e > crate::model::builder::FIT_WARNING_FRACTION * d)
        {
            out.push(format!(
                "more control points on patch `{}` (`mesh.n`, now {}): its spline fit deviates {:.1} % of the wire diameter from the curve",
                patch.name,
                patch.curve.num_points(),
                100.0 * patch.fit_error.unwrap_or(0.0) / d
            ));
        }
        // A generated stent's bridges are `b<crown>_<k>` (geometry::stent::bridges).
        let bridge = model.programme.is_some()
            && patch.name.starts_with('b')
            && patch.name[1..].starts_with(|c: char| c.is_ascii_digit());
        if bridge {
            out.push(format!(
                "stiffer or shorter bridges: the largest residual is on bridge `{}`, and slender bridges buckle into loops under the programme (straight bridges, a smaller `stent.bridges.amplitude`, a thicker `section`)",
                patch.name
            ));
        }
    }
    if model.solver.stabilisation.is_none() {
        out.push(
            "automatic stabilisation, `solver: {stabilisation: {}}`, carries a run through a buckle or a snap; summary.json then says how much energy it dissipated"
                .to_string(),
        );
    }
    out
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
    if let Some(w) = &failure.worst_equation {
        lines.push(format!("  largest residual: in the equation of {w}"));
    }
    if let Some(w) = &failure.diagnosis {
        lines.push(format!("  diagnosis: {w}"));
    }
    let snapshot = summary
        .snapshots
        .last()
        .filter(|s| s.step == failure.last_converged_step)
        .and_then(|s| {
            crate::io::formats::FORMATS
                .iter()
                .find_map(|f| s.files.get(f.extension()))
        })
        .map(|f| format!(", snapshot {f}"))
        .unwrap_or_default();
    lines.push(format!(
        "  last converged: step {}, t = {} s (history.csv and run.mcap end there{snapshot})",
        failure.last_converged_step,
        short_time(failure.last_converged_time)
    ));
    for (k, suggestion) in failure.suggestions.iter().enumerate() {
        lines.push(format!(
            "  {} {suggestion}",
            if k == 0 { "try:" } else { "  or" }
        ));
    }
    lines.join("\n")
}
