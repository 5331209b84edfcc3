//! Checks and thresholds shared by the builder, the stent it generates ([`crate::model::stent`]) and the
//! checked setters of a built [`crate::model::Model`] (`Model::with_name`, `with_record_times`,
//! `with_temperature`).

use super::field::{BuildError, Field, Result};
use crate::math::Real;
use crate::math::quote::quoted;
use crate::model::TimeFunction;

/// Fit deviation, as a fraction of the wire diameter, above which a build warns.
pub const FIT_WARNING_FRACTION: Real = 0.01;

/// Checks a discretisation: `p ≥ 2` (collocation of the strong form needs second derivatives), `n > p`.
pub(crate) fn check_discretisation(p: usize, n: usize, degree: Field, points: Field) -> Result<()> {
    if p < 2 {
        return Err(BuildError::new(
            degree,
            format!(
                "degree p = {p} is too low: collocation of the strong form needs second derivatives, so p ≥ 2"
            ),
        ));
    }
    if n <= p {
        return Err(BuildError::new(
            points,
            format!("n = {n} control points cannot carry degree p = {p}: need n > p"),
        ));
    }
    Ok(())
}

/// Longest model name \[bytes\]: the name is the run folder's name (`runs/<name>`), and 255 bytes is the
/// longest file name of the usual file systems (ext4, XFS, Btrfs, APFS).
pub(crate) const MAX_NAME_BYTES: usize = 255;

/// What a model's (a design's) name may be, as the errors say it.
pub(crate) const NAME_RULE: &str = "a name becomes the run folder `runs/<name>`, so it must be one folder name: not empty, not `.` or `..`, at most 255 bytes, without `/`, `\\` or control characters";

/// Why `name` cannot be a run folder's name, if it cannot: a single normal path component on every platform
/// (no separator, no `.` or `..`, no absolute path or drive prefix), without control characters. The design
/// layer says it in the design's words, [`check_model_name`] in the builder's.
pub(crate) fn check_name(name: &str) -> std::result::Result<(), String> {
    if name.is_empty() {
        return Err("it is empty".into());
    }
    if name == "." || name == ".." {
        return Err("it names a folder itself, not a new one".into());
    }
    if let Some(c) = name.chars().find(|&c| c == '/' || c == '\\') {
        return Err(format!("it contains `{c}`, a path separator"));
    }
    if let Some(c) = name.chars().find(|c| c.is_control()) {
        return Err(format!(
            "it contains the control character {}",
            c.escape_debug()
        ));
    }
    if name.len() > MAX_NAME_BYTES {
        return Err(format!("it has {} bytes", name.len()));
    }
    // Whatever the platform adds (a Windows drive prefix such as `C:`): one normal component, itself.
    let mut components = std::path::Path::new(name).components();
    match (components.next(), components.next()) {
        (Some(std::path::Component::Normal(c)), None) if c == name => Ok(()),
        _ => Err("it is not a plain folder name on this system".into()),
    }
}

/// Checks a model's name ([`check_name`]) at [`Field::Name`].
pub(crate) fn check_model_name(name: &str) -> Result<()> {
    check_name(name).map_err(|why| {
        BuildError::new(
            Field::Name,
            format!(
                "{} is not a valid model name ({why}): {NAME_RULE}",
                quoted(name)
            ),
        )
    })
}

/// The record times `times` as a model holds them: each finite and within `(0, end]` (the start is the
/// reference state, which no step lands on), then sorted and without repeats.
///
/// # Errors
/// At [`Field::RecordTime`] of the first time outside `(0, end]`.
pub(crate) fn record_times(times: &[Real], end: Real) -> Result<Vec<Real>> {
    if let Some((index, t)) = times
        .iter()
        .enumerate()
        .find(|&(_, &t)| !(t > 0.0 && t <= end))
    {
        return Err(BuildError::new(
            Field::RecordTime { index },
            format!("record time {t} is not within the run: allowed: 0 < t ≤ the end time {end}"),
        ));
    }
    let mut times = times.to_vec();
    times.sort_by(Real::total_cmp);
    times.dedup();
    Ok(times)
}

/// Checks a temperature schedule: every value finite (a table is checked so when it is made,
/// [`TimeFunction::try_table`], a constant is not).
pub(crate) fn check_temperature(temperature: &TimeFunction) -> Result<()> {
    match temperature.points().iter().find(|(_, v)| !v.is_finite()) {
        Some((t, v)) => Err(BuildError::new(
            Field::Temperature,
            format!("the temperature {v} °C at t = {t} is not finite"),
        )),
        None => Ok(()),
    }
}
