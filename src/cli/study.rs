//! `stentkit study`: the arguments of each study turned into its settings, the study run by the library
//! ([`crate::study`]), its CSV and charts written into the output folder, and its progress and results printed.

use super::BadInput;
use super::Target;
use super::arguments::{count, rounded_up, short};
use crate::design::size::{StepCount, over_limit};
use crate::design::{Design, load_design};
use crate::io::chart::write_svg;
use crate::material::Integrator;
use crate::study::convergence::{
    ConvergenceStudy, convergence_charts, convergence_csv, convergence_study,
};
use crate::study::stability::{StabilityStudy, stability};
use crate::study::time::{TimeReference, TimeStudy, time_charts, time_csv, time_study};
use crate::study::variant::TimeVariant;
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
pub(crate) struct Sampling {
    /// Time of the measurement.
    pub time: Option<f64>,
    /// Sampling points per patch.
    pub samples: usize,
}

/// `stentkit study convergence`: the `p × n` sweep of `design` against the reference `P,N`, measured at `time`
/// (default: the design's end time), written into the folder `output` (its files replaced only with `--force`).
pub(crate) fn convergence(
    design: &Path,
    output: Target<'_>,
    degrees: Vec<usize>,
    points: Vec<usize>,
    reference: (usize, usize),
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
    if let Some(t) = time {
        check_steps(
            &design,
            &format!("--time {}", short(t)),
            &ending(t, None),
            1.0,
        )?;
    }
    let study = ConvergenceStudy {
        degrees,
        points,
        time: time.unwrap_or(model.time().end),
        reference,
        samples,
        time_tolerance,
    };
    create(output)?;
    let rows = convergence_study(&design, &study, progress)?;
    let [csv, by_n_svg, by_time_svg] = CONVERGENCE_FILES.map(|f| output.join(f));
    write(&csv, &convergence_csv(&rows, &study, model.name()))?;
    let [by_n, by_time] = convergence_charts(&rows, &study, model.name());
    write_svg(&by_n, &by_n_svg)?;
    write_svg(&by_time, &by_time_svg)?;
    println!(
        "{}: {} runs → {} (and error_vs_n.svg, error_vs_time.svg)",
        model.name(),
        rows.len(),
        csv.display()
    );
    Ok(())
}

/// Parses an integrator's design-file name (`trapezoidal`, `backward-euler`, `exponential`).
pub(crate) fn parse_integrator(name: &str) -> Result<Integrator, String> {
    [
        Integrator::Trapezoidal,
        Integrator::BackwardEuler,
        Integrator::Exponential,
    ]
    .into_iter()
    .find(|i| i.name() == name)
    .ok_or_else(|| "must be one of trapezoidal, backward-euler, exponential".to_string())
}

/// Parses `study time --reference`: `auto`, `design` or a time step > 0.
pub(crate) fn parse_reference(text: &str) -> Result<TimeReference, String> {
    match text {
        "auto" => Ok(TimeReference::Auto),
        "design" => Ok(TimeReference::Design),
        h => match h.parse::<f64>() {
            Ok(h) if h > 0.0 && h.is_finite() => Ok(TimeReference::Step(h)),
            _ => Err("must be auto, design or a time step > 0".to_string()),
        },
    }
}

/// Parses `study convergence --reference P,N`: a degree ≥ 2 and more control points than that.
pub(crate) fn degree_and_points(text: &str) -> Result<(usize, usize), String> {
    text.split_once(',')
        .and_then(|(p, n)| Some((p.trim().parse().ok()?, n.trim().parse().ok()?)))
        .filter(|&(p, n)| p >= 2 && n > p)
        .ok_or_else(|| "must be two whole numbers P,N with P ≥ 2 and N > P".to_string())
}

/// The maps `study stability --maps` draws.
pub(crate) const MAPS: &[&str] = &[
    "material", "bend45", "heating", "release", "coarse", "contact", "meshes", "curved",
];

