//! Obstacles: surfaces the rods of a device touch (issue 33) — a cylinder that keeps the rods inside it (a
//! crimper, a catheter sheath, a vessel idealised as a tube), a plane that keeps them on one side (a crush plate,
//! a table) — with a rigid or a compliant wall, and the contact settings of a model.
//!
//! What an obstacle is, not how the solver enforces it: the geometry gives the signed distance of a point from
//! the surface (positive on the side the rods belong to), its gradient and its Hessian
//! ([`Surface::distance`]); the contact law and the augmented-Lagrange updates are the solver's
//! (`crate::solver::terms::contact`).
//!
//! **Compliant wall.** A thin tube of Young's modulus `E_w`, thickness `h` and radius `R` under an internal
//! pressure `q` widens by `δ = q R² / (E_w h)` (Laplace's law for a thin tube, hoop stress `q R / h`, hoop strain
//! `δ / R`): a radial foundation of stiffness `k = E_w h / R²` \[force/length³\]. A wire presses on the strip of
//! wall it carries, of width `b` (the wall area per unit length of wire), so its line force per unit wire length is
//! `k b` times the wall's displacement: the contact law's penalty becomes the physical `k b`, and the
//! penetration is the wall's displacement, not an error (no augmented-Lagrange updates).
//!
//! **Friction.** Each obstacle has its Coulomb coefficient ([`Obstacle::friction`]): a point in contact carries
//! a tangential line force of at most `μ p` opposing its slip over the surface (the solver's regularised law).

use super::schedule::TimeFunction;
use crate::math::{Mat3, Real, Vec3};

/// A surface the rods touch, with its wall (module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Obstacle {
    /// Unique name (history columns, messages).
    pub name: String,
    /// The surface.
    pub surface: Surface,
    /// Rigid, or a compliant wall.
    pub wall: Wall,
    /// Coulomb friction coefficient `μ ≥ 0` between the rods and this surface (0: frictionless). Per obstacle,
    /// not in [`ContactSettings`], because it belongs to the pair of materials that touch: one device meets a
    /// polished crimper (μ ≈ 0.1), a sheath and a vessel wall, each with its own; the regularisation of the law
    /// (its stick stiffness) is the solver's (`crate::solver::terms::contact`).
    pub friction: Real,
}

/// The geometry of an obstacle.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum Surface {
    /// A circular cylinder around the axis through `point` along the unit vector `axis`, of radius `radius(t)`;
    /// the rods are kept inside it (a crimper shrinks, holds and opens through its schedule).
    Cylinder {
        /// A point of the axis \[length\].
        #[serde(serialize_with = "crate::math::serial::components")]
        point: Vec3,
        /// Unit direction of the axis.
        #[serde(serialize_with = "crate::math::serial::components")]
        axis: Vec3,
        /// Radius of the surface as a function of time \[length\].
        radius: TimeFunction,
    },
    /// The plane through `point + offset(t) · normal` with the unit `normal`; the rods are kept on the side
    /// the normal points to (a plate moves along its normal through its schedule).
    Plane {
        /// A point of the plane at zero offset \[length\].
        #[serde(serialize_with = "crate::math::serial::components")]
        point: Vec3,
        /// Unit normal, pointing to the rods' side.
        #[serde(serialize_with = "crate::math::serial::components")]
        normal: Vec3,
        /// Displacement of the plane along its normal as a function of time \[length\].
        offset: TimeFunction,
    },
}

/// The signed distance of a point from a surface (positive on the rods' side), with its gradient (the unit
/// normal pointing to the rods' side) and Hessian.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Distance {
    /// Signed distance \[length\].
    pub value: Real,
    /// Its gradient: unit, pointing away from the surface into the rods' side.
    pub normal: Vec3,
    /// Its Hessian \[1/length\] (zero for a plane).
    pub hessian: Mat3,
}

