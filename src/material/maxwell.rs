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
//!
//! # Temperature that varies along the rod
//!
//! The paper takes the temperature uniform, so the rates `λ_α`, hence the coefficients `(β_α, γ_α, δ_α)` of (★)
//! and `Ē`, are the same at every point, and the s-derivatives of the branch strains obey (★) with the same
//! coefficients ([`super::history`]). When `T = T(s, t)` ([`StepInput::field`]) the continuous evolution
//! `ε̇_α = λ_α(T(s, t)) (ε − ε_α)` differentiated along the reference arc length gives
//!
//! ```text
//! ε̇_α,s = λ_α (ε,s − ε_α,s) + λ_α,s (ε − ε_α),        λ_α,s = λ_α · d ln(rate_factor)/dT · T,s,
//! d ln(rate_factor)/dT = ln 10 · C1 C2 / (C2 + T − Tg)²                  (from paper Eq. at),
//! ```
//!
//! a term the paper's `T,s = 0` removes. We differentiate the *discrete* update (★) instead of discretising this
//! equation, so that the stored `ε_α,s` stay the exact s-derivative of the stored `ε_α` (the balance equations
//! need `N,s` consistent with `N`):
//!
//! ```text
//! ε_α,s^{n+1} = β_α ε,s^{n+1} + γ_α ε,s^n + δ_α ε_α,s^n + β_α,s ε^{n+1} + γ_α,s ε^n + δ_α,s ε_α^n,
//! ```
//!
//! with the coefficient slopes of [`super::step_coefficients_with_slope_into`] (a consistent discretisation of
//! the equation above: its extra terms are the slopes of the rates). Inserted into `σ = E∞ ε + Σ_α E_α (ε − ε_α)`
//! and multiplied by the section shapes, which do not vary along a patch:
//!
//! ```text
//! N,s = C̄_N Γ_N,s + C̄_N,s Γ_N − H_N,s,      C̄_N,s = S_N ⊙ Ē,s,     Ē,s = −Σ_α E_α β_α,s,
//! H_N,s = S_N ⊙ Σ_α E_α (γ_α Γ_N,s^n + δ_α Γ_Nα,s^n + γ_α,s Γ_N^n + δ_α,s Γ_Nα^n),
//! ```
//!
//! and likewise for `M,s` ([`SectionLaw::with_slope`], [`super::add_history_slope`],
//! [`super::update_branch_strains_with_slope`]); the tangent gains `∂N,s/∂Γ_N = C̄_N,s`, `∂M,s/∂K_M = C̄_M,s`. The
//! moduli themselves do not depend on temperature in this material (only the relaxation times do), so no
//! `E,s` term appears. The coefficients are then computed per point and step (a few exponentials per point:
//! negligible beside the assembly); with a uniform temperature nothing changes.

use super::constitutive::{
    ConstitutiveLaw, PointStrains, SECTION_NUMBERS, StepInput, check_state_length, push_strains,
    push_stress, read_strains, read_stress,
};
use super::{
    BranchHistory, Integrator, Material, MaterialError, MaterialNotice, ReducedTimeQuadrature,
    SectionLaw, SectionShape, SectionStrains, SectionStress, StepCoefficients, add_history_slope,
    history_stress, step_coefficients_into, step_coefficients_with_slope_into,
    update_branch_strains, update_branch_strains_with_slope,
};
use crate::math::{Real, Vec3};
use rayon::prelude::*;

/// The generalized Maxwell/WLF material with its time integrator (module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
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
    /// Per point, when the temperature varies along the rod (module docs); `None` when it is uniform.
    field: Option<Box<PointSteps>>,
}

/// The step data of every point where the temperature varies along the rod.
#[derive(Debug, Clone, PartialEq)]
struct PointSteps {
    /// Coefficients of (★) per point.
    coeffs: Vec<StepCoefficients>,
    /// Their s-derivatives per point \[1/length\].
    coeffs_ds: Vec<StepCoefficients>,
    /// `(Ē, Ē,s)` per point for the step being solved \[stress, stress/length\].
    modulus: Vec<(Real, Real)>,
    /// `(Ē, Ē,s)` per point of the last converged step.
    converged_modulus: Vec<(Real, Real)>,
}

