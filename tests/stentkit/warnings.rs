//! Issue 31, "a wrong result is never 'completed' without a word": a run that ends heated but far from its
//! permanent shape completes beside a warning (summary.json, stderr, `sweep collect`); `mesh --state temporary`
//! and `check` say nothing untrue of an error-controlled stent; a wire thicker than its stent's radius is
//! refused. (The stabilisation's warnings are in `stabilisation.rs`.)

use crate::common::{design_text, fixtures, replace_line};
use crate::outputs::{design, path_str, run_in_process, stentkit, test_outputs, text};
use crate::stabilisation::warning_said;
use std::path::{Path, PathBuf};
use stentkit::design::{DesignOverrides, load_design, load_design_with};
use stentkit::math::Real;

/// The straight stent (designs/straight_stent.yaml) with two crowns and error-controlled steps (tolerance
/// 1e-2), whose temperature schedule is replaced by `temperature` and whose run ends at `end`, written as
/// `name.yaml` into `dir`.
fn two_crown_stent(dir: &Path, name: &str, temperature: &str, end: Real) -> PathBuf {
    fixtures::straight_stent()
        .crowns(2)
        .set("temperature", temperature)
        .time(end, 0.01)
        .set("time.tolerance", "1.0e-2")
        .write(&dir.join(format!("{name}.yaml")))
}

/// The schedule of the stent heated above its Tg (70 °C) at the end but only for a moment: cooled to 45 °C
/// by the release at 1.75 s, then raised to 71 °C by 2.0 s and held for 0.05 s.
const BRIEFLY_HEATED: &str = "[[0, 90], [1, 90], [1.75, 45], [2.0, 71], [2.05, 71]]";

/// The summary.json of run folder `dir`.
fn summary(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).expect("summary.json");
    serde_json::from_str(&text).expect("JSON")
}

/// Issue 31 item 20: a run that ends with its device far from the permanent shape although it was heated above
/// every material's Tg completed with `warnings: []` (the stent on the aorta, stabilised, ended at a
/// recovery ratio of 1.8). The two-crown straight stent heated to 71 °C for 0.05 s keeps 0.80 of its
/// temporary shape (recovery ratio mean, measured), far above the threshold of 0.1; the same device heated to
/// 90 °C as the design does ends at 0.004 (measured, with the design's rotation field, the paper's; at n = 40 it
/// is 0.011, as with the objective field at n = 20 and 40, with either time tolerance 1e-2 or 1e-3), far below:
/// no warning there. The run still completes (exit status 0: the numbers are the simulation's), with the warning
/// in summary.json and on stderr.
#[test]
fn a_run_that_ends_heated_but_not_recovered_completes_with_a_warning() {
    let root = test_outputs("recovery_warning");
    let brief = two_crown_stent(&root, "brief", BRIEFLY_HEATED, 2.05);
    let dir = root.join("brief_run");
    let (code, stderr) = run_in_process(&brief, &dir, &[]);
    assert_eq!(code, 0, "{stderr}");
    let s = summary(&dir);
    assert_eq!(s["status"], "completed");
    let ratio = s["final_state"]["recovery_ratio_mean"]
        .as_f64()
        .expect("a ratio");
    assert!(ratio > 0.5, "{ratio}");
    let said = warning_said(&s, &stderr, "recovery ratio");
    assert!(said.contains(&format!("{ratio:.3}")), "{said}");

    let full = two_crown_stent(
        &root,
        "full",
        "[[0, 90], [1, 90], [1.75, 45], [3.16876, 90], [3.25, 90]]",
        3.25,
    );
    let dir = root.join("full_run");
    let (code, stderr) = run_in_process(&full, &dir, &[]);
    assert_eq!(code, 0, "{stderr}");
    let s = summary(&dir);
    assert!(
        s["final_state"]["recovery_ratio_mean"]
            .as_f64()
            .expect("ratio")
            < 0.01,
        "{}",
        s["final_state"]
    );
    assert_eq!(s["warnings"], serde_json::json!([]), "{}", s["warnings"]);
    assert!(!stderr.contains("warning"), "{stderr}");
}

/// Issue 31 item 20: `sweep collect` shows the warnings of every variant. The briefly heated two-crown stent
/// swept over Tg ∈ {65, 75} °C: at Tg = 65 °C it ends 6 K above Tg and recovered only to 0.56 (measured), which
/// is warned about; at Tg = 75 °C it ends below Tg, where nothing says it should have recovered (no warning).
/// sweep.csv's `warnings` column counts them: 1 and 0.
#[test]
fn sweep_collect_counts_the_warnings_of_each_variant() {
    let root = test_outputs("sweep_warnings");
    let file = two_crown_stent(&root, "brief", BRIEFLY_HEATED, 2.05);
    let dir = root.join("sweep");
    let out = stentkit(&[
        "sweep",
        path_str(&file),
        "--set",
        "material.wlf.Tg=65,75",
        "-o",
        path_str(&dir),
        "--jobs",
        "2",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).expect("sweep.csv");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no `{name}` in {header:?}"))
    };
    let (tg, warnings) = (column("material.wlf.Tg"), column("warnings"));
    let counts: Vec<(String, String)> = lines
        .map(|l| {
            let row: Vec<&str> = l.split(',').collect();
            (row[tg].to_string(), row[warnings].to_string())
        })
        .collect();
    assert_eq!(
        counts,
        [("65".into(), "1".into()), ("75".into(), "0".into())],
        "{csv}"
    );
}

