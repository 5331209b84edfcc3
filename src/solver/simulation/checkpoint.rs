//! Checkpoints: the whole state of a simulation at a converged step as a plain value ([`Checkpoint`]), and
//! the restore that continues from it **bit for bit** as the uninterrupted simulation would.
//!
//! What "the whole state" is: what a step changes, as the [`StepSnapshot`] that a roll-back also puts back
//! (the clock — time, step count, step size and cuts of the step in progress, error control —, the
//! configuration (control points, rotations, curvatures, multipliers) and the last step's increment, the release
//! ramps captured and whether the gauge constraints are active, the arc-length state, the point terms' states
//! ([`crate::solver::terms`])); the materials' internal variables; and the records an abandoned attempt does not
//! undo: the gauge constraints once built (their frozen positions), the notices said and their flags, the
//! stabiliser's memory, the solver's timing; and
//! — because Newton reuses a factorisation of the tangent across iterations and steps while it contracts
//! (`solver.reuse_factorisation`) — what the current factorisation was computed from: the state, the section
//! laws, the loads, the gauge activity and the terms' states at the iterate where that tangent was assembled
//! ([`TangentOrigin`]). A restore assembles and factorises that tangent again (the same numbers in the same
//! order give the same factors), so the restored run reuses exactly the factorisation the uninterrupted run
//! does. Without it a restored run would refactorise at its first iteration and converge to a slightly
//! different iterate (within the Newton tolerance, not bitwise).
//!
//! The simulation keeps the tangent's origin as it goes: at each successful factorisation it copies the state
//! and the section laws into a buffer it reuses (about 0.3 kB per collocation point: 0.8 MB on the curved
//! stent, a fraction of a millisecond against the ~10 ms of a factorisation). It also keeps, for the attempt of
//! a step in progress, the origin of the factorisation that attempt started with (by swapping buffers when the
//! attempt first factorises anew), so that an interrupted attempt can take the factorisation back to it
//! (`TangentRecord::revert_attempt`): a checkpoint taken after an interruption is then as good as one taken
//! between steps.
//!
//! A checkpoint names its model by a fingerprint ([`model_fingerprint`]): restoring into a simulation of
//! another model is refused. Writing a checkpoint to a file is the `io` layer's business
//! (`io::checkpoint`); this module owns no format.

use super::Simulation;
use super::timing::SolverTiming;
use super::{Restorable, StepSnapshot};
use crate::material::{ConstitutiveLaw, LAW_NUMBERS, MaterialError, MaterialState, SectionLaw};
use crate::math::{Real, Vec3};
use crate::model::Model;
use crate::solver::SolverError;
use crate::solver::assembly::Actions;
use crate::solver::state::State;
use crate::solver::terms::{Constraint, PointTerm};

/// Everything a simulation needs to continue exactly from where it was ([`Simulation::checkpoint`]): what a
/// step changes ([`StepSnapshot`], the value a roll-back puts back too) and the run's records that an
/// abandoned attempt does not undo. Plain data (numbers, vectors, strings), so that any format can store it.
#[derive(Debug, Clone, PartialEq)]
pub struct Checkpoint {
    /// [`model_fingerprint`] of the model simulated.
    pub model: u64,
    /// What a step changes: clock, configuration, last increment, release ramps and gauge activity,
    /// arc-length state, point terms' states.
    pub snapshot: StepSnapshot,
    /// Per material that some patch uses: its index in `Model::materials` and its saved state
    /// ([`ConstitutiveLaw::save_state`]).
    pub materials: Vec<(usize, Vec<Real>)>,
    /// Material notices said, as `(material, kind)`.
    pub material_notices: Vec<(usize, String)>,
    /// Every notice said so far, in order.
    pub notices: Vec<String>,
    /// Whether a step accepted at the round-off floor has been reported.
    pub round_off_reported: bool,
    /// The gauge constraints, if built: the positions they freeze, by node.
    pub gauge: Option<Vec<(usize, Vec3)>>,
    /// What the current factorisation was computed from; `None` when there is none.
    pub tangent: Option<TangentOrigin>,
    /// Where the solver's time went so far.
    pub timing: SolverTiming,
    /// The stabiliser's memory (`super::stabilisation`).
    pub stabiliser: super::StabiliserState,
}

