//! A run as a library call: simulate a design and write its run folder (DESIGN §7), from a new folder or from a
//! checkpoint of an interrupted run. `stentkit run` ([`crate::cli`]) parses the command line, maps the
//! signals onto an [`Interrupt`], prints through a [`Console`] and turns a [`RunError`] into an exit status;
//! tests and a sweep's workers call [`run`] in the same way, in process.
//!
//! ```text
//! DIR/history.csv             one row per step (io::history)
//! DIR/summary.json            what the run was and did (io::summary)
//! DIR/snapshots/step_NNNNN.{stl,obj}   the full device at the snapshot steps (io::snapshots)
//! DIR/run.mcap                the recording for Foxglove (io::mcap)
//! DIR/charts/*.svg            histories (io::run_charts)
//! ```
//!
//! The folder is taken through `crate::io::run_folder` (refusals, lock, manifest, `force`). The outputs that
//! follow the simulation are the [`recorder::RECORDERS`], observed with the console's progress display.
//! `summary.json` exists from the start (`"status": "running"`) and is rewritten every [`HEARTBEAT`] (2 s) with
//! the last converged step, when the recorders also make what they wrote readable (the recording's chunk is
//! closed), so that SIGKILL leaves a folder `stentkit repair` makes whole. Every file is finished whether the
//! run completes, fails, is interrupted ([`Interrupt`]: the step in progress is abandoned at its next Newton
//! iteration) or is stopped by an output error (a full disk: the history is cut back to its last complete row,
//! the recording salvaged up to its last complete chunk, and the error lists which files are complete): the
//! last state gets a snapshot and the summary says where the run stopped.
//!
//! **Checkpoints and resume.** Every [`RunSettings::checkpoint_every`] seconds of wall time (default 60), right
//! after a heartbeat (so the recording's chunks hold every state up to it), and when an interruption stops the
//! run, the run writes `checkpoint.bin` (`crate::io::checkpoint`: the simulation's
//! [`crate::solver::Checkpoint`] and each recorder's position under its name), atomically, listed in the
//! manifest; a completed run removes it. [`Folder::Resume`] takes the folder of a killed or interrupted run
//! (`run_folder::check_resume`), refuses another design (model and output fingerprints), a run that completed
//! or failed, a folder without a checkpoint and whatever a recorder refuses (a history shorter than the
//! checkpoint's or missing) with [`RunError::Refused`] (a refusal changes nothing, the summary included, so the
//! run can still be resumed once the cause is put right), restores the simulation and continues every recorder
//! from its position: `history.csv` is cut back to the checkpoint's row and continued; the snapshots after it
//! are removed and written again as their steps come; the recording (salvaged first if the run was killed) is
//! copied up to the checkpoint's last message into a new file built beside it, which then replaces it, and
//! continues; the charts and the summary's counts go on from the checkpoint's. The result is the uninterrupted
//! run's: the same history.csv byte for byte.
//!
//! **Disk.** A new run is refused when its estimated output ([`estimate`]: each recorder's part and the
//! summary) and `disk::FINISHING_RESERVE` exceed the free space (`disk::check_space`).

pub(crate) mod disk;
pub mod estimate;
pub mod recorder;

pub use recorder::{RECORDERS, Recorder, RecorderKind};

use crate::design::Design;
use crate::design::size::human_bytes;
use crate::io::checkpoint::{self, OutputsCheckpoint, RunCheckpoint};
use crate::io::mcap::RunInfo;
use crate::io::run_folder::{self, Manifest, RunFolder, RunFolderError};
use crate::io::summary::{FailureReport, OutputState, RunStatus, RunSummaryFile, peak_memory_mib};
use crate::math::quote::short_time;
use crate::math::{Real, Short};
use crate::model::Model;
use crate::solver::simulation::model_fingerprint;
use crate::solver::{NewtonReport, Observer, Simulation, SolverError, StepReport};
use recorder::{Finishing, Setup};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// How often a run rewrites `summary.json` with its last converged step and the recorders flush (the
/// recording's chunk is closed): what SIGKILL or a power loss can take is at most this much of the run (plus
/// the step in progress). Each chunk boundary costs a little compression; every 2 s is far below a percent of
/// the recording.
pub const HEARTBEAT: Duration = Duration::from_secs(2);

