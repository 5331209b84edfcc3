//! Issue 35 item 2, wires that pass through each other are said everywhere: `check` and `mesh` name the wires of
//! a design that already overlap (where, by how much), and a run whose wires are driven through each other
//! completes with a warning (summary.json, stderr) saying where and when. Issue 35 items 1 and 4: with
//! `contact: {wires: true}` the same rods press on each other, and the outputs say where and how hard.

use crate::common::read_json;
use crate::outputs::{path_str, run_in_process, scratch_folder, stentkit, test_outputs, text};
use crate::stabilisation::warning_said;
use std::path::{Path, PathBuf};

/// Two straight rods of diameter 0.2 crossing at right angles, the upper one `gap` above the lower one (between
/// their centrelines) and its ends moved down by `drop` over the run: written as `name.yaml` into `dir`.
fn crossing_rods(dir: &Path, name: &str, gap: f64, drop: f64) -> PathBuf {
    crossing_rods_with(dir, name, gap, drop, "")
}

/// [`crossing_rods`] with `extra` lines appended to the design.
fn crossing_rods_with(dir: &Path, name: &str, gap: f64, drop: f64, extra: &str) -> PathBuf {
    let text = format!(
        "version: 1
name: {name}
units: mm-N-MPa
material: {{E_inf: 2000, nu: 0.3}}
section: {{diameter: 0.2}}
mesh: {{p: 4, n: 10}}
patches:
  - name: low
    line: {{from: [-1, 0, 0], to: [1, 0, 0]}}
  - name: high
    line: {{from: [0, -1, {gap}], to: [0, 1, {gap}]}}
nodes:
  - {{name: a, ends: [low.start]}}
  - {{name: b, ends: [low.end]}}
  - {{name: c, ends: [high.start]}}
  - {{name: d, ends: [high.end]}}
conditions:
  - {{node: a, displacement: [0, 0, 0], rotation: [0, 0, 0]}}
  - {{node: b, displacement: [0, 0, 0], rotation: [0, 0, 0]}}
  - {{node: c, displacement: [0, 0, [[0, 0], [1, -{drop}]]], rotation: [0, 0, 0]}}
  - {{node: d, displacement: [0, 0, [[0, 0], [1, -{drop}]]], rotation: [0, 0, 0]}}
time: {{end: 1.0, step: 0.125}}
{extra}"
    );
    std::fs::create_dir_all(dir).expect("folder");
    let path = dir.join(format!("{name}.yaml"));
    std::fs::write(&path, text).expect("design written");
    path
}

