//! `stentkit mesh`: the full device as a closed tube surface, in its permanent shape (the shape a 4D printer
//! prints) or in the temporary shape its programme drives it to (the shape a designer previews), without
//! simulating.
//!
//! The temporary shape is the device generated in the programme's temporary placement
//! ([`crate::geometry::stent::StentSpec::generate_temporary`]: every crown shrunk by Δr for a radial
//! contraction; the `temporary` centreline and radius for a target shape), then moved by the rigid motion that
//! takes its driven nodes onto the programme's targets `P_0 + η` (the identity, unless the target shape is
//! aligned). Its driven nodes then sit where the programme prescribes them at the end of its ramp, which the
//! command checks and prints. The wires between the nodes follow the generator, not a simulation: the
//! simulated programmed shape is `stentkit export RUN_DIR --phase programmed`.
//!
//! With `--print`, either shape is written as one printable solid ([`crate::post::print`]) instead of one
//! tube per rod.

use super::BadInput;
use super::drawing::{Drawing, Sampling, check_drawing};
use crate::design::{DesignOverrides, SetOverride, load_design_with};
use crate::geometry::fit::best_fit_rigid;
use crate::io::{obj, stl, threemf};
use crate::math::{Real, Vec3};
use crate::model::Model;
use crate::post::device::{device_rods, reference_device_mesh, reference_patch_shapes};
use crate::post::print::{PrintSettings, print_solid};
use anyhow::{Context, bail};
use std::path::Path;

/// Which shape `mesh` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum State {
    /// The shape the device is made in (and recovers to).
    Permanent,
    /// The shape the programme drives it to, before it is released.
    Temporary,
}

/// How finely `mesh` draws the device.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Resolution {
    /// Vertices around each tube.
    pub segments: usize,
    /// Samples along each patch per control point.
    pub samples: usize,
    /// One print solid instead of tubes, and how fine.
    pub print: Option<PrintSettings>,
}

