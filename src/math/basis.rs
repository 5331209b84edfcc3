//! B-spline and NURBS basis functions and their derivatives (Piegl–Tiller A2.2, A2.3; rational basis by the
//! quotient rule, Piegl–Tiller Eq. 4.2 differentiated as in A4.2).
//!
//! The allocating functions [`bspline_basis`] and [`nurbs_basis`] wrap the `*_into` kernels, which write into
//! a caller's [`BasisTable`] and reuse the scratch of a [`BasisWorkspace`]; once both have grown to the
//! degree and derivative order in use, the kernels allocate nothing.

use super::{KnotVector, Real};

/// The `p + 1` non-zero basis functions at a parameter and their derivatives up to order `nders`.
///
/// `ders[k][j]` is the `k`-th derivative with respect to the curve parameter `u` of the basis function with
/// global index `first + j`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BasisTable {
    /// Global index of the first non-zero basis function (`span − p`).
    pub first: usize,
    /// `ders[k][j]`: `k`-th derivative of basis function `first + j`; `k = 0 … nders`, `j = 0 … p`.
    pub ders: Vec<Vec<Real>>,
}

impl BasisTable {
    /// Resizes to `nders + 1` rows of `p + 1` zeros, keeping the allocations.
    fn reset(&mut self, degree: usize, nders: usize) {
        self.ders.resize_with(nders + 1, Vec::new);
        for row in &mut self.ders {
            row.clear();
            row.resize(degree + 1, 0.0);
        }
    }
}

/// Scratch storage of the basis kernels (the triangular table `ndu`, the coefficient rows `a`, the knot
/// differences `left`/`right` of Piegl–Tiller A2.3, and the weight-function derivatives of the rational
/// basis). Grows on demand; reuse one per thread to make [`bspline_basis_into`] allocation-free.
#[derive(Debug, Clone, Default)]
pub struct BasisWorkspace {
    ndu: Vec<Real>,
    a: Vec<Real>,
    left: Vec<Real>,
    right: Vec<Real>,
    wders: Vec<Real>,
}

impl BasisWorkspace {
    /// An empty workspace (it grows to the degree and derivative order of the first call).
    pub fn new() -> Self {
        Self::default()
    }
}

/// The binomial coefficient `C(n, k)` as a float (exact for the small orders used here).
pub(crate) fn binomial(n: usize, k: usize) -> Real {
    if k > n {
        return 0.0;
    }
    let k = k.min(n - k);
    (0..k).fold(1.0, |c, i| c * (n - i) as Real / (i + 1) as Real)
}

/// Non-zero B-spline basis functions at `u` and their derivatives up to order `nders`
/// (Piegl–Tiller A2.3). Derivatives above the degree are zero. `u` outside the domain is clamped to it
/// (see [`KnotVector::find_span`]).
pub fn bspline_basis(knots: &KnotVector, u: Real, nders: usize) -> BasisTable {
    let mut table = BasisTable::default();
    bspline_basis_into(knots, u, nders, &mut BasisWorkspace::new(), &mut table);
    table
}

