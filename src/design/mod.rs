//! YAML design files (format version 1): reading, validation and the errors a designer sees.
//!
//! A design is read in three passes: serde_yaml deserialises it into `dto` types (unknown fields, missing
//! fields, wrong types and bad single numbers are reported there with line and column); `build` generates
//! the geometry and checks everything that involves several values; `locate` maps the field path of such a
//! check back to its line and column. Every error names the file, the line and column, the field, what is
//! wrong and what is allowed. Before any of this, `guard` refuses text too large, too deeply nested or with
//! aliases, which would make the parsers slow or the design enormous. [`tuned_text`] writes a design's text
//! with the discretisation `stentkit tune` chose.
//!
//! Layer: above `io` (it reads centreline files and names output formats through it) and `study` (a
//! [`Design`] is the [`crate::study::variant::VariedDesign`] a study re-builds, [`variants`]); `io`'s writers
//! see it as an `crate::io::output::RunDesign`.

pub(crate) mod build;
mod contact;
mod diamond;
pub(crate) mod dto;
pub(crate) mod family;
pub(crate) mod guard;
pub(crate) mod issue;
pub(crate) mod locate;
pub(crate) mod materials;
pub(crate) mod set;
pub(crate) mod size;

pub(crate) mod stent;
mod tuned;
pub mod variants;
pub mod vessel;

pub use crate::io::output::{OutputSettings, RecordingSettings, SnapshotSettings};
pub use set::{PathStep, SetOverride};
pub use tuned::{TunedChoice, TunedTextError, tuned_text};

use crate::io::output::RunDesign;
use crate::math::quote;
use crate::model::Model;
use std::fmt;
use std::path::{Path, PathBuf};

/// A design read from a file.
#[derive(Debug, Clone)]
pub struct Design {
    /// The validated model.
    pub model: Model,
    /// Snapshot and recording settings.
    pub output: OutputSettings,
    /// Things worth knowing that do not stop a run.
    pub warnings: Vec<String>,
    /// How the design was read where it involved a choice (a file centreline's fit), for `check`.
    pub notes: Vec<String>,
    /// The memory a run is estimated to need (below `size::MEMORY_LIMIT_BYTES`: larger designs are refused).
    pub memory: size::MemoryEstimate,
    /// The steps a run takes when no step is cut ([`Model::planned_steps`], computed once here: it sorts every
    /// breakpoint).
    pub steps: crate::model::StepPlan,
    /// The YAML text as read (embedded in run recordings); with `--set` overrides, the resolved design
    /// (`set::resolved_text`).
    pub source: String,
    /// The `--set` overrides applied, as given (`stent.crowns=8`).
    pub overrides: Vec<String>,
    /// Where it was read from.
    pub path: PathBuf,
    /// The virtual bench's settings as written (`bench:`; `crate::bench` resolves the defaults).
    pub bench: BenchSpec,
}

/// The `bench` block of a design as written: `None` where it gives no value (`crate::bench` resolves the
/// defaults, some of which need the model).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BenchSpec {
    /// Temperature of the test \[°C\].
    pub temperature: Option<f64>,
    /// Rate of the crimper's diameter \[length/time\].
    pub rate: Option<f64>,
    /// The smallest diameter the crimper closes to \[length\].
    pub min_diameter: Option<f64>,
    /// The vessel's diameter, where the chronic outward force is read \[length\].
    pub vessel_diameter: Option<f64>,
    /// Diameters recorded per branch.
    pub diameters: Option<usize>,
    /// The smallest gap the crush plates close to \[length\].
    pub min_gap: Option<f64>,
    /// Segments of the radial bench's segmented-head crimper (`None`: a cylinder).
    pub segments: Option<usize>,
}

impl RunDesign for Design {
    fn model(&self) -> &Model {
        &self.model
    }
    fn output(&self) -> &OutputSettings {
        &self.output
    }
    fn steps(&self) -> &crate::model::StepPlan {
        &self.steps
    }
    fn source(&self) -> &str {
        &self.source
    }
    fn path(&self) -> &Path {
        &self.path
    }
}

