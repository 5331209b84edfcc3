//! The design file format, version 1, as serde data-transfer objects.
//!
//! Every struct denies unknown fields; numbers are checked while they are read (finite, positive where a
//! size must be), so serde_yaml reports the offending value with its line and column. Checks that need
//! several fields at once are in [`super::build`].

use crate::math::Short;
use schemars::{JsonSchema, Schema, SchemaGenerator, json_schema};
use serde::Deserialize;
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use std::borrow::Cow;
use std::fmt;

/// JSON Schema of a number table `[[t0, v0], [t1, v1], …]` (piecewise linear in time).
fn table_schema() -> serde_json::Value {
    serde_json::json!({
        "type": "array",
        "description": "a table [[t0, v0], [t1, v1], …] of times and values, piecewise linear in time (held constant outside)",
        "items": {
            "type": "array",
            "items": {"type": "number"},
            "minItems": 2,
            "maxItems": 2
        }
    })
}

/// Small schemas written out by hand for the number types that check their values while reading.
macro_rules! inline_schema {
    ($t:ty, $name:literal, $schema:expr) => {
        impl JsonSchema for $t {
            fn inline_schema() -> bool {
                true
            }

            fn schema_name() -> Cow<'static, str> {
                $name.into()
            }

            fn json_schema(_: &mut SchemaGenerator) -> Schema {
                $schema
            }
        }
    };
}

inline_schema!(
    Finite,
    "Finite",
    json_schema!({"type": "number", "description": "a finite number"})
);
inline_schema!(
    Positive,
    "Positive",
    json_schema!({"type": "number", "exclusiveMinimum": 0, "description": "a finite number > 0"})
);
inline_schema!(
    NonNegative,
    "NonNegative",
    json_schema!({"type": "number", "minimum": 0, "description": "a finite number ≥ 0"})
);
inline_schema!(
    TimeFn,
    "TimeFn",
    json_schema!({
        "description": "a function of time: a number (constant) or a table [[t0, v0], [t1, v1], …]",
        "anyOf": [{"type": "number"}, table_schema()]
    })
);
inline_schema!(
    ComponentValue,
    "ComponentValue",
    json_schema!({
        "description": "one component: free (`free` or null), a number, or a table [[t0, v0], [t1, v1], …]",
        "anyOf": [{"type": "null"}, {"const": "free"}, {"type": "number"}, table_schema()]
    })
);

/// A finite number (NaN and ±∞ rejected where read).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Finite(pub f64);

impl<'de> Deserialize<'de> for Finite {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let x = f64::deserialize(d)?;
        if x.is_finite() {
            Ok(Finite(x))
        } else {
            Err(de::Error::custom(format!("{x} is not a finite number")))
        }
    }
}

/// A finite number > 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Positive(pub f64);

impl<'de> Deserialize<'de> for Positive {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let Finite(x) = Finite::deserialize(d)?;
        if x > 0.0 {
            Ok(Positive(x))
        } else {
            Err(de::Error::custom(format!("{} must be > 0", Short(x))))
        }
    }
}

/// A finite number ≥ 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NonNegative(pub f64);

impl<'de> Deserialize<'de> for NonNegative {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let Finite(x) = Finite::deserialize(d)?;
        if x >= 0.0 {
            Ok(NonNegative(x))
        } else {
            Err(de::Error::custom(format!("{} must be ≥ 0", Short(x))))
        }
    }
}

/// A 3-vector of finite numbers, written `[x, y, z]`.
pub(crate) type Vector = [Finite; 3];

/// A design's vector as the model's.
pub(crate) fn vec3(v: &Vector) -> crate::math::Vec3 {
    crate::math::Vec3::new(v[0].0, v[1].0, v[2].0)
}

/// A function of time: a number (constant) or a table `[[t0, v0], [t1, v1], …]` (piecewise linear).
#[derive(Debug, Clone, PartialEq)]
pub enum TimeFn {
    /// A constant.
    Constant(f64),
    /// A table of `(t, value)` points (validated when the model is built).
    Table(Vec<(f64, f64)>),
}

impl<'de> Deserialize<'de> for TimeFn {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(TimeFnVisitor)
    }
}

struct TimeFnVisitor;

impl<'de> Visitor<'de> for TimeFnVisitor {
    type Value = TimeFn;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number or a table [[t0, v0], [t1, v1], …]")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<TimeFn, E> {
        if v.is_finite() {
            Ok(TimeFn::Constant(v))
        } else {
            Err(E::custom(format!("{v} is not a finite number")))
        }
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<TimeFn, E> {
        Ok(TimeFn::Constant(v as f64))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<TimeFn, E> {
        Ok(TimeFn::Constant(v as f64))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<TimeFn, A::Error> {
        let mut points = Vec::new();
        while let Some([Finite(t), Finite(v)]) = seq.next_element::<[Finite; 2]>()? {
            points.push((t, v));
        }
        Ok(TimeFn::Table(points))
    }
}

/// One component of a condition: absent/`null`/`free` (not prescribed), a number or a table.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum ComponentValue {
    /// Not given.
    #[default]
    Free,
    /// Given as a function of time.
    Value(TimeFn),
}

impl<'de> Deserialize<'de> for ComponentValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ComponentVisitor)
    }
}

struct ComponentVisitor;

