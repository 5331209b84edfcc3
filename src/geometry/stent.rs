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
//! (`x = −h_c`), which become its nodes.
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

use super::GeometryError;
use super::analytic::{Centreline, ParametricCurve, point_list_curve};
use super::frame::normal_to;
use crate::math::{Mat3, Real, Vec3};
use nalgebra::{Rotation3, Unit};
use std::collections::BTreeMap;
use std::f64::consts::{PI, TAU};
use std::sync::Arc;

/// A mirror of the device as a map of angles `ϑ`, with the plane's description.
type Mirror = (fn(Real) -> Real, &'static str);

/// Tolerance on angles [rad] when testing whether a node lies on a symmetry plane, whether crests face
/// troughs and whether `m α` is a multiple of π. Angles are built from the design's numbers by a few
/// operations, so they carry ~1e-15 rad of round-off; a rotation typed in degrees with ten significant digits is
/// still recognised.
pub const ANGLE_TOLERANCE: Real = 1e-9;

/// Relative tolerance (of the centreline length) when testing that a centreline lies in a symmetry plane.
pub const PLANARITY_TOLERANCE: Real = 1e-9;

/// The sinusoidal ring repeated along the device.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrownSpec {
    /// Radius `R` of the cylinder the crown lies on [length], > 0.
    pub radius: Real,
    /// Amplitude `h_c` (half the crown height `2 h_c`) [length], > 0.
    pub amplitude: Real,
    /// Number of peaks (crests) `m` per crown, ≥ 1.
    pub peaks: usize,
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
        /// Amplitude `h_b` [length], > 0.
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
        /// Swept angle [rad], `0 < |angle| ≤ 2π`.
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
    /// Crown spacing `d_c` along the centreline [length]; required on a straight centreline, optional
    /// otherwise (crowns spread over the whole centreline).
    pub spacing: Option<Real>,
    /// Rotation `α` of each crown about the axis relative to the previous one [rad].
    pub rotation: Real,
    /// Bridges between consecutive crowns; `None` = unconnected crowns.
    pub bridges: Option<BridgeSpec>,
    /// The axis.
    pub centreline: CentrelineSpec,
    /// The symmetry of the device (decides the bridge handedness and the possible cuts).
    pub symmetry: Symmetry,
    /// Keep only the symmetry sector (`true`) or the whole device (`false`, e.g. to check the reduced model).
    pub cut: bool,
}

/// How the temporary (programmed) shape differs from the permanent one: same crowns, nodes and stations.
#[derive(Debug, Clone, PartialEq)]
pub struct TemporarySpec {
    /// The temporary centreline.
    pub centreline: TemporaryCentreline,
    /// Crown radius in the temporary shape [length]; `None` keeps `R`.
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

/// What a patch is in the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PatchRole {
    /// Wire `wire` (0-based, from node `wire` to node `wire + 1`) of crown `crown`.
    Crown {
        /// Crown index, 0-based.
        crown: usize,
        /// Wire index within the crown, 0-based.
        wire: usize,
    },
    /// The bridge from crest `crest` (0-based) of crown `pair` to the facing trough of crown `pair + 1`.
    Bridge {
        /// Index of the first crown of the pair, 0-based.
        pair: usize,
        /// Crest index within that crown, 0-based.
        crest: usize,
    },
}

/// Whether a node is a crest (`x = +h_c`, facing the next crown) or a trough.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeKind {
    /// `x = +h_c`.
    Crest,
    /// `x = −h_c`.
    Trough,
}

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
    /// Crown wire or bridge.
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
        match (&self.curve.kind, self.curve.axis.as_ref()) {
            (
                CurveKind::Bridge {
                    offset: Offset::None,
                    ..
                },
                Axis::Straight { .. },
            ) => Some((self.curve.point(0.0), self.curve.point(1.0))),
            _ => None,
        }
    }
}

