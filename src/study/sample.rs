//! One run of a design sampled for a study: the displacement on a grid of equally spaced parameters per patch,
//! with the run's wall time and the solver's totals.

use super::StudyError;
use crate::io::design::{DesignOverrides, parse_design_with};
use crate::math::{Real, Vec3};
use crate::model::ProbeLocation;
use crate::solver::simulation::NoObserver;
use crate::solver::{RunSummary, Simulation};
use std::path::Path;
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

/// Runs `text` (a design; `path` names it in errors) with `overrides` to its (overridden) end time and samples
/// the displacement at `samples` equally spaced parameters per patch.
pub fn sample_run(
    text: &str,
    path: &Path,
    overrides: &DesignOverrides,
    samples: usize,
) -> Result<SampledRun, StudyError> {
    let design = parse_design_with(text, path, overrides)?;
    let model = &design.model;
    let started = Instant::now();
    let mut sim = Simulation::new(model)?;
    let summary = sim.run(&mut NoObserver)?;
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
