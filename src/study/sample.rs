//! One run of a model sampled for a study: the displacement on a grid of equally spaced parameters per patch
//! at the end ([`sample_run`]), or the watched quantities — displacements at chosen locations, the recovery
//! measures, optionally the grid — at every record time ([`watched_run`]); with the run's wall time and the
//! solver's totals.

use crate::math::{Real, Vec3};
use crate::model::{Model, ProbeLocation};
use crate::post::recovery::{Recovery, recovery};
use crate::solver::{Observer, RunSummary, Simulation, SolverError, StepReport};
use std::ops::ControlFlow;
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
    let grid = grid_locations(model, samples)
        .map(|loc| sim.probe_displacement(&loc))
        .collect();
    Ok(SampledRun {
        grid,
        wall,
        summary,
        unknowns: model.num_unknowns(),
    })
}

/// `samples` equally spaced parameters on every patch, patch by patch.
pub fn grid_locations(model: &Model, samples: usize) -> impl Iterator<Item = ProbeLocation> + '_ {
    (0..model.patches.len()).flat_map(move |patch| {
        (0..samples).map(move |k| ProbeLocation::Patch {
            patch,
            u: k as Real / (samples.max(2) - 1) as Real,
        })
    })
}

/// The length of the shortest patch at each node, along its control polygon (at least the arc length, and not
/// zero for a closed patch): a node's translation over it is the translation part of Newton's normalised norm,
/// in which the time-error estimate is measured.
pub fn node_lengths(model: &Model) -> Vec<Real> {
    model
        .nodes
        .iter()
        .map(|node| {
            node.ends
                .iter()
                .map(|e| {
                    let points = model.patches[e.patch].curve.points();
                    points
                        .windows(2)
                        .map(|w| (w[1] - w[0]).norm())
                        .sum::<Real>()
                })
                .fold(Real::INFINITY, Real::min)
        })
        .collect()
}

/// The watched quantities of a run at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct Watched {
    /// The time \[time\].
    pub time: Real,
    /// Displacements at the watched locations, in their order \[length\].
    pub displacements: Vec<Vec3>,
    /// The recovery measures, for a model with a programme.
    pub recovery: Option<Recovery>,
    /// The displacement on the study grid (empty unless asked for) \[length\].
    pub grid: Vec<Vec3>,
}

/// A run watched at its record times.
#[derive(Debug, Clone, PartialEq)]
pub struct WatchedRun {
    /// One per record time the run reached, in order.
    pub states: Vec<Watched>,
    /// Wall time of the run \[s\].
    pub wall: Real,
    /// The stabilisation's warnings at the end ([`Simulation::stabilisation_warnings`]: the damping carried the
    /// load or dissipated more than its limit — a fold or snap the run did not pass quasi-statically — or could
    /// not be scaled); empty when it did not warn.
    pub stabilised: Vec<String>,
    /// The solver's totals.
    pub summary: RunSummary,
}

/// Runs `model` to its end time and records, at each of its record times ([`Model::record_times`]: fixed steps
/// land on them, an error-controlled run reaches them by its continuous extension), the displacements at
/// `locations`, the recovery measures and, with `grid_samples`, the grid.
///
/// # Errors
/// The solver's, when the run fails.
pub fn watched_run(
    model: &Model,
    locations: &[ProbeLocation],
    grid_samples: Option<usize>,
) -> Result<WatchedRun, SolverError> {
    // The model holds its record times sorted.
    let times = model.record_times();
    let started = Instant::now();
    let mut sim = Simulation::new(model)?;
    let mut watch = Watch {
        times,
        locations,
        grid_samples,
        states: Vec::new(),
    };
    let summary = sim.run(&mut [&mut watch])?;
    Ok(WatchedRun {
        states: watch.states,
        wall: started.elapsed().as_secs_f64(),
        stabilised: sim.stabilisation_warnings(),
        summary,
    })
}

/// Records the watched quantities when a run reaches each of `times`.
struct Watch<'a> {
    times: &'a [Real],
    locations: &'a [ProbeLocation],
    grid_samples: Option<usize>,
    states: Vec<Watched>,
}

impl Watch<'_> {
    fn record(&mut self, sim: &Simulation<'_>) {
        let t = sim.time();
        // Fixed steps land on record times, error-controlled runs report them between their steps (the continuous
        // extension); the tolerance only absorbs the rounding of the accumulated time.
        let eps = 1e-9 * sim.model().time().end.max(1.0);
        while let Some(&target) = self.times.get(self.states.len()) {
            if t + eps < target {
                break;
            }
            self.states.push(Watched {
                time: target,
                displacements: self
                    .locations
                    .iter()
                    .map(|l| sim.probe_displacement(l))
                    .collect(),
                recovery: recovery(sim),
                grid: self.grid_samples.map_or_else(Vec::new, |samples| {
                    grid_locations(sim.model(), samples)
                        .map(|l| sim.probe_displacement(&l))
                        .collect()
                }),
            });
        }
    }
}

impl Observer for Watch<'_> {
    fn start(&mut self, sim: &Simulation<'_>) -> ControlFlow<()> {
        self.record(sim);
        ControlFlow::Continue(())
    }

    fn step(&mut self, sim: &Simulation<'_>, _: &StepReport) -> ControlFlow<()> {
        self.record(sim);
        ControlFlow::Continue(())
    }

    fn requested(&mut self, sim: &Simulation<'_>, _: &StepReport) {
        self.record(sim);
    }
}
