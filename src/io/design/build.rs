//! From the deserialised design ([`super::dto`]) to a validated [`Model`]: geometry is generated, names are
//! resolved, and every check that involves more than one value is made here. A failed check is an [`Issue`]
//! naming the field path; [`super`] turns it into a line and column.

use super::dto::*;
pub use super::issue::Issue;
use super::issue::{FIT_WARNING_FRACTION, Result, issue};
use super::quote::quoted;
use super::stent;
use crate::geometry::analytic::{
    Helix, ParametricCurve, RigidPlacement, SineWire, frame_from_axis, point_list_curve,
};
use crate::geometry::fit::{FitSettings, fit_curve};
use crate::geometry::{GeometryError, primitives};
use crate::material::{
    CircularSection, Integrator, Material, MaterialError, Prony, PronyBranch, Section,
    SectionProperties, ShearFactor, Wlf,
};
use crate::math::{Mat3, NurbsCurve, Real, Vec3};
use crate::model::*;
use std::collections::{BTreeMap, HashMap};

/// Relative size of the default joint tolerance: ends closer than this fraction of the model's bounding-box
/// diagonal are the same point. Fits and exact primitives place shared ends to ~1e-14 relative, so 1e-8
/// separates coincident ends from distinct ones with a wide margin on both sides.
const DEFAULT_JOINT_TOLERANCE: Real = 1e-8;

/// Default smallest step, as a fraction of the nominal step: ten halvings.
const DEFAULT_MIN_STEP_FRACTION: Real = 1.0 / 1024.0;

fn vec3(v: &Vector) -> Vec3 {
    Vec3::new(v[0].0, v[1].0, v[2].0)
}

fn time_function(f: &TimeFn, path: &str) -> Result<TimeFunction> {
    match f {
        TimeFn::Constant(v) => Ok(TimeFunction::constant(*v)),
        TimeFn::Table(points) => {
            TimeFunction::try_table(points.clone()).map_err(|e| issue(path, e.to_string()))
        }
    }
}

/// A design built and validated by [`build`].
#[derive(Debug, Clone)]
pub struct Built {
    /// The model.
    pub model: Model,
    /// Snapshot and recording settings.
    pub output: super::OutputSettings,
    /// Things worth knowing that do not stop a run.
    pub warnings: Vec<String>,
    /// The memory the run is estimated to need (below [`MEMORY_LIMIT_BYTES`]).
    pub memory: MemoryEstimate,
    /// The steps the run takes when no step is cut ([`Model::planned_steps`]).
    pub steps: StepPlan,
}

/// Builds and validates the model; returns it with the output settings, the warnings found and the memory
/// estimate.
pub fn build(dto: &DesignDto, default_name: &str) -> Result<Built> {
    let mut warnings = Vec::new();
    if let Some(v) = dto.version
        && v != 1
    {
        return Err(issue(
            "version",
            format!("version {v} is not supported; allowed: 1"),
        ));
    }
    let name = match &dto.name {
        Some(name) => {
            check_name(name).map_err(|why| {
                issue(
                    "name",
                    format!(
                        "{} is not a valid design name ({why}): {NAME_RULE}",
                        quoted(name)
                    ),
                )
            })?;
            name.clone()
        }
        None => {
            check_name(default_name).map_err(|why| {
                issue(
                    "name",
                    format!(
                        "the design has no `name`, and its file name gives {} ({why}): add `name:`; {NAME_RULE}",
                        quoted(default_name)
                    ),
                )
            })?;
            default_name.to_string()
        }
    };
    let units = match dto.units {
        UnitsDto::Si => Units::Si,
        UnitsDto::MmNMpa => Units::MmNMpa,
    };
    let (material, integrator) = material(&dto.material)?;
    let (section, shear_factor) = section(&dto.section)?;
    // Before any geometry is generated: a size that would exhaust memory is refused with an estimate (with the
    // nominal steps; the steps landing on breakpoints are counted once the model exists, below).
    check_size(dto, &StepCount::nominal(&time_settings(&dto.time)?))?;
    let mut sections = vec![section];
    // A generated stent's patches and nodes come first; its node sets index the model's nodes.
    let stent = match &dto.stent {
        Some(s) => Some(stent::generate(
            s,
            dto.mesh.as_ref(),
            &mut sections,
            material.poisson(),
            &mut warnings,
        )?),
        None => None,
    };
    let generated = stent.as_ref().map_or_else(Vec::new, |s| s.patches.clone());
    let patches = patches(dto, generated, &mut sections, shear_factor, &mut warnings)?;
    let tolerance = joint_tolerance(dto, &patches);
    let initial = stent.as_ref().map_or_else(Vec::new, |s| s.nodes.clone());
    let mut nodes = nodes(dto, &patches, tolerance, initial)?;
    let node_sets = stent.as_ref().map_or_else(BTreeMap::new, stent::node_sets);
    let symmetry_planes = stent.as_ref().map_or_else(Vec::new, stent::symmetry_planes);
    // Components set by the stent's symmetry planes and the programme, which `conditions` must not override.
    let mut preset: HashMap<(usize, usize), String> = HashMap::new();
    if let Some(s) = &stent {
        for (k, g) in s.geometry.nodes.iter().enumerate() {
            if g.symmetry_plane.is_some() {
                for i in [0, 4, 5] {
                    preset.insert((k, i), "the stent's symmetry plane".into());
                }
            }
        }
    }
    let programme = match &dto.programme {
        Some(p) => {
            let end = time_settings(&dto.time)?.end;
            let programme = stent::programme(p, stent.as_ref(), &mut nodes, end, &mut warnings)?;
            for d in &programme.nodes {
                for i in 0..3 {
                    preset
                        .entry((d.node, i))
                        .or_insert_with(|| "the programme".into());
                }
            }
            Some(programme)
        }
        None => None,
    };
    conditions(dto, &patches, &mut nodes, &node_sets, &preset)?;
    let distributed_loads = distributed_loads(dto, &patches)?;
    let temperature = match (&dto.temperature, material.wlf()) {
        (Some(f), _) => time_function(f, "temperature")?,
        (None, None) => TimeFunction::constant(20.0),
        (None, Some(_)) => {
            return Err(issue(
                "temperature",
                "missing: a material with `wlf` needs a temperature schedule (a number or [[t, T], …] in °C)",
            ));
        }
    };
    if let Some(w) = material.wlf() {
        let freeze = w.frozen_below();
        let (lo, _) = temperature.range();
        if lo <= freeze {
            warnings.push(format!(
                "temperature reaches {lo} °C, at or below the WLF singularity Tg − C2 = {freeze} °C: relaxation freezes there (instantaneous moduli)"
            ));
        }
    }
    let time = time_settings(&dto.time)?;
    let solver = solver_settings(dto.solver.as_ref())?;
    let probes = probes(dto, &patches, &nodes)?;
    let mut output = output_settings(dto.output.as_ref(), &time)?;
    let record_times = output
        .snapshots
        .times
        .iter()
        .copied()
        .filter(|&t| t > 0.0)
        .collect();
    let model = Model {
        name,
        units,
        // The design's one material, used by every patch (`Patch::material` 0).
        materials: vec![crate::material::MaterialLaw::from_material(
            material, integrator,
        )],
        sections,
        patches,
        nodes,
        distributed_loads,
        temperature,
        time,
        solver,
        probes,
        node_sets,
        programme,
        symmetry_planes,
        record_times,
    };
    // The steps the run takes, landing on every breakpoint: refused if their memory is too much, and the
    // default snapshot spacing follows them.
    let plan = model.planned_steps();
    let memory = check_size(dto, &StepCount::planned(&plan, model.time.step, dto))?;
    if dto
        .output
        .as_ref()
        .and_then(|o| o.snapshots.as_ref())
        .and_then(|s| s.every)
        .is_none()
    {
        output.snapshots.every = plan
            .total()
            .div_ceil(super::SnapshotSettings::DEFAULT_COUNT);
    }
    // A part no condition holds can move as a rigid body: `run` refuses it (the solver's check), `check` warns.
    for body in crate::solver::diagnose::free_bodies(&model) {
        let names: Vec<String> = body
            .patches
            .iter()
            .map(|&k| quoted(&model.patches[k].name))
            .collect();
        warnings.push(format!(
            "no component of any node of patch{} {} is prescribed: {} free to move as a rigid body, the tangent is singular and `run` will refuse the design",
            if names.len() == 1 { "" } else { "es" },
            names.join(", "),
            if names.len() == 1 { "it is" } else { "they are" }
        ));
    }
    Ok(Built {
        model,
        output,
        warnings,
        memory,
        steps: plan,
    })
}

