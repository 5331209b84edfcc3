//! A programme by a crimper (`kind: crimp`) and obstacles in the design language (issue 33): what the design
//! builds, checked against values worked out by hand from the design file.

use stentkit::design::load_design;
use stentkit::model::{ProgrammeKind, Surface, Wall};

/// `designs/straight_stent_crimped.yaml`: the paper's straight stent (R = 20, wire d = 0.6, Δr = 15, ramp 0–1 s,
/// release 1.75 s) with a sheath of radius 5.3 from 1.75 to 2.2 s. Worked out from the file and the crimper's
/// rule (`crate::model::stent::crimper`): the crown wires lie on the cylinder of radius 20, so the device's
/// reach is 20 + 0.3 and the crimper starts 2 % outside it, at 20.706; it closes until the wires' reach is
/// R − Δr = 5, its radius 5.3, at t = 1; it opens over a tenth of the ramp (0.1 s) from the release. Nothing is
/// prescribed but the symmetry: the driven nodes (every joint) keep only the components their symmetry planes
/// set, and the device is gauged from the start. The cycle: programmed at the end of the ramp (1 s), fixed at
/// the release (1.75 s), released when the crimper is open (1.85 s). Contact defaults: penalty = E_inf I / d⁴
/// = 80.59 π / 64 = 3.955952 N/mm² for the circular wire, tolerance 1 % of 0.6 = 6e-3, transition band 6e-4,
/// 10 updates; a model with contact starts its steps extrapolated.
#[test]
fn a_crimp_programme_builds_its_crimper_and_prescribes_nothing() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("designs/straight_stent_crimped.yaml");
    let design = load_design(&path).expect("the crimped straight stent loads");
    let model = &design.model;
    let programme = model.programme.as_ref().expect("a programme");
    let ProgrammeKind::Crimp {
        delta_r,
        obstacle,
        open,
        ..
    } = programme.kind
    else {
        panic!("a crimp programme: {:?}", programme.kind);
    };
    assert_eq!((delta_r, open), (15.0, 0.1));
    assert!(!programme.prescribes());
    assert_eq!(programme.free_from(), Some(0.0));
    let contact = model.contact.as_ref().expect("contact");
    let names: Vec<&str> = contact.obstacles.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(
        names,
        ["sheath", "crimper"],
        "the design's obstacles, then the crimper"
    );
    assert_eq!(obstacle, 1);
    let crimper = &contact.obstacles[1];
    assert_eq!(crimper.wall, Wall::Rigid);
    let Surface::Cylinder {
        point,
        axis,
        radius,
    } = &crimper.surface
    else {
        panic!("a cylinder");
    };
    assert!(point.norm() < 1e-12 && (axis - stentkit::math::Vec3::x()).norm() < 1e-12);
    // The reach is sampled on the fitted splines (fit error 2.7e-5 of the design): 1e-4 covers it.
    for (t, expected) in [
        (0.0, 1.02 * 20.3),
        (0.5, 0.5 * (1.02 * 20.3 + 5.3)),
        (1.0, 5.3),
        (1.75, 5.3),
        (1.85, 1.02 * 20.3),
        (3.0, 1.02 * 20.3),
    ] {
        let r = radius.value(t);
        assert!(
            (r - expected).abs() < 1e-4,
            "crimper radius {r} at t = {t}, expected {expected}"
        );
    }
    let sheath = &contact.obstacles[0];
    assert_eq!(sheath.active, (1.75, Some(2.2)));
    assert!(
        !sheath.is_active(1.75)
            && sheath.is_active(1.76)
            && sheath.is_active(2.2)
            && !sheath.is_active(2.21)
    );
    let s = contact.settings;
    assert!((s.penalty - 3.955_952).abs() < 1e-6, "{}", s.penalty);
    assert!(model.solver().extrapolate);
    assert!((s.tolerance - 6e-3).abs() < 1e-15 && (s.regularisation - 6e-4).abs() < 1e-15);
    assert_eq!(s.max_updates, 10);
    // Only the symmetry planes prescribe: no node has a prescribed component on a non-symmetry node.
    let prescribed: usize = model
        .nodes
        .iter()
        .flat_map(|n| &n.conditions.components)
        .filter(|c| c.is_prescribed_at(0.5))
        .count();
    let symmetry_nodes = model
        .nodes
        .iter()
        .filter(|n| {
            n.conditions
                .components
                .iter()
                .any(|c| c.is_prescribed_at(0.5))
        })
        .count();
    assert_eq!(
        prescribed,
        3 * symmetry_nodes,
        "a symmetry node holds its normal translation and two rotations"
    );
    let cycle = model.cycle().expect("a cycle");
    assert_eq!((cycle.programmed, cycle.fixed), (Some(1.0), 1.75));
    assert!((cycle.released - 1.85).abs() < 1e-12, "{}", cycle.released);
    // The crimper's breakpoints and the sheath's are times the run lands on.
    let breakpoints = model.schedule_breakpoints();
    for t in [1.0, 1.75, 1.85, 2.2] {
        assert!(
            breakpoints.iter().any(|b| (b - t).abs() < 1e-12),
            "{t} in {breakpoints:?}"
        );
    }
}

