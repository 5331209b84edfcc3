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

/// Checks a contact law's settings: a positive penalty, band and tolerance (of the surfaces' contact and of the
/// wires').
pub(crate) fn contact_settings(settings: &crate::model::ContactSettings) -> Result<()> {
    let positive = |x: Real| x.is_finite() && x > 0.0;
    if positive(settings.penalty)
        && positive(settings.regularisation)
        && positive(settings.tolerance)
    {
        return Ok(());
    }
    Err(BuildError::new(
        Field::ContactSettings,
        format!(
            "the penalty ({}), the law's transition band ({}) and the penetration tolerance ({}) must be positive and finite",
            settings.penalty, settings.regularisation, settings.tolerance
        ),
    ))
}

/// Checks a model's contact (the checks [`super::ModelBuilder::contact`] lists), at the obstacle and part at
/// fault. A wire through a surface at the start is refused with where it is: the contact law would throw it out
/// with a force of the penalty times the penetration in the first step.
pub(crate) fn contact(contact: &crate::model::Contact, model: &crate::model::Model) -> Result<()> {
    use super::field::ObstacleField;
    use crate::model::{Surface, Wall};
    let settings = &contact.settings;
    contact_settings(settings)?;
    let positive = |x: Real| x.is_finite() && x > 0.0;
    let wire = model
        .patches
        .iter()
        .map(|p| 0.5 * model.sections[p.section].diameter())
        .fold(0.0, Real::max);
    for (index, obstacle) in contact.obstacles.iter().enumerate() {
        let at = |field| Field::Obstacle { index, field };
        if contact.obstacles[..index]
            .iter()
            .any(|o| o.name == obstacle.name)
        {
            return Err(BuildError::new(
                at(ObstacleField::Name),
                format!(
                    "two obstacles are named {}: names must be unique",
                    quoted(&obstacle.name)
                ),
            ));
        }
        let direction = match &obstacle.surface {
            Surface::Cylinder { axis, radius, .. } => Some((axis, radius)),
            Surface::Plane { normal, offset, .. } => Some((normal, offset)),
            Surface::Lumen(lumen) => {
                let narrowest = lumen
                    .radius_table()
                    .iter()
                    .map(|&(_, r)| r)
                    .fold(Real::INFINITY, Real::min);
                if !(narrowest > wire) {
                    return Err(BuildError::new(
                        at(ObstacleField::Schedule),
                        format!(
                            "the lumen's radius narrows to {narrowest}, not more than the wire's radius {wire}: no wire fits inside it"
                        ),
                    ));
                }
                None
            }
        };
        if let Some((direction, schedule)) = direction {
            if !((direction.norm() - 1.0).abs() <= 1e-9) {
                return Err(BuildError::new(
                    at(ObstacleField::Direction),
                    format!(
                        "the direction must be a unit vector (its length is {})",
                        direction.norm()
                    ),
                ));
            }
            let (lo, _) = schedule.range();
            if matches!(obstacle.surface, Surface::Cylinder { .. }) && !(lo > wire) {
                return Err(BuildError::new(
                    at(ObstacleField::Schedule),
                    format!(
                        "the cylinder's radius reaches {lo}, not more than the wire's radius {wire}: no wire fits inside it"
                    ),
                ));
            }
        }
        if !(obstacle.friction.is_finite() && obstacle.friction >= 0.0) {
            return Err(BuildError::new(
                at(ObstacleField::Friction),
                format!(
                    "the friction coefficient must be zero or positive and finite (it is {})",
                    obstacle.friction
                ),
            ));
        }
        match obstacle.wall {
            Wall::Rigid => {}
            Wall::Compliant {
                modulus,
                thickness,
                width,
            } => {
                if matches!(obstacle.surface, Surface::Plane { .. }) {
                    return Err(BuildError::new(
                        at(ObstacleField::Wall),
                        "a compliant wall is a thin tube (stiffness E_w h / R²): a plane's wall must be rigid".to_string(),
                    ));
                }
                if !(positive(modulus) && positive(thickness) && positive(width)) {
                    return Err(BuildError::new(
                        at(ObstacleField::Wall),
                        format!(
                            "a compliant wall needs a positive modulus ({modulus}), thickness ({thickness}) and width ({width})"
                        ),
                    ));
                }
            }
        }
        // The wires at the start: every patch sampled densely against the surface at t = 0 (an obstacle put
        // in place later is checked by the solver when it is: `crate::solver::terms::contact`).
        for patch in model.patches.iter().filter(|_| obstacle.is_active(0.0)) {
            let r = 0.5 * model.sections[patch.section].diameter();
            for x in patch.dense_points() {
                let Some(d) = obstacle.surface.distance(&x, 0.0) else {
                    continue;
                };
                if d.value - r < -settings.tolerance {
                    return Err(BuildError::new(
                        at(ObstacleField::Schedule),
                        format!(
                            "patch {} starts {:.4} through the surface (at {:.4}, {:.4}, {:.4}): a device must start clear of every obstacle",
                            quoted(&patch.name),
                            r - d.value,
                            x.x,
                            x.y,
                            x.z
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}
