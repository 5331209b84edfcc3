//! What the run folder says of contact (issue 33 item 4), for a model with contact and nothing at all for one
//! without: the `history.csv` columns per obstacle, their peaks over the run for `summary.json`, and the names
//! the other outputs give an obstacle. The numbers are the contact term's report
//! ([`crate::solver::terms::contact::ContactReport`], through [`crate::solver::Simulation::contact`]).
//!
//! **Columns** (after every other column, per obstacle `<name>` in the model's order; the file's convention for a
//! quantity per part, as `recovery_ratio_mean@<material>`): `contact_force_x@<name>`, `contact_force_y@<name>`,
//! `contact_force_z@<name>` (the total force the obstacle exerts on the rods [force]), for a cylinder and a lumen
//! `contact_radial_force@<name>` (its radial part, the sum of the pressures' magnitudes: positive when the wires press
//! on the wall [force]), `contact_points@<name>` (collocation points with a positive pressure),
//! `contact_penetration@<name>` (the largest penetration [length]), `contact_friction_work@<name>` ([force·length];
//! 0 for a frictionless obstacle), and how the wires lie on it (the contact report's *Apposition*):
//! `contact_length_fraction@<name>` (the share of the wires' length in contact), `contact_largest_gap@<name>` (the
//! widest gap of a wire from the surface [length], empty when no point has one) and `contact_mean_pressure@<name>`
//! (the mean line pressure over the length in contact [force/length]). Of the model as simulated: a
//! symmetry-reduced model's share (the fractions and pressures are the device's).
//!
//! With the contact between the wires (`contact: {wires: true}`, `crate::solver::terms::wires`), three columns
//! after the obstacles': `wire_contacts` (the wires' samples pressing on another wire: the contact pairs of the
//! step), `wire_contact_force` (the total force between the wires [force]) and `wire_penetration` (the deepest
//! penetration of a sample [length]).

use crate::math::Real;
use crate::model::{Model, Obstacle, Surface};
use crate::solver::terms::contact::ContactReport;
use crate::solver::terms::wires::WireContactReport;
use serde::Serialize;

/// An obstacle's name as it appears in a column or array name: a comma, quote or line break (which would
/// break the CSV) becomes `_`.
pub(crate) fn column_name(obstacle: &Obstacle) -> String {
    obstacle
        .name
        .chars()
        .map(|c| {
            if matches!(c, ',' | '"' | '\n' | '\r') {
                '_'
            } else {
                c
            }
        })
        .collect()
}

/// The obstacles of `model` (none without contact).
fn obstacles(model: &Model) -> &[Obstacle] {
    model.contact.as_ref().map_or(&[], |c| &c.obstacles)
}

/// The contact columns of `history.csv` (module docs), each with its leading comma; empty without contact.
pub(crate) fn header(model: &Model) -> String {
    let mut header = String::new();
    for o in obstacles(model) {
        let name = column_name(o);
        for quantity in ["force_x", "force_y", "force_z"] {
            header.push_str(&format!(",contact_{quantity}@{name}"));
        }
        if matches!(o.surface, Surface::Cylinder { .. } | Surface::Lumen(_)) {
            header.push_str(&format!(",contact_radial_force@{name}"));
        }
        for quantity in [
            "points",
            "penetration",
            "friction_work",
            "length_fraction",
            "largest_gap",
            "mean_pressure",
        ] {
            header.push_str(&format!(",contact_{quantity}@{name}"));
        }
    }
    header
}

/// The columns of the contact between the wires (module docs), each with its leading comma; empty without it.
pub(crate) fn wire_header(model: &Model) -> String {
    if model.wire_contact.is_none() {
        return String::new();
    }
    ",wire_contacts,wire_contact_force,wire_penetration".into()
}

/// Appends the columns of the wires' contact `report` to a row of `history.csv` (nothing without one).
pub(crate) fn push_wire_row(line: &mut String, report: Option<&WireContactReport>) {
    if let Some(r) = report {
        line.push_str(&format!(
            ",{},{:.9e},{:.6e}",
            r.samples, r.force, r.penetration
        ));
    }
}