/// The iterate at which the current factorisation's tangent was assembled (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct TangentOrigin {
    /// The configuration.
    pub state: State,
    /// Every collocation point's section law ([`SectionLaw::to_numbers`]).
    pub laws: Vec<[Real; LAW_NUMBERS]>,
    /// The loads and prescribed values.
    pub actions: Actions,
    /// Whether the tangent includes the gauge constraints.
    pub gauge_active: bool,
    /// The point terms' states ([`crate::solver::terms::PointTerm::save`]), in the order of the list: a term's
    /// tangent may depend on what it keeps between steps.
    pub terms: Vec<Vec<Real>>,
}

/// Why a checkpoint cannot be restored.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CheckpointError {
    /// The checkpoint is of another model (or of another version of the same design).
    #[error(
        "the checkpoint is of another model (fingerprint {found:016x}, this model's is {expected:016x})"
    )]
    ModelMismatch {
        /// This model's fingerprint.
        expected: u64,
        /// The checkpoint's.
        found: u64,
    },
    /// A part of the checkpoint has another size than this model's (a damaged checkpoint).
    #[error("the checkpoint's {what} has {found} entries where this model has {expected}")]
    Size {
        /// Which part.
        what: &'static str,
        /// This model's size.
        expected: usize,
        /// The checkpoint's.
        found: usize,
    },
    /// A material state cannot be restored.
    #[error("material {material}: {source}")]
    Material {
        /// Index into `Model::materials`.
        material: usize,
        /// Why.
        source: MaterialError,
    },
    /// A point term cannot take the state the checkpoint kept for it.
    #[error(
        "the checkpoint's state of term `{term}` has {found} numbers where it needs {expected}"
    )]
    Term {
        /// The term's name.
        term: &'static str,
        /// The numbers it needs.
        expected: usize,
        /// The checkpoint's.
        found: usize,
    },
    /// The gauge system or the factorisation could not be rebuilt.
    #[error("rebuilding the linear system: {0}")]
    Solver(#[from] SolverError),
}

/// The fingerprint of `model` ([`crate::model::fingerprint`]: a hash of its serialised, versioned
/// description). Two models with the same fingerprint are the same model for all practical purposes (a
/// collision of two different models has probability ~2⁻⁶⁴).
pub fn model_fingerprint(model: &Model) -> u64 {
    crate::model::fingerprint::fingerprint(model)
}

/// The simulation's record of its current factorisation's origin, kept as it goes (module docs).
#[derive(Debug, Clone, Default)]
pub(super) struct TangentRecord {
    /// The current factorisation's origin.
    current: Origin,
    /// The loads of the tangent assembled last (not necessarily factorised yet).
    pending_actions: Option<Actions>,
    /// Factorisations so far.
    generation: u64,
    /// The attempt of a step in progress, if marked: the generation at its start, and whether `before` holds
    /// the origin of the factorisation it started with (saved at its first factorisation).
    attempt: Option<(u64, bool)>,
    /// The origin of the factorisation an attempt started with, once the attempt factorised anew.
    before: Origin,
}

/// Where a factorisation's tangent was assembled.
#[derive(Debug, Clone, Default)]
struct Origin {
    /// Whether the other fields describe a factorisation.
    valid: bool,
    state: Option<State>,
    laws: Vec<SectionLaw>,
    actions: Option<Actions>,
    gauge_active: bool,
    /// The point terms' states.
    terms: Vec<Vec<Real>>,
}

impl TangentRecord {
    /// A tangent was assembled with these loads.
    pub(super) fn assembled(&mut self, actions: &Actions) {
        match &mut self.pending_actions {
            // Field by field: `Vec::clone_from` reuses the memory.
            Some(a) => {
                a.node_force.clone_from(&actions.node_force);
                a.node_moment.clone_from(&actions.node_moment);
                a.prescribed.clone_from(&actions.prescribed);
                a.dist_force.clone_from(&actions.dist_force);
                a.dist_couple.clone_from(&actions.dist_couple);
            }
            None => self.pending_actions = Some(actions.clone()),
        }
    }