/// One generated node: a crest or trough of a crown, where wires (and bridges) meet.
#[derive(Debug, Clone, PartialEq)]
pub struct GeneratedNode {
    /// Name `c<k>_n<i>`: crown `k` (1-based), node `i` counted from 1 at the first node at or after `ϑ = 0`
    /// by increasing angle (for symmetric devices node `i` is at `ϑ = (i − 1) π/m`).
    pub name: String,
    /// Exact position [length].
    pub position: Vec3,
    /// The patch ends joined here.
    pub ends: Vec<(usize, WireEnd)>,
    /// Crown index, 0-based.
    pub crown: usize,
    /// Node index within the crown, 0-based (even: crest).
    pub index: usize,
    /// Crest or trough.
    pub kind: NodeKind,
    /// Angle `ϑ` in the crown's section plane [rad].
    pub angle: Real,
    /// Station `s_k` of the crown [length].
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
    /// Station `s_k` of every crown [length].
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

/// The centreline, evaluated exactly for lines and arcs and through the rotation-minimising frame of the
/// fitted spline for point lists. Beyond its ends a centreline continues along its end tangents (only
/// finite differences look there).
#[derive(Debug, Clone)]
pub(crate) enum Axis {
    Straight {
        origin: Vec3,
        frame: Mat3,
    },
    Arc {
        centre: Vec3,
        offset: Vec3,
        axis: Vec3,
        radius: Real,
        frame: Mat3,
        length: Real,
    },
    Curve {
        centreline: Box<Centreline>,
    },
}

/// Frame `[t, d2, d3]` from a tangent and a hint for `d2`.
fn frame_from(tangent: &Vec3, reference: Option<Vec3>) -> Mat3 {
    let d2 = normal_to(tangent, reference);
    Mat3::from_columns(&[*tangent, d2, tangent.cross(&d2)])
}

fn finite(what: StentParameter, v: &Vec3) -> Result<(), GeometryError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(invalid(what, format!("must be finite, got {v:?}")))
    }
}

impl Axis {
    fn new(spec: &CentrelineSpec) -> Result<Self, GeometryError> {
        match spec {
            CentrelineSpec::Straight {
                origin,
                direction,
                reference,
            } => {
                finite(StentParameter::Centreline, origin)?;
                finite(StentParameter::Centreline, direction)?;
                let n = direction.norm();
                if !(n.is_finite() && n > 0.0) {
                    return Err(invalid(StentParameter::Centreline, "the direction is zero"));
                }
                Ok(Axis::Straight {
                    origin: *origin,
                    frame: frame_from(&(direction / n), *reference),
                })
            }
            CentrelineSpec::Arc {
                centre,
                start,
                axis,
                angle,
                reference,
            } => {
                finite(StentParameter::Centreline, centre)?;
                finite(StentParameter::Centreline, start)?;
                finite(StentParameter::Centreline, axis)?;
                if !(angle.is_finite() && *angle != 0.0 && angle.abs() <= TAU) {
                    return Err(invalid(
                        StentParameter::CentrelineAngle,
                        format!(
                            "the swept angle must be non-zero and at most 360°, got {}°",
                            angle.to_degrees()
                        ),
                    ));
                }
                let a = axis.norm();
                if !(a.is_finite() && a > 0.0) {
                    return Err(invalid(StentParameter::Centreline, "the arc axis is zero"));
                }
                let axis = axis / a;
                let offset = start - centre;
                let radius = offset.norm();
                if !(radius.is_finite() && radius > 0.0)
                    || offset.dot(&axis).abs() > PLANARITY_TOLERANCE * radius
                {
                    return Err(invalid(
                        StentParameter::Centreline,
                        "the start point must differ from the centre and lie in the plane through the centre normal to the axis",
                    ));
                }
                // A negative angle is a positive one about the reversed axis.
                let axis = if *angle < 0.0 { -axis } else { axis };
                let tangent = axis.cross(&offset).normalize();
                let hint = reference.or(Some(offset));
                Ok(Axis::Arc {
                    centre: *centre,
                    offset,
                    axis,
                    radius,
                    frame: frame_from(&tangent, hint),
                    length: radius * angle.abs(),
                })
            }
            CentrelineSpec::Points { points, reference } => {
                for p in points {
                    finite(StentParameter::Centreline, p)?;
                }
                let curve = point_list_curve(points)?;
                Ok(Axis::Curve {
                    centreline: Box::new(Centreline::new(curve, *reference)?),
                })
            }
        }
    }

    /// Length, `None` for the unbounded straight line.
    fn length(&self) -> Option<Real> {
        match self {
            Axis::Straight { .. } => None,
            Axis::Arc { length, .. } => Some(*length),
            Axis::Curve { centreline } => Some(centreline.length()),
        }
    }

    /// `c(s)` and `R(s) = [t, d2, d3]`.
    fn frame(&self, s: Real) -> (Vec3, Mat3) {
        match self {
            Axis::Straight { origin, frame } => (origin + frame.column(0) * s, *frame),
            Axis::Arc {
                centre,
                offset,
                axis,
                radius,
                frame,
                ..
            } => {
                let q = Rotation3::from_axis_angle(&Unit::new_unchecked(*axis), s / radius);
                (centre + q * offset, q.matrix() * frame)
            }
            Axis::Curve { centreline } => {
                let length = centreline.length();
                let clamped = s.clamp(0.0, length);
                // `Centreline::new` rejected degenerate curves, so the frame exists.
                let (c, r) = centreline
                    .at(clamped)
                    .unwrap_or((Vec3::repeat(Real::NAN), Mat3::repeat(Real::NAN)));
                (c + r.column(0) * (s - clamped), r)
            }
        }
    }

