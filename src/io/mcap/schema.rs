//! JSON Schemas of the recorded channels: `foxglove.SceneUpdate` (the fields used here) and `stentkit.State`.

use crate::io::state::LoadChannel;
use crate::model::Model;
use serde_json::{Map, Value, json};

/// JSON Schema of the `foxglove.SceneUpdate` fields used here (entities with line and triangle-list
/// primitives); Foxglove recognises the message by its schema name.
pub(crate) fn scene_update_schema() -> Value {
    let xyz = |title: &str| {
        json!({
            "title": title, "type": "object",
            "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}},
            "required": ["x", "y", "z"]
        })
    };
    let time = json!({
        "type": "object", "title": "time",
        "properties": {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}}
    });
    let duration = json!({
        "type": "object", "title": "duration",
        "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}}
    });
    let color = json!({
        "title": "foxglove.Color", "type": "object",
        "properties": {"r": {"type": "number"}, "g": {"type": "number"}, "b": {"type": "number"}, "a": {"type": "number"}},
        "required": ["r", "g", "b", "a"]
    });
    let pose = json!({
        "title": "foxglove.Pose", "type": "object",
        "properties": {
            "position": xyz("foxglove.Vector3"),
            "orientation": {
                "title": "foxglove.Quaternion", "type": "object",
                "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}, "w": {"type": "number"}},
                "required": ["x", "y", "z", "w"]
            }
        },
        "required": ["position", "orientation"]
    });
    let points = json!({"type": "array", "items": xyz("foxglove.Point3")});
    let colors = json!({"type": "array", "items": color});
    let indices = json!({"type": "array", "items": {"type": "integer", "minimum": 0}});
    let line = json!({
        "title": "foxglove.LinePrimitive",
        "description": "A primitive representing a series of points connected by lines",
        "type": "object",
        "properties": {
            "type": {
                "title": "foxglove.LineType",
                "oneOf": [
                    {"title": "LINE_STRIP", "const": 0},
                    {"title": "LINE_LOOP", "const": 1},
                    {"title": "LINE_LIST", "const": 2}
                ]
            },
            "pose": pose,
            "thickness": {"type": "number"},
            "scale_invariant": {"type": "boolean"},
            "points": points,
            "color": color,
            "colors": colors,
            "indices": indices
        },
        "required": ["type", "pose", "thickness", "scale_invariant", "points", "color", "colors", "indices"]
    });
    let triangles = json!({
        "title": "foxglove.TriangleListPrimitive",
        "description": "A primitive representing a set of triangles or a surface tiled by triangles",
        "type": "object",
        "properties": {"pose": pose, "points": points, "color": color, "colors": colors, "indices": indices},
        "required": ["pose", "points", "color", "colors", "indices"]
    });
    let other = json!({"type": "array", "items": {"type": "object"}});
    json!({
        "title": "foxglove.SceneUpdate",
        "description": "An update to the entities displayed in a 3D scene",
        "type": "object",
        "properties": {
            "deletions": {
                "type": "array",
                "items": {
                    "title": "foxglove.SceneEntityDeletion",
                    "type": "object",
                    "properties": {
                        "timestamp": time,
                        "type": {"oneOf": [{"title": "MATCHING_ID", "const": 0}, {"title": "ALL", "const": 1}]},
                        "id": {"type": "string"}
                    }
                }
            },
            "entities": {
                "type": "array",
                "items": {
                    "title": "foxglove.SceneEntity",
                    "type": "object",
                    "properties": {
                        "timestamp": time,
                        "frame_id": {"type": "string"},
                        "id": {"type": "string"},
                        "lifetime": duration,
                        "frame_locked": {"type": "boolean"},
                        "metadata": {"type": "array", "items": {
                            "type": "object",
                            "properties": {"key": {"type": "string"}, "value": {"type": "string"}}
                        }},
                        "arrows": other,
                        "cubes": other,
                        "spheres": other,
                        "cylinders": other,
                        "lines": {"type": "array", "items": line},
                        "triangles": {"type": "array", "items": triangles},
                        "texts": other,
                        "models": other
                    },
                    "required": ["timestamp", "frame_id", "id", "lifetime", "frame_locked", "metadata", "arrows",
                        "cubes", "spheres", "cylinders", "lines", "triangles", "texts", "models"]
                }
            }
        },
        "required": ["deletions", "entities"]
    })
}

/// Names of the probe and load keys of the state messages (sanitised for message paths).
pub(super) struct StateKeys {
    pub(super) probes: Vec<String>,
    pub(super) loads: Vec<String>,
}

/// JSON Schema of the `/state` messages of `model`.
pub(super) fn state_schema(model: &Model, channels: &[LoadChannel], keys: &StateKeys) -> Value {
    let units = model.units;
    let length = units.length();
    let num = |description: String| json!({"type": "number", "description": description});
    let mut probes = Map::new();
    for (key, probe) in keys.probes.iter().zip(&model.probes) {
        probes.insert(
            key.clone(),
            json!({
                "type": "object",
                "description": format!("displacement of probe `{}` [{length}]", probe.name),
                "properties": {
                    "x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"},
                    "magnitude": {"type": "number"}
                }
            }),
        );
    }
    let mut loads = Map::new();
    for (key, c) in keys.loads.iter().zip(channels) {
        loads.insert(key.clone(), num(format!("{} [{}]", c.name, c.unit)));
    }
    let mut properties = json!({
        "step": {"type": "integer", "description": "step number (0: initial state)"},
        "time": num("simulated time [s]".into()),
        "dt": num("step size that reached this state [s]".into()),
        "temperature": num("temperature [°C]".into()),
        "loads": {"type": "object", "properties": loads},
        "iterations": {"type": "integer", "description": "Newton iterations of the step"},
        "residual": num("final normalised residual".into()),
        "residuals": {"type": "array", "items": {"type": "number"}, "description": "normalised residual after each Newton iteration"},
        "cuts": {"type": "integer", "description": "step cuts before the step converged"},
        "probes": {"type": "object", "properties": probes}
    });
    if let Some(p) = &model.programme {
        let map = properties.as_object_mut().expect("object literal");
        map.insert(
            "recovery_ratio_mean".into(),
            num("mean |η| / |η_temp| over the driven nodes: 1 at the temporary shape, 0 at the permanent one".into()),
        );
        map.insert(
            "recovery_ratio_max".into(),
            num("largest |η| / |η_temp| over the driven nodes".into()),
        );
        if p.is_radial() {
            map.insert(
                "delta_r".into(),
                num(format!(
                    "mean radial contraction of the driven nodes [{length}]"
                )),
            );
        }
    }
    json!({
        "title": "stentkit.State",
        "description": format!("state of a stentkit run (units {}; time in s, temperature in °C)", units.name()),
        "type": "object",
        "properties": properties
    })
}