/// A request to stop a run, made from outside it (a signal's thread, another thread, a test) and read by the
/// run between Newton iterations. The first request stops the run at its next iteration, every file finished;
/// a second one also skips the optional work of finishing (the final snapshot's meshes).
#[derive(Debug, Default)]
pub struct Interrupt {
    /// Requests so far.
    count: AtomicUsize,
    /// What made the first request (`SIGINT`, …).
    cause: OnceLock<&'static str>,
}

impl Interrupt {
    /// No request yet.
    pub const fn new() -> Self {
        Self {
            count: AtomicUsize::new(0),
            cause: OnceLock::new(),
        }
    }

    /// Asks the run to stop; `cause` names what asked (kept from the first request only).
    pub fn request(&self, cause: &'static str) {
        let _ = self.cause.set(cause);
        self.count.fetch_add(1, Ordering::SeqCst);
    }

    /// Whether the run was asked to stop.
    pub fn requested(&self) -> bool {
        self.count.load(Ordering::SeqCst) > 0
    }

    /// Whether a second request asked to finish the files at once.
    pub fn hurried(&self) -> bool {
        self.count.load(Ordering::SeqCst) > 1
    }

    /// What made the first request, if any.
    pub fn cause(&self) -> Option<&'static str> {
        self.cause.get().copied()
    }

    /// The cause for messages: `a signal` when none was named.
    fn said(&self) -> &'static str {
        self.cause().unwrap_or("a signal")
    }
}

/// Where a run's messages go: the user's terminal (`cli`), a log (a sweep's variant), or nowhere.
pub trait Console {
    /// The run is set up and about to step `model`; the first `notices_shown` of the simulation's notices
    /// were shown already (a resumed run's). A progress display starts here.
    fn begin(&mut self, model: &Model, notices_shown: usize);
    /// The progress display as an observer of the simulation (`None`: none).
    fn progress(&mut self) -> Option<&mut dyn Observer>;
    /// A line for the user (a warning, a report), shown without disturbing the progress display.
    fn say(&self, line: &str);
    /// The run stopped stepping: the progress display ends; the notices not shown yet are.
    fn end(&mut self, sim: &Simulation<'_>);
}

/// A console that keeps the lines said and shows no progress (tests; a run whose messages go to a file).
#[derive(Debug, Default)]
pub struct Lines {
    lines: std::sync::Mutex<Vec<String>>,
}

impl Lines {
    /// The lines said so far, in order.
    pub fn lines(&self) -> Vec<String> {
        self.lines.lock().map(|l| l.clone()).unwrap_or_default()
    }
}

impl Console for Lines {
    fn begin(&mut self, _: &Model, _: usize) {}
    fn progress(&mut self) -> Option<&mut dyn Observer> {
        None
    }
    fn say(&self, line: &str) {
        if let Ok(mut lines) = self.lines.lock() {
            lines.push(line.to_string());
        }
    }
    fn end(&mut self, _: &Simulation<'_>) {}
}

/// How a run goes, besides its design and folder.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSettings {
    /// Wall time between checkpoints \[s\] (0: after every step; finite and ≥ 0).
    pub checkpoint_every: Real,
    /// No start line (the progress display is the console's business).
    pub quiet: bool,
    /// The command line to record (`summary.json`, `run.mcap`).
    pub command_line: String,
    /// When the command started (the setup time and the wall time count from here).
    pub started: Instant,
}

impl RunSettings {
    /// A checkpoint a minute, the start line said, started now.
    pub fn new(command_line: impl Into<String>) -> Self {
        Self {
            checkpoint_every: 60.0,
            quiet: false,
            command_line: command_line.into(),
            started: Instant::now(),
        }
    }
}

/// Which folder a run writes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Folder {
    /// A new run into `dir`; `force` replaces an earlier run there (only the files it wrote are removed).
    New {
        /// The run folder.
        dir: PathBuf,
        /// Replace an earlier run.
        force: bool,
    },
    /// Continue the killed or interrupted run in this folder from its checkpoint.
    Resume(PathBuf),
}

/// A run that completed.
#[derive(Debug, Clone, PartialEq)]
pub struct Completed {
    /// The run folder.
    pub dir: PathBuf,
    /// What the run did, in one line: steps, iterations, snapshots, recording, folder size, wall time, memory.
    pub report: String,
}

