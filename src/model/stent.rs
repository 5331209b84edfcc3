//! A generated stent in the model: its patches fitted at the crown and bridge discretisations (half a section
//! for patches lying in a symmetry plane), its nodes with their symmetry conditions, node sets and symmetry
//! planes, and the [`Programme`] that drives a node set to the temporary shape. The geometry itself is
//! [`crate::geometry::stent`], of any family: this module asks only the [`StentFamily`] interface (the rings of
//! a `StentSpec`, the diamond cells of a `DiamondSpec`); [`super::builder::ModelBuilder::stent`] and
//! [`super::builder::ModelBuilder::programme`] put both into a model.

use super::builder::checks::{FIT_WARNING_FRACTION, check_discretisation};
use super::builder::field::{BuildError, Field, ProgrammeField, Result, StentField};
use super::{
    Component, DrivenNode, End, Lumen, Node, NodeConditions, Obstacle, Patch, PatchEnd, Programme,
    ProgrammeKind, TimeFunction,
};
use crate::geometry::GeometryError;
use crate::geometry::fit::{FitSettings, best_fit_rigid, fit_curve};
use crate::geometry::frame::basis_from_unit_axis;
use crate::geometry::primitives;
use crate::geometry::stent::{
    GeneratedPatch, StentFamily, StentGeometry, StentParameter, TemporarySpec, WireEnd,
};
use crate::material::{Section, SectionProperties};
use crate::math::quote::quoted;
use crate::math::{Real, Vec3};
use std::sync::Arc;

/// Degree and control points of the stent's wires.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StentMesh {
    /// `(p, n)` of each crown wire.
    pub crown: (usize, usize),
    /// `(p, n)` of each bridge.
    pub bridge: (usize, usize),
}

/// Which material each part of a generated stent is made of (indices into the model's materials): one per
/// crown (or one for every crown) and one for the bridges. The default is material 0 everywhere.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct StentMaterials {
    /// The material of crown `k` (0-based) is `crowns[k]`; a single entry applies to every crown; empty: 0.
    pub crowns: Vec<usize>,
    /// The material of every bridge.
    pub bridges: usize,
}

impl StentMaterials {
    /// The material of a part of crown `crown` (0-based), or of a connector between crowns (a bridge)
    /// ([`StentFamily::is_connector`]).
    pub fn of(&self, crown: usize, connector: bool) -> usize {
        if connector {
            return self.bridges;
        }
        match self.crowns.as_slice() {
            [] => 0,
            [one] => *one,
            many => many[crown],
        }
    }
}

/// Where the programme takes the driven nodes.
#[derive(Debug, Clone, PartialEq)]
pub enum ProgrammeTarget {
    /// Every driven node moves towards the axis by `delta_r` (paper §4.3, straight stent).
    RadialContraction {
        /// Radius change Δr \[length\], `0 < Δr < R`.
        delta_r: Real,
    },
    /// A crimper closes on the device until the wires' reach is `R − Δr` (`R` the largest crown radius) over the
    /// ramp, holds, and opens over `open` from the release ([`crate::model::ProgrammeKind::Crimp`]).
    Crimp {
        /// Nominal radius change Δr \[length\], `0 < Δr < R`.
        delta_r: Real,
        /// Time the crimper takes to open \[time\], > 0.
        open: Real,
        /// Flat segments of a segmented-head crimper (≥ 3; `None`: a cylinder or a tube).
        segments: Option<usize>,
    },
    /// Flat plates either side of the straight axis close until the wires' reach across them is `R − Δr` over
    /// the ramp, hold, and open over `open` from the release ([`crate::model::ProgrammeKind::Crush`]).
    Crush {
        /// Nominal plate travel Δr \[length\], `0 < Δr < R`.
        delta_r: Real,
        /// Time the plates take to open \[time\], > 0.
        open: Real,
    },
    /// Every driven node moves to its place in a temporary shape of the same crowns (paper §4.3, curved
    /// stent).
    TargetShape {
        /// The temporary shape.
        temporary: TemporarySpec,
        /// Place the temporary shape by the rigid motion that best fits it onto the permanent one (see
        /// [`align_temporary`]); `false` keeps it where the generator puts it.
        align: bool,
    },
}

/// A programme as asked for: which node set goes where, over which ramp, released when.
#[derive(Debug, Clone, PartialEq)]
pub struct ProgrammeSpec {
    /// Where the nodes go.
    pub target: ProgrammeTarget,
    /// The driven node set (`all_joints` by default in designs).
    pub node_set: String,
    /// Start and end of the linear ramp to the temporary shape \[time\].
    pub ramp: (Real, Real),
    /// Time at which the driven components are released; `None` = never.
    pub release: Option<Real>,
}

