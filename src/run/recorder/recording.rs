//! `run.mcap` as a recorder: [`crate::io::mcap`]'s recording, its position the last message; resumed by copying
//! the old recording up to it; its estimate the compressed messages of every state and snapshot.

use super::{Finishing, Recorder, RecorderKind, Setup, damaged, upto};
use crate::io::checkpoint::{Decoder, Encoder, Problem};
use crate::io::mcap::{McapRecorder, RecordingPosition};
use crate::io::mcap_salvage::{Salvage, salvage};
use crate::io::state::load_channels;
use crate::math::Real;
use crate::model::Model;
use crate::post::device::{device_sample_counts, patch_copies};
use crate::run::RunError;
use crate::run::estimate::{DiskPart, Sizing, digits};
use crate::solver::Simulation;
use std::path::Path;

/// `run.mcap` ([`crate::io::mcap`]), unless the design turns it off (`output.recording.enabled`).
pub(super) const RECORDING: RecorderKind = RecorderKind {
    name: "mcap",
    create: |setup, _| {
        let design = setup.design;
        if !design.output.recording.enabled {
            return Ok(Box::new(None::<McapRecorder>));
        }
        setup
            .folder
            .manifest()
            .claim(Path::new(MCAP_FILE))
            .map_err(RunError::other)?;
        let recorder = McapRecorder::create(
            &setup.folder.dir().join(MCAP_FILE),
            design,
            setup.info,
            &design.output.snapshots,
        )
        .map_err(RunError::other)?;
        Ok(Box::new(Some(recorder)))
    },
    check_resume: |_, position, _| {
        decode_recording(position).map_err(|p| damaged(MCAP_FILE, p))?;
        Ok(())
    },
    resume: |setup, _, position| {
        if !setup.design.output.recording.enabled {
            return Ok(Box::new(None::<McapRecorder>));
        }
        let position = decode_recording(position).map_err(|p| damaged(MCAP_FILE, p))?;
        Ok(Box::new(Some(resume_recording(setup, &position)?)))
    },
    estimate: |s| {
        if !s.design.output.recording.enabled {
            return DiskPart::new("no recording", 0);
        }
        DiskPart {
            holds_design_text: true,
            advice: Some((
                "output.recording.centreline_points",
                "record fewer centreline points per patch, or set `meshes: false`",
            )),
            ..DiskPart::new(MCAP_FILE, estimated_bytes(s) as u64)
        }
    },
};

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

/// Compressed bytes of an obstacle's entity in a `/obstacles` message (a primitive of about 400 bytes of JSON
/// that changes only in its size or position: charged at the state messages' compression).
const OBSTACLE_BYTES: Real = 100.0;

/// Compressed bytes of a centreline sample's colour with contact (the same two colour texts repeated): 1.
const SAMPLE_COLOR_BYTES: Real = 1.0;

/// `run.mcap` of a recording the design turns on: a state and the centrelines at every state, a mesh at every
/// snapshot, the vessel once, the obstacles at every state (a model with contact), the fixed records and the
/// design's text.
fn estimated_bytes(s: &Sizing<'_>) -> Real {
    let design = s.design;
    let model = s.model();
    let recording = &design.output.recording;
    let count = s.snapshots as Real;
    let point_counts = device_sample_counts(model, recording.centreline_points);
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
        let (v, t) = s.tube_mesh(recording.mesh_rings, recording.mesh_segments);
        let raw = 400.0 + v * s.point_bytes() + 3.0 * t * (digits(v) + 1.0);
        count * (raw / MESH_COMPRESSION + MESSAGE_BYTES)
    } else {
        0.0
    };
    // The vessel, recorded once: its centreline and, with a radius, its lumen at the recording's segments.
    let vessel = match &model.vessel {
        Some(vessel) => {
            let rings = vessel.points.len() as Real;
            let mesh = match vessel.radius {
                Some(_) => {
                    let m = recording.mesh_segments as Real;
                    let (v, t) = (rings * m + 2.0, 2.0 * m * rings);
                    v * s.point_bytes() + 3.0 * t * (digits(v) + 1.0)
                }
                None => 0.0,
            };
            let raw = 400.0 + rings * s.point_bytes() + mesh;
            raw / MESH_COMPRESSION + MESSAGE_BYTES
        }
        None => 0.0,
    };
    let obstacles = match &model.contact {
        Some(contact) => {
            contact.obstacles.len() as Real * OBSTACLE_BYTES
                + MESSAGE_BYTES
                + (unique + mirrored) * SAMPLE_COLOR_BYTES
        }
        None => 0.0,
    };
    s.states * (centrelines + state + obstacles)
        + meshes
        + vessel
        + RECORDING_FIXED_BYTES
        + design.source.len() as Real
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

/// The recording's file name in the run folder.
const MCAP_FILE: &str = "run.mcap";

fn decode_recording(bytes: &[u8]) -> Result<RecordingPosition, Problem> {
    let mut d = Decoder::new(bytes);
    let position = RecordingPosition {
        sequence: d.u32()?,
        last: d.option(|d| Ok((d.u64()?, d.usize()?, d.f64()?)))?,
        last_mesh: d.option(|d| d.usize())?,
    };
    d.finish()?;
    Ok(position)
}

