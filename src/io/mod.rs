//! Files: YAML design files, STL and OBJ meshes, SVG charts.

pub mod chart;
pub mod design;
pub mod history;
pub mod obj;
pub mod stl;
