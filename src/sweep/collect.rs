//! `sweep.csv` and the charts of a sweep folder: one row per variant (its parameters, state, wall time and
//! `super::metrics`), and each metric against each numeric parameter, one line per combination of the other
//! parameters. Collecting reads only the folder's files, so it gives the same table whether the variants ran
//! here or on a cluster, and it can run while variants are still running (their rows say so). The table and
//! the charts are written atomically (`crate::io::atomic`), after removing the temporaries a collection
//! killed outright left of them (module docs of [`super`]).

use super::metrics::{Metrics, Release, run_metrics};
use super::{Plan, SweepDir, SweepError, VariantState, short_name};
use crate::design::load_design;
use crate::io::atomic::{Durability, remove_stale_temporaries, write_file_atomically};
use crate::io::chart::{LineChart, Series, write_svg};
use crate::math::Real;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The table's file in a sweep folder.
pub(super) const TABLE_FILE: &str = "sweep.csv";

/// The charts' folder in a sweep folder.
const CHARTS_FOLDER: &str = "charts";

/// One variant's row.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Row {
    /// Index of the variant in the plan.
    pub index: usize,
    /// What its files say.
    pub state: VariantState,
    /// Its metrics (empty for a variant that has not run).
    pub metrics: Metrics,
}

/// What [`collect`] wrote (its parts are the crate's own: a program gets the table from `sweep.csv`).
#[derive(Debug, Clone, PartialEq)]
pub struct Collected {
    /// The plan.
    pub(crate) plan: Plan,
    /// The rows, in the plan's order.
    pub(crate) rows: Vec<Row>,
    /// The times of the recovery-ratio columns.
    pub(crate) times: Vec<Real>,
    /// `DIR/sweep.csv`.
    pub(crate) csv: PathBuf,
    /// The charts written.
    pub(crate) charts: Vec<PathBuf>,
}

/// A fixed metric column: name, unit kind, value.
type Column = (&'static str, Unit, fn(&Metrics) -> Option<Real>);

/// How a column reads its value from a row's metrics.
type Getter = Box<dyn Fn(&Metrics) -> Option<Real>>;

/// One metric column of the table and its charts.
struct MetricColumn {
    /// Header without the unit.
    name: String,
    /// ` (mm)`, ` (s)` or nothing.
    unit: String,
    /// Its value in a row.
    get: Getter,
}

/// The unit of a metric column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Unit {
    Length,
    Time,
    None,
}

const BEFORE_RATIOS: [Column; 3] = [
    ("programmed_displacement", Unit::Length, |m| {
        m.programmed_displacement
    }),
    ("snap_at_release", Unit::Length, |m| m.snap),
    ("fixity", Unit::None, |m| m.fixity),
];

const AFTER_RATIOS: [Column; 5] = [
    ("time_to_50pc_recovery", Unit::Time, |m| m.time_to_50),
    ("time_to_90pc_recovery", Unit::Time, |m| m.time_to_90),
    ("final_recovery_ratio_mean", Unit::None, |m| {
        m.final_ratio_mean
    }),
    ("final_recovery_ratio_max", Unit::None, |m| {
        m.final_ratio_max
    }),
    ("final_displacement", Unit::Length, |m| m.final_displacement),
];

/// The bench's columns of a sweep of `test` (none for a plain sweep; a bench sweep has only these): the
/// smallest size the tool reached, its size where the wires first touched (empty if they did not) and where the
/// struts locked (empty without the wires' contact or a lock), and its forces
/// at the readings ([`crate::bench::BenchResults`]), the units'
/// suffixes `length` and `force`.
fn bench_columns(test: Option<crate::bench::Test>, length: &str, force: &str) -> Vec<MetricColumn> {
    use crate::bench::Test;
    let Some(test) = test else {
        return Vec::new();
    };
    let reading = |name: String, loading: bool| -> Getter {
        Box::new(move |m: &Metrics| {
            let r = m.bench.as_ref()?.readings.iter().find(|r| r.name == name)?;
            if loading { r.loading } else { r.unloading }
        })
    };
    let mut columns = vec![MetricColumn {
        name: format!("smallest_{}", test.size()),
        unit: length.to_string(),
        get: Box::new(|m: &Metrics| m.bench.as_ref()?.reached),
    }];
    columns.push(MetricColumn {
        name: format!("touch_{}", test.size()),
        unit: length.to_string(),
        get: Box::new(|m: &Metrics| Some(m.bench.as_ref()?.touch.as_ref()?.size)),
    });
    columns.push(MetricColumn {
        name: format!("lock_{}", test.size()),
        unit: length.to_string(),
        get: Box::new(|m: &Metrics| Some(m.bench.as_ref()?.lock.as_ref()?.size)),
    });
    let readings: Vec<(String, String, bool)> = match test {
        Test::Radial => vec![
            ("rrf@vessel".into(), "vessel".into(), true),
            ("cof@vessel".into(), "vessel".into(), false),
        ],
        Test::Crush => crate::bench::CRUSH_READINGS
            .into_iter()
            .map(|f| {
                let r = crate::bench::crush_reading_name(f);
                (format!("crush_force@{r}"), r, true)
            })
            .collect(),
    };
    for (name, at, loading) in readings {
        columns.push(MetricColumn {
            name,
            unit: force.to_string(),
            get: reading(at, loading),
        });
    }
    columns
}

