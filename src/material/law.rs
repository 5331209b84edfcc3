//! The section constitutive law of one time step at one point — the one place the solver gets stresses and
//! stiffnesses from.
//!
//! Within a step every [`super::Integrator`] makes the Maxwell/Prony section law affine in the new strains
//! (paper Eqs. `N_constitutive_disc`, `M_constitutive_disc`, generalised in [`super::history`]):
//!
//! ```text
//! N = C̄_N Γ_N − H_N,    M = C̄_M K_M − H_M,    N,s = C̄_N Γ_N,s − H_N,s,    M,s = C̄_M K_M,s − H_M,s,
//! C̄_N = diag(S_N ⊙ Ē),  C̄_M = diag(S_M ⊙ Ē),
//! ```
//!
//! with the step's effective modulus `Ē` ([`super::StepCoefficients::effective_modulus`]), the section shapes
//! `S` ([`SectionShape`]) and the history stresses `H` ([`super::history_stress`]), both fixed during Newton.
//! Where the temperature varies along the rod, `Ē` does too, and the derivatives of the stresses gain the term
//! of its slope `C̄,s = S ⊙ Ē,s` (module docs of [`super::maxwell`]):
//!
//! ```text
//! N,s = C̄_N Γ_N,s + C̄_N,s Γ_N − H_N,s,     M,s = C̄_M K_M,s + C̄_M,s K_M − H_M,s,
//! ```
//!
//! with `∂N,s/∂Γ_N = C̄_N,s`, `∂M,s/∂K_M = C̄_M,s` in the tangent ([`SectionLaw::stiffness_slope_matrices`]).
//! [`SectionLaw`] holds `C̄` and `H` of one point for one step; [`SectionLaw::stress`] evaluates the law and
//! [`SectionLaw::stiffness_matrices`] gives its (constant) derivative `∂N/∂Γ_N = C̄_N`, `∂M/∂K_M = C̄_M`.
//! It is `Copy`, allocates nothing and inlines: the solver builds one per collocation point per iteration.

use super::{SectionShape, SectionStrains, SectionStress};
use crate::math::{Mat3, Real, Vec3};

/// Numbers of a [`SectionLaw`] ([`SectionLaw::to_numbers`]).
pub const LAW_NUMBERS: usize = 24;

/// The section law `N = C̄_N Γ_N − H_N`, `M = C̄_M K_M − H_M` (and the same for the s-derivatives) of one
/// point during one time step (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SectionLaw {
    /// Diagonal of `C̄_N = diag(S_N ⊙ Ē)` \[force\].
    force_stiffness: Vec3,
    /// Diagonal of `C̄_M = diag(S_M ⊙ Ē)` \[force·length²\].
    moment_stiffness: Vec3,
    /// Diagonal of `C̄_N,s` \[force/length\] (zero unless the temperature varies along the rod).
    force_stiffness_ds: Vec3,
    /// Diagonal of `C̄_M,s` \[force·length\].
    moment_stiffness_ds: Vec3,
    /// History stresses `H = (H_N, H_M, H_N,s, H_M,s)` (zero for an elastic material or the first step).
    history: SectionStress,
}

impl SectionLaw {
    /// The law for a section of shape `shape`, the step's effective modulus `Ē` \[stress\] and the point's
    /// history stresses `history` ([`super::history_stress`]).
    #[inline]
    pub fn new(shape: &SectionShape, effective_modulus: Real, history: SectionStress) -> Self {
        Self {
            force_stiffness: shape.force_stiffness(effective_modulus),
            moment_stiffness: shape.moment_stiffness(effective_modulus),
            force_stiffness_ds: Vec3::zeros(),
            moment_stiffness_ds: Vec3::zeros(),
            history,
        }
    }

    /// The law at a point where the effective modulus varies along the rod: `Ē` \[stress\] and its slope
    /// `Ē,s` \[stress/length\] (module docs).
    #[inline]
    pub fn with_slope(
        shape: &SectionShape,
        effective_modulus: Real,
        modulus_slope: Real,
        history: SectionStress,
    ) -> Self {
        Self {
            force_stiffness_ds: shape.force_stiffness(modulus_slope),
            moment_stiffness_ds: shape.moment_stiffness(modulus_slope),
            ..Self::new(shape, effective_modulus, history)
        }
    }

    /// The elastic law (no history stresses) with modulus `E` \[stress\].
    #[inline]
    pub fn elastic(shape: &SectionShape, modulus: Real) -> Self {
        Self::new(shape, modulus, SectionStress::default())
    }

    /// The section stresses `N`, `M`, `N,s`, `M,s` at the strains `strain` (`Γ_N`, `K_M` and their
    /// s-derivatives).
    #[inline]
    pub fn stress(&self, strain: &SectionStrains) -> SectionStress {
        let (c_n, c_m, h) = (&self.force_stiffness, &self.moment_stiffness, &self.history);
        SectionStress {
            force: c_n.component_mul(&strain.force) - h.force,
            moment: c_m.component_mul(&strain.moment) - h.moment,
            force_ds: c_n.component_mul(&strain.force_ds)
                + self.force_stiffness_ds.component_mul(&strain.force)
                - h.force_ds,
            moment_ds: c_m.component_mul(&strain.moment_ds)
                + self.moment_stiffness_ds.component_mul(&strain.moment)
                - h.moment_ds,
        }
    }

