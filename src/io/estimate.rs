//! What a run of a design will write to disk, estimated before it starts, part by part (DESIGN §7's run
//! folder): the snapshots (binary STL and OBJ of the full device, the field files for ParaView), `run.mcap`,
//! `history.csv`, the charts (the configuration figures among them) and `summary.json`.
//!
//! Everything but the recording's compression is counted from what the writers write: the snapshot steps of
//! [`crate::io::snapshots::SnapshotSchedule`] over [`Model::planned_steps`], the ring and point counts of
//! [`crate::post::device`], binary STL's 84 + 50 bytes per triangle, OBJ's `v`/`f` lines, the recording's JSON
//! messages. Step cuts add steps (and so rows, states and possibly snapshots): the estimate is for a run
//! without cuts.
//!
//! **How conservative.** Measured on run folders (release build; the first two rows with this version, the others
//! with the earlier defaults they name), estimate against bytes
//! written, in all and for `run.mcap` alone:
//!
//! | design | estimated | written | ratio |
//! |---|---|---|---|
//! | straight stent (1301 steps, 8 snapshots, STL only) | 64.3 MB (mcap 19.0 MB) | 58.1 MB (mcap 13.3 MB) | 1.11 (mcap 1.43) |
//! | curved stent (4000 steps, 8 snapshots) | 85.1 MB (mcap 46.2 MB) | 70.9 MB (mcap 31.9 MB) | 1.20 (mcap 1.45) |
//! | straight stent (21 snapshots, STL and OBJ: the earlier default) | 314.2 MB (mcap 22.8 MB) | 300.6 MB (mcap 16.1 MB) | 1.05 (mcap 1.42) |
//! | 45° bend, h = 1e-3 (1000 steps, 21 snapshots, STL and OBJ) | 3.46 MB (mcap 0.49 MB) | 3.29 MB (mcap 0.45 MB) | 1.05 (mcap 1.09) |
//! | 45° bend, h = 1e-5 (10⁵ steps) | 65.2 MB (mcap 41.9 MB) | 37.8 MB (mcap 19.3 MB) | 1.73 (mcap 2.17) |
//!
//! The snapshots, which dominate the stents' runs, are counted almost exactly: the STL to the byte (caps on
//! every tube end: a welded end would make it an overestimate; the vessel's lumen of a stent on a file
//! centreline too, at most [`crate::design::vessel::MAX_LUMEN_RINGS`] rings), the OBJ 5 % over (coordinates at their longest
//! usual length). The recording is compressed (zstd level 1), and how much depends on how much the device
//! moves per step: a centreline point whose coordinates all change costs about 10 bytes compressed (the bend
//! at 1000 steps), one that barely moves 4–5 (the stents, the bend at 10⁵ steps). The estimate charges the
//! moving case, so it overestimates slow runs' recordings (up to about twice) and has not underestimated a
//! measured one.

use super::configurations::{CENTRELINE_SAMPLES, MAX_ROWS};
use super::mcap::coordinate_decimals;
use super::output::{RunDesign, SnapshotSettings};
use super::render::PANEL_WIDTH;
use super::snapshots::SnapshotSchedule;
use super::state::load_channels;
use crate::math::Real;
use crate::model::Model;
use crate::post::device::{device_sample_counts, patch_copies};

/// Bytes a run is estimated to write, part by part ([`estimated_disk`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DiskEstimate {
    /// Snapshots written (the initial state, every `every` steps, the requested times, the end).
    pub snapshots: usize,
    /// The binary STL files of all snapshots \[bytes\].
    pub snapshot_stl: u64,
    /// The OBJ files of all snapshots \[bytes\].
    pub snapshot_obj: u64,
    /// The field files of all snapshots and `run.pvd` \[bytes\] ([`crate::io::vtk`]).
    pub snapshot_vtp: u64,
    /// The vessel's lumen, `snapshots/vessel_lumen.stl`, for a stent on a file centreline with a lumen
    /// radius \[bytes\] ([`crate::io::snapshots::VESSEL_FILE`]).
    pub vessel_lumen: u64,
    /// `run.mcap` \[bytes\].
    pub recording: u64,
    /// `history.csv` \[bytes\].
    pub history: u64,
    /// `charts/*.svg` \[bytes\].
    pub charts: u64,
    /// `summary.json` \[bytes\].
    pub summary: u64,
}

impl DiskEstimate {
    /// The snapshot folder's files: STL, OBJ, the field files and the vessel's lumen \[bytes\].
    pub fn snapshots_bytes(&self) -> u64 {
        self.snapshot_stl + self.snapshot_obj + self.snapshot_vtp + self.vessel_lumen
    }

