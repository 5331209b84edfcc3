//! Automatic stabilisation of time-driven steps ([`crate::model::StabilisationSettings`], issue 18 item 2):
//! viscous regularisation switched on where Newton stalls, its factor, and the energies it is judged by.
//!
//! **When.** A step whose Newton iteration fails (after the retry with a fresh tangent) is retried at the same
//! size with the damping of [`crate::solver::terms::damping::Damping`] on, instead of being cut. A damped step that
//! still fails is retried with the factor ten times larger, [`MAX_ESCALATIONS`] times, and then cut as before
//! (halving the step raises `c/h` as well). After a damped step converges the damping stays on for the next
//! step while the step dissipated more than `dissipated_fraction` of the strain energy — the motion is still
//! faster than the rule's estimate — and is switched off otherwise; a later stall switches it on again with a
//! new factor. Runs that never stall are unchanged to the bit.
//!
//! **The factor.** As Abaqus's automatic stabilisation (Abaqus Analysis User's Guide §7.1.1): `c` is chosen
//! so that the damped step would dissipate `f` (`dissipated_fraction`) of the strain energy `E` if it moved as
//! far as the estimate of its motion, here Newton's first increment `δ₁` of the failed attempt (the linearised
//! response to the step's change of load, with the tangent at the last converged state):
//! ```text
//! D = (c/h) Q(δ),    Q(δ) = Σ_g w_g (A_g |δx_g|² + δΘ_g · J_g δΘ_g),    c = f E h / Q(δ₁)
//! ```
//! over the interior collocation points `g` (where the damping acts) with trapezoidal weights `w_g` of the
//! reference arc length, the unit-density masses `A`, `J` of [`Damping::masses`], and `E` the strain energy at
//! the last converged state (or the largest the run reached, if that is larger: a device that stalls while
//! unloading still scales with the energy it stored). A given `factor` replaces the rule.
//!
//! **The energies.** The strain energy is `E = ½ Σ_g w_g (ΔΓ·N + ΔK·M)` over all collocation points (the
//! stored energy of an elastic rod; for a viscoelastic one the same measure of the work held in the section's
//! current forces), and a converged damped step dissipates `D = (c/h) Q` of its actual motion (`x − xₙ`,
//! `log(Rₙᵀ R)`). The run's ratio is the dissipated total over the largest strain energy it reached — not the
//! current one, which is zero once a released device is free — and the run is warned about once it has gone
//! above `limit` ([`StabiliserState::warnings`], giving the run's final ratio).
//!
//! **The force.** Energy alone misses a damping that carries the load: a device the damping holds still
//! dissipates little (issue 31: `factor: 1e9` kept the overloaded 45° bend's tip at 3.6e-4 where it moves 87,
//! and dissipated 1.2 % of the strain energy). So every damped step is also judged by force, at its converged
//! state: the damping's force and couple densities integrated along the rods (the trapezoidal weights over every
//! collocation point, ends included: the density is a field along the whole rod, although the equations
//! impose it at the interior points only; without the ends the overloaded bend's share came out 0.85),
//! ```text
//! D = Σ_g w_g (c/h) (A |x − xₙ| + |J Θ| / ℓ),
//! ```
//! against what acts on the device from outside, the loads and reactions,
//! ```text
//! E = Σ_nodes (|Σ_e σ R N_e| + |Σ_e σ R M_e| / ℓ) + Σ_g w_g Σ_terms (|n̄_t| + |m̄_t| / ℓ),
//! ```
//! (the rod ends' resultants at a node equal its load at free components and its reaction at prescribed ones; a
//! joint's cancel; `n̄_t`, `m̄_t` the force and couple densities of each of the simulation's point terms on its
//! own, [`crate::solver::terms`]: the distributed loads, and the contact of a wall, which is a reaction too —
//! added up term by term, so that a load and the wall that bears it do not cancel; without the contact, a
//! device the crimper holds would be judged against its node reactions alone), couples turned into forces
//! over the model size `ℓ` (the bounding-box diagonal of the
//! reference control points, the lever of the largest couple a force can make on it). The step's share is
//! `D / max(D, E)`: 0 for a quasi-static step, 1 when the damping balances the loads by itself (a load the
//! structure does not carry) or opposes the motion alone (a free device springing back). Above `limit` — the
//! same 5 % as the energy's: a damping force of 5 % of the loads is an equilibrium off by as much — the run is
//! warned about, with the number of such steps and the largest share.
//!
//! **Checkpoints.** A damped tangent is never carried past its step (its factorisation is forgotten when the
//! step converges), so a checkpoint's tangent is always an undamped one; the stabiliser's memory is in
//! [`StabiliserState`].

