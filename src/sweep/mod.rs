//! Families of variants of one design (`stentkit sweep`): the swept parameters, the variants they make, the
//! sweep folder and the state of each variant as its files tell it — the same whether the variants ran on this
//! machine or as a Slurm job array.
//!
//! **Parameters.** `--set PATH=V1,V2,…` (YAML values, split at the commas outside brackets) or
//! `--set PATH=START:STOP:STEP` (numbers; STOP included when a whole number of steps reaches it, to 1e-9 of a
//! step). The variants are the cartesian product of the values, the first parameter varying slowest, or with
//! `--zip` the k-th values of every parameter together (the lists must be equally long).
//!
//! **Folder.** `DIR/sweep.json` (the plan: the design file, the parameters, the variants with their
//! overrides), and per variant `DIR/variants/vNNN/`: `design.yaml` (the resolved design, [`crate::io::design::set`]),
//! `run/` (its run folder), `log.txt` (what its run printed) or `error.txt` (why its design was refused: a
//! variant the values make invalid is a failed row, not the end of the sweep). Nothing in DIR is removed by a
//! sweep: a rerun skips completed variants, continues interrupted or killed ones from their checkpoint, starts
//! those never started, and reruns failed ones only when asked (`--retry-failed`, which replaces only the files
//! that failed run wrote). A rerun must describe the same sweep: a different plan or a variant whose resolved
//! design changed (the design file was edited) is refused.
//!
//! **State** of a variant ([`VariantState`]) is read from its files: `summary.json`'s status, or `error.txt`
//! (its design was refused), or `task_error.txt` (its run was refused before it wrote a summary), or nothing
//! yet.

pub mod collect;
pub mod metrics;
pub mod slurm;

use crate::io::design::{DesignError, DesignOverrides, SetOverride, load_design_with};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The plan file in a sweep folder.
pub const PLAN_FILE: &str = "sweep.json";

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
}

impl Plan {
    /// The variants of `parameters` (module docs) of the design at `design` (a parameter with one value is
    /// the same in every variant).
    ///
    /// # Errors
    /// [`SweepError::Plan`] for no parameters, `--zip` lists of different lengths or more than
    /// [`MAX_VARIANTS`] variants.
    pub fn new(design: &Path, parameters: Vec<Parameter>, zip: bool) -> Result<Self, SweepError> {
        if parameters.is_empty() {
            return Err(SweepError::Plan(
                "give at least one swept parameter: --set PATH=V1,V2,… or PATH=START:STOP:STEP"
                    .into(),
            ));
        }
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
        self.variant(id).join("design.yaml")
    }

    /// The run folder of variant `id`.
    pub fn run(&self, id: &str) -> PathBuf {
        self.variant(id).join("run")
    }

    /// Why variant `id`'s design was refused, if it was.
    pub fn error(&self, id: &str) -> PathBuf {
        self.variant(id).join("error.txt")
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

    /// Reads the plan.
    ///
    /// # Errors
    /// [`SweepError::Folder`] when DIR holds no sweep or an unreadable plan.
    pub fn read_plan(&self) -> Result<Plan, SweepError> {
        let path = self.plan_file();
        let text = std::fs::read_to_string(&path).map_err(|e| SweepError::Folder {
            dir: self.dir.clone(),
            reason: format!("no sweep here ({PLAN_FILE}: {e})"),
        })?;
        serde_json::from_str(&text).map_err(|e| SweepError::Folder {
            dir: self.dir.clone(),
            reason: format!("{PLAN_FILE} is not a sweep plan: {e}"),
        })
    }

    /// Writes `plan` and each variant's resolved design (or the reason it was refused) into a new folder, or
    /// checks that an existing folder holds the same plan and the same resolved designs (module docs).
    ///
    /// # Errors
    /// [`SweepError::Folder`] for a folder holding another sweep or a changed design (or a folder that is not
    /// empty and holds no sweep); [`SweepError::Io`] when a file cannot be written.
    pub fn prepare(&self, plan: &Plan) -> Result<(), SweepError> {
        let folder = |reason: String| SweepError::Folder {
            dir: self.dir.clone(),
            reason,
        };
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| SweepError::Io { path, source }
        };
        if self.plan_file().exists() {
            let existing = self.read_plan()?;
            if existing != *plan {
                return Err(folder(format!(
                    "holds another sweep ({} with {}); give the same design and --set arguments to continue it, or another -o",
                    existing.design.display(),
                    existing
                        .parameters
                        .iter()
                        .map(|p| format!("{}={}", p.path, p.values.join(",")))
                        .collect::<Vec<_>>()
                        .join(" ")
                )));
            }
        } else if self.dir.read_dir().is_ok_and(|mut d| d.next().is_some()) {
            return Err(folder(
                "is not empty and holds no sweep: choose a new folder (nothing in it is removed)"
                    .into(),
            ));
        }
        std::fs::create_dir_all(&self.dir).map_err(io(&self.dir))?;
        for (index, v) in plan.variants.iter().enumerate() {
            let dir = self.variant(&v.id);
            std::fs::create_dir_all(&dir).map_err(io(&dir))?;
            let resolved = resolve(plan, index);
            let (path, text) = match &resolved {
                Ok(text) => (self.design(&v.id), text),
                Err(error) => (self.error(&v.id), error),
            };
            match std::fs::read_to_string(&path) {
                Ok(existing) if existing == *text => {}
                Ok(_) => {
                    return Err(folder(format!(
                        "variant {} ({}) resolves to another design than the one it was written with ({}): was the design file edited? Start a new sweep folder",
                        v.id,
                        plan.label(index),
                        path.display()
                    )));
                }
                Err(_) => write_new(&path, text).map_err(io(&path))?,
            }
        }
        let text = serde_json::to_string_pretty(plan).unwrap_or_default();
        if !self.plan_file().exists() {
            write_new(&self.plan_file(), &text).map_err(io(&self.plan_file()))?;
        }
        Ok(())
    }

    /// The state of variant `id` from its files.
    pub fn state(&self, id: &str) -> VariantState {
        if let Ok(error) = std::fs::read_to_string(self.error(id)) {
            return VariantState::Failed(error.trim().to_string());
        }
        let summary = std::fs::read_to_string(self.run(id).join("summary.json"))
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok());
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

/// Writes `text` to a file that must not exist yet (nothing the user wrote is replaced).
fn write_new(path: &Path, text: &str) -> std::io::Result<()> {
    use std::io::Write as _;
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)?;
    file.write_all(text.as_bytes())
}

/// The resolved design text of variant `index`, or the design error its overrides give.
pub fn resolve(plan: &Plan, index: usize) -> Result<String, String> {
    let sets: Result<Vec<SetOverride>, _> = plan
        .overrides(index)
        .iter()
        .map(|s| s.parse::<SetOverride>())
        .collect();
    let sets = sets.map_err(|e| e.to_string())?;
    load_design_with(&plan.design, &DesignOverrides::sets(sets))
        .map(|d| d.source)
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
