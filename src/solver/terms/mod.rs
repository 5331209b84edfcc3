//! The solver's seams for physics beyond the rod itself: **point terms** (loads, dampers, foundations, contact
//! at the collocation points and patch ends) and **constraints** (rows held by Lagrange multipliers).
//!
//! The collocated equations (module docs of `super::assembly`) are the rod's balance laws at the interior
//! collocation points and the node equations at the patch ends. Everything else that acts on the device enters
//! through one of two interfaces, and the assembly (`super::assembly::Assembler::assemble`) calls every term
//! of a list ([`Terms`]) in its order:
//!
//! **[`PointTerm`]** — something that acts at a point of the rod.
//! - *What it sees* ([`PointView`]): the discretisation, the current iterate (`State`), the resolved loads of
//!   the instant (`Actions`), the collocation point (its index, basis, section shape, reference kinematics),
//!   the point's position `c` and rotation `R` (with `Rᵀ`), and whether the tangent is wanted this time.
//! - *What it returns*, at an **interior point** ([`PointTerm::interior`], into [`InteriorLoad`]): a spatial
//!   force density `n̄` and couple density `m̄` [force/length, force·length/length], which the balance laws take
//!   in the material frame as `Rᵀ n̄`, `Rᵀ m̄` (paper Eqs. mat_f, mat_m), and a couple density already in the
//!   material frame; with the tangent, its derivatives in the material rows with respect to the point's position
//!   `c` and material rotation increment `δΘ` (`R ← R exp(δΘ̃)`) — the derivative of `Rᵀ` itself under a fixed
//!   spatial `n̄`, `m̄` (`hat(Rᵀ n̄)`, `hat(Rᵀ m̄)`) is the assembly's, not the term's. The assembly multiplies
//!   each block by the basis values `N_a` of the point's control points (`δc = Σ N_a δη_a`, `δΘ = Σ N_a δθ_a`).
//!   At a **patch end** ([`PointTerm::end`], into [`EndLoad`]): a concentrated spatial force and moment on the
//!   node the end belongs to, which join the node's applied load in its equilibrium rows (DESIGN §4 "Joints"),
//!   and their spatial derivatives with respect to the end's `c` and `δΘ`. A term that acts only along the rods
//!   leaves `end` as it is (the default does nothing).
//! - *Contributions add up in the order of the list*: the first value given for a quantity is taken as it is,
//!   later ones are added to it, and a quantity no term gives is zero and adds nothing. Only what a term gives is
//!   added, so a list of terms that act nowhere changes no bit of the assembly.
//! - *Its state*: what a term keeps between steps (an anchor, a slip, a history) changes only when a step
//!   converges ([`PointTerm::commit`], called with the converged state after the materials' commit); during
//!   the attempts of a step the term is read-only (`&self`), so an attempt that fails, is rejected or is
//!   interrupted leaves the term as the last converged step left it. Its numbers ([`PointTerm::save`],
//!   [`PointTerm::restore`]) are part of what a step changes, the simulation's `StepSnapshot::terms` (in the
//!   order of the list): a roll-back puts them back (which changes nothing for a term that attempts only read)
//!   and a checkpoint keeps them, so a restored run continues bit for bit. A stateless term (today's three) keeps the defaults. The
//!   damping of stabilisation is the one term built per attempt from the simulation's own memory (the last
//!   converged state and `c/h`), which drops it when the attempt ends either way.
//!
//! **Coupled loads** — a point term whose line force at a point depends on control points other than those of
//! the point's basis (the contact of two wires: the force on one depends on where the other is) gives them once per
//! assembly ([`PointTerm::coupled`]: the forces per point and, with the tangent, a spatial block `∂q_g/∂c_k` per
//! entry `(g, k)` of its [`PointTerm::coupling`]). The assembly adds each force to the point's load after the
//! terms' own (so the balance law takes `Rᵀ q` and its rotation derivative as for any force) and pushes the blocks
//! `Rᵀ_g ∂q_g/∂c_k` into the force rows of `g` and the translation columns of `k` after every other entry. The
//! entries are part of the tangent's pattern: when a term's coupling changes (contact pairs found or lost between
//! steps) the simulation analyses the pattern again before its next tangent; the block solver then takes the
//! patches whose interiors couple as one block (module docs of `src/solver/block.rs`).
//!
//! **[`Constraint`]** — equations held by Lagrange multipliers. A constraint of `m` rows adds `m` unknowns
//! (its multipliers `λ_j`, stored after the rod's unknowns in `State::multipliers`) and `m` equations, linear
//! in the positions of nodes (the position of a node's first end):
//! ```text
//! C_j = Σ_l a_jl · (c_l − c̄_l) = 0,
//! ```
//! with the coefficients `a_jl` and the origins `c̄_l` given by the constraint. Each multiplier acts on the nodes
//! it constrains as the force `−λ_j a_jl` in the free translational rows of their equilibrium (zero where a
//! component is prescribed, whose row is a kinematic condition). Because the constraints are linear, the
//! tangent's blocks are `a_jl` and `−a_jl` exactly. Several constraints number their multipliers one after
//! another in the order of the list.
//!
//! The terms of today: [`distributed::DistributedLoad`] (the model's distributed loads), the contact with
//! surfaces [`contact::SurfaceContact`], the check for wires passing through each other
//! [`crossing::WireCrossing`] (no load; it reports), the viscous regularisation [`damping::Damping`] of
//! automatic stabilisation, and the gauge constraints (`super::gauge::Gauge`) of a released device.
//!
//! **A new term** is one module here (a type implementing [`PointTerm`]; its `pub mod` line above) plus one
//! registration line: in `registered_terms` of `simulation/mod.rs` for a term every simulation of a model has,
//! or a call of [`super::Simulation::add_term`] for one the model does not describe. Adding it to the list of
//! the generic central-difference test in `tests` checks its tangent. `spring` (test-only: a spring to ground)
//! is the example: the module, and `sim.add_term(Box::new(SpringToGround { … }))` in the test of a bar on a
//! foundation against its closed form.

