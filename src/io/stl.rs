//! Binary STL export of triangle meshes (via `stl_io`), and an STL reader for round-trip checks.
//!
//! Every file is written through `crate::io::atomic`, so that an interrupted or failed export never leaves a
//! half-written mesh behind: the target either keeps its old content or gets the complete new one.
//!
//! Binary STL stores `f32` coordinates and one facet normal per triangle; the normals written here are
//! computed from the triangles (right-hand rule, so outward for an outward-oriented mesh). The 80-byte
//! header starts with `stentkit` (never with `solid`, which would make readers mistake the file for ASCII
//! STL) followed by the caller's text, typically the unit system.

use std::fs::File;
use std::io::{self, BufReader, Write};
use std::path::Path;

use super::atomic::write_atomically;

use crate::geometry::mesh::TriangleMesh;
use crate::math::Vec3;

/// Length of the binary STL header in bytes.
const STL_HEADER_LEN: usize = 80;

pub use super::mesh_format::MeshIoError;

/// Writes `mesh` to `path` as binary STL, atomically, with the header `stentkit binary STL`.
///
/// # Errors
/// [`MeshIoError::Write`] if the mesh cannot be written (an index out of range, a coordinate that is not
/// finite or overflows `f32`) or the file cannot be created, written or renamed; the target is then left
/// as it was.
pub fn write_stl(path: &Path, mesh: &TriangleMesh) -> Result<(), MeshIoError> {
    write_stl_with_header(path, mesh, "")
}

/// Binary STL snapshots (`super::formats::FORMATS`): an 80-byte header naming the design, step, time and
/// unit system.
pub struct Stl;

impl super::mesh_format::MeshFormat for Stl {
    fn extension(&self) -> &'static str {
        "stl"
    }

    fn write(
        &self,
        path: &Path,
        mesh: &TriangleMesh,
        s: &super::mesh_format::SnapshotState<'_>,
    ) -> Result<(), MeshIoError> {
        let header = format!(
            "{} step {} t={:.6} {}",
            s.model.name(),
            s.step,
            s.time,
            s.model.units.name()
        );
        write_stl_with_header(path, mesh, &header)
    }
}

/// Writes `mesh` to `path` as binary STL, atomically, with `header` (e.g. `"units: mm-N-MPa"`) after the
/// `stentkit binary STL` prefix in the 80-byte header (truncated to fit; control characters become spaces).
///
/// # Errors
/// As [`write_stl`].
pub fn write_stl_with_header(
    path: &Path,
    mesh: &TriangleMesh,
    header: &str,
) -> Result<(), MeshIoError> {
    write_atomically(path, |w| write_stl_to_with_header(w, mesh, header))
}

/// Writes `mesh` as binary STL to `w`, with the header `stentkit binary STL`.
///
/// # Errors
/// [`io::ErrorKind::InvalidInput`] for a mesh that cannot be written (see [`write_stl`]), checked before
/// anything is written; otherwise any error of `w`.
pub fn write_stl_to<W: Write>(w: &mut W, mesh: &TriangleMesh) -> io::Result<()> {
    write_stl_to_with_header(w, mesh, "")
}

/// Writes `mesh` as binary STL to `w`, with `header` in the 80-byte header as in [`write_stl_with_header`].
///
/// # Errors
/// As [`write_stl_to`].
pub fn write_stl_to_with_header<W: Write>(
    w: &mut W,
    mesh: &TriangleMesh,
    header: &str,
) -> io::Result<()> {
    check_writable(mesh, true)?;
    let to_f32 = |v: &Vec3| stl_io::Vector::new([v.x as f32, v.y as f32, v.z as f32]);
    let triangles = (0..mesh.triangles.len()).map(|t| {
        let [a, b, c] = mesh.corners(t);
        stl_io::Triangle {
            normal: to_f32(&mesh.triangle_normal(t)),
            vertices: [to_f32(&a), to_f32(&b), to_f32(&c)],
        }
    });
    let mut with_header = HeaderWriter {
        inner: w,
        header: stl_header(header),
        position: 0,
    };
    stl_io::write_stl(&mut with_header, triangles)
}

