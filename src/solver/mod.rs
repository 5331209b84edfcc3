//! The quasi-static IGA-collocation solver (paper §3).
