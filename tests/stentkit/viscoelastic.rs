//! Thermo-viscoelastic rods (issue 4): a rod problem with an independent answer under time-varying temperature,
//! and the paper's cantilever cycle.

use std::ops::ControlFlow;
use std::path::Path;
use stentkit::material::{
    CircularSection, Integrator, Material, MaterialLaw, Prony, PronyBranch, Wlf,
};
use stentkit::math::so3::log;
use stentkit::math::{Real, Rot3, Vec3};
use stentkit::model::builder::{
    BuildError, ConditionSpec, Field, ModelBuilder, NodeEnds, PatchShape, TimeField, TimeSpec,
};
use stentkit::model::{Model, Profile, TemperatureField, TimeFunction};
use stentkit::solver::{Observer, Simulation, StepReport};

/// A straight PLA cantilever (L = 1 m along x, d = 0.05 m, paper Table PLA and WLF row 1) under a dead end
/// couple about z and the programme of `scripts/maxwell_bending_reference.py`.
fn bending_model(integrator: Integrator, step: Real) -> Model {
    bending_model_with(integrator, TimeSpec::new(3.0, step))
}

/// [`bending_model`] with the given time stepping.
fn bending_model_with(integrator: Integrator, time: TimeSpec) -> Model {
    bending_model_result(integrator, time).expect("valid model")
}

/// The model of [`bending_model_with`], or the builder's error.
fn bending_model_result(integrator: Integrator, time: TimeSpec) -> Result<Model, BuildError> {
    let prony = pla_prony(1.0);
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
    b.time(time);
    b.build().map(|built| built.model)
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

/// Records the curvature `κ = φ_tip / L` (tip rotation about z over the length) at every step, and apart at
/// every requested time an error-controlled run reaches by its continuous extension.
struct Curvature {
    tip_point: usize,
    samples: Vec<(Real, Real)>,
    requested: Vec<(Real, Real)>,
}

impl Curvature {
    fn kappa(&self, sim: &Simulation<'_>) -> Real {
        let g = self.tip_point;
        let r = sim.state().rotation[g] * sim.discretisation().points[g].rotation0.transpose();
        log(&Rot3::from_matrix_unchecked(r)).z
    }
}

impl Observer for Curvature {
    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        self.samples.push((report.time, self.kappa(sim)));
        ControlFlow::Continue(())
    }

    fn requested(&mut self, sim: &Simulation<'_>, report: &StepReport) {
        assert_eq!(report.time, sim.time());
        self.requested.push((report.time, self.kappa(sim)));
    }
}

fn run(integrator: Integrator, step: Real) -> Vec<(Real, Real)> {
    run_model(&bending_model(integrator, step))
}

fn run_model(model: &Model) -> Vec<(Real, Real)> {
    run_model_with_requested(model).0
}

/// `(time, value)` samples of a run.
type Samples = Vec<(Real, Real)>;

