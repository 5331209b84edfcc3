//! `run.mcap`: a recording of the run that Foxglove opens (MCAP, zstd-compressed chunks, JSON messages with a
//! JSON Schema per channel).
//!
//! | topic | schema | when | content |
//! |---|---|---|---|
//! | `/state` | `stentkit.State` | every step and the initial state | time, step size, temperature, loads, Newton iterations and residuals, step cuts, probe displacements, recovery measures |
//! | `/centrelines` | `foxglove.SceneUpdate` | every step | entity `centrelines`: one `LINE_STRIP` per rod of the full device (mirrored back), coloured by temperature |
//! | `/device` | `foxglove.SceneUpdate` | snapshot steps | entity `device`: the full device's closed tube mesh (`TriangleListPrimitive` with indices) |
//!
//! The design file is attached (`application/yaml`), and a metadata record `stentkit` holds the version, the
//! command line, the design name and the units. Log times are the simulated time in nanoseconds (1 s of
//! simulation is 1 s of playback), strictly increasing per channel: a step shorter than 1 ns (impossible with
//! sane settings) is moved to 1 ns after the previous one. Coordinates are in the design's length unit
//! (Foxglove's 3D panel reads them as metres); they are rounded to a fixed number of decimals,
//! [`coordinate_decimals`]: a resolution between 10⁻⁶ and 10⁻⁵ of the device's size (1 µm on a 100 mm stent),
//! far below what a viewer shows, which keeps the file small.
//!
//! The file is complete only after [`McapRecorder::finish`] (also called on drop): the run calls it whether
//! the simulation succeeded or failed.

use super::design::{Design, RecordingSettings, SnapshotSettings};
use super::device::{current_device_shapes, device_centrelines, device_tube_mesh};
use super::snapshots::SnapshotSchedule;
use super::state::{LoadChannel, StateSample, load_channels};
use crate::math::{Real, Vec3};
use crate::model::Model;
use crate::solver::{Observer, Simulation, StepReport};
use serde_json::{Map, Value, json};
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

/// Decimals of recorded coordinates for a device of size `scale` (largest distance of a control point from
/// the origin) [length]: `max(0, 5 − ⌊log₁₀ scale⌋)`, a resolution `10^(⌊log₁₀ scale⌋ − 5)` between `10⁻⁶` and
/// `10⁻⁵` of the size.
pub fn coordinate_decimals(scale: Real) -> usize {
    if !(scale > 0.0 && scale.is_finite()) {
        return 6;
    }
    (5 - scale.log10().floor() as i64).clamp(0, 12) as usize
}

/// Topic of the state channel.
pub const STATE_TOPIC: &str = "/state";
/// Topic of the centrelines.
pub const CENTRELINE_TOPIC: &str = "/centrelines";
/// Topic of the tube meshes.
pub const DEVICE_TOPIC: &str = "/device";
/// Frame of every scene entity.
pub const FRAME_ID: &str = "world";

/// What the recording says about the run that made it.
#[derive(Debug, Clone, PartialEq)]
pub struct RunInfo {
    /// stentkit's version.
    pub version: String,
    /// The command line, as typed (arguments joined by spaces).
    pub command_line: String,
}

/// Why the recording failed.
#[derive(Debug, thiserror::Error)]
pub enum McapError {
    /// The file could not be created.
    #[error("cannot create {path}: {source}")]
    Create {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },
    /// Writing failed.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// The MCAP error.
        #[source]
        source: ::mcap::McapError,
    },
    /// Flushing the finished file failed.
    #[error("cannot write {path}: {source}")]
    Flush {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },
    /// A tube mesh could not be built.
    #[error("step {step}: patch `{patch}`: {source}")]
    Mesh {
        /// Step.
        step: usize,
        /// Patch name.
        patch: String,
        /// What failed.
        #[source]
        source: crate::geometry::tube::TubeError,
    },
}

