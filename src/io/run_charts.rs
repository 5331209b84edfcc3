//! The charts of a run folder (`charts/*.svg`), drawn from the states recorded during the run, in the spirit of
//! the paper's history figures:
//!
//! * `temperature.svg` — temperature against time (every run);
//! * `displacement.svg` — the displacement components of every probe against time (designs with probes);
//! * `normalised.svg` — the probe components, the loads and the temperature each divided by its largest
//!   magnitude over the run, on the same axes (the paper's cantilever figure: how the response follows the
//!   programme);
//! * `recovery.svg` — the mean and largest recovery ratio against time with the normalised temperature and
//!   the programme's ramp (designs with a programme: 1 at the temporary shape, 0 at the permanent one);
//! * `recovery_by_material.svg` — the mean recovery ratio of each material region against time, with the
//!   normalised temperature (devices of several materials: which part recovers first);
//! * `delta_r.svg` — the mean radial contraction Δr against time (radial-contraction programmes);
//! * `load_path.svg` — the load factor against every probe displacement component (arc-length runs: the
//!   load–displacement curves, through limit points);
//! * `newton.svg` — Newton iterations per step against time (every run);
//! * `step_size.svg` — the step size and the time-error estimate over the tolerance against time, on log axes
//!   (error-controlled runs, `time.tolerance`);
//! * `contact_force.svg` — per obstacle the contact force against time: a cylinder's radial force (positive:
//!   the wires press on it), a plane's total force magnitude (models with contact; [`super::contact`]);
//! * `contact_diameter.svg` — per cylinder its radial force against its diameter `2R(t)` (the crimper's curve
//!   of a bench test: loading and unloading; models with a cylinder).

use super::chart::{ChartError, LineChart, Series, write_svg};
use super::contact::ContactSample;
use super::run_folder::Manifest;
use super::state::{LoadChannel, StateSample, load_channels};
use crate::math::Real;
use crate::model::Model;
use crate::solver::{Observer, Simulation, StepReport};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

/// Collects the states of a run for its charts.
pub(crate) struct RunCharts {
    channels: Vec<LoadChannel>,
    samples: Vec<StateSample>,
    /// The contact of each state (empty without contact).
    contact: Vec<ContactSample>,
}

impl RunCharts {
    /// Folder of the charts inside the run folder.
    pub(crate) const FOLDER: &'static str = super::run_folder::CHARTS_FOLDER;

    /// An empty collection for a run of `model`.
    pub(crate) fn new(model: &Model) -> Self {
        Self {
            channels: load_channels(model),
            samples: Vec::new(),
            contact: Vec::new(),
        }
    }

    /// The states recorded so far.
    pub(crate) fn samples(&self) -> &[StateSample] {
        &self.samples
    }

    /// The contact of the states recorded so far (empty without contact).
    pub(crate) fn contact_samples(&self) -> &[ContactSample] {
        &self.contact
    }

    /// Continues the charts of a resumed run with the states (and their contact) recorded up to its
    /// checkpoint.
    pub(crate) fn resumed(
        mut self,
        samples: Vec<StateSample>,
        contact: Vec<ContactSample>,
    ) -> Self {
        self.samples = samples;
        self.contact = contact;
        self
    }