    /// Everything \[bytes\].
    pub fn total(&self) -> u64 {
        self.snapshots_bytes() + self.recording + self.history + self.charts + self.summary
    }
}

/// Bytes of an OBJ `v x y z` line: three coordinates in Rust's shortest round-trip form, each with a sign,
/// two integer digits and up to 16 decimals, 62 in all. Measured on the straight stent: 57 on average, 67
/// at most.
const OBJ_VERTEX_LINE_BYTES: Real = 62.0;

/// Bytes of an OBJ file's comment lines besides the design name: about 150 (144 for the straight stent).
const OBJ_HEADER_BYTES: Real = 200.0;

/// Compressed bytes of a recorded centreline point whose coordinates change from step to step: 10.5, measured
/// on the 45° bend at 1000 steps (21 points per step, 234 kB of zstd-1 chunks for 1001 steps, besides the
/// message headers). Points that barely move compress to 4–5 bytes (the straight stent's 5.3).
const CENTRELINE_POINT_BYTES: Real = 10.5;

/// Compressed bytes of a point of a mirrored copy of a rod: 4, measured on the straight stent (the three
/// mirrored copies of each rod added 7.25 MB to 4.03 MB of unique centrelines, 3.6 bytes a point).
const MIRRORED_POINT_BYTES: Real = 4.0;

/// Compressed bytes of a recorded line's header (pose, colour, thickness: the same text every step): 2.
const LINE_BYTES: Real = 2.0;

/// Bytes per recorded message besides its content: the MCAP record header (31 bytes, compressed with its
/// chunk), the message index entry (16 bytes, uncompressed) and the compressed scene-update wrapper.
const MESSAGE_BYTES: Real = 40.0;

/// Compression of the `/state` messages (full-precision numbers): 4.7 measured on the bend, 5.7 on the straight
/// stent; 4 charged.
const STATE_COMPRESSION: Real = 4.0;

/// Compression of the recorded tube meshes (points at fixed decimals, sequential indices): 4.9 measured on the
/// bend, 5.5 on the straight stent; 4.5 charged.
const MESH_COMPRESSION: Real = 4.5;

/// Bytes of a recording besides the messages and the design attached: schemas, metadata, chunk and summary
/// indexes (about 12 kB for the straight stent).
const RECORDING_FIXED_BYTES: Real = 20_000.0;

/// Bytes of a chart besides its points: axes, labels, legend (22 kB measured for the straight stent's
/// temperature chart).
const CHART_FIXED_BYTES: Real = 30_000.0;

/// Bytes per plotted point of a chart series: 8.2 measured (the bend's temperature chart at 10⁵ steps).
const CHART_POINT_BYTES: Real = 10.0;

/// Bytes of a field file besides its arrays: the XML of 18 arrays with their units (4.1 kB measured).
const VTP_FIXED_BYTES: Real = 6_000.0;

/// Bytes of a `run.pvd` line (about 100 measured).
const PVD_LINE_BYTES: Real = 120.0;

/// Bytes per point of a polyline in an SVG figure (`x,y ` with plotters' coordinates: 8–9 measured).
const SVG_POINT_BYTES: Real = 10.0;

/// Bytes per pixel of the shaded picture's PNG: 0.33 measured (the straight stent's, 485 kB for 1.47 million
/// pixels, mostly white).
const PNG_PIXEL_BYTES: Real = 0.5;

/// Bytes of `summary.json` besides its list of snapshots: about 4 kB (the straight stent's), 8 kB charged
/// for a failure report and warnings.
const SUMMARY_FIXED_BYTES: Real = 8_000.0;

/// Bytes per snapshot listed in `summary.json`: 200 measured.
const SUMMARY_SNAPSHOT_BYTES: Real = 250.0;

