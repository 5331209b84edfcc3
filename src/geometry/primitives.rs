//! Exact NURBS primitives: straight lines and circular arcs, refined by degree elevation and knot insertion
//! to a patch's degree `p` and number of control points `n` (the geometry is unchanged by refinement).

use super::GeometryError;
use crate::math::{NurbsCurve, Real, Vec3};

/// PLACEHOLDER (math branch).
pub fn line(a: Vec3, b: Vec3, degree: usize, n: usize) -> Result<NurbsCurve, GeometryError> {
    todo!("{a}{b}{degree}{n}")
}

/// PLACEHOLDER (math branch).
pub fn arc(
    center: Vec3,
    start: Vec3,
    axis: Vec3,
    angle: Real,
    degree: usize,
    n: usize,
) -> Result<NurbsCurve, GeometryError> {
    todo!("{center}{start}{axis}{angle}{degree}{n}")
}
