//! The variants of a model a study runs.
//!
//! A variation of the time stepping, the release ramp or the internal-variable update changes settings of a
//! built [`Model`] ([`TimeVariant`]): nothing is re-parsed. A variation of the geometry's discretisation (`p`,
//! `n`) or of a generated stent's crowns changes the patches, nodes and conditions, so the design is re-built
//! from its source ([`rebuild`]) — the one place a study goes back to the design file's layer, to be swapped
//! for the model builder when it exists.

use super::{StudyError, positive};
use crate::io::design::{Design, DesignOverrides, parse_design_with};
use crate::material::{Integrator, MaterialLaw, MaxwellLaw};
use crate::math::Real;
use crate::model::Model;

/// Settings of the time stepping and the internal-variable update a study changes on a built model; `None`
/// keeps the model's.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TimeVariant {
    /// End time `time.end` \[time\], > 0.
    pub end: Option<Real>,
    /// Nominal step `time.step` \[time\], > 0 and at most the end time. The smallest step `time.min_step` keeps
    /// its ratio to the step (the design file's default, `step/1024`, stays the default), and a release ramp of
    /// one step (the default) stays one step; a ramp of another length is a duration and is kept.
    pub step: Option<Real>,
    /// Release ramp `time.release_ramp` \[time\], > 0 (applied after `step`).
    pub release_ramp: Option<Real>,
    /// Error-controlled steps at this time-error tolerance (`time.tolerance`, > 0; `step` is then the first
    /// step). A `step` without a tolerance means fixed steps: the model's tolerance is cleared.
    pub tolerance: Option<Real>,
    /// Internal-variable update of every Maxwell material (an elastic one has no internal variables).
    pub integrator: Option<Integrator>,
}

impl TimeVariant {
    /// Changes `model` to this variant.
    ///
    /// # Errors
    /// [`StudyError::InvalidSetting`] when a value is not positive and finite, [`StudyError::StepBeyondEnd`]
    /// when the step exceeds the end time, [`StudyError::Refused`] for error control with an internal-variable
    /// update that has no estimate; `model` may then be partly changed.
    pub fn apply(&self, model: &mut Model) -> Result<(), StudyError> {
        let time = &mut model.time;
        if let Some(end) = self.end {
            time.end = positive("the end time", end)?;
        }
        if let Some(h) = self.step {
            let h = positive("the time step", h)?;
            let old = time.step;
            time.min_step = h * (time.min_step / old);
            // The default ramp is the step itself, not a value near it.
            if time.release_ramp == old {
                time.release_ramp = h;
            }
            time.step = h;
        }
        match (self.tolerance, self.step) {
            (Some(tol), _) => time.tolerance = Some(positive("the time-error tolerance", tol)?),
            (None, Some(_)) => time.tolerance = None,
            (None, None) => {}
        }
        if let Some(ramp) = self.release_ramp {
            time.release_ramp = positive("the release ramp", ramp)?;
        }
        if time.step > time.end {
            return Err(StudyError::StepBeyondEnd {
                step: time.step,
                end: time.end,
            });
        }
        if let Some(integrator) = self.integrator {
            for law in &mut model.materials {
                if let MaterialLaw::Maxwell(maxwell) = law {
                    *maxwell = MaxwellLaw::new(maxwell.material().clone(), integrator);
                }
            }
        }
        // As the builder does: error control only where its estimate holds (`Integrator::companion`).
        if let Some(why) = model.time.error_control_refusal(&model.materials) {
            return Err(StudyError::Refused(why));
        }
        Ok(())
    }

    /// A copy of `model` changed to this variant ([`TimeVariant::apply`]).
    ///
    /// # Errors
    /// As [`TimeVariant::apply`].
    pub fn of(&self, model: &Model) -> Result<Model, StudyError> {
        let mut model = model.clone();
        self.apply(&mut model)?;
        Ok(model)
    }
}

