//! How a programmed device sits: its diameter and length as a crimper, a sheath or a vessel leaves them (issue
//! 34 item 3: ASTM F2079's recoil and F2081's foreshortening, adapted to a shape-memory device), and each crown's
//! diameter against the lumen around it. Computation only: `io` records these in `history.csv` and
//! `summary.json`.
//!
//! **Diameter.** Of a programme's driven nodes (`all_joints` by default: every crest and trough), the mean outer
//! diameter `D = 2 Σ w_l r_l / Σ w_l + d`, with `r_l` the node's distance from its crown's axis (the permanent
//! axis at the crown's station: the gauge holds the device's rigid placement, so the axis stays where it was),
//! `w_l` the nodes of the full device it stands for and `d` the thickest wire: the outer diameter a crimper or
//! a lumen meets at the crests. Per crown, the same mean over the crown's own nodes.
//!
//! **Length.** The nodes' extent along the axis, `max − min` of `s_l + t_l·(x_l − a_l)` over the driven nodes
//! (`s_l` the arc length of the axis at their crown's station, `a_l` and `t_l` the axis point and tangent
//! there): the crest-to-crest length along a straight axis, measured crown by crown along a curved one; wire
//! centrelines, without the wire's thickness at the ends (which does not change).
//!
//! **Recoil** (F2079 measures the diameter a device gives back when its expansion tool lets go; a shape-memory
//! device is crimped by its tool, so here it is what the crimped device gives back when the tool lets go, before
//! heating recovers it): `(D_open − D_closed) / D_closed` between the cycle's `fixed` event (the tool's release:
//! closed, about to open) and its `released` event (fully open; for a prescribed programme, the end of the
//! release ramp), positive when the device opens. A sheath put on at the release holds it: then the recoil is
//! what it gives back into the sheath.
//!
//! **Foreshortening** (F2081): `(L_crimped − L_end) / L_crimped`, the length at `fixed` against the length at
//! the end of the run, positive when the device shortened as it deployed.
//!
//! **Crowns against the lumen.** Each crown's diameter next to the diameter of the lumen around its axis point:
//! of the first obstacle acting then that is not the programme's tool and is a lumen (twice its radius at the
//! centreline point closest to the crown's axis point, the undeformed wall) or a cylinder (its diameter then).

use crate::math::{Real, Vec3};
use crate::model::cycle::Cycle;
use crate::model::{ProbeLocation, Programme, Surface};
use crate::solver::Simulation;

/// A device's diameter and length at one state (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct DeviceShape {
    /// Mean outer diameter of the driven nodes \[length\].
    pub diameter: Real,
    /// Extent of the driven nodes along the axis \[length\].
    pub length: Real,
    /// Per crown with driven nodes, in increasing order: `(crown, mean outer diameter)` \[1, length\].
    pub crowns: Vec<(usize, Real)>,
}

/// The shape of the programmed device at the simulation's current state (`None` without a programme).
pub fn device_shape(sim: &Simulation<'_>) -> Option<DeviceShape> {
    let model = sim.model();
    let programme = model.programme.as_ref()?;
    let positions: Vec<Vec3> = programme
        .nodes
        .iter()
        .map(|d| d.position + sim.probe_displacement(&ProbeLocation::Node(d.node)))
        .collect();
    let wire = model
        .sections
        .iter()
        .map(|s| s.diameter())
        .fold(0.0, Real::max);
    shape(programme, wire, &positions)
}

/// The shape of `programme`'s device with its driven nodes at `positions` (in the programme's order) and its
/// thickest wire `wire` thick.
fn shape(programme: &Programme, wire: Real, positions: &[Vec3]) -> Option<DeviceShape> {
    let (mut lo, mut hi) = (Real::INFINITY, Real::NEG_INFINITY);
    // Per crown: Σ w r and Σ w.
    let mut crowns: Vec<(usize, Real, Real)> = Vec::new();
    for (d, x) in programme.nodes.iter().zip(positions) {
        let t = d.axis_direction.normalize();
        let offset = x - d.axis_point;
        let along = t.dot(&offset);
        let r = (offset - t * along).norm();
        let s = d.station + along;
        (lo, hi) = (lo.min(s), hi.max(s));
        match crowns.iter_mut().find(|c| c.0 == d.crown) {
            Some(c) => {
                c.1 += d.weight * r;
                c.2 += d.weight;
            }
            None => crowns.push((d.crown, d.weight * r, d.weight)),
        }
    }
    let (sum, weight) = crowns
        .iter()
        .fold((0.0, 0.0), |(s, w), c| (s + c.1, w + c.2));
    if !(weight > 0.0) {
        return None;
    }
    crowns.sort_by_key(|c| c.0);
    Some(DeviceShape {
        diameter: 2.0 * sum / weight + wire,
        length: hi - lo,
        crowns: crowns
            .into_iter()
            .map(|(k, s, w)| (k, 2.0 * s / w + wire))
            .collect(),
    })
}

