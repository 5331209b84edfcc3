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
//!
//! **What reaches the script.** The partition, the time limit, the job name (from the design file's name), the
//! sweep folder's path and the binary's path are written into it; a control character in any of them (a line
//! break would start a shell command) is refused ([`check_script_values`]). The rest is quoted for who reads
//! it: `#SBATCH` values in double quotes with `\`, `"`, `'` and `#` escaped by a backslash (how sbatch splits
//! those lines: `_get_argument` in Slurm's `src/sbatch/opt.c`), `%` doubled in the output file name (Slurm's
//! file name patterns, where a backslash would turn the `%a` of the variant off: a folder with one is refused),
//! and the command line in single quotes for bash.

use super::{Plan, SweepDir, SweepError};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The job file in a sweep folder.
pub(crate) const JOBS_FILE: &str = "slurm.json";

/// What `--slurm` asks of the scheduler.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct SlurmOptions {
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
pub(crate) fn array_ranges(indices: &[usize]) -> String {
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

/// `text` as one argument of an `#SBATCH` line: in double quotes, with `\`, `"`, `'` and `#` escaped by a
/// backslash (sbatch's `_get_argument` takes a backslash to escape the next character, in quotes or not, and
/// older versions end the line at a `#` even in quotes).
fn sbatch_quoted(text: &str) -> String {
    let mut out = String::from("\"");
    for c in text.chars() {
        if matches!(c, '\\' | '"' | '\'' | '#') {
            out.push('\\');
        }
        out.push(c);
    }
    out.push('"');
    out
}

/// The job's name: `stentkit-` and the design file's name without its extension.
fn job_name(plan: &Plan) -> String {
    let stem = plan
        .design
        .file_stem()
        .map_or_else(|| "design".into(), |s| s.to_string_lossy().into_owned());
    format!("stentkit-{stem}")
}

/// Refuses (naming it) a value that would reach the batch script of the sweep in `dir`, run by `exe`, and
/// that the script cannot hold: a control character in the partition, the time limit, the job name, the
/// folder's or the binary's path, or a backslash in the folder's path (Slurm would then not replace the `%a`
/// in the output file name, and every task would write one file).
///
/// # Errors
/// [`SweepError::Script`] naming the value, shown with escapes.
pub(crate) fn check_script_values(
    dir: &Path,
    exe: &Path,
    plan: &Plan,
    options: &SlurmOptions,
) -> Result<(), SweepError> {
    let folder = dir.to_string_lossy();
    // What, where it comes from (what to change), the value.
    let values = [
        ("--partition", "", options.partition.clone()),
        ("--time", "", options.time.clone()),
        (
            "the job name",
            " (from the design file's name: rename the file)",
            Some(job_name(plan)),
        ),
        ("the sweep folder's path", "", Some(folder.to_string())),
        (
            "the stentkit binary's path",
            " (move the binary)",
            Some(exe.to_string_lossy().into_owned()),
        ),
    ];
    for (what, origin, value) in values {
        let Some(value) = value else {
            continue;
        };
        if let Some(c) = value.chars().find(|c| c.is_control()) {
            return Err(SweepError::Script(format!(
                "{what} `{}`{origin}: holds a control character (U+{:04X}), which the batch script cannot hold (a line break would start a shell command): remove it",
                value.escape_debug(),
                u32::from(c),
            )));
        }
    }
    for (what, path) in [
        ("the sweep folder's path", dir),
        ("the stentkit binary's path", exe),
    ] {
        if path.to_str().is_none() {
            return Err(SweepError::Script(format!(
                "{what} `{}` is not UTF-8 text, which the batch script cannot name: choose another",
                path.display()
            )));
        }
    }
    if folder.contains('\\') {
        return Err(SweepError::Script(format!(
            "the sweep folder's path `{folder}` holds a backslash, which makes Slurm write every task's output to one file (no `%a` in its name): choose a folder without one"
        )));
    }
    Ok(())
}

/// The batch script of the tasks `indices` of the sweep in `dir` (an absolute path), run by `exe`.
///
/// # Errors
/// [`SweepError::Script`] for a value the script cannot hold ([`check_script_values`]).
pub(crate) fn sbatch_text(
    dir: &Path,
    exe: &Path,
    plan: &Plan,
    indices: &[usize],
    options: &SlurmOptions,
) -> Result<String, SweepError> {
    check_script_values(dir, exe, plan, options)?;
    let mut array = array_ranges(indices);
    if let Some(m) = options.max_parallel {
        array.push_str(&format!("%{m}"));
    }
    // `%3a`: the task id padded to three digits, the variant's folder `v%3a`; a `%` of the folder's path is
    // `%%` in a Slurm file name.
    let output = format!(
        "{}/variants/v%3a/log.txt",
        dir.to_string_lossy().replace('%', "%%")
    );
    let mut lines = vec![
        "#!/bin/bash".to_string(),
        format!("#SBATCH --job-name={}", sbatch_quoted(&job_name(plan))),
        format!("#SBATCH --array={array}"),
        "#SBATCH --ntasks=1".into(),
        format!("#SBATCH --cpus-per-task={}", options.cpus_per_task.max(1)),
        format!("#SBATCH --output={}", sbatch_quoted(&output)),
        "#SBATCH --open-mode=append".into(),
    ];
    if let Some(p) = &options.partition {
        lines.push(format!("#SBATCH --partition={}", sbatch_quoted(p)));
    }
    if let Some(t) = &options.time {
        lines.push(format!("#SBATCH --time={}", sbatch_quoted(t)));
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
    Ok(lines.join("\n") + "\n")
}

/// One submitted job array.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct Job {
    /// Slurm's job id.
    pub id: String,
    /// The variants (array task ids) it holds.
    pub tasks: Vec<usize>,
}

/// The jobs submitted for a sweep folder (`DIR/slurm.json`), oldest first.
pub(crate) fn read_jobs(dir: &SweepDir) -> Vec<Job> {
    std::fs::read_to_string(dir.dir.join(JOBS_FILE))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or_default()
}

/// Appends `job` to `DIR/slurm.json`.
///
/// # Errors
/// [`SweepError::Io`] when the file cannot be written.
pub(crate) fn record_job(dir: &SweepDir, job: Job) -> Result<(), SweepError> {
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
pub(crate) fn submit(script: &Path) -> Result<String, String> {
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
pub(crate) fn queued(jobs: &[Job]) -> Option<BTreeMap<usize, String>> {
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
pub(crate) fn absolute(dir: &Path) -> Result<PathBuf, SweepError> {
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
        )
        .expect("a script");
        assert!(text.contains("#SBATCH --array=0,2%4\n"), "{text}");
        assert!(text.contains("#SBATCH --partition=\"debug\"\n#SBATCH --time=\"00:10:00\"\n"));
        assert!(text.contains("#SBATCH --output=\"/s w/dir/variants/v%3a/log.txt\"\n"));
        assert!(
            text.ends_with("exec '/bin/stentkit' sweep task '/s w/dir' \"$SLURM_ARRAY_TASK_ID\"\n")
        );
    }

    /// The arguments sbatch takes from the text after `#SBATCH`: Slurm's `_get_argument` (src/sbatch/opt.c,
    /// versions 18 to 24) transcribed — whitespace separates arguments, a backslash takes the next character
    /// as it is (in quotes too), `"` or `'` quote up to the same character, an unquoted `#` ends the line.
    fn sbatch_arguments(text: &str) -> Vec<String> {
        let (mut arguments, mut current, mut chars) = (Vec::new(), None::<String>, text.chars());
        let mut quote = None;
        while let Some(c) = chars.next() {
            match (c, quote) {
                ('\\', _) => {
                    if let Some(next) = chars.next() {
                        current.get_or_insert_with(String::new).push(next);
                    }
                }
                (c, Some(q)) if c == q => quote = None,
                (c, Some(_)) => current.get_or_insert_with(String::new).push(c),
                ('"' | '\'', None) => {
                    quote = Some(c);
                    current.get_or_insert_with(String::new);
                }
                ('#', None) => break,
                (c, None) if c.is_whitespace() => arguments.extend(current.take()),
                (c, None) => current.get_or_insert_with(String::new).push(c),
            }
        }
        assert!(quote.is_none(), "unmatched quote in {text}");
        arguments.extend(current);
        arguments
    }

    // Item 15 of issue 31: values with spaces, quotes, `#`, `%` and backslashes reach sbatch and bash as
    // they were given. Each `#SBATCH` line is split as sbatch splits it (the transcription above) and must
    // give exactly the one intended argument, with `%` doubled in the output file name (Slurm's `%%`); the
    // command line is run by bash, with the binary a link to `echo` whose name holds a space and quotes, and
    // must print the folder and the task id unchanged. Control characters are refused, naming the value.
    #[test]
    fn the_script_passes_odd_values_through_sbatch_and_bash_unchanged() {
        let scratch = std::env::temp_dir().join(format!("stentkit-sbatch-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&scratch);
        let bin = scratch.join("my bin");
        std::fs::create_dir_all(&bin).expect("folder");
        let exe = bin.join("it's \"stentkit\" #1");
        std::os::unix::fs::symlink("/bin/echo", &exe).expect("a link to echo");
        let plan = Plan::new(
            Path::new("designs/my \"odd\" design #2.yaml"),
            vec![super::super::Parameter::parse("a=1,2").expect("a")],
            false,
        )
        .expect("plan");
        let options = SlurmOptions {
            partition: Some("a b#\"c'd\\e".into()),
            time: Some("1-00:00:00".into()),
            cpus_per_task: 1,
            max_parallel: None,
            retry_failed: false,
        };
        let dir = Path::new("/s w/50%/it's \"x\" $HOME #1");
        let text = sbatch_text(dir, &exe, &plan, &[0, 1], &options).expect("a script");
        let argument = |option: &str| {
            let line = text
                .lines()
                .find(|l| l.starts_with(&format!("#SBATCH {option}=")))
                .unwrap_or_else(|| panic!("no {option} in {text}"));
            let arguments = sbatch_arguments(&line["#SBATCH ".len()..]);
            assert_eq!(arguments.len(), 1, "{line}: {arguments:?}");
            arguments[0].clone()
        };
        assert_eq!(argument("--partition"), "--partition=a b#\"c'd\\e");
        assert_eq!(argument("--time"), "--time=1-00:00:00");
        assert_eq!(
            argument("--job-name"),
            "--job-name=stentkit-my \"odd\" design #2"
        );
        assert_eq!(
            argument("--output"),
            "--output=/s w/50%%/it's \"x\" $HOME #1/variants/v%3a/log.txt"
        );
        let script = scratch.join("sweep.sbatch");
        std::fs::write(&script, &text).expect("script");
        let out = Command::new("bash")
            .arg(&script)
            .env("SLURM_ARRAY_TASK_ID", "7")
            .output()
            .expect("bash runs");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(
            String::from_utf8_lossy(&out.stdout),
            "sweep task /s w/50%/it's \"x\" $HOME #1 7\n"
        );
        let _ = std::fs::remove_dir_all(&scratch);
        for (options, dir, expected) in [
            (
                SlurmOptions {
                    partition: Some("debug\ntouch X".into()),
                    ..options.clone()
                },
                Path::new("/s"),
                "--partition `debug\\ntouch X`: holds a control character (U+000A)",
            ),
            (
                SlurmOptions {
                    time: Some("1:00\u{7f}".into()),
                    ..options.clone()
                },
                Path::new("/s"),
                "--time `1:00\\u{7f}`: holds a control character (U+007F)",
            ),
            (
                options.clone(),
                Path::new("/s\r/x"),
                "the sweep folder's path `/s\\r/x`: holds a control character (U+000D)",
            ),
            (
                options.clone(),
                Path::new("/s\\x"),
                "the sweep folder's path `/s\\x` holds a backslash",
            ),
        ] {
            let error = sbatch_text(dir, &exe, &plan, &[0], &options)
                .expect_err("refused")
                .to_string();
            assert!(error.contains(expected), "{error}");
        }
    }
}
