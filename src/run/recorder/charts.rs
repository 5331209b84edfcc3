//! The charts as a recorder: [`crate::io::run_charts`]' histories of the states collected (its position); its
//! estimate the charts' points and the snapshots' configuration figures.

use super::{Finishing, Recorder, RecorderKind, damaged};
use crate::io::checkpoint::{Decoder, Encoder, Problem};
use crate::io::configurations::{CENTRELINE_SAMPLES, MAX_ROWS};
use crate::io::contact::{ContactSample, ObstacleSample};
use crate::io::render::PANEL_WIDTH;
use crate::io::run_charts::RunCharts;
use crate::io::state::{StateSample, load_channels};
use crate::io::summary::{FinalState, RunSummaryFile};
use crate::math::Real;
use crate::model::Model;
use crate::post::device::{device_sample_counts, patch_copies};
use crate::post::recovery::Recovery;
use crate::run::RunError;
use crate::run::estimate::{DiskPart, Sizing};
use crate::solver::Simulation;

/// The charts of the run's histories ([`crate::io::run_charts`]), with the snapshots' configuration figures.
pub(super) const CHARTS: RecorderKind = RecorderKind {
    name: "charts",
    create: |_, sim| Ok(Box::new(RunCharts::new(sim.model()))),
    check_resume: |_, position, _| {
        decode_position(position).map_err(|p| damaged("charts/", p))?;
        Ok(())
    },
    resume: |_, sim, position| {
        let (samples, contact) = decode_position(position).map_err(|p| damaged("charts/", p))?;
        Ok(Box::new(
            RunCharts::new(sim.model()).resumed(samples, contact),
        ))
    },
    estimate: |s| DiskPart::new("charts", estimated_bytes(s) as u64),
};

/// Bytes of a chart besides its points: axes, labels, legend (22 kB measured for the straight stent's
/// temperature chart).
const CHART_FIXED_BYTES: Real = 30_000.0;

/// Bytes per plotted point of a chart series: 8.2 measured (the bend's temperature chart at 10⁵ steps).
const CHART_POINT_BYTES: Real = 10.0;

/// Bytes per point of a polyline in an SVG figure (`x,y ` with plotters' coordinates: 8–9 measured).
const SVG_POINT_BYTES: Real = 10.0;

/// Bytes per pixel of the shaded picture's PNG: 0.33 measured (the straight stent's, 485 kB for 1.47 million
/// pixels, mostly white).
const PNG_PIXEL_BYTES: Real = 0.5;

/// `charts/`: the charts' fixed parts and a point per state and series, and the configuration figures.
fn estimated_bytes(s: &Sizing<'_>) -> Real {
    let model = s.model();
    let count = s.snapshots as Real;
    let device_points: Real = device_sample_counts(model, CENTRELINE_SAMPLES)
        .iter()
        .enumerate()
        .map(|(k, &n)| (patch_copies(model, k).len() * n) as Real)
        .sum();
    let (charts, series) = chart_counts(model);
    // The configuration figures: up to MAX_ROWS rows and one figure per row, each panel the initial and the
    // current centrelines of the full device in two views.
    let figure_rows = (count - 1.0).clamp(0.0, MAX_ROWS as Real);
    let figures = 2.0 * figure_rows * 2.0 * 2.0 * device_points * SVG_POINT_BYTES;
    // Their shaded picture: the initial state and each row, a square panel each (the straight stent's are
    // 2:3) of PANEL_WIDTH² pixels.
    let picture = if s.design.output.snapshots.render {
        (figure_rows + 1.0) * Real::from(PANEL_WIDTH).powi(2) * PNG_PIXEL_BYTES
    } else {
        0.0
    };
    let figures = figures + picture;
    charts * CHART_FIXED_BYTES + s.states * series * CHART_POINT_BYTES + figures
}

/// The charts a run draws and the number of series in them (io::run_charts): temperature (1), probe
/// displacements (3 per probe) and their normalised overlay (3 per probe, a load per channel, the
/// temperature), recovery (4) and Δr (1) with a programme, Newton iterations (1), the contact force (1 per
/// obstacle) and the radial force against the diameter (1 per obstacle, charged for every obstacle).
fn chart_counts(model: &Model) -> (Real, Real) {
    let probes = model.probes.len() as Real;
    let mut charts = 2.0;
    let mut series = 2.0;
    if probes > 0.0 {
        charts += 2.0;
        series += 6.0 * probes + load_channels(model).len() as Real + 1.0;
    }
    if model.programme.is_some() {
        charts += 2.0;
        series += 5.0;
    }
    if let Some(contact) = &model.contact {
        charts += 2.0;
        series += 2.0 * contact.obstacles.len() as Real;
    }
    (charts, series)
}