impl PointSteps {
    /// Identity coefficients and the equilibrium modulus `e_inf` everywhere.
    fn new(points: usize, branches: usize, e_inf: Real) -> Self {
        Self {
            coeffs: vec![StepCoefficients::identity(branches); points],
            coeffs_ds: vec![StepCoefficients::identity(branches); points],
            modulus: vec![(e_inf, 0.0); points],
            converged_modulus: vec![(e_inf, 0.0); points],
        }
    }
}

/// `Ē,s = −Σ_α E_α β_α,s` \[stress/length\] (module docs).
fn modulus_slope(prony: &super::Prony, coeffs_ds: &StepCoefficients) -> Real {
    -prony
        .branches()
        .iter()
        .zip(&coeffs_ds.beta)
        .map(|(b, beta_s)| b.modulus * beta_s)
        .sum::<Real>()
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
            field: None,
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
        if let Some(field) = step.field {
            self.prepare_field_step(state, step, field)?;
        } else {
            state.field = None;
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
        }
        let Some(wlf) = material.wlf() else {
            return Ok(None);
        };
        let temperature = match step.field {
            Some(field) => (0..state.shapes.len())
                .map(|i| field(i, step.t_np1).0)
                .fold(Real::INFINITY, Real::min),
            None => (step.temperature)(step.t_np1),
        };
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
        if let Some(field) = step.field {
            let (m, span) = (material.num_branches(), (step.t_n, step.t_np1));
            return (0..state.shapes.len())
                .into_par_iter()
                .map(|i| {
                    let (mut coeffs, mut coeffs_ds) =
                        (StepCoefficients::identity(m), StepCoefficients::identity(m));
                    let (modulus, slope, history) = self.point_step(
                        companion,
                        state,
                        i,
                        span,
                        &|t| field(i, t),
                        &mut coeffs,
                        &mut coeffs_ds,
                    )?;
                    Ok(SectionLaw::with_slope(
                        &state.shapes[i],
                        modulus,
                        slope,
                        history,
                    ))
                })
                .collect::<Result<Vec<_>, MaterialError>>()
                .map(|laws| {
                    *out = laws;
                    true
                });
        }
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
        let (shape, history) = (&state.shapes[point], state.history[point]);
        match &state.field {
            Some(field) => {
                let (modulus, slope) = field.modulus[point];
                SectionLaw::with_slope(shape, modulus, slope, history)
            }
            None => SectionLaw::new(shape, state.modulus, history),
        }
    }

    /// `ε_α ← β_α ε^{n+1} + γ_α ε^n + δ_α ε_α` and `ε^n ← ε^{n+1}` at every point (in parallel); the step's `Ē`
    /// and `H` become the converged ones.
    fn commit_step(&self, state: &mut MaxwellState, strains: PointStrains<'_>) {
        let (coeffs, field) = (&state.coeffs, &state.field);
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
                    match field {
                        Some(f) => update_branch_strains_with_slope(
                            &f.coeffs[i],
                            &f.coeffs_ds[i],
                            &strain,
                            strain_n,
                            point_branches,
                        ),
                        None => update_branch_strains(coeffs, &strain, strain_n, point_branches),
                    }
                    *strain_n = strain;
                }),
        }
        state.converged_modulus = state.modulus;
        state.converged_history.copy_from_slice(&state.history);
        if let Some(field) = &mut state.field {
            field.converged_modulus.copy_from_slice(&field.modulus);
        }
    }

    fn viscous_strains(&self, state: &MaxwellState, i: usize) -> Option<(Vec3, Vec3)> {
        let branches = self.material.prony().branches();
        let total: Real = branches.iter().map(|b| b.modulus).sum();
        if branches.is_empty() || total <= 0.0 {
            return None;
        }
        let (force, moment) = branches
            .iter()
            .zip(state.branches.point(i))
            .fold((Vec3::zeros(), Vec3::zeros()), |(f, m), (b, e)| {
                (f + e.force * b.modulus, m + e.moment * b.modulus)
            });
        Some((force / total, moment / total))
    }

    fn roll_back(&self, state: &mut MaxwellState) {
        state.modulus = state.converged_modulus;
        state.history.copy_from_slice(&state.converged_history);
        if let Some(field) = &mut state.field {
            field.modulus.copy_from_slice(&field.converged_modulus);
        }
    }

    /// Per point `ε^n` (12 numbers), then per point and branch `ε_α^n` (12 each), then the converged `Ē` and per
    /// point its `H` (12 each); with a temperature varying along the rod, then per point `(Ē, Ē,s)`.
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
        // With a temperature varying along the rod: `(Ē, Ē,s)` per point.
        if let Some(field) = &state.field {
            for &(modulus, slope) in &field.converged_modulus {
                out.extend([modulus, slope]);
            }
        }
    }

    fn restore_state(
        &self,
        state: &mut MaxwellState,
        values: &[Real],
    ) -> Result<(), MaterialError> {
        let points = state.strain_n.len();
        let m = self.material.num_branches();
        let uniform_length = saved_length(points, m);
        let with_field = values.len() == uniform_length + 2 * points && points > 0;
        if !with_field {
            check_state_length(values, uniform_length)?;
        }
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
        state.field = with_field.then(|| {
            let mut field = PointSteps::new(points, m, self.material.prony().e_inf());
            for (pair, chunk) in field
                .converged_modulus
                .iter_mut()
                .zip(values[uniform_length..].chunks_exact(2))
            {
                *pair = (chunk[0], chunk[1]);
            }
            Box::new(field)
        });
        // At a converged step the step's data are the converged ones.
        self.roll_back(state);
        Ok(())
    }
}

