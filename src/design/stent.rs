//! The `stent:` and `programme:` blocks of a design: a generated stent (crowns, bridges, centreline, symmetry)
//! and the programme that drives its nodes to a temporary shape. The geometry is [`crate::geometry::stent`] and
//! its place in the model [`crate::model::stent`]; this module translates the blocks into a [`StentSpec`],
//! a [`StentMesh`] and a [`ProgrammeSpec`] with the checks of the blocks' form, and names the design field of a
//! stent [`StentField`].
//!
//! Every stent family translates its own block behind `FamilyBlock`; [`super::family`] is the registry that
//! the block's `family` key selects from. This file holds the ring family's block and what the families share
//! (centreline, symmetry, meshes, materials, programme).
//!
//! ```yaml
//! stent:
//!   family: ring          # the default; `diamond`: closed diamond cells (its block in `diamond.rs`)
//!   crowns: 6
//!   radius: 20            # crown radius R [length]
//!   amplitude: 5          # h_c: the crown is 2 h_c high
//!   peaks: 6              # crests per crown (the crown has 2 × peaks wire patches)
//!   crown_shape: sinusoidal   # the default; `zigzag`: straight struts between crests and troughs (a Z-ring)
//!   spacing: 15           # d_c along the centreline (optional on arcs and point lists)
//!   rotation_deg: 90      # of each crown about the axis relative to the previous one (default 180/peaks)
//!   bridges: {shape: straight}   # or {shape: sinusoidal, amplitude: 2.5, waves: 1, direction: radial}
//!   centreline: {straight: {origin: [0, 0, 0], direction: [1, 0, 0], reference: [0, 1, 0]}}
//!   symmetry: quarter     # none | half | quarter (the model keeps one sector)
//!   crown_mesh: {p: 6, n: 20}    # optional; default: the top-level `mesh`
//! programme:
//!   kind: radial_contraction
//!   nodes: all_joints
//!   delta_r: 15
//!   ramp: [0, 1]
//!   release: 1.75
//! ```

use super::dto::*;
use super::issue::{Result, issue, mesh_key_path};
use super::vessel::{VesselCentreline, tightest_bend, vessel_centreline};
use crate::geometry::stent::{
    BridgeDirection, BridgeShape, BridgeSpec, CentrelineSpec, CrownShape, CrownSpec, FamilyCounts,
    StentFamily, StentParameter, StentSpec, Symmetry, TemporaryCentreline, TemporarySpec,
    ring_counts,
};
use crate::math::{Real, Vec3};
use crate::model::builder::StentField;
use crate::model::stent::{ProgrammeSpec, ProgrammeTarget, StentMaterials, StentMesh};
use std::sync::Arc;

/// A generated device of a `stent:` block: its family's specification, what `check` says about it, and the
/// vessel of a file centreline.
pub(crate) type Device = (
    Arc<dyn StentFamily>,
    Vec<String>,
    Option<crate::model::Vessel>,
);

/// How a family's `stent:` block becomes its device, with the checks of the block's form: one implementation
/// per family, registered in [`super::family`] under the block's `family` key.
pub(super) trait FamilyBlock {
    /// The device of the block (lengths in units of `metres_per_unit` metres).
    fn device(&self, dto: &StentDto, metres_per_unit: Real) -> Result<Device>;

    /// The device's size from the block alone (the memory estimate's, before anything is generated).
    fn counts(&self, dto: &StentDto) -> FamilyCounts;
}

/// The symmetry a block asks for.
pub(super) fn symmetry(dto: &StentDto) -> Symmetry {
    match dto.symmetry {
        None | Some(SymmetryDto::None) => Symmetry::None,
        Some(SymmetryDto::Half) => Symmetry::Half,
        Some(SymmetryDto::Quarter) => Symmetry::Quarter,
    }
}

/// The copies of the modelled part that make the full device: the symmetry's sectors, 1 for a full model.
pub(super) fn sectors(dto: &StentDto) -> usize {
    if dto.full_model {
        1
    } else {
        symmetry(dto).sectors()
    }
}

/// The ring family (`family: ring`, the default): crowns joined by bridges.
pub(super) struct Ring;

impl FamilyBlock for Ring {
    fn device(&self, dto: &StentDto, metres_per_unit: Real) -> Result<Device> {
        let (spec, notes, vessel) = ring_spec(dto, metres_per_unit)?;
        Ok((Arc::new(spec), notes, vessel))
    }

