//! Error against the time step `h` for each internal-variable integrator (DESIGN §6; `stentkit study time`).
//!
//! Every integrator asked for (trapezoidal, backward Euler, exponential) runs the design with every step `h`
//! asked for, up to a time `T`; the displacement on the study grid at `T` is compared with a self-converged
//! reference run (by default the exponential integrator with the smallest `h` halved again; or the design's own
//! step and integrator; or the exponential integrator at a given step), with the error measure of the
//! convergence study: `‖u_ref − u_h‖ / ‖u_ref‖` over the grid. The observed order per integrator is the
//! least-squares slope of `log err` against `log h`. Steps are nominal: the solver lands on every schedule
//! breakpoint and may cut a step, so a run's steps are `≤ h`.
//!
//! Beside the fixed steps, the trapezoidal update with error-controlled steps runs at every time-error
//! tolerance asked for (`time.tolerance`): its rows carry the tolerance and, as their `h`, the mean step
//! `T / steps`, so they sit on the same charts — error against (mean) step and error against wall time, the
//! work–precision comparison of fixed and adaptive steps.

use super::charts::{ErrorChartLabels, ErrorCurve, error_charts};
use super::fit::{fit_log_slope, relative_error};
use super::sample::{SampledRun, sample_run};
use super::variant::TimeVariant;
use super::{StudyError, error_chain};
use crate::material::Integrator;
use crate::math::Real;
use crate::model::Model;
use crate::post::chart::LineChart;
use std::fmt::Write as _;

/// Which run the errors of a time-step study are measured against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum TimeReference {
    /// The exponential integrator with the smallest step of the study halved.
    Auto,
    /// The design's own `time.step` and integrator.
    Design,
    /// The exponential integrator with this step \[time\].
    Step(Real),
}

/// Settings of a time-step study.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct TimeStudy {
    /// Integrators to compare.
    pub integrators: Vec<Integrator>,
    /// Nominal time steps `h` \[time\].
    pub steps: Vec<Real>,
    /// Time-error tolerances of the error-controlled runs (trapezoidal update).
    pub tolerances: Vec<Real>,
    /// Time at which errors are measured (the runs end there) \[time\].
    pub time: Real,
    /// The reference run.
    pub reference: TimeReference,
    /// Sampling points per patch.
    pub samples: usize,
}

/// One run of a time-step study.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct TimePoint {
    /// The integrator.
    pub integrator: Integrator,
    /// Nominal step `h` \[time\]; for an error-controlled run the mean step `T / steps` (its first step when
    /// it failed).
    pub step: Real,
    /// The time-error tolerance of an error-controlled run (`None`: fixed steps of `step`).
    pub tolerance: Option<Real>,
    /// Relative displacement error at the study time, or why the run failed.
    pub error: Result<Real, String>,
    /// Wall time of the run \[s\].
    pub wall: Real,
    /// Converged time steps.
    pub steps: usize,
    /// Newton iterations.
    pub iterations: usize,
    /// Step cuts.
    pub cuts: usize,
}

/// The result of a time-step study.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct TimeStudyResult {
    /// Every run, integrator by integrator, steps in the given order.
    pub rows: Vec<TimePoint>,
    /// What the reference run was, in words (for the CSV header, chart titles and the terminal).
    pub reference: String,
    /// Observed order per integrator (least-squares slope of `log err` against `log h`), `None` when fewer than
    /// two runs have a positive error.
    pub orders: Vec<(Integrator, Option<Real>)>,
}