/// The samples of [`run_model`] at the steps, and at the requested times reached between them.
fn run_model_with_requested(model: &Model) -> (Samples, Samples) {
    let mut sim = Simulation::new(model).expect("simulation");
    let tip_point = sim.discretisation().points.len() - 1;
    let mut obs = Curvature {
        tip_point,
        samples: Vec::new(),
        requested: Vec::new(),
    };
    sim.run(&mut [&mut obs]).expect("run completes");
    (obs.samples, obs.requested)
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

// Source: the same stiff-ODE reference as above (scripts/maxwell_bending_reference.py, scipy Radau at rtol 1e-12), now
// for error-controlled steps. The estimate is normalised as Newton's increments: for this rod of length L = 1 the tip
// rotation φ = κ L is in radians, so the error measured is |φ − κ_ref L|. It is measured at every 20 ms (150 times, the
// reference's own samples), asked of the run as record times: an error-controlled run does not land on them but reaches
// each by the continuous extension of the step that holds it (dense output, issue 36 item 3; module docs of
// `solver::simulation::dense`). The error of the rod itself (p = 6, n = 16) is ~1e-6 of κ_max (0.39). An estimator that
// under-reports, or an extension that loses the method's accuracy between steps, is a defect: the error at every
// requested time must be at most the tolerance asked, at every tolerance (measured with the paper's rotation field:
// 0.26, 0.20, 0.31 of it at 1e-3, 1e-4, 1e-5 when the steps landed on these times; from the extension, 146 of the 150
// states, 0.40, 0.20, 0.28; with the objective field, the default since 2026-11-28, from the extension 0.61, 0.19,
// 0.37), and error control must pay: far fewer steps than the 3000 fixed steps of 1 ms. The requested times must not
// change the steps: the accepted states are the same, bit for bit, as a run asking for none. For comparison the test
// prints the error of the accepted steps interpolated linearly at the same times (what a reader of history.csv without
// the extension would get: measured 0.94, 0.46, 0.39 of the tolerance with the paper's field, 1.44, 0.50, 0.42 with the
// objective one). The other updates have no estimate that holds this (backward Euler measured 3–45 times the tolerance,
// the exponential update 1.2–2.3 times, before they were refused, `Integrator::companion`): a design asking for both
// gets a located error.
#[test]
fn error_controlled_steps_keep_the_bending_error_below_the_tolerance() {
    let reference = reference();
    let every = 20;
    let record: Vec<Real> = reference
        .iter()
        .step_by(every)
        .skip(1)
        .map(|r| r.0)
        .collect();
    let at_reference = |t: Real| {
        let i = (t / 1e-3).round() as usize;
        assert!((reference[i].0 - t).abs() < 1e-9, "t = {t} off the grid");
        reference[i].1
    };
    for tolerance in [1e-3, 1e-4, 1e-5] {
        let time = TimeSpec::new(3.0, 1e-3).with_tolerance(tolerance);
        let plain = bending_model_with(Integrator::Trapezoidal, time);
        let model = plain
            .clone()
            .with_record_times(record.clone())
            .expect("record times within the run");
        let (steps, requested) = run_model_with_requested(&model);
        assert_eq!(
            steps,
            run_model(&plain),
            "the requested times changed the steps"
        );
        let landed = steps
            .iter()
            .filter(|s| record.iter().any(|&r| (r - s.0).abs() < 1e-9))
            .count();
        assert_eq!(
            requested.len() + landed,
            record.len(),
            "every record time is reached once, by a step or by the extension"
        );
        let mut error: Real = 0.0;
        let mut interpolated: Real = 0.0;
        for &r in &record {
            let k = (requested.iter().chain(&steps))
                .find(|s| (s.0 - r).abs() < 1e-9)
                .expect("reached")
                .1;
            error = error.max((k - at_reference(r)).abs());
            let after = steps.partition_point(|s| s.0 < r);
            let (a, b) = (steps[after - 1], steps[after]);
            let linear = a.1 + (b.1 - a.1) * (r - a.0) / (b.0 - a.0);
            interpolated = interpolated.max((linear - at_reference(r)).abs());
        }
        println!(
            "tolerance {tolerance:e}: {} steps, {} states from the extension; error over the tolerance at the {} \
             requested times {:.2} (the steps interpolated linearly {:.2})",
            steps.len(),
            requested.len(),
            record.len(),
            error / tolerance,
            interpolated / tolerance
        );
        assert!(
            requested.len() > record.len() / 2,
            "the steps landed on most requested times"
        );
        assert!(
            error <= tolerance,
            "error {error:.3e} above the tolerance {tolerance:e}"
        );
        assert!(steps.len() < 1500, "{} steps", steps.len());
    }
    for integrator in [Integrator::BackwardEuler, Integrator::Exponential] {
        let err = bending_model_result(integrator, TimeSpec::new(3.0, 1e-3).with_tolerance(1e-4))
            .expect_err("refused");
        assert_eq!(err.field, Field::Time(TimeField::Tolerance), "{err}");
        assert!(err.message.contains("trapezoidal"), "{err}");
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
    let design = stentkit::design::load_design(&path).expect("design loads");
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

/// A straight rod (L = 1, d = 0.05) of a standard linear solid — `E∞ = 1e6`, one branch `E₁ = 1e7` with
/// `τ = 0.01` s, no temperature shift — clamped at one end, with a dead end couple `M` about z applied at t = 0
/// and held to t = 0.5, at the given time stepping (trapezoidal update): the tip rotation at every step.
fn creep_rod(time: TimeSpec, couple: Real) -> Vec<(Real, Real)> {
    run_model(&creep_model(time, couple))
}

/// The model of [`creep_rod`].
fn creep_model(time: TimeSpec, couple: Real) -> Model {
    let prony = Prony::try_new(
        1e6,
        vec![PronyBranch {
            modulus: 1e7,
            tau_g: 0.01,
        }],
    )
    .expect("valid Prony series");
    let material = Material::try_new(prony, 0.3, None).expect("valid material");
    let law = MaterialLaw::from_material(material, Integrator::Trapezoidal);
    let wire = CircularSection::try_new(0.05).expect("d > 0");
    let mut b = ModelBuilder::new("creep", law, wire.into());
    let rod = PatchShape::Line {
        from: Vec3::zeros(),
        to: Vec3::x(),
    };
    b.patch("rod", rod, 4, 8);
    b.condition(ConditionSpec::clamp("rod.start"));
    b.condition(ConditionSpec::at("rod.end").with_moment(2, TimeFunction::constant(couple)));
    b.time(time);
    b.build().expect("valid model").model
}

// Source: closed form. Pure bending under a dead end couple has uniform curvature (the geometrically exact rod is
// exact there), and a standard linear solid under a stress applied at t = 0 and held creeps as
// κ(t) = M/I · J(t), J(t) = 1/E∞ − (1/E∞ − 1/E₀) e^{−t/τ_c}, E₀ = E∞ + E₁, τ_c = τ E₀/E∞ (Findley, Lai & Onaran,
// *Creep and Relaxation of Nonlinear Viscoelastic Materials*, §5.3); the tip rotates by φ = κ L. Steps of 0.05 s
// are five relaxation times τ: the trapezoidal update, amplification (1 − hλ/2)/(1 + hλ/2) = −0.43, rings after
// the jump (`study stability` maps where), and the fixed run misses the closed form by more than 1e-3 rad.
// With error control the estimate (the difference to backward Euler, which does not ring) catches the ringing:
// the first steps are rejected and shrunk until the jump is resolved, and the whole history stays within the
// tolerance of the closed form, at tolerances 1e-3 … 1e-5 rad (the rotation creeps from 0.003 to 0.032 rad).
// The history asked at 60 times (every 1/120 s, with t = 0 the 61 times of a creep–recovery table) comes from
// the continuous extension (issue 36 item 3) and stays within the tolerance too (measured 0.49, 0.40, 0.44 of it),
// without changing the steps; the steps' history interpolated linearly there is printed for comparison (0.49,
// 0.42, 0.44: here the error is the one made at the jump, which the steps carry along).
#[test]
fn error_control_catches_the_trapezoidal_ringing_after_a_jump() {
    let couple = 0.01;
    let second_moment = std::f64::consts::PI * 0.05_f64.powi(4) / 64.0;
    let (e_inf, e0, tau) = (1e6, 1.1e7, 0.01);
    let exact = |t: Real| {
        let tau_c = tau * e0 / e_inf;
        couple / second_moment * (1.0 / e_inf - (1.0 / e_inf - 1.0 / e0) * (-t / tau_c).exp())
    };
    let error = |history: &[(Real, Real)]| {
        history
            .iter()
            .map(|&(t, phi)| (phi - exact(t)).abs())
            .fold(0.0, Real::max)
    };
    let fixed = creep_rod(TimeSpec::new(0.5, 0.05), couple);
    let fixed_error = error(&fixed);
    println!(
        "creep after a jump, final rotation {:.4} rad: fixed steps of 0.05 s: error {fixed_error:.2e}",
        exact(0.5)
    );
    assert!(fixed_error > 1e-3, "the fixed run rings: {fixed_error:.2e}");
    for tolerance in [1e-3, 1e-4, 1e-5] {
        let mut time = TimeSpec::new(0.5, 0.05).with_tolerance(tolerance);
        time.min_step = Some(1e-8);
        let model = creep_model(time, couple);
        let adaptive = run_model(&model);
        let adaptive_error = error(&adaptive);
        let asked: Vec<Real> = (1..=60).map(|k| k as Real * 0.5 / 60.0).collect();
        let (steps, requested) = run_model_with_requested(
            &model
                .with_record_times(asked.clone())
                .expect("within the run"),
        );
        assert_eq!(steps, adaptive, "the requested times changed the steps");
        let mut linear_error: Real = 0.0;
        for &t in &asked {
            let after = steps.partition_point(|s| s.0 < t - 1e-12);
            let (a, b) = (steps[after.saturating_sub(1)], steps[after]);
            let linear = a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0).max(Real::MIN_POSITIVE);
            linear_error = linear_error.max((linear - exact(t)).abs());
        }
        let landed = asked
            .iter()
            .filter(|&&t| steps.iter().any(|s| (s.0 - t).abs() < 1e-9))
            .count();
        assert_eq!(
            requested.len() + landed,
            asked.len(),
            "each time reached once"
        );
        assert!(
            requested.len() > asked.len() / 2,
            "the steps landed on most requested times"
        );
        let dense_error = error(&requested);
        println!(
            "  error control at {tolerance:e}: {} steps, error {adaptive_error:.2e} (measured/requested {:.2}); at the \
             {} requested times {:.2} of the tolerance ({} from the extension; the steps interpolated linearly {:.2})",
            adaptive.len(),
            adaptive_error / tolerance,
            asked.len(),
            dense_error / tolerance,
            requested.len(),
            linear_error / tolerance
        );
        assert!(
            adaptive_error <= tolerance,
            "error control at {tolerance:e}: {adaptive_error:.2e}"
        );
        assert!(
            dense_error <= tolerance,
            "the extension at {tolerance:e}: {dense_error:.2e}"
        );
    }
}

// Source: the straight stent of paper §4.3.1 at the paper's settings (p = 6, n = 20, fixed steps of 2.5 ms, the
// trapezoidal rule) as the reference; its own time error against a run of tenth steps is 1.6e-5 in the measure below
// (measured), 1.6 % of the tolerance. Measure: every node's translation difference over the length of the shortest
// patch at the node (`study::sample::node_lengths`), the translation part of the norm the estimate is held to, at the
// tenths of the run, the schedule's breakpoints (the release at 1.75 s and the end of its ramp) and 1.8 s (the
// error-controlled run reaches those between its steps by its continuous extension; the fixed one lands on them). Same
// mesh, so the difference is time error, which must stay within the tolerance asked (measured 0.15 of it in 415 steps;
// 0.14 in 381 when the steps landed on those times). While the driven nodes are held, an error of the internal
// variables barely moves the constrained configuration and shows only once the nodes are freed: with the configuration
// difference alone as the estimate this measured 1.94 times the tolerance at the release (1.0 whatever share of the
// tolerance the steps were held to, 1/4 to 1/8); the section-stress part of the estimate is what catches it.
#[test]
fn error_control_sees_the_errors_made_while_nodes_are_held() {
    use stentkit::design::load_design;
    use stentkit::model::ProbeLocation;
    use stentkit::study::sample::{node_lengths, watched_run};
    use stentkit::study::tune::comparison_times;
    use stentkit::study::variant::TimeVariant;
    let tolerance = 1e-3;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/straight_stent.yaml");
    let paper = load_design(&path).expect("the straight stent reads").model;
    let mut times = comparison_times(&paper);
    times.push(1.8);
    times.sort_by(Real::total_cmp);
    let nodes: Vec<ProbeLocation> = (0..paper.nodes.len()).map(ProbeLocation::Node).collect();
    let run = |model: &Model| {
        let model = model
            .clone()
            .with_record_times(times.clone())
            .expect("record times within the run");
        let run = watched_run(&model, &nodes, None).expect("the run converges");
        assert_eq!(run.states.len(), times.len(), "every time reached");
        run
    };
    let reference = run(&paper);
    let controlled = TimeVariant {
        tolerance: Some(tolerance),
        ..TimeVariant::default()
    }
    .of(&paper)
    .expect("the trapezoidal update has an estimate");
    let adaptive = run(&controlled);
    let lengths = node_lengths(&paper);
    let (error, at) = adaptive
        .states
        .iter()
        .zip(&reference.states)
        .flat_map(|(a, b)| {
            let nodes = a.displacements.iter().zip(&b.displacements).zip(&lengths);
            nodes.map(|((u, v), l)| ((u - v).norm() / l, b.time))
        })
        .fold((0.0, 0.0), |m, e| if e.0 > m.0 { e } else { m });
    println!(
        "straight stent at {tolerance:e}: {} steps, time error {error:.3e} at t = {at} ({:.2} of the tolerance)",
        adaptive.summary.steps,
        error / tolerance
    );
    assert!(
        error <= tolerance,
        "{error:.3e} at t = {at} above the tolerance"
    );
}

/// The tip's rotation about z and its position `(x, y)` along a run, sampled at the record times.
struct Tip {
    point: usize,
    samples: Vec<(Real, Real, Real, Real)>,
}

impl Tip {
    fn sample(&mut self, sim: &Simulation<'_>) {
        let g = self.point;
        let r = sim.state().rotation[g] * sim.discretisation().points[g].rotation0.transpose();
        let phi = log(&Rot3::from_matrix_unchecked(r));
        let u = sim.probe_displacement(&sim.model().probes[0].location);
        self.samples.push((sim.time(), phi.z, 1.0 + u.x, u.y));
    }
}

/// At every step, and at every requested time an error-controlled run reaches between its steps.
impl Observer for Tip {
    fn step(&mut self, sim: &Simulation<'_>, _: &StepReport) -> ControlFlow<()> {
        self.sample(sim);
        ControlFlow::Continue(())
    }

    fn requested(&mut self, sim: &Simulation<'_>, _: &StepReport) {
        self.sample(sim);
    }
}

/// Reads the columns `time, …, rotation, x, y` (the last three) of a reference CSV.
fn tip_reference(file: &str) -> Vec<(Real, Real, Real, Real)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(file);
    std::fs::read_to_string(path)
        .expect("reference data")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("time"))
        .map(|l| {
            let v: Vec<Real> = l.split(',').map(|x| x.parse().expect("number")).collect();
            let n = v.len();
            (v[0], v[n - 3], v[n - 2], v[n - 1])
        })
        .collect()
}