pub mod contact;
pub mod crossing;
pub mod damping;
pub mod distributed;
#[cfg(test)]
pub(crate) mod spring;
#[cfg(test)]
mod tests;
pub mod wires;

use super::actions::Actions;
use super::discretisation::{CollocationPoint, Discretisation, point_position};
use super::state::State;
use crate::material::SectionShape;
use crate::math::{Mat3, Real, Vec3};

/// Something that acts at the collocation points of the rods and at their ends (module docs).
pub trait PointTerm: Sync {
    /// A short name for diagnostics and tests.
    fn name(&self) -> &'static str;

    /// The term itself, for a typed accessor of the simulation that reads what the term reports to the run's
    /// outputs (`Simulation::contact` reads the contact term's report); the default: nothing to read.
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        None
    }

    /// Adds this term's load (and, when `at.tangent`, its derivatives) at an interior collocation point.
    fn interior(&self, at: &PointView<'_>, load: &mut InteriorLoad);

    /// Adds this term's concentrated load on a node through one of its patch ends (and, when `at.tangent`, its
    /// derivatives). The default adds nothing.
    fn end(&self, _at: &PointView<'_>, _load: &mut EndLoad) {}

    /// A step (or an attempt at one) from the converged `state` to time `t` begins: a term that depends on time
    /// (a moving surface) takes it here, and one that keeps multipliers updates them from `state`. Every attempt
    /// of a step starts from the term's state saved at the step's start, so this is called with the same
    /// arguments on the same term state each time. The default ignores it.
    fn prepare(&mut self, _disc: &Discretisation, _state: &State, _t: Real) {}

    /// A step converged at `state`, not yet committed: a term that enforces a condition by augmented-Lagrange
    /// updates (contact) updates its multipliers and returns `true` if the step must be solved again with them.
    /// The term bounds its own updates per step (counted from [`PointTerm::prepare`]) and, when they run out
    /// with the condition still violated, says so in [`PointTerm::warnings`]. What it changes is part of its
    /// saved state ([`PointTerm::save`]), so a roll-back of the step undoes it. The default changes nothing.
    fn augment(&mut self, _disc: &Discretisation, _state: &State) -> bool {
        false
    }

    /// The fraction `α ∈ (0, 1]` of the Newton increment `delta` (laid out as the solver's unknowns: six per
    /// control point, translations first) that this term lets the iteration take from `state`: a term whose
    /// load the tangent at `state` cannot see coming (a contact not yet touched) limits the step to where it
    /// starts to act. Asked for the first increment of each Newton solve. The default takes the whole
    /// increment.
    fn step_limit(&self, _disc: &Discretisation, _state: &State, _delta: &[Real]) -> Real {
        1.0
    }

    /// The tangent entries this term's **coupled** loads occupy (module docs): `(g, k)` for a block of interior
    /// collocation point `g`'s force rows against control point `k`'s translations, in the order of the blocks
    /// of [`PointTerm::coupled`]. A term whose load at a point depends only on that point (every term but the
    /// wires' contact) has none, the default. The list may change between steps (not during a Newton solve);
    /// [`PointTerm::coupling_version`] says when.
    fn coupling(&self) -> &[(usize, usize)] {
        &[]
    }

    /// A number that changes whenever [`PointTerm::coupling`] does, so the simulation analyses the linear
    /// system's pattern again (the default: never).
    fn coupling_version(&self) -> usize {
        0
    }

    /// The coupled loads at `state` (module docs): spatial line forces at interior collocation points that
    /// depend on control points beyond the point's own basis (another wire's, in contact), and with `tangent`
    /// their derivatives, one block per entry of [`PointTerm::coupling`]. The default: none.
    fn coupled(&self, _disc: &Discretisation, _state: &State, _tangent: bool) -> Option<Coupled> {
        None
    }

    /// What the run's result must be read with, from this term (e.g. contact left above its tolerance); the
    /// default: nothing.
    fn warnings(&self) -> Vec<String> {
        Vec::new()
    }

    /// A step converged at `state`: the term updates what it keeps between steps (module docs). The default
    /// keeps nothing.
    fn commit(&mut self, _disc: &Discretisation, _state: &State) {}

    /// Appends what a checkpoint keeps of the term's state (the default: nothing).
    fn save(&self, _out: &mut Vec<Real>) {}

    /// Takes the state a checkpoint kept ([`PointTerm::save`]).
    ///
    /// # Errors
    /// The number of values expected, when `values` cannot be this term's state (a damaged checkpoint, or one
    /// of a simulation with other terms).
    fn restore(&mut self, values: &[Real]) -> Result<(), usize> {
        if values.is_empty() { Ok(()) } else { Err(0) }
    }
}

/// Equations held by Lagrange multipliers, linear in node positions (module docs).
pub trait Constraint: Sync {
    /// A short name for diagnostics and tests.
    fn name(&self) -> &'static str;

    /// Number of equations (and multipliers).
    fn len(&self) -> usize;

    /// Whether there are no equations.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Equation `j`'s coefficients: `(node index, a_jl)` \[1\] or \[1/length\] (a rotation's lever).
    fn row(&self, j: usize) -> &[(usize, Vec3)];

    /// The origin `c̄_l` of node `node`'s position in the equations (`None`: the current position, so that the
    /// node contributes nothing to the residual).
    fn origin(&self, node: usize) -> Option<Vec3>;

    /// The scale that makes the equations' residuals dimensionless \[length\].
    fn scale(&self) -> Real;
}

/// A term's coupled loads at one iterate ([`PointTerm::coupled`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Coupled {
    /// Spatial line forces `q` \[force/length\] at interior collocation points `g`, `(g, q)`, a point possibly
    /// more than once (they add up).
    pub forces: Vec<(usize, Vec3)>,
    /// `∂q_g/∂c_k` \[force/length²\] per entry `(g, k)` of [`PointTerm::coupling`] (empty without the tangent).
    pub blocks: Vec<Mat3>,
}

