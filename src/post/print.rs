//! The device as one printable solid: the union of its wires (each patch's centreline swept by a ball of the
//! wire's radius, so the joints are filled with the balls at the wire ends), contoured on a grid
//! ([`crate::geometry::solid::union_surface`]), simplified within a tolerance
//! (`crate::geometry::simplify::simplify`) and stood upright on the build plate. What `stentkit mesh --print`
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
use crate::geometry::solid::{
    Capsule, ContourSize, WireSize, estimated_contour, offset_to_volume, union_surface,
};
use crate::math::{Mat3, Real, Rot3, Short, Vec3};
use crate::model::Model;
use crate::post::device::{device_rods, patch_sizes};
use crate::solver::shape::PatchShape;

/// The grid spacing of a print solid, as a fraction of the thinnest wire's radius.
pub const DEFAULT_SPACING_PER_RADIUS: Real = 1.0 / 3.0;
/// The simplification tolerance of a print solid, as a fraction of the thinnest wire's radius.
pub const DEFAULT_TOLERANCE_PER_RADIUS: Real = 0.02;

/// The coarsest grid spacing of a print solid, as a fraction of the thinnest wire's radius: 1. Every point
/// of space lies within `√3 h / 2 < r` of a grid point, so a wire of radius `r ≥ h` holds grid points all along
/// and is contoured; on a coarser grid a wire can fall between the grid points and vanish (`--grid 1e9` made
/// an empty solid).
pub const MAX_SPACING_PER_RADIUS: Real = 1.0;

/// The largest simplification tolerance of a print solid, as a fraction of the thinnest wire's radius: 1/4
/// (12.5 times the default). A wire's section then stays a polygon of at least five sides (a side's sagitta
/// `r (1 − cos π/m)` is at most r/4 for m ≥ 5); a tolerance of the order of the radius lets the collapses
/// flatten a wire, and one beyond the gaps between the wires lets them join wires
/// (`crate::geometry::simplify` is meant for tolerances far below both). Measured on the straight stent
/// (r = 0.3 mm, processor time, with the sequential simplifier before 2026-11-28): the default r/50 gave
/// 152 836 triangles in 22.9 s, r/10 17 306 in 24.9 s, r/4 5370 in 25.6 s, r/2 2450 and r 1454 in 27 s;
/// `--deviation 1e9` had not finished after 15 minutes.
pub const MAX_TOLERANCE_PER_RADIUS: Real = 0.25;

/// Peak memory of a print solid per triangle of its contour \[bytes\]: the contour's vertices, normals and
/// edge-to-vertex map, the simplification's quadrics, edges and queue, and the output. With [`BASE_BYTES`]
/// fitted (and [`BYTES_PER_BAND_POINT`] held) to the peak resident memory of `stentkit mesh --print` on the
/// straight stent, 2026-11-28: 221, 394, 655 MB and 1.34 GB at h = r/2, r/3, r/4 and r/6 (0.89, 2.02, 3.60 and
/// 8.12 million triangles); the estimate gives 236, 395, 628 MB and 1.34 GB (within 7 %).
pub const BYTES_PER_CONTOUR_TRIANGLE: Real = 105.0;

/// Peak memory of a print solid that does not grow with its grid \[bytes\]: the process, the design and the
/// device's shapes (fitted with [`BYTES_PER_CONTOUR_TRIANGLE`]).
pub const BASE_BYTES: Real = 111e6;

/// Peak memory of a print solid per grid point sampled \[bytes\]: an entry of the sampled field (a point, its
/// distance and capsule: 40 bytes) in a hash map filled to at most 7/8, whose table doubles as it grows.
pub const BYTES_PER_BAND_POINT: Real = 80.0;

/// Memory per capsule united \[bytes\]: its ends and radius (56 bytes) and its point in the device's rods.
pub const BYTES_PER_CAPSULE: Real = 80.0;

