//! Release ramps (a released component's reaction, captured before the step that releases it) and the gauge
//! constraints switched on by a programme's release.

use super::{Simulation, patch_ranges};
use crate::math::{Real, Vec3};
use crate::solver::SolverError;
use crate::solver::assembly::{
    Actions, Assembly, Linearisation, ReleaseRamp, Sink, point_position,
};
use crate::solver::gauge::Gauge;
use crate::solver::linear::LinearSystem;
use crate::solver::terms::{Constraint, Terms};

impl Simulation<'_> {
    /// Before a step ending at `t_np1`: every prescribed component released at or before `t_np1` and not yet
    /// ramped gets its reaction in the current (converged) state, which is then applied as a load falling
    /// linearly to the load after release over `time.release_ramp` (the release snap as a continuation).
    /// Returns the `(node, component)` pairs captured, so a failed step can forget them (the step may then be
    /// cut to end before the release, and the reaction is captured again from the state just before it).
    pub(super) fn capture_releases(&mut self, t_np1: Real) -> Vec<(usize, usize)> {
        use crate::model::Component;
        let mut captured = Vec::new();
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
                    } if *r <= t_np1 && self.ramps[k][i].is_none() => Some((i, *r)),
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
                self.ramps[k][i] = Some(ReleaseRamp {
                    reaction,
                    start,
                    duration: self.model.time().release_ramp,
                });
                captured.push((k, i));
            }
        }
        captured
    }

    /// Activates the gauge constraints for a step ending at `t_np1` once the programme's release has happened by
    /// then (building them, and their extended system, the first time), and deactivates them otherwise.
    pub(super) fn set_gauge(&mut self, t_np1: Real) -> Result<(), SolverError> {
        let release = self.model.programme.as_ref().and_then(|p| p.release);
        let active = release.is_some_and(|r| r <= t_np1);
        if active && self.gauge.is_none() {
            let positions: Vec<Vec3> = (0..self.model.nodes.len())
                .map(|k| {
                    point_position(
                        &self.disc,
                        &self.state.control,
                        self.disc.end_point(self.model.nodes[k].ends[0]),
                    )
                })
                .collect();
            self.build_gauge(&positions, t_np1)?;
        }
        self.gauge_active = active && self.gauge.is_some();
        let m = if self.gauge_active {
            self.gauge.as_ref().map_or(0, |g| g.0.len())
        } else {
            0
        };
        self.state.multipliers.resize(m, 0.0);
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
        let mut pattern = Vec::new();
        let actions = Actions::at(self.model, t, &self.ramps);
        let material = self.step_material();
        let mut lin = Linearisation::default();
        let (point, constraints) = super::assembly_terms(&self.terms, None, Some(&gauge));
        self.assembler.assemble(
            &Assembly {
                disc: &self.disc,
                state: &self.state,
                material,
                actions: &actions,
                terms: Terms {
                    point: &point,
                    constraints: &constraints,
                },
            },
            &mut lin,
            &mut Sink::Pattern(&mut pattern),
        );
        let system = LinearSystem::new(
            self.disc.num_unknowns() + gauge.len(),
            &pattern,
            &patch_ranges(&self.disc),
            self.model.solver().linear,
        )?;
        let values = vec![0.0; pattern.len()];
        self.gauge = Some((gauge, system, values));
        Ok(())
    }
}
