//! Line charts as SVG: several series of `(x, y)` points on linear or logarithmic axes, with an optional
//! legend, markers and dashed lines (reference slopes, tolerances).
//!
//! Rendering uses plotters' SVG backend only (no font or C libraries): text is written as SVG `<text>`
//! elements and laid out by plotters' crude size estimate, which is enough for axis labels, a title and a
//! legend. The chart is a plain description ([`LineChart`], in [`crate::post::chart`], below `study`) so
//! studies, run histories and tests can build one and render it with [`render_svg`] or [`write_svg`].
//!
//! ```no_run
//! use stentkit::io::chart::{LineChart, Scale, Series};
//! let mut chart = LineChart::new("convergence", "n", "error");
//! chart.x_scale = Scale::Log;
//! chart.y_scale = Scale::Log;
//! chart.series.push(Series::new("p = 2", vec![(8.0, 1e-2), (16.0, 2.5e-3), (32.0, 6.2e-4)]).with_markers());
//! chart.series.push(Series::new("slope 2", vec![(8.0, 2e-2), (32.0, 1.25e-3)]).dashed().unlabelled());
//! stentkit::io::chart::write_svg(&chart, std::path::Path::new("conv.svg")).unwrap();
//! ```

pub use crate::post::chart::{LineChart, LineStyle, Scale, Series};

use crate::math::Real;
use plotters::coord::ranged1d::{AsRangedCoord, Ranged, ValueFormatter};
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Why a chart could not be drawn or written.
#[derive(Debug, thiserror::Error)]
pub enum ChartError {
    /// No series has a point.
    #[error("the chart `{title}` has no points")]
    Empty {
        /// Chart title.
        title: String,
    },
    /// A point cannot be placed on the axes (not finite, or ≤ 0 on a logarithmic axis).
    #[error(
        "series {series} of chart `{title}`: point ({x}, {y}) cannot be drawn on its axes (not finite, or ≤ 0 on a log axis)"
    )]
    InvalidPoint {
        /// Chart title.
        title: String,
        /// Index of the series.
        series: usize,
        /// The point.
        x: Real,
        /// The point.
        y: Real,
    },
    /// plotters failed.
    #[error("drawing the chart `{title}`: {message}")]
    Drawing {
        /// Chart title.
        title: String,
        /// plotters' message.
        message: String,
    },
    /// The file could not be written.
    #[error("{}: cannot write the chart: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
}

/// Tableau 10: distinguishable colours, also in grey-scale print.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Renders the chart as an SVG document.
pub fn render_svg(chart: &LineChart) -> Result<String, ChartError> {
    let x = axis_range(chart, chart.x_scale, |p| p.0)?;
    let y = axis_range(chart, chart.y_scale, |p| p.1)?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, chart.size).into_drawing_area();
        match (chart.x_scale, chart.y_scale) {
            (Scale::Linear, Scale::Linear) => draw(chart, &root, x.0..x.1, y.0..y.1),
            (Scale::Linear, Scale::Log) => draw(chart, &root, x.0..x.1, (y.0..y.1).log_scale()),
            (Scale::Log, Scale::Linear) => draw(chart, &root, (x.0..x.1).log_scale(), y.0..y.1),
            (Scale::Log, Scale::Log) => {
                draw(chart, &root, (x.0..x.1).log_scale(), (y.0..y.1).log_scale())
            }
        }
        .map_err(|message| ChartError::Drawing {
            title: chart.title.clone(),
            message,
        })?;
    }
    Ok(svg)
}

