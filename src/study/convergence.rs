//! `p × n` convergence: the displacement error of a design against a self-converged reference run, for every
//! degree `p` and number of control points `n` asked for, with the wall time of each run (DESIGN §6).
//!
//! Every run goes up to a time `t`; the error is measured on a grid of points per patch (9 equally spaced
//! parameters by default) against a reference run (by default `p = 8`, `n = 150`), as the paper does for its
//! Fig. conv_circ: `err = ‖u_ref − u_h‖ / ‖u_ref‖` over the grid ([`super::relative_error`]). The table, with
//! the wall time of each run, charts error against `n` and against time (work–precision).
//!
//! With a time-error tolerance, every `p × n` runs a second time with error-controlled steps at that tolerance
//! and the trapezoidal update (the reference keeps the design's steps and update): the work–precision chart then shows, per degree, what adaptive
//! steps buy at the same discretisation in space.

use super::StudyError;
use super::charts::{ErrorChartLabels, ErrorCurve, error_charts};
use super::fit::relative_error;
use super::sample::{SampledRun, sample_run};
use super::variant::{Remesh, TimeVariant, VariedDesign};
use crate::material::Integrator;
use crate::math::Real;
use crate::post::chart::LineChart;
use std::fmt::Write as _;

/// One run of a convergence study.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ConvergencePoint {
    /// Degree.
    pub degree: usize,
    /// Control points per patch.
    pub points: usize,
    /// The time-error tolerance of an error-controlled run (`None`: the design's steps).
    pub time_tolerance: Option<Real>,
    /// Unknowns of the global system.
    pub unknowns: usize,
    /// Relative displacement error against the reference.
    pub error: Real,
    /// Wall time of the run \[s\].
    pub wall: Real,
    /// Newton iterations of the run.
    pub iterations: usize,
}

/// Settings of a convergence study.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ConvergenceStudy {
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
    /// Also run every `p × n` with error-controlled steps at this time-error tolerance.
    pub time_tolerance: Option<Real>,
}

impl ConvergenceStudy {
    /// The time steppings every `p × n` runs with: the design's steps (`None`), then error control at the
    /// study's time tolerance, if any.
    fn steppings(&self) -> impl Iterator<Item = Option<Real>> + use<> {
        [None].into_iter().chain(self.time_tolerance.map(Some))
    }
}

/// Runs the study on `design` (re-built for every `p` and `n`, [`VariedDesign::rebuild`]) and returns its rows; `progress` is
/// told about each finished run.
///
/// # Errors
/// The first run that fails ([`StudyError::Run`] says which): every run must succeed for the rates to mean
/// anything.
pub(crate) fn convergence_study(
    design: &dyn VariedDesign,
    study: &ConvergenceStudy,
    mut progress: impl FnMut(&str),
) -> Result<Vec<ConvergencePoint>, StudyError> {
    let (rp, rn) = study.reference;
    let run = |p: usize, n: usize, tolerance: Option<Real>| -> Result<SampledRun, StudyError> {
        let remesh = Remesh {
            degree: Some(p),
            points: Some(n),
            ..Remesh::default()
        };
        // Error control needs the trapezoidal update (`Integrator::companion`): its runs take it.
        let until = TimeVariant {
            end: Some(study.time),
            tolerance,
            integrator: tolerance.map(|_| Integrator::Trapezoidal),
            ..TimeVariant::default()
        };
        let model = until.of(&design.rebuild(&remesh)?)?;
        Ok(sample_run(&model, study.samples)?)
    };
    let reference = run(rp, rn, None).map_err(|e| e.in_run("reference run"))?;
    progress(&format!(
        "reference p = {rp}, n = {rn}: {:.2} s",
        reference.wall
    ));
    let mut rows = Vec::new();
    for &p in &study.degrees {
        for tolerance in study.steppings() {
            let what = |n: usize| match tolerance {
                Some(tol) => format!("p = {p}, n = {n}, τ = {tol:e}"),
                None => format!("p = {p}, n = {n}"),
            };
            for &n in study.points.iter().filter(|&&n| n > p) {
                let run =
                    run(p, n, tolerance).map_err(|e| e.in_run(format!("run with {}", what(n))))?;
                let error = relative_error(&run.grid, &reference.grid);
                progress(&format!(
                    "{}: error {error:.3e}, {} steps, {:.2} s",
                    what(n),
                    run.summary.steps,
                    run.wall
                ));
                rows.push(ConvergencePoint {
                    degree: p,
                    points: n,
                    time_tolerance: tolerance,
                    unknowns: run.unknowns,
                    error,
                    wall: run.wall,
                    iterations: run.summary.iterations,
                });
            }
        }
    }
    Ok(rows)
}

/// The rows as CSV, with a comment header saying what the error is measured against.
pub(crate) fn convergence_csv(
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
    let _ = writeln!(
        s,
        "p,n,time_tolerance,unknowns,error,wall_s,newton_iterations"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{},{},{:.6e},{:.4},{}",
            r.degree,
            r.points,
            r.time_tolerance.map_or(String::new(), |t| format!("{t:e}")),
            r.unknowns,
            r.error,
            r.wall,
            r.iterations
        );
    }
    s
}

/// The two charts of a convergence study: error against `n` and error against wall time (work–precision),
/// one series per degree, on log–log axes.
pub(crate) fn convergence_charts(
    rows: &[ConvergencePoint],
    study: &ConvergenceStudy,
    design: &str,
) -> [LineChart; 2] {
    let reference = format!(
        "against p = {}, n = {} at t = {}",
        study.reference.0, study.reference.1, study.time
    );
    let curves: Vec<ErrorCurve> = study
        .steppings()
        .flat_map(|tolerance| {
            study.degrees.iter().map(move |&p| ErrorCurve {
                label: match tolerance {
                    Some(tol) => format!("p = {p}, τ = {tol:e}"),
                    None => format!("p = {p}"),
                },
                runs: rows
                    .iter()
                    .filter(|r| r.degree == p && r.time_tolerance == tolerance)
                    .map(|r| (r.points as Real, r.error, r.wall))
                    .collect(),
            })
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
