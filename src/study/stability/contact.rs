//! The contact map of the stability study (issue 33): one crown of the paper's straight stent, elastic at its
//! rubbery modulus, crimped by a rigid cylinder, held and released, at several time steps and penalties —
//! points switching in and out of contact, and what Newton does there.
//!
//! The crimper closes from [`CLEAR`] outside the wires' reach to [`CRIMP`] inside it over the first second
//! (the middle of each strut meets it first and stays on it; the crests and troughs stay clear), holds until
//! 1.25 s and opens back over a second: the crown springs back with it, rounding until the whole wire follows
//! it, and the crimper leaves the crown as it passes the crown's free radius. Each run is Newton's record
//! ([`newton_run_with`]) with its failed attempts and its smallest converged step split by phase: while the
//! crimper closes and while it opens.

use super::MapReport;
use super::newton::{
    SolverMap, SolverPoint, describe, newton_run_with, solver_chart, solver_csv, solver_summary,
};
use crate::geometry::stent::{CentrelineSpec, CrownShape, CrownSpec, StentSpec, Symmetry};
use crate::material::{CircularSection, ElasticLaw};
use crate::math::{Mat3, Real, Vec3};
use crate::model::builder::{ConditionSpec, ModelBuilder, TimeSpec};
use crate::model::stent::StentMesh;
use crate::model::{
    Contact, ContactSettings, Model, Obstacle, SolverSettings, Surface, TimeFunction, Units, Wall,
};
use crate::solver::{Observer, Simulation, StepReport};
use crate::study::{StudyError, positive};
use std::fmt::Write as _;
use std::ops::ControlFlow;

/// Crown radius R \[mm\], amplitude \[mm\] and peaks of the paper's straight stent (designs/straight_stent.yaml).
const CROWN: CrownSpec = CrownSpec {
    radius: 20.0,
    amplitude: 5.0,
    peaks: 6,
    shape: CrownShape::Sinusoidal,
};
/// Wire diameter \[mm\] (designs/straight_stent.yaml).
const WIRE: Real = 0.6;
/// How far the crimper goes inside the wires' reach `R + d/2` \[mm\]: a quarter of the radius.
pub const CRIMP: Real = 5.0;
/// How far outside the wires' reach the crimper starts and ends \[mm\].
pub const CLEAR: Real = 0.5;
/// The paper's PLA above its Tg: its rubbery modulus `E∞` \[MPa\] and Poisson's ratio
/// (designs/straight_stent.yaml). A crimper programmes a device hot; elastic here, so that what the map shows
/// is contact, not relaxation.
const RUBBERY: (Real, Real) = (80.59, 0.33);
/// When the crimper is closed, when it starts to open, when it is open again \[s\].
pub const SCHEDULE: [Real; 3] = [1.0, 1.25, 2.25];
/// Degree and control points of every wire: n = 24, since at n = 12 the map's crown was under-resolved, by its own
/// notices and by a limit point of its path with the objective rotation field (docs/choices.md, *Rotation field*).
pub const MESH: (usize, usize) = (4, 24);
/// The contact law's transition band `2δ`, and the penetration its augmented-Lagrange updates allow \[mm\]: a
/// thousandth of the wire's radius. The crimper moves 460 to 1800 times as far in one step of the map, so
/// points cross the band within a step: the case the map is about.
const BAND: Real = 3e-4;
/// The joint whose axial displacement is held: the one 30° from the first symmetry plane, off both planes,
/// whose components are global ([`crimped_crown`] checks it).
const HELD: &str = "c1_n2";

/// One run of the contact map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactCase {
    /// Time step \[s\].
    pub h: Real,
    /// Contact penalty `ε` \[N/mm²\].
    pub penalty: Real,
}

