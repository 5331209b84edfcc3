//! The generic central-difference test of every term's tangent, a check that it fails for a term with a wrong
//! tangent, and the spring to ground against a closed form.

use super::contact::SurfaceContact;
use super::damping::Damping;
use super::distributed::DistributedLoad;
use super::spring::SpringToGround;
use super::{Constraint, EndLoad, InteriorLoad, PointTerm, PointView, Terms};
use crate::material::{CircularSection, ElasticLaw, SectionLaw};
use crate::math::{Real, Vec3};
use crate::model::builder::{ConditionSpec, ModelBuilder, PatchShape, TimeSpec};
use crate::model::{Model, ProbeLocation, TimeFunction};
use crate::solver::Simulation;
use crate::solver::assembly::{Actions, Assembler, Assembly, StepMaterial};
use crate::solver::discretisation::Discretisation;
use crate::solver::gauge::{Gauge, GaugeRow};
use crate::solver::state::State;
use crate::solver::tests::{deformed_state, dense_tangent, perturbed, residual, test_model};

/// Central-difference step: truncation O(ε²) ≈ 1e-12 relative, round-off ≈ 1e-16/ε = 1e-10 relative to the
/// residual's scale.
const EPS: Real = 1e-6;

/// Tolerance of the comparison, relative to the largest entry of the term's own tangent row: well above the
/// difference's error, far below a missing or wrong block (an O(1) relative error).
pub(super) const TOLERANCE: Real = 1e-6;

/// The largest error of `terms`' own tangent — the tangent with them minus the rod's alone — against central
/// differences of their own residual (with them minus without), relative to the largest entry of the term's
/// tangent row, at a deformed state of the test structure; and a description of the worst entries. The rod
/// has no stiffness here (`Ē = 0` at every point): its balance laws vanish, so the residual with the terms is
/// theirs plus the rod's kinematic rows (node conditions and continuity, of order one), and the difference of
/// the two residuals loses no digits to a large elastic residual (with the rod's stiffness, its 1e4-sized
/// force rows leave round-off of ~1e-11/ε = 1e-5 in the differences, above a small term's entries).
pub(super) fn term_tangent_error(model: &Model, terms: Terms<'_>) -> (Real, Vec<String>) {
    let disc = Discretisation::new(model).expect("discretisation");
    let laws: Vec<SectionLaw> = disc
        .points
        .iter()
        .map(|p| SectionLaw::elastic(&disc.shapes[p.shape], 0.0))
        .collect();
    let asm = Assembler::new(model, &disc);
    let actions = Actions::at(model, 1.0, &[]);
    let n = disc.num_unknowns();
    let size = n + terms.multipliers();
    let state = deformed_state(&disc, terms.multipliers());
    let at = |state: &State, terms: Terms<'_>| -> (Vec<Vec<Real>>, Vec<Real>) {
        let assembly = Assembly {
            disc: &disc,
            state,
            material: StepMaterial { laws: &laws },
            actions: &actions,
            terms,
        };
        (dense_tangent(&asm, &assembly), residual(&asm, &assembly))
    };
    let own_residual = |state: &State| {
        let (_, with) = at(state, terms);
        let (_, without) = at(state, Terms::default());
        let mut r = with;
        for (a, b) in r.iter_mut().zip(without) {
            *a -= b;
        }
        r
    };
    let (with, _) = at(&state, terms);
    let (without, _) = at(&state, Terms::default());
    let mut own = with.clone();
    for (row, base) in own.iter_mut().zip(&without) {
        for (a, b) in row.iter_mut().zip(base) {
            *a -= b;
        }
    }
    let largest = |row: &[Real]| row.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let mut worst: Real = 0.0;
    let mut report = Vec::new();
    for j in 0..size {
        let rp = own_residual(&perturbed(&disc, &state, j, EPS));
        let rm = own_residual(&perturbed(&disc, &state, j, -EPS));
        for i in 0..size {
            let fd = (rp[i] - rm[i]) / (2.0 * EPS);
            let scale = largest(&own[i]).max(1e-300);
            let err = (fd - own[i][j]).abs() / scale;
            if err > TOLERANCE && report.len() < 10 {
                report.push(format!(
                    "row {i} col {j}: tangent {:.6e}, differences {fd:.6e}",
                    own[i][j]
                ));
            }
            worst = worst.max(err);
        }
    }
    (worst, report)
}

