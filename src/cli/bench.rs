//! `stentkit bench`: the virtual bench's tests as runs of a design (`crate::bench`), on this terminal.

use super::run::{Out, Terminal, command_error, command_line};
use super::signals;
use crate::design::{DesignOverrides, SetOverride};
use crate::run::{Folder, RunSettings};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// `stentkit bench radial` and `bench crush`: sets the bench's run up from the design, runs it into its folder
/// (default `runs/<design name>-<test>`), adds the table and chart, and prints the results.
///
/// # Errors
/// The design or the bench refused (exit status 2), the run failed or was interrupted (as `run`'s), a file of
/// the bench not written.
pub(crate) fn bench(
    test: crate::bench::Test,
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
    let (design, bench) =
        crate::bench::bench_design(test, design_path, &overrides).map_err(|e| match e {
            crate::bench::BenchError::Design(d) => anyhow::Error::from(d),
            e => super::BadInput(e.to_string()).into(),
        })?;
    let mut console = Terminal::new(quiet, false, Out::default());
    let length = design.model.units.length();
    let size = test.size();
    let tool = match test {
        crate::bench::Test::Radial => "the crimper's diameter",
        crate::bench::Test::Crush => "the plates' gap",
    };
    eprintln!(
        "{} bench: {} °C, {tool} from {:.4} to {:.4} {length} and back at {} {length}/s ({} {size}s each way); device length {:.4} {length}, {} of it modelled",
        test.name(),
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
    );
    let dir = output.unwrap_or_else(|| {
        Path::new("runs").join(format!("{}-{}", design.model.name(), test.name()))
    });
    let settings = RunSettings {
        quiet,
        started,
        ..RunSettings::new(command_line())
    };
    let completed = crate::run::run(
        &design,
        Folder::New {
            dir: dir.clone(),
            force,
        },
        &settings,
        &signals::INTERRUPT,
        &mut console,
    );
    // A run refused before it started wrote nothing, and the folder (an earlier run's) is left as it is; a run
    // that stopped early still gives the table up to where it got.
    if let Err(e @ crate::run::RunError::Refused(_)) = completed {
        return Err(command_error(e));
    }
    let lines = crate::bench::write_outputs(&dir, &bench, &design.model);
    match (completed, lines) {
        (Ok(c), Ok(lines)) => {
            println!("{}", c.report);
            for l in lines {
                println!("{l}");
            }
            Ok(())
        }
        (Err(e), lines) => {
            if let Ok(lines) = lines {
                for l in lines {
                    eprintln!("{l}");
                }
            }
            Err(command_error(e))
        }
        (Ok(_), Err(e)) => Err(e.into()),
    }
}