/// Appends the contact columns of `report` to a row of `history.csv` (nothing without a report).
pub(crate) fn push_row(line: &mut String, report: Option<&ContactReport>) {
    for o in report.iter().flat_map(|r| &r.obstacles) {
        line.push_str(&format!(
            ",{:.9e},{:.9e},{:.9e}",
            o.force.x, o.force.y, o.force.z
        ));
        if let Some(radial) = o.radial_force {
            line.push_str(&format!(",{radial:.9e}"));
        }
        line.push_str(&format!(
            ",{},{:.6e},{:.6e}",
            o.points, o.penetration, o.friction_work
        ));
        let a = &o.apposition;
        line.push_str(&format!(",{:.6e},", a.contact_fraction));
        if let Some((gap, _, _)) = a.largest_gap {
            line.push_str(&format!("{gap:.6e}"));
        }
        line.push_str(&format!(",{:.6e}", a.mean_pressure));
    }
}

/// A largest value over the run and when it was reached.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Peak {
    /// The value (unit of its quantity).
    pub value: Real,
    /// When \[s\].
    pub time: Real,
}

impl Peak {
    /// Keeps `value` at `time` if it is larger than the peak so far (the first of equal values).
    fn keep(peak: &mut Option<Peak>, value: Real, time: Real) {
        if value.is_finite() && peak.is_none_or(|p| value > p.value) {
            *peak = Some(Peak { value, time });
        }
    }
}

/// Contact with one obstacle over a run (`summary.json`'s `contact`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObstaclePeaks {
    /// The obstacle's name.
    pub obstacle: String,
    /// The largest magnitude of the total contact force \[force\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_force: Option<Peak>,
    /// For a cylinder and a lumen, the largest radial force (positive: the wires press on it) \[force\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_radial_force: Option<Peak>,
    /// The largest penetration \[length\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub largest_penetration: Option<Peak>,
    /// How the wires lie on it at the last converged step (the end of a completed run; [`Apposition`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub apposition: Option<Apposition>,
}

/// How the wires lie on an obstacle at one state (`summary.json`'s `contact[].apposition`; the contact report's
/// module docs, *Apposition*).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Apposition {
    /// The time of the state \[s\].
    pub time: Real,
    /// The share of the wires' length in contact, in \[0, 1\].
    pub contact_fraction: Real,
    /// The largest gap of a wire from the surface, with where.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub largest_gap: Option<Located>,
    /// The largest line pressure \[force/length\].
    pub peak_pressure: Real,
    /// The mean line pressure over the length in contact \[force/length\].
    pub mean_pressure: Real,
}

/// A value at a point of a wire.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Located {
    /// The value.
    pub value: Real,
    /// The patch's name.
    pub patch: String,
    /// The curve parameter on it, in \[0, 1\].
    pub u: Real,
}

/// The apposition of every obstacle in `report` (of `model`), in the model's order.
pub(crate) fn appositions(model: &Model, report: &ContactReport) -> Vec<Apposition> {
    report
        .obstacles
        .iter()
        .map(|o| {
            let a = &o.apposition;
            Apposition {
                time: report.time,
                contact_fraction: a.contact_fraction,
                largest_gap: a.largest_gap.map(|(value, patch, u)| Located {
                    value,
                    patch: model.patches[patch].name.clone(),
                    u,
                }),
                peak_pressure: a.peak_pressure,
                mean_pressure: a.mean_pressure,
            }
        })
        .collect()
}

/// The peaks of every obstacle of `model` over the rows seen so far (empty without contact).
pub(crate) fn no_peaks(model: &Model) -> Vec<ObstaclePeaks> {
    obstacles(model)
        .iter()
        .map(|o| ObstaclePeaks {
            obstacle: o.name.clone(),
            peak_force: None,
            peak_radial_force: None,
            largest_penetration: None,
            apposition: None,
        })
        .collect()
}

