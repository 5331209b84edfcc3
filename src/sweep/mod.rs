//! Families of variants of one design (`stentkit sweep`): the swept parameters, the variants they make, the
//! sweep folder and the state of each variant as its files tell it — the same whether the variants ran on this
//! machine or as a Slurm job array.
//!
//! **Parameters.** `--set PATH=V1,V2,…` (YAML values, split at the commas outside brackets) or
//! `--set PATH=START:STOP:STEP` (numbers; STOP included when a whole number of steps reaches it, to 1e-9 of a
//! step). The variants are the cartesian product of the values, the first parameter varying slowest, or with
//! `--zip` the k-th values of every parameter together (the lists must be equally long).
//!
//! A path may be swept once: a second `--set` of the same path, or a later `--set` of a map that holds an
//! earlier swept path (`mesh.n=…` then `mesh={…}`), would run other values than the variant's row says
//! ([`Plan::new`] refuses both). A later `--set` inside an earlier one (`mesh={p: 6}` then `mesh.n=…`) changes
//! only what it names.
//!
//! **Folder.** `DIR/sweep.json` (the plan: the design file, the parameters, the variants with their
//! overrides), and per variant `DIR/variants/vNNN/`: `design.yaml` (the resolved design, `crate::design::set`),
//! `run/` (its run folder), `log.txt` (what its run printed) or `error.txt` (why its design was refused: a
//! variant the values make invalid is a failed row, not the end of the sweep). Nothing in DIR is removed by a
//! sweep: a rerun skips completed variants, continues interrupted or killed ones from their checkpoint, starts
//! those never started, and reruns failed ones only when asked (`--retry-failed`, which replaces only the files
//! that failed run wrote). A rerun must describe the same sweep: a different plan or a variant whose resolved
//! design changed (the design file was edited) is refused, and so is a `sweep.json` that no longer describes
//! its sweep (edited by hand: [`SweepDir::read_plan`]).
//!
//! **Preparation** ([`SweepDir::prepare`]) writes `sweep.json` first, then the variants' designs, every file
//! through a temporary renamed into place (`crate::io::atomic`; `sweep.json` synced to disk, the designs
//! not: a design a power loss left empty is written again): a preparation stopped by a signal (between two
//! variants) or killed outright leaves a folder the same command continues — it checks the designs already
//! written and writes the rest — and never half a file.
//!
//! **Stale temporaries.** A writer killed outright leaves its temporary, `.<name>.<pid>.<n>.tmp` beside the file
//! it was writing (io::atomic's name). A folder holding only temporaries of `sweep.json` is as good as empty
//! ([`SweepDir::check`]); the preparation removes the temporaries of the files it writes — `sweep.json` and
//! `sweep.csv` in the folder, `design.yaml` and `error.txt` in each variant's — and the collection those of
//! `sweep.csv` and of the charts (`collect::collect`); a variant's `run/` is a run folder, whose own
//! temporaries its run removes (`crate::io::run_folder`). Nothing else is removed, and a sweep folder has no
//! lock: one command at a time prepares or collects it (two at once could remove each other's temporary in
//! progress, and the later rename fails with an error naming the file).
//!
//! **Bench.** With `--bench radial` or `--bench crush` (`sweep.json`'s `bench`) every variant runs that bench
//! test of its design (`crate::bench`) instead of the design's own run: its `run/` is the bench's run folder,
//! with `bench.json`, whose smallest size reached and forces `sweep collect` adds as columns. A bench run
//! cannot be continued from a checkpoint: an interrupted variant runs again from the start.
//!
//! **State** of a variant ([`VariantState`]) is read from its files: `summary.json`'s status, or `error.txt`
//! (its design was refused), or `task_error.txt` (its run was refused before it wrote a summary), or nothing
//! yet.

pub mod collect;
pub(crate) mod disk;
pub(crate) mod metrics;
pub(crate) mod slurm;

