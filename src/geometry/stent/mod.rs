//! The stent generator (paper §4.3 and its appendix; DESIGN §5): crowns, bridges, a centreline and
//! symmetry cuts, from a few parameters to a multi-patch rod device with named nodes.
//!
//! # Construction
//!
//! Local coordinates of the device are those of a centreline frame `R_stent(s) = [t, d2, d3]`
//! (rotation-minimising): `x` along the tangent `t`, and the angle `ϑ` measured in the section plane from `d2`
//! towards `d3`. A point with local coordinates `(x, r, ϑ)` at station `s` is placed as (paper §4.3.2)
//!
//! ```text
//! P = c_stent(s) + R_stent(s) · (x, r cos ϑ, r sin ϑ).
//! ```
//!
//! **Crown** `k` (0-based) is the sinusoidal ring of radius `R`, amplitude `h_c` and `m` peaks, placed rigidly at
//! its station `s_k`:
//!
//! ```text
//! x(ϑ) = h_c cos(m (ϑ − α_k)),    r = R,    α_k = k α,
//! ```
//!
//! where `α` is the rotation per crown about the axis. This is the appendix's wire
//! `h_c sin(n_w ϑ / 2)` (with `n_w = 2m` wires per crown) with the phase chosen so that a crest lies at `ϑ = α_k`:
//! the wire is then even about `ϑ = α_k` and, when `m α_k` is a multiple of π, about the planes `ϑ = 0, π`
//! (and `ϑ = ±π/2` for even `m`), which are the symmetry cuts. With the appendix's phase (`sin`) the crown
//! is odd about `ϑ = 0` and the half model about `x2 = 0` the paper describes would not be a symmetry.
//! The crown is split into `2m` wire patches at its crests (`x = +h_c`, facing crown `k + 1`) and troughs
//! (`x = −h_c`), which become its nodes. A **zigzag** crown ([`CrownShape::Zigzag`], a Z-ring) has the same
//! nodes and straight wires between them: the chord from a node to the next, `(1 − t) P_a + t P_b` in the
//! station's frame, inside the cylinder by `R (1 − cos(π/2m))` at its middle.
//!
//! **Stations.** On a straight centreline, `s_k = k d_c`. On an arc or a point list of length `L`, the crowns
//! are spread uniformly over the whole centreline (`d_c = L/(N − 1)`, the appendix's "equal circular sectors")
//! unless `d_c` is given, in which case they are centred on it.
//!
//! **Rotation per crown.** Crests of crown `k` face troughs of crown `k + 1` (same `ϑ`) exactly when
//! `m α ≡ π (mod 2π)`: half a wave (`α = π/m`, the default) or, as in the paper, `α = π/2` with 6 peaks
//! (1.5 waves). The appendix's flip of every other crown by π about `x2` is, for a crown with a crest on the
//! flip axis, the same as such a rotation.
//!
//! **Bridges** join a crest of crown `k` (at angle `ϑ₀`) to the facing trough of crown `k + 1`. Along the bridge
//! (`ξ ∈ [0, 1]`) the station slides from `s_k` to `s_{k+1}` while the local axial coordinate goes from `+h_c`
//! to `−h_c`:
//!
//! ```text
//! σ(ξ) = (1 − ξ) s_k + ξ s_{k+1},   x(ξ) = h_c (1 − 2ξ),   δ(ξ) = a sin(2π w ξ),
//! P(ξ) = c_stent(σ) + R_stent(σ) · (x, r cos ϑ, r sin ϑ),
//! ```
//!
//! so both ends are *exactly* the crown nodes (the same formula at `ξ = 0, 1`) on any centreline, and on a
//! straight one the straight bridge is the segment between them. A straight bridge has `δ = 0`; a sinusoidal
//! one (amplitude `a = ±h_b`, `w` waves) oscillates either circumferentially (`ϑ = ϑ₀ + δ/R`, `r = R`: the
//! bridge stays on the cylinder) or radially (`ϑ = ϑ₀`, `r = R + δ`: the bridge lies in the meridional plane
//! through its crest). The appendix calls its bridges "radially oriented along the stent"; we read that as
//! the radial variant (see `designs/curved_stent.yaml`), which is also the one a bridge lying in a symmetry plane
//! can have. The sign of a circumferential bridge mirrors across the symmetry planes of the device (`sign sin ϑ₀`
//! for half, `sign sin 2ϑ₀` for quarter symmetry) and is `+1` without symmetry.
//!
//! **Symmetry cuts.** Half symmetry is about the plane through the axis spanned by `t` and `d2` (`ϑ = 0, π`),
//! which needs a planar centreline lying in it; quarter symmetry adds the plane spanned by `t` and `d3`
//! (`ϑ = ±π/2`) and needs a straight centreline. The reduced model keeps `ϑ ∈ [0, π]` (half) or `[0, π/2]`
//! (quarter): every wire whose mid-angle lies there and every bridge at a crest there. Nodes on a plane get its
//! normal (their symmetry condition); a bridge lying in a plane is kept whole and flagged
//! ([`GeneratedPatch::in_plane`]): in the reduced model it must carry half its section, since the full model's
//! resultants there are shared by the two halves.
//!
//! # Files
//!
//! This file holds the specification, the generated device and [`StentSpec::generate`], which calls, in
//! order: the checks that need no geometry (`checks.rs`), the axis and the crowns' stations on it (`axis.rs`),
//! the symmetry's validity and the sector a cut keeps (`sector.rs`), the crowns' angular layout, nodes and wires
//! (`crowns.rs`), the bridges and the crowns' clearance (`bridges.rs`) and the named node sets (`sets.rs`).
//! Every patch is a [`StentCurve`] (`curve.rs`); the temporary placement of the nodes is in `temporary.rs`.
//!
//! # Families
//!
//! [`StentSpec`] is the ring family (`family: ring`, the default). Every family implements [`StentFamily`]
//! (`family.rs`), which the model and the design language ask, and generates a [`StentGeometry`]; the closed
//! diamond cells of [`DiamondSpec`] (`diamond.rs`, `family: diamond`) are the second. A new family is one module
//! implementing the trait on the axis, sector and curve of this folder.

