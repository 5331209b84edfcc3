//! Wires passing through each other during a run (issue 35, item 2): a point term that adds no load and, after
//! every converged step, looks for the device's wires overlapping ([`crate::model::wires`]), recording the
//! deepest overlap with where and when, for the run's warnings (stderr and summary.json).
//!
//! **Touching.** The first step whose wires overlap at all beyond the reference's own (round-off aside) is kept
//! with its deepest overlap and where ([`WireCrossing::first_touch`], summary.json's `wire_touch`): the moment
//! struts close on each other, which a bench reads as the diameter where they lock.
//!
//! **What counts.** An overlap deeper than the tolerance — the contact settings' penetration tolerance when the
//! design has contact, otherwise [`TOLERANCE_OF_DIAMETER`] of the thinnest wire's diameter — beyond what the
//! device's own reference shape already has (the deepest overlap there, which `check` reports: a design whose
//! wires are fused by construction is not warned at every step). Without the wires' contact (`contact: {wires:
//! true}`, [`super::wires`]) wires that overlap pass through each other unresisted and the run goes on: the
//! warning says the result past that time is not the device's. With it, the check stays as an independent
//! witness on the segments between the samples (the contact's tolerance then): a warning says the contact let
//! wires through.
//!
//! **Cost.** At most one search per converged step (not per iteration): the samples' positions (linear in the
//! control points), an R*-tree of runs of segments and its join with itself and with each mirror image. A
//! search also finds its *slack* (module docs of [`crate::geometry::proximity`]): how much closer any two places
//! can come before an overlap would be recorded, up to the largest wire radius. While no control point has moved
//! half the slack since the last search, no step can have a new overlap, and none is searched for: on the
//! crimped straight stent that leaves out most steps' searches until the struts close on each other. Once wires
//! overlap the slack is below zero at every step; then, while no control point has moved half the margin (the
//! largest wire radius) since the last search, only the pairs that search found within reach are measured again
//! (its *candidates*), which finds the same overlaps without the R*-tree: the curved stent's bridge lying through
//! its own mirror image costs a search per step no more. After a restored checkpoint the first step searches
//! (the positions and candidates of the last search are not kept), which finds the same as skipping would
//! have.

use super::{InteriorLoad, PointTerm, PointView};
use crate::geometry::proximity::{Candidate, Overlap};
use crate::math::{Real, Vec3};
use crate::model::Model;
use crate::model::wires::{DeviceWires, ROUND_OFF};
use crate::solver::discretisation::Discretisation;
use crate::solver::state::State;

/// Without contact settings, the overlap tolerated as a fraction of the thinnest wire's diameter (module docs):
/// 5 %, a slip of a wire into another that a contact would also allow at a soft penalty, far below wires that
/// have passed through each other.
pub const TOLERANCE_OF_DIAMETER: Real = 0.05;

/// The deepest overlap found in the committed steps and where (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Deepest {
    overlap: Overlap,
    time: Real,
}

/// The wire-crossing check of a run (module docs).
pub struct WireCrossing {
    wires: DeviceWires,
    /// Overlaps deeper than this are recorded \[length\].
    threshold: Real,
    /// The tolerance beyond the reference's own overlap \[length\].
    tolerance: Real,
    /// The unit of length, for the warning.
    unit: &'static str,
    /// Whether the wires' contact is modelled (the warning's advice).
    contact: bool,
    /// The time of the step being solved.
    time: Real,
    /// Committed steps with an overlap above the threshold.
    steps: usize,
    /// The first such step's time.
    first: Real,
    /// The deepest overlap in them.
    deepest: Option<Deepest>,
    /// Overlaps deeper than this are wires touching \[length\]: the reference's own deepest overlap, and
    /// round-off.
    touch: Real,
    /// The first committed step whose wires touch, with its deepest overlap (module docs).
    first_touch: Option<Deepest>,
    /// The control points at the last search and the candidates it found (module docs); empty before the first.
    searched: Vec<Vec3>,
    candidates: Vec<Candidate>,
    /// The control points at the last search or recheck and its slack (module docs); empty before the first.
    checked: Vec<Vec3>,
    slack: Real,
    /// The margin of the searches: the largest wire radius \[length\].
    margin: Real,
}

