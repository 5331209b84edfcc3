//! Knot vectors: validation, clamped (open) construction, span search (Piegl–Tiller A2.1) and Greville
//! abscissae.
//!
//! Nothing here assumes the domain is `[0, 1]`: a validated knot vector may live on any finite interval
//! `[u_p, u_n]` (Piegl–Tiller Ex. 2.3 uses `[0, 5]`). The constructors [`KnotVector::clamped_uniform`] and
//! [`KnotVector::clamped_with_interior`] build the `[0, 1]` vectors the rest of the crate uses.

use super::{MathError, Real};

/// A validated, non-decreasing knot vector of a degree-`p` spline with `n` basis functions
/// (`n + p + 1` knots). Clamped (open): the first and last knots repeat `p + 1` times.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct KnotVector {
    degree: usize,
    knots: Vec<Real>,
}

/// Builds the error value of a failed knot-vector validation.
fn invalid(reason: String) -> MathError {
    MathError::InvalidKnots { reason }
}

impl KnotVector {
    /// Validates a clamped knot vector of degree `degree ≥ 1`: finite, non-decreasing, end knots repeated
    /// exactly `p + 1` times, interior multiplicity ≤ `p`, at least `p + 1` basis functions, non-empty domain.
    ///
    /// These are the assumptions of every algorithm of Piegl–Tiller ch. 2–5 on open (clamped) knot vectors
    /// (Eq. 2.13); the error names the offending knot index and value.
    pub fn try_new(degree: usize, knots: Vec<Real>) -> Result<Self, MathError> {
        let p = degree;
        if p == 0 {
            return Err(invalid("degree must be at least 1, got 0".into()));
        }
        let len = knots.len();
        if len < 2 * (p + 1) {
            return Err(invalid(format!(
                "degree {p} needs at least {} knots (p + 1 basis functions), got {len}",
                2 * (p + 1)
            )));
        }
        if let Some((i, u)) = knots.iter().enumerate().find(|(_, u)| !u.is_finite()) {
            return Err(invalid(format!("knot {i} is not finite ({u})")));
        }
        if let Some(i) = (1..len).find(|&i| knots[i] < knots[i - 1]) {
            return Err(invalid(format!(
                "knots decrease at index {i}: u[{}] = {} > u[{i}] = {}",
                i - 1,
                knots[i - 1],
                knots[i]
            )));
        }
        let (lo, hi) = (knots[0], knots[len - 1]);
        if lo >= hi {
            return Err(invalid(format!("empty domain: all knots equal {lo}")));
        }
        let first = knots.iter().take_while(|&&u| u == lo).count();
        if first != p + 1 {
            return Err(invalid(format!(
                "first knot {lo} repeats {first} times; a clamped degree-{p} vector needs exactly {}",
                p + 1
            )));
        }
        let last = knots.iter().rev().take_while(|&&u| u == hi).count();
        if last != p + 1 {
            return Err(invalid(format!(
                "last knot {hi} repeats {last} times; a clamped degree-{p} vector needs exactly {}",
                p + 1
            )));
        }
        let mut i = p + 1;
        while i < len - p - 1 {
            let run = knots[i..].iter().take_while(|&&u| u == knots[i]).count();
            if run > p {
                return Err(invalid(format!(
                    "interior knot {} (index {i}) repeats {run} times, more than the degree {p}",
                    knots[i]
                )));
            }
            i += run;
        }
        Ok(Self { degree, knots })
    }

    /// The clamped knot vector on `[0, 1]` with `n ≥ p + 1` basis functions and `n − p − 1` uniformly spaced
    /// simple interior knots `i / (n − p)`, `i = 1 … n − p − 1` (Piegl–Tiller Eq. 2.13 with uniform spans).
    pub fn clamped_uniform(degree: usize, n: usize) -> Result<Self, MathError> {
        if n < degree + 1 {
            return Err(invalid(format!(
                "degree {degree} needs at least {} basis functions, asked for {n}",
                degree + 1
            )));
        }
        let spans = n - degree;
        let interior: Vec<Real> = (1..spans).map(|i| i as Real / spans as Real).collect();
        Self::clamped_with_interior(degree, &interior)
    }

