//! Snapshots of a run: the full device as closed tubes swept along the deformed centrelines with the solver's
//! section frames, written in the design's formats (`super::formats`; binary STL by default, OBJ on request)
//! at the initial state, at the final one, at the events of the shape-memory cycle ([`crate::model::cycle`]:
//! programmed, fixed, released), at a few times between them, every `every` steps and at the requested times
//! (they are the model's record times: fixed steps land on them, and an error-controlled run reaches each by its
//! continuous extension, [`Observer::requested`]). Each is named by its time and phase,
//! `snapshots/t1.750_fixed.stl` ([`snapshot_name`]). With each snapshot, unless the design turns them off, the
//! fields along the rods for ParaView (`.vtp`, [`super::vtk`], listed with their times in `run.pvd`); and the
//! full device's centrelines are kept for the configuration figures drawn at the end (`super::configurations`).

use super::chart::ChartError;
use super::configurations::{self, CENTRELINE_SAMPLES, Configuration};
use super::mesh_format::{MeshFormat, SnapshotState};
use super::output::SnapshotSettings;
use super::run_folder::Manifest;
use super::stl::MeshIoError;
use super::{formats, render, stl, vtk};
use crate::geometry::device_tubes::DeviceMeshError;
use crate::geometry::mesh::TriangleMesh;
use crate::math::Real;
use crate::model::Model;
use crate::model::cycle::Phase;
use crate::post::device::{
    current_device_shapes, decimated, device_centrelines, device_tube_mesh, reference_patch_shapes,
    samples_per_point,
};
use crate::solver::{Observer, Simulation, StepReport};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

/// Decides which states get a snapshot (shared by the snapshot files and the meshes of the recording).
#[derive(Debug, Clone, PartialEq)]
pub struct SnapshotSchedule {
    /// The times due, sorted: the requested ones, the cycle's events, the cuts between them.
    times: Vec<Real>,
    /// The requested times (`output.snapshots.times`), sorted.
    requested: Vec<Real>,
    /// Every this many steps (0: never).
    every: usize,
    /// End time of the run.
    end: Real,
    /// Times closer than this are equal: the solver's landing tolerance ([`crate::model::LANDING_TOLERANCE`] of
    /// the nominal step).
    snap: Real,
}

impl SnapshotSchedule {
    /// The schedule of a design's snapshot settings for its model.
    pub fn new(settings: &SnapshotSettings, model: &Model) -> Self {
        let snap = model.time().landing_tolerance();
        let requested = settings.times.clone();
        // An error-controlled run reaches the requested times between its steps (its continuous extension): they
        // are not "the first step at or after".
        let mut times = if model.time().tolerance.is_some() {
            Vec::new()
        } else {
            requested.clone()
        };
        // An arc-length path's `time` is its path parameter, which passes `time.end` anywhere: its last state
        // is written by the writers' `finish`, and it has neither events nor times between them.
        let end = match model.solver().path.arc_length() {
            None => {
                let events: Vec<Real> = model.events().iter().map(|&(t, _)| t).collect();
                if settings.events {
                    times.extend(&events);
                }
                times.extend(between_events(&events, settings.between));
                model.time().end
            }
            Some(_) => Real::INFINITY,
        };
        times.sort_by(Real::total_cmp);
        times.dedup_by(|a, b| (*a - *b).abs() <= snap);
        Self {
            times,
            requested,
            every: settings.every,
            end,
            snap,
        }
    }

    /// The times due (sorted), besides step 0, the end, every `every` steps and the requested times: the first
    /// step at or after each gets a snapshot.
    pub fn times(&self) -> &[Real] {
        &self.times
    }

    /// The requested times (`output.snapshots.times`), sorted: among [`Self::times`] with fixed steps; an
    /// error-controlled run reaches them between its steps.
    pub fn requested(&self) -> &[Real] {
        &self.requested
    }

    /// Whether `time` is a requested snapshot time (within the landing tolerance).
    pub fn is_requested(&self, time: Real) -> bool {
        crate::math::near_one_of(&self.requested, time, self.snap)
    }