/// A JSON number, `null` for NaN or infinity (which JSON cannot hold).
fn number(x: Real) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// Appends `x` with `decimals` decimals, trailing zeros dropped, as a JSON number (`null` if not finite).
///
/// Rounds in integers (`x · 10^decimals` to the nearest integer, then its digits), not with `format!("{:.N}")`,
/// whose exact decimal expansion cost a fifth of a straight-stent run; values too large for that fall back to it.
fn push_coordinate(out: &mut String, x: Real, decimals: usize) {
    if !x.is_finite() {
        out.push_str("null");
        return;
    }
    let scale = 10f64.powi(decimals as i32);
    let scaled = (x * scale).round();
    if decimals > 15 || scaled.abs() >= 1e15 {
        let start = out.len();
        let _ = write!(out, "{x:.decimals$}");
        if out[start..].contains('.') {
            let trimmed = out.trim_end_matches('0').trim_end_matches('.').len();
            out.truncate(trimmed);
        }
        if &out[start..] == "-0" {
            out.truncate(start);
            out.push('0');
        }
        return;
    }
    let n = scaled as i64;
    if n == 0 {
        out.push('0');
        return;
    }
    let unit = 10i64.pow(decimals as u32);
    let (whole, mut fraction) = (n.abs() / unit, n.abs() % unit);
    if n < 0 {
        out.push('-');
    }
    let _ = write!(out, "{whole}");
    if fraction != 0 {
        let mut digits = decimals;
        while fraction % 10 == 0 {
            fraction /= 10;
            digits -= 1;
        }
        let _ = write!(out, ".{fraction:0digits$}");
    }
}

/// Appends a `foxglove.Point3`.
fn push_point(out: &mut String, p: &Vec3, decimals: usize) {
    out.push_str("{\"x\":");
    push_coordinate(out, p.x, decimals);
    out.push_str(",\"y\":");
    push_coordinate(out, p.y, decimals);
    out.push_str(",\"z\":");
    push_coordinate(out, p.z, decimals);
    out.push('}');
}

/// Appends a JSON array of points.
fn push_points(out: &mut String, points: &[Vec3], decimals: usize) {
    out.push('[');
    for (i, p) in points.iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        push_point(out, p, decimals);
    }
    out.push(']');
}

/// The identity `foxglove.Pose`.
const IDENTITY_POSE: &str =
    r#"{"position":{"x":0,"y":0,"z":0},"orientation":{"x":0,"y":0,"z":0,"w":1}}"#;