/// Runs the study on variants of `model` ([`TimeVariant`]: end time, step and integrator); `progress` is told
/// about each finished run. A run that fails is a row with its reason, not an error.
///
/// # Errors
/// A step that is not positive, or a failed reference run.
pub(crate) fn time_study(
    model: &Model,
    study: &TimeStudy,
    mut progress: impl FnMut(&str),
) -> Result<TimeStudyResult, StudyError> {
    let smallest = study.steps.iter().copied().fold(Real::INFINITY, Real::min);
    if !(smallest.is_finite() && smallest > 0.0) {
        return Err(StudyError::InvalidSetting {
            setting: "every time step h",
            value: smallest,
            expected: "a positive number",
        });
    }
    let run = |variant: &TimeVariant| -> Result<SampledRun, StudyError> {
        Ok(sample_run(&variant.of(model)?, study.samples)?)
    };
    let mut reference_variant = TimeVariant {
        end: Some(study.time),
        ..TimeVariant::default()
    };
    let reference = match study.reference {
        TimeReference::Auto | TimeReference::Step(_) => {
            let (h, why) = match study.reference {
                TimeReference::Step(h) => (h, "given"),
                _ => (smallest / 2.0, "the smallest h halved"),
            };
            reference_variant.step = Some(h);
            reference_variant.integrator = Some(Integrator::Exponential);
            format!("exponential integrator, h = {h:e} ({why})")
        }
        TimeReference::Design => "the design's own time step and integrator".to_string(),
    };
    let reference_run = run(&reference_variant).map_err(|e| e.in_run("reference run"))?;
    progress(&format!(
        "reference ({reference}): {} steps, {:.2} s",
        reference_run.summary.steps, reference_run.wall
    ));
    let mut rows = Vec::new();
    let fixed = study.integrators.iter().flat_map(|&integrator| {
        study.steps.iter().map(move |&step| TimeVariant {
            end: Some(study.time),
            step: Some(step),
            integrator: Some(integrator),
            ..TimeVariant::default()
        })
    });
    let controlled = study.tolerances.iter().map(|&tolerance| TimeVariant {
        end: Some(study.time),
        tolerance: Some(tolerance),
        integrator: Some(Integrator::Trapezoidal),
        ..TimeVariant::default()
    });
    for variant in fixed.chain(controlled) {
        let integrator = variant.integrator.unwrap_or(Integrator::Trapezoidal);
        let first = variant.step.unwrap_or(model.time().step);
        let mut row = TimePoint {
            integrator,
            step: first,
            tolerance: variant.tolerance,
            error: Err(String::new()),
            wall: 0.0,
            steps: 0,
            iterations: 0,
            cuts: 0,
        };
        match run(&variant) {
            Ok(run) => {
                if row.tolerance.is_some() {
                    row.step = study.time / run.summary.steps.max(1) as Real;
                }
                row.error = Ok(relative_error(&run.grid, &reference_run.grid));
                row.wall = run.wall;
                row.steps = run.summary.steps;
                row.iterations = run.summary.iterations;
                row.cuts = run.summary.cuts;
            }
            Err(e) => row.error = Err(error_chain(&e)),
        }
        let what = match row.tolerance {
            Some(tol) => format!("{} τ = {tol:e}", integrator.name()),
            None => format!("{} h = {:e}", integrator.name(), row.step),
        };
        progress(&match &row.error {
            Ok(e) => format!(
                "{what}: error {e:.3e}, {} steps, {} cuts, {:.2} s",
                row.steps, row.cuts, row.wall
            ),
            Err(e) => format!("{what}: failed: {e}"),
        });
        rows.push(row);
    }
    let orders = study
        .integrators
        .iter()
        .map(|&i| (i, fit_log_slope(&error_points(&rows, i))))
        .collect();
    Ok(TimeStudyResult {
        rows,
        reference,
        orders,
    })
}

/// `(h, error)` of the successful fixed-step runs of one integrator.
fn error_points(rows: &[TimePoint], integrator: Integrator) -> Vec<(Real, Real)> {
    rows.iter()
        .filter(|r| r.integrator == integrator && r.tolerance.is_none())
        .filter_map(|r| r.error.as_ref().ok().map(|e| (r.step, *e)))
        .collect()
}

/// The rows as CSV, with a comment header naming the design, the study time and the reference run; failed
/// runs have an empty error and their message in the last column.
pub(crate) fn time_csv(result: &TimeStudyResult, study: &TimeStudy, design: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# time-step study of {design}: displacement error at t = {} on {} points per patch against a reference run: {}",
        study.time, study.samples, result.reference
    );
    for (integrator, order) in &result.orders {
        let _ = writeln!(
            s,
            "# observed order of {}: {}",
            integrator.name(),
            order.map_or("n/a".to_string(), |q| format!("{q:.2}"))
        );
    }
    let _ = writeln!(
        s,
        "integrator,time_tolerance,h,error,wall_s,steps,newton_iterations,cuts,failure"
    );
    for r in &result.rows {
        let (error, failure) = match &r.error {
            Ok(e) => (format!("{e:.6e}"), String::new()),
            Err(m) => (String::new(), m.replace(['\n', ','], " ")),
        };
        let _ = writeln!(
            s,
            "{},{},{:e},{error},{:.4},{},{},{},{failure}",
            r.integrator.name(),
            r.tolerance.map_or(String::new(), |t| format!("{t:e}")),
            r.step,
            r.wall,
            r.steps,
            r.iterations,
            r.cuts
        );
    }
    s
}

/// The two charts of a time-step study: error against `h` and error against wall time, one series per
/// integrator (labelled with its observed order), on log–log axes; the titles name the reference.
pub(crate) fn time_charts(
    result: &TimeStudyResult,
    study: &TimeStudy,
    design: &str,
) -> [LineChart; 2] {
    let runs = |keep: &dyn Fn(&TimePoint) -> bool| -> Vec<(Real, Real, Real)> {
        result
            .rows
            .iter()
            .filter(|r| keep(r))
            .filter_map(|r| r.error.as_ref().ok().map(|e| (r.step, *e, r.wall)))
            .collect()
    };
    let mut curves: Vec<ErrorCurve> = result
        .orders
        .iter()
        .map(|(integrator, order)| ErrorCurve {
            label: match order {
                Some(q) => format!("{} (order {q:.2})", integrator.name()),
                None => integrator.name().to_string(),
            },
            runs: runs(&|r| r.integrator == *integrator && r.tolerance.is_none()),
        })
        .collect();
    if !study.tolerances.is_empty() {
        curves.push(ErrorCurve {
            label: "trapezoidal, error-controlled (h = mean step)".into(),
            runs: runs(&|r| r.tolerance.is_some()),
        });
    }
    let against = format!("at t = {}, against {}", study.time, result.reference);
    error_charts(
        &curves,
        &ErrorChartLabels {
            by_parameter: format!("{design}: error vs time step ({against})"),
            by_time: format!("{design}: work-precision over h ({against})"),
            parameter: "time step h [time]".into(),
        },
    )
}
