//! The quasi-static IGA-collocation solver (paper §3; DESIGN §4).
//!
//! [`Simulation`] owns the discrete problem (`discretisation`), the evolving `state::State`, the assembly of
//! residual and tangent (`assembly`) and the linear solves (`linear`: the block-bordered solver of `block`
//! or the sparse LU of `sparse`), with the loads, dampers and constraints beyond the rod as [`terms`]. It steps through time with Newton's method on normalised per-field norms,
//! cuts the step when Newton fails (restoring the last converged state), and reports every converged step to an
//! [`Observer`] — the engine reports, observers record.

pub(crate) mod actions;
pub(crate) mod assembly;
pub(crate) mod block;
pub(crate) mod diagnose;
pub(crate) mod discretisation;
pub(crate) mod gauge;
pub(crate) mod linear;
pub(crate) mod shape;
pub mod simulation;
pub(crate) mod sparse;
pub(crate) mod state;
pub mod terms;

pub use simulation::{
    Checkpoint, CheckpointError, NewtonReport, Observer, Observers, PeakSurfaceStrain, PointFields,
    RunSummary, Simulation, SolverTiming, StabiliserState, StepOutcome, StepReport,
    StepStabilisation,
};

use crate::geometry::GeometryError;
use crate::math::Real;
use faer::sparse::FaerError;

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
    Linear(#[from] LinearError),
    /// The tangent is structurally singular: no pivot for an unknown.
    #[error(
        "the tangent matrix is singular: no pivot for unknown {column}{}: is that patch or node free to move as a rigid body?",
        if location.is_empty() { String::new() } else { format!(" ({location})") }
    )]
    Singular {
        /// The unknown (column of the tangent) without a pivot.
        column: usize,
        /// Where that unknown is (patch, control point, field), when known.
        location: String,
    },
    /// Parts of the model are held by no condition: each can move as a rigid body and the tangent is singular.
    #[error(
        "{} held by no condition: {} free to move as a rigid body and the tangent would be singular; prescribe a component (e.g. `clamp: true`) at one of {} nodes ({}){}",
        list(parts), if parts.len() == 1 { "it is" } else { "they are" }, if parts.len() == 1 { "its" } else { "their" },
        nodes.join(", "), if *rest_held { if parts.len() == 1 { ", or join it to the rest" } else { ", or join them to the rest" } } else { "" }
    )]
    FreeBody {
        /// Each free part, described by its patches (`patches `a`, `b``).
        parts: Vec<String>,
        /// The names of the free parts' nodes.
        nodes: Vec<String>,
        /// Whether the rest of the model is held (joining the free parts to it is then a remedy).
        rest_held: bool,
    },
    /// Newton failed even at the smallest allowed step.
    #[error(
        "no convergence at t = {} (step {step}, dt = {dt:.3e} ≤ min_step) after {iterations} Newton iterations{}{}{}",
        crate::math::Short(*time),
        residuals.last().map(|r| format!(", normalised residual {r:.3e}")).unwrap_or_default(),
        worst_equation.as_ref().map(|w| format!(", largest in the equation of {w}")).unwrap_or_default(),
        diagnosis.as_ref().map(|w| format!("; {w}")).unwrap_or_default()
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
        /// Why the last attempt was abandoned at once, if it was: where a NaN or infinity first appeared, or
        /// where an increment too large for a regular tangent was largest.
        diagnosis: Option<String>,
        /// The equation whose normalised residual was largest at the last assembly.
        worst_equation: Option<String>,
    },
}

/// Why the sparse linear algebra failed for a reason other than a singular tangent (which is
/// [`SolverError::Singular`]): each variant carries what is needed to act on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum LinearError {
    /// An assembled entry lies outside the system: a programmer error in the assembly's numbering.
    #[error("entry ({row}, {column}) outside a {size}×{size} system")]
    EntryOutside {
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        column: usize,
        /// Number of unknowns (and equations).
        size: usize,
    },
    /// The symbolic LU analysis of the pattern failed (faer: an index overflow or out of memory).
    #[error("symbolic LU: {reason:?}")]
    Symbolic {
        /// Number of unknowns.
        size: usize,
        /// faer's reason.
        reason: FaerError,
    },
    /// The LU workspace could not be allocated.
    #[error("LU workspace: {bytes} bytes cannot be allocated")]
    Workspace {
        /// The workspace asked for \[bytes\].
        bytes: usize,
    },
    /// The numeric LU failed for a reason other than a missing pivot (faer: an index overflow or out of memory).
    #[error("numeric LU: {reason:?}")]
    Numeric {
        /// Number of unknowns.
        size: usize,
        /// faer's reason.
        reason: FaerError,
    },
}

/// `a`, `a and b`, `a, b and c`.
fn list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

#[cfg(test)]
mod tests;
