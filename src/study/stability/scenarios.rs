//! The scenarios of the solver maps: the elastic 45° bend in fewer and fewer load steps, the loaded arch heated
//! faster and faster, and the release snap of a two-crown stent with several steps and release ramps. Each
//! varies the model of an embedded design ([`designs`], read by the caller's [`ReadDesign`]) — its time stepping
//! ([`TimeVariant`]), its temperature schedule, and for the stent its crowns and mesh
//! ([`VariedDesign::rebuild`]) — runs it through [`newton_run`] and presents its map ([`MapReport`]).

use super::newton::{
    NewtonRun, SolverMap, SolverPoint, describe, newton_run, solver_chart, solver_csv,
    solver_summary,
};
use super::{MapReport, ReadDesign};
use crate::math::Real;
use crate::model::{
    ArcLengthSettings, Model, PathControl, RotationField, SolverSettings, StabilisationSettings,
    TimeFunction, TimeSettings,
};
use crate::study::variant::{Remesh, TimeVariant, VariedDesign};
use crate::study::{StudyError, positive};
use std::fmt::Write as _;
use std::path::Path;

/// The designs the solver maps use, embedded so that the command runs from any folder.
pub mod designs {
    /// designs/bend45.yaml.
    pub const BEND45: &str = include_str!("../../../designs/bend45.yaml");
    /// designs/circular_arch.yaml.
    pub const ARCH: &str = include_str!("../../../designs/circular_arch.yaml");
    /// designs/straight_stent.yaml.
    pub const STRAIGHT_STENT: &str = include_str!("../../../designs/straight_stent.yaml");
    /// designs/rollup.yaml.
    pub const ROLLUP: &str = include_str!("../../../designs/rollup.yaml");
    /// designs/curved_stent.yaml.
    pub const CURVED_STENT: &str = include_str!("../../../designs/curved_stent.yaml");
}

/// The 45° bend with each number of equal load steps.
pub fn bend45_map(
    load_steps: &[usize],
    read: &ReadDesign,
    mut progress: impl FnMut(&str),
) -> Result<SolverMap, StudyError> {
    let bend = embedded(read, designs::BEND45, "bend45.yaml")?
        .model()
        .clone();
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
    read: &ReadDesign,
    mut progress: impl FnMut(&str),
) -> Result<SolverMap, StudyError> {
    let arch = embedded(read, designs::ARCH, "circular_arch.yaml")?
        .model()
        .clone();
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
        let model = TimeVariant {
            step: Some(h),
            ..TimeVariant::default()
        }
        .of(&arch)?
        .with_temperature(TimeFunction::try_table(schedule)?)?;
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

/// One run of the release map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReleaseCase {
    /// Time step \[s\].
    pub h: Real,
    /// Release ramp \[s\].
    pub ramp: Real,
    /// Control points per patch (degree by [`release_mesh`]).
    pub n: usize,
    /// With automatic stabilisation (`solver.stabilisation` at its defaults).
    pub stabilised: bool,
    /// Held at 90 °C throughout (a programme without cooling: a hot release), instead of the design's schedule.
    pub hot: bool,
}

impl ReleaseCase {
    /// The design's programme, Newton alone.
    pub const fn plain(h: Real, ramp: Real, n: usize) -> Self {
        Self {
            h,
            ramp,
            n,
            stabilised: false,
            hot: false,
        }
    }

    /// The same case with stabilisation.
    pub const fn stabilised(self) -> Self {
        Self {
            stabilised: true,
            ..self
        }
    }

    /// The same case held at 90 °C.
    pub const fn hot(self) -> Self {
        Self { hot: true, ..self }
    }
}

/// Temperature of a hot release \[°C\] (the straight stent's programming temperature, above its Tg = 70 °C).
const HOT: Real = 90.0;

