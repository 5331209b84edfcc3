//! `--set PATH=VALUE` overrides of a design's fields (`check`, `mesh`, `run`, `tune`, `sweep`).
//!
//! `PATH` is the design's own field path, written as in error messages: keys joined by `.`, sequence
//! elements by `[i]` (`stent.crowns`, `material.wlf.Tg`, `patches[2].arc.radius`, `material.prony[3]`).
//! `VALUE` is YAML (`8`, `65.5`, `sinusoidal`, `[20.12, 1.0e-10]`, `{p: 6, n: 30}`). The overrides are applied
//! in order to the file's YAML tree, creating the maps a path needs (`--set mesh.n=30` on a design without
//! `mesh`), and the tree is then read exactly as a file is: every check applies. An error about a field that an
//! override set (or a map it created, or anything below either) names the `--set` argument instead of a line;
//! any other error keeps the file's line and column. The resolved design — the tree as YAML, with a comment
//! naming the file and the overrides — is what a run records ([`resolved_text`]); the file's comments are not
//! kept in it.

use crate::math::quote::{QUOTED_CHARS, quoted, shortened, shortened_message};
use serde_yaml::{Mapping, Value};
use std::fmt;
use std::str::FromStr;

/// One step of a field path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PathStep {
    /// A map key.
    Key(String),
    /// A sequence element, 0-based.
    Index(usize),
}

/// One `--set PATH=VALUE` argument, parsed.
#[derive(Debug, Clone, PartialEq)]
pub struct SetOverride {
    /// The argument as given (`stent.crowns=8`), for messages and records.
    pub argument: String,
    /// The field path.
    pub path: Vec<PathStep>,
    /// The value, parsed as YAML.
    pub value: Value,
}

/// Why a `--set` argument was refused before the design was read (the argument shown shortened, as values
/// in messages are: [`crate::math::quote`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("--set {}: {message}", shortened(argument, QUOTED_CHARS))]
pub struct SetSyntaxError {
    /// The argument as given.
    pub argument: String,
    /// What is wrong.
    pub message: String,
}

impl FromStr for SetOverride {
    type Err = SetSyntaxError;

    fn from_str(argument: &str) -> Result<Self, Self::Err> {
        let fail = |message: String| SetSyntaxError {
            argument: argument.to_string(),
            message,
        };
        let (path, value) = argument.split_once('=').ok_or_else(|| {
            fail("expected PATH=VALUE (e.g. `stent.crowns=8`, `material.wlf.Tg=65`)".into())
        })?;
        let path = parse_path(path.trim()).map_err(fail)?;
        let value: Value = serde_yaml::from_str(value).map_err(|e| {
            fail(format!(
                "the value is not YAML: {}",
                shortened_message(&e.to_string())
            ))
        })?;
        Ok(Self {
            argument: argument.to_string(),
            path,
            value,
        })
    }
}

impl SetOverride {
    /// The path as the design's error messages write it (`patches[2].arc.radius`).
    pub fn field(&self) -> String {
        path_text(&self.path)
    }
}

impl fmt::Display for SetOverride {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.argument)
    }
}