/// Longest design name [bytes]: the name is the run folder's name (`runs/<name>`), and 255 bytes is the
/// longest file name of the usual file systems (ext4, XFS, Btrfs, APFS).
pub const MAX_NAME_BYTES: usize = 255;

/// What a design name may be, as the errors say it.
const NAME_RULE: &str = "a name becomes the run folder `runs/<name>`, so it must be one folder name: not empty, not `.` or `..`, at most 255 bytes, without `/`, `\\` or control characters";

/// Why `name` cannot be a run folder's name, if it cannot: a single normal path component on every platform
/// (no separator, no `.` or `..`, no absolute path or drive prefix), without control characters.
fn check_name(name: &str) -> std::result::Result<(), String> {
    if name.is_empty() {
        return Err("it is empty".into());
    }
    if name == "." || name == ".." {
        return Err("it names a folder itself, not a new one".into());
    }
    if let Some(c) = name.chars().find(|&c| c == '/' || c == '\\') {
        return Err(format!("it contains `{c}`, a path separator"));
    }
    if let Some(c) = name.chars().find(|c| c.is_control()) {
        return Err(format!(
            "it contains the control character {}",
            c.escape_debug()
        ));
    }
    if name.len() > MAX_NAME_BYTES {
        return Err(format!("it has {} bytes", name.len()));
    }
    // Whatever the platform adds (a Windows drive prefix such as `C:`): one normal component, itself.
    let mut components = std::path::Path::new(name).components();
    match (components.next(), components.next()) {
        (Some(std::path::Component::Normal(c)), None) if c == name => Ok(()),
        _ => Err("it is not a plain folder name on this system".into()),
    }
}

/// Memory a design may need before it is refused [bytes]: 8 GB. The estimate ([`estimated_memory`]) is
/// checked before any geometry is generated, so that a typo (`n: 100000000`, `step: 1e-12`) gets an error
/// naming the field and the estimate instead of exhausting the machine. The paper's curved stent needs about
/// 0.1 GB; 8 GB leaves two orders of magnitude for refined studies while staying below the memory of a
/// typical workstation.
pub const MEMORY_LIMIT_BYTES: Real = 8e9;

/// Estimated bytes per control point of degree `p` with `branches` Maxwell branches: the tangent's entries
/// (6 rows × 6(p+1) columns, each with its pattern, slot and value: ~48 bytes) and its LU factors (banded
/// fill of about twice the entries, value and index: ~16 bytes each), plus the state and the history at the
/// collocation point (strains and their s-derivatives per branch, ~200 bytes each) and ~1 kB of basis
/// tables and state.
fn bytes_per_control_point(p: usize, branches: usize) -> Real {
    let width = 36.0 * (p as Real + 1.0);
    width * 48.0 + 2.0 * width * 16.0 + 200.0 * branches as Real + 1000.0
}

/// Estimated bytes kept per time step (the chart and summary samples with the probes' displacements and the
/// residual history), with `probes` probes. Measured: the 45° bend (one probe) peaks at 12.6 MB over 10⁴
/// steps and 55.1 MB over 10⁵, 470 bytes per step against 536 here.
fn bytes_per_step(probes: usize) -> Real {
    512.0 + 24.0 * probes as Real
}

/// One contribution to the memory a design needs.
#[derive(Debug, Clone, PartialEq)]
pub struct MemoryTerm {
    /// The field that sets it (`patches[2].n`, `time.step`, `temperature`, …).
    pub field: String,
    /// What it is, in words.
    pub what: String,
    /// Bytes.
    pub bytes: Real,
}

/// The memory a design is estimated to need ([`estimated_memory`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MemoryEstimate {
    /// The contributions.
    pub terms: Vec<MemoryTerm>,
}

impl MemoryEstimate {
    /// All contributions [bytes] (NaN if one is).
    pub fn total(&self) -> Real {
        self.terms.iter().map(|t| t.bytes).sum()
    }

    /// The largest contribution.
    pub fn largest(&self) -> Option<&MemoryTerm> {
        self.terms.iter().max_by(|a, b| a.bytes.total_cmp(&b.bytes))
    }
}

/// The time steps a memory estimate charges, with the field that makes them as many.
#[derive(Debug, Clone, PartialEq)]
pub struct StepCount {
    /// Number of steps (floating point: a typo's count may not fit an integer).
    pub steps: Real,
    /// The field charged: `time.step`, or the schedule whose breakpoints make most of the steps.
    pub field: String,
    /// The count in words.
    pub what: String,
}

impl StepCount {
    /// The nominal steps `end / step`, charged to `time.step` (known before the model is built).
    pub fn nominal(time: &TimeSettings) -> Self {
        let steps = time.end / time.step;
        Self {
            steps,
            field: "time.step".to_string(),
            what: format!("{steps:.3e} time steps"),
        }
    }

    /// The steps the run takes (`plan`, [`Model::planned_steps`] with nominal step `step`): charged to
    /// `time.step` unless the steps shortened to land on breakpoints outnumber the full ones, then to the
    /// schedule with the most breakpoints.
    pub fn planned(plan: &StepPlan, step: Real, dto: &DesignDto) -> Self {
        // The schedules are walked only when they make most of the steps.
        let field = (plan.shortened > plan.full)
            .then(|| busiest_schedule(dto))
            .flatten()
            .unwrap_or_else(|| "time.step".to_string());
        Self {
            steps: plan.total() as Real,
            what: format!(
                "{} time steps ({} of {} + {} shortened to land on breakpoints)",
                plan.total(),
                plan.full,
                step,
                plan.shortened
            ),
            field,
        }
    }
}

