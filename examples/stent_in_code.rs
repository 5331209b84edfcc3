//! The straight stent of paper §4.3.1 built in Rust, without a design file: six crowns of radius 20 mm and
//! amplitude 5 mm, spaced 15 mm and twisted by 90°, straight bridges at every crest, a quarter model, PLA of
//! van Manen et al. (2021), contracted radially by Δr = 15 mm, cooled, released and re-heated.
//!
//! It runs the model built in code and the same device from `designs/straight_stent.yaml`, and prints the final
//! mean radial contraction Δr of both: they are the same model, so they agree to round-off (the example fails
//! unless they agree to 1e-12 relative).
//!
//! ```text
//! cargo run --release --example stent_in_code
//! ```

use std::path::Path;
use stentkit::geometry::stent::{
    BridgeShape, BridgeSpec, CentrelineSpec, CrownSpec, StentSpec, Symmetry,
};
use stentkit::material::{CircularSection, Integrator, Material};
use stentkit::math::{Real, Vec3};
use stentkit::model::builder::{ModelBuilder, TimeSpec};
use stentkit::model::stent::{ProgrammeSpec, ProgrammeTarget, StentMesh};
use stentkit::model::{Model, TimeFunction, Units};
use stentkit::solver::Simulation;
use stentkit::solver::simulation::NoObserver;

/// The straight stent of paper §4.3.1, in millimetres, newtons and megapascals.
fn straight_stent() -> Result<Model, Box<dyn std::error::Error>> {
    let material = Material::pla_van_manen_2021();
    let wire = CircularSection::try_new(0.6)?; // diameter [mm]
    let mut b = ModelBuilder::new(
        "straight_stent",
        material,
        Integrator::Trapezoidal,
        wire.into(),
    );
    b.units(Units::MmNMpa);
    b.stent(
        StentSpec {
            crown: CrownSpec {
                radius: 20.0,
                amplitude: 5.0,
                peaks: 6,
            },
            crowns: 6,
            spacing: Some(15.0),
            rotation: 90.0_f64.to_radians(),
            bridges: Some(BridgeSpec {
                shape: BridgeShape::Straight,
                every: 1,
                first: 0,
            }),
            centreline: CentrelineSpec::Straight {
                origin: Vec3::zeros(),
                direction: Vec3::x(),
                reference: Some(Vec3::y()),
            },
            symmetry: Symmetry::Quarter,
            cut: true,
        },
        StentMesh {
            crown: (6, 20),
            bridge: (6, 20),
        },
    );
    b.programme(ProgrammeSpec {
        target: ProgrammeTarget::RadialContraction { delta_r: 15.0 },
        node_set: "all_joints".into(),
        ramp: (0.0, 1.0),
        release: Some(1.75),
    });
    // Held hot while programmed, cooled while held, re-heated after the release (°C).
    b.temperature(TimeFunction::try_table(vec![
        (0.0, 90.0),
        (1.0, 90.0),
        (1.75, 45.0),
        (3.16876, 90.0),
        (3.25, 90.0),
    ])?);
    b.time(TimeSpec::new(3.25, 2.5e-3));
    let built = b.build()?;
    for w in &built.warnings {
        eprintln!("warning: {w}");
    }
    Ok(built.model)
}

/// Runs a model to its end and returns the final Δr (mean radial contraction of the driven nodes) [mm].
fn final_delta_r(model: &Model) -> Result<Real, Box<dyn std::error::Error>> {
    let mut sim = Simulation::new(model)?;
    sim.run(&mut NoObserver)?;
    let recovery = stentkit::io::state::recovery(&sim).ok_or("the model has no programme")?;
    Ok(recovery.delta_r.ok_or("the programme is not a radial contraction")?)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let in_code = straight_stent()?;
    println!(
        "built in code: {} patches, {} nodes, {} unknowns",
        in_code.patches.len(),
        in_code.nodes.len(),
        in_code.num_unknowns()
    );
    let delta_code = final_delta_r(&in_code)?;
    println!("final Δr, model built in code:      {delta_code:.15e} mm");

    let design = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/straight_stent.yaml");
    let from_yaml = stentkit::io::design::load_design(&design)?.model;
    let delta_yaml = final_delta_r(&from_yaml)?;
    println!("final Δr, designs/straight_stent.yaml: {delta_yaml:.15e} mm");

    let difference = (delta_code - delta_yaml).abs() / delta_yaml.abs();
    println!("relative difference: {difference:.3e}");
    if difference > 1e-12 {
        return Err(format!("the two models differ: relative difference {difference:.3e} > 1e-12").into());
    }
    Ok(())
}
