//! The design's `obstacles:` and `contact:` blocks: the surfaces the rods touch and how contact is enforced,
//! into the builder's [`Contact`] (the physics: `crate::model::obstacle`, `crate::solver::terms::contact`).
//!
//! ```yaml
//! obstacles:
//!   - name: sheath
//!     cylinder: {point: [0, 0, 0], axis: [1, 0, 0], radius: 5.4}
//!     from: 1.8                   # put in place at t = 1.8 (default: from the start)
//!     until: 2.4                  # withdrawn at t = 2.4 (default: never)
//!   - name: plate
//!     plane: {point: [0, 0, -6], normal: [0, 0, 1], offset: [[0, 0], [1, 2]]}
//!   - name: vessel
//!     lumen: {}                   # the lumen of the stent's vessel file (`stent.centreline.file`)
//!     from: 2.25
//!     wall: {E: 0.5, thickness: 0.9}   # compliant at its local radius where each wire touches
//!   - name: sheath
//!     lumen: {radius: 3.5}        # a tube of its own radius along the vessel's centreline
//!     from: 2.25
//!     until: 2.6
//!   - name: tube
//!     cylinder: {point: [0, 0, 0], axis: [1, 0, 0], radius: 21}
//!     wall: {E: 1.0, thickness: 0.5}   # compliant (width: default the wire's diameter); rigid without it
//!     friction: 0.1               # Coulomb coefficient μ between the wires and this surface (default 0)
//! contact: {penalty: 2500, tolerance: 0.006, regularisation: 0.0006, max_updates: 10, wires: true}
//! ```
//!
//! `wires: true` adds contact between the device's own wires (struts closing on each other when crimped, a wire
//! on its mirror image across a symmetry cut; `crate::solver::terms::wires`) with the same law and settings; it
//! needs no obstacle. Off by default: the wires' contact couples patches, so the Newton systems are solved by the
//! general sparse LU while wires touch, and a run without it still reports wires that pass through each other.
//!
//! A name of our own for each surface, because the words a designer uses (crimper, sheath, vessel, plate) are
//! roles, not shapes: the shape is the key (`cylinder`, `plane`, `lumen`), the role is the name, which the outputs use.
//!
//! **Defaults** (stentkit's choice, stated in `contact`'s schema): the penalty is `E_∞ I / d⁴` (`E_∞` the
//! material's relaxed, rubbery modulus — the softest it gets —, `I` and `d` the section's second moment and
//! (drawing) diameter; `E_∞ π / 64` for a circular wire): the line stiffness, per unit length, of the wire bent
//! over a length of its own diameter, the stiffest bending response a rod model represents (`E I / ℓ⁴` falls
//! as `ℓ⁻⁴` for the longer waves a device bends in). The law is then stiffer than anything it pushes against at
//! the scale of the wire, and no stiffer: the augmented-Lagrange updates, not the penalty, bring the
//! penetration below its tolerance. A penalty orders of magnitude above the structure's stiffness makes every
//! point that touches a step for Newton: measured on `designs/straight_stent_crimped.yaml` (1301 steps of
//! 2.5 ms, with the extrapolated start a model with contact has and the step limit), this default (3.96 N/mm²)
//! and 30 N/mm² finish without a cut (262 and 279 factorisations) and agree within 1e-3 in the crimp force
//! (0.1666 N) and the final recovery ratio (0.0141); the instantaneous modulus (2394 MPa, the default before)
//! gets the same force and recovery with 18 cuts and 603 factorisations; started from the last state and
//! without the step limit it took 1632 cuts and 2545 steps. A design may give its own. The tolerance on
//! penetration is 1 % of the wire diameter (what a drawing of the wire cannot show); the law's transition band
//! is a tenth of the tolerance; at most 10 augmented-Lagrange updates per step besides the one between steps.
//! A `programme` of `kind: crimp` adds its crimper after the design's obstacles, one of `kind: crush` its plates.
//!
//! **Friction** is a property of an obstacle (`friction: μ`, the pair of surfaces that touch), so friction
//! without contact cannot be written; the crimper of a crimp programme is frictionless.

