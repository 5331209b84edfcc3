//! Edits of design texts at the YAML level, for benchmarks that vary what
//! [`crate::io::design::DesignOverrides`] does not cover: parse the text into a generic YAML tree, set a value
//! at a key path, and write the tree back. (The studies vary built models instead, [`crate::study::variant`];
//! this stays for `benches/support` until the model builder replaces it there.) Comments and key order of untouched maps are not kept, so the result is for the solver, not for
//! people; validation (and its located errors) happens afterwards, when the edited text is parsed as a design.

use serde_yaml::{Mapping, Value};

/// Why a design text could not be edited.
#[derive(Debug, thiserror::Error)]
pub enum YamlEditError {
    /// The text is not YAML.
    #[error("not YAML: {0}")]
    Parse(#[from] serde_yaml::Error),
    /// A key on the path names something that is not a map.
    #[error("cannot set `{path}`: `{key}` is not a map in the design")]
    NotAMap {
        /// The whole key path, dotted.
        path: String,
        /// The key whose value is not a map.
        key: String,
    },
}

/// Returns `text` with the value at `path` (keys from the top, e.g. `["stent", "crowns"]`) set to `value`,
/// creating missing maps on the way.
pub fn set_yaml(text: &str, path: &[&str], value: Value) -> Result<String, YamlEditError> {
    set_yaml_many(text, &[(path, value)])
}

/// Returns `text` with every `(path, value)` of `edits` set, in order (see [`set_yaml`]).
pub fn set_yaml_many(text: &str, edits: &[(&[&str], Value)]) -> Result<String, YamlEditError> {
    let mut root: Value = serde_yaml::from_str(text)?;
    for (path, value) in edits {
        let dotted = path.join(".");
        let mut node = &mut root;
        for (depth, key) in path.iter().enumerate() {
            if node.is_null() {
                *node = Value::Mapping(Mapping::new());
            }
            let Value::Mapping(map) = node else {
                return Err(YamlEditError::NotAMap {
                    path: dotted,
                    key: path[..depth].join("."),
                });
            };
            node = map
                .entry(Value::String((*key).to_string()))
                .or_insert(Value::Null);
        }
        *node = value.clone();
    }
    Ok(serde_yaml::to_string(&root)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_nested_values_and_creates_missing_maps() {
        let text = "name: x\nstent:\n  crowns: 6 # comment\ntime: {end: 1.0, step: 0.1}\n";
        let edited = set_yaml_many(
            text,
            &[
                (&["stent", "crowns"], Value::from(2)),
                (&["time", "release_ramp"], Value::from(0.5)),
                (&["solver", "tolerance"], Value::from(1e-8)),
            ],
        )
        .expect("edits");
        let v: Value = serde_yaml::from_str(&edited).expect("YAML");
        assert_eq!(v["stent"]["crowns"], Value::from(2));
        assert_eq!(v["time"]["release_ramp"], Value::from(0.5));
        assert_eq!(v["time"]["end"], Value::from(1.0));
        assert_eq!(v["solver"]["tolerance"], Value::from(1e-8));
        assert!(matches!(
            set_yaml(text, &["name", "first"], Value::from(1)),
            Err(YamlEditError::NotAMap { .. })
        ));
    }
}
