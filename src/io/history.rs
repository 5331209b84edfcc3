//! `history.csv`: one row per converged step (and the initial state): `time` (with arc-length continuation the
//! path parameter, the sum of the arc lengths, followed by `load_factor`, the load factor λ reached), then for
//! each probe `P` the
//! displacement columns `P.ux, P.uy, P.uz` (in the design's length unit), then `temperature` [°C],
//! `iterations` (Newton solves of the step), `residual` (final normalised residual) and `cuts` (step cuts).
//! With error-controlled stepping (`time.tolerance`) it adds `dt` (the step taken), `error_estimate` (its
//! time-error estimate, normalised as Newton's increments; 0 for a material without internal variables) and
//! `rejected` (attempts rejected by error control before it).
//! With automatic stabilisation (`solver.stabilisation`) it adds `stabilisation_factor` (the damping factor `c`
//! of the step, 0 when undamped), `strain_energy` (at the step's end), `dissipated_energy` (by the damping since
//! the start), `dissipated_ratio` (that over the largest strain energy so far) and `damping_force_share` (the
//! damping force's share of the forces on the device at the step's end, 0 when undamped;
//! `crate::solver::simulation::stabilisation`).
//! A design with a programme (stents) adds `recovery_ratio_mean` and `recovery_ratio_max`, the mean (weighted
//! over the full device) and largest `‖η_l‖ / ‖η_temp,l‖` over the driven nodes — 1 at the temporary shape, 0 at
//! the permanent one — and, for a radial contraction, `delta_r`: the mean radial contraction of the driven
//! nodes (positive towards the axis; the paper's Δr), and for a device of several materials
//! `recovery_ratio_mean@<material>`, the mean ratio over the driven nodes touching a rod of that material (a node
//! joining two materials counts in both; [`crate::model::Model::material_regions`]), then `device_diameter` and
//! `device_length`, the driven nodes' mean outer diameter and their extent along the axis (length unit;
//! [`crate::post::deployment`], whose recoil and foreshortening `summary.json` reads off them). With a temperature field,
//! `temperature` is the field's reference schedule and `temperature_min`, `temperature_max` (after `cuts`) the
//! extremes over the collocation points. Then `max_displacement`, the largest
//! displacement of any node from the reference shape (length unit): the size of the programmed shape, of the
//! snap at a release and of what is left at the end (`stentkit sweep`'s metrics). The last three columns say
//! where the surface strain of the wire peaks (`crate::solver::simulation::fields`): `surface_strain_peak`
//! (the largest fibre stretch `λ − 1` over the collocation points),
//! `surface_strain_patch` (the patch's name) and `surface_strain_s` (the reference arc length from the patch's
//! start, length unit).
//! With contact (`model.contact`), the contact columns of each obstacle follow (`crate::io::contact`: the total
//! force, its radial part for a cylinder, the points in contact, the largest penetration, the friction work, and
//! how the wires lie on it: the share of their length in contact, the largest gap, the mean line pressure).
//! Rows are flushed as they are written, so an interrupted run leaves a valid file up to its last step; a row
//! that cannot be written whole (a full disk) is cut off again, so the file always ends with a complete row.

use crate::math::Real;
use crate::solver::{Observer, Simulation, StepReport};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

/// The columns of `history.csv` that hold text (a patch's name) rather than numbers.
pub const TEXT_COLUMNS: &[&str] = &["surface_strain_patch"];

/// `history.csv` read back as columns (`sweep collect`'s metrics, the bench's table).
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct History {
    names: Vec<String>,
    rows: Vec<Vec<Real>>,
}

