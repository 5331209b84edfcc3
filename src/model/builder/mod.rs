//! Building a [`Model`] in Rust: patches from geometry, a generated stent and its programme, nodes and joints
//! (by end or by coincidence), conditions, loads, temperature, material, time and solver settings, probes.
//! [`ModelBuilder::build`] makes and checks the model; every check that involves more than one value is made
//! here, and a failed one is a [`BuildError`] naming the input [`Field`]. The design-file layer
//! ([`crate::design`]) is a translation of YAML into builder calls that maps fields back to lines.
//!
//! ```
//! use stentkit::material::{CircularSection, ElasticLaw};
//! use stentkit::math::Vec3;
//! use stentkit::model::TimeFunction;
//! use stentkit::model::builder::{ConditionSpec, ModelBuilder, PatchShape, TimeSpec};
//!
//! let section = CircularSection::try_new(0.01)?.into();
//! let mut b = ModelBuilder::new("cantilever", ElasticLaw::try_new(1e7, 0.3)?, section);
//! b.patch("beam", PatchShape::Line { from: Vec3::zeros(), to: Vec3::x() }, 4, 12);
//! b.condition(ConditionSpec::clamp("beam.start"));
//! b.condition(ConditionSpec::at("beam.end").with_force(2, TimeFunction::constant(1e-3)));
//! b.time(TimeSpec::new(1.0, 0.25));
//! let model = b.build()?.model;
//! assert_eq!(model.nodes.len(), 2);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub(crate) mod checks;
mod conditions;
pub mod field;
mod nodes;

pub use checks::FIT_WARNING_FRACTION;
use checks::{check_discretisation, check_model_name, check_temperature};
pub use field::{
    BuildError, ConditionField, Field, NodeField, ObstacleField, PatchField, ProbeField,
    ProgrammeField, Result, SolverField, StentField, TimeField,
};

use super::stent::{self as stent_model, ProgrammeSpec, StentMesh};
use super::*;
use crate::geometry::analytic::ParametricCurve;
use crate::geometry::fit::{FitSettings, fit_curve};
use crate::geometry::stent::StentFamily;
use crate::geometry::{GeometryError, Parameter, primitives};
use crate::material::{ConstitutiveLaw, Integrator, MaterialLaw, MaxwellLaw, Section, Wlf};
use crate::math::quote::quoted;
use crate::math::{Mat3, Real, Vec3};
use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

/// Default smallest step, as a fraction of the nominal step: ten halvings.
pub const DEFAULT_MIN_STEP_FRACTION: Real = 1.0 / 1024.0;

/// Relative size of the default joint tolerance: ends closer than this fraction of the model's bounding-box
/// diagonal are the same point. Fits and exact primitives place shared ends to ~1e-14 relative, so 1e-8
/// separates coincident ends from distinct ones with a wide margin on both sides.
pub const DEFAULT_JOINT_TOLERANCE: Real = 1e-8;

/// Control points a temperature front's width should span along a patch for the solution to follow the change
/// of stiffness across it. Measured on a cantilever recovered by a front (tests/data/front_bending.yaml): with
/// 1.5 points per width Newton diverged; with 3.1, 4.7 and 6.3 the tip dipped below the axis by 15 %, 8 % and
/// 1.4 % of its programmed displacement while the front left the beam (a curvature of the wrong sign, which the
/// local 1-D law cannot give); with 9.5 it did not.
const FRONT_POINTS_PER_WIDTH: Real = 6.0;

/// A warning when a temperature front is narrower than [`FRONT_POINTS_PER_WIDTH`] control-point spacings of a
/// patch it runs along (spacing measured along the front's direction on the control polygon).
fn unresolved_front(field: &crate::model::TemperatureField, patches: &[Patch]) -> Option<String> {
    let crate::model::Profile::Front { width, .. } = &field.profile else {
        return None;
    };
    let (worst, name) = patches
        .iter()
        .map(|p| {
            let points = p.curve.points();
            let along: Real = points
                .windows(2)
                .map(|w| field.direction.dot(&(w[1] - w[0])).abs())
                .sum();
            (along / (points.len() - 1).max(1) as Real, &p.name)
        })
        .fold((0.0, None), |(h, n), (spacing, name)| {
            if spacing > h {
                (spacing, Some(name))
            } else {
                (h, n)
            }
        });
    let name = name?;
    (*width < FRONT_POINTS_PER_WIDTH * worst).then(|| {
        format!(
            "the temperature front of width {width} spans {:.1} control-point spacings ({worst:.3e}) of patch `{name}` along its direction, fewer than {FRONT_POINTS_PER_WIDTH}: the solution cannot follow the change of stiffness across it (Newton may fail, or the shape overshoot); raise n or widen the front",
            width / worst
        )
    })
}

/// The name of a model's first material unless [`ModelBuilder::name_first_material`] gives another.
pub const DEFAULT_MATERIAL_NAME: &str = "material";

/// Temperature of a model without a temperature schedule whose material does not depend on it [°C].
pub const DEFAULT_TEMPERATURE: Real = 20.0;

/// The reference centreline of a patch.
pub enum PatchShape {
    /// A straight segment (exact).
    Line {
        /// Start point.
        from: Vec3,
        /// End point.
        to: Vec3,
    },
    /// A circular arc (exact), [`primitives::arc`].
    Arc {
        /// Centre.
        centre: Vec3,
        /// Start point.
        start: Vec3,
        /// Axis (right-hand rule).
        axis: Vec3,
        /// Angle \[rad\].
        angle: Real,
    },
    /// Any curve, fitted by a spline of the patch's degree and control points ([`fit_curve`]).
    Fitted(Box<dyn ParametricCurve + Send + Sync>),
}

/// What a patch is made of, beyond its shape and discretisation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PatchOptions {
    /// Its section: an index from [`ModelBuilder::section`] (0: the builder's first section).
    pub section: usize,
    /// Its material: an index from [`ModelBuilder::material`] (0: the builder's first material).
    pub material: usize,
    /// A hint for the first section axis at its start (irrelevant to circular sections).
    pub normal_hint: Option<Vec3>,
}

/// A patch to build.
struct PatchInput {
    name: String,
    shape: PatchShape,
    degree: usize,
    points: usize,
    options: PatchOptions,
}

/// How a node finds its patch ends.
#[derive(Debug, Clone, PartialEq)]
pub enum NodeEnds {
    /// The named ends (`patch.start`, `patch.end`), which must coincide.
    Named(Vec<String>),
    /// Every patch end within the joint tolerance of the point.
    At(Vec3),
}

/// The local basis of a condition.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BasisSpec {
    /// Columns `e1, e2, e3`: orthonormal and right-handed.
    Axes(Mat3),
    /// A symmetry plane of the given normal: `e1` is the normal, and `u1, θ2, θ3` are held at zero.
    SymmetryPlane(Vec3),
}

/// Which nodes a condition acts on.
#[derive(Debug, Clone, PartialEq)]
pub enum Target {
    /// One node: its name, or `patch.start` / `patch.end` of an end it holds.
    Node(String),
    /// Every node of a named set (a generated stent's `all_joints`, `crown_1`, …).
    Set(String),
}