/// A node condition holding `end`'s rotations and its x and y translations, its z translation free (to be
/// prescribed or loaded).
pub(crate) fn held_but_z(end: &str) -> ConditionSpec {
    let mut c = ConditionSpec::at(end);
    for i in 0..3 {
        c = c.with_rotation(i, TimeFunction::constant(0.0));
    }
    for i in 0..2 {
        c = c.with_displacement(i, TimeFunction::constant(0.0));
    }
    c
}

/// Two straight rods of diameter 0.2 (E = 2e5, ν = 0.3) crossing at right angles, at degree 4 with `elements`
/// elements: `low` from (−1, 0, 0) to (1, 0, 0), clamped at both ends; `high` from (0, −1, z) to (0, 1, z), its
/// ends moved down by `drop` over t ∈ [0, 1] ([`held_but_z`] otherwise); steps of `step`.
pub(crate) fn crossing_rods(z: Real, drop: Real, elements: usize, step: Real) -> ModelBuilder {
    let material = ElasticLaw::try_new(2.0e5, 0.3).expect("E > 0, ν = 0.3");
    let section = CircularSection::try_new(0.2).expect("d > 0").into();
    let mut b = ModelBuilder::new("crossing rods", material, section);
    for (name, from, to) in [
        ("low", Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0)),
        ("high", Vec3::new(0.0, -1.0, z), Vec3::new(0.0, 1.0, z)),
    ] {
        b.patch(name, PatchShape::Line { from, to }, 4, elements);
    }
    b.condition(ConditionSpec::clamp("low.start"));
    b.condition(ConditionSpec::clamp("low.end"));
    let ramp = TimeFunction::try_table(vec![(0.0, 0.0), (1.0, -drop)]).expect("a ramp");
    for end in ["high.start", "high.end"] {
        b.condition(held_but_z(end).with_displacement(2, ramp.clone()));
    }
    b.time(TimeSpec::new(1.0, step));
    b
}

/// The springs of the tests: forces and couples of the order of the test structure's own residual terms at
/// its deformed state (displacements ~0.05, rotations ~0.3).
fn spring() -> SpringToGround {
    SpringToGround {
        foundation: 1e3,
        rotational_foundation: 3.0,
        end: 1e2,
        rotational_end: 3.0,
    }
}

/// Contact of the test structure with a compliant cylinder around the arc's centre and a rigid plane under it, placed so that
/// at the deformed state of the tests some points are clear, some in the law's quadratic band and some on its
/// linear branch (the three branches and the cylinder's curvature term all enter the tangent). Forces of the
/// order of the structure's own residual terms.
fn contact(model: &Model, disc: &Discretisation) -> SurfaceContact {
    use crate::model::{ContactSettings, Obstacle, Surface, Wall};
    let constant = TimeFunction::constant;
    let obstacles = vec![
        Obstacle::new(
            "cylinder",
            Surface::Cylinder {
                point: Vec3::new(0.0, 1.0, 0.0),
                axis: Vec3::new(0.2, 0.0, 1.0).normalize(),
                radius: constant(1.02),
            },
            Wall::Compliant {
                modulus: 1e4,
                thickness: 0.1,
                width: 0.2,
            },
        )
        .with_friction(0.4),
        Obstacle::new(
            "plane",
            Surface::Plane {
                point: Vec3::zeros(),
                normal: Vec3::new(0.1, 0.0, 1.0).normalize(),
                offset: constant(-0.1),
            },
            Wall::Rigid,
        )
        .with_friction(0.3),
    ];
    let settings = ContactSettings {
        penalty: 1e3,
        regularisation: 0.06,
        tolerance: 1e-3,
        max_updates: 5,
    };
    SurfaceContact::new(model, disc, obstacles, settings)
}