/// The terms of one assembly, in the order they add up.
#[derive(Clone, Copy, Default)]
pub struct Terms<'a> {
    /// Terms at the collocation points and ends.
    pub point: &'a [&'a dyn PointTerm],
    /// Constraints with multipliers.
    pub constraints: &'a [&'a dyn Constraint],
}

impl Terms<'_> {
    /// The number of multipliers (extra unknowns) of the constraints.
    pub fn multipliers(&self) -> usize {
        self.constraints.iter().map(|c| c.len()).sum()
    }
}

/// What a term sees at one collocation point (module docs).
#[derive(Clone, Copy)]
pub struct PointView<'a> {
    /// The discrete problem.
    pub disc: &'a Discretisation,
    /// The current iterate.
    pub state: &'a State,
    /// The loads and prescribed values of the instant.
    pub actions: &'a Actions,
    /// Global index of the collocation point.
    pub g: usize,
    /// The collocation point.
    pub point: &'a CollocationPoint,
    /// Its section shape (the stiffness per unit modulus: area, second moments).
    pub shape: &'a SectionShape,
    /// `Rᵀ` at the point (spatial to material).
    pub rotation_t: Mat3,
    /// Whether the tangent blocks are wanted (false: a residual-only assembly).
    pub tangent: bool,
}

impl PointView<'_> {
    /// The position `c = Σ N_a p_a` of the point \[length\].
    pub fn position(&self) -> Vec3 {
        point_position(self.disc, &self.state.control, self.g)
    }

    /// The point's rotation `R` (columns: the directors).
    pub fn rotation(&self) -> &Mat3 {
        &self.state.rotation[self.g]
    }
}

