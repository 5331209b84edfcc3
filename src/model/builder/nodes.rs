//! Joints: the model's nodes from a generated stent's, the named ones (by their ends or by a point their ends
//! lie within the joint tolerance of) and the remaining ends (joined where they coincide when joints are
//! automatic, each its own node otherwise); and how a node is found by name.

use super::NodeEnds;
use super::field::{BuildError, Field, NodeField, Result};
use crate::math::quote::quoted;
use crate::math::{Real, Vec3};
use crate::model::{End, Node, NodeConditions, Patch, PatchEnd};
use std::collections::HashMap;

fn end_position(patches: &[Patch], e: PatchEnd) -> Vec3 {
    patches[e.patch].curve.point(e.end.parameter())
}

fn all_ends(patches: &[Patch]) -> impl Iterator<Item = PatchEnd> + '_ {
    (0..patches.len()).flat_map(|patch| [End::Start, End::End].map(|end| PatchEnd { patch, end }))
}

/// `patch.start` / `patch.end` as a patch end.
pub(super) fn parse_end(name: &str, patches: &[Patch]) -> Option<PatchEnd> {
    let (patch, end) = name.rsplit_once('.')?;
    let end = match end {
        "start" => End::Start,
        "end" => End::End,
        _ => return None,
    };
    let patch = patches.iter().position(|p| p.name == patch)?;
    Some(PatchEnd { patch, end })
}

/// `patch.start` / `patch.end` of a patch end.
fn end_name(patches: &[Patch], e: PatchEnd) -> String {
    format!("{}.{}", patches[e.patch].name, e.end.name())
}

/// Resolves a node reference: a node name, or `patch.start` / `patch.end` of any end the node holds.
pub(super) fn find(name: &str, patches: &[Patch], nodes: &[Node]) -> Option<usize> {
    nodes.iter().position(|n| n.name == name).or_else(|| {
        let e = parse_end(name, patches)?;
        nodes.iter().position(|n| n.ends.contains(&e))
    })
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

/// The nodes: `initial` (a generated stent's) first, then the declared ones, then the remaining ends.
pub(super) fn nodes(
    declared: &[(String, NodeEnds)],
    patches: &[Patch],
    tolerance: Real,
    automatic: bool,
    initial: Vec<Node>,
) -> Result<Vec<Node>> {
    let mut owner: HashMap<PatchEnd, usize> = HashMap::new();
    for (k, n) in initial.iter().enumerate() {
        owner.extend(n.ends.iter().map(|&e| (e, k)));
    }
    let mut nodes: Vec<Node> = initial;
    let mut names: HashMap<&str, usize> = HashMap::new();
    for (k, (name, how)) in declared.iter().enumerate() {
        let at = |field| Field::Node { index: k, field };
        if name.is_empty() {
            return Err(BuildError::new(
                at(NodeField::Name),
                "a node needs a non-empty name",
            ));
        }
        if nodes.iter().any(|n| &n.name == name) && !names.contains_key(name.as_str()) {
            return Err(BuildError::new(
                at(NodeField::Name),
                format!(
                    "node name {} is already used by the generated stent",
                    quoted(name)
                ),
            ));
        }
        if let Some(first) = names.insert(name, k) {
            return Err(BuildError::new(
                at(NodeField::Name),
                format!(
                    "node name {} is already used by nodes[{first}]",
                    quoted(name)
                ),
            ));
        }
        let mut ends = Vec::new();
        match how {
            NodeEnds::Named(list) => {
                if list.is_empty() {
                    return Err(BuildError::new(
                        at(NodeField::Ends),
                        "list at least one patch end (`patch.start` or `patch.end`)",
                    ));
                }
                for (j, end) in list.iter().enumerate() {
                    let e = parse_end(end, patches).ok_or_else(|| {
                        BuildError::new(
                            at(NodeField::End(j)),
                            format!("{} is not a patch end; write `<patch>.start` or `<patch>.end` with a patch named in `patches`", quoted(end)),
                        )
                    })?;
                    ends.push(e);
                }
            }
            NodeEnds::At(x) => {
                ends.extend(
                    all_ends(patches)
                        .filter(|&e| (end_position(patches, e) - x).norm() <= tolerance),
                );
                if ends.is_empty() {
                    return Err(BuildError::new(
                        at(NodeField::At),
                        format!(
                            "no patch end lies within {tolerance:.3e} of [{}, {}, {}]",
                            x.x, x.y, x.z
                        ),
                    ));
                }
            }
        }
        let x0 = end_position(patches, ends[0]);
        for (j, &e) in ends.iter().enumerate() {
            if let Some(&other) = owner.get(&e) {
                return Err(BuildError::new(
                    at(NodeField::End(j)),
                    format!(
                        "{} already belongs to node {}",
                        quoted(&end_name(patches, e)),
                        quoted(&nodes[other].name)
                    ),
                ));
            }
            let gap = (end_position(patches, e) - x0).norm();
            if gap > tolerance {
                return Err(BuildError::new(
                    at(NodeField::End(j)),
                    format!(
                        "{} is {gap:.3e} away from {}: joined ends must coincide (tolerance {tolerance:.3e}; set `joints.tolerance` to change it)",
                        quoted(&end_name(patches, e)),
                        quoted(&end_name(patches, ends[0]))
                    ),
                ));
            }
            owner.insert(e, nodes.len());
        }
        nodes.push(new_node(name.clone(), ends, patches));
    }
    // Remaining ends: joined automatically when asked for, otherwise free ends.
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
        if automatic {
            let x = end_position(patches, free[i]);
            for j in i + 1..free.len() {
                if !used[j] && (end_position(patches, free[j]) - x).norm() <= tolerance {
                    used[j] = true;
                    ends.push(free[j]);
                }
            }
        }
        let name = end_name(patches, ends[0]);
        nodes.push(new_node(name, ends, patches));
    }
    Ok(nodes)
}
