//! Fuzzing the design path (issue 7): every design in `designs/` and the two bases of the broken designs,
//! mutated the way a designer's typo or a half-saved file mutates them — a line deleted, duplicated or swapped
//! with the next, a scalar replaced by a token (`nan`, `.inf`, `-1`, `0`, `1e308`, `100000000`, a word, an
//! empty value, brackets…), the indentation of a line shifted, the file truncated — then read, validated and,
//! when the design builds and is small, discretised (`Simulation::new`).
//!
//! The properties: nothing panics; a rejected design gets an error whose message is non-empty and starts with
//! the file's name (the designer's editor can jump to it); a simulation that cannot be set up says why. The
//! test would fail on any panic in serde_yaml's or saphyr's handling of broken text, in the locator, in the
//! model builder (an index or an allocation that trusts a number) or in the discretisation, and on an empty or
//! unlocated error.
//!
//! Cases: [`CASES`] from a fixed seed (about 10 s in release); `PROPTEST_CASES` and `PROPTEST_RNG_SEED` override
//! them for longer runs (a 20 000-case run was made while writing it, see docs/when-things-go-wrong.md).

use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use stentkit::design::{DesignError, parse_design};
use stentkit::solver::Simulation;

/// Cases per run of the test.
const CASES: u32 = 600;

/// Largest model (unknowns) that is also discretised: `Simulation::new` analyses the sparsity pattern, which
/// for the stents takes a noticeable fraction of a second.
const SIMULATE_BELOW_UNKNOWNS: usize = 20_000;

/// What replaces a scalar.
const TOKENS: &[&str] = &[
    "nan",
    ".nan",
    ".inf",
    "-.inf",
    "-1",
    "0",
    "1",
    "2",
    "0.5",
    "-0.0",
    "1e308",
    "-1e308",
    "1e-308",
    "100000000",
    "18446744073709551616",
    "abc",
    "free",
    "''",
    "~",
    "[]",
    "{}",
    "[1, 2]",
    "[[0, 1], [0, 2]]",
    "\"",
    ":",
    "- x",
    "true",
    "&a",
    "*a",
];

/// The files mutated: every design and the bases of the broken designs.
fn sources() -> Vec<(PathBuf, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<PathBuf> = std::fs::read_dir(root.join("designs"))
        .expect("designs/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    files.sort();
    files.push(root.join("tests/data/good_small.yaml"));
    files.push(root.join("tests/data/good_stent_small.yaml"));
    files
        .into_iter()
        .map(|f| {
            let text = std::fs::read_to_string(&f).expect("readable design");
            (f, text)
        })
        .collect()
}

/// One mutation, its numbers to be reduced modulo the sizes of the text they apply to.
#[derive(Debug, Clone)]
enum Mutation {
    DeleteLine(usize),
    DuplicateLine(usize),
    SwapWithNext(usize),
    /// Replace the k-th scalar (a number or a word) of a line by a token.
    ReplaceScalar {
        line: usize,
        scalar: usize,
        token: usize,
    },
    /// Shift a line's indentation by −4…+4 spaces.
    Indent(usize, i8),
    /// Keep this fraction (in thousandths) of the text.
    Truncate(u16),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        1 => any::<usize>().prop_map(Mutation::DeleteLine),
        1 => any::<usize>().prop_map(Mutation::DuplicateLine),
        1 => any::<usize>().prop_map(Mutation::SwapWithNext),
        4 => (any::<usize>(), any::<usize>(), any::<usize>()).prop_map(|(line, scalar, token)| {
            Mutation::ReplaceScalar {
                line,
                scalar,
                token,
            }
        }),
        1 => (any::<usize>(), -4i8..=4).prop_map(|(l, d)| Mutation::Indent(l, d)),
        1 => (0u16..1000).prop_map(Mutation::Truncate),
    ]
}

/// Byte ranges of the scalars of a line: runs of characters other than YAML punctuation and spaces, after
/// the comment is cut off.
fn scalars(line: &str) -> Vec<(usize, usize)> {
    let code = line.split(" #").next().unwrap_or(line);
    let mut out = Vec::new();
    let mut start = None;
    for (i, c) in code.char_indices() {
        let part = !(c.is_whitespace() || "[]{},:#".contains(c));
        match (part, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push((s, i));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, code.len()));
    }
    out
}

/// Applies `m` to `text`.
fn apply(text: &str, m: &Mutation) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let n = lines.len().max(1);
    match *m {
        Mutation::DeleteLine(k) => {
            if !lines.is_empty() {
                lines.remove(k % n);
            }
        }
        Mutation::DuplicateLine(k) => {
            if !lines.is_empty() {
                let l = lines[k % n].clone();
                lines.insert(k % n, l);
            }
        }
        Mutation::SwapWithNext(k) => {
            if lines.len() >= 2 {
                let k = k % (lines.len() - 1);
                lines.swap(k, k + 1);
            }
        }
        Mutation::ReplaceScalar {
            line,
            scalar,
            token,
        } => {
            // Only lines that have scalars count, so every case changes a value.
            let candidates: Vec<usize> = (0..lines.len())
                .filter(|&i| !scalars(&lines[i]).is_empty())
                .collect();
            if !candidates.is_empty() {
                let i = candidates[line % candidates.len()];
                let found = scalars(&lines[i]);
                let (a, b) = found[scalar % found.len()];
                lines[i].replace_range(a..b, TOKENS[token % TOKENS.len()]);
            }
        }
        Mutation::Indent(k, d) => {
            if !lines.is_empty() {
                let l = &mut lines[k % n];
                if d >= 0 {
                    l.insert_str(0, &" ".repeat(d as usize));
                } else {
                    let strip = l
                        .chars()
                        .take(d.unsigned_abs() as usize)
                        .take_while(|&c| c == ' ')
                        .count();
                    l.replace_range(..strip, "");
                }
            }
        }
        Mutation::Truncate(per_mille) => {
            let mut cut = text.len() * per_mille as usize / 1000;
            while !text.is_char_boundary(cut) {
                cut -= 1;
            }
            return text[..cut].to_string();
        }
    }
    let mut out = lines.join("\n");
    out.push('\n');
    out
}

