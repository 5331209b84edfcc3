//! The virtual bench (issue 34): the tests a stent engineer runs on a device, as runs of a design.
//!
//! **Radial force** (`stentkit bench radial`; ASTM F3067). The device as designed (its permanent shape, full or
//! symmetry-reduced) is held at the bench's temperature in a rigid cylindrical crimper — for a device on a
//! curved axis, the tube around that axis — that closes at a constant rate of its diameter from just outside the
//! device (2 % clear of its outermost wire) to the bench's smallest diameter and opens again at the same rate.
//! The bench is a run of the design with its programme replaced by that crimp (`programme: {kind: crimp}`,
//! nothing prescribed, the device's free rigid motion held by the gauge), its temperature by the bench's, its
//! obstacles removed and fixed time steps that record `diameters` diameters on each branch; the run folder is a
//! run's (history, snapshots at the closed crimper, recording) with the bench's table and chart added. What the
//! design says under `bench:` (every field optional, each overridable with `--set bench.…`):
//!
//! ```yaml
//! bench:
//!   temperature: 37       # °C (default 37; above Tg the polymer is rubbery and the force depends on the rate)
//!   rate: 0.1             # diameter rate [length/time] (default 0.1 mm/s)
//!   min_diameter: 10      # [length] (default: the programme's crimped outer diameter 2 (R − Δr) + d)
//!   vessel_diameter: 12   # [length] where the chronic outward force is read (default: a vessel file's mean lumen)
//!   diameters: 30         # recorded per branch (default 30)
//! ```
//!
//! **What it measures.** At each recorded step the crimper's diameter `D` (its inner diameter, the device's outer
//! diameter where they touch) and the radial force `F`, the sum of the inward contact forces on the crimper over
//! the whole device (the model's share times `2^k` for `k` symmetry planes; the contact report's `Σ w p`): the
//! radial resistive force (RRF) while closing, the chronic outward force (COF) while opening. Per unit length,
//! `F / L` with `L` the device's length along its axis; as the equivalent uniform pressure on a cylinder of that
//! diameter and length, `P = F / (π D L)` (in kPa and mmHg). The table `radial.csv`, the chart
//! `charts/radial_force.svg` (both branches: the hysteresis loop) and, printed at the end, the smallest diameter
//! the crimper reached and the RRF and COF at the vessel's diameter (interpolated linearly between recorded
//! diameters on each branch).
//!
//! A run the solver could not finish leaves what it reached: the table up to there, and the smallest diameter
//! reached says how far it got.

use crate::design::{Design, DesignError, DesignOverrides, SetOverride, load_design_with};
use crate::io::chart::{LineChart, Series};
use crate::math::{Real, Vec3};
use crate::model::{Model, Surface, Units};
use std::path::{Path, PathBuf};

/// The default temperature of a bench test \[°C\]: body temperature.
pub const DEFAULT_TEMPERATURE: Real = 37.0;
/// The default rate of the crimper's diameter, in mm/s (converted to the design's units).
pub const DEFAULT_RATE_MM_PER_S: Real = 0.1;
/// The default number of diameters recorded per branch.
pub const DEFAULT_DIAMETERS: usize = 30;
/// 1 mmHg in kPa (133.322 Pa).
const KPA_PER_MMHG: Real = 0.133_322_387;

/// Why a bench could not be set up.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// The design (with the command's `--set`) was refused.
    #[error(transparent)]
    Design(#[from] DesignError),
    /// The design cannot be put on this bench, and why.
    #[error("{}: {message}", file.display())]
    Unfit {
        /// The design file.
        file: PathBuf,
        /// What does not fit.
        message: String,
    },
    /// The bench's table or chart could not be written into the run folder.
    #[error("{0}")]
    Output(String),
}

/// The radial bench of a design, its defaults resolved (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct RadialBench {
    /// Temperature \[°C\].
    pub temperature: Real,
    /// Rate of the crimper's diameter \[length/time\].
    pub rate: Real,
    /// The crimper's diameter at the start, 2 % clear of the device \[length\].
    pub start_diameter: Real,
    /// The smallest diameter \[length\].
    pub min_diameter: Real,
    /// Where the chronic outward force is read \[length\].
    pub vessel_diameter: Option<Real>,
    /// Diameters recorded per branch.
    pub diameters: usize,
    /// The time the crimper takes to close (and to open) \[time\].
    pub closing: Real,
    /// The device's length along its axis \[length\].
    pub length: Real,
    /// The whole device over the model: `2^k` for `k` symmetry planes.
    pub copies: Real,
    /// The unit system (for the pressure's units).
    pub units: Units,
}

