//! Generated straight stents for the solver benchmarks (`benches/solver.rs`) and the scaling table
//! (`examples/scaling.rs`): the paper's straight stent built in code (`examples/common/straight_stent.rs`)
//! with its crown count changed, on a moderate mesh so that 64 crowns stay feasible, and a simulation
//! advanced a few steps into the contraction ramp.

#[path = "../../examples/common/straight_stent.rs"]
mod straight_stent;

use std::ops::ControlFlow;
use stentkit::model::Model;
use stentkit::solver::{Observer, Simulation, StepReport};

/// Crown counts benchmarked.
pub const CROWNS: [usize; 4] = [1, 4, 16, 64];
/// Degree and control points per patch of the benchmark stents (the design's own are p = 6, n = 20).
pub const MESH: (usize, usize) = (4, 12);
/// Time step of the benchmark runs [s] (the contraction ramp lasts 1 s).
pub const STEP: f64 = 0.01;
/// Steps taken before measuring, so that the state is deformed and the history non-trivial.
pub const WARM_UP_STEPS: usize = 3;

/// The paper's straight stent with `crowns` crowns on the benchmark mesh and step.
pub fn stent_model(crowns: usize) -> Model {
    straight_stent::straight_stent(crowns, MESH, STEP)
        .build()
        .expect("the generated stent is valid")
        .model
}

/// Stops a run after a given number of steps.
pub struct StopAfter(pub usize);

impl Observer for StopAfter {
    fn step(&mut self, _: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        if report.step >= self.0 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// Stops a run after one more step.
pub struct OneStep;

impl Observer for OneStep {
    fn step(&mut self, _: &Simulation<'_>, _: &StepReport) -> ControlFlow<()> {
        ControlFlow::Break(())
    }
}

/// A simulation of `model` advanced [`WARM_UP_STEPS`] steps into the ramp.
pub fn warmed_up(model: &Model) -> Simulation<'_> {
    let mut sim = Simulation::new(model).expect("simulation");
    sim.run(&mut [&mut StopAfter(WARM_UP_STEPS)])
        .expect("the first steps of the ramp converge");
    sim
}
