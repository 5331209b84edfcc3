//! `stentkit mesh`: the reference shape of the full device as a closed tube surface.

use crate::io::design::{DesignOverrides, SetOverride, load_design_with};
use crate::io::{obj, stl};
use crate::post::device::reference_device_mesh;
use anyhow::{Context, bail};
use std::path::Path;

/// Writes the reference shape of the design (with the `--set` overrides `sets`) to `output` (`.stl` or `.obj`).
pub fn run(
    design: &Path,
    output: &Path,
    segments: usize,
    samples: usize,
    sets: Vec<SetOverride>,
) -> anyhow::Result<()> {
    let extension = output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(extension.as_deref(), Some("stl" | "obj")) {
        bail!("{}: the output must end in .stl or .obj", output.display());
    }
    let design = load_design_with(design, &DesignOverrides::sets(sets))?;
    let model = &design.model;
    let mesh = reference_device_mesh(model, segments, samples)?;
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
