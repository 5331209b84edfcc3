//! What a sweep will write to disk, estimated before anything is written: for each variant still to run, the
//! estimate `run` checks before it writes ([`estimated_disk`]) plus the variant's design file, summed.
//!
//! **Cheaply, and exactly that sum.** Building a variant's design costs 2 ms (the 45° bend) to 0.1 s (the straight
//! stent), so a 5000-variant stent sweep would take minutes to estimate variant by variant, before it could be
//! refused. But [`estimated_disk`] reads the model's patches, nodes, conditions, probes, programme, schedules,
//! steps and output settings, and never a material's constitutive constants or the section (they change the
//! stiffness, not what is written): the fields of [`size_neutral`]. Variants whose values differ only in such
//! fields write alike, so they form one group and one design is built per group: the first variant of the group
//! whose design is valid (those before it are refused designs, each writing only its `error.txt`). The other
//! variants of the group differ from it only in the resolved design text, which `run.mcap` and `design.yaml`
//! hold: its length is computed for each of them from the built variant's text with the variant's own values
//! (YAML only, no model), and the estimate adjusted by the difference. A unit test checks the neutral fields
//! against [`estimated_disk`] on every design in `designs/`, and the grouped sum against the variant-by-variant
//! one.

use super::{Plan, Resolutions, resolve_design};
use crate::design::set::{PathStep, SetOverride, apply, parse_path, resolved_text};
use crate::run::estimate::{DiskEstimate, estimated_disk};
use std::collections::HashMap;

/// A material's fields that [`estimated_disk`] does not read (its constitutive constants; not its `name`,
/// which patches refer to, nor its `strain_limit`, which adds a `history.csv` column).
const NEUTRAL_MATERIAL_FIELDS: [&str; 5] = ["E_inf", "prony", "nu", "wlf", "integrator"];

/// Whether the field at `path` (or anything below it) cannot change what a run writes
/// ([`estimated_disk`]): the section (`section…`) and the constitutive constants of a material
/// (`material.wlf.Tg`, `materials[1].prony`, … : `NEUTRAL_MATERIAL_FIELDS`).
pub(crate) fn size_neutral(path: &[PathStep]) -> bool {
    let neutral = |field: &str| NEUTRAL_MATERIAL_FIELDS.contains(&field);
    match path {
        [PathStep::Key(section), ..] => {
            section == "section"
                || matches!(path, [_, PathStep::Key(f), ..] if section == "material" && neutral(f))
                || matches!(path, [_, PathStep::Index(_), PathStep::Key(f), ..] if section == "materials" && neutral(f))
        }
        _ => false,
    }
}

/// A sweep's estimate ([`estimate`]).
#[derive(Debug, Clone, Default)]
pub(crate) struct SweepEstimate {
    /// Variants counted (those still to run).
    pub variants: usize,
    /// Bytes they are estimated to write: their runs and their design files (or refusals).
    pub total: u64,
    /// Designs built to estimate them (one per group of variants that write alike, plus refused ones).
    pub built: usize,
    /// The variant whose run is estimated to write the most, with that estimate (`None` when no variant's
    /// design is valid).
    pub largest: Option<(usize, DiskEstimate)>,
    /// The resolutions made on the way, for [`super::SweepDir::prepare`] (not made twice).
    pub resolved: Resolutions,
}

/// A group's built variant: its estimate, the length of its resolved text, and that text as a YAML tree.
struct Representative {
    estimate: DiskEstimate,
    source_len: u64,
    tree: serde_yaml::Value,
}