/// Boundary conditions and loads on one node or a node set, components in the condition's basis.
#[derive(Debug, Clone, PartialEq)]
pub struct ConditionSpec {
    /// The nodes.
    pub target: Target,
    /// The local basis (global axes when `None`).
    pub basis: Option<BasisSpec>,
    /// Hold all six components at zero.
    pub clamp: bool,
    /// Prescribed displacements `u1, u2, u3` \[length\].
    pub displacement: [Option<TimeFunction>; 3],
    /// Prescribed rotations `θ1, θ2, θ3` \[rad\].
    pub rotation: [Option<TimeFunction>; 3],
    /// Forces on free components (or on prescribed ones after the release).
    pub force: [Option<TimeFunction>; 3],
    /// Moments on free components (or on prescribed ones after the release).
    pub moment: [Option<TimeFunction>; 3],
    /// Time from which the prescribed components are free.
    pub release: Option<Real>,
}

impl ConditionSpec {
    /// Nothing prescribed or loaded at the named node yet.
    pub fn at(node: impl Into<String>) -> Self {
        Self {
            target: Target::Node(node.into()),
            basis: None,
            clamp: false,
            displacement: Default::default(),
            rotation: Default::default(),
            force: Default::default(),
            moment: Default::default(),
            release: None,
        }
    }

    /// Nothing prescribed or loaded on the named node set yet.
    pub fn on_set(set: impl Into<String>) -> Self {
        Self {
            target: Target::Set(set.into()),
            ..Self::at("")
        }
    }

    /// The named node clamped (all six components held at zero).
    pub fn clamp(node: impl Into<String>) -> Self {
        Self {
            clamp: true,
            ..Self::at(node)
        }
    }

    /// With displacement component `i` prescribed.
    pub fn with_displacement(mut self, i: usize, f: TimeFunction) -> Self {
        self.displacement[i] = Some(f);
        self
    }

    /// With rotation component `i` prescribed.
    pub fn with_rotation(mut self, i: usize, f: TimeFunction) -> Self {
        self.rotation[i] = Some(f);
        self
    }

    /// With force component `i`.
    pub fn with_force(mut self, i: usize, f: TimeFunction) -> Self {
        self.force[i] = Some(f);
        self
    }

    /// With moment component `i`.
    pub fn with_moment(mut self, i: usize, f: TimeFunction) -> Self {
        self.moment[i] = Some(f);
        self
    }
}

/// Which patches a distributed load acts on.
#[derive(Debug, Clone, PartialEq)]
pub enum PatchTarget {
    /// The named patch.
    Named(String),
    /// Every patch.
    All,
}

/// A distributed dead load, global components.
#[derive(Debug, Clone, PartialEq)]
pub struct DistributedLoadSpec {
    /// The patches.
    pub patches: PatchTarget,
    /// Force per unit length [force/length].
    pub force: [TimeFunction; 3],
    /// Couple per unit length \[force\].
    pub couple: [TimeFunction; 3],
}

/// Where a probe reads.
#[derive(Debug, Clone, PartialEq)]
pub enum ProbeAt {
    /// At the named node (or `patch.start` / `patch.end`).
    Node(String),
    /// On the named patch at the curve parameter `u ∈ [0, 1]`.
    Patch(String, Real),
}

/// Time stepping as asked for; [`TimeSettings`] once built.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeSpec {
    /// End time.
    pub end: Real,
    /// Nominal step.
    pub step: Real,
    /// Smallest step (default: [`DEFAULT_MIN_STEP_FRACTION`] of the step).
    pub min_step: Option<Real>,
    /// Release ramp (default: one step).
    pub release_ramp: Option<Real>,
    /// Time-error tolerance: error-controlled stepping from a first step `step` when given
    /// ([`TimeSettings::tolerance`]); fixed steps otherwise.
    pub tolerance: Option<Real>,
    /// Largest step of error-controlled stepping (default: the end time).
    pub max_step: Option<Real>,
}

impl TimeSpec {
    /// From 0 to `end` by `step`, with the default smallest step and release ramp.
    pub fn new(end: Real, step: Real) -> Self {
        Self {
            end,
            step,
            min_step: None,
            release_ramp: None,
            tolerance: None,
            max_step: None,
        }
    }

    /// The same with error-controlled stepping at the time-error tolerance `tolerance`, `step` being the first
    /// step.
    pub fn with_tolerance(mut self, tolerance: Real) -> Self {
        self.tolerance = Some(tolerance);
        self
    }

    /// The settings, checked: `0 < step ≤ end`, `0 < min_step ≤ step`, `release_ramp ≥ 0`, a tolerance > 0,
    /// `step ≤ max_step`.
    pub fn settings(&self) -> Result<TimeSettings> {
        let (end, step) = (self.end, self.step);
        let positive = |v: Real| v > 0.0 && v.is_finite();
        if !positive(end) {
            return Err(BuildError::new(
                Field::Time(TimeField::End),
                format!("{end} must be > 0 and finite"),
            ));
        }
        if !positive(step) {
            return Err(BuildError::new(
                Field::Time(TimeField::Step),
                format!("{step} must be > 0 and finite"),
            ));
        }
        if step > end {
            return Err(BuildError::new(
                Field::Time(TimeField::Step),
                format!("the step {step} exceeds the end time {end}"),
            ));
        }
        let min_step = self.min_step.unwrap_or(step * DEFAULT_MIN_STEP_FRACTION);
        if !positive(min_step) {
            return Err(BuildError::new(
                Field::Time(TimeField::MinStep),
                format!("{min_step} must be > 0 and finite"),
            ));
        }
        if min_step > step {
            return Err(BuildError::new(
                Field::Time(TimeField::MinStep),
                format!("min_step {min_step} exceeds the step {step}"),
            ));
        }
        let release_ramp = self.release_ramp.unwrap_or(step);
        if !(release_ramp >= 0.0 && release_ramp.is_finite()) {
            return Err(BuildError::new(
                Field::Time(TimeField::ReleaseRamp),
                format!("{release_ramp} must be ≥ 0 and finite"),
            ));
        }
        if let Some(tolerance) = self.tolerance
            && !positive(tolerance)
        {
            return Err(BuildError::new(
                Field::Time(TimeField::Tolerance),
                format!("{tolerance} must be > 0 and finite"),
            ));
        }
        if let Some(max_step) = self.max_step {
            if !positive(max_step) {
                return Err(BuildError::new(
                    Field::Time(TimeField::MaxStep),
                    format!("{max_step} must be > 0 and finite"),
                ));
            }
            if max_step < step {
                return Err(BuildError::new(
                    Field::Time(TimeField::MaxStep),
                    format!("max_step {max_step} is below the (first) step {step}"),
                ));
            }
        }
        Ok(TimeSettings {
            end,
            step,
            min_step,
            release_ramp,
            tolerance: self.tolerance,
            max_step: self.max_step,
        })
    }
}

impl From<&TimeSettings> for TimeSpec {
    /// The spec whose [`TimeSpec::settings`] are `time` again, every default spelled out.
    fn from(time: &TimeSettings) -> Self {
        Self {
            end: time.end,
            step: time.step,
            min_step: Some(time.min_step),
            release_ramp: Some(time.release_ramp),
            tolerance: time.tolerance,
            max_step: time.max_step,
        }
    }
}

