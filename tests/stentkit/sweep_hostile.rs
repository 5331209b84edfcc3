//! Hostile sweeps (issue 31, items 11, 13, 14 and 15): a sweep the disk cannot hold, a signal or SIGKILL while
//! the variants are prepared, a hand-edited `sweep.json`, a path swept twice, and control characters headed for
//! the batch script.
//!
//! Most cases use the 45° bend (designs/bend45.yaml: one patch, ten steps, a few milliseconds to read) and
//! `--slurm --dry-run`, which prepares the sweep folder and writes `sweep.sbatch` without running a variant, so
//! no simulation runs and no Slurm is needed. The disk refusal uses the straight stent with a snapshot at every
//! step (1301 snapshots of 5 MB each), so that 5000 variants need tens of terabytes, more than any disk these
//! tests run on.

use crate::outputs::{design, path_str, stentkit, test_outputs, text, wait_at_most};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};
use stentkit::design::{DesignOverrides, load_design_with};
use stentkit::run::estimate::estimated_disk;

/// 5000 values of the Poisson ratio of the bend (`0, 0.0001, …, 0.4999`): the issue's sweep size, each value
/// valid, none changing what a run writes.
const NU_5000: &str = "material.nu=0:0.4999:0.0001";

/// `stentkit sweep DESIGN --set … -o DIR --slurm --dry-run` followed by `extra`.
fn dry_run_args(design_file: &Path, sets: &[&str], dir: &Path, extra: &[&str]) -> Vec<String> {
    let mut args = vec!["sweep".to_string(), path_str(design_file).to_string()];
    for s in sets {
        args.push("--set".into());
        args.push(s.to_string());
    }
    args.extend(["-o".into(), path_str(dir).into(), "--slurm".into()]);
    args.push("--dry-run".into());
    args.extend(extra.iter().map(|s| s.to_string()));
    args
}