/// Reads, validates and (when small) discretises `text`; `Err` describes a broken property.
fn check(text: &str, path: &Path) -> Result<&'static str, String> {
    let outcome = catch_unwind(AssertUnwindSafe(|| match parse_design(text, path) {
        Err(e) => Err(e),
        Ok(design) => {
            let model = &design.model;
            if model.num_unknowns() >= SIMULATE_BELOW_UNKNOWNS {
                return Ok(Ok("accepted (large, not discretised)"));
            }
            Ok(match Simulation::new(model) {
                Ok(_) => Ok("accepted and discretised"),
                Err(e) => Err(e.to_string()),
            })
        }
    }));
    match outcome {
        Err(panic) => {
            let why = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            Err(format!("panicked: {why}"))
        }
        Ok(Err(e)) => {
            let message = e.to_string();
            let prefix = format!("{}:", path.display());
            match &e {
                DesignError::Invalid { message: m, .. } if m.trim().is_empty() => {
                    Err(format!("empty message: `{message}`"))
                }
                _ if !message.starts_with(&prefix) => {
                    Err(format!("error does not start with the file: `{message}`"))
                }
                _ => Ok("rejected"),
            }
        }
        Ok(Ok(Err(sim))) if sim.trim().is_empty() => Err("empty simulation error".into()),
        Ok(Ok(Err(_))) => Ok("accepted, simulation refused"),
        Ok(Ok(Ok(what))) => Ok(what),
    }
}

fn config() -> Config {
    let base = Config::default();
    Config {
        cases: if std::env::var_os("PROPTEST_CASES").is_some() {
            base.cases
        } else {
            CASES
        },
        rng_seed: if std::env::var_os("PROPTEST_RNG_SEED").is_some() {
            base.rng_seed
        } else {
            RngSeed::Fixed(0x4953_5355_4537)
        },
        // Mutating a file never panics the strategy; failures are reported with the mutated text.
        failure_persistence: None,
        ..base
    }
}

#[test]
fn unmutated_designs_are_accepted() {
    // The fuzz starts from valid files: were one of them rejected, every mutation would test nothing new.
    for (path, text) in sources() {
        parse_design(&text, &path)
            .unwrap_or_else(|e| panic!("{} should be valid: {e}", path.display()));
    }
}

/// Mutations that once panicked, kept as fixed cases: `(design, line fragment, replacement)`.
const REGRESSIONS: &[(&str, &str, &str)] = &[
    // A crown rotation of 1e308° lost all precision in the angles: a bridge found no facing trough and the
    // generator panicked (`retained trough`). Rotations are now reduced modulo 360°, and a crest facing no
    // trough is an error.
    (
        "straight_stent.yaml",
        "rotation_deg: 90",
        "rotation_deg: 1e308",
    ),
    (
        "straight_stent.yaml",
        "rotation_deg: 90",
        "rotation_deg: 1e17",
    ),
];

#[test]
fn mutations_that_once_panicked_are_handled() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs");
    for (file, from, to) in REGRESSIONS {
        let path = root.join(file);
        let text = std::fs::read_to_string(&path).expect("design");
        assert!(text.contains(from), "{file}: `{from}`");
        let mutated = text.replacen(from, to, 1);
        if let Err(why) = check(&mutated, &path) {
            panic!("{file} with `{to}`: {why}");
        }
    }
}

#[test]
fn mutated_designs_never_panic_and_every_rejection_names_the_file() {
    let sources = sources();
    let counts = std::sync::Mutex::new(std::collections::BTreeMap::<&'static str, usize>::new());
    let mut runner = proptest::test_runner::TestRunner::new(config());
    let strategy = (
        0..sources.len(),
        proptest::collection::vec(mutation(), 1..=3),
    );
    let result = runner.run(&strategy, |(file, mutations)| {
        let (path, text) = &sources[file];
        let mutated = mutations.iter().fold(text.clone(), |t, m| apply(&t, m));
        match check(&mutated, path) {
            Ok(what) => {
                *counts.lock().expect("counts").entry(what).or_default() += 1;
                Ok(())
            }
            Err(why) => Err(TestCaseError::fail(format!(
                "{} after {mutations:?}: {why}\n--- mutated text ---\n{mutated}",
                path.display()
            ))),
        }
    });
    let counts = counts.into_inner().expect("counts");
    println!("fuzzed designs: {counts:?}");
    if let Err(e) = result {
        panic!("{e}");
    }
    // The mutations must exercise both sides: many rejections, and designs that still build.
    let total: usize = counts.values().sum();
    assert!(
        counts.get("rejected").copied().unwrap_or(0) > total / 10,
        "{counts:?}"
    );
    assert!(
        counts.get("accepted and discretised").copied().unwrap_or(0) > total / 10,
        "{counts:?}"
    );
}