impl Model {
    /// This model with the time stepping `time`, checked as [`ModelBuilder::build`] checks it
    /// ([`Model::with_settings`]).
    ///
    /// # Errors
    /// As [`Model::with_settings`].
    pub fn with_time(self, time: TimeSettings) -> Result<Model> {
        let solver = self.solver.clone();
        self.with_settings(time, solver)
    }

    /// This model with the Newton settings `solver`, checked as [`ModelBuilder::build`] checks them
    /// ([`Model::with_settings`]).
    ///
    /// # Errors
    /// As [`Model::with_settings`].
    pub fn with_solver(self, solver: SolverSettings) -> Result<Model> {
        let time = self.time.clone();
        self.with_settings(time, solver)
    }

    /// This model with the time stepping `time` and the Newton settings `solver`, after the checks
    /// [`ModelBuilder::build`] runs on them: the time spec's ([`TimeSpec::settings`]), error control only where
    /// every material's estimate holds, the solver's tolerances and stabilisation, and an arc-length path only
    /// for an elastic model without programme, error control or releases. What the builder made from the old
    /// settings stays as it was (a programme's times, the record times).
    ///
    /// # Errors
    /// The [`BuildError`] of the first check that fails, at the field the builder would name.
    pub fn with_settings(mut self, time: TimeSettings, solver: SolverSettings) -> Result<Model> {
        let time = TimeSpec::from(&time).settings()?;
        if let Some(why) = time.error_control_refusal(&self.materials) {
            return Err(BuildError::new(Field::Time(TimeField::Tolerance), why));
        }
        check_solver(&solver)?;
        check_path(
            &solver,
            &self.materials,
            &self.material_names,
            self.programme.is_some() || time.tolerance.is_some() || self.contact.is_some(),
            &self.nodes,
        )?;
        self.time = time;
        self.solver = solver;
        Ok(self)
    }

    /// This model named `name`, checked as [`ModelBuilder::build`] checks a name: it becomes the run folder
    /// `runs/<name>`, so it must be one plain folder name.
    ///
    /// # Errors
    /// At [`Field::Name`] when `name` is not one folder name.
    pub fn with_name(mut self, name: impl Into<String>) -> Result<Model> {
        let name = name.into();
        check_model_name(&name)?;
        self.name = name;
        Ok(self)
    }

    /// This model recording its state at `times`, checked as [`ModelBuilder::build`] checks them and held as it
    /// holds them: each within `(0, time.end]`, then sorted and without repeats.
    ///
    /// # Errors
    /// At [`Field::RecordTime`] of the first time that is not finite or not within `(0, time.end]`.
    pub fn with_record_times(mut self, times: Vec<Real>) -> Result<Model> {
        self.record_times = checks::record_times(&times, self.time.end)?;
        Ok(self)
    }

    /// This model with the temperature schedule `temperature` [°C], checked as [`ModelBuilder::build`] checks
    /// it (every value finite). With a [`Model::temperature_field`], the field stays what the material sees and
    /// `temperature` is the schedule the reports show. (The builder's warning of a temperature at or below a WLF
    /// singularity is not repeated here.)
    ///
    /// # Errors
    /// At [`Field::Temperature`] when a value is not finite.
    pub fn with_temperature(mut self, temperature: TimeFunction) -> Result<Model> {
        check_temperature(&temperature)?;
        self.temperature = temperature;
        Ok(self)
    }

    /// This model with every viscoelastic (Maxwell) material's internal variables updated by `integrator` (an
    /// elastic material has none), checked with the model's settings as [`ModelBuilder::build`] checks them
    /// ([`Model::with_settings`]): error-controlled steps only where the new update has an estimate.
    ///
    /// # Errors
    /// As [`Model::with_settings`]: at [`Field::Time`]`(`[`TimeField::Tolerance`]`)` when the model's steps are
    /// error-controlled and `integrator` has no estimate ([`Integrator::companion`]).
    pub fn with_integrator(mut self, integrator: Integrator) -> Result<Model> {
        for law in &mut self.materials {
            if let MaterialLaw::Maxwell(maxwell) = law {
                *maxwell = MaxwellLaw::new(maxwell.material().clone(), integrator);
            }
        }
        let (time, solver) = (self.time.clone(), self.solver.clone());
        self.with_settings(time, solver)
    }
}

/// How patch ends that no node names are joined.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointRule {
    /// Join every group of coincident free ends automatically (otherwise each is a node of its own).
    pub automatic: bool,
    /// Distance within which ends coincide \[length\]; default [`DEFAULT_JOINT_TOLERANCE`] of the model's
    /// bounding-box diagonal.
    pub tolerance: Option<Real>,
}

/// A built model with what is worth knowing about it.
#[derive(Debug, Clone)]
pub struct Built {
    /// The model.
    pub model: Model,
    /// Things worth knowing that do not stop a run (a coarse fit, a temperature below the WLF singularity, a
    /// programme that outlasts the run).
    pub warnings: Vec<String>,
}

/// Builds a [`Model`]: add what the model holds, then [`ModelBuilder::build`].
pub struct ModelBuilder {
    name: String,
    units: Units,
    materials: Vec<MaterialLaw>,
    material_names: Vec<String>,
    sections: Vec<Section>,
    stent: Option<(Arc<dyn StentFamily>, StentMesh)>,
    stent_materials: stent_model::StentMaterials,
    programme: Option<ProgrammeSpec>,
    /// Generate the stent in its programme's temporary placement, without the programme.
    temporary_shape: bool,
    patches: Vec<PatchInput>,
    nodes: Vec<(String, NodeEnds)>,
    joints: JointRule,
    conditions: Vec<ConditionSpec>,
    distributed: Vec<DistributedLoadSpec>,
    temperature: Option<TimeFunction>,
    temperature_field: Option<crate::model::TemperatureField>,
    time: TimeSpec,
    solver: SolverSettings,
    probes: Vec<(String, ProbeAt)>,
    record_times: Vec<Real>,
    /// The vessel a stent sits on, for the outputs.
    vessel: Option<crate::model::Vessel>,
    /// Surfaces the rods touch.
    contact: Option<crate::model::Contact>,
    wire_contact: Option<crate::model::ContactSettings>,
}

impl ModelBuilder {
    /// A model named `name` with `material` as material 0 and `section` as section 0 (every patch's unless it
    /// says otherwise; a generated stent's), in [`Units::Si`], from 0 to 1 by 0.1, default solver settings.
    pub fn new(
        name: impl Into<String>,
        material: impl Into<MaterialLaw>,
        section: Section,
    ) -> Self {
        Self {
            name: name.into(),
            units: Units::Si,
            materials: vec![material.into()],
            material_names: vec![DEFAULT_MATERIAL_NAME.to_string()],
            sections: vec![section],
            stent: None,
            stent_materials: stent_model::StentMaterials::default(),
            programme: None,
            temporary_shape: false,
            patches: Vec::new(),
            nodes: Vec::new(),
            joints: JointRule {
                automatic: false,
                tolerance: None,
            },
            conditions: Vec::new(),
            distributed: Vec::new(),
            temperature: None,
            temperature_field: None,
            time: TimeSpec::new(1.0, 0.1),
            solver: SolverSettings::default(),
            probes: Vec::new(),
            record_times: Vec::new(),
            vessel: None,
            contact: None,
            wire_contact: None,
        }
    }

    /// The unit system every number is in.
    pub fn units(&mut self, units: Units) -> &mut Self {
        self.units = units;
        self
    }

