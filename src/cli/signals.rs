//! The signals that end a run: SIGINT (Ctrl-C), SIGTERM (Slurm at the time limit or on `scancel`, `timeout`,
//! `docker stop`, `kill`) and SIGHUP (a closed terminal or dropped SSH session) are handled alike.
//!
//! - The first asks the run to stop: the solver abandons the step in progress at its next Newton iteration or
//!   step cut, rolls back to the last converged state, and every output is finished there.
//! - The second says, in one line, that the files are being finished and the run then exits: the expensive
//!   part of finishing (the final snapshot's tube meshes, in the files and the recording) is skipped, the
//!   recording is closed, the charts drawn and `summary.json` written.
//! - A third quits at once (exit status 130); `stentkit repair DIR` then finishes the folder.
//!
//! A dedicated thread receives the signals (signal-hook's iterator), so nothing here runs in a signal handler;
//! it passes each on as a request to [`INTERRUPT`], the [`crate::run::Interrupt`] a run of this process is
//! given. SIGKILL cannot be caught: what it leaves is made useful by the periodic summary and chunk flushes
//! ([`crate::run`]) and by `stentkit repair`.

use crate::run::Interrupt;
use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use std::sync::Once;

/// The signals received, as requests to stop: what `stentkit run` and the sweep's workers are given.
pub(crate) static INTERRUPT: Interrupt = Interrupt::new();
static INSTALL: Once = Once::new();

/// What the first and second signal make the process do, said when they arrive.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Messages {
    /// After the first signal.
    pub first: &'static str,
    /// After the second.
    pub second: &'static str,
}

/// A run's messages (module docs).
pub(crate) const RUN: Messages = Messages {
    first: "stopping at the next Newton iteration and finishing every file (send it again to skip the final snapshot)",
    second: "finishing run.mcap and summary.json, then exiting (a third signal quits at once)",
};

/// A sweep's messages (`cli::sweep`).
pub(crate) const SWEEP: Messages = Messages {
    first: "no new variant is prepared or started; the running ones finish their files and stop (the same command continues the sweep)",
    second: "still waiting for the running variants (a third signal quits the sweep and them; the same command continues them)",
};

/// Starts the thread that receives SIGINT, SIGTERM and SIGHUP for the rest of the process, with a run's
/// messages. Later calls do nothing. If the handlers cannot be installed the default actions stay (the process
/// is killed) and a warning says so.
pub(crate) fn install() {
    install_with(RUN);
}

/// [`install`] with `messages`.
pub(crate) fn install_with(messages: Messages) {
    INSTALL.call_once(|| {
        let mut signals = match signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("warning: cannot handle SIGINT/SIGTERM/SIGHUP ({e}); a signal will kill the run");
                return;
            }
        };
        let spawned = std::thread::Builder::new()
            .name("stentkit-signals".into())
            .spawn(move || {
                let mut n = 0;
                for signal in signals.forever() {
                    let name = name(signal);
                    INTERRUPT.request(name);
                    n += 1;
                    match n {
                        1 => eprintln!("\n{name}: {}", messages.first),
                        2 => eprintln!("{name} again: {}", messages.second),
                        _ => {
                            eprintln!(
                                "{name} a third time: quitting now; `stentkit repair RUN_DIR` finishes the run folder"
                            );
                            std::process::exit(130);
                        }
                    }
                }
            });
        if let Err(e) = spawned {
            eprintln!("warning: cannot start the signal thread ({e}); a signal will kill the run");
        }
    });
}

/// Whether a run was asked to stop (any handled signal received).
pub(crate) fn stop_requested() -> bool {
    INTERRUPT.requested()
}

/// The name of the first signal received (`SIGINT`, `SIGTERM`, `SIGHUP`), if any.
pub(crate) fn first() -> Option<&'static str> {
    INTERRUPT.cause()
}

fn name(signal: i32) -> &'static str {
    match signal {
        SIGINT => "SIGINT",
        SIGTERM => "SIGTERM",
        SIGHUP => "SIGHUP",
        _ => "signal",
    }
}
