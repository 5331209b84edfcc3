//! The analytic centreline of a generated patch — a crown wire or a bridge — in local coordinates placed on the
//! axis (see the module documentation of [`super`] for the formulas), with its closed-form derivative.

use super::axis::Axis;
use super::{CrownShape, CrownSpec};
use crate::geometry::analytic::ParametricCurve;
use crate::math::{Mat3, Real, Vec3};
use std::f64::consts::{PI, TAU};
use std::sync::Arc;

/// The local shape of a bridge across the axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Offset {
    None,
    Circumferential { amplitude: Real, waves: Real },
    Radial { amplitude: Real, waves: Real },
}

/// Which patch a [`StentCurve`] draws, with its angles and stations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum CurveKind {
    /// A crown wire from `from` to `to` (angles) at station `station`, crest at `phase`.
    Crown {
        station: Real,
        phase: Real,
        from: Real,
        to: Real,
    },
    /// A bridge from station `from` to `to` at angle `angle`.
    Bridge {
        from: Real,
        to: Real,
        angle: Real,
        offset: Offset,
    },
    /// A strut of a diamond cell from the node at `(station, angle)` `from` to the node at `to`, the angle
    /// turning by `turn` (signed, `±π/m`) (module documentation of [`super::diamond`]).
    Strut {
        from: (Real, Real),
        to: (Real, Real),
        turn: Real,
    },
}

/// The analytic centreline of a generated patch, `u ∈ [0, 1]` (see the module documentation for the formulas).
#[derive(Debug, Clone)]
pub struct StentCurve {
    axis: Arc<Axis>,
    /// For a crown wire, the centreline frame `(c, R)` at its station, evaluated once (every point of the wire
    /// uses it; on a file centreline one evaluation costs an arc-length inversion).
    station_frame: Option<(Vec3, Mat3)>,
    /// The radius at `u = 0` and at `u = 1` (equal on a crown; a bridge's goes linearly between its crowns').
    radius: (Real, Real),
    amplitude: Real,
    peaks: Real,
    /// The crown wire's shape (a bridge and a strut ignore it).
    shape: CrownShape,
    kind: CurveKind,
}

impl StentCurve {
    /// The curve `kind` of a device with crowns `crown` placed on `axis`, of radius `radius.0` at its start and
    /// `radius.1` at its end.
    pub(super) fn new(
        axis: &Arc<Axis>,
        crown: &CrownSpec,
        radius: (Real, Real),
        kind: CurveKind,
    ) -> Self {
        let station_frame = match kind {
            CurveKind::Crown { station, .. } => Some(axis.frame(station)),
            CurveKind::Bridge { .. } | CurveKind::Strut { .. } => None,
        };
        Self {
            axis: axis.clone(),
            station_frame,
            radius,
            amplitude: crown.amplitude,
            peaks: crown.peaks as Real,
            shape: crown.shape,
            kind,
        }
    }

    /// The end points when the curve is an exact straight segment (a straight bridge on a straight
    /// centreline), else `None`.
    pub(super) fn straight_segment(&self) -> Option<(Vec3, Vec3)> {
        match (&self.kind, self.axis.as_ref()) {
            (
                CurveKind::Bridge {
                    offset: Offset::None,
                    ..
                },
                Axis::Straight { .. },
            ) => Some((self.point(0.0), self.point(1.0))),
            _ => None,
        }
    }

    /// The centreline frame at station `s`: the crown's, kept, or the axis's.
    fn frame(&self, s: Real) -> (Vec3, Mat3) {
        self.station_frame.unwrap_or_else(|| self.axis.frame(s))
    }