/// The contact of the tangent test acts where it should be tested: at the deformed state some points are
/// clear of both surfaces, some in the law's quadratic band and some on its linear branch, both obstacles press
/// on some point, and the corner where the arc meets the leg at an angle has its ends pressed, so that the
/// concentrated force at a corner ([`PointTerm::end`]) is in the comparison (else the central-difference
/// comparison would check nothing of it).
#[test]
fn the_tangent_tests_contact_covers_every_branch_of_its_law() {
    let model = test_model();
    let disc = Discretisation::new(&model).expect("discretisation");
    let contact = contact(&model, &disc);
    let state = deformed_state(&disc, 0);
    let (mut clear, mut band, mut linear) = (0, 0, 0);
    let (mut sticking, mut sliding) = ([0; 2], [0; 2]);
    let mut pressed = [false; 2];
    let mut corners = 0;
    for (g, point) in disc.points.iter().enumerate() {
        if !contact.acts_at(g) {
            continue;
        }
        let x = crate::solver::discretisation::point_position(&disc, &state.control, g);
        if disc.is_end(g)
            && (0..2).any(|k| {
                contact
                    .at(k, g, point.patch, &x)
                    .is_some_and(|c| c.pressure > 0.0)
            })
        {
            corners += 1;
        }
        for (k, pressed) in pressed.iter_mut().enumerate() {
            let Some(c) = contact.at(k, g, point.patch, &x) else {
                continue;
            };
            *pressed |= c.pressure > 0.0;
            if let Some(f) = contact.friction(k, g, &x, &c) {
                if f.sliding {
                    sliding[k] += 1;
                } else {
                    sticking[k] += 1;
                }
            }
            if c.stiffness == 0.0 {
                clear += 1;
            } else if c.stiffness > -contact.law(k, g).0 {
                band += 1;
            } else {
                linear += 1;
            }
        }
    }
    assert!(
        clear > 0 && band > 0 && linear > 0,
        "clear {clear}, band {band}, linear {linear}"
    );
    assert_eq!(pressed, [true, true]);
    assert_eq!(corners, 2, "the corner's two ends pressed");
    println!("sticking {sticking:?}, sliding {sliding:?}");
    assert!(
        sticking.iter().chain(&sliding).all(|&n| n > 0),
        "sticking {sticking:?}, sliding {sliding:?}"
    );
}

/// The gauge of the tests: a translation and a rotation-like row on the free end of the leg (node 2) and the
/// clamped start of the arc (node 0, whose prescribed components take no multiplier force), with origins off
/// the reference so that the rows' residuals are not zero.
fn gauge() -> Gauge {
    Gauge {
        rows: vec![
            GaugeRow {
                terms: vec![
                    (2, Vec3::new(0.3, -0.5, 0.8)),
                    (0, Vec3::new(0.1, 0.2, 0.3)),
                ],
            },
            GaugeRow {
                terms: vec![(2, Vec3::new(-0.7, 0.2, 0.4))],
            },
        ],
        frozen: vec![
            (2, Vec3::new(1.1, 0.8, 0.5)),
            (0, Vec3::new(0.01, 0.0, 0.0)),
        ],
        scale: 1.0,
    }
}

