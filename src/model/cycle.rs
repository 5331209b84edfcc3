//! The shape-memory cycle of a model read off its conditions: when the device is programmed, when it is let go
//! and when it is free again, and the phase any time of the run lies in. Snapshots are taken and named by
//! these events ([`crate::io::snapshots`]), and `stentkit export --phase` finds its state by them.
//!
//! A model has a cycle when something that drives it is let go: a prescribed component with a `release` (a
//! programme's driven nodes, or any condition written with one), a load that returns to zero and stays
//! there (the cantilever of paper §4.2, programmed by a tip force and moment), or a crimper that opens. Then
//!
//! * **fixed** is the earliest let-go: a release time, or the start of a load's last descent to zero (the
//!   device is still held in its programmed shape, cooled or not);
//! * **released** is the latest end of one: a release time plus the release ramp
//!   ([`super::TimeSettings::release_ramp`]), the time a load reaches zero for good, or the end of a crimper's
//!   opening (a crimper is let go when it starts to open at the programme's release);
//! * **programmed** is the last time before *fixed* at which one of those drives changed slope: the end of the
//!   programme's ramp (the paper's t = 1 s), or the end of the load's rise. A drive held from the start has
//!   none.
//!
//! A model whose drives are never let go (a load ramp, an arc-length path) has no cycle: its runs have no
//! phases, only an initial and a final state.

use super::{Component, Model, TimeFunction};
use crate::math::Real;

/// The events of a model's shape-memory cycle \[time\] (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cycle {
    /// End of programming: the last change of a drive before it is let go; `None` when the drives are held
    /// from the start.
    pub programmed: Option<Real>,
    /// The first let-go: the device is still held in its temporary shape.
    pub fixed: Real,
    /// The end of the last let-go: the device is free.
    pub released: Real,
}

/// Where a state lies in the cycle (the name of a snapshot, `stentkit export --phase`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Phase {
    /// t = 0.
    Initial,
    /// Between the start and the end of programming.
    Programming,
    /// At the end of programming.
    Programmed,
    /// Held in the temporary shape (cooled, in a shape-memory programme) until the release.
    Fixing,
    /// At the release, still held: the fixed temporary shape.
    Fixed,
    /// During the release ramp.
    Releasing,
    /// At the end of the release: the temporary shape the device keeps on its own.
    Released,
    /// After the release, while the device recovers.
    Recovering,
    /// At the end of the run.
    Final,
}

impl Phase {
    /// Every phase, in the order a run passes them.
    pub const ALL: [Phase; 9] = [
        Phase::Initial,
        Phase::Programming,
        Phase::Programmed,
        Phase::Fixing,
        Phase::Fixed,
        Phase::Releasing,
        Phase::Released,
        Phase::Recovering,
        Phase::Final,
    ];

    /// Its name in file names and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Initial => "initial",
            Phase::Programming => "programming",
            Phase::Programmed => "programmed",
            Phase::Fixing => "fixing",
            Phase::Fixed => "fixed",
            Phase::Releasing => "releasing",
            Phase::Released => "released",
            Phase::Recovering => "recovering",
            Phase::Final => "final",
        }
    }

    /// The phase of a name ([`Phase::name`]).
    pub fn parse(name: &str) -> Option<Phase> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// Whether the phase is an instant (an event) rather than an interval.
    pub fn is_event(self) -> bool {
        matches!(
            self,
            Phase::Initial | Phase::Programmed | Phase::Fixed | Phase::Released | Phase::Final
        )
    }
}

impl std::fmt::Display for Phase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A drive's let-go: `(fixed, released)`, and the function whose breakpoints before it are its programming.
fn let_go<'m>(model: &Model, c: &'m Component) -> Option<((Real, Real), &'m TimeFunction)> {
    match c {
        Component::Prescribed {
            value,
            release: Some(r),
            ..
        } => Some(((*r, r + model.time.release_ramp), value)),
        Component::Load(f) => load_let_go(f).map(|times| (times, f)),
        Component::Prescribed { release: None, .. } => None,
    }
}

/// A load's let-go: the start and the end of its last descent to zero, if it is non-zero somewhere and ends
/// at zero.
fn load_let_go(f: &TimeFunction) -> Option<(Real, Real)> {
    let points = f.points();
    let last_nonzero = points.iter().rposition(|&(_, v)| v != 0.0)?;
    let &(end, _) = points.get(last_nonzero + 1)?;
    Some((points[last_nonzero].0, end))
}