/// A two-crown straight stent run to 2 s (released at 1.75 s) with step `h`, release ramp `ramp` and `n`
/// control points per patch (degree by [`release_mesh`]), with or without stabilisation, cooled before the
/// release as designed or held hot.
pub fn release_map(
    cases: &[ReleaseCase],
    read: &ReadDesign,
    mut progress: impl FnMut(&str),
) -> Result<SolverMap, StudyError> {
    let stent = embedded(read, designs::STRAIGHT_STENT, "straight_stent.yaml")?;
    let mut points = Vec::new();
    for &ReleaseCase {
        h,
        ramp,
        n,
        stabilised,
        hot,
    } in cases
    {
        positive("the time step h [s]", h)?;
        positive("the release ramp [s]", ramp)?;
        let remesh = Remesh {
            degree: Some(release_mesh(n)),
            points: Some(n),
            crowns: Some(2),
        };
        let mut model = TimeVariant {
            end: Some(RELEASE_END),
            step: Some(h),
            release_ramp: Some(ramp),
            ..TimeVariant::default()
        }
        .of(&stent.rebuild(&remesh)?)?;
        if stabilised {
            model = stabilised_model(model)?;
        }
        if hot {
            model = model.with_temperature(TimeFunction::constant(HOT))?;
        }
        let run = newton_run(&model)?;
        let at_release = run
            .failure_times
            .iter()
            .filter(|&&t| t >= RELEASE && t <= RELEASE + ramp + h)
            .count();
        progress(&format!(
            "2-crown stent, p = {}, n = {n}, h = {h}, release ramp {ramp} s{}{}: {} ({at_release} failed attempts at the release)",
            release_mesh(n),
            if hot { ", held at 90 °C" } else { "" },
            if stabilised { ", stabilised" } else { "" },
            describe(&run)
        ));
        points.push(SolverPoint {
            parameters: vec![
                h,
                ramp,
                n as Real,
                Real::from(u8::from(stabilised)),
                Real::from(u8::from(hot)),
                at_release as Real,
            ],
            run,
        });
    }
    Ok(SolverMap {
        name: "release",
        columns: vec![
            "h_s",
            "release_ramp_s",
            "n",
            "stabilised",
            "hot",
            "failed_attempts_in_release_window",
        ],
        points,
    })
}

/// An elastic design of the coarse-model map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoarseDesign {
    /// designs/bend45.yaml (10 load steps).
    Bend45,
    /// designs/rollup.yaml (20 load steps).
    Rollup,
}

impl CoarseDesign {
    /// The design's name and text.
    fn source(self) -> (&'static str, &'static str) {
        match self {
            Self::Bend45 => ("bend45", designs::BEND45),
            Self::Rollup => ("rollup", designs::ROLLUP),
        }
    }
}

/// Each `(design, p, n)` by its design's load steps, by arc length (its loads at the end scaled by a load
/// factor, to λ = 1) and by load steps with automatic stabilisation; the map's parameters are `design` (0
/// bend45, 1 rollup), `p`, `n` and `route` ([`route_name`]).
pub fn coarse_map(
    cases: &[(CoarseDesign, usize, usize)],
    read: &ReadDesign,
    mut progress: impl FnMut(&str),
) -> Result<SolverMap, StudyError> {
    let mut points = Vec::new();
    for &(design, p, n) in cases {
        let (name, text) = design.source();
        let parsed = embedded(read, text, &format!("{name}.yaml"))?;
        let remesh = Remesh {
            degree: Some(p),
            points: Some(n),
            crowns: None,
        };
        let stepped = parsed.rebuild(&remesh)?;
        // Short arcs (the first 1 % of the load, growing at most fourfold) sample the path densely enough to
        // locate its limit points to about 1e-3.
        let step = stepped.time().end / 100.0;
        let arc = stepped.clone().with_settings(
            TimeSettings {
                step,
                min_step: step / 1024.0,
                ..stepped.time().clone()
            },
            SolverSettings {
                path: PathControl::ArcLength(ArcLengthSettings {
                    max_growth: 4.0,
                    ..ArcLengthSettings::default()
                }),
                ..stepped.solver().clone()
            },
        )?;
        let stabilised = stabilised_model(stepped.clone())?;
        for (route, model) in [(0.0, &stepped), (1.0, &arc), (2.0, &stabilised)] {
            let run = newton_run(model)?;
            progress(&format!(
                "{name}, p = {p}, n = {n}, {}: {}",
                route_name(route),
                describe(&run)
            ));
            points.push(SolverPoint {
                parameters: vec![design as usize as Real, p as Real, n as Real, route],
                run,
            });
        }
    }
    Ok(SolverMap {
        name: "coarse",
        columns: vec!["design", "p", "n", "route"],
        points,
    })
}