use super::Simulation;
use crate::math::{Real, Vec3};
use crate::model::StabilisationSettings;
use crate::solver::assembly::{Actions, point_strains};
use crate::solver::discretisation::point_increment;
use crate::solver::state::State;
use crate::solver::terms::damping::Damping;
use crate::solver::terms::{InteriorLoad, PointView};

/// How many times a damped step that still fails has its factor multiplied by [`ESCALATION`] before it is cut.
pub(crate) const MAX_ESCALATIONS: usize = 3;

/// The factor by which a failed damped step's damping is raised.
pub(crate) const ESCALATION: Real = 10.0;

/// The stabiliser's memory, kept over steps (and in checkpoints).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StabiliserState {
    /// The damping factor `c` \[1/time\] while the damping is on; `None` when off.
    pub factor: Option<Real>,
    /// Escalations of the factor in the step in progress (`MAX_ESCALATIONS`).
    pub escalations: usize,
    /// The factor the damping was last switched on with (the energy rule's, or the given one) \[1/time\]: it
    /// is lowered back towards this after each damped step.
    pub base_factor: Real,
    /// Energy dissipated by the damping so far \[energy\].
    pub dissipated: Real,
    /// The largest strain energy of the converged states so far \[energy\].
    pub peak_strain_energy: Real,
    /// The largest ratio of a step's dissipated energy to the strain energy at its end.
    pub largest_step_ratio: Real,
    /// Steps taken with the damping on.
    pub damped_steps: usize,
    /// When the run's ratio first exceeded the limit \[time\] (`None`: it has not).
    pub energy_limit_time: Option<Real>,
    /// The largest share of the damping force among the forces on the device of a damped step (module docs,
    /// *The force*).
    pub largest_force_share: Real,
    /// The time of the step with that share \[time\].
    pub largest_force_share_time: Real,
    /// Damped steps whose force share exceeded the limit.
    pub steps_above_force_limit: usize,
    /// Stalls whose damping factor the energy rule could not scale (the step was cut instead).
    pub unscaled_stalls: usize,
    /// The time the first of them tried to reach \[time\].
    pub first_unscaled_time: Real,
}

impl StabiliserState {
    /// The run's dissipated energy over the largest strain energy it reached (0 before any energy).
    pub fn ratio(&self) -> Real {
        if self.peak_strain_energy > 0.0 {
            self.dissipated / self.peak_strain_energy
        } else {
            0.0
        }
    }

    /// Whether the run went above `settings.limit` by energy (the run's ratio, now or at some step) or by force
    /// (a damped step's force share): what [`StabiliserState::warnings`] warns about.
    pub fn above_limit(&self, settings: &StabilisationSettings) -> bool {
        self.energy_limit_time.is_some() || self.largest_force_share > settings.limit
    }

    /// What the run must say about its stabilisation so far (summary.json's `warnings` and stderr): the
    /// dissipated energy above the limit, with the run's ratio now; damped steps whose damping force carried
    /// more than the limit's share of the loads; stalls the damping could not be scaled for.
    pub fn warnings(&self, settings: &StabilisationSettings) -> Vec<String> {
        let mut out = Vec::new();
        let limit = settings.limit;
        let advice = if settings.factor.is_some() {
            "a smaller `solver.stabilisation.factor`, or none (the energy rule then chooses it), a slower programme or a finer mesh may keep it so"
        } else {
            "a smaller `solver.stabilisation.dissipated_fraction`, a slower programme or a finer mesh may keep it so"
        };
        if let Some(since) = self.energy_limit_time {
            let ratio = self.ratio();
            out.push(format!(
                "the stabilisation dissipated {ratio:.3e} of the largest strain energy over the run ({:.3e} of {:.3e}, in {} damped steps), {}: the result is not quasi-static ({advice})",
                self.dissipated,
                self.peak_strain_energy,
                self.damped_steps,
                if ratio > limit {
                    format!("above the limit {limit} since t = {since}")
                } else {
                    format!(
                        "below the limit {limit} in the end (the strain energy grew) but above it from t = {since}"
                    )
                }
            ));
        }
        if self.largest_force_share > limit {
            out.push(format!(
                "in {} of the {} damped steps the damping force was more than {limit} of the forces on the device from outside (its loads, reactions and walls), up to {:.3e} of them at t = {}: there the damping, not the structure, carried the load, and the result is not quasi-static ({advice})",
                self.steps_above_force_limit,
                self.damped_steps,
                self.largest_force_share,
                self.largest_force_share_time
            ));
        }
        if self.unscaled_stalls > 0 {
            out.push(format!(
                "stabilisation could not scale its damping factor for the step to t = {}{} (no strain energy yet, or no motion in Newton's first increment): the step was cut instead; give `solver.stabilisation.factor` to damp such a step",
                self.first_unscaled_time,
                if self.unscaled_stalls > 1 {
                    format!(" and {} later stalls", self.unscaled_stalls - 1)
                } else {
                    String::new()
                }
            ));
        }
        out
    }
}