/// Processor time of a print solid of [`REFERENCE_TRIANGLES`] contour triangles \[s\]: contouring,
/// simplifying and placing it; it grows as the triangles to the power [`TIME_GROWTH`] (the larger maps miss
/// the caches more often). Fitted (least squares on the logarithms) to the user + system time of `stentkit mesh
/// --print` on the straight stent on this machine, 2026-11-28 (nothing else running): 2.28, 5.60, 10.52 and
/// 27.19 s for 0.89, 2.02, 3.60 and 8.12 million triangles at h = r/2, r/3 (its default), r/4 and r/6; the fit
/// gives 2.28, 5.62, 10.75 and 26.96 s (within 3 %). (Before the parallel contour and the simplifier's slabs,
/// 2026-11-26: 8.7, 22.9 and 178 s at r/2, r/3 and r/6.)
pub const REFERENCE_SECONDS: Real = 5.2;

/// The contour triangles [`REFERENCE_SECONDS`] is the time of.
pub const REFERENCE_TRIANGLES: Real = 2.0e6;

/// How a print solid's time grows with its contour's triangles (see [`REFERENCE_SECONDS`]).
pub const TIME_GROWTH: Real = 1.14;

/// Processor time per grid point a print solid visits \[s\] (a capsule's distance there, and its entry in the
/// sampled field when within the band). Measured: the straight stent's print solid at 100 samples per control
/// point (204 000 capsules, about 1500 points visited each) took 5.1 s longer than at the default 4 (8160),
/// 2026-11-28.
pub const SECONDS_PER_GRID_VISIT: Real = 18e-9;

/// The longest a print solid may be estimated to take \[s\]: 10 minutes, about a hundred times the straight
/// stent's default solid (5.6 s of processor time). On the paper's 0.3 mm wires the memory limit (8 GB) binds
/// first on the grid, at about 0.022 mm (r/14, about 42 million contour triangles, estimated 3 minutes), and
/// this one on the samples, at about 10 700 per control point (the polyline's segments then 1/1800 of the
/// grid's spacing; `--samples 1000000` would take about 15 hours and 266 GB).
pub const TIME_LIMIT_SECONDS: Real = 600.0;

/// How finely a print solid is made (lengths in the model's unit).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PrintSettings {
    /// Grid spacing; `None`: [`DEFAULT_SPACING_PER_RADIUS`] of the thinnest wire's radius.
    pub spacing: Option<Real>,
    /// Simplification tolerance; `None`: [`DEFAULT_TOLERANCE_PER_RADIUS`] of the thinnest wire's radius.
    pub tolerance: Option<Real>,
}

/// Why print settings are refused (lengths in the model's unit).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum PrintSettingsError {
    /// The grid spacing is not positive and finite, or coarser than [`MAX_SPACING_PER_RADIUS`] allows.
    #[error(
        "the grid spacing must be > 0 and at most the thinnest wire's radius, {} (a coarser grid can miss a wire \
         altogether); the default is a third of it, {}",
        Short::rounded(*radius * MAX_SPACING_PER_RADIUS, 4),
        Short::rounded(*radius * DEFAULT_SPACING_PER_RADIUS, 4)
    )]
    Spacing {
        /// The spacing given.
        spacing: Real,
        /// The thinnest wire's radius.
        radius: Real,
    },
    /// The simplification tolerance is negative, not finite, or larger than [`MAX_TOLERANCE_PER_RADIUS`]
    /// allows.
    #[error(
        "the simplification's deviation must be ≥ 0 and at most a quarter of the thinnest wire's radius, {} \
         (a larger one can flatten a wire); the default is a fiftieth of it, {}",
        Short::rounded(*radius * MAX_TOLERANCE_PER_RADIUS, 4),
        Short::rounded(*radius * DEFAULT_TOLERANCE_PER_RADIUS, 4)
    )]
    Tolerance {
        /// The tolerance given.
        tolerance: Real,
        /// The thinnest wire's radius.
        radius: Real,
    },
}

