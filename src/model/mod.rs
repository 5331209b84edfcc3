//! The continuous problem: patches (reference centrelines), cross-sections and materials, nodes that join
//! patch ends, boundary conditions and loads per node in a local basis, distributed loads, the temperature
//! schedule, time and solver settings, and named probes.
//!
//! A [`Model`] is built and validated by [`builder::ModelBuilder`] (in Rust, or from a design file by the `io`
//! layer, which translates YAML into builder calls); [`stent`] puts a generated stent and its programme into it.
//! It holds no file names or YAML positions. Every physical field is in the design's consistent unit system
//! ([`Units`]); temperatures are in °C.

pub mod builder;
pub mod cycle;
pub mod fingerprint;
pub(crate) mod obstacle;
pub(crate) mod programme;
pub(crate) mod schedule;
pub mod stent;
pub(crate) mod temperature;
pub mod wires;

pub use obstacle::{Contact, ContactSettings, Distance, Lumen, Obstacle, Surface, Wall};
pub use programme::{DrivenNode, Programme, ProgrammeError, ProgrammeKind};
pub use schedule::{ScheduleError, TimeFunction};
pub use temperature::{Profile, TemperatureField};

use crate::material::{ConstitutiveLaw as _, MaterialLaw, Section};
use crate::math::{Mat3, NurbsCurve, Real, Vec3};
use std::collections::BTreeMap;

/// The consistent unit system a design declares; every length, force, stress and time in the model is in it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Units {
    /// m, N, Pa, s.
    Si,
    /// mm, N, MPa, s.
    MmNMpa,
}

impl Units {
    /// The design-file spelling (`SI`, `mm-N-MPa`).
    pub fn name(self) -> &'static str {
        match self {
            Units::Si => "SI",
            Units::MmNMpa => "mm-N-MPa",
        }
    }

    /// Unit of length.
    pub fn length(self) -> &'static str {
        match self {
            Units::Si => "m",
            Units::MmNMpa => "mm",
        }
    }

    /// Unit of force.
    pub fn force(self) -> &'static str {
        "N"
    }

    /// Unit of stress.
    pub fn stress(self) -> &'static str {
        match self {
            Units::Si => "Pa",
            Units::MmNMpa => "MPa",
        }
    }

    /// Unit of moment.
    pub fn moment(self) -> &'static str {
        match self {
            Units::Si => "N·m",
            Units::MmNMpa => "N·mm",
        }
    }
}

/// One rod patch: a reference centreline with its discretisation, cross-section and material.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Patch {
    /// Unique name (design files refer to its ends as `name.start`, `name.end`).
    pub name: String,
    /// Reference centreline, already at the analysis degree `p` and number of control points `n`.
    pub curve: NurbsCurve,
    /// Optional hint for the first section axis `d2` at `u = 0` (projected normal to the tangent);
    /// `None` lets the frame pick one. Irrelevant to the mechanics of circular sections.
    #[serde(serialize_with = "crate::math::serial::components")]
    pub normal_hint: Option<Vec3>,
    /// Index into [`Model::sections`].
    pub section: usize,
    /// Index into [`Model::materials`].
    pub material: usize,
    /// Largest deviation of `curve` from the analytic curve it was fitted to \[length\]; `None` when exact.
    pub fit_error: Option<Real>,
}

impl Patch {
    /// Points of the reference centreline at `8 n + 1` evenly spaced parameters (`n` control points, ends
    /// included): dense enough to follow every bend of the spline, for checks of the whole wire against a
    /// surface (an obstacle the wires start through, a crimper's reach).
    pub fn dense_points(&self) -> impl Iterator<Item = Vec3> + '_ {
        let samples = 8 * self.curve.num_points();
        let (lo, hi) = self.curve.knots().domain();
        (0..=samples).map(move |i| {
            self.curve
                .point(lo + (hi - lo) * i as Real / samples as Real)
        })
    }
}

/// Which end of a patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub enum End {
    /// `u = 0`; outward sign σ = −1.
    Start,
    /// `u = 1`; outward sign σ = +1.
    End,
}