impl MaxwellLaw {
    /// [`ConstitutiveLaw::prepare_step`] where the temperature varies along the rod: per point (in parallel) its
    /// coefficients and their slopes, `(Ē, Ē,s)` and the history stresses with their slope terms (module docs).
    fn prepare_field_step(
        &self,
        state: &mut MaxwellState,
        step: &StepInput<'_>,
        field: &super::PointTemperature<'_>,
    ) -> Result<(), MaterialError> {
        let material = &self.material;
        let (points, m) = (state.shapes.len(), material.num_branches());
        let mut steps = state
            .field
            .take()
            .unwrap_or_else(|| Box::new(PointSteps::new(points, m, material.prony().e_inf())));
        let mut history = std::mem::take(&mut state.history);
        let span = (step.t_n, step.t_np1);
        let result = steps
            .coeffs
            .par_iter_mut()
            .zip(steps.coeffs_ds.par_iter_mut())
            .zip(steps.modulus.par_iter_mut())
            .zip(history.par_iter_mut())
            .enumerate()
            .try_for_each(|(i, (((coeffs, coeffs_ds), modulus), h))| {
                let (e, e_s, stress) = self.point_step(
                    self.integrator,
                    state,
                    i,
                    span,
                    &|t| field(i, t),
                    coeffs,
                    coeffs_ds,
                )?;
                (*modulus, *h) = ((e, e_s), stress);
                Ok(())
            });
        state.history = history;
        state.field = Some(steps);
        result
    }