    /// Adds a section; returns its index for [`PatchOptions::section`].
    pub fn section(&mut self, section: Section) -> usize {
        self.sections.push(section);
        self.sections.len() - 1
    }

    /// Adds a material named `material_<index>`; returns its index for [`PatchOptions::material`].
    pub fn material(&mut self, material: impl Into<MaterialLaw>) -> usize {
        let name = format!("material_{}", self.materials.len());
        self.named_material(name, material)
    }

    /// Adds a material with a name (reports' per-material columns use it; names must be unique, which
    /// [`ModelBuilder::build`] checks); returns its index.
    pub fn named_material(
        &mut self,
        name: impl Into<String>,
        material: impl Into<MaterialLaw>,
    ) -> usize {
        self.materials.push(material.into());
        self.material_names.push(name.into());
        self.materials.len() - 1
    }

    /// Renames material 0 (named `material` by default).
    pub fn name_first_material(&mut self, name: impl Into<String>) -> &mut Self {
        self.material_names[0] = name.into();
        self
    }

    /// The materials of a generated stent's crowns and bridges (default: material 0 everywhere).
    pub fn stent_materials(&mut self, materials: stent_model::StentMaterials) -> &mut Self {
        self.stent_materials = materials;
        self
    }

    /// Generates a stent of any family (the rings of a [`crate::geometry::stent::StentSpec`], the diamond
    /// cells of a [`crate::geometry::stent::DiamondSpec`], …) whose patches and nodes come first in the model,
    /// with its node sets (`all_joints`, `crown_<k>`, …), symmetry planes and the symmetry conditions of its cut
    /// nodes ([`stent_model`]).
    pub fn stent(&mut self, family: Arc<dyn StentFamily>, mesh: StentMesh) -> &mut Self {
        self.stent = Some((family, mesh));
        self
    }

    /// The vessel the stent sits on, for the outputs ([`crate::model::Vessel`]).
    pub fn vessel(&mut self, vessel: crate::model::Vessel) -> &mut Self {
        self.vessel = Some(vessel);
        self
    }

    /// Surfaces the rods touch and the contact law ([`crate::model::Contact`]), checked when the model is built:
    /// unique names, unit axes and normals, a positive penalty, band and tolerance, a compliant wall only on a
    /// cylinder and with a positive modulus, thickness and width, a cylinder never narrower than a wire, and no
    /// wire through a surface at the start.
    pub fn contact(&mut self, contact: crate::model::Contact) -> &mut Self {
        self.contact = Some(contact);
        self
    }

    /// Contact between the device's own wires under `settings` (its law, `crate::solver::terms::wires`),
    /// checked when the model is built like the surfaces' settings (a positive penalty, band and tolerance).
    pub fn wire_contact(&mut self, settings: crate::model::ContactSettings) -> &mut Self {
        self.wire_contact = Some(settings);
        self
    }

    /// Drives a node set of the generated stent to a temporary shape ([`ProgrammeSpec`]).
    pub fn programme(&mut self, programme: ProgrammeSpec) -> &mut Self {
        self.programme = Some(programme);
        self
    }

    /// Builds the stent in the temporary shape its programme drives it to — generated in that placement
    /// ([`crate::model::stent::ProgrammeSpec::placement`]) — and without the programme: the shape a designer
    /// previews (`stentkit mesh --state temporary`). A design without a programme has no temporary shape: `build`
    /// refuses it.
    pub fn temporary_shape(&mut self) -> &mut Self {
        self.temporary_shape = true;
        self
    }

    /// Adds a patch of section 0 and material 0 with degree `p` and `n` control points.
    pub fn patch(&mut self, name: impl Into<String>, shape: PatchShape, p: usize, n: usize) {
        self.patch_with(name, shape, p, n, PatchOptions::default());
    }

    /// Adds a patch with its section, material and normal hint.
    pub fn patch_with(
        &mut self,
        name: impl Into<String>,
        shape: PatchShape,
        p: usize,
        n: usize,
        options: PatchOptions,
    ) {
        self.patches.push(PatchInput {
            name: name.into(),
            shape,
            degree: p,
            points: n,
            options,
        });
    }

    /// Adds a named node joining the given ends.
    pub fn node(&mut self, name: impl Into<String>, ends: NodeEnds) {
        self.nodes.push((name.into(), ends));
    }

    /// How the ends no node names are joined.
    pub fn joints(&mut self, rule: JointRule) -> &mut Self {
        self.joints = rule;
        self
    }

    /// Adds boundary conditions and loads; one condition per node component.
    pub fn condition(&mut self, condition: ConditionSpec) {
        self.conditions.push(condition);
    }

    /// Adds a distributed load.
    pub fn distributed_load(&mut self, load: DistributedLoadSpec) {
        self.distributed.push(load);
    }

    /// The temperature schedule [°C] (required by a material with WLF; [`DEFAULT_TEMPERATURE`] otherwise).
    pub fn temperature(&mut self, temperature: TimeFunction) -> &mut Self {
        self.temperature = Some(temperature);
        self
    }

    /// A temperature that varies in space ([`crate::model::TemperatureField`]), instead of a uniform schedule;
    /// reports show its [`crate::model::TemperatureField::reference`] schedule unless
    /// [`ModelBuilder::temperature`] gives another.
    pub fn temperature_field(&mut self, field: crate::model::TemperatureField) -> &mut Self {
        self.temperature_field = Some(field);
        self
    }

    /// Time stepping.
    pub fn time(&mut self, time: TimeSpec) -> &mut Self {
        self.time = time;
        self
    }

    /// Newton settings.
    pub fn solver(&mut self, solver: SolverSettings) -> &mut Self {
        self.solver = solver;
        self
    }

    /// Adds a probe.
    pub fn probe(&mut self, name: impl Into<String>, at: ProbeAt) {
        self.probes.push((name.into(), at));
    }

    /// Times within `(0, end]` at which the state is recorded; time stepping lands on each. The model holds
    /// them sorted and without repeats; [`ModelBuilder::build`] refuses one outside `(0, end]`.
    pub fn record_times(&mut self, times: Vec<Real>) -> &mut Self {
        self.record_times = times;
        self
    }

    /// Checks everything [`ModelBuilder::build`] checks, without keeping the model.
    pub fn validate(&self) -> Result<()> {
        self.build().map(|_| ())
    }

