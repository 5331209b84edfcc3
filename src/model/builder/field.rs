//! What a [`super::ModelBuilder`] reports when an input cannot make a model: a [`BuildError`] carrying the
//! [`Field`] it is about, so that a caller maps it to its own input — the design-file layer to a YAML line and
//! column, a Rust caller to the argument it passed — without reading the message.
//!
//! Entities are counted in the order they were added to the builder (the first patch added is patch 0, even
//! when a generated stent's patches come first in the model).

use crate::geometry::stent::StentParameter;

/// A problem with the builder's input, at a field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct BuildError {
    /// The input it is about.
    pub field: Field,
    /// What is wrong and what is allowed.
    pub message: String,
}

impl BuildError {
    /// The error at `field`.
    pub fn new(field: Field, message: impl Into<String>) -> Self {
        Self {
            field,
            message: message.into(),
        }
    }
}

/// A result whose error is a [`BuildError`].
pub type Result<T> = std::result::Result<T, BuildError>;

/// One input of the builder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {
    /// The model's name ([`super::ModelBuilder::new`]).
    Name,
    /// The set of patches as a whole (e.g. there is none).
    Patches,
    /// A patch added with [`super::ModelBuilder::patch`].
    Patch {
        /// Its index among the added patches.
        index: usize,
        /// Which part of it.
        field: PatchField,
    },
    /// The generated stent ([`super::ModelBuilder::stent`]).
    Stent(StentField),
    /// A node added with [`super::ModelBuilder::node`].
    Node {
        /// Its index among the added nodes.
        index: usize,
        /// Which part of it.
        field: NodeField,
    },
    /// A condition added with [`super::ModelBuilder::condition`].
    Condition {
        /// Its index among the added conditions.
        index: usize,
        /// Which part of it.
        field: ConditionField,
    },
    /// The patch named by a distributed load added with [`super::ModelBuilder::distributed_load`].
    DistributedLoad {
        /// Its index among the added loads.
        index: usize,
    },
    /// The temperature schedule.
    Temperature,
    /// The set of materials (e.g. two share a name).
    Materials,
    /// A time setting.
    Time(TimeField),
    /// A Newton setting.
    Solver(SolverField),
    /// A probe added with [`super::ModelBuilder::probe`].
    Probe {
        /// Its index among the added probes.
        index: usize,
        /// Which part of it.
        field: ProbeField,
    },
    /// The programme ([`super::ModelBuilder::programme`]).
    Programme(ProgrammeField),
    /// A record time given to [`super::ModelBuilder::record_times`].
    RecordTime {
        /// Its index in the list given.
        index: usize,
    },
    /// An obstacle given to [`super::ModelBuilder::contact`].
    Obstacle {
        /// Its index in the list given.
        index: usize,
        /// Which part of it.
        field: ObstacleField,
    },
    /// The contact law's settings given to [`super::ModelBuilder::contact`].
    ContactSettings,
}

/// A part of an obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ObstacleField {
    /// Its name.
    Name,
    /// Its axis (a cylinder) or normal (a plane).
    Direction,
    /// Its radius schedule (a cylinder) or offset schedule (a plane).
    Schedule,
    /// Its wall.
    Wall,
    /// Its friction coefficient.
    Friction,
}

/// A part of a patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PatchField {
    /// Its name.
    Name,
    /// Its degree `p`.
    Degree,
    /// Its number of control points `n`.
    ControlPoints,
    /// Its geometry as a whole.
    Geometry,
    /// The angle of its arc.
    Angle,
    /// Its section.
    Section,
    /// Its material.
    Material,
}

/// A part of the generated stent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StentField {
    /// The stent as a whole.
    Whole,
    /// A generator parameter.
    Parameter(StentParameter),
    /// The degree of the crown (`bridge: false`) or bridge wires.
    Degree {
        /// Bridges rather than crowns.
        bridge: bool,
    },
    /// The number of control points of the crown or bridge wires.
    ControlPoints {
        /// Bridges rather than crowns.
        bridge: bool,
    },
    /// The materials of its crowns and bridges.
    Materials,
}

/// A part of a node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeField {
    /// Its name.
    Name,
    /// Its list of ends as a whole.
    Ends,
    /// One of its ends.
    End(usize),
    /// The point it is placed at.
    At,
}

/// A part of a condition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConditionField {
    /// The condition as a whole.
    Whole,
    /// The node it names.
    Node,
    /// The node set it names.
    NodeSet,
    /// Its basis.
    Basis,
    /// Its symmetry plane.
    SymmetryPlane,
    /// Its clamp.
    Clamp,
    /// A prescribed displacement component.
    Displacement(usize),
    /// A prescribed rotation component.
    Rotation(usize),
    /// A force component.
    Force(usize),
    /// A moment component.
    Moment(usize),
    /// Its release time.
    Release,
}

/// A time setting.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeField {
    /// The end time.
    End,
    /// The nominal step.
    Step,
    /// The smallest step.
    MinStep,
    /// The release ramp.
    ReleaseRamp,
    /// The time-error tolerance of error-controlled stepping.
    Tolerance,
    /// The largest step of error-controlled stepping.
    MaxStep,
}

/// A Newton setting.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolverField {
    /// The tolerance.
    Tolerance,
    /// The iterations allowed per step.
    MaxIterations,
    /// What drives the path (time or arc length).
    Path,
    /// The arc-length settings.
    ArcLength,
    /// The stabilisation settings.
    Stabilisation,
    /// The stabilisation's dissipated-energy fraction.
    DissipatedFraction,
    /// The stabilisation's limit on its energy and force shares.
    StabilisationLimit,
}

/// A part of a probe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProbeField {
    /// Its name.
    Name,
    /// The node it reads.
    Node,
    /// The patch it reads.
    Patch,
    /// The curve parameter it reads at.
    U,
}

/// A part of the programme.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProgrammeField {
    /// The programme as a whole.
    Whole,
    /// The node set it drives.
    Nodes,
    /// The end of its ramp.
    RampEnd,
    /// Its release time.
    Release,
    /// The radius change of a radial contraction.
    DeltaR,
    /// The temporary shape of a target-shape programme.
    Temporary,
    /// Whether the temporary shape is aligned.
    Align,
}
