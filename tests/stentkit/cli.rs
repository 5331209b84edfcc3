//! The `stentkit` binary end to end: `check` and `mesh` on every design, located errors for a broken design,
//! refused output formats, and `--help` texts with examples.

use crate::mesh::{TempDir, designs_and_good_small};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use stentkit::design::load_design;

/// Runs `stentkit` with `args`.
fn stentkit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stentkit"))
        .args(args)
        .output()
        .expect("stentkit runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// No Rust panic reached the user.
fn assert_no_panic(out: &Output) {
    let stderr = text(&out.stderr);
    assert!(
        !stderr.contains("panicked") && !stderr.contains("RUST_BACKTRACE"),
        "panic: {stderr}"
    );
}

/// The value after a `label` at the start of a line of `check`'s output (its first word).
fn value_after<'a>(stdout: &'a str, label: &str) -> &'a str {
    stdout
        .lines()
        .find_map(|l| l.strip_prefix(label))
        .and_then(|rest| rest.split_whitespace().next())
        .unwrap_or_else(|| panic!("no `{label}` line in\n{stdout}"))
}

fn path_str(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// A one-patch design with a fitted helix, so that `check` has a fit error to report.
const HELIX: &str = "\
version: 1
name: coil
units: mm-N-MPa
material:
  E_inf: 2000
  nu: 0.3
section:
  diameter: 0.2
mesh: {p: 4, n: 16}
patches:
  - name: coil
    helix: {radius: 2, pitch: 1, turns: 1}
nodes:
  - {name: root, ends: [coil.start]}
conditions:
  - {node: root, clamp: true}
time: {end: 1.0, step: 0.25}
";

#[test]
#[ignore = "full size (every design of designs/, the paper stents included): run by .ci/run with cargo test --release -- --ignored"]
fn check_describes_every_design() {
    // Every count `check` prints must equal the model's own; the fit error and warnings lines are present.
    let dir = TempDir::new("cli-check");
    let helix = dir.join("coil.yaml");
    std::fs::write(&helix, HELIX).expect("design written");
    let mut files: Vec<PathBuf> = designs_and_good_small();
    files.push(helix);
    for file in files {
        let out = stentkit(&["check", path_str(&file)]);
        assert_no_panic(&out);
        let stdout = text(&out.stdout);
        assert!(
            out.status.success(),
            "{}: {}",
            file.display(),
            text(&out.stderr)
        );
        let model = load_design(&file).expect("valid design").model;
        let count = |label: &str| -> usize {
            value_after(&stdout, label)
                .parse()
                .unwrap_or_else(|e| panic!("{label}: {e}\n{stdout}"))
        };
        assert_eq!(count("patches"), model.patches.len());
        assert_eq!(count("nodes"), model.nodes.len());
        assert_eq!(count("collocation points"), model.num_collocation_points());
        assert_eq!(count("unknowns"), model.num_unknowns());
        match model.solver().path {
            // Error-controlled steps are not known before the run: `check` says so instead of a count.
            stentkit::model::PathControl::Time if model.time().tolerance.is_some() => {
                assert_eq!(value_after(&stdout, "time steps"), "error-controlled");
            }
            stentkit::model::PathControl::Time => {
                assert_eq!(count("time steps"), model.planned_steps().total());
            }
            stentkit::model::PathControl::ArcLength(a) => {
                let line = stdout
                    .lines()
                    .find_map(|l| l.strip_prefix("arc-length path"))
                    .map(str::trim)
                    .unwrap_or_else(|| panic!("no `arc-length path` line in\n{stdout}"));
                assert!(
                    line.starts_with(&format!("at most {} increments", a.max_increments)),
                    "{line}"
                );
            }
        }
        let fit = value_after(&stdout, "geometry fit error");
        match model
            .patches
            .iter()
            .filter_map(|p| p.fit_error)
            .reduce(f64::max)
        {
            None => assert_eq!(fit, "0", "exact geometry"),
            Some(e) => {
                let printed: f64 = fit.parse().expect("fit error number");
                assert!(
                    e > 0.0 && (printed / e - 1.0).abs() < 1e-3,
                    "{printed} vs {e}"
                );
            }
        }
        assert_eq!(value_after(&stdout, "warnings"), "none", "{stdout}");
    }
}

#[test]
#[ignore = "full size (every design of designs/, the paper stents included): run by .ci/run with cargo test --release -- --ignored"]
fn mesh_writes_stl_and_obj_for_every_design() {
    let dir = TempDir::new("cli-mesh");
    for file in designs_and_good_small() {
        let stem = file.file_stem().and_then(|s| s.to_str()).expect("name");
        for extension in ["stl", "obj"] {
            let output = dir.join(&format!("{stem}.{extension}"));
            let out = stentkit(&["mesh", path_str(&file), "-o", path_str(&output)]);
            assert_no_panic(&out);
            assert!(
                out.status.success(),
                "{}: {}",
                file.display(),
                text(&out.stderr)
            );
            assert!(text(&out.stdout).contains("wrote"));
            let bytes = std::fs::read(&output).expect("mesh file written");
            match extension {
                // Binary STL: 80-byte header, u32 count, 50 bytes per triangle.
                "stl" => {
                    assert!(bytes.len() > 84);
                    let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]);
                    assert!(count > 0);
                    assert_eq!(bytes.len(), 84 + 50 * count as usize);
                    assert!(bytes.starts_with(b"stentkit"));
                }
                _ => {
                    let obj = text(&bytes);
                    assert!(obj.lines().any(|l| l.starts_with("v ")));
                    assert!(obj.lines().any(|l| l.starts_with("f ")));
                }
            }
        }
    }
}

