//! A spring to ground (test-only): the example of a new point term, and the one the generic tangent test and
//! the closed-form foundation test run.
//!
//! Along the rods (interior collocation points) a Winkler foundation: a force density `n̄ = −k (c − X)` on the
//! displacement from the reference position `X`, and a couple density `m̄ = −k_r φ` on the rotation from the
//! reference, `R = exp(φ̃) R⁰` (both spatial). At every patch end a concentrated spring on the node: force
//! `−k_e (c − X)` and moment `−k_er φ`.
//!
//! Tangent: `∂(Rᵀ n̄)/∂c = −k Rᵀ` at fixed `R`; under `R ← R exp(δΘ̃)`, `R R⁰ᵀ ← exp((R δΘ)~) R R⁰ᵀ`, so
//! `δφ = J_l⁻¹(φ) R δΘ` with `J_l(φ) = J_r(−φ)` (the left Jacobian, as the node equations' prescribed rotations
//! use it) and `∂(Rᵀ m̄)/∂δΘ` beyond `hat(Rᵀ m̄)` is `−k_r Rᵀ J_l⁻¹(φ) R`.

use super::{EndLoad, InteriorLoad, PointTerm, PointView};
use crate::math::so3::{log, right_jacobian_inverse};
use crate::math::{Real, Rot3, Vec3};
use crate::solver::discretisation::point_position;

/// Springs to ground along the rods and at their ends (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SpringToGround {
    /// Foundation stiffness `k` \[force/length²\].
    pub foundation: Real,
    /// Rotational foundation stiffness `k_r` \[force\].
    pub rotational_foundation: Real,
    /// Stiffness of the spring at each patch end `k_e` \[force/length\].
    pub end: Real,
    /// Rotational stiffness of the spring at each patch end `k_er` \[force·length\].
    pub rotational_end: Real,
}

impl SpringToGround {
    /// The displacement `c − X` and the rotation vector `φ` of the point from its reference (spatial).
    fn motion(at: &PointView<'_>) -> (Vec3, Vec3) {
        let dx = at.position() - point_position(at.disc, &at.disc.control0, at.g);
        let phi = log(&Rot3::from_matrix_unchecked(
            at.rotation() * at.point.rotation0.transpose(),
        ));
        (dx, phi)
    }
}

impl PointTerm for SpringToGround {
    fn name(&self) -> &'static str {
        "spring to ground"
    }

    fn interior(&self, at: &PointView<'_>, load: &mut InteriorLoad) {
        let (dx, phi) = Self::motion(at);
        load.add_force(-dx * self.foundation);
        load.add_couple(-phi * self.rotational_foundation);
        if at.tangent {
            let rt = at.rotation_t;
            load.add_force_position(-rt * self.foundation);
            let dphi = right_jacobian_inverse(&(-phi)) * at.rotation();
            load.add_couple_rotation(-(rt * dphi) * self.rotational_foundation);
        }
    }

    fn end(&self, at: &PointView<'_>, load: &mut EndLoad) {
        let (dx, phi) = Self::motion(at);
        load.add_force(-dx * self.end);
        load.add_moment(-phi * self.rotational_end);
        if at.tangent {
            load.add_force_position(crate::math::Mat3::identity() * -self.end);
            let dphi = right_jacobian_inverse(&(-phi)) * at.rotation();
            load.add_moment_rotation(dphi * -self.rotational_end);
        }
    }
}
