//! Centreline files (issue 16, part 1): VMTK's aorta centreline and the same data re-encoded by VTK's own
//! writers in every encoding (tests/data/centrelines/, made by scripts/centreline_test_files.py) read to the
//! values VTK's reader gives; bad files are refused with the file named and what is wrong.

use crate::common::{edit, fixtures};
use std::path::{Path, PathBuf};
use stentkit::io::centreline::{CentrelineError, read_centreline};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/centrelines")
        .join(name)
}

/// Source: the data's provenance note (../shared/data/vessels/README.md, from VMTK's test data): 409 points in
/// two polylines of 211 and 198 points sharing their start, radius 2.78–7.58 mm.
#[test]
fn vmtks_aorta_centreline_reads_as_its_provenance_says() {
    let lines = read_centreline(
        &data("aorta-centerline.vtp"),
        Some("MaximumInscribedSphereRadius"),
    )
    .expect("the aorta centreline reads");
    assert_eq!(lines.len(), 2);
    assert_eq!((lines[0].points.len(), lines[1].points.len()), (211, 198));
    assert_eq!(
        lines[0].points[0], lines[1].points[0],
        "they share their start"
    );
    let radius: Vec<f64> = lines
        .iter()
        .flat_map(|l| l.radius.clone().expect("radius"))
        .collect();
    let (lo, hi) = radius
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &r| (a.min(r), b.max(r)));
    assert!(
        (lo - 2.7758680852).abs() < 1e-9 && (hi - 7.5780218521).abs() < 1e-9,
        "{lo} {hi}"
    );
}

/// A radius array the file does not have is refused with the arrays it does have.
#[test]
fn a_missing_radius_array_names_the_arrays_there_are() {
    let error =
        read_centreline(&data("aorta-centerline.vtp"), Some("Radius")).expect_err("no such array");
    let CentrelineError::Invalid { message, .. } = &error else {
        panic!("{error}");
    };
    assert!(
        message.contains("no point array `Radius`")
            && message.contains("`MaximumInscribedSphereRadius`"),
        "{error}"
    );
}

