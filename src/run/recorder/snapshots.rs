//! The snapshots as a recorder: [`crate::io::snapshots`]' tube meshes and fields, with the configuration figures
//! drawn when the run ends; its position the snapshots written; its estimate the files of each snapshot by kind.

use super::{Finishing, Recorder, RecorderKind, damaged};
use crate::io::checkpoint::{Decoder, Encoder, Problem};
use crate::io::snapshots::{Snapshot, SnapshotWriter};
use crate::io::summary::RunSummaryFile;
use crate::math::Real;
use crate::math::quote::short_time;
use crate::model::cycle::Phase;
use crate::run::RunError;
use crate::run::estimate::{DiskPart, Sizing, digits};
use crate::solver::Simulation;
use std::path::{Path, PathBuf};

/// The snapshots and their configuration figures ([`crate::io::snapshots`]).
pub(super) const SNAPSHOTS: RecorderKind = RecorderKind {
    name: "snapshots",
    create: |setup, sim| {
        let design = setup.design;
        let writer =
            SnapshotWriter::create(setup.folder.dir(), &design.output.snapshots, sim.model())
                .map_err(RunError::other)?
                .with_manifest(setup.folder.manifest().clone());
        Ok(Box::new(writer))
    },
    check_resume: |_, position, _| {
        decode_snapshots(position).map_err(|p| damaged("snapshots/", p))?;
        Ok(())
    },
    resume: |setup, sim, position| {
        let (written, last) = decode_snapshots(position).map_err(|p| damaged("snapshots/", p))?;
        let (dir, manifest) = (setup.folder.dir(), setup.folder.manifest());
        // Snapshots the checkpoint does not list are from after it (or the final one of an interrupted run).
        let kept: std::collections::BTreeSet<&Path> = written
            .iter()
            .flat_map(|s| s.files.iter().map(PathBuf::as_path))
            .collect();
        for listed in manifest.listed() {
            if listed.starts_with(SnapshotWriter::FOLDER) && !kept.contains(listed.as_path()) {
                crate::io::no_follow::remove_inside(dir, &listed).map_err(|e| {
                    RunError::context(format!("cannot remove {}", dir.join(&listed).display()), e)
                })?;
            }
        }
        let writer = SnapshotWriter::create(dir, &setup.design.output.snapshots, sim.model())
            .map_err(RunError::other)?
            .with_manifest(manifest.clone())
            .resumed(written, last);
        Ok(Box::new(writer))
    },
    estimate: |s| {
        let files = estimated_files(s);
        DiskPart {
            files: files.to_vec(),
            advice: Some((
                "output.snapshots",
                "take fewer snapshots (fewer `between` or `times`, a larger `every`) or smaller ones (fewer `rings`, `segments`, one of the `formats`)",
            )),
            ..DiskPart::new(
                format!("{} snapshots", s.snapshots),
                files.iter().map(|&(_, bytes)| bytes).sum(),
            )
        }
    },
};

/// Bytes of an OBJ `v x y z` line: three coordinates in Rust's shortest round-trip form, each with a sign,
/// two integer digits and up to 16 decimals, 62 in all. Measured on the straight stent: 57 on average, 67
/// at most.
const OBJ_VERTEX_LINE_BYTES: Real = 62.0;

/// Bytes of an OBJ file's comment lines besides the design name: about 150 (144 for the straight stent).
const OBJ_HEADER_BYTES: Real = 200.0;

/// Bytes of a field file besides its arrays: the XML of 18 arrays with their units (4.1 kB measured).
const VTP_FIXED_BYTES: Real = 6_000.0;

/// Bytes of a `run.pvd` line (about 100 measured).
const PVD_LINE_BYTES: Real = 120.0;

