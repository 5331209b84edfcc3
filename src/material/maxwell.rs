//! The generalized Maxwell (Prony) solid with the WLF time–temperature shift, advanced by one of the
//! [`Integrator`]s: the paper's thermo-viscoelastic material (§2.2, §3.1) as a [`ConstitutiveLaw`].
//!
//! Per point the internal variables are the converged total strains `ε^n` (`Γ_N`, `K_M` and their
//! s-derivatives, [`SectionStrains`]) and the branch strains `ε_α^n` of every Maxwell branch
//! ([`BranchHistory`]). A step (module docs of [`super`] and [`super::integrator`]):
//!
//! ```text
//! prepare:  (β_α, γ_α, δ_α) from T over the step,  Ē = E∞ + Σ_α E_α (1 − β_α),
//!           H = S ⊙ Σ_α E_α (γ_α ε^n + δ_α ε_α^n)            (paper Eqs. N_constitutive_disc, M_constitutive_disc)
//! law:      N = S_N ⊙ Ē Γ_N − H_N, …                          ([`SectionLaw`])
//! commit:   ε_α ← β_α ε^{n+1} + γ_α ε^n + δ_α ε_α,  ε^n ← ε^{n+1}   (Eq. evol_f_thermal_disc and its kin)
//! ```
//!
//! The step's `Ē` and `H` are kept with those of the last converged step, which a roll-back restores (the
//! section laws of the converged state are then those that produced it, so its stresses — the reactions a
//! release captures — are the converged ones).

use super::constitutive::{
    ConstitutiveLaw, PointStrains, SECTION_NUMBERS, StepInput, check_state_length, push_strains,
    push_stress, read_strains, read_stress,
};
use super::{
    BranchHistory, Integrator, Material, MaterialError, MaterialNotice, ReducedTimeQuadrature,
    SectionLaw, SectionShape, SectionStrains, SectionStress, StepCoefficients, history_stress,
    step_coefficients_into, update_branch_strains,
};
use crate::math::Real;
use rayon::prelude::*;

/// The generalized Maxwell/WLF material with its time integrator (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct MaxwellLaw {
    material: Material,
    integrator: Integrator,
}

impl MaxwellLaw {
    /// The law of a validated `material` advanced by `integrator`.
    pub fn new(material: Material, integrator: Integrator) -> Self {
        Self {
            material,
            integrator,
        }
    }

    /// The Prony series, Poisson ratio and WLF shift.
    pub fn material(&self) -> &Material {
        &self.material
    }

    /// The internal-variable update.
    pub fn integrator(&self) -> Integrator {
        self.integrator
    }
}

/// The internal variables of a Maxwell material at its points and the constitutive data of the step.
#[derive(Debug, Clone, PartialEq)]
pub struct MaxwellState {
    /// Section stiffness shapes per point.
    shapes: Vec<SectionShape>,
    /// Converged total strains per point at `t_n`.
    strain_n: Vec<SectionStrains>,
    /// Maxwell-branch strains per point and branch at `t_n`.
    branches: BranchHistory,
    /// Internal-variable update coefficients of the step being solved (or last solved).
    coeffs: StepCoefficients,
    /// Effective modulus `Ē` of the step being solved \[stress\].
    modulus: Real,
    /// History stresses `H` per point for the step being solved.
    history: Vec<SectionStress>,
    /// `Ē` of the last converged step \[stress\].
    converged_modulus: Real,
    /// `H` per point of the last converged step.
    converged_history: Vec<SectionStress>,
}

impl ConstitutiveLaw for MaxwellLaw {
    type State = MaxwellState;

    fn poisson(&self) -> Real {
        self.material.poisson()
    }

    /// The instantaneous (glassy) modulus `E0 = E∞ + Σ E_α`.
    fn temperature_shift(&self) -> Option<&super::Wlf> {
        self.material.wlf()
    }

    fn time_error_unsupported(&self) -> Option<String> {
        if self.material.num_branches() == 0 {
            return None;
        }
        self.integrator.companion().err().map(|why| {
            format!(
                "error-controlled steps need `integrator: trapezoidal` (the material's is `{}`): {why}",
                self.integrator.name()
            )
        })
    }

    fn reference_modulus(&self) -> Real {
        self.material.prony().instantaneous_modulus()
    }

    /// Branches at rest; before the first step the law of each point is the equilibrium spring's (`E∞`, no
    /// history): the reference state is unstrained, so its stresses are zero either way.
    fn new_state(&self, shapes: Vec<SectionShape>) -> MaxwellState {
        let points = shapes.len();
        let m = self.material.num_branches();
        let e_inf = self.material.prony().e_inf();
        MaxwellState {
            shapes,
            strain_n: vec![SectionStrains::default(); points],
            branches: BranchHistory::new(points, m),
            coeffs: StepCoefficients::identity(m),
            modulus: e_inf,
            history: vec![SectionStress::default(); points],
            converged_modulus: e_inf,
            converged_history: vec![SectionStress::default(); points],
        }
    }

