//! The charts as a recorder: [`crate::io::run_charts`]' histories of the states collected (its position).

use super::{Finishing, Recorder, RecorderKind, damaged};
use crate::io::checkpoint::{Decoder, Encoder, Problem};
use crate::io::run_charts::RunCharts;
use crate::io::state::StateSample;
use crate::io::summary::{FinalState, RunSummaryFile};
use crate::math::Real;
use crate::post::recovery::Recovery;
use crate::run::RunError;
use crate::solver::Simulation;

/// The charts of the run's histories ([`crate::io::run_charts`]), with the snapshots' configuration figures.
pub(super) const CHARTS: RecorderKind = RecorderKind {
    name: "charts",
    create: |_, sim| Ok(Box::new(RunCharts::new(sim.model()))),
    check_resume: |_, position, _| {
        decode_samples(position).map_err(|p| damaged("charts/", p))?;
        Ok(())
    },
    resume: |_, sim, position| {
        let samples = decode_samples(position).map_err(|p| damaged("charts/", p))?;
        Ok(Box::new(RunCharts::new(sim.model()).resumed(samples)))
    },
};

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

pub(super) fn decode_samples(bytes: &[u8]) -> Result<Vec<StateSample>, Problem> {
    let mut d = Decoder::new(bytes);
    let samples = d.list(64, decode_sample)?;
    d.finish()?;
    Ok(samples)
}

impl Recorder for RunCharts {
    fn name(&self) -> &'static str {
        CHARTS.name
    }

    fn position(&self) -> Vec<u8> {
        let mut e = Encoder::default();
        e.list(self.samples(), encode_sample);
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
