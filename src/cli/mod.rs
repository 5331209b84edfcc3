//! The `stentkit` command line: `check` (validate a design and describe it), `mesh` (write the reference
//! shape as a closed tube surface), `run` (simulate and write the run folder), `study` (accuracy against cost)
//! and `schema` (the JSON Schema of the design format). The only module that uses `anyhow` and prints.

pub(crate) mod arguments;
pub(crate) mod bench;
pub mod check;
pub(crate) mod disk;
pub(crate) mod drawing;
pub(crate) mod export;
pub(crate) mod mesh;
pub(crate) mod render;
pub(crate) mod repair;
pub mod run;
pub(crate) mod signals;
pub(crate) mod study;
pub(crate) mod sweep;
pub(crate) mod tune;

use crate::bench::Test;
use crate::design::SetOverride;
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// stentkit — design, simulate and export 4D-printed shape-memory-polymer rod devices.
#[derive(Debug, Parser)]
#[command(
    name = "stentkit",
    version,
    about,
    long_about = None,
    after_help = "Exit status: 0 completed, 1 failed (solver, output, folder in use), 2 bad input (design, \
                  arguments, folder, existing output or size refused; nothing ran), 130 interrupted by SIGINT, SIGTERM or SIGHUP."
)]
pub(crate) struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The tests of `stentkit bench`.
#[derive(Debug, Subcommand)]
pub(crate) enum BenchTest {
    /// The radial force (ASTM F3067): the device at the bench's temperature in a rigid crimper closing from
    /// just outside it to `bench.min_diameter` and opening again at `bench.rate`; writes `radial.csv` (diameter,
    /// branch, force in N, N per length, kPa, mmHg) and `charts/radial_force.svg` into the run folder and prints
    /// the smallest diameter reached and the forces at the vessel's diameter.
    ///
    /// Example: stentkit bench radial designs/straight_stent.yaml --set bench.temperature=90
    Radial(BenchArgs),
    /// The flat-plate crush: the device at the bench's temperature between two rigid plates parallel to its
    /// straight axis closing from just outside it to `bench.min_gap` (default a 50 % crush) and opening again
    /// at `bench.rate`; writes `crush.csv` (gap, branch, force on one plate in N, N per length, kPa, mmHg) and
    /// `charts/crush_force.svg` and prints the smallest gap reached and the forces at 10, 25 and 50 % crushed.
    ///
    /// Example: stentkit bench crush designs/straight_stent.yaml --set bench.min_gap=30
    Crush(BenchArgs),
}