use crate::design::set::{PathStep, parse_path, path_text};
use crate::design::{Design, DesignError, DesignOverrides, SetOverride, load_design_with};
use crate::io::atomic::{
    Durability, RemoveError, remove_stale_temporaries, temporary_target, write_file_atomically,
};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The plan file in a sweep folder.
pub const PLAN_FILE: &str = "sweep.json";

/// A variant's resolved design, in its folder.
const DESIGN_FILE: &str = "design.yaml";

/// Why a variant's design was refused, in its folder.
const ERROR_FILE: &str = "error.txt";

/// One swept parameter: a field path and its values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Parameter {
    /// The design's field path (`material.wlf.Tg`).
    pub path: String,
    /// The values as YAML text, in order.
    pub values: Vec<String>,
}

/// Why a sweep's arguments or folder were refused.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// A `--set` argument of the sweep is malformed.
    #[error("--set {argument}: {message}")]
    Parameter {
        /// The argument.
        argument: String,
        /// What is wrong.
        message: String,
    },
    /// The parameters do not make a sweep (none, `--zip` with lists of different lengths, too many variants).
    #[error("{0}")]
    Plan(String),
    /// The folder holds another sweep, or a variant's design changed since it was written.
    #[error("{dir}: {reason}")]
    Folder {
        /// The sweep folder.
        dir: PathBuf,
        /// Why it cannot be used.
        reason: String,
    },
    /// A value that would reach the batch script cannot be written into it safely (a control character).
    #[error("{0}")]
    Script(String),
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// The largest number of variants of one sweep (a Slurm array's default `MaxArraySize` is 1001).
pub const MAX_VARIANTS: usize = 10_000;

impl Parameter {
    /// Parses `PATH=V1,V2,…` or `PATH=START:STOP:STEP` (module docs).
    ///
    /// # Errors
    /// [`SweepError::Parameter`] naming the argument.
    pub fn parse(argument: &str) -> Result<Self, SweepError> {
        let fail = |message: String| SweepError::Parameter {
            argument: argument.to_string(),
            message,
        };
        let (path, values) = argument
            .split_once('=')
            .ok_or_else(|| fail("expected PATH=V1,V2,… or PATH=START:STOP:STEP".into()))?;
        let values = values.trim();
        let range: Vec<&str> = values.split(':').collect();
        let values = if range.len() == 3 && !values.starts_with(['[', '{', '"', '\'']) {
            let number = |s: &str| {
                s.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| fail(format!("`{s}` in START:STOP:STEP is not a number")))
            };
            range_values(number(range[0])?, number(range[1])?, number(range[2])?).map_err(fail)?
        } else {
            split_values(values)
        };
        if values.is_empty() || values.iter().any(|v| v.trim().is_empty()) {
            return Err(fail("give at least one value, none empty".into()));
        }
        // Each value must be a valid override (the path's syntax, the value's YAML).
        for v in &values {
            format!("{path}={v}")
                .parse::<SetOverride>()
                .map_err(|e| fail(e.message))?;
        }
        Ok(Self {
            path: path.trim().to_string(),
            values,
        })
    }

    /// The parameter as a `--set` argument (`mesh.n=20,22`), for messages.
    pub fn argument(&self) -> String {
        format!("{}={}", self.path, self.values.join(","))
    }
}

/// `START, START + STEP, …` up to STOP (included within 1e-9 of a step), each value printed with 12
/// significant digits so that `0.1:0.3:0.1` gives `0.1, 0.2, 0.3`.
fn range_values(start: f64, stop: f64, step: f64) -> Result<Vec<String>, String> {
    if step == 0.0 || (stop - start) * step < 0.0 {
        return Err(format!("STEP {step} does not lead from {start} to {stop}"));
    }
    // Counted in floating point: a tiny step's count overflows an integer (and wrapped to none).
    let counted = ((stop - start) / step + 1e-9).floor() + 1.0;
    if !(counted <= MAX_VARIANTS as f64) {
        return Err(format!(
            "about {} values: at most {MAX_VARIANTS}",
            crate::math::Short::rounded(counted, 3)
        ));
    }
    let count = counted as usize;
    Ok((0..count)
        .map(|k| {
            let x = start + k as f64 * step;
            let rounded: f64 = format!("{x:.11e}").parse().unwrap_or(x);
            crate::math::Short(rounded).to_string()
        })
        .collect())
}

