//! `stentkit tune`: the cheapest discretisation of a design — degree `p`, control points per patch `n` and
//! time-error tolerance `τ` — whose results stay within a requested tolerance of a finer run over the design's
//! whole schedule (issue 14, item 2).
//!
//! # What is compared
//!
//! A design's *results* are what its outputs report: every probe's displacement, and for a programme the
//! recovery ratios (mean and largest) and the radial contraction Δr; a design with neither probes nor a
//! programme is watched at all its nodes. They are sampled at the *comparison times*: every breakpoint of the
//! schedule (loads, temperatures, releases), ten evenly spaced times and the end; fixed steps land on them, and
//! an error-controlled run reaches them by its continuous extension (without steps there). The
//! difference of two runs is the largest over those times and quantities of
//! - a displacement's difference over the largest displacement of the finer run (any probe, any time),
//! - Δr's difference over the largest |Δr| of the finer run,
//! - a recovery ratio's difference, absolute (a ratio is already relative: 1 at the temporary shape).
//!
//! A tolerance of 1e-3 thus asks for probes within 0.1 % of the largest displacement and recovery ratios within
//! 0.001.
//!
//! # How (cheap estimates first)
//!
//! The tolerance is split evenly between space and time.
//!
//! 1. **Space, on a short horizon** (the first schedule breakpoint at or after a quarter of the run: the end of
//!    programming for a shape-memory cycle) with [`SCREEN_STEPS`] fixed steps, the same for every run so that
//!    time errors cancel in a difference: for each candidate degree, the points `n` climb a ladder (ratio
//!    [`LADDER`], from `2p`) until the Richardson-style difference between `n` and `2n` of the whole sampled
//!    displacement field (9 points per patch, over its largest value) is at most half the tolerance. At the
//!    horizon of a programme the driven nodes are prescribed, so the field, not the results, is what shows the
//!    space error there. Each degree's `n` is ranked by the wall time of its screening run; the cheapest wins
//!    (the coarsest model in cost, not in `p` alone).
//! 2. **Time, over the whole schedule**, at the chosen `p` and `n`: the time tolerance climbs down a ladder
//!    (0.1, 0.03, 0.01, 0.003, …, from ten times the tolerance but at most 0.1) until the results at `τ` differ from those at
//!    `τ/10` by at most half the tolerance. A candidate whose results do not settle within [`MAX_TIME_RUNGS`]
//!    rungs (a coarse model near a limit point follows a path that depends on the step: the straight stent at
//!    p = 5, n = 17 still moves by 1e-2 in its largest recovery ratio at τ = 1e-4) is given up for the next
//!    cheapest one.
//! 3. **Verification, over the whole schedule**: the chosen `(p, n, τ)` against the finer run `(p, 2n, τ/10)`.
//!    That difference is the *estimated error* reported and written into the tuned design; when it exceeds the
//!    tolerance, `n` goes one rung up and steps 2–3 are repeated, the time ladder starting at the tolerance
//!    just chosen (at most [`MAX_ROUNDS`] rounds, else tune fails and says what it reached).
//!
//! **Folds.** A run that fails is unresolved, and so is one whose stabilisation warned (the damping carried the
//! load or dissipated more than its limit: a fold or snap the run did not pass quasi-statically, as the coarse
//! straight stent at p = 5, n = 14 folds at its release and follows a branch of its own; or the damping could
//! not be scaled): a comparison with such a run, as the candidate or as the finer one, is not accepted, and the
//! trial says why.
//!
//! The expected saving compares the tuned run's wall time (measured, step 2) with the design's own settings:
//! measured over the first twentieth of its fixed steps and extrapolated to all of them (run in full when the
//! design already controls its time error).
//!
//! Every run is cached by its settings, so a run both a comparison and a candidate is run once. Nothing here
//! writes files or prints: the caller gets each [`Trial`] as it finishes and the [`Tuned`] result.

