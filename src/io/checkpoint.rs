//! The checkpoint file of a run folder (`checkpoint.bin`): the simulation's [`Checkpoint`] and where every
//! output stood at that step ([`OutputsCheckpoint`]), from which `stentkit run --resume` continues a killed or
//! interrupted run exactly.
//!
//! # Format (version 9; version 8 named the model and the output settings by a hash of their `Debug` text, had a fixed
//! list of outputs and no point terms' states, version 7's stabiliser state had no force share and no times of its warnings, version 6 had no snapshot phase, version 5 no stabiliser state, version 4 no load factor per chart sample, version 3 no arc-length state, version 2 had 18 numbers per section law and no
//! per-material recovery, version 1, before error-controlled stepping, no step-control memory)
//!
//! ```text
//! magic     8 bytes   "STKCKPT\0"
//! version   u32       9
//! length    u64       bytes of the payload
//! payload   …         the fields below, in order
//! crc32     u32       CRC-32 (IEEE 802.3, as zlib and PNG) of everything before it
//! ```
//!
//! All integers and floats little-endian; a float is its IEEE-754 bits (`f64::to_bits`), so every number comes
//! back exactly; a `usize` is a `u64`; a vector or string is its length (`u64`) then its items; an option is a
//! byte 0/1 then the value. The payload is the model fingerprint of the outputs' settings, the solver's
//! checkpoint (time, step, step control, state, materials, ramps, gauge, tangent origin, notices, timing, arc-length
//! state, stabiliser, point terms' states) and the outputs: each
//! recorder's position under its name (bytes in the recorder's own encoding, written and read with this
//! module's [`Encoder`] and [`Decoder`] by `crate::run::recorder`), the run's totals and each recorder's wall
//! time, in the order [`write()`] writes them.
//!
//! Why this format: a checkpoint must restore every number bit for bit (a text format would need round-trip
//! formatting for millions of floats and be three times larger); it is read only by the version of stentkit
//! that wrote it, so a version number that refuses other versions is simpler and safer than a self-describing
//! schema; the CRC catches a file damaged on disk or copied short (a torn write cannot happen: the file is
//! written to a temporary and renamed, [`crate::io::atomic::write_bytes_atomically`]); and it needs no dependency
//! beyond `crc32fast`, already in the tree through `mcap`. The solver's checkpoint is plain data and has no
//! serde derive (the solver layer is pure, DESIGN §2): its encoding lives here.

use crate::material::LAW_NUMBERS;
use crate::math::{Mat3, Real, Vec3};
use crate::solver::assembly::{Actions, ReleaseRamp};
use crate::solver::simulation::adaptive::StepControl;
use crate::solver::simulation::{
    ArcState, Clock, ReleaseSnapshot, SolutionSnapshot, StabiliserState, StepSnapshot,
    TangentOrigin,
};
use crate::solver::state::State;
use crate::solver::{Checkpoint, RunSummary, SolverTiming};
use std::path::{Path, PathBuf};

/// The checkpoint's file name inside a run folder.
pub(crate) const FILE_NAME: &str = crate::io::run_folder::CHECKPOINT_FILE;

/// The format's first eight bytes.
const MAGIC: &[u8; 8] = b"STKCKPT\0";

/// The format version this build writes and reads.
pub(crate) const VERSION: u32 = 13;

/// Bytes before the payload: magic, version, length.
const HEADER: usize = 8 + 4 + 8;

/// What a run checkpoint holds: the simulation and its outputs at one converged step.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RunCheckpoint {
    /// The simulation ([`crate::solver::Simulation::checkpoint`]).
    pub solver: Checkpoint,
    /// The outputs.
    pub outputs: OutputsCheckpoint,
}

/// Where the outputs of a run stood at a checkpoint: enough to continue each as if never interrupted.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct OutputsCheckpoint {
    /// Fingerprint of the design's output settings (snapshots, recording): a resumed run must write the same.
    pub settings: u64,
    /// Each recorder's position, by its name, in the recorder's own encoding (`crate::run::recorder`: each
    /// recorder writes and reads its position with an [`Encoder`] and a [`Decoder`]).
    pub positions: Vec<(String, Vec<u8>)>,
    /// What the run did so far.
    pub totals: RunSummary,
    /// Wall time spent in each recorder so far, by name \[s\].
    pub spent: Vec<(String, Real)>,
    /// Wall time of the run so far, over every process that ran it \[s\].
    pub wall_time_s: Real,
}

