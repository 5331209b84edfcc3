//! Criterion benchmarks of the solver's hot kernels (DESIGN §6, STYLE 17) on generated straight stents with
//! 1, 4, 16 and 64 crowns (`benches/support/stents.rs`): residual assembly, residual-and-tangent assembly, numeric
//! factorisation with one solve, and one whole time step (Newton with the solver's factorisation reuse), each
//! from a state a few steps into the contraction ramp (`benches/support/stents.rs`: p = 4, n = 12, h = 0.01 s). Sample counts and measurement times are small so that
//! `cargo bench --bench solver` finishes in a few minutes on two cores.

#[path = "support/stents.rs"]
mod stents;

use criterion::{BenchmarkId, Criterion, SamplingMode, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::{Duration, Instant};

fn solver(c: &mut Criterion) {
    let mut group = c.benchmark_group("solver");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    for crowns in stents::CROWNS {
        let model = stents::stent_model(crowns);
        let mut sim = stents::warmed_up(&model);
        let t = sim.time();
        group.sampling_mode(SamplingMode::Auto);
        group.bench_with_input(BenchmarkId::new("residual", crowns), &t, |b, &t| {
            b.iter(|| black_box(sim.assemble(t, false).expect("assembles")))
        });
        group.bench_with_input(BenchmarkId::new("tangent", crowns), &t, |b, &t| {
            b.iter(|| black_box(sim.assemble(t, true).expect("assembles")))
        });
        sim.assemble(t, true).expect("assembles");
        group.bench_function(BenchmarkId::new("factor_and_solve", crowns), |b| {
            b.iter(|| black_box(sim.factor_and_solve().expect("factorises")[0]))
        });
        // The same step every iteration: a fresh warmed-up simulation (untimed), then one timed step. (Stepping
        // on along the ramp would time ever harder steps: on this coarse mesh the larger stents need cuts
        // after t ≈ 0.3 s.) Flat sampling keeps the number of untimed set-ups at the sample size for the
        // large stents.
        group.sampling_mode(SamplingMode::Flat);
        group.bench_function(BenchmarkId::new("time_step", crowns), |b| {
            b.iter_custom(|iterations| {
                let mut total = Duration::ZERO;
                for _ in 0..iterations {
                    sim = stents::warmed_up(&model);
                    let start = Instant::now();
                    sim.run(&mut [&mut stents::OneStep])
                        .expect("the step converges");
                    total += start.elapsed();
                }
                total
            })
        });
    }
    group.finish();
}

criterion_group!(benches, solver);
criterion_main!(benches);
