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

pub(crate) use super::actions::{Actions, ReleaseRamp};
pub(crate) use super::discretisation::point_position;
use super::discretisation::{BasisRow, CollocationPoint, Discretisation};
use super::state::State;
use super::terms::{Coupled, EndLoad, InteriorLoad, PointView, Terms};
use crate::material::{ConstitutiveLaw, SectionLaw, SectionStrains};
use crate::math::so3::{hat, log};
use crate::math::{Mat3, Real, Rot3, Vec3};
use crate::model::Model;
use rayon::prelude::*;

/// Receives the tangent's entries in a fixed order: first to record the sparsity pattern, then to fill values.
pub(crate) enum Sink<'a> {
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

/// The constitutive data of one time step: the section law of every collocation point (from its patch's
/// material, [`crate::material::ConstitutiveLaw::section_law`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepMaterial<'a> {
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

/// Everything one assembly reads: the discrete problem, the iterate, the section laws of the step, the loads of
/// the instant and the terms beyond the rod ([`super::terms`]).
#[derive(Clone, Copy)]
pub(crate) struct Assembly<'a> {
    /// The discrete problem.
    pub disc: &'a Discretisation,
    /// The iterate.
    pub state: &'a State,
    /// The section law of every collocation point.
    pub material: StepMaterial<'a>,
    /// The loads and prescribed values of the instant.
    pub actions: &'a Actions,
    /// The point terms and constraints, in the order they add up.
    pub terms: Terms<'a>,
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
pub(crate) struct Assembler {
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

/// Tangent entries pushed by one interior collocation point: four 3×3 blocks per control point of its basis, and
/// two in the rotation columns of each of its patch's reference control points that the objective field's
/// reference rotation depends on and the basis does not hold ([`RotationBasis`]).
fn interior_entry_count(disc: &Discretisation, point: &CollocationPoint) -> usize {
    4 * 9 * point.basis.len() + 2 * 9 * references_outside(disc, point).len()
}

/// The objective rotation field's reference control points of `point`'s patch
/// ([`super::discretisation::PatchRange::references`], each once) that lie outside the point's basis: their
/// rotation columns take blocks of their own ([`RotationBasis`]). Empty for the incremental field.
fn references_outside(disc: &Discretisation, point: &CollocationPoint) -> Vec<usize> {
    if disc.rotations != crate::model::RotationField::Objective {
        return Vec::new();
    }
    let mut out: Vec<usize> = (disc.patches[point.patch].references().into_iter())
        .filter(|&r| r < point.first || r >= point.first + point.basis.len())
        .collect();
    out.dedup();
    out
}

/// Tangent and residual of one Newton iteration, and the row scales of the residual.
#[derive(Debug, Clone, Default)]
pub(crate) struct Linearisation {
    /// Residual vector (one entry per equation).
    pub residual: Vec<Real>,
    /// Dimensionless scale of each row (residual / scale is strain-like).
    pub row_scale: Vec<Real>,
    /// Seconds the last assembly spent in each point term's coupled loads ([`PointTerm::coupled`]), by the
    /// term's name, so the caller can count them apart (terms that have none are left out).
    pub coupled_seconds: Vec<(&'static str, Real)>,
}

impl Assembler {
    /// Prepares the node equations of `model` on `disc`.
    pub(crate) fn new(model: &Model, disc: &Discretisation) -> Self {
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
            .map(|p| model.materials()[p.material].reference_modulus())
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
                    interior_entry_count(disc, point)
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

    /// Assembles the residual into `lin` and the tangent into `sink` (entries in the pattern's order), with the
    /// point terms and constraints of `at.terms` ([`super::terms`]). With constraints the system has one more
    /// unknown (a multiplier, in `state.multipliers`) and equation per constraint equation, after the rod's.
    pub(crate) fn assemble(&self, at: &Assembly<'_>, lin: &mut Linearisation, sink: &mut Sink<'_>) {
        let disc = at.disc;
        let n = disc.num_unknowns();
        let m = at.terms.multipliers();
        lin.residual.resize(n + m, 0.0);
        lin.row_scale.resize(n + m, 1.0);
        // The coupled loads of the iterate (module docs of `super::terms`), their forces gathered per point.
        let coupled: Vec<Option<Coupled>> = if matches!(sink, Sink::Pattern(_)) {
            Vec::new()
        } else {
            let tangent = matches!(sink, Sink::Values { .. });
            lin.coupled_seconds.clear();
            (at.terms.point.iter())
                .map(|t| {
                    let start = std::time::Instant::now();
                    let loads = t.coupled(disc, at.state, tangent);
                    if loads.is_some() {
                        let seconds = start.elapsed().as_secs_f64();
                        lin.coupled_seconds.push((t.name(), seconds));
                    }
                    loads
                })
                .collect()
        };
        let mut extra: Vec<Option<Vec3>> = Vec::new();
        for c in coupled.iter().flatten() {
            extra.resize(disc.points.len(), None);
            for &(g, q) in &c.forces {
                *extra[g].get_or_insert_with(Vec3::zeros) += q;
            }
        }
        let extra = |g: usize| extra.get(g).copied().flatten();
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
                    self.interior(at, g, extra(g), residual, scale, &mut sink);
                    if let Sink::Values { values, next } = sink {
                        debug_assert_eq!(
                            next,
                            values.len(),
                            "interior_entry_count matches the pushes"
                        );
                    }
                });
        } else {
            for g in 0..disc.points.len() {
                if !disc.is_end(g) {
                    let rows = 6 * g..6 * g + 6;
                    let (residual, scale) =
                        (&mut lin.residual[rows.clone()], &mut lin.row_scale[rows]);
                    self.interior(at, g, extra(g), residual, scale, sink);
                }
            }
        }
        // Node rows.
        for (k, node) in self.nodes.iter().enumerate() {
            self.node(at, k, node, lin, sink);
        }
        self.constraints(at, lin, sink);
        self.coupled_blocks(at, &coupled, sink);
    }

