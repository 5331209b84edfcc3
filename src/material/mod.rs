//! Material: the generalized Maxwell (Prony) solid, the WLF shift of relaxation times, cross-section
//! stiffnesses and the internal-variable updates.
//!
//! PLACEHOLDER until the material branch lands (types only).

use crate::math::Real;

/// A Maxwell branch.
#[derive(Debug, Clone, PartialEq)]
pub struct PronyBranch {
    /// Modulus E_α [stress].
    pub modulus: Real,
    /// Relaxation time at Tg [time].
    pub tau_g: Real,
}

/// Prony series.
#[derive(Debug, Clone, PartialEq)]
pub struct Prony {
    /// Equilibrium modulus [stress].
    pub e_inf: Real,
    /// Branches.
    pub branches: Vec<PronyBranch>,
}

/// WLF.
#[derive(Debug, Clone, PartialEq)]
pub struct Wlf {
    /// C1.
    pub c1: Real,
    /// C2 [K].
    pub c2: Real,
    /// Tg [°C].
    pub tg: Real,
}

/// Material.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Prony.
    pub prony: Prony,
    /// Poisson.
    pub poisson: Real,
    /// WLF.
    pub wlf: Option<Wlf>,
}

/// Integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Integrator {
    /// Trapezoidal.
    #[default]
    Trapezoidal,
    /// BE.
    BackwardEuler,
    /// Exp.
    Exponential,
}

/// Section.
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    /// Diameter.
    pub diameter: Real,
    /// Shear factor.
    pub shear_factor: Real,
}