    /// Whether the state of step `step` at `time`, reached from `previous` (the time of the step before),
    /// gets a snapshot: step 0 and the end always; every `every` steps; a step on a requested time; and the
    /// first step at or after each time due (which is the step landing on it, for requested times with fixed
    /// steps and for events). (A requested time inside a step of an error-controlled run is the continuous
    /// extension's state, [`Observer::requested`], not a step's.)
    pub fn is_due(&self, step: usize, previous: Real, time: Real) -> bool {
        step == 0
            || (self.every > 0 && step.is_multiple_of(self.every))
            || time >= self.end - self.snap
            || self.is_requested(time)
            || self
                .times
                // Sorted: the first time due after `previous` decides (one binary search per step).
                .get(self.times.partition_point(|&t| t <= previous + self.snap))
                .is_some_and(|&t| t <= time + self.snap)
    }
}

/// The times between `events` (sorted, the first 0 and the last the end of the run) that divide the run into
/// about `pieces` equal pieces: each interval between two events into `max(1, round(pieces · length / run))`
/// equal parts.
fn between_events(events: &[Real], pieces: usize) -> Vec<Real> {
    let (Some(first), Some(last)) = (events.first(), events.last()) else {
        return Vec::new();
    };
    let run = last - first;
    if pieces == 0 || run <= 0.0 {
        return Vec::new();
    }
    events
        .windows(2)
        .flat_map(|w| {
            let (a, b) = (w[0], w[1]);
            let parts = ((pieces as Real * (b - a) / run).round() as usize).max(1);
            (1..parts).map(move |k| a + (b - a) * k as Real / parts as Real)
        })
        .collect()
}

/// What a snapshot's name ([`snapshot_name`], without extension) says of it: its step (`step_00012`) or its
/// time as written (`t1.750_fixed`), and its phase.
pub fn parse_snapshot_name(name: &str) -> Option<(SnapshotAt, Option<Phase>)> {
    if let Some(step) = name.strip_prefix("step_") {
        return Some((SnapshotAt::Step(step.parse().ok()?), None));
    }
    let (time, phase) = match name.strip_prefix('t')?.split_once('_') {
        Some((time, phase)) => (time, Phase::parse(phase)),
        None => (name.strip_prefix('t')?, None),
    };
    Some((SnapshotAt::Time(time.parse().ok()?), phase))
}

/// Where a snapshot's name places it ([`parse_snapshot_name`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SnapshotAt {
    /// The step (an arc-length path's names).
    Step(usize),
    /// The time, to the name's decimals (at least three, at most six: within 5e-7 of the state's).
    Time(Real),
}

/// The name of the snapshot of step `step` at `time` in `phase` of the model's cycle (without extension): its
/// time with at least three decimals and its phase, `t1.750_fixed` (`t0.500` without a phase), or
/// `step_00012` on an arc-length path, whose `time` is the path parameter.
pub fn snapshot_name(model: &Model, step: usize, time: Real, phase: Option<Phase>) -> String {
    if model.solver().path.arc_length().is_some() {
        return format!("step_{step:05}");
    }
    // The fewest decimals, at least three, that write the time exactly (to 1e-9 of it): 1.750, 1.7525.
    let decimals = (3..=6)
        .find(|&d| {
            let scale = Real::powi(10.0, d);
            ((time * scale).round() / scale - time).abs() <= 1e-9 * time.abs().max(1.0)
        })
        .unwrap_or(6) as usize;
    match phase {
        Some(phase) => format!("t{time:.decimals$}_{phase}"),
        None => format!("t{time:.decimals$}"),
    }
}

/// One written snapshot.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Step number (0: the initial state).
    pub step: usize,
    /// Time \[time\].
    pub time: Real,
    /// Its phase in the model's cycle ([`Model::phase_at`]).
    pub phase: Option<Phase>,
    /// Its files relative to the run folder, one per format of the design in the registry's order
    /// (`super::formats::FORMATS`), each with its format's extension, then the fields for ParaView (`.vtp`)
    /// when the design writes them.
    pub files: Vec<PathBuf>,
    /// Triangles of the mesh.
    pub triangles: usize,
    /// Enclosed volume \[length³\].
    pub volume: Real,
}

/// The ParaView collection of a run's field files, in the run folder ([`vtk::collection`]).
pub const COLLECTION_FILE: &str = super::run_folder::COLLECTION_FILE;