/// The field of the design's time table with the most points (`temperature`, `conditions[0].force[2]`,
/// `output.snapshots.times`, …), if any has more than one.
fn busiest_schedule(dto: &DesignDto) -> Option<String> {
    let table = |f: &TimeFn| match f {
        TimeFn::Table(points) => points.len(),
        TimeFn::Constant(_) => 1,
    };
    let mut tables: Vec<(String, usize)> = Vec::new();
    if let Some(f) = &dto.temperature {
        tables.push(("temperature".into(), table(f)));
    }
    for (k, c) in dto.conditions.iter().enumerate() {
        for (field, values) in [
            ("displacement", &c.displacement),
            ("rotation", &c.rotation),
            ("force", &c.force),
            ("moment", &c.moment),
        ] {
            for (i, v) in values.iter().flatten().enumerate() {
                if let ComponentValue::Value(f) = v {
                    tables.push((format!("conditions[{k}].{field}[{i}]"), table(f)));
                }
            }
        }
    }
    for (k, d) in dto.distributed_loads.iter().enumerate() {
        for (field, values) in [("force", &d.force), ("couple", &d.couple)] {
            for (i, f) in values.iter().flatten().enumerate() {
                tables.push((format!("distributed_loads[{k}].{field}[{i}]"), table(f)));
            }
        }
    }
    if let Some(times) = dto
        .output
        .as_ref()
        .and_then(|o| o.snapshots.as_ref())
        .and_then(|s| s.times.as_ref())
    {
        tables.push(("output.snapshots.times".into(), times.len()));
    }
    tables
        .into_iter()
        .filter(|t| t.1 > 1)
        .max_by_key(|t| t.1)
        .map(|t| t.0)
}

/// The contributions to the memory a design needs, each with the field that sets it. Computed from the
/// deserialised design (degree and size of every patch, the stent's patch count, the snapshot mesh size) and
/// the number of time steps `steps` (nominal before the model exists, [`StepCount::planned`] after), in
/// floating point so that absurd sizes do not overflow.
pub fn estimated_memory(dto: &DesignDto, steps: &StepCount) -> MemoryEstimate {
    let branches = dto.material.prony.len();
    let mesh = dto.mesh.as_ref();
    // (path, what, bytes, patches)
    let mut terms: Vec<(String, String, Real, Real)> = Vec::new();
    let mut patches: Real = 0.0;
    for (k, pd) in dto.patches.iter().enumerate() {
        let (Some(p), Some(n)) = (
            pd.p.or(mesh.and_then(|m| m.p)),
            pd.n.or(mesh.and_then(|m| m.n)),
        ) else {
            continue;
        };
        let path = if pd.n.is_some() {
            format!("patches[{k}].n")
        } else {
            "mesh.n".to_string()
        };
        patches += 1.0;
        terms.push((
            path,
            format!("patch {} ({n} control points, p = {p})", quoted(&pd.name)),
            n as Real * bytes_per_control_point(p, branches),
            1.0,
        ));
    }
    if let Some(s) = &dto.stent {
        let sector = match s.symmetry {
            _ if s.full_model => 1.0,
            None | Some(SymmetryDto::None) => 1.0,
            Some(SymmetryDto::Half) => 2.0,
            Some(SymmetryDto::Quarter) => 4.0,
        };
        let (crowns, peaks) = (s.crowns as Real, s.peaks as Real);
        let every = s
            .bridges
            .as_ref()
            .map_or(0.0, |b| 1.0 / b.every.unwrap_or(1).max(1) as Real);
        let pick = |own: Option<&MeshDto>| {
            let p = own.and_then(|m| m.p).or(mesh.and_then(|m| m.p));
            let n = own.and_then(|m| m.n).or(mesh.and_then(|m| m.n));
            p.zip(n)
        };
        let crown_patches = crowns * 2.0 * peaks / sector;
        let bridge_patches = (crowns - 1.0).max(0.0) * peaks * every / sector;
        patches += crown_patches + bridge_patches;
        for (count, pn, what) in [
            (crown_patches, pick(s.crown_mesh.as_ref()), "crown wires"),
            (bridge_patches, pick(s.bridge_mesh.as_ref()), "bridges"),
        ] {
            if let Some((p, n)) = pn
                && count > 0.0
            {
                let path = if crowns * peaks > 1e4 {
                    "stent.crowns"
                } else if what == "bridges" && s.bridge_mesh.is_some() {
                    "stent.bridge_mesh.n"
                } else if what == "crown wires" && s.crown_mesh.is_some() {
                    "stent.crown_mesh.n"
                } else {
                    "mesh.n"
                };
                terms.push((
                    path.to_string(),
                    format!("about {count:.0} stent {what} of {n} control points (p = {p})"),
                    count * n as Real * bytes_per_control_point(p, branches),
                    count,
                ));
            }
        }
    }
    let patch_terms = terms.len();
    let probes = dto.output.as_ref().map_or(0, |o| o.probes.len());
    terms.push((
        steps.field.clone(),
        steps.what.clone(),
        steps.steps * bytes_per_step(probes),
        0.0,
    ));
    // Snapshot meshes: up to four mirrored copies of every patch; a vertex (24 bytes) and two triangles
    // (24 bytes) per ring segment. Charged to `rings` or `segments` when the design sets them, otherwise to
    // the patches themselves.
    let snapshots = dto.output.as_ref().and_then(|o| o.snapshots.as_ref());
    let segments = snapshots.and_then(|s| s.segments);
    let rings = snapshots.and_then(|s| s.rings);
    let per_patch = 4.0
        * rings.unwrap_or(super::SnapshotSettings::DEFAULT_RINGS) as Real
        * segments.unwrap_or(super::SnapshotSettings::DEFAULT_SEGMENTS) as Real
        * 48.0;
    match (rings, segments) {
        (None, None) => {
            for term in &mut terms[..patch_terms] {
                term.2 += term.3 * per_patch;
            }
        }
        (r, s) => {
            let path = if r.unwrap_or(0) >= s.unwrap_or(0) {
                "output.snapshots.rings"
            } else {
                "output.snapshots.segments"
            };
            terms.push((
                path.to_string(),
                "snapshot meshes".to_string(),
                patches * per_patch,
                0.0,
            ));
        }
    }
    MemoryEstimate {
        terms: terms
            .into_iter()
            .map(|(field, what, bytes, _)| MemoryTerm { field, what, bytes })
            .collect(),
    }
}

