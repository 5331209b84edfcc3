//! The virtual bench (issue 34): the tests a stent engineer runs on a device, as runs of a design.
//!
//! **Radial force** (`stentkit bench radial`; ASTM F3067). The device as designed (its permanent shape, full or
//! symmetry-reduced) is held at the bench's temperature in a rigid cylindrical crimper — for a device on a
//! curved axis, the tube around that axis — that closes at a constant rate of its diameter from just outside the
//! device (2 % clear of its outermost wire) to the bench's smallest diameter and opens again at the same rate.
//! With `segments`, a segmented head of that many flat faces around a straight axis instead
//! (`crate::model::stent::segmented_crimper`): its diameter is the polygon's inscribed one, its force the faces'
//! normal forces summed.
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
//!   diameters: 30         # recorded per branch (default 30; 120 with `contact: {wires: true}`)
//!   min_gap: 6            # [length] the crush's smallest plate gap (default half the device's outer diameter)
//!   segments: 12          # the radial bench's crimper as a segmented head of 12 flat faces (default: a cylinder)
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
//! **Flat-plate crush** (`stentkit bench crush`). The same run with two rigid plates instead of the crimper:
//! planes parallel to the device's straight axis, either side of it, closing along the normal of the model's
//! first symmetry plane through the axis (for a full model, of the plane through the axis and its first node) from
//! 2 % clear of the device to the smallest gap `bench.min_gap` (default half the device's outer diameter, a
//! 50 % crush) and opening again, their gap changing at `rate` (`programme: {kind: crush}`; a symmetry plane
//! parallel to the plates leaves one plate in the model). What it measures: the gap `D` between the plates and
//! the force `F` on one plate (the model's plates' normal forces times `2^k / 2`), per unit length `F / L` and
//! as the mean pressure on the device's projected area `F / (D L)`; `crush.csv`, `charts/crush_force.svg`, and
//! printed the smallest gap reached and the force on each branch at 10 %, 25 % and 50 % of the device's outer
//! diameter crushed (`bench.vessel_diameter` adds its gap).
//!
//! **Where the wires touch** (issue 35, both tests). The run records the first step at which the device's wires
//! touch each other (module docs of `crate::solver::terms::crossing`); the bench reads its time from
//! summary.json and prints the tool's sizes at that step's start and end — between them struts lock — with
//! where they touched (refine the bench's steps to narrow it), and `bench.json` keeps it (`touch`; `sweep
//! collect`'s `touch_diameter`, `touch_gap`). Without the wires' contact past that size the wires pass through
//! each other (the run warns once they do by more than its tolerance), so the forces past it are not the
//! device's. With it (`contact: {wires: true}`, `crate::solver::terms::wires`) they press on each other, and
//! the bench reads where the struts **lock**: the first recorded size after the wires touched at which the
//! closing force's secant stiffness `ΔF/ΔD` is `LOCK_STIFFENING` = 10 times its mean between the tool's first
//! touch of the device and the wires' first touch (the knee of the curve an engineer reads; on the straight
//! stent the stiffness jumps from 8× to 36× across one step of 0.26 mm, so the choice of 10 moves the reading by
//! at most a step). Printed, in `bench.json` (`lock`) and as `sweep collect`'s `lock_diameter` (`lock_gap`): the
//! smallest crimp diameter the struts allow. The tool closes on to its smallest size past the lock (choose
//! `bench.min_diameter` a little below it), pressing locked struts with the contact's penalty, which the run's
//! warnings report when it leaves the penetration above the tolerance.
//!
//! A run the solver could not finish leaves what it reached: the table up to there, and the smallest diameter
//! (gap) reached says how far it got.

use crate::design::{Design, DesignError, DesignOverrides, SetOverride, load_design_with};
use crate::io::chart::{LineChart, Series};
use crate::math::{Real, Vec3};
use crate::model::{Model, Surface, Units};
use std::path::{Path, PathBuf};

/// The default temperature of a bench test \[°C\]: body temperature.
pub const DEFAULT_TEMPERATURE: Real = 37.0;
/// The default rate of the crimper's diameter (the plates' gap), in mm/s (converted to the design's units).
pub const DEFAULT_RATE_MM_PER_S: Real = 0.1;
/// The file of a bench's results in its run folder ([`BenchResults`]).
pub const RESULTS_FILE: &str = "bench.json";
/// The default number of diameters recorded per branch.
pub const DEFAULT_DIAMETERS: usize = 30;