/// A boxed error of a layer below.
pub type BoxError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// Why a run did not complete.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// Refused before anything was written: a folder that cannot take the run, a checkpoint of another design,
    /// a disk too small (the input is at fault).
    #[error("{0}")]
    Refused(String),
    /// Stopped by an [`Interrupt`]; every file is finished and the message says where.
    #[error("{0}")]
    Interrupted(String),
    /// Failed, with what failed and its cause.
    #[error("{message}")]
    Failed {
        /// What failed.
        message: String,
        /// Why.
        #[source]
        source: Option<BoxError>,
    },
    /// An error of a layer below, as it is.
    #[error(transparent)]
    Other(BoxError),
}

impl RunError {
    /// An error of a layer below.
    pub fn other(error: impl Into<BoxError>) -> Self {
        Self::Other(error.into())
    }

    /// `message` caused by `error`.
    pub fn context(message: impl Into<String>, error: impl Into<BoxError>) -> Self {
        Self::Failed {
            message: message.into(),
            source: Some(error.into()),
        }
    }

    /// `message` alone.
    pub fn message(message: impl Into<String>) -> Self {
        Self::Failed {
            message: message.into(),
            source: None,
        }
    }
}

/// An error's message followed by its causes, each said once ([`crate::study::error_chain`]), numbers written
/// short (as `cli` prints errors).
pub fn error_text(error: &(dyn std::error::Error + 'static)) -> String {
    crate::math::quote::shortened_numbers(&crate::study::error_chain(error)).into_owned()
}

/// Runs `design` into `folder` (module docs): a new run, or the continuation of an interrupted one.
///
/// # Errors
/// [`RunError::Refused`] for a folder or disk refused before anything was written, [`RunError::Interrupted`]
/// for a run stopped by `interrupt`, another [`RunError`] for a failed run (its folder says how far it got).
pub fn run(
    design: &Design,
    folder: Folder,
    settings: &RunSettings,
    interrupt: &Interrupt,
    console: &mut dyn Console,
) -> Result<Completed, RunError> {
    match folder {
        Folder::New { dir, force } => {
            // Nothing is written before the folder and the disk are found fit for the run.
            let fit = run_folder::check(&dir, &design.path, force).map_err(refused)?;
            disk::check_space(design, &fit)?;
            let mut folder = fit.open().map_err(refused)?;
            folder.clear_previous().map_err(refused)?;
            run_in(design, &folder, settings, interrupt, console, None)
        }
        Folder::Resume(dir) => resume(design, &dir, settings, interrupt, console),
    }
}

/// A folder refused for the run is [`RunError::Refused`].
fn refused(e: RunFolderError) -> RunError {
    match e {
        RunFolderError::Refused { .. } => RunError::Refused(e.to_string()),
        e => RunError::other(e),
    }
}

/// Checks that `dir` holds a killed or interrupted run of this design with a checkpoint, then continues it
/// (module docs).
fn resume(
    design: &Design,
    dir: &Path,
    settings: &RunSettings,
    interrupt: &Interrupt,
    console: &mut dyn Console,
) -> Result<Completed, RunError> {
    // The summary's word first: a completed run has no checkpoint left, and that is why.
    match previous_status(dir).as_deref() {
        Some("completed") => {
            return Err(RunError::Refused(format!(
                "{}: the run there completed (summary.json says `completed`): there is nothing to resume",
                dir.display()
            )));
        }
        Some("failed") => {
            return Err(RunError::Refused(format!(
                "{}: the run there failed (summary.json says `failed`, with the reason); resuming would fail \
                 the same way: change the design and run it again with --force",
                dir.display()
            )));
        }
        _ => {}
    }
    let fit = run_folder::check_resume(dir, Path::new(checkpoint::FILE_NAME)).map_err(refused)?;
    let file = dir.join(checkpoint::FILE_NAME);
    let saved = checkpoint::read(&file).map_err(|e| RunError::Refused(e.to_string()))?;
    if saved.solver.model != model_fingerprint(&design.model) {
        return Err(RunError::Refused(format!(
            "{}: its checkpoint is of another model than {} (another design, or this one since changed): \
             resume it with the design it was started with, or start this one with -o DIR --force",
            dir.display(),
            design.path.display()
        )));
    }
    if saved.outputs.settings != checkpoint::settings_fingerprint(&design.output) {
        return Err(RunError::Refused(format!(
            "{}: the run there wrote other outputs (the design's `output` settings changed): resume it with \
             the design it was started with",
            dir.display()
        )));
    }
    for kind in RECORDERS {
        let position = saved_position(&saved.outputs, kind)?;
        (kind.check_resume)(dir, position, saved.solver.snapshot.clock.step)?;
    }
    // Every check passed: only now is anything written (the lock, stale temporaries removed).
    let folder = fit.open().map_err(refused)?;
    if !settings.quiet {
        console.say(&format!(
            "stentkit run: resuming {} from its checkpoint at step {} (t = {} s)",
            dir.display(),
            saved.solver.snapshot.clock.step,
            short_time(saved.solver.snapshot.clock.time)
        ));
    }
    run_in(design, &folder, settings, interrupt, console, Some(saved))
}

/// The position of recorder `kind` in a checkpoint, which every checkpoint of this version holds.
fn saved_position<'a>(
    saved: &'a OutputsCheckpoint,
    kind: &RecorderKind,
) -> Result<&'a [u8], RunError> {
    saved.position(kind.name).ok_or_else(|| {
        RunError::Refused(format!(
            "the checkpoint has no position of the recorder `{}`: it was written by another build of stentkit",
            kind.name
        ))
    })
}

