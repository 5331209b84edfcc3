//! `stentkit check`: validate a design and describe what a run would solve.

use crate::design::size::{MEMORY_LIMIT_BYTES, human_bytes};
use crate::design::{Design, DesignOverrides, SetOverride, load_design_with};
use crate::material::{ConstitutiveLaw, MaterialLaw};
use crate::model::Component;
use crate::run::estimate::estimated_disk;
use std::fmt::Write as _;
use std::path::Path;

/// Loads the design with the `--set` overrides `sets` and prints its description.
pub(crate) fn run(path: &Path, sets: Vec<SetOverride>) -> anyhow::Result<()> {
    let design = load_design_with(path, &DesignOverrides::sets(sets))?;
    print!("{}", describe(&design, &path.display().to_string()));
    Ok(())
}

/// The human-readable description printed by `check`.
pub fn describe(design: &Design, file: &str) -> String {
    let (model, warnings) = (&design.model, &design.warnings);
    let mut s = String::new();
    let u = model.units;
    let _ = writeln!(
        s,
        "design      {} ({file}), units {}",
        model.name(),
        u.name()
    );
    for (k, law) in model.materials().iter().enumerate() {
        let label = if model.materials().len() == 1 {
            "material   ".to_string()
        } else {
            format!("material {k}  `{}`:", model.material_names[k])
        };
        let _ = writeln!(s, "{label} {}", describe_material(law, u.stress()));
    }
    // Shear factors with the first material's ν (the design's one material).
    let poisson = model.materials().first().map_or(0.0, |m| m.poisson());
    for (k, sec) in model.sections.iter().enumerate() {
        let kind = match sec {
            crate::material::Section::Circular(_) => {
                format!("circular, d = {} {}", sec.diameter(), u.length())
            }
            crate::material::Section::Properties(_) => format!(
                "A = {}, I = {}, J = {} (drawn at d = {} {})",
                sec.area(),
                sec.second_moment(),
                sec.polar_moment(),
                sec.diameter(),
                u.length()
            ),
        };
        let _ = writeln!(
            s,
            "section {k}   {kind}, shear factor {:.4}",
            sec.shear_factor(poisson)
        );
    }
    if let Some(field) = &model.temperature_field {
        let e = field.direction;
        let kind = match &field.profile {
            crate::model::Profile::Stations(stations) => format!(
                "schedules at {} stations ζ = {:?} {}",
                stations.len(),
                stations.iter().map(|st| st.0).collect::<Vec<_>>(),
                u.length()
            ),
            crate::model::Profile::Front { width, .. } => {
                format!("a moving front of width {width} {}", u.length())
            }
        };
        let (lo, hi) = field.range();
        let _ = writeln!(
            s,
            "temperature varies along ζ = ({:.4}, {:.4}, {:.4})·(X − X₀): {kind}, between {lo} and {hi} °C",
            e.x, e.y, e.z
        );
    }
    let _ = writeln!(s, "patches     {}", model.patches.len());
    let width = model
        .patches
        .iter()
        .map(|p| p.name.len())
        .max()
        .unwrap_or(0);
    for p in &model.patches {
        let fit = match p.fit_error {
            None => "exact".to_string(),
            Some(e) => format!("fit error {e:.3e} {}", u.length()),
        };
        let material = if model.materials().len() > 1 {
            format!(", material `{}`", model.material_names[p.material])
        } else {
            String::new()
        };
        let _ = writeln!(
            s,
            "  {:width$}  p = {}, n = {:3}, section {}{material}, {fit}",
            p.name,
            p.curve.degree(),
            p.curve.num_points(),
            p.section
        );
    }
    let _ = writeln!(s, "nodes       {}", model.nodes.len());
    let width = model.nodes.iter().map(|n| n.name.len()).max().unwrap_or(0);
    for n in &model.nodes {
        let prescribed = n
            .conditions
            .components
            .iter()
            .filter(|c| matches!(c, Component::Prescribed { .. }))
            .count();
        let loaded = n
            .conditions
            .components
            .iter()
            .filter(|c| matches!(c, Component::Load(f) if !f.is_zero()))
            .count();
        let released = n.conditions.components.iter().find_map(|c| match c {
            Component::Prescribed {
                release: Some(r), ..
            } => Some(*r),
            _ => None,
        });
        let mut what = format!(
            "{} end{}, {prescribed} prescribed, {loaded} loaded",
            n.ends.len(),
            if n.ends.len() == 1 { "" } else { "s" }
        );
        if let Some(r) = released {
            let _ = write!(what, ", released at t = {r}");
        }
        let _ = writeln!(s, "  {:width$}  {what}", n.name);
    }
    let _ = writeln!(s, "collocation points  {}", model.num_collocation_points());
    let _ = writeln!(s, "unknowns            {}", model.num_unknowns());
    let plan = design.steps;
    let bound = error_controlled_bound(design);
    match model.solver().path {
        crate::model::PathControl::Time => match (model.time().tolerance, bound) {
            (Some(tolerance), Some(most)) => {
                let _ = writeln!(
                    s,
                    "time steps          error-controlled (tolerance {tolerance:e}): from h = {} s, as many as the time-error estimate needs, between min_step = {:e} s and {}; at most {} (every step at min_step); {} at h; end {} s",
                    model.time().step,
                    model.time().min_step,
                    model
                        .time()
                        .max_step
                        .map_or("no max_step".to_string(), |m| format!("max_step = {m} s")),
                    most.total(),
                    plan.total(),
                    model.time().end
                );
            }
            _ => {
                let _ = writeln!(
                    s,
                    "time steps          {} ({} of h = {} s + {} shortened to land on breakpoints; end {} s)",
                    plan.total(),
                    plan.full,
                    model.time().step,
                    plan.shortened,
                    model.time().end
                );
            }
        },
        crate::model::PathControl::ArcLength(a) => {
            let _ = writeln!(
                s,
                "arc-length path     at most {} increments to load factor {} (the loads at t = {} s; first increment {} of them)",
                a.max_increments,
                a.end_load_factor,
                model.time().end,
                model.time().step / model.time().end
            );
        }
    }
    let memory = &design.memory;
    let _ = write!(
        s,
        "memory              about {}{} (limit {})",
        human_bytes(memory.total()),
        if bound.is_some() {
            format!(" at {} steps of h", plan.total())
        } else {
            String::new()
        },
        human_bytes(MEMORY_LIMIT_BYTES)
    );
    if let Some(term) = memory.largest() {
        let _ = write!(s, "; largest: {} ({})", term.what, term.field);
    }
    let _ = writeln!(s);
    let disk = estimated_disk(design);
    let mb = |bytes: u64| format!("{:.1} MB", bytes as f64 / 1e6);
    // An error-controlled run's steps are known only as it runs: the estimate at h, and the most it can write.
    let (basis, most) = match bound {
        Some(steps) => (
            format!(" at {} steps of h", plan.total()),
            format!(
                "; error-controlled, so at most {} ({} steps at min_step)",
                human_bytes(
                    estimated_disk(&Design {
                        steps,
                        ..design.clone()
                    })
                    .total() as f64
                ),
                steps.total()
            ),
        ),
        None => (String::new(), String::new()),
    };
    // Each part with its kinds of file that the design writes.
    let _ = writeln!(
        s,
        "disk                run folder about {}{basis}: {}{most}",
        mb(disk.total()),
        disk.describe(&mb, true)
    );
    let worst = model
        .patches
        .iter()
        .filter_map(|p| p.fit_error.map(|e| (e, &p.name)))
        .max_by(|a, b| a.0.total_cmp(&b.0));
    match worst {
        Some((e, name)) => {
            let _ = writeln!(
                s,
                "geometry fit error  {e:.3e} {} (patch {name})",
                u.length()
            );
        }
        None => {
            let _ = writeln!(s, "geometry fit error  0 (all patches exact)");
        }
    }
    let _ = write!(s, "{}", describe_overlaps(model));
    if !model.probes.is_empty() {
        let names: Vec<_> = model.probes.iter().map(|p| p.name.as_str()).collect();
        let _ = writeln!(s, "probes              {}", names.join(", "));
    }
    for note in &design.notes {
        let _ = writeln!(s, "note                {note}");
    }
    if warnings.is_empty() {
        let _ = writeln!(s, "warnings            none");
    } else {
        let _ = writeln!(s, "warnings            {}", warnings.len());
        for w in warnings {
            let _ = writeln!(s, "  - {w}");
        }
    }
    s
}

