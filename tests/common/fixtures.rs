//! Models and designs for tests, built in code: [`bend45_builder`], the 45° bend as [`ModelBuilder`] calls;
//! and the designs of `designs/` changed in code instead of by editing their YAML text
//! (`fixtures::straight_stent().crowns(2).time(2.0, 0.01)`), each change a field path and a value applied to
//! the design's tree exactly as `stentkit --set PATH=VALUE` applies it ([`stentkit::design::set`]). A
//! path that names no field of the design format is refused when the design is read (its fields are closed), so
//! a change that no longer applies fails loudly instead of testing the unchanged design — where a text edit
//! (`str::replace`) did nothing silently.
//!
//! [`DesignFixture::design`] and [`DesignFixture::model`] read the changed design in memory;
//! [`DesignFixture::write`] writes it for tests whose command line reads a file (the resolved design, as a run
//! records it: file references made absolute, so it can be written anywhere). Tests of the design language
//! itself (located errors, bad designs, `--set` paths) keep their YAML text.

use std::path::{Path, PathBuf};
use stentkit::design::{Design, DesignError, DesignOverrides, SetOverride, parse_design_with};
use stentkit::material::{ElasticLaw, Section, SectionProperties};
use stentkit::math::{Real, Vec3};
use stentkit::model::builder::{
    ConditionSpec, ModelBuilder, NodeEnds, PatchShape, ProbeAt, TimeSpec,
};
use stentkit::model::{Model, TimeFunction};

/// The 45° bend of designs/bend45.yaml built in code, split into `patches` exact arcs of `45° / patches`
/// each (joined end to start: `b0`, `b1`, …; one patch is `bend`, as in the file), degree `p` and `n` control
/// points per patch, in `steps` load steps. With one patch, p = 6, n = 20 and 10 steps it is the file's model
/// (`designs.rs` checks it).
pub fn bend45_builder(patches: usize, p: usize, n: usize, steps: usize) -> ModelBuilder {
    let material = ElasticLaw::try_new(1e7, 0.0).expect("E > 0, ν = 0");
    let section = Section::try_from_properties(SectionProperties {
        area: 1.0,
        second_moment: 1.0 / 12.0,
        polar_moment: 1.0 / 6.0,
        shear_factor: 5.0 / 6.0,
        drawing_diameter: (4.0 / std::f64::consts::PI).sqrt(),
    })
    .expect("positive properties");
    let mut b = ModelBuilder::new("bend45", material, section);
    let angle = 45.0 / patches as Real;
    let name = |k: usize| {
        if patches == 1 {
            "bend".to_string()
        } else {
            format!("b{k}")
        }
    };
    for k in 0..patches {
        let a = (k as Real * angle).to_radians();
        // Start of arc k on the circle of radius 100 about (0, 100, 0), starting at the origin.
        let start = Vec3::new(100.0 * a.sin(), 100.0 - 100.0 * a.cos(), 0.0);
        let arc = PatchShape::Arc {
            centre: Vec3::new(0.0, 100.0, 0.0),
            start,
            axis: Vec3::z(),
            angle: angle.to_radians(),
        };
        b.patch(name(k), arc, p, n);
    }
    b.node("root", NodeEnds::Named(vec![format!("{}.start", name(0))]));
    for k in 1..patches {
        b.node(
            format!("j{k}"),
            NodeEnds::Named(vec![
                format!("{}.end", name(k - 1)),
                format!("{}.start", name(k)),
            ]),
        );
    }
    b.node(
        "tip",
        NodeEnds::Named(vec![format!("{}.end", name(patches - 1))]),
    );
    b.condition(ConditionSpec::clamp("root"));
    let ramp = TimeFunction::try_table(vec![(0.0, 0.0), (1.0, 600.0)]).expect("increasing times");
    b.condition(ConditionSpec::at("tip").with_force(2, ramp));
    b.time(TimeSpec::new(1.0, 1.0 / steps as Real));
    b.probe("tip", ProbeAt::Node("tip".into()));
    b
}