/// The coarse map's routes: 0 load steps, 1 arc length, 2 load steps with automatic stabilisation.
pub fn route_name(route: Real) -> &'static str {
    match route as usize {
        0 => "load steps",
        1 => "arc length",
        _ => "stabilised load steps",
    }
}

/// The coarse map's files and paragraph: per run, the limit load factor of an arc-length path and how far the
/// end state's probe (the tip) is from the finest completed load-stepped run of the same design.
pub fn coarse_report(map: &SolverMap) -> MapReport {
    let name = |d: Real| if d == 0.0 { "bend45" } else { "rollup" };
    // The finest completed load-stepped run of each design: the reference end state.
    let reference = |d: Real| {
        map.points
            .iter()
            .filter(|q| q.parameters[0] == d && q.parameters[3] == 0.0 && q.run.completed)
            .max_by(|a, b| (a.parameters[2]).total_cmp(&b.parameters[2]))
            .and_then(|q| q.run.final_probe)
    };
    let mut summary = solver_summary(
        map,
        "coarse: coarse models by load steps and by arc length",
        |p| {
            let mut s = format!(
                "{}, p = {}, n = {}, {}",
                name(p[0]),
                p[1],
                p[2],
                route_name(p[3])
            );
            let run = map
                .points
                .iter()
                .find(|q| q.parameters == p)
                .map(|q| &q.run);
            let Some(run) = run.filter(|_| p[3] != 0.0) else {
                return s;
            };
            let mut notes = Vec::new();
            if p[3] == 1.0 {
                notes.push(match run.first_limit_load_factor() {
                    Some(l) => format!("the path's load factor peaks at {l:.4}, then falls"),
                    None => "the load factor rises monotonically".to_string(),
                });
            }
            if let (Some(u), Some(r), true) = (run.final_probe, reference(p[0]), run.completed) {
                notes.push(format!(
                    "at the full load the tip is {:.3} from the finest load-stepped run's, |u| = {:.3}",
                    (u - r).norm(),
                    r.norm()
                ));
            }
            if !notes.is_empty() {
                let _ = write!(s, " ({})", notes.join("; "));
            }
            s
        },
    );
    summary.push_str("A limit point of the coarse model's own path (its load factor peaks below 1 and falls) is where its load steps fail: no load step can pass it, whatever Newton does. Arc length passes it and then follows the coarse model's own path, which has little to do with the converged one: it wanders through further limit points until its increments run out, or meets a turn of that path too sharp for its smallest arc length (with the paper's rotation field two of them reached λ = 1, far from the converged tip). Such a coarse model is unresolved, not badly solved: refine it (the fine meshes here have no limit point). Automatic stabilisation carries the load steps past the limit point too (the third route), damping the snap rather than following the path back, and reaches the full load on the coarse model's own, inaccurate branch; the dissipated energy it reports (above the 5 % limit on two of the roll-ups) is the sign that the steps were not quasi-static there. On the fine meshes no step stalls and the stabilised runs are the load-stepped ones to the bit. The peak that arc length reports is the largest load factor among its increments, which straddle the peak, so it can lie below the last load at which the load steps converged (the lines above). With the paper's rotation field (`solver.rotations: incremental`) a coarse discrete solution also depends on the increments that reach it (issue 36; measured 2026-11-27 with that field: at p = 4, n = 10 the bend's tip at half the load moved by 0.05 of its 39 between 5 and 20 load steps and by 2e-3 between 20 and 100, at p = 6, n = 20 by 1.1e-4 of 60 at the full load); the objective field, the default, is path-independent.\n\n");
    MapReport {
        name: map.name,
        csv: solver_csv(
            map,
            "coarse models of the elastic 45-degree bend (designs/bend45.yaml, design 0) and roll-up (designs/rollup.yaml, design 1), by load steps (route 0), arc length (1) and stabilised load steps (2)",
        ),
        chart: solver_chart(
            map,
            "coarse models: Newton by load steps and by arc length",
            2,
            "control points per patch n",
            &[0, 1, 3],
        ),
        summary,
    }
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
                "p = {}, n = {}, h = {} s, release ramp {} s{}{} ({} failed attempts in [1.75 s, 1.75 s + ramp + h])",
                release_mesh(p[2] as usize),
                p[2],
                p[0],
                p[1],
                if p[4] == 1.0 { ", held at 90 °C" } else { "" },
                if p[3] == 1.0 { ", **stabilised**" } else { "" },
                p[5]
            )
        },
    );
    summary.push_str(&format!(
        "Release at t = {RELEASE} s; the reaction of each released component is ramped to zero over the release ramp (time.release_ramp, default one step). Stabilised runs have `solver.stabilisation` at its defaults (dissipated fraction 2e-4, limit 0.05); a run held at 90 °C releases a rubbery device (a programme without cooling).\n\nStabilisation removes every failure of this map, and leaves the runs that never stall as they were. The hot release shows what it is for: Newton alone meets the rubbery snap-back with tens of cuts (and the six-crown stent stalls at the smallest step), the damped steps pass it with a few, and the dissipated energy says that the snap is not quasi-static. The coarse stent (p = 5, n = 14) is another matter: its own release path folds (the failure times move with the release ramp but fall at the same fraction of it, as a limit point of the ramped reaction would), and past the fold its contraction grows instead of springing back, away from the converged models (p = 6, n = 20; p = 5, n ≥ 16), which have no fold. Stabilisation completes such a run; it does not make it right: refine it.\n\n"
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
            &[2, 0, 3, 4],
        ),
        summary,
    }
}