/// Source: the curved stent of designs/curved_stent.yaml, whose centreline is an exact circular arc (radius
/// 100 mm, 45°). The same arc given as a CSV of 400 points and smoothed to 1e-4 mm gives the same device: every
/// node within 1e-3 mm. Tolerance: the fitted axis is within the smoothing (1e-4 mm) of the arc, and a node sits
/// up to R = 20 mm off the axis, so the frame's angle error (the tangent error of a cubic whose deviation is δ
/// over spans of h ≈ 10 mm: about 4δ/h = 4e-5 rad) moves it by about 8e-4 mm; the arc-length stations move by
/// less than the deviation. Measured: 7.2e-4 mm.
#[test]
fn a_csv_of_an_exact_arc_gives_the_arc_centrelines_device() {
    let dir = std::env::temp_dir().join(format!("stentkit-csv-arc-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch");
    let csv = dir.join("arc.csv");
    let mut text = String::from("x,y,z\n");
    for k in 0..400 {
        let theta = (45.0f64).to_radians() * k as f64 / 399.0;
        text.push_str(&format!(
            "{},{},{}\n",
            100.0 * theta.cos(),
            0.0,
            100.0 * theta.sin() - 5.0
        ));
    }
    std::fs::write(&csv, text).expect("csv");
    let curved = fixtures::design("curved_stent.yaml");
    let exact = curved.design();
    let fitted = curved
        .set(
            "stent.centreline",
            &format!(
                "{{file: {{path: {}, smoothing: 1.0e-4, reference: [1, 0, 0]}}}}",
                csv.display()
            ),
        )
        .design();
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(exact.model.nodes.len(), fitted.model.nodes.len());
    let largest = exact
        .model
        .nodes
        .iter()
        .zip(&fitted.model.nodes)
        .map(|(a, b)| (a.position - b.position).norm())
        .fold(0.0, f64::max);
    eprintln!("largest node difference {largest:.3e} mm");
    assert!(largest < 1e-3, "largest node difference {largest} mm");
    assert!(
        fitted.notes.iter().any(|n| n.contains("centreline from")),
        "{:?}",
        fitted.notes
    );
}

/// One polyline of a reference: its points and, where the file has it, the radius at them.
type ReferenceLine = (Vec<[f64; 3]>, Option<Vec<f64>>);

/// The polylines of a `*.reference.json` (written by scripts/centreline_test_files.py from VTK's readers).
fn reference(file: &Path) -> Vec<ReferenceLine> {
    let text =
        std::fs::read_to_string(format!("{}.reference.json", file.display())).expect("reference");
    let json: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    json["polylines"]
        .as_array()
        .expect("polylines")
        .iter()
        .map(|l| {
            let points = l["points"]
                .as_array()
                .expect("points")
                .iter()
                .map(|p| {
                    let c: Vec<f64> = p
                        .as_array()
                        .expect("xyz")
                        .iter()
                        .map(|x| x.as_f64().expect("number"))
                        .collect();
                    [c[0], c[1], c[2]]
                })
                .collect();
            let radius = l["radius"]
                .as_array()
                .map(|r| r.iter().map(|x| x.as_f64().expect("number")).collect());
            (points, radius)
        })
        .collect()
}

/// Source: VTK 9.7's own readers (scripts/centreline_test_files.py), on files VTK's writers made from the aorta
/// centreline in every XML encoding (ascii; inline base64 with and without zlib; appended raw with and without
/// zlib; appended base64; UInt64 headers; the radius array after two others), as legacy VTK (ASCII and binary,
/// the 5.1 OFFSETS/CONNECTIVITY layout and the 4.2 one), with a third polyline, as CSV and as a SimVascular path.
/// Tolerance 1e-12 relative: both read the same stored numbers (a Float32 array's text rounded to single
/// precision as VTK does); the reference's JSON is parsed by serde_json, whose float parsing may be one ulp off.
#[test]
fn every_encoding_reads_to_what_vtk_reads() {
    let dir = data("");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("centrelines")
        .map(|e| e.expect("entry").path())
        .filter(|p| {
            p.extension().is_some_and(|e| e == "json")
                && p.to_string_lossy().ends_with(".reference.json")
        })
        .map(|p| PathBuf::from(p.to_string_lossy().trim_end_matches(".reference.json")))
        .collect();
    files.sort();
    assert!(files.len() >= 13, "{files:?}");
    for file in &files {
        let radius_array = (!file.extension().is_some_and(|e| e == "pth" || e == "csv"))
            .then_some("MaximumInscribedSphereRadius");
        let lines = read_centreline(file, radius_array).unwrap_or_else(|e| panic!("{e}"));
        let expected = reference(file);
        assert_eq!(lines.len(), expected.len(), "{}", file.display());
        for (line, (points, radius)) in lines.iter().zip(&expected) {
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
            assert_eq!(line.points.len(), points.len(), "{}", file.display());
            for (k, (p, q)) in line.points.iter().zip(points).enumerate() {
                assert!(
                    close(p.x, q[0]) && close(p.y, q[1]) && close(p.z, q[2]),
                    "{}: point {k}: {p:?} against VTK's {q:?}",
                    file.display()
                );
            }
            match (&line.radius, radius) {
                (Some(r), Some(q)) => assert!(
                    r.len() == q.len() && r.iter().zip(q).all(|(a, b)| close(*a, *b)),
                    "{}: radius",
                    file.display()
                ),
                (None, None) => {}
                (r, q) => panic!("{}: radius {r:?} against VTK's {q:?}", file.display()),
            }
        }
    }
}

/// Bad files are refused naming the file and what is wrong.
#[test]
fn bad_centreline_files_are_refused_with_the_reason() {
    for (name, radius, fragment) in [
        ("not_vtk.vtp", None, "not VTK XML PolyData"),
        ("no_lines.vtp", None, "no polyline"),
        (
            "no_radius.vtp",
            Some("MaximumInscribedSphereRadius"),
            "no point array `MaximumInscribedSphereRadius`",
        ),
        ("nan_point.vtp", None, "is not finite ([NaN,"),
        ("missing.vtp", None, "cannot read the centreline"),
        (
            "aorta_line0.csv.reference.json",
            None,
            "unknown centreline format",
        ),
    ] {
        let error = read_centreline(&data(name), radius)
            .expect_err(name)
            .to_string();
        assert!(
            error.starts_with(&data(name).display().to_string()),
            "{error}"
        );
        assert!(error.contains(fragment), "{name}: {error}");
    }
}

/// A design placing a stent on a file centreline refuses a segment longer than the polyline, a polyline index
/// the file does not have, and a centreline bending tighter than the stent radius, each at its field; the
/// aorta design itself reads and sizes the stent at the segment's mean lumen radius × (1 + oversize).
#[test]
fn designs_on_file_centrelines_are_checked() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/aorta_stent.yaml");
    let text = std::fs::read_to_string(&path).expect("design");
    let design = stentkit::design::parse_design(&text, &path).expect("the aorta design reads");
    assert!(
        design
            .notes
            .iter()
            .any(|n| n.contains("mean lumen radius") && n.contains("stent radius")),
        "{:?}",
        design.notes
    );
    for (from, to, field, fragment) in [
        (
            "length: 40 ",
            "length: 400 ",
            "stent.centreline.file.length",
            "longer than the polyline",
        ),
        (
            "polyline: longest",
            "polyline: 7",
            "stent.centreline.file.polyline",
            "the file has 2 polylines",
        ),
        (
            "smoothing: 0.2 ",
            "smoothing: 0.01 ",
            "stent.centreline.file",
            "radius of curvature",
        ),
    ] {
        assert!(text.contains(from), "{from}");
        let error = stentkit::design::parse_design(&text.replace(from, to), &path)
            .expect_err(to)
            .to_string();
        assert!(
            error.contains(field) && error.contains(fragment),
            "{to}: {error}"
        );
    }
}

