//! How much memory a design needs, estimated from the deserialised design before any geometry is generated
//! (so that a typo such as `n: 100000000` or `step: 1e-12` is refused with the field to fix, not by exhausting
//! the machine), and again once the model's time steps are planned.

use super::dto::*;
use super::issue::{Result, issue};
use crate::math::Real;
use crate::math::quote::quoted;
use crate::model::{StepPlan, TimeSettings};
/// Memory a design may need before it is refused \[bytes\]: 8 GB. The estimate ([`estimated_memory`]) is
/// checked before any geometry is generated, so that a typo (`n: 100000000`, `step: 1e-12`) gets an error
/// naming the field and the estimate instead of exhausting the machine. The paper's curved stent needs about
/// 0.1 GB; 8 GB leaves two orders of magnitude for refined studies while staying below the memory of a
/// typical workstation.
pub(crate) const MEMORY_LIMIT_BYTES: Real = 8e9;

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
    /// Bytes kept per time step (the design's probes decide it).
    pub bytes_per_step: Real,
    /// Which of `terms` is the time steps' (none in an empty estimate).
    steps_term: Option<usize>,
}

impl MemoryEstimate {
    /// All contributions \[bytes\] (NaN if one is).
    pub fn total(&self) -> Real {
        self.terms.iter().map(|t| t.bytes).sum()
    }

    /// The largest contribution.
    pub fn largest(&self) -> Option<&MemoryTerm> {
        self.terms.iter().max_by(|a, b| a.bytes.total_cmp(&b.bytes))
    }

    /// The estimate for a run of the same design that takes the time steps `steps` instead of those it was
    /// made for (a study's variant of the time stepping): the time steps' term replaced, the rest kept.
    pub fn with_steps(&self, steps: &StepCount) -> MemoryEstimate {
        let mut changed = self.clone();
        if let Some(term) = self.steps_term.and_then(|k| changed.terms.get_mut(k)) {
            *term = MemoryTerm {
                field: steps.field.clone(),
                what: steps.what.clone(),
                bytes: steps.steps * self.bytes_per_step,
            };
        }
        changed
    }

    /// The most time steps that keep this estimate within [`MEMORY_LIMIT_BYTES`], the other terms as they are
    /// (zero when they alone exceed it).
    pub fn steps_within_limit(&self) -> Real {
        let steps = self
            .steps_term
            .and_then(|k| self.terms.get(k))
            .map_or(0.0, |t| t.bytes);
        ((MEMORY_LIMIT_BYTES - (self.total() - steps)) / self.bytes_per_step).max(0.0)
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
            what: if steps.is_finite() {
                format!("{steps:.3e} time steps")
            } else {
                "more than 1e308 time steps".to_string()
            },
        }
    }

    /// The steps the run takes (`plan`, `Model::planned_steps` with nominal step `step`): charged to
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
/// `output.snapshots.times`, `output.history.times`, …), if any has more than one.
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
    let output = dto.output.as_ref();
    for (field, times) in [
        (
            "output.snapshots.times",
            output.and_then(|o| o.snapshots.as_ref()?.times.as_ref()),
        ),
        (
            "output.history.times",
            output.and_then(|o| o.history.as_ref()?.times.as_ref()),
        ),
    ] {
        if let Some(times) = times {
            tables.push((field.into(), times.len()));
        }
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
pub(crate) fn estimated_memory(dto: &DesignDto, steps: &StepCount) -> MemoryEstimate {
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
        // The family's own counts of the full device, shared among the modelled sectors.
        let counts = super::family::counts(s);
        let sector = counts.sectors as Real;
        let (crowns, peaks) = (s.crowns as Real, s.peaks as Real);
        let pick = |own: Option<&MeshDto>| {
            let p = own.and_then(|m| m.p).or(mesh.and_then(|m| m.p));
            let n = own.and_then(|m| m.n).or(mesh.and_then(|m| m.n));
            p.zip(n)
        };
        let crown_patches = counts.crown_wires / sector;
        let bridge_patches = counts.bridges / sector;
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
    let steps_term = terms.len();
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
        bytes_per_step: bytes_per_step(probes),
        steps_term: Some(steps_term),
    }
}

/// `1.2 GB`-style size (`more than 1e308 bytes` when the count overflowed).
pub(crate) fn human_bytes(bytes: Real) -> String {
    if bytes == Real::INFINITY {
        "more than 1e308 bytes".to_string()
    } else if bytes >= 1e15 {
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

/// Whether `estimate` is above [`MEMORY_LIMIT_BYTES`] (or not a number): then what it would need, in words
/// (`would need about 2 TB of memory (patch `beam` (…): 2 TB), more than stentkit's limit of 8.0 GB`).
pub(crate) fn over_limit(estimate: &MemoryEstimate) -> Option<String> {
    let total = estimate.total();
    if !(total.is_nan() || total > MEMORY_LIMIT_BYTES) {
        return None;
    }
    let term = estimate.largest()?;
    Some(format!(
        "would need {} of memory ({}: {}), more than stentkit's limit of {}",
        if total.is_finite() {
            format!("about {}", human_bytes(total))
        } else {
            human_bytes(total)
        },
        term.what,
        human_bytes(term.bytes),
        human_bytes(MEMORY_LIMIT_BYTES)
    ))
}

/// The [`estimated_memory`] for `steps`; refused when above [`MEMORY_LIMIT_BYTES`], naming the field of the
/// largest contribution.
pub(super) fn check_size(dto: &DesignDto, steps: &StepCount) -> Result<MemoryEstimate> {
    let estimate = estimated_memory(dto, steps);
    if let (Some(too_much), Some(term)) = (over_limit(&estimate), estimate.largest()) {
        return Err(issue(
            &term.field,
            format!("this design {too_much}: reduce it"),
        ));
    }
    Ok(estimate)
}
