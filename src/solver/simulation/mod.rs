//! Time stepping with Newton's method and automatic step cutting.
//!
//! A step from `t_n` to `t_{n+1}` (landing on every schedule breakpoint) solves the collocated equations by
//! Newton's method from the last converged state. Convergence is judged on normalised per-field norms
//! (DESIGN §4; deal.II step-44 style): the largest scaled residual of force rows, of moment rows and of
//! kinematic rows, and the largest translation increment over the patch length and rotation increment in
//! radians, must all be below the tolerance. A NaN or infinity anywhere stops the iteration at once. When
//! Newton fails the last converged state is restored and the step halved, down to `min_step`; after a success
//! the step grows back by doubling.
//!
//! **Progress.** A step's size is computed as `(t + h) − t`, which rounds to within half an ulp of `t + h`: at
//! `t = 1.75` a step meant to be `min_step = 2.44e-6` can come out larger by ~1e-10 of itself. The smallest step
//! is therefore recognised with an allowance of [`STEP_ROUND_OFF_ULPS`] ulps of the time reached (not a relative
//! `1e-12` of `min_step`, which round-off exceeds once `t/min_step ≳ 1e4`), and a halved step within that
//! allowance of `min_step` is `min_step` exactly. Every failure thus either halves the step or ends the run with
//! [`SolverError::StepFailed`]: a run makes progress or fails with a report, never retries the same step forever.
//!
//! **Round-off.** The normalised residual and increment cannot fall below their round-off floors (measured:
//! residuals 4e-13 … 1.5e-10, increments 2e-13 … 3e-10 on the 45° bend and the straight stent, growing with
//! `p² n²`). A tolerance below [`ROUND_OFF_TOLERANCE`] may be below that floor: there Newton accepts an iterate
//! that meets the stopping rule at [`ROUND_OFF_TOLERANCE`] once the residual stopped falling (an iteration with a
//! fresh tangent did not halve it), and says so once in [`Simulation::notices`] (time, residual reached,
//! tolerance asked); [`NewtonReport::at_round_off`] marks each such step. At tolerances from
//! [`ROUND_OFF_TOLERANCE`] up (the default is 1e-9) this rule never applies: the stopping rule is unchanged.
//!
//! **Error-controlled stepping.** With `time.tolerance` (a design's `time: {tolerance: 1e-4}` or `run --tol`)
//! every converged step gets a time-error estimate — how far the configuration would move had the internal
//! variables been advanced by a companion update (backward Euler for the second-order rules), measured in
//! Newton's normalised norm, so that a tolerance means the same on a stent and an arch, or, where held nodes
//! keep the configuration from showing it, the strain that carries the two updates' stress difference — and a
//! step whose estimate exceeds its share of the tolerance is rejected and retried shorter; the next step comes from a PI controller
//! with growth and shrink limits (`adaptive`). Steps still land on every schedule breakpoint (releases, load
//! and temperature breakpoints) but not on the record times (`output.history.times`, `output.snapshots.times`):
//! the state at a record time inside an accepted step comes from the integrator's continuous extension and is
//! told to the observers ([`Observer::requested`]; `dense`), so asking for an output does not change the steps.
//! Newton failures still halve the step, and a step at
//! `min_step` whose estimate is above the tolerance is accepted with a notice (said once). Fixed steps (no
//! tolerance) are unchanged. [`StepReport::error_estimate`] and [`StepReport::rejected`] report each step.
//!
//! **Arc-length continuation.** With `solver.path` arc length ([`crate::model::PathControl::ArcLength`]) a step
//! is an increment along the equilibrium path of the loads at `time.end` scaled by a load factor, held by an
//! arc-length constraint (Riks/Crisfield; `arclength`): it passes limit points in load and in displacement,
//! where time steps stop. [`StepReport::load_factor`] carries the load factor, [`Simulation::load_factor`] the
//! current one, and the step's `time` is the path parameter.
//!
//! **Stepping as an API.** [`Simulation::step`] takes one converged step (with the retries and cuts it needs)
//! and returns its [`StepReport`]; the caller reads the state between steps ([`Simulation::state`],
//! [`Simulation::probe_displacement`], [`Simulation::node_end_resultants`]). [`Simulation::run`] is the loop over
//! [`Simulation::step_with`] that tells a list of observers the caller owns ([`Observers`]) of each step.
//! [`Simulation::checkpoint`] and [`Simulation::restore`] save and restore the whole state, so that a restored
//! simulation continues bit for bit (`checkpoint`).
//!
//! **Interruption.** [`Observer::interrupted`] is polled by Newton before every iteration and by
//! [`Simulation::step_with`] before every attempt of a step (first, retried with a fresh tangent, or cut). When
//! it answers true the step in progress is abandoned and rolled back as a failed step is, `step_with` returns
//! [`StepOutcome::Interrupted`] and `run` returns at the last converged step with [`RunSummary::stopped`] set.
//! Unlike a failure, an interruption keeps the step size and cuts of the abandoned step and takes the
//! factorisation back to the one its attempt started with (kept, or made again from its recorded origin), so a
//! later `step` or `run` — or a checkpoint taken now — continues bit for bit as the uninterrupted run.
//!
//! **Parts.** A [`Simulation`] is the model, its discretisation, assembler, point terms and materials, and a
//! few parts, each a struct in its own module owning its fields: the [`Clock`] (time, steps, step size, cuts,
//! error control; `clock`), the solution (the configuration and the steps' increments; `solution`), the
//! releases (ramps and gauge constraints; `releases`), the arc-length path's state (`arclength`), the
//! stabiliser (its memory and the attempt's damping; `stabilisation`), the workspace (linear system,
//! assembly, increment, factorisation record; `workspace`), the run's record (notices, timing; `record`) and
//! fixed measures of the model (`measures`). What a step changes — clock, solution, releases, arc-length
//! state, the terms' states — is saved by one value, the [`StepSnapshot`] (`snapshot`): roll-back puts back
//! the snapshot taken at the start of an attempt, and a [`Checkpoint`] is that snapshot between steps plus the
//! run's records.
//!
//! The concepts live in their own files: `report` (what a step and a run report), `observer` (who is told),
//! `adaptive` (the time-error estimate and the step-size controller), `dense` (the states at requested times
//! between error-controlled steps), `arclength` (arc-length continuation),
//! `timing` (where the wall time went), `stepping` (the step loop and roll-back), `newton`
//! (Newton's method on normalised norms and its diagnostics), `releases` (release ramps and gauge constraints),
//! `constitutive` (the materials at the points: step preparation, commit, roll-back), `snapshot` (what a step
//! changes, taken and put back) and `checkpoint` (the whole state as a value, and its restore).
pub(crate) mod adaptive;
mod arclength;
pub(crate) mod checkpoint;
mod clock;
mod constitutive;
mod contact;
mod dense;
pub(crate) mod fields;
mod measures;
mod newton;
pub(crate) mod observer;
mod record;
mod releases;
pub(crate) mod report;
mod snapshot;
mod solution;
pub(crate) mod stabilisation;
mod stepping;
pub(crate) mod timing;
mod workspace;