use super::StudyError;
use super::sample::{Watched, WatchedRun, watched_run};
use super::variant::{Remesh, TimeVariant, VariedDesign};
use crate::math::{Real, Short, Vec3};
use crate::model::{Model, ProbeLocation, TimeSettings};
use std::fmt;

/// Fixed steps over the screening horizon. With 20 (a step of 0.075 s on the curved stent's programming) the
/// path of the compacted crowns depends on the step as much as on `n` and `n` against `2n` does not converge
/// (5.7e-2 at n = 38 and 48 against 96); with 200 it does (1.5e-3, 2.3e-4).
pub const SCREEN_STEPS: usize = 200;
/// Ratio between consecutive rungs of the `n` ladder.
pub const LADDER: Real = 1.25;
/// Rounds of refinement after a failed verification.
pub const MAX_ROUNDS: usize = 6;
/// Sampling points per patch of the screened displacement field.
const SAMPLES: usize = 9;
/// Largest time tolerance tried (looser ones leave Newton too little to go on).
const LOOSEST_TIME_TOLERANCE: Real = 0.1;
/// Rungs of the time ladder tried before a candidate is given up (from 0.1: down to 1e-3).
pub const MAX_TIME_RUNGS: usize = 5;

/// What `tune` is asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct TuneSettings {
    /// Tolerance on the results (module docs: *What is compared*), > 0.
    pub tolerance: Real,
    /// Degrees to try (each at least 2).
    pub degrees: Vec<usize>,
    /// Most control points per patch tried.
    pub max_points: usize,
}

/// How a run steps in time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stepping {
    /// Fixed steps of this size \[time\].
    Fixed(Real),
    /// Error-controlled steps at this time-error tolerance.
    Tolerance(Real),
}

impl fmt::Display for Stepping {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Stepping::Fixed(h) => write!(f, "h = {}", Short(*h)),
            Stepping::Tolerance(t) => write!(f, "τ = {}", Short(*t)),
        }
    }
}

/// The stage of `tune` a trial belongs to (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Space, on the short horizon: `n` against `2n`.
    Space,
    /// Time, over the whole schedule: `τ` against `τ/10`.
    Time,
    /// The choice against the finer run `(p, 2n, τ/10)`.
    Verify,
}

impl fmt::Display for Stage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Stage::Space => "space",
            Stage::Time => "time",
            Stage::Verify => "verify",
        })
    }
}

/// One comparison `tune` made: a candidate against a finer run.
#[derive(Debug, Clone, PartialEq)]
pub struct Trial {
    /// Which stage.
    pub stage: Stage,
    /// The candidate's degree.
    pub degree: usize,
    /// The candidate's control points per patch.
    pub points: usize,
    /// The candidate's time stepping.
    pub stepping: Stepping,
    /// Time the runs went to \[time\].
    pub horizon: Real,
    /// The finer run, in words (`n = 40`, `τ = 1e-4`).
    pub against: String,
    /// The candidate's wall time \[s\], steps and Newton iterations (`None` when it failed).
    pub cost: Option<(Real, usize, usize)>,
    /// The difference and where it is largest (`None` when a run failed).
    pub difference: Option<Difference>,
    /// Whether the difference is within this stage's share of the tolerance.
    pub accepted: bool,
    /// Why the comparison could not be made (a failed run), if so.
    pub failure: Option<String>,
}

/// The largest difference between two runs and where it is.
#[derive(Debug, Clone, PartialEq)]
pub struct Difference {
    /// The normalised difference (module docs).
    pub value: Real,
    /// The quantity (`probe tip`, `recovery ratio (mean)`, `Δr`, `displacement field`).
    pub quantity: String,
    /// The time \[time\].
    pub time: Real,
}

/// What `tune` chose.
#[derive(Debug, Clone, PartialEq)]
pub struct Tuned {
    /// Degree of every patch.
    pub degree: usize,
    /// Control points of every patch.
    pub points: usize,
    /// Time-error tolerance.
    pub time_tolerance: Real,
    /// Its difference from the finer run over the whole schedule (the estimated error).
    pub error: Difference,
    /// The finer run, in words.
    pub reference: String,
    /// Wall time of the tuned settings over the whole schedule \[s\], their steps and Newton iterations.
    pub cost: (Real, usize, usize),
    /// Wall time the design's own settings take \[s\] (extrapolated from its first steps when they are fixed).
    pub design_wall: Real,
    /// Every comparison made, in order.
    pub trials: Vec<Trial>,
}

