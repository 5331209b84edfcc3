//! Spline fits of analytic curves (DESIGN §5): the degree-`p` B-spline with `n` control points on a clamped
//! uniform knot vector that interpolates the curve at the Greville abscissae, parametrised by normalised arc
//! length (`u = s / L`), so the parametric speed of the fit is nearly constant — what collocation wants.
//! The largest deviation from the analytic curve is measured and reported.

use super::GeometryError;
use super::analytic::{ArcLengthTable, ParametricCurve};
use crate::math::{KnotVector, NurbsCurve, Real, interp};

/// Settings of a fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSettings {
    /// Panels of the arc-length table of the analytic curve (see [`ArcLengthTable`]).
    pub arc_length_panels: usize,
    /// Sample points per knot span where the deviation is measured.
    pub samples_per_span: usize,
}

impl Default for FitSettings {
    /// 512 panels (arc length to round-off for crown wires and helices of a few turns) and 16 samples per
    /// span (the interpolation error of a smooth curve peaks once per span; 16 samples find its maximum to a
    /// few per cent).
    fn default() -> Self {
        Self {
            arc_length_panels: 512,
            samples_per_span: 16,
        }
    }
}

/// A fitted spline and how far it is from the curve it stands for.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// The analysis spline, `u ∈ [0, 1]`.
    pub curve: NurbsCurve,
    /// Largest distance between the fit and the analytic curve at equal arc-length parameter over the sample
    /// points (an upper bound of the geometric distance there) [length].
    pub max_deviation: Real,
    /// Length of the analytic curve [length].
    pub length: Real,
}

/// Fits `curve` by the degree-`degree` spline with `n` control points interpolating it at the Greville
/// abscissae of the clamped uniform knot vector, parametrised by normalised arc length.
pub fn fit_curve(
    curve: &dyn ParametricCurve,
    degree: usize,
    n: usize,
    settings: &FitSettings,
) -> Result<Fit, GeometryError> {
    let knots = KnotVector::clamped_uniform(degree, n)?;
    let table = ArcLengthTable::new(curve, settings.arc_length_panels);
    let length = table.length();
    if !(length > 0.0) || !length.is_finite() {
        return Err(GeometryError::InvalidParameter {
            what: "curve",
            reason: format!("its length is {length}; it must be positive and finite"),
        });
    }
    let on_curve = |u: Real| curve.point(table.parameter_at(curve, u * length));
    let params = knots.greville();
    let points: Vec<_> = params.iter().map(|&u| on_curve(u)).collect();
    if let Some(k) = points.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
        return Err(GeometryError::InvalidParameter {
            what: "curve",
            reason: format!("its point at u = {} is not finite", params[k]),
        });
    }
    let spline = interp::interpolate(knots, &params, &points)?;
    let breaks = spline.knots().breakpoints();
    let m = settings.samples_per_span.max(1);
    let mut max_deviation: Real = 0.0;
    for w in breaks.windows(2) {
        for k in 1..=m {
            let u = w[0] + (w[1] - w[0]) * (k as Real - 0.5) / m as Real;
            max_deviation = max_deviation.max((spline.point(u) - on_curve(u)).norm());
        }
    }
    Ok(Fit {
        curve: spline,
        max_deviation,
        length,
    })
}