/// The device's diameter and length at a time \[s, length, length\].
pub type Sample = (Real, Real, Real);

/// The device's shape at the cycle's events, gathered state by state (or row by row of a history): the last
/// sample at or before `fixed`, at or before `released`, and the last of all.
#[derive(Debug, Clone, PartialEq)]
pub struct DeploymentTrack {
    /// The model's cycle, if it has one.
    cycle: Option<Cycle>,
    /// Time stepping's landing tolerance \[s\].
    tolerance: Real,
    closed: Option<Sample>,
    open: Option<Sample>,
    last: Option<Sample>,
}

/// Recoil as the tool lets go (module docs).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Recoil {
    /// The diameter at the tool's release \[length\] and when \[s\].
    pub diameter_closed: Real,
    /// When the tool released \[s\].
    pub closed_at: Real,
    /// The diameter once the tool is open \[length\].
    pub diameter_open: Real,
    /// When it was open \[s\].
    pub open_at: Real,
    /// `(D_open − D_closed) / D_closed`.
    pub recoil: Real,
}

/// Foreshortening between the crimped state and the end (module docs).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Foreshortening {
    /// The length at the tool's release \[length\].
    pub crimped_length: Real,
    /// The length at the end of the run \[length\].
    pub final_length: Real,
    /// `(L_crimped − L_end) / L_crimped`.
    pub foreshortening: Real,
}

impl DeploymentTrack {
    /// An empty track for the events of `cycle` (a model's, if it has one) with time stepping's landing
    /// `tolerance`.
    pub fn new(cycle: Option<Cycle>, tolerance: Real) -> Self {
        Self {
            cycle,
            tolerance,
            closed: None,
            open: None,
            last: None,
        }
    }

    /// Takes the sample `(t, D, L)` of a state (or a history row).
    pub fn observe(&mut self, sample: Sample) {
        let t = sample.0;
        if let Some(c) = &self.cycle {
            if t <= c.fixed + self.tolerance {
                self.closed = Some(sample);
            }
            if t <= c.released + self.tolerance {
                self.open = Some(sample);
            }
        }
        self.last = Some(sample);
    }

    /// The recoil, once the run has reached the cycle's `released` event (and the tool's release before it).
    pub fn recoil(&self) -> Option<Recoil> {
        let tolerance = self.tolerance;
        let (c, closed, open) = (self.cycle.as_ref()?, self.closed?, self.open?);
        (closed.0 >= c.fixed - tolerance && open.0 >= c.released - tolerance && closed.1 > 0.0)
            .then(|| Recoil {
                diameter_closed: closed.1,
                closed_at: closed.0,
                diameter_open: open.1,
                open_at: open.0,
                recoil: (open.1 - closed.1) / closed.1,
            })
    }

    /// The foreshortening, once the run has gone past the cycle's `released` event.
    pub fn foreshortening(&self) -> Option<Foreshortening> {
        let tolerance = self.tolerance;
        let (c, closed, last) = (self.cycle.as_ref()?, self.closed?, self.last?);
        (closed.0 >= c.fixed - tolerance && last.0 >= c.released - tolerance && closed.2 > 0.0)
            .then(|| Foreshortening {
                crimped_length: closed.2,
                final_length: last.2,
                foreshortening: (closed.2 - last.2) / closed.2,
            })
    }
}

/// One crown against the lumen around it (module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CrownFit {
    /// The crown, 1-based (as in node names `c<k>_…`).
    pub crown: usize,
    /// Its mean outer diameter \[length\].
    pub diameter: Real,
    /// The lumen's diameter around it \[length\] (`None` without a vessel).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lumen_diameter: Option<Real>,
}

