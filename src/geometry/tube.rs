//! Closed tube surfaces swept along centrelines: a circular section swept along sampled centre points with
//! given section frames, closed at both ends by flat caps ([`sweep_tube`], [`sweep_tube_with_caps`]), or
//! along a spline curve with its rotation-minimising frames ([`sweep_curve`]). [`TubeSettings`] hold the
//! resolution and tolerances of these and of the other shell generators (`super::sphere`,
//! `super::device_tubes`), and [`TubeError`] says why a tube, sphere or frame set cannot be built.
//!
//! ## Several tubes make one device
//!
//! A device is exported as the plain union ([`TriangleMesh::append`]) of one closed tube per rod patch,
//! optionally plus spheres at joints. Each shell is closed and outward on its own, so the union is closed
//! edge-wise (every edge still has exactly its two triangles), but the shells *overlap* at joints: two caps
//! may sit inside a neighbouring tube or coincide with each other. That is deliberate. Slicers and viewers
//! take the union of overlapping closed shells; a boolean union would be slow and fragile, and flat caps
//! keep the tube ends exactly where the rod ends are (a free end looks like the cut end of a wire).
//! Spheres at joints are an optional cosmetic addition, not a replacement for the caps.
//!
//! The mesh type and the other generators moved to their own modules; their old paths under
//! `geometry::tube` are kept by the re-exports below.
//!
//! Nothing here writes files: the `io` layer turns a [`TriangleMesh`] into STL or OBJ.

use std::f64::consts::PI;

use crate::math::{Mat3, Real, Vec3};

use super::mesh::TriangleMesh;

/// Resolution and tolerances of the tube and sphere generators.
#[derive(Debug, Clone, PartialEq)]
pub struct TubeSettings {
    /// Number of vertices around each circular section (the section is the inscribed regular polygon).
    /// At least 3. Default 16: the polygon's area is `sin(2π/16)/(2π/16) = 97.4 %` of the circle's, and it
    /// looks round in a viewer at the usual stent scale. The volume error falls as `(2π/m)²/6`.
    pub segments_around: usize,
    /// Smallest accepted `|cos|` of the angle between the section normal `d2 × d3` and the local
    /// centreline direction. Default `1e-3` (sections within 0.06° of containing the centreline are
    /// rejected): it only catches frames that cannot define a tube, since the sign of the cosine decides the
    /// winding; any physically sensible shear angle passes.
    pub min_section_cosine: Real,
    /// Largest accepted `max |Fᵀ F − I|` entry for a section frame `F`. Default `1e-6`: frames from
    /// rotations are orthonormal to rounding (`~1e-15`); anything worse than `1e-6` would draw a visibly
    /// elliptic or skewed section and indicates a bug or unnormalised input.
    pub frame_tolerance: Real,
    /// Largest angle \[rad\] between a ring's section normal (`d2 × d3`) and the sampled centreline direction
    /// that `super::device_tubes::device_mesh` draws as given. Coarse samples of a bent rod tilt the sections against the polyline
    /// that joins them (by half the angle the rod turns between two samples): two rings on a patch bent into a
    /// half circle put both sections edge-on to the chord, which no tube can be swept through. A ring tilted
    /// further is turned, about the axis normal to both directions, until its tilt is this angle. Default
    /// `π/3` (60°): up to 120° of turn between samples is drawn as the solver's sections; the default 41
    /// rings per patch never come close.
    pub max_section_tilt: Real,
    /// Largest distance of an end ring from a symmetry plane, as a fraction of the tube radius, for
    /// `super::device_tubes::device_mesh` to treat the ring as lying in the plane (left open and welded to its mirror image).
    /// Default `1e-6`: a rod end held by symmetry conditions lies in the plane to the solver's round-off
    /// (~1e-12 of the radius), while any end not on a plane is at least a fraction of a radius away.
    pub seam_tolerance: Real,
}

impl Default for TubeSettings {
    /// 16 segments around, `min_section_cosine = 1e-3`, `max_section_tilt = π/3`, `frame_tolerance = 1e-6`,
    /// `seam_tolerance = 1e-6` (see the fields).
    fn default() -> Self {
        Self {
            segments_around: 16,
            min_section_cosine: 1e-3,
            max_section_tilt: PI / 3.0,
            frame_tolerance: 1e-6,
            seam_tolerance: 1e-6,
        }
    }
}

