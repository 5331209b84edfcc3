//! `stentkit run --resume` (issue 13 item 4): a run killed by SIGKILL, or stopped by SIGINT, after a
//! checkpoint continues from it to the uninterrupted run's result — history.csv byte for byte, the same
//! snapshot files, the recording's messages (topic, sequence number, log time, body) all equal — and resuming
//! with another design, a run that completed, or a folder without a checkpoint is refused with exit status 2.
//!
//! Source: the contract (`stentkit::run` module docs; `solver::simulation::checkpoint` restores the simulation bit
//! for bit). Design: the straight stent of designs/straight_stent.yaml with two crowns (1301 steps of 2.5 ms,
//! about a second and a half of solving: long enough to be killed in the middle), with checkpoints every
//! 0.1 s of wall time (`--checkpoint-every`, a test interval; the default is 60 s). Exact comparisons.

use crate::common::{edit, fixtures};
use crate::outputs::{check_recording, completed_in_process, path_str, stentkit, summary, text};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A fresh scratch folder for test `name`.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("resume-tests")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// The two-crown straight stent, written into `dir`.
fn two_crown_stent(dir: &Path) -> PathBuf {
    fixtures::straight_stent()
        .crowns(2)
        .write(&dir.join("two_crowns.yaml"))
}

/// Starts `stentkit run DESIGN -o DIR --quiet --checkpoint-every 0.1`.
fn spawn(design: &Path, dir: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_stentkit"))
        .args(["run", path_str(design), "-o", path_str(dir), "--quiet"])
        .args(["--checkpoint-every", "0.1"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("stentkit starts")
}

/// Waits (at most two minutes) until `dir` holds a checkpoint and `rows` history rows, while `child` runs;
/// panics if the run ended first.
fn wait_for_checkpoint(child: &mut Child, dir: &Path, rows: usize) {
    let started = Instant::now();
    loop {
        let history = std::fs::read_to_string(dir.join("history.csv")).unwrap_or_default();
        if dir.join("checkpoint.bin").exists() && history.lines().count() >= rows {
            return;
        }
        assert!(
            child.try_wait().expect("status").is_none(),
            "the run ended before it could be stopped"
        );
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "no checkpoint in 2 min"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// The two-crown stent written into `root` and run into `root/run`, killed by SIGKILL after its first checkpoint
/// with at least 50 history rows: a folder `--resume` continues. Returns the design and the run folder.
pub(crate) fn killed_two_crown_run(root: &Path) -> (PathBuf, PathBuf) {
    let design = two_crown_stent(root);
    let dir = root.join("run");
    let mut child = spawn(&design, &dir);
    wait_for_checkpoint(&mut child, &dir, 50);
    child.kill().expect("SIGKILL");
    child.wait().expect("reaped");
    (design, dir)
}

/// Every message of a recording: (topic, sequence, log time, body).
fn messages(dir: &Path) -> Vec<(String, u32, u64, Vec<u8>)> {
    let bytes = std::fs::read(dir.join("run.mcap")).expect("run.mcap");
    mcap::MessageStream::new(&bytes)
        .expect("stream")
        .map(|m| {
            let m = m.expect("message");
            (
                m.channel.topic.clone(),
                m.sequence,
                m.log_time,
                m.data.into_owned(),
            )
        })
        .collect()
}

/// The files of `dir/snapshots`, by name.
fn snapshot_files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir.join("snapshots"))
        .expect("snapshots/")
        .map(|e| {
            let e = e.expect("entry");
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).expect("file"),
            )
        })
        .collect()
}

/// Resumes `dir` with `design`: the status and the standard error.
pub(crate) fn resume(design: &Path, dir: &Path) -> (Option<i32>, String) {
    let out = stentkit(&[
        "run",
        path_str(design),
        "--resume",
        path_str(dir),
        "--quiet",
    ]);
    (out.status.code(), text(&out.stderr))
}