impl End {
    /// The outward sign σ of the end (DESIGN §4 "Joints").
    pub fn sign(self) -> Real {
        match self {
            End::Start => -1.0,
            End::End => 1.0,
        }
    }

    /// The curve parameter of the end.
    pub fn parameter(self) -> Real {
        match self {
            End::Start => 0.0,
            End::End => 1.0,
        }
    }

    /// `start` or `end`.
    pub fn name(self) -> &'static str {
        match self {
            End::Start => "start",
            End::End => "end",
        }
    }
}

/// One end of one patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub struct PatchEnd {
    /// Index into [`Model::patches`].
    pub patch: usize,
    /// Which end.
    pub end: End,
}

/// What is known at one of a node's six components (three translations, three rotations, in the node's
/// local basis).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum Component {
    /// Neumann: the component is free and loaded by the given force/moment component (dead load, fixed in
    /// space) as a function of time.
    Load(TimeFunction),
    /// Dirichlet: the displacement component \[length\] or rotation component \[rad\] is prescribed as a
    /// function of time; after `release` (if any) it becomes free with the given load.
    Prescribed {
        /// The prescribed value.
        value: TimeFunction,
        /// Time from which the component is free (the paper's release step); `None` = never.
        release: Option<Real>,
        /// Load on the component once released.
        load_after_release: TimeFunction,
    },
}

impl Component {
    /// A free, unloaded component.
    pub fn free() -> Self {
        Component::Load(TimeFunction::zero())
    }

    /// A component held at zero for all time.
    pub fn fixed() -> Self {
        Component::Prescribed {
            value: TimeFunction::zero(),
            release: None,
            load_after_release: TimeFunction::zero(),
        }
    }

    /// True when the component is prescribed at time `t`.
    pub fn is_prescribed_at(&self, t: Real) -> bool {
        match self {
            Component::Load(_) => false,
            Component::Prescribed { release, .. } => release.is_none_or(|r| t < r),
        }
    }
}

/// The conditions at a node: six components in a local orthonormal basis fixed in space.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct NodeConditions {
    /// Local basis: columns are the unit axes `e1, e2, e3` in global coordinates (identity by default).
    #[serde(serialize_with = "crate::math::serial::components")]
    pub basis: Mat3,
    /// Components `[u1, u2, u3, θ1, θ2, θ3]`: translations along and rotations about `e1, e2, e3`
    /// (loads: forces along and moments about them).
    pub components: [Component; 6],
}

impl Default for NodeConditions {
    fn default() -> Self {
        Self {
            basis: Mat3::identity(),
            components: std::array::from_fn(|_| Component::free()),
        }
    }
}

/// A point where patch ends meet (a joint), or a single free end.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Node {
    /// Unique name; an end that no declared node names gets the node `patch.start` / `patch.end`.
    pub name: String,
    /// The patch ends joined here (at least one).
    pub ends: Vec<PatchEnd>,
    /// Reference position \[length\].
    #[serde(serialize_with = "crate::math::serial::components")]
    pub position: Vec3,
    /// Boundary conditions and concentrated loads.
    pub conditions: NodeConditions,
}

/// A distributed load on a patch: force and couple per unit reference length, fixed in space (dead), each
/// global component a function of time.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DistributedLoad {
    /// Index into [`Model::patches`].
    pub patch: usize,
    /// Force per unit length `n̄` [force/length], global components.
    pub force: [TimeFunction; 3],
    /// Couple per unit length `m̄` \[force\], global components.
    pub couple: [TimeFunction; 3],
}

/// Where a probe reads the displacement.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum ProbeLocation {
    /// At a node.
    Node(usize),
    /// On a patch at the curve parameter `u ∈ [0, 1]`.
    Patch {
        /// Index into [`Model::patches`].
        patch: usize,
        /// Curve parameter.
        u: Real,
    },
}

/// A named point whose displacement is recorded (`P.ux`, `P.uy`, `P.uz` in `history.csv`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Probe {
    /// Name used in the output columns.
    pub name: String,
    /// Where.
    pub location: ProbeLocation,
}

