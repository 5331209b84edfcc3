//! NURBS curves in 3-D: evaluation with derivatives (Piegl–Tiller A3.2 / A4.2), knot insertion (A5.1),
//! knot refinement and degree elevation (A5.9), and the refinement of a curve to a prescribed degree and
//! number of control points.

use super::{KnotVector, MathError, Real, Vec3};

/// A NURBS curve `c(u) = Σ R_j(u) p_j` with control points `p_j` and positive weights `w_j` (all 1 for a
/// plain B-spline).
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsCurve {
    knots: KnotVector,
    points: Vec<Vec3>,
    weights: Vec<Real>,
}

impl NurbsCurve {
    /// A NURBS curve; fails unless there is one point and one positive finite weight per basis function.
    pub fn try_new(
        knots: KnotVector,
        points: Vec<Vec3>,
        weights: Vec<Real>,
    ) -> Result<Self, MathError> {
        todo!("{knots:?} {points:?} {weights:?}")
    }

    /// A non-rational B-spline curve (all weights 1).
    pub fn try_bspline(knots: KnotVector, points: Vec<Vec3>) -> Result<Self, MathError> {
        let weights = vec![1.0; points.len()];
        Self::try_new(knots, points, weights)
    }

    /// The knot vector.
    pub fn knots(&self) -> &KnotVector {
        &self.knots
    }

    /// The control points.
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    /// The weights.
    pub fn weights(&self) -> &[Real] {
        &self.weights
    }

    /// Degree `p`.
    pub fn degree(&self) -> usize {
        self.knots.degree()
    }

    /// Number of control points `n`.
    pub fn num_points(&self) -> usize {
        self.points.len()
    }

    /// True when every weight is 1 (a plain B-spline).
    pub fn is_polynomial(&self) -> bool {
        self.weights.iter().all(|&w| w == 1.0)
    }

    /// The point `c(u)`.
    pub fn point(&self, u: Real) -> Vec3 {
        self.derivatives(u, 0)[0]
    }

    /// `c(u)` and its derivatives with respect to `u` up to order `nders` (`result[k]` = k-th derivative).
    pub fn derivatives(&self, u: Real, nders: usize) -> Vec<Vec3> {
        todo!("{u} {nders}")
    }

    /// The same curve with the knot `u` inserted `times` times (Piegl–Tiller A5.1); the result's multiplicity
    /// at `u` may not exceed the degree.
    pub fn insert_knot(&self, u: Real, times: usize) -> Result<Self, MathError> {
        todo!("{u} {times}")
    }

    /// The same curve with its degree raised by `t` (Piegl–Tiller A5.9, on homogeneous coordinates).
    pub fn elevate_degree(&self, t: usize) -> Result<Self, MathError> {
        todo!("{t}")
    }

    /// The same curve, degree-elevated to `degree` and then knot-refined to exactly `n` control points.
    /// Only for curves without interior knots (single Bézier segments, as the exact primitives are built):
    /// the inserted knots are `n − degree − 1` simple knots, uniform in the parameter.
    pub fn refined(&self, degree: usize, n: usize) -> Result<Self, MathError> {
        todo!("{degree} {n}")
    }
}