/// The `status` of the run folder's `summary.json`, if it can be read.
fn previous_status(dir: &Path) -> Option<String> {
    let value: serde_json::Value = crate::io::input::read_json(&dir.join("summary.json")).ok()?;
    value.get("status")?.as_str().map(str::to_string)
}

/// The recorders of a run with the console, the time spent in each, and what the run did so far.
struct Outputs<'c> {
    /// The recorders, in the order of [`RECORDERS`].
    recorders: Vec<Box<dyn Recorder>>,
    /// Wall time spent in each recorder during the run.
    spent: Vec<Duration>,
    /// Where the messages go.
    console: &'c mut dyn Console,
    /// When the running summary was last written.
    beat: Instant,
    /// What the run did so far.
    totals: crate::solver::RunSummary,
    /// Materials' strain limits exceeded, as said.
    strain_warnings: Vec<String>,
    /// The design's warnings (the first of summary.json's `warnings`).
    design_warnings: Vec<String>,
}

impl Outputs<'_> {
    /// Calls every recorder (all of them, even after one asked to stop) with the time spent in each, then the
    /// progress display.
    fn observe(
        &mut self,
        interrupt: &Interrupt,
        mut call: impl FnMut(&mut dyn Observer) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let mut flow = ControlFlow::Continue(());
        for (recorder, spent) in self.recorders.iter_mut().zip(&mut self.spent) {
            let t = Instant::now();
            if call(recorder.as_mut()).is_break() {
                flow = ControlFlow::Break(());
            }
            *spent += t.elapsed();
        }
        let progress = self.console.progress().map(&mut call);
        if progress.is_some_and(|f| f.is_break()) || interrupt.requested() {
            flow = ControlFlow::Break(());
        }
        for recorder in &mut self.recorders {
            for warning in recorder.take_warnings() {
                self.console.say(&format!("warning: {warning}"));
                self.strain_warnings.push(warning);
            }
        }
        flow
    }

    /// Where every recorder stands, for a checkpoint; `wall_time_s` is the run's wall time so far.
    fn checkpoint(&self, settings: u64, wall_time_s: Real) -> OutputsCheckpoint {
        OutputsCheckpoint {
            settings,
            positions: self
                .recorders
                .iter()
                .map(|r| (r.name().to_string(), r.position()))
                .collect(),
            totals: self.totals.clone(),
            spent: self.spent_by_name().collect(),
            wall_time_s,
        }
    }

    /// The time spent in each recorder \[s\], by name.
    fn spent_by_name(&self) -> impl Iterator<Item = (String, Real)> + '_ {
        self.recorders
            .iter()
            .zip(&self.spent)
            .map(|(r, d)| (r.name().to_string(), d.as_secs_f64()))
    }

    /// Puts what the run did so far into `s`: counts, the time reached, each recorder's part, the last state,
    /// notices and the solver's time split.
    fn fill(&self, s: &mut RunSummaryFile, sim: &Simulation<'_>) {
        let t = &self.totals;
        s.steps = t.steps;
        s.newton_iterations = t.iterations;
        s.iterations_per_step = t.iterations as Real / t.steps.max(1) as Real;
        s.step_cuts = t.cuts;
        if let Some(control) = &mut s.time_error_control {
            control.accepted_steps = t.steps;
            control.rejected_steps = t.rejected;
            control.requested_states = t.requested;
        }
        if let (Some(summary), Some(settings)) =
            (&mut s.stabilisation, &sim.model().solver().stabilisation)
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
        s.warnings.extend(sim.warnings());
        s.final_time = sim.time();
        for recorder in &self.recorders {
            recorder.summarise(s, sim);
        }
        s.notices = sim.notices().to_vec();
        s.strain_limit_warnings.clone_from(&self.strain_warnings);
        s.timing.solver = sim.timing().entries().into_iter().collect();
        s.timing.recording = self.spent_by_name().collect();
    }
}

