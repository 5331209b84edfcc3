//! What the contact between wires costs (issue 35, speed): the paper's straight stent on the radial bench crimped
//! past its locking diameter — the settings of `assets/bench/straight_stent_lock.*` (`scripts/bench_assets.sh
//! lock`: 37 °C, 0.1 mm/s, closing to 9 mm over 120 recorded diameters, 30 augmented-Lagrange updates per step)
//! — as its quarter model (the design's) and as the full device (`stent.symmetry=none`), each with the wires'
//! contact and without it (where the struts pass through each other), solver only (no output files).
//!
//! The steps measured are those from the wires' first touch to the closed crimper: where the struts press on
//! each other and lock. In them, from the solver's own clocks ([`stentkit::solver::SolverTiming`]):
//! - **the contact's own work**: the wires' contact term (its search, projections, law, coupled loads and their
//!   tangent, step limit, multiplier updates) and the crossing check beside it;
//! - **the linear algebra its coupling adds**: the analyses of the pattern when contact pairs come and go, and
//!   the factorisations and solves of those steps against what the same number would cost without the coupling
//!   (each at the mean cost of a factorisation and of a solve over the run without the contact);
//! - their **share of the steps' wall time** (the target: under 25 %), first the contact's own work
//!   alone, then with the linear algebra it adds.
//!
//! The rest of those steps is the solve of a harder problem — more Newton iterations and augmented-Lagrange
//! updates per step while the struts lock — which the whole runs' times, with and without the contact, show.
//! The quarter model's runs are made three times and the one with the shortest steps kept; the full device's
//! once.
//!
//! `cargo bench --bench wires`. With `STENTKIT_WRITE_ASSETS=1` in the environment it also writes the table,
//! unrounded, to `assets/wires_speed.csv`. An asset measured again needs a new entry in
//! `assets/provenance.json` (date, machine, command, sha256).

use std::path::Path;
use std::time::Instant;
use stentkit::bench::radial_design;
use stentkit::design::DesignOverrides;
use stentkit::model::Model;
use stentkit::solver::{Simulation, SolverTiming};

/// What one run measured.
struct Run {
    /// Wall seconds of the steps from the first touch to the closed crimper, and their count.
    window: f64,
    steps: usize,
    /// The solver's clocks at the window's start and end.
    before: SolverTiming,
    after: SolverTiming,
    /// Wall seconds of every step, and the solver's clocks at the end.
    whole: f64,
    total: SolverTiming,
}

/// Runs `model` to its end, timing the steps that end in `[touch, closing]`.
fn run(model: &Model, touch: f64, closing: f64) -> Run {
    let mut sim = Simulation::new(model).expect("discretised");
    let (mut window, mut steps, mut whole) = (0.0, 0, 0.0);
    let (mut before, mut after) = (None, None);
    loop {
        let clocks = sim.timing().clone();
        let start = Instant::now();
        let Some(_) = sim.step().expect("converges") else {
            break;
        };
        let wall = start.elapsed().as_secs_f64();
        whole += wall;
        if sim.time() >= touch && sim.time() <= closing * (1.0 + 1e-9) {
            before.get_or_insert(clocks);
            after = Some(sim.timing().clone());
            window += wall;
            steps += 1;
        }
    }
    Run {
        window,
        steps,
        before: before.expect("steps after the first touch"),
        after: after.expect("steps after the first touch"),
        whole,
        total: sim.timing().clone(),
    }
}

/// The seconds of the contact's own work between two clocks: the wires' contact term and the crossing check.
fn own(t: &SolverTiming) -> f64 {
    (t.terms.iter())
        .filter(|(name, _)| name == "wire contact" || name == "wire crossing")
        .map(|(_, (_, s))| s)
        .sum()
}