    /// The integrator's coefficients for the step, `Ē` and, per point, the history stresses from the converged
    /// strains at `t_n` (Ψ-terms of paper Eqs. `N_constitutive_disc`, `M_constitutive_disc`); a notice when the
    /// temperature at `t_{n+1}` freezes relaxation.
    fn prepare_step(
        &self,
        state: &mut MaxwellState,
        step: &StepInput<'_>,
    ) -> Result<Option<MaterialNotice>, MaterialError> {
        let material = &self.material;
        step_coefficients_into(
            material,
            self.integrator,
            &ReducedTimeQuadrature::default(),
            step.t_n,
            step.t_np1,
            step.temperature,
            &mut state.coeffs,
        )?;
        state.modulus = state.coeffs.effective_modulus(material.prony());
        if material.num_branches() > 0 {
            // Per point and independent: in parallel.
            let MaxwellState {
                shapes,
                strain_n,
                branches,
                coeffs,
                history,
                ..
            } = state;
            history.par_iter_mut().enumerate().for_each(|(i, h)| {
                *h = history_stress(
                    material.prony(),
                    &shapes[i],
                    coeffs,
                    &strain_n[i],
                    branches.point(i),
                );
            });
        }
        let Some(wlf) = material.wlf() else {
            return Ok(None);
        };
        let temperature = (step.temperature)(step.t_np1);
        Ok(wlf
            .is_frozen(temperature)
            .then(|| MaterialNotice::RelaxationFrozen {
                time: step.t_np1,
                temperature,
                frozen_below: wlf.frozen_below(),
            }))
    }

    /// The companion integrator's coefficients for the step (computed here, not kept), its `Ē` and every point's
    /// history stresses from the internal variables at `t_n`: the laws `prepare_step` would give under
    /// [`Integrator::companion`]. An elastic Maxwell material (no branch) has no time error: `false`.
    fn companion_laws(
        &self,
        state: &MaxwellState,
        step: &StepInput<'_>,
        out: &mut Vec<SectionLaw>,
    ) -> Result<bool, MaterialError> {
        out.clear();
        let material = &self.material;
        if material.num_branches() == 0 {
            return Ok(false);
        }
        let companion =
            self.integrator
                .companion()
                .map_err(|why| MaterialError::NoTimeErrorEstimate {
                    integrator: self.integrator.name(),
                    why,
                })?;
        let mut coeffs = StepCoefficients::identity(material.num_branches());
        step_coefficients_into(
            material,
            companion,
            &ReducedTimeQuadrature::default(),
            step.t_n,
            step.t_np1,
            step.temperature,
            &mut coeffs,
        )?;
        let modulus = coeffs.effective_modulus(material.prony());
        (0..state.shapes.len())
            .into_par_iter()
            .map(|i| {
                let shape = &state.shapes[i];
                let history = history_stress(
                    material.prony(),
                    shape,
                    &coeffs,
                    &state.strain_n[i],
                    state.branches.point(i),
                );
                SectionLaw::new(shape, modulus, history)
            })
            .collect_into_vec(out);
        Ok(true)
    }

    #[inline]
    fn section_law(&self, state: &MaxwellState, point: usize) -> SectionLaw {
        SectionLaw::new(&state.shapes[point], state.modulus, state.history[point])
    }

    /// `ε_α ← β_α ε^{n+1} + γ_α ε^n + δ_α ε_α` and `ε^n ← ε^{n+1}` at every point (in parallel); the step's `Ē`
    /// and `H` become the converged ones.
    fn commit_step(&self, state: &mut MaxwellState, strains: PointStrains<'_>) {
        let coeffs = &state.coeffs;
        // Per point and independent: in parallel, each point's strain computed where it is used.
        match self.material.num_branches() {
            0 => state
                .strain_n
                .par_iter_mut()
                .enumerate()
                .for_each(|(i, strain_n)| *strain_n = strains(i)),
            m => state
                .strain_n
                .par_iter_mut()
                .zip(state.branches.as_mut_slice().par_chunks_mut(m))
                .enumerate()
                .for_each(|(i, (strain_n, point_branches))| {
                    let strain = strains(i);
                    update_branch_strains(coeffs, &strain, strain_n, point_branches);
                    *strain_n = strain;
                }),
        }
        state.converged_modulus = state.modulus;
        state.converged_history.copy_from_slice(&state.history);
    }

    fn roll_back(&self, state: &mut MaxwellState) {
        state.modulus = state.converged_modulus;
        state.history.copy_from_slice(&state.converged_history);
    }