/// The sizes recorded per branch by default when the device's wires touch each other (`contact: {wires: true}`):
/// the lock is read to a recorded step, and struts that close on each other over a long step go deep before the
/// contact's updates can hold them. On the straight stent crimped to 9 mm, 30 diameters (1.1 mm steps) read the
/// lock at 9.279 mm with struts 7.7e-3 mm into each other (tolerance 6e-3); 120 (0.27 mm) read 9.545 mm, as
/// `assets/bench/straight_stent_lock.json` has it.
pub const DEFAULT_DIAMETERS_WITH_WIRES: usize = 120;
/// The crush's readings: the force at these fractions of the device's outer diameter crushed (module docs).
pub const CRUSH_READINGS: [Real; 3] = [0.1, 0.25, 0.5];
/// The name of the crush's reading at the fraction `f` of the outer diameter crushed (`10%` for 0.1).
pub fn crush_reading_name(f: Real) -> String {
    format!("{}%", crate::math::Short(100.0 * f))
}

/// 1 mmHg in kPa (133.322 Pa).
const KPA_PER_MMHG: Real = 0.133_322_387;

/// Which test of the bench (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Test {
    /// The radial force in a closing and opening cylindrical crimper.
    Radial,
    /// The flat-plate crush.
    Crush,
}

impl Test {
    /// The command's and the run folder's name, and the stem of its table and chart.
    pub fn name(self) -> &'static str {
        match self {
            Test::Radial => "radial",
            Test::Crush => "crush",
        }
    }

    /// The test of a name ([`Test::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        [Test::Radial, Test::Crush]
            .into_iter()
            .find(|t| t.name() == name)
    }

    /// The programme kind the bench gives the design.
    fn programme(self) -> &'static str {
        match self {
            Test::Radial => "crimp",
            Test::Crush => "crush",
        }
    }

    /// What the tool's size is: the crimper's diameter or the plates' gap.
    pub fn size(self) -> &'static str {
        match self {
            Test::Radial => "diameter",
            Test::Crush => "gap",
        }
    }
}

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

/// A bench test of a design, its defaults resolved (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Bench {
    /// Radial force or crush.
    pub test: Test,
    /// Temperature \[°C\].
    pub temperature: Real,
    /// Rate of the crimper's diameter or the plates' gap \[length/time\].
    pub rate: Real,
    /// The tool's size at the start (the crimper's diameter, the plates' gap), 2 % clear of the device
    /// \[length\].
    pub start_diameter: Real,
    /// The device's outer diameter across the tool (twice the wires' reach from the axis) \[length\].
    pub outer_diameter: Real,
    /// The smallest size the tool closes to \[length\].
    pub min_diameter: Real,
    /// Where the chronic outward force is read \[length\].
    pub vessel_diameter: Option<Real>,
    /// Sizes recorded per branch.
    pub diameters: usize,
    /// The time the tool takes to close (and to open) \[time\].
    pub closing: Real,
    /// The device's length along its axis \[length\].
    pub length: Real,
    /// The whole device over the model: `2^k` for `k` symmetry planes.
    pub copies: Real,
    /// The unit system (for the pressure's units).
    pub units: Units,
    /// Whether the device's wires touch each other (`contact: {wires: true}`): the bench then reads where the
    /// struts lock ([`Lock`]).
    pub wire_contact: bool,
}

/// The radial bench's design of the design at `path` (module docs): [`bench_design`] with [`Test::Radial`].
///
/// # Errors
/// As [`bench_design`].
pub fn radial_design(
    path: &Path,
    overrides: &DesignOverrides,
) -> Result<(Design, Bench), BenchError> {
    bench_design(Test::Radial, path, overrides)
}