/// Overlaps of `model`'s wires in the shape it is generated in (module docs of [`crate::model::wires`]) deeper than
/// its round-off, the deepest first, the first five in words: the `wires` lines of `check` and `mesh`.
pub(crate) fn describe_overlaps(model: &crate::model::Model) -> String {
    use crate::model::wires::{DeviceWires, ROUND_OFF, reference_control};
    let wires = DeviceWires::new(model);
    let found = wires.overlaps(
        &reference_control(model),
        ROUND_OFF * wires.largest_radius(),
    );
    let unit = model.units.length();
    let mut s = String::new();
    if found.is_empty() {
        let _ = writeln!(
            s,
            "wires               no two closer than their radii allow"
        );
        return s;
    }
    let _ = writeln!(
        s,
        "wires               {} pair{} of wires overlap; the deepest by {:.4e} {unit}",
        found.len(),
        if found.len() == 1 { "" } else { "s" },
        found[0].depth
    );
    for o in found.iter().take(5) {
        let _ = writeln!(s, "  - {}", wires.describe(o, unit));
    }
    if found.len() > 5 {
        let _ = writeln!(s, "  - and {} more", found.len() - 5);
    }
    s
}

/// The most steps an error-controlled run of `design` can take, `None` for fixed steps (and arc length): every
/// step at `time.min_step` (error control and step cutting take no shorter one, except to land on a
/// breakpoint), and one more per landing span for the round-off sliver [`crate::model::Model::planned_steps`]
/// allows.
fn error_controlled_bound(design: &Design) -> Option<crate::model::StepPlan> {
    let model = &design.model;
    model.time().tolerance?;
    model.solver().path.arc_length().is_none().then(|| {
        let mut plan = model.planned_steps_at(model.time().min_step);
        plan.full = plan
            .full
            .saturating_add(model.schedule_breakpoints().len() + 1);
        plan
    })
}

/// One line about a material: the elastic modulus, or the Prony series, the WLF shift and the integrator.
fn describe_material(law: &MaterialLaw, stress: &str) -> String {
    match law {
        MaterialLaw::Elastic(e) => format!(
            "elastic, E = {} {stress}, nu = {} (no Maxwell branches, no WLF shift)",
            e.modulus(),
            e.poisson()
        ),
        MaterialLaw::Maxwell(law) => {
            let m = law.material();
            let integrator = law.integrator().name();
            let head = format!(
                "E_inf = {} {stress}, {} Maxwell branches (E0 = {} {stress}), nu = {}",
                m.prony().e_inf(),
                m.num_branches(),
                m.prony().instantaneous_modulus(),
                m.poisson()
            );
            match m.wlf() {
                Some(w) => format!(
                    "{head}, WLF C1 = {}, C2 = {} K, Tg = {} °C (frozen at and below {} °C), integrator {integrator}",
                    w.c1(),
                    w.c2(),
                    w.tg(),
                    w.frozen_below(),
                ),
                None => format!(
                    "{head}, no WLF shift (temperature-independent), integrator {integrator}"
                ),
            }
        }
    }
}
