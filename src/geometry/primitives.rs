//! Exact NURBS primitives: straight lines and circular arcs, refined by degree elevation and knot insertion
//! to a patch's degree `p` and number of control points `n` (the geometry is unchanged by refinement).
