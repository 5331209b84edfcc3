//! Unit tests of the solver internals: the consistent tangent against central differences of the residual,
//! and Newton's quadratic convergence.

use super::assembly::{Actions, Assembler, Assembly, Linearisation, Sink, StepMaterial};
use super::discretisation::Discretisation;
use super::state::State;
use super::terms::damping::Damping;
use super::terms::distributed::DistributedLoad;
use super::terms::{PointTerm, Terms};
use crate::material::{CircularSection, ConstitutiveLaw, ElasticLaw, SectionLaw};
use crate::math::{Real, Vec3};
use crate::model::builder::{
    ConditionSpec, DistributedLoadSpec, JointRule, ModelBuilder, PatchShape, PatchTarget, TimeSpec,
};
use crate::model::{Model, RotationField, SolverSettings, TimeFunction};

/// A curved, loaded, two-patch test structure: a 60° arc (NURBS, so the rational basis is exercised) clamped at
/// its start and joined at an angle to a straight patch whose free end carries a force and a couple; a
/// distributed load acts on the arc. Elastic, ν = 0.3.
pub(super) fn test_model() -> Model {
    test_model_with(RotationField::default())
}

/// [`test_model`] with the rotation field `rotations`.
pub(super) fn test_model_with(rotations: RotationField) -> Model {
    let material = ElasticLaw::try_new(2.0e5, 0.3).expect("E > 0, ν = 0.3");
    let section = CircularSection::try_new(0.1).expect("d > 0").into();
    let mut b = ModelBuilder::new("tangent_test", material, section);
    b.patch(
        "arc",
        PatchShape::Arc {
            centre: Vec3::new(0.0, 1.0, 0.0),
            start: Vec3::zeros(),
            axis: Vec3::new(0.2, 0.0, 1.0),
            angle: 60.0_f64.to_radians(),
        },
        4,
        9,
    );
    b.patch(
        "leg",
        PatchShape::Line {
            from: Vec3::new(0.84920778, 0.5, -0.16984156),
            to: Vec3::new(1.2, 0.9, 0.4),
        },
        4,
        12,
    );
    b.joints(JointRule {
        automatic: true,
        tolerance: Some(1e-6),
    });
    b.condition(ConditionSpec::clamp("arc.start"));
    let constant = TimeFunction::constant;
    b.condition(
        ConditionSpec::at("leg.end")
            .with_force(0, constant(3.0))
            .with_force(1, constant(-2.0))
            .with_force(2, constant(5.0))
            .with_moment(0, constant(0.5))
            .with_moment(1, constant(1.0))
            .with_moment(2, constant(-0.7)),
    );
    b.distributed_load(DistributedLoadSpec {
        patches: PatchTarget::Named("arc".into()),
        force: [constant(0.0), constant(0.0), constant(-4.0)],
        couple: [constant(0.3), constant(0.0), constant(0.0)],
    });
    b.time(TimeSpec::new(1.0, 1.0));
    b.solver(SolverSettings {
        rotations,
        ..SolverSettings::default()
    });
    let model = b.build().expect("valid test model").model;
    assert_eq!(
        model.nodes.len(),
        3,
        "the arc's end and the leg's start are joined"
    );
    model
}

/// The tangent of `at` as a dense matrix (entries at the same place summed), rows and columns including the
/// constraints' multipliers.
pub(super) fn dense_tangent(asm: &Assembler, at: &Assembly<'_>) -> Vec<Vec<Real>> {
    let n = at.disc.num_unknowns() + at.terms.multipliers();
    let mut pattern = Vec::new();
    let mut lin = Linearisation::default();
    asm.assemble(at, &mut lin, &mut Sink::Pattern(&mut pattern));
    let mut values = vec![0.0; pattern.len()];
    asm.assemble(
        at,
        &mut lin,
        &mut Sink::Values {
            values: &mut values,
            next: 0,
        },
    );
    let mut k = vec![vec![0.0; n]; n];
    for (&(r, c), v) in pattern.iter().zip(&values) {
        k[r][c] += v;
    }
    k
}

/// The residual of `at` (a residual-only assembly).
pub(super) fn residual(asm: &Assembler, at: &Assembly<'_>) -> Vec<Real> {
    let mut lin = Linearisation::default();
    asm.assemble(at, &mut lin, &mut Sink::Discard);
    lin.residual
}

