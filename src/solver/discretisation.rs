//! The discrete problem's fixed data: collocation points (Greville abscissae) per patch, basis tables in
//! arc-length derivatives at each point, the reference kinematics there (`R0, Γ0, Γ0,s, K0, K0,s`), section
//! stiffness shapes, and the global numbering of unknowns and equations.
//!
//! Numbering: the control points of all patches are numbered consecutively (patch by patch); control point
//! `g` owns unknowns `6g .. 6g+3` (`δη`, translation) and `6g+3 .. 6g+6` (`δθ`, material rotation).
//! Collocation point `g` (there is one per control point) owns equations `6g .. 6g+6`: force then moment
//! balance at interior points; at patch ends, the rows of the node the end belongs to (DESIGN §4 "Joints").

use super::SolverError;
use crate::geometry::frame::{FrameField, FrameSettings};
use crate::material::{ConstitutiveLaw, SectionShape};
use crate::math::basis::nurbs_basis;
use crate::math::{Mat3, Real, Vec3};
use crate::model::{End, Model, PatchEnd, RotationField};

/// Basis values at one collocation point for one control point: `N`, `N,s`, `N,ss` (arc-length derivatives).
pub(crate) type BasisRow = [Real; 3];

/// One collocation point: where it is, its basis table and the reference kinematics.
#[derive(Debug, Clone, PartialEq)]
pub struct CollocationPoint {
    /// Curve parameter (a Greville abscissa).
    pub u: Real,
    /// Global index of the first control point with a non-zero basis function here.
    pub first: usize,
    /// `[N, N,s, N,ss]` of control points `first ..= first + p`.
    pub basis: Vec<BasisRow>,
    /// Reference rotation `R0`.
    pub rotation0: Mat3,
    /// Reference strain `Γ0 = R0ᵀ c0,s` (computed from the same basis table as the current strain, so the
    /// unloaded reference has exactly zero strain).
    pub gamma0: Vec3,
    /// `Γ0,s = R0ᵀ c0,ss − K0 × Γ0`.
    pub gamma0_s: Vec3,
    /// Reference curvature `K0`.
    pub kappa0: Vec3,
    /// `K0,s`.
    pub kappa0_s: Vec3,
    /// Index into [`Discretisation::shapes`]: the shape of its patch's section and material.
    pub shape: usize,
    /// Index of the patch.
    pub patch: usize,
}

/// One patch's slice of the global numbering.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchRange {
    /// Global index of the first control (and collocation) point.
    pub offset: usize,
    /// Number of control points `n`.
    pub n: usize,
    /// Degree `p`.
    pub degree: usize,
}

impl PatchRange {
    /// The global indices of the control points whose rotations make the patch's reference rotation for the
    /// objective rotation field: its middle one twice, or its two middle ones for an even count — the same pair
    /// whichever end the patch starts from (`crate::math::quaternion_field`, *The reference*).
    pub fn references(&self) -> [usize; 2] {
        let m = self.offset + (self.n - 1) / 2;
        [m, self.offset + self.n / 2]
    }

    /// The global index of the collocation (= control) point at a patch end.
    pub fn end_point(&self, end: End) -> usize {
        match end {
            End::Start => self.offset,
            End::End => self.offset + self.n - 1,
        }
    }
}

/// The fixed discrete data of a model.
#[derive(Debug, Clone)]
pub struct Discretisation {
    /// Per patch, its numbering.
    pub patches: Vec<PatchRange>,
    /// All collocation points, globally numbered.
    pub points: Vec<CollocationPoint>,
    /// Section stiffness shapes, one per model material and section: material `m`, section `s` at
    /// `m · sections + s` ([`Discretisation::shape_index`]).
    pub shapes: Vec<SectionShape>,
    /// Reference control points, globally numbered.
    pub control0: Vec<Vec3>,
    /// How the section rotations are represented (the model's solver settings; [`super::state::State`]).
    pub rotations: RotationField,
    /// A length scale of the model (bounding-box diagonal) used to normalise norms \[length\].
    pub length_scale: Real,
}

impl Discretisation {
    /// The control points the objective rotation field's patch references are made of
    /// ([`PatchRange::references`], each once): every row of their patch reaches their rotation columns, so the
    /// block solver puts them on its border. Empty for the incremental field.
    pub fn reference_points(&self) -> Vec<usize> {
        if self.rotations != RotationField::Objective {
            return Vec::new();
        }
        let mut out: Vec<usize> = self.patches.iter().flat_map(|r| r.references()).collect();
        out.dedup();
        out
    }

