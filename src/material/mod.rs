//! Material: the constitutive interface the solver calls ([`ConstitutiveLaw`], `constitutive`), its laws —
//! the generalized Maxwell (Prony) solid with the WLF shift of relaxation times ([`MaxwellLaw`]) and the plain
//! elastic material ([`ElasticLaw`]) —, cross-section stiffnesses and the internal-variable updates.
//!
//! # Laws
//!
//! The laws are registered in one list, the `register_laws!` invocation below, which makes [`MaterialLaw`] (the
//! material of a model's patch) and [`MaterialState`] (its internal variables). **A new law is a new module
//! plus one registration line**: write `material/<law>.rs` implementing [`ConstitutiveLaw`], declare it here
//! (`pub mod <law>;`) and add `Name(<law>::Type),` to the list (see `constitutive` for the interface and why
//! it is an enum).
//!
//! # Model (paper §2.2, §3.1)
//!
//! A generalized Maxwell solid: an equilibrium spring `E∞` in parallel with `m` Maxwell branches
//! `(E_α, τ_G,α)`, every branch sharing one Poisson ratio `ν` ([`Prony`], [`Material`]). Each branch carries a
//! viscous strain `ε_α` (the paper's `Γ_Nα` and `K_Mα`) that relaxes towards the total strain `ε`
//! (`Γ_N` or `K_M`) at the temperature-dependent rate `λ_α(T) = 1/τ_α(T)` (Eq. `evol_f_m_thermal`):
//!
//! ```text
//! ε̇_α = λ_α(T(t)) (ε − ε_α),        λ_α(T) = rate_factor(T) / τ_G,α,
//! ```
//!
//! with the time–temperature shift of Williams, Landel and Ferry ([`Wlf`], Eq. `at`). The stress of one strain
//! component is `σ = E∞ ε + Σ_α E_α (ε − ε_α)`; in the rod the moduli become the diagonal section stiffnesses
//! `C_Nα = E_α S_N`, `C_Mα = E_α S_M` ([`SectionShape`]).
//!
//! # Time stepping
//!
//! Every [`Integrator`] advances a branch by an update affine in the new total strain
//! (see `integrator` for the three formulas, and the correspondence with the paper's Eqs.
//! `evol_f_thermal_disc`, `N_constitutive_disc`, `M_constitutive_disc`):
//!
//! ```text
//! ε_α^{n+1} = β_α ε^{n+1} + γ_α ε^n + δ_α ε_α^n,
//! ```
//!
//! so that within a time step the section law is linear in the unknown strain:
//! `N^{n+1} = C̄ Γ_N^{n+1} − H_N` with `C̄ = S_N ⊙ Ē`, `Ē = E∞ + Σ_α E_α (1 − β_α)`
//! ([`StepCoefficients::effective_modulus`]) and a history force `H_N` fixed during Newton
//! ([`history_stress`]); [`SectionLaw`] evaluates this law at one point and is what the solver calls. After
//! convergence the branch strains are advanced in place ([`update_branch_strains`]); they live in a
//! [`BranchHistory`].
//!
//! # Units
//!
//! Any consistent system: moduli `[stress]`, times `[time]`, lengths `[length]`, temperatures in °C
//! (temperature differences, such as `C2`, in K).
//!
//! # Errors
//!
//! Constructors validate their data (`try_new`) and report the offending value in a [`MaterialError`];
//! time stepping reports non-finite inputs (a temperature schedule returning NaN) rather than propagating NaN.

pub(crate) mod constitutive;
pub(crate) mod elastic;
pub(crate) mod history;
pub(crate) mod integrator;
pub(crate) mod law;
pub(crate) mod maxwell;
pub(crate) mod point;
pub(crate) mod prony;
pub(crate) mod section;
pub(crate) mod wlf;

