//! The block-bordered solver of the collocation system (DESIGN §6): a banded LU per patch interior and a sparse
//! LU of the Schur complement on the patch-end unknowns.
//!
//! Number the unknowns and equations of every patch's interior control (= collocation) points apart from those
//! of the patch ends and of any extra unknowns (gauge multipliers); together the latter form the border `B`.
//! An interior collocation row touches only control points of its own patch (the `p + 1` around its Greville
//! point), so in that ordering
//! ```text
//! A = ⎡ A_II,1              A_IB,1 ⎤        A_II,k banded (half-bandwidths ≈ 3(p + 1)),
//!     ⎢        ⋱             ⋮    ⎥        A_IB,k: the 12 end columns of patch k,
//!     ⎢          A_II,K     A_IB,K ⎥        A_BI,k: node-equation rows reaching into patch k,
//!     ⎣ A_BI,1 … A_BI,K     A_BB   ⎦
//! ```
//! and `A x = b` is solved by block elimination: `X_k = A_II,k⁻¹ A_IB,k` (banded LU with partial pivoting,
//! LAPACK `dgbtf2`/`dgbtrs`), the Schur complement `S = A_BB − Σ_k A_BI,k X_k` (a small sparse matrix: a
//! patch couples only its own two ends with the node rows at them) factorised by [`SparseSystem`], then
//! `x_B = S⁻¹ (b_B − Σ_k A_BI,k A_II,k⁻¹ b_I,k)` and `x_I,k = A_II,k⁻¹ b_I,k − X_k x_B,k`.
//!
//! The work is linear in the number of patches (the banded factorisations cost `O(m kl (kl + ku))` each) and the
//! patches are independent, so they are factorised and solved in parallel. The LU pivots within each patch
//! interior only: a patch whose interior block is singular on its own (with its ends held) is reported as a
//! failed factorisation, and the caller falls back to the general sparse LU.

use super::sparse::SparseSystem;
use super::{LinearError, SolverError};
use crate::math::Real;
use rayon::prelude::*;

/// Border columns per patch: the six unknowns of each end's control point.
const END_COLUMNS: usize = 12;

/// A square banded matrix with its LU factors in LAPACK band storage (column-major, `2 kl + ku + 1` rows,
/// `A(i, j)` at row `kl + ku + i − j` of column `j`; the top `kl` rows take the fill of row interchanges).
#[derive(Debug, Clone)]
struct BandLu {
    m: usize,
    kl: usize,
    ku: usize,
    ab: Vec<Real>,
    pivots: Vec<usize>,
}

impl BandLu {
    fn new(m: usize, kl: usize, ku: usize) -> Self {
        Self {
            m,
            kl,
            ku,
            ab: vec![0.0; (2 * kl + ku + 1) * m],
            pivots: vec![0; m],
        }
    }

    fn ld(&self) -> usize {
        2 * self.kl + self.ku + 1
    }

    /// Storage index of `A(i, j)` (`j − ku ≤ i ≤ j + kl`).
    #[inline]
    fn at(&self, i: usize, j: usize) -> usize {
        j * self.ld() + self.kl + self.ku + i - j
    }

    /// In-place LU with partial pivoting (LAPACK `dgbtf2`). `Err(j)` when column `j` has no non-zero pivot.
    fn factor(&mut self) -> Result<(), usize> {
        let (m, kl, ku, ld) = (self.m, self.kl, self.ku, self.ld());
        let kv = kl + ku;
        let ab = &mut self.ab;
        let mut ju = 0;
        for j in 0..m {
            let km = kl.min(m - 1 - j);
            let col = j * ld + kv;
            let mut jp = 0;
            let mut best = ab[col].abs();
            for i in 1..=km {
                let v = ab[col + i].abs();
                if v > best {
                    best = v;
                    jp = i;
                }
            }
            self.pivots[j] = j + jp;
            if best == 0.0 || !best.is_finite() {
                return Err(j);
            }
            ju = ju.max((j + ku + jp).min(m - 1));
            if jp != 0 {
                for c in j..=ju {
                    let base = c * ld + kv;
                    ab.swap(base + j - c, base + j + jp - c);
                }
            }
            let inv = 1.0 / ab[col];
            for v in &mut ab[col + 1..=col + km] {
                *v *= inv;
            }
            if km == 0 {
                continue;
            }
            let (head, tail) = ab.split_at_mut((j + 1) * ld);
            let multipliers = &head[col + 1..=col + km];
            for c in j + 1..=ju {
                let base = (c - j - 1) * ld + kv + j - c;
                let u = tail[base];
                if u != 0.0 {
                    for (t, l) in tail[base + 1..=base + km].iter_mut().zip(multipliers) {
                        *t -= l * u;
                    }
                }
            }
        }
        Ok(())
    }

