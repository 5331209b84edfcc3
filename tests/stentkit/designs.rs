//! Every design in `designs/` loads, and `check` describes it.

use std::path::{Path, PathBuf};
use stentkit::io::design::load_design;

/// All YAML files in `designs/`.
pub fn all_designs() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs");
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("designs/ exists")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_design_in_designs_loads_without_warnings() {
    let files = all_designs();
    assert!(files.len() >= 2);
    for f in files {
        let d = load_design(&f).unwrap_or_else(|e| panic!("{e}"));
        assert!(d.warnings.is_empty(), "{}: {:?}", f.display(), d.warnings);
        assert!(d.model.num_unknowns() > 0);
    }
}