/// The design of the radial bench of the design at `path` with the command's `overrides` (module docs), and the
/// bench with its defaults resolved.
///
/// # Errors
/// [`BenchError::Design`] for a design or an override refused (located in the file), [`BenchError::Unfit`] for
/// a design without a generated stent or a smallest diameter at or above the device's.
pub fn radial_design(
    path: &Path,
    overrides: &DesignOverrides,
) -> Result<(Design, RadialBench), BenchError> {
    let design = load_design_with(path, overrides)?;
    let unfit = |message: String| BenchError::Unfit {
        file: path.to_path_buf(),
        message,
    };
    let has_stent = serde_yaml::from_str::<serde_yaml::Value>(&design.source)
        .ok()
        .is_some_and(|v| v.get("stent").is_some());
    if !has_stent {
        return Err(unfit(
            "the radial bench crimps a generated stent (a `stent:` block); this design has none"
                .into(),
        ));
    }
    if design.model.temperature_field.is_some() {
        return Err(unfit(
            "the radial bench holds the device at one temperature (`bench.temperature`): a design with a \
             `temperature_field` cannot be put on it as it is; remove the field"
                .into(),
        ));
    }
    let spec = design.bench;
    let units = design.model.units;
    let per_mm = match units {
        Units::Si => 1e-3,
        Units::MmNMpa => 1.0,
    };
    // A first crimper closing by a negligible Δr tells the crimper's geometry: its start radius (2 % clear of
    // the device) and `R + d/2` (its closed radius plus that Δr), from which any smallest diameter follows.
    let probe = 1e-9 * per_mm;
    let first = with_sets(
        path,
        overrides,
        &bench_sets(probe, 1.0, 1.0, DEFAULT_TEMPERATURE),
    )?;
    let crimper = crimper_radius(&first.model)
        .ok_or_else(|| unfit("the crimp programme built no crimper".into()))?;
    let (start, reach) = (crimper(0.0), crimper(1.0) + probe);
    let min_diameter = match spec.min_diameter {
        Some(d) => d,
        None => match design.model.programme.as_ref().map(|p| p.kind) {
            Some(
                crate::model::ProgrammeKind::RadialContraction { delta_r }
                | crate::model::ProgrammeKind::Crimp { delta_r, .. },
            ) => 2.0 * (reach - delta_r),
            _ => reach,
        },
    };
    let wire = design
        .model
        .sections
        .iter()
        .map(|s| s.diameter())
        .fold(0.0, Real::max);
    if !(min_diameter > wire && min_diameter < 2.0 * start) {
        return Err(unfit(format!(
            "bench.min_diameter: the crimper would close to {min_diameter} {}, which must lie between the wire's \
             diameter {wire} and the crimper's start {:.4} (2 % clear of the device)",
            units.length(),
            2.0 * start
        )));
    }
    let rate = spec.rate.unwrap_or(DEFAULT_RATE_MM_PER_S * per_mm);
    let temperature = spec.temperature.unwrap_or(DEFAULT_TEMPERATURE);
    let closing = (2.0 * start - min_diameter) / rate;
    let diameters = spec.diameters.unwrap_or(DEFAULT_DIAMETERS);
    let sets = bench_sets(
        reach - 0.5 * min_diameter,
        closing,
        closing / (diameters - 1) as Real,
        temperature,
    );
    let bench_design = with_sets(path, overrides, &sets)?;
    let model = &bench_design.model;
    let bench = RadialBench {
        temperature,
        rate,
        start_diameter: 2.0 * start,
        min_diameter,
        vessel_diameter: spec.vessel_diameter.or_else(|| vessel_diameter(model)),
        diameters,
        closing,
        length: device_length(model),
        copies: (2.0 as Real).powi(model.symmetry_planes.len() as i32),
        units,
    };
    Ok((bench_design, bench))
}

