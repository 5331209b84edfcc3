//! `stentkit study`: accuracy against cost.
//!
//! `study convergence` runs a design for every degree `p` and number of control points `n` asked for, up to a
//! time `t`, and measures the error of the displacement on a grid of points per patch (9 equally spaced
//! parameters by default) against a self-converged reference run (by default `p = 8`, `n = 150`), as the paper
//! does for its Fig. conv_circ: `err = ‖u_ref − u_h‖ / ‖u_ref‖` over the grid. It writes the table as CSV with
//! the wall time of each run, so error can be charted against `n` and against time (work–precision).

use crate::io::chart::{LineChart, Scale, Series};
use crate::io::design::{DesignOverrides, parse_design_with};
use crate::math::{Real, Vec3};
use crate::model::ProbeLocation;
use crate::solver::Simulation;
use crate::solver::simulation::NoObserver;
use anyhow::Context;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// One run of a convergence study.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvergencePoint {
    /// Degree.
    pub degree: usize,
    /// Control points per patch.
    pub points: usize,
    /// Unknowns of the global system.
    pub unknowns: usize,
    /// Relative displacement error against the reference.
    pub error: Real,
    /// Wall time of the run [s].
    pub wall: Real,
    /// Newton iterations of the run.
    pub iterations: usize,
}

/// The displacements on the sampling grid (`samples` equally spaced parameters per patch) at the end of a run of
/// `text` with degree `p`, `n` points per patch, up to time `end`; with the run's wall time, iterations and size.
pub fn sampled_run(
    text: &str,
    path: &Path,
    p: usize,
    n: usize,
    end: Real,
    samples: usize,
) -> anyhow::Result<(Vec<Vec3>, Real, usize, usize)> {
    let overrides = DesignOverrides {
        degree: Some(p),
        points: Some(n),
        end_time: Some(end),
        ..DesignOverrides::default()
    };
    let design = parse_design_with(text, path, &overrides)?;
    let model = &design.model;
    let started = Instant::now();
    let mut sim = Simulation::new(model)?;
    let summary = sim
        .run(&mut NoObserver)
        .with_context(|| format!("run with p = {p}, n = {n}"))?;
    let wall = started.elapsed().as_secs_f64();
    let grid = (0..model.patches.len())
        .flat_map(|patch| {
            (0..samples).map(move |k| ProbeLocation::Patch {
                patch,
                u: k as Real / (samples.max(2) - 1) as Real,
            })
        })
        .map(|loc| sim.probe_displacement(&loc))
        .collect();
    Ok((grid, wall, summary.iterations, model.num_unknowns()))
}

/// `‖a − b‖ / ‖b‖` over a grid of vectors.
pub fn relative_error(a: &[Vec3], b: &[Vec3]) -> Real {
    let num: Real = a.iter().zip(b).map(|(x, y)| (x - y).norm_squared()).sum();
    let den: Real = b.iter().map(|y| y.norm_squared()).sum();
    (num / den).sqrt()
}

/// Settings of a convergence study.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvergenceStudy {
    /// Degrees to run.
    pub degrees: Vec<usize>,
    /// Control points per patch to run (values `≤ p` are skipped for that `p`).
    pub points: Vec<usize>,
    /// Time at which errors are measured [time].
    pub time: Real,
    /// Reference `(p, n)`.
    pub reference: (usize, usize),
    /// Sampling points per patch.
    pub samples: usize,
}

/// Runs the study and returns its rows; `progress` is told about each finished run.
pub fn convergence(
    text: &str,
    path: &Path,
    study: &ConvergenceStudy,
    mut progress: impl FnMut(&str),
) -> anyhow::Result<Vec<ConvergencePoint>> {
    let (rp, rn) = study.reference;
    let (reference, wall, _, _) =
        sampled_run(text, path, rp, rn, study.time, study.samples).context("reference run")?;
    progress(&format!("reference p = {rp}, n = {rn}: {wall:.2} s"));
    let mut rows = Vec::new();
    for &p in &study.degrees {
        for &n in study.points.iter().filter(|&&n| n > p) {
            let (grid, wall, iterations, unknowns) =
                sampled_run(text, path, p, n, study.time, study.samples)?;
            let error = relative_error(&grid, &reference);
            progress(&format!("p = {p}, n = {n}: error {error:.3e}, {wall:.2} s"));
            rows.push(ConvergencePoint {
                degree: p,
                points: n,
                unknowns,
                error,
                wall,
                iterations,
            });
        }
    }
    Ok(rows)
}

/// The rows as CSV, with a comment header saying what the error is measured against.
pub fn convergence_csv(
    rows: &[ConvergencePoint],
    study: &ConvergenceStudy,
    design: &str,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# convergence study of {design}: displacement error at t = {} on {} points per patch against a self-converged run with p = {}, n = {}",
        study.time, study.samples, study.reference.0, study.reference.1
    );
    let _ = writeln!(s, "p,n,unknowns,error,wall_s,newton_iterations");
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{},{:.6e},{:.4},{}",
            r.degree, r.points, r.unknowns, r.error, r.wall, r.iterations
        );
    }
    s
}

/// The two charts of a convergence study: error against `n` and error against wall time (work–precision),
/// one series per degree, on log–log axes.
pub fn convergence_charts(
    rows: &[ConvergencePoint],
    study: &ConvergenceStudy,
    design: &str,
) -> [LineChart; 2] {
    let reference = format!(
        "against p = {}, n = {} at t = {}",
        study.reference.0, study.reference.1, study.time
    );
    let mut by_n = LineChart::new(
        format!("{design}: displacement error vs n ({reference})"),
        "control points per patch n",
        "relative displacement error",
    );
    let mut by_time = LineChart::new(
        format!("{design}: work-precision ({reference})"),
        "wall time of the run [s]",
        "relative displacement error",
    );
    for chart in [&mut by_n, &mut by_time] {
        chart.x_scale = Scale::Log;
        chart.y_scale = Scale::Log;
    }
    for (index, &p) in study.degrees.iter().enumerate() {
        let of_p: Vec<&ConvergencePoint> = rows
            .iter()
            .filter(|r| r.degree == p && r.error > 0.0)
            .collect();
        if of_p.is_empty() {
            continue;
        }
        by_n.series.push(
            Series::new(
                format!("p = {p}"),
                of_p.iter().map(|r| (r.points as Real, r.error)).collect(),
            )
            .with_markers()
            .with_color(index),
        );
        by_time.series.push(
            Series::new(
                format!("p = {p}"),
                of_p.iter().map(|r| (r.wall.max(1e-6), r.error)).collect(),
            )
            .with_markers()
            .with_color(index),
        );
    }
    [by_n, by_time]
}