pub use arclength::ArcState;
pub use checkpoint::{Checkpoint, CheckpointError, TangentOrigin, model_fingerprint};
pub use clock::Clock;
pub use fields::{PeakSurfaceStrain, PointFields, peak_surface_strain};
pub use newton::ROUND_OFF_TOLERANCE;
pub use observer::{NoObserver, Observer, Observers};
pub use releases::ReleaseSnapshot;
pub use report::{NewtonReport, RunSummary, StepReport};
pub use snapshot::StepSnapshot;
pub use solution::SolutionSnapshot;
pub use stabilisation::{StabiliserState, StepStabilisation};
pub use stepping::{STEP_FACTOR, STEP_ROUND_OFF_ULPS, StepOutcome};
pub use timing::SolverTiming;

use super::SolverError;
use super::assembly::{
    Actions, Assembler, Assembly, Linearisation, Sink, StepMaterial, point_position,
};
use super::discretisation::Discretisation;
use super::gauge::Gauge;
use super::linear::LinearSystem;
use super::state::State;
use super::terms::contact::SurfaceContact;
use super::terms::crossing::WireCrossing;
use super::terms::damping::Damping;
use super::terms::distributed::DistributedLoad;
use super::terms::wires::WireContact;
use super::terms::{Constraint, PointTerm, Terms};
use crate::math::{Real, Vec3};
use crate::model::{Model, ProbeLocation};
use constitutive::PointMaterials;
use snapshot::{Restorable, restore_terms};

