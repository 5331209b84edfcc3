//! Thermo-viscoelastic rods (issue 4): a rod problem with an independent answer under time-varying temperature,
//! and the paper's cantilever cycle.

use std::ops::ControlFlow;
use std::path::Path;
use stentkit::material::{
    CircularSection, Integrator, Material, MaterialLaw, Prony, PronyBranch, Wlf,
};
use stentkit::math::so3::log;
use stentkit::math::{Real, Rot3, Vec3};
use stentkit::model::builder::{ConditionSpec, ModelBuilder, PatchShape, TimeSpec};
use stentkit::model::{Model, TimeFunction};
use stentkit::solver::{Observer, Simulation, StepReport};

/// A straight PLA cantilever (L = 1 m along x, d = 0.05 m, paper Table PLA and WLF row 1) under a dead end
/// couple about z and the programme of `scripts/maxwell_bending_reference.py`.
fn bending_model(integrator: Integrator, step: Real) -> Model {
    // Paper Table PLA in Pa (van Manen et al. 2021): [E_α, τ_G,α].
    const TABLE: [(Real, Real); 15] = [
        (20.12e6, 1.0e-10),
        (50.31e6, 1.0e-9),
        (81.37e6, 1.0e-8),
        (97.02e6, 1.0e-7),
        (173.70e6, 1.0e-6),
        (225.60e6, 1.0e-5),
        (292.64e6, 1.0e-4),
        (474.56e6, 1.0e-3),
        (449.43e6, 1.0e-2),
        (237.98e6, 1.0e-1),
        (114.16e6, 1.0e+0),
        (51.82e6, 1.0e+1),
        (29.98e6, 1.0e+2),
        (14.40e6, 1.0e+3),
        (0.72e6, 1.0e+5),
    ];
    let branches = TABLE
        .iter()
        .map(|&(modulus, tau_g)| PronyBranch { modulus, tau_g })
        .collect();
    let prony = Prony::try_new(80.59e6, branches).expect("valid Prony series");
    let wlf = Wlf::try_new(14.59, 48.43, 70.0).expect("valid WLF constants");
    let material = Material::try_new(prony, 0.33, Some(wlf)).expect("valid material");
    let wire = CircularSection::try_new(0.05).expect("d > 0");
    let law = MaterialLaw::from_material(material, integrator);
    let mut b = ModelBuilder::new("bending", law, wire.into());
    let beam = PatchShape::Line {
        from: Vec3::zeros(),
        to: Vec3::x(),
    };
    b.patch("beam", beam, 6, 16);
    b.condition(ConditionSpec::clamp("beam.start"));
    let table = |points: &[(Real, Real)]| TimeFunction::try_table(points.to_vec()).expect("table");
    let couple = table(&[(0.0, 0.0), (0.5, 10.0), (0.75, 10.0), (1.0, 0.0)]);
    b.condition(ConditionSpec::at("beam.end").with_moment(2, couple));
    b.temperature(table(&[
        (0.0, 90.0),
        (0.5, 90.0),
        (0.75, 31.5),
        (1.625, 31.5),
        (2.5, 90.0),
    ]));
    b.time(TimeSpec::new(3.0, step));
    b.build().expect("valid model").model
}

/// Reads `(t, κ)` from the reference CSV.
fn reference() -> Vec<(Real, Real)> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/maxwell_bending_reference.csv");
    std::fs::read_to_string(path)
        .expect("reference data")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("time"))
        .map(|l| {
            let (t, k) = l.split_once(',').expect("two columns");
            (t.parse().expect("time"), k.parse().expect("kappa"))
        })
        .collect()
}

/// Records the curvature `κ = φ_tip / L` (tip rotation about z over the length) at every step.
struct Curvature {
    tip_point: usize,
    samples: Vec<(Real, Real)>,
}

impl Observer for Curvature {
    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        let g = self.tip_point;
        let r = sim.state().rotation[g] * sim.discretisation().points[g].rotation0.transpose();
        let phi = log(&Rot3::from_matrix_unchecked(r));
        self.samples.push((report.time, phi.z));
        ControlFlow::Continue(())
    }
}

fn run(integrator: Integrator, step: Real) -> Vec<(Real, Real)> {
    let model = bending_model(integrator, step);
    let mut sim = Simulation::new(&model).expect("simulation");
    let tip_point = sim.discretisation().points.len() - 1;
    let mut obs = Curvature {
        tip_point,
        samples: Vec::new(),
    };
    sim.run(&mut [&mut obs]).expect("run completes");
    obs.samples
}

/// Largest |κ_rod − κ_ref| over the reference times the run landed on, relative to max |κ_ref|.
fn error(samples: &[(Real, Real)], reference: &[(Real, Real)]) -> Real {
    let kmax = reference.iter().fold(0.0_f64, |m, r| m.max(r.1.abs()));
    let mut worst: Real = 0.0;
    for &(t, k) in samples {
        let i = (t / 1e-3).round() as usize;
        if (reference[i].0 - t).abs() < 1e-9 {
            worst = worst.max((k - reference[i].1).abs());
        }
    }
    worst / kmax
}

