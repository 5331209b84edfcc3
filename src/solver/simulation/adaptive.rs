//! Error-controlled time stepping (`time.tolerance`): the estimate of a step's time error and the step-size
//! controller (module docs of [`super`], *Error-controlled stepping*).
//!
//! **Estimate.** The only quantities a quasi-static step integrates in time are the materials' internal
//! variables (the Maxwell branch strains); loads, prescribed motions and temperatures are evaluated exactly at
//! each time. After Newton converged at `t_{n+1}` with the design's update of the internal variables, each
//! material gives the section laws its *companion* update would give over the same step from the same
//! internal variables at `t_n` ([`crate::material::ConstitutiveLaw::companion_laws`]; backward Euler for the
//! second-order rules, the trapezoidal rule for backward Euler). The residual of the converged configuration
//! under those laws, `r_c`, is what keeps the two updates' solutions apart; one linear solve with the step's
//! tangent, `δ = −K⁻¹ r_c`, is the first-order difference of the two configurations, and its normalised norm
//! (Newton's: translations over the patch length, rotations in radians) is one part of the estimate. Where
//! nodes are held (a programme before its release) a stress difference hardly moves the constrained
//! configuration and shows only when the nodes are freed: the other part is the difference of the two laws'
//! section stresses at the converged strains as the strain that carries it, `ΔN/C̄_N` and `ΔM/C̄_M` times the
//! patch length (a rotation, as in Newton's norm), largest over the points. The estimate is the larger of the
//! two. (Without that part the straight stent's error after its release measured 1.0 times the tolerance at
//! 1e-3 whatever share of it the steps were held to, 1/4 to 1/8: it appeared in the release step, 4e-8 at
//! 1.75 s and 1.0e-3 at 1.7525 s.) For the second-order
//! rules it is backward Euler's local error, `O(h²)`, larger than their own `O(h³)` error for smooth histories
//! (the estimate is conservative) and equal to the trapezoidal rule's ringing when `hλ ≫ 1` after a jump of
//! strain, which backward Euler does not have (so the ringing is caught: the step is rejected and shrunk until
//! `hλ` is small enough for the ringing to be resolved). A law without internal variables (elastic) has no
//! time error: no estimate, and steps grow to `max_step` or to what Newton manages.
//!
//! **Controller.** With `e_n` the estimate over its share of the tolerance ([`LOCAL_FRACTION`]; accept when
//! `e_n ≤ 1`) and the estimate of
//! order `k = 2` in `h`, the next step is the PI controller of Gustafsson (ACM TOMS 17, 1991; Hairer & Wanner,
//! *Solving ODEs II*, §IV.8), `h_{n+1} = h_n · s · e_n^{−0.7/k} · e_{n−1}^{0.4/k}`, with the safety factor
//! `s` = [`SAFETY`] and the change limited to [`MIN_FACTOR`] … [`MAX_FACTOR`]; after a rejection the memory
//! is dropped and the step is `h_n · max(MIN_FACTOR, s · e_n^{−1/k})`. A step that lands short on a breakpoint
//! does not shrink the next one below the step planned before it.

use super::Simulation;
use super::constitutive::with_step_input;
use crate::material::{ConstitutiveLaw, SectionLaw};
use crate::math::Real;
use crate::solver::SolverError;
use crate::solver::assembly::{Actions, Assembly, Sink, StepMaterial, point_strains};
use crate::solver::terms::Terms;

/// Order of the estimate in the step size: the local error of backward Euler, `O(h²)`.
const ESTIMATE_ORDER: Real = 2.0;

/// Safety factor of the proposed step.
pub(crate) const SAFETY: Real = 0.9;

/// Largest growth of the step from one step to the next.
pub(crate) const MAX_FACTOR: Real = 2.0;

/// Largest shrink of the step from one attempt to the next.
pub(crate) const MIN_FACTOR: Real = 0.2;

/// The share of the tolerance each step's estimate is held to. For smooth histories the estimate (backward
/// Euler's local error) is far above the trapezoidal rule's own, but not at a jump of strain: a branch jumped to
/// `ε₁` at `t_n` gets `r/(1 + r) ε₁` from the trapezoidal rule (which averages the strains before and after),
/// `2r/(1 + 2r) ε₁` from backward Euler and `(1 − e^{−2r}) ε₁` exactly (`r = hλ/2`), so both the trapezoidal
/// error and the estimate are `r ε₁` to first order: the estimate *equals* the error there. The errors of the
/// steps that follow add to it before the material relaxes it away, so the estimate is held to half the
/// tolerance. Measured global errors over the tolerance: creep after a jump 0.50 / 0.43 / 0.47 at 1e-3 / 1e-4 /
/// 1e-5 (1.07 when held to all of the tolerance); pure bending 0.26 / 0.20 / 0.31; the four paper cases at
/// 1e-1 … 1e-4 at most 0.30 (docs/speed.md, `cargo bench --bench adaptive`).
pub(crate) const LOCAL_FRACTION: Real = 0.5;

/// The estimate over its share of the tolerance ([`LOCAL_FRACTION`]): a step is accepted when this is at most
/// 1; 0 without an estimate (no internal variables).
pub(crate) fn error_ratio(estimate: Option<Real>, tolerance: Real) -> Real {
    estimate.map_or(0.0, |e| e / (LOCAL_FRACTION * tolerance))
}

/// Estimates below this fraction of the tolerance count as this fraction (the controller's powers of `e`
/// would otherwise overflow; the growth is limited anyway).
const SMALLEST_RATIO: Real = 1e-10;