    /// Solves `A X = B` in place for `B` with `W` columns stored row-major (`b[i * W + q]`), LAPACK `dgbtrs`:
    /// row interchanges and the unit lower triangle column by column, then the upper triangle (bandwidth
    /// `kl + ku`) backwards, each column an `axpy` of `W`-wide rows (`W` fixed so the inner loops unroll; one
    /// right-hand side is the plain vector `axpy`).
    fn solve<const W: usize>(&self, b: &mut [Real]) {
        let (m, kl, ld) = (self.m, self.kl, self.ld());
        let kv = kl + self.ku;
        for j in 0..m.saturating_sub(1) {
            let lm = kl.min(m - 1 - j);
            let p = self.pivots[j];
            if p != j {
                for q in 0..W {
                    b.swap(p * W + q, j * W + q);
                }
            }
            let col = j * ld + kv;
            let (head, tail) = b.split_at_mut((j + 1) * W);
            let bj: [Real; W] = std::array::from_fn(|q| head[j * W + q]);
            let (rows, _) = tail[..lm * W].as_chunks_mut::<W>();
            for (t, l) in rows.iter_mut().zip(&self.ab[col + 1..=col + lm]) {
                for q in 0..W {
                    t[q] -= l * bj[q];
                }
            }
        }
        for j in (0..m).rev() {
            let col = j * ld + kv;
            let inv = 1.0 / self.ab[col];
            let (head, tail) = b.split_at_mut(j * W);
            let bj = &mut tail[..W];
            for v in bj.iter_mut() {
                *v *= inv;
            }
            let len = kv.min(j);
            let bj: [Real; W] = std::array::from_fn(|q| bj[q]);
            let (rows, _) = head[(j - len) * W..].as_chunks_mut::<W>();
            for (t, u) in rows.iter_mut().zip(&self.ab[col - len..col]) {
                for q in 0..W {
                    t[q] -= u * bj[q];
                }
            }
        }
    }
}

/// Scatter list: `(pushed entry, destination index)` pairs (32-bit: half the memory traffic of `usize`).
type Scatter = Vec<(u32, u32)>;

/// Adds the pushed `values` listed in `scatter` into `out`.
#[inline]
fn scatter_add(scatter: &[(u32, u32)], values: &[Real], out: &mut [Real]) {
    for &(e, i) in scatter {
        out[i as usize] += values[e as usize];
    }
}

/// One patch's blocks and factors.
#[derive(Debug, Clone)]
struct PatchBlock {
    /// First global unknown of the interior (its `lu.m` unknowns follow).
    start: usize,
    /// Border index of the patch's first end column (its 12 end columns are consecutive there).
    border: usize,
    lu: BandLu,
    /// `A_IB,k` on assembly, then `X_k = A_II,k⁻¹ A_IB,k` (`m × 12`, row-major).
    x: Vec<Real>,
    /// `A_BI,k` as `(border row, interior column)` with values.
    coupling: Vec<(usize, usize)>,
    coupling_values: Vec<Real>,
    /// Distinct border rows of `coupling` (its block of the Schur complement has 12 entries per row, in
    /// ascending row order), and per coupling entry the position of its row among them.
    rows: usize,
    row_of: Vec<usize>,
    /// Where the pushed entries of `A_II,k` (band storage), `A_IB,k` (`x`) and `A_BI,k` (`coupling_values`) go.
    band_in: Scatter,
    border_in: Scatter,
    coupling_in: Scatter,
}

