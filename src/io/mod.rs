//! Files: YAML design files, STL and OBJ meshes.

pub mod design;
pub mod history;
pub mod obj;
pub mod stl;
