//! `stentkit tune`: the design tuned by the library ([`crate::study::tune`]), each trial printed as a table row
//! as it finishes, the choice summarised, and the tuned design written with `-o`
//! ([`crate::design::tuned_text`]).

use crate::design::{
    DesignOverrides, SetOverride, TunedChoice, load_design_with, parse_design, tuned_text,
};
use crate::math::Short;
use crate::study::tune::{Trial, TuneSettings, Tuned, tune};
use anyhow::Context;
use std::io::Write as _;
use std::path::Path;

/// Tunes `design` to `tolerance`, trying `degrees` and at most `max_points` points per patch; writes the tuned
/// design to `output` when given (over an existing file only with `--force`). `sets` are `--set` overrides of
/// the design.
pub(crate) fn run(
    design_path: &Path,
    tolerance: f64,
    output: Option<super::Target<'_>>,
    degrees: Vec<usize>,
    max_points: usize,
    sets: Vec<SetOverride>,
) -> anyhow::Result<()> {
    if let Some(out) = output {
        super::refuse_existing([out.path], out.force)?;
    }
    let design = load_design_with(design_path, &DesignOverrides::sets(sets))?;
    let settings = TuneSettings {
        tolerance,
        degrees,
        max_points,
    };
    println!(
        "tuning {} to {} (results: displacements over the largest, Δr over its largest, recovery ratios absolute)",
        design.model.name(),
        Short(tolerance)
    );
    println!(
        "{:<7} {:>2} {:>4} {:<14} {:>6}  {:<26} {:>10}  {:<30} {:>8} {:>6} {:>6}  verdict",
        "stage",
        "p",
        "n",
        "stepping",
        "to t",
        "against",
        "difference",
        "largest at",
        "wall s",
        "steps",
        "its"
    );
    let tuned = tune(&design, &settings, print_trial)
        .with_context(|| format!("tune {} --tol {}", design_path.display(), Short(tolerance)))?;
    let (wall, steps, iterations) = tuned.cost;
    println!("\nchosen: {}", choice(&tuned));
    println!(
        "expected wall time {wall:.2} s ({steps} steps, {iterations} Newton iterations) against {:.2} s for the \
         design's own settings ({:.1}× less)",
        tuned.design_wall,
        tuned.design_wall / wall
    );
    if let Some(out) = output {
        write_tuned(design_path, &design.source, &tuned, tolerance, out)?;
    }
    Ok(())
}

/// What was chosen and its estimated error, in words.
fn choice(tuned: &Tuned) -> String {
    format!(
        "p = {}, n = {}, time.tolerance = {}: estimated error {:.1e} ({} at t = {}) against {}",
        tuned.degree,
        tuned.points,
        Short(tuned.time_tolerance),
        tuned.error.value,
        tuned.error.quantity,
        Short(tuned.error.time),
        tuned.reference
    )
}

fn print_trial(t: &Trial) {
    let (difference, at) = match (&t.difference, &t.failure) {
        (_, Some(failure)) => ("failed".to_string(), first_words(failure)),
        (Some(d), None) => (
            format!("{:.2e}", d.value),
            format!("{} @ {}", d.quantity, Short(d.time)),
        ),
        (None, None) => (String::new(), String::new()),
    };
    let (wall, steps, its) = t
        .cost
        .map_or((String::new(), String::new(), String::new()), |c| {
            (format!("{:.2}", c.0), c.1.to_string(), c.2.to_string())
        });
    println!(
        "{:<7} {:>2} {:>4} {:<14} {:>6}  {:<26} {:>10}  {:<30} {:>8} {:>6} {:>6}  {}",
        t.stage.to_string(),
        t.degree,
        t.points,
        t.stepping.to_string(),
        Short(t.horizon).to_string(),
        t.against,
        difference,
        at,
        wall,
        steps,
        its,
        if t.accepted { "ok" } else { "no" }
    );
    let _ = std::io::stdout().flush();
}

/// The start of a failure's text, for a table cell (the run and the first clause of its reason).
fn first_words(text: &str) -> String {
    const MOST: usize = 60;
    let clause = text.split(" (").next().unwrap_or(text);
    match clause.char_indices().nth(MOST) {
        Some((i, _)) => format!("{}…", &clause[..i]),
        None => clause.to_string(),
    }
}

/// Writes the tuned design, checked to read back as the tuned model: a new file (with `--force`, written
/// atomically over what is there).
fn write_tuned(
    design_path: &Path,
    source: &str,
    tuned: &Tuned,
    tolerance: f64,
    target: super::Target<'_>,
) -> anyhow::Result<()> {
    let out = target.path;
    let (wall, ..) = tuned.cost;
    let choice = TunedChoice {
        degree: tuned.degree,
        points: tuned.points,
        time_tolerance: tuned.time_tolerance,
        header: format!(
            "Tuned by `stentkit tune {} --tol {}` (stentkit {}):\n{},\n\
             over the whole schedule (displacements over the largest one, Δr over its largest, recovery ratios\n\
             absolute). Expected wall time {wall:.2} s against {:.2} s for the source's settings ({:.1}× less, on\n\
             the machine that tuned it).",
            design_path.display(),
            Short(tolerance),
            env!("CARGO_PKG_VERSION"),
            choice(tuned),
            tuned.design_wall,
            tuned.design_wall / wall
        ),
    };
    let text = tuned_text(source, &choice)
        .with_context(|| format!("writing the tuned design of {}", design_path.display()))?;
    // The written text must be the model that was tuned.
    let written = parse_design(&text, out).with_context(|| {
        format!(
            "the tuned text of {} does not read back",
            design_path.display()
        )
    })?;
    let overrides = DesignOverrides {
        degree: Some(tuned.degree),
        points: Some(tuned.points),
        time_tolerance: Some(tuned.time_tolerance),
        ..DesignOverrides::default()
    };
    let expected = crate::design::parse_design_with(source, design_path, &overrides)?;
    anyhow::ensure!(
        written.model == expected.model,
        "the tuned text of {} does not give the tuned model (please report this)",
        design_path.display()
    );
    if target.force {
        crate::io::atomic::write_bytes_atomically(out, text.as_bytes())
    } else {
        // `create_new`: a file that appeared since the check is not replaced either.
        std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(out)
            .and_then(|mut f| f.write_all(text.as_bytes()))
    }
    .with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}
