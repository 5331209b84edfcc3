//! Refusing a sweep that the disk cannot hold: its variants' estimates summed ([`crate::sweep::disk`]) and a
//! finishing reserve per concurrent run against the free space of the sweep folder's file system, as a run is
//! refused ([`crate::run::disk`]).

use super::BadInput;
use crate::design::size::human_bytes;
use crate::math::Real;
use crate::run::disk::{free_space, largest_part, parts, position};
use crate::sweep::Plan;
use crate::sweep::disk::SweepEstimate;
use std::path::Path;

pub(crate) use crate::run::disk::FINISHING_RESERVE;

/// Refuses (with [`BadInput`]) a sweep into `dir` whose estimated output ([`SweepEstimate`]: what the runs of its
/// variants still to run write, and their design files) plus [`FINISHING_RESERVE`] for each of the
/// `concurrent` runs at once exceeds the free space of the folder's file system (of its nearest existing
/// ancestor). A file system whose free space cannot be read is not checked. Returns the free space, if known.
///
/// # Errors
/// [`BadInput`] naming the design file, the field that sizes the largest part of the largest variant, the
/// total, that variant's estimate by part, and the free space.
pub(crate) fn check_sweep_space(
    plan: &Plan,
    dir: &Path,
    estimate: &SweepEstimate,
    concurrent: usize,
) -> anyhow::Result<Option<u64>> {
    let needed = sweep_bytes(estimate, concurrent);
    let free = free_space(dir);
    let (Some(free_bytes), Some((index, largest))) = (free, &estimate.largest) else {
        return Ok(free);
    };
    if needed <= free_bytes {
        return Ok(free);
    }
    let (field, advice) = largest_part(largest);
    let source = std::fs::read_to_string(&plan.design).unwrap_or_default();
    Err(BadInput(format!(
        "{}{}: {field}: this sweep would write about {} ({} variants to run; the largest, {} [{}], about {}: {}) into {}, whose file system has {} free: {advice}, sweep fewer variants, or choose a folder on a larger disk with -o",
        plan.design.display(),
        position(&source, field),
        human_bytes(needed as Real),
        estimate.variants,
        plan.variants.get(*index).map_or("?", |v| v.id.as_str()),
        plan.label(*index),
        human_bytes(largest.total() as Real),
        parts(largest),
        dir.display(),
        human_bytes(free_bytes as Real),
    ))
    .into())
}

/// What a sweep needs free: its estimate and [`FINISHING_RESERVE`] for each of the `concurrent` runs \[bytes\].
pub(crate) fn sweep_bytes(estimate: &SweepEstimate, concurrent: usize) -> u64 {
    estimate.total + (concurrent.min(estimate.variants) * FINISHING_RESERVE) as u64
}