impl OutputsCheckpoint {
    /// The position saved by the recorder named `name`.
    pub(crate) fn position(&self, name: &str) -> Option<&[u8]> {
        self.positions
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, bytes)| bytes.as_slice())
    }
}

/// Why a checkpoint file cannot be read.
#[derive(Debug, thiserror::Error)]
pub(crate) enum CheckpointFileError {
    /// Reading the file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// The file is not a stentkit checkpoint.
    #[error("{path}: not a stentkit checkpoint (no `STKCKPT` magic at its start)")]
    NotACheckpoint {
        /// The file.
        path: PathBuf,
    },
    /// The file was written by another version of the format.
    #[error(
        "{path}: a checkpoint of format version {found}; this stentkit reads version {VERSION} only (resume with the stentkit that wrote it)"
    )]
    Version {
        /// The file.
        path: PathBuf,
        /// Its version.
        found: u32,
    },
    /// The file is shorter than its header says, or its checksum does not match: it was damaged.
    #[error("{path}: damaged ({what})")]
    Damaged {
        /// The file.
        path: PathBuf,
        /// What does not add up.
        what: String,
    },
}

/// The version of the output settings' description hashed by [`settings_fingerprint`]: raised when its form
/// changes (as [`crate::model::fingerprint::VERSION`] is for the model's).
pub(crate) const SETTINGS_DESCRIPTION_VERSION: u32 = 1;

/// The fingerprint of the outputs' settings of a design: as the model's ([`crate::model::fingerprint`]), a
/// hash of their serialised, versioned description (every field of [`super::output::OutputSettings`]).
pub(crate) fn settings_fingerprint(settings: &super::output::OutputSettings) -> u64 {
    crate::model::fingerprint::fingerprint_of(
        "stentkit output settings",
        SETTINGS_DESCRIPTION_VERSION,
        settings,
    )
}

/// Writes `checkpoint` to `path` atomically (a temporary in the same folder, synced, renamed over `path`).
///
/// # Errors
/// The I/O error; `path` is then unchanged.
pub(crate) fn write(path: &Path, checkpoint: &RunCheckpoint) -> std::io::Result<()> {
    let mut e = Encoder(Vec::with_capacity(1 << 16));
    e.0.extend_from_slice(MAGIC);
    e.u32(VERSION);
    e.u64(0); // the payload's length, filled in below
    encode_solver(&mut e, &checkpoint.solver);
    encode_outputs(&mut e, &checkpoint.outputs);
    let length = (e.0.len() - HEADER) as u64;
    e.0[12..HEADER].copy_from_slice(&length.to_le_bytes());
    let crc = crc32fast::hash(&e.0);
    e.u32(crc);
    super::atomic::write_bytes_atomically(path, &e.0)
}

/// Reads the checkpoint at `path`.
///
/// # Errors
/// [`CheckpointFileError`]: not readable, not a checkpoint, another version, or damaged.
pub(crate) fn read(path: &Path) -> Result<RunCheckpoint, CheckpointFileError> {
    let bytes = std::fs::read(path).map_err(|source| CheckpointFileError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    decode(&bytes).map_err(|e| e.at(path))
}

/// The checkpoint encoded in `bytes` (the whole file).
fn decode(bytes: &[u8]) -> Result<RunCheckpoint, Problem> {
    if bytes.len() < 8 || &bytes[..8] != MAGIC {
        return Err(Problem::NotACheckpoint);
    }
    if bytes.len() < HEADER + 4 {
        return Err(Problem::Damaged("shorter than its header".into()));
    }
    let mut d = Decoder { bytes, at: 8 };
    let version = d.u32()?;
    if version != VERSION {
        return Err(Problem::Version(version));
    }
    let length = d.u64()?;
    let expected = (HEADER as u64).saturating_add(length).saturating_add(4);
    if bytes.len() as u64 != expected {
        return Err(Problem::Damaged(format!(
            "{} bytes where its header says {expected}",
            bytes.len()
        )));
    }
    let (body, crc) = bytes.split_at(bytes.len() - 4);
    let stored = u32::from_le_bytes([crc[0], crc[1], crc[2], crc[3]]);
    let computed = crc32fast::hash(body);
    if stored != computed {
        return Err(Problem::Damaged(format!(
            "CRC-32 {computed:08x} where the file says {stored:08x}"
        )));
    }
    let mut d = Decoder {
        bytes: body,
        at: HEADER,
    };
    let solver = decode_solver(&mut d)?;
    let outputs = decode_outputs(&mut d)?;
    if d.at != body.len() {
        return Err(Problem::Damaged(format!(
            "{} bytes left after the last field",
            body.len() - d.at
        )));
    }
    Ok(RunCheckpoint { solver, outputs })
}

/// A decoding problem, before the path is known.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Problem {
    /// No magic at the file's start.
    NotACheckpoint,
    /// Another version of the format.
    Version(u32),
    /// What does not add up.
    Damaged(String),
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Problem::NotACheckpoint => write!(f, "not a checkpoint"),
            Problem::Version(v) => write!(f, "format version {v}"),
            Problem::Damaged(what) => write!(f, "damaged ({what})"),
        }
    }
}