/// `designs/curved_stent_crimped.yaml`: the paper's curved stent (four crowns of R = 20 on a 45° arc of radius
/// 100 mm about O = (0, 0, −5), wire d = 0.6, Δr = 15, ramp 0–1.5 s, release 2.25 s) crimped by a tube around
/// its own axis. Worked out from the file: the tube's centreline is the arc, so a point 1 mm off the axis in
/// the arc's plane at angle ψ, `O + 101 (cos ψ, 0, sin ψ)`, is `r(t) − 1` inside the tube of radius `r(t)`; the
/// tube is closed at t = 1.5 s to R − Δr + d/2 = 5.3 and starts at least 2 % clear of the crowns' reach
/// 20.3 (the radial bridges reach further). The axis is fitted within 1e-5 of the crown radius (2e-4): the
/// tolerance covers it. The cycle's events are the tube's schedule's, as for a cylinder.
#[test]
fn a_curved_stent_is_crimped_by_a_tube_around_its_own_axis() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/curved_stent_crimped.yaml");
    let design = load_design(&path).expect("the crimped curved stent loads");
    let model = &design.model;
    let contact = model.contact.as_ref().expect("contact");
    let crimper = contact.obstacles.last().expect("the crimper");
    let Surface::Lumen(tube) = &crimper.surface else {
        panic!("a tube around the curved axis: {:?}", crimper.surface);
    };
    let (closed, start) = (tube.scale().value(1.5), tube.scale().value(0.0));
    assert!((closed - 5.3).abs() < 1e-9, "closed at {closed}");
    assert!(start >= 1.02 * 20.3, "starts at {start}");
    for psi in [0.1_f64, 0.3, 0.5, 0.7] {
        let x = stentkit::math::Vec3::new(101.0 * psi.cos(), 0.0, 101.0 * psi.sin() - 5.0);
        for t in [0.0, 1.5] {
            let d = crimper.surface.distance(&x, t).expect("inside the tube");
            let expected = tube.scale().value(t) - 1.0;
            assert!(
                (d.value - expected).abs() < 2e-4,
                "ψ = {psi}, t = {t}: distance {} against {expected}",
                d.value
            );
        }
    }
    assert!(!model.programme.as_ref().expect("a programme").prescribes());
    // Its cycle, as the straight crimper's: programmed when the tube has closed (1.5 s), fixed at the release
    // (2.25 s), released when it is open (2.25 + 0.15 s) — what the recovery warning and the snapshots' events
    // read.
    let cycle = model.cycle().expect("a cycle");
    assert_eq!((cycle.programmed, cycle.fixed), (Some(1.5), 2.25));
    assert!((cycle.released - 2.4).abs() < 1e-12, "{}", cycle.released);
}