/// `1.2 GB`-style size.
pub fn human_bytes(bytes: Real) -> String {
    if bytes >= 1e15 {
        format!("{bytes:.1e} bytes")
    } else if bytes >= 1e12 {
        format!("{:.0} TB", bytes / 1e12)
    } else if bytes >= 1e9 {
        format!("{:.1} GB", bytes / 1e9)
    } else if bytes >= 1e8 {
        format!("{:.0} MB", bytes / 1e6)
    } else if bytes >= 1e6 {
        format!("{:.1} MB", bytes / 1e6)
    } else if bytes >= 1e3 {
        format!("{:.0} kB", bytes / 1e3)
    } else {
        format!("{bytes:.0} B")
    }
}

/// The [`estimated_memory`] for `steps`; refused when above [`MEMORY_LIMIT_BYTES`], naming the field of the
/// largest contribution.
fn check_size(dto: &DesignDto, steps: &StepCount) -> Result<MemoryEstimate> {
    let estimate = estimated_memory(dto, steps);
    let total = estimate.total();
    if (total.is_nan() || total > MEMORY_LIMIT_BYTES)
        && let Some(term) = estimate.largest()
    {
        return Err(issue(
            &term.field,
            format!(
                "this design would need about {} of memory ({}: {}), more than stentkit's limit of {}: reduce it",
                human_bytes(total),
                term.what,
                human_bytes(term.bytes),
                human_bytes(MEMORY_LIMIT_BYTES)
            ),
        ));
    }
    Ok(estimate)
}

/// The `output:` block's snapshot and recording settings, with their defaults.
fn output_settings(
    output: Option<&OutputDto>,
    time: &TimeSettings,
) -> Result<super::OutputSettings> {
    use super::{OutputSettings, RecordingSettings, SnapshotSettings};
    let at_least = |value: Option<usize>, default: usize, min: usize, path: &str| match value {
        None => Ok(default),
        Some(v) if v >= min => Ok(v),
        Some(v) => Err(issue(path, format!("{v} must be at least {min}"))),
    };
    let snapshots = output.and_then(|o| o.snapshots.as_ref());
    let mut times = Vec::new();
    for (k, NonNegative(t)) in snapshots
        .and_then(|s| s.times.as_ref())
        .into_iter()
        .flatten()
        .enumerate()
    {
        if *t > time.end {
            return Err(issue(
                format!("output.snapshots.times[{k}]"),
                format!(
                    "{t} is after the end of the run (time.end = {}); allowed: 0 ≤ t ≤ time.end",
                    time.end
                ),
            ));
        }
        times.push(*t);
    }
    times.sort_by(Real::total_cmp);
    times.dedup();
    let snapshot_settings = SnapshotSettings {
        times,
        // The default (about DEFAULT_COUNT over the run) is set by `build` once the steps are planned.
        every: snapshots.and_then(|s| s.every).unwrap_or(0),
        segments: at_least(
            snapshots.and_then(|s| s.segments),
            SnapshotSettings::DEFAULT_SEGMENTS,
            3,
            "output.snapshots.segments",
        )?,
        rings: at_least(
            snapshots.and_then(|s| s.rings),
            SnapshotSettings::DEFAULT_RINGS,
            2,
            "output.snapshots.rings",
        )?,
    };
    let recording = output.and_then(|o| o.recording.as_ref());
    let recording_settings = RecordingSettings {
        centreline_points: at_least(
            recording.and_then(|r| r.centreline_points),
            RecordingSettings::DEFAULT_CENTRELINE_POINTS,
            2,
            "output.recording.centreline_points",
        )?,
        meshes: recording.and_then(|r| r.meshes).unwrap_or(true),
        mesh_segments: at_least(
            recording.and_then(|r| r.mesh_segments),
            RecordingSettings::DEFAULT_MESH_SEGMENTS,
            3,
            "output.recording.mesh_segments",
        )?,
        mesh_rings: at_least(
            recording.and_then(|r| r.mesh_rings),
            RecordingSettings::DEFAULT_MESH_RINGS,
            2,
            "output.recording.mesh_rings",
        )?,
    };
    Ok(OutputSettings {
        snapshots: snapshot_settings,
        recording: recording_settings,
    })
}

/// The design's material, validated once, by the material constructors ([`Prony::try_new`], [`Wlf::try_new`],
/// [`Material::try_new`]); their errors are mapped to the design's fields by [`material_issue`].
fn material(m: &MaterialDto) -> Result<(Material, Integrator)> {
    let branches = m
        .prony
        .iter()
        .map(|[Finite(e), Finite(tau)]| PronyBranch {
            modulus: *e,
            tau_g: *tau,
        })
        .collect();
    let prony = Prony::try_new(m.e_inf.0, branches).map_err(material_issue)?;
    let wlf = m
        .wlf
        .as_ref()
        .map(|w| Wlf::try_new(w.c1.0, w.c2.0, w.tg.0))
        .transpose();
    let material = match wlf {
        Ok(wlf) => Material::try_new(prony, m.nu.0, wlf),
        // ν precedes the WLF constants in a design and is reported first.
        Err(e) => Material::try_new(prony, m.nu.0, None).and(Err(e)),
    }
    .map_err(material_issue)?;
    let integrator = match m.integrator {
        None | Some(IntegratorDto::Trapezoidal) => Integrator::Trapezoidal,
        Some(IntegratorDto::BackwardEuler) => Integrator::BackwardEuler,
        Some(IntegratorDto::Exponential) => Integrator::Exponential,
    };
    Ok((material, integrator))
}

/// The design field a material constructor's error is about (`material.prony[k][0]`, `material.wlf.C2`, …),
/// with the constructor's message. Errors count Prony branches `α` from 1, the design's list from 0.
fn material_issue(e: MaterialError) -> Issue {
    let path = match e {
        MaterialError::BranchModulus { branch, .. } => format!("material.prony[{}][0]", branch - 1),
        MaterialError::BranchRelaxationTime { branch, .. } => {
            format!("material.prony[{}][1]", branch - 1)
        }
        MaterialError::EquilibriumModulus { .. } | MaterialError::InstantaneousModulus { .. } => {
            "material.E_inf".into()
        }
        MaterialError::PoissonRatio { .. } => "material.nu".into(),
        MaterialError::WlfC1 { .. } => "material.wlf.C1".into(),
        MaterialError::WlfC2 { .. } => "material.wlf.C2".into(),
        MaterialError::GlassTransition { .. } => "material.wlf.Tg".into(),
        _ => "material".into(),
    };
    issue(path, e.to_string())
}

