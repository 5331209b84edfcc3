//! The atomic file write every writer of stentkit uses: a temporary file `.<name>.<pid>.<n>.tmp` in the
//! target's directory, filled, flushed, synced to disk and renamed over the target (an atomic replacement on
//! POSIX file systems). A reader, or a run interrupted while writing, never sees a partial file: the target
//! either keeps its old content or gets the complete new one; a link in the target's place is replaced, not
//! written through. [`crate::io::run_folder`] recognises the temporary names and removes those a killed run
//! left.

use std::ffi::OsString;
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use super::mesh_format::MeshIoError;

/// Distinguishes temporary files of concurrent writes from one process.
static TEMPORARY_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `bytes` to `path` atomically, as the mesh writers do: a temporary file in the same folder, synced,
/// then renamed over the target, so that a reader (or a run interrupted while writing) never sees a partial
/// file. Used for `summary.json` and the charts.
///
/// # Errors
/// The I/O error of creating, writing, syncing or renaming the temporary file; the target is then unchanged.
pub(crate) fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomically(path, |w| w.write_all(bytes)).map_err(|e| match e {
        MeshIoError::Write { source, .. } | MeshIoError::Read { source, .. } => source,
    })
}

/// A fresh temporary file name for `file_name`, `.<name>.<pid>.<n>.tmp` (unique within the process; what
/// [`crate::io::run_folder::remove_stale_temporaries`] recognises and removes after a killed run).
pub(crate) fn temporary_name(file_name: &std::ffi::OsStr) -> OsString {
    let mut name = OsString::from(".");
    name.push(file_name);
    name.push(format!(
        ".{}.{}.tmp",
        std::process::id(),
        TEMPORARY_COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    name
}

/// Writes a file atomically: `write` fills a temporary file `.<name>.<pid>.<n>.tmp` in the target's
/// directory, which is then flushed, synced to disk and renamed over `path` (an atomic replacement on
/// POSIX and Windows file systems). On any error the temporary file is removed and the target is untouched.
///
/// # Errors
/// [`MeshIoError::Write`] with `path` and the first error met.
pub(crate) fn write_atomically<F>(path: &Path, write: F) -> Result<(), MeshIoError>
where
    F: FnOnce(&mut BufWriter<File>) -> io::Result<()>,
{
    let err = |source| MeshIoError::Write {
        path: path.to_path_buf(),
        source,
    };
    let file_name = path.file_name().ok_or_else(|| {
        err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "the path does not name a file",
        ))
    })?;
    let directory = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let temporary = directory.join(temporary_name(file_name));
    let file = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&temporary)
        .map_err(err)?;
    let result = (|| {
        let mut buffered = BufWriter::new(file);
        write(&mut buffered)?;
        let file = buffered
            .into_inner()
            .map_err(io::IntoInnerError::into_error)?;
        file.sync_all()?;
        drop(file);
        fs::rename(&temporary, path)
    })();
    result.map_err(|e| {
        // Best effort: the write already failed, and a leftover temporary file is only litter.
        let _ = fs::remove_file(&temporary);
        err(e)
    })
}
