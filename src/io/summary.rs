//! `summary.json`: what a run was and what it did — design, units, version and command line, status, wall
//! time and its split, steps, Newton iterations, step cuts, size of the problem, the snapshots and other files
//! written, the final state, warnings and notices. Written when the run starts (`"status": "running"`),
//! rewritten every few seconds with the last converged step, and at the end of every run, also one that failed
//! (`stentkit repair` marks the summary of a killed run `"killed"`).

use super::snapshots::Snapshot;
use super::state::StateSample;
use crate::math::Real;
use crate::model::Model;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// How the run ended, or that it has not ended yet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RunStatus {
    /// Still running (or killed without a chance to say so: SIGKILL, power loss; `stentkit repair` then says
    /// `killed`). The summary holds the last converged step, rewritten every few seconds.
    Running,
    /// The process was killed while running (found and marked by `stentkit repair`); the outputs hold the
    /// states up to the last converged step they recorded.
    Killed,
    /// Reached the end time.
    Completed,
    /// Stopped early by an output that could not be written (see `error`).
    Stopped,
    /// The solver failed (see `error`); the outputs hold the states up to the last converged step.
    Failed,
    /// Interrupted by a signal (SIGINT, SIGTERM, SIGHUP); the outputs hold the states up to the last converged
    /// step.
    Interrupted,
}

/// The state of one output at the end of a run that could not write everything (e.g. a full disk): which
/// files are complete and which are not.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OutputState {
    /// The file or folder, relative to the run folder.
    pub file: String,
    /// Whether it is complete and valid (possibly ending before the run did).
    pub complete: bool,
    /// What it holds, or why it is missing.
    pub state: String,
}

/// Where and how the solver failed (`status: failed`), and the last converged state the run folder holds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FailureReport {
    /// What failed: `no_convergence` (Newton failed at the smallest step), `free_body`, `singular_tangent`,
    /// `geometry`, `material` or `linear_solver`.
    pub kind: String,
    /// Time the failing step tried to reach \[s\] (no convergence only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time: Option<Real>,
    /// Number of the failing step, 1-based (no convergence only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub step: Option<usize>,
    /// Step size of the last attempt \[s\] (no convergence only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dt: Option<Real>,
    /// Newton iterations of the last attempt (no convergence only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub iterations: Option<usize>,
    /// Normalised residual at each assembly of the last attempt (`null` where it was not finite).
    pub residuals: Vec<Real>,
    /// Why the last attempt was abandoned at once, if it was: where a NaN or infinity first appeared, or where
    /// an increment too large for a regular tangent was largest.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diagnosis: Option<String>,
    /// The equation whose normalised residual was largest at the last assembly (no convergence only): patch,
    /// collocation point or node, and which balance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub worst_equation: Option<String>,
    /// What the run met before it failed that may be why, in words (filled by `stentkit run`): wires that had
    /// passed through each other, and since when.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub before: Vec<String>,
    /// What to change, most likely first (filled by `stentkit run` from the model and where it failed).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub suggestions: Vec<String>,
    /// The last converged step (0: the initial state), whose state the outputs end with.
    pub last_converged_step: usize,
    /// Its time \[s\].
    pub last_converged_time: Real,
    /// The solver's message.
    pub message: String,
}

impl FailureReport {
    /// The report of `error`, the run having converged up to `step` at `time`.
    pub fn of(error: &crate::solver::SolverError, step: usize, time: Real) -> Self {
        use crate::solver::SolverError as E;
        let mut report = Self {
            kind: match error {
                E::StepFailed { .. } => "no_convergence",
                E::FreeBody { .. } => "free_body",
                E::Singular { .. } => "singular_tangent",
                E::Geometry { .. } => "geometry",
                E::Material(_) => "material",
                E::Linear(_) => "linear_solver",
            }
            .into(),
            time: None,
            step: None,
            dt: None,
            iterations: None,
            residuals: Vec::new(),
            diagnosis: None,
            worst_equation: None,
            before: Vec::new(),
            suggestions: Vec::new(),
            last_converged_step: step,
            last_converged_time: time,
            message: error.to_string(),
        };
        if let E::StepFailed {
            time,
            step,
            dt,
            iterations,
            residuals,
            diagnosis,
            worst_equation,
        } = error
        {
            report.worst_equation = worst_equation.clone();
            report.time = Some(*time);
            report.step = Some(*step);
            report.dt = Some(*dt);
            report.iterations = Some(*iterations);
            report.residuals = residuals.clone();
            report.diagnosis = diagnosis.clone();
        }
        report
    }
}