/// The file of the vessel's lumen in the snapshot folder (a stent on a centreline read from a file).
pub const VESSEL_FILE: &str = "vessel_lumen.stl";

/// Why a snapshot could not be written.
#[derive(Debug, thiserror::Error)]
pub enum SnapshotError {
    /// The snapshot folder could not be created.
    #[error("cannot create {path}: {source}")]
    Folder {
        /// The folder.
        path: PathBuf,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },
    /// The deformed tubes could not be built (e.g. a section turned into the centreline). The cause is the
    /// error's source, not part of its message: error chains print it once.
    #[error("step {step} (t = {}): patch `{patch}`", crate::math::Short(*time))]
    Mesh {
        /// Step.
        step: usize,
        /// Time.
        time: Real,
        /// Patch name.
        patch: String,
        /// What failed.
        #[source]
        source: crate::geometry::tube::TubeError,
    },
    /// A file could not be written.
    #[error(transparent)]
    Write(#[from] MeshIoError),
    /// A field file for ParaView (or their collection) could not be written.
    #[error("cannot write {path}: {source}")]
    Fields {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },
    /// The run folder's manifest could not list the snapshot's files.
    #[error("cannot list a snapshot in the run folder's manifest: {0}")]
    Manifest(std::io::Error),
}

/// The full device's tube mesh in the current state of `sim`, with `segments` vertices around and about
/// `rings` rings per patch.
///
/// # Errors
/// `DeviceMeshError` naming the patch index that cannot be swept.
pub fn current_device_mesh(
    sim: &Simulation<'_>,
    segments: usize,
    rings: usize,
) -> Result<TriangleMesh, DeviceMeshError> {
    let shapes = current_device_shapes(sim, rings);
    device_tube_mesh(sim.model(), &shapes, segments)
}

/// Writes the snapshots of a run as the simulation reports its steps.
pub struct SnapshotWriter {
    /// The run folder (file names in [`Snapshot`] are relative to it).
    run_dir: PathBuf,
    schedule: SnapshotSchedule,
    /// The times the design lists (`output.snapshots.times`): the configuration figures show these.
    requested: Vec<Real>,
    segments: usize,
    rings: usize,
    /// The formats each snapshot is written in.
    formats: Vec<&'static dyn MeshFormat>,
    /// The model's cycle, which names the snapshots.
    phases: crate::model::cycle::Phases,
    /// Time and step of the last state seen.
    last: Option<(usize, Real)>,
    written: Vec<Snapshot>,
    error: Option<SnapshotError>,
    /// The run folder's manifest, which lists each file before it is written.
    manifest: Option<Manifest>,
    /// Whether each snapshot also writes the fields for ParaView ([`vtk`]) and `run.pvd` lists them.
    vtk: bool,
    /// Whether `run.pvd` is listed in the manifest yet.
    collection_claimed: bool,
    /// The centrelines at every snapshot written by this process.
    configurations: Vec<Configuration>,
    /// The views of the configuration figures (`None`: the defaults).
    views: Option<Vec<configurations::View>>,
    /// Whether the configuration figures' states are also rendered (`charts/configurations.png`).
    render: bool,
}

impl SnapshotWriter {
    /// Folder of the snapshots inside the run folder.
    pub const FOLDER: &'static str = super::run_folder::SNAPSHOTS_FOLDER;

    /// Creates `run_dir/snapshots`.
    ///
    /// # Errors
    /// [`SnapshotError::Folder`] when the folder cannot be created.
    pub fn create(
        run_dir: &Path,
        settings: &SnapshotSettings,
        model: &Model,
    ) -> Result<Self, SnapshotError> {
        let folder = run_dir.join(Self::FOLDER);
        std::fs::create_dir_all(&folder).map_err(|source| SnapshotError::Folder {
            path: folder.clone(),
            source,
        })?;
        Ok(Self {
            run_dir: run_dir.to_path_buf(),
            schedule: SnapshotSchedule::new(settings, model),
            requested: settings.times.clone(),
            segments: settings.segments,
            rings: settings.rings,
            formats: settings
                .formats
                .iter()
                .filter_map(|e| formats::format(e))
                .collect(),
            phases: model.phases(),
            last: None,
            written: Vec::new(),
            error: None,
            manifest: None,
            vtk: settings.vtk,
            collection_claimed: false,
            configurations: Vec::new(),
            views: settings.views.clone(),
            render: settings.render,
        })
    }