/// A geometry a study varies: the design is re-built ([`rebuild`]); `None` keeps the design's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Remesh {
    /// Degree `p` of every patch.
    pub degree: Option<usize>,
    /// Control points `n` of every patch.
    pub points: Option<usize>,
    /// Crowns of a generated stent.
    pub crowns: Option<usize>,
}

/// The model of `design` re-built with the geometry `remesh`: today its YAML source parsed again with
/// [`DesignOverrides`] (the design layer generates, fits and validates the patches, joints and conditions).
///
/// # Errors
/// [`StudyError::Design`] when the variant is refused (e.g. `n ≤ p`, crowns for a design without a stent).
pub fn rebuild(design: &Design, remesh: &Remesh) -> Result<Model, StudyError> {
    let overrides = DesignOverrides {
        degree: remesh.degree,
        points: remesh.points,
        crowns: remesh.crowns,
        ..DesignOverrides::default()
    };
    Ok(parse_design_with(&design.source, &design.path, &overrides)?.model)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::design::parse_design;
    use std::path::Path;

    const BEND45: &str = include_str!("../../designs/bend45.yaml");

    // The variant gives the model the design file would give with the same settings: on the viscoelastic arch
    // (a Maxwell material), `time.end: 0.5`, `time.step: 0.25` and `material.integrator: exponential` make
    // `min_step = 0.25/1024` and `release_ramp = 0.25` by the file's defaults and the exponential update, to the
    // bit.
    #[test]
    fn a_time_variant_equals_the_file_with_the_same_settings() {
        const ARCH: &str = include_str!("../../designs/circular_arch.yaml");
        let path = Path::new("circular_arch.yaml");
        let design = parse_design(ARCH, path).expect("the arch parses");
        let varied = TimeVariant {
            end: Some(0.5),
            step: Some(0.25),
            integrator: Some(Integrator::Exponential),
            ..TimeVariant::default()
        }
        .of(&design.model)
        .expect("a valid variant");
        let overrides = DesignOverrides {
            end_time: Some(0.5),
            step: Some(0.25),
            integrator: Some(crate::io::design::dto::IntegratorDto::Exponential),
            ..DesignOverrides::default()
        };
        let file = parse_design_with(ARCH, path, &overrides).expect("overrides parse");
        assert_ne!(varied, design.model);
        assert_eq!(varied, file.model);
    }

    #[test]
    fn a_step_beyond_the_end_is_refused() {
        let design = parse_design(BEND45, Path::new("bend45.yaml")).expect("bend45 parses");
        let too_long = TimeVariant {
            step: Some(2.0),
            ..TimeVariant::default()
        };
        assert!(matches!(
            too_long.of(&design.model),
            Err(StudyError::StepBeyondEnd {
                step: 2.0,
                end: 1.0
            })
        ));
    }

    // The crown count goes through the design layer: the same model as the design text with `stent.crowns: 2`
    // written in (what the stability study did before, with a YAML edit). A design without a stent refuses a crown count.
    #[test]
    fn a_remeshed_stent_equals_the_edited_file() {
        const STENT: &str = include_str!("../../designs/straight_stent.yaml");
        let path = Path::new("straight_stent.yaml");
        let design = parse_design(STENT, path).expect("the straight stent parses");
        let remesh = Remesh {
            degree: Some(5),
            points: Some(14),
            crowns: Some(2),
        };
        let rebuilt = rebuild(&design, &remesh).expect("two crowns");
        assert_eq!(STENT.matches("\n  crowns: 6\n").count(), 1);
        let edited = STENT.replace("\n  crowns: 6\n", "\n  crowns: 2\n");
        let overrides = DesignOverrides {
            degree: Some(5),
            points: Some(14),
            ..DesignOverrides::default()
        };
        let file = parse_design_with(&edited, path, &overrides).expect("parses");
        assert_eq!(rebuilt, file.model);
        let bend = parse_design(BEND45, Path::new("bend45.yaml")).expect("bend45 parses");
        assert!(matches!(
            rebuild(&bend, &remesh),
            Err(StudyError::Design(_))
        ));
    }
}
