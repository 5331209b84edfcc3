//! How the command line refuses a bad argument: one way for every command.
//!
//! **What an argument alone can tell** (a number that must be positive and finite, a count with a least value,
//! a word from a list, an output file's extension, the syntax of `--set PATH=VALUE`) is declared on the
//! argument with a value parser from here (`#[arg(value_parser = arguments::positive())]`). clap runs it while
//! it reads the command line, before anything else: the command ends with exit status 2
//! ([`super::EXIT_BAD_INPUT`], clap's own for usage errors) and one line naming the argument, its value quoted
//! as design errors quote values (`quoted`: cut after 40 characters, with its length) and what is allowed:
//!
//! ```text
//! error: --grid `-1`: must be a finite number > 0
//! ```
//!
//! **What needs the design** (a print grid against the design's wire radius, the memory a mesh or a study
//! would take) is checked once the design is read, before anything is sampled, simulated or written, and
//! refused as [`super::BadInput`] (also exit status 2) with [`too_costly`]'s wording.

use super::BadInput;
use crate::design::SetOverride;
use crate::design::size::{MEMORY_LIMIT_BYTES, human_bytes};
use crate::math::quote::{QUOTED_CHARS, quoted_up_to};
use crate::math::{Real, Short};
use crate::post::print::TIME_LIMIT_SECONDS;
use clap::builder::{PossibleValue, TypedValueParser};
use clap::error::ErrorKind;
use std::ffi::OsStr;

/// A value parser that turns an argument's text into its value or says what is wrong with it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Checked<T> {
    parse: fn(&str) -> Result<T, String>,
    /// Characters of the value shown in a refusal: [`QUOTED_CHARS`], or a path's whole length.
    shown: usize,
}

impl<T: Clone + Send + Sync + 'static> TypedValueParser for Checked<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<T, clap::Error> {
        let text = value.to_string_lossy();
        (self.parse)(&text).map_err(|message| refusal(cmd, arg, &text, self.shown, &message))
    }
}

/// A value parser for one of a fixed list of words (listed in `--help` and in the refusal).
#[derive(Debug, Clone, Copy)]
pub(crate) struct OneOf(&'static [&'static str]);

impl TypedValueParser for OneOf {
    type Value = String;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<String, clap::Error> {
        let text = value.to_string_lossy();
        if self.0.contains(&text.as_ref()) {
            Ok(text.into_owned())
        } else {
            Err(refusal(
                cmd,
                arg,
                &text,
                QUOTED_CHARS,
                &format!("must be one of {}", self.0.join(", ")),
            ))
        }
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(self.0.iter().map(PossibleValue::new)))
    }
}

/// The error clap prints for argument `arg` given the text `value` (its first `shown` characters): `--flag
/// `value`: message`.
fn refusal(
    cmd: &clap::Command,
    arg: Option<&clap::Arg>,
    value: &str,
    shown: usize,
    message: &str,
) -> clap::Error {
    let name = arg.map_or_else(String::new, |a| match (a.get_long(), a.get_short()) {
        (Some(long), _) => format!("--{long}"),
        (None, Some(short)) => format!("-{short}"),
        (None, None) => a.get_id().to_string().to_uppercase(),
    });
    clap::Error::raw(
        ErrorKind::ValueValidation,
        format!("{name} {}: {message}\n", quoted_up_to(value, shown)),
    )
    .with_cmd(cmd)
}

/// A finite number > 0 (a tolerance, a time step, a grid spacing).
pub(crate) fn positive() -> Checked<Real> {
    Checked {
        shown: QUOTED_CHARS,
        parse: |text| number(text).and_then(|x| check(x, x > 0.0, "a finite number > 0")),
    }
}

/// A finite number ≥ 0 (a time, a distance that may be zero).
pub(crate) fn non_negative() -> Checked<Real> {
    Checked {
        shown: QUOTED_CHARS,
        parse: |text| number(text).and_then(|x| check(x, x >= 0.0, "a finite number ≥ 0")),
    }
}

/// A whole number ≥ `MIN` (a count of samples, segments, rings).
pub(crate) fn at_least<const MIN: usize>() -> Checked<usize> {
    Checked {
        shown: QUOTED_CHARS,
        parse: |text| match text.trim().parse::<usize>() {
            Ok(n) if n >= MIN => Ok(n),
            _ => Err(format!("must be a whole number ≥ {MIN}")),
        },
    }
}

/// One of `words`.
pub(crate) fn one_of(words: &'static [&'static str]) -> OneOf {
    OneOf(words)
}

/// A value parser from a parse function (`--set`, `--reference`, an integrator's name).
pub(crate) fn parsed_by<T>(parse: fn(&str) -> Result<T, String>) -> Checked<T> {
    Checked {
        parse,
        shown: QUOTED_CHARS,
    }
}