pub use constitutive::{
    ConstitutiveLaw, MaterialNotice, PointStrains, PointTemperature, StepInput,
};
pub use elastic::{ElasticLaw, ElasticState};
pub use history::{
    BranchHistory, SectionStrains, SectionStress, add_history_slope, history_stress,
    update_branch_strains, update_branch_strains_with_slope,
};
pub use integrator::{
    Integrator, MAX_STEP_RATE, ReducedTimeQuadrature, StepCoefficients,
    exponential_coefficient_slopes, exponential_coefficients, reduced_time_increment,
    step_coefficients, step_coefficients_into, step_coefficients_with_slope_into,
};
pub use law::{LAW_NUMBERS, SectionLaw};
pub use maxwell::{MaxwellLaw, MaxwellState};
pub use point::{simulate_strain_history, simulate_stress_history};
pub use prony::{Prony, PronyBranch};
pub use section::{CircularSection, Section, SectionProperties, SectionShape, ShearFactor};
pub use wlf::Wlf;

use crate::math::{Real, Short};

// The registry of constitutive laws: one line per law (module docs).
constitutive::register_laws! {
    /// Linear elastic: a modulus and a Poisson ratio, no internal variables (`elastic`).
    Elastic(elastic::ElasticLaw),
    /// Generalized Maxwell solid with WLF shift and a time integrator (paper §2.2, §3.1; `maxwell`).
    Maxwell(maxwell::MaxwellLaw),
}

impl MaterialLaw {
    /// The simplest law that represents `material` advanced by `integrator`: [`ElasticLaw`] with `E = E∞` when
    /// the Prony series has no branches and there is no WLF shift (no internal variables, no temperature
    /// dependence: the same numbers as the Maxwell law would give, with nothing to store or prepare), otherwise
    /// [`MaxwellLaw`].
    pub fn from_material(material: Material, integrator: Integrator) -> Self {
        if material.num_branches() == 0 && material.wlf().is_none() {
            // `Material` validated both: E0 = E∞ finite and > 0 without branches, −1 < ν < 0.5.
            if let Ok(elastic) = ElasticLaw::try_new(material.prony().e_inf(), material.poisson()) {
                return elastic.into();
            }
        }
        MaxwellLaw::new(material, integrator).into()
    }
}