/// Reads an STL file (binary or ASCII) into an indexed mesh. Vertices with bit-identical `f32` coordinates
/// are merged (stl_io's `IndexedMesh`), so a closed mesh written by [`write_stl`] reads back closed;
/// facet normals are discarded.
///
/// Meant for round-trip checks. Merging by bit pattern can join vertices that were distinct in `f64` but
/// round to the same `f32`, and it also joins coincident vertices of different shells (for example two
/// coinciding end caps of tubes meeting at a joint), which then makes their edges non-manifold for
/// [`TriangleMesh::check_closed`].
///
/// # Errors
/// [`MeshIoError::Read`] when the file cannot be opened or parsed, or has more than `u32::MAX` vertices.
pub fn read_stl(path: &Path) -> Result<TriangleMesh, MeshIoError> {
    let err = |source| MeshIoError::Read {
        path: path.to_path_buf(),
        source,
    };
    let file = File::open(path).map_err(err)?;
    let indexed = stl_io::read_stl(&mut BufReader::new(file)).map_err(err)?;
    let index = |i: usize| {
        u32::try_from(i).map_err(|_| {
            err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!("vertex index {i} exceeds u32"),
            ))
        })
    };
    let triangles = indexed
        .faces
        .iter()
        .map(|f| {
            Ok([
                index(f.vertices[0])?,
                index(f.vertices[1])?,
                index(f.vertices[2])?,
            ])
        })
        .collect::<Result<Vec<_>, MeshIoError>>()?;
    let vertices = indexed
        .vertices
        .iter()
        .map(|v| Vec3::new(v[0].into(), v[1].into(), v[2].into()))
        .collect();
    Ok(TriangleMesh {
        vertices,
        triangles,
    })
}

/// The 80-byte STL header: `stentkit binary STL`, then `; ` and `text` if given, truncated at a character
/// boundary, padded with zeros.
fn stl_header(text: &str) -> [u8; STL_HEADER_LEN] {
    let mut line = String::from("stentkit binary STL");
    if !text.is_empty() {
        line.push_str("; ");
        line.extend(text.chars().map(|c| if c.is_control() { ' ' } else { c }));
    }
    let mut end = line.len().min(STL_HEADER_LEN);
    while !line.is_char_boundary(end) {
        end -= 1;
    }
    let mut bytes = [0u8; STL_HEADER_LEN];
    bytes[..end].copy_from_slice(&line.as_bytes()[..end]);
    bytes
}

/// A writer that replaces the first 80 bytes passing through it (stl_io's all-zero header) with `header`.
struct HeaderWriter<'a, W: Write> {
    inner: &'a mut W,
    header: [u8; STL_HEADER_LEN],
    /// Bytes written so far.
    position: usize,
}

impl<W: Write> Write for HeaderWriter<'_, W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if self.position >= STL_HEADER_LEN {
            let n = self.inner.write(buf)?;
            self.position += n;
            return Ok(n);
        }
        // Within the header: substitute our bytes for as much of `buf` as overlaps it.
        let overlap = buf.len().min(STL_HEADER_LEN - self.position);
        let n = self
            .inner
            .write(&self.header[self.position..self.position + overlap])?;
        self.position += n;
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

