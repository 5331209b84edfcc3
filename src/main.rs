//! The `stentkit` command line; see [`stentkit::cli`].

fn main() -> std::process::ExitCode {
    stentkit::cli::main()
}