    /// Lists every snapshot file in `manifest` before writing it (a run folder's files, see
    /// `crate::io::run_folder`).
    pub fn with_manifest(mut self, manifest: Manifest) -> Self {
        self.manifest = Some(manifest);
        self
    }

    /// The snapshots written so far.
    pub fn snapshots(&self) -> &[Snapshot] {
        &self.written
    }

    /// The last state seen `(step, time)`, for a checkpoint.
    pub fn last_seen(&self) -> Option<(usize, Real)> {
        self.last
    }

    /// Continues the snapshots of a resumed run: the snapshots written up to its checkpoint (whose files are in
    /// the run folder) and the last state it saw.
    pub fn resumed(mut self, written: Vec<Snapshot>, last: Option<(usize, Real)>) -> Self {
        self.written = written;
        self.last = last;
        self
    }

    /// The first error, if any (writing stops there and the run is asked to stop).
    pub fn take_error(&mut self) -> Option<SnapshotError> {
        self.error.take()
    }

    /// Writes the final snapshot of a run that ended (or stopped, or failed) at a step without one.
    ///
    /// # Errors
    /// As the snapshots during the run.
    pub fn finish(&mut self, sim: &Simulation<'_>) -> Result<(), SnapshotError> {
        if let Some((step, _)) = self.last
            && self.written.last().is_none_or(|s| s.step != step)
        {
            self.write(sim, step)?;
        }
        Ok(())
    }

    fn write(&mut self, sim: &Simulation<'_>, step: usize) -> Result<(), SnapshotError> {
        let model = sim.model();
        let time = sim.time();
        let mesh = current_device_mesh(sim, self.segments, self.rings).map_err(|e| {
            SnapshotError::Mesh {
                step,
                time,
                patch: model.patches[e.rod].name.clone(),
                source: e.source,
            }
        })?;
        let phase = self.phases.at(time);
        let name = self.unique_name(snapshot_name(model, step, time, phase), step);
        let files: Vec<PathBuf> = self
            .formats
            .iter()
            .map(|f| Path::new(Self::FOLDER).join(format!("{name}.{}", f.extension())))
            .collect();
        if let Some(manifest) = &self.manifest {
            for path in &files {
                manifest.claim(path).map_err(SnapshotError::Manifest)?;
            }
        }
        let state = SnapshotState { model, step, time };
        for (format, path) in self.formats.iter().zip(&files) {
            format.write(&self.run_dir.join(path), &mesh, &state)?;
        }
        let mut files = files;
        if self.vtk {
            let path = Path::new(Self::FOLDER).join(format!("{name}.vtp"));
            if let Some(manifest) = &self.manifest {
                manifest.claim(&path).map_err(SnapshotError::Manifest)?;
            }
            let target = self.run_dir.join(&path);
            vtk::write_polydata(
                &target,
                model,
                &sim.point_fields(),
                sim.contact().as_ref(),
                sim.wire_contact().as_ref(),
                &sim.probe_points(),
                time,
            )
            .map_err(|source| SnapshotError::Fields {
                path: target,
                source,
            })?;
            files.push(path);
        }
        if self.written.is_empty() {
            self.write_vessel(model)?;
        }
        self.written.push(Snapshot {
            step,
            time,
            phase,
            files,
            triangles: mesh.triangles.len(),
            volume: mesh.volume(),
        });
        if self.vtk {
            self.write_collection()?;
        }
        self.configurations.push(Configuration {
            time,
            temperature: model.temperature().value(sim.schedule_time()),
            lines: device_centrelines(model, &current_device_shapes(sim, CENTRELINE_SAMPLES)),
        });
        Ok(())
    }

    /// `name`, or `name_stepN` when an earlier snapshot has it (times closer than a microsecond apart, as step
    /// cuts can make them).
    fn unique_name(&self, name: String, step: usize) -> String {
        let taken = self.written.iter().any(|s| {
            s.files
                .first()
                .and_then(|f| f.file_stem())
                .is_some_and(|stem| stem == name.as_str())
        });
        if taken {
            format!("{name}_step{step}")
        } else {
            name
        }
    }