/// Why a tube, sphere or frame set cannot be built from the given data.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TubeError {
    /// Fewer than two centreline samples.
    #[error("a tube needs at least 2 centreline samples, got {count}")]
    TooFewSamples {
        /// Number of samples given.
        count: usize,
    },
    /// The centreline and the frames have different lengths.
    #[error("{centre} centreline samples but {frames} frames")]
    LengthMismatch {
        /// Number of centre points.
        centre: usize,
        /// Number of frames.
        frames: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("{what} {index} is not finite")]
    NonFinite {
        /// `"centre point"`, `"frame"` or `"sphere centre"`.
        what: &'static str,
        /// Sample index.
        index: usize,
    },
    /// The radius is not a positive finite number.
    #[error("radius must be positive and finite, got {radius}")]
    InvalidRadius {
        /// The radius given \[length\].
        radius: Real,
    },
    /// Fewer than 3 segments around the section.
    #[error("segments_around must be at least 3, got {segments}")]
    TooFewSegments {
        /// The value given.
        segments: usize,
    },
    /// A tolerance in [`TubeSettings`] is out of range.
    #[error("setting {name} = {value} is out of range ({expected})")]
    InvalidSetting {
        /// Field name.
        name: &'static str,
        /// The value given.
        value: Real,
        /// The accepted range.
        expected: &'static str,
    },
    /// Two consecutive centreline samples coincide.
    #[error("centreline samples {index} and {} coincide", index + 1)]
    CoincidentSamples {
        /// Index of the first of the two samples.
        index: usize,
    },
    /// The centreline turns back on itself at a sample, so no tangent can be estimated there.
    #[error("zero centreline tangent at sample {index} (the polyline reverses there)")]
    ZeroTangent {
        /// Sample index.
        index: usize,
    },
    /// A frame's `d2, d3` are not orthonormal within [`TubeSettings::frame_tolerance`].
    #[error("frame {index} is not orthonormal: max |FᵀF − I| = {deviation:e}")]
    FrameNotOrthonormal {
        /// Sample index.
        index: usize,
        /// The largest entry of `|FᵀF − I|`.
        deviation: Real,
    },
    /// The section plane (d2–d3) nearly contains the centreline direction, so it does not cut the tube.
    #[error("section {index} is not transverse: cos(d2×d3, centreline direction) = {cosine:e}")]
    SectionNotTransverse {
        /// Sample index.
        index: usize,
        /// Cosine of the angle between `d2 × d3` and the centreline direction.
        cosine: Real,
    },
    /// The mesh would need more vertices than `u32` indices can address.
    #[error("the mesh would have {vertices} vertices, more than u32 indices can address")]
    TooManyVertices {
        /// Vertices needed.
        vertices: usize,
    },
}

/// Which ends of a swept tube get a flat cap.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EndCaps {
    /// Cap at the first sample.
    pub start: bool,
    /// Cap at the last sample.
    pub end: bool,
}

impl EndCaps {
    /// Both ends capped: a closed tube.
    pub const BOTH: EndCaps = EndCaps {
        start: true,
        end: true,
    };
}