/// The design of `test` on the design at `path` with the command's `overrides` (module docs), and the bench
/// with its defaults resolved.
///
/// # Errors
/// [`BenchError::Design`] for a design or an override refused (located in the file), [`BenchError::Unfit`] for
/// a design without a generated stent, a temperature field, a crush of a curved device, or a smallest size at
/// or above the device's.
pub fn bench_design(
    test: Test,
    path: &Path,
    overrides: &DesignOverrides,
) -> Result<(Design, Bench), BenchError> {
    // `--set contact…` tunes the tool's contact: a design without obstacles has no contact to tune until the
    // bench's programme brings its tool, so those come after the bench's own overrides.
    let (contact, others): (Vec<SetOverride>, Vec<SetOverride>) = overrides
        .sets
        .iter()
        .cloned()
        .partition(|s| s.path.first() == Some(&crate::design::PathStep::Key("contact".into())));
    let overrides = &DesignOverrides {
        sets: others,
        ..overrides.clone()
    };
    let design = load_design_with(path, overrides)?;
    let unfit = |message: String| BenchError::Unfit {
        file: path.to_path_buf(),
        message,
    };
    let has_stent = serde_yaml::from_str::<serde_yaml::Value>(&design.source)
        .ok()
        .is_some_and(|v| v.get("stent").is_some());
    if !has_stent {
        return Err(unfit(format!(
            "the {} bench closes on a generated stent (a `stent:` block); this design has none",
            test.name()
        )));
    }
    if design.model.temperature_field.is_some() {
        return Err(unfit(format!(
            "the {} bench holds the device at one temperature (`bench.temperature`): a design with a \
             `temperature_field` cannot be put on it as it is; remove the field",
            test.name()
        )));
    }
    let spec = design.bench;
    let units = design.model.units;
    let per_mm = match units {
        Units::Si => 1e-3,
        Units::MmNMpa => 1.0,
    };
    // A first tool closing by a negligible Δr tells the tool's geometry: its start distance from the axis (2 %
    // clear of the device) and `R + d/2` (its closed distance plus that Δr), from which any smallest size
    // follows.
    let probe = 1e-9 * per_mm;
    let first = with_sets(
        path,
        overrides,
        &bench_sets(test, spec.segments, probe, 1.0, 1.0, DEFAULT_TEMPERATURE),
        &contact,
    )?;
    let distance = tool_distance(&first.model)
        .ok_or_else(|| unfit(format!("the {} programme built no tool", test.programme())))?;
    let (start, reach) = (distance(0.0), distance(1.0) + probe);
    let min_diameter = match (test, spec.min_diameter, spec.min_gap) {
        (Test::Radial, Some(d), _) | (Test::Crush, _, Some(d)) => d,
        (Test::Crush, _, None) => reach,
        (Test::Radial, None, _) => match design.model.programme.as_ref().map(|p| p.kind) {
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
        let field = match test {
            Test::Radial => "bench.min_diameter: the crimper would close to",
            Test::Crush => "bench.min_gap: the plates would close to",
        };
        return Err(unfit(format!(
            "{field} {min_diameter} {}, which must lie between the wire's diameter {wire} and the tool's start \
             {:.4} (2 % clear of the device)",
            units.length(),
            2.0 * start
        )));
    }
    let rate = spec.rate.unwrap_or(DEFAULT_RATE_MM_PER_S * per_mm);
    let temperature = spec.temperature.unwrap_or(DEFAULT_TEMPERATURE);
    let closing = (2.0 * start - min_diameter) / rate;
    let diameters = spec
        .diameters
        .unwrap_or(if first.model.wire_contact.is_some() {
            DEFAULT_DIAMETERS_WITH_WIRES
        } else {
            DEFAULT_DIAMETERS
        });
    let sets = bench_sets(
        test,
        spec.segments,
        reach - 0.5 * min_diameter,
        closing,
        closing / (diameters - 1) as Real,
        temperature,
    );
    let bench_design = with_sets(path, overrides, &sets, &contact)?;
    let model = &bench_design.model;
    let bench = Bench {
        test,
        temperature,
        rate,
        start_diameter: 2.0 * start,
        outer_diameter: 2.0 * start / crate::model::stent::TOOL_CLEARANCE,
        min_diameter,
        vessel_diameter: spec.vessel_diameter.or_else(|| vessel_diameter(model)),
        diameters,
        closing,
        length: device_length(model),
        copies: (2.0 as Real).powi(model.symmetry_planes.len() as i32),
        units,
        wire_contact: model.wire_contact.is_some(),
    };
    Ok((bench_design, bench))
}

/// The design at `path` with the command's `overrides`, then the bench's `sets`, then the command's `after`.
fn with_sets(
    path: &Path,
    overrides: &DesignOverrides,
    sets: &[String],
    after: &[SetOverride],
) -> Result<Design, BenchError> {
    let mut all = overrides.clone();
    for s in sets {
        all.sets
            .push(s.parse::<SetOverride>().map_err(|e| BenchError::Unfit {
                file: path.to_path_buf(),
                message: format!("the bench's own override was refused: {e}"),
            })?);
    }
    all.sets.extend_from_slice(after);
    // The design refused what the bench set (its tool, its temperature, its time): say so in the bench's words,
    // not as an override the user did not give.
    load_design_with(path, &all).map_err(|e| match e {
        DesignError::Override {
            argument,
            field,
            message,
            ..
        } if sets.contains(&argument) => BenchError::Unfit {
            file: path.to_path_buf(),
            message: format!("the bench cannot be set up on this design: {field}: {message}"),
        },
        e => e.into(),
    })
}

/// The bench's overrides of a design (module docs): the test's tool (a radial bench's crimper of `segments`
/// segments if given) closing by `delta_r` over `closing` and opening over as long, fixed steps of `step`, the
/// temperature held, no other obstacle.
fn bench_sets(
    test: Test,
    segments: Option<usize>,
    delta_r: Real,
    closing: Real,
    step: Real,
    temperature: Real,
) -> Vec<String> {
    let segments = match (test, segments) {
        (Test::Radial, Some(n)) => format!(", segments: {n}"),
        _ => String::new(),
    };
    vec![
        format!(
            "programme={{kind: {}, nodes: all_joints, delta_r: {delta_r:e}, ramp: [0, {closing:e}], release: {closing:e}, open: {closing:e}{segments}}}",
            test.programme()
        ),
        format!("temperature={temperature:e}"),
        "obstacles=[]".into(),
        format!("time={{end: {:e}, step: {step:e}}}", 2.0 * closing),
    ]
}

/// The tool of a crimp or crush programme's model: its obstacles (the last ones, from the programme's first).
fn tool(model: &Model) -> Option<&[crate::model::Obstacle]> {
    let (first, _) = model.programme.as_ref()?.kind.tool()?;
    model.contact.as_ref()?.obstacles.get(first..)
}

/// The tool's distance from the axis as a function of time: a crimper's radius (a cylinder's, or the scale
/// of a tube of radius 1 around a curved axis), a plate's distance from the axis plane between the plates.
fn tool_distance(model: &Model) -> Option<impl Fn(Real) -> Real + '_> {
    let first = tool(model)?.first()?;
    let axis_point = model.programme.as_ref()?.nodes.first()?.axis_point;
    let distance: Box<dyn Fn(Real) -> Real + '_> = match &first.surface {
        Surface::Cylinder { radius, .. } => Box::new(move |t| radius.value(t)),
        Surface::Lumen(tube) => Box::new(move |t| tube.scale().value(t)),
        Surface::Plane {
            point,
            normal,
            offset,
        } => {
            let start = (point - axis_point).dot(normal).abs();
            Box::new(move |t| start - offset.value(t))
        }
    };
    Some(distance)
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

