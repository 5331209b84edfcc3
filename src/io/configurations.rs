//! Configuration figures like the paper's (Figs. `straight_stent_def`, `bend_stent_plane_config`): the full
//! device's centrelines at chosen snapshot times in black over the initial shape in light grey, in a 3D
//! axonometric view and in plane views, one row per time with the time and temperature in its caption —
//! `charts/configurations.svg` — and the same per time, `charts/configuration_t<time>.svg`.
//!
//! **Which times.** The design's `output.snapshots.times` when it lists any (the paper's figure times are
//! snapshot times), otherwise up to [`MAX_ROWS`] of the snapshots spread evenly over the run, the final one
//! always; the initial state is the grey shape of every panel.
//!
//! **Which views.** `output.configurations.views` (`axonometric`, `x1-x2`, `x1-x3`, `x2-x3`); by default the
//! axonometric view and the coordinate plane of the initial shape's two largest extents — `x1–x2` for the
//! straight stent (its axis and a diameter; ties go to the lower axis), `x1–x3` for the curved one (its plane
//! of bending), the paper's choices. Every panel keeps the lengths' proportions (equal scales on both axes).
//!
//! The figures are drawn from the centrelines the snapshot writer keeps at every snapshot (no file is read
//! back): after `--resume` they hold the snapshots since the checkpoint and the final one.

use super::chart::ChartError;
use crate::math::{Real, Vec3};
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Most rows (times) in `configurations.svg`.
pub(crate) const MAX_ROWS: usize = 6;

/// Samples per patch of the centrelines kept for the figures.
pub(crate) const CENTRELINE_SAMPLES: usize = 41;

/// One state of the device for the figures: its time, temperature and the full device's centrelines.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Configuration {
    /// Time \[s\].
    pub time: Real,
    /// Temperature \[°C\].
    pub temperature: Real,
    /// The centrelines of the full device (mirrored back), one polyline per rod.
    pub lines: Vec<Vec<Vec3>>,
}

/// How a panel looks at the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum View {
    /// From the direction of azimuth −55° and elevation 25° (x3 up).
    Axonometric,
    /// Onto the plane of two coordinate axes (0-based), the first horizontal.
    Plane(usize, usize),
}

impl View {
    /// Parses `axonometric`, `x1-x2`, `x1-x3`, `x2-x3` (or the reversed pairs).
    pub fn parse(text: &str) -> Option<Self> {
        if text == "axonometric" {
            return Some(View::Axonometric);
        }
        let (a, b) = text.split_once('-')?;
        let axis = |s: &str| match s {
            "x1" => Some(0),
            "x2" => Some(1),
            "x3" => Some(2),
            _ => None,
        };
        let (a, b) = (axis(a)?, axis(b)?);
        (a != b).then_some(View::Plane(a, b))
    }

    /// The view's name (what [`View::parse`] reads).
    pub fn name(self) -> String {
        match self {
            View::Axonometric => "axonometric".into(),
            View::Plane(a, b) => format!("x{}-x{}", a + 1, b + 1),
        }
    }

    /// The panel's horizontal and vertical directions and the direction toward the viewer (right-handed,
    /// unit vectors).
    pub fn axes(self) -> [Vec3; 3] {
        match self {
            View::Axonometric => {
                let (azimuth, elevation) = (-55f64.to_radians(), 25f64.to_radians());
                let right = Vec3::new(-azimuth.sin(), azimuth.cos(), 0.0);
                let toward = Vec3::new(
                    elevation.cos() * azimuth.cos(),
                    elevation.cos() * azimuth.sin(),
                    elevation.sin(),
                );
                [right, toward.cross(&right), toward]
            }
            View::Plane(a, b) => {
                let (right, up) = (Vec3::ith(a, 1.0), Vec3::ith(b, 1.0));
                [right, up, right.cross(&up)]
            }
        }
    }

    /// The point's place on the panel (horizontal, vertical).
    pub fn project(self, x: &Vec3) -> (Real, Real) {
        let [right, up, _] = self.axes();
        (x.dot(&right), x.dot(&up))
    }
}

/// The default views of a device whose initial centrelines are `lines` (module docs).
pub(crate) fn default_views(lines: &[Vec<Vec3>]) -> Vec<View> {
    let (mut lo, mut hi) = (
        Vec3::repeat(Real::INFINITY),
        Vec3::repeat(Real::NEG_INFINITY),
    );
    for x in lines.iter().flatten() {
        lo = lo.inf(x);
        hi = hi.sup(x);
    }
    let extent = hi - lo;
    let mut axes = [0, 1, 2];
    // Largest extents first; equal extents (to 1e-9 of the largest) keep the lower axis first.
    let tie = 1e-9 * extent.max();
    axes.sort_by(|&a, &b| {
        if (extent[a] - extent[b]).abs() <= tie {
            a.cmp(&b)
        } else {
            extent[b].total_cmp(&extent[a])
        }
    });
    let (a, b) = (axes[0].min(axes[1]), axes[0].max(axes[1]));
    vec![View::Axonometric, View::Plane(a, b)]
}