impl Model {
    /// A tool's let-go (a crimper's or crush plates'): the tool opening from the release, with its schedule
    /// (whose breakpoints before the release are the programming): a cylinder's radius, the factor on a curved
    /// crimper tube's radius, a plate's offset.
    fn tool_let_go(&self) -> Option<((Real, Real), &TimeFunction)> {
        let programme = self.programme.as_ref()?;
        let (obstacle, open) = programme.kind.tool()?;
        let release = programme.release?;
        let tool = self.contact.as_ref()?.obstacles.get(obstacle)?;
        let schedule = match &tool.surface {
            super::Surface::Cylinder { radius, .. } => radius,
            super::Surface::Lumen(tube) => tube.scale(),
            super::Surface::Plane { offset, .. } => offset,
        };
        Some(((release, release + open), schedule))
    }

    /// The model's shape-memory cycle, if it has one (see [`crate::model::cycle`]). An arc-length path has
    /// none: its `time` is the path parameter.
    pub fn cycle(&self) -> Option<Cycle> {
        if self.solver.path.arc_length().is_some() {
            return None;
        }
        let drives = self
            .nodes
            .iter()
            .flat_map(|n| &n.conditions.components)
            .filter_map(|c| let_go(self, c))
            .chain(
                self.distributed_loads
                    .iter()
                    .flat_map(|l| l.force.iter().chain(&l.couple))
                    .filter_map(|f| load_let_go(f).map(|times| (times, f))),
            )
            .chain(self.tool_let_go())
            .collect::<Vec<_>>();
        let fixed = drives.iter().map(|((f, _), _)| *f).reduce(Real::min)?;
        let released = drives.iter().map(|((_, r), _)| *r).reduce(Real::max)?;
        let tolerance = self.time.landing_tolerance();
        let programmed = drives
            .iter()
            .flat_map(|(_, f)| f.breakpoints())
            .filter(|&t| t > tolerance && t < fixed - tolerance)
            .reduce(Real::max);
        Some(Cycle {
            programmed,
            fixed,
            released,
        })
    }

    /// The model's cycle and the events of its run, read once for many [`Phases::at`].
    pub fn phases(&self) -> Phases {
        let end = self.time.end;
        let tolerance = self.time.landing_tolerance();
        let cycle = self.cycle();
        let mut events = vec![(0.0, Phase::Initial)];
        if let Some(c) = cycle {
            events.extend(c.programmed.map(|t| (t, Phase::Programmed)));
            events.push((c.fixed, Phase::Fixed));
            events.push((c.released, Phase::Released));
        }
        events.retain(|&(t, _)| t < end - tolerance);
        if self.solver.path.arc_length().is_none() {
            events.push((end, Phase::Final));
        }
        Phases {
            cycle,
            events,
            tolerance,
        }
    }

    /// The events of the run ([`Phases::events`]).
    pub fn events(&self) -> Vec<(Real, Phase)> {
        self.phases().events
    }

    /// The phase of the state at time `t` ([`Phases::at`]).
    pub fn phase_at(&self, t: Real) -> Option<Phase> {
        self.phases().at(t)
    }
}

/// A model's cycle and the events of its run ([`Model::phases`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Phases {
    cycle: Option<Cycle>,
    /// t = 0, the cycle's events that fall inside the run, and its end (on a time-driven path), in time order.
    pub events: Vec<(Real, Phase)>,
    /// Times closer than this are one time: the model's landing tolerance.
    tolerance: Real,
}

impl Phases {
    /// The phase of the state at time `t`: the event there, else the interval between events it lies in
    /// (`None` for a model without a cycle, between its start and end).
    pub fn at(&self, t: Real) -> Option<Phase> {
        if let Some(&(_, phase)) = self
            .events
            .iter()
            .find(|(e, _)| (t - e).abs() <= self.tolerance)
        {
            return Some(phase);
        }
        let c = self.cycle?;
        Some(if c.programmed.is_some_and(|p| t < p) {
            Phase::Programming
        } else if t < c.fixed {
            Phase::Fixing
        } else if t < c.released {
            Phase::Releasing
        } else {
            Phase::Recovering
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_load_let_go_is_its_last_descent_to_zero() {
        let f = TimeFunction::try_table(vec![(0.0, 0.0), (0.5, 50.0), (0.75, 50.0), (1.0, 0.0)])
            .expect("table");
        assert_eq!(load_let_go(&f), Some((0.75, 1.0)));
        let held = TimeFunction::try_table(vec![(0.0, 0.0), (0.5, 50.0)]).expect("table");
        assert_eq!(
            load_let_go(&held),
            None,
            "a load that stays on is never let go"
        );
        assert_eq!(load_let_go(&TimeFunction::zero()), None);
    }

    #[test]
    fn phases_round_trip_through_their_names() {
        for p in Phase::ALL {
            assert_eq!(Phase::parse(p.name()), Some(p));
        }
        assert_eq!(Phase::parse("cooled"), None);
    }
}
