//! The symmetry cut (module documentation of [`super`], "Symmetry cuts"): whether the device can have its
//! symmetry, which angles `ϑ` a reduced model keeps, which lie on a cut plane, the planes themselves, and how
//! many nodes of the full device a node of the reduced one stands for.

use super::axis::Axis;
use super::{
    ANGLE_TOLERANCE, PLANARITY_TOLERANCE, StentParameter, StentSpec, Symmetry, SymmetryPlane,
    invalid, is_multiple, same_angle,
};
use crate::geometry::GeometryError;
use crate::math::Real;
use std::f64::consts::PI;

/// The sector of the device a model keeps: all of it, or for a cut symmetric device `ϑ ∈ [0, π]` (half) or
/// `[0, π/2]` (quarter). Plane A is `ϑ = 0, π` (normal `d3` at the first crown), plane B, for quarter symmetry,
/// `ϑ = ±π/2` (normal `d2`). Near a plane `|sin ϑ|` (A) or `|cos ϑ|` (B) is the angular distance from it, compared
/// with [`ANGLE_TOLERANCE`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Sector {
    symmetry: Symmetry,
    cut: bool,
}

impl Sector {
    /// The sector of `spec`.
    pub(super) fn new(spec: &StentSpec) -> Self {
        Self::of(spec.symmetry, spec.cut)
    }

    /// The sector a device of `symmetry` keeps, cut (`cut`) or whole.
    pub(super) fn of(symmetry: Symmetry, cut: bool) -> Self {
        Self { symmetry, cut }
    }

    /// The angle is kept in the model.
    pub(super) fn retained(&self, a: Real) -> bool {
        match (self.cut, self.symmetry) {
            (false, _) | (_, Symmetry::None) => true,
            (true, Symmetry::Half) => a.sin() >= -ANGLE_TOLERANCE,
            (true, Symmetry::Quarter) => a.sin() >= -ANGLE_TOLERANCE && a.cos() >= -ANGLE_TOLERANCE,
        }
    }

    /// The cut planes, through the centreline point at the first crown's station `first_station` with the
    /// frame `[t, d2, d3]` there: A with normal `d3`, then B with normal `d2`; none for an uncut model.
    pub(super) fn planes(&self, axis: &Axis, first_station: Real) -> Vec<SymmetryPlane> {
        let (c0, r0) = axis.frame(first_station);
        let mut planes = Vec::new();
        if self.cut && self.symmetry != Symmetry::None {
            planes.push(SymmetryPlane {
                point: c0,
                normal: r0.column(2).into_owned(),
            });
            if self.symmetry == Symmetry::Quarter {
                planes.push(SymmetryPlane {
                    point: c0,
                    normal: r0.column(1).into_owned(),
                });
            }
        }
        planes
    }

    /// The cut plane (index into [`Sector::planes`]) the angle lies on, `None` off the planes or uncut.
    pub(super) fn plane_of(&self, a: Real) -> Option<usize> {
        if !self.cut {
            None
        } else if self.on_plane_a(a) {
            Some(0)
        } else if self.on_plane_b(a) {
            Some(1)
        } else {
            None
        }
    }

    /// How many nodes of the full device a node at the angle stands for: 1 uncut; the number of sectors off
    /// the planes, half of it on one.
    pub(super) fn multiplicity(&self, a: Real) -> usize {
        if !self.cut {
            1
        } else if self.on_plane_a(a) || self.on_plane_b(a) {
            self.symmetry.sectors() / 2
        } else {
            self.symmetry.sectors()
        }
    }

    /// On plane A (`ϑ = 0, π`) of a symmetric device, cut or not.
    fn on_plane_a(&self, a: Real) -> bool {
        self.symmetry != Symmetry::None && a.sin().abs() <= ANGLE_TOLERANCE
    }

    /// On plane B (`ϑ = ±π/2`) of a quarter-symmetric device, cut or not.
    fn on_plane_b(&self, a: Real) -> bool {
        self.symmetry == Symmetry::Quarter && a.cos().abs() <= ANGLE_TOLERANCE
    }
}

