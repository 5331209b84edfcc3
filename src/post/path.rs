//! An arc-length path's limit points in load, read from its sampled increments (`solver: {path: arc-length}`):
//! the stability study's coarse map and the benchmark tests locate the limit loads with it.

use crate::math::Real;

/// The interior local extrema of the load factor along a path sampled as `(path parameter, load factor)`,
/// each refined by the vertex of the parabola through it and its two neighbours (Lagrange interpolation in the
/// path parameter): `(index of the sample, refined load factor)`, in path order. The refinement's error is of
/// the third order in the arc length around the extremum.
pub fn load_extrema(path: &[(Real, Real)]) -> Vec<(usize, Real)> {
    (1..path.len().saturating_sub(1))
        .filter(|&k| (path[k].1 - path[k - 1].1) * (path[k + 1].1 - path[k].1) < 0.0)
        .map(|k| {
            let [(s0, l0), (s1, l1), (s2, _)] = [path[k - 1], path[k], path[k + 1]];
            let d01 = (l1 - l0) / (s1 - s0);
            let d12 = (path[k + 1].1 - l1) / (s2 - s1);
            let a = (d12 - d01) / (s2 - s0);
            let b = d01 - a * (s0 + s1);
            let vertex = -b / (2.0 * a);
            (
                k,
                l0 + d01 * (vertex - s0) + a * (vertex - s0) * (vertex - s1),
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A parabola sampled unevenly has its vertex found exactly (λ = 1 − (s − 0.3)², vertex 1 at s = 0.3), and
    /// a monotone path has no extremum. Source: the interpolating parabola of a parabola is itself; tolerance
    /// round-off.
    #[test]
    fn the_vertex_of_a_sampled_parabola_is_found() {
        let f = |s: Real| 1.0 - (s - 0.3) * (s - 0.3);
        let path: Vec<(Real, Real)> = [0.0, 0.1, 0.25, 0.4, 0.7]
            .iter()
            .map(|&s| (s, f(s)))
            .collect();
        let found = load_extrema(&path);
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].0, 2);
        assert!((found[0].1 - 1.0).abs() < 1e-14, "{}", found[0].1);
        let rising: Vec<(Real, Real)> = (0..5).map(|k| (k as Real, k as Real)).collect();
        assert!(load_extrema(&rising).is_empty());
    }
}
