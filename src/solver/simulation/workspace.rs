//! The solver's workspace: the linear system, the last assembly, the Newton increment and the record of
//! what the current factorisation was computed from.

use super::checkpoint::TangentRecord;
use crate::math::Real;
use crate::solver::assembly::Linearisation;
use crate::solver::linear::LinearSystem;

/// Buffers the Newton iterations reuse: a part of [`super::Simulation`] that holds no converged data. An
/// abandoned attempt forgets or reverts its factorisation (`Simulation::roll_back`), and a checkpoint keeps
/// only where that factorisation was computed ([`super::TangentOrigin`]), from which a restore makes it again.
pub(super) struct Workspace {
    /// The sparse system of the rods' unknowns (without the gauge multipliers).
    pub(super) system: LinearSystem,
    /// The residual, row scales and tangent entries of the last assembly.
    pub(super) lin: Linearisation,
    /// The tangent's entries in the order of `system`'s pattern.
    pub(super) values: Vec<Real>,
    /// The point terms' coupling versions the systems' patterns were analysed for (`super::analyse`).
    pub(super) coupling: Vec<usize>,
    /// The last Newton increment.
    pub(super) delta: Vec<Real>,
    /// What the current factorisation was computed from, for checkpoints ([`super::checkpoint`]).
    pub(super) tangent: TangentRecord,
}
