//! Snapshots of a run: the full device as closed tubes swept along the deformed centrelines with the solver's
//! section frames, written in every registered [`MeshFormat`] — binary STL and OBJ (`snapshots/step_NNNNN.stl`,
//! `.obj`) — at the initial state, at the final one, every `every` steps and at the requested times (time
//! stepping lands on those: they are the model's record times). With each snapshot, unless the design turns
//! them off, the fields along the rods for ParaView (`snapshots/step_NNNNN.vtp`, [`super::vtk`], listed with
//! their times in `run.pvd`); and the full device's centrelines are kept for the configuration figures drawn at
//! the end ([`super::configurations`]).
//!
//! **A new snapshot file format is a new module plus one registration line**: write `io/<format>.rs` with a
//! type implementing [`MeshFormat`] (in [`super::mesh_format`]: its extension and how it writes a mesh), declare the module in `io/mod.rs`,
//! and add the type to [`FORMATS`]. Each snapshot then lists its file under the extension as key in
//! summary.json, the run folder's manifest claims it, and `--resume` keeps or rewrites it with the others.

use super::chart::ChartError;
use super::configurations::{self, CENTRELINE_SAMPLES, Configuration};
use super::design::SnapshotSettings;
use super::mesh_format::{MeshFormat, SnapshotState};
use super::run_folder::Manifest;
use super::stl::MeshIoError;
use super::{obj, render, stl, vtk};
use crate::geometry::device_tubes::DeviceMeshError;
use crate::geometry::mesh::TriangleMesh;
use crate::math::Real;
use crate::model::Model;
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
    /// Requested times, sorted.
    times: Vec<Real>,
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
        Self {
            times: settings.times.clone(),
            every: settings.every,
            // An arc-length path's `time` is its path parameter, which passes `time.end` anywhere: its last state
            // is written by the writers' `finish`.
            end: match model.solver.path.arc_length() {
                None => model.time.end,
                Some(_) => Real::INFINITY,
            },
            snap: crate::model::LANDING_TOLERANCE * model.time.step,
        }
    }

    /// Whether the state of step `step` at `time`, reached from `previous` (the time of the step before),
    /// gets a snapshot: step 0 and the end always; every `every` steps; and the first step at or after each
    /// requested time (which is the step landing on it).
    pub fn is_due(&self, step: usize, previous: Real, time: Real) -> bool {
        step == 0
            || (self.every > 0 && step.is_multiple_of(self.every))
            || time >= self.end - self.snap
            || self
                .times
                // Sorted: the first requested time after `previous` decides (one binary search per step).
                .get(self.times.partition_point(|&t| t <= previous + self.snap))
                .is_some_and(|&t| t <= time + self.snap)
    }
}

/// The formats every snapshot is written in, in this order: the registration list of [`MeshFormat`]s.
pub const FORMATS: &[&dyn MeshFormat] = &[&stl::Stl, &obj::Obj];

/// One written snapshot.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Step number (0: the initial state).
    pub step: usize,
    /// Time [time].
    pub time: Real,
    /// Its files relative to the run folder, one per format of [`FORMATS`] in that order, each with its
    /// format's extension, then the fields for ParaView (`.vtp`) when the design writes them.
    pub files: Vec<PathBuf>,
    /// Triangles of the mesh.
    pub triangles: usize,
    /// Enclosed volume [length³].
    pub volume: Real,
}

/// The ParaView collection of a run's field files, in the run folder ([`vtk::collection`]).
pub const COLLECTION_FILE: &str = "run.pvd";

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
/// [`DeviceMeshError`] naming the patch index that cannot be swept.
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
    segments: usize,
    rings: usize,
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
    pub const FOLDER: &'static str = "snapshots";

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
            segments: settings.segments,
            rings: settings.rings,
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
    /// [`crate::io::run_folder`]).
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
        let name = format!("step_{step:05}");
        let files: Vec<PathBuf> = FORMATS
            .iter()
            .map(|f| Path::new(Self::FOLDER).join(format!("{name}.{}", f.extension())))
            .collect();
        if let Some(manifest) = &self.manifest {
            for path in &files {
                manifest.claim(path).map_err(SnapshotError::Manifest)?;
            }
        }
        let state = SnapshotState { model, step, time };
        for (format, path) in FORMATS.iter().zip(&files) {
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
            files,
            triangles: mesh.triangles.len(),
            volume: mesh.volume(),
        });
        if self.vtk {
            self.write_collection()?;
        }
        self.configurations.push(Configuration {
            time,
            temperature: model.temperature.value(sim.schedule_time()),
            lines: device_centrelines(model, &current_device_shapes(sim, CENTRELINE_SAMPLES)),
        });
        Ok(())
    }

    /// Draws the configuration figures ([`crate::io::configurations`]) of the snapshots written by this process
    /// into `charts/`, each file listed in the manifest first; returns their paths relative to the run folder.
    ///
    /// # Errors
    /// [`ChartError`] when the initial shape cannot be sampled, a figure drawn or a file written.
    pub fn write_configuration_figures(&self, model: &Model) -> Result<Vec<PathBuf>, ChartError> {
        let title = |message: String| ChartError::Drawing {
            title: format!("{}: configurations", model.name),
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
            temperature: model.temperature.value(0.0),
            lines: device_centrelines(model, &shapes),
        };
        let times: Vec<Real> = self.configurations.iter().map(|c| c.time).collect();
        let picked =
            configurations::chosen_indices(&times, &self.schedule.times, self.schedule.snap);
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
            (&model.name, model.units.length()),
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
            model.name,
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
        if self.error.is_some() || !self.schedule.is_due(step, previous, sim.time()) {
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
}
