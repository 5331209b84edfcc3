//! `--set PATH=VALUE` overrides (issue 15): a design read with overrides is the design with those values
//! written in the file; an override's error names the `--set` argument; every other error is located in the file
//! exactly as without overrides; the resolved design reads back as the model that was built.

use crate::common::edit;
use std::path::{Path, PathBuf};
use stentkit::design::{
    DesignError, DesignOverrides, SetOverride, load_design, load_design_with, parse_design,
};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn sets(args: &[&str]) -> DesignOverrides {
    DesignOverrides::sets(
        args.iter()
            .map(|a| a.parse::<SetOverride>().expect("a valid --set"))
            .collect(),
    )
}

/// Source: the same design edited by hand. Overrides of a scalar, of a value in a flow map, and of a map the
/// file does not have give the model of the edited text, and the resolved design reads back as that model.
#[test]
fn overrides_give_the_model_of_the_edited_file() {
    let path = data("good_stent_small.yaml");
    let text = std::fs::read_to_string(&path).expect("readable");
    let edited = [
        ("crowns: 2", "crowns: 3"),
        ("Tg: 70.0", "Tg: 65.0"),
        ("  diameter: 0.6", "  diameter: 0.5"),
        ("mesh: {p: 4, n: 8}\n", ""),
    ]
    .iter()
    .fold(text.clone(), |t, (from, to)| edit(&t, from, to));
    let edited = format!("{edited}mesh: {{p: 5, n: 9}}\n");
    let by_hand = parse_design(&edited, &path).expect("the edited design is valid");
    let mut text_without_mesh = edit(&text, "mesh: {p: 4, n: 8}\n", "");
    text_without_mesh.push('\n');
    let scratch = std::env::temp_dir().join(format!("stentkit-set-{}.yaml", std::process::id()));
    std::fs::write(&scratch, &text_without_mesh).expect("writable");
    let overridden = load_design_with(
        &scratch,
        &sets(&[
            "stent.crowns=3",
            "material.wlf.Tg=65",
            "section.diameter=0.5",
            "mesh.p=5",
            "mesh.n=9",
            "name=good_stent_small",
        ]),
    )
    .expect("the overrides are valid");
    std::fs::remove_file(&scratch).ok();
    assert_eq!(overridden.model, by_hand.model);
    assert_eq!(overridden.overrides.len(), 6);
    let resolved = parse_design(&overridden.source, Path::new("resolved.yaml"))
        .expect("the resolved design reads");
    assert_eq!(resolved.model, by_hand.model);
    assert!(overridden.source.contains("#   --set stent.crowns=3"));
}

/// An override's own error names the `--set` argument and the field, whatever stage finds it (the value's
/// type, a check of one value, a check of several, a path that does not fit the design).
#[test]
fn an_overrides_error_names_the_argument() {
    let path = data("good_stent_small.yaml");
    for (arg, field, fragment) in [
        ("stent.crowns=abc", "stent.crowns", "invalid type"),
        ("stent.crownz=3", "stent.crownz", "unknown field `crownz`"),
        ("section.diameter=-1", "section.diameter", "must be > 0"),
        ("mesh.n=3", "mesh.n", "need n > p"),
        (
            "programme.delta_r=25",
            "programme.delta_r",
            "smaller than the crown radius",
        ),
        ("temperature[7]=3", "temperature[7]", "there is no `[7]`"),
        ("units.x=1", "units.x", "not a map"),
        ("joints.tolerance=-1", "joints.tolerance", ""),
    ] {
        let error = load_design_with(&path, &sets(&[arg])).expect_err(arg);
        let DesignError::Override {
            argument,
            field: got,
            message,
            ..
        } = &error
        else {
            panic!("{arg}: not an override error: {error}");
        };
        assert_eq!(argument, arg);
        assert_eq!(got, field, "{arg}: {error}");
        assert!(message.contains(fragment), "{arg}: {error}");
        let shown = error.to_string();
        assert!(
            shown.starts_with(&format!("{}: --set {arg}: {field}: ", path.display())),
            "{shown}"
        );
    }
}

/// Every broken design of tests/data/bad_designs/ gives the same error (file, line, column, field, message)
/// with an override of an unrelated field as without: the file's errors stay located in the file.
#[test]
fn the_files_own_errors_keep_their_place_under_an_override() {
    let dir = data("bad_designs");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("bad_designs")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    files.sort();
    assert!(files.len() > 40);
    let unrelated = sets(&["description=a variant"]);
    let mut differ = Vec::new();
    for file in &files {
        let plain = load_design(file).err().map(|e| e.to_string());
        let overridden = load_design_with(file, &unrelated)
            .err()
            .map(|e| e.to_string());
        if plain != overridden {
            differ.push(format!(
                "{}:\n  {plain:?}\n  {overridden:?}",
                file.display()
            ));
        }
    }
    assert!(differ.is_empty(), "{}", differ.join("\n"));
}

/// A resolved design names its centreline file by an absolute path (source: the file's own relative path
/// joined to the design's folder), so that it reads the same from a sweep's variant folder.
#[test]
fn a_resolved_design_reads_from_anywhere() {
    let design = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/aorta_stent.yaml");
    let relative = Path::new("designs/aorta_stent.yaml");
    let path = if relative.exists() {
        relative
    } else {
        design.as_path()
    };
    let resolved = load_design_with(path, &sets(&["stent.crowns=2"])).expect("the design reads");
    let elsewhere = std::env::temp_dir().join(format!("stentkit-resolved-{}", std::process::id()));
    std::fs::create_dir_all(&elsewhere).expect("scratch");
    let copy = elsewhere.join("design.yaml");
    std::fs::write(&copy, &resolved.source).expect("written");
    let reread = load_design(&copy).expect("the resolved design reads from another folder");
    std::fs::remove_dir_all(&elsewhere).ok();
    assert_eq!(reread.model.nodes.len(), resolved.model.nodes.len());
    assert!(
        resolved.source.contains(&format!(
            "path: {}",
            design
                .parent()
                .expect("folder")
                .join("data/aorta-centerline.vtp")
                .display()
        )),
        "{}",
        resolved.source
    );
}
