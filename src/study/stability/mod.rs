//! The stability study: where each method fails and what the program does there (DESIGN §4, §6;
//! `stentkit study stability`).
//!
//! Seven maps, each a CSV, an SVG chart and a paragraph of `stability.md` ([`MapReport`]):
//!
//! * **material** ([`material`]) — one Maxwell branch (`E∞ = E₁ = 1`) after a unit strain jump, for `h/τ` from
//!   `1e-2` to `1e4`, with the rod's own integrators, held at constant temperature or held while cooling, against
//!   the exact branch stress: the largest deviation (the *amplitude*, in units of `E₁ Δε`) and the sign changes
//!   of the computed branch stress (ringing).
//! * **bend45** — the elastic 45° bend (designs/bend45.yaml) with 1 to 20 load steps: whether Newton converges
//!   without cuts, cuts, failed attempts and iterations.
//! * **heating** — the circular arch (designs/circular_arch.yaml; loads and heating 31.5 → 90 °C together):
//!   fewer steps at the design's rate, and faster heating at a fixed step; temperature change per step against
//!   iterations and cuts.
//! * **release** — the release snap of a two-crown straight stent (designs/straight_stent.yaml with 2 crowns,
//!   run to 2 s, released at 1.75 s): step size and release-ramp length against cuts and iterations.
//! * **coarse** — the elastic 45° bend and roll-up on coarse and fine meshes, by load steps and by arc length
//!   (issue 18): where load steps fail, whether the coarse model's own path has a limit point there (the largest
//!   load factor before it falls), and how far its end state is from the fine model's.
//! * **contact** ([`contact`]) — one crown of the straight stent crimped by a rigid cylinder, held and released
//!   (issue 33), at several time steps and contact penalties: points entering contact while the crimper closes
//!   and leaving it while it opens; failed attempts and the smallest step in each phase.
//! * **meshes** — the straight stent's whole cycle at p ∈ {4, 5, 6}, n ∈ [14, 40] with each rotation field
//!   (issue 36): which meshes finish and where the others fail (about 20 minutes: not among the default maps
//!   of `stentkit study stability`, and empty in [`StabilityStudy::default`]).
//! * **curved** — the same for the curved stent at p ∈ {5, 6}, n ∈ [30, 81] (hours on two cores: not among the
//!   default maps either).
//!
//! bend45, heating, release, coarse, meshes and curved are [`scenarios`] run through [`newton::newton_run`], which records what
//! the solver did; contact is built in code ([`contact::crimped_crown`]) and run the same way.

pub mod contact;
pub mod material;
pub mod newton;
pub mod scenarios;

use super::StudyError;
use super::variant::VariedDesign;
use crate::material::Integrator;
use crate::math::Real;
use crate::post::chart::LineChart;
use std::path::Path;

/// The three integrators, in the order of the maps.
pub const INTEGRATORS: [Integrator; 3] = [
    Integrator::Trapezoidal,
    Integrator::BackwardEuler,
    Integrator::Exponential,
];

/// One finished map: its files (`<name>.csv`, `<name>.svg`) and its paragraph of `stability.md`.
#[derive(Debug, Clone)]
pub struct MapReport {
    /// File stem (`material`, `bend45`, `heating`, `release`).
    pub name: &'static str,
    /// The map as CSV (with a comment header).
    pub csv: String,
    /// The map's chart.
    pub chart: LineChart,
    /// The map's paragraph of `stability.md` (Markdown).
    pub summary: String,
}

/// Settings of the stability study.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilityStudy {
    /// `h/τ` of the material map.
    pub ratios: Vec<Real>,
    /// Load steps of the 45° bend.
    pub load_steps: Vec<usize>,
    /// `(heating duration [s], h [s])` of the arch.
    pub heating: Vec<(Real, Real)>,
    /// The runs of the two-crown stent's release.
    pub release: Vec<scenarios::ReleaseCase>,
    /// `(design, p, n)` of the coarse-model map.
    pub coarse: Vec<(scenarios::CoarseDesign, usize, usize)>,
    /// The runs of the crimped crown.
    pub contact: Vec<contact::ContactCase>,
    /// The runs of the meshes map ([`scenarios::stent_meshes`] for the whole map; empty by default).
    pub meshes: Vec<scenarios::MeshCase>,
    /// The runs of the curved stent's meshes map ([`scenarios::curved_meshes`] for the whole map; empty by
    /// default).
    pub curved: Vec<scenarios::MeshCase>,
}