mod axis;
mod bridges;
mod checks;
mod crowns;
mod curve;
mod diamond;
mod family;
mod sector;
mod sets;
mod temporary;

pub use curve::StentCurve;
pub use diamond::{DiamondSpec, diamond_counts};
pub use family::{FamilyCounts, StentFamily, ring_counts};

use super::GeometryError;
use crate::math::{Real, Vec3};
use axis::Axis;
use crowns::Layout;
use sector::Sector;
use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::sync::Arc;

/// Tolerance on angles \[rad\] when testing whether a node lies on a symmetry plane, whether crests face
/// troughs and whether `m α` is a multiple of π. Angles are built from the design's numbers by a few
/// operations, so they carry ~1e-15 rad of round-off; a rotation typed in degrees with ten significant digits is
/// still recognised.
pub const ANGLE_TOLERANCE: Real = 1e-9;

/// Relative tolerance (of the centreline length) when testing that a centreline lies in a symmetry plane.
pub const PLANARITY_TOLERANCE: Real = 1e-9;

/// The ring repeated along the device.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrownSpec {
    /// Radius `R` of the cylinder the crown lies on \[length\], > 0.
    pub radius: Real,
    /// Amplitude `h_c` (half the crown height `2 h_c`) \[length\], > 0.
    pub amplitude: Real,
    /// Number of peaks (crests) `m` per crown, ≥ 1.
    pub peaks: usize,
    /// The shape of the wire between a crest and a trough.
    pub shape: CrownShape,
}

/// The shape of a crown's wire between a crest and the next trough (module documentation, "Crown").
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum CrownShape {
    /// `x = h_c cos(m (ϑ − α_k))` on the cylinder: smooth through its crests and troughs (the paper's crowns).
    #[default]
    Sinusoidal,
    /// A Z-ring: straight struts, each the chord from a crest to the next trough (inside the cylinder between
    /// them), meeting at an angle at the crests and troughs — the open-stent calculator's ring.
    Zigzag,
}

