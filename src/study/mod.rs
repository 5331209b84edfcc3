//! Studies: accuracy against cost, measured by running variants of a model (DESIGN §6).
//!
//! This module owns the science above the solver — the scenarios, the exact references they are measured
//! against, the error measure and fits, and the sweeps — and presents each study's result as CSV text, charts
//! ([`crate::post::chart::LineChart`]) and prose. It writes no file and prints nothing: `stentkit study`
//! ([`crate::cli`]) parses the arguments, calls a study, writes what it returns and prints the progress lines it
//! is handed.
//!
//! * [`fit`]: the relative error of a sampled displacement field and the least-squares slope of a log–log
//!   relation (observed orders, growth exponents).
//! * [`variant`]: the variants of a model a study runs — time stepping and integrator changed on the built
//!   model, geometry (`p`, `n`, crowns) re-built by the design ([`variant::VariedDesign`]).
//! * [`sample`]: one run of a model sampled on a grid of points per patch.
//! * `charts`: the pair of log–log charts error-against-parameter and error-against-wall-time.
//! * `convergence`: error against `p` and `n` (the paper's Fig. conv_circ) and work–precision.
//! * `time`: error against the time step per internal-variable integrator, observed orders.
//! * [`tune`]: the cheapest `p`, `n` and time tolerance whose results stay within a tolerance of a finer run.
//! * [`stability`]: where each integrator rings (one Maxwell branch against its exact solution) and where
//!   Newton needs cuts or fails (load steps, heating rate, release snap).
//!
//! # Layer
//!
//! `study` sits above `post` and below `io`: `… → solver → post → study → io → design → …`. It takes a built
//! [`crate::model::Model`], the [`crate::solver::Simulation`] that runs it and the material's point integrators
//! from the layers below, and returns its charts as descriptions ([`crate::post::chart`]) that `cli` draws
//! through `io`. A design whose geometry a study varies (the mesh `p`, `n` or a stent's crowns) is re-built by
//! the design language above it, seen through [`variant::VariedDesign`]; the stability maps read their
//! embedded designs through a [`stability::ReadDesign`] their caller hands in.

pub(crate) mod charts;
pub(crate) mod convergence;
pub mod fit;
pub mod sample;
pub mod stability;
pub(crate) mod time;
pub mod tune;
pub mod variant;

pub use fit::{fit_log_slope, relative_error};

use crate::material::MaterialError;
use crate::math::Real;
use crate::model::ScheduleError;
use crate::model::builder::BuildError;
use crate::solver::SolverError;

/// Why a study could not be carried out. A run that fails inside a sweep meant to find failures (a time-step
/// or stability study) is a result, not an error: it is recorded in the study's rows.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The design, or a variant of it a study builds, was refused (a [`crate::design::DesignError`]: the design
    /// language sits above this layer).
    #[error("{0}")]
    Design(#[source] Box<dyn std::error::Error + Send + Sync>),
    /// A run failed where the study needs it to succeed (a reference run, a convergence run).
    #[error(transparent)]
    Solver(#[from] SolverError),
    /// A material scenario's constants or its integration were refused.
    #[error(transparent)]
    Material(#[from] MaterialError),
    /// A schedule a study sets (a temperature history) was refused.
    #[error(transparent)]
    Schedule(#[from] ScheduleError),
    /// Settings a study gives a model (its time stepping, its Newton settings) were refused by the builder's
    /// checks ([`crate::model::Model::with_settings`]).
    #[error(transparent)]
    Model(#[from] BuildError),
    /// A study setting is out of range.
    #[error("{setting} must be {expected}, got {value}")]
    InvalidSetting {
        /// The setting (`time step h`, `h/τ`, `load steps`, …).
        setting: &'static str,
        /// The rejected value.
        value: Real,
        /// What it must be.
        expected: &'static str,
    },
    /// A variant's time step exceeds its end time.
    #[error("the time step {step} exceeds the end time {end}")]
    StepBeyondEnd {
        /// The step \[time\].
        step: Real,
        /// The end time \[time\].
        end: Real,
    },
    /// A variant the solver cannot run as asked (error control with an update that has no estimate).
    #[error("{0}")]
    Refused(String),
    /// One run of a study failed: which one, and why.
    #[error("{run}")]
    Run {
        /// The run, in words (`reference run`, `run with p = 4, n = 12`).
        run: String,
        /// Why it failed.
        #[source]
        source: Box<StudyError>,
    },
}

impl StudyError {
    /// `self` as the failure of the run described by `run`.
    pub fn in_run(self, run: impl Into<String>) -> Self {
        StudyError::Run {
            run: run.into(),
            source: Box::new(self),
        }
    }
}

/// An error's message followed by its causes, joined by `: `, each said once (a cause whose text is already
/// there, as when an error prints its source and also returns it, is left out): a failed run's reason in a
/// study's CSV and prose.
pub fn error_chain(error: &(dyn std::error::Error + 'static)) -> String {
    let mut text = String::new();
    let mut cause = Some(error);
    while let Some(e) = cause {
        let s = e.to_string();
        if !text.contains(&s) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&s);
        }
        cause = e.source();
    }
    text
}

/// `value` when it is positive and finite, else the setting's error.
pub(crate) fn positive(setting: &'static str, value: Real) -> Result<Real, StudyError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(StudyError::InvalidSetting {
            setting,
            value,
            expected: "positive and finite",
        })
    }
}
