//! The temporary (programmed) placement of a generated device's nodes: the same crowns at the same stations
//! and angles on another centreline and/or radius.

use super::axis::Axis;
use super::{
    NodeKind, PLANARITY_TOLERANCE, StentGeometry, StentParameter, StentSpec, TemporaryCentreline,
    TemporarySpec, invalid,
};
use crate::geometry::GeometryError;
use crate::math::Vec3;

impl StentSpec {
    /// Positions of the nodes of `geometry` (generated from `self`) in a temporary placement: the same crowns at
    /// the same stations and angles on another centreline and/or radius (paper Eq. `target_disp`: `P_temp`).
    pub fn temporary_node_positions(
        &self,
        geometry: &StentGeometry,
        temporary: &TemporarySpec,
    ) -> Result<Vec<Vec3>, GeometryError> {
        if let Some(radius) = temporary.radius
            && !(radius.is_finite() && radius > 0.0)
        {
            return Err(invalid(
                StentParameter::TemporaryRadius,
                format!("must be > 0, got {radius}"),
            ));
        }
        let permanent = Axis::new(&self.centreline)?;
        let stations = &geometry.stations;
        let axis = match &temporary.centreline {
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
        };
        let h = self.crown.amplitude;
        Ok(geometry
            .nodes
            .iter()
            .map(|node| {
                let (c, r) = axis.frame(node.station);
                let x = if node.kind == NodeKind::Crest { h } else { -h };
                let (sa, ca) = node.angle.sin_cos();
                let radius = temporary.radius.unwrap_or(self.radius_of(node.crown));
                c + r * Vec3::new(x, radius * ca, radius * sa)
            })
            .collect())
    }
}
