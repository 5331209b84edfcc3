//! A design as a study varies it ([`VariedDesign`]): the model as designed, and the model re-built with another
//! mesh or crown count by parsing the design's text again with [`DesignOverrides`]. `study` sits below this
//! layer and sees a design through that trait; [`read_varied`] is the reader its stability maps are handed.

use super::{Design, DesignError, DesignOverrides, parse_design, parse_design_with};
use crate::model::{Model, StepPlan};
use crate::study::StudyError;
use crate::study::variant::{Remesh, VariedDesign};
use std::path::Path;

impl VariedDesign for Design {
    fn model(&self) -> &Model {
        &self.model
    }

    fn steps(&self) -> &StepPlan {
        &self.steps
    }

    /// The design's YAML source parsed again with the geometry as [`DesignOverrides`] (the design layer
    /// generates, fits and validates the patches, joints and conditions).
    fn rebuild(&self, remesh: &Remesh) -> Result<Model, StudyError> {
        let overrides = DesignOverrides {
            degree: remesh.degree,
            points: remesh.points,
            crowns: remesh.crowns,
            ..DesignOverrides::default()
        };
        Ok(parse_design_with(&self.source, &self.path, &overrides)?.model)
    }
}

impl From<DesignError> for StudyError {
    fn from(e: DesignError) -> Self {
        StudyError::Design(Box::new(e))
    }
}

/// The design `text`, named `path` in errors and as its default name, as a design a study can vary
/// ([`crate::study::stability::ReadDesign`]).
///
/// # Errors
/// [`StudyError::Design`] when the text is not a valid design.
pub fn read_varied(text: &str, path: &Path) -> Result<Box<dyn VariedDesign>, StudyError> {
    Ok(Box::new(parse_design(text, path)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::{DesignOverrides, parse_design, parse_design_with};
    use crate::material::Integrator;
    use crate::study::variant::{Remesh, TimeVariant};
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
            integrator: Some(crate::design::dto::IntegratorDto::Exponential),
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
        let rebuilt = design.rebuild(&remesh).expect("two crowns");
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
        assert!(matches!(bend.rebuild(&remesh), Err(StudyError::Design(_))));
    }
}