/// The global system solved by banded patch LUs and a Schur complement on the patch ends.
pub(crate) struct BlockSystem {
    n: usize,
    /// Pushed entries.
    entries: usize,
    /// Where the pushed entries of `A_BB` go in `schur_values`.
    corner_in: Scatter,
    patches: Vec<PatchBlock>,
    /// Global index of each border unknown.
    border: Vec<usize>,
    /// Values of the Schur complement's entries: `A_BB` first, then each patch's `−A_BI,k X_k`.
    schur_values: Vec<Real>,
    corner_entries: usize,
    schur: SparseSystem,
    /// Border right-hand side and solution.
    border_rhs: Vec<Real>,
    factored: bool,
}

impl std::fmt::Debug for BlockSystem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BlockSystem")
            .field("n", &self.n)
            .field("patches", &self.patches.len())
            .field("border", &self.border.len())
            .finish()
    }
}

impl BlockSystem {
    /// Analyses the pattern (`(row, column)` per pushed entry, in assembly order) of an `n × n` system whose
    /// first unknowns are the control points of the patches given as `(first control point, count)`, six
    /// unknowns each; unknowns past them join the border. `None` when the pattern is not block-bordered (an
    /// interior row reaching outside its patch), so the caller uses the general sparse LU.
    pub(crate) fn new(
        n: usize,
        entries: &[(usize, usize)],
        patches: &[(usize, usize)],
    ) -> Result<Option<Self>, SolverError> {
        // Owner of each unknown: Some((patch, local interior index)) or None for the border.
        let mut interior: Vec<Option<(usize, usize)>> = vec![None; n];
        let mut border_index = vec![usize::MAX; n];
        let mut border = Vec::new();
        let mut blocks = Vec::with_capacity(patches.len());
        for (k, &(first, count)) in patches.iter().enumerate() {
            if count < 3 {
                return Ok(None);
            }
            let start = 6 * (first + 1);
            let m = 6 * (count - 2);
            if 6 * (first + count) > n {
                return Ok(None);
            }
            for (i, owner) in interior[start..start + m].iter_mut().enumerate() {
                *owner = Some((k, i));
            }
            let ends = (6 * first..6 * first + 6).chain(start + m..start + m + 6);
            let offset = border.len();
            for g in ends {
                border_index[g] = border.len();
                border.push(g);
            }
            blocks.push((start, m, offset));
        }
        for (g, b) in border_index.iter_mut().enumerate() {
            if *b == usize::MAX && interior[g].is_none() {
                *b = border.len();
                border.push(g);
            }
        }
        // Bandwidths of the interior blocks, and the bordered structure.
        let mut kl = vec![0usize; patches.len()];
        let mut ku = vec![0usize; patches.len()];
        for &(r, c) in entries {
            if r >= n || c >= n {
                return Err(LinearError::EntryOutside {
                    row: r,
                    column: c,
                    size: n,
                }
                .into());
            }
            match (interior[r], interior[c]) {
                (Some((kr, i)), Some((kc, j))) => {
                    if kr != kc {
                        return Ok(None);
                    }
                    kl[kr] = kl[kr].max(i.saturating_sub(j));
                    ku[kr] = ku[kr].max(j.saturating_sub(i));
                }
                (Some((kr, _)), None) => {
                    let b = border_index[c];
                    let own = blocks[kr].2;
                    if b < own || b >= own + END_COLUMNS {
                        return Ok(None);
                    }
                }
                _ => {}
            }
        }
        let mut patch_blocks: Vec<PatchBlock> = blocks
            .iter()
            .enumerate()
            .map(|(k, &(start, m, offset))| PatchBlock {
                start,
                border: offset,
                lu: BandLu::new(m, kl[k], ku[k]),
                x: vec![0.0; m * END_COLUMNS],
                coupling: Vec::new(),
                coupling_values: Vec::new(),
                rows: 0,
                row_of: Vec::new(),
                band_in: Vec::new(),
                border_in: Vec::new(),
                coupling_in: Vec::new(),
            })
            .collect();
        if entries.len() > u32::MAX as usize || n > u32::MAX as usize {
            return Ok(None);
        }
        let mut corner_in = Vec::new();
        let mut schur_entries: Vec<(usize, usize)> = Vec::new();
        for (e, &(r, c)) in entries.iter().enumerate() {
            let e = e as u32;
            match (interior[r], interior[c]) {
                (Some((k, i)), Some((_, j))) => {
                    let at = patch_blocks[k].lu.at(i, j) as u32;
                    patch_blocks[k].band_in.push((e, at));
                }
                (Some((k, i)), None) => {
                    let at = i * END_COLUMNS + border_index[c] - patch_blocks[k].border;
                    patch_blocks[k].border_in.push((e, at as u32));
                }
                (None, Some((k, j))) => {
                    let block = &mut patch_blocks[k];
                    block.coupling.push((border_index[r], j));
                    block
                        .coupling_in
                        .push((e, (block.coupling.len() - 1) as u32));
                }
                (None, None) => {
                    schur_entries.push((border_index[r], border_index[c]));
                    corner_in.push((e, (schur_entries.len() - 1) as u32));
                }
            }
        }
        let corner_entries = schur_entries.len();
        for block in &mut patch_blocks {
            let mut rows: Vec<usize> = block.coupling.iter().map(|&(r, _)| r).collect();
            rows.sort_unstable();
            rows.dedup();
            block.row_of = block
                .coupling
                .iter()
                .map(|&(r, _)| rows.binary_search(&r).unwrap_or(0))
                .collect();
            block.coupling_values = vec![0.0; block.coupling.len()];
            for &r in &rows {
                schur_entries.extend((0..END_COLUMNS).map(|q| (r, block.border + q)));
            }
            block.rows = rows.len();
        }
        let schur = SparseSystem::new(border.len(), &schur_entries)?;
        Ok(Some(Self {
            n,
            entries: entries.len(),
            corner_in,
            patches: patch_blocks,
            schur_values: vec![0.0; schur_entries.len()],
            corner_entries,
            border_rhs: vec![0.0; border.len()],
            border,
            schur,
            factored: false,
        }))
    }