    fn counts(&self, dto: &StentDto) -> FamilyCounts {
        ring_counts(
            dto.crowns,
            dto.peaks,
            dto.bridges
                .as_ref()
                .map(|b| (b.every.unwrap_or(1), b.first.unwrap_or(1).saturating_sub(1))),
            sectors(dto),
        )
    }
}

/// The field of a stent parameter.
fn spec_path(parameter: StentParameter) -> &'static str {
    use StentParameter as P;
    match parameter {
        P::Crowns => "stent.crowns",
        P::Radius => "stent.radius",
        P::Amplitude => "stent.amplitude",
        P::Peaks => "stent.peaks",
        P::Spacing => "stent.spacing",
        P::Rotation => "stent.rotation_deg",
        P::Symmetry => "stent.symmetry",
        P::Bridges => "stent.bridges",
        P::BridgesEvery => "stent.bridges.every",
        P::BridgesFirst => "stent.bridges.first",
        P::BridgesAmplitude => "stent.bridges.amplitude",
        P::BridgesWaves => "stent.bridges.waves",
        P::BridgesDirection => "stent.bridges.direction",
        P::Centreline => "stent.centreline",
        P::CentrelineAngle => "stent.centreline.arc.angle_deg",
        P::TemporaryRadius => "programme.temporary.radius",
        P::TemporaryCentreline => "programme.temporary.centreline",
    }
}

/// The design field path of a stent field: a parameter's, or the key the crown or bridge mesh came from.
pub(super) fn field_path(field: StentField, dto: &DesignDto) -> String {
    let own = |bridge: bool| {
        dto.stent.as_ref().and_then(|s| {
            if bridge {
                s.bridge_mesh.as_ref()
            } else {
                s.crown_mesh.as_ref()
            }
        })
    };
    let mesh_key = |bridge: bool, given: fn(&MeshDto) -> Option<usize>, key: &str| {
        let own_path = if bridge {
            "stent.bridge_mesh"
        } else {
            "stent.crown_mesh"
        };
        mesh_key_path(own(bridge).and_then(given), own_path, key)
    };
    match field {
        StentField::Whole => "stent".into(),
        // A radius sized from the lumen has no `radius` key: the field that sized it is `oversize`.
        StentField::Parameter(StentParameter::Radius)
            if dto
                .stent
                .as_ref()
                .is_some_and(|s| s.radius.is_none() && s.oversize.is_some()) =>
        {
            "stent.oversize".into()
        }
        StentField::Parameter(p) => spec_path(p).into(),
        StentField::Degree { bridge } => mesh_key(bridge, |m| m.p, "p"),
        StentField::ControlPoints { bridge } => mesh_key(bridge, |m| m.n, "n"),
        StentField::Materials => "stent.materials.crowns".into(),
    }
}

/// The stent's materials by name (`names`: every material's, in model order).
pub(super) fn materials(m: &StentMaterialsDto, names: &[String]) -> Result<StentMaterials> {
    let base = "stent.materials";
    let crowns = match &m.crowns {
        None => Vec::new(),
        Some(OneOrMany::One(name)) => {
            vec![super::materials::material_index(
                name,
                names,
                &format!("{base}.crowns"),
            )?]
        }
        Some(OneOrMany::Many(list)) => list
            .iter()
            .enumerate()
            .map(|(k, name)| {
                super::materials::material_index(name, names, &format!("{base}.crowns[{k}]"))
            })
            .collect::<Result<_>>()?,
    };
    let bridges = match &m.bridges {
        Some(name) => super::materials::material_index(name, names, &format!("{base}.bridges"))?,
        None => 0,
    };
    Ok(StentMaterials { crowns, bridges })
}

