//! Wavefront OBJ export of triangle meshes (plain text, written by hand).
