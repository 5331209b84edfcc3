//! What the engine reports: one Newton solve ([`NewtonReport`]), one converged step ([`StepReport`]) and the
//! totals of a run ([`RunSummary`]).

use crate::math::Real;

/// What one Newton solve did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NewtonReport {
    /// Linear solves performed.
    pub iterations: usize,
    /// Normalised residual norm (largest over fields) at each assembly, the last one at the converged state.
    pub residuals: Vec<Real>,
    /// Normalised increment norm of each solve.
    pub increments: Vec<Real>,
    /// LU factorisations performed (fewer than `iterations` when a factorisation was reused).
    pub factorisations: usize,
    /// Why the iteration was abandoned at once, if it was: where a NaN or infinity first appeared (the equation
    /// of the residual, or the patches and unknown of the increment), or where an increment so large that the
    /// tangent must be (nearly) singular is largest.
    pub diagnosis: Option<String>,
    /// For a solve that did not converge: the equation whose normalised residual was largest at the last
    /// assembly, in the designer's terms (`crate::solver::diagnose::describe_row`).
    pub worst_equation: Option<String>,
    /// True when the step was accepted at the round-off floor: the tolerance asked (below
    /// [`super::ROUND_OFF_TOLERANCE`]) was not met, the residual stopped falling, and the iterate met the stopping rule
    /// at [`super::ROUND_OFF_TOLERANCE`] (see the module docs).
    pub at_round_off: bool,
    /// Iterations whose increment a point term limited (a contact that began within it,
    /// [`crate::solver::terms::PointTerm::step_limit`]).
    pub limited: u32,
}

/// One converged time step, as reported to observers.
#[derive(Debug, Clone, PartialEq)]
pub struct StepReport {
    /// Step number, 1-based (0 is the initial state).
    pub step: usize,
    /// Time reached.
    pub time: Real,
    /// Step size taken.
    pub dt: Real,
    /// Temperature at `time` \[°C\].
    pub temperature: Real,
    /// Newton history of the step.
    pub newton: NewtonReport,
    /// Step cuts needed before this step converged.
    pub cuts: usize,
    /// The time-error estimate of the step (error-controlled stepping, `time.tolerance`), in Newton's
    /// normalised increment norm; `None` with fixed steps or without internal variables.
    pub error_estimate: Option<Real>,
    /// Attempts of this step rejected because their time-error estimate exceeded the tolerance.
    pub rejected: usize,
    /// The load factor reached (arc-length continuation); `None` for time steps.
    pub load_factor: Option<Real>,
    /// What the stabilisation did (runs with `solver.stabilisation`; `None` otherwise).
    pub stabilisation: Option<super::StepStabilisation>,
    /// States at requested times inside this step, reported before it ([`super::Observer::requested`]); 0 for
    /// such a state's own report.
    pub requested: usize,
}

/// Totals of a run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunSummary {
    /// Converged steps.
    pub steps: usize,
    /// Newton iterations (linear solves) over all converged steps.
    pub iterations: usize,
    /// Step cuts.
    pub cuts: usize,
    /// Steps rejected by error control.
    pub rejected: usize,
    /// LU factorisations over all converged steps.
    pub factorisations: usize,
    /// States reported at requested times between the steps (error control's continuous extension,
    /// [`super::Observer::requested`]).
    pub requested: usize,
    /// Time reached.
    pub time: Real,
    /// True when an observer asked to stop before the end.
    pub stopped: bool,
}
