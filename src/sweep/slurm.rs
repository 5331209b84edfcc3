//! A sweep as a Slurm job array: `DIR/sweep.sbatch` (one array task per variant, the task id is the
//! variant's number), its submission with `sbatch`, the jobs submitted (`DIR/slurm.json`) and their tasks'
//! states from `squeue`.
//!
//! Each task runs `stentkit sweep task DIR INDEX`, which runs the variant's resolved design exactly as the
//! local sweep does — `stentkit run`, continued from its checkpoint when an earlier attempt was cancelled or
//! preempted (Slurm sends SIGTERM, on which a run finishes its files and writes a checkpoint, then SIGKILL
//! after `KillWait`; a run killed outright continues from its last periodic checkpoint). Its output is appended
//! to the variant's `log.txt`. A resubmission (`stentkit sweep … --slurm` again) submits only the variants
//! that are neither completed nor queued or running in a job of this sweep.

use super::{Plan, SweepDir, SweepError};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The job file in a sweep folder.
pub const JOBS_FILE: &str = "slurm.json";

/// What `--slurm` asks of the scheduler.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SlurmOptions {
    /// `--partition` (the cluster's default when `None`).
    pub partition: Option<String>,
    /// `--time` limit per task, `HH:MM:SS` (the partition's default when `None`).
    pub time: Option<String>,
    /// `--cpus-per-task`: the threads of each run (`RAYON_NUM_THREADS`).
    pub cpus_per_task: usize,
    /// Tasks running at once (`--array=…%M`).
    pub max_parallel: Option<usize>,
    /// Passed to the tasks: rerun failed variants.
    pub retry_failed: bool,
}

/// `0-3,7,9-10`: the indices as Slurm's array ranges.
pub fn array_ranges(indices: &[usize]) -> String {
    let mut parts = Vec::new();
    let mut i = 0;
    while i < indices.len() {
        let start = indices[i];
        let mut end = start;
        while i + 1 < indices.len() && indices[i + 1] == end + 1 {
            i += 1;
            end += 1;
        }
        parts.push(if end == start {
            start.to_string()
        } else {
            format!("{start}-{end}")
        });
        i += 1;
    }
    parts.join(",")
}

/// `text` single-quoted for bash.
fn quoted(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

/// The batch script of the tasks `indices` of the sweep in `dir` (an absolute path), run by `exe`.
pub fn sbatch_text(
    dir: &Path,
    exe: &Path,
    plan: &Plan,
    indices: &[usize],
    options: &SlurmOptions,
) -> String {
    let name = plan
        .design
        .file_stem()
        .map_or_else(|| "design".into(), |s| s.to_string_lossy().into_owned());
    let mut array = array_ranges(indices);
    if let Some(m) = options.max_parallel {
        array.push_str(&format!("%{m}"));
    }
    let mut lines = vec![
        "#!/bin/bash".to_string(),
        format!("#SBATCH --job-name=stentkit-{name}"),
        format!("#SBATCH --array={array}"),
        "#SBATCH --ntasks=1".into(),
        format!("#SBATCH --cpus-per-task={}", options.cpus_per_task.max(1)),
        // `%3a`: the task id padded to three digits, the variant's folder `v%3a`.
        format!(
            "#SBATCH --output={}",
            dir.join("variants/v%3a/log.txt").display()
        ),
        "#SBATCH --open-mode=append".into(),
    ];
    if let Some(p) = &options.partition {
        lines.push(format!("#SBATCH --partition={p}"));
    }
    if let Some(t) = &options.time {
        lines.push(format!("#SBATCH --time={t}"));
    }
    lines.extend([
        String::new(),
        format!(
            "# Written by `stentkit sweep` for the sweep in {}: one array task per variant (task k runs variant v{{k:03}}).",
            dir.display()
        ),
        "# On a cluster, load what the binary needs here (e.g. `module load gcc`); the binary below must be".into(),
        "# reachable from the compute nodes (a shared file system), and so must the sweep folder.".into(),
        String::new(),
        "export RAYON_NUM_THREADS=\"${SLURM_CPUS_PER_TASK:-1}\"".into(),
        format!(
            "exec {} sweep task {} \"$SLURM_ARRAY_TASK_ID\"{}",
            quoted(&exe.display().to_string()),
            quoted(&dir.display().to_string()),
            if options.retry_failed {
                " --retry-failed"
            } else {
                ""
            }
        ),
    ]);
    lines.join("\n") + "\n"
}

/// One submitted job array.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Job {
    /// Slurm's job id.
    pub id: String,
    /// The variants (array task ids) it holds.
    pub tasks: Vec<usize>,
}

/// The jobs submitted for a sweep folder (`DIR/slurm.json`), oldest first.
pub fn read_jobs(dir: &SweepDir) -> Vec<Job> {
    std::fs::read_to_string(dir.dir.join(JOBS_FILE))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or_default()
}

