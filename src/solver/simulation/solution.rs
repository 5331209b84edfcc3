//! The solution of a simulation: the last converged configuration and the increments that predict the next
//! step's.

use super::{CheckpointError, Restorable};
use crate::math::Real;
use crate::solver::discretisation::Discretisation;
use crate::solver::state::State;

/// The converged configuration and the increments of the steps: a part of [`super::Simulation`] that every
/// step changes.
#[derive(Debug)]
pub(super) struct Solution {
    /// The configuration: the last converged one between steps, the iterate during a step.
    pub(super) state: State,
    /// The last converged step's total increment and its size \[time\], for the next step's prediction
    /// (`None` after a step that ended on a breakpoint).
    pub(super) last_increment: Option<(Vec<Real>, Real)>,
    /// Sum of the increments applied in the step being solved (prediction and Newton corrections): scratch
    /// of the attempt in progress, empty between attempts.
    pub(super) step_increment: Vec<Real>,
}

/// What the solution part of a simulation saves in a [`super::StepSnapshot`].
#[derive(Debug, Clone, PartialEq)]
pub struct SolutionSnapshot {
    /// The configuration.
    pub state: State,
    /// The last converged step's total increment and its size \[time\].
    pub last_increment: Option<(Vec<Real>, Real)>,
}

impl Solution {
    /// The solution before any step, at the configuration `state`.
    pub(super) fn starting_at(state: State) -> Self {
        Self {
            state,
            last_increment: None,
            step_increment: Vec::new(),
        }
    }

    /// Predicts the state after a step of size `dt` by extrapolating the last step's increment linearly in time
    /// (scaled by `dt` over its size; the rotation part applied as one more multiplicative increment).
    /// Schedules are piecewise linear, so the last step's rate is a good guess except across a breakpoint, after
    /// which there is no prediction (`last_increment` is `None`).
    pub(super) fn predict(&mut self, disc: &Discretisation, dt: Real) {
        self.step_increment.clear();
        let n = disc.num_unknowns();
        // (A step that needed no iteration left an empty increment: nothing to extrapolate.)
        let Some((increment, h)) = self.last_increment.as_ref().filter(|(i, _)| i.len() >= n)
        else {
            return;
        };
        let scale = dt / h;
        self.step_increment
            .extend(increment[..n].iter().map(|d| d * scale));
        self.state.apply_increment(disc, &self.step_increment);
    }
}

impl Restorable for Solution {
    type Saved = SolutionSnapshot;

    /// The configuration and the last step's increment (the increment of an attempt is scratch).
    fn save(&self) -> SolutionSnapshot {
        SolutionSnapshot {
            state: self.state.clone(),
            last_increment: self.last_increment.clone(),
        }
    }

    /// Puts them back and empties the scratch of an attempt.
    fn restore(&mut self, saved: &SolutionSnapshot) -> Result<(), CheckpointError> {
        self.state.copy_from(&saved.state);
        self.last_increment.clone_from(&saved.last_increment);
        self.step_increment.clear();
        Ok(())
    }
}