/// The design's section and the shear-factor rule patches with their own diameter inherit.
fn section(s: &SectionDto) -> Result<(Section, ShearFactor)> {
    let rule = s
        .shear_factor
        .map_or(ShearFactor::Cowper, |Positive(k)| ShearFactor::Given(k));
    match (s.diameter, s.area, s.inertia, s.polar) {
        (Some(Positive(d)), None, None, None) => {
            if s.draw_diameter.is_some() {
                return Err(issue(
                    "section.draw_diameter",
                    "a circular section is drawn at its own diameter",
                ));
            }
            let c = CircularSection::try_with_shear_factor(d, rule)
                .map_err(|e| issue("section.diameter", e.to_string()))?;
            Ok((c.into(), rule))
        }
        (None, Some(Positive(area)), Some(Positive(inertia)), Some(Positive(polar))) => {
            let Some(Positive(k)) = s.shear_factor else {
                return Err(issue(
                    "section",
                    "a section given by properties needs `shear_factor`",
                ));
            };
            let p = SectionProperties {
                area,
                second_moment: inertia,
                polar_moment: polar,
                shear_factor: k,
                drawing_diameter: s
                    .draw_diameter
                    .map_or_else(|| (4.0 * area / std::f64::consts::PI).sqrt(), |d| d.0),
            };
            let section =
                Section::try_from_properties(p).map_err(|e| issue("section", e.to_string()))?;
            Ok((section, rule))
        }
        _ => Err(issue(
            "section",
            "give either `diameter` (a solid circle) or all of `area`, `inertia` and `polar` (with `shear_factor`)",
        )),
    }
}

fn geometry_issue(path: &str, e: GeometryError) -> Issue {
    issue(path, e.to_string())
}

/// Checks a discretisation: `p ≥ 2`, `n ≥ p + 1`.
fn discretisation(dto: &DesignDto, k: usize, patch: &PatchDto) -> Result<(usize, usize)> {
    let base = format!("patches[{k}]");
    let mesh = dto.mesh.as_ref();
    let (p, p_path) = match (patch.p, mesh.and_then(|m| m.p)) {
        (Some(p), _) => (p, format!("{base}.p")),
        (None, Some(p)) => (p, "mesh.p".to_string()),
        (None, None) => return Err(issue(&base, "no degree: give `p` here or `mesh.p` (p ≥ 2)")),
    };
    let (n, n_path) = match (patch.n, mesh.and_then(|m| m.n)) {
        (Some(n), _) => (n, format!("{base}.n")),
        (None, Some(n)) => (n, "mesh.n".to_string()),
        (None, None) => {
            return Err(issue(
                &base,
                "no number of control points: give `n` here or `mesh.n` (n > p)",
            ));
        }
    };
    if p < 2 {
        return Err(issue(
            p_path,
            format!(
                "degree p = {p} is too low: collocation of the strong form needs second derivatives, so p ≥ 2"
            ),
        ));
    }
    if n <= p {
        return Err(issue(
            n_path,
            format!("n = {n} control points cannot carry degree p = {p}: need n > p"),
        ));
    }
    Ok((p, n))
}

fn placement(
    origin: &Option<Vector>,
    axis: &Option<Vector>,
    x_axis: &Option<Vector>,
) -> std::result::Result<RigidPlacement, GeometryError> {
    let axis = axis.as_ref().map(vec3).unwrap_or(Vec3::z());
    Ok(RigidPlacement {
        origin: origin.as_ref().map(vec3).unwrap_or_else(Vec3::zeros),
        rotation: frame_from_axis(&axis, x_axis.as_ref().map(vec3))?,
    })
}

fn fitted(
    curve: &dyn ParametricCurve,
    p: usize,
    n: usize,
    path: &str,
) -> Result<(NurbsCurve, Option<Real>)> {
    let fit =
        fit_curve(curve, p, n, &FitSettings::default()).map_err(|e| geometry_issue(path, e))?;
    Ok((fit.curve, Some(fit.max_deviation)))
}

fn patches(
    dto: &DesignDto,
    generated: Vec<Patch>,
    sections: &mut Vec<Section>,
    shear_factor: ShearFactor,
    warnings: &mut Vec<String>,
) -> Result<Vec<Patch>> {
    if dto.patches.is_empty() && generated.is_empty() {
        return Err(issue(
            "patches",
            "a design needs at least one patch: give `patches` or a `stent` block",
        ));
    }
    let mut names: HashMap<&str, usize> = HashMap::new();
    let mut out = generated;
    for (k, pd) in dto.patches.iter().enumerate() {
        let base = format!("patches[{k}]");
        if pd.name.is_empty() || pd.name.contains('.') || pd.name.contains(char::is_whitespace) {
            return Err(issue(
                format!("{base}.name"),
                format!(
                    "{} is not a valid patch name: use a non-empty name without dots or spaces",
                    quoted(&pd.name)
                ),
            ));
        }
        if out.iter().any(|p| p.name == pd.name) && !names.contains_key(pd.name.as_str()) {
            return Err(issue(
                format!("{base}.name"),
                format!(
                    "patch name {} is already used by the generated stent",
                    quoted(&pd.name)
                ),
            ));
        }
        if let Some(first) = names.insert(&pd.name, k) {
            return Err(issue(
                format!("{base}.name"),
                format!(
                    "patch name {} is already used by patches[{first}]",
                    quoted(&pd.name)
                ),
            ));
        }
        let given = [
            pd.line.is_some(),
            pd.arc.is_some(),
            pd.helix.is_some(),
            pd.sine_wire.is_some(),
            pd.points.is_some(),
        ];
        let count = given.iter().filter(|&&g| g).count();
        if count != 1 {
            return Err(issue(
                &base,
                format!(
                    "give exactly one geometry (line, arc, helix, sine_wire or points); found {count}"
                ),
            ));
        }
        let (p, n) = discretisation(dto, k, pd)?;
        let (curve, fit_error) = if let Some(l) = &pd.line {
            let path = format!("{base}.line");
            let c = primitives::line(vec3(&l.from), vec3(&l.to), p, n)
                .map_err(|e| geometry_issue(&path, e))?;
            (c, None)
        } else if let Some(a) = &pd.arc {
            let path = format!("{base}.arc");
            let c = primitives::arc(
                vec3(&a.center),
                vec3(&a.start),
                vec3(&a.axis),
                a.angle_deg.0.to_radians(),
                p,
                n,
            )
            .map_err(|e| match &e {
                GeometryError::InvalidParameter { what, .. } if what.contains("angle") => {
                    geometry_issue(&format!("{path}.angle_deg"), e)
                }
                _ => geometry_issue(&path, e),
            })?;
            (c, None)
        } else if let Some(h) = &pd.helix {
            let path = format!("{base}.helix");
            let helix = Helix {
                radius: h.radius.0,
                pitch: h.pitch.0,
                turns: h.turns.0,
                start_angle: h.start_deg.map_or(0.0, |a| a.0.to_radians()),
                placement: placement(&h.origin, &h.axis, &h.x_axis)
                    .map_err(|e| geometry_issue(&path, e))?,
            };
            fitted(&helix, p, n, &path)?
        } else if let Some(w) = &pd.sine_wire {
            let path = format!("{base}.sine_wire");
            if w.from_deg.0 == w.to_deg.0 {
                return Err(issue(
                    format!("{path}.to_deg"),
                    "the wire must span a non-zero angle: to_deg ≠ from_deg",
                ));
            }
            let wire = SineWire {
                radius: w.radius.0,
                amplitude: w.amplitude.0,
                waves: w.waves.0,
                phase: w.phase_deg.map_or(0.0, |a| a.0.to_radians()),
                from: w.from_deg.0.to_radians(),
                to: w.to_deg.0.to_radians(),
                placement: placement(&w.origin, &w.axis, &w.x_axis)
                    .map_err(|e| geometry_issue(&path, e))?,
            };
            fitted(&wire, p, n, &path)?
        } else if let Some(pts) = &pd.points {
            let path = format!("{base}.points");
            let points: Vec<Vec3> = pts.iter().map(vec3).collect();
            let through = point_list_curve(&points).map_err(|e| geometry_issue(&path, e))?;
            fitted(&through, p, n, &path)?
        } else {
            unreachable!("exactly one geometry was checked above")
        };
        let section = match pd.diameter {
            None => 0,
            Some(Positive(d)) => {
                let path = format!("{base}.diameter");
                if !matches!(sections[0], Section::Circular(_)) {
                    return Err(issue(
                        path,
                        "only a circular section's diameter can be overridden per patch",
                    ));
                }
                let c = CircularSection::try_with_shear_factor(d, shear_factor)
                    .map_err(|e| issue(&path, e.to_string()))?;
                sections.push(c.into());
                sections.len() - 1
            }
        };
        if let Some(dev) = fit_error {
            let d = sections[section].diameter();
            if dev > FIT_WARNING_FRACTION * d {
                warnings.push(format!(
                    "patch {}: the spline fit deviates up to {dev:.3e} from the curve, {:.1}% of the wire diameter; raise n",
                    quoted(&pd.name),
                    100.0 * dev / d
                ));
            }
        }
        out.push(Patch {
            name: pd.name.clone(),
            curve,
            normal_hint: pd.normal.as_ref().map(vec3),
            section,
            material: 0,
            fit_error,
        });
    }
    Ok(out)
}

