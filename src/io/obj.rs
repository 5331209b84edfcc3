//! Wavefront OBJ export of triangle meshes (plain text, written by hand), with atomic file writes.
//!
//! The file holds comment lines (`#`) naming stentkit and the caller's header text (the unit system),
//! then one `v x y z` line per vertex and one `f i j k` line per triangle (1-based indices, counter-clockwise
//! seen from outside, as in [`TriangleMesh`]). Coordinates are printed in Rust's shortest round-trip form,
//! so reading the file back gives the same `f64` values.

use std::io::{self, Write};
use std::path::Path;

use crate::geometry::mesh::TriangleMesh;
use crate::io::atomic::write_atomically;
use crate::io::stl::{MeshIoError, check_writable};

/// OBJ snapshots (`super::formats::FORMATS`): a comment naming the design, step, time and units.
pub struct Obj;

impl super::mesh_format::MeshFormat for Obj {
    fn extension(&self) -> &'static str {
        "obj"
    }

    fn write(
        &self,
        path: &Path,
        mesh: &TriangleMesh,
        s: &super::mesh_format::SnapshotState<'_>,
    ) -> Result<(), MeshIoError> {
        let header = format!(
            "{}: full device at step {}, t = {} s; units {} (lengths in {})",
            s.model.name(),
            s.step,
            s.time,
            s.model.units.name(),
            s.model.units.length()
        );
        write_obj(path, mesh, &header)
    }
}

/// Writes `mesh` to `path` as OBJ, atomically (see [`crate::io::stl`]); `header` (e.g. `"units: mm-N-MPa"`,
/// possibly several lines) goes into comment lines after the `# stentkit …` line.
///
/// # Errors
/// [`MeshIoError::Write`] if the mesh cannot be written (an index out of range, a coordinate that is not
/// finite) or the file cannot be created, written or renamed; the target is then left as it was.
pub fn write_obj(path: &Path, mesh: &TriangleMesh, header: &str) -> Result<(), MeshIoError> {
    write_atomically(path, |w| write_obj_to(w, mesh, header))
}

