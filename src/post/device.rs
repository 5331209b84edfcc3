//! The full device from a (possibly symmetry-reduced) model, as exports draw it (DESIGN §5: exports always
//! show the full device): closed tube meshes and centrelines, mirrored back about the model's symmetry planes.
//!
//! Both take the rods sampled as `PatchShape`s, from a running simulation
//! (`crate::solver::shape::current_shapes`, with the solver's section frames) or from the reference geometry
//! ([`reference_patch_shapes`], rotation-minimising frames, no simulation needed). Each patch is swept with its
//! own section phase (`section_phase`) so that tubes meeting at a joint never share a ring; rods lying in a
//! symmetry plane (bridges kept with half their section) are drawn once at their full drawing diameter, and
//! rods ending on a plane are welded to their mirror images (`device_mesh`).

use crate::geometry::GeometryError;
use crate::geometry::device_tubes::{DeviceMeshError, RodTube, device_mesh, section_phase};
use crate::geometry::frame::{FrameField, FrameSettings};
use crate::geometry::mesh::TriangleMesh;
use crate::geometry::tube::{TubeError, TubeSettings};
use crate::math::{Real, Vec3};
use crate::model::Model;
use crate::solver::Simulation;
use crate::solver::shape::{PatchShape, current_shapes};

/// Why the full device could not be meshed in its reference shape ([`reference_device_mesh`]): the patch
/// (index and name) and the cause.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReferenceMeshError {
    /// The patch's rotation-minimising frame cannot be evaluated.
    #[error("patch `{name}`")]
    Frame {
        /// Index into [`Model::patches`].
        patch: usize,
        /// The patch's name.
        name: String,
        /// What is wrong.
        #[source]
        source: GeometryError,
    },
    /// The patch's tube cannot be swept.
    #[error("patch `{name}`")]
    Tube {
        /// Index into [`Model::patches`].
        patch: usize,
        /// The patch's name.
        name: String,
        /// What is wrong.
        #[source]
        source: TubeError,
    },
}

/// Memory per sample of a patch's shape \[bytes\]: its point and section frame (a `Vec3` and a `Rot3`).
pub const BYTES_PER_SHAPE_SAMPLE: Real = 96.0;

/// Memory per point of the full device's rods \[bytes\] (a `Vec3`), for the print solid and the centrelines.
pub const BYTES_PER_ROD_POINT: Real = 24.0;

/// Memory per row of a centreline file \[bytes\]: `rod,point,x,y,z,radius` with the coordinates at full
/// precision is at most about 100 characters.
pub const BYTES_PER_CENTRELINE_ROW: Real = 100.0;

/// Peak memory of the full device's tube mesh per triangle \[bytes\]: the mesh, its closedness check and the
/// file's bytes. Measured (peak resident memory of `stentkit mesh` on the straight stent over its triangles):
/// 151 at its defaults (0.26 million triangles, with the program's own few MB), 163 at 10 samples per control
/// point and 64 segments (2.6 million; STL, OBJ and 3MF alike) and 161 at 40 and 64 (10.5 million).
pub const BYTES_PER_TUBE_TRIANGLE: Real = 165.0;

/// Each patch of `model` as `(copies, length)`: how many rods of the full device it makes (itself and its
/// mirror images, [`patch_copies`]) and the length of its control polygon, which bounds the curve's length
/// from above (knot insertion cuts the polygon's corners towards the curve).
pub fn patch_sizes(model: &Model) -> Vec<(usize, Real)> {
    (0..model.patches.len())
        .map(|k| {
            let points = model.patches[k].curve.points();
            let length = points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
            (patch_copies(model, k).len(), length)
        })
        .collect()
}

/// Indices of about `target` of `n` samples, evenly spaced (every k-th, `k = round((n − 1)/(target − 1))`),
/// the first and the last always included; all of them when `n ≤ target`.
pub fn decimation(n: usize, target: usize) -> Vec<usize> {
    let target = target.max(2);
    if n <= target {
        return (0..n).collect();
    }
    let k = (((n - 1) as Real / (target - 1) as Real).round() as usize).max(1);
    let mut out: Vec<usize> = (0..n).step_by(k).collect();
    if !(n - 1).is_multiple_of(k) {
        out.push(n - 1);
    }
    out
}