/// Why a design could not be read.
#[derive(Debug)]
pub enum DesignError {
    /// The file could not be read.
    Read {
        /// The file.
        file: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// The file's content is invalid.
    Invalid {
        /// The file.
        file: PathBuf,
        /// Line, 1-based.
        line: usize,
        /// Column, 1-based.
        column: usize,
        /// Field path (`patches[2].arc.radius`), empty for syntax errors.
        field: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// A `--set` override was refused: its path does not fit the design, or the value it sets (or a field of a
    /// map it created) is invalid.
    Override {
        /// The design file the override applies to.
        file: PathBuf,
        /// The `--set` argument as given.
        argument: String,
        /// Field path of the invalid value (the override's own, or one below it).
        field: String,
        /// What is wrong and what is allowed.
        message: String,
    },
}

impl fmt::Display for DesignError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DesignError::Read { file, source } => {
                write!(f, "{}: cannot read the design: {source}", file.display())
            }
            DesignError::Invalid {
                file,
                line,
                column,
                field,
                message,
            } => {
                write!(f, "{}:{line}:{column}: ", file.display())?;
                if !field.is_empty() {
                    write!(f, "{field}: ")?;
                }
                write!(f, "{message}")
            }
            DesignError::Override {
                file,
                argument,
                field,
                message,
            } => {
                // The argument and its path are the user's: shortened as values in messages are.
                write!(
                    f,
                    "{}: --set {}: ",
                    file.display(),
                    quote::shortened(argument, quote::QUOTED_CHARS)
                )?;
                // A long path that is the argument's own was just shown (shortened) with it.
                let own = argument.starts_with(field.as_str())
                    && argument[field.len()..].starts_with('=');
                let shown = own && field.chars().nth(quote::QUOTED_CHARS).is_some();
                if !(field.is_empty() || shown) {
                    write!(f, "{}: ", quote::shortened(field, quote::MAX_FIELD_CHARS))?;
                }
                write!(f, "{message}")
            }
        }
    }
}

/// The I/O cause is part of the message (so it is not also returned as the error's source, which would make
/// error chains print it twice).
impl std::error::Error for DesignError {}

/// Reads and validates the design file at `path`. At most `guard::MAX_DESIGN_BYTES` are read: a larger
/// file is refused without reading the rest.
pub fn load_design(path: &Path) -> Result<Design, DesignError> {
    load_design_with(path, &DesignOverrides::default())
}

/// [`load_design`] with `overrides` applied before the model is built (e.g. `run --tol`).
pub fn load_design_with(path: &Path, overrides: &DesignOverrides) -> Result<Design, DesignError> {
    use crate::io::input::{InputError, read_regular_file};
    let read_error = |source| DesignError::Read {
        file: path.to_path_buf(),
        source,
    };
    let bytes = read_regular_file(path, guard::MAX_DESIGN_BYTES as u64).map_err(|e| match e {
        InputError::Io(source) => read_error(source),
        InputError::NotRegular(what) => read_error(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("{what}, not a regular file"),
        )),
        InputError::TooLarge(size) => refused(path, guard::too_large(size)),
    })?;
    let text = String::from_utf8(bytes)
        .map_err(|e| read_error(std::io::Error::new(std::io::ErrorKind::InvalidData, e)))?;
    parse_design_with(&text, path, overrides)
}

/// The design error of a text refused by [`guard`] (no field: the text is refused before it is read as
/// fields).
fn refused(path: &Path, refusal: guard::Refusal) -> DesignError {
    DesignError::Invalid {
        file: path.to_path_buf(),
        line: refusal.position.line,
        column: refusal.position.column,
        field: String::new(),
        message: refusal.message,
    }
}

