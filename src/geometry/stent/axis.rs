//! The stent's axis: its centreline with the rotation-minimising frame `R_stent(s) = [t, d2, d3]` that places
//! every local point (`P = c_stent(s) + R_stent(s) · (x, r cos ϑ, r sin ϑ)`, paper §4.3.2), and the crowns'
//! stations `s_k` along it.

use super::{CentrelineSpec, PLANARITY_TOLERANCE, StentParameter, StentSpec, invalid};
use crate::geometry::GeometryError;
use crate::geometry::analytic::{Centreline, point_list_curve};
use crate::geometry::frame::normal_to;
use crate::math::{Mat3, Real, Vec3};
use nalgebra::{Rotation3, Unit};
use std::f64::consts::TAU;

/// The centreline, evaluated exactly for lines and arcs and through the rotation-minimising frame of the
/// fitted spline for point lists. Beyond its ends a centreline continues along its end tangents (only
/// finite differences look there).
#[derive(Debug, Clone)]
pub(super) enum Axis {
    Straight {
        origin: Vec3,
        frame: Mat3,
    },
    Arc {
        centre: Vec3,
        offset: Vec3,
        axis: Vec3,
        radius: Real,
        frame: Mat3,
        length: Real,
    },
    Curve {
        centreline: Box<Centreline>,
    },
}

/// Frame `[t, d2, d3]` from a tangent and a hint for `d2`.
fn frame_from(tangent: &Vec3, reference: Option<Vec3>) -> Mat3 {
    let d2 = normal_to(tangent, reference);
    Mat3::from_columns(&[*tangent, d2, tangent.cross(&d2)])
}

fn finite(what: StentParameter, v: &Vec3) -> Result<(), GeometryError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(invalid(what, format!("must be finite, got {v:?}")))
    }
}

impl Axis {
    pub(super) fn new(spec: &CentrelineSpec) -> Result<Self, GeometryError> {
        match spec {
            CentrelineSpec::Straight {
                origin,
                direction,
                reference,
            } => {
                finite(StentParameter::Centreline, origin)?;
                finite(StentParameter::Centreline, direction)?;
                let n = direction.norm();
                if !(n.is_finite() && n > 0.0) {
                    return Err(invalid(StentParameter::Centreline, "the direction is zero"));
                }
                Ok(Axis::Straight {
                    origin: *origin,
                    frame: frame_from(&(direction / n), *reference),
                })
            }
            CentrelineSpec::Arc {
                centre,
                start,
                axis,
                angle,
                reference,
            } => {
                finite(StentParameter::Centreline, centre)?;
                finite(StentParameter::Centreline, start)?;
                finite(StentParameter::Centreline, axis)?;
                if !(angle.is_finite() && *angle != 0.0 && angle.abs() <= TAU) {
                    return Err(invalid(
                        StentParameter::CentrelineAngle,
                        format!(
                            "the swept angle must be non-zero and at most 360°, got {}°",
                            angle.to_degrees()
                        ),
                    ));
                }
                let a = axis.norm();
                if !(a.is_finite() && a > 0.0) {
                    return Err(invalid(StentParameter::Centreline, "the arc axis is zero"));
                }
                let axis = axis / a;
                let offset = start - centre;
                let radius = offset.norm();
                if !(radius.is_finite() && radius > 0.0)
                    || offset.dot(&axis).abs() > PLANARITY_TOLERANCE * radius
                {
                    return Err(invalid(
                        StentParameter::Centreline,
                        "the start point must differ from the centre and lie in the plane through the centre normal to the axis",
                    ));
                }
                // A negative angle is a positive one about the reversed axis.
                let axis = if *angle < 0.0 { -axis } else { axis };
                let tangent = axis.cross(&offset).normalize();
                let hint = reference.or(Some(offset));
                Ok(Axis::Arc {
                    centre: *centre,
                    offset,
                    axis,
                    radius,
                    frame: frame_from(&tangent, hint),
                    length: radius * angle.abs(),
                })
            }
            CentrelineSpec::Points { points, reference } => {
                for p in points {
                    finite(StentParameter::Centreline, p)?;
                }
                let curve = point_list_curve(points)?;
                Ok(Axis::Curve {
                    centreline: Box::new(Centreline::new(curve, *reference)?),
                })
            }
            CentrelineSpec::Spline { curve, reference } => Ok(Axis::Curve {
                centreline: Box::new(Centreline::new(curve.clone(), *reference)?),
            }),
        }
    }