/// A centreline of the design; a `file` one is read, cut and fitted ([`super::vessel`]) and returned with it.
pub(super) fn centreline(
    c: &CentrelineDto,
    path: &str,
    metres_per_unit: Real,
    radius_needed: bool,
) -> Result<(CentrelineSpec, Option<VesselCentreline>)> {
    let given = [
        c.straight.is_some(),
        c.arc.is_some(),
        c.points.is_some(),
        c.file.is_some(),
    ];
    if given.iter().filter(|&&g| g).count() != 1 {
        return Err(issue(
            path,
            "give exactly one of `straight`, `arc`, `points` or `file`",
        ));
    }
    if let Some(f) = &c.file {
        let vessel = vessel_centreline(f, &format!("{path}.file"), metres_per_unit, radius_needed)?;
        return Ok((vessel.spec.clone(), Some(vessel)));
    }
    let reference = |r: &Option<Vector>| r.as_ref().map(vec3);
    Ok((
        if let Some(s) = &c.straight {
            CentrelineSpec::Straight {
                origin: s.origin.as_ref().map_or_else(Vec3::zeros, vec3),
                direction: s.direction.as_ref().map_or_else(Vec3::x, vec3),
                reference: reference(&s.reference),
            }
        } else if let Some(a) = &c.arc {
            CentrelineSpec::Arc {
                centre: vec3(&a.center),
                start: vec3(&a.start),
                axis: vec3(&a.axis),
                angle: a.angle_deg.0.to_radians(),
                reference: reference(&a.reference),
            }
        } else if let Some(p) = &c.points {
            CentrelineSpec::Points {
                points: p.points.iter().map(vec3).collect(),
                reference: reference(&p.reference),
            }
        } else {
            unreachable!("exactly one centreline was checked above")
        },
        None,
    ))
}

fn bridges(b: &BridgesDto) -> Result<BridgeSpec> {
    let base = "stent.bridges";
    let shape = match b.shape {
        BridgeShapeDto::Straight => {
            for (given, field) in [
                (b.amplitude.is_some(), "amplitude"),
                (b.waves.is_some(), "waves"),
                (b.direction.is_some(), "direction"),
            ] {
                if given {
                    return Err(issue(
                        format!("{base}.{field}"),
                        "only a sinusoidal bridge has an amplitude, waves and a direction",
                    ));
                }
            }
            BridgeShape::Straight
        }
        BridgeShapeDto::Sinusoidal => BridgeShape::Sinusoidal {
            amplitude: b
                .amplitude
                .ok_or_else(|| {
                    issue(
                        base,
                        "a sinusoidal bridge needs `amplitude` (h_b, in the design's length unit)",
                    )
                })?
                .0,
            waves: b.waves.map_or(1.0, |w| w.0),
            direction: match b.direction {
                None | Some(BridgeDirectionDto::Circumferential) => {
                    BridgeDirection::Circumferential
                }
                Some(BridgeDirectionDto::Radial) => BridgeDirection::Radial,
            },
        },
    };
    let every = b.every.unwrap_or(1);
    let first = b.first.unwrap_or(1);
    if first == 0 {
        return Err(issue(format!("{base}.first"), "crests are numbered from 1"));
    }
    Ok(BridgeSpec {
        shape,
        every,
        first: first - 1,
    })
}

