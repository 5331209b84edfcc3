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
