//! What a failure is about, in the designer's terms: an equation row or an unknown named by its patch,
//! collocation or control point, node and field; and the parts of a model that no condition holds, which can
//! move as a rigid body and make the tangent singular.
//!
//! Numbering (see [`super::discretisation`]): control point `g` owns unknowns `6g..6g+3` (translation) and
//! `6g+3..6g+6` (rotation); collocation point `g` owns rows `6g..6g+6` — force and moment balance inside a
//! patch, the node's equilibrium or prescribed components at the first end of a node, continuity with that end
//! at the node's other ends. Rows beyond the collocation rows are gauge constraints.

use super::discretisation::Discretisation;
use crate::model::{Component, End, Model, PatchEnd};

/// Local axis names of a node's components (its basis `e1, e2, e3`).
const COMPONENTS: [&str; 6] = ["u1", "u2", "u3", "θ1", "θ2", "θ3"];
/// Global axis names.
const AXES: [&str; 3] = ["x", "y", "z"];

/// The patch, its local point index and the number of its points, for global point `g`.
fn locate(disc: &Discretisation, g: usize) -> Option<(usize, usize, usize)> {
    disc.patches
        .iter()
        .enumerate()
        .find(|(_, r)| (r.offset..r.offset + r.n).contains(&g))
        .map(|(k, r)| (k, g - r.offset, r.n))
}

/// The node holding the end of patch `k` at local point `j` of `n`, if `j` is an end.
fn node_at(model: &Model, k: usize, j: usize, n: usize) -> Option<(usize, bool)> {
    let end = if j == 0 {
        End::Start
    } else if j + 1 == n {
        End::End
    } else {
        return None;
    };
    let e = PatchEnd { patch: k, end };
    let node = model.node_of(e)?;
    Some((node, model.nodes[node].ends.first() == Some(&e)))
}

/// Names equation row `row`: e.g. ``patch `hook`, collocation point 4 of 10 (u = 0.35): moment balance, y``
/// or ``node `tip` (end of patch `bend`): prescribed component u2``.
pub(crate) fn describe_row(model: &Model, disc: &Discretisation, row: usize) -> String {
    let (g, i) = (row / 6, row % 6);
    let Some((k, j, n)) = locate(disc, g) else {
        return format!(
            "gauge constraint {} (rigid placement after the release)",
            row - 6 * disc.points.len()
        );
    };
    let patch = &model.patches[k].name;
    match node_at(model, k, j, n) {
        Some((node, true)) => {
            let name = &model.nodes[node].name;
            let what = match &model.nodes[node].conditions.components[i] {
                Component::Prescribed { .. } => "prescribed component",
                _ if i < 3 => "force equilibrium, component",
                _ => "moment equilibrium, component",
            };
            format!(
                "node `{name}` (at patch `{patch}`): {what} {}",
                COMPONENTS[i]
            )
        }
        Some((node, false)) => format!(
            "node `{}`: continuity of patch `{patch}`'s {} with the node, {} {}",
            model.nodes[node].name,
            if j == 0 { "start" } else { "end" },
            if i < 3 { "position" } else { "rotation" },
            AXES[i % 3]
        ),
        None => format!(
            "patch `{patch}`, collocation point {} of {n} (u = {:.4}): {} balance, {}",
            j + 1,
            disc.points[g].u,
            if i < 3 { "force" } else { "moment" },
            AXES[i % 3]
        ),
    }
}

/// Names unknown `column`: e.g. ``patch `hook`, control point 3 of 10: rotation θ2``.
pub(crate) fn describe_unknown(model: &Model, disc: &Discretisation, column: usize) -> String {
    let (g, i) = (column / 6, column % 6);
    let Some((k, j, n)) = locate(disc, g) else {
        return format!("gauge multiplier {}", column - 6 * disc.points.len());
    };
    let at_node = node_at(model, k, j, n)
        .map(|(node, _)| format!(" (at node `{}`)", model.nodes[node].name))
        .unwrap_or_default();
    format!(
        "patch `{}`, control point {} of {n}{at_node}: {} {}",
        model.patches[k].name,
        j + 1,
        if i < 3 { "translation" } else { "rotation" },
        AXES[i % 3]
    )
}