impl Problem {
    fn at(self, path: &Path) -> CheckpointFileError {
        let path = path.to_path_buf();
        match self {
            Problem::NotACheckpoint => CheckpointFileError::NotACheckpoint { path },
            Problem::Version(found) => CheckpointFileError::Version { path, found },
            Problem::Damaged(what) => CheckpointFileError::Damaged { path, what },
        }
    }
}

/// Appends little-endian fields to a byte buffer (the format's encoding, module docs).
#[derive(Debug, Default)]
pub(crate) struct Encoder(pub Vec<u8>);

impl Encoder {
    /// A byte.
    pub(crate) fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    /// A `u32`.
    pub(crate) fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    /// A `u64`.
    pub(crate) fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    /// A `usize`, as a `u64`.
    pub(crate) fn usize(&mut self, v: usize) {
        self.u64(v as u64);
    }
    /// A flag, as a byte 0/1.
    pub(crate) fn bool(&mut self, v: bool) {
        self.u8(u8::from(v));
    }
    /// A float, by its bits.
    pub(crate) fn f64(&mut self, v: Real) {
        self.u64(v.to_bits());
    }
    /// A list of floats.
    pub(crate) fn f64s(&mut self, v: &[Real]) {
        self.usize(v.len());
        for &x in v {
            self.f64(x);
        }
    }
    /// A vector's three components.
    pub(crate) fn vec3(&mut self, v: &Vec3) {
        for &x in v.iter() {
            self.f64(x);
        }
    }
    /// A list of vectors.
    pub(crate) fn vec3s(&mut self, v: &[Vec3]) {
        self.usize(v.len());
        for x in v {
            self.vec3(x);
        }
    }
    /// A string: its length, then its UTF-8 bytes.
    pub(crate) fn str(&mut self, s: &str) {
        self.usize(s.len());
        self.0.extend_from_slice(s.as_bytes());
    }
    /// An option: a flag, then the value written by `f`.
    pub(crate) fn option<T>(&mut self, v: Option<&T>, mut f: impl FnMut(&mut Self, &T)) {
        match v {
            None => self.bool(false),
            Some(x) => {
                self.bool(true);
                f(self, x);
            }
        }
    }
    /// A list: its length, then each item written by `f`.
    pub(crate) fn list<T>(&mut self, v: &[T], mut f: impl FnMut(&mut Self, &T)) {
        self.usize(v.len());
        for x in v {
            f(self, x);
        }
    }
}

