//! The atomic file write every writer of stentkit uses: a temporary file `.<name>.<pid>.<n>.tmp` in the
//! target's directory, filled, flushed, synced to disk (unless asked not to: [`Durability`]) and renamed over
//! the target (an atomic replacement on POSIX file systems). A reader, or a run interrupted while writing,
//! never sees a partial file: the target either keeps its old content or gets the complete new one; a link in
//! the target's place is replaced, not written through.
//!
//! **Stale temporaries.** A writer killed between creating its temporary and renaming it (SIGKILL, a power
//! loss) leaves the temporary behind, a hidden file that nothing reads. The names are recognised here
//! ([`temporary_target`]) and removed, only for targets the caller owns, by [`remove_stale_temporaries`]:
//! [`crate::io::run_folder`] does so for the files a run folder's manifest lists (on `--force` and on
//! `--resume`), [`crate::sweep`] for a sweep folder's own files when it prepares or collects the sweep. A name
//! of this pattern whose target is not the caller's (a user's `.notes.txt.1.2.tmp` beside a run) is left.

use std::ffi::OsString;
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use super::mesh_format::MeshIoError;
use super::no_follow;

/// Whether an atomic write waits for the disk before it renames its temporary into place.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Durability {
    /// Synced (`fsync`) before the rename: once the call returns the new content survives a power loss.
    Synced,
    /// Renamed as soon as written: the new content survives the process being killed (the kernel holds it),
    /// but after a power loss the file may be empty. For many small files a reader checks anyway (a sweep's
    /// variant designs: a sync each would cost more than the rest of the preparation).
    Unsynced,
}

/// A stale temporary that could not be removed ([`remove_stale_temporaries`]).
#[derive(Debug, thiserror::Error)]
#[error("cannot remove {path}: {source}")]
pub struct RemoveError {
    /// The temporary.
    pub path: PathBuf,
    /// The underlying error.
    #[source]
    pub source: io::Error,
}

/// Distinguishes temporary files of concurrent writes from one process.
static TEMPORARY_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `bytes` to `path` atomically, as the mesh writers do: a temporary file in the same folder, synced,
/// then renamed over the target, so that a reader (or a run interrupted while writing) never sees a partial
/// file. Used for `summary.json` and the charts.
///
/// # Errors
/// The I/O error of creating, writing, syncing or renaming the temporary file; the target is then unchanged.
pub(crate) fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_file_atomically(path, bytes, Durability::Synced)
}

/// Writes `contents` (bytes or text) to `path` atomically, synced to disk before the rename or not as
/// `durability` says ([`write_bytes_atomically`] syncs).
///
/// # Errors
/// The I/O error of creating, writing, syncing or renaming the temporary file; the target is then unchanged.
pub(crate) fn write_file_atomically(
    path: &Path,
    contents: impl AsRef<[u8]>,
    durability: Durability,
) -> io::Result<()> {
    write_atomically_as(path, durability, |w| w.write_all(contents.as_ref())).map_err(|e| match e {
        MeshIoError::Write { source, .. } | MeshIoError::Read { source, .. } => source,
    })
}

/// A fresh temporary file name for `file_name`, `.<name>.<pid>.<n>.tmp` (unique within the process; what
/// [`temporary_target`] recognises and [`remove_stale_temporaries`] removes after a killed writer).
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
    write_atomically_as(path, Durability::Synced, write)
}

/// [`write_atomically`], synced to disk before the rename or not as `durability` says.
fn write_atomically_as<F>(path: &Path, durability: Durability, write: F) -> Result<(), MeshIoError>
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
        if durability == Durability::Synced {
            file.sync_all()?;
        }
        drop(file);
        fs::rename(&temporary, path)
    })();
    result.map_err(|e| {
        // Best effort: the write already failed, and a leftover temporary file is only litter.
        let _ = fs::remove_file(&temporary);
        err(e)
    })
}

