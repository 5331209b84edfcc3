//! A line chart as a plain description: several series of `(x, y)` points on linear or logarithmic axes, with
//! an optional legend, markers and dashed lines (reference slopes, tolerances). Studies, run histories and tests
//! build one; [`crate::io::chart`] draws it as SVG. Pure data, below `study` so that a study can return its
//! charts without knowing how they are drawn.

use crate::math::Real;

/// How an axis maps values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scale {
    /// Linear axis.
    #[default]
    Linear,
    /// Base-10 logarithmic axis (every value on it must be > 0).
    Log,
}

/// How a series' points are joined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LineStyle {
    /// A solid polyline.
    #[default]
    Solid,
    /// A dashed polyline (reference lines).
    Dashed,
    /// No line (markers only, if any).
    None,
}

/// One series of a chart.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry; `None` keeps the series out of the legend.
    pub label: Option<String>,
    /// The points, drawn in the given order.
    pub points: Vec<(Real, Real)>,
    /// Colour as an index into a fixed 10-colour palette (wraps around). Defaults to the series' position.
    pub color: Option<usize>,
    /// Line style.
    pub line: LineStyle,
    /// Draw a filled circle at every point.
    pub markers: bool,
}

impl Series {
    /// A solid, labelled series without markers, coloured by its position in the chart.
    pub fn new(label: impl Into<String>, points: Vec<(Real, Real)>) -> Self {
        Self {
            label: Some(label.into()),
            points,
            color: None,
            line: LineStyle::Solid,
            markers: false,
        }
    }

    /// Draws the series dashed.
    pub fn dashed(mut self) -> Self {
        self.line = LineStyle::Dashed;
        self
    }

    /// Adds markers at the points.
    pub fn with_markers(mut self) -> Self {
        self.markers = true;
        self
    }

    /// Uses palette colour `index`.
    pub fn with_color(mut self, index: usize) -> Self {
        self.color = Some(index);
        self
    }

    /// Leaves the series out of the legend.
    pub fn unlabelled(mut self) -> Self {
        self.label = None;
        self
    }
}

/// A line chart: a title, two axes and series.
#[derive(Debug, Clone, PartialEq)]
pub struct LineChart {
    /// Title above the plot.
    pub title: String,
    /// Horizontal axis label (include the unit).
    pub x_label: String,
    /// Vertical axis label (include the unit).
    pub y_label: String,
    /// Horizontal axis scale.
    pub x_scale: Scale,
    /// Vertical axis scale.
    pub y_scale: Scale,
    /// Series, drawn in order (later on top).
    pub series: Vec<Series>,
    /// Image size in pixels (width, height).
    pub size: (u32, u32),
}

impl LineChart {
    /// An empty 800×600 chart with linear axes.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            series: Vec::new(),
            size: (800, 600),
        }
    }
}
