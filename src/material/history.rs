//! Branch strains of the rod at its collocation points, the history stresses they produce and their update.
//!
//! Because the strong form (paper Eqs. `gov_N_disc`, `gov_M_disc`) needs `N,s` and `M,s`, every collocation
//! point carries, per branch, the viscous strains `Γ_Nα`, `K_Mα` *and* their s-derivatives `Γ_Nα,s`, `K_Mα,s`
//! ([`SectionStrains`]: four `Vec3`). All four obey the same affine recursion (★) of [`super::integrator`]
//! with the same coefficients (the rates do not vary along `s` when the temperature is uniform over the rod,
//! DESIGN §4 "History variables"), so differentiating (★) in `s` is exact.
//!
//! Within a step (paper Eqs. `N_constitutive_disc`, `M_constitutive_disc`, generalised to every integrator):
//!
//! ```text
//! N^{n+1} = S_N ⊙ Ē Γ_N^{n+1} − H_N,     H_N = S_N ⊙ Σ_α E_α (γ_α Γ_N^n + δ_α Γ_Nα^n),
//! M^{n+1} = S_M ⊙ Ē K_M^{n+1} − H_M,     H_M = S_M ⊙ Σ_α E_α (γ_α K_M^n + δ_α K_Mα^n),
//! ```
//!
//! and the same with every strain replaced by its s-derivative for `N,s`, `M,s`. The history `H` is formed once
//! per step and point ([`history_stress`]); Newton evaluates the law with it ([`super::SectionLaw`], which
//! holds `C̄ = S ⊙ Ē` and `H`); after convergence [`update_branch_strains`] advances the branches in place.

use super::{Prony, SectionShape, StepCoefficients};
use crate::math::{Real, Vec3};

/// The four strain vectors of one point (material frame): total strains `Γ_N = Γ − Γ0`, `K_M = K − K0`
/// and their derivatives along the reference arc length — or the same four for one branch (`Γ_Nα`, …).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SectionStrains {
    /// Force-conjugate strain `Γ_N` (axial, two shears) \[-\].
    pub force: Vec3,
    /// Moment-conjugate strain `K_M` (twist, two curvatures) \[1/length\].
    pub moment: Vec3,
    /// `Γ_N,s` \[1/length\].
    pub force_ds: Vec3,
    /// `K_M,s` \[1/length²\].
    pub moment_ds: Vec3,
}

impl SectionStrains {
    /// `a·self + b·other`, component by component.
    fn combine(&self, a: Real, other: &Self, b: Real) -> Self {
        Self {
            force: self.force * a + other.force * b,
            moment: self.moment * a + other.moment * b,
            force_ds: self.force_ds * a + other.force_ds * b,
            moment_ds: self.moment_ds * a + other.moment_ds * b,
        }
    }
}

/// Section forces and moments at a point (material frame) — or the history part of them.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SectionStress {
    /// Internal force `N` \[force\].
    pub force: Vec3,
    /// Internal moment `M` \[force·length\].
    pub moment: Vec3,
    /// `N,s` \[force/length\].
    pub force_ds: Vec3,
    /// `M,s` \[force\].
    pub moment_ds: Vec3,
}

/// The branch strains of every collocation point: `num_points × num_branches` [`SectionStrains`] (four `Vec3`,
/// 96 bytes each), stored point-major — the `m` branches of point `i` are the contiguous slice
/// `[i·m, (i+1)·m)`, so the per-point work (parallel over points) reads one contiguous block. Zero-initialised
/// (the unstrained reference state: branches at rest). Clone it, or [`Self::copy_from`] without allocating, to
/// back up and restore a converged state when a step is cut.
#[derive(Debug, Clone, PartialEq)]
pub struct BranchHistory {
    num_points: usize,
    num_branches: usize,
    strains: Vec<SectionStrains>,
}

impl BranchHistory {
    /// All-zero branch strains for `num_points` points and `num_branches` branches.
    pub fn new(num_points: usize, num_branches: usize) -> Self {
        Self {
            num_points,
            num_branches,
            strains: vec![SectionStrains::default(); num_points * num_branches],
        }
    }

