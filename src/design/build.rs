//! From the deserialised design ([`super::dto`]) to a [`Model`]: a translation into
//! [`ModelBuilder`] calls, which generate the geometry and make every check that involves more than one value.
//! A failed check names a builder [`Field`]; [`field_path`] turns it into the design's field path, which
//! [`super`] turns into a line and column. What is about the design file itself — its version, the run folder's
//! name (by the builder's rule for a model name, in the design's words), the memory it may take, the output
//! settings — is checked here.

use super::dto::*;
pub(crate) use super::issue::Issue;
use super::issue::{Result, issue, mesh_key_path};
use super::materials::{material, material_index, named_materials};
use super::size::{MemoryEstimate, StepCount, check_size};
use super::stent;
use crate::geometry::GeometryError;
use crate::geometry::analytic::{
    Helix, RigidPlacement, SineWire, frame_from_axis, point_list_curve,
};
use crate::material::{CircularSection, MaterialLaw, Section, SectionProperties, ShearFactor};
use crate::math::quote::quoted;
use crate::math::{Mat3, Real, Vec3};
use crate::model::builder::checks::{NAME_RULE, check_name};
use crate::model::builder::*;
use crate::model::temperature::FieldError;
use crate::model::*;

/// A design built and validated by [`build`].
#[derive(Debug, Clone)]
pub(crate) struct Built {
    /// The model.
    pub model: Model,
    /// Snapshot and recording settings.
    pub output: super::OutputSettings,
    /// Things worth knowing that do not stop a run.
    pub warnings: Vec<String>,
    /// How the design was read where it involved a choice (a file centreline's fit), for `check`.
    pub notes: Vec<String>,
    /// The memory the run is estimated to need (below [`super::size::MEMORY_LIMIT_BYTES`]).
    pub memory: MemoryEstimate,
    /// The steps the run takes when no step is cut ([`Model::planned_steps`]).
    pub steps: StepPlan,
    /// The virtual bench's settings as written.
    pub bench: super::BenchSpec,
}