/// The arguments of every bench test.
#[derive(Debug, clap::Args)]
pub(crate) struct BenchArgs {
    /// The design file (YAML).
    design: PathBuf,
    /// Run folder (default: `runs/<design name>-<test>`).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Replace an earlier run in the run folder (only the files it wrote are removed).
    #[arg(long)]
    force: bool,
    /// No progress bar; the results are printed.
    #[arg(short, long)]
    quiet: bool,
    /// Override a field of the design, `bench:` included: `PATH=VALUE` (`--set bench.rate=0.5`).
    #[arg(long = "set", value_name = "PATH=VALUE", value_parser = arguments::set_override())]
    set: Vec<SetOverride>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub(crate) enum Command {
    /// Validate a design and print its patches, nodes, collocation points, unknowns, time steps, geometry fit
    /// error and warnings.
    ///
    /// Example: stentkit check designs/circular_arch.yaml
    Check {
        /// The design file (YAML).
        design: PathBuf,
        /// Override a field of the design: `PATH=VALUE`, the field path as error messages write it and a YAML
        /// value (`--set stent.crowns=8 --set material.wlf.Tg=65 --set mesh.n=30`); repeatable, applied in order
        /// and checked as if written in the file.
        #[arg(long = "set", value_name = "PATH=VALUE", value_parser = arguments::set_override())]
        set: Vec<SetOverride>,
    },
    /// Simulate a design and write the run folder: history.csv, summary.json, snapshots/ (STL and OBJ of the
    /// full device), run.mcap (open it in Foxglove) and charts/ (SVG).
    ///
    /// SIGINT (Ctrl-C), SIGTERM and SIGHUP stop the run at the next Newton iteration and finish every file; a
    /// second signal skips the final snapshot and charts; a third quits at once (then `stentkit repair`).
    /// Exit status: 0 completed, 1 failed, 2 bad input, 130 interrupted.
    ///
    /// A run writes a checkpoint (checkpoint.bin) every --checkpoint-every seconds of wall time and when it is
    /// interrupted; `--resume RUN_DIR` continues a killed (even by SIGKILL) or interrupted run from its last
    /// checkpoint with the same design, and ends with the files an uninterrupted run writes (history.csv
    /// identical, the recording continued, the snapshots after the checkpoint written again).
    ///
    /// Example: stentkit run designs/straight_stent.yaml -o runs/straight_stent
    ///
    /// Example: stentkit run designs/straight_stent.yaml --resume runs/straight_stent
    Run {
        /// The design file (YAML).
        design: PathBuf,
        /// Run folder (default: `runs/<design name>`).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Replace an earlier run in the run folder: only the files that run wrote (its manifest lists them) are
        /// removed. A folder that is not a run folder is never used.
        #[arg(long)]
        force: bool,
        /// No progress bar (it is also hidden when stderr is not a terminal); the summary line is printed.
        #[arg(short, long)]
        quiet: bool,
        /// Report every failed Newton attempt (before the step is cut).
        #[arg(short, long)]
        verbose: bool,
        /// Continue the run in RUN_DIR from its last checkpoint instead of starting one: RUN_DIR must hold a run
        /// of the same design that was killed or interrupted (not one that completed or failed).
        #[arg(long, value_name = "RUN_DIR", conflicts_with_all = ["output", "force"])]
        resume: Option<PathBuf>,
        /// Wall time between checkpoints, in seconds (0: after every step). A checkpoint costs a write of the
        /// state (a few MB for a large stent) and closes the recording's chunk.
        #[arg(long, value_name = "SECONDS", default_value_t = 60.0, value_parser = arguments::non_negative(), allow_negative_numbers = true)]
        checkpoint_every: f64,
        /// Error-controlled time steps at this time-error tolerance (replaces the design's `time.tolerance`; a
        /// design's `step` becomes the first step): the estimated error of each step, normalised as Newton's
        /// increments (translations over the patch length, rotations in radians), stays below it.
        #[arg(long, value_name = "TOLERANCE", value_parser = arguments::positive(), allow_negative_numbers = true)]
        tol: Option<f64>,
        /// Override a field of the design: `PATH=VALUE`, the field path as error messages write it and a YAML
        /// value (`--set stent.crowns=8 --set material.wlf.Tg=65 --set mesh.n=30`); repeatable, applied in order
        /// and checked as if written in the file.
        #[arg(long = "set", value_name = "PATH=VALUE", value_parser = arguments::set_override())]
        set: Vec<SetOverride>,
    },
    /// The virtual bench: a test a stent engineer runs on the device, as a run of the design (`bench radial`:
    /// the radial force in a closing and opening crimper; `bench crush`: the flat-plate crush). The design's `bench:` block sets it (`--set
    /// bench.temperature=90`); the run folder gets the bench's table and chart besides a run's files.
    ///
    /// Example: stentkit bench radial designs/straight_stent.yaml -o runs/straight_stent-radial
    Bench {
        /// Which test.
        #[command(subcommand)]
        test: BenchTest,
    },
    /// Write the full device's tube mesh in any state of a finished run: at a time, or at an event of its
    /// shape-memory cycle (initial, programmed, fixed, released, final). The run's design (summary.json's
    /// design_file with its --set overrides, checked against the run's model fingerprint) is simulated again to
    /// the first step at or after that time, which is the run's own state.
    ///
    /// Example: stentkit export runs/straight_stent --phase released -o released.stl
    ///
    /// Example: stentkit export runs/straight_stent --phase final --print -o final.3mf
    Export {
        /// The run folder.
        run_dir: PathBuf,
        /// The first step at or after this time.
        #[arg(long, conflicts_with = "phase", required_unless_present = "phase", value_parser = arguments::non_negative(), allow_negative_numbers = true)]
        time: Option<f64>,
        /// An event of the cycle: initial, programmed, fixed, released, final.
        #[arg(long)]
        phase: Option<String>,
        /// Output file, `.stl`, `.obj` or `.3mf`; or `.csv` for the wires' centrelines (rod, point, x, y, z,
        /// radius).
        #[arg(short, long, value_parser = arguments::device_file())]
        output: PathBuf,
        /// Replace the output file if it exists (without --force an existing file is refused, exit status 2).
        #[arg(long)]
        force: bool,
        /// The design file, when it is no longer where the run found it (summary.json's design_file).
        #[arg(long)]
        design: Option<PathBuf>,
        /// Segments around each tube.
        #[arg(long, default_value_t = drawing::DEFAULT_SEGMENTS, value_parser = arguments::at_least::<3>(), allow_negative_numbers = true)]
        segments: usize,
        /// Rings along each patch, about.
        #[arg(long, default_value_t = drawing::DEFAULT_RINGS, value_parser = arguments::at_least::<2>(), allow_negative_numbers = true)]
        rings: usize,
        #[command(flatten)]
        print: PrintArgs,
    },
    /// Find the cheapest degree p, points per patch n and time-error tolerance whose results (every probe, Δr,
    /// the recovery ratios) stay within --tol of a finer run over the design's whole schedule: the space error
    /// screened on a short horizon (n against 2n), then the time tolerance (τ against τ/10), then the choice
    /// verified against (p, 2n, τ/10). Prints what it tried; writes the tuned design with -o.
    ///
    /// Example: stentkit tune designs/curved_stent.yaml --tol 5e-3 -o curved_stent_tuned.yaml
    Tune {
        /// The design file (YAML).
        design: PathBuf,
        /// Tolerance on the results: displacements over the largest one, Δr over its largest, recovery ratios
        /// absolute.
        #[arg(long, value_name = "TOLERANCE", value_parser = arguments::positive(), allow_negative_numbers = true)]
        tol: f64,
        /// Write the tuned design here (the design's text with `mesh` and `time` changed and a comment block
        /// stating the estimated error and the expected saving). An existing file is replaced only with --force.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Replace the -o file if it exists (without --force an existing file is refused, exit status 2).
        #[arg(long, requires = "output")]
        force: bool,
        /// Degrees to try.
        #[arg(long, value_delimiter = ',', default_value = "4,5,6", value_parser = arguments::at_least::<2>(), allow_negative_numbers = true)]
        degrees: Vec<usize>,
        /// Most control points per patch tried.
        #[arg(long, default_value_t = 200, value_parser = arguments::at_least::<3>(), allow_negative_numbers = true)]
        max_points: usize,
        /// Override a field of the design: `PATH=VALUE`, the field path as error messages write it and a YAML
        /// value (`--set stent.crowns=8 --set material.wlf.Tg=65 --set mesh.n=30`); repeatable, applied in order
        /// and checked as if written in the file.
        #[arg(long = "set", value_name = "PATH=VALUE", value_parser = arguments::set_override())]
        set: Vec<SetOverride>,
    },
    /// Run a family of variants of a design: the cartesian product (or with --zip the pairs) of the values of
    /// every --set, each variant a resolved design and a run folder under -o DIR, on this machine with --jobs
    /// workers or as a Slurm job array (--slurm). A rerun continues: completed variants are skipped, interrupted
    /// ones continue from their checkpoint, failed ones rerun with --retry-failed. Writes DIR/sweep.csv and
    /// DIR/charts/ at the end (and `sweep collect DIR` at any time).
    ///
    /// Example: stentkit sweep designs/straight_stent.yaml --set material.wlf.Tg=60,65,70 --set section.diameter=0.5:0.7:0.1 -o runs/tg_sweep
    ///
    /// Example: stentkit sweep designs/straight_stent.yaml --set material.wlf.Tg=60:80:5 -o runs/tg --slurm --partition debug --time 00:30:00
    Sweep(SweepCli),
    /// Make the folder of a run that was killed (SIGKILL, power loss, crash) whole: cut history.csv back to its
    /// last complete row, finish run.mcap after its last complete chunk, remove unfinished temporaries, and mark
    /// summary.json `killed`. A folder whose run is still going is refused.
    ///
    /// Example: stentkit repair runs/straight_stent
    Repair {
        /// The run folder.
        run_dir: PathBuf,
    },
    /// Accuracy against cost: convergence in p × n, error against time step per integrator, stability map.
    ///
    /// Example: stentkit study convergence designs/circular_arch.yaml --time 3 -o runs/arch_convergence
    #[command(subcommand)]
    Study(StudyCommand),
    /// Print the JSON Schema of the design format, for editors that complete and check YAML (e.g. the YAML
    /// language server: `# yaml-language-server: $schema=stentkit.schema.json` at the top of a design).
    ///
    /// Example: stentkit schema > stentkit.schema.json
    Schema,
    /// Draw a finished run's snapshots as a shaded picture (PNG): the initial shape, then the device at each
    /// chosen time over it in light grey (software rasteriser, no GPU).
    ///
    /// Example: stentkit render runs/straight_stent --times 1.75 3.25 -o straight.png
    Render {
        /// The run folder.
        run_dir: PathBuf,
        /// Output file (`.png`).
        #[arg(short, long)]
        output: PathBuf,
        /// Replace the output file if it exists (without --force an existing file is refused, exit status 2).
        #[arg(long)]
        force: bool,
        /// Times to draw, each the nearest snapshot's (default: those of the configuration figures).
        #[arg(long, num_args = 1.., value_parser = arguments::non_negative(), allow_negative_numbers = true)]
        times: Vec<f64>,
        /// View: `axonometric`, `x1-x2`, `x1-x3` or `x2-x3`.
        #[arg(long, default_value = "axonometric", value_parser = arguments::parsed_by(render::view_name))]
        view: String,
        /// Width of each panel in pixels.
        #[arg(long, default_value_t = crate::io::render::PANEL_WIDTH)]
        width: u32,
    },
    /// Write the reference (permanent) shape as a closed tube surface, or with `--state temporary` the shape
    /// the programme drives it to: binary STL, OBJ or 3MF by extension. With `--print`, one solid for a
    /// printer instead: the union of the wires, joints filled, standing on its axis on z = 0.
    ///
    /// Example: stentkit mesh designs/circular_arch.yaml -o arch.stl
    ///
    /// Example: stentkit mesh designs/straight_stent.yaml --print -o stent.3mf
    ///
    /// Example: stentkit mesh designs/curved_stent.yaml --state temporary -o crimped.stl
    Mesh {
        /// The design file (YAML).
        design: PathBuf,
        /// Output file, `.stl`, `.obj` or `.3mf`; or `.csv` for the wires' centrelines (rod, point, x, y, z,
        /// radius).
        #[arg(short, long, value_parser = arguments::device_file())]
        output: PathBuf,
        /// Replace the output file if it exists (without --force an existing file is refused, exit status 2).
        #[arg(long)]
        force: bool,
        /// Which shape: the permanent one (printed), or the temporary one the programme drives it to (generated
        /// in the programme's placement, not simulated).
        #[arg(long, value_enum, default_value = "permanent")]
        state: mesh::State,
        /// Segments around each tube.
        #[arg(long, default_value_t = drawing::DEFAULT_SEGMENTS, value_parser = arguments::at_least::<3>(), allow_negative_numbers = true)]
        segments: usize,
        /// Samples along each patch per control point.
        #[arg(long, default_value_t = drawing::DEFAULT_SAMPLES, value_parser = arguments::at_least::<1>(), allow_negative_numbers = true)]
        samples: usize,
        /// Override a field of the design: `PATH=VALUE`, the field path as error messages write it and a YAML
        /// value (`--set stent.crowns=8 --set material.wlf.Tg=65 --set mesh.n=30`); repeatable, applied in order
        /// and checked as if written in the file.
        #[arg(long = "set", value_name = "PATH=VALUE", value_parser = arguments::set_override())]
        set: Vec<SetOverride>,
        #[command(flatten)]
        print: PrintArgs,
    },
}

/// The print-solid options of `mesh` and `export`.
#[derive(Debug, Clone, Copy, clap::Args)]
pub(crate) struct PrintArgs {
    /// Write one closed, manifold solid for a printer (the union of the wires, joints filled, simplified,
    /// standing on its axis on z = 0) instead of one tube per rod.
    #[arg(long)]
    pub print: bool,
    /// Grid spacing of the print solid, in the design's length unit (default: a third of the thinnest wire's
    /// radius).
    #[arg(long, requires = "print", value_parser = arguments::positive(), allow_negative_numbers = true)]
    pub grid: Option<f64>,
    /// How far the print solid's simplification may move the surface, in the design's length unit (default: a
    /// fiftieth of the thinnest wire's radius).
    #[arg(long, requires = "print", value_parser = arguments::non_negative(), allow_negative_numbers = true)]
    pub deviation: Option<f64>,
}

impl PrintArgs {
    /// The print settings, if `--print` was given.
    pub(crate) fn settings(self) -> Option<crate::post::print::PrintSettings> {
        self.print.then_some(crate::post::print::PrintSettings {
            spacing: self.grid,
            tolerance: self.deviation,
        })
    }
}

/// `stentkit sweep`: a sweep to run, or one of its subcommands.
#[derive(Debug, clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub(crate) struct SweepCli {
    /// collect, status or task.
    #[command(subcommand)]
    pub command: Option<SweepCommand>,
    /// The design file (YAML).
    #[arg(required = true)]
    pub design: Option<PathBuf>,
    /// A swept field: `PATH=V1,V2,…` (YAML values) or `PATH=START:STOP:STEP` (numbers, STOP included);
    /// repeatable. A single value is the same in every variant.
    #[arg(long = "set", value_name = "PATH=VALUES", required = true)]
    pub set: Vec<String>,
    /// Pair the k-th values of every --set instead of taking their cartesian product.
    #[arg(long)]
    pub zip: bool,
    /// Run a bench test on every variant instead of its design's run (`radial` or `crush`, as `stentkit
    /// bench`): sweep.csv gets the smallest size reached and the bench's forces.
    #[arg(long, value_parser = ["radial", "crush"])]
    pub bench: Option<String>,
    /// The sweep folder (new, or one this sweep wrote: it continues).
    #[arg(short, long, required = true)]
    pub output: Option<PathBuf>,
    /// Variants run at once on this machine (default: cores / --threads-per-run).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Threads of each run (RAYON_NUM_THREADS of each worker).
    #[arg(long, default_value_t = 1)]
    pub threads_per_run: usize,
    /// Rerun the variants that failed.
    #[arg(long)]
    pub retry_failed: bool,
    /// Times of the recovery-ratio columns of sweep.csv (default: halfway from the release to the end, and
    /// the end).
    #[arg(long, value_delimiter = ',')]
    pub at: Option<Vec<f64>>,
    /// Submit the variants as a Slurm job array (DIR/sweep.sbatch, one task per variant) instead of running
    /// them here; again after a cancellation, it submits only the unfinished ones.
    #[arg(long)]
    pub slurm: bool,
    /// With --slurm: the partition.
    #[arg(long, requires = "slurm")]
    pub partition: Option<String>,
    /// With --slurm: the time limit of each task, HH:MM:SS.
    #[arg(long, requires = "slurm")]
    pub time: Option<String>,
    /// With --slurm: CPUs (and threads) of each task.
    #[arg(long, default_value_t = 1, requires = "slurm")]
    pub cpus_per_task: usize,
    /// With --slurm: tasks running at once (`--array=…%M`).
    #[arg(long, requires = "slurm")]
    pub max_parallel: Option<usize>,
    /// With --slurm: write DIR/sweep.sbatch without submitting it.
    #[arg(long, requires = "slurm")]
    pub dry_run: bool,
}