/// Splits serde_yaml's message into the text and the position it names. A syntax error reads
/// `problem at line L column C, while parsing … at line L' column C'`: the problem's own position (the first one)
/// is where the designer must look. Other messages end in ` at line L column C`. serde_yaml's leading
/// `path: ` is dropped too (the path is reported separately).
fn split_message(message: &str) -> (String, Option<locate::Position>) {
    let mut text = message.to_string();
    let mut position = None;
    if let Some(i) = text.find(" at line ") {
        let rest = &text[i + " at line ".len()..];
        let digits = |s: &str| {
            s.chars()
                .take_while(char::is_ascii_digit)
                .collect::<String>()
        };
        let line = digits(rest);
        let column = rest[line.len()..].strip_prefix(" column ").map(digits);
        if let (Ok(line), Some(Ok(column))) = (line.parse(), column.map(|c| c.parse())) {
            position = Some(locate::Position { line, column });
            let end = i + " at line ".len() + rest.find(',').unwrap_or(rest.len());
            text.replace_range(i..end, "");
        }
    }
    if let Some(j) = text.find(" at line ") {
        text.truncate(j);
    }
    if let Some((path, rest)) = text.split_once(": ")
        && !path.is_empty()
        && !path.contains(' ')
    {
        text = rest.to_string();
    }
    (text, position)
}

/// Changes applied to a design after it is read and before the model is built (studies vary these).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DesignOverrides {
    /// Degree of every patch (replaces `mesh.p`, per-patch `p` and a stent's `crown_mesh.p`/`bridge_mesh.p`).
    pub degree: Option<usize>,
    /// Control points of every patch (replaces `mesh.n`, per-patch `n` and a stent's `crown_mesh.n`/`bridge_mesh.n`).
    pub points: Option<usize>,
    /// End time (replaces `time.end`).
    pub end_time: Option<f64>,
    /// Time step (replaces `time.step`).
    pub step: Option<f64>,
    /// Time-error tolerance (replaces `time.tolerance`: error-controlled steps).
    pub time_tolerance: Option<f64>,
    /// Internal-variable update (replaces `material.integrator`).
    pub integrator: Option<dto::IntegratorDto>,
    /// Crowns of the generated stent (replaces `stent.crowns`); a design without a `stent` block is refused.
    pub crowns: Option<usize>,
    /// `--set PATH=VALUE` overrides of any field, applied in order to the file's YAML before it is read
    /// (`set`); the others above are applied after them.
    pub sets: Vec<SetOverride>,
    /// Build the device in the temporary shape its programme drives it to, without the programme
    /// ([`crate::model::builder::ModelBuilder::temporary_shape`]; `stentkit mesh --state temporary`).
    pub temporary_shape: bool,
}

impl DesignOverrides {
    /// Only the `--set` overrides `sets`.
    pub fn sets(sets: Vec<SetOverride>) -> Self {
        Self {
            sets,
            ..Self::default()
        }
    }

    fn apply(&self, d: &mut dto::DesignDto) {
        if self.degree.is_some() || self.points.is_some() {
            let mesh = d.mesh.get_or_insert(dto::MeshDto { p: None, n: None });
            if let Some(p) = self.degree {
                mesh.p = Some(p);
            }
            if let Some(n) = self.points {
                mesh.n = Some(n);
            }
            // The meshes patches and a stent's crowns or bridges give themselves yield to the override.
            let own = d.patches.iter_mut().map(|q| (&mut q.p, &mut q.n)).chain(
                d.stent
                    .iter_mut()
                    .flat_map(|s| [s.crown_mesh.as_mut(), s.bridge_mesh.as_mut()])
                    .flatten()
                    .map(|m| (&mut m.p, &mut m.n)),
            );
            for (p, n) in own {
                if self.degree.is_some() {
                    *p = None;
                }
                if self.points.is_some() {
                    *n = None;
                }
            }
        }
        if let Some(t) = self.end_time {
            d.time.end = dto::Positive(t);
        }
        if let Some(h) = self.step {
            d.time.step = Some(dto::Positive(h));
        }
        if let Some(tol) = self.time_tolerance {
            d.time.tolerance = Some(dto::Positive(tol));
        }
        if let Some(i) = self.integrator {
            d.material.integrator = Some(i);
        }
        if let (Some(c), Some(stent)) = (self.crowns, d.stent.as_mut()) {
            stent.crowns = c;
        }
    }
}

/// The JSON Schema (draft 2020-12) of the design format, for editors that complete and check YAML.
pub fn design_schema() -> serde_json::Value {
    let mut schema = schemars::schema_for!(dto::DesignDto);
    schema.insert("title".into(), "stentkit design, format version 1".into());
    schema.to_value()
}

