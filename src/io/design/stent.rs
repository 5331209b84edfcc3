//! The `stent:` and `programme:` blocks of a design: a generated stent (crowns, bridges, centreline, symmetry)
//! and the programme that drives its nodes to a temporary shape. The geometry itself is
//! [`crate::geometry::stent`]; this module reads the parameters, fits the patches, makes the nodes with their
//! symmetry conditions and node sets, and builds the [`Programme`].
//!
//! ```yaml
//! stent:
//!   crowns: 6
//!   radius: 20            # crown radius R [length]
//!   amplitude: 5          # h_c: the crown is 2 h_c high
//!   peaks: 6              # crests per crown (the crown has 2 × peaks wire patches)
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
use super::issue::{FIT_WARNING_FRACTION, Issue, Result, issue};
use crate::geometry::GeometryError;
use crate::geometry::fit::{FitSettings, best_fit_rigid, fit_curve};
use crate::geometry::frame::normal_to;
use crate::geometry::primitives;
use crate::geometry::stent::{
    BridgeDirection, BridgeShape, BridgeSpec, CentrelineSpec, CrownSpec, PatchRole, StentGeometry,
    StentParameter, StentSpec, Symmetry, TemporaryCentreline, TemporarySpec, WireEnd,
};
use crate::material::{Section, SectionProperties};
use crate::math::{Mat3, Real, Vec3};
use crate::model::{
    Component, DrivenNode, End, Node, NodeConditions, Patch, PatchEnd, Programme, ProgrammeKind,
};
use std::collections::BTreeMap;

/// The temporary node positions moved by the rigid motion that best fits the driven nodes (`set`) of the FULL
/// device — every node mirrored about every combination of symmetry planes, weights shared among the copies —
/// onto their permanent positions ([`best_fit_rigid`]). A free device has no preferred placement once released;
/// placing the temporary shape this way gives its displacement `η_temp = P_temp − P_0` no rigid part, so the
/// gauge that fixes the free device's rigid motion at the release ([`crate::solver::gauge`]) holds it where a full
/// recovery brings every node back to `P_0`. By symmetry of the mirrored point sets the fitted motion respects
/// the symmetry planes.
fn align_temporary(
    geometry: &StentGeometry,
    positions: &[Vec3],
    set: &[usize],
) -> Option<Vec<Vec3>> {
    let planes: Vec<(Vec3, Vec3)> = geometry
        .symmetry_planes
        .iter()
        .map(|p| (p.point, p.normal.normalize()))
        .collect();
    let reflect = |x: Vec3, mask: usize| {
        planes.iter().enumerate().fold(x, |x, (i, (p, n))| {
            if mask >> i & 1 == 1 {
                x - n * (2.0 * n.dot(&(x - p)))
            } else {
                x
            }
        })
    };
    let copies = 1usize << planes.len();
    let (mut from, mut to, mut weights) = (Vec::new(), Vec::new(), Vec::new());
    for &k in set {
        for mask in 0..copies {
            from.push(reflect(positions[k], mask));
            to.push(reflect(geometry.nodes[k].position, mask));
            weights.push(geometry.nodes[k].multiplicity as Real / copies as Real);
        }
    }
    let (r, t) = best_fit_rigid(&from, &to, &weights)?;
    Some(positions.iter().map(|p| r * p + t).collect())
}

fn vec3(v: &Vector) -> Vec3 {
    Vec3::new(v[0].0, v[1].0, v[2].0)
}

/// The generated stent, ready to be merged into the model (its patches and nodes come first).
#[derive(Debug, Clone)]
pub struct GeneratedStent {
    /// The specification it was generated from.
    pub spec: StentSpec,
    /// The analytic device.
    pub geometry: StentGeometry,
    /// Fitted patches, in the order of `geometry.patches`.
    pub patches: Vec<Patch>,
    /// Nodes, in the order of `geometry.nodes`, with their symmetry conditions.
    pub nodes: Vec<Node>,
}

/// Maps a generator parameter name to its field path under `stent` (or `programme`).
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