/// [`bspline_basis`] writing into `table` (resized to `nders + 1` rows of `p + 1` values) with the scratch of
/// `work` (Piegl–Tiller A2.3: the triangular table of basis functions and knot differences `ndu`, then the
/// derivative coefficients `a_{k,j}` of Eq. 2.10 computed row by row).
pub fn bspline_basis_into(
    knots: &KnotVector,
    u: Real,
    nders: usize,
    work: &mut BasisWorkspace,
    table: &mut BasisTable,
) {
    let p = knots.degree();
    let kn = knots.knots();
    let (lo, hi) = knots.domain();
    let u = if u.is_nan() { lo } else { u.clamp(lo, hi) };
    let span = knots.find_span(u);
    table.first = span - p;
    table.reset(p, nders);

    let w = p + 1;
    work.ndu.clear();
    work.ndu.resize(w * w, 0.0);
    work.left.clear();
    work.left.resize(w, 0.0);
    work.right.clear();
    work.right.resize(w, 0.0);
    let BasisWorkspace {
        ndu,
        a,
        left,
        right,
        ..
    } = work;
    // ndu[j][r] (row j, column r) stored at j * w + r.
    // Upper triangle: basis functions N_{span-p+r, j}; lower triangle: knot differences.
    ndu[0] = 1.0;
    for j in 1..=p {
        left[j] = u - kn[span + 1 - j];
        right[j] = kn[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j * w + r] = right[r + 1] + left[j - r];
            let temp = ndu[r * w + j - 1] / ndu[j * w + r];
            ndu[r * w + j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j * w + j] = saved;
    }
    for j in 0..=p {
        table.ders[0][j] = ndu[j * w + p];
    }

    let nd = nders.min(p);
    if nd == 0 {
        return;
    }
    // Two alternating rows a[s][·] of the coefficients a_{k,j} (Piegl–Tiller Eq. 2.10).
    a.clear();
    a.resize(2 * w, 0.0);
    for r in 0..=p {
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0] = 1.0;
        for k in 1..=nd {
            let mut d = 0.0;
            let rk = r as isize - k as isize;
            let pk = p - k;
            if r >= k {
                let rk = rk as usize;
                a[s2 * w] = a[s1 * w] / ndu[(pk + 1) * w + rk];
                d = a[s2 * w] * ndu[rk * w + pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if r <= pk + 1 { k - 1 } else { p - r };
            for j in j1..=j2 {
                let col = (rk + j as isize) as usize;
                a[s2 * w + j] = (a[s1 * w + j] - a[s1 * w + j - 1]) / ndu[(pk + 1) * w + col];
                d += a[s2 * w + j] * ndu[col * w + pk];
            }
            if r <= pk {
                a[s2 * w + k] = -a[s1 * w + k - 1] / ndu[(pk + 1) * w + r];
                d += a[s2 * w + k] * ndu[r * w + pk];
            }
            table.ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    // Multiply by p! / (p − k)!.
    let mut factor = p as Real;
    for k in 1..=nd {
        for v in &mut table.ders[k] {
            *v *= factor;
        }
        factor *= (p - k) as Real;
    }
}

/// Non-zero NURBS basis functions `R_j = w_j N_j / Σ w_k N_k` at `u` and their derivatives up to order
/// `nders`, from the B-spline table by the quotient (Leibniz) rule.
/// `weights` has one positive weight per basis function.
///
/// With `A_j = w_j N_j` and `W = Σ_j A_j` (Piegl–Tiller Eq. 4.2), differentiating `A_j = W R_j` `k` times gives
/// `R_j^(k) = (A_j^(k) − Σ_{i=1..k} C(k,i) W^(i) R_j^(k−i)) / W`, the same recursion as A4.2 for curves.
///
/// # Panics
/// If `weights.len()` differs from `knots.num_basis()` (a programmer error: curves validate their weights).
#[track_caller]
pub fn nurbs_basis(knots: &KnotVector, weights: &[Real], u: Real, nders: usize) -> BasisTable {
    let mut table = BasisTable::default();
    nurbs_basis_into(
        knots,
        weights,
        u,
        nders,
        &mut BasisWorkspace::new(),
        &mut table,
    );
    table
}

/// [`nurbs_basis`] writing into `table` with the scratch of `work`.
///
/// # Panics
/// If `weights.len()` differs from `knots.num_basis()`.
#[track_caller]
pub fn nurbs_basis_into(
    knots: &KnotVector,
    weights: &[Real],
    u: Real,
    nders: usize,
    work: &mut BasisWorkspace,
    table: &mut BasisTable,
) {
    assert_eq!(
        weights.len(),
        knots.num_basis(),
        "nurbs_basis: one weight per basis function"
    );
    bspline_basis_into(knots, u, nders, work, table);
    let w = &weights[table.first..table.first + knots.degree() + 1];
    // W^(k) = Σ_j w_j N_j^(k).
    work.wders.clear();
    work.wders.extend(
        table
            .ders
            .iter()
            .map(|row| row.iter().zip(w).map(|(n, wj)| n * wj).sum::<Real>()),
    );
    let wd = &work.wders;
    for k in 0..=nders {
        let (done, rest) = table.ders.split_at_mut(k);
        let row = &mut rest[0];
        for (j, v) in row.iter_mut().enumerate() {
            let mut value = w[j] * *v;
            for i in 1..=k {
                value -= binomial(k, i) * wd[i] * done[k - i][j];
            }
            *v = value / wd[0];
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The property-test configuration of the math tests: `cases` cases from a fixed seed, so runs are
    /// reproducible (failures found during development are kept in `proptest-regressions/`). For stress runs,
    /// the environment variables `PROPTEST_CASES` and `PROPTEST_RNG_SEED` override both.
    pub(crate) fn config(cases: u32) -> ProptestConfig {
        let base = ProptestConfig::default();
        let cases = if std::env::var_os("PROPTEST_CASES").is_some() {
            base.cases
        } else {
            cases
        };
        let rng_seed = if std::env::var_os("PROPTEST_RNG_SEED").is_some() {
            base.rng_seed
        } else {
            proptest::test_runner::RngSeed::Fixed(0x5354_454e_544b_4954)
        };
        ProptestConfig {
            cases,
            rng_seed,
            ..base
        }
    }

    /// A random clamped knot vector on `[lo, lo + len]` with interior knots of multiplicity ≤ p
    /// (multiplicities drawn so that the spline keeps at least C^0 continuity).
    pub(crate) fn knot_vector(p: usize, raw: &[(u8, u8)], lo: Real, len: Real) -> KnotVector {
        let mut knots = vec![lo; p + 1];
        let mut vals: Vec<(Real, usize)> = raw
            .iter()
            .map(|&(k, m)| (lo + len * (k as Real + 1.0) / 32.0, 1 + (m as usize) % p))
            .collect();
        vals.sort_by(|a, b| a.0.total_cmp(&b.0));
        vals.dedup_by(|a, b| a.0 == b.0);
        for (u, m) in vals {
            knots.extend(std::iter::repeat_n(u, m));
        }
        knots.extend(vec![lo + len; p + 1]);
        KnotVector::try_new(p, knots).expect("generated knot vector is valid")
    }

    /// Degree 1…8, up to 10 interior knot values (multiplicity 1…p) on a domain `[lo, lo + len]`.
    pub(crate) fn knot_strategy() -> impl Strategy<Value = (usize, Vec<(u8, u8)>, Real, Real)> {
        (
            1usize..=8,
            proptest::collection::vec((0u8..31, 0u8..8), 0..10),
            -2.0..2.0f64,
            0.5..5.0f64,
        )
    }

    /// All basis function derivatives of order k at u, as a dense vector over every basis index.
    fn dense(kv: &KnotVector, w: Option<&[Real]>, u: Real, k: usize) -> Vec<Real> {
        let t = match w {
            Some(w) => nurbs_basis(kv, w, u, k),
            None => bspline_basis(kv, u, k),
        };
        let mut out = vec![0.0; kv.num_basis()];
        for (j, v) in t.ders[k].iter().enumerate() {
            out[t.first + j] = *v;
        }
        out
    }

    // Checks Piegl–Tiller Ex. 2.3 by hand: p = 2, U = {0,0,0,1,2,3,4,4,5,5,5}, u = 5/2 gives
    // N_{2,2} = 1/8, N_{3,2} = 6/8, N_{4,2} = 1/8, and the derivatives (from Eq. 2.9 / the explicit quadratic
    // pieces (u−2)²/2 … ) N' = (−1/2, 0, 1/2), N'' = (1, −2, 1). All values are dyadic, so the tolerance is a
    // few ulps (1e-15).
    #[test]
    fn piegl_tiller_example_2_3() {
        let kv = KnotVector::try_new(2, vec![0., 0., 0., 1., 2., 3., 4., 4., 5., 5., 5.]).unwrap();
        let t = bspline_basis(&kv, 2.5, 3);
        assert_eq!(t.first, 2);
        let expect = [
            [0.125, 0.75, 0.125],
            [-0.5, 0.0, 0.5],
            [1.0, -2.0, 1.0],
            [0.0, 0.0, 0.0],
        ];
        for (k, row) in expect.iter().enumerate() {
            for (j, e) in row.iter().enumerate() {
                assert!(
                    (t.ders[k][j] - e).abs() < 1e-15,
                    "k={k} j={j}: {:?}",
                    t.ders
                );
            }
        }
        // At the right end of the domain the last function is 1 (left limit convention of A2.1).
        let t = bspline_basis(&kv, 5.0, 0);
        assert_eq!(t.first, 5);
        assert_eq!(t.ders[0], vec![0.0, 0.0, 1.0]);
    }

    // Checks the rational quadratic quarter circle by hand: weights (1, 1/√2, 1), no interior knots. At u = 1/2
    // the Bernstein values are (1/4, 1/2, 1/4), W = 1/2 + √2/4, so R_1 = (√2/4)/W; independent closed form.
    // Tolerance 1e-15: a handful of roundings of O(1) values.
    #[test]
    fn nurbs_quarter_circle_by_hand() {
        let kv = KnotVector::clamped_uniform(2, 3).unwrap();
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let t = nurbs_basis(&kv, &[1.0, s, 1.0], 0.5, 0);
        let wsum = 0.5 + s / 2.0;
        let expect = [0.25 / wsum, 0.5 * s / wsum, 0.25 / wsum];
        for (value, e) in t.ders[0].iter().zip(expect) {
            assert!((value - e).abs() < 1e-15);
        }
    }

    proptest! {
        #![proptest_config(config(300))]

        // Checks partition of unity Σ_j N_j = Σ_j R_j = 1 and Σ_j N_j^(k) = Σ_j R_j^(k) = 0 for k = 1…p+2
        // (Piegl–Tiller P2.4 and its derivative; P4.2 for the rational basis) at random u on random clamped
        // vectors of degree 1…8 on non-unit domains, weights in [0.2, 5]. Reference is exact arithmetic; the
        // tolerance 1e-11·max(1, Σ|N^(k)|) allows for the growth of the derivative terms, whose size scales with
        // (p/h)^k and cancels in the sum.
        #[test]
        fn partition_of_unity_and_zero_derivative_sums(
            (p, raw, lo, len) in knot_strategy(),
            t in 0.0..=1.0f64,
            wraw in proptest::collection::vec(0.2..5.0f64, 96),
        ) {
            let kv = knot_vector(p, &raw, lo, len);
            let w = &wraw[..kv.num_basis()];
            let u = lo + t * len;
            let nd = p + 2;
            for table in [bspline_basis(&kv, u, nd), nurbs_basis(&kv, w, u, nd)] {
                prop_assert_eq!(table.ders.len(), nd + 1);
                prop_assert!(table.ders[0].iter().all(|&v| v >= -1e-15));
                for (k, row) in table.ders.iter().enumerate() {
                    let sum: Real = row.iter().sum();
                    let scale: Real = row.iter().map(|v| v.abs()).sum::<Real>().max(1.0);
                    let expect = if k == 0 { 1.0 } else { 0.0 };
                    prop_assert!((sum - expect).abs() <= 1e-11 * scale, "k={} sum={} scale={}", k, sum, scale);
                }
            }
            // Derivatives above the degree of the polynomial basis vanish identically.
            let table = bspline_basis(&kv, u, nd);
            prop_assert!(table.ders[p + 1..].iter().all(|row| row.iter().all(|&v| v == 0.0)));
        }

        // Checks every derivative order k = 1…3 of the B-spline and NURBS basis against a central difference
        // of order k−1 (independent of A2.3's derivative recursion), at u at least 2h away from every knot so
        // the functions are smooth across the stencil. If q bounds the growth per derivative order
        // (|f^(k+1)| ≲ q|f^(k)|; q ≤ p/Δ ≤ 256/len for these polynomial pieces, a few thousand/len for weight
        // ratios up to 25), the relative truncation error is ~ (hq)²/6 and the rounding error ~ ε·len/h.
        // Step h = 1e-6·len makes both ≤ ~1e-7; tolerance 1e-5 × the magnitude max(‖f^(k)‖∞, ‖f^(k−1)‖∞/len).
        #[test]
        fn basis_derivatives_match_central_differences(
            (p, raw, lo, len) in knot_strategy(),
            t in 0.0..=1.0f64,
            wraw in proptest::collection::vec(0.2..5.0f64, 96),
        ) {
            let kv = knot_vector(p, &raw, lo, len);
            let w = &wraw[..kv.num_basis()];
            let h = 1e-6 * len;
            let u = lo + t * len;
            let bps = kv.breakpoints();
            prop_assume!(bps.iter().all(|b| (u - b).abs() > 2.0 * h));
            for weights in [None, Some(w)] {
                for k in 1..=3usize {
                    let fm = dense(&kv, weights, u - h, k - 1);
                    let fp = dense(&kv, weights, u + h, k - 1);
                    let exact = dense(&kv, weights, u, k);
                    let norm = |v: &[Real]| v.iter().fold(0.0, |m: Real, x| m.max(x.abs()));
                    let scale = norm(&exact).max(norm(&fm) / len);
                    for j in 0..kv.num_basis() {
                        let fd = (fp[j] - fm[j]) / (2.0 * h);
                        prop_assert!((fd - exact[j]).abs() <= 1e-5 * scale,
                            "k={} j={} fd={} exact={} scale={}", k, j, fd, exact[j], scale);
                    }
                }
            }
        }
    }

    // Checks the `_into` kernels reuse a table of a different shape and give the same values as the
    // allocating wrappers. Exact equality (same arithmetic).
    #[test]
    fn into_variants_reuse_buffers() {
        let kv = KnotVector::clamped_uniform(4, 9).unwrap();
        let w: Vec<Real> = (0..9).map(|i| 1.0 + 0.1 * i as Real).collect();
        let mut work = BasisWorkspace::new();
        let mut table = BasisTable {
            first: 0,
            ders: vec![vec![7.0; 2]; 6],
        };
        for &u in &[0.0, 0.3, 0.77, 1.0] {
            bspline_basis_into(&kv, u, 2, &mut work, &mut table);
            assert_eq!(table, bspline_basis(&kv, u, 2));
            nurbs_basis_into(&kv, &w, u, 5, &mut work, &mut table);
            assert_eq!(table, nurbs_basis(&kv, &w, u, 5));
        }
    }
}