/// The bytes the run of `design` is estimated to write, part by part, assuming no step is cut; see the module
/// documentation for how conservative each part is.
pub fn estimated_disk(design: &impl RunDesign) -> DiskEstimate {
    let model = design.model();
    let snapshot = &design.output().snapshots;
    let recording = &design.output().recording;
    let steps = design.steps().total();
    let states = steps as Real + 1.0;
    let snapshots = snapshot_count(model, steps, snapshot);
    let count = snapshots as Real;

    let (vertices, triangles) = tube_mesh_size(model, snapshot.rings, snapshot.segments);
    let written = |extension: &str| {
        if snapshot.formats.contains(&extension) {
            count
        } else {
            0.0
        }
    };
    let stl = written("stl") * (84.0 + 50.0 * triangles);
    let obj = written("obj")
        * (OBJ_HEADER_BYTES
            + model.name.len() as Real
            + vertices * OBJ_VERTEX_LINE_BYTES
            + triangles * (3.0 * digits(vertices) + 5.0));

    // The recording: a state and the centrelines at every state, a mesh at every snapshot.
    let point_counts = device_sample_counts(model, recording.centreline_points);
    let device_points: Real = device_sample_counts(model, CENTRELINE_SAMPLES)
        .iter()
        .enumerate()
        .map(|(k, &n)| (patch_copies(model, k).len() * n) as Real)
        .sum();
    let (mut unique, mut mirrored, mut lines) = (0.0, 0.0, 0.0);
    for (k, &points) in point_counts.iter().enumerate() {
        let copies = patch_copies(model, k).len() as Real;
        unique += points as Real;
        mirrored += (copies - 1.0) * points as Real;
        lines += copies;
    }
    let centrelines = unique * CENTRELINE_POINT_BYTES
        + mirrored * MIRRORED_POINT_BYTES
        + lines * LINE_BYTES
        + MESSAGE_BYTES;
    let state = state_message_bytes(model) / STATE_COMPRESSION + MESSAGE_BYTES;
    let meshes = if recording.meshes {
        let (v, t) = tube_mesh_size(model, recording.mesh_rings, recording.mesh_segments);
        let raw = 400.0 + v * point_bytes(model) + 3.0 * t * (digits(v) + 1.0);
        count * (raw / MESH_COMPRESSION + MESSAGE_BYTES)
    } else {
        0.0
    };
    // The vessel: its lumen written once with the first snapshot, and recorded once (its centreline and, with
    // a radius, its lumen at the recording's segments).
    let (lumen, vessel_message) = match &model.vessel {
        Some(vessel) => {
            let rings = vessel.points.len() as Real;
            let lumen = |segments: usize| -> (Real, Real) {
                let m = segments as Real;
                (rings * m + 2.0, 2.0 * m * rings)
            };
            let (stl, mesh) = match vessel.radius {
                Some(_) => {
                    let (v, t) = lumen(recording.mesh_segments);
                    (
                        84.0 + 50.0 * lumen(snapshot.segments).1,
                        v * point_bytes(model) + 3.0 * t * (digits(v) + 1.0),
                    )
                }
                None => (0.0, 0.0),
            };
            let raw = 400.0 + rings * point_bytes(model) + mesh;
            (stl, raw / MESH_COMPRESSION + MESSAGE_BYTES)
        }
        None => (0.0, 0.0),
    };
    let mcap = if recording.enabled {
        states * (centrelines + state)
            + meshes
            + vessel_message
            + RECORDING_FIXED_BYTES
            + design.source().len() as Real
    } else {
        0.0
    };

    // The field files: per collocation point three coordinates, 34 field values and a connectivity entry,
    // 8 bytes each in base64 (4/3), plus the XML; run.pvd a line per snapshot.
    let vtp = if snapshot.vtk {
        let points: usize = model.patches.iter().map(|p| p.curve.num_points()).sum();
        count * (VTP_FIXED_BYTES + points as Real * 38.0 * 8.0 * 4.0 / 3.0 + PVD_LINE_BYTES)
    } else {
        0.0
    };

    let history = (states + 1.0) * history_row_bytes(model, &design.output().strain_limits);
    let (charts, series) = chart_counts(model);
    // The configuration figures: up to MAX_ROWS rows and one figure per row, each panel the initial and the
    // current centrelines of the full device in two views.
    let figure_rows = (count - 1.0).clamp(0.0, MAX_ROWS as Real);
    let figures = 2.0 * figure_rows * 2.0 * 2.0 * device_points * SVG_POINT_BYTES;
    // Their shaded picture: the initial state and each row, a square panel each (the straight stent's are
    // 2:3) of PANEL_WIDTH² pixels.
    let picture = if snapshot.render {
        (figure_rows + 1.0) * Real::from(PANEL_WIDTH).powi(2) * PNG_PIXEL_BYTES
    } else {
        0.0
    };
    let figures = figures + picture;
    let chart_bytes = charts * CHART_FIXED_BYTES + states * series * CHART_POINT_BYTES + figures;
    let summary = SUMMARY_FIXED_BYTES + count * SUMMARY_SNAPSHOT_BYTES;

    DiskEstimate {
        snapshots,
        snapshot_stl: stl as u64,
        snapshot_obj: obj as u64,
        snapshot_vtp: vtp as u64,
        vessel_lumen: lumen as u64,
        recording: mcap as u64,
        history: history as u64,
        charts: chart_bytes as u64,
        summary: summary as u64,
    }
}

