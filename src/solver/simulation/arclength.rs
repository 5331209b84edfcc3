//! Arc-length continuation (`solver: {path: arc-length}`; module docs of [`super`]): the Riks/Crisfield method
//! that follows an elastic model's equilibrium path through limit points in load and in displacement.
//!
//! **Equations.** The loads and prescribed values of the design at `time.end` are the reference load; a load
//! factor λ scales them, so the residual `R(x, λ)` is affine in λ and `q = ∂R/∂λ = R(x, λ + 1) − R(x, λ)` is
//! computed exactly by one more residual assembly. An increment from the converged `(x_n, λ_n)` seeks
//! `(x_n + Δx, λ_n + Δλ)` with `R = 0` and the constraint `‖Δx‖² + ψ² Δλ² = Δs²` (cylindrical: ψ = 0;
//! spherical: ψ = 1), in the root-mean-square of Newton's normalised unknowns (translations over their patch's
//! length, rotations in radians), so that Δs is a typical change of shape per increment whatever the mesh.
//!
//! **Predictor** (Crisfield, *Non-linear Finite Element Analysis of Solids and Structures*, vol. 1, 1991, §9.4):
//! the tangent direction `δx_q = −K⁻¹ q`, `Δλ = ± Δs / √(‖δx_q‖² + ψ²)`, its sign that of the previous
//! increment's projection on it, `Δx_prev · δx_q + ψ² Δλ_prev` (Feng, Perić & Owen, 1996), so the path does not
//! turn back at a limit point in load, where the tangent stiffness's determinant changes sign; the first
//! increment goes towards the end load factor and takes `time.step / time.end` of it.
//!
//! **Corrector** (Crisfield §9.3.2, Batoz & Dhatt's two solves with one factorisation): every iteration
//! assembles and factorises the tangent at the iterate, solves `δx_R = −K⁻¹ R` and `δx_q = −K⁻¹ q`, and takes
//! `δx = δx_R + δλ δx_q` with δλ the root of the constraint's quadratic whose new increment is nearest in
//! direction to the current one (the smallest angle, Crisfield Eq. 9.29). Convergence is Newton's rule: the
//! normalised residual below `residual_factor` times the tolerance and the last correction below the
//! tolerance. No real root, no convergence within `max_iterations`, or a non-finite number cuts the arc length
//! in half and the increment starts again, down to the first arc length times `time.min_step / time.step`.
//!
//! **Adaptive arc length**: after a converged increment the next arc length is the last one times
//! `√(iterations aimed at / corrections taken)` (Crisfield Eq. 9.40), within ½ … 2 and at most `max_growth`
//! times the first.
//!
//! **The end.** When an increment passes the end load factor, it is solved again from its start with the load
//! factor held at the end value (a Newton solve at fixed load), so the path lands on it exactly; the run also
//! ends after `max_increments`, with a notice. The run's "time" is the path parameter, the sum of the
//! increments' `‖Δx‖` (the arc lengths of the cylindrical constraint; it grows while λ may fall);
//! [`super::StepReport::load_factor`] carries λ.

use super::newton::NewtonFailure;
use super::report::NewtonReport;
use super::stepping::{Abandon, StepOutcome};
use super::{Observer, Simulation, StepReport};
use crate::math::Real;
use crate::model::{ArcConstraint, ArcLengthSettings, PathControl};
use crate::solver::SolverError;
use crate::solver::assembly::Actions;

/// Where an arc-length run is on its path.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ArcState {
    /// The load factor of the converged state.
    pub load_factor: Real,
    /// The arc length of the next increment (0 before the first, which sets it from `time.step`).
    pub arc: Real,
    /// The first increment's arc length, which bounds the later ones.
    pub first_arc: Real,
    /// The last converged increment `(Δx, Δλ)`, for the predictor's sign.
    pub previous: Option<(Vec<Real>, Real)>,
    /// Whether the end load factor was reached.
    pub reached_end: bool,
}

/// What holds an increment: the arc length, or the load factor (the landing on the end).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Constraint {
    /// `‖Δx‖² + ψ² Δλ² = Δs²`.
    Arc(Real),
    /// λ equal to this value.
    Load(Real),
}

/// A converged increment.
struct Increment {
    newton: NewtonReport,
    /// Its total change of the unknowns.
    dx: Vec<Real>,
    /// Its change of the load factor.
    dlambda: Real,
    /// Corrections after the predictor.
    corrections: usize,
}

