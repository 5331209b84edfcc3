//! The mechanics measures of a state as a whole device: how far a programmed device has recovered its
//! permanent shape (paper §4.3; DESIGN §7), whether a run that ended heated and released should be warned
//! about for not recovering, and the largest node displacement. Computation only: `io` records these, `study`
//! and `sweep` judge by them.

use crate::math::quote::quoted;
use crate::math::{Real, Vec3};
use crate::model::ProbeLocation;
use crate::solver::Simulation;

/// Recovery measures of a programme (DESIGN §7; paper §4.3).
#[derive(Debug, Clone, PartialEq)]
pub struct Recovery {
    /// Mean over the full device of `‖η_l‖ / ‖η_temp,l‖` over the driven nodes: 1 at the temporary shape, 0
    /// at the permanent one.
    pub ratio_mean: Real,
    /// Its largest value over the driven nodes.
    pub ratio_max: Real,
    /// Mean radial contraction of the driven nodes \[length\], positive towards the axis (the paper's Δr),
    /// for a radial-contraction programme.
    pub delta_r: Option<Real>,
    /// For a device of several materials, the mean ratio over the driven nodes of each material region, in the
    /// order of [`crate::model::Model::material_regions`] (empty for one material).
    pub by_material: Vec<Real>,
}

/// The recovery measures of the current state, for a model with a programme.
pub fn recovery(sim: &Simulation<'_>) -> Option<Recovery> {
    let model = sim.model();
    let programme = model.programme.as_ref()?;
    let u: Vec<Vec3> = programme
        .nodes
        .iter()
        .map(|d| sim.probe_displacement(&ProbeLocation::Node(d.node)))
        .collect();
    Some(Recovery {
        ratio_mean: programme.target_fraction(&u),
        ratio_max: programme.target_fraction_max(&u),
        delta_r: programme
            .is_radial()
            .then(|| -programme.mean_radial_displacement(&u)),
        by_material: model
            .material_regions()
            .into_iter()
            .map(|m| programme.target_fraction_where(&u, |k| model.node_touches_material(k, m)))
            .collect(),
    })
}

/// The mean recovery ratio above which a run that ends released and heated above every material's glass
/// transition is warned about ([`recovery_warning`]). The designs end below it — the straight stent at 0.009,
/// the curved one at 0.002, the aorta stent at 0.005 and tapered at 0.083 (its wide crowns, compacted most, are
/// still recovering at 4 s), the sequential stent below 0.02 (measured) — while a device that did not recover
/// ends far above (the stabilised 3-crown stent on the aorta at 0.36 mean and 1.46 at worst, measured
/// here; a stent heated just past Tg for 0.05 s at 0.80). A tenth of the programme left is what a designer
/// calls "not recovered" (the sweeps' time to 90 % recovery uses the same 0.1).
pub const RECOVERY_WARNING_RATIO: Real = 0.1;

/// What a run that ends with its device free and heated — past its cycle's release, every material above its
/// Tg (every point's temperature, with a temperature field) — must say when its mean recovery ratio is above
/// [`RECOVERY_WARNING_RATIO`]: heated that far, the device was expected to recover, and a result that did not
/// (too short a heating, a damping that held it, a wire caught) is not to be read as a recovered device.
/// `None` for a model without a programme, a device still held or not heated past every Tg, or a good
/// recovery. For the end of a completed run (its current state).
pub fn recovery_warning(sim: &Simulation<'_>) -> Option<String> {
    let model = sim.model();
    let t = sim.time();
    let released = model.cycle()?.released;
    if t < released {
        return None;
    }
    let tg = model
        .materials()
        .iter()
        .filter_map(|law| crate::material::ConstitutiveLaw::temperature_shift(law).map(|w| w.tg()))
        .fold(Real::NEG_INFINITY, Real::max);
    let coldest = sim.temperature_extremes(t).map_or_else(
        || model.temperature().value(sim.schedule_time()),
        |(lo, _)| lo,
    );
    if coldest < tg {
        return None;
    }
    let r = recovery(sim)?;
    if r.ratio_mean <= RECOVERY_WARNING_RATIO {
        return None;
    }
    let heated = if tg.is_finite() {
        format!(
            "{} °C, above the glass transition of every material (Tg up to {} °C)",
            crate::math::Short(coldest),
            crate::math::Short(tg)
        )
    } else {
        format!("{} °C", crate::math::Short(coldest))
    };
    let beyond = if r.ratio_max > 1.0 {
        "; above 1, some nodes ended further from the permanent shape than the temporary shape took them"
    } else {
        ""
    };
    let damped = sim.stabilisation().damped_steps;
    // Obstacles that press on the device at the end (a vessel it opened against) hold it short of its
    // permanent shape: that is the result, not a failure to recover.
    let held: Vec<String> = match (sim.contact(), &model.contact) {
        (Some(report), Some(contact)) => report
            .obstacles
            .iter()
            .zip(&contact.obstacles)
            .filter(|(r, _)| r.points > 0)
            .map(|(r, o)| format!("{} at {} points", quoted(&o.name), r.points))
            .collect(),
        _ => Vec::new(),
    };
    let cause = if !held.is_empty() {
        format!(
            "obstacles press on it at the end ({}): a device held by a wall stops short of its permanent shape, and this is its recovery as they hold it (history.csv's contact columns give their forces)",
            held.join(", ")
        )
    } else if damped > 0 {
        format!(
            "this run was damped in {damped} steps (`solver.stabilisation`), and damping can hold a device away from equilibrium: see the stabilisation's numbers in summary.json and the final snapshot"
        )
    } else {
        "if it is still recovering (history.csv's `recovery_ratio_mean`), heat it for longer; otherwise look at the final snapshot for a wire caught or folded".to_string()
    };
    Some(format!(
        "the run ended at t = {} s at {heated}, released, yet the device has not recovered its permanent shape: its recovery ratio is {:.3} (mean over the driven nodes; largest {:.3}; 1 is the temporary shape, 0 the permanent one), above {RECOVERY_WARNING_RATIO}{beyond}; {cause}",
        crate::math::Short(t),
        r.ratio_mean,
        r.ratio_max
    ))
}

/// The largest displacement of any node from the reference shape \[length\] (0 for a model without nodes).
pub fn max_node_displacement(sim: &Simulation<'_>) -> Real {
    (0..sim.model().nodes.len())
        .map(|k| sim.probe_displacement(&ProbeLocation::Node(k)).norm())
        .fold(0.0, Real::max)
}
