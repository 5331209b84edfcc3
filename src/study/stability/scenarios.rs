//! The scenarios of the solver maps: the elastic 45° bend in fewer and fewer load steps, the loaded arch heated
//! faster and faster, and the release snap of a two-crown stent with several steps and release ramps. Each
//! varies the model of an embedded design ([`designs`]) — its time stepping ([`TimeVariant`]), its temperature
//! schedule, and for the stent its crowns and mesh ([`rebuild`]) — runs it through [`newton_run`] and presents
//! its map ([`MapReport`]).

use super::MapReport;
use super::newton::{
    SolverMap, SolverPoint, describe, newton_run, solver_chart, solver_csv, solver_summary,
};
use crate::io::design::{Design, parse_design};
use crate::math::Real;
use crate::model::TimeFunction;
use crate::study::variant::{Remesh, TimeVariant, rebuild};
use crate::study::{StudyError, positive};
use std::path::Path;

/// The designs the solver maps use, embedded so that the command runs from any folder.
pub mod designs {
    /// designs/bend45.yaml.
    pub const BEND45: &str = include_str!("../../../designs/bend45.yaml");
    /// designs/circular_arch.yaml.
    pub const ARCH: &str = include_str!("../../../designs/circular_arch.yaml");
    /// designs/straight_stent.yaml.
    pub const STRAIGHT_STENT: &str = include_str!("../../../designs/straight_stent.yaml");
}

/// The 45° bend with each number of equal load steps.
pub fn bend45_map(
    load_steps: &[usize],
    mut progress: impl FnMut(&str),
) -> Result<SolverMap, StudyError> {
    let bend = embedded(designs::BEND45, "bend45.yaml")?.model;
    let mut points = Vec::new();
    for &n in load_steps {
        if n == 0 {
            return Err(StudyError::InvalidSetting {
                setting: "the number of load steps",
                value: 0.0,
                expected: "positive",
            });
        }
        let model = TimeVariant {
            step: Some(1.0 / n as Real),
            ..TimeVariant::default()
        }
        .of(&bend)?;
        let run = newton_run(&model)?;
        progress(&format!("bend45, {n} load steps: {}", describe(&run)));
        points.push(SolverPoint {
            parameters: vec![n as Real],
            run,
        });
    }
    Ok(SolverMap {
        name: "bend45",
        columns: vec!["load_steps"],
        points,
    })
}

/// Temperature of the arch before its heating \[°C\].
const ARCH_COLD: Real = 31.5;
/// Temperature change of the arch's heating \[K\] (31.5 → 90 °C).
const ARCH_HEATING: Real = 58.5;
/// The arch's load ramp and end time \[s\].
const ARCH_END: Real = 5.0;

/// The arch heated over `duration` (loads still ramp over 5 s) with step `h`: `(duration [s], h [s])` pairs.
pub fn heating_map(
    cases: &[(Real, Real)],
    mut progress: impl FnMut(&str),
) -> Result<SolverMap, StudyError> {
    let arch = embedded(designs::ARCH, "circular_arch.yaml")?.model;
    let mut points = Vec::new();
    for &(duration, h) in cases {
        if !(duration > 0.0 && duration <= ARCH_END) {
            return Err(StudyError::InvalidSetting {
                setting: "the heating duration [s]",
                value: duration,
                expected: "in (0, 5]",
            });
        }
        positive("the time step h [s]", h)?;
        let mut schedule = vec![(0.0, ARCH_COLD), (duration, ARCH_COLD + ARCH_HEATING)];
        if duration < ARCH_END {
            schedule.push((ARCH_END, ARCH_COLD + ARCH_HEATING));
        }
        let mut model = TimeVariant {
            step: Some(h),
            ..TimeVariant::default()
        }
        .of(&arch)?;
        model.temperature = TimeFunction::try_table(schedule)?;
        let run = newton_run(&model)?;
        let per_step = ARCH_HEATING * h.min(duration) / duration;
        progress(&format!(
            "arch heated over {duration} s, h = {h}: ΔT = {per_step:.3} K per step: {}",
            describe(&run)
        ));
        points.push(SolverPoint {
            parameters: vec![duration, h, per_step],
            run,
        });
    }
    Ok(SolverMap {
        name: "heating",
        columns: vec!["heating_duration_s", "h_s", "dT_per_step_K"],
        points,
    })
}

/// Release time of the straight stent \[s\].
const RELEASE: Real = 1.75;
/// End of the release runs \[s\].
const RELEASE_END: Real = 2.0;

