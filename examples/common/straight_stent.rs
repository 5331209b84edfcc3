//! The straight stent of paper §4.3.1 built in Rust (shared by `examples/stent_in_code.rs`, the solver
//! benchmarks and `examples/scaling.rs`, which include this file with `#[path]`): six crowns of radius 20 mm
//! and amplitude 5 mm, spaced 15 mm and twisted by 90°, straight bridges at every crest, a quarter model, PLA
//! of van Manen et al. (2021), contracted radially by Δr = 15 mm over 1 s, cooled from 90 °C to 45 °C while
//! held, released at 1.75 s and re-heated — the values of designs/straight_stent.yaml, whose comments say
//! where each comes from.

use stentkit::geometry::stent::{
    BridgeShape, BridgeSpec, CentrelineSpec, CrownShape, CrownSpec, StentSpec, Symmetry,
};
use stentkit::material::{CircularSection, Integrator, Material, MaterialLaw};
use stentkit::math::Vec3;
use stentkit::model::builder::{ModelBuilder, TimeSpec};
use stentkit::model::stent::{ProgrammeSpec, ProgrammeTarget, StentMesh};
use stentkit::model::{RotationField, SolverSettings, TimeFunction, Units};

/// The paper's straight stent with `crowns` crowns, every wire of degree `p` with `n` control points, time
/// step `step` [s] (the paper: 6 crowns, p = 6, n = 20, 2.5e-3 s) and the paper's rotation field, ready to build
/// or to change further.
pub fn straight_stent(crowns: usize, (p, n): (usize, usize), step: f64) -> ModelBuilder {
    let wire = CircularSection::try_new(0.6).expect("a 0.6 mm wire is a valid section"); // diameter [mm]
    let mut b = ModelBuilder::new(
        "straight_stent",
        MaterialLaw::from_material(Material::pla_van_manen_2021(), Integrator::Trapezoidal),
        wire.into(),
    );
    b.units(Units::MmNMpa);
    b.stent(
        std::sync::Arc::new(StentSpec {
            crown: CrownSpec {
                radius: 20.0,
                amplitude: 5.0,
                peaks: 6,
                shape: CrownShape::Sinusoidal,
            },
            crowns,
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
            crown_radii: None,
        }),
        StentMesh {
            crown: (p, n),
            bridge: (p, n),
        },
    );
    b.programme(ProgrammeSpec {
        target: ProgrammeTarget::RadialContraction { delta_r: 15.0 },
        node_set: "all_joints".into(),
        ramp: (0.0, 1.0),
        release: Some(1.75),
    });
    // Held hot while programmed, cooled while held, re-heated after the release (°C).
    b.temperature(
        TimeFunction::try_table(vec![
            (0.0, 90.0),
            (1.0, 90.0),
            (1.75, 45.0),
            (3.16876, 90.0),
            (3.25, 90.0),
        ])
        .expect("the table's times increase"),
    );
    b.time(TimeSpec::new(3.25, step));
    // The paper's rotation field, as the design names it (docs/choices.md, *Rotation field*).
    b.solver(SolverSettings {
        rotations: RotationField::Incremental,
        ..SolverSettings::default()
    });
    b
}
