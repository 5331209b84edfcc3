//! Closed forms, published reference values and small helpers shared by the integration-test binaries
//! (`tests/stentkit`, `tests/convergence`). Each binary includes this file with
//! `#[path = "../common/mod.rs"] mod common;`.

// Each binary uses a different subset.
#![allow(dead_code)]

pub mod fixtures;

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use stentkit::design::parse_design;
use stentkit::math::{Real, Vec3};
use stentkit::model::{Model, ProbeLocation};
use stentkit::solver::{Observer, Simulation, StepReport};

/// A file of the repository, by its path relative to the crate root.
pub fn repo_file(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

/// The JSON document in the file `path` (a run's summary.json, a bench's bench.json).
pub fn read_json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The `(time, value)` pairs of a `history.csv` column.
pub fn history_column(history: &str, name: &str) -> Vec<(Real, Real)> {
    let mut lines = history.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let k = header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].parse().expect("time"), f[k].parse().expect("value"))
        })
        .collect()
}

/// The text of a design in `designs/`.
pub fn design_text(name: &str) -> String {
    let path = repo_file(&format!("designs/{name}"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Replaces the one line of `text` that starts with `prefix` (after indentation) by `line` (indentation kept).
/// Panics unless exactly one line matches, so a changed design file fails loudly instead of silently
/// testing something else.
#[track_caller]
pub fn replace_line(text: &str, prefix: &str, line: &str) -> String {
    let hits = text
        .lines()
        .filter(|l| l.trim_start().starts_with(prefix))
        .count();
    assert_eq!(hits, 1, "expected one line starting with `{prefix}`");
    text.lines()
        .map(|l| {
            if l.trim_start().starts_with(prefix) {
                let indent = &l[..l.len() - l.trim_start().len()];
                format!("{indent}{line}\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect()
}

/// `text` with every occurrence of `from` replaced by `to`, as `str::replace` does, but panics when `from` does
/// not occur: an edit of a design whose text has changed fails loudly instead of silently testing the unedited
/// design.
#[track_caller]
pub fn edit(text: &str, from: &str, to: &str) -> String {
    assert!(
        text.contains(from),
        "the text to replace is missing: `{from}`"
    );
    text.replace(from, to)
}

/// Removes every line that starts with `prefix` (after indentation); panics when none does.
#[track_caller]
pub fn remove_lines(text: &str, prefix: &str) -> String {
    let before = text.lines().count();
    let out: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with(prefix))
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(
        out.lines().count() < before,
        "no line starts with `{prefix}`"
    );
    out
}

/// Replaces the lines from the one starting with `from` (inclusive) up to the one starting with `to`
/// (exclusive) by `block`.
#[track_caller]
pub fn replace_block(text: &str, from: &str, to: &str, block: &str) -> String {
    let start = text
        .find(&format!("\n{from}"))
        .unwrap_or_else(|| panic!("no line starts with `{from}`"))
        + 1;
    let end = start
        + text[start..]
            .find(&format!("\n{to}"))
            .unwrap_or_else(|| panic!("no line starts with `{to}` after `{from}`"))
        + 1;
    format!("{}{block}{}", &text[..start], &text[end..])
}

/// Validates a design given as text (a panic names the problem).
#[track_caller]
pub fn model_from_text(text: &str, name: &str) -> Model {
    let design = parse_design(text, Path::new(name)).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert!(design.warnings.is_empty(), "{name}: {:?}", design.warnings);
    design.model
}

/// Index of the node called `name`.
#[track_caller]
pub fn node_index(model: &Model, name: &str) -> usize {
    model
        .nodes
        .iter()
        .position(|n| n.name == name)
        .unwrap_or_else(|| panic!("no node `{name}`"))
}

/// One converged step as seen by [`Recorder`].
#[derive(Debug, Clone)]
pub struct RecordedStep {
    /// The solver's report.
    pub report: StepReport,
    /// Wall time since the previous report (or the start of the run).
    pub wall: Duration,
}

/// An observer that keeps every step report and the wall time each step took.
#[derive(Debug, Default)]
pub struct Recorder {
    /// Every converged step.
    pub steps: Vec<RecordedStep>,
    last: Option<Instant>,
}

impl Observer for Recorder {
    fn start(&mut self, _: &Simulation<'_>) -> ControlFlow<()> {
        self.last = Some(Instant::now());
        ControlFlow::Continue(())
    }

    fn step(&mut self, _: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        let now = Instant::now();
        let wall = now - self.last.unwrap_or(now);
        self.last = Some(now);
        self.steps.push(RecordedStep {
            report: report.clone(),
            wall,
        });
        ControlFlow::Continue(())
    }
}

impl Recorder {
    /// Newton iterations (linear solves) of each step.
    pub fn iterations(&self) -> Vec<usize> {
        self.steps
            .iter()
            .map(|s| s.report.newton.iterations)
            .collect()
    }

    /// Total wall time of the recorded steps.
    pub fn wall(&self) -> Duration {
        self.steps.iter().map(|s| s.wall).sum()
    }

    /// Total Newton iterations.
    pub fn total_iterations(&self) -> usize {
        self.iterations().iter().sum()
    }

    /// Wall time per Newton iteration (assembly, factorisation, solve and update; the final residual
    /// assembly of each step included) [s].
    pub fn seconds_per_iteration(&self) -> Real {
        self.wall().as_secs_f64() / self.total_iterations().max(1) as Real
    }

    /// Step cuts over the run.
    pub fn cuts(&self) -> usize {
        self.steps.iter().map(|s| s.report.cuts).sum()
    }

    /// One line summarising iterations and timing.
    pub fn summary(&self) -> String {
        format!(
            "{} steps, {} cuts, Newton iterations per step {:?}, {:.3} ms per iteration, {:.1} ms in all",
            self.steps.len(),
            self.cuts(),
            self.iterations(),
            1e3 * self.seconds_per_iteration(),
            1e3 * self.wall().as_secs_f64()
        )
    }
}

/// Runs a model to its end time; returns the finished simulation and the record of its steps.
#[track_caller]
pub fn solve(model: &Model) -> (Simulation<'_>, Recorder) {
    let mut sim = Simulation::new(model).unwrap_or_else(|e| panic!("{}: {e}", model.name()));
    let mut recorder = Recorder::default();
    let summary = sim
        .run(&mut [&mut recorder])
        .unwrap_or_else(|e| panic!("{}: {e}", model.name()));
    assert!(!summary.stopped);
    (sim, recorder)
}

/// Displacement of node `name` in the simulation's current state.
pub fn node_displacement(sim: &Simulation<'_>, name: &str) -> Vec3 {
    let k = node_index(sim.model(), name);
    sim.probe_displacement(&ProbeLocation::Node(k))
}

/// Current position of the centreline of `patch` at curve parameter `u` (reference point plus displacement).
pub fn centreline_point(sim: &Simulation<'_>, patch: usize, u: Real) -> Vec3 {
    sim.model().patches[patch].curve.point(u)
        + sim.probe_displacement(&ProbeLocation::Patch { patch, u })
}

/// Least-squares slope of `log y` against `log x`.
pub fn log_log_slope(points: &[(Real, Real)]) -> Real {
    let m = points.len() as Real;
    let (lx, ly): (Vec<Real>, Vec<Real>) = points.iter().map(|&(x, y)| (x.ln(), y.ln())).unzip();
    let (mx, my) = (lx.iter().sum::<Real>() / m, ly.iter().sum::<Real>() / m);
    let sxy: Real = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: Real = lx.iter().map(|x| (x - mx).powi(2)).sum();
    sxy / sxx
}

// ---------------------------------------------------------------------------------------------------------
// Closed forms and published values.

/// Roll-up of a straight cantilever of length `length` along +x by an end couple `M = 2π EI / L` about +z:
/// with no force the rod neither stretches nor shears and its curvature is `M / EI = 2π / L` everywhere, so
/// the centreline is the full circle `c(s) = (R sin(s/R), R (1 − cos(s/R)), 0)`, `R = L / 2π`
/// (e.g. Simo & Vu-Quoc 1986, Part II, §7.1; Ibrahimbegović 1995).
pub fn rollup_centreline(s: Real, length: Real) -> Vec3 {
    let r = length / (2.0 * std::f64::consts::PI);
    Vec3::new(r * (s / r).sin(), r * (1.0 - (s / r).cos()), 0.0)
}

/// The 45° bend's reference tip position `(100 sin 45°, 100 (1 − cos 45°), 0)`.
pub fn bend45_reference_tip() -> Vec3 {
    let a = std::f64::consts::FRAC_PI_4;
    Vec3::new(100.0 * a.sin(), 100.0 * (1.0 - a.cos()), 0.0)
}

/// Bathe & Bolourchi (1979), "Large displacement analysis of three-dimensional beam structures", IJNME 14,
/// 961–986: tip position of the 45° bend under the tip load 600, eight 3-D beam elements.
pub const BATHE_BOLOURCHI_1979_TIP: [Real; 3] = [47.2, 15.9, 53.4];

/// Simo & Vu-Quoc (1986), "A three-dimensional finite-strain rod model. Part II: computational aspects",
/// CMAME 58, 79–116, §7.5: tip position of the 45° bend under the tip load 600, eight linear elements.
pub const SIMO_VU_QUOC_1986_TIP: [Real; 3] = [47.23, 15.79, 53.37];

/// The converged tip displacement of the 45° bend written by `scripts/bend45_reference.py` into
/// `tests/data/bend45_reference.txt` (line `tip displacement x y z`).
pub fn bend45_shooting_displacement() -> Vec3 {
    let path = repo_file("tests/data/bend45_reference.txt");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix("tip displacement"))
        .expect("a `tip displacement` line");
    let v: Vec<Real> = line
        .split_whitespace()
        .map(|x| x.parse().expect("a number"))
        .collect();
    assert_eq!(v.len(), 3);
    Vec3::new(v[0], v[1], v[2])
}

/// One span of a cantilever made of spans of different materials, from the clamp outwards: length `L`
/// [length], Young's modulus `E` [stress] and shear modulus times shear factor `k_s G` [stress].
#[derive(Debug, Clone, Copy)]
pub struct CantileverSpan {
    /// Length `L_i` [length].
    pub length: Real,
    /// Young's modulus `E_i` [stress].
    pub modulus: Real,
    /// `k_s G_i` [stress].
    pub shear_modulus: Real,
}

/// Tip deflection [length] of a straight cantilever of spans `spans` (clamp first) with a common section (area
/// `A`, second moment `I`) under a transverse tip force `P`, by linear Timoshenko beam theory (small
/// deflections; e.g. Timoshenko & Gere, *Mechanics of Materials*, §9 and §10.10, unit-load method):
/// `M(x) = P (L − x)`, `V = P`, and the unit-load integral gives
/// `δ = P Σ_i [ ((L − x_i)³ − (L − x_{i+1})³) / (3 E_i I) + L_i / (k_s G_i A) ]`
/// with `x_i` the start of span `i` and `L` the total length (for one span: `P L³/(3EI) + P L/(k_s G A)`).
pub fn cantilever_tip_deflection(
    spans: &[CantileverSpan],
    area: Real,
    inertia: Real,
    force: Real,
) -> Real {
    let total: Real = spans.iter().map(|s| s.length).sum();
    let mut x = 0.0;
    let mut deflection = 0.0;
    for s in spans {
        let (a, b) = (total - x, total - x - s.length);
        deflection += force * (a.powi(3) - b.powi(3)) / (3.0 * s.modulus * inertia)
            + force * s.length / (s.shear_modulus * area);
        x += s.length;
    }
    deflection
}

/// Tip elongation [length] of a bar of spans `spans` in series with a common area `A` under an axial tip force
/// `F`: `δ = F Σ_i L_i / (E_i A)` (the rod's axial strain is linear in `N`, so this is exact for it at any `F`
/// that leaves the bar straight).
pub fn series_bar_elongation(spans: &[CantileverSpan], area: Real, force: Real) -> Real {
    spans
        .iter()
        .map(|s| force * s.length / (s.modulus * area))
        .sum()
}

/// A Z-ring as the open-stent calculator sees it: `struts` straight struts of length `L` (crown centre to crown
/// centre) and bending stiffness `EI` in the plane of the unrolled pattern, parallel to the axis at the diameter
/// `crimp` (the tube they are cut from), made at the diameter `set`.
#[derive(Debug, Clone, Copy)]
pub struct OpenStentRing {
    /// Number of struts `N_struts`.
    pub struts: usize,
    /// Strut length `L_strut` [length].
    pub length: Real,
    /// Bending stiffness `E I` of a strut in the plane of the pattern [force·length²].
    pub bending: Real,
    /// Diameter at which the ring is made, `D_set` [length].
    pub set: Real,
    /// Diameter at which the struts are parallel, `D_crimp` [length].
    pub crimp: Real,
}

impl OpenStentRing {
    /// The strut angle to the axis at diameter `d` [rad]: `θ = asin(π (d − D_crimp) / (N L))` (the
    /// circumference beyond the tube's is shared by the `N` struts' circumferential spans `L sin θ`).
    pub fn strut_angle(&self, d: Real) -> Real {
        (std::f64::consts::PI * (d - self.crimp) / (self.struts as Real * self.length)).asin()
    }

    /// The total radial force [force] of the ring held at the diameter `d < D_set`, as the open-stent calculator
    /// computes it (C. Bonsignore, `stent-calculator.py`, 2010, github.com/cbonsig/open-stent: "Strut Angles
    /// and Deflections", "Force and Strain Calculations", "Pressure and Stiffness"). Each strut is a guided
    /// beam (one end clamped, the other free to translate but not to rotate; Machinery's Handbook, the
    /// calculator's source) whose crowns turn by `Δθ = θ_set − θ_d`, so its end moves across it by
    /// `δ = 2 L sin(Δθ/2)` and it carries `F = 12 E I δ / L³`; the calculator takes this force as the ring's
    /// hoop force (`F_hoop = F_total`) and the radial force of the ring as `2π F_hoop` (Laplace's law for a
    /// thin ring: its `RF_trf = 2π RF_hoop` per unit length). Transcribed from the formulas, not the code;
    /// the calculator's section property (Roark's annular sector for a laser-cut strut) is replaced by the
    /// caller's `EI`. Its assumptions: a flat pattern (the ring's curvature left out), straight struts joined
    /// by rigid crowns, slender Euler–Bernoulli struts, small strain, and `F_hoop = F` (the force across the
    /// strut taken as the hoop force, true as `θ → 0`).
    pub fn radial_force(&self, d: Real) -> Real {
        let turn = self.strut_angle(self.set) - self.strut_angle(d);
        let across = 2.0 * self.length * (turn / 2.0).sin();
        let hoop = 12.0 * self.bending * across / self.length.powi(3);
        2.0 * std::f64::consts::PI * hoop
    }
}
