//! The global linear system: [`LinearSystem`] chooses between the block-bordered solver of [`super::block`]
//! and the general sparse LU of [`super::sparse`].

use super::SolverError;
use super::block::BlockSystem;
use super::sparse::SparseSystem;
use crate::math::Real;
use crate::model::LinearMethod;

/// The Newton systems' solver: the block-bordered solver ([`BlockSystem`]) when the design asks for it and the
/// pattern allows, with the general sparse LU as its fallback (a patch interior singular on its own) and as
/// the alternative the design can choose (`solver: {linear: sparse-lu}`). Behind a block solver the sparse
/// LU's analysis waits until a factorisation falls back to it: patterns are analysed again whenever a
/// coupling changes (contact between wires), and most never need it.
pub struct LinearSystem {
    n: usize,
    /// The pattern, kept until the sparse LU is analysed.
    entries: Vec<(usize, usize)>,
    sparse: Option<SparseSystem>,
    block: Option<BlockSystem>,
    /// The last factorisation is the sparse LU's although a block solver exists.
    fallback: bool,
}

impl std::fmt::Debug for LinearSystem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LinearSystem")
            .field("sparse", &self.sparse)
            .field("block", &self.block)
            .finish()
    }
}

impl LinearSystem {
    /// Analyses the pattern (see [`SparseSystem::new`]) for `method`; `patches` lists each patch's first
    /// control point and count and `border_points` the control points the block solver puts on its border (see
    /// [`BlockSystem::new`]).
    pub fn new(
        n: usize,
        entries: &[(usize, usize)],
        patches: &[(usize, usize)],
        border_points: &[usize],
        method: LinearMethod,
    ) -> Result<Self, SolverError> {
        let block = match method {
            LinearMethod::Block => BlockSystem::new(n, entries, patches, border_points)?,
            LinearMethod::SparseLu => None,
        };
        let sparse = match block {
            Some(_) => None,
            None => Some(SparseSystem::new(n, entries)?),
        };
        Ok(Self {
            n,
            entries: if sparse.is_none() {
                entries.to_vec()
            } else {
                Vec::new()
            },
            sparse,
            block,
            fallback: false,
        })
    }

    /// The solver that factorised last: `"block"` or `"sparse-lu"`.
    pub fn method(&self) -> &'static str {
        if self.block.is_some() && !self.fallback {
            "block"
        } else {
            "sparse-lu"
        }
    }

    /// Number of unknowns.
    pub fn size(&self) -> usize {
        self.n
    }

    /// Forgets the factorisation (it belonged to a state that was abandoned).
    pub fn invalidate(&mut self) {
        if let Some(s) = &mut self.sparse {
            s.invalidate();
        }
        if let Some(b) = &mut self.block {
            b.invalidate();
        }
    }

    /// True when a factorisation is available for solves.
    pub fn is_factored(&self) -> bool {
        match &self.block {
            Some(b) if !self.fallback => b.is_factored(),
            _ => self.sparse.as_ref().is_some_and(SparseSystem::is_factored),
        }
    }

    /// Factorises the matrix whose pushed entries are `entry_values`; the sparse LU takes over a
    /// factorisation the block solver cannot do.
    pub fn factor(&mut self, entry_values: &[Real]) -> Result<(), SolverError> {
        if let Some(b) = &mut self.block {
            match b.factor(entry_values) {
                Ok(()) => {
                    self.fallback = false;
                    return Ok(());
                }
                Err(SolverError::Singular { .. }) => self.fallback = true,
                Err(e) => return Err(e),
            }
        }
        let sparse = match self.sparse.take() {
            Some(s) => s,
            None => SparseSystem::new(self.n, &self.entries)?,
        };
        self.entries = Vec::new();
        self.sparse.insert(sparse).factor(entry_values)
    }

    /// Solves `A x = b` in place with the last factorisation.
    pub fn solve_in_place(&mut self, rhs: &mut [Real]) {
        match &mut self.block {
            Some(b) if !self.fallback => b.solve_in_place(rhs),
            _ => match &mut self.sparse {
                Some(s) => s.solve_in_place(rhs),
                None => panic!("solve before a successful factorisation"),
            },
        }
    }
}