impl History {
    /// Parses the text of a `history.csv` (a row that does not parse whole ends the table: a killed run's
    /// last line may be cut). An empty cell — a quantity the row does not have, such as the largest gap from an
    /// obstacle not yet in place — reads as NaN and keeps its row.
    pub(crate) fn parse(text: &str) -> Self {
        let mut lines = text.lines();
        let names: Vec<String> = lines
            .next()
            .map(|h| h.split(',').map(str::to_string).collect())
            .unwrap_or_default();
        // Text columns (a patch's name) are read as NaN: only numbers are looked up.
        let text: Vec<bool> = names
            .iter()
            .map(|n| TEXT_COLUMNS.contains(&n.as_str()))
            .collect();
        let rows = lines
            .map(|l| {
                l.split(',')
                    .zip(text.iter().chain(std::iter::repeat(&false)))
                    .map(|(x, &is_text)| {
                        if is_text || x.is_empty() {
                            Ok(Real::NAN)
                        } else {
                            x.parse::<Real>()
                        }
                    })
                    .collect::<Result<Vec<_>, _>>()
            })
            .take_while(|r| r.as_ref().is_ok_and(|r| r.len() == names.len()))
            .filter_map(Result::ok)
            .collect();
        Self { names, rows }
    }

    /// The column `name` as (time, value) pairs.
    pub(crate) fn column(&self, name: &str) -> Option<Vec<(Real, Real)>> {
        let c = self.names.iter().position(|n| n == name)?;
        Some(self.rows.iter().map(|r| (r[0], r[c])).collect())
    }
}

/// The materials with a strain limit, as `(material index, limit)`.
fn limited_materials(strain_limits: &[Option<f64>]) -> Vec<(usize, f64)> {
    strain_limits
        .iter()
        .enumerate()
        .filter_map(|(m, l)| l.map(|l| (m, l)))
        .collect()
}

/// Where the surface strain peaked over a run (`summary.json` `peak_surface_strain`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SurfaceStrainPeak {
    /// The strain (positive: stretched) \[-\].
    pub value: f64,
    /// When \[s\].
    pub time: f64,
    /// The patch's name.
    pub patch: String,
    /// Reference arc length from the patch's start \[length\].
    pub arc_length: f64,
}

/// The column of the programmed device's mean outer diameter (`crate::post::deployment`).
pub const DEVICE_DIAMETER: &str = "device_diameter";
/// The column of the programmed device's length along its axis (`crate::post::deployment`).
pub const DEVICE_LENGTH: &str = "device_length";

/// The deployment samples of a history's rows `text` (a resumed run's rows before its checkpoint), as a run
/// of `model` gathered them.
fn run_deployment(
    model: &crate::model::Model,
    text: &str,
) -> crate::post::deployment::DeploymentTrack {
    let mut track = deployment_track(model);
    let history = History::parse(text);
    if let (Some(d), Some(l)) = (
        history.column(DEVICE_DIAMETER),
        history.column(DEVICE_LENGTH),
    ) {
        for (&(t, d), &(_, l)) in d.iter().zip(&l) {
            track.observe((t, d, l));
        }
    }
    track
}

/// An empty deployment track for `model`'s cycle.
fn deployment_track(model: &crate::model::Model) -> crate::post::deployment::DeploymentTrack {
    crate::post::deployment::DeploymentTrack::new(model.cycle(), model.time().landing_tolerance())
}

/// The row of `history.csv` (its text) where the device's surface strain peaks over the run; `None` without
/// such a column or rows. Read back from the file, so that a resumed run's summary covers the steps before its
/// checkpoint too.
pub fn run_peak_surface_strain(text: &str) -> Option<SurfaceStrainPeak> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next()?.split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name);
    let (value, patch, s) = (
        column("surface_strain_peak")?,
        column("surface_strain_patch")?,
        column("surface_strain_s")?,
    );
    lines
        .filter_map(|l| {
            let fields: Vec<&str> = l.split(',').collect();
            let number = |k: usize| fields.get(k)?.parse::<f64>().ok();
            Some(SurfaceStrainPeak {
                value: number(value)?,
                time: number(0)?,
                patch: fields.get(patch)?.to_string(),
                arc_length: number(s)?,
            })
        })
        .fold(None, |best: Option<SurfaceStrainPeak>, row| match best {
            Some(b) if b.value >= row.value => Some(b),
            _ => Some(row),
        })
}

/// How far `history.csv` was written: what a checkpoint records and a resumed run continues from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HistoryPosition {
    /// Length of the file up to its last complete row \[bytes\].
    pub bytes: u64,
    /// Complete rows (the initial state is row 0).
    pub rows: usize,
    /// Time of the last row.
    pub last_time: Option<f64>,
}