/// Estimates what the variants `todo` of `plan` will write (module docs); `None` when `stop` said so (asked
/// before each design is built).
pub(crate) fn estimate(
    plan: &Plan,
    todo: &[usize],
    stop: &dyn Fn() -> bool,
) -> Option<SweepEstimate> {
    // Which parameters can change a variant's size; a path that does not parse is treated as one that can.
    let neutral: Vec<bool> = plan
        .parameters
        .iter()
        .map(|p| parse_path(&p.path).is_ok_and(|steps| size_neutral(&steps)))
        .collect();
    let mut groups: HashMap<Vec<&str>, Representative> = HashMap::new();
    let mut result = SweepEstimate {
        variants: todo.len(),
        ..SweepEstimate::default()
    };
    for &index in todo {
        let Some(variant) = plan.variants.get(index) else {
            continue;
        };
        let key: Vec<&str> = variant
            .values
            .iter()
            .zip(&neutral)
            .filter(|(_, n)| !**n)
            .map(|(v, _)| v.as_str())
            .collect();
        let bytes = match groups.get(&key) {
            Some(rep) => {
                let len = member_source_len(plan, index, &neutral, rep).unwrap_or(rep.source_len);
                let estimate = rep.estimate.with_design_text(rep.source_len, len);
                let bytes = estimate.total() + len;
                note_largest(&mut result.largest, index, estimate);
                bytes
            }
            None => {
                if stop() {
                    return None;
                }
                result.built += 1;
                match resolve_design(plan, index) {
                    Ok(design) => {
                        let estimate = estimated_disk(&design);
                        let source_len = design.source.len() as u64;
                        let bytes = estimate.total() + source_len;
                        note_largest(&mut result.largest, index, estimate.clone());
                        if let Ok(tree) = serde_yaml::from_str(&design.source) {
                            groups.insert(
                                key,
                                Representative {
                                    estimate,
                                    source_len,
                                    tree,
                                },
                            );
                        }
                        result.resolved.insert(index, Ok(design.source));
                        bytes
                    }
                    Err(error) => {
                        let len = error.len() as u64;
                        result.resolved.insert(index, Err(error));
                        len
                    }
                }
            }
        };
        result.total += bytes;
    }
    Some(result)
}

/// Keeps the larger of `largest` and (`index`, `estimate`).
fn note_largest(largest: &mut Option<(usize, DiskEstimate)>, index: usize, estimate: DiskEstimate) {
    if largest
        .as_ref()
        .is_none_or(|(_, e)| estimate.total() > e.total())
    {
        *largest = Some((index, estimate));
    }
}