/// One crown of the straight stent (quarter model, its wires p = 4, n = 24, [`MESH`]), elastic at the rubbery modulus,
/// inside a rigid crimper around its axis (x1) that closes, holds and opens ([`CRIMP`], [`SCHEDULE`]), with the
/// case's time step and penalty. The crown is held only by its symmetry planes and, at one joint, in its axial
/// displacement (a frictionless crimper leaves the axial translation free and puts no axial force on the crown).
///
/// # Errors
/// A step or penalty that is not positive, or a model the builder refuses.
pub fn crimped_crown(case: &ContactCase) -> Result<Model, StudyError> {
    let ContactCase { h, penalty } = *case;
    positive("the time step h [s]", h)?;
    positive("the contact penalty [N/mm²]", penalty)?;
    let mut b = ModelBuilder::new(
        "crimped_crown",
        ElasticLaw::try_new(RUBBERY.0, RUBBERY.1)?,
        CircularSection::try_new(WIRE)?.into(),
    );
    b.units(Units::MmNMpa);
    b.stent(
        std::sync::Arc::new(StentSpec {
            crown: CROWN,
            crowns: 1,
            spacing: None,
            rotation: 0.0,
            bridges: None,
            centreline: CentrelineSpec::Straight {
                origin: Vec3::zeros(),
                direction: Vec3::x(),
                reference: Some(Vec3::y()),
            },
            symmetry: Symmetry::Quarter,
            cut: true,
            crown_radii: None,
        }),
        StentMesh {
            crown: MESH,
            bridge: MESH,
        },
    );
    let reach = CROWN.radius + WIRE / 2.0;
    let [closed, opens, open] = SCHEDULE;
    b.contact(Contact {
        obstacles: vec![Obstacle::new(
            "crimper",
            Surface::Cylinder {
                point: Vec3::zeros(),
                axis: Vec3::x(),
                radius: TimeFunction::try_table(vec![
                    (0.0, reach + CLEAR),
                    (closed, reach - CRIMP),
                    (opens, reach - CRIMP),
                    (open, reach + CLEAR),
                ])?,
            },
            Wall::Rigid,
        )],
        settings: ContactSettings {
            penalty,
            regularisation: BAND,
            tolerance: BAND,
            max_updates: 10,
        },
    });
    b.solver(SolverSettings::for_contact());
    b.condition(ConditionSpec::at(HELD).with_displacement(0, TimeFunction::zero()));
    b.time(TimeSpec::new(open, h));
    let model = b.build()?.model;
    let global = model
        .nodes
        .iter()
        .any(|n| n.name == HELD && n.conditions.basis == Mat3::identity());
    if !global {
        return Err(StudyError::Refused(format!(
            "the crown's joint `{HELD}` lies on a symmetry plane: its axial displacement is not a global component"
        )));
    }
    Ok(model)
}

/// The smallest converged step while the crimper closes and while it opens \[s\] (infinite for a phase the run
/// did not reach).
struct Phases([Real; 2]);

impl Observer for Phases {
    fn step(&mut self, _: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        let [closed, opens, _] = SCHEDULE;
        let phase = if report.time <= closed {
            Some(0)
        } else if report.time - report.dt >= opens {
            Some(1)
        } else {
            None
        };
        if let Some(k) = phase {
            self.0[k] = self.0[k].min(report.dt);
        }
        ControlFlow::Continue(())
    }
}

/// The crown crimped and released at each case. Parameters of each point: `h`, the penalty, the failed
/// attempts while the crimper closes and while it opens, and the smallest converged step in each phase.
///
/// # Errors
/// A case [`crimped_crown`] refuses, or a model the solver cannot analyse.
pub fn contact_map(
    cases: &[ContactCase],
    mut progress: impl FnMut(&str),
) -> Result<SolverMap, StudyError> {
    let mut points = Vec::new();
    for case in cases {
        let mut phases = Phases([Real::INFINITY; 2]);
        let run = newton_run_with(&crimped_crown(case)?, &mut phases)?;
        let [closed, opens, _] = SCHEDULE;
        let closing = run.failure_times.iter().filter(|&&t| t <= closed).count();
        let opening = run.failure_times.iter().filter(|&&t| t > opens).count();
        let [smallest_closing, smallest_opening] = phases.0;
        progress(&format!(
            "crown crimped and released, h = {}, penalty {} N/mm²: {} (closing: {closing} failed attempts, smallest step {smallest_closing:.3e} s; opening: {opening}, {smallest_opening:.3e} s)",
            case.h,
            case.penalty,
            describe(&run)
        ));
        points.push(SolverPoint {
            parameters: vec![
                case.h,
                case.penalty,
                closing as Real,
                opening as Real,
                smallest_closing,
                smallest_opening,
            ],
            run,
        });
    }
    Ok(SolverMap {
        name: "contact",
        columns: vec![
            "h_s",
            "penalty_N_per_mm2",
            "failed_attempts_closing",
            "failed_attempts_opening",
            "smallest_step_closing_s",
            "smallest_step_opening_s",
        ],
        points,
    })
}