/// Time stepping settings.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TimeSettings {
    /// End time \[time\] (the run starts at 0).
    pub end: Real,
    /// Nominal time step `h` \[time\]; steps are shortened to land on schedule breakpoints. With error-controlled
    /// stepping (`tolerance`), the first step.
    pub step: Real,
    /// Smallest step that automatic step cutting may reach before giving up \[time\].
    pub min_step: Real,
    /// Duration over which a released component's reaction is ramped to its load after release \[time\]
    /// (default: one nominal step). At the release time the component becomes free under exactly the reaction
    /// that held it, so the node stays in equilibrium; the reaction then falls linearly to the prescribed load
    /// after release. This turns the release snap into a continuation that step cutting can subdivide.
    pub release_ramp: Real,
    /// Error-controlled stepping when `Some`: the tolerance of the time error estimated per step, in Newton's
    /// normalised norm (translations over the patch length, rotations in radians; see
    /// [`crate::solver::simulation`], *Error-controlled stepping*). Steps then grow and shrink with the estimate
    /// between `min_step` and `max_step`, starting from `step`. `None`: fixed steps of `step`.
    pub tolerance: Option<Real>,
    /// The largest step error-controlled stepping takes \[time\] (`None`: no bound but the end time).
    pub max_step: Option<Real>,
}

impl TimeSettings {
    /// Why these settings' error control cannot be trusted with `materials`, if they ask for it and one of the
    /// materials has no estimate that holds ([`crate::material::ConstitutiveLaw::time_error_unsupported`]): the
    /// builder and the studies refuse the model then.
    pub fn error_control_refusal(&self, materials: &[MaterialLaw]) -> Option<String> {
        self.tolerance?;
        materials.iter().find_map(|m| m.time_error_unsupported())
    }

    /// Times closer than this are one time: [`LANDING_TOLERANCE`] of the nominal step \[time\].
    pub fn landing_tolerance(&self) -> Real {
        LANDING_TOLERANCE * self.step
    }
}

/// Times closer than this fraction of the nominal step are one time when time stepping lands on schedule
/// breakpoints: the landing tolerance of the solver ([`crate::solver::Simulation::run`]), of the snapshot
/// schedule and of [`Model::planned_steps`], which keeps round-off from making sliver steps.
pub const LANDING_TOLERANCE: Real = 1e-9;

/// Breakpoints closer than this fraction of the end time are merged into one ([`Model::schedule_breakpoints`]):
/// the same time written in two tables (`1.75` and `1.7500000000000002` after unit arithmetic), far below
/// [`LANDING_TOLERANCE`] of any step.
pub const BREAKPOINT_MERGE: Real = 1e-12;

/// The time steps a run takes when no step is cut ([`Model::planned_steps`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StepPlan {
    /// Steps of the nominal length `time.step`.
    pub full: usize,
    /// Steps shortened to land on a schedule breakpoint or on the end time.
    pub shortened: usize,
}

impl StepPlan {
    /// All steps.
    pub fn total(&self) -> usize {
        self.full + self.shortened
    }
}

/// How the Newton systems are solved (DESIGN §6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub enum LinearMethod {
    /// Banded LU per patch interior and a sparse LU of the Schur complement on the patch ends
    /// (`crate::solver::block`); the general sparse LU where that is impossible.
    #[default]
    Block,
    /// faer's general sparse LU of the whole system.
    SparseLu,
}

/// How the section rotations along a rod are represented between its control points
/// (`crate::math::quaternion_field`'s module docs). The default is the objective field; the designs of the paper's
/// four cases (with their tuned copies and the two crimped stents) name the paper's, `incremental`, so that they
/// reproduce its numbers (docs/choices.md, issue 36).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub enum RotationField {
    /// Each control point's rotation from the reference; within a patch, their rotation vectors relative to one
    /// reference rotation of the patch are interpolated (Crisfield & Jelenić's interpolation): the
    /// configuration is a function of the control points' positions and rotations alone (path-independent) and
    /// a rigid rotation strains nothing (objective).
    #[default]
    Objective,
    /// The paper's: a rotation and a curvature kept at every collocation point and updated by interpolated
    /// increments (DESIGN §4 "Updates"), which makes the configuration depend on the increments that led to it
    /// (Crisfield & Jelenić 1999).
    Incremental,
}