/// A PLA cantilever (L = 1 m along x, d = 0.05 m) under the end couple and temperature of
/// `scripts/maxwell_bending_reference.py`, with error-controlled steps of tolerance `tolerance` landing every
/// 20 ms; `setup` makes its beam (patches, materials, temperature field) on the builder.
fn tip_history(
    tolerance: Real,
    setup: impl FnOnce(&mut ModelBuilder),
) -> Vec<(Real, Real, Real, Real)> {
    let wire = CircularSection::try_new(0.05).expect("d > 0");
    let mut b = ModelBuilder::new("bending", pla(70.0), wire.into());
    setup(&mut b);
    let table = |points: &[(Real, Real)]| TimeFunction::try_table(points.to_vec()).expect("table");
    b.condition(ConditionSpec::clamp("a.start"));
    let couple = table(&[(0.0, 0.0), (0.5, 10.0), (0.75, 10.0), (1.0, 0.0)]);
    b.condition(ConditionSpec::at("tip").with_moment(2, couple));
    b.probe("tip", stentkit::model::builder::ProbeAt::Node("tip".into()));
    b.time(TimeSpec::new(3.0, 1e-3).with_tolerance(tolerance));
    b.record_times((1..150).map(|k| 0.02 * k as Real).chain([3.0]).collect());
    let model = b.build().expect("valid model").model;
    let mut sim = Simulation::new(&model).expect("simulation");
    let point = sim.discretisation().points.len() - 1;
    let mut tip = Tip {
        point,
        samples: Vec::new(),
    };
    sim.run(&mut [&mut tip]).expect("run completes");
    tip.samples
}