/// Which way a sinusoidal bridge oscillates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BridgeDirection {
    /// Along the circumference: the bridge stays on the cylinder of radius `R`.
    Circumferential,
    /// Along the radius: the bridge lies in the meridional plane through its crest.
    Radial,
}

/// The shape of the bridges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BridgeShape {
    /// Straight (along the axis on a straight centreline).
    Straight,
    /// A sine of the given amplitude and number of waves over the bridge.
    Sinusoidal {
        /// Amplitude `h_b` \[length\], > 0.
        amplitude: Real,
        /// Waves over the bridge `w` [-], a positive multiple of 1/2 (so that the sine vanishes at both ends).
        waves: Real,
        /// Direction of the oscillation.
        direction: BridgeDirection,
    },
}

/// Which crests carry bridges, and their shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BridgeSpec {
    /// Shape.
    pub shape: BridgeShape,
    /// A bridge at every `every`-th crest of each crown (1 = every crest), ≥ 1.
    pub every: usize,
    /// Index (0-based) of the first bridged crest, counted from the crest at `ϑ = α_k`; `< every`.
    pub first: usize,
}

/// The stent axis.
#[derive(Debug, Clone, PartialEq)]
pub enum CentrelineSpec {
    /// The line `origin + s direction`, `s ≥ 0`.
    Straight {
        /// Centre of the first crown.
        origin: Vec3,
        /// Direction (normalised here).
        direction: Vec3,
        /// Direction of `ϑ = 0` (`d2`, projected normal to the axis); `None` picks one.
        reference: Option<Vec3>,
    },
    /// A circular arc from `start` about `axis` through `centre` by `angle` (right-hand rule).
    Arc {
        /// Centre of the circle.
        centre: Vec3,
        /// Start point (in the plane through `centre` normal to `axis`).
        start: Vec3,
        /// Rotation axis.
        axis: Vec3,
        /// Swept angle \[rad\], `0 < |angle| ≤ 2π`.
        angle: Real,
        /// Direction of `ϑ = 0` at the start; `None` = outward from the centre (the extrados).
        reference: Option<Vec3>,
    },
    /// The cubic spline through a list of points, with a rotation-minimising frame.
    Points {
        /// At least two distinct points.
        points: Vec<Vec3>,
        /// Direction of `ϑ = 0` at the start; `None` picks one.
        reference: Option<Vec3>,
    },
    /// A given spline (e.g. fitted to a vessel centreline read from a file), with a rotation-minimising frame.
    Spline {
        /// The curve, `u ∈ [0, 1]`.
        curve: crate::math::NurbsCurve,
        /// Direction of `ϑ = 0` at the start; `None` picks one.
        reference: Option<Vec3>,
    },
}

/// The symmetry of the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Symmetry {
    /// No symmetry assumed; circumferential bridges all turn the same way.
    None,
    /// Mirror symmetry about the plane `ϑ = 0, π`.
    Half,
    /// Mirror symmetry about the planes `ϑ = 0, π` and `ϑ = ±π/2`.
    Quarter,
}

impl Symmetry {
    /// Number of copies of the reduced model that make the full device.
    pub fn sectors(self) -> usize {
        match self {
            Symmetry::None => 1,
            Symmetry::Half => 2,
            Symmetry::Quarter => 4,
        }
    }
}

/// Everything that defines a stent.
#[derive(Debug, Clone, PartialEq)]
pub struct StentSpec {
    /// The ring.
    pub crown: CrownSpec,
    /// Number of crowns `N`, ≥ 1.
    pub crowns: usize,
    /// Crown spacing `d_c` along the centreline \[length\]; required on a straight centreline, optional
    /// otherwise (crowns spread over the whole centreline).
    pub spacing: Option<Real>,
    /// Rotation `α` of each crown about the axis relative to the previous one \[rad\].
    pub rotation: Real,
    /// Bridges between consecutive crowns; `None` = unconnected crowns.
    pub bridges: Option<BridgeSpec>,
    /// The axis.
    pub centreline: CentrelineSpec,
    /// The symmetry of the device (decides the bridge handedness and the possible cuts).
    pub symmetry: Symmetry,
    /// Keep only the symmetry sector (`true`) or the whole device (`false`, e.g. to check the reduced model).
    pub cut: bool,
    /// The radius of each crown, first crown first, where they differ (a stent sized to a tapering vessel);
    /// `None`: every crown has `crown.radius`. A bridge's radius goes linearly from its crest's crown to its
    /// trough's.
    pub crown_radii: Option<Vec<Real>>,
}

