//! Closed tube surfaces swept along centrelines: vertices and outward-oriented triangles.
//!
//! This module owns the crate's surface vocabulary, [`TriangleMesh`] (indexed triangles, counter-clockwise
//! seen from outside), its integral checks ([`TriangleMesh::volume`], [`TriangleMesh::area`]) and its
//! topological check ([`TriangleMesh::check_closed`], which reports a [`MeshDefect`]), and the generators
//! that produce closed shells from rod data:
//!
//! * [`sweep_tube`] — a circular section of radius `r` swept along sampled centre points with given
//!   section frames, closed at both ends by flat caps;
//! * [`parallel_transport_frames`] — rotation-minimising frames for a bare polyline (double reflection,
//!   Wang, Jüttler, Zheng & Liu 2008), for deformed centrelines where the circular section makes twist
//!   irrelevant;
//! * [`sphere`] — a closed UV sphere, to round joints if wanted.
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
//! Nothing here writes files: the `io` layer turns a [`TriangleMesh`] into STL or OBJ.

use std::collections::HashMap;
use std::f64::consts::PI;

use crate::math::{Mat3, Real, Vec3};

/// A triangle is degenerate (zero area) when twice its area, `|(b − a) × (c − a)|`, is at most this
/// fraction of its longest edge squared, i.e. when its height is below `1e-12` times its longest edge.
///
/// Relative, so the check is the same in any unit system; `1e-12` is about 4500 ulps of `f64`, far below
/// any triangle a sweep of sensible resolution produces (a slender side triangle of a tube `10⁶` radii long
/// still has a height ratio near `10⁻⁷`), and far above the rounding noise of exactly collinear points.
pub const DEGENERATE_TRIANGLE_TOLERANCE: Real = 1e-12;

/// A surface made of indexed triangles.
///
/// Each triangle lists its vertices counter-clockwise seen from outside, so that by the right-hand rule
/// `(b − a) × (c − a)` points outward. Indices are `u32` (the STL/OBJ and GPU convention), which caps a
/// mesh at `u32::MAX` vertices.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions \[length\].
    pub vertices: Vec<Vec3>,
    /// Triangles as indices into [`TriangleMesh::vertices`], counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// Why a mesh is not a closed, consistently oriented surface; returned by [`TriangleMesh::check_closed`].
///
/// Each variant names the first offending item (in triangle order) and how many items share the defect.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshDefect {
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "triangle {triangle} refers to vertex {index}, but the mesh has {vertex_count} vertices"
    )]
    IndexOutOfRange {
        /// Triangle index.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices in the mesh.
        vertex_count: usize,
    },
    /// A triangle uses the same vertex twice.
    #[error("triangle {triangle} repeats a vertex: {indices:?} ({count} such triangles)")]
    RepeatedIndex {
        /// Triangle index.
        triangle: usize,
        /// Its vertex indices.
        indices: [u32; 3],
        /// Number of triangles with a repeated index.
        count: usize,
    },
    /// A triangle has (numerically) zero area; see [`DEGENERATE_TRIANGLE_TOLERANCE`].
    #[error(
        "triangle {triangle} {indices:?} is degenerate: height/longest edge = {relative_height:e} \
         ({count} degenerate triangles)"
    )]
    ZeroArea {
        /// Triangle index.
        triangle: usize,
        /// Its vertex indices.
        indices: [u32; 3],
        /// `|(b − a) × (c − a)| / (longest edge)²` (0 for coincident points, NaN for non-finite ones).
        relative_height: Real,
        /// Number of degenerate triangles.
        count: usize,
    },
    /// An edge belongs to one triangle only: the surface has a hole.
    #[error("edge {edge:?} of triangle {triangle} is a boundary edge ({count} boundary edges)")]
    BoundaryEdge {
        /// The edge, as directed in `triangle`.
        edge: [u32; 2],
        /// The triangle that has it.
        triangle: usize,
        /// Number of boundary edges.
        count: usize,
    },
    /// An edge belongs to more than two triangles.
    #[error(
        "edge {edge:?} of triangle {triangle} is shared by {triangles} triangles \
         ({count} non-manifold edges)"
    )]
    NonManifoldEdge {
        /// The edge, as directed in `triangle`.
        edge: [u32; 2],
        /// The first triangle that has it.
        triangle: usize,
        /// How many triangles share it.
        triangles: usize,
        /// Number of non-manifold edges.
        count: usize,
    },
    /// Two triangles traverse their common edge in the same direction: their orientations disagree.
    #[error(
        "triangles {triangles:?} both traverse edge {edge:?} in the same direction \
         ({count} inconsistently oriented edges)"
    )]
    InconsistentOrientation {
        /// The edge, as directed in both triangles.
        edge: [u32; 2],
        /// The two triangles.
        triangles: [usize; 2],
        /// Number of inconsistently oriented edges.
        count: usize,
    },
    /// A vertex is used by no triangle.
    #[error("vertex {vertex} is used by no triangle ({count} unused vertices)")]
    UnusedVertex {
        /// Vertex index.
        vertex: usize,
        /// Number of unused vertices.
        count: usize,
    },
}

/// Per undirected edge: how often it is used in each direction and by which triangles first.
#[derive(Debug, Clone, Copy)]
struct EdgeUse {
    /// Uses from the smaller to the larger vertex index.
    forward: usize,
    /// Uses from the larger to the smaller vertex index.
    backward: usize,
    /// The first two triangles that use the edge.
    first: [usize; 2],
}