    /// The clamped knot vector on `[0, 1]` with the given non-decreasing interior knots in `(0, 1)`: each
    /// entry adds one knot, so a value listed `k ≤ p` times gets multiplicity `k` (Piegl–Tiller Eq. 2.13).
    pub fn clamped_with_interior(degree: usize, interior: &[Real]) -> Result<Self, MathError> {
        if let Some((i, u)) = interior
            .iter()
            .enumerate()
            .find(|(_, u)| !(**u > 0.0 && **u < 1.0))
        {
            return Err(invalid(format!(
                "interior knot {i} = {u} does not lie in (0, 1)"
            )));
        }
        let mut knots = Vec::with_capacity(interior.len() + 2 * (degree + 1));
        knots.extend(std::iter::repeat_n(0.0, degree + 1));
        knots.extend_from_slice(interior);
        knots.extend(std::iter::repeat_n(1.0, degree + 1));
        Self::try_new(degree, knots)
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
    /// returns the last non-empty span (Piegl–Tiller A2.1, by bisection). `u` is clamped into the domain
    /// (a NaN `u` returns the first span).
    pub fn find_span(&self, u: Real) -> usize {
        let p = self.degree;
        let n = self.num_basis();
        let (lo, hi) = self.domain();
        let k = &self.knots;
        // Clamped ends have multiplicity exactly p + 1, so spans p and n − 1 are non-empty.
        if u >= hi {
            return n - 1;
        }
        if u.is_nan() || u <= lo {
            return p;
        }
        // Invariant: k[low] ≤ u < k[high].
        let (mut low, mut high) = (p, n);
        while high - low > 1 {
            let mid = low + (high - low) / 2;
            if u < k[mid] {
                high = mid;
            } else {
                low = mid;
            }
        }
        low
    }

    /// Multiplicity of the knot value `u` (0 if `u` is not a knot), compared exactly.
    pub fn multiplicity(&self, u: Real) -> usize {
        // The knots are sorted: count the run of equal values.
        let start = self.knots.partition_point(|&k| k < u);
        self.knots[start..].iter().take_while(|&&k| k == u).count()
    }

    /// The Greville abscissae `ξ_j = (u_{j+1} + … + u_{j+p}) / p`, `j = 0 … n − 1`: the collocation points
    /// (the knot averages of de Boor, *A Practical Guide to Splines*, ch. XIII; the parameters of the
    /// Schoenberg–Whitney-safe interpolation of Piegl–Tiller §9.2). `ξ_0 = u_p`, `ξ_{n−1} = u_n`, and they
    /// increase strictly because no interior knot repeats more than `p` times.
    pub fn greville(&self) -> Vec<Real> {
        let p = self.degree;
        let (lo, hi) = self.domain();
        // Averaging the offsets from the first knot makes an average of equal knots exact (a plain sum of
        // p copies of u, divided by p, can miss u by an ulp and leave the domain).
        (0..self.num_basis())
            .map(|j| {
                let base = self.knots[j + 1];
                let offset = self.knots[j + 2..=j + p]
                    .iter()
                    .map(|u| u - base)
                    .sum::<Real>()
                    / p as Real;
                (base + offset).clamp(lo, hi)
            })
            .collect()
    }

    /// The distinct knot values (breakpoints) in increasing order.
    pub fn breakpoints(&self) -> Vec<Real> {
        let mut out = self.knots.clone();
        out.dedup();
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    // Checks that bad knot vectors return descriptive errors and never panic. Reference: the definition of a
    // clamped knot vector (Piegl–Tiller Eq. 2.13). Exact checks, no tolerance.
    #[test]
    fn validation_rejects_bad_vectors() {
        let cases: Vec<(usize, Vec<Real>, &str)> = vec![
            (
                2,
                vec![0.0, 0.0, 0.0, 0.6, 0.5, 1.0, 1.0, 1.0],
                "decrease at index 4",
            ),
            (
                2,
                vec![0.0, 0.0, 0.0, Real::NAN, 1.0, 1.0, 1.0],
                "knot 3 is not finite",
            ),
            (
                2,
                vec![0.0, 0.0, 0.0, Real::INFINITY, 1.0, 1.0, 1.0],
                "knot 3 is not finite",
            ),
            (
                2,
                vec![0.0, 0.0, 0.5, 1.0, 1.0, 1.0],
                "first knot 0 repeats 2 times",
            ),
            (
                2,
                vec![0.0, 0.0, 0.0, 0.5, 1.0, 1.0],
                "last knot 1 repeats 2 times",
            ),
            (
                2,
                vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
                "first knot 0 repeats 4 times",
            ),
            (2, vec![0.0, 0.0, 1.0, 1.0], "at least 6 knots"),
            (2, vec![], "at least 6 knots"),
            (2, vec![1.0; 6], "empty domain"),
            (
                2,
                vec![0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0],
                "repeats 3 times, more than the degree",
            ),
            (0, vec![0.0, 1.0], "degree must be at least 1"),
        ];
        for (p, knots, expect) in cases {
            let err = KnotVector::try_new(p, knots.clone()).expect_err("bad vector accepted");
            let msg = err.to_string();
            assert!(
                msg.contains(expect),
                "{knots:?}: got '{msg}', expected '{expect}'"
            );
        }
        assert!(KnotVector::clamped_uniform(3, 3).is_err());
        assert!(KnotVector::clamped_with_interior(2, &[0.0]).is_err());
        assert!(KnotVector::clamped_with_interior(2, &[0.5, Real::NAN]).is_err());
        assert!(KnotVector::clamped_with_interior(2, &[0.7, 0.3]).is_err());
    }

    // Checks the constructors and accessors on hand-written vectors. Reference: Piegl–Tiller Ex. 2.3
    // (U = {0,0,0,1,2,3,4,4,5,5,5}, p = 2) and hand-computed knot averages. Exact (dyadic) values except the
    // Greville averages, compared to 1 ulp-level 1e-15.
    #[test]
    fn hand_checked_spans_multiplicities_greville() {
        let kv = KnotVector::try_new(2, vec![0., 0., 0., 1., 2., 3., 4., 4., 5., 5., 5.]).unwrap();
        assert_eq!(kv.num_basis(), 8);
        assert_eq!(kv.domain(), (0.0, 5.0));
        assert_eq!(kv.find_span(2.5), 4);
        assert_eq!(kv.find_span(0.0), 2);
        assert_eq!(kv.find_span(1.0), 3);
        assert_eq!(kv.find_span(4.0), 7);
        assert_eq!(kv.find_span(5.0), 7);
        assert_eq!(kv.find_span(7.0), 7);
        assert_eq!(kv.find_span(-1.0), 2);
        assert_eq!(kv.find_span(Real::NAN), 2);
        assert_eq!(kv.multiplicity(4.0), 2);
        assert_eq!(kv.multiplicity(0.0), 3);
        assert_eq!(kv.multiplicity(2.5), 0);
        assert_eq!(kv.breakpoints(), vec![0., 1., 2., 3., 4., 5.]);
        let g = kv.greville();
        let expect = [0.0, 0.5, 1.5, 2.5, 3.5, 4.0, 4.5, 5.0];
        for (a, b) in g.iter().zip(expect) {
            assert!((a - b).abs() < 1e-15, "{g:?}");
        }
        let u = KnotVector::clamped_uniform(3, 6).unwrap();
        assert_eq!(u.knots().len(), 10);
        assert_eq!(u.breakpoints(), vec![0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0]);
        let w = KnotVector::clamped_with_interior(3, &[0.25, 0.25, 0.5]).unwrap();
        assert_eq!(w.multiplicity(0.25), 2);
        assert_eq!(w.num_basis(), 7);
    }

    proptest! {
        #![proptest_config(crate::math::basis::tests::config(256))]

        // Checks find_span's defining inequality u_i ≤ u < u_{i+1} (Piegl–Tiller A2.1) against a linear scan, on
        // random clamped vectors with repeated interior knots over a non-unit domain. Exact comparison.
        #[test]
        fn find_span_matches_linear_scan(
            p in 1usize..6,
            raw in proptest::collection::vec(0u8..8, 0..12),
            lo in -3.0..3.0f64,
            len in 0.5..4.0f64,
            t in 0.0..=1.0f64,
        ) {
            let mut interior: Vec<Real> = raw.iter().map(|&k| lo + len * (k as Real + 1.0) / 9.0).collect();
            interior.sort_by(Real::total_cmp);
            // Cap interior multiplicities at p.
            let mut capped: Vec<Real> = Vec::new();
            for u in interior {
                if capped.iter().filter(|&&v| v == u).count() < p {
                    capped.push(u);
                }
            }
            let mut knots = vec![lo; p + 1];
            knots.extend(&capped);
            knots.extend(vec![lo + len; p + 1]);
            let kv = KnotVector::try_new(p, knots).unwrap();
            let k = kv.knots();
            let n = kv.num_basis();
            for u in [lo + t * len, lo, lo + len] {
                let span = kv.find_span(u);
                prop_assert!(span >= p && span < n);
                prop_assert!(k[span] < k[span + 1]);
                if u < lo + len {
                    prop_assert!(k[span] <= u && u < k[span + 1]);
                } else {
                    prop_assert_eq!(span, n - 1);
                }
            }
            let g = kv.greville();
            prop_assert_eq!(g.len(), n);
            prop_assert_eq!(g[0], lo);
            prop_assert_eq!(g[n - 1], lo + len);
            prop_assert!(g.windows(2).all(|w| w[0] < w[1]));
        }
    }
}
