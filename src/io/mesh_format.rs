//! What a snapshot file format is ([`MeshFormat`]), what its writer is told about the state
//! ([`SnapshotState`]) and how mesh files fail ([`MeshIoError`]): the interface between the snapshots ([`super::snapshots`], which lists the formats) and
//! each format's module ([`super::stl`], [`super::obj`]).

use crate::geometry::mesh::TriangleMesh;
use crate::math::Real;
use crate::model::Model;
use std::io;
use std::path::{Path, PathBuf};

/// Errors of the mesh readers and writers, each carrying the file's path.
#[derive(Debug, thiserror::Error)]
pub enum MeshIoError {
    /// Writing (creating the temporary file, writing, syncing or renaming it) failed; the target is
    /// unchanged and the temporary file has been removed.
    #[error("cannot write mesh file {path}: {source}")]
    Write {
        /// The target path.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: io::Error,
    },
    /// Opening or reading a mesh file failed, or its content is not a valid mesh.
    #[error("cannot read mesh file {path}: {source}")]
    Read {
        /// The file read.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: io::Error,
    },
}

/// What a snapshot file says about the state it holds (for its header).
#[derive(Debug, Clone, Copy)]
pub(crate) struct SnapshotState<'a> {
    /// The model.
    pub model: &'a Model,
    /// Step number (0: the initial state).
    pub step: usize,
    /// Time \[time\].
    pub time: Real,
}

/// A file format of snapshot meshes.
pub(crate) trait MeshFormat: Sync {
    /// The file extension, also the snapshot's key in summary.json (`stl`).
    fn extension(&self) -> &'static str;

    /// Writes the device mesh of `state` to `path` (atomically: a reader sees the old file or the new one).
    ///
    /// # Errors
    /// [`MeshIoError`] when the file cannot be written.
    fn write(
        &self,
        path: &Path,
        mesh: &TriangleMesh,
        state: &SnapshotState<'_>,
    ) -> Result<(), MeshIoError>;
}
