//! What building a design reports: an [`Issue`] at a field path (which [`super::locate`] maps to
//! the file's line and column), shared by the builder of plain designs ([`super::build`]) and of stents
//! ([`super::stent`]).

/// A problem found while building the model, at a field path.
#[derive(Debug, Clone, PartialEq)]
pub struct Issue {
    /// Field path, e.g. `patches[2].arc.angle_deg`.
    pub path: String,
    /// What is wrong and what is allowed.
    pub message: String,
}

/// The issue at `path`.
pub(super) fn issue(path: impl Into<String>, message: impl Into<String>) -> Issue {
    Issue {
        path: path.into(),
        message: message.into(),
    }
}

/// A result whose error is an [`Issue`].
pub(super) type Result<T> = std::result::Result<T, Issue>;

/// The path of a degree or size `key` (`p`, `n`) that a block may give itself (`own` at `own_path`) or inherit
/// from the design's `mesh`: where the value came from.
pub(super) fn mesh_key_path(own: Option<usize>, own_path: &str, key: &str) -> String {
    match own {
        Some(_) => format!("{own_path}.{key}"),
        None => format!("mesh.{key}"),
    }
}
