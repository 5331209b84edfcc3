//! `stentkit repair RUN_DIR`: makes the folder of a run that was killed (SIGKILL, a power loss, a crash) whole,
//! as far as what it holds allows:
//!
//! - hidden temporaries of unfinished atomic writes are removed;
//! - `history.csv` is cut back to its last complete row;
//! - `run.mcap` is finished after its last complete chunk ([`crate::io::mcap_salvage`]);
//! - a `summary.json` still saying `"running"` says `"killed"`, with the time of the last row of the history,
//!   the steps it holds and every complete snapshot on disk.
//!
//! The folder's lock is taken first, so a folder whose run is still going is refused. Only files the run
//! folder's manifest lists are touched, and none through a symbolic link: a folder holding links where
//! stentkit writes is refused, naming them ([`classify`]), and each file is opened without following one
//! ([`crate::io::no_follow`]). Repairing a folder twice changes nothing the second time.

use super::{BadInput, short_time};
use crate::io::mcap_salvage::{Salvage, salvage};
use crate::io::run_folder::{FolderKind, classify, lock_existing, remove_stale_temporaries};
use anyhow::Context;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// Repairs the run folder `dir` and prints what was done.
///
/// # Errors
/// [`BadInput`] for a folder that is not a run folder; the I/O error of a file that cannot be repaired.
pub(crate) fn run(dir: &Path) -> anyhow::Result<()> {
    let listed = match classify(dir)? {
        FolderKind::Run(files) => files,
        FolderKind::Empty => {
            return Err(BadInput(format!(
                "{}: empty or missing, nothing to repair",
                dir.display()
            ))
            .into());
        }
        FolderKind::Foreign => {
            return Err(BadInput(format!(
                "{}: not a stentkit run folder (no .stentkit-run manifest); nothing was changed",
                dir.display()
            ))
            .into());
        }
    };
    let _lock = lock_existing(dir)?;
    let mut done: Vec<String> = Vec::new();
    for removed in remove_stale_temporaries(dir, &listed)? {
        done.push(format!(
            "removed the unfinished temporary {}",
            removed.display()
        ));
    }
    let history = dir.join("history.csv");
    let rows = if history.exists() {
        let (rows, cut) = repair_history(&history)?;
        if cut > 0 {
            done.push(format!("history.csv: cut a partial last row ({cut} bytes)"));
        }
        rows
    } else {
        Vec::new()
    };
    let mcap = dir.join("run.mcap");
    let mut mcap_bytes = None;
    if mcap.exists() {
        match salvage(&mcap)? {
            Salvage::AlreadyValid { bytes } => mcap_bytes = Some(bytes),
            Salvage::Finished {
                before,
                after,
                messages,
                last_log_time,
                indexed,
            } => {
                mcap_bytes = Some(after);
                done.push(format!(
                    "run.mcap: finished after its last complete chunk ({messages} messages up to t = {} s; {after} bytes, {before} before){}",
                    short_time(last_log_time.map_or(0.0, |ns| ns as f64 * 1e-9)),
                    if indexed { "" } else { "; not indexed (no room for a copy): viewers read it linearly" }
                ));
            }
        }
    }
    let summary_path = dir.join("summary.json");
    if summary_path.exists() {
        let mut summary: Value = crate::io::input::read_json(&summary_path)
            .map_err(|why| anyhow::anyhow!("{}: {why}", summary_path.display()))?;
        if summary["status"] == "running" {
            mark_killed(&mut summary, &rows, dir, &listed, mcap_bytes);
            let mut text = serde_json::to_string_pretty(&summary)?;
            text.push('\n');
            crate::io::atomic::write_bytes_atomically(&summary_path, text.as_bytes())
                .with_context(|| format!("cannot write {}", summary_path.display()))?;
            done.push(format!(
                "summary.json: status `killed`, the run folder holds steps 0–{} up to t = {} s",
                rows.len().saturating_sub(1),
                short_time(rows.last().map_or(0.0, |r| r.0))
            ));
        }
    } else {
        done.push(
            "summary.json is missing (the run was killed while starting): not written".into(),
        );
    }
    if done.is_empty() {
        println!("{}: nothing to repair", dir.display());
    } else {
        println!("{}: repaired", dir.display());
        for line in done {
            println!("  {line}");
        }
    }
    Ok(())
}

/// A row of `history.csv`: its time, and whether it is a step's (or the initial state's) rather than the
/// continuous extension's at a requested time between steps (`requested` = 2).
type Row = (f64, bool);