/// Splits at the commas that are not inside brackets, braces or quotes.
fn split_values(text: &str) -> Vec<String> {
    let (mut values, mut current, mut depth, mut quote) = (Vec::new(), String::new(), 0i32, None);
    for c in text.chars() {
        match (c, quote) {
            ('"' | '\'', None) => quote = Some(c),
            (q, Some(open)) if q == open => quote = None,
            ('[' | '{', None) => depth += 1,
            (']' | '}', None) => depth -= 1,
            (',', None) if depth == 0 => {
                values.push(current.trim().to_string());
                current.clear();
                continue;
            }
            _ => {}
        }
        current.push(c);
    }
    values.push(current.trim().to_string());
    values
}

/// One variant: its folder name and the values of the parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Variant {
    /// Folder name, `v000`, `v001`, ….
    pub id: String,
    /// The value of each parameter (YAML text), in the parameters' order.
    pub values: Vec<String>,
}

/// A sweep: the design, its parameters and its variants (`sweep.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// The design file as given.
    pub design: PathBuf,
    /// The swept parameters.
    pub parameters: Vec<Parameter>,
    /// Paired lists instead of the cartesian product.
    pub zip: bool,
    /// The variants.
    pub variants: Vec<Variant>,
    /// The bench test each variant runs instead of its design's run (`stentkit sweep --bench`; module docs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bench: Option<crate::bench::Test>,
}

impl Plan {
    /// The variants of `parameters` (module docs) of the design at `design` (a parameter with one value is
    /// the same in every variant).
    ///
    /// # Errors
    /// [`SweepError::Plan`] for no parameters, `--zip` lists of different lengths or more than
    /// [`MAX_VARIANTS`] variants; [`SweepError::Parameter`] for a path swept twice or replaced by a later
    /// parameter (module docs).
    pub fn new(design: &Path, parameters: Vec<Parameter>, zip: bool) -> Result<Self, SweepError> {
        if parameters.is_empty() {
            return Err(SweepError::Plan(
                "give at least one swept parameter: --set PATH=V1,V2,… or PATH=START:STOP:STEP"
                    .into(),
            ));
        }
        check_paths(&parameters)?;
        let rows: Vec<Vec<String>> = if zip {
            let n = parameters[0].values.len();
            if let Some(p) = parameters.iter().find(|p| p.values.len() != n) {
                return Err(SweepError::Plan(format!(
                    "--zip pairs the k-th values: `{}` has {} values, `{}` has {n}",
                    p.path,
                    p.values.len(),
                    parameters[0].path
                )));
            }
            (0..n)
                .map(|k| parameters.iter().map(|p| p.values[k].clone()).collect())
                .collect()
        } else {
            let count = parameters
                .iter()
                .try_fold(1usize, |acc, p| acc.checked_mul(p.values.len()))
                .filter(|&c| c <= MAX_VARIANTS)
                .ok_or_else(|| SweepError::Plan(format!("more than {MAX_VARIANTS} variants")))?;
            (0..count)
                .map(|mut k| {
                    let mut row = vec![String::new(); parameters.len()];
                    for (i, p) in parameters.iter().enumerate().rev() {
                        row[i] = p.values[k % p.values.len()].clone();
                        k /= p.values.len();
                    }
                    row
                })
                .collect()
        };
        Ok(Self {
            design: design.to_path_buf(),
            parameters,
            zip,
            variants: rows
                .into_iter()
                .enumerate()
                .map(|(i, values)| Variant {
                    id: format!("v{i:03}"),
                    values,
                })
                .collect(),
            bench: None,
        })
    }