    /// Number of collocation points.
    pub fn num_points(&self) -> usize {
        self.num_points
    }

    /// Number of branches per point.
    pub fn num_branches(&self) -> usize {
        self.num_branches
    }

    /// The branches of point `i` (empty for an elastic material). Panics if `i ≥ num_points`.
    #[track_caller]
    pub fn point(&self, i: usize) -> &[SectionStrains] {
        assert!(i < self.num_points, "point {i} out of {}", self.num_points);
        &self.strains[i * self.num_branches..(i + 1) * self.num_branches]
    }

    /// The branches of point `i`, mutable. Panics if `i ≥ num_points`.
    #[track_caller]
    pub fn point_mut(&mut self, i: usize) -> &mut [SectionStrains] {
        assert!(i < self.num_points, "point {i} out of {}", self.num_points);
        &mut self.strains[i * self.num_branches..(i + 1) * self.num_branches]
    }

    /// All branch strains, point-major (for chunked or parallel traversal: chunks of `num_branches`).
    pub fn as_slice(&self) -> &[SectionStrains] {
        &self.strains
    }

    /// All branch strains, point-major, mutable.
    pub fn as_mut_slice(&mut self) -> &mut [SectionStrains] {
        &mut self.strains
    }

    /// Overwrites this history with `other` (same shape) without allocating: restore after a cut step.
    #[track_caller]
    pub fn copy_from(&mut self, other: &Self) {
        assert_eq!(
            (self.num_points, self.num_branches),
            (other.num_points, other.num_branches),
            "branch histories differ in shape"
        );
        self.strains.copy_from_slice(&other.strains);
    }
}

/// The history stresses `H = (H_N, H_M, H_N,s, H_M,s)` at one point for the step described by `coeffs`:
/// `H_N = S_N ⊙ Σ_α E_α (γ_α Γ_N^n + δ_α Γ_Nα^n)` and likewise (module docs), from the converged total
/// strains `strain_n` and branch strains `branches_n` of the previous step. For the trapezoidal rule this is the
/// paper's `Σ_α C_α τ_α^{n+1}/(2τ_α^{n+1}+h) Ψ_α^n` (Eqs. `N_constitutive_disc`, `M_constitutive_disc`).
/// Panics if the branch counts of `prony`, `coeffs` and `branches_n` differ.
#[track_caller]
pub fn history_stress(
    prony: &Prony,
    shape: &SectionShape,
    coeffs: &StepCoefficients,
    strain_n: &SectionStrains,
    branches_n: &[SectionStrains],
) -> SectionStress {
    let m = prony.num_branches();
    assert!(
        coeffs.num_branches() == m && branches_n.len() == m,
        "branch counts differ"
    );
    let mut weighted_old_strain = 0.0; // Σ E_α γ_α
    let mut acc = SectionStrains::default(); // Σ E_α δ_α ε_α^n
    for ((b, (&gamma, &delta)), branch) in prony
        .branches()
        .iter()
        .zip(coeffs.gamma.iter().zip(&coeffs.delta))
        .zip(branches_n)
    {
        weighted_old_strain += b.modulus * gamma;
        acc = acc.combine(1.0, branch, b.modulus * delta);
    }
    let acc = acc.combine(1.0, strain_n, weighted_old_strain);
    SectionStress {
        force: shape.force.component_mul(&acc.force),
        moment: shape.moment.component_mul(&acc.moment),
        force_ds: shape.force.component_mul(&acc.force_ds),
        moment_ds: shape.moment.component_mul(&acc.moment_ds),
    }
}