/// Parses a field path `a.b[2].c` (module docs).
///
/// # Errors
/// A message for an empty path or key, or a malformed index.
pub(crate) fn parse_path(text: &str) -> Result<Vec<PathStep>, String> {
    if text.is_empty() {
        return Err("the field path is empty".into());
    }
    let mut steps = Vec::new();
    for part in text.split('.') {
        let (key, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        if key.is_empty() && (steps.is_empty() || rest.is_empty()) {
            return Err(format!("{} has an empty key", quoted(text)));
        }
        if !key.is_empty() {
            steps.push(PathStep::Key(key.to_string()));
        }
        while !rest.is_empty() {
            let close = rest
                .find(']')
                .filter(|_| rest.starts_with('['))
                .ok_or_else(|| {
                    format!("{}: expected `[index]` after {}", quoted(text), quoted(key))
                })?;
            let index = rest[1..close].trim().parse().map_err(|_| {
                format!(
                    "{}: {} is not an index (0, 1, …)",
                    quoted(text),
                    quoted(&rest[1..close])
                )
            })?;
            steps.push(PathStep::Index(index));
            rest = &rest[close + 1..];
        }
    }
    Ok(steps)
}

/// The path as text (`a.b[2].c`).
pub(crate) fn path_text(path: &[PathStep]) -> String {
    let mut text = String::new();
    for step in path {
        match step {
            PathStep::Key(k) if text.is_empty() => text.push_str(k),
            PathStep::Key(k) => {
                text.push('.');
                text.push_str(k);
            }
            PathStep::Index(i) => text.push_str(&format!("[{i}]")),
        }
    }
    text
}

/// What applying one override did: the path of the first map it created (if any), so that an error about a
/// field below it is the override's.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Applied {
    /// The override's own path (`stent.crowns`).
    pub field: String,
    /// The shallowest map the override created, when the path did not exist (`mesh` for `mesh.n=30` on a
    /// design without `mesh`).
    pub created: Option<String>,
}

/// Sets `set.value` at `set.path` in `root` (module docs), creating missing maps along the path.
///
/// # Errors
/// A message when the path goes through a value that is not a map (for a key) or a sequence (for an index),
/// or an index is past the end of its sequence.
pub(crate) fn apply(root: &mut Value, set: &SetOverride) -> Result<Applied, String> {
    let mut node = root;
    let mut created = None;
    for (i, step) in set.path.iter().enumerate() {
        let here = path_text(&set.path[..i]);
        node = match step {
            PathStep::Key(key) => {
                if node.is_null() {
                    *node = Value::Mapping(Mapping::new());
                    created.get_or_insert_with(|| here.clone());
                }
                let what = kind_of(node);
                let map = node.as_mapping_mut().ok_or_else(|| {
                    format!(
                        "{} is {what}, not a map: it has no field {}",
                        if here.is_empty() {
                            "the design".to_string()
                        } else {
                            quoted(&here)
                        },
                        quoted(key)
                    )
                })?;
                // A missing key is inserted empty; the next step makes it a map (and records it as created).
                map.entry(Value::String(key.clone())).or_insert(Value::Null)
            }
            PathStep::Index(index) => {
                let seq = node.as_sequence_mut().ok_or_else(|| {
                    format!(
                        "{} is not a list: `[{index}]` does not apply to it",
                        quoted(&here)
                    )
                })?;
                let len = seq.len();
                seq.get_mut(*index).ok_or_else(|| {
                    format!(
                        "{} has {len} entries: there is no `[{index}]` (entries count from 0)",
                        quoted(&here)
                    )
                })?
            }
        };
    }
    *node = set.value.clone();
    Ok(Applied {
        field: set.field(),
        created,
    })
}

/// What a YAML value is, for messages.
fn kind_of(v: &Value) -> &'static str {
    match v {
        Value::Null => "empty",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Sequence(_) => "a list",
        Value::Mapping(_) => "a map",
        Value::Tagged(_) => "a tagged value",
    }
}

/// Whether `field` (an error's path) is `root` or below it.
fn at_or_below(field: &str, root: &str) -> bool {
    root.is_empty()
        || field == root
        || field
            .strip_prefix(root)
            .is_some_and(|rest| rest.starts_with(['.', '[']))
}

/// The override an error about `field` belongs to, if any: the last one whose path or created map holds
/// `field` (module docs).
pub(crate) fn owner<'a>(
    applied: &'a [(Applied, &'a SetOverride)],
    field: &str,
) -> Option<&'a SetOverride> {
    applied
        .iter()
        .rev()
        .find(|(a, _)| {
            at_or_below(field, &a.field)
                || a.created.as_deref().is_some_and(|c| at_or_below(field, c))
        })
        .map(|(_, s)| *s)
}

