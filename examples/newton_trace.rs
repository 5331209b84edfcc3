//! Prints the Newton history (normalised residuals and increments, factorisations) of every k-th step of a run,
//! then the run's totals and the solver's time split: the tool used to tune the chord iterations and the
//! stopping criterion.
//!
//! `cargo run --release --example newton_trace -- designs/curved_stent.yaml 20 0.2`
//! (design, print every k-th step, optional end time).

use anyhow::Context;
use std::ops::ControlFlow;
use std::path::Path;
use stentkit::design::{DesignOverrides, parse_design_with};
use stentkit::solver::{Observer, Simulation, StepReport};

/// Prints every `0`-th step.
struct Trace(usize);

impl Observer for Trace {
    fn step(&mut self, _: &Simulation<'_>, r: &StepReport) -> ControlFlow<()> {
        if r.step.is_multiple_of(self.0) {
            let list = |v: &[f64]| {
                v.iter()
                    .map(|x| format!("{x:.1e}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            println!(
                "step {} t = {:.4}: {} iterations, {} factorisations; residuals {}; increments {}",
                r.step,
                r.time,
                r.newton.iterations,
                r.newton.factorisations,
                list(&r.newton.residuals),
                list(&r.newton.increments)
            );
        }
        ControlFlow::Continue(())
    }
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .context("usage: newton_trace DESIGN [EVERY] [END]")?;
    let every: usize = args.next().map_or(Ok(1), |s| s.parse()).context("EVERY")?;
    let end_time: Option<f64> = args.next().map(|s| s.parse()).transpose().context("END")?;
    let text = std::fs::read_to_string(&path).with_context(|| format!("cannot read {path}"))?;
    let overrides = DesignOverrides {
        end_time,
        ..Default::default()
    };
    let design = parse_design_with(&text, Path::new(&path), &overrides)?;
    let mut sim = Simulation::new(&design.model)?;
    let summary = sim.run(&mut [&mut Trace(every.max(1))])?;
    println!("{summary:?}");
    for (name, value) in sim.timing().entries() {
        println!("{name}: {value:.4}");
    }
    Ok(())
}