/// Whether the history at `path` can be continued from `position` (a checkpoint's), changing nothing: the file
/// must exist and hold at least the bytes it held at the checkpoint (a killed run may have written more, which
/// [`HistoryWriter::resume`] cuts off; fewer means rows before the checkpoint are lost).
///
/// # Errors
/// [`std::io::ErrorKind::NotFound`] or [`std::io::ErrorKind::InvalidData`], each naming the file and what it
/// holds against what the checkpoint needs; another I/O error reading its size.
pub fn check_resumable(path: &Path, position: &HistoryPosition) -> std::io::Result<()> {
    let length = match std::fs::symlink_metadata(path) {
        Ok(meta) => meta.len(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(std::io::Error::new(
                e.kind(),
                format!(
                    "{} is missing; the checkpoint continues it after its {} bytes ({} rows)",
                    path.display(),
                    position.bytes,
                    position.rows
                ),
            ));
        }
        Err(e) => {
            return Err(std::io::Error::new(
                e.kind(),
                format!("{}: {e}", path.display()),
            ));
        }
    };
    shorter_than(path, length, position)
}

/// The error of a history of `length` bytes at `path` that is shorter than `position` says it was.
fn shorter_than(path: &Path, length: u64, position: &HistoryPosition) -> std::io::Result<()> {
    if length < position.bytes {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "{} holds {length} bytes, fewer than the {} ({} rows) it held at the checkpoint",
                path.display(),
                position.bytes,
                position.rows
            ),
        ));
    }
    Ok(())
}

/// Writes `history.csv` as the simulation reports steps.
pub struct HistoryWriter {
    /// The materials with a strain limit: `(material index, limit)`, each with a column of its own.
    limits: Vec<(usize, f64)>,
    /// Per entry of `limits`, whether its exceedance has been said.
    exceeded: Vec<bool>,
    /// Warnings not yet taken by the caller ([`HistoryWriter::take_warnings`]).
    warnings: Vec<String>,
    /// The row where the surface strain peaked so far.
    peak: Option<SurfaceStrainPeak>,
    /// The peaks of the contact columns so far (empty without contact).
    contact: Vec<super::contact::ObstaclePeaks>,
    /// The programmed device's diameter and length at the cycle's events so far.
    deployment: crate::post::deployment::DeploymentTrack,
    path: PathBuf,
    /// `None` once a write failed.
    out: Option<BufWriter<File>>,
    /// Length of the file up to its last complete row [bytes].
    complete: u64,
    /// Rows written (the initial state is row 0) and the time of the last one.
    rows: usize,
    last_time: Option<f64>,
    /// First write error; writing stops there and the run is asked to stop.
    error: Option<std::io::Error>,
}