/// Builds and validates the model (with `temporary_shape`, the device in its programme's temporary shape,
/// without the programme); returns it with the output settings, the warnings found and the memory estimate.
pub(crate) fn build(dto: &DesignDto, default_name: &str, temporary_shape: bool) -> Result<Built> {
    if let Some(v) = dto.version
        && v != 1
    {
        return Err(issue(
            "version",
            format!("version {v} is not supported; allowed: 1"),
        ));
    }
    let name = design_name(dto, default_name)?;
    let (material, integrator) = material(&dto.material, "material")?;
    let (section, shear_factor) = section(&dto.section)?;
    let time = time_spec(&dto.time)?;
    let settings = time.settings().map_err(|e| builder_issue(e, dto))?;
    // Before any geometry is generated: a size that would exhaust memory is refused with an estimate (with the
    // nominal steps; the steps landing on breakpoints are counted once the model exists, below).
    check_size(dto, &StepCount::nominal(&settings))?;
    let circular = matches!(section, Section::Circular(_));
    // The design's `material` is material 0 (every patch's unless it names another), `materials` follow.
    let mut builder = ModelBuilder::new(
        name,
        MaterialLaw::from_material(material, integrator),
        section,
    );
    if let Some(first) = &dto.material.name {
        builder.name_first_material(first.clone());
    }
    let material_names = named_materials(dto, &mut builder)?;
    builder.units(match dto.units {
        UnitsDto::Si => Units::Si,
        UnitsDto::MmNMpa => Units::MmNMpa,
    });
    builder.time(time);
    let metres_per_unit = match dto.units {
        UnitsDto::Si => 1.0,
        UnitsDto::MmNMpa => 1e-3,
    };
    let mut notes = Vec::new();
    let mut vessel = None;
    if let Some(s) = &dto.stent {
        let (device, said, file_vessel) = super::family::device(s, metres_per_unit)?;
        notes.extend(said);
        if let Some(v) = &file_vessel {
            builder.vessel(v.clone());
        }
        vessel = file_vessel;
        builder.stent(device, stent::mesh(s, dto.mesh.as_ref())?);
        if let Some(m) = &s.materials {
            builder.stent_materials(stent::materials(m, &material_names)?);
        }
    }
    if let Some(p) = &dto.programme {
        builder.programme(stent::programme(p, metres_per_unit)?);
    }
    let contact = super::contact::contact(dto, &section, vessel.as_ref())?;
    let wires = super::contact::wire_contact(dto, &section);
    let has_contact = contact.is_some() || wires.is_some();
    if let Some(c) = contact {
        builder.contact(c);
    }
    if let Some(w) = wires {
        builder.wire_contact(w);
    }
    if temporary_shape {
        builder.temporary_shape();
    }
    patches(dto, &mut builder, circular, shear_factor, &material_names)?;
    if let Some(j) = &dto.joints {
        builder.joints(JointRule {
            automatic: true,
            tolerance: Some(j.tolerance.0),
        });
    }
    for (k, nd) in dto.nodes.iter().enumerate() {
        let ends = match (&nd.ends, &nd.at) {
            (Some(list), None) => NodeEnds::Named(list.clone()),
            (None, Some(at)) => NodeEnds::At(vec3(at)),
            _ => {
                return Err(issue(
                    format!("nodes[{k}]"),
                    "give exactly one of `ends` or `at`",
                ));
            }
        };
        builder.node(nd.name.clone(), ends);
    }
    for (k, c) in dto.conditions.iter().enumerate() {
        builder.condition(condition(k, c)?);
    }
    for (k, d) in dto.distributed_loads.iter().enumerate() {
        builder.distributed_load(distributed_load(k, d)?);
    }
    if let Some(f) = &dto.temperature {
        builder.temperature(time_function(f, "temperature")?);
    }
    if let Some(f) = &dto.temperature_field {
        builder.temperature_field(temperature_field(f)?);
    }
    builder.solver(solver_settings(dto.solver.as_ref(), has_contact));
    for (k, p) in dto.output.iter().flat_map(|o| o.probes.iter()).enumerate() {
        let base = format!("output.probes[{k}]");
        let at = match (&p.node, &p.patch, &p.u) {
            (Some(n), None, None) => ProbeAt::Node(n.clone()),
            (None, Some(patch), Some(Finite(u))) => ProbeAt::Patch(patch.clone(), *u),
            _ => {
                return Err(issue(
                    &base,
                    "give either `node`, or `patch` together with `u`",
                ));
            }
        };
        builder.probe(p.name.clone(), at);
    }
    let mut output = output_settings(dto, &settings)?;
    // (The builder sorts them and drops repeats.)
    builder.record_times(
        (output.snapshots.times.iter())
            .chain(&output.history_times)
            .copied()
            .filter(|&t| t > 0.0)
            .collect(),
    );
    let crate::model::builder::Built {
        model,
        mut warnings,
    } = builder.build().map_err(|e| builder_issue(e, dto))?;
    // The steps the run takes, landing on every breakpoint: refused if their memory is too much. An arc-length
    // path takes at most its increments allowed, and has no times to place snapshots at: by default about
    // DEFAULT_COUNT of them over its increments.
    let snapshots = dto.output.as_ref().and_then(|o| o.snapshots.as_ref());
    let plan = match model.solver().path {
        PathControl::ArcLength(a) => {
            if snapshots.is_some_and(|s| s.times.is_some()) {
                return Err(issue(
                    "output.snapshots.times",
                    "an arc-length path has no times to land on (its `time` is the path parameter, known only as it is followed): use `output.snapshots.every`",
                ));
            }
            if snapshots.and_then(|s| s.every).is_none() {
                output.snapshots.every = a
                    .max_increments
                    .div_ceil(super::SnapshotSettings::DEFAULT_COUNT);
            }
            StepPlan {
                full: a.max_increments,
                shortened: 0,
            }
        }
        PathControl::Time => {
            if dto.solver.as_ref().is_some_and(|s| s.arc_length.is_some()) {
                return Err(issue(
                    "solver.arc_length",
                    "arc-length settings are given but the path is driven by time: add `path: arc-length` to `solver` (or remove `arc_length`)",
                ));
            }
            model.planned_steps()
        }
    };
    let memory = check_size(dto, &StepCount::planned(&plan, model.time().step, dto))?;
    // A part no condition holds can move as a rigid body: `run` refuses it (the solver's check), `check` warns.
    // Not of a temporary shape, which is built without its programme (the programme is what takes the nodes
    // there): `run` solves the permanent design, whose programme holds them (issue 31: `mesh --state temporary`
    // said the aorta stent would be refused).
    let free = if temporary_shape {
        Vec::new()
    } else {
        crate::solver::diagnose::free_bodies(&model)
    };
    for body in free {
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
    warnings.extend(hot_release_warnings(&model));
    warnings.extend(short_schedule_warning(&model));
    Ok(Built {
        model,
        output,
        warnings,
        notes,
        memory,
        steps: plan,
        bench: bench(dto.bench.as_ref(), section.diameter())?,
    })
}

/// The `bench` block, checked: a finite temperature, at least two diameters per branch, a smallest diameter
/// above the design's wire diameter `wire` (a crimper closed to the wire's own diameter would leave the
/// wire's centreline on the axis).
fn bench(dto: Option<&super::dto::BenchDto>, wire: Real) -> Result<super::BenchSpec> {
    let Some(b) = dto else {
        return Ok(super::BenchSpec::default());
    };
    if let Some(t) = b.temperature
        && !t.is_finite()
    {
        return Err(issue(
            "bench.temperature",
            format!("{t} °C is not a temperature"),
        ));
    }
    if let Some(n) = b.segments
        && n < 3
    {
        return Err(issue(
            "bench.segments",
            format!("a segmented crimper needs at least 3 segments, not {n}"),
        ));
    }
    if let Some(n) = b.diameters
        && n < 2
    {
        return Err(issue(
            "bench.diameters",
            format!("{n} diameters per branch: at least 2 make a curve"),
        ));
    }
    for (field, value, tool) in [
        ("bench.min_diameter", b.min_diameter, "the crimper"),
        ("bench.min_gap", b.min_gap, "the plates"),
    ] {
        if let Some(d) = value
            && d.0 <= wire
        {
            return Err(issue(
                field,
                format!(
                    "{} is not above the wire's diameter {}: {tool} cannot close onto the axis",
                    d.0, wire
                ),
            ));
        }
    }
    Ok(super::BenchSpec {
        temperature: b.temperature,
        rate: b.rate.map(|r| r.0),
        min_diameter: b.min_diameter.map(|d| d.0),
        vessel_diameter: b.vessel_diameter.map(|d| d.0),
        diameters: b.diameters,
        min_gap: b.min_gap.map(|d| d.0),
        segments: b.segments,
    })
}

/// The design's name: its `name`, or the file's stem, checked by the builder's rule for a model name
/// ([`check_name`]) with the design's words.
fn design_name(dto: &DesignDto, default_name: &str) -> Result<String> {
    match &dto.name {
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
            Ok(name.clone())
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
            Ok(default_name.to_string())
        }
    }
}

