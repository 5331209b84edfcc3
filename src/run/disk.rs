//! Refusing a run that the disk cannot hold: the run's estimated output ([`estimated_disk`]: each recorder's
//! part and the summary) and the finishing reserve against the free space of the run folder's file system,
//! before anything is removed or written.

use super::RunError;
use crate::design::Design;
use crate::design::locate::Locator;
use crate::design::size::human_bytes;
use crate::io::run_folder::FitFolder;
use crate::math::Real;
use crate::run::estimate::{DiskEstimate, estimated_disk};
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

/// `history.csv 203 kB, run.mcap 19.0 MB, 8 snapshots 42.0 MB, charts 3.0 MB, summary.json 10 kB`: the parts in
/// the registry's order ([`DiskEstimate::describe`]).
pub(crate) fn parts(estimate: &DiskEstimate) -> String {
    estimate.describe(&|bytes| human_bytes(bytes as Real), false)
}

/// The field that sizes the largest part of `estimate` that has one ([`DiskEstimate::largest`]), and what to
/// do with it (`output`, in general terms, for an estimate without advice: never met, as `history.csv`'s part
/// has some).
pub(crate) fn largest_part(estimate: &DiskEstimate) -> (&'static str, &'static str) {
    estimate
        .largest()
        .and_then(|p| p.advice)
        .unwrap_or(("output", "write fewer outputs"))
}
