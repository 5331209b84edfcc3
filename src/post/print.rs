//! The device as one printable solid: the union of its wires (each patch's centreline swept by a ball of the
//! wire's radius, so the joints are filled with the balls at the wire ends), contoured on a grid
//! ([`crate::geometry::solid::union_surface`]), simplified within a tolerance
//! ([`crate::geometry::simplify::simplify`]) and stood upright on the build plate. What `stentkit mesh --print`
//! and `stentkit export --print` write (issue 19, item 1), where the tube meshes of the snapshots are one closed
//! body per rod, overlapping at the joints, which slicers and mesh-repair tools flag.
//!
//! **Resolution and volume.** The default grid spacing is a third of the thinnest wire's radius and the
//! default simplification tolerance a fiftieth of it (0.1 mm and 6 µm for the paper's 0.3 mm wires; a
//! printer's layers and nozzle are coarser). The contour's facets are chords of the tubes, 1.3 % short of a
//! capsule's volume at r/3; the simplification keeps the volume it is given, collapse by collapse. The
//! union's volume is estimated to second order from the contour and the exact normals at its vertices
//! ([`crate::geometry::solid::UnionSurface::volume_second_order`]: 1.4e-4 short of a capsule's at r/3), and
//! the simplified surface is given it by a uniform outward offset ([`offset_to_volume`]: 1.4 µm on the
//! straight stent, far below every feature). Measured on the straight stent: 343.1009 mm³ at a 0.1 mm grid,
//! 343.1033 mm³ at 0.06 mm, whose contours alone hold 339.97 and 342.02 mm³.
//!
//! **Placement.** The solid's axis (the principal direction of its vertices whose second moment is farthest
//! from the other two: a stent's axis, whether it is long or short) is turned to +z, the lowest point put on
//! z = 0 and the bounding box centred on the z axis: a stent stands on its end, where every layer crosses
//! wires at an angle (lying on its side, the layers tangent to its wires would print slivers).

use crate::geometry::mesh::TriangleMesh;
use crate::geometry::simplify::{SimplifyReport, simplify};
use crate::geometry::solid::{Capsule, offset_to_volume, union_surface};
use crate::math::{Mat3, Real, Rot3, Vec3};
use crate::model::Model;
use crate::post::device::device_rods;
use crate::solver::shape::PatchShape;

/// The grid spacing of a print solid, as a fraction of the thinnest wire's radius.
pub const DEFAULT_SPACING_PER_RADIUS: Real = 1.0 / 3.0;
/// The simplification tolerance of a print solid, as a fraction of the thinnest wire's radius.
pub const DEFAULT_TOLERANCE_PER_RADIUS: Real = 0.02;

/// How finely a print solid is made (lengths in the model's unit).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PrintSettings {
    /// Grid spacing; `None`: [`DEFAULT_SPACING_PER_RADIUS`] of the thinnest wire's radius.
    pub spacing: Option<Real>,
    /// Simplification tolerance; `None`: [`DEFAULT_TOLERANCE_PER_RADIUS`] of the thinnest wire's radius.
    pub tolerance: Option<Real>,
}

/// A print solid and how it was made.
#[derive(Debug, Clone)]
pub struct PrintSolid {
    /// The closed, 2-manifold surface, upright on z = 0.
    pub mesh: TriangleMesh,
    /// The grid spacing used.
    pub spacing: Real,
    /// The simplification tolerance used.
    pub tolerance: Real,
    /// The capsules united.
    pub capsules: usize,
    /// The simplification's counts.
    pub simplified: SimplifyReport,
    /// The contour's own volume, short of the union's by its chords.
    pub contour_volume: Real,
    /// The union's volume to second order in the grid spacing, which the solid is given
    /// ([`crate::geometry::solid::UnionSurface::volume_second_order`]).
    pub volume: Real,
    /// The outward offset that gave it.
    pub offset: Real,
}

impl PrintSolid {
    /// One line on how the solid was made, lengths in `unit`.
    pub fn describe(&self, unit: &str) -> String {
        format!(
            "print solid: union of {} capsules on a {:.4} {unit} grid, {} triangles simplified to {} within {:.2e} {unit}, given the union's volume to second order, {:.6e} {unit}³ (the contour's chords held {:.6e}: offset {:.2e} {unit} outward)",
            self.capsules,
            self.spacing,
            self.simplified.triangles_before,
            self.simplified.triangles_after,
            self.tolerance,
            self.volume,
            self.contour_volume,
            self.offset,
        )
    }
}

