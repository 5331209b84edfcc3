//! The `stent:` block of the closed diamond-cell family (registered in [`super::family`]) ([`crate::geometry::stent::DiamondSpec`]): rings that
//! meet crest to trough, so the block has no spacing (it is `2 × amplitude`), rotation (`180°/peaks`) or bridges.
//!
//! ```yaml
//! stent:
//!   family: diamond
//!   crowns: 4             # rings N (N − 1 rows of closed cells)
//!   radius: 3             # R [length]
//!   amplitude: 1          # h: a ring is 2 h long, a cell 4 h
//!   peaks: 6              # crests per ring (cells around)
//!   centreline: {straight: {origin: [0, 0, 0], direction: [1, 0, 0], reference: [0, 1, 0]}}
//!   symmetry: quarter     # none | half | quarter (quarter needs an even number of peaks)
//!   crown_mesh: {p: 4, n: 14}    # optional; default: the top-level `mesh`
//! ```
//!
//! Node sets: `all_joints`, `crown_<k>` (the nodes of ring `k`), `junctions` (where two rings meet), `ends` (the
//! free first and last rows) and `symmetry`; nodes are named `r<row>_n<i>` (rows 1 … N + 1), struts
//! `c<ring>_w<i>` as the ring family's crown wires.

use super::dto::StentDto;
use super::issue::{Result, issue};
use super::stent::{Device, FamilyBlock, centreline, check_centreline_bend, sectors, symmetry};
use crate::geometry::stent::{DiamondSpec, FamilyCounts, diamond_counts};
use crate::math::Real;
use std::sync::Arc;

/// The diamond family's block (`family: diamond`).
pub(super) struct Diamond;

impl FamilyBlock for Diamond {
    fn device(&self, dto: &StentDto, metres_per_unit: Real) -> Result<Device> {
        let why_not = [
            (
                dto.spacing.is_some(),
                "spacing",
                "its rings meet crest to trough, 2 × amplitude apart",
            ),
            (
                dto.rotation_deg.is_some(),
                "rotation_deg",
                "each ring is turned by half a wave (180°/peaks) so that its crests meet the next ring's troughs",
            ),
            (
                dto.bridges.is_some(),
                "bridges",
                "its rings are joined where they meet",
            ),
            (
                dto.bridge_mesh.is_some(),
                "bridge_mesh",
                "it has no bridges",
            ),
            (dto.oversize.is_some(), "oversize", "give its `radius`"),
            (dto.taper, "taper", "its rings share one radius"),
            (
                dto.crown_shape.is_some(),
                "crown_shape",
                "its struts follow the cylinder between the nodes",
            ),
            (
                dto.materials.as_ref().is_some_and(|m| m.bridges.is_some()),
                "materials.bridges",
                "it has no bridges",
            ),
        ];
        if let Some((_, field, why)) = why_not.iter().find(|w| w.0) {
            return Err(issue(
                format!("stent.{field}"),
                format!("a diamond stent has no `{field}`: {why}"),
            ));
        }
        let Some(radius) = dto.radius else {
            return Err(issue("stent", "a diamond stent needs `radius` (R)"));
        };
        let (axis, vessel) =
            centreline(&dto.centreline, "stent.centreline", metres_per_unit, false)?;
        check_centreline_bend(&axis, radius.0)?;
        let spec = DiamondSpec {
            radius: radius.0,
            amplitude: dto.amplitude.0,
            peaks: dto.peaks,
            rings: dto.crowns,
            centreline: axis,
            symmetry: symmetry(dto),
            cut: !dto.full_model,
        };
        Ok((Arc::new(spec), Vec::new(), vessel.map(|v| v.vessel)))
    }

    fn counts(&self, dto: &StentDto) -> FamilyCounts {
        diamond_counts(dto.crowns, dto.peaks, sectors(dto))
    }
}
