//! Geometry: exact NURBS primitives (lines, circular arcs), analytic curves and their spline fits,
//! rotation-minimising section frames (along spline curves in `frame`, along bare polylines in `polyline`), the
//! stent generator, and closed surfaces: the triangle mesh type (`mesh`), tubes swept along centrelines
//! (`tube`), spheres (`sphere`) and whole devices (`device_tubes`) — vertices and triangles only; writing files
//! is the `io` layer's job.

pub mod analytic;
pub mod device_tubes;
pub mod fit;
pub mod frame;
pub mod mesh;
pub mod polyline;
pub mod primitives;
pub mod sphere;
pub mod stent;
#[cfg(test)]
mod test_shapes;
pub mod tube;

use crate::math::{MathError, Real};

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
        what: &'static str,
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
}
