//! Files: STL and OBJ meshes, the run folder (history CSV, snapshots, MCAP recording, charts, summary), SVG
//! charts, centreline files. What the meshes and recorded centrelines show (the full device mirrored from a
//! reduced model) is computed in [`crate::post`]; this layer writes it. The YAML design language is
//! [`crate::design`], above this layer: the writers see a design through `output::RunDesign`.

pub(crate) mod atomic;
pub mod centreline;
pub mod chart;
pub(crate) mod checkpoint;
pub(crate) mod configurations;
pub(crate) mod contact;
pub(crate) mod formats;
pub mod history;
pub(crate) mod input;
pub(crate) mod mcap;
pub(crate) mod mcap_salvage;
pub(crate) mod mesh_format;
pub(crate) mod no_follow;
pub mod obj;
pub(crate) mod output;
pub(crate) mod render;
pub(crate) mod run_charts;
pub(crate) mod run_folder;
pub mod snapshots;
pub(crate) mod state;
pub mod stl;
pub(crate) mod summary;
pub mod threemf;
pub mod vtk;