/// Validates a design given as text; `path` names it in errors.
pub fn parse_design(text: &str, path: &Path) -> Result<Design, DesignError> {
    parse_design_with(text, path, &DesignOverrides::default())
}

/// Validates a design given as text with `overrides` applied; `path` names it in errors.
pub fn parse_design_with(
    text: &str,
    path: &Path,
    overrides: &DesignOverrides,
) -> Result<Design, DesignError> {
    let file = path.to_path_buf();
    guard::check_text(text).map_err(|r| refused(path, r))?;
    let locator = locate::Locator::new(text);
    let stem = path.file_stem().map_or_else(
        || "design".to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let (mut dto, source, applied) = if overrides.sets.is_empty() {
        let deserializer = serde_yaml::Deserializer::from_str(text);
        let dto: dto::DesignDto = serde_path_to_error::deserialize(deserializer)
            .map_err(|e| design_read_error(&e, text, &locator, &file))?;
        (dto, text.to_string(), Vec::new())
    } else {
        let mut root: serde_yaml::Value = match serde_yaml::from_str(text) {
            Ok(root) => root,
            // Not YAML: the error is reported exactly as without overrides.
            Err(e) => {
                return Err(parse_design(text, path).err().unwrap_or_else(|| {
                    DesignError::Invalid {
                        file,
                        line: 1,
                        column: 1,
                        field: String::new(),
                        message: e.to_string(),
                    }
                }));
            }
        };
        let mut applied = Vec::new();
        for s in &overrides.sets {
            let a = set::apply(&mut root, s).map_err(|message| DesignError::Override {
                file: file.clone(),
                argument: s.argument.clone(),
                field: s.field(),
                message,
            })?;
            applied.push((a, s));
        }
        // The resolved design is written elsewhere (a sweep's variant folder): it keeps the file's name.
        if let Some(top) = root.as_mapping_mut()
            && !top.contains_key("name")
        {
            top.insert("name".into(), stem.clone().into());
        }
        let dto: dto::DesignDto = serde_path_to_error::deserialize(root.clone())
            .map_err(|e| owned(read_error(&e, &locator, &file), &applied))?;
        vessel::absolute_file_paths(&mut root, path.parent().unwrap_or(Path::new("")));
        let source =
            set::resolved_text(&root, path, &overrides.sets).map_err(|e| DesignError::Invalid {
                file: file.clone(),
                line: 1,
                column: 1,
                field: String::new(),
                message: format!("the resolved design cannot be written as YAML: {e}"),
            })?;
        (dto, source, applied)
    };
    overrides.apply(&mut dto);
    // Centreline files are named relative to the design file.
    let dir = path.parent().unwrap_or(Path::new(""));
    for c in [
        dto.stent.as_mut().map(|s| &mut s.centreline),
        dto.programme
            .as_mut()
            .and_then(|p| p.temporary.as_mut())
            .and_then(|t| t.centreline.as_mut()),
    ]
    .into_iter()
    .flatten()
    {
        if let Some(f) = &mut c.file
            && Path::new(&f.path).is_relative()
        {
            f.path = dir.join(&f.path).to_string_lossy().into_owned();
        }
    }
    if overrides.crowns.is_some() && dto.stent.is_none() {
        let pos = locator.find("stent");
        return Err(DesignError::Invalid {
            file,
            line: pos.line,
            column: pos.column,
            field: "stent.crowns".into(),
            message: "the crown count is overridden, but the design has no `stent` block".into(),
        });
    }
    let built = build::build(&dto, &stem, overrides.temporary_shape).map_err(|issue| {
        let pos = locator.find(&issue.path);
        owned(
            DesignError::Invalid {
                file: file.clone(),
                line: pos.line,
                column: pos.column,
                message: quote::shortened_message(&issue.message).into_owned(),
                field: issue.path,
            },
            &applied,
        )
    })?;
    Ok(Design {
        model: built.model,
        output: built.output,
        warnings: built.warnings,
        notes: built.notes,
        memory: built.memory,
        steps: built.steps,
        source,
        overrides: overrides.sets.iter().map(|s| s.argument.clone()).collect(),
        path: file,
        bench: built.bench,
    })
}

/// The error of reading `text` into a design. A YAML syntax error is reported where the parser found it, also
/// when the design's reader met a missing field first: an over-indented key ends its mapping early, and the
/// reader then misses a field of that mapping at the wrong line (issue 19), so a reading error is checked
/// against a plain YAML parse of the text.
fn design_read_error(
    e: &serde_path_to_error::Error<serde_yaml::Error>,
    text: &str,
    locator: &locate::Locator,
    file: &Path,
) -> DesignError {
    if is_syntax_error(e.inner()) {
        return not_yaml(read_error(e, locator, file), false);
    }
    match serde_path_to_error::deserialize::<_, serde_yaml::Value>(
        serde_yaml::Deserializer::from_str(text),
    ) {
        Err(syntax) if is_syntax_error(syntax.inner()) => {
            not_yaml(read_error(&syntax, locator, file), true)
        }
        _ => read_error(e, locator, file),
    }
}

/// Whether `e` is one of libyaml's syntax errors (they name the construct being parsed: "…, while parsing a
/// block mapping").
fn is_syntax_error(e: &serde_yaml::Error) -> bool {
    e.to_string().contains(", while ")
}

/// A syntax error's message says it is one, and where a block structure broke, the usual cause; `clear_field`
/// drops a field path that a plain parse cannot know.
fn not_yaml(mut error: DesignError, clear_field: bool) -> DesignError {
    if let DesignError::Invalid { field, message, .. } = &mut error {
        // (A key the parser had not read yet shows as `?`: the mapping around it is what is known.)
        *field = if clear_field {
            String::new()
        } else {
            field
                .trim_end_matches('?')
                .trim_end_matches('.')
                .to_string()
        };
        let hint = if message.contains("while parsing a block") {
            " (a key indented more or less than its neighbours does this)"
        } else {
            ""
        };
        *message = format!("not valid YAML: {message}{hint}");
    }
    error
}

/// The design error of a deserialisation error `e` of the text indexed by `locator` (module docs: the
/// position of a syntax error is the problem's own, a rejected value is found by its path, serde_yaml's
/// position is best for unknown and missing fields).
fn read_error(
    e: &serde_path_to_error::Error<serde_yaml::Error>,
    locator: &locate::Locator,
    file: &Path,
) -> DesignError {
    let field = match e.path().to_string() {
        p if p == "." => String::new(),
        p => p,
    };
    let inner = e.inner().to_string();
    let (message, named) = split_message(&inner);
    // Only libyaml's syntax errors name the position of the problem itself.
    let named = named.filter(|_| is_syntax_error(e.inner()));
    let serde_position = e.inner().location().map(|l| locate::Position {
        line: l.line(),
        column: l.column(),
    });
    let unknown_field = inner.contains("unknown field");
    let pos = match (named, locator.get(&field), serde_position) {
        (Some(p), _, _) => p,
        (None, Some(p), _) if !unknown_field => p,
        (None, _, Some(p)) => p,
        // Read from a tree (with `--set` overrides), an unknown field has no position of its own: its key's.
        (None, _, None) => locator
            .key(&field)
            .filter(|_| unknown_field)
            .unwrap_or_else(|| locator.find(&field)),
    };
    DesignError::Invalid {
        file: file.to_path_buf(),
        line: pos.line,
        column: pos.column,
        field: quote::shortened(&field, quote::MAX_FIELD_CHARS).into_owned(),
        message: quote::shortened_message(&message).into_owned(),
    }
}

/// `error` as the error of the `--set` override that set or created its field, if one did ([`set::owner`]).
fn owned(error: DesignError, applied: &[(set::Applied, &SetOverride)]) -> DesignError {
    match error {
        DesignError::Invalid {
            file,
            field,
            message,
            ..
        } if let Some(set) = set::owner(applied, &field) => DesignError::Override {
            file,
            argument: set.argument.clone(),
            field,
            message,
        },
        e => e,
    }
}