/// Source: every term's tangent must be the exact derivative of its residual under the solver's own update
/// (additive for `δη`, `R exp(δΘ̃)` with the `K`, `K,s` updates for `δΘ`, multipliers additive). Reference:
/// central differences of the term's own residual; see [`term_tangent_error`] for the step and [`TOLERANCE`]
/// for the tolerance. The list is every term of the crate: a new term joins it.
#[test]
fn every_terms_tangent_matches_central_differences() {
    let model = test_model();
    let disc = Discretisation::new(&model).expect("discretisation");
    let previous = State::reference(&disc);
    // `c/h = 1e5`: damping force ≈ 1e5 · A · 0.05 ≈ 40 and couple ≈ 1e5 · 2I · 0.3 ≈ 0.3, of the order of the
    // structure's own residual terms.
    let damping = Damping {
        previous: &previous,
        rate: 1e5,
    };
    let spring = spring();
    let gauge = gauge();
    let contact = contact(&model, &disc);
    let point_terms: [&dyn PointTerm; 4] = [&DistributedLoad, &damping, &spring, &contact];
    for term in point_terms {
        let (worst, report) = term_tangent_error(
            &model,
            Terms {
                point: &[term],
                constraints: &[],
            },
        );
        println!("{}: worst relative error {worst:.3e}", term.name());
        assert!(
            worst < TOLERANCE,
            "{}: worst relative error {worst:.3e}:\n{}",
            term.name(),
            report.join("\n")
        );
    }
    let constraints: [&dyn Constraint; 1] = [&gauge];
    for constraint in constraints {
        let (worst, report) = term_tangent_error(
            &model,
            Terms {
                point: &[],
                constraints: &[constraint],
            },
        );
        println!("{}: worst relative error {worst:.3e}", constraint.name());
        assert!(
            worst < TOLERANCE,
            "{}: worst relative error {worst:.3e}:\n{}",
            constraint.name(),
            report.join("\n")
        );
    }
    // All of them at once add up as they do one by one.
    let (worst, report) = term_tangent_error(
        &model,
        Terms {
            point: &point_terms,
            constraints: &constraints,
        },
    );
    assert!(
        worst < TOLERANCE,
        "all terms: worst relative error {worst:.3e}:\n{}",
        report.join("\n")
    );
}

/// A term whose tangent is left out: the residual of the term it wraps, no blocks.
struct WithoutTangent<'a>(&'a dyn PointTerm);

impl PointTerm for WithoutTangent<'_> {
    fn name(&self) -> &'static str {
        "a term without its tangent"
    }

    fn interior(&self, at: &PointView<'_>, load: &mut InteriorLoad) {
        self.0.interior(
            &PointView {
                tangent: false,
                ..*at
            },
            load,
        );
    }

    fn end(&self, at: &PointView<'_>, load: &mut EndLoad) {
        self.0.end(
            &PointView {
                tangent: false,
                ..*at
            },
            load,
        );
    }
}

/// Source: the test above can fail. The spring to ground without its tangent blocks (its residual unchanged)
/// must show errors of order one (the missing blocks are the whole of its position derivative).
#[test]
fn the_generic_tangent_test_fails_for_a_term_with_a_wrong_tangent() {
    let model = test_model();
    let spring = spring();
    let broken = WithoutTangent(&spring);
    let (worst, _) = term_tangent_error(
        &model,
        Terms {
            point: &[&broken],
            constraints: &[],
        },
    );
    println!("spring to ground without its tangent: worst relative error {worst:.3e}");
    assert!(worst > 0.1, "worst relative error {worst:.3e}");
}