/// Why a curve could not be swept.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SweepError {
    /// The frames could not be evaluated.
    #[error(transparent)]
    Frame(#[from] super::GeometryError),
    /// The tube could not be built.
    #[error(transparent)]
    Tube(#[from] TubeError),
}

impl TubeSettings {
    /// Checks the settings' ranges.
    pub(crate) fn validate(&self) -> Result<(), TubeError> {
        if self.segments_around < 3 {
            return Err(TubeError::TooFewSegments {
                segments: self.segments_around,
            });
        }
        if !(0.0..1.0).contains(&self.min_section_cosine) {
            return Err(TubeError::InvalidSetting {
                name: "min_section_cosine",
                value: self.min_section_cosine,
                expected: "0 <= value < 1",
            });
        }
        if !(self.max_section_tilt > 0.0 && self.max_section_tilt.cos() > self.min_section_cosine) {
            return Err(TubeError::InvalidSetting {
                name: "max_section_tilt",
                value: self.max_section_tilt,
                expected: "0 < value, cos(value) > min_section_cosine",
            });
        }
        if !(self.frame_tolerance >= 0.0 && self.frame_tolerance.is_finite()) {
            return Err(TubeError::InvalidSetting {
                name: "frame_tolerance",
                value: self.frame_tolerance,
                expected: "finite and >= 0",
            });
        }
        if !(self.seam_tolerance >= 0.0 && self.seam_tolerance.is_finite()) {
            return Err(TubeError::InvalidSetting {
                name: "seam_tolerance",
                value: self.seam_tolerance,
                expected: "finite and >= 0",
            });
        }
        Ok(())
    }
}

/// Sweeps a circular section of `radius` along a sampled centreline and closes both ends with flat caps.
///
/// Sample `i` contributes the ring `centre[i] + radius (cos φ_k d2 + sin φ_k d3)`, `φ_k = 2πk/m`,
/// `k = 0 … m−1` (`m = settings.segments_around`), where `d2, d3` are the second and third columns of
/// `frames[i]` (columns `d1, d2, d3`; `d1` is not used, the section plane is the d2–d3 plane whatever the
/// shear). Consecutive rings are joined by quads `(i,k) (i,k+1) (i+1,k+1) (i+1,k)`, each split into two
/// triangles along the same diagonal; each end gets a centre vertex and a fan of `m` triangles.
///
/// **Orientation.** Every ring is traversed counter-clockwise about the local marching direction
/// (the centreline tangent estimated from the samples, see `super::polyline::parallel_transport_frames`): when
/// `d2 × d3` points backwards at a sample, that ring is drawn with `−φ`. The result is a closed surface
/// with outward normals and positive [`TriangleMesh::volume`] whichever way the frames are handed, and
/// even if their handedness changes along the centreline. Vertex `k` of one ring is joined to vertex `k`
/// of the next, so consecutive frames must differ by a small rotation (a twist of a quarter turn between
/// two samples would skew the quads badly).
///
/// **Layout.** Vertex `i·m + k` is point `k` of ring `i`; the start and end cap centres follow, at
/// `n·m` and `n·m + 1`. There are `2m(n−1)` side and `2m` cap triangles.
///
/// **Limitations.** Where the centreline bends with a radius of curvature below `radius`, or samples are
/// closer than the section is wide on the inside of a sharp bend, neighbouring rings cross and the surface
/// self-intersects (still closed edge-wise); sample finely enough for the curvature.
///
/// # Errors
/// [`TubeError`] when there are fewer than 2 samples, the lengths differ, a coordinate is not finite, the
/// radius is not positive, `segments_around < 3`, consecutive samples coincide, the polyline reverses,
/// a frame is not orthonormal or its section plane (nearly) contains the centreline.
pub fn sweep_tube(
    centre: &[Vec3],
    frames: &[Mat3],
    radius: Real,
    settings: &TubeSettings,
) -> Result<TriangleMesh, TubeError> {
    sweep_tube_with_caps(centre, frames, radius, EndCaps::BOTH, settings)
}

/// [`sweep_tube`] with a choice of caps. An uncapped end leaves its ring as a boundary: the surface is open
/// there, meant to be welded to another surface sharing the same ring (the mirror image of a rod ending on a
/// symmetry plane, see `super::device_tubes::device_mesh`).
///
/// **Layout.** As [`sweep_tube`]: vertex `i·m + k` is point `k` of ring `i`; then the centre of the start cap
/// (if capped), then that of the end cap (if capped). The start ring is vertices `0 … m−1`, the end ring
/// `(n−1)·m … n·m − 1`.
///
/// # Errors
/// As [`sweep_tube`].
pub fn sweep_tube_with_caps(
    centre: &[Vec3],
    frames: &[Mat3],
    radius: Real,
    caps: EndCaps,
    settings: &TubeSettings,
) -> Result<TriangleMesh, TubeError> {
    sweep_rings(centre, frames, &vec![radius; centre.len()], caps, settings)
}

/// [`sweep_tube`] with a radius per sample (a vessel's lumen), closed at both ends.
///
/// # Errors
/// As [`sweep_tube`], and a radius per sample is needed.
pub fn sweep_tube_varying(
    centre: &[Vec3],
    frames: &[Mat3],
    radii: &[Real],
    settings: &TubeSettings,
) -> Result<TriangleMesh, TubeError> {
    if radii.len() != centre.len() {
        return Err(TubeError::LengthMismatch {
            centre: centre.len(),
            frames: radii.len(),
        });
    }
    sweep_rings(centre, frames, radii, EndCaps::BOTH, settings)
}

/// The tube of ring `i` of radius `radii[i]` (module docs of [`sweep_tube_with_caps`]).
fn sweep_rings(
    centre: &[Vec3],
    frames: &[Mat3],
    radii: &[Real],
    caps: EndCaps,
    settings: &TubeSettings,
) -> Result<TriangleMesh, TubeError> {
    settings.validate()?;
    let n = centre.len();
    if n < 2 {
        return Err(TubeError::TooFewSamples { count: n });
    }
    if frames.len() != n {
        return Err(TubeError::LengthMismatch {
            centre: n,
            frames: frames.len(),
        });
    }
    if let Some(&radius) = radii.iter().find(|r| !(**r > 0.0 && r.is_finite())) {
        return Err(TubeError::InvalidRadius { radius });
    }
    if let Some(index) = frames.iter().position(|f| !f.iter().all(|x| x.is_finite())) {
        return Err(TubeError::NonFinite {
            what: "frame",
            index,
        });
    }
    let tangents = centreline_tangents(centre)?;
    let m = settings.segments_around;
    let vertex_count = ring_vertex_count(n, m)?;

    // Direction of traversal per ring: +1 when d2 × d3 points along the marching direction.
    let mut handedness = Vec::with_capacity(n);
    for (index, (frame, tangent)) in frames.iter().zip(&tangents).enumerate() {
        let deviation = (frame.transpose() * frame - Mat3::identity()).abs().max();
        if deviation.is_nan() || deviation > settings.frame_tolerance {
            return Err(TubeError::FrameNotOrthonormal { index, deviation });
        }
        let section_normal = frame.column(1).cross(&frame.column(2));
        let cosine = section_normal.dot(tangent) / section_normal.norm();
        if cosine.is_nan() || cosine.abs() < settings.min_section_cosine || cosine == 0.0 {
            return Err(TubeError::SectionNotTransverse { index, cosine });
        }
        handedness.push(cosine.signum());
    }

    let mut mesh = TriangleMesh {
        vertices: Vec::with_capacity(vertex_count),
        triangles: Vec::with_capacity(2 * m * n),
    };
    let angles: Vec<(Real, Real)> = (0..m)
        .map(|k| (2.0 * PI * k as Real / m as Real).sin_cos())
        .collect();
    for (((c, frame), sign), &radius) in centre.iter().zip(frames).zip(&handedness).zip(radii) {
        let (d2, d3) = (frame.column(1).into_owned(), frame.column(2).into_owned());
        mesh.vertices.extend(
            angles
                .iter()
                .map(|&(sin, cos)| c + radius * (cos * d2 + sign * sin * d3)),
        );
    }

    // Indices fit u32: checked above.
    let m32 = m as u32;
    let at = |i: usize, k: u32| i as u32 * m32 + k % m32;
    for i in 0..n - 1 {
        for k in 0..m32 {
            let (a, b, c, d) = (at(i, k), at(i, k + 1), at(i + 1, k + 1), at(i + 1, k));
            mesh.triangles.push([a, b, c]);
            mesh.triangles.push([a, c, d]);
        }
    }
    // The start cap faces backwards (against the marching direction), the end cap forwards.
    if caps.start {
        let start = mesh.vertices.len() as u32;
        mesh.vertices.push(centre[0]);
        for k in 0..m32 {
            mesh.triangles.push([start, at(0, k + 1), at(0, k)]);
        }
    }
    if caps.end {
        let end = mesh.vertices.len() as u32;
        mesh.vertices.push(centre[n - 1]);
        for k in 0..m32 {
            mesh.triangles.push([end, at(n - 1, k), at(n - 1, k + 1)]);
        }
    }
    Ok(mesh)
}

/// The closed tube of radius `radius` around a spline curve, sampled at `samples + 1` uniform parameters with
/// its rotation-minimising frames. The section polygon is turned by `phase` segments (a fraction in `[0, 1)`)
/// about the axis: giving each patch of a device its own phase keeps the end rings of patches that meet at a
/// joint from coinciding vertex for vertex, which would make their edges non-manifold once an STL reader merges
/// equal vertices.
pub fn sweep_curve(
    curve: &crate::math::NurbsCurve,
    frames: &super::frame::FrameField,
    radius: Real,
    samples: usize,
    phase: Real,
    settings: &TubeSettings,
) -> Result<TriangleMesh, SweepError> {
    let (u0, u1) = curve.knots().domain();
    let samples = samples.max(1);
    let turn = crate::math::so3::exp(
        &(Vec3::x() * (2.0 * PI * phase / settings.segments_around.max(1) as Real)),
    );
    let mut centre = Vec::with_capacity(samples + 1);
    let mut rotations = Vec::with_capacity(samples + 1);
    for k in 0..=samples {
        let u = u0 + (u1 - u0) * k as Real / samples as Real;
        let f = frames.at(curve, u)?;
        centre.push(f.position);
        rotations.push(f.rotation * turn.matrix());
    }
    Ok(sweep_tube(&centre, &rotations, radius, settings)?)
}

/// Unit tangents of a sampled centreline by chord-length-weighted central differences.
///
/// At an interior sample the tangent is the derivative of the parabola through the sample and its two
/// neighbours, parametrised by chord length (second-order accurate on non-uniform samples; the plain
/// central difference `x_{i+1} − x_{i−1}` on uniform ones). At the ends it is the one-sided derivative of
/// the same parabola (second order), or the chord when there are only two samples.
pub(crate) fn centreline_tangents(centre: &[Vec3]) -> Result<Vec<Vec3>, TubeError> {
    let n = centre.len();
    if n < 2 {
        return Err(TubeError::TooFewSamples { count: n });
    }
    if let Some(index) = centre.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
        return Err(TubeError::NonFinite {
            what: "centre point",
            index,
        });
    }
    let chords: Vec<Vec3> = centre.windows(2).map(|w| w[1] - w[0]).collect();
    let lengths: Vec<Real> = chords.iter().map(|c| c.norm()).collect();
    if let Some(index) = lengths.iter().position(|&h| !(h > 0.0 && h.is_finite())) {
        return Err(TubeError::CoincidentSamples { index });
    }
    let unit = |v: Vec3, index: usize| v.try_normalize(0.0).ok_or(TubeError::ZeroTangent { index });
    if n == 2 {
        let t = unit(chords[0], 0)?;
        return Ok(vec![t, t]);
    }
    // Parabola through three samples with chord-length spacings h1, h2, differentiated at a node:
    // in terms of the unit chord directions u1, u2 (x1 − x0 = h1 u1, x2 − x1 = h2 u2).
    let mut tangents = Vec::with_capacity(n);
    let (h1, h2) = (lengths[0], lengths[1]);
    let (u1, u2) = (chords[0] / h1, chords[1] / h2);
    // p'(s0) = ((2h1 + h2) u1 − h1 u2) / (h1 + h2)
    tangents.push(unit((2.0 * h1 + h2) * u1 - h1 * u2, 0)?);
    for i in 1..n - 1 {
        let (h1, h2) = (lengths[i - 1], lengths[i]);
        let (u1, u2) = (chords[i - 1] / h1, chords[i] / h2);
        // p'(s1) = (h2 u1 + h1 u2) / (h1 + h2)
        tangents.push(unit(h2 * u1 + h1 * u2, i)?);
    }
    let (h1, h2) = (lengths[n - 3], lengths[n - 2]);
    let (u1, u2) = (chords[n - 3] / h1, chords[n - 2] / h2);
    // p'(s2) = ((h1 + 2h2) u2 − h2 u1) / (h1 + h2)
    tangents.push(unit((h1 + 2.0 * h2) * u2 - h2 * u1, n - 1)?);
    Ok(tangents)
}