    /// The tangent assembled last was factorised at this state, these laws, gauge activity and terms.
    pub(super) fn factorised(
        &mut self,
        state: &State,
        laws: &[SectionLaw],
        gauge_active: bool,
        terms: &[Box<dyn PointTerm + Send>],
    ) {
        if let Some((_, saved @ false)) = &mut self.attempt {
            // The first factorisation of an attempt: keep the one it started with (buffers swapped, no copy).
            std::mem::swap(&mut self.before, &mut self.current);
            *saved = true;
        }
        let origin = &mut self.current;
        match &mut origin.state {
            Some(s) => s.copy_from(state),
            None => origin.state = Some(state.clone()),
        }
        // (No allocation once the capacity is there.)
        origin.laws.clear();
        origin.laws.extend_from_slice(laws);
        std::mem::swap(&mut origin.actions, &mut self.pending_actions);
        origin.gauge_active = gauge_active;
        origin.terms.resize_with(terms.len(), Vec::new);
        for (values, term) in origin.terms.iter_mut().zip(terms) {
            values.clear();
            term.save(values);
        }
        origin.valid = origin.actions.is_some();
        self.generation += 1;
    }

    /// The factorisations were forgotten.
    pub(super) fn invalidate(&mut self) {
        self.current.valid = false;
        self.attempt = None;
    }

    /// An attempt of a step starts with the current factorisation.
    pub(super) fn begin_attempt(&mut self) {
        self.attempt = Some((self.generation, false));
    }

    /// The attempt in progress converged.
    pub(super) fn end_attempt(&mut self) {
        self.attempt = None;
    }

    /// The attempt in progress was abandoned: the record goes back to the factorisation it started with.
    /// Returns what the linear system must do: [`Revert::Keep`] its factorisation (the attempt made none),
    /// [`Revert::Refactor`] the recorded origin's tangent (the attempt replaced it), or [`Revert::Forget`] it
    /// (the attempt started with none).
    pub(super) fn revert_attempt(&mut self) -> Revert {
        match self.attempt.take() {
            Some((generation, _)) if generation == self.generation => Revert::Keep,
            Some((_, true)) => {
                std::mem::swap(&mut self.before, &mut self.current);
                if self.current.valid {
                    Revert::Refactor
                } else {
                    Revert::Forget
                }
            }
            _ => Revert::Forget,
        }
    }
}

/// What an abandoned attempt leaves to the linear system ([`TangentRecord::revert_attempt`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Revert {
    /// The factorisation is the one the attempt started with.
    Keep,
    /// The factorisation the attempt started with must be made again from its recorded origin.
    Refactor,
    /// There is none to go back to.
    Forget,
}

