//! A stent centreline from a vessel file (`centreline: {file: …}`): the polyline chosen, its segment, the
//! unit conversion, the smoothing spline, the lumen radius along the segment, and the check that the centreline
//! does not bend tighter than the stent's radius.
//!
//! ```yaml
//! stent:
//!   oversize: 0.1                       # R = mean lumen radius over the segment × 1.1 (or give `radius`)
//!   taper: true                         # optional: each crown from the lumen radius at its own station
//!   centreline:
//!     file:
//!       path: data/aorta-centerline.vtp # relative to the design file
//!       polyline: longest               # or an index from 0
//!       start: 20                       # arc length where the segment starts [design length unit]
//!       length: 60                      # the segment's length (default: to the end)
//!       unit: mm                        # the file's (default: the design's)
//!       smoothing: 0.1                  # largest distance of the spline from the points (default L/1000)
//! ```
//!
//! The segment is cut from the polyline at those arc lengths (its end points and radii interpolated linearly);
//! the spline is the cubic with the fewest control points within `smoothing` of every point of the segment
//! ([`crate::geometry::fit::smooth_points`]); `check` prints its deviation. The stent radius from the lumen is
//! the mean of the radius along the segment (weighted by arc length), one radius for every crown.

use super::dto::{FileCentrelineDto, FileUnitDto, PolylineChoiceDto};
use super::issue::{Result, issue};
use crate::geometry::GeometryError;
use crate::geometry::fit::{MAX_SMOOTHING_CONTROL_POINTS, smooth_points};
use crate::geometry::stent::CentrelineSpec;
use crate::io::centreline::{Polyline, read_centreline};
use crate::math::{Real, Short, Vec3};
use crate::model::Vessel;
use std::path::Path;

/// VMTK's point array of the lumen radius.
pub const DEFAULT_RADIUS_ARRAY: &str = "MaximumInscribedSphereRadius";

/// Most samples of the vessel kept for the outputs: the rings of its lumen (`snapshots/vessel_lumen.stl`,
/// `run.mcap`'s `/vessel`, the shaded picture) and the points of its centreline there. The vessel is the
/// smoothing spline sampled at twice the segment's points, up to 1000: the aorta's 40 mm segment has 238. A
/// ring every 0.1 mm of a 100 mm segment still shows a spline of up to
/// [`crate::geometry::fit::MAX_SMOOTHING_CONTROL_POINTS`] control points, and 1000 rings of 12 vertices make
/// 24 000 triangles, 1.2 MB of STL. (Unbounded, a 100 000-point centreline wrote a 240 MB lumen.)
pub const MAX_LUMEN_RINGS: usize = 1000;

/// A file centreline as the stent uses it.
#[derive(Debug, Clone, PartialEq)]
pub struct VesselCentreline {
    /// The smooth centreline.
    pub spec: CentrelineSpec,
    /// The segment's mean lumen radius [design length unit], when the file has the radius.
    pub mean_radius: Option<Real>,
    /// Largest distance of the spline from the segment's points [design length unit].
    pub deviation: Real,
    /// The spline's control points.
    pub control_points: usize,
    /// The segment's length along the polyline [design length unit].
    pub length: Real,
    /// Points of the segment.
    pub points: usize,
    /// The vessel for the outputs: the spline sampled at twice the segment's points, at most
    /// [`MAX_LUMEN_RINGS`], the lumen radius interpolated there (by normalised arc length along the segment).
    pub vessel: Vessel,
}

