//! `stentkit study`: the arguments of each study turned into its settings, the study run by the library
//! ([`crate::study`]), its CSV and charts written into the output folder, and its progress and results printed.

use super::Target;
use crate::io::chart::write_svg;
use crate::io::design::load_design;
use crate::material::Integrator;
use crate::study::convergence::{
    ConvergenceStudy, convergence_charts, convergence_csv, convergence_study,
};
use crate::study::stability::{StabilityStudy, stability};
use crate::study::time::{TimeReference, TimeStudy, time_charts, time_csv, time_study};
use anyhow::Context;
use std::path::Path;

/// The files `study convergence` writes into its folder.
const CONVERGENCE_FILES: [&str; 3] = ["convergence.csv", "error_vs_n.svg", "error_vs_time.svg"];
/// The files `study time` writes into its folder.
const TIME_FILES: [&str; 3] = ["time_steps.csv", "error_vs_h.svg", "error_vs_time.svg"];
/// The summary `study stability` writes after its maps (`<map>.csv`, `<map>.svg`).
const STABILITY_SUMMARY: &str = "stability.md";

/// When and where a study measures its error: at `time` (default: the design's end time), on `samples` points
/// per patch.
#[derive(Debug, Clone, Copy)]
pub struct Sampling {
    /// Time of the measurement.
    pub time: Option<f64>,
    /// Sampling points per patch.
    pub samples: usize,
}

/// `stentkit study convergence`: the `p × n` sweep of `design` against the reference `P,N`, measured at `time`
/// (default: the design's end time), written into the folder `output` (its files replaced only with `--force`).
pub fn convergence(
    design: &Path,
    output: Target<'_>,
    degrees: Vec<usize>,
    points: Vec<usize>,
    reference: Vec<usize>,
    sampling: Sampling,
    time_tolerance: Option<f64>,
) -> anyhow::Result<()> {
    let Sampling { time, samples } = sampling;
    let Target {
        path: output,
        force,
    } = output;
    refuse_existing(output, CONVERGENCE_FILES, force)?;
    let design = load_design(design)?;
    let model = &design.model;
    let [rp, rn] = reference[..] else {
        anyhow::bail!("--reference takes two numbers, P,N");
    };
    let study = ConvergenceStudy {
        degrees,
        points,
        time: time.unwrap_or(model.time.end),
        reference: (rp, rn),
        samples,
        time_tolerance,
    };
    create(output)?;
    let rows = convergence_study(&design, &study, progress)?;
    let [csv, by_n_svg, by_time_svg] = CONVERGENCE_FILES.map(|f| output.join(f));
    write(&csv, &convergence_csv(&rows, &study, &model.name))?;
    let [by_n, by_time] = convergence_charts(&rows, &study, &model.name);
    write_svg(&by_n, &by_n_svg)?;
    write_svg(&by_time, &by_time_svg)?;
    println!(
        "{}: {} runs → {} (and error_vs_n.svg, error_vs_time.svg)",
        model.name,
        rows.len(),
        csv.display()
    );
    Ok(())
}

/// Parses an integrator's design-file name (`trapezoidal`, `backward-euler`, `exponential`).
pub fn parse_integrator(name: &str) -> Result<Integrator, String> {
    [
        Integrator::Trapezoidal,
        Integrator::BackwardEuler,
        Integrator::Exponential,
    ]
    .into_iter()
    .find(|i| i.name() == name)
    .ok_or_else(|| {
        format!("unknown integrator `{name}` (trapezoidal, backward-euler or exponential)")
    })
}

