//! The checks of a stent specification that need no geometry: its numbers on their own, the bend radius
//! against the crown radius, and the rotation per crown that bridges need.

use super::axis::Axis;
use super::{BridgeDirection, BridgeShape, StentParameter, StentSpec, invalid, is_multiple};
use crate::geometry::GeometryError;
use crate::math::Real;
use std::f64::consts::{PI, TAU};

impl StentSpec {
    /// Checks the numbers that must hold on their own.
    pub(super) fn check_numbers(&self) -> Result<(), GeometryError> {
        let c = &self.crown;
        if !(c.radius.is_finite() && c.radius > 0.0) {
            return Err(invalid(
                StentParameter::Radius,
                format!("must be > 0, got {}", c.radius),
            ));
        }
        if let Some(radii) = &self.crown_radii {
            if radii.len() != self.crowns {
                return Err(invalid(
                    StentParameter::Radius,
                    format!("{} crown radii for {} crowns", radii.len(), self.crowns),
                ));
            }
            if let Some(r) = radii.iter().find(|r| !(r.is_finite() && **r > 0.0)) {
                return Err(invalid(
                    StentParameter::Radius,
                    format!("every crown radius must be > 0, got {r}"),
                ));
            }
        }
        if !(c.amplitude.is_finite() && c.amplitude > 0.0) {
            return Err(invalid(
                StentParameter::Amplitude,
                format!("must be > 0, got {}", c.amplitude),
            ));
        }
        if c.peaks == 0 {
            return Err(invalid(
                StentParameter::Peaks,
                "a crown needs at least one peak",
            ));
        }
        if self.crowns == 0 {
            return Err(invalid(
                StentParameter::Crowns,
                "a stent needs at least one crown",
            ));
        }
        if !self.rotation.is_finite() {
            return Err(invalid(StentParameter::Rotation, "must be finite"));
        }
        if let Some(d) = self.spacing
            && !(d.is_finite() && d > 0.0)
        {
            return Err(invalid(
                StentParameter::Spacing,
                format!("must be > 0, got {d}"),
            ));
        }
        if let Some(b) = &self.bridges {
            if b.every == 0 {
                return Err(invalid(StentParameter::BridgesEvery, "must be ≥ 1"));
            }
            if b.first >= b.every {
                return Err(invalid(
                    StentParameter::BridgesFirst,
                    format!(
                        "crest {} does not exist in a pattern of every {} crests: use 1 … {}",
                        b.first + 1,
                        b.every,
                        b.every
                    ),
                ));
            }
            if let BridgeShape::Sinusoidal {
                amplitude,
                waves,
                direction,
            } = b.shape
            {
                if !(amplitude.is_finite() && amplitude > 0.0) {
                    return Err(invalid(
                        StentParameter::BridgesAmplitude,
                        format!("must be > 0, got {amplitude}"),
                    ));
                }
                if !(waves > 0.0 && is_multiple(2.0 * waves, 1.0)) {
                    return Err(invalid(
                        StentParameter::BridgesWaves,
                        format!(
                            "must be a positive multiple of 1/2 so that the sine vanishes at both ends, got {waves}"
                        ),
                    ));
                }
                let smallest = self.radius_range().0;
                if direction == BridgeDirection::Radial && amplitude >= smallest {
                    return Err(invalid(
                        StentParameter::BridgesAmplitude,
                        format!(
                            "a radial bridge amplitude {amplitude} must be below the crown radius {smallest}"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The crowns fit inside the bend of an arc centreline: `R` below the bend radius.
    pub(super) fn check_bend_radius(&self, axis: &Axis) -> Result<(), GeometryError> {
        check_bend_radius(self.radius_range().1, axis)
    }

    /// Bridges join each crest to the facing trough of the next crown, which needs `m α ≡ π (mod 2π)` (module
    /// documentation, "Rotation per crown").
    pub(super) fn check_bridge_rotation(&self) -> Result<(), GeometryError> {
        let m = self.crown.peaks;
        let mf = m as Real;
        if self.bridges.is_some() && self.crowns > 1 && !is_multiple(mf * self.rotation - PI, TAU) {
            return Err(invalid(
                StentParameter::Rotation,
                format!(
                    "bridges join each crest to the facing trough of the next crown, which needs peaks × rotation ≡ 180° (mod 360°); got {} × {}° (e.g. use {}°)",
                    m,
                    self.rotation.to_degrees(),
                    180.0 / mf
                ),
            ));
        }
        Ok(())
    }
}

/// A device of largest radius `largest` fits inside the bend of an arc centreline: `R` below the bend radius.
pub(super) fn check_bend_radius(largest: Real, axis: &Axis) -> Result<(), GeometryError> {
    if let Axis::Arc { radius, .. } = axis
        && largest >= *radius
    {
        return Err(invalid(
            StentParameter::Radius,
            format!(
                "the crown radius {largest} must be smaller than the centreline's bend radius {radius}"
            ),
        ));
    }
    Ok(())
}
