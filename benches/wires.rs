//! What the contact between wires costs (issue 35, speed): the paper's straight stent (its quarter model) on the
//! radial bench crimped past its locking diameter — the settings of `assets/bench/straight_stent_lock.*`
//! (`scripts/bench_assets.sh lock`: 37 °C, 0.1 mm/s, closing to 9 mm over 120 recorded diameters, 30
//! augmented-Lagrange updates per step) — with the wires' contact and without it (where the struts pass through
//! each other), solver only (no output files), each run three times, the shortest reported.
//!
//! Reported: the wall time of the steps from the wires' first touch to the closed crimper (the steps where the
//! struts press on each other and lock), with and without the contact, and the contact's share of those steps,
//! `1 − without / with` (the target: under 25 %); and the same for the whole run. The share counts
//! everything the contact brings: its own search, law and tangent, the sparse LU its coupling needs instead of
//! the block solver, the extra Newton iterations and updates.
//!
//! Where the time goes inside the run with the contact — the share of the contact term's own work (its search,
//! projections, law and tangent, step limit, updates) against the linear algebra it brings — is measured by
//! sampling (`scripts/wires_share.sh`, which runs this bench's contact run alone: `cargo bench --bench wires --
//! with`).
//!
//! `cargo bench --bench wires`. With `STENTKIT_WRITE_ASSETS=1` in the environment it also writes the table,
//! unrounded, to `assets/wires_speed.csv`. An asset measured again needs a new entry in
//! `assets/provenance.json` (date, machine, command, sha256).

use std::path::Path;
use std::time::Instant;
use stentkit::bench::radial_design;
use stentkit::design::DesignOverrides;
use stentkit::solver::Simulation;

/// One run's step times: `(time at the step's end, wall seconds)` per converged step.
fn steps(model: &stentkit::model::Model) -> Vec<(f64, f64)> {
    let mut sim = Simulation::new(model).expect("discretised");
    let mut out = Vec::new();
    loop {
        let start = Instant::now();
        let Some(_) = sim.step().expect("converges") else {
            break;
        };
        out.push((sim.time(), start.elapsed().as_secs_f64()));
    }
    out
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let design_file = root.join("designs/straight_stent.yaml");
    let model = |wires: bool| {
        let sets = [
            format!("contact.wires={wires}"),
            "bench.min_diameter=9".into(),
            "bench.diameters=120".into(),
            "contact.max_updates=30".into(),
        ]
        .iter()
        .map(|s| s.parse().expect("a --set"))
        .collect();
        let (design, bench) = radial_design(&design_file, &DesignOverrides::sets(sets))
            .unwrap_or_else(|e| panic!("the radial bench's design: {e}"));
        (design.model, bench.closing)
    };
    let ((with, closing), (without, _)) = (model(true), model(false));
    // The first touch of the wires, from a run with the contact.
    let touch = {
        let mut sim = Simulation::new(&with).expect("discretised");
        while sim.wire_touch().is_none() && sim.step().expect("converges").is_some() {}
        sim.wire_touch().expect("the struts touch").time
    };
    let best = |model: &stentkit::model::Model| {
        (0..3)
            .map(|_| steps(model))
            .map(|s| {
                let window: f64 = (s.iter())
                    .filter(|(t, _)| *t >= touch && *t <= closing * (1.0 + 1e-9))
                    .map(|(_, w)| w)
                    .sum();
                let whole: f64 = s.iter().map(|(_, w)| w).sum();
                (window, whole)
            })
            .fold((f64::INFINITY, f64::INFINITY), |a, b| {
                (a.0.min(b.0), a.1.min(b.1))
            })
    };
    let (with_window, with_whole) = best(&with);
    if std::env::args().any(|a| a == "with") {
        // `scripts/wires_share.sh` samples this run alone.
        println!(
            "with the wires' contact: touch to closed {with_window:.3} s, whole run {with_whole:.3} s"
        );
        return;
    }
    let (without_window, without_whole) = best(&without);
    let share = |with: f64, without: f64| 1.0 - without / with;
    println!("the wires first touch at t = {touch:.3} s, the crimper closes at {closing:.3} s");
    println!("| steps | with the wires' contact (s) | without (s) | the contact's share |");
    println!("|---|---|---|---|");
    println!(
        "| touch to closed | {with_window:.3} | {without_window:.3} | {:.1} % (target: under 25 %) |",
        100.0 * share(with_window, without_window)
    );
    println!(
        "| whole run | {with_whole:.3} | {without_whole:.3} | {:.1} % |",
        100.0 * share(with_whole, without_whole)
    );
    if std::env::var_os("STENTKIT_WRITE_ASSETS").is_some() {
        let csv = format!(
            "# the straight stent's radial bench crimped past its lock (9 mm, 120 diameters, 30 updates), solver only, shortest of three runs; wall seconds\nsteps,with_wires_s,without_s,contact_share\ntouch_to_closed,{with_window},{without_window},{}\nwhole_run,{with_whole},{without_whole},{}\n",
            share(with_window, without_window),
            share(with_whole, without_whole)
        );
        std::fs::write(root.join("assets/wires_speed.csv"), csv).expect("assets/wires_speed.csv");
        println!("wrote assets/wires_speed.csv");
    }
}
