//! stentkit's integration tests: one binary, one module per capability.

mod cli;
mod design_errors;
mod designs;
mod mesh;
mod stent;
mod viscoelastic;