impl HistoryWriter {
    /// Creates (truncates) the file and writes the header for the model's probes; `strain_limits` (per material,
    /// [`crate::design::OutputSettings::strain_limits`]) adds a peak column per material with a limit.
    pub fn create(
        path: &Path,
        sim: &Simulation<'_>,
        strain_limits: &[Option<f64>],
    ) -> std::io::Result<Self> {
        let limits = limited_materials(strain_limits);
        let mut out = BufWriter::new(super::no_follow::create(path)?);
        let mut header = String::from("time");
        if sim.model().solver().path.arc_length().is_some() {
            header.push_str(",load_factor");
        }
        for p in &sim.model().probes {
            for c in ["ux", "uy", "uz"] {
                header.push_str(&format!(",{}.{c}", p.name));
            }
        }
        header.push_str(",temperature,iterations,residual,cuts");
        if sim.model().temperature_field.is_some() {
            header.push_str(",temperature_min,temperature_max");
        }
        if sim.model().time().tolerance.is_some() {
            header.push_str(",dt,error_estimate,rejected");
        }
        if !sim.model().record_times().is_empty() {
            header.push_str(",requested");
        }
        if sim.model().solver().stabilisation.is_some() {
            header
                .push_str(",stabilisation_factor,strain_energy,dissipated_energy,dissipated_ratio");
            header.push_str(",damping_force_share");
        }
        if let Some(programme) = &sim.model().programme {
            header.push_str(",recovery_ratio_mean,recovery_ratio_max");
            if programme.is_radial() {
                header.push_str(",delta_r");
            }
            let model = sim.model();
            for m in model.material_regions() {
                header.push_str(&format!(",recovery_ratio_mean@{}", model.material_names[m]));
            }
            header.push_str(&format!(",{DEVICE_DIAMETER},{DEVICE_LENGTH}"));
        }
        header.push_str(
            ",max_displacement,surface_strain_peak,surface_strain_patch,surface_strain_s",
        );
        for &(m, _) in &limits {
            header.push_str(&format!(
                ",surface_strain_peak@{}",
                sim.model().material_names[m]
            ));
        }
        header.push_str(&super::contact::header(sim.model()));
        header.push_str(&super::contact::wire_header(sim.model()));
        writeln!(out, "{header}")?;
        out.flush()?;
        Ok(Self {
            exceeded: vec![false; limits.len()],
            limits,
            warnings: Vec::new(),
            peak: None,
            contact: super::contact::no_peaks(sim.model()),
            deployment: deployment_track(sim.model()),
            path: path.to_path_buf(),
            complete: header.len() as u64 + 1,
            out: Some(out),
            rows: 0,
            last_time: None,
            error: None,
        })
    }

    /// Continues the history of a resumed run at `position` (a checkpoint's): the file is cut back to the rows
    /// written up to the checkpoint — a killed run may have written more — and rows are appended after them.
    ///
    /// # Errors
    /// The I/O error, or [`std::io::ErrorKind::InvalidData`] when the file is shorter than the checkpoint says.
    pub fn resume(
        path: &Path,
        model: &crate::model::Model,
        position: HistoryPosition,
        strain_limits: &[Option<f64>],
    ) -> std::io::Result<Self> {
        let limits = limited_materials(strain_limits);
        check_resumable(path, &position)?;
        // The handle, opened without following a link, is measured, cut, read and appended to: the path is not
        // looked up again.
        let mut file =
            super::no_follow::open(path, std::fs::OpenOptions::new().read(true).write(true))?;
        shorter_than(path, file.metadata()?.len(), &position)?;
        file.set_len(position.bytes)?;
        let mut text = String::new();
        std::io::Read::read_to_string(&mut file, &mut text)?;
        let peak = run_peak_surface_strain(&text);
        let contact = super::contact::run_peaks(model, &text);
        let deployment = run_deployment(model, &text);
        std::io::Seek::seek(&mut file, std::io::SeekFrom::End(0))?;
        Ok(Self {
            exceeded: vec![false; limits.len()],
            limits,
            warnings: Vec::new(),
            peak,
            contact,
            deployment,
            path: path.to_path_buf(),
            complete: position.bytes,
            out: Some(BufWriter::new(file)),
            rows: position.rows,
            last_time: position.last_time,
            error: None,
        })
    }

    /// How far the file is written (for a checkpoint).
    pub fn position(&self) -> HistoryPosition {
        HistoryPosition {
            bytes: self.complete,
            rows: self.rows,
            last_time: self.last_time,
        }
    }

    /// The time of the last complete row (`None`: the header only).
    pub fn last_time(&self) -> Option<f64> {
        self.last_time
    }

    /// Complete rows written (the initial state included).
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The file written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The programmed device's diameter and length at the cycle's events over the rows written, whose recoil and
    /// foreshortening `summary.json` reports ([`crate::post::deployment`]).
    pub fn deployment(&self) -> &crate::post::deployment::DeploymentTrack {
        &self.deployment
    }

    /// Where the surface strain peaked over the rows written.
    pub fn peak_surface_strain(&self) -> Option<&SurfaceStrainPeak> {
        self.peak.as_ref()
    }

    /// The peaks of the contact columns over the rows written, per obstacle (empty without contact).
    pub fn contact_peaks(&self) -> &[super::contact::ObstaclePeaks] {
        &self.contact
    }