/// The states shown: those at `requested` times (to `snap`) when any is requested, otherwise up to
/// [`MAX_ROWS`] spread evenly over `states` after the first (the initial state), the last always (the tests'
/// view of [`chosen_indices`]).
#[cfg(test)]
fn chosen<'a>(
    states: &'a [Configuration],
    requested: &[Real],
    snap: Real,
) -> Vec<&'a Configuration> {
    let times: Vec<Real> = states.iter().map(|s| s.time).collect();
    chosen_indices(&times, requested, snap)
        .into_iter()
        .map(|k| &states[k])
        .collect()
}

/// The indices into `times` (the states' times, the first the initial state) of the states shown: those at
/// `requested` times (to `snap`) when any is requested, otherwise up to [`MAX_ROWS`] spread evenly after the
/// first, the last always.
pub(crate) fn chosen_indices(times: &[Real], requested: &[Real], snap: Real) -> Vec<usize> {
    let later = 1..times.len().max(1);
    if !requested.is_empty() {
        let picked: Vec<usize> = later
            .clone()
            .filter(|&k| requested.iter().any(|t| (times[k] - t).abs() <= snap))
            .collect();
        if !picked.is_empty() {
            return picked;
        }
    }
    let n = later.len();
    if n <= MAX_ROWS {
        return later.collect();
    }
    (1..=MAX_ROWS).map(|k| (k * n).div_ceil(MAX_ROWS)).collect()
}

/// Light grey of the initial shape.
const INITIAL: RGBColor = RGBColor(200, 200, 200);

/// Panel size in pixels.
const PANEL: (u32, u32) = (480, 360);

/// The SVG of `rows` (one row per state) against the initial state `initial`, one column per view.
///
/// # Errors
/// [`ChartError::Drawing`] when plotters fails, [`ChartError::Empty`] without a point to draw.
pub(crate) fn render(
    title: &str,
    length: &str,
    initial: &Configuration,
    rows: &[&Configuration],
    views: &[View],
) -> Result<String, ChartError> {
    let drawing = |message: String| ChartError::Drawing {
        title: title.to_string(),
        message,
    };
    if initial.lines.iter().all(Vec::is_empty) || views.is_empty() || rows.is_empty() {
        return Err(ChartError::Empty {
            title: title.to_string(),
        });
    }
    let (width, height) = (
        PANEL.0 * views.len() as u32,
        PANEL.1 * rows.len() as u32 + 40,
    );
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| drawing(e.to_string()))?;
        let root = root
            .titled(title, ("sans-serif", 22))
            .map_err(|e| drawing(e.to_string()))?;
        let panels = root.split_evenly((rows.len(), views.len()));
        for (k, panel) in panels.iter().enumerate() {
            let (state, view) = (rows[k / views.len()], views[k % views.len()]);
            draw_panel(panel, length, initial, state, view).map_err(drawing)?;
        }
        root.present().map_err(|e| drawing(e.to_string()))?;
    }
    Ok(svg)
}

/// One panel: the initial shape in grey, `state` in black, equal scales, the caption naming time, temperature
/// and view.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    length: &str,
    initial: &Configuration,
    state: &Configuration,
    view: View,
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let project = |lines: &[Vec<Vec3>]| -> Vec<Vec<(Real, Real)>> {
        lines
            .iter()
            .map(|l| l.iter().map(|x| view.project(x)).collect())
            .collect()
    };
    let (grey, black) = (project(&initial.lines), project(&state.lines));
    let (mut lo, mut hi) = (
        (Real::INFINITY, Real::INFINITY),
        (Real::NEG_INFINITY, Real::NEG_INFINITY),
    );
    for &(x, y) in grey.iter().chain(&black).flatten() {
        lo = (lo.0.min(x), lo.1.min(y));
        hi = (hi.0.max(x), hi.1.max(y));
    }
    // Equal scales: widen the shorter range to the panel's aspect ratio.
    let (w, h) = area.dim_in_pixel();
    let (plot_w, plot_h) = (
        Real::from(w.saturating_sub(70)),
        Real::from(h.saturating_sub(70)),
    );
    let (cx, cy) = (0.5 * (lo.0 + hi.0), 0.5 * (lo.1 + hi.1));
    let scale = ((hi.0 - lo.0) / plot_w)
        .max((hi.1 - lo.1) / plot_h)
        .max(Real::MIN_POSITIVE)
        * 1.08;
    let (hx, hy) = (0.5 * scale * plot_w, 0.5 * scale * plot_h);
    let caption = format!(
        "t = {:.4} s, T = {:.1} °C — {}",
        state.time,
        state.temperature,
        view.name()
    );
    let (x_label, y_label) = match view {
        View::Axonometric => (String::new(), String::new()),
        View::Plane(a, b) => (
            format!("x{} ({length})", a + 1),
            format!("x{} ({length})", b + 1),
        ),
    };
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 15))
        .margin(8)
        .x_label_area_size(30)
        .y_label_area_size(40)
        .build_cartesian_2d(cx - hx..cx + hx, cy - hy..cy + hy)
        .map_err(err)?;
    let mut mesh = chart.configure_mesh();
    mesh.disable_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_labels(5)
        .y_labels(5);
    if view == View::Axonometric {
        mesh.disable_axes();
    }
    mesh.draw().map_err(err)?;
    for (lines, colour) in [(&grey, INITIAL), (&black, BLACK)] {
        chart
            .draw_series(
                lines
                    .iter()
                    .map(|l| PathElement::new(l.clone(), colour.stroke_width(1))),
            )
            .map_err(err)?;
    }
    Ok(())
}

