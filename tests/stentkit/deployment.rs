//! Deployment measures of a run (issue 34 item 3): the programmed device's diameter and length in
//! `history.csv`, its recoil, foreshortening and crowns against the lumen in `summary.json`, checked where a
//! prescribed programme fixes them exactly.

use crate::mesh::TempDir;
use std::path::Path;
use std::process::Command;
use stentkit::math::Real;

/// Source: the prescription and the design's geometry. The paper's straight stent cut to two crowns (R = 20,
/// amplitude 5, crowns 15 apart, wire 0.6) is contracted radially by Δr = 15 over [0, 1] s and released at
/// 1.75 s into a rigid tube of radius 18 put in place then. Its driven nodes (every crest and trough) start at
/// radius 20 and sit at radius 5 while prescribed, so the device's mean outer diameter is `2 R + d` = 40.6 at
/// the start and `2 (R − Δr) + d` = 10.6 at the release; their axial positions do not move under a radial
/// prescription, so its length is the crest-to-crest extent `15 + 2 · 5` = 25 at both. Tolerance 1e-8:
/// round-off in the node positions, and the 10 digits `history.csv` prints. The summary's recoil and
/// foreshortening are those columns' values at the release, at the end of the release ramp (1.7525 s) and at
/// the end (same digits), and each crown stands in the tube's diameter 36, its mean outer diameter not above it
/// by more than twice the contact's penetration tolerance (1 % of the wire: the crests press on the wall).
#[test]
fn a_released_stent_reports_its_recoil_foreshortening_and_crowns_against_its_vessel() {
    let dir = TempDir::new("deployment");
    let run = dir.join("run");
    let design = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/straight_stent.yaml");
    let out = Command::new(env!("CARGO_BIN_EXE_stentkit"))
        .arg("run")
        .arg(&design)
        .arg("-o")
        .arg(&run)
        .args(["--quiet", "--set", "stent.crowns=2", "--set"])
        .arg("obstacles=[{name: vessel, cylinder: {point: [0, 0, 0], axis: [1, 0, 0], radius: 18}, from: 1.75}]")
        .output()
        .expect("stentkit runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let history = std::fs::read_to_string(run.join("history.csv")).expect("history.csv");
    let (diameter, length) = (
        column(&history, "device_diameter"),
        column(&history, "device_length"),
    );
    let at = |series: &[(Real, Real)], t: Real| {
        series
            .iter()
            .find(|p| (p.0 - t).abs() < 1e-9)
            .map(|p| p.1)
            .unwrap_or_else(|| panic!("no row at {t}"))
    };
    let close = |a: Real, b: Real| (a - b).abs() <= 1e-8 * b.abs();
    assert!(close(at(&diameter, 0.0), 40.6), "{}", at(&diameter, 0.0));
    assert!(close(at(&diameter, 1.75), 10.6), "{}", at(&diameter, 1.75));
    assert!(close(at(&length, 0.0), 25.0) && close(at(&length, 1.75), 25.0));
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(run.join("summary.json")).expect("summary.json"),
    )
    .expect("JSON");
    let d = &summary["deployment"];
    let number = |v: &serde_json::Value| v.as_f64().expect("a number");
    let recoil = &d["recoil"];
    assert!(close(number(&recoil["diameter_closed"]), 10.6), "{recoil}");
    assert!(close(number(&recoil["closed_at"]), 1.75) && close(number(&recoil["open_at"]), 1.7525));
    let open = at(&diameter, 1.7525);
    assert!(close(number(&recoil["diameter_open"]), open), "{recoil}");
    assert!(
        close(number(&recoil["recoil"]), (open - 10.6) / 10.6),
        "{recoil}"
    );
    let fore = &d["foreshortening"];
    let end = length.last().expect("rows").1;
    assert!(close(number(&fore["crimped_length"]), 25.0), "{fore}");
    assert!(close(number(&fore["final_length"]), end), "{fore}");
    assert!(
        close(number(&fore["foreshortening"]), (25.0 - end) / 25.0),
        "{fore}"
    );
    let crowns = d["crowns"].as_array().expect("crowns");
    assert_eq!(crowns.len(), 2, "{crowns:?}");
    for (k, c) in crowns.iter().enumerate() {
        assert_eq!(c["crown"].as_u64(), Some(k as u64 + 1));
        assert!(close(number(&c["lumen_diameter"]), 36.0), "{c}");
        let diameter = number(&c["diameter"]);
        assert!(diameter > 30.0 && diameter <= 36.0 + 2.0 * 0.006, "{c}");
    }
}

/// The `(time, value)` pairs of a `history.csv` column.
fn column(history: &str, name: &str) -> Vec<(Real, Real)> {
    let mut lines = history.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let k = header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].parse().expect("time"), f[k].parse().expect("value"))
        })
        .collect()
}