    /// Forgets the factorisation.
    pub(crate) fn invalidate(&mut self) {
        self.factored = false;
    }

    /// True when a factorisation is available for solves.
    pub(crate) fn is_factored(&self) -> bool {
        self.factored
    }

    /// Factorises the matrix whose pushed entries are `entry_values` (in the pattern's assembly order).
    /// `Err(Singular)` when a patch interior or the Schur complement has no pivot.
    pub(crate) fn factor(&mut self, entry_values: &[Real]) -> Result<(), SolverError> {
        assert_eq!(
            entry_values.len(),
            self.entries,
            "one value per pushed entry"
        );
        self.factored = false;
        self.schur_values[..self.corner_entries].fill(0.0);
        scatter_add(&self.corner_in, entry_values, &mut self.schur_values);
        // Per patch (in parallel): its blocks from the pushed entries, the banded LU, X_k = A_II,k⁻¹ A_IB,k, and
        // its block of −A_BI,k X_k.
        let (_, products) = self.schur_values.split_at_mut(self.corner_entries);
        let mut chunks: Vec<&mut [Real]> = Vec::with_capacity(self.patches.len());
        let mut rest = products;
        for block in &self.patches {
            let (head, tail) = rest.split_at_mut(block.rows * END_COLUMNS);
            chunks.push(head);
            rest = tail;
        }
        let failed = self
            .patches
            .par_iter_mut()
            .zip(chunks)
            .find_map_any(|(block, out)| {
                block.lu.ab.fill(0.0);
                scatter_add(&block.band_in, entry_values, &mut block.lu.ab);
                block.x.fill(0.0);
                scatter_add(&block.border_in, entry_values, &mut block.x);
                block.coupling_values.fill(0.0);
                scatter_add(&block.coupling_in, entry_values, &mut block.coupling_values);
                if let Err(j) = block.lu.factor() {
                    return Some(block.start + j);
                }
                block.lu.solve::<END_COLUMNS>(&mut block.x);
                out.fill(0.0);
                for ((&(_, j), &a), &row) in block
                    .coupling
                    .iter()
                    .zip(&block.coupling_values)
                    .zip(&block.row_of)
                {
                    let x = &block.x[j * END_COLUMNS..(j + 1) * END_COLUMNS];
                    for (s, xv) in out[row * END_COLUMNS..(row + 1) * END_COLUMNS]
                        .iter_mut()
                        .zip(x)
                    {
                        *s -= a * xv;
                    }
                }
                None
            });
        if let Some(column) = failed {
            return Err(SolverError::Singular {
                column,
                location: String::new(),
            });
        }
        self.schur.factor(&self.schur_values).map_err(|e| match e {
            // The Schur complement's unknowns are the border's.
            SolverError::Singular { column, location } => SolverError::Singular {
                column: self.border.get(column).copied().unwrap_or(column),
                location,
            },
            e => e,
        })?;
        self.factored = true;
        Ok(())
    }