/// A running simulation of one model: a composition of parts (module docs), each in its own module.
pub struct Simulation<'m> {
    model: &'m Model,
    disc: Discretisation,
    assembler: Assembler,
    /// The point terms every assembly includes, in the order they add up (before the damping of
    /// stabilisation): [`registered_terms`] and those added by [`Simulation::add_term`].
    terms: Vec<Box<dyn PointTerm + Send>>,
    /// Every material's points and internal variables, and every point's section law for the step being solved.
    materials: PointMaterials,
    /// Time, steps, the next step's size and the error controller's memory ([`Clock`]).
    clock: Clock,
    /// The configuration and the increments of the steps.
    solution: solution::Solution,
    /// Release ramps and gauge constraints.
    releases: releases::Releases,
    /// Where an arc-length run is on its path (`None` for time-driven runs, and before the first increment).
    arc: Option<arclength::ArcState>,
    /// The stabiliser's memory and the damping of the attempt in progress ([`stabilisation`]).
    stabiliser: stabilisation::Stabiliser,
    /// The linear system, the last assembly and increment, and the factorisation's origin.
    work: workspace::Workspace,
    /// What the run has said and spent.
    record: record::RunRecord,
    /// Fixed measures of the model: increment lengths, breakpoints, arc lengths and weights.
    measures: measures::Measures,
}

impl<'m> Simulation<'m> {
    /// Discretises the model, builds the sparsity pattern and analyses it.
    pub fn new(model: &'m Model) -> Result<Self, SolverError> {
        let free = super::diagnose::free_bodies(model);
        if !free.is_empty() {
            let parts = free
                .iter()
                .map(|b| {
                    let names: Vec<String> = b
                        .patches
                        .iter()
                        .map(|&k| format!("`{}`", model.patches[k].name))
                        .collect();
                    if names.len() == 1 {
                        format!("patch {}", names[0])
                    } else {
                        format!("patches {}", names.join(", "))
                    }
                })
                .collect();
            let nodes = free
                .iter()
                .flat_map(|b| b.nodes.iter().map(|&k| model.nodes[k].name.clone()))
                .collect();
            let free_patches: usize = free.iter().map(|b| b.patches.len()).sum();
            return Err(SolverError::FreeBody {
                parts,
                nodes,
                rest_held: free_patches < model.patches.len(),
            });
        }
        let disc = Discretisation::new(model)?;
        let assembler = Assembler::new(model, &disc);
        let state = State::reference(&disc);
        let materials = PointMaterials::new(model, &disc);
        let terms = registered_terms(model, &disc);
        let (system, values) = analyse(
            &Assembly {
                disc: &disc,
                state: &state,
                material: StepMaterial {
                    laws: &materials.laws,
                },
                actions: &Actions::at(model, 0.0, &[]),
                terms: Terms::default(),
            },
            &assembler,
            &terms,
            None,
            model.solver().linear,
        )?;
        let n = disc.num_unknowns();
        let coupling = coupling_versions(&terms);
        Ok(Self {
            model,
            measures: measures::Measures::new(model, &disc),
            solution: solution::Solution::starting_at(state),
            disc,
            assembler,
            terms,
            materials,
            clock: Clock::start(model.time()),
            releases: releases::Releases::new(model.nodes.len()),
            arc: None,
            stabiliser: stabilisation::Stabiliser::default(),
            work: workspace::Workspace {
                system,
                lin: Linearisation::default(),
                values,
                coupling,
                delta: vec![0.0; n],
                tangent: checkpoint::TangentRecord::default(),
            },
            record: record::RunRecord::default(),
        })
    }
}

