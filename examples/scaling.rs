//! Per-size costs of the solver on generated straight stents (1, 4, 16, 64 crowns; see `benches/support/stents.rs`):
//! unknowns and milliseconds per residual assembly, tangent assembly, factorisation with solve, and one full
//! time step, with the growth exponent of each cost (least-squares slope of log cost against log crowns).
//! The criterion benchmarks (`cargo bench --bench solver`) measure the same kernels with statistics.
//!
//! Run: cargo run --release --example scaling
//!
//! With `STENTKIT_WRITE_ASSETS=1` in the environment it also writes the table, unrounded, to
//! `assets/scaling.csv` (the growth exponents in a comment line), the asset `scripts/docs_tables.py` makes the
//! scaling table of docs/speed.md from. An asset measured again needs a new entry in `assets/provenance.json`
//! (date, machine, command, sha256), or the script refuses it.

#[path = "../benches/support/stents.rs"]
mod stents;

use std::time::Instant;
use stentkit::study::fit_log_slope;

/// Mean wall time of `f` over `repeats` calls [ms].
fn mean_ms(repeats: usize, mut f: impl FnMut()) -> f64 {
    let start = Instant::now();
    for _ in 0..repeats {
        f();
    }
    1e3 * start.elapsed().as_secs_f64() / repeats as f64
}

fn main() {
    println!(
        "straight stent, p = {}, n = {}, h = {} s, after {} steps of the ramp",
        stents::MESH.0,
        stents::MESH.1,
        stents::STEP,
        stents::WARM_UP_STEPS
    );
    println!(
        "{:>6} {:>9} {:>9} {:>12} {:>12} {:>15} {:>10}",
        "crowns", "patches", "unknowns", "residual ms", "tangent ms", "factor+solve ms", "step ms"
    );
    let mut rows: Vec<(f64, [f64; 4])> = Vec::new();
    let mut csv = String::from("crowns,unknowns,residual_ms,tangent_ms,factor_solve_ms,step_ms\n");
    for crowns in stents::CROWNS {
        let model = stents::stent_model(crowns);
        let mut sim = stents::warmed_up(&model);
        let t = sim.time();
        let repeats = (200 / crowns).max(3);
        let residual = mean_ms(repeats, || {
            sim.assemble(t, false).expect("assembles");
        });
        let tangent = mean_ms(repeats, || {
            sim.assemble(t, true).expect("assembles");
        });
        let factor = mean_ms(repeats, || {
            sim.factor_and_solve().expect("factorises");
        });
        let steps = 3;
        let step = mean_ms(steps, || {
            sim.run(&mut [&mut stents::OneStep])
                .expect("step converges");
        });
        println!(
            "{crowns:>6} {:>9} {:>9} {residual:>12.3} {tangent:>12.3} {factor:>15.3} {step:>10.2}",
            model.patches.len(),
            model.num_unknowns()
        );
        csv.push_str(&format!(
            "{crowns},{},{residual},{tangent},{factor},{step}\n",
            model.num_unknowns()
        ));
        rows.push((crowns as f64, [residual, tangent, factor, step]));
    }
    let exponent = |k: usize| {
        let points: Vec<(f64, f64)> = rows.iter().map(|(c, v)| (*c, v[k])).collect();
        fit_log_slope(&points).map_or("n/a".to_string(), |q| format!("{q:.2}"))
    };
    let exponents = format!(
        "growth exponent (cost ∝ crowns^q): residual {}, tangent {}, factor+solve {}, step {}",
        exponent(0),
        exponent(1),
        exponent(2),
        exponent(3)
    );
    println!("{exponents}");
    if std::env::var_os("STENTKIT_WRITE_ASSETS").is_some() {
        let header = format!(
            "# straight stents (benches/support/stents.rs), p = {}, n = {}, h = {} s, after {} steps of the ramp; mean ms per call\n# {exponents}\n",
            stents::MESH.0,
            stents::MESH.1,
            stents::STEP,
            stents::WARM_UP_STEPS
        );
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scaling.csv");
        std::fs::write(&path, header + &csv).expect("assets/scaling.csv is writable");
        println!("wrote {}", path.display());
    }
}
