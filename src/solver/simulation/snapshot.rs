//! What a step changes, as one value ([`StepSnapshot`]), and the one way it is taken and put back.
//!
//! A [`super::Simulation`] is a composition of parts (module docs of [`super`]). Those a step changes
//! implement [`Restorable`]: each says, in its `impl`, what it saves and how it comes back, and
//! [`StepSnapshot`] holds one saved value per such part. Two paths use it:
//! - **roll-back** (`Simulation::roll_back`): the snapshot taken at the start of every attempt of a step is
//!   put back when the attempt fails, is rejected by error control or is interrupted;
//! - **checkpoint** ([`super::Checkpoint::snapshot`]): a checkpoint is the snapshot between steps plus the run's
//!   records that an abandoned attempt does not undo (module docs of [`super::checkpoint`]).
//!
//! A new part that a step changes is one more field here and one more `impl Restorable`; [`Simulation::snapshot`]
//! builds the struct and [`Simulation::put_back`] takes it apart field by field (a pattern without `..`), so
//! the compiler asks for the new field on both paths at once. The checkpoint file (`io::checkpoint`) then
//! encodes and decodes the new field, under a new format version.
//!
//! The materials' internal variables are the one thing a step changes that is not here: a material keeps the
//! data of its last converged step itself ([`crate::material::ConstitutiveLaw::roll_back`], which a roll-back
//! calls, costs no copy per attempt), and a checkpoint saves them through the same interface
//! ([`crate::material::ConstitutiveLaw::save_state`]).

use super::{ArcState, CheckpointError, Clock, ReleaseSnapshot, Simulation, SolutionSnapshot};
use crate::math::Real;
use crate::solver::terms::PointTerm;

/// A part of a simulation that a step changes: what it saves into a [`StepSnapshot`] and how it comes back.
pub(super) trait Restorable {
    /// What the part saves.
    type Saved;

    /// The part's saved value now.
    fn save(&self) -> Self::Saved;

    /// Puts back a value [`Restorable::save`] made (in this simulation or, through a checkpoint, in one of the
    /// same model).
    ///
    /// # Errors
    /// [`CheckpointError`] when `saved` cannot be this part's (a damaged checkpoint, or one of a simulation
    /// with other terms); never for a value this very part saved.
    fn restore(&mut self, saved: &Self::Saved) -> Result<(), CheckpointError>;
}

/// Everything a step changes (module docs): the clock, the solution, the release ramps and gauge activity,
/// the arc-length path's state and the point terms' states.
#[derive(Debug, Clone, PartialEq)]
pub struct StepSnapshot {
    /// Time, steps, step size and cuts, and the error controller's memory.
    pub clock: Clock,
    /// The configuration and the last step's increment.
    pub solution: SolutionSnapshot,
    /// The release ramps captured and whether the gauge constraints apply.
    pub releases: ReleaseSnapshot,
    /// Where an arc-length run is on its path (`None` for time-driven runs and before the first increment).
    pub arc: Option<ArcState>,
    /// Per point term of the simulation's list, in its order: the numbers it keeps between steps
    /// ([`PointTerm::save`]).
    pub terms: Vec<Vec<Real>>,
}

impl Restorable for Clock {
    type Saved = Clock;

    /// All of it.
    fn save(&self) -> Clock {
        *self
    }

    fn restore(&mut self, saved: &Clock) -> Result<(), CheckpointError> {
        *self = *saved;
        Ok(())
    }
}

impl Restorable for Option<ArcState> {
    type Saved = Option<ArcState>;

    /// All of it.
    fn save(&self) -> Option<ArcState> {
        self.clone()
    }

    fn restore(&mut self, saved: &Option<ArcState>) -> Result<(), CheckpointError> {
        self.clone_from(saved);
        Ok(())
    }
}

impl Restorable for Vec<Box<dyn PointTerm + Send>> {
    type Saved = Vec<Vec<Real>>;

    /// Every term's state ([`PointTerm::save`]), in the order of the list.
    fn save(&self) -> Vec<Vec<Real>> {
        self.iter()
            .map(|t| {
                let mut values = Vec::new();
                t.save(&mut values);
                values
            })
            .collect()
    }

    /// Every term takes its state ([`restore_terms`]).
    fn restore(&mut self, saved: &Vec<Vec<Real>>) -> Result<(), CheckpointError> {
        restore_terms(self, saved)
    }
}

/// Every term of `terms` takes its state from `saved` ([`PointTerm::restore`]), which must be as long as the
/// list.
///
/// # Errors
/// [`CheckpointError::Size`] for a list of another length, [`CheckpointError::Term`] for a state a term
/// refuses.
pub(super) fn restore_terms(
    terms: &mut [Box<dyn PointTerm + Send>],
    saved: &[Vec<Real>],
) -> Result<(), CheckpointError> {
    if saved.len() != terms.len() {
        return Err(CheckpointError::Size {
            what: "list of point terms",
            expected: terms.len(),
            found: saved.len(),
        });
    }
    for (term, values) in terms.iter_mut().zip(saved) {
        term.restore(values)
            .map_err(|expected| CheckpointError::Term {
                term: term.name(),
                expected,
                found: values.len(),
            })?;
    }
    Ok(())
}

impl Simulation<'_> {
    /// What a step changes, now (module docs).
    pub(super) fn snapshot(&self) -> StepSnapshot {
        StepSnapshot {
            clock: self.clock.save(),
            solution: self.solution.save(),
            releases: self.releases.save(),
            arc: self.arc.save(),
            terms: self.terms.save(),
        }
    }

    /// Puts back a snapshot this simulation took itself ([`Self::put_back`]): a part that refuses it is a
    /// programmer error, and panics.
    pub(super) fn put_back_own(&mut self, snapshot: &StepSnapshot) {
        let restored = self.put_back(snapshot);
        assert!(
            restored.is_ok(),
            "a part refused the snapshot it saved itself: {restored:?}"
        );
    }

    /// Puts every part a step changes back as `snapshot` has it (module docs).
    ///
    /// # Errors
    /// As [`Restorable::restore`]: a part cannot take its value (then the simulation must not be used).
    pub(super) fn put_back(&mut self, snapshot: &StepSnapshot) -> Result<(), CheckpointError> {
        let StepSnapshot {
            clock,
            solution,
            releases,
            arc,
            terms,
        } = snapshot;
        self.clock.restore(clock)?;
        self.solution.restore(solution)?;
        self.releases.restore(releases)?;
        self.arc.restore(arc)?;
        self.terms.restore(terms)
    }
}
