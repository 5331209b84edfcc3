//! Refusing a run that the disk cannot hold: the run's estimated output ([`estimated_disk`]: snapshots,
//! recording, history, charts, summary) and the finishing reserve against the free space of the run folder's
//! file system, before anything is removed or written.

use super::RunError;
use crate::io::design::Design;
use crate::io::design::locate::Locator;
use crate::io::design::size::human_bytes;
use crate::io::estimate::{DiskEstimate, estimated_disk};
use crate::io::run_folder::FitFolder;
use crate::math::Real;
use std::path::Path;

/// Room a run keeps free for finishing \[bytes\]: the summary (a few kB) and the charts (tens of kB each), written
/// after a disk that filled up during the run ([`crate::io::run_folder::RunFolder::reserve`]).
pub(crate) const FINISHING_RESERVE: usize = 1 << 20;

/// Refuses (with [`RunError::Refused`]) a run into `folder` whose estimated output plus [`FINISHING_RESERVE`]
/// exceeds the free space of the folder's file system (of its nearest existing ancestor, if it does not exist
/// yet) plus what `force` will free (the earlier run's files). A file system whose free space cannot be read is
/// not checked.
///
/// # Errors
/// [`RunError::Refused`] naming the design file, the field that sizes the largest part (with its line and
/// column when the design sets it), the estimate by part and the free space.
pub(crate) fn check_space(design: &Design, folder: &FitFolder) -> Result<(), RunError> {
    let dir = folder.dir();
    let estimate = estimated_disk(design);
    let needed = estimate.total() + FINISHING_RESERVE as u64;
    let Some(free) = free_space(dir) else {
        return Ok(());
    };
    let free = free + folder.previous_bytes();
    if needed <= free {
        return Ok(());
    }
    let (field, advice) = largest_part(&estimate);
    Err(RunError::Refused(format!(
        "{}{}: {field}: this run would write about {} ({}) into {}, whose file system has {} free: {advice}, or choose a folder on a larger disk with -o",
        design.path.display(),
        position(&design.source, field),
        human_bytes(needed as Real),
        parts(&estimate),
        dir.display(),
        human_bytes(free as Real),
    )))
}

/// Free bytes of the file system of `dir` (of its nearest existing ancestor, if it does not exist yet: the
/// current folder for a relative `runs/x` whose `runs` does not exist), or `None` when they cannot be read.
pub(crate) fn free_space(dir: &Path) -> Option<u64> {
    std::path::absolute(dir)
        .ok()?
        .ancestors()
        .find(|a| a.exists())
        .and_then(|a| fs4::available_space(a).ok())
}

/// `:line:column` of `field` in the design text `source`, or nothing when the text does not set it.
pub(crate) fn position(source: &str, field: &str) -> String {
    Locator::new(source)
        .get(field)
        .map(|p| format!(":{}:{}", p.line, p.column))
        .unwrap_or_default()
}

/// `8 snapshots 42.0 MB, run.mcap 19.0 MB, history.csv 203 kB, charts and summary 3.0 MB`.
pub(crate) fn parts(estimate: &DiskEstimate) -> String {
    format!(
        "{} snapshots {}, run.mcap {}, history.csv {}, charts and summary {}",
        estimate.snapshots,
        human_bytes(estimate.snapshots_bytes() as Real),
        human_bytes(estimate.recording as Real),
        human_bytes(estimate.history as Real),
        human_bytes((estimate.charts + estimate.summary) as Real),
    )
}

/// The field that sizes the largest part of `estimate`, and what to do with it.
pub(crate) fn largest_part(estimate: &DiskEstimate) -> (&'static str, &'static str) {
    let snapshots = estimate.snapshots_bytes();
    if snapshots >= estimate.recording && snapshots >= estimate.history {
        (
            "output.snapshots",
            "take fewer snapshots (fewer `between` or `times`, a larger `every`) or smaller ones (fewer `rings`, `segments`, one of the `formats`)",
        )
    } else if estimate.recording >= estimate.history {
        (
            "output.recording.centreline_points",
            "record fewer centreline points per patch, or set `meshes: false`",
        )
    } else {
        ("time.step", "take larger time steps")
    }
}