/// Reads little-endian fields from a byte buffer; every read checks the bytes are there.
#[derive(Debug)]
pub(crate) struct Decoder<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Decoder<'a> {
    /// Reads `bytes` from their start.
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, at: 0 }
    }

    /// Refuses bytes left after the last field.
    ///
    /// # Errors
    /// [`Problem::Damaged`] naming how many are left.
    pub(crate) fn finish(&self) -> Result<(), Problem> {
        if self.at == self.bytes.len() {
            Ok(())
        } else {
            Err(Problem::Damaged(format!(
                "{} bytes left after the last field",
                self.bytes.len() - self.at
            )))
        }
    }

    /// The next `n` bytes.
    pub(crate) fn take(&mut self, n: usize) -> Result<&[u8], Problem> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| {
                Problem::Damaged(format!("a field runs past the end at byte {}", self.at))
            })?;
        let out = &self.bytes[self.at..end];
        self.at = end;
        Ok(out)
    }
    /// A byte.
    pub(crate) fn u8(&mut self) -> Result<u8, Problem> {
        Ok(self.take(1)?[0])
    }
    /// A `u32`.
    pub(crate) fn u32(&mut self) -> Result<u32, Problem> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    /// A `u64`.
    pub(crate) fn u64(&mut self) -> Result<u64, Problem> {
        let b = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(u64::from_le_bytes(a))
    }
    /// A `usize` (written as a `u64`).
    pub(crate) fn usize(&mut self) -> Result<usize, Problem> {
        let v = self.u64()?;
        usize::try_from(v).map_err(|_| Problem::Damaged(format!("a count of {v}")))
    }
    /// A count of items of at least `item_bytes` each: refused when the rest of the file cannot hold them (so a
    /// damaged count never allocates absurdly).
    pub(crate) fn count(&mut self, item_bytes: usize) -> Result<usize, Problem> {
        let n = self.usize()?;
        let left = self.bytes.len() - self.at;
        if n.saturating_mul(item_bytes.max(1)) > left {
            return Err(Problem::Damaged(format!(
                "a list of {n} items in the last {left} bytes"
            )));
        }
        Ok(n)
    }
    /// A flag.
    pub(crate) fn bool(&mut self) -> Result<bool, Problem> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(Problem::Damaged(format!("a flag of {b}"))),
        }
    }
    /// A float.
    pub(crate) fn f64(&mut self) -> Result<Real, Problem> {
        Ok(Real::from_bits(self.u64()?))
    }
    /// A list of floats.
    pub(crate) fn f64s(&mut self) -> Result<Vec<Real>, Problem> {
        let n = self.count(8)?;
        (0..n).map(|_| self.f64()).collect()
    }
    /// A vector.
    pub(crate) fn vec3(&mut self) -> Result<Vec3, Problem> {
        Ok(Vec3::new(self.f64()?, self.f64()?, self.f64()?))
    }
    /// A list of vectors.
    pub(crate) fn vec3s(&mut self) -> Result<Vec<Vec3>, Problem> {
        let n = self.count(24)?;
        (0..n).map(|_| self.vec3()).collect()
    }
    /// A string.
    pub(crate) fn str(&mut self) -> Result<String, Problem> {
        let n = self.count(1)?;
        String::from_utf8(self.take(n)?.to_vec())
            .map_err(|_| Problem::Damaged("a text that is not UTF-8".into()))
    }
    /// An option, its value read by `f`.
    pub(crate) fn option<T>(
        &mut self,
        mut f: impl FnMut(&mut Self) -> Result<T, Problem>,
    ) -> Result<Option<T>, Problem> {
        if self.bool()? {
            Ok(Some(f(self)?))
        } else {
            Ok(None)
        }
    }
    /// A list of items of at least `item_bytes` each, read by `f`.
    pub(crate) fn list<T>(
        &mut self,
        item_bytes: usize,
        mut f: impl FnMut(&mut Self) -> Result<T, Problem>,
    ) -> Result<Vec<T>, Problem> {
        let n = self.count(item_bytes)?;
        (0..n).map(|_| f(self)).collect()
    }
}

fn encode_state(e: &mut Encoder, s: &State) {
    e.vec3s(&s.control);
    e.list(&s.rotation, |e, r: &Mat3| {
        for &x in r.iter() {
            e.f64(x);
        }
    });
    e.vec3s(&s.kappa);
    e.vec3s(&s.kappa_s);
    e.f64s(&s.multipliers);
    e.list(&s.orientation, |e, q| {
        for &x in q.coords.iter() {
            e.f64(x);
        }
    });
    e.vec3s(&s.relative);
}