/// The overrides of a brief run (as `the_aorta_stents_run_shows_the_vessel_lumen`'s): to t = 0.004 s, with one
/// snapshot there besides the initial one.
const BRIEF_RUN: [&str; 2] = ["time.end=0.004", "output={snapshots: {times: [0.004]}}"];

/// The aorta stent's run folder holds the vessel's lumen beside the device (snapshots/vessel_lumen.stl, a
/// closed tube of the file's lumen radius; `.ci/run` checks it with trimesh), and the stent's reference shape
/// sits around the lumen's centreline at the oversized radius. Source: the design's sizing rule, R = the
/// segment's mean lumen radius × (1 + oversize) with oversize 0.1, and crowns generated at R from the axis.
/// Tolerance 3 % of R: a crest or trough sits h_c = 2 mm along the axis from its station, so on an axis bending
/// with a radius of curvature ρ ≳ 20 mm its distance to the axis differs from R by up to about h_c²/(2ρ) ≈
/// 0.1 mm (1.6 %); the mean over the samples of the lumen differs from the segment's by their spacing.
#[test]
fn the_aorta_stents_run_shows_the_vessel_lumen() {
    let dir = crate::materials::run("designs/aorta_stent.yaml", "aorta_stent_vessel", &BRIEF_RUN);
    let design = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/aorta_stent.yaml");
    let recording = std::fs::read(dir.join("run.mcap")).expect("run.mcap");
    assert!(
        recording.windows(b"/vessel".len()).any(|w| w == b"/vessel"),
        "run.mcap has a /vessel channel (its one message is checked by scripts/check_outputs.py)"
    );
    let stl = std::fs::read(dir.join("snapshots/vessel_lumen.stl")).expect("the lumen");
    let triangles = u32::from_le_bytes([stl[80], stl[81], stl[82], stl[83]]) as usize;
    assert_eq!(stl.len(), 84 + 50 * triangles);
    let model = stentkit::design::load_design(&design)
        .expect("design")
        .model;
    let vessel = model.vessel.as_ref().expect("a vessel");
    let radius = vessel.radius.as_ref().expect("a lumen radius");
    let mut weighted = 0.0;
    let mut length = 0.0;
    for (w, r) in vessel.points.windows(2).zip(radius.windows(2)) {
        let d = (w[1] - w[0]).norm();
        weighted += 0.5 * (r[0] + r[1]) * d;
        length += d;
    }
    let stent_radius = 1.1 * weighted / length;
    for node in &model.nodes {
        let distance = vessel
            .points
            .windows(2)
            .map(|w| {
                let (a, b) = (w[0], w[1]);
                let t =
                    ((node.position - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
                (node.position - (a + (b - a) * t)).norm()
            })
            .fold(f64::MAX, f64::min);
        assert!(
            (distance - stent_radius).abs() < 0.03 * stent_radius,
            "node {} at {distance} from the lumen's centreline, the stent radius is {stent_radius}",
            node.name
        );
    }
}

// Source: the lumen radius the file gives (VMTK's MaximumInscribedSphereRadius of the aorta, interpolated along
// the vessel the model keeps). With `taper: true` every crown is sized from the lumen at its own station: the
// centre of each crown's nodes lies on the centreline, so their mean distance from the vessel's centreline must
// be the local lumen radius there × 1.1 (oversize), found here independently of the generator by the closest
// point of the sampled vessel (3 %: the crown's nodes sit ±h_c = 2 mm off its station, where the lumen differs by
// up to 0.1 mm of its ~6 mm, and the centreline is a fit within 0.16 mm of the file's points). This aorta
// narrows from 7.3 to 4.3 mm over the segment, so the crowns must differ by far more than that tolerance; a
// design asking to taper without the lumen radius is refused at `stent.taper`.
#[test]
fn a_tapered_stent_follows_the_local_lumen() {
    let design = fixtures::design("aorta_stent.yaml")
        .set("stent.taper", "true")
        .design();
    assert!(
        design
            .notes
            .iter()
            .any(|n| n.contains("local lumen radius")),
        "{:?}",
        design.notes
    );
    let model = &design.model;
    let vessel = model.vessel.as_ref().expect("a vessel");
    let lumen = vessel.radius.as_ref().expect("a lumen radius");
    // The closest point of the sampled vessel and the lumen radius interpolated there.
    let closest = |p: &stentkit::math::Vec3| {
        vessel
            .points
            .windows(2)
            .zip(lumen.windows(2))
            .map(|(w, r)| {
                let (a, b) = (w[0], w[1]);
                let t = ((p - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
                ((p - (a + (b - a) * t)).norm(), r[0] + t * (r[1] - r[0]))
            })
            .fold((f64::MAX, 0.0), |m, x| if x.0 < m.0 { x } else { m })
    };
    let mut sizes = Vec::new();
    for k in 1..=5 {
        let nodes: Vec<_> = model
            .nodes
            .iter()
            .filter(|n| n.name.starts_with(&format!("c{k}_")))
            .collect();
        let centre = nodes
            .iter()
            .fold(stentkit::math::Vec3::zeros(), |c, n| c + n.position)
            / nodes.len() as f64;
        let target = 1.1 * closest(&centre).1;
        let mean = nodes.iter().map(|n| closest(&n.position).0).sum::<f64>() / nodes.len() as f64;
        println!("crown {k}: nodes {mean:.4} from the centreline, local lumen × 1.1 = {target:.4}");
        assert!(
            (mean - target).abs() < 0.03 * target,
            "crown {k}: {mean} against {target}"
        );
        sizes.push(mean);
    }
    let (lo, hi) = sizes
        .iter()
        .fold((f64::MAX, 0.0_f64), |(lo, hi), &s| (lo.min(s), hi.max(s)));
    assert!(hi > 1.3 * lo, "the crowns taper: {sizes:?}");
    // Edited as text, not through `fixtures`: a refused design (a field removed, which `--set` cannot do).
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/aorta_stent.yaml");
    let refused = edit(
        &std::fs::read_to_string(&path).expect("design"),
        "  oversize: 0.1 ",
        "  taper: true\n  radius: 6 #",
    );
    let err = stentkit::design::parse_design(&refused, &path).expect_err("no oversize");
    assert!(err.to_string().contains("stent.taper"), "{err}");
}

/// A scratch folder for one test (removed first if a previous run left it).
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("stentkit-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// A VTK XML PolyData file of one polyline through `points` `Float32` points, whose `Points` array is the
/// base64 text `block` (header and data, as VTK writes `format="binary"`), zlib-compressed as the file says,
/// with headers of `header_type`; the lines are ASCII.
fn vtp_with_points(points: usize, block: &str, header_type: &str) -> String {
    let ids: Vec<String> = (0..points).map(|k| k.to_string()).collect();
    format!(
        r#"<?xml version="1.0"?>
<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="{header_type}" compressor="vtkZLibDataCompressor">
  <PolyData>
    <Piece NumberOfPoints="{points}" NumberOfVerts="0" NumberOfLines="1" NumberOfStrips="0" NumberOfPolys="0">
      <Points>
        <DataArray type="Float32" Name="Points" NumberOfComponents="3" format="binary">{block}</DataArray>
      </Points>
      <Lines>
        <DataArray type="Int64" Name="connectivity" format="ascii">{}</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">{points}</DataArray>
      </Lines>
    </Piece>
  </PolyData>
</VTKFile>
"#,
        ids.join(" ")
    )
}

/// VTK's compressed binary block: the header words (block count, block size, last block's size, each
/// block's compressed size) as `u32` or `u64`, then the compressed blocks, in base64.
fn compressed_block(words: &[u64], wide: bool, blocks: &[Vec<u8>]) -> String {
    use base64::Engine as _;
    let mut raw = Vec::new();
    for &w in words {
        if wide {
            raw.extend_from_slice(&w.to_le_bytes());
        } else {
            raw.extend_from_slice(&(w as u32).to_le_bytes());
        }
    }
    for b in blocks {
        raw.extend_from_slice(b);
    }
    base64::engine::general_purpose::STANDARD.encode(raw)
}

/// zlib of `bytes` zero bytes, compressed from a 64 KiB buffer so that the input is never held whole.
fn zlib_of_zeros(bytes: usize) -> Vec<u8> {
    use std::io::Write as _;
    let mut encoder = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
    let chunk = vec![0u8; 1 << 16];
    let mut left = bytes;
    while left > 0 {
        let n = left.min(chunk.len());
        encoder.write_all(&chunk[..n]).expect("compresses");
        left -= n;
    }
    encoder.finish().expect("compresses")
}

/// Issue 31, item 5: a zlib bomb in a `.vtp`. Reproduces the issue's files, generated here (352 kB is too large
/// to commit): 409 `Float32` points (4908 bytes, VMTK's aorta's count) whose one zlib block inflates to
/// 256 MiB while its header says 1 KiB — before the fix it took 15 s and 2.4 GB and then read as a centreline
/// of zeros —, and a header declaring two blocks of 4 GiB (8 GiB) — before, a 1.4 MB file asked for 8 GiB and
/// aborted. Both are now refused naming the file: the first after inflating 1 KiB + 1 byte (the header's
/// size, the bound), the second before inflating anything (8 GiB is more than 409 points need). The control:
/// the same generator's honest file (one block of 4908 bytes) reads to its 409 points, and the same file
/// claiming 300 000 points (more than `MAX_CENTRELINE_POINTS`, 262 144) is refused before any array is read.
#[test]
fn a_zlib_bomb_is_refused_without_inflating_it() {
    use std::io::Write as _;
    let dir = scratch("zlib-bomb");
    let points = 409;
    let need = points * 3 * 4;
    // The control: a straight line, x = k, its one block declared as it is.
    let data: Vec<u8> = (0..points)
        .flat_map(|k| [k as f32, 0.0, 0.0])
        .flat_map(f32::to_le_bytes)
        .collect();
    let mut encoder = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
    encoder.write_all(&data).expect("compresses");
    let honest = encoder.finish().expect("compresses");
    let good = dir.join("good.vtp");
    let block = compressed_block(
        &[1, need as u64, need as u64, honest.len() as u64],
        false,
        std::slice::from_ref(&honest),
    );
    std::fs::write(&good, vtp_with_points(points, &block, "UInt32")).expect("write");
    let lines = read_centreline(&good, None).expect("the honest file reads");
    assert_eq!(lines[0].points.len(), points);
    assert_eq!(lines[0].points[408].x, 408.0);

    // More points than the limit, claimed by an honest-looking file: refused before any array is decoded.
    let many = dir.join("many.vtp");
    std::fs::write(
        &many,
        edit(
            &std::fs::read_to_string(&good).expect("good.vtp"),
            "NumberOfPoints=\"409\"",
            "NumberOfPoints=\"300000\"",
        ),
    )
    .expect("write");
    let error = read_centreline(&many, None)
        .expect_err("too many points")
        .to_string();
    assert!(
        error.contains("the file declares 300000 points, more than stentkit's limit of 262144"),
        "{error}"
    );

    let bomb = zlib_of_zeros(256 << 20);
    let block = compressed_block(&[1, 1024, 1024, bomb.len() as u64], false, &[bomb]);
    let inflating = dir.join("bomb.vtp");
    std::fs::write(&inflating, vtp_with_points(points, &block, "UInt32")).expect("write");
    let size = std::fs::metadata(&inflating).expect("size").len();
    let started = std::time::Instant::now();
    let error = read_centreline(&inflating, None)
        .expect_err("a block inflating past its header is refused")
        .to_string();
    eprintln!(
        "{size} bytes, refused in {:.3} s: {error}",
        started.elapsed().as_secs_f64()
    );
    assert!(
        error.starts_with(&inflating.display().to_string())
            && error.contains("array `Points`: compressed block 1 of 1 inflates to more than the 1024 bytes its header declares"),
        "{error}"
    );

    let claiming = dir.join("claims_8_gib.vtp");
    let small = zlib_of_zeros(1 << 20);
    let block = compressed_block(
        &[2, 4 << 30, 4 << 30, small.len() as u64, small.len() as u64],
        true,
        &[small.clone(), small],
    );
    std::fs::write(&claiming, vtp_with_points(points, &block, "UInt64")).expect("write");
    let error = read_centreline(&claiming, None)
        .expect_err("a header claiming more than the points need is refused")
        .to_string();
    eprintln!("{error}");
    assert!(
        error.starts_with(&claiming.display().to_string())
            && error.contains(&format!(
                "its header declares 8589934592 bytes, more than the {need} bytes its {points} points need"
            )),
        "{error}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Calls `read_centreline(path)` on a thread and waits at most `seconds` for it: before the fix a FIFO blocked
/// for ever and `/dev/zero` was read until memory ran out, so a hang must fail the test, not stall it.
fn read_within(path: &Path, seconds: u64) -> Result<usize, String> {
    let (send, receive) = std::sync::mpsc::channel();
    let owned = path.to_path_buf();
    std::thread::spawn(move || {
        let result = read_centreline(&owned, None)
            .map(|lines| lines.len())
            .map_err(|e| e.to_string());
        let _ = send.send(result);
    });
    receive
        .recv_timeout(std::time::Duration::from_secs(seconds))
        .unwrap_or_else(|_| panic!("reading {} did not end in {seconds} s", path.display()))
}

/// Issue 31, item 6: a centreline path that is not a regular file. `/dev/zero` and `/dev/urandom` were read
/// until memory ran out, a FIFO blocked for ever (here: a FIFO no one writes to), a folder gave the operating
/// system's error; a regular file of 4 MiB + 1 byte (sparse) is one byte over the limit. Each is refused at
/// once naming the file and why (20 s is the deadline of a hang, not a timing). End to end, `stentkit check`
/// on the aorta design pointed at the FIFO exits with status 2 (bad input) naming the field and the file.
/// The design file itself is read the same way (`check` on the FIFO, on `/dev/zero`).
#[test]
fn only_regular_files_within_the_size_limit_are_read() {
    let dir = scratch("not-regular");
    let fifo = dir.join("centreline.vtp");
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo runs")
            .success()
    );
    let big = dir.join("big.csv");
    std::fs::File::create(&big)
        .and_then(|f| f.set_len(4 * 1024 * 1024 + 1))
        .expect("a sparse file");
    let limit = stentkit::io::centreline::MAX_CENTRELINE_BYTES;
    assert_eq!(
        limit,
        4 * 1024 * 1024,
        "the limit docs/when-things-go-wrong.md states"
    );
    for (path, fragment) in [
        (
            Path::new("/dev/zero"),
            "a character device, not a regular file",
        ),
        (
            Path::new("/dev/urandom"),
            "a character device, not a regular file",
        ),
        (fifo.as_path(), "a FIFO (named pipe), not a regular file"),
        (dir.as_path(), "a folder, not a regular file"),
        (
            big.as_path(),
            "the file has 4194305 bytes (4.0 MiB), more than stentkit's limit of 4 MiB",
        ),
    ] {
        let error = read_within(path, 20).expect_err("refused");
        assert!(
            error.starts_with(&path.display().to_string()) && error.contains(fragment),
            "{error}"
        );
    }

    let design = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/aorta_stent.yaml");
    let text = std::fs::read_to_string(&design).expect("design");
    let on_fifo = dir.join("on_fifo.yaml");
    // Edited as text, not through `fixtures`: reading the design is what is tested (and would block here).
    std::fs::write(
        &on_fifo,
        edit(
            &text,
            "data/aorta-centerline.vtp",
            fifo.to_str().expect("UTF-8"),
        ),
    )
    .expect("design");
    let out = check_within(&on_fifo);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("stent.centreline.file.path")
            && stderr.contains(&format!(
                "{}: a FIFO (named pipe), not a regular file",
                fifo.display()
            )),
        "{stderr}"
    );
    // The design file itself read from the same paths: before io::input it was read with no kind check, so
    // `check FIFO` hung and `check /dev/zero` said "the design is 0 bytes … more than the limit".
    for (path, what) in [
        (Path::new("/dev/zero"), "a character device"),
        (fifo.as_path(), "a FIFO (named pipe)"),
    ] {
        let out = check_within(path);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(
            stderr.contains(&format!(
                "{}: cannot read the design: {what}, not a regular file",
                path.display()
            )),
            "{stderr}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `stentkit check DESIGN`, failed if it has not ended within 20 s (the deadline of a hang, not a timing).
fn check_within(design: &Path) -> std::process::Output {
    crate::outputs::stentkit_within(
        &["check", design.to_str().expect("UTF-8")],
        std::time::Duration::from_secs(20),
    )
}

/// The aorta design with its centreline file block replaced: `path` and the lines of `file:` given
/// (`start`, `length`, `smoothing` when `Some`; dropped when `None`).
fn aorta_design_on(path: &Path, smoothing: Option<&str>, whole: bool) -> String {
    let design = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/aorta_stent.yaml");
    let text = std::fs::read_to_string(design).expect("design");
    text.lines()
        .filter_map(|line| {
            let key = line.trim_start();
            if key.starts_with("path: data/aorta-centerline.vtp") {
                Some(format!("      path: {}", path.display()))
            } else if whole && (key.starts_with("start:") || key.starts_with("length:")) {
                None
            } else if key.starts_with("smoothing:") {
                smoothing.map(|s| format!("      smoothing: {s}"))
            } else {
                Some(line.to_string())
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The value of `smoothing: X` that a too-tight refusal suggests (`set `smoothing: X` or more`).
fn suggested_smoothing(error: &str) -> String {
    error
        .split("set `smoothing: ")
        .nth(1)
        .and_then(|rest| rest.split('`').next())
        .unwrap_or_else(|| panic!("no suggestion in {error}"))
        .to_string()
}

/// Issue 31, item 7: a smoothing tighter than the points' scatter. Reproduces the issue's two cases: the
/// aorta design with `smoothing: 1e-9` (its 40 mm segment of 119 points; before, "singular system … a knot span
/// holds no data") and 10 000 noisy points (a 45° arc of radius 100 mm sampled every 0.008 mm, each point moved
/// by up to ±0.02 mm in each coordinate by a seeded generator; `smoothing: 0.001`, below the noise) — before,
/// 167 s and 791 MB (dense normal equations of up to 10 000 control points, O(n³)) and the same message. Both
/// are refused at `stent.centreline.file.smoothing`, saying the smoothing is too tight and what to set; the
/// value suggested is then accepted by the fit (the design may still be refused for the noise's tight bends,
/// which the stent cannot follow, but not for the smoothing).
#[test]
fn a_smoothing_tighter_than_the_points_is_refused_in_words() {
    let dir = scratch("too-tight");
    let aorta = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/data/aorta-centerline.vtp");
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut noise = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 0.04 - 0.02
    };
    let mut csv = String::from("x,y,z,radius\n");
    for k in 0..10_000 {
        let theta = 45f64.to_radians() * k as f64 / 9_999.0;
        csv.push_str(&format!(
            "{:.5},{:.5},{:.5},6\n",
            100.0 * theta.cos() + noise(),
            noise(),
            100.0 * theta.sin() + noise()
        ));
    }
    let noisy = dir.join("noisy.csv");
    std::fs::write(&noisy, csv).expect("csv");
    for (name, text) in [
        ("aorta", aorta_design_on(&aorta, Some("1e-9"), false)),
        ("noisy", aorta_design_on(&noisy, Some("0.001"), true)),
    ] {
        let path = dir.join(format!("{name}.yaml"));
        let started = std::time::Instant::now();
        let error = stentkit::design::parse_design(&text, &path)
            .expect_err("too tight")
            .to_string();
        eprintln!(
            "{name}: refused in {:.2} s: {error}",
            started.elapsed().as_secs_f64()
        );
        assert!(
            error.contains("stent.centreline.file.smoothing")
                && error.contains("is too tight")
                && error.contains("set `smoothing: "),
            "{error}"
        );
        let enough = suggested_smoothing(&error);
        let retried = edit(
            &text,
            text.lines()
                .find(|l| l.trim_start().starts_with("smoothing:"))
                .expect("a smoothing line"),
            &format!("      smoothing: {enough}"),
        );
        if let Err(e) = stentkit::design::parse_design(&retried, &path) {
            assert!(!e.to_string().contains("too tight"), "{enough}: {e}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 31, item 8: the lumen of a dense centreline. Reproduces the issue's 100 000-point centreline: a 45° arc
/// of radius 100 mm (78.5 mm) with a lumen radius of 6 mm as CSV (2.2 MB, under the 4 MiB limit), the aorta
/// stent on its whole length. Before, the lumen was sampled at twice the points (200 000 rings, a 240 MB
/// `vessel_lumen.stl`) and the disk estimate (45.7 MB) did not count it. Now the rings are at most
/// `MAX_LUMEN_RINGS` (1000; 12 segments around, so at most 24 000 triangles), and the disk estimate counts the
/// lumen to the byte (84 + 50 bytes per triangle) and, as for every run it is made for, covers every byte
/// written (module docs of `run::estimate`: it has not underestimated a run).
#[test]
fn a_dense_centrelines_lumen_is_bounded_and_counted() {
    let dir = scratch("dense-lumen");
    let mut csv = String::new();
    for k in 0..100_000 {
        let theta = 45f64.to_radians() * k as f64 / 99_999.0;
        csv.push_str(&format!(
            "{:.5},0,{:.5},6\n",
            100.0 * theta.cos(),
            100.0 * theta.sin()
        ));
    }
    let dense = dir.join("dense.csv");
    std::fs::write(&dense, csv).expect("csv");
    let design = dir.join("dense.yaml");
    std::fs::write(&design, aorta_design_on(&dense, Some("0.01"), true)).expect("design");
    let loaded = stentkit::design::load_design(&design).expect("the design reads");
    let rings = loaded.model.vessel.as_ref().expect("a vessel").points.len();
    assert_eq!(rings, stentkit::design::vessel::MAX_LUMEN_RINGS);
    let estimate = stentkit::run::estimate::estimated_disk(&loaded);
    let run = crate::materials::run(design.to_str().expect("UTF-8"), "dense_lumen", &BRIEF_RUN);
    let lumen = std::fs::metadata(run.join("snapshots/vessel_lumen.stl"))
        .expect("the lumen")
        .len();
    assert_eq!(lumen, 84 + 50 * 2 * 12 * rings as u64);
    let ran = stentkit::design::load_design_with(
        &design,
        &stentkit::design::DesignOverrides::sets(
            BRIEF_RUN
                .iter()
                .map(|set| set.parse().expect("override"))
                .collect(),
        ),
    )
    .expect("the design reads");
    let estimate_ran = stentkit::run::estimate::estimated_disk(&ran);
    assert_eq!(
        estimate_ran
            .part("snapshots")
            .expect("the snapshots' part")
            .file("vessel lumen"),
        lumen
    );
    let files = walk(&run);
    let written: u64 = files.iter().map(|f| f.1).sum();
    eprintln!(
        "lumen {lumen} bytes; run folder {written} bytes, estimated {} (the full design: {})",
        estimate_ran.total(),
        estimate.total()
    );
    assert!(
        written <= estimate_ran.total(),
        "{written} > {estimate_ran:?}: {files:?}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Every file under `dir` with its size.
fn walk(dir: &Path) -> Vec<(PathBuf, u64)> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).expect("folder").flatten() {
        let path = entry.path();
        if path.is_dir() {
            files.extend(walk(&path));
        } else if let Ok(m) = entry.metadata() {
            files.push((path, m.len()));
        }
    }
    files
}

/// Issue 31, item 16: the header of a CSV centreline. `bom.csv` (tests/data/centrelines) starts with a UTF-8
/// byte-order mark before the numeric row `0.0,0.0,0.0,6.0`; `letter_o.csv`'s first row is `0.0,0.0,O.0,6.0`
/// (a letter O). Before, both first rows were taken for a header and the first point silently lost (3 points
/// of 4). Now the mark is skipped and the four points read; a first row with a number in it is not a header,
/// so the O is an error at line 1, column 9; a header (no number) is still skipped, after a mark too; and a
/// second row without numbers is an error at its line.
#[test]
fn a_csv_header_is_a_row_without_numbers() {
    let lines = read_centreline(&data("bom.csv"), None).expect("bom.csv reads");
    assert_eq!(lines[0].points.len(), 4);
    assert_eq!(lines[0].points[0], stentkit::math::Vec3::zeros());
    assert_eq!(lines[0].radius.as_ref().expect("radius")[0], 6.0);
    let error = read_centreline(&data("letter_o.csv"), None)
        .expect_err("a letter in a number")
        .to_string();
    assert!(
        error.starts_with(&data("letter_o.csv").display().to_string())
            && error.contains("line 1, column 9: `O.0` (field 3 of 4) is not a number"),
        "{error}"
    );
    let dir = scratch("csv-header");
    for (name, text, expected) in [
        (
            "header.csv",
            "\u{feff}x,y,z,radius\n0,0,0,6\n1,0,0,6\n",
            Ok(2),
        ),
        (
            "two_headers.csv",
            "x,y,z\n0,0,0\nx,y,z\n1,0,0\n",
            Err("line 3: `x,y,z` has no number (only the first row may be a header)"),
        ),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text).expect("csv");
        match (read_centreline(&path, None), expected) {
            (Ok(lines), Ok(n)) => assert_eq!(lines[0].points.len(), n),
            (Err(e), Err(fragment)) => assert!(e.to_string().contains(fragment), "{e}"),
            (got, _) => panic!("{name}: {got:?}"),
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