/// Errors raised by the material layer when data (not the programmer) is wrong. Branch indices are 1-based,
/// as `α` in the paper's Table `PLA`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MaterialError {
    /// The equilibrium modulus `E∞` is negative or not finite.
    #[error("equilibrium modulus E∞ = {value} must be finite and ≥ 0")]
    EquilibriumModulus {
        /// The rejected `E∞` \[stress\].
        value: Real,
    },
    /// A branch modulus `E_α` is not positive or not finite.
    #[error("Prony branch {branch}: modulus E = {value} must be finite and > 0")]
    BranchModulus {
        /// 1-based branch index `α`.
        branch: usize,
        /// The rejected modulus \[stress\].
        value: Real,
    },
    /// A branch relaxation time `τ_G,α` is not positive or not finite.
    #[error("Prony branch {branch}: relaxation time τ_G = {value} must be finite and > 0")]
    BranchRelaxationTime {
        /// 1-based branch index `α`.
        branch: usize,
        /// The rejected relaxation time \[time\].
        value: Real,
    },
    /// The instantaneous modulus `E0 = E∞ + Σ E_α` is not positive (only possible with no branches and
    /// `E∞ = 0`) or overflows.
    #[error("instantaneous modulus E0 = {value} must be finite and > 0")]
    InstantaneousModulus {
        /// The rejected `E0` \[stress\].
        value: Real,
    },
    /// Poisson's ratio outside `(−1, 0.5)`.
    #[error("Poisson ratio ν = {value} must lie in (−1, 0.5)")]
    PoissonRatio {
        /// The rejected ratio \[-\].
        value: Real,
    },
    /// The WLF constant `C1` is outside `(0, 300]` or not finite.
    #[error("WLF constant C1 = {value} must lie in (0, {max}]", max = wlf::MAX_C1)]
    WlfC1 {
        /// The rejected `C1` \[-\].
        value: Real,
    },
    /// The WLF constant `C2` is not positive, not finite or subnormal.
    #[error("WLF constant C2 = {value} K must be a finite, normal number > 0")]
    WlfC2 {
        /// The rejected `C2` \[K\].
        value: Real,
    },
    /// The glass-transition temperature is not finite.
    #[error("glass-transition temperature Tg = {value} °C must be finite")]
    GlassTransition {
        /// The rejected `Tg` \[°C\].
        value: Real,
    },
    /// The section diameter is not positive or not finite.
    #[error("section diameter d = {value} must be finite and > 0")]
    Diameter {
        /// The rejected diameter \[length\].
        value: Real,
    },
    /// A given shear factor is not positive or not finite.
    #[error("shear factor k_s = {value} must be finite and > 0")]
    ShearFactor {
        /// The rejected factor \[-\].
        value: Real,
    },
    /// A time step runs backwards or has non-finite ends.
    #[error(
        "invalid time step from t = {t_n} to t = {t_np1}: times must be finite and non-decreasing"
    )]
    TimeStep {
        /// Start of the step \[time\].
        t_n: Real,
        /// End of the step \[time\].
        t_np1: Real,
    },
    /// A prescribed history (temperature, strain or stress) returned a non-finite value.
    #[error("{quantity} at t = {} is {value}, not a finite number", Short(*time))]
    NonFiniteInput {
        /// Which history: `"temperature"`, `"temperature gradient"`, `"strain"` or `"stress"`.
        quantity: &'static str,
        /// Where it was evaluated \[time\].
        time: Real,
        /// What it returned.
        value: Real,
    },
    /// An elastic modulus is not positive or not finite.
    #[error("elastic modulus E = {value} must be finite and > 0")]
    ElasticModulus {
        /// The rejected modulus \[stress\].
        value: Real,
    },
    /// A saved material state has another length than the state it is restored into (a checkpoint of another
    /// model or material).
    #[error("a saved material state of {found} numbers cannot be restored into one of {expected}")]
    StateLength {
        /// Numbers the state saves.
        expected: usize,
        /// Numbers given.
        found: usize,
    },
    /// Error-controlled stepping was asked of a Maxwell material whose update has no trustworthy time-error
    /// estimate ([`Integrator::companion`]).
    #[error("no time-error estimate for the `{integrator}` update: {why}")]
    NoTimeErrorEstimate {
        /// The update's design name.
        integrator: &'static str,
        /// Why.
        why: &'static str,
    },
    /// Stress control is impossible: the step's effective modulus vanished (a Maxwell fluid, `E∞ = 0`, whose
    /// branches all relax completely within one step cannot carry a prescribed stress).
    #[error("effective modulus {modulus} at t = {} leaves the stress-controlled step singular", Short(*time))]
    SingularCompliance {
        /// End of the step \[time\].
        time: Real,
        /// The step's effective modulus `Ē` \[stress\].
        modulus: Real,
    },
}

/// A validated thermo-viscoelastic material: a Prony series, the Poisson ratio shared by all branches and an
/// optional WLF shift (none: temperature-independent relaxation times).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Material {
    prony: Prony,
    poisson: Real,
    wlf: Option<Wlf>,
}

impl Material {
    /// Validates the Poisson ratio `−1 < ν < 0.5` (finite); `prony` and `wlf` are validated by their own
    /// constructors.
    pub fn try_new(prony: Prony, poisson: Real, wlf: Option<Wlf>) -> Result<Self, MaterialError> {
        if !(poisson > -1.0 && poisson < 0.5) {
            return Err(MaterialError::PoissonRatio { value: poisson });
        }
        Ok(Self {
            prony,
            poisson,
            wlf,
        })
    }