/// What drives the solution along its path: time (the schedules), or the load factor under an arc-length
/// constraint ([`crate::solver::simulation`] module docs, *Arc-length continuation*).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub enum PathControl {
    /// Time steps through the schedules (the default; every material).
    #[default]
    Time,
    /// Riks/Crisfield arc-length continuation of the loads at `time.end` scaled by a load factor (elastic
    /// materials, no programme).
    ArcLength(ArcLengthSettings),
}

impl PathControl {
    /// The arc-length settings, when the path is driven by arc length.
    pub fn arc_length(&self) -> Option<ArcLengthSettings> {
        match self {
            Self::ArcLength(a) => Some(*a),
            Self::Time => None,
        }
    }
}

/// The arc-length constraint's form (Crisfield, *Non-linear Finite Element Analysis of Solids and Structures*,
/// vol. 1, §9.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub enum ArcConstraint {
    /// `‖Δx‖² = Δs²`: the load factor takes no part in the arc length (Crisfield's recommendation).
    #[default]
    Cylindrical,
    /// `‖Δx‖² + Δλ² = Δs²`: the load factor counts as one more (normalised) unknown.
    Spherical,
}

/// Settings of arc-length continuation. The reference load is every load and prescribed value of the design at
/// `time.end`; the load factor λ scales it (λ = 1: the design's end state). The first increment takes
/// `time.step / time.end` of the reference load; later arc lengths adapt to Newton's iterations.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ArcLengthSettings {
    /// The path ends where the load factor reaches this value (landing on it exactly).
    pub end_load_factor: Real,
    /// At most this many increments; the run ends there with a notice if the end load factor was not reached.
    pub max_increments: usize,
    /// Newton iterations an increment aims at: the next arc length is scaled by `√(target / iterations)`
    /// (within ½ … 2).
    pub target_iterations: usize,
    /// The arc length never grows beyond this multiple of the first one.
    pub max_growth: Real,
    /// The constraint's form.
    pub constraint: ArcConstraint,
}

impl Default for ArcLengthSettings {
    /// End at λ = 1, at most 1000 increments, 4 iterations aimed at (Crisfield's and cardillo's `iter_goal`),
    /// arc lengths up to 10 times the first, the cylindrical constraint.
    fn default() -> Self {
        Self {
            end_load_factor: 1.0,
            max_increments: 1000,
            target_iterations: 4,
            max_growth: 10.0,
            constraint: ArcConstraint::Cylindrical,
        }
    }
}

/// Automatic stabilisation of time-driven runs (issue 18): where Newton stalls — a release snap, a buckling
/// bridge, a limit point of a load that is not a free parameter — the equilibrium equations gain a viscous
/// force `−c A (x − xₙ)/h` and couple `−c J Θ/h` per unit length (the section's area and second moments as
/// the mass of a unit density; `Θ` the rotation since the last converged state), as Abaqus's `*STATIC,
/// STABILIZE` does. The factor `c` is chosen so that the first damped step would dissipate
/// `dissipated_fraction` of the strain energy if it moved as Newton's first (undamped) increment says, and
/// made ten times larger while the damped step still fails. The damping stays on while a step dissipates more
/// than that fraction, and the dissipated energy is reported per step and for the run, with a warning when
/// it exceeds `limit` of the largest strain energy the run reached, or when a damped step's damping force is
/// more than `limit` of the loads, reactions and walls' contact on the device (the result is then not quasi-static;
/// `crate::solver::simulation::stabilisation`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct StabilisationSettings {
    /// Dissipated energy aimed at by the first damped step, as a fraction of the strain energy (in (0, 1):
    /// the builder refuses others).
    pub dissipated_fraction: Real,
    /// The run's dissipated energy above this fraction of its largest strain energy is warned about, and so is a
    /// damped step whose damping force is more than this share of the forces on the device (in (0, 1)).
    pub limit: Real,
    /// A damping factor `c` \[1/time\] given outright, instead of the energy rule.
    pub factor: Option<Real>,
}

