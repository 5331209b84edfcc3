//! Files: YAML design files, STL and OBJ meshes, the run folder (history CSV, snapshots, MCAP recording,
//! charts, summary), SVG charts.

pub mod chart;
pub mod checkpoint;
pub mod design;
pub mod device;
pub mod estimate;
pub mod history;
pub mod mcap;
pub mod mcap_salvage;
pub mod obj;
pub mod run_charts;
pub mod run_folder;
pub mod snapshots;
pub mod state;
pub mod stl;
pub mod summary;
pub mod yaml_edit;