/// The deployment columns of a programmed device's `model` (none without a programme): its recoil and
/// foreshortening.
fn deployment_columns(model: Option<&crate::model::Model>) -> Vec<MetricColumn> {
    if model.is_none_or(|m| m.programme.is_none()) {
        return Vec::new();
    }
    let recoil: fn(&Metrics) -> Option<Real> = |m| m.recoil;
    let foreshortening: fn(&Metrics) -> Option<Real> = |m| m.foreshortening;
    [("recoil", recoil), ("foreshortening", foreshortening)]
        .into_iter()
        .map(|(name, get)| MetricColumn {
            name: name.into(),
            unit: String::new(),
            get: Box::new(get),
        })
        .collect()
}

/// The apposition columns of `model`'s obstacles (none without contact): per obstacle `<name>` the share of the
/// wires' length in contact, the largest gap (`length`: the length unit's suffix) and the mean line pressure.
fn apposition_columns(model: Option<&crate::model::Model>, length: &str) -> Vec<MetricColumn> {
    let Some(model) = model else {
        return Vec::new();
    };
    let names = model.contact.as_ref().map_or(Vec::new(), |c| {
        c.obstacles
            .iter()
            .map(crate::io::contact::column_name)
            .collect()
    });
    let line_pressure = format!(" ({}/{})", model.units.force(), model.units.length());
    let mut columns = Vec::new();
    for (k, name) in names.into_iter().enumerate() {
        type Pick = fn(&super::metrics::AppositionMetrics) -> Option<Real>;
        let quantities: [(&str, String, Pick); 3] = [
            ("contact_fraction", String::new(), |a| a.contact_fraction),
            ("largest_gap", length.to_string(), |a| a.largest_gap),
            ("mean_line_pressure", line_pressure.clone(), |a| {
                a.mean_pressure
            }),
        ];
        for (quantity, unit, pick) in quantities {
            columns.push(MetricColumn {
                name: format!("{quantity}@{name}"),
                unit,
                get: Box::new(move |m: &Metrics| m.apposition.get(k).and_then(pick)),
            });
        }
    }
    columns
}

