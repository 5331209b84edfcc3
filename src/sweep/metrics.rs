//! What a designer compares across variants, read from one run folder (`history.csv`, `summary.json`) and the
//! variant's design (the programme's release time) — so a run on this machine and one on a cluster give the
//! same numbers.
//!
//! With `u` the largest node displacement from the permanent shape (`history.csv` `max_displacement`),
//! `ρ` the recovery ratio (`recovery_ratio_mean`: the mean over the driven nodes of `‖η‖ / ‖η_temp‖`, 1 at the
//! programme's temporary shape, 0 at the permanent one), `t_r` the release and `t_r⁺` the first saved step at
//! or after the end of the release ramp:
//! - **programmed displacement** `u(t_r)`: how far the programme deformed the device;
//! - **snap at release** `u(t_r) − u(t_r⁺)`: how far the largest displacement springs back when released;
//! - **fixity** `ρ(t_r⁺) / ρ(t_r)`: the share of the programmed shape kept after the release;
//! - **recovery ratio at chosen times** `ρ(t)`, linear between saved steps;
//! - **time to 50 % / 90 % recovery**: `t − t_r` where `ρ` first falls to 0.5 / 0.1 after the release (empty
//!   when it never does);
//! - **final residual shape**: `ρ` (mean and largest) and `u` at the last saved step;
//! - **warnings**: how many `summary.json` lists (a run can complete with one: stabilisation above its limit,
//!   a device heated but not recovered), so a table of completed variants does not hide them;
//! - **apposition**, per obstacle of a model with contact, at the end (`summary.json`'s `contact[].apposition`):
//!   the share of the wires' length in contact, the largest gap of a wire from the surface (malapposition) and
//!   the mean line pressure over the length in contact;
//! - **the bench's numbers**, for a sweep of a bench test (`bench.json`, `crate::bench::BenchResults`): the
//!   smallest size the tool reached and its forces at the readings (the radial force closing and opening at
//!   the vessel's diameter; the crush force closing at 10 %, 25 % and 50 % crushed);
//! - **recoil** and **foreshortening** of a programmed device (`summary.json`'s `deployment`;
//!   `crate::post::deployment`): the diameter it gave back as its tool let go, and its length lost from the
//!   crimped state to the end, each as a fraction.
//!
//! The peak strain is not reported: runs do not compute strains yet. A design without a programme gets only
//! the final displacement. A run that stopped early gives the metrics its history reaches.

use crate::io::history::History;
use crate::math::Real;
use crate::model::Model;
use std::path::Path;

/// The metrics of one run (module docs); `None` where the run does not give it.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Metrics {
    /// Wall time of the run \[s\].
    pub wall_time_s: Option<Real>,
    /// Converged steps.
    pub steps: Option<u64>,
    /// The warnings in the run's `summary.json` (the design's, and the run's own: stabilisation above its
    /// limit, a device heated but not recovered).
    pub warnings: Option<u64>,
    /// `u(t_r)` \[length\].
    pub programmed_displacement: Option<Real>,
    /// `u(t_r) − u(t_r⁺)` \[length\].
    pub snap: Option<Real>,
    /// `ρ(t_r⁺) / ρ(t_r)`.
    pub fixity: Option<Real>,
    /// `ρ` at the chosen times, in their order.
    pub recovery_at: Vec<Option<Real>>,
    /// Time from the release to `ρ ≤ 0.5` \[time\].
    pub time_to_50: Option<Real>,
    /// Time from the release to `ρ ≤ 0.1` \[time\].
    pub time_to_90: Option<Real>,
    /// `ρ` at the last saved step.
    pub final_ratio_mean: Option<Real>,
    /// The largest `‖η‖ / ‖η_temp‖` over the driven nodes at the last saved step.
    pub final_ratio_max: Option<Real>,
    /// `u` at the last saved step \[length\].
    pub final_displacement: Option<Real>,
    /// Per obstacle of a model with contact, in the model's order, how the wires lie on it at the last
    /// converged step (`summary.json`'s `contact[].apposition`).
    pub apposition: Vec<AppositionMetrics>,
    /// `(D_open − D_closed) / D_closed` as the tool let go (`summary.json`'s `deployment.recoil`).
    pub recoil: Option<Real>,
    /// `(L_crimped − L_end) / L_crimped` (`summary.json`'s `deployment.foreshortening`).
    pub foreshortening: Option<Real>,
    /// A bench run's results (`bench.json`).
    pub bench: Option<crate::bench::BenchResults>,
}

