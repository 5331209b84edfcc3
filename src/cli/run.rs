//! `stentkit run`: simulates a design and writes the run folder through [`crate::run`] (the folder's layout,
//! heartbeat, checkpoints and `--resume` are described there). This command reads the design with its
//! `--set` and `--tol` overrides, maps SIGINT, SIGTERM and SIGHUP onto the run's interruption
//! (`super::signals`: the step in progress is abandoned at its next Newton iteration), shows a progress bar
//! (indicatif, on stderr, hidden when stderr is not a terminal or with `--quiet`) and prints the run's
//! messages, and turns the run's errors into exit statuses: a refusal is bad input (2), an interruption 130,
//! anything else a failed run (1).

use super::signals;
use super::{BadInput, Interrupted};
use crate::design::{DesignOverrides, load_design_with};
use crate::math::Real;
use crate::model::Model;
use crate::run::{Console, Folder, Interrupt, RunError, RunSettings};
use crate::solver::{NewtonReport, Observer, Simulation, StepReport};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::Write as _;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

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
    /// Where its lines go.
    out: Arc<Out>,
}

/// How often the progress bar is redrawn when nothing is reported (a step being cut): its elapsed time keeps
/// moving.
const PROGRESS_TICK: Duration = Duration::from_millis(250);

impl Progress {
    fn new(model: &Model, quiet: bool, verbose: bool, out: Arc<Out>) -> Self {
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
            end: model.time().end,
            said: 0,
            verbose,
            cuts: 0,
            failed: 0,
            last: String::new(),
            phases: model.phases(),
            out,
        }
    }

    fn notices(&mut self, sim: &Simulation<'_>) {
        for notice in &sim.notices()[self.said..] {
            self.out.say(&self.bar, &format!("note: {notice}"));
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
            self.out.say(&self.bar, &format!(
                "  step to t = {time} (dt = {dt:.3e}) failed after {} iterations; normalised residuals {:?}; increments {:?}",
                newton.iterations, newton.residuals, newton.increments
            ));
        }
    }
}

/// The command line as typed, arguments with spaces quoted.
pub(crate) fn command_line() -> String {
    quoted_command_line(std::env::args())
}

/// `args` as one line, arguments that are empty or hold spaces quoted (what `summary.json` and `run.mcap`
/// record as the command line).
pub(crate) fn quoted_command_line(args: impl IntoIterator<Item = String>) -> String {
    args.into_iter()
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
    pub sets: Vec<crate::design::SetOverride>,
}

/// Simulates the design and writes the run folder, on this terminal, stopped by the process's signals.
///
/// # Errors
/// A `BadInput` or [`crate::design::DesignError`] for a design or folder refused before anything ran
/// (exit status 2), `Interrupted` for a run stopped by a signal (130), anything else for a failed run (1).
pub fn run(design_path: &Path, options: RunOptions) -> anyhow::Result<()> {
    let started = Instant::now();
    signals::install();
    let mut console = Terminal::new(options.quiet, options.verbose, Out::default());
    let completed = run_with(
        design_path,
        options,
        (started, command_line()),
        &mut console,
        &signals::INTERRUPT,
    )?;
    println!("{}", completed.report);
    Ok(())
}

/// [`run`] with its messages (and the completed run's report, returned) going to `console`, stopped by
/// `interrupt`, started at `started.0` by the command line `started.1` (recorded in `summary.json` and
/// `run.mcap`): what a sweep's worker calls in process.
///
/// # Errors
/// As [`run`].
pub fn run_with(
    design_path: &Path,
    options: RunOptions,
    (started, command_line): (Instant, String),
    console: &mut dyn Console,
    interrupt: &Interrupt,
) -> anyhow::Result<crate::run::Completed> {
    // `--tol` and `--checkpoint-every` were checked with the arguments (`super::arguments`).
    let overrides = DesignOverrides {
        time_tolerance: options.time_tolerance,
        sets: options.sets.clone(),
        ..DesignOverrides::default()
    };
    let design = load_design_with(design_path, &overrides)?;
    for w in &design.warnings {
        console.say(&format!("warning: {w}"));
    }
    if interrupt.requested() {
        return Err(Interrupted(format!(
            "{} while reading the design: nothing was written",
            interrupt.cause().unwrap_or("signal")
        ))
        .into());
    }
    let folder = match &options.resume {
        Some(dir) => Folder::Resume(dir.clone()),
        None => Folder::New {
            dir: run_dir(options.output.clone(), design.model.name()),
            force: options.force,
        },
    };
    let settings = RunSettings {
        checkpoint_every: options.checkpoint_every,
        quiet: options.quiet,
        command_line,
        started,
    };
    crate::run::run(&design, folder, &settings, interrupt, console).map_err(command_error)
}

