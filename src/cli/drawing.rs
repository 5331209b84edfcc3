//! What `mesh` and `export` are asked to draw, and what it would cost: the samples along every patch, the
//! tubes' triangles or the print solid's contour, estimated from the model and the arguments before anything
//! is sampled ([`check_drawing`]), and refused above the memory limit designs get
//! ([`crate::design::size::MEMORY_LIMIT_BYTES`]) or, for a print solid, above
//! [`crate::post::print::TIME_LIMIT_SECONDS`], naming the argument to change and a value that fits.

use super::BadInput;
use super::arguments::{count, rounded_up, short, too_costly};
use crate::design::size::{MEMORY_LIMIT_BYTES, human_bytes};
use crate::math::{Real, Short};
use crate::model::Model;
use crate::post::device::{
    BYTES_PER_CENTRELINE_ROW, BYTES_PER_ROD_POINT, BYTES_PER_SHAPE_SAMPLE, BYTES_PER_TUBE_TRIANGLE,
    patch_sizes,
};
use crate::post::print::{
    BYTES_PER_CAPSULE, MAX_SPACING_PER_RADIUS, PrintSettings, PrintSettingsError,
    TIME_LIMIT_SECONDS, estimated_device_print, thinnest_wire,
};

/// The default vertices around a tube of `mesh` and `export` (`--segments`).
pub(crate) const DEFAULT_SEGMENTS: usize = 16;
/// The default samples per control point of `mesh` (`--samples`).
pub(crate) const DEFAULT_SAMPLES: usize = 4;
/// The default rings per patch of `export` (`--rings`).
pub(crate) const DEFAULT_RINGS: usize = 41;

/// How a command samples the device's patches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Sampling {
    /// `mesh --samples`: this many samples per control point of every patch.
    PerPoint(usize),
    /// `export --rings`: about this many samples per patch, taken at a whole number per control point (the
    /// least that gives every patch that many) and decimated ([`crate::post::device::current_device_shapes`]).
    PerPatch(usize),
}

impl Sampling {
    /// The argument as typed.
    fn argument(self) -> String {
        match self {
            Sampling::PerPoint(s) => format!("--samples {s}"),
            Sampling::PerPatch(r) => format!("--rings {r}"),
        }
    }

    /// The count given.
    fn count(self) -> usize {
        match self {
            Sampling::PerPoint(c) | Sampling::PerPatch(c) => c,
        }
    }

    /// The default count (what the ratio of a count to the tubes' segments is judged against).
    fn default_count(self) -> usize {
        match self {
            Sampling::PerPoint(_) => DEFAULT_SAMPLES,
            Sampling::PerPatch(_) => DEFAULT_RINGS,
        }
    }

    /// The least count allowed (`arguments::at_least` on the argument).
    fn least(self) -> usize {
        match self {
            Sampling::PerPoint(_) => 1,
            Sampling::PerPatch(_) => 2,
        }
    }

    /// The same sampling with count `count`.
    fn with(self, count: usize) -> Self {
        match self {
            Sampling::PerPoint(_) => Sampling::PerPoint(count),
            Sampling::PerPatch(_) => Sampling::PerPatch(count),
        }
    }

    /// Per patch of `model`, the samples taken and those kept, in floating point (an absurd count must give
    /// an absurd estimate, not an overflow).
    fn counts(self, model: &Model) -> Vec<(Real, Real)> {
        let points = |k: usize| model.patches[k].curve.num_points().max(1) as Real;
        let per_point = match self {
            Sampling::PerPoint(s) => s as Real,
            Sampling::PerPatch(r) => (0..model.patches.len())
                .map(|k| ((r as Real - 1.0) / points(k)).ceil())
                .fold(1.0, Real::max),
        };
        (0..model.patches.len())
            .map(|k| {
                let taken = per_point * points(k) + 1.0;
                match self {
                    Sampling::PerPoint(_) => (taken, taken),
                    Sampling::PerPatch(r) => (taken, taken.min(r as Real + 1.0)),
                }
            })
            .collect()
    }
}

