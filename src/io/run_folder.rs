//! The run folder as a place on disk: which folders a run may write into, the manifest of the files stentkit
//! wrote there, the lock that keeps two runs out of one folder, and what `--force` may remove.
//!
//! Rules (docs/when-things-go-wrong.md):
//!
//! - A run writes only into an empty or missing folder, or into a **stentkit run folder**: one holding the
//!   manifest [`MANIFEST`] (or, for folders written before the manifest existed, a `summary.json` whose
//!   `stentkit_version` marks it as ours; its file lists are the manifest then). The file-system root, the
//!   home folder and the folder of the design file are refused whatever they hold.
//! - The manifest lists every file the run writes, each appended (and synced) **before** the file is created,
//!   so that even a run killed half-way has listed everything it left. `--force` removes exactly the listed
//!   files (and their hidden temporaries), then the `snapshots/` and `charts/` folders if that left them
//!   empty: a file the user put in the folder is never removed.
//! - A run holds an advisory lock on [`LOCK`] (`flock`, released by the kernel when the process ends, also on
//!   SIGKILL) for its whole length; the lock file records the holder's pid and start time, which a second run
//!   into the same folder is refused with.
//! - Nothing is removed, truncated or rewritten through a symbolic link ([`crate::io::no_follow`]): a run
//!   folder holding a link in the place of a listed file, of a file every run writes ([`RUN_NAMES`]) or of
//!   `snapshots/` or `charts/` is refused by [`classify`], naming the links, before anything is changed; and
//!   every removal, truncation and rewrite below opens its file or folder without following a link. The
//!   folder itself may be a link (the user chose it).

use super::{atomic, no_follow};
use serde::Deserialize;
use std::collections::BTreeSet;
use std::fs::{self, File, OpenOptions};
use std::io::{self, Read, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};

/// The manifest's file name inside a run folder.
pub(crate) const MANIFEST: &str = ".stentkit-run";
/// The lock file's name inside a run folder.
pub(crate) const LOCK: &str = ".stentkit-run.lock";
/// The space reserve's file name inside a run folder (see [`RunFolder::reserve`]).
pub(crate) const RESERVE: &str = ".stentkit-reserve";
/// The checkpoint's file name ([`crate::io::checkpoint`]). The run folder's layout is named here, below the
/// writers that fill it, so that the folder's rules need none of them.
pub(crate) const CHECKPOINT_FILE: &str = "checkpoint.bin";
/// The ParaView collection of the run's field files ([`crate::io::snapshots`]).
pub(crate) const COLLECTION_FILE: &str = "run.pvd";
/// The folder of the snapshots ([`crate::io::snapshots::SnapshotWriter`]).
pub(crate) const SNAPSHOTS_FOLDER: &str = "snapshots";
/// The folder of the charts ([`crate::io::run_charts::RunCharts`]).
pub(crate) const CHARTS_FOLDER: &str = "charts";
/// The names every run writes (or may write) in its folder besides the snapshots and charts: none of them may
/// be a symbolic link ([`classify`]).
pub(crate) const RUN_NAMES: [&str; 10] = [
    MANIFEST,
    LOCK,
    RESERVE,
    "summary.json",
    "history.csv",
    "run.mcap",
    CHECKPOINT_FILE,
    COLLECTION_FILE,
    SNAPSHOTS_FOLDER,
    CHARTS_FOLDER,
];
/// The manifest's first line (the format: one path relative to the run folder per following line).
const MANIFEST_HEADER: &str = "# stentkit run folder: files written by stentkit (`run --force` removes only these), one per line";

/// Why a folder cannot be used as a run folder.
#[derive(Debug, thiserror::Error)]
pub enum RunFolderError {
    /// The folder is not one a run may write into (bad input: choose another `-o`).
    #[error("{path}: {reason}")]
    Refused {
        /// The folder.
        path: PathBuf,
        /// Why, and what to do instead.
        reason: String,
    },
    /// Another run holds the folder's lock.
    #[error(
        "{path} is in use by another stentkit run ({holder}); wait for it to end or choose another folder with -o"
    )]
    Busy {
        /// The folder.
        path: PathBuf,
        /// The holder as its lock file describes it: `pid N, started T`.
        holder: String,
    },
    /// A file-system operation failed.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The operating-system error (its message is part of this error's, so it is not also the source).
        source: io::Error,
    },
}

