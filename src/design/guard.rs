//! Limits checked on a design's text before any YAML parser sees it: its size, its nesting depth and its
//! aliases. Each limit is far beyond what a real design needs and far below what makes reading it expensive.
//!
//! **Why before parsing.** Measured on this machine with the parsers stentkit uses (release build):
//! - serde_yaml's scanner (libyaml) is quadratic in the depth of flow nesting: a `name:` of 10 000 nested `[`
//!   took 0.28 s, 30 000 took 2.2 s, and a 200 kB design of 100 000 took 21.5 s (about a minute on a busy
//!   machine), before failing on its own recursion limit.
//! - Block nesting (`- - - - …` on one line) is linear in both parsers, but the field-position index
//!   ([`super::locate`]) stores one path per node, and a path is as long as the node is deep: 30 000 levels took
//!   8 s and 2.7 GB.
//! - An alias (`*name`) repeats the anchored node each time it is used, in serde_yaml's deserialiser and in the
//!   design built from it. serde_yaml stops exponential "billion laughs" (its repetition limit, 15 ms) but not
//!   linear repetition: a 40 kB design whose `patches` list repeats a 1000-point patch 10 000 times took 1.5 s
//!   and 250 MB before the first check ran; a 4 MiB one would need about 25 GB.
//! - Parsing costs about 40 bytes of memory per byte of YAML (serde_yaml's event buffer and the position
//!   index): a 19 MB design took 4.4 s and 750 MB to reach its first check.
//!
//! The scan here is a single pass over the text, linear in its length (100 000 levels of flow or block
//! nesting are refused in about a millisecond). It is a deliberately simple YAML lexer: it tracks quoted and
//! block scalars, comments, plain multi-line scalars, flow collections and block indentation, and counts
//! nesting as the parsers do (the root mapping is level 1). Where it cannot tell, it counts a level more,
//! never fewer: every design and test file's depth from it equals the parser's (a unit test checks).
//!
//! **Aliases are refused, all of them.** A design is a few kilobytes written by hand; no design in the
//! repository uses an alias, and writing a repeated table out costs a few lines. An expansion budget would need
//! the parser's event stream (so it could not run before the parser), and still let each design repeat
//! something up to the budget. Anchors (`&name`) alone are harmless and accepted.

use super::locate::Position;

/// Largest design file stentkit reads \[bytes\]: 4 MiB. The largest design in the repository
/// (`designs/curved_stent.yaml`) has 4.4 kB; a point-list centreline of 10 000 points or a measured
/// temperature table of 100 000 rows still fits (about 400 kB and 2 MB). Reading a design of this size takes
/// about 0.8 s and 170 MB (about 40 bytes of memory per byte of YAML, measured), so the limit also bounds what
/// merely reading a design can cost.
pub(crate) const MAX_DESIGN_BYTES: usize = 4 * 1024 * 1024;

/// Deepest nesting of mappings and sequences a design may have: 32 levels, the root mapping being level 1.
/// The format itself needs at most 6 (`conditions[k].displacement[i]` given as a table `[[t, v], …]`: root,
/// `conditions`, the entry, `displacement`, the table, a row). At 32 levels the parsers' quadratic terms
/// cost nothing.
pub(crate) const MAX_NESTING_DEPTH: usize = 32;

/// Why a design's text is refused before parsing, and where.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Refusal {
    /// Where the limit is exceeded.
    pub position: Position,
    /// What is wrong and what is allowed.
    pub message: String,
}

/// The refusal of a design of `bytes` bytes (more than [`MAX_DESIGN_BYTES`]), reported at its start.
pub(crate) fn too_large(bytes: u64) -> Refusal {
    let size = format!(
        "{bytes} bytes ({:.1} MiB)",
        bytes as f64 / (1024.0 * 1024.0)
    );
    Refusal {
        position: Position { line: 1, column: 1 },
        message: format!(
            "the design is {size}, more than stentkit's limit of {} MiB ({MAX_DESIGN_BYTES} bytes) for a design file; a design is a few kB, and a long point list or table still fits",
            MAX_DESIGN_BYTES / (1024 * 1024)
        ),
    }
}