/// What `mesh` or `export` is asked to draw.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Drawing {
    /// How the patches are sampled.
    pub sampling: Sampling,
    /// Vertices around each tube (`--segments`).
    pub segments: usize,
    /// One print solid instead of tubes.
    pub print: Option<PrintSettings>,
    /// The centrelines (a `.csv` output) instead of a mesh.
    pub centrelines: bool,
}

/// Refuses (exit status 2, [`BadInput`]) drawing `drawing` of `model` before anything is sampled: print
/// settings out of range ([`PrintSettings::resolved`]), or an estimated cost (`DrawingCost`) above the
/// memory limit designs get ([`MEMORY_LIMIT_BYTES`]) or, for a print solid, above [`TIME_LIMIT_SECONDS`];
/// naming the argument to change and the value that fits.
pub(crate) fn check_drawing(model: &Model, drawing: &Drawing) -> anyhow::Result<()> {
    let thinnest = thinnest_wire(model);
    let spacing = match &drawing.print {
        Some(settings) => {
            settings
                .resolved(thinnest)
                .map_err(|e| {
                    let flag = match e {
                        PrintSettingsError::Spacing { spacing, .. } => {
                            format!("--grid {}", short(spacing))
                        }
                        PrintSettingsError::Tolerance { tolerance, .. } => {
                            format!("--deviation {}", short(tolerance))
                        }
                    };
                    BadInput(format!("{flag}: {e}"))
                })?
                .0
        }
        None => 0.0,
    };
    let cost = DrawingCost::of(model, drawing, spacing);
    if cost.fits() {
        return Ok(());
    }
    let unit = model.units.length();
    let (task, mut what) = match (drawing.centrelines, drawing.print.is_some()) {
        (true, _) => ("the centrelines", String::new()),
        (false, true) => (
            "the print solid",
            format!(
                "a contour of about {} triangles on a {} {unit} grid, ",
                count(cost.triangles),
                Short::rounded(spacing, 4)
            ),
        ),
        (false, false) => (
            "the tube mesh",
            format!("about {} triangles, ", count(cost.triangles)),
        ),
    };
    what.push_str(&format!("{} for the samples", human_bytes(cost.sampled)));
    // The grid is to change when it is too fine even at the default sampling.
    let default_sampling = Drawing {
        sampling: drawing.sampling.with(drawing.sampling.default_count()),
        ..*drawing
    };
    let grid_first =
        drawing.print.is_some() && !DrawingCost::of(model, &default_sampling, spacing).fits();
    let (argument, instead) = if grid_first {
        // The grid: the finest spacing, up to the coarsest allowed, that fits.
        let coarsest = MAX_SPACING_PER_RADIUS * thinnest;
        let fits = |h: Real| DrawingCost::of(model, drawing, h).fits();
        let argument = match drawing.print.and_then(|p| p.spacing) {
            Some(h) => format!("--grid {}", short(h)),
            None => format!("--grid (default {})", Short::rounded(spacing, 4)),
        };
        let instead = if fits(coarsest) {
            let h = finest_fitting(spacing, coarsest, fits);
            format!("give a --grid of at least {h} {unit}")
        } else {
            format!("use fewer samples than {}", drawing.sampling.argument())
        };
        (argument, instead)
    } else {
        // The sampling, or the tubes' segments when they are further above their default.
        let count = drawing.sampling.count();
        let segments_first = drawing.print.is_none()
            && !drawing.centrelines
            && drawing.segments * drawing.sampling.default_count() > count * DEFAULT_SEGMENTS;
        if segments_first {
            let most = most_fitting(drawing.segments, |segments| {
                DrawingCost::of(
                    model,
                    &Drawing {
                        segments,
                        ..*drawing
                    },
                    spacing,
                )
                .fits()
            });
            (
                format!("--segments {}", drawing.segments),
                at_most(format!("--segments {most}"), most >= 3),
            )
        } else {
            let most = most_fitting(count, |c| {
                let sampling = drawing.sampling.with(c);
                DrawingCost::of(
                    model,
                    &Drawing {
                        sampling,
                        ..*drawing
                    },
                    spacing,
                )
                .fits()
            });
            (
                drawing.sampling.argument(),
                at_most(
                    drawing.sampling.with(most).argument(),
                    most >= drawing.sampling.least(),
                ),
            )
        }
    };
    Err(too_costly(&argument, task, cost.bytes(), cost.seconds, &what, &instead).into())
}

