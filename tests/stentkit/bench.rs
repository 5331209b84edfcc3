//! `stentkit bench radial` (issue 34): the radial-force bench as a run of a design, its table and what it
//! measures, checked against the contact report it is made of and against the symmetry it multiplies by.

use crate::mesh::TempDir;
use std::path::{Path, PathBuf};
use std::process::Command;
use stentkit::bench::{RadialBench, radial_design};
use stentkit::design::{DesignOverrides, SetOverride};
use stentkit::math::Real;

/// The paper's straight stent cut to two crowns, on a short bench: the crimper closes from 2 % outside it to a
/// diameter of 30 (of the device's 41.2) and opens again, recording `diameters` on each branch.
fn small_bench(extra: &[&str]) -> (PathBuf, Vec<String>) {
    let design = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/straight_stent.yaml");
    let mut sets: Vec<String> = [
        "stent.crowns=2",
        "bench.min_diameter=30",
        "bench.diameters=5",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    sets.extend(extra.iter().map(|s| s.to_string()));
    (design, sets)
}

/// The overrides of `sets`.
fn overrides(sets: &[String]) -> DesignOverrides {
    DesignOverrides {
        sets: sets
            .iter()
            .map(|s| s.parse::<SetOverride>().expect("an override"))
            .collect(),
        ..DesignOverrides::default()
    }
}

/// The radial force on the whole device at the end of the bench's closing branch, as the contact's line
/// pressures at the collocation points integrated here: the trapezoidal rule in the reference arc length along
/// each patch (the points' `arc_length`), times the copies of the model in the device.
fn closed_force_from_pressures(design: &stentkit::Design, bench: &RadialBench) -> Real {
    let mut sim = stentkit::Simulation::new(&design.model).expect("valid");
    while sim.time() < bench.closing * (1.0 - 1e-12) {
        sim.step().expect("the bench's closing converges");
    }
    let report = sim.contact().expect("contact");
    let pressure = &report.obstacles.last().expect("the crimper").pressure;
    let fields = sim.point_fields();
    assert_eq!(fields.len(), pressure.len());
    let mut total = 0.0;
    for (g, f) in fields.iter().enumerate() {
        let same = |k: usize| fields.get(k).filter(|o| o.patch == f.patch);
        let before = g
            .checked_sub(1)
            .and_then(same)
            .map_or(f.arc_length, |o| o.arc_length);
        let after = same(g + 1).map_or(f.arc_length, |o| o.arc_length);
        total += 0.5 * (after - before) * pressure[g];
    }
    bench.copies * total
}

/// Source: the bench's force is the contact of the crimper on the whole device — the line pressures the
/// contact law puts at the collocation points, integrated along the wires (trapezoidal rule in the reference
/// arc length, as the contact report's module docs state it) and multiplied by the four quarters of the
/// model — recomputed here from the pressures and the points' arc lengths of an in-process simulation of the
/// same bench design: equal to the table's to its 10 printed digits (1e-8). The table's branches: the
/// closing one from the crimper's start (2 % clear of the device's outer diameter 2 (20 + 0.3), so 41.412)
/// down to the asked 30 in 5 diameters, the opening one back up to the start; the smallest diameter is
/// printed as reached.
#[test]
fn the_radial_bench_records_both_branches_and_its_force_is_the_contact_on_the_whole_device() {
    let dir = TempDir::new("bench-radial");
    let out_dir = dir.join("run");
    let (design, sets) = small_bench(&[]);
    let mut args: Vec<String> = vec![
        "bench".into(),
        "radial".into(),
        design.to_string_lossy().into_owned(),
        "-o".into(),
        out_dir.to_string_lossy().into_owned(),
        "--quiet".into(),
    ];
    for s in &sets {
        args.extend(["--set".to_string(), s.clone()]);
    }
    let out = Command::new(env!("CARGO_BIN_EXE_stentkit"))
        .args(&args)
        .output()
        .expect("stentkit runs");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("smallest diameter reached: 30"), "{stdout}");
    let table = std::fs::read_to_string(out_dir.join("radial.csv")).expect("radial.csv");
    assert!(out_dir.join("charts/radial_force.svg").is_file());
    let rows: Vec<Vec<String>> = table
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    let branch = |name: &str| -> Vec<(Real, Real)> {
        rows.iter()
            .filter(|r| r[1] == name)
            .map(|r| {
                (
                    r[2].parse().expect("diameter"),
                    r[3].parse().expect("force"),
                )
            })
            .collect()
    };
    let (closing, opening) = (branch("loading"), branch("unloading"));
    assert_eq!(closing.len(), 5, "{table}");
    assert!(closing.windows(2).all(|w| w[1].0 < w[0].0), "{closing:?}");
    assert!(
        (closing[0].0 - 1.02 * 2.0 * 20.3).abs() < 1e-3,
        "{closing:?}"
    );
    let closed = closing.last().expect("a closed crimper");
    assert!(
        (closed.0 - 30.0).abs() < 1e-9 && closed.1 > 0.0,
        "{closed:?}"
    );
    assert!(opening.len() >= 5, "{table}");
    assert!(opening.windows(2).all(|w| w[1].0 > w[0].0), "{opening:?}");
    assert!((opening.last().expect("open").0 - closing[0].0).abs() < 1e-9);
    // The same folder again without --force is refused, and the earlier bench's table is left as it was.
    let again = Command::new(env!("CARGO_BIN_EXE_stentkit"))
        .args(&args)
        .args(["--set", "bench.min_diameter=35"])
        .output()
        .expect("stentkit runs");
    assert_eq!(again.status.code(), Some(2));
    assert_eq!(
        std::fs::read_to_string(out_dir.join("radial.csv")).expect("radial.csv"),
        table
    );
    let (model_design, bench) = radial_design(&design, &overrides(&sets)).expect("the bench");
    let expected = closed_force_from_pressures(&model_design, &bench);
    assert!(
        ((closed.1 - expected) / expected).abs() < 1e-8,
        "table {} against the pressures' {expected}",
        closed.1
    );
}

