//! stentkit's integration tests: one binary, one module per capability.

mod design_errors;
mod designs;
mod stent;
