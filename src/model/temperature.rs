//! Temperature that varies in space: `T(X, t)` over the reference configuration, with the derivative along a
//! rod's reference arc length that the balance equations need (module docs of [`crate::material::maxwell`]).
//!
//! A [`TemperatureField`] is a function of one coordinate `ζ = e·(X − X₀)` of the reference position `X` (a
//! direction `e` and an origin `X₀`) and of time — the shape of the heating a designer can prescribe on a
//! device: a table of schedules at stations along an axis (a gradient from a heater at one end, zones heated
//! in turn) or a front moving along it (a heated bath the device is lowered into, a warm-water jet). Along a
//! rod of reference tangent `t₀ = X,s` (unit: `s` is the reference arc length), `T,s = ∂T/∂ζ · (e·t₀)`.
//!
//! Per-region schedules (one `T(t)` per patch or stent role, no gradient inside a region) are a
//! [`Profile::Stations`] table whose stations lie between the regions' extents, or different materials; a
//! field is uniform across each section (the rod model has no through-thickness temperature).

use super::TimeFunction;
use crate::math::{Real, Vec3};

/// How the temperature varies with `ζ` and time.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum Profile {
    /// Schedules at stations `ζ_k` (strictly increasing, at least two): linear in `ζ` between consecutive
    /// stations, `T(ζ, t) = (1 − w) T_k(t) + w T_{k+1}(t)`, `w = (ζ − ζ_k)/(ζ_{k+1} − ζ_k)`; constant beyond the
    /// first and the last (`∂T/∂ζ = 0` there). At a station the slope of the interval after it is used.
    Stations(Vec<(Real, TimeFunction)>),
    /// A front at `ζ_f(t)` of width `w` between a region behind it (`ζ < ζ_f`) at `behind(t)` and one ahead at
    /// `ahead(t)`: `T = ahead + (behind − ahead) · S((ζ_f − ζ)/w)` with the logistic `S(z) = 1/(1 + e^{−z})`
    /// (smooth: the temperature goes from 12 % to 88 % of the jump over `4 w`).
    Front {
        /// Front position `ζ_f(t)` \[length\].
        position: TimeFunction,
        /// Width `w` \[length\], > 0.
        width: Real,
        /// Temperature behind the front (`ζ ≪ ζ_f`) \[°C\].
        behind: TimeFunction,
        /// Temperature ahead of it (`ζ ≫ ζ_f`) \[°C\].
        ahead: TimeFunction,
    },
}

/// A temperature field over the reference configuration (module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TemperatureField {
    /// `X₀` \[length\].
    #[serde(serialize_with = "crate::math::serial::components")]
    pub origin: Vec3,
    /// `e`, a unit vector.
    #[serde(serialize_with = "crate::math::serial::components")]
    pub direction: Vec3,
    /// `T(ζ, t)`.
    pub profile: Profile,
}

/// Why a temperature field is invalid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FieldError {
    /// The direction is zero or not finite.
    #[error("the direction must be a non-zero finite vector")]
    Direction,
    /// The origin is not finite.
    #[error("the origin must be finite")]
    Origin,
    /// Fewer than two stations.
    #[error(
        "a field along an axis needs at least two stations (one station is a uniform temperature)"
    )]
    TooFewStations,
    /// Station coordinates not finite or not strictly increasing.
    #[error(
        "station {index} at {at} must lie after the one before it (stations strictly increasing, finite)"
    )]
    Stations {
        /// Index of the station.
        index: usize,
        /// Its coordinate.
        at: Real,
    },
    /// The front width is not positive and finite.
    #[error("the front width {0} must be finite and > 0")]
    Width(Real),
}