/// A design of `designs/` and the changes made to it, in order.
#[derive(Debug, Clone)]
pub struct DesignFixture {
    /// The design file, `designs/<name>`.
    file: PathBuf,
    /// The changes, as `--set` overrides.
    sets: Vec<SetOverride>,
}

/// The design `designs/<name>`, unchanged.
pub fn design(name: &str) -> DesignFixture {
    DesignFixture {
        file: super::repo_file(&format!("designs/{name}")),
        sets: Vec::new(),
    }
}

/// The 45° bend (`designs/bend45.yaml`: one arc patch `bend`, p = 6, n = 20, clamped at `root`, tip force 600
/// along z at `tip`, time 1 in steps of 0.1).
pub fn bend45() -> DesignFixture {
    design("bend45.yaml")
}

/// The straight stent of the paper (`designs/straight_stent.yaml`: 6 crowns, quarter symmetry, radial
/// programme, time 3.25 in steps of 2.5e-3).
pub fn straight_stent() -> DesignFixture {
    design("straight_stent.yaml")
}

/// The roll-up of a cantilever by an end couple (`designs/rollup.yaml`).
pub fn rollup() -> DesignFixture {
    design("rollup.yaml")
}

impl DesignFixture {
    /// Sets the field at `path` (as error messages write it: `stent.crowns`, `conditions[1].force[2]`) to
    /// `value`, YAML (`2`, `1.0e-2`, `{p: 6, n: 30}`, `[[0, 90], [3.25, 90]]`).
    #[track_caller]
    pub fn set(mut self, path: &str, value: &str) -> Self {
        let argument = format!("{path}={value}");
        self.sets.push(
            argument
                .parse()
                .unwrap_or_else(|e| panic!("fixture change `{argument}`: {e}")),
        );
        self
    }

    /// Crowns of the generated stent (`stent.crowns`).
    #[track_caller]
    pub fn crowns(self, crowns: usize) -> Self {
        self.set("stent.crowns", &crowns.to_string())
    }

    /// Degree and control points of every patch that takes the design's mesh (`mesh: {p, n}`).
    #[track_caller]
    pub fn mesh(self, p: usize, n: usize) -> Self {
        self.set("mesh", &format!("{{p: {p}, n: {n}}}"))
    }

    /// End time and nominal step (`time.end`, `time.step`; the other time settings kept).
    #[track_caller]
    pub fn time(self, end: Real, step: Real) -> Self {
        self.set("time.end", &format!("{end:?}"))
            .set("time.step", &format!("{step:?}"))
    }

    /// The design read with the changes applied, or why it cannot be.
    pub fn try_design(&self) -> Result<Design, DesignError> {
        let text = std::fs::read_to_string(&self.file)
            .unwrap_or_else(|e| panic!("{}: {e}", self.file.display()));
        parse_design_with(&text, &self.file, &DesignOverrides::sets(self.sets.clone()))
    }

    /// The design read with the changes applied (a panic names the problem).
    #[track_caller]
    pub fn design(&self) -> Design {
        self.try_design()
            .unwrap_or_else(|e| panic!("{} with {:?}: {e}", self.file.display(), self.changes()))
    }

    /// The model of the changed design, which must read without warnings.
    #[track_caller]
    pub fn model(&self) -> Model {
        let design = self.design();
        assert!(
            design.warnings.is_empty(),
            "{} with {:?}: {:?}",
            self.file.display(),
            self.changes(),
            design.warnings
        );
        design.model
    }

    /// The changed design as YAML: the resolved design a run records (the file's own text when nothing is
    /// changed).
    #[track_caller]
    pub fn text(&self) -> String {
        self.design().source
    }

    /// Writes the changed design to `path` (its folder created) and returns `path`.
    #[track_caller]
    pub fn write(&self, path: &Path) -> PathBuf {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).expect("design folder");
        }
        std::fs::write(path, self.text()).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        path.to_path_buf()
    }

    /// The changes, as `--set` arguments.
    fn changes(&self) -> Vec<&str> {
        self.sets.iter().map(|s| s.argument.as_str()).collect()
    }
}
