//! The evolving discrete state: control points (additive updates) and, at every collocation point, the
//! rotation, the curvature and its arc-length derivative (multiplicative updates, DESIGN §4 "Updates after a
//! Newton increment").

use super::discretisation::Discretisation;
use crate::math::so3::{exp, right_jacobian_rate};
use crate::math::{Mat3, Vec3};

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
}

impl State {
    /// The reference (unstressed) configuration.
    pub fn reference(disc: &Discretisation) -> Self {
        Self {
            control: disc.control0.clone(),
            rotation: disc.points.iter().map(|p| p.rotation0).collect(),
            kappa: disc.points.iter().map(|p| p.kappa0).collect(),
            kappa_s: disc.points.iter().map(|p| p.kappa0_s).collect(),
            multipliers: Vec::new(),
        }
    }

    /// Overwrites this state with `other`, reusing its memory (no allocation once the sizes match).
    pub fn copy_from(&mut self, other: &State) {
        self.control.clone_from(&other.control);
        self.rotation.clone_from(&other.rotation);
        self.kappa.clone_from(&other.kappa);
        self.kappa_s.clone_from(&other.kappa_s);
        self.multipliers.clone_from(&other.multipliers);
    }

    /// Applies a Newton increment `δ` (6 per control point: `δη` then `δθ`):
    /// `p_j ← p_j + δη_j` and, at each collocation point with `δΘ = Σ N_j δθ_j` (and its s-derivatives),
    /// `R ← R Λ`, `K ← Λᵀ K + w`, `K,s ← Λᵀ K,s − w × (Λᵀ K) + w,s` with `Λ = exp(δΘ̃)`, `w = T(δΘ) δΘ,s`.
    /// Entries of `delta` past the control points are the multipliers' increments.
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
}