/// The observer of a run: the outputs, the running summary every [`HEARTBEAT`] and the checkpoints.
struct RunObserver<'a, 'c> {
    outputs: &'a mut Outputs<'c>,
    summary: &'a mut SummaryFile,
    checkpoints: &'a mut Checkpoints,
    interrupt: &'a Interrupt,
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
        outputs: &Outputs<'_>,
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
            outputs.console.say(&format!(
                "warning: cannot write the checkpoint {}: {e}; the run goes on without checkpoints",
                self.path.display()
            ));
        }
    }
}

impl RunObserver<'_, '_> {
    /// Every [`HEARTBEAT`] (or now, with `now`): the recorders flush and the running summary is rewritten.
    fn heartbeat(&mut self, sim: &Simulation<'_>, now: bool) -> ControlFlow<()> {
        if !now && self.outputs.beat.elapsed() < HEARTBEAT {
            return ControlFlow::Continue(());
        }
        self.outputs.beat = Instant::now();
        for recorder in &mut self.outputs.recorders {
            if let Err(e) = recorder.flush() {
                self.summary.problem = Some(e);
                return ControlFlow::Break(());
            }
        }
        let outputs = &*self.outputs;
        if let Err(e) = self.summary.write(|s| outputs.fill(s, sim)) {
            self.summary.problem = Some(e);
            return ControlFlow::Break(());
        }
        ControlFlow::Continue(())
    }
}