/// Reads and fits the file centreline `f` (at `path` in the design); `metres_per_unit` is the design's length
/// unit; `radius_needed` asks for the lumen radius (sizing by `oversize`).
pub fn vessel_centreline(
    f: &FileCentrelineDto,
    path: &str,
    metres_per_unit: Real,
    radius_needed: bool,
) -> Result<VesselCentreline> {
    let field = |name: &str| format!("{path}.{name}");
    let radius_array = f.radius_array.as_deref().unwrap_or(DEFAULT_RADIUS_ARRAY);
    let asked = (radius_needed || f.radius_array.is_some()).then_some(radius_array);
    let polylines = read_centreline(Path::new(&f.path), asked)
        .map_err(|e| issue(field("path"), e.to_string()))?;
    let chosen = match f.polyline {
        Some(PolylineChoiceDto::Index(k)) => polylines.get(k).ok_or_else(|| {
            issue(
                field("polyline"),
                format!(
                    "the file has {} polylines (0 … {})",
                    polylines.len(),
                    polylines.len() - 1
                ),
            )
        })?,
        _ => polylines
            .iter()
            .max_by(|a, b| a.length().total_cmp(&b.length()))
            .ok_or_else(|| issue(field("path"), "no polyline"))?,
    };
    let scale = match f.unit {
        None => 1.0,
        Some(FileUnitDto::Mm) => 1e-3 / metres_per_unit,
        Some(FileUnitDto::Cm) => 1e-2 / metres_per_unit,
        Some(FileUnitDto::M) => 1.0 / metres_per_unit,
    };
    let mut line = Polyline {
        points: chosen.points.iter().map(|p| p * scale).collect(),
        radius: chosen
            .radius
            .as_ref()
            .map(|r| r.iter().map(|x| x * scale).collect()),
    };
    if f.reverse {
        line.points.reverse();
        if let Some(r) = &mut line.radius {
            r.reverse();
        }
    }
    // Consecutive duplicates (VMTK repeats a point where branches meet) carry no direction.
    let total = line.length();
    let start = f.start.map_or(0.0, |s| s.0);
    let length = f.length.map_or(total - start, |l| l.0);
    if !(start < total) {
        return Err(issue(
            field("start"),
            format!(
                "the segment starts at {}, not before the end of the polyline, which is {} long in the design's length unit",
                Short(start),
                Short(total)
            ),
        ));
    }
    if !(start + length <= total * (1.0 + 1e-12)) {
        return Err(issue(
            field("length"),
            format!(
                "the segment from {} to {} is longer than the polyline ({} in the design's length unit)",
                Short(start),
                Short(start + length),
                Short(total)
            ),
        ));
    }
    let segment = cut(&line, start, start + length);
    let smoothing = f.smoothing.map_or(1e-3 * length, |s| s.0);
    let fit = smooth_points(&segment.points, smoothing).map_err(|e| match e {
        GeometryError::SmoothingTooTight {
            points,
            closest,
            worst_point,
            control_points,
            enough,
            ..
        } => {
            let (at, what) = match f.smoothing {
                Some(_) => (field("smoothing"), format!("`smoothing: {}`", Short(smoothing))),
                None => (
                    path.to_string(),
                    format!("the default smoothing (length/1000 = {})", Short(smoothing)),
                ),
            };
            issue(
                at,
                format!(
                    "{what} is too tight: the segment's {points} points scatter more than that about any smooth line (the closest spline found, of {control_points} control points, is {closest:.2e} from point {worst_point}; a spline has at most {MAX_SMOOTHING_CONTROL_POINTS} control points, and at most one per point); set `smoothing: {}` or more",
                    Short(enough)
                ),
            )
        }
        e => issue(field("path"), format!("the segment cannot be fitted: {e}")),
    })?;
    let mean_radius = segment.radius.as_ref().map(|r| {
        let mut weighted = 0.0;
        for (w, rr) in segment.points.windows(2).zip(r.windows(2)) {
            weighted += 0.5 * (rr[0] + rr[1]) * (w[1] - w[0]).norm();
        }
        weighted / length
    });
    let samples = (2 * segment.points.len()).min(MAX_LUMEN_RINGS);
    let u: Vec<Real> = (0..samples)
        .map(|k| k as Real / (samples - 1) as Real)
        .collect();
    let along = crate::math::approx::chord_parameters(&segment.points);
    let vessel = Vessel {
        points: u.iter().map(|&u| fit.curve.point(u)).collect(),
        radius: segment.radius.as_ref().zip(along).map(|(r, t)| {
            u.iter()
                .map(|&u| {
                    let i = t.partition_point(|&x| x < u).clamp(1, t.len() - 1);
                    let w = ((u - t[i - 1]) / (t[i] - t[i - 1])).clamp(0.0, 1.0);
                    r[i - 1] + w * (r[i] - r[i - 1])
                })
                .collect()
        }),
    };
    Ok(VesselCentreline {
        vessel,
        spec: CentrelineSpec::Spline {
            curve: fit.curve,
            reference: f.reference.as_ref().map(super::dto::vec3),
        },
        mean_radius,
        deviation: fit.max_deviation,
        control_points: fit.control_points,
        length,
        points: segment.points.len(),
    })
}