/// The subcommands of `stentkit sweep`.
#[derive(Debug, Subcommand)]
pub(crate) enum SweepCommand {
    /// Write DIR/sweep.csv (a row per variant: parameters, status, wall time, programmed displacement, snap at
    /// release, fixity, recovery ratios, times to 50 % and 90 % recovery, final residual shape) and
    /// DIR/charts/ (each metric against each numeric parameter), from the variants' run folders.
    ///
    /// Example: stentkit sweep collect runs/tg_sweep
    Collect {
        /// The sweep folder.
        dir: PathBuf,
        /// Times of the recovery-ratio columns.
        #[arg(long, value_delimiter = ',')]
        at: Option<Vec<f64>>,
    },
    /// Each variant's state: from Slurm (squeue) for the tasks it still lists, from the run folders otherwise.
    ///
    /// Example: stentkit sweep status runs/tg_sweep
    Status {
        /// The sweep folder.
        dir: PathBuf,
    },
    /// Run one variant of a sweep (what each local worker and each Slurm array task runs).
    #[command(hide = true)]
    Task {
        /// The sweep folder.
        dir: PathBuf,
        /// The variant's number (the array task id).
        index: usize,
        /// Rerun the variant if it failed.
        #[arg(long)]
        retry_failed: bool,
    },
}