/// The unit system of every number in the run folder.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnitsSummary {
    /// `SI` or `mm-N-MPa`.
    pub system: String,
    /// Length unit.
    pub length: String,
    /// Force unit.
    pub force: String,
    /// Stress unit.
    pub stress: String,
    /// Moment unit.
    pub moment: String,
    /// Time unit (always s).
    pub time: String,
    /// Temperature unit (always °C).
    pub temperature: String,
}

impl UnitsSummary {
    /// The units of `model`.
    pub fn of(model: &Model) -> Self {
        let u = model.units;
        Self {
            system: u.name().into(),
            length: u.length().into(),
            force: u.force().into(),
            stress: u.stress().into(),
            moment: u.moment().into(),
            time: "s".into(),
            temperature: "°C".into(),
        }
    }
}

/// Where the wall time went \[s\]. `recording` splits the time spent in each output during the run; `solver`
/// splits the solver's share (residual and tangent assembly, factorisation, solves, material updates: seconds
/// as `<part>_s`, counts as `<part>_count`).
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Timing {
    /// Reading the design, building the model and the discretisation, creating the outputs.
    pub setup_s: Real,
    /// Time stepping, including the outputs recorded during it.
    pub run_s: Real,
    /// Time spent in each output during the run (`history`, `snapshots`, `mcap`, `charts`).
    pub recording: BTreeMap<String, Real>,
    /// Writing the final snapshot, closing the recording and drawing the charts.
    pub finish_s: Real,
    /// The solver's own split ([`crate::solver::SolverTiming::entries`]).
    pub solver: BTreeMap<String, Real>,
}

/// One snapshot as listed in the summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SnapshotEntry {
    /// Step (0: initial state).
    pub step: usize,
    /// Time \[s\].
    pub time: Real,
    /// Its phase in the shape-memory cycle ([`crate::model::cycle::Phase`]: `programmed`, `fixed`, …), when
    /// the model has a cycle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase: Option<String>,
    /// Its files relative to the run folder by extension: `"stl"`, `"obj"` ([`crate::io::formats::FORMATS`])
    /// and `"vtp"` (the fields for ParaView, [`crate::io::vtk`]).
    #[serde(flatten)]
    pub files: std::collections::BTreeMap<String, String>,
    /// Triangles.
    pub triangles: usize,
    /// Enclosed volume \[length³\].
    pub volume: Real,
}

impl From<&Snapshot> for SnapshotEntry {
    fn from(s: &Snapshot) -> Self {
        Self {
            step: s.step,
            time: s.time,
            phase: s.phase.map(|p| p.name().to_string()),
            files: s
                .files
                .iter()
                .map(|path| {
                    let extension = path
                        .extension()
                        .map_or_else(String::new, |e| e.to_string_lossy().into_owned());
                    (extension, path.display().to_string())
                })
                .collect(),
            triangles: s.triangles,
            volume: s.volume,
        }
    }
}

/// The last recorded state.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FinalState {
    /// Step.
    pub step: usize,
    /// Time \[s\].
    pub time: Real,
    /// Temperature [°C].
    pub temperature: Real,
    /// Displacement `[ux, uy, uz]` of every probe \[length\].
    pub probes: BTreeMap<String, [Real; 3]>,
    /// Mean recovery ratio (programmes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub recovery_ratio_mean: Option<Real>,
    /// Largest recovery ratio (programmes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub recovery_ratio_max: Option<Real>,
    /// Mean radial contraction \[length\] (radial-contraction programmes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_r: Option<Real>,
}