/// Where a design's results are watched, with their names: its probes, or every node when it has neither probes
/// nor programme.
pub fn watched_locations(model: &Model) -> (Vec<String>, Vec<ProbeLocation>) {
    if model.probes.is_empty() && model.programme.is_none() {
        let names = model.nodes.iter().map(|n| format!("node {}", n.name));
        (
            names.collect(),
            (0..model.nodes.len()).map(ProbeLocation::Node).collect(),
        )
    } else {
        let names = model.probes.iter().map(|p| format!("probe {}", p.name));
        let locations = model.probes.iter().map(|p| p.location);
        (names.collect(), locations.collect())
    }
}

/// The settings of one run: degree, points, stepping, end time.
#[derive(Debug, Clone, Copy, PartialEq)]
struct RunKey {
    degree: usize,
    points: usize,
    stepping: Stepping,
    end: Real,
}

impl fmt::Display for RunKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "p = {}, n = {}, {}",
            self.degree, self.points, self.stepping
        )
    }
}

/// Runs `tune`'s variants of one design, each once.
struct Runner<'d> {
    design: &'d dyn VariedDesign,
    /// Names of the watched locations (`probe tip`, `node base`).
    names: Vec<String>,
    locations: Vec<ProbeLocation>,
    /// Comparison times over the whole schedule.
    times: Vec<Real>,
    cache: Vec<(RunKey, Result<WatchedRun, String>)>,
}

impl Runner<'_> {
    /// The index in the cache of `key`'s results (run now, or remembered).
    fn cached(&mut self, key: RunKey) -> usize {
        match self.cache.iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                let outcome = self.run(key).map_err(|e| super::error_chain(&e));
                self.cache.push((key, outcome));
                self.cache.len() - 1
            }
        }
    }

    fn run(&self, key: RunKey) -> Result<WatchedRun, StudyError> {
        let remesh = Remesh {
            degree: Some(key.degree),
            points: Some(key.points),
            crowns: None,
        };
        let rebuilt = self.design.rebuild(&remesh)?;
        let whole = key.end >= rebuilt.time().end;
        let (step, tolerance) = match key.stepping {
            Stepping::Fixed(h) => (Some(h), None),
            Stepping::Tolerance(tol) => (None, Some(tol)),
        };
        // The whole schedule is compared at the comparison times, a screening run by its grid at its end.
        let model = TimeVariant {
            end: Some(key.end),
            step,
            tolerance,
            ..TimeVariant::default()
        }
        .of(&rebuilt)?
        .with_record_times(if whole {
            self.times.clone()
        } else {
            vec![key.end]
        })?;
        let grid = (!whole).then_some(SAMPLES);
        Ok(watched_run(&model, &self.locations, grid)?)
    }

    /// Compares run `candidate` with run `finer`: the trial, with `accepted` against `share` of the tolerance.
    fn compare(
        &mut self,
        stage: Stage,
        candidate: RunKey,
        finer: RunKey,
        share: Real,
        against: String,
    ) -> Trial {
        let (a, b) = (self.cached(candidate), self.cached(finer));
        let mut trial = Trial {
            stage,
            degree: candidate.degree,
            points: candidate.points,
            stepping: candidate.stepping,
            horizon: candidate.end,
            against,
            cost: None,
            difference: None,
            accepted: false,
            failure: None,
        };
        match (&self.cache[a].1, &self.cache[b].1) {
            (Err(e), _) => trial.failure = Some(format!("{candidate}: {e}")),
            (Ok(a), Err(e)) => {
                trial.cost = Some((a.wall, a.summary.steps, a.summary.iterations));
                trial.failure = Some(format!("{finer}: {e}"));
            }
            (Ok(a), Ok(b)) => {
                trial.cost = Some((a.wall, a.summary.steps, a.summary.iterations));
                let d = difference(&a.states, &b.states, &self.names);
                trial.accepted = d.value <= share;
                trial.difference = Some(d);
                // A run whose stabilisation warned followed a path of its own: its difference says nothing of
                // its resolution (module docs, *Folds*).
                if let Some((key, warning)) = [(candidate, a), (finer, b)]
                    .into_iter()
                    .find_map(|(key, run)| run.stabilised.first().map(|w| (key, w)))
                {
                    trial.accepted = false;
                    trial.failure = Some(format!(
                        "{key} folds or snaps (unresolved, the stabilisation warned): {warning}"
                    ));
                }
            }
        }
        trial
    }
}