fn geometry_issue(e: GeometryError) -> Issue {
    match e {
        GeometryError::InvalidStent { parameter, reason } => issue(spec_path(parameter), reason),
        e => issue("stent", e.to_string()),
    }
}

fn centreline(c: &CentrelineDto, path: &str) -> Result<CentrelineSpec> {
    let given = [c.straight.is_some(), c.arc.is_some(), c.points.is_some()];
    if given.iter().filter(|&&g| g).count() != 1 {
        return Err(issue(
            path,
            "give exactly one of `straight`, `arc` or `points`",
        ));
    }
    let reference = |r: &Option<Vector>| r.as_ref().map(vec3);
    Ok(if let Some(s) = &c.straight {
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
    })
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

/// The specification of a `stent:` block.
pub fn spec(dto: &StentDto) -> Result<StentSpec> {
    Ok(StentSpec {
        crown: CrownSpec {
            radius: dto.radius.0,
            amplitude: dto.amplitude.0,
            peaks: dto.peaks,
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
        centreline: centreline(&dto.centreline, "stent.centreline")?,
        symmetry: match dto.symmetry {
            None | Some(SymmetryDto::None) => Symmetry::None,
            Some(SymmetryDto::Half) => Symmetry::Half,
            Some(SymmetryDto::Quarter) => Symmetry::Quarter,
        },
        cut: !dto.full_model,
    })
}

/// `(p, n)` of a role: its own mesh, else the design's.
fn discretisation(
    own: Option<&MeshDto>,
    own_path: &str,
    mesh: Option<&MeshDto>,
) -> Result<(usize, usize)> {
    let pick = |f: fn(&MeshDto) -> Option<usize>, key: &str| -> Result<(usize, String)> {
        match (own.and_then(f), mesh.and_then(f)) {
            (Some(v), _) => Ok((v, format!("{own_path}.{key}"))),
            (None, Some(v)) => Ok((v, format!("mesh.{key}"))),
            (None, None) => Err(issue(
                "stent",
                format!(
                    "no `{key}` for the stent's patches: give `mesh.{key}` or `{own_path}.{key}`"
                ),
            )),
        }
    };
    let (p, p_path) = pick(|m| m.p, "p")?;
    let (n, n_path) = pick(|m| m.n, "n")?;
    if p < 2 {
        return Err(issue(
            p_path,
            format!("degree p = {p} is too low: collocation of the strong form needs p ≥ 2"),
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

/// Completes an orthonormal right-handed basis whose first axis is the unit `n`.
fn basis_from_normal(n: &Vec3) -> Mat3 {
    let e2 = normal_to(n, None);
    Mat3::from_columns(&[*n, e2, n.cross(&e2)])
}

/// Generates the stent of a `stent:` block: fitted patches (section 0, or a half section for patches lying in
/// a symmetry plane, appended to `sections`), nodes with their symmetry conditions.
pub fn generate(
    dto: &StentDto,
    mesh: Option<&MeshDto>,
    sections: &mut Vec<Section>,
    poisson: Real,
    warnings: &mut Vec<String>,
) -> Result<GeneratedStent> {
    let spec = spec(dto)?;
    let geometry = spec.generate().map_err(geometry_issue)?;
    let crown_pn = discretisation(dto.crown_mesh.as_ref(), "stent.crown_mesh", mesh)?;
    let bridge_pn = discretisation(dto.bridge_mesh.as_ref(), "stent.bridge_mesh", mesh)?;
    let full = sections[0];
    let mut half_section = None;
    let mut patches = Vec::with_capacity(geometry.patches.len());
    let mut worst: Option<(Real, &str)> = None;
    for g in &geometry.patches {
        let (p, n) = match g.role {
            PatchRole::Crown { .. } => crown_pn,
            PatchRole::Bridge { .. } => bridge_pn,
        };
        let (curve, fit_error) = match g.straight_segment() {
            Some((a, b)) => (
                primitives::line(a, b, p, n).map_err(|e| issue("stent", e.to_string()))?,
                None,
            ),
            None => {
                let fit = fit_curve(&g.curve, p, n, &FitSettings::default())
                    .map_err(|e| issue("stent", format!("patch `{}`: {e}", g.name)))?;
                if worst.is_none_or(|(w, _)| fit.max_deviation > w) {
                    worst = Some((fit.max_deviation, &g.name));
                }
                (fit.curve, Some(fit.max_deviation))
            }
        };
        let section = match g.in_plane {
            None => 0,
            Some(_) => *half_section.get_or_insert_with(|| {
                // Half of every stiffness: the two halves of the full model share this rod.
                sections.push(Section::Properties(SectionProperties {
                    area: 0.5 * full.area(),
                    second_moment: 0.5 * full.second_moment(),
                    polar_moment: 0.5 * full.polar_moment(),
                    shear_factor: full.shear_factor(poisson),
                    drawing_diameter: full.diameter(),
                }));
                sections.len() - 1
            }),
        };
        patches.push(Patch {
            name: g.name.clone(),
            curve,
            normal_hint: Some(g.normal_hint),
            section,
            material: 0,
            fit_error,
        });
    }
    if let Some((dev, name)) = worst {
        let d = full.diameter();
        if dev > FIT_WARNING_FRACTION * d {
            warnings.push(format!(
                "stent patch `{name}`: the spline fit deviates up to {dev:.3e} from the curve, {:.1}% of the wire diameter; raise n",
                100.0 * dev / d
            ));
        }
    }
    let nodes = geometry
        .nodes
        .iter()
        .map(|g| {
            let mut conditions = NodeConditions::default();
            if let Some(k) = g.symmetry_plane {
                conditions.basis = basis_from_normal(&geometry.symmetry_planes[k].normal);
                for i in [0, 4, 5] {
                    conditions.components[i] = Component::fixed();
                }
            }
            Node {
                name: g.name.clone(),
                ends: g
                    .ends
                    .iter()
                    .map(|&(patch, end)| PatchEnd {
                        patch,
                        end: match end {
                            WireEnd::Start => End::Start,
                            WireEnd::End => End::End,
                        },
                    })
                    .collect(),
                position: g.position,
                conditions,
            }
        })
        .collect();
    Ok(GeneratedStent {
        spec,
        geometry,
        patches,
        nodes,
    })
}

/// The node sets of a generated stent (node indices are the same in the model: the stent's nodes come first).
pub fn node_sets(stent: &GeneratedStent) -> BTreeMap<String, Vec<usize>> {
    stent.geometry.node_sets.clone()
}

/// The symmetry planes of a generated stent as `(point, normal)`.
pub fn symmetry_planes(stent: &GeneratedStent) -> Vec<(Vec3, Vec3)> {
    stent
        .geometry
        .symmetry_planes
        .iter()
        .map(|p| (p.point, p.normal))
        .collect()
}

/// Builds the programme of a `programme:` block and applies it to the stent's nodes.
pub fn programme(
    dto: &ProgrammeDto,
    stent: Option<&GeneratedStent>,
    nodes: &mut [Node],
    end_time: Real,
    warnings: &mut Vec<String>,
) -> Result<Programme> {
    let base = "programme";
    let Some(stent) = stent else {
        return Err(issue(
            base,
            "a programme drives the nodes of a generated stent: add a `stent` block",
        ));
    };
    let set_name = dto.nodes.clone().unwrap_or_else(|| "all_joints".into());
    let sets = &stent.geometry.node_sets;
    let Some(set) = sets.get(&set_name) else {
        let known: Vec<&str> = sets.keys().map(String::as_str).collect();
        return Err(issue(
            format!("{base}.nodes"),
            format!(
                "no node set {}; the stent has: {}",
                super::quote::quoted(&set_name),
                known.join(", ")
            ),
        ));
    };
    if set.is_empty() {
        return Err(issue(
            format!("{base}.nodes"),
            format!("node set {} is empty", super::quote::quoted(&set_name)),
        ));
    }
    let (t0, t1) = (dto.ramp[0].0, dto.ramp[1].0);
    if t1 <= t0 {
        return Err(issue(
            format!("{base}.ramp[1]"),
            format!(
                "programme times must increase: the ramp ends at t = {t1}, not after its start t = {t0}"
            ),
        ));
    }
    let release = dto.release.map(|r| r.0);
    if let Some(r) = release {
        if r < t1 {
            return Err(issue(
                format!("{base}.release"),
                format!(
                    "programme times must increase: the release at t = {r} comes before the end of the ramp (t = {t1})"
                ),
            ));
        }
        if r >= end_time {
            warnings.push(format!(
                "the programme releases at t = {r}, at or after the end of the run ({end_time}): the nodes are never released"
            ));
        }
    }
    if t1 > end_time {
        warnings.push(format!(
            "the programme's ramp ends at t = {t1}, after the end of the run ({end_time})"
        ));
    }
    let geometry = &stent.geometry;
    let radius = stent.spec.crown.radius;
    let (kind, targets): (ProgrammeKind, Vec<Vec3>) = match dto.kind {
        ProgrammeKindDto::RadialContraction => {
            if dto.temporary.is_some() {
                return Err(issue(
                    format!("{base}.temporary"),
                    "`temporary` belongs to `kind: target_shape`; a radial contraction needs only `delta_r`",
                ));
            }
            let Some(Positive(delta_r)) = dto.delta_r else {
                return Err(issue(
                    base,
                    "a radial contraction needs `delta_r` (the radius change, in the design's length unit)",
                ));
            };
            if delta_r >= radius {
                return Err(issue(
                    format!("{base}.delta_r"),
                    format!(
                        "Δr = {delta_r} must be smaller than the crown radius R = {radius}: the nodes would reach or cross the axis"
                    ),
                ));
            }
            (
                ProgrammeKind::RadialContraction { delta_r },
                geometry.nodes.iter().map(|n| -n.radial * delta_r).collect(),
            )
        }
        ProgrammeKindDto::TargetShape => {
            if dto.delta_r.is_some() {
                return Err(issue(
                    format!("{base}.delta_r"),
                    "`delta_r` belongs to `kind: radial_contraction`; a target shape needs `temporary`",
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
                (false, Some(c)) => {
                    TemporaryCentreline::Given(centreline(c, &format!("{tpath}.centreline"))?)
                }
                (false, None) => TemporaryCentreline::Same,
            };
            if matches!(centreline, TemporaryCentreline::Same) && t.radius.is_none() {
                return Err(issue(
                    tpath,
                    "the temporary shape equals the permanent one: give `straighten: true`, a `centreline` or a `radius`",
                ));
            }
            let temporary = TemporarySpec {
                centreline,
                radius: t.radius.map(|r| r.0),
            };
            let positions = stent
                .spec
                .temporary_node_positions(geometry, &temporary)
                .map_err(geometry_issue)?;
            let positions = if t.align.unwrap_or(true) {
                align_temporary(geometry, &positions, set).ok_or_else(|| {
                    issue(
                        format!("{tpath}.align"),
                        "the driven nodes do not define a rigid placement",
                    )
                })?
            } else {
                positions
            };
            (
                ProgrammeKind::TargetShape,
                positions
                    .iter()
                    .zip(&geometry.nodes)
                    .map(|(p, n)| p - n.position)
                    .collect(),
            )
        }
    };
    let programme = Programme {
        kind,
        node_set: set_name,
        nodes: set
            .iter()
            .map(|&k| {
                let g = &geometry.nodes[k];
                DrivenNode {
                    node: k,
                    position: g.position,
                    target: targets[k],
                    axis_point: g.axis_point,
                    axis_direction: g.axis_tangent,
                    radius,
                    weight: g.multiplicity as Real,
                }
            })
            .collect(),
        ramp: (t0, t1),
        release,
    };
    programme
        .apply(nodes)
        .map_err(|e| issue(format!("{base}.temporary"), e.to_string()))?;
    Ok(programme)
}