impl Simulation<'_> {
    /// The whole state at this point (module docs): restoring it into a simulation of the same model
    /// ([`Simulation::restore`]) continues exactly as this one does. Taken between steps (after
    /// [`Simulation::step`] returned, or in [`super::Observer::step`]).
    pub fn checkpoint(&self) -> Checkpoint {
        let materials = self
            .materials
            .groups
            .iter()
            .map(|g| {
                let mut values = Vec::new();
                self.model.materials()[g.material].save_state(&g.state, &mut values);
                (g.material, values)
            })
            .collect();
        let active_factored = match (&self.releases.gauge, self.releases.gauge_active) {
            (Some((_, system, _)), true) => system.is_factored(),
            _ => self.work.system.is_factored(),
        };
        let record = &self.work.tangent.current;
        let tangent = match (&record.state, &record.actions) {
            (Some(state), Some(actions))
                if record.valid
                    && active_factored
                    && record.gauge_active == self.releases.gauge_active =>
            {
                Some(TangentOrigin {
                    state: state.clone(),
                    laws: record.laws.iter().map(SectionLaw::to_numbers).collect(),
                    actions: actions.clone(),
                    gauge_active: record.gauge_active,
                    terms: record.terms.clone(),
                })
            }
            _ => None,
        };
        Checkpoint {
            model: model_fingerprint(self.model),
            snapshot: self.snapshot(),
            materials,
            material_notices: self.materials.said.clone(),
            notices: self.record.notices.clone(),
            round_off_reported: self.record.round_off_reported,
            gauge: self
                .releases
                .gauge
                .as_ref()
                .map(|(g, _, _)| g.frozen.clone()),
            tangent,
            timing: self.record.timing.clone(),
            stabiliser: self.stabiliser.memory,
        }
    }

    /// Continues from `checkpoint`, taken ([`Simulation::checkpoint`]) from a simulation of the same model: the
    /// steps that follow are bit for bit those of that simulation. Restoring a checkpoint of the state a
    /// simulation is in changes nothing.
    ///
    /// # Errors
    /// [`CheckpointError::ModelMismatch`] for a checkpoint of another model, [`CheckpointError::Size`] or
    /// [`CheckpointError::Material`] for a damaged one (the simulation is then unchanged), and
    /// [`CheckpointError::Solver`] when the gauge system or the factorisation cannot be rebuilt, and
    /// [`CheckpointError::Term`] when a point term cannot take its state (then the simulation must not be used).
    pub fn restore(&mut self, checkpoint: &Checkpoint) -> Result<(), CheckpointError> {
        let expected = model_fingerprint(self.model);
        if checkpoint.model != expected {
            return Err(CheckpointError::ModelMismatch {
                expected,
                found: checkpoint.model,
            });
        }
        self.check_sizes(checkpoint)?;
        // The materials first, into copies: a damaged state leaves the simulation as it was.
        let mut states: Vec<MaterialState> = Vec::with_capacity(self.materials.groups.len());
        for (group, (material, values)) in self.materials.groups.iter().zip(&checkpoint.materials) {
            if group.material != *material {
                return Err(CheckpointError::Size {
                    what: "list of materials",
                    expected: group.material,
                    found: *material,
                });
            }
            let mut state = group.state.clone();
            self.model.materials()[group.material]
                .restore_state(&mut state, values)
                .map_err(|source| CheckpointError::Material {
                    material: group.material,
                    source,
                })?;
            states.push(state);
        }
        for (group, state) in self.materials.groups.iter_mut().zip(states) {
            group.state = state;
        }
        self.materials.refresh_laws(self.model.materials());
        // Each term's state at the tangent's origin is checked by restoring it first (module docs of
        // `crate::solver::terms`), then the snapshot's own with every other part a step changes.
        if let Some(origin) = &checkpoint.tangent {
            self.terms.restore(&origin.terms)?;
        }
        self.put_back(&checkpoint.snapshot)?;
        self.materials.said.clone_from(&checkpoint.material_notices);
        self.record.notices.clone_from(&checkpoint.notices);
        self.record.round_off_reported = checkpoint.round_off_reported;
        self.stabiliser.memory = checkpoint.stabiliser;
        self.stabiliser.damping = None;
        self.work.system.invalidate();
        self.work.tangent.invalidate();
        self.releases.gauge = None;
        if let Some(frozen) = &checkpoint.gauge {
            let mut positions = vec![Vec3::zeros(); self.model.nodes.len()];
            for &(k, x) in frozen {
                positions[k] = x;
            }
            self.build_gauge(&positions, checkpoint.snapshot.clock.time)?;
        }
        if let Some(origin) = &checkpoint.tangent {
            // The tangent of the current factorisation, assembled and factorised again at its iterate.
            self.work.tangent.current = Origin {
                valid: true,
                state: Some(origin.state.clone()),
                laws: origin.laws.iter().map(SectionLaw::from_numbers).collect(),
                actions: Some(origin.actions.clone()),
                gauge_active: origin.gauge_active,
                terms: origin.terms.clone(),
            };
            self.refactor_recorded()?;
        }
        self.releases.gauge_active &= self.releases.gauge.is_some();
        let multipliers = self.releases.active_gauge().map_or(0, |g| g.len());
        if self.solution.state.multipliers.len() != multipliers {
            return Err(CheckpointError::Size {
                what: "gauge multipliers",
                expected: multipliers,
                found: self.solution.state.multipliers.len(),
            });
        }
        self.record.timing = checkpoint.timing.clone();
        Ok(())
    }

    /// Assembles and factorises again the tangent of the recorded origin (its state, section laws, loads, gauge
    /// activity and terms' states): the factorisation it had, bit for bit. The simulation's own state, laws,
    /// gauge activity and terms' states are left as they were.
    pub(super) fn refactor_recorded(&mut self) -> Result<(), SolverError> {
        let origin = std::mem::take(&mut self.work.tangent.current);
        let (Some(state), Some(actions)) = (&origin.state, &origin.actions) else {
            return Ok(());
        };
        let own_state = std::mem::replace(&mut self.solution.state, state.clone());
        let own_laws = std::mem::replace(&mut self.materials.laws, origin.laws.clone());
        let own_gauge = std::mem::replace(
            &mut self.releases.gauge_active,
            origin.gauge_active && self.releases.gauge.is_some(),
        );
        let own_terms = self.terms.save();
        self.swap_term_states(&origin.terms);
        self.work.system.invalidate();
        if let Some((_, system, _)) = &mut self.releases.gauge {
            system.invalidate();
        }
        let result = self
            .linearise(actions, true)
            .and_then(|_| self.factor_tangent());
        self.solution.state = own_state;
        self.materials.laws = own_laws;
        self.releases.gauge_active = own_gauge;
        self.swap_term_states(&own_terms);
        result
    }

    /// Puts the states `values` (one per term, saved by [`PointTerm::save`] from these very terms or checked
    /// when a checkpoint was restored) into the terms.
    fn swap_term_states(&mut self, values: &[Vec<Real>]) {
        let restored = super::restore_terms(&mut self.terms, values);
        assert!(
            restored.is_ok(),
            "a state a term saved or that a restore checked is refused: {restored:?}"
        );
    }

    /// The checkpoint's sizes against this model's (the terms' states are checked as they are restored).
    fn check_sizes(&self, c: &Checkpoint) -> Result<(), CheckpointError> {
        let points = self.disc.points.len();
        let controls = self.disc.control0.len();
        let mut checks = vec![
            (
                "control points",
                controls,
                c.snapshot.solution.state.control.len(),
            ),
            (
                "rotations",
                points,
                c.snapshot.solution.state.rotation.len(),
            ),
            ("curvatures", points, c.snapshot.solution.state.kappa.len()),
            (
                "curvature derivatives",
                points,
                c.snapshot.solution.state.kappa_s.len(),
            ),
            (
                "release ramps",
                self.model.nodes.len(),
                c.snapshot.releases.ramps.len(),
            ),
            (
                "list of point terms",
                self.terms.len(),
                c.snapshot.terms.len(),
            ),
            (
                "list of materials",
                self.materials.groups.len(),
                c.materials.len(),
            ),
        ];
        if !c.snapshot.releases.gauge_active {
            checks.push((
                "gauge multipliers",
                0,
                c.snapshot.solution.state.multipliers.len(),
            ));
        }
        if let Some(origin) = &c.tangent {
            let tangent = [
                (
                    "tangent's control points",
                    controls,
                    origin.state.control.len(),
                ),
                ("tangent's rotations", points, origin.state.rotation.len()),
                ("tangent's curvatures", points, origin.state.kappa.len()),
                (
                    "tangent's curvature derivatives",
                    points,
                    origin.state.kappa_s.len(),
                ),
                ("tangent's section laws", points, origin.laws.len()),
                (
                    "tangent's point terms",
                    self.terms.len(),
                    origin.terms.len(),
                ),
                (
                    "tangent's node loads",
                    self.model.nodes.len(),
                    origin.actions.node_force.len(),
                ),
            ];
            checks.extend(tangent);
        }
        for (what, expected, found) in checks {
            if expected != found {
                return Err(CheckpointError::Size {
                    what,
                    expected,
                    found,
                });
            }
        }
        if let Some(frozen) = &c.gauge
            && let Some(&(k, _)) = frozen.iter().find(|(k, _)| *k >= self.model.nodes.len())
        {
            return Err(CheckpointError::Size {
                what: "gauge's nodes",
                expected: self.model.nodes.len(),
                found: k + 1,
            });
        }
        Ok(())
    }
}