/// A stent of the meshes maps (issue 36 item 1): the paper's straight or curved stent, whose whole cycle each
/// map runs on coarse meshes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshStent {
    /// designs/straight_stent.yaml: the map `meshes`.
    Straight,
    /// designs/curved_stent.yaml: the map `curved`.
    Curved,
}

impl MeshStent {
    /// The map's name (its files' stem).
    pub const fn map_name(self) -> &'static str {
        match self {
            Self::Straight => "meshes",
            Self::Curved => "curved",
        }
    }

    /// The design's file name and text.
    const fn source(self) -> (&'static str, &'static str) {
        match self {
            Self::Straight => ("straight_stent.yaml", designs::STRAIGHT_STENT),
            Self::Curved => ("curved_stent.yaml", designs::CURVED_STENT),
        }
    }

    /// What the stent is called in progress lines and the paragraph.
    const fn label(self) -> &'static str {
        match self {
            Self::Straight => "straight stent",
            Self::Curved => "curved stent",
        }
    }

    /// What its programme does before the release, for the map's paragraph.
    const fn programme(self) -> &'static str {
        match self {
            Self::Straight => "crimped, cooled",
            Self::Curved => "straightened and compacted, cooled",
        }
    }

    /// What the map's paragraph says of this stent's failures.
    const fn remark(self) -> &'static str {
        match self {
            Self::Straight => {
                "The paper's field's failures come and go with n, which a resolution limit would not do: its discrete configuration depends on the increments that led to it (docs/choices.md, *Rotation field*). Where the objective field fails the meshes are the coarsest; the release map (`--maps release`) shows one of them (p = 5, n = 14) folding in its own release path. Rod contact (`contact: {wires: true}`) does not rescue these coarse meshes (docs/speed.md, *Coarse stents and the rotation field*)."
            }
            Self::Curved => {
                "The paper's programme pushes a bridge lying in the symmetry plane across it while the stent is straightened (the crossing check warns of it on the design's own mesh too, README *Wires through each other are said*): a run with its wires through each other from the programming on is the paper's programme's, on any mesh."
            }
        }
    }

    /// The design's release time \[s\] (`programme.release`; the test
    /// `the_meshes_maps_know_their_stents_release` holds it to the design's model).
    pub const fn release(self) -> Real {
        match self {
            Self::Straight => RELEASE,
            Self::Curved => 2.25,
        }
    }
}

/// One run of a meshes map (issue 36 item 1): a stent as designed (its whole cycle) but for its degree, control
/// points per patch and rotation field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshCase {
    /// Degree `p`.
    pub p: usize,
    /// Control points per patch `n`.
    pub n: usize,
    /// The rotation field.
    pub rotations: RotationField,
}