/// How the wires lie on one obstacle at the end of a run (`summary.json`'s `contact[].apposition`).
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct AppositionMetrics {
    /// The share of the wires' length in contact.
    pub contact_fraction: Option<Real>,
    /// The largest gap of a wire from the surface \[length\].
    pub largest_gap: Option<Real>,
    /// The mean line pressure over the length in contact \[force/length\].
    pub mean_pressure: Option<Real>,
}

/// The value of `series` at `t`, linear between its points; `None` outside them.
fn at(series: &[(Real, Real)], t: Real) -> Option<Real> {
    let i = series.partition_point(|&(s, _)| s < t);
    let &(t1, v1) = series.get(i)?;
    if t1 == t || i == 0 {
        return (t1 == t).then_some(v1);
    }
    let (t0, v0) = series[i - 1];
    Some(v0 + (v1 - v0) * (t - t0) / (t1 - t0))
}

/// The value of `series` at its last point at or before `t`.
fn last_at_or_before(series: &[(Real, Real)], t: Real) -> Option<Real> {
    series.iter().rev().find(|&&(s, _)| s <= t).map(|&(_, v)| v)
}

/// The first time after `from` where `series` falls to `level`, linear between points.
fn first_at_or_below(series: &[(Real, Real)], from: Real, level: Real) -> Option<Real> {
    let mut previous: Option<(Real, Real)> = None;
    for &(t, v) in series.iter().filter(|&&(t, _)| t >= from) {
        if v <= level {
            return Some(match previous {
                Some((t0, v0)) if v0 > v => t0 + (t - t0) * (v0 - level) / (v0 - v),
                _ => t,
            });
        }
        previous = Some((t, v));
    }
    None
}

/// When a programme releases the device: the release time and the duration of its ramp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Release {
    /// `t_r` \[time\].
    pub time: Real,
    /// The release ramp \[time\] (`time.release_ramp`).
    pub ramp: Real,
}

impl Release {
    /// The release of `model`'s programme, if it has one that releases.
    pub(crate) fn of(model: &Model) -> Option<Self> {
        let time = model.programme.as_ref()?.release?;
        Some(Self {
            time,
            ramp: model.time().release_ramp,
        })
    }
}

/// The metrics of the run whose history is `history` and whose `summary.json` is `summary`, released at
/// `release`, with the recovery ratio taken at `times` (module docs).
pub(crate) fn metrics(
    release: Option<Release>,
    history: &History,
    summary: Option<&serde_json::Value>,
    times: &[Real],
) -> Metrics {
    let u = history.column("max_displacement").unwrap_or_default();
    let rho = history.column("recovery_ratio_mean").unwrap_or_default();
    let rho_max = history.column("recovery_ratio_max").unwrap_or_default();
    let after = release.and_then(|r| {
        u.iter()
            .map(|&(t, _)| t)
            .find(|&t| t > r.time && t >= r.time + r.ramp)
    });
    let release = release.map(|r| r.time);
    let value = |series: &[(Real, Real)], t: Option<Real>| t.and_then(|t| at(series, t));
    let before = |series: &[(Real, Real)]| release.and_then(|r| last_at_or_before(series, r));
    let programmed = before(&u);
    let fixity = match (value(&rho, after), before(&rho)) {
        (Some(a), Some(b)) if b != 0.0 => Some(a / b),
        _ => None,
    };
    let recovered = |level: Real| {
        let r = release?;
        first_at_or_below(&rho, r, level).map(|t| t - r)
    };
    Metrics {
        wall_time_s: summary.and_then(|s| s["wall_time_s"].as_f64()),
        steps: summary.and_then(|s| s["steps"].as_u64()),
        warnings: summary.and_then(|s| s["warnings"].as_array().map(|w| w.len() as u64)),
        programmed_displacement: programmed,
        snap: programmed.zip(value(&u, after)).map(|(b, a)| b - a),
        fixity,
        recovery_at: times.iter().map(|&t| at(&rho, t)).collect(),
        time_to_50: recovered(0.5),
        time_to_90: recovered(0.1),
        final_ratio_mean: rho.last().map(|p| p.1),
        final_ratio_max: rho_max.last().map(|p| p.1),
        final_displacement: u.last().map(|p| p.1),
        apposition: summary
            .and_then(|s| s["contact"].as_array())
            .map(|obstacles| {
                obstacles
                    .iter()
                    .map(|o| {
                        let a = &o["apposition"];
                        AppositionMetrics {
                            contact_fraction: a["contact_fraction"].as_f64(),
                            largest_gap: a["largest_gap"]["value"].as_f64(),
                            mean_pressure: a["mean_pressure"].as_f64(),
                        }
                    })
                    .collect()
            })
            .unwrap_or_default(),
        recoil: summary.and_then(|s| s["deployment"]["recoil"]["recoil"].as_f64()),
        foreshortening: summary
            .and_then(|s| s["deployment"]["foreshortening"]["foreshortening"].as_f64()),
        bench: None,
    }
}