/// The temperature of `scripts/maxwell_bending_reference.py` plus `offset` °C.
fn programme_temperature(offset: Real) -> TimeFunction {
    let points = [
        (0.0, 90.0),
        (0.5, 90.0),
        (0.75, 31.5),
        (1.625, 31.5),
        (2.5, 90.0),
    ];
    TimeFunction::try_table(points.iter().map(|&(t, v)| (t, v + offset)).collect()).expect("table")
}

/// PLA (paper Table PLA, WLF of Table aT_PLA row 1) with its glass transition at `tg`, trapezoidal rule.
fn pla(tg: Real) -> MaterialLaw {
    let prony = pla_prony(1.0);
    let wlf = Wlf::try_new(14.59, 48.43, tg).expect("valid WLF constants");
    let material = Material::try_new(prony, 0.33, Some(wlf)).expect("valid material");
    MaterialLaw::from_material(material, Integrator::Trapezoidal)
}

/// The PLA Prony series (paper Table PLA, van Manen et al. 2021, the library's [`Prony::pla_van_manen_2021`])
/// in Pa with every modulus times `factor`.
fn pla_prony(factor: Real) -> Prony {
    let pla = Prony::pla_van_manen_2021(); // MPa
    let scale = factor * 1e6; // to Pa
    let branches = pla
        .branches()
        .iter()
        .map(|b| PronyBranch {
            modulus: scale * b.modulus,
            tau_g: b.tau_g,
        })
        .collect();
    Prony::try_new(scale * pla.e_inf(), branches).expect("valid Prony series")
}