    /// Makes the model: generates and fits the geometry, joins the ends, resolves every name, applies the
    /// symmetry conditions, the programme and the conditions, and checks them.
    pub fn build(&self) -> Result<Built> {
        let mut warnings = Vec::new();
        check_model_name(&self.name)?;
        let time = self.time.settings()?;
        if let Some(why) = time.error_control_refusal(&self.materials) {
            return Err(BuildError::new(Field::Time(TimeField::Tolerance), why));
        }
        check_solver(&self.solver)?;
        self.check_materials()?;
        let mut sections = self.sections.clone();
        let placement = match (&self.programme, self.temporary_shape) {
            (_, false) => None,
            (Some(p), true) => Some(p.placement()),
            (None, true) => {
                return Err(BuildError::new(
                    Field::Programme(ProgrammeField::Whole),
                    "the design has no programme, so no temporary shape: its permanent shape is the only one",
                ));
            }
        };
        let mut stent = match &self.stent {
            Some((family, mesh)) => Some(stent_model::generate(
                family,
                mesh,
                &self.stent_materials,
                &mut sections,
                self.materials[0].poisson(),
                placement.as_ref(),
                &mut warnings,
            )?),
            None => None,
        };
        // The generated patches come first in the model: a connector's index there is its index in the stent.
        let connectors = stent.as_ref().map_or_else(Vec::new, |s| {
            (s.geometry.patches.iter().enumerate())
                .filter(|(_, g)| s.family.is_connector(&g.role))
                .map(|(k, _)| k)
                .collect()
        });
        // The stent's fitted patches and nodes move into the model; its geometry stays for the programme.
        let generated = stent
            .as_mut()
            .map_or_else(Vec::new, |s| std::mem::take(&mut s.patches));
        let patches = self.patches(generated, &sections, &mut warnings)?;
        let tolerance = self.joints.tolerance.unwrap_or_else(|| {
            let (mut lo, mut hi) = (
                Vec3::repeat(Real::INFINITY),
                Vec3::repeat(Real::NEG_INFINITY),
            );
            for q in patches.iter().flat_map(|p| p.curve.points()) {
                lo = lo.inf(q);
                hi = hi.sup(q);
            }
            DEFAULT_JOINT_TOLERANCE * (hi - lo).norm()
        });
        let initial = stent
            .as_mut()
            .map_or_else(Vec::new, |s| std::mem::take(&mut s.nodes));
        let mut nodes = nodes::nodes(
            &self.nodes,
            &patches,
            tolerance,
            self.joints.automatic,
            initial,
        )?;
        let node_sets = stent
            .as_ref()
            .map_or_else(BTreeMap::new, |s| s.geometry.node_sets.clone());
        let symmetry_planes = stent
            .as_ref()
            .map_or_else(Vec::new, stent_model::symmetry_planes);
        // Components set by the stent's symmetry planes and the programme, which conditions must not override.
        let mut preset: HashMap<(usize, usize), String> = HashMap::new();
        if let Some(s) = &stent {
            for (k, g) in s.geometry.nodes.iter().enumerate() {
                if g.symmetry_plane.is_some() {
                    for i in [0, 4, 5] {
                        preset.insert((k, i), "the stent's symmetry plane".into());
                    }
                }
            }
        }
        let programme = match self.programme.as_ref().filter(|_| placement.is_none()) {
            Some(p) => {
                let Some(stent) = &stent else {
                    return Err(BuildError::new(
                        Field::Programme(ProgrammeField::Whole),
                        "a programme drives the nodes of a generated stent: add a `stent` block",
                    ));
                };
                let programme =
                    stent_model::programme(p, stent, &mut nodes, time.end, &mut warnings)?;
                for d in programme.nodes.iter().filter(|_| programme.prescribes()) {
                    for i in 0..3 {
                        preset
                            .entry((d.node, i))
                            .or_insert_with(|| "the programme".into());
                    }
                }
                Some(programme)
            }
            None => None,
        };
        conditions::apply(&self.conditions, &patches, &mut nodes, &node_sets, &preset)?;
        let distributed_loads = self.distributed_loads(&patches)?;
        let shifts: Vec<&Wlf> = self
            .materials
            .iter()
            .filter_map(ConstitutiveLaw::temperature_shift)
            .collect();
        let temperature = match (
            &self.temperature,
            &self.temperature_field,
            shifts.is_empty(),
        ) {
            (Some(f), _, _) => f.clone(),
            (None, Some(field), _) => field.reference().clone(),
            (None, None, true) => TimeFunction::constant(DEFAULT_TEMPERATURE),
            (None, None, false) => {
                return Err(BuildError::new(
                    Field::Temperature,
                    "missing: a material with `wlf` needs a temperature schedule (a number or [[t, T], …] in °C)",
                ));
            }
        };
        check_temperature(&temperature)?;
        for w in shifts {
            let freeze = w.frozen_below();
            let (lo, _) = match &self.temperature_field {
                Some(field) => field.range(),
                None => temperature.range(),
            };
            if lo <= freeze {
                warnings.push(format!(
                    "temperature reaches {lo} °C, at or below the WLF singularity Tg − C2 = {freeze} °C: relaxation freezes there (instantaneous moduli)"
                ));
            }
        }
        if let Some(field) = &self.temperature_field {
            warnings.extend(unresolved_front(field, &patches));
        }
        check_path(
            &self.solver,
            &self.materials,
            &self.material_names,
            programme.is_some()
                || time.tolerance.is_some()
                || self.contact.is_some()
                || self.wire_contact.is_some(),
            &nodes,
        )?;
        let probes = self.probes(&patches, &nodes)?;
        let record_times = checks::record_times(&self.record_times, time.end)?;
        // A crimper programme's crimper, or a crush programme's plates, are the last obstacles.
        let mut contact = self.contact.clone();
        let mut programme = programme;
        if let (Some(p), Some(s)) = (programme.as_mut(), &stent)
            && p.kind.tool().is_some()
        {
            let Some(c) = contact.as_mut() else {
                return Err(BuildError::new(
                    Field::Programme(ProgrammeField::Whole),
                    "a crimper or crush programme needs the contact settings (`ModelBuilder::contact`, a design's `contact:`)",
                ));
            };
            let first = c.obstacles.len();
            match &mut p.kind {
                ProgrammeKind::Crimp { obstacle, .. } => {
                    *obstacle = first;
                    c.obstacles
                        .extend(stent_model::crimper(p, s, &patches, &sections)?);
                }
                ProgrammeKind::Crush { obstacle, .. } => {
                    *obstacle = first;
                    c.obstacles
                        .extend(stent_model::plates(p, s, &patches, &sections)?);
                }
                ProgrammeKind::RadialContraction { .. } | ProgrammeKind::TargetShape => {}
            }
        }
        let model = Model {
            name: self.name.clone(),
            units: self.units,
            materials: self.materials.clone(),
            material_names: self.material_names.clone(),
            sections,
            patches,
            nodes,
            distributed_loads,
            temperature,
            temperature_field: self.temperature_field.clone(),
            time,
            solver: self.solver.clone(),
            probes,
            node_sets,
            programme,
            symmetry_planes,
            record_times,
            vessel: self.vessel.clone(),
            contact,
            wire_contact: self.wire_contact,
            connectors,
        };
        if let Some(contact) = &model.contact {
            checks::contact(contact, &model)?;
        }
        if let Some(settings) = &model.wire_contact {
            checks::contact_settings(settings)?;
        }
        Ok(Built { model, warnings })
    }

    /// Material names unique; the stent's materials exist and name one per crown or one for all.
    fn check_materials(&self) -> Result<()> {
        for (k, name) in self.material_names.iter().enumerate() {
            if self.material_names[..k].contains(name) {
                return Err(BuildError::new(
                    Field::Materials,
                    format!("two materials are named `{name}`: names must be unique"),
                ));
            }
        }
        let (crowns, bridges) = (&self.stent_materials.crowns, self.stent_materials.bridges);
        let field = || Field::Stent(StentField::Materials);
        let count = self.materials.len();
        if let Some(&m) = crowns.iter().chain([&bridges]).find(|&&m| m >= count) {
            return Err(BuildError::new(
                field(),
                format!("material {m} does not exist ({count} materials)"),
            ));
        }
        if let Some((family, _)) = &self.stent
            && crowns.len() > 1
            && crowns.len() != family.crowns()
        {
            return Err(BuildError::new(
                field(),
                format!(
                    "{} crown materials for {} crowns: give one for every crown, or one for all",
                    crowns.len(),
                    family.crowns()
                ),
            ));
        }
        Ok(())
    }