/// The design at `path` with the command's `overrides`, then the bench's `sets`.
fn with_sets(
    path: &Path,
    overrides: &DesignOverrides,
    sets: &[String],
) -> Result<Design, BenchError> {
    let mut all = overrides.clone();
    for s in sets {
        all.sets
            .push(s.parse::<SetOverride>().map_err(|e| BenchError::Unfit {
                file: path.to_path_buf(),
                message: format!("the bench's own override was refused: {e}"),
            })?);
    }
    Ok(load_design_with(path, &all)?)
}

/// The bench's overrides of a design (module docs): a crimper closing by `delta_r` over `closing` and opening
/// over as long, fixed steps of `step`, the temperature held, no other obstacle.
fn bench_sets(delta_r: Real, closing: Real, step: Real, temperature: Real) -> Vec<String> {
    vec![
        format!(
            "programme={{kind: crimp, nodes: all_joints, delta_r: {delta_r:e}, ramp: [0, {closing:e}], release: {closing:e}, open: {closing:e}}}"
        ),
        format!("temperature={temperature:e}"),
        "obstacles=[]".into(),
        format!("time={{end: {:e}, step: {step:e}}}", 2.0 * closing),
    ]
}

/// The crimper's radius as a function of time: the last obstacle of a crimp programme's model (a cylinder's
/// radius, or the scale of a tube of radius 1 around a curved axis).
fn crimper_radius(model: &Model) -> Option<impl Fn(Real) -> Real + '_> {
    let crimper = model.contact.as_ref()?.obstacles.last()?;
    let schedule = match &crimper.surface {
        Surface::Cylinder { radius, .. } => radius,
        Surface::Lumen(tube) => tube.scale(),
        Surface::Plane { .. } => return None,
    };
    Some(move |t: Real| schedule.value(t))
}

/// A vessel file's mean lumen diameter (its radius samples weighted by the chords between them), if the
/// design's stent sits on one that gives the radius.
fn vessel_diameter(model: &Model) -> Option<Real> {
    let vessel = model.vessel.as_ref()?;
    let radius = vessel.radius.as_ref()?;
    let (mut weighted, mut length) = (0.0, 0.0);
    for (p, r) in vessel.points.windows(2).zip(radius.windows(2)) {
        let chord = (p[1] - p[0]).norm();
        weighted += 0.5 * (r[0] + r[1]) * chord;
        length += chord;
    }
    (length > 0.0).then(|| 2.0 * weighted / length)
}

/// The device's length along its axis: the extent of its wires' sample points along a straight crimper's
/// axis, or along the centreline of a curved crimper's tube (between the points' closest parameters).
fn device_length(model: &Model) -> Real {
    let Some(crimper) = model.contact.as_ref().and_then(|c| c.obstacles.last()) else {
        return 0.0;
    };
    let points: Vec<Vec3> = model
        .patches
        .iter()
        .flat_map(|p| p.dense_points())
        .collect();
    match &crimper.surface {
        Surface::Cylinder { point, axis, .. } => {
            let along = points.iter().map(|x| (x - point).dot(axis));
            let (lo, hi) = along.fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), s| {
                (lo.min(s), hi.max(s))
            });
            (hi - lo).max(0.0)
        }
        Surface::Lumen(tube) => {
            let u: Vec<Real> = points
                .iter()
                .filter_map(|x| tube.closest(x, None))
                .collect();
            let (lo, hi) = u
                .iter()
                .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), &s| {
                    (lo.min(s), hi.max(s))
                });
            if !(hi > lo) {
                return 0.0;
            }
            const SAMPLES: usize = 256;
            let curve = tube.centreline();
            (0..SAMPLES)
                .map(|i| {
                    let (a, b) = (
                        lo + (hi - lo) * i as Real / SAMPLES as Real,
                        lo + (hi - lo) * (i + 1) as Real / SAMPLES as Real,
                    );
                    (curve.point(b) - curve.point(a)).norm()
                })
                .sum()
        }
        Surface::Plane { .. } => 0.0,
    }
}

/// Closing or opening.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Branch {
    /// The crimper closes: the radial resistive force.
    Loading,
    /// The crimper opens: the chronic outward force.
    Unloading,
}

