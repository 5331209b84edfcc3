//! Broken designs: every file in `tests/data/bad_designs/` breaks the valid `tests/data/good_small.yaml` (or,
//! for the stent and programme errors, `tests/data/good_stent_small.yaml`) in one place and states, on its
//! first line, the error it must produce:
//! `# expect: LINE:COLUMN | field path | message fragment`.
//! The positions were read off each file by eye: they point at the offending value (or key, or the parent of
//! a missing field). The test checks that loading fails with exactly that position, field and a message
//! containing the fragment, and that nothing panics.

use std::path::{Path, PathBuf};
use stentkit::io::design::{DesignError, load_design};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

struct Expectation {
    line: usize,
    column: usize,
    field: String,
    fragment: String,
}

fn expectation(path: &Path) -> Expectation {
    let text = std::fs::read_to_string(path).expect("readable test file");
    let first = text.lines().next().expect("non-empty test file");
    let spec = first
        .strip_prefix("# expect: ")
        .expect("first line starts with `# expect: `");
    let parts: Vec<&str> = spec.split(" | ").collect();
    assert_eq!(
        parts.len(),
        3,
        "{}: expect line has three parts",
        path.display()
    );
    let (line, column) = parts[0].split_once(':').expect("LINE:COLUMN");
    Expectation {
        line: line.trim().parse().expect("line number"),
        column: column.trim().parse().expect("column number"),
        field: parts[1].trim().to_string(),
        fragment: parts[2].trim().to_string(),
    }
}

#[test]
fn the_base_of_the_broken_designs_is_valid() {
    let design = load_design(&data("good_small.yaml")).expect("good_small.yaml is valid");
    assert_eq!(design.model.patches.len(), 2);
    assert_eq!(
        design.model.nodes.len(),
        3,
        "root, knee and the free end hook.end"
    );
}

#[test]
fn the_base_of_the_broken_stent_designs_is_valid() {
    let design =
        load_design(&data("good_stent_small.yaml")).expect("good_stent_small.yaml is valid");
    assert!(design.model.programme.is_some());
    assert!(!design.model.symmetry_planes.is_empty(), "a quarter model");
}

#[test]
fn temperature_below_the_wlf_singularity_is_a_warning_with_the_freeze() {
    // good_small cooled to 10 °C, below Tg − C2 = 70 − 48.43 = 21.57 °C, where the WLF shift is singular: the
    // design is accepted (DESIGN §4: the relaxation freezes, as Abaqus' TRS does), with a warning naming the
    // singularity and the freeze; the solver says once, when it gets there, that relaxation is frozen. This
    // fails if the design were rejected, or accepted silently.
    let text = std::fs::read_to_string(data("good_small.yaml"))
        .expect("base")
        .replace(
            "temperature: [[0, 90], [1, 40]]",
            "temperature: [[0, 90], [1, 10]]",
        );
    assert!(text.contains("[1, 10]"));
    let path = Path::new("wlf_freeze.yaml");
    let design = stentkit::io::design::parse_design(&text, path).expect("accepted with a warning");
    let warning = design
        .warnings
        .iter()
        .find(|w| w.contains("WLF singularity"))
        .unwrap_or_else(|| panic!("no WLF warning in {:?}", design.warnings));
    assert!(
        warning.contains("21.57") && warning.contains("freezes"),
        "{warning}"
    );
    // The base, cooled only to 40 °C, has no such warning.
    let base = load_design(&data("good_small.yaml")).expect("base");
    assert!(
        base.warnings.iter().all(|w| !w.contains("WLF")),
        "{:?}",
        base.warnings
    );
    // A run through the singularity: the 45° bend (elastic and robust, 10 steps) given a Maxwell branch, the
    // same WLF constants and cooling from 90 °C to 10 °C over the run. Each step's temperature is 90 − 80 t, so
    // the first step ending at or below 21.57 °C is the one to t = 0.9 (18 °C): the solver says there, once,
    // that relaxation is frozen, and the run completes.
    let bend =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/bend45.yaml"))
            .expect("bend45")
            .replace(
                "  nu: 0.0\n",
                "  nu: 0.0\n  prony: [[2.0e7, 0.1]]\n  wlf: {C1: 14.59, C2: 48.43, Tg: 70.0}\n",
            )
            .replace("time: {", "temperature: [[0, 90], [1, 10]]\ntime: {");
    assert!(bend.contains("wlf:") && bend.contains("[1, 10]"));
    let design = stentkit::io::design::parse_design(&bend, path).expect("cooled bend");
    assert!(
        design
            .warnings
            .iter()
            .any(|w| w.contains("WLF singularity"))
    );
    let mut sim = stentkit::solver::Simulation::new(&design.model).expect("simulation");
    let summary = sim
        .run(&mut stentkit::solver::simulation::NoObserver)
        .expect("the run passes the singularity");
    assert_eq!(summary.steps, 10);
    let notices = sim.notices();
    assert_eq!(notices.len(), 1, "said once: {notices:?}");
    let at: f64 = notices[0]
        .strip_prefix("at t = ")
        .and_then(|r| r.split_once(' '))
        .and_then(|(t, _)| t.parse().ok())
        .unwrap_or_else(|| panic!("no time in {notices:?}"));
    assert!((at - 0.9).abs() < 1e-9, "{notices:?}");
    assert!(notices[0].contains("frozen"), "{notices:?}");
}

#[test]
fn every_broken_design_gets_a_clear_located_error() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(data("bad_designs"))
        .expect("bad_designs exists")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    files.sort();
    assert!(
        files.len() >= 40,
        "issue 7 asks for at least 40 broken designs, found {}",
        files.len()
    );
    let mut failures = Vec::new();
    for file in &files {
        let want = expectation(file);
        let result = std::panic::catch_unwind(|| load_design(file));
        let outcome = match result {
            Err(_) => Err("panicked".to_string()),
            Ok(Ok(_)) => Err("was accepted".to_string()),
            Ok(Err(DesignError::Read { .. })) => Err("could not be read".to_string()),
            Ok(Err(e @ DesignError::Invalid { .. })) => {
                let text = e.to_string();
                let DesignError::Invalid {
                    line,
                    column,
                    field,
                    message,
                    ..
                } = &e
                else {
                    unreachable!()
                };
                if (*line, *column) != (want.line, want.column)
                    || *field != want.field
                    || !message.contains(&want.fragment)
                {
                    Err(format!("got `{text}`"))
                } else if !text.starts_with(&format!("{}:{line}:{column}: ", file.display())) {
                    Err(format!(
                        "message does not start with file:line:column: `{text}`"
                    ))
                } else {
                    Ok(())
                }
            }
        };
        if let Err(why) = outcome {
            failures.push(format!(
                "{}: expected {}:{} `{}` containing `{}`; {why}",
                file.file_name().unwrap_or_default().to_string_lossy(),
                want.line,
                want.column,
                want.field,
                want.fragment
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} broken designs misreported:\n{}",
        failures.len(),
        files.len(),
        failures.join("\n")
    );
}