impl<'de> Visitor<'de> for ComponentVisitor {
    type Value = ComponentValue;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("`free`, null, a number or a table [[t0, v0], [t1, v1], …]")
    }

    fn visit_unit<E: de::Error>(self) -> Result<ComponentValue, E> {
        Ok(ComponentValue::Free)
    }

    fn visit_none<E: de::Error>(self) -> Result<ComponentValue, E> {
        Ok(ComponentValue::Free)
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<ComponentValue, E> {
        if v == "free" {
            Ok(ComponentValue::Free)
        } else {
            Err(E::custom(format!(
                "{} is not a component value; allowed: free, null, a number or a table [[t, v], …]",
                crate::math::quote::quoted(v)
            )))
        }
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<ComponentValue, E> {
        TimeFnVisitor.visit_f64(v).map(ComponentValue::Value)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<ComponentValue, E> {
        TimeFnVisitor.visit_i64(v).map(ComponentValue::Value)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<ComponentValue, E> {
        TimeFnVisitor.visit_u64(v).map(ComponentValue::Value)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<ComponentValue, A::Error> {
        TimeFnVisitor.visit_seq(seq).map(ComponentValue::Value)
    }
}

/// The unit system.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, JsonSchema)]
pub enum UnitsDto {
    /// m, N, Pa, s.
    #[serde(rename = "SI")]
    Si,
    /// mm, N, MPa, s.
    #[serde(rename = "mm-N-MPa")]
    MmNMpa,
}

/// The whole design file.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DesignDto {
    /// Format version; only 1 exists.
    #[serde(default)]
    pub version: Option<u32>,
    /// Design name (defaults to the file stem).
    #[serde(default)]
    pub name: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
    /// Unit system (required).
    pub units: UnitsDto,
    /// The material (every patch's unless it names another of `materials`).
    pub material: MaterialDto,
    /// More materials, each with a `name`, for patches (`patches[].material`) and stent parts
    /// (`stent.materials`) to name.
    #[serde(default)]
    pub materials: Vec<MaterialDto>,
    /// The cross-section of every patch (patches may override the diameter).
    pub section: SectionDto,
    /// Default discretisation of patches.
    #[serde(default)]
    pub mesh: Option<MeshDto>,
    /// Rod patches (besides those of a generated `stent`).
    #[serde(default)]
    pub patches: Vec<PatchDto>,
    /// A generated stent: crowns, bridges, centreline, symmetry ([`super::stent`]).
    #[serde(default)]
    pub stent: Option<StentDto>,
    /// A programme driving a node set of the stent to a target shape ([`super::stent`]).
    #[serde(default)]
    pub programme: Option<ProgrammeDto>,
    /// Automatic joining of coincident patch ends.
    #[serde(default)]
    pub joints: Option<JointsDto>,
    /// Named nodes.
    #[serde(default)]
    pub nodes: Vec<NodeDto>,
    /// Boundary conditions and concentrated loads.
    #[serde(default)]
    pub conditions: Vec<ConditionDto>,
    /// Distributed loads.
    #[serde(default)]
    pub distributed_loads: Vec<DistributedLoadDto>,
    /// Temperature [°C] as a function of time (uniform over the device; with `temperature_field`, the schedule
    /// reports show).
    #[serde(default)]
    pub temperature: Option<TimeFn>,
    /// A temperature that varies in space along an axis: schedules at stations, or a moving front.
    #[serde(default)]
    pub temperature_field: Option<TemperatureFieldDto>,
    /// Surfaces the rods touch: crimpers, sheaths, plates (module docs of `crate::model::obstacle`).
    #[serde(default)]
    pub obstacles: Vec<ObstacleDto>,
    /// How contact with the obstacles is enforced (defaults from the design's material and wire).
    #[serde(default)]
    pub contact: Option<ContactDto>,
    /// Time stepping.
    pub time: TimeDto,
    /// Newton settings.
    #[serde(default)]
    pub solver: Option<SolverDto>,
    /// Outputs.
    #[serde(default)]
    pub output: Option<OutputDto>,
    /// The virtual bench's settings (`stentkit bench radial`; every one optional): read by the bench
    /// commands only, a run ignores them.
    #[serde(default)]
    pub bench: Option<BenchDto>,
}

/// The virtual bench's settings (module docs of `crate::bench`).
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BenchDto {
    /// Temperature of the test \[°C\] (default 37, body temperature).
    #[serde(default)]
    pub temperature: Option<f64>,
    /// Rate of the crimper's diameter \[length/time\] (default 0.1 mm/s).
    #[serde(default)]
    pub rate: Option<Positive>,
    /// The smallest diameter the crimper closes to \[length\] (default: the programme's crimped or contracted
    /// outer diameter `2 (R − Δr) + d`, or half the device's outer diameter without a programme).
    #[serde(default)]
    pub min_diameter: Option<Positive>,
    /// The vessel's diameter, where the chronic outward force is read \[length\] (default: a vessel file's
    /// mean lumen diameter; none without one).
    #[serde(default)]
    pub vessel_diameter: Option<Positive>,
    /// Diameters recorded on each branch, closing and opening (default 30, at least 2).
    #[serde(default)]
    pub diameters: Option<usize>,
    /// The smallest gap the crush plates close to \[length\] (default half the device's outer diameter, a
    /// 50 % crush).
    #[serde(default)]
    pub min_gap: Option<Positive>,
    /// The radial bench's crimper as a segmented head of this many flat segments (default: a cylinder).
    #[serde(default)]
    pub segments: Option<usize>,
}

/// An obstacle: a named surface (give exactly one of `cylinder`, `plane` or `lumen`) with its wall and the times
/// it acts between.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ObstacleDto {
    /// Unique name (history columns, messages); `crimper` is taken by a crimp programme's, `upper_plate` and
    /// `lower_plate` by a crush programme's.
    pub name: String,
    /// A circular cylinder that keeps the rods inside it (a crimper, a sheath, a tube).
    #[serde(default)]
    pub cylinder: Option<CylinderDto>,
    /// A plane that keeps the rods on the side its normal points to (a crush plate, a table).
    #[serde(default)]
    pub plane: Option<PlaneDto>,
    /// The lumen of the stent's vessel (a `stent.centreline.file` with its lumen radius): the rods are kept
    /// inside it.
    #[serde(default)]
    pub lumen: Option<LumenDto>,
    /// A compliant wall (a thin elastic tube acting as a radial foundation of stiffness `E h / R²`); without
    /// it the wall is rigid.
    #[serde(default)]
    pub wall: Option<WallDto>,
    /// The time it is put in place \[time\]: it acts after it (default 0, from the start).
    #[serde(default)]
    pub from: Option<NonNegative>,
    /// The time it is withdrawn \[time\] (default: never).
    #[serde(default)]
    pub until: Option<Positive>,
    /// Coulomb friction coefficient μ between the wires and this surface (default 0, frictionless).
    #[serde(default)]
    pub friction: Option<NonNegative>,
}

/// A cylinder obstacle.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CylinderDto {
    /// A point of its axis \[length\].
    pub point: Vector,
    /// Direction of its axis (normalised when read).
    pub axis: Vector,
    /// Its radius \[length\]: a number or a table `[[t, r], …]` (a crimper closes and opens).
    pub radius: TimeFn,
}

/// The vessel's lumen as an obstacle.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LumenDto {
    /// A factor on the lumen radius: a number or a table `[[t, f], …]` (default 1).
    #[serde(default)]
    pub scale: Option<TimeFn>,
    /// A radius of its own along the vessel's centreline instead of the file's lumen radius \[length\]: a
    /// number or a table `[[t, r], …]` (a sheath or a catheter that follows the vessel); not with `scale`.
    #[serde(default)]
    pub radius: Option<TimeFn>,
}