impl StentSpec {
    /// The radius of crown `k` (0-based) \[length\].
    pub fn radius_of(&self, k: usize) -> Real {
        self.crown_radii
            .as_ref()
            .and_then(|r| r.get(k).copied())
            .unwrap_or(self.crown.radius)
    }

    /// The largest and smallest crown radius \[length\].
    pub fn radius_range(&self) -> (Real, Real) {
        (0..self.crowns.max(1))
            .map(|k| self.radius_of(k))
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), r| {
                (lo.min(r), hi.max(r))
            })
    }

    /// The arc-length stations of the crowns on the centreline \[length\] (module docs, *Stations*).
    pub fn crown_stations(&self) -> Result<Vec<Real>, GeometryError> {
        self.stations(&axis::Axis::new(&self.centreline)?)
    }
}

/// How the temporary (programmed) shape differs from the permanent one: same crowns, nodes and stations.
#[derive(Debug, Clone, PartialEq)]
pub struct TemporarySpec {
    /// The temporary centreline.
    pub centreline: TemporaryCentreline,
    /// Crown radius in the temporary shape \[length\]; `None` keeps each crown's.
    pub radius: Option<Real>,
}

/// The temporary centreline.
#[derive(Debug, Clone, PartialEq)]
pub enum TemporaryCentreline {
    /// The permanent one.
    Same,
    /// The tangent line of the permanent centreline at the middle station between the first and last crown,
    /// with its frame there: the device straightened about its middle, every crown at the same arc length.
    Straightened,
    /// A given centreline (crowns at the same arc-length stations).
    Given(CentrelineSpec),
}

/// A family's kind of part, numbered by the family (the ring family's crown wires and bridges, the diamond
/// family's struts): the family answers what a kind means ([`StentFamily::is_connector`]), so a new family
/// numbers its own kinds without editing this type or any `match` over it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PartKind(pub u8);

/// What a patch is in the device: the family's kind of part, the crown (ring) it belongs to and its index
/// there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PatchRole {
    /// The family's kind of part.
    pub kind: PartKind,
    /// Crown index, 0-based; of a connector between crowns (a bridge), the first crown of the pair it joins.
    pub crown: usize,
    /// Index of the part within its crown, 0-based (a wire's from its first node, a bridge's crest).
    pub index: usize,
}

/// A family's kind of node, numbered by the family (the ring family's crests and troughs, the diamond
/// family's free ends and junctions): what a kind means is the family's, which is asked through
/// [`StentFamily`], so a new family numbers its own kinds without editing this type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NodeKind(pub u8);

/// Which end of a generated patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WireEnd {
    /// `u = 0`.
    Start,
    /// `u = 1`.
    End,
}

/// One generated patch: an analytic curve on `[0, 1]`, to be fitted (or represented exactly) at the analysis
/// degree and number of control points.
#[derive(Debug, Clone)]
pub struct GeneratedPatch {
    /// Name: `c<k>_w<i>` for the wire of crown `k` that starts at node `c<k>_n<i>`, `b<k>_<i>` for the bridge
    /// from node `c<k>_n<i>` (a crest) to crown `k + 1` (see [`GeneratedNode::name`]; names are those of the full
    /// device, so a reduced model's names say where its patches are).
    pub name: String,
    /// What the patch is (its family's kind of part, crown and index).
    pub role: PatchRole,
    /// The analytic centreline.
    pub curve: StentCurve,
    /// Node index at `u = 0`.
    pub start_node: usize,
    /// Node index at `u = 1`.
    pub end_node: usize,
    /// Outward radial direction at the start (a natural first section axis).
    pub normal_hint: Vec3,
    /// The symmetry plane (index into [`StentGeometry::symmetry_planes`]) the patch lies in, if any: such a
    /// patch carries half its section in the reduced model.
    pub in_plane: Option<usize>,
}

