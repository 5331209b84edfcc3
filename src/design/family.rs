//! The registry of stent families: the `family` key of a `stent:` block (`ring`, the default, or `diamond`)
//! selects the module that translates the block (a `stent::FamilyBlock`: the ring family's in [`super::stent`],
//! the diamond cells' in `diamond.rs`). A new family is its block's module and one line here.

use super::dto::{StentDto, StentFamilyDto};
use super::issue::Result;
use super::stent::{Device, FamilyBlock, Ring};
use crate::geometry::stent::FamilyCounts;
use crate::math::Real;

/// The families a `stent:` block can name, by its `family` key.
fn family(dto: &StentDto) -> &'static dyn FamilyBlock {
    match dto.family {
        StentFamilyDto::Ring => &Ring,
        StentFamilyDto::Diamond => &super::diamond::Diamond,
    }
}

/// The device of a `stent:` block, of the family it names (lengths in units of `metres_per_unit` metres), with
/// what `check` says about a file centreline and the vessel of one.
pub(crate) fn device(dto: &StentDto, metres_per_unit: Real) -> Result<Device> {
    family(dto).device(dto, metres_per_unit)
}

/// The size of a `stent:` block's device, asked of its family ([`FamilyCounts`]).
pub(crate) fn counts(dto: &StentDto) -> FamilyCounts {
    family(dto).counts(dto)
}