fn end_position(patches: &[Patch], e: PatchEnd) -> Vec3 {
    patches[e.patch].curve.point(e.end.parameter())
}

fn all_ends(patches: &[Patch]) -> impl Iterator<Item = PatchEnd> + '_ {
    (0..patches.len()).flat_map(|patch| [End::Start, End::End].map(|end| PatchEnd { patch, end }))
}

fn joint_tolerance(dto: &DesignDto, patches: &[Patch]) -> Real {
    if let Some(j) = &dto.joints {
        return j.tolerance.0;
    }
    let (mut lo, mut hi) = (
        Vec3::repeat(Real::INFINITY),
        Vec3::repeat(Real::NEG_INFINITY),
    );
    for p in patches {
        for q in p.curve.points() {
            lo = lo.inf(q);
            hi = hi.sup(q);
        }
    }
    DEFAULT_JOINT_TOLERANCE * (hi - lo).norm()
}

/// Parses `patch.start` / `patch.end`.
fn parse_end(name: &str, patches: &[Patch]) -> Option<PatchEnd> {
    let (patch, end) = name.rsplit_once('.')?;
    let end = match end {
        "start" => End::Start,
        "end" => End::End,
        _ => return None,
    };
    let patch = patches.iter().position(|p| p.name == patch)?;
    Some(PatchEnd { patch, end })
}

/// The nodes: `initial` (a generated stent's) first, then the declared ones, then the remaining ends.
fn nodes(
    dto: &DesignDto,
    patches: &[Patch],
    tolerance: Real,
    initial: Vec<Node>,
) -> Result<Vec<Node>> {
    let mut owner: HashMap<PatchEnd, usize> = HashMap::new();
    for (k, n) in initial.iter().enumerate() {
        owner.extend(n.ends.iter().map(|&e| (e, k)));
    }
    let mut nodes: Vec<Node> = initial;
    let mut names: HashMap<String, usize> = HashMap::new();
    for (k, nd) in dto.nodes.iter().enumerate() {
        let base = format!("nodes[{k}]");
        if nd.name.is_empty() {
            return Err(issue(
                format!("{base}.name"),
                "a node needs a non-empty name",
            ));
        }
        if nodes.iter().any(|n| n.name == nd.name) && !names.contains_key(&nd.name) {
            return Err(issue(
                format!("{base}.name"),
                format!(
                    "node name {} is already used by the generated stent",
                    quoted(&nd.name)
                ),
            ));
        }
        if let Some(first) = names.insert(nd.name.clone(), k) {
            return Err(issue(
                format!("{base}.name"),
                format!(
                    "node name {} is already used by nodes[{first}]",
                    quoted(&nd.name)
                ),
            ));
        }
        let mut ends = Vec::new();
        match (&nd.ends, &nd.at) {
            (Some(list), None) => {
                if list.is_empty() {
                    return Err(issue(
                        format!("{base}.ends"),
                        "list at least one patch end (`patch.start` or `patch.end`)",
                    ));
                }
                for (j, name) in list.iter().enumerate() {
                    let e = parse_end(name, patches).ok_or_else(|| {
                        issue(
                            format!("{base}.ends[{j}]"),
                            format!("{} is not a patch end; write `<patch>.start` or `<patch>.end` with a patch named in `patches`", quoted(name)),
                        )
                    })?;
                    ends.push(e);
                }
            }
            (None, Some(at)) => {
                let x = vec3(at);
                ends.extend(
                    all_ends(patches)
                        .filter(|&e| (end_position(patches, e) - x).norm() <= tolerance),
                );
                if ends.is_empty() {
                    return Err(issue(
                        format!("{base}.at"),
                        format!(
                            "no patch end lies within {tolerance:.3e} of [{}, {}, {}]",
                            x.x, x.y, x.z
                        ),
                    ));
                }
            }
            _ => return Err(issue(&base, "give exactly one of `ends` or `at`")),
        }
        let x0 = end_position(patches, ends[0]);
        for (j, &e) in ends.iter().enumerate() {
            if let Some(&other) = owner.get(&e) {
                return Err(issue(
                    format!("{base}.ends[{j}]"),
                    format!(
                        "{} already belongs to node {}",
                        quoted(&format!("{}.{}", patches[e.patch].name, e.end.name())),
                        quoted(&nodes[other].name)
                    ),
                ));
            }
            let gap = (end_position(patches, e) - x0).norm();
            if gap > tolerance {
                return Err(issue(
                    format!("{base}.ends[{j}]"),
                    format!(
                        "{} is {gap:.3e} away from {}: joined ends must coincide (tolerance {tolerance:.3e}; set `joints.tolerance` to change it)",
                        quoted(&format!("{}.{}", patches[e.patch].name, e.end.name())),
                        quoted(&format!(
                            "{}.{}",
                            patches[ends[0].patch].name,
                            ends[0].end.name()
                        ))
                    ),
                ));
            }
            owner.insert(e, nodes.len());
        }
        nodes.push(new_node(nd.name.clone(), ends, patches));
    }
    // Remaining ends: joined automatically when `joints` is given, otherwise free ends.
    let auto = dto.joints.is_some();
    let free: Vec<PatchEnd> = all_ends(patches)
        .filter(|e| !owner.contains_key(e))
        .collect();
    let mut used = vec![false; free.len()];
    for i in 0..free.len() {
        if used[i] {
            continue;
        }
        used[i] = true;
        let mut ends = vec![free[i]];
        if auto {
            let x = end_position(patches, free[i]);
            for j in i + 1..free.len() {
                if !used[j] && (end_position(patches, free[j]) - x).norm() <= tolerance {
                    used[j] = true;
                    ends.push(free[j]);
                }
            }
        }
        let e = ends[0];
        let name = format!("{}.{}", patches[e.patch].name, e.end.name());
        nodes.push(new_node(name, ends, patches));
    }
    Ok(nodes)
}

