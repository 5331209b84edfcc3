//! What a run has said and spent so far: notices and the solver's timing.

use super::SolverTiming;

/// The run's record: a part of [`super::Simulation`] that grows over the run and is never undone — what was
/// said stays said, the time spent on an abandoned attempt was spent — so a roll-back leaves it as it is and a
/// checkpoint saves it ([`super::Checkpoint`]).
#[derive(Debug, Default)]
pub(super) struct RunRecord {
    /// Messages for the user, each said once (e.g. the WLF freeze), in the order they arose.
    pub(super) notices: Vec<String>,
    /// Whether a step accepted at the round-off floor has been reported.
    pub(super) round_off_reported: bool,
    /// Where the time went so far.
    pub(super) timing: SolverTiming,
}