impl GeneratedPatch {
    /// The end points when the patch is an exact straight segment (a straight bridge on a straight centreline),
    /// else `None`.
    pub fn straight_segment(&self) -> Option<(Vec3, Vec3)> {
        self.curve.straight_segment()
    }
}

/// One generated node: a crest or trough of a crown, where wires (and bridges) meet.
#[derive(Debug, Clone, PartialEq)]
pub struct GeneratedNode {
    /// Name `c<k>_n<i>`: crown `k` (1-based), node `i` counted from 1 at the first node at or after `ϑ = 0`
    /// by increasing angle (for symmetric devices node `i` is at `ϑ = (i − 1) π/m`).
    pub name: String,
    /// Exact position \[length\].
    pub position: Vec3,
    /// The patch ends joined here.
    pub ends: Vec<(usize, WireEnd)>,
    /// Crown index, 0-based (of a junction: the crown whose crest it is).
    pub crown: usize,
    /// Node index within the crown, 0-based (even: crest); of a diamond stent's node, its angle in half waves.
    pub index: usize,
    /// The family's kind of node (the ring family's crest or trough).
    pub kind: NodeKind,
    /// Angle `ϑ` in the crown's section plane \[rad\].
    pub angle: Real,
    /// Station `s_k` of the crown \[length\].
    pub station: Real,
    /// Centreline point `c_stent(s_k)`.
    pub axis_point: Vec3,
    /// Centreline tangent `t(s_k)`.
    pub axis_tangent: Vec3,
    /// Outward radial unit vector `R_stent(s_k) (0, cos ϑ, sin ϑ)`.
    pub radial: Vec3,
    /// The symmetry plane the node lies on (index into [`StentGeometry::symmetry_planes`]), if cut.
    pub symmetry_plane: Option<usize>,
    /// How many nodes of the full device this node stands for (1, 2 or 4).
    pub multiplicity: usize,
}

/// A symmetry plane of a reduced model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SymmetryPlane {
    /// A point of the plane.
    pub point: Vec3,
    /// Unit normal, pointing into the retained side.
    pub normal: Vec3,
}

/// The generated device.
#[derive(Debug, Clone)]
pub struct StentGeometry {
    /// Crown wires, then bridges.
    pub patches: Vec<GeneratedPatch>,
    /// Crown nodes, crown by crown.
    pub nodes: Vec<GeneratedNode>,
    /// Named node sets (indices into `nodes`): `all_joints`, `crown_<k>`, `crests`, `troughs`, `bridge_ends`,
    /// `symmetry`.
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// The cut planes (empty for a full model).
    pub symmetry_planes: Vec<SymmetryPlane>,
    /// Station `s_k` of every crown \[length\].
    pub stations: Vec<Real>,
}

/// A parameter of a [`StentSpec`] (or its temporary shape) that is out of range, named in
/// [`GeometryError::InvalidStent`]: the design layer maps each to its field, with no string matching.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StentParameter {
    /// The number of crowns.
    Crowns,
    /// The crown radius `R`.
    Radius,
    /// The crown amplitude `h_c`.
    Amplitude,
    /// The crests per crown.
    Peaks,
    /// The crown spacing `d_c`.
    Spacing,
    /// The rotation of each crown about the axis.
    Rotation,
    /// The symmetry cut.
    Symmetry,
    /// The bridges as a whole.
    Bridges,
    /// Bridges every so many crests.
    BridgesEvery,
    /// The first bridged crest.
    BridgesFirst,
    /// The amplitude of sinusoidal bridges.
    BridgesAmplitude,
    /// The waves of sinusoidal bridges.
    BridgesWaves,
    /// The direction of sinusoidal bridges.
    BridgesDirection,
    /// The centreline.
    Centreline,
    /// The angle of an arc centreline.
    CentrelineAngle,
    /// The radius of the temporary shape.
    TemporaryRadius,
    /// The centreline of the temporary shape.
    TemporaryCentreline,
}