    /// Why this plan, read from a file, is not the one its own parameters make (a variant lost a value, an id
    /// was changed, a variant added or removed: `sweep.json` edited by hand), naming the field; `None` when it is.
    fn mismatch(&self) -> Option<String> {
        let expected = match Self::new(&self.design, self.parameters.clone(), self.zip) {
            Ok(plan) => plan,
            Err(e) => return Some(format!("parameters: {e}")),
        };
        if self.variants.len() != expected.variants.len() {
            return Some(format!(
                "variants: {} variants, where its parameters make {}",
                self.variants.len(),
                expected.variants.len()
            ));
        }
        let paths = || {
            self.parameters
                .iter()
                .map(|p| p.path.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        self.variants
            .iter()
            .zip(&expected.variants)
            .enumerate()
            .find_map(|(k, (v, e))| {
                if v.id != e.id {
                    Some(format!(
                        "variants[{k}].id: `{}`, expected `{}`",
                        v.id.escape_debug(),
                        e.id
                    ))
                } else if v.values.len() != self.parameters.len() {
                    Some(format!(
                        "variants[{k}].values: {} value{} for {} parameters ({})",
                        v.values.len(),
                        if v.values.len() == 1 { "" } else { "s" },
                        self.parameters.len(),
                        paths()
                    ))
                } else if v.values != e.values {
                    Some(format!(
                        "variants[{k}].values: {:?}, where its parameters give {:?}",
                        v.values, e.values
                    ))
                } else {
                    None
                }
            })
    }

    /// The `--set` overrides of variant `index`, in the parameters' order.
    pub fn overrides(&self, index: usize) -> Vec<String> {
        self.variants.get(index).map_or_else(Vec::new, |v| {
            self.parameters
                .iter()
                .zip(&v.values)
                .map(|(p, value)| format!("{}={value}", p.path))
                .collect()
        })
    }

    /// `Tg=65, diameter=0.6`: the variant's values labelled by the last key of each path.
    pub fn label(&self, index: usize) -> String {
        let Some(v) = self.variants.get(index) else {
            return String::new();
        };
        self.parameters
            .iter()
            .zip(&v.values)
            .map(|(p, value)| format!("{}={value}", short_name(&p.path)))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Refuses a path swept twice, or swept and then replaced by a later parameter that sets a map holding it
/// (module docs); paths are compared as parsed, so `patches[00].n` is `patches[0].n`.
fn check_paths(parameters: &[Parameter]) -> Result<(), SweepError> {
    let steps = parameters
        .iter()
        .map(|p| {
            parse_path(&p.path).map_err(|message| SweepError::Parameter {
                argument: p.argument(),
                message,
            })
        })
        .collect::<Result<Vec<Vec<PathStep>>, _>>()?;
    for (j, later) in parameters.iter().enumerate() {
        for (i, earlier) in parameters[..j].iter().enumerate() {
            let message = if steps[i] == steps[j] {
                format!(
                    "`{}` is already swept by --set {}: give all its values in one --set",
                    path_text(&steps[j]),
                    earlier.argument()
                )
            } else if steps[i].starts_with(&steps[j]) {
                format!(
                    "it replaces `{}`, swept by the earlier --set {}: give the --set of the whole `{}` first",
                    path_text(&steps[i]),
                    earlier.argument(),
                    path_text(&steps[j])
                )
            } else {
                continue;
            };
            return Err(SweepError::Parameter {
                argument: later.argument(),
                message,
            });
        }
    }
    Ok(())
}

/// The last key of a field path (`material.wlf.Tg` → `Tg`).
pub fn short_name(path: &str) -> &str {
    path.rsplit('.').next().unwrap_or(path)
}

/// The files of one sweep folder.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepDir {
    /// The folder.
    pub dir: PathBuf,
}

impl SweepDir {
    /// `DIR/sweep.json`.
    pub fn plan_file(&self) -> PathBuf {
        self.dir.join(PLAN_FILE)
    }

    /// `DIR/variants/<id>`.
    pub fn variant(&self, id: &str) -> PathBuf {
        self.dir.join("variants").join(id)
    }

    /// The resolved design of variant `id`.
    pub fn design(&self, id: &str) -> PathBuf {
        self.variant(id).join(DESIGN_FILE)
    }

    /// The run folder of variant `id`.
    pub fn run(&self, id: &str) -> PathBuf {
        self.variant(id).join("run")
    }

    /// Why variant `id`'s design was refused, if it was.
    pub fn error(&self, id: &str) -> PathBuf {
        self.variant(id).join(ERROR_FILE)
    }

    /// What variant `id`'s runs printed (appended by every attempt, here or on the cluster).
    pub fn log(&self, id: &str) -> PathBuf {
        self.variant(id).join("log.txt")
    }

    /// Why variant `id`'s last attempt stopped before its run folder had a summary (a folder or the disk
    /// refused); removed by the next attempt.
    pub fn task_error(&self, id: &str) -> PathBuf {
        self.variant(id).join("task_error.txt")
    }

    /// Reads the plan, and checks that it is the plan its own parameters make.
    ///
    /// # Errors
    /// [`SweepError::Folder`] when DIR holds no sweep or an unreadable plan, or a plan that no longer describes
    /// its sweep (naming the field: `sweep.json: variants[3].values: 1 value for 2 parameters …`).
    pub fn read_plan(&self) -> Result<Plan, SweepError> {
        let path = self.plan_file();
        let folder = |reason: String| SweepError::Folder {
            dir: self.dir.clone(),
            reason,
        };
        let text = std::fs::read_to_string(&path)
            .map_err(|e| folder(format!("no sweep here ({PLAN_FILE}: {e})")))?;
        let plan: Plan = serde_json::from_str(&text)
            .map_err(|e| folder(format!("{PLAN_FILE} is not a sweep plan: {e}")))?;
        match plan.mismatch() {
            None => Ok(plan),
            Some(why) => Err(folder(format!(
                "{PLAN_FILE}: {why}: the file no longer describes the sweep written here (was it edited?); restore it, or start a new sweep folder"
            ))),
        }
    }

    /// Whether `plan` may be prepared here, changing nothing: a new or empty folder, or one that holds the same
    /// plan (a sweep to continue).
    ///
    /// # Errors
    /// [`SweepError::Folder`] for a folder holding another sweep, or a folder that is not empty and holds no
    /// sweep.
    pub fn check(&self, plan: &Plan) -> Result<(), SweepError> {
        let folder = |reason: String| SweepError::Folder {
            dir: self.dir.clone(),
            reason,
        };
        if self.plan_file().exists() {
            let existing = self.read_plan()?;
            if existing != *plan {
                return Err(folder(format!(
                    "holds another sweep ({} with {}{}); give the same design, --set and --bench arguments to continue it, or another -o",
                    existing.design.display(),
                    existing
                        .parameters
                        .iter()
                        .map(Parameter::argument)
                        .collect::<Vec<_>>()
                        .join(" "),
                    existing
                        .bench
                        .map_or_else(String::new, |t| format!(" --bench {}", t.name()))
                )));
            }
            return Ok(());
        }
        // A preparation killed while it wrote the plan leaves only the plan's temporaries: as good as empty.
        let plan_temporary =
            |name: &std::ffi::OsStr| name.to_str().and_then(temporary_target) == Some(PLAN_FILE);
        let mut entries = match self.dir.read_dir() {
            Ok(d) => d.flatten().filter(|e| !plan_temporary(&e.file_name())),
            Err(_) => return Ok(()),
        };
        match entries.next() {
            None => Ok(()),
            Some(_) if self.dir.join("variants").is_dir() => Err(folder(format!(
                "holds variants/ but no {PLAN_FILE}: a sweep whose preparation was killed by a stentkit that wrote the plan last; nothing in it is removed: delete the folder yourself and run the sweep again, or choose a new folder"
            ))),
            Some(_) => Err(folder(
                "is not empty and holds no sweep: choose a new folder (nothing in it is removed)"
                    .into(),
            )),
        }
    }

    /// Writes `plan` into the folder ([`SweepDir::check`] must accept it) and then each variant's resolved
    /// design, or the reason it was refused, checking those an earlier preparation wrote. The plan comes
    /// first and every file is written through a temporary renamed into place, so a preparation killed at any
    /// moment leaves a folder this continues; the temporaries a killed one left are removed (module docs).
    /// `known` holds resolutions already made (`disk::SweepEstimate::resolved`); `stop` is asked before each
    /// variant, and when it says so the preparation ends there.
    ///
    /// # Errors
    /// [`SweepError::Folder`] for a folder [`SweepDir::check`] refuses or a variant whose design changed;
    /// [`SweepError::Io`] when a file cannot be written.
    pub fn prepare(
        &self,
        plan: &Plan,
        known: &Resolutions,
        stop: &dyn Fn() -> bool,
    ) -> Result<Prepared, SweepError> {
        self.check(plan)?;
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| SweepError::Io { path, source }
        };
        std::fs::create_dir_all(&self.dir).map_err(io(&self.dir))?;
        remove_stale_temporaries(&self.dir, Path::new(""), &|t| {
            t == PLAN_FILE || t == collect::TABLE_FILE
        })?;
        if !self.plan_file().exists() {
            let text = serde_json::to_string_pretty(plan).unwrap_or_default();
            write_file_atomically(&self.plan_file(), text, Durability::Synced)
                .map_err(io(&self.plan_file()))?;
        }
        for (index, v) in plan.variants.iter().enumerate() {
            if stop() {
                return Ok(Prepared::Stopped { prepared: index });
            }
            let dir = self.variant(&v.id);
            std::fs::create_dir_all(&dir).map_err(io(&dir))?;
            remove_stale_temporaries(&dir, Path::new(""), &|t| {
                t == DESIGN_FILE || t == ERROR_FILE
            })?;
            let resolved = known
                .get(&index)
                .cloned()
                .unwrap_or_else(|| resolve(plan, index));
            let (path, text) = match &resolved {
                Ok(text) => (self.design(&v.id), text),
                Err(error) => (self.error(&v.id), error),
            };
            match std::fs::read_to_string(&path) {
                Ok(existing) if existing == *text => {}
                // Empty: written but not yet flushed when the machine stopped (the text is never empty).
                Ok(existing) if existing.is_empty() => {
                    write_file_atomically(&path, text, Durability::Unsynced).map_err(io(&path))?;
                }
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                    write_file_atomically(&path, text, Durability::Unsynced).map_err(io(&path))?;
                }
                Err(e) if e.kind() != std::io::ErrorKind::InvalidData => {
                    return Err(io(&path)(e));
                }
                _ => {
                    return Err(SweepError::Folder {
                        dir: self.dir.clone(),
                        reason: format!(
                            "variant {} ({}) resolves to another design than the one it was written with ({}): was the design file edited? Start a new sweep folder",
                            v.id,
                            plan.label(index),
                            path.display()
                        ),
                    });
                }
            }
        }
        Ok(Prepared::All)
    }

    /// The state of variant `id` from its files.
    pub fn state(&self, id: &str) -> VariantState {
        if let Ok(error) = std::fs::read_to_string(self.error(id)) {
            return VariantState::Failed(error.trim().to_string());
        }
        let summary =
            crate::io::input::read_json::<serde_json::Value>(&self.run(id).join("summary.json"))
                .ok();
        let Some(summary) = summary else {
            return match std::fs::read_to_string(self.task_error(id)) {
                Ok(why) => VariantState::Failed(why.trim().to_string()),
                Err(_) => VariantState::Pending,
            };
        };
        let error = || {
            summary["error"]
                .as_str()
                .unwrap_or("see the run folder")
                .to_string()
        };
        match summary["status"].as_str() {
            Some("completed") => VariantState::Completed,
            Some("failed" | "stopped") => VariantState::Failed(error()),
            Some(other) => VariantState::Unfinished(other.to_string()),
            None => VariantState::Unfinished("unreadable summary".into()),
        }
    }
}

/// Resolutions of variants made before the preparation, by index: the resolved design text, or why the
/// design was refused ([`resolve`]).
pub type Resolutions = HashMap<usize, Result<String, String>>;

/// How far [`SweepDir::prepare`] got.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Prepared {
    /// Every variant's design is written.
    All,
    /// Stopped when asked, with the variants before `prepared` written.
    Stopped {
        /// Variants written (those with a smaller index).
        prepared: usize,
    },
}