#[test]
fn a_killed_or_interrupted_run_resumes_to_the_uninterrupted_result() {
    let root = scratch("equal");
    let design = two_crown_stent(&root);
    let full = root.join("full");
    // The reference run in process: the runs stopped by signals below are what is tested.
    completed_in_process(&design, &full, &[]);
    assert!(
        !full.join("checkpoint.bin").exists(),
        "a completed run removes its checkpoint"
    );
    let history = std::fs::read(full.join("history.csv")).expect("history");
    let rows = history.split(|&b| b == b'\n').count();
    assert!(rows > 1000);

    for (case, signal) in [("killed", "KILL"), ("interrupted", "INT")] {
        let dir = root.join(case);
        let mut child = spawn(&design, &dir);
        wait_for_checkpoint(&mut child, &dir, rows / 4);
        let status = Command::new("kill")
            .args([&format!("-{signal}"), &child.id().to_string()])
            .status()
            .expect("kill runs");
        assert!(status.success());
        let ended = child.wait_with_output().expect("reaped");
        let before = summary(&dir);
        let written = std::fs::read(dir.join("history.csv")).expect("history");
        println!(
            "{case}: stopped with {:?} at {} of {rows} history rows (summary: {}, {} steps)",
            ended.status.code(),
            written.split(|&b| b == b'\n').count(),
            before["status"],
            before["steps"]
        );
        if case == "interrupted" {
            assert_eq!(ended.status.code(), Some(130), "{}", text(&ended.stderr));
        }

        let (code, stderr) = resume(&design, &dir);
        assert_eq!(code, Some(0), "{case}: {stderr}");
        let after = summary(&dir);
        assert_eq!(after["status"], "completed", "{case}");
        let resumed = std::fs::read(dir.join("history.csv")).expect("history");
        if resumed != history {
            let (a, b) = (text(&resumed), text(&history));
            let first = a.lines().zip(b.lines()).position(|(x, y)| x != y);
            panic!(
                "{case}: history.csv differs from the uninterrupted run's ({} and {} lines), first at line {first:?}: {:?} vs {:?}; the resume said: {stderr}",
                a.lines().count(),
                b.lines().count(),
                first.and_then(|k| a.lines().nth(k)),
                first.and_then(|k| b.lines().nth(k)),
            );
        }
        assert_eq!(
            snapshot_files(&dir),
            snapshot_files(&full),
            "{case}: snapshots"
        );
        assert_eq!(messages(&dir), messages(&full), "{case}: recorded messages");
        check_recording(&dir, &design);
        for key in [
            "steps",
            "newton_iterations",
            "step_cuts",
            "snapshots",
            "final_state",
        ] {
            assert_eq!(after[key], summary(&full)[key], "{case}: summary {key}");
        }
        assert!(
            !dir.join("checkpoint.bin").exists(),
            "{case}: checkpoint removed at the end"
        );
        // The resumed run's files are all listed, so `--force` can replace it.
        let again = stentkit(&[
            "run",
            path_str(&design),
            "-o",
            path_str(&dir),
            "--quiet",
            "--force",
        ]);
        assert_eq!(again.status.code(), Some(0), "{}", text(&again.stderr));
    }
}