impl FinalState {
    /// The summary of `sample`.
    pub fn of(model: &Model, sample: &StateSample) -> Self {
        Self {
            step: sample.step,
            time: sample.time,
            temperature: sample.temperature,
            probes: model
                .probes
                .iter()
                .zip(&sample.probes)
                .map(|(p, u)| (p.name.clone(), [u.x, u.y, u.z]))
                .collect(),
            recovery_ratio_mean: sample.recovery.as_ref().map(|r| r.ratio_mean),
            recovery_ratio_max: sample.recovery.as_ref().map(|r| r.ratio_max),
            delta_r: sample.recovery.as_ref().and_then(|r| r.delta_r),
        }
    }
}

/// Files of the run folder besides the snapshots.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Files {
    /// The history CSV.
    pub history: String,
    /// The MCAP recording.
    pub mcap: String,
    /// Its size in bytes.
    pub mcap_bytes: u64,
    /// The charts.
    pub charts: Vec<String>,
}

/// The content of `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunSummaryFile {
    /// Design name.
    pub design: String,
    /// The design file as given on the command line.
    pub design_file: String,
    /// The fingerprint of the model that ran ([`model_fingerprint_text`]): `stentkit export` checks the design
    /// it re-runs against it.
    pub model_fingerprint: String,
    /// The `--set` overrides applied to it, as given.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub overrides: Vec<String>,
    /// The design that ran, when overrides changed the file's: the resolved YAML.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resolved_design: Option<String>,
    /// stentkit's version.
    pub stentkit_version: String,
    /// The command line.
    pub command_line: String,
    /// Units of every number in the run folder.
    pub units: UnitsSummary,
    /// How the run ended (`running` while it runs).
    pub status: RunStatus,
    /// When this summary was written (UTC, RFC 3339): a `running` summary much older than a few seconds
    /// belongs to a run that was killed.
    pub updated: String,
    /// Why it stopped or failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The failure report of a run whose solver failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<FailureReport>,
    /// Wall time of the whole command \[s\].
    pub wall_time_s: Real,
    /// Peak resident memory of the process \[MiB\] (Linux `VmHWM`; absent elsewhere).
    pub peak_memory_mib: Option<Real>,
    /// Its split.
    pub timing: Timing,
    /// Converged steps.
    pub steps: usize,
    /// Newton iterations over all steps.
    pub newton_iterations: usize,
    /// Mean Newton iterations per step.
    pub iterations_per_step: Real,
    /// Step cuts.
    pub step_cuts: usize,
    /// Error-controlled stepping, when the design asks for it (`time.tolerance`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_error_control: Option<TimeErrorControl>,
    /// Automatic stabilisation, when the design asks for it (`solver.stabilisation`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stabilisation: Option<StabilisationSummary>,
    /// Time reached \[s\].
    pub final_time: Real,
    /// End time of the design \[s\].
    pub end_time: Real,
    /// Nominal time step \[s\].
    pub time_step: Real,
    /// Patches of the (possibly reduced) model.
    pub patches: usize,
    /// Collocation points.
    pub collocation_points: usize,
    /// Unknowns of the global system.
    pub unknowns: usize,
    /// Symmetry planes the exports mirror about.
    pub symmetry_planes: usize,
    /// The snapshots written.
    pub snapshots: Vec<SnapshotEntry>,
    /// Other files.
    pub files: Files,
    /// Which outputs are complete, when some could not be written (e.g. a full disk).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub outputs: Vec<OutputState>,
    /// The last recorded state.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub final_state: Option<FinalState>,
    /// Warnings: about the design (as `check` says them), and about the run's result — a stabilisation above
    /// its limit by energy or force, a device that ended heated above its Tg but not recovered
    /// ([`crate::post::recovery::recovery_warning`]). A run with a warning may still be `completed`: its numbers are
    /// the simulation's, and these say why they may not be what was wanted.
    pub warnings: Vec<String>,
    /// Notices of the solver (e.g. relaxation frozen below Tg − C2).
    pub notices: Vec<String>,
    /// Where the wire's surface strain peaked over the run (`history.csv`'s `surface_strain_peak`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_surface_strain: Option<super::history::SurfaceStrainPeak>,
    /// Materials whose `strain_limit` the surface strain exceeded, as `run` said (each once).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub strain_limit_warnings: Vec<String>,
    /// Per obstacle of a model with contact, the peak force and radial force and the largest penetration over
    /// the run, with when (`history.csv`'s contact columns; [`super::contact`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub contact: Vec<super::contact::ObstaclePeaks>,
    /// For a programmed device, how it deployed: recoil, foreshortening and each crown against the lumen
    /// ([`crate::post::deployment`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub deployment: Option<Deployment>,
    /// When and where the device's wires first touched each other, if they did (without the wires' contact,
    /// `contact: {wires: true}`, they may pass through each other from then on; [`crate::solver::terms::crossing`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wire_touch: Option<crate::solver::terms::crossing::WireTouch>,
}

