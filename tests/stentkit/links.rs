//! Links and existing files (issue 31, "Data written or deleted outside the run folder"): nothing stentkit
//! removes, truncates or rewrites is reached through a symbolic link — `repair`, `run --resume` and
//! `run --force` refuse a run folder holding links where stentkit writes, naming them, and change nothing; a
//! refused `--resume` (its history shortened or missing) changes nothing either, so the run resumes once the
//! history is back; and every command that writes a file the user names refuses to replace it without
//! `--force` (exit status 2, the path named).
//!
//! Source: the rule in docs/when-things-go-wrong.md (**Links and existing files**); each test reproduces one of
//! the reports on the smallest designs (bend45: 10 steps, half a second; the two-crown stent of
//! `resume.rs` where a checkpoint is needed, killed after its first one). Comparisons are exact: a refusal
//! leaves every byte, link and folder as it was.

use crate::outputs::{design, path_str, scratch_folder, stentkit, summary, text};
use crate::resume::{killed_two_crown_run, resume};
use std::collections::BTreeMap;
use std::os::unix::fs::symlink;
use std::path::{Path, PathBuf};
use std::process::Output;

/// A fresh scratch folder for test `name`.
fn scratch(name: &str) -> PathBuf {
    scratch_folder("links-tests", name)
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

/// A fresh scratch folder for test `name` holding a completed bend45 run in `run/`: (scratch, run folder).
fn finished_bend45(name: &str) -> (PathBuf, PathBuf) {
    let root = scratch(name);
    let run = root.join("run");
    let out = run_bend45(&run, &[]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    (root, run)
}

/// `stentkit sweep designs/bend45.yaml --set time.step=0.1,0.05 -o DIR` with `extra` arguments.
fn sweep_bend45(dir: &Path, extra: &[&str]) -> Output {
    let file = design("bend45.yaml");
    let mut args = vec!["sweep", path_str(&file), "--set", "time.step=0.1,0.05"];
    args.extend_from_slice(&["-o", path_str(dir)]);
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
    let (root, run) = finished_bend45("repair");
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
        let (root, run) = finished_bend45(&format!("force-{}", name.replace('.', "_")));
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

/// `--resume` with `history.csv` a link to a user's copy of it: before, the resumed run cut the user's file
/// back to the checkpoint's row and wrote its rows into it. Now the resume is refused (exit status 2) naming
/// the link, and nothing changes.
#[test]
fn resume_refuses_a_linked_history_and_changes_nothing() {
    let root = scratch("resume-link");
    let (design, dir) = killed_two_crown_run(&root);
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
    let (design, dir) = killed_two_crown_run(&scratch("resume-refused"));
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

/// `mesh -o FILE` over an existing file (a mesh, the wires' CSV, a print solid): before, the file was replaced
/// silently. Now each is refused (exit status 2, the path named, the file unchanged); with `--force` it is
/// replaced — and a link in its place is replaced by the file, not written through.
#[test]
fn mesh_refuses_an_existing_file_without_force() {
    let dir = scratch("mesh");
    let file = design("bend45.yaml");
    let design = path_str(&file);
    for (name, extra) in [
        ("shape.stl", &[][..]),
        ("wires.csv", &[][..]),
        ("solid.3mf", &["--print"][..]),
    ] {
        let output = dir.join(name);
        std::fs::write(&output, "the user's").expect("written");
        let mut args = vec!["mesh", design, "-o", path_str(&output)];
        args.extend_from_slice(extra);
        assert_refused(&stentkit(&args), &[path_str(&output), "--force"]);
        assert_eq!(
            std::fs::read(&output).expect("kept"),
            b"the user's",
            "{name}"
        );
    }
    // With --force: replaced.
    for name in ["shape.stl", "wires.csv"] {
        let output = dir.join(name);
        let out = stentkit(&["mesh", design, "-o", path_str(&output), "--force"]);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        assert_ne!(std::fs::read(&output).expect("written"), b"the user's");
    }
    // A link in the output's place: refused without --force, replaced (not written through) with it.
    let users = dir.join("users.stl");
    std::fs::write(&users, "the user's").expect("written");
    let link = dir.join("link.stl");
    symlink(&users, &link).expect("link");
    assert_refused(
        &stentkit(&["mesh", design, "-o", path_str(&link)]),
        &[path_str(&link)],
    );
    let out = stentkit(&["mesh", design, "-o", path_str(&link), "--force"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(
        !std::fs::symlink_metadata(&link)
            .expect("there")
            .is_symlink()
    );
    assert_eq!(std::fs::read(&users).expect("kept"), b"the user's");
}

/// `export -o FILE` and `render -o FILE.png` over an existing file: refused without `--force` (exit status 2,
/// the path named, the file unchanged), replaced with it.
#[test]
fn export_and_render_refuse_an_existing_file_without_force() {
    let (dir, run) = finished_bend45("export-render");
    let stl = dir.join("state.stl");
    let png = dir.join("picture.png");
    let export = |extra: &[&str]| {
        let mut args = vec!["export", path_str(&run), "--time", "0.5"];
        args.extend_from_slice(&["-o", path_str(&stl)]);
        args.extend_from_slice(extra);
        stentkit(&args)
    };
    let render = |extra: &[&str]| {
        let mut args = vec!["render", path_str(&run), "-o", path_str(&png)];
        args.extend_from_slice(extra);
        stentkit(&args)
    };
    for (output, command) in [
        (&stl, &export as &dyn Fn(&[&str]) -> Output),
        (&png, &render),
    ] {
        std::fs::write(output, "the user's").expect("written");
        assert_refused(&command(&[]), &[path_str(output), "--force"]);
        assert_eq!(std::fs::read(output).expect("kept"), b"the user's");
        let out = command(&["--force"]);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        assert_ne!(std::fs::read(output).expect("written"), b"the user's");
    }
}

/// `study … -o DIR` over a folder holding a file the study writes (`convergence.csv`, `error_vs_h.svg`,
/// `stability.md`): before, `study convergence` overwrote the user's CSV. Now each is refused before any run
/// (exit status 2, the file named, unchanged). A folder holding only other files is used, and they stay; with
/// `--force` the study's files are replaced. The convergence study is the cheapest there is (pure bending,
/// p = 4, n = 8 against n = 12, to t = 0.5: 0.2 s).
#[test]
fn studies_refuse_to_replace_their_files_without_force() {
    let dir = scratch("studies");
    let pure_bending = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/pure_bending.yaml");
    let bending = path_str(&pure_bending);
    let convergence = |out: &Path, extra: &[&str]| {
        let mut args = vec!["study", "convergence", bending, "--degrees", "4"];
        args.extend_from_slice(&["--points", "8", "--reference", "4,12", "--time", "0.5"]);
        args.extend_from_slice(&["--time-tolerance", "none", "-o", path_str(out)]);
        args.extend_from_slice(extra);
        stentkit(&args)
    };
    let cases: [(&str, Vec<&str>); 3] = [
        ("convergence.csv", vec![]),
        (
            "error_vs_h.svg",
            vec!["study", "time", bending, "--steps", "0.1"],
        ),
        (
            "stability.md",
            vec!["study", "stability", "--maps", "material"],
        ),
    ];
    for (file, command) in cases {
        let out_dir = dir.join(file.replace('.', "_"));
        std::fs::create_dir_all(&out_dir).expect("mkdir");
        let users = out_dir.join(file);
        std::fs::write(&users, "the user's").expect("written");
        let out = if command.is_empty() {
            convergence(&out_dir, &[])
        } else {
            let mut args = command.clone();
            args.extend_from_slice(&["-o", path_str(&out_dir)]);
            stentkit(&args)
        };
        assert_refused(&out, &[path_str(&users), "--force"]);
        assert_eq!(
            std::fs::read(&users).expect("kept"),
            b"the user's",
            "{file}"
        );
    }

    // A folder with the user's notes only: used, the notes kept.
    let notes_dir = dir.join("with_notes");
    std::fs::create_dir_all(&notes_dir).expect("mkdir");
    std::fs::write(notes_dir.join("notes.txt"), "the user's").expect("written");
    let out = convergence(&notes_dir, &[]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(
        std::fs::read(notes_dir.join("notes.txt")).expect("kept"),
        b"the user's"
    );
    // With --force over the refused folder: replaced.
    let refused = dir.join("convergence_csv");
    let out = convergence(&refused, &["--force"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let csv = std::fs::read_to_string(refused.join("convergence.csv")).expect("written");
    assert!(csv.contains("pure_bending"), "{csv}");
}

/// `tune -o FILE` refused an existing file before this issue (with no way to replace it) and still does, now
/// through the same check as every command (exit status 2, the path named); `sweep -o DIR` refuses a folder
/// that is not empty and holds no sweep (its own rule, unchanged). Neither touches the user's file.
#[test]
fn tune_and_sweep_refuse_the_users_files() {
    let dir = scratch("tune-sweep");
    let users = dir.join("tuned.yaml");
    std::fs::write(&users, "the user's").expect("written");
    let file = design("bend45.yaml");
    let out = stentkit(&[
        "tune",
        path_str(&file),
        "--tol",
        "1e-2",
        "-o",
        path_str(&users),
    ]);
    assert_refused(&out, &[path_str(&users), "--force"]);
    assert_refused(&sweep_bend45(&dir, &[]), &["holds no sweep"]);
    assert_eq!(std::fs::read(&users).expect("kept"), b"the user's");
}

/// A sweep folder's own files are not written through links either: `sweep --slurm --dry-run` rewrites
/// `sweep.sbatch` on every call, and before it wrote the script into whatever a link in its place pointed at.
/// Now the write fails, naming the link, and the user's file is unchanged.
#[test]
fn a_sweeps_script_is_not_written_through_a_link() {
    let root = scratch("sweep-script");
    let dir = root.join("sweep");
    let sweep = || sweep_bend45(&dir, &["--slurm", "--dry-run"]);
    let out = sweep();
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let users = root.join("job.sh");
    std::fs::write(&users, "the user's").expect("written");
    std::fs::remove_file(dir.join("sweep.sbatch")).expect("removed");
    symlink(&users, dir.join("sweep.sbatch")).expect("link");
    let out = sweep();
    assert_ne!(out.status.code(), Some(0));
    assert!(
        text(&out.stderr).contains("is a symbolic link"),
        "{}",
        text(&out.stderr)
    );
    assert_eq!(std::fs::read(&users).expect("kept"), b"the user's");
}