#[test]
fn resuming_the_wrong_run_is_refused_with_status_2() {
    let root = scratch("refused");
    let (design, dir) = killed_two_crown_run(&root);

    // Another design.
    let bend = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs/bend45.yaml");
    let (code, stderr) = resume(&bend, &dir);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("another model"), "{stderr}");
    // The same design with another load: another model too.
    let changed = fixtures::straight_stent()
        .crowns(2)
        .set("programme.delta_r", "14")
        .write(&root.join("changed.yaml"));
    let (code, stderr) = resume(&changed, &dir);
    assert_eq!(code, Some(2), "{stderr}");
    // A folder that is not a run folder, and one that does not exist.
    let (code, stderr) = resume(&design, &root);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("not a stentkit run folder"), "{stderr}");
    let (code, stderr) = resume(&design, &root.join("missing"));
    assert_eq!(code, Some(2), "{stderr}");
    // A damaged checkpoint.
    let checkpoint = dir.join("checkpoint.bin");
    let good = std::fs::read(&checkpoint).expect("checkpoint");
    let mut bad = good.clone();
    let middle = bad.len() / 2;
    bad[middle] ^= 1;
    std::fs::write(&checkpoint, &bad).expect("damaged");
    let (code, stderr) = resume(&design, &dir);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("damaged"), "{stderr}");
    std::fs::write(&checkpoint, &good).expect("restored");
    // The right design finishes the run; then there is nothing to resume.
    let (code, stderr) = resume(&design, &dir);
    assert_eq!(code, Some(0), "{stderr}");
    let (code, stderr) = resume(&design, &dir);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("completed"), "{stderr}");
    // A run folder without a checkpoint (a run that ended before its first one).
    let short = root.join("short");
    completed_in_process(&bend, &short, &[]);
    let summary_path = short.join("summary.json");
    let s = std::fs::read_to_string(&summary_path).expect("summary");
    std::fs::write(&summary_path, edit(&s, "\"completed\"", "\"killed\"")).expect("written");
    let (code, stderr) = resume(&bend, &short);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("no checkpoint"), "{stderr}");
}

/// A console that asks the run to stop when the simulation reaches step `at` (an interruption at a chosen,
/// reproducible point, where a signal's arrives at whatever step the process is in).
struct StopAt<'a> {
    at: usize,
    interrupt: &'a stentkit::run::Interrupt,
}

impl stentkit::solver::Observer for StopAt<'_> {
    fn step(
        &mut self,
        _: &stentkit::solver::Simulation<'_>,
        report: &stentkit::solver::StepReport,
    ) -> std::ops::ControlFlow<()> {
        if report.step == self.at {
            self.interrupt.request("a test");
        }
        std::ops::ControlFlow::Continue(())
    }
}

impl stentkit::run::Console for StopAt<'_> {
    fn begin(&mut self, _: &stentkit::model::Model, _: usize) {}
    fn progress(&mut self) -> Option<&mut dyn stentkit::solver::Observer> {
        Some(self)
    }
    fn say(&self, _: &str) {}
    fn end(&mut self, _: &stentkit::solver::Simulation<'_>) {}
}

/// `design` run in process into the new folder `dir` to its end; its report.
fn run_whole(design: &stentkit::Design, dir: &Path) -> String {
    use stentkit::run::{Folder, Interrupt, Lines, RunSettings, run};
    let folder = Folder::New {
        dir: dir.to_path_buf(),
        force: false,
    };
    let settings = RunSettings::new("in-process test");
    run(
        design,
        folder,
        &settings,
        &Interrupt::new(),
        &mut Lines::default(),
    )
    .expect("the uninterrupted run completes")
    .report
}

/// `design` run in process into the new folder `dir`, its interrupt requested at step `at`: what it ended with.
fn stop_at(
    design: &stentkit::Design,
    dir: &Path,
    at: usize,
) -> Result<stentkit::run::Completed, stentkit::run::RunError> {
    use stentkit::run::{Folder, Interrupt, RunSettings, run};
    let interrupt = Interrupt::new();
    let mut console = StopAt {
        at,
        interrupt: &interrupt,
    };
    let folder = Folder::New {
        dir: dir.to_path_buf(),
        force: false,
    };
    run(
        design,
        folder,
        &RunSettings::new("in-process test"),
        &interrupt,
        &mut console,
    )
}