/// The recording of a resumed run: the killed or interrupted run's `run.mcap` (salvaged, if it was cut short)
/// is copied up to the checkpoint's last message into a new recording built in a temporary file beside it,
/// which then replaces it. A recording that cannot be read is started afresh with a warning (its states before
/// the checkpoint are lost; the other outputs are whole).
fn resume_recording(
    setup: &Setup<'_>,
    position: &RecordingPosition,
) -> Result<McapRecorder, RunError> {
    let (design, dir) = (setup.design, setup.folder.dir());
    let path = dir.join(MCAP_FILE);
    let temporary = dir.join(crate::io::atomic::temporary_name(std::ffi::OsStr::new(
        MCAP_FILE,
    )));
    let mut recorder =
        McapRecorder::create(&temporary, design, setup.info, &design.output.snapshots)
            .map_err(RunError::other)?;
    let previous = salvage(&path)
        .map_err(RunError::other)
        .and_then(|_| std::fs::read(&path).map_err(RunError::other));
    let copied = match previous {
        Ok(bytes) => recorder
            .resume(&bytes, &path, position)
            .map_err(|e| e.to_string()),
        Err(e) => Err(crate::run::error_text(&e)),
    };
    match copied {
        Ok(n) if n as u64 == u64::from(position.sequence) => {}
        Ok(n) => setup.console.say(&format!(
            "warning: {} kept {n} of the {} messages recorded up to the checkpoint; the recording has a gap before it",
            path.display(),
            position.sequence
        )),
        Err(e) => setup.console.say(&format!(
            "warning: the recording {} cannot be continued ({e}); it holds the states from the checkpoint on",
            path.display()
        )),
    }
    recorder.flush_chunk().map_err(RunError::other)?;
    recorder
        .rename(&path)
        .map_err(|e| RunError::context(format!("cannot replace {}", path.display()), e))?;
    Ok(recorder)
}

impl Recorder for Option<McapRecorder> {
    fn name(&self) -> &'static str {
        RECORDING.name
    }

    fn position(&self) -> Vec<u8> {
        let p = self
            .as_ref()
            .map(McapRecorder::position)
            .unwrap_or_default();
        let mut e = Encoder::default();
        e.u32(p.sequence);
        e.option(p.last.as_ref(), |e, (log_time, step, time)| {
            e.u64(*log_time);
            e.usize(*step);
            e.f64(*time);
        });
        e.option(p.last_mesh.as_ref(), |e, step| e.usize(*step));
        e.0
    }

    fn flush(&mut self) -> Result<(), RunError> {
        match self {
            Some(recorder) => recorder.flush_chunk().map_err(RunError::other),
            None => Ok(()),
        }
    }

    fn abandon(&mut self) {
        if let Some(recorder) = self {
            let _ = recorder.close();
        }
    }

    /// Finishes the recording (or, after a write error or a second signal, closes it and salvages what it
    /// holds, removing it only if even that fails: a full disk).
    fn finish(&mut self, sim: &Simulation<'_>, f: &mut Finishing<'_>) {
        let Some(recorder) = self else {
            return;
        };
        let record_error = recorder.take_error().map(RunError::other);
        // A writer that failed once refuses every later write: only the salvage can finish the file.
        let closed = if record_error.is_some() || f.hurry {
            recorder.close()
        } else {
            recorder.finish(sim)
        };
        let mcap_path = f.dir.join(MCAP_FILE);
        let complete_to = format!("complete up to {}", upto(recorder.last_time()));
        // The first error is the cause; closing after it fails for that reason too.
        let (closed_bytes, cause) = match closed {
            Ok(bytes) => (bytes, record_error),
            Err(e) => (0, Some(record_error.unwrap_or_else(|| RunError::other(e)))),
        };
        f.mcap_bytes = match cause {
            None => {
                f.state(MCAP_FILE, true, complete_to);
                closed_bytes
            }
            Some(e) => {
                let text = crate::run::error_text(&e);
                let bytes = match salvage(&mcap_path) {
                    Ok(Salvage::Finished {
                        after,
                        last_log_time,
                        ..
                    }) => {
                        let t = last_log_time.map(|ns| ns as Real * 1e-9);
                        f.state(
                            MCAP_FILE,
                            true,
                            format!(
                                "finalised up to {}; later states not recorded: {text}",
                                upto(t)
                            ),
                        );
                        after
                    }
                    Ok(Salvage::AlreadyValid { bytes }) => {
                        f.state(
                            MCAP_FILE,
                            true,
                            format!("{complete_to}; later states not recorded: {text}"),
                        );
                        bytes
                    }
                    Err(salvage_error) => {
                        let removed =
                            crate::io::no_follow::remove_inside(f.dir, Path::new(MCAP_FILE))
                                .unwrap_or(false);
                        f.state(
                            MCAP_FILE,
                            false,
                            format!(
                                "incomplete ({text}) and cannot be finished ({salvage_error}){}",
                                if removed { ": removed" } else { "" }
                            ),
                        );
                        0
                    }
                };
                f.problems.push(e);
                bytes
            }
        };
    }
}