/// Cuts `history.csv` back to its last complete row; returns every row ([`Row`]: the `k`-th step row is step
/// `k`) and the bytes cut.
fn repair_history(path: &Path) -> anyhow::Result<(Vec<Row>, usize)> {
    use crate::io::no_follow;
    use std::io::Read as _;
    let mut text = Vec::new();
    no_follow::open(path, std::fs::OpenOptions::new().read(true))
        .and_then(|mut f| f.read_to_end(&mut text))
        .with_context(|| format!("cannot read {}", path.display()))?;
    let complete = text.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let cut = text.len() - complete;
    if cut > 0 {
        let file = no_follow::open(path, std::fs::OpenOptions::new().write(true))
            .and_then(|f| f.set_len(complete as u64).and_then(|()| f.sync_all()));
        file.with_context(|| format!("cannot cut {}", path.display()))?;
    }
    let text = String::from_utf8_lossy(&text[..complete]);
    let mut lines = text.lines();
    let requested = lines
        .next()
        .and_then(|header| header.split(',').position(|h| h == "requested"));
    let rows = lines
        .map_while(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            let time = cells.first()?.parse::<f64>().ok()?;
            let extension = requested.is_some_and(|k| cells.get(k) == Some(&"2"));
            Some((time, !extension))
        })
        .collect();
    Ok((rows, cut))
}

/// Turns a `running` summary into the summary of a killed run: status, error, the time and steps the history
/// holds (and the states between steps an error-controlled run reached), the recording's size, and every snapshot
/// whose files are all on disk (a snapshot written after the last summary is added with the step and time of the
/// history row of the time in its name: the step of that row, or the last before it for a state between steps).
fn mark_killed(
    summary: &mut Value,
    rows: &[Row],
    dir: &Path,
    listed: &std::collections::BTreeSet<PathBuf>,
    mcap_bytes: Option<u64>,
) {
    // The step each row is (or follows, for a state between steps).
    let steps_of: Vec<usize> = rows
        .iter()
        .scan(0usize, |steps, &(_, is_step)| {
            *steps += usize::from(is_step);
            Some(steps.saturating_sub(1))
        })
        .collect();
    let last_step = steps_of.last().copied().unwrap_or(0);
    let last_time = rows.last().map_or(0.0, |r| r.0);
    let between = rows.iter().filter(|r| !r.1).count();
    if summary["time_error_control"].is_object() {
        summary["time_error_control"]["requested_states"] = json!(between);
    }
    summary["status"] = json!("killed");
    summary["error"] = json!(format!(
        "the run was killed (SIGKILL, a power loss or a crash) after t = {} s; repaired by `stentkit repair`",
        short_time(last_time)
    ));
    summary["updated"] = json!(crate::io::run_folder::utc_timestamp(
        std::time::SystemTime::now()
    ));
    summary["steps"] = json!(last_step);
    summary["final_time"] = json!(last_time);
    if let Some(bytes) = mcap_bytes {
        summary["files"]["mcap_bytes"] = json!(bytes);
    }
    // A listed snapshot is kept when every file it lists is on disk.
    let kinds: Vec<&str> = crate::io::formats::FORMATS
        .iter()
        .map(|f| f.extension())
        .chain(["vtp"])
        .collect();
    let mut snapshots: Vec<Value> = summary["snapshots"]
        .as_array()
        .cloned()
        .unwrap_or_default()
        .into_iter()
        .filter(|s| {
            let files: Vec<&str> = kinds.iter().filter_map(|k| s[k].as_str()).collect();
            !files.is_empty() && files.iter().all(|f| dir.join(f).is_file())
        })
        .collect();
    // Listed snapshots by time (a state between steps carries the step before it, which may have its own).
    let known: Vec<f64> = snapshots
        .iter()
        .filter_map(|s| s["time"].as_f64())
        .collect();
    // A snapshot written after the last summary: the files the manifest lists under one name
    // (`snapshots/t1.750_fixed.stl`, `.obj`, `.vtp`), complete when all of them are on disk. Its step is the
    // history row of the time in its name (`step_NNNNN` on an arc-length path); its time in full is the
    // ParaView collection's, when it lists the snapshot's field file (history.csv writes 11 digits).
    let mut unlisted: std::collections::BTreeMap<PathBuf, Vec<&PathBuf>> = Default::default();
    for file in listed.iter().filter(|p| {
        p.starts_with(crate::io::snapshots::SnapshotWriter::FOLDER)
            && p.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| kinds.contains(&e))
    }) {
        unlisted
            .entry(file.with_extension(""))
            .or_default()
            .push(file);
    }
    let collection = std::fs::read_to_string(dir.join(crate::io::snapshots::COLLECTION_FILE))
        .map(|text| crate::io::vtk::collection_entries(&text))
        .unwrap_or_default();
    for (stem, files) in unlisted {
        use crate::io::snapshots::{SnapshotAt, parse_snapshot_name};
        let name = stem
            .file_name()
            .and_then(|s| s.to_str())
            .unwrap_or_default();
        let Some((at, phase)) = parse_snapshot_name(name) else {
            continue;
        };
        // Within the name's rounding: half its sixth decimal.
        let near = |r: f64, t: f64| (r - t).abs() <= 0.5e-6 * t.abs().max(1.0) + 5e-7;
        let row = match at {
            SnapshotAt::Step(step) => steps_of.iter().position(|&s| s == step),
            SnapshotAt::Time(t) => rows.iter().position(|&(r, _)| near(r, t)),
        };
        let Some(row) = row else {
            continue;
        };
        let step = steps_of[row] as u64;
        if known.iter().any(|&k| near(k, rows[row].0))
            || !files.iter().all(|f| dir.join(f).is_file())
        {
            continue;
        }
        let time = files
            .iter()
            .find_map(|f| {
                collection
                    .iter()
                    .find(|(_, listed)| Path::new(listed) == f.as_path())
            })
            .map(|&(t, _)| t)
            .unwrap_or(rows[row].0);
        let mut entry = json!({
            "step": step,
            "time": time,
            "triangles": null,
            "volume": null,
        });
        if let Some(phase) = phase {
            entry["phase"] = json!(phase.name());
        }
        for f in &files {
            if let Some(e) = f.extension().and_then(|e| e.to_str()) {
                entry[e] = json!(f.display().to_string());
                if e == "stl" {
                    entry["triangles"] = json!(stl_triangles(&dir.join(f)));
                }
            }
        }
        snapshots.push(entry);
    }
    snapshots.sort_by(|a, b| {
        let t = |s: &Value| s["time"].as_f64().unwrap_or(0.0);
        t(a).total_cmp(&t(b))
    });
    summary["snapshots"] = Value::Array(snapshots);
}

