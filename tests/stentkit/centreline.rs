//! Centreline files (issue 16, part 1): VMTK's aorta centreline and the same data re-encoded by VTK's own
//! writers in every encoding (tests/data/centrelines/, made by scripts/centreline_test_files.py) read to the
//! values VTK's reader gives; bad files are refused with the file named and what is wrong.

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
    let design = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/curved_stent.yaml"),
    )
    .expect("design");
    let arc_line = design
        .lines()
        .find(|l| l.trim_start().starts_with("arc:"))
        .expect("an arc centreline");
    let from_file = design.replace(
        arc_line,
        &format!(
            "    file: {{path: {}, smoothing: 1.0e-4, reference: [1, 0, 0]}}",
            csv.display()
        ),
    );
    let exact = stentkit::io::design::parse_design(&design, Path::new("arc.yaml")).expect("arc");
    let fitted =
        stentkit::io::design::parse_design(&from_file, Path::new("file.yaml")).expect("file");
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
