//! What contact costs (issue 33, speed): the paper's straight stent programmed by prescribed joints
//! (`designs/straight_stent.yaml`) against the same device programmed by a crimper and sheathed
//! (`designs/straight_stent_crimped.yaml`), at the same time steps (1301 of 2.5 ms), solver only (no output
//! files), one after the other in one process; each run three times, the shortest wall time reported.
//!
//! Reported per run: wall time, steps, Newton iterations, factorisations, step cuts, and the crimped run's wall
//! time over the prescribed one (the target: at most 2). Where the time goes inside the crimped run —
//! the share of the contact term (its search, law and tangent at the points, the step limit, the checks
//! between points) — is measured by sampling the process, not by timers in the hot loop
//! (`scripts/contact_share.sh`, which runs this bench's crimped run alone: `cargo bench --bench contact --
//! crimped`).
//!
//! `cargo bench --bench contact` runs both (about a minute on two cores). With `STENTKIT_WRITE_ASSETS=1` in the
//! environment it also writes the table, unrounded, to `assets/contact_speed.csv`, which `scripts/docs_tables.py`
//! makes the contact table of docs/speed.md from. An asset measured again needs a new entry in
//! `assets/provenance.json` (date, machine, command, sha256), or the script refuses it.

use std::path::Path;
use std::time::Instant;
use stentkit::design::load_design;
use stentkit::solver::simulation::NoObserver;
use stentkit::solver::{RunSummary, Simulation};

/// The shortest of three runs of `design`: its wall time \[s\] and its summary.
fn run(root: &Path, design: &str) -> (f64, RunSummary) {
    let model = load_design(&root.join(design))
        .unwrap_or_else(|e| panic!("{design}: {e}"))
        .model;
    let mut best: Option<(f64, RunSummary)> = None;
    for _ in 0..3 {
        let start = Instant::now();
        let mut sim = Simulation::new(&model).expect("discretised");
        let summary = sim
            .run(&mut [&mut NoObserver])
            .unwrap_or_else(|e| panic!("{design}: {e}"));
        let wall = start.elapsed().as_secs_f64();
        if best.as_ref().is_none_or(|(w, _)| wall < *w) {
            best = Some((wall, summary));
        }
    }
    best.expect("three runs")
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let only_crimped = std::env::args().any(|a| a == "crimped");
    let designs: &[&str] = if only_crimped {
        &["designs/straight_stent_crimped.yaml"]
    } else {
        &[
            "designs/straight_stent.yaml",
            "designs/straight_stent_crimped.yaml",
        ]
    };
    let mut csv = String::from(
        "# the straight stent programmed by prescribed joints and by a crimper, solver only, shortest of three runs\nrun,design,wall_s,steps,newton_iterations,factorisations,cuts\n",
    );
    let mut walls = Vec::new();
    println!("| run | wall s | steps | Newton its | factorisations | cuts |");
    println!("|---|---|---|---|---|---|");
    for design in designs {
        let (wall, s) = run(root, design);
        let name = Path::new(design)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or(design);
        println!(
            "| {name} | {wall:.2} | {} | {} | {} | {} |",
            s.steps, s.iterations, s.factorisations, s.cuts
        );
        csv.push_str(&format!(
            "{name},{design},{wall},{},{},{},{}\n",
            s.steps, s.iterations, s.factorisations, s.cuts
        ));
        walls.push(wall);
    }
    if let [prescribed, crimped] = walls[..] {
        println!(
            "crimped over prescribed: {:.2} (target: at most 2)",
            crimped / prescribed
        );
        if std::env::var_os("STENTKIT_WRITE_ASSETS").is_some() {
            let path = root.join("assets/contact_speed.csv");
            std::fs::write(&path, csv).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            println!("wrote {}", path.display());
        }
    }
}
