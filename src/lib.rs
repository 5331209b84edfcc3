//! # stentkit
//!
//! Design, simulate and export 4D-printed shape-memory-polymer (SMP) devices made of slender rods —
//! cardiovascular stents first — following Ferri & Marino, *Simulating programmable morphing of shape memory
//! polymer beam systems with complex geometry and topology* (equation labels in the docs refer to that paper).
//!
//! ## Layers
//!
//! Dependencies point one way, left to right never imported from the right: `math → geometry → material → model →
//! solver → post → study → io → design → run → bench → sweep → cli`, and no two modules import each other, directly or
//! through others (`scripts/module_cycles.py`, run by CI, checks both from the source). `math`, `geometry`,
//! `material`, `model`, `solver` and `post` are pure: no files, no printing, no serde. `study` writes no file and
//! prints nothing either: it varies built models and returns its charts as descriptions ([`post::chart`]) that `cli`
//! draws through `io`; a design whose geometry it varies is re-built by the design language above it, through
//! [`study::variant::VariedDesign`]. `design` is the YAML design language: it translates a design file into
//! [`model::builder`] calls and sits above `io`, whose centreline files it reads and whose output formats it names;
//! `io`'s writers see a design through `io::output::RunDesign`. `sweep` owns a sweep folder's files and asks Slurm
//! (`sbatch`, `squeue`) about its jobs; the processes that run variants are `cli`'s. `run` is a run as a library
//! call: the recorders of a run folder in one registry, the heartbeat, checkpoints and resume, with the interruption
//! and the console passed in; `cli` parses, prints and maps signals onto it.
//!
//! | module | owns |
//! |---|---|
//! | [`math`] | vocabulary types, knot vectors, B-spline/NURBS basis, curves, SO(3) maps |
//! | [`geometry`] | exact NURBS primitives, analytic curves and their spline fits, rotation-minimising frames, tube surfaces, the union of tubes as one solid |
//! | [`material`] | the constitutive interface and its laws (elastic, Maxwell/WLF), Prony series, WLF shift, section stiffness |
//! | [`model`] | the continuous problem: patches, nodes, conditions, loads, schedules; [`model::builder`], which makes and checks one in Rust, and [`model::stent`], a generated stent and its programme in it; [`model::cycle`], the shape-memory cycle read off the conditions |
//! | [`solver`] | collocation, residual and tangent, Newton, time stepping as an API (step, checkpoint, restore) |
//! | [`post`] | the full device from a (symmetry-reduced) model or state: sampled shapes, mirror copies, tube meshes; recovery measures; chart descriptions |
//! | [`study`] | accuracy against cost: scenarios, exact references, error measures and fits, sweeps over variants of a model |
//! | [`io`] | file formats: writers of STL/OBJ/3MF/VTK, the MCAP recording, the run folder, checkpoints, charts; centreline readers; a run's output settings |
//! | [`design`] | the YAML design language: DTOs, validation with line and column, device families' YAML, `--set` overrides, the translation into [`model::builder`] calls |
//! | [`run`] | a run of a design into its run folder: the recorders ([`run::recorder::RECORDERS`]), summary, heartbeat, checkpoints, resume, the disk check; interruption and console passed in |
//! | [`bench`](mod@bench) | the virtual bench: a design's radial-force test as a run of a crimp, its table and chart |
//! | [`sweep`] | families of variants of a design: swept parameters, the sweep folder and its variants' states, their metrics, `sweep.csv` and charts, the Slurm batch script |
//! | [`cli`] | the `stentkit` command line |
//!
//! ## Conventions (stated once, here and in [`math::so3`])
//!
//! * Units: any consistent system, declared by the design (`SI` = m, N, Pa, s; `mm-N-MPa` = mm, N, MPa, s).
//!   Temperature is always °C.
//! * Rotations: the columns of a rotation `R` are the directors `d1, d2, d3` in global coordinates. `d1` is the
//!   rod axis (the tangent in the reference configuration), `d2, d3` span the cross-section.
//! * Material (body) quantities are capitalised in the paper (`Γ, K, N, M`), spatial ones lower-case.
//!   Rotation increments are material: `R ← R exp(δΘ̃)`.
//! * Strains: `Γ = Rᵀ c,s`, `K = axial(Rᵀ R,s)`, measured from the reference as `Γ_N = Γ − Γ0`, `K_M = K − K0`.
//! * `s` is the arc length of the *reference* centreline; curve parameters `u` live in `[0, 1]`.

// Checks such as `!(x > 0.0)` are deliberate: they reject NaN along with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// The public API is curated: an item is `pub` only where a program using the crate can reach it (the modules
// below and the re-exports after them); everything else is `pub(crate)`. Every public item has a doc comment.
#![warn(missing_docs, unreachable_pub)]

pub mod bench;
pub mod cli;
pub mod design;
pub mod geometry;
pub mod io;
pub mod material;
pub mod math;
pub mod model;
pub mod post;
pub mod run;
pub mod solver;
pub mod study;
pub mod sweep;

// The entry points most programs need, at the crate root: build a model in code or read a design file, and
// simulate it step by step (a run into a run folder, as the command line does, is [`run::run`]).
pub use design::{Design, load_design, parse_design};
pub use model::Model;
pub use model::builder::ModelBuilder;
pub use solver::{Observer, Simulation, SolverError, StepReport};