fn io_error(path: &Path) -> impl FnOnce(io::Error) -> RunFolderError + '_ {
    move |source| RunFolderError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// What a folder holds, as far as a run is concerned.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum FolderKind {
    /// Missing, or holding nothing (a lone lock file of ours counts as nothing).
    Empty,
    /// A stentkit run folder; the files stentkit wrote there (relative paths).
    Run(BTreeSet<PathBuf>),
    /// Anything else: a run must not write there.
    Foreign,
}

/// Looks at `dir` without changing anything. A run folder (or an empty one) holding a symbolic link where
/// stentkit writes — a listed file, one of [`RUN_NAMES`], a folder of either — is refused, naming the links.
///
/// # Errors
/// [`RunFolderError::Refused`] for a path that is not a folder or a folder with links;
/// [`RunFolderError::Io`] when the folder or its manifest cannot be read.
pub(crate) fn classify(dir: &Path) -> Result<FolderKind, RunFolderError> {
    if !dir.exists() {
        return Ok(FolderKind::Empty);
    }
    if !dir.is_dir() {
        return Err(RunFolderError::Refused {
            path: dir.to_path_buf(),
            reason: "exists and is not a folder".into(),
        });
    }
    let manifest = dir.join(MANIFEST);
    let kind = if manifest.exists() {
        let text = fs::read_to_string(&manifest).map_err(io_error(&manifest))?;
        FolderKind::Run(parse_manifest(&text))
    } else if let Some(files) = legacy_outputs(dir) {
        FolderKind::Run(files)
    } else {
        let mut entries = fs::read_dir(dir).map_err(io_error(dir))?;
        if entries.any(|e| e.is_ok_and(|e| e.file_name() != LOCK)) {
            return Ok(FolderKind::Foreign);
        }
        FolderKind::Empty
    };
    let listed = match &kind {
        FolderKind::Run(files) => files.iter().map(PathBuf::as_path).collect(),
        _ => Vec::new(),
    };
    let links = super::no_follow::links_inside(dir, RUN_NAMES.iter().map(Path::new).chain(listed));
    if !links.is_empty() {
        let named: Vec<String> = links
            .iter()
            .map(|(link, target)| format!("{} → {}", link.display(), target.display()))
            .collect();
        return Err(RunFolderError::Refused {
            path: dir.to_path_buf(),
            reason: format!(
                "holds symbolic links where stentkit writes ({}); stentkit removes, truncates or rewrites \
                 nothing through a link: put the files or folders themselves there, or choose another folder \
                 (nothing was changed)",
                named.join(", ")
            ),
        });
    }
    Ok(kind)
}

/// The relative paths a manifest lists: every line but comments and blanks; absolute paths and paths that
/// climb out of the folder (`..`) are ignored, so that a tampered manifest cannot make `--force` remove
/// anything outside the run folder.
fn parse_manifest(text: &str) -> BTreeSet<PathBuf> {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(PathBuf::from)
        .filter(|p| is_inside(p))
        .collect()
}

/// Whether a relative path stays inside its folder (no root, no `..`, not empty).
fn is_inside(path: &Path) -> bool {
    use std::path::Component;
    path.components().next().is_some()
        && path
            .components()
            .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
}

/// The summary fields that list a run's files (summaries written before the manifest existed).
#[derive(Deserialize)]
struct LegacySummary {
    stentkit_version: String,
    #[serde(default)]
    snapshots: Vec<LegacySnapshot>,
    files: LegacyFiles,
}

#[derive(Deserialize)]
struct LegacySnapshot {
    stl: PathBuf,
    obj: PathBuf,
}

#[derive(Deserialize)]
struct LegacyFiles {
    history: PathBuf,
    mcap: PathBuf,
    #[serde(default)]
    charts: Vec<PathBuf>,
}