/// A finite number > 0, or `none` (a tolerance that can be turned off).
pub(crate) fn positive_or_none() -> Checked<super::MaybeTolerance> {
    Checked {
        shown: QUOTED_CHARS,
        parse: |text| match text.trim() {
            "none" => Ok(super::MaybeTolerance(None)),
            t => number(t)
                .and_then(|x| check(x, x > 0.0, "a finite number > 0 or `none`"))
                .map(|x| super::MaybeTolerance(Some(x))),
        },
    }
}

/// A `--set PATH=VALUE` override ([`SetOverride`]); its refusal quotes the argument once, shortened.
pub(crate) fn set_override() -> Checked<SetOverride> {
    Checked {
        shown: QUOTED_CHARS,
        parse: |text| text.parse::<SetOverride>().map_err(|e| e.message),
    }
}

/// The extensions `mesh -o` and `export -o` write: the snapshot formats ([`crate::io::formats`]) and `csv`
/// for the centrelines.
pub(crate) fn device_file() -> Checked<std::path::PathBuf> {
    Checked {
        // A path is shown whole (the longest a path can be is 4096 bytes).
        shown: 4096,
        parse: |text| {
            let extension = std::path::Path::new(text)
                .extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase)
                .unwrap_or_default();
            if crate::io::formats::format(&extension).is_some() || extension == "csv" {
                Ok(text.into())
            } else {
                let known: Vec<String> = crate::io::formats::FORMATS
                    .iter()
                    .map(|f| format!(".{}", f.extension()))
                    .collect();
                Err(format!(
                    "the output must end in {} or .csv",
                    known.join(", ")
                ))
            }
        },
    }
}

/// `text` as a number, or why it is not one.
fn number(text: &str) -> Result<Real, String> {
    text.trim()
        .parse::<Real>()
        .map_err(|_| "not a number".to_string())
}

/// `x` when `ok` and finite, else `must be {what}`.
fn check(x: Real, ok: bool, what: &str) -> Result<Real, String> {
    if ok && x.is_finite() {
        Ok(x)
    } else {
        Err(format!("must be {what}"))
    }
}

/// The refusal of an argument whose cost, estimated from its value and the design, is above
/// [`MEMORY_LIMIT_BYTES`] (the limit designs get) or `seconds` above the print solid's
/// [`TIME_LIMIT_SECONDS`]: `--grid 0.0001: the print solid would need about 2.8e16 bytes of memory (…), more
/// than stentkit's limit of 8.0 GB: give a --grid of at least 0.0277 mm`. `argument` is the flag and its
/// value as typed, `task` what it is for, `what` the estimate's parts in words, `instead` the value that fits.
pub(crate) fn too_costly(
    argument: &str,
    task: &str,
    bytes: Real,
    seconds: Real,
    what: &str,
    instead: &str,
) -> BadInput {
    let cost = if bytes > MEMORY_LIMIT_BYTES {
        format!(
            "would need about {} of memory ({what}), more than stentkit's limit of {}",
            human_bytes(bytes),
            human_bytes(MEMORY_LIMIT_BYTES)
        )
    } else {
        format!(
            "would take about {} ({what}, {} of memory), more than stentkit's limit of {} for it",
            duration(seconds),
            human_bytes(bytes),
            duration(TIME_LIMIT_SECONDS)
        )
    };
    BadInput(format!("{argument}: {task} {cost}: {instead}"))
}

/// `20 s`, `12 min`, `5.3 h`, `13 days`.
fn duration(seconds: Real) -> String {
    if seconds < 120.0 {
        format!("{seconds:.0} s")
    } else if seconds < 7200.0 {
        format!("{:.0} min", seconds / 60.0)
    } else if seconds < 2.0 * 86400.0 {
        format!("{:.1} h", seconds / 3600.0)
    } else {
        format!("{} days", Short::rounded(seconds / 86400.0, 2))
    }
}

/// A count for a message: whole below a million, `2.03e12` above.
pub(crate) fn count(x: Real) -> String {
    if x < 1e6 {
        format!("{x:.0}")
    } else {
        format!("{x:.2e}")
    }
}

/// `x` > 0 rounded up to three significant digits, for a least value to suggest (`2.02e-7` for
/// `2.0101451485608872e-7`).
pub(crate) fn rounded_up(x: Real) -> Short {
    let scale = Real::powi(10.0, x.log10().floor() as i32 - 2);
    Short::rounded((x / scale).ceil() * scale, 3)
}

/// A number for a message: shortest round trip, in exponent form far from 1 ([`Short`]).
pub(crate) fn short(x: Real) -> String {
    Short(x).to_string()
}
