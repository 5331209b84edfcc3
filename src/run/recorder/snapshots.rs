//! The snapshots as a recorder: [`crate::io::snapshots`]' tube meshes and fields, with the configuration figures
//! drawn when the run ends; its position the snapshots written.

use super::{Finishing, Recorder, RecorderKind, damaged};
use crate::io::checkpoint::{Decoder, Encoder, Problem};
use crate::io::snapshots::{Snapshot, SnapshotWriter};
use crate::io::summary::RunSummaryFile;
use crate::math::Real;
use crate::math::quote::short_time;
use crate::model::cycle::Phase;
use crate::run::RunError;
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
};

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
