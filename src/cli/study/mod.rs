//! `stentkit study`: accuracy against cost.
//!
//! This module owns what the studies share — a run of a design with overrides sampled on a grid of points per
//! patch ([`sample_run`]), the relative error measure ([`relative_error`]), the fit of an observed order or growth
//! exponent ([`fit_log_slope`]) and the pair of log–log charts error-against-parameter and error-against-wall-time
//! ([`error_charts`]) — and the convergence study itself; [`time`] and [`stability`] hold the other studies.
//!
//! `study convergence` runs a design for every degree `p` and number of control points `n` asked for, up to a
//! time `t`, and measures the error of the displacement on a grid of points per patch (9 equally spaced
//! parameters by default) against a self-converged reference run (by default `p = 8`, `n = 150`), as the paper
//! does for its Fig. conv_circ: `err = ‖u_ref − u_h‖ / ‖u_ref‖` over the grid. It writes the table as CSV with
//! the wall time of each run, so error can be charted against `n` and against time (work–precision).

pub mod stability;
pub mod time;

use crate::io::chart::{LineChart, Scale, Series};
use crate::io::design::{DesignOverrides, parse_design_with};
use crate::math::{Real, Vec3};
use crate::model::ProbeLocation;
use crate::solver::simulation::NoObserver;
use crate::solver::{RunSummary, Simulation};
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
    /// Wall time of the run \[s\].
    pub wall: Real,
    /// Newton iterations of the run.
    pub iterations: usize,
}

/// A finished run sampled on the study grid.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledRun {
    /// Displacements at `samples` equally spaced parameters per patch, patch by patch \[length\].
    pub grid: Vec<Vec3>,
    /// Wall time of the run (discretisation, analysis and time stepping) \[s\].
    pub wall: Real,
    /// The solver's totals (steps, Newton iterations, cuts, factorisations).
    pub summary: RunSummary,
    /// Unknowns of the global system.
    pub unknowns: usize,
}

/// Runs `text` (a design; `path` names it in errors) with `overrides` to its (overridden) end time and samples
/// the displacement at `samples` equally spaced parameters per patch.
pub fn sample_run(
    text: &str,
    path: &Path,
    overrides: &DesignOverrides,
    samples: usize,
) -> anyhow::Result<SampledRun> {
    let design = parse_design_with(text, path, overrides)?;
    let model = &design.model;
    let started = Instant::now();
    let mut sim = Simulation::new(model)?;
    let summary = sim.run(&mut [&mut NoObserver])?;
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
    Ok(SampledRun {
        grid,
        wall,
        summary,
        unknowns: model.num_unknowns(),
    })
}

/// `‖a − b‖ / ‖b‖` over a grid of vectors.
pub fn relative_error(a: &[Vec3], b: &[Vec3]) -> Real {
    let num: Real = a.iter().zip(b).map(|(x, y)| (x - y).norm_squared()).sum();
    let den: Real = b.iter().map(|y| y.norm_squared()).sum();
    (num / den).sqrt()
}

/// Least-squares slope of `log y` against `log x` over the points with `x, y > 0` and finite: the observed
/// order of an error `y ≈ C x^q` or the growth exponent of a cost. `None` with fewer than two such points or
/// no spread in `x`.
pub fn fit_log_slope(points: &[(Real, Real)]) -> Option<Real> {
    let logs: Vec<(Real, Real)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if logs.len() < 2 {
        return None;
    }
    let n = logs.len() as Real;
    let (mx, my) = logs
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxx: Real = logs.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    let sxy: Real = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// One curve of an error study: a label and its runs as `(parameter, error, wall time [s])`.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorCurve {
    /// Legend entry (e.g. `p = 4`, `backward-euler`).
    pub label: String,
    /// Runs as `(parameter, relative error, wall time [s])`; runs with a zero or failed error are left out.
    pub runs: Vec<(Real, Real, Real)>,
}

/// Titles and axis labels of the two charts of an error study.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorChartLabels {
    /// Title of the error-against-parameter chart.
    pub by_parameter: String,
    /// Title of the work–precision chart.
    pub by_time: String,
    /// Label of the parameter axis (with its unit).
    pub parameter: String,
}

/// The two log–log charts of an error study: error against the study's parameter and error against wall time
/// (work–precision), one series per curve.
pub fn error_charts(curves: &[ErrorCurve], labels: &ErrorChartLabels) -> [LineChart; 2] {
    let y = "relative displacement error";
    let mut by_parameter = LineChart::new(&labels.by_parameter, &labels.parameter, y);
    let mut by_time = LineChart::new(&labels.by_time, "wall time of the run [s]", y);
    for chart in [&mut by_parameter, &mut by_time] {
        chart.x_scale = Scale::Log;
        chart.y_scale = Scale::Log;
    }
    for (index, curve) in curves.iter().enumerate() {
        let runs: Vec<&(Real, Real, Real)> = curve
            .runs
            .iter()
            .filter(|r| r.1 > 0.0 && r.1.is_finite())
            .collect();
        if runs.is_empty() {
            continue;
        }
        by_parameter.series.push(
            Series::new(&curve.label, runs.iter().map(|r| (r.0, r.1)).collect())
                .with_markers()
                .with_color(index),
        );
        by_time.series.push(
            Series::new(
                &curve.label,
                runs.iter().map(|r| (r.2.max(1e-6), r.1)).collect(),
            )
            .with_markers()
            .with_color(index),
        );
    }
    [by_parameter, by_time]
}

/// Settings of a convergence study.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvergenceStudy {
    /// Degrees to run.
    pub degrees: Vec<usize>,
    /// Control points per patch to run (values `≤ p` are skipped for that `p`).
    pub points: Vec<usize>,
    /// Time at which errors are measured \[time\].
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
    let overrides = |p: usize, n: usize| DesignOverrides {
        degree: Some(p),
        points: Some(n),
        end_time: Some(study.time),
        ..DesignOverrides::default()
    };
    let reference =
        sample_run(text, path, &overrides(rp, rn), study.samples).context("reference run")?;
    progress(&format!(
        "reference p = {rp}, n = {rn}: {:.2} s",
        reference.wall
    ));
    let mut rows = Vec::new();
    for &p in &study.degrees {
        for &n in study.points.iter().filter(|&&n| n > p) {
            let run = sample_run(text, path, &overrides(p, n), study.samples)
                .with_context(|| format!("run with p = {p}, n = {n}"))?;
            let error = relative_error(&run.grid, &reference.grid);
            progress(&format!(
                "p = {p}, n = {n}: error {error:.3e}, {:.2} s",
                run.wall
            ));
            rows.push(ConvergencePoint {
                degree: p,
                points: n,
                unknowns: run.unknowns,
                error,
                wall: run.wall,
                iterations: run.summary.iterations,
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
    let curves: Vec<ErrorCurve> = study
        .degrees
        .iter()
        .map(|&p| ErrorCurve {
            label: format!("p = {p}"),
            runs: rows
                .iter()
                .filter(|r| r.degree == p)
                .map(|r| (r.points as Real, r.error, r.wall))
                .collect(),
        })
        .collect();
    error_charts(
        &curves,
        &ErrorChartLabels {
            by_parameter: format!("{design}: displacement error vs n ({reference})"),
            by_time: format!("{design}: work-precision ({reference})"),
            parameter: "control points per patch n".into(),
        },
    )
}