/// How a programmed device deployed (`summary.json` `deployment`; [`crate::post::deployment`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Deployment {
    /// Recoil as the tool let go, once the run reached the end of the let-go.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub recoil: Option<crate::post::deployment::Recoil>,
    /// Foreshortening from the crimped state to the end, once the run went past the let-go.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub foreshortening: Option<crate::post::deployment::Foreshortening>,
    /// Each crown's diameter at the end against the lumen around it.
    pub crowns: Vec<crate::post::deployment::CrownFit>,
}

/// What error-controlled stepping did (`summary.json` `time_error_control`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TimeErrorControl {
    /// The time-error tolerance asked (normalised as Newton's increments).
    pub tolerance: Real,
    /// Steps accepted.
    pub accepted_steps: usize,
    /// Attempts rejected because their estimate exceeded the tolerance.
    pub rejected_steps: usize,
    /// States at requested times between the steps (the continuous extension): each a row of `history.csv`
    /// besides the steps' (and a snapshot, at a snapshot time).
    pub requested_states: usize,
    /// The largest estimate of an accepted step (above the tolerance only at the smallest step, with a notice).
    pub largest_estimate: Real,
    /// The smallest step taken \[s\].
    pub smallest_step: Real,
    /// The largest step taken \[s\].
    pub largest_step: Real,
}

/// What automatic stabilisation did (`summary.json` `stabilisation`;
/// [`crate::solver::simulation::stabilisation`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StabilisationSummary {
    /// The dissipated-energy fraction the damping factor aims at.
    pub dissipated_fraction: Real,
    /// The limit on `ratio` above which the run is warned to be not quasi-static.
    pub limit: Real,
    /// Steps taken with the damping on.
    pub damped_steps: usize,
    /// Energy the damping dissipated \[energy\].
    pub dissipated_energy: Real,
    /// The largest strain energy of the run's states \[energy\].
    pub peak_strain_energy: Real,
    /// `dissipated_energy / peak_strain_energy`.
    pub ratio: Real,
    /// The largest ratio of one step's dissipated energy to the strain energy at its end.
    pub largest_step_ratio: Real,
    /// The largest share of the damping force among the forces on the device (loads, reactions, walls' contact
    /// and the damping) of a damped step: 0 quasi-static, 1 when the damping alone balanced the loads or the motion
    /// ([`crate::solver::simulation::stabilisation`], *The force*).
    pub largest_force_share: Real,
    /// The time of the step with that share \[s\] (0 when no step was damped).
    pub largest_force_share_time: Real,
    /// Damped steps whose force share exceeded `limit`.
    pub steps_above_force_limit: usize,
    /// Whether `ratio` exceeds `limit` (or did at some step) or `largest_force_share` does: the run then says so
    /// in `warnings`.
    pub above_limit: bool,
}