/// The memory of the step-size controller.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepControl {
    /// The last accepted step's estimate over the tolerance (`None` at the start and after a rejection).
    pub previous_ratio: Option<Real>,
    /// Rejections of the step in progress (0 between steps).
    pub rejections: usize,
    /// Whether a step accepted above the tolerance at the smallest step has been reported.
    pub above_tolerance_reported: bool,
}

impl StepControl {
    /// The next step after an accepted step of size `h` whose estimate was `ratio` times the tolerance.
    pub fn accepted(&mut self, h: Real, ratio: Real) -> Real {
        let ratio = ratio.max(SMALLEST_RATIO);
        let mut factor = ratio.powf(-0.7 / ESTIMATE_ORDER);
        if let Some(previous) = self.previous_ratio {
            factor *= previous.powf(0.4 / ESTIMATE_ORDER);
        }
        self.previous_ratio = Some(ratio);
        h * (SAFETY * factor).clamp(MIN_FACTOR, MAX_FACTOR)
    }

    /// The step to retry with after a step of size `h` was rejected with the estimate `ratio` (> 1) times the
    /// tolerance.
    pub fn rejected(&mut self, h: Real, ratio: Real) -> Real {
        self.previous_ratio = None;
        self.rejections += 1;
        h * (SAFETY * ratio.powf(-1.0 / ESTIMATE_ORDER)).clamp(MIN_FACTOR, 1.0)
    }
}

impl Simulation<'_> {
    /// The time-error estimate of the step `t_n → t_np1` just converged (module docs), in Newton's normalised
    /// increment norm; `None` when no material has internal variables. Leaves the configuration as it is; may
    /// factorise the tangent at it when no factorisation is at hand.
    pub(super) fn time_error_estimate(
        &mut self,
        t_n: Real,
        t_np1: Real,
    ) -> Result<Option<Real>, SolverError> {
        let model = self.model;
        // The converged laws, with each material's companion laws over its points.
        let mut laws: Vec<SectionLaw> = self.materials.laws.clone();
        let mut companion = Vec::new();
        let mut any = false;
        for group in &self.materials.groups {
            let law = &model.materials()[group.material];
            let has = with_step_input(
                model,
                self.materials.places(),
                &group.points,
                (t_n, t_np1),
                |step| law.companion_laws(&group.state, step, &mut companion),
            )?;
            if has {
                any = true;
                for (&g, c) in group.points.iter().zip(&companion) {
                    laws[g] = *c;
                }
            }
        }
        if !any {
            return Ok(None);
        }
        let actions = Actions::at(model, t_np1, &self.releases.ramps);
        if !self.active_system().0.is_factored() {
            self.linearise(&actions, true)?;
            self.factor_tangent()?;
        }
        let gauge = self.releases.active_gauge();
        let damping = super::stabilisation::view(&self.stabiliser.damping);
        let (point, constraints) = super::assembly_terms(&self.terms, damping.as_ref(), gauge);
        self.assembler.assemble(
            &Assembly {
                disc: &self.disc,
                state: &self.solution.state,
                material: StepMaterial { laws: &laws },
                actions: &actions,
                terms: Terms {
                    point: &point,
                    constraints: &constraints,
                },
            },
            &mut self.work.lin,
            &mut Sink::Discard,
        );
        self.solve_increment();
        Ok(Some(
            self.increment_norm().max(self.held_stress_error(&laws)),
        ))
    }

    /// The difference of the converged laws' section stresses from `companion`'s at the converged strains, as
    /// the strain that carries it (`ΔN/C̄_N`, `ΔM/C̄_M` times the patch length: a rotation), largest over the
    /// points (module docs, *Estimate*: where nodes are held it is what the configuration cannot show).
    fn held_stress_error(&self, companion: &[SectionLaw]) -> Real {
        let (disc, state) = (&self.disc, &self.solution.state);
        let mut largest: Real = 0.0;
        for (g, (law, other)) in self.materials.laws.iter().zip(companion).enumerate() {
            if law == other {
                continue;
            }
            let strain = point_strains(disc, state, g);
            let (a, b) = (law.stress(&strain), other.stress(&strain));
            let (c_n, c_m) = law.stiffness();
            let length = self.measures.control_length[disc.patches[disc.points[g].patch].offset];
            for i in 0..3 {
                largest = largest
                    .max(((a.force[i] - b.force[i]) / c_n[i]).abs())
                    .max(((a.moment[i] - b.moment[i]) / c_m[i] * length).abs());
            }
        }
        largest
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Source: the controller's formula (module docs). A ratio of 1 keeps the step up to the safety factor; a
    /// small ratio grows it by at most `MAX_FACTOR`; a rejection shrinks by at least `MIN_FACTOR` and forgets the
    /// memory; the PI term shrinks the next step when the error grows from one step to the next.
    #[test]
    fn the_controller_follows_its_formula_and_limits() {
        let mut c = StepControl::default();
        assert!((c.accepted(1.0, 1.0) - SAFETY).abs() < 1e-15);
        assert_eq!(c.accepted(1.0, 1e-12), MAX_FACTOR);
        let grown = c.accepted(1.0, 0.5);
        // e_n = 0.5 after e_{n−1} = 1e-10 (floored): the memory damps the growth.
        let expected =
            (SAFETY * 0.5_f64.powf(-0.35) * SMALLEST_RATIO.powf(0.2)).clamp(MIN_FACTOR, MAX_FACTOR);
        assert!((grown - expected).abs() < 1e-12, "{grown} vs {expected}");
        assert_eq!(c.rejected(1.0, 1e6), MIN_FACTOR);
        assert_eq!(c.previous_ratio, None);
        assert_eq!(c.rejections, 1);
        let retry = c.rejected(1.0, 4.0);
        assert!((retry - SAFETY * 0.5).abs() < 1e-15);
    }
}