/// The largest normalised difference of `run` from `finer` (module docs), over their common times: the first
/// `names.len()` displacements of each state are the watched ones ([`watched_locations`]), further ones are not
/// compared.
pub fn difference(run: &[Watched], finer: &[Watched], names: &[String]) -> Difference {
    let largest = |f: &dyn Fn(&Watched) -> Real| finer.iter().map(f).fold(0.0, Real::max);
    fn watched<'w>(w: &'w Watched, names: &[String]) -> &'w [Vec3] {
        &w.displacements[..names.len().min(w.displacements.len())]
    }
    let u_scale = largest(&|w| {
        watched(w, names)
            .iter()
            .map(|u| u.norm())
            .fold(0.0, Real::max)
    });
    let r_scale = largest(&|w| {
        w.recovery
            .as_ref()
            .and_then(|r| r.delta_r)
            .map_or(0.0, Real::abs)
    });
    let f_scale = largest(&|w| w.grid.iter().map(|u| u.norm()).fold(0.0, Real::max));
    let mut worst = Difference {
        value: 0.0,
        quantity: "no difference".into(),
        time: 0.0,
    };
    let mut see = |value: Real, quantity: &dyn Fn() -> String, time: Real| {
        if value > worst.value || value.is_nan() {
            worst = Difference {
                value,
                quantity: quantity(),
                time,
            };
        }
    };
    for (a, b) in run.iter().zip(finer) {
        if u_scale > 0.0 {
            for ((u, v), name) in watched(a, names).iter().zip(watched(b, names)).zip(names) {
                see((u - v).norm() / u_scale, &|| name.clone(), b.time);
            }
        }
        if let (Some(x), Some(y)) = (&a.recovery, &b.recovery) {
            if let (Some(x), Some(y)) = (x.delta_r, y.delta_r)
                && r_scale > 0.0
            {
                see((x - y).abs() / r_scale, &|| "Δr".into(), b.time);
            }
            let mean = (x.ratio_mean - y.ratio_mean).abs();
            see(mean, &|| "recovery ratio (mean)".into(), b.time);
            let max = (x.ratio_max - y.ratio_max).abs();
            see(max, &|| "recovery ratio (max)".into(), b.time);
            for (k, (p, q)) in x.by_material.iter().zip(&y.by_material).enumerate() {
                see(
                    (p - q).abs(),
                    &|| format!("recovery ratio of material region {}", k + 1),
                    b.time,
                );
            }
        }
        if f_scale > 0.0 {
            let field = a
                .grid
                .iter()
                .zip(&b.grid)
                .map(|(u, v)| (u - v).norm())
                .fold(0.0, Real::max);
            see(field / f_scale, &|| "displacement field".into(), b.time);
        }
    }
    if run.len() != finer.len() {
        // A run that stopped short of a comparison time cannot be within any tolerance.
        see(
            Real::INFINITY,
            &|| "comparison times not reached".into(),
            0.0,
        );
    }
    worst
}

/// The comparison times of `model` over its whole schedule (module docs).
pub fn comparison_times(model: &Model) -> Vec<Real> {
    let end = model.time().end;
    let mut times = model.condition_breakpoints();
    times.extend((1..=10).map(|k| end * k as Real / 10.0));
    times.sort_by(Real::total_cmp);
    times.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * end);
    times
}