    /// Builds the collocation points, basis tables and reference kinematics of every patch.
    pub fn new(model: &Model) -> Result<Self, SolverError> {
        let shapes = model
            .materials()
            .iter()
            .flat_map(|law| model.sections.iter().map(|s| law.section_shape(s)))
            .collect();
        let mut patches = Vec::with_capacity(model.patches.len());
        let mut points = Vec::with_capacity(model.num_collocation_points());
        let mut control0 = Vec::with_capacity(model.num_collocation_points());
        for (k, patch) in model.patches.iter().enumerate() {
            assert!(
                patch.material < model.materials().len(),
                "patch `{}` refers to material {} of {}",
                patch.name,
                patch.material,
                model.materials().len()
            );
            let shape = Self::shape_index(model, patch.material, patch.section);
            let curve = &patch.curve;
            let offset = control0.len();
            let p = curve.degree();
            let n = curve.num_points();
            patches.push(PatchRange {
                offset,
                n,
                degree: p,
            });
            control0.extend_from_slice(curve.points());
            let frames = FrameField::rotation_minimising(
                curve,
                patch.normal_hint,
                &FrameSettings::default(),
            )
            .map_err(|e| SolverError::Geometry {
                patch: patch.name.clone(),
                source: e,
            })?;
            for u in curve.knots().greville() {
                let frame = frames.at(curve, u).map_err(|e| SolverError::Geometry {
                    patch: patch.name.clone(),
                    source: e,
                })?;
                let table = nurbs_basis(curve.knots(), curve.weights(), u, 2);
                let (j, jp) = (frame.jacobian, frame.jacobian_u);
                let basis: Vec<BasisRow> = (0..=p)
                    .map(|a| {
                        let (d0, d1, d2) = (table.ders[0][a], table.ders[1][a], table.ders[2][a]);
                        [d0, d1 / j, (d2 - jp / j * d1) / (j * j)]
                    })
                    .collect();
                let first = offset + table.first;
                let (mut c_s, mut c_ss) = (Vec3::zeros(), Vec3::zeros());
                for (a, row) in basis.iter().enumerate() {
                    c_s += control0[first + a] * row[1];
                    c_ss += control0[first + a] * row[2];
                }
                let r0t = frame.rotation.transpose();
                let gamma0 = r0t * c_s;
                let gamma0_s = r0t * c_ss - frame.curvature.cross(&gamma0);
                points.push(CollocationPoint {
                    u,
                    first,
                    basis,
                    rotation0: frame.rotation,
                    gamma0,
                    gamma0_s,
                    kappa0: frame.curvature,
                    kappa0_s: frame.curvature_s,
                    shape,
                    patch: k,
                });
            }
        }
        let (mut lo, mut hi) = (
            Vec3::repeat(Real::INFINITY),
            Vec3::repeat(Real::NEG_INFINITY),
        );
        for q in &control0 {
            lo = lo.inf(q);
            hi = hi.sup(q);
        }
        let length_scale = (hi - lo).norm().max(Real::MIN_POSITIVE);
        Ok(Self {
            patches,
            points,
            shapes,
            control0,
            rotations: model.solver().rotations,
            length_scale,
        })
    }

    /// The index into [`Discretisation::shapes`] of material `material` and section `section` of `model`.
    pub fn shape_index(model: &Model, material: usize, section: usize) -> usize {
        material * model.sections.len() + section
    }

    /// Number of unknowns (= equations).
    pub fn num_unknowns(&self) -> usize {
        6 * self.points.len()
    }

    /// The global collocation point at a patch end.
    pub fn end_point(&self, end: PatchEnd) -> usize {
        self.patches[end.patch].end_point(end.end)
    }

    /// True when collocation point `g` is the first or last of its patch.
    pub fn is_end(&self, g: usize) -> bool {
        let r = &self.patches[self.points[g].patch];
        g == r.offset || g == r.offset + r.n - 1
    }
}

/// The position `c = Σ N_j p_j` at collocation point `g`.
pub(crate) fn point_position(disc: &Discretisation, control: &[Vec3], g: usize) -> Vec3 {
    let point = &disc.points[g];
    point
        .basis
        .iter()
        .enumerate()
        .map(|(a, b)| control[point.first + a] * b[0])
        .sum()
}

/// The increment `delta` of the solver's unknowns (six per control point, the translation first) at collocation
/// point `g`: its translation `Σ N_a δp_a` and rotation `Σ N_a δθ_a` (basis values `N_a`).
pub(crate) fn point_increment(disc: &Discretisation, delta: &[Real], g: usize) -> (Vec3, Vec3) {
    let point = &disc.points[g];
    let (mut dx, mut theta) = (Vec3::zeros(), Vec3::zeros());
    for (a, row) in point.basis.iter().enumerate() {
        let j = 6 * (point.first + a);
        dx += Vec3::new(delta[j], delta[j + 1], delta[j + 2]) * row[0];
        theta += Vec3::new(delta[j + 3], delta[j + 4], delta[j + 5]) * row[0];
    }
    (dx, theta)
}