/// The studies.
#[derive(Debug, Subcommand)]
pub(crate) enum StudyCommand {
    /// p × n sweep: displacement error against a self-converged run, and wall time, per run (CSV).
    ///
    /// Example: stentkit study convergence designs/circular_arch.yaml --time 3 -o runs/arch_convergence
    Convergence {
        /// The design file (YAML).
        design: PathBuf,
        /// Output folder.
        #[arg(short, long)]
        output: PathBuf,
        /// Replace the files the study writes if the output folder holds them (without --force they are
        /// refused, exit status 2; other files in the folder are never touched).
        #[arg(long)]
        force: bool,
        /// Degrees p.
        #[arg(long, value_delimiter = ',', default_value = "2,3,4,5,6,7,8", value_parser = arguments::at_least::<2>(), allow_negative_numbers = true)]
        degrees: Vec<usize>,
        /// Control points n per patch.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "8,10,12,16,20,24,32,40,48,64",
            value_parser = arguments::at_least::<3>(), allow_negative_numbers = true
        )]
        points: Vec<usize>,
        /// Time at which the error is measured (default: the design's end time).
        #[arg(long, value_parser = arguments::positive(), allow_negative_numbers = true)]
        time: Option<f64>,
        /// Reference degree and points, `P,N`.
        #[arg(long, default_value = "8,150", value_parser = arguments::parsed_by(study::degree_and_points))]
        reference: (usize, usize),
        /// Sampling points per patch.
        #[arg(long, default_value_t = 9, value_parser = arguments::at_least::<2>(), allow_negative_numbers = true)]
        samples: usize,
        /// Also run every p × n with error-controlled steps at this time-error tolerance (work–precision
        /// curves beside the fixed steps); `none` for none.
        #[arg(long, default_value = "1e-4", value_parser = arguments::positive_or_none(), allow_negative_numbers = true)]
        time_tolerance: MaybeTolerance,
    },
    /// Time-step sweep per integrator: displacement error at time T against a self-converged run, and wall
    /// time (CSV, error_vs_h.svg, error_vs_time.svg); prints the observed order of each integrator.
    ///
    /// Example: stentkit study time designs/cantilever_morphing.yaml --time 1 --steps 0.02,0.01,0.005 -o runs/cantilever_time
    Time {
        /// The design file (YAML).
        design: PathBuf,
        /// Output folder.
        #[arg(short, long)]
        output: PathBuf,
        /// Replace the files the study writes if the output folder holds them (without --force they are
        /// refused, exit status 2; other files in the folder are never touched).
        #[arg(long)]
        force: bool,
        /// Time at which the error is measured; the runs end there (default: the design's end time).
        #[arg(long, value_parser = arguments::positive(), allow_negative_numbers = true)]
        time: Option<f64>,
        /// Nominal time steps h.
        #[arg(long, value_delimiter = ',', default_value = "0.04,0.02,0.01,0.005", value_parser = arguments::positive(), allow_negative_numbers = true)]
        steps: Vec<f64>,
        /// Time-error tolerances of error-controlled runs (trapezoidal update) beside the fixed steps; `none`
        /// for none.
        #[arg(long, value_delimiter = ',', default_value = "1e-2,1e-3,1e-4,1e-5", value_parser = arguments::positive_or_none(), allow_negative_numbers = true)]
        tolerances: Vec<MaybeTolerance>,
        /// Integrators to compare.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "trapezoidal,backward-euler,exponential",
            value_parser = arguments::parsed_by(study::parse_integrator)
        )]
        integrators: Vec<crate::material::Integrator>,
        /// Reference run: `auto` (exponential integrator, smallest h halved), `design` (the design's own step
        /// and integrator) or a step (exponential integrator with that step).
        #[arg(long, default_value = "auto", value_parser = arguments::parsed_by(study::parse_reference))]
        reference: crate::study::time::TimeReference,
        /// Sampling points per patch.
        #[arg(long, default_value_t = 9, value_parser = arguments::at_least::<2>(), allow_negative_numbers = true)]
        samples: usize,
    },
    /// Stability map: where each integrator rings (h/τ on one Maxwell branch, held and cooled) and where
    /// Newton needs step cuts or fails (load steps of the 45° bend, heating per step of the loaded arch, the
    /// release snap of a two-crown stent, coarse models, a crown crimped and released by a cylinder). Writes a
    /// CSV and an SVG per map and stability.md.
    ///
    /// Example: stentkit study stability -o runs/stability
    Stability {
        /// Output folder.
        #[arg(short, long)]
        output: PathBuf,
        /// Replace the files the study writes if the output folder holds them (without --force they are
        /// refused, exit status 2; other files in the folder are never touched).
        #[arg(long)]
        force: bool,
        /// Maps to draw: any of material, bend45, heating, release, coarse, contact, meshes (the straight
        /// stent's cycle on 81 meshes with each rotation field, about 20 minutes) and curved (the curved
        /// stent's on 104, hours on two cores); meshes and curved are drawn only when named.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "material,bend45,heating,release,coarse,contact",
            value_parser = arguments::one_of(study::MAPS)
        )]
        maps: Vec<String>,
    },
}

