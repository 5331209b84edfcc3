//! Prony series of the generalized Maxwell solid: `E(t) = E∞ + Σ_α E_α exp(−t/τ_α)` at constant temperature.

use super::MaterialError;
use crate::math::Real;

/// One Maxwell branch: a spring `E_α` in series with a dashpot of relaxation time `τ_G,α` at the glass
/// transition temperature. A plain record; it is validated as part of a [`Prony`] series, which knows its
/// index.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PronyBranch {
    /// Branch modulus `E_α` \[stress\], `> 0`.
    pub modulus: Real,
    /// Relaxation time `τ_G,α` at `Tg` \[time\], `> 0` (at other temperatures see [`super::Wlf`]).
    pub tau_g: Real,
}

/// A validated Prony series: equilibrium modulus `E∞ ≥ 0` and `m ≥ 0` branches (`m = 0`: linear elastic).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Prony {
    e_inf: Real,
    branches: Vec<PronyBranch>,
    e_0: Real,
}

impl Prony {
    /// Validates `E∞` (finite, `≥ 0`), each branch (`E_α`, `τ_G,α` finite and `> 0`; errors name the 1-based
    /// branch index `α`) and the instantaneous modulus `E0 = E∞ + Σ E_α` (finite, `> 0`).
    pub fn try_new(e_inf: Real, branches: Vec<PronyBranch>) -> Result<Self, MaterialError> {
        if !(e_inf.is_finite() && e_inf >= 0.0) {
            return Err(MaterialError::EquilibriumModulus { value: e_inf });
        }
        for (i, b) in branches.iter().enumerate() {
            if !(b.modulus.is_finite() && b.modulus > 0.0) {
                return Err(MaterialError::BranchModulus {
                    branch: i + 1,
                    value: b.modulus,
                });
            }
            if !(b.tau_g.is_finite() && b.tau_g > 0.0) {
                return Err(MaterialError::BranchRelaxationTime {
                    branch: i + 1,
                    value: b.tau_g,
                });
            }
        }
        let e_0 = e_inf + branches.iter().map(|b| b.modulus).sum::<Real>();
        if !(e_0.is_finite() && e_0 > 0.0) {
            return Err(MaterialError::InstantaneousModulus { value: e_0 });
        }
        Ok(Self {
            e_inf,
            branches,
            e_0,
        })
    }

    /// PLA with 15 Maxwell elements, paper Table `PLA` (van Manen et al. 2021), in MPa and s:
    /// `E∞ = 80.59 MPa`, `τ_G` from `1e-10 s` to `1e5 s` (note the table jumps from `1e3` to `1e5`).
    pub fn pla_van_manen_2021() -> Self {
        const TABLE: [(Real, Real); 15] = [
            (20.12, 1e-10),
            (50.31, 1e-9),
            (81.37, 1e-8),
            (97.02, 1e-7),
            (173.70, 1e-6),
            (225.60, 1e-5),
            (292.64, 1e-4),
            (474.56, 1e-3),
            (449.43, 1e-2),
            (237.98, 1e-1),
            (114.16, 1e0),
            (51.82, 1e1),
            (29.98, 1e2),
            (14.40, 1e3),
            (0.72, 1e5),
        ];
        let branches: Vec<PronyBranch> = TABLE
            .iter()
            .map(|&(modulus, tau_g)| PronyBranch { modulus, tau_g })
            .collect();
        let e_inf = 80.59;
        let e_0 = e_inf + branches.iter().map(|b| b.modulus).sum::<Real>();
        Self {
            e_inf,
            branches,
            e_0,
        }
    }

    /// Equilibrium (fully relaxed) modulus `E∞` \[stress\].
    pub fn e_inf(&self) -> Real {
        self.e_inf
    }

    /// The Maxwell branches, in the order given (index `α − 1`).
    pub fn branches(&self) -> &[PronyBranch] {
        &self.branches
    }

    /// Number of branches `m`.
    pub fn num_branches(&self) -> usize {
        self.branches.len()
    }

