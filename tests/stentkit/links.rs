//! Links and existing files (issue 31, "Data written or deleted outside the run folder"): nothing stentkit
//! removes, truncates or rewrites is reached through a symbolic link — `repair`, `run --resume` and
//! `run --force` refuse a run folder holding links where stentkit writes, naming them, and change nothing; a
//! refused `--resume` (its history shortened or missing) changes nothing either, so the run resumes once the
//! history is back; and every command that writes a file the user names refuses to replace it without
//! `--force` (exit status 2, the path named).
//!
//! Source: the rule in README "When things go wrong" (**Links and existing files**); each test reproduces one of
//! the reports on the smallest designs (bend45: 10 steps, half a second; the two-crown stent of
//! `resume.rs` where a checkpoint is needed, killed after its first one). Comparisons are exact: a refusal
//! leaves every byte, link and folder as it was.

use crate::outputs::{design, path_str, stentkit, summary, text};
use crate::resume::{resume, spawn, two_crown_stent, wait_for_checkpoint};
use std::collections::BTreeMap;
use std::os::unix::fs::symlink;
use std::path::{Path, PathBuf};
use std::process::Output;

/// A fresh scratch folder for test `name`.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("links-tests")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// One entry of a folder, seen without following links.
#[derive(Debug, PartialEq)]
enum Entry {
    File(Vec<u8>),
    Link(PathBuf),
    Folder,
}

/// Everything below `dir` (relative paths), links not followed: what a refusal must leave unchanged.
fn contents(dir: &Path) -> BTreeMap<PathBuf, Entry> {
    fn walk(root: &Path, folder: &Path, into: &mut BTreeMap<PathBuf, Entry>) {
        for entry in std::fs::read_dir(folder).expect("readable folder") {
            let path = entry.expect("entry").path();
            let relative = path.strip_prefix(root).expect("inside").to_path_buf();
            let kind = std::fs::symlink_metadata(&path)
                .expect("metadata")
                .file_type();
            if kind.is_symlink() {
                into.insert(
                    relative,
                    Entry::Link(std::fs::read_link(&path).expect("link")),
                );
            } else if kind.is_dir() {
                into.insert(relative, Entry::Folder);
                walk(root, &path, into);
            } else {
                into.insert(relative, Entry::File(std::fs::read(&path).expect("file")));
            }
        }
    }
    let mut found = BTreeMap::new();
    walk(dir, dir, &mut found);
    found
}

/// `stentkit run designs/bend45.yaml -o DIR --quiet` with `extra` arguments.
fn run_bend45(dir: &Path, extra: &[&str]) -> Output {
    let file = design("bend45.yaml");
    let mut args = vec!["run", path_str(&file), "-o", path_str(dir), "--quiet"];
    args.extend_from_slice(extra);
    stentkit(&args)
}

/// Asserts exit status 2 with a message containing every one of `words`.
fn assert_refused(out: &Output, words: &[&str]) {
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    for w in words {
        assert!(stderr.contains(w), "`{w}` not in: {stderr}");
    }
}

