//! Changing files without following symbolic links: every file stentkit removes, truncates or rewrites in a
//! folder of its own (a run folder, a sweep folder) goes through this module.
//!
//! The rule (docs/when-things-go-wrong.md, **Links and existing files**): nothing stentkit removes, truncates
//! or rewrites is reached through a symbolic link. A link named `history.csv` may point at a user's file, and a
//! `snapshots/` that is a link may be a user's folder: opening such a path for writing, or removing a file
//! below it, would change the user's data instead of stentkit's. So
//!
//! - a file is opened for a change with `O_NOFOLLOW` ([`open`]): a link in its place makes the open fail
//!   (`ELOOP`), and the change is then made on the handle (read, cut, appended to), never on the path again;
//! - a file below a folder is removed through that folder opened with `O_NOFOLLOW | O_DIRECTORY`, one path
//!   component at a time (`openat`), then `unlinkat` ([`remove_inside`]): no component below the root is a
//!   link at the moment of the removal, whatever happens to the paths meanwhile;
//! - a folder that holds links where stentkit writes is refused before anything is changed, naming them
//!   ([`links_inside`]; [`crate::io::run_folder::classify`] refuses a run folder that holds any);
//! - a sweep folder's own files that are not written atomically (`sweep.sbatch`, `slurm.json`, a variant's
//!   `log.txt` and `task_error.txt`) are written with [`write()`] or [`open`], so a link in their place is an
//!   error, not a way into a user's file.
//!
//! The folder the user names (`-o DIR`, `RUN_DIR`) may itself be a link: the user chose that place, as they
//! choose any path they type. Only what lies inside it is held to the rule. A file written atomically (a
//! temporary renamed over the target, [`crate::io::atomic::write_bytes_atomically`]) replaces a link in its place
//! and never writes through it, so it needs nothing from here.

use std::ffi::{CString, OsStr};
use std::fs::{File, OpenOptions};
use std::io;
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Component, Path, PathBuf};

/// Opens `path` with `options` and `O_NOFOLLOW`: when `path` is a symbolic link the open fails (an error that
/// says so, naming the path) instead of opening what the link points at. Links in the folders above `path`
/// are followed (see [`remove_inside`] for a path checked component by component).
///
/// # Errors
/// The operating system's, with the path in the message when `path` is a link.
pub(crate) fn open(path: &Path, options: &mut OpenOptions) -> io::Result<File> {
    options
        .custom_flags(libc::O_NOFOLLOW | libc::O_CLOEXEC)
        .open(path)
        .map_err(|e| named_link(e, path))
}

/// Creates (or truncates) `path` for writing, refusing a link in its place ([`open`]).
///
/// # Errors
/// As [`open`].
pub(crate) fn create(path: &Path) -> io::Result<File> {
    open(
        path,
        OpenOptions::new().write(true).create(true).truncate(true),
    )
}

/// Writes `bytes` to `path`, created or truncated, refusing a link in its place ([`create`]): `std::fs::write`
/// for a file stentkit owns.
///
/// # Errors
/// As [`open`], and the write's.
pub(crate) fn write(path: &Path, bytes: &[u8]) -> io::Result<()> {
    io::Write::write_all(&mut create(path)?, bytes)
}

/// Removes the file `root/relative` without following a link below `root`: each folder of `relative` is
/// opened with `O_NOFOLLOW | O_DIRECTORY` from the one before (`openat`), and the file is removed from the
/// last with `unlinkat` (a link in the file's own place is removed itself; what it points at is not touched).
/// Returns whether there was a file to remove.
///
/// # Errors
/// The operating system's; a folder of `relative` that is a link is an error naming it.
pub(crate) fn remove_inside(root: &Path, relative: &Path) -> io::Result<bool> {
    let (Some(folder), Some(name)) = (relative.parent(), relative.file_name()) else {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{}: does not name a file", root.join(relative).display()),
        ));
    };
    folder_inside(root, folder)?.remove(name)
}