/// The files of a run folder written before the manifest existed, as its `summary.json` lists them; `None`
/// when there is no such summary.
fn legacy_outputs(dir: &Path) -> Option<BTreeSet<PathBuf>> {
    let summary: LegacySummary = crate::io::input::read_json(&dir.join("summary.json")).ok()?;
    if summary.stentkit_version.is_empty() {
        return None;
    }
    let mut files: BTreeSet<PathBuf> = [
        PathBuf::from("summary.json"),
        summary.files.history,
        summary.files.mcap,
    ]
    .into_iter()
    .chain(summary.files.charts)
    .chain(summary.snapshots.into_iter().flat_map(|s| [s.stl, s.obj]))
    .collect();
    files.retain(|p| is_inside(p));
    Some(files)
}

/// Folders no run may write into, whatever they hold: the file-system root, the home folder and the folder of
/// the design file. `None` when `dir` is none of them.
fn forbidden(dir: &Path, design_file: &Path) -> Option<&'static str> {
    let Ok(dir) = dir.canonicalize() else {
        // A folder that does not exist yet is none of these (they all exist).
        return None;
    };
    if dir.parent().is_none() {
        return Some("is the file-system root");
    }
    if std::env::var_os("HOME")
        .and_then(|h| PathBuf::from(h).canonicalize().ok())
        .is_some_and(|home| home == dir)
    {
        return Some("is your home folder");
    }
    let design_dir = design_file
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if design_dir.canonicalize().is_ok_and(|d| d == dir) {
        return Some("is the folder of the design file");
    }
    None
}

/// Whether a run of the design in `design_file` may write into `dir`, changing nothing: refuses the root, the
/// home folder, the design's folder, a folder that is not empty and not a run folder, and (without `force`) a
/// run folder that holds an earlier run. Returns the folder found fit, with the earlier run's files (what
/// `--force` will remove), to be taken with [`FitFolder::open`].
///
/// # Errors
/// [`RunFolderError::Refused`] (bad input), [`RunFolderError::Io`].
pub(crate) fn check(
    dir: &Path,
    design_file: &Path,
    force: bool,
) -> Result<FitFolder, RunFolderError> {
    let refuse = |reason: String| RunFolderError::Refused {
        path: dir.to_path_buf(),
        reason,
    };
    if let Some(why) = forbidden(dir, design_file) {
        return Err(refuse(format!(
            "{why}; a run writes into a folder of its own: choose one with -o (default runs/<design name>)"
        )));
    }
    let previous = match classify(dir)? {
        FolderKind::Empty => BTreeSet::new(),
        FolderKind::Foreign => {
            return Err(refuse(
                "is not empty and is not a stentkit run folder (it has no .stentkit-run manifest); \
                 choose an empty or new folder with -o"
                    .into(),
            ));
        }
        // A folder whose earlier run left none of its files (a refused or cleared run) is as good as empty.
        FolderKind::Run(files) if files.iter().all(|f| !dir.join(f).exists()) => files,
        FolderKind::Run(_) if !force => {
            return Err(refuse(
                "holds an earlier run; pass --force to replace it (only the files that run wrote are \
                 removed) or choose another folder with -o"
                    .into(),
            ));
        }
        FolderKind::Run(files) => files,
    };
    Ok(FitFolder {
        dir: dir.to_path_buf(),
        previous,
    })
}

/// A folder [`check`] found fit for a run, not yet taken: nothing has been written.
#[derive(Debug)]
pub(crate) struct FitFolder {
    dir: PathBuf,
    /// Files of the earlier run here.
    previous: BTreeSet<PathBuf>,
}

impl FitFolder {
    /// The folder.
    pub(crate) fn dir(&self) -> &Path {
        &self.dir
    }

    /// Bytes of the earlier run's files: what `--force` will free.
    pub(crate) fn previous_bytes(&self) -> u64 {
        files_bytes(&self.dir, &self.previous)
    }

    /// Takes the folder: creates it, takes its lock and opens the manifest. Nothing is removed yet.
    ///
    /// # Errors
    /// [`RunFolderError::Busy`] when another run holds the lock, [`RunFolderError::Io`].
    pub(crate) fn open(self) -> Result<RunFolder, RunFolderError> {
        RunFolder::take(self.dir, self.previous)
    }
}