fn decode_state(d: &mut Decoder<'_>) -> Result<State, Problem> {
    Ok(State {
        control: d.vec3s()?,
        rotation: d.list(72, |d| {
            let mut m = [0.0; 9];
            for x in &mut m {
                *x = d.f64()?;
            }
            Ok(Mat3::from_column_slice(&m))
        })?,
        kappa: d.vec3s()?,
        kappa_s: d.vec3s()?,
        multipliers: d.f64s()?,
        orientation: d.list(32, |d| {
            let mut v = [0.0; 4];
            for x in &mut v {
                *x = d.f64()?;
            }
            Ok(crate::math::quaternion_field::Quat::from(
                nalgebra::Vector4::from(v),
            ))
        })?,
        relative: d.vec3s()?,
    })
}

fn encode_ramps(e: &mut Encoder, ramps: &[[Option<ReleaseRamp>; 6]]) {
    e.list(ramps, |e, node| {
        for ramp in node {
            e.option(ramp.as_ref(), |e, r| {
                e.f64(r.reaction);
                e.f64(r.start);
                e.f64(r.duration);
            });
        }
    });
}

fn decode_ramps(d: &mut Decoder<'_>) -> Result<Vec<[Option<ReleaseRamp>; 6]>, Problem> {
    d.list(6, |d| {
        let mut node = [None; 6];
        for ramp in &mut node {
            *ramp = d.option(|d| {
                Ok(ReleaseRamp {
                    reaction: d.f64()?,
                    start: d.f64()?,
                    duration: d.f64()?,
                })
            })?;
        }
        Ok(node)
    })
}

fn encode_actions(e: &mut Encoder, a: &Actions) {
    e.vec3s(&a.node_force);
    e.vec3s(&a.node_moment);
    e.list(&a.prescribed, |e, node| {
        for value in node {
            e.option(value.as_ref(), |e, v| e.f64(*v));
        }
    });
    e.vec3s(&a.dist_force);
    e.vec3s(&a.dist_couple);
}

fn decode_actions(d: &mut Decoder<'_>) -> Result<Actions, Problem> {
    Ok(Actions {
        node_force: d.vec3s()?,
        node_moment: d.vec3s()?,
        prescribed: d.list(6, |d| {
            let mut node = [None; 6];
            for value in &mut node {
                *value = d.option(|d| d.f64())?;
            }
            Ok(node)
        })?,
        dist_force: d.vec3s()?,
        dist_couple: d.vec3s()?,
    })
}

fn encode_timing(e: &mut Encoder, t: &SolverTiming) {
    let parts = [
        t.residual,
        t.tangent,
        t.factorisation,
        t.solve,
        t.material,
        t.analysis,
    ];
    for (count, secs) in parts {
        e.usize(count);
        e.f64(secs);
    }
    e.usize(t.terms.len());
    for (name, (count, secs)) in &t.terms {
        e.str(name);
        e.usize(*count);
        e.f64(*secs);
    }
}

fn decode_timing(d: &mut Decoder<'_>) -> Result<SolverTiming, Problem> {
    let mut slot = || -> Result<(usize, Real), Problem> { Ok((d.usize()?, d.f64()?)) };
    let mut timing = SolverTiming {
        residual: slot()?,
        tangent: slot()?,
        factorisation: slot()?,
        solve: slot()?,
        material: slot()?,
        analysis: slot()?,
        terms: Vec::new(),
    };
    for _ in 0..d.usize()? {
        timing.terms.push((d.str()?, (d.usize()?, d.f64()?)));
    }
    Ok(timing)
}

