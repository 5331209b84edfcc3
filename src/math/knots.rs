//! Knot vectors: validation, clamped (open) construction, span search (Piegl–Tiller A2.1) and Greville
//! abscissae.

use super::{MathError, Real};

/// A validated, non-decreasing knot vector of a degree-`p` spline with `n` basis functions
/// (`n + p + 1` knots). Clamped (open): the first and last knots repeat `p + 1` times.
#[derive(Debug, Clone, PartialEq)]
pub struct KnotVector {
    degree: usize,
    knots: Vec<Real>,
}

impl KnotVector {
    /// Validates a clamped knot vector of degree `degree ≥ 1`: finite, non-decreasing, end knots repeated
    /// exactly `p + 1` times, interior multiplicity ≤ `p`, at least `p + 1` basis functions, non-empty domain.
    pub fn try_new(degree: usize, knots: Vec<Real>) -> Result<Self, MathError> {
        todo!("{degree} {knots:?}")
    }

    /// The clamped knot vector on `[0, 1]` with `n ≥ p + 1` basis functions and `n − p − 1` uniformly spaced
    /// simple interior knots.
    pub fn clamped_uniform(degree: usize, n: usize) -> Result<Self, MathError> {
        todo!("{degree} {n}")
    }

    /// The clamped knot vector on `[0, 1]` with the given strictly increasing interior knots in `(0, 1)`,
    /// each of multiplicity one (repeat a value to raise its multiplicity).
    pub fn clamped_with_interior(degree: usize, interior: &[Real]) -> Result<Self, MathError> {
        todo!("{degree} {interior:?}")
    }

    /// Polynomial degree `p`.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The knots `u_0 … u_{n+p}`.
    pub fn knots(&self) -> &[Real] {
        &self.knots
    }

    /// Number of basis functions `n`.
    pub fn num_basis(&self) -> usize {
        self.knots.len() - self.degree - 1
    }

    /// The parameter domain `[u_p, u_n]`.
    pub fn domain(&self) -> (Real, Real) {
        (self.knots[self.degree], self.knots[self.num_basis()])
    }

    /// The knot span index `i` with `u_i ≤ u < u_{i+1}` and `p ≤ i ≤ n − 1`; `u` at the right end of the domain
    /// returns the last non-empty span (Piegl–Tiller A2.1, by bisection). `u` is clamped into the domain.
    pub fn find_span(&self, u: Real) -> usize {
        todo!("{u}")
    }

    /// Multiplicity of the knot value `u` (0 if `u` is not a knot), compared exactly.
    pub fn multiplicity(&self, u: Real) -> usize {
        todo!("{u}")
    }

    /// The Greville abscissae `ξ_j = (u_{j+1} + … + u_{j+p}) / p`, `j = 0 … n − 1`: the collocation points.
    pub fn greville(&self) -> Vec<Real> {
        todo!()
    }

    /// The distinct knot values (breakpoints) in increasing order.
    pub fn breakpoints(&self) -> Vec<Real> {
        todo!()
    }
}