/// The device's length along its axis: the extent of its wires' sample points along the axis of a straight
/// crimper (or of the driven nodes' axis, for plates), or along the centreline of a curved crimper's tube
/// (between the points' closest parameters).
fn device_length(model: &Model) -> Real {
    let Some(first) = tool(model).and_then(|t| t.first()) else {
        return 0.0;
    };
    let points: Vec<Vec3> = model
        .patches
        .iter()
        .flat_map(|p| p.dense_points())
        .collect();
    let extent = |values: &mut dyn Iterator<Item = Real>| {
        values.fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s), hi.max(s))
        })
    };
    let along = |point: Vec3, axis: Vec3| {
        let (lo, hi) = extent(&mut points.iter().map(|x| (x - point).dot(&axis)));
        (hi - lo).max(0.0)
    };
    match &first.surface {
        Surface::Cylinder { point, axis, .. } => along(*point, *axis),
        Surface::Plane { .. } => match model.programme.as_ref().and_then(|p| p.nodes.first()) {
            Some(node) => along(node.axis_point, node.axis_direction.normalize()),
            None => 0.0,
        },
        Surface::Lumen(tube) => {
            let (lo, hi) = extent(&mut points.iter().filter_map(|x| tube.closest(x, None)));
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
    }
}
/// Closing or opening.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Branch {
    /// The tool closes: the radial resistive force, the crush force.
    Loading,
    /// The tool opens: the chronic outward force, the force of the device's spring-back.
    Unloading,
}

impl Branch {
    /// The name in the bench's table.
    pub fn name(self) -> &'static str {
        match self {
            Branch::Loading => "loading",
            Branch::Unloading => "unloading",
        }
    }
}

/// One recorded size of a bench run (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BenchPoint {
    /// Time \[time\].
    pub time: Real,
    /// Closing or opening (the smallest size is the last of the loading branch and the first of the unloading
    /// one).
    pub branch: Branch,
    /// The crimper's diameter or the plates' gap \[length\].
    pub diameter: Real,
    /// The radial force on the whole device, or the force on one plate \[force\].
    pub force: Real,
    /// Points of the model in contact with the tool.
    pub points: usize,
}

