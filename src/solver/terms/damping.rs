//! Viscous regularisation of the equilibrium equations ([`crate::model::StabilisationSettings`], issue 18) as a
//! point term: at every interior collocation point a force density `−c A (x − xₙ)/h` (spatial) and a couple
//! density `−c J Θ/h` (material, `Θ = log(Rₙᵀ R)`) oppose the motion since the last converged state `xₙ, Rₙ`,
//! with the section's area `A` and its second moments `J = diag(I₂ + I₃, I₂, I₃)` as the mass of a unit density
//! (Abaqus's automatic stabilisation scales its damping by such an artificial mass matrix).
//!
//! Tangent: `δ(−c A Δx/h)` in the material frame is `−(c A/h) Rᵀ δc`; the couple's `δΘ = T(Θ)⁻¹ δθ` is the
//! right trivialisation of `log(Rₙᵀ R exp(δθ̃))` (`T` the right Jacobian of SO(3)).
//!
//! **State.** The term is built for each attempt of a step from the stabiliser's memory (when it has the
//! damping on): the last converged state and `c/h`. A step abandoned or converged drops it; a checkpoint never
//! holds one (module docs of `simulation::stabilisation`).

use super::{InteriorLoad, PointTerm, PointView};
use crate::material::SectionShape;
use crate::math::so3::{log, right_jacobian_inverse};
use crate::math::{Mat3, Real, Rot3, Vec3};
use crate::solver::discretisation::{Discretisation, point_position};
use crate::solver::state::State;

/// The damping of one attempt of a step (module docs).
#[derive(Debug, Clone, Copy)]
pub struct Damping<'a> {
    /// The last converged state.
    pub previous: &'a State,
    /// `c / h`, the damping factor over the step \[1/time²\] (per unit density).
    pub rate: Real,
}

impl Damping<'_> {
    /// The unit-density translational mass `A` and rotational mass `diag(I₂ + I₃, I₂, I₃)` of a section shape.
    pub fn masses(shape: &SectionShape) -> (Real, Vec3) {
        let (i2, i3) = (shape.moment.y, shape.moment.z);
        (shape.force.x, Vec3::new(i2 + i3, i2, i3))
    }

    /// The motion of collocation point `g` since the last converged state: `(x − xₙ, Θ)` with `Θ = log(Rₙᵀ R)`
    /// (material).
    pub fn motion(&self, disc: &Discretisation, state: &State, g: usize) -> (Vec3, Vec3) {
        let dx = point_position(disc, &state.control, g)
            - point_position(disc, &self.previous.control, g);
        let relative = self.previous.rotation[g].transpose() * state.rotation[g];
        (dx, log(&Rot3::from_matrix_unchecked(relative)))
    }
}

impl PointTerm for Damping<'_> {
    fn name(&self) -> &'static str {
        "viscous damping"
    }

    fn interior(&self, at: &PointView<'_>, load: &mut InteriorLoad) {
        let (area, inertia) = Self::masses(at.shape);
        let (dx, theta) = self.motion(at.disc, at.state, at.g);
        let c_area = self.rate * area;
        let c_inertia = inertia * self.rate;
        load.add_force(-(dx * c_area));
        load.add_material_couple(-c_inertia.component_mul(&theta));
        if at.tangent {
            load.add_force_position(-at.rotation_t * c_area);
            load.add_couple_rotation(
                -(Mat3::from_diagonal(&c_inertia) * right_jacobian_inverse(&theta)),
            );
        }
    }
}