/// The file a temporary `.<name>.<pid>.<n>.tmp` of this module was to become (`<name>`), if `name` is one.
pub(crate) fn temporary_target(name: &str) -> Option<&str> {
    let rest = name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (rest, counter) = rest.rsplit_once('.')?;
    let (target, pid) = rest.rsplit_once('.')?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    (digits(counter) && digits(pid) && !target.is_empty()).then_some(target)
}

/// Removes from the folder `dir/folder` (reached without following a link: [`no_follow::folder_inside`]) the
/// temporaries of this module whose target `owns` (a file name in that folder) — what a writer killed during
/// an atomic write leaves (module docs). Returns them, relative to `dir`. A folder that is missing (or is a
/// link) holds none of ours. Not for a folder another process may be writing into at the same time: its
/// temporary in progress would be removed under it.
///
/// # Errors
/// [`RemoveError`] naming the temporary that could not be removed.
pub(crate) fn remove_stale_temporaries(
    dir: &Path,
    folder: &Path,
    owns: &dyn Fn(&str) -> bool,
) -> Result<Vec<PathBuf>, RemoveError> {
    let Ok(opened) = no_follow::folder_inside(dir, folder) else {
        return Ok(Vec::new());
    };
    let Ok(names) = opened.names() else {
        return Ok(Vec::new());
    };
    let mut removed = Vec::new();
    for name in names {
        if !name.to_str().and_then(temporary_target).is_some_and(owns) {
            continue;
        }
        let removed_one = opened.remove(&name).map_err(|source| RemoveError {
            path: dir.join(folder).join(&name),
            source,
        })?;
        if removed_one {
            removed.push(folder.join(&name));
        }
    }
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporaries_are_recognised_by_their_whole_pattern() {
        assert_eq!(
            temporary_target(".summary.json.123.4.tmp"),
            Some("summary.json")
        );
        assert_eq!(
            temporary_target(".step_00001.stl.9.0.tmp"),
            Some("step_00001.stl")
        );
        assert_eq!(temporary_target("summary.json.123.4.tmp"), None);
        assert_eq!(temporary_target(".notes.tmp"), None);
        assert_eq!(temporary_target(".a.b.c.tmp"), None);
        // What this module names its temporaries, recognised as such.
        let name = temporary_name(std::ffi::OsStr::new("sweep.json"));
        assert_eq!(
            temporary_target(name.to_str().expect("UTF-8")),
            Some("sweep.json")
        );
    }

    // An unsynced write lands as a synced one does, replaces the target whole, and leaves no temporary; a
    // stale temporary of an owned target is removed, one of another target is left. Reference: the bytes
    // written and the folder's listing.
    #[test]
    fn unsynced_writes_land_whole_and_only_owned_temporaries_are_removed() {
        let dir = std::env::temp_dir().join(format!("stentkit-atomic-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).expect("folder");
        let target = dir.join("design.yaml");
        fs::write(&target, "old and longer").expect("write");
        write_file_atomically(&target, "new", Durability::Unsynced).expect("unsynced");
        assert_eq!(fs::read_to_string(&target).expect("read"), "new");
        write_file_atomically(&target, b"newer", Durability::Synced).expect("synced");
        assert_eq!(fs::read_to_string(&target).expect("read"), "newer");
        let names = || -> Vec<String> {
            let mut n: Vec<String> = fs::read_dir(&dir)
                .expect("list")
                .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
                .collect();
            n.sort();
            n
        };
        assert_eq!(names(), ["design.yaml"]);
        fs::write(dir.join(".design.yaml.77.0.tmp"), "stale").expect("write");
        fs::write(dir.join(".notes.txt.77.1.tmp"), "user's").expect("write");
        let removed = remove_stale_temporaries(&dir, Path::new(""), &|t| t == "design.yaml")
            .expect("removed");
        assert_eq!(removed, [PathBuf::from(".design.yaml.77.0.tmp")]);
        assert_eq!(names(), [".notes.txt.77.1.tmp", "design.yaml"]);
        assert_eq!(
            remove_stale_temporaries(&dir.join("missing"), Path::new(""), &|_| true)
                .expect("nothing"),
            Vec::<PathBuf>::new()
        );
        fs::remove_dir_all(&dir).expect("clean up");
    }
}
