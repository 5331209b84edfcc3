//! `history.csv` as a recorder: the rows of [`crate::io::history`], its position the file's length and rows,
//! its estimate a row per state at its longest.

use super::{Finishing, Recorder, RecorderKind, damaged, upto};
use crate::io::checkpoint::{Decoder, Encoder, Problem};
use crate::io::history::{HistoryPosition, HistoryWriter};
use crate::io::summary::RunSummaryFile;
use crate::math::Real;
use crate::model::Model;
use crate::run::RunError;
use crate::run::estimate::DiskPart;
use crate::solver::Simulation;
use std::path::Path;

/// `history.csv` ([`crate::io::history`]).
pub(super) const HISTORY: RecorderKind = RecorderKind {
    name: "history",
    create: |setup, sim| {
        let dir = setup.folder.dir();
        setup
            .folder
            .manifest()
            .claim(Path::new(HISTORY_FILE))
            .map_err(RunError::other)?;
        let path = dir.join(HISTORY_FILE);
        let writer = HistoryWriter::create(&path, sim, &setup.design.output.strain_limits)
            .map_err(|e| RunError::context(format!("cannot write {}", path.display()), e))?;
        Ok(Box::new(writer))
    },
    check_resume: |dir, position, step| {
        let position = decode_history(position).map_err(|p| damaged("history.csv", p))?;
        crate::io::history::check_resumable(&dir.join(HISTORY_FILE), &position).map_err(|e| {
            RunError::Refused(format!(
                "{e}; the run cannot be continued from its checkpoint at step {step} without the rows before it \
                 (nothing was changed: put the history back, or run the design again with --force)"
            ))
        })
    },
    resume: |setup, sim, position| {
        let position = decode_history(position).map_err(|p| damaged("history.csv", p))?;
        let path = setup.folder.dir().join(HISTORY_FILE);
        let writer = HistoryWriter::resume(
            &path,
            sim.model(),
            position,
            &setup.design.output.strain_limits,
        )
        .map_err(|e| RunError::context(format!("cannot continue {}", path.display()), e))?;
        Ok(Box::new(writer))
    },
    estimate: |s| {
        let design = s.design;
        let rows = s.states + 1.0;
        let bytes = rows * row_bytes(&design.model, &design.output.strain_limits);
        DiskPart {
            advice: Some(("time.step", "take larger time steps")),
            ..DiskPart::new(HISTORY_FILE, bytes as u64)
        }
    },
};

/// The history's file name in the run folder.
const HISTORY_FILE: &str = "history.csv";

/// Bytes of a `history.csv` row (io::history's formats at their longest): time (17), three displacements per
/// probe (20 each), temperature (11), iterations (3), residual (10), cuts (3), the recovery ratios (18 each),
/// Δr (17), the device's diameter and length (17 each) of a programme, the largest node displacement (16), the peak surface strain (16), its patch
/// (the longest name) and arc length (16), one peak per material with a strain limit (16), per obstacle of a
/// model with contact its force components and radial force (17 each), points (6), penetration, friction
/// work and the three apposition columns (14 each), the `requested` mark (2) of a model with record times, the
/// line end.
fn row_bytes(model: &Model, strain_limits: &[Option<Real>]) -> Real {
    let name = model
        .patches
        .iter()
        .map(|p| p.name.len())
        .max()
        .unwrap_or(0) as Real;
    let limits = strain_limits.iter().flatten().count() as Real;
    let peaks = 16.0 + 17.0 + name + 1.0 + 17.0 + 17.0 * limits;
    let recovery = match &model.programme {
        Some(p) => 36.0 + if p.is_radial() { 18.0 } else { 0.0 } + 34.0,
        None => 0.0,
    };
    let contact = 144.0 * model.contact.as_ref().map_or(0, |c| c.obstacles.len()) as Real;
    17.0 + 60.0 * model.probes.len() as Real
        + 11.0
        + 3.0
        + 11.0
        + 3.0
        + recovery
        + peaks
        + contact
        + if model.record_times().is_empty() {
            0.0
        } else {
            2.0
        }
        + 1.0
}

pub(super) fn decode_history(bytes: &[u8]) -> Result<HistoryPosition, Problem> {
    let mut d = Decoder::new(bytes);
    let position = HistoryPosition {
        bytes: d.u64()?,
        rows: d.usize()?,
        last_time: d.option(|d| d.f64())?,
    };
    d.finish()?;
    Ok(position)
}

impl Recorder for HistoryWriter {
    fn name(&self) -> &'static str {
        HISTORY.name
    }

    fn position(&self) -> Vec<u8> {
        let p = self.position();
        let mut e = Encoder::default();
        e.u64(p.bytes);
        e.usize(p.rows);
        e.option(p.last_time.as_ref(), |e, t| e.f64(*t));
        e.0
    }

    fn take_warnings(&mut self) -> Vec<String> {
        self.take_warnings()
    }

    fn summarise(&self, summary: &mut RunSummaryFile, sim: &Simulation<'_>) {
        summary.peak_surface_strain = self.peak_surface_strain().cloned();
        summary.contact = self.contact_peaks().to_vec();
        summary.wire_touch = sim.wire_touch();
        if let Some(report) = sim.contact() {
            let now = crate::io::contact::appositions(sim.model(), &report);
            for (peaks, a) in summary.contact.iter_mut().zip(now) {
                peaks.apposition = Some(a);
            }
        }
        if sim.model().programme.is_some() {
            let track = self.deployment();
            summary.deployment = Some(crate::io::summary::Deployment {
                recoil: track.recoil(),
                foreshortening: track.foreshortening(),
                crowns: crate::post::deployment::crown_fits(sim),
            });
        }
    }

    fn finish(&mut self, _: &Simulation<'_>, f: &mut Finishing<'_>) {
        let path = f.dir.join(HISTORY_FILE);
        let writer = self;
        match writer.take_error() {
            Some(e) => {
                let e = RunError::context(format!("cannot write {}", path.display()), e);
                f.state(
                    HISTORY_FILE,
                    true,
                    format!(
                        "complete up to {} ({} rows); later rows not written: {}",
                        upto(writer.last_time()),
                        writer.rows(),
                        crate::run::error_text(&e)
                    ),
                );
                f.problems.push(e);
            }
            None => f.state(
                HISTORY_FILE,
                true,
                format!("complete up to {}", upto(writer.last_time())),
            ),
        }
    }
}