/// The resolved design's text: a comment naming the file and the overrides, then the tree as YAML.
///
/// # Errors
/// When the tree cannot be written as YAML (it was read from YAML, so this does not happen).
pub(crate) fn resolved_text(
    root: &Value,
    file: &std::path::Path,
    sets: &[SetOverride],
) -> Result<String, serde_yaml::Error> {
    let mut text = format!(
        "# The design {} with{}\n",
        file.display(),
        if sets.len() == 1 { "" } else { " (in order)" }
    );
    for s in sets {
        text.push_str(&format!("#   --set {}\n", s.argument));
    }
    text.push_str("# written by stentkit from the parsed file (its comments are not kept).\n");
    text.push_str(&serde_yaml::to_string(root)?);
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(a: &str) -> SetOverride {
        a.parse().expect("a valid --set")
    }

    #[test]
    fn paths_parse_as_error_messages_write_them() {
        let s = set("patches[2].arc.radius=3.5");
        assert_eq!(
            s.path,
            vec![
                PathStep::Key("patches".into()),
                PathStep::Index(2),
                PathStep::Key("arc".into()),
                PathStep::Key("radius".into())
            ]
        );
        assert_eq!(s.field(), "patches[2].arc.radius");
        assert_eq!(s.value, Value::from(3.5));
        assert_eq!(
            set("material.prony[3][0]=1").field(),
            "material.prony[3][0]"
        );
        // The value is YAML: a list, a string, a map.
        assert!(set("material.prony[3]=[20, 1e-3]").value.is_sequence());
        assert_eq!(
            set("stent.bridges.shape=sinusoidal").value,
            Value::from("sinusoidal")
        );
        assert!(set("mesh={p: 6, n: 30}").value.is_mapping());
        for bad in ["stent.crowns", "=3", "a..b=1", "a[x]=1", "a[1=2", "a.b=[1,"] {
            assert!(bad.parse::<SetOverride>().is_err(), "{bad} accepted");
        }
    }

    #[test]
    fn apply_replaces_creates_and_refuses_with_reasons() {
        let mut root: Value =
            serde_yaml::from_str("stent: {crowns: 6}\nlist: [1, 2]\nname: x\n").expect("yaml");
        let a = apply(&mut root, &set("stent.crowns=8")).expect("applies");
        assert_eq!(a.created, None);
        assert_eq!(root["stent"]["crowns"], Value::from(8));
        let a = apply(&mut root, &set("mesh.n=30")).expect("applies");
        assert_eq!(a.created.as_deref(), Some("mesh"));
        assert_eq!(root["mesh"]["n"], Value::from(30));
        apply(&mut root, &set("list[1]=5")).expect("applies");
        assert_eq!(root["list"][1], Value::from(5));
        let e = apply(&mut root, &set("list[2]=5")).expect_err("past the end");
        assert!(e.contains("has 2 entries"), "{e}");
        let e = apply(&mut root, &set("name.first=5")).expect_err("through a string");
        assert!(e.contains("`name` is a string, not a map"), "{e}");
        let e = apply(&mut root, &set("stent[0]=5")).expect_err("index of a map");
        assert!(e.contains("not a list"), "{e}");
    }

    #[test]
    fn errors_belong_to_the_override_that_set_or_created_their_field() {
        let (s1, s2) = (set("stent.crowns=8"), set("mesh.n=30"));
        let applied = vec![
            (
                Applied {
                    field: "stent.crowns".into(),
                    created: None,
                },
                &s1,
            ),
            (
                Applied {
                    field: "mesh.n".into(),
                    created: Some("mesh".into()),
                },
                &s2,
            ),
        ];
        assert_eq!(owner(&applied, "stent.crowns"), Some(&s1));
        assert_eq!(owner(&applied, "stent.crowns_x"), None);
        assert_eq!(owner(&applied, "stent.radius"), None);
        assert_eq!(owner(&applied, "mesh.p"), Some(&s2));
        assert_eq!(owner(&applied, "mesh"), Some(&s2));
        assert_eq!(owner(&applied, "material.E_inf"), None);
    }
}