/// Issue 31 item 21: `mesh --state temporary` on designs/aorta_stent.yaml warned "no component of any node of
/// patches … is prescribed … `run` will refuse the design", which is false: the temporary shape is generated
/// without its programme (it is where the programme takes the nodes), and `run` solves the permanent design,
/// whose programme holds every joint. The temporary shape's build says nothing of free bodies; the permanent
/// design that `run` solves has none (its simulation sets up).
#[test]
fn the_temporary_shape_does_not_say_that_run_refuses_the_design() {
    let file = design("aorta_stent.yaml");
    let temporary = load_design_with(
        &file,
        &DesignOverrides {
            temporary_shape: true,
            ..DesignOverrides::default()
        },
    )
    .expect("the temporary shape builds");
    assert!(
        !temporary
            .warnings
            .iter()
            .any(|w| w.contains("refuse") || w.contains("rigid body")),
        "{:?}",
        temporary.warnings
    );
    let permanent = load_design(&file).expect("valid");
    stentkit::solver::Simulation::new(&permanent.model).expect("run accepts the design");
}

/// Issue 31 item 21: `check` printed "4000 time steps" for designs/aorta_stent.yaml, whose steps are
/// error-controlled (`time.tolerance: 1e-2`; its run takes 230 steps, measured). It now says that the steps
/// are error-controlled, starting from h, and the true upper bound (every step at `min_step` = h/1024, each
/// landing span one more for round-off), and the disk line says its basis and that bound. A fixed-step design
/// keeps its exact count.
#[test]
fn check_of_an_error_controlled_design_says_what_error_control_does() {
    let out = stentkit(&["check", path_str(&design("aorta_stent.yaml"))]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let line = |label: &str| {
        stdout
            .lines()
            .find(|l| l.starts_with(label))
            .unwrap_or_else(|| panic!("no `{label}` in\n{stdout}"))
            .to_string()
    };
    let steps = line("time steps");
    assert!(
        steps.contains("error-controlled") && !steps.contains("time steps          4000"),
        "{steps}"
    );
    let model = load_design(&design("aorta_stent.yaml"))
        .expect("valid")
        .model;
    let bound = model.planned_steps_at(model.time().min_step).total()
        + model.schedule_breakpoints().len()
        + 1;
    assert!(steps.contains(&format!("at most {bound}")), "{steps}");
    let disk = line("disk");
    assert!(
        disk.contains("4000 steps of h") && disk.contains("at most"),
        "{disk}"
    );

    let out = stentkit(&["check", path_str(&design("straight_stent.yaml"))]);
    assert!(text(&out.stdout).contains("time steps          1301 (1299 of h = 0.0025 s"));
}

/// Issue 31 item 22: a lumen radius of 1e-9 (a centreline file whose radius column is in the wrong unit, or
/// broken) sized a stent of radius 1.1e-9 mm with a 0.4 mm wire, and `check` said "warnings none". A wire
/// thicker than its stent's radius is refused, naming `stent.oversize` (the field that sized it from the lumen)
/// and both numbers. The centreline is generated here: a straight 30 mm line of 31 points with that radius, two
/// crowns on 20 mm of it.
#[test]
fn a_stent_sized_from_a_tiny_lumen_is_refused() {
    let dir = test_outputs("tiny_lumen");
    std::fs::create_dir_all(&dir).expect("folder");
    let mut csv = String::from("x,y,z,radius\n");
    for k in 0..=30 {
        csv.push_str(&format!("{k},0,0,1e-9\n"));
    }
    std::fs::write(dir.join("tiny.csv"), csv).expect("centreline written");
    // Edited as text, not through `fixtures`: the design is refused, and its file, which names the centreline
    // file beside it, is what `check` reads.
    let text = replace_line(
        &replace_line(&design_text("aorta_stent.yaml"), "path:", "path: tiny.csv"),
        "polyline:",
        "polyline: 0",
    );
    let file = dir.join("tiny_lumen.yaml");
    let text = replace_line(
        &replace_line(
            &replace_line(&text, "start:", "start: 2"),
            "length:",
            "length: 20",
        ),
        "crowns:",
        "crowns: 2",
    );
    std::fs::write(&file, text).expect("design written");
    let out = stentkit(&["check", path_str(&file)]);
    let stderr = crate::outputs::text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("stent.oversize") && stderr.contains("thicker than the stent's radius"),
        "{stderr}"
    );
    assert!(
        stderr.contains("0.4") && stderr.contains("1.1e-9"),
        "{stderr}"
    );
}
