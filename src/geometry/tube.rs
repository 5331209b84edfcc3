//! Closed tube surfaces swept along centrelines: vertices and outward-oriented triangles.