/// A model's fingerprint as summary.json writes it: `v`, the version of the fingerprint's form
/// ([`crate::model::fingerprint::VERSION`]), `-` and 16 hex digits of
/// [`crate::solver::simulation::model_fingerprint`] (`v2-9e2ebac6ae4221be`). The version tells a fingerprint of
/// another form — a summary written by a stentkit that hashed the model otherwise (before version 1: 16 hex
/// digits alone) — from one of another model.
pub(crate) fn model_fingerprint_text(model: &Model) -> String {
    format!(
        "v{}-{:016x}",
        crate::model::fingerprint::VERSION,
        crate::solver::simulation::model_fingerprint(model)
    )
}

impl RunSummaryFile {
    /// The summary of a run of `model` that is starting: `"status": "running"`, nothing done yet.
    pub fn start(
        model: &Model,
        design_file: &str,
        version: &str,
        command_line: &str,
        warnings: Vec<String>,
    ) -> Self {
        Self {
            design: model.name().to_string(),
            design_file: design_file.to_string(),
            model_fingerprint: model_fingerprint_text(model),
            overrides: Vec::new(),
            resolved_design: None,
            stentkit_version: version.to_string(),
            command_line: command_line.to_string(),
            units: UnitsSummary::of(model),
            status: RunStatus::Running,
            updated: String::new(),
            error: None,
            failure: None,
            wall_time_s: 0.0,
            peak_memory_mib: None,
            timing: Timing::default(),
            steps: 0,
            newton_iterations: 0,
            iterations_per_step: 0.0,
            step_cuts: 0,
            time_error_control: model.time().tolerance.map(|tolerance| TimeErrorControl {
                tolerance,
                accepted_steps: 0,
                rejected_steps: 0,
                requested_states: 0,
                largest_estimate: 0.0,
                smallest_step: 0.0,
                largest_step: 0.0,
            }),
            stabilisation: model.solver().stabilisation.map(|s| StabilisationSummary {
                dissipated_fraction: s.dissipated_fraction,
                limit: s.limit,
                damped_steps: 0,
                dissipated_energy: 0.0,
                peak_strain_energy: 0.0,
                ratio: 0.0,
                largest_step_ratio: 0.0,
                largest_force_share: 0.0,
                largest_force_share_time: 0.0,
                steps_above_force_limit: 0,
                above_limit: false,
            }),
            final_time: 0.0,
            end_time: model.time().end,
            time_step: model.time().step,
            patches: model.patches.len(),
            collocation_points: model.num_collocation_points(),
            unknowns: model.num_unknowns(),
            symmetry_planes: model.symmetry_planes.len(),
            snapshots: Vec::new(),
            files: Files {
                history: "history.csv".into(),
                mcap: "run.mcap".into(),
                mcap_bytes: 0,
                charts: Vec::new(),
            },
            outputs: Vec::new(),
            final_state: None,
            warnings,
            notices: Vec::new(),
            peak_surface_strain: None,
            strain_limit_warnings: Vec::new(),
            contact: Vec::new(),
            deployment: None,
            wire_touch: None,
        }
    }

    /// Writes the summary as pretty-printed JSON, atomically (a temporary file renamed over the target), so
    /// that a reader never sees a partial summary.
    ///
    /// # Errors
    /// The I/O error when the file cannot be written.
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        let mut text = serde_json::to_string_pretty(self).map_err(std::io::Error::other)?;
        text.push('\n');
        super::atomic::write_bytes_atomically(path, text.as_bytes())
    }
}

/// Peak resident memory of this process so far \[MiB\]: `VmHWM` of `/proc/self/status` (Linux); `None` where that
/// is not available.
pub(crate) fn peak_memory_mib() -> Option<Real> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: Real = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}