/// A plane obstacle.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PlaneDto {
    /// A point of the plane \[length\].
    pub point: Vector,
    /// Its normal, pointing to the rods' side (normalised when read).
    pub normal: Vector,
    /// Its displacement along the normal \[length\]: a number or a table `[[t, s], …]` (default 0).
    #[serde(default)]
    pub offset: Option<TimeFn>,
}

/// A compliant wall: a thin tube of Young's modulus `E`, thickness and the width of wall each unit length of
/// wire carries.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WallDto {
    /// Young's modulus of the wall \[stress\].
    #[serde(rename = "E")]
    pub modulus: Option<Positive>,
    /// Wall thickness \[length\].
    #[serde(default)]
    pub thickness: Option<Positive>,
    /// Width of wall per unit length of wire \[length\] (default: the wire's diameter).
    #[serde(default)]
    pub width: Option<Positive>,
}

/// The contact law's settings (every one optional).
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ContactDto {
    /// Penalty \[force/length²\]: line force per unit wire length per unit penetration (default: `E_inf I / d⁴`,
    /// the wire's bending stiffness at the scale of its diameter with the relaxed modulus).
    #[serde(default)]
    pub penalty: Option<Positive>,
    /// Width of the law's quadratic transition \[length\] (default: a tenth of `tolerance`).
    #[serde(default)]
    pub regularisation: Option<Positive>,
    /// Largest penetration a step may keep \[length\] (default: 1 % of the wire diameter).
    #[serde(default)]
    pub tolerance: Option<Positive>,
    /// Most augmented-Lagrange updates per step (default 10).
    #[serde(default)]
    pub max_updates: Option<usize>,
    /// Contact between the device's own wires, with the same law (default false: wires pass through each
    /// other, which the run reports).
    #[serde(default)]
    pub wires: Option<bool>,
}

/// Material block.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MaterialDto {
    /// Name (required in `materials`; `material` is named `material` unless it says otherwise).
    #[serde(default)]
    pub name: Option<String>,
    /// Equilibrium modulus E∞ \[stress\], ≥ 0.
    #[serde(rename = "E_inf")]
    pub e_inf: NonNegative,
    /// Maxwell branches `[E_α, τ_G,α]`.
    #[serde(default)]
    pub prony: Vec<[Finite; 2]>,
    /// Poisson's ratio.
    pub nu: Finite,
    /// WLF shift (omit for a temperature-independent material).
    #[serde(default)]
    pub wlf: Option<WlfDto>,
    /// Internal-variable update: `trapezoidal` (default), `backward-euler`, `exponential`.
    #[serde(default)]
    pub integrator: Option<IntegratorDto>,
    /// The surface strain the printed material survives [-] (a fraction: its elongation at break, e.g. 0.06
    /// for 6 %): `run` warns when the peak surface strain of a rod of this material exceeds it.
    #[serde(default)]
    pub strain_limit: Option<Positive>,
}

/// WLF constants.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WlfDto {
    /// C1 [-].
    #[serde(rename = "C1")]
    pub c1: Finite,
    /// C2 \[K\].
    #[serde(rename = "C2")]
    pub c2: Finite,
    /// Glass transition (reference) temperature [°C].
    #[serde(rename = "Tg")]
    pub tg: Finite,
}

/// Internal-variable update.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum IntegratorDto {
    /// The paper's trapezoidal rule.
    Trapezoidal,
    /// Backward Euler.
    BackwardEuler,
    /// Exact for strain linear in reduced time.
    Exponential,
}

/// Cross-section: a solid circle (`diameter`) or given properties (`area`, `inertia`, `polar`).
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SectionDto {
    /// Circular section diameter \[length\].
    #[serde(default)]
    pub diameter: Option<Positive>,
    /// Area \[length²\].
    #[serde(default)]
    pub area: Option<Positive>,
    /// Second moment of area about either section axis \[length⁴\].
    #[serde(default)]
    pub inertia: Option<Positive>,
    /// Torsion constant \[length⁴\].
    #[serde(default)]
    pub polar: Option<Positive>,
    /// Diameter of the tube drawn for a section given by properties \[length\].
    #[serde(default)]
    pub draw_diameter: Option<Positive>,
    /// Shear correction factor (default: Cowper's value for a solid circle).
    #[serde(default)]
    pub shear_factor: Option<Positive>,
}

/// Discretisation.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MeshDto {
    /// Degree.
    pub p: Option<usize>,
    /// Control (= collocation) points per patch.
    pub n: Option<usize>,
}

