//! Source positions of the fields of a YAML document, by field path (`patches[2].arc.radius`), so that
//! checks made after deserialisation can still name the line and column they are about.

use saphyr_parser::{Event, Parser};
use std::collections::HashMap;

/// A position in the source: line and column, both 1-based.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Position {
    /// Line, 1-based.
    pub line: usize,
    /// Column, 1-based.
    pub column: usize,
}

/// Keys longer than this many bytes appear as `…` in the paths of the nodes below them. No field of the
/// format is longer than 20; without the cap, a long key (up to the size limit) would be copied into the path
/// of every node below it, and the index would grow with the key's length times their number.
const MAX_PATH_KEY_BYTES: usize = 64;

/// Field path → position of its value (and of its key, for mapping entries).
#[derive(Debug, Default, Clone)]
pub(crate) struct Locator {
    values: HashMap<String, Position>,
    keys: HashMap<String, Position>,
}

enum Frame {
    Map { path: String, key: Option<String> },
    Seq { path: String, index: usize },
}

fn join_key(parent: &str, key: &str) -> String {
    if parent.is_empty() {
        key.to_string()
    } else {
        format!("{parent}.{key}")
    }
}

impl Locator {
    /// Indexes `text`; a document that does not parse gives an empty index (the deserialiser reports the
    /// syntax error itself).
    pub(crate) fn new(text: &str) -> Self {
        let mut values = HashMap::new();
        let mut keys = HashMap::new();
        let mut stack: Vec<Frame> = Vec::new();
        for item in Parser::new_from_str(text) {
            let Ok((event, span)) = item else {
                break;
            };
            let pos = Position {
                line: span.start.line(),
                column: span.start.col() + 1,
            };
            let is_node = matches!(
                event,
                Event::Scalar(..)
                    | Event::MappingStart(..)
                    | Event::SequenceStart(..)
                    | Event::Alias(..)
            );
            if is_node {
                // The path of this node, or None if it is a mapping key.
                let path = match stack.last_mut() {
                    None => Some(String::new()),
                    Some(Frame::Map { path, key }) => match key.take() {
                        None => {
                            let k = match &event {
                                Event::Scalar(v, ..) => v.to_string(),
                                _ => "?".to_string(),
                            };
                            keys.entry(join_key(path, &k)).or_insert(pos);
                            *key = Some(if k.len() > MAX_PATH_KEY_BYTES {
                                "…".to_string()
                            } else {
                                k
                            });
                            None
                        }
                        Some(k) => Some(join_key(path, &k)),
                    },
                    Some(Frame::Seq { path, index }) => {
                        *index += 1;
                        Some(format!("{path}[{}]", *index - 1))
                    }
                };
                // A key just recorded: keep it pending until its value arrives.
                let Some(path) = path else {
                    continue;
                };
                values.insert(path.clone(), pos);
                match event {
                    Event::MappingStart(..) => stack.push(Frame::Map { path, key: None }),
                    Event::SequenceStart(..) => stack.push(Frame::Seq { path, index: 0 }),
                    _ => {}
                }
            } else if matches!(event, Event::MappingEnd | Event::SequenceEnd) {
                stack.pop();
            }
        }
        Self { values, keys }
    }

    /// The position of the key of the mapping entry `path`, if the document has that entry.
    pub(crate) fn key(&self, path: &str) -> Option<Position> {
        self.keys.get(path).copied()
    }

    /// The position of `path`'s value, if the document has that field.
    pub(crate) fn get(&self, path: &str) -> Option<Position> {
        self.values.get(path).copied()
    }

    /// The position of `path`'s value, or of the nearest enclosing field that exists (so an error about a
    /// missing field points at its parent), or line 1 column 1.
    pub(crate) fn find(&self, path: &str) -> Position {
        let mut p = path;
        loop {
            if let Some(pos) = self.values.get(p) {
                return *pos;
            }
            match p.rfind(['.', '[']) {
                Some(i) => p = &p[..i],
                None => {
                    return self
                        .values
                        .get("")
                        .copied()
                        .unwrap_or(Position { line: 1, column: 1 });
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Positions are read off the literal below by eye (1-based lines and columns).
    #[test]
    fn finds_nested_fields_and_falls_back_to_parents() {
        let text = "units: SI\npatches:\n  - name: a\n    arc:\n      radius: 2\n  - name: b\n    line: {from: [0, 0, 0], to: [1, 0, 0]}\n";
        let loc = Locator::new(text);
        assert_eq!(loc.find("units"), Position { line: 1, column: 8 });
        assert_eq!(
            loc.find("patches[0].name"),
            Position {
                line: 3,
                column: 11
            }
        );
        assert_eq!(
            loc.find("patches[0].arc.radius"),
            Position {
                line: 5,
                column: 15
            }
        );
        assert_eq!(
            loc.find("patches[1].line.to[0]"),
            Position {
                line: 7,
                column: 34
            }
        );
        // Missing field: the nearest existing parent.
        assert_eq!(
            loc.find("patches[0].arc.center"),
            Position { line: 5, column: 7 }
        );
        assert_eq!(loc.find("nope.deeper"), Position { line: 1, column: 1 });
    }
}