    /// The coupled loads' tangent blocks `Rᵀ_g ∂q_g/∂c_k` in the force rows of `g` and the translation columns of
    /// `k`, term after term in the order of their coupling (module docs of [`super::terms`]); every entry of the
    /// coupling is pushed (zero where a term gave no block), so the pattern is the coupling's.
    fn coupled_blocks(&self, at: &Assembly<'_>, coupled: &[Option<Coupled>], sink: &mut Sink<'_>) {
        if matches!(sink, Sink::Discard) {
            return;
        }
        for (k, term) in at.terms.point.iter().enumerate() {
            let blocks = coupled.get(k).and_then(|c| c.as_ref()).map(|c| &c.blocks);
            for (e, &(g, c)) in term.coupling().iter().enumerate() {
                let block = match blocks.and_then(|b| b.get(e)) {
                    Some(b) => at.state.rotation[g].transpose() * b,
                    None => Mat3::zeros(),
                };
                sink.block(6 * g, 6 * c, &block);
            }
        }
    }

    /// The constraints' rows (`C_j`, rows `n + j`) and their multipliers' columns in the free translational rows
    /// of the constrained nodes (always emitted, zero where a component is prescribed, so the pattern does not
    /// depend on the conditions); module docs of [`super::terms`].
    fn constraints(&self, at: &Assembly<'_>, lin: &mut Linearisation, sink: &mut Sink<'_>) {
        let (disc, state) = (at.disc, at.state);
        let n = disc.num_unknowns();
        let mut row = n;
        for constraint in at.terms.constraints {
            for j in 0..constraint.len() {
                let lambda = state.multipliers.get(row - n).copied().unwrap_or(0.0);
                let mut c = 0.0;
                for &(k, a) in constraint.row(j) {
                    let node = &self.nodes[k];
                    let first = &node.ends[0];
                    let g1 = first.point;
                    let position = point_position(disc, &state.control, g1);
                    let origin = constraint.origin(k).unwrap_or(position);
                    c += a.dot(&(position - origin));
                    let local = node.basis.transpose() * a;
                    let col = 6 * (disc.points[g1].first + first.end_basis);
                    for i in 0..3 {
                        let free = at.actions.prescribed[k][i].is_none();
                        if free {
                            lin.residual[6 * g1 + i] -= lambda * local[i];
                        }
                        sink.push(6 * g1 + i, row, if free { -local[i] } else { 0.0 });
                    }
                    for i in 0..3 {
                        sink.push(row, col + i, a[i]);
                    }
                }
                lin.residual[row] = c;
                lin.row_scale[row] = constraint.scale();
                row += 1;
            }
        }
    }