/// A patch; exactly one geometry key.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PatchDto {
    /// Unique name.
    pub name: String,
    /// Straight line.
    #[serde(default)]
    pub line: Option<LineDto>,
    /// Circular arc (exact).
    #[serde(default)]
    pub arc: Option<ArcDto>,
    /// Helix (fitted).
    #[serde(default)]
    pub helix: Option<HelixDto>,
    /// Sinusoidal crown wire (fitted).
    #[serde(default)]
    pub sine_wire: Option<SineWireDto>,
    /// Curve through points (fitted).
    #[serde(default)]
    pub points: Option<Vec<Vector>>,
    /// Degree (overrides `mesh.p`).
    #[serde(default)]
    pub p: Option<usize>,
    /// Control points (overrides `mesh.n`).
    #[serde(default)]
    pub n: Option<usize>,
    /// Diameter (overrides `section.diameter`).
    #[serde(default)]
    pub diameter: Option<Positive>,
    /// The name of its material (default: `material`'s).
    #[serde(default)]
    pub material: Option<String>,
    /// Hint for the first section axis at the start.
    #[serde(default)]
    pub normal: Option<Vector>,
}

/// Line from a point to a point.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LineDto {
    /// Start point.
    pub from: Vector,
    /// End point.
    pub to: Vector,
}

/// Circular arc.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ArcDto {
    /// Centre.
    pub center: Vector,
    /// Start point.
    pub start: Vector,
    /// Rotation axis (right-hand rule).
    pub axis: Vector,
    /// Swept angle \[degrees\].
    pub angle_deg: Finite,
}

/// Helix about a local z axis.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HelixDto {
    /// Radius.
    pub radius: Positive,
    /// Rise per turn.
    pub pitch: Finite,
    /// Number of turns.
    pub turns: Positive,
    /// Start angle \[degrees\].
    #[serde(default)]
    pub start_deg: Option<Finite>,
    /// Centre of the base circle.
    #[serde(default)]
    pub origin: Option<Vector>,
    /// Helix axis (local z).
    #[serde(default)]
    pub axis: Option<Vector>,
    /// Direction of the local x axis (angle 0).
    #[serde(default)]
    pub x_axis: Option<Vector>,
}

/// Sinusoidal wire on a cylinder about a local z axis.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SineWireDto {
    /// Cylinder radius.
    pub radius: Positive,
    /// Amplitude (half the crown height).
    pub amplitude: Finite,
    /// Waves per full turn.
    pub waves: Positive,
    /// Start angle \[degrees\].
    pub from_deg: Finite,
    /// End angle \[degrees\].
    pub to_deg: Finite,
    /// Phase \[degrees\].
    #[serde(default)]
    pub phase_deg: Option<Finite>,
    /// Cylinder centre.
    #[serde(default)]
    pub origin: Option<Vector>,
    /// Cylinder axis (local z).
    #[serde(default)]
    pub axis: Option<Vector>,
    /// Direction of the local x axis (angle 0).
    #[serde(default)]
    pub x_axis: Option<Vector>,
}

/// Automatic joints.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JointsDto {
    /// Join every set of patch ends closer than this \[length\].
    pub tolerance: Positive,
}

/// A named node.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NodeDto {
    /// Unique name.
    pub name: String,
    /// The patch ends it joins (`patch.start`, `patch.end`).
    #[serde(default)]
    pub ends: Option<Vec<String>>,
    /// Or: every patch end at this point.
    #[serde(default)]
    pub at: Option<Vector>,
}

/// Conditions at one node, or at every node of a named set; exactly one of `node` and `node_set`.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConditionDto {
    /// Node name (or `patch.start` / `patch.end`).
    #[serde(default)]
    pub node: Option<String>,
    /// Node set name: a generated stent's `all_joints`, `crests`, `troughs`, `crown_<k>` (k = 1, 2, … along
    /// the centreline), `bridge_ends` or `symmetry`.
    #[serde(default)]
    pub node_set: Option<String>,
    /// Local basis: three rows, the unit axes e1, e2, e3 (orthonormal, right-handed).
    #[serde(default)]
    pub basis: Option<[Vector; 3]>,
    /// All six components held at zero.
    #[serde(default)]
    pub clamp: bool,
    /// Symmetry plane with this normal: normal translation and in-plane rotations held at zero.
    #[serde(default)]
    pub symmetry_plane: Option<Vector>,
    /// Prescribed displacement components (in the local basis).
    #[serde(default)]
    pub displacement: Option<[ComponentValue; 3]>,
    /// Prescribed rotation components \[rad\] (in the local basis).
    #[serde(default)]
    pub rotation: Option<[ComponentValue; 3]>,
    /// Force components on free components (dead load).
    #[serde(default)]
    pub force: Option<[ComponentValue; 3]>,
    /// Moment components on free components (dead load).
    #[serde(default)]
    pub moment: Option<[ComponentValue; 3]>,
    /// Time from which the prescribed components of this entry are released (become free).
    #[serde(default)]
    pub release: Option<NonNegative>,
}

/// A distributed load.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DistributedLoadDto {
    /// Patch name, or `all`.
    pub patch: String,
    /// Force per unit length, global components.
    #[serde(default)]
    pub force: Option<[TimeFn; 3]>,
    /// Couple per unit length, global components.
    #[serde(default)]
    pub couple: Option<[TimeFn; 3]>,
}

/// Time stepping.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TimeDto {
    /// End time.
    pub end: Positive,
    /// Nominal step (fixed steps); with `tolerance`, the first step (default: end / 1000).
    #[serde(default)]
    pub step: Option<Positive>,
    /// Time-error tolerance: error-controlled steps (normalised as Newton's increments) instead of fixed ones.
    #[serde(default)]
    pub tolerance: Option<Positive>,
    /// Largest step of error-controlled stepping (default: the end time).
    #[serde(default)]
    pub max_step: Option<Positive>,
    /// Smallest step of automatic step cutting.
    #[serde(default)]
    pub min_step: Option<Positive>,
    /// Duration of the ramp from a released component's reaction to its load after release.
    #[serde(default)]
    pub release_ramp: Option<Positive>,
}