impl PrintSettings {
    /// The grid spacing and simplification tolerance for wires whose thinnest radius is `thinnest`: the
    /// defaults where none is given, else the given ones when within [`MAX_SPACING_PER_RADIUS`] and
    /// [`MAX_TOLERANCE_PER_RADIUS`].
    ///
    /// # Errors
    /// [`PrintSettingsError`] for a spacing or tolerance out of range.
    pub fn resolved(&self, thinnest: Real) -> Result<(Real, Real), PrintSettingsError> {
        let spacing = self
            .spacing
            .unwrap_or(DEFAULT_SPACING_PER_RADIUS * thinnest);
        if !(spacing > 0.0 && spacing.is_finite() && spacing <= MAX_SPACING_PER_RADIUS * thinnest) {
            return Err(PrintSettingsError::Spacing {
                spacing,
                radius: thinnest,
            });
        }
        let tolerance = self
            .tolerance
            .unwrap_or(DEFAULT_TOLERANCE_PER_RADIUS * thinnest);
        if !(tolerance >= 0.0
            && tolerance.is_finite()
            && tolerance <= MAX_TOLERANCE_PER_RADIUS * thinnest)
        {
            return Err(PrintSettingsError::Tolerance {
                tolerance,
                radius: thinnest,
            });
        }
        Ok((spacing, tolerance))
    }
}

/// The memory and time a print solid needs, estimated before any of it is made ([`estimated_print`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrintEstimate {
    /// The contour's size.
    pub contour: ContourSize,
    /// Capsules united.
    pub capsules: Real,
    /// Peak memory \[bytes\].
    pub bytes: Real,
    /// Processor time on the machine the constants were measured on \[s\].
    pub seconds: Real,
}

/// The memory and time of the print solid of `wires` (every rod of the full device) contoured at grid spacing
/// `spacing` ([`estimated_contour`], with [`BYTES_PER_CONTOUR_TRIANGLE`], [`BYTES_PER_BAND_POINT`] and
/// [`BYTES_PER_CAPSULE`] for the memory, [`REFERENCE_SECONDS`] and [`SECONDS_PER_GRID_VISIT`] for the time).
pub fn estimated_print(wires: impl IntoIterator<Item = WireSize>, spacing: Real) -> PrintEstimate {
    let wires: Vec<WireSize> = wires.into_iter().collect();
    let contour = estimated_contour(wires.iter().copied(), spacing);
    let capsules = wires.iter().map(|w| w.capsules).sum::<Real>();
    PrintEstimate {
        contour,
        capsules,
        bytes: BASE_BYTES
            + contour.triangles * BYTES_PER_CONTOUR_TRIANGLE
            + contour.band_points * BYTES_PER_BAND_POINT
            + capsules * BYTES_PER_CAPSULE,
        seconds: REFERENCE_SECONDS * (contour.triangles / REFERENCE_TRIANGLES).powf(TIME_GROWTH)
            + contour.visits * SECONDS_PER_GRID_VISIT,
    }
}

/// [`estimated_print`] for the full device of `model` with `samples[k]` samples (capsule ends) along patch
/// `k`: every rod its patch's length ([`patch_sizes`]: an upper bound) and radius.
pub fn estimated_device_print(model: &Model, samples: &[Real], spacing: Real) -> PrintEstimate {
    let wires = patch_sizes(model)
        .into_iter()
        .zip(samples)
        .enumerate()
        .flat_map(|(k, ((copies, length), &kept))| {
            let wire = WireSize {
                length,
                radius: model.wire_radius(k),
                capsules: kept - 1.0,
            };
            std::iter::repeat_n(wire, copies)
        });
    estimated_print(wires, spacing)
}

/// The radius of the thinnest wire of `model` (∞ for a model without patches).
pub fn thinnest_wire(model: &Model) -> Real {
    (0..model.patches.len())
        .map(|k| model.wire_radius(k))
        .fold(Real::INFINITY, Real::min)
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
///
/// # Errors
/// [`PrintSettingsError`] for settings out of range ([`PrintSettings::resolved`]).
pub fn print_solid(
    model: &Model,
    shapes: &[PatchShape],
    settings: &PrintSettings,
) -> Result<PrintSolid, PrintSettingsError> {
    let (spacing, tolerance) = settings.resolved(thinnest_wire(model))?;
    let capsules = device_capsules(model, shapes);
    let contoured = union_surface(&capsules, spacing);
    let (mut mesh, simplified) = simplify(&contoured.mesh, tolerance);
    let volume = contoured.volume_second_order();
    let offset = offset_to_volume(&mut mesh, volume);
    stand_upright(&mut mesh);
    Ok(PrintSolid {
        mesh,
        spacing,
        tolerance,
        capsules: capsules.len(),
        simplified,
        contour_volume: contoured.mesh.volume(),
        volume,
        offset,
    })
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