/// After convergence: advances the branch strains of one point in place,
/// `ε_α ← β_α ε^{n+1} + γ_α ε^n + δ_α ε_α` (all four vectors). Panics if the branch counts differ.
#[track_caller]
pub fn update_branch_strains(
    coeffs: &StepCoefficients,
    strain_np1: &SectionStrains,
    strain_n: &SectionStrains,
    branches: &mut [SectionStrains],
) {
    assert_eq!(
        coeffs.num_branches(),
        branches.len(),
        "branch counts differ"
    );
    for ((branch, &beta), (&gamma, &delta)) in branches
        .iter_mut()
        .zip(&coeffs.beta)
        .zip(coeffs.gamma.iter().zip(&coeffs.delta))
    {
        *branch = strain_np1
            .combine(beta, strain_n, gamma)
            .combine(1.0, branch, delta);
    }
}

/// Where the temperature varies along the rod (module docs of `super::maxwell`): the extra history of the
/// s-derivatives from the slopes `coeffs_ds = (β_α,s, γ_α,s, δ_α,s)` of the step coefficients,
/// `H_N,s += S_N ⊙ Σ_α E_α (γ_α,s Γ_N^n + δ_α,s Γ_Nα^n)` and likewise for `H_M,s`, added to `history`.
/// Panics if the branch counts differ.
#[track_caller]
pub fn add_history_slope(
    prony: &Prony,
    shape: &SectionShape,
    coeffs_ds: &StepCoefficients,
    strain_n: &SectionStrains,
    branches_n: &[SectionStrains],
    history: &mut SectionStress,
) {
    assert!(
        coeffs_ds.num_branches() == prony.num_branches()
            && branches_n.len() == coeffs_ds.num_branches(),
        "branch counts differ"
    );
    let (mut force, mut moment) = (Vec3::zeros(), Vec3::zeros());
    for ((b, (&gamma_s, &delta_s)), branch) in prony
        .branches()
        .iter()
        .zip(coeffs_ds.gamma.iter().zip(&coeffs_ds.delta))
        .zip(branches_n)
    {
        force += (strain_n.force * gamma_s + branch.force * delta_s) * b.modulus;
        moment += (strain_n.moment * gamma_s + branch.moment * delta_s) * b.modulus;
    }
    history.force_ds += shape.force.component_mul(&force);
    history.moment_ds += shape.moment.component_mul(&moment);
}

/// [`update_branch_strains`] where the temperature varies along the rod: the s-derivatives of the branch
/// strains also take the exact s-derivative of (★) through the coefficients,
/// `ε_α,s ← β_α ε,s^{n+1} + γ_α ε,s^n + δ_α ε_α,s + β_α,s ε^{n+1} + γ_α,s ε^n + δ_α,s ε_α`.
/// Panics if the branch counts differ.
#[track_caller]
pub fn update_branch_strains_with_slope(
    coeffs: &StepCoefficients,
    coeffs_ds: &StepCoefficients,
    strain_np1: &SectionStrains,
    strain_n: &SectionStrains,
    branches: &mut [SectionStrains],
) {
    assert_eq!(
        coeffs_ds.num_branches(),
        branches.len(),
        "branch counts differ"
    );
    assert_eq!(
        coeffs.num_branches(),
        branches.len(),
        "branch counts differ"
    );
    for (k, branch) in branches.iter_mut().enumerate() {
        let (beta_s, gamma_s, delta_s) =
            (coeffs_ds.beta[k], coeffs_ds.gamma[k], coeffs_ds.delta[k]);
        let force = strain_np1.force * beta_s + strain_n.force * gamma_s + branch.force * delta_s;
        let moment =
            strain_np1.moment * beta_s + strain_n.moment * gamma_s + branch.moment * delta_s;
        *branch = strain_np1
            .combine(coeffs.beta[k], strain_n, coeffs.gamma[k])
            .combine(1.0, branch, coeffs.delta[k]);
        branch.force_ds += force;
        branch.moment_ds += moment;
    }
}

#[cfg(test)]
mod tests {
    // Reference: the definition σ = E∞ ε + Σ E_α (ε − ε_α^{n+1}) (paper, the unnumbered equations before
    // N_constitutive_disc) evaluated directly after the branch update, versus the split form C̄ ε − H used
    // in Newton. Same algebra, different order of operations: agreement to 1e-13 relative to the largest
    // stress term (PLA moduli ~1e3 against strains ~1e-2, 16 terms).
    use super::*;
    use crate::material::{CircularSection, Integrator, Material, SectionLaw, step_coefficients};