    /// The warnings found since the last call (a material's strain limit exceeded: each said once).
    pub fn take_warnings(&mut self) -> Vec<String> {
        std::mem::take(&mut self.warnings)
    }

    /// The first write error, if any.
    pub fn take_error(&mut self) -> Option<std::io::Error> {
        self.error.take()
    }

    /// Writes the row of the state of `sim` (`report`: its step's, or with `extension` the continuous extension's
    /// at a requested time between steps; `None`: the initial state).
    fn row(
        &mut self,
        sim: &Simulation<'_>,
        report: Option<&StepReport>,
        extension: bool,
    ) -> ControlFlow<()> {
        let t = sim.time();
        let mut line = format!("{t:.10e}");
        if sim.model().solver().path.arc_length().is_some() {
            line.push_str(&format!(",{:.12e}", sim.load_factor().unwrap_or(0.0)));
        }
        for p in &sim.model().probes {
            let u = sim.probe_displacement(&p.location);
            line.push_str(&format!(",{:.12e},{:.12e},{:.12e}", u.x, u.y, u.z));
        }
        let temperature = sim.model().temperature().value(sim.schedule_time());
        let (iterations, residual, cuts) = match report {
            Some(r) => (
                r.newton.iterations,
                r.newton.residuals.last().copied().unwrap_or(0.0),
                r.cuts,
            ),
            None => (0, 0.0, 0),
        };
        line.push_str(&format!(
            ",{temperature:.6},{iterations},{residual:.3e},{cuts}"
        ));
        if let Some((lo, hi)) = sim.temperature_extremes(sim.schedule_time()) {
            line.push_str(&format!(",{lo:.6},{hi:.6}"));
        }
        if sim.model().time().tolerance.is_some() {
            let (dt, estimate, rejected) = report.map_or((0.0, 0.0, 0), |r| {
                (r.dt, r.error_estimate.unwrap_or(0.0), r.rejected)
            });
            line.push_str(&format!(",{dt:.6e},{estimate:.3e},{rejected}"));
        }
        let requested = sim.model().record_times();
        if !requested.is_empty() {
            // A row at a requested time: the step landing on it (1), or the continuous extension's state there (2).
            let snap = sim.model().time().landing_tolerance();
            line.push_str(if extension {
                ",2"
            } else if crate::math::near_one_of(requested, t, snap) {
                ",1"
            } else {
                ",0"
            });
        }
        if sim.model().solver().stabilisation.is_some() {
            let s = report.and_then(|r| r.stabilisation);
            let factor = s.map_or(0.0, |s| s.factor);
            let energy = s.map_or_else(|| sim.strain_energy(), |s| s.strain_energy);
            let share = s.map_or(0.0, |s| s.force_share);
            let totals = sim.stabilisation();
            line.push_str(&format!(
                ",{factor:.6e},{energy:.9e},{:.9e},{:.6e},{share:.6e}",
                totals.dissipated,
                totals.ratio()
            ));
        }
        if let Some(r) = crate::post::recovery::recovery(sim) {
            line.push_str(&format!(",{:.9e},{:.9e}", r.ratio_mean, r.ratio_max));
            if let Some(delta_r) = r.delta_r {
                line.push_str(&format!(",{delta_r:.9e}"));
            }
            for ratio in &r.by_material {
                line.push_str(&format!(",{ratio:.9e}"));
            }
        }
        if sim.model().programme.is_some() {
            match crate::post::deployment::device_shape(sim) {
                Some(shape) => {
                    // The track keeps the values as the row prints them, so that a run resumed from its
                    // checkpoint (whose track is read back from these rows) reports the same recoil and
                    // foreshortening as one never interrupted, to the last digit.
                    let (diameter, length) = (
                        format!("{:.9e}", shape.diameter),
                        format!("{:.9e}", shape.length),
                    );
                    line.push_str(&format!(",{diameter},{length}"));
                    let printed = |text: &str, exact: Real| text.parse().unwrap_or(exact);
                    let time = printed(&format!("{t:.10e}"), t);
                    self.deployment.observe((
                        time,
                        printed(&diameter, shape.diameter),
                        printed(&length, shape.length),
                    ));
                }
                None => line.push_str(",,"),
            }
        }
        line.push_str(&format!(
            ",{:.9e}",
            crate::post::recovery::max_node_displacement(sim)
        ));
        match sim.peak_surface_strain() {
            Some(peak) => {
                let patch = &sim.model().patches[peak.patch].name;
                line.push_str(&format!(
                    ",{:.9e},{patch},{:.9e}",
                    peak.value, peak.arc_length
                ));
                if self.peak.as_ref().is_none_or(|p| peak.value > p.value) {
                    self.peak = Some(SurfaceStrainPeak {
                        value: peak.value,
                        time: t,
                        patch: patch.clone(),
                        arc_length: peak.arc_length,
                    });
                }
            }
            None => line.push_str(",,,"),
        }
        for (k, &(m, limit)) in self.limits.iter().enumerate() {
            let Some(peak) = sim.peak_surface_strain_of(Some(m)) else {
                line.push(',');
                continue;
            };
            line.push_str(&format!(",{:.9e}", peak.value));
            if peak.value > limit && !self.exceeded[k] {
                self.exceeded[k] = true;
                let model = sim.model();
                self.warnings.push(format!(
                    "at t = {t:.4} s the surface strain of material `{}` reaches {:.3} % (patch `{}`, s = {:.4} {}), above its strain_limit {:.3} % (said once)",
                    model.material_names[m],
                    100.0 * peak.value,
                    model.patches[peak.patch].name,
                    peak.arc_length,
                    model.units.length(),
                    100.0 * limit
                ));
            }
        }
        let contact = sim.contact();
        super::contact::push_row(&mut line, contact.as_ref());
        if let Some(report) = &contact {
            super::contact::keep_peaks(&mut self.contact, report, t);
        }
        super::contact::push_wire_row(&mut line, sim.wire_contact().as_ref());
        let Some(out) = &mut self.out else {
            return ControlFlow::Break(());
        };
        match writeln!(out, "{line}").and_then(|_| out.flush()) {
            Ok(()) => {
                self.complete += line.len() as u64 + 1;
                self.rows += 1;
                self.last_time = Some(t);
                ControlFlow::Continue(())
            }
            Err(e) => {
                self.cut_partial_row();
                self.error = Some(e);
                ControlFlow::Break(())
            }
        }
    }

