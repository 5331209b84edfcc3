//! One run of a model sampled for a study: the displacement on a grid of equally spaced parameters per patch,
//! with the run's wall time and the solver's totals.

use crate::math::{Real, Vec3};
use crate::model::{Model, ProbeLocation};
use crate::solver::{RunSummary, Simulation, SolverError};
use std::time::Instant;

/// A finished run sampled on the study grid.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledRun {
    /// Displacements at `samples` equally spaced parameters per patch, patch by patch \[length\].
    pub grid: Vec<Vec3>,
    /// Wall time of the run (discretisation, analysis and time stepping) \[s\].
    pub wall: Real,
    /// The solver's totals (steps, Newton iterations, cuts, factorisations).
    pub summary: RunSummary,
    /// Unknowns of the global system.
    pub unknowns: usize,
}

/// Runs `model` to its end time and samples the displacement at `samples` equally spaced parameters per patch.
///
/// # Errors
/// The solver's, when the run fails.
pub fn sample_run(model: &Model, samples: usize) -> Result<SampledRun, SolverError> {
    let started = Instant::now();
    let mut sim = Simulation::new(model)?;
    let summary = sim.run(&mut [])?;
    let wall = started.elapsed().as_secs_f64();
    let grid = (0..model.patches.len())
        .flat_map(|patch| {
            (0..samples).map(move |k| ProbeLocation::Patch {
                patch,
                u: k as Real / (samples.max(2) - 1) as Real,
            })
        })
        .map(|loc| sim.probe_displacement(&loc))
        .collect();
    Ok(SampledRun {
        grid,
        wall,
        summary,
        unknowns: model.num_unknowns(),
    })
}
