//! The model's fingerprint: a 64-bit hash of a serialised, versioned description of the [`Model`], which a
//! checkpoint carries so that `--resume` and [`crate::solver::Simulation::restore`] refuse another model, and
//! which `summary.json` states (`model_fingerprint`) so that `export` can tell whether a design is the one that
//! ran.
//!
//! **What is in the description.** Every field of the [`Model`], as serde derives it: the name and units, the
//! materials (each law's parameters and integrator) and their names, the sections, the patches (control
//! points, weights, knots, section and material, fit error), the nodes with their conditions (basis, every
//! component's schedule and release), distributed loads, temperature and temperature field, time and solver
//! settings, probes, node sets, the programme, symmetry planes, record times and the vessel. Everything, not
//! only the physics, because a resumed run continues the outputs too (the probes and node sets name columns
//! of `history.csv`; the name and record times appear in the recording and the snapshots): two models with the
//! same description give the same run, and a model that differs in any value does not resume another's
//! checkpoint. Derived data (collocation points, basis tables) is not in the model and not described.
//!
//! **The form.** JSON as `serde_json` writes it, `{"description":"stentkit model","version":V,"model":{…}}`:
//! fields in declaration order, enums by variant name, maps (node sets) in key order, vectors and matrices as
//! their components (`crate::math::serial`), every float in its shortest round-trip form, so that two models
//! share a description exactly when every number is bit for bit the same (except that NaN and ±∞, which the
//! builder refuses anywhere they could reach a model, would all be `null`). The hash is 64-bit FNV-1a of those
//! bytes (`Fnv1a`); a collision of two different models has a probability of about 2⁻⁶⁴.
//!
//! **Why serialised, and why versioned.** The fingerprint used to hash the model's `Debug` text, so a change
//! to a `Debug` impl — or a dependency's — changed every fingerprint and refused every checkpoint. The
//! description depends only on the fields' names, order and values, which change with the model itself; when
//! its *form* changes on purpose (a field added, renamed or moved, a type's serialisation changed), [`VERSION`]
//! is raised so that the old and new descriptions of a model can never be taken for each other, and the
//! test's committed description (`tests/data/fingerprint/`) is written again. The checkpoint file's own
//! format version (`crate::io::checkpoint::VERSION`) says which fingerprint its checkpoints carry.
//!
//! The description exists only in memory (written into the hasher as it is made); nothing here touches a
//! file.

use super::Model;
use serde::Serialize;

/// The version of the description's form (module docs): raised whenever the form changes.
pub const VERSION: u32 = 2;

/// What the description says it is.
const KIND: &str = "stentkit model";

/// The description's envelope: what it is, its form's version and the model.
#[derive(Serialize)]
struct Description<'a, T: Serialize> {
    description: &'a str,
    version: u32,
    model: &'a T,
}

/// The serialised description of `model` (module docs), as text: what [`fingerprint`] hashes.
pub fn description(model: &Model) -> String {
    let mut out = Vec::new();
    write_description(model, &mut out);
    // serde_json writes UTF-8 only.
    String::from_utf8(out).expect("serde_json writes UTF-8")
}

/// The fingerprint of `model`: FNV-1a of its [`description`].
pub fn fingerprint(model: &Model) -> u64 {
    let mut hasher = Fnv1a::default();
    write_description(model, &mut hasher);
    hasher.0
}

/// The fingerprint of any other settings a checkpoint must match (e.g. a run's output settings): FNV-1a of
/// `{"description":kind,"version":version,"model":value}` as serde_json writes it.
pub fn fingerprint_of(kind: &str, version: u32, value: &impl Serialize) -> u64 {
    let mut hasher = Fnv1a::default();
    write(kind, version, value, &mut hasher);
    hasher.0
}

fn write_description(model: &Model, out: &mut impl std::io::Write) {
    write(KIND, VERSION, model, out);
}

fn write<T: Serialize>(kind: &str, version: u32, value: &T, out: &mut impl std::io::Write) {
    let description = Description {
        description: kind,
        version,
        model: value,
    };
    // The writers here cannot fail, and every map key of the model is a string: an error is a programmer's.
    serde_json::to_writer(out, &description).expect("a model serialises to JSON");
}