/// Checks that every index is in range and every coordinate is finite (also after rounding to `f32` when
/// `single_precision`), so that writing cannot panic or silently produce infinities.
pub(crate) fn check_writable(mesh: &TriangleMesh, single_precision: bool) -> io::Result<()> {
    let invalid = |message: String| io::Error::new(io::ErrorKind::InvalidInput, message);
    let count = mesh.vertices.len();
    if let Some((t, tri)) = mesh
        .triangles
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&i| i as usize >= count))
    {
        return Err(invalid(format!(
            "triangle {t} {tri:?} refers to a vertex beyond the {count} vertices"
        )));
    }
    let representable = |x: f64| x.is_finite() && (!single_precision || (x as f32).is_finite());
    if let Some(i) = mesh
        .vertices
        .iter()
        .position(|v| !v.iter().all(|&x| representable(x)))
    {
        let precision = if single_precision { "single" } else { "double" };
        return Err(invalid(format!(
            "vertex {i} {:?} is not finite in {precision} precision",
            mesh.vertices[i]
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::mesh::MeshDefect;
    use crate::geometry::polyline::parallel_transport_frames;
    use crate::geometry::sphere::sphere;
    use crate::geometry::tube::{TubeSettings, sweep_tube};
    use crate::math::{Mat3, Real};
    use std::fs;
    use std::path::PathBuf;

    /// A fresh, empty scratch directory under the system temporary directory.
    fn scratch_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("stentkit-stl-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).expect("scratch directory");
        dir
    }

    /// File names in `dir`, sorted.
    fn listing(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = fs::read_dir(dir)
            .expect("readable directory")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    /// A device-like mesh: a helix tube, a straight tube and a sphere (separate, non-touching shells).
    fn sample_mesh() -> TriangleMesh {
        let s = TubeSettings::default();
        let helix: Vec<Vec3> = (0..60)
            .map(|i| i as Real * 0.1)
            .map(|t| Vec3::new(2.0 * t.cos(), 2.0 * t.sin(), 0.4 * t))
            .collect();
        let frames = parallel_transport_frames(&helix).expect("valid helix");
        let mut mesh = sweep_tube(&helix, &frames, 0.15, &s).expect("valid tube");
        let line = [
            Vec3::new(5.0, 0.0, 0.0),
            Vec3::new(5.0, 0.0, 1.0),
            Vec3::new(5.0, 0.0, 3.0),
        ];
        // d1 = e_z (unequal sample spacing on purpose), d2 = e_y, d3 = −e_x.
        let along_z = Mat3::from_columns(&[Vec3::z(), Vec3::y(), -Vec3::x()]);
        let tube = sweep_tube(&line, &[along_z; 3], 0.2, &s).expect("valid tube");
        mesh.append(&tube);
        mesh.append(&sphere(&Vec3::new(-5.0, 1.0, 0.0), 0.5, &s).expect("valid sphere"));
        mesh
    }

    // Checks: write_stl → read_stl keeps the triangle and vertex counts, closedness (our check and stl_io's
    // IndexedMesh::validate) and the volume; the facet normals are the outward unit normals; the header
    // carries stentkit and the caller's text.
    // Reference: the in-memory mesh. Tolerances: coordinates are rounded to f32 (relative 6e-8), so the
    // volume may change by a few 1e-7 relative (accepted 1e-6) and normals recomputed from the rounded
    // corners agree to ~1e-6 (accepted 1e-4 on |n_file − n|).
    #[test]
    fn stl_round_trip_keeps_counts_and_closedness() {
        let dir = scratch_dir("round-trip");
        let path = dir.join("device.stl");
        let mesh = sample_mesh();
        assert_eq!(mesh.check_closed(), Ok(()));
        write_stl_with_header(&path, &mesh, "units: mm-N-MPa").expect("writable");
        assert_eq!(listing(&dir), ["device.stl"], "no temporary file is left");
        let bytes = fs::read(&path).expect("readable");
        assert_eq!(bytes.len(), 84 + 50 * mesh.triangles.len());
        assert!(bytes.starts_with(b"stentkit binary STL; units: mm-N-MPa\0"));

        let read = read_stl(&path).expect("readable STL");
        assert_eq!(read.triangles.len(), mesh.triangles.len());
        assert_eq!(read.vertices.len(), mesh.vertices.len());
        assert_eq!(read.check_closed(), Ok(()));
        let indexed = stl_io::read_stl(&mut File::open(&path).expect("readable")).expect("STL");
        assert!(indexed.validate().is_ok(), "{:?}", indexed.validate());
        assert!(
            (read.volume() / mesh.volume() - 1.0).abs() < 1e-6,
            "{} vs {}",
            read.volume(),
            mesh.volume()
        );

        let raw = stl_io::create_stl_reader(&mut File::open(&path).expect("readable"))
            .expect("STL")
            .collect::<io::Result<Vec<_>>>()
            .expect("triangles");
        for (t, facet) in raw.iter().enumerate() {
            let n = Vec3::new(
                facet.normal[0].into(),
                facet.normal[1].into(),
                facet.normal[2].into(),
            );
            assert!((n - mesh.triangle_normal(t)).norm() < 1e-4, "facet {t}");
        }
        let _ = fs::remove_dir_all(&dir);
    }

    // Checks: the streaming writer's byte count and default header; an empty mesh is a valid 84-byte file.
    // Reference: the binary STL layout (80-byte header, u32 count, 50 bytes per facet).
    #[test]
    fn stl_to_writer_layout() {
        let mesh = sample_mesh();
        let mut bytes = Vec::new();
        write_stl_to(&mut bytes, &mesh).expect("in-memory write");
        assert_eq!(bytes.len(), 84 + 50 * mesh.triangles.len());
        assert!(bytes.starts_with(b"stentkit binary STL\0"));
        assert_eq!(
            u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize,
            mesh.triangles.len()
        );
        let mut empty = Vec::new();
        write_stl_to(&mut empty, &TriangleMesh::new()).expect("in-memory write");
        assert_eq!(empty.len(), 84);
        // A long, multi-line, non-ASCII header is cut at a character boundary and never breaks the layout.
        let mut long = Vec::new();
        write_stl_to_with_header(&mut long, &mesh, &"µm\nline ".repeat(20))
            .expect("in-memory write");
        assert_eq!(long.len(), bytes.len());
        assert!(std::str::from_utf8(long[..80].split(|&b| b == 0).next().expect("text")).is_ok());
    }

    // Checks: failures never leave a half-written or clobbered file and never panic: an invalid mesh
    // (NaN, f32 overflow, index out of range), a target that is a directory, a missing directory, and a
    // writer that fails midway.
    // Reference: the directory listing and the earlier file content, byte for byte.
    #[test]
    fn stl_failures_leave_no_partial_file() {
        let dir = scratch_dir("failures");
        let path = dir.join("part.stl");
        let mesh = sample_mesh();
        write_stl(&path, &mesh).expect("writable");
        let before = fs::read(&path).expect("readable");

        let mut nan = mesh.clone();
        nan.vertices[3].x = Real::NAN;
        let mut huge = mesh.clone();
        huge.vertices[0].z = 1e300;
        let mut dangling = mesh.clone();
        dangling.triangles[7][1] = u32::MAX;
        for bad in [&nan, &huge, &dangling] {
            let e = write_stl(&path, bad).expect_err("invalid mesh");
            assert!(
                matches!(&e, MeshIoError::Write { path: p, source } if p == &path
                && source.kind() == io::ErrorKind::InvalidInput),
                "{e}"
            );
        }
        assert_eq!(
            fs::read(&path).expect("readable"),
            before,
            "target unchanged"
        );

        fs::create_dir(dir.join("sub")).expect("directory");
        assert!(matches!(
            write_stl(&dir.join("sub"), &mesh),
            Err(MeshIoError::Write { .. })
        ));
        assert!(matches!(
            write_stl(&dir.join("missing/part.stl"), &mesh),
            Err(MeshIoError::Write { .. })
        ));
        assert!(matches!(
            write_stl(Path::new("/"), &mesh),
            Err(MeshIoError::Write { .. })
        ));
        assert_eq!(
            listing(&dir),
            ["part.stl", "sub"],
            "no temporary file is left"
        );
        assert!(listing(&dir.join("sub")).is_empty());

        /// Accepts `capacity` bytes, then fails.
        struct Failing {
            capacity: usize,
        }
        impl Write for Failing {
            fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
                if self.capacity == 0 {
                    return Err(io::Error::other("disk full"));
                }
                let n = buf.len().min(self.capacity);
                self.capacity -= n;
                Ok(n)
            }
            fn flush(&mut self) -> io::Result<()> {
                Ok(())
            }
        }
        for capacity in [0, 40, 84, 1000] {
            assert!(
                write_stl_to(&mut Failing { capacity }, &mesh).is_err(),
                "capacity {capacity}"
            );
        }
        assert!(matches!(
            read_stl(&dir.join("absent.stl")),
            Err(MeshIoError::Read { .. })
        ));
        fs::write(dir.join("short.stl"), &before[..200]).expect("writable");
        assert!(
            matches!(
                read_stl(&dir.join("short.stl")),
                Err(MeshIoError::Read { .. })
            ),
            "truncated file"
        );
        let _ = fs::remove_dir_all(&dir);
    }

    // Checks (documents a limitation): two tubes meeting end to end with the same frame at the joint have
    // coinciding end caps. In memory the union is closed (each shell separately); after an STL round trip
    // the reader merges the coincident cap vertices, so the cap edges are shared by four triangles:
    // check_closed reports them as non-manifold, while stl_io's validate (which only pairs opposite
    // directed edges) still passes. Viewers and slicers accept such files.
    // Reference: hand count — the 16 rim edges of the joint cap, each used by two caps and two tube sides,
    // plus the 16 spokes, each used by the two coinciding fans, so 32 non-manifold edges.
    #[test]
    fn coincident_caps_merge_on_read() {
        let dir = scratch_dir("joint");
        let path = dir.join("joint.stl");
        let s = TubeSettings::default();
        let frame = Mat3::from_columns(&[Vec3::z(), Vec3::y(), -Vec3::x()]);
        let first = [Vec3::zeros(), Vec3::new(0.0, 0.0, 1.0)];
        let second = [Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, 2.0)];
        let mut mesh = sweep_tube(&first, &[frame; 2], 0.1, &s).expect("valid tube");
        mesh.append(&sweep_tube(&second, &[frame; 2], 0.1, &s).expect("valid tube"));
        assert_eq!(mesh.check_closed(), Ok(()));
        write_stl(&path, &mesh).expect("writable");
        let read = read_stl(&path).expect("readable");
        assert!(
            matches!(
                read.check_closed(),
                Err(MeshDefect::NonManifoldEdge {
                    triangles: 4,
                    count: 32,
                    ..
                })
            ),
            "{:?}",
            read.check_closed()
        );
        let indexed = stl_io::read_stl(&mut File::open(&path).expect("readable")).expect("STL");
        assert!(indexed.validate().is_ok());
        let _ = fs::remove_dir_all(&dir);
    }
}