impl TemperatureField {
    /// A validated field; the direction is normalised.
    pub fn try_new(origin: Vec3, direction: Vec3, profile: Profile) -> Result<Self, FieldError> {
        let norm = direction.norm();
        if !(norm.is_finite() && norm > 0.0) {
            return Err(FieldError::Direction);
        }
        if !origin.iter().all(|v| v.is_finite()) {
            return Err(FieldError::Origin);
        }
        match &profile {
            Profile::Stations(stations) => {
                if stations.len() < 2 {
                    return Err(FieldError::TooFewStations);
                }
                for (index, pair) in stations.windows(2).enumerate() {
                    if !(pair[0].0.is_finite() && pair[1].0.is_finite() && pair[1].0 > pair[0].0) {
                        return Err(FieldError::Stations {
                            index: index + 1,
                            at: pair[1].0,
                        });
                    }
                }
            }
            Profile::Front { width, .. } => {
                if !(width.is_finite() && *width > 0.0) {
                    return Err(FieldError::Width(*width));
                }
            }
        }
        Ok(Self {
            origin,
            direction: direction / norm,
            profile,
        })
    }

    /// The coordinate `ζ = e·(X − X₀)` of a reference position \[length\].
    pub fn coordinate(&self, position: &Vec3) -> Real {
        self.direction.dot(&(position - self.origin))
    }

    /// `(T, ∂T/∂ζ)` at coordinate `zeta` and time `t` \[°C, K/length\].
    pub fn along(&self, zeta: Real, t: Real) -> (Real, Real) {
        match &self.profile {
            Profile::Stations(stations) => {
                let first = &stations[0];
                let last = &stations[stations.len() - 1];
                if zeta < first.0 {
                    return (first.1.value(t), 0.0);
                }
                if zeta >= last.0 {
                    return (last.1.value(t), 0.0);
                }
                // First interval [ζ_k, ζ_{k+1}) holding ζ (stations.len() ≥ 2, ζ_0 ≤ ζ < ζ_last).
                let k = stations.partition_point(|s| s.0 <= zeta).saturating_sub(1);
                let (a, b) = (&stations[k], &stations[k + 1]);
                let span = b.0 - a.0;
                let (ta, tb) = (a.1.value(t), b.1.value(t));
                let w = (zeta - a.0) / span;
                ((1.0 - w) * ta + w * tb, (tb - ta) / span)
            }
            Profile::Front {
                position,
                width,
                behind,
                ahead,
            } => {
                let z = (position.value(t) - zeta) / width;
                let s = logistic(z);
                let jump = behind.value(t) - ahead.value(t);
                (ahead.value(t) + jump * s, -jump * s * (1.0 - s) / width)
            }
        }
    }

    /// `(T, T,s)` at a point of a rod with reference position `position` and unit reference tangent `tangent`
    /// \[°C, K/length\].
    pub fn at(&self, position: &Vec3, tangent: &Vec3, t: Real) -> (Real, Real) {
        let (value, slope) = self.along(self.coordinate(position), t);
        (value, slope * self.direction.dot(tangent))
    }

    /// Every time at which a schedule of the field or the front's motion changes slope (time stepping lands on
    /// each).
    pub fn breakpoints(&self) -> Vec<Real> {
        let mut times: Vec<Real> = self.schedules().flat_map(|f| f.breakpoints()).collect();
        if let Profile::Front { position, .. } = &self.profile {
            times.extend(position.breakpoints());
        }
        times
    }

    /// The schedule reports show as "the" temperature of a device under this field: the first station's, or
    /// the temperature behind the front (the heater's).
    pub fn reference(&self) -> &TimeFunction {
        match &self.profile {
            Profile::Stations(stations) => &stations[0].1,
            Profile::Front { behind, .. } => behind,
        }
    }

    /// The lowest and highest temperature any of its schedules reaches \[°C\] (the field lies between them).
    pub fn range(&self) -> (Real, Real) {
        self.schedules()
            .map(TimeFunction::range)
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), (a, b)| {
                (lo.min(a), hi.max(b))
            })
    }

    /// The temperature schedules of the field (not the front's position).
    fn schedules(&self) -> Box<dyn Iterator<Item = &TimeFunction> + '_> {
        match &self.profile {
            Profile::Stations(stations) => Box::new(stations.iter().map(|s| &s.1)),
            Profile::Front { behind, ahead, .. } => Box::new([behind, ahead].into_iter()),
        }
    }
}