/// Exit status of a command that failed: the solver failed, an output could not be written, the run folder is
/// in use.
pub const EXIT_FAILED: u8 = 1;
/// Exit status of bad input: a design refused (file, line, column and field named), a bad argument, a run folder
/// refused, a design too large for the memory or the disk. Nothing was run.
pub const EXIT_BAD_INPUT: u8 = 2;
/// Exit status of a run interrupted by SIGINT, SIGTERM or SIGHUP (128 + SIGINT, the shells' convention).
pub const EXIT_INTERRUPTED: u8 = 130;

/// Input refused before anything ran (exit status [`EXIT_BAD_INPUT`]).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub(crate) struct BadInput(pub String);

/// A file or folder the user named for a command's output (`-o`), and whether what is there may be replaced
/// (`--force`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Target<'a> {
    /// The file or folder.
    pub path: &'a std::path::Path,
    /// Replace what exists.
    pub force: bool,
}

/// Refuses to replace any of `targets` that exists (a file, a folder, a link, even a dangling one) unless
/// `force`: every command that writes a file the user names (`mesh`, `export`, `render`, `tune -o`, the files a
/// `study` writes into its `-o` folder) asks this before any work, so that a refusal costs nothing and changes
/// nothing. Their files are written atomically (a temporary renamed over the target): with `force` a link in a
/// target's place is replaced, never written through.
///
/// # Errors
/// [`BadInput`] (exit status 2) naming every target that exists.
pub(crate) fn refuse_existing<'a>(
    targets: impl IntoIterator<Item = &'a std::path::Path>,
    force: bool,
) -> Result<(), BadInput> {
    if force {
        return Ok(());
    }
    let existing: Vec<String> = targets
        .into_iter()
        .filter(|p| p.symlink_metadata().is_ok())
        .map(|p| p.display().to_string())
        .collect();
    match existing.as_slice() {
        [] => Ok(()),
        [one] => Err(BadInput(format!(
            "{one}: exists; pass --force to replace it, or choose another name (nothing was written)"
        ))),
        many => Err(BadInput(format!(
            "{}: exist; pass --force to replace them, or choose another folder with -o (nothing was written)",
            many.join(", ")
        ))),
    }
}