    /// `(c'(s), R'(s))` where known in closed form: `R' = ω̂ R` with `ω = axis/ρ` on an arc.
    fn frame_derivative(&self, s: Real) -> Option<(Vec3, Mat3)> {
        match self {
            Axis::Straight { frame, .. } => Some((frame.column(0).into_owned(), Mat3::zeros())),
            Axis::Arc { axis, radius, .. } => {
                let (_, r) = self.frame(s);
                Some((
                    r.column(0).into_owned(),
                    (axis / *radius).cross_matrix() * r,
                ))
            }
            Axis::Curve { .. } => None,
        }
    }
}

/// The local shape of a bridge across the axis.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Offset {
    None,
    Circumferential { amplitude: Real, waves: Real },
    Radial { amplitude: Real, waves: Real },
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum CurveKind {
    /// A crown wire from `from` to `to` (angles) at station `station`, crest at `phase`.
    Crown {
        station: Real,
        phase: Real,
        from: Real,
        to: Real,
    },
    /// A bridge from station `from` to `to` at angle `angle`.
    Bridge {
        from: Real,
        to: Real,
        angle: Real,
        offset: Offset,
    },
}

/// The analytic centreline of a generated patch, `u ∈ [0, 1]` (see the module documentation for the formulas).
#[derive(Debug, Clone)]
pub struct StentCurve {
    axis: Arc<Axis>,
    radius: Real,
    amplitude: Real,
    peaks: Real,
    kind: CurveKind,
}

impl StentCurve {
    /// Local coordinates `(x, r cos ϑ, r sin ϑ)`, their derivative in the curve parameter, the station and
    /// its derivative.
    fn local(&self, t: Real) -> (Vec3, Vec3, Real, Real) {
        let (h, m, big_r) = (self.amplitude, self.peaks, self.radius);
        match self.kind {
            CurveKind::Crown {
                station,
                phase,
                from,
                to,
            } => {
                let a = from * (1.0 - t) + to * t;
                let da = to - from;
                let (sa, ca) = a.sin_cos();
                let arg = m * (a - phase);
                let p = Vec3::new(h * arg.cos(), big_r * ca, big_r * sa);
                let dp = Vec3::new(-h * m * arg.sin(), -big_r * sa, big_r * ca) * da;
                (p, dp, station, 0.0)
            }
            CurveKind::Bridge {
                from,
                to,
                angle,
                offset,
            } => {
                let sigma = from * (1.0 - t) + to * t;
                let dsigma = to - from;
                let x = h * (1.0 - 2.0 * t);
                let dx = -2.0 * h;
                let wave = |amplitude: Real, waves: Real| {
                    let k = TAU * waves;
                    (amplitude * (k * t).sin(), amplitude * k * (k * t).cos())
                };
                let (r, dr, a, da) = match offset {
                    Offset::None => (big_r, 0.0, angle, 0.0),
                    Offset::Circumferential { amplitude, waves } => {
                        let (d, dd) = wave(amplitude, waves);
                        (big_r, 0.0, angle + d / big_r, dd / big_r)
                    }
                    Offset::Radial { amplitude, waves } => {
                        let (d, dd) = wave(amplitude, waves);
                        (big_r + d, dd, angle, 0.0)
                    }
                };
                let (sa, ca) = a.sin_cos();
                let p = Vec3::new(x, r * ca, r * sa);
                let dp = Vec3::new(dx, dr * ca - r * sa * da, dr * sa + r * ca * da);
                (p, dp, sigma, dsigma)
            }
        }
    }
}

impl ParametricCurve for StentCurve {
    fn domain(&self) -> (Real, Real) {
        (0.0, 1.0)
    }

    fn point(&self, t: Real) -> Vec3 {
        let (p, _, s, _) = self.local(t);
        let (c, r) = self.axis.frame(s);
        c + r * p
    }

