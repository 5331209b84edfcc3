//! Newton's method at one time (module docs of [`super`]: normalised per-field norms, reuse of a
//! factorisation, the round-off floor) and the diagnostics of an abandoned iteration.

use super::report::NewtonReport;
use super::{Observer, Simulation, SolverTiming};
use crate::math::Real;
use crate::solver::SolverError;
use crate::solver::assembly::{Actions, Assembly, Sink, StepMaterial};
use crate::solver::linear::LinearSystem;
use crate::solver::terms::Terms;
use std::time::Instant;

/// The tolerance that round-off is taken to allow. With a smaller `solver.tolerance`, an iterate whose
/// residual stopped falling (a Newton iteration with a fresh tangent did not reduce it by the factor
/// `STAGNATION_RATIO`) is accepted if it meets the stopping rule at this tolerance, with a notice. It is above
/// the round-off floors measured (by six more Newton iterations with fresh tangents after every converged step)
/// on the 45° bend (p = 6, n = 20: residuals 2e-11 … 1.5e-10, increments 1e-11 … 3e-10) and on the two-crown
/// straight stent (residuals 4e-13 … 6e-11, increments 2e-13 … 1e-10, before and after the release), and
/// equal to the default tolerance, so an iterate accepted there is as accurate as a default run's.
pub const ROUND_OFF_TOLERANCE: Real = 1e-9;

/// A normalised Newton increment above this (a translation of 10⁸ patch lengths, a rotation of 10⁸ rad) never
/// leads to convergence: it comes from a singular or nearly singular tangent (a part free to move as a rigid
/// body) or from a load far beyond the structure's strength. The iteration stops there and names where the
/// increment is largest.
const SINGULAR_INCREMENT: Real = 1e8;

/// With error-controlled steps, Newton's tolerance as a fraction of the error allowed per step (see
/// [`Simulation::newton_tolerance`]).
pub(super) const NEWTON_SHARE: Real = 1e-2;

/// An iteration counts as stagnant when its residual is above this fraction of the previous one.
const STAGNATION_RATIO: Real = 0.5;

/// The error left after the last of a Newton solve's increments `Δ_1 … Δ_k` (normalised norms). Two successive
/// increments measure the iteration's contraction `θ = ‖Δ_k‖ / ‖Δ_{k−1}‖`, and with `θ < 1` the error left is at
/// most `θ / (1 − θ) ‖Δ_k‖` (the stopping criterion of simplified Newton iterations, Hairer & Wanner, *Solving
/// ODEs II*, §IV.8, Eq. 8.10); otherwise (the first increment, no contraction) it is taken as `‖Δ_k‖` itself.
///
/// The ratio is not a contraction when `Δ_{k−1}` is the step's first increment solved with a factorisation
/// carried over from an earlier step (`stale_first`): that increment answers the change of load since the step
/// began, not the error of an iterate, and is large whatever the iteration's contraction. Measured on the
/// viscoelastic arch (p = 8, n = 32, steps of 1 ms): `Δ_1 = 2.9e-4`, `Δ_2 = 7.9e-8` would give `θ = 3e-4`, where
/// the chord iterations that followed contracted by 0.3; stopping there left an error of 1e-7, a hundred times
/// the tolerance (issue 14). There `‖Δ_2‖` itself is the error bound.
fn remaining_error(increments: &[Real], stale_first: bool) -> Real {
    match increments {
        [_, last] if stale_first => *last,
        [.., previous, last] if last < previous => {
            let theta = last / previous;
            last.min(theta / (1.0 - theta) * last)
        }
        [.., last] => *last,
        [] => Real::INFINITY,
    }
}

/// Why one Newton solve failed (the step will be cut).
#[derive(Debug, Clone, PartialEq)]
pub(super) enum NewtonFailure {
    /// Not converged within the iteration limit, or diverging.
    NotConverged(NewtonReport),
    /// A fatal error (singular tangent, broken linear algebra).
    Fatal(SolverError),
    /// The observer asked to stop ([`Observer::interrupted`]).
    Interrupted,
}

