//! The text of a tuned design (`stentkit tune -o`): the source with its discretisation replaced — `mesh: {p, n}`
//! for every patch and `time.tolerance` — and a comment block on top.
//!
//! The source's own text, comments included, is kept: the top-level `mesh:` and `time:` entries (a line and the
//! indented lines under it) are replaced by one flow-style line each, the other keys of `time` kept. When the
//! source gives meshes of its own to patches (`patches[].p`/`n`) or to a stent's crowns or bridges
//! (`stent.crown_mesh`, `stent.bridge_mesh`), those entries are nested where a line edit is not safe: the
//! document is then written from its parsed tree without them (its comments other than the header are lost, and
//! the header says so).

use serde_yaml::{Mapping, Value};

/// What a tuned design sets.
#[derive(Debug, Clone, PartialEq)]
pub struct TunedChoice {
    /// Degree of every patch.
    pub degree: usize,
    /// Control points of every patch.
    pub points: usize,
    /// `time.tolerance`.
    pub time_tolerance: f64,
    /// The comment block's text (lines without `#`).
    pub header: String,
}

/// Why a tuned text could not be made.
#[derive(Debug, thiserror::Error)]
pub enum TunedTextError {
    /// The source is not YAML.
    #[error("not YAML: {0}")]
    Yaml(#[from] serde_yaml::Error),
    /// The source's top level or its `time` is not a map.
    #[error("`{0}` is not a map")]
    NotAMap(&'static str),
}

/// The source `text` with `choice` applied (module docs).
///
/// # Errors
/// [`TunedTextError`] when `text` is not a YAML map with a `time` map (a design that parsed always is).
pub fn tuned_text(text: &str, choice: &TunedChoice) -> Result<String, TunedTextError> {
    let mut root: Value = serde_yaml::from_str(text)?;
    let top = root
        .as_mapping_mut()
        .ok_or(TunedTextError::NotAMap("the design"))?;
    let time = top
        .get("time")
        .and_then(Value::as_mapping)
        .ok_or(TunedTextError::NotAMap("time"))?;
    let mesh_line = format!("mesh: {{p: {}, n: {}}}", choice.degree, choice.points);
    let time_line = format!("time: {}", flow(time, choice.time_tolerance)?);
    let mut header: String = choice.header.lines().map(|l| format!("# {l}\n")).collect();
    if !own_meshes(top) {
        // A design that parsed has a top-level `time` entry; one without `mesh` gets it appended.
        let body = replace_entry(text, "time", &time_line).unwrap_or_else(|| text.to_string());
        let body = replace_entry(&body, "mesh", &mesh_line)
            .unwrap_or_else(|| format!("{}\n{mesh_line}\n", body.trim_end()));
        return Ok(format!("{header}#\n{body}"));
    }
    if let Some(Value::Sequence(patches)) = top.get_mut("patches") {
        for patch in patches.iter_mut().filter_map(Value::as_mapping_mut) {
            patch.remove("p");
            patch.remove("n");
        }
    }
    if let Some(stent) = top.get_mut("stent").and_then(Value::as_mapping_mut) {
        stent.remove("crown_mesh");
        stent.remove("bridge_mesh");
    }
    let mut mesh = Mapping::new();
    mesh.insert("p".into(), choice.degree.into());
    mesh.insert("n".into(), choice.points.into());
    top.insert("mesh".into(), Value::Mapping(mesh));
    if let Some(Value::Mapping(time)) = top.get_mut("time") {
        time.insert("tolerance".into(), choice.time_tolerance.into());
    }
    header.push_str(
        "# (Written from the parsed source: its own per-patch, crown or bridge meshes were removed, and with them\n\
         # its comments.)\n",
    );
    Ok(format!("{header}#\n{}", serde_yaml::to_string(&root)?))
}

/// Whether the design gives meshes of its own below the top level.
fn own_meshes(top: &Mapping) -> bool {
    let patch_mesh = top
        .get("patches")
        .and_then(Value::as_sequence)
        .is_some_and(|ps| {
            ps.iter()
                .any(|p| p.get("p").is_some() || p.get("n").is_some())
        });
    let stent_mesh = top
        .get("stent")
        .is_some_and(|s| s.get("crown_mesh").is_some() || s.get("bridge_mesh").is_some());
    patch_mesh || stent_mesh
}

/// `time`'s entries in flow style with `tolerance` set.
fn flow(time: &Mapping, tolerance: f64) -> Result<String, TunedTextError> {
    let mut entries = Vec::new();
    for (k, v) in time {
        if k.as_str() == Some("tolerance") {
            continue;
        }
        let value = serde_yaml::to_string(v)?;
        entries.push(format!(
            "{}: {}",
            serde_yaml::to_string(k)?.trim(),
            value.trim()
        ));
    }
    entries.push(format!("tolerance: {tolerance:e}"));
    Ok(format!("{{{}}}", entries.join(", ")))
}

/// `text` with the top-level entry `key` (its line and the indented or blank lines under it, but not the blank
/// lines that end it) replaced by `line`; `None` when there is no such entry.
fn replace_entry(text: &str, key: &str, line: &str) -> Option<String> {
    let lines: Vec<&str> = text.lines().collect();
    let starts = |l: &str| {
        l.strip_prefix(key)
            .is_some_and(|rest| rest.trim_start().starts_with(':'))
    };
    let first = lines.iter().position(|l| starts(l))?;
    let mut last = first;
    for (i, l) in lines.iter().enumerate().skip(first + 1) {
        if l.starts_with([' ', '\t']) {
            last = i;
        } else if !l.trim().is_empty() {
            break;
        }
    }
    let mut out: Vec<&str> = lines[..first].to_vec();
    out.push(line);
    out.extend(&lines[last + 1..]);
    let mut joined = out.join("\n");
    if text.ends_with('\n') {
        joined.push('\n');
    }
    Some(joined)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::{DesignOverrides, parse_design, parse_design_with};
    use std::path::Path;

    fn choice() -> TunedChoice {
        TunedChoice {
            degree: 5,
            points: 17,
            time_tolerance: 3e-3,
            header: "tuned\nsecond line".into(),
        }
    }

    /// What the tuned text reads as: the source with the same settings as overrides.
    fn check(name: &str, source: &str) -> String {
        let text = tuned_text(source, &choice()).expect("tuned text");
        let written = parse_design(&text, Path::new(name)).expect("reads back");
        let overrides = DesignOverrides {
            degree: Some(5),
            points: Some(17),
            time_tolerance: Some(3e-3),
            ..DesignOverrides::default()
        };
        let expected = parse_design_with(source, Path::new(name), &overrides).expect("overrides");
        assert_eq!(written.model, expected.model, "{name}");
        assert!(text.starts_with("# tuned\n# second line\n"));
        text
    }

    #[test]
    fn every_design_tunes_to_the_overridden_model_and_keeps_its_comments() {
        for (name, source) in [
            (
                "curved_stent.yaml",
                include_str!("../../designs/curved_stent.yaml"),
            ),
            (
                "circular_arch.yaml",
                include_str!("../../designs/circular_arch.yaml"),
            ),
            ("bend45.yaml", include_str!("../../designs/bend45.yaml")),
        ] {
            let text = check(name, source);
            // Every comment line of the source is still there.
            for comment in source.lines().filter(|l| l.starts_with('#')) {
                assert!(text.contains(comment), "{name}: lost {comment}");
            }
            assert_eq!(text.matches("\nmesh: {p: 5, n: 17}\n").count(), 1, "{name}");
        }
    }

    #[test]
    fn a_block_style_time_and_per_patch_meshes_are_replaced() {
        let arch = include_str!("../../designs/circular_arch.yaml");
        // Each edit below must find its text (a silent no-op would test the unedited design).
        for from in [
            "time: {end: 5.0, step: 1.0e-3}",
            "mesh: {p: 6, n: 20}\n",
            "angle_deg: 90}",
        ] {
            assert!(arch.contains(from), "circular_arch.yaml: `{from}`");
        }
        let block = arch
            .replace(
                "time: {end: 5.0, step: 1.0e-3}",
                "time:\n  end: 5.0   # s\n\n  step: 1.0e-3\n",
            )
            .replace("mesh: {p: 6, n: 20}\n", "");
        let text = check("block.yaml", &block);
        assert!(
            text.contains("time: {end: 5.0, step: 0.001, tolerance: 3e-3}\n"),
            "{text}"
        );
        assert!(text.trim_end().ends_with("mesh: {p: 5, n: 17}"));
        let per_patch = arch.replace("angle_deg: 90}", "angle_deg: 90}\n    p: 4\n    n: 12");
        let text = check("per_patch.yaml", &per_patch);
        assert!(text.contains("comments.)"));
    }
}