/// `shape` reduced to about `target` samples ([`decimation`]).
pub fn decimated(shape: &PatchShape, target: usize) -> PatchShape {
    let keep = decimation(shape.points.len(), target);
    PatchShape {
        points: keep.iter().map(|&i| shape.points[i]).collect(),
        frames: keep.iter().map(|&i| shape.frames[i]).collect(),
    }
}

/// Every patch of the simulation in its current configuration with about `samples` samples (rings of a tube,
/// points of a centreline) per patch, whatever its number of control points `n`: sampled at the smallest whole
/// number of samples per control point that gives at least that many for every patch, then reduced
/// ([`decimated`]). The ends of every patch are always samples.
pub fn current_device_shapes(sim: &Simulation<'_>, samples: usize) -> Vec<PatchShape> {
    current_shapes(sim, samples_per_point(sim.model(), samples))
        .iter()
        .map(|s| decimated(s, samples))
        .collect()
}

/// The smallest whole number of samples per control point that gives every patch of `model` at least
/// `samples` samples ([`current_device_shapes`] samples at it, then decimates).
pub fn samples_per_point(model: &Model, samples: usize) -> usize {
    model
        .patches
        .iter()
        .map(|p| (samples.saturating_sub(1)).div_ceil(p.curve.num_points().max(1)))
        .max()
        .unwrap_or(1)
        .max(1)
}

/// The number of samples (rings of a tube, points of a centreline) each patch of `model` gets from
/// [`current_device_shapes`] with `samples`, in patch order: `samples_per_point · n + 1` decimated.
pub fn device_sample_counts(model: &Model, samples: usize) -> Vec<usize> {
    let per_point = samples_per_point(model, samples);
    model
        .patches
        .iter()
        .map(|p| decimation(per_point * p.curve.num_points().max(1) + 1, samples).len())
        .collect()
}

/// Samples every patch of the model in its reference shape with rotation-minimising frames: `m + 1` points
/// at `u = k/m`, `m = samples_per_point · n` (the sampling of `crate::solver::shape`).
///
/// # Errors
/// [`GeometryError`] with the patch index when a frame cannot be evaluated.
pub fn reference_patch_shapes(
    model: &Model,
    samples_per_point: usize,
) -> Result<Vec<PatchShape>, (usize, GeometryError)> {
    model
        .patches
        .iter()
        .enumerate()
        .map(|(k, patch)| {
            let frames = FrameField::rotation_minimising(
                &patch.curve,
                patch.normal_hint,
                &FrameSettings::default(),
            )
            .map_err(|e| (k, e))?;
            let (u0, u1) = patch.curve.knots().domain();
            let m = (samples_per_point.max(1) * patch.curve.num_points()).max(1);
            let mut shape = PatchShape {
                points: Vec::with_capacity(m + 1),
                frames: Vec::with_capacity(m + 1),
            };
            for i in 0..=m {
                let u = u0 + (u1 - u0) * i as Real / m as Real;
                let f = frames.at(&patch.curve, u).map_err(|e| (k, e))?;
                shape.points.push(f.position);
                shape.frames.push(f.rotation);
            }
            Ok(shape)
        })
        .collect()
}

/// The closed tube surface of the full device: one tube per patch of `shapes` (in the model's patch order)
/// with `segments` vertices around, mirrored about the model's symmetry planes.
///
/// # Errors
/// `DeviceMeshError` whose `rod` is the index of the patch that cannot be swept.
pub fn device_tube_mesh(
    model: &Model,
    shapes: &[PatchShape],
    segments: usize,
) -> Result<TriangleMesh, DeviceMeshError> {
    let settings = TubeSettings {
        segments_around: segments,
        ..TubeSettings::default()
    };
    let rods: Vec<RodTube<'_>> = shapes
        .iter()
        .enumerate()
        .map(|(k, shape)| RodTube {
            centre: &shape.points,
            frames: &shape.frames,
            radius: model.wire_radius(k),
            phase: section_phase(k),
            in_plane: model.patch_symmetry_plane(k),
        })
        .collect();
    device_mesh(&rods, &model.symmetry_planes, &settings)
}

