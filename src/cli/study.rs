//! `stentkit study`: the arguments of each study turned into its settings, the study run by the library
//! ([`crate::study`]), its CSV and charts written into the output folder, and its progress and results printed.

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
/// (default: the design's end time).
pub fn convergence(
    design: &Path,
    output: &Path,
    degrees: Vec<usize>,
    points: Vec<usize>,
    reference: Vec<usize>,
    sampling: Sampling,
    time_tolerance: Option<f64>,
) -> anyhow::Result<()> {
    let Sampling { time, samples } = sampling;
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
    let csv = output.join("convergence.csv");
    write(&csv, &convergence_csv(&rows, &study, &model.name))?;
    let [by_n, by_time] = convergence_charts(&rows, &study, &model.name);
    write_svg(&by_n, &output.join("error_vs_n.svg"))?;
    write_svg(&by_time, &output.join("error_vs_time.svg"))?;
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
/// design's end time) against `reference` (`auto`, `design` or a step).
pub fn time(
    design: &Path,
    output: &Path,
    steps: Vec<f64>,
    tolerances: Vec<f64>,
    integrators: &[String],
    reference: &str,
    sampling: Sampling,
) -> anyhow::Result<()> {
    let Sampling { time, samples } = sampling;
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
    let csv = output.join("time_steps.csv");
    write(&csv, &time_csv(&result, &study, &model.name))?;
    let [by_h, by_time] = time_charts(&result, &study, &model.name);
    write_svg(&by_h, &output.join("error_vs_h.svg"))?;
    write_svg(&by_time, &output.join("error_vs_time.svg"))?;
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
/// written as `<map>.csv` and `<map>.svg` as soon as it is done, then `stability.md`.
pub fn stability_maps(output: &Path, maps: &[String]) -> anyhow::Result<()> {
    for m in maps {
        anyhow::ensure!(
            ["material", "bend45", "heating", "release", "coarse"].contains(&m.as_str()),
            "unknown map `{m}` (material, bend45, heating, release, coarse)"
        );
    }
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
    write(&output.join("stability.md"), &summary)?;
    println!("{summary}");
    println!("→ {}", output.join("stability.md").display());
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

/// Writes `text` to `file`.
fn write(file: &Path, text: &str) -> anyhow::Result<()> {
    std::fs::write(file, text).with_context(|| format!("cannot write {}", file.display()))
}
