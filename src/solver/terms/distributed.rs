//! The model's distributed loads ([`crate::model::DistributedLoad`]) as a point term: per patch a force and a
//! couple per unit length, fixed in space, resolved at each instant by `Actions::at` (and scaled with the
//! load factor of arc-length continuation, `Actions::scaled`).
//!
//! At an interior collocation point they are the `n̄`, `m̄` of the balance laws (paper Eqs. mat_f, mat_m); being
//! fixed in space they depend neither on the position nor on the rotation, so the term gives no tangent block
//! (the derivative of `Rᵀ n̄`, `Rᵀ m̄` under the rotation is the assembly's).

use super::{InteriorLoad, PointTerm, PointView};
#[cfg(doc)]
use crate::solver::actions::Actions;

/// The distributed loads of the model (stateless: the values of the instant are in `Actions`).
#[derive(Debug, Clone, Copy, Default)]
pub struct DistributedLoad;

impl PointTerm for DistributedLoad {
    fn name(&self) -> &'static str {
        "distributed load"
    }

    fn interior(&self, at: &PointView<'_>, load: &mut InteriorLoad) {
        load.add_force(at.actions.dist_force[at.point.patch]);
        load.add_couple(at.actions.dist_couple[at.point.patch]);
    }
}