/// The screening horizon: the first schedule breakpoint at or after a quarter of the run.
fn screening_horizon(model: &Model) -> Real {
    let end = model.time().end;
    model
        .condition_breakpoints()
        .into_iter()
        .find(|&t| t >= 0.25 * end)
        .unwrap_or(end)
}

/// The `n` ladder of degree `p`: from `2p` (and above `p + 1`) by [`LADDER`], up to `max`.
fn ladder(p: usize, max: usize) -> Vec<usize> {
    std::iter::successors(Some((2 * p).max(p + 2)), |&n| Some(rung_above(n)))
        .take_while(|&n| n <= max)
        .collect()
}

/// The next rung above `n` (module docs, step 3).
fn rung_above(n: usize) -> usize {
    ((n as Real * LADDER).ceil() as usize).max(n + 1)
}

/// The largest time tolerance `m·10^k` with `m` ∈ {1, 3} at most `limit` (the ladder's values are round, so the
/// tuned design states the tolerance that was measured).
fn time_ladder_start(limit: Real) -> Real {
    let decade = Real::powf(10.0, limit.log10().floor());
    // (The rounding of `powf` and `log10` could leave 3·decade a hair above a limit of exactly 3·decade.)
    let three = round_sig(3.0 * decade);
    if three <= limit * (1.0 + 1e-12) {
        three
    } else {
        round_sig(decade)
    }
}

/// The rung of the time ladder below `tau` (…, 3e-3, 1e-3, 3e-4, …).
fn time_rung_below(tau: Real) -> Real {
    let decade = Real::powf(10.0, tau.log10().floor());
    let m = (tau / decade).round();
    round_sig(if m >= 3.0 { decade } else { 0.3 * decade })
}

/// `x` rounded to 12 significant digits (the ladder's values written as they are meant, `3e-3`, not
/// `0.0030000000000000005`).
fn round_sig(x: Real) -> Real {
    format!("{x:.11e}").parse().unwrap_or(x)
}

