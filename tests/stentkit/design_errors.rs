//! Broken designs: every file in `tests/data/bad_designs/` breaks the valid `tests/data/good_small.yaml` in one
//! place and states, on its first line, the error it must produce:
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
fn every_broken_design_gets_a_clear_located_error() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(data("bad_designs"))
        .expect("bad_designs exists")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    files.sort();
    assert!(
        files.len() >= 20,
        "the issue asks for at least 20 broken designs, found {}",
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