impl std::fmt::Display for StentParameter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Crowns => "crown count",
            Self::Radius => "radius",
            Self::Amplitude => "amplitude",
            Self::Peaks => "peak count",
            Self::Spacing => "crown spacing",
            Self::Rotation => "crown rotation",
            Self::Symmetry => "symmetry",
            Self::Bridges => "bridges",
            Self::BridgesEvery => "bridge spacing",
            Self::BridgesFirst => "first bridge",
            Self::BridgesAmplitude => "bridge amplitude",
            Self::BridgesWaves => "bridge waves",
            Self::BridgesDirection => "bridge direction",
            Self::Centreline => "centreline",
            Self::CentrelineAngle => "centreline angle",
            Self::TemporaryRadius => "temporary radius",
            Self::TemporaryCentreline => "temporary centreline",
        })
    }
}

impl StentSpec {
    /// Generates the device (full or cut): checks the specification, places the crowns at their stations on
    /// the axis, makes their nodes and wires and the bridges in the sector the symmetry cut keeps, joins the
    /// patch ends at the nodes and names the node sets (the steps are listed in the module documentation,
    /// "Files").
    ///
    /// # Errors
    /// [`GeometryError::InvalidStent`] naming the parameter at fault (or the centreline fit's error).
    pub fn generate(&self) -> Result<StentGeometry, GeometryError> {
        self.check_numbers()?;
        let axis = Arc::new(Axis::new(&self.centreline)?);
        let stations = self.stations(&axis)?;
        self.generate_on(axis, stations, true)
    }

    /// The device on `axis` with its crowns at `stations`; `checked`: refused where the permanent shape's
    /// limits are broken (bend radius, symmetry, bridge rotation, clearance).
    fn generate_on(
        &self,
        axis: Arc<Axis>,
        stations: Vec<Real>,
        checked: bool,
    ) -> Result<StentGeometry, GeometryError> {
        if checked {
            self.check_bend_radius(&axis)?;
            self.check_symmetry(&axis)?;
            self.check_bridge_rotation()?;
        }
        let layout = Layout::new(self);
        let sector = Sector::new(self);
        let symmetry_planes = sector.planes(&axis, stations[0]);
        let (mut nodes, node_index) = crowns::crown_nodes(self, &axis, &stations, &layout, &sector);
        let mut patches =
            crowns::crown_wires(self, &axis, &stations, &layout, &sector, &node_index);
        let mut bridge_ends = Vec::new();
        if let Some(spec) = &self.bridges {
            let (more, ends) =
                bridges::bridges(self, spec, &axis, &stations, &layout, &sector, &node_index)?;
            patches.extend(more);
            bridge_ends = ends;
            if checked {
                self.check_clearance(&axis, &stations, &nodes)?;
            }
        }
        for (p, patch) in patches.iter().enumerate() {
            nodes[patch.start_node].ends.push((p, WireEnd::Start));
            nodes[patch.end_node].ends.push((p, WireEnd::End));
        }
        let node_sets = sets::node_sets(&nodes, self.crowns, bridge_ends);
        Ok(StentGeometry {
            patches,
            nodes,
            node_sets,
            symmetry_planes,
            stations,
        })
    }
}

impl StentGeometry {
    /// Index of the node named `name`.
    pub fn node(&self, name: &str) -> Option<usize> {
        self.nodes.iter().position(|n| n.name == name)
    }
}

/// The error naming `parameter` with `reason`.
fn invalid(parameter: StentParameter, reason: impl Into<String>) -> GeometryError {
    GeometryError::InvalidStent {
        parameter,
        reason: reason.into(),
    }
}

/// `x` is an integer multiple of `period` (within [`ANGLE_TOLERANCE`] in angle).
fn is_multiple(x: Real, period: Real) -> bool {
    let q = x / period;
    (q - q.round()).abs() * period <= ANGLE_TOLERANCE
}

