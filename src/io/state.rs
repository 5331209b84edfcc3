//! What every output records about one state of a run: time, temperature, the applied loads, Newton's effort,
//! probe displacements and, for programmes, the recovery measures. `history.csv`, the `/state` channel of
//! `run.mcap`, the charts and `summary.json` all read it from here, so they agree.

use crate::math::{Real, Vec3};
use crate::model::{Component, Model};
use crate::post::recovery::{Recovery, recovery};
use crate::solver::{Simulation, StepReport};

/// Largest number of load channels recorded (a condition on a large node set would otherwise add one per
/// node); the first ones in node order are kept.
pub(crate) const MAX_LOAD_CHANNELS: usize = 32;

/// Where a recorded load value comes from.
#[derive(Debug, Clone, PartialEq)]
enum LoadSource {
    /// Component `i` (0–5, local basis) of node `node`: a load, or a prescribed value.
    Node { node: usize, component: usize },
    /// Global component `i` (0–2 force, 3–5 couple) of distributed load `load`.
    Distributed { load: usize, component: usize },
    /// The programme's ramp factor.
    Programme,
}

/// A named time-dependent input of the model, recorded with every state.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadChannel {
    /// Name: `node.F1`…`node.M3` for loads and `node.u1`…`node.r3` for prescribed displacements and
    /// rotations (local basis components), `patch.q1`…`patch.c3` for distributed forces and couples,
    /// `programme` for the programme's ramp factor `f(t)` ∈ [0, 1].
    pub name: String,
    /// Unit (in the design's system).
    pub unit: String,
    source: LoadSource,
}

/// Every input of the model that varies in time (at most [`MAX_LOAD_CHANNELS`]): non-zero node loads and
/// prescribed values (except those set by the programme), non-zero distributed loads, and the programme's
/// ramp factor.
pub(crate) fn load_channels(model: &Model) -> Vec<LoadChannel> {
    let units = model.units;
    let driven: Vec<usize> = model
        .programme
        .iter()
        .flat_map(|p| p.nodes.iter().map(|d| d.node))
        .collect();
    let mut out = Vec::new();
    for (k, node) in model.nodes.iter().enumerate() {
        for (i, c) in node.conditions.components.iter().enumerate() {
            let (prefix, unit, f) = match c {
                Component::Load(f) => {
                    (["F", "M"][i / 3], [units.force(), units.moment()][i / 3], f)
                }
                Component::Prescribed { value, .. } if !driven.contains(&k) => {
                    (["u", "r"][i / 3], [units.length(), "rad"][i / 3], value)
                }
                Component::Prescribed { .. } => continue,
            };
            if !f.is_zero() {
                out.push(LoadChannel {
                    name: format!("{}.{prefix}{}", node.name, i % 3 + 1),
                    unit: unit.to_string(),
                    source: LoadSource::Node {
                        node: k,
                        component: i,
                    },
                });
            }
        }
    }
    for (l, load) in model.distributed_loads.iter().enumerate() {
        let patch = &model.patches[load.patch].name;
        for (i, f) in load.force.iter().chain(&load.couple).enumerate() {
            if !f.is_zero() {
                let (prefix, unit) = if i < 3 {
                    ("q", format!("{}/{}", units.force(), units.length()))
                } else {
                    ("c", units.force().to_string())
                };
                out.push(LoadChannel {
                    name: format!("{patch}.{prefix}{}", i % 3 + 1),
                    unit,
                    source: LoadSource::Distributed {
                        load: l,
                        component: i,
                    },
                });
            }
        }
    }
    if model.programme.is_some() {
        out.push(LoadChannel {
            name: "programme".into(),
            unit: "1".into(),
            source: LoadSource::Programme,
        });
    }
    out.truncate(MAX_LOAD_CHANNELS);
    out
}

impl LoadChannel {
    /// The value at time `t`.
    pub fn value(&self, model: &Model, t: Real) -> Real {
        match self.source {
            LoadSource::Node { node, component } => {
                match &model.nodes[node].conditions.components[component] {
                    Component::Load(f) => f.value(t),
                    Component::Prescribed {
                        value,
                        release,
                        load_after_release,
                    } => match release {
                        // After the release the component carries its load after release.
                        Some(r) if t >= *r => load_after_release.value(t),
                        _ => value.value(t),
                    },
                }
            }
            LoadSource::Distributed { load, component } => {
                let l = &model.distributed_loads[load];
                if component < 3 {
                    l.force[component].value(t)
                } else {
                    l.couple[component - 3].value(t)
                }
            }
            LoadSource::Programme => model
                .programme
                .as_ref()
                .map_or(0.0, |p| p.factor().value(t)),
        }
    }
}

/// One recorded state: the initial one (step 0) or a converged step.
#[derive(Debug, Clone, PartialEq)]
pub struct StateSample {
    /// Step number (0 for the initial state).
    pub step: usize,
    /// Time \[time\].
    pub time: Real,
    /// Step size that reached it \[time\] (0 for the initial state).
    pub dt: Real,
    /// Temperature [°C].
    pub temperature: Real,
    /// Values of [`load_channels`], in their order.
    pub loads: Vec<Real>,
    /// Newton iterations of the step.
    pub iterations: usize,
    /// Normalised residual after each iteration (the last one at the converged state).
    pub residuals: Vec<Real>,
    /// Step cuts before the step converged.
    pub cuts: usize,
    /// The step's time-error estimate (error-controlled stepping), normalised as Newton's increments.
    pub error_estimate: Option<Real>,
    /// The load factor (an arc-length path; `None` for time steps).
    pub load_factor: Option<Real>,
    /// Displacement of every probe of the model, in its order \[length\].
    pub probes: Vec<Vec3>,
    /// Recovery measures, for a model with a programme.
    pub recovery: Option<Recovery>,
}

impl StateSample {
    /// The current state of `sim`, reached by `report` (`None` for the initial state).
    pub fn of(sim: &Simulation<'_>, channels: &[LoadChannel], report: Option<&StepReport>) -> Self {
        let model = sim.model();
        let time = sim.time();
        Self {
            step: report.map_or(0, |r| r.step),
            time,
            dt: report.map_or(0.0, |r| r.dt),
            temperature: model.temperature().value(sim.schedule_time()),
            loads: channels
                .iter()
                .map(|c| sim.load_scale() * c.value(model, sim.schedule_time()))
                .collect(),
            iterations: report.map_or(0, |r| r.newton.iterations),
            residuals: report.map_or_else(Vec::new, |r| r.newton.residuals.clone()),
            cuts: report.map_or(0, |r| r.cuts),
            error_estimate: report.and_then(|r| r.error_estimate),
            load_factor: model.solver().path.arc_length().map(|_| sim.load_scale()),
            probes: model
                .probes
                .iter()
                .map(|p| sim.probe_displacement(&p.location))
                .collect(),
            recovery: recovery(sim),
        }
    }

    /// The final normalised residual (0 for the initial state).
    pub fn residual(&self) -> Real {
        self.residuals.last().copied().unwrap_or(0.0)
    }
}