/// The specification of a ring family's `stent:` block (lengths in units of `metres_per_unit` metres), with
/// what `check` says about a file centreline.
fn ring_spec(
    dto: &StentDto,
    metres_per_unit: Real,
) -> Result<(StentSpec, Vec<String>, Option<crate::model::Vessel>)> {
    let sized = dto.oversize.is_some();
    let (axis, vessel) = centreline(&dto.centreline, "stent.centreline", metres_per_unit, sized)?;
    let radius = match (
        dto.radius,
        dto.oversize,
        vessel.as_ref().and_then(|v| v.mean_radius),
    ) {
        (Some(r), None, _) => r.0,
        (None, Some(o), Some(lumen)) => lumen * (1.0 + o.0),
        (Some(_), Some(_), _) => {
            return Err(issue(
                "stent.oversize",
                "give `radius` or `oversize`, not both",
            ));
        }
        (None, Some(_), None) => {
            return Err(issue(
                "stent.oversize",
                "sizing from the lumen needs a `file` centreline with the lumen radius",
            ));
        }
        (None, None, _) => {
            return Err(issue(
                "stent",
                "give `radius` (the crown radius), or `oversize` with a `file` centreline that has the lumen radius",
            ));
        }
    };
    let mut notes = Vec::new();
    if let Some(v) = &vessel {
        notes.push(format!(
            "centreline from {}: a {}-point segment {:.4} long, fitted by a cubic with {} control points within {:.3e} of its points{}",
            dto.centreline.file.as_ref().map_or("", |f| f.path.as_str()),
            v.points,
            v.length,
            v.control_points,
            v.deviation,
            v.mean_radius.map_or_else(String::new, |r| format!(
                "; mean lumen radius {r:.4}, stent radius {radius:.4}"
            ))
        ));
    }
    let mut spec = StentSpec {
        crown: CrownSpec {
            radius,
            amplitude: dto.amplitude.0,
            peaks: dto.peaks,
            shape: match dto.crown_shape {
                None | Some(CrownShapeDto::Sinusoidal) => CrownShape::Sinusoidal,
                Some(CrownShapeDto::Zigzag) => CrownShape::Zigzag,
            },
        },
        crowns: dto.crowns,
        spacing: dto.spacing.map(|d| d.0),
        // Reduced to (−360°, 360°): whole turns do not change the device, and angles of the size of the largest
        // finite numbers have lost their precision.
        rotation: dto
            .rotation_deg
            .map_or(std::f64::consts::PI / dto.peaks.max(1) as Real, |r| {
                (r.0 % 360.0).to_radians()
            }),
        bridges: dto.bridges.as_ref().map(bridges).transpose()?,
        centreline: axis,
        symmetry: symmetry(dto),
        cut: !dto.full_model,
        crown_radii: None,
    };
    if dto.taper {
        let (Some(o), Some(v)) = (dto.oversize, &vessel) else {
            return Err(issue(
                "stent.taper",
                "tapering sizes each crown from the lumen radius at its station: it needs `oversize` and a `file` centreline with the lumen radius",
            ));
        };
        let stations = spec
            .crown_stations()
            .map_err(|e| issue("stent", e.to_string()))?;
        let radii: Vec<Real> = stations
            .iter()
            .map(|&s| lumen_radius_at(&v.vessel, s).map(|r| r * (1.0 + o.0)))
            .collect::<Option<_>>()
            .ok_or_else(|| issue("stent.taper", "the centreline file has no lumen radius"))?;
        let (lo, hi) = radii
            .iter()
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), &r| {
                (lo.min(r), hi.max(r))
            });
        notes.push(format!(
            "crowns sized from the local lumen radius × {:.4}: from {lo:.4} to {hi:.4} (crown 1 {:.4}, crown {} {:.4})",
            1.0 + o.0,
            radii[0],
            radii.len(),
            radii[radii.len() - 1]
        ));
        spec.crown_radii = Some(radii);
    }
    check_centreline_bend(&spec.centreline, spec.radius_range().1)?;
    Ok((spec, notes, vessel.map(|v| v.vessel)))
}

/// A point-list or file centreline must not bend tighter than the stent's largest radius `largest`, or the
/// crowns would fold onto themselves.
pub(super) fn check_centreline_bend(centreline: &CentrelineSpec, largest: Real) -> Result<()> {
    if let Some((bend, u)) = tightest_bend(centreline)
        && bend < largest
    {
        let (field, advice) = match centreline {
            CentrelineSpec::Points { .. } => (
                "stent.centreline.points",
                "spread the points or lower their bend",
            ),
            _ => (
                "stent.centreline.file",
                "smooth it more or choose another segment",
            ),
        };
        return Err(issue(
            field,
            format!(
                "the centreline bends with a radius of curvature {} (at {:.0} % of its length), less than the stent radius {}: the crowns would fold onto themselves; {advice}",
                crate::math::Short(bend),
                100.0 * u,
                crate::math::Short(largest)
            ),
        ));
    }
    Ok(())
}

/// The lumen radius of the vessel at arc length `s` along its sampled centreline (linear between samples,
/// clamped to the ends); `None` without a radius.
fn lumen_radius_at(vessel: &crate::model::Vessel, s: Real) -> Option<Real> {
    let radius = vessel.radius.as_ref()?;
    let mut arc = 0.0;
    for (k, w) in vessel.points.windows(2).enumerate() {
        let step = (w[1] - w[0]).norm();
        if s <= arc + step || k + 2 == vessel.points.len() {
            let f = if step > 0.0 {
                ((s - arc) / step).clamp(0.0, 1.0)
            } else {
                0.0
            };
            return Some(radius[k] + f * (radius[k + 1] - radius[k]));
        }
        arc += step;
    }
    radius.first().copied()
}

