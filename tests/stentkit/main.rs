//! stentkit's integration tests: one binary, one module per capability.

#[path = "../common/mod.rs"]
mod common;

mod arc_length;
mod arguments;
mod bench;
mod centreline;
mod checkpoint;
mod cli;
mod contact;
mod crimp;
mod deployment;
mod design_errors;
mod designs;
mod diamond;
mod export;
mod fields;
mod fuzz;
mod links;
mod materials;
mod mesh;
mod outputs;
mod overrides;
mod print;
mod reliability;
mod resume;
mod run_folder;
mod solver;
mod stabilisation;
mod stent;
mod studies;
mod sweep;
mod sweep_hostile;
mod tune;
mod viscoelastic;
mod warnings;
mod wires;
