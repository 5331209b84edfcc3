//! Post-processing: what a model or a simulation's state looks like as a whole device — computation, not
//! files. The `io` writers (snapshots, the MCAP recording, the disk estimate) and `stentkit mesh` draw what this
//! module computes.
//!
//! [`device`] samples every patch (the deformed state through `crate::solver::shape`, or the reference
//! geometry with rotation-minimising frames), decimates the samples to a drawing budget, and turns a
//! symmetry-reduced model back into the full device (DESIGN §5: exports always show the full device): mirror
//! copies of every patch, centrelines and closed tube meshes. [`path`] reads an arc-length path's limit loads; [`recovery`]
//! measures how far a programmed device has recovered. [`chart`] describes a line chart (`io` draws it).
//!
//! Layer: above `solver` (it reads a [`crate::solver::Simulation`]'s state), below `io` (which writes what it
//! returns). Pure: no files, no printing, no serde.

pub mod chart;
pub mod deployment;
pub mod device;
pub mod path;
pub mod print;
pub mod recovery;
pub mod vessel;