/// Newton settings.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SolverDto {
    /// Convergence tolerance.
    #[serde(default)]
    pub tolerance: Option<Positive>,
    /// Iterations per step.
    #[serde(default)]
    pub max_iterations: Option<usize>,
    /// Reuse the tangent's factorisation across iterations and steps (default true).
    #[serde(default)]
    pub reuse_factorisation: Option<bool>,
    /// Start each step from the previous step's increment, scaled to the step size (default false).
    #[serde(default)]
    pub extrapolate: Option<bool>,
    /// Linear solver: `block` (banded per patch + Schur complement on the patch ends, default) or `sparse-lu`.
    #[serde(default)]
    pub linear: Option<LinearDto>,
    /// The rotation field: `objective` (rotations at the control points interpolated relative to a reference
    /// rotation per patch: path-independent and objective; the default) or `incremental` (the paper's updates at
    /// the collocation points, which the paper's designs name).
    #[serde(default)]
    pub rotations: Option<RotationsDto>,
    /// What drives the path: `time` (the schedules, default) or `arc-length` (Riks/Crisfield continuation of
    /// the loads at `time.end` scaled by a load factor; elastic materials, no programme).
    #[serde(default)]
    pub path: Option<PathDto>,
    /// Arc-length settings (with `path: arc-length`).
    #[serde(default)]
    pub arc_length: Option<ArcLengthDto>,
    /// Automatic stabilisation where Newton stalls (time-driven paths): viscous damping of the motion since
    /// the last converged state, its dissipated energy reported (`{}` for the defaults).
    #[serde(default)]
    pub stabilisation: Option<StabilisationDto>,
}

/// Automatic stabilisation settings.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StabilisationDto {
    /// Dissipated energy the first damped step aims at, as a fraction of the strain energy (default 2e-4;
    /// below 1).
    #[serde(default)]
    pub dissipated_fraction: Option<Positive>,
    /// The run's dissipated energy over its largest strain energy, and a damped step's damping force over the
    /// loads, reactions and walls' contact, above which a warning is given (default 0.05; below 1).
    #[serde(default)]
    pub limit: Option<Positive>,
    /// A damping factor c [1/time] given outright instead of the energy rule.
    #[serde(default)]
    pub factor: Option<Positive>,
}

/// What drives the path.
#[derive(Debug, Clone, Copy, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum PathDto {
    /// Time steps through the schedules.
    Time,
    /// Arc-length continuation in the load factor.
    ArcLength,
}

/// The arc-length constraint.
#[derive(Debug, Clone, Copy, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum ArcConstraintDto {
    /// The load factor takes no part in the arc length (default).
    Cylindrical,
    /// The load factor counts as one more unknown.
    Spherical,
}

/// Arc-length continuation settings.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ArcLengthDto {
    /// The load factor the path ends at (default 1: the loads at `time.end`).
    #[serde(default)]
    pub end: Option<f64>,
    /// Increments allowed (default 1000).
    #[serde(default)]
    pub max_increments: Option<usize>,
    /// Newton iterations an increment aims at (default 4).
    #[serde(default)]
    pub iterations: Option<usize>,
    /// Largest arc length as a multiple of the first (default 10).
    #[serde(default)]
    pub max_growth: Option<f64>,
    /// `cylindrical` (default) or `spherical`.
    #[serde(default)]
    pub constraint: Option<ArcConstraintDto>,
}

/// Rotation field names.
#[derive(Debug, Clone, Copy, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum RotationsDto {
    /// Rotations at the control points, interpolated as rotation vectors relative to a reference rotation per
    /// patch: objective and path-independent.
    Objective,
    /// The paper's incremental updates at the collocation points.
    Incremental,
}

/// Linear solver names.
#[derive(Debug, Clone, Copy, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum LinearDto {
    /// Banded LU per patch and a sparse LU of the Schur complement on the patch ends.
    Block,
    /// General sparse LU of the whole system.
    SparseLu,
}

/// Outputs.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OutputDto {
    /// Recorded points.
    #[serde(default)]
    pub probes: Vec<ProbeDto>,
    /// Tube meshes of the full device written during a run (`snapshots/t1.750_fixed.stl`: named by time and
    /// phase of the shape-memory cycle).
    #[serde(default)]
    pub snapshots: Option<SnapshotsDto>,
    /// `history.csv`: a row at every converged step, and at the times asked here.
    #[serde(default)]
    pub history: Option<HistoryDto>,
    /// What `run.mcap` holds besides the state per step.
    #[serde(default)]
    pub recording: Option<RecordingDto>,
    /// Fields along the rods for ParaView with every snapshot (`snapshots/t1.750_fixed.vtp`, listed in `run.pvd`
    /// with their times); default true.
    #[serde(default)]
    pub vtk: Option<bool>,
    /// The configuration figures (`charts/configurations.svg`).
    #[serde(default)]
    pub configurations: Option<ConfigurationsDto>,
}

/// `history.csv`'s rows besides the steps'.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HistoryDto {
    /// Times at which to write a row \[time\], within [0, time.end]: fixed steps land on each; an
    /// error-controlled run (`time.tolerance`) takes the state there from its continuous extension, within its
    /// tolerance, without a step there. Rows at these times (and at the snapshot times) have `requested` = 1 (a
    /// step there) or 2 (the continuous extension's state between steps).
    #[serde(default)]
    pub times: Option<Vec<NonNegative>>,
}