/// What the stabilisation did in one converged step (runs with `solver.stabilisation`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepStabilisation {
    /// The damping factor `c` of the step \[1/time\]; 0 when the step was undamped.
    pub factor: Real,
    /// Energy the damping dissipated in the step \[energy\] (the run's total is in [`StabiliserState`]).
    pub dissipated: Real,
    /// Strain energy at the step's end \[energy\].
    pub strain_energy: Real,
    /// The damping force's share of the forces on the device at the step's end (module docs, *The force*); 0
    /// when the step was undamped.
    pub force_share: Real,
}

/// The stabilisation's part of a simulation: its memory over the run and the damping of the attempt in
/// progress.
#[derive(Debug, Default)]
pub(super) struct Stabiliser {
    /// The stabiliser's memory: kept over an abandoned attempt (a failed attempt is what switches the damping
    /// on or raises it) and saved by a checkpoint ([`super::Checkpoint::stabiliser`]).
    pub(super) memory: StabiliserState,
    /// The damping of the attempt in progress: the last converged state and `c/h` (`None`: undamped); dropped
    /// when the attempt ends, either way.
    pub(super) damping: Option<(State, Real)>,
    /// The first Newton increment of the last attempt (runs with stabilisation: the estimate of a stalled
    /// step's motion, module docs).
    pub(super) first_increment: Vec<Real>,
}

/// The damping of the attempt in progress as the assembly sees it.
pub(super) fn view(damping: &Option<(State, Real)>) -> Option<Damping<'_>> {
    damping.as_ref().map(|(previous, rate)| Damping {
        previous,
        rate: *rate,
    })
}