fn new_node(name: String, ends: Vec<PatchEnd>, patches: &[Patch]) -> Node {
    let position =
        ends.iter().map(|&e| end_position(patches, e)).sum::<Vec3>() / ends.len() as Real;
    Node {
        name,
        ends,
        position,
        conditions: NodeConditions::default(),
    }
}

/// Resolves a node reference: a node name, or `patch.start` / `patch.end` of any end the node holds.
fn find_node(name: &str, patches: &[Patch], nodes: &[Node]) -> Option<usize> {
    nodes.iter().position(|n| n.name == name).or_else(|| {
        let e = parse_end(name, patches)?;
        nodes.iter().position(|n| n.ends.contains(&e))
    })
}

/// Completes an orthonormal right-handed basis whose first axis is `n`.
fn basis_from_normal(n: &Vec3) -> Mat3 {
    let e1 = n.normalize();
    let e2 = crate::geometry::frame::normal_to(&e1, None);
    Mat3::from_columns(&[e1, e2, e1.cross(&e2)])
}

/// Orthonormality tolerance of a user-given basis: rows typed with about seven significant digits pass.
const BASIS_TOLERANCE: Real = 1e-6;

/// Applies the design's `conditions` to `nodes`. An entry names one node (`node`) or every node of a set
/// (`node_set`); `preset` names what already set a component (a stent's symmetry plane, the programme), which an
/// entry may not override.
fn conditions(
    dto: &DesignDto,
    patches: &[Patch],
    nodes: &mut [Node],
    node_sets: &BTreeMap<String, Vec<usize>>,
    preset: &HashMap<(usize, usize), String>,
) -> Result<()> {
    // What set each node's basis and each component, to report contradictions.
    let mut basis_from: HashMap<usize, String> = HashMap::new();
    for &(node, _) in preset.keys() {
        if nodes[node].conditions.basis != Mat3::identity() {
            basis_from.insert(node, "the stent's symmetry plane".into());
        }
    }
    let mut set_by: HashMap<(usize, usize), String> = preset.clone();
    for (k, c) in dto.conditions.iter().enumerate() {
        let base = format!("conditions[{k}]");
        let targets: Vec<usize> = match (&c.node, &c.node_set) {
            (Some(name), None) => vec![find_node(name, patches, nodes).ok_or_else(|| {
                issue(
                    format!("{base}.node"),
                    format!("no node {}: name a node from `nodes` or a patch end `<patch>.start` / `<patch>.end`", quoted(name)),
                )
            })?],
            (None, Some(set)) => node_sets.get(set).cloned().ok_or_else(|| {
                let known: Vec<&str> = node_sets.keys().map(String::as_str).collect();
                issue(
                    format!("{base}.node_set"),
                    if known.is_empty() {
                        format!("no node set {}: node sets come from a generated `stent`", quoted(set))
                    } else {
                        format!("no node set {}; known sets: {}", quoted(set), known.join(", "))
                    },
                )
            })?,
            _ => {
                return Err(issue(
                    &base,
                    "give exactly one of `node` (a node name) or `node_set` (a set name)",
                ));
            }
        };
        let basis = match (&c.basis, &c.symmetry_plane) {
            (Some(_), Some(_)) => {
                return Err(issue(
                    &base,
                    "give `basis` or `symmetry_plane`, not both: the plane defines the basis",
                ));
            }
            (Some(rows), None) => {
                let m = Mat3::from_columns(&[vec3(&rows[0]), vec3(&rows[1]), vec3(&rows[2])]);
                let err = (m.transpose() * m - Mat3::identity()).abs().max();
                if err > BASIS_TOLERANCE || m.determinant() < 0.0 {
                    return Err(issue(
                        format!("{base}.basis"),
                        format!(
                            "the rows must be orthonormal and right-handed (|BᵀB − I| = {err:.2e}, det = {:.3})",
                            m.determinant()
                        ),
                    ));
                }
                Some(m)
            }
            (None, Some(n)) => {
                let n = vec3(n);
                if n.norm() == 0.0 {
                    return Err(issue(
                        format!("{base}.symmetry_plane"),
                        "the plane normal must be non-zero",
                    ));
                }
                Some(basis_from_normal(&n))
            }
            (None, None) => None,
        };
        // Collect this entry's prescribed values and loads per component.
        let mut prescribed: [Option<(TimeFunction, String)>; 6] = Default::default();
        let mut loads: [Option<(TimeFunction, String)>; 6] = Default::default();
        if c.clamp {
            if c.displacement.is_some() || c.rotation.is_some() || c.symmetry_plane.is_some() {
                return Err(issue(
                    format!("{base}.clamp"),
                    "`clamp` holds all six components: do not also give displacement, rotation or symmetry_plane",
                ));
            }
            for (i, slot) in prescribed.iter_mut().enumerate() {
                *slot = Some((TimeFunction::zero(), format!("{base}.clamp#{i}")));
            }
        }
        if c.symmetry_plane.is_some() {
            for i in [0, 4, 5] {
                prescribed[i] = Some((TimeFunction::zero(), format!("{base}.symmetry_plane")));
            }
        }
        for (field, offset, target) in [
            ("displacement", 0, &c.displacement),
            ("rotation", 3, &c.rotation),
        ] {
            if let Some(values) = target {
                for (i, v) in values.iter().enumerate() {
                    if let ComponentValue::Value(f) = v {
                        let path = format!("{base}.{field}[{i}]");
                        if prescribed[offset + i].is_some() {
                            return Err(issue(
                                &path,
                                "this component is already held by symmetry_plane",
                            ));
                        }
                        prescribed[offset + i] = Some((time_function(f, &path)?, path));
                    }
                }
            }
        }
        for (field, offset, target) in [("force", 0, &c.force), ("moment", 3, &c.moment)] {
            if let Some(values) = target {
                for (i, v) in values.iter().enumerate() {
                    if let ComponentValue::Value(f) = v {
                        let path = format!("{base}.{field}[{i}]");
                        loads[offset + i] = Some((time_function(f, &path)?, path));
                    }
                }
            }
        }
        let release = c.release.map(|r| r.0);
        if release.is_some() && prescribed.iter().all(Option::is_none) {
            return Err(issue(
                format!("{base}.release"),
                "nothing to release: this entry prescribes no component",
            ));
        }
        const NAMES: [&str; 6] = ["u1", "u2", "u3", "θ1", "θ2", "θ3"];
        for node in targets {
            if let Some(b) = basis {
                match basis_from.get(&node) {
                    Some(first)
                        if (nodes[node].conditions.basis - b).abs().max() > BASIS_TOLERANCE =>
                    {
                        return Err(issue(
                            &base,
                            format!(
                                "node {} already has a different basis from {first}; one node has one basis",
                                quoted(&nodes[node].name)
                            ),
                        ));
                    }
                    _ => {
                        basis_from.insert(node, base.clone());
                        nodes[node].conditions.basis = b;
                    }
                }
            }
            for i in 0..6 {
                let (p, l) = (&prescribed[i], &loads[i]);
                if p.is_none() && l.is_none() {
                    continue;
                }
                let path = p
                    .as_ref()
                    .or(l.as_ref())
                    .map(|(_, path)| path.clone())
                    .unwrap_or_default();
                if let Some(first) = set_by.get(&(node, i)) {
                    return Err(issue(
                        path,
                        format!(
                            "component {} of node {} is already set by {first}: one condition per component",
                            NAMES[i],
                            quoted(&nodes[node].name)
                        ),
                    ));
                }
                set_by.insert((node, i), base.clone());
                nodes[node].conditions.components[i] = match (p, l) {
                    (Some((value, _)), load) => {
                        if let (Some((_, lpath)), None) = (load, release) {
                            return Err(issue(
                                lpath,
                                format!(
                                    "component {} is both prescribed and loaded: a load acts only on a free component (add `release` to load it after release)",
                                    NAMES[i]
                                ),
                            ));
                        }
                        Component::Prescribed {
                            value: value.clone(),
                            release,
                            load_after_release: load
                                .as_ref()
                                .map_or_else(TimeFunction::zero, |(f, _)| f.clone()),
                        }
                    }
                    (None, Some((f, _))) => Component::Load(f.clone()),
                    (None, None) => unreachable!("skipped above"),
                };
            }
        }
    }
    Ok(())
}

