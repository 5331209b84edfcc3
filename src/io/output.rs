//! The output settings of a run — which snapshot meshes it writes, what `run.mcap` records, the strain
//! limits it warns above — and [`RunDesign`], what the files of a run need of a design. The design language
//! ([`crate::design`]) fills these in from a design's `output:` block; it sits above `io` (it reads centreline
//! files through it), so the writers here name the trait rather than [`crate::design::Design`].

use crate::math::Real;
use crate::model::{Model, StepPlan};
use std::path::Path;

/// Which tube meshes of the full device a run writes (the design's `output.snapshots`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SnapshotSettings {
    /// Requested snapshot times \[time\], sorted, within `[0, end]` (with the history's, the model's record
    /// times: fixed steps land on them, error-controlled steps reach them by their continuous extension).
    pub times: Vec<Real>,
    /// A snapshot every this many converged steps; 0 for none.
    pub every: usize,
    /// A snapshot at each event of the model's cycle ([`crate::model::cycle`]: programmed, fixed, released)
    /// besides the initial and final states (`output.snapshots.events`, default true).
    pub events: bool,
    /// Snapshots between the events: the run, cut at its events, is divided into about this many equal pieces
    /// ([`crate::io::snapshots::SnapshotSchedule`]); 0 for none. Default [`Self::DEFAULT_BETWEEN`] when the
    /// design sets neither `every` nor `times`.
    pub between: usize,
    /// The file formats, by extension, in the registry's order (`crate::io::formats`; default STL only).
    pub formats: Vec<&'static str>,
    /// Vertices around each tube section.
    pub segments: usize,
    /// Rings (sections) along each patch, about: every k-th of the samples taken at a whole number of samples
    /// per control point, the ends always included ([`crate::post::device::current_device_shapes`]).
    pub rings: usize,
    /// With every snapshot, the fields along the rods for ParaView (`output.vtk`, default true;
    /// [`crate::io::vtk`]).
    pub vtk: bool,
    /// The views of the configuration figures (`output.configurations.views`); `None`: the defaults
    /// (`crate::io::configurations::default_views`).
    pub views: Option<Vec<crate::io::configurations::View>>,
    /// A shaded picture of the configuration figures' states (`output.configurations.render`, default true;
    /// `crate::io::render`).
    pub render: bool,
}

impl SnapshotSettings {
    /// Default number of periodic snapshots over an arc-length path, which has no times to place them at:
    /// `every = ⌈increments / 20⌉`.
    pub const DEFAULT_COUNT: usize = 20;
    /// Default pieces between the events ([`Self::between`]): 6. With the events this gives the straight stent 8
    /// snapshots (t = 0, 0.5, 1 programmed, 1.75 fixed, 1.7525 released, 2.2525, 2.7525, 3.25 final), a
    /// 58 MB folder with the recording, which holds every step besides.
    pub const DEFAULT_BETWEEN: usize = 6;
    /// Default vertices around a section: 12, the section polygon has 95.5 % of the circle's area (16 would
    /// have 97.4 %, in files a third larger). A snapshot is a preview: `stentkit mesh` writes finer ones.
    pub const DEFAULT_SEGMENTS: usize = 12;
    /// Default rings per patch: 41, about one per wire diameter along a crown wire of the paper's stents
    /// (the full straight stent at 12 segments: 100 000 triangles, 5 MB of binary STL), whatever the patch's
    /// `n`.
    pub const DEFAULT_RINGS: usize = 41;
}

/// What `run.mcap` records (the design's `output.recording`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RecordingSettings {
    /// Whether `run.mcap` is written at all.
    pub enabled: bool,
    /// Points per patch of the centrelines recorded every step (about: every k-th point of one sample per
    /// control point, the ends always included).
    pub centreline_points: usize,
    /// Whether the tube meshes are recorded at snapshot steps.
    pub meshes: bool,
    /// Vertices around each section of a recorded mesh.
    pub mesh_segments: usize,
    /// Rings per patch of a recorded mesh, about.
    pub mesh_rings: usize,
}

impl RecordingSettings {
    /// Default centreline points per patch: 21 (one per control point of the paper's n = 20 patches). The
    /// centrelines are recorded at every step, so they dominate the file size: the straight stent's run gives
    /// a recording of about 20 MB.
    pub const DEFAULT_CENTRELINE_POINTS: usize = 21;
    /// Default vertices around a recorded section: 8, enough to see a round wire in Foxglove.
    pub const DEFAULT_MESH_SEGMENTS: usize = 8;
    /// Default rings per patch of a recorded mesh: 21.
    pub const DEFAULT_MESH_RINGS: usize = 21;
}

/// The validated `output:` block besides the probes (which are part of the model).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct OutputSettings {
    /// Snapshot meshes.
    pub snapshots: SnapshotSettings,
    /// Times at which `history.csv` has a row besides the steps' (`output.history.times`) \[time\], sorted,
    /// within `[0, end]`: with the snapshot times, the model's record times.
    pub history_times: Vec<Real>,
    /// The MCAP recording.
    pub recording: RecordingSettings,
    /// Per material of the model (`material` first, then `materials`), the surface strain it survives
    /// (`strain_limit`), which `run` warns above.
    pub strain_limits: Vec<Option<Real>>,
}

/// A design as the files of its run see it: the model, the output settings, the steps planned and the text
/// it was read from ([`crate::design::Design`] is one). The MCAP recording attaches the text; the disk
/// estimate counts the steps.
pub trait RunDesign {
    /// The validated model.
    fn model(&self) -> &Model;
    /// Snapshot and recording settings.
    fn output(&self) -> &OutputSettings;
    /// The steps a run takes when no step is cut ([`Model::planned_steps`]).
    fn steps(&self) -> &StepPlan;
    /// The design's text as read (with `--set` overrides, the resolved design).
    fn source(&self) -> &str;
    /// Where it was read from.
    fn path(&self) -> &Path;
}