/// Asserts that a run's tip rotation and position stay within 1e-6 of the reference's largest rotation and tip
/// displacement at each of its 150 landing times (printing the measured errors, labelled).
fn assert_tip_within_1e6(
    label: &str,
    samples: &[(Real, Real, Real, Real)],
    reference: &[(Real, Real, Real, Real)],
) {
    let (rotation, position, compared) = tip_errors(samples, reference);
    let largest_rotation = reference.iter().fold(0.0_f64, |m, r| m.max(r.1.abs()));
    let largest_displacement = reference
        .iter()
        .fold(0.0_f64, |m, r| m.max((r.2 - 1.0).hypot(r.3)));
    println!(
        "{label}: {} steps; rotation error {rotation:.3e} of {largest_rotation:.3} rad, tip error {position:.3e} of {largest_displacement:.3} m at {compared} times",
        samples.len()
    );
    assert_eq!(compared, 150, "every landing time is compared");
    assert!(
        rotation <= 1e-6 * largest_rotation,
        "{label}: rotation error {rotation:.3e}"
    );
    assert!(
        position <= 1e-6 * largest_displacement,
        "{label}: tip error {position:.3e}"
    );
}

/// Largest differences between a run's tip history and the reference at the reference's own times (every 20
/// ms): of the rotation \[rad\] and of the position \[m\].
fn tip_errors(
    samples: &[(Real, Real, Real, Real)],
    reference: &[(Real, Real, Real, Real)],
) -> (Real, Real, usize) {
    let (mut rotation, mut position, mut compared) = (0.0_f64, 0.0_f64, 0);
    for &(t, phi, x, y) in samples {
        let i = (t / 1e-3).round() as usize;
        let r = &reference[i];
        if i.is_multiple_of(20) && (r.0 - t).abs() < 1e-9 {
            compared += 1;
            rotation = rotation.max((phi - r.1).abs());
            position = position.max((x - r.2).hypot(y - r.3));
        }
    }
    (rotation, position, compared)
}