/// Refuses (exit status 2, naming `argument`) a study run of `design` changed by `variant` whose time steps
/// would need more memory than a design may ([`crate::design::size::MemoryEstimate::with_steps`]: the
/// guard designs get, for the run's steps landing on every breakpoint), or that the variant itself refuses
/// (a step beyond the end). The argument's value is `scale` times the run's step.
fn check_steps(
    design: &Design,
    argument: &str,
    variant: &TimeVariant,
    scale: f64,
) -> anyhow::Result<()> {
    let model = variant
        .of(&design.model)
        .map_err(|e| BadInput(format!("{argument}: {e}")))?;
    let plan = model.planned_steps();
    // In floating point: an absurd count saturates the plan's integers.
    let steps = plan.full as f64 + plan.shortened as f64;
    let counted = StepCount {
        steps,
        field: argument.to_string(),
        what: format!(
            "{} time steps of h = {} s to t = {} s",
            count(steps),
            short(model.time().step),
            short(model.time().end)
        ),
    };
    let estimate = design.memory.with_steps(&counted);
    if let Some(refusal) = over_limit(&estimate) {
        let most = estimate.steps_within_limit();
        return Err(BadInput(format!(
            "{argument}: the run {refusal}: give a step of at least {} s, or an earlier --time (at most {} steps fit)",
            rounded_up(scale * model.time().end / most.max(1.0)),
            count(most.floor())
        ))
        .into());
    }
    Ok(())
}

/// `stentkit study time`: the time-step sweep of `design` per integrator, measured at `time` (default: the
/// design's end time) against `reference` (`auto`, `design` or a step), written into the folder `output` (its
/// files replaced only with `--force`).
pub(crate) fn time(
    design: &Path,
    output: Target<'_>,
    steps: Vec<f64>,
    tolerances: Vec<f64>,
    integrators: Vec<Integrator>,
    reference: TimeReference,
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
    let end = time.unwrap_or(model.time().end);
    // Every run's steps, before any runs: the reference's (the smallest step halved by default) first.
    let smallest = steps.iter().copied().fold(f64::INFINITY, f64::min);
    // A step suggested for --steps must also hold for the reference run when that halves it.
    let scale = if reference == TimeReference::Auto {
        2.0
    } else {
        1.0
    };
    let mut checks: Vec<(String, TimeVariant, f64)> = steps
        .iter()
        .map(|&h| (format!("--steps {}", short(h)), ending(end, Some(h)), scale))
        .collect();
    checks.push(match reference {
        TimeReference::Auto => (
            format!(
                "--steps {} (the reference run's step is half of it)",
                short(smallest)
            ),
            ending(end, Some(smallest / 2.0)),
            2.0,
        ),
        TimeReference::Step(h) => (
            format!("--reference {}", short(h)),
            ending(end, Some(h)),
            1.0,
        ),
        TimeReference::Design => (format!("--time {}", short(end)), ending(end, None), 1.0),
    });
    for (argument, variant, scale) in &checks {
        check_steps(&design, argument, variant, *scale)?;
    }
    let study = TimeStudy {
        integrators,
        steps,
        tolerances,
        time: end,
        reference,
        samples,
    };
    create(output)?;
    let result = time_study(model, &study, progress)?;
    let [csv, by_h_svg, by_time_svg] = TIME_FILES.map(|f| output.join(f));
    write(&csv, &time_csv(&result, &study, model.name()))?;
    let [by_h, by_time] = time_charts(&result, &study, model.name());
    write_svg(&by_h, &by_h_svg)?;
    write_svg(&by_time, &by_time_svg)?;
    println!(
        "{}: errors at t = {} against {}",
        model.name(),
        study.time,
        result.reference
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

/// `stentkit study stability`: the maps named in `maps` (any of material, bend45, heating, release, coarse,
/// contact, meshes, curved), each written as `<map>.csv` and `<map>.svg` as soon as it is done, then `stability.md`, into the
/// folder `output` (its files replaced only with `--force`).
pub(crate) fn stability_maps(output: Target<'_>, maps: &[String]) -> anyhow::Result<()> {
    let Target {
        path: output,
        force,
    } = output;
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
    if !wanted("contact") {
        study.contact.clear();
    }
    if wanted("meshes") {
        study.meshes = crate::study::stability::scenarios::stent_meshes();
    }
    if wanted("curved") {
        study.curved = crate::study::stability::scenarios::curved_meshes();
    }
    create(output)?;
    let summary = stability(
        &study,
        &crate::design::variants::read_varied,
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

/// The variant of a design's run that ends at `end` (with fixed steps `step`, when given).
fn ending(end: f64, step: Option<f64>) -> TimeVariant {
    TimeVariant {
        end: Some(end),
        step,
        ..TimeVariant::default()
    }
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
    crate::io::atomic::write_bytes_atomically(file, text.as_bytes())
        .with_context(|| format!("cannot write {}", file.display()))
}