/// A run stopped by a signal (exit status [`EXIT_INTERRUPTED`]).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub(crate) struct Interrupted(pub String);

/// The exit status of a command that ended with `error`.
pub fn exit_code(error: &anyhow::Error) -> u8 {
    use crate::design::DesignError;
    use crate::io::run_folder::RunFolderError;
    for cause in error.chain() {
        if cause.is::<Interrupted>() {
            return EXIT_INTERRUPTED;
        }
        if cause.is::<BadInput>()
            || cause.is::<DesignError>()
            || matches!(
                cause.downcast_ref::<RunFolderError>(),
                Some(RunFolderError::Refused { .. })
            )
        {
            return EXIT_BAD_INPUT;
        }
    }
    EXIT_FAILED
}

/// An error's message followed by its causes, each said once: a cause whose text the message already holds
/// (an error that prints its source and also returns it, as many libraries' errors do) is not repeated; its
/// numbers written out in full are written short ([`crate::math::quote::shortened_numbers`]).
pub fn error_text(error: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in error.chain() {
        let s = cause.to_string();
        if text.contains(&s) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&s);
    }
    crate::math::quote::shortened_numbers(&text).into_owned()
}

pub(crate) use crate::math::quote::short_time;

/// Runs the command line and returns the process exit code.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Check { design, set } => check::run(&design, set),
        Command::Run {
            design,
            output,
            force,
            quiet,
            verbose,
            resume,
            checkpoint_every,
            tol,
            set,
        } => run::run(
            &design,
            run::RunOptions {
                output,
                force,
                quiet,
                verbose,
                resume,
                checkpoint_every,
                time_tolerance: tol,
                sets: set,
            },
        ),
        Command::Bench { test } => {
            let (test, a) = match test {
                BenchTest::Radial(a) => (Test::Radial, a),
                BenchTest::Crush(a) => (Test::Crush, a),
            };
            bench::bench(test, &a.design, a.output, a.force, a.quiet, a.set)
        }
        Command::Export {
            run_dir,
            time,
            phase,
            output,
            force,
            design,
            segments,
            rings,
            print,
        } => export::run(
            &run_dir,
            &export::ExportOptions {
                which: match (time, phase) {
                    (Some(t), _) => export::Which::Time(t),
                    (None, phase) => export::Which::Phase(phase.unwrap_or_default()),
                },
                output,
                force,
                design,
                segments,
                rings,
                print: print.settings(),
            },
        ),
        Command::Tune {
            design,
            tol,
            output,
            force,
            degrees,
            max_points,
            set,
        } => tune::run(
            &design,
            tol,
            output.as_deref().map(|path| Target { path, force }),
            degrees,
            max_points,
            set,
        ),
        Command::Sweep(cli) => sweep(cli),
        Command::Schema => schema(),
        Command::Repair { run_dir } => repair::run(&run_dir),
        Command::Study(StudyCommand::Convergence {
            design,
            output,
            force,
            degrees,
            points,
            time,
            reference,
            samples,
            time_tolerance,
        }) => study::convergence(
            &design,
            Target {
                path: &output,
                force,
            },
            degrees,
            points,
            reference,
            study::Sampling { time, samples },
            time_tolerance.0,
        ),
        Command::Study(StudyCommand::Time {
            design,
            output,
            force,
            time,
            steps,
            tolerances,
            integrators,
            reference,
            samples,
        }) => study::time(
            &design,
            Target {
                path: &output,
                force,
            },
            steps,
            tolerances.into_iter().filter_map(|t| t.0).collect(),
            integrators,
            reference,
            study::Sampling { time, samples },
        ),
        Command::Study(StudyCommand::Stability {
            output,
            force,
            maps,
        }) => study::stability_maps(
            Target {
                path: &output,
                force,
            },
            &maps,
        ),
        Command::Render {
            run_dir,
            output,
            force,
            times,
            view,
            width,
        } => render::run(
            &run_dir,
            Target {
                path: &output,
                force,
            },
            &times,
            &view,
            width,
        ),
        Command::Mesh {
            design,
            output,
            force,
            state,
            segments,
            samples,
            set,
            print,
        } => mesh::run(
            &design,
            Target {
                path: &output,
                force,
            },
            state,
            mesh::Resolution {
                segments,
                samples,
                print: print.settings(),
            },
            set,
        ),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_text(&e));
            ExitCode::from(exit_code(&e))
        }
    }
}