    /// Per end of node `k`: `(σ R N, σ R M)` in the given state (see [`super::Simulation::node_end_resultants`]).
    #[allow(non_snake_case)]
    pub(crate) fn node_end_resultants(
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

    /// The balance laws `F`, `T` at interior collocation point `g` (module docs) with the point terms' loads and
    /// the coupled loads' force there (`coupled`), their row scales and, unless the sink discards them, their
    /// tangent blocks.
    #[allow(non_snake_case)]
    fn interior(
        &self,
        at: &Assembly<'_>,
        g: usize,
        coupled: Option<Vec3>,
        residual: &mut [Real],
        row_scale: &mut [Real],
        sink: &mut Sink<'_>,
    ) {
        let (disc, state) = (at.disc, at.state);
        let point = &disc.points[g];
        let law = at.material.law(g);
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
        let tangent = !matches!(sink, Sink::Discard);
        let view = PointView {
            disc,
            state,
            actions: at.actions,
            g,
            point,
            shape,
            rotation_t: Rt,
            tangent,
        };
        let mut load = InteriorLoad::default();
        for term in at.terms.point {
            term.interior(&view, &mut load);
        }
        if let Some(q) = coupled {
            load.add_force(q);
        }
        let nbar = Rt * load.force.unwrap_or_else(Vec3::zeros);
        let mbar = Rt * load.couple.unwrap_or_else(Vec3::zeros);
        let F = K.cross(&N) + N_s + nbar;
        let T = K.cross(&M)
            + M_s
            + k.gamma.cross(&N)
            + mbar
            + load.material_couple.unwrap_or_else(Vec3::zeros);
        let row = 6 * g;
        residual[..3].copy_from_slice(F.as_slice());
        residual[3..6].copy_from_slice(T.as_slice());
        let length = self.patch_length[point.patch];
        let modulus_scale = self.modulus_scale[point.patch];
        let force_scale = modulus_scale * shape.force.x / length;
        let moment_scale = modulus_scale * shape.moment.y / (length * length);
        row_scale[..3].fill(force_scale);
        row_scale[3..6].fill(moment_scale);
        if !tangent {
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
        let f_eta = load.force_position.unwrap_or_else(Mat3::zeros);
        if let Some(block) = load.force_rotation {
            f_th += block;
        }
        if let Some(block) = load.couple_rotation {
            t_th += block;
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
        let rotations = RotationBasis::at(disc, state, g);
        for (a, b) in point.basis.iter().enumerate() {
            let col = 6 * (point.first + a);
            let t_eta = match load.couple_position {
                Some(t_eta) => t_eta * b[0] + t_eta_s * b[1],
                None => t_eta_s * b[1],
            };
            sink.block(row, col, &(f_eta * b[0] + f_eta_s * b[1] + f_eta_ss * b[2]));
            sink.block(
                row,
                col + 3,
                &rotations.block(a, b, &f_th, Some(&f_th_s), None),
            );
            sink.block(row + 3, col, &t_eta);
            sink.block(
                row + 3,
                col + 3,
                &rotations.block(a, b, &t_th, Some(&t_th_s), Some(&t_th_ss)),
            );
        }
        for (r, m) in rotations.outside() {
            sink.block(row, 6 * r + 3, &combine(m, &f_th, Some(&f_th_s), None));
            let t = combine(m, &t_th, Some(&t_th_s), Some(&t_th_ss));
            sink.block(row + 3, 6 * r + 3, &t);
        }
    }

    /// The rows of node `k` (module docs): equilibrium or kinematic conditions in the rows of its first end,
    /// continuity in the rows of the others.
    fn node(
        &self,
        at: &Assembly<'_>,
        k: usize,
        node: &NodeRows,
        lin: &mut Linearisation,
        sink: &mut Sink<'_>,
    ) {
        let tangent = !matches!(sink, Sink::Discard);
        let ends = self.node_equilibrium(at, k, node, lin, tangent);
        self.continuity_residual(at, node, lin);
        if !tangent {
            return;
        }
        self.node_equilibrium_tangent(at, k, node, &ends, sink);
        self.continuity_tangent(at, node, sink);
    }

    /// The residual and row scales of the rows of node `k`'s first end: equilibrium `Bᵀ(Σ σ_e R_e N_e − f̄ − f)`,
    /// `Bᵀ(Σ σ_e R_e M_e − m̄ − m)` with the point terms' loads `f`, `m` on the ends, or the kinematic condition of
    /// a prescribed component. Returns per end what the tangent needs.
    #[allow(non_snake_case)]
    fn node_equilibrium(
        &self,
        at: &Assembly<'_>,
        k: usize,
        node: &NodeRows,
        lin: &mut Linearisation,
        tangent: bool,
    ) -> Vec<EndTerms> {
        let (disc, state) = (at.disc, at.state);
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
        // Equilibrium residual (spatial) and, per end, its derivatives (spatial).
        let mut force = -at.actions.node_force[k];
        let mut moment = -at.actions.node_moment[k];
        let mut terms = Vec::with_capacity(node.ends.len());
        for e in &node.ends {
            let point = &disc.points[e.point];
            let law = at.material.law(e.point);
            let (CN, CM) = law.stiffness_matrices();
            let kin = kinematics(point, state, e.point);
            let stress = law.stress(&strains(point, state, e.point, &kin));
            let (N, M) = (stress.force, stress.moment);
            let K = state.kappa[e.point];
            let R = &state.rotation[e.point];
            force += R * N * e.sign;
            moment += R * M * e.sign;
            let mut load = EndLoad::default();
            if !at.terms.point.is_empty() {
                let view = PointView {
                    disc,
                    state,
                    actions: at.actions,
                    g: e.point,
                    point,
                    shape: &disc.shapes[point.shape],
                    rotation_t: R.transpose(),
                    tangent,
                };
                for term in at.terms.point {
                    term.end(&view, &mut load);
                }
                if let Some(f) = load.force {
                    force -= f;
                }
                if let Some(m) = load.moment {
                    moment -= m;
                }
            }
            let sR = R * e.sign;
            terms.push(EndTerms {
                n_eta_s: sR * CN * R.transpose(),
                n_th: sR * (-hat(&N) + CN * hat(&kin.gamma)),
                m_th: sR * (-hat(&M) + CM * hat(&K)),
                m_th_s: sR * CM,
                load,
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
        let prescribed = &at.actions.prescribed[k];
        let c1 = point_position(disc, &state.control, g1);
        let phi = node.rotation_vector(state);
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
        terms
    }

    /// The tangent of the rows of node `k`'s first end: equilibrium blocks per end and support control point,
    /// with the rows of prescribed components replaced by their kinematic conditions.
    #[allow(non_snake_case)]
    fn node_equilibrium_tangent(
        &self,
        at: &Assembly<'_>,
        k: usize,
        node: &NodeRows,
        ends: &[EndTerms],
        sink: &mut Sink<'_>,
    ) {
        let (disc, state) = (at.disc, at.state);
        let B = &node.basis;
        let Bt = B.transpose();
        let first = &node.ends[0];
        let row1 = 6 * first.point;
        let prescribed = &at.actions.prescribed[k];
        let R1 = &state.rotation[first.point];
        let jl_inv = crate::math::so3::right_jacobian_inverse(&(-node.rotation_vector(state)));
        let kin_rows: [Option<nalgebra::RowVector3<Real>>; 6] = std::array::from_fn(|i| {
            prescribed[i].map(|_| {
                let axis = B.column(i % 3).transpose();
                if i < 3 { axis } else { axis * jl_inv * R1 }
            })
        });
        let zero_row = nalgebra::RowVector3::zeros();
        for (ei, (e, t)) in node.ends.iter().zip(ends).enumerate() {
            let point = &disc.points[e.point];
            let rotations = RotationBasis::at(disc, state, e.point);
            for (a, b) in point.basis.iter().enumerate() {
                let col = 6 * (point.first + a);
                let mut fe = Bt * t.n_eta_s * b[1];
                let mut ft = rotations.block(a, b, &(Bt * t.n_th), None, None);
                let mut me = Mat3::zeros();
                let mut mt = Bt * rotations.block(a, b, &t.m_th, Some(&t.m_th_s), None);
                // The point terms' loads on the node, `−Bᵀ ∂(f, m)/∂(c, δΘ)` times the basis value (its rotation
                // matrix for the rotation columns).
                let load = &t.load;
                if let Some(block) = load.force_position {
                    fe -= Bt * (block * b[0]);
                }
                if let Some(block) = load.force_rotation {
                    ft -= Bt * rotations.block(a, b, &block, None, None);
                }
                if let Some(block) = load.moment_position {
                    me -= Bt * (block * b[0]);
                }
                if let Some(block) = load.moment_rotation {
                    mt -= Bt * rotations.block(a, b, &block, None, None);
                }
                for (i, kr) in kin_rows.iter().enumerate() {
                    let Some(kr) = kr else { continue };
                    let on_end = ei == 0 && a == first.end_basis;
                    let row = if on_end { *kr } else { zero_row };
                    if i < 3 {
                        fe.set_row(i, &row);
                        ft.set_row(i, &zero_row);
                    } else {
                        me.set_row(i - 3, &zero_row);
                        mt.set_row(i - 3, &row);
                    }
                }
                sink.block(row1, col, &fe);
                sink.block(row1, col + 3, &ft);
                sink.block(row1 + 3, col, &me);
                sink.block(row1 + 3, col + 3, &mt);
            }
            // The objective field's reference control points outside the end's support: rotation columns only,
            // and zero in the kinematic rows (they hold the end's own control point).
            for (r, m) in rotations.outside() {
                let mut ft = combine(m, &(Bt * t.n_th), None, None);
                let mut mt = Bt * combine(m, &t.m_th, Some(&t.m_th_s), None);
                if let Some(block) = t.load.force_rotation {
                    ft -= Bt * combine(m, &block, None, None);
                }
                if let Some(block) = t.load.moment_rotation {
                    mt -= Bt * combine(m, &block, None, None);
                }
                for (i, kr) in kin_rows.iter().enumerate() {
                    match (kr, i < 3) {
                        (None, _) => {}
                        (Some(_), true) => ft.set_row(i, &zero_row),
                        (Some(_), false) => mt.set_row(i - 3, &zero_row),
                    }
                }
                sink.block(row1, 6 * r + 3, &ft);
                sink.block(row1 + 3, 6 * r + 3, &mt);
            }
        }
    }

    /// The residual and row scales of the continuity rows of node `node`'s other ends: `c_e − c_1` and the
    /// rotation mismatch `log(R_e (R_1 Q_e)ᵀ)`.
    #[allow(non_snake_case)]
    fn continuity_residual(&self, at: &Assembly<'_>, node: &NodeRows, lin: &mut Linearisation) {
        let (disc, state) = (at.disc, at.state);
        let g1 = node.ends[0].point;
        let length = self.patch_length[disc.points[g1].patch];
        let c1 = point_position(disc, &state.control, g1);
        let R1 = &state.rotation[g1];
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
    }

    /// The tangent of the continuity rows at the end control points: `δη_e − δη_1`, and for the rotation
    /// mismatch `r = log(E)`, `E = R_e (R_1 Q_e)ᵀ`, under spatial increments `φ = R δΘ`: `E ← exp(φ̃_e) E
    /// exp(−φ̃_1)`, so `δr = J_l⁻¹(r) (R_e δΘ_e − E R_1 δΘ_1)` (`= R_e δΘ_e − R_1 δΘ_1` once continuity holds,
    /// `r = 0`).
    #[allow(non_snake_case)]
    fn continuity_tangent(&self, at: &Assembly<'_>, node: &NodeRows, sink: &mut Sink<'_>) {
        let (disc, state) = (at.disc, at.state);
        let first = &node.ends[0];
        let p1 = &disc.points[first.point];
        let R1 = &state.rotation[first.point];
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

/// What a collocation point's rotation increment and its derivatives are in the rotation unknowns of its control
/// points (and, with the objective field, of the one or two control points its patch's reference rotation is
/// made of): `δΘ = Σ_a B_a δθ_a`,
/// `δΘ,s = Σ_a B_a,s δθ_a`, `δΘ,ss = Σ_a B_a,ss δθ_a` — the basis values times the identity for the paper's
/// incremental field; for the objective field (`crate::math::quaternion_field`, *Linearisation*; `R = P R0`
/// with `P` the field of the control points' rotations from the reference, each turned by `R0_a δθ_a`), with
/// `X_a` the field's matrices (`Y` for the reference) and `R0`, `K0`, `K0,s` the point's reference:
/// ```text
/// B_a = R0ᵀ X_a R0_a,   B_a,s = R0ᵀ X_a,s R0_a − K̂0 B_a,
/// B_a,ss = R0ᵀ X_a,ss R0_a − 2 K̂0 R0ᵀ X_a,s R0_a + (K̂0 K̂0 − K̂0,s) B_a
/// ```
/// (`(R0ᵀ),s = −K̂0 R0ᵀ`). At a patch end `B_a` is the identity for the end's own control point and zero for the
/// others and the reference, as in the incremental field, so the node rows' kinematic and continuity blocks are
/// the same.
enum RotationBasis {
    /// The paper's field: the basis rows themselves.
    Incremental,
    /// The objective field: `[B_a, B_a,s, B_a,ss]` per control point of the support and, for each of the
    /// patch's reference control points outside it ([`references_outside`], in that order), its global index
    /// and matrices.
    Objective {
        support: Vec<[Mat3; 3]>,
        reference: Vec<(usize, [Mat3; 3])>,
    },
}

impl RotationBasis {
    /// The matrices of collocation point `g` at `state`.
    fn at(disc: &Discretisation, state: &State, g: usize) -> Self {
        if state.orientation.is_empty() {
            return Self::Incremental;
        }
        let point = &disc.points[g];
        let thetas = &state.relative[point.first..point.first + point.basis.len()];
        let theta = crate::math::quaternion_field::interpolate(thetas, &point.basis);
        let (x, y) = crate::math::quaternion_field::rotation_basis(&theta, thetas, &point.basis);
        let r0t = point.rotation0.transpose();
        let k0 = hat(&point.kappa0);
        let k0k0 = k0 * k0 - hat(&point.kappa0_s);
        let to_unknowns = |[x0, x1, x2]: [Mat3; 3], a: usize| {
            let r0a = &disc.points[a].rotation0;
            let b0 = r0t * x0 * r0a;
            let y1 = r0t * x1 * r0a;
            [b0, y1 - k0 * b0, r0t * x2 * r0a - k0 * y1 * 2.0 + k0k0 * b0]
        };
        // The reference rotation turns by `A_m v_m + A_m+1 v_m+1`: `Y A_m` and `Y A_m+1` are those points'.
        let range = &disc.patches[point.patch];
        let middle = range.references();
        let (_, a) = crate::math::quaternion_field::reference_rotation(
            &state.orientation[middle[0]],
            &state.orientation[middle[1]],
        );
        let mut support: Vec<[Mat3; 3]> = (x.into_iter().enumerate())
            .map(|(a, xa)| to_unknowns(xa, point.first + a))
            .collect();
        let mut reference: Vec<(usize, [Mat3; 3])> = Vec::new();
        for (r, am) in middle.into_iter().zip(a) {
            let b = to_unknowns(y.map(|m| m * am), r);
            let target = if (point.first..point.first + support.len()).contains(&r) {
                &mut support[r - point.first]
            } else if let Some((_, m)) = reference.iter_mut().find(|(q, _)| *q == r) {
                m
            } else {
                reference.push((r, [Mat3::zeros(); 3]));
                &mut reference.last_mut().expect("just pushed").1
            };
            for (m, bm) in target.iter_mut().zip(b) {
                *m += bm;
            }
        }
        Self::Objective { support, reference }
    }

    /// The block in control point `a`'s rotation columns (basis row `b`) of a row whose coefficients of `δΘ`,
    /// `δΘ,s` and `δΘ,ss` are `x0`, `x1`, `x2`: `x0 B_a + x1 B_a,s + x2 B_a,ss`.
    #[inline]
    fn block(
        &self,
        a: usize,
        b: &BasisRow,
        x0: &Mat3,
        x1: Option<&Mat3>,
        x2: Option<&Mat3>,
    ) -> Mat3 {
        match self {
            Self::Incremental => {
                let mut m = x0 * b[0];
                if let Some(x1) = x1 {
                    m += x1 * b[1];
                }
                if let Some(x2) = x2 {
                    m += x2 * b[2];
                }
                m
            }
            Self::Objective { support, .. } => combine(&support[a], x0, x1, x2),
        }
    }

    /// The objective field's reference control points outside the support: each one's global index and
    /// `[B, B,s, B,ss]` (rows combine them with [`combine`], as [`RotationBasis::block`] does).
    fn outside(&self) -> impl Iterator<Item = (usize, &[Mat3; 3])> {
        let reference: &[(usize, [Mat3; 3])] = match self {
            Self::Objective { reference, .. } => reference,
            Self::Incremental => &[],
        };
        reference.iter().map(|(r, m)| (*r, m))
    }
}

/// `x0 B + x1 B,s + x2 B,ss` for `[B, B,s, B,ss]`.
#[inline]
fn combine(b: &[Mat3; 3], x0: &Mat3, x1: Option<&Mat3>, x2: Option<&Mat3>) -> Mat3 {
    let mut m = x0 * b[0];
    if let Some(x1) = x1 {
        m += x1 * b[1];
    }
    if let Some(x2) = x2 {
        m += x2 * b[2];
    }
    m
}

/// Per end of a node, the derivatives of its equilibrium terms (spatial) and the point terms' load on it.
struct EndTerms {
    /// ∂(σ R N)/∂δη,s and ∂(σ R N)/∂δΘ.
    n_eta_s: Mat3,
    n_th: Mat3,
    /// ∂(σ R M)/∂δΘ and ∂(σ R M)/∂δΘ,s.
    m_th: Mat3,
    m_th_s: Mat3,
    /// The point terms' concentrated load through this end.
    load: EndLoad,
}

impl NodeRows {
    /// The rotation of the node's first end from its reference, `φ` with `R_1 = exp(φ̃) R_1⁰` (spatial).
    fn rotation_vector(&self, state: &State) -> Vec3 {
        let r1 = &state.rotation[self.ends[0].point];
        log(&Rot3::from_matrix_unchecked(
            r1 * self.rotation0.transpose(),
        ))
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
pub(crate) fn point_strains(disc: &Discretisation, state: &State, g: usize) -> SectionStrains {
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

/// Parts per interval between collocation points in the arc-length quadrature (5-point Gauss–Legendre each):
/// the reference speed `|c0'(u)|` is smooth there, so the arc length is exact to round-off.
pub(crate) const ARC_LENGTH_PARTS: usize = 4;

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