    /// Per point `ε^n` (12 numbers), then per point and branch `ε_α^n` (12 each), then the converged `Ē` and per
    /// point its `H` (12 each).
    fn save_state(&self, state: &MaxwellState, out: &mut Vec<Real>) {
        out.reserve(saved_length(
            state.strain_n.len(),
            self.material.num_branches(),
        ));
        for s in &state.strain_n {
            push_strains(out, s);
        }
        for s in state.branches.as_slice() {
            push_strains(out, s);
        }
        out.push(state.converged_modulus);
        for h in &state.converged_history {
            push_stress(out, h);
        }
    }

    fn restore_state(
        &self,
        state: &mut MaxwellState,
        values: &[Real],
    ) -> Result<(), MaterialError> {
        let points = state.strain_n.len();
        let m = self.material.num_branches();
        check_state_length(values, saved_length(points, m))?;
        let mut chunks = values[..SECTION_NUMBERS * points * (1 + m)].chunks_exact(SECTION_NUMBERS);
        for (s, chunk) in state.strain_n.iter_mut().zip(chunks.by_ref()) {
            *s = read_strains(chunk);
        }
        for (s, chunk) in state.branches.as_mut_slice().iter_mut().zip(chunks) {
            *s = read_strains(chunk);
        }
        let rest = &values[SECTION_NUMBERS * points * (1 + m)..];
        state.converged_modulus = rest[0];
        for (h, chunk) in state
            .converged_history
            .iter_mut()
            .zip(rest[1..].chunks_exact(SECTION_NUMBERS))
        {
            *h = read_stress(chunk);
        }
        // At a converged step the step's data are the converged ones.
        self.roll_back(state);
        Ok(())
    }
}

/// Numbers [`MaxwellLaw::save_state`] writes for `points` points of `branches` branches.
fn saved_length(points: usize, branches: usize) -> usize {
    SECTION_NUMBERS * points * (2 + branches) + 1
}

#[cfg(test)]
mod tests {
    // Source: a saved and restored state continues exactly (bit for bit) as the original (the checkpoint
    // contract of `ConstitutiveLaw`), and a roll-back returns the step's law to the converged one. PLA
    // (15 branches, WLF) cooled through Tg; strains varied per step and point.
    use super::*;
    use crate::material::CircularSection;
    use crate::math::Vec3;

    fn strains(seed: Real) -> SectionStrains {
        let v =
            |k: Real| Vec3::new((seed * k).sin(), (seed + k).cos(), (0.3 * seed * k).sin()) * 1e-3;
        SectionStrains {
            force: v(1.0),
            moment: v(2.0),
            force_ds: v(3.0),
            moment_ds: v(4.0),
        }
    }

    #[test]
    fn saved_state_continues_exactly_and_roll_back_restores_the_law() {
        let law = MaxwellLaw::new(Material::pla_van_manen_2021(), Integrator::Exponential);
        let shape = law.section_shape(&CircularSection::try_new(0.6).expect("valid").into());
        let points = 3;
        let mut a = law.new_state(vec![shape; points]);
        let temperature = |t: Real| 90.0 - 30.0 * t;
        let run = |law: &MaxwellLaw, state: &mut MaxwellState, steps: std::ops::Range<usize>| {
            for n in steps {
                let step = StepInput {
                    t_n: 0.1 * n as Real,
                    t_np1: 0.1 * (n + 1) as Real,
                    temperature: &temperature,
                };
                law.prepare_step(state, &step).expect("valid step");
                law.commit_step(state, &|p| strains((n * points + p) as Real));
            }
        };
        run(&law, &mut a, 0..5);
        let mut saved = Vec::new();
        law.save_state(&a, &mut saved);
        assert_eq!(saved.len(), saved_length(points, 15));
        let mut b = law.new_state(vec![shape; points]);
        law.restore_state(&mut b, &saved).expect("same length");
        // (The step coefficients are scratch of the next prepare: not saved, not compared.)
        let numbers = |state: &MaxwellState| {
            let mut out = Vec::new();
            law.save_state(state, &mut out);
            let laws: Vec<SectionLaw> = (0..points).map(|p| law.section_law(state, p)).collect();
            (out, laws)
        };
        assert_eq!(
            numbers(&a),
            numbers(&b),
            "restored state equals the saved one"
        );
        run(&law, &mut a, 5..9);
        run(&law, &mut b, 5..9);
        assert_eq!(
            numbers(&a),
            numbers(&b),
            "continued states are equal bit for bit"
        );
        // A prepared step changes the laws; a roll-back restores the converged ones.
        let before = law.section_law(&a, 1);
        let step = StepInput {
            t_n: 0.9,
            t_np1: 1.0,
            temperature: &temperature,
        };
        law.prepare_step(&mut a, &step).expect("valid step");
        assert_ne!(law.section_law(&a, 1), before);
        law.roll_back(&mut a);
        assert_eq!(law.section_law(&a, 1), before);
        assert!(matches!(
            law.restore_state(&mut b, &saved[1..]),
            Err(MaterialError::StateLength { .. })
        ));
    }
}
