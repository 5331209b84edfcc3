//! A model's rods as the wire-on-wire proximity search sees them ([`crate::geometry::proximity`], issue 35):
//! each patch sampled into a polyline, its radius, the nodes its ends belong to and the symmetry planes it lies
//! in; and the overlaps of the device's wires at any placement of its control points, located by patch and
//! curve parameter for the user.
//!
//! **Sampling.** Each patch's knot spans cut into equal parts of the parameter, as few as keep every part under
//! half the wire's radius long and at most `SAMPLES_PER_SPAN` = 8 (a fine mesh's short spans take one or two, a
//! coarse one's eight). A curve between two samples lies off its chord by `h²/(8ρ)` at most (`h` the chord, `ρ`
//! the curve's radius of curvature there), which is how much an overlap can be under-reported: for `h ≤ r/2` and
//! a wire bent no tighter than its own radius (`ρ ≥ r`; tighter, it overlaps itself anyway), `r/32`, a third of
//! the tolerance a run warns past without contact (5 % of the diameter). The positions of the samples are linear
//! in the control points (`x(u) = Σ R_a(u) c_a`, the patch's rational basis), so a state's are found with the
//! basis values kept from the start.

use super::{End, Model};
use crate::geometry::proximity::{Candidate, Mirror, Overlap, Search, Wire, Wires};
use crate::math::basis::nurbs_basis;
use crate::math::{Real, Vec3};

/// The most parts of a knot span between samples (module docs).
const SAMPLES_PER_SPAN: usize = 8;

/// The longest part between samples, in wire radii (module docs).
const SEGMENT_OF_RADIUS: Real = 0.5;

/// Overlaps no deeper than this fraction of the largest wire radius are round-off of wires that touch, not
/// overlaps (`check`, `mesh` and the run's first touch).
pub const ROUND_OFF: Real = 1e-9;

/// The control points of `model`'s patches as generated, one patch after another: the reference placement.
pub fn reference_control(model: &Model) -> Vec<Vec3> {
    (model.patches.iter())
        .flat_map(|p| p.curve.points().iter().copied())
        .collect()
}

/// One sample of a patch: the index of its first control point in the model's flat list of control points
/// (the patches' points one after another) and the basis values there.
#[derive(Debug, Clone)]
struct Sample {
    first: usize,
    basis: Vec<Real>,
}

/// The device's wires with their samples (module docs).
pub struct DeviceWires {
    wires: Wires,
    /// Per patch, its samples in order along it.
    samples: Vec<Vec<Sample>>,
    /// Patch names, for the reports.
    names: Vec<String>,
}

impl DeviceWires {
    /// The wires of `model`, their reference arc lengths taken from its patches' curves.
    pub fn new(model: &Model) -> Self {
        Self::with_parameters(model, &[])
    }

    /// [`DeviceWires::new`] with the curve parameters `extra[k]` among patch `k`'s samples too (the wires'
    /// contact samples every collocation point's parameter besides, `crate::solver::terms::wires`); a patch
    /// past the end of `extra` gets none.
    pub fn with_parameters(model: &Model, extra: &[Vec<Real>]) -> Self {
        let mut samples = Vec::with_capacity(model.patches.len());
        let mut wires = Vec::with_capacity(model.patches.len());
        let mut offset = 0;
        let mut ends = vec![[0usize; 2]; model.patches.len()];
        for (k, node) in model.nodes.iter().enumerate() {
            for e in &node.ends {
                ends[e.patch][usize::from(e.end == End::End)] = k;
            }
        }
        for (k, patch) in model.patches.iter().enumerate() {
            let curve = &patch.curve;
            let knots = curve.knots();
            let (lo, hi) = knots.domain();
            let mut parameters = vec![lo];
            let longest = SEGMENT_OF_RADIUS * model.wire_radius(k);
            for w in knots.knots().windows(2) {
                let (a, b) = (w[0], w[1]);
                if !(b > a && a >= lo && b <= hi) {
                    continue;
                }
                // The span's length along its finest parts, then as many parts as keep each under the longest.
                let finest: Vec<Vec3> = (0..=SAMPLES_PER_SPAN)
                    .map(|j| curve.point(a + (b - a) * j as Real / SAMPLES_PER_SPAN as Real))
                    .collect();
                let length: Real = finest.windows(2).map(|q| (q[1] - q[0]).norm()).sum();
                let parts = ((length / longest).ceil() as usize).clamp(1, SAMPLES_PER_SPAN);
                for j in 1..=parts {
                    parameters.push(a + (b - a) * j as Real / parts as Real);
                }
            }
            if let Some(more) = extra.get(k) {
                parameters.extend(more.iter().filter(|&&u| u > lo && u < hi));
                parameters.sort_by(Real::total_cmp);
                let close = 1e-12 * (hi - lo);
                parameters.dedup_by(|b, a| *b - *a <= close);
            }
            let here: Vec<Sample> = parameters
                .iter()
                .map(|&u| {
                    let table = nurbs_basis(knots, curve.weights(), u, 0);
                    Sample {
                        first: offset + table.first,
                        basis: table.ders[0].clone(),
                    }
                })
                .collect();
            let reference: Vec<Vec3> = parameters.iter().map(|&u| curve.point(u)).collect();
            let mut arc = vec![0.0];
            for pair in reference.windows(2) {
                arc.push(arc[arc.len() - 1] + (pair[1] - pair[0]).norm());
            }
            wires.push(Wire {
                parameters,
                arc,
                radius: model.wire_radius(k),
                ends: ends[k],
                lies_in: model.patch_symmetry_plane(k).into_iter().collect(),
            });
            samples.push(here);
            offset += curve.num_points();
        }
        let mirrors = (model.symmetry_planes.iter().enumerate())
            .map(|(plane, (point, normal))| Mirror {
                point: *point,
                normal: *normal,
                nodes: (model.nodes.iter().enumerate())
                    .filter(|(_, n)| model.lies_on_symmetry_plane(plane, &n.position))
                    .map(|(k, _)| k)
                    .collect(),
            })
            .collect();
        Self {
            wires: Wires::new(wires, mirrors, model.nodes.len()),
            samples,
            names: model.patches.iter().map(|p| p.name.clone()).collect(),
        }
    }

