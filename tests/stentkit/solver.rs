//! Verification of the solver against closed forms, published benchmarks and an independent numerical
//! reference (STYLE 15): Newton's quadratic convergence, the roll-up of a cantilever into a circle, the 45°
//! bend of Bathe & Bolourchi, the same bend split into several patches, and equilibrium of an L-shaped frame.
//! Run with `--nocapture` to see the measured numbers (iterations, timings, errors, rates).

use crate::common::{
    BATHE_BOLOURCHI_1979_TIP, SIMO_VU_QUOC_1986_TIP, bend45_reference_tip,
    bend45_shooting_displacement, centreline_point, fixtures, log_log_slope, model_from_text,
    node_displacement, node_index, rollup_centreline, solve,
};
use stentkit::material::ElasticLaw;
use stentkit::math::{Real, Vec3};
use stentkit::model::builder::{ConditionSpec, ModelBuilder, NodeEnds, PatchShape, TimeSpec};
use stentkit::model::{Model, ProbeLocation, RotationField, SolverSettings, TimeFunction};
use stentkit::solver::Simulation;

/// A model the builder accepts without warnings.
#[track_caller]
fn built(b: &ModelBuilder) -> Model {
    let built = b.build().unwrap_or_else(|e| panic!("{e}"));
    assert!(built.warnings.is_empty(), "{:?}", built.warnings);
    built.model
}

/// The 45° bend (designs/bend45.yaml) at degree `p` with `n` control points, in `steps` load steps.
fn bend45(p: usize, n: usize, steps: usize) -> Model {
    fixtures::bend45()
        .mesh(p, n)
        .time(1.0, 1.0 / steps as Real)
        .model()
}

// ---------------------------------------------------------------------------------------------------------
// 1. Newton's method converges quadratically.
//
// Source: Newton's method with the exact (consistent) tangent converges quadratically near the solution
// (e.g. Wriggers, Nonlinear Finite Element Methods, §5.1); the tangent is checked against finite differences in
// the solver's unit tests, this checks the whole loop (assembly, LU, multiplicative update of R, K, K,s).
// Problem: the 45° bend (below), p = 6, n = 20, tip load 0 → 600 in 50 steps of 12 (dimensionless benchmark
// units; each step moves the tip by about 1.5 % of the bend's length), each starting from the last
// converged state.
// Measure: the normalised increment norms e_k of every step (translations / patch length, rotations in rad:
// e_k is the error of iterate k to first order). A pair (e_k, e_{k+1}) is pre-round-off when the residual
// that e_{k+1} was solved from is above 1e-9 (ten times the residual's round-off floor, 3e-11 … 1.5e-10 here);
// the order estimate of a step is log e_{k+1} / log e_k for its last such pair.
// Tolerance: with e_{k+1} = C e_k² the estimate is 2 + ln C / ln e_k; the last pre-round-off pairs have
// e_k ≈ 2e-5 … 5e-4 and C ≤ 10 (measured), so it lies in 1.75 … 2.2: we assert ≥ 1.7 in every step and
// C = e_{k+1}/e_k² < 100 for every last pair. Linear convergence at any rate ρ would give C = ρ/e_k, ≳ 1e3 at
// these e_k, or an estimate 1 + ln ρ / ln e_k < 1.7 unless ρ < 1e-3. (The first two steps measure 1.76 and
// 1.78, the other 48 at least 1.8.) The constant C of the intermediate iterations can be much larger
// (up to ~1e4 ≈ (p n)²: the second-order terms of the strong form carry δΘ,s² and δΘ × δΘ,ss), which is why
// large load steps take a few iterations to reach the quadratic regime; the sequences are printed.
#[test]
fn newton_converges_quadratically() {
    // Newton's method proper from the last converged state: a factorisation per iteration (the default reuses it
    // while it contracts) and no extrapolated start (which puts the first iterate inside the quadratic basin).
    let mut b = fixtures::bend45_builder(1, 6, 20, 50);
    b.solver(SolverSettings {
        reuse_factorisation: false,
        extrapolate: false,
        ..SolverSettings::default()
    });
    let model = built(&b);
    let (_, rec) = solve(&model);
    let pre_round_off = 1e-9;
    let mut orders = Vec::new();
    for s in &rec.steps {
        let nr = &s.report.newton;
        let (r, e) = (&nr.residuals, &nr.increments);
        let last = (0..e.len().saturating_sub(1))
            .rev()
            .find(|&k| r[k + 1] >= pre_round_off)
            .unwrap_or_else(|| panic!("step {}: no pre-round-off pair", s.report.step));
        let q = e[last + 1].ln() / e[last].ln();
        if s.report.step % 10 == 1 || s.report.step == rec.steps.len() {
            println!(
                "step {} (load {:.0}): {} iterations",
                s.report.step,
                600.0 * s.report.time,
                nr.iterations
            );
            println!("  normalised residuals  {:?}", fmt(r));
            println!("  normalised increments {:?}", fmt(e));
            println!(
                "  order of the last pre-round-off pair log e_{}/log e_{} = {q:.2}, e_{}/e_{}² = {:.1e}",
                last + 1,
                last,
                last + 1,
                last,
                e[last + 1] / (e[last] * e[last])
            );
        }
        orders.push((s.report.step, q, e[last + 1] / (e[last] * e[last])));
    }
    let lowest =
        orders.iter().copied().fold(
            (0, Real::INFINITY, 0.0),
            |a, b| if b.1 < a.1 { b } else { a },
        );
    let above = orders.iter().filter(|o| o.1 >= 1.8).count();
    let largest_constant = orders.iter().map(|o| o.2).fold(0.0, Real::max);
    println!(
        "{}\nlowest order estimate {:.2} (step {}); {above} of {} steps ≥ 1.8; largest e_k+1/e_k² {largest_constant:.1e}",
        rec.summary(),
        lowest.1,
        lowest.0,
        orders.len()
    );
    assert!(
        lowest.1 >= 1.7,
        "step {}: convergence order {:.2} < 1.7",
        lowest.0,
        lowest.1
    );
    assert!(
        largest_constant < 1e2,
        "e_k+1/e_k² up to {largest_constant:.1e}"
    );
}