/// Vertices of `rings` rings of `segments` vertices plus two cap (or pole) centres: the size of a swept tube
/// or a sphere, refused as [`TubeError::TooManyVertices`] when it does not fit the `u32` indices of a mesh.
pub(crate) fn ring_vertex_count(rings: usize, segments: usize) -> Result<usize, TubeError> {
    let count = rings
        .checked_mul(segments)
        .and_then(|v| v.checked_add(2))
        .unwrap_or(usize::MAX);
    if u32::try_from(count).is_err() {
        return Err(TubeError::TooManyVertices { vertices: count });
    }
    Ok(count)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::polyline::parallel_transport_frames;
    use crate::geometry::sphere::sphere;
    use crate::geometry::test_shapes::{
        flip_d3, helix, polygon_factor, ring, sci, settings, straight,
    };
    use nalgebra::{Rotation3, Unit};
    use proptest::prelude::*;

    // Checks: a straight tube (radius r, length L, m around, several samples, oblique placement) is closed and
    // outward, and its volume and area equal those of the inscribed prism.
    // Reference: the regular m-gon of circumradius r has area (m/2) r² sin(2π/m) and perimeter 2 m r sin(π/m);
    // the prism of length L has volume area·L and surface perimeter·L + 2·area (exact for planar quads/caps).
    // Tolerance 1e-12 relative: the sums have ~10² terms of rounding 1e-16 each; the shape is exact.
    #[test]
    fn straight_tube_matches_inscribed_prism() {
        let (r, length) = (0.3, 2.5);
        let rotation =
            Rotation3::from_axis_angle(&Unit::new_normalize(Vec3::new(1.0, -2.0, 0.5)), 0.7);
        for m in [3, 4, 7, 16, 33] {
            for n in [2, 5] {
                let (centre, frames) =
                    straight(Vec3::new(10.0, -3.0, 7.0), rotation.matrix(), length, n);
                let mesh = sweep_tube(&centre, &frames, r, &settings(m)).expect("valid tube");
                assert_eq!(mesh.check_closed(), Ok(()));
                assert_eq!(mesh.vertices.len(), n * m + 2);
                assert_eq!(mesh.triangles.len(), 2 * m * (n - 1) + 2 * m);
                let section = 0.5 * m as Real * r * r * (2.0 * PI / m as Real).sin();
                let perimeter = 2.0 * m as Real * r * (PI / m as Real).sin();
                let (v, a) = (mesh.volume(), mesh.area());
                assert!(v > 0.0);
                assert!(
                    (v / (section * length) - 1.0).abs() < 1e-12,
                    "m={m} n={n}: V={v}"
                );
                assert!(
                    (a / (perimeter * length + 2.0 * section) - 1.0).abs() < 1e-12,
                    "m={m}: A={a}"
                );
            }
        }
    }

    // Checks: the tube along a full circle (a torus with a seam where two opposite caps coincide) is closed,
    // outward, and its volume follows the closed form; then that the volume converges to π r²·2πR at O(1/m²).
    // Reference (derived for this test, Pappus-like): each piece between two meridian sections Δ = 2π/N apart,
    // joined by straight segments, has volume sin(Δ)·A·R (Jacobian ρ sin Δ, centroid at R), so
    // V = π r² · 2πR · f(m) · f(N) with f(x) = sin(2π/x)/(2π/x). Tolerance 1e-12: exact geometry, rounding only.
    // Convergence: 1 − f(x) = (2π/x)²/6 + O(x⁻⁴), so with N = 4m the error ratio between m and 2m is
    // 4 (1 − O(1/m²)): measured 3.896, 3.974, 3.993 for m = 8→16→32→64.
    #[test]
    fn ring_volume_closed_form_and_second_order_convergence() {
        let (big_r, r) = (2.0, 0.25);
        let exact = PI * r * r * 2.0 * PI * big_r;
        let mut errors = Vec::new();
        for m in [8, 16, 32, 64] {
            let n = 4 * m;
            let (centre, frames) = ring(big_r, n);
            let mesh = sweep_tube(&centre, &frames, r, &settings(m)).expect("valid ring");
            assert_eq!(mesh.check_closed(), Ok(()));
            let v = mesh.volume();
            let closed_form = exact * polygon_factor(m) * polygon_factor(n);
            assert!(
                (v / closed_form - 1.0).abs() < 1e-12,
                "m={m}: V={v}, closed form {closed_form}"
            );
            errors.push(1.0 - v / exact);
        }
        let ratios: Vec<Real> = errors.windows(2).map(|e| e[0] / e[1]).collect();
        eprintln!(
            "ring relative volume errors {}, ratios {ratios:.4?}",
            sci(&errors)
        );
        assert!(
            errors.iter().all(|&e| e > 0.0),
            "inscribed polygons under-estimate the volume"
        );
        // Ratios rise monotonically towards 4 from below (the O(1/m⁴) term has the opposite sign).
        assert!(ratios.windows(2).all(|w| w[0] < w[1]), "{ratios:?}");
        assert!(
            ratios.iter().all(|&q| q < 4.0) && ratios[ratios.len() - 1] > 3.99,
            "{ratios:?}"
        );
        // At m = 64 the error matches its leading term (2π/m)²/6 · (1 + (m/N)²) to 1 %.
        let leading = (2.0 * PI / 64.0).powi(2) / 6.0 * (1.0 + 1.0 / 16.0);
        assert!(
            (errors[3] / leading - 1.0).abs() < 0.01,
            "{} vs {leading}",
            errors[3]
        );
    }

    // Checks: a helix tube with parallel-transport frames is closed and outward, and its volume converges
    // to π r² · L (L = arc length = turns·2π·√(R² + h²)) at second order in the resolution.
    // Reference: the exact volume of a tube of radius r about a curve with curvature κ r < 1 is π r² L
    // (Pappus/Weyl tube formula). Discrete errors: the inscribed section (2π/m)²/6, and the chords and
    // second-order tangents along the curve, O(1/N²) with N ∝ m. Expected ratio of errors at m and 2m: 4;
    // accepted 3.8 … 4.2 (the O(1/m⁴) remainder at m = 8 is a few %); measured 3.898, 3.974, 3.994.
    #[test]
    fn helix_volume_converges_at_second_order() {
        let (big_r, h, turns, r): (Real, Real, Real, Real) = (1.0, 0.3, 2.0, 0.1);
        let length = turns * 2.0 * PI * (big_r * big_r + h * h).sqrt();
        let exact = PI * r * r * length;
        let mut errors = Vec::new();
        for m in [8, 16, 32, 64] {
            let centre = helix(big_r, h, turns, 8 * m + 1);
            let frames = parallel_transport_frames(&centre).expect("valid helix");
            let mesh = sweep_tube(&centre, &frames, r, &settings(m)).expect("valid tube");
            assert_eq!(mesh.check_closed(), Ok(()));
            let v = mesh.volume();
            assert!(v > 0.0);
            errors.push((v - exact).abs() / exact);
        }
        let ratios: Vec<Real> = errors.windows(2).map(|e| e[0] / e[1]).collect();
        eprintln!(
            "helix relative volume errors {}, ratios {ratios:.4?}",
            sci(&errors)
        );
        for (i, ratio) in ratios.iter().enumerate() {
            assert!((3.8..=4.2).contains(ratio), "ratio {i} = {ratio}");
        }
    }

    // Checks: the chord-weighted tangents (interior and one-sided end formulas) are second-order accurate on
    // non-uniform samples.
    // Reference: the exact unit tangent ∝ (1, 2 cos 2t, t) of the space curve (t, sin 2t, t²/2), sampled at
    // t_i = 2(s_i + 0.3 s_i²) (spacing varying by a factor 1.6). (A circle would be a poor test: there the
    // interior formula is exact.) Expected: error ∝ h², so the ratio when halving h tends to 4; measured
    // 3.93 (max error 7.1e-3 → 1.8e-3, 41 → 81 samples), accepted 3.5 … 4.5.
    #[test]
    fn tangents_are_second_order_on_nonuniform_samples() {
        let max_error = |n: usize| {
            let params: Vec<Real> = (0..n)
                .map(|i| i as Real / (n - 1) as Real)
                .map(|s| 2.0 * (s + 0.3 * s * s))
                .collect();
            let centre: Vec<Vec3> = params
                .iter()
                .map(|&t| Vec3::new(t, (2.0 * t).sin(), 0.5 * t * t))
                .collect();
            let tangents = centreline_tangents(&centre).expect("valid curve");
            params
                .iter()
                .zip(&tangents)
                .map(|(&t, d)| (d - Vec3::new(1.0, 2.0 * (2.0 * t).cos(), t).normalize()).norm())
                .fold(0.0, Real::max)
        };
        let (coarse, fine) = (max_error(41), max_error(81));
        eprintln!(
            "tangent errors {coarse:.3e} → {fine:.3e}, ratio {:.3}",
            coarse / fine
        );
        assert!((3.5..=4.5).contains(&(coarse / fine)), "{coarse} {fine}");
    }

    // Checks: frames with d2 × d3 = −d1 (left-handed) or with handedness changing from sample to sample
    // give the same outward tube as right-handed ones.
    // Reference: the right-handed tube of the same centreline. Tolerance 1e-12: same vertices, same
    // triangles up to order — only rounding differs.
    #[test]
    fn left_handed_frames_still_give_outward_tubes() {
        let (r, m) = (0.25, 12);
        let (centre, frames) = ring(2.0, 40);
        let reference = sweep_tube(&centre, &frames, r, &settings(m))
            .expect("valid ring")
            .volume();
        assert!(reference > 0.0);
        let left: Vec<Mat3> = frames.iter().map(flip_d3).collect();
        let mixed: Vec<Mat3> = frames
            .iter()
            .enumerate()
            .map(|(i, f)| if i % 3 == 0 { flip_d3(f) } else { *f })
            .collect();
        // d1 reversed (marching against d1) with a proper rotation: (−d1, d3, d2) has d2' × d3' = −d1 · (−1).
        let reversed: Vec<Mat3> = frames
            .iter()
            .map(|f| {
                Mat3::from_columns(&[
                    -f.column(0),
                    f.column(2).into_owned(),
                    f.column(1).into_owned(),
                ])
            })
            .collect();
        for (name, frames) in [("left", left), ("mixed", mixed), ("reversed d1", reversed)] {
            let mesh = sweep_tube(&centre, &frames, r, &settings(m)).expect("valid ring");
            assert_eq!(mesh.check_closed(), Ok(()), "{name}");
            let v = mesh.volume();
            assert!(
                (v / reference - 1.0).abs() < 1e-12,
                "{name}: {v} vs {reference}"
            );
        }
        // The same for a straight tube whose frame marches against d2 × d3.
        let (centre, frames) = straight(Vec3::zeros(), &flip_d3(&Mat3::identity()), 1.0, 3);
        let mesh = sweep_tube(&centre, &frames, 0.1, &settings(5)).expect("valid tube");
        assert_eq!(mesh.check_closed(), Ok(()));
        assert!(mesh.volume() > 0.0);
    }

    // Checks: every kind of bad input gives its error, and none panics.
    #[test]
    fn bad_input_gives_errors() {
        let s = TubeSettings::default();
        let (centre, frames) = straight(Vec3::zeros(), &Mat3::identity(), 1.0, 3);
        let sweep =
            |c: &[Vec3], f: &[Mat3], r: Real, s: &TubeSettings| sweep_tube(c, f, r, s).map(|_| ());
        assert_eq!(
            sweep(&centre[..1], &frames[..1], 0.1, &s),
            Err(TubeError::TooFewSamples { count: 1 })
        );
        assert_eq!(
            sweep(&[], &[], 0.1, &s),
            Err(TubeError::TooFewSamples { count: 0 })
        );
        assert_eq!(
            sweep(&centre, &frames[..2], 0.1, &s),
            Err(TubeError::LengthMismatch {
                centre: 3,
                frames: 2
            })
        );
        for radius in [0.0, -1.0, Real::NAN, Real::INFINITY] {
            assert!(matches!(
                sweep(&centre, &frames, radius, &s),
                Err(TubeError::InvalidRadius { .. })
            ));
        }
        let mut nan_centre = centre.clone();
        nan_centre[1].y = Real::NAN;
        assert_eq!(
            sweep(&nan_centre, &frames, 0.1, &s),
            Err(TubeError::NonFinite {
                what: "centre point",
                index: 1
            })
        );
        let mut nan_frames = frames.clone();
        nan_frames[2][(0, 1)] = Real::INFINITY;
        assert_eq!(
            sweep(&centre, &nan_frames, 0.1, &s),
            Err(TubeError::NonFinite {
                what: "frame",
                index: 2
            })
        );
        assert_eq!(
            sweep(&centre, &frames, 0.1, &settings(2)),
            Err(TubeError::TooFewSegments { segments: 2 })
        );
        let bad_tol = TubeSettings {
            frame_tolerance: Real::NAN,
            ..s.clone()
        };
        assert!(matches!(
            sweep(&centre, &frames, 0.1, &bad_tol),
            Err(TubeError::InvalidSetting { .. })
        ));
        let repeated = vec![centre[0], centre[1], centre[1]];
        assert_eq!(
            sweep(&repeated, &frames, 0.1, &s),
            Err(TubeError::CoincidentSamples { index: 1 })
        );
        let back_and_forth = vec![centre[0], centre[1], centre[0]];
        assert_eq!(
            sweep(&back_and_forth, &frames, 0.1, &s),
            Err(TubeError::ZeroTangent { index: 1 })
        );
        let mut scaled = frames.clone();
        scaled[1] *= 1.01;
        assert!(matches!(
            sweep(&centre, &scaled, 0.1, &s),
            Err(TubeError::FrameNotOrthonormal { index: 1, .. })
        ));
        // Section plane containing the centreline: frame rotated a quarter turn about d2.
        let mut tilted = frames.clone();
        tilted[0] = *Rotation3::from_axis_angle(&Vec3::y_axis(), PI / 2.0).matrix();
        assert!(matches!(
            sweep(&centre, &tilted, 0.1, &s),
            Err(TubeError::SectionNotTransverse { index: 0, .. })
        ));
        assert_eq!(
            parallel_transport_frames(&centre[..1]),
            Err(TubeError::TooFewSamples { count: 1 })
        );
        assert_eq!(
            parallel_transport_frames(&nan_centre),
            Err(TubeError::NonFinite {
                what: "centre point",
                index: 1
            })
        );
        assert_eq!(
            parallel_transport_frames(&repeated),
            Err(TubeError::CoincidentSamples { index: 1 })
        );
        assert!(matches!(
            sphere(&Vec3::zeros(), 0.0, &s),
            Err(TubeError::InvalidRadius { .. })
        ));
        assert!(matches!(
            sphere(&Vec3::zeros(), 1.0, &settings(0)),
            Err(TubeError::TooFewSegments { .. })
        ));
        assert!(matches!(
            sphere(&Vec3::new(Real::NAN, 0.0, 0.0), 1.0, &s),
            Err(TubeError::NonFinite { .. })
        ));
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

        // Checks: for any placement (rotation, translation), handedness, resolution and size, a straight
        // tube is closed, outward and has the inscribed prism's volume.
        // Reference: (m/2) r² sin(2π/m) L. Tolerance 1e-10 relative: translations up to 100 lengths cost
        // up to ~2 digits of cancellation in the vertex coordinates.
        #[test]
        fn straight_tube_invariants(
            axis in prop::array::uniform3(-1.0..1.0f64),
            angle in 0.0..PI,
            shift in prop::array::uniform3(-100.0..100.0f64),
            m in 3usize..40,
            n in 2usize..8,
            r in 0.01..2.0f64,
            length in 0.1..10.0f64,
            left_handed in any::<bool>(),
        ) {
            let axis = Unit::try_new(Vec3::from(axis), 1e-3).unwrap_or(Vec3::z_axis());
            let rotation = *Rotation3::from_axis_angle(&axis, angle).matrix();
            let frame = if left_handed { flip_d3(&rotation) } else { rotation };
            let (centre, frames) = straight(Vec3::from(shift), &frame, length, n);
            let mesh = sweep_tube(&centre, &frames, r, &settings(m)).expect("valid tube");
            prop_assert_eq!(mesh.check_closed(), Ok(()));
            let expected = 0.5 * m as Real * r * r * (2.0 * PI / m as Real).sin() * length;
            prop_assert!((mesh.volume() / expected - 1.0).abs() < 1e-10);
        }
    }
}
