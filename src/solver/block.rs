//! The block-bordered solver of the collocation system (DESIGN §6): a banded LU per patch interior and a sparse
//! LU of the Schur complement on the patch-end unknowns (and any control points coupled across patches).
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
//!
//! **Coupled loads** (contact between wires, [`super::terms`]) make interior rows of one patch reach into
//! another's. The patches so joined are then one block `k` — their interiors renumbered together by reverse
//! Cuthill–McKee, so the band stays narrow where struts lie side by side — and the block's `A_IB,k` has the 12
//! end columns of each of its patches (solved for in groups of 12). The blocks follow a spanning forest of the
//! joins: a join that would close a cycle (the struts of a crown all touching round the ring) moves the control
//! points its rows reach to the border instead (their six unknowns and equations), which the block's rows then
//! reach as extra columns; a ring ordered whole would grow its band from two fronts. Coupling within one patch
//! only widens its band. Measured on the straight stent locked in its crimper (`cargo bench --bench wires`):
//! the quarter model's crowns become blocks of three patches (324 unknowns, half-bandwidths 98 and 92 against
//! 35 for one patch), and the whole bench took 2.70 s against 3.15 s with the general sparse LU (its analysis
//! already deferred, [`super::linear`]).

use super::SolverError;
use super::sparse::{SparseSystem, inside};
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

    /// Solves `A X = B` in place for `B` given as consecutive blocks of `W` columns, each stored row-major
    /// (`b[(g m + i) W + q]` for block `g`), LAPACK `dgbtrs`: row interchanges and the unit lower triangle
    /// column by column, then the upper triangle (bandwidth `kl + ku`) backwards, each column an `axpy` of
    /// `W`-wide rows (`W` fixed so the inner loops unroll; one right-hand side is the plain vector `axpy`).
    /// Every block is updated at each column, so the factors are read once however many blocks there are (a
    /// band larger than the cache would otherwise be streamed from memory once per block). `first` gives, per
    /// block, a row above which its right-hand sides are zero (or is empty): the lower triangle's columns that
    /// reach no row from there on leave the block as it is, and are skipped.
    fn solve<const W: usize>(&self, b: &mut [Real], first: &[usize]) {
        let (m, kl, ld) = (self.m, self.kl, self.ld());
        if m == 0 {
            return;
        }
        let kv = kl + self.ku;
        for j in 0..m - 1 {
            let lm = kl.min(m - 1 - j);
            let p = self.pivots[j];
            let col = j * ld + kv;
            let l = &self.ab[col + 1..=col + lm];
            for (g, block) in b.chunks_exact_mut(m * W).enumerate() {
                // Column j swaps and updates rows j..=j + kl only.
                if first.get(g).is_some_and(|&f| f > j + kl) {
                    continue;
                }
                if p != j {
                    for q in 0..W {
                        block.swap(p * W + q, j * W + q);
                    }
                }
                let (head, tail) = block.split_at_mut((j + 1) * W);
                let bj: [Real; W] = std::array::from_fn(|q| head[j * W + q]);
                let (rows, _) = tail[..lm * W].as_chunks_mut::<W>();
                for (t, l) in rows.iter_mut().zip(l) {
                    for q in 0..W {
                        t[q] -= l * bj[q];
                    }
                }
            }
        }
        for j in (0..m).rev() {
            let col = j * ld + kv;
            let inv = 1.0 / self.ab[col];
            let len = kv.min(j);
            let u = &self.ab[col - len..col];
            for block in b.chunks_exact_mut(m * W) {
                let (head, tail) = block.split_at_mut(j * W);
                let bj = &mut tail[..W];
                for v in bj.iter_mut() {
                    *v *= inv;
                }
                let bj: [Real; W] = std::array::from_fn(|q| bj[q]);
                let (rows, _) = head[(j - len) * W..].as_chunks_mut::<W>();
                for (t, u) in rows.iter_mut().zip(u) {
                    for q in 0..W {
                        t[q] -= u * bj[q];
                    }
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

/// The largest work (`Σ m kl (kl + ku)`, multiply–adds of the banded factorisations) the blocks of coupled
/// patches may take; past it the general sparse LU, whose fill-reducing ordering does not depend on a band, is
/// used instead. Measured on the full straight stent locked in its crimper (12 240 unknowns): blocks of work
/// 1.4e8 took 88 ms per factorisation (with their `X_k`), faer's sparse LU 110 ms; the bound leaves room for
/// blocks a few times larger before the band's cost, growing with its square, passes the sparse LU's.
const MAX_BLOCK_WORK: f64 = 5e8;

/// Reverse Cuthill–McKee ordering of a graph given by its adjacency lists (sorted and deduplicated here): from a
/// pseudo-peripheral start (the last node of a breadth-first search from a node of least degree), breadth-first
/// visiting neighbours by increasing degree, reversed (George & Liu, *Computer Solution of Large Sparse Positive
/// Definite Systems*, 1981, §4.3). It keeps a banded matrix's bandwidth small when its rows are renumbered.
fn reverse_cuthill_mckee(adjacency: &mut [Vec<usize>]) -> Vec<usize> {
    for list in adjacency.iter_mut() {
        list.sort_unstable();
        list.dedup();
    }
    let n = adjacency.len();
    let mut order = Vec::with_capacity(n);
    let mut seen = vec![false; n];
    let mut level = vec![false; n];
    let breadth_first = |start: usize, seen: &mut [bool], out: &mut Vec<usize>| {
        let from = out.len();
        seen[start] = true;
        out.push(start);
        let mut at = from;
        while at < out.len() {
            let v = out[at];
            at += 1;
            let mut next: Vec<usize> = adjacency[v].iter().copied().filter(|&w| !seen[w]).collect();
            next.sort_by_key(|&w| adjacency[w].len());
            for w in next {
                seen[w] = true;
                out.push(w);
            }
        }
    };
    while let Some(least) = (0..n)
        .filter(|&v| !seen[v])
        .min_by_key(|&v| adjacency[v].len())
    {
        level.copy_from_slice(&seen);
        let mut probe = Vec::new();
        breadth_first(least, &mut level, &mut probe);
        let start = probe.last().copied().unwrap_or(least);
        breadth_first(start, &mut seen, &mut order);
    }
    order.reverse();
    order
}

/// One block's matrices and factors: a patch's, or several coupled patches'.
#[derive(Debug, Clone)]
struct Block {
    /// Global index of each interior unknown, in the band's order (its patches' interior control points but
    /// those moved to the border).
    unknowns: Vec<usize>,
    lu: BandLu,
    /// Border index of each border column the interior rows reach (`A_IB,k`: its patches' end columns and any
    /// other), ascending.
    columns: Vec<usize>,
    /// `A_IB,k` on assembly, then `X_k = A_II,k⁻¹ A_IB,k`, in groups of [`END_COLUMNS`] columns (group `g`
    /// holds `columns[12 g..12 g + 12]`, zero-padded, `m × 12` row-major) so each group is one banded solve.
    x: Vec<Real>,
    /// Per column group of `x`, its first row with an entry of `A_IB,k` (`m` for none).
    x_first: Vec<usize>,
    /// `A_BI,k` as `(border row, interior column)` with values.
    coupling: Vec<(usize, usize)>,
    coupling_values: Vec<Real>,
    /// Distinct border rows of `coupling` (its block of the Schur complement has one entry per row and
    /// column of `columns`, in ascending row order), and per coupling entry the position of its row among
    /// them.
    rows: usize,
    row_of: Vec<usize>,
    /// Where the pushed entries of `A_II,k` (band storage), `A_IB,k` (`x`) and `A_BI,k` (`coupling_values`) go.
    band_in: Scatter,
    border_in: Scatter,
    coupling_in: Scatter,
    /// The interior's share of a right-hand side, then of the solution.
    y: Vec<Real>,
}

impl Block {
    /// Number of column groups of `x`.
    fn groups(&self) -> usize {
        self.columns.len().div_ceil(END_COLUMNS)
    }

    /// `X_k`'s row `i` within column group `g`.
    fn x_row(&self, g: usize, i: usize) -> &[Real] {
        let at = (g * self.lu.m + i) * END_COLUMNS;
        &self.x[at..at + END_COLUMNS]
    }
}

/// The global system solved by banded LUs of the blocks and a Schur complement on the border.
pub(crate) struct BlockSystem {
    n: usize,
    /// Pushed entries.
    entries: usize,
    /// Where the pushed entries of `A_BB` go in `schur_values`.
    corner_in: Scatter,
    blocks: Vec<Block>,
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
            .field("blocks", &self.blocks.len())
            .field("border", &self.border.len())
            .finish()
    }
}

impl BlockSystem {
    /// Analyses the pattern (`(row, column)` per pushed entry, in assembly order) of an `n × n` system whose
    /// first unknowns are the control points of the patches given as `(first control point, count)`, six
    /// unknowns each; unknowns past them join the border. Patches whose interiors reach each other (coupled
    /// loads, module docs) are one block. The control points `border_points` (the objective rotation field's
    /// patch references, whose rotation columns every row of their patch reaches) join the border with their six
    /// unknowns and equations. `None` when the patches cannot be blocked (a patch of fewer than three control
    /// points, or past the unknowns) or a coupled block would cost more than [`MAX_BLOCK_WORK`] to factorise, so
    /// the caller uses the general sparse LU.
    pub(crate) fn new(
        n: usize,
        entries: &[(usize, usize)],
        patches: &[(usize, usize)],
        border_points: &[usize],
    ) -> Result<Option<Self>, SolverError> {
        if entries.len() > u32::MAX as usize || n > u32::MAX as usize {
            return Ok(None);
        }
        // The patch of each unknown in a patch interior.
        let mut patch_of: Vec<Option<usize>> = vec![None; n];
        for (k, &(first, count)) in patches.iter().enumerate() {
            if count < 3 || 6 * (first + count) > n {
                return Ok(None);
            }
            patch_of[6 * (first + 1)..6 * (first + count - 1)].fill(Some(k));
        }
        for &j in border_points {
            if 6 * j + 6 > n {
                return Ok(None);
            }
            patch_of[6 * j..6 * j + 6].fill(None);
        }
        // Blocks: the patches joined by interior rows reaching another patch's interior, along a spanning forest
        // of those joins (union–find); a join that would close a cycle (a ring of struts touching all round)
        // moves the control points it reaches to the border instead, so a block is a tree of patches whose band
        // grows from one end instead of two fronts.
        let mut joins = Vec::new();
        for &(r, c) in entries {
            inside(n, r, c)?;
            if let (Some(a), Some(b)) = (patch_of[r], patch_of[c])
                && a != b
            {
                joins.push((a.min(b), a.max(b)));
            }
        }
        joins.sort_unstable();
        joins.dedup();
        let mut parent: Vec<usize> = (0..patches.len()).collect();
        fn root(parent: &mut [usize], mut k: usize) -> usize {
            while parent[k] != k {
                parent[k] = parent[parent[k]];
                k = parent[k];
            }
            k
        }
        let mut cuts = Vec::new();
        for &(a, b) in &joins {
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            if ra == rb {
                cuts.push((a, b));
            } else {
                parent[ra.max(rb)] = ra.min(rb);
            }
        }
        if !cuts.is_empty() {
            for &(r, c) in entries {
                if let (Some(a), Some(b)) = (patch_of[r], patch_of[c])
                    && cuts.binary_search(&(a.min(b), a.max(b))).is_ok()
                {
                    patch_of[c - c % 6..c - c % 6 + 6].fill(None);
                }
            }
        }
        let mut block_of = vec![usize::MAX; patches.len()];
        let mut members: Vec<Vec<usize>> = Vec::new();
        for k in 0..patches.len() {
            let r = root(&mut parent, k);
            if block_of[r] == usize::MAX {
                block_of[r] = members.len();
                members.push(Vec::new());
            }
            block_of[k] = block_of[r];
            members[block_of[k]].push(k);
        }
        // Each block's interior unknowns in the band's order: one patch's in their own order, coupled patches'
        // by reverse Cuthill–McKee over their control points.
        let interior_of = |k: usize| 6 * (patches[k].0 + 1)..6 * (patches[k].0 + patches[k].1 - 1);
        // The control points of coupled blocks (block, local index) and their graph, in one pass.
        let mut slot: Vec<Option<(usize, usize)>> = vec![None; n / 6];
        let mut graphs: Vec<(Vec<usize>, Vec<Vec<usize>>)> =
            vec![Default::default(); members.len()];
        for (b, ks) in members.iter().enumerate().filter(|(_, ks)| ks.len() > 1) {
            let points = &mut graphs[b].0;
            for g in ks.iter().flat_map(|&k| interior_of(k).step_by(6)) {
                if patch_of[g].is_none() {
                    continue;
                }
                slot[g / 6] = Some((b, points.len()));
                points.push(g / 6);
            }
            graphs[b].1 = vec![Vec::new(); points.len()];
        }
        for &(r, c) in entries {
            if let (Some(Some((b, i))), Some(Some((_, j)))) = (slot.get(r / 6), slot.get(c / 6))
                && i != j
            {
                graphs[*b].1[*i].push(*j);
                graphs[*b].1[*j].push(*i);
            }
        }
        let orders: Vec<Vec<usize>> = (members.iter().zip(graphs))
            .map(|(ks, (points, mut adjacency))| match ks.as_slice() {
                [k] => interior_of(*k).filter(|&g| patch_of[g].is_some()).collect(),
                _ => reverse_cuthill_mckee(&mut adjacency)
                    .into_iter()
                    .flat_map(|i| 6 * points[i]..6 * points[i] + 6)
                    .collect(),
            })
            .collect();
        // Owner of each unknown: Some((block, local interior index)) or None for the border; the border
        // numbers each patch's two ends first (12 consecutive columns), then every other unknown left.
        let mut interior: Vec<Option<(usize, usize)>> = vec![None; n];
        for (b, order) in orders.iter().enumerate() {
            for (i, &g) in order.iter().enumerate() {
                interior[g] = Some((b, i));
            }
        }
        let mut border_index = vec![usize::MAX; n];
        let mut border = Vec::new();
        for &(first, count) in patches {
            let ends = 6 * first..6 * first + 6;
            for g in ends.chain(6 * (first + count - 1)..6 * (first + count)) {
                border_index[g] = border.len();
                border.push(g);
            }
        }
        for (g, b) in border_index.iter_mut().enumerate() {
            if *b == usize::MAX && interior[g].is_none() {
                *b = border.len();
                border.push(g);
            }
        }
        // Bandwidths of the interior blocks, and the border columns each reaches (its patches' ends at least).
        let mut kl = vec![0usize; orders.len()];
        let mut ku = vec![0usize; orders.len()];
        let mut columns: Vec<Vec<usize>> = (members.iter())
            .map(|ks| {
                ks.iter()
                    .flat_map(|&k| END_COLUMNS * k..END_COLUMNS * (k + 1))
                    .collect()
            })
            .collect();
        for &(r, c) in entries {
            match (interior[r], interior[c]) {
                (Some((b, i)), Some((_, j))) => {
                    kl[b] = kl[b].max(i.saturating_sub(j));
                    ku[b] = ku[b].max(j.saturating_sub(i));
                }
                (Some((b, _)), None) => columns[b].push(border_index[c]),
                _ => {}
            }
        }
        let work: f64 = (orders.iter().enumerate())
            .filter(|(b, _)| members[*b].len() > 1)
            .map(|(b, o)| o.len() as f64 * kl[b] as f64 * (kl[b] + ku[b]) as f64)
            .sum();
        if work > MAX_BLOCK_WORK {
            return Ok(None);
        }
        let mut blocks: Vec<Block> = orders
            .into_iter()
            .zip(columns)
            .enumerate()
            .map(|(b, (unknowns, mut columns))| {
                columns.sort_unstable();
                columns.dedup();
                let m = unknowns.len();
                let groups = columns.len().div_ceil(END_COLUMNS);
                Block {
                    unknowns,
                    lu: BandLu::new(m, kl[b], ku[b]),
                    x: vec![0.0; groups * m * END_COLUMNS],
                    x_first: vec![m; groups],
                    columns,
                    coupling: Vec::new(),
                    coupling_values: Vec::new(),
                    rows: 0,
                    row_of: Vec::new(),
                    band_in: Vec::new(),
                    border_in: Vec::new(),
                    coupling_in: Vec::new(),
                    y: vec![0.0; m],
                }
            })
            .collect();
        let mut corner_in = Vec::new();
        let mut schur_entries: Vec<(usize, usize)> = Vec::new();
        for (e, &(r, c)) in entries.iter().enumerate() {
            let e = e as u32;
            match (interior[r], interior[c]) {
                (Some((b, i)), Some((_, j))) => {
                    let at = blocks[b].lu.at(i, j) as u32;
                    blocks[b].band_in.push((e, at));
                }
                (Some((b, i)), None) => {
                    let block = &mut blocks[b];
                    let q = block.columns.binary_search(&border_index[c]).unwrap_or(0);
                    let at = (q / END_COLUMNS * block.lu.m + i) * END_COLUMNS + q % END_COLUMNS;
                    block.border_in.push((e, at as u32));
                    let first = &mut block.x_first[q / END_COLUMNS];
                    *first = (*first).min(i);
                }
                (None, Some((b, j))) => {
                    let block = &mut blocks[b];
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
        for block in &mut blocks {
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
                schur_entries.extend(block.columns.iter().map(|&c| (r, c)));
            }
            block.rows = rows.len();
        }
        let schur = SparseSystem::new(border.len(), &schur_entries)?;
        Ok(Some(Self {
            n,
            entries: entries.len(),
            corner_in,
            blocks,
            schur_values: vec![0.0; schur_entries.len()],
            corner_entries,
            border_rhs: vec![0.0; border.len()],
            border,
            schur,
            factored: false,
        }))
    }

    /// Number of border unknowns (the Schur complement's size) and of blocks.
    #[cfg(test)]
    fn sizes(&self) -> (usize, usize) {
        (self.border.len(), self.blocks.len())
    }

    /// Whether some block's column solves skip columns of the lower triangle (a group's first entry below the
    /// band's reach from the top).
    #[cfg(test)]
    fn skips(&self) -> bool {
        (self.blocks.iter()).any(|b| b.x_first.iter().any(|&f| f > b.lu.kl))
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
        // Per block (in parallel): its matrices from the pushed entries, the banded LU, X_k = A_II,k⁻¹ A_IB,k, and
        // its block of −A_BI,k X_k.
        let (_, products) = self.schur_values.split_at_mut(self.corner_entries);
        let mut chunks: Vec<&mut [Real]> = Vec::with_capacity(self.blocks.len());
        let mut rest = products;
        for block in &self.blocks {
            let (head, tail) = rest.split_at_mut(block.rows * block.columns.len());
            chunks.push(head);
            rest = tail;
        }
        let failed = self
            .blocks
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
                    return Some(block.unknowns[j]);
                }
                block.lu.solve::<END_COLUMNS>(&mut block.x, &block.x_first);
                out.fill(0.0);
                let width = block.columns.len();
                for ((&(_, j), &a), &row) in block
                    .coupling
                    .iter()
                    .zip(&block.coupling_values)
                    .zip(&block.row_of)
                {
                    let out_row = &mut out[row * width..(row + 1) * width];
                    for (g, s) in out_row.chunks_mut(END_COLUMNS).enumerate() {
                        for (s, xv) in s.iter_mut().zip(block.x_row(g, j)) {
                            *s -= a * xv;
                        }
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
        // y_k = A_II,k⁻¹ b_I,k, in each block's buffer.
        {
            let b: &[Real] = rhs;
            self.blocks.par_iter_mut().for_each(|block| {
                for (y, &g) in block.y.iter_mut().zip(&block.unknowns) {
                    *y = b[g];
                }
                block.lu.solve::<1>(&mut block.y, &[]);
            });
        }
        // b_B − Σ_k A_BI,k y_k, then x_B = S⁻¹ (…).
        for (b, &g) in self.border_rhs.iter_mut().zip(&self.border) {
            *b = rhs[g];
        }
        for block in &self.blocks {
            for (&(r, j), &a) in block.coupling.iter().zip(&block.coupling_values) {
                self.border_rhs[r] -= a * block.y[j];
            }
        }
        self.schur.solve_in_place(&mut self.border_rhs);
        for (&g, &x) in self.border.iter().zip(&self.border_rhs) {
            rhs[g] = x;
        }
        // x_I,k = y_k − X_k x_B,k.
        let mut xb = Vec::new();
        for block in &self.blocks {
            xb.clear();
            xb.extend(block.columns.iter().map(|&c| self.border_rhs[c]));
            xb.resize(block.groups() * END_COLUMNS, 0.0);
            for (i, (&y, &g)) in block.y.iter().zip(&block.unknowns).enumerate() {
                let mut v = y;
                for (q, xb) in xb.chunks_exact(END_COLUMNS).enumerate() {
                    v -= block
                        .x_row(q, i)
                        .iter()
                        .zip(xb)
                        .map(|(a, b)| a * b)
                        .sum::<Real>();
                }
                rhs[g] = v;
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
        lu.solve::<1>(&mut b, &[]);
        lu.solve::<2>(&mut wide, &[]);
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

    /// A collocation-like system of three patches joined at nodes, with a gauge multiplier, and coupled loads:
    /// interior rows of one patch reaching another patch's interior and ends, and one reaching far along its
    /// own patch. The block solver must solve the system
    /// exactly as the general sparse LU (faer's, an independent factorisation) does, with the coupled patches
    /// as one block.
    #[test]
    fn coupled_patches_solve_as_the_sparse_lu_does() {
        // Patches of 9, 8 and 10 control points, joined end to end by node rows reaching both ends; one
        // multiplier after the 6 · 27 control unknowns.
        let patches: [(usize, usize); 3] = [(0, 9), (9, 8), (17, 10)];
        let n = 6 * 27 + 1;
        let mut entries = Vec::new();
        for &(first, count) in &patches {
            // Each control point's six rows reach the points within two of it in its patch.
            for a in first..first + count {
                for b in a.saturating_sub(2).max(first)..(a + 3).min(first + count) {
                    for (r, c) in (0..6).flat_map(|r| (0..6).map(move |c| (r, c))) {
                        entries.push((6 * a + r, 6 * b + c));
                    }
                }
            }
        }
        for (a, b) in [(8, 9), (16, 17)] {
            for (r, c) in (0..6).flat_map(|r| (0..6).map(move |c| (r, c))) {
                entries.push((6 * a + r, 6 * b + c));
                entries.push((6 * b + r, 6 * a + c));
            }
        }
        // The multiplier: a row reaching patch 2's first end, and its column in that end's rows.
        for q in 0..6 {
            entries.push((n - 1, 6 * 17 + q));
            entries.push((6 * 17 + q, n - 1));
        }
        let coupling_from = entries.len();
        // Coupled loads: points 3 and 4 (patch 0) with 12 and 13 (patch 1) both ways, point 5 with patch 2's
        // end 26, and point 19 with point 24 of its own patch (far outside its band).
        for (a, b) in [(3, 12), (4, 13), (3, 13), (5, 26), (19, 24)] {
            for (r, c) in (0..6).flat_map(|r| (0..6).map(move |c| (r, c))) {
                entries.push((6 * a + r, 6 * b + c));
                entries.push((6 * b + r, 6 * a + c));
            }
        }
        let mut s = 11u64;
        let mut values: Vec<Real> = entries
            .iter()
            .map(|&(r, c)| noise(&mut s) + if r == c { 8.0 } else { 0.0 })
            .collect();
        // The multiplier's diagonal stays zero (a saddle point, as the gauge's).
        for (v, &(r, c)) in values.iter_mut().zip(&entries) {
            if r == n - 1 && c == n - 1 {
                *v = 0.0;
            }
        }
        let b: Vec<Real> = (0..n).map(|i| (i as Real * 0.61).cos()).collect();
        let solve = |entries: &[(usize, usize)], values: &[Real]| {
            let mut block = BlockSystem::new(n, entries, &patches, &[])
                .expect("analysed")
                .expect("blocked");
            block.factor(values).expect("factored");
            let mut x = b.clone();
            block.solve_in_place(&mut x);
            let mut sparse = SparseSystem::new(n, entries).expect("analysed");
            sparse.factor(values).expect("factored");
            let mut y = b.clone();
            sparse.solve_in_place(&mut y);
            let diff = x
                .iter()
                .zip(&y)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, Real::max);
            let size = y.iter().map(|v| v.abs()).fold(0.0, Real::max);
            (diff / size, block.sizes(), block.skips())
        };
        let (uncoupled, sizes, _) = solve(&entries[..coupling_from], &values[..coupling_from]);
        // Both solvers are backward stable on this well-conditioned system: round-off times a small factor.
        assert!(uncoupled < 1e-12, "relative difference {uncoupled:e}");
        assert_eq!(
            sizes,
            (6 * 6 + 1, 3),
            "six ends and the multiplier; a block per patch"
        );
        let (coupled, sizes, _) = solve(&entries, &values);
        assert!(coupled < 1e-12, "relative difference {coupled:e}");
        // Patches 0 and 1 are one block now (their interiors reach each other); patch 2's coupling reaches its
        // own end (an extra border column for patch 0's block) and far along its own band.
        assert_eq!(sizes, (6 * 6 + 1, 2));
        // A ring: patch 2's interior joins both others' too (points 20–6 and 21–14); the join that closes the
        // cycle moves the points its interior rows reach to the border, and one block of all three is left.
        let mut ring = entries.clone();
        for (a, b) in [(20, 6), (21, 14)] {
            for (r, c) in (0..6).flat_map(|r| (0..6).map(move |c| (r, c))) {
                ring.push((6 * a + r, 6 * b + c));
                ring.push((6 * b + r, 6 * a + c));
            }
        }
        let values: Vec<Real> = (ring.iter())
            .map(|&(r, c)| match (r, c) {
                _ if r == n - 1 && c == n - 1 => 0.0,
                _ => noise(&mut s) + if r == c { 8.0 } else { 0.0 },
            })
            .collect();
        let (ringed, sizes, skips) = solve(&ring, &values);
        assert!(ringed < 1e-12, "relative difference {ringed:e}");
        // Joins (0, 1), (0, 2) make the tree; (1, 2) is cut: the first of its entries moves point 14 (reached from
        // 21's rows), and 21, reached then only from the border's rows, stays.
        assert_eq!(
            sizes,
            (6 * 6 + 1 + 6, 1),
            "one point of the last join moved"
        );
        // The ring's block orders some patch ends past the band's reach from the top: its column solves skip
        // the lower triangle's first columns there, and still agree with the sparse LU.
        assert!(skips, "the ring's column solves skip nothing");
    }
}