impl WireCrossing {
    /// The check of `model`'s wires.
    pub fn new(model: &Model, disc: &Discretisation) -> Self {
        let wires = DeviceWires::new(model);
        let thinnest = (0..model.patches.len())
            .map(|k| 2.0 * model.wire_radius(k))
            .fold(Real::INFINITY, Real::min);
        let tolerance = (model.wire_contact.as_ref())
            .or(model.contact.as_ref().map(|c| &c.settings))
            .map_or(TOLERANCE_OF_DIAMETER * thinnest, |c| c.tolerance);
        let reference = wires
            .overlaps(&disc.control0, 0.0)
            .first()
            .map_or(0.0, |o| o.depth);
        let touch = reference + ROUND_OFF * wires.largest_radius();
        Self {
            threshold: reference + tolerance,
            tolerance,
            unit: model.units.length(),
            contact: model.wire_contact.is_some(),
            time: 0.0,
            steps: 0,
            first: 0.0,
            deepest: None,
            touch,
            first_touch: None,
            searched: Vec::new(),
            candidates: Vec::new(),
            checked: Vec::new(),
            slack: 0.0,
            margin: wires.largest_radius(),
            wires,
        }
    }

    /// The time of the first committed step whose wires had passed through each other (an overlap beyond the
    /// tolerance: module docs, *What counts*), if any.
    pub fn first_crossing(&self) -> Option<Real> {
        (self.steps > 0).then_some(self.first)
    }

    /// The first step whose wires touched (module docs): its time, the deepest overlap then (beyond the design's
    /// own) and where, in words.
    pub fn first_touch(&self) -> Option<WireTouch> {
        self.first_touch.map(|d| WireTouch {
            time: d.time,
            depth: d.overlap.depth,
            position: d.overlap.a.position.into(),
            place: self.wires.describe(&d.overlap, self.unit),
        })
    }
}

/// When and where a run's wires first touched (summary.json's `wire_touch`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct WireTouch {
    /// The time of the step \[time\].
    pub time: Real,
    /// The deepest overlap at that step, the design's own included \[length\].
    pub depth: Real,
    /// The point of the first wire there \[length\].
    pub position: [Real; 3],
    /// Where, in words: the two patches and curve parameters, the depth and the point.
    pub place: String,
}

