//! `stentkit sweep` (issue 15): a family of variants run by local workers, stopped by a signal and continued,
//! tabulated by `collect`; failures as rows; folders never taken over; and (ignored unless a Slurm is up,
//! `.ci/run` brings one up with scripts/slurm-single-node.sh) the same sweep as a Slurm job array, cancelled and
//! resubmitted, giving the same table.
//!
//! Design: the straight stent of designs/straight_stent.yaml with two crowns (1301 steps, about two seconds a
//! run on one thread), over Tg ∈ {65, 75} °C × wire diameter ∈ {0.5, 0.6} mm. Reference values: the same
//! design run by `stentkit run` with the same `--set` (byte-identical history), and the uninterrupted local
//! sweep (identical metrics: the runs are deterministic and a resumed run continues bit for bit).

use crate::outputs::{completed_in_process, design, path_str, stentkit, test_outputs, text};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The swept parameters.
const SETS: [&str; 3] = [
    "stent.crowns=2",
    "material.wlf.Tg=65,75",
    "section.diameter=0.5,0.6",
];

/// `sweep designs/straight_stent.yaml --set … -o DIR` followed by `extra`.
fn sweep_args(dir: &Path, extra: &[&str]) -> Vec<String> {
    let mut args = vec![
        "sweep".to_string(),
        path_str(&design("straight_stent.yaml")).to_string(),
    ];
    for s in SETS {
        args.push("--set".into());
        args.push(s.into());
    }
    args.push("-o".into());
    args.push(path_str(dir).into());
    args.extend(extra.iter().map(|s| s.to_string()));
    args
}

