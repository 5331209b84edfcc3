//! The recorders of a run: each output that follows the simulation step by step (`history.csv`, the
//! snapshots, `run.mcap`, the charts) is a [`Recorder`], and [`RECORDERS`] is the list the run takes them from.
//!
//! A recorder owns its files (it claims them in the run folder's manifest as it creates them), its position in a
//! checkpoint (the bytes [`Recorder::position`] encodes and its kind's `resume` decodes, with
//! `crate::io::checkpoint::Encoder` and `crate::io::checkpoint::Decoder`), its resume (its kind's
//! `check_resume` before anything is written, then `resume`), its part of `summary.json`
//! ([`Recorder::summarise`]), how it is finished whatever happened ([`Recorder::finish`]: the state of its
//! files and its problem, if any) and what it will write, estimated before the run starts (its kind's
//! `estimate`, a [`DiskPart`] of [`super::estimate`]). The run ([`super`]) knows none of them by name: it makes
//! them from the list, observes the simulation through them, times each (`summary.json`'s `timing.recording`,
//! by name), saves and restores their positions by name and finishes them in the list's order; the disk
//! estimate (`check`, the run's and the sweep's refusals) adds up their parts in the list's order.
//!
//! A new recorder is one module here with its [`RecorderKind`] and [`Recorder`] (and, for a new file format, its
//! writer in [`crate::io`]), its `mod` line and one line in [`RECORDERS`].

mod charts;
#[cfg(test)]
mod contact_tests;
mod history;
mod recording;
mod snapshots;

use super::estimate::{DiskPart, Sizing};
use super::{Console, RunError};
use crate::design::Design;
use crate::io::checkpoint::Problem;
use crate::io::mcap::RunInfo;
use crate::io::run_folder::{Manifest, RunFolder};
use crate::io::summary::{OutputState, RunSummaryFile};
use crate::math::Real;
use crate::math::quote::short_time;
use crate::solver::{Observer, Simulation};
use std::path::{Path, PathBuf};

/// An output of a run that follows the simulation (module docs). As an [`Observer`] it sees the start and
/// every converged step; a write error asks the run to stop (`ControlFlow::Break`) and is kept for
/// [`Recorder::finish`].
pub trait Recorder: Observer {
    /// Its kind's name ([`RecorderKind::name`]).
    fn name(&self) -> &'static str;

    /// Where it stands, for a checkpoint: the bytes its kind's `resume` continues from.
    fn position(&self) -> Vec<u8>;

    /// Warnings found since the last call, to be shown and kept in `summary.json`'s `strain_limit_warnings`.
    fn take_warnings(&mut self) -> Vec<String> {
        Vec::new()
    }

    /// At a heartbeat: makes what it wrote so far readable should the process be killed.
    ///
    /// # Errors
    /// The write error (the run then stops).
    fn flush(&mut self) -> Result<(), RunError> {
        Ok(())
    }

    /// Closes its files at once (a run interrupted before its first step).
    fn abandon(&mut self) {}

    /// Puts its part of the summary so far into `summary`.
    fn summarise(&self, summary: &mut RunSummaryFile, sim: &Simulation<'_>) {
        let _ = (summary, sim);
    }

    /// Finishes its files, whatever happened, and says how they stand in `finishing`.
    fn finish(&mut self, sim: &Simulation<'_>, finishing: &mut Finishing<'_>);
}

/// What a recorder is made from.
pub struct Setup<'a> {
    /// The design run.
    pub design: &'a Design,
    /// The run folder.
    pub folder: &'a RunFolder,
    /// The version and command line, for the recording.
    pub info: &'a RunInfo,
    /// Where the run's messages go.
    pub console: &'a dyn Console,
}

/// A recorder made, or the reason it could not be.
pub type Made = Result<Box<dyn Recorder>, RunError>;

