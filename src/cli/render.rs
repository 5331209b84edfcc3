//! `stentkit render RUN_DIR -o OUT.png`: a finished run's snapshots as a shaded picture ([`crate::io::render`]),
//! the times chosen as the configuration figures choose them unless `--times` names others (each the nearest
//! snapshot's).

use super::{BadInput, short_time};
use crate::io::configurations::{View, chosen_indices};
use crate::io::render::{render_snapshots, write_png};
use crate::io::snapshots::{SnapshotWriter, VESSEL_FILE};
use std::path::{Path, PathBuf};

/// `text` when it names a view ([`View::parse`]; `--view` is checked with it as it is read).
pub(crate) fn view_name(text: &str) -> Result<String, String> {
    View::parse(text)
        .map(|_| text.to_string())
        .ok_or_else(|| "must be axonometric, x1-x2, x1-x3 or x2-x3".to_string())
}

/// Draws the snapshots of the run folder `dir` at `times` (empty: the default choice) in `view` into `output`
/// (an existing file only with `--force`).
///
/// # Errors
/// [`BadInput`] for an unknown view, an output that is not `.png` or exists (without `--force`), or a folder
/// without summary or snapshots; the error of a mesh that cannot be read or a picture that cannot be written.
pub(crate) fn run(
    dir: &Path,
    output: super::Target<'_>,
    times: &[f64],
    view: &str,
    width: u32,
) -> anyhow::Result<()> {
    let super::Target {
        path: output,
        force,
    } = output;
    let view = View::parse(view).ok_or_else(|| {
        BadInput(format!(
            "--view `{view}`: expected axonometric, x1-x2, x1-x3 or x2-x3"
        ))
    })?;
    if output.extension().and_then(|e| e.to_str()) != Some("png") {
        return Err(BadInput(format!("{}: the output must end in .png", output.display())).into());
    }
    if !(16..=2048).contains(&width) {
        return Err(BadInput(format!("--width {width}: expected 16 to 2048 pixels")).into());
    }
    super::refuse_existing([output], force)?;
    let summary_path = dir.join("summary.json");
    let summary: serde_json::Value = crate::io::input::read_json(&summary_path).map_err(|why| {
        BadInput(format!(
            "{}: {why} (not a run folder?)",
            summary_path.display()
        ))
    })?;
    // Every snapshot with an STL, in time order (the first is the initial state).
    let snapshots: Vec<(f64, PathBuf)> = summary["snapshots"]
        .as_array()
        .map(|list| {
            list.iter()
                .filter_map(|s| Some((s["time"].as_f64()?, dir.join(s["stl"].as_str()?))))
                .collect()
        })
        .unwrap_or_default();
    let Some((_, initial)) = snapshots.first() else {
        return Err(BadInput(format!(
            "{}: lists no snapshot with an STL file",
            summary_path.display()
        ))
        .into());
    };
    let snapshot_times: Vec<f64> = snapshots.iter().map(|s| s.0).collect();
    let picked: Vec<usize> = if times.is_empty() {
        chosen_indices(&snapshot_times, &[], 0.0)
    } else {
        let mut picked: Vec<usize> = times
            .iter()
            .filter_map(|t| {
                (0..snapshots.len()).min_by(|&a, &b| {
                    (snapshot_times[a] - t)
                        .abs()
                        .total_cmp(&(snapshot_times[b] - t).abs())
                })
            })
            .filter(|&k| k > 0)
            .collect();
        picked.dedup();
        picked
    };
    let states: Vec<PathBuf> = picked.iter().map(|&k| snapshots[k].1.clone()).collect();
    let lumen = dir.join(SnapshotWriter::FOLDER).join(VESSEL_FILE);
    let pixmap = render_snapshots(
        initial,
        &states,
        lumen.exists().then_some(lumen.as_path()),
        view,
        width,
    )?;
    write_png(output, &pixmap)?;
    let shown: Vec<String> = std::iter::once(0)
        .chain(picked)
        .map(|k| short_time(snapshot_times[k]))
        .collect();
    println!(
        "wrote {} ({} × {} px, {} view): t = {} s, left to right and top to bottom",
        output.display(),
        pixmap.width(),
        pixmap.height(),
        view.name(),
        shown.join(", ")
    );
    Ok(())
}