impl Default for StabilityStudy {
    /// The default maps (8 s together on the development machine, 2026-11-28).
    fn default() -> Self {
        Self {
            ratios: (-4..=8).map(|k| 10f64.powf(k as Real / 2.0)).collect(),
            load_steps: vec![1, 2, 3, 4, 5, 10, 20],
            heating: vec![
                (5.0, 5.0),
                (5.0, 2.5),
                (5.0, 1.0),
                (5.0, 0.5),
                (5.0, 0.25),
                (5.0, 0.1),
                (2.0, 0.1),
                (0.5, 0.1),
                (0.1, 0.1),
            ],
            release: {
                let plain = scenarios::ReleaseCase::plain;
                let mut cases: Vec<scenarios::ReleaseCase> = [
                    (0.25, 0.001, 20),
                    (0.25, 0.25, 20),
                    (0.1, 0.001, 20),
                    (0.1, 0.1, 20),
                    (0.05, 0.05, 20),
                    (0.05, 0.2, 20),
                    (0.02, 0.001, 20),
                    (0.02, 0.02, 20),
                    (0.02, 0.2, 20),
                    (0.01, 0.001, 20),
                    (0.01, 0.01, 20),
                    (0.01, 0.2, 20),
                ]
                .into_iter()
                .map(|(h, ramp, n)| plain(h, ramp, n))
                .collect();
                // The coarse stent whose release folds, and a hot release, each without and with stabilisation.
                for case in [
                    plain(0.01, 0.01, 14),
                    plain(0.01, 0.3, 14),
                    plain(0.01, 0.01, 20).hot(),
                ] {
                    cases.extend([case, case.stabilised()]);
                }
                cases
            },
            coarse: {
                use scenarios::CoarseDesign::{Bend45, Rollup};
                vec![
                    (Bend45, 4, 10),
                    (Bend45, 6, 20),
                    (Rollup, 4, 8),
                    (Rollup, 4, 10),
                    (Rollup, 6, 8),
                    (Rollup, 6, 30),
                ]
            },
            // The stiff penalty at the shortest step is left out: it crawls through the opening at 2.4e-5 s
            // steps for minutes before it fails, which the longer steps show in under a second.
            contact: [
                (0.1, 0.1),
                (0.1, 1.0),
                (0.1, 10.0),
                (0.05, 0.1),
                (0.05, 1.0),
                (0.05, 10.0),
                (0.025, 0.1),
                (0.025, 1.0),
            ]
            .into_iter()
            .map(|(h, penalty)| contact::ContactCase { h, penalty })
            .collect(),
            meshes: Vec::new(),
            curved: Vec::new(),
        }
    }
}

/// Reads a design's text (named by the path in errors and as its default name) into a design a study can vary:
/// the design language's parser ([`crate::design::variants::read_varied`]), handed in by the caller because
/// `study` sits below `design`.
pub type ReadDesign = dyn Fn(&str, &Path) -> Result<Box<dyn VariedDesign>, StudyError>;

/// Runs every map of `study` whose list is not empty, in the order material, bend45, heating, release, coarse,
/// contact, meshes, curved. Each finished map is handed to `done` (which writes it), so the maps finished before a failure are
/// kept; the text of `stability.md` (a title and every map's paragraph) is returned. `read` reads the embedded
/// designs the maps vary; `progress` is told about each run.
///
/// # Errors
/// The first error of a map (an out-of-range setting, a refused design) or of `done`.
pub fn stability<E: From<StudyError>>(
    study: &StabilityStudy,
    read: &ReadDesign,
    mut done: impl FnMut(&MapReport) -> Result<(), E>,
    mut progress: impl FnMut(&str),
) -> Result<String, E> {
    let mut summary = String::from(
        "# Stability map\n\nWhere each method fails and what stentkit does there (`stentkit study stability`).\n\n",
    );
    if !study.ratios.is_empty() {
        let rows = material::material_map(&study.ratios)?;
        let report = MapReport {
            name: "material",
            csv: material::material_csv(&rows),
            chart: material::material_chart(&rows),
            summary: material::material_summary(&rows),
        };
        done(&report)?;
        summary.push_str(&report.summary);
        progress("material map done");
    }
    if !study.load_steps.is_empty() {
        let map = scenarios::bend45_map(&study.load_steps, read, &mut progress)?;
        let report = scenarios::bend45_report(&map);
        done(&report)?;
        summary.push_str(&report.summary);
    }
    if !study.heating.is_empty() {
        let map = scenarios::heating_map(&study.heating, read, &mut progress)?;
        let report = scenarios::heating_report(&map);
        done(&report)?;
        summary.push_str(&report.summary);
    }
    if !study.release.is_empty() {
        let map = scenarios::release_map(&study.release, read, &mut progress)?;
        let report = scenarios::release_report(&map);
        done(&report)?;
        summary.push_str(&report.summary);
    }
    if !study.coarse.is_empty() {
        let map = scenarios::coarse_map(&study.coarse, read, &mut progress)?;
        let report = scenarios::coarse_report(&map);
        done(&report)?;
        summary.push_str(&report.summary);
    }
    if !study.contact.is_empty() {
        let map = contact::contact_map(&study.contact, &mut progress)?;
        let report = contact::contact_report(&map);
        done(&report)?;
        summary.push_str(&report.summary);
    }
    for (stent, cases) in [
        (scenarios::MeshStent::Straight, &study.meshes),
        (scenarios::MeshStent::Curved, &study.curved),
    ] {
        if cases.is_empty() {
            continue;
        }
        let map = scenarios::meshes_map(stent, cases, None, read, &mut progress)?;
        let report = scenarios::meshes_report(stent, &map);
        done(&report)?;
        summary.push_str(&report.summary);
    }
    Ok(summary)
}
