//! The clock of a simulation: where it is in time and steps, and the size of its next step (module docs of
//! [`super`]: landing on breakpoints, halving on failure, doubling back, error control).

use super::STEP_FACTOR;
use super::adaptive::{StepControl, error_ratio};
use crate::math::Real;
use crate::model::TimeSettings;

/// Where a simulation is in time and steps and how long its next step is: a part of [`super::Simulation`]
/// that every step changes, saved whole in a [`super::StepSnapshot`] (plain numbers, so it is its own
/// snapshot).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clock {
    /// Time of the last converged state \[time\] (the path parameter in arc-length runs).
    pub time: Real,
    /// Converged steps (0: the initial state).
    pub step: usize,
    /// The size of the next step's first attempt \[time\]: the nominal step, or less after a cut (doubled back
    /// by converged steps).
    pub step_size: Real,
    /// Cuts of the step in progress (0 between steps; kept over an interruption, so that the continued step
    /// reports them all).
    pub step_cuts: usize,
    /// The memory of error-controlled stepping (`super::adaptive`).
    pub control: StepControl,
}

impl Clock {
    /// The clock at the initial state: time 0, no step, the nominal step size `time.step`.
    pub(super) fn start(time: &TimeSettings) -> Self {
        Self {
            time: 0.0,
            step: 0,
            step_size: time.step,
            step_cuts: 0,
            control: StepControl::default(),
        }
    }

    /// An attempt failed and is cut: the next is of size `next_size` (the halved step), one more cut of the
    /// step in progress.
    pub(super) fn cut(&mut self, next_size: Real) {
        self.step_size = next_size;
        self.step_cuts += 1;
    }

    /// A step of size `dt` converged at `target` (after `cuts` cuts, with the time-error `estimate` of error
    /// control): the clock moves to `target`, and the next step's size comes from the error controller (with
    /// `time.tolerance`) or grows back by [`STEP_FACTOR`] towards the nominal step.
    pub(super) fn advance(
        &mut self,
        time: &TimeSettings,
        target: Real,
        dt: Real,
        cuts: usize,
        estimate: Option<Real>,
    ) {
        self.time = target;
        self.step += 1;
        match time.tolerance {
            Some(tolerance) => {
                let ratio = error_ratio(estimate, tolerance);
                let mut next = self.control.accepted(dt, ratio);
                // A step shortened to land on a breakpoint does not shrink the next below the plan.
                if dt < self.step_size && cuts == 0 {
                    next = next.max(self.step_size);
                }
                let largest = time.max_step.unwrap_or(Real::INFINITY);
                self.step_size = next.clamp(time.min_step, largest.max(time.min_step));
            }
            None if self.step_size < time.step => {
                self.step_size = (STEP_FACTOR * self.step_size).min(time.step);
            }
            None => {}
        }
    }
}