/// The straight stent's lock bench with `stent.symmetry` set to `symmetry` (the design's when `None`): its
/// unknowns, and the runs with the wires' contact and without it.
fn measure(design_file: &Path, symmetry: Option<&str>) -> (usize, Run, Run) {
    let model = |wires: bool| {
        let mut sets = vec![
            format!("contact.wires={wires}"),
            "bench.min_diameter=9".into(),
            "bench.diameters=120".into(),
            "contact.max_updates=30".into(),
        ];
        sets.extend(symmetry.map(|s| format!("stent.symmetry={s}")));
        let sets = (sets.iter()).map(|s| s.parse().expect("a --set")).collect();
        let (design, bench) = radial_design(design_file, &DesignOverrides::sets(sets))
            .unwrap_or_else(|e| panic!("the radial bench's design: {e}"));
        (design.model, bench.closing)
    };
    let ((with, closing), (without, _)) = (model(true), model(false));
    let (touch, unknowns) = {
        let mut sim = Simulation::new(&with).expect("discretised");
        while sim.wire_touch().is_none() && sim.step().expect("converges").is_some() {}
        let touch = sim.wire_touch().expect("the struts touch").time;
        (touch, sim.discretisation().num_unknowns())
    };
    let repeats = if symmetry.is_none() { 3 } else { 1 };
    let best = |model: &Model| {
        (0..repeats)
            .map(|_| run(model, touch, closing))
            .min_by(|a, b| a.window.total_cmp(&b.window))
            .expect("one run")
    };
    (unknowns, best(&with), best(&without))
}

/// Seconds of the window's parts in the run with the contact.
struct Shares {
    /// The contact's own work.
    own: f64,
    /// Analyses of the pattern.
    analysis: f64,
    /// Factorisations and solves.
    linear: f64,
    /// What as many factorisations and solves cost without the coupling.
    uncoupled: f64,
}

fn shares(with: &Run, without: &Run) -> Shares {
    let (a, b) = (&with.before, &with.after);
    let mean = |(count, secs): (usize, f64)| secs / count.max(1) as f64;
    let factorisations = b.factorisation.0 - a.factorisation.0;
    let solves = b.solve.0 - a.solve.0;
    Shares {
        own: own(b) - own(a),
        analysis: b.analysis.1 - a.analysis.1,
        linear: (b.factorisation.1 - a.factorisation.1) + (b.solve.1 - a.solve.1),
        uncoupled: factorisations as f64 * mean(without.total.factorisation)
            + solves as f64 * mean(without.total.solve),
    }
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let design_file = root.join("designs/straight_stent.yaml");
    let mut rows = Vec::new();
    println!(
        "| model | unknowns | steps touch→closed | their wall time | contact's own work | + pattern analyses and the linear algebra it adds | whole run with / without the contact |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (label, symmetry) in [("quarter", None), ("full", Some("none"))] {
        let (unknowns, with, without) = measure(&design_file, symmetry);
        let s = shares(&with, &without);
        let added = s.own + s.analysis + (s.linear - s.uncoupled);
        println!(
            "| {label} | {unknowns} | {} | {:.3} s | {:.3} s ({:.1} %) | {:.3} s ({:.1} %) | {:.2} / {:.2} s |",
            with.steps,
            with.window,
            s.own,
            100.0 * s.own / with.window,
            added,
            100.0 * added / with.window,
            with.whole,
            without.whole
        );
        rows.push(format!(
            "{label},{unknowns},{},{},{},{},{},{},{},{},{},{}",
            with.steps,
            with.window,
            s.own,
            s.analysis,
            s.linear,
            s.uncoupled,
            s.own / with.window,
            added / with.window,
            with.whole,
            without.whole
        ));
    }
    if std::env::var_os("STENTKIT_WRITE_ASSETS").is_some() {
        let csv = format!(
            "# the straight stent's radial bench crimped past its lock (9 mm, 120 diameters, 30 updates), solver only; the steps from the wires' first touch to the closed crimper (window); seconds from the solver's clocks\nmodel,unknowns,window_steps,window_s,contact_own_s,analysis_s,linear_s,linear_uncoupled_s,own_share,contact_share,whole_with_s,whole_without_s\n{}\n",
            rows.join("\n")
        );
        std::fs::write(root.join("assets/wires_speed.csv"), csv).expect("assets/wires_speed.csv");
        println!("wrote assets/wires_speed.csv");
    }
}