    /// The law as 24 plain numbers (for checkpoints): the diagonals of `C̄_N` and `C̄_M`, then `H_N`, `H_M`,
    /// `H_N,s`, `H_M,s`, then the diagonals of `C̄_N,s` and `C̄_M,s`. [`SectionLaw::from_numbers`] inverts it exactly.
    pub fn to_numbers(&self) -> [Real; LAW_NUMBERS] {
        let h = &self.history;
        let mut out = [0.0; LAW_NUMBERS];
        for (k, v) in [
            &self.force_stiffness,
            &self.moment_stiffness,
            &h.force,
            &h.moment,
            &h.force_ds,
            &h.moment_ds,
            &self.force_stiffness_ds,
            &self.moment_stiffness_ds,
        ]
        .into_iter()
        .enumerate()
        {
            out[3 * k..3 * k + 3].copy_from_slice(v.as_slice());
        }
        out
    }

    /// The law of numbers written by [`SectionLaw::to_numbers`].
    pub fn from_numbers(numbers: &[Real; LAW_NUMBERS]) -> Self {
        let v = |k: usize| Vec3::new(numbers[3 * k], numbers[3 * k + 1], numbers[3 * k + 2]);
        Self {
            force_stiffness: v(0),
            moment_stiffness: v(1),
            force_stiffness_ds: v(6),
            moment_stiffness_ds: v(7),
            history: SectionStress {
                force: v(2),
                moment: v(3),
                force_ds: v(4),
                moment_ds: v(5),
            },
        }
    }

    /// The diagonals of `C̄_N` \[force\] and `C̄_M` \[force·length²\].
    #[inline]
    pub fn stiffness(&self) -> (Vec3, Vec3) {
        (self.force_stiffness, self.moment_stiffness)
    }

    /// `C̄_N,s = ∂N,s/∂Γ_N` \[force/length\] and `C̄_M,s = ∂M,s/∂K_M` \[force·length\] as (diagonal) matrices, or
    /// `None` when the modulus does not vary along the rod (the common case: nothing to add to the tangent).
    #[inline]
    pub fn stiffness_slope_matrices(&self) -> Option<(Mat3, Mat3)> {
        (self.force_stiffness_ds != Vec3::zeros() || self.moment_stiffness_ds != Vec3::zeros())
            .then(|| {
                (
                    Mat3::from_diagonal(&self.force_stiffness_ds),
                    Mat3::from_diagonal(&self.moment_stiffness_ds),
                )
            })
    }

    /// `C̄_N = ∂N/∂Γ_N` \[force\] and `C̄_M = ∂M/∂K_M` \[force·length²\] as (diagonal) matrices, for the tangent.
    #[inline]
    pub fn stiffness_matrices(&self) -> (Mat3, Mat3) {
        (
            Mat3::from_diagonal(&self.force_stiffness),
            Mat3::from_diagonal(&self.moment_stiffness),
        )
    }
}

#[cfg(test)]
mod tests {
    // Source: the law is affine in the strain with slope C̄ (module docs), so a central difference of `stress`
    // in any strain direction equals C̄ times that direction up to round-off. Stresses and history are of the
    // size C̄·1e-2, so the difference quotient (step 1e-6) carries a round-off of about 1e-16·1e-2/1e-6 = 1e-12
    // relative to the slope; the tolerance 1e-9 is far above that and far below any wrong stiffness.
    use super::*;
    use crate::material::{CircularSection, Material};

    #[test]
    fn stress_is_affine_with_slope_the_stiffness() {
        let material = Material::pla_van_manen_2021();
        let shape = material.section_shape(&CircularSection::try_new(0.05).expect("valid").into());
        let modulus = material.prony().instantaneous_modulus();
        let v = |k: Real| Vec3::new(k.sin(), (k + 1.0).cos(), (0.7 * k).sin());
        let (c_n, c_m) = (shape.force * modulus, shape.moment * modulus);
        let history = SectionStress {
            force: c_n.component_mul(&v(1.0)) * 1e-2,
            moment: c_m.component_mul(&v(2.0)) * 1e-2,
            force_ds: c_n.component_mul(&v(3.0)) * 1e-2,
            moment_ds: c_m.component_mul(&v(4.0)) * 1e-2,
        };
        let law = SectionLaw::new(&shape, modulus, history);
        let strain = SectionStrains {
            force: v(5.0) * 1e-2,
            moment: v(6.0) * 1e-2,
            force_ds: v(7.0) * 1e-2,
            moment_ds: v(8.0) * 1e-2,
        };
        // At zero strain the stress is −H.
        assert_eq!(law.stress(&SectionStrains::default()).force, -history.force);
        assert_eq!(law.stiffness(), (c_n, c_m));
        let (c_n, c_m) = law.stiffness_matrices();
        let eps = 1e-6;
        let d = v(9.0);
        let shifted = |sign: Real| {
            let mut s = strain;
            s.force += d * (sign * eps);
            s.moment += d * (sign * eps);
            law.stress(&s)
        };
        let (plus, minus) = (shifted(1.0), shifted(-1.0));
        let fd_n = (plus.force - minus.force) / (2.0 * eps);
        let fd_m = (plus.moment - minus.moment) / (2.0 * eps);
        let scale_n = (c_n * d).norm();
        let scale_m = (c_m * d).norm();
        assert!((fd_n - c_n * d).norm() < 1e-9 * scale_n, "{fd_n:?}");
        assert!((fd_m - c_m * d).norm() < 1e-9 * scale_m, "{fd_m:?}");
    }
}