/// Checks a design's text against [`MAX_DESIGN_BYTES`] and [`MAX_NESTING_DEPTH`] and refuses aliases, in one
/// pass linear in the text's length.
///
/// # Errors
/// [`Refusal`] at the start of the text for its size, at the bracket, dash or key that opens the first level
/// beyond the limit, or at the first alias.
pub(crate) fn check_text(text: &str) -> Result<(), Refusal> {
    if text.len() > MAX_DESIGN_BYTES {
        return Err(too_large(text.len() as u64));
    }
    scan(text, MAX_NESTING_DEPTH).map(|_| ())
}

/// The deepest nesting of `text` as the scan counts it, refusing depths beyond `limit` and aliases.
fn scan(text: &str, limit: usize) -> Result<usize, Refusal> {
    let mut scanner = Scanner {
        text,
        limit,
        blocks: Vec::new(),
        flow: 0,
        flow_at_start: true,
        flow_key_column: 0,
        flow_peak: 0,
        pending: Pending::None,
        deepest: 0,
        line_start: 0,
        line_number: 0,
    };
    let body = text.strip_prefix('\u{feff}').unwrap_or(text);
    let offset = text.len() - body.len();
    let mut start = offset;
    for line in body.split('\n') {
        scanner.line_start = start;
        scanner.line_number += 1;
        start += line.len() + 1;
        let line = line.strip_suffix('\r').unwrap_or(line);
        scanner.line(line.as_bytes())?;
    }
    Ok(scanner.deepest)
}

/// A construct that continues on the next line.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Pending {
    None,
    /// Inside a quoted scalar (double-quoted when `true`).
    Quoted(bool),
    /// Inside a block scalar (`|` or `>`) whose owner is at column `parent`; its content indentation once known.
    BlockScalar {
        parent: isize,
        content: Option<usize>,
    },
    /// After a plain scalar in block context owned by column `parent`: more indented lines continue it.
    Plain {
        parent: isize,
    },
}

/// An open block collection: its column and whether it is a sequence.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Block {
    column: usize,
    sequence: bool,
}

struct Scanner<'a> {
    text: &'a str,
    limit: usize,
    /// Open block collections, outermost first.
    blocks: Vec<Block>,
    /// Open flow collections.
    flow: usize,
    /// In flow context: whether the next character starts a node (after `[`, `{`, `,`, `:` or `?`).
    flow_at_start: bool,
    /// Column where the outermost flow collection of the current line began (a flow collection can be a key).
    flow_key_column: usize,
    /// Deepest flow level since that collection began: were it a key, its mapping adds a level to all of them.
    flow_peak: usize,
    pending: Pending,
    deepest: usize,
    /// Byte offset of the current line in `text`.
    line_start: usize,
    line_number: usize,
}

fn is_blank(b: u8) -> bool {
    b == b' ' || b == b'\t'
}

/// Whether `line[i]` is a blank or the end of the line.
fn blank_or_end(line: &[u8], i: usize) -> bool {
    line.get(i).is_none_or(|&b| is_blank(b))
}

fn skip_blanks(line: &[u8], mut i: usize) -> usize {
    while i < line.len() && is_blank(line[i]) {
        i += 1;
    }
    i
}

/// The index of the quote that closes a scalar opened before `from` (`"` when `double`, else `'`), if it is
/// on this line. `\` escapes in double quotes; `''` is a quote inside single quotes.
fn quote_end(line: &[u8], from: usize, double: bool) -> Option<usize> {
    let mut i = from;
    while i < line.len() {
        match (line[i], double) {
            (b'\\', true) => i += 2,
            (b'"', true) => return Some(i),
            (b'\'', false) if line.get(i + 1) == Some(&b'\'') => i += 2,
            (b'\'', false) => return Some(i),
            _ => i += 1,
        }
    }
    None
}

/// If the node at `pos` (not a flow collection) is an implicit key, the index of its `:`.
fn implicit_key(line: &[u8], pos: usize) -> Option<usize> {
    let mut i = match line[pos] {
        q @ (b'"' | b'\'') => skip_blanks(line, quote_end(line, pos + 1, q == b'"')? + 1),
        _ => pos,
    };
    if i > pos {
        return (line.get(i) == Some(&b':') && blank_or_end(line, i + 1)).then_some(i);
    }
    while i < line.len() {
        match line[i] {
            b':' if blank_or_end(line, i + 1) => return Some(i),
            b'#' if i > pos && is_blank(line[i - 1]) => return None,
            _ => i += 1,
        }
    }
    None
}