impl TriangleMesh {
    /// An empty mesh.
    pub fn new() -> Self {
        Self::default()
    }

    /// `true` when the mesh has no triangles.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Appends `other`'s vertices and triangles (indices shifted); the result is the union of both surfaces.
    ///
    /// # Panics
    /// If the combined vertex count does not fit the `u32` indices (more than 4·10⁹ vertices).
    #[track_caller]
    pub fn append(&mut self, other: &TriangleMesh) {
        let offset = u32::try_from(self.vertices.len())
            .ok()
            .filter(|&o| {
                u32::try_from(other.vertices.len()).is_ok_and(|n| o.checked_add(n).is_some())
            })
            .unwrap_or_else(|| {
                panic!(
                    "appending {} vertices to {} overflows the u32 vertex indices",
                    other.vertices.len(),
                    self.vertices.len()
                )
            });
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles.extend(
            other
                .triangles
                .iter()
                // Saturating: an index already out of range in `other` stays out of range here.
                .map(|t| t.map(|i| i.saturating_add(offset))),
        );
    }

    /// The three corner positions of triangle `t`.
    ///
    /// # Panics
    /// If `t` or one of its indices is out of range ([`TriangleMesh::check_closed`] reports the latter).
    #[track_caller]
    pub fn corners(&self, t: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[t];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }

