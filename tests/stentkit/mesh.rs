//! The reference shape of every design as a closed tube surface, checked on what the files hold: the binary
//! STL and OBJ that `stentkit mesh` writes are read back and must be closed and consistently oriented (every
//! edge in exactly two triangles, in opposite directions) with the volume of the tubes.
//!
//! Expected volume. Each patch is a tube of `m` segments around, i.e. an inscribed regular m-gon of area
//! `A_m = (m/2) r² sin(2π/m)` (0.9745 π r² for m = 16) swept along the patch's length `L` (5-point
//! Gauss–Legendre on 256 panels of the exact NURBS, round-off accurate). For a straight patch the tube is a
//! prism and `V = A_m L` exactly. Along a bend the rings are joined by straight rulings: the slice between
//! two rings turned by `δ` about the bend axis is a wedge of volume `A_m R sin δ` instead of the `A_m R δ` of
//! Pappus' rule, a relative defect of `δ²/6`. With `δ` the largest angle between consecutive sample tangents
//! of a patch we allow `δ²/4` (measured: 0.16 δ² on bend45 and circular_arch), plus 10⁻¹² for round-off.
//! The union of overlapping shells at joints is not subtracted: `volume()` of a union of closed shells is the
//! sum of their volumes, which is what we compare with.
//!
//! A symmetry-reduced stent is exported as the full device: each patch counts once per mirror copy
//! (`post::device::patch_copies`: 4 in a quarter model, 2 for a bridge lying in a plane). A wire ending on a
//! plane is welded to its image without caps; the two flat caps it would otherwise have coincide with opposite
//! orientations and contribute nothing to the volume, so the sum is unchanged.
//!
//! STL stores `f32`: every coordinate moves by at most `2⁻²⁴|x|`, so the volume moves by at most
//! `area · 2⁻²⁴ · max|x|`; the read-back volume must match the in-memory one within twice that.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use stentkit::design::load_design;
use stentkit::geometry::analytic::ArcLengthTable;
use stentkit::geometry::frame::{FrameField, FrameSettings};
use stentkit::geometry::mesh::TriangleMesh;
use stentkit::geometry::tube::{TubeSettings, sweep_curve};
use stentkit::io::{obj, stl};
use stentkit::math::{Real, Vec3};
use stentkit::model::Model;
use stentkit::post::device::patch_copies;
use stentkit::post::device::reference_device_mesh;

/// Segments around each tube and samples per control point: the `stentkit mesh` defaults.
pub const SEGMENTS: usize = 16;
/// See [`SEGMENTS`].
pub const SAMPLES_PER_POINT: usize = 4;

/// A fresh directory under the system temporary directory, removed (with its content) when dropped.
pub struct TempDir(PathBuf);

impl TempDir {
    /// A new empty directory whose name holds `tag`, the process id and a per-process counter.
    pub fn new(tag: &str) -> Self {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let k = COUNTER.fetch_add(1, Ordering::Relaxed);
        let path =
            std::env::temp_dir().join(format!("stentkit-test-{tag}-{}-{k}", std::process::id()));
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path).expect("temporary directory");
        Self(path)
    }

    /// A path inside the directory.
    pub fn join(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Every design: all YAML files in `designs/` (listed at run time) and the two-patch base of the broken
/// designs, `tests/data/good_small.yaml` (a line and an arc meeting tangentially, with identical frames).
pub fn designs_and_good_small() -> Vec<PathBuf> {
    let mut files = crate::designs::all_designs();
    assert!(!files.is_empty(), "designs/ holds no YAML file");
    files.push(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/good_small.yaml"));
    files
}

/// Two collinear straight patches meeting at (1, 0, 0): the same tangent and the same start frame, so their
/// end rings would coincide vertex for vertex without the per-patch section phase.
const COLLINEAR: &str = "\
version: 1
name: collinear
units: mm-N-MPa
material:
  E_inf: 2000
  nu: 0.3
section:
  diameter: 0.1
mesh: {p: 3, n: 6}
patches:
  - name: first
    line: {from: [0, 0, 0], to: [1, 0, 0]}
  - name: second
    line: {from: [1, 0, 0], to: [2, 0, 0]}
nodes:
  - {name: root, ends: [first.start]}
  - {name: middle, ends: [first.end, second.start]}
conditions:
  - {node: root, clamp: true}
time: {end: 1.0, step: 0.5}
";

/// Parses the `v` and `f` lines of an OBJ file (1-based indices; `f i/j/k` forms take the vertex index).
fn read_obj(path: &Path) -> TriangleMesh {
    let text = std::fs::read_to_string(path).expect("readable OBJ");
    let mut mesh = TriangleMesh::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let x: Vec<Real> = words.map(|w| w.parse().expect("coordinate")).collect();
                assert_eq!(x.len(), 3, "vertex line `{line}`");
                mesh.vertices.push(Vec3::new(x[0], x[1], x[2]));
            }
            Some("f") => {
                let i: Vec<u32> = words
                    .map(|w| w.split('/').next().unwrap_or(w).parse().expect("index"))
                    .collect();
                assert_eq!(i.len(), 3, "face line `{line}`");
                assert!(i.iter().all(|&i| i >= 1), "1-based index in `{line}`");
                mesh.triangles.push([i[0] - 1, i[1] - 1, i[2] - 1]);
            }
            _ => {}
        }
    }
    mesh
}