/// The patches whose unknowns in `values` are not finite, with how many, in patch order: e.g.
/// ``patch `hook` (60 of 60 unknowns)``.
pub(crate) fn non_finite_patches(
    model: &Model,
    disc: &Discretisation,
    values: &[f64],
) -> Vec<String> {
    disc.patches
        .iter()
        .enumerate()
        .filter_map(|(k, r)| {
            let range = 6 * r.offset..(6 * (r.offset + r.n)).min(values.len());
            let bad = values[range.clone()]
                .iter()
                .filter(|v| !v.is_finite())
                .count();
            (bad > 0).then(|| {
                format!(
                    "patch `{}` ({bad} of {} unknowns)",
                    model.patches[k].name,
                    range.len()
                )
            })
        })
        .collect()
}

/// A connected part of the model (patches joined through nodes) on which no node has a prescribed component.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct FreeBody {
    /// Its patches, by index.
    pub patches: Vec<usize>,
    /// Its nodes, by index.
    pub nodes: Vec<usize>,
}

/// The parts of the model that no condition holds: connected components of the patch–node graph none of whose
/// nodes prescribes any component (at any time) or is held by gauge constraints from the start (a crimper's
/// driven nodes). Each can translate as a rigid body, so the tangent is singular
/// whatever the loads. (A part held by too few components — say one translation — is not found here; its
/// singular tangent shows as a non-finite Newton increment on its patches.)
pub(crate) fn free_bodies(model: &Model) -> Vec<FreeBody> {
    let np = model.patches.len();
    // Union–find over patches.
    let mut parent: Vec<usize> = (0..np).collect();
    fn root(parent: &mut [usize], mut a: usize) -> usize {
        while parent[a] != a {
            parent[a] = parent[parent[a]];
            a = parent[a];
        }
        a
    }
    for node in &model.nodes {
        if let Some(first) = node.ends.first() {
            for e in &node.ends[1..] {
                let (a, b) = (root(&mut parent, first.patch), root(&mut parent, e.patch));
                parent[a] = b;
            }
        }
    }
    let mut held = vec![false; np];
    // A device free from the start (a crimper's) is held by its gauge constraints on the driven nodes.
    let gauged: Vec<usize> = model
        .programme
        .iter()
        .filter(|p| p.free_from() == Some(0.0))
        .flat_map(|p| p.nodes.iter().map(|d| d.node))
        .collect();
    for (k, node) in model.nodes.iter().enumerate() {
        let prescribed = gauged.contains(&k)
            || node
                .conditions
                .components
                .iter()
                .any(|c| matches!(c, Component::Prescribed { .. }));
        if prescribed && let Some(e) = node.ends.first() {
            let r = root(&mut parent, e.patch);
            held[r] = true;
        }
    }
    let mut bodies: Vec<(usize, FreeBody)> = Vec::new();
    for k in 0..np {
        let r = root(&mut parent, k);
        if held[r] {
            continue;
        }
        match bodies.iter_mut().find(|(root, _)| *root == r) {
            Some((_, b)) => b.patches.push(k),
            None => bodies.push((
                r,
                FreeBody {
                    patches: vec![k],
                    nodes: Vec::new(),
                },
            )),
        }
    }
    for (k, node) in model.nodes.iter().enumerate() {
        if let Some(e) = node.ends.first() {
            let r = root(&mut parent, e.patch);
            if let Some((_, b)) = bodies.iter_mut().find(|(root, _)| *root == r) {
                b.nodes.push(k);
            }
        }
    }
    bodies.into_iter().map(|(_, b)| b).collect()
}