/// File name of the per-time figure of a state at `time`.
pub(crate) fn per_time_file(time: Real) -> String {
    format!("configuration_t{time:.4}.svg")
}

/// Writes `configurations.svg` and one figure per chosen state into `folder` (the run's `charts/`), each claimed
/// first by `claim` with its path relative to the run folder (`charts/<file>`); returns those paths.
///
/// # Errors
/// As [`render`], and [`ChartError::Io`] when a file cannot be claimed or written.
pub(crate) fn write(
    folder: &Path,
    relative: &Path,
    titles: (&str, &str),
    initial: &Configuration,
    rows: &[&Configuration],
    views: &[View],
    mut claim: impl FnMut(&Path) -> std::io::Result<()>,
) -> Result<Vec<PathBuf>, ChartError> {
    let (name, length) = titles;
    let mut figures = vec![(
        "configurations.svg".to_string(),
        format!("{name}: configurations (initial shape in grey)"),
        rows.to_vec(),
    )];
    for state in rows {
        figures.push((
            per_time_file(state.time),
            format!("{name} at t = {:.4} s (initial shape in grey)", state.time),
            vec![*state],
        ));
    }
    let mut written = Vec::new();
    for (file, title, shown) in figures {
        let path = relative.join(&file);
        claim(&path).map_err(|source| ChartError::Io {
            path: path.clone(),
            source,
        })?;
        let svg = render(&title, length, initial, &shown, views)?;
        let target = folder.join(&file);
        super::atomic::write_bytes_atomically(&target, svg.as_bytes()).map_err(|source| {
            ChartError::Io {
                path: target,
                source,
            }
        })?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn configuration(time: Real, lines: Vec<Vec<Vec3>>) -> Configuration {
        Configuration {
            time,
            temperature: 90.0,
            lines,
        }
    }

    /// The straight stent lies along x1 with equal x2 and x3 extents: x1–x2 (the paper's view); the curved
    /// stent bends in x1–x3: x1–x3.
    #[test]
    fn the_default_plane_holds_the_two_largest_extents() {
        let straight = vec![vec![
            Vec3::new(0.0, -20.0, -20.0),
            Vec3::new(75.0, 20.0, 20.0),
        ]];
        assert_eq!(default_views(&straight)[1], View::Plane(0, 1));
        let bent = vec![vec![
            Vec3::new(0.0, -10.0, 0.0),
            Vec3::new(60.0, 10.0, 40.0),
        ]];
        assert_eq!(default_views(&bent)[1], View::Plane(0, 2));
    }

    #[test]
    fn views_parse_and_name_each_other() {
        for text in ["axonometric", "x1-x2", "x1-x3", "x2-x3", "x3-x1"] {
            let view = View::parse(text).expect(text);
            assert_eq!(View::parse(&view.name()), Some(view));
        }
        assert_eq!(View::parse("x1-x1"), None);
        assert_eq!(View::parse("top"), None);
    }

    /// Requested times pick their snapshots; otherwise at most MAX_ROWS spread over the run, the last kept.
    #[test]
    fn the_rows_are_the_requested_times_or_an_even_spread() {
        let states: Vec<Configuration> = (0..21)
            .map(|k| configuration(0.1 * k as Real, vec![vec![Vec3::zeros()]]))
            .collect();
        let picked = chosen(&states, &[0.5, 1.75], 1e-9);
        assert_eq!(picked.len(), 1);
        assert!((picked[0].time - 0.5).abs() < 1e-12);
        let spread = chosen(&states, &[], 1e-9);
        assert_eq!(spread.len(), MAX_ROWS);
        assert!((spread.last().expect("last").time - 2.0).abs() < 1e-12);
        assert!(spread.windows(2).all(|w| w[0].time < w[1].time));
    }

    #[test]
    fn a_figure_draws_both_shapes() {
        let initial = configuration(0.0, vec![vec![Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0)]]);
        let later = configuration(1.0, vec![vec![Vec3::zeros(), Vec3::new(0.5, 0.5, 0.0)]]);
        let svg = render(
            "test",
            "mm",
            &initial,
            &[&later],
            &[View::Axonometric, View::Plane(0, 1)],
        )
        .expect("svg");
        assert!(svg.contains("<svg") && svg.contains("t = 1.0000 s"));
        assert!(
            svg.contains("#C8C8C8") || svg.contains("rgb(200,200,200)"),
            "grey lines"
        );
    }
}