/// `stentkit study time`: the time-step sweep of `design` per integrator, measured at `time` (default: the
/// design's end time) against `reference` (`auto`, `design` or a step), written into the folder `output` (its
/// files replaced only with `--force`).
pub fn time(
    design: &Path,
    output: Target<'_>,
    steps: Vec<f64>,
    tolerances: Vec<f64>,
    integrators: &[String],
    reference: &str,
    sampling: Sampling,
) -> anyhow::Result<()> {
    let Sampling { time, samples } = sampling;
    let Target {
        path: output,
        force,
    } = output;
    refuse_existing(output, TIME_FILES, force)?;
    let design = load_design(design)?;
    let model = &design.model;
    let integrators = integrators
        .iter()
        .map(|name| parse_integrator(name).map_err(anyhow::Error::msg))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let reference = match reference {
        "auto" => TimeReference::Auto,
        "design" => TimeReference::Design,
        h => TimeReference::Step(h.parse().with_context(|| {
            format!("--reference takes auto, design or a time step, not `{h}`")
        })?),
    };
    let study = TimeStudy {
        integrators,
        steps,
        tolerances,
        time: time.unwrap_or(model.time.end),
        reference,
        samples,
    };
    create(output)?;
    let result = time_study(model, &study, progress)?;
    let [csv, by_h_svg, by_time_svg] = TIME_FILES.map(|f| output.join(f));
    write(&csv, &time_csv(&result, &study, &model.name))?;
    let [by_h, by_time] = time_charts(&result, &study, &model.name);
    write_svg(&by_h, &by_h_svg)?;
    write_svg(&by_time, &by_time_svg)?;
    println!(
        "{}: errors at t = {} against {}",
        model.name, study.time, result.reference
    );
    for (integrator, order) in &result.orders {
        match order {
            Some(q) => println!("  {:<15} observed order {q:.2}", integrator.name()),
            None => println!(
                "  {:<15} observed order n/a (fewer than two runs with an error)",
                integrator.name()
            ),
        }
    }
    println!(
        "{} runs → {} (and error_vs_h.svg, error_vs_time.svg)",
        result.rows.len(),
        csv.display()
    );
    Ok(())
}

/// `stentkit study stability`: the maps named in `maps` (any of material, bend45, heating, release, coarse), each
/// written as `<map>.csv` and `<map>.svg` as soon as it is done, then `stability.md`, into the folder `output`
/// (its files replaced only with `--force`).
pub fn stability_maps(output: Target<'_>, maps: &[String]) -> anyhow::Result<()> {
    let Target {
        path: output,
        force,
    } = output;
    for m in maps {
        anyhow::ensure!(
            ["material", "bend45", "heating", "release", "coarse"].contains(&m.as_str()),
            "unknown map `{m}` (material, bend45, heating, release, coarse)"
        );
    }
    let files: Vec<String> = maps
        .iter()
        .flat_map(|m| [format!("{m}.csv"), format!("{m}.svg")])
        .chain([STABILITY_SUMMARY.to_string()])
        .collect();
    refuse_existing(output, files.iter().map(String::as_str), force)?;
    let mut study = StabilityStudy::default();
    let wanted = |name: &str| maps.iter().any(|m| m == name);
    if !wanted("material") {
        study.ratios.clear();
    }
    if !wanted("bend45") {
        study.load_steps.clear();
    }
    if !wanted("heating") {
        study.heating.clear();
    }
    if !wanted("release") {
        study.release.clear();
    }
    if !wanted("coarse") {
        study.coarse.clear();
    }
    create(output)?;
    let summary = stability(
        &study,
        |map| -> anyhow::Result<()> {
            write(&output.join(format!("{}.csv", map.name)), &map.csv)?;
            write_svg(&map.chart, &output.join(format!("{}.svg", map.name)))?;
            Ok(())
        },
        progress,
    )?;
    write(&output.join(STABILITY_SUMMARY), &summary)?;
    println!("{summary}");
    println!("→ {}", output.join(STABILITY_SUMMARY).display());
    Ok(())
}

/// Prints a study's progress line (indented, on stderr: stdout holds the results).
fn progress(line: &str) {
    eprintln!("  {line}");
}

/// Creates the output folder.
fn create(output: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(output).with_context(|| format!("cannot create {}", output.display()))
}

/// Refuses (exit status 2) the folder `output` when it holds any of the study's `files`, unless `force`; an
/// empty or new folder, or one holding only other files, is fine.
fn refuse_existing<'a>(
    output: &Path,
    files: impl IntoIterator<Item = &'a str>,
    force: bool,
) -> Result<(), super::BadInput> {
    let paths: Vec<std::path::PathBuf> = files.into_iter().map(|f| output.join(f)).collect();
    super::refuse_existing(paths.iter().map(std::path::PathBuf::as_path), force)
}

/// Writes `text` to `file` atomically (a link in its place is replaced, not written through).
fn write(file: &Path, text: &str) -> anyhow::Result<()> {
    crate::io::stl::write_bytes_atomically(file, text.as_bytes())
        .with_context(|| format!("cannot write {}", file.display()))
}