/// A kind of recorder: its name, how it is made, continued and checked, and what it will write (module docs).
#[derive(Clone, Copy)]
pub struct RecorderKind {
    /// Its name in `summary.json`'s `timing.recording` and in checkpoints.
    pub name: &'static str,
    /// Makes it for a new run (a recorder the design turns off records nothing).
    pub create: fn(&Setup<'_>, &Simulation<'_>) -> Made,
    /// Checks, before anything is written, that the run folder lets it continue from `position`; `step` is the
    /// checkpoint's.
    pub check_resume: fn(dir: &Path, position: &[u8], step: usize) -> Result<(), RunError>,
    /// Continues it from `position` (a checkpoint's).
    pub resume: fn(&Setup<'_>, &Simulation<'_>, &[u8]) -> Made,
    /// What it will write in a run of the design, estimated before the run (a part of no bytes when the design
    /// turns it off).
    pub estimate: fn(&Sizing<'_>) -> DiskPart,
}

/// The recorders of a run, in the order they observe each step and are finished (the recording before the
/// snapshots: salvaging a recording cut short by a full disk frees room for them).
pub const RECORDERS: &[RecorderKind] = &[
    history::HISTORY,
    recording::RECORDING,
    snapshots::SNAPSHOTS,
    charts::CHARTS,
];

/// How the recorders' files stand after the run, and the problems met finishing them.
pub struct Finishing<'a> {
    /// The run folder.
    pub dir: &'a Path,
    /// Its manifest.
    pub manifest: &'a Manifest,
    /// A second interruption asked to skip the optional work (the final snapshot's meshes).
    pub hurry: bool,
    /// Every problem met, the first one first.
    pub problems: Vec<RunError>,
    /// The state of each output, in order.
    pub states: Vec<OutputState>,
    /// Size of the recording \[bytes\] (0 if there is none).
    pub mcap_bytes: u64,
    /// The charts and figures written.
    pub charts: Vec<PathBuf>,
    /// The configuration figures written with the snapshots (drawn beside the charts), when drawn.
    pub figures: Option<Result<Vec<PathBuf>, crate::io::chart::ChartError>>,
}

impl Finishing<'_> {
    /// Says how `file` stands.
    pub fn state(&mut self, file: &str, complete: bool, state: String) {
        self.states.push(OutputState {
            file: file.into(),
            complete,
            state,
        });
    }
}

/// `t = …` of the last complete row or message, or `the header only`.
pub(crate) fn upto(t: Option<Real>) -> String {
    t.map_or("the header only".to_string(), |t| {
        format!("t = {} s", short_time(t))
    })
}

/// A position that cannot be decoded: the checkpoint is damaged.
pub(crate) fn damaged(name: &str, problem: Problem) -> RunError {
    RunError::Refused(format!(
        "the checkpoint's position of {name} cannot be read: {problem}"
    ))
}

#[cfg(test)]
mod tests {
    // Source: each recorder's own contract — the position it encodes for a checkpoint decodes to the same
    // values (floats by their bits), and bytes left over or cut short are refused.
    use super::charts::{decode_position, encode_contact, encode_sample};
    use super::history::decode_history;
    use crate::io::checkpoint::Encoder;
    use crate::io::contact::{ContactSample, ObstacleSample};
    use crate::io::history::HistoryPosition;
    use crate::io::state::StateSample;
    use crate::math::{Real, Vec3};
    use crate::post::recovery::Recovery;

    #[test]
    fn positions_come_back_exactly() {
        let history = HistoryPosition {
            bytes: 1234,
            rows: 10,
            last_time: Some(0.9),
        };
        let mut e = Encoder::default();
        e.u64(history.bytes);
        e.usize(history.rows);
        e.option(history.last_time.as_ref(), |e, t| e.f64(*t));
        assert_eq!(decode_history(&e.0), Ok(history));
        let mut longer = e.0.clone();
        longer.push(0);
        assert!(decode_history(&longer).is_err());
        assert!(decode_history(&e.0[..e.0.len() - 1]).is_err());

        let sample = StateSample {
            step: 1,
            time: 0.1,
            dt: 0.1,
            temperature: 90.0,
            loads: vec![1.0],
            iterations: 3,
            residuals: vec![1e-3, 1e-11],
            cuts: 0,
            error_estimate: Some(2.5e-4),
            load_factor: Some(-0.0),
            probes: vec![Vec3::new(1.0, 2.0, 3.0)],
            recovery: Some(Recovery {
                ratio_mean: 0.5,
                ratio_max: 0.75,
                delta_r: None,
                by_material: vec![0.25, 0.125],
            }),
        };
        let mut e = Encoder::default();
        e.list(std::slice::from_ref(&sample), encode_sample);
        let (back, contact) = decode_position(&e.0).expect("valid");
        assert_eq!(back, vec![sample.clone()]);
        assert!(contact.is_empty());
        // With contact, its samples follow the states.
        let contact = ContactSample {
            time: 0.1,
            obstacles: vec![
                ObstacleSample {
                    force: 2.5,
                    radial_force: Some(-0.0),
                    diameter: Some(19.5),
                },
                ObstacleSample {
                    force: 1.0,
                    radial_force: None,
                    diameter: None,
                },
            ],
        };
        e.list(std::slice::from_ref(&contact), encode_contact);
        assert_eq!(
            decode_position(&e.0).expect("valid"),
            (vec![sample.clone()], vec![contact])
        );
        assert!(decode_position(&e.0[..e.0.len() - 1]).is_err());
        assert_eq!(
            back[0].load_factor.map(Real::to_bits),
            Some((-0.0 as Real).to_bits())
        );
    }
}