/// `history.csv` and `run.mcap` of a killed run, replaced by links to a user's files: before, `repair` cut the
/// partial last row off the user's CSV and cut and rewrote the user's recording. Now it refuses (exit status 2)
/// naming both links, and nothing changes, in the run folder or in the user's.
#[test]
fn repair_refuses_links_and_changes_nothing() {
    let root = scratch("repair");
    let run = root.join("run");
    let out = run_bend45(&run, &[]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    // As a killed run leaves it: the summary still says `running`.
    let summary_path = run.join("summary.json");
    let s = std::fs::read_to_string(&summary_path).expect("summary");
    let running = s.replace("\"status\": \"completed\"", "\"status\": \"running\"");
    assert_ne!(running, s, "the summary's status is written as expected");
    std::fs::write(&summary_path, running).expect("written");
    // The user's files: a CSV with a partial last row, and a recording cut two thirds in (both what repair
    // would cut and finish if they were the run's).
    let users = root.join("users");
    std::fs::create_dir_all(&users).expect("mkdir");
    let mut csv = std::fs::read(run.join("history.csv")).expect("history");
    csv.extend_from_slice(b"1.1,0.25");
    std::fs::write(users.join("measurements.csv"), &csv).expect("written");
    let mcap = std::fs::read(run.join("run.mcap")).expect("recording");
    std::fs::write(users.join("bench.mcap"), &mcap[..mcap.len() * 2 / 3]).expect("written");
    for (name, target) in [
        ("history.csv", "measurements.csv"),
        ("run.mcap", "bench.mcap"),
    ] {
        std::fs::remove_file(run.join(name)).expect("removed");
        symlink(users.join(target), run.join(name)).expect("link");
    }
    let (run_before, users_before) = (contents(&run), contents(&users));

    let out = stentkit(&["repair", path_str(&run)]);
    assert_refused(
        &out,
        &[
            &format!("history.csv → {}", users.join("measurements.csv").display()),
            &format!("run.mcap → {}", users.join("bench.mcap").display()),
            "symbolic link",
            "nothing was changed",
        ],
    );
    assert_eq!(contents(&users), users_before, "the user's files");
    assert_eq!(contents(&run), run_before, "the run folder");
}

/// `run --force` over a run folder whose `snapshots/` or `charts/` is a link to a user's folder (holding files
/// with the manifest's names and one of the user's), or whose `history.csv` is a link to a user's file: before,
/// the user's files with manifest names were deleted and the new run's written into the user's folder. Now
/// the run is refused (exit status 2) naming the link and its target, and nothing changes anywhere. A run
/// folder that is itself a link (`-o` names a link to a folder) is the user's choice and is used.
#[test]
fn force_refuses_a_folder_holding_links_and_changes_nothing() {
    for (name, is_folder) in [
        ("snapshots", true),
        ("charts", true),
        ("history.csv", false),
    ] {
        let root = scratch(&format!("force-{}", name.replace('.', "_")));
        let run = root.join("run");
        let out = run_bend45(&run, &[]);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        // The user's folder or file: the run's moved there, so its names are the manifest's.
        let users = root.join("users");
        std::fs::create_dir_all(&users).expect("mkdir");
        let target = users.join(name);
        std::fs::rename(run.join(name), &target).expect("moved");
        if is_folder {
            std::fs::write(target.join("holiday.jpg"), "the user's").expect("written");
        }
        symlink(&target, run.join(name)).expect("link");
        let (run_before, users_before) = (contents(&run), contents(&users));

        let out = run_bend45(&run, &["--force"]);
        assert_refused(
            &out,
            &[
                &format!("{name} → {}", target.display()),
                "nothing was changed",
            ],
        );
        assert_eq!(contents(&users), users_before, "{name}: the user's files");
        assert_eq!(contents(&run), run_before, "{name}: the run folder");
    }

    // The run folder itself may be a link.
    let root = scratch("force-linked-folder");
    let real = root.join("real");
    std::fs::create_dir_all(&real).expect("mkdir");
    symlink(&real, root.join("via_link")).expect("link");
    for extra in [&[][..], &["--force"][..]] {
        let out = run_bend45(&root.join("via_link"), extra);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    }
    assert_eq!(summary(&real)["status"], "completed");
}

/// The two-crown stent killed by SIGKILL after its first checkpoint (at least 50 history rows written): a folder
/// `--resume` continues. Returns the scratch folder, the design and the run folder.
fn killed_run(name: &str) -> (PathBuf, PathBuf, PathBuf) {
    let root = scratch(name);
    let design = two_crown_stent(&root);
    let dir = root.join("run");
    let mut child = spawn(&design, &dir);
    wait_for_checkpoint(&mut child, &dir, 50);
    child.kill().expect("SIGKILL");
    child.wait().expect("reaped");
    (root, design, dir)
}

/// `--resume` with `history.csv` a link to a user's copy of it: before, the resumed run cut the user's file
/// back to the checkpoint's row and wrote its rows into it. Now the resume is refused (exit status 2) naming
/// the link, and nothing changes.
#[test]
fn resume_refuses_a_linked_history_and_changes_nothing() {
    let (root, design, dir) = killed_run("resume-link");
    let users = root.join("users");
    std::fs::create_dir_all(&users).expect("mkdir");
    let history = dir.join("history.csv");
    std::fs::rename(&history, users.join("copy.csv")).expect("moved");
    symlink(users.join("copy.csv"), &history).expect("link");
    let (dir_before, users_before) = (contents(&dir), contents(&users));

    let (code, stderr) = resume(&design, &dir);
    assert_eq!(code, Some(2), "{stderr}");
    let named = format!("history.csv → {}", users.join("copy.csv").display());
    assert!(stderr.contains(&named), "{stderr}");
    assert_eq!(contents(&users), users_before, "the user's copy");
    assert_eq!(contents(&dir), dir_before, "the run folder");
}

/// A resume refused because `history.csv` is shorter than at the checkpoint (cut to its header) or missing:
/// before, the refusal rewrote `summary.json` to `failed`, and every later `--resume` was refused for that
/// status although `checkpoint.bin` was intact. Now each refusal (exit status 2, naming the file and what it
/// holds against what the checkpoint needs) leaves the folder byte for byte as it was, and with the history put
/// back the run resumes and completes.
#[test]
fn a_refused_resume_changes_nothing_and_the_run_resumes_later() {
    let (_root, design, dir) = killed_run("resume-refused");
    let history = dir.join("history.csv");
    let rows = std::fs::read(&history).expect("history");
    let header = rows.iter().position(|&b| b == b'\n').expect("a header") + 1;

    for (case, damage, said) in [
        ("shortened", Some(&rows[..header]), "fewer than"),
        ("missing", None, "is missing"),
    ] {
        match damage {
            Some(bytes) => std::fs::write(&history, bytes).expect("shortened"),
            None => std::fs::remove_file(&history).expect("removed"),
        }
        let before = contents(&dir);
        let (code, stderr) = resume(&design, &dir);
        assert_eq!(code, Some(2), "{case}: {stderr}");
        assert!(
            stderr.contains(said) && stderr.contains("history.csv"),
            "{case}: {stderr}"
        );
        assert_eq!(contents(&dir), before, "{case}: the run folder");
    }

    std::fs::write(&history, &rows).expect("put back");
    let (code, stderr) = resume(&design, &dir);
    assert_eq!(code, Some(0), "{stderr}");
    assert_eq!(summary(&dir)["status"], "completed");
}