    /// The charts of the states recorded so far (see the module documentation).
    pub(crate) fn charts(&self, model: &Model) -> Vec<(&'static str, LineChart)> {
        let name = model.name();
        let length = model.units.length();
        let times: Vec<Real> = self.samples.iter().map(|s| s.time).collect();
        let series = |f: &dyn Fn(&StateSample) -> Real| -> Vec<(Real, Real)> {
            times
                .iter()
                .zip(&self.samples)
                .map(|(&t, s)| (t, f(s)))
                .collect()
        };
        let normalised = |points: Vec<(Real, Real)>| -> Vec<(Real, Real)> {
            let peak = points.iter().map(|p| p.1.abs()).fold(0.0, Real::max);
            let scale = if peak > 0.0 { 1.0 / peak } else { 1.0 };
            points.into_iter().map(|(t, v)| (t, v * scale)).collect()
        };
        let mut charts = Vec::new();

        let mut temperature = LineChart::new(
            format!("{name}: temperature"),
            "time [s]",
            "temperature [°C]",
        );
        temperature
            .series
            .push(Series::new("T", series(&|s| s.temperature)).with_color(3));
        charts.push(("temperature.svg", temperature));

        if !model.probes.is_empty() {
            let mut displacement = LineChart::new(
                format!("{name}: probe displacements"),
                "time [s]",
                format!("displacement [{length}]"),
            );
            let mut overlay = LineChart::new(
                format!("{name}: response and programme, each divided by its largest magnitude"),
                "time [s]",
                "normalised value [-]",
            );
            for (p, probe) in model.probes.iter().enumerate() {
                for (c, axis) in ["ux", "uy", "uz"].iter().enumerate() {
                    let points = series(&|s| s.probes[p][c]);
                    if points.iter().all(|q| q.1.abs() == 0.0) {
                        continue;
                    }
                    let label = format!("{}.{axis}", probe.name);
                    displacement
                        .series
                        .push(Series::new(label.clone(), points.clone()));
                    overlay.series.push(Series::new(label, normalised(points)));
                }
            }
            for (l, channel) in self.channels.iter().enumerate() {
                overlay.series.push(
                    Series::new(
                        format!("{} [{}]", channel.name, channel.unit),
                        normalised(series(&|s| s.loads[l])),
                    )
                    .dashed(),
                );
            }
            overlay.series.push(
                Series::new("T", normalised(series(&|s| s.temperature)))
                    .dashed()
                    .with_color(3),
            );
            if !displacement.series.is_empty() {
                charts.push(("displacement.svg", displacement));
                charts.push(("normalised.svg", overlay));
            }
            if self.samples.iter().any(|s| s.load_factor.is_some()) {
                let mut path = LineChart::new(
                    format!("{name}: load factor against displacement"),
                    format!("displacement [{length}]"),
                    "load factor λ [-]",
                );
                for (p, probe) in model.probes.iter().enumerate() {
                    for (c, axis) in ["ux", "uy", "uz"].iter().enumerate() {
                        let points: Vec<(Real, Real)> = self
                            .samples
                            .iter()
                            .map(|s| (s.probes[p][c], s.load_factor.unwrap_or(0.0)))
                            .collect();
                        if points.iter().all(|q| q.0 == 0.0) {
                            continue;
                        }
                        path.series
                            .push(Series::new(format!("{}.{axis}", probe.name), points));
                    }
                }
                if !path.series.is_empty() {
                    charts.push(("load_path.svg", path));
                }
            }
        }

        if self.samples.iter().any(|s| s.recovery.is_some()) {
            let recovery = |f: &dyn Fn(&crate::post::recovery::Recovery) -> Real| {
                self.samples
                    .iter()
                    .filter_map(|s| s.recovery.as_ref().map(|r| (s.time, f(r))))
                    .collect::<Vec<_>>()
            };
            let mut chart = LineChart::new(
                format!("{name}: recovery ratio |η|/|η_temp| (1: temporary shape, 0: permanent)"),
                "time [s]",
                "ratio [-], normalised temperature [-]",
            );
            chart
                .series
                .push(Series::new("mean ratio", recovery(&|r| r.ratio_mean)));
            chart
                .series
                .push(Series::new("largest ratio", recovery(&|r| r.ratio_max)));
            let (lo, hi) = model.temperature().range();
            let span = if hi > lo { hi - lo } else { 1.0 };
            let temperature = || {
                Series::new(
                    format!("(T − {lo} °C)/{span} °C"),
                    series(&|s| (s.temperature - lo) / span),
                )
                .dashed()
                .with_color(3)
            };
            chart.series.push(temperature());
            if let Some(l) = self.channels.iter().position(|c| c.name == "programme") {
                chart.series.push(
                    Series::new("programme ramp f(t)", series(&|s| s.loads[l]))
                        .dashed()
                        .with_color(7),
                );
            }
            charts.push(("recovery.svg", chart));
            let regions = model.material_regions();
            if !regions.is_empty() {
                let mut chart = LineChart::new(
                    format!(
                        "{name}: mean recovery ratio per material (1: temporary shape, 0: permanent)"
                    ),
                    "time [s]",
                    "ratio [-], normalised temperature [-]",
                );
                for (k, m) in regions.iter().enumerate() {
                    let points = self
                        .samples
                        .iter()
                        .filter_map(|s| {
                            let r = s.recovery.as_ref()?;
                            r.by_material.get(k).map(|&v| (s.time, v))
                        })
                        .collect();
                    chart
                        .series
                        .push(Series::new(model.material_names[*m].clone(), points));
                }
                chart.series.push(temperature());
                charts.push(("recovery_by_material.svg", chart));
            }
            let delta_r: Vec<(Real, Real)> = self
                .samples
                .iter()
                .filter_map(|s| {
                    s.recovery
                        .as_ref()
                        .and_then(|r| r.delta_r)
                        .map(|d| (s.time, d))
                })
                .collect();
            if !delta_r.is_empty() {
                let mut chart = LineChart::new(
                    format!("{name}: mean radial contraction Δr of the driven nodes"),
                    "time [s]",
                    format!("Δr [{length}]"),
                );
                chart.series.push(Series::new("Δr", delta_r));
                charts.push(("delta_r.svg", chart));
            }
        }

        let mut newton = LineChart::new(
            format!("{name}: Newton iterations per step"),
            "time [s]",
            "iterations",
        );
        newton.series.push(
            Series::new(
                "iterations",
                self.samples
                    .iter()
                    .skip(1)
                    .map(|s| (s.time, s.iterations as Real))
                    .collect(),
            )
            .with_color(4),
        );
        if newton.series[0].points.is_empty() {
            newton.series[0].points.push((0.0, 0.0));
        }
        charts.push(("newton.svg", newton));

        if let Some(tolerance) = model.time().tolerance {
            let mut steps = LineChart::new(
                format!("{name}: error-controlled steps (tolerance {tolerance:e})"),
                "time [s]",
                "step size [s]; estimate / tolerance [-]",
            );
            steps.y_scale = super::chart::Scale::Log;
            let dt: Vec<(Real, Real)> = self
                .samples
                .iter()
                .filter(|s| s.dt > 0.0)
                .map(|s| (s.time, s.dt))
                .collect();
            // (A log axis takes positive values only: estimates of zero, in holds of an elastic material, are
            // left out.)
            let ratio: Vec<(Real, Real)> = self
                .samples
                .iter()
                .filter_map(|s| s.error_estimate.map(|e| (s.time, e / tolerance)))
                .filter(|p| p.1 > 0.0)
                .collect();
            if !dt.is_empty() {
                steps
                    .series
                    .push(Series::new("step size dt [s]", dt).with_color(0));
                if !ratio.is_empty() {
                    steps.series.push(
                        Series::new("estimate / tolerance [-]", ratio)
                            .dashed()
                            .with_color(1),
                    );
                }
                charts.push(("step_size.svg", steps));
            }
        }
        charts.extend(self.contact_charts(model));
        charts
    }