    /// The model's patches: `generated` (a stent's) first, then the added ones, fitted.
    fn patches(
        &self,
        generated: Vec<Patch>,
        sections: &[Section],
        warnings: &mut Vec<String>,
    ) -> Result<Vec<Patch>> {
        if self.patches.is_empty() && generated.is_empty() {
            return Err(BuildError::new(
                Field::Patches,
                "a design needs at least one patch: give `patches` or a `stent` block",
            ));
        }
        let mut names: HashMap<&str, usize> = HashMap::new();
        let mut out = generated;
        for (k, input) in self.patches.iter().enumerate() {
            let at = |field| Field::Patch { index: k, field };
            let name = &input.name;
            if name.is_empty() || name.contains('.') || name.contains(char::is_whitespace) {
                return Err(BuildError::new(
                    at(PatchField::Name),
                    format!(
                        "{} is not a valid patch name: use a non-empty name without dots or spaces",
                        quoted(name)
                    ),
                ));
            }
            if out.iter().any(|p| &p.name == name) && !names.contains_key(name.as_str()) {
                return Err(BuildError::new(
                    at(PatchField::Name),
                    format!(
                        "patch name {} is already used by the generated stent",
                        quoted(name)
                    ),
                ));
            }
            if let Some(first) = names.insert(name, k) {
                return Err(BuildError::new(
                    at(PatchField::Name),
                    format!(
                        "patch name {} is already used by patches[{first}]",
                        quoted(name)
                    ),
                ));
            }
            let (p, n) = (input.degree, input.points);
            check_discretisation(p, n, at(PatchField::Degree), at(PatchField::ControlPoints))?;
            let geometry = |e: GeometryError| {
                let field = match e {
                    GeometryError::InvalidParameter {
                        what: Parameter::ArcAngle,
                        ..
                    } => PatchField::Angle,
                    _ => PatchField::Geometry,
                };
                BuildError::new(at(field), e.to_string())
            };
            let (curve, fit_error) = match &input.shape {
                PatchShape::Line { from, to } => {
                    (primitives::line(*from, *to, p, n).map_err(geometry)?, None)
                }
                PatchShape::Arc {
                    centre,
                    start,
                    axis,
                    angle,
                } => (
                    primitives::arc(*centre, *start, *axis, *angle, p, n).map_err(geometry)?,
                    None,
                ),
                PatchShape::Fitted(curve) => {
                    let fit = fit_curve(curve.as_ref(), p, n, &FitSettings::default())
                        .map_err(geometry)?;
                    (fit.curve, Some(fit.max_deviation))
                }
            };
            let options = input.options;
            let Some(section) = sections.get(options.section) else {
                return Err(BuildError::new(
                    at(PatchField::Section),
                    format!(
                        "section {} does not exist ({} sections)",
                        options.section,
                        sections.len()
                    ),
                ));
            };
            if options.material >= self.materials.len() {
                return Err(BuildError::new(
                    at(PatchField::Material),
                    format!(
                        "material {} does not exist ({} materials)",
                        options.material,
                        self.materials.len()
                    ),
                ));
            }
            if let Some(dev) = fit_error {
                let d = section.diameter();
                if dev > FIT_WARNING_FRACTION * d {
                    warnings.push(format!(
                        "patch {}: the spline fit deviates up to {dev:.3e} from the curve, {:.1}% of the wire diameter; raise n",
                        quoted(name),
                        100.0 * dev / d
                    ));
                }
            }
            out.push(Patch {
                name: name.clone(),
                curve,
                normal_hint: options.normal_hint,
                section: options.section,
                material: options.material,
                fit_error,
            });
        }
        Ok(out)
    }

    fn distributed_loads(&self, patches: &[Patch]) -> Result<Vec<DistributedLoad>> {
        let mut out = Vec::new();
        for (k, d) in self.distributed.iter().enumerate() {
            let targets: Vec<usize> = match &d.patches {
                PatchTarget::All => (0..patches.len()).collect(),
                PatchTarget::Named(name) => {
                    vec![
                        patches
                            .iter()
                            .position(|p| &p.name == name)
                            .ok_or_else(|| {
                                BuildError::new(
                                    Field::DistributedLoad { index: k },
                                    format!(
                                        "no patch {}: name a patch or write `all`",
                                        quoted(name)
                                    ),
                                )
                            })?,
                    ]
                }
            };
            out.extend(targets.into_iter().map(|patch| DistributedLoad {
                patch,
                force: d.force.clone(),
                couple: d.couple.clone(),
            }));
        }
        Ok(out)
    }

    fn probes(&self, patches: &[Patch], nodes: &[Node]) -> Result<Vec<Probe>> {
        let mut out: Vec<Probe> = Vec::new();
        for (k, (name, at)) in self.probes.iter().enumerate() {
            let field = |field| Field::Probe { index: k, field };
            if name.is_empty() || name.contains([',', '"', '\n']) {
                return Err(BuildError::new(
                    field(ProbeField::Name),
                    "a probe name must be non-empty, without commas or quotes",
                ));
            }
            if out.iter().any(|q| &q.name == name) {
                return Err(BuildError::new(
                    field(ProbeField::Name),
                    format!("probe name {} is used twice", quoted(name)),
                ));
            }
            let location = match at {
                ProbeAt::Node(n) => {
                    ProbeLocation::Node(nodes::find(n, patches, nodes).ok_or_else(|| {
                        BuildError::new(field(ProbeField::Node), format!("no node {}", quoted(n)))
                    })?)
                }
                ProbeAt::Patch(patch_name, u) => {
                    let patch = patches
                        .iter()
                        .position(|q| &q.name == patch_name)
                        .ok_or_else(|| {
                            BuildError::new(
                                field(ProbeField::Patch),
                                format!("no patch {}", quoted(patch_name)),
                            )
                        })?;
                    if !(0.0..=1.0).contains(u) {
                        return Err(BuildError::new(
                            field(ProbeField::U),
                            format!("u = {u} must lie in [0, 1]"),
                        ));
                    }
                    ProbeLocation::Patch { patch, u: *u }
                }
            };
            out.push(Probe {
                name: name.clone(),
                location,
            });
        }
        Ok(out)
    }
}