/// Source: a bar on an axial Winkler foundation, clamped at `x = 0` and pulled by `P` at `x = L`:
/// `EA u'' − k u = 0`, `u(0) = 0`, `EA u'(L) = P`, so `u(L) = P tanh(βL) / (EA β)` with `β = √(k/EA)`. The
/// geometrically exact rod is exactly linear in axial stretching (`Γ₁ − 1 = u'`), so this holds at any load.
/// Here `E = 2e5`, `d = 0.1` (`EA = 1570.8`), `L = 1`, `βL = 2`, `P = 10`: `u(L) = 3.07e-3`, less than half of
/// the bar's `P L/EA` without the foundation. Tolerance 1e-5 relative: collocation of degree 6 on 30 control
/// points is accurate to about `(βh)⁶ ≈ 3e-7` for this exponential profile; a missing foundation is a 100 %
/// error. The spring joins the simulation by one line (`add_term`).
#[test]
fn a_bar_on_a_spring_foundation_stretches_as_the_closed_form() {
    let (e, d, length, beta_l, force) = (2.0e5, 0.1, 1.0, 2.0, 10.0);
    let material = ElasticLaw::try_new(e, 0.3).expect("E > 0, ν = 0.3");
    let section = CircularSection::try_new(d).expect("d > 0").into();
    let mut b = ModelBuilder::new("foundation", material, section);
    b.patch(
        "bar",
        PatchShape::Line {
            from: Vec3::zeros(),
            to: Vec3::new(length, 0.0, 0.0),
        },
        6,
        30,
    );
    b.condition(ConditionSpec::clamp("bar.start"));
    b.condition(ConditionSpec::at("bar.end").with_force(0, TimeFunction::constant(force)));
    b.time(TimeSpec::new(1.0, 1.0));
    let model = b.build().expect("valid model").model;
    let ea = e * std::f64::consts::PI * d * d / 4.0;
    let beta = beta_l / length;
    let mut sim = Simulation::new(&model).expect("simulation");
    sim.add_term(Box::new(SpringToGround {
        foundation: beta * beta * ea,
        rotational_foundation: 0.0,
        end: 0.0,
        rotational_end: 0.0,
    }));
    while sim.step().expect("converges").is_some() {}
    let tip = model
        .nodes
        .iter()
        .position(|n| n.name == "bar.end")
        .expect("node bar.end");
    let u = sim.probe_displacement(&ProbeLocation::Node(tip));
    let expected = force * beta_l.tanh() / (ea * beta);
    println!(
        "bar on a foundation: u(L) = {:.9e}, closed form {expected:.9e}",
        u.x
    );
    assert!(
        ((u.x - expected) / expected).abs() < 1e-5,
        "u(L) = {:.9e}, closed form {expected:.9e}",
        u.x
    );
    assert!(u.y.abs() < 1e-12 && u.z.abs() < 1e-12, "u = {u:?}");
}

/// A stateful test term: a foundation anchored where the rod was at the last converged step (a tissue that
/// remodels around the device), force density `−k (c − a)` at the interior points, the anchors `a` moved to
/// the converged positions at every commit.
struct RelaxingSpring {
    /// Stiffness `k` \[force/length²\].
    stiffness: Real,
    /// Anchor of every collocation point \[length\] (ends unused).
    anchors: Vec<Vec3>,
}

impl RelaxingSpring {
    /// Anchored at the reference positions.
    fn new(disc: &Discretisation, stiffness: Real) -> Self {
        let anchors = (0..disc.points.len())
            .map(|g| crate::solver::assembly::point_position(disc, &disc.control0, g))
            .collect();
        Self { stiffness, anchors }
    }
}

impl PointTerm for RelaxingSpring {
    fn name(&self) -> &'static str {
        "relaxing spring"
    }

    fn interior(&self, at: &PointView<'_>, load: &mut InteriorLoad) {
        load.add_force(-(at.position() - self.anchors[at.g]) * self.stiffness);
        if at.tangent {
            load.add_force_position(-at.rotation_t * self.stiffness);
        }
    }

    fn commit(&mut self, disc: &Discretisation, state: &State) {
        for (g, a) in self.anchors.iter_mut().enumerate() {
            *a = crate::solver::assembly::point_position(disc, &state.control, g);
        }
    }

    fn save(&self, out: &mut Vec<Real>) {
        out.extend(self.anchors.iter().flat_map(|a| a.iter().copied()));
    }

    fn restore(&mut self, values: &[Real]) -> Result<(), usize> {
        if values.len() != 3 * self.anchors.len() {
            return Err(3 * self.anchors.len());
        }
        for (a, v) in self.anchors.iter_mut().zip(values.chunks_exact(3)) {
            *a = Vec3::new(v[0], v[1], v[2]);
        }
        Ok(())
    }
}

