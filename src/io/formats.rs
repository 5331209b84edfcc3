//! The registry of snapshot file formats: every [`MeshFormat`] a run can write its snapshots in, and the ones
//! it writes unless the design says otherwise (`output.snapshots.formats`).
//!
//! **A new snapshot file format is a new module plus one registration line**: write `io/<format>.rs` with a
//! type implementing [`MeshFormat`] (its extension and how it writes a mesh), declare the module in
//! `io/mod.rs`, and add the type to [`FORMATS`]. A design can then name it; each snapshot lists its file under
//! the extension as key in summary.json, the run folder's manifest claims it, and `--resume` keeps or rewrites
//! it with the others.

use super::mesh_format::MeshFormat;
use super::{obj, stl, threemf};

/// Every snapshot format, in the order a snapshot writes them.
pub(crate) const FORMATS: &[&dyn MeshFormat] = &[&stl::Stl, &obj::Obj, &threemf::ThreeMf];

/// The formats a run writes by default: binary STL only. STL is what slicers, mesh repair tools and
/// `stentkit`'s own picture read; OBJ holds the same triangles (with shared vertices, about as large: 6.2 MB
/// against STL's 6.4 MB per snapshot of the straight stent) and is written when a design asks for it.
pub(crate) const DEFAULT_FORMATS: &[&str] = &["stl"];

/// The format of an extension (`stl`, `obj`), if registered.
pub(crate) fn format(extension: &str) -> Option<&'static dyn MeshFormat> {
    FORMATS.iter().copied().find(|f| f.extension() == extension)
}

/// The registered extensions, for messages (`stl, obj`).
pub(crate) fn extensions() -> String {
    FORMATS
        .iter()
        .map(|f| f.extension())
        .collect::<Vec<_>>()
        .join(", ")
}