/// The run in folder `dir` of `design` resumed in process from its checkpoint to its end: the lines it said.
fn resume_in_process(design: &stentkit::Design, dir: &Path) -> Vec<String> {
    use stentkit::run::{Folder, Interrupt, Lines, RunSettings, run};
    let mut lines = Lines::default();
    run(
        design,
        Folder::Resume(dir.to_path_buf()),
        &RunSettings::new("in-process test"),
        &Interrupt::new(),
        &mut lines,
    )
    .expect("the resumed run completes");
    lines.lines().to_vec()
}

/// The run as a library call ([`stentkit::run::run`], no process, no signal): the two-crown stent stopped by an
/// [`stentkit::run::Interrupt`] requested at step 400 of 1301 ends with [`stentkit::run::RunError::Interrupted`]
/// and a checkpoint at that step, and [`stentkit::run::Folder::Resume`] continues it to the uninterrupted
/// in-process run's files: history.csv byte for byte, the snapshots, the recorded messages (the contract of
/// `stentkit::run`, as the test above for signals).
#[test]
fn an_in_process_run_stopped_by_its_interrupt_resumes_to_the_uninterrupted_result() {
    use stentkit::run::RunError;
    let root = scratch("in_process");
    let design = stentkit::design::load_design(&two_crown_stent(&root)).expect("design");
    let full = root.join("full");
    let report = run_whole(&design, &full);
    assert!(report.contains("1301 steps"), "{report}");

    let dir = root.join("stopped");
    match stop_at(&design, &dir, 400) {
        Err(RunError::Interrupted(message)) => assert!(
            message.contains("interrupted by a test after 400 steps"),
            "{message}"
        ),
        other => panic!("not interrupted: {other:?}"),
    }
    assert_eq!(summary(&dir)["status"], "interrupted");
    assert!(dir.join("checkpoint.bin").exists());
    let lines = resume_in_process(&design, &dir);
    assert!(
        lines[0].starts_with(&format!(
            "stentkit run: resuming {} from its checkpoint at step 400",
            dir.display()
        )),
        "{lines:?}"
    );
    assert_eq!(
        std::fs::read(dir.join("history.csv")).expect("history"),
        std::fs::read(full.join("history.csv")).expect("history")
    );
    assert_eq!(snapshot_files(&dir), snapshot_files(&full));
    assert_eq!(messages(&dir), messages(&full));
    assert!(!dir.join("checkpoint.bin").exists());
}

/// What summary.json reports over a whole run — the contact peaks (issue 33), the deployment's recoil and
/// foreshortening (issue 34), the wires' first touch (issue 35) — is the same after an interruption and a
/// resume as without: a resumed run reads the part before its checkpoint back from history.csv's printed rows
/// (or the terms' saved state), so a run that goes on must keep the same printed values. The two-crown crimped
/// straight stent (`designs/straight_stent_crimped.yaml`), stopped at step 800 (after the crimper's peak at
/// t = 1, before the sheath's), resumed, against the uninterrupted run: the `contact`, `deployment` and
/// `wire_touch` entries equal to the last digit. Before the contact peaks were kept as printed this failed: the
/// crimper's largest penetration read back as 6.988908e-5 at t = 0.985 against 6.988908128419125e-5 at
/// t = 0.98499999999999 kept exactly (and its peak force in the 12th digit).
#[test]
fn a_resumed_crimped_run_reports_the_uninterrupted_runs_peaks() {
    let root = scratch("resumed_peaks");
    let design = fixtures::design("straight_stent_crimped.yaml")
        .crowns(2)
        .design();
    let full = root.join("full");
    run_whole(&design, &full);
    let dir = root.join("stopped");
    assert!(stop_at(&design, &dir, 800).is_err());
    resume_in_process(&design, &dir);
    let (resumed, uninterrupted) = (summary(&dir), summary(&full));
    assert!(uninterrupted["contact"].is_array(), "{uninterrupted}");
    for key in ["contact", "deployment", "wire_touch"] {
        assert_eq!(resumed[key], uninterrupted[key], "{key}");
    }
}