/// The configuration figures: which views.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConfigurationsDto {
    /// Panels per time: `axonometric`, `x1-x2`, `x1-x3`, `x2-x3` (default: axonometric and the plane of the
    /// initial shape's two largest extents).
    #[serde(default)]
    pub views: Option<Vec<String>>,
    /// Also a shaded picture of the tube meshes at the same times, in the first view
    /// (`charts/configurations.png`); default true.
    #[serde(default)]
    pub render: Option<bool>,
}

/// Snapshots: the initial and final shapes always, the cycle's events (programmed, fixed, released), and a few
/// between them; or every `every` steps and at the given times. Each is named by its time and phase
/// (`t1.750_fixed.stl`; `step_00012.stl` on an arc-length path).
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SnapshotsDto {
    /// Times at which to write a snapshot \[time\], within [0, time.end]: fixed steps land on each; an
    /// error-controlled run (`time.tolerance`) takes the state there from its continuous extension, without a
    /// step there.
    #[serde(default)]
    pub times: Option<Vec<NonNegative>>,
    /// A snapshot every this many converged steps (0: none). Default: none (on an arc-length path, about 20
    /// over its increments).
    #[serde(default)]
    pub every: Option<usize>,
    /// A snapshot at each event of the shape-memory cycle: the end of programming, the release (still held:
    /// `fixed`) and its end (`released`); default true.
    #[serde(default)]
    pub events: Option<bool>,
    /// Snapshots between the events: the run, cut at its events, is divided into about this many equal
    /// pieces, a snapshot at the first step at or after each cut (no step lands on them). Default 6 when
    /// neither `every` nor `times` is given, else 0.
    #[serde(default)]
    pub between: Option<usize>,
    /// File formats: `stl`, `obj` (default `[stl]`).
    #[serde(default)]
    pub formats: Option<Vec<String>>,
    /// Vertices around each tube section (default 12, at least 3).
    #[serde(default)]
    pub segments: Option<usize>,
    /// Rings (sections) along each patch, about (default 41, at least 2).
    #[serde(default)]
    pub rings: Option<usize>,
}

/// The recording (`run.mcap`): whether, and at which resolution.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RecordingDto {
    /// Write `run.mcap` at all (default true).
    #[serde(default)]
    pub enabled: Option<bool>,
    /// Points per patch of the centrelines recorded at every step (default 21, at least 2; never more than
    /// one per control point).
    #[serde(default)]
    pub centreline_points: Option<usize>,
    /// Record the tube meshes at snapshot steps (default true).
    #[serde(default)]
    pub meshes: Option<bool>,
    /// Vertices around each tube section of the recorded meshes (default 8, at least 3).
    #[serde(default)]
    pub mesh_segments: Option<usize>,
    /// Rings along each patch of the recorded meshes, about (default 21, at least 2).
    #[serde(default)]
    pub mesh_rings: Option<usize>,
}

/// A probe: at a node, or on a patch at a parameter.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ProbeDto {
    /// Column prefix in history.csv.
    pub name: String,
    /// Node name.
    #[serde(default)]
    pub node: Option<String>,
    /// Patch name.
    #[serde(default)]
    pub patch: Option<String>,
    /// Curve parameter on the patch, in [0, 1].
    #[serde(default)]
    pub u: Option<Finite>,
}

/// The `stent:` block.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StentDto {
    /// The device family: `ring` (crowns joined by bridges, the default) or `diamond` (closed diamond cells:
    /// neighbouring rings meet crest to trough, no bridges).
    #[serde(default)]
    pub family: StentFamilyDto,
    /// Number of crowns (the rings of a diamond stent).
    pub crowns: usize,
    /// Crown radius `R` \[length\]; or give `oversize` to size the stent from a file centreline's lumen radius.
    #[serde(default)]
    pub radius: Option<Positive>,
    /// With a file centreline that has the lumen radius: `R` = the segment's mean lumen radius × (1 + oversize).
    #[serde(default)]
    pub oversize: Option<NonNegative>,
    /// With `oversize`: size each crown from the lumen radius at its own station (× (1 + oversize)) instead of
    /// the segment's mean; bridges taper between their crowns.
    #[serde(default)]
    pub taper: bool,
    /// Crown amplitude `h_c` (half the crown height) \[length\].
    pub amplitude: Positive,
    /// Crests per crown.
    pub peaks: usize,
    /// The wire between a crest and a trough: `sinusoidal` (the default) or `zigzag` (straight struts, a
    /// Z-ring; ring family only).
    #[serde(default)]
    pub crown_shape: Option<CrownShapeDto>,
    /// Crown spacing `d_c` along the centreline \[length\].
    #[serde(default)]
    pub spacing: Option<Positive>,
    /// Rotation of each crown about the axis relative to the previous one \[degrees\] (default `180/peaks`).
    #[serde(default)]
    pub rotation_deg: Option<Finite>,
    /// Bridges between consecutive crowns (none when absent).
    #[serde(default)]
    pub bridges: Option<BridgesDto>,
    /// The stent axis.
    #[serde(alias = "centerline")]
    pub centreline: CentrelineDto,
    /// Symmetry of the device: `none` (default), `half`, `quarter`.
    #[serde(default)]
    pub symmetry: Option<SymmetryDto>,
    /// Model the whole (symmetric) device instead of one sector.
    #[serde(default)]
    pub full_model: bool,
    /// Discretisation of the crown wires (default: `mesh`).
    #[serde(default)]
    pub crown_mesh: Option<MeshDto>,
    /// Discretisation of the bridges (default: `mesh`).
    #[serde(default)]
    pub bridge_mesh: Option<MeshDto>,
    /// The materials of crowns and bridges (default: `material` everywhere).
    #[serde(default)]
    pub materials: Option<StentMaterialsDto>,
}