/// The generated stent, ready to be merged into the model (its patches and nodes come first).
#[derive(Debug, Clone)]
pub struct GeneratedStent {
    /// The family and specification it was generated from.
    pub family: Arc<dyn StentFamily>,
    /// The analytic device.
    pub geometry: StentGeometry,
    /// Fitted patches, in the order of `geometry.patches` (moved into the model by the builder).
    pub patches: Vec<Patch>,
    /// Nodes, in the order of `geometry.nodes`, with their symmetry conditions (moved into the model by the
    /// builder).
    pub nodes: Vec<Node>,
}

fn geometry_error(e: GeometryError) -> BuildError {
    match e {
        GeometryError::InvalidStent { parameter, reason } => {
            BuildError::new(Field::Stent(StentField::Parameter(parameter)), reason)
        }
        e => BuildError::new(Field::Stent(StentField::Whole), e.to_string()),
    }
}

/// Where a programme's temporary shape puts the device: the placement and how much every crown's radius
/// shrinks ([`StentFamily::generate_temporary`]).
pub type Placement = (TemporarySpec, Real);

impl ProgrammeSpec {
    /// The temporary placement of the programme's target: a radial contraction keeps the centreline and
    /// shrinks every crown by Δr; a target shape is its `temporary` placement.
    pub fn placement(&self) -> Placement {
        match &self.target {
            ProgrammeTarget::RadialContraction { delta_r }
            | ProgrammeTarget::Crimp { delta_r, .. }
            | ProgrammeTarget::Crush { delta_r, .. } => (
                TemporarySpec {
                    centreline: crate::geometry::stent::TemporaryCentreline::Same,
                    radius: None,
                },
                *delta_r,
            ),
            ProgrammeTarget::TargetShape { temporary, .. } => (temporary.clone(), 0.0),
        }
    }
}

/// Generates the stent: fitted patches (section 0, or a half section for patches lying in a symmetry plane,
/// appended to `sections`; `poisson` gives its shear factor), of the materials `materials` gives per role
/// (already checked against the number of crowns), nodes with their symmetry conditions.
pub fn generate(
    family: &Arc<dyn StentFamily>,
    mesh: &StentMesh,
    materials: &StentMaterials,
    sections: &mut Vec<Section>,
    poisson: Real,
    placement: Option<&Placement>,
    warnings: &mut Vec<String>,
) -> Result<GeneratedStent> {
    wire_fits(family.as_ref(), sections[0].diameter())?;
    let geometry = match placement {
        None => family.generate(),
        Some((temporary, shrink)) => family.generate_temporary(temporary, *shrink),
    }
    .map_err(geometry_error)?;
    for (bridge, (p, n)) in [(false, mesh.crown), (true, mesh.bridge)] {
        check_discretisation(
            p,
            n,
            Field::Stent(StentField::Degree { bridge }),
            Field::Stent(StentField::ControlPoints { bridge }),
        )?;
    }
    let full = sections[0];
    if let Some(w) = crowns_touch(&geometry, &family.facing_nodes(&geometry), full.diameter()) {
        warnings.push(w);
    }
    let mut half_section = None;
    let mut patches = Vec::with_capacity(geometry.patches.len());
    let mut worst: Option<(Real, &str)> = None;
    // In a temporary placement: how many patches fold, and the first one's message.
    let mut folds: Option<(usize, String)> = None;
    let whole = |message: String| BuildError::new(Field::Stent(StentField::Whole), message);
    for g in &geometry.patches {
        let connector = family.is_connector(&g.role);
        let (p, n) = if connector { mesh.bridge } else { mesh.crown };
        let (curve, fit_error) = match g.straight_segment() {
            Some((a, b)) => (
                primitives::line(a, b, p, n).map_err(|e| whole(e.to_string()))?,
                None,
            ),
            None => {
                let fit = fit_curve(&g.curve, p, n, &FitSettings::default())
                    .map_err(|e| whole(format!("patch `{}`: {e}", g.name)))?;
                if worst.is_none_or(|(w, _)| fit.max_deviation > w) {
                    worst = Some((fit.max_deviation, &g.name));
                }
                if let Some(fold) = Fold::of(&fit.curve, full.diameter()) {
                    // The temporary placement keeps the crowns' amplitude on a smaller radius: its wires are
                    // where the nodes go, not how the wires bend (module docs of `cli::mesh`), so a fold is said.
                    if placement.is_none() {
                        return Err(fold.refusal(g, connector));
                    }
                    folds.get_or_insert((0, fold.describe(&g.name))).0 += 1;
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
            material: materials.of(g.role.crown, connector),
            fit_error,
        });
    }
    if let Some((count, first)) = folds {
        warnings.push(format!(
            "the generated temporary shape folds in {count} patch{}: {first}. The programme prescribes only where the nodes go; how the wires between them bend is the simulation's (`stentkit export RUN_DIR --phase programmed`)",
            if count == 1 { "" } else { "es" }
        ));
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
                conditions.basis = basis_from_unit_axis(&geometry.symmetry_planes[k].normal);
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
        family: family.clone(),
        geometry,
        patches,
        nodes,
    })
}