/// `Σ A_m L` over patches and the relative tolerance `max δ²/4 + 10⁻¹²` (see the module docs).
fn expected_volume(model: &Model) -> (Real, Real) {
    let m = SEGMENTS as Real;
    let mut volume = 0.0;
    let mut tolerance: Real = 1e-12;
    for (k, patch) in model.patches.iter().enumerate() {
        let r = 0.5 * model.sections[patch.section].diameter();
        let area = 0.5 * m * r * r * (std::f64::consts::TAU / m).sin();
        let length = ArcLengthTable::new(&patch.curve, 256).length();
        let copies = patch_copies(model, k).len() as Real;
        volume += copies * area * length;
        let samples = SAMPLES_PER_POINT * patch.curve.num_points();
        let tangent = |k: usize| {
            let u = k as Real / samples as Real;
            patch.curve.derivatives(u, 1)[1].normalize()
        };
        let delta = (0..samples)
            .map(|k| tangent(k).dot(&tangent(k + 1)).clamp(-1.0, 1.0).acos())
            .fold(0.0, Real::max);
        tolerance = tolerance.max(delta * delta / 4.0);
    }
    (volume, tolerance)
}

/// What one design's mesh measured.
struct Measured {
    triangles: usize,
    volume: Real,
    expected: Real,
}

/// Meshes `model`, writes STL and OBJ into `dir`, reads both back and checks them; returns the numbers.
fn check_model(model: &Model, dir: &TempDir, name: &str) -> Measured {
    let mesh = reference_device_mesh(model, SEGMENTS, SAMPLES_PER_POINT).expect("reference mesh");
    mesh.check_closed()
        .unwrap_or_else(|e| panic!("{name}: in memory: {e}"));
    let (expected, relative) = expected_volume(model);
    let volume = mesh.volume();
    assert!(
        (volume / expected - 1.0).abs() < relative,
        "{name}: volume {volume:e}, expected {expected:e} ± {relative:e} relative"
    );

    let stl_path = dir.join(&format!("{name}.stl"));
    stl::write_stl_with_header(&stl_path, &mesh, "test").expect("STL written");
    let read = stl::read_stl(&stl_path).expect("STL read back");
    assert_eq!(
        read.triangles.len(),
        mesh.triangles.len(),
        "{name}: STL triangles"
    );
    read.check_closed()
        .unwrap_or_else(|e| panic!("{name}: STL read back (vertices merged): {e}"));
    let extent = mesh.vertices.iter().map(|v| v.amax()).fold(0.0, Real::max);
    let f32_bound = 2.0 * mesh.area() * extent * (2.0 as Real).powi(-24);
    let read_volume = read.volume();
    assert!(read_volume > 0.0, "{name}: STL volume {read_volume}");
    assert!(
        (read_volume - volume).abs() < f32_bound,
        "{name}: STL volume {read_volume:e} vs {volume:e} (f32 bound {f32_bound:e})"
    );

    let obj_path = dir.join(&format!("{name}.obj"));
    obj::write_obj(&obj_path, &mesh, "test").expect("OBJ written");
    let read = read_obj(&obj_path);
    read.check_closed()
        .unwrap_or_else(|e| panic!("{name}: OBJ read back: {e}"));
    // The OBJ writer prints shortest round-trip decimals: the mesh comes back bit for bit.
    assert_eq!(read, mesh, "{name}: OBJ round trip");
    println!(
        "{name}: {} patches, {} triangles, volume {volume:.6e} = {:.6} × Σ A_16 L (tolerance {relative:.1e}), \
         STL read-back volume off by {:.1e} relative",
        model.patches.len(),
        mesh.triangles.len(),
        volume / expected,
        (read_volume / volume - 1.0).abs()
    );
    Measured {
        triangles: mesh.triangles.len(),
        volume,
        expected,
    }
}

