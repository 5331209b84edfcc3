//! The run's outputs of contact, through the run itself ([`crate::run::run`]): the quarter ring of the contact
//! term's tests, built in code, crimped by a rigid cylinder; the design's other settings (outputs) are those of
//! `tests/data/good_small.yaml`, whose model is replaced (the design language has no contact yet). And the same
//! design without contact writes none of them.

use crate::model::Model;
use crate::run::{Folder, Interrupt, Lines, RunSettings, run};
use crate::solver::Simulation;
use crate::solver::simulation::NoObserver;
use crate::solver::terms::contact::ContactReport;
use crate::solver::terms::contact::report::tests::{CRIMPED, SETTINGS, crimped_ring};
use base64::Engine;
use std::path::{Path, PathBuf};

/// A fresh folder for a run of this test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("stentkit-contact-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Runs `model` with the outputs of `tests/data/good_small.yaml` into `dir`.
fn run_into(dir: &Path, model: Model) -> serde_json::Value {
    let mut design = crate::design::load_design(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/good_small.yaml"),
    )
    .expect("design");
    design.steps = model.planned_steps();
    design.model = model;
    design.output.snapshots.vtk = true;
    run(
        &design,
        Folder::New {
            dir: dir.to_path_buf(),
            force: false,
        },
        &RunSettings::new("contact outputs test"),
        &Interrupt::new(),
        &mut Lines::default(),
    )
    .expect("the run completes");
    let text = std::fs::read_to_string(dir.join("summary.json")).expect("summary");
    serde_json::from_str(&text).expect("JSON")
}

/// The float values of the field file's point array `name` (VTK inline binary: a UInt64 byte count, then the
/// little-endian values, base64 together).
fn vtk_array(text: &str, name: &str) -> Vec<f64> {
    let at = text
        .find(&format!("Name=\"{name}\""))
        .unwrap_or_else(|| panic!("array {name}"));
    let block = text[at..].lines().nth(1).expect("its data").trim();
    let raw = base64::engine::general_purpose::STANDARD
        .decode(block)
        .expect("base64");
    raw[8..]
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
        .collect()
}