#[test]
fn broken_design_fails_with_its_location_and_no_panic() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/bad_designs/04_negative_diameter.yaml");
    let dir = TempDir::new("cli-broken");
    let output = dir.join("never.stl");
    for args in [
        vec!["check", path_str(&file)],
        vec!["mesh", path_str(&file), "-o", path_str(&output)],
    ] {
        let out = stentkit(&args);
        assert_no_panic(&out);
        assert!(!out.status.success(), "{args:?} succeeded");
        let stderr = text(&out.stderr);
        // file:line:column of the offending value (line 11, column 13: `diameter: -0.01`).
        assert!(
            stderr.contains(&format!("{}:11:13", file.display())),
            "{stderr}"
        );
        assert!(stderr.contains("diameter"), "{stderr}");
        assert!(out.stdout.is_empty(), "{}", text(&out.stdout));
    }
    assert!(!output.exists());
    // A missing file is an error too, not a panic.
    let out = stentkit(&["check", path_str(&dir.join("missing.yaml"))]);
    assert_no_panic(&out);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("missing.yaml"));
}

#[test]
fn mesh_refuses_other_extensions() {
    let design = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/bend45.yaml");
    let dir = TempDir::new("cli-ext");
    for name in ["shape.txt", "shape"] {
        let output = dir.join(name);
        let out = stentkit(&["mesh", path_str(&design), "-o", path_str(&output)]);
        assert_no_panic(&out);
        assert!(!out.status.success(), "{name} accepted");
        assert!(
            text(&out.stderr).contains(".stl, .obj, .3mf or .csv"),
            "{}",
            text(&out.stderr)
        );
        assert!(!output.exists());
    }
}

#[test]
fn every_subcommand_help_has_an_example() {
    for command in [
        &["check"][..],
        &["mesh"],
        &["run"],
        &["schema"],
        &["study"],
        &["study", "convergence"],
        &["study", "time"],
        &["study", "stability"],
    ] {
        let mut args = command.to_vec();
        args.push("--help");
        let out = stentkit(&args);
        assert!(out.status.success());
        let help = text(&out.stdout);
        assert!(help.contains("Example"), "{command:?} --help:\n{help}");
        assert!(
            help.contains(&format!("stentkit {}", command.join(" "))),
            "{help}"
        );
    }
}

/// `--set` on `run` (issue 15): summary.json lists the overrides and holds the resolved design, which reads
/// back as the design with the overridden values; `check` prints the overridden value; a bad override exits
/// with status 2 naming the argument.
#[test]
fn run_with_overrides_records_the_resolved_design() {
    let dir = TempDir::new("set_run");
    let out = dir.join("run");
    let design = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/good_stent_small.yaml");
    let run = stentkit(&[
        "run",
        path_str(&design),
        "-q",
        "-o",
        path_str(&out),
        "--set",
        "time.end=0.1",
        "--set",
        "material.wlf.Tg=65",
    ]);
    assert_no_panic(&run);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("summary.json")).expect("summary.json"),
    )
    .expect("JSON");
    assert_eq!(
        summary["overrides"],
        serde_json::json!(["time.end=0.1", "material.wlf.Tg=65"])
    );
    let resolved = summary["resolved_design"]
        .as_str()
        .expect("resolved_design");
    let model = stentkit::design::parse_design(resolved, Path::new("resolved.yaml"))
        .expect("the resolved design reads")
        .model;
    assert_eq!(model.time().end, 0.1);
    assert_eq!(summary["final_time"], serde_json::json!(0.1));
    let check = stentkit(&["check", path_str(&design), "--set", "material.wlf.Tg=61.5"]);
    assert!(
        text(&check.stdout).contains("Tg = 61.5 °C"),
        "{}",
        text(&check.stdout)
    );
    let bad = stentkit(&["check", path_str(&design), "--set", "stent.crowns=-2"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(
        text(&bad.stderr).contains("--set stent.crowns=-2: stent.crowns: "),
        "{}",
        text(&bad.stderr)
    );
}
