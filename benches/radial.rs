//! What the radial bench costs (issue 34, speed): `stentkit bench radial` on the paper's straight stent
//! (`designs/straight_stent.yaml`, its quarter model) with the bench's defaults — 37 °C, 0.1 mm/s, closing from
//! just outside the device to its programme's crimped diameter and opening again, 30 diameters each way (60) —
//! as the command does it: the bench design built, the run written into a run folder with its outputs, the
//! bench's table and chart added. Each run three times into a fresh folder, the shortest wall time reported
//! (the target: under 30 s on two cores). Then the patient deployment `designs/aorta_stent_deployed.yaml`
//! (crimp, sheath, compliant vessel, recovery) as `stentkit run` does it, once (target: under 2 minutes).
//!
//! `cargo bench --bench radial`. With `STENTKIT_WRITE_ASSETS=1` in the environment it also writes the result,
//! unrounded, to `assets/bench_speed.csv`, which `scripts/docs_tables.py` makes the README's bench table from.
//! An asset measured again needs a new entry in `assets/provenance.json` (date, machine, command, sha256), or
//! the script refuses it.

use std::path::Path;
use std::time::Instant;
use stentkit::bench::{radial_design, write_outputs};
use stentkit::design::DesignOverrides;
use stentkit::run::{Folder, Interrupt, Lines, RunSettings};

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let design_file = "designs/straight_stent.yaml";
    let work = std::env::temp_dir().join(format!("stentkit-bench-radial-{}", std::process::id()));
    let mut best: Option<(f64, usize, usize)> = None;
    for k in 0..3 {
        let dir = work.join(format!("run{k}"));
        let start = Instant::now();
        let (design, bench) = radial_design(&root.join(design_file), &DesignOverrides::default())
            .unwrap_or_else(|e| panic!("{design_file}: {e}"));
        let settings = RunSettings {
            quiet: true,
            ..RunSettings::new("cargo bench --bench radial")
        };
        run_bench(&design, &dir, &settings);
        let lines = write_outputs(&dir, &bench, &design.model).expect("the bench's outputs");
        let wall = start.elapsed().as_secs_f64();
        let table = std::fs::read_to_string(dir.join("radial.csv")).expect("radial.csv");
        let rows = table.lines().count() - 1;
        assert!(
            lines
                .iter()
                .any(|l| l.starts_with("smallest diameter reached"))
        );
        if best.is_none_or(|(w, _, _)| wall < w) {
            best = Some((wall, rows, bench.diameters));
        }
    }
    let (wall, rows, diameters) = best.expect("three runs");
    // The patient deployment, once: design, run folder and outputs, as `stentkit run`.
    let deployment_file = "designs/aorta_stent_deployed.yaml";
    let start = Instant::now();
    let design = stentkit::design::load_design(&root.join(deployment_file))
        .unwrap_or_else(|e| panic!("{deployment_file}: {e}"));
    let settings = RunSettings {
        quiet: true,
        ..RunSettings::new("cargo bench --bench radial")
    };
    run_bench(&design, &work.join("deployment"), &settings);
    let deployment = start.elapsed().as_secs_f64();
    let steps = std::fs::read_to_string(work.join("deployment/history.csv"))
        .expect("history.csv")
        .lines()
        .count()
        - 2;
    let _ = std::fs::remove_dir_all(&work);
    println!("| command | design | wall s | table rows or steps | diameters per branch |");
    println!("|---|---|---|---|---|");
    println!("| bench radial | {design_file} | {wall:.2} | {rows} | {diameters} |");
    println!("| run | {deployment_file} | {deployment:.2} | {steps} | |");
    if std::env::var_os("STENTKIT_WRITE_ASSETS").is_some() {
        let csv = format!(
            "# stentkit bench radial with the bench's defaults, the whole command (design, run folder, table, chart), shortest of three; the aorta deployment as stentkit run, once (rows: its converged steps)\nbench,design,wall_s,table_rows,diameters_per_branch\nradial,{design_file},{wall},{rows},{diameters}\nrun,{deployment_file},{deployment},{steps},\n"
        );
        std::fs::write(root.join("assets/bench_speed.csv"), csv).expect("assets/bench_speed.csv");
    }
}

/// Runs `design` into the new folder `dir`, messages kept, never interrupted.
fn run_bench(design: &stentkit::Design, dir: &Path, settings: &RunSettings) {
    let mut console = Lines::default();
    stentkit::run::run(
        design,
        Folder::New {
            dir: dir.to_path_buf(),
            force: false,
        },
        settings,
        &Interrupt::default(),
        &mut console,
    )
    .unwrap_or_else(|e| panic!("the bench's run: {e}"));
}
