//! The crate's surface vocabulary: [`TriangleMesh`] (indexed triangles, counter-clockwise seen from outside),
//! its integral checks ([`TriangleMesh::volume`], [`TriangleMesh::area`]), its topological check
//! ([`TriangleMesh::check_closed`], which reports a [`MeshDefect`]), and the operations that combine closed
//! shells: union ([`TriangleMesh::append`]) and mirror images ([`TriangleMesh::mirrored`],
//! [`TriangleMesh::mirrored_welded`]).
//!
//! The generators that produce closed shells live beside it: tubes in [`super::tube`], spheres in
//! `super::sphere`, whole devices in `super::device_tubes`. Nothing here writes files: the `io` layer
//! turns a [`TriangleMesh`] into STL or OBJ.

use std::collections::HashMap;

use crate::math::{Real, Vec3};

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

/// The three directed edges `(a, b), (b, c), (c, a)` of a triangle.
fn directed_edges(tri: &[u32; 3]) -> [(u32, u32); 3] {
    [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::polyline::parallel_transport_frames;
    use crate::geometry::sphere::sphere;
    use crate::geometry::test_shapes::{helix, settings, straight};
    use crate::geometry::tube::sweep_tube;
    use crate::math::Mat3;
    use nalgebra::Rotation3;

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
}
