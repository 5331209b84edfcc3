//! The temporary (programmed) placement of a generated device's nodes: the same crowns at the same stations
//! and angles on another centreline and/or radius.

use super::axis::Axis;
use super::crowns::CREST;
use super::{
    CentrelineSpec, PLANARITY_TOLERANCE, StentGeometry, StentParameter, StentSpec,
    TemporaryCentreline, TemporarySpec, invalid,
};
use crate::geometry::GeometryError;
use crate::math::{Real, Vec3};

/// The axis of a temporary placement: the permanent one, its tangent line at the middle station between the
/// first and last crown (`straighten`), or a given centreline long enough for the crowns' `stations`.
pub(super) fn temporary_axis(
    permanent: Axis,
    stations: &[Real],
    temporary: &TemporarySpec,
) -> Result<Axis, GeometryError> {
    if let Some(radius) = temporary.radius
        && !(radius.is_finite() && radius > 0.0)
    {
        return Err(invalid(
            StentParameter::TemporaryRadius,
            format!("must be > 0, got {radius}"),
        ));
    }
    Ok(match &temporary.centreline {
        TemporaryCentreline::Same => permanent,
        TemporaryCentreline::Straightened => {
            let mid = 0.5 * (stations[0] + stations[stations.len() - 1]);
            let (c, r) = permanent.frame(mid);
            Axis::Straight {
                origin: c - r.column(0) * mid,
                frame: r,
            }
        }
        TemporaryCentreline::Given(spec) => {
            let axis = Axis::new(spec).map_err(|e| match e {
                GeometryError::InvalidStent { reason, .. } => {
                    invalid(StentParameter::TemporaryCentreline, reason)
                }
                e => e,
            })?;
            if let Some(l) = axis.length() {
                let last = stations[stations.len() - 1];
                if last > l * (1.0 + PLANARITY_TOLERANCE) {
                    return Err(invalid(
                        StentParameter::TemporaryCentreline,
                        format!(
                            "the last crown sits at arc length {last}, beyond the temporary centreline's length {l}"
                        ),
                    ));
                }
            }
            axis
        }
    })
}

/// Where a family's temporary placement puts its crowns: the temporary axis, the crowns' stations on it (those
/// of the permanent axis) and each crown's temporary radius.
pub(super) struct Placement {
    /// The temporary axis.
    pub(super) axis: Axis,
    /// The crowns' (or rows') arc-length stations, as on the permanent axis \[length\].
    pub(super) stations: Vec<Real>,
    /// The temporary radius of each of `radii` given \[length\], all > 0.
    pub(super) radii: Vec<Real>,
}

/// The opening every family's `generate_temporary` shares: the permanent axis of `centreline`, the stations
/// `stations` places on it, the temporary axis ([`temporary_axis`]) and, for each permanent radius in `radii`,
/// the temporary radius (the given one, or that radius less `shrink`), refused where it is not positive with
/// the family's word for a crown (`part`: "crown", "ring").
pub(super) fn placement(
    centreline: &CentrelineSpec,
    stations: impl FnOnce(&Axis) -> Result<Vec<Real>, GeometryError>,
    temporary: &TemporarySpec,
    radii: impl IntoIterator<Item = Real>,
    shrink: Real,
    part: &str,
) -> Result<Placement, GeometryError> {
    let permanent = Axis::new(centreline)?;
    let stations = stations(&permanent)?;
    let axis = temporary_axis(permanent, &stations, temporary)?;
    let radii: Vec<Real> = radii
        .into_iter()
        .map(|r| temporary.radius.unwrap_or(r - shrink))
        .collect();
    if let Some(&r) = radii.iter().find(|r| !(**r > 0.0)) {
        return Err(invalid(
            StentParameter::TemporaryRadius,
            format!("a {part}'s temporary radius must be > 0, got {r}"),
        ));
    }
    Ok(Placement {
        axis,
        stations,
        radii,
    })
}

impl StentSpec {
    /// Positions of the nodes of `geometry` (generated from `self`) in a temporary placement: the same crowns at
    /// the same stations and angles on another centreline and/or radius (paper Eq. `target_disp`: `P_temp`).
    pub fn temporary_node_positions(
        &self,
        geometry: &StentGeometry,
        temporary: &TemporarySpec,
    ) -> Result<Vec<Vec3>, GeometryError> {
        let axis = temporary_axis(Axis::new(&self.centreline)?, &geometry.stations, temporary)?;
        let h = self.crown.amplitude;
        Ok(geometry
            .nodes
            .iter()
            .map(|node| {
                let (c, r) = axis.frame(node.station);
                let x = if node.kind == CREST { h } else { -h };
                let (sa, ca) = node.angle.sin_cos();
                let radius = temporary.radius.unwrap_or(self.radius_of(node.crown));
                c + r * Vec3::new(x, radius * ca, radius * sa)
            })
            .collect())
    }

    /// The whole device in a temporary placement: the crowns at the same arc-length stations on the temporary
    /// axis ([`Self::temporary_node_positions`]), every crown at the temporary radius, or at its own radius less
    /// `shrink` (a radial contraction by Δr), wires and bridges generated there as on the permanent axis. Its
    /// nodes are where [`Self::temporary_node_positions`] puts them. Not checked against the permanent shape's
    /// limits (bend radius, clearance between crowns): a programmed device is compacted on purpose.
    ///
    /// # Errors
    /// [`GeometryError::InvalidStent`] for a specification the permanent shape refuses, a temporary radius
    /// that is not positive (or a shrink that leaves none), a temporary centreline too short.
    pub fn generate_temporary(
        &self,
        temporary: &TemporarySpec,
        shrink: Real,
    ) -> Result<StentGeometry, GeometryError> {
        self.check_numbers()?;
        let Placement {
            axis,
            stations,
            radii,
        } = placement(
            &self.centreline,
            |axis| self.stations(axis),
            temporary,
            (0..self.crowns).map(|k| self.radius_of(k)),
            shrink,
            "crown",
        )?;
        let placed = StentSpec {
            crown_radii: Some(radii),
            ..self.clone()
        };
        placed.generate_on(std::sync::Arc::new(axis), stations, false)
    }
}