    /// One point's step where the temperature varies along the rod, advanced by `integrator` (the law's or its
    /// companion): fills its coefficients and their slopes and returns `(Ē, Ē,s, H)` with the history's slope
    /// terms (module docs), from the point's internal variables at `t_n`.
    #[allow(clippy::too_many_arguments)]
    fn point_step(
        &self,
        integrator: Integrator,
        state: &MaxwellState,
        i: usize,
        (t_n, t_np1): (Real, Real),
        temperature: &dyn Fn(Real) -> (Real, Real),
        coeffs: &mut StepCoefficients,
        coeffs_ds: &mut StepCoefficients,
    ) -> Result<(Real, Real, SectionStress), MaterialError> {
        let prony = self.material.prony();
        step_coefficients_with_slope_into(
            &self.material,
            integrator,
            &ReducedTimeQuadrature::default(),
            t_n,
            t_np1,
            temperature,
            coeffs,
            Some(&mut *coeffs_ds),
        )?;
        let history = if prony.num_branches() == 0 {
            SectionStress::default()
        } else {
            let (shape, strain_n, branches) = (
                &state.shapes[i],
                &state.strain_n[i],
                state.branches.point(i),
            );
            let mut h = history_stress(prony, shape, coeffs, strain_n, branches);
            add_history_slope(prony, shape, coeffs_ds, strain_n, branches, &mut h);
            h
        };
        Ok((
            coeffs.effective_modulus(prony),
            modulus_slope(prony, coeffs_ds),
            history,
        ))
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
                    field: None,
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
            field: None,
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

    // Source: the stored s-derivatives must be the derivatives of the stored values (module docs, *Temperature
    // that varies along the rod*). Three points at s = −δ, 0, δ of a rod with T(s, t) = T₀(t) + s·G(t) (cooling
    // through Tg or heating through it, 12 K per unit length) and smooth strain histories ε(s, t) given with their exact
    // s-derivatives; after several steps N,s and M,s of the law at s = 0 must equal central differences of N and
    // M across the points. δ = 1e-4: truncation ~δ² = 1e-8 and round-off ~1e-16/δ = 1e-12 relative to the
    // stress slopes; tolerance 1e-6 relative. Without the slope terms (the paper's uniform-temperature
    // recursion: each point its own temperature, T,s = 0) the same check is off by 180–420 % (measured; asserted
    // above 1 %, so the test sees the terms go missing).

    #[test]
    fn stress_slopes_are_derivatives_where_the_temperature_varies_along_the_rod() {
        let delta = 1e-4;
        let positions = [-delta, 0.0, delta];
        let strain = |s: Real, t: Real| {
            let w = |k: Real| (1.0 + 0.5 * k * s + 0.3 * s * s) * (t * k).sin() * 1e-2;
            let w_s = |k: Real| (0.5 * k + 0.6 * s) * (t * k).sin() * 1e-2;
            SectionStrains {
                force: Vec3::new(w(1.0), w(2.0), w(3.0)),
                moment: Vec3::new(w(4.0), w(5.0), w(6.0)),
                force_ds: Vec3::new(w_s(1.0), w_s(2.0), w_s(3.0)),
                moment_ds: Vec3::new(w_s(4.0), w_s(5.0), w_s(6.0)),
            }
        };
        let gradient = 12.0;
        let mismatch = |integrator: Integrator, rate: Real, with_slopes: bool| {
            let temperature = |t: Real| if rate < 0.0 { 85.0 } else { 40.0 } + rate * t;
            let field = |i: usize, t: Real| (temperature(t) + gradient * positions[i], gradient);
            let law = MaxwellLaw::new(Material::pla_van_manen_2021(), integrator);
            let shape = law.section_shape(&CircularSection::try_new(0.6).expect("valid").into());
            let mut state = law.new_state(vec![shape; 3]);
            let h = 0.02;
            let mut t = 0.0;
            // Without the slopes: the paper's recursion, each point with its own temperature and T,s = 0.
            let without = |i: usize, t: Real| (field(i, t).0, 0.0);
            let at: &crate::material::PointTemperature<'_> =
                if with_slopes { &field } else { &without };
            for _ in 0..30 {
                let step = StepInput {
                    t_n: t,
                    t_np1: t + h,
                    temperature: &temperature,
                    field: Some(at),
                };
                law.prepare_step(&mut state, &step).expect("valid step");
                t += h;
                law.commit_step(&mut state, &|i| strain(positions[i], t));
            }
            let stress: Vec<SectionStress> = (0..3)
                .map(|i| law.section_law(&state, i).stress(&strain(positions[i], t)))
                .collect();
            let fd_force = (stress[2].force - stress[0].force) / (2.0 * delta);
            let fd_moment = (stress[2].moment - stress[0].moment) / (2.0 * delta);
            ((stress[1].force_ds - fd_force).norm() / fd_force.norm())
                .max((stress[1].moment_ds - fd_moment).norm() / fd_moment.norm())
        };
        // The trapezoidal rule only while heating: cooling, its amplification |δ| ≫ 1 of the fast branches (module
        // docs of `integrator`) makes N a difference of numbers 1e8 times larger, and the central difference
        // loses every digit to round-off (measured: 3e-4 at δ = 1e-4, 3e-3 at 1e-5) though the slopes are right.
        for (integrator, rate) in [
            (Integrator::Trapezoidal, 60.0),
            (Integrator::BackwardEuler, -60.0),
            (Integrator::BackwardEuler, 60.0),
            (Integrator::Exponential, -60.0),
            (Integrator::Exponential, 60.0),
        ] {
            let with = mismatch(integrator, rate, true);
            let without = mismatch(integrator, rate, false);
            eprintln!("{integrator:?} at {rate} K/s: {with:.3e} {without:.3e}");
            assert!(
                with < 1e-6,
                "{integrator:?}: N,s and M,s against central differences: {with:.3e}"
            );
            assert!(
                without > 1e-2,
                "{integrator:?}: without the slope terms: {without:.3e}"
            );
        }
    }
}
