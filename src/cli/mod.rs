//! The `stentkit` command line: `check` (validate a design and describe it) and `mesh` (write the reference
//! shape as a closed tube surface). The only module that uses `anyhow` and prints.

pub mod check;
pub mod mesh;
pub mod run;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// stentkit — design, simulate and export 4D-printed shape-memory-polymer rod devices.
#[derive(Debug, Parser)]
#[command(name = "stentkit", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Validate a design and print its patches, nodes, collocation points, unknowns, time steps, geometry fit
    /// error and warnings.
    ///
    /// Example: stentkit check designs/circular_arch.yaml
    Check {
        /// The design file (YAML).
        design: PathBuf,
    },
    /// Simulate a design and write the run folder (history.csv, …).
    ///
    /// Example: stentkit run designs/bend45.yaml -o runs/bend45
    Run {
        /// The design file (YAML).
        design: PathBuf,
        /// Run folder (default: runs/<design name>).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Overwrite a non-empty run folder.
        #[arg(long)]
        force: bool,
        /// No progress output.
        #[arg(short, long)]
        quiet: bool,
    },
    /// Write the reference (permanent) shape as a closed tube surface: binary STL or OBJ by extension.
    ///
    /// Example: stentkit mesh designs/circular_arch.yaml -o arch.stl
    Mesh {
        /// The design file (YAML).
        design: PathBuf,
        /// Output file, `.stl` or `.obj`.
        #[arg(short, long)]
        output: PathBuf,
        /// Segments around each tube.
        #[arg(long, default_value_t = 16)]
        segments: usize,
        /// Samples along each patch per control point.
        #[arg(long, default_value_t = 4)]
        samples: usize,
    },
}

/// Runs the command line and returns the process exit code.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Check { design } => check::run(&design),
        Command::Run {
            design,
            output,
            force,
            quiet,
        } => run::run(&design, output, force, quiet),
        Command::Mesh {
            design,
            output,
            segments,
            samples,
        } => mesh::run(&design, &output, segments, samples),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
