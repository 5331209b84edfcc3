//! Spline fits of analytic curves: interpolation at the Greville abscissae, with the deviation reported.