impl Branch {
    /// The name in `radial.csv`.
    pub fn name(self) -> &'static str {
        match self {
            Branch::Loading => "loading",
            Branch::Unloading => "unloading",
        }
    }
}

/// One recorded diameter of the radial bench (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadialPoint {
    /// Time \[time\].
    pub time: Real,
    /// Closing or opening (the smallest diameter is the last of the loading branch and the first of the
    /// unloading one).
    pub branch: Branch,
    /// The crimper's diameter \[length\].
    pub diameter: Real,
    /// The radial force on the whole device \[force\].
    pub force: Real,
    /// Points of the model in contact with the crimper.
    pub points: usize,
}

impl RadialBench {
    /// The recorded diameters of a bench run from its `history.csv` text (module docs): each row's time, the
    /// crimper's diameter from `model`'s (the bench design's) schedule, the radial force and points from the
    /// crimper's columns. Rows after a cut one end the table (as a killed run's last line may be cut).
    pub fn points(&self, model: &Model, history: &str) -> Vec<RadialPoint> {
        let Some(radius) = crimper_radius(model) else {
            return Vec::new();
        };
        let history = crate::io::history::History::parse(history);
        let (Some(force), Some(points)) = (
            history.column("contact_radial_force@crimper"),
            history.column("contact_points@crimper"),
        ) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (&(time, f), &(_, n)) in force.iter().zip(&points) {
            let point = |branch| RadialPoint {
                time,
                branch,
                diameter: 2.0 * radius(time),
                force: self.copies * f,
                points: n as usize,
            };
            if time <= self.closing * (1.0 + 1e-9) {
                out.push(point(Branch::Loading));
            }
            if time >= self.closing * (1.0 - 1e-9) {
                out.push(point(Branch::Unloading));
            }
        }
        out
    }

    /// The radial force `force` at diameter `diameter` per unit length \[force/length\] and as the equivalent
    /// pressure in kPa.
    pub fn per_length_and_pressure(&self, force: Real, diameter: Real) -> (Real, Real) {
        let kpa_per_stress = match self.units {
            Units::Si => 1e-3,
            Units::MmNMpa => 1e3,
        };
        let per_length = force / self.length;
        let pressure = force / (std::f64::consts::PI * diameter * self.length);
        (per_length, pressure * kpa_per_stress)
    }

    /// `radial.csv`: one row per recorded diameter and branch (module docs).
    pub fn table(&self, points: &[RadialPoint]) -> String {
        let length = self.units.length();
        let mut out = format!(
            "time,branch,diameter_{length},radial_force_N,force_per_length_N_per_{length},pressure_kPa,pressure_mmHg,points_in_contact\n"
        );
        for p in points {
            let (per_length, kpa) = self.per_length_and_pressure(p.force, p.diameter);
            out.push_str(&format!(
                "{:.10e},{},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{}\n",
                p.time,
                p.branch.name(),
                p.diameter,
                p.force,
                per_length,
                kpa,
                kpa / KPA_PER_MMHG,
                p.points
            ));
        }
        out
    }

    /// The radial force on `branch` at diameter `d`, linear between the recorded diameters; `None` outside them.
    pub fn force_at(points: &[RadialPoint], branch: Branch, d: Real) -> Option<Real> {
        let branch: Vec<&RadialPoint> = points.iter().filter(|p| p.branch == branch).collect();
        branch.windows(2).find_map(|w| {
            let (a, b) = (w[0], w[1]);
            let (lo, hi) = (a.diameter.min(b.diameter), a.diameter.max(b.diameter));
            if !(lo <= d && d <= hi) {
                return None;
            }
            if hi == lo {
                return Some(a.force);
            }
            Some(a.force + (b.force - a.force) * (d - a.diameter) / (b.diameter - a.diameter))
        })
    }

