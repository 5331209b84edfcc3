//! Binary STL export of triangle meshes (stl_io).
