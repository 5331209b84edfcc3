//! The two log–log charts of an error study: error against the study's parameter (`n`, `h`) and error against
//! wall time (work–precision), one series per curve (a degree, an integrator).

use crate::math::Real;
use crate::post::chart::{LineChart, Scale, Series};

/// Wall times are charted on a log axis; a run faster than the clock resolves is drawn at this floor \[s\].
pub(crate) const WALL_TIME_FLOOR: Real = 1e-6;

/// One curve of an error study: a label and its runs as `(parameter, error, wall time [s])`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ErrorCurve {
    /// Legend entry (e.g. `p = 4`, `backward-euler`).
    pub label: String,
    /// Runs as `(parameter, relative error, wall time [s])`; runs with a zero or failed error are left out.
    pub runs: Vec<(Real, Real, Real)>,
}

/// Titles and axis labels of the two charts of an error study.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ErrorChartLabels {
    /// Title of the error-against-parameter chart.
    pub by_parameter: String,
    /// Title of the work–precision chart.
    pub by_time: String,
    /// Label of the parameter axis (with its unit).
    pub parameter: String,
}

/// The two log–log charts of an error study: error against the study's parameter and error against wall time
/// (work–precision), one series per curve.
pub(crate) fn error_charts(curves: &[ErrorCurve], labels: &ErrorChartLabels) -> [LineChart; 2] {
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
                runs.iter()
                    .map(|r| (r.2.max(WALL_TIME_FLOOR), r.1))
                    .collect(),
            )
            .with_markers()
            .with_color(index),
        );
    }
    [by_parameter, by_time]
}
