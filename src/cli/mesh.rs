//! `stentkit mesh`: the reference shape of the full device as a closed tube surface.

use crate::geometry::mesh::TriangleMesh;
use crate::io::design::load_design;
use crate::io::device::{device_tube_mesh, reference_patch_shapes};
use crate::io::{obj, stl};
use crate::model::Model;
use anyhow::{Context, bail};
use std::path::Path;

/// The closed tube surface of the full device (mirrored back from a symmetry-reduced model) in its reference
/// shape.
pub fn reference_mesh(
    model: &Model,
    segments: usize,
    samples_per_point: usize,
) -> anyhow::Result<TriangleMesh> {
    let shapes = reference_patch_shapes(model, samples_per_point).map_err(|(k, e)| {
        anyhow::Error::new(e).context(format!("patch `{}`", model.patches[k].name))
    })?;
    device_tube_mesh(model, &shapes, segments).map_err(|e| {
        let name = &model.patches[e.rod].name;
        anyhow::Error::new(e.source).context(format!("patch `{name}`"))
    })
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
        "wrote {} ({} triangles, {} patches{}, volume {:.6e} {}³)",
        output.display(),
        mesh.triangles.len(),
        model.patches.len(),
        match model.symmetry_planes.len() {
            0 => String::new(),
            n => format!(
                " mirrored about {n} symmetry plane{}",
                if n > 1 { "s" } else { "" }
            ),
        },
        mesh.volume(),
        model.units.length()
    );
    Ok(())
}