    /// The PLA of the paper's circular-arch and stent examples: Table `PLA` (15 branches, van Manen et al.
    /// 2021), `ν = 0.33`, and the first row of Table `aT_PLA` (van Manen: `C1 = 14.59`, `C2 = 48.43 K`,
    /// `Tg = 70 °C`). Units: MPa and s.
    pub fn pla_van_manen_2021() -> Self {
        Self {
            prony: Prony::pla_van_manen_2021(),
            poisson: 0.33,
            wlf: Some(Wlf::van_manen_2021()),
        }
    }

    /// The Prony series.
    pub fn prony(&self) -> &Prony {
        &self.prony
    }

    /// Poisson's ratio `ν` \[-\], shared by the equilibrium spring and every branch.
    pub fn poisson(&self) -> Real {
        self.poisson
    }

    /// The WLF shift, if the relaxation times depend on temperature.
    pub fn wlf(&self) -> Option<&Wlf> {
        self.wlf.as_ref()
    }

    /// Number of Maxwell branches `m`.
    pub fn num_branches(&self) -> usize {
        self.prony.branches().len()
    }

    /// The factor `1/a_T` multiplying every branch's relaxation rate at temperature `T` \[°C\]:
    /// `λ_α(T) = rate_factor(T) / τ_G,α` ([`Wlf::rate_factor`]); `1` without WLF, `0` where relaxation is
    /// frozen.
    pub fn rate_factor(&self, temperature: Real) -> Real {
        self.wlf
            .as_ref()
            .map_or(1.0, |w| w.rate_factor(temperature))
    }

    /// Whether relaxation is frozen at temperature `T` \[°C\] (at or below `Tg − C2`; never without WLF), so a
    /// caller can warn once.
    pub fn is_frozen(&self, temperature: Real) -> bool {
        self.wlf.as_ref().is_some_and(|w| w.is_frozen(temperature))
    }

    /// The stiffness shapes of a section made of this material ([`SectionShape::new`] with this
    /// material's `ν`).
    pub fn section_shape(&self, section: &Section) -> SectionShape {
        SectionShape::new(section, self.poisson)
    }
}

#[cfg(test)]
mod tests {
    // Validation of the material record: the admissible Poisson range (−1, 0.5) is the one of isotropic
    // linear elasticity (positive-definite bulk and shear moduli); exact comparisons, no tolerance involved.
    use super::*;

    #[test]
    fn poisson_ratio_is_validated() {
        let prony = Prony::try_new(1.0, vec![]).expect("elastic Prony series is valid");
        for bad in [-1.0, 0.5, 0.7, Real::NAN, Real::INFINITY] {
            let err = Material::try_new(prony.clone(), bad, None).expect_err("ν outside (−1, 0.5)");
            assert!(matches!(err, MaterialError::PoissonRatio { .. }), "{err}");
        }
        let m = Material::try_new(prony, 0.3, None).expect("ν = 0.3 is valid");
        assert_eq!(m.rate_factor(-1000.0), 1.0);
        assert!(!m.is_frozen(-1000.0));
        assert_eq!(m.num_branches(), 0);
    }

    #[test]
    fn pla_preset_validates() {
        let m = Material::pla_van_manen_2021();
        let p = m.prony();
        let branches: Vec<_> = p.branches().iter().map(|b| (b.modulus, b.tau_g)).collect();
        let rebuilt =
            Prony::try_new(p.e_inf(), p.branches().to_vec()).expect("table PLA validates");
        assert_eq!(&rebuilt, p);
        assert_eq!(branches.len(), 15);
        let w = m.wlf().expect("PLA preset has WLF");
        let again = Wlf::try_new(w.c1(), w.c2(), w.tg()).expect("table aT_PLA validates");
        assert_eq!(&again, w);
        assert!(Material::try_new(p.clone(), m.poisson(), Some(again)).is_ok());
    }
}
