//! Where the solver's wall time went ([`SolverTiming`]).

use crate::math::Real;
use std::time::Instant;

/// Where the solver's wall time went, with counts (DESIGN §6): residual assemblies, tangent assemblies,
/// factorisations, solves and the per-step material work (history stresses before, internal-variable update
/// after a step). Counts include the work of abandoned attempts (cut steps, retried reuse).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SolverTiming {
    /// Residual-only assemblies and their time \[s\].
    pub residual: (usize, Real),
    /// Residual-and-tangent assemblies and their time \[s\].
    pub tangent: (usize, Real),
    /// Numeric LU factorisations and their time \[s\].
    pub factorisation: (usize, Real),
    /// Solves with a factorisation (forward and back substitution) and their time \[s\].
    pub solve: (usize, Real),
    /// Step preparation (integrator coefficients, history stresses) and commits (internal variables) \[s\].
    pub material: (usize, Real),
}

impl SolverTiming {
    /// Adds one event that started at `start` to `slot`.
    pub(super) fn add(slot: &mut (usize, Real), start: Instant) {
        slot.0 += 1;
        slot.1 += start.elapsed().as_secs_f64();
    }

    /// The split as named entries: `<part>_s` (seconds) and `<part>_count`.
    pub fn entries(&self) -> Vec<(String, Real)> {
        let parts = [
            ("residual", self.residual),
            ("tangent", self.tangent),
            ("factorisation", self.factorisation),
            ("solve", self.solve),
            ("material", self.material),
        ];
        parts
            .iter()
            .flat_map(|(name, (count, secs))| {
                [
                    (format!("{name}_s"), *secs),
                    (format!("{name}_count"), *count as Real),
                ]
            })
            .collect()
    }
}
