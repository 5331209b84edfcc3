//! Where the solver's wall time went ([`SolverTiming`]).

use crate::math::Real;
use std::time::Instant;

/// Where the solver's wall time went, with counts (DESIGN §6): residual assemblies, tangent assemblies,
/// factorisations, solves, the per-step material work (history stresses before, internal-variable update
/// after a step), the point terms' own work (contact searches and updates) and the analyses of the linear
/// system's pattern. Counts include the work of abandoned attempts (cut steps, retried reuse).
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
    /// Each point term's own work outside the assembly's loop over points, by the term's name, counted apart
    /// from the parts above: its step hooks (a step's start and end, multiplier updates, step limits: the search
    /// of contact) and its coupled loads (contact between wires, taken out of `residual` and `tangent`) \[s\];
    /// the count is of hooks and coupled assemblies.
    pub terms: Vec<(String, (usize, Real))>,
    /// Analyses of the linear systems' patterns again, when a coupling changed (contact between wires found
    /// or lost) \[s\].
    pub analysis: (usize, Real),
}

impl SolverTiming {
    /// Adds one event that started at `start` to `slot`.
    pub(super) fn add(slot: &mut (usize, Real), start: Instant) {
        slot.0 += 1;
        slot.1 += start.elapsed().as_secs_f64();
    }

    /// Adds `seconds` of the point term `name`'s own work to [`SolverTiming::terms`].
    pub(super) fn add_term(&mut self, name: &str, seconds: Real) {
        let slot = match self.terms.iter().position(|(n, _)| n == name) {
            Some(i) => &mut self.terms[i].1,
            None => {
                self.terms.push((name.to_string(), (0, 0.0)));
                &mut self.terms.last_mut().expect("just pushed").1
            }
        };
        slot.0 += 1;
        slot.1 += seconds;
    }

    /// The split as named entries: `<part>_s` (seconds) and `<part>_count`; a point term's as
    /// `term_<name>_s` with its name's spaces as underscores.
    pub fn entries(&self) -> Vec<(String, Real)> {
        let parts = [
            ("residual", self.residual),
            ("tangent", self.tangent),
            ("factorisation", self.factorisation),
            ("solve", self.solve),
            ("material", self.material),
            ("analysis", self.analysis),
        ];
        let terms =
            (self.terms.iter()).map(|(n, slot)| (format!("term_{}", n.replace(' ', "_")), *slot));
        (parts.iter().map(|(n, slot)| (n.to_string(), *slot)))
            .chain(terms)
            .flat_map(|(name, (count, secs))| {
                [
                    (format!("{name}_s"), secs),
                    (format!("{name}_count"), count as Real),
                ]
            })
            .collect()
    }
}