impl Simulation<'_> {
    /// Newton's method at time `t` from the current state (modified in place). With `reuse`, the last
    /// factorisation of the tangent (from an earlier iteration or step) is kept while each iteration reduces the
    /// normalised residual at least by the factor `refactor_ratio`; otherwise the tangent is assembled and
    /// factorised afresh. `observer` is polled before every iteration ([`Observer::interrupted`]).
    pub(super) fn newton(
        &mut self,
        t: Real,
        reuse: bool,
        observer: &dyn Observer,
    ) -> Result<NewtonReport, NewtonFailure> {
        let actions = Actions::at(self.model, t, &self.releases.ramps);
        let settings = self.model.solver();
        let (tol, max_iterations, ratio) = (
            self.newton_tolerance(),
            settings.max_iterations,
            settings.refactor_ratio,
        );
        let mut report = NewtonReport::default();
        let mut previous = Real::INFINITY;
        // Whether the last increment was solved with a tangent assembled at the iterate it started from.
        let mut fresh_last = false;
        // Whether the first increment was solved with a factorisation from an earlier step ([`remaining_error`]).
        let mut stale_first = false;
        loop {
            let r = self
                .linearise(&actions, false)
                .map_err(NewtonFailure::Fatal)?;
            report.residuals.push(r);
            if !r.is_finite() {
                report.diagnosis = Some(self.non_finite_residual(report.iterations));
                return Err(NewtonFailure::NotConverged(report));
            }
            let converged = if report.iterations == 0 {
                // Nothing changed since the last converged state (e.g. a hold step): the residual alone says so,
                // at the solver's own tolerance (a looser one for error-controlled steps bounds the error of an
                // iterate through its increments, which a first iterate has none of).
                r <= settings.tolerance
            } else {
                // At the residual's round-off floor an ill-conditioned tangent (a free device after a release)
                // leaves increments of noise that never fall below the tolerance: accept when the residual is
                // below the tolerance itself and stopped falling (quadratic or chord convergence would still reduce
                // it many-fold).
                let n = report.residuals.len();
                let stagnant = n >= 3 && r > STAGNATION_RATIO * report.residuals[n - 2];
                let meets = |tol: Real| {
                    let small = r <= self.model.solver().residual_factor * tol;
                    (small && remaining_error(&report.increments, stale_first) <= tol)
                        || (r <= tol && stagnant)
                };
                if meets(tol) {
                    true
                } else {
                    // A tolerance below the round-off floor: accept where a Newton iteration with a fresh
                    // tangent no longer reduces the residual, if the iterate is as good as round-off allows.
                    let at_floor = tol < ROUND_OFF_TOLERANCE
                        && stagnant
                        && fresh_last
                        && meets(ROUND_OFF_TOLERANCE);
                    report.at_round_off = at_floor;
                    at_floor
                }
            };
            if converged {
                return Ok(report);
            }
            if report.iterations >= max_iterations {
                return Err(NewtonFailure::NotConverged(report));
            }
            if observer.interrupted() {
                return Err(NewtonFailure::Interrupted);
            }
            let factored = self.active_system().0.is_factored();
            // A reused factorisation is kept while it contracts the residual fast enough.
            let fresh_tangent = !reuse || !factored || r > ratio * previous;
            if fresh_tangent {
                self.linearise(&actions, true)
                    .map_err(NewtonFailure::Fatal)?;
                self.factor_tangent().map_err(NewtonFailure::Fatal)?;
                report.factorisations += 1;
            }
            self.solve_increment();
            fresh_last = fresh_tangent;
            if report.iterations == 0 {
                stale_first = !fresh_tangent;
                if self.model.solver().stabilisation.is_some() {
                    self.stabiliser.first_increment.clone_from(&self.work.delta);
                }
            }
            self.record_increment(&mut report)?;
            // The first increment answers the step's change of loads and surfaces with the tangent of its start: a
            // point a moving surface reaches within the step is not in it (module docs of the contact term).
            let limited = report.iterations == 1 && self.limit_step();
            self.solution
                .state
                .apply_increment(&self.disc, &self.work.delta);
            if self.model.solver().extrapolate {
                self.solution
                    .step_increment
                    .resize(self.work.delta.len(), 0.0);
                for (a, d) in self
                    .solution
                    .step_increment
                    .iter_mut()
                    .zip(&self.work.delta)
                {
                    *a += d;
                }
            }
            previous = if fresh_tangent { Real::INFINITY } else { r };
            if limited {
                report.limited += 1;
            }
        }
    }

    /// Scales the Newton increment in `self.work.delta` by the smallest fraction the point terms allow
    /// ([`crate::solver::terms::PointTerm::step_limit`]: a contact that the tangent does not see yet stops the step
    /// where it begins to act); whether it was limited. Called for the first increment of each solve. The increment's
    /// norm was recorded before: it is Newton's measure of the iterate's error, which the limit does not change.
    fn limit_step(&mut self) -> bool {
        let mut alpha: Real = 1.0;
        for term in &self.terms {
            let start = Instant::now();
            alpha = alpha.min(term.step_limit(&self.disc, &self.solution.state, &self.work.delta));
            (self.record.timing).add_term(term.name(), start.elapsed().as_secs_f64());
        }
        if alpha < 1.0 {
            for d in &mut self.work.delta {
                *d *= alpha;
            }
        }
        alpha < 1.0
    }

    /// Counts the increment in `self.work.delta` as one more iteration of `report` with its normalised norm, or
    /// abandons the iteration where it is not finite or so large that the tangent must be (nearly) singular
    /// ([`SINGULAR_INCREMENT`]), saying where.
    pub(super) fn record_increment(&self, report: &mut NewtonReport) -> Result<(), NewtonFailure> {
        let increment = self.increment_norm();
        report.increments.push(increment);
        report.iterations += 1;
        if !increment.is_finite() {
            report.diagnosis = Some(self.non_finite_increment(report.iterations));
            return Err(NewtonFailure::NotConverged(std::mem::take(report)));
        }
        if increment > SINGULAR_INCREMENT {
            report.diagnosis = Some(self.huge_increment(report.iterations, increment));
            return Err(NewtonFailure::NotConverged(std::mem::take(report)));
        }
        Ok(())
    }

    /// The tolerance Newton stops at: `solver.tolerance`, and with error-controlled steps at least
    /// [`NEWTON_SHARE`] of the share of the time tolerance each step is held to
    /// ([`super::adaptive::LOCAL_FRACTION`]).
    pub(super) fn newton_tolerance(&self) -> Real {
        let tolerance = self.model.solver().tolerance;
        self.model.time().tolerance.map_or(tolerance, |tau| {
            tolerance.max(NEWTON_SHARE * super::adaptive::LOCAL_FRACTION * tau)
        })
    }

    /// Assembles residual and tangent at the current state for time `t` and returns the normalised residual
    /// norm (largest over fields).
    pub(super) fn linearise(
        &mut self,
        actions: &Actions,
        with_tangent: bool,
    ) -> Result<Real, SolverError> {
        if with_tangent {
            self.refresh_pattern()?;
        }
        let start = Instant::now();
        let material = StepMaterial {
            laws: &self.materials.laws,
        };
        let (gauge, values) = match (&mut self.releases.gauge, self.releases.gauge_active) {
            (Some((g, _, v)), true) => (Some(&*g), v),
            _ => (None, &mut self.work.values),
        };
        let mut sink = if with_tangent {
            Sink::Values { values, next: 0 }
        } else {
            Sink::Discard
        };
        let damping = super::stabilisation::view(&self.stabiliser.damping);
        let (point, constraints) = super::assembly_terms(&self.terms, damping.as_ref(), gauge);
        self.assembler.assemble(
            &Assembly {
                disc: &self.disc,
                state: &self.solution.state,
                material,
                actions,
                terms: Terms {
                    point: &point,
                    constraints: &constraints,
                },
            },
            &mut self.work.lin,
            &mut sink,
        );
        let timing = &mut self.record.timing;
        let coupled = std::mem::take(&mut self.work.lin.coupled_seconds);
        let slot = if with_tangent {
            &mut timing.tangent
        } else {
            &mut timing.residual
        };
        SolverTiming::add(slot, start);
        slot.1 -= coupled.iter().map(|(_, s)| s).sum::<Real>();
        for &(name, seconds) in &coupled {
            timing.add_term(name, seconds);
        }
        self.work.lin.coupled_seconds = coupled;
        if with_tangent {
            self.work.tangent.assembled(actions);
        }
        let mut norm: Real = 0.0;
        for (r, s) in self.work.lin.residual.iter().zip(&self.work.lin.row_scale) {
            let x = (r / s).abs();
            if !x.is_finite() {
                return Ok(Real::INFINITY);
            }
            norm = norm.max(x);
        }
        Ok(norm)
    }

    /// Analyses the linear systems' patterns again (the rods' own and, once built, the gauge constraints') when a
    /// point term's coupling changed since they were analysed (module docs of [`crate::solver::terms`]: contact
    /// between wires found or lost); the factorisations are forgotten with the old patterns.
    fn refresh_pattern(&mut self) -> Result<(), SolverError> {
        let versions = super::coupling_versions(&self.terms);
        if versions == self.work.coupling {
            return Ok(());
        }
        let actions = Actions::at(self.model, self.clock.time, &self.releases.ramps);
        let at = Assembly {
            disc: &self.disc,
            state: &self.solution.state,
            material: StepMaterial {
                laws: &self.materials.laws,
            },
            actions: &actions,
            terms: Terms::default(),
        };
        let start = Instant::now();
        let method = self.model.solver().linear;
        (self.work.system, self.work.values) =
            super::analyse(&at, &self.assembler, &self.terms, None, method)?;
        if let Some((gauge, system, values)) = &mut self.releases.gauge {
            (*system, *values) =
                super::analyse(&at, &self.assembler, &self.terms, Some(gauge), method)?;
        }
        self.work.coupling = versions;
        self.work.tangent.invalidate();
        SolverTiming::add(&mut self.record.timing.analysis, start);
        Ok(())
    }

    /// Normalised norm of the increment in `self.work.delta`: translations over the patch length, rotations in
    /// radians.
    pub(super) fn increment_norm(&self) -> Real {
        let mut norm: Real = 0.0;
        let n = self.disc.num_unknowns();
        for (j, d) in self.work.delta[..n].chunks_exact(6).enumerate() {
            let l = self.measures.control_length[j];
            for i in 0..3 {
                norm = norm.max((d[i] / l).abs()).max(d[i + 3].abs());
            }
        }
        if norm.is_finite() {
            norm
        } else {
            Real::INFINITY
        }
    }

    /// The system that the step being solved uses (with the gauge constraints or without) and its entries.
    pub(super) fn active_system(&mut self) -> (&mut LinearSystem, &[Real]) {
        match (&mut self.releases.gauge, self.releases.gauge_active) {
            (Some((_, s, v)), true) => (s, &*v),
            _ => (&mut self.work.system, &self.work.values),
        }
    }

    /// Factorises the last assembled tangent; a singular one names where its pivotless unknown is.
    pub(super) fn factor_tangent(&mut self) -> Result<(), SolverError> {
        let start = Instant::now();
        let (system, values) = self.active_system();
        system.factor(values).map_err(|e| match e {
            SolverError::Singular { column, .. } => SolverError::Singular {
                column,
                location: crate::solver::diagnose::describe_unknown(self.model, &self.disc, column),
            },
            e => e,
        })?;
        self.work.tangent.factorised(
            &self.solution.state,
            &self.materials.laws,
            self.releases.gauge_active,
            &self.terms,
        );
        SolverTiming::add(&mut self.record.timing.factorisation, start);
        Ok(())
    }

    /// Solves for the Newton increment `δ = −K⁻¹ r` of the last assembled residual with the last factorisation,
    /// into `self.work.delta`.
    pub(super) fn solve_increment(&mut self) {
        let mut delta = std::mem::take(&mut self.work.delta);
        delta.clear();
        delta.extend(self.work.lin.residual.iter().map(|r| -r));
        self.solve_in_place(&mut delta);
        self.work.delta = delta;
    }

    /// Solves the last factorised system for the right-hand side in `rhs`, in place (counted in
    /// [`SolverTiming::solve`]).
    pub(super) fn solve_in_place(&mut self, rhs: &mut [Real]) {
        let start = Instant::now();
        self.active_system().0.solve_in_place(rhs);
        SolverTiming::add(&mut self.record.timing.solve, start);
    }

    /// Where the residual in `self.work.lin` is not finite, after `iteration` Newton iterations: its first such
    /// equation, and how many there are.
    pub(super) fn worst_equation(&self) -> Option<String> {
        // The first of the largest, a NaN counting as infinite: where a non-finite residual appeared first.
        let mut worst: Option<(usize, Real)> = None;
        for (row, (r, s)) in self
            .work
            .lin
            .residual
            .iter()
            .zip(&self.work.lin.row_scale)
            .enumerate()
        {
            let v = (r / s).abs();
            let v = if v.is_nan() { Real::INFINITY } else { v };
            if worst.is_none_or(|(_, w)| v > w) {
                worst = Some((row, v));
            }
        }
        let (row, _) = worst?;
        Some(crate::solver::diagnose::describe_row(
            self.model, &self.disc, row,
        ))
    }

    /// Names the equations whose residual is not finite after `iteration` iterations.
    pub(super) fn non_finite_residual(&self, iteration: usize) -> String {
        let bad: Vec<usize> = self
            .work
            .lin
            .residual
            .iter()
            .zip(&self.work.lin.row_scale)
            .enumerate()
            .filter(|(_, (r, s))| !(*r / *s).is_finite())
            .map(|(i, _)| i)
            .collect();
        match bad.first() {
            Some(&row) => format!(
                "the residual became non-finite after {iteration} iterations, first in the equation of {} ({} non-finite equations in all)",
                crate::solver::diagnose::describe_row(self.model, &self.disc, row),
                bad.len()
            ),
            None => format!("the residual became non-finite after {iteration} iterations"),
        }
    }

    /// Where the Newton increment in `self.work.delta` is not finite (at iteration `iteration`, 1-based): the patches
    /// and the first unknown. A singular tangent (a part free to move as a rigid body) gives this.
    pub(super) fn non_finite_increment(&self, iteration: usize) -> String {
        let patches =
            crate::solver::diagnose::non_finite_patches(self.model, &self.disc, &self.work.delta);
        let first = self
            .work
            .delta
            .iter()
            .position(|d| !d.is_finite())
            .map(|c| crate::solver::diagnose::describe_unknown(self.model, &self.disc, c))
            .unwrap_or_default();
        format!(
            "the Newton increment of iteration {iteration} is not finite in {}, first at {first}: the tangent is singular or nearly so there (a part free to move as a rigid body, or a load far beyond the structure's strength)",
            if patches.is_empty() {
                "the gauge multipliers".to_string()
            } else {
                patches.join(", ")
            }
        )
    }

    /// Where the (finite) Newton increment in `self.work.delta`, of normalised size `norm`, is largest.
    pub(super) fn huge_increment(&self, iteration: usize, norm: Real) -> String {
        let n = self.disc.num_unknowns();
        let largest = self.work.delta[..n]
            .iter()
            .enumerate()
            .map(|(c, d)| {
                let scale = if c % 6 < 3 {
                    self.measures.control_length[c / 6]
                } else {
                    1.0
                };
                (c, (d / scale).abs())
            })
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(0, |(c, _)| c);
        format!(
            "the Newton increment of iteration {iteration} is {norm:.3e} (normalised), largest at {}: Newton is diverging from a singular or nearly singular tangent (a part held too weakly to stop a rigid rotation or translation?) or from a load far beyond what the structure carries",
            crate::solver::diagnose::describe_unknown(self.model, &self.disc, largest)
        )
    }
}

/// The notice for the first step accepted at the round-off floor.
pub(super) fn round_off_notice(time: Real, newton: &NewtonReport, tolerance: Real) -> String {
    let residual = newton.residuals.last().copied().unwrap_or(Real::NAN);
    let increment = newton.increments.last().copied().unwrap_or(Real::NAN);
    format!(
        "at t = {time} Newton's normalised residual stopped falling at {residual:.2e} (last increment {increment:.2e}) without reaching the tolerance {tolerance:e} asked, which round-off does not allow there: this step and any other that stalls the same way are accepted at the round-off floor when they meet the tolerance {ROUND_OFF_TOLERANCE:e} (said once; a tolerance of at least {ROUND_OFF_TOLERANCE:e} is met as asked)"
    )
}