impl Surface {
    /// The signed distance of the point `x` from the surface at time `t` (module docs). For a cylinder, `None`
    /// on its axis, where the distance has no gradient (a point there is a radius away from the wall).
    ///
    /// Cylinder: with `d = x − point`, `x⊥ = d − (d·a) a`, `ρ = |x⊥|` and `e = x⊥ / ρ`, the distance is
    /// `R(t) − ρ`, its gradient `−e` and its Hessian `−(I − a aᵀ − e eᵀ) / ρ` (the Hessian of `ρ` is the
    /// projector onto the plane normal to both `a` and `e`, over `ρ`). Plane: `n · (x − point) − offset(t)`,
    /// gradient `n`, Hessian zero.
    pub fn distance(&self, x: &Vec3, t: Real) -> Option<Distance> {
        match self {
            Surface::Cylinder {
                point,
                axis,
                radius,
            } => {
                let d = x - point;
                let perp = d - axis * axis.dot(&d);
                let rho = perp.norm();
                let r = radius.value(t);
                if rho <= Real::EPSILON * r.abs().max(1.0) {
                    return None;
                }
                let e = perp / rho;
                let projector = Mat3::identity() - axis * axis.transpose() - e * e.transpose();
                Some(Distance {
                    value: r - rho,
                    normal: -e,
                    hessian: -projector / rho,
                })
            }
            Surface::Plane {
                point,
                normal,
                offset,
            } => Some(Distance {
                value: normal.dot(&(x - point)) - offset.value(t),
                normal: *normal,
                hessian: Mat3::zeros(),
            }),
        }
    }

    /// The radius of a cylinder at time `t` (`None` for a plane): the `R` of a compliant wall's stiffness.
    pub fn radius(&self, t: Real) -> Option<Real> {
        match self {
            Surface::Cylinder { radius, .. } => Some(radius.value(t)),
            Surface::Plane { .. } => None,
        }
    }

    /// The times at which the surface's schedule changes its rate (time stepping lands on them).
    pub fn breakpoints(&self) -> Vec<Real> {
        match self {
            Surface::Cylinder { radius: f, .. } | Surface::Plane { offset: f, .. } => {
                f.breakpoints().collect()
            }
        }
    }
}

/// The wall of an obstacle.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum Wall {
    /// Rigid: the contact law's penalty with augmented-Lagrange updates drives the penetration below the
    /// model's tolerance ([`ContactSettings`]).
    Rigid,
    /// A thin elastic tube (or plate) acting as a radial foundation (module docs).
    Compliant {
        /// Young's modulus of the wall `E_w` \[stress\].
        modulus: Real,
        /// Thickness `h` \[length\].
        thickness: Real,
        /// Width of wall each unit length of wire carries, `b` \[length\].
        width: Real,
    },
}

impl Wall {
    /// The line stiffness of a compliant wall of radius `radius`, `k b = E_w h b / R²` \[force/length²\]
    /// (module docs); `None` for a rigid wall.
    pub fn line_stiffness(&self, radius: Real) -> Option<Real> {
        match *self {
            Wall::Rigid => None,
            Wall::Compliant {
                modulus,
                thickness,
                width,
            } => Some(modulus * thickness * width / (radius * radius)),
        }
    }
}

/// The obstacles of a model and how contact with them is enforced.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Contact {
    /// The surfaces the rods touch.
    pub obstacles: Vec<Obstacle>,
    /// The contact law's settings.
    pub settings: ContactSettings,
}

/// How contact with rigid walls is enforced (the solver's `contact` term).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ContactSettings {
    /// Penalty `ε` \[force/length²\]: line force per unit length of wire per unit penetration.
    pub penalty: Real,
    /// Width of the law's quadratic transition `2δ` \[length\] (C¹ at zero force).
    pub regularisation: Real,
    /// Largest penetration a converged step may keep \[length\]: beyond it the augmented-Lagrange multipliers
    /// are updated and the step solved again.
    pub tolerance: Real,
    /// Most augmented-Lagrange updates per step.
    pub max_updates: usize,
}
