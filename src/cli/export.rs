//! `stentkit export RUN_DIR --time T | --phase P -o FILE`: the full device's tube mesh in any state of a
//! finished run, at any resolution, not only at the snapshots the run wrote.
//!
//! A run folder holds no full state per step (the recording's centrelines are decimated), so the state is
//! computed again: the design that ran (`summary.json`'s `design_file` with its `--set` overrides, or `--design`,
//! and, for an error-controlled run, its time tolerance) is simulated from the start to the first step at or
//! after the time asked for, with no outputs. Steps are
//! deterministic, so that step is the run's own state to the bit; a phase's time is an event of the cycle
//! ([`crate::model::cycle`]), on which the run landed. The design is checked against the run's model
//! fingerprint (`summary.json`'s `model_fingerprint`) first: a changed design would export another device.
//! (An error-controlled run's snapshot at a requested time inside a step is its continuous extension there,
//! `crate::solver::simulation`'s dense output, not a step: `--time` exports the first step at or after it.)
//! Costs what the run's solver cost up to that time (the straight stent to its end: about 6 s).
//!
//! With `--print` the state is written as one printable solid ([`crate::post::print`]), with its rods sampled
//! at `--rings` points each (the straight stent's final state: 343.10 mm³ with the default 41, 342.87 mm³ with
//! 161, 0.07 % apart); a `.csv` output holds the state's centrelines instead of a mesh.

use super::BadInput;
use crate::design::{DesignOverrides, SetOverride, load_design_with};
use crate::io::formats;
use crate::io::mesh_format::SnapshotState;
use crate::io::snapshots::{current_device_mesh, snapshot_name};
use crate::io::summary::model_fingerprint_text;
use crate::math::Real;
use crate::model::cycle::Phase;
use crate::post::device::current_device_shapes;
use crate::post::print::PrintSettings;
use crate::solver::Simulation;
use anyhow::Context;
use std::path::{Path, PathBuf};

/// Which state of the run to export.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Which {
    /// The first step at or after this time.
    Time(Real),
    /// An event of the cycle: `initial`, `programmed`, `fixed`, `released`, `final`.
    Phase(String),
}

/// What to export and how finely.
#[derive(Debug, Clone)]
pub(crate) struct ExportOptions {
    /// The state.
    pub which: Which,
    /// The mesh file (`.stl`, `.obj`, `.3mf`), or `.csv` for the centrelines.
    pub output: PathBuf,
    /// Replace `output` if it exists (otherwise an existing file is refused).
    pub force: bool,
    /// The design, instead of the run's `design_file`.
    pub design: Option<PathBuf>,
    /// Vertices around each tube section.
    pub segments: usize,
    /// Rings along each patch, about.
    pub rings: usize,
    /// One print solid instead of tubes ([`crate::post::print`]), and how fine.
    pub print: Option<PrintSettings>,
}

