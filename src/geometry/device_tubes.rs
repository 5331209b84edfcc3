//! The closed surface of a whole device from the rods of a symmetry-reduced model ([`device_mesh`]): one
//! tube per rod ([`RodTube`]), each with its own section phase ([`section_phase`]) and its sections' tilt
//! limited ([`limited_tilt`]), mirrored about the symmetry planes and welded to its images where a rod ends
//! on a plane.

use std::f64::consts::PI;

use super::mesh::TriangleMesh;
use super::tube::{EndCaps, TubeError, TubeSettings, centreline_tangents, sweep_tube_with_caps};
use crate::math::{Mat3, Real, Vec3};

/// One rod of a device, sampled for drawing as a tube.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RodTube<'a> {
    /// Centreline samples \[length\].
    pub centre: &'a [Vec3],
    /// Section frames at the samples (columns `d1, d2, d3`).
    pub frames: &'a [Mat3],
    /// Tube radius \[length\].
    pub radius: Real,
    /// Section phase, a fraction of a segment (see [`section_phase`]).
    pub phase: Real,
    /// The symmetry plane (index into the planes given to [`device_mesh`]) the rod lies in, if any: it is its
    /// own mirror image there and is drawn once, not mirrored about that plane.
    pub in_plane: Option<usize>,
}

/// Why a device could not be meshed: which rod failed and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("rod {rod}: {source}")]
pub struct DeviceMeshError {
    /// Index of the rod.
    pub rod: usize,
    /// What went wrong.
    #[source]
    pub source: TubeError,
}

/// Golden-ratio conjugate: successive multiples modulo 1 are as evenly spread as possible, so no two patches
/// get (nearly) the same section phase.
const PHASE_STEP: Real = 0.618_033_988_749_894_9;

/// The section phase of the `k`-th rod of a device, a fraction of a segment in `[0, 1)`: `k φ mod 1` with
/// `φ` the golden-ratio conjugate. Sweeping each rod with its own phase keeps the end rings of rods meeting at
/// a joint from coinciding vertex for vertex (see [`super::tube::sweep_curve`]).
pub(crate) fn section_phase(k: usize) -> Real {
    (k as Real * PHASE_STEP).fract()
}

/// The rotation about the rod axis `d1` that turns a section polygon of `segments` vertices by `phase`
/// segments: multiply a frame by it on the right.
pub(crate) fn phase_turn(phase: Real, segments: usize) -> Mat3 {
    *crate::math::so3::exp(&(Vec3::x() * (2.0 * PI * phase / segments.max(1) as Real))).matrix()
}

/// `frames` for drawing the polyline `centre` as a tube: each frame whose section normal (`d2 × d3`) is more
/// than `max_tilt` from the sampled centreline direction (the tangents of [`super::tube::sweep_tube`]) is
/// turned, about the axis normal to both, until it is `max_tilt` from it; the others are kept. The normals are
/// compared on the side most of the rod's sections face (`d2 × d3` along or against the samples' order; along when
/// undecided), so a ring facing the wrong way is turned too. Frames the sweep would reject (too few samples,
/// coincident samples, non-finite or degenerate frames) are returned unchanged, for the sweep to report.
pub(crate) fn limited_tilt(centre: &[Vec3], frames: &[Mat3], max_tilt: Real) -> Vec<Mat3> {
    let Ok(tangents) = centreline_tangents(centre) else {
        return frames.to_vec();
    };
    if tangents.len() != frames.len() {
        return frames.to_vec();
    }
    let normals: Vec<Option<Vec3>> = frames
        .iter()
        .map(|f| f.column(1).cross(&f.column(2)).try_normalize(0.0))
        .collect();
    let facing: Real = normals
        .iter()
        .zip(&tangents)
        .filter_map(|(n, t)| n.map(|n| n.dot(t)))
        .filter(|c| c.is_finite())
        .sum();
    let side = if facing < 0.0 { -1.0 } else { 1.0 };
    frames
        .iter()
        .zip(&normals)
        .zip(&tangents)
        .map(|((frame, normal), tangent)| {
            let Some(n) = normal.map(|n| side * n) else {
                return *frame;
            };
            let tilt = n.dot(tangent).clamp(-1.0, 1.0).acos();
            if !(tilt > max_tilt) {
                return *frame;
            }
            // Turning n about n × t moves it towards t; edge-on the other way, any axis normal to t.
            let axis = n
                .cross(tangent)
                .try_normalize(0.0)
                .unwrap_or_else(|| super::frame::normal_to(tangent, None));
            let turn = crate::math::so3::exp(&(axis * (tilt - max_tilt)));
            turn.matrix() * frame
        })
        .collect()
}

