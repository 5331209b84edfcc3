//! Programmes: a set of nodes driven to a target shape and then let go (paper §4.3).
//!
//! A programme prescribes the displacement of every driven node as `η(t) = f(t) η_target`, where the ramp
//! `f` rises linearly from 0 at `ramp.0` to 1 at `ramp.1` and is then held, and releases it (Dirichlet → free
//! Neumann, the paper's release step) at `release`. The rotations of the driven nodes stay free. Two kinds:
//!
//! * **radial contraction** (§4.3.1): `η_target = −Δr e_r`, with `e_r` the outward radial unit vector of the
//!   node with respect to the stent axis at its crown's station;
//! * **target shape** (§4.3.2, Eq. `target_disp`): `η_target = P_temp − P_0`, with `P_temp` the node's position in
//!   a temporary placement of the same device (e.g. straightened and compacted).
//!
//! What later outputs need is kept here: per driven node, its reference position, the axis point and direction
//! of its crown and its reference radius (for the mean radial displacement), its target, and how many nodes of
//! the full device it stands for in a reduced (symmetric) model.

use super::{Component, Node, TimeFunction};
use crate::math::{Real, Vec3};

/// Which target a programme drives to.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum ProgrammeKind {
    /// Radial contraction by `delta_r` \[length\] towards the stent axis.
    RadialContraction {
        /// `Δr` at the end of the ramp \[length\], `0 < Δr < R`.
        delta_r: Real,
    },
    /// The displacement to a temporary placement, `η_temp = P_temp − P_0`.
    TargetShape,
    /// A crimper: a cylinder around the stent axis (the model's contact obstacle `obstacle`) closes until the
    /// wires' reach is `R − Δr`, holds, and opens over `open` from the release. Nothing is prescribed: the
    /// temporary shape is what contact makes it, and the targets are the nominal `−Δr e_r` of a radial
    /// contraction (the recovery measures' reference). The device is free from the start, its rigid-body
    /// motion fixed by the gauge constraints (`crate::solver::gauge`).
    Crimp {
        /// Nominal radial contraction `Δr` \[length\], `0 < Δr < R`.
        delta_r: Real,
        /// Index of the crimper in the model's contact obstacles.
        obstacle: usize,
        /// Time the crimper takes to open from the release \[time\].
        open: Real,
        /// A segmented-head crimper of this many flat segments (the model's obstacles from `obstacle` on)
        /// instead of a cylinder; `None`: a cylinder, or a tube around a curved axis.
        segments: Option<usize>,
    },
    /// A flat-plate crush: plates either side of a straight stent axis, parallel to it (the model's contact
    /// obstacles from `obstacle` on: two, or the one on the modelled side of a symmetry plane parallel to them),
    /// close until the wires' reach across them is `R − Δr`, hold, and open over `open` from the release. Free
    /// from the start like a crimper; the targets are the nominal flattening (each driven node moved along the
    /// plates' normal to within `R − Δr` of the axis plane between them).
    Crush {
        /// Nominal plate travel past the crown radius: the plates close to `R − Δr` from the axis (plus the
        /// wire's radius) \[length\], `0 < Δr < R`.
        delta_r: Real,
        /// Index of the first plate in the model's contact obstacles.
        obstacle: usize,
        /// Time the plates take to open from the release \[time\].
        open: Real,
    },
}

impl ProgrammeKind {
    /// The tool of a programme driven through contact (a crimper or crush plates): the index of its first
    /// obstacle among the model's and the time it takes to open; `None` for a programme that prescribes its
    /// nodes.
    pub fn tool(&self) -> Option<(usize, Real)> {
        match *self {
            ProgrammeKind::Crimp { obstacle, open, .. }
            | ProgrammeKind::Crush { obstacle, open, .. } => Some((obstacle, open)),
            ProgrammeKind::RadialContraction { .. } | ProgrammeKind::TargetShape => None,
        }
    }
}

/// One driven node.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DrivenNode {
    /// Index into [`super::Model::nodes`].
    pub node: usize,
    /// Reference position `P_0` \[length\].
    #[serde(serialize_with = "crate::math::serial::components")]
    pub position: Vec3,
    /// Displacement at the end of the ramp, `η_target` \[length\] (global components).
    #[serde(serialize_with = "crate::math::serial::components")]
    pub target: Vec3,
    /// Point of the stent axis at the node's crown station \[length\].
    #[serde(serialize_with = "crate::math::serial::components")]
    pub axis_point: Vec3,
    /// Unit direction of the stent axis there.
    #[serde(serialize_with = "crate::math::serial::components")]
    pub axis_direction: Vec3,
    /// The crown the node belongs to (0-based; a junction's: the crown whose crest it is).
    pub crown: usize,
    /// The arc length of the stent axis at the node's crown station \[length\].
    pub station: Real,
    /// Reference distance from the axis (the crown radius `R`) \[length\].
    pub radius: Real,
    /// Number of nodes of the full device this node stands for (1, 2 or 4 in a reduced model): the weight of
    /// the node in device averages.
    pub weight: Real,
}