    fn strains(seed: Real) -> SectionStrains {
        let v = |k: Real| {
            Vec3::new(
                (seed * k).sin(),
                (seed * k + 1.0).cos(),
                (seed * k * 0.7).sin(),
            ) * 1e-2
        };
        SectionStrains {
            force: v(1.0),
            moment: v(2.0),
            force_ds: v(3.0),
            moment_ds: v(4.0),
        }
    }

    #[test]
    fn split_form_equals_the_definition_after_update() {
        let material = Material::pla_van_manen_2021();
        let prony = material.prony();
        let shape = material.section_shape(&CircularSection::try_new(0.05).expect("valid").into());
        let m = prony.num_branches();
        let mut history = BranchHistory::new(3, m);
        for (k, s) in history.as_mut_slice().iter_mut().enumerate() {
            *s = strains(0.37 * k as Real + 0.1);
        }
        let temp = |t: Real| 65.0 + 20.0 * t;
        for integrator in [
            Integrator::Trapezoidal,
            Integrator::BackwardEuler,
            Integrator::Exponential,
        ] {
            let coeffs =
                step_coefficients(&material, integrator, 0.1, 0.3, &temp).expect("valid step");
            let e_bar = coeffs.effective_modulus(prony);
            for p in 0..history.num_points() {
                let strain_n = strains(10.0 + p as Real);
                let strain_np1 = strains(20.0 + p as Real);
                let mut branches = history.point(p).to_vec();
                let h = history_stress(prony, &shape, &coeffs, &strain_n, &branches);
                let split = SectionLaw::new(&shape, e_bar, h).stress(&strain_np1);
                update_branch_strains(&coeffs, &strain_np1, &strain_n, &mut branches);
                // Definition, per vector: S ⊙ (E∞ ε + Σ E_α (ε − ε_α)).
                let define = |s: &Vec3, eps: Vec3, pick: fn(&SectionStrains) -> Vec3| {
                    let mut sum = eps * prony.e_inf();
                    for (b, br) in prony.branches().iter().zip(&branches) {
                        sum += (eps - pick(br)) * b.modulus;
                    }
                    s.component_mul(&sum)
                };
                let direct = SectionStress {
                    force: define(&shape.force, strain_np1.force, |s| s.force),
                    moment: define(&shape.moment, strain_np1.moment, |s| s.moment),
                    force_ds: define(&shape.force, strain_np1.force_ds, |s| s.force_ds),
                    moment_ds: define(&shape.moment, strain_np1.moment_ds, |s| s.moment_ds),
                };
                let scale_n = shape.force.norm() * prony.instantaneous_modulus() * 1e-2;
                let scale_m = shape.moment.norm() * prony.instantaneous_modulus() * 1e-2;
                for (a, b, s) in [
                    (split.force, direct.force, scale_n),
                    (split.moment, direct.moment, scale_m),
                    (split.force_ds, direct.force_ds, scale_n),
                    (split.moment_ds, direct.moment_ds, scale_m),
                ] {
                    assert!(
                        (a - b).norm() < 1e-13 * s,
                        "{integrator:?} point {p}: {a:?} vs {b:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn history_layout_and_backup() {
        let mut h = BranchHistory::new(4, 3);
        assert_eq!(
            (h.num_points(), h.num_branches(), h.as_slice().len()),
            (4, 3, 12)
        );
        h.point_mut(2)[1].moment.x = 5.0;
        assert_eq!(h.as_slice()[2 * 3 + 1].moment.x, 5.0);
        let backup = h.clone();
        h.point_mut(2)[1].moment.x = -1.0;
        h.copy_from(&backup);
        assert_eq!(h, backup);
        // Elastic material: every point has an empty branch slice.
        let e = BranchHistory::new(5, 0);
        assert!(e.point(4).is_empty());
    }
}