/// What drawing `drawing` of `model`'s full device costs, estimated before anything is sampled: `sampled`,
/// the memory of the patches' shapes and the rods' points (with the print solid's capsules or the centreline
/// rows) [bytes]; `mesh`, that of the tubes' triangles or of the print solid's contour at grid spacing
/// `spacing` ([`estimated_device_print`]) [bytes]; and the print solid's time [s].
#[derive(Debug, Clone, Copy)]
struct DrawingCost {
    sampled: Real,
    mesh: Real,
    /// The triangles of the tubes or of the print solid's contour.
    triangles: Real,
    seconds: Real,
}

impl DrawingCost {
    fn of(model: &Model, drawing: &Drawing, spacing: Real) -> Self {
        let sizes = patch_sizes(model);
        let counts = drawing.sampling.counts(model);
        let mut cost = Self {
            sampled: 0.0,
            mesh: 0.0,
            triangles: 0.0,
            seconds: 0.0,
        };
        let (mut rod_points, mut rod_segments) = (0.0, 0.0);
        for (&(copies, _), &(taken, kept)) in sizes.iter().zip(&counts) {
            cost.sampled += taken * BYTES_PER_SHAPE_SAMPLE;
            rod_points += copies as Real * kept;
            rod_segments += copies as Real * (kept - 1.0);
        }
        if drawing.centrelines {
            cost.sampled += rod_points * (BYTES_PER_ROD_POINT + BYTES_PER_CENTRELINE_ROW);
        } else if drawing.print.is_none() {
            cost.triangles = rod_segments * drawing.segments as Real * 2.0;
            cost.mesh = cost.triangles * BYTES_PER_TUBE_TRIANGLE;
        } else {
            let kept: Vec<Real> = counts.iter().map(|&(_, kept)| kept).collect();
            let solid = estimated_device_print(model, &kept, spacing);
            let capsules = solid.capsules * BYTES_PER_CAPSULE;
            cost.sampled += rod_points * BYTES_PER_ROD_POINT + capsules;
            cost.mesh = solid.bytes - capsules;
            cost.triangles = solid.contour.triangles;
            cost.seconds = solid.seconds;
        }
        cost
    }

    fn bytes(&self) -> Real {
        self.sampled + self.mesh
    }

    /// Within the memory limit designs get and the print solid's time limit.
    fn fits(&self) -> bool {
        self.bytes() <= MEMORY_LIMIT_BYTES && self.seconds <= TIME_LIMIT_SECONDS
    }
}

/// `give at most {argument}` when that value is `allowed`, else that no value of it fits.
fn at_most(argument: String, allowed: bool) -> String {
    if allowed {
        format!("give at most {argument}")
    } else {
        "no value of it fits: the device is too large to draw".to_string()
    }
}

/// A spacing in `[from, to]` for which `fits` holds, within 1 % of the least, rounded up to three significant
/// digits (`fits` holding at `to`, failing at `from` and only growing with the spacing: bisection on its
/// logarithm).
fn finest_fitting(from: Real, to: Real, fits: impl Fn(Real) -> bool) -> Short {
    let (mut lo, mut hi) = (from.ln(), to.ln());
    while hi - lo > 1e-3 {
        let mid = 0.5 * (lo + hi);
        if fits(mid.exp()) { hi = mid } else { lo = mid }
    }
    let h = hi.exp();
    let rounded = rounded_up(h);
    if rounded.0 <= to && fits(rounded.0) {
        rounded
    } else {
        Short(h)
    }
}

/// The largest count below `from` for which `fits` holds (0 if none), `fits` failing at `from` and only
/// failing more as the count grows (bisection).
fn most_fitting(from: usize, fits: impl Fn(usize) -> bool) -> usize {
    let (mut lo, mut hi) = (0, from);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if fits(mid) { lo = mid } else { hi = mid }
    }
    lo
}