impl Simulation<'_> {
    /// The strain energy of the current state, `½ Σ_g w_g (ΔΓ·N + ΔK·M)` (module docs) \[energy\].
    pub fn strain_energy(&self) -> Real {
        let weights = self.point_weights();
        (0..self.disc.points.len())
            .map(|g| {
                let strain = point_strains(&self.disc, &self.solution.state, g);
                let stress = self.materials.laws[g].stress(&strain);
                0.5 * weights[g]
                    * (strain.force.dot(&stress.force) + strain.moment.dot(&stress.moment))
            })
            .sum()
    }

    /// The stabiliser's memory: the damping factor, if on, and the dissipated and strain energies so far.
    pub fn stabilisation(&self) -> &StabiliserState {
        &self.stabiliser.memory
    }

    /// What the run must say about its stabilisation so far ([`StabiliserState::warnings`]); none without
    /// `solver.stabilisation`.
    pub fn stabilisation_warnings(&self) -> Vec<String> {
        self.model
            .solver()
            .stabilisation
            .map_or_else(Vec::new, |settings| {
                self.stabiliser.memory.warnings(&settings)
            })
    }

    /// The damping force's share `D / max(D, E)` of the forces on the device in the current state, under the
    /// damping `d` and the loads at time `t` (module docs, *The force*); 0 when nothing acts.
    pub(crate) fn damping_force_share(&self, t: Real, d: Damping<'_>) -> Real {
        let disc = &self.disc;
        let weights = self.point_weights();
        let lever = disc.length_scale;
        let actions = Actions::at(self.model, t, &self.releases.ramps);
        let state = &self.solution.state;
        let (mut damping, mut external) = (0.0, 0.0);
        for (g, point) in disc.points.iter().enumerate() {
            let w = weights[g];
            let view = PointView {
                disc,
                state,
                actions: &actions,
                g,
                point,
                shape: &disc.shapes[point.shape],
                rotation_t: state.rotation[g].transpose(),
                tangent: false,
            };
            // Each term on its own: a load and the contact that bears it are both forces from outside.
            for term in &self.terms {
                let mut load = InteriorLoad::default();
                term.interior(&view, &mut load);
                let couple = load.couple.unwrap_or_else(Vec3::zeros)
                    + load
                        .material_couple
                        .map_or_else(Vec3::zeros, |m| state.rotation[g] * m);
                external +=
                    w * (load.force.unwrap_or_else(Vec3::zeros).norm() + couple.norm() / lever);
            }
            let (area, inertia) = Damping::masses(&disc.shapes[point.shape]);
            let (dx, theta) = d.motion(disc, state, g);
            damping +=
                w * d.rate * (area * dx.norm() + inertia.component_mul(&theta).norm() / lever);
        }
        for k in 0..self.model.nodes.len() {
            let (force, moment) = self
                .node_end_resultants(k)
                .iter()
                .fold((Vec3::zeros(), Vec3::zeros()), |(f, m), (ef, em)| {
                    (f + ef, m + em)
                });
            external += force.norm() + moment.norm() / lever;
        }
        let largest = damping.max(external);
        if largest > 0.0 {
            damping / largest
        } else {
            0.0
        }
    }

    /// `Q` of a motion given per interior collocation point by `motion(g) = (δx, δΘ)` (module docs).
    fn motion_measure(&self, motion: impl Fn(usize) -> (Vec3, Vec3)) -> Real {
        let weights = self.point_weights();
        let disc = &self.disc;
        (0..disc.points.len())
            .filter(|&g| !disc.is_end(g))
            .map(|g| {
                let (area, inertia) = Damping::masses(&disc.shapes[disc.points[g].shape]);
                let (dx, theta) = motion(g);
                weights[g] * (area * dx.norm_squared() + theta.dot(&inertia.component_mul(&theta)))
            })
            .sum()
    }

    /// Trapezoidal weights of the collocation points in the reference arc length, patch by patch.
    fn point_weights(&self) -> &[Real] {
        self.measures.point_weights(self.model, &self.disc)
    }

    /// Called after a step of size `dt` to `target` failed and was rolled back: switches the damping on (or
    /// raises it) for a retry at the same size, and says whether to retry. `false`: stabilisation is off,
    /// exhausted for this step, or cannot be scaled; the step is then cut.
    pub(super) fn stabilise_retry(&mut self, dt: Real, target: Real) -> bool {
        let Some(settings) = self.model.solver().stabilisation else {
            return false;
        };
        match self.stabiliser.memory.factor {
            Some(c) if self.stabiliser.memory.escalations < MAX_ESCALATIONS => {
                self.stabiliser.memory.factor = Some(c * ESCALATION);
                self.stabiliser.memory.escalations += 1;
                true
            }
            Some(_) => false,
            None => {
                let c = settings.factor.unwrap_or_else(|| {
                    let energy = self
                        .strain_energy()
                        .max(self.stabiliser.memory.peak_strain_energy);
                    let n = self.disc.num_unknowns();
                    let first = &self.stabiliser.first_increment;
                    let motion = if first.len() >= n {
                        self.motion_measure(|g| point_increment(&self.disc, first, g))
                    } else {
                        0.0
                    };
                    settings.dissipated_fraction * energy * dt / motion
                });
                if !(c.is_finite() && c > 0.0) {
                    let s = &mut self.stabiliser.memory;
                    if s.unscaled_stalls == 0 {
                        s.first_unscaled_time = target;
                    }
                    s.unscaled_stalls += 1;
                    return false;
                }
                self.stabiliser.memory.factor = Some(c);
                self.stabiliser.memory.base_factor = c;
                self.stabiliser.memory.escalations = 0;
                true
            }
        }
    }

    /// After a converged step to `t`: its damping's dissipated energy and force share and the strain energy (for
    /// runs with stabilisation), the damping switched off when the step dissipated no more than the fraction
    /// aimed at, a damped tangent forgotten, and when the run went above the limit remembered.
    pub(super) fn account_stabilisation(&mut self, t: Real) -> Option<StepStabilisation> {
        let settings = self.model.solver().stabilisation?;
        let energy = self.strain_energy();
        let damping = self.stabiliser.damping.take();
        let factor = self
            .stabiliser
            .memory
            .factor
            .filter(|_| damping.is_some())
            .unwrap_or(0.0);
        let dissipated = view(&damping).map_or(0.0, |d| {
            d.rate * self.motion_measure(|g| d.motion(&self.disc, &self.solution.state, g))
        });
        let force_share = view(&damping).map_or(0.0, |d| self.damping_force_share(t, d));
        let s = &mut self.stabiliser.memory;
        s.escalations = 0;
        s.peak_strain_energy = s.peak_strain_energy.max(energy);
        if damping.is_some() {
            s.damped_steps += 1;
            s.dissipated += dissipated;
            if force_share > s.largest_force_share {
                s.largest_force_share = force_share;
                s.largest_force_share_time = t;
            }
            if force_share > settings.limit {
                s.steps_above_force_limit += 1;
            }
            if energy > 0.0 {
                s.largest_step_ratio = s.largest_step_ratio.max(dissipated / energy);
            }
            // The least damping that converges: lowered by the escalation factor after every damped step, and
            // off once below the energy rule's value or once the step dissipated no more than it aims at.
            let lowered = s
                .factor
                .map(|c| c / ESCALATION)
                .filter(|&c| c >= s.base_factor);
            s.factor = lowered.filter(|_| {
                dissipated > settings.dissipated_fraction * energy.max(s.peak_strain_energy)
            });
            self.forget_factorisation();
        }
        let s = &mut self.stabiliser.memory;
        if s.energy_limit_time.is_none() && s.ratio() > settings.limit {
            s.energy_limit_time = Some(t);
        }
        Some(StepStabilisation {
            factor,
            dissipated,
            strain_energy: energy,
            force_share,
        })
    }
}