/// The names in the folder `root/relative` and a handle that removes from that very folder (see
/// [`FolderInside::remove`]); no component of `relative` may be a link.
///
/// # Errors
/// The operating system's; a component that is a link is an error naming it.
pub(crate) fn folder_inside(root: &Path, relative: &Path) -> io::Result<FolderInside> {
    Ok(FolderInside {
        path: root.join(relative),
        fd: open_folder_inside(root, relative)?,
    })
}

/// A folder opened without following links ([`folder_inside`]).
#[derive(Debug)]
pub(crate) struct FolderInside {
    path: PathBuf,
    fd: OwnedFd,
}

impl FolderInside {
    /// The names of the entries of the folder (listed by path: a listing raced by a swapped folder can only
    /// name files that [`FolderInside::remove`] then looks for in the folder opened, not in the swapped one).
    ///
    /// # Errors
    /// The folder cannot be read.
    pub(crate) fn names(&self) -> io::Result<Vec<std::ffi::OsString>> {
        std::fs::read_dir(&self.path)?
            .map(|e| e.map(|e| e.file_name()))
            .collect()
    }

    /// Removes the entry `name` of this folder (a link is removed itself); whether there was one.
    ///
    /// # Errors
    /// The operating system's, naming the file.
    pub(crate) fn remove(&self, name: &OsStr) -> io::Result<bool> {
        let c = c_name(name)?;
        // SAFETY: `self.fd` is an open directory descriptor owned by `self`, alive for the call, and `c` a
        // NUL-terminated string that outlives it; unlinkat(2) touches no memory of ours beyond reading `c`.
        let status = unsafe { libc::unlinkat(self.fd.as_raw_fd(), c.as_ptr(), 0) };
        if status == 0 {
            return Ok(true);
        }
        match io::Error::last_os_error() {
            e if e.kind() == io::ErrorKind::NotFound => Ok(false),
            e => Err(io::Error::new(
                e.kind(),
                format!("{}: {e}", self.path.join(name).display()),
            )),
        }
    }
}

/// The paths below `root`, among `relatives` and their folders, that are symbolic links (each once, in the
/// order met), with what they point at. Looks only; a path that does not exist is no link.
pub(crate) fn links_inside<'a>(
    root: &Path,
    relatives: impl IntoIterator<Item = &'a Path>,
) -> Vec<(PathBuf, PathBuf)> {
    let mut links: Vec<(PathBuf, PathBuf)> = Vec::new();
    for relative in relatives {
        let mut prefix = PathBuf::new();
        for component in relative.components() {
            let Component::Normal(part) = component else {
                continue;
            };
            prefix.push(part);
            let path = root.join(&prefix);
            let Ok(meta) = std::fs::symlink_metadata(&path) else {
                // Missing: nothing below it exists either.
                break;
            };
            if meta.file_type().is_symlink() {
                if !links.iter().any(|(p, _)| *p == prefix) {
                    let target = std::fs::read_link(&path).unwrap_or_default();
                    links.push((prefix.clone(), target));
                }
                break;
            }
        }
    }
    links
}

/// `root/relative` opened as a folder, each component of `relative` with `O_NOFOLLOW` from the folder before
/// (`root` itself is opened as named: see the module docs).
fn open_folder_inside(root: &Path, relative: &Path) -> io::Result<OwnedFd> {
    let root_path = if root.as_os_str().is_empty() {
        Path::new(".")
    } else {
        root
    };
    let mut folder: OwnedFd = OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_DIRECTORY | libc::O_CLOEXEC)
        .open(root_path)
        .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", root_path.display())))?
        .into();
    let mut reached = root.to_path_buf();
    for component in relative.components() {
        let part = match component {
            Component::Normal(part) => part,
            Component::CurDir => continue,
            _ => {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!(
                        "{}: leaves the folder {}",
                        relative.display(),
                        root.display()
                    ),
                ));
            }
        };
        reached.push(part);
        let name = c_name(part)?;
        // SAFETY: `folder` is an open directory descriptor we own and `name` a NUL-terminated string alive for
        // the call; openat(2) returns a new descriptor (or -1), which we take ownership of just below.
        let fd = unsafe {
            libc::openat(
                folder.as_raw_fd(),
                name.as_ptr(),
                libc::O_RDONLY | libc::O_DIRECTORY | libc::O_NOFOLLOW | libc::O_CLOEXEC,
            )
        };
        if fd < 0 {
            return Err(named_link(io::Error::last_os_error(), &reached));
        }
        // SAFETY: `fd` was just returned by openat(2), is valid and owned by nothing else.
        folder = unsafe { OwnedFd::from_raw_fd(fd) };
    }
    Ok(folder)
}