/// Whether the folder of an earlier run can be continued (`stentkit run --resume`), changing nothing: `dir`
/// must be a stentkit run folder ([`classify`]: no links where stentkit writes) whose manifest lists
/// `checkpoint` (a path inside it), and that file must exist. Returns the folder found fit, to be taken with
/// [`ResumableFolder::open`] once the caller's own checks (the checkpoint's content, the history's length)
/// pass too: a refusal changes nothing on disk.
///
/// # Errors
/// [`RunFolderError::Refused`] (bad input) for a folder that is not a run folder or holds no checkpoint,
/// [`RunFolderError::Io`].
pub(crate) fn check_resume(
    dir: &Path,
    checkpoint: &Path,
) -> Result<ResumableFolder, RunFolderError> {
    let refuse = |reason: String| RunFolderError::Refused {
        path: dir.to_path_buf(),
        reason,
    };
    let files = match classify(dir)? {
        FolderKind::Run(files) => files,
        FolderKind::Empty => {
            return Err(refuse(
                "is empty or missing: there is no run to resume; start one without --resume".into(),
            ));
        }
        FolderKind::Foreign => {
            return Err(refuse(
                "is not a stentkit run folder (it has no .stentkit-run manifest): there is no run to resume"
                    .into(),
            ));
        }
    };
    if !files.contains(checkpoint) || !dir.join(checkpoint).is_file() {
        return Err(refuse(format!(
            "holds no checkpoint ({}): the run wrote none (it ran for less than --checkpoint-every, or with a stentkit without checkpoints), so it cannot be resumed; run it again with --force",
            checkpoint.display()
        )));
    }
    Ok(ResumableFolder {
        dir: dir.to_path_buf(),
        files,
    })
}

/// The folder of an earlier run that [`check_resume`] found fit to continue, not yet taken: nothing has been
/// written.
#[derive(Debug)]
pub(crate) struct ResumableFolder {
    dir: PathBuf,
    /// The files its manifest lists.
    files: BTreeSet<PathBuf>,
}

impl ResumableFolder {
    /// Takes the folder (its lock; the manifest keeps its list, and the continued run appends to it) and
    /// removes the hidden temporaries of listed files (what a killed run leaves); nothing else is removed.
    ///
    /// # Errors
    /// [`RunFolderError::Busy`] when a run holds it, [`RunFolderError::Io`].
    pub(crate) fn open(self) -> Result<RunFolder, RunFolderError> {
        let folder = RunFolder::take(self.dir, BTreeSet::new())?;
        remove_stale_temporaries(&folder.dir, &self.files)?;
        Ok(folder)
    }
}

/// Bytes of the files `files` (relative to `dir`) that exist.
fn files_bytes(dir: &Path, files: &BTreeSet<PathBuf>) -> u64 {
    files
        .iter()
        .filter_map(|p| fs::metadata(dir.join(p)).ok())
        .map(|m| m.len())
        .sum()
}

/// A run folder held by this process: locked, with its manifest open for appending.
#[derive(Debug)]
pub struct RunFolder {
    dir: PathBuf,
    /// Files of the previous run here (removed by [`RunFolder::clear_previous`]).
    previous: BTreeSet<PathBuf>,
    manifest: Manifest,
    /// Held for the life of the run: the kernel releases the lock when the process ends.
    _lock: File,
}

/// The manifest of a run folder, shared by the writers of one run (cheap to clone).
#[derive(Debug, Clone)]
pub struct Manifest {
    inner: Arc<Mutex<ManifestFile>>,
}

#[derive(Debug)]
struct ManifestFile {
    path: PathBuf,
    file: File,
    listed: BTreeSet<PathBuf>,
}

impl Manifest {
    /// Lists `relative` (a path inside the run folder) before the file is created: appended and synced, so that
    /// a run killed right after still owns the file. Listing a file twice writes it once.
    ///
    /// # Errors
    /// The I/O error (e.g. a full disk), naming the manifest.
    pub fn claim(&self, relative: &Path) -> io::Result<()> {
        let mut m = self.inner.lock().unwrap_or_else(PoisonError::into_inner);
        if m.listed.contains(relative) {
            return Ok(());
        }
        let line = format!("{}\n", relative.display());
        let result = m
            .file
            .write_all(line.as_bytes())
            .and_then(|()| m.file.sync_data());
        result.map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", m.path.display())))?;
        m.listed.insert(relative.to_path_buf());
        Ok(())
    }