/// The contact map's files and paragraph.
pub fn contact_report(map: &SolverMap) -> MapReport {
    let mut summary = solver_summary(
        map,
        "contact: a crown crimped and released by a rigid cylinder",
        |p| {
            format!(
                "h = {} s, penalty {} N/mm² (closing: {} failed attempts, smallest step {:.2e} s; opening: {}, {:.2e} s)",
                p[0], p[1], p[2], p[4], p[3], p[5]
            )
        },
    );
    let [closed, opens, open] = SCHEDULE;
    let _ = write!(
        summary,
        "One crown of the straight stent (6 peaks, R = {} mm, {WIRE} mm wire, quarter model, p = {}, n = {}), elastic at the PLA's rubbery modulus, inside a rigid crimper that closes from {CLEAR} mm outside its wires to {CRIMP} mm inside them by {closed} s, holds, and opens from {opens} s back to the start by {open} s; contact band and penetration tolerance {BAND} mm, at most 10 augmented-Lagrange updates a step. The contact law is C¹ across its band; each step starts from the last step's increment extrapolated, and the first Newton increment of each solve is limited so that a point the law does not act on yet stops in the law's band (the contact term's module docs: what each of the two does, measured on this map). While the crimper closes, points enter contact in steps in which the crimper moves 460 to 1800 times the band; while it opens, the crown springs back with it and its points leave the crimper one after another. The runs above say what Newton did in each case: a cut or a failure there is the map's finding.\n\n",
        CROWN.radius, MESH.0, MESH.1,
    );
    MapReport {
        name: map.name,
        csv: solver_csv(
            map,
            &format!(
                "one crown of the straight stent (elastic; the PLA's rubbery modulus) crimped by a rigid cylinder {CRIMP} mm inside its wires over {closed} s; held to {opens} s; opened by {open} s"
            ),
        ),
        chart: solver_chart(
            map,
            "crown crimped and released: Newton against the time step",
            0,
            "time step h [s]",
            &[1],
        ),
        summary,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tiny contact map: the longest step of the map with its softest and its stiffest penalty (the map's
    /// runs that finish in a fraction of a second). Both must finish the whole cycle at their nominal step,
    /// without a cut while the crimper closes (points entering) or opens (points leaving, where Newton stalled
    /// before the step limit and the extrapolated start: module docs of the contact term); the CSV and the
    /// paragraph hold every case.
    #[test]
    fn a_tiny_contact_map_closes_the_crimper_and_reports_each_run() {
        let cases = [
            ContactCase {
                h: 0.1,
                penalty: 0.1,
            },
            ContactCase {
                h: 0.1,
                penalty: 10.0,
            },
        ];
        let map = contact_map(&cases, |_| {}).expect("the map runs");
        assert_eq!(map.points.len(), cases.len());
        for (p, case) in map.points.iter().zip(&cases) {
            let r = &p.run;
            assert!(r.completed && r.failure.is_none(), "{case:?}: {r:?}");
            // Steps land on the schedule's times exactly: a step shorter than h by more than round-off is a cut.
            let (smallest_closing, smallest_opening) = (p.parameters[4], p.parameters[5]);
            assert!(
                smallest_closing >= case.h * (1.0 - 1e-9)
                    && smallest_opening >= case.h * (1.0 - 1e-9),
                "{case:?}: steps of {smallest_closing} closing and {smallest_opening} opening"
            );
        }
        let report = contact_report(&map);
        // A comment, the header, a row per case.
        assert_eq!(
            report.csv.lines().count(),
            2 + cases.len(),
            "{}",
            report.csv
        );
        for case in &cases {
            let named = format!("h = {} s, penalty {} N/mm²", case.h, case.penalty);
            assert!(report.summary.contains(&named), "{}", report.summary);
        }
    }
}
