//! Fields along the rods (issue 17): the peak surface strain in `history.csv` and `summary.json` against a
//! closed form, the strain limit's warning, and the ParaView files (`snapshots/*.vtp`, `run.pvd`) a run writes
//! or, when the design says so, does not write. CI reads the field files with VTK's own reader
//! (`scripts/check_outputs.py`).

use crate::outputs::{completed_in_process, run_in_process, test_outputs};
use std::path::Path;

fn design(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("designs")
        .join(name)
}

/// The columns `names` of every row of a run's `history.csv`.
fn columns(dir: &Path, names: &[&str]) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(dir.join("history.csv")).expect("history.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let index: Vec<usize> = names
        .iter()
        .map(|n| header.iter().position(|h| h == n).expect(n))
        .collect();
    lines
        .map(|l| {
            let fields: Vec<&str> = l.split(',').collect();
            index.iter().map(|&k| fields[k].to_string()).collect()
        })
        .collect()
}

/// Source: the roll-up (an elastic rod of length L = 10 clamped at one end, end moment M(t) = 2π EI t / L)
/// bends to the uniform curvature κ = M/EI = 2π t / L with no axial force, so Γ = Γ0 and every section's
/// fibres stretch by `λ = 1 + κ y` exactly (module docs of `solver::simulation::fields`): the peak surface
/// strain is `r κ`, with r half the drawing diameter √(4A/π) of the section (A = 1). Tolerance 1e-7: the
/// collocation's own error on this mesh (p = 6, n = 30), which grows with the rotation — 1e-12 at a tenth of
/// the circle, 2.7e-8 at the full circle, where the tip also misses the clamp by 5.8e-6 of the length 10.
#[test]
fn the_rolled_up_rod_strains_its_surface_by_r_kappa() {
    let dir = test_outputs("fields_rollup");
    let (code, stderr) =
        run_in_process(&design("rollup.yaml"), &dir, &["material.strain_limit=0.3"]);
    assert_eq!(code, 0, "{stderr}");
    let r = 0.5 * (4.0 / std::f64::consts::PI).sqrt();
    let rows = columns(
        &dir,
        &[
            "time",
            "surface_strain_peak",
            "surface_strain_patch",
            "surface_strain_peak@material",
        ],
    );
    assert_eq!(rows.len(), 21);
    for row in &rows[1..] {
        let t: f64 = row[0].parse().expect("time");
        let peak: f64 = row[1].parse().expect("peak");
        let expected = r * std::f64::consts::TAU * t / 10.0;
        assert!(
            (peak - expected).abs() <= 1e-7,
            "t = {t}: {peak} vs {expected}"
        );
        assert_eq!(row[2], "beam");
        assert_eq!(row[3], row[1], "one material: its peak is the device's");
    }
    // The limit (30 %) is crossed where r κ(t) = 0.3 (t = 0.846) and said once, at the first step after it
    // (steps of 0.05), on stderr and in the summary.
    let crossing = 0.3 / (r * std::f64::consts::TAU / 10.0);
    assert_eq!(stderr.matches("strain_limit").count(), 1, "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).expect("summary"))
            .expect("json");
    let warning = summary["strain_limit_warnings"][0]
        .as_str()
        .expect("a warning");
    let said: f64 = warning
        .split_whitespace()
        .nth(3)
        .and_then(|t| t.parse().ok())
        .expect("the time in the warning");
    assert!(
        said >= crossing && said < crossing + 0.05 + 1e-9,
        "{warning} (crossing {crossing})"
    );
    let peak = &summary["peak_surface_strain"];
    assert_eq!(peak["time"], 1.0);
    assert_eq!(peak["patch"], "beam");
    assert!(
        (peak["value"].as_f64().expect("value") - r * std::f64::consts::TAU / 10.0).abs() <= 1e-7
    );
    // The configuration figures: the chosen times (up to six of the 21 snapshots, the last at t = 1), the
    // initial shape in grey, each listed among the charts.
    let figure = std::fs::read_to_string(dir.join("charts/configurations.svg")).expect("figure");
    assert!(
        figure.contains("t = 1.0000 s") && figure.contains("x1-x2"),
        "captions"
    );
    let charts: Vec<&str> = summary["files"]["charts"]
        .as_array()
        .expect("charts")
        .iter()
        .filter_map(|c| c.as_str())
        .collect();
    assert!(charts.contains(&"charts/configurations.svg"), "{charts:?}");
    assert!(
        charts.contains(&"charts/configuration_t1.0000.svg"),
        "{charts:?}"
    );
    // The shaded picture of the same states (the initial shape, then six), listed among the charts; `stentkit
    // render` draws the times asked for, each the nearest snapshot's.
    assert!(charts.contains(&"charts/configurations.png"), "{charts:?}");
    let picture = tiny_skia::Pixmap::load_png(dir.join("charts/configurations.png")).expect("PNG");
    assert!(drawn_pixels(&picture) > 0);
    let out = dir.join("render_test.png");
    let rendered = crate::outputs::stentkit(&[
        "render",
        dir.to_str().expect("path"),
        "-o",
        out.to_str().expect("path"),
        "--times",
        "0.52",
        "1",
        "--view",
        "x1-x2",
        "--width",
        "200",
    ]);
    assert!(rendered.status.success(), "{rendered:?}");
    let printed = crate::outputs::text(&rendered.stdout);
    assert!(printed.contains("t = 0, 0.5, 1 s"), "{printed}");
    let rendered = tiny_skia::Pixmap::load_png(&out).expect("PNG");
    // Three panels 200 pixels wide with gaps of 6: the rolled-up rod's panels (height/width 0.62) come nearest
    // 16:9 in a 2 + 1 grid.
    assert_eq!(
        (rendered.width(), rendered.height()),
        (2 * 206 + 6, 2 * (123 + 6) + 6),
        "{printed}"
    );
    assert!(drawn_pixels(&rendered) > 0);
    // Every snapshot has its field file, listed with its time in run.pvd.
    let collection = std::fs::read_to_string(dir.join("run.pvd")).expect("run.pvd");
    for snapshot in summary["snapshots"].as_array().expect("snapshots") {
        let file = snapshot["vtp"].as_str().expect("a field file");
        assert!(dir.join(file).is_file(), "{file}");
        assert!(collection.contains(&format!("file=\"{file}\"")), "{file}");
    }
}

/// Pixels that are not the white background.
fn drawn_pixels(pixmap: &tiny_skia::Pixmap) -> usize {
    pixmap
        .pixels()
        .iter()
        .filter(|p| (p.red(), p.green(), p.blue()) != (255, 255, 255))
        .count()
}

/// `output.vtk: false` writes no field file and no collection.
#[test]
fn a_design_can_turn_the_field_files_off() {
    let dir = test_outputs("fields_off");
    completed_in_process(&design("bend45.yaml"), &dir, &["output.vtk=false"]);
    assert!(!dir.join("run.pvd").exists());
    let vtp = std::fs::read_dir(dir.join("snapshots"))
        .expect("snapshots")
        .filter(|e| {
            e.as_ref()
                .is_ok_and(|e| e.path().extension().is_some_and(|x| x == "vtp"))
        })
        .count();
    assert_eq!(vtp, 0);
}

/// `stentkit render` refuses an unknown view, an output that is not PNG and a folder without a summary, with
/// exit status 2 (bad input) and a message naming what is wrong.
#[test]
fn render_refuses_bad_input() {
    let dir = test_outputs("render_refusals");
    std::fs::create_dir_all(&dir).expect("folder");
    let folder = dir.to_str().expect("path");
    let out_png = dir.join("out.png");
    let out_png = out_png.to_str().expect("path");
    for (args, message) in [
        (vec!["-o", out_png, "--view", "x1-x1"], "--view `x1-x1`"),
        (vec!["-o", "picture.jpg"], "must end in .png"),
        (vec!["-o", out_png], "not a run folder"),
    ] {
        let mut all = vec!["render", folder];
        all.extend(args);
        let out = crate::outputs::stentkit(&all);
        let stderr = crate::outputs::text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(message), "{stderr}");
    }
}