impl Observer for RunObserver<'_, '_> {
    fn start(&mut self, sim: &Simulation<'_>) -> ControlFlow<()> {
        let flow = self.outputs.observe(self.interrupt, |o| o.start(sim));
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
        totals.requested += report.requested;
        totals.time = report.time;
        let flow = self
            .outputs
            .observe(self.interrupt, |o| o.step(sim, report));
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

    fn requested(&mut self, sim: &Simulation<'_>, report: &StepReport) {
        // (A recorder that failed asks to stop at the next step.)
        let _ = self.outputs.observe(self.interrupt, |o| {
            o.requested(sim, report);
            ControlFlow::Continue(())
        });
    }

    fn step_failed(&mut self, time: Real, dt: Real, newton: &NewtonReport) {
        if let Some(progress) = self.outputs.console.progress() {
            progress.step_failed(time, dt, newton);
        }
    }

    fn interrupted(&self) -> bool {
        self.interrupt.requested()
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
    /// The first problem met while the run went on (writing the summary or flushing a recorder).
    problem: Option<RunError>,
}

impl SummaryFile {
    /// The run's wall time so far, over every command that ran it \[s\].
    fn wall_time_s(&self) -> Real {
        self.earlier_wall_s + self.started.elapsed().as_secs_f64()
    }

    /// Updates the summary with `update` (and the time, wall time and peak memory) and writes it.
    fn write(&mut self, update: impl FnOnce(&mut RunSummaryFile)) -> Result<(), RunError> {
        update(&mut self.summary);
        self.summary.updated = crate::io::run_folder::utc_timestamp(std::time::SystemTime::now());
        self.summary.wall_time_s = self.wall_time_s();
        self.summary.peak_memory_mib = peak_memory_mib();
        self.summary
            .write(&self.path)
            .map_err(|e| RunError::context(format!("cannot write {}", self.path.display()), e))
    }
}

/// Sets up the simulation (restored from `resumed`) and the recorders (continued from its positions), saying
/// the start line.
fn setup<'m, 'c>(
    design: &'m Design,
    folder: &RunFolder,
    info: &RunInfo,
    settings: &RunSettings,
    console: &'c mut dyn Console,
    resumed: Option<&RunCheckpoint>,
) -> Result<(Simulation<'m>, Outputs<'c>), RunError> {
    let model = &design.model;
    let mut sim = Simulation::new(model).map_err(RunError::other)?;
    if let Some(saved) = resumed {
        sim.restore(&saved.solver).map_err(|e| {
            RunError::context(format!("cannot restore {}", checkpoint::FILE_NAME), e)
        })?;
    }
    if !settings.quiet {
        let plan = match model.solver().path {
            crate::model::PathControl::Time => format!(
                "{} steps of {} s to {} s",
                design.steps.total(),
                model.time().step,
                model.time().end
            ),
            crate::model::PathControl::ArcLength(a) => format!(
                "arc-length path to load factor {} (at most {} increments)",
                a.end_load_factor, a.max_increments
            ),
        };
        console.say(&format!(
            "stentkit run: {} — {} patches, {} unknowns, {plan} → {}",
            model.name(),
            model.patches.len(),
            model.num_unknowns(),
            folder.dir().display()
        ));
    }
    let setup = Setup {
        design,
        folder,
        info,
        console: &*console,
    };
    let mut recorders = Vec::with_capacity(RECORDERS.len());
    let mut spent = Vec::with_capacity(RECORDERS.len());
    for kind in RECORDERS {
        recorders.push(match resumed {
            None => (kind.create)(&setup, &sim)?,
            Some(saved) => (kind.resume)(&setup, &sim, saved_position(&saved.outputs, kind)?)?,
        });
        let earlier = resumed.and_then(|saved| {
            saved
                .outputs
                .spent
                .iter()
                .find(|(name, _)| name == kind.name)
                .map(|(_, s)| *s)
        });
        spent.push(Duration::from_secs_f64(earlier.unwrap_or(0.0).max(0.0)));
    }
    console.begin(
        model,
        if resumed.is_some() {
            sim.notices().len()
        } else {
            0
        },
    );
    Ok((
        sim,
        Outputs {
            recorders,
            spent,
            console,
            beat: Instant::now(),
            totals: resumed.map_or_else(Default::default, |saved| saved.outputs.totals.clone()),
            strain_warnings: Vec::new(),
            design_warnings: design.warnings.clone(),
        },
    ))
}

/// Runs the design into the opened `folder`, new or continued from `resumed`.
fn run_in(
    design: &Design,
    folder: &RunFolder,
    settings: &RunSettings,
    interrupt: &Interrupt,
    console: &mut dyn Console,
    resumed: Option<RunCheckpoint>,
) -> Result<Completed, RunError> {
    let started = settings.started;
    let model = &design.model;
    let dir = folder.dir();
    let manifest = folder.manifest();
    let info = RunInfo {
        version: env!("CARGO_PKG_VERSION").to_string(),
        command_line: settings.command_line.clone(),
    };
    manifest
        .claim(Path::new("summary.json"))
        .map_err(RunError::other)?;
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
    let reserve = folder.reserve(disk::FINISHING_RESERVE).map_err(refused)?;
    let (mut sim, mut outputs) =
        match setup(design, folder, &info, settings, console, resumed.as_ref()) {
            Ok(x) => x,
            Err(e) => {
                let failure = match &e {
                    RunError::Other(source) => source
                        .downcast_ref::<SolverError>()
                        .map(|s| FailureReport::of(s, 0, 0.0)),
                    _ => None,
                };
                let text = error_text(&e);
                summary.write(|s| {
                    s.status = RunStatus::Failed;
                    s.error = Some(text);
                    s.failure = failure;
                })?;
                return Err(e);
            }
        };
    if interrupt.requested() {
        return interrupted_in_setup(&mut summary, &mut outputs, &sim, started, interrupt);
    }
    summary.summary.timing.setup_s = started.elapsed().as_secs_f64();

    let mut checkpoints = Checkpoints {
        path: dir.join(checkpoint::FILE_NAME),
        every: Duration::from_secs_f64(settings.checkpoint_every),
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
        interrupt,
    }]);
    summary.summary.timing.run_s = run_started.elapsed().as_secs_f64();
    outputs.console.end(&sim);
    // What the result must be read with: the stabilisation above its limit, a term's own (contact above its
    // penetration tolerance), and a device that ended heated but
    // not recovered (a completed run only). Said here and in summary.json's `warnings`, whatever the status.
    let recovered = result
        .as_ref()
        .is_ok_and(|s| !s.stopped && sim.is_finished())
        .then(|| crate::post::recovery::recovery_warning(&sim))
        .flatten();
    for warning in sim.warnings().iter().chain(&recovered) {
        outputs.console.say(&format!("warning: {warning}"));
    }