/// `degrees` × `points` with each rotation field, the paper's first.
fn mesh_cases(
    degrees: std::ops::RangeInclusive<usize>,
    points: std::ops::RangeInclusive<usize>,
) -> Vec<MeshCase> {
    let mut cases = Vec::new();
    for rotations in [RotationField::Incremental, RotationField::Objective] {
        for p in degrees.clone() {
            cases.extend(points.clone().map(|n| MeshCase { p, n, rotations }));
        }
    }
    cases
}

/// The straight stent's meshes map: p ∈ {4, 5, 6}, n ∈ [14, 40], with each rotation field (162 runs of the
/// six-crown stent: about 20 minutes on one core).
pub fn stent_meshes() -> Vec<MeshCase> {
    mesh_cases(4..=6, 14..=40)
}

/// The curved stent's meshes map: p ∈ {5, 6}, n ∈ [30, 81] (the design's own mesh is p = 6, n = 81), with each
/// rotation field (208 runs of 4000 steps: hours on two cores; 108 of them took about 96 minutes, 2026-11-28).
pub fn curved_meshes() -> Vec<MeshCase> {
    mesh_cases(5..=6, 30..=81)
}

/// `stent`'s whole cycle at each mesh and rotation field of `cases`, with `crowns` crowns instead of the
/// design's when given. The runs are independent: one thread per core takes them one after the other, each
/// reported to `progress` as it finishes; the map keeps the order of `cases`, and each run's wall time is its
/// own (longer than alone when the runs share the cores).
pub fn meshes_map(
    stent: MeshStent,
    cases: &[MeshCase],
    crowns: Option<usize>,
    read: &ReadDesign,
    mut progress: impl FnMut(&str),
) -> Result<SolverMap, StudyError> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let (file, text) = stent.source();
    let design = embedded(read, text, file)?;
    let models = (cases.iter())
        .map(|&MeshCase { p, n, rotations }| {
            let remesh = Remesh {
                degree: Some(p),
                points: Some(n),
                crowns,
            };
            let model = design.rebuild(&remesh)?;
            let solver = SolverSettings {
                rotations,
                ..model.solver().clone()
            };
            Ok(model.with_solver(solver)?)
        })
        .collect::<Result<Vec<Model>, StudyError>>()?;
    // Plain threads, each taking the next case: a rayon task waiting in a run's own parallel work could start
    // another whole run on its stack (rayon-rs/rayon#854), and that run's time would count in this one's.
    let workers = std::thread::available_parallelism().map_or(1, usize::from);
    let next = AtomicUsize::new(0);
    let (sender, finished) = std::sync::mpsc::channel();
    let mut runs: Vec<Option<NewtonRun>> = cases.iter().map(|_| None).collect();
    std::thread::scope(|scope| -> Result<(), StudyError> {
        for _ in 0..workers.min(models.len()) {
            let (sender, models, next) = (sender.clone(), &models, &next);
            scope.spawn(move || {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(model) = models.get(k) else {
                        break;
                    };
                    // The receiver is gone only after an error: stop.
                    if sender.send((k, newton_run(model))).is_err() {
                        break;
                    }
                }
            });
        }
        // The workers' senders are dropped as they finish, which ends this loop (a panic too: the scope
        // then passes it on).
        drop(sender);
        for (k, run) in finished {
            let run = run?;
            let MeshCase { p, n, rotations } = cases[k];
            progress(&format!(
                "{}, p = {p}, n = {n}, {} rotation field: {}",
                stent.label(),
                field_name(rotations),
                describe(&run)
            ));
            runs[k] = Some(run);
        }
        Ok(())
    })?;
    let runs = runs.into_iter().map(|run| {
        run.expect("every case ran: the workers stop early only after an error, returned above")
    });
    let points = (cases.iter().zip(runs))
        .map(|(&MeshCase { p, n, rotations }, run)| SolverPoint {
            parameters: vec![
                p as Real,
                n as Real,
                Real::from(u8::from(rotations == RotationField::Objective)),
            ],
            run,
        })
        .collect();
    Ok(SolverMap {
        name: stent.map_name(),
        columns: vec!["p", "n", "objective_rotations"],
        points,
    })
}