/// Source: the checkpoint contract ([`Simulation::restore`]: a restored simulation continues bit for bit) for a
/// term with a state of its own. A bar pulled by a force ramped over four steps, on a foundation that follows it
/// (`RelaxingSpring`, stiffness `k = EA/L²`, so it carries a share of the load comparable to the bar's):
/// checkpointed after two steps, the run continued in a fresh simulation from the checkpoint ends with the same
/// bits as the run that went on; the same checkpoint with the term's state set back to the reference anchors
/// ends elsewhere, so the term's state is what the checkpoint carries (and the comparison can fail).
#[test]
fn a_terms_state_is_committed_and_carried_by_checkpoints() {
    let material = ElasticLaw::try_new(2.0e5, 0.3).expect("E > 0, ν = 0.3");
    let section = CircularSection::try_new(0.1).expect("d > 0").into();
    let mut b = ModelBuilder::new("relaxing", material, section);
    b.patch(
        "bar",
        PatchShape::Line {
            from: Vec3::zeros(),
            to: Vec3::new(1.0, 0.0, 0.0),
        },
        4,
        12,
    );
    b.condition(ConditionSpec::clamp("bar.start"));
    let ramp = TimeFunction::try_table(vec![(0.0, 0.0), (1.0, 10.0)]).expect("a ramp");
    b.condition(
        ConditionSpec::at("bar.end")
            .with_force(0, ramp.clone())
            .with_force(1, ramp),
    );
    b.time(TimeSpec::new(1.0, 0.25));
    let model = b.build().expect("valid model").model;
    let disc = Discretisation::new(&model).expect("discretisation");
    let stiffness = 2.0e5 * std::f64::consts::PI * 0.01 / 4.0;
    let simulation = || {
        let mut sim = Simulation::new(&model).expect("simulation");
        sim.add_term(Box::new(RelaxingSpring::new(&disc, stiffness)));
        sim
    };
    let mut first = simulation();
    for _ in 0..2 {
        first.step().expect("converges");
    }
    let checkpoint = first.checkpoint();
    assert_eq!(
        checkpoint.snapshot.terms.len(),
        3,
        "distributed load, wire crossing and the spring"
    );
    assert!(checkpoint.snapshot.terms[0].is_empty());
    // The wire crossing's: no step with an overlap (a count of 0, its first time, no deepest overlap and no
    // touch recorded).
    assert_eq!(checkpoint.snapshot.terms[1], [0.0; 4]);
    let anchors = &checkpoint.snapshot.terms[2];
    let reference: Vec<Real> = RelaxingSpring::new(&disc, stiffness)
        .anchors
        .iter()
        .flat_map(|a| a.iter().copied())
        .collect();
    assert_ne!(anchors, &reference, "two commits moved the anchors");
    while first.step().expect("converges").is_some() {}
    let mut second = simulation();
    second.restore(&checkpoint).expect("restores");
    while second.step().expect("converges").is_some() {}
    assert_eq!(first.state(), second.state(), "continued bit for bit");
    let mut forgotten = checkpoint.clone();
    forgotten.snapshot.terms[2] = reference;
    let mut third = simulation();
    third.restore(&forgotten).expect("restores");
    while third.step().expect("converges").is_some() {}
    assert_ne!(first.state().control, third.state().control);
    let mut damaged = checkpoint;
    damaged.snapshot.terms[2].pop();
    assert!(matches!(
        simulation().restore(&damaged),
        Err(crate::solver::CheckpointError::Term { expected, .. }) if expected == 3 * disc.points.len()
    ));
}