#[test]
#[ignore = "full size (every design of designs/, the paper stents included): run by .ci/run with cargo test --release -- --ignored"]
fn every_design_exports_closed_outward_stl_and_obj() {
    let dir = TempDir::new("mesh-designs");
    for file in designs_and_good_small() {
        let design = load_design(&file).unwrap_or_else(|e| panic!("{e}"));
        let name = file
            .file_stem()
            .and_then(|s| s.to_str())
            .expect("file name");
        let measured = check_model(&design.model, &dir, name);
        assert!(measured.triangles > 0 && measured.volume > 0.0 && measured.expected > 0.0);
    }
}

/// The closed-check of the STL read back when every patch is swept with the same section phase, as
/// `reference_device_mesh` would without its per-patch phase.
fn same_phase_stl_is_closed(model: &Model, dir: &TempDir, name: &str) -> bool {
    let settings = TubeSettings {
        segments_around: SEGMENTS,
        ..TubeSettings::default()
    };
    let mut mesh = TriangleMesh::new();
    for patch in &model.patches {
        let frames = FrameField::rotation_minimising(
            &patch.curve,
            patch.normal_hint,
            &FrameSettings::default(),
        )
        .expect("frames");
        let r = 0.5 * model.sections[patch.section].diameter();
        let samples = SAMPLES_PER_POINT * patch.curve.num_points();
        let tube = sweep_curve(&patch.curve, &frames, r, samples, 0.0, &settings).expect("tube");
        mesh.append(&tube);
    }
    // In memory every shell is closed on its own…
    mesh.check_closed().expect("closed in memory");
    let path = dir.join(&format!("{name}-same-phase.stl"));
    stl::write_stl(&path, &mesh).expect("STL written");
    // …but merging coincident vertices on reading joins the coinciding rings.
    stl::read_stl(&path)
        .expect("STL read")
        .check_closed()
        .is_ok()
}

#[test]
fn tangential_joints_stay_manifold_after_vertex_merging() {
    // Two patches meeting tangentially with the same frame have coinciding end rings when swept with the
    // same section phase; STL vertex merging then glues four triangles to each ring edge. The control
    // (same phase) must fail, and `reference_device_mesh` (its own phase per patch) must pass, both on the
    // multi-patch `good_small.yaml` (line + arc, tangent +x and d2 = e_y at the knee) and on two collinear
    // lines.
    let dir = TempDir::new("mesh-phase");
    let yaml = dir.join("collinear.yaml");
    std::fs::write(&yaml, COLLINEAR).expect("design written");
    let good_small = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/good_small.yaml");
    for file in [yaml, good_small] {
        let design = load_design(&file).unwrap_or_else(|e| panic!("{e}"));
        let model = &design.model;
        assert!(model.patches.len() >= 2);
        let name = file
            .file_stem()
            .and_then(|s| s.to_str())
            .expect("file name");
        // The joint really is tangential with equal frames: the end frame of the first patch equals the start
        // frame of the second.
        let frame = |k: usize, u: Real| {
            let p = &model.patches[k];
            FrameField::rotation_minimising(&p.curve, p.normal_hint, &FrameSettings::default())
                .and_then(|f| f.at(&p.curve, u))
                .expect("frame")
        };
        let (end, start) = (frame(0, 1.0), frame(1, 0.0));
        assert!((end.position - start.position).norm() < 1e-12);
        assert!(
            (end.rotation - start.rotation).norm() < 1e-9,
            "{name}: frames differ at the joint"
        );
        assert!(
            !same_phase_stl_is_closed(model, &dir, name),
            "{name}: the control should expose the coinciding rings"
        );
        let measured = check_model(model, &dir, name);
        assert!(measured.volume > 0.0);
    }
}

/// The largest distance of `points` from the line through their centroid along their principal direction.
fn distance_from_principal_line(points: &[Vec3]) -> Real {
    let n = points.len() as Real;
    let centroid = points.iter().sum::<Vec3>() / n;
    let covariance = points
        .iter()
        .map(|p| (p - centroid) * (p - centroid).transpose())
        .sum::<stentkit::math::Mat3>();
    let eigen = covariance.symmetric_eigen();
    let k = eigen.eigenvalues.imax();
    let axis = eigen.eigenvectors.column(k).into_owned();
    points
        .iter()
        .map(|p| {
            let d = p - centroid;
            (d - axis * axis.dot(&d)).norm()
        })
        .fold(0.0, Real::max)
}