/// The closed surface of a whole device from the rods of a symmetry-reduced model: one tube per rod, mirrored
/// about every symmetry plane `(point, normal)` in turn (a quarter model gives four copies of each rod), with
/// the rods lying in a plane ([`RodTube::in_plane`]) not mirrored about it.
///
/// A rod end whose ring lies in a plane the rod does not lie in (within [`TubeSettings::seam_tolerance`] of
/// the radius) continues in the mirror image: it is left uncapped and welded to its image
/// ([`TriangleMesh::mirrored_welded`]), so the rod and its image form one closed tube, without two caps
/// coinciding (which would make their edges non-manifold once an STL reader merges equal vertices). Every
/// other end is capped. The result is closed ([`TriangleMesh::check_closed`]) and outward; like any device
/// from [`super::tube::sweep_tube`], tubes overlap at joints.
///
/// Mirroring about several planes assumes that the reflections commute (orthogonal planes, as for half and
/// quarter models).
///
/// # Errors
/// [`DeviceMeshError`] naming the rod whose tube cannot be swept.
pub(crate) fn device_mesh(
    rods: &[RodTube<'_>],
    planes: &[(Vec3, Vec3)],
    settings: &TubeSettings,
) -> Result<TriangleMesh, DeviceMeshError> {
    /// A rod's tube and its copies so far, with the rings still to be welded per plane.
    struct Piece {
        mesh: TriangleMesh,
        in_plane: Option<usize>,
        /// `(plane, ring vertex indices)` of open ends.
        seams: Vec<(usize, Vec<u32>)>,
    }
    let m = settings.segments_around;
    let units: Vec<Vec3> = planes
        .iter()
        .map(|(_, n)| n.try_normalize(0.0).unwrap_or_else(Vec3::zeros))
        .collect();
    let mut pieces = Vec::with_capacity(rods.len());
    for (index, rod) in rods.iter().enumerate() {
        let error = |source| DeviceMeshError { rod: index, source };
        let n = rod.centre.len();
        if n < 2 {
            return Err(error(TubeError::TooFewSamples { count: n }));
        }
        if rod.frames.len() != n {
            return Err(error(TubeError::LengthMismatch {
                centre: n,
                frames: rod.frames.len(),
            }));
        }
        let turn = phase_turn(rod.phase, m);
        let turned: Vec<Mat3> = rod.frames.iter().map(|f| f * turn).collect();
        let frames = limited_tilt(rod.centre, &turned, settings.max_section_tilt);
        // The plane an end ring lies in: its largest distance from the plane is
        // |(c − p)·n| + r |(d2·n, d3·n)|.
        let ring_plane = |i: usize| {
            let (c, f) = (rod.centre[i], frames[i]);
            planes.iter().zip(&units).position(|((p, _), u)| {
                let tilt = Real::hypot(f.column(1).dot(u), f.column(2).dot(u));
                let distance = (c - p).dot(u).abs() + rod.radius * tilt;
                distance <= settings.seam_tolerance * rod.radius
            })
        };
        let open =
            [ring_plane(0), ring_plane(n - 1)].map(|j| j.filter(|&j| Some(j) != rod.in_plane));
        let caps = EndCaps {
            start: open[0].is_none(),
            end: open[1].is_none(),
        };
        let mesh =
            sweep_tube_with_caps(rod.centre, &frames, rod.radius, caps, settings).map_err(error)?;
        let ring = |i: usize| (i * m..(i + 1) * m).map(|v| v as u32).collect::<Vec<u32>>();
        let seams = [(open[0], 0), (open[1], n - 1)]
            .into_iter()
            .filter_map(|(j, i)| j.map(|j| (j, ring(i))))
            .collect();
        pieces.push(Piece {
            mesh,
            in_plane: rod.in_plane,
            seams,
        });
    }
    for (j, (point, normal)) in planes.iter().enumerate() {
        for piece in &mut pieces {
            if piece.in_plane == Some(j) {
                continue;
            }
            let seam: Vec<u32> = piece
                .seams
                .iter()
                .filter(|(plane, _)| *plane == j)
                .flat_map(|(_, ring)| ring.iter().copied())
                .collect();
            let (mesh, image) = piece.mesh.mirrored_welded(point, normal, &seam);
            let others: Vec<(usize, Vec<u32>)> = piece
                .seams
                .iter()
                .filter(|(plane, _)| *plane != j)
                .cloned()
                .collect();
            let mirrored = others
                .iter()
                .map(|(plane, ring)| (*plane, ring.iter().map(|&v| image[v as usize]).collect()));
            piece.seams = others.iter().cloned().chain(mirrored).collect();
            piece.mesh = mesh;
        }
    }
    let mut device = TriangleMesh::new();
    for piece in &pieces {
        device.append(&piece.mesh);
    }
    Ok(device)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::tube::sweep_tube;

    /// Samples and frames of a circular arc of radius `big_r` in the (x, y) plane about the origin, from angle
    /// `a0` to `a1`: d1 the tangent, d2 radial, d3 = e_z.
    fn arc(big_r: Real, a0: Real, a1: Real, n: usize) -> (Vec<Vec3>, Vec<Mat3>) {
        (0..n)
            .map(|i| {
                let a = a0 + (a1 - a0) * i as Real / (n - 1) as Real;
                let (s, c) = a.sin_cos();
                let radial = Vec3::new(c, s, 0.0);
                let tangent = Vec3::new(-s, c, 0.0);
                (
                    big_r * radial,
                    Mat3::from_columns(&[tangent, radial, Vec3::z()]),
                )
            })
            .unzip()
    }

    fn polygon_area(r: Real, m: usize) -> Real {
        0.5 * m as Real * r * r * (2.0 * PI / m as Real).sin()
    }

    #[test]
    fn quarter_ring_mirrored_about_two_planes_is_one_closed_torus() {
        // A quarter of a ring (R = 1, r = 0.1) from the x axis to the y axis ends on both symmetry planes
        // (y = 0 and x = 0): both ends stay open and the four copies weld into one closed torus whose volume is
        // that of the full ring, ≈ A_m · 2πR (second order in the sampling).
        let (centre, frames) = arc(1.0, 0.0, 0.5 * PI, 33);
        let planes = [
            (Vec3::zeros(), Vec3::new(0.0, 1.0, 0.0)),
            (Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0)),
        ];
        let settings = TubeSettings::default();
        let rod = RodTube {
            centre: &centre,
            frames: &frames,
            radius: 0.1,
            phase: section_phase(3),
            in_plane: None,
        };
        let mesh = device_mesh(&[rod], &planes, &settings).expect("device mesh");
        assert_eq!(mesh.check_closed(), Ok(()));
        // 4 × 32 quads of 16 segments, no caps; 4 × 33 rings of which 4 are shared.
        assert_eq!(mesh.triangles.len(), 4 * 32 * 2 * 16);
        assert_eq!(mesh.vertices.len(), (4 * 33 - 4) * 16);
        let expected = polygon_area(0.1, 16) * 2.0 * PI;
        let volume = mesh.volume();
        assert!(
            (volume / expected - 1.0).abs() < 2e-3,
            "volume {volume} vs {expected}"
        );
    }

    #[test]
    fn rods_in_a_plane_are_drawn_once_and_ends_off_planes_are_capped() {
        // A straight rod lying in the plane y = 0 is not mirrored about it (one copy, capped); a rod ending off
        // every plane is mirrored and capped at both ends (two closed copies).
        let line = |from: Vec3, to: Vec3| -> (Vec<Vec3>, Vec<Mat3>) {
            let d1 = (to - from).normalize();
            let frame = Mat3::from_columns(&[d1, Vec3::y(), d1.cross(&Vec3::y())]);
            (0..5)
                .map(|i| (from + (to - from) * (i as Real / 4.0), frame))
                .unzip()
        };
        let (c0, f0) = line(Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0));
        let (c1, f1) = line(Vec3::new(1.0, 0.5, 0.0), Vec3::new(1.0, 0.5, 1.0));
        let planes = [(Vec3::zeros(), Vec3::y())];
        let settings = TubeSettings::default();
        let rods = [
            RodTube {
                centre: &c0,
                frames: &f0,
                radius: 0.1,
                phase: 0.0,
                in_plane: Some(0),
            },
            RodTube {
                centre: &c1,
                frames: &f1,
                radius: 0.1,
                phase: 0.5,
                in_plane: None,
            },
        ];
        let mesh = device_mesh(&rods, &planes, &settings).expect("device mesh");
        assert_eq!(mesh.check_closed(), Ok(()));
        let tube = polygon_area(0.1, 16);
        assert!((mesh.volume() / (3.0 * tube) - 1.0).abs() < 1e-12);
        assert_eq!(mesh.triangles.len(), 3 * (4 * 2 * 16 + 2 * 16));
    }

    #[test]
    fn welded_half_ring_survives_stl_style_vertex_merging() {
        // After welding, no two distinct vertices share a position (an STL reader merging equal positions
        // would otherwise change the topology).
        let (centre, frames) = arc(2.0, 0.0, PI, 41);
        let planes = [(Vec3::zeros(), Vec3::y())];
        let rod = RodTube {
            centre: &centre,
            frames: &frames,
            radius: 0.05,
            phase: 0.25,
            in_plane: None,
        };
        let mesh = device_mesh(&[rod], &planes, &TubeSettings::default()).expect("mesh");
        assert_eq!(mesh.check_closed(), Ok(()));
        let mut keys: Vec<[u32; 3]> = mesh
            .vertices
            .iter()
            .map(|v| [v.x as f32, v.y as f32, v.z as f32].map(f32::to_bits))
            .collect();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), mesh.vertices.len());
    }

    #[test]
    fn two_rings_on_a_half_circle_are_drawn_as_a_tilted_straight_tube() {
        // A half ring (R = 1) sampled at its two ends only: the chord is (−2, 0, 0), and both sections (normal
        // to the arc's tangent, ±y) contain it, so the sweep alone rejects them (cosine 0). device_mesh turns
        // each ring towards the chord until its normal is 60° from it (TubeSettings::max_section_tilt); the
        // tube is then closed and outward, with each ring's plane at 60° from the chord: the normal of the
        // plane through three of a ring's vertices, dotted with the chord direction, is cos 60° = 0.5 in
        // magnitude (round-off aside).
        let (centre, frames) = arc(1.0, 0.0, PI, 2);
        let settings = TubeSettings::default();
        assert!(matches!(
            sweep_tube(&centre, &frames, 0.1, &settings),
            Err(TubeError::SectionNotTransverse { .. })
        ));
        let rod = RodTube {
            centre: &centre,
            frames: &frames,
            radius: 0.1,
            phase: 0.0,
            in_plane: None,
        };
        let mesh = device_mesh(&[rod], &[], &settings).expect("drawn");
        assert_eq!(mesh.check_closed(), Ok(()));
        assert!(mesh.volume() > 0.0);
        let m = settings.segments_around;
        let chord = Vec3::new(-1.0, 0.0, 0.0);
        for ring in 0..2 {
            let v = |k: usize| mesh.vertices[ring * m + k];
            let normal = (v(1) - v(0)).cross(&(v(m / 2) - v(0))).normalize();
            assert!(
                (normal.dot(&chord).abs() - 0.5).abs() < 1e-12,
                "ring {ring}"
            );
        }
        // A ring within 60° of the samples' direction is kept as given (the quarter ring's 45° at two samples).
        let (centre, frames) = arc(1.0, 0.0, 0.5 * PI, 2);
        assert_eq!(
            limited_tilt(&centre, &frames, settings.max_section_tilt),
            frames
        );
    }
}
