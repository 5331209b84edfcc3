//! The general sparse linear system (faer): the compressed-column pattern and the symbolic LU analysis once per
//! pattern, then a numeric LU per Newton iteration into reused storage and scratch (faer's low-level
//! `factorize_numeric_lu`, no allocation once warm), and solves.
//!
//! Assembly pushes entries in a fixed order (repeats allowed, they are summed); the pattern maps each pushed
//! entry to its slot in the compressed columns once, so refilling the values is one pass with no sorting.

use super::{LinearError, SolverError};
use crate::math::Real;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::lu::{LuRef, NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};

/// `Ok` when the entry `(r, c)` lies in an `n × n` matrix.
pub(super) fn inside(n: usize, r: usize, c: usize) -> Result<(), SolverError> {
    if r < n && c < n {
        return Ok(());
    }
    Err(LinearError::EntryOutside {
        row: r,
        column: c,
        size: n,
    }
    .into())
}

/// A square sparse matrix pattern, its symbolic LU analysis and reusable numeric storage.
pub(crate) struct SparseSystem {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// For each pushed entry, its slot in `values`.
    slot: Vec<usize>,
    /// Matrix values in compressed-column order.
    values: Vec<Real>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, Real>,
    factor_scratch: MemBuffer,
    solve_scratch: MemBuffer,
    factored: bool,
}

impl std::fmt::Debug for SparseSystem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SparseSystem")
            .field("n", &self.n)
            .field("nonzeros", &self.row_idx.len())
            .field("entries", &self.slot.len())
            .finish()
    }
}

impl SparseSystem {
    /// Analyses the pattern given as `(row, column)` pairs in assembly order (repeats are summed).
    pub(crate) fn new(n: usize, entries: &[(usize, usize)]) -> Result<Self, SolverError> {
        // Sort entry indices by (column, row) and merge repeats into slots.
        let mut order: Vec<usize> = (0..entries.len()).collect();
        order.sort_unstable_by_key(|&k| (entries[k].1, entries[k].0));
        let mut col_ptr = vec![0usize; n + 1];
        let mut row_idx = Vec::with_capacity(entries.len());
        let mut slot = vec![0usize; entries.len()];
        let mut last: Option<(usize, usize)> = None;
        for &k in &order {
            let (r, c) = entries[k];
            inside(n, r, c)?;
            if last != Some((r, c)) {
                row_idx.push(r);
                col_ptr[c + 1] += 1;
                last = Some((r, c));
            }
            slot[k] = row_idx.len() - 1;
        }
        for c in 0..n {
            col_ptr[c + 1] += col_ptr[c];
        }
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let symbolic = factorize_symbolic_lu(pattern, Default::default())
            .map_err(|reason| LinearError::Symbolic { size: n, reason })?;
        let factor_req =
            symbolic.factorize_numeric_lu_scratch::<Real>(Par::Seq, Default::default());
        let solve_req = symbolic.solve_in_place_scratch::<Real>(1, Par::Seq);
        let alloc = |req: StackReq| {
            MemBuffer::try_new(req).map_err(|_| LinearError::Workspace {
                bytes: req.size_bytes(),
            })
        };
        let factor_scratch = alloc(factor_req)?;
        let solve_scratch = alloc(solve_req)?;
        let nnz = row_idx.len();
        Ok(Self {
            n,
            col_ptr,
            row_idx,
            slot,
            values: vec![0.0; nnz],
            symbolic,
            numeric: NumericLu::new(),
            factor_scratch,
            solve_scratch,
            factored: false,
        })
    }

    /// Forgets the factorisation (it belonged to a state that was abandoned).
    pub(crate) fn invalidate(&mut self) {
        self.factored = false;
    }

    /// True when a factorisation is available for solves.
    pub(crate) fn is_factored(&self) -> bool {
        self.factored
    }

    /// Factorises the matrix whose pushed entries are `entry_values` (in the pattern's assembly order).
    /// `Err(Singular)` when no pivot is found: the tangent is singular.
    pub(crate) fn factor(&mut self, entry_values: &[Real]) -> Result<(), SolverError> {
        assert_eq!(
            entry_values.len(),
            self.slot.len(),
            "one value per pushed entry"
        );
        self.values.fill(0.0);
        for (&s, &v) in self.slot.iter().zip(entry_values) {
            self.values[s] += v;
        }
        self.factored = false;
        let pattern = SymbolicSparseColMatRef::new_checked(
            self.n,
            self.n,
            &self.col_ptr,
            None,
            &self.row_idx,
        );
        let matrix = SparseColMatRef::new(pattern, &self.values);
        let stack = MemStack::new(&mut self.factor_scratch);
        match self.symbolic.factorize_numeric_lu(
            &mut self.numeric,
            matrix,
            Par::Seq,
            stack,
            Default::default(),
        ) {
            Ok(_) => {
                self.factored = true;
                Ok(())
            }
            Err(LuError::SymbolicSingular { index }) => {
                // `index` is the elimination step; the column permutation names the unknown.
                let (forward, _) = self.symbolic.col_perm().arrays();
                let column = forward.get(index).copied().unwrap_or(index);
                Err(SolverError::Singular {
                    column,
                    location: String::new(),
                })
            }
            Err(LuError::Generic(reason)) => Err(LinearError::Numeric {
                size: self.n,
                reason,
            }
            .into()),
        }
    }

    /// Solves `A x = b` in place with the last factorisation (`rhs` holds `b` on entry and `x` on exit).
    pub(crate) fn solve_in_place(&mut self, rhs: &mut [Real]) {
        assert!(self.factored, "solve before a successful factorisation");
        let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        let n = rhs.len();
        let rhs = MatMut::from_column_major_slice_mut(rhs, n, 1);
        let stack = MemStack::new(&mut self.solve_scratch);
        lu.solve_in_place_with_conj(Conj::No, rhs, Par::Seq, stack);
    }
}
