//! Residual and consistent tangent of the collocated equations (paper §3, compact form of DESIGN §4).
//!
//! At an interior collocation point the material balance laws (paper Eqs. mat_f, mat_m)
//! ```text
//! F = K × N + N,s + Rᵀ n̄ = 0,      T = K × M + M,s + Γ × N + Rᵀ m̄ = 0
//! ```
//! with `N = C̄_N (Γ − Γ0) − H_N`, `M = C̄_M (K − K0) − H_M` (N_constitutive_disc, M_constitutive_disc; the
//! history terms `H` are constant during Newton; evaluated by [`crate::material::SectionLaw`], the only place
//! the law is written) and `Γ,s = Rᵀ c,ss − K × Γ`.
//! Their linearisation under `R exp(εδΘ̃)`, `c + εδη` uses
//! ```text
//! δΓ = Γ × δΘ + Rᵀ δη,s            δK = K × δΘ + δΘ,s
//! δΓ,s = (Rᵀc,ss) × δΘ + Rᵀ δη,ss + Γ × δK − K × δΓ
//! δK,s = K,s × δΘ + K × δΘ,s + δΘ,ss
//! ```
//! which gives 3×3 coefficient blocks of `δΘ, δΘ,s, δΘ,ss, δη,s, δη,ss` per point; multiplied by the basis
//! values they are the tangent's blocks per control point.
//!
//! Patch ends carry the node equations (DESIGN §4 "Joints"): for a node joining ends `e = 1 … k` with outward
//! signs `σ_e`, the rows of end 1 hold, per component of the node's local basis `B`, either equilibrium
//! `Bᵀ(Σ σ_e R_e N_e − f̄)`, `Bᵀ(Σ σ_e R_e M_e − m̄)` or, for a prescribed component, the kinematic condition
//! (`e_i·(c_1 − X_1) = ḡ_i`, or `e_i·φ = ḡ_i` with `R_1 = exp(φ̃) R_1⁰`); the rows of every other end hold
//! continuity of position and rotation with end 1 (`c_e = c_1`, `R_e = R_1 Q_e` with the reference relative
//! rotation `Q_e = R_1⁰ᵀ R_e⁰`). The sparsity pattern is the union over all conditions, so it never changes when
//! a condition is released.
//!
//! Every equation row gets a scale that turns its residual into a dimensionless, strain-like number (force
//! rows by `E A`, moment rows by `E I / L`, per unit length by one more `1/L`, translations by `L`), used by
//! Newton's normalised norms.

use super::discretisation::{CollocationPoint, Discretisation};
use super::gauge::Gauge;
use super::state::State;
use crate::material::{ConstitutiveLaw, SectionLaw, SectionStrains};
use crate::math::so3::{hat, log, right_jacobian_inverse};
use crate::math::{Mat3, Real, Rot3, Vec3};
use crate::model::{Component, Model};
use rayon::prelude::*;

/// Receives the tangent's entries in a fixed order: first to record the sparsity pattern, then to fill values.
pub enum Sink<'a> {
    /// Records `(row, column)` of every entry.
    Pattern(&'a mut Vec<(usize, usize)>),
    /// Writes the values in the recorded order.
    Values {
        /// One value per recorded entry.
        values: &'a mut [Real],
        /// Next position.
        next: usize,
    },
    /// Discards entries (residual-only assembly).
    Discard,
}

impl Sink<'_> {
    #[inline]
    fn push(&mut self, row: usize, col: usize, v: Real) {
        match self {
            Sink::Pattern(p) => p.push((row, col)),
            Sink::Values { values, next } => {
                values[*next] = v;
                *next += 1;
            }
            Sink::Discard => {}
        }
    }

    /// Adds a 3×3 block at `(row, col)`.
    #[inline]
    fn block(&mut self, row: usize, col: usize, m: &Mat3) {
        if matches!(self, Sink::Discard) {
            return;
        }
        for i in 0..3 {
            for j in 0..3 {
                self.push(row + i, col + j, m[(i, j)]);
            }
        }
    }
}

/// A released component's reaction, ramped to the load after release (see
/// [`crate::model::TimeSettings::release_ramp`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReleaseRamp {
    /// The reaction component that held the node at the release, in the node's local basis [force or moment].
    pub reaction: Real,
    /// Release time \[time\].
    pub start: Real,
    /// Ramp duration \[time\].
    pub duration: Real,
}