/// The builder's error at the design's field path.
fn builder_issue(e: BuildError, dto: &DesignDto) -> Issue {
    issue(field_path(&e.field, dto), e.message)
}

/// The design field path of a builder [`Field`]: the builder counts patches, nodes, conditions, loads and probes
/// in the order this module adds them, which is the order of the design's lists.
pub(crate) fn field_path(field: &Field, dto: &DesignDto) -> String {
    match *field {
        Field::Name => "name".into(),
        // The design's snapshot and history times are checked (and those at 0 dropped) before they are given.
        Field::RecordTime { .. } => "output.snapshots.times / output.history.times".into(),
        Field::Obstacle { index, field } => {
            let base = format!("obstacles[{index}]");
            // The obstacles after the design's are a crimp programme's crimper or a crush programme's plates.
            let Some(o) = dto.obstacles.get(index) else {
                return "programme".into();
            };
            let shape = if o.cylinder.is_some() {
                "cylinder"
            } else if o.plane.is_some() {
                "plane"
            } else {
                "lumen"
            };
            match field {
                ObstacleField::Name => format!("{base}.name"),
                ObstacleField::Direction if o.cylinder.is_some() => format!("{base}.cylinder.axis"),
                ObstacleField::Direction if o.plane.is_some() => format!("{base}.plane.normal"),
                ObstacleField::Direction => format!("{base}.lumen"),
                ObstacleField::Schedule if o.cylinder.is_some() => {
                    format!("{base}.cylinder.radius")
                }
                ObstacleField::Schedule if o.plane.is_some() => format!("{base}.plane.offset"),
                ObstacleField::Schedule => format!("{base}.lumen"),
                ObstacleField::Wall if o.wall.is_some() => format!("{base}.wall"),
                ObstacleField::Wall => format!("{base}.{shape}"),
                ObstacleField::Friction => format!("{base}.friction"),
            }
        }
        Field::ContactSettings if dto.contact.is_some() => "contact".into(),
        Field::ContactSettings => "obstacles".into(),
        Field::Patches => "patches".into(),
        Field::Patch { index, field } => {
            let base = format!("patches[{index}]");
            let Some(pd) = dto.patches.get(index) else {
                return base;
            };
            match field {
                PatchField::Name => format!("{base}.name"),
                PatchField::Degree => mesh_key_path(pd.p, &base, "p"),
                PatchField::ControlPoints => mesh_key_path(pd.n, &base, "n"),
                PatchField::Section => format!("{base}.diameter"),
                PatchField::Material => base,
                PatchField::Geometry | PatchField::Angle => {
                    let key = if pd.line.is_some() {
                        "line"
                    } else if pd.arc.is_some() {
                        "arc"
                    } else if pd.helix.is_some() {
                        "helix"
                    } else if pd.sine_wire.is_some() {
                        "sine_wire"
                    } else {
                        "points"
                    };
                    if field == PatchField::Angle {
                        format!("{base}.{key}.angle_deg")
                    } else {
                        format!("{base}.{key}")
                    }
                }
            }
        }
        Field::Stent(field) => stent::field_path(field, dto),
        Field::Materials => "materials".into(),
        Field::Node { index, field } => {
            let base = format!("nodes[{index}]");
            match field {
                NodeField::Name => format!("{base}.name"),
                NodeField::Ends => format!("{base}.ends"),
                NodeField::End(j) => format!("{base}.ends[{j}]"),
                NodeField::At => format!("{base}.at"),
            }
        }
        Field::Condition { index, field } => {
            let base = format!("conditions[{index}]");
            match field {
                ConditionField::Whole => base,
                ConditionField::Node => format!("{base}.node"),
                ConditionField::NodeSet => format!("{base}.node_set"),
                ConditionField::Basis => format!("{base}.basis"),
                ConditionField::SymmetryPlane => format!("{base}.symmetry_plane"),
                ConditionField::Clamp => format!("{base}.clamp"),
                ConditionField::Displacement(i) => format!("{base}.displacement[{i}]"),
                ConditionField::Rotation(i) => format!("{base}.rotation[{i}]"),
                ConditionField::Force(i) => format!("{base}.force[{i}]"),
                ConditionField::Moment(i) => format!("{base}.moment[{i}]"),
                ConditionField::Release => format!("{base}.release"),
            }
        }
        Field::DistributedLoad { index } => format!("distributed_loads[{index}].patch"),
        Field::Temperature => "temperature".into(),
        Field::Time(field) => match field {
            TimeField::End => "time.end",
            TimeField::Step => "time.step",
            TimeField::MinStep => "time.min_step",
            TimeField::ReleaseRamp => "time.release_ramp",
            TimeField::Tolerance => "time.tolerance",
            TimeField::MaxStep => "time.max_step",
        }
        .into(),
        Field::Solver(field) => match field {
            SolverField::Tolerance => "solver.tolerance",
            SolverField::MaxIterations => "solver.max_iterations",
            SolverField::Path => "solver.path",
            SolverField::ArcLength => "solver.arc_length",
            SolverField::Stabilisation => "solver.stabilisation",
            SolverField::DissipatedFraction => "solver.stabilisation.dissipated_fraction",
            SolverField::StabilisationLimit => "solver.stabilisation.limit",
        }
        .into(),
        Field::Probe { index, field } => {
            let base = format!("output.probes[{index}]");
            match field {
                ProbeField::Name => format!("{base}.name"),
                ProbeField::Node => format!("{base}.node"),
                ProbeField::Patch => format!("{base}.patch"),
                ProbeField::U => format!("{base}.u"),
            }
        }
        Field::Programme(field) => match field {
            ProgrammeField::Whole => "programme",
            ProgrammeField::Nodes => "programme.nodes",
            ProgrammeField::RampEnd => "programme.ramp[1]",
            ProgrammeField::Release => "programme.release",
            ProgrammeField::DeltaR => "programme.delta_r",
            ProgrammeField::Temporary => "programme.temporary",
            ProgrammeField::Align => "programme.temporary.align",
        }
        .into(),
    }
}