    /// The chart of both branches, force against diameter, the vessel's diameter dashed.
    pub fn chart(&self, points: &[RadialPoint]) -> LineChart {
        let length = self.units.length();
        let mut chart = LineChart::new(
            format!(
                "radial force at {} °C, {} {length}/s",
                crate::math::Short(self.temperature),
                crate::math::Short(self.rate)
            ),
            format!("diameter ({length})"),
            "radial force (N)",
        );
        for (branch, label) in [
            (Branch::Loading, "closing (RRF)"),
            (Branch::Unloading, "opening (COF)"),
        ] {
            let xy: Vec<(Real, Real)> = points
                .iter()
                .filter(|p| p.branch == branch)
                .map(|p| (p.diameter, p.force))
                .collect();
            if !xy.is_empty() {
                chart.series.push(Series::new(label, xy).with_markers());
            }
        }
        if let Some(d) = self.vessel_diameter {
            let top = points.iter().map(|p| p.force).fold(0.0, Real::max);
            chart
                .series
                .push(Series::new("vessel diameter", vec![(d, 0.0), (d, top)]).dashed());
        }
        chart
    }

    /// What the bench prints at the end: the smallest diameter reached and the forces at the vessel's diameter.
    pub fn summary(&self, points: &[RadialPoint]) -> Vec<String> {
        let length = self.units.length();
        let mut lines = Vec::new();
        let reached = points
            .iter()
            .map(|p| p.diameter)
            .fold(Real::INFINITY, Real::min);
        if reached.is_finite() {
            lines.push(format!(
                "smallest diameter reached: {reached:.4} {length} (asked {:.4} {length})",
                self.min_diameter
            ));
        }
        match self.vessel_diameter {
            None => lines.push(
                "no vessel diameter (a vessel file's lumen, or `bench.vessel_diameter`): no COF read".into(),
            ),
            Some(d) => {
                for (branch, what) in [
                    (Branch::Loading, "radial resistive force (closing)"),
                    (Branch::Unloading, "chronic outward force (opening)"),
                ] {
                    let line = match Self::force_at(points, branch, d) {
                        Some(f) => {
                            let (per_length, kpa) = self.per_length_and_pressure(f, d);
                            format!(
                                "{what} at the vessel diameter {d:.4} {length}: {f:.4e} N, {per_length:.4e} N/{length}, {kpa:.4} kPa ({:.4} mmHg)",
                                kpa / KPA_PER_MMHG
                            )
                        }
                        None => format!(
                            "{what}: the vessel diameter {d:.4} {length} was not reached on this branch"
                        ),
                    };
                    lines.push(line);
                }
            }
        }
        lines
    }
}

/// Adds the radial bench's table (`radial.csv`) and chart (`charts/radial_force.svg`) to the run folder `dir` of
/// its run (listed in the folder's manifest, so `--force` removes them with the run's files) and returns what the
/// bench prints at the end ([`RadialBench::summary`]). `model` is the bench design's.
///
/// # Errors
/// [`BenchError::Output`] when the folder cannot be taken again (another run holds it) or a file cannot be written.
pub fn write_radial_outputs(
    dir: &Path,
    bench: &RadialBench,
    model: &Model,
) -> Result<Vec<String>, BenchError> {
    use crate::io::run_folder;
    let fail = |e: &dyn std::fmt::Display| BenchError::Output(e.to_string());
    let history = std::fs::read_to_string(dir.join("history.csv"))
        .map_err(|e| fail(&format!("{}: {e}", dir.join("history.csv").display())))?;
    let points = bench.points(model, &history);
    let folder = run_folder::check_resume(dir, Path::new("summary.json"))
        .and_then(run_folder::ResumableFolder::open)
        .map_err(|e| fail(&e))?;
    let write = |relative: &str, bytes: &[u8]| -> Result<(), BenchError> {
        let relative = Path::new(relative);
        folder.manifest().claim(relative).map_err(|e| fail(&e))?;
        let path = dir.join(relative);
        crate::io::atomic::write_bytes_atomically(&path, bytes)
            .map_err(|e| fail(&format!("{}: {e}", path.display())))
    };
    write("radial.csv", bench.table(&points).as_bytes())?;
    if !points.is_empty() {
        let svg = crate::io::chart::render_svg(&bench.chart(&points)).map_err(|e| fail(&e))?;
        std::fs::create_dir_all(dir.join(run_folder::CHARTS_FOLDER)).map_err(|e| fail(&e))?;
        write("charts/radial_force.svg", svg.as_bytes())?;
    }
    Ok(bench.summary(&points))
}