/// `x` as history.csv prints it with `digits` digits after the point (`{:.digits e}`), read back.
fn as_printed(x: Real, digits: usize) -> Real {
    format!("{x:.digits$e}").parse().unwrap_or(x)
}

/// Takes the row of `report` at `time` into `peaks` (made by [`no_peaks`] for the same model). The values are
/// taken as the row prints them ([`push_row`]; the time as history.csv prints it), so that a run resumed from
/// its checkpoint, whose peaks before it are read back from the rows ([`run_peaks`]), reports the same peaks
/// as one never interrupted, to the last digit.
pub(crate) fn keep_peaks(peaks: &mut [ObstaclePeaks], report: &ContactReport, time: Real) {
    let time = as_printed(time, 10);
    for (p, o) in peaks.iter_mut().zip(&report.obstacles) {
        let force = o.force.map(|c| as_printed(c, 9));
        Peak::keep(&mut p.peak_force, force.norm(), time);
        if let Some(radial) = o.radial_force {
            Peak::keep(&mut p.peak_radial_force, as_printed(radial, 9), time);
        }
        Peak::keep(
            &mut p.largest_penetration,
            as_printed(o.penetration, 6),
            time,
        );
    }
}

/// The peaks of `model`'s obstacles over the rows of `history.csv` (its text): a resumed run's summary covers
/// the steps before its checkpoint too. A column the file lacks leaves its peak out.
pub(crate) fn run_peaks(model: &Model, text: &str) -> Vec<ObstaclePeaks> {
    let mut peaks = no_peaks(model);
    let mut lines = text.lines();
    let Some(header) = lines.next() else {
        return peaks;
    };
    let header: Vec<&str> = header.split(',').collect();
    let column = |quantity: &str, o: &Obstacle| {
        let name = format!("contact_{quantity}@{}", column_name(o));
        header.iter().position(|h| *h == name)
    };
    let columns: Vec<[Option<usize>; 3]> = obstacles(model)
        .iter()
        .map(|o| {
            [
                column("force_x", o),
                column("radial_force", o),
                column("penetration", o),
            ]
        })
        .collect();
    for line in lines {
        let fields: Vec<&str> = line.split(',').collect();
        let number = |k: Option<usize>| fields.get(k?)?.parse::<Real>().ok();
        let Some(time) = number(Some(0)) else {
            continue;
        };
        for (p, [force, radial, penetration]) in peaks.iter_mut().zip(&columns) {
            let components: Option<Vec<Real>> =
                (0..3).map(|c| number(force.map(|f| f + c))).collect();
            if let Some(f) = components {
                Peak::keep(
                    &mut p.peak_force,
                    crate::math::Vec3::new(f[0], f[1], f[2]).norm(),
                    time,
                );
            }
            if let Some(r) = number(*radial) {
                Peak::keep(&mut p.peak_radial_force, r, time);
            }
            if let Some(d) = number(*penetration) {
                Peak::keep(&mut p.largest_penetration, d, time);
            }
        }
    }
    peaks
}

/// What the charts keep of contact at one state ([`crate::io::run_charts`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ContactSample {
    /// Time of the state \[s\].
    pub time: Real,
    /// Per obstacle, in the model's order.
    pub obstacles: Vec<ObstacleSample>,
}

/// What the charts keep of one obstacle at one state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ObstacleSample {
    /// Magnitude of the total contact force \[force\].
    pub force: Real,
    /// A cylinder's or a lumen's radial force \[force\].
    pub radial_force: Option<Real>,
    /// A cylinder's diameter `2R(t)` at the state \[length\].
    pub diameter: Option<Real>,
}

/// The chart sample of `report` for `model` at `time`.
pub(crate) fn sample(model: &Model, report: &ContactReport, time: Real) -> ContactSample {
    ContactSample {
        time,
        obstacles: obstacles(model)
            .iter()
            .zip(&report.obstacles)
            .map(|(o, r)| ObstacleSample {
                force: r.force.norm(),
                radial_force: r.radial_force,
                diameter: o.surface.radius(report.time).map(|r| 2.0 * r),
            })
            .collect(),
    }
}