    /// The unit normal of triangle `t` by the right-hand rule (outward for a correctly oriented mesh);
    /// the zero vector for a degenerate triangle.
    ///
    /// # Panics
    /// As [`TriangleMesh::corners`].
    #[track_caller]
    pub fn triangle_normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.corners(t);
        (b - a)
            .cross(&(c - a))
            .try_normalize(0.0)
            .unwrap_or_else(Vec3::zeros)
    }

    /// The signed enclosed volume \[length³\] by the divergence theorem,
    /// `V = (1/6) Σ (a − o) · ((b − o) × (c − o))` over all triangles.
    ///
    /// Positive for a closed, outward-oriented surface; for a closed surface the result does not depend on
    /// the reference point `o`, which is taken at the bounding-box centre to keep the sum free of
    /// cancellation when the mesh sits far from the origin. For an open surface the value is meaningless.
    ///
    /// # Panics
    /// If a triangle index is out of range (see [`TriangleMesh::check_closed`]).
    pub fn volume(&self) -> Real {
        let Some((lo, hi)) = self.bounding_box() else {
            return 0.0;
        };
        let o = (lo + hi) * 0.5;
        let six_v: Real = (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                (a - o).dot(&(b - o).cross(&(c - o)))
            })
            .sum();
        six_v / 6.0
    }

    /// The total surface area \[length²\], `Σ |(b − a) × (c − a)| / 2`.
    ///
    /// # Panics
    /// If a triangle index is out of range (see [`TriangleMesh::check_closed`]).
    pub fn area(&self) -> Real {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum()
    }

    /// The axis-aligned bounding box `(min, max)` of the vertices, `None` for a mesh without vertices.
    pub fn bounding_box(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.vertices.first()?;
        Some(
            self.vertices
                .iter()
                .fold((first, first), |(lo, hi), v| (lo.inf(v), hi.sup(v))),
        )
    }

    /// Checks that the mesh is a closed, consistently oriented 2-manifold surface (possibly several shells):
    ///
    /// 1. every index is in range, and no triangle repeats a vertex;
    /// 2. no triangle is degenerate ([`DEGENERATE_TRIANGLE_TOLERANCE`]);
    /// 3. every undirected edge is shared by exactly two triangles, which traverse it in opposite directions
    ///    (so the orientation is consistent across the edge);
    /// 4. every vertex is used by some triangle.
    ///
    /// The first failing check is reported, naming its first offending item in triangle (or vertex) order
    /// and how many items fail it. An empty mesh is (vacuously) closed. Consistent orientation does not
    /// by itself mean *outward*: a closed, consistent mesh is outward exactly when
    /// [`TriangleMesh::volume`] is positive (per shell).
    pub fn check_closed(&self) -> Result<(), MeshDefect> {
        let vertex_count = self.vertices.len();
        // 1. Indices.
        for (t, tri) in self.triangles.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i as usize >= vertex_count) {
                return Err(MeshDefect::IndexOutOfRange {
                    triangle: t,
                    index,
                    vertex_count,
                });
            }
        }
        let repeats = |tri: &[u32; 3]| tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0];
        let repeated: Vec<usize> = self
            .triangles
            .iter()
            .enumerate()
            .filter(|(_, tri)| repeats(tri))
            .map(|(t, _)| t)
            .collect();
        if let Some(&t) = repeated.first() {
            return Err(MeshDefect::RepeatedIndex {
                triangle: t,
                indices: self.triangles[t],
                count: repeated.len(),
            });
        }
        // 2. Degenerate triangles.
        let relative_heights: Vec<Real> = (0..self.triangles.len())
            .map(|t| self.relative_height(t))
            .collect();
        // NaN comes from non-finite coordinates.
        let is_degenerate = |h: Real| h.is_nan() || h <= DEGENERATE_TRIANGLE_TOLERANCE;
        let degenerate_count = relative_heights
            .iter()
            .filter(|&&h| is_degenerate(h))
            .count();
        if let Some(t) = relative_heights.iter().position(|&h| is_degenerate(h)) {
            return Err(MeshDefect::ZeroArea {
                triangle: t,
                indices: self.triangles[t],
                relative_height: relative_heights[t],
                count: degenerate_count,
            });
        }
        // 3. Edges.
        let mut edges: HashMap<(u32, u32), EdgeUse> =
            HashMap::with_capacity(self.triangles.len() * 3 / 2);
        for (t, tri) in self.triangles.iter().enumerate() {
            for (u, v) in directed_edges(tri) {
                let entry = edges.entry((u.min(v), u.max(v))).or_insert(EdgeUse {
                    forward: 0,
                    backward: 0,
                    first: [t, usize::MAX],
                });
                if entry.forward + entry.backward == 1 {
                    entry.first[1] = t;
                }
                if u < v {
                    entry.forward += 1;
                } else {
                    entry.backward += 1;
                }
            }
        }
        let uses = |e: &EdgeUse| e.forward + e.backward;
        let boundary = edges.values().filter(|e| uses(e) == 1).count();
        let non_manifold = edges.values().filter(|e| uses(e) > 2).count();
        let misoriented = edges
            .values()
            .filter(|e| uses(e) == 2 && e.forward != 1)
            .count();
        // Report in triangle order, so the message is deterministic.
        let first_edge = |pred: &dyn Fn(&EdgeUse) -> bool| {
            self.triangles.iter().enumerate().find_map(|(t, tri)| {
                directed_edges(tri).into_iter().find_map(|(u, v)| {
                    let e = edges[&(u.min(v), u.max(v))];
                    pred(&e).then_some((t, [u, v], e))
                })
            })
        };
        if boundary > 0
            && let Some((triangle, edge, _)) = first_edge(&|e| uses(e) == 1)
        {
            return Err(MeshDefect::BoundaryEdge {
                edge,
                triangle,
                count: boundary,
            });
        }
        if non_manifold > 0
            && let Some((triangle, edge, e)) = first_edge(&|e| uses(e) > 2)
        {
            return Err(MeshDefect::NonManifoldEdge {
                edge,
                triangle,
                triangles: uses(&e),
                count: non_manifold,
            });
        }
        if misoriented > 0
            && let Some((_, edge, e)) = first_edge(&|e| uses(e) == 2 && e.forward != 1)
        {
            return Err(MeshDefect::InconsistentOrientation {
                edge,
                triangles: e.first,
                count: misoriented,
            });
        }
        // 4. Unused vertices.
        let mut used = vec![false; vertex_count];
        for tri in &self.triangles {
            for &i in tri {
                used[i as usize] = true;
            }
        }
        let unused = used.iter().filter(|&&u| !u).count();
        if let Some(vertex) = used.iter().position(|&u| !u) {
            return Err(MeshDefect::UnusedVertex {
                vertex,
                count: unused,
            });
        }
        Ok(())
    }

    /// `|(b − a) × (c − a)| / (longest edge)²` of triangle `t`, i.e. its height over its longest edge
    /// (twice the area is that edge times that height); 0 for coincident or collinear corners.
    fn relative_height(&self, t: usize) -> Real {
        let [a, b, c] = self.corners(t);
        let longest2 = (b - a)
            .norm_squared()
            .max((c - b).norm_squared())
            .max((a - c).norm_squared());
        if longest2 == 0.0 {
            return 0.0;
        }
        (b - a).cross(&(c - a)).norm() / longest2
    }

    /// The mirror image in the plane through `plane_point` with normal `plane_normal` (any length), with
    /// every triangle's winding reversed so that the image of an outward-oriented surface is again
    /// outward-oriented (a reflection reverses handedness). Volume and area are preserved.
    ///
    /// Used to restore the full device from a symmetry-reduced model: append the mirrored copy to the
    /// original. Vertices on the plane are duplicated, not merged, so each half stays a closed shell
    /// ([`TriangleMesh::mirrored_welded`] joins open surfaces along the plane instead).
    ///
    /// # Panics
    /// If `plane_normal` is zero or not finite (a symmetry plane is validated when the design is read).
    #[track_caller]
    pub fn mirrored(&self, plane_point: &Vec3, plane_normal: &Vec3) -> TriangleMesh {
        let n = plane_normal
            .try_normalize(0.0)
            .filter(|n| n.iter().all(|x| x.is_finite()))
            .unwrap_or_else(|| {
                panic!("mirror plane normal {plane_normal:?} is zero or not finite")
            });
        TriangleMesh {
            vertices: self
                .vertices
                .iter()
                .map(|v| v - 2.0 * (v - plane_point).dot(&n) * n)
                .collect(),
            triangles: self.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect(),
        }
    }

    /// This mesh together with its mirror image in the plane through `plane_point` with normal `plane_normal`,
    /// welded along `seam`: vertices of this mesh lying in the plane (ends of rods on a symmetry plane, left
    /// uncapped). A seam vertex is projected onto the plane and shared by both copies, so the boundary rings
    /// of an open surface and of its mirror image become interior edges of one surface.
    ///
    /// Returns the welded mesh and, for every vertex `i` of this mesh, the index of its mirror image in the
    /// result (`i` itself for a seam vertex). Vertex `i < self.vertices.len()` of the result is vertex `i` of
    /// this mesh; the mirrored triangles follow the original ones, with their winding reversed.
    ///
    /// # Panics
    /// As [`TriangleMesh::mirrored`]; also if a seam index is out of range.
    #[track_caller]
    pub fn mirrored_welded(
        &self,
        plane_point: &Vec3,
        plane_normal: &Vec3,
        seam: &[u32],
    ) -> (TriangleMesh, Vec<u32>) {
        let mirror = self.mirrored(plane_point, plane_normal);
        let normal = plane_normal.normalize();
        let count = self.vertices.len();
        let mut on_seam = vec![false; count];
        let mut out = self.clone();
        for &i in seam {
            let i = i as usize;
            assert!(i < count, "seam vertex {i} of a mesh with {count} vertices");
            on_seam[i] = true;
            let v = out.vertices[i];
            out.vertices[i] = v - (v - plane_point).dot(&normal) * normal;
        }
        let mut image = Vec::with_capacity(count);
        for (i, &seam_vertex) in on_seam.iter().enumerate() {
            if seam_vertex {
                image.push(i as u32);
            } else {
                image.push(u32::try_from(out.vertices.len()).unwrap_or_else(|_| {
                    panic!("mirroring {count} vertices overflows the u32 vertex indices")
                }));
                out.vertices.push(mirror.vertices[i]);
            }
        }
        out.triangles.extend(
            mirror
                .triangles
                .iter()
                .map(|t| t.map(|i| image[i as usize])),
        );
        (out, image)
    }
}