/// The times of `list` (the design's field `path`), sorted and without repeats, each within `[0, time.end]`.
fn requested_times(
    list: Option<&Vec<NonNegative>>,
    path: &str,
    time: &TimeSettings,
) -> Result<Vec<Real>> {
    let mut times = Vec::new();
    for (k, NonNegative(t)) in list.into_iter().flatten().enumerate() {
        if *t > time.end {
            return Err(issue(
                format!("{path}[{k}]"),
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
    Ok(times)
}

/// The `output:` block's snapshot, recording and field-file settings with their defaults, and the materials' strain limits.
fn output_settings(dto: &DesignDto, time: &TimeSettings) -> Result<super::OutputSettings> {
    let output = dto.output.as_ref();
    use super::{OutputSettings, RecordingSettings, SnapshotSettings};
    let at_least = |value: Option<usize>, default: usize, min: usize, path: &str| match value {
        None => Ok(default),
        Some(v) if v >= min => Ok(v),
        Some(v) => Err(issue(path, format!("{v} must be at least {min}"))),
    };
    let snapshots = output.and_then(|o| o.snapshots.as_ref());
    let times = requested_times(
        snapshots.and_then(|s| s.times.as_ref()),
        "output.snapshots.times",
        time,
    )?;
    let history_times = requested_times(
        output
            .and_then(|o| o.history.as_ref())
            .and_then(|h| h.times.as_ref()),
        "output.history.times",
        time,
    )?;
    let formats: Vec<&str> = match snapshots.and_then(|s| s.formats.as_ref()) {
        None => crate::io::formats::DEFAULT_FORMATS.to_vec(),
        Some(names) => names
            .iter()
            .enumerate()
            .map(
                |(k, name)| match crate::io::formats::format(&name.to_ascii_lowercase()) {
                    Some(format) => Ok(format.extension()),
                    None => Err(issue(
                        format!("output.snapshots.formats[{k}]"),
                        format!(
                            "`{name}` is not a snapshot format; allowed: {}",
                            crate::io::formats::extensions()
                        ),
                    )),
                },
            )
            .collect::<Result<_>>()?,
    };
    // The registry's order, once each.
    let formats = crate::io::formats::FORMATS
        .iter()
        .map(|f| f.extension())
        .filter(|e| formats.contains(e))
        .collect();
    let chosen = snapshots.is_some_and(|s| s.every.is_some() || s.times.is_some());
    let snapshot_settings = SnapshotSettings {
        times,
        // An arc-length path's default is set by `build` once its increments are known.
        every: snapshots.and_then(|s| s.every).unwrap_or(0),
        events: snapshots.and_then(|s| s.events).unwrap_or(true),
        between: snapshots.and_then(|s| s.between).unwrap_or(if chosen {
            0
        } else {
            SnapshotSettings::DEFAULT_BETWEEN
        }),
        formats,
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
        vtk: output.and_then(|o| o.vtk).unwrap_or(true),
        render: output
            .and_then(|o| o.configurations.as_ref())
            .and_then(|c| c.render)
            .unwrap_or(true),
        views: match output
            .and_then(|o| o.configurations.as_ref())
            .and_then(|c| c.views.as_ref())
        {
            None => None,
            Some(views) => Some(
                views
                    .iter()
                    .enumerate()
                    .map(|(k, v)| {
                        crate::io::configurations::View::parse(v).ok_or_else(|| {
                            issue(
                                format!("output.configurations.views[{k}]"),
                                format!(
                                    "`{v}` is not a view; allowed: axonometric, x1-x2, x1-x3, x2-x3"
                                ),
                            )
                        })
                    })
                    .collect::<Result<Vec<_>>>()?,
            ),
        },
    };
    let recording = output.and_then(|o| o.recording.as_ref());
    let recording_settings = RecordingSettings {
        enabled: recording.and_then(|r| r.enabled).unwrap_or(true),
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
        history_times,
        recording: recording_settings,
        strain_limits: std::iter::once(&dto.material)
            .chain(&dto.materials)
            .map(|m| m.strain_limit.map(|l| l.0))
            .collect(),
    })
}

/// The design's temperature field.
fn temperature_field(f: &TemperatureFieldDto) -> Result<TemperatureField> {
    let base = "temperature_field";
    let profile = match (&f.stations, &f.front) {
        (Some(stations), None) => Profile::Stations(
            stations
                .iter()
                .enumerate()
                .map(|(k, st)| {
                    let path = format!("{base}.stations[{k}].T");
                    Ok((st.at.0, time_function(&st.temperature, &path)?))
                })
                .collect::<Result<Vec<_>>>()?,
        ),
        (None, Some(front)) => {
            let path = |key: &str| format!("{base}.front.{key}");
            Profile::Front {
                position: time_function(&front.position, &path("position"))?,
                width: front.width.0,
                behind: time_function(&front.behind, &path("behind"))?,
                ahead: time_function(&front.ahead, &path("ahead"))?,
            }
        }
        _ => {
            return Err(issue(base, "give exactly one of `stations` or `front`"));
        }
    };
    let origin = f.origin.as_ref().map_or_else(Vec3::zeros, vec3);
    TemperatureField::try_new(origin, vec3(&f.direction), profile).map_err(|e| {
        let path = match e {
            FieldError::Direction => format!("{base}.direction"),
            FieldError::Origin => format!("{base}.origin"),
            FieldError::TooFewStations => format!("{base}.stations"),
            FieldError::Stations { index, .. } => format!("{base}.stations[{index}].at"),
            FieldError::Width(_) => format!("{base}.front.width"),
        };
        issue(path, e.to_string())
    })
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

/// The design's patches, with the DTO-level checks (exactly one geometry; a diameter only on a circular
/// section), added to the builder.
fn patches(
    dto: &DesignDto,
    builder: &mut ModelBuilder,
    circular: bool,
    shear_factor: ShearFactor,
    material_names: &[String],
) -> Result<()> {
    let mesh = dto.mesh.as_ref();
    for (k, pd) in dto.patches.iter().enumerate() {
        let base = format!("patches[{k}]");
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
        let (p, n) = match (
            pd.p.or(mesh.and_then(|m| m.p)),
            pd.n.or(mesh.and_then(|m| m.n)),
        ) {
            (Some(p), Some(n)) => (p, n),
            (None, _) => return Err(issue(&base, "no degree: give `p` here or `mesh.p` (p ≥ 2)")),
            (_, None) => {
                return Err(issue(
                    &base,
                    "no number of control points: give `n` here or `mesh.n` (n > p)",
                ));
            }
        };
        let geometry_issue =
            |key: &str, e: GeometryError| issue(format!("{base}.{key}"), e.to_string());
        let shape = if let Some(l) = &pd.line {
            PatchShape::Line {
                from: vec3(&l.from),
                to: vec3(&l.to),
            }
        } else if let Some(a) = &pd.arc {
            PatchShape::Arc {
                centre: vec3(&a.center),
                start: vec3(&a.start),
                axis: vec3(&a.axis),
                angle: a.angle_deg.0.to_radians(),
            }
        } else if let Some(h) = &pd.helix {
            PatchShape::Fitted(Box::new(Helix {
                radius: h.radius.0,
                pitch: h.pitch.0,
                turns: h.turns.0,
                start_angle: h.start_deg.map_or(0.0, |a| a.0.to_radians()),
                placement: placement(&h.origin, &h.axis, &h.x_axis)
                    .map_err(|e| geometry_issue("helix", e))?,
            }))
        } else if let Some(w) = &pd.sine_wire {
            if w.from_deg.0 == w.to_deg.0 {
                return Err(issue(
                    format!("{base}.sine_wire.to_deg"),
                    "the wire must span a non-zero angle: to_deg ≠ from_deg",
                ));
            }
            PatchShape::Fitted(Box::new(SineWire {
                radius: w.radius.0,
                amplitude: w.amplitude.0,
                waves: w.waves.0,
                phase: w.phase_deg.map_or(0.0, |a| a.0.to_radians()),
                from: w.from_deg.0.to_radians(),
                to: w.to_deg.0.to_radians(),
                placement: placement(&w.origin, &w.axis, &w.x_axis)
                    .map_err(|e| geometry_issue("sine_wire", e))?,
            }))
        } else if let Some(pts) = &pd.points {
            let points: Vec<Vec3> = pts.iter().map(vec3).collect();
            PatchShape::Fitted(Box::new(
                point_list_curve(&points).map_err(|e| geometry_issue("points", e))?,
            ))
        } else {
            unreachable!("exactly one geometry was checked above")
        };
        let section = match pd.diameter {
            None => 0,
            Some(Positive(d)) => {
                let path = format!("{base}.diameter");
                if !circular {
                    return Err(issue(
                        path,
                        "only a circular section's diameter can be overridden per patch",
                    ));
                }
                let c = CircularSection::try_with_shear_factor(d, shear_factor)
                    .map_err(|e| issue(&path, e.to_string()))?;
                builder.section(c.into())
            }
        };
        let material = match &pd.material {
            Some(name) => material_index(name, material_names, &format!("patches[{k}].material"))?,
            None => 0,
        };
        let options = PatchOptions {
            section,
            material,
            normal_hint: pd.normal.as_ref().map(vec3),
        };
        builder.patch_with(pd.name.clone(), shape, p, n, options);
    }
    Ok(())
}

/// A `conditions` entry, with the DTO-level checks (one target; a basis or a symmetry plane).
fn condition(k: usize, c: &ConditionDto) -> Result<ConditionSpec> {
    let base = format!("conditions[{k}]");
    let target = match (&c.node, &c.node_set) {
        (Some(name), None) => Target::Node(name.clone()),
        (None, Some(set)) => Target::Set(set.clone()),
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
        (Some(rows), None) => Some(BasisSpec::Axes(Mat3::from_columns(&[
            vec3(&rows[0]),
            vec3(&rows[1]),
            vec3(&rows[2]),
        ]))),
        (None, Some(n)) => Some(BasisSpec::SymmetryPlane(vec3(n))),
        (None, None) => None,
    };
    let three =
        |values: &Option<[ComponentValue; 3]>, field: &str| -> Result<[Option<TimeFunction>; 3]> {
            let mut out: [Option<TimeFunction>; 3] = Default::default();
            for (i, v) in values.iter().flatten().enumerate() {
                if let ComponentValue::Value(f) = v {
                    out[i] = Some(time_function(f, &format!("{base}.{field}[{i}]"))?);
                }
            }
            Ok(out)
        };
    Ok(ConditionSpec {
        target,
        basis,
        clamp: c.clamp,
        displacement: three(&c.displacement, "displacement")?,
        rotation: three(&c.rotation, "rotation")?,
        force: three(&c.force, "force")?,
        moment: three(&c.moment, "moment")?,
        release: c.release.map(|r| r.0),
    })
}

fn distributed_load(k: usize, d: &DistributedLoadDto) -> Result<DistributedLoadSpec> {
    let base = format!("distributed_loads[{k}]");
    let three = |f: &Option<[TimeFn; 3]>, field: &str| -> Result<[TimeFunction; 3]> {
        let mut out: [TimeFunction; 3] = std::array::from_fn(|_| TimeFunction::zero());
        if let Some(fs) = f {
            for (i, fi) in fs.iter().enumerate() {
                out[i] = time_function(fi, &format!("{base}.{field}[{i}]"))?;
            }
        }
        Ok(out)
    };
    Ok(DistributedLoadSpec {
        patches: if d.patch == "all" {
            PatchTarget::All
        } else {
            PatchTarget::Named(d.patch.clone())
        },
        force: three(&d.force, "force")?,
        couple: three(&d.couple, "couple")?,
    })
}

/// The first step of error-controlled stepping when the design gives none, as a fraction of the end time.
pub(crate) const DEFAULT_FIRST_STEP_FRACTION: Real = 1e-3;

/// The time stepping of the design: fixed steps of `step`, or error-controlled ones from `step` (default
/// [`DEFAULT_FIRST_STEP_FRACTION`] of the end time) when a tolerance is given.
fn time_spec(t: &TimeDto) -> Result<TimeSpec> {
    let step = match (t.step, t.tolerance) {
        (Some(Positive(h)), _) => h,
        (None, Some(_)) => t.end.0 * DEFAULT_FIRST_STEP_FRACTION,
        (None, None) => {
            return Err(issue(
                "time.step",
                "missing: give `step` (fixed steps) or `tolerance` (error-controlled steps)",
            ));
        }
    };
    Ok(TimeSpec {
        end: t.end.0,
        step,
        min_step: t.min_step.map(|m| m.0),
        release_ramp: t.release_ramp.map(|r| r.0),
        tolerance: t.tolerance.map(|r| r.0),
        max_step: t.max_step.map(|r| r.0),
    })
}

/// The design's solver settings over the defaults (those of a model with contact when `contact`,
/// [`SolverSettings::for_contact`]).
fn solver_settings(s: Option<&SolverDto>, contact: bool) -> SolverSettings {
    let mut out = if contact {
        SolverSettings::for_contact()
    } else {
        SolverSettings::default()
    };
    if let Some(s) = s {
        if let Some(Positive(t)) = s.tolerance {
            out.tolerance = t;
        }
        if let Some(m) = s.max_iterations {
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
        if let Some(r) = s.rotations {
            out.rotations = match r {
                RotationsDto::Objective => RotationField::Objective,
                RotationsDto::Incremental => RotationField::Incremental,
            };
        }
        if let Some(PathDto::ArcLength) = s.path {
            let mut a = ArcLengthSettings::default();
            if let Some(d) = &s.arc_length {
                a.end_load_factor = d.end.unwrap_or(a.end_load_factor);
                a.max_increments = d.max_increments.unwrap_or(a.max_increments);
                a.target_iterations = d.iterations.unwrap_or(a.target_iterations);
                a.max_growth = d.max_growth.unwrap_or(a.max_growth);
                if let Some(c) = d.constraint {
                    a.constraint = match c {
                        ArcConstraintDto::Cylindrical => ArcConstraint::Cylindrical,
                        ArcConstraintDto::Spherical => ArcConstraint::Spherical,
                    };
                }
            }
            out.path = PathControl::ArcLength(a);
        }
        if let Some(d) = &s.stabilisation {
            let mut st = crate::model::StabilisationSettings::default();
            if let Some(Positive(f)) = d.dissipated_fraction {
                st.dissipated_fraction = f;
            }
            if let Some(Positive(l)) = d.limit {
                st.limit = l;
            }
            st.factor = d.factor.map(|f| f.0);
            out.stabilisation = Some(st);
        }
    }
    out
}

/// A temperature schedule that ends before the run does is held at its last value from there, which a table
/// written for a shorter run (1.75 s of a 3.25 s programme, issue 19) does silently. Time-driven runs only (an
/// arc-length path reads its schedules at `time.end`).
fn short_schedule_warning(model: &crate::model::Model) -> Option<String> {
    let schedule = model.temperature();
    let &(last, value) = schedule.points().last()?;
    let end = model.time().end;
    (model.solver().path.arc_length().is_none()
        && !schedule.is_constant()
        && last < end - model.time().landing_tolerance())
        .then(|| {
            format!(
                "the temperature schedule ends at t = {last}, before the run does ({end}): the temperature is held at its last value, {value} °C, from there (extend the table to the end if that is not meant)"
            )
        })
}

/// A programme that releases its nodes above a material's glass transition fixes no temporary shape: the
/// rubbery device springs back at the release (and Newton meets the snap with step cuts, issue 18). One warning
/// per such material, from the temperature schedule at the release (a temperature field's reference schedule).
fn hot_release_warnings(model: &crate::model::Model) -> Vec<String> {
    let Some(release) = model
        .programme
        .as_ref()
        .and_then(|p| p.release)
        .filter(|&r| r < model.time().end)
    else {
        return Vec::new();
    };
    let temperature = model.temperature().value(release);
    model
        .materials()
        .iter()
        .zip(&model.material_names)
        .filter_map(|(law, name)| {
            let tg = crate::material::ConstitutiveLaw::temperature_shift(law)?.tg();
            (temperature > tg).then(|| {
                format!(
                    "the programme releases its nodes at t = {release} at {temperature} °C, above the glass transition of material `{name}` (Tg = {tg} °C): the device is rubbery there and springs back, so no temporary shape is fixed; cool it below Tg before the release{}",
                    if model.solver().stabilisation.is_some() {
                        ""
                    } else {
                        " (to simulate the snap-back anyway, add `solver: {stabilisation: {}}`: Newton alone meets it with step cuts and may stall)"
                    }
                )
            })
        })
        .collect()
}
