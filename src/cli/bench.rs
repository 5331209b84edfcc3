//! `stentkit bench`: the virtual bench's tests as runs of a design (`crate::bench`), on this terminal or, for a
//! sweep's variant (`stentkit sweep --bench`), into its log.

use super::run::{Out, Terminal, command_error, command_line};
use super::signals;
use crate::bench::Test;
use crate::design::{DesignOverrides, SetOverride};
use crate::run::{Console, Folder, Interrupt, RunSettings};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// `stentkit bench radial` and `bench crush`: sets the bench's run up from the design, runs it into its folder
/// (default `runs/<design name>-<test>`), adds the table and chart, and prints the results.
///
/// # Errors
/// The design or the bench refused (exit status 2), the run failed or was interrupted (as `run`'s), a file of
/// the bench not written.
pub(crate) fn bench(
    test: Test,
    design_path: &Path,
    output: Option<PathBuf>,
    force: bool,
    quiet: bool,
    sets: Vec<SetOverride>,
) -> anyhow::Result<()> {
    let started = Instant::now();
    signals::install();
    let overrides = DesignOverrides {
        sets,
        ..DesignOverrides::default()
    };
    let (design, bench) = set_up(test, design_path, &overrides)?;
    let mut console = Terminal::new(quiet, false, Out::default());
    console.say(&announcement(&design, &bench));
    let dir = output.unwrap_or_else(|| {
        Path::new("runs").join(format!("{}-{}", design.model.name(), test.name()))
    });
    let settings = RunSettings {
        quiet,
        started,
        ..RunSettings::new(command_line())
    };
    let (report, lines) = run_bench(
        &design,
        &bench,
        &dir,
        force,
        &settings,
        &signals::INTERRUPT,
        &mut console,
    )?;
    println!("{report}");
    for l in lines {
        println!("{l}");
    }
    Ok(())
}

/// `test` of the design at `design_path` run into the run folder `dir` (replaced with `force`), its messages to
/// `console`, stopped by `interrupt`, started at `started.0` by the command line `started.1`: what a sweep's
/// variant runs with `--bench`. Returns the run's report and the bench's results as printed.
///
/// # Errors
/// As [`bench`].
pub(crate) fn bench_into(
    test: Test,
    design_path: &Path,
    dir: &Path,
    force: bool,
    (started, command_line): (Instant, String),
    console: &mut dyn Console,
    interrupt: &Interrupt,
) -> anyhow::Result<(String, Vec<String>)> {
    let (design, bench) = set_up(test, design_path, &DesignOverrides::default())?;
    console.say(&announcement(&design, &bench));
    let settings = RunSettings {
        quiet: true,
        started,
        ..RunSettings::new(command_line)
    };
    run_bench(&design, &bench, dir, force, &settings, interrupt, console)
}

/// The bench's design and bench of `test` on the design at `design_path` with `overrides`.
fn set_up(
    test: Test,
    design_path: &Path,
    overrides: &DesignOverrides,
) -> anyhow::Result<(crate::design::Design, crate::bench::Bench)> {
    crate::bench::bench_design(test, design_path, overrides).map_err(|e| match e {
        crate::bench::BenchError::Design(d) => anyhow::Error::from(d),
        e => super::BadInput(e.to_string()).into(),
    })
}

/// The line that says what the bench will do.
fn announcement(design: &crate::design::Design, bench: &crate::bench::Bench) -> String {
    let length = design.model.units.length();
    let size = bench.test.size();
    let tool = match bench.test {
        Test::Radial => "the crimper's diameter",
        Test::Crush => "the plates' gap",
    };
    format!(
        "{} bench: {} °C, {tool} from {:.4} to {:.4} {length} and back at {} {length}/s ({} {size}s each way); device length {:.4} {length}, {} of it modelled",
        bench.test.name(),
        crate::math::Short(bench.temperature),
        bench.start_diameter,
        bench.min_diameter,
        crate::math::Short(bench.rate),
        bench.diameters,
        bench.length,
        if bench.copies > 1.0 {
            format!("1/{}", bench.copies)
        } else {
            "all".to_string()
        }
    )
}

/// Runs the bench's design into `dir` and adds the bench's outputs: the run's report and the bench's results
/// as printed. A run refused before it started wrote nothing (the folder, an earlier run's, is left as it is);
/// a run that stopped early still gives the table up to where it got, its results said before its error.
fn run_bench(
    design: &crate::design::Design,
    bench: &crate::bench::Bench,
    dir: &Path,
    force: bool,
    settings: &RunSettings,
    interrupt: &Interrupt,
    console: &mut dyn Console,
) -> anyhow::Result<(String, Vec<String>)> {
    let completed = crate::run::run(
        design,
        Folder::New {
            dir: dir.to_path_buf(),
            force,
        },
        settings,
        interrupt,
        console,
    );
    if let Err(e @ crate::run::RunError::Refused(_)) = completed {
        return Err(command_error(e));
    }
    let lines = crate::bench::write_outputs(dir, bench, &design.model);
    match (completed, lines) {
        (Ok(c), Ok(lines)) => Ok((c.report, lines)),
        (Err(e), lines) => {
            if let Ok(lines) = lines {
                for l in lines {
                    console.say(&l);
                }
            }
            Err(command_error(e))
        }
        (Ok(_), Err(e)) => Err(e.into()),
    }
}