impl From<RemoveError> for SweepError {
    fn from(e: RemoveError) -> Self {
        Self::Io {
            path: e.path,
            source: e.source,
        }
    }
}

/// The resolved design text of variant `index`, or the design error its overrides give.
pub fn resolve(plan: &Plan, index: usize) -> Result<String, String> {
    resolve_design(plan, index).map(|d| d.source)
}

/// The resolved design of variant `index`, or the design error its overrides give (as text).
pub fn resolve_design(plan: &Plan, index: usize) -> Result<Design, String> {
    let sets: Result<Vec<SetOverride>, _> = plan
        .overrides(index)
        .iter()
        .map(|s| s.parse::<SetOverride>())
        .collect();
    let sets = sets.map_err(|e| e.to_string())?;
    load_design_with(&plan.design, &DesignOverrides::sets(sets))
        .map_err(|e: DesignError| e.to_string())
}

/// What a variant's files say about it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum VariantState {
    /// Not started.
    Pending,
    /// Its run reached the end time.
    Completed,
    /// Its design was refused or its run failed: why.
    Failed(String),
    /// Its run stopped before the end without failing (`interrupted`, `killed`, or `running` — a run in
    /// progress or one killed without a trace): it continues from its checkpoint.
    Unfinished(String),
}

impl VariantState {
    /// A one-word name for tables: `pending`, `completed`, `failed`, or the run's status.
    pub fn name(&self) -> &str {
        match self {
            Self::Pending => "pending",
            Self::Completed => "completed",
            Self::Failed(_) => "failed",
            Self::Unfinished(status) => status,
        }
    }