fn encode_solver(e: &mut Encoder, c: &Checkpoint) {
    let step = &c.snapshot;
    e.u64(c.model);
    e.f64(step.clock.time);
    e.usize(step.clock.step);
    e.f64(step.clock.step_size);
    e.usize(step.clock.step_cuts);
    e.option(step.clock.control.previous_ratio.as_ref(), |e, r| e.f64(*r));
    e.usize(step.clock.control.rejections);
    e.bool(step.clock.control.above_tolerance_reported);
    encode_state(e, &step.solution.state);
    e.list(&c.materials, |e, (material, values)| {
        e.usize(*material);
        e.f64s(values);
    });
    e.list(&c.material_notices, |e, (material, kind)| {
        e.usize(*material);
        e.str(kind);
    });
    e.list(&c.notices, |e, n| e.str(n));
    e.bool(c.round_off_reported);
    encode_ramps(e, &step.releases.ramps);
    e.option(c.gauge.as_ref(), |e, frozen| {
        e.list(frozen, |e, (node, x)| {
            e.usize(*node);
            e.vec3(x);
        });
    });
    e.bool(step.releases.gauge_active);
    e.option(
        step.solution.last_increment.as_ref(),
        |e, (increment, h)| {
            e.f64s(increment);
            e.f64(*h);
        },
    );
    e.option(c.tangent.as_ref(), |e, t| {
        encode_state(e, &t.state);
        e.list(&t.laws, |e, law| {
            for &x in law {
                e.f64(x);
            }
        });
        encode_actions(e, &t.actions);
        e.bool(t.gauge_active);
        e.list(&t.terms, |e, v| e.f64s(v));
    });
    encode_timing(e, &c.timing);
    e.option(step.arc.as_ref(), |e, a| {
        e.f64(a.load_factor);
        e.f64(a.arc);
        e.f64(a.first_arc);
        e.option(a.previous.as_ref(), |e, (dx, dl)| {
            e.f64s(dx);
            e.f64(*dl);
        });
        e.bool(a.reached_end);
    });
    let s = &c.stabiliser;
    e.option(s.factor.as_ref(), |e, f| e.f64(*f));
    e.usize(s.escalations);
    e.f64(s.base_factor);
    e.f64(s.dissipated);
    e.f64(s.peak_strain_energy);
    e.f64(s.largest_step_ratio);
    e.usize(s.damped_steps);
    e.option(s.energy_limit_time.as_ref(), |e, t| e.f64(*t));
    e.f64(s.largest_force_share);
    e.f64(s.largest_force_share_time);
    e.usize(s.steps_above_force_limit);
    e.usize(s.unscaled_stalls);
    e.f64(s.first_unscaled_time);
    e.list(&step.terms, |e, t| e.f64s(t));
}

fn decode_solver(d: &mut Decoder<'_>) -> Result<Checkpoint, Problem> {
    // In the order of the file (`encode_solver`), then put together.
    let model = d.u64()?;
    let clock = Clock {
        time: d.f64()?,
        step: d.usize()?,
        step_size: d.f64()?,
        step_cuts: d.usize()?,
        control: StepControl {
            previous_ratio: d.option(|d| d.f64())?,
            rejections: d.usize()?,
            above_tolerance_reported: d.bool()?,
        },
    };
    let state = decode_state(d)?;
    let materials = d.list(16, |d| Ok((d.usize()?, d.f64s()?)))?;
    let material_notices = d.list(16, |d| Ok((d.usize()?, d.str()?)))?;
    let notices = d.list(8, |d| d.str())?;
    let round_off_reported = d.bool()?;
    let ramps = decode_ramps(d)?;
    let gauge = d.option(|d| d.list(32, |d| Ok((d.usize()?, d.vec3()?))))?;
    let gauge_active = d.bool()?;
    let last_increment = d.option(|d| Ok((d.f64s()?, d.f64()?)))?;
    let tangent = d.option(|d| {
        Ok(TangentOrigin {
            state: decode_state(d)?,
            laws: d.list(8 * LAW_NUMBERS, |d| {
                let mut law = [0.0; LAW_NUMBERS];
                for x in &mut law {
                    *x = d.f64()?;
                }
                Ok(law)
            })?,
            actions: decode_actions(d)?,
            gauge_active: d.bool()?,
            terms: d.list(8, |d| d.f64s())?,
        })
    })?;
    let timing = decode_timing(d)?;
    let arc = d.option(|d| {
        Ok(ArcState {
            load_factor: d.f64()?,
            arc: d.f64()?,
            first_arc: d.f64()?,
            previous: d.option(|d| Ok((d.f64s()?, d.f64()?)))?,
            reached_end: d.bool()?,
        })
    })?;
    let stabiliser = StabiliserState {
        factor: d.option(|d| d.f64())?,
        escalations: d.usize()?,
        base_factor: d.f64()?,
        dissipated: d.f64()?,
        peak_strain_energy: d.f64()?,
        largest_step_ratio: d.f64()?,
        damped_steps: d.usize()?,
        energy_limit_time: d.option(|d| d.f64())?,
        largest_force_share: d.f64()?,
        largest_force_share_time: d.f64()?,
        steps_above_force_limit: d.usize()?,
        unscaled_stalls: d.usize()?,
        first_unscaled_time: d.f64()?,
    };
    let terms = d.list(8, |d| d.f64s())?;
    Ok(Checkpoint {
        model,
        snapshot: StepSnapshot {
            clock,
            solution: SolutionSnapshot {
                state,
                last_increment,
            },
            releases: ReleaseSnapshot {
                ramps,
                gauge_active,
            },
            arc,
            terms,
        },
        materials,
        material_notices,
        notices,
        round_off_reported,
        gauge,
        tangent,
        timing,
        stabiliser,
    })
}