/// The three directed edges `(a, b), (b, c), (c, a)` of a triangle.
fn directed_edges(tri: &[u32; 3]) -> [(u32, u32); 3] {
    [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])]
}

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
    /// Largest angle [rad] between a ring's section normal (`d2 × d3`) and the sampled centreline direction
    /// that [`device_mesh`] draws as given. Coarse samples of a bent rod tilt the sections against the polyline
    /// that joins them (by half the angle the rod turns between two samples): two rings on a patch bent into a
    /// half circle put both sections edge-on to the chord, which no tube can be swept through. A ring tilted
    /// further is turned, about the axis normal to both directions, until its tilt is this angle. Default
    /// `π/3` (60°): up to 120° of turn between samples is drawn as the solver's sections; the default 41
    /// rings per patch never come close.
    pub max_section_tilt: Real,
    /// Largest distance of an end ring from a symmetry plane, as a fraction of the tube radius, for
    /// [`device_mesh`] to treat the ring as lying in the plane (left open and welded to its mirror image).
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

impl TubeSettings {
    /// Checks the settings' ranges.
    fn validate(&self) -> Result<(), TubeError> {
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
/// (the centreline tangent estimated from the samples, see [`parallel_transport_frames`]): when
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

/// [`sweep_tube`] with a choice of caps. An uncapped end leaves its ring as a boundary: the surface is open
/// there, meant to be welded to another surface sharing the same ring (the mirror image of a rod ending on a
/// symmetry plane, see [`device_mesh`]).
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
    if !(radius > 0.0 && radius.is_finite()) {
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
    let vertex_count = n
        .checked_mul(m)
        .and_then(|v| v.checked_add(2))
        .unwrap_or(usize::MAX);
    if u32::try_from(vertex_count).is_err() {
        return Err(TubeError::TooManyVertices {
            vertices: vertex_count,
        });
    }

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
    for ((c, frame), sign) in centre.iter().zip(frames).zip(&handedness) {
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

/// Unit tangents of a sampled centreline by chord-length-weighted central differences.
///
/// At an interior sample the tangent is the derivative of the parabola through the sample and its two
/// neighbours, parametrised by chord length (second-order accurate on non-uniform samples; the plain
/// central difference `x_{i+1} − x_{i−1}` on uniform ones). At the ends it is the one-sided derivative of
/// the same parabola (second order), or the chord when there are only two samples.
fn centreline_tangents(centre: &[Vec3]) -> Result<Vec<Vec3>, TubeError> {
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

/// Rotation-minimising (parallel-transport) frames along a polyline, by the double reflection method of
/// Wang, Jüttler, Zheng & Liu, *Computation of rotation minimizing frames*, ACM TOG 27(1), 2008, §4.
///
/// Frame `i` has columns `d1 = t_i` (unit tangent by chord-weighted central differences, second order,
/// see [`sweep_tube`]), `d2 = r_i`, `d3 = t_i × r_i` (a proper rotation). The first reference vector
/// `r_0` is the coordinate axis least aligned with `t_0`, made orthogonal to it. Each next one is obtained
/// by reflecting `(r_i, t_i)` in the bisector plane of `x_i, x_{i+1}` (normal `v1 = x_{i+1} − x_i`) and
/// then in the plane that maps the reflected tangent onto `t_{i+1}` (normal `v2 = t_{i+1} − t_i^L`):
///
/// ```text
/// r_i^L = r_i − 2 (v1·r_i)/(v1·v1) v1,   t_i^L = t_i − 2 (v1·t_i)/(v1·v1) v1,
/// r_{i+1} = r_i^L − 2 (v2·r_i^L)/(v2·v2) v2   (no second reflection when v2 = 0).
/// ```
///
/// With exact tangents the method is fourth-order accurate; here the tangents are second-order, which
/// limits the frames to second order. Meant for deformed centrelines drawn as tubes, where a circular
/// section makes the twist about `d1` invisible; the reference frames of the rod model come from
/// `geometry::frame`.
///
/// # Errors
/// [`TubeError::TooFewSamples`], [`TubeError::NonFinite`], [`TubeError::CoincidentSamples`] or
/// [`TubeError::ZeroTangent`] when the polyline cannot define tangents.
pub fn parallel_transport_frames(centre: &[Vec3]) -> Result<Vec<Mat3>, TubeError> {
    let tangents = centreline_tangents(centre)?;
    let t0 = tangents[0];
    // The coordinate axis least aligned with t0 is at least 54.7° away from it, so r0 is well conditioned.
    let axis = (0..3)
        .min_by(|&a, &b| t0[a].abs().total_cmp(&t0[b].abs()))
        .map_or_else(Vec3::x, |a| Vec3::ith(a, 1.0));
    let mut r = (axis - axis.dot(&t0) * t0).normalize();
    let mut frames = Vec::with_capacity(centre.len());
    frames.push(Mat3::from_columns(&[t0, r, t0.cross(&r)]));
    for i in 0..centre.len() - 1 {
        let (t, t_next) = (tangents[i], tangents[i + 1]);
        let v1 = centre[i + 1] - centre[i];
        let c1 = v1.norm_squared(); // > 0: coincident samples were rejected.
        let r_l = r - (2.0 / c1) * v1.dot(&r) * v1;
        let t_l = t - (2.0 / c1) * v1.dot(&t) * v1;
        let v2 = t_next - t_l;
        let c2 = v2.norm_squared();
        r = if c2 > 0.0 {
            r_l - (2.0 / c2) * v2.dot(&r_l) * v2
        } else {
            r_l
        };
        // Reflections preserve length and orthogonality to rounding; re-orthonormalise against drift.
        r = (r - r.dot(&t_next) * t_next).normalize();
        frames.push(Mat3::from_columns(&[t_next, r, t_next.cross(&r)]));
    }
    Ok(frames)
}

/// A closed UV sphere of `radius` about `center`: `segments_around` meridians, `max(2, m/2)` latitude
/// bands, and a vertex at each pole (z axis), triangles counter-clockwise seen from outside.
///
/// Meant to round the joints of a tube union; its vertex count is `(bands − 1)·m + 2`.
///
/// # Errors
/// [`TubeError::InvalidRadius`], [`TubeError::TooFewSegments`] or [`TubeError::NonFinite`]
/// (`what = "sphere centre"`) for unusable input.
pub fn sphere(
    center: &Vec3,
    radius: Real,
    settings: &TubeSettings,
) -> Result<TriangleMesh, TubeError> {
    settings.validate()?;
    if !(radius > 0.0 && radius.is_finite()) {
        return Err(TubeError::InvalidRadius { radius });
    }
    if !center.iter().all(|x| x.is_finite()) {
        return Err(TubeError::NonFinite {
            what: "sphere centre",
            index: 0,
        });
    }
    let m = settings.segments_around;
    let bands = (m / 2).max(2);
    let rings = bands - 1;
    let vertex_count = rings
        .checked_mul(m)
        .and_then(|v| v.checked_add(2))
        .unwrap_or(usize::MAX);
    if u32::try_from(vertex_count).is_err() {
        return Err(TubeError::TooManyVertices {
            vertices: vertex_count,
        });
    }
    let mut mesh = TriangleMesh {
        vertices: Vec::with_capacity(vertex_count),
        triangles: Vec::with_capacity(2 * m * bands),
    };
    // Ring j (j = 0 … rings−1) lies at polar angle θ = π (j+1)/bands from +z.
    for j in 0..rings {
        let (sin_t, cos_t) = (PI * (j + 1) as Real / bands as Real).sin_cos();
        for k in 0..m {
            let (sin_p, cos_p) = (2.0 * PI * k as Real / m as Real).sin_cos();
            mesh.vertices
                .push(center + radius * Vec3::new(sin_t * cos_p, sin_t * sin_p, cos_t));
        }
    }
    mesh.vertices.push(center + radius * Vec3::z());
    mesh.vertices.push(center - radius * Vec3::z());
    let m32 = m as u32;
    let at = |j: usize, k: u32| j as u32 * m32 + k % m32;
    let (north, south) = ((rings * m) as u32, (rings * m + 1) as u32);
    for k in 0..m32 {
        mesh.triangles.push([north, at(0, k), at(0, k + 1)]);
    }
    for j in 0..rings - 1 {
        for k in 0..m32 {
            // (a, d, c), (a, c, b) with a, b on the upper ring and d, c below: normal e_θ × e_φ = e_r.
            let (a, b, c, d) = (at(j, k), at(j, k + 1), at(j + 1, k + 1), at(j + 1, k));
            mesh.triangles.push([a, d, c]);
            mesh.triangles.push([a, c, b]);
        }
    }
    for k in 0..m32 {
        mesh.triangles
            .push([south, at(rings - 1, k + 1), at(rings - 1, k)]);
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Unit};
    use proptest::prelude::*;

    /// `sin(2π/x) / (2π/x)`: the area of the regular x-gon inscribed in a circle over the circle's area.
    fn polygon_factor(x: usize) -> Real {
        let a = 2.0 * PI / x as Real;
        a.sin() / a
    }

    /// Samples `0, L/(n−1), …, L` along `axis` from `origin`, with the frame `rotation` (columns d1, d2, d3)
    /// at every sample.
    fn straight(origin: Vec3, rotation: &Mat3, length: Real, n: usize) -> (Vec<Vec3>, Vec<Mat3>) {
        let axis = rotation.column(0).into_owned();
        let centre = (0..n)
            .map(|i| origin + axis * (length * i as Real / (n - 1) as Real))
            .collect();
        (centre, vec![*rotation; n])
    }

    /// A full circle of radius `big_r` in the xy plane, `segments` chords (first sample repeated at the
    /// end), with the analytic frame d1 = e_θ, d2 = e_r, d3 = d1 × d2 = −e_z.
    fn ring(big_r: Real, segments: usize) -> (Vec<Vec3>, Vec<Mat3>) {
        (0..=segments)
            .map(|i| {
                let (s, c) = (2.0 * PI * i as Real / segments as Real).sin_cos();
                let (e_r, e_t) = (Vec3::new(c, s, 0.0), Vec3::new(-s, c, 0.0));
                (
                    big_r * e_r,
                    Mat3::from_columns(&[e_t, e_r, e_t.cross(&e_r)]),
                )
            })
            .unzip()
    }

    /// `n` samples of the helix `(R cos t, R sin t, h t)`, `t ∈ [0, turns·2π]`.
    fn helix(big_r: Real, h: Real, turns: Real, n: usize) -> Vec<Vec3> {
        (0..n)
            .map(|i| {
                let t = turns * 2.0 * PI * i as Real / (n - 1) as Real;
                Vec3::new(big_r * t.cos(), big_r * t.sin(), h * t)
            })
            .collect()
    }

    /// Numbers in scientific notation, for the measured-value printouts.
    fn sci(values: &[Real]) -> String {
        let parts: Vec<String> = values.iter().map(|v| format!("{v:.3e}")).collect();
        format!("[{}]", parts.join(", "))
    }

    fn settings(m: usize) -> TubeSettings {
        TubeSettings {
            segments_around: m,
            ..TubeSettings::default()
        }
    }

    /// Negates d3 (and keeps d1, d2), so that d2 × d3 = −d1: a left-handed frame.
    fn flip_d3(f: &Mat3) -> Mat3 {
        Mat3::from_columns(&[
            f.column(0).into_owned(),
            f.column(1).into_owned(),
            -f.column(2).into_owned(),
        ])
    }

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

    // Checks: the double-reflection frames on a helix are orthonormal proper rotations with d1 along the
    // exact tangent, and rotate about d1 exactly as a rotation-minimising frame must.
    // Reference: writing d2 = cos α N + sin α B in the Frenet frame, zero rotation about the tangent requires
    // α' = −τ (in arc length), so α(t) = α(0) − (h/c) t for the helix (R cos t, R sin t, h t), c = √(R²+h²),
    // τ = h/c², N = −(cos t, sin t, 0), B = (h sin t, −h cos t, R)/c.
    // Tolerance: with second-order tangents the drift is guaranteed O(Δt²) only; on this uniformly sampled
    // helix the central-difference tangent error is the same tilt at every sample (factor sin Δt/Δt on the
    // horizontal components), and the measured drift is fourth order: 8.0e-9 rad at Δt = 4π/400, 4.8e-10
    // at Δt/2 (ratio 16.6). Required: below 1e-7 rad and at least second order (ratio > 3.5).
    #[test]
    fn helix_frames_are_rotation_minimising() {
        let (big_r, h, turns): (Real, Real, Real) = (1.0, 0.3, 2.0);
        let c = (big_r * big_r + h * h).sqrt();
        let mut drifts = Vec::new();
        for n in [401, 801] {
            let centre = helix(big_r, h, turns, n);
            let frames = parallel_transport_frames(&centre).expect("valid helix");
            let mut max_drift: Real = 0.0;
            let mut alpha0 = None;
            for (i, f) in frames.iter().enumerate() {
                assert!((f.transpose() * f - Mat3::identity()).abs().max() < 1e-14);
                assert!((f.determinant() - 1.0).abs() < 1e-14);
                let t = turns * 2.0 * PI * i as Real / (n - 1) as Real;
                let tangent = Vec3::new(-big_r * t.sin(), big_r * t.cos(), h) / c;
                let normal = -Vec3::new(t.cos(), t.sin(), 0.0);
                let binormal = Vec3::new(h * t.sin(), -h * t.cos(), big_r) / c;
                assert!((f.column(0) - tangent).norm() < 1e-3, "tangent at {i}");
                let d2 = f.column(1);
                let alpha = d2.dot(&binormal).atan2(d2.dot(&normal));
                let a0 = *alpha0.get_or_insert(alpha);
                // Wrap the difference to (−π, π].
                let diff = alpha - (a0 - h / c * t);
                let wrapped = diff - 2.0 * PI * (diff / (2.0 * PI)).round();
                max_drift = max_drift.max(wrapped.abs());
            }
            drifts.push(max_drift);
        }
        eprintln!("helix RMF angle drift {}", sci(&drifts));
        assert!(drifts[0] < 1e-7, "{drifts:?}");
        assert!(
            drifts[0] / drifts[1] > 3.5,
            "less than second order: {drifts:?}"
        );
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

    // Checks: on a planar curve with inflection points (a sine wave in the xy plane), the frames keep
    // d3 = +e_z at every sample, i.e. they do not flip at inflections as Frenet frames do.
    // Reference: the plane normal is parallel-transported unchanged along a planar curve; the start
    // tangent ∝ (1, 1.2, 0) has z as its least-aligned axis, so r0 = d2 = e_z and must stay e_z.
    // Tolerance 1e-12: reflections in vertical planes keep e_z exactly up to rounding.
    #[test]
    fn planar_curve_frames_keep_the_plane_normal() {
        let centre: Vec<Vec3> = (0..200)
            .map(|i| i as Real * 0.05)
            .map(|x| Vec3::new(x, 0.6 * (2.0 * x).sin(), 0.0))
            .collect();
        let frames = parallel_transport_frames(&centre).expect("valid curve");
        // Least-aligned axis of t0 ∝ (1, 1.2, 0) is z, so r0 = d2 = e_z all along.
        for (i, f) in frames.iter().enumerate() {
            assert!(
                (f.column(1) - Vec3::z()).norm() < 1e-12,
                "d2 at {i}: {:?}",
                f.column(1)
            );
        }
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

    // Checks: the mirror image of a helix tube in an oblique plane is closed and outward with the same
    // volume and area, and mirroring twice restores the vertices.
    // Reference: a reflection is an isometry reversing handedness; winding reversal restores the outward
    // orientation. Tolerance 1e-12 relative (volume, area), 1e-12 absolute on unit-size coordinates.
    #[test]
    fn mirrored_tube_is_closed_with_equal_volume() {
        let centre = helix(1.0, 0.3, 1.0, 101);
        let frames = parallel_transport_frames(&centre).expect("valid helix");
        let mesh = sweep_tube(&centre, &frames, 0.1, &settings(10)).expect("valid tube");
        let (p, n) = (Vec3::new(0.3, -0.2, 1.0), Vec3::new(1.0, 2.0, -0.5));
        let image = mesh.mirrored(&p, &n);
        assert_eq!(image.check_closed(), Ok(()));
        assert!((image.volume() / mesh.volume() - 1.0).abs() < 1e-12);
        assert!((image.area() / mesh.area() - 1.0).abs() < 1e-12);
        let back = image.mirrored(&p, &(3.0 * n));
        assert_eq!(back.triangles, mesh.triangles);
        let max_err = back
            .vertices
            .iter()
            .zip(&mesh.vertices)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, Real::max);
        assert!(max_err < 1e-12, "{max_err}");
        // Half + mirrored half = the full device: closed, twice the volume.
        let mut full = mesh.clone();
        full.append(&image);
        assert_eq!(full.check_closed(), Ok(()));
        assert!((full.volume() / (2.0 * mesh.volume()) - 1.0).abs() < 1e-12);
    }

    // Checks: the union of two tubes meeting at a joint, plus a sphere on the joint, is closed edge-wise and
    // its (overlap-counting) volume is the sum of the parts.
    // Reference: the parts' own volumes; the divergence-theorem sum is additive over shells.
    // Tolerance 1e-12 relative (rounding only).
    #[test]
    fn appended_tubes_and_sphere_stay_closed() {
        let s = settings(12);
        let (c1, f1) = straight(Vec3::zeros(), &Mat3::identity(), 1.0, 4);
        let rotation = Rotation3::from_axis_angle(&Vec3::z_axis(), 1.0);
        let (c2, f2) = straight(Vec3::x(), rotation.matrix(), 0.8, 3);
        let a = sweep_tube(&c1, &f1, 0.1, &s).expect("valid tube");
        let b = sweep_tube(&c2, &f2, 0.1, &s).expect("valid tube");
        let ball = sphere(&Vec3::x(), 0.1, &s).expect("valid sphere");
        let mut union = TriangleMesh::new();
        for part in [&a, &b, &ball] {
            union.append(part);
        }
        assert_eq!(union.check_closed(), Ok(()));
        assert_eq!(
            union.vertices.len(),
            a.vertices.len() + b.vertices.len() + ball.vertices.len()
        );
        let sum = a.volume() + b.volume() + ball.volume();
        assert!((union.volume() / sum - 1.0).abs() < 1e-12);
    }

    // Checks: the UV sphere is closed and outward and its volume converges to 4/3 π r³ at second order.
    // Reference: 4/3 π r³. The inscribed polyhedron misses O(h²) of the volume, so the ratio of errors
    // at m and 2m tends to 4; measured 3.70, 3.92, 3.98 for m = 8→16→32→64, required monotone and > 3.95
    // at the finest pair. m = 3, 4 (coarsest allowed) only need to be closed and inside the sphere.
    #[test]
    fn sphere_is_closed_and_converges() {
        let (centre, r) = (Vec3::new(1.0, 2.0, 3.0), 0.5);
        let exact = 4.0 / 3.0 * PI * r * r * r;
        let mut errors = Vec::new();
        for m in [3, 4, 8, 16, 32, 64] {
            let mesh = sphere(&centre, r, &settings(m)).expect("valid sphere");
            assert_eq!(mesh.check_closed(), Ok(()), "m = {m}");
            let v = mesh.volume();
            assert!(v > 0.0 && v < exact, "m = {m}: {v}");
            errors.push(1.0 - v / exact);
        }
        let ratios: Vec<Real> = errors[2..].windows(2).map(|e| e[0] / e[1]).collect();
        eprintln!(
            "sphere relative volume errors {}, ratios (m ≥ 8) {ratios:.4?}",
            sci(&errors)
        );
        assert!(ratios.windows(2).all(|w| w[0] < w[1]), "{ratios:?}");
        assert!(
            ratios.iter().all(|&q| q < 4.0) && ratios[ratios.len() - 1] > 3.95,
            "{ratios:?}"
        );
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

    // Checks: check_closed names each defect (first item, count) on deliberately broken copies of a tube.
    // Reference: hand-counted: removing one triangle opens its 3 edges; duplicating one makes its 3 edges
    // shared by 3 triangles; reversing one makes its 3 edges traversed twice the same way.
    #[test]
    fn check_closed_reports_each_defect() {
        let (centre, frames) = straight(Vec3::zeros(), &Mat3::identity(), 1.0, 3);
        let tube = sweep_tube(&centre, &frames, 0.1, &settings(6)).expect("valid tube");
        assert_eq!(tube.check_closed(), Ok(()));

        let mut open = tube.clone();
        open.triangles.remove(4);
        assert!(matches!(
            open.check_closed(),
            Err(MeshDefect::BoundaryEdge { count: 3, .. })
        ));

        let mut doubled = tube.clone();
        doubled.triangles.push(tube.triangles[4]);
        assert!(matches!(
            doubled.check_closed(),
            Err(MeshDefect::NonManifoldEdge {
                triangle: 4,
                triangles: 3,
                count: 3,
                ..
            })
        ));

        let mut flipped = tube.clone();
        let [a, b, c] = flipped.triangles[4];
        flipped.triangles[4] = [a, c, b];
        assert!(matches!(
            flipped.check_closed(),
            Err(MeshDefect::InconsistentOrientation { count: 3, .. })
        ));

        let mut unused = tube.clone();
        unused.vertices.push(Vec3::zeros());
        assert_eq!(
            unused.check_closed(),
            Err(MeshDefect::UnusedVertex {
                vertex: tube.vertices.len(),
                count: 1
            })
        );

        let mut repeated = tube.clone();
        repeated.triangles[2][1] = repeated.triangles[2][0];
        assert!(matches!(
            repeated.check_closed(),
            Err(MeshDefect::RepeatedIndex {
                triangle: 2,
                count: 1,
                ..
            })
        ));

        let mut out_of_range = tube.clone();
        out_of_range.triangles[5][2] = 999;
        assert!(matches!(
            out_of_range.check_closed(),
            Err(MeshDefect::IndexOutOfRange {
                triangle: 5,
                index: 999,
                ..
            })
        ));

        let collinear = TriangleMesh {
            vertices: vec![Vec3::zeros(), Vec3::x(), 2.0 * Vec3::x()],
            triangles: vec![[0, 1, 2]],
        };
        assert!(matches!(
            collinear.check_closed(),
            Err(MeshDefect::ZeroArea {
                triangle: 0,
                count: 1,
                ..
            })
        ));
        assert_eq!(TriangleMesh::new().check_closed(), Ok(()));
        assert_eq!(TriangleMesh::new().bounding_box(), None);
        assert_eq!(TriangleMesh::new().volume(), 0.0);
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

/// Golden-ratio conjugate: successive multiples modulo 1 are as evenly spread as possible, so no two patches
/// get (nearly) the same section phase.
const PHASE_STEP: Real = 0.618_033_988_749_894_9;

/// The section phase of the `k`-th rod of a device, a fraction of a segment in `[0, 1)`: `k φ mod 1` with
/// `φ` the golden-ratio conjugate. Sweeping each rod with its own phase keeps the end rings of rods meeting at
/// a joint from coinciding vertex for vertex (see [`sweep_curve`]).
pub fn section_phase(k: usize) -> Real {
    (k as Real * PHASE_STEP).fract()
}

/// The rotation about the rod axis `d1` that turns a section polygon of `segments` vertices by `phase`
/// segments: multiply a frame by it on the right.
pub fn phase_turn(phase: Real, segments: usize) -> Mat3 {
    *crate::math::so3::exp(&(Vec3::x() * (2.0 * PI * phase / segments.max(1) as Real))).matrix()
}

/// `frames` for drawing the polyline `centre` as a tube: each frame whose section normal (`d2 × d3`) is more
/// than `max_tilt` from the sampled centreline direction (the tangents of [`sweep_tube`]) is turned, about
/// the axis normal to both, until it is `max_tilt` from it; the others are kept. The normals are compared on
/// the side most of the rod's sections face (`d2 × d3` along or against the samples' order; along when
/// undecided), so a ring facing the wrong way is turned too. Frames the sweep would reject (too few samples,
/// coincident samples, non-finite or degenerate frames) are returned unchanged, for the sweep to report.
pub fn limited_tilt(centre: &[Vec3], frames: &[Mat3], max_tilt: Real) -> Vec<Mat3> {
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

/// One rod of a device, sampled for drawing as a tube.
#[derive(Debug, Clone, Copy)]
pub struct RodTube<'a> {
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

/// The closed surface of a whole device from the rods of a symmetry-reduced model: one tube per rod, mirrored
/// about every symmetry plane `(point, normal)` in turn (a quarter model gives four copies of each rod), with
/// the rods lying in a plane ([`RodTube::in_plane`]) not mirrored about it.
///
/// A rod end whose ring lies in a plane the rod does not lie in (within [`TubeSettings::seam_tolerance`] of
/// the radius) continues in the mirror image: it is left uncapped and welded to its image
/// ([`TriangleMesh::mirrored_welded`]), so the rod and its image form one closed tube, without two caps
/// coinciding (which would make their edges non-manifold once an STL reader merges equal vertices). Every
/// other end is capped. The result is closed ([`TriangleMesh::check_closed`]) and outward; like any device
/// from [`sweep_tube`], tubes overlap at joints.
///
/// Mirroring about several planes assumes that the reflections commute (orthogonal planes, as for half and
/// quarter models).
///
/// # Errors
/// [`DeviceMeshError`] naming the rod whose tube cannot be swept.
pub fn device_mesh(
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
mod device_tests {
    use super::*;

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