    /// The contact charts (module docs): none without contact samples.
    fn contact_charts(&self, model: &Model) -> Vec<(&'static str, LineChart)> {
        let Some(contact) = &model.contact else {
            return Vec::new();
        };
        if self.contact.is_empty() {
            return Vec::new();
        }
        let (name, units) = (model.name(), model.units);
        let force = units.force();
        let mut against_time = LineChart::new(
            format!(
                "{name}: contact force (cylinders: radial, positive pressing; planes: magnitude)"
            ),
            "time [s]",
            format!("force [{force}]"),
        );
        let mut against_diameter = LineChart::new(
            format!("{name}: radial force against the cylinder's diameter"),
            format!("diameter 2R [{}]", units.length()),
            format!("radial force [{force}]"),
        );
        for (k, obstacle) in contact.obstacles.iter().enumerate() {
            let of = |s: &ContactSample| s.obstacles.get(k).copied();
            let over_time: Vec<(Real, Real)> = self
                .contact
                .iter()
                .filter_map(|s| of(s).map(|o| (s.time, o.radial_force.unwrap_or(o.force))))
                .collect();
            let label = match obstacle.surface {
                crate::model::Surface::Cylinder { .. } | crate::model::Surface::Lumen(_) => {
                    format!("{} radial", obstacle.name)
                }
                crate::model::Surface::Plane { .. } => format!("{} |F|", obstacle.name),
            };
            against_time.series.push(Series::new(label, over_time));
            let curve: Vec<(Real, Real)> = self
                .contact
                .iter()
                .filter_map(|s| of(s).and_then(|o| Some((o.diameter?, o.radial_force?))))
                .collect();
            if !curve.is_empty() {
                against_diameter
                    .series
                    .push(Series::new(obstacle.name.clone(), curve));
            }
        }
        let mut charts = vec![("contact_force.svg", against_time)];
        if !against_diameter.series.is_empty() {
            charts.push(("contact_diameter.svg", against_diameter));
        }
        charts
    }

    /// Writes the charts into `run_dir/charts`, each listed in the run folder's `manifest` first (if given);
    /// returns the files written (relative to `run_dir`).
    ///
    /// # Errors
    /// [`ChartError`] when a chart cannot be listed, drawn or written.
    pub(crate) fn write(
        &self,
        model: &Model,
        run_dir: &Path,
        manifest: Option<&Manifest>,
    ) -> Result<Vec<PathBuf>, ChartError> {
        let folder = run_dir.join(Self::FOLDER);
        std::fs::create_dir_all(&folder).map_err(|source| ChartError::Io {
            path: folder.clone(),
            source,
        })?;
        let mut written = Vec::new();
        for (file, chart) in self.charts(model) {
            let relative = Path::new(Self::FOLDER).join(file);
            if let Some(manifest) = manifest {
                manifest.claim(&relative).map_err(|source| ChartError::Io {
                    path: run_dir.join(super::run_folder::MANIFEST),
                    source,
                })?;
            }
            write_svg(&chart, &folder.join(file))?;
            written.push(relative);
        }
        Ok(written)
    }
}

impl RunCharts {
    /// Keeps the state of `sim` (and its contact, with contact).
    fn keep(&mut self, sim: &Simulation<'_>, report: Option<&StepReport>) {
        self.samples
            .push(StateSample::of(sim, &self.channels, report));
        if let Some(contact) = sim.contact() {
            self.contact
                .push(super::contact::sample(sim.model(), &contact, sim.time()));
        }
    }
}

impl Observer for RunCharts {
    fn start(&mut self, sim: &Simulation<'_>) -> ControlFlow<()> {
        self.keep(sim, None);
        ControlFlow::Continue(())
    }

    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        self.keep(sim, Some(report));
        ControlFlow::Continue(())
    }
}