/// Adds `value` to an optional sum: the first value is taken as it is (module docs: no term, no bit changed).
#[inline]
fn add<T: std::ops::AddAssign>(slot: &mut Option<T>, value: T) {
    match slot {
        Some(sum) => *sum += value,
        None => *slot = Some(value),
    }
}

/// What the terms add to the balance laws `F`, `T` at an interior collocation point (module docs). Tangent
/// blocks are the derivatives of the material-frame rows with respect to the point's position `c` and material
/// rotation increment `δΘ`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct InteriorLoad {
    /// Spatial force density `n̄` \[force/length\] (enters `F` as `Rᵀ n̄`).
    pub force: Option<Vec3>,
    /// Spatial couple density `m̄` \[force\] (enters `T` as `Rᵀ m̄`).
    pub couple: Option<Vec3>,
    /// Couple density in the material frame \[force\] (enters `T` as it is).
    pub material_couple: Option<Vec3>,
    /// `∂F/∂c` at fixed `R` (`Rᵀ ∂n̄/∂c`) \[force/length²\].
    pub force_position: Option<Mat3>,
    /// `∂F/∂δΘ` beyond the assembly's `hat(Rᵀ n̄)` \[force/length\].
    pub force_rotation: Option<Mat3>,
    /// `∂T/∂c` at fixed `R` \[force/length\].
    pub couple_position: Option<Mat3>,
    /// `∂T/∂δΘ` beyond the assembly's `hat(Rᵀ m̄)` \[force\].
    pub couple_rotation: Option<Mat3>,
}

impl InteriorLoad {
    /// Adds a spatial force density.
    pub fn add_force(&mut self, value: Vec3) {
        add(&mut self.force, value);
    }
    /// Adds a spatial couple density.
    pub fn add_couple(&mut self, value: Vec3) {
        add(&mut self.couple, value);
    }
    /// Adds a material couple density.
    pub fn add_material_couple(&mut self, value: Vec3) {
        add(&mut self.material_couple, value);
    }
    /// Adds to `∂F/∂c`.
    pub fn add_force_position(&mut self, block: Mat3) {
        add(&mut self.force_position, block);
    }
    /// Adds to `∂F/∂δΘ`.
    pub fn add_force_rotation(&mut self, block: Mat3) {
        add(&mut self.force_rotation, block);
    }
    /// Adds to `∂T/∂c`.
    pub fn add_couple_position(&mut self, block: Mat3) {
        add(&mut self.couple_position, block);
    }
    /// Adds to `∂T/∂δΘ`.
    pub fn add_couple_rotation(&mut self, block: Mat3) {
        add(&mut self.couple_rotation, block);
    }
}

/// What the terms apply to a node through one of its ends (module docs): a concentrated spatial force and moment
/// that join the node's applied load, and their spatial derivatives with respect to the end's position `c` and
/// material rotation increment `δΘ`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EndLoad {
    /// Force on the node \[force\].
    pub force: Option<Vec3>,
    /// Moment on the node \[force·length\].
    pub moment: Option<Vec3>,
    /// `∂f/∂c` \[force/length\].
    pub force_position: Option<Mat3>,
    /// `∂f/∂δΘ` \[force\].
    pub force_rotation: Option<Mat3>,
    /// `∂m/∂c` \[force\].
    pub moment_position: Option<Mat3>,
    /// `∂m/∂δΘ` \[force·length\].
    pub moment_rotation: Option<Mat3>,
}

impl EndLoad {
    /// Adds a force.
    pub fn add_force(&mut self, value: Vec3) {
        add(&mut self.force, value);
    }
    /// Adds a moment.
    pub fn add_moment(&mut self, value: Vec3) {
        add(&mut self.moment, value);
    }
    /// Adds to `∂f/∂c`.
    pub fn add_force_position(&mut self, block: Mat3) {
        add(&mut self.force_position, block);
    }
    /// Adds to `∂f/∂δΘ`.
    pub fn add_force_rotation(&mut self, block: Mat3) {
        add(&mut self.force_rotation, block);
    }
    /// Adds to `∂m/∂c`.
    pub fn add_moment_position(&mut self, block: Mat3) {
        add(&mut self.moment_position, block);
    }
    /// Adds to `∂m/∂δΘ`.
    pub fn add_moment_rotation(&mut self, block: Mat3) {
        add(&mut self.moment_rotation, block);
    }

    /// Whether no term gave anything.
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }
}
