//! Every design in `designs/` loads, and `check` describes it.

use std::path::{Path, PathBuf};
use stentkit::design::load_design;

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

/// A design whose Prony series has no branches and no WLF shift is the plain elastic material (no internal
/// variables to store or prepare); the others are the Maxwell/WLF material. Every patch uses the design's one
/// material. (That the elastic law gives the Maxwell law's numbers bit for bit is checked in
/// `material::elastic`'s unit test; the histories of bend45 and rollup were compared with the runs before the
/// interface existed, bitwise.)
#[test]
fn elastic_designs_use_the_elastic_law() {
    use stentkit::material::MaterialLaw;
    for f in all_designs() {
        let d = load_design(&f).unwrap_or_else(|e| panic!("{e}"));
        let name = f.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
        let elastic = matches!(
            name,
            "bend45" | "rollup" | "arch215" | "von_mises_truss" | "z_ring"
        );
        if name == "sequential_stent" {
            // Four named materials: crowns of three glass transitions and the bridges.
            assert_eq!(d.model.material_names, ["tg55", "tg70", "tg85", "bridge"]);
            assert_eq!(d.model.material_regions().len(), 4);
        } else {
            assert_eq!(d.model.materials().len(), 1, "{name}");
            assert!(d.model.patches.iter().all(|p| p.material == 0), "{name}");
        }
        for law in d.model.materials() {
            match law {
                MaterialLaw::Elastic(_) => assert!(elastic, "{name} is viscoelastic"),
                MaterialLaw::Maxwell(m) => {
                    assert!(!elastic, "{name} is elastic");
                    assert!(m.material().num_branches() > 0 || m.material().wlf().is_some());
                }
            }
        }
    }
}

/// The builder fixture of the 45° bend (`fixtures::bend45_builder`, which `solver.rs` uses to split the bend
/// into patches and vary its load steps) is the model of designs/bend45.yaml: the two serialise to the same
/// description (`stentkit::model::fingerprint`'s JSON), so what the solver tests find of one holds for the file.
#[test]
fn the_bend_built_in_code_is_the_design_files_bend() {
    use crate::common::fixtures;
    let built = fixtures::bend45_builder(1, 6, 20, 10)
        .build()
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(built.warnings.is_empty(), "{:?}", built.warnings);
    let json = |m: &stentkit::model::Model| serde_json::to_string(m).expect("a model serialises");
    let (code, file) = (json(&built.model), json(&fixtures::bend45().model()));
    let first = code
        .bytes()
        .zip(file.bytes())
        .position(|(a, b)| a != b)
        .unwrap_or(code.len().min(file.len()));
    let around = |s: &str| {
        s.get(first.saturating_sub(80)..(first + 80).min(s.len()))
            .map(str::to_string)
    };
    assert!(
        code == file,
        "they differ at byte {first}: built {:?}, file {:?}",
        around(&code),
        around(&file)
    );
}

/// A fixture change fails loudly where a text edit did nothing: a path that names no field of the design
/// format (`stent.crown`) is refused when the design is read, naming the change, and a change of an
/// existing field takes effect (the crown count is the model's).
#[test]
fn a_fixture_change_of_a_field_that_does_not_exist_is_refused() {
    use crate::common::fixtures;
    let error = fixtures::straight_stent()
        .set("stent.crown", "2")
        .try_design()
        .expect_err("no field `stent.crown`");
    assert!(error.to_string().contains("stent.crown=2"), "{error}");
    let two = fixtures::straight_stent().crowns(2).model();
    let six = fixtures::straight_stent().model();
    assert!(
        two.patches.len() < six.patches.len(),
        "{} patches with 2 crowns, {} with 6",
        two.patches.len(),
        six.patches.len()
    );
}
