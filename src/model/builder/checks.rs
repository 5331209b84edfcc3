//! Checks and thresholds shared by the builder and the stent it generates ([`crate::model::stent`]).

use super::field::{BuildError, Field, Result};
use crate::math::Real;

/// Fit deviation, as a fraction of the wire diameter, above which a build warns.
pub const FIT_WARNING_FRACTION: Real = 0.01;

/// Checks a discretisation: `p ≥ 2` (collocation of the strong form needs second derivatives), `n > p`.
pub(crate) fn check_discretisation(p: usize, n: usize, degree: Field, points: Field) -> Result<()> {
    if p < 2 {
        return Err(BuildError::new(
            degree,
            format!(
                "degree p = {p} is too low: collocation of the strong form needs second derivatives, so p ≥ 2"
            ),
        ));
    }
    if n <= p {
        return Err(BuildError::new(
            points,
            format!("n = {n} control points cannot carry degree p = {p}: need n > p"),
        ));
    }
    Ok(())
}