/// The snapshots' files by kind \[bytes\]: the binary STL and OBJ files of all snapshots, their field files and
/// `run.pvd` ([`crate::io::vtk`]), and the vessel's lumen, `snapshots/vessel_lumen.stl`, for a stent on a file
/// centreline with a lumen radius ([`crate::io::snapshots::VESSEL_FILE`]).
fn estimated_files(s: &Sizing<'_>) -> [(&'static str, u64); 4] {
    let model = s.model();
    let snapshot = &s.design.output.snapshots;
    let count = s.snapshots as Real;
    let (vertices, triangles) = s.tube_mesh(snapshot.rings, snapshot.segments);
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
            + model.name().len() as Real
            + vertices * OBJ_VERTEX_LINE_BYTES
            + triangles * (3.0 * digits(vertices) + 5.0));
    // The field files: per collocation point three coordinates, 34 field values (and two per obstacle of a
    // model with contact: gap and pressure; with the wires' contact its pressure) and a connectivity entry,
    // 8 bytes each in base64 (4/3), plus the XML; run.pvd a line per snapshot.
    let vtp = if snapshot.vtk {
        let points: usize = model.patches.iter().map(|p| p.curve.num_points()).sum();
        let values = 38.0
            + 2.0 * model.contact.as_ref().map_or(0, |c| c.obstacles.len()) as Real
            + Real::from(u8::from(model.wire_contact.is_some()));
        count * (VTP_FIXED_BYTES + points as Real * values * 8.0 * 4.0 / 3.0 + PVD_LINE_BYTES)
    } else {
        0.0
    };
    // The vessel's lumen, written once with the first snapshot: a closed tube of the vessel's rings.
    let lumen = match &model.vessel {
        Some(vessel) if vessel.radius.is_some() => {
            let rings = vessel.points.len() as Real;
            let m = snapshot.segments as Real;
            84.0 + 50.0 * (2.0 * m * rings)
        }
        _ => 0.0,
    };
    [
        ("STL", stl as u64),
        ("OBJ", obj as u64),
        ("fields", vtp as u64),
        ("vessel lumen", lumen as u64),
    ]
}

type SnapshotsPosition = (Vec<Snapshot>, Option<(usize, Real)>);

fn decode_snapshots(bytes: &[u8]) -> Result<SnapshotsPosition, Problem> {
    let mut d = Decoder::new(bytes);
    let written = d.list(40, |d| {
        Ok(Snapshot {
            step: d.usize()?,
            time: d.f64()?,
            phase: d.option(|d| {
                let name = d.str()?;
                Phase::parse(&name)
                    .ok_or_else(|| Problem::Damaged(format!("an unknown snapshot phase `{name}`")))
            })?,
            files: d.list(8, |d| Ok(PathBuf::from(d.str()?)))?,
            triangles: d.usize()?,
            volume: d.f64()?,
        })
    })?;
    let last = d.option(|d| Ok((d.usize()?, d.f64()?)))?;
    d.finish()?;
    Ok((written, last))
}

impl Recorder for SnapshotWriter {
    fn name(&self) -> &'static str {
        SNAPSHOTS.name
    }

    fn position(&self) -> Vec<u8> {
        let mut e = Encoder::default();
        e.list(self.snapshots(), |e, s| {
            e.usize(s.step);
            e.f64(s.time);
            e.option(s.phase.as_ref(), |e, p| e.str(p.name()));
            e.list(&s.files, |e, f| e.str(&f.to_string_lossy()));
            e.usize(s.triangles);
            e.f64(s.volume);
        });
        e.option(self.last_seen().as_ref(), |e, (step, time)| {
            e.usize(*step);
            e.f64(*time);
        });
        e.0
    }

    fn summarise(&self, summary: &mut RunSummaryFile, _: &Simulation<'_>) {
        summary.snapshots = self.snapshots().iter().map(Into::into).collect();
    }

    /// Writes the final snapshot (skipped after a second signal, and after any output error — most often a full
    /// disk: the room left is for the charts and the summary) and the configuration figures.
    fn finish(&mut self, sim: &Simulation<'_>, f: &mut Finishing<'_>) {
        let snapshots = self;
        let snapshot_error = snapshots.take_error().map(RunError::other);
        let final_snapshot = if f.hurry || snapshot_error.is_some() || !f.problems.is_empty() {
            None
        } else {
            snapshots.finish(sim).err().map(RunError::other)
        };
        let written = snapshots.snapshots();
        let listed = written
            .last()
            .map(|s| {
                format!(
                    ", the last at step {} (t = {} s)",
                    s.step,
                    short_time(s.time)
                )
            })
            .unwrap_or_default();
        let count = written.len();
        match snapshot_error.or(final_snapshot) {
            Some(e) => {
                f.state(
                    "snapshots/",
                    false,
                    format!(
                        "{count} complete{listed}; the next not written: {}",
                        crate::run::error_text(&e)
                    ),
                );
                f.problems.push(e);
            }
            None if f.hurry => f.state(
                "snapshots/",
                true,
                format!("{count} complete{listed}; final snapshot skipped (second signal)"),
            ),
            None => f.state("snapshots/", true, format!("{count} complete{listed}")),
        }
        f.figures = Some(snapshots.write_configuration_figures(sim.model()));
    }
}