    /// The samples' positions for the control points `control` (the patches' points one after another).
    pub fn points(&self, control: &[Vec3]) -> Vec<Vec<Vec3>> {
        (self.samples.iter())
            .map(|patch| {
                (patch.iter())
                    .map(|s| {
                        (s.basis.iter().enumerate())
                            .map(|(a, n)| control[s.first + a] * *n)
                            .sum()
                    })
                    .collect()
            })
            .collect()
    }

    /// The overlaps deeper than `depth` of the wires with control points `control` (deepest first; module docs of
    /// [`crate::geometry::proximity`]).
    pub fn overlaps(&self, control: &[Vec3], depth: Real) -> Vec<Overlap> {
        self.wires.overlaps(&self.points(control), depth)
    }

    /// [`DeviceWires::overlaps`] with the slack of the search (module docs of [`crate::geometry::proximity`]),
    /// up to `margin`.
    pub fn search(&self, control: &[Vec3], depth: Real, margin: Real) -> Search {
        self.wires.search(&self.points(control), depth, margin)
    }

    /// [`DeviceWires::search`] over the candidates of an earlier one alone ([`Wires::recheck`]).
    pub fn recheck(
        &self,
        control: &[Vec3],
        depth: Real,
        margin: Real,
        candidates: &[Candidate],
    ) -> Search {
        (self.wires).recheck(&self.points(control), depth, margin, candidates)
    }

    /// The patches' names, by wire.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The wires as the proximity search sees them.
    pub fn wires(&self) -> &Wires {
        &self.wires
    }

    /// Sample `i` of patch `patch`: the index of its first control point in the model's flat list and the basis
    /// values of the control points from there (its position is `Σ_a basis[a] c[first + a]`).
    pub fn sample(&self, patch: usize, i: usize) -> (usize, &[Real]) {
        let s = &self.samples[patch][i];
        (s.first, &s.basis)
    }

    /// The largest radius of the wires \[length\].
    pub fn largest_radius(&self) -> Real {
        (self.wires.wires().iter())
            .map(|w| w.radius)
            .fold(0.0, Real::max)
    }

    /// Where an overlap is, in words: the two patches and curve parameters, the image, the depth and the point.
    pub fn describe(&self, o: &Overlap, unit: &str) -> String {
        let planes: Vec<String> = (0..usize::BITS as usize)
            .filter(|k| o.image & (1 << k) != 0)
            .map(|k| (k + 1).to_string())
            .collect();
        let image = match planes.len() {
            0 => String::new(),
            1 => format!(" (its mirror image across symmetry plane {})", planes[0]),
            _ => format!(
                " (its mirror image across symmetry planes {})",
                planes.join(" and ")
            ),
        };
        let x = o.a.position;
        format!(
            "patch `{}` at u = {:.4} and patch `{}` at u = {:.4}{image} overlap by {:.4e} {unit} at ({:.4}, {:.4}, {:.4})",
            self.names[o.a.wire],
            o.a.parameter,
            self.names[o.b.wire],
            o.b.parameter,
            o.depth,
            x.x,
            x.y,
            x.z
        )
    }
}