#[test]
fn the_temporary_shape_is_the_device_where_its_programme_takes_it() {
    // `stentkit mesh --state temporary` generates the device in its programme's temporary placement, without
    // simulating. References, from the designs: the straight stent contracts radially by Δr = 15 mm from
    // R = 20 mm, and the curved stent's target is straightened with crowns of radius 5 mm; both have a wire of
    // diameter 0.6 mm. So the straight stent's temporary device lies within 5 + 0.3 mm of a straight axis (its
    // crown wires on the cylinder of radius 5, its straight bridges' chords inside it), and the curved stent's
    // within 5 + 2.5 + 0.3 mm (its radial sine bridges, amplitude h_b = 2.5 mm, bulge out by that), and each
    // reaches its bound, to the section polygon: its vertices there lie on the bound, or up to
    // 0.3 (1 − cos(π/16)) = 5.8e-3 mm inside it with 16 segments; the fitted wires stray outside by up to their
    // fit error, and STL's f32 adds 1e-5 at most. The straight stent is measured from its axis x1, the curved
    // one from the vertices' principal line. The curved stent's permanent shape is 20 mm in radius on a 45°
    // arc: tens of mm off any line. The driven nodes must meet the programme's targets P_0 + η to round-off
    // (the fitted wires' ends are exact).
    let dir = TempDir::new("temporary_shape");
    for (name, radius) in [("straight_stent.yaml", 5.3), ("curved_stent.yaml", 7.8)] {
        let out_path = dir.join(&format!("{name}.stl"));
        let out = crate::outputs::stentkit(&[
            "mesh",
            crate::outputs::path_str(&crate::outputs::design(name)),
            "--state",
            "temporary",
            "-o",
            crate::outputs::path_str(&out_path),
        ]);
        let stdout = crate::outputs::text(&out.stdout);
        assert!(
            out.status.success(),
            "{}",
            crate::outputs::text(&out.stderr)
        );
        let misfit: Real = stdout
            .split("within ")
            .nth(1)
            .and_then(|s| s.split_whitespace().next())
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| panic!("{stdout}"));
        assert!(
            misfit < 1e-9,
            "{name}: driven nodes {misfit} off their targets"
        );
        let mesh = stl::read_stl(&out_path).expect("STL");
        mesh.check_closed().expect("closed");
        // The wires are the generated curves as fitted: their centrelines stray from the bound's cylinder by
        // up to the fit's deviation.
        let fit = stentkit::design::load_design_with(
            &crate::outputs::design(name),
            &stentkit::design::DesignOverrides {
                temporary_shape: true,
                ..Default::default()
            },
        )
        .expect("temporary design")
        .model
        .patches
        .iter()
        .filter_map(|p| p.fit_error)
        .fold(0.0, Real::max);
        // The straight stent's axis is x1 (its design's centreline); the curved one's, placed by the fit, is
        // found as the principal line.
        let far = if name == "straight_stent.yaml" {
            mesh.vertices
                .iter()
                .map(|v| v.y.hypot(v.z))
                .fold(0.0, Real::max)
        } else {
            distance_from_principal_line(&mesh.vertices)
        };
        assert!(
            (radius - 5.8e-3..=radius + fit + 1e-5).contains(&far),
            "{name}: the temporary device reaches {far} from its axis (fit error {fit})"
        );
    }
    // The permanent curved stent, for contrast, is far from straight.
    let permanent = dir.join("curved_permanent.stl");
    let out = crate::outputs::stentkit(&[
        "mesh",
        crate::outputs::path_str(&crate::outputs::design("curved_stent.yaml")),
        "-o",
        crate::outputs::path_str(&permanent),
    ]);
    assert!(out.status.success());
    let far = distance_from_principal_line(&stl::read_stl(&permanent).expect("STL").vertices);
    assert!(far > 20.3, "{far}");
    // A design without a programme has no temporary shape.
    let out = crate::outputs::stentkit(&[
        "mesh",
        crate::outputs::path_str(&crate::outputs::design("bend45.yaml")),
        "--state",
        "temporary",
        "-o",
        crate::outputs::path_str(&dir.join("bend.stl")),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(crate::outputs::text(&out.stderr).contains("no programme, so no temporary shape"));
}