// Source: a cantilever of two materials in series under a pure end couple carries the same moment in every
// section, so each half bends with the uniform curvature its own 1-D Maxwell–WLF law gives for M(t), T(t)
// (paper §2.2); the tip rotation is κ_a/2 + κ_b/2 and the tip position follows from the two circular arcs in
// closed form. scripts/maxwell_bending_reference.py integrates both laws independently (scipy Radau, rtol
// 1e-12). The rod: two patches (p = 6, n = 24) joined at x = 1/2, PLA and a second material (PLA moduli × 0.6,
// WLF C1 = 17.44, C2 = 51.6, Tg = 60 °C), error-controlled steps at a tolerance of 1e-7 (8 700 steps). Measured:
// rotation error 4.3e-8 rad of a largest rotation of 0.534 rad, tip-position error 2.8e-8 m of a largest tip
// displacement of 0.230 m (8e-8 and 1.2e-7 relative); asserted within 1e-6 of each. A material taken for the
// other, a wrong WLF per region or a joint that does not carry the moment would be off by 1e-2 to 1.
#[test]
fn two_materials_in_series_bend_as_their_one_dimensional_laws() {
    let reference = tip_reference("two_material_bending_reference.csv");
    let samples = tip_history(1e-7, |b| {
        let wlf = Wlf::try_new(17.44, 51.6, 60.0).expect("valid WLF constants");
        let second = Material::try_new(pla_prony(0.6), 0.33, Some(wlf)).expect("valid material");
        let second = b.named_material(
            "second",
            MaterialLaw::from_material(second, Integrator::Trapezoidal),
        );
        let line = |from: Real, to: Real| PatchShape::Line {
            from: Vec3::new(from, 0.0, 0.0),
            to: Vec3::new(to, 0.0, 0.0),
        };
        b.patch("a", line(0.0, 0.5), 6, 24);
        b.patch_with(
            "b",
            line(0.5, 1.0),
            6,
            24,
            stentkit::model::builder::PatchOptions {
                material: second,
                ..Default::default()
            },
        );
        b.node(
            "joint",
            NodeEnds::Named(vec!["a.end".into(), "b.start".into()]),
        );
        b.node("tip", NodeEnds::Named(vec!["b.end".into()]));
        b.temperature(programme_temperature(0.0));
    });
    assert_tip_within_1e6("two materials", &samples, &reference);
}