impl Default for StabilisationSettings {
    /// Abaqus's defaults: a dissipated-energy fraction of 2e-4 (`*STATIC, STABILIZE`) and an accuracy
    /// tolerance of 0.05 on the ratio of stabilisation to strain energy (adaptive stabilisation), Abaqus
    /// Analysis User's Guide §7.1.1 "Automatic stabilization of static problems".
    fn default() -> Self {
        Self {
            dissipated_fraction: 2e-4,
            limit: 0.05,
            factor: None,
        }
    }
}

/// Newton settings.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SolverSettings {
    /// Convergence tolerance: Newton stops when the normalised increment (translations over the patch length,
    /// rotations in radians) is below it and the normalised residual (strain-like, DESIGN §4) below
    /// `residual_factor` times it.
    pub tolerance: Real,
    /// Allowance of the residual norm over the tolerance: the residual's round-off floor grows with `p² n²`
    /// and with the ratio of coordinates to patch length, so it cannot always reach the increment tolerance,
    /// while an increment below the tolerance already means the solution is converged to its square.
    pub residual_factor: Real,
    /// Newton iterations allowed per step before the step is cut.
    pub max_iterations: usize,
    /// Reuse the last LU factorisation of the tangent while it still contracts the residual fast enough
    /// (the chord method, refactorising when an iteration reduces the residual by less than
    /// `refactor_ratio`); a step that fails this way is retried with a fresh factorisation every iteration
    /// before it is cut. `false`: Newton's method with a factorisation per iteration.
    pub reuse_factorisation: bool,
    /// Residual reduction per iteration below which a reused factorisation is kept.
    pub refactor_ratio: Real,
    /// Start each step's Newton iteration from a linear extrapolation of the last two converged states (the
    /// last step's increment scaled by the step-size ratio), except right after a schedule breakpoint. Off by
    /// default: on the straight stent it saves factorisations (738 → 414) but costs iterations (4187 → 4675) and
    /// moves Δr after the release by 4e-5 mm, 40 times further from a tight Newton reference than without it.
    /// On by default in a model with contact ([`SolverSettings::for_contact`]).
    pub extrapolate: bool,
    /// The linear solver.
    pub linear: LinearMethod,
    /// How the section rotations along a rod are represented (issue 36).
    pub rotations: RotationField,
    /// What drives the path: time, or the load factor under an arc-length constraint.
    pub path: PathControl,
    /// Viscous regularisation where Newton stalls (time-driven paths only); `None`: off (the default: a run
    /// that converges is exactly quasi-static, and a stall cuts the step).
    pub stabilisation: Option<StabilisationSettings>,
}

impl Default for SolverSettings {
    /// Tolerance 1e-9 (below the 1e-8 accuracy floor the paper reports for its convergence study, above the
    /// round-off floor of high-order patches), residual factor 100, and 25 iterations (quadratic convergence
    /// needs fewer than 10 when the step is reasonable).
    fn default() -> Self {
        Self {
            tolerance: 1e-9,
            residual_factor: 100.0,
            reuse_factorisation: true,
            refactor_ratio: 0.25,
            max_iterations: 25,
            extrapolate: false,
            linear: LinearMethod::Block,
            rotations: RotationField::default(),
            path: PathControl::Time,
            stabilisation: None,
        }
    }
}

impl SolverSettings {
    /// The defaults of a model with contact: [`SolverSettings::default`] with `extrapolate` on. An obstacle
    /// that moves (a crimper closing or opening) moves its contact points in every step; started from the last
    /// converged state, Newton's first iterate has them a whole step's travel through the surface (or clear of
    /// it), the law's force there is far from the answer and the first increments overshoot. Extrapolated, the
    /// points start near where the surface will hold them. Measured on `designs/straight_stent_crimped.yaml`
    /// (1301 steps of 2.5 ms, the default contact settings): from the last state, 10 cuts, 4826 Newton
    /// iterations and 4041 factorisations; extrapolated, no cut, 4439 iterations and 262 factorisations, 2.8×
    /// less wall time.
    pub fn for_contact() -> Self {
        Self {
            extrapolate: true,
            ..Self::default()
        }
    }
}

