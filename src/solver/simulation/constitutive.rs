//! The material's part of a step: preparing its constitutive data before Newton and advancing the internal
//! variables after convergence (paper §3.1).

use super::{Simulation, SolverTiming};
use crate::material::{
    ReducedTimeQuadrature, history_stress, step_coefficients_into, update_branch_strains,
};
use crate::math::Real;
use crate::solver::SolverError;
use crate::solver::assembly::{StepMaterial, point_strains};
use rayon::prelude::*;
use std::time::Instant;

impl Simulation<'_> {
    /// Prepares the constitutive data of the step `t_n → t_np1` (paper §3.1): the internal-variable
    /// coefficients of the design's integrator, the effective modulus `Ē` of `C̄ = S Ē` and, per collocation
    /// point, the history stresses from the converged strains at `t_n` (Ψ-terms of N/M_constitutive_disc).
    pub(super) fn prepare_step(&mut self, t_n: Real, t_np1: Real) -> Result<(), SolverError> {
        let start = Instant::now();
        let material = &self.model.material;
        let temperature = |t: Real| self.model.temperature.value(t);
        step_coefficients_into(
            material,
            self.model.integrator,
            &ReducedTimeQuadrature::default(),
            t_n,
            t_np1,
            &temperature,
            &mut self.coeffs,
        )?;
        self.modulus = self.coeffs.effective_modulus(material.prony());
        if material.num_branches() > 0 {
            // Per collocation point and independent: in parallel.
            let (disc, coeffs, strain_n, branches) =
                (&self.disc, &self.coeffs, &self.strain_n, &self.branches);
            self.history
                .par_iter_mut()
                .enumerate()
                .for_each(|(g, history)| {
                    let shape = &disc.shapes[disc.points[g].shape];
                    *history = history_stress(
                        material.prony(),
                        shape,
                        coeffs,
                        &strain_n[g],
                        branches.point(g),
                    );
                });
        }
        if !self.freeze_reported && material.is_frozen(temperature(t_np1)) {
            self.freeze_reported = true;
            if let Some(w) = material.wlf() {
                self.notices.push(format!(
                    "at t = {t_np1} the temperature {} °C is at or below Tg − C2 = {} °C: relaxation is frozen there (instantaneous moduli), as in Abaqus' TRS",
                    temperature(t_np1),
                    w.frozen_below()
                ));
            }
        }
        SolverTiming::add(&mut self.timing.material, start);
        Ok(())
    }

    /// After a converged step: advances the Maxwell-branch strains and the converged total strains.
    pub(super) fn commit_step(&mut self) {
        let start = Instant::now();
        let (disc, state, coeffs) = (&self.disc, &self.state, &self.coeffs);
        // Per collocation point and independent: in parallel.
        match self.model.material.num_branches() {
            0 => self
                .strain_n
                .par_iter_mut()
                .enumerate()
                .for_each(|(g, strain_n)| *strain_n = point_strains(disc, state, g)),
            branches => self
                .strain_n
                .par_iter_mut()
                .zip(self.branches.as_mut_slice().par_chunks_mut(branches))
                .enumerate()
                .for_each(|(g, (strain_n, point_branches))| {
                    let strain = point_strains(disc, state, g);
                    update_branch_strains(coeffs, &strain, strain_n, point_branches);
                    *strain_n = strain;
                }),
        }
        // Counted with the step's preparation.
        self.timing.material.1 += start.elapsed().as_secs_f64();
    }

    /// The constitutive data of the current (or last solved) step: `C̄ = S Ē` and the history stresses.
    pub(super) fn step_material(&self) -> StepMaterial<'_> {
        StepMaterial {
            modulus: self.modulus,
            history: &self.history,
        }
    }
}