/// Appends `job` to `DIR/slurm.json`.
///
/// # Errors
/// [`SweepError::Io`] when the file cannot be written.
pub fn record_job(dir: &SweepDir, job: Job) -> Result<(), SweepError> {
    let mut jobs = read_jobs(dir);
    jobs.push(job);
    let path = dir.dir.join(JOBS_FILE);
    crate::io::no_follow::write(
        &path,
        serde_json::to_string_pretty(&jobs)
            .unwrap_or_default()
            .as_bytes(),
    )
    .map_err(|source| SweepError::Io { path, source })
}

/// Submits `script` with `sbatch --parsable` and returns the job id.
///
/// # Errors
/// A message when sbatch cannot be started or refuses the script (its own message).
pub fn submit(script: &Path) -> Result<String, String> {
    let out = Command::new("sbatch")
        .arg("--parsable")
        .arg(script)
        .output()
        .map_err(|e| format!("cannot start sbatch ({e}): is Slurm installed here?"))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        return Err(format!(
            "sbatch refused {}: {}",
            script.display(),
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    // `--parsable` prints `jobid` or `jobid;cluster`.
    stdout
        .trim()
        .split(';')
        .next()
        .filter(|id| !id.is_empty())
        .map(str::to_string)
        .ok_or_else(|| format!("sbatch printed no job id: `{}`", stdout.trim()))
}

/// The scheduler's state (`PENDING`, `RUNNING`, …) of every task of `jobs` that Slurm still lists, by
/// variant index; `None` when `squeue` cannot be run (not a Slurm machine). A task Slurm no longer lists has
/// ended: its files say how.
pub fn queued(jobs: &[Job]) -> Option<BTreeMap<usize, String>> {
    if jobs.is_empty() {
        return Some(BTreeMap::new());
    }
    let ids: Vec<&str> = jobs.iter().map(|j| j.id.as_str()).collect();
    let out = Command::new("squeue")
        .args(["--noheader", "--array", "--format=%i %T", "--jobs"])
        .arg(ids.join(","))
        .output()
        .ok()?;
    // squeue exits non-zero when none of the jobs is known any more: nothing is queued.
    let text = String::from_utf8_lossy(&out.stdout);
    Some(parse_squeue(&text))
}

/// Parses `squeue --array --format='%i %T'` lines (`123_4 RUNNING`).
fn parse_squeue(text: &str) -> BTreeMap<usize, String> {
    text.lines()
        .filter_map(|l| {
            let (id, state) = l.trim().split_once(' ')?;
            let task = id.split_once('_')?.1.parse().ok()?;
            Some((task, state.trim().to_string()))
        })
        .collect()
}

/// The sweep folder's absolute path (for the batch script, which runs elsewhere).
///
/// # Errors
/// [`SweepError::Io`] when the folder cannot be resolved.
pub fn absolute(dir: &Path) -> Result<PathBuf, SweepError> {
    std::fs::canonicalize(dir).map_err(|source| SweepError::Io {
        path: dir.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn array_ranges_compress_runs() {
        assert_eq!(array_ranges(&[0, 1, 2, 3, 7, 9, 10]), "0-3,7,9-10");
        assert_eq!(array_ranges(&[5]), "5");
        assert_eq!(array_ranges(&[]), "");
    }

    #[test]
    fn squeue_lines_give_task_states() {
        let states = parse_squeue("12_0 RUNNING\n12_3 PENDING\n13 RUNNING\n");
        assert_eq!(states.get(&0).map(String::as_str), Some("RUNNING"));
        assert_eq!(states.get(&3).map(String::as_str), Some("PENDING"));
        assert_eq!(states.len(), 2);
    }

    #[test]
    fn the_script_runs_one_task_per_variant() {
        let plan = Plan::new(
            Path::new("designs/straight_stent.yaml"),
            vec![super::super::Parameter::parse("a=1,2,3").expect("a")],
            false,
        )
        .expect("plan");
        let options = SlurmOptions {
            partition: Some("debug".into()),
            time: Some("00:10:00".into()),
            cpus_per_task: 2,
            max_parallel: Some(4),
            retry_failed: false,
        };
        let text = sbatch_text(
            Path::new("/s w/dir"),
            Path::new("/bin/stentkit"),
            &plan,
            &[0, 2],
            &options,
        );
        assert!(text.contains("#SBATCH --array=0,2%4\n"), "{text}");
        assert!(text.contains("#SBATCH --partition=debug\n#SBATCH --time=00:10:00\n"));
        assert!(text.contains("#SBATCH --output=/s w/dir/variants/v%3a/log.txt\n"));
        assert!(
            text.ends_with("exec '/bin/stentkit' sweep task '/s w/dir' \"$SLURM_ARRAY_TASK_ID\"\n")
        );
    }
}
