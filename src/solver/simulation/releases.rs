//! Release ramps (a released component's reaction, captured before the step that releases it) and the gauge
//! constraints switched on by a programme's release.

use super::{CheckpointError, Restorable, Simulation};
use crate::math::{Real, Vec3};
use crate::solver::SolverError;
use crate::solver::assembly::{Actions, Assembly, ReleaseRamp, point_position};
use crate::solver::gauge::Gauge;
use crate::solver::linear::LinearSystem;
use crate::solver::terms::{Constraint, Terms};

/// The programme's release bookkeeping: a part of [`super::Simulation`] that a step changes.
pub(super) struct Releases {
    /// Per node and local component: the release ramp, once the component has been released.
    pub(super) ramps: Vec<[Option<ReleaseRamp>; 6]>,
    /// Gauge constraints after a programme's release, with their extended system and entry values: built once,
    /// at the first attempt of a step that reaches the release, from the configuration that attempt starts
    /// from, and kept from then on (an abandoned attempt keeps them too; a checkpoint saves the positions they
    /// freeze).
    pub(super) gauge: Option<(Gauge, LinearSystem, Vec<Real>)>,
    /// Whether the gauge constraints apply to the step being solved.
    pub(super) gauge_active: bool,
}

/// What the releases part of a simulation saves in a [`super::StepSnapshot`].
#[derive(Debug, Clone, PartialEq)]
pub struct ReleaseSnapshot {
    /// Per node and local component: the release ramp captured, if any.
    pub ramps: Vec<[Option<ReleaseRamp>; 6]>,
    /// Whether the gauge constraints apply to the step being solved.
    pub gauge_active: bool,
}

impl Releases {
    /// No release captured, no gauge, for a model of `nodes` nodes.
    pub(super) fn new(nodes: usize) -> Self {
        Self {
            ramps: vec![[None; 6]; nodes],
            gauge: None,
            gauge_active: false,
        }
    }

    /// The gauge constraints, when they apply to the step being solved.
    pub(super) fn active_gauge(&self) -> Option<&Gauge> {
        match (&self.gauge, self.gauge_active) {
            (Some((g, _, _)), true) => Some(g),
            _ => None,
        }
    }
}

impl Restorable for Releases {
    type Saved = ReleaseSnapshot;

    /// The ramps and the gauge activity (the gauge itself is kept, see [`Releases::gauge`]).
    fn save(&self) -> ReleaseSnapshot {
        ReleaseSnapshot {
            ramps: self.ramps.clone(),
            gauge_active: self.gauge_active,
        }
    }

    /// Puts them back: a ramp captured since is forgotten (captured again from the configuration a retried
    /// step starts from).
    fn restore(&mut self, saved: &ReleaseSnapshot) -> Result<(), CheckpointError> {
        if saved.ramps.len() != self.ramps.len() {
            return Err(CheckpointError::Size {
                what: "release ramps",
                expected: self.ramps.len(),
                found: saved.ramps.len(),
            });
        }
        self.ramps.clone_from(&saved.ramps);
        self.gauge_active = saved.gauge_active;
        Ok(())
    }
}

impl Simulation<'_> {
    /// Before a step ending at `t_np1`: every prescribed component released at or before `t_np1` and not yet
    /// ramped gets its reaction in the current (converged) state, which is then applied as a load falling
    /// linearly to the load after release over `time.release_ramp` (the release snap as a continuation).
    /// A failed step forgets them with the rest of its attempt ([`ReleaseSnapshot`]): the step may then be cut
    /// to end before the release, and the reaction is captured again from the state just before it.
    pub(super) fn capture_releases(&mut self, t_np1: Real) {
        use crate::model::Component;
        for k in 0..self.model.nodes.len() {
            let node = &self.model.nodes[k];
            let pending: Vec<(usize, Real)> = node
                .conditions
                .components
                .iter()
                .enumerate()
                .filter_map(|(i, c)| match c {
                    Component::Prescribed {
                        release: Some(r), ..
                    } if *r <= t_np1 && self.releases.ramps[k][i].is_none() => Some((i, *r)),
                    _ => None,
                })
                .collect();
            if pending.is_empty() {
                continue;
            }
            let (force, moment) = self
                .node_end_resultants(k)
                .iter()
                .fold((Vec3::zeros(), Vec3::zeros()), |(f, m), (ef, em)| {
                    (f + ef, m + em)
                });
            let basis = node.conditions.basis;
            for (i, start) in pending {
                let axis = basis.column(i % 3);
                let reaction = if i < 3 {
                    axis.dot(&force)
                } else {
                    axis.dot(&moment)
                };
                self.releases.ramps[k][i] = Some(ReleaseRamp {
                    reaction,
                    start,
                    duration: self.model.time().release_ramp,
                });
            }
        }
    }

    /// Activates the gauge constraints for a step ending at `t_np1` once the programme has let the device free by
    /// then (its release, or the start for a crimper: [`crate::model::Programme::free_from`]; building them, and
    /// their extended system, the first time), and deactivates them otherwise.
    pub(super) fn set_gauge(&mut self, t_np1: Real) -> Result<(), SolverError> {
        let release = self.model.programme.as_ref().and_then(|p| p.free_from());
        let active = release.is_some_and(|r| r <= t_np1);
        if active && self.releases.gauge.is_none() {
            let positions: Vec<Vec3> = (0..self.model.nodes.len())
                .map(|k| {
                    point_position(
                        &self.disc,
                        &self.solution.state.control,
                        self.disc.end_point(self.model.nodes[k].ends[0]),
                    )
                })
                .collect();
            self.build_gauge(&positions, t_np1)?;
        }
        self.releases.gauge_active = active && self.releases.gauge.is_some();
        let m = if self.releases.gauge_active {
            self.releases.gauge.as_ref().map_or(0, |g| g.0.len())
        } else {
            0
        };
        self.solution.state.multipliers.resize(m, 0.0);
        Ok(())
    }

    /// Builds the gauge constraints freezing the node positions `positions` (by node), and their extended
    /// system (its pattern analysed once), unless the model has nothing to constrain; `t` is the time whose
    /// loads the pattern's assembly sees (the pattern does not depend on them).
    pub(super) fn build_gauge(&mut self, positions: &[Vec3], t: Real) -> Result<(), SolverError> {
        let Some(gauge) =
            Gauge::new(self.model, positions, self.disc.length_scale).filter(|g| !g.is_empty())
        else {
            return Ok(());
        };
        let (system, values) = super::analyse(
            &Assembly {
                disc: &self.disc,
                state: &self.solution.state,
                material: self.step_material(),
                actions: &Actions::at(self.model, t, &self.releases.ramps),
                terms: Terms::default(),
            },
            &self.assembler,
            &self.terms,
            Some(&gauge),
            self.model.solver().linear,
        )?;
        self.releases.gauge = Some((gauge, system, values));
        Ok(())
    }
}