fn call(args: &[String]) -> Output {
    stentkit(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

fn spawn(args: &[String]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_stentkit"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("stentkit starts")
}

/// Polls `done` every 2 ms for at most a minute.
fn wait_until(what: &str, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "timed out waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
}

fn signal(child: &Child, name: &str) {
    let status = Command::new("kill")
        .args([&format!("-{name}"), &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(status.success());
}

/// Variants of the sweep in `dir` whose design was written (`design.yaml` or `error.txt`).
fn prepared(dir: &Path) -> usize {
    std::fs::read_dir(dir.join("variants")).map_or(0, |entries| {
        entries
            .flatten()
            .filter(|e| {
                e.path().join("design.yaml").exists() || e.path().join("error.txt").exists()
            })
            .count()
    })
}

/// Every file under `dir` that is a writer's temporary: io::atomic's hidden `.<name>.<pid>.<n>.tmp`, or the
/// `.partial` of the sweep's earlier writer.
fn partial_files(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if is_temporary(&e.file_name().to_string_lossy()) {
                found.push(p);
            }
        }
    }
    found
}

/// Whether `name` is a writer's temporary (see [`partial_files`]).
fn is_temporary(name: &str) -> bool {
    name.ends_with(".partial") || (name.starts_with('.') && name.ends_with(".tmp"))
}

/// `32 TB`, `6.5 GB`, `740 kB` (as stentkit prints sizes) in bytes.
fn parse_bytes(text: &str) -> f64 {
    let (number, unit) = text.trim().split_once(' ').expect("NUMBER UNIT");
    let scale = match unit {
        "TB" => 1e12,
        "GB" => 1e9,
        "MB" => 1e6,
        "kB" => 1e3,
        "B" => 1.0,
        other => panic!("unit {other}"),
    };
    number.parse::<f64>().expect("a number") * scale
}

// Item 11, the estimate. Reproduces: `sweep` of 5000 variants started without a disk estimate (the issue's
// straight stent: 5000 × 58 MB ≈ 290 GB). Numbers: here each variant takes a snapshot at every one of its 1301
// steps, so the run estimate of one variant (`estimated_disk`, what `run` checks) is about 6.5 GB and the sweep's
// 5000 variants need about 32 TB; the test first checks that this exceeds the free space of the file system it
// writes to (it does on any disk we know of). The sweep sums the run estimate over its variants: the total it
// prints must be at least 5000 times the smallest variant's estimate (Tg changes nothing a run writes but the
// few bytes of its value in the recorded design) and at most 1 % above it (the variants' design files and the
// 1 MiB reserve of each concurrent run are a few kB per variant besides). The refusal must come before anything
// is written (the folder does not exist afterwards) and quickly: the variants differ only in Tg, so one design
// is built to estimate all 5000; 60 s is the limit (before the fix the command went on preparing and running
// the variants, which takes hours).
#[test]
fn a_sweep_the_disk_cannot_hold_is_refused_before_anything_is_written() {
    let stent = design("straight_stent.yaml");
    let sets = ["output.snapshots.every=1", "material.wlf.Tg=50:99.99:0.01"];
    let one = load_design_with(
        &stent,
        &DesignOverrides::sets(vec![
            sets[0].parse().expect("override"),
            "material.wlf.Tg=50".parse().expect("override"),
        ]),
    )
    .expect("the variant is valid");
    let per_variant = estimated_disk(&one).total() as f64;
    let lower = 5000.0 * per_variant;
    let dir = test_outputs("sweep_hostile_disk");
    let root = dir.parent().expect("a parent");
    let free = fs4::available_space(root).expect("free space") as f64;
    assert!(
        free < lower,
        "this file system has {free} bytes free, more than the {lower} bytes this test's sweep needs"
    );
    let args = dry_run_args(&stent, &sets, &dir, &[]);
    let started = Instant::now();
    let out = wait_at_most(spawn(&args), Duration::from_secs(60), "the refusal");
    let elapsed = started.elapsed();
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(!dir.exists(), "the refusal wrote {}", dir.display());
    let message = stderr
        .lines()
        .find(|l| l.starts_with("error:"))
        .unwrap_or_else(|| panic!("no error line in {stderr}"));
    assert!(message.contains("5000 variants to run"), "{message}");
    assert!(
        message.contains(&format!("into {}", dir.display())),
        "{message}"
    );
    let total = message
        .split("would write about ")
        .nth(1)
        .and_then(|rest| rest.split(" (").next())
        .map(parse_bytes)
        .unwrap_or_else(|| panic!("no total in {message}"));
    // `32 TB` is rounded to whole terabytes: half a unit either way.
    assert!(
        (lower - 0.5e12..=1.01 * lower + 0.5e12).contains(&total),
        "{total} against {lower}: {message}"
    );
    assert!(
        message.contains("whose file system has ") && message.contains(" free"),
        "{message}"
    );
    eprintln!("refused in {elapsed:.2?}: {message}");
    // The same with a relative folder whose parent does not exist yet (`-o new/tg` in an empty folder): the
    // free space is the current folder's file system's (it was not checked at all before).
    let cwd = test_outputs("sweep_hostile_disk_relative");
    std::fs::create_dir_all(&cwd).expect("folder");
    let relative = dry_run_args(&stent, &sets, Path::new("new/tg"), &[]);
    let child = Command::new(env!("CARGO_BIN_EXE_stentkit"))
        .args(&relative)
        .current_dir(&cwd)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("stentkit starts");
    let out = wait_at_most(child, Duration::from_secs(60), "the relative refusal");
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("into new/tg, whose file system has "),
        "{}",
        text(&out.stderr)
    );
    assert!(!cwd.join("new").exists());
}

// Item 11, a signal while the variants are prepared. Reproduces: a signal during the preparation of 5000
// variants was ignored until every variant was prepared (41 s in the issue). Now the plan is written first and
// the first signal stops the preparation after the variant in hand: exit status 130, `sweep.json` in place,
// fewer than the 5000 variants prepared, no temporary file left; the same command then prepares the rest (all
// 5000) and ends normally.
#[test]
fn a_signal_stops_the_preparation_and_the_same_command_continues_it() {
    let dir = test_outputs("sweep_hostile_signal");
    let args = dry_run_args(&design("bend45.yaml"), &[NU_5000], &dir, &[]);
    let child = spawn(&args);
    wait_until("the first variant", || {
        dir.join("variants/v000/design.yaml").exists()
    });
    let signalled = Instant::now();
    signal(&child, "INT");
    let out = wait_at_most(child, Duration::from_secs(60), "the stop");
    let latency = signalled.elapsed();
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(dir.join("sweep.json").exists());
    let done = prepared(&dir);
    assert!(
        done < 5000,
        "all {done} variants were prepared after the signal"
    );
    assert!(partial_files(&dir).is_empty(), "{:?}", partial_files(&dir));
    assert!(stderr.contains("the same command continues"), "{stderr}");
    eprintln!("stopped {latency:.2?} after SIGINT with {done} of 5000 variants prepared");
    let out = call(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(prepared(&dir), 5000);
    assert!(dir.join("sweep.sbatch").exists());
}

// Item 11, SIGKILL while the variants are prepared. Reproduces: a preparation killed outright left a folder of
// variants without `sweep.json`, which the same command then refused for ever ("is not empty and holds no
// sweep"). Now `sweep.json` is written first and every file atomically: the same command continues the folder
// and prepares all 5000 variants.
#[test]
fn a_preparation_killed_outright_is_continued_by_the_same_command() {
    let dir = test_outputs("sweep_hostile_kill");
    let args = dry_run_args(&design("bend45.yaml"), &[NU_5000], &dir, &[]);
    let mut child = spawn(&args);
    wait_until("the first variants", || {
        dir.join("variants/v010/design.yaml").exists()
    });
    child.kill().expect("SIGKILL");
    let _ = child.wait();
    let before = prepared(&dir);
    assert!(before < 5000, "the kill came after the preparation");
    let out = call(&args);
    assert!(
        out.status.success(),
        "after SIGKILL with {before} variants prepared: {}",
        text(&out.stderr)
    );
    assert_eq!(prepared(&dir), 5000);
    assert!(partial_files(&dir).is_empty(), "{:?}", partial_files(&dir));
}

// Issue 32, item 3: stale temporaries in a sweep folder. The sweep's files are written through io::atomic,
// whose temporaries are `.<name>.<pid>.<n>.tmp` (unique per write, so a killed writer's is not overwritten by
// the next one, as the earlier `<name>.partial` was). Planted here as a writer killed outright leaves them: a
// folder holding only a temporary of `sweep.json` is accepted as empty and prepared; a rerun of the
// preparation removes the temporaries of `sweep.json`, `sweep.csv` and each variant's `design.yaml` and
// `error.txt`, a collection those of `sweep.csv` and the charts; a hidden file of the same pattern whose
// target is not the sweep's (a user's `.notes.txt.1.2.tmp`) is left. Reference: the folder's listing, and the
// prepared designs, which must be those of a folder prepared without temporaries (the bend over two Poisson
// ratios, one refused: nu = 0.6 > 0.5).
#[test]
fn stale_temporaries_in_a_sweep_folder_are_removed_and_nothing_else() {
    use stentkit::sweep::collect::collect;
    use stentkit::sweep::{Parameter, Plan, Prepared, Resolutions, SweepDir};
    let parameters = vec![Parameter::parse("material.nu=0.3,0.6").expect("parameter")];
    let plan = Plan::new(&design("bend45.yaml"), parameters, false).expect("plan");
    let stale = ".sweep.json.999999.0.tmp";
    let prepare = |dir: &SweepDir| {
        let prepared = dir.prepare(&plan, &Resolutions::new(), &|| false);
        assert_eq!(prepared.expect("prepared"), Prepared::All);
    };
    // The reference: a folder prepared without temporaries.
    let clean = SweepDir {
        dir: test_outputs("sweep_stale_clean"),
    };
    prepare(&clean);
    // A folder a preparation was killed in while writing the plan.
    let dir = SweepDir {
        dir: test_outputs("sweep_stale"),
    };
    std::fs::create_dir_all(&dir.dir).expect("folder");
    std::fs::write(dir.dir.join(stale), "{\"design\": ").expect("stale plan");
    dir.check(&plan)
        .expect("a folder holding only the plan's temporary is empty");
    prepare(&dir);
    assert!(
        partial_files(&dir.dir).is_empty(),
        "{:?}",
        partial_files(&dir.dir)
    );
    // Killed writers of every kind, and a user's hidden file of the same pattern.
    let planted = [
        stale,
        ".sweep.csv.999999.1.tmp",
        "variants/v000/.design.yaml.999999.2.tmp",
        "variants/v001/.error.txt.999999.3.tmp",
        "charts/.fixity_vs_nu.svg.999999.4.tmp",
    ];
    std::fs::create_dir_all(dir.dir.join("charts")).expect("charts");
    for name in planted {
        std::fs::write(dir.dir.join(name), "stale").expect("planted");
    }
    let users = dir.dir.join("variants/v000/.notes.txt.1.2.tmp");
    std::fs::write(&users, "the user's").expect("user's file");
    prepare(&dir);
    let mut left = partial_files(&dir.dir);
    left.sort();
    let chart = dir.dir.join("charts/.fixity_vs_nu.svg.999999.4.tmp");
    assert_eq!(left, [chart, users.clone()], "after the preparation");
    collect(&dir, None).expect("collected");
    assert_eq!(partial_files(&dir.dir), [users], "after the collection");
    for file in [
        "sweep.json",
        "variants/v000/design.yaml",
        "variants/v001/error.txt",
    ] {
        assert_eq!(
            std::fs::read_to_string(dir.dir.join(file)).expect("written"),
            std::fs::read_to_string(clean.dir.join(file)).expect("reference"),
            "{file}"
        );
    }
}

// Item 13. Reproduces: `sweep collect` panicked (index out of bounds, src/sweep/collect.rs:201) on a sweep.json
// whose variant had lost its `values`. A plan that no longer describes its sweep is refused with exit status 2
// by every command that reads it, naming the file and the field, and nothing is written.
#[test]
fn a_hand_edited_plan_is_refused_with_its_field_not_a_panic() {
    let dir = test_outputs("sweep_hostile_plan");
    let sets = ["material.nu=0,0.1", "section.area=1,2"];
    let args = dry_run_args(&design("bend45.yaml"), &sets, &dir, &[]);
    let out = call(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let plan_file = dir.join("sweep.json");
    let mut plan: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&plan_file).expect("plan")).expect("JSON");
    plan["variants"][1]["values"] = serde_json::json!(["0"]);
    std::fs::write(
        &plan_file,
        serde_json::to_string_pretty(&plan).expect("JSON"),
    )
    .expect("edit");
    for command in [
        vec!["sweep", "collect", path_str(&dir)],
        vec!["sweep", "status", path_str(&dir)],
        vec!["sweep", "task", path_str(&dir), "1"],
        args.iter().map(String::as_str).collect(),
    ] {
        let out = stentkit(&command);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{command:?}: {stderr}");
        assert!(
            stderr.contains("sweep.json: variants[1].values: 1 value for 2 parameters"),
            "{command:?}: {stderr}"
        );
    }
    assert!(!dir.join("sweep.csv").exists());
    // A variant's id edited to reach outside the folder is refused the same way.
    plan["variants"][1]["values"] = serde_json::json!(["0", "2"]);
    plan["variants"][1]["id"] = serde_json::json!("../../x");
    std::fs::write(
        &plan_file,
        serde_json::to_string_pretty(&plan).expect("JSON"),
    )
    .expect("edit");
    let out = stentkit(&["sweep", "collect", path_str(&dir)]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("sweep.json: variants[1].id: `../../x`, expected `v001`"),
        "{}",
        text(&out.stderr)
    );
}

// Item 14. Reproduces: `--set mesh.n=20,22 --set mesh.n=24,26` ran, labelled rows n = 20/22 that ran n = 24 (the
// later override wins) and wrote two `mesh.n` columns. A path swept twice is refused, and so is a path a later
// `--set` replaces (`mesh.n=…` then `mesh={…}`), both before anything is written; a later `--set` inside an
// earlier one (`mesh={p: 6}` then `mesh.n=…`) changes only what it names and stays allowed.
#[test]
fn a_path_swept_twice_or_replaced_later_is_refused() {
    let bend = design("bend45.yaml");
    let dir = test_outputs("sweep_hostile_twice");
    for (sets, expected) in [
        (
            ["mesh.n=20,22", "mesh.n=24,26"],
            "--set mesh.n=24,26: `mesh.n` is already swept by --set mesh.n=20,22: give all its values in one --set",
        ),
        (
            ["mesh.n=20,22", "mesh={p: 6, n: 30}"],
            "--set mesh={p: 6, n: 30}: it replaces `mesh.n`, swept by the earlier --set mesh.n=20,22",
        ),
        (
            ["patches[0].n=20,22", "patches[00].n=24"],
            "--set patches[00].n=24: `patches[0].n` is already swept by --set patches[0].n=20,22",
        ),
    ] {
        let out = call(&dry_run_args(&bend, &sets, &dir, &[]));
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{sets:?}: {stderr}");
        assert!(stderr.contains(expected), "{sets:?}: {stderr}");
        assert!(!dir.exists(), "{sets:?} wrote {}", dir.display());
    }
    let out = call(&dry_run_args(
        &bend,
        &["mesh={p: 6}", "mesh.n=20,22"],
        &dir,
        &[],
    ));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let resolved = std::fs::read_to_string(dir.join("variants/v001/design.yaml")).expect("v001");
    assert!(
        resolved.contains("p: 6") && resolved.contains("n: 22"),
        "{resolved}"
    );
}

// Item 15. Reproduces: `--partition $'debug\ntouch X'` wrote the line `touch X` into sweep.sbatch, where bash
// would run it. Every value that reaches the script (partition, time limit, the job name from the design file's
// name, the sweep folder's path) is refused with exit status 2 when it holds a control character, before
// anything is written.
#[test]
fn control_characters_never_reach_the_batch_script() {
    let bend = design("bend45.yaml");
    let dir = test_outputs("sweep_hostile_script");
    let sets = ["material.nu=0,0.1"];
    for (extra, expected) in [
        (
            ["--partition", "debug\ntouch X"],
            "--partition `debug\\ntouch X`: holds a control character (U+000A)",
        ),
        (
            ["--time", "00:10:00\r"],
            "--time `00:10:00\\r`: holds a control character (U+000D)",
        ),
    ] {
        let out = call(&dry_run_args(&bend, &sets, &dir, &extra));
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {stderr}");
        assert!(stderr.contains(expected), "{extra:?}: {stderr}");
        assert!(!dir.exists(), "{extra:?} wrote {}", dir.display());
    }
    // A design file and a sweep folder whose names hold a line break.
    let odd = test_outputs("sweep_hostile_script_names");
    std::fs::create_dir_all(&odd).expect("folder");
    let renamed = odd.join("bend\ntouch X.yaml");
    std::fs::copy(&bend, &renamed).expect("copy");
    let out = call(&dry_run_args(&renamed, &sets, &dir, &[]));
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("the job name `stentkit-bend\\ntouch X` (from the design file's name: rename the file): holds a control character"),
        "{}",
        text(&out.stderr)
    );
    let folder = odd.join("runs\ntouch X");
    let out = call(&dry_run_args(&bend, &sets, &folder, &[]));
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("the sweep folder's path")
            && text(&out.stderr).contains("holds a control character"),
        "{}",
        text(&out.stderr)
    );
    assert!(!dir.exists() && !folder.exists());
}