impl Simulation<'_> {
    /// Adds a point term to every assembly from now on, after those already there ([`crate::solver::terms`]):
    /// how a term that the model does not describe (a test's spring to ground) joins a simulation. A term
    /// added after a checkpoint was taken is not in it: add the same terms before restoring.
    pub fn add_term(&mut self, term: Box<dyn PointTerm + Send>) {
        self.terms.push(term);
        self.forget_factorisation();
    }

    /// What the result must be read with: the stabilisation above its limit
    /// ([`Simulation::stabilisation_warnings`]) and each point term's own (contact left above its penetration
    /// tolerance).
    pub fn warnings(&self) -> Vec<String> {
        let mut out = self.stabilisation_warnings();
        for term in &self.terms {
            out.extend(term.warnings());
        }
        out
    }

    /// Messages worth telling the user, each added once (e.g. that relaxation froze below `Tg − C2`), in the
    /// order they arose.
    pub fn notices(&self) -> &[String] {
        &self.record.notices
    }

    /// Assembles the residual (and with `with_tangent` the tangent) at the current state for time `t` and
    /// returns the normalised residual norm: one piece of a Newton iteration, for benchmarks and diagnostics.
    pub fn assemble(&mut self, t: Real, with_tangent: bool) -> Result<Real, SolverError> {
        let actions = Actions::at(self.model, t, &self.releases.ramps);
        self.linearise(&actions, with_tangent)
    }

    /// Factorises the last assembled tangent and solves for the Newton increment of the last assembled
    /// residual, which is returned (not applied): the linear-algebra part of a Newton iteration, for benchmarks
    /// and diagnostics.
    pub fn factor_and_solve(&mut self) -> Result<&[Real], SolverError> {
        self.factor_tangent()?;
        self.solve_increment();
        Ok(&self.work.delta)
    }

    /// Where the solver's time went so far.
    pub fn timing(&self) -> &SolverTiming {
        &self.record.timing
    }

    /// The model.
    pub fn model(&self) -> &Model {
        self.model
    }

    /// The discretisation.
    pub fn discretisation(&self) -> &Discretisation {
        &self.disc
    }

    /// The current (last converged) state.
    pub fn state(&self) -> &State {
        &self.solution.state
    }

    /// Time of the current state.
    pub fn time(&self) -> Real {
        self.clock.time
    }

    /// Converged steps so far (0: the initial state).
    pub fn step_count(&self) -> usize {
        self.clock.step
    }

    /// The size of the next step's first attempt \[time\]: the nominal `time.step`, or less while a cut step
    /// size grows back ([`STEP_FACTOR`]).
    pub fn step_size(&self) -> Real {
        self.clock.step_size
    }

    /// The linear system (solver, size, pattern).
    pub fn system(&self) -> &LinearSystem {
        &self.work.system
    }

    /// Displacement of a probe in the current state.
    pub fn probe_displacement(&self, location: &ProbeLocation) -> Vec3 {
        match *location {
            ProbeLocation::Node(k) => {
                let g = self.disc.end_point(self.model.nodes[k].ends[0]);
                point_position(&self.disc, &self.solution.state.control, g)
                    - point_position(&self.disc, &self.disc.control0, g)
            }
            ProbeLocation::Patch { patch, u } => {
                let curve = &self.model.patches[patch].curve;
                let range = &self.disc.patches[patch];
                let table = crate::math::basis::nurbs_basis(curve.knots(), curve.weights(), u, 0);
                table.ders[0]
                    .iter()
                    .enumerate()
                    .map(|(a, n)| {
                        let j = range.offset + table.first + a;
                        (self.solution.state.control[j] - self.disc.control0[j]) * *n
                    })
                    .sum()
            }
        }
    }

    /// The stress resultants that the rod ends of node `k` exert on the node, in the current state: per end
    /// `(σ R N, σ R M)` (spatial force and moment, outward sign σ), in the order of the node's ends. At
    /// equilibrium their sums equal the node's applied load (or its reaction, at prescribed components).
    pub fn node_end_resultants(&self, k: usize) -> Vec<(Vec3, Vec3)> {
        self.assembler.node_end_resultants(
            &self.disc,
            &self.solution.state,
            self.step_material(),
            k,
        )
    }
}