/// Source: symmetry. The straight stent is symmetric about its two planes through the axis, so the quarter
/// model on the bench, its force multiplied by 4, must give the full device's — simulated whole
/// (`stent.symmetry: none`), a model with four times the patches and nothing prescribed on the planes —
/// at the closed crimper. Tolerance 1e-3: the crimper prescribes where the wires are, up to the contact's
/// penetration tolerance (1 % of the wire, 6e-3), which each model meets with its own augmented-Lagrange
/// updates; against the crimper's travel since the wires first touched (~5.7), the force is known to about
/// 6e-3 / 5.7 ≈ 1e-3 of itself. Measured 3.9e-5.
#[test]
fn a_quarter_model_on_the_radial_bench_gives_the_full_devices_force() {
    let (design, sets) = small_bench(&[]);
    let (quarter, quarter_bench) = radial_design(&design, &overrides(&sets)).expect("the bench");
    let (_, sets) = small_bench(&["stent.symmetry=none"]);
    let (full, full_bench) = radial_design(&design, &overrides(&sets)).expect("the bench");
    assert_eq!((quarter_bench.copies, full_bench.copies), (4.0, 1.0));
    let (a, b) = (
        closed_force_from_pressures(&quarter, &quarter_bench),
        closed_force_from_pressures(&full, &full_bench),
    );
    println!(
        "quarter × 4: {a:.12e} N, full: {b:.12e} N, relative {:.3e}",
        (a - b) / b
    );
    assert!(((a - b) / b).abs() < 1e-3, "quarter × 4 {a}, full {b}");
}

/// A bench the device does not fit is refused before anything runs (exit status 2), naming the design file and
/// the field: a smallest diameter above the crimper's start (the device's outer diameter 40.6 and 2 %).
#[test]
fn a_smallest_diameter_above_the_device_is_refused_and_nothing_is_written() {
    let dir = TempDir::new("bench-refused");
    let out_dir = dir.join("run");
    let (design, _) = small_bench(&[]);
    let out = Command::new(env!("CARGO_BIN_EXE_stentkit"))
        .args(["bench", "radial"])
        .arg(&design)
        .arg("-o")
        .arg(&out_dir)
        .args(["--set", "bench.min_diameter=50"])
        .output()
        .expect("stentkit runs");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr
            .contains("straight_stent.yaml: bench.min_diameter: the crimper would close to 50 mm")
            && stderr.contains("41.4120"),
        "{stderr}"
    );
    assert!(!out_dir.exists());
}