impl ReleaseRamp {
    /// The part of the reaction still applied at time `t`.
    pub fn value(&self, t: Real) -> Real {
        let f = if self.duration > 0.0 {
            1.0 - (t - self.start) / self.duration
        } else {
            0.0
        };
        self.reaction * f.clamp(0.0, 1.0)
    }
}

/// The loads and prescribed values at one instant, resolved from the model's schedules.
#[derive(Debug, Clone, PartialEq)]
pub struct Actions {
    /// Per node: concentrated force and moment (spatial) on its free components.
    pub node_force: Vec<Vec3>,
    /// Per node: concentrated moment (spatial).
    pub node_moment: Vec<Vec3>,
    /// Per node and local component: the prescribed value, or `None` when the component is free.
    pub prescribed: Vec<[Option<Real>; 6]>,
    /// Per patch: distributed force per unit length (spatial).
    pub dist_force: Vec<Vec3>,
    /// Per patch: distributed couple per unit length (spatial).
    pub dist_couple: Vec<Vec3>,
}

impl Actions {
    /// Evaluates every schedule of the model at time `t`; `ramps[k][i]` is the release ramp of node `k`'s
    /// component `i` once it has been released (empty: none).
    pub fn at(model: &Model, t: Real, ramps: &[[Option<ReleaseRamp>; 6]]) -> Self {
        let mut node_force = Vec::with_capacity(model.nodes.len());
        let mut node_moment = Vec::with_capacity(model.nodes.len());
        let mut prescribed = Vec::with_capacity(model.nodes.len());
        for (k, node) in model.nodes.iter().enumerate() {
            let mut local = [0.0; 6];
            let mut fixed = [None; 6];
            for (i, c) in node.conditions.components.iter().enumerate() {
                match c {
                    Component::Load(f) => local[i] = f.value(t),
                    Component::Prescribed {
                        value,
                        release,
                        load_after_release,
                    } => {
                        if release.is_none_or(|r| t < r) {
                            fixed[i] = Some(value.value(t));
                        } else {
                            let ramp = ramps.get(k).and_then(|r| r[i]).map_or(0.0, |r| r.value(t));
                            local[i] = load_after_release.value(t) + ramp;
                        }
                    }
                }
            }
            let b = &node.conditions.basis;
            node_force.push(b * Vec3::new(local[0], local[1], local[2]));
            node_moment.push(b * Vec3::new(local[3], local[4], local[5]));
            prescribed.push(fixed);
        }
        let mut dist_force = vec![Vec3::zeros(); model.patches.len()];
        let mut dist_couple = vec![Vec3::zeros(); model.patches.len()];
        for load in &model.distributed_loads {
            dist_force[load.patch] += Vec3::from_fn(|i, _| load.force[i].value(t));
            dist_couple[load.patch] += Vec3::from_fn(|i, _| load.couple[i].value(t));
        }
        Self {
            node_force,
            node_moment,
            prescribed,
            dist_force,
            dist_couple,
        }
    }

    /// Every load and prescribed value multiplied by `factor` (arc-length continuation's load factor: the
    /// residual is affine in it).
    pub fn scaled(&self, factor: Real) -> Self {
        let scale = |v: &[Vec3]| v.iter().map(|x| x * factor).collect();
        Self {
            node_force: scale(&self.node_force),
            node_moment: scale(&self.node_moment),
            prescribed: self
                .prescribed
                .iter()
                .map(|c| c.map(|v| v.map(|v| v * factor)))
                .collect(),
            dist_force: scale(&self.dist_force),
            dist_couple: scale(&self.dist_couple),
        }
    }
}

/// The constitutive data of one time step: the section law of every collocation point (from its patch's
/// material, [`crate::material::ConstitutiveLaw::section_law`]).
#[derive(Debug, Clone, Copy)]
pub struct StepMaterial<'a> {
    /// Section law per collocation point.
    pub laws: &'a [SectionLaw],
}

impl StepMaterial<'_> {
    /// The section law of collocation point `g` (the one place the residual, tangent and resultants take `N`,
    /// `M` and `C̄` from).
    #[inline]
    fn law(&self, g: usize) -> SectionLaw {
        self.laws[g]
    }
}