    /// Local coordinates `(x, r cos ϑ, r sin ϑ)`, their derivative in the curve parameter, the station and
    /// its derivative.
    fn local(&self, t: Real) -> (Vec3, Vec3, Real, Real) {
        let (h, m) = (self.amplitude, self.peaks);
        let big_r = self.radius.0;
        match self.kind {
            CurveKind::Crown {
                station,
                phase,
                from,
                to,
            } => {
                let on_crown = |a: Real| {
                    let (sa, ca) = a.sin_cos();
                    Vec3::new(h * (m * (a - phase)).cos(), big_r * ca, big_r * sa)
                };
                if self.shape == CrownShape::Zigzag {
                    // The chord between the nodes (module documentation of `super`, "Crown").
                    let (pa, pb) = (on_crown(from), on_crown(to));
                    return (pa * (1.0 - t) + pb * t, pb - pa, station, 0.0);
                }
                let a = from * (1.0 - t) + to * t;
                let da = to - from;
                let (sa, ca) = a.sin_cos();
                let arg = m * (a - phase);
                let p = on_crown(a);
                let dp = Vec3::new(-h * m * arg.sin(), -big_r * sa, big_r * ca) * da;
                (p, dp, station, 0.0)
            }
            CurveKind::Bridge {
                from,
                to,
                angle,
                offset,
            } => {
                let sigma = from * (1.0 - t) + to * t;
                let dsigma = to - from;
                let x = h * (1.0 - 2.0 * t);
                let dx = -2.0 * h;
                let wave = |amplitude: Real, waves: Real| {
                    let k = TAU * waves;
                    (amplitude * (k * t).sin(), amplitude * k * (k * t).cos())
                };
                // The cylinder's radius, linear from the crest's crown to the trough's.
                let (r0, r1) = self.radius;
                let (rc, drc) = (r0 + (r1 - r0) * t, r1 - r0);
                let (r, dr, a, da) = match offset {
                    Offset::None => (rc, drc, angle, 0.0),
                    Offset::Circumferential { amplitude, waves } => {
                        let (d, dd) = wave(amplitude, waves);
                        // ϑ = ϑ₀ + δ/r: the arc length δ along the circumference.
                        (rc, drc, angle + d / rc, dd / rc - d * drc / (rc * rc))
                    }
                    Offset::Radial { amplitude, waves } => {
                        let (d, dd) = wave(amplitude, waves);
                        (rc + d, drc + dd, angle, 0.0)
                    }
                };
                let (sa, ca) = a.sin_cos();
                let p = Vec3::new(x, r * ca, r * sa);
                let dp = Vec3::new(dx, dr * ca - r * sa * da, dr * sa + r * ca * da);
                (p, dp, sigma, dsigma)
            }
            CurveKind::Strut {
                from: (s0, a0),
                to: (s1, a1),
                turn,
            } => {
                // The station follows the half wave w = (1 − cos πu)/2 between the nodes' stations, as a crown
                // wire's axial coordinate does between its trough and crest; both ends are exactly the nodes'
                // (w is exactly 0 and 1 there, and `(1 − w) s0 + w s1` then exactly s0 and s1).
                let (sw, cw) = (PI * t).sin_cos();
                let w = 0.5 * (1.0 - cw);
                let sigma = (1.0 - w) * s0 + w * s1;
                let dsigma = (s1 - s0) * 0.5 * PI * sw;
                // The angle is counted from the nearer end, so that both ends are exactly the nodes' angles (a
                // strut across ϑ = 0 ends at 2π counted from one end and at 0 counted from the other).
                let a = if t <= 0.5 {
                    a0 + t * turn
                } else {
                    a1 - (1.0 - t) * turn
                };
                let (sa, ca) = a.sin_cos();
                let p = Vec3::new(0.0, big_r * ca, big_r * sa);
                let dp = Vec3::new(0.0, -big_r * sa, big_r * ca) * turn;
                (p, dp, sigma, dsigma)
            }
        }
    }
}

impl ParametricCurve for StentCurve {
    fn domain(&self) -> (Real, Real) {
        (0.0, 1.0)
    }

    fn point(&self, t: Real) -> Vec3 {
        let (p, _, s, _) = self.local(t);
        let (c, r) = self.frame(s);
        c + r * p
    }

    fn derivative(&self, t: Real) -> Vec3 {
        let (p, dp, s, ds) = self.local(t);
        let (_, r) = self.frame(s);
        if ds == 0.0 {
            return r * dp;
        }
        match self.axis.frame_derivative(s) {
            Some((dc, drot)) => (dc + drot * p) * ds + r * dp,
            None => {
                // Fourth-order central difference, as the trait's default (the point-list frame has no closed
                // form); the centreline continues straight beyond its ends, so the stencil stays valid there.
                let h = 1e-3;
                (self.point(t - 2.0 * h) - self.point(t + 2.0 * h)
                    + (self.point(t + h) - self.point(t - h)) * 8.0)
                    / (12.0 * h)
            }
        }
    }
}