use super::dto::{ContactDto, DesignDto, ObstacleDto, Positive, ProgrammeKindDto, vec3};
use super::issue::{Result, issue};
use crate::geometry::fit::smooth_points;
use crate::material::Section;
use crate::math::{Real, Vec3};
use crate::model::{
    Contact, ContactSettings, Lumen, Obstacle, Surface, TimeFunction, Vessel, Wall,
};

/// The contact of a design (`None` when it has no obstacle, no `contact` block and no crimper); `section` is
/// the design's wire section, `vessel` the vessel of its file centreline.
pub(crate) fn contact(
    dto: &DesignDto,
    section: &Section,
    vessel: Option<&Vessel>,
) -> Result<Option<Contact>> {
    let diameter = section.diameter();
    let tool = dto
        .programme
        .as_ref()
        .is_some_and(|p| matches!(p.kind, ProgrammeKindDto::Crimp | ProgrammeKindDto::Crush));
    if dto.obstacles.is_empty() && !tool {
        return match &dto.contact {
            Some(c) if c.wires == Some(true) => Ok(None),
            Some(_) => Err(issue(
                "contact",
                "contact settings without anything to touch: add `obstacles` (or a `programme` of `kind: crimp` or `crush`), set `wires: true` for contact between the device's wires, or remove `contact`",
            )),
            None => Ok(None),
        };
    }
    let obstacles = dto
        .obstacles
        .iter()
        .enumerate()
        .map(|(k, o)| obstacle(o, &format!("obstacles[{k}]"), diameter, vessel))
        .collect::<Result<Vec<_>>>()?;
    Ok(Some(Contact {
        obstacles,
        settings: settings(dto.contact.as_ref(), dto, section),
    }))
}

/// The settings of the contact between the device's wires (`contact: {wires: true}`): the block's law, with the
/// same defaults as the surfaces'.
pub(crate) fn wire_contact(dto: &DesignDto, section: &Section) -> Option<ContactSettings> {
    let c = dto.contact.as_ref().filter(|c| c.wires == Some(true))?;
    Some(settings(Some(c), dto, section))
}

/// The settings of a `contact` block with the module's defaults.
fn settings(c: Option<&ContactDto>, dto: &DesignDto, section: &Section) -> ContactSettings {
    let value = |f: fn(&ContactDto) -> Option<Positive>| c.and_then(f).map(|v| v.0);
    let tolerance = value(|c| c.tolerance).unwrap_or(0.01 * section.diameter());
    ContactSettings {
        penalty: value(|c| c.penalty)
            .unwrap_or(dto.material.e_inf.0 * section.second_moment() / section.diameter().powi(4)),
        regularisation: value(|c| c.regularisation).unwrap_or(0.1 * tolerance),
        tolerance,
        max_updates: c.and_then(|c| c.max_updates).unwrap_or(10),
    }
}

/// A unit vector from a design vector, refused at `path` when it is zero.
fn unit(v: &super::dto::Vector, path: String) -> Result<Vec3> {
    let v = vec3(v);
    let norm = v.norm();
    if norm > 0.0 {
        Ok(v / norm)
    } else {
        Err(issue(path, "a direction must not be zero"))
    }
}