    /// Drops what a failed write left in the buffer and cuts the file back to its last complete row.
    fn cut_partial_row(&mut self) {
        if let Some(out) = self.out.take() {
            let (file, _unwritten) = out.into_parts();
            // Best effort: truncating needs no free space; if even that fails the error already reported stands.
            let _ = file.set_len(self.complete).and_then(|()| file.sync_all());
        }
    }
}

impl Observer for HistoryWriter {
    fn start(&mut self, sim: &Simulation<'_>) -> ControlFlow<()> {
        self.row(sim, None, false)
    }

    fn step(&mut self, sim: &Simulation<'_>, report: &StepReport) -> ControlFlow<()> {
        self.row(sim, Some(report), false)
    }

    fn requested(&mut self, sim: &Simulation<'_>, report: &StepReport) {
        // (A write error is kept and stops the run at the next step, whose row cannot be written either.)
        let _ = self.row(sim, Some(report), true);
    }
}

#[cfg(test)]
mod tests {
    use super::History;

    // Hand-written: a row with an empty cell (an obstacle's largest gap before it is in place) is kept, its cell
    // NaN; a row cut short (a killed run's last line) ends the table.
    #[test]
    fn an_empty_cell_keeps_its_row_and_a_cut_row_ends_the_table() {
        let h = History::parse("time,a,contact_largest_gap@sheath\n0,1,\n1,2,0.5\n2,3");
        let gap = h.column("contact_largest_gap@sheath").expect("the column");
        assert_eq!(gap.len(), 2);
        assert!(gap[0].1.is_nan() && gap[1] == (1.0, 0.5));
        assert_eq!(h.column("a"), Some(vec![(0.0, 1.0), (1.0, 2.0)]));
    }
}