/// A deformed state of `disc`: a smooth finite increment of the reference (translations ~5 % of the size,
/// rotations ~0.3 rad), and `multipliers` multipliers of order 10.
pub(super) fn deformed_state(disc: &Discretisation, multipliers: usize) -> State {
    let n = disc.num_unknowns();
    let mut state = State::reference(disc);
    let delta: Vec<Real> = (0..n)
        .map(|i| {
            let x = i as Real;
            if i % 6 < 3 {
                0.05 * (0.37 * x).sin()
            } else {
                0.3 * (0.21 * x + 1.0).cos()
            }
        })
        .collect();
    state.apply_increment(disc, &delta);
    state.multipliers = (0..multipliers)
        .map(|j| 10.0 * (1.3 * j as Real + 0.4).sin())
        .collect();
    state
}

/// `state` moved by `eps` along unknown `j` (a multiplier when `j` is past the rod's unknowns) under the
/// solver's own update.
pub(super) fn perturbed(disc: &Discretisation, state: &State, j: usize, eps: Real) -> State {
    let mut out = state.clone();
    let mut e = vec![0.0; disc.num_unknowns() + state.multipliers.len()];
    e[j] = eps;
    out.apply_increment(disc, &e);
    out
}

// Source: the tangent must be the exact directional derivative of the residual under the solver's own update
// (additive for δη, `R exp(δΘ̃)` with the K and K,s updates for δΘ). Reference: central differences of the
// assembled residual, step ε = 1e-6 (truncation O(ε²) ≈ 1e-12 relative, round-off ≈ 1e-16/ε = 1e-10 relative
// to the residual scale), in a deformed state reached by a random finite increment from the reference.
// Tolerance: 1e-6 relative to the largest entry of the tangent's row — well above the FD error, far below any
// missing or wrong term (which shows as O(1) relative errors). With both rotation fields: the objective field's
// rotation columns carry its matrices `B_a`, `B_a,s`, `B_a,ss` (module docs of the assembly's `RotationBasis`),
// exercised where the deformed state turns the control points by ~0.3 rad, each differently.
#[test]
fn tangent_matches_central_differences_of_the_residual() {
    with_each_rotation_field(|model, disc, laws| check_tangent(model, disc, laws, None));
}

/// Calls `check` with the test structure of each rotation field, its discretisation and its laws at rest.
fn with_each_rotation_field(check: impl Fn(&Model, &Discretisation, &[SectionLaw])) {
    for rotations in [RotationField::Incremental, RotationField::Objective] {
        let model = test_model_with(rotations);
        let disc = Discretisation::new(&model).expect("discretisation");
        let laws = initial_laws(&model, &disc);
        check(&model, &disc, &laws);
    }
}

// Source: objectivity (`crate::math::quaternion_field`'s module docs). A rigid rotation `Q` of a deformed state of
// the objective field — every control point `c → Q c`, every control rotation `ρ → r ρ` — leaves every strain
// unchanged, to round-off (1e-12 of the largest strain). (That the paper's field's deformed states depend on the
// path is `tests/stentkit/solver.rs`'s.)
#[test]
fn a_rigid_rotation_of_a_deformed_state_leaves_every_strain_unchanged() {
    use crate::math::quaternion_field::quaternion_of;
    let model = test_model_with(RotationField::Objective);
    let disc = Discretisation::new(&model).expect("discretisation");
    let state = deformed_state(&disc, 0);
    let q = crate::math::so3::exp(&Vec3::new(0.7, -1.9, 2.4));
    let r = quaternion_of(q.matrix());
    let mut turned = state.clone();
    for c in &mut turned.control {
        *c = q * *c;
    }
    for rho in &mut turned.orientation {
        *rho = r * *rho;
    }
    turned.sync_rotations(&disc);
    let strains = |s: &State| -> Vec<[Vec3; 4]> {
        (0..disc.points.len())
            .map(|g| {
                let e = super::assembly::point_strains(&disc, s, g);
                [e.force, e.moment, e.force_ds, e.moment_ds]
            })
            .collect()
    };
    let (before, after) = (strains(&state), strains(&turned));
    let scale = before
        .iter()
        .flatten()
        .map(|v| v.norm())
        .fold(0.0, Real::max);
    assert!(scale > 0.1, "a deformed state: largest strain {scale}");
    for (g, (a, b)) in before.iter().zip(&after).enumerate() {
        for (x, y) in a.iter().zip(b) {
            assert!(
                (x - y).norm() <= 1e-12 * scale,
                "point {g}: {x} against {y}"
            );
        }
    }
}

