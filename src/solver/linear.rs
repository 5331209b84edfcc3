//! The global sparse linear system: the pattern and the symbolic LU analysis once per pattern (faer), a
//! numeric LU per Newton iteration, and solves.

use super::SolverError;
use crate::math::Real;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{Argsort, Pair, SparseColMat, SymbolicSparseColMat};

/// A square sparse matrix pattern with its symbolic LU analysis.
#[derive(Debug, Clone)]
pub struct SparseSystem {
    n: usize,
    /// Number of entries pushed per assembly (duplicates included; they are summed).
    entries: usize,
    pattern: SymbolicSparseColMat<usize>,
    argsort: Argsort<usize>,
    symbolic: SymbolicLu<usize>,
}

/// A numeric LU factorisation of the system matrix.
pub struct Factorisation {
    lu: Lu<usize, Real>,
}

impl SparseSystem {
    /// Analyses the pattern given as `(row, column)` pairs in assembly order (repeats are summed).
    pub fn new(n: usize, entries: &[(usize, usize)]) -> Result<Self, SolverError> {
        let pairs: Vec<Pair<usize, usize>> =
            entries.iter().map(|&(r, c)| Pair::new(r, c)).collect();
        let (pattern, argsort) = SymbolicSparseColMat::try_new_from_indices(n, n, &pairs)
            .map_err(|e| SolverError::Linear(format!("sparsity pattern: {e:?}")))?;
        let symbolic = SymbolicLu::try_new(pattern.as_ref())
            .map_err(|e| SolverError::Linear(format!("symbolic LU: {e:?}")))?;
        Ok(Self {
            n,
            entries: entries.len(),
            pattern,
            argsort,
            symbolic,
        })
    }

    /// Number of unknowns.
    pub fn size(&self) -> usize {
        self.n
    }

    /// Number of entries one assembly pushes.
    pub fn entries(&self) -> usize {
        self.entries
    }

    /// Number of structural non-zeros.
    pub fn nonzeros(&self) -> usize {
        self.pattern.compute_nnz()
    }

    /// Factorises the matrix whose entries are `values`, in the pattern's assembly order.
    /// `Err(Singular)` when no pivot is found: the tangent is singular.
    pub fn factor(&self, values: &[Real]) -> Result<Factorisation, SolverError> {
        let matrix = SparseColMat::new_from_argsort(self.pattern.clone(), &self.argsort, values)
            .map_err(|e| SolverError::Linear(format!("matrix values: {e:?}")))?;
        match Lu::try_new_with_symbolic(self.symbolic.clone(), matrix.as_ref()) {
            Ok(lu) => Ok(Factorisation { lu }),
            Err(LuError::SymbolicSingular { index }) => Err(SolverError::Singular { index }),
            Err(LuError::Generic(e)) => Err(SolverError::Linear(format!("numeric LU: {e:?}"))),
        }
    }
}

impl Factorisation {
    /// Solves `A x = b` in place (`rhs` holds `b` on entry and `x` on exit).
    pub fn solve_in_place(&self, rhs: &mut [Real]) {
        let col = faer::ColMut::from_slice_mut(rhs);
        self.lu.solve_in_place(col);
    }
}