/// Source: the geometry. Rods of radius 0.1 whose centrelines cross 0.15 apart overlap by 0.2 − 0.15 = 0.05 at
/// the crossing, the middle of both (u = 0.5 of each line's parameter on [0, 1]); 0.25 apart they clear each
/// other. `check` and `mesh` say so in their `wires` line.
#[test]
fn check_and_mesh_name_wires_that_already_overlap() {
    let dir = scratch_folder("wires", "check");
    let overlapping = crossing_rods(&dir, "overlapping", 0.15, 0.0);
    let out = stentkit(&["check", path_str(&overlapping)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let said = text(&out.stdout);
    assert!(
        said.contains("wires               1 pair of wires overlap; the deepest by 5.0000e-2 mm\n  - patch `low` at u = 0.5000 and patch `high` at u = 0.5000 overlap by 5.0000e-2 mm at (0.0000, 0.0000, 0.0000)"),
        "{said}"
    );
    let mesh = dir.join("overlapping.stl");
    let out = stentkit(&["mesh", path_str(&overlapping), "-o", path_str(&mesh)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("1 pair of wires overlap; the deepest by 5.0000e-2 mm"),
        "{}",
        text(&out.stdout)
    );
    let clear = crossing_rods(&dir, "clear", 0.25, 0.0);
    let out = stentkit(&["check", path_str(&clear)]);
    assert!(
        text(&out.stdout).contains("wires               no two closer than their radii allow"),
        "{}",
        text(&out.stdout)
    );
}

/// Source: the rigid motion. The upper rod's ends moved down by 0.8 in eight steps translate it rigidly, so the
/// overlap at the crossing is `0.2 − |0.5 − 0.8 t|`: 0.1, 0.2 and 0.1 at t = 0.5, 0.625 and 0.75, above the
/// tolerance of 5 % of the diameter (0.01), nowhere else. The run completes (its numbers are the simulation's)
/// with a warning in summary.json and on stderr that names the steps, the deepest overlap and where. Moved down
/// by 0.2 the rods stay 0.1 apart: no warning.
#[test]
fn a_run_that_drives_wires_through_each_other_completes_with_a_warning() {
    let root = test_outputs("wires_crossing");
    let through = crossing_rods(&root, "through", 0.5, 0.8);
    let dir = root.join("through_run");
    let (code, stderr) = run_in_process(&through, &dir, &[]);
    assert_eq!(code, 0, "{stderr}");
    let summary = read_json(&dir.join("summary.json"));
    let said = warning_said(&summary, &stderr, "wires passed through each other");
    assert!(
        said.starts_with("wires passed through each other in 3 step(s) (first at t = 0.5), deepest at t = 0.625: patch `low` at u = 0.5000 and patch `high` at u = 0.5000 overlap by 2.0000e-1 mm"),
        "{said}"
    );
    let short = crossing_rods(&root, "short", 0.5, 0.2);
    let dir = root.join("short_run");
    let (code, stderr) = run_in_process(&short, &dir, &[]);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("wires passed"), "{stderr}");
}

/// Source: the failure report's contract (issue 36 item 1: a failure states what the run met before it). The
/// rods driven through each other from t = 0.5 (as above), then one end twisted by 10 rad about y in one step that
/// may not be cut (`min_step` = `step`): Newton fails at t = 1.125, and the failure report (stderr and
/// summary.json's `failure.before`) says the wires had passed through each other since t = 0.5.
#[test]
fn a_failed_run_says_its_wires_had_passed_through_each_other_before() {
    let root = test_outputs("wires_failed");
    let design = crossing_rods(&root, "then_twisted", 0.5, 0.8);
    let text = std::fs::read_to_string(&design).expect("design");
    let text = crate::common::edit(
        &text,
        "{node: c, displacement: [0, 0, [[0, 0], [1, -0.8]]], rotation: [0, 0, 0]}",
        "{node: c, displacement: [0, 0, [[0, 0], [1, -0.8]]], rotation: [0, [[1, 0], [1.125, 10]], 0]}",
    );
    let text = crate::common::edit(
        &text,
        "time: {end: 1.0, step: 0.125}",
        "time: {end: 1.125, step: 0.125, min_step: 0.125}",
    );
    std::fs::write(&design, text).expect("design written");
    let dir = root.join("then_twisted_run");
    let (code, stderr) = run_in_process(&design, &dir, &[]);
    assert_ne!(code, 0, "the twist fails: {stderr}");
    let said = "the wires had passed through each other since t = 0.5 s";
    assert!(
        stderr.contains(&format!("before it failed: {said}")),
        "{stderr}"
    );
    let summary = read_json(&dir.join("summary.json"));
    let before = summary["failure"]["before"][0].as_str().expect("a line");
    assert!(before.starts_with(said), "{before}");
}

/// Source: the geometry and the outputs' definitions. The same crossing rods 0.5 apart with the wires' contact
/// on, the upper one's ends moved down by 0.35: the rods touch from a drop of 0.3 (`0.5 − 0.2`), so at the end
/// they press on each other (both bent, the penetration within the contact's tolerance, 1 % of the diameter by
/// default): no warning; `history.csv`'s `wire_contacts` and `wire_contact_force` are zero while they are apart
/// (t ≤ 0.75, a drop of 0.2625) and positive at the end, its `wire_penetration` at most the tolerance; the last
/// field file's `wire_contact_pressure` is positive at the crossing; the recording draws the pairs; summary.json's
/// solver clocks count the contact's own work apart (`term_wire_contact_s`), each part non-negative (the coupled
/// loads are taken out of the assemblies' time, not counted twice) and all of them within the stepping's time.
#[test]
fn wires_with_contact_press_on_each_other_and_the_outputs_say_so() {
    let root = test_outputs("wires_contact");
    let design = crossing_rods_with(&root, "pressed", 0.5, 0.35, "contact: {wires: true}\n");
    let dir = root.join("pressed_run");
    let (code, stderr) = run_in_process(&design, &dir, &[]);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("warning"), "{stderr}");
    let history = std::fs::read_to_string(dir.join("history.csv")).expect("history");
    let mut lines = history.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let (time, pairs, force, depth) = (
        column("time"),
        column("wire_contacts"),
        column("wire_contact_force"),
        column("wire_penetration"),
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    for row in &rows {
        if row[time] <= 0.75 {
            assert_eq!((row[pairs], row[force]), (0.0, 0.0), "{row:?}");
        }
    }
    let last = rows.last().expect("rows");
    assert!(last[pairs] > 0.0 && last[force] > 0.0, "{last:?}");
    assert!(last[depth] <= 0.01 * 0.2, "{last:?}");
    let pvd = std::fs::read_to_string(dir.join("run.pvd")).expect("run.pvd");
    let last_vtp = pvd
        .lines()
        .rev()
        .find_map(|l| l.split("file=\"").nth(1)?.split('"').next())
        .expect("a field file");
    let vtp = std::fs::read_to_string(dir.join(last_vtp)).expect("field file");
    assert!(
        vtp.contains("Name=\"wire_contact_pressure\""),
        "no wire_contact_pressure array"
    );
    let recording = crate::outputs::read_recording(&dir.join("run.mcap"));
    let (_, update) = recording.messages["/centrelines"]
        .last()
        .expect("a message");
    let lists = update["entities"][0]["lines"]
        .as_array()
        .expect("lines")
        .iter()
        .filter(|l| l["type"] == 2)
        .count();
    assert_eq!(lists, 1, "the pairs' LINE_LIST at the end");
    let summary = read_json(&dir.join("summary.json"));
    let clocks = summary["timing"]["solver"]
        .as_object()
        .expect("timing.solver");
    let seconds = |name: &str| clocks[name].as_f64().expect(name);
    assert!(
        seconds("term_wire_contact_s") > 0.0 && seconds("term_wire_contact_count") > 0.0,
        "{clocks:?}"
    );
    let parts: Vec<f64> = (clocks.iter())
        .filter(|(k, _)| k.ends_with("_s"))
        .map(|(_, v)| v.as_f64().expect("seconds"))
        .collect();
    assert!(parts.iter().all(|&s| s >= 0.0), "{clocks:?}");
    let stepping = summary["timing"]["run_s"].as_f64().expect("run_s");
    assert!(
        parts.iter().sum::<f64>() <= stepping,
        "{clocks:?} within {stepping}"
    );
}