/// A generated wire, as fitted for the analysis, must not bend tighter than its own radius: the inner fibre's
/// length `1 − r κ` would be negative, the wire folded onto itself — a shape no rod (and no printer) can make.
/// On a tight bend of the centreline the crowns come close on its inner side, and a bridge swept along the bent
/// tube between them turns sharply or back on itself (issue 18: the 5-crown device on an S-shaped centreline,
/// whose inner bridges bent with radii of 0.02–0.03 mm against a wire radius of 0.25 mm). The fitted curve is
/// checked, with exact derivatives, rather than the generator's curve, whose derivatives are finite differences
/// that a centreline's end (straight beyond it) disturbs. Refused, with what to change.
struct Fold {
    /// The tightest radius of curvature \[length\].
    radius: Real,
    /// Where, as a fraction of the curve parameter.
    at: Real,
    /// The wire's radius \[length\].
    wire: Real,
}

impl Fold {
    /// The fold of the fitted wire `fitted` of diameter `diameter`, if it bends tighter than its radius.
    fn of(fitted: &crate::math::NurbsCurve, diameter: Real) -> Option<Self> {
        use crate::geometry::analytic::ParametricCurve;
        let (radius, at) = fitted.tightest_bend();
        (radius < 0.5 * diameter).then_some(Self {
            radius,
            at,
            wire: 0.5 * diameter,
        })
    }

    /// What folds, where.
    fn describe(&self, name: &str) -> String {
        format!(
            "stent patch `{name}` bends with a radius of curvature {:.3e} (at {:.0} % of its length), less than the wire's radius {}: the wire would fold onto itself",
            self.radius,
            100.0 * self.at,
            crate::math::Short(self.wire)
        )
    }

    /// The refusal of a permanent shape with this fold in `g` (a `connector` between crowns, or a part of
    /// one), with what to change.
    fn refusal(&self, g: &GeneratedPatch, connector: bool) -> BuildError {
        let (parameter, advice) = if connector {
            (
                StentParameter::Bridges,
                "where the centreline bends, the crowns on its inner side come close and the bridge between them is squeezed or turns back: bend the centreline less, use fewer or lower crowns (more room between them), or a smaller bridge amplitude",
            )
        } else {
            (
                StentParameter::Amplitude,
                "lower the crown amplitude or the number of peaks, or raise the radius",
            )
        };
        BuildError::new(
            Field::Stent(StentField::Parameter(parameter)),
            format!("{}; {advice}", self.describe(&g.name)),
        )
    }
}

/// A wire thicker than the stent's radius (its smallest crown's, with a taper) is refused before anything is
/// generated: the tube it sweeps would fill the stent's lumen and cross itself, which no printer makes and the
/// rod model does not describe (issue 31: a lumen radius of 1e-9 in a centreline file sized a stent of radius
/// 1.1e-9 with a 0.4 mm wire, and `check` said "warnings none"). The paper's stents have a wire of 0.6 mm on a
/// radius of 20 mm; the aorta stent 0.4 mm on 6.3 mm, and compacted to 2 mm.
fn wire_fits(spec: &dyn StentFamily, diameter: Real) -> Result<()> {
    let (smallest, _) = spec.radius_range();
    if diameter <= smallest {
        return Ok(());
    }
    // Four significant digits: a radius sized from a lumen (1e-9 × 1.1) is shown as 1.1e-9, not 1.1000000000000001e-9.
    let shown = |x: Real| crate::math::Short(format!("{x:.3e}").parse().unwrap_or(x));
    Err(BuildError::new(
        Field::Stent(StentField::Parameter(StentParameter::Radius)),
        format!(
            "the wire (diameter {}) is thicker than the stent's radius {}{}: its tube would fill the stent's lumen; give a radius larger than the wire (a radius sized from a centreline file's lumen radius: check that radius and the file's `unit`)",
            shown(diameter),
            shown(smallest),
            if spec.crowns() > 1 && spec.radius_range().1 > smallest {
                " (its smallest crown)"
            } else {
                ""
            }
        ),
    ))
}