/// A tolerance argument that may be `none` (a type of its own: clap would take an `Option` field for an
/// optional argument).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MaybeTolerance(pub Option<f64>);

/// `stentkit sweep …`.
fn sweep(cli: SweepCli) -> anyhow::Result<()> {
    match cli.command {
        Some(SweepCommand::Collect { dir, at }) => sweep::collect_command(&dir, at),
        Some(SweepCommand::Status { dir }) => sweep::status(&dir),
        Some(SweepCommand::Task {
            dir,
            index,
            retry_failed,
        }) => sweep::task(&dir, index, retry_failed),
        None => {
            let (Some(design), Some(output)) = (cli.design, cli.output) else {
                return Err(BadInput("give a design, --set and -o".into()).into());
            };
            let slurm = cli.slurm.then_some(crate::sweep::slurm::SlurmOptions {
                partition: cli.partition,
                time: cli.time,
                cpus_per_task: cli.cpus_per_task,
                max_parallel: cli.max_parallel,
                retry_failed: cli.retry_failed,
            });
            sweep::run(
                &design,
                sweep::SweepOptions {
                    sets: cli.set,
                    zip: cli.zip,
                    bench: cli.bench.as_deref().and_then(Test::from_name),
                    output,
                    jobs: cli.jobs,
                    threads_per_run: cli.threads_per_run,
                    retry_failed: cli.retry_failed,
                    at: cli.at,
                    slurm,
                    dry_run: cli.dry_run,
                },
            )
        }
    }
}

/// Prints the design format's JSON Schema.
fn schema() -> anyhow::Result<()> {
    println!(
        "{}",
        serde_json::to_string_pretty(&crate::design::design_schema())?
    );
    Ok(())
}