/// Writes the shape `state` of the design (with the `--set` overrides `sets`) to `output` (`.stl`, `.obj`,
/// `.3mf` or `.csv`; an existing file only with `--force`).
pub(crate) fn run(
    design: &Path,
    output: super::Target<'_>,
    state: State,
    resolution: Resolution,
    sets: Vec<SetOverride>,
) -> anyhow::Result<()> {
    let super::Target {
        path: output,
        force,
    } = output;
    let extension = output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    super::refuse_existing([output], force)?;
    let permanent = load_design_with(design, &DesignOverrides::sets(sets.clone()))?;
    check_drawing(
        &permanent.model,
        &Drawing {
            sampling: Sampling::PerPoint(resolution.samples),
            segments: resolution.segments,
            print: resolution.print,
            centrelines: extension.as_deref() == Some("csv"),
        },
    )?;
    let (model, placed) = match state {
        State::Permanent => (permanent.model, None),
        State::Temporary => {
            // A design without a programme is refused by the builder, at its `programme` field.
            let temporary = load_design_with(
                design,
                &DesignOverrides {
                    sets,
                    temporary_shape: true,
                    ..DesignOverrides::default()
                },
            )?;
            for w in &temporary.warnings {
                eprintln!("warning: {w}");
            }
            let placement = placement(&permanent.model, &temporary.model)?;
            (temporary.model, Some(placement))
        }
    };
    let shapes = || {
        reference_patch_shapes(&model, resolution.samples)
            .map_err(|(k, e)| anyhow::anyhow!("patch `{}`: {e}", model.patches[k].name))
    };
    if extension.as_deref() == Some("csv") {
        return write_centrelines(&model, &shapes()?, placed.map(|(r, t, _)| (r, t)), output);
    }
    let solid = resolution.print.is_some();
    let mut mesh = match resolution.print {
        None => reference_device_mesh(&model, resolution.segments, resolution.samples)?,
        // The solid stands upright whatever the placement: a rigid motion first would change nothing.
        Some(settings) => print_solid_mesh(&model, &shapes()?, &settings)?,
    };
    if let (Some((r, t, _)), false) = (placed, solid) {
        for v in &mut mesh.vertices {
            *v = r * *v + t;
        }
    }
    mesh.check_closed()
        .context("the surface is not closed (please report this)")?;
    let header = format!(
        "{}{} {} shape, units {} (lengths in {})",
        if solid { "print solid: " } else { "" },
        model.name(),
        match state {
            State::Permanent => "reference (permanent)",
            State::Temporary => "temporary (programmed)",
        },
        model.units.name(),
        model.units.length()
    );
    match extension.as_deref() {
        Some("stl") => stl::write_stl_with_header(output, &mesh, &header)?,
        Some("3mf") => threemf::write_3mf(output, &mesh, model.units, &header)?,
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
    if let Some((_, _, off)) = placed {
        println!(
            "temporary shape: the driven nodes are within {off:.3e} {} of the programme's targets",
            model.units.length()
        );
    }
    // Wires that overlap in the shape written (a rigid motion changes no distance).
    print!("{}", super::check::describe_overlaps(&model));
    Ok(())
}

/// The print solid of `model` in the shape `shapes` ([`print_solid`]), saying that it is being made (it takes
/// a few seconds for the paper's stents) and how it was made.
pub(super) fn print_solid_mesh(
    model: &Model,
    shapes: &[crate::solver::shape::PatchShape],
    settings: &PrintSettings,
) -> anyhow::Result<crate::geometry::mesh::TriangleMesh> {
    eprintln!("making the print solid (a few seconds for the paper's stents)");
    let solid = print_solid(model, shapes, settings).map_err(|e| BadInput(e.to_string()))?;
    println!("{}", solid.describe(model.units.length()));
    if solid.mesh.triangles.is_empty() {
        bail!("the print solid is empty (please report this)");
    }
    Ok(solid.mesh)
}

/// Writes the full device's wires in the shape `shapes` as centrelines to `output` (CSV: `rod,point,x,y,z,
/// radius`, one row per sample; rods numbered in the order of the model's patches and their mirror copies),
/// moved by `motion`: the device for CAD tools, and the input of the independent check of the print solid's
/// volume (`scripts/check_print.py`).
pub(super) fn write_centrelines(
    model: &Model,
    shapes: &[crate::solver::shape::PatchShape],
    motion: Option<(crate::math::Mat3, Vec3)>,
    output: &Path,
) -> anyhow::Result<()> {
    use std::fmt::Write as _;
    let mut text = format!(
        "# {}: wire centrelines, lengths in {}\nrod,point,x,y,z,radius\n",
        model.name(),
        model.units.length()
    );
    let mut rods = 0;
    for (rod, (patch, line)) in device_rods(model, shapes).enumerate() {
        let radius = model.wire_radius(patch);
        for (k, p) in line.iter().enumerate() {
            let p = motion.map_or(*p, |(r, t)| r * p + t);
            let _ = writeln!(text, "{rod},{k},{},{},{},{radius}", p.x, p.y, p.z);
        }
        rods += 1;
    }
    crate::io::atomic::write_bytes_atomically(output, text.as_bytes())
        .with_context(|| format!("cannot write {}", output.display()))?;
    println!("wrote {} ({rods} rods)", output.display());
    Ok(())
}

/// The rigid motion `(R, t)` that takes the driven nodes of the device in its temporary placement
/// (`temporary`, nodes named as in `permanent`) onto the programme's targets `P_0 + η` (weighted as the
/// programme weighs them), and the largest distance left between a moved node and its target.
fn placement(
    permanent: &Model,
    temporary: &Model,
) -> anyhow::Result<(crate::math::Mat3, Vec3, Real)> {
    let Some(programme) = &permanent.programme else {
        bail!("no programme");
    };
    let (mut from, mut to, mut weights) = (Vec::new(), Vec::new(), Vec::new());
    for d in &programme.nodes {
        let name = &permanent.nodes[d.node].name;
        let position = temporary
            .nodes
            .iter()
            .find(|n| &n.name == name)
            .map(|n| n.position)
            .with_context(|| format!("node `{name}` is missing from the temporary shape"))?;
        from.push(position);
        to.push(d.position + d.target);
        weights.push(d.weight);
    }
    let (r, t) = best_fit_rigid(&from, &to, &weights)
        .context("the driven nodes do not define a rigid placement")?;
    let off = from
        .iter()
        .zip(&to)
        .map(|(p, q)| (r * p + t - q).norm())
        .fold(0.0, Real::max);
    Ok((r, t, off))
}