fn check_solver(s: &SolverSettings) -> Result<()> {
    if !(s.tolerance > 0.0 && s.tolerance.is_finite()) {
        return Err(BuildError::new(
            Field::Solver(SolverField::Tolerance),
            format!("{} must be > 0 and finite", s.tolerance),
        ));
    }
    if s.max_iterations == 0 {
        return Err(BuildError::new(
            Field::Solver(SolverField::MaxIterations),
            "must be ≥ 1",
        ));
    }
    if let Some(st) = &s.stabilisation {
        // Both are shares of the strain energy (and the limit of the damping force's share of the loads too):
        // a damping that may dissipate all the energy the device stores, or carry all its loads, is not a
        // stabilisation of a quasi-static run but its load path (issue 31: `dissipated_fraction: 1e6` ended at a
        // dissipated ratio of 19.4).
        for (value, field, what) in [
            (
                st.dissipated_fraction,
                SolverField::DissipatedFraction,
                "the share of the strain energy the first damped step aims to dissipate (Abaqus's default 2e-4)",
            ),
            (
                st.limit,
                SolverField::StabilisationLimit,
                "the share of the strain energy, and of the loads, that the damping may take before the run is warned to be not quasi-static (Abaqus's accuracy tolerance 0.05)",
            ),
        ] {
            if !(value > 0.0 && value < 1.0) {
                return Err(BuildError::new(
                    Field::Solver(field),
                    format!(
                        "{value} must be above 0 and below 1: it is {what}; a damping that takes as much as the device holds carries the run instead of stabilising it"
                    ),
                ));
            }
        }
        if let Some(c) = st.factor
            && !(c > 0.0 && c.is_finite())
        {
            return Err(BuildError::new(
                Field::Solver(SolverField::Stabilisation),
                format!("the damping factor {c} must be > 0 and finite"),
            ));
        }
    }
    Ok(())
}