/// 64-bit FNV-1a (Fowler, Noll, Vo; offset basis and prime from the reference, IETF draft
/// draft-eastlake-fnv-17, §2): a fast, stable, well-distributed hash, enough to tell models apart.
struct Fnv1a(u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl std::io::Write for Fnv1a {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{
        CircularSection, Integrator, Material, MaxwellLaw, Prony, PronyBranch, Section, Wlf,
    };
    use crate::math::{Mat3, Vec3};
    use crate::model::builder::{ConditionSpec, ModelBuilder, PatchShape, ProbeAt, TimeSpec};
    use crate::model::{Component, LinearMethod, SolverSettings, TimeFunction, TimeSettings};

    /// A heated cantilever of a one-branch Maxwell/WLF material: one patch (p = 2, n = 4), clamped at its
    /// start, loaded at its end, with a temperature ramp and a probe — small enough to read its description.
    fn cantilever() -> Model {
        let prony = Prony::try_new(
            1.0e6,
            vec![PronyBranch {
                modulus: 2.0e6,
                tau_g: 0.5,
            }],
        )
        .expect("valid series");
        let material = Material::try_new(prony, 0.3, Some(Wlf::van_manen_2021())).expect("valid");
        let section: Section = CircularSection::try_new(0.01).expect("d > 0").into();
        let mut b = ModelBuilder::new(
            "cantilever",
            MaxwellLaw::new(material, Integrator::Trapezoidal),
            section,
        );
        let shape = PatchShape::Line {
            from: Vec3::zeros(),
            to: Vec3::new(0.1, 0.0, 0.0),
        };
        b.patch("beam", shape, 2, 4);
        b.condition(ConditionSpec::clamp("beam.start"));
        b.condition(ConditionSpec::at("beam.end").with_force(2, TimeFunction::constant(1e-3)));
        b.temperature(TimeFunction::try_table(vec![(0.0, 20.0), (1.0, 90.0)]).expect("table"));
        b.time(TimeSpec::new(1.0, 0.25));
        b.probe("tip", ProbeAt::Node("beam.end".into()));
        b.build().expect("a valid cantilever").model
    }

    /// The committed description of [`cantilever`] (form version 2), without a final newline: the bytes hashed.
    const DESCRIPTION: &str =
        include_str!("../../tests/data/fingerprint/cantilever_description.json");

    /// The fingerprint of [`DESCRIPTION`], not computed by this crate: the output of
    /// `python3 scripts/fnv1a.py tests/data/fingerprint/cantilever_description.json`, FNV-1a written
    /// independently from the reference.
    const FINGERPRINT: u64 = 0x85d3_73bd_dbf5_3295;

    #[test]
    fn the_fingerprint_is_the_hash_of_the_committed_description() {
        // The fingerprint depends on the serialised description and nothing else (not on any `Debug` text):
        // the description of a fixed model is the committed file byte for byte, and its fingerprint is what an
        // independent FNV-1a gives for that file. If this fails because the form changed on purpose, raise
        // VERSION and write the file and the value again (module docs).
        let model = cantilever();
        let text = description(&model);
        if std::env::var_os("STENTKIT_WRITE_DESCRIPTION").is_some() {
            // Writing the file again (after a deliberate change of form): then run scripts/fnv1a.py on it.
            let path = concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/tests/data/fingerprint/cantilever_description.json"
            );
            std::fs::write(path, &text).expect("written");
        }
        assert_eq!(
            text, DESCRIPTION,
            "the description of the cantilever changed (raise fingerprint::VERSION if its form did)"
        );
        assert_eq!(fingerprint(&model), FINGERPRINT);
    }

    #[test]
    fn a_change_of_any_setting_changes_the_fingerprint() {
        // Each change is the smallest there is for its kind (the next float up, one iteration, another
        // variant), in every part of the model: all the fingerprints must differ from the model's and from
        // each other.
        let up = |x: crate::math::Real| x.next_up();
        type Change = Box<dyn Fn(&mut Model)>;
        // The time and Newton settings change as they do outside `model`: through the checked setters.
        fn time(change: impl Fn(&mut TimeSettings) + 'static) -> Change {
            Box::new(move |m| {
                let mut time = m.time().clone();
                change(&mut time);
                *m = m.clone().with_time(time).expect("valid time settings");
            })
        }
        fn solver(change: impl Fn(&mut SolverSettings) + 'static) -> Change {
            Box::new(move |m| {
                let mut solver = m.solver().clone();
                change(&mut solver);
                *m = m
                    .clone()
                    .with_solver(solver)
                    .expect("valid Newton settings");
            })
        }
        let changes: Vec<(&str, Change)> = vec![
            (
                "a branch modulus",
                Box::new(move |m| {
                    let prony = Prony::try_new(
                        1.0e6,
                        vec![PronyBranch {
                            modulus: up(2.0e6),
                            tau_g: 0.5,
                        }],
                    )
                    .expect("valid");
                    let material =
                        Material::try_new(prony, 0.3, Some(Wlf::van_manen_2021())).expect("valid");
                    m.materials[0] = MaxwellLaw::new(material, Integrator::Trapezoidal).into();
                }),
            ),
            (
                "the integrator",
                Box::new(|m| {
                    if let crate::material::MaterialLaw::Maxwell(law) = &mut m.materials[0] {
                        *law = MaxwellLaw::new(law.material().clone(), Integrator::Exponential);
                    }
                }),
            ),
            (
                "the section diameter",
                Box::new(move |m| {
                    m.sections[0] = CircularSection::try_new(up(0.01)).expect("d > 0").into()
                }),
            ),
            (
                "a control point",
                Box::new(move |m| {
                    let curve = &m.patches[0].curve;
                    let mut points = curve.points().to_vec();
                    points[1].y = up(points[1].y);
                    m.patches[0].curve =
                        crate::math::NurbsCurve::try_bspline(curve.knots().clone(), points)
                            .expect("valid curve");
                }),
            ),
            (
                "a node's load",
                Box::new(move |m| {
                    let end = m.nodes.iter().position(|n| n.name == "beam.end");
                    m.nodes[end.expect("tip node")].conditions.components[2] =
                        Component::Load(TimeFunction::constant(up(1e-3)));
                }),
            ),
            (
                "a node's basis",
                Box::new(move |m| m.nodes[0].conditions.basis[(0, 0)] = up(1.0)),
            ),
            (
                "the temperature",
                Box::new(move |m| {
                    m.temperature =
                        TimeFunction::try_table(vec![(0.0, 20.0), (1.0, up(90.0))]).expect("table")
                }),
            ),
            ("the end time", time(move |t| t.end = up(1.0))),
            ("the time step", time(move |t| t.step = up(0.25))),
            (
                "the smallest step",
                time(move |t| t.min_step = up(t.min_step)),
            ),
            (
                "the release ramp",
                time(move |t| t.release_ramp = up(t.release_ramp)),
            ),
            (
                "the Newton tolerance",
                solver(move |s| s.tolerance = up(s.tolerance)),
            ),
            ("the iterations allowed", solver(|s| s.max_iterations += 1)),
            (
                "the linear solver",
                solver(|s| s.linear = LinearMethod::SparseLu),
            ),
            (
                "stabilisation",
                solver(|s| s.stabilisation = Some(Default::default())),
            ),
            (
                "a symmetry plane",
                Box::new(|m| m.symmetry_planes.push((Vec3::zeros(), Vec3::y()))),
            ),
            ("a record time", Box::new(|m| m.record_times.push(0.5))),
            ("the probes", Box::new(|m| m.probes.clear())),
            (
                "the units",
                Box::new(|m| m.units = crate::model::Units::MmNMpa),
            ),
        ];
        let model = cantilever();
        let base = fingerprint(&model);
        let mut seen = vec![("the model", base)];
        for (what, change) in &changes {
            let mut changed = model.clone();
            change(&mut changed);
            assert_ne!(changed, model, "{what}: the change must change the model");
            let f = fingerprint(&changed);
            if let Some((other, _)) = seen.iter().find(|(_, g)| *g == f) {
                panic!("changing {what} gives the fingerprint of {other}");
            }
            seen.push((what, f));
        }
        // The basis of an unchanged model is still the identity (the changes worked on copies).
        assert_eq!(model.nodes[0].conditions.basis, Mat3::identity());
    }
}