/// The part of `line` between arc lengths `from` and `to`, its ends interpolated, consecutive duplicate points
/// dropped.
fn cut(line: &Polyline, from: Real, to: Real) -> Polyline {
    let (mut points, mut radius) = (Vec::new(), Vec::new());
    let at = |k: usize, t: Real| -> (Vec3, Option<Real>) {
        let p = line.points[k] + (line.points[k + 1] - line.points[k]) * t;
        let r = line.radius.as_ref().map(|r| r[k] + (r[k + 1] - r[k]) * t);
        (p, r)
    };
    let mut s = 0.0;
    for k in 0..line.points.len() - 1 {
        let d = (line.points[k + 1] - line.points[k]).norm();
        if d == 0.0 {
            continue;
        }
        let (a, b) = (s, s + d);
        if b >= from && a <= to {
            let t0 = ((from - a) / d).clamp(0.0, 1.0);
            let t1 = ((to - a) / d).clamp(0.0, 1.0);
            for t in [t0, t1] {
                let (p, r) = at(k, t);
                if points
                    .last()
                    .is_none_or(|q: &Vec3| (p - q).norm() > 1e-12 * (1.0 + to))
                {
                    points.push(p);
                    radius.extend(r);
                }
            }
        }
        s = b;
    }
    Polyline {
        points,
        radius: line.radius.as_ref().map(|_| radius),
    }
}

/// The smallest radius of curvature of `spec`'s spline (a file's, or the cubic through a point list) and the
/// normalised parameter where it is, sampled at 1000 points (`None` for other centrelines, and for a point list
/// that makes no curve, which the geometry reports).
pub fn tightest_bend(spec: &CentrelineSpec) -> Option<(Real, Real)> {
    let points_curve;
    let curve = match spec {
        CentrelineSpec::Spline { curve, .. } => curve,
        CentrelineSpec::Points { points, .. } => {
            points_curve = crate::geometry::analytic::point_list_curve(points).ok()?;
            &points_curve
        }
        _ => return None,
    };
    let (a, b) = crate::geometry::analytic::ParametricCurve::domain(curve);
    (0..=1000)
        .map(|k| {
            let f = k as Real / 1000.0;
            let u = a + f * (b - a);
            let d = curve.derivatives(u, 2);
            let speed = d[1].norm();
            let curvature = d[1].cross(&d[2]).norm() / (speed * speed * speed);
            (1.0 / curvature, f)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// The field paths of the centreline files a design can name.
const FILE_FIELDS: [[&str; 4]; 2] = [
    ["stent", "centreline", "file", "path"],
    ["temporary", "centreline", "file", "path"],
];

/// Makes every centreline file path of the design tree `root` that is relative absolute, relative to `dir`
/// (the design file's folder), so that the design reads the same from anywhere — a sweep's resolved designs
/// are written into other folders.
pub fn absolute_file_paths(root: &mut serde_yaml::Value, dir: &Path) {
    for fields in FILE_FIELDS {
        let mut node = if fields[0] == "temporary" {
            root.get_mut("programme")
        } else {
            Some(&mut *root)
        };
        for key in fields {
            node = node.and_then(|n| n.get_mut(key));
        }
        if let Some(value) = node
            && let Some(text) = value.as_str()
            && Path::new(text).is_relative()
        {
            let joined = dir.join(text);
            let absolute = std::path::absolute(&joined).unwrap_or(joined);
            *value = absolute.to_string_lossy().into_owned().into();
        }
    }
}