impl PointTerm for WireCrossing {
    fn name(&self) -> &'static str {
        "wire crossing"
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }

    fn interior(&self, _at: &PointView<'_>, _load: &mut InteriorLoad) {}

    fn prepare(&mut self, _disc: &Discretisation, _state: &State, t: Real) {
        self.time = t;
    }

    fn commit(&mut self, _disc: &Discretisation, state: &State) {
        // How far the control points have moved since `from` (infinitely far before the first).
        let moved = |from: &[Vec3]| {
            if from.len() != state.control.len() {
                return Real::INFINITY;
            }
            (from.iter().zip(&state.control))
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, Real::max)
        };
        if 2.0 * moved(&self.checked) < self.slack {
            return;
        }
        let since = moved(&self.searched);
        let search = if 2.0 * since < self.margin {
            // No pair outside the candidates has come closer than their radii and the margin less twice the
            // motion since the search (module docs, *Cost*).
            let mut search =
                (self.wires).recheck(&state.control, self.touch, self.margin, &self.candidates);
            search.slack = search.slack.min(self.margin - 2.0 * since);
            search
        } else {
            let mut search = self.wires.search(&state.control, self.touch, self.margin);
            self.searched.clone_from(&state.control);
            self.candidates = std::mem::take(&mut search.candidates);
            search
        };
        self.checked.clone_from(&state.control);
        self.slack = search.slack;
        let Some(&o) = search.overlaps.first() else {
            return;
        };
        if self.first_touch.is_none() {
            self.first_touch = Some(Deepest {
                overlap: o,
                time: self.time,
            });
        }
        if o.depth <= self.threshold {
            return;
        }
        if self.steps == 0 {
            self.first = self.time;
        }
        self.steps += 1;
        if self.deepest.is_none_or(|d| o.depth > d.overlap.depth) {
            self.deepest = Some(Deepest {
                overlap: o,
                time: self.time,
            });
        }
    }

    fn warnings(&self) -> Vec<String> {
        let Some(d) = self.deepest else {
            return Vec::new();
        };
        let why = if self.contact {
            "the wires' contact let them through (a penalty too soft for the force, or a wire crossing another within one step: a stiffer penalty or shorter steps)"
        } else {
            "rod-on-rod contact is off (`contact: {wires: true}` turns it on)"
        };
        vec![format!(
            "wires passed through each other in {} step(s) (first at t = {}), deepest at t = {}: {}; {why}, so the result from then on is not the device's (tolerance {:.3e} {} beyond the design's own overlap)",
            self.steps,
            self.first,
            d.time,
            self.wires.describe(&d.overlap, self.unit),
            self.tolerance,
            self.unit
        )]
    }

    fn save(&self, out: &mut Vec<Real>) {
        out.extend([
            self.steps as Real,
            self.first,
            Real::from(u8::from(self.deepest.is_some())),
            Real::from(u8::from(self.first_touch.is_some())),
        ]);
        for d in [self.deepest, self.first_touch].into_iter().flatten() {
            let o = d.overlap;
            out.extend([d.time, o.depth, o.image as Real]);
            for p in [o.a, o.b] {
                out.extend([p.wire as Real, p.parameter, p.arc]);
                out.extend(p.position.iter());
            }
        }
    }

    fn restore(&mut self, values: &[Real]) -> Result<(), usize> {
        /// Steps, first time and which records follow; each record its time, depth, image and two wire points.
        const HEAD: usize = 4;
        const RECORD: usize = 3 + 2 * 6;
        let record = |v: &[Real]| {
            let point = |v: &[Real]| crate::geometry::proximity::WirePoint {
                wire: v[0] as usize,
                parameter: v[1],
                arc: v[2],
                position: Vec3::new(v[3], v[4], v[5]),
            };
            Deepest {
                time: v[0],
                overlap: Overlap {
                    depth: v[1],
                    image: v[2] as usize,
                    a: point(&v[3..9]),
                    b: point(&v[9..15]),
                },
            }
        };
        let Some(head) = values.get(..HEAD) else {
            return Err(HEAD);
        };
        let (deepest, touched) = (head[2] == 1.0, head[3] == 1.0);
        let expected = HEAD + RECORD * (usize::from(deepest) + usize::from(touched));
        if values.len() != expected {
            return Err(expected);
        }
        let mut records = values[HEAD..].chunks_exact(RECORD).map(record);
        self.deepest = if deepest { records.next() } else { None };
        self.first_touch = if touched { records.next() } else { None };
        self.steps = head[0] as usize;
        self.first = head[1];
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::solver::Simulation;

    /// A checkpoint keeps what the check found (the steps, the deepest overlap, the first touch), so a run
    /// restored from it reports what the run that went on reports. Two rods of diameter 0.2 crossing 0.5 apart,
    /// the upper one's ends moved down by 0.8 in eight steps (they touch from t = 0.5 on and overlap by more than
    /// the tolerance at t = 0.5, 0.625, 0.75); the checkpoint after six steps, with both records held.
    #[test]
    fn a_restored_run_reports_the_crossing_the_first_run_found() {
        let b = crate::solver::terms::tests::crossing_rods(0.5, 0.8, 10, 0.125);
        let model = b.build().expect("valid model").model;
        let mut first = Simulation::new(&model).expect("simulation");
        for _ in 0..6 {
            first.step().expect("converges");
        }
        let checkpoint = first.checkpoint();
        assert_eq!(
            checkpoint.snapshot.terms[1].len(),
            4 + 2 * 15,
            "both records"
        );
        while first.step().expect("converges").is_some() {}
        let mut second = Simulation::new(&model).expect("simulation");
        second.restore(&checkpoint).expect("restores");
        while second.step().expect("converges").is_some() {}
        assert_eq!(first.warnings(), second.warnings());
        assert_eq!(first.wire_touch(), second.wire_touch());
        let touch = first.wire_touch().expect("the rods touched");
        assert_eq!(touch.time, 0.5, "{touch:?}");
        assert_eq!(first.warnings().len(), 1, "{:?}", first.warnings());
        assert!(
            first.warnings()[0].contains("in 3 step(s)"),
            "{:?}",
            first.warnings()
        );
    }
}