impl Scanner<'_> {
    fn position(&self, index: usize) -> Position {
        let line = &self.text[self.line_start..];
        let column = line.char_indices().take_while(|&(i, _)| i < index).count() + 1;
        Position {
            line: self.line_number,
            column,
        }
    }

    /// Records one more level opened at `index`; refuses it beyond the limit.
    fn deeper(&mut self, index: usize) -> Result<(), Refusal> {
        let depth = self.blocks.len() + self.flow;
        self.deepest = self.deepest.max(depth);
        if depth > self.limit {
            return Err(Refusal {
                position: self.position(index),
                message: format!(
                    "nesting {depth} levels deep here, deeper than stentkit's limit of {} levels: a design needs at most 6 (a table in a condition); deeper YAML is refused before parsing because the parser's cost grows with the square of the depth",
                    self.limit
                ),
            });
        }
        Ok(())
    }

    fn alias(&self, index: usize) -> Refusal {
        Refusal {
            position: self.position(index),
            message: "aliases (`*name`) are not allowed in a design: write the value out (an alias repeats a node wherever it is used, so a small file could stand for an enormous design)".to_string(),
        }
    }

    fn push_block(&mut self, column: usize, sequence: bool) -> Result<(), Refusal> {
        let block = Block { column, sequence };
        if self.blocks.last() == Some(&block) {
            return Ok(());
        }
        self.blocks.push(block);
        self.deeper(column)
    }

    fn line(&mut self, line: &[u8]) -> Result<(), Refusal> {
        let indent = line.iter().take_while(|&&b| b == b' ').count();
        let blank = line[indent..].iter().all(|&b| is_blank(b));
        let mut from = None;
        match self.pending {
            Pending::None => {}
            Pending::Quoted(double) => match quote_end(line, 0, double) {
                None => return Ok(()),
                Some(end) => {
                    self.pending = Pending::None;
                    from = Some(end + 1);
                }
            },
            Pending::BlockScalar { parent, content } => {
                if blank {
                    return Ok(());
                }
                match content {
                    None if indent as isize > parent => {
                        self.pending = Pending::BlockScalar {
                            parent,
                            content: Some(indent),
                        };
                        return Ok(());
                    }
                    Some(c) if indent >= c => return Ok(()),
                    _ => self.pending = Pending::None,
                }
            }
            Pending::Plain { parent } => {
                if blank {
                    return Ok(());
                }
                if line[indent] != b'#' && indent as isize > parent {
                    return Ok(());
                }
                self.pending = Pending::None;
            }
        }
        if let Some(from) = from {
            // The rest of a line that closed a quoted scalar.
            return if self.flow > 0 {
                self.flow_at_start = false;
                self.flow_lex(line, from)
            } else {
                self.flow_peak = 0;
                self.after_node(line, from)
            };
        }
        if self.flow > 0 {
            return self.flow_lex(line, 0);
        }
        if blank || line[indent] == b'#' {
            return Ok(());
        }
        if indent == 0
            && (line.starts_with(b"---") || line.starts_with(b"..."))
            && blank_or_end(line, 3)
        {
            self.blocks.clear();
            return self.block_node(line, 3);
        }
        if indent == 0 && line[0] == b'%' {
            return Ok(());
        }
        while self.blocks.last().is_some_and(|b| b.column > indent) {
            self.blocks.pop();
        }
        let entry = line[indent] == b'-' && blank_or_end(line, indent + 1);
        if !entry {
            // A block sequence may sit at its mapping key's column; a key there ends it.
            while self
                .blocks
                .last()
                .is_some_and(|b| b.column == indent && b.sequence)
            {
                self.blocks.pop();
            }
        }
        self.block_node(line, indent)
    }

    /// A node starting at `pos` in block context: compact entries (`- `, `? `), properties, a key, a value.
    fn block_node(&mut self, line: &[u8], mut pos: usize) -> Result<(), Refusal> {
        loop {
            pos = skip_blanks(line, pos);
            let Some(&c) = line.get(pos) else {
                return Ok(());
            };
            match c {
                b'#' => return Ok(()),
                b'-' | b'?' if blank_or_end(line, pos + 1) => {
                    self.push_block(pos, c == b'-')?;
                    pos += 1;
                }
                b':' if blank_or_end(line, pos + 1) => pos += 1,
                b'&' | b'!' => {
                    while pos < line.len() && !is_blank(line[pos]) {
                        pos += 1;
                    }
                }
                b'*' => return Err(self.alias(pos)),
                b'[' | b'{' => return self.flow_start(line, pos),
                _ => {
                    if let Some(colon) = implicit_key(line, pos) {
                        self.push_block(pos, false)?;
                        return self.value(line, colon + 1, pos as isize);
                    }
                    let owner = self.blocks.last().map_or(-1, |b| b.column as isize);
                    return self.value(line, pos, owner);
                }
            }
        }
    }

    /// A value at `pos` in block context whose owner (key or entry) is at column `owner`.
    fn value(&mut self, line: &[u8], pos: usize, owner: isize) -> Result<(), Refusal> {
        let mut pos = skip_blanks(line, pos);
        while let Some(b'&' | b'!') = line.get(pos) {
            while pos < line.len() && !is_blank(line[pos]) {
                pos += 1;
            }
            pos = skip_blanks(line, pos);
        }
        let Some(&c) = line.get(pos) else {
            return Ok(());
        };
        match c {
            b'#' => Ok(()),
            b'*' => Err(self.alias(pos)),
            b'[' | b'{' => self.flow_start(line, pos),
            b'"' | b'\'' => match quote_end(line, pos + 1, c == b'"') {
                None => {
                    self.pending = Pending::Quoted(c == b'"');
                    Ok(())
                }
                Some(end) => {
                    self.flow_key_column = pos;
                    self.flow_peak = 0;
                    self.after_node(line, end + 1)
                }
            },
            b'|' | b'>' => {
                self.pending = Pending::BlockScalar {
                    parent: owner,
                    content: None,
                };
                Ok(())
            }
            // Not valid after a key, but counted rather than skipped.
            b'-' | b'?' if blank_or_end(line, pos + 1) => self.block_node(line, pos),
            _ => {
                self.pending = Pending::Plain { parent: owner };
                Ok(())
            }
        }
    }

    /// A flow collection starting at `pos` in block context.
    fn flow_start(&mut self, line: &[u8], pos: usize) -> Result<(), Refusal> {
        self.flow_key_column = pos;
        self.flow_peak = 0;
        self.flow_at_start = true;
        self.flow_lex(line, pos)
    }

    /// The rest of a line after a complete flow collection or quoted scalar in block context: a `:` makes that
    /// node a key, whose mapping encloses the levels the node opened.
    fn after_node(&mut self, line: &[u8], pos: usize) -> Result<(), Refusal> {
        let pos = skip_blanks(line, pos);
        if line.get(pos) == Some(&b':') && blank_or_end(line, pos + 1) {
            let column = self.flow_key_column.min(pos);
            self.push_block(column, false)?;
            let peak = std::mem::take(&mut self.flow_peak);
            if peak > 0 {
                self.flow += peak;
                let deeper = self.deeper(column);
                self.flow -= peak;
                deeper?;
            }
            return self.value(line, pos + 1, column as isize);
        }
        Ok(())
    }

    /// Flow context from `pos` to the end of the line.
    fn flow_lex(&mut self, line: &[u8], pos: usize) -> Result<(), Refusal> {
        let mut at_start = self.flow_at_start;
        // After a quoted scalar or a closed collection a `:` is an indicator even when no blank follows.
        let mut after_json = false;
        let mut i = pos;
        while i < line.len() {
            let c = line[i];
            let blank_before = i == 0 || is_blank(line[i - 1]);
            match c {
                b' ' | b'\t' => {
                    i += 1;
                    continue;
                }
                b'#' if blank_before => break,
                b'[' | b'{' => {
                    self.flow += 1;
                    self.flow_peak = self.flow_peak.max(self.flow);
                    self.deeper(i)?;
                    at_start = true;
                    after_json = false;
                }
                b']' | b'}' => {
                    self.flow = self.flow.saturating_sub(1);
                    at_start = false;
                    after_json = true;
                    if self.flow == 0 {
                        self.flow_at_start = true;
                        return self.after_node(line, i + 1);
                    }
                }
                b',' => {
                    at_start = true;
                    after_json = false;
                }
                b'"' | b'\'' if at_start => match quote_end(line, i + 1, c == b'"') {
                    None => {
                        self.pending = Pending::Quoted(c == b'"');
                        self.flow_at_start = false;
                        return Ok(());
                    }
                    Some(end) => {
                        i = end;
                        at_start = false;
                        after_json = true;
                    }
                },
                b'*' if at_start => return Err(self.alias(i)),
                b'&' | b'!' if at_start => {
                    while i + 1 < line.len()
                        && !is_blank(line[i + 1])
                        && !b",[]{}".contains(&line[i + 1])
                    {
                        i += 1;
                    }
                }
                b':' if after_json
                    || line
                        .get(i + 1)
                        .is_none_or(|&b| is_blank(b) || b",[]{}".contains(&b)) =>
                {
                    at_start = true;
                    after_json = false;
                }
                b'?' if at_start && blank_or_end(line, i + 1) => {}
                _ => {
                    at_start = false;
                    after_json = false;
                }
            }
            i += 1;
        }
        self.flow_at_start = at_start;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use saphyr_parser::{Event, Parser};
    use std::path::Path;

    /// The nesting depth the YAML parser (saphyr, the one the position index uses) reports, the root being 1,
    /// up to the end or its first syntax error (then also `false`).
    fn parser_depth_to_error(text: &str) -> (usize, bool) {
        let (mut depth, mut deepest) = (0usize, 0usize);
        for item in Parser::new_from_str(text) {
            let Ok((event, _)) = item else {
                return (deepest, false);
            };
            match event {
                Event::SequenceStart(..) | Event::MappingStart(..) => {
                    depth += 1;
                    deepest = deepest.max(depth);
                }
                Event::SequenceEnd | Event::MappingEnd => depth -= 1,
                _ => {}
            }
        }
        (deepest, true)
    }

    fn parser_depth(text: &str) -> usize {
        parser_depth_to_error(text).0
    }

    fn yaml_files() -> Vec<std::path::PathBuf> {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = Vec::new();
        for dir in ["designs", "tests/data", "tests/data/bad_designs"] {
            for entry in std::fs::read_dir(root.join(dir)).expect("folder") {
                let path = entry.expect("entry").path();
                if path.extension().is_some_and(|e| e == "yaml") {
                    files.push(path);
                }
            }
        }
        files.sort();
        files
    }

    // Reference: saphyr's event stream. The scan must never count fewer levels than the parser (it would let
    // deep input through), and on real designs it counts exactly as many (so the limit means what it says).
    #[test]
    fn the_scan_counts_the_parsers_depth_on_every_design_and_test_file() {
        let mut checked = 0;
        for path in yaml_files() {
            let text = std::fs::read_to_string(&path).expect("readable");
            let (expected, parsed) = parser_depth_to_error(&text);
            match scan(&text, usize::MAX) {
                // A file with a syntax error is compared up to the error only.
                Ok(depth) if !parsed => assert!(depth >= expected, "{}", path.display()),
                Ok(depth) => {
                    assert_eq!(depth, expected, "{}", path.display());
                    checked += 1;
                }
                // Only the broken designs that exist to be refused here may be.
                Err(r) => assert!(
                    path.to_string_lossy().contains("bad_designs"),
                    "{}: {r:?}",
                    path.display()
                ),
            }
        }
        assert!(checked > 50, "{checked} files");
    }

    // Hand-made cases; the expected depth is read off each text (root mapping = 1) and agrees with saphyr.
    #[test]
    fn quoted_block_and_plain_scalars_hide_their_brackets() {
        let cases: &[(&str, usize)] = &[
            ("a: [[1, 2], [3, 4]]\n", 3),
            ("a:\n- - - x\n", 4),
            ("a:\n  - b: 1\n    c: [1, {d: 2}]\n", 5),
            ("a: \"[[[[\"\nb: '{{{{ '' ]]'\n", 1),
            ("a: |\n  [[[[[[\n    - - - -\nb: 1\n", 1),
            ("a: >-\n\n  {{{{\n  - - -\nb: [1]\n", 2),
            ("a: some [text\n  [[[[ more text\nb: 1\n", 1),
            ("a: [1, # ]]]]\n  [2]]\n", 3),
            ("a: [\"]]]\", '[[[']\n", 2),
            ("a: x#[[[[\n", 1),
            ("? [a, b]\n: c\n", 2),
            ("[a, b]: c\n", 2),
            ("\"k\": [1]\n", 2),
            ("a:\n  b:\n    c:\n      - [1]\n", 5),
            ("a: [it's, [x]]\n", 3),
            ("- - a: 1\n    b: 2\n", 3),
            ("a: 'multi\n  [[[[ line'\nb: [1]\n", 2),
        ];
        for &(text, depth) in cases {
            assert_eq!(scan(text, usize::MAX), Ok(depth), "{text:?}");
            assert_eq!(parser_depth(text), depth, "saphyr on {text:?}");
        }
    }

    // Positions read off the generated texts: the level beyond the limit opens at the limit-th bracket after
    // the root (column 4 + limit for `a: ` then brackets), or at the (limit)-th dash.
    #[test]
    fn deep_nesting_is_refused_where_it_passes_the_limit() {
        let flow = format!("a: {}{}\n", "[".repeat(100), "]".repeat(100));
        let e = scan(&flow, 32).expect_err("too deep");
        assert_eq!(
            e.position,
            Position {
                line: 1,
                column: 4 + 31
            }
        );
        assert!(e.message.contains("33 levels"), "{}", e.message);
        let mapping = format!("a: {}\n", "{b: ".repeat(100));
        let e = scan(&mapping, 32).expect_err("too deep");
        assert_eq!(
            e.position,
            Position {
                line: 1,
                column: 4 + 4 * 31
            }
        );
        let block = format!("a:\n{}x\n", "- ".repeat(100));
        let e = scan(&block, 32).expect_err("too deep");
        assert_eq!(
            e.position,
            Position {
                line: 2,
                column: 1 + 2 * 31
            }
        );
        let stairs: String = (0..40)
            .map(|k| format!("{}k{k}:\n", " ".repeat(k)))
            .collect();
        let e = scan(&stairs, 32).expect_err("too deep");
        assert_eq!(
            e.position,
            Position {
                line: 33,
                column: 33
            }
        );
        // Exactly at the limit: accepted.
        let at = format!("a: {}{}\n", "[".repeat(31), "]".repeat(31));
        assert_eq!(scan(&at, 32), Ok(32));
    }

    #[test]
    fn aliases_are_refused_at_the_alias_and_anchors_accepted() {
        assert_eq!(scan("a: &x [1, 2]\nb: 1\n", 32), Ok(2));
        let e = scan("a: &x [1, 2]\nb: *x\n", 32).expect_err("alias");
        assert_eq!(e.position, Position { line: 2, column: 4 });
        let e = scan("a: &x 1\nb: [1, *x]\n", 32).expect_err("alias");
        assert_eq!(e.position, Position { line: 2, column: 8 });
        let e = scan("- &p {n: 1}\n- *p\n", 32).expect_err("alias");
        assert_eq!(e.position, Position { line: 2, column: 3 });
        // A star inside text is text.
        assert_eq!(scan("a: x *y\nb: \"*z\"\nc: |\n  *w\n", 32), Ok(1));
    }

    #[test]
    fn the_size_limit_is_checked_first() {
        let big = "#".repeat(MAX_DESIGN_BYTES + 1);
        let e = check_text(&big).expect_err("too large");
        assert_eq!(e.position, Position { line: 1, column: 1 });
        assert!(e.message.contains("4 MiB"), "{}", e.message);
        assert!(check_text(&"#".repeat(MAX_DESIGN_BYTES)).is_ok());
    }
}
