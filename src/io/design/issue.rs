//! What the model builder reports about a design: an [`Issue`] at a field path (which [`super::locate`] maps to
//! the file's line and column), shared by the builder of plain designs ([`super::build`]) and of stents
//! ([`super::stent`]).

use crate::math::Real;

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

/// Fit deviation, as a fraction of the wire diameter, above which the design gets a warning.
pub(super) const FIT_WARNING_FRACTION: Real = 0.01;
