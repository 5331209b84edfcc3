//! The evolving discrete state: control points (additive updates) and, at every collocation point, the
//! rotation, the curvature and its arc-length derivative. With the objective rotation field (the default) each
//! control point also carries its rotation from the reference, a unit quaternion `ρ_a` turned by its increment,
//! and the collocation points' rotations and curvatures follow from them (`crate::math::quaternion_field`);
//! with the paper's incremental field they are updated at the collocation points by interpolated increments
//! (multiplicative updates, DESIGN §4 "Updates after a Newton increment").

use super::discretisation::Discretisation;
use crate::math::quaternion_field::{self, Quat};
use crate::math::so3::{exp, right_jacobian_rate};
use crate::math::{Mat3, Vec3};
use crate::model::RotationField;

/// The configuration at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// Control points `p_j` (global numbering) \[length\].
    pub control: Vec<Vec3>,
    /// Section rotation `R` at each collocation point.
    pub rotation: Vec<Mat3>,
    /// Material curvature `K` at each collocation point \[1/length\].
    pub kappa: Vec<Vec3>,
    /// Its arc-length derivative `K,s` \[1/length²\].
    pub kappa_s: Vec<Vec3>,
    /// Lagrange multipliers of the active gauge constraints ([`super::gauge`]) \[force\].
    pub multipliers: Vec<f64>,
    /// The control points' rotations from the reference, `ρ_a`, as unit quaternions (the objective field; empty
    /// for the incremental one; module docs).
    pub orientation: Vec<Quat>,
    /// Their rotation vectors relative to their patch's reference rotation, `θ_a`, unwrapped (the objective field,
    /// derived from `orientation` by [`State::sync_rotations`]; empty for the incremental one).
    pub relative: Vec<Vec3>,
}

impl State {
    /// The reference (unstressed) configuration.
    pub fn reference(disc: &Discretisation) -> Self {
        let (orientation, relative) = match disc.rotations {
            RotationField::Objective => (
                vec![Quat::identity(); disc.points.len()],
                vec![Vec3::zeros(); disc.points.len()],
            ),
            RotationField::Incremental => (Vec::new(), Vec::new()),
        };
        Self {
            control: disc.control0.clone(),
            rotation: disc.points.iter().map(|p| p.rotation0).collect(),
            kappa: disc.points.iter().map(|p| p.kappa0).collect(),
            kappa_s: disc.points.iter().map(|p| p.kappa0_s).collect(),
            multipliers: Vec::new(),
            orientation,
            relative,
        }
    }

    /// Overwrites this state with `other`, reusing its memory (no allocation once the sizes match).
    pub fn copy_from(&mut self, other: &State) {
        self.control.clone_from(&other.control);
        self.rotation.clone_from(&other.rotation);
        self.kappa.clone_from(&other.kappa);
        self.kappa_s.clone_from(&other.kappa_s);
        self.multipliers.clone_from(&other.multipliers);
        self.orientation.clone_from(&other.orientation);
        self.relative.clone_from(&other.relative);
    }

    /// Applies a Newton increment `δ` (6 per control point: `δη` then `δθ`): `p_j ← p_j + δη_j` and, with the
    /// objective field, `ρ_j ← ρ_j ⊗ exp(R0_j δθ_j / 2)` (`δθ_j` a material increment of the control point's
    /// rotation `P_j R0_j`, `R0_j` its collocation point's reference rotation) and the collocation points' `R`,
    /// `K`, `K,s` from them ([`State::sync_rotations`]); with the incremental field, at each collocation point with `δΘ = Σ N_j δθ_j`
    /// (and its s-derivatives), `R ← R Λ`, `K ← Λᵀ K + w`, `K,s ← Λᵀ K,s − w × (Λᵀ K) + w,s` with
    /// `Λ = exp(δΘ̃)`, `w = T(δΘ) δΘ,s`. Entries of `delta` past the control points are the multipliers'
    /// increments.
    pub fn apply_increment(&mut self, disc: &Discretisation, delta: &[f64]) {
        let n = disc.num_unknowns();
        for (m, d) in self
            .multipliers
            .iter_mut()
            .zip(&delta[n.min(delta.len())..])
        {
            *m += d;
        }
        for (j, p) in self.control.iter_mut().enumerate() {
            *p += Vec3::new(delta[6 * j], delta[6 * j + 1], delta[6 * j + 2]);
        }
        if !self.orientation.is_empty() {
            for (j, q) in self.orientation.iter_mut().enumerate() {
                let d = Vec3::new(delta[6 * j + 3], delta[6 * j + 4], delta[6 * j + 5]);
                *q = quaternion_field::turned(q, &(disc.points[j].rotation0 * d));
            }
            self.sync_rotations(disc);
            return;
        }
        for (g, point) in disc.points.iter().enumerate() {
            let (mut th, mut th_s, mut th_ss) = (Vec3::zeros(), Vec3::zeros(), Vec3::zeros());
            for (a, row) in point.basis.iter().enumerate() {
                let j = point.first + a;
                let d = Vec3::new(delta[6 * j + 3], delta[6 * j + 4], delta[6 * j + 5]);
                th += d * row[0];
                th_s += d * row[1];
                th_ss += d * row[2];
            }
            let lambda = exp(&th);
            let lt = lambda.matrix().transpose();
            let (w, w_s) = right_jacobian_rate(&th, &th_s, &th_ss);
            let lk = lt * self.kappa[g];
            let r = self.rotation[g] * lambda.matrix();
            // One Newton step of the polar decomposition keeps R orthogonal to round-off over long runs.
            self.rotation[g] = r * (Mat3::identity() * 1.5 - r.transpose() * r * 0.5);
            self.kappa_s[g] = lt * self.kappa_s[g] - w.cross(&lk) + w_s;
            self.kappa[g] = lk + w;
        }
    }

    /// The control points' rotation vectors relative to their patch's reference and, from them, the collocation
    /// points' rotations `R`, curvatures `K` and `K,s` (the objective field, `crate::math::quaternion_field`):
    /// `R = P R0`, `K = R0ᵀ ω + K0`, `K,s = R0ᵀ ω,s − K0 × (R0ᵀ ω) + K0,s` with the field's `P`, `ω`, `ω,s`.
    pub fn sync_rotations(&mut self, disc: &Discretisation) {
        let references: Vec<Quat> = (disc.patches.iter())
            .map(|range| {
                let [m, m1] = range.references();
                let span = range.offset..range.offset + range.n;
                let (reference, _) = quaternion_field::reference_rotation(
                    &self.orientation[m],
                    &self.orientation[m1],
                );
                quaternion_field::relative_rotations(
                    &self.orientation[span.clone()],
                    &reference,
                    m - range.offset,
                    &mut self.relative[span],
                );
                reference
            })
            .collect();
        for (g, point) in disc.points.iter().enumerate() {
            let thetas = &self.relative[point.first..point.first + point.basis.len()];
            let (p, w, w_s) = quaternion_field::kinematics(
                &references[point.patch],
                &quaternion_field::interpolate(thetas, &point.basis),
            );
            let r0t = point.rotation0.transpose();
            let k = r0t * w;
            self.rotation[g] = p * point.rotation0;
            self.kappa[g] = k + point.kappa0;
            self.kappa_s[g] = r0t * w_s - point.kappa0.cross(&k) + point.kappa0_s;
        }
    }
}
