//! `stentkit mesh`: the reference shape as a closed tube surface.

use crate::geometry::frame::{FrameField, FrameSettings};
use crate::geometry::tube::{TriangleMesh, TubeSettings, sweep_curve};
use crate::io::design::load_design;
use crate::io::{obj, stl};
use crate::model::Model;
use anyhow::{Context, bail};
use std::path::Path;

/// Golden-ratio conjugate: successive multiples modulo 1 are as evenly spread as possible, so no two patches
/// get (nearly) the same section phase.
const PHASE_STEP: f64 = 0.618_033_988_749_894_9;

/// The closed tube surface of every patch of the model in its reference shape.
pub fn reference_mesh(
    model: &Model,
    segments: usize,
    samples_per_point: usize,
) -> anyhow::Result<TriangleMesh> {
    let settings = TubeSettings {
        segments_around: segments,
        ..TubeSettings::default()
    };
    let mut mesh = TriangleMesh::new();
    for (k, patch) in model.patches.iter().enumerate() {
        let frames = FrameField::rotation_minimising(
            &patch.curve,
            patch.normal_hint,
            &FrameSettings::default(),
        )
        .with_context(|| format!("patch `{}`", patch.name))?;
        let radius = 0.5 * model.sections[patch.section].diameter();
        let samples = samples_per_point.max(1) * patch.curve.num_points();
        let phase = (k as f64 * PHASE_STEP).fract();
        let tube = sweep_curve(&patch.curve, &frames, radius, samples, phase, &settings)
            .with_context(|| format!("patch `{}`", patch.name))?;
        mesh.append(&tube);
    }
    Ok(mesh)
}

/// Writes the reference shape of the design to `output` (`.stl` or `.obj`).
pub fn run(design: &Path, output: &Path, segments: usize, samples: usize) -> anyhow::Result<()> {
    let extension = output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(extension.as_deref(), Some("stl" | "obj")) {
        bail!("{}: the output must end in .stl or .obj", output.display());
    }
    let design = load_design(design)?;
    let model = &design.model;
    let mesh = reference_mesh(model, segments, samples)?;
    mesh.check_closed()
        .context("the tube surface is not closed (please report this)")?;
    let header = format!(
        "{} reference shape, units {} (lengths in {})",
        model.name,
        model.units.name(),
        model.units.length()
    );
    match extension.as_deref() {
        Some("stl") => stl::write_stl_with_header(output, &mesh, &header)?,
        _ => obj::write_obj(output, &mesh, &header)?,
    }
    println!(
        "wrote {} ({} triangles, {} patches, volume {:.6e} {}³)",
        output.display(),
        mesh.triangles.len(),
        model.patches.len(),
        mesh.volume(),
        model.units.length()
    );
    Ok(())
}
