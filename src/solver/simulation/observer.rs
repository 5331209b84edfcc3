//! Who is told about a run: the [`Observer`] seam (the engine reports, observers record), [`NoObserver`], an
//! absent observer (`Option`), and
//! [`Observers`], a list of observers the caller owns, told in its order.

use super::{NewtonReport, Simulation, StepReport};
use crate::math::Real;
use std::ops::ControlFlow;

/// Receives the initial state and every converged step; may stop the run.
pub trait Observer {
    /// Called once with the initial state (step 0).
    fn start(&mut self, sim: &Simulation<'_>) -> ControlFlow<()> {
        let _ = sim;
        ControlFlow::Continue(())
    }

    /// Called after each converged step.
    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()>;

    /// Called with the state at a requested time that no step landed on ([`crate::model::Model::record_times`]
    /// of an error-controlled run: the continuous extension of the step that holds it, module docs of
    /// `super::dense`), in time order and before that step's [`Observer::step`]. `sim` is at `report.time`,
    /// with [`Simulation::step_count`] the last step before it; `report.step` is that step too, `report.dt` the
    /// time from it and `report.newton` the extension's solve. An observer that must stop (a write error) keeps
    /// its error and asks at the next step.
    fn requested(&mut self, sim: &Simulation<'_>, report: &StepReport) {
        let _ = (sim, report);
    }

    /// Called when Newton fails on a step that is then cut (`time` is the target that was not reached).
    fn step_failed(&mut self, time: Real, dt: Real, newton: &NewtonReport) {
        let _ = (time, dt, newton);
    }

    /// Called when a converged step is rejected by error control (its time-error `estimate` exceeded the
    /// tolerance) and is retried shorter (`time` is the target that was not accepted).
    fn step_rejected(&mut self, time: Real, dt: Real, estimate: Real) {
        let _ = (time, dt, estimate);
    }

    /// Whether the run should stop now, within the step in progress: the seam for an interrupt (Ctrl-C) that
    /// should not wait for a long step and its cuts to finish. Polled (cheaply and often: keep it an atomic
    /// load or a counter) by Newton before every iteration and by [`Simulation::step_with`] before every attempt
    /// of a step: the first, the retry with a fresh tangent, and each cut. When it answers true, the step in
    /// progress is abandoned and rolled back as a failed step is (positions, rotations, curvatures, gauge
    /// multipliers, captured release reactions, the step's history stresses), except that the factorisation goes
    /// back to the one the attempt started with (kept, or made again) and the step size and cuts are kept;
    /// [`Observer::step`] and [`Observer::step_failed`] are not called for it, and `run` returns `Ok` with
    /// [`super::RunSummary::stopped`] at the last converged step, which is the simulation's state. A later `run`
    /// or `step` continues from there exactly as the uninterrupted run. The default never interrupts.
    fn interrupted(&self) -> bool {
        false
    }
}

/// An observer that records nothing.
pub struct NoObserver;

impl Observer for NoObserver {
    fn step(&mut self, _: &Simulation<'_>, _: &StepReport) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }
}

/// An observer that may be absent (an output the design turned off): `None` records nothing and never stops
/// or interrupts the run.
impl<O: Observer> Observer for Option<O> {
    fn start(&mut self, sim: &Simulation<'_>) -> ControlFlow<()> {
        self.as_mut()
            .map_or(ControlFlow::Continue(()), |o| o.start(sim))
    }

    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        self.as_mut()
            .map_or(ControlFlow::Continue(()), |o| o.step(sim, report))
    }

    fn requested(&mut self, sim: &Simulation<'_>, report: &StepReport) {
        if let Some(o) = self {
            o.requested(sim, report);
        }
    }

    fn step_failed(&mut self, time: Real, dt: Real, newton: &NewtonReport) {
        if let Some(o) = self {
            o.step_failed(time, dt, newton);
        }
    }

    fn step_rejected(&mut self, time: Real, dt: Real, estimate: Real) {
        if let Some(o) = self {
            o.step_rejected(time, dt, estimate);
        }
    }

    fn interrupted(&self) -> bool {
        self.as_ref().is_some_and(O::interrupted)
    }
}

/// A list of observers, owned by the caller, that acts as one ([`super::Simulation::run`] takes the list): each
/// is told of every event in the list's order — all of them, even after one asked to stop — and the run stops
/// when any asked to; an interruption is asked of each until one answers yes.
pub struct Observers<'a, 'o> {
    list: &'a mut [&'o mut dyn Observer],
}

impl<'a, 'o> Observers<'a, 'o> {
    /// The list `list`.
    pub fn new(list: &'a mut [&'o mut dyn Observer]) -> Self {
        Self { list }
    }

    /// Calls `f` on every observer; `Break` if any returned `Break`.
    fn each(&mut self, mut f: impl FnMut(&mut dyn Observer) -> ControlFlow<()>) -> ControlFlow<()> {
        let mut flow = ControlFlow::Continue(());
        for observer in self.list.iter_mut() {
            if f(&mut **observer).is_break() {
                flow = ControlFlow::Break(());
            }
        }
        flow
    }
}

impl Observer for Observers<'_, '_> {
    fn start(&mut self, sim: &Simulation<'_>) -> ControlFlow<()> {
        self.each(|o| o.start(sim))
    }

    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        self.each(|o| o.step(sim, report))
    }

    fn requested(&mut self, sim: &Simulation<'_>, report: &StepReport) {
        for observer in self.list.iter_mut() {
            observer.requested(sim, report);
        }
    }

    fn step_failed(&mut self, time: Real, dt: Real, newton: &NewtonReport) {
        for observer in self.list.iter_mut() {
            observer.step_failed(time, dt, newton);
        }
    }

    fn step_rejected(&mut self, time: Real, dt: Real, estimate: Real) {
        for observer in self.list.iter_mut() {
            observer.step_rejected(time, dt, estimate);
        }
    }

    fn interrupted(&self) -> bool {
        self.list.iter().any(|o| o.interrupted())
    }
}