/// Tunes `design` (module docs); `progress` is told about every trial as it finishes.
///
/// # Errors
/// [`StudyError::InvalidSetting`] for a tolerance that is not positive or no degree to try, or when no degree
/// passes screening; [`StudyError::Refused`] for a design whose internal-variable update has no time-error
/// estimate (not the trapezoidal one); [`StudyError::Run`] when no candidate's results settle in time or pass
/// verification within [`MAX_ROUNDS`] rounds (each one's reason given).
pub fn tune(
    design: &dyn VariedDesign,
    settings: &TuneSettings,
    mut progress: impl FnMut(&Trial),
) -> Result<Tuned, StudyError> {
    let tol = super::positive("the tolerance", settings.tolerance)?;
    if settings.degrees.is_empty() {
        return Err(StudyError::InvalidSetting {
            setting: "the degrees to try",
            value: 0.0,
            expected: "at least one",
        });
    }
    let model = design.model();
    let end = model.time().end;
    // Every candidate controls its time error: refused at once for an update without an estimate.
    TimeVariant {
        tolerance: Some(tol),
        ..TimeVariant::default()
    }
    .of(model)?;
    let (names, locations) = watched_locations(model);
    let mut runner = Runner {
        design,
        names,
        locations,
        times: comparison_times(model),
        cache: Vec::new(),
    };
    let mut trials = Vec::new();
    let mut record = |trial: Trial, trials: &mut Vec<Trial>| {
        progress(&trial);
        trials.push(trial);
    };

    // 1. Space, on the short horizon.
    let horizon = screening_horizon(model);
    let screen = Stepping::Fixed(horizon / SCREEN_STEPS as Real);
    let key = |degree, points, stepping, end| RunKey {
        degree,
        points,
        stepping,
        end,
    };
    let mut candidates: Vec<(Real, usize, usize)> = Vec::new();
    for &p in &settings.degrees {
        for n in ladder(p, settings.max_points) {
            let trial = runner.compare(
                Stage::Space,
                key(p, n, screen, horizon),
                key(p, 2 * n, screen, horizon),
                tol / 2.0,
                format!("n = {}", 2 * n),
            );
            let found = trial.accepted.then_some(trial.cost).flatten();
            record(trial, &mut trials);
            if let Some((wall, ..)) = found {
                candidates.push((wall, p, n));
                break;
            }
        }
    }
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
    if candidates.is_empty() {
        return Err(StudyError::InvalidSetting {
            setting: "the tolerance (no degree reached it on the screening horizon within --max-points)",
            value: tol,
            expected: "looser, or more points allowed",
        });
    }

    // 2–3. Time over the whole schedule, then verification; refine n when the verification fails; the next
    // candidate when the results do not settle.
    let mut gave_up = Vec::new();
    for &(_, p, n0) in &candidates {
        let mut n = n0;
        let mut tau = time_ladder_start((10.0 * tol).min(LOOSEST_TIME_TOLERANCE));
        let mut rounds = 0;
        let outcome = loop {
            let Some(chosen) = time_ladder(&mut runner, &mut trials, &mut record, (p, n), tau, tol)
            else {
                let last = (trials.last().and_then(|t| t.failure.as_deref()))
                    .map_or_else(String::new, |why| format!(" (the last: {why})"));
                break format!(
                    "p = {p}, n = {n}: the results did not settle within {MAX_TIME_RUNGS} time tolerances{last}"
                );
            };
            let candidate = key(p, n, Stepping::Tolerance(chosen), end);
            let finer_tau = round_sig(chosen / 10.0);
            let finer = key(p, 2 * n, Stepping::Tolerance(finer_tau), end);
            let trial = runner.compare(
                Stage::Verify,
                candidate,
                finer,
                tol,
                format!("p = {p}, n = {}, τ = {finer_tau:e}", 2 * n),
            );
            record(trial.clone(), &mut trials);
            if let (true, Some(error), Some(cost)) = (trial.accepted, trial.difference, trial.cost)
            {
                let design_wall = design_cost(design)?;
                return Ok(Tuned {
                    degree: p,
                    points: n,
                    time_tolerance: chosen,
                    error,
                    reference: trial.against,
                    cost,
                    design_wall,
                    trials,
                });
            }
            rounds += 1;
            if rounds == MAX_ROUNDS {
                break format!("p = {p}: not verified up to n = {n}");
            }
            // The time tolerance was good enough at the coarser n; the next round starts its ladder there.
            tau = chosen;
            n = rung_above(n);
        };
        gave_up.push(outcome);
    }
    Err(StudyError::Run {
        run: gave_up.join("; "),
        source: Box::new(StudyError::InvalidSetting {
            setting: "the tolerance (no candidate met it against its finer run)",
            value: tol,
            expected: "looser, or other degrees",
        }),
    })
}

/// The time ladder of step 2 at `(p, n)` from `tau`: the first time tolerance whose results differ from those at
/// a tenth of it by at most half of `tol`, or `None` after [`MAX_TIME_RUNGS`] tries (a model near a limit point
/// whose path depends on the step: the next candidate is tried).
fn time_ladder(
    runner: &mut Runner<'_>,
    trials: &mut Vec<Trial>,
    record: &mut impl FnMut(Trial, &mut Vec<Trial>),
    (p, n): (usize, usize),
    mut tau: Real,
    tol: Real,
) -> Option<Real> {
    let end = runner.design.model().time().end;
    for _ in 0..MAX_TIME_RUNGS {
        let finer = round_sig(tau / 10.0);
        let key = |stepping| RunKey {
            degree: p,
            points: n,
            stepping,
            end,
        };
        let trial = runner.compare(
            Stage::Time,
            key(Stepping::Tolerance(tau)),
            key(Stepping::Tolerance(finer)),
            tol / 2.0,
            format!("τ = {finer:e}"),
        );
        let accepted = trial.accepted;
        record(trial, trials);
        if accepted {
            return Some(tau);
        }
        tau = time_rung_below(tau);
    }
    None
}

