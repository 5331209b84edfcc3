//! The variants of a model a study runs.
//!
//! A variation of the time stepping, the release ramp or the internal-variable update changes settings of a
//! built [`Model`] ([`TimeVariant`]): nothing is re-parsed. A variation of the geometry's discretisation (`p`,
//! `n`) or of a generated stent's crowns changes the patches, nodes and conditions, so the design is re-built
//! ([`VariedDesign::rebuild`]): the design language ([`crate::design`], above this layer) implements it.

use super::{StudyError, positive};
use crate::material::Integrator;
use crate::math::Real;
use crate::model::{Model, StepPlan, TimeSettings};

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
    /// A copy of `model` changed to this variant: the time settings through [`Model::with_time`] and the
    /// internal-variable update through [`Model::with_integrator`], which check them as the builder does.
    ///
    /// # Errors
    /// [`StudyError::InvalidSetting`] when a value is not positive and finite, [`StudyError::StepBeyondEnd`]
    /// when the step exceeds the end time, [`StudyError::Refused`] for error control with an internal-variable
    /// update that has no estimate, [`StudyError::Model`] for settings the builder refuses otherwise.
    pub fn of(&self, model: &Model) -> Result<Model, StudyError> {
        let mut time = model.time().clone();
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
        let mut model = model.clone();
        if let Some(integrator) = self.integrator {
            // The update is changed under fixed steps: error control is then checked once, for the new time
            // stepping with the new update (below and by `with_time`), not for either with the old other.
            let fixed = TimeSettings {
                tolerance: None,
                ..model.time().clone()
            };
            model = model.with_time(fixed)?.with_integrator(integrator)?;
        }
        // As the builder does: error control only where its estimate holds (`Integrator::companion`).
        if let Some(why) = time.error_control_refusal(model.materials()) {
            return Err(StudyError::Refused(why));
        }
        Ok(model.with_time(time)?)
    }
}

/// A geometry a study varies: the design is re-built ([`VariedDesign::rebuild`]); `None` keeps the design's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Remesh {
    /// Degree `p` of every patch.
    pub degree: Option<usize>,
    /// Control points `n` of every patch.
    pub points: Option<usize>,
    /// Crowns of a generated stent.
    pub crowns: Option<usize>,
}

/// A design a study varies: the model as designed, and the model re-built with another geometry ([`Remesh`]),
/// which only the design language can make (it generates, fits and validates the patches, joints and
/// conditions). [`crate::design::Design`] is one; `study` sits below `design` and sees a design through this
/// trait only.
pub trait VariedDesign {
    /// The model as designed.
    fn model(&self) -> &Model;

    /// The steps a run of the model as designed takes when no step is cut (an arc-length path: its increments).
    fn steps(&self) -> &StepPlan;

    /// The model re-built with the geometry `remesh`.
    ///
    /// # Errors
    /// [`StudyError::Design`] when the variant is refused (e.g. `n ≤ p`, crowns for a design without a stent).
    fn rebuild(&self, remesh: &Remesh) -> Result<Model, StudyError>;
}