/// Reads every variant of the sweep in `dir` and writes `sweep.csv` and `charts/` (module docs). The recovery
/// ratio is taken at `times`, or by default halfway between the release and the end and at the end (the end
/// alone for a design without a release).
///
/// # Errors
/// [`SweepError`] when the folder holds no sweep or a file cannot be written.
pub fn collect(dir: &SweepDir, times: Option<&[Real]>) -> Result<Collected, SweepError> {
    let plan = dir.read_plan()?;
    let models: Vec<_> = plan
        .variants
        .iter()
        .map(|v| load_design(&dir.design(&v.id)).ok().map(|d| d.model))
        .collect();
    // Times are in seconds in both unit systems.
    let (length, time) = (
        models
            .iter()
            .flatten()
            .next()
            .map_or("", |m| m.units.length()),
        "s",
    );
    let times: Vec<Real> = match times {
        Some(t) => t.to_vec(),
        None => models.iter().flatten().next().map_or_else(Vec::new, |m| {
            let end = m.time().end;
            match Release::of(m) {
                Some(r) if r.time < end => vec![r.time + 0.5 * (end - r.time), end],
                _ => vec![end],
            }
        }),
    };
    let rows: Vec<Row> = plan
        .variants
        .iter()
        .enumerate()
        .map(|(index, v)| {
            let state = dir.state(&v.id);
            let metrics = models[index]
                .as_ref()
                .map(|m| run_metrics(m, &dir.run(&v.id), &times))
                .unwrap_or_default();
            Row {
                index,
                state,
                metrics,
            }
        })
        .collect();
    let unit = |u: Unit| match u {
        Unit::Length => format!(" ({length})"),
        Unit::Time => format!(" ({time})"),
        Unit::None => String::new(),
    };
    let fixed = |(name, u, get): &Column| MetricColumn {
        name: name.to_string(),
        unit: unit(*u),
        get: Box::new(*get),
    };
    // A bench's run is not the design's cycle: its columns are the bench's alone.
    let columns: Vec<MetricColumn> = if plan.bench.is_some() {
        bench_columns(plan.bench, &unit(Unit::Length), " (N)")
    } else {
        BEFORE_RATIOS
            .iter()
            .map(fixed)
            .chain(times.iter().enumerate().map(|(k, t)| MetricColumn {
                name: format!("recovery_ratio@{}", crate::math::Short(*t)),
                unit: String::new(),
                get: Box::new(move |m: &Metrics| m.recovery_at.get(k).copied().flatten()),
            }))
            .chain(AFTER_RATIOS.iter().map(fixed))
            .chain(deployment_columns(models.iter().flatten().next()))
            .chain(apposition_columns(
                models.iter().flatten().next(),
                &unit(Unit::Length),
            ))
            .collect()
    };
    // The table.
    let mut csv = String::from("variant");
    for p in &plan.parameters {
        csv.push(',');
        csv.push_str(&field(&p.path));
    }
    csv.push_str(&format!(",status,error,wall_time ({time}),steps,warnings"));
    for c in &columns {
        csv.push_str(&format!(",{}{}", c.name, c.unit));
    }
    csv.push('\n');
    let number = |x: Option<Real>| x.map_or_else(String::new, significant);
    for row in &rows {
        let v = &plan.variants[row.index];
        let m = &row.metrics;
        csv.push_str(&v.id);
        for value in &v.values {
            csv.push(',');
            csv.push_str(&field(value));
        }
        let error = match &row.state {
            VariantState::Failed(why) => why.as_str(),
            _ => "",
        };
        let count = |x: Option<u64>| x.map_or_else(String::new, |s| s.to_string());
        let _ = write!(
            csv,
            ",{},{},{},{},{}",
            row.state.name(),
            field(error),
            number(m.wall_time_s),
            count(m.steps),
            count(m.warnings)
        );
        for c in &columns {
            let _ = write!(csv, ",{}", number((c.get)(m)));
        }
        csv.push('\n');
    }
    let csv_path = dir.dir.join(TABLE_FILE);
    remove_stale_temporaries(&dir.dir, Path::new(""), &|t| t == TABLE_FILE)?;
    write_file_atomically(&csv_path, &csv, Durability::Unsynced).map_err(|source| {
        SweepError::Io {
            path: csv_path.clone(),
            source,
        }
    })?;
    // The charts, every one an SVG of this collection.
    remove_stale_temporaries(&dir.dir, Path::new(CHARTS_FOLDER), &|t| t.ends_with(".svg"))?;
    let charts_dir = dir.dir.join(CHARTS_FOLDER);
    let mut charts = Vec::new();
    // A parameter with one value is the same in every variant: no chart against it, no line per its value.
    let varied: Vec<bool> = plan.parameters.iter().map(|p| p.values.len() > 1).collect();
    for (i, p) in plan.parameters.iter().enumerate() {
        let xs: Option<Vec<Real>> = plan
            .variants
            .iter()
            .map(|v| v.values[i].parse().ok())
            .collect();
        let (Some(xs), true) = (xs, varied[i]) else {
            continue;
        };
        for MetricColumn { name, unit, get } in &columns {
            // One line per combination of the other parameters' values, in the plan's order.
            let mut groups: Vec<(String, Vec<(Real, Real)>)> = Vec::new();
            for row in &rows {
                let Some(y) = get(&row.metrics) else {
                    continue;
                };
                let v = &plan.variants[row.index];
                let key = plan
                    .parameters
                    .iter()
                    .zip(&v.values)
                    .enumerate()
                    .filter(|&(j, _)| j != i && varied[j] && !plan.zip)
                    .map(|(_, (q, value))| format!("{}={value}", short_name(&q.path)))
                    .collect::<Vec<_>>()
                    .join(", ");
                match groups.iter_mut().find(|(k, _)| *k == key) {
                    Some((_, points)) => points.push((xs[row.index], y)),
                    None => groups.push((key, vec![(xs[row.index], y)])),
                }
            }
            if groups.is_empty() {
                continue;
            }
            let mut chart = LineChart::new(
                format!("{name} against {}", p.path),
                p.path.clone(),
                format!("{name}{unit}"),
            );
            for (k, (key, mut points)) in groups.into_iter().enumerate() {
                points.sort_by(|a, b| a.0.total_cmp(&b.0));
                let label = if key.is_empty() { name.clone() } else { key };
                chart
                    .series
                    .push(Series::new(label, points).with_markers().with_color(k));
            }
            std::fs::create_dir_all(&charts_dir).map_err(|source| SweepError::Io {
                path: charts_dir.clone(),
                source,
            })?;
            let file = charts_dir.join(format!(
                "{}_vs_{}.svg",
                name.replace('@', "_at_"),
                short_name(&p.path)
            ));
            write_svg(&chart, &file).map_err(|e| SweepError::Io {
                path: file.clone(),
                source: std::io::Error::other(e.to_string()),
            })?;
            charts.push(file);
        }
    }
    Ok(Collected {
        plan,
        rows,
        times,
        csv: csv_path,
        charts,
    })
}

/// `x` to 10 significant digits, in Rust's shortest form (`0.43047603`, not `0.43047602999999945`).
fn significant(x: Real) -> String {
    let rounded: Real = format!("{x:.9e}").parse().unwrap_or(x);
    format!("{rounded}")
}

/// A CSV field: quoted when it holds a comma, a quote or a line break.
fn field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}