/// Arc-length continuation follows a load-driven path of a rate-independent model: every material elastic (a
/// viscoelastic response depends on time, which the load factor replaces), no programme, no error-controlled time
/// steps, no contact and no releases (they are about times). Its settings: an end load factor that is finite and
/// not 0, at least one increment, a target of at least one iteration and a growth of at least 1.
fn check_path(
    s: &SolverSettings,
    materials: &[MaterialLaw],
    names: &[String],
    timed: bool,
    nodes: &[crate::model::Node],
) -> Result<()> {
    let PathControl::ArcLength(a) = s.path else {
        return Ok(());
    };
    let path = |why: String| Err(BuildError::new(Field::Solver(SolverField::Path), why));
    if s.stabilisation.is_some() {
        return Err(BuildError::new(
            Field::Solver(SolverField::Stabilisation),
            "stabilisation damps time steps, and an arc-length path has none: it passes limit points by its constraint (remove `stabilisation`, or use `path: time`)",
        ));
    }
    if let Some(m) = materials
        .iter()
        .position(|m| !matches!(m, MaterialLaw::Elastic(_)))
    {
        return path(format!(
            "arc-length continuation needs rate-independent materials, and material `{}` is viscoelastic: its response depends on time, which the load factor replaces (use `path: time`; a release snap of a viscoelastic device is met by step cuts)",
            names.get(m).map_or("?", String::as_str)
        ));
    }
    if timed {
        return path("arc-length continuation follows loads, and a programme (heating, release, recovery), `time.tolerance` (the time-error control) or contact (its surfaces move on schedules in time, its step limit and multiplier updates act per time step) is about times: use `path: time`".into());
    }
    if let Some(node) = nodes.iter().find(|n| {
        n.conditions.components.iter().any(|c| {
            matches!(
                c,
                crate::model::Component::Prescribed {
                    release: Some(_),
                    ..
                }
            )
        })
    }) {
        return path(format!(
            "arc-length continuation has no time at which node `{}` could be released: use `path: time`",
            node.name
        ));
    }
    let settings = |why: &str| Err(BuildError::new(Field::Solver(SolverField::ArcLength), why));
    if !(a.end_load_factor.is_finite() && a.end_load_factor != 0.0) {
        return settings("`end` (the load factor the path ends at) must be finite and not 0");
    }
    if a.max_increments == 0 || a.target_iterations == 0 {
        return settings("`max_increments` and `iterations` must be ≥ 1");
    }
    if !(a.max_growth >= 1.0 && a.max_growth.is_finite()) {
        return settings("`max_growth` must be ≥ 1 and finite");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    //! Each check of the builder reports the field it is about; the positions of the design-file layer rest on
    //! these fields (tests/data/bad_designs checks them end to end, with line and column).
    use super::*;
    use crate::material::{CircularSection, ElasticLaw};

    fn elastic() -> ModelBuilder {
        let section = CircularSection::try_new(0.01).expect("d > 0").into();
        let mut b = ModelBuilder::new(
            "frame",
            ElasticLaw::try_new(1e7, 0.3).expect("valid"),
            section,
        );
        let line = |from: Vec3, to: Vec3| PatchShape::Line { from, to };
        b.patch("beam", line(Vec3::zeros(), Vec3::x()), 3, 6);
        b.patch("post", line(Vec3::x(), Vec3::new(1.0, 1.0, 0.0)), 3, 6);
        b.condition(ConditionSpec::clamp("beam.start"));
        b
    }

    #[track_caller]
    fn field_of(b: &ModelBuilder) -> Field {
        b.build().expect_err("refused").field
    }

    #[test]
    fn a_good_frame_builds_with_its_ends_joined_by_coincidence() {
        let mut b = elastic();
        b.node("knee", NodeEnds::At(Vec3::x()));
        let model = b.build().expect("valid").model;
        // beam.start (clamped), knee (beam.end + post.start), post.end.
        assert_eq!(model.nodes.len(), 3);
        assert_eq!(model.nodes[0].name, "knee");
        assert_eq!(model.nodes[0].ends.len(), 2);
        assert!(b.validate().is_ok());
    }

    // A built model's settings change only through the checked setters, which refuse what the builder refuses
    // at the field the builder names (the reference: the builder given the same settings, `field_of`) and take
    // valid settings as given.
    #[test]
    fn changed_settings_are_checked_as_the_builder_checks_them() {
        let model = elastic().build().expect("valid").model;
        let beyond = TimeSettings {
            step: 2.0 * model.time().end,
            ..model.time().clone()
        };
        let mut b = elastic();
        b.time(TimeSpec::from(&beyond));
        let refused = model
            .clone()
            .with_time(beyond)
            .expect_err("a step beyond the end");
        assert_eq!(refused.field, Field::Time(TimeField::Step));
        assert_eq!(refused.field, field_of(&b));

        let no_iterations = SolverSettings {
            max_iterations: 0,
            ..model.solver().clone()
        };
        let mut b = elastic();
        b.solver(no_iterations.clone());
        let refused = model
            .clone()
            .with_solver(no_iterations)
            .expect_err("no Newton iteration");
        assert_eq!(refused.field, Field::Solver(SolverField::MaxIterations));
        assert_eq!(refused.field, field_of(&b));

        let longer = TimeSettings {
            end: 2.0 * model.time().end,
            ..model.time().clone()
        };
        let changed = model
            .clone()
            .with_time(longer.clone())
            .expect("a longer run");
        assert_eq!(changed.time(), &longer);
        assert_eq!(changed.solver(), model.solver());
    }

    // The setters of the name, record times, temperature and internal-variable update refuse what the builder
    // refuses, with the builder's error (field and message), and leave a model as the builder would have made it.
    #[test]
    fn a_changed_name_is_checked_as_the_builder_checks_it() {
        let model = elastic().build().expect("valid").model;
        let refused = model
            .clone()
            .with_name("runs/frame")
            .expect_err("a path, not a folder name");
        assert_eq!(refused.field, Field::Name);
        assert!(refused.message.contains("a path separator"), "{refused}");
        let mut b = elastic();
        b.name = "runs/frame".into();
        assert_eq!(b.build().expect_err("refused"), refused);

        let renamed = model.clone().with_name("frame_2").expect("a folder name");
        assert_eq!(renamed.name(), "frame_2");
    }

    #[test]
    fn changed_record_times_are_checked_and_held_as_the_builder_holds_them() {
        let model = elastic().build().expect("valid").model;
        assert_eq!(model.time().end, 1.0);
        let beyond = vec![0.5, 1.5];
        let refused = model
            .clone()
            .with_record_times(beyond.clone())
            .expect_err("a record time beyond the end");
        assert_eq!(refused.field, Field::RecordTime { index: 1 });
        assert!(refused.message.contains("≤ the end time 1"), "{refused}");
        let mut b = elastic();
        b.record_times(beyond);
        assert_eq!(b.build().expect_err("refused"), refused);
        for bad in [0.0, Real::NAN, Real::INFINITY] {
            let refused = model.clone().with_record_times(vec![bad]);
            assert_eq!(
                refused.expect_err("not within (0, end]").field,
                Field::RecordTime { index: 0 },
                "{bad}"
            );
        }

        let times = vec![0.75, 0.25, 1.0, 0.25];
        let changed = model
            .clone()
            .with_record_times(times.clone())
            .expect("within the run");
        assert_eq!(changed.record_times(), [0.25, 0.75, 1.0]);
        let mut b = elastic();
        b.record_times(times);
        assert_eq!(b.build().expect("valid").model, changed);
    }

    #[test]
    fn a_changed_temperature_is_checked_as_the_builder_checks_it() {
        let model = elastic().build().expect("valid").model;
        let refused = model
            .clone()
            .with_temperature(TimeFunction::constant(Real::NAN))
            .expect_err("not a temperature");
        assert_eq!(refused.field, Field::Temperature);
        assert!(refused.message.contains("is not finite"), "{refused}");
        let mut b = elastic();
        b.temperature(TimeFunction::constant(Real::NAN));
        assert_eq!(b.build().expect_err("refused"), refused);

        let hot = TimeFunction::constant(90.0);
        let changed = model.with_temperature(hot.clone()).expect("finite");
        let mut b = elastic();
        b.temperature(hot);
        assert_eq!(b.build().expect("valid").model, changed);
    }

    #[test]
    fn a_changed_integrator_is_checked_as_the_builder_checks_it() {
        use crate::material::{Material, Prony, PronyBranch};
        let maxwell = |integrator| {
            let branch = PronyBranch {
                modulus: 2.0e6,
                tau_g: 0.5,
            };
            let prony = Prony::try_new(1.0e6, vec![branch]).expect("valid series");
            let material = Material::try_new(prony, 0.3, None).expect("valid");
            let section = CircularSection::try_new(0.01).expect("d > 0").into();
            let mut b =
                ModelBuilder::new("relaxing", MaxwellLaw::new(material, integrator), section);
            let line = PatchShape::Line {
                from: Vec3::zeros(),
                to: Vec3::x(),
            };
            b.patch("beam", line, 3, 6);
            b.condition(ConditionSpec::clamp("beam.start"));
            b.time(TimeSpec::new(1.0, 0.1).with_tolerance(1e-3));
            b
        };
        let model = maxwell(Integrator::Trapezoidal)
            .build()
            .expect("error control with the trapezoidal rule")
            .model;
        let refused = model
            .clone()
            .with_integrator(Integrator::BackwardEuler)
            .expect_err("backward Euler has no time-error estimate");
        assert_eq!(refused.field, Field::Time(TimeField::Tolerance));
        assert!(
            refused.message.contains("need `integrator: trapezoidal`"),
            "{refused}"
        );
        let b = maxwell(Integrator::BackwardEuler);
        assert_eq!(b.build().expect_err("refused"), refused);

        let fixed_steps = TimeSettings {
            tolerance: None,
            ..model.time().clone()
        };
        let fixed = model.with_time(fixed_steps).expect("fixed steps");
        let changed = fixed
            .with_integrator(Integrator::BackwardEuler)
            .expect("fixed steps need no estimate");
        let MaterialLaw::Maxwell(law) = &changed.materials()[0] else {
            panic!("a Maxwell law stays one");
        };
        assert_eq!(law.integrator(), Integrator::BackwardEuler);
    }

    #[test]
    fn errors_name_the_input_they_are_about() {
        let mut b = elastic();
        b.node(
            "knee",
            NodeEnds::Named(vec!["beam.end".into(), "post.end".into()]),
        );
        assert_eq!(
            field_of(&b),
            Field::Node {
                index: 0,
                field: NodeField::End(1)
            },
            "post.end is 1 away from beam.end"
        );

        let mut b = elastic();
        b.condition(ConditionSpec::at("nowhere"));
        assert_eq!(
            field_of(&b),
            Field::Condition {
                index: 1,
                field: ConditionField::Node
            }
        );

        let mut b = elastic();
        b.condition(ConditionSpec::at("beam.start").with_displacement(1, TimeFunction::zero()));
        assert_eq!(
            field_of(&b),
            Field::Condition {
                index: 1,
                field: ConditionField::Displacement(1)
            },
            "u2 of beam.start is already clamped"
        );

        let mut b = elastic();
        b.condition(
            ConditionSpec::at("post.end")
                .with_displacement(0, TimeFunction::zero())
                .with_force(0, TimeFunction::constant(1.0)),
        );
        assert_eq!(
            field_of(&b),
            Field::Condition {
                index: 1,
                field: ConditionField::Force(0)
            },
            "prescribed and loaded without a release"
        );

        let mut b = elastic();
        b.patch(
            "hook",
            PatchShape::Arc {
                centre: Vec3::zeros(),
                start: Vec3::y(),
                axis: Vec3::z(),
                angle: 3.0,
            },
            3,
            6,
        );
        assert_eq!(
            field_of(&b),
            Field::Patch {
                index: 2,
                field: PatchField::Angle
            },
            "172° is more than one patch holds"
        );

        let mut b = elastic();
        b.patch(
            "bad.name",
            PatchShape::Line {
                from: Vec3::zeros(),
                to: Vec3::y(),
            },
            3,
            6,
        );
        assert_eq!(
            field_of(&b),
            Field::Patch {
                index: 2,
                field: PatchField::Name
            }
        );

        let mut b = elastic();
        b.patch(
            "stub",
            PatchShape::Line {
                from: Vec3::zeros(),
                to: Vec3::y(),
            },
            3,
            3,
        );
        assert_eq!(
            field_of(&b),
            Field::Patch {
                index: 2,
                field: PatchField::ControlPoints
            }
        );

        let mut b = elastic();
        b.time(TimeSpec::new(1.0, 2.0));
        assert_eq!(field_of(&b), Field::Time(TimeField::Step));

        let mut b = elastic();
        b.probe("tip", ProbeAt::Patch("post".into(), 1.5));
        assert_eq!(
            field_of(&b),
            Field::Probe {
                index: 0,
                field: ProbeField::U
            }
        );

        let mut b = elastic();
        b.programme(ProgrammeSpec {
            target: stent_model::ProgrammeTarget::RadialContraction { delta_r: 1.0 },
            node_set: "all_joints".into(),
            ramp: (0.0, 1.0),
            release: None,
        });
        assert_eq!(field_of(&b), Field::Programme(ProgrammeField::Whole));
    }
}