/// The root of `a δλ² + b δλ + c = 0` that `better` prefers, or `None` when both are complex.
fn constraint_root(a: Real, b: Real, c: Real, better: impl Fn(Real) -> Real) -> Option<Real> {
    if a <= 0.0 {
        // δx_q vanishes (no load at all in the normalised unknowns): the constraint is linear in δλ.
        return (b != 0.0).then(|| -c / b);
    }
    let disc = b * b - 4.0 * a * c;
    if !(disc >= 0.0) {
        return None;
    }
    // The stable pair of roots (no cancellation between −b and √disc).
    let root = disc.sqrt();
    let q = -0.5 * (b + b.signum() * root);
    let (r1, r2) = if q != 0.0 { (q / a, c / q) } else { (0.0, 0.0) };
    Some(if better(r1) >= better(r2) { r1 } else { r2 })
}

impl Simulation<'_> {
    /// The arc-length settings, when the path is driven by arc length.
    pub(super) fn arc_length_settings(&self) -> Option<ArcLengthSettings> {
        self.model.solver().path.arc_length()
    }

    /// The load factor of the current state (arc-length runs; `None` for time-driven ones).
    pub fn load_factor(&self) -> Option<Real> {
        self.arc.as_ref().map(|a| a.load_factor)
    }

    /// The time at which the model's schedules are read for the current state: its time, or `time.end` on an
    /// arc-length path (whose loads are those at `time.end` scaled by the load factor, [`Self::load_scale`]).
    pub fn schedule_time(&self) -> Real {
        match self.model.solver().path {
            PathControl::Time => self.clock.time,
            PathControl::ArcLength(_) => self.model.time().end,
        }
    }

    /// The factor on the loads the schedules give at [`Self::schedule_time`]: 1, or an arc-length path's load
    /// factor (0 before its first increment).
    pub fn load_scale(&self) -> Real {
        match self.model.solver().path {
            PathControl::Time => 1.0,
            PathControl::ArcLength(_) => self.load_factor().unwrap_or(0.0),
        }
    }

    /// Whether an arc-length run is over: the end load factor reached, or the increments allowed taken.
    pub(super) fn arc_length_finished(&self, settings: &ArcLengthSettings) -> bool {
        self.arc.as_ref().is_some_and(|a| a.reached_end)
            || self.clock.step >= settings.max_increments
    }

    /// The weighted inner product of two vectors of unknowns: translations over their patch's length,
    /// rotations in radians, averaged over the control points (the root-mean-square of Newton's normalised
    /// increment, whose largest entry is [`Simulation::increment_norm`]).
    fn arc_dot(&self, a: &[Real], b: &[Real]) -> Real {
        let n = self.disc.num_unknowns();
        let mut sum = 0.0;
        for (j, (x, y)) in a[..n]
            .chunks_exact(6)
            .zip(b[..n].chunks_exact(6))
            .enumerate()
        {
            let w = 1.0 / (self.measures.control_length[j] * self.measures.control_length[j]);
            for i in 0..3 {
                sum += w * x[i] * y[i] + x[i + 3] * y[i + 3];
            }
        }
        sum / (n / 6).max(1) as Real
    }

    /// Takes one arc-length increment (with the cuts it needs), or lands on the end load factor; the arc-length
    /// counterpart of [`Simulation::step_with`], which calls it.
    pub(super) fn arc_length_step(
        &mut self,
        observer: &mut dyn Observer,
        settings: ArcLengthSettings,
    ) -> Result<StepOutcome, SolverError> {
        if self.arc_length_finished(&settings) {
            return Ok(StepOutcome::Finished);
        }
        let mut state = self.arc.take().unwrap_or_default();
        let outcome = self.arc_length_increment(observer, &settings, &mut state);
        self.arc = Some(state);
        outcome
    }

    /// [`Simulation::arc_length_step`] with the path's state taken out of the simulation.
    fn arc_length_increment(
        &mut self,
        observer: &mut dyn Observer,
        settings: &ArcLengthSettings,
        state: &mut ArcState,
    ) -> Result<StepOutcome, SolverError> {
        let end_time = self.model.time().end;
        let min_ratio = self.model.time().min_step / self.model.time().step;
        let reference = Actions::at(self.model, end_time, &self.releases.ramps);
        loop {
            if observer.interrupted() {
                return Ok(StepOutcome::Interrupted);
            }
            let (lambda0, ds) = (state.load_factor, state.arc);
            let start = self.begin_attempt();
            self.prepare_step(end_time, end_time)?;
            let attempt = self
                .arc_increment(&reference, settings, state, Constraint::Arc(ds), observer)
                .and_then(|inc| {
                    // Passing the end load factor: solve again from the start with λ held there.
                    let end = settings.end_load_factor;
                    let lambda = lambda0 + inc.dlambda;
                    if (lambda0 - end) * (lambda - end) <= 0.0 {
                        self.solution.state = start.solution.state.clone();
                        self.arc_increment(
                            &reference,
                            settings,
                            state,
                            Constraint::Load(end),
                            observer,
                        )
                        .map(|landed| (landed, true))
                    } else {
                        Ok((inc, false))
                    }
                });
            match attempt {
                Ok((inc, landed)) => {
                    self.work.tangent.end_attempt();
                    self.commit_step();
                    self.clock.step += 1;
                    let ds = self.arc_dot(&inc.dx, &inc.dx).sqrt();
                    self.clock.time += ds;
                    state.load_factor += inc.dlambda;
                    state.reached_end = landed;
                    let growth = (settings.target_iterations as Real
                        / inc.corrections.max(1) as Real)
                        .sqrt()
                        .clamp(0.5, 2.0);
                    state.arc = (state.arc * growth).min(settings.max_growth * state.first_arc);
                    state.previous = Some((inc.dx, inc.dlambda));
                    let report = StepReport {
                        step: self.clock.step,
                        time: self.clock.time,
                        dt: ds,
                        temperature: self.model.temperature().value(end_time),
                        newton: inc.newton,
                        cuts: std::mem::take(&mut self.clock.step_cuts),
                        error_estimate: None,
                        rejected: 0,
                        load_factor: Some(state.load_factor),
                        stabilisation: None,
                        requested: 0,
                    };
                    if !landed && self.clock.step >= settings.max_increments {
                        self.record.notices.push(format!(
                            "the arc-length path stopped after its {} increments allowed at load factor {:.6} without reaching the end load factor {} (raise `solver.arc_length.max_increments`)",
                            settings.max_increments, state.load_factor, settings.end_load_factor
                        ));
                    }
                    return Ok(StepOutcome::Stepped(Box::new(report)));
                }
                Err(NewtonFailure::Fatal(e)) => {
                    self.roll_back(&start, Abandon::Failed);
                    return Err(e);
                }
                Err(NewtonFailure::Interrupted) => {
                    self.roll_back(&start, Abandon::Failed);
                    return Ok(StepOutcome::Interrupted);
                }
                Err(NewtonFailure::NotConverged(mut newton)) => {
                    newton.worst_equation = self.worst_equation();
                    self.roll_back(&start, Abandon::Failed);
                    observer.step_failed(self.clock.time + state.arc, state.arc, &newton);
                    if state.arc <= state.first_arc * min_ratio * (1.0 + 1e-12) {
                        return Err(SolverError::StepFailed {
                            time: self.clock.time + state.arc,
                            step: self.clock.step + 1,
                            dt: state.arc,
                            iterations: newton.iterations,
                            residuals: newton.residuals,
                            worst_equation: newton.worst_equation,
                            diagnosis: newton.diagnosis.or_else(|| {
                                Some(format!(
                                    "the arc-length increment from load factor {:.6} failed at the smallest arc length {:.3e}",
                                    state.load_factor, state.arc
                                ))
                            }),
                        });
                    }
                    state.arc = (0.5 * state.arc).max(state.first_arc * min_ratio);
                    self.clock.step_cuts += 1;
                }
            }
        }
    }

    /// One increment from the current (converged) state under `constraint`: predictor and corrections.
    fn arc_increment(
        &mut self,
        reference: &Actions,
        settings: &ArcLengthSettings,
        state: &mut ArcState,
        constraint: Constraint,
        observer: &dyn Observer,
    ) -> Result<Increment, NewtonFailure> {
        let n = self.disc.num_unknowns();
        let psi2 = match settings.constraint {
            ArcConstraint::Cylindrical => 0.0,
            ArcConstraint::Spherical => 1.0,
        };
        let tol = self.model.solver().tolerance;
        let residual_tol = self.model.solver().residual_factor * tol;
        let lambda0 = state.load_factor;
        let mut lambda = lambda0;
        let mut dx = vec![0.0; n];
        let mut dlambda = 0.0;
        let mut report = NewtonReport::default();
        let mut corrections = 0;
        loop {
            if observer.interrupted() {
                return Err(NewtonFailure::Interrupted);
            }
            let r = self
                .linearise(&reference.scaled(lambda), false)
                .map_err(NewtonFailure::Fatal)?;
            report.residuals.push(r);
            if !r.is_finite() {
                report.diagnosis = Some(self.non_finite_residual(report.iterations));
                return Err(NewtonFailure::NotConverged(report));
            }
            let last = report.increments.last().copied().unwrap_or(Real::INFINITY);
            if corrections > 0 && r <= residual_tol && last <= tol {
                return Ok(Increment {
                    newton: report,
                    dx,
                    dlambda,
                    corrections,
                });
            }
            if corrections >= self.model.solver().max_iterations {
                return Err(NewtonFailure::NotConverged(report));
            }
            // q = ∂R/∂λ, then the residual and tangent at λ (kept in `self.work.lin`).
            self.linearise(&reference.scaled(lambda + 1.0), false)
                .map_err(NewtonFailure::Fatal)?;
            let shifted = self.work.lin.residual.clone();
            self.linearise(&reference.scaled(lambda), true)
                .map_err(NewtonFailure::Fatal)?;
            self.factor_tangent().map_err(NewtonFailure::Fatal)?;
            report.factorisations += 1;
            let mut dx_q: Vec<Real> = shifted
                .iter()
                .zip(&self.work.lin.residual)
                .map(|(s, r)| -(s - r))
                .collect();
            self.solve_in_place(&mut dx_q);
            let predictor = report.iterations == 0;
            let dl = if predictor {
                match constraint {
                    Constraint::Load(target) => target - lambda0,
                    Constraint::Arc(arc) => {
                        let qq = self.arc_dot(&dx_q, &dx_q);
                        if !(qq + psi2 > 0.0) {
                            report.diagnosis = Some("the reference load is zero (no load or prescribed value differs from zero at `time.end`): arc-length continuation has no path to follow".into());
                            return Err(NewtonFailure::NotConverged(report));
                        }
                        let arc = if arc > 0.0 {
                            arc
                        } else {
                            // The first increment: `time.step / time.end` of the end load factor.
                            let dl0 = settings.end_load_factor * self.model.time().step
                                / self.model.time().end;
                            let first = dl0.abs() * (qq + psi2).sqrt();
                            state.arc = first;
                            state.first_arc = first;
                            first
                        };
                        let size = arc / (qq + psi2).sqrt();
                        let sign = match &state.previous {
                            Some((px, pl)) => self.arc_dot(px, &dx_q) + psi2 * pl,
                            None => settings.end_load_factor,
                        };
                        if sign < 0.0 { -size } else { size }
                    }
                }
            } else {
                // δx_R = −K⁻¹ R, the residual kept in `self.work.lin`.
                self.solve_increment();
                match constraint {
                    Constraint::Load(_) => 0.0,
                    Constraint::Arc(arc) => {
                        let dx_r = &self.work.delta[..n];
                        let base: Vec<Real> = dx.iter().zip(dx_r).map(|(a, b)| a + b).collect();
                        let a = self.arc_dot(&dx_q, &dx_q) + psi2;
                        let b = 2.0 * (self.arc_dot(&base, &dx_q) + psi2 * dlambda);
                        let c = self.arc_dot(&base, &base) + psi2 * dlambda * dlambda - arc * arc;
                        // Of the two roots, the one whose new increment turns least from the current one.
                        let along = self.arc_dot(&base, &dx);
                        let turn = self.arc_dot(&dx_q, &dx);
                        let better = |d: Real| along + d * turn + psi2 * (dlambda + d) * dlambda;
                        match constraint_root(a, b, c, better) {
                            Some(d) => d,
                            None => {
                                report.diagnosis = Some(format!(
                                    "the arc-length constraint has no real root at load factor {lambda:.6} (iteration {}): the arc length is too long for the path's curvature here",
                                    report.iterations + 1
                                ));
                                return Err(NewtonFailure::NotConverged(report));
                            }
                        }
                    }
                }
            };
            // The increment: the tangent direction scaled by δλ, plus (in corrections) δx_R.
            if predictor {
                self.work.delta.clear();
                self.work.delta.extend(dx_q.iter().map(|d| d * dl));
            } else {
                for (d, q) in self.work.delta.iter_mut().zip(&dx_q) {
                    *d += dl * q;
                }
            }
            self.record_increment(&mut report)?;
            if !predictor {
                corrections += 1;
            }
            self.solution
                .state
                .apply_increment(&self.disc, &self.work.delta);
            for (a, d) in dx.iter_mut().zip(&self.work.delta) {
                *a += d;
            }
            dlambda += dl;
            lambda = lambda0 + dlambda;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quadratic's roots, checked against the closed form (δλ² − 3δλ + 2 = 0: roots 1 and 2) with either
    /// preference, and the complex case (δλ² + 1 = 0) refused. Exact arithmetic on small integers.
    #[test]
    fn the_constraint_root_is_the_preferred_real_root() {
        assert_eq!(constraint_root(1.0, -3.0, 2.0, |d| d), Some(2.0));
        assert_eq!(constraint_root(1.0, -3.0, 2.0, |d| -d), Some(1.0));
        assert_eq!(constraint_root(1.0, 0.0, 1.0, |d| d), None);
        assert_eq!(constraint_root(0.0, 2.0, -4.0, |d| d), Some(2.0));
    }
}