fn fmt(v: &[Real]) -> Vec<String> {
    v.iter().map(|x| format!("{x:.2e}")).collect()
}

// ---------------------------------------------------------------------------------------------------------
// 2. Roll-up of a cantilever into a full circle.
//
// Source: closed form (tests/common `rollup_centreline`; Simo & Vu-Quoc 1986 Part II §7.1). Sketch: a straight
// cantilever of length L = 10 along +x, clamped at the origin; a dead end couple M = 2π EI / L about +z
// (EI = 1e6) curls it into a circle of radius R = L / 2π through the origin: c(s) = (R sin(s/R),
// R(1 − cos(s/R)), 0). Consistent dimensionless units (designs/rollup.yaml).
// Measure: max over 101 points u ∈ [0, 1] (s = L u, the reference line is parametrised uniformly) of
// |c_h(s) − c(s)| / L, for p = 3 … 8 and growing n; the couple in 20 steps.
// n = 16, 24, 32, 48, 64 (coarser meshes are far from resolving a full circle: p = 3 is not yet monotone there
// and p = 4, n = 8 fails to converge past a half turn).
// Tolerance: the error must fall with n (or be below 1e-9, the Newton floor); the slope over the last three n
// must be at least the known rate (p for even, p − 1 for odd p) less 0.7 — measured 1.7, 4.7, 4.4, 7.1, 7.1 and
// 12.5 for p = 3 … 8 (p = 8 super-converges, as in the paper); at n = 64 the error must be below bounds about
// 5–10 times the measured values.
#[test]
fn rollup_becomes_a_full_circle() {
    let length = 10.0;
    let mut report = Vec::new();
    for p in 3..=8usize {
        let ns = [16usize, 24, 32, 48, 64];
        let mut errors = Vec::new();
        for &n in &ns {
            // Newton's method proper: the algebraic error must be far below the finest discretisation error
            // (5.6e-13), and quadratic convergence puts the iterate at ~‖Δ‖² when the estimated error (Hairer's
            // θ/(1 − θ)‖Δ‖) passes the tolerance, where the chord method stops at ~1e-9.
            let model = fixtures::rollup()
                .mesh(p, n)
                .set("solver.reuse_factorisation", "false")
                .model();
            let (sim, _) = solve(&model);
            let error = (0..=100)
                .map(|i| {
                    let u = i as Real / 100.0;
                    let x0 = model.patches[0].curve.point(u);
                    (centreline_point(&sim, 0, u) - rollup_centreline(x0.x, length)).norm() / length
                })
                .fold(0.0, Real::max);
            errors.push((n as Real, error));
        }
        let rate = -log_log_slope(&errors[errors.len() - 3..]);
        println!(
            "roll-up p = {p}: (n, max |c_h − c| / L) = {:?}; slope over the last three {rate:.2}",
            errors
                .iter()
                .map(|(n, e)| format!("({n}, {e:.2e})"))
                .collect::<Vec<_>>()
        );
        report.push((p, errors));
    }
    for (p, errors) in &report {
        for w in errors.windows(2) {
            assert!(
                w[1].1 < w[0].1 || w[1].1 < 1e-9,
                "p = {p}: the error does not fall from n = {} to n = {}: {:.3e} → {:.3e}",
                w[0].0,
                w[1].0,
                w[0].1,
                w[1].1
            );
        }
        let finest = errors.last().expect("at least one n").1;
        // About 5–10 times the measured errors at n = 64 (1.6e-2, 1.9e-6, 3.5e-6, 2.7e-9, 1.2e-9, 5.6e-13).
        let bound = match p {
            3 => 1e-1,
            4 => 1e-5,
            5 => 2e-5,
            6 => 2e-8,
            7 => 1e-8,
            _ => 1e-11,
        };
        assert!(
            finest < bound,
            "p = {p}: finest error {finest:.3e} ≥ {bound:.0e}"
        );
        let expected = if p % 2 == 0 {
            *p as Real
        } else {
            (p - 1) as Real
        };
        let rate = -log_log_slope(&errors[errors.len() - 3..]);
        assert!(
            rate >= expected - 0.7,
            "p = {p}: rate {rate:.2} < {expected} − 0.7"
        );
    }
}