/// Writes `mesh` as OBJ text to `w` (see [`write_obj`]).
///
/// # Errors
/// [`io::ErrorKind::InvalidInput`] for a mesh that cannot be written, checked before anything is written;
/// otherwise any error of `w`.
pub fn write_obj_to<W: Write>(w: &mut W, mesh: &TriangleMesh, header: &str) -> io::Result<()> {
    check_writable(mesh, false)?;
    writeln!(w, "# stentkit {} OBJ export", env!("CARGO_PKG_VERSION"))?;
    for line in header.lines() {
        writeln!(w, "# {line}")?;
    }
    writeln!(
        w,
        "# {} vertices, {} triangles",
        mesh.vertices.len(),
        mesh.triangles.len()
    )?;
    for v in &mesh.vertices {
        writeln!(w, "v {} {} {}", v.x, v.y, v.z)?;
    }
    for [a, b, c] in &mesh.triangles {
        writeln!(
            w,
            "f {} {} {}",
            u64::from(*a) + 1,
            u64::from(*b) + 1,
            u64::from(*c) + 1
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::polyline::parallel_transport_frames;
    use crate::geometry::sphere::sphere;
    use crate::geometry::tube::{TubeSettings, sweep_tube};
    use crate::math::{Real, Vec3};
    use std::fs;
    use std::path::PathBuf;

    /// A helix tube plus a sphere (two closed shells).
    fn sample_mesh() -> TriangleMesh {
        let s = TubeSettings {
            segments_around: 9,
            ..TubeSettings::default()
        };
        let helix: Vec<Vec3> = (0..40)
            .map(|i| i as Real * 0.1)
            .map(|t| Vec3::new(1.0e3 + 2.0 * t.cos(), 2.0 * t.sin(), 0.4 * t))
            .collect();
        let frames = parallel_transport_frames(&helix).expect("valid helix");
        let mut mesh = sweep_tube(&helix, &frames, 0.15, &s).expect("valid tube");
        mesh.append(&sphere(&Vec3::new(-5.0, 1.0, 1.0 / 3.0), 0.5, &s).expect("valid sphere"));
        mesh
    }

    /// A minimal OBJ reader for `v` and triangular `f` lines (1-based, plain indices), enough to check
    /// what `write_obj_to` produces; comment lines are returned separately.
    fn parse_obj(text: &str) -> (TriangleMesh, Vec<String>) {
        let mut mesh = TriangleMesh::new();
        let mut comments = Vec::new();
        for line in text.lines() {
            let mut fields = line.split_whitespace();
            match fields.next() {
                Some("#") | None => comments.push(line.to_owned()),
                Some("v") => {
                    let c: Vec<Real> = fields.map(|x| x.parse().expect("float")).collect();
                    assert_eq!(c.len(), 3, "{line}");
                    mesh.vertices.push(Vec3::new(c[0], c[1], c[2]));
                }
                Some("f") => {
                    let i: Vec<u32> = fields
                        .map(|x| x.parse::<u32>().expect("index") - 1)
                        .collect();
                    assert_eq!(i.len(), 3, "{line}");
                    mesh.triangles.push([i[0], i[1], i[2]]);
                }
                Some(other) => panic!("unexpected OBJ record {other:?} in {line:?}"),
            }
        }
        (mesh, comments)
    }

    // Checks: the OBJ text has one `v` line per vertex and one `f` line per triangle, a header naming
    // stentkit and the caller's units, and parses back to exactly the same mesh (closed).
    // Reference: the in-memory mesh; coordinates are printed in shortest round-trip form, so equality is
    // exact (no tolerance), even for vertices 1e3 away from the origin with non-terminating decimals.
    #[test]
    fn obj_text_parses_back_exactly() {
        let mesh = sample_mesh();
        let mut bytes = Vec::new();
        write_obj_to(&mut bytes, &mesh, "units: mm-N-MPa\nstep 12").expect("in-memory write");
        let text = String::from_utf8(bytes).expect("UTF-8");
        let count = |prefix: &str| text.lines().filter(|l| l.starts_with(prefix)).count();
        assert_eq!(count("v "), mesh.vertices.len());
        assert_eq!(count("f "), mesh.triangles.len());
        let (parsed, comments) = parse_obj(&text);
        assert!(
            comments[0].starts_with("# stentkit ") && comments[0].contains("OBJ"),
            "{comments:?}"
        );
        assert_eq!(comments[1], "# units: mm-N-MPa");
        assert_eq!(comments[2], "# step 12");
        assert_eq!(parsed, mesh);
        assert_eq!(parsed.check_closed(), Ok(()));
    }

    // Checks: write_obj writes the same text atomically (no temporary file left) and an invalid mesh fails
    // without touching the existing file.
    // Reference: write_obj_to's output and the directory listing.
    #[test]
    fn obj_file_is_written_atomically() {
        let dir: PathBuf =
            std::env::temp_dir().join(format!("stentkit-obj-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).expect("scratch directory");
        let path = dir.join("step_00001.obj");
        let mesh = sample_mesh();
        write_obj(&path, &mesh, "units: SI").expect("writable");
        let mut expected = Vec::new();
        write_obj_to(&mut expected, &mesh, "units: SI").expect("in-memory write");
        assert_eq!(fs::read(&path).expect("readable"), expected);

        let mut bad = mesh.clone();
        bad.vertices[1].y = Real::INFINITY;
        assert!(matches!(
            write_obj(&path, &bad, "units: SI"),
            Err(MeshIoError::Write { .. })
        ));
        let mut dangling = mesh.clone();
        dangling.triangles[0][0] = mesh.vertices.len() as u32;
        assert!(matches!(
            write_obj(&path, &dangling, ""),
            Err(MeshIoError::Write { .. })
        ));
        assert_eq!(
            fs::read(&path).expect("readable"),
            expected,
            "target unchanged"
        );
        let names: Vec<_> = fs::read_dir(&dir)
            .expect("listing")
            .map(|e| e.expect("entry").file_name())
            .collect();
        assert_eq!(names, ["step_00001.obj"]);
        let _ = fs::remove_dir_all(&dir);
    }
}