/// Wall time of the design's own settings \[s\]: fixed steps are timed over their first twentieth (at least 20
/// steps) and extrapolated by the planned step count; error-controlled ones are run in full.
fn design_cost(design: &dyn VariedDesign) -> Result<Real, StudyError> {
    let designed = design.model();
    let planned = design.steps().total().max(1);
    let fraction = if designed.time().tolerance.is_some() {
        1.0
    } else {
        (planned / 20).max(20).min(planned) as Real / planned as Real
    };
    let model = designed.clone().with_time(TimeSettings {
        end: designed.time().end * fraction,
        ..designed.time().clone()
    })?;
    let run = watched_run(&model, &[], None)?;
    Ok(if fraction < 1.0 {
        run.wall * planned as Real / run.summary.steps.max(1) as Real
    } else {
        run.wall
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ladder_climbs_by_its_ratio_from_twice_the_degree() {
        assert_eq!(ladder(6, 40), vec![12, 15, 19, 24, 30, 38]);
        assert_eq!(ladder(2, 8), vec![4, 5, 7]);
        assert_eq!(rung_above(4), 5);
    }

    // Source: the module docs' definition. Displacements count over the finer run's largest (a 1 mm
    // difference when it reaches 100 mm is 1e-2), Δr over its largest |Δr| (0.03 of 15: 2e-3), recovery ratios
    // absolutely (0.004); the largest of them is reported with its quantity and time, and a run that stopped
    // short of a comparison time cannot pass.
    #[test]
    fn the_difference_normalises_each_quantity_as_documented() {
        use crate::post::recovery::Recovery;
        let watched = |time: Real, u: Real, delta_r: Real, ratio: Real| Watched {
            time,
            displacements: vec![Vec3::new(u, 0.0, 0.0)],
            recovery: Some(Recovery {
                ratio_mean: ratio,
                ratio_max: ratio,
                delta_r: Some(delta_r),
                by_material: Vec::new(),
            }),
            grid: Vec::new(),
        };
        let names = vec!["probe tip".to_string()];
        let finer = [
            watched(1.0, 100.0, 15.0, 0.5),
            watched(2.0, 50.0, 10.0, 0.2),
        ];
        let run = [
            watched(1.0, 100.0, 15.03, 0.5),
            watched(2.0, 51.0, 10.0, 0.204),
        ];
        let d = difference(&run, &finer, &names);
        assert!((d.value - 1e-2).abs() < 1e-12, "{d:?}");
        assert_eq!((d.quantity.as_str(), d.time), ("probe tip", 2.0));
        let run = [
            watched(1.0, 100.0, 15.03, 0.5),
            watched(2.0, 50.0, 10.0, 0.204),
        ];
        let d = difference(&run, &finer, &names);
        assert!((d.value - 4e-3).abs() < 1e-12, "{d:?}");
        assert!(d.quantity.starts_with("recovery ratio"), "{d:?}");
        let run = [
            watched(1.0, 100.0, 15.03, 0.5),
            watched(2.0, 50.0, 10.0, 0.2),
        ];
        let d = difference(&run, &finer, &names);
        assert!((d.value - 2e-3).abs() < 1e-12, "{d:?}");
        assert_eq!(d.quantity, "Δr");
        let d = difference(&run[..1], &finer, &names);
        assert!(d.value.is_infinite(), "{d:?}");
    }

    #[test]
    fn the_time_ladder_takes_round_values_one_and_three() {
        assert_eq!(time_ladder_start(0.1), 0.1);
        assert_eq!(time_ladder_start(0.05), 0.03);
        assert_eq!(time_ladder_start(0.01), 0.01);
        assert_eq!(time_ladder_start(3e-3), 3e-3);
        assert_eq!(time_ladder_start(2.9e-3), 1e-3);
        assert_eq!(time_rung_below(0.03), 0.01);
        assert_eq!(time_rung_below(0.01), 3e-3);
        assert_eq!(time_rung_below(3e-3), 1e-3);
        assert_eq!(time_rung_below(1e-4), 3e-5);
    }
}