    /// The files listed so far.
    pub fn listed(&self) -> BTreeSet<PathBuf> {
        self.inner
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .listed
            .clone()
    }
}

impl RunFolder {
    /// [`check`] then [`FitFolder::open`]: takes `dir` for a run of the design in `design_file`.
    ///
    /// # Errors
    /// As those two.
    pub fn open(dir: &Path, design_file: &Path, force: bool) -> Result<Self, RunFolderError> {
        check(dir, design_file, force)?.open()
    }

    fn take(dir: PathBuf, previous: BTreeSet<PathBuf>) -> Result<Self, RunFolderError> {
        let dir = dir.as_path();
        fs::create_dir_all(dir).map_err(io_error(dir))?;
        let lock = lock(dir)?;
        let path = dir.join(MANIFEST);
        let mut file = no_follow::open(
            &path,
            OpenOptions::new().create(true).append(true).read(true),
        )
        .map_err(io_error(&path))?;
        let mut text = String::new();
        file.seek(io::SeekFrom::Start(0))
            .and_then(|_| file.read_to_string(&mut text))
            .map_err(io_error(&path))?;
        if text.is_empty() {
            writeln!(file, "{MANIFEST_HEADER}")
                .and_then(|()| file.sync_data())
                .map_err(io_error(&path))?;
        }
        let listed = parse_manifest(&text);
        Ok(Self {
            dir: dir.to_path_buf(),
            previous,
            manifest: Manifest {
                inner: Arc::new(Mutex::new(ManifestFile { path, file, listed })),
            },
            _lock: lock,
        })
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The manifest, for the writers of the run.
    pub fn manifest(&self) -> &Manifest {
        &self.manifest
    }

    /// Bytes of the files this run wrote (those its manifest lists) as they are now.
    pub fn written_bytes(&self) -> u64 {
        files_bytes(&self.dir, &self.manifest.listed())
    }

    /// Writes a hidden file of `bytes` zeros (real blocks, not a sparse file), deleted when the returned
    /// [`Reserve`] is released or dropped: a disk that fills up during the run still has that much room for the
    /// summary and the charts.
    ///
    /// # Errors
    /// [`RunFolderError::Io`] when the reserve cannot be written (the disk is already full).
    pub fn reserve(&self, bytes: usize) -> Result<Reserve, RunFolderError> {
        let relative = Path::new(RESERVE);
        let path = self.dir.join(relative);
        self.manifest.claim(relative).map_err(io_error(&path))?;
        let written = no_follow::create(&path)
            .and_then(|mut f| f.write_all(&vec![0u8; bytes]).and_then(|()| f.sync_data()));
        let reserve = Reserve {
            dir: self.dir.clone(),
        };
        if let Err(e) = written {
            drop(reserve);
            return Err(io_error(&path)(e));
        }
        Ok(reserve)
    }

    /// Removes the files of the earlier run in this folder (only those its manifest lists), stale hidden
    /// temporaries of listed files (left by a killed run), then `snapshots/` and `charts/` if that left them
    /// empty; starts a fresh manifest.
    ///
    /// # Errors
    /// [`RunFolderError::Io`] naming the file that could not be removed.
    pub fn clear_previous(&mut self) -> Result<(), RunFolderError> {
        remove_stale_temporaries(&self.dir, &self.previous)?;
        for relative in &self.previous {
            let path = self.dir.join(relative);
            if path.is_file() {
                no_follow::remove_inside(&self.dir, relative).map_err(io_error(&path))?;
            }
        }
        for folder in [SNAPSHOTS_FOLDER, CHARTS_FOLDER] {
            // Only if empty: a file of the user's keeps its folder.
            let _ = fs::remove_dir(self.dir.join(folder));
        }
        let mut m = self
            .manifest
            .inner
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        let path = m.path.clone();
        m.file
            .set_len(0)
            .and_then(|()| writeln!(m.file, "{MANIFEST_HEADER}"))
            .and_then(|()| m.file.sync_data())
            .map_err(io_error(&path))?;
        m.listed.clear();
        self.previous.clear();
        Ok(())
    }
}

/// Room on disk held for finishing a run (see [`RunFolder::reserve`]); given back by [`Reserve::release`] or
/// when dropped.
#[derive(Debug)]
pub struct Reserve {
    /// The run folder it is in (as [`RESERVE`]).
    dir: PathBuf,
}

impl Reserve {
    /// Deletes the reserve file, giving its room to the files that finish the run.
    pub fn release(self) {}
}

impl Drop for Reserve {
    fn drop(&mut self) {
        // Best effort: a reserve that cannot be deleted is listed in the manifest and removed by `--force`.
        let _ = no_follow::remove_inside(&self.dir, Path::new(RESERVE));
    }
}

/// Removes the hidden temporaries of the listed files `owned` in their folders
/// ([`atomic::remove_stale_temporaries`]): what a run killed during an atomic write leaves. Returns them,
/// relative to `dir`.
///
/// # Errors
/// [`RunFolderError::Io`] naming the file that could not be removed.
pub(crate) fn remove_stale_temporaries(
    dir: &Path,
    owned: &BTreeSet<PathBuf>,
) -> Result<Vec<PathBuf>, RunFolderError> {
    let folders: BTreeSet<&Path> = owned
        .iter()
        .map(|p| p.parent().unwrap_or(Path::new("")))
        .collect();
    let mut removed = Vec::new();
    for folder in folders {
        let owns = |target: &str| owned.contains(&folder.join(target));
        removed.extend(
            atomic::remove_stale_temporaries(dir, folder, &owns).map_err(|e| {
                RunFolderError::Io {
                    path: e.path,
                    source: e.source,
                }
            })?,
        );
    }
    Ok(removed)
}

/// Takes the lock of `dir` and writes who holds it.
fn lock(dir: &Path) -> Result<File, RunFolderError> {
    let path = dir.join(LOCK);
    let mut file = no_follow::open(
        &path,
        OpenOptions::new()
            .create(true)
            .truncate(false)
            .read(true)
            .write(true),
    )
    .map_err(io_error(&path))?;
    match file.try_lock() {
        Ok(()) => {}
        Err(fs::TryLockError::WouldBlock) => {
            let mut holder = String::new();
            let _ = file.read_to_string(&mut holder);
            let holder = holder.trim();
            return Err(RunFolderError::Busy {
                path: dir.to_path_buf(),
                holder: if holder.is_empty() {
                    "pid unknown".into()
                } else {
                    holder.to_string()
                },
            });
        }
        Err(fs::TryLockError::Error(e)) => return Err(io_error(&path)(e)),
    }
    let holder = format!(
        "pid {}, started {}",
        std::process::id(),
        utc_timestamp(std::time::SystemTime::now())
    );
    file.set_len(0)
        .and_then(|()| file.write_all(holder.as_bytes()))
        .and_then(|()| file.sync_data())
        .map_err(io_error(&path))?;
    Ok(file)
}

/// Takes the lock of an existing run folder without starting a run (for `stentkit repair`): refuses a folder
/// another run holds.
///
/// # Errors
/// As [`RunFolder::open`].
pub(crate) fn lock_existing(dir: &Path) -> Result<File, RunFolderError> {
    lock(dir)
}

/// `2026-11-23T21:56:03Z` for a system time (UTC; days to civil date by Howard Hinnant's algorithm,
/// <https://howardhinnant.github.io/date_algorithms.html#civil_from_days>).
pub(crate) fn utc_timestamp(time: std::time::SystemTime) -> String {
    let secs = time
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (days, rest) = ((secs / 86_400) as i64, secs % 86_400);
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rest / 3600,
        rest % 3600 / 60,
        rest % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("stentkit-folder-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).expect("scratch folder");
        dir
    }

    /// Known instants: the Unix epoch, a leap day and the session's date (checked with `date -u -d @SECS`).
    #[test]
    fn utc_timestamps_match_the_civil_calendar() {
        let at = |s| utc_timestamp(std::time::UNIX_EPOCH + std::time::Duration::from_secs(s));
        assert_eq!(at(0), "1970-01-01T00:00:00Z");
        assert_eq!(at(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(at(1_795_471_563), "2026-11-23T22:06:03Z");
    }

    #[test]
    fn a_manifest_cannot_point_outside_its_folder() {
        let listed = parse_manifest(
            "# header\nhistory.csv\n../x\n/etc/passwd\nsnapshots/step_00000.stl\n\n",
        );
        let expected: BTreeSet<PathBuf> = ["history.csv", "snapshots/step_00000.stl"]
            .into_iter()
            .map(PathBuf::from)
            .collect();
        assert_eq!(listed, expected);
    }

    /// A second lock on the same folder (another open file description, as another process would hold) is
    /// refused and names the holder's pid.
    #[test]
    fn a_locked_folder_is_refused_with_its_holder() {
        let dir = scratch("lock");
        let design = dir.join("design.yaml");
        let run = dir.join("run");
        let first = RunFolder::open(&run, &design, false).expect("first run");
        let second = RunFolder::open(&run, &design, true);
        match second {
            Err(RunFolderError::Busy { holder, .. }) => {
                assert!(
                    holder.contains(&format!("pid {}", std::process::id())),
                    "{holder}"
                )
            }
            other => panic!("expected Busy, got {other:?}"),
        }
        drop(first);
        RunFolder::open(&run, &design, true).expect("free again once the first is dropped");
    }

    /// `clear_previous` removes the listed files and their stale temporaries, nothing else.
    #[test]
    fn force_removes_only_listed_files() {
        let dir = scratch("force");
        let design = dir.join("design.yaml");
        let run = dir.join("run");
        {
            let folder = RunFolder::open(&run, &design, false).expect("open");
            fs::create_dir_all(run.join("snapshots")).expect("mkdir");
            for f in ["history.csv", "snapshots/step_00000.stl"] {
                folder.manifest().claim(Path::new(f)).expect("claim");
                fs::write(run.join(f), "ours").expect("write");
            }
        }
        fs::write(run.join("notes.txt"), "user").expect("write");
        fs::write(run.join("snapshots/mine.stl"), "user").expect("write");
        fs::write(run.join("snapshots/.step_00000.stl.77.0.tmp"), "stale").expect("write");
        fs::write(run.join("snapshots/.mine.stl.77.0.tmp"), "user's").expect("write");
        assert!(matches!(
            RunFolder::open(&run, &design, false),
            Err(RunFolderError::Refused { .. })
        ));
        let mut folder = RunFolder::open(&run, &design, true).expect("force");
        folder.clear_previous().expect("clear");
        assert!(!run.join("history.csv").exists());
        assert!(!run.join("snapshots/step_00000.stl").exists());
        assert!(!run.join("snapshots/.step_00000.stl.77.0.tmp").exists());
        assert!(run.join("notes.txt").exists());
        assert!(run.join("snapshots/mine.stl").exists());
        assert!(run.join("snapshots/.mine.stl.77.0.tmp").exists());
        assert!(folder.manifest().listed().is_empty());
    }

    #[test]
    fn foreign_root_home_and_design_folders_are_refused() {
        let dir = scratch("refuse");
        let design = dir.join("design.yaml");
        fs::write(&design, "x").expect("write");
        for (target, force) in [(dir.clone(), true), (PathBuf::from("/"), true)] {
            assert!(
                matches!(
                    RunFolder::open(&target, &design, force),
                    Err(RunFolderError::Refused { .. })
                ),
                "{} accepted",
                target.display()
            );
        }
        let foreign = dir.join("foreign");
        fs::create_dir_all(&foreign).expect("mkdir");
        fs::write(foreign.join("thesis.tex"), "user").expect("write");
        assert!(matches!(
            RunFolder::open(&foreign, &design, true),
            Err(RunFolderError::Refused { .. })
        ));
        assert!(foreign.join("thesis.tex").exists());
        assert!(
            !foreign.join(LOCK).exists(),
            "nothing written into a refused folder"
        );
    }
}
