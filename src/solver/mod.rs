//! The quasi-static IGA-collocation solver (paper §3; DESIGN §4).
//!
//! [`Simulation`] owns the discrete problem ([`discretisation`]), the evolving [`state::State`], the assembly of
//! residual and tangent ([`assembly`]) and the sparse LU ([`linear`]). It steps through time with Newton's
//! method on normalised per-field norms, cuts the step when Newton fails (restoring the last converged state),
//! and reports every converged step to an [`Observer`] — the engine reports, observers record.

pub mod assembly;
pub mod block;
pub mod discretisation;
pub mod gauge;
pub mod linear;
pub mod shape;
pub mod simulation;
pub mod state;

pub use simulation::{NewtonReport, Observer, RunSummary, Simulation, SolverTiming, StepReport};

use crate::geometry::GeometryError;
use crate::math::Real;

/// Why a simulation could not proceed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolverError {
    /// The reference geometry of a patch is unusable (e.g. a zero tangent).
    #[error("patch `{patch}`: {source}")]
    Geometry {
        /// Patch name.
        patch: String,
        /// What is wrong.
        source: GeometryError,
    },
    /// The material update failed (non-finite temperature, backwards step).
    #[error("material: {0}")]
    Material(#[from] crate::material::MaterialError),
    /// The sparse linear algebra failed for a reason other than singularity.
    #[error("linear solver: {0}")]
    Linear(String),
    /// The tangent is singular (no pivot at the given elimination step).
    #[error(
        "the tangent matrix is singular (no pivot at elimination step {index}): is some patch or node free to move as a rigid body?"
    )]
    Singular {
        /// Elimination step without a pivot.
        index: usize,
    },
    /// Newton failed even at the smallest allowed step.
    #[error(
        "no convergence at t = {time} (step {step}, dt = {dt:.3e} ≤ min_step): after {iterations} Newton iterations the normalised residuals were {residuals:?}"
    )]
    StepFailed {
        /// Time the step tried to reach.
        time: Real,
        /// Step number (1-based).
        step: usize,
        /// The step size at the last attempt.
        dt: Real,
        /// Newton iterations of the last attempt.
        iterations: usize,
        /// Normalised residual norm at each iteration of the last attempt.
        residuals: Vec<Real>,
    },
}

#[cfg(test)]
mod tests;
