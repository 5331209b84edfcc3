//! Analytic curves that are not NURBS (helix, the sinusoidal crown wire, placed curves, point lists).