fn encode_outputs(e: &mut Encoder, o: &OutputsCheckpoint) {
    e.u64(o.settings);
    e.list(&o.positions, |e, (name, bytes)| {
        e.str(name);
        e.usize(bytes.len());
        e.0.extend_from_slice(bytes);
    });
    let t = &o.totals;
    for v in [
        t.steps,
        t.iterations,
        t.cuts,
        t.rejected,
        t.factorisations,
        t.requested,
    ] {
        e.usize(v);
    }
    e.f64(t.time);
    e.bool(t.stopped);
    e.list(&o.spent, |e, (name, s)| {
        e.str(name);
        e.f64(*s);
    });
    e.f64(o.wall_time_s);
}

fn decode_outputs(d: &mut Decoder<'_>) -> Result<OutputsCheckpoint, Problem> {
    Ok(OutputsCheckpoint {
        settings: d.u64()?,
        positions: d.list(16, |d| {
            let name = d.str()?;
            let n = d.count(1)?;
            Ok((name, d.take(n)?.to_vec()))
        })?,
        totals: RunSummary {
            steps: d.usize()?,
            iterations: d.usize()?,
            cuts: d.usize()?,
            rejected: d.usize()?,
            factorisations: d.usize()?,
            requested: d.usize()?,
            time: d.f64()?,
            stopped: d.bool()?,
        },
        spent: d.list(16, |d| Ok((d.str()?, d.f64()?)))?,
        wall_time_s: d.f64()?,
    })
}

#[cfg(test)]
mod tests {
    // Source: the format's own contract — every field comes back exactly (floats by their bits, including
    // NaN payloads and −0), and a file damaged anywhere (a flipped byte, a short copy, another version) is
    // refused with a reason rather than read wrongly.
    use super::*;