// Source: pure bending of a straight cantilever under a dead end couple has uniform curvature, and the section
// law reduces to the 1-D generalized Maxwell model with the WLF shift (paper §2.2); its curvature history
// through loading at 90 °C, cooling to 31.5 °C under load, release and re-heating is the solution of a linear
// stiff ODE, integrated independently by scripts/maxwell_bending_reference.py (scipy Radau, rtol 1e-12; two
// tolerances agree to 2e-11 relative). The rod (p = 6, n = 16: the spatial error of the bent shape is ~1e-6
// relative, measured) must reproduce it up to its time-discretisation error, which must fall as h is halved
// (2, 1, 0.5 ms). Measured errors (max over the run, relative to max κ): trapezoidal 1.2e-4, 5.0e-5, 5.2e-6;
// exponential 1.1e-4, 3.5e-5, 1.1e-5; backward Euler 2.5e-3, 1.3e-3, 6.4e-4 (order 0.99). The second-order
// rules show order reduction (1.3–3.3 per halving) because during cooling the relaxation rates change by
// decades within one step; we assert an average order of at least 1.5 for them and 1 ± 0.1 for backward
// Euler, and finest errors below 2e-5 (second order) and 1e-3 (backward Euler): far below what a wrong
// history term, shift or integrator coefficient produces (errors of order 1e-2 to 1).
#[test]
fn pure_bending_follows_the_one_dimensional_maxwell_law_through_a_shape_memory_cycle() {
    let reference = reference();
    let steps = [2e-3, 1e-3, 5e-4];
    for (integrator, bound) in [
        (Integrator::Trapezoidal, 2e-5),
        (Integrator::Exponential, 2e-5),
        (Integrator::BackwardEuler, 1e-3),
    ] {
        let errors: Vec<Real> = steps
            .iter()
            .map(|&h| error(&run(integrator, h), &reference))
            .collect();
        eprintln!("{integrator:?}: errors at h = {steps:?}: {errors:?}");
        assert!(
            errors.windows(2).all(|w| w[1] < w[0]),
            "{integrator:?}: errors must fall with h: {errors:?}"
        );
        let average_order = (errors[0] / errors[2]).log2() / 2.0;
        if integrator == Integrator::BackwardEuler {
            assert!(
                (average_order - 1.0).abs() < 0.1,
                "backward Euler order {average_order:.2}"
            );
        } else {
            assert!(
                average_order >= 1.5,
                "{integrator:?}: average order {average_order:.2}"
            );
        }
        assert!(
            errors[2] < bound,
            "{integrator:?}: error {:.3e} at h = 0.5 ms",
            errors[2]
        );
    }
}

/// Records the tip displacement magnitude at every step.
struct TipHistory(Vec<(Real, Real)>);

impl Observer for TipHistory {
    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        let probe = &sim.model().probes[0];
        self.0
            .push((report.time, sim.probe_displacement(&probe.location).norm()));
        ControlFlow::Continue(())
    }
}

// Source: paper §4.2 — the cantilever is programmed hot under a tip force and couple, fixed by cooling, released
// and recovers its permanent shape on re-heating ("the beam initial shape is fully recovered"). The issue asks
// that the tip come back to within 1 % of its programmed maximum displacement; we also check that the
// temporary shape is held (the tip keeps more than 90 % of its maximum between release and re-heating, when the
// material is glassy: τ at 31.5 °C is ~1e56 τ_G, so nothing relaxes). Design: designs/cantilever_morphing.yaml.
#[test]
fn the_cantilever_is_programmed_holds_its_temporary_shape_and_recovers() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/cantilever_morphing.yaml");
    let design = stentkit::io::design::load_design(&path).expect("design loads");
    let mut sim = Simulation::new(&design.model).expect("simulation");
    let mut tip = TipHistory(Vec::new());
    let summary = sim.run(&mut [&mut tip]).expect("run completes");
    let max = tip.0.iter().fold(0.0_f64, |m, s| m.max(s.1));
    let held = tip
        .0
        .iter()
        .filter(|s| (1.0..=1.625).contains(&s.0))
        .fold(Real::INFINITY, |m, s| m.min(s.1));
    let last = tip.0.last().expect("steps").1;
    eprintln!(
        "cantilever: {} steps, {} Newton iterations; max tip displacement {max:.4} m, held {held:.4} m, final {last:.3e} m ({:.3} %)",
        summary.steps,
        summary.iterations,
        100.0 * last / max
    );
    assert!(
        max > 0.3,
        "the programming load bends the beam substantially (max {max})"
    );
    assert!(held > 0.9 * max, "temporary shape held: {held} of {max}");
    assert!(last < 0.01 * max, "recovery to within 1 %: {last} of {max}");
}