/// A `foxglove.Color` as JSON.
fn color(r: Real, g: Real, b: Real) -> String {
    format!(r#"{{"r":{r:.3},"g":{g:.3},"b":{b:.3},"a":1}}"#)
}

/// A key usable in a Foxglove message path (`/state.probes.tip.x`): letters, digits and `_`.
pub fn path_key(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

/// Colour for temperature `t` between `lo` and `hi`: blue (cold) to red (hot).
fn temperature_color(t: Real, lo: Real, hi: Real) -> String {
    let s = if hi > lo {
        ((t - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        1.0
    };
    color(0.15 + 0.8 * s, 0.35, 0.95 - 0.8 * s)
}

/// A `foxglove.SceneUpdate` replacing entity `id` with the given line and triangle-list primitives (JSON
/// array contents). Written by hand: the centrelines are recorded at every step and dominate the recording
/// time.
fn scene_update(id: &str, nanoseconds: u64, lines: &str, triangles: &str) -> String {
    let (sec, nsec) = (nanoseconds / 1_000_000_000, nanoseconds % 1_000_000_000);
    format!(
        r#"{{"deletions":[],"entities":[{{"timestamp":{{"sec":{sec},"nsec":{nsec}}},"frame_id":"{FRAME_ID}","id":"{id}","lifetime":{{"sec":0,"nsec":0}},"frame_locked":false,"metadata":[],"arrows":[],"cubes":[],"spheres":[],"cylinders":[],"lines":[{lines}],"triangles":[{triangles}],"texts":[],"models":[]}}]}}"#
    )
}

/// JSON Schema of the `foxglove.SceneUpdate` fields used here (entities with line and triangle-list
/// primitives); Foxglove recognises the message by its schema name.
pub fn scene_update_schema() -> Value {
    let xyz = |title: &str| {
        json!({
            "title": title, "type": "object",
            "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}},
            "required": ["x", "y", "z"]
        })
    };
    let time = json!({
        "type": "object", "title": "time",
        "properties": {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}}
    });
    let duration = json!({
        "type": "object", "title": "duration",
        "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}}
    });
    let color = json!({
        "title": "foxglove.Color", "type": "object",
        "properties": {"r": {"type": "number"}, "g": {"type": "number"}, "b": {"type": "number"}, "a": {"type": "number"}},
        "required": ["r", "g", "b", "a"]
    });
    let pose = json!({
        "title": "foxglove.Pose", "type": "object",
        "properties": {
            "position": xyz("foxglove.Vector3"),
            "orientation": {
                "title": "foxglove.Quaternion", "type": "object",
                "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}, "w": {"type": "number"}},
                "required": ["x", "y", "z", "w"]
            }
        },
        "required": ["position", "orientation"]
    });
    let points = json!({"type": "array", "items": xyz("foxglove.Point3")});
    let colors = json!({"type": "array", "items": color});
    let indices = json!({"type": "array", "items": {"type": "integer", "minimum": 0}});
    let line = json!({
        "title": "foxglove.LinePrimitive",
        "description": "A primitive representing a series of points connected by lines",
        "type": "object",
        "properties": {
            "type": {
                "title": "foxglove.LineType",
                "oneOf": [
                    {"title": "LINE_STRIP", "const": 0},
                    {"title": "LINE_LOOP", "const": 1},
                    {"title": "LINE_LIST", "const": 2}
                ]
            },
            "pose": pose,
            "thickness": {"type": "number"},
            "scale_invariant": {"type": "boolean"},
            "points": points,
            "color": color,
            "colors": colors,
            "indices": indices
        },
        "required": ["type", "pose", "thickness", "scale_invariant", "points", "color", "colors", "indices"]
    });
    let triangles = json!({
        "title": "foxglove.TriangleListPrimitive",
        "description": "A primitive representing a set of triangles or a surface tiled by triangles",
        "type": "object",
        "properties": {"pose": pose, "points": points, "color": color, "colors": colors, "indices": indices},
        "required": ["pose", "points", "color", "colors", "indices"]
    });
    let other = json!({"type": "array", "items": {"type": "object"}});
    json!({
        "title": "foxglove.SceneUpdate",
        "description": "An update to the entities displayed in a 3D scene",
        "type": "object",
        "properties": {
            "deletions": {
                "type": "array",
                "items": {
                    "title": "foxglove.SceneEntityDeletion",
                    "type": "object",
                    "properties": {
                        "timestamp": time,
                        "type": {"oneOf": [{"title": "MATCHING_ID", "const": 0}, {"title": "ALL", "const": 1}]},
                        "id": {"type": "string"}
                    }
                }
            },
            "entities": {
                "type": "array",
                "items": {
                    "title": "foxglove.SceneEntity",
                    "type": "object",
                    "properties": {
                        "timestamp": time,
                        "frame_id": {"type": "string"},
                        "id": {"type": "string"},
                        "lifetime": duration,
                        "frame_locked": {"type": "boolean"},
                        "metadata": {"type": "array", "items": {
                            "type": "object",
                            "properties": {"key": {"type": "string"}, "value": {"type": "string"}}
                        }},
                        "arrows": other,
                        "cubes": other,
                        "spheres": other,
                        "cylinders": other,
                        "lines": {"type": "array", "items": line},
                        "triangles": {"type": "array", "items": triangles},
                        "texts": other,
                        "models": other
                    },
                    "required": ["timestamp", "frame_id", "id", "lifetime", "frame_locked", "metadata", "arrows",
                        "cubes", "spheres", "cylinders", "lines", "triangles", "texts", "models"]
                }
            }
        },
        "required": ["deletions", "entities"]
    })
}

/// Names of the probe and load keys of the state messages (sanitised for message paths).
struct StateKeys {
    probes: Vec<String>,
    loads: Vec<String>,
}

/// JSON Schema of the `/state` messages of `model`.
fn state_schema(model: &Model, channels: &[LoadChannel], keys: &StateKeys) -> Value {
    let units = model.units;
    let length = units.length();
    let num = |description: String| json!({"type": "number", "description": description});
    let mut probes = Map::new();
    for (key, probe) in keys.probes.iter().zip(&model.probes) {
        probes.insert(
            key.clone(),
            json!({
                "type": "object",
                "description": format!("displacement of probe `{}` [{length}]", probe.name),
                "properties": {
                    "x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"},
                    "magnitude": {"type": "number"}
                }
            }),
        );
    }
    let mut loads = Map::new();
    for (key, c) in keys.loads.iter().zip(channels) {
        loads.insert(key.clone(), num(format!("{} [{}]", c.name, c.unit)));
    }
    let mut properties = json!({
        "step": {"type": "integer", "description": "step number (0: initial state)"},
        "time": num("simulated time [s]".into()),
        "dt": num("step size that reached this state [s]".into()),
        "temperature": num("temperature [°C]".into()),
        "loads": {"type": "object", "properties": loads},
        "iterations": {"type": "integer", "description": "Newton iterations of the step"},
        "residual": num("final normalised residual".into()),
        "residuals": {"type": "array", "items": {"type": "number"}, "description": "normalised residual after each Newton iteration"},
        "cuts": {"type": "integer", "description": "step cuts before the step converged"},
        "probes": {"type": "object", "properties": probes}
    });
    if let Some(p) = &model.programme {
        let map = properties.as_object_mut().expect("object literal");
        map.insert(
            "recovery_ratio_mean".into(),
            num("mean |η| / |η_temp| over the driven nodes: 1 at the temporary shape, 0 at the permanent one".into()),
        );
        map.insert(
            "recovery_ratio_max".into(),
            num("largest |η| / |η_temp| over the driven nodes".into()),
        );
        if matches!(
            p.kind,
            crate::model::ProgrammeKind::RadialContraction { .. }
        ) {
            map.insert(
                "delta_r".into(),
                num(format!(
                    "mean radial contraction of the driven nodes [{length}]"
                )),
            );
        }
    }
    json!({
        "title": "stentkit.State",
        "description": format!("state of a stentkit run (units {}; time in s, temperature in °C)", units.name()),
        "type": "object",
        "properties": properties
    })
}

/// Records a run into an MCAP file as the simulation reports its steps.
pub struct McapRecorder {
    path: PathBuf,
    writer: Option<::mcap::Writer<BufWriter<File>>>,
    state_channel: u16,
    centreline_channel: u16,
    device_channel: Option<u16>,
    channels: Vec<LoadChannel>,
    keys: StateKeys,
    schedule: SnapshotSchedule,
    settings: RecordingSettings,
    /// Drawing diameter of every rod of the full device, in the order of the centrelines.
    thickness: Vec<Real>,
    /// Temperature range of the schedule, for the colours.
    temperature_range: (Real, Real),
    /// Decimals of the recorded coordinates.
    decimals: usize,
    sequence: u32,
    /// Log time, step and time of the last state recorded.
    last: Option<(u64, usize, Real)>,
    /// Step of the last mesh recorded.
    last_mesh: Option<usize>,
    error: Option<McapError>,
}

impl McapRecorder {
    /// Creates the file and writes the header records: metadata, the design as an attachment, schemas and
    /// channels.
    ///
    /// # Errors
    /// [`McapError`] when the file cannot be created or written.
    pub fn create(
        path: &Path,
        design: &Design,
        info: &RunInfo,
        snapshots: &SnapshotSettings,
    ) -> Result<Self, McapError> {
        let model = &design.model;
        let settings = design.output.recording.clone();
        let file = File::create(path).map_err(|source| McapError::Create {
            path: path.to_path_buf(),
            source,
        })?;
        let write_error = |source| McapError::Write {
            path: path.to_path_buf(),
            source,
        };
        let mut writer = ::mcap::WriteOptions::new()
            .compression(Some(::mcap::Compression::Zstd))
            // zstd level 1 with one background thread, measured against the default level on the calling
            // thread: the straight stent's recording 1.5 s → 1.05 s and 16.5 → 16.3 MB (level 1 compresses
            // these JSON messages no worse), the curved stent's run 63.0 → 59.0 s (the thread overlaps the
            // solver's sequential parts).
            .compression_level(1)
            .compression_threads(1)
            .profile("")
            .library(format!("stentkit {} (mcap crate)", info.version))
            .create(BufWriter::new(file))
            .map_err(write_error)?;
        let units = model.units;
        let metadata: BTreeMap<String, String> = [
            ("stentkit_version", info.version.clone()),
            ("command_line", info.command_line.clone()),
            ("design", model.name.clone()),
            ("design_file", design.path.display().to_string()),
            ("units", units.name().to_string()),
            ("length_unit", units.length().to_string()),
            ("force_unit", units.force().to_string()),
            ("stress_unit", units.stress().to_string()),
            ("moment_unit", units.moment().to_string()),
            ("time_unit", "s".to_string()),
            ("temperature_unit", "°C".to_string()),
            (
                "log_time",
                "simulated time in ns (1 s of simulation = 1 s of log time)".to_string(),
            ),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
        writer
            .write_metadata(&::mcap::records::Metadata {
                name: "stentkit".into(),
                metadata,
            })
            .map_err(write_error)?;
        let name = design.path.file_name().map_or_else(
            || "design.yaml".to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        writer
            .attach(&::mcap::Attachment {
                log_time: 0,
                create_time: 0,
                name,
                media_type: "application/yaml".into(),
                data: Cow::Borrowed(design.source.as_bytes()),
            })
            .map_err(write_error)?;
        let channels = load_channels(model);
        let keys = StateKeys {
            probes: model.probes.iter().map(|p| path_key(&p.name)).collect(),
            loads: channels.iter().map(|c| path_key(&c.name)).collect(),
        };
        let no_metadata = BTreeMap::new();
        let state_schema = writer
            .add_schema(
                "stentkit.State",
                "jsonschema",
                state_schema(model, &channels, &keys).to_string().as_bytes(),
            )
            .map_err(write_error)?;
        let state_channel = writer
            .add_channel(state_schema, STATE_TOPIC, "json", &no_metadata)
            .map_err(write_error)?;
        let scene_schema = writer
            .add_schema(
                "foxglove.SceneUpdate",
                "jsonschema",
                scene_update_schema().to_string().as_bytes(),
            )
            .map_err(write_error)?;
        let centreline_channel = writer
            .add_channel(scene_schema, CENTRELINE_TOPIC, "json", &no_metadata)
            .map_err(write_error)?;
        let device_channel = if settings.meshes {
            Some(
                writer
                    .add_channel(scene_schema, DEVICE_TOPIC, "json", &no_metadata)
                    .map_err(write_error)?,
            )
        } else {
            None
        };
        let thickness = (0..model.patches.len())
            .flat_map(|k| {
                let d = model.sections[model.patches[k].section].diameter();
                std::iter::repeat_n(d, super::device::patch_copies(model, k).len())
            })
            .collect();
        Ok(Self {
            path: path.to_path_buf(),
            writer: Some(writer),
            state_channel,
            centreline_channel,
            device_channel,
            channels,
            keys,
            schedule: SnapshotSchedule::new(snapshots, model),
            settings,
            thickness,
            temperature_range: model.temperature.range(),
            decimals: coordinate_decimals(
                model
                    .patches
                    .iter()
                    .flat_map(|p| p.curve.points().iter().map(|q| q.norm()))
                    .fold(0.0, Real::max),
            ),
            sequence: 0,
            last: None,
            last_mesh: None,
            error: None,
        })
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The first error, if any (recording stops there and the run is asked to stop).
    pub fn take_error(&mut self) -> Option<McapError> {
        self.error.take()
    }

    /// The simulated time of the last state recorded \[s\].
    pub fn last_time(&self) -> Option<Real> {
        self.last.map(|(_, _, t)| t)
    }

    /// Closes the current chunk and flushes it to the file, so that a run killed after this call (SIGKILL, a
    /// power loss) leaves a recording that [`crate::io::mcap_salvage::salvage`] restores up to here. The run
    /// calls it every few seconds; each call costs a chunk boundary (slightly less compression).
    ///
    /// # Errors
    /// [`McapError::Write`] when the chunk cannot be written (the recording stops there).
    pub fn flush_chunk(&mut self) -> Result<(), McapError> {
        let Some(writer) = &mut self.writer else {
            return Ok(());
        };
        writer.flush().map_err(|source| McapError::Write {
            path: self.path.clone(),
            source,
        })
    }

    fn write(&mut self, channel: u16, log_time: u64, message: &[u8]) -> Result<(), McapError> {
        let Some(writer) = &mut self.writer else {
            return Ok(());
        };
        self.sequence += 1;
        writer
            .write_to_known_channel(
                &::mcap::records::MessageHeader {
                    channel_id: channel,
                    sequence: self.sequence,
                    log_time,
                    publish_time: log_time,
                },
                message,
            )
            .map_err(|source| McapError::Write {
                path: self.path.clone(),
                source,
            })
    }

    fn state_message(&self, sample: &StateSample) -> Value {
        let mut probes = Map::new();
        for (key, u) in self.keys.probes.iter().zip(&sample.probes) {
            probes.insert(
                key.clone(),
                json!({"x": number(u.x), "y": number(u.y), "z": number(u.z), "magnitude": number(u.norm())}),
            );
        }
        let mut loads = Map::new();
        for (key, v) in self.keys.loads.iter().zip(&sample.loads) {
            loads.insert(key.clone(), number(*v));
        }
        let mut message = json!({
            "step": sample.step,
            "time": number(sample.time),
            "dt": number(sample.dt),
            "temperature": number(sample.temperature),
            "loads": loads,
            "iterations": sample.iterations,
            "residual": number(sample.residual()),
            "residuals": sample.residuals.iter().map(|r| number(*r)).collect::<Vec<_>>(),
            "cuts": sample.cuts,
            "probes": probes,
        });
        if let Some(r) = sample.recovery {
            let map = message.as_object_mut().expect("object literal");
            map.insert("recovery_ratio_mean".into(), number(r.ratio_mean));
            map.insert("recovery_ratio_max".into(), number(r.ratio_max));
            if let Some(d) = r.delta_r {
                map.insert("delta_r".into(), number(d));
            }
        }
        message
    }

    fn centreline_message(&self, sim: &Simulation<'_>, log_time: u64) -> String {
        let shapes = current_device_shapes(sim, self.settings.centreline_points);
        let (lo, hi) = self.temperature_range;
        let color = temperature_color(sim.model().temperature.value(sim.time()), lo, hi);
        let mut lines = String::new();
        for (i, (points, thickness)) in device_centrelines(sim.model(), &shapes)
            .iter()
            .zip(&self.thickness)
            .enumerate()
        {
            if i > 0 {
                lines.push(',');
            }
            let _ = write!(
                lines,
                r#"{{"type":0,"pose":{IDENTITY_POSE},"thickness":{thickness},"scale_invariant":false,"color":{color},"colors":[],"indices":[],"points":"#
            );
            push_points(&mut lines, points, self.decimals);
            lines.push('}');
        }
        scene_update("centrelines", log_time, &lines, "")
    }

    fn mesh_message(
        &self,
        sim: &Simulation<'_>,
        step: usize,
        log_time: u64,
    ) -> Result<String, McapError> {
        let shapes = current_device_shapes(sim, self.settings.mesh_rings);
        let mesh =
            device_tube_mesh(sim.model(), &shapes, self.settings.mesh_segments).map_err(|e| {
                McapError::Mesh {
                    step,
                    patch: sim.model().patches[e.rod].name.clone(),
                    source: e.source,
                }
            })?;
        let mut triangles = format!(
            r#"{{"pose":{IDENTITY_POSE},"color":{},"colors":[],"points":"#,
            color(0.80, 0.72, 0.45)
        );
        push_points(&mut triangles, &mesh.vertices, self.decimals);
        triangles.push_str(r#","indices":["#);
        for (i, index) in mesh.triangles.iter().flatten().enumerate() {
            if i > 0 {
                triangles.push(',');
            }
            let _ = write!(triangles, "{index}");
        }
        triangles.push_str("]}");
        Ok(scene_update("device", log_time, "", &triangles))
    }

    fn record(
        &mut self,
        sim: &Simulation<'_>,
        report: Option<&StepReport>,
    ) -> Result<(), McapError> {
        let step = report.map_or(0, |r| r.step);
        let time = sim.time();
        let nominal = (time.max(0.0) * 1e9).round() as u64;
        let log_time = match self.last {
            Some((last, _, _)) => nominal.max(last + 1),
            None => nominal,
        };
        let previous = self.last.map_or(0.0, |(_, _, t)| t);
        self.last = Some((log_time, step, time));
        let sample = StateSample::of(sim, &self.channels, report);
        let state = self.state_message(&sample).to_string();
        self.write(self.state_channel, log_time, state.as_bytes())?;
        let centrelines = self.centreline_message(sim, log_time);
        self.write(self.centreline_channel, log_time, centrelines.as_bytes())?;
        if self.device_channel.is_some() && self.schedule.is_due(step, previous, time) {
            self.record_mesh(sim, step, log_time)?;
        }
        Ok(())
    }

    fn record_mesh(
        &mut self,
        sim: &Simulation<'_>,
        step: usize,
        log_time: u64,
    ) -> Result<(), McapError> {
        if let Some(channel) = self.device_channel {
            let message = self.mesh_message(sim, step, log_time)?;
            self.write(channel, log_time, message.as_bytes())?;
            self.last_mesh = Some(step);
        }
        Ok(())
    }

    fn observe(&mut self, sim: &Simulation<'_>, report: Option<&StepReport>) -> ControlFlow<()> {
        if self.error.is_some() {
            return ControlFlow::Break(());
        }
        match self.record(sim, report) {
            Ok(()) => ControlFlow::Continue(()),
            Err(e) => {
                self.error = Some(e);
                ControlFlow::Break(())
            }
        }
    }

    /// Records the final mesh if the last state has none (a run that stopped or failed between snapshot
    /// steps), writes the summary section and closes the file; returns its size in bytes. Later calls do
    /// nothing and return the same size.
    ///
    /// # Errors
    /// [`McapError`] when the last records cannot be written.
    pub fn finish(&mut self, sim: &Simulation<'_>) -> Result<u64, McapError> {
        if let Some((log_time, step, _)) = self.last
            && self.last_mesh != Some(step)
            && self.writer.is_some()
        {
            self.record_mesh(sim, step, log_time)?;
        }
        self.close()
    }

    /// Closes the file without recording anything more (no final mesh); returns its size in bytes.
    ///
    /// # Errors
    /// [`McapError`] when the summary section cannot be written.
    pub fn close(&mut self) -> Result<u64, McapError> {
        if let Some(mut writer) = self.writer.take() {
            writer.finish().map_err(|source| McapError::Write {
                path: self.path.clone(),
                source,
            })?;
            let mut out = writer.into_inner();
            let flush = |source| McapError::Flush {
                path: self.path.clone(),
                source,
            };
            out.flush().map_err(flush)?;
            out.get_ref().sync_all().map_err(flush)?;
        }
        std::fs::metadata(&self.path)
            .map(|m| m.len())
            .map_err(|source| McapError::Flush {
                path: self.path.clone(),
                source,
            })
    }
}

impl Drop for McapRecorder {
    /// A recorder dropped without [`McapRecorder::finish`] (an early error) still leaves a valid file.
    fn drop(&mut self) {
        let _ = self.close();
    }
}

impl Observer for McapRecorder {
    fn start(&mut self, sim: &Simulation<'_>) -> ControlFlow<()> {
        self.observe(sim, None)
    }

    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        self.observe(sim, Some(report))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinates_are_short_fixed_point_numbers() {
        assert_eq!(coordinate_decimals(110.0), 3);
        assert_eq!(coordinate_decimals(75.0), 4);
        assert_eq!(coordinate_decimals(1.0), 5);
        assert_eq!(coordinate_decimals(1e7), 0);
        let text = |x: Real, d: usize| {
            let mut s = String::new();
            push_coordinate(&mut s, x, d);
            s
        };
        assert_eq!(text(109.856_4, 3), "109.856");
        assert_eq!(text(0.050_943_5, 3), "0.051");
        assert_eq!(text(19.999_999_9, 4), "20");
        assert_eq!(text(-0.000_01, 3), "0");
        assert_eq!(text(-2.5, 3), "-2.5");
        assert_eq!(text(1234.0, 0), "1234");
        assert_eq!(text(-0.0307, 3), "-0.031");
        assert_eq!(text(3.000_5, 5), "3.0005");
        assert_eq!(text(2e16, 3), "20000000000000000");
        assert_eq!(text(Real::NAN, 3), "null");
        assert_eq!(number(Real::NAN), Value::Null);
    }

    #[test]
    fn hand_written_scene_updates_are_json() {
        let mut points = String::new();
        push_points(
            &mut points,
            &[
                Vec3::new(1.0, -0.5, 1e-7),
                Vec3::new(19.999_999_9, 0.0, -0.0),
            ],
            6,
        );
        let line = format!(
            r#"{{"type":0,"pose":{IDENTITY_POSE},"thickness":0.6,"scale_invariant":false,"color":{},"colors":[],"indices":[],"points":{points}}}"#,
            temperature_color(50.0, 20.0, 90.0)
        );
        let message: Value =
            serde_json::from_str(&scene_update("centrelines", 1_500_000_001, &line, ""))
                .expect("valid JSON");
        let entity = &message["entities"][0];
        assert_eq!(entity["timestamp"]["sec"], 1);
        assert_eq!(entity["timestamp"]["nsec"], 500_000_001);
        assert_eq!(entity["lines"][0]["points"][1]["x"], 20.0);
        assert_eq!(entity["lines"][0]["points"][0]["z"], 0.0);
        assert_eq!(entity["lines"][0]["points"][0]["y"], -0.5);
        assert_eq!(entity["triangles"], json!([]));
    }

    #[test]
    fn path_keys_are_identifiers() {
        assert_eq!(path_key("tip"), "tip");
        assert_eq!(path_key("arch.end.F3"), "arch_end_F3");
        assert_eq!(path_key("a-b c"), "a_b_c");
    }
}