    /// Instantaneous (glassy) modulus `E0 = E∞ + Σ_α E_α` \[stress\] (paper: `C_N0 = C_N∞ + Σ C_Nα`).
    pub fn instantaneous_modulus(&self) -> Real {
        self.e_0
    }

    /// Relaxation modulus `E(t) = E∞ + Σ_α E_α exp(−t · rate_factor / τ_G,α)` \[stress\] at a constant
    /// temperature whose rate factor `1/a_T` is given ([`super::Material::rate_factor`]); the stress response
    /// to a unit strain step applied at `t = 0`. `t ≥ 0` \[time\].
    pub fn relaxation_modulus(&self, t: Real, rate_factor: Real) -> Real {
        // Frozen (rate factor 0): no relaxation at any time, also for t = ∞ (0 · ∞ would be NaN).
        let reduced_time = if rate_factor == 0.0 {
            0.0
        } else {
            t * rate_factor
        };
        self.e_inf
            + self
                .branches
                .iter()
                .map(|b| b.modulus * (-(reduced_time / b.tau_g)).exp())
                .sum::<Real>()
    }
}

#[cfg(test)]
mod tests {
    // Validation of Prony data: exact comparisons of accepted/rejected inputs, no tolerances. The instantaneous
    // modulus of Table PLA is checked against a hand sum (python/mpmath: 80.59 + 2313.81 = 2394.40 MPa),
    // to 1e-12 relative because the sum of 16 two-decimal numbers carries a few ulps of rounding.
    use super::*;

    #[test]
    fn rejects_bad_branches_naming_them() {
        let good = PronyBranch {
            modulus: 1.0,
            tau_g: 1.0,
        };
        let cases = [
            (
                PronyBranch {
                    modulus: 0.0,
                    tau_g: 1.0,
                },
                "modulus",
            ),
            (
                PronyBranch {
                    modulus: -2.0,
                    tau_g: 1.0,
                },
                "modulus",
            ),
            (
                PronyBranch {
                    modulus: Real::NAN,
                    tau_g: 1.0,
                },
                "modulus",
            ),
            (
                PronyBranch {
                    modulus: 1.0,
                    tau_g: 0.0,
                },
                "time",
            ),
            (
                PronyBranch {
                    modulus: 1.0,
                    tau_g: Real::INFINITY,
                },
                "time",
            ),
        ];
        for (bad, what) in cases {
            let err = Prony::try_new(1.0, vec![good, bad]).expect_err("invalid branch");
            match (what, err) {
                ("modulus", MaterialError::BranchModulus { branch, .. }) => assert_eq!(branch, 2),
                ("time", MaterialError::BranchRelaxationTime { branch, .. }) => {
                    assert_eq!(branch, 2)
                }
                (w, e) => panic!("expected a {w} error, got {e}"),
            }
        }
        assert!(matches!(
            Prony::try_new(-1.0, vec![good]),
            Err(MaterialError::EquilibriumModulus { .. })
        ));
        assert!(matches!(
            Prony::try_new(0.0, vec![]),
            Err(MaterialError::InstantaneousModulus { .. })
        ));
        // Zero branches with E∞ > 0 is linear elasticity; E∞ = 0 with branches is a Maxwell fluid: both valid.
        assert_eq!(
            Prony::try_new(3.0, vec![]).map(|p| p.instantaneous_modulus()),
            Ok(3.0)
        );
        assert_eq!(
            Prony::try_new(0.0, vec![good]).map(|p| p.instantaneous_modulus()),
            Ok(1.0)
        );
    }

    #[test]
    fn pla_instantaneous_modulus_is_the_table_sum() {
        let p = Prony::pla_van_manen_2021();
        assert_eq!(p.num_branches(), 15);
        assert!((p.instantaneous_modulus() - 2394.40).abs() < 1e-12 * 2394.4);
        assert_eq!(p.relaxation_modulus(0.0, 1.0), p.instantaneous_modulus());
        assert_eq!(p.relaxation_modulus(Real::INFINITY, 1.0), p.e_inf());
    }
}