fn distributed_loads(dto: &DesignDto, patches: &[Patch]) -> Result<Vec<DistributedLoad>> {
    let mut out = Vec::new();
    for (k, d) in dto.distributed_loads.iter().enumerate() {
        let base = format!("distributed_loads[{k}]");
        let targets: Vec<usize> = if d.patch == "all" {
            (0..patches.len()).collect()
        } else {
            vec![
                patches
                    .iter()
                    .position(|p| p.name == d.patch)
                    .ok_or_else(|| {
                        issue(
                            format!("{base}.patch"),
                            format!("no patch {}: name a patch or write `all`", quoted(&d.patch)),
                        )
                    })?,
            ]
        };
        let three = |f: &Option<[TimeFn; 3]>, field: &str| -> Result<[TimeFunction; 3]> {
            let mut out: [TimeFunction; 3] = std::array::from_fn(|_| TimeFunction::zero());
            if let Some(fs) = f {
                for (i, fi) in fs.iter().enumerate() {
                    out[i] = time_function(fi, &format!("{base}.{field}[{i}]"))?;
                }
            }
            Ok(out)
        };
        let force = three(&d.force, "force")?;
        let couple = three(&d.couple, "couple")?;
        for patch in targets {
            out.push(DistributedLoad {
                patch,
                force: force.clone(),
                couple: couple.clone(),
            });
        }
    }
    Ok(out)
}

fn time_settings(t: &TimeDto) -> Result<TimeSettings> {
    let (end, step) = (t.end.0, t.step.0);
    if step > end {
        return Err(issue(
            "time.step",
            format!("the step {step} exceeds the end time {end}"),
        ));
    }
    let min_step = t.min_step.map_or(step * DEFAULT_MIN_STEP_FRACTION, |m| m.0);
    if min_step > step {
        return Err(issue(
            "time.min_step",
            format!("min_step {min_step} exceeds the step {step}"),
        ));
    }
    Ok(TimeSettings {
        end,
        step,
        min_step,
        release_ramp: t.release_ramp.map_or(step, |r| r.0),
    })
}

fn solver_settings(s: Option<&SolverDto>) -> Result<SolverSettings> {
    let mut out = SolverSettings::default();
    if let Some(s) = s {
        if let Some(Positive(t)) = s.tolerance {
            out.tolerance = t;
        }
        if let Some(m) = s.max_iterations {
            if m == 0 {
                return Err(issue("solver.max_iterations", "must be ≥ 1"));
            }
            out.max_iterations = m;
        }
        if let Some(r) = s.reuse_factorisation {
            out.reuse_factorisation = r;
        }
        if let Some(e) = s.extrapolate {
            out.extrapolate = e;
        }
        if let Some(l) = s.linear {
            out.linear = match l {
                LinearDto::Block => LinearMethod::Block,
                LinearDto::SparseLu => LinearMethod::SparseLu,
            };
        }
    }
    Ok(out)
}

fn probes(dto: &DesignDto, patches: &[Patch], nodes: &[Node]) -> Result<Vec<Probe>> {
    let Some(output) = &dto.output else {
        return Ok(Vec::new());
    };
    let mut out: Vec<Probe> = Vec::new();
    for (k, p) in output.probes.iter().enumerate() {
        let base = format!("output.probes[{k}]");
        if p.name.is_empty() || p.name.contains([',', '"', '\n']) {
            return Err(issue(
                format!("{base}.name"),
                "a probe name must be non-empty, without commas or quotes",
            ));
        }
        if out.iter().any(|q| q.name == p.name) {
            return Err(issue(
                format!("{base}.name"),
                format!("probe name {} is used twice", quoted(&p.name)),
            ));
        }
        let location = match (&p.node, &p.patch, &p.u) {
            (Some(n), None, None) => {
                ProbeLocation::Node(find_node(n, patches, nodes).ok_or_else(|| {
                    issue(format!("{base}.node"), format!("no node {}", quoted(n)))
                })?)
            }
            (None, Some(name), Some(Finite(u))) => {
                let patch = patches
                    .iter()
                    .position(|q| &q.name == name)
                    .ok_or_else(|| {
                        issue(
                            format!("{base}.patch"),
                            format!("no patch {}", quoted(name)),
                        )
                    })?;
                if !(0.0..=1.0).contains(u) {
                    return Err(issue(
                        format!("{base}.u"),
                        format!("u = {u} must lie in [0, 1]"),
                    ));
                }
                ProbeLocation::Patch { patch, u: *u }
            }
            _ => {
                return Err(issue(
                    &base,
                    "give either `node`, or `patch` together with `u`",
                ));
            }
        };
        out.push(Probe {
            name: p.name.clone(),
            location,
        });
    }
    Ok(out)
}