/// A warning when the wires of two consecutive crowns come closer, centre to centre, than the wire's
/// `diameter`: the closest of the `facing` pairs of nodes ([`StentFamily::facing_nodes`]: a crest of one crown
/// and a trough of the next, the crowns' axial extremes, so the distance across the gap between them). Their
/// surfaces then touch or overlap: a printer fuses them, and the rods know of no contact. Said, not refused:
/// the simulation runs all the same.
fn crowns_touch(
    geometry: &StentGeometry,
    facing: &[(usize, usize)],
    diameter: Real,
) -> Option<String> {
    let nodes = &geometry.nodes;
    let (gap, crest) = facing
        .iter()
        .map(|&(c, q)| ((nodes[q].position - nodes[c].position).norm(), &nodes[c]))
        .min_by(|a, b| a.0.total_cmp(&b.0))?;
    (gap < diameter).then(|| {
        format!(
            "crowns {} and {} come within {} of each other (a crest to the next crown's trough, centre to centre, at ϑ = {:.1}°), less than the wire's diameter {}: their wires touch or overlap there, which a printer fuses and the rods do not model (no contact); widen `stent.spacing`, or lower `stent.amplitude` or the wire",
            crest.crown + 1,
            crest.crown + 2,
            crate::math::Short(gap),
            crest.angle.to_degrees(),
            crate::math::Short(diameter)
        )
    })
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

/// The temporary node positions moved by the rigid motion that best fits the driven nodes (`set`) of the FULL
/// device — every node mirrored about every combination of symmetry planes, weights shared among the copies —
/// onto their permanent positions ([`best_fit_rigid`]). A free device has no preferred placement once released;
/// placing the temporary shape this way gives its displacement `η_temp = P_temp − P_0` no rigid part, so the
/// gauge that fixes the free device's rigid motion at the release (`crate::solver::gauge`) holds it where a full
/// recovery brings every node back to `P_0`. By symmetry of the mirrored point sets the fitted motion respects
/// the symmetry planes.
pub fn align_temporary(
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

/// Builds the programme and applies it to the stent's nodes (the first of `nodes`).
pub fn programme(
    spec: &ProgrammeSpec,
    stent: &GeneratedStent,
    nodes: &mut [Node],
    end_time: Real,
    warnings: &mut Vec<String>,
) -> Result<Programme> {
    let at = |field| Field::Programme(field);
    let sets = &stent.geometry.node_sets;
    let set_name = &spec.node_set;
    let Some(set) = sets.get(set_name) else {
        let known: Vec<&str> = sets.keys().map(String::as_str).collect();
        return Err(BuildError::new(
            at(ProgrammeField::Nodes),
            format!(
                "no node set {}; the stent has: {}",
                quoted(set_name),
                known.join(", ")
            ),
        ));
    };
    if set.is_empty() {
        return Err(BuildError::new(
            at(ProgrammeField::Nodes),
            format!("node set {} is empty", quoted(set_name)),
        ));
    }
    let (t0, t1) = spec.ramp;
    if t1 <= t0 {
        return Err(BuildError::new(
            at(ProgrammeField::RampEnd),
            format!(
                "programme times must increase: the ramp ends at t = {t1}, not after its start t = {t0}"
            ),
        ));
    }
    if let Some(r) = spec.release {
        if r < t1 {
            return Err(BuildError::new(
                at(ProgrammeField::Release),
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
    // Δr must stay below the smallest crown radius.
    let radius = stent.family.radius_range().0;
    let (kind, targets): (ProgrammeKind, Vec<Vec3>) = match &spec.target {
        &ProgrammeTarget::RadialContraction { delta_r }
        | &ProgrammeTarget::Crimp { delta_r, .. }
        | &ProgrammeTarget::Crush { delta_r, .. } => {
            if !(delta_r > 0.0 && delta_r.is_finite()) {
                return Err(BuildError::new(
                    at(ProgrammeField::DeltaR),
                    format!("Δr = {delta_r} must be > 0 and finite"),
                ));
            }
            if delta_r >= radius {
                return Err(BuildError::new(
                    at(ProgrammeField::DeltaR),
                    format!(
                        "Δr = {delta_r} must be smaller than the crown radius R = {radius}: the nodes would reach or cross the axis"
                    ),
                ));
            }
            if let ProgrammeTarget::Crimp { open, .. } | ProgrammeTarget::Crush { open, .. } =
                spec.target
                && !(open > 0.0 && open.is_finite())
            {
                return Err(BuildError::new(
                    at(ProgrammeField::Whole),
                    format!("the tool's opening time {open} must be > 0 and finite"),
                ));
            }
            // A crimper or crush plates are the model's last obstacles: the builder appends them (`crimper`,
            // `plates`).
            match spec.target {
                ProgrammeTarget::Crimp { open, segments, .. } => (
                    ProgrammeKind::Crimp {
                        delta_r,
                        obstacle: usize::MAX,
                        open,
                        segments,
                    },
                    geometry.nodes.iter().map(|n| -n.radial * delta_r).collect(),
                ),
                ProgrammeTarget::Crush { open, .. } => {
                    let frame = CrushFrame::of(stent)
                        .map_err(|e| BuildError::new(at(ProgrammeField::Whole), e))?;
                    let limit = stent.family.radius_range().1 - delta_r;
                    let targets = geometry
                        .nodes
                        .iter()
                        .map(|n| {
                            let h = frame.normal.dot(&(n.position - frame.point));
                            frame.normal * (-h.signum() * (h.abs() - limit).max(0.0))
                        })
                        .collect();
                    (
                        ProgrammeKind::Crush {
                            delta_r,
                            obstacle: usize::MAX,
                            open,
                        },
                        targets,
                    )
                }
                _ => (
                    ProgrammeKind::RadialContraction { delta_r },
                    geometry.nodes.iter().map(|n| -n.radial * delta_r).collect(),
                ),
            }
        }
        ProgrammeTarget::TargetShape { temporary, align } => {
            let positions = stent
                .family
                .temporary_node_positions(geometry, temporary)
                .map_err(geometry_error)?;
            let positions = if *align {
                align_temporary(geometry, &positions, set).ok_or_else(|| {
                    BuildError::new(
                        at(ProgrammeField::Align),
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
        node_set: set_name.clone(),
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
                    crown: g.crown,
                    station: g.station,
                    radius,
                    weight: g.multiplicity as Real,
                }
            })
            .collect(),
        ramp: (t0, t1),
        release: spec.release,
    };
    if programme.prescribes() {
        programme
            .apply(nodes)
            .map_err(|e| BuildError::new(at(ProgrammeField::Temporary), e.to_string()))?;
    }
    Ok(programme)
}

/// The crimper of a crimp programme ([`crate::model::ProgrammeKind::Crimp`]): a rigid tube around the stent's
/// axis whose radius starts 2 % clear of the device's outermost wire ([`Patch::dense_points`]), holds there
/// until the ramp starts, closes linearly over the ramp until the wires' reach is `R − Δr` (`R` the largest
/// crown radius; its radius `R − Δr + d/2`, `d` the thickest wire), holds until the release and opens back
/// over `open` (`tool_schedule`). Around a straight axis it is a cylinder; around a curved one, the tube of
/// that radius around the permanent centreline between the first and the last crown, continued straight
/// beyond (a curved crimping tube, or a mandrel-guided crimp: the device is compacted onto its own axis). With
/// `segments`, a segmented-head crimper instead ([`segmented_crimper`]).
pub fn crimper(
    programme: &Programme,
    stent: &GeneratedStent,
    patches: &[Patch],
    sections: &[Section],
) -> Result<Vec<Obstacle>> {
    let at = || Field::Programme(ProgrammeField::Whole);
    let ProgrammeKind::Crimp {
        delta_r,
        open,
        segments,
        ..
    } = programme.kind
    else {
        return Err(BuildError::new(at(), "not a crimp programme"));
    };
    if let Some(n) = segments {
        return segmented_crimper(programme, stent, patches, sections, n);
    }
    // The curved crimper is a tube of radius 1 scaled by the radius schedule.
    let axis = straight_axis(stent);
    let tube = match axis {
        Some(_) => None,
        None => Some(crimper_tube(stent).map_err(|e| BuildError::new(at(), e))?),
    };
    let (start, closed) = reach(stent, patches, sections, delta_r, |x| match (&tube, axis) {
        (Some(t), _) => t.distance(x, None, 0.0).map_or(0.0, |d| 1.0 - d.value),
        (None, Some((point, axis))) => off_axis(x, point, axis),
        (None, None) => 0.0,
    });
    let radius = tool_schedule(programme, open, |t| t, start, closed)?;
    let surface = match (tube, axis) {
        (Some(tube), _) => crate::model::Surface::Lumen(tube.with_scale(radius)),
        (None, Some((point, axis))) => crate::model::Surface::Cylinder {
            point,
            axis,
            radius,
        },
        (None, None) => return Err(BuildError::new(at(), "the stent has no nodes")),
    };
    Ok(vec![Obstacle::new(
        "crimper",
        surface,
        crate::model::Wall::Rigid,
    )])
}

/// A segmented-head crimper of `n` segments (ASTM F3067's radial-force tester): `n` rigid flat faces parallel to
/// the straight stent axis, the inner faces of a regular `n`-gon around it, the first centred on the first
/// node's radial direction (`crimper_1` … `crimper_n`). Their distance from the axis (the polygon's inscribed
/// radius) follows a crimper's schedule (2 % clear of the wires' reach across the faces, closing to
/// `R − Δr + d/2`, `tool_schedule`); as a plane's schedule it is the offset `start − distance` along its inward
/// normal. Every face is in the model, whatever its symmetry (a face across the axis from the modelled part
/// never touches it), and the polygon must be symmetric about every symmetry plane of the model.
///
/// # Errors
/// Fewer than 3 segments, a curved axis, or a polygon a symmetry plane does not map onto itself.
pub fn segmented_crimper(
    programme: &Programme,
    stent: &GeneratedStent,
    patches: &[Patch],
    sections: &[Section],
    n: usize,
) -> Result<Vec<Obstacle>> {
    let at = || Field::Programme(ProgrammeField::Whole);
    let (ProgrammeKind::Crimp { .. }, Some(first)) = (programme.kind, stent.geometry.nodes.first())
    else {
        return Err(BuildError::new(
            at(),
            "not a crimp programme of a stent with nodes",
        ));
    };
    if n < 3 {
        return Err(BuildError::new(
            at(),
            format!("a segmented crimper needs at least 3 segments, not {n}"),
        ));
    }
    let (point, axis) = straight_axis(stent).ok_or_else(|| {
        BuildError::new(
            at(),
            "a segmented crimper closes on a device with a straight axis; this stent's axis is curved",
        )
    })?;
    let e0 = (first.radial - axis * axis.dot(&first.radial)).normalize();
    let e1 = axis.cross(&e0);
    let directions: Vec<Vec3> = (0..n)
        .map(|k| {
            let angle = 2.0 * std::f64::consts::PI * k as Real / n as Real;
            e0 * angle.cos() + e1 * angle.sin()
        })
        .collect();
    for (k, plane) in stent.geometry.symmetry_planes.iter().enumerate() {
        let m = plane.normal.normalize();
        let mirrored = directions.iter().all(|e| {
            let image = e - m * (2.0 * m.dot(e));
            directions.iter().any(|f| (image - f).norm() <= 1e-9)
        });
        if !mirrored {
            return Err(BuildError::new(
                at(),
                format!(
                    "a crimper of {n} segments is not symmetric about the model's symmetry plane {}: give an even \
                     number of segments for a quarter model (its first face is centred at ϑ = 0), or model the \
                     device whole",
                    k + 1
                ),
            ));
        }
    }
    let faces = directions
        .iter()
        .enumerate()
        .map(|(k, &e)| (format!("crimper_{}", k + 1), e));
    flat_tool(
        programme,
        stent,
        patches,
        sections,
        point,
        &directions,
        faces,
    )
}

/// The rigid flat faces of a tool closing on a straight stent along the outward unit `directions` from its axis
/// point `point` (a segmented crimper's `n`, a crush's two): the faces `(name, direction)` of the model, each at
/// a distance from the axis that starts 2 % clear of the wires' reach across the faces, the largest
/// `e · (x − point)` over the directions and the dense points (plus the wire's radius), and follows the
/// programme's tool schedule (`tool_schedule`) as the plane's offset `start − distance` along its inward normal.
fn flat_tool(
    programme: &Programme,
    stent: &GeneratedStent,
    patches: &[Patch],
    sections: &[Section],
    point: Vec3,
    directions: &[Vec3],
    faces: impl Iterator<Item = (String, Vec3)>,
) -> Result<Vec<Obstacle>> {
    let (ProgrammeKind::Crimp { delta_r, open, .. } | ProgrammeKind::Crush { delta_r, open, .. }) =
        programme.kind
    else {
        return Err(BuildError::new(
            Field::Programme(ProgrammeField::Whole),
            "not a programme with a tool",
        ));
    };
    let (start, closed) = reach(stent, patches, sections, delta_r, |x| {
        directions
            .iter()
            .map(|e| e.dot(&(x - point)))
            .fold(Real::NEG_INFINITY, Real::max)
    });
    let offset = tool_schedule(programme, open, |d| start - d, start, closed)?;
    Ok(faces
        .map(|(name, e)| {
            let surface = crate::model::Surface::Plane {
                point: point + e * start,
                normal: -e,
                offset: offset.clone(),
            };
            Obstacle::new(name, surface, crate::model::Wall::Rigid)
        })
        .collect())
}

/// The plates of a crush programme ([`crate::model::ProgrammeKind::Crush`]): rigid planes parallel to the
/// straight stent axis, either side of it along the crush direction ([`CrushFrame`]), `upper_plate` on the
/// side the direction points to and `lower_plate` opposite (only the one on the modelled side when a symmetry
/// plane parallel to them halves the device). Their distance from the axis starts 2 % clear of the wires'
/// reach across them, closes over the ramp to `R − Δr + d/2` (`R` the largest crown radius, `d` the thickest
/// wire), holds until the release and opens back over `open` (`tool_schedule`); as a plane's schedule it is
/// the offset `start − distance` along its inward normal.
pub fn plates(
    programme: &Programme,
    stent: &GeneratedStent,
    patches: &[Patch],
    sections: &[Section],
) -> Result<Vec<Obstacle>> {
    let at = || Field::Programme(ProgrammeField::Whole);
    if !matches!(programme.kind, ProgrammeKind::Crush { .. }) {
        return Err(BuildError::new(at(), "not a crush programme"));
    }
    let frame = CrushFrame::of(stent).map_err(|e| BuildError::new(at(), e))?;
    let faces = frame.sides.iter().map(|&side| {
        let name = if side > 0.0 {
            "upper_plate"
        } else {
            "lower_plate"
        };
        (name.to_string(), frame.normal * side)
    });
    let both = [frame.normal, -frame.normal];
    flat_tool(
        programme,
        stent,
        patches,
        sections,
        frame.point,
        &both,
        faces,
    )
}

/// How a crush sits on a straight stent: a point of its axis, the unit direction the plates close along, and
/// the signs of that direction on which plates are modelled.
#[derive(Debug, Clone, PartialEq)]
pub struct CrushFrame {
    /// A point of the axis \[length\].
    pub point: Vec3,
    /// The plates' unit normal (the crush direction), perpendicular to the axis.
    pub normal: Vec3,
    /// `+1` for the plate the normal points to, `−1` for the opposite one: both, or the modelled side's alone.
    pub sides: Vec<Real>,
}

impl CrushFrame {
    /// The crush of `stent` (module docs of [`plates`]): along the normal of its first symmetry plane through
    /// the axis (the plates parallel to it, so the mirror image across it is the other plate), or, without one,
    /// along the normal of the plane through the axis and the first node (the plane a half model is cut by: the
    /// same crush, whole). Every symmetry plane must be one of the crush's: across the axis, along the crush
    /// direction, or through the axis perpendicular to it.
    ///
    /// # Errors
    /// A sentence: a curved axis, or a symmetry plane the crush does not share.
    pub fn of(stent: &GeneratedStent) -> std::result::Result<Self, String> {
        let (point, axis) = straight_axis(stent).ok_or(
            "crush plates close on a device with a straight axis; this stent's axis is curved (crimp it instead)",
        )?;
        let scale = stent.family.radius_range().1;
        let parallel = |a: &Vec3, b: &Vec3| a.cross(b).norm() <= 1e-9;
        let through_axis = |p: &Vec3| off_axis(p, point, axis) <= 1e-9 * scale;
        let planes = &stent.geometry.symmetry_planes;
        let normal = match planes.iter().find(|p| !parallel(&p.normal, &axis)) {
            Some(p) => p.normal.normalize(),
            None => {
                let first = stent
                    .geometry
                    .nodes
                    .first()
                    .ok_or("the stent has no nodes")?;
                axis.cross(&first.radial).normalize()
            }
        };
        let mut sides = vec![1.0, -1.0];
        for (k, p) in planes.iter().enumerate() {
            let m = p.normal.normalize();
            if parallel(&m, &axis) {
                continue;
            }
            let along = parallel(&m, &normal);
            if !(through_axis(&p.point) && (along || m.dot(&normal).abs() <= 1e-9)) {
                return Err(format!(
                    "the crush along ({:.3}, {:.3}, {:.3}) is not symmetric about the model's symmetry plane {} \
                     (normal ({:.3}, {:.3}, {:.3})): crush a model with `symmetry: half`, `quarter` about \
                     perpendicular planes, or `none`",
                    normal.x,
                    normal.y,
                    normal.z,
                    k + 1,
                    m.x,
                    m.y,
                    m.z
                ));
            }
            if along {
                let side: Real = (stent.geometry.nodes.iter())
                    .map(|n| normal.dot(&(n.position - point)))
                    .sum();
                sides = vec![if side >= 0.0 { 1.0 } else { -1.0 }];
            }
        }
        Ok(Self {
            point,
            normal,
            sides,
        })
    }
}

/// The stent's axis when it is straight, as a point and a unit direction (its first node's crown station and
/// tangent, every other node's on the same line).
fn straight_axis(stent: &GeneratedStent) -> Option<(Vec3, Vec3)> {
    let nodes = &stent.geometry.nodes;
    let first = nodes.first()?;
    let (point, axis) = (first.axis_point, first.axis_tangent.normalize());
    let scale = stent.family.radius_range().1;
    nodes
        .iter()
        .all(|n| {
            n.axis_tangent.normalize().cross(&axis).norm() <= 1e-9
                && off_axis(&n.axis_point, point, axis) <= 1e-9 * scale
        })
        .then_some((point, axis))
}

/// The distance of `x` from the line through `point` along the unit `axis`.
fn off_axis(x: &Vec3, point: Vec3, axis: Vec3) -> Real {
    let d = x - point;
    (d - axis * axis.dot(&d)).norm()
}

/// A crimper's or crush plate's distance from the axis at the start over the wires' reach: 2 % clear of the
/// device.
pub const TOOL_CLEARANCE: Real = 1.02;

/// A tool's start and closed distance from the axis: 2 % clear of the wires' reach (the largest `distance` of
/// a dense point plus its wire's radius), and `R − Δr + d/2` with `R` the largest crown radius and `d` the
/// thickest wire.
fn reach(
    stent: &GeneratedStent,
    patches: &[Patch],
    sections: &[Section],
    delta_r: Real,
    distance: impl Fn(&Vec3) -> Real,
) -> (Real, Real) {
    let mut reach: Real = 0.0;
    let mut wire: Real = 0.0;
    for patch in patches {
        let r = 0.5 * sections[patch.section].diameter();
        wire = wire.max(r);
        for x in patch.dense_points() {
            reach = reach.max(distance(&x) + r);
        }
    }
    (
        TOOL_CLEARANCE * reach,
        stent.family.radius_range().1 - delta_r + wire,
    )
}

/// A tool's schedule: its distance from the axis `start` until the ramp, closing linearly to `closed` over the
/// ramp, held until the release and back to `start` over `open`, mapped through `value` (a crimper's radius is
/// the distance itself, a plate's offset is `start − distance`).
fn tool_schedule(
    programme: &Programme,
    open: Real,
    value: impl Fn(Real) -> Real,
    start: Real,
    closed: Real,
) -> Result<TimeFunction> {
    let (t0, t1) = programme.ramp;
    let mut table = Vec::new();
    if t0 > 0.0 {
        table.push((0.0, start));
    }
    table.extend([(t0, start), (t1, closed)]);
    if let Some(r) = programme.release {
        table.extend([(r, closed), (r + open, start)]);
    }
    table.dedup_by(|b, a| a.0 == b.0 && a.1 == b.1);
    let table = table.into_iter().map(|(t, d)| (t, value(d))).collect();
    TimeFunction::try_table(table)
        .map_err(|e| BuildError::new(Field::Programme(ProgrammeField::Release), e.to_string()))
}

/// Samples of the axis per largest crown radius of its length, for the curved crimper's centreline.
const TUBE_SAMPLES_PER_RADIUS: Real = 8.0;

/// The tube of radius 1 around the permanent axis of a curved stent, from its first crown's station to its
/// last (a crown's radius either side of a single one): the axis sampled at [`TUBE_SAMPLES_PER_RADIUS`] points
/// per largest crown radius (at least 17) and fitted by the fewest-control-point cubic within 1e-5 of that
/// radius (`crate::geometry::fit::smooth_points`).
fn crimper_tube(stent: &GeneratedStent) -> std::result::Result<Lumen, String> {
    let stations = &stent.geometry.stations;
    let radius = stent.family.radius_range().1;
    let (mut a, mut b) = (
        stations.iter().copied().fold(Real::INFINITY, Real::min),
        stations.iter().copied().fold(Real::NEG_INFINITY, Real::max),
    );
    if !(b > a) {
        (a, b) = (a - radius, b + radius);
    }
    let n = ((TUBE_SAMPLES_PER_RADIUS * (b - a) / radius).ceil() as usize).max(16);
    let s: Vec<Real> = (0..=n)
        .map(|i| a + (b - a) * i as Real / n as Real)
        .collect();
    let points = stent
        .family
        .axis_points(&s)
        .map_err(|e| format!("the crimper's axis: {e}"))?;
    let fit = crate::geometry::fit::smooth_points(&points, 1e-5 * radius)
        .map_err(|e| format!("the crimper's axis could not be fitted: {e}"))?;
    let lo = fit.curve.knots().domain().0;
    Lumen::try_new(fit.curve, vec![(lo, 1.0)])
}
