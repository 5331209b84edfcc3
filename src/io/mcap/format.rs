//! The JSON of the recorded messages, written by hand where it is hot: fixed-point coordinates
//! ([`coordinate_decimals`]), points, colours and `foxglove.SceneUpdate` messages, plus JSON numbers and
//! message-path keys.

use crate::math::{Real, Vec3};
use serde_json::Value;
use std::fmt::Write as _;

/// Frame of every scene entity.
pub(crate) const FRAME_ID: &str = "world";

/// Decimals of recorded coordinates for a device of size `scale` (largest distance of a control point from
/// the origin) \[length\]: `max(0, 5 − ⌊log₁₀ scale⌋)`, a resolution `10^(⌊log₁₀ scale⌋ − 5)` between `10⁻⁶` and
/// `10⁻⁵` of the size.
pub(crate) fn coordinate_decimals(scale: Real) -> usize {
    if !(scale > 0.0 && scale.is_finite()) {
        return 6;
    }
    (5 - scale.log10().floor() as i64).clamp(0, 12) as usize
}

/// A key usable in a Foxglove message path (`/state.probes.tip.x`): letters, digits and `_`.
pub(crate) fn path_key(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

/// A JSON number, `null` for NaN or infinity (which JSON cannot hold).
pub(super) fn number(x: Real) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// Appends a JSON array of points.
pub(super) fn push_points(out: &mut String, points: &[Vec3], decimals: usize) {
    out.push('[');
    for (i, p) in points.iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        push_point(out, p, decimals);
    }
    out.push(']');
}

/// The identity `foxglove.Pose`.
pub(super) const IDENTITY_POSE: &str =
    r#"{"position":{"x":0,"y":0,"z":0},"orientation":{"x":0,"y":0,"z":0,"w":1}}"#;