    fn sample_checkpoint() -> RunCheckpoint {
        let state = State {
            control: vec![
                Vec3::new(1.0, -0.0, 3.5e-300),
                Vec3::new(Real::MIN_POSITIVE, 2.0, 3.0),
            ],
            rotation: vec![Mat3::from_fn(|i, j| (i * 3 + j) as Real * 0.1); 2],
            kappa: vec![Vec3::new(0.1, 0.2, 0.3); 2],
            kappa_s: vec![Vec3::new(-1.0, 0.0, 1.0); 2],
            multipliers: vec![1e-20, -3.0],
            orientation: vec![crate::math::quaternion_field::Quat::new(0.5, -0.5, 0.5, -0.5); 2],
            relative: vec![Vec3::new(0.25, -3.5, 1e-3); 2],
        };
        let solver = Checkpoint {
            model: 0x0123_4567_89ab_cdef,
            snapshot: StepSnapshot {
                clock: Clock {
                    time: 1.75,
                    step: 700,
                    step_size: 2.5e-3 / 4.0,
                    step_cuts: 0,
                    control: StepControl {
                        previous_ratio: Some(0.25),
                        rejections: 2,
                        above_tolerance_reported: true,
                    },
                },
                solution: SolutionSnapshot {
                    state: state.clone(),
                    last_increment: Some((vec![0.5; 12], 2.5e-3)),
                },
                releases: ReleaseSnapshot {
                    ramps: vec![
                        [
                            None,
                            Some(ReleaseRamp {
                                reaction: 3.0,
                                start: 1.75,
                                duration: 2.5e-3
                            }),
                            None,
                            None,
                            None,
                            None
                        ];
                        2
                    ],
                    gauge_active: true,
                },
                arc: Some(ArcState {
                    load_factor: -0.25,
                    arc: 0.125,
                    first_arc: 0.0625,
                    previous: Some((vec![1.5; 12], -0.5)),
                    reached_end: false,
                }),
                terms: vec![Vec::new(), vec![1.5, -0.0, f64::MIN_POSITIVE]],
            },
            materials: vec![(0, vec![1.0, 2.0, Real::NAN]), (2, vec![])],
            material_notices: vec![(0, "relaxation_frozen".into())],
            notices: vec!["at t = 1 …".into()],
            round_off_reported: true,
            gauge: Some(vec![(1, Vec3::new(1.0, 2.0, 3.0))]),
            tangent: Some(TangentOrigin {
                state,
                laws: vec![[0.25; LAW_NUMBERS]; 2],
                actions: Actions {
                    node_force: vec![Vec3::x(); 2],
                    node_moment: vec![Vec3::y(); 2],
                    prescribed: vec![[Some(0.0), None, None, Some(1.0), None, None]; 2],
                    dist_force: vec![Vec3::z()],
                    dist_couple: vec![Vec3::zeros()],
                },
                gauge_active: false,
                terms: vec![vec![0.5, -2.0], Vec::new()],
            }),
            timing: SolverTiming {
                residual: (3, 0.5),
                ..SolverTiming::default()
            },
            stabiliser: StabiliserState {
                factor: Some(2.5e-6),
                escalations: 2,
                base_factor: 2.5e-8,
                dissipated: 0.125,
                peak_strain_energy: 3.5,
                largest_step_ratio: 0.01,
                damped_steps: 7,
                energy_limit_time: Some(1.25),
                largest_force_share: 0.75,
                largest_force_share_time: 1.5,
                steps_above_force_limit: 3,
                unscaled_stalls: 2,
                first_unscaled_time: 0.5,
            },
        };
        let outputs = OutputsCheckpoint {
            settings: 42,
            positions: vec![
                ("history".into(), vec![1, 2, 3, 0, 255]),
                ("nothing".into(), Vec::new()),
            ],
            totals: RunSummary {
                steps: 9,
                iterations: 30,
                cuts: 1,
                rejected: 3,
                factorisations: 5,
                requested: 2,
                time: 0.9,
                stopped: false,
            },
            spent: vec![("history".into(), 0.1), ("charts".into(), 0.4)],
            wall_time_s: 12.5,
        };
        RunCheckpoint { solver, outputs }
    }

    fn encoded(c: &RunCheckpoint) -> Vec<u8> {
        let dir = std::env::temp_dir().join(format!("stentkit-checkpoint-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("scratch");
        let path = dir.join(FILE_NAME);
        write(&path, c).expect("written");
        std::fs::read(&path).expect("read back")
    }

    #[test]
    fn every_field_comes_back_exactly() {
        let c = sample_checkpoint();
        let bytes = encoded(&c);
        let back = decode(&bytes).expect("valid");
        // NaN ≠ NaN: compare the material numbers by their bits, the rest with `==`.
        let bits = |c: &RunCheckpoint| -> Vec<u64> {
            c.solver
                .materials
                .iter()
                .flat_map(|(_, v)| v.iter().map(|x| x.to_bits()))
                .collect()
        };
        assert_eq!(bits(&back), bits(&c));
        let (mut a, mut b) = (back.clone(), c.clone());
        a.solver.materials.clear();
        b.solver.materials.clear();
        assert_eq!(a, b);
        assert_eq!(
            back.solver.snapshot.solution.state.control[0].y.to_bits(),
            (-0.0 as Real).to_bits()
        );
    }

    #[test]
    fn damaged_files_are_refused() {
        let bytes = encoded(&sample_checkpoint());
        // Every single flipped byte is caught (by the magic, the version, the length or the CRC).
        for k in (0..bytes.len()).step_by(7) {
            let mut damaged = bytes.clone();
            damaged[k] ^= 0x10;
            assert!(decode(&damaged).is_err(), "byte {k} flipped and accepted");
        }
        assert!(matches!(
            decode(&bytes[..bytes.len() - 1]),
            Err(Problem::Damaged(_))
        ));
        assert!(matches!(
            decode(b"{\"not\": 1}"),
            Err(Problem::NotACheckpoint)
        ));
        let mut other = bytes.clone();
        other[8] = 2; // the format before this one
        assert!(matches!(decode(&other), Err(Problem::Version(2))));
    }
}