/// [`metrics`] of the run folder `run` of `model`.
pub(crate) fn run_metrics(model: &Model, run: &Path, times: &[Real]) -> Metrics {
    let history = std::fs::read_to_string(run.join("history.csv"))
        .map(|t| History::parse(&t))
        .unwrap_or_default();
    let summary = crate::io::input::read_json(&run.join("summary.json")).ok();
    Metrics {
        bench: std::fs::read_to_string(run.join(crate::bench::RESULTS_FILE))
            .ok()
            .and_then(|text| serde_json::from_str(&text).ok()),
        ..metrics(Release::of(model), &history, summary.as_ref(), times)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Source: the definitions (module docs) on a hand-made history: a ramp to u = 10 (ρ = 1) by t = 1,
    /// release at 1 with a ramp of 0.1, u = 8 (ρ = 0.8) at 1.1, then ρ = 0.8 − 0.5 (t − 1.1) down to 0.
    #[test]
    fn the_metrics_follow_their_definitions() {
        let mut text =
            String::from("time,recovery_ratio_mean,recovery_ratio_max,max_displacement\n");
        for (t, rho) in [
            (0.0, 0.0),
            (1.0, 1.0),
            (1.1, 0.8),
            (1.7, 0.5),
            (2.5, 0.1),
            (2.7, 0.0),
        ] {
            text.push_str(&format!("{t},{rho},{},{}\n", rho * 1.5, rho * 10.0));
        }
        text.push_str("2.8,0.0,0"); // a cut last row is ignored
        let history = History::parse(&text);
        let release = Release {
            time: 1.0,
            ramp: 0.1,
        };
        let m = metrics(Some(release), &history, None, &[1.4, 9.0]);
        let close = |a: Option<Real>, b: Real| a.is_some_and(|a| (a - b).abs() < 1e-12);
        assert!(close(m.programmed_displacement, 10.0));
        assert!(close(m.snap, 2.0));
        assert!(close(m.fixity, 0.8));
        assert!(close(m.recovery_at[0], 0.65), "{:?}", m.recovery_at);
        assert_eq!(m.recovery_at[1], None);
        assert!(close(m.time_to_50, 0.7));
        assert!(close(m.time_to_90, 1.5));
        assert!(close(m.final_ratio_mean, 0.0));
        assert!(close(m.final_displacement, 0.0));
        assert!(m.apposition.is_empty(), "no summary, no apposition");
    }

    /// Source: `summary.json`'s contact entries as the run writes them: each obstacle's apposition read back in
    /// the model's order, an obstacle without one (a summary written before it existed) left empty.
    #[test]
    fn the_apposition_is_read_per_obstacle_from_the_summary() {
        let summary = serde_json::json!({
            "contact": [
                {"obstacle": "vessel", "apposition": {"time": 4.0, "contact_fraction": 0.25,
                    "largest_gap": {"value": 1.5, "patch": "c1_w9", "u": 0.5},
                    "peak_pressure": 0.04, "mean_pressure": 0.01}},
                {"obstacle": "crimper"}
            ]
        });
        let m = metrics(None, &History::default(), Some(&summary), &[]);
        assert_eq!(
            m.apposition,
            vec![
                AppositionMetrics {
                    contact_fraction: Some(0.25),
                    largest_gap: Some(1.5),
                    mean_pressure: Some(0.01),
                },
                AppositionMetrics::default(),
            ]
        );
    }
}