/// The materials of a stent's parts, by name.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StentMaterialsDto {
    /// One name for every crown, or a list with one per crown (first crown first).
    #[serde(default)]
    pub crowns: Option<OneOrMany>,
    /// The bridges' material.
    #[serde(default)]
    pub bridges: Option<String>,
}

/// A name or a list of names.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum OneOrMany {
    /// One name.
    One(String),
    /// A list of names.
    Many(Vec<String>),
}

/// A temperature field: `T(ζ, t)` with `ζ = direction·(X − origin)` of the reference position `X`.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TemperatureFieldDto {
    /// `X₀` \[length\] (default the origin).
    #[serde(default)]
    pub origin: Option<Vector>,
    /// The axis along which the temperature varies.
    pub direction: Vector,
    /// Schedules at stations along the axis (linear between them); or give `front`.
    #[serde(default)]
    pub stations: Option<Vec<StationDto>>,
    /// A front moving along the axis.
    #[serde(default)]
    pub front: Option<FrontDto>,
}

/// A station of a temperature field.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StationDto {
    /// Its coordinate `ζ` \[length\].
    pub at: Finite,
    /// Its temperature [°C] as a function of time.
    #[serde(rename = "T")]
    pub temperature: TimeFn,
}

/// A moving temperature front.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FrontDto {
    /// Its position `ζ_f(t)` \[length\].
    pub position: TimeFn,
    /// Its width \[length\] (the temperature goes from 12 % to 88 % of the jump over four widths).
    pub width: Positive,
    /// The temperature behind it (`ζ < ζ_f`) [°C].
    pub behind: TimeFn,
    /// The temperature ahead of it [°C].
    pub ahead: TimeFn,
}

/// Crown shape keyword.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum CrownShapeDto {
    /// Sinusoidal, smooth through crests and troughs.
    Sinusoidal,
    /// Straight struts between crests and troughs.
    Zigzag,
}

/// Bridge shape keyword.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BridgeShapeDto {
    /// Straight.
    Straight,
    /// Sinusoidal.
    Sinusoidal,
}

/// Sinusoidal bridge direction keyword.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BridgeDirectionDto {
    /// On the cylinder.
    Circumferential,
    /// In the meridional plane.
    Radial,
}

/// The bridges.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BridgesDto {
    /// `straight` or `sinusoidal`.
    pub shape: BridgeShapeDto,
    /// Amplitude `h_b` of a sinusoidal bridge \[length\].
    #[serde(default)]
    pub amplitude: Option<Positive>,
    /// Waves over a sinusoidal bridge (default 1; a multiple of 1/2).
    #[serde(default)]
    pub waves: Option<Positive>,
    /// `circumferential` (default) or `radial`.
    #[serde(default)]
    pub direction: Option<BridgeDirectionDto>,
    /// A bridge at every `every`-th crest (default 1: every crest).
    #[serde(default)]
    pub every: Option<usize>,
    /// The first bridged crest, 1-based (default 1: the crest at ϑ = rotation × crown index).
    #[serde(default)]
    pub first: Option<usize>,
}

/// The centreline: exactly one of `straight`, `arc`, `points`, `file`.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CentrelineDto {
    /// A vessel centreline read from a file ([`crate::io::centreline`]).
    #[serde(default)]
    pub file: Option<FileCentrelineDto>,
    /// A straight axis.
    #[serde(default)]
    pub straight: Option<StraightDto>,
    /// A circular arc.
    #[serde(default)]
    pub arc: Option<ArcCentrelineDto>,
    /// A spline through points.
    #[serde(default)]
    pub points: Option<PointsCentrelineDto>,
}

/// A straight axis.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StraightDto {
    /// Centre of the first crown (default origin).
    #[serde(default)]
    pub origin: Option<Vector>,
    /// Axis direction (default `[1, 0, 0]`).
    #[serde(default)]
    pub direction: Option<Vector>,
    /// Direction of ϑ = 0 (the first symmetry plane contains it and the axis).
    #[serde(default)]
    pub reference: Option<Vector>,
}

/// A circular-arc axis.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ArcCentrelineDto {
    /// Centre of the circle.
    pub center: Vector,
    /// Start point (the first crown's centre).
    pub start: Vector,
    /// Rotation axis (right-hand rule).
    pub axis: Vector,
    /// Swept angle \[degrees\].
    pub angle_deg: Finite,
    /// Direction of ϑ = 0 at the start (default: outward from the centre).
    #[serde(default)]
    pub reference: Option<Vector>,
}

/// A point-list axis.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PointsCentrelineDto {
    /// The points (a cubic spline passes through them).
    pub points: Vec<Vector>,
    /// Direction of ϑ = 0 at the start.
    #[serde(default)]
    pub reference: Option<Vector>,
}

/// A vessel centreline from a file: one polyline, a segment of it, smoothed by a cubic spline.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FileCentrelineDto {
    /// The file (`.vtp`, `.vtk`, `.pth`, `.csv`), relative to the design file's folder or absolute.
    pub path: String,
    /// Which polyline: its index in the file (from 0) or `longest` (default).
    #[serde(default)]
    pub polyline: Option<PolylineChoiceDto>,
    /// Walk the polyline from its last point.
    #[serde(default)]
    pub reverse: bool,
    /// Arc length along the polyline where the segment starts [the design's length unit] (default 0).
    #[serde(default)]
    pub start: Option<NonNegative>,
    /// Length of the segment [the design's length unit] (default: to the polyline's end).
    #[serde(default)]
    pub length: Option<Positive>,
    /// The file's length unit: `mm`, `cm` or `m` (default: the design's).
    #[serde(default)]
    pub unit: Option<FileUnitDto>,
    /// Largest distance of the smooth centreline from the file's points [the design's length unit] (default:
    /// a thousandth of the segment's length).
    #[serde(default)]
    pub smoothing: Option<Positive>,
    /// The point array holding the lumen radius (default `MaximumInscribedSphereRadius`, VMTK's).
    #[serde(default)]
    pub radius_array: Option<String>,
    /// Direction of ϑ = 0 at the start.
    #[serde(default)]
    pub reference: Option<Vector>,
}