/// The length of variant `index`'s resolved design text, from its group's built variant: that variant's tree
/// with this variant's values of the neutral parameters set again, in order (every other value is the same in
/// the group, and a later parameter never replaces an earlier one: [`Plan::new`]). `None` when a value does
/// not apply (the variant's design is refused: it writes less than the estimate charged).
fn member_source_len(
    plan: &Plan,
    index: usize,
    neutral: &[bool],
    rep: &Representative,
) -> Option<u64> {
    let sets: Vec<SetOverride> = plan
        .overrides(index)
        .iter()
        .map(|s| s.parse())
        .collect::<Result<_, _>>()
        .ok()?;
    let mut tree = rep.tree.clone();
    for (set, _) in sets.iter().zip(neutral).filter(|(_, n)| **n) {
        apply(&mut tree, set).ok()?;
    }
    resolved_text(&tree, &plan.design, &sets)
        .ok()
        .map(|t| t.len() as u64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::{DesignOverrides, load_design, load_design_with};
    use crate::sweep::Parameter;
    use std::path::{Path, PathBuf};

    fn designs() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("designs")
    }

    // The grouped estimate must be the sum a variant-by-variant estimate gives: the 45° bend over
    // 3 Poisson ratios × 2 meshes × 2 section areas (12 variants, 2 groups: the mesh changes the size, the
    // others do not), one Poisson ratio refused (nu = 0.6 > 0.5), so the first variants of each group are
    // refused designs and the first valid one is built. Reference: every variant built and estimated alone. Tolerance: one
    // byte per variant (the recording's estimate is a float sum truncated to bytes, so adding the length
    // difference afterwards can differ from adding it inside by one).
    #[test]
    fn the_grouped_estimate_is_the_variant_by_variant_sum() {
        let parameters = [
            "material.nu=0.6,0,0.1",
            "mesh.n=20,24",
            "section.area=1,2.5",
        ]
        .iter()
        .map(|a| Parameter::parse(a).expect("parameter"))
        .collect();
        let plan = Plan::new(&designs().join("bend45.yaml"), parameters, false).expect("plan");
        let todo: Vec<usize> = (0..plan.variants.len()).collect();
        let grouped = estimate(&plan, &todo, &|| false).expect("not stopped");
        let mut reference = 0u64;
        for &i in &todo {
            reference += match resolve_design(&plan, i) {
                Ok(d) => estimated_disk(&d).total() + d.source.len() as u64,
                Err(e) => e.len() as u64,
            };
        }
        assert!(
            grouped.total.abs_diff(reference) <= todo.len() as u64,
            "{} against {reference}",
            grouped.total
        );
        // Built, per mesh: the two refused variants of nu = 0.6 (both areas: the group has no valid design
        // yet), then nu = 0 with the first area; the other three of the group are not built.
        assert_eq!(grouped.built, 6);
        assert_eq!(grouped.resolved.len(), 6);
        assert!(estimate(&plan, &todo, &|| true).is_none());
    }

    // The fields `size_neutral` names must not change `estimated_disk` but through the resolved text's length
    // (which the grouped estimate adds per variant): on every design in designs/, each neutral field present
    // is changed to another valid value and the estimate compared, part by part, with the recording's part
    // less the text's length difference. Exact (to the byte of that truncation, as above).
    #[test]
    fn the_neutral_fields_do_not_change_what_a_run_writes() {
        let mut checked = 0;
        for entry in std::fs::read_dir(designs()).expect("designs") {
            let path = entry.expect("entry").path();
            if path.extension().is_none_or(|e| e != "yaml") {
                continue;
            }
            let base = load_design(&path).expect("valid design");
            let text = std::fs::read_to_string(&path).expect("text");
            let tree: serde_yaml::Value = serde_yaml::from_str(&text).expect("YAML");
            let mut changes = vec![
                "material.nu=0.31".to_string(),
                "material.E_inf=123.5".to_string(),
                "material.integrator=exponential".to_string(),
            ];
            if tree["material"]["wlf"].is_mapping() {
                changes.push("material.wlf.Tg=57.25".into());
            }
            if tree["material"]["prony"]
                .as_sequence()
                .is_some_and(|s| !s.is_empty())
            {
                changes.push("material.prony[0][0]=7.5".into());
            }
            for (key, value) in tree["section"].as_mapping().into_iter().flatten() {
                if let (Some(key), Some(x)) = (key.as_str(), value.as_f64()) {
                    changes.push(format!("section.{key}={}", x * 0.9));
                }
            }
            let before = estimated_disk(&base);
            for change in &changes {
                let sets = vec![change.parse().expect("override")];
                let Ok(changed) = load_design_with(&path, &DesignOverrides::sets(sets)) else {
                    continue;
                };
                let after = estimated_disk(&changed)
                    .with_design_text(changed.source.len() as u64, base.source.len() as u64);
                for (a, b) in after.parts.iter().zip(&before.parts) {
                    let (mut a, mut b) = (a.clone(), b.clone());
                    if a.holds_design_text {
                        let off = a.bytes.abs_diff(b.bytes);
                        assert!(off <= 1, "{}: {change}: {} {off}", path.display(), a.writer);
                        (a.bytes, b.bytes) = (0, 0);
                    }
                    assert_eq!(a, b, "{}: {change}", path.display());
                }
                assert_eq!(after.parts.len(), before.parts.len());
                checked += 1;
            }
        }
        eprintln!("{checked} changes checked");
        assert!(checked >= 30, "only {checked} changes checked");
    }

    #[test]
    fn neutral_paths_are_the_section_and_the_constitutive_constants() {
        let neutral = |p: &str| size_neutral(&parse_path(p).expect("path"));
        for p in [
            "section",
            "section.diameter",
            "material.wlf.Tg",
            "material.prony[0][1]",
            "materials[2].nu",
        ] {
            assert!(neutral(p), "{p}");
        }
        for p in [
            "material",
            "material.strain_limit",
            "material.name",
            "materials[0]",
            "mesh.n",
            "time.step",
            "output",
        ] {
            assert!(!neutral(p), "{p}");
        }
    }
}