    // A run stopped by an interruption keeps its last converged step as a checkpoint (before the recorders
    // finish with the final snapshot and mesh, which an uninterrupted run does not have); a completed run needs
    // its checkpoint no more.
    let interrupted = interrupt.requested();
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
    let mut finished = Finishing {
        dir,
        manifest,
        hurry: interrupt.hurried(),
        problems: Vec::new(),
        states: Vec::new(),
        mcap_bytes: 0,
        charts: Vec::new(),
        figures: None,
    };
    for recorder in &mut outputs.recorders {
        recorder.finish(&sim, &mut finished);
    }
    if let Some(p) = summary.problem.take() {
        finished.problems.insert(0, p);
    }
    summary.summary.timing.finish_s = finish_started.elapsed().as_secs_f64();

    let first_problem = finished.problems.first().map(|p| error_text(p));
    let (status, error) = match (&result, first_problem) {
        (Err(e), _) => (RunStatus::Failed, Some(e.to_string())),
        (Ok(_), None) if stopped && interrupted => (
            RunStatus::Interrupted,
            Some(format!(
                "interrupted by {} at t = {} s",
                interrupt.said(),
                short_time(sim.time())
            )),
        ),
        (Ok(_), Some(p)) if stopped => (RunStatus::Stopped, Some(p)),
        (Ok(_), p) => (RunStatus::Completed, p),
    };
    let failure = result.as_ref().err().map(|e| {
        let mut report = FailureReport::of(e, outputs.totals.steps, sim.time());
        if let Some(t) = sim.wires_crossed() {
            report.before.push(format!(
                "the wires had passed through each other since t = {} s (where: the run's warning on wires passing \
                 through each other; a wire through another, or a quarter model's wire through its own mirror \
                 image), so the model was no longer the device from then on, which may be why it failed",
                short_time(t)
            ));
        }
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
        outputs
            .console
            .say(&failure_report(failure, &summary.summary));
    }
    if let Err(e) = write {
        finished.states.push(OutputState {
            file: "summary.json".into(),
            complete: false,
            state: format!("not updated (it says `running`): {}", error_text(&e)),
        });
        finished.problems.push(e);
    }

    let files = file_report(&finished.problems, &finished.states);
    let where_ = |what: &str| {
        format!(
            "{what} at t = {} s; results up to there are in {}",
            short_time(sim.time()),
            dir.display(),
        )
    };
    if !files.is_empty() && (result.is_err() || (stopped && interrupted)) {
        outputs.console.say(files.trim_start_matches("; "));
    }
    if let Err(e) = result {
        // A step that did not converge is told in full by the failure report said above: the error only points
        // there (the residuals and the equation once, not twice).
        if let SolverError::StepFailed { time, step, .. } = &e {
            return Err(RunError::message(format!(
                "{}: no convergence in step {step} to t = {} s (the failure report above)",
                where_("the run failed"),
                short_time(*time)
            )));
        }
        return Err(RunError::context(where_("the run failed"), e));
    }
    if stopped && interrupted {
        return Err(RunError::Interrupted(where_(&format!(
            "interrupted by {} after {} steps",
            interrupt.said(),
            outputs.totals.steps
        ))));
    }
    if let Some(problem) = finished.problems.first() {
        // The cause first, then where the run stopped and which files are complete.
        return Err(RunError::message(format!(
            "{}; {}{files}",
            error_text(problem),
            where_(if stopped {
                "the run stopped"
            } else {
                "the run ended"
            })
        )));
    }
    let totals = &outputs.totals;
    let reached = match sim.load_factor() {
        Some(lambda) => format!(
            "load factor {lambda} (path parameter {})",
            Short(totals.time)
        ),
        None => format!("t = {} s", Short(totals.time)),
    };
    let report = format!(
        "{}: {} steps to {reached}, {} Newton iterations ({:.2} per step), {} factorisations, {} step cuts, {} snapshots, {}, folder {}, wall time {:.2} s, peak memory {} → {}",
        model.name(),
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
    Ok(Completed {
        dir: dir.to_path_buf(),
        report,
    })
}

/// An interruption arrived while the run was set up: the (empty) outputs are closed and the summary says so.
fn interrupted_in_setup(
    summary: &mut SummaryFile,
    outputs: &mut Outputs<'_>,
    sim: &Simulation<'_>,
    started: Instant,
    interrupt: &Interrupt,
) -> Result<Completed, RunError> {
    for recorder in &mut outputs.recorders {
        recorder.abandon();
    }
    let message = format!(
        "interrupted by {} during setup, before the first step",
        interrupt.said()
    );
    let text = message.clone();
    summary.write(|s| {
        outputs.fill(s, sim);
        s.status = RunStatus::Interrupted;
        s.error = Some(text);
        s.timing.setup_s = started.elapsed().as_secs_f64();
    })?;
    Err(RunError::Interrupted(message))
}

/// The files' states for an error message, when some output could not be finished; empty otherwise.
fn file_report(problems: &[RunError], states: &[OutputState]) -> String {
    if problems.is_empty() {
        return String::new();
    }
    let lines: Vec<String> = states
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
    let h = model.time().step;
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
            short_time(model.time().release_ramp)
        )),
        _ => out.push(format!(
            "a smaller `time.step` (now {} s) or a smaller `time.min_step` (now {} s)",
            short_time(h),
            short_time(model.time().min_step)
        )),
    }
    // The patch of the worst equation, as `describe_row` quotes it.
    let worst = failure.worst_equation.as_deref().and_then(|w| {
        model
            .patches
            .iter()
            .position(|p| w.contains(&format!("`{}`", p.name)))
    });
    let mut refine_named = false;
    if let Some(index) = worst {
        let patch = &model.patches[index];
        let d = model.sections[patch.section].diameter();
        if patch
            .fit_error
            .is_some_and(|e| e > crate::model::builder::FIT_WARNING_FRACTION * d)
        {
            refine_named = true;
            out.push(format!(
                "more control points on patch `{}` (`mesh.n`, now {}): its spline fit deviates {:.1} % of the wire diameter from the curve",
                patch.name,
                patch.curve.num_points(),
                100.0 * patch.fit_error.unwrap_or(0.0) / d
            ));
        }
        // A connector of a generated stent (its family's bridges) under a programme.
        if model.programme.is_some() && model.connectors.contains(&index) {
            out.push(format!(
                "stiffer or shorter bridges: the largest residual is on bridge `{}`, and slender bridges buckle into loops under the programme (straight bridges, a smaller `stent.bridges.amplitude`, a thicker `section`)",
                patch.name
            ));
        }
    }
    // A coarse model's own path can fold where the converged model's does not (issue 36: the straight stent's
    // meshes map), which a smaller step does not cure and stabilisation only carries the run through.
    if let Some(patch) = (!refine_named)
        .then(|| worst.or((!model.patches.is_empty()).then_some(0)))
        .flatten()
        .map(|k| &model.patches[k])
    {
        out.push(format!(
            "a finer mesh (`mesh.n`, now {} with p = {}): a coarse model's own equilibrium path can fold where a finer one's does not (`stentkit tune` finds the mesh that resolves the results)",
            patch.curve.num_points(),
            patch.curve.degree()
        ));
    }
    // The paper's rotation field composes Newton's increments into the state (issue 36): some coarse stents, the
    // 10-peak radial bench and contact runs that it failed finished with the objective field, not all
    // (docs/choices.md).
    if model.solver().rotations == crate::model::RotationField::Incremental {
        out.push(
            "the objective rotation field, `solver: {rotations: objective}` (the default; this run uses the paper's, whose configuration depends on the increments that reach it): some runs the paper's field failed finish with it, not all (docs/choices.md, *Rotation field*)"
                .to_string(),
        );
    }
    if model.solver().stabilisation.is_none() {
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
    for b in &failure.before {
        lines.push(format!("  before it failed: {b}"));
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