/// Exports the state `options.which` of the run in `run_dir` to `options.output`.
///
/// # Errors
/// [`BadInput`] for an output that exists (without `force`), a folder that is not a run folder, a design that
/// is not the one that ran, a phase the model does not have or a time outside what the run reached; the design's errors; a step that fails.
pub(crate) fn run(run_dir: &Path, options: &ExportOptions) -> anyhow::Result<()> {
    let extension = options
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    // (The extension was checked with the arguments: `arguments::device_file`.)
    let format = formats::format(&extension);
    super::refuse_existing([options.output.as_path()], options.force)?;
    let summary_path = run_dir.join("summary.json");
    let summary: serde_json::Value = crate::io::input::read_json(&summary_path).map_err(|why| {
        BadInput(format!(
            "{}: not a run folder (summary.json: {why})",
            run_dir.display()
        ))
    })?;
    let design_path = match &options.design {
        Some(path) => path.clone(),
        None => PathBuf::from(summary["design_file"].as_str().unwrap_or_default()),
    };
    let sets = summary["overrides"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|v| v.as_str())
        .map(str::parse::<SetOverride>)
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| BadInput(format!("{}: overrides: {e}", summary_path.display())))?;
    // A run with `--tol` stepped at that tolerance, which summary.json records.
    let overrides = DesignOverrides {
        sets,
        time_tolerance: summary["time_error_control"]["tolerance"].as_f64(),
        ..DesignOverrides::default()
    };
    let design = load_design_with(&design_path, &overrides)?;
    let model = &design.model;
    let fingerprint = model_fingerprint_text(model);
    if let Some(ran) = summary["model_fingerprint"].as_str()
        && ran != fingerprint
    {
        // The form's version (`v2-…`, io::summary::model_fingerprint_text) tells a run of an earlier stentkit,
        // which hashed models otherwise, from a run of another model.
        let form = fingerprint.split('-').next().unwrap_or_default();
        let why = if ran.split('-').next() == Some(form) {
            format!(
                "{}: this design (with the run's overrides) is not the model that ran in {} (fingerprint {fingerprint}, the run's {ran}): restore the design as it ran, or give it with --design",
                design_path.display(),
                run_dir.display()
            )
        } else {
            format!(
                "{}: its summary.json holds a model fingerprint of another form ({ran}; this stentkit writes {form}-…), from a stentkit that fingerprinted models otherwise, so the design cannot be checked against the model that ran: run the design again with this stentkit",
                run_dir.display()
            )
        };
        return Err(BadInput(why).into());
    }
    // Before the simulation: what drawing the state would cost.
    super::drawing::check_drawing(
        model,
        &super::drawing::Drawing {
            sampling: super::drawing::Sampling::PerPatch(options.rings),
            segments: options.segments,
            print: options.print,
            centrelines: extension == "csv",
        },
    )?;
    let snap = model.time().landing_tolerance();
    let target = match &options.which {
        Which::Time(t) => *t,
        Which::Phase(name) => {
            let events = model.events();
            let found = Phase::parse(name)
                .and_then(|p| events.iter().find(|(_, e)| *e == p))
                .map(|&(t, _)| t);
            found.ok_or_else(|| {
                let known: Vec<String> = events
                    .iter()
                    .map(|(t, p)| format!("{p} (t = {})", super::short_time(*t)))
                    .collect();
                BadInput(format!(
                    "`{name}` is not an event of {}; its events: {}",
                    model.name(),
                    known.join(", ")
                ))
            })?
        }
    };
    let reached = summary["final_time"].as_f64().unwrap_or(model.time().end);
    if !(0.0..=reached + snap).contains(&target) {
        return Err(BadInput(format!(
            "t = {} is outside the run in {}, which reached t = {}",
            super::short_time(target),
            run_dir.display(),
            super::short_time(reached)
        ))
        .into());
    }

    let mut sim = Simulation::new(model)?;
    let mut step = 0;
    while sim.time() < target - snap {
        match sim
            .step()
            .with_context(|| format!("re-running {} to t = {}", model.name(), target))?
        {
            Some(report) => step = report.step,
            None => break,
        }
    }
    if extension == "csv" {
        let shapes = current_device_shapes(&sim, options.rings);
        return super::mesh::write_centrelines(model, &shapes, None, &options.output);
    }
    let mesh = match &options.print {
        None => current_device_mesh(&sim, options.segments, options.rings)
            .map_err(|e| anyhow::anyhow!("patch `{}`: {}", model.patches[e.rod].name, e.source))?,
        Some(settings) => super::mesh::print_solid_mesh(
            model,
            &current_device_shapes(&sim, options.rings),
            settings,
        )?,
    };
    let time = sim.time();
    let state = SnapshotState { model, step, time };
    if let Some(format) = format {
        format.write(&options.output, &mesh, &state)?;
    }
    println!(
        "wrote {} ({}, step {step}: {} triangles, volume {:.6e} {}³)",
        options.output.display(),
        snapshot_name(model, step, time, model.phase_at(time)),
        mesh.triangles.len(),
        mesh.volume(),
        model.units.length()
    );
    Ok(())
}