    /// Draws the configuration figures (`crate::io::configurations`) of the snapshots written by this process
    /// into `charts/`, each file listed in the manifest first; returns their paths relative to the run folder.
    ///
    /// # Errors
    /// [`ChartError`] when the initial shape cannot be sampled, a figure drawn or a file written.
    pub fn write_configuration_figures(&self, model: &Model) -> Result<Vec<PathBuf>, ChartError> {
        let title = |message: String| ChartError::Drawing {
            title: format!("{}: configurations", model.name()),
            message,
        };
        let shapes = reference_patch_shapes(model, samples_per_point(model, CENTRELINE_SAMPLES))
            .map_err(|(k, e)| title(format!("patch `{}`: {e}", model.patches[k].name)))?;
        let shapes: Vec<_> = shapes
            .iter()
            .map(|s| decimated(s, CENTRELINE_SAMPLES))
            .collect();
        let initial = Configuration {
            time: 0.0,
            temperature: model.temperature().value(0.0),
            lines: device_centrelines(model, &shapes),
        };
        let times: Vec<Real> = self.configurations.iter().map(|c| c.time).collect();
        let picked = configurations::chosen_indices(&times, &self.requested, self.schedule.snap);
        if picked.is_empty() {
            return Ok(Vec::new());
        }
        let rows: Vec<&Configuration> = picked.iter().map(|&k| &self.configurations[k]).collect();
        let views = self
            .views
            .clone()
            .unwrap_or_else(|| configurations::default_views(&initial.lines));
        let charts = Path::new(super::run_charts::RunCharts::FOLDER);
        let folder = self.run_dir.join(charts);
        std::fs::create_dir_all(&folder).map_err(|source| ChartError::Io {
            path: folder.clone(),
            source,
        })?;
        let claim = |path: &Path| match &self.manifest {
            Some(manifest) => manifest.claim(path),
            None => Ok(()),
        };
        let mut files = configurations::write(
            &folder,
            charts,
            (model.name(), model.units.length()),
            &initial,
            &rows,
            &views,
            claim,
        )?;
        if self.render
            && let Some((initial, states)) = self
                .stl_files(&picked)
                .as_deref()
                .and_then(<[_]>::split_first)
        {
            let lumen = self.run_dir.join(Self::FOLDER).join(VESSEL_FILE);
            let path = charts.join("configurations.png");
            claim(&path).map_err(|e| title(e.to_string()))?;
            let pixmap = render::render_snapshots(
                initial,
                states,
                lumen.exists().then_some(lumen.as_path()),
                views[0],
                render::PANEL_WIDTH,
            )
            .map_err(|e| title(e.to_string()))?;
            render::write_png(&self.run_dir.join(&path), &pixmap)
                .map_err(|e| title(e.to_string()))?;
            files.push(path);
        }
        Ok(files)
    }

    /// The STL files of the initial snapshot (step 0, also after `--resume`) and of the configurations
    /// `picked` (indices into those of this process); `None` when a snapshot has no STL.
    fn stl_files(&self, picked: &[usize]) -> Option<Vec<PathBuf>> {
        // The snapshots of this process are the last of those written (a resumed run lists earlier ones).
        let first = self.written.len() - self.configurations.len();
        let stl = |k: usize| {
            let files = &self.written.get(k)?.files;
            let stl = files
                .iter()
                .find(|f| f.extension().is_some_and(|e| e == "stl"))?;
            Some(self.run_dir.join(stl))
        };
        std::iter::once(0)
            .chain(picked.iter().map(|&k| first + k))
            .map(stl)
            .collect()
    }

    /// Rewrites `run.pvd`, the ParaView collection of the field files written so far with their times.
    fn write_collection(&mut self) -> Result<(), SnapshotError> {
        let entries: Vec<(Real, String)> = self
            .written
            .iter()
            .flat_map(|s| {
                s.files
                    .iter()
                    .filter(|f| f.extension().is_some_and(|e| e == "vtp"))
                    .map(|f| (s.time, f.to_string_lossy().into_owned()))
            })
            .collect();
        let path = Path::new(COLLECTION_FILE);
        if !self.collection_claimed {
            if let Some(manifest) = &self.manifest {
                manifest.claim(path).map_err(SnapshotError::Manifest)?;
            }
            self.collection_claimed = true;
        }
        let target = self.run_dir.join(path);
        vtk::write_collection(&target, &entries).map_err(|source| SnapshotError::Fields {
            path: target,
            source,
        })
    }