/// Source: the contact term's report of the same model run in process (a [`Simulation`] to the same end, the
/// same steps: the same numbers), which the report's own test checks against the ring's closed form. Each
/// output must carry it: history.csv's last row (to its printed digits, 1e-9 relative), summary.json's peaks
/// (the largest of the history's column, when), the last field file's pressure and gap (to the bit: written
/// as binary; the penetration is written to 7 digits), run.mcap's cylinder at the crimper's final diameter (coordinates at the recording's fixed
/// decimals) with every centreline sample touching it, and both contact charts. The crimper first touches the
/// wires at t = 0.2/0.7: the first row has no point in contact.
#[test]
fn a_crimped_ring_writes_its_contact_into_every_output() {
    let model = crimped_ring();
    let mut sim = Simulation::new(&model).expect("discretised");
    sim.run(&mut [&mut NoObserver]).expect("converges");
    let report: ContactReport = sim.contact().expect("contact");
    let o = &report.obstacles[0];
    let radial = o.radial_force.expect("cylinder");
    let n = sim.discretisation().points.len();

    let dir = scratch("ring");
    let summary = run_into(&dir, crimped_ring());

    let history = std::fs::read_to_string(dir.join("history.csv")).expect("history");
    let mut lines = history.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("column {name} in {header:?}"))
    };
    let value = |row: &[&str], name: &str| -> f64 { row[column(name)].parse().expect("number") };
    let last = rows.last().expect("rows");
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1e-12);
    assert!(close(value(last, "contact_radial_force@crimper"), radial));
    for (c, expected) in ["x", "y", "z"]
        .iter()
        .zip([o.force.x, o.force.y, o.force.z])
    {
        let got = value(last, &format!("contact_force_{c}@crimper"));
        assert!(
            (got - expected).abs() <= 1e-9 * radial,
            "{c}: {got} {expected}"
        );
    }
    assert_eq!(value(last, "contact_points@crimper"), n as f64);
    // Written with 7 digits.
    let penetration = value(last, "contact_penetration@crimper");
    assert!((penetration - o.penetration).abs() <= 1e-6 * o.penetration.max(1e-300));
    assert_eq!(value(last, "contact_friction_work@crimper"), 0.0);
    assert_eq!(value(&rows[0], "contact_points@crimper"), 0.0);
    assert_eq!(value(&rows[0], "contact_radial_force@crimper"), 0.0);

    let peaks = &summary["contact"][0];
    assert_eq!(peaks["obstacle"], "crimper");
    let largest = rows
        .iter()
        .map(|r| value(r, "contact_radial_force@crimper"))
        .fold(0.0, f64::max);
    let peak = peaks["peak_radial_force"]["value"].as_f64().expect("peak");
    assert!(close(peak, largest), "{peak} {largest}");
    assert_eq!(peaks["peak_radial_force"]["time"], 1.0);
    assert!(
        peaks["largest_penetration"]["value"]
            .as_f64()
            .expect("value")
            <= SETTINGS.tolerance
    );
    assert!(peaks["peak_force"]["value"].as_f64().expect("value") > 0.0);
    // The apposition at the end is the report's, to the last bits (serde_json reads a number back within an
    // ulp or two without its `float_roundtrip` feature: 1e-15 relative).
    let a = &peaks["apposition"];
    let same = |json: &serde_json::Value, x: f64| {
        json.as_f64()
            .is_some_and(|v| (v - x).abs() <= 1e-15 * x.abs())
    };
    assert_eq!(a["time"], 1.0);
    assert!(
        same(&a["contact_fraction"], o.apposition.contact_fraction),
        "{a}"
    );
    assert!(same(&a["mean_pressure"], o.apposition.mean_pressure), "{a}");
    assert!(same(&a["peak_pressure"], o.apposition.peak_pressure), "{a}");
    let (gap, patch, u) = o.apposition.largest_gap.expect("a gap");
    assert!(same(&a["largest_gap"]["value"], gap), "{a}");
    assert_eq!(
        a["largest_gap"]["patch"],
        model.patches[patch].name.as_str()
    );
    assert!(same(&a["largest_gap"]["u"], u), "{a}");

    let snapshots = summary["snapshots"].as_array().expect("snapshots");
    let vtp = snapshots.last().expect("a snapshot")["vtp"]
        .as_str()
        .expect("field file");
    let fields = std::fs::read_to_string(dir.join(vtp)).expect("field file");
    assert_eq!(vtk_array(&fields, "contact_pressure@crimper"), o.pressure);
    assert_eq!(vtk_array(&fields, "contact_gap@crimper"), o.gap);

    let bytes = std::fs::read(dir.join("run.mcap")).expect("recording");
    let (mut obstacles, mut last_obstacle, mut last_lines) = (0, None, None);
    for message in ::mcap::MessageStream::new(&bytes).expect("mcap") {
        let message = message.expect("message");
        let json: serde_json::Value = serde_json::from_slice(&message.data).expect("JSON");
        match message.channel.topic.as_str() {
            "/obstacles" => {
                obstacles += 1;
                last_obstacle = Some(json);
            }
            "/centrelines" => last_lines = Some(json),
            _ => {}
        }
    }
    assert_eq!(obstacles, rows.len());
    let entity = &last_obstacle.expect("an obstacle message")["entities"][0];
    assert_eq!(entity["id"], "obstacle.crimper");
    let diameter = entity["cylinders"][0]["size"]["x"].as_f64().expect("size");
    let expected = 2.0 * CRIMPED;
    assert!((diameter - expected).abs() <= 1e-5 * expected, "{diameter}");
    let line = &last_lines.expect("centrelines")["entities"][0]["lines"][0];
    let colors = line["colors"].as_array().expect("colours");
    assert_eq!(
        colors.len(),
        line["points"].as_array().expect("points").len()
    );
    assert!(colors.iter().all(|c| c["g"].as_f64() == Some(0.85)));

    for chart in ["contact_force.svg", "contact_diameter.svg"] {
        assert!(dir.join("charts").join(chart).exists(), "{chart}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The same ring without contact writes nothing of it: no history column, no summary entry, no field array,
/// no channel, no chart.
#[test]
fn a_run_without_contact_writes_none_of_it() {
    let dir = scratch("none");
    let mut model = crimped_ring();
    model.contact = None;
    let summary = run_into(&dir, model);
    let history = std::fs::read_to_string(dir.join("history.csv")).expect("history");
    assert!(!history.lines().next().expect("header").contains("contact"));
    assert!(summary.get("contact").is_none());
    for s in summary["snapshots"].as_array().expect("snapshots") {
        let fields =
            std::fs::read_to_string(dir.join(s["vtp"].as_str().expect("vtp"))).expect("vtp");
        assert!(!fields.contains("contact_"));
    }
    let bytes = std::fs::read(dir.join("run.mcap")).expect("recording");
    let summary_section = ::mcap::Summary::read(&bytes)
        .expect("mcap")
        .expect("summary");
    assert!(
        summary_section
            .channels
            .values()
            .all(|c| c.topic != "/obstacles")
    );
    assert!(!dir.join("charts/contact_force.svg").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
