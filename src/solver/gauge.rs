//! Gauge constraints: fixing the rigid-body motion of a device that a programme's release leaves free.
//!
//! Before the release the driven nodes are held, so the device cannot move as a rigid body. After it, a stent
//! is a free body loaded only by itself: its deformation is determined, its rigid placement is not, and the
//! tangent is singular along the rigid modes that the symmetry planes leave (a quarter model of a straight
//! device: the axial translation; a half model: two translations in the plane and the rotation about its
//! normal; a full model: all six). We fix exactly those modes by Lagrange multipliers on the driven nodes, the
//! rigid part of their motion being frozen at its value at the release (a Tisserand frame):
//! ```text
//! C_t = Σ_l w_l t · (c_l − c_l^rel) = 0            for every allowed translation direction t
//! C_ω = Σ_l w_l ω · ((X_l − X̄) × (c_l − c_l^rel)) = 0 for every allowed rotation axis ω
//! ```
//! with `w_l` the number of full-device nodes node `l` stands for, `X_l` its reference position and `X̄` their
//! weighted centroid. Allowed translations are orthogonal to every symmetry normal; a rotation is allowed only
//! about the normal of a single symmetry plane (a mirror-symmetric displacement field has no other rigid part).
//! The multipliers enter the free force components of the driven nodes' equilibrium rows as `−λ a_l`; for a
//! self-equilibrated device their converged values are zero (sum the equilibrium rows: `λ Σ w_l = 0`), so the
//! constraints fix the placement without changing the deformation.
//!
//! A device programmed by a crimper (`crate::model::ProgrammeKind::Crimp`) is free from the start: nothing
//! holds it but contact, which fixes no rigid mode along the crimper's axis; its gauge acts from the first step,
//! freezing the reference placement.
//!
//! The gauge is a [`Constraint`] ([`crate::solver::terms`]): the assembly writes its rows and the multipliers'
//! forces; the simulation builds it at the release and keeps its frozen positions (in its checkpoints too).

use crate::math::{Real, Vec3};
use crate::model::Model;
use crate::solver::terms::Constraint;

/// One constraint: per driven node, the coefficient vector `a_l` on its displacement.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct GaugeRow {
    /// `(node index, a_l)`.
    pub terms: Vec<(usize, Vec3)>,
}

/// The active gauge constraints and the positions they freeze.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Gauge {
    /// The constraints (one extra unknown and equation each).
    pub rows: Vec<GaugeRow>,
    /// Positions of the constrained nodes at the release, `c_l^rel`, by node index.
    pub frozen: Vec<(usize, Vec3)>,
    /// Row scale of the constraint equations \[length\].
    pub scale: Real,
}

/// A unit vector whose projection off the vectors already spanned is shorter than this is taken as dependent on
/// them (Gram–Schmidt in [`complement`]). Symmetry normals are either parallel (the same plane given twice,
/// projections at round-off, ~1e-16) or at a stent's sector angle (at least a few degrees, projections ≳ 0.05):
/// 1e-8 separates the two with margins of eight orders and more.
const DEPENDENT: Real = 1e-8;

/// Unit vectors spanning the orthogonal complement of `normals` (Gram–Schmidt: the normals first, then the
/// global axes against them; vectors shorter than [`DEPENDENT`] after projection are dependent).
fn complement(normals: &[Vec3]) -> Vec<Vec3> {
    let mut spanned: Vec<Vec3> = Vec::new();
    for n in normals {
        let w = spanned.iter().fold(*n, |w, q| w - q * q.dot(&w));
        if w.norm() > DEPENDENT {
            spanned.push(w.normalize());
        }
    }
    let mut basis = Vec::new();
    for axis in [Vec3::x(), Vec3::y(), Vec3::z()] {
        let w = spanned
            .iter()
            .chain(&basis)
            .fold(axis, |w, q: &Vec3| w - q * q.dot(&w));
        if w.norm() > DEPENDENT {
            basis.push(w.normalize());
        }
    }
    basis
}

impl Gauge {
    /// The constraints for the model's driven nodes, freezing the given current positions (`positions[k]` is
    /// the position of node `k`). `None` when the model has no programme.
    pub(crate) fn new(model: &Model, positions: &[Vec3], length_scale: Real) -> Option<Self> {
        let programme = model.programme.as_ref()?;
        let normals: Vec<Vec3> = model
            .symmetry_planes
            .iter()
            .map(|(_, n)| n.normalize())
            .collect();
        let translations = complement(&normals);
        let rotations: Vec<Vec3> = match normals.len() {
            0 => vec![Vec3::x(), Vec3::y(), Vec3::z()],
            1 => vec![normals[0]],
            _ => Vec::new(),
        };
        let total: Real = programme.nodes.iter().map(|d| d.weight).sum();
        if total <= 0.0 {
            return None;
        }
        let centroid = programme
            .nodes
            .iter()
            .map(|d| d.position * d.weight)
            .sum::<Vec3>()
            / total;
        let mut rows = Vec::new();
        for t in &translations {
            rows.push(GaugeRow {
                terms: programme
                    .nodes
                    .iter()
                    .map(|d| (d.node, t * (d.weight / total)))
                    .collect(),
            });
        }
        for w in &rotations {
            rows.push(GaugeRow {
                terms: programme
                    .nodes
                    .iter()
                    .map(|d| {
                        (
                            d.node,
                            w.cross(&(d.position - centroid)) * (d.weight / total / length_scale),
                        )
                    })
                    .collect(),
            });
        }
        let frozen = programme
            .nodes
            .iter()
            .map(|d| (d.node, positions[d.node]))
            .collect();
        Some(Self {
            rows,
            frozen,
            scale: length_scale,
        })
    }
}

impl Constraint for Gauge {
    fn name(&self) -> &'static str {
        "gauge"
    }

    fn len(&self) -> usize {
        self.rows.len()
    }

    fn row(&self, j: usize) -> &[(usize, Vec3)] {
        &self.rows[j].terms
    }

    fn origin(&self, node: usize) -> Option<Vec3> {
        self.frozen
            .iter()
            .find(|(l, _)| *l == node)
            .map(|(_, x)| *x)
    }

    fn scale(&self) -> Real {
        self.scale
    }
}