    /// With the first snapshot: the lumen of the vessel the stent sits on, `snapshots/vessel_lumen.stl` (a
    /// closed tube of the file's lumen radius around the smoothed centreline, [`crate::post::vessel`]).
    fn write_vessel(&mut self, model: &Model) -> Result<(), SnapshotError> {
        let Some(lumen) = model
            .vessel
            .as_ref()
            .and_then(|v| crate::post::vessel::lumen_mesh(v, self.segments))
        else {
            return Ok(());
        };
        let mesh = lumen.map_err(|source| SnapshotError::Mesh {
            step: 0,
            time: 0.0,
            patch: "vessel lumen".into(),
            source,
        })?;
        let path = Path::new(Self::FOLDER).join(VESSEL_FILE);
        if let Some(manifest) = &self.manifest {
            manifest.claim(&path).map_err(SnapshotError::Manifest)?;
        }
        let header = format!(
            "{} vessel lumen, lengths in {}",
            model.name(),
            model.units.length()
        );
        Ok(stl::write_stl_with_header(
            &self.run_dir.join(&path),
            &mesh,
            &header,
        )?)
    }

    fn observe(&mut self, sim: &Simulation<'_>, step: usize) -> ControlFlow<()> {
        let previous = self.last.map_or(0.0, |(_, t)| t);
        self.last = Some((step, sim.time()));
        if self.error.is_some() {
            return ControlFlow::Break(());
        }
        if !self.schedule.is_due(step, previous, sim.time()) {
            return ControlFlow::Continue(());
        }
        match self.write(sim, step) {
            Ok(()) => ControlFlow::Continue(()),
            Err(e) => {
                self.error = Some(e);
                ControlFlow::Break(())
            }
        }
    }
}

impl Observer for SnapshotWriter {
    fn start(&mut self, sim: &Simulation<'_>) -> ControlFlow<()> {
        self.observe(sim, 0)
    }

    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        self.observe(sim, report.step)
    }

    /// A requested snapshot time inside a step of an error-controlled run: the snapshot is the continuous
    /// extension's state there, with the step before it. (The steps' schedule is not changed by it: the last
    /// state seen stays the last step's.) A requested history time alone writes nothing here.
    fn requested(&mut self, sim: &Simulation<'_>, _: &StepReport) {
        let time = sim.time();
        if self.error.is_some() || !self.schedule.is_requested(time) {
            return;
        }
        if let Err(e) = self.write(sim, sim.step_count()) {
            // (Kept: the next step asks the run to stop.)
            self.error = Some(e);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_run_is_cut_between_its_events_in_proportion() {
        // The straight stent's events (0, 1, 1.75, 1.7525, 3.25) in 6 pieces: the intervals get
        // round(6 · length / 3.25) = 2, 1, 1 (at least one) and 3 parts.
        let cuts = between_events(&[0.0, 1.0, 1.75, 1.7525, 3.25], 6);
        let expected = [0.5, 1.7525 + 1.4975 / 3.0, 1.7525 + 2.0 * 1.4975 / 3.0];
        assert_eq!(cuts.len(), expected.len(), "{cuts:?}");
        for (c, e) in cuts.iter().zip(expected) {
            assert!((c - e).abs() < 1e-12, "{cuts:?}");
        }
        assert!(between_events(&[0.0, 1.0], 0).is_empty());
        assert!(between_events(&[0.0], 6).is_empty());
    }

    #[test]
    fn snapshot_names_read_back() {
        assert_eq!(
            parse_snapshot_name("t1.7525_released"),
            Some((SnapshotAt::Time(1.7525), Some(Phase::Released)))
        );
        assert_eq!(
            parse_snapshot_name("t0.500"),
            Some((SnapshotAt::Time(0.5), None))
        );
        assert_eq!(
            parse_snapshot_name("step_00012"),
            Some((SnapshotAt::Step(12), None))
        );
        assert_eq!(parse_snapshot_name("vessel_lumen"), None);
    }
}