/// The capsules of the full device: every patch's polyline in `shapes` (mirrored about the model's symmetry
/// planes) with the radius of its section's drawing diameter.
pub fn device_capsules(model: &Model, shapes: &[PatchShape]) -> Vec<Capsule> {
    device_rods(model, shapes)
        .flat_map(|(patch, line)| {
            Capsule::along(&line, model.wire_radius(patch)).collect::<Vec<_>>()
        })
        .collect()
}

/// The full device of `model` in the shape `shapes` as one solid (see the module documentation).
pub fn print_solid(model: &Model, shapes: &[PatchShape], settings: &PrintSettings) -> PrintSolid {
    let capsules = device_capsules(model, shapes);
    let thinnest = capsules
        .iter()
        .map(|c| c.radius)
        .fold(Real::INFINITY, Real::min);
    let spacing = settings
        .spacing
        .unwrap_or(DEFAULT_SPACING_PER_RADIUS * thinnest);
    let tolerance = settings
        .tolerance
        .unwrap_or(DEFAULT_TOLERANCE_PER_RADIUS * thinnest);
    let contoured = union_surface(&capsules, spacing);
    let (mut mesh, simplified) = simplify(&contoured.mesh, tolerance);
    let volume = contoured.volume_second_order();
    let offset = offset_to_volume(&mut mesh, volume);
    stand_upright(&mut mesh);
    PrintSolid {
        mesh,
        spacing,
        tolerance,
        capsules: capsules.len(),
        simplified,
        contour_volume: contoured.mesh.volume(),
        volume,
        offset,
    }
}

/// Turns `mesh` so that its axis points along +z, then moves it onto z = 0, centred on the z axis (see the
/// module documentation). A rigid motion: the surface's shape, orientation and volume are unchanged.
pub fn stand_upright(mesh: &mut TriangleMesh) {
    let n = mesh.vertices.len();
    if n == 0 {
        return;
    }
    let mean = mesh.vertices.iter().sum::<Vec3>() / n as Real;
    let moment = mesh
        .vertices
        .iter()
        .map(|v| (v - mean) * (v - mean).transpose())
        .sum::<Mat3>()
        / n as Real;
    let eigen = moment.symmetric_eigen();
    let l = eigen.eigenvalues;
    let separation = |k: usize| {
        (0..3)
            .filter(|&j| j != k)
            .map(|j| (l[k] - l[j]).abs())
            .fold(Real::INFINITY, Real::min)
    };
    let k = (0..3)
        .max_by(|&a, &b| separation(a).total_cmp(&separation(b)))
        .unwrap_or(0);
    let axis: Vec3 = eigen.eigenvectors.column(k).into();
    let turn = Rot3::rotation_between(&axis, &Vec3::z())
        .unwrap_or_else(|| Rot3::from_axis_angle(&Vec3::x_axis(), std::f64::consts::PI));
    for v in &mut mesh.vertices {
        *v = turn * (*v - mean);
    }
    if let Some((lo, hi)) = mesh.bounding_box() {
        let shift = Vec3::new(-0.5 * (lo.x + hi.x), -0.5 * (lo.y + hi.y), -lo.z);
        for v in &mut mesh.vertices {
            *v += shift;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ring_and_a_rod_stand_on_their_axes() {
        // A short wide ring (axis along x: smallest moment) and a long thin rod (axis along y: largest
        // moment) both end up with their axis along z, standing on z = 0.
        let ring: Vec<Vec3> = (0..=48)
            .map(|k| {
                let a = k as Real / 48.0 * std::f64::consts::TAU;
                Vec3::new(0.0, 5.0 * a.cos(), 5.0 * a.sin())
            })
            .collect();
        let rod = [Vec3::new(1.0, -4.0, 2.0), Vec3::new(1.0, 4.0, 2.0)];
        for (line, height) in [(&ring[..], 0.6), (&rod[..], 8.6)] {
            let capsules: Vec<Capsule> = Capsule::along(line, 0.3).collect();
            let mut mesh = union_surface(&capsules, 0.1).mesh;
            let volume = mesh.volume();
            stand_upright(&mut mesh);
            let (lo, hi) = mesh.bounding_box().expect("not empty");
            assert!(lo.z.abs() < 1e-12, "on the plate: {lo}");
            assert!(
                (hi.z - height).abs() < 0.02,
                "height {} against {height}",
                hi.z
            );
            assert!((lo.x + hi.x).abs() < 1e-9 && (lo.y + hi.y).abs() < 1e-9);
            assert!((mesh.volume() - volume).abs() < 1e-9 * volume);
        }
    }
}