/// The triangle count a binary STL declares (bytes 80–83), if the file is that long; reads those bytes only.
fn stl_triangles(path: &Path) -> Option<u32> {
    use std::io::{Read, Seek};
    let mut file = std::fs::File::open(path).ok()?;
    let mut count = [0u8; 4];
    file.seek(std::io::SeekFrom::Start(80)).ok()?;
    file.read_exact(&mut count).ok()?;
    Some(u32::from_le_bytes(count))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Source: the history's and the summary's contracts (issue 36 item 3). An error-controlled run's history
    /// holds, besides the initial state and its steps, rows the continuous extension wrote at requested times
    /// between steps (`requested` = 2): repair counts only the steps as steps, the others as the summary's
    /// `requested_states`, so that the repaired folder keeps `rows = steps + 1 + requested_states`.
    #[test]
    fn a_killed_error_controlled_run_counts_its_states_between_steps_apart() {
        let dir = std::env::temp_dir().join(format!("stentkit-repair-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("folder");
        let history = dir.join("history.csv");
        std::fs::write(
            &history,
            "time,iterations,requested\n0,0,0\n0.1,3,0\n0.15,2,2\n0.2,3,1\n0.3,3,0\n0.35,2,2\n0.4,1",
        )
        .expect("written");
        let (rows, cut) = repair_history(&history).expect("read");
        assert_eq!(cut, 5, "the partial last row is cut");
        assert_eq!(
            rows,
            [
                (0.0, true),
                (0.1, true),
                (0.15, false),
                (0.2, true),
                (0.3, true),
                (0.35, false)
            ]
        );
        let mut summary = json!({
            "status": "running",
            "steps": 1,
            "time_error_control": {"requested_states": 0},
            "snapshots": [],
            "files": {},
        });
        mark_killed(&mut summary, &rows, &dir, &Default::default(), None);
        assert_eq!(summary["steps"], 3);
        assert_eq!(summary["final_time"], 0.35);
        assert_eq!(summary["time_error_control"]["requested_states"], 2);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