    /// Solves `A x = b` in place with the last factorisation.
    pub(crate) fn solve_in_place(&mut self, rhs: &mut [Real]) {
        assert!(self.factored, "solve before a successful factorisation");
        // y_k = A_II,k⁻¹ b_I,k, in place in the interior slices of `rhs`.
        let mut slices: Vec<&mut [Real]> = Vec::with_capacity(self.patches.len());
        {
            let mut rest: &mut [Real] = rhs;
            let mut at = 0;
            for block in &self.patches {
                let (_, tail) = rest.split_at_mut(block.start - at);
                let (interior, tail) = tail.split_at_mut(block.lu.m);
                slices.push(interior);
                rest = tail;
                at = block.start + block.lu.m;
            }
        }
        self.patches
            .par_iter()
            .zip(slices.par_iter_mut())
            .for_each(|(block, y)| block.lu.solve::<1>(y));
        // b_B − Σ_k A_BI,k y_k, then x_B = S⁻¹ (…).
        for (b, &g) in self.border_rhs.iter_mut().zip(&self.border) {
            *b = rhs[g];
        }
        for block in &self.patches {
            for (&(r, j), &a) in block.coupling.iter().zip(&block.coupling_values) {
                self.border_rhs[r] -= a * rhs[block.start + j];
            }
        }
        self.schur.solve_in_place(&mut self.border_rhs);

        for (&g, &x) in self.border.iter().zip(&self.border_rhs) {
            rhs[g] = x;
        }
        // x_I,k = y_k − X_k x_B,k.
        for block in &self.patches {
            let xb = &self.border_rhs[block.border..block.border + END_COLUMNS];
            let y = &mut rhs[block.start..block.start + block.lu.m];
            for (i, yi) in y.iter_mut().enumerate() {
                let row = &block.x[i * END_COLUMNS..(i + 1) * END_COLUMNS];
                *yi -= row.iter().zip(xb).map(|(a, b)| a * b).sum::<Real>();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic pseudo-random number in [−1, 1) (xorshift), so the test needs no extra crate.
    fn noise(state: &mut u64) -> Real {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as Real / (1u64 << 52) as Real - 1.0
    }

    #[test]
    fn band_lu_solves_against_the_dense_product() {
        // A random banded matrix that needs pivoting (small diagonal): A x = b for a known x.
        let (m, kl, ku) = (40, 5, 3);
        let mut lu = BandLu::new(m, kl, ku);
        let mut dense = vec![0.0; m * m];
        let mut s = 7u64;
        for j in 0..m {
            for i in j.saturating_sub(ku)..(j + kl + 1).min(m) {
                let v = noise(&mut s) + if i == j { 0.01 } else { 0.0 };
                dense[i * m + j] = v;
                let at = lu.at(i, j);
                lu.ab[at] = v;
            }
        }
        let x: Vec<Real> = (0..m).map(|i| (i as Real * 0.37).sin()).collect();
        let mut b: Vec<Real> = (0..m)
            .map(|i| (0..m).map(|j| dense[i * m + j] * x[j]).sum())
            .collect();
        assert_eq!(lu.factor(), Ok(()));
        let mut wide: Vec<Real> = b.iter().flat_map(|&v| [v, 2.0 * v]).collect();
        lu.solve::<1>(&mut b);
        lu.solve::<2>(&mut wide);
        for (i, v) in b.iter().enumerate() {
            assert!((wide[2 * i] - v).abs() < 1e-12 && (wide[2 * i + 1] - 2.0 * v).abs() < 1e-12);
        }
        let err = b
            .iter()
            .zip(&x)
            .map(|(a, e)| (a - e).abs())
            .fold(0.0, Real::max);
        // Backward-stable elimination: the error is round-off times the condition number (≈1e3 here).
        assert!(err < 1e-10, "error {err:e}");
    }
}