/// The whole continuous problem.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Model {
    /// Design name ([`Model::name`]; changed through [`Model::with_name`], which checks it as the builder does).
    name: String,
    /// Unit system of every number.
    pub units: Units,
    /// The materials (constitutive laws), referred to by [`Patch::material`]: a design's `material` (index 0,
    /// every patch's unless it names another) and its named `materials` ([`Model::materials`]; their
    /// internal-variable update changed through [`Model::with_integrator`]).
    materials: Vec<MaterialLaw>,
    /// The name of each material, in the order of `materials` (unique; `history.csv`'s per-material columns).
    pub material_names: Vec<String>,
    /// Cross-sections, referred to by [`Patch::section`].
    pub sections: Vec<Section>,
    /// Rod patches.
    pub patches: Vec<Patch>,
    /// Nodes: every patch end belongs to exactly one.
    pub nodes: Vec<Node>,
    /// Distributed loads.
    pub distributed_loads: Vec<DistributedLoad>,
    /// Temperature [°C] as a function of time, uniform over the device — or, with a `temperature_field`, the
    /// schedule reports show as the device's ([`TemperatureField::reference`]). Read through
    /// [`Model::temperature`], changed through [`Model::with_temperature`].
    temperature: TimeFunction,
    /// A temperature that varies in space, which the material sees instead of `temperature` (`None`: uniform).
    pub temperature_field: Option<TemperatureField>,
    /// Time stepping ([`Model::time`]; changed through [`Model::with_time`], which checks it as the builder does).
    time: TimeSettings,
    /// Newton settings ([`Model::solver`]; changed through [`Model::with_solver`]).
    solver: SolverSettings,
    /// Recorded points.
    pub probes: Vec<Probe>,
    /// Named node sets (indices into `nodes`), e.g. a generated stent's `all_joints`, `crown_1`, `symmetry`.
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// The programme driving a node set to a target shape, if any.
    pub programme: Option<Programme>,
    /// Symmetry planes `(point, unit normal)` of a reduced model; exports mirror the model about each (the
    /// normal points into the modelled side). A patch lying in a plane ([`Model::patch_symmetry_plane`]) is its
    /// own mirror image and carries half its section in the reduced model.
    #[serde(serialize_with = "crate::math::serial::components")]
    pub symmetry_planes: Vec<(Vec3, Vec3)>,
    /// Times within `(0, end]` at which the state is recorded (history rows, snapshots) \[time\], sorted and
    /// without repeats: fixed steps land on each, as on a schedule breakpoint; error-controlled steps reach them
    /// by their continuous extension (`crate::solver::simulation`, dense output) and are not changed by them
    /// ([`Model::record_times`]; changed through [`Model::with_record_times`]).
    record_times: Vec<Real>,
    /// The vessel a stent was placed on (a centreline read from a file), for the outputs to show beside it.
    pub vessel: Option<Vessel>,
    /// Surfaces the rods touch and the contact law (`None`: nothing to touch). Left out of the serialised
    /// description when `None`, so the checkpoint fingerprints of models without contact stay as they were.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact: Option<Contact>,
    /// Contact between the device's own wires and the law it is enforced with (`None`: wires pass through
    /// each other, which the run's wire-crossing check reports; `crate::solver::terms::wires`). Left out of the
    /// serialised description when `None`, like `contact`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wire_contact: Option<ContactSettings>,
    /// The patches (indices into `patches`) that connect the crowns of a generated stent, as its family says
    /// (`StentFamily::is_connector`: the ring family's bridges), for advice that names them. A label, not
    /// mechanics: left out of the serialised description (the checkpoint fingerprint).
    #[serde(skip)]
    pub connectors: Vec<usize>,
}

/// A vessel segment: its smoothed centreline and, where the file gave it, the lumen radius along it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Vessel {
    /// Points along the centreline \[length\].
    #[serde(serialize_with = "crate::math::serial::components")]
    pub points: Vec<Vec3>,
    /// The lumen radius at each point \[length\].
    pub radius: Option<Vec<Real>>,
}

