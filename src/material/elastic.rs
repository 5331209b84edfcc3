//! The plain linear-elastic material: a modulus and a Poisson ratio, no internal variables, no temperature
//! dependence.
//!
//! The section law is `N = C_N Γ_N`, `M = C_M K_M` (and the same for the s-derivatives) with `C_N = E S_N`,
//! `C_M = E S_M` (DESIGN §3, [`super::section`]): the generalized Maxwell law of paper Eqs.
//! `N_constitutive_disc`, `M_constitutive_disc` with no branches (`C̄ = C_∞`, `H = 0`). A design whose Prony
//! series has no branches and no WLF shift is this material ([`super::MaterialLaw::from_material`]), with the
//! same numbers: `E = E∞`.

use super::constitutive::{ConstitutiveLaw, PointStrains, StepInput, check_state_length};
use super::{MaterialError, MaterialNotice, SectionLaw, SectionShape};
use crate::math::Real;

/// A linear-elastic material (module docs).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ElasticLaw {
    /// Young's modulus `E` \[stress\].
    modulus: Real,
    /// Poisson's ratio `ν` \[-\].
    poisson: Real,
}

impl ElasticLaw {
    /// Validates `E > 0` (finite) and `−1 < ν < 0.5`.
    ///
    /// # Errors
    /// [`MaterialError::ElasticModulus`], [`MaterialError::PoissonRatio`].
    pub fn try_new(modulus: Real, poisson: Real) -> Result<Self, MaterialError> {
        if !(modulus.is_finite() && modulus > 0.0) {
            return Err(MaterialError::ElasticModulus { value: modulus });
        }
        if !(poisson > -1.0 && poisson < 0.5) {
            return Err(MaterialError::PoissonRatio { value: poisson });
        }
        Ok(Self { modulus, poisson })
    }

    /// Young's modulus `E` \[stress\].
    pub fn modulus(&self) -> Real {
        self.modulus
    }
}

/// The points of an elastic material: only their section shapes (there are no internal variables).
#[derive(Debug, Clone, PartialEq)]
pub struct ElasticState {
    shapes: Vec<SectionShape>,
}

impl ConstitutiveLaw for ElasticLaw {
    type State = ElasticState;

    fn poisson(&self) -> Real {
        self.poisson
    }

    fn reference_modulus(&self) -> Real {
        self.modulus
    }

    fn new_state(&self, shapes: Vec<SectionShape>) -> ElasticState {
        ElasticState { shapes }
    }

    /// Nothing to prepare: the law is the same in every step.
    fn prepare_step(
        &self,
        _: &mut ElasticState,
        _: &StepInput<'_>,
    ) -> Result<Option<MaterialNotice>, MaterialError> {
        Ok(None)
    }

    #[inline]
    fn section_law(&self, state: &ElasticState, point: usize) -> SectionLaw {
        SectionLaw::elastic(&state.shapes[point], self.modulus)
    }

    /// Nothing to advance (the strains are not even computed).
    fn commit_step(&self, _: &mut ElasticState, _: PointStrains<'_>) {}

    fn roll_back(&self, _: &mut ElasticState) {}

    /// Nothing to save.
    fn save_state(&self, _: &ElasticState, _: &mut Vec<Real>) {}

    fn restore_state(&self, _: &mut ElasticState, values: &[Real]) -> Result<(), MaterialError> {
        check_state_length(values, 0)
    }
}

#[cfg(test)]
mod tests {
    // Source: the elastic law is the Maxwell law without branches (module docs): same stresses, bit for bit, on
    // a strained point, and it validates its two numbers as `Material` does.
    use super::*;
    use crate::material::{
        CircularSection, Integrator, Material, MaxwellLaw, Prony, SectionStrains, StepInput,
    };
    use crate::math::Vec3;

    #[test]
    fn elastic_equals_maxwell_without_branches() {
        let section = CircularSection::try_new(0.05).expect("valid").into();
        let elastic = ElasticLaw::try_new(80.59e6, 0.33).expect("valid");
        let material =
            Material::try_new(Prony::try_new(80.59e6, vec![]).expect("valid"), 0.33, None)
                .expect("valid");
        let maxwell = MaxwellLaw::new(material, Integrator::Trapezoidal);
        let shapes = vec![elastic.section_shape(&section); 2];
        assert_eq!(shapes[0], maxwell.section_shape(&section));
        let mut e_state = elastic.new_state(shapes.clone());
        let mut m_state = maxwell.new_state(shapes);
        let strain = SectionStrains {
            force: Vec3::new(1e-3, -2e-4, 3e-4),
            moment: Vec3::new(0.1, 0.2, -0.3),
            force_ds: Vec3::new(1e-2, 0.0, -1e-2),
            moment_ds: Vec3::new(-1.0, 2.0, 0.5),
        };
        let temperature = |_: Real| 20.0;
        for step in 0..3 {
            let input = StepInput {
                t_n: step as Real,
                t_np1: step as Real + 1.0,
                temperature: &temperature,
                field: None,
            };
            assert_eq!(elastic.prepare_step(&mut e_state, &input), Ok(None));
            assert_eq!(maxwell.prepare_step(&mut m_state, &input), Ok(None));
            for p in 0..2 {
                let a = elastic.section_law(&e_state, p).stress(&strain);
                let b = maxwell.section_law(&m_state, p).stress(&strain);
                assert_eq!(a, b);
            }
            elastic.commit_step(&mut e_state, &|_| strain);
            maxwell.commit_step(&mut m_state, &|_| strain);
        }
        assert_eq!(elastic.reference_modulus(), maxwell.reference_modulus());
        let mut saved = Vec::new();
        elastic.save_state(&e_state, &mut saved);
        assert!(saved.is_empty());
        assert!(elastic.restore_state(&mut e_state, &[1.0]).is_err());
        for bad in [0.0, -1.0, Real::NAN, Real::INFINITY] {
            assert!(matches!(
                ElasticLaw::try_new(bad, 0.3),
                Err(MaterialError::ElasticModulus { .. })
            ));
        }
        assert!(matches!(
            ElasticLaw::try_new(1.0, 0.5),
            Err(MaterialError::PoissonRatio { .. })
        ));
    }
}