/// Snapshots of a run of `steps` steps: step 0, every `every`-th step, the last one, and one per time due
/// strictly inside the run (requested, events, between them: [`SnapshotSchedule`]); an upper bound, as a time
/// due may fall on an `every` step.
fn snapshot_count(model: &Model, steps: usize, settings: &SnapshotSettings) -> usize {
    let every = settings.every;
    let periodic = steps.checked_div(every).unwrap_or(0);
    let last = usize::from(every == 0 || !steps.is_multiple_of(every));
    let due = SnapshotSchedule::new(settings, model)
        .times()
        .iter()
        .filter(|&&t| t > 0.0 && t < model.time().end)
        .count();
    1 + periodic + last + due
}

/// Vertices and triangles of the full device's tube mesh with about `rings` rings per patch and `segments`
/// vertices around ([`crate::post::device::device_tube_mesh`]): per copy of a patch, `r · m` ring vertices
/// and `2m(r − 1)` side triangles, plus two capped ends (a centre vertex and `m` triangles each; ends welded to
/// a mirror image have none, so this is an upper bound).
fn tube_mesh_size(model: &Model, rings: usize, segments: usize) -> (Real, Real) {
    let m = segments as Real;
    let (mut vertices, mut triangles) = (0.0, 0.0);
    for (k, &r) in device_sample_counts(model, rings).iter().enumerate() {
        let copies = patch_copies(model, k).len() as Real;
        let r = r as Real;
        vertices += copies * (r * m + 2.0);
        triangles += copies * (2.0 * m * (r - 1.0) + 2.0 * m);
    }
    (vertices, triangles)
}

/// Decimal digits of the largest index below `n` (at least 1).
fn digits(n: Real) -> Real {
    (n.max(1.0).log10().floor() + 1.0).max(1.0)
}

/// Bytes of a recorded point `{"x":…,"y":…,"z":…}` with the recording's fixed decimals: 16 characters of
/// keys and braces and three coordinates of a sign, the integer digits of the device's size and the decimals.
fn point_bytes(model: &Model) -> Real {
    let scale = model
        .patches
        .iter()
        .flat_map(|p| p.curve.points().iter().map(|q| q.norm()))
        .fold(0.0, Real::max);
    let decimals = coordinate_decimals(scale) as Real;
    let integer = digits(scale.max(1.0) + 1.0);
    16.0 + 3.0 * (1.0 + integer + 1.0 + decimals)
}

/// Bytes of a `/state` message before compression: the fixed fields, a load per channel, about six Newton
/// residuals, a probe's displacement and magnitude, the recovery measures of a programme (398 bytes measured
/// for the straight stent, 412 for the bend; 472 and 462 here).
fn state_message_bytes(model: &Model) -> Real {
    200.0
        + 30.0 * load_channels(model).len() as Real
        + 22.0 * 6.0
        + 100.0 * model.probes.len() as Real
        + if model.programme.is_some() {
            110.0
        } else {
            0.0
        }
}

/// Bytes of a `history.csv` row (io::history's formats at their longest): time (17), three displacements per
/// probe (20 each), temperature (11), iterations (3), residual (10), cuts (3), the recovery ratios (18 each)
/// and Δr (17) of a programme, the largest node displacement (16), the peak surface strain (16), its patch
/// (the longest name) and arc length (16), one peak per material with a strain limit (16), the line end.
fn history_row_bytes(model: &Model, strain_limits: &[Option<Real>]) -> Real {
    let name = model
        .patches
        .iter()
        .map(|p| p.name.len())
        .max()
        .unwrap_or(0) as Real;
    let limits = strain_limits.iter().flatten().count() as Real;
    let peaks = 16.0 + 17.0 + name + 1.0 + 17.0 + 17.0 * limits;
    let recovery = match &model.programme {
        Some(p) => {
            36.0 + if matches!(
                p.kind,
                crate::model::ProgrammeKind::RadialContraction { .. }
            ) {
                18.0
            } else {
                0.0
            }
        }
        None => 0.0,
    };
    17.0 + 60.0 * model.probes.len() as Real + 11.0 + 3.0 + 11.0 + 3.0 + recovery + peaks + 1.0
}

/// The charts a run draws and the number of series in them (io::run_charts): temperature (1), probe
/// displacements (3 per probe) and their normalised overlay (3 per probe, a load per channel, the
/// temperature), recovery (4) and Δr (1) with a programme, Newton iterations (1).
fn chart_counts(model: &Model) -> (Real, Real) {
    let probes = model.probes.len() as Real;
    let mut charts = 2.0;
    let mut series = 2.0;
    if probes > 0.0 {
        charts += 2.0;
        series += 6.0 * probes + load_channels(model).len() as Real + 1.0;
    }
    if model.programme.is_some() {
        charts += 2.0;
        series += 5.0;
    }
    (charts, series)
}