/// A path component as a C string (a component holds no NUL byte; one that did is refused).
fn c_name(name: &OsStr) -> io::Result<CString> {
    CString::new(name.as_bytes())
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "a file name holds a NUL byte"))
}

/// `error` of an open with `O_NOFOLLOW`, said plainly when the cause is that `path` is a link (`ELOOP`; for a
/// folder opened with `O_DIRECTORY` a link is `ELOOP` too, and `ENOTDIR` when it is a file).
fn named_link(error: io::Error, path: &Path) -> io::Error {
    let is_link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    if error.raw_os_error() == Some(libc::ELOOP) || is_link {
        io::Error::new(
            error.kind(),
            format!(
                "{} is a symbolic link: stentkit changes no file through a link",
                path.display()
            ),
        )
    } else {
        error
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::symlink;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("stentkit-no-follow-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("scratch folder");
        dir
    }

    /// A link in a file's place: opening it to write fails and names it; the file it points at keeps its bytes.
    #[test]
    fn a_link_is_not_opened_for_a_change() {
        let dir = scratch("open");
        std::fs::write(dir.join("users.txt"), "keep me").expect("write");
        symlink(dir.join("users.txt"), dir.join("history.csv")).expect("link");
        let e = open(&dir.join("history.csv"), OpenOptions::new().write(true))
            .expect_err("a link is refused");
        assert!(e.to_string().contains("is a symbolic link"), "{e}");
        let e = create(&dir.join("history.csv")).expect_err("a link is refused");
        assert!(e.to_string().contains("history.csv"), "{e}");
        assert_eq!(
            std::fs::read_to_string(dir.join("users.txt")).expect("read"),
            "keep me"
        );
        // A plain file opens.
        create(&dir.join("plain.csv")).expect("a file is created");
    }

    /// A file below a folder that is a link is not removed (the folder is a user's); a link in the file's own
    /// place is removed itself, and what it points at stays.
    #[test]
    fn nothing_is_removed_through_a_linked_folder() {
        let dir = scratch("remove");
        let users = dir.join("pictures");
        std::fs::create_dir_all(&users).expect("mkdir");
        std::fs::write(users.join("t0.stl"), "user's").expect("write");
        let run = dir.join("run");
        std::fs::create_dir_all(&run).expect("mkdir");
        symlink(&users, run.join("snapshots")).expect("link");
        let e = remove_inside(&run, Path::new("snapshots/t0.stl")).expect_err("refused");
        assert!(e.to_string().contains("snapshots"), "{e}");
        assert!(users.join("t0.stl").exists());
        assert!(folder_inside(&run, Path::new("snapshots")).is_err());
        assert_eq!(
            links_inside(&run, [Path::new("snapshots/t0.stl")]),
            vec![(PathBuf::from("snapshots"), users.clone())]
        );

        symlink(users.join("t0.stl"), run.join("history.csv")).expect("link");
        assert!(remove_inside(&run, Path::new("history.csv")).expect("removed"));
        assert!(!run.join("history.csv").exists() && users.join("t0.stl").exists());
        assert!(!remove_inside(&run, Path::new("history.csv")).expect("gone"));

        std::fs::create_dir_all(run.join("charts")).expect("mkdir");
        std::fs::write(run.join("charts/a.svg"), "ours").expect("write");
        let charts = folder_inside(&run, Path::new("charts")).expect("a real folder");
        assert_eq!(charts.names().expect("names"), vec!["a.svg"]);
        assert!(charts.remove(OsStr::new("a.svg")).expect("removed"));
        assert!(links_inside(&run, [Path::new("charts/a.svg")]).is_empty());
    }
}