/// Viscous regularisation of the equilibrium equations ([`crate::model::StabilisationSettings`], issue 18):
/// at every interior collocation point a force density `−c A (x − xₙ)/h` (spatial) and a couple density
/// `−c J Θ/h` (material, `Θ = log(Rₙᵀ R)`) oppose the motion since the last converged state `xₙ, Rₙ`, with
/// the section's area `A` and its second moments `J = diag(I₂ + I₃, I₂, I₃)` as the mass of a unit density
/// (Abaqus's automatic stabilisation scales its damping by such an artificial mass matrix).
#[derive(Debug, Clone, Copy)]
pub struct Damping<'a> {
    /// The last converged state.
    pub previous: &'a State,
    /// `c / h`, the damping factor over the step \[1/time²\] (per unit density).
    pub rate: Real,
}

impl Damping<'_> {
    /// The unit-density translational mass `A` and rotational mass `diag(I₂ + I₃, I₂, I₃)` of a section shape.
    pub fn masses(shape: &crate::material::SectionShape) -> (Real, Vec3) {
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

/// One end of a node, as the node equations see it.
#[derive(Debug, Clone, PartialEq)]
struct NodeEnd {
    /// Global collocation point of the end.
    point: usize,
    /// Outward sign σ.
    sign: Real,
    /// The index `a` of the basis function that equals 1 at the end (the end control point).
    end_basis: usize,
    /// Reference relative rotation `Q_e = R_1⁰ᵀ R_e⁰` (identity for the first end).
    relative: Mat3,
}

/// The fixed data of one node's equations.
#[derive(Debug, Clone, PartialEq)]
struct NodeRows {
    ends: Vec<NodeEnd>,
    /// Local basis (columns e1, e2, e3).
    basis: Mat3,
    /// Reference position of end 1.
    position0: Vec3,
    /// Reference rotation of end 1.
    rotation0: Mat3,
}

/// Everything the assembly needs that does not change during a run.
#[derive(Debug, Clone)]
pub struct Assembler {
    nodes: Vec<NodeRows>,
    /// Reference modulus of each patch's material for residual scales (instantaneous modulus) \[stress\].
    modulus_scale: Vec<Real>,
    /// Length of each patch \[length\].
    patch_length: Vec<Real>,
    /// Tangent entries pushed by each collocation point's interior equations (zero at patch ends), and their
    /// total: the interior points come first in the push order, so point `g`'s entries are a known slice.
    interior_entries: Vec<usize>,
    interior_total: usize,
}

/// Tangent entries pushed by one interior collocation point: four 3×3 blocks per control point of its basis.
fn interior_entry_count(point: &CollocationPoint) -> usize {
    4 * 9 * point.basis.len()
}

/// Tangent and residual of one Newton iteration, and the row scales of the residual.
#[derive(Debug, Clone, Default)]
pub struct Linearisation {
    /// Residual vector (one entry per equation).
    pub residual: Vec<Real>,
    /// Dimensionless scale of each row (residual / scale is strain-like).
    pub row_scale: Vec<Real>,
}

impl Assembler {
    /// Prepares the node equations of `model` on `disc`.
    pub fn new(model: &Model, disc: &Discretisation) -> Self {
        let nodes = model
            .nodes
            .iter()
            .map(|node| {
                let g1 = disc.end_point(node.ends[0]);
                let r1 = disc.points[g1].rotation0;
                let ends = node
                    .ends
                    .iter()
                    .map(|&e| {
                        let g = disc.end_point(e);
                        let point = &disc.points[g];
                        let end_basis = point.basis.iter().position(|row| row[0] == 1.0).unwrap_or(
                            if e.end.sign() < 0.0 {
                                0
                            } else {
                                point.basis.len() - 1
                            },
                        );
                        NodeEnd {
                            point: g,
                            sign: e.end.sign(),
                            end_basis,
                            relative: r1.transpose() * point.rotation0,
                        }
                    })
                    .collect();
                NodeRows {
                    ends,
                    basis: node.conditions.basis,
                    position0: point_position(disc, &disc.control0, g1),
                    rotation0: r1,
                }
            })
            .collect();
        let modulus_scale = model
            .patches
            .iter()
            .map(|p| model.materials[p.material].reference_modulus())
            .collect();
        let patch_length = model
            .patches
            .iter()
            .map(|p| curve_length(&p.curve))
            .collect();
        let interior_entries: Vec<usize> = disc
            .points
            .iter()
            .enumerate()
            .map(|(g, point)| {
                if disc.is_end(g) {
                    0
                } else {
                    interior_entry_count(point)
                }
            })
            .collect();
        Self {
            nodes,
            modulus_scale,
            patch_length,
            interior_total: interior_entries.iter().sum(),
            interior_entries,
        }
    }

    /// Assembles the residual into `lin` and the tangent into `sink` (entries in the pattern's order).
    /// With active gauge constraints ([`Gauge`]) the system has one more unknown (a multiplier, in
    /// `state.multipliers`) and equation per constraint, after the rod's.
    #[allow(clippy::too_many_arguments)]
    pub fn assemble(
        &self,
        disc: &Discretisation,
        state: &State,
        material: StepMaterial<'_>,
        actions: &Actions,
        damping: Option<Damping<'_>>,
        gauge: Option<&Gauge>,
        lin: &mut Linearisation,
        sink: &mut Sink<'_>,
    ) {
        let n = disc.num_unknowns();
        let m = gauge.map_or(0, Gauge::len);
        lin.residual.resize(n + m, 0.0);
        lin.row_scale.resize(n + m, 1.0);
        // Interior points: independent (each owns its six rows and a known slice of the tangent's entries), so
        // the tangent is assembled in parallel; the residual alone is too cheap per point to gain from it
        // (measured on the curved stent: tangent 0.81 → 0.60 s, residual 0.29 → 0.44 s over 0.5 s of the run).
        if let Sink::Values { values, next } = sink {
            *next = self.interior_total;
            let mut entries = &mut values[..self.interior_total];
            let mut tasks = Vec::with_capacity(disc.points.len());
            for ((g, residual), scale) in lin.residual[..n]
                .chunks_mut(6)
                .enumerate()
                .zip(lin.row_scale[..n].chunks_mut(6))
            {
                let (head, tail) =
                    std::mem::take(&mut entries).split_at_mut(self.interior_entries[g]);
                entries = tail;
                if !disc.is_end(g) {
                    tasks.push((g, residual, scale, head));
                }
            }
            tasks
                .into_par_iter()
                .for_each(|(g, residual, scale, values)| {
                    let mut sink = Sink::Values { values, next: 0 };
                    let point = &disc.points[g];
                    self.interior(
                        disc, state, material, actions, damping, g, point, residual, scale,
                        &mut sink,
                    );
                    if let Sink::Values { values, next } = sink {
                        debug_assert_eq!(
                            next,
                            values.len(),
                            "interior_entry_count matches the pushes"
                        );
                    }
                });
        } else {
            for (g, point) in disc.points.iter().enumerate() {
                if !disc.is_end(g) {
                    let rows = 6 * g..6 * g + 6;
                    let (residual, scale) =
                        (&mut lin.residual[rows.clone()], &mut lin.row_scale[rows]);
                    self.interior(
                        disc, state, material, actions, damping, g, point, residual, scale, sink,
                    );
                }
            }
        }
        // Node rows.
        for (k, node) in self.nodes.iter().enumerate() {
            self.node(disc, state, material, actions, k, node, lin, sink);
        }
        if let Some(gauge) = gauge {
            self.gauge(disc, state, actions, gauge, lin, sink);
        }
    }

    /// The gauge constraints' rows (`C_j`, rows `n + j`) and their multipliers' columns in the free
    /// translational rows of the constrained nodes (always emitted, zero where a component is prescribed, so
    /// the pattern does not depend on the conditions).
    fn gauge(
        &self,
        disc: &Discretisation,
        state: &State,
        actions: &Actions,
        gauge: &Gauge,
        lin: &mut Linearisation,
        sink: &mut Sink<'_>,
    ) {
        let n = disc.num_unknowns();
        for (j, row) in gauge.rows.iter().enumerate() {
            let lambda = state.multipliers.get(j).copied().unwrap_or(0.0);
            let mut c = 0.0;
            for &(k, a) in &row.terms {
                let node = &self.nodes[k];
                let first = &node.ends[0];
                let g1 = first.point;
                let position = point_position(disc, &state.control, g1);
                let frozen = gauge
                    .frozen
                    .iter()
                    .find(|(l, _)| *l == k)
                    .map_or(position, |(_, x)| *x);
                c += a.dot(&(position - frozen));
                let local = node.basis.transpose() * a;
                let col = 6 * (disc.points[g1].first + first.end_basis);
                for i in 0..3 {
                    let free = actions.prescribed[k][i].is_none();
                    if free {
                        lin.residual[6 * g1 + i] -= lambda * local[i];
                    }
                    sink.push(6 * g1 + i, n + j, if free { -local[i] } else { 0.0 });
                }
                for i in 0..3 {
                    sink.push(n + j, col + i, a[i]);
                }
            }
            lin.residual[n + j] = c;
            lin.row_scale[n + j] = gauge.scale;
        }
    }

    /// Per end of node `k`: `(σ R N, σ R M)` in the given state (see [`super::Simulation::node_end_resultants`]).
    #[allow(non_snake_case)]
    pub fn node_end_resultants(
        &self,
        disc: &Discretisation,
        state: &State,
        material: StepMaterial<'_>,
        k: usize,
    ) -> Vec<(Vec3, Vec3)> {
        self.nodes[k]
            .ends
            .iter()
            .map(|e| {
                let point = &disc.points[e.point];
                let kin = kinematics(point, state, e.point);
                let stress = material
                    .law(e.point)
                    .stress(&strains(point, state, e.point, &kin));
                let (N, M) = (stress.force, stress.moment);
                let R = &state.rotation[e.point];
                (R * N * e.sign, R * M * e.sign)
            })
            .collect()
    }

    #[allow(non_snake_case, clippy::too_many_arguments)]
    fn interior(
        &self,
        disc: &Discretisation,
        state: &State,
        material: StepMaterial<'_>,
        actions: &Actions,
        damping: Option<Damping<'_>>,
        g: usize,
        point: &CollocationPoint,
        residual: &mut [Real],
        row_scale: &mut [Real],
        sink: &mut Sink<'_>,
    ) {
        let law = material.law(g);
        let (CN, CM) = law.stiffness_matrices();
        let k = kinematics(point, state, g);
        let stress = law.stress(&strains(point, state, g, &k));
        let (N, N_s, M, M_s) = (
            stress.force,
            stress.force_ds,
            stress.moment,
            stress.moment_ds,
        );
        let K = state.kappa[g];
        let K_s = state.kappa_s[g];
        let R = &state.rotation[g];
        let Rt = R.transpose();
        let shape = &disc.shapes[point.shape];
        // Viscous regularisation ([`Damping`]): a spatial force density that joins the distributed load (whose
        // rotation derivative `hat(n̄)` the tangent has) and a material couple density, `(c A/h, Θ, c J/h)`.
        let mut force_density = actions.dist_force[point.patch];
        let mut viscous = None;
        if let Some(d) = damping {
            let (area, inertia) = Damping::masses(shape);
            let (dx, theta) = d.motion(disc, state, g);
            force_density -= dx * (d.rate * area);
            viscous = Some((d.rate * area, theta, inertia * d.rate));
        }
        let viscous_couple =
            viscous.map_or(Vec3::zeros(), |(_, theta, c)| -c.component_mul(&theta));
        let nbar = Rt * force_density;
        let mbar = Rt * actions.dist_couple[point.patch];
        let F = K.cross(&N) + N_s + nbar;
        let T = K.cross(&M) + M_s + k.gamma.cross(&N) + mbar + viscous_couple;
        let row = 6 * g;
        residual[..3].copy_from_slice(F.as_slice());
        residual[3..6].copy_from_slice(T.as_slice());
        let length = self.patch_length[point.patch];
        let modulus_scale = self.modulus_scale[point.patch];
        let force_scale = modulus_scale * shape.force.x / length;
        let moment_scale = modulus_scale * shape.moment.y / (length * length);
        row_scale[..3].fill(force_scale);
        row_scale[3..6].fill(moment_scale);
        if matches!(sink, Sink::Discard) {
            return;
        }
        let (Kt, Gt, Nt, Mt) = (hat(&K), hat(&k.gamma), hat(&N), hat(&M));
        let cssm = hat(&(Rt * k.c_ss));
        let mut f_th = -Nt * Kt + Kt * CN * Gt + CN * (cssm + Gt * Kt - Kt * Gt) + hat(&nbar);
        let f_th_s = -Nt + CN * Gt;
        let mut f_eta_s = (Kt * CN - CN * Kt) * Rt;
        let f_eta_ss = CN * Rt;
        let ng = -Nt + Gt * CN;
        let mut t_th = -Mt * Kt + Kt * CM * Kt + CM * hat(&K_s) + ng * Gt + hat(&mbar);
        let mut f_eta = Mat3::zeros();
        if let Some((c_area, theta, c_inertia)) = viscous {
            // δ(−c A Δx/h) in the material frame is −(c A/h) Rᵀ δη; the couple's `δΘ = T(Θ)⁻¹ δθ` is the right
            // trivialisation of `log(Rₙᵀ R exp(δθ̃))`.
            f_eta = -Rt * c_area;
            t_th -= Mat3::from_diagonal(&c_inertia) * right_jacobian_inverse(&theta);
        }
        let mut t_th_s = -Mt + Kt * CM + CM * Kt;
        if let Some((CN_s, CM_s)) = law.stiffness_slope_matrices() {
            // A modulus varying along s: N,s gains C̄_N,s δΓ = C̄_N,s (Γ × δΘ + Rᵀ δη,s), M,s gains C̄_M,s δK =
            // C̄_M,s (K × δΘ + δΘ,s) (module docs of `material::law`).
            f_th += CN_s * Gt;
            f_eta_s += CN_s * Rt;
            t_th += CM_s * Kt;
            t_th_s += CM_s;
        }
        let t_th_ss = CM;
        let t_eta_s = ng * Rt;
        for (a, b) in point.basis.iter().enumerate() {
            let col = 6 * (point.first + a);
            sink.block(row, col, &(f_eta * b[0] + f_eta_s * b[1] + f_eta_ss * b[2]));
            sink.block(row, col + 3, &(f_th * b[0] + f_th_s * b[1]));
            sink.block(row + 3, col, &(t_eta_s * b[1]));
            sink.block(
                row + 3,
                col + 3,
                &(t_th * b[0] + t_th_s * b[1] + t_th_ss * b[2]),
            );
        }
    }

    #[allow(non_snake_case, clippy::too_many_arguments)]
    fn node(
        &self,
        disc: &Discretisation,
        state: &State,
        material: StepMaterial<'_>,
        actions: &Actions,
        k: usize,
        node: &NodeRows,
        lin: &mut Linearisation,
        sink: &mut Sink<'_>,
    ) {
        let B = &node.basis;
        let Bt = B.transpose();
        let first = &node.ends[0];
        let g1 = first.point;
        let row1 = 6 * g1;
        let p1 = &disc.points[g1];
        let length = self.patch_length[p1.patch];
        let shape1 = &disc.shapes[p1.shape];
        let modulus_scale = self.modulus_scale[p1.patch];
        let force_scale = modulus_scale * shape1.force.x;
        let moment_scale = modulus_scale * shape1.moment.y / length;
        // Equilibrium residual (spatial) and, per end and support control point, its 6×6 blocks in the local basis.
        let mut force = -actions.node_force[k];
        let mut moment = -actions.node_moment[k];
        struct EndTerms {
            /// ∂(σ R N)/∂δη,s and ∂(σ R N)/∂δΘ (spatial).
            n_eta_s: Mat3,
            n_th: Mat3,
            /// ∂(σ R M)/∂δΘ and ∂(σ R M)/∂δΘ,s.
            m_th: Mat3,
            m_th_s: Mat3,
        }
        let mut terms = Vec::with_capacity(node.ends.len());
        for e in &node.ends {
            let point = &disc.points[e.point];
            let law = material.law(e.point);
            let (CN, CM) = law.stiffness_matrices();
            let kin = kinematics(point, state, e.point);
            let stress = law.stress(&strains(point, state, e.point, &kin));
            let (N, M) = (stress.force, stress.moment);
            let K = state.kappa[e.point];
            let R = &state.rotation[e.point];
            force += R * N * e.sign;
            moment += R * M * e.sign;
            let sR = R * e.sign;
            terms.push(EndTerms {
                n_eta_s: sR * CN * R.transpose(),
                n_th: sR * (-hat(&N) + CN * hat(&kin.gamma)),
                m_th: sR * (-hat(&M) + CM * hat(&K)),
                m_th_s: sR * CM,
            });
        }
        let mut r = [0.0; 6];
        r[..3].copy_from_slice((Bt * force).as_slice());
        r[3..].copy_from_slice((Bt * moment).as_slice());
        let mut scale = [
            force_scale,
            force_scale,
            force_scale,
            moment_scale,
            moment_scale,
            moment_scale,
        ];
        // Kinematic rows for prescribed components.
        let prescribed = &actions.prescribed[k];
        let c1 = point_position(disc, &state.control, g1);
        let R1 = &state.rotation[g1];
        let phi = log(&Rot3::from_matrix_unchecked(
            R1 * node.rotation0.transpose(),
        ));
        let jl_inv = crate::math::so3::right_jacobian_inverse(&(-phi));
        for i in 0..6 {
            if let Some(value) = prescribed[i] {
                let axis = B.column(i % 3).into_owned();
                if i < 3 {
                    r[i] = axis.dot(&(c1 - node.position0)) - value;
                    scale[i] = length;
                } else {
                    r[i] = axis.dot(&phi) - value;
                    scale[i] = 1.0;
                }
            }
        }
        lin.residual[row1..row1 + 6].copy_from_slice(&r);
        lin.row_scale[row1..row1 + 6].copy_from_slice(&scale);
        // Continuity rows of the other ends.
        for e in &node.ends[1..] {
            let row = 6 * e.point;
            let ce = point_position(disc, &state.control, e.point);
            let Re = &state.rotation[e.point];
            let mismatch = log(&Rot3::from_matrix_unchecked(
                Re * (R1 * e.relative).transpose(),
            ));
            lin.residual[row..row + 3].copy_from_slice((ce - c1).as_slice());
            lin.residual[row + 3..row + 6].copy_from_slice(mismatch.as_slice());
            lin.row_scale[row..row + 3].fill(length);
            lin.row_scale[row + 3..row + 6].fill(1.0);
        }
        if matches!(sink, Sink::Discard) {
            return;
        }
        // Tangent of the rows of end 1: equilibrium blocks, with prescribed rows replaced.
        let kin_rows: [Option<nalgebra::RowVector3<Real>>; 6] = std::array::from_fn(|i| {
            prescribed[i].map(|_| {
                let axis = B.column(i % 3).transpose();
                if i < 3 { axis } else { axis * jl_inv * R1 }
            })
        });
        for (ei, (e, t)) in node.ends.iter().zip(&terms).enumerate() {
            let point = &disc.points[e.point];
            for (a, b) in point.basis.iter().enumerate() {
                let col = 6 * (point.first + a);
                let mut fe = Bt * t.n_eta_s * b[1];
                let mut ft = Bt * t.n_th * b[0];
                let mut me = Mat3::zeros();
                let mut mt = Bt * (t.m_th * b[0] + t.m_th_s * b[1]);
                for (i, kr) in kin_rows.iter().enumerate() {
                    let Some(kr) = kr else { continue };
                    let on_end = ei == 0 && a == first.end_basis;
                    let (row_eta, row_th) = if i < 3 {
                        (
                            if on_end {
                                *kr
                            } else {
                                nalgebra::RowVector3::zeros()
                            },
                            nalgebra::RowVector3::zeros(),
                        )
                    } else {
                        (
                            nalgebra::RowVector3::zeros(),
                            if on_end {
                                *kr
                            } else {
                                nalgebra::RowVector3::zeros()
                            },
                        )
                    };
                    if i < 3 {
                        fe.set_row(i, &row_eta);
                        ft.set_row(i, &row_th);
                    } else {
                        me.set_row(i - 3, &row_eta);
                        mt.set_row(i - 3, &row_th);
                    }
                }
                sink.block(row1, col, &fe);
                sink.block(row1, col + 3, &ft);
                sink.block(row1 + 3, col, &me);
                sink.block(row1 + 3, col + 3, &mt);
            }
        }
        // Continuity rows at the end control points: δη_e − δη_1, and for the rotation mismatch
        // r = log(E), E = R_e (R_1 Q_e)ᵀ, under spatial increments φ = R δΘ: E ← exp(φ̃_e) E exp(−φ̃_1), so
        // δr = J_l⁻¹(r) (R_e δΘ_e − E R_1 δΘ_1) (= R_e δΘ_e − R_1 δΘ_1 once continuity holds, r = 0).
        for e in &node.ends[1..] {
            let row = 6 * e.point;
            let ce = 6 * (disc.points[e.point].first + e.end_basis);
            let c1col = 6 * (p1.first + first.end_basis);
            let Re = state.rotation[e.point];
            let E = Re * (R1 * e.relative).transpose();
            let r = log(&Rot3::from_matrix_unchecked(E));
            let jl_inv = crate::math::so3::right_jacobian_inverse(&(-r));
            let id = Mat3::identity();
            let zero = Mat3::zeros();
            sink.block(row, ce, &id);
            sink.block(row, ce + 3, &zero);
            sink.block(row + 3, ce, &zero);
            sink.block(row + 3, ce + 3, &(jl_inv * Re));
            sink.block(row, c1col, &(-id));
            sink.block(row, c1col + 3, &zero);
            sink.block(row + 3, c1col, &zero);
            sink.block(row + 3, c1col + 3, &(-jl_inv * E * R1));
        }
    }
}

/// Kinematic quantities at a collocation point computed from the control points.
#[derive(Debug, Clone, Copy)]
struct Kinematics {
    gamma: Vec3,
    gamma_s: Vec3,
    c_ss: Vec3,
}

fn kinematics(point: &CollocationPoint, state: &State, g: usize) -> Kinematics {
    let (mut c_s, mut c_ss) = (Vec3::zeros(), Vec3::zeros());
    for (a, b) in point.basis.iter().enumerate() {
        let p = &state.control[point.first + a];
        c_s += p * b[1];
        c_ss += p * b[2];
    }
    let rt = state.rotation[g].transpose();
    let gamma = rt * c_s;
    let gamma_s = rt * c_ss - state.kappa[g].cross(&gamma);
    Kinematics {
        gamma,
        gamma_s,
        c_ss,
    }
}

/// The total strains `Γ_N = Γ − Γ0`, `K_M = K − K0` and their arc-length derivatives at collocation point `g`.
pub fn point_strains(disc: &Discretisation, state: &State, g: usize) -> SectionStrains {
    let point = &disc.points[g];
    strains(point, state, g, &kinematics(point, state, g))
}

/// The total strains at collocation point `g` from its kinematics `k`.
#[inline]
fn strains(point: &CollocationPoint, state: &State, g: usize, k: &Kinematics) -> SectionStrains {
    SectionStrains {
        force: k.gamma - point.gamma0,
        moment: state.kappa[g] - point.kappa0,
        force_ds: k.gamma_s - point.gamma0_s,
        moment_ds: state.kappa_s[g] - point.kappa0_s,
    }
}

/// The position `c = Σ N_j p_j` at collocation point `g`.
pub fn point_position(disc: &Discretisation, control: &[Vec3], g: usize) -> Vec3 {
    let point = &disc.points[g];
    point
        .basis
        .iter()
        .enumerate()
        .map(|(a, b)| control[point.first + a] * b[0])
        .sum()
}

/// Parts of each knot span in [`curve_length`]'s quadrature: 5-point Gauss–Legendre is exact for polynomials of
/// degree 9, and eight parts of a span of a smooth analysis spline bring the speed `|c'(u)|` (not a polynomial)
/// within round-off; the length only scales residuals, so any accuracy near that is enough.
const LENGTH_PARTS_PER_SPAN: usize = 8;

/// Arc length of a curve by 5-point Gauss–Legendre on [`LENGTH_PARTS_PER_SPAN`] parts of each knot span (used
/// only for residual scales).
fn curve_length(curve: &crate::math::NurbsCurve) -> Real {
    let breaks = curve.knots().breakpoints();
    breaks
        .windows(2)
        .flat_map(|w| arc_length_parts(curve, w[0], w[1], LENGTH_PARTS_PER_SPAN))
        .sum()
}

/// Arc length of `curve` from parameter `a` to `b`: 5-point Gauss–Legendre of the speed `|c'(u)|` on `parts`
/// equal parts (exact to round-off where the speed is smooth and the parts short).
pub(crate) fn arc_length_between(
    curve: &crate::math::NurbsCurve,
    a: Real,
    b: Real,
    parts: usize,
) -> Real {
    arc_length_parts(curve, a, b, parts).sum()
}

/// The arc lengths of `curve` over `parts` equal parts of `[a, b]`, in order ([`arc_length_between`]).
fn arc_length_parts(
    curve: &crate::math::NurbsCurve,
    a: Real,
    b: Real,
    parts: usize,
) -> impl Iterator<Item = Real> + '_ {
    let n = parts as Real;
    (0..parts).map(move |k| {
        let lo = a + (b - a) * k as Real / n;
        let hi = a + (b - a) * (k + 1) as Real / n;
        crate::geometry::analytic::gauss_legendre_5(lo, hi, |u| curve.derivatives(u, 1)[1].norm())
    })
}