/// A `foxglove.Color` as JSON.
pub(super) fn color(r: Real, g: Real, b: Real) -> String {
    format!(r#"{{"r":{r:.3},"g":{g:.3},"b":{b:.3},"a":1}}"#)
}

/// Colour for temperature `t` between `lo` and `hi`: blue (cold) to red (hot).
pub(super) fn temperature_color(t: Real, lo: Real, hi: Real) -> String {
    let s = if hi > lo {
        ((t - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        1.0
    };
    color(0.15 + 0.8 * s, 0.35, 0.95 - 0.8 * s)
}

/// A `foxglove.SceneUpdate` replacing entity `id` with the given line and triangle-list primitives (JSON
/// array contents). Written by hand: the centrelines are recorded at every step and dominate the recording
/// time.
pub(super) fn scene_update(id: &str, nanoseconds: u64, lines: &str, triangles: &str) -> String {
    scene_update_of(&[entity(
        id,
        nanoseconds,
        &Primitives {
            lines,
            triangles,
            ..Primitives::default()
        },
    )])
}

/// A `foxglove.SceneUpdate` replacing `entities` (each from [`entity`]).
pub(super) fn scene_update_of(entities: &[String]) -> String {
    format!(r#"{{"deletions":[],"entities":[{}]}}"#, entities.join(","))
}

/// The primitives of an entity, each the JSON contents of its array (empty: none).
#[derive(Default)]
pub(super) struct Primitives<'a> {
    /// `CubePrimitive`s.
    pub(super) cubes: &'a str,
    /// `CylinderPrimitive`s.
    pub(super) cylinders: &'a str,
    /// `LinePrimitive`s.
    pub(super) lines: &'a str,
    /// `TriangleListPrimitive`s.
    pub(super) triangles: &'a str,
}

/// A `foxglove.SceneEntity` `id` at `nanoseconds` with `primitives`.
pub(super) fn entity(id: &str, nanoseconds: u64, primitives: &Primitives<'_>) -> String {
    let (sec, nsec) = (nanoseconds / 1_000_000_000, nanoseconds % 1_000_000_000);
    let Primitives {
        cubes,
        cylinders,
        lines,
        triangles,
    } = primitives;
    format!(
        r#"{{"timestamp":{{"sec":{sec},"nsec":{nsec}}},"frame_id":"{FRAME_ID}","id":"{id}","lifetime":{{"sec":0,"nsec":0}},"frame_locked":false,"metadata":[],"arrows":[],"cubes":[{cubes}],"spheres":[],"cylinders":[{cylinders}],"lines":[{lines}],"triangles":[{triangles}],"texts":[],"models":[]}}"#
    )
}

/// Appends `x` with `decimals` decimals, trailing zeros dropped, as a JSON number (`null` if not finite).
///
/// Rounds in integers (`x · 10^decimals` to the nearest integer, then its digits), not with `format!("{:.N}")`,
/// whose exact decimal expansion cost a fifth of a straight-stent run; values too large for that fall back to it.
fn push_coordinate(out: &mut String, x: Real, decimals: usize) {
    if !x.is_finite() {
        out.push_str("null");
        return;
    }
    let scale = 10f64.powi(decimals as i32);
    let scaled = (x * scale).round();
    if decimals > 15 || scaled.abs() >= 1e15 {
        let start = out.len();
        let _ = write!(out, "{x:.decimals$}");
        if out[start..].contains('.') {
            let trimmed = out.trim_end_matches('0').trim_end_matches('.').len();
            out.truncate(trimmed);
        }
        if &out[start..] == "-0" {
            out.truncate(start);
            out.push('0');
        }
        return;
    }
    let n = scaled as i64;
    if n == 0 {
        out.push('0');
        return;
    }
    let unit = 10i64.pow(decimals as u32);
    let (whole, mut fraction) = (n.abs() / unit, n.abs() % unit);
    if n < 0 {
        out.push('-');
    }
    let _ = write!(out, "{whole}");
    if fraction != 0 {
        let mut digits = decimals;
        while fraction % 10 == 0 {
            fraction /= 10;
            digits -= 1;
        }
        let _ = write!(out, ".{fraction:0digits$}");
    }
}

/// Appends a `foxglove.Point3` (or `Vector3`).
pub(super) fn push_point(out: &mut String, p: &Vec3, decimals: usize) {
    out.push_str("{\"x\":");
    push_coordinate(out, p.x, decimals);
    out.push_str(",\"y\":");
    push_coordinate(out, p.y, decimals);
    out.push_str(",\"z\":");
    push_coordinate(out, p.z, decimals);
    out.push('}');
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn coordinates_are_short_fixed_point_numbers() {
        assert_eq!(coordinate_decimals(110.0), 3);
        assert_eq!(coordinate_decimals(75.0), 4);
        assert_eq!(coordinate_decimals(1.0), 5);
        assert_eq!(coordinate_decimals(1e7), 0);
        let text = |x: Real, d: usize| {
            let mut s = String::new();
            push_coordinate(&mut s, x, d);
            s
        };
        assert_eq!(text(109.856_4, 3), "109.856");
        assert_eq!(text(0.050_943_5, 3), "0.051");
        assert_eq!(text(19.999_999_9, 4), "20");
        assert_eq!(text(-0.000_01, 3), "0");
        assert_eq!(text(-2.5, 3), "-2.5");
        assert_eq!(text(1234.0, 0), "1234");
        assert_eq!(text(-0.0307, 3), "-0.031");
        assert_eq!(text(3.000_5, 5), "3.0005");
        assert_eq!(text(2e16, 3), "20000000000000000");
        assert_eq!(text(Real::NAN, 3), "null");
        assert_eq!(number(Real::NAN), Value::Null);
    }

    #[test]
    fn hand_written_scene_updates_are_json() {
        let mut points = String::new();
        push_points(
            &mut points,
            &[
                Vec3::new(1.0, -0.5, 1e-7),
                Vec3::new(19.999_999_9, 0.0, -0.0),
            ],
            6,
        );
        let line = format!(
            r#"{{"type":0,"pose":{IDENTITY_POSE},"thickness":0.6,"scale_invariant":false,"color":{},"colors":[],"indices":[],"points":{points}}}"#,
            temperature_color(50.0, 20.0, 90.0)
        );
        let message: Value =
            serde_json::from_str(&scene_update("centrelines", 1_500_000_001, &line, ""))
                .expect("valid JSON");
        let entity = &message["entities"][0];
        assert_eq!(entity["timestamp"]["sec"], 1);
        assert_eq!(entity["timestamp"]["nsec"], 500_000_001);
        assert_eq!(entity["lines"][0]["points"][1]["x"], 20.0);
        assert_eq!(entity["lines"][0]["points"][0]["z"], 0.0);
        assert_eq!(entity["lines"][0]["points"][0]["y"], -0.5);
        assert_eq!(entity["triangles"], json!([]));
    }

    #[test]
    fn path_keys_are_identifiers() {
        assert_eq!(path_key("tip"), "tip");
        assert_eq!(path_key("arch.end.F3"), "arch_end_F3");
        assert_eq!(path_key("a-b c"), "a_b_c");
    }
}