/// The crown and bridge discretisations: each role's own mesh, else the design's.
pub(crate) fn mesh(dto: &StentDto, mesh: Option<&MeshDto>) -> Result<StentMesh> {
    let pick = |own: Option<&MeshDto>, own_path: &str| -> Result<(usize, usize)> {
        let one = |f: fn(&MeshDto) -> Option<usize>, key: &str| {
            own.and_then(f).or(mesh.and_then(f)).ok_or_else(|| {
                issue(
                    "stent",
                    format!(
                        "no `{key}` for the stent's patches: give `mesh.{key}` or `{own_path}.{key}`"
                    ),
                )
            })
        };
        Ok((one(|m| m.p, "p")?, one(|m| m.n, "n")?))
    };
    Ok(StentMesh {
        crown: pick(dto.crown_mesh.as_ref(), "stent.crown_mesh")?,
        bridge: pick(dto.bridge_mesh.as_ref(), "stent.bridge_mesh")?,
    })
}

/// The programme of a `programme:` block, with the checks of its form (which fields go with which kind).
pub(crate) fn programme(dto: &ProgrammeDto, metres_per_unit: Real) -> Result<ProgrammeSpec> {
    let base = "programme";
    let tool = matches!(dto.kind, ProgrammeKindDto::Crimp | ProgrammeKindDto::Crush);
    if let Some(n) = dto.segments {
        if dto.kind != ProgrammeKindDto::Crimp {
            return Err(issue(
                format!("{base}.segments"),
                "`segments` (a segmented-head crimper) belongs to `kind: crimp`",
            ));
        }
        if n < 3 {
            return Err(issue(
                format!("{base}.segments"),
                format!("a segmented crimper needs at least 3 segments, not {n}"),
            ));
        }
    }
    if dto.open.is_some() && !tool {
        return Err(issue(
            format!("{base}.open"),
            "`open` (the tool's opening time) belongs to `kind: crimp` or `crush`",
        ));
    }
    let target = match dto.kind {
        ProgrammeKindDto::RadialContraction | ProgrammeKindDto::Crimp | ProgrammeKindDto::Crush => {
            if dto.temporary.is_some() {
                return Err(issue(
                    format!("{base}.temporary"),
                    "`temporary` belongs to `kind: target_shape`; a radial contraction, a crimp or a crush needs only `delta_r`",
                ));
            }
            let Some(Positive(delta_r)) = dto.delta_r else {
                return Err(issue(
                    base,
                    "a radial contraction, a crimp or a crush needs `delta_r` (the radius change, in the design's length unit)",
                ));
            };
            let open = dto
                .open
                .map_or(0.1 * (dto.ramp[1].0 - dto.ramp[0].0), |o| o.0);
            match dto.kind {
                ProgrammeKindDto::Crimp => ProgrammeTarget::Crimp {
                    delta_r,
                    open,
                    segments: dto.segments,
                },
                ProgrammeKindDto::Crush => ProgrammeTarget::Crush { delta_r, open },
                _ => ProgrammeTarget::RadialContraction { delta_r },
            }
        }
        ProgrammeKindDto::TargetShape => {
            if dto.delta_r.is_some() {
                return Err(issue(
                    format!("{base}.delta_r"),
                    "`delta_r` belongs to `kind: radial_contraction`, `crimp` or `crush`; a target shape needs `temporary`",
                ));
            }
            let Some(t) = &dto.temporary else {
                return Err(issue(
                    base,
                    "a target shape needs `temporary` (e.g. {straighten: true, radius: 5})",
                ));
            };
            let tpath = format!("{base}.temporary");
            let centreline = match (t.straighten, &t.centreline) {
                (true, Some(_)) => {
                    return Err(issue(
                        format!("{tpath}.centreline"),
                        "give `straighten: true` or a `centreline`, not both",
                    ));
                }
                (true, None) => TemporaryCentreline::Straightened,
                (false, Some(c)) => TemporaryCentreline::Given(
                    centreline(c, &format!("{tpath}.centreline"), metres_per_unit, false)?.0,
                ),
                (false, None) => TemporaryCentreline::Same,
            };
            if matches!(centreline, TemporaryCentreline::Same) && t.radius.is_none() {
                return Err(issue(
                    tpath,
                    "the temporary shape equals the permanent one: give `straighten: true`, a `centreline` or a `radius`",
                ));
            }
            ProgrammeTarget::TargetShape {
                temporary: TemporarySpec {
                    centreline,
                    radius: t.radius.map(|r| r.0),
                },
                align: t.align.unwrap_or(true),
            }
        }
    };
    Ok(ProgrammeSpec {
        target,
        node_set: dto.nodes.clone().unwrap_or_else(|| "all_joints".into()),
        ramp: (dto.ramp[0].0, dto.ramp[1].0),
        release: dto.release.map(|r| r.0),
    })
}