/// Contact with every material integrator (issue 33): the crimped straight stent (two crowns) crimped at 90 °C
/// to its temporary shape (t = 1 s) with the trapezoidal rule, backward Euler and the exponential integrator.
/// Each run closes the crimper without a warning, and the three agree on the crimper's radial force at the
/// end of the crimp, a converged run of three different time integrations of the same Prony series: measured
/// 0.054325 N, the three within 5e-6 relative (backward Euler, first order, the farthest). Tolerance 1e-3: well
/// above the methods' difference, far below a contact force that depended on the integrator's state (an
/// integrator whose history the contact term disturbed would be off by the relaxed fraction, tens of %).
#[test]
fn the_crimp_force_is_the_same_with_every_material_integrator() {
    let mut forces = Vec::new();
    for integrator in ["trapezoidal", "backward-euler", "exponential"] {
        let model = crate::common::fixtures::design("straight_stent_crimped.yaml")
            .crowns(2)
            .set("material.integrator", integrator)
            .model();
        let mut sim = stentkit::solver::Simulation::new(&model).expect("valid");
        while sim.time() < 1.0 - 1e-12 {
            sim.step().expect("the crimp converges");
        }
        assert!((sim.time() - 1.0).abs() < 1e-12, "{}", sim.time());
        assert!(
            sim.warnings().is_empty(),
            "{integrator}: {:?}",
            sim.warnings()
        );
        let report = sim.contact().expect("contact");
        let crimper = report.obstacles.last().expect("the crimper");
        let force = crimper.radial_force.expect("a cylinder's radial force");
        println!(
            "{integrator}: crimper radial force {force:.9e} N at t = {}",
            report.time
        );
        forces.push(force);
    }
    for f in &forces[1..] {
        assert!(((f - forces[0]) / forces[0]).abs() < 1e-3, "{forces:?}");
    }
}

/// `designs/aorta_stent_crimped.yaml` (issue 33): the patient stent (five crowns on the aorta file's
/// centreline, R = 6.3075 mm) programmed by a crimper — a tube around its own curved centreline closing until
/// the wires' reach is R − Δr, Δr = 3.3 mm, at 1.5 s — cooled, released into its rigid lumen at 2.25 s and
/// heated. What must hold, from the geometry and the contact law's promise, not from a run:
/// - at the end of the crimp, every collocation point at most the contact tolerance (4e-3, 1 % of the wire)
///   through the crimper, and the driven nodes (every joint, on the cylinder of radius R in the reference) moved
///   towards the axis by at least Δr on average: a node inside the tube of reach R − Δr has moved at least Δr
///   less that tolerance, up to the change of its nearest axis point as it slides along the curved axis (1 %
///   allowed);
/// - no step above the tolerance anywhere (collocation points and between them: the run's warnings);
/// - at the end, the vessel holds the device (its permanent shape is 10 % larger than the lumen): points in
///   contact, pressure on the wall, and the recovery warning naming the vessel.
///
/// Its crimp once stalled at t ≈ 0.22 s, when the projection on the tube's centreline lost points at random.
#[test]
#[ignore = "full size (the patient stent's crimped cycle, ~30 s): run by .ci/run with cargo test --release -- --ignored"]
fn the_aorta_stent_is_crimped_by_a_tube_deployed_and_held_by_its_vessel() {
    let model = crate::common::fixtures::design("aorta_stent_crimped.yaml").model();
    let tolerance = model.contact.as_ref().expect("contact").settings.tolerance;
    assert!((tolerance - 4e-3).abs() < 1e-15, "{tolerance}");
    let mut sim = stentkit::solver::Simulation::new(&model).expect("valid");
    while sim.time() < 1.5 - 1e-12 {
        sim.step().expect("the crimp converges");
    }
    let report = sim.contact().expect("contact");
    let crimper = report.obstacles.last().expect("the crimper");
    assert!(
        crimper.penetration <= tolerance && crimper.points > 0,
        "{} points, penetration {}",
        crimper.points,
        crimper.penetration
    );
    let recovery = stentkit::post::recovery::recovery(&sim).expect("a programme");
    let delta_r = recovery.delta_r.expect("a radial programme");
    assert!(delta_r >= 0.99 * 3.3, "mean contraction {delta_r}");
    while sim.time() < model.time().end - 1e-12 {
        sim.step().expect("the cycle converges");
    }
    // The crimper drives the struts of the loops through each other (rod-on-rod contact, issue 35, is not
    // modelled yet): that is said, and it is the only warning.
    let warnings = sim.warnings();
    assert!(
        warnings.len() == 1 && warnings[0].starts_with("wires passed through each other"),
        "{warnings:?}"
    );
    let report = sim.contact().expect("contact");
    let vessel = &report.obstacles[0];
    assert!(
        vessel.points > 0 && vessel.radial_force.is_some_and(|f| f > 0.0),
        "{vessel:?}"
    );
    assert!(vessel.penetration <= tolerance, "{}", vessel.penetration);
    let warning =
        stentkit::post::recovery::recovery_warning(&sim).expect("held short of its shape");
    assert!(warning.contains("`vessel` at"), "{warning}");
}
