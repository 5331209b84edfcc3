//! B-spline and NURBS basis functions and their derivatives (Piegl–Tiller A2.2, A2.3; rational basis by the
//! quotient rule, Piegl–Tiller Eq. 4.2 differentiated as in A4.2).

use super::{KnotVector, Real};

/// The `p + 1` non-zero basis functions at a parameter and their derivatives up to order `nders`.
///
/// `ders[k][j]` is the `k`-th derivative with respect to the curve parameter `u` of the basis function with
/// global index `first + j`.
#[derive(Debug, Clone, PartialEq)]
pub struct BasisTable {
    /// Global index of the first non-zero basis function (`span − p`).
    pub first: usize,
    /// `ders[k][j]`: `k`-th derivative of basis function `first + j`; `k = 0 … nders`, `j = 0 … p`.
    pub ders: Vec<Vec<Real>>,
}

/// Non-zero B-spline basis functions at `u` and their derivatives up to order `nders`
/// (Piegl–Tiller A2.3). Derivatives above the degree are zero.
pub fn bspline_basis(knots: &KnotVector, u: Real, nders: usize) -> BasisTable {
    todo!("{knots:?} {u} {nders}")
}

/// Non-zero NURBS basis functions `R_j = w_j N_j / Σ w_k N_k` at `u` and their derivatives up to order
/// `nders`, from the B-spline table by the quotient (Leibniz) rule.
/// `weights` has one positive weight per basis function.
pub fn nurbs_basis(knots: &KnotVector, weights: &[Real], u: Real, nders: usize) -> BasisTable {
    todo!("{knots:?} {weights:?} {u} {nders}")
}
