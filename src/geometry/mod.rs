//! Geometry: exact NURBS primitives (lines, circular arcs), analytic curves and their spline fits,
//! rotation-minimising section frames (along spline curves in `frame`, along bare polylines in `polyline`), the
//! stent generator, wire-on-wire proximity (`proximity`), and closed surfaces: the triangle mesh type (`mesh`),
//! tubes swept along centrelines (`tube`), spheres (`sphere`) and whole devices (`device_tubes`) — vertices and
//! triangles only; writing files is the `io` layer's job.

pub mod analytic;
pub(crate) mod device_tubes;
pub mod fit;
pub mod frame;
pub mod mesh;
#[cfg(test)]
pub(crate) mod polyline;
pub mod primitives;
pub mod proximity;
pub(crate) mod simplify;
pub mod solid;
#[cfg(test)]
pub(crate) mod sphere;
pub mod stent;
#[cfg(test)]
mod test_shapes;
pub mod tube;

use crate::math::{MathError, Real};

/// The parameter of a primitive, analytic curve or fit that an [`GeometryError::InvalidParameter`] is about:
/// a caller maps it to its own input (a design file's field) without reading the message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parameter {
    /// The degree of a primitive.
    Degree,
    /// The number of control points of a primitive.
    ControlPoints,
    /// A line's start point.
    LineStart,
    /// A line's end point.
    LineEnd,
    /// A line's two end points together (they coincide).
    LineEnds,
    /// An arc's centre.
    ArcCentre,
    /// An arc's start point.
    ArcStart,
    /// An arc's axis.
    ArcAxis,
    /// An arc's angle.
    ArcAngle,
    /// The axis of a rigid placement.
    Axis,
    /// The points a curve passes through.
    Points,
    /// A curve to be fitted.
    Curve,
}

impl std::fmt::Display for Parameter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Parameter::Degree => "degree",
            Parameter::ControlPoints => "number of control points",
            Parameter::LineStart => "line start point",
            Parameter::LineEnd => "line end point",
            Parameter::LineEnds => "line end points",
            Parameter::ArcCentre => "arc centre",
            Parameter::ArcStart => "arc start point",
            Parameter::ArcAxis => "arc axis",
            Parameter::ArcAngle => "arc angle",
            Parameter::Axis => "axis",
            Parameter::Points => "points",
            Parameter::Curve => "curve",
        })
    }
}

/// Errors raised when geometric data cannot produce a valid curve, frame or surface.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeometryError {
    /// A NURBS operation failed.
    #[error(transparent)]
    Math(#[from] MathError),
    /// A parameter of a primitive or analytic curve is out of range.
    #[error("invalid {what}: {reason}")]
    InvalidParameter {
        /// Which parameter.
        what: Parameter,
        /// What is wrong, with the value.
        reason: String,
    },
    /// A parameter of a stent specification is out of range.
    #[error("invalid {parameter}: {reason}")]
    InvalidStent {
        /// Which parameter.
        parameter: stent::StentParameter,
        /// What is wrong, with the value.
        reason: String,
    },
    /// A curve is degenerate where a frame is needed (zero tangent).
    #[error("degenerate curve: zero tangent at u = {u}")]
    ZeroTangent {
        /// Curve parameter.
        u: Real,
    },
    /// No smoothing spline of at most [`fit::MAX_SMOOTHING_CONTROL_POINTS`] control points stays within the
    /// tolerance of every point ([`fit::smooth_points`]): the tolerance is tighter than the points' scatter.
    #[error(
        "a smoothing tolerance of {} is too tight for these {points} points: the closest spline found, with {control_points} control points, is {} from point {worst_point}; set the tolerance to at least {}",
        crate::math::Short(*tolerance),
        crate::math::Short(*closest),
        crate::math::Short(*enough)
    )]
    SmoothingTooTight {
        /// The tolerance asked for \[length\].
        tolerance: Real,
        /// The points to fit.
        points: usize,
        /// Largest distance of the closest fit found from a point \[length\].
        closest: Real,
        /// The point (from 0) where that fit is farthest.
        worst_point: usize,
        /// Control points of that fit.
        control_points: usize,
        /// A tolerance that the same search meets: `closest` rounded up to two significant digits \[length\].
        enough: Real,
    },
}