// Source: a PLA cantilever under a pure end couple with a temperature that varies linearly along it,
// T(x, t) = T(t) + 10 K/m (x − 1/2): the moment is still the same in every section, so the curvature at each
// x is the 1-D Maxwell–WLF law at that section's temperature history; scripts/maxwell_bending_reference.py
// integrates it at 40 Chebyshev points and integrates the interpolated curvature along x for the tip rotation
// and position. The balance equations now need the s-derivatives of the viscous strains and of the shift
// factor (module docs of `material::maxwell`): with the paper's T,s = 0 recursion the equilibrium M,s = 0 would
// be met by a wrong curvature. The rod: one patch (p = 6, n = 40) in a field of two stations (x = 0: T(t) − 5,
// x = 1: T(t) + 5), error-controlled steps at 1e-7 (10 800 steps). The curvature has a steep transition where
// the glass transition runs along the beam while it cools and heats, so the mesh matters more than the step:
// measured rotation errors 4.2e-6 rad at n = 24 (tolerance 1e-6, 1e-7 or 1e-8 alike), 3.4e-7 at n = 32,
// 5.7e-8 at n = 40 (tip 4.0e-8 m), of a largest rotation of 0.389 rad and tip displacement of 0.190 m (1.5e-7
// and 2.1e-7 relative); asserted within 1e-6 of each. The reference's interpolation in x is good to ~1e-7
// (its last Chebyshev coefficients, 6.5e-8 of the first).
#[test]
fn a_temperature_gradient_bends_as_the_one_dimensional_law_integrated_along_the_beam() {
    let reference = tip_reference("gradient_bending_reference.csv");
    let samples = tip_history(1e-7, |b| {
        b.patch(
            "a",
            PatchShape::Line {
                from: Vec3::zeros(),
                to: Vec3::x(),
            },
            6,
            40,
        );
        b.node("tip", NodeEnds::Named(vec!["a.end".into()]));
        let field = TemperatureField::try_new(
            Vec3::zeros(),
            Vec3::x(),
            Profile::Stations(vec![
                (0.0, programme_temperature(-5.0)),
                (1.0, programme_temperature(5.0)),
            ]),
        )
        .expect("valid field");
        b.temperature_field(field);
    });
    assert_tip_within_1e6("gradient", &samples, &reference);
}
