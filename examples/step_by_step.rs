//! Stepping a simulation as a library (issue 13 item 4): load a model, take steps one at a time and read the
//! state between them, take a checkpoint, go on, restore the checkpoint and continue — and check that the
//! continued run ends exactly where an uninterrupted run does.
//!
//! `cargo run --release --example step_by_step` (about a second).
//!
//! The model is the paper's morphing cantilever (`designs/cantilever_morphing.yaml`: PLA with 15 Maxwell
//! branches and the WLF shift, programmed hot, fixed cold, recovered hot; 3000 steps), read with
//! `parse_design` for now — a `model::builder` will make it in code.

use std::error::Error;
use std::path::Path;
use stentkit::design::parse_design;
use stentkit::math::{Real, Vec3};
use stentkit::model::Model;
use stentkit::solver::Simulation;

/// The largest relative difference allowed between the continued and the uninterrupted run (they are equal
/// bit for bit: a restored simulation repeats the same floating-point operations).
const TOLERANCE: Real = 1e-12;

fn main() -> Result<(), Box<dyn Error>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/cantilever_morphing.yaml");
    let design = parse_design(&std::fs::read_to_string(&path)?, &path)?;
    let model = &design.model;
    let probe = &model.probes[0];
    println!(
        "{}: {} patches, {} unknowns, {} steps to t = {} s; probe `{}`",
        model.name(),
        model.patches.len(),
        model.num_unknowns(),
        design.steps.total(),
        model.time().end,
        probe.name
    );

    // The reference: an uninterrupted run, step by step (`run` would do the same loop).
    let mut reference = Simulation::new(model)?;
    while reference.step()?.is_some() {}

    // Step to t = 1 s (programmed and fixed), reading the state every 250 steps.
    let mut sim = Simulation::new(model)?;
    while sim.time() < 1.0 {
        let Some(report) = sim.step()? else { break };
        if report.step % 250 == 0 {
            let u = sim.probe_displacement(&probe.location);
            println!(
                "  step {:4}  t = {:.3} s  T = {:5.1} °C  {} Newton iterations  {}: u = {}",
                report.step,
                sim.time(),
                report.temperature,
                report.newton.iterations,
                probe.name,
                show(u)
            );
        }
    }
    let checkpoint = sim.checkpoint();
    println!(
        "checkpoint at step {} (t = {} s): {} materials' states, factorisation {}",
        checkpoint.snapshot.clock.step,
        checkpoint.snapshot.clock.time,
        checkpoint.materials.len(),
        if checkpoint.tangent.is_some() {
            "to rebuild"
        } else {
            "none"
        }
    );

    // Go on to t = 2 s: this branch is then thrown away.
    while sim.time() < 2.0 && sim.step()?.is_some() {}
    println!(
        "went on to t = {:.3} s ({}: u = {}); restoring the checkpoint",
        sim.time(),
        probe.name,
        show(sim.probe_displacement(&probe.location))
    );
    sim.restore(&checkpoint)?;
    println!("restored: t = {} s, step {}", sim.time(), sim.step_count());

    // Continue to the end and compare with the uninterrupted run.
    while sim.step()?.is_some() {}
    let (probe_difference, state_difference) = differences(model, &sim, &reference);
    println!(
        "continued to t = {} s: {}: u = {} (uninterrupted: {})",
        sim.time(),
        probe.name,
        show(sim.probe_displacement(&probe.location)),
        show(reference.probe_displacement(&probe.location))
    );
    println!(
        "largest relative difference to the uninterrupted run: probe {probe_difference:.1e}, control points {state_difference:.1e} (tolerance {TOLERANCE:.0e})"
    );
    assert!(probe_difference <= TOLERANCE && state_difference <= TOLERANCE);
    Ok(())
}

/// The relative differences between two simulations of `model`: of the first probe's displacement, and of
/// the control points' displacements (largest over them, relative to the largest displacement).
fn differences(model: &Model, a: &Simulation<'_>, b: &Simulation<'_>) -> (Real, Real) {
    let location = &model.probes[0].location;
    let (ua, ub) = (
        a.probe_displacement(location),
        b.probe_displacement(location),
    );
    let probe = (ua - ub).norm() / ub.norm().max(Real::MIN_POSITIVE);
    let reference = &b.discretisation().control0;
    let (pa, pb) = (&a.state().control, &b.state().control);
    let scale = pb
        .iter()
        .zip(reference)
        .map(|(p, p0)| (p - p0).norm())
        .fold(Real::MIN_POSITIVE, Real::max);
    let state = pa
        .iter()
        .zip(pb)
        .map(|(x, y)| (x - y).norm() / scale)
        .fold(0.0, Real::max);
    (probe, state)
}

/// `(x, y, z)` in scientific notation (the design's length unit).
fn show(u: Vec3) -> String {
    format!("({:+.6e}, {:+.6e}, {:+.6e})", u.x, u.y, u.z)
}