/// Renders the chart and writes it to `path`, atomically (no partial SVG is ever visible).
pub fn write_svg(chart: &LineChart, path: &Path) -> Result<(), ChartError> {
    let svg = render_svg(chart)?;
    super::atomic::write_bytes_atomically(path, svg.as_bytes()).map_err(|source| ChartError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// The drawn range of one axis: the data's extent, padded by 5 % (linear) or to whole decades (log).
fn axis_range(
    chart: &LineChart,
    scale: Scale,
    coordinate: impl Fn(&(Real, Real)) -> Real,
) -> Result<(Real, Real), ChartError> {
    let (mut lo, mut hi) = (Real::INFINITY, Real::NEG_INFINITY);
    for (k, s) in chart.series.iter().enumerate() {
        for p in &s.points {
            let v = coordinate(p);
            let bad = !p.0.is_finite()
                || !p.1.is_finite()
                || (chart.x_scale == Scale::Log && p.0 <= 0.0)
                || (chart.y_scale == Scale::Log && p.1 <= 0.0);
            if bad {
                return Err(ChartError::InvalidPoint {
                    title: chart.title.clone(),
                    series: k,
                    x: p.0,
                    y: p.1,
                });
            }
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if lo > hi {
        return Err(ChartError::Empty {
            title: chart.title.clone(),
        });
    }
    Ok(match scale {
        Scale::Linear => {
            let pad = if hi > lo {
                0.05 * (hi - lo)
            } else {
                0.5 * lo.abs().max(1.0)
            };
            (lo - pad, hi + pad)
        }
        Scale::Log => {
            let (a, b) = (lo.log10().floor(), hi.log10().ceil());
            let b = if b > a { b } else { a + 1.0 };
            (10f64.powf(a), 10f64.powf(b))
        }
    })
}

/// Draws the chart on `root` with the given axis specifications (linear ranges or `log_scale()` ranges).
fn draw<DB, X, Y>(
    chart: &LineChart,
    root: &DrawingArea<DB, plotters::coord::Shift>,
    x: X,
    y: Y,
) -> Result<(), String>
where
    DB: DrawingBackend,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let mut ctx = ChartBuilder::on(root)
        .caption(&chart.title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(75)
        .build_cartesian_2d(x, y)
        .map_err(err)?;
    // A linear tick within round-off of zero (1e-9 of the axis span) is zero: plotters places ticks by adding
    // steps, and `-2.22e-16` is not a label anyone wants.
    let span = |scale: Scale, coordinate: fn(&(Real, Real)) -> Real| {
        axis_range(chart, scale, coordinate).map_or(0.0, |(lo, hi)| hi - lo)
    };
    let (x_span, y_span) = (span(chart.x_scale, |p| p.0), span(chart.y_scale, |p| p.1));
    let tick = |scale: Scale, v: &f64, span: Real| {
        if scale == Scale::Linear && v.abs() <= 1e-9 * span {
            "0".to_string()
        } else {
            tick_label(scale, *v)
        }
    };
    let (xs, ys) = (chart.x_scale, chart.y_scale);
    ctx.configure_mesh()
        .x_desc(&chart.x_label)
        .y_desc(&chart.y_label)
        .x_label_formatter(&|v| tick(xs, v, x_span))
        .y_label_formatter(&|v| tick(ys, v, y_span))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(err)?;
    let mut labelled = false;
    for (k, s) in chart.series.iter().enumerate() {
        let color = PALETTE[s.color.unwrap_or(k) % PALETTE.len()];
        let style = color.stroke_width(2);
        let points = s.points.clone();
        let drawn = match s.line {
            LineStyle::Solid => Some(
                ctx.draw_series(LineSeries::new(points.iter().copied(), style))
                    .map_err(err)?,
            ),
            LineStyle::Dashed => Some(
                ctx.draw_series(DashedLineSeries::new(points.iter().copied(), 8, 6, style))
                    .map_err(err)?,
            ),
            LineStyle::None => None,
        };
        if let (Some(drawn), Some(label)) = (drawn, &s.label) {
            labelled = true;
            let dashed = s.line == LineStyle::Dashed;
            drawn.label(label.as_str()).legend(move |(x, y)| {
                if dashed {
                    PathElement::new(vec![(x, y), (x + 8, y)], style)
                } else {
                    PathElement::new(vec![(x, y), (x + 20, y)], style)
                }
            });
        }
        if s.markers {
            ctx.draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))
                .map_err(err)?;
        }
    }
    if labelled {
        ctx.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerLeft)
            .draw()
            .map_err(err)?;
    }
    root.present().map_err(err)?;
    Ok(())
}

/// A short tick label: up to four significant digits on linear axes (`0.3`, `1250`), `1e-5` or `2.5e-5` on
/// logarithmic ones (plotters' computed tick values carry round-off such as 9.999999e-6).
fn tick_label(scale: Scale, v: Real) -> String {
    let trim = |s: String| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    match scale {
        Scale::Log => {
            let s = format!("{v:.2e}");
            let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
            format!("{}e{exponent}", trim(mantissa.to_string()))
        }
        Scale::Linear => {
            if v == 0.0 {
                return "0".to_string();
            }
            let magnitude = v.abs().log10().floor();
            if !(-4.0..6.0).contains(&magnitude) {
                return tick_label(Scale::Log, v);
            }
            let decimals = (3.0 - magnitude).max(0.0) as usize;
            trim(format!("{v:.decimals$}"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(scale: Scale) -> LineChart {
        let mut chart = LineChart::new("error vs n", "n", "relative error");
        chart.x_scale = scale;
        chart.y_scale = scale;
        chart.series.push(
            Series::new("p = 2", vec![(4.0, 1e-2), (8.0, 2.5e-3), (16.0, 6.25e-4)]).with_markers(),
        );
        chart
            .series
            .push(Series::new("slope −2", vec![(4.0, 2e-2), (16.0, 1.25e-3)]).dashed());
        chart
    }

    #[test]
    fn renders_every_series_and_the_labels_as_svg() {
        for scale in [Scale::Linear, Scale::Log] {
            let svg = render_svg(&sample(scale)).expect("renders");
            assert!(svg.starts_with("<svg"), "{}", &svg[..40]);
            assert!(svg.trim_end().ends_with("</svg>"));
            for text in ["error vs n", "relative error", "p = 2", "slope −2"] {
                assert!(svg.contains(text), "missing `{text}`");
            }
            // Three markers of the first series.
            assert_eq!(svg.matches("<circle").count(), 3);
        }
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick_label(Scale::Log, 9.999999999e-6), "1e-5");
        assert_eq!(tick_label(Scale::Log, 2.5e-3), "2.5e-3");
        assert_eq!(tick_label(Scale::Log, 100.0), "1e2");
        assert_eq!(tick_label(Scale::Linear, 0.30000000000000004), "0.3");
        assert_eq!(tick_label(Scale::Linear, 1250.0), "1250");
        assert_eq!(tick_label(Scale::Linear, -0.0125), "-0.0125");
        assert_eq!(tick_label(Scale::Linear, 0.0), "0");
    }

    #[test]
    fn rejects_points_a_log_axis_cannot_show() {
        let mut chart = sample(Scale::Log);
        chart.series[0].points.push((32.0, 0.0));
        assert!(matches!(
            render_svg(&chart),
            Err(ChartError::InvalidPoint { series: 0, .. })
        ));
        let empty = LineChart::new("t", "x", "y");
        assert!(matches!(render_svg(&empty), Err(ChartError::Empty { .. })));
    }
}