fn run_sweep(dir: &Path, extra: &[&str]) -> std::process::Output {
    let args = sweep_args(dir, extra);
    stentkit(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// sweep.csv without the wall-time column: what must agree between two sweeps of the same variants.
fn metrics_table(dir: &Path) -> Vec<Vec<String>> {
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).expect("sweep.csv");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let wall = header
        .iter()
        .position(|h| h.starts_with("wall_time"))
        .expect("a wall_time column");
    std::iter::once(header.iter().map(|s| s.to_string()).collect::<Vec<_>>())
        .chain(lines.map(|l| l.split(',').map(str::to_string).collect()))
        .map(|mut row: Vec<String>| {
            row.remove(wall);
            row
        })
        .collect()
}

/// Polls `done` every 100 ms for at most `limit`.
fn wait_until(limit: Duration, what: &str, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(start.elapsed() < limit, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// The status in a variant's summary.json, if any.
fn variant_status(dir: &Path, id: &str) -> Option<String> {
    let text =
        std::fs::read_to_string(dir.join("variants").join(id).join("run/summary.json")).ok()?;
    let json: serde_json::Value = serde_json::from_str(&text).ok()?;
    json["status"].as_str().map(str::to_string)
}

/// The uninterrupted local sweep, its table checked.
fn local_reference() -> PathBuf {
    let dir = test_outputs("sweep_local");
    let out = run_sweep(&dir, &["--jobs", "2"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let table = metrics_table(&dir);
    assert_eq!(table.len(), 5, "a header and four variants");
    let status = table[0].iter().position(|h| h == "status").expect("status");
    assert!(
        table[1..].iter().all(|r| r[status] == "completed"),
        "{table:?}"
    );
    dir
}

#[test]
fn a_local_sweep_runs_continues_after_a_signal_and_tabulates() {
    let reference = local_reference();
    // Variant v001 (Tg = 65, d = 0.6) is the design run with those values.
    let single = test_outputs("sweep_single");
    completed_in_process(
        &design("straight_stent.yaml"),
        &single,
        &[
            "stent.crowns=2",
            "material.wlf.Tg=65",
            "section.diameter=0.6",
        ],
    );
    let history = |dir: &Path| std::fs::read(dir.join("history.csv")).expect("history.csv");
    assert_eq!(
        history(&reference.join("variants/v001/run")),
        history(&single)
    );
    // Charts of every metric against the swept parameters, none against the constant crown count.
    let charts: Vec<String> = std::fs::read_dir(reference.join("charts"))
        .expect("charts")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert!(charts.iter().any(|c| c == "fixity_vs_Tg.svg"), "{charts:?}");
    assert!(
        charts
            .iter()
            .any(|c| c == "time_to_50pc_recovery_vs_diameter.svg")
    );
    assert!(!charts.iter().any(|c| c.ends_with("_vs_crowns.svg")));
    // A rerun of a finished sweep runs nothing and changes no run.
    let modified = |dir: &Path| {
        std::fs::metadata(dir.join("variants/v000/run/summary.json"))
            .and_then(|m| m.modified())
            .expect("summary.json")
    };
    let before = modified(&reference);
    let out = run_sweep(&reference, &[]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("4 completed earlier, 0 to run"),
        "{}",
        text(&out.stderr)
    );
    assert_eq!(modified(&reference), before);

    // The same sweep stopped by SIGTERM once a variant completed, then continued.
    let dir = test_outputs("sweep_interrupted");
    let args = sweep_args(&dir, &["--jobs", "2"]);
    let child = Command::new(env!("CARGO_BIN_EXE_stentkit"))
        .args(&args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("stentkit starts");
    wait_until(Duration::from_secs(120), "a completed variant", || {
        ["v000", "v001"]
            .iter()
            .any(|id| variant_status(&dir, id).as_deref() == Some("completed"))
    });
    let killed = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(killed.success());
    let out = child.wait_with_output().expect("the sweep ends");
    assert_eq!(out.status.code(), Some(130), "{}", text(&out.stderr));
    let statuses: Vec<Option<String>> = ["v000", "v001", "v002", "v003"]
        .iter()
        .map(|id| variant_status(&dir, id))
        .collect();
    assert!(
        statuses.iter().any(|s| s.as_deref() != Some("completed")),
        "the signal came after every variant: {statuses:?}"
    );
    let out = run_sweep(&dir, &["--jobs", "2"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(metrics_table(&dir), metrics_table(&reference));
}

#[test]
fn failed_variants_are_rows_and_folders_are_not_taken_over() {
    let dir = test_outputs("sweep_failures");
    let base = path_str(&design("straight_stent.yaml")).to_string();
    let args = |dir: &Path, diameters: &str| {
        vec![
            "sweep".to_string(),
            base.clone(),
            "--set".into(),
            "stent.crowns=2".into(),
            "--set".into(),
            "time.end=0.2".into(),
            "--set".into(),
            format!("section.diameter={diameters}"),
            "-o".into(),
            path_str(dir).into(),
        ]
    };
    let call = |a: Vec<String>| stentkit(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let out = call(args(&dir, "0.6,-1"));
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).expect("sweep.csv");
    let rows: Vec<&str> = csv.lines().collect();
    assert!(rows[1].starts_with("v000,2,0.2,0.6,completed,,"), "{csv}");
    assert!(
        rows[2].starts_with("v001,2,0.2,-1,failed,")
            && rows[2].contains("--set section.diameter=-1: section.diameter: -1 must be > 0"),
        "{csv}"
    );
    let status = stentkit(&["sweep", "status", path_str(&dir)]);
    assert!(
        text(&status.stdout).contains("1 completed, 1 failed"),
        "{}",
        text(&status.stdout)
    );
    // Another sweep into the same folder is refused; so is a folder that holds something else.
    let out = call(args(&dir, "0.5"));
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("holds another sweep"),
        "{}",
        text(&out.stderr)
    );
    let other = test_outputs("sweep_not_a_sweep");
    std::fs::create_dir_all(&other).expect("folder");
    std::fs::write(other.join("notes.txt"), "mine").expect("a user's file");
    let out = call(args(&other, "0.6"));
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        std::fs::read_to_string(other.join("notes.txt")).expect("kept"),
        "mine"
    );
}

/// Needs a running Slurm (`sudo scripts/slurm-single-node.sh up`; `.ci/run` does it): the sweep as a job
/// array gives the local sweep's table; cancelled while its second variant runs (with one task at a time) and
/// resubmitted, only the unfinished variants are submitted again and the table is the same.
#[test]
#[ignore = "needs a Slurm cluster: scripts/slurm-single-node.sh up, then cargo test --release -- --ignored slurm"]
fn slurm_sweep_gives_the_local_table_and_resubmits_only_unfinished_variants() {
    let reference = local_reference();
    let squeue_empty = |job: &str| {
        let out = Command::new("squeue")
            .args(["--noheader", "--jobs", job])
            .output()
            .expect("squeue runs");
        String::from_utf8_lossy(&out.stdout).trim().is_empty()
    };
    let job_id = |out: &std::process::Output| -> String {
        let stdout = text(&out.stdout);
        stdout
            .split_whitespace()
            .skip_while(|w| *w != "job")
            .nth(1)
            .map(|id| id.trim_end_matches(':').to_string())
            .unwrap_or_else(|| panic!("no job id in `{stdout}`"))
    };
    // The whole sweep at once.
    let dir = test_outputs("sweep_slurm");
    let out = run_sweep(&dir, &["--slurm", "--cpus-per-task", "1"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let job = job_id(&out);
    wait_until(Duration::from_secs(600), "the job array", || {
        squeue_empty(&job)
    });
    let out = stentkit(&["sweep", "collect", path_str(&dir)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(metrics_table(&dir), metrics_table(&reference));

    // One task at a time, cancelled while the second runs, then resubmitted.
    let dir = test_outputs("sweep_slurm_cancelled");
    let out = run_sweep(&dir, &["--slurm", "--max-parallel", "1"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let job = job_id(&out);
    wait_until(
        Duration::from_secs(300),
        "the second variant running",
        || {
            variant_status(&dir, "v000").as_deref() == Some("completed")
                && variant_status(&dir, "v001").as_deref() == Some("running")
        },
    );
    let cancelled = Command::new("scancel")
        .arg(&job)
        .status()
        .expect("scancel runs");
    assert!(cancelled.success());
    wait_until(Duration::from_secs(120), "the cancellation", || {
        squeue_empty(&job)
    });
    let interrupted = variant_status(&dir, "v001");
    assert!(
        matches!(interrupted.as_deref(), Some("interrupted" | "running")),
        "{interrupted:?}"
    );
    let out = run_sweep(&dir, &["--slurm", "--max-parallel", "1"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let script = std::fs::read_to_string(dir.join("sweep.sbatch")).expect("sweep.sbatch");
    assert!(script.contains("#SBATCH --array=1-3%1\n"), "{script}");
    let job = job_id(&out);
    wait_until(Duration::from_secs(600), "the resubmitted array", || {
        squeue_empty(&job)
    });
    let out = stentkit(&["sweep", "collect", path_str(&dir)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(metrics_table(&dir), metrics_table(&reference));
}
