//! `history.csv` as a recorder: the rows of [`crate::io::history`], its position the file's length and rows.

use super::{Finishing, Recorder, RecorderKind, damaged, upto};
use crate::io::checkpoint::{Decoder, Encoder, Problem};
use crate::io::history::{HistoryPosition, HistoryWriter};
use crate::io::summary::RunSummaryFile;
use crate::run::RunError;
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
    resume: |setup, _, position| {
        let position = decode_history(position).map_err(|p| damaged("history.csv", p))?;
        let path = setup.folder.dir().join(HISTORY_FILE);
        let writer = HistoryWriter::resume(&path, position, &setup.design.output.strain_limits)
            .map_err(|e| RunError::context(format!("cannot continue {}", path.display()), e))?;
        Ok(Box::new(writer))
    },
};

/// The history's file name in the run folder.
const HISTORY_FILE: &str = "history.csv";

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

    fn summarise(&self, summary: &mut RunSummaryFile, _: &Simulation<'_>) {
        summary.peak_surface_strain = self.peak_surface_strain().cloned();
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