/// A programme: nodes driven along a ramp, held, and released.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Programme {
    /// Radial contraction or target shape.
    pub kind: ProgrammeKind,
    /// Name of the driven node set (for reports).
    pub node_set: String,
    /// The driven nodes.
    pub nodes: Vec<DrivenNode>,
    /// Ramp start and end times \[time\], `start < end`.
    pub ramp: (Real, Real),
    /// Time from which the driven components are free \[time\]; `None` = never.
    pub release: Option<Real>,
}

/// Why a programme cannot be applied to the nodes.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProgrammeError {
    /// The target displacement has a component along a direction that is already prescribed (a symmetry
    /// plane normal) and differs from it.
    #[error(
        "node `{node}`: the target displacement has a component {value:.3e} along its prescribed local axis e{axis} (a symmetry plane normal); the temporary shape must respect the symmetry"
    )]
    Conflict {
        /// Node name.
        node: String,
        /// Local axis, 1-based.
        axis: usize,
        /// The target's component along it \[length\].
        value: Real,
    },
}

/// Relative size (of the largest target displacement) below which a target component along a prescribed
/// symmetry normal counts as zero: symmetric placements give round-off there (~1e-15 of the device size).
pub(crate) const SYMMETRY_TOLERANCE: Real = 1e-9;

impl Programme {
    /// Whether it prescribes its driven nodes (a crimper or crush plates drive them through contact instead).
    pub fn prescribes(&self) -> bool {
        self.kind.tool().is_none()
    }

    /// Whether its target is a radial contraction of the driven nodes (by prescription or by a crimper), whose
    /// mean radial displacement the outputs report as the paper's Δr.
    pub fn is_radial(&self) -> bool {
        matches!(
            self.kind,
            ProgrammeKind::RadialContraction { .. } | ProgrammeKind::Crimp { .. }
        )
    }

    /// The time from which the device is free and its rigid-body motion is fixed by gauge constraints: the
    /// release for a programme that prescribes its nodes, the start for a crimper or crush plates (`None`: never
    /// released).
    pub fn free_from(&self) -> Option<Real> {
        if self.prescribes() {
            self.release
        } else {
            Some(0.0)
        }
    }

    /// The ramp factor `f(t)`: 0 before `ramp.0`, linear to 1 at `ramp.1`, 1 after.
    pub fn factor(&self) -> TimeFunction {
        TimeFunction::try_table(vec![(self.ramp.0, 0.0), (self.ramp.1, 1.0)])
            .expect("a programme's ramp times increase (checked when it is built)")
    }

    /// The displacement prescribed on driven node `k` (index into [`Self::nodes`]) at time `t`, while not
    /// released.
    pub fn prescribed_displacement(&self, k: usize, t: Real) -> Vec3 {
        self.nodes[k].target * self.factor().value(t)
    }

    /// Prescribes the translations of every driven node (in the node's local basis, set before — e.g. by a
    /// symmetry plane — so that components already prescribed are kept; the target must vanish along them).
    pub fn apply(&self, nodes: &mut [Node]) -> Result<(), ProgrammeError> {
        let factor = self.factor();
        let scale = self
            .nodes
            .iter()
            .map(|d| d.target.norm())
            .fold(0.0, Real::max);
        for driven in &self.nodes {
            let node = &mut nodes[driven.node];
            let basis = node.conditions.basis;
            for i in 0..3 {
                let value = driven.target.dot(&basis.column(i));
                let component = &mut node.conditions.components[i];
                if matches!(component, Component::Prescribed { .. }) {
                    if value.abs() > SYMMETRY_TOLERANCE * scale {
                        return Err(ProgrammeError::Conflict {
                            node: node.name.clone(),
                            axis: i + 1,
                            value,
                        });
                    }
                    continue;
                }
                *component = Component::Prescribed {
                    value: factor.scaled(value),
                    release: self.release,
                    load_after_release: TimeFunction::zero(),
                };
            }
        }
        Ok(())
    }

    /// Radial displacement of driven node `k` given its displacement `u`: the change of its distance from the
    /// stent axis (a line through `axis_point` along `axis_direction`); negative when it contracts.
    pub fn radial_displacement(&self, k: usize, u: &Vec3) -> Real {
        let d = &self.nodes[k];
        let r = d.position + u - d.axis_point;
        (r - d.axis_direction * r.dot(&d.axis_direction)).norm() - d.radius
    }

    /// Mean radial displacement over the full device (weighted by [`DrivenNode::weight`]); `u[k]` is the
    /// displacement of driven node `k`.
    pub fn mean_radial_displacement(&self, u: &[Vec3]) -> Real {
        self.weighted_mean(|k| self.radial_displacement(k, &u[k]))
    }