/// Each crown's diameter at the current state against the lumen around it (module docs); empty without a
/// programme.
pub fn crown_fits(sim: &Simulation<'_>) -> Vec<CrownFit> {
    let model = sim.model();
    let (Some(programme), Some(shape)) = (&model.programme, device_shape(sim)) else {
        return Vec::new();
    };
    let t = sim.time();
    let tool = programme.kind.tool().map(|(first, _)| first);
    let vessel = model.contact.as_ref().and_then(|c| {
        c.obstacles.iter().enumerate().find_map(|(k, o)| {
            let wall = matches!(o.surface, Surface::Cylinder { .. } | Surface::Lumen(_));
            (tool.is_none_or(|first| k < first) && wall && o.is_active(t)).then_some(o)
        })
    });
    shape
        .crowns
        .iter()
        .map(|&(crown, diameter)| {
            let axis_point = programme
                .nodes
                .iter()
                .find(|d| d.crown == crown)
                .map(|d| d.axis_point);
            // The wall's radius where the crown's axis point projects on the lumen's centreline (none beyond
            // its ends), or the cylinder's.
            let lumen_diameter = vessel.zip(axis_point).and_then(|(o, a)| {
                let parameter = match &o.surface {
                    Surface::Lumen(lumen) => Some(lumen.closest(&a, None)?),
                    _ => None,
                };
                o.surface.wall_radius(t, parameter).map(|r| 2.0 * r)
            });
            CrownFit {
                crown: crown + 1,
                diameter,
                lumen_diameter,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{DrivenNode, ProgrammeKind};

    /// A ring of four nodes at radius 10 around the x axis, one of them standing for two nodes, for the tests.
    fn ring(crown: usize, x: Real) -> Vec<DrivenNode> {
        (0..4)
            .map(|i| {
                let a = std::f64::consts::FRAC_PI_2 * i as Real;
                DrivenNode {
                    node: 4 * crown + i,
                    position: Vec3::new(x, 10.0 * a.cos(), 10.0 * a.sin()),
                    target: Vec3::zeros(),
                    axis_point: Vec3::new(x, 0.0, 0.0),
                    axis_direction: Vec3::x(),
                    crown,
                    station: x,
                    radius: 10.0,
                    weight: if i == 0 { 2.0 } else { 1.0 },
                }
            })
            .collect()
    }

    // Hand-checked: two rings at x = 0 and x = 5 with their nodes at radius 10, then the second ring's nodes
    // moved out to radius 12 and 1 further along the axis; the wire 0 thick. Diameters 20 and 24 per crown,
    // the device's the weighted mean (5 node weights each: (5·20 + 5·24) / 10 = 22); length 5, then 6.
    #[test]
    fn diameter_and_length_of_two_rings() {
        let nodes: Vec<DrivenNode> = ring(0, 0.0).into_iter().chain(ring(1, 5.0)).collect();
        let programme = Programme {
            kind: ProgrammeKind::TargetShape,
            node_set: "all".into(),
            nodes: nodes.clone(),
            ramp: (0.0, 1.0),
            release: None,
        };
        let at_rest: Vec<Vec3> = nodes.iter().map(|d| d.position).collect();
        let s = shape(&programme, 0.0, &at_rest).expect("a shape");
        assert!((s.diameter - 20.0).abs() < 1e-12 && (s.length - 5.0).abs() < 1e-12);
        let moved: Vec<Vec3> = nodes
            .iter()
            .map(|d| {
                if d.crown == 1 {
                    let r = d.position - d.axis_point;
                    d.axis_point + r * 1.2 + Vec3::x()
                } else {
                    d.position
                }
            })
            .collect();
        let s = shape(&programme, 0.0, &moved).expect("a shape");
        assert_eq!(s.crowns.len(), 2);
        assert!((s.crowns[0].1 - 20.0).abs() < 1e-12 && (s.crowns[1].1 - 24.0).abs() < 1e-12);
        assert!((s.diameter - 22.0).abs() < 1e-12, "{}", s.diameter);
        assert!((s.length - 6.0).abs() < 1e-12);
    }

    // Hand-checked: a cycle fixed at 1 and released at 1.1; samples every 0.05 with the diameter 10 up to 1,
    // 11 from 1.1 on and the length 30 → 28 at the end: recoil (11 − 10)/10 = 0.1, foreshortening 2/30.
    #[test]
    fn recoil_and_foreshortening_from_the_samples_at_the_events() {
        let cycle = Cycle {
            programmed: Some(0.5),
            fixed: 1.0,
            released: 1.1,
        };
        let mut track = DeploymentTrack::new(Some(cycle), 1e-9);
        for i in 0..=40 {
            let t = 0.05 * i as Real;
            assert!(track.recoil().is_none() || t > 1.1 - 1e-9);
            let d = if t <= 1.0 + 1e-9 { 10.0 } else { 11.0 };
            let l = if t >= 2.0 - 1e-9 { 28.0 } else { 30.0 };
            track.observe((t, d, l));
        }
        let r = track.recoil().expect("recoil");
        assert!((r.recoil - 0.1).abs() < 1e-12, "{r:?}");
        assert!((r.closed_at - 1.0).abs() < 1e-9 && (r.open_at - 1.1).abs() < 1e-9);
        let f = track.foreshortening().expect("foreshortening");
        assert!((f.foreshortening - 2.0 / 30.0).abs() < 1e-12, "{f:?}");
        let mut no_cycle = DeploymentTrack::new(None, 1e-9);
        no_cycle.observe((1.5, 10.0, 30.0));
        assert!(no_cycle.recoil().is_none() && no_cycle.foreshortening().is_none());
    }
}