/// Which polyline of a centreline file: an index or `longest` (read by `PolylineChoiceVisitor`, which says
/// what is allowed when neither fits; an untagged enum would only say that no variant matched).
#[derive(Debug, Clone, Copy, PartialEq, Eq, JsonSchema)]
#[serde(untagged)]
pub enum PolylineChoiceDto {
    /// Its index, from 0.
    Index(usize),
    /// `longest`.
    Keyword(PolylineKeywordDto),
}

impl<'de> Deserialize<'de> for PolylineChoiceDto {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(PolylineChoiceVisitor)
    }
}

struct PolylineChoiceVisitor;

impl PolylineChoiceVisitor {
    /// The refusal of `value` (already written for a message).
    fn refused<E: de::Error>(value: &str) -> E {
        E::custom(format!(
            "{value} is not a polyline of the file: give its index (0, 1, …) or `longest`"
        ))
    }
}

impl<'de> Visitor<'de> for PolylineChoiceVisitor {
    type Value = PolylineChoiceDto;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a polyline index (0, 1, …) or `longest`")
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<PolylineChoiceDto, E> {
        usize::try_from(v)
            .map(PolylineChoiceDto::Index)
            .map_err(|_| Self::refused(&v.to_string()))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<PolylineChoiceDto, E> {
        match u64::try_from(v) {
            Ok(v) => self.visit_u64(v),
            Err(_) => Err(Self::refused(&v.to_string())),
        }
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<PolylineChoiceDto, E> {
        Err(Self::refused(&Short(v).to_string()))
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<PolylineChoiceDto, E> {
        match v {
            "longest" => Ok(PolylineChoiceDto::Keyword(PolylineKeywordDto::Longest)),
            _ => Err(Self::refused(&crate::math::quote::quoted(v))),
        }
    }
}

/// `longest`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum PolylineKeywordDto {
    /// The longest polyline.
    Longest,
}

/// A centreline file's length unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, JsonSchema)]
pub enum FileUnitDto {
    /// Millimetres.
    #[serde(rename = "mm")]
    Mm,
    /// Centimetres.
    #[serde(rename = "cm")]
    Cm,
    /// Metres.
    #[serde(rename = "m")]
    M,
}

/// Stent family keyword.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum StentFamilyDto {
    /// Sinusoidal crowns joined by bridges ([`crate::geometry::stent::StentSpec`]).
    #[default]
    Ring,
    /// Closed diamond cells: rings that meet crest to trough ([`crate::geometry::stent::DiamondSpec`]).
    Diamond,
}

/// Symmetry keyword.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum SymmetryDto {
    /// No symmetry.
    None,
    /// About the plane through the axis and ϑ = 0.
    Half,
    /// About that plane and the one through ϑ = 90°.
    Quarter,
}

/// Programme kind keyword.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ProgrammeKindDto {
    /// `η = −Δr e_r`.
    RadialContraction,
    /// `η = P_temp − P_0`.
    TargetShape,
    /// A crimper closes on the device to a radial contraction `Δr`, holds, and opens at the release.
    Crimp,
    /// Flat plates either side of a straight device close to `R − Δr` from its axis, hold, and open at the
    /// release.
    Crush,
}

/// The `programme:` block.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ProgrammeDto {
    /// `radial_contraction`, `target_shape`, `crimp` or `crush`.
    pub kind: ProgrammeKindDto,
    /// The driven node set (default `all_joints`): `all_joints`, `crests`, `troughs`, `crown_<k>` (k = 1, 2, …
    /// along the centreline), `bridge_ends` or `symmetry`.
    #[serde(default)]
    pub nodes: Option<String>,
    /// Radial contraction `Δr` \[length\] (radial_contraction, crimp, crush).
    #[serde(default)]
    pub delta_r: Option<Positive>,
    /// The temporary placement (target_shape).
    #[serde(default)]
    pub temporary: Option<TemporaryDto>,
    /// Ramp `[start, end]` \[time\]: the target is reached linearly over it and then held.
    pub ramp: [NonNegative; 2],
    /// Release time \[time\]: the driven components become free, or the crimper opens (default: never).
    #[serde(default)]
    pub release: Option<NonNegative>,
    /// Time a crimper or crush plates take to open from the release \[time\] (crimp, crush; default a tenth of
    /// the ramp).
    #[serde(default)]
    pub open: Option<Positive>,
    /// A segmented-head crimper of this many flat segments instead of a cylinder (crimp; at least 3, a straight
    /// device).
    #[serde(default)]
    pub segments: Option<usize>,
}

/// The temporary placement of a target-shape programme.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TemporaryDto {
    /// Straighten the centreline about its middle station.
    #[serde(default)]
    pub straighten: bool,
    /// Or a given centreline (crowns at the same arc lengths).
    #[serde(default, alias = "centerline")]
    pub centreline: Option<CentrelineDto>,
    /// Crown radius in the temporary shape (default: the permanent one) \[length\].
    #[serde(default)]
    pub radius: Option<Positive>,
    /// Place the temporary shape by the rigid motion that best fits its driven nodes to their permanent
    /// positions (default true), so that `η_temp` has no rigid part.
    #[serde(default)]
    pub align: Option<bool>,
}

/// A design function of time as a model's, its table's errors at `path`.
pub(crate) fn time_function(
    f: &TimeFn,
    path: &str,
) -> super::issue::Result<crate::model::TimeFunction> {
    match f {
        TimeFn::Constant(v) => Ok(crate::model::TimeFunction::constant(*v)),
        TimeFn::Table(points) => crate::model::TimeFunction::try_table(points.clone())
            .map_err(|e| super::issue::issue(path, e.to_string())),
    }
}
