//! `run.mcap`: a recording of the run that Foxglove opens (MCAP, zstd-compressed chunks, JSON messages with a
//! JSON Schema per channel).
//!
//! | topic | schema | when | content |
//! |---|---|---|---|
//! | `/state` | `stentkit.State` | every step, the initial state and each requested time an error-controlled run reaches between its steps | time, step size, temperature, loads, Newton iterations and residuals, step cuts, probe displacements, recovery measures |
//! | `/centrelines` | `foxglove.SceneUpdate` | every step | entity `centrelines`: one `LINE_STRIP` per rod of the full device (mirrored back), coloured by temperature; with contact, the samples touching an obstacle in green (`mcap/obstacles.rs`); with the wires' contact, its pairs as a magenta `LINE_LIST` (each pressing sample to its closest point on the other wire, of the model as simulated) |
//! | `/device` | `foxglove.SceneUpdate` | snapshot steps | entity `device`: the full device's closed tube mesh (`TriangleListPrimitive` with indices) |
//! | `/vessel` | `foxglove.SceneUpdate` | once, at the start (a stent on a file centreline) | entity `vessel`: the vessel's centreline (`LINE_STRIP`) and its lumen (a translucent closed tube) |
//! | `/obstacles` | `foxglove.SceneUpdate` | every step (a model with contact) | entity `obstacle.<name>` per obstacle: a cylinder (`CylinderPrimitive`, its diameter following its schedule) or a plane (a large thin square `CubePrimitive`), translucent (`mcap/obstacles.rs`) |
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
//!
//! The recorder lives here; the channels' JSON Schemas are in `mcap/schema.rs` and the hand-written message
//! JSON (fixed-point coordinates, colours, scene updates) in `mcap/format.rs`, both private:
//! [`coordinate_decimals`], [`path_key`], [`scene_update_schema`] and [`FRAME_ID`] are re-exported here.

mod format;
mod obstacles;
mod schema;

/// Colour of the wires' contact pairs on `/centrelines` (`foxglove.Color`, opaque magenta).
const WIRE_CONTACT_COLOR: &str = r#"{"r":0.900,"g":0.100,"b":0.800,"a":1}"#;

pub(crate) use format::{coordinate_decimals, path_key};
pub(crate) use schema::scene_update_schema;

use super::output::{RecordingSettings, RunDesign, SnapshotSettings};
use super::snapshots::SnapshotSchedule;
use super::state::{LoadChannel, StateSample, load_channels};
use crate::math::Real;
use crate::post::device::{current_device_shapes, device_rods, device_tube_mesh};
use crate::solver::{Observer, Simulation, StepReport};
use format::{IDENTITY_POSE, color, number, push_points, scene_update, temperature_color};
use schema::{StateKeys, state_schema};
use serde_json::{Map, Value, json};
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

/// Topic of the state channel.
pub(crate) const STATE_TOPIC: &str = "/state";
/// Topic of the centrelines.
pub(crate) const CENTRELINE_TOPIC: &str = "/centrelines";
/// Topic of the tube meshes.
pub(crate) const DEVICE_TOPIC: &str = "/device";
/// Topic of the vessel a stent sits on (a centreline read from a file): one message at the start.
pub(crate) const VESSEL_TOPIC: &str = "/vessel";
/// Topic of the obstacles of a model with contact: one message per state.
pub(crate) const OBSTACLE_TOPIC: &str = "/obstacles";

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
    /// An earlier recording to continue could not be read.
    #[error("cannot read {path}: {source}")]
    Read {
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

/// How far a recording has got: what a checkpoint records and a resumed run continues from.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RecordingPosition {
    /// Sequence number of the last message written (messages are numbered from 1 across channels).
    pub sequence: u32,
    /// Log time \[ns\], step and time of the last state recorded.
    pub last: Option<(u64, usize, Real)>,
    /// Step of the last mesh recorded.
    pub last_mesh: Option<usize>,
}