impl Bench {
    /// The recorded sizes of a bench run from its `history.csv` text (module docs): each row's time, the tool's
    /// size from `model`'s (the bench design's) schedule, the force and points from the tool's columns. Rows
    /// after a cut one end the table (as a killed run's last line may be cut).
    pub fn points(&self, model: &Model, history: &str) -> Vec<BenchPoint> {
        let (Some(distance), Some(tool)) = (tool_distance(model), tool(model)) else {
            return Vec::new();
        };
        let history = crate::io::history::History::parse(history);
        // Per tool obstacle: its force on the rods per row (inward for a crimper, along the plate's normal),
        // and its points in contact.
        let mut columns = Vec::new();
        for obstacle in tool {
            let name = &obstacle.name;
            let force = match &obstacle.surface {
                Surface::Plane { normal, .. } => {
                    let axes = ["x", "y", "z"]
                        .map(|c| history.column(&format!("contact_force_{c}@{name}")));
                    let [Some(x), Some(y), Some(z)] = axes else {
                        return Vec::new();
                    };
                    x.iter()
                        .zip(&y)
                        .zip(&z)
                        .map(|((&(t, fx), &(_, fy)), &(_, fz))| {
                            (t, Vec3::new(fx, fy, fz).dot(normal))
                        })
                        .collect()
                }
                Surface::Cylinder { .. } | Surface::Lumen(_) => {
                    match history.column(&format!("contact_radial_force@{name}")) {
                        Some(f) => f,
                        None => return Vec::new(),
                    }
                }
            };
            let Some(points) = history.column(&format!("contact_points@{name}")) else {
                return Vec::new();
            };
            columns.push((force, points));
        }
        // The whole device's radial force; one plate's force (the plates of the whole device carry twice it).
        let share = match self.test {
            Test::Radial => self.copies,
            Test::Crush => 0.5 * self.copies,
        };
        let rows = columns
            .iter()
            .map(|(f, p)| f.len().min(p.len()))
            .min()
            .unwrap_or(0);
        let mut out = Vec::new();
        for row in 0..rows {
            let time = columns[0].0[row].0;
            let force: Real = columns.iter().map(|(f, _)| f[row].1).sum();
            let points: Real = columns.iter().map(|(_, p)| p[row].1).sum();
            let point = |branch| BenchPoint {
                time,
                branch,
                diameter: 2.0 * distance(time),
                // `+ 0.0`: no force is 0, not the −0 of a plate's `−0 · n`.
                force: share * force + 0.0,
                points: points as usize,
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

    /// The force `force` at size `diameter` per unit length \[force/length\] and as the equivalent pressure in
    /// kPa: on a cylinder of that diameter, `F / (π D L)`, or on the device's area projected on a plate,
    /// `F / (D L)`.
    pub fn per_length_and_pressure(&self, force: Real, diameter: Real) -> (Real, Real) {
        let kpa_per_stress = match self.units {
            Units::Si => 1e-3,
            Units::MmNMpa => 1e3,
        };
        let per_length = force / self.length;
        let area = match self.test {
            Test::Radial => std::f64::consts::PI * diameter * self.length,
            Test::Crush => diameter * self.length,
        };
        (per_length, force / area * kpa_per_stress)
    }

    /// The bench's table (`radial.csv`, `crush.csv`): one row per recorded size and branch (module docs).
    pub fn table(&self, points: &[BenchPoint]) -> String {
        let length = self.units.length();
        let (size, force) = match self.test {
            Test::Radial => ("diameter", "radial_force"),
            Test::Crush => ("gap", "crush_force"),
        };
        let mut out = format!(
            "time,branch,{size}_{length},{force}_N,force_per_length_N_per_{length},pressure_kPa,pressure_mmHg,points_in_contact\n"
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

    /// The force on `branch` at size `d`, linear between the recorded sizes; `None` outside them (by more than
    /// 1e-9 of the size: a reading at the smallest size, computed another way, lands on it to round-off).
    pub fn force_at(points: &[BenchPoint], branch: Branch, d: Real) -> Option<Real> {
        let branch: Vec<&BenchPoint> = points.iter().filter(|p| p.branch == branch).collect();
        branch.windows(2).find_map(|w| {
            let (a, b) = (w[0], w[1]);
            let (lo, hi) = (a.diameter.min(b.diameter), a.diameter.max(b.diameter));
            let slack = 1e-9 * hi.abs();
            if !(lo - slack <= d && d <= hi + slack) {
                return None;
            }
            if hi == lo {
                return Some(a.force);
            }
            Some(a.force + (b.force - a.force) * (d - a.diameter) / (b.diameter - a.diameter))
        })
    }

    /// The chart of both branches, force against size, the vessel's diameter dashed.
    pub fn chart(&self, points: &[BenchPoint]) -> LineChart {
        let length = self.units.length();
        let (what, size, labels) = match self.test {
            Test::Radial => (
                "radial force",
                "diameter",
                ["closing (RRF)", "opening (COF)"],
            ),
            Test::Crush => ("crush force", "plate gap", ["closing", "opening"]),
        };
        let mut chart = LineChart::new(
            format!(
                "{what} at {} °C, {} {length}/s",
                crate::math::Short(self.temperature),
                crate::math::Short(self.rate)
            ),
            format!("{size} ({length})"),
            format!("{what} (N)"),
        );
        for (branch, label) in [Branch::Loading, Branch::Unloading].into_iter().zip(labels) {
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

    /// Where the bench reads its forces: the vessel's diameter (named `vessel`) and, for a crush, 10 %, 25 % and
    /// 50 % of the device's outer diameter crushed (named `10%`, …), as `(name, size)`.
    fn reading_sizes(&self) -> Vec<(String, Real)> {
        let mut sizes = Vec::new();
        if self.test == Test::Crush {
            for f in CRUSH_READINGS {
                sizes.push((crush_reading_name(f), self.outer_diameter * (1.0 - f)));
            }
        }
        sizes.extend(self.vessel_diameter.map(|d| ("vessel".to_string(), d)));
        sizes
    }

    /// The bench's results from its recorded `points` (module docs) and the run's first touch of its wires
    /// (summary.json's `wire_touch`: time and where): what it prints and writes to `bench.json`.
    pub fn results(&self, points: &[BenchPoint], touch: Option<(Real, String)>) -> BenchResults {
        let reached = points
            .iter()
            .map(|p| p.diameter)
            .fold(Real::INFINITY, Real::min);
        // The tool's size at the step the wires first touched (a recorded row: each step has one) and at the
        // step before, when they did not yet.
        let touch = touch.and_then(|(time, place)| {
            let k = (0..points.len()).min_by(|&a, &b| {
                (points[a].time - time)
                    .abs()
                    .total_cmp(&(points[b].time - time).abs())
            })?;
            let p = points[k];
            Some(Touch {
                size: p.diameter,
                before: points[k.saturating_sub(1)].diameter,
                time,
                branch: p.branch,
                place,
            })
        });
        let lock = if self.wire_contact {
            touch.as_ref().and_then(|t| lock(points, t.time))
        } else {
            None
        };
        BenchResults {
            lock,
            touch,
            test: self.test,
            temperature: self.temperature,
            rate: self.rate,
            length: self.length,
            asked: self.min_diameter,
            reached: reached.is_finite().then_some(reached),
            readings: self
                .reading_sizes()
                .into_iter()
                .map(|(name, size)| Reading {
                    name,
                    size,
                    loading: Self::force_at(points, Branch::Loading, size),
                    unloading: Self::force_at(points, Branch::Unloading, size),
                })
                .collect(),
        }
    }

    /// What the bench prints at the end of its `results` ([`Bench::results`]): the smallest size reached and
    /// the forces at the vessel's diameter (and, for a crush, at 10 %, 25 % and 50 % of the outer diameter
    /// crushed).
    pub fn summary(&self, results: &BenchResults) -> Vec<String> {
        let length = self.units.length();
        let size = self.test.size();
        let mut lines = Vec::new();
        if let Some(reached) = results.reached {
            lines.push(format!(
                "smallest {size} reached: {reached:.4} {length} (asked {:.4} {length})",
                self.min_diameter
            ));
        }
        match &results.touch {
            Some(t) => lines.push(format!(
                "wires first touched in the step from {size} {:.4} to {:.4} {length} ({}, t = {}): {}; {}",
                t.before,
                t.size,
                match t.branch {
                    Branch::Loading => "closing",
                    Branch::Unloading => "opening",
                },
                t.time,
                t.place,
                if self.wire_contact {
                    "from there on they press on each other"
                } else {
                    "rod-on-rod contact is off (`contact: {wires: true}`), so past it they pass through each other"
                }
            )),
            None if results.reached.is_some() => {
                lines.push("wires never touched each other".into());
            }
            None => {}
        }
        if self.wire_contact && results.touch.is_some() {
            lines.push(match &results.lock {
                Some(l) => format!(
                    "struts lock at {size} {:.4} {length}: the force's stiffness there {:.4e} N/{length}, {:.1}× its mean {:.4e} N/{length} while closing before the wires touched",
                    l.size, l.stiffness, l.stiffness / l.before, l.before
                ),
                None => format!(
                    "the struts did not lock down to {size} {:.4} {length} (the force's stiffness never {LOCK_STIFFENING}× its mean before the wires touched)",
                    results.reached.unwrap_or(Real::NAN)
                ),
            });
        }
        if self.test == Test::Radial && self.vessel_diameter.is_none() {
            lines.push(
                "no vessel diameter (a vessel file's lumen, or `bench.vessel_diameter`): no COF read".into(),
            );
        }
        let whats = match self.test {
            Test::Radial => [
                "radial resistive force (closing)",
                "chronic outward force (opening)",
            ],
            Test::Crush => ["crush force (closing)", "crush force (opening)"],
        };
        for r in &results.readings {
            let at = match r.name.as_str() {
                "vessel" => "the vessel diameter".to_string(),
                fraction => format!("{} crushed, the gap", fraction.replace('%', " %")),
            };
            let d = r.size;
            for (force, what) in [r.loading, r.unloading].into_iter().zip(whats) {
                lines.push(match force {
                    Some(f) => {
                        let (per_length, kpa) = self.per_length_and_pressure(f, d);
                        format!(
                            "{what} at {at} {d:.4} {length}: {f:.4e} N, {per_length:.4e} N/{length}, {kpa:.4} kPa ({:.4} mmHg)",
                            kpa / KPA_PER_MMHG
                        )
                    }
                    None => format!("{what}: {at} {d:.4} {length} was not reached on this branch"),
                });
            }
        }
        lines
    }
}

/// What a bench found (`bench.json` in its run folder; `stentkit sweep --bench` reads it): the smallest size
/// the tool reached and the forces at the bench's readings.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BenchResults {
    /// The test.
    pub test: Test,
    /// Temperature \[°C\].
    pub temperature: Real,
    /// Rate of the tool's size \[length/time\].
    pub rate: Real,
    /// The device's length along its axis \[length\].
    pub length: Real,
    /// The smallest size asked \[length\].
    pub asked: Real,
    /// The smallest size reached \[length\] (`None`: nothing recorded).
    pub reached: Option<Real>,
    /// The forces at the readings.
    pub readings: Vec<Reading>,
    /// Where the device's wires first touched each other, if they did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub touch: Option<Touch>,
    /// Where the struts locked, with the wires' contact on and the tool closing past it ([`Lock`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lock: Option<Lock>,
}

/// The stiffening of the closing force that the bench calls struts locking: the secant stiffness `ΔF/ΔD`
/// between two recorded sizes at least this many times its mean between the tool's first touch of the device and
/// the wires' first touch of each other ([`lock`]).
pub const LOCK_STIFFENING: Real = 10.0;

/// Where the struts lock (module docs, *Where the wires touch*): the first recorded size on the closing branch,
/// after the wires touched, at which the tool's force has stiffened [`LOCK_STIFFENING`] times.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Lock {
    /// The tool's size \[length\].
    pub size: Real,
    /// The force's secant stiffness `ΔF/ΔD` over the step that ends there \[force/length\].
    pub stiffness: Real,
    /// Its mean while closing before the wires touched \[force/length\].
    pub before: Real,
}

/// The lock on the closing branch of `points`, the wires having first touched at time `touch` (module docs).
/// `None` when the tool had not touched the device before the wires touched each other, or the force did not
/// stiffen [`LOCK_STIFFENING`] times.
pub fn lock(points: &[BenchPoint], touch: Real) -> Option<Lock> {
    let closing: Vec<&BenchPoint> = (points.iter())
        .filter(|p| p.branch == Branch::Loading)
        .collect();
    let touched = closing
        .iter()
        .position(|p| p.time >= touch * (1.0 - 1e-12))?;
    let first = closing.iter().position(|p| p.force > 0.0)?;
    let last = touched.checked_sub(1).filter(|&k| k > first)?;
    let secant = |a: &BenchPoint, b: &BenchPoint| (b.force - a.force) / (a.diameter - b.diameter);
    let before = secant(closing[first], closing[last]);
    if !(before > 0.0) {
        return None;
    }
    closing[touched..].iter().enumerate().find_map(|(k, b)| {
        let stiffness = secant(closing[touched + k - 1], b);
        (stiffness >= LOCK_STIFFENING * before).then_some(Lock {
            size: b.diameter,
            stiffness,
            before,
        })
    })
}

/// The tool's size when the device's wires first touched each other (module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Touch {
    /// The tool's size at the end of the step in which the wires first touched \[length\].
    pub size: Real,
    /// The tool's size at the step's start, when they did not yet \[length\].
    pub before: Real,
    /// The time \[time\].
    pub time: Real,
    /// Closing or opening.
    pub branch: Branch,
    /// Where, in words (the two patches, the depth, the point).
    pub place: String,
}

/// The force on both branches at one size.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Reading {
    /// `vessel` (at the vessel's diameter) or a crush's `10%`, `25%`, `50%`.
    pub name: String,
    /// The size \[length\].
    pub size: Real,
    /// The force closing (RRF, crush force) \[force\]; `None` where the branch did not reach the size.
    pub loading: Option<Real>,
    /// The force opening (COF) \[force\].
    pub unloading: Option<Real>,
}

/// Adds the bench's table (`radial.csv`, `crush.csv`), chart (`charts/radial_force.svg`,
/// `charts/crush_force.svg`) and results ([`RESULTS_FILE`]) to the run folder `dir` of its run (listed in the folder's manifest, so `--force`
/// removes them with the run's files) and returns what the bench prints at the end ([`Bench::summary`]).
/// `model` is the bench design's.
///
/// # Errors
/// [`BenchError::Output`] when the folder cannot be taken again (another run holds it) or a file cannot be written.
pub fn write_outputs(dir: &Path, bench: &Bench, model: &Model) -> Result<Vec<String>, BenchError> {
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
    let name = bench.test.name();
    write(&format!("{name}.csv"), bench.table(&points).as_bytes())?;
    if !points.is_empty() {
        let svg = crate::io::chart::render_svg(&bench.chart(&points)).map_err(|e| fail(&e))?;
        std::fs::create_dir_all(dir.join(run_folder::CHARTS_FOLDER)).map_err(|e| fail(&e))?;
        write(&format!("charts/{name}_force.svg"), svg.as_bytes())?;
    }
    // The run's first touch of its wires, from its summary.json (written by the run before the bench's files).
    let touch = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
        .and_then(|v| {
            let t = &v["wire_touch"];
            Some((t["time"].as_f64()?, t["place"].as_str()?.to_string()))
        });
    let results = bench.results(&points, touch);
    let json = serde_json::to_string_pretty(&results).map_err(|e| fail(&e))?;
    write(RESULTS_FILE, json.as_bytes())?;
    Ok(bench.summary(&results))
}

#[cfg(test)]
mod tests {
    use super::{BenchPoint, Branch, LOCK_STIFFENING, lock};

    /// Closing points at diameters 20, 19, … with the forces `forces`, one time unit apart.
    fn closing(forces: &[f64]) -> Vec<BenchPoint> {
        (forces.iter().enumerate())
            .map(|(k, &force)| BenchPoint {
                time: k as f64,
                branch: Branch::Loading,
                diameter: 20.0 - k as f64,
                force,
                points: 0,
            })
            .collect()
    }

    /// Source: the definition (module docs). The tool touches the device at diameter 19 (force 0 at 20), the force
    /// grows by 1 per unit of diameter to the wires' touch at 16 (t = 4), then by 5 (below the threshold of 10),
    /// then by 12: the lock is the first size after the touch whose step's stiffness is 10× the mean 1 — 14 —
    /// and a force that stiffens only 5× never locks.
    #[test]
    fn the_lock_is_where_the_closing_force_first_stiffens_tenfold() {
        let points = closing(&[0.0, 1.0, 2.0, 3.0, 4.0, 9.0, 21.0, 33.0]);
        let found = lock(&points, 4.0).expect("a lock");
        assert_eq!(
            (found.size, found.stiffness, found.before),
            (14.0, 12.0, 1.0)
        );
        assert!(found.stiffness >= LOCK_STIFFENING * found.before);
        assert_eq!(
            lock(&closing(&[0.0, 1.0, 2.0, 3.0, 4.0, 9.0, 14.0]), 4.0),
            None
        );
        // Wires touching before the tool has pressed over a step leave no mean to compare with.
        assert_eq!(lock(&closing(&[0.0, 1.0, 20.0]), 1.0), None);
    }

    /// Source: the defaults' definitions. The straight stent's radial bench records 30 diameters per branch,
    /// and 120 when its wires touch each other (`contact.wires=true`, which the bench applies after its own
    /// settings); a design's own `bench.diameters` wins over both.
    #[test]
    fn the_bench_records_finer_diameters_when_the_wires_touch() {
        use super::{DEFAULT_DIAMETERS, DEFAULT_DIAMETERS_WITH_WIRES, radial_design};
        use crate::design::DesignOverrides;
        let design =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/straight_stent.yaml");
        let diameters = |sets: &[&str]| {
            let sets = sets.iter().map(|s| s.parse().expect("a --set")).collect();
            radial_design(&design, &DesignOverrides::sets(sets))
                .expect("the bench's design")
                .1
                .diameters
        };
        assert_eq!(diameters(&[]), DEFAULT_DIAMETERS);
        assert_eq!(
            diameters(&["contact.wires=true"]),
            DEFAULT_DIAMETERS_WITH_WIRES
        );
        assert_eq!(diameters(&["contact.wires=true", "bench.diameters=40"]), 40);
    }
}
