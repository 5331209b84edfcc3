//! The named node sets of a generated device ([`super::StentGeometry::node_sets`]), which designs use to apply
//! conditions and programmes to many nodes at once.

use super::GeneratedNode;
use super::crowns::{CREST, TROUGH};
use std::collections::BTreeMap;

/// `all_joints`, `crown_<k>` (1-based) for each of `crowns` crowns, `crests`, `troughs`, `bridge_ends` (given)
/// and `symmetry` (the nodes on a cut plane), each as indices into `nodes` in increasing order.
pub(super) fn node_sets(
    nodes: &[GeneratedNode],
    crowns: usize,
    bridge_ends: Vec<usize>,
) -> BTreeMap<String, Vec<usize>> {
    let mut node_sets: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    node_sets.insert("all_joints".into(), (0..nodes.len()).collect());
    for k in 0..crowns {
        node_sets.insert(
            format!("crown_{}", k + 1),
            (0..nodes.len()).filter(|&i| nodes[i].crown == k).collect(),
        );
    }
    for (name, kind) in [("crests", CREST), ("troughs", TROUGH)] {
        node_sets.insert(
            name.into(),
            (0..nodes.len())
                .filter(|&i| nodes[i].kind == kind)
                .collect(),
        );
    }
    node_sets.insert("bridge_ends".into(), bridge_ends);
    node_sets.insert(
        "symmetry".into(),
        (0..nodes.len())
            .filter(|&i| nodes[i].symmetry_plane.is_some())
            .collect(),
    );
    node_sets
}
