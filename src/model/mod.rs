//! The continuous problem: patches, sections, materials, nodes, boundary conditions, loads and schedules.