// ---------------------------------------------------------------------------------------------------------
// 3. The 45° bend of Bathe & Bolourchi (1979).
//
// Sources: Bathe & Bolourchi, IJNME 14 (1979) 961–986; Simo & Vu-Quoc, CMAME 58 (1986) 79–116, §7.5; and a
// converged solution by a different method: shooting on the rod ODEs (scripts/bend45_reference.py, DOP853 at
// 1e-13, output in tests/data/bend45_reference.txt).
// Sketch: a 45° arc of radius 100 in the x–y plane (centre (0, 100, 0)), clamped at the origin with tangent
// +x, dead tip force 600 along +z (out of plane: bending and torsion). A = 1, I = 1/12, J = 1/6 (GJ = EI),
// k_s = 5/6, E = 1e7, ν = 0; the benchmark's inch/lbf, consistent.
// Tolerances: the published tip positions come from eight-element meshes and are quoted to 3–4 digits; ours
// differs from them by 0.2–0.3 % of |x_tip| (the y component by up to 1.4 %), so 1 % of |x_tip| in norm.
// Against the shooting reference (accurate to ~1e-11): p = 6, n = 80 measured ≈ 3e-9 relative, so 1e-7
// leaves room for platform round-off but not for any modelling error (those show at 1e-4 and up).
#[test]
fn bend45_matches_published_values_and_a_shooting_reference() {
    let reference = bend45_shooting_displacement();
    let x0 = bend45_reference_tip();
    for (p, n) in [(6, 20), (6, 80)] {
        let model = bend45(p, n, 10);
        let (sim, rec) = solve(&model);
        let u = node_displacement(&sim, "tip");
        let tip = x0 + u;
        let rel = (u - reference).norm() / reference.norm();
        println!(
            "bend45 p = {p}, n = {n}: tip position ({:.6}, {:.6}, {:.6}), displacement ({:.9}, {:.9}, {:.9}); \
             |u − u_ref| / |u_ref| = {rel:.2e}",
            tip.x, tip.y, tip.z, u.x, u.y, u.z
        );
        println!("  {}", rec.summary());
        for (name, published) in [
            ("Bathe & Bolourchi 1979", BATHE_BOLOURCHI_1979_TIP),
            ("Simo & Vu-Quoc 1986", SIMO_VU_QUOC_1986_TIP),
        ] {
            let published = Vec3::from(published);
            let d = (tip - published).norm() / published.norm();
            println!("  vs {name} {published:?}: {:.3} % of |x_tip|", 100.0 * d);
            assert!(d < 0.01, "{name}: {:.3} % off", 100.0 * d);
        }
        if n == 80 {
            assert!(
                rel < 1e-7,
                "p = 6, n = 80: relative error {rel:.3e} vs the shooting reference"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------------------
// 4. One beam, several patches.
//
// Source: a joint of two patch ends with continuity of position and rotation and nodal equilibrium (DESIGN §4
// "Joints") is an exact statement of the continuum problem, so splitting a rod into patches changes only the
// discretisation error. Sketch: the 45° bend split into 1, 2 and 5 exact arcs of equal angle, joined end to
// start, p = 6 and about 60 control points in all (60, 2 × 30, 5 × 12).
// Measure: each tip displacement against the shooting reference (its discretisation error e) and against the
// single patch (d). Measured: e = 2.6e-8, 4.7e-8, 2.2e-7 (the 5-patch mesh, n = 12 per patch, is the coarsest);
// d = 2.0e-8 and 2.0e-7 relative to |u_ref|.
// Tolerance: e < 1e-6 and d < 1e-6 — about five times the coarsest run's measured error; a joint that lost
// moment transmission or rotation continuity changes the tip by O(1).
#[test]
fn splitting_the_bend_into_patches_changes_only_the_discretisation_error() {
    let reference = bend45_shooting_displacement();
    let mut results = Vec::new();
    for (patches, n) in [(1usize, 60usize), (2, 30), (5, 12)] {
        let model = built(&fixtures::bend45_builder(patches, 6, n, 10));
        assert_eq!(model.patches.len(), patches);
        let (sim, rec) = solve(&model);
        let u = node_displacement(&sim, "tip");
        let e = (u - reference).norm() / reference.norm();
        println!(
            "bend45 in {patches} patch(es) of n = {n}, p = 6: tip displacement ({:.9}, {:.9}, {:.9}), error vs \
             shooting {e:.2e}; {}",
            u.x,
            u.y,
            u.z,
            rec.summary()
        );
        results.push((patches, u, e));
    }
    let (_, u1, e1) = results[0];
    for &(patches, u, e) in &results {
        assert!(
            e < 1e-6,
            "{patches} patches: error {e:.3e} vs the shooting reference"
        );
        let d = (u - u1).norm() / reference.norm();
        println!("  {patches} patches vs 1 patch: {d:.2e}");
        assert!(
            d < 1e-6,
            "{patches} patches differ from 1 patch by {d:.3e} (errors {e:.2e}, {e1:.2e})"
        );
    }
}

// ---------------------------------------------------------------------------------------------------------
// 5. Equilibrium of an L-shaped frame.
//
// Source: statics. Sketch: leg a from the clamp at (0, 0, 0) to the knee at (1, 0, 0); leg b from the knee to
// the tip at (1, 0.8, 0); circular section d = 0.05 m, E = 2e9 Pa, ν = 0.3 (SI); dead tip force
// F = (30, −40, 60) N and couple M = (5, −8, 12) N·m in 10 steps (tip deflection ≈ 0.2 m: large rotations).
// No load at the knee.
// Checks, with `node_end_resultants` (per end σ R N, σ R M; their sum is the node's applied load, or its
// reaction at prescribed components):
// (a) knee: Σ over its two ends = 0. These sums are exactly the solver's knee equilibrium rows, converged to
//     a normalised residual below 100 × tol = 1e-7 with scales E A (forces) and E I / L (moments); so the
//     tolerance is 1e-7 E A for forces and 1e-7 E I / L for moments, and the test prints how far below it is.
// (b) global: the clamp's reaction (f_r, m_r) balances the load: f_r + F = 0 and
//     m_r + M + (c_tip − c_clamp) × F = 0. Collocation satisfies the field equations only at the collocation
//     points, so global balance holds to discretisation accuracy, not round-off: with p = 6, n = 20 per leg the
//     measured imbalance is printed and the tolerance is 1e-6 of |F| and of |M| + L|F|.
#[test]
fn l_frame_joint_and_clamp_balance_the_loads() {
    let material = ElasticLaw::try_new(2.0e9, 0.3).expect("E > 0, ν = 0.3");
    let wire = stentkit::material::CircularSection::try_new(0.05).expect("d > 0");
    let mut b = ModelBuilder::new("l_frame", material, wire.into());
    let (clamp, knee, tip) = (Vec3::zeros(), Vec3::x(), Vec3::new(1.0, 0.8, 0.0));
    b.patch(
        "a",
        PatchShape::Line {
            from: clamp,
            to: knee,
        },
        6,
        20,
    );
    b.patch(
        "b",
        PatchShape::Line {
            from: knee,
            to: tip,
        },
        6,
        20,
    );
    b.node("clamp", NodeEnds::Named(vec!["a.start".into()]));
    b.node(
        "knee",
        NodeEnds::Named(vec!["a.end".into(), "b.start".into()]),
    );
    b.node("tip", NodeEnds::Named(vec!["b.end".into()]));
    b.condition(ConditionSpec::clamp("clamp"));
    let ramp = |v: Real| TimeFunction::try_table(vec![(0.0, 0.0), (1.0, v)]).expect("increasing");
    b.condition(
        ConditionSpec::at("tip")
            .with_force(0, ramp(30.0))
            .with_force(1, ramp(-40.0))
            .with_force(2, ramp(60.0))
            .with_moment(0, ramp(5.0))
            .with_moment(1, ramp(-8.0))
            .with_moment(2, ramp(12.0)),
    );
    b.time(TimeSpec::new(1.0, 0.1));
    let model = built(&b);
    let (sim, rec) = solve(&model);
    let f = Vec3::new(30.0, -40.0, 60.0);
    let m = Vec3::new(5.0, -8.0, 12.0);
    let tip = Vec3::new(1.0, 0.8, 0.0) + node_displacement(&sim, "tip");
    println!(
        "L-frame: tip displacement {:?}; {}",
        tip - Vec3::new(1.0, 0.8, 0.0),
        rec.summary()
    );

    let d: Real = 0.05;
    let (e_modulus, area, inertia) = (
        2.0e9,
        std::f64::consts::PI * d * d / 4.0,
        std::f64::consts::PI * d.powi(4) / 64.0,
    );
    let sum = |k: usize| {
        sim.node_end_resultants(k)
            .into_iter()
            .fold((Vec3::zeros(), Vec3::zeros()), |(a, b), (n, m)| {
                (a + n, b + m)
            })
    };
    let (kf, km) = sum(node_index(&model, "knee"));
    let (force_tol, moment_tol) = (1e-7 * e_modulus * area, 1e-7 * e_modulus * inertia / 1.0);
    println!(
        "  knee: |Σ σRN| = {:.2e} N (tolerance {force_tol:.1e}), |Σ σRM| = {:.2e} N·m (tolerance {moment_tol:.1e})",
        kf.norm(),
        km.norm()
    );
    assert!(kf.norm() < force_tol && km.norm() < moment_tol);

    let (rf, rm) = sum(node_index(&model, "clamp"));
    let force_imbalance = (rf + f).norm();
    let moment_imbalance = (rm + m + tip.cross(&f)).norm();
    println!(
        "  clamp reaction f_r = {rf:?}, m_r = {rm:?}; |f_r + F| = {force_imbalance:.2e} N, \
         |m_r + M + c_tip × F| = {moment_imbalance:.2e} N·m"
    );
    assert!(
        force_imbalance < 1e-6 * f.norm(),
        "force imbalance {force_imbalance:.3e}"
    );
    let lever = 1.8;
    assert!(
        moment_imbalance < 1e-6 * (m.norm() + lever * f.norm()),
        "moment imbalance {moment_imbalance:.3e}"
    );
    // The tip's own node row: its end resultant is the applied load.
    let (tf, tm) = sum(node_index(&model, "tip"));
    println!(
        "  tip: |σRN − F| = {:.2e}, |σRM − M| = {:.2e}",
        (tf - f).norm(),
        (tm - m).norm()
    );
    assert!((tf - f).norm() < force_tol && (tm - m).norm() < moment_tol);
}

// ---------------------------------------------------------------------------------------------------------
// Materials per patch: a cantilever of two patches of different materials.
//
// Source: linear Timoshenko beam theory and the series bar (closed forms in tests/common,
// `cantilever_tip_deflection`, `series_bar_elongation`). Sketch: patch a from the clamp at (0, 0, 0) to the
// joint at (0.6, 0, 0), patch b from there to the tip at (1, 0, 0); circular section d = 0.05 m (SI); patch a
// of E1 = 2e9 Pa, ν1 = 0.3, patch b of E2 = 5e8 Pa, ν2 = 0.35 (its own shear modulus and Cowper factor). The
// design file gives the second as a named material of patch b (`Model::materials`, `Patch::material`: the data
// structure under test). Two runs: a transverse tip force P = 0.02 N along z (tip deflection 1.3e-5 of
// the length) and an axial tip force F = 5 kN (strain 1.3e-6 … 5e-6; the rod's axial law is exactly linear).
// The exact linear solutions are cubic in each span, which a degree-6 spline represents exactly; Newton is
// driven to the round-off floor (tolerance 1e-13, a factorisation per iteration), so what is left is the
// geometric nonlinearity, O((δ/L)²): measured 2.2e-10 relative for the deflection, growing as P² (2.2e-8 at
// P = 0.2 N, 2.2e-6 at 2 N), and 1.5e-13 for the elongation. Tolerance 1e-8 for both. Each patch with the
// other's material gives a deflection 16 % (E1 everywhere) or far (E2 everywhere) off, so the test sees whether
// each patch takes its own material.
#[test]
fn a_cantilever_of_two_materials_deflects_as_beam_theory_says() {
    use crate::common::{CantileverSpan, cantilever_tip_deflection, series_bar_elongation};
    use stentkit::material::ConstitutiveLaw;
    let text = |force: &str| {
        format!(
            r#"
version: 1
name: two_materials
units: SI
material: {{E_inf: 2.0e9, nu: 0.3}}
materials:
  - {{name: soft, E_inf: 5.0e8, nu: 0.35}}
section: {{diameter: 0.05}}
mesh: {{p: 6, n: 10}}
patches:
  - name: a
    line: {{from: [0, 0, 0], to: [0.6, 0, 0]}}
  - name: b
    line: {{from: [0.6, 0, 0], to: [1, 0, 0]}}
    material: soft
nodes:
  - {{name: clamp, ends: [a.start]}}
  - {{name: joint, ends: [a.end, b.start]}}
  - {{name: tip, ends: [b.end]}}
conditions:
  - {{node: clamp, clamp: true}}
  - {{node: tip, force: {force}}}
time: {{end: 1.0, step: 1.0}}
solver: {{tolerance: 1.0e-13, reuse_factorisation: false}}
"#
        )
    };
    let (e1, nu1, e2, nu2) = (2.0e9, 0.3, 5.0e8, 0.35);
    let d: Real = 0.05;
    let area = std::f64::consts::PI * d * d / 4.0;
    let inertia = std::f64::consts::PI * d.powi(4) / 64.0;
    let cowper = |nu: Real| 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu);
    let span = |length: Real, e: Real, nu: Real| CantileverSpan {
        length,
        modulus: e,
        shear_modulus: cowper(nu) * e / (2.0 * (1.0 + nu)),
    };
    let spans = [span(0.6, e1, nu1), span(0.4, e2, nu2)];
    for (force, direction, expected) in [
        (
            "[0, 0, 0.02]",
            Vec3::z(),
            cantilever_tip_deflection(&spans, area, inertia, 0.02),
        ),
        (
            "[5000.0, 0, 0]",
            Vec3::x(),
            series_bar_elongation(&spans, area, 5000.0),
        ),
    ] {
        let model = model_from_text(&text(force), "two_materials.yaml");
        assert_eq!(model.materials().len(), 2, "the design gives two materials");
        assert_eq!(model.patches[1].material, 1);
        assert_eq!(model.materials()[0].poisson(), nu1);
        assert_eq!(model.materials()[1].poisson(), nu2);
        let (sim, _) = solve(&model);
        let tip = node_displacement(&sim, "tip");
        let measured = tip.dot(&direction);
        let error = (measured - expected).abs() / expected.abs();
        // The same model with one material everywhere, to show the test tells the materials apart.
        let mut single = model.clone();
        single.patches[1].material = 0;
        let (sim1, _) = solve(&single);
        let one = node_displacement(&sim1, "tip").dot(&direction);
        println!(
            "two materials, tip force {force}: δ = {measured:.9e} m, beam theory {expected:.9e} m, relative error {error:.2e} (material 0 everywhere: {one:.6e} m)"
        );
        assert!(error < 1e-8, "relative error {error:e}");
        assert!((one - expected).abs() > 0.1 * expected.abs());
    }
}

// ---------------------------------------------------------------------------------------------------------
// 8. Newton's stopping rule delivers the accuracy it promises (issue 14, item 0).
//
// Source: the same runs with a tolerance a thousand times tighter (1e-12; round-off then sets the floor, 1e-9 at
// worst, ROUND_OFF_TOLERANCE), and the path independence of an elastic end state. The stopping rule estimates
// the error left after the last increment from the contraction of the last two (Hairer & Wanner, §IV.8); the
// ratio of the first increment of a step solved with an earlier step's factorisation to the next one is not a
// contraction (that increment answers the load's change), and reading it as one accepted errors of 1e-7 at the
// default tolerance 1e-9 (the arch below: 1.9e-7 m at t = 3 s; the committed convergence curve flattened at
// 1.6e-6).
// Tolerances: 1e-8 (ten times the Newton tolerance: the error left is at most the tolerance in the normalised
// increment norm, translations over the patch length, and the tight run's own floor is ~1e-9).

/// The viscoelastic circular arch of designs/circular_arch.yaml at p = 8, n = 32 to t = 3 s (3000 steps of 1 ms,
/// as the committed convergence study), with the given Newton tolerance: the tip displacement at every step.
fn arch_tip_history(tolerance: Real) -> Vec<Vec3> {
    let model = fixtures::design("circular_arch.yaml")
        .mesh(8, 32)
        .set("solver.tolerance", &format!("{tolerance:e}"))
        .time(3.0, 1.0e-3)
        .model();
    let tip = node_index(&model, "tip");
    let mut sim = Simulation::new(&model).expect("simulation");
    let mut history = Vec::new();
    while sim.step().expect("step converges").is_some() {
        history.push(sim.probe_displacement(&ProbeLocation::Node(tip)));
    }
    history
}

// Measured: largest difference over the 3000 steps 1.9e-9 m (the arch is 1.57 m long: 1.2e-9 normalised); the
// rule before this fix gave 1.9e-7 m at t = 3 s.
#[test]
fn at_the_default_tolerance_newton_leaves_errors_below_it() {
    let length = std::f64::consts::FRAC_PI_2;
    let default = arch_tip_history(SolverSettings::default().tolerance);
    let tight = arch_tip_history(1e-12);
    assert_eq!(default.len(), tight.len());
    let worst = default
        .iter()
        .zip(&tight)
        .map(|(a, b)| (a - b).norm() / length)
        .fold(0.0, Real::max);
    println!(
        "arch p = 8, n = 32: largest |u_tip(1e-9) − u_tip(1e-12)| / L over 3000 steps = {worst:.2e}"
    );
    assert!(worst < 1e-8, "Newton error {worst:.2e} above 1e-8");
}

// An elastic end state does not depend on the load path, so the bend's tip after 20, 25, 40 and 50 load steps
// must agree to the Newton tolerance. Measured (p = 8, n = 20, default tolerance): within 7e-10 of one another
// and of the tolerance-1e-13 runs. Fewer steps are not independent even at a tolerance of 1e-13 — 4 steps differ
// from 50 by 6e-5, 10 steps by 3e-7 — because the paper's update of rotations and curvatures at the collocation
// points by interpolated incremental rotations (DESIGN §4 "Updates") makes the discrete solution depend on the
// path, like Simo & Vu-Quoc's (Jelenić & Crisfield, CMAME 171, 1999); that part is a discretisation error:
// with 4 steps it falls from 6e-5 at n = 20 to 2e-7 at n = 40 and 2e-9 at n = 80 (measured).
#[test]
fn the_elastic_bend_ends_where_it_ends_whatever_the_number_of_load_steps() {
    assert_same_tip(&[20, 25, 40, 50], RotationField::Incremental, 1e-9, 1e-8);
}

/// Asserts that the bend at p = 8, n = 20 with the rotation field `rotations` and Newton's tolerance `tolerance`
/// ends within `bound` (relative to the tip's displacement) of its first entry's tip after each number of load
/// steps of `steps`.
fn assert_same_tip(steps: &[usize], rotations: RotationField, tolerance: Real, bound: Real) {
    let tips: Vec<Vec3> = (steps.iter())
        .map(|&s| bend45_tip(8, 20, s, rotations, tolerance))
        .collect();
    let scale = tips[0].norm();
    for (s, tip) in steps.iter().zip(&tips).skip(1) {
        let d = (tip - tips[0]).norm() / scale;
        println!(
            "bend45 p = 8, n = 20, {rotations:?}: tip after {s} steps vs {}: {d:.2e}",
            steps[0]
        );
        assert!(d < bound, "{s} steps: {d:.2e}");
    }
}

/// The 45° bend ([`bend45`]'s fixture) at degree `p` with `n` control points in `steps` load steps, with the
/// rotation field `rotations` and Newton's tolerance `tolerance`; its tip displacement.
fn bend45_tip(p: usize, n: usize, steps: usize, rotations: RotationField, tolerance: Real) -> Vec3 {
    let mut b = fixtures::bend45_builder(1, p, n, steps);
    b.solver(SolverSettings {
        rotations,
        tolerance,
        ..SolverSettings::default()
    });
    let model = built(&b);
    let (sim, _) = solve(&model);
    node_displacement(&sim, "tip")
}

// Issue 36, item 2: with the objective rotation field (`stentkit::math::quaternion_field`) the elastic bend's end
// state does not depend on the load steps. Source: path independence of an elastic end state; the paper's field
// (the test above) leaves 4 steps 6e-5 and 10 steps 3e-7 (relative) from 50 at p = 8, n = 20. Here 2, 4, 10 and
// 40 steps at p = 8, n = 20 against each other, at a Newton tolerance of 1e-13 (the default 1e-9 leaves ~1e-8
// between 2 and 10 steps, its stopping rule's error; 1e-12 left 1.1e-10; 1e-13 leaves 3e-11 to 1.1e-10, no
// longer falling with the tolerance and moving with the round-off of the tangent — an equivalent rewriting of
// ω in it moved the largest from 8e-11 to 1.1e-10: the round-off floor of the p = 8 system): within 5e-10
// relative to the tip's displacement, five orders below the paper's field's 6e-5.
#[test]
fn with_the_objective_field_the_bend_ends_where_it_ends_whatever_the_load_steps() {
    assert_same_tip(&[2, 4, 10, 40], RotationField::Objective, 1e-13, 5e-10);
}

// Issue 36, item 2: the objective field converges to the bend's shooting reference (scripts/bend45_reference.py,
// accurate to ~1e-11) as the paper's field does. Measured, absolute errors of the tip displacement (10 load steps,
// Newton tolerance 1e-12; the tip moves ~60), objective / paper's field: p = 6, n = 20, 40, 80: 6.63e-3 /
// 6.47e-3, 2.82e-5 / 2.74e-5, 2.60e-7 / 2.16e-7; p = 8: 1.50e-4 / 1.34e-4, 8.61e-8 / 1.79e-7, 1.88e-8 /
// 1.73e-8 (both at the floor the round-off of the p = 8 system sets: an equivalent rewriting of ω in the
// objective field's tangent moved its p = 6, n = 80 and p = 8, n = 40 and 80 figures to 2.30e-7, 8.26e-8 and
// 2.45e-8). So the issue's "at least as close as
// today" holds at p = 8, n = 40 (2.1 times closer) and misses by 2.5–3 % at p = 6, n = 20 and 40, 9–12 % at
// p = 8, n = 20 and 80 and 20 % at p = 6, n = 80: two discretisations of the same order with their own constants
// (the reference rotation's choice moves them too: with the middle control point alone, which breaks the mirror
// symmetry of a patch with an even count, p = 6, n = 80 measured 2.25e-7 and p = 8, n = 80 6.5e-9). Checked
// here, both fields solved side by side: each doubling of n divides the objective field's error by at least
// 2^p, half the rate p + 1 (measured 235 and 108 at p = 6, 1742 at p = 8 from 20 to 40; its last doubling, at the
// floor, is not held to the rate), and it is nowhere more than 25 % further from the reference than the paper's
// but at that floor (p = 8, n = 80), where both are held to 5e-8, 1e-9 of the tip's displacement.
#[test]
fn the_objective_field_converges_to_the_shooting_reference() {
    let reference = bend45_shooting_displacement();
    for p in [6, 8] {
        let errors: Vec<Real> = [20, 40, 80]
            .into_iter()
            .map(|n| {
                let [objective, paper] = [RotationField::Objective, RotationField::Incremental]
                    .map(|field| (bend45_tip(p, n, 10, field, 1e-12) - reference).norm());
                println!(
                    "bend45 p = {p}, n = {n}: error {objective:.2e} (objective), {paper:.2e} (paper's field)"
                );
                if p == 8 && n == 80 {
                    assert!(objective < 5e-8 && paper < 5e-8, "{objective:.2e}, {paper:.2e}");
                } else {
                    assert!(
                        objective <= 1.25 * paper,
                        "p = {p}, n = {n}: {objective:.2e} against the paper's field's {paper:.2e}"
                    );
                }
                objective
            })
            .collect();
        let rate = (1usize << p) as Real;
        let held = if p == 8 { 1 } else { 2 };
        for pair in errors.windows(2).take(held) {
            assert!(
                pair[1] <= pair[0] / rate,
                "p = {p}: {:.2e} after {:.2e}",
                pair[1],
                pair[0]
            );
        }
    }
}

// Issue 36, item 1: the paper's straight stent at p = 5, n = 20 (its design otherwise unchanged) fails in its
// recovery with the paper's rotation field (no convergence at t = 2.536 s, step 1020: the issue's case), while
// p = 5, n = 18 finishes. With the objective field it runs its whole cycle unaided. Measured on the map of
// p ∈ {4, 5, 6}, n ∈ [14, 40] (81 runs each): the paper's field finishes 66, failing at p = 4 for n = 14 … 19,
// 21 and 25, p = 5 for 14, 15, 16, 20 and 21, and p = 6 for 14 and 17 — a failure that comes and goes with n,
// not a resolution limit; the objective field finishes 74, all but the coarsest (p = 4, n ≤ 19; p = 5, n = 14).
// Checked here on the same mesh cut to two crowns (a small device: 1.9 s), which the paper's field fails at the
// release (t = 1.7508 s, step 705): completed, nothing warned (no stabilisation, no unrecovered device), and
// recovered at the end below the run's own threshold (0.1).
#[test]
fn with_the_objective_field_a_coarse_straight_stent_finishes_its_cycle() {
    let tmp = crate::mesh::TempDir::new("objective-coarse-stent");
    let dir = tmp.join("run");
    let design =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/straight_stent.yaml");
    crate::outputs::run_ok(
        &design,
        &dir,
        &[
            "--quiet",
            "--set",
            "mesh={p: 5, n: 20}",
            "--set",
            "stent.crowns=2",
            "--set",
            "solver.rotations=objective",
        ],
    );
    let summary = crate::common::read_json(&dir.join("summary.json"));
    assert_eq!(summary["status"], "completed", "{summary}");
    assert_eq!(summary["warnings"], serde_json::json!([]), "{summary}");
    let history = std::fs::read_to_string(dir.join("history.csv")).expect("history.csv");
    let recovery = crate::common::history_column(&history, "recovery_ratio_mean");
    let (t, last) = *recovery.last().expect("rows");
    assert!((t - 3.25).abs() < 1e-9 && last < 0.1, "{t}: {last}");
}

// The meshes maps name a failure's phase (before, at or after the release) from the release time each holds for
// its stent: it must be the one the design's model releases at, the earliest release of a prescribed component.
#[test]
fn the_meshes_maps_know_their_stents_release() {
    use stentkit::model::Component;
    use stentkit::study::stability::scenarios::MeshStent;
    for (stent, file) in [
        (MeshStent::Straight, "straight_stent.yaml"),
        (MeshStent::Curved, "curved_stent.yaml"),
    ] {
        let model = crate::common::model_from_text(&crate::common::design_text(file), file);
        let releases: Vec<f64> = (model.nodes.iter())
            .flat_map(|node| &node.conditions.components)
            .filter_map(|c| match c {
                Component::Prescribed { release, .. } => *release,
                Component::Load(_) => None,
            })
            .collect();
        let first = releases.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(!releases.is_empty(), "{file}: no release");
        assert_eq!(stent.release(), first, "{file}");
    }
}

// Issue 36 item 1's map in `study stability` (`--maps meshes`), on the test above's mesh cut to two crowns: the
// paper's field fails at the release there (t = 1.7508 s, measured) and the objective field finishes, and the
// map's paragraph counts them so, per field, naming the phase of the failure.
#[test]
fn the_meshes_map_counts_the_coarse_stent_that_fails_with_the_papers_field_only() {
    use stentkit::model::RotationField;
    use stentkit::study::stability::scenarios::{MeshCase, MeshStent, meshes_map, meshes_report};
    let cases = [RotationField::Incremental, RotationField::Objective].map(|rotations| MeshCase {
        p: 5,
        n: 20,
        rotations,
    });
    let map = meshes_map(
        MeshStent::Straight,
        &cases,
        Some(2),
        &stentkit::design::variants::read_varied,
        |_| {},
    )
    .expect("runs");
    let [paper, objective] = &map.points[..] else {
        panic!("two runs");
    };
    assert!(
        !paper.run.completed && (paper.run.time - 1.75).abs() < 0.01,
        "{:?}",
        paper.run
    );
    assert!(objective.run.completed, "{:?}", objective.run);
    let report = meshes_report(MeshStent::Straight, &map);
    assert!(
        report.summary.contains("**incremental** rotation field: 0 of 1 meshes finish the cycle; failing: p = 5, n = 20 at the release")
            && report.summary.contains("**objective** rotation field: 1 of 1 meshes finish the cycle."),
        "{}",
        report.summary
    );
    assert_eq!(
        report.csv.lines().count(),
        2 + cases.len(),
        "{}",
        report.csv
    );
}