    fn derivative(&self, t: Real) -> Vec3 {
        let (p, dp, s, ds) = self.local(t);
        let (_, r) = self.axis.frame(s);
        if ds == 0.0 {
            return r * dp;
        }
        match self.axis.frame_derivative(s) {
            Some((dc, drot)) => (dc + drot * p) * ds + r * dp,
            None => {
                // Fourth-order central difference, as the trait's default (the point-list frame has no closed
                // form); the centreline continues straight beyond its ends, so the stencil stays valid there.
                let h = 1e-3;
                (self.point(t - 2.0 * h) - self.point(t + 2.0 * h)
                    + (self.point(t + h) - self.point(t - h)) * 8.0)
                    / (12.0 * h)
            }
        }
    }
}

impl StentSpec {
    /// Checks the numbers that must hold on their own.
    fn check_numbers(&self) -> Result<(), GeometryError> {
        let c = &self.crown;
        if !(c.radius.is_finite() && c.radius > 0.0) {
            return Err(invalid(
                StentParameter::Radius,
                format!("must be > 0, got {}", c.radius),
            ));
        }
        if !(c.amplitude.is_finite() && c.amplitude > 0.0) {
            return Err(invalid(
                StentParameter::Amplitude,
                format!("must be > 0, got {}", c.amplitude),
            ));
        }
        if c.peaks == 0 {
            return Err(invalid(
                StentParameter::Peaks,
                "a crown needs at least one peak",
            ));
        }
        if self.crowns == 0 {
            return Err(invalid(
                StentParameter::Crowns,
                "a stent needs at least one crown",
            ));
        }
        if !self.rotation.is_finite() {
            return Err(invalid(StentParameter::Rotation, "must be finite"));
        }
        if let Some(d) = self.spacing
            && !(d.is_finite() && d > 0.0)
        {
            return Err(invalid(
                StentParameter::Spacing,
                format!("must be > 0, got {d}"),
            ));
        }
        if let Some(b) = &self.bridges {
            if b.every == 0 {
                return Err(invalid(StentParameter::BridgesEvery, "must be ≥ 1"));
            }
            if b.first >= b.every {
                return Err(invalid(
                    StentParameter::BridgesFirst,
                    format!(
                        "crest {} does not exist in a pattern of every {} crests: use 1 … {}",
                        b.first + 1,
                        b.every,
                        b.every
                    ),
                ));
            }
            if let BridgeShape::Sinusoidal {
                amplitude,
                waves,
                direction,
            } = b.shape
            {
                if !(amplitude.is_finite() && amplitude > 0.0) {
                    return Err(invalid(
                        StentParameter::BridgesAmplitude,
                        format!("must be > 0, got {amplitude}"),
                    ));
                }
                if !(waves > 0.0 && is_multiple(2.0 * waves, 1.0)) {
                    return Err(invalid(
                        StentParameter::BridgesWaves,
                        format!(
                            "must be a positive multiple of 1/2 so that the sine vanishes at both ends, got {waves}"
                        ),
                    ));
                }
                if direction == BridgeDirection::Radial && amplitude >= c.radius {
                    return Err(invalid(
                        StentParameter::BridgesAmplitude,
                        format!(
                            "a radial bridge amplitude {amplitude} must be below the crown radius {}",
                            c.radius
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Crown stations on `axis`.
    fn stations(&self, axis: &Axis) -> Result<Vec<Real>, GeometryError> {
        let n = self.crowns;
        let (start, spacing) = match (axis.length(), self.spacing) {
            (None, Some(d)) => (0.0, d),
            (None, None) if n == 1 => (0.0, 0.0),
            (None, None) => {
                return Err(invalid(
                    StentParameter::Spacing,
                    "a straight centreline needs the crown spacing d_c",
                ));
            }
            (Some(_), None) if n == 1 => (0.0, 0.0),
            (Some(l), None) => (0.0, l / (n - 1) as Real),
            (Some(l), Some(d)) => {
                let span = d * (n - 1) as Real;
                if span > l * (1.0 + PLANARITY_TOLERANCE) {
                    return Err(invalid(
                        StentParameter::Spacing,
                        format!(
                            "{n} crowns at spacing {d} span {span}, more than the centreline length {l}"
                        ),
                    ));
                }
                (0.5 * (l - span).max(0.0), d)
            }
        };
        if n > 1 && spacing <= 2.0 * self.crown.amplitude {
            return Err(invalid(
                StentParameter::Spacing,
                format!(
                    "the crown spacing {spacing} must exceed the crown height 2 h_c = {}, or crowns overlap",
                    2.0 * self.crown.amplitude
                ),
            ));
        }
        Ok((0..n).map(|k| start + spacing * k as Real).collect())
    }

    /// The cut planes' normals in the axis frame at `s = 0` and their validity for this centreline.
    fn check_symmetry(&self, axis: &Axis) -> Result<(), GeometryError> {
        let m = self.crown.peaks as Real;
        if self.symmetry != Symmetry::None && !is_multiple(m * self.rotation, PI) {
            return Err(invalid(
                StentParameter::Rotation,
                format!(
                    "a symmetric device needs every crown even about the cut planes: peaks × rotation must be a multiple of 180°, got {} × {}°",
                    self.crown.peaks,
                    self.rotation.to_degrees()
                ),
            ));
        }
        match (self.symmetry, axis) {
            (Symmetry::None, _) => Ok(()),
            (Symmetry::Quarter, Axis::Straight { .. }) => {
                if !self.crown.peaks.is_multiple_of(2) {
                    return Err(invalid(
                        StentParameter::Symmetry,
                        format!(
                            "quarter symmetry needs an even number of peaks (a crest or trough on the plane ϑ = 90°), got {}",
                            self.crown.peaks
                        ),
                    ));
                }
                Ok(())
            }
            (Symmetry::Quarter, _) => Err(invalid(
                StentParameter::Symmetry,
                "quarter symmetry needs a straight centreline; use half symmetry for a planar bent one",
            )),
            (Symmetry::Half, Axis::Straight { .. }) => Ok(()),
            (Symmetry::Half, Axis::Arc { axis: a, frame, .. }) => {
                if frame.column(1).dot(a).abs() > PLANARITY_TOLERANCE {
                    return Err(invalid(
                        StentParameter::Symmetry,
                        "half symmetry needs the reference direction (ϑ = 0) in the plane of the arc",
                    ));
                }
                Ok(())
            }
            (Symmetry::Half, Axis::Curve { centreline }) => {
                let length = centreline.length();
                let (c0, r0) = axis.frame(0.0);
                let normal = r0.column(2).into_owned();
                let samples = 64;
                for k in 0..=samples {
                    let (c, r) = axis.frame(length * k as Real / samples as Real);
                    if (c - c0).dot(&normal).abs() > PLANARITY_TOLERANCE * length
                        || (r.column(2) - normal).norm() > PLANARITY_TOLERANCE
                    {
                        return Err(invalid(
                            StentParameter::Symmetry,
                            "half symmetry needs a planar centreline with the reference direction (ϑ = 0) in its plane",
                        ));
                    }
                }
                Ok(())
            }
        }
    }

    /// Generates the device (full or cut).
    pub fn generate(&self) -> Result<StentGeometry, GeometryError> {
        self.check_numbers()?;
        let axis = Arc::new(Axis::new(&self.centreline)?);
        let stations = self.stations(&axis)?;
        if let Axis::Arc { radius, .. } = axis.as_ref()
            && self.crown.radius >= *radius
        {
            return Err(invalid(
                StentParameter::Radius,
                format!(
                    "the crown radius {} must be smaller than the centreline's bend radius {radius}",
                    self.crown.radius
                ),
            ));
        }
        self.check_symmetry(&axis)?;
        let m = self.crown.peaks;
        let mf = m as Real;
        let n = self.crowns;
        if self.bridges.is_some() && n > 1 && !is_multiple(mf * self.rotation - PI, TAU) {
            return Err(invalid(
                StentParameter::Rotation,
                format!(
                    "bridges join each crest to the facing trough of the next crown, which needs peaks × rotation ≡ 180° (mod 360°); got {} × {}° (e.g. use {}°)",
                    m,
                    self.rotation.to_degrees(),
                    180.0 / mf
                ),
            ));
        }
        let (h, big_r) = (self.crown.amplitude, self.crown.radius);
        let half_wave = PI / mf;
        let phase = |k: usize| self.rotation * k as Real;
        let curve = |kind| StentCurve {
            axis: axis.clone(),
            radius: big_r,
            amplitude: h,
            peaks: mf,
            kind,
        };

        // Sector tests: near a plane, |sin| (or |cos|) is the angular distance from it.
        let sin_tol = ANGLE_TOLERANCE;
        let on_plane_a = |a: Real| self.symmetry != Symmetry::None && a.sin().abs() <= sin_tol;
        let on_plane_b = |a: Real| self.symmetry == Symmetry::Quarter && a.cos().abs() <= sin_tol;
        let retained = |a: Real| match (self.cut, self.symmetry) {
            (false, _) | (_, Symmetry::None) => true,
            (true, Symmetry::Half) => a.sin() >= -sin_tol,
            (true, Symmetry::Quarter) => a.sin() >= -sin_tol && a.cos() >= -sin_tol,
        };

        // Planes: A (ϑ = 0, π; normal d3 at s = 0) and, for quarter symmetry, B (ϑ = ±π/2; normal d2).
        let (c0, r0) = axis.frame(stations[0]);
        let mut symmetry_planes = Vec::new();
        if self.cut && self.symmetry != Symmetry::None {
            symmetry_planes.push(SymmetryPlane {
                point: c0,
                normal: r0.column(2).into_owned(),
            });
            if self.symmetry == Symmetry::Quarter {
                symmetry_planes.push(SymmetryPlane {
                    point: c0,
                    normal: r0.column(1).into_owned(),
                });
            }
        }
        let plane_of = |a: Real| -> Option<usize> {
            if !self.cut {
                None
            } else if on_plane_a(a) {
                Some(0)
            } else if on_plane_b(a) {
                Some(1)
            } else {
                None
            }
        };
        let multiplicity = |a: Real| -> usize {
            if !self.cut {
                1
            } else if on_plane_a(a) || on_plane_b(a) {
                self.symmetry.sectors() / 2
            } else {
                self.symmetry.sectors()
            }
        };

        // Nodes: every crest and trough of every crown, kept when in the sector.
        let mut nodes = Vec::new();
        let mut node_index = vec![vec![None; 2 * m]; n];
        // Node numbers (0-based) by increasing angle from ϑ = 0, whatever the crown's rotation.
        let first: Vec<usize> = (0..n)
            .map(|k| {
                let key = |j: usize| {
                    let x = (phase(k) + half_wave * j as Real).rem_euclid(TAU);
                    if TAU - x <= ANGLE_TOLERANCE { 0.0 } else { x }
                };
                (0..2 * m)
                    .min_by(|&a, &b| key(a).total_cmp(&key(b)))
                    .unwrap_or(0)
            })
            .collect();
        let number = |k: usize, j: usize| (j + 2 * m - first[k]) % (2 * m);
        for (k, &s) in stations.iter().enumerate() {
            let (c, r) = axis.frame(s);
            let t = r.column(0).into_owned();
            for j in (0..2 * m).map(|i| (i + first[k]) % (2 * m)) {
                let a = phase(k) + half_wave * j as Real;
                if !retained(a) {
                    continue;
                }
                let (sa, ca) = a.sin_cos();
                let x = if j % 2 == 0 { h } else { -h };
                let radial = r * Vec3::new(0.0, ca, sa);
                node_index[k][j] = Some(nodes.len());
                nodes.push(GeneratedNode {
                    name: format!("c{}_n{}", k + 1, number(k, j) + 1),
                    position: c + r * Vec3::new(x, big_r * ca, big_r * sa),
                    ends: Vec::new(),
                    crown: k,
                    index: j,
                    kind: if j % 2 == 0 {
                        NodeKind::Crest
                    } else {
                        NodeKind::Trough
                    },
                    angle: a,
                    station: s,
                    axis_point: c,
                    axis_tangent: t,
                    radial,
                    symmetry_plane: plane_of(a),
                    multiplicity: multiplicity(a),
                });
            }
        }

        // Crown wires.
        let mut patches = Vec::new();
        for (k, &s) in stations.iter().enumerate() {
            let (_, r) = axis.frame(s);
            for j in (0..2 * m).map(|i| (i + first[k]) % (2 * m)) {
                let from = phase(k) + half_wave * j as Real;
                let to = from + half_wave;
                if !retained(0.5 * (from + to)) {
                    continue;
                }
                let (Some(a), Some(b)) = (node_index[k][j], node_index[k][(j + 1) % (2 * m)])
                else {
                    unreachable!(
                        "the ends of a retained wire are retained (cuts pass through nodes)"
                    );
                };
                let (sa, ca) = from.sin_cos();
                patches.push(GeneratedPatch {
                    name: format!("c{}_w{}", k + 1, number(k, j) + 1),
                    role: PatchRole::Crown { crown: k, wire: j },
                    curve: curve(CurveKind::Crown {
                        station: s,
                        phase: phase(k),
                        from,
                        to,
                    }),
                    start_node: a,
                    end_node: b,
                    normal_hint: r * Vec3::new(0.0, ca, sa),
                    in_plane: None,
                });
            }
        }

        // Bridges.
        let mut bridge_ends = Vec::new();
        if let Some(b) = &self.bridges {
            for k in 0..n.saturating_sub(1) {
                let mut crests: Vec<usize> = (0..m).filter(|c| c % b.every == b.first).collect();
                crests.sort_by_key(|&c| number(k, 2 * c));
                let angles: Vec<Real> = crests
                    .iter()
                    .map(|&c| phase(k) + 2.0 * half_wave * c as Real)
                    .collect();
                self.check_bridge_symmetry(k, &angles)?;
                let (_, r) = axis.frame(stations[k]);
                for (&c, &a) in crests.iter().zip(&angles) {
                    if !retained(a) {
                        continue;
                    }
                    // The facing trough of crown k + 1.
                    let q = (a - phase(k + 1)) / half_wave;
                    let j = (q.round() as i64).rem_euclid(2 * m as i64) as usize;
                    debug_assert!(
                        j % 2 == 1 && same_angle(a, phase(k + 1) + half_wave * j as Real)
                    );
                    // A rotation so large that angles lost their precision (found by fuzzing the designs:
                    // `rotation_deg: 1e308`) can leave a crest facing no retained trough: an error, not a panic.
                    let (Some(start), Some(end)) = (node_index[k][2 * c], node_index[k + 1][j])
                    else {
                        return Err(invalid(
                            StentParameter::Rotation,
                            format!(
                                "the bridge from crown {} at ϑ = {:.6} rad finds no trough of crown {} facing it; give a rotation in degrees within (−360, 360)",
                                k + 1,
                                a,
                                k + 2
                            ),
                        ));
                    };
                    let in_plane = plane_of(a);
                    let offset = match b.shape {
                        BridgeShape::Straight => Offset::None,
                        BridgeShape::Sinusoidal {
                            amplitude,
                            waves,
                            direction: BridgeDirection::Radial,
                        } => Offset::Radial { amplitude, waves },
                        BridgeShape::Sinusoidal {
                            amplitude,
                            waves,
                            direction: BridgeDirection::Circumferential,
                        } => {
                            let sign = match self.symmetry {
                                Symmetry::None => 1.0,
                                Symmetry::Half => a.sin(),
                                Symmetry::Quarter => (2.0 * a).sin(),
                            };
                            if sign.abs() <= sin_tol {
                                return Err(invalid(
                                    StentParameter::BridgesDirection,
                                    format!(
                                        "the circumferential sinusoidal bridge at ϑ = {:.3}° lies on a symmetry plane and cannot be symmetric about it: use `direction: radial`, straight bridges, or crests off the plane (`every`, `first`)",
                                        a.to_degrees()
                                    ),
                                ));
                            }
                            Offset::Circumferential {
                                amplitude: amplitude * sign.signum(),
                                waves,
                            }
                        }
                    };
                    let (sa, ca) = a.sin_cos();
                    bridge_ends.extend([start, end]);
                    patches.push(GeneratedPatch {
                        name: format!("b{}_{}", k + 1, number(k, 2 * c) + 1),
                        role: PatchRole::Bridge { pair: k, crest: c },
                        curve: curve(CurveKind::Bridge {
                            from: stations[k],
                            to: stations[k + 1],
                            angle: a,
                            offset,
                        }),
                        start_node: start,
                        end_node: end,
                        normal_hint: r * Vec3::new(0.0, ca, sa),
                        in_plane,
                    });
                }
            }
            self.check_clearance(&axis, &stations, &nodes)?;
        }

        for (p, patch) in patches.iter().enumerate() {
            nodes[patch.start_node].ends.push((p, WireEnd::Start));
            nodes[patch.end_node].ends.push((p, WireEnd::End));
        }

        let mut node_sets: BTreeMap<String, Vec<usize>> = BTreeMap::new();
        node_sets.insert("all_joints".into(), (0..nodes.len()).collect());
        for k in 0..n {
            node_sets.insert(
                format!("crown_{}", k + 1),
                (0..nodes.len()).filter(|&i| nodes[i].crown == k).collect(),
            );
        }
        for (name, kind) in [("crests", NodeKind::Crest), ("troughs", NodeKind::Trough)] {
            node_sets.insert(
                name.into(),
                (0..nodes.len())
                    .filter(|&i| nodes[i].kind == kind)
                    .collect(),
            );
        }
        bridge_ends.sort_unstable();
        bridge_ends.dedup();
        node_sets.insert("bridge_ends".into(), bridge_ends);
        node_sets.insert(
            "symmetry".into(),
            (0..nodes.len())
                .filter(|&i| nodes[i].symmetry_plane.is_some())
                .collect(),
        );
        Ok(StentGeometry {
            patches,
            nodes,
            node_sets,
            symmetry_planes,
            stations,
        })
    }

    /// The bridges of pair `k` at crest angles `angles` must map onto themselves under every mirror of the
    /// device's symmetry.
    fn check_bridge_symmetry(&self, k: usize, angles: &[Real]) -> Result<(), GeometryError> {
        let mirrors: &[Mirror] = match self.symmetry {
            Symmetry::None => &[],
            Symmetry::Half => &[(|a| -a, "ϑ = 0°/180°")],
            Symmetry::Quarter => &[(|a| -a, "ϑ = 0°/180°"), (|a| PI - a, "ϑ = ±90°")],
        };
        for (mirror, plane) in mirrors {
            for &a in angles {
                if !angles.iter().any(|&b| same_angle(mirror(a), b)) {
                    return Err(invalid(
                        StentParameter::Bridges,
                        format!(
                            "the bridges between crowns {} and {} are not symmetric about the plane {plane}: the bridge at ϑ = {:.3}° has no mirror image; choose `every` and `first` so that the bridged crests are symmetric",
                            k + 1,
                            k + 2,
                            a.to_degrees()
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Consecutive crowns must not overlap: at every retained crest the next crown's facing trough lies ahead
    /// along the axis (tight bends bring crowns together on the inside).
    fn check_clearance(
        &self,
        axis: &Axis,
        stations: &[Real],
        nodes: &[GeneratedNode],
    ) -> Result<(), GeometryError> {
        for crest in nodes {
            if crest.kind != NodeKind::Crest || crest.crown + 1 >= stations.len() {
                continue;
            }
            let k = crest.crown;
            let (_, r) = axis.frame(0.5 * (stations[k] + stations[k + 1]));
            let facing = nodes.iter().find(|q| {
                q.crown == k + 1 && q.kind == NodeKind::Trough && same_angle(q.angle, crest.angle)
            });
            if let Some(q) = facing
                && (q.position - crest.position).dot(&r.column(0)) <= 0.0
            {
                return Err(invalid(
                    StentParameter::Spacing,
                    format!(
                        "crowns {} and {} overlap at ϑ = {:.1}°: the bend is too tight for the crown height (increase the spacing or the bend radius)",
                        k + 1,
                        k + 2,
                        crest.angle.to_degrees()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Positions of the nodes of `geometry` (generated from `self`) in a temporary placement: the same crowns at
    /// the same stations and angles on another centreline and/or radius (paper Eq. `target_disp`: `P_temp`).
    pub fn temporary_node_positions(
        &self,
        geometry: &StentGeometry,
        temporary: &TemporarySpec,
    ) -> Result<Vec<Vec3>, GeometryError> {
        let radius = temporary.radius.unwrap_or(self.crown.radius);
        if !(radius.is_finite() && radius > 0.0) {
            return Err(invalid(
                StentParameter::TemporaryRadius,
                format!("must be > 0, got {radius}"),
            ));
        }
        let permanent = Axis::new(&self.centreline)?;
        let stations = &geometry.stations;
        let axis = match &temporary.centreline {
            TemporaryCentreline::Same => permanent,
            TemporaryCentreline::Straightened => {
                let mid = 0.5 * (stations[0] + stations[stations.len() - 1]);
                let (c, r) = permanent.frame(mid);
                Axis::Straight {
                    origin: c - r.column(0) * mid,
                    frame: r,
                }
            }
            TemporaryCentreline::Given(spec) => {
                let axis = Axis::new(spec).map_err(|e| match e {
                    GeometryError::InvalidStent { reason, .. } => {
                        invalid(StentParameter::TemporaryCentreline, reason)
                    }
                    e => e,
                })?;
                if let Some(l) = axis.length() {
                    let last = stations[stations.len() - 1];
                    if last > l * (1.0 + PLANARITY_TOLERANCE) {
                        return Err(invalid(
                            StentParameter::TemporaryCentreline,
                            format!(
                                "the last crown sits at arc length {last}, beyond the temporary centreline's length {l}"
                            ),
                        ));
                    }
                }
                axis
            }
        };
        let h = self.crown.amplitude;
        Ok(geometry
            .nodes
            .iter()
            .map(|node| {
                let (c, r) = axis.frame(node.station);
                let x = if node.kind == NodeKind::Crest { h } else { -h };
                let (sa, ca) = node.angle.sin_cos();
                c + r * Vec3::new(x, radius * ca, radius * sa)
            })
            .collect())
    }
}

impl StentGeometry {
    /// Index of the node named `name`.
    pub fn node(&self, name: &str) -> Option<usize> {
        self.nodes.iter().position(|n| n.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn straight(symmetry: Symmetry, cut: bool) -> StentSpec {
        StentSpec {
            crown: CrownSpec {
                radius: 20.0,
                amplitude: 5.0,
                peaks: 6,
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