/// The design-language name of a rotation field.
fn field_name(rotations: RotationField) -> &'static str {
    match rotations {
        RotationField::Incremental => "incremental",
        RotationField::Objective => "objective",
    }
}

/// Where in a stent's cycle released at `release` a failure at `t` falls: before, at (within 0.01 s of) or
/// after the release.
fn phase(t: Real, release: Real) -> &'static str {
    if t < release {
        "before the release"
    } else if t <= release + 0.01 {
        "at the release"
    } else {
        "in the recovery"
    }
}

/// A meshes map's report: per rotation field, how many meshes finish the cycle and where each other one failed.
pub fn meshes_report(stent: MeshStent, map: &SolverMap) -> MapReport {
    let (file, _) = stent.source();
    let mut summary = format!(
        "## {0}: the {1}'s whole cycle on coarse meshes, with each rotation field ({0}.csv, {0}.svg)\n\n",
        map.name,
        stent.label()
    );
    for (flag, field) in [
        (0.0, RotationField::Incremental),
        (1.0, RotationField::Objective),
    ] {
        let runs: Vec<&SolverPoint> = (map.points.iter())
            .filter(|q| q.parameters[2] == flag)
            .collect();
        if runs.is_empty() {
            continue;
        }
        let finished = runs.iter().filter(|q| q.run.completed).count();
        let _ = write!(
            summary,
            "- **{}** rotation field: {finished} of {} meshes finish the cycle",
            field_name(field),
            runs.len()
        );
        let crossed: Vec<Real> = runs.iter().filter_map(|q| q.run.wires_crossed).collect();
        if let (Some(first), Some(last)) = (
            crossed.iter().copied().reduce(Real::min),
            crossed.iter().copied().reduce(Real::max),
        ) {
            let _ = write!(
                summary,
                " ({} of the {} with wires through each other, from t = {first:.4} s to {last:.4} s)",
                crossed.len(),
                runs.len()
            );
        }
        let crossing = |q: &SolverPoint| {
            (q.run.wires_crossed)
                .map(|t| format!(", its wires through each other from t = {t:.4} s"))
                .unwrap_or_default()
        };
        let failed: Vec<String> = (runs.iter().filter(|q| !q.run.completed))
            .map(|q| {
                format!(
                    "p = {}, n = {} {} (t = {:.4} s{})",
                    q.parameters[0],
                    q.parameters[1],
                    phase(q.run.time, stent.release()),
                    q.run.time,
                    crossing(q)
                )
            })
            .collect();
        if failed.is_empty() {
            summary.push_str(".\n");
        } else {
            let _ = writeln!(summary, "; failing: {}.", failed.join("; "));
        }
    }
    let _ = write!(
        summary,
        "\nThe stent (designs/{file}) runs its whole programme — {}, released at {} s, re-heated — at each degree and number of control points per patch, Newton alone (no stabilisation). A failure is the solver's: no convergence at the smallest step. A failure after the device's wires had passed through each other (the crossing check: a wire through another, or a wire through its own mirror image across a symmetry plane) says since when: the model was then no longer the device, the physical reason it gives. {}\n\n",
        stent.programme(),
        stent.release(),
        stent.remark()
    );
    let header = format!(
        "the {}'s whole cycle (designs/{file}) at each degree p, control points per patch n and rotation field (objective_rotations: 1 for the objective field, 0 for the paper's)",
        stent.label()
    );
    let title = format!("the {} on coarse meshes: Newton against n", stent.label());
    MapReport {
        name: map.name,
        csv: solver_csv(map, &header),
        chart: solver_chart(map, &title, 1, "control points per patch n", &[0, 2]),
        summary,
    }
}

/// `model` with automatic stabilisation at its defaults (`solver.stabilisation`).
fn stabilised_model(model: Model) -> Result<Model, StudyError> {
    let solver = SolverSettings {
        stabilisation: Some(StabilisationSettings::default()),
        ..model.solver().clone()
    };
    Ok(model.with_solver(solver)?)
}

/// The embedded design `text`, named `file` in errors and as its default name.
fn embedded(
    read: &ReadDesign,
    text: &str,
    file: &str,
) -> Result<Box<dyn VariedDesign>, StudyError> {
    read(text, Path::new(file))
}
