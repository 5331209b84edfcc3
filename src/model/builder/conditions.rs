//! Conditions applied to the nodes: each names one node or a node set, optionally a local basis (given axes or
//! a symmetry plane), and prescribes or loads components in it. One node has one basis and each component one
//! condition; what a stent's symmetry plane or the programme already set cannot be overridden.

use super::field::{BuildError, ConditionField, Field, Result};
use super::{BasisSpec, ConditionSpec, Target, nodes};
use crate::geometry::frame::basis_from_unit_axis;
use crate::math::quote::quoted;
use crate::math::{Mat3, Real, Vec3};
use crate::model::{Component, Node, Patch, TimeFunction};
use std::collections::{BTreeMap, HashMap};

/// Orthonormality tolerance of a given basis: rows typed with about seven significant digits pass.
pub(super) const BASIS_TOLERANCE: Real = 1e-6;

/// The components' names in messages.
const NAMES: [&str; 6] = ["u1", "u2", "u3", "θ1", "θ2", "θ3"];

/// Completes an orthonormal right-handed basis whose first axis is the direction of `n`.
fn basis_from_normal(n: &Vec3) -> Mat3 {
    basis_from_unit_axis(&n.normalize())
}

/// The basis a condition gives, checked.
fn basis(spec: &ConditionSpec, at: impl Fn(ConditionField) -> Field) -> Result<Option<Mat3>> {
    match spec.basis {
        Some(BasisSpec::Axes(m)) => {
            let err = (m.transpose() * m - Mat3::identity()).abs().max();
            if err > BASIS_TOLERANCE || m.determinant() < 0.0 {
                return Err(BuildError::new(
                    at(ConditionField::Basis),
                    format!(
                        "the rows must be orthonormal and right-handed (|BᵀB − I| = {err:.2e}, det = {:.3})",
                        m.determinant()
                    ),
                ));
            }
            Ok(Some(m))
        }
        Some(BasisSpec::SymmetryPlane(n)) => {
            if n.norm() == 0.0 {
                return Err(BuildError::new(
                    at(ConditionField::SymmetryPlane),
                    "the plane normal must be non-zero",
                ));
            }
            Ok(Some(basis_from_normal(&n)))
        }
        None => Ok(None),
    }
}

/// A component's value with the field that gave it.
type Given = Option<(TimeFunction, ConditionField)>;

/// Applies `conditions` to `nodes`. `preset` names what already set a component (a stent's symmetry plane, the
/// programme), which a condition may not override.
pub(super) fn apply(
    conditions: &[ConditionSpec],
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
    for (k, c) in conditions.iter().enumerate() {
        let at = |field| Field::Condition { index: k, field };
        let this = format!("conditions[{k}]");
        let targets: Vec<usize> = match &c.target {
            Target::Node(name) => vec![nodes::find(name, patches, nodes).ok_or_else(|| {
                BuildError::new(
                    at(ConditionField::Node),
                    format!("no node {}: name a node from `nodes` or a patch end `<patch>.start` / `<patch>.end`", quoted(name)),
                )
            })?],
            Target::Set(set) => node_sets.get(set).cloned().ok_or_else(|| {
                let known: Vec<&str> = node_sets.keys().map(String::as_str).collect();
                BuildError::new(
                    at(ConditionField::NodeSet),
                    if known.is_empty() {
                        format!("no node set {}: node sets come from a generated `stent`", quoted(set))
                    } else {
                        format!("no node set {}; known sets: {}", quoted(set), known.join(", "))
                    },
                )
            })?,
        };
        let basis = basis(c, at)?;
        let symmetry_plane = matches!(c.basis, Some(BasisSpec::SymmetryPlane(_)));
        // This condition's prescribed values and loads per component.
        let mut prescribed: [Given; 6] = Default::default();
        let mut loads: [Given; 6] = Default::default();
        if c.clamp {
            if c.displacement
                .iter()
                .chain(&c.rotation)
                .any(Option::is_some)
                || symmetry_plane
            {
                return Err(BuildError::new(
                    at(ConditionField::Clamp),
                    "`clamp` holds all six components: do not also give displacement, rotation or symmetry_plane",
                ));
            }
            for slot in &mut prescribed {
                *slot = Some((TimeFunction::zero(), ConditionField::Clamp));
            }
        }
        if symmetry_plane {
            for i in [0, 4, 5] {
                prescribed[i] = Some((TimeFunction::zero(), ConditionField::SymmetryPlane));
            }
        }
        for (offset, values, field) in [
            (
                0,
                &c.displacement,
                ConditionField::Displacement as fn(usize) -> ConditionField,
            ),
            (3, &c.rotation, ConditionField::Rotation),
        ] {
            for (i, v) in values.iter().enumerate() {
                if let Some(f) = v {
                    if prescribed[offset + i].is_some() {
                        return Err(BuildError::new(
                            at(field(i)),
                            "this component is already held by symmetry_plane",
                        ));
                    }
                    prescribed[offset + i] = Some((f.clone(), field(i)));
                }
            }
        }
        for (offset, values, field) in [
            (
                0,
                &c.force,
                ConditionField::Force as fn(usize) -> ConditionField,
            ),
            (3, &c.moment, ConditionField::Moment),
        ] {
            for (i, v) in values.iter().enumerate() {
                if let Some(f) = v {
                    loads[offset + i] = Some((f.clone(), field(i)));
                }
            }
        }
        let release = c.release;
        if release.is_some() && prescribed.iter().all(Option::is_none) {
            return Err(BuildError::new(
                at(ConditionField::Release),
                "nothing to release: this entry prescribes no component",
            ));
        }
        for node in targets {
            if let Some(b) = basis {
                match basis_from.get(&node) {
                    Some(first)
                        if (nodes[node].conditions.basis - b).abs().max() > BASIS_TOLERANCE =>
                    {
                        return Err(BuildError::new(
                            at(ConditionField::Whole),
                            format!(
                                "node {} already has a different basis from {first}; one node has one basis",
                                quoted(&nodes[node].name)
                            ),
                        ));
                    }
                    _ => {
                        basis_from.insert(node, this.clone());
                        nodes[node].conditions.basis = b;
                    }
                }
            }
            for i in 0..6 {
                let (p, l) = (&prescribed[i], &loads[i]);
                let Some((_, field)) = p.as_ref().or(l.as_ref()) else {
                    continue;
                };
                if let Some(first) = set_by.get(&(node, i)) {
                    return Err(BuildError::new(
                        at(*field),
                        format!(
                            "component {} of node {} is already set by {first}: one condition per component",
                            NAMES[i],
                            quoted(&nodes[node].name)
                        ),
                    ));
                }
                set_by.insert((node, i), this.clone());
                nodes[node].conditions.components[i] = match (p, l) {
                    (Some((value, _)), load) => {
                        if let (Some((_, load_field)), None) = (load, release) {
                            return Err(BuildError::new(
                                at(*load_field),
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
