//! The loads and prescribed values at one instant ([`Actions`]), resolved from the model's schedules, and the
//! release ramps of released components ([`ReleaseRamp`]): what the assembly and the point terms read of the
//! model's time functions.

use crate::math::{Real, Vec3};
use crate::model::{Component, Model};

/// A released component's reaction, ramped to the load after release (see
/// [`crate::model::TimeSettings::release_ramp`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReleaseRamp {
    /// The reaction component that held the node at the release, in the node's local basis [force or moment].
    pub reaction: Real,
    /// Release time \[time\].
    pub start: Real,
    /// Ramp duration \[time\].
    pub duration: Real,
}

impl ReleaseRamp {
    /// The part of the reaction still applied at time `t`.
    pub fn value(&self, t: Real) -> Real {
        let f = if self.duration > 0.0 {
            1.0 - (t - self.start) / self.duration
        } else {
            0.0
        };
        self.reaction * f.clamp(0.0, 1.0)
    }
}

/// The loads and prescribed values at one instant, resolved from the model's schedules.
#[derive(Debug, Clone, PartialEq)]
pub struct Actions {
    /// Per node: concentrated force and moment (spatial) on its free components.
    pub node_force: Vec<Vec3>,
    /// Per node: concentrated moment (spatial).
    pub node_moment: Vec<Vec3>,
    /// Per node and local component: the prescribed value, or `None` when the component is free.
    pub prescribed: Vec<[Option<Real>; 6]>,
    /// Per patch: distributed force per unit length (spatial).
    pub dist_force: Vec<Vec3>,
    /// Per patch: distributed couple per unit length (spatial).
    pub dist_couple: Vec<Vec3>,
}

impl Actions {
    /// Evaluates every schedule of the model at time `t`; `ramps[k][i]` is the release ramp of node `k`'s
    /// component `i` once it has been released (empty: none).
    pub fn at(model: &Model, t: Real, ramps: &[[Option<ReleaseRamp>; 6]]) -> Self {
        let mut node_force = Vec::with_capacity(model.nodes.len());
        let mut node_moment = Vec::with_capacity(model.nodes.len());
        let mut prescribed = Vec::with_capacity(model.nodes.len());
        for (k, node) in model.nodes.iter().enumerate() {
            let mut local = [0.0; 6];
            let mut fixed = [None; 6];
            for (i, c) in node.conditions.components.iter().enumerate() {
                match c {
                    Component::Load(f) => local[i] = f.value(t),
                    Component::Prescribed {
                        value,
                        release,
                        load_after_release,
                    } => {
                        if release.is_none_or(|r| t < r) {
                            fixed[i] = Some(value.value(t));
                        } else {
                            let ramp = ramps.get(k).and_then(|r| r[i]).map_or(0.0, |r| r.value(t));
                            local[i] = load_after_release.value(t) + ramp;
                        }
                    }
                }
            }
            let b = &node.conditions.basis;
            node_force.push(b * Vec3::new(local[0], local[1], local[2]));
            node_moment.push(b * Vec3::new(local[3], local[4], local[5]));
            prescribed.push(fixed);
        }
        let mut dist_force = vec![Vec3::zeros(); model.patches.len()];
        let mut dist_couple = vec![Vec3::zeros(); model.patches.len()];
        for load in &model.distributed_loads {
            dist_force[load.patch] += Vec3::from_fn(|i, _| load.force[i].value(t));
            dist_couple[load.patch] += Vec3::from_fn(|i, _| load.couple[i].value(t));
        }
        Self {
            node_force,
            node_moment,
            prescribed,
            dist_force,
            dist_couple,
        }
    }

    /// Every load and prescribed value multiplied by `factor` (arc-length continuation's load factor: the
    /// residual is affine in it).
    pub fn scaled(&self, factor: Real) -> Self {
        let scale = |v: &[Vec3]| v.iter().map(|x| x * factor).collect();
        Self {
            node_force: scale(&self.node_force),
            node_moment: scale(&self.node_moment),
            prescribed: self
                .prescribed
                .iter()
                .map(|c| c.map(|v| v.map(|v| v * factor)))
                .collect(),
            dist_force: scale(&self.dist_force),
            dist_couple: scale(&self.dist_couple),
        }
    }
}
