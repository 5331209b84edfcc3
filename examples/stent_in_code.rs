//! The straight stent of paper §4.3.1 built in Rust, without a design file: six crowns of radius 20 mm and
//! amplitude 5 mm, spaced 15 mm and twisted by 90°, straight bridges at every crest, a quarter model, PLA of
//! van Manen et al. (2021), contracted radially by Δr = 15 mm, cooled, released and re-heated.
//!
//! The model is built in `examples/common/straight_stent.rs` (shared with the benchmarks). The example runs
//! the model built in code and the same device from `designs/straight_stent.yaml`, and prints the final
//! mean radial contraction Δr of both: they are the same model, so they agree to round-off (the example fails
//! unless they agree to 1e-12 relative).
//!
//! ```text
//! cargo run --release --example stent_in_code
//! ```

#[path = "common/straight_stent.rs"]
mod straight_stent;

use std::path::Path;
use stentkit::math::Real;
use stentkit::model::Model;
use stentkit::solver::Simulation;

/// Runs a model to its end and returns the final Δr (mean radial contraction of the driven nodes) [mm].
fn final_delta_r(model: &Model) -> Result<Real, Box<dyn std::error::Error>> {
    let mut sim = Simulation::new(model)?;
    sim.run(&mut [])?;
    let recovery = stentkit::post::recovery::recovery(&sim).ok_or("the model has no programme")?;
    Ok(recovery
        .delta_r
        .ok_or("the programme is not a radial contraction")?)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The whole model is built in examples/common/straight_stent.rs.
    let built = straight_stent::straight_stent(6, (6, 20), 2.5e-3).build()?;
    for w in &built.warnings {
        eprintln!("warning: {w}");
    }
    let in_code = built.model;
    println!(
        "built in code: {} patches, {} nodes, {} unknowns",
        in_code.patches.len(),
        in_code.nodes.len(),
        in_code.num_unknowns()
    );
    let delta_code = final_delta_r(&in_code)?;
    println!("final Δr, model built in code:      {delta_code:.15e} mm");

    let design = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/straight_stent.yaml");
    let from_yaml = stentkit::design::load_design(&design)?.model;
    println!(
        "the two models are {}",
        if in_code == from_yaml {
            "identical"
        } else {
            "different"
        }
    );
    let delta_yaml = final_delta_r(&from_yaml)?;
    println!("final Δr, designs/straight_stent.yaml: {delta_yaml:.15e} mm");

    let difference = (delta_code - delta_yaml).abs() / delta_yaml.abs();
    println!("relative difference: {difference:.3e}");
    if difference > 1e-12 {
        return Err(
            format!("the two models differ: relative difference {difference:.3e} > 1e-12").into(),
        );
    }
    Ok(())
}