/// A two-crown straight stent run to 2 s (released at 1.75 s) with step `h`, release ramp `ramp` and `n`
/// control points per patch (degree by [`release_mesh`]): `(h [s], ramp [s], n)` triples.
pub fn release_map(
    cases: &[(Real, Real, usize)],
    mut progress: impl FnMut(&str),
) -> Result<SolverMap, StudyError> {
    let stent = embedded(designs::STRAIGHT_STENT, "straight_stent.yaml")?;
    let mut points = Vec::new();
    for &(h, ramp, n) in cases {
        positive("the time step h [s]", h)?;
        positive("the release ramp [s]", ramp)?;
        let remesh = Remesh {
            degree: Some(release_mesh(n)),
            points: Some(n),
            crowns: Some(2),
        };
        let model = TimeVariant {
            end: Some(RELEASE_END),
            step: Some(h),
            release_ramp: Some(ramp),
            ..TimeVariant::default()
        }
        .of(&rebuild(&stent, &remesh)?)?;
        let run = newton_run(&model)?;
        let at_release = run
            .failure_times
            .iter()
            .filter(|&&t| t >= RELEASE && t <= RELEASE + ramp + h)
            .count();
        progress(&format!(
            "2-crown stent, p = {}, n = {n}, h = {h}, release ramp {ramp} s: {} ({at_release} failed attempts at the release)",
            release_mesh(n),
            describe(&run)
        ));
        points.push(SolverPoint {
            parameters: vec![h, ramp, n as Real, at_release as Real],
            run,
        });
    }
    Ok(SolverMap {
        name: "release",
        columns: vec![
            "h_s",
            "release_ramp_s",
            "n",
            "failed_attempts_in_release_window",
        ],
        points,
    })
}

/// The degree used with `n` control points in the release map: the design's `p = 6` at its `n = 20`, `p = 5`
/// on coarser meshes.
pub fn release_mesh(n: usize) -> usize {
    if n >= 20 { 6 } else { 5 }
}

/// The bend45 map's files and paragraph.
pub fn bend45_report(map: &SolverMap) -> MapReport {
    MapReport {
        name: map.name,
        csv: solver_csv(
            map,
            "elastic 45-degree bend (designs/bend45.yaml), tip force 600 in equal load steps",
        ),
        chart: solver_chart(
            map,
            "45-degree bend: Newton against load steps",
            0,
            "load steps",
            &[],
        ),
        summary: solver_summary(
            map,
            "bend45: load step size of the elastic 45° bend",
            |p| format!("{} load steps", p[0]),
        ),
    }
}

/// The heating map's files and paragraph.
pub fn heating_report(map: &SolverMap) -> MapReport {
    MapReport {
        name: map.name,
        csv: solver_csv(
            map,
            "circular arch (designs/circular_arch.yaml): moments ramp over 5 s while heating 31.5 -> 90 C over the given duration, with step h",
        ),
        chart: solver_chart(
            map,
            "arch heated under load: Newton against temperature change per step",
            2,
            "temperature change per step [K]",
            &[],
        ),
        summary: solver_summary(
            map,
            "heating: temperature change per step of the loaded arch",
            |p| {
                format!(
                    "heating over {} s, h = {} s (ΔT = {:.2} K per step)",
                    p[0], p[1], p[2]
                )
            },
        ),
    }
}

/// The release map's files and paragraph (with the release time and ramp rule after the runs).
pub fn release_report(map: &SolverMap) -> MapReport {
    let mut summary = solver_summary(
        map,
        "release: step size and release ramp of the stent's release snap",
        |p| {
            format!(
                "p = {}, n = {}, h = {} s, release ramp {} s ({} failed attempts in [1.75 s, 1.75 s + ramp + h])",
                release_mesh(p[2] as usize),
                p[2],
                p[0],
                p[1],
                p[3]
            )
        },
    );
    summary.push_str(&format!(
        "Release at t = {RELEASE} s; the reaction of each released component is ramped to zero over the release ramp (time.release_ramp, default one step).\n\n"
    ));
    MapReport {
        name: map.name,
        csv: solver_csv(
            map,
            "two-crown straight stent (designs/straight_stent.yaml, crowns: 2) to t = 2 s, released at 1.75 s",
        ),
        chart: solver_chart(
            map,
            "release snap of a 2-crown stent: Newton against release ramp",
            1,
            "release ramp [s]",
            &[2, 0],
        ),
        summary,
    }
}

/// The embedded design `text`, named `file` in errors and as its default name.
fn embedded(text: &str, file: &str) -> Result<Design, StudyError> {
    Ok(parse_design(text, Path::new(file))?)
}