/// The point terms of `model` that every assembly includes, in the order they add up: the registry of
/// [`crate::solver::terms`] (a new term is one line here).
fn registered_terms(model: &Model, disc: &Discretisation) -> Vec<Box<dyn PointTerm + Send>> {
    // The wire crossing adds no load: it looks for wires passing through each other after each step (issue 35).
    let mut terms: Vec<Box<dyn PointTerm + Send>> = vec![
        Box::new(DistributedLoad),
        Box::new(WireCrossing::new(model, disc)),
    ];
    if let Some(contact) = &model.contact {
        terms.push(Box::new(SurfaceContact::new(
            model,
            disc,
            contact.obstacles.clone(),
            contact.settings,
        )));
    }
    if let Some(settings) = model.wire_contact {
        terms.push(Box::new(WireContact::new(model, disc, settings)));
    }
    terms
}

/// The terms of one assembly: the registered ones, then the damping of stabilisation when it is on, and the
/// gauge constraints when they are active.
fn assembly_terms<'a>(
    registered: &'a [Box<dyn PointTerm + Send>],
    damping: Option<&'a Damping<'a>>,
    gauge: Option<&'a Gauge>,
) -> (Vec<&'a dyn PointTerm>, Vec<&'a dyn Constraint>) {
    let mut point: Vec<&dyn PointTerm> =
        registered.iter().map(|t| &**t as &dyn PointTerm).collect();
    if let Some(d) = damping {
        point.push(d);
    }
    let constraints = gauge.map(|g| g as &dyn Constraint).into_iter().collect();
    (point, constraints)
}

/// The linear system of the assemblies with the point terms `registered` and the constraints of `gauge` (their
/// pattern recorded at `at`'s iterate, whose own terms are ignored, and analysed for `method`), and room for its
/// entries.
fn analyse(
    at: &Assembly<'_>,
    assembler: &Assembler,
    registered: &[Box<dyn PointTerm + Send>],
    gauge: Option<&Gauge>,
    method: crate::model::LinearMethod,
) -> Result<(LinearSystem, Vec<Real>), SolverError> {
    let mut pattern = Vec::new();
    let (point, constraints) = assembly_terms(registered, None, gauge);
    let terms = Terms {
        point: &point,
        constraints: &constraints,
    };
    assembler.assemble(
        &Assembly { terms, ..*at },
        &mut Linearisation::default(),
        &mut Sink::Pattern(&mut pattern),
    );
    let n = at.disc.num_unknowns() + terms.multipliers();
    let borders = at.disc.reference_points();
    let system = LinearSystem::new(n, &pattern, &patch_ranges(at.disc), &borders, method)?;
    Ok((system, vec![0.0; pattern.len()]))
}

/// The coupling version of every registered term ([`PointTerm::coupling_version`]): the pattern's analysis was
/// made for these.
fn coupling_versions(terms: &[Box<dyn PointTerm + Send>]) -> Vec<usize> {
    terms.iter().map(|t| t.coupling_version()).collect()
}

/// Each patch's first control point and count, for the block solver.
fn patch_ranges(disc: &Discretisation) -> Vec<(usize, usize)> {
    disc.patches.iter().map(|r| (r.offset, r.n)).collect()
}
