//! stentkit's integration tests: one binary, one module per capability.

#[path = "../common/mod.rs"]
mod common;

mod design_errors;
mod designs;
mod solver;