    /// Length, `None` for the unbounded straight line.
    pub(super) fn length(&self) -> Option<Real> {
        match self {
            Axis::Straight { .. } => None,
            Axis::Arc { length, .. } => Some(*length),
            Axis::Curve { centreline } => Some(centreline.length()),
        }
    }

    /// `c(s)` and `R(s) = [t, d2, d3]`.
    pub(super) fn frame(&self, s: Real) -> (Vec3, Mat3) {
        match self {
            Axis::Straight { origin, frame } => (origin + frame.column(0) * s, *frame),
            Axis::Arc {
                centre,
                offset,
                axis,
                radius,
                frame,
                ..
            } => {
                let q = Rotation3::from_axis_angle(&Unit::new_unchecked(*axis), s / radius);
                (centre + q * offset, q.matrix() * frame)
            }
            Axis::Curve { centreline } => {
                let length = centreline.length();
                let clamped = s.clamp(0.0, length);
                // `Centreline::new` rejected degenerate curves, so the frame exists.
                let (c, r) = centreline
                    .at(clamped)
                    .unwrap_or((Vec3::repeat(Real::NAN), Mat3::repeat(Real::NAN)));
                (c + r.column(0) * (s - clamped), r)
            }
        }
    }

    /// `(c'(s), R'(s))`: `R' = ω̂ R` with `ω = axis/ρ` on an arc, `R' = R K̂` from the frame's curvature on a
    /// spline centreline; `None` only where that frame cannot be evaluated.
    pub(super) fn frame_derivative(&self, s: Real) -> Option<(Vec3, Mat3)> {
        match self {
            Axis::Straight { frame, .. } => Some((frame.column(0).into_owned(), Mat3::zeros())),
            Axis::Arc { axis, radius, .. } => {
                let (_, r) = self.frame(s);
                Some((
                    r.column(0).into_owned(),
                    (axis / *radius).cross_matrix() * r,
                ))
            }
            Axis::Curve { centreline } => {
                let length = centreline.length();
                let clamped = s.clamp(0.0, length);
                let (dc, drot) = centreline.derivative_at(clamped).ok()?;
                // Beyond its ends the centreline continues straight, with the end frame.
                Some(if clamped == s {
                    (dc, drot)
                } else {
                    (dc, Mat3::zeros())
                })
            }
        }
    }
}

/// The points of the centreline `spec` at the arc lengths `s` ([`super::StentFamily::axis_points`]).
pub(super) fn points(spec: &CentrelineSpec, s: &[Real]) -> Result<Vec<Vec3>, GeometryError> {
    let axis = Axis::new(spec)?;
    Ok(s.iter().map(|&s| axis.frame(s).0).collect())
}

impl StentSpec {
    /// Crown stations on `axis`.
    pub(super) fn stations(&self, axis: &Axis) -> Result<Vec<Real>, GeometryError> {
        let n = self.crowns;
        let (start, spacing) = match (axis.length(), self.spacing) {
            (None, Some(d)) => (0.0, d),
            (None, None) if n == 1 => (0.0, 0.0),
            (None, None) => {
                return Err(invalid(
                    StentParameter::Spacing,
                    "a straight centreline needs the crown spacing d_c",
                ));
            }
            (Some(_), None) if n == 1 => (0.0, 0.0),
            (Some(l), None) => (0.0, l / (n - 1) as Real),
            (Some(l), Some(d)) => {
                let span = d * (n - 1) as Real;
                if span > l * (1.0 + PLANARITY_TOLERANCE) {
                    return Err(invalid(
                        StentParameter::Spacing,
                        format!(
                            "{n} crowns at spacing {d} span {span}, more than the centreline length {l}"
                        ),
                    ));
                }
                (0.5 * (l - span).max(0.0), d)
            }
        };
        if n > 1 && spacing <= 2.0 * self.crown.amplitude {
            return Err(invalid(
                StentParameter::Spacing,
                format!(
                    "the crown spacing {spacing} must exceed the crown height 2 h_c = {}, or crowns overlap",
                    2.0 * self.crown.amplitude
                ),
            ));
        }
        Ok((0..n).map(|k| start + spacing * k as Real).collect())
    }
}