impl Model {
    /// Time stepping.
    pub fn time(&self) -> &TimeSettings {
        &self.time
    }

    /// Newton settings.
    pub fn solver(&self) -> &SolverSettings {
        &self.solver
    }

    /// Design name (the run folder's name, `runs/<name>`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The materials (constitutive laws), referred to by [`Patch::material`], in the order of
    /// [`Model::material_names`].
    pub fn materials(&self) -> &[MaterialLaw] {
        &self.materials
    }

    /// Temperature [°C] as a function of time, uniform over the device — or, with a `temperature_field`, the
    /// schedule reports show as the device's.
    pub fn temperature(&self) -> &TimeFunction {
        &self.temperature
    }

    /// Times within `(0, end]` at which the state is recorded \[time\], sorted and without repeats.
    pub fn record_times(&self) -> &[Real] {
        &self.record_times
    }

    /// The material regions of a device made of several materials: every material some patch uses, in material
    /// order; a region's nodes are those touching a patch of it ([`Model::node_touches_material`]: a node
    /// joining two materials belongs to both). Empty when every patch is of one material (no regions to compare).
    pub fn material_regions(&self) -> Vec<usize> {
        let mut used: Vec<usize> = self.patches.iter().map(|p| p.material).collect();
        used.sort_unstable();
        used.dedup();
        if used.len() < 2 {
            used.clear();
        }
        used
    }

    /// Whether node `node` joins an end of a patch of material `material`.
    pub fn node_touches_material(&self, node: usize, material: usize) -> bool {
        self.nodes[node]
            .ends
            .iter()
            .any(|e| self.patches[e.patch].material == material)
    }

    /// Total number of collocation points (one per control point of every patch).
    pub fn num_collocation_points(&self) -> usize {
        self.patches.iter().map(|p| p.curve.num_points()).sum()
    }

    /// Number of unknowns of the global system: 3 translations and 3 rotations per control point.
    pub fn num_unknowns(&self) -> usize {
        6 * self.num_collocation_points()
    }

    /// The node that holds the given patch end.
    pub fn node_of(&self, end: PatchEnd) -> Option<usize> {
        self.nodes.iter().position(|n| n.ends.contains(&end))
    }

    /// The radius of patch `patch`'s wire as drawn: half its section's diameter (the drawing diameter of a
    /// section given by its properties).
    pub fn wire_radius(&self, patch: usize) -> Real {
        0.5 * self.sections[self.patches[patch].section].diameter()
    }

    /// The symmetry plane (index into [`Model::symmetry_planes`]) that patch `patch` lies in, if any: every
    /// control point within `1e-9` of the model size from the plane.
    pub fn patch_symmetry_plane(&self, patch: usize) -> Option<usize> {
        let points = self.patches[patch].curve.points();
        let tolerance = self.symmetry_tolerance();
        (0..self.symmetry_planes.len()).find(|&k| {
            points
                .iter()
                .all(|q| self.plane_distance(k, q) <= tolerance)
        })
    }

    /// Whether `x` lies on symmetry plane `plane` (index into [`Model::symmetry_planes`]), as a patch does for
    /// [`Model::patch_symmetry_plane`].
    pub fn lies_on_symmetry_plane(&self, plane: usize, x: &Vec3) -> bool {
        self.plane_distance(plane, x) <= self.symmetry_tolerance()
    }

    /// The distance of `x` from symmetry plane `plane`.
    fn plane_distance(&self, plane: usize, x: &Vec3) -> Real {
        let (point, normal) = &self.symmetry_planes[plane];
        (x - point).dot(normal).abs()
    }

    /// How near a symmetry plane a point lies on it: `1e-9` of the model size, the distance of its farthest node
    /// from the origin. Generated in-plane patches and nodes are there to round-off (~1e-15), the others a
    /// wire's length away.
    fn symmetry_tolerance(&self) -> Real {
        const IN_PLANE: Real = 1e-9;
        let scale = (self.nodes.iter())
            .map(|n| n.position.norm())
            .fold(0.0, Real::max)
            .max(Real::MIN_POSITIVE);
        IN_PLANE * scale
    }