/// The lumen of `vessel` as a surface: its sampled centreline (the file's smoothing spline at up to 1000
/// points, `super::vessel`) fitted again within a thousandth of the smallest lumen radius, by chord length
/// (`smooth_points`), and its radius at each sample's chord parameter.
fn lumen(vessel: Option<&Vessel>, path: &str) -> Result<Lumen> {
    let Some((vessel, radii)) = vessel.and_then(|v| v.radius.as_ref().map(|r| (v, r))) else {
        return Err(issue(
            path,
            "a lumen needs the stent's vessel: a `stent.centreline.file` whose points carry the lumen radius",
        ));
    };
    let smallest = radii.iter().copied().fold(Real::INFINITY, Real::min);
    let fit = smooth_points(&vessel.points, 1e-3 * smallest).map_err(|e| {
        issue(
            path,
            format!("the vessel's centreline could not be fitted: {e}"),
        )
    })?;
    let mut chord = vec![0.0];
    for w in vessel.points.windows(2) {
        chord.push(chord[chord.len() - 1] + (w[1] - w[0]).norm());
    }
    let total = chord[chord.len() - 1];
    let table = chord
        .iter()
        .zip(radii)
        .map(|(c, &r)| (c / total, r))
        .collect();
    Lumen::try_new(fit.curve, table).map_err(|e| issue(path, e))
}

/// One obstacle of the list, at `base` (`obstacles[k]`).
fn obstacle(
    o: &ObstacleDto,
    base: &str,
    diameter: Real,
    vessel: Option<&Vessel>,
) -> Result<Obstacle> {
    let time_function = |f, key: &str| super::dto::time_function(f, &format!("{base}.{key}"));
    let surface = match (&o.cylinder, &o.plane, &o.lumen) {
        (None, None, Some(l)) => {
            let lumen = lumen(vessel, &format!("{base}.lumen"))?;
            // A radius of its own: the centreline's tube of radius 1 scaled by it.
            match (&l.radius, &l.scale) {
                (Some(_), Some(_)) => {
                    return Err(issue(
                        format!("{base}.lumen.scale"),
                        "give the lumen a `radius` of its own or a `scale` on the file's radius, not both",
                    ));
                }
                (Some(r), None) => {
                    let lo = lumen.centreline().knots().domain().0;
                    let unit = Lumen::try_new(lumen.centreline().clone(), vec![(lo, 1.0)])
                        .map_err(|e| issue(format!("{base}.lumen"), e))?;
                    Surface::Lumen(unit.with_scale(time_function(r, "lumen.radius")?))
                }
                (None, Some(f)) => {
                    Surface::Lumen(lumen.with_scale(time_function(f, "lumen.scale")?))
                }
                (None, None) => Surface::Lumen(lumen),
            }
        }
        (Some(c), None, None) => Surface::Cylinder {
            point: vec3(&c.point),
            axis: unit(&c.axis, format!("{base}.cylinder.axis"))?,
            radius: time_function(&c.radius, "cylinder.radius")?,
        },
        (None, Some(p), None) => Surface::Plane {
            point: vec3(&p.point),
            normal: unit(&p.normal, format!("{base}.plane.normal"))?,
            offset: match &p.offset {
                Some(f) => time_function(f, "plane.offset")?,
                None => TimeFunction::constant(0.0),
            },
        },
        _ => {
            return Err(issue(
                base,
                "give exactly one surface: `cylinder`, `plane` or `lumen`",
            ));
        }
    };
    let wall = match &o.wall {
        None => Wall::Rigid,
        Some(w) => {
            let (Some(modulus), Some(thickness)) = (w.modulus, w.thickness) else {
                return Err(issue(
                    format!("{base}.wall"),
                    "a compliant wall needs its Young's modulus `E` and its `thickness` (and takes `width`, default the wire's diameter); remove `wall` for a rigid one",
                ));
            };
            Wall::Compliant {
                modulus: modulus.0,
                thickness: thickness.0,
                width: w.width.map_or(diameter, |b| b.0),
            }
        }
    };
    let from = o.from.map_or(0.0, |f| f.0);
    let until = o.until.map(|u| u.0);
    if let Some(u) = until
        && u <= from
    {
        return Err(issue(
            format!("{base}.until"),
            format!(
                "the obstacle is withdrawn at t = {u}, not after it is put in place (t = {from})"
            ),
        ));
    }
    Ok(Obstacle {
        name: o.name.clone(),
        surface,
        wall,
        active: (from, until),
        friction: o.friction.map_or(0.0, |f| f.0),
    })
}