/// Records a run into an MCAP file as the simulation reports its steps.
pub struct McapRecorder {
    path: PathBuf,
    writer: Option<::mcap::Writer<BufWriter<File>>>,
    state_channel: u16,
    centreline_channel: u16,
    device_channel: Option<u16>,
    /// The vessel's channel, until its one message is written.
    vessel_channel: Option<u16>,
    /// The obstacles' channel and drawing (a model with contact).
    obstacles: Option<(u16, obstacles::ObstacleDrawing)>,
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
    /// Time of the last step recorded (a requested state between steps is not one), for the snapshot schedule.
    last_step_time: Option<Real>,
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
        design: &impl RunDesign,
        info: &RunInfo,
        snapshots: &SnapshotSettings,
    ) -> Result<Self, McapError> {
        let model = design.model();
        let settings = design.output().recording.clone();
        let file = super::no_follow::create(path).map_err(|source| McapError::Create {
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
            ("design", model.name().to_string()),
            ("design_file", design.path().display().to_string()),
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
        let name = design.path().file_name().map_or_else(
            || "design.yaml".to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        writer
            .attach(&::mcap::Attachment {
                log_time: 0,
                create_time: 0,
                name,
                media_type: "application/yaml".into(),
                data: Cow::Borrowed(design.source().as_bytes()),
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
        let vessel_channel = match &model.vessel {
            Some(_) => Some(
                writer
                    .add_channel(scene_schema, VESSEL_TOPIC, "json", &no_metadata)
                    .map_err(write_error)?,
            ),
            None => None,
        };
        let obstacles = match obstacles::ObstacleDrawing::new(model) {
            Some(drawing) => Some((
                writer
                    .add_channel(scene_schema, OBSTACLE_TOPIC, "json", &no_metadata)
                    .map_err(write_error)?,
                drawing,
            )),
            None => None,
        };
        let thickness = (0..model.patches.len())
            .flat_map(|k| {
                let d = model.sections[model.patches[k].section].diameter();
                std::iter::repeat_n(d, crate::post::device::patch_copies(model, k).len())
            })
            .collect();
        Ok(Self {
            path: path.to_path_buf(),
            writer: Some(writer),
            state_channel,
            centreline_channel,
            device_channel,
            vessel_channel,
            obstacles,
            channels,
            keys,
            schedule: SnapshotSchedule::new(snapshots, model),
            settings,
            thickness,
            temperature_range: model.temperature().range(),
            decimals: coordinate_decimals(
                model
                    .patches
                    .iter()
                    .flat_map(|p| p.curve.points().iter().map(|q| q.norm()))
                    .fold(0.0, Real::max),
            ),
            sequence: 0,
            last: None,
            last_step_time: None,
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

    /// How far the recording has got (for a checkpoint).
    pub fn position(&self) -> RecordingPosition {
        RecordingPosition {
            sequence: self.sequence,
            last: self.last,
            last_mesh: self.last_mesh,
        }
    }

    /// Continues the recording of a resumed run: copies the messages of `previous` (the bytes of the killed or
    /// interrupted run's recording, a valid MCAP file — salvaged if need be) numbered up to `position.sequence`
    /// into this recording, each onto the channel of the same topic with its sequence number and times, and
    /// continues from `position`. Returns the number of messages copied: fewer than `position.sequence` when
    /// the previous recording lost some (its last chunks, before a salvage).
    ///
    /// # Errors
    /// [`McapError::Read`] when `previous` cannot be read, [`McapError::Write`].
    pub fn resume(
        &mut self,
        previous: &[u8],
        previous_path: &Path,
        position: &RecordingPosition,
    ) -> Result<usize, McapError> {
        let read_error = |source| McapError::Read {
            path: previous_path.to_path_buf(),
            source,
        };
        let channels: BTreeMap<&str, u16> = [
            (STATE_TOPIC, Some(self.state_channel)),
            (CENTRELINE_TOPIC, Some(self.centreline_channel)),
            (DEVICE_TOPIC, self.device_channel),
            (OBSTACLE_TOPIC, self.obstacles.as_ref().map(|(id, _)| *id)),
        ]
        .into_iter()
        .filter_map(|(topic, id)| id.map(|id| (topic, id)))
        .collect();
        // The position is taken over whatever the copy finds: the continued messages are numbered after the
        // checkpoint's in any case.
        self.sequence = position.sequence;
        self.last = position.last;
        self.last_mesh = position.last_mesh;
        // A checkpoint is taken after a step: its last state is a step's.
        self.last_step_time = position.last.map(|(_, _, t)| t);
        let mut copied = 0;
        for message in ::mcap::MessageStream::new(previous).map_err(read_error)? {
            let message = message.map_err(read_error)?;
            if message.sequence > position.sequence {
                continue;
            }
            let Some(&channel) = channels.get(message.channel.topic.as_str()) else {
                continue;
            };
            let Some(writer) = &mut self.writer else {
                break;
            };
            writer
                .write_to_known_channel(
                    &::mcap::records::MessageHeader {
                        channel_id: channel,
                        sequence: message.sequence,
                        log_time: message.log_time,
                        publish_time: message.publish_time,
                    },
                    &message.data,
                )
                .map_err(|source| McapError::Write {
                    path: self.path.clone(),
                    source,
                })?;
            copied += 1;
        }
        Ok(copied)
    }

    /// Moves the file being written to `to` (a rename in the same folder: the open file is kept), e.g. a
    /// recording built in a temporary file over the one it replaces.
    ///
    /// # Errors
    /// The I/O error of the rename; the recording is then still at its old path.
    pub fn rename(&mut self, to: &Path) -> std::io::Result<()> {
        std::fs::rename(&self.path, to)?;
        self.path = to.to_path_buf();
        Ok(())
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
        if let Some(r) = &sample.recovery {
            let map = message.as_object_mut().expect("object literal");
            map.insert("recovery_ratio_mean".into(), number(r.ratio_mean));
            map.insert("recovery_ratio_max".into(), number(r.ratio_max));
            if let Some(d) = r.delta_r {
                map.insert("delta_r".into(), number(d));
            }
        }
        message
    }

    /// The centrelines at `log_time`; with contact at time `contact_time`, each sample touching an obstacle
    /// coloured ([`obstacles::TOUCH_COLOR`]), the others by temperature.
    fn centreline_message(
        &self,
        sim: &Simulation<'_>,
        log_time: u64,
        contact_time: Option<Real>,
    ) -> String {
        let shapes = current_device_shapes(sim, self.settings.centreline_points);
        let (lo, hi) = self.temperature_range;
        let color = temperature_color(sim.model().temperature().value(sim.schedule_time()), lo, hi);
        // Per patch, the per-sample colours (JSON array contents; empty: the line's colour throughout).
        let colors: Vec<String> = shapes
            .iter()
            .enumerate()
            .map(|(k, shape)| match (&self.obstacles, contact_time) {
                (Some((_, drawing)), Some(t)) => shape
                    .points
                    .iter()
                    .map(|x| {
                        if drawing.touches(k, x, t) {
                            obstacles::TOUCH_COLOR
                        } else {
                            &color
                        }
                    })
                    .collect::<Vec<&str>>()
                    .join(","),
                _ => String::new(),
            })
            .collect();
        let mut lines = String::new();
        for (i, ((k, points), thickness)) in device_rods(sim.model(), &shapes)
            .zip(&self.thickness)
            .enumerate()
        {
            if i > 0 {
                lines.push(',');
            }
            let _ = write!(
                lines,
                r#"{{"type":0,"pose":{IDENTITY_POSE},"thickness":{thickness},"scale_invariant":false,"color":{color},"colors":[{}],"indices":[],"points":"#,
                colors[k]
            );
            push_points(&mut lines, &points, self.decimals);
            lines.push('}');
        }
        // The wires' contact pairs: a segment from each pressing sample to its closest point on the other wire.
        if let Some(report) = sim.wire_contact().filter(|r| !r.pairs.is_empty()) {
            let points: Vec<crate::math::Vec3> =
                report.pairs.iter().flat_map(|&(a, b)| [a, b]).collect();
            let thickness = self.thickness.first().copied().unwrap_or(0.1);
            let _ = write!(
                lines,
                r#",{{"type":2,"pose":{IDENTITY_POSE},"thickness":{thickness},"scale_invariant":false,"color":{WIRE_CONTACT_COLOR},"colors":[],"indices":[],"points":"#
            );
            push_points(&mut lines, &points, self.decimals);
            lines.push('}');
        }
        scene_update("centrelines", log_time, &lines, "")
    }

    /// The vessel: its centreline (a thin grey line) and, with a radius, its lumen (a translucent tube).
    fn vessel_message(
        &self,
        vessel: &crate::model::Vessel,
        log_time: u64,
    ) -> Result<String, McapError> {
        let mut line = format!(
            r#"{{"type":0,"pose":{IDENTITY_POSE},"thickness":{},"scale_invariant":false,"color":{},"colors":[],"indices":[],"points":"#,
            self.thickness.first().copied().unwrap_or(0.1),
            color(0.5, 0.5, 0.5)
        );
        push_points(&mut line, &vessel.points, self.decimals);
        line.push('}');
        let mut triangles = String::new();
        if let Some(lumen) = crate::post::vessel::lumen_mesh(vessel, self.settings.mesh_segments) {
            let mesh = lumen.map_err(|source| McapError::Mesh {
                step: 0,
                patch: "vessel lumen".into(),
                source,
            })?;
            triangles = self.triangle_list(&mesh, r#"{"r":0.8,"g":0.3,"b":0.3,"a":0.25}"#);
        }
        Ok(scene_update("vessel", log_time, &line, &triangles))
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
        let triangles = self.triangle_list(&mesh, &color(0.80, 0.72, 0.45));
        Ok(scene_update("device", log_time, "", &triangles))
    }

    /// A `TriangleListPrimitive` of `mesh` in colour `color` (JSON).
    fn triangle_list(&self, mesh: &crate::geometry::mesh::TriangleMesh, color: &str) -> String {
        let mut triangles =
            format!(r#"{{"pose":{IDENTITY_POSE},"color":{color},"colors":[],"points":"#);
        push_points(&mut triangles, &mesh.vertices, self.decimals);
        triangles.push_str(r#","indices":["#);
        for (i, index) in mesh.triangles.iter().flatten().enumerate() {
            if i > 0 {
                triangles.push(',');
            }
            let _ = write!(triangles, "{index}");
        }
        triangles.push_str("]}");
        triangles
    }

    /// Records the state of `sim` (`report`: of a step, or of a requested time inside one when `requested`;
    /// `None`: the initial state), with a mesh when the snapshot schedule has one due. A requested state's
    /// record does not move the schedule's last step (`previous`): its mesh is due at a requested snapshot time
    /// only.
    fn record(
        &mut self,
        sim: &Simulation<'_>,
        report: Option<&StepReport>,
        requested: bool,
    ) -> Result<(), McapError> {
        let step = match report {
            Some(_) if requested => sim.step_count(),
            Some(r) => r.step,
            None => 0,
        };
        let time = sim.time();
        let nominal = (time.max(0.0) * 1e9).round() as u64;
        let log_time = match self.last {
            Some((last, _, _)) => nominal.max(last + 1),
            None => nominal,
        };
        let previous = self.last_step_time.unwrap_or(0.0);
        self.last = Some((log_time, step, time));
        if !requested {
            self.last_step_time = Some(time);
        }
        let sample = StateSample::of(sim, &self.channels, report);
        let state = self.state_message(&sample).to_string();
        self.write(self.state_channel, log_time, state.as_bytes())?;
        let contact_time = sim.contact().map(|c| c.time);
        let centrelines = self.centreline_message(sim, log_time, contact_time);
        self.write(self.centreline_channel, log_time, centrelines.as_bytes())?;
        if let (Some((channel, drawing)), Some(t)) = (&self.obstacles, contact_time) {
            let message = drawing.message(t, log_time, self.decimals);
            self.write(*channel, log_time, message.as_bytes())?;
        }
        if let (Some(channel), Some(vessel)) = (self.vessel_channel.take(), &sim.model().vessel) {
            let message = self.vessel_message(vessel, log_time)?;
            self.write(channel, log_time, message.as_bytes())?;
        }
        let due = if requested {
            self.schedule.is_requested(time)
        } else {
            self.schedule.is_due(step, previous, time)
        };
        if self.device_channel.is_some() && due {
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

    fn observe(
        &mut self,
        sim: &Simulation<'_>,
        report: Option<&StepReport>,
        requested: bool,
    ) -> ControlFlow<()> {
        if self.error.is_some() {
            return ControlFlow::Break(());
        }
        match self.record(sim, report, requested) {
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
        self.observe(sim, None, false)
    }

    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        self.observe(sim, Some(report), false)
    }

    /// The state at a requested time inside a step, with its mesh at a requested snapshot time, as the snapshots
    /// have it.
    fn requested(&mut self, sim: &Simulation<'_>, report: &StepReport) {
        // (A write error is kept: the next step asks the run to stop.)
        let _ = self.observe(sim, Some(report), true);
    }
}