    /// Whether a sweep (re)runs it: not completed, and not failed unless `retry_failed`.
    pub fn to_run(&self, retry_failed: bool) -> bool {
        match self {
            Self::Pending | Self::Unfinished(_) => true,
            Self::Completed => false,
            Self::Failed(_) => retry_failed,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_and_ranges_give_the_values_asked() {
        let p = Parameter::parse("material.wlf.Tg=60,65,70").expect("list");
        assert_eq!(p.values, ["60", "65", "70"]);
        let p = Parameter::parse("section.diameter=0.5:0.7:0.1").expect("range");
        assert_eq!(p.values, ["0.5", "0.6", "0.7"]);
        let p = Parameter::parse("x=1:2:0.3").expect("range without STOP");
        assert_eq!(p.values, ["1", "1.3", "1.6", "1.9"]);
        let p = Parameter::parse("material.prony[0]=[1, 2],[3, 4]").expect("lists");
        assert_eq!(p.values, ["[1, 2]", "[3, 4]"]);
        for bad in [
            "x", "x=", "x=1,,2", "x=1:0:1", "x=0:1:0", "x=a:1:1", "=1", "x=[1,",
        ] {
            assert!(Parameter::parse(bad).is_err(), "{bad} accepted");
        }
    }

    #[test]
    fn the_product_varies_the_last_parameter_fastest_and_zip_pairs() {
        let a = Parameter::parse("a=1,2").expect("a");
        let b = Parameter::parse("b=x,y,z").expect("b");
        let plan =
            Plan::new(Path::new("d.yaml"), vec![a.clone(), b.clone()], false).expect("product");
        let rows: Vec<_> = plan.variants.iter().map(|v| v.values.join("")).collect();
        assert_eq!(rows, ["1x", "1y", "1z", "2x", "2y", "2z"]);
        assert_eq!(plan.variants[4].id, "v004");
        assert_eq!(plan.overrides(4), ["a=2", "b=y"]);
        assert!(Plan::new(Path::new("d.yaml"), vec![a.clone(), b], true).is_err());
        let c = Parameter::parse("c=5,6").expect("c");
        let plan = Plan::new(Path::new("d.yaml"), vec![a, c], true).expect("zip");
        assert_eq!(plan.variants.len(), 2);
        assert_eq!(plan.overrides(1), ["a=2", "c=6"]);
    }
}