/// `1/(1 + e^{−z})`, without overflow for large `|z|`.
fn logistic(z: Real) -> Real {
    if z >= 0.0 {
        1.0 / (1.0 + (-z).exp())
    } else {
        let e = z.exp();
        e / (1.0 + e)
    }
}

#[cfg(test)]
mod tests {
    // Source: the definitions of the module docs; ∂T/∂ζ is checked against central differences of T (step
    // 1e-6 of a unit-size coordinate: truncation ~1e-12 · T''' and round-off ~1e-16·100/1e-6 = 1e-8 relative to
    // slopes of order 1–100 K/length, so the tolerance 1e-6 relative separates a right slope from a wrong one).
    use super::*;

    fn table(points: &[(Real, Real)]) -> TimeFunction {
        TimeFunction::try_table(points.to_vec()).expect("table")
    }

    fn fields() -> Vec<TemperatureField> {
        let stations = Profile::Stations(vec![
            (0.0, table(&[(0.0, 30.0), (1.0, 90.0)])),
            (0.4, table(&[(0.0, 30.0), (2.0, 90.0)])),
            (1.0, TimeFunction::constant(40.0)),
        ]);
        let front = Profile::Front {
            position: table(&[(0.0, -0.2), (1.0, 1.2)]),
            width: 0.05,
            behind: TimeFunction::constant(90.0),
            ahead: table(&[(0.0, 30.0), (1.0, 35.0)]),
        };
        [stations, front]
            .into_iter()
            .map(|p| {
                TemperatureField::try_new(Vec3::new(0.1, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0), p)
                    .expect("valid")
            })
            .collect()
    }

    #[test]
    fn slopes_are_derivatives_of_the_values() {
        let h = 1e-6;
        for field in fields() {
            for t in [0.0, 0.3, 0.7, 1.5] {
                for zeta in [-0.5, 0.05, 0.2, 0.41, 0.55, 0.9, 1.3] {
                    let (_, slope) = field.along(zeta, t);
                    let fd = (field.along(zeta + h, t).0 - field.along(zeta - h, t).0) / (2.0 * h);
                    assert!(
                        (slope - fd).abs() <= 1e-6 * (1.0 + slope.abs()),
                        "{:?} at ζ = {zeta}, t = {t}: slope {slope} against {fd}",
                        field.profile
                    );
                }
            }
        }
        // Along a rod: T,s = ∂T/∂ζ · e·t₀; a rod across the axis sees no gradient.
        let field = &fields()[0];
        let x = Vec3::new(0.5, 0.2, 0.0);
        let along = field.at(&x, &Vec3::new(0.6, 0.8, 0.0), 0.5);
        let (_, slope) = field.along(field.coordinate(&x), 0.5);
        assert!((along.1 - 0.6 * slope).abs() < 1e-15);
        assert_eq!(field.at(&x, &Vec3::y(), 0.5).1, 0.0);
    }

    #[test]
    fn stations_interpolate_and_hold_beyond_the_ends() {
        let field = &fields()[0];
        // ζ = X·e − 0.1: the first station at X = 0.1.
        assert_eq!(field.along(-1.0, 0.5), (60.0, 0.0));
        assert_eq!(field.along(2.0, 0.5), (40.0, 0.0));
        let (value, _) = field.along(0.2, 0.5); // halfway between 60 and 45
        assert!((value - 52.5).abs() < 1e-12);
        assert_eq!(field.range(), (30.0, 90.0));
        assert!(matches!(
            TemperatureField::try_new(
                Vec3::zeros(),
                Vec3::x(),
                Profile::Stations(vec![
                    (0.0, TimeFunction::zero()),
                    (0.0, TimeFunction::zero())
                ])
            ),
            Err(FieldError::Stations { index: 1, .. })
        ));
        assert!(
            TemperatureField::try_new(Vec3::zeros(), Vec3::zeros(), fields()[1].profile.clone())
                .is_err()
        );
    }
}