/// The two angles are equal modulo 2π.
fn same_angle(a: Real, b: Real) -> bool {
    is_multiple(a - b, TAU)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::analytic::ParametricCurve;
    use std::f64::consts::PI;

    fn straight(symmetry: Symmetry, cut: bool) -> StentSpec {
        StentSpec {
            crown: CrownSpec {
                radius: 20.0,
                amplitude: 5.0,
                peaks: 6,
                shape: CrownShape::Sinusoidal,
            },
            crowns: 3,
            spacing: Some(15.0),
            rotation: PI / 2.0,
            bridges: Some(BridgeSpec {
                shape: BridgeShape::Straight,
                every: 1,
                first: 0,
            }),
            centreline: CentrelineSpec::Straight {
                origin: Vec3::zeros(),
                direction: Vec3::x(),
                reference: Some(Vec3::y()),
            },
            symmetry,
            cut,
            crown_radii: None,
        }
    }

    // Counts by hand: 3 crowns × 12 wires and 2 pairs × 6 bridges in the full device; the quarter keeps 3 wires
    // per crown (ϑ ∈ [0°, 90°]: 0–30, 30–60, 60–90) and, per pair, the bridges at the two crests in [0°, 90°]
    // (0° and 60° after crown 1, 30° and 90° after crown 2); the half keeps 6 wires per crown and the bridges at
    // 0, 60, 120, 180° (pair 1) and 30, 90, 150° (pair 2).
    #[test]
    fn counts_of_full_and_quarter_models() {
        let full = straight(Symmetry::Quarter, false).generate().unwrap();
        assert_eq!(full.patches.len(), 36 + 12);
        assert_eq!(full.nodes.len(), 36);
        let quarter = straight(Symmetry::Quarter, true).generate().unwrap();
        assert_eq!(quarter.patches.len(), 9 + 4);
        assert_eq!(quarter.nodes.len(), 12);
        assert_eq!(quarter.node_sets["symmetry"].len(), 6);
        assert_eq!(
            quarter
                .patches
                .iter()
                .filter(|p| p.in_plane.is_some())
                .count(),
            2
        );
        let half = straight(Symmetry::Half, true).generate().unwrap();
        assert_eq!(half.patches.len(), 18 + 7);
    }

    // The counts the ring family reports without generating (what the memory estimate charges) are what it
    // generates: a cut model's patches and nodes weighted by the copies each stands for (half as many for a
    // bridge or node on a plane), for bridges at every crest and at every third one (two per pair, at 0° and
    // 180° from the crown's first crest, which keeps the quarter symmetry).
    #[test]
    fn reported_counts_are_the_generated_ones() {
        for (symmetry, cut) in [
            (Symmetry::None, false),
            (Symmetry::Half, true),
            (Symmetry::Quarter, true),
        ] {
            for (every, first) in [(1, 0), (3, 0)] {
                let mut spec = straight(symmetry, cut);
                spec.bridges = Some(BridgeSpec {
                    shape: BridgeShape::Straight,
                    every,
                    first,
                });
                let counts = StentFamily::counts(&spec);
                let g = spec.generate().unwrap();
                let sectors = counts.sectors;
                let weight = |in_plane: bool| if in_plane { sectors / 2 } else { sectors };
                let patches: usize = g.patches.iter().map(|p| weight(p.in_plane.is_some())).sum();
                let nodes: usize = g.nodes.iter().map(|n| n.multiplicity).sum();
                let label = format!("{symmetry:?}, every {every}");
                assert_eq!(
                    patches as Real,
                    counts.crown_wires + counts.bridges,
                    "{label}"
                );
                assert_eq!(nodes as Real, counts.nodes, "{label}");
            }
        }
    }

    // What the ring family answers about its own kinds, checked against the topology it generates: a connector
    // (a bridge) joins a node of crown k to one of crown k + 1 with k its role's crown, every other part joins
    // two nodes of its role's crown; the facing pairs are crests of crown k and troughs of crown k + 1, the
    // closest of them the crest and the trough at the same angle, `d_c − 2 h_c = 15 − 2 × 5 = 5` apart on the
    // straight device (by hand).
    #[test]
    fn ring_roles_and_facing_nodes_match_the_topology() {
        let spec = straight(Symmetry::None, false);
        let g = spec.generate().unwrap();
        let mut connectors = 0;
        for p in &g.patches {
            let (a, b) = (&g.nodes[p.start_node], &g.nodes[p.end_node]);
            if StentFamily::is_connector(&spec, &p.role) {
                connectors += 1;
                assert_eq!(
                    (a.crown, b.crown),
                    (p.role.crown, p.role.crown + 1),
                    "{}",
                    p.name
                );
            } else {
                assert_eq!(
                    (a.crown, b.crown),
                    (p.role.crown, p.role.crown),
                    "{}",
                    p.name
                );
            }
        }
        assert_eq!(connectors, 12);
        let facing = StentFamily::facing_nodes(&spec, &g);
        // 2 pairs of crowns × 6 crests × 6 troughs.
        assert_eq!(facing.len(), 72);
        let gap = facing
            .iter()
            .map(|&(c, q)| (g.nodes[q].position - g.nodes[c].position).norm())
            .fold(Real::INFINITY, Real::min);
        assert!((gap - 5.0).abs() < 1e-12, "{gap}");
        for &(c, q) in &facing {
            assert_eq!(g.nodes[q].crown, g.nodes[c].crown + 1);
            // A crest lies ahead of its crown's station along the axis (x = +h_c), a trough behind.
            let ahead = |i: usize| {
                (g.nodes[i].position - g.nodes[i].axis_point).dot(&g.nodes[i].axis_tangent)
            };
            assert!(ahead(c) > 0.0 && ahead(q) < 0.0);
        }
    }

    // Crests of crown k face troughs of crown k + 1, and the bridge ends are those nodes to round-off.
    #[test]
    fn bridges_end_at_crown_nodes() {
        let g = straight(Symmetry::None, false).generate().unwrap();
        for p in &g.patches {
            let a = p.curve.point(0.0);
            let b = p.curve.point(1.0);
            assert!((a - g.nodes[p.start_node].position).norm() < 1e-13);
            assert!((b - g.nodes[p.end_node].position).norm() < 1e-13);
        }
    }

    #[test]
    fn rotation_must_align_crests_with_troughs() {
        let mut s = straight(Symmetry::None, false);
        s.rotation = 0.0;
        assert!(matches!(
            s.generate(),
            Err(GeometryError::InvalidStent {
                parameter: StentParameter::Rotation,
                ..
            })
        ));
    }

    // The closed-form derivative agrees with a central difference of the point (arc centreline, sinusoidal
    // bridge, so every term is exercised); the difference step 1e-5 gives ~1e-9 relative truncation error.
    #[test]
    fn curve_derivatives_match_differences() {
        let mut s = straight(Symmetry::None, false);
        s.centreline = CentrelineSpec::Arc {
            centre: Vec3::new(0.0, 0.0, -5.0),
            start: Vec3::new(100.0, 0.0, -5.0),
            axis: Vec3::new(0.0, -1.0, 0.0),
            angle: PI / 4.0,
            reference: None,
        };
        s.spacing = None;
        s.bridges = Some(BridgeSpec {
            shape: BridgeShape::Sinusoidal {
                amplitude: 2.5,
                waves: 1.0,
                direction: BridgeDirection::Circumferential,
            },
            every: 1,
            first: 0,
        });
        let g = s.generate().unwrap();
        for p in &g.patches {
            for &t in &[0.1, 0.37, 0.8] {
                let h = 1e-5;
                let fd = (p.curve.point(t + h) - p.curve.point(t - h)) / (2.0 * h);
                let d = p.curve.derivative(t);
                assert!(
                    (fd - d).norm() <= 1e-8 * d.norm(),
                    "{}: {fd} vs {d}",
                    p.name
                );
            }
        }
    }
}