    /// The steps a run takes when no step is cut: time stepping goes by `time.step` and also lands on every
    /// [`Model::schedule_breakpoints`] time, so a table of a million breakpoints means a million steps
    /// whatever the step. Between consecutive landing times `a < b` (breakpoints and the end, those within
    /// [`LANDING_TOLERANCE`]` · step` of the previous one skipped, as the run skips them) the run takes
    /// `⌊(b − a − tol)/h⌋` full steps and one more to `b`, full if the remainder is `h` within the tolerance,
    /// shortened otherwise. Linear in the number of breakpoints (after their sort).
    ///
    /// The run accumulates its time by addition, so its rounding can leave one more sliver step before a
    /// landing time than this exact count (measured: the 45° bend at `h = 1e-5` takes 100 001 steps, planned
    /// 100 000); step cuts add steps too.
    pub fn planned_steps(&self) -> StepPlan {
        self.planned_steps_at(self.time.step)
    }

    /// [`Model::planned_steps`] with every full step of length `h` instead of `time.step`: with `time.min_step`,
    /// the most steps error-controlled stepping can take (no step is shorter, except to land on a breakpoint).
    pub fn planned_steps_at(&self, h: Real) -> StepPlan {
        let end = self.time.end;
        let tolerance = self.time.landing_tolerance();
        let mut plan = StepPlan::default();
        let mut time = 0.0;
        for landing in self.schedule_breakpoints().into_iter().chain([end]) {
            if landing <= time + tolerance {
                continue;
            }
            let span = landing - time;
            let full = ((span - tolerance) / h).floor().max(0.0);
            let last = span - full * h;
            // (Counts beyond usize — absurd steps, refused by the memory limit — saturate.)
            plan.full = plan.full.saturating_add(full as usize);
            if last >= h - tolerance {
                plan.full = plan.full.saturating_add(1);
            } else {
                plan.shortened += 1;
            }
            time = landing;
        }
        plan
    }

    /// Every time at which a schedule changes slope or a condition switches, and with fixed steps every record
    /// time, within `(0, end]`, sorted and deduplicated: time stepping lands on each. (Error-controlled steps do
    /// not land on the record times: the solver reaches those by its continuous extension.)
    pub fn schedule_breakpoints(&self) -> Vec<Real> {
        self.breakpoints(self.time.tolerance.is_none())
    }

    /// [`Model::schedule_breakpoints`] without the record times: where the temperature, a load or a prescribed
    /// value changes slope, and the releases with the ends of their ramps.
    pub fn condition_breakpoints(&self) -> Vec<Real> {
        self.breakpoints(false)
    }

    fn breakpoints(&self, with_record_times: bool) -> Vec<Real> {
        let mut times: Vec<Real> = self.temperature.breakpoints().collect();
        if let Some(field) = &self.temperature_field {
            times.extend(field.breakpoints());
        }
        if with_record_times {
            times.extend(&self.record_times);
        }
        for node in &self.nodes {
            for c in &node.conditions.components {
                match c {
                    Component::Load(f) => times.extend(f.breakpoints()),
                    Component::Prescribed {
                        value,
                        release,
                        load_after_release,
                    } => {
                        times.extend(value.breakpoints());
                        times.extend(*release);
                        times.extend(release.map(|r| r + self.time.release_ramp));
                        times.extend(load_after_release.breakpoints());
                    }
                }
            }
        }
        for load in &self.distributed_loads {
            for f in load.force.iter().chain(&load.couple) {
                times.extend(f.breakpoints());
            }
        }
        for obstacle in self.contact.iter().flat_map(|c| &c.obstacles) {
            times.extend(obstacle.breakpoints());
        }
        let end = self.time.end;
        times.retain(|&t| t > 0.0 && t <= end);
        times.sort_by(Real::total_cmp);
        times.dedup_by(|a, b| (*a - *b).abs() <= BREAKPOINT_MERGE * end);
        times
    }
}