/// The command's error for a run's: a refusal is [`BadInput`], an interruption [`Interrupted`], the rest keeps
/// its message and causes as they were.
pub(crate) fn command_error(e: RunError) -> anyhow::Error {
    match e {
        RunError::Refused(message) => BadInput(message).into(),
        RunError::Interrupted(message) => Interrupted(message).into(),
        RunError::Failed {
            message,
            source: Some(source),
        } => anyhow::Error::from_boxed(source).context(message),
        RunError::Failed {
            message,
            source: None,
        } => anyhow::Error::msg(message),
        RunError::Other(source) => anyhow::Error::from_boxed(source),
    }
}

/// The run folder for a design: `-o DIR` or `runs/<design name>`.
fn run_dir(output: Option<PathBuf>, name: &str) -> PathBuf {
    output.unwrap_or_else(|| Path::new("runs").join(name))
}

/// Where a console's lines go: stderr (around the progress bar), or a log file (a sweep's variant run in
/// process, whose lines a worker process wrote to its log before).
#[derive(Debug, Default)]
pub(crate) struct Out {
    log: Option<Mutex<std::fs::File>>,
}

impl Out {
    /// Lines appended to `log`.
    pub(crate) fn log(log: std::fs::File) -> Self {
        Self {
            log: Some(Mutex::new(log)),
        }
    }

    /// Writes `line`, around `bar` on stderr (a log write that fails is dropped, as stderr's).
    fn say(&self, bar: &ProgressBar, line: &str) {
        match &self.log {
            Some(log) => {
                if let Ok(mut file) = log.lock() {
                    let _ = writeln!(file, "{line}");
                }
            }
            None => bar.suspend(|| eprintln!("{line}")),
        }
    }
}

/// The terminal (or a log) as a run's console: the progress bar, from the run's start, and the messages.
pub(crate) struct Terminal {
    quiet: bool,
    verbose: bool,
    out: Arc<Out>,
    /// A hidden bar for the lines said before the progress bar starts.
    none: ProgressBar,
    progress: Option<Progress>,
}

impl Terminal {
    /// A console with a progress bar unless `quiet` (a log has none), every failed Newton attempt reported with
    /// `verbose`, its lines going to `out`.
    pub(crate) fn new(quiet: bool, verbose: bool, out: Out) -> Self {
        let quiet = quiet || out.log.is_some();
        Self {
            quiet,
            verbose,
            out: Arc::new(out),
            none: ProgressBar::hidden(),
            progress: None,
        }
    }
}

impl Console for Terminal {
    fn begin(&mut self, model: &Model, notices_shown: usize) {
        let mut progress = Progress::new(model, self.quiet, self.verbose, self.out.clone());
        progress.said = notices_shown;
        self.progress = Some(progress);
    }

    fn progress(&mut self) -> Option<&mut dyn Observer> {
        self.progress.as_mut().map(|p| p as &mut dyn Observer)
    }

    fn say(&self, line: &str) {
        let bar = self.progress.as_ref().map_or(&self.none, |p| &p.bar);
        self.out.say(bar, line);
    }

    fn end(&mut self, sim: &Simulation<'_>) {
        if let Some(p) = &mut self.progress {
            p.bar.finish_and_clear();
            p.notices(sim);
        }
    }
}
