//! Unit tests of the solver internals: the consistent tangent against central differences of the residual,
//! and Newton's quadratic convergence.

use super::assembly::{Actions, Assembler, Linearisation, Sink, StepMaterial};
use super::discretisation::Discretisation;
use super::state::State;
use crate::io::design::parse_design;
use crate::material::{ConstitutiveLaw, SectionLaw};
use crate::math::Real;
use crate::model::Model;
use std::path::Path;

/// A curved, loaded, two-patch test structure: a 60° arc (NURBS, so the rational basis is exercised) clamped at
/// its start and joined at an angle to a straight patch whose free end carries a force and a couple; a
/// distributed load acts on the arc. Elastic, ν = 0.3.
fn test_model() -> Model {
    let text = r#"
units: SI
material: {E_inf: 2.0e5, nu: 0.3}
section: {diameter: 0.1}
mesh: {p: 4, n: 9}
patches:
  - name: arc
    arc: {center: [0, 1, 0], start: [0, 0, 0], axis: [0.2, 0, 1], angle_deg: 60}
  - name: leg
    line: {from: [0.84920778, 0.5, -0.16984156], to: [1.2, 0.9, 0.4]}
joints: {tolerance: 1.0e-6}
conditions:
  - {node: arc.start, clamp: true}
  - node: leg.end
    force: [3, -2, 5]
    moment: [0.5, 1, -0.7]
distributed_loads:
  - {patch: arc, force: [0, 0, -4], couple: [0.3, 0, 0]}
time: {end: 1, step: 1}
"#;
    let model = parse_design(text, Path::new("tangent_test.yaml"))
        .expect("valid test design")
        .model;
    assert_eq!(
        model.nodes.len(),
        3,
        "the arc's end and the leg's start are joined"
    );
    model
}

fn dense_tangent(
    disc: &Discretisation,
    asm: &Assembler,
    state: &State,
    material: StepMaterial<'_>,
    actions: &Actions,
) -> Vec<Vec<Real>> {
    let n = disc.num_unknowns();
    let mut pattern = Vec::new();
    let mut lin = Linearisation::default();
    asm.assemble(
        disc,
        state,
        material,
        actions,
        None,
        &mut lin,
        &mut Sink::Pattern(&mut pattern),
    );
    let mut values = vec![0.0; pattern.len()];
    asm.assemble(
        disc,
        state,
        material,
        actions,
        None,
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

fn residual(
    disc: &Discretisation,
    asm: &Assembler,
    state: &State,
    material: StepMaterial<'_>,
    actions: &Actions,
) -> Vec<Real> {
    let mut lin = Linearisation::default();
    asm.assemble(
        disc,
        state,
        material,
        actions,
        None,
        &mut lin,
        &mut Sink::Discard,
    );
    lin.residual
}

// Source: the tangent must be the exact directional derivative of the residual under the solver's own update
// (additive for δη, `R exp(δΘ̃)` with the K and K,s updates for δΘ). Reference: central differences of the
// assembled residual, step ε = 1e-6 (truncation O(ε²) ≈ 1e-12 relative, round-off ≈ 1e-16/ε = 1e-10 relative
// to the residual scale), in a deformed state reached by a random finite increment from the reference.
// Tolerance: 1e-6 relative to the largest entry of the tangent's row — well above the FD error, far below any
// missing or wrong term (which shows as O(1) relative errors).
#[test]
fn tangent_matches_central_differences_of_the_residual() {
    let model = test_model();
    let disc = Discretisation::new(&model).expect("discretisation");
    let asm = Assembler::new(&model, &disc);
    let actions = Actions::at(&model, 1.0, &[]);
    let laws: Vec<SectionLaw> = disc
        .points
        .iter()
        .map(|p| {
            let law = &model.materials[model.patches[p.patch].material];
            law.section_law(&law.new_state(vec![disc.shapes[p.shape]]), 0)
        })
        .collect();
    let material = StepMaterial { laws: &laws };
    let n = disc.num_unknowns();
    // A deformed state: a smooth finite increment (translations ~5 % of the size, rotations ~0.3 rad).
    let mut state = State::reference(&disc);
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
    state.apply_increment(&disc, &delta);
    let k = dense_tangent(&disc, &asm, &state, material, &actions);
    let eps = 1e-6;
    let mut worst: Real = 0.0;
    let mut report = Vec::new();
    for j in 0..n {
        let mut plus = state.clone();
        let mut minus = state.clone();
        let mut e = vec![0.0; n];
        e[j] = eps;
        plus.apply_increment(&disc, &e);
        e[j] = -eps;
        minus.apply_increment(&disc, &e);
        let rp = residual(&disc, &asm, &plus, material, &actions);
        let rm = residual(&disc, &asm, &minus, material, &actions);
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