    /// Mean of `|η_l| / |η_temp,l|` over the full device (the paper's measure of how far the device is from
    /// its temporary shape, Fig. `bend_stent_ext`); nodes with a zero target are skipped.
    pub fn target_fraction(&self, u: &[Vec3]) -> Real {
        self.target_fraction_where(u, |_| true)
    }

    /// [`Programme::target_fraction`] over the driven nodes whose model node `keep` accepts (a material region);
    /// 0 when none is left.
    pub fn target_fraction_where(&self, u: &[Vec3], keep: impl Fn(usize) -> bool) -> Real {
        let (mut sum, mut weight) = (0.0, 0.0);
        for (d, uk) in self.nodes.iter().zip(u) {
            let t = d.target.norm();
            if t > 0.0 && keep(d.node) {
                sum += d.weight * uk.norm() / t;
                weight += d.weight;
            }
        }
        if weight > 0.0 { sum / weight } else { 0.0 }
    }

    /// Largest `|η_l| / |η_temp,l|` over the driven nodes with a non-zero target (0 when there is none).
    pub fn target_fraction_max(&self, u: &[Vec3]) -> Real {
        self.nodes
            .iter()
            .zip(u)
            .filter(|(d, _)| d.target.norm() > 0.0)
            .fold(0.0, |m, (d, uk)| m.max(uk.norm() / d.target.norm()))
    }

    fn weighted_mean(&self, value: impl Fn(usize) -> Real) -> Real {
        let (mut sum, mut weight) = (0.0, 0.0);
        for (k, d) in self.nodes.iter().enumerate() {
            sum += d.weight * value(k);
            weight += d.weight;
        }
        if weight > 0.0 { sum / weight } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Mat3;
    use crate::model::{NodeConditions, PatchEnd};

    fn node(name: &str) -> Node {
        Node {
            name: name.into(),
            ends: Vec::<PatchEnd>::new(),
            position: Vec3::new(0.0, 20.0, 0.0),
            conditions: NodeConditions::default(),
        }
    }

    fn contraction() -> Programme {
        Programme {
            kind: ProgrammeKind::RadialContraction { delta_r: 15.0 },
            node_set: "all_joints".into(),
            nodes: vec![DrivenNode {
                node: 0,
                position: Vec3::new(0.0, 20.0, 0.0),
                target: Vec3::new(0.0, -15.0, 0.0),
                axis_point: Vec3::zeros(),
                axis_direction: Vec3::x(),
                crown: 0,
                station: 0.0,
                radius: 20.0,
                weight: 2.0,
            }],
            ramp: (0.0, 1.0),
            release: Some(1.75),
        }
    }

    // Hand-checked: half-way up the ramp the node has moved 7.5 towards the axis, radius 20 → 12.5.
    #[test]
    fn ramp_and_radial_displacement() {
        let p = contraction();
        let u = p.prescribed_displacement(0, 0.5);
        assert_eq!(u, Vec3::new(0.0, -7.5, 0.0));
        assert!((p.radial_displacement(0, &u) + 7.5).abs() < 1e-14);
        assert!((p.mean_radial_displacement(&[u]) + 7.5).abs() < 1e-14);
        assert!((p.target_fraction(&[u]) - 0.5).abs() < 1e-14);
    }

    // A symmetry node (basis e1 = z, u1 held) keeps u1 and gets u2, u3 from the in-plane target; a target
    // leaving the plane is refused.
    #[test]
    fn apply_respects_symmetry_components() {
        let p = contraction();
        let mut nodes = vec![node("a")];
        nodes[0].conditions.basis = Mat3::from_columns(&[Vec3::z(), Vec3::x(), Vec3::y()]);
        nodes[0].conditions.components[0] = Component::fixed();
        p.apply(&mut nodes).unwrap();
        let Component::Prescribed { value, release, .. } = &nodes[0].conditions.components[2]
        else {
            panic!("u3 (global y) is prescribed");
        };
        assert_eq!(value.value(1.0), -15.0);
        assert_eq!(*release, Some(1.75));
        assert!(
            nodes[0].conditions.components[0].is_prescribed_at(10.0),
            "symmetry is never released"
        );
        let mut bad = p.clone();
        bad.nodes[0].target = Vec3::new(0.0, -15.0, 1.0);
        let mut nodes = vec![node("a")];
        nodes[0].conditions.basis = Mat3::from_columns(&[Vec3::z(), Vec3::x(), Vec3::y()]);
        nodes[0].conditions.components[0] = Component::fixed();
        assert!(matches!(
            bad.apply(&mut nodes),
            Err(ProgrammeError::Conflict { axis: 1, .. })
        ));
    }
}