/// The closed tube surface of the full device (mirrored back from a symmetry-reduced model) in its reference
/// shape: every patch sampled with [`reference_patch_shapes`] at `samples_per_point` samples per control point
/// and swept with `segments` vertices around ([`device_tube_mesh`]).
///
/// # Errors
/// [`ReferenceMeshError`] naming the patch whose frame or tube failed.
pub fn reference_device_mesh(
    model: &Model,
    segments: usize,
    samples_per_point: usize,
) -> Result<TriangleMesh, ReferenceMeshError> {
    let name = |k: usize| model.patches[k].name.clone();
    let shapes = reference_patch_shapes(model, samples_per_point).map_err(|(patch, source)| {
        ReferenceMeshError::Frame {
            patch,
            name: name(patch),
            source,
        }
    })?;
    device_tube_mesh(model, &shapes, segments).map_err(|e| ReferenceMeshError::Tube {
        patch: e.rod,
        name: name(e.rod),
        source: e.source,
    })
}

/// The reflections that make the full device's copies of patch `patch`: each entry lists the symmetry planes
/// (indices into [`Model::symmetry_planes`]) to reflect about, the empty list being the patch itself. A patch
/// lying in a plane is not reflected about that plane.
pub fn patch_copies(model: &Model, patch: usize) -> Vec<Vec<usize>> {
    let own = model.patch_symmetry_plane(patch);
    let mut copies = vec![Vec::new()];
    for j in 0..model.symmetry_planes.len() {
        if own == Some(j) {
            continue;
        }
        let more: Vec<Vec<usize>> = copies
            .iter()
            .map(|c| c.iter().copied().chain([j]).collect())
            .collect();
        copies.extend(more);
    }
    copies
}

/// `point` reflected about each listed symmetry plane in turn.
pub fn reflect(model: &Model, planes: &[usize], point: Vec3) -> Vec3 {
    planes.iter().fold(point, |x, &j| {
        let (p, n) = &model.symmetry_planes[j];
        let n = n.normalize();
        x - 2.0 * (x - p).dot(&n) * n
    })
}

/// The centrelines of the full device: every patch's points and their mirror images (a quarter model gives
/// four polylines per patch off the planes, two for a patch lying in one).
pub fn device_centrelines(model: &Model, shapes: &[PatchShape]) -> Vec<Vec<Vec3>> {
    device_rods(model, shapes).map(|(_, line)| line).collect()
}

/// The rods of the full device: each patch's points in `shapes` and their mirror images, with the index of
/// the patch each copies ([`device_centrelines`] without the indices).
pub fn device_rods<'a>(
    model: &'a Model,
    shapes: &'a [PatchShape],
) -> impl Iterator<Item = (usize, Vec<Vec3>)> + 'a {
    shapes.iter().enumerate().flat_map(move |(k, shape)| {
        patch_copies(model, k).into_iter().map(move |planes| {
            (
                k,
                shape
                    .points
                    .iter()
                    .map(|&x| reflect(model, &planes, x))
                    .collect(),
            )
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimation_keeps_the_ends_and_spreads_evenly() {
        // n = 82 (p = 6, n = 81 patches sampled once per control point): every 4th, 0 … 80, and the end.
        let d = decimation(82, 21);
        assert_eq!(d.len(), 22);
        assert_eq!((d[0], d[20], d[21]), (0, 80, 81));
        assert_eq!(decimation(21, 21), (0..21).collect::<Vec<_>>());
        assert_eq!(decimation(24, 21).len(), 24);
        let d = decimation(41, 21);
        assert_eq!((d.len(), d[20]), (21, 40));
        assert_eq!(decimation(5, 0), (0..2).map(|i| 4 * i).collect::<Vec<_>>());
    }
}