// Source: as above, with the viscous regularisation of automatic stabilisation (issue 18): the residual gains
// `−c A (x − xₙ)/h` and `−c J log(Rₙᵀ R)/h` at the interior points, measured from the reference state as the
// last converged one. `c/h = 1e5` makes the damping force (`1e5 · A · 0.05 ≈ 40`) and couple (`1e5 · 2I · 0.3 ≈
// 0.3`) of the order of the structure's own residual terms, so a wrong or missing term would show as an O(1)
// relative error. Same reference and tolerance; with both rotation fields.
#[test]
fn tangent_matches_central_differences_with_viscous_damping() {
    with_each_rotation_field(|model, disc, laws| {
        let previous = State::reference(disc);
        let damping = Damping {
            previous: &previous,
            rate: 1e5,
        };
        check_tangent(model, disc, laws, Some(&damping));
    });
}

// Source: as above, where the temperature varies along the rods: every point's law has a modulus slope `Ē,s`
// (±30 % of `Ē` per unit length, varying from point to point) and history stresses with their slopes, so the
// residual's `N,s`, `M,s` carry the `C̄,s Γ_N`, `C̄,s K_M` terms whose linearisation the tangent must hold
// (module docs of `material::law`). Same reference and tolerance.
#[test]
fn tangent_matches_central_differences_with_a_modulus_varying_along_the_rod() {
    let model = test_model();
    let disc = Discretisation::new(&model).expect("discretisation");
    let laws: Vec<SectionLaw> = disc
        .points
        .iter()
        .enumerate()
        .map(|(g, p)| {
            let x = g as Real;
            let v = |k: Real| Vec3::new((k * x).sin(), (k + x).cos(), (0.3 * k * x).sin());
            let shape = &disc.shapes[p.shape];
            let history = crate::material::SectionStress {
                force: shape.force.component_mul(&v(1.0)) * 1e3,
                moment: shape.moment.component_mul(&v(2.0)) * 1e3,
                force_ds: shape.force.component_mul(&v(3.0)) * 1e3,
                moment_ds: shape.moment.component_mul(&v(4.0)) * 1e3,
            };
            SectionLaw::with_slope(shape, 2.0e5, 6.0e4 * (0.7 * x + 0.3).sin(), history)
        })
        .collect();
    assert!(laws.iter().all(|l| l.stiffness_slope_matrices().is_some()));
    check_tangent(&model, &disc, &laws, None);
}

/// Every collocation point's section law of `model` at rest (its material's law before any step).
fn initial_laws(model: &Model, disc: &Discretisation) -> Vec<SectionLaw> {
    disc.points
        .iter()
        .map(|p| {
            let law = &model.materials()[model.patches[p.patch].material];
            law.section_law(&law.new_state(vec![disc.shapes[p.shape]]), 0)
        })
        .collect()
}

/// The tangent of `model` with the section laws `laws`, its distributed loads and `damping`, against central
/// differences of its residual (see the tests' sources).
fn check_tangent(
    model: &Model,
    disc: &Discretisation,
    laws: &[SectionLaw],
    damping: Option<&Damping<'_>>,
) {
    let asm = Assembler::new(model, disc);
    let actions = Actions::at(model, 1.0, &[]);
    let mut point: Vec<&dyn PointTerm> = vec![&DistributedLoad];
    point.extend(damping.map(|d| d as &dyn PointTerm));
    let n = disc.num_unknowns();
    let state = deformed_state(disc, 0);
    let terms = Terms {
        point: &point,
        constraints: &[],
    };
    let material = StepMaterial { laws };
    let residual_at = |state: &State| {
        residual(
            &asm,
            &Assembly {
                disc,
                state,
                material,
                actions: &actions,
                terms,
            },
        )
    };
    let k = dense_tangent(
        &asm,
        &Assembly {
            disc,
            state: &state,
            material,
            actions: &actions,
            terms,
        },
    );
    let eps = 1e-6;
    let mut worst: Real = 0.0;
    let mut report = Vec::new();
    for j in 0..n {
        let (plus, minus) = (
            perturbed(disc, &state, j, eps),
            perturbed(disc, &state, j, -eps),
        );
        let rp = residual_at(&plus);
        let rm = residual_at(&minus);
        for i in 0..n {
            let fd = (rp[i] - rm[i]) / (2.0 * eps);
            let row_scale = k[i].iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(1e-300);
            let err = (fd - k[i][j]).abs() / row_scale;
            if err > 1e-6 && report.len() < 20 {
                report.push(format!("row {i} (point {}, comp {}) col {j} (ctrl {}, comp {}): tangent {:.6e}, fd {:.6e}", i / 6, i % 6, j / 6, j % 6, k[i][j], fd));
            }
            worst = worst.max(err);
        }
    }
    assert!(
        worst < 1e-6,
        "worst relative error {worst:.3e}:\n{}",
        report.join("\n")
    );
}
