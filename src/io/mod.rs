//! Files: YAML design files, STL and OBJ meshes.