pub(super) fn encode_sample(e: &mut Encoder, s: &StateSample) {
    e.usize(s.step);
    e.f64(s.time);
    e.f64(s.dt);
    e.f64(s.temperature);
    e.f64s(&s.loads);
    e.usize(s.iterations);
    e.f64s(&s.residuals);
    e.usize(s.cuts);
    e.option(s.error_estimate.as_ref(), |e, v| e.f64(*v));
    e.option(s.load_factor.as_ref(), |e, v| e.f64(*v));
    e.vec3s(&s.probes);
    e.option(s.recovery.as_ref(), |e, r| {
        e.f64(r.ratio_mean);
        e.f64(r.ratio_max);
        e.option(r.delta_r.as_ref(), |e, v| e.f64(*v));
        e.f64s(&r.by_material);
    });
}

fn decode_sample(d: &mut Decoder<'_>) -> Result<StateSample, Problem> {
    Ok(StateSample {
        step: d.usize()?,
        time: d.f64()?,
        dt: d.f64()?,
        temperature: d.f64()?,
        loads: d.f64s()?,
        iterations: d.usize()?,
        residuals: d.f64s()?,
        cuts: d.usize()?,
        error_estimate: d.option(|d| d.f64())?,
        load_factor: d.option(|d| d.f64())?,
        probes: d.vec3s()?,
        recovery: d.option(|d| {
            Ok(Recovery {
                ratio_mean: d.f64()?,
                ratio_max: d.f64()?,
                delta_r: d.option(|d| d.f64())?,
                by_material: d.f64s()?,
            })
        })?,
    })
}

pub(super) fn encode_contact(e: &mut Encoder, s: &ContactSample) {
    e.f64(s.time);
    e.list(&s.obstacles, |e, o| {
        e.f64(o.force);
        e.option(o.radial_force.as_ref(), |e, v| e.f64(*v));
        e.option(o.diameter.as_ref(), |e, v| e.f64(*v));
    });
}

fn decode_contact(d: &mut Decoder<'_>) -> Result<ContactSample, Problem> {
    Ok(ContactSample {
        time: d.f64()?,
        obstacles: d.list(10, |d| {
            Ok(ObstacleSample {
                force: d.f64()?,
                radial_force: d.option(|d| d.f64())?,
                diameter: d.option(|d| d.f64())?,
            })
        })?,
    })
}

/// The charts' position: the states, then — only with contact, so that a position without stays as it was —
/// the contact of each state.
pub(super) fn decode_position(
    bytes: &[u8],
) -> Result<(Vec<StateSample>, Vec<ContactSample>), Problem> {
    let mut d = Decoder::new(bytes);
    let samples = d.list(64, decode_sample)?;
    // Bytes left after the states: the contact samples follow.
    let contact = if d.finish().is_ok() {
        Vec::new()
    } else {
        d.list(16, decode_contact)?
    };
    d.finish()?;
    Ok((samples, contact))
}

impl Recorder for RunCharts {
    fn name(&self) -> &'static str {
        CHARTS.name
    }

    fn position(&self) -> Vec<u8> {
        let mut e = Encoder::default();
        e.list(self.samples(), encode_sample);
        if !self.contact_samples().is_empty() {
            e.list(self.contact_samples(), encode_contact);
        }
        e.0
    }

    /// The error control's counts and the final state, from the states collected.
    fn summarise(&self, s: &mut RunSummaryFile, sim: &Simulation<'_>) {
        let samples = self.samples();
        if let Some(control) = &mut s.time_error_control {
            let steps = || samples.iter().skip(1);
            control.largest_estimate = steps()
                .filter_map(|x| x.error_estimate)
                .fold(0.0, Real::max);
            control.smallest_step = steps().map(|x| x.dt).fold(Real::INFINITY, Real::min);
            control.largest_step = steps().map(|x| x.dt).fold(0.0, Real::max);
            if control.accepted_steps == 0 {
                control.smallest_step = 0.0;
            }
        }
        s.final_state = samples.last().map(|x| FinalState::of(sim.model(), x));
    }

    fn finish(&mut self, sim: &Simulation<'_>, f: &mut Finishing<'_>) {
        let figures = f.figures.take().unwrap_or(Ok(Vec::new()));
        match self
            .write(sim.model(), f.dir, Some(f.manifest))
            .and_then(|charts| figures.map(|figures| [charts, figures].concat()))
        {
            Ok(files) => {
                f.state("charts/", true, format!("{} complete", files.len()));
                f.charts = files;
            }
            Err(e) => {
                let e = RunError::other(e);
                f.state(
                    "charts/",
                    false,
                    format!("not all drawn: {}", crate::run::error_text(&e)),
                );
                f.problems.push(e);
            }
        }
    }
}