/// A mirror of the device as a map of angles `ϑ`, with the plane's description.
type Mirror = (fn(Real) -> Real, &'static str);

impl StentSpec {
    /// The symmetry is possible: every crown even about the cut planes, and a centreline that lies in them
    /// (straight for quarter symmetry, planar with `ϑ = 0` in its plane for half symmetry).
    pub(super) fn check_symmetry(&self, axis: &Axis) -> Result<(), GeometryError> {
        let m = self.crown.peaks as Real;
        if self.symmetry != Symmetry::None && !is_multiple(m * self.rotation, PI) {
            return Err(invalid(
                StentParameter::Rotation,
                format!(
                    "a symmetric device needs every crown even about the cut planes: peaks × rotation must be a multiple of 180°, got {} × {}°",
                    self.crown.peaks,
                    self.rotation.to_degrees()
                ),
            ));
        }
        check_axis_symmetry(self.symmetry, self.crown.peaks, axis)
    }
}

impl StentSpec {
    /// The bridges of pair `k` at crest angles `angles` must map onto themselves under every mirror of the
    /// device's symmetry.
    pub(super) fn check_bridge_symmetry(
        &self,
        k: usize,
        angles: &[Real],
    ) -> Result<(), GeometryError> {
        let mirrors: &[Mirror] = match self.symmetry {
            Symmetry::None => &[],
            Symmetry::Half => &[(|a| -a, "ϑ = 0°/180°")],
            Symmetry::Quarter => &[(|a| -a, "ϑ = 0°/180°"), (|a| PI - a, "ϑ = ±90°")],
        };
        for (mirror, plane) in mirrors {
            for &a in angles {
                if !angles.iter().any(|&b| same_angle(mirror(a), b)) {
                    return Err(invalid(
                        StentParameter::Bridges,
                        format!(
                            "the bridges between crowns {} and {} are not symmetric about the plane {plane}: the bridge at ϑ = {:.3}° has no mirror image; choose `every` and `first` so that the bridged crests are symmetric",
                            k + 1,
                            k + 2,
                            a.to_degrees()
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The centreline can carry the symmetry of a device with `peaks` crests per crown, with a node on every cut
/// plane: straight with an even number of peaks for quarter symmetry, planar with `ϑ = 0` in its plane for half
/// symmetry.
pub(super) fn check_axis_symmetry(
    symmetry: Symmetry,
    peaks: usize,
    axis: &Axis,
) -> Result<(), GeometryError> {
    match (symmetry, axis) {
        (Symmetry::None, _) => Ok(()),
        (Symmetry::Quarter, Axis::Straight { .. }) => {
            if !peaks.is_multiple_of(2) {
                return Err(invalid(
                    StentParameter::Symmetry,
                    format!(
                        "quarter symmetry needs an even number of peaks (a crest or trough on the plane ϑ = 90°), got {}",
                        peaks
                    ),
                ));
            }
            Ok(())
        }
        (Symmetry::Quarter, _) => Err(invalid(
            StentParameter::Symmetry,
            "quarter symmetry needs a straight centreline; use half symmetry for a planar bent one",
        )),
        (Symmetry::Half, Axis::Straight { .. }) => Ok(()),
        (Symmetry::Half, Axis::Arc { axis: a, frame, .. }) => {
            if frame.column(1).dot(a).abs() > PLANARITY_TOLERANCE {
                return Err(invalid(
                    StentParameter::Symmetry,
                    "half symmetry needs the reference direction (ϑ = 0) in the plane of the arc",
                ));
            }
            Ok(())
        }
        (Symmetry::Half, Axis::Curve { centreline }) => {
            let length = centreline.length();
            let (c0, r0) = axis.frame(0.0);
            let normal = r0.column(2).into_owned();
            let samples = 64;
            for k in 0..=samples {
                let (c, r) = axis.frame(length * k as Real / samples as Real);
                if (c - c0).dot(&normal).abs() > PLANARITY_TOLERANCE * length
                    || (r.column(2) - normal).norm() > PLANARITY_TOLERANCE
                {
                    return Err(invalid(
                        StentParameter::Symmetry,
                        "half symmetry needs a planar centreline with the reference direction (ϑ = 0) in its plane",
                    ));
                }
            }
            Ok(())
        }
    }
}
