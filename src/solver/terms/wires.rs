//! Contact between the wires of a device (issue 35, item 1): a wire pressing on another, on itself further
//! along, or on a mirror image across a symmetry cut, as a point term with **coupled** loads (module docs of
//! [`super`]): the force on one wire depends on where the other is.
//!
//! **Where it acts: line to line, by the samples.** Every sample of every wire (the points of
//! [`crate::model::wires`], at most half a radius apart along it) is projected onto the polyline of each wire
//! near it: `y` the closest point, `d = |x − y|`, the gap `g = d − (r_a + r_b)` and the normal `n = (x − y)/d`.
//! The law of the surfaces' contact ([`super::contact`]: `p = ε Φ(λ/ε − g)`, the C¹ ramp `Φ` of half-width
//! `δ` = half the settings' `regularisation`, a multiplier `λ` per sample and wire) gives a line force `p`
//! \[force/length\] and the sample carries `F = ½ p l n`, `l` its tributary reference length (half the arc to
//! each neighbour), and the other wire the reaction `−F` at `y`. Both ways round: the samples of `b` near `a`
//! are projected onto `a` too, each with half the force, so the pair is symmetric and the total force between
//! two wires lying side by side is `p` per unit length, whichever wire's samples carry it. This is the
//! line-to-line contact of Meier, Popp & Wall (2016) with the samples as its quadrature, which, unlike
//! point-to-point contact at the wires' closest points, has a unique closest point for every sample when wires
//! lie parallel. Wires crossing at an angle touch over a short length (`2 √(2 (r_a + r_b) δ_p)` for a
//! penetration `δ_p`, plus the law's band): the samples there, half a radius apart, integrate the force over it
//! (the all-angle blending of Meier et al. is not needed for the force to act at any angle, only for its
//! smoothness at steep crossings, which the test of crossing rods measures against the same integral in closed
//! form). A mirror image `y = M y' + b` passes the reaction back to its wire as `−M F` (the full device's
//! mirror contact acts on the wire that way).
//!
//! **Into the collocated equations.** A force at a sample (parameter `u`) is shared between the two
//! collocation points of its patch around it, `w = 1 − ξ` and `ξ` by its place `ξ` between their parameters
//! (a patch end's share goes to the interior point next to it: the node equations take no line force), as a
//! line force `q_g = Σ w_g F / L_g` with `L_g = Σ w_g l` over the samples: a uniform line force `p` along a
//! wire is then exactly `p` at every collocation point, and `Σ L_g q_g` is the total force. The samples include
//! every collocation point's parameter (besides those half a radius apart), so each interior point has
//! samples on both sides and a positive `L_g` (a fine mesh of high degree has Greville points closer than its
//! knots, between which the plain samples could leave a point none).
//!
//! **Tangent.** With `e = y₁ − y₀` the other wire's segment and `t` the projection's place on it
//! (`t = (x − y₀)·e/|e|²`, held at 0 or 1 beyond its ends), `dd = (I − e aᵀ) dx + (−(1−t) I − e b₀ᵀ) dy₀ +
//! (−t I − e b₁ᵀ) dy₁` with `dt = aᵀ dx + b₀ᵀ dy₀ + b₁ᵀ dy₁`, `a = e/|e|²`, `b₀ = (2t e − e − (x − y₀))/|e|²`,
//! `b₁ = ((x − y₀) − 2t e)/|e|²` (zero where `t` is held), and `dF = ½ l (p' n nᵀ + (p/d)(I − n nᵀ)) dd`
//! (`p' = dp/dg`). The reaction's share also moves with `t` (`dw/du · Δu dt`). The positions `x`, `y₀`, `y₁`
//! are linear in the control points (the samples' basis values), so every block is exact: checked against
//! central differences.
//!
//! **Which pairs.** The candidates — each sample with the segments of other wires within `r_a + r_b` and a
//! margin (the largest radius) — come from the proximity search ([`crate::geometry::proximity::Wires::near`]:
//! an R*-tree, joints and neighbours along the wires left out) at the start of a step. A new search is made when
//! a control point has moved half the margin since the last, at a step's start or after it converged (then the
//! step is solved again if the new candidates touch). A sample takes the nearest of its candidate segments of each
//! wire at every iterate. Only the candidates within half the margin of the law's band at a step's start, or
//! pressing, put their tangent blocks into the coupling (the linear system's pattern): the others cannot press
//! unless they close half a radius within the step, and a model whose wires are nowhere near each other keeps the
//! block solver's patches apart (measured on `designs/aorta_stent.yaml` compacted with the contact on, when a
//! coupling sent the system to the general sparse LU: coupling every candidate kept it there for the whole run,
//! 20.6 s of solver against 4.9 s without the contact). One that
//! presses within a step without its blocks gets its force with no tangent in that step (the iteration still
//! converges to the same equilibrium, more slowly) and its blocks from the next. The coupling only grows while
//! any group is coupled (entries of pairs that parted stay, as zeros), so the pattern is analysed again when a
//! pair brings new entries, not whenever one parts; with none coupled it is emptied and the block solver's
//! patches are apart again.
//!
//! **Augmented Lagrange** as for the surfaces: every step starts with each multiplier set to its pressure at the
//! converged state, and a converged step whose deepest penetration (over the samples) exceeds the tolerance is
//! solved again with the multipliers updated, at most `max_updates` times; past them the run's warnings say so.
//!
//! **Checkpoints.** The multipliers (by sample, wire and image), the update count and the record of unresolved
//! steps are the term's state, which a roll-back restores and a checkpoint keeps; the candidates are not: a
//! restored run searches them again at its first step, so its pattern may come from another candidate set, its
//! factorisations differ in round-off, and its chord iterations (which reuse a factorisation) may stop at
//! another iterate: the run continues to within Newton's tolerance (4e-12 of the length in the test against a
//! tolerance of 1e-9), not bit for bit.

use super::contact::ramp;
use super::{Coupled, InteriorLoad, PointTerm, PointView};
use crate::geometry::proximity::Near;
use crate::math::basis::{BasisTable, BasisWorkspace, nurbs_basis_into};
use crate::math::{KnotVector, Mat3, Real, Vec3};
use crate::model::wires::DeviceWires;
use crate::model::{ContactSettings, Model};
use crate::solver::discretisation::Discretisation;
use crate::solver::state::State;
use nalgebra::RowVector3;
use std::collections::HashMap;

/// One sample of a wire with the candidate segments of one other wire (or image) near it, and its multiplier.
#[derive(Debug, Clone, PartialEq)]
struct Group {
    wire: usize,
    point: usize,
    other: usize,
    image: usize,
    segments: Vec<usize>,
    multiplier: Real,
    /// Whether its tangent blocks are in the coupling (module docs, *Which pairs*).
    coupled: bool,
}

/// Newton iterations of a closest-point projection at most, and their stopping step (a fraction of the
/// parameter range searched).
const PROJECTION_ITERATIONS: usize = 20;
const PROJECTION_TOLERANCE: Real = 1e-13;

/// How far a polyline of samples can lie off its curve, as a fraction of the largest wire radius (twice the
/// `r/32` of the sampling's bound, module docs of [`crate::model::wires`]): a sample further from a polyline
/// than the law's reach by this is clear of the curve.
const CHORD_OF_MARGIN: Real = 1.0 / 16.0;

/// Where a force on a patch at a curve parameter goes: the two collocation points around it (ends' shares
/// moved to their interior neighbours) with their weights, and the weights' derivatives by the parameter.
#[derive(Debug, Clone, Copy)]
struct Share {
    points: [usize; 2],
    weights: [Real; 2],
    slopes: [Real; 2],
}

/// What the tangent of one sample's forces needs from [`WireContact::loads`]: half its tributary length, the
/// image's reflection, the reaction and where the forces went.
struct Loads {
    l: Real,
    m: Mat3,
    reaction: Vec3,
    mine: Share,
    theirs: Share,
}

/// A sample's contact with one other wire at an iterate (module docs).
#[derive(Debug, Clone)]
struct Touch {
    /// The sample's line force `p` \[force/length\] and `dp/dg`.
    pressure: Real,
    slope: Real,
    gap: Real,
    distance: Real,
    normal: Vec3,
    /// The closest point's curve parameter on the other wire; whether it is held at the end of its range.
    u: Real,
    held: bool,
    /// `y'` and `D = |y'|² − (x − y)·y''` there (in the image's coordinates).
    tangent: Vec3,
    denominator: Real,
    /// The other wire's basis there (values and first derivatives, global control point indices from `first`).
    basis: BasisTable,
}

/// The contact between a device's wires (module docs).
pub struct WireContact {
    wires: DeviceWires,
    settings: ContactSettings,
    /// Each patch's collocation points: global index of its first and the parameters.
    points: Vec<(usize, Vec<Real>)>,
    /// Each patch's knots, weights and first control point's global index.
    curves: Vec<(KnotVector, Vec<Real>, usize)>,
    /// Per patch and sample, the tributary reference length \[length\].
    lengths: Vec<Vec<Real>>,
    /// Per collocation point, `L_g` (module docs) \[length\].
    tributary: Vec<Real>,
    groups: Vec<Group>,
    coupling: Vec<(usize, usize)>,
    /// The position of each entry in `coupling`, kept with it.
    index: HashMap<(usize, usize), usize>,
    version: usize,
    /// The control points at the last search (empty before the first) and the search's margin.
    searched: Vec<Vec3>,
    margin: Real,
    /// Updates of the multipliers in the step being solved.
    updates: usize,
    /// The unit of length and the patches' names, for the warnings.
    unit: &'static str,
    time: Real,
    /// Multipliers restored from a checkpoint for groups not searched yet, by group.
    restored: HashMap<Key, Real>,
    /// Committed steps left above the tolerance, the first one's time and the deepest.
    unresolved: usize,
    first: Real,
    deepest: Option<Deepest>,
}

/// A group's identity: its wire, sample, the other wire and the image.
type Key = (usize, usize, usize, usize);

/// The deepest penetration of the committed steps: depth, time, the group's key, and the sample's position.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Deepest {
    depth: Real,
    time: Real,
    key: Key,
    position: Vec3,
}

impl Group {
    fn key(&self) -> Key {
        (self.wire, self.point, self.other, self.image)
    }
}

impl WireContact {
    /// The contact of `model`'s wires under `settings`, no candidates yet (they are searched at the first step).
    pub fn new(model: &Model, disc: &Discretisation, settings: ContactSettings) -> Self {
        let points: Vec<(usize, Vec<Real>)> = (disc.patches.iter())
            .map(|r| {
                (
                    r.offset,
                    (0..r.n).map(|j| disc.points[r.offset + j].u).collect(),
                )
            })
            .collect();
        // Every collocation point's parameter among the samples: each interior point's share of a force then
        // has samples on both sides (its `L_g` is positive) and is linear between them.
        let parameters: Vec<Vec<Real>> = points.iter().map(|(_, u)| u.clone()).collect();
        let wires = DeviceWires::with_parameters(model, &parameters);
        let lengths: Vec<Vec<Real>> = (wires.wires().wires().iter())
            .map(|w| {
                let n = w.arc.len();
                (0..n)
                    .map(|i| 0.5 * (w.arc[(i + 1).min(n - 1)] - w.arc[i.saturating_sub(1)]))
                    .collect()
            })
            .collect();
        let mut tributary = vec![0.0; disc.points.len()];
        for (k, wire) in wires.wires().wires().iter().enumerate() {
            for (i, &u) in wire.parameters.iter().enumerate() {
                let share = share(&points[k], u);
                for (g, w) in share.points.into_iter().zip(share.weights) {
                    tributary[g] += w * lengths[k][i];
                }
            }
        }
        let curves = (model.patches.iter().zip(&disc.patches))
            .map(|(p, r)| {
                (
                    p.curve.knots().clone(),
                    p.curve.weights().to_vec(),
                    r.offset,
                )
            })
            .collect();
        Self {
            curves,
            margin: wires.largest_radius(),
            wires,
            settings,
            points,
            lengths,
            tributary,
            groups: Vec::new(),
            coupling: Vec::new(),
            index: HashMap::new(),
            version: 0,
            searched: Vec::new(),
            updates: 0,
            unit: model.units.length(),
            time: 0.0,
            restored: HashMap::new(),
            unresolved: 0,
            first: 0.0,
            deepest: None,
        }
    }

    /// Half the law's transition band `δ`.
    fn delta(&self) -> Real {
        0.5 * self.settings.regularisation
    }

    /// The sum of the two wires' radii of a group.
    fn reach(&self, g: &Group) -> Real {
        let w = self.wires.wires().wires();
        w[g.wire].radius + w[g.other].radius
    }

    /// The position of sample `i` of patch `k` for the control points `control`.
    fn position(&self, control: &[Vec3], k: usize, i: usize) -> Vec3 {
        let (first, basis) = self.wires.sample(k, i);
        (basis.iter().enumerate())
            .map(|(a, n)| control[first + a] * *n)
            .sum()
    }

    /// The other wire's point at parameter `u` for the control points `control` in the image `(m, b)`: its
    /// position, first and second derivatives, and the basis there.
    fn curve_point(
        &self,
        control: &[Vec3],
        k: usize,
        u: Real,
        (m, b): (Mat3, Vec3),
        work: &mut BasisWorkspace,
        table: &mut BasisTable,
    ) -> [Vec3; 3] {
        let (knots, weights, offset) = &self.curves[k];
        nurbs_basis_into(knots, weights, u, 2, work, table);
        let derivative = |row: &[Real]| -> Vec3 {
            (row.iter().enumerate())
                .map(|(a, n)| control[offset + table.first + a] * *n)
                .sum()
        };
        [
            m * derivative(&table.ders[0]) + b,
            m * derivative(&table.ders[1]),
            m * derivative(&table.ders[2]),
        ]
    }

    /// The contact of `group` at the control points `control` (module docs): the closest point of the other
    /// wire, found by Newton's method on its curve from the nearest point of its polyline, within the run of
    /// candidate segments that point lies in, and the law there.
    fn touch(&self, control: &[Vec3], group: &Group) -> Touch {
        let x = self.position(control, group.wire, group.point);
        let image = self.wires.wires().image_map(group.image);
        let (m, b) = image;
        let parameters = &self.wires.wires().wires()[group.other].parameters;
        // The nearest point of the polyline.
        let mut start = (Real::INFINITY, 0, 0.0);
        for &j in &group.segments {
            let y0 = m * self.position(control, group.other, j) + b;
            let y1 = m * self.position(control, group.other, j + 1) + b;
            let edge = y1 - y0;
            let length2 = edge.norm_squared();
            let t = if length2 > 0.0 {
                ((x - y0).dot(&edge) / length2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let distance = (x - (y0 + edge * t)).norm();
            if distance < start.0 {
                start = (distance, j, t);
            }
        }
        let (polyline, j, t) = start;
        let eps = self.settings.penalty;
        // A polyline further than the law's reach by more than its chords can lie off the curve (a sixteenth of
        // the largest radius: module docs of `crate::model::wires`) is clear of it: no projection.
        let reach = self.reach(group);
        if polyline - reach > group.multiplier / eps + self.delta() + CHORD_OF_MARGIN * self.margin
        {
            return Touch {
                pressure: 0.0,
                slope: 0.0,
                gap: polyline - reach,
                distance: polyline,
                normal: Vec3::zeros(),
                u: parameters[j],
                held: true,
                tangent: Vec3::zeros(),
                denominator: 1.0,
                basis: BasisTable::default(),
            };
        }
        // The run of consecutive candidate segments around it bounds the parameter.
        let at = group.segments.iter().position(|&s| s == j).unwrap_or(0);
        let (mut lo, mut hi) = (at, at);
        while lo > 0 && group.segments[lo - 1] + 1 == group.segments[lo] {
            lo -= 1;
        }
        while hi + 1 < group.segments.len() && group.segments[hi + 1] == group.segments[hi] + 1 {
            hi += 1;
        }
        let (u_lo, u_hi) = (
            parameters[group.segments[lo]],
            parameters[group.segments[hi] + 1],
        );
        let mut u = parameters[j] + (parameters[j + 1] - parameters[j]) * t;
        let (mut work, mut basis) = (BasisWorkspace::new(), BasisTable::default());
        for _ in 0..PROJECTION_ITERATIONS {
            let [y, y1, y2] =
                self.curve_point(control, group.other, u, image, &mut work, &mut basis);
            let denominator = y1.norm_squared() - (x - y).dot(&y2);
            if denominator <= 0.0 {
                break;
            }
            let next = (u + (x - y).dot(&y1) / denominator).clamp(u_lo, u_hi);
            let done = (next - u).abs() <= PROJECTION_TOLERANCE * (u_hi - u_lo);
            u = next;
            if done {
                break;
            }
        }
        let [y, y1, y2] = self.curve_point(control, group.other, u, image, &mut work, &mut basis);
        let d = x - y;
        let distance = d.norm();
        let gap = distance - reach;
        let (phi, dphi) = ramp(group.multiplier / eps - gap, self.delta());
        Touch {
            pressure: eps * phi,
            slope: -eps * dphi,
            gap,
            distance,
            normal: if distance > 0.0 {
                d / distance
            } else {
                Vec3::zeros()
            },
            u,
            held: u <= u_lo || u >= u_hi,
            tangent: y1,
            denominator: y1.norm_squared() - d.dot(&y2),
            basis,
        }
    }

    /// Searches the candidates again at `control` (module docs), keeping the multipliers of the groups found
    /// again; the coupling changes with them. Returns the new groups' gaps and pressures there ([`Self::gaps`]).
    fn search(&mut self, control: &[Vec3]) -> Vec<(Real, Real)> {
        let points = self.wires.points(control);
        let near = self.wires.wires().near(&points, self.margin);
        let mut old = std::mem::take(&mut self.restored);
        old.extend(self.groups.iter().map(|g| (g.key(), g.multiplier)));
        let mut groups: Vec<Group> = Vec::new();
        for Near {
            wire,
            point,
            other,
            segment,
            image,
        } in near
        {
            match groups.last_mut() {
                Some(g) if g.key() == (wire, point, other, image) => {
                    g.segments.push(segment);
                }
                _ => groups.push(Group {
                    wire,
                    point,
                    other,
                    image,
                    segments: vec![segment],
                    coupled: false,
                    multiplier: old
                        .get(&(wire, point, other, image))
                        .copied()
                        .unwrap_or(0.0),
                }),
            }
        }
        self.groups = groups;
        self.searched = control.to_vec();
        let gaps = self.gaps(control);
        self.couple(&gaps);
        gaps
    }

    /// Each group's gap and pressure at `control`, under its multiplier.
    fn gaps(&self, control: &[Vec3]) -> Vec<(Real, Real)> {
        (self.groups.iter())
            .map(|g| {
                let t = self.touch(control, g);
                (t.gap, t.pressure)
            })
            .collect()
    }

    /// Marks the groups whose tangent enters the coupling at the state of their `gaps` ([`Self::gaps`]) — those
    /// within half the margin of the law's band, or pressing, and those marked before (until the next search) —
    /// and, when that brings entries the coupling has not, adds them and changes its version (module docs,
    /// *Which pairs*).
    fn couple(&mut self, gaps: &[(Real, Real)]) {
        let near = self.delta() + 0.5 * self.margin;
        let flags: Vec<bool> = (self.groups.iter().zip(gaps))
            .map(|(g, &(gap, pressure))| g.coupled || gap < near || pressure > 0.0)
            .collect();
        let changed = (self.groups.iter().zip(&flags)).any(|(g, f)| g.coupled != *f);
        for (g, f) in self.groups.iter_mut().zip(flags) {
            g.coupled = f;
        }
        if !(changed || self.version == 0) {
            return;
        }
        // The pattern is analysed again only when an entry is new: entries of groups no longer coupled stay (as
        // zeros) until no group is, when the block solver comes back.
        let wanted = self.pattern();
        if wanted.is_empty() {
            if !self.coupling.is_empty() || self.version == 0 {
                self.coupling.clear();
                self.index.clear();
                self.version += 1;
            }
        } else if wanted.iter().any(|e| !self.index.contains_key(e)) {
            for e in wanted {
                if !self.index.contains_key(&e) {
                    self.index.insert(e, self.coupling.len());
                    self.coupling.push(e);
                }
            }
            self.version += 1;
        }
    }

    /// The coupling of the groups: per group, its rows (the collocation points its force and reactions can
    /// reach) against its columns (the control points of its sample and of its segments' ends).
    fn pattern(&self) -> Vec<(usize, usize)> {
        let mut seen = std::collections::HashSet::new();
        let mut out = Vec::new();
        for g in self.groups.iter().filter(|g| g.coupled) {
            let mut rows = share(&self.points[g.wire], self.parameter(g.wire, g.point))
                .points
                .to_vec();
            let mut columns: Vec<usize> = self.columns(g.wire, g.point).collect();
            let (knots, _, offset) = &self.curves[g.other];
            let degree = knots.degree();
            for &j in &g.segments {
                let (a, b) = (self.parameter(g.other, j), self.parameter(g.other, j + 1));
                rows.extend(reached(&self.points[g.other], a, b));
                let (first, last) = (knots.find_span(a) - degree, knots.find_span(b));
                columns.extend(offset + first..=offset + last);
            }
            for &r in &rows {
                for &c in &columns {
                    if seen.insert((r, c)) {
                        out.push((r, c));
                    }
                }
            }
        }
        out
    }

    /// The curve parameter of sample `i` of patch `k`.
    fn parameter(&self, k: usize, i: usize) -> Real {
        self.wires.wires().wires()[k].parameters[i]
    }

    /// The control points sample `i` of patch `k` depends on.
    fn columns(&self, k: usize, i: usize) -> impl Iterator<Item = usize> + use<> {
        let (first, basis) = self.wires.sample(k, i);
        first..first + basis.len()
    }

    /// Whether a control point has moved half the margin since the last search (or none was made).
    fn stale(&self, control: &[Vec3]) -> bool {
        self.searched.len() != control.len()
            || (self.searched.iter().zip(control)).any(|(a, b)| 2.0 * (a - b).norm() >= self.margin)
    }

    /// The deepest penetration over the groups' `gaps` ([`Self::gaps`]), with its group.
    fn deepest(gaps: &[(Real, Real)]) -> Option<(Real, usize)> {
        (gaps.iter().enumerate())
            .map(|(k, &(gap, _))| (-gap, k))
            .max_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// Sets every multiplier to its pressure in `gaps` ([`Self::gaps`]).
    fn update_multipliers(&mut self, gaps: &[(Real, Real)]) {
        for (g, &(_, p)) in self.groups.iter_mut().zip(gaps) {
            g.multiplier = p;
        }
    }

    /// Pushes the line forces of `group`'s contact `t` (module docs, *Into the collocated equations*) onto
    /// `forces`: the sample's force on its wire's collocation points around it, the reaction on the other's
    /// around the closest point. Returns what the tangent of those forces needs.
    fn loads(&self, g: &Group, t: &Touch, forces: &mut Vec<(usize, Vec3)>) -> Loads {
        let l = 0.5 * self.lengths[g.wire][g.point];
        let force = t.normal * (t.pressure * l);
        let (m, _) = self.wires.wires().image_map(g.image);
        let reaction = -(m * force);
        let mine = share(&self.points[g.wire], self.parameter(g.wire, g.point));
        let theirs = share(&self.points[g.other], t.u);
        for (p, w) in mine.points.into_iter().zip(mine.weights) {
            forces.push((p, force * (w / self.tributary[p])));
        }
        for (p, w) in theirs.points.into_iter().zip(theirs.weights) {
            forces.push((p, reaction * (w / self.tributary[p])));
        }
        Loads {
            l,
            m,
            reaction,
            mine,
            theirs,
        }
    }

    /// What the contact does at `state` ([`WireContactReport`]).
    pub fn report(&self, disc: &Discretisation, state: &State) -> WireContactReport {
        let mut samples = 0;
        let mut force = 0.0;
        let mut penetration: Real = 0.0;
        let mut pairs = Vec::new();
        let mut forces = Vec::new();
        for g in &self.groups {
            let t = self.touch(&state.control, g);
            penetration = penetration.max(-t.gap);
            if t.pressure > 0.0 {
                samples += 1;
                force += 0.5 * t.pressure * self.lengths[g.wire][g.point];
                let x = self.position(&state.control, g.wire, g.point);
                pairs.push((x, x - t.normal * t.distance));
                self.loads(g, &t, &mut forces);
            }
        }
        let mut sums = vec![Vec3::zeros(); disc.points.len()];
        for (g, q) in forces {
            sums[g] += q;
        }
        WireContactReport {
            samples,
            force,
            penetration,
            line_force: sums.iter().map(Vec3::norm).collect(),
            pairs,
        }
    }
}

/// What the wires' contact does at a state, for the run's outputs (`history.csv`'s `wire_*` columns, the field
/// files' `wire_contact_pressure`): of the model as simulated (a symmetry-reduced model's share).
#[derive(Debug, Clone, PartialEq)]
pub struct WireContactReport {
    /// Samples pressing on another wire (a positive line force), each with each wire it presses on.
    pub samples: usize,
    /// The total force between the wires \[force\]: the samples' forces summed over both ways round, each
    /// contact counted once.
    pub force: Real,
    /// The deepest penetration over the samples \[length\] (0 when none).
    pub penetration: Real,
    /// Per collocation point, the magnitude of the wires' line force there \[force/length\].
    pub line_force: Vec<Real>,
    /// Each pressing sample and its closest point on the wire it presses on (on a mirror image for a contact
    /// across a symmetry cut) \[length\]: the contact pairs, drawn in the recording.
    pub pairs: Vec<(Vec3, Vec3)>,
}

/// Where a force at parameter `u` of a patch with collocation points `points` (first global index and
/// parameters) goes (module docs): the interval of parameters around it, an end's share given to its interior
/// neighbour.
fn share(points: &(usize, Vec<Real>), u: Real) -> Share {
    let (first, params) = (points.0, &points.1);
    let n = params.len();
    let k = params[1..n - 1].partition_point(|&p| p <= u).min(n - 2);
    let (a, b) = (params[k], params[k + 1]);
    let xi = ((u - a) / (b - a)).clamp(0.0, 1.0);
    let dxi = if u > a && u < b { 1.0 / (b - a) } else { 0.0 };
    let (mut lo, mut hi) = (k, k + 1);
    let (mut w, mut s) = ([1.0 - xi, xi], [-dxi, dxi]);
    if lo == 0 {
        lo = hi;
        (w, s) = ([1.0, 0.0], [0.0, 0.0]);
    }
    if hi == n - 1 {
        hi = lo;
        (w, s) = ([1.0, 0.0], [0.0, 0.0]);
    }
    Share {
        points: [first + lo, first + hi],
        weights: w,
        slopes: s,
    }
}

/// The collocation points a force anywhere between parameters `a` and `b` of a patch can reach.
fn reached(points: &(usize, Vec<Real>), a: Real, b: Real) -> Vec<usize> {
    let (lo, hi) = (share(points, a.min(b)), share(points, a.max(b)));
    (lo.points[0]..=hi.points[1]).collect()
}

impl PointTerm for WireContact {
    fn name(&self) -> &'static str {
        "wire contact"
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }

    fn interior(&self, _at: &PointView<'_>, _load: &mut InteriorLoad) {}

    fn coupling(&self) -> &[(usize, usize)] {
        &self.coupling
    }

    fn coupling_version(&self) -> usize {
        self.version
    }

    fn coupled(&self, _disc: &Discretisation, state: &State, tangent: bool) -> Option<Coupled> {
        if self.groups.is_empty() {
            return None;
        }
        let (control, index) = (&state.control, &self.index);
        let mut out = Coupled {
            forces: Vec::new(),
            blocks: if tangent {
                vec![Mat3::zeros(); self.coupling.len()]
            } else {
                Vec::new()
            },
        };
        for g in &self.groups {
            let t = self.touch(control, g);
            if !(t.pressure > 0.0 || t.slope < 0.0) {
                continue;
            }
            let Loads {
                l,
                m,
                reaction,
                mine,
                theirs,
            } = self.loads(g, &t, &mut out.forces);
            if !tangent || !g.coupled {
                continue;
            }
            // dF = G dd with dd = dx − dy − y' du and du = aᵀ (dx − dy) + wᵀ dy' (module docs).
            let n = t.normal;
            let nn = n * n.transpose();
            let stiff = (nn * t.slope + (Mat3::identity() - nn) * (t.pressure / t.distance)) * l;
            let (a, w) = if t.held {
                (Vec3::zeros(), Vec3::zeros())
            } else {
                (t.tangent / t.denominator, n * (t.distance / t.denominator))
            };
            let mut add = |col: usize, dd: Mat3, du: RowVector3<Real>| {
                let df = stiff * dd;
                for (p, wp) in mine.points.into_iter().zip(mine.weights) {
                    out.blocks[index[&(p, col)]] += df * (wp / self.tributary[p]);
                }
                for ((p, wp), sp) in
                    (theirs.points.into_iter().zip(theirs.weights)).zip(theirs.slopes)
                {
                    let block = -(m * df) * wp + reaction * du * sp;
                    out.blocks[index[&(p, col)]] += block / self.tributary[p];
                }
            };
            let (first, basis) = self.wires.sample(g.wire, g.point);
            let dd_x = Mat3::identity() - t.tangent * a.transpose();
            for (c, nb) in basis.iter().enumerate() {
                add(first + c, dd_x * *nb, a.transpose() * *nb);
            }
            let offset = self.curves[g.other].2;
            for (c, (r0, r1)) in t.basis.ders[0].iter().zip(&t.basis.ders[1]).enumerate() {
                let du = (w * *r1 - a * *r0).transpose() * m;
                let dd = -m * *r0 - t.tangent * du;
                add(offset + t.basis.first + c, dd, du);
            }
        }
        Some(out)
    }

    fn step_limit(&self, _disc: &Discretisation, state: &State, delta: &[Real]) -> Real {
        // As the surfaces' contact (module docs there): a sample the law does not act on yet stops at the middle
        // of the law's band, the gap along the increment interpolated linearly.
        let moved: Vec<Vec3> = (state.control.iter().enumerate())
            .map(|(k, c)| c + Vec3::new(delta[6 * k], delta[6 * k + 1], delta[6 * k + 2]))
            .collect();
        let mut alpha: Real = 1.0;
        for g in &self.groups {
            let now = self.touch(&state.control, g);
            if now.slope != 0.0 {
                continue;
            }
            let stop = g.multiplier / self.settings.penalty;
            let then = self.touch(&moved, g);
            if then.gap < stop {
                alpha = alpha.min((now.gap - stop) / (now.gap - then.gap));
            }
        }
        alpha
    }

    fn prepare(&mut self, _disc: &Discretisation, state: &State, t: Real) {
        self.time = t;
        self.updates = 0;
        let gaps = if self.stale(&state.control) {
            self.search(&state.control)
        } else {
            let gaps = self.gaps(&state.control);
            self.couple(&gaps);
            gaps
        };
        self.update_multipliers(&gaps);
    }

    fn augment(&mut self, _disc: &Discretisation, state: &State) -> bool {
        let control = &state.control;
        let gaps = if self.stale(control) {
            // The step moved the wires past what the candidates cover: search again, and solve again if a new
            // candidate acts.
            let before: std::collections::HashSet<Key> =
                self.groups.iter().map(Group::key).collect();
            let gaps = self.search(control);
            let band = self.delta();
            let new_touch = (self.groups.iter().zip(&gaps))
                .filter(|(g, _)| !before.contains(&g.key()))
                .any(|(_, &(gap, _))| gap < band);
            if new_touch && self.updates < self.settings.max_updates {
                self.updates += 1;
                return true;
            }
            gaps
        } else {
            self.gaps(control)
        };
        let Some((depth, _)) = Self::deepest(&gaps) else {
            return false;
        };
        if depth <= self.settings.tolerance || self.updates >= self.settings.max_updates {
            return false;
        }
        self.updates += 1;
        self.update_multipliers(&gaps);
        true
    }

    fn commit(&mut self, _disc: &Discretisation, state: &State) {
        let Some((depth, k)) = Self::deepest(&self.gaps(&state.control)) else {
            return;
        };
        if depth <= self.settings.tolerance {
            return;
        }
        if self.unresolved == 0 {
            self.first = self.time;
        }
        self.unresolved += 1;
        if self.deepest.is_none_or(|d| depth > d.depth) {
            let g = &self.groups[k];
            self.deepest = Some(Deepest {
                depth,
                time: self.time,
                key: g.key(),
                position: self.position(&state.control, g.wire, g.point),
            });
        }
    }

    fn warnings(&self) -> Vec<String> {
        let Some(d) = self.deepest else {
            return Vec::new();
        };
        let names = self.wires.names();
        let (wire, point, other, image) = d.key;
        let x = d.position;
        vec![format!(
            "wires pressed into each other beyond the contact tolerance ({:.3e} {unit}) in {} step(s) (first at t = {}) after {} augmented-Lagrange updates: the deepest {:.3e} {unit} at t = {}, patch `{}` at u = {:.4} on patch `{}`{} at ({:.4}, {:.4}, {:.4}); a larger penalty or more `max_updates` in `contact` brings it down",
            self.settings.tolerance,
            self.unresolved,
            self.first,
            self.settings.max_updates,
            d.depth,
            d.time,
            names[wire],
            self.parameter(wire, point),
            names[other],
            if image > 0 { " (its mirror image)" } else { "" },
            x.x,
            x.y,
            x.z,
            unit = self.unit,
        )]
    }

    fn save(&self, out: &mut Vec<Real>) {
        out.extend([self.unresolved as Real, self.first, self.updates as Real]);
        match self.deepest {
            Some(d) => {
                let (a, b, c, e) = d.key;
                out.extend([
                    1.0, d.depth, d.time, a as Real, b as Real, c as Real, e as Real,
                ]);
                out.extend(d.position.iter());
            }
            None => out.extend([0.0; 10]),
        }
        // The groups' multipliers, and those restored for groups not searched again yet, in a fixed order.
        let mut kept: Vec<(Key, Real)> = (self.groups.iter().map(|g| (g.key(), g.multiplier)))
            .chain(self.restored.iter().map(|(k, v)| (*k, *v)))
            .filter(|(_, v)| *v != 0.0)
            .collect();
        kept.sort_by_key(|(k, _)| *k);
        for ((a, b, c, e), v) in kept {
            out.extend([a as Real, b as Real, c as Real, e as Real, v]);
        }
    }

    fn restore(&mut self, values: &[Real]) -> Result<(), usize> {
        /// Counts and the deepest record, then five numbers per multiplier.
        const HEAD: usize = 13;
        if values.len() < HEAD || !(values.len() - HEAD).is_multiple_of(5) {
            return Err(HEAD);
        }
        self.unresolved = values[0] as usize;
        self.first = values[1];
        self.updates = values[2] as usize;
        let key = |v: &[Real]| (v[0] as usize, v[1] as usize, v[2] as usize, v[3] as usize);
        self.deepest = (values[3] == 1.0).then(|| Deepest {
            depth: values[4],
            time: values[5],
            key: key(&values[6..10]),
            position: Vec3::new(values[10], values[11], values[12]),
        });
        self.restored = (values[HEAD..].chunks_exact(5))
            .map(|v| (key(v), v[4]))
            .collect();
        for g in &mut self.groups {
            g.multiplier = self.restored.remove(&g.key()).unwrap_or(0.0);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::WireContact;
    use crate::material::{CircularSection, ElasticLaw};
    use crate::math::{Mat3, Real, Vec3};
    use crate::model::builder::{ConditionSpec, ModelBuilder, PatchShape, TimeSpec};
    use crate::model::{ContactSettings, Model};
    use crate::solver::discretisation::Discretisation;
    use crate::solver::terms::tests::{TOLERANCE, crossing_rods, held_but_z, term_tangent_error};
    use crate::solver::terms::{PointTerm, Terms};
    use crate::solver::tests::deformed_state;

    /// Straight rods of diameter 0.2 given as `(name, from, to)`, each clamped at its start, at degree 4 with
    /// `elements` elements.
    fn rods(rods: &[(&str, Vec3, Vec3)], elements: usize) -> Model {
        let material = ElasticLaw::try_new(2.0e5, 0.3).expect("E > 0, ν = 0.3");
        let section = CircularSection::try_new(0.2).expect("d > 0").into();
        let mut b = ModelBuilder::new("rods", material, section);
        for &(name, from, to) in rods {
            b.patch(name, PatchShape::Line { from, to }, 4, elements);
            b.condition(ConditionSpec::clamp(format!("{name}.start")));
        }
        b.time(TimeSpec::new(1.0, 0.1));
        b.wire_contact(settings());
        b.build().expect("valid model").model
    }

    /// A penalty with forces of the order of the test structure's residual terms, a band of 0.02.
    fn settings() -> ContactSettings {
        ContactSettings {
            penalty: 1e3,
            regularisation: 0.02,
            tolerance: 1e-3,
            max_updates: 5,
        }
    }

    /// Three rods of radius 0.1: `low` along x, `side` beside it 0.19 apart (line contact), `cross` over both
    /// at 60°, 0.17 above (crossings).
    fn three_rods() -> Model {
        let c = Vec3::new(0.5, 0.75_f64.sqrt(), 0.0);
        rods(
            &[
                ("low", Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0)),
                (
                    "side",
                    Vec3::new(-0.8, 0.19, 0.0),
                    Vec3::new(0.8, 0.19, 0.0),
                ),
                (
                    "cross",
                    Vec3::new(0.0, 0.0, 0.17) - c,
                    Vec3::new(0.0, 0.0, 0.17) + c,
                ),
            ],
            8,
        )
    }

    /// Source: the coupled blocks must be the exact derivative of the coupled forces (module docs: positions
    /// linear in the control points, the projection's place differentiated). Reference: central differences of
    /// the term's residual (`term_tangent_error`, step 1e-6, tolerance 1e-6 of the row's largest entry), at the
    /// deformed state of the tangent tests with the candidates searched there; the state has samples clear, in
    /// the law's band and on its linear branch (counted), so pairs switching on and off are in the comparison.
    #[test]
    fn the_wire_contacts_tangent_matches_central_differences() {
        let model = three_rods();
        let disc = Discretisation::new(&model).expect("discretisation");
        let mut contact = WireContact::new(&model, &disc, settings());
        let state = deformed_state(&disc, 0);
        contact.prepare(&disc, &state, 1.0);
        let delta = contact.delta();
        let (mut clear, mut band, mut linear) = (0, 0, 0);
        for g in &contact.groups {
            let t = contact.touch(&state.control, g);
            let x = g.multiplier / contact.settings.penalty - t.gap;
            if x <= -delta {
                clear += 1;
            } else if x < delta {
                band += 1;
            } else {
                linear += 1;
            }
        }
        println!(
            "groups {}, clear {clear}, band {band}, linear {linear}",
            contact.groups.len()
        );
        assert!(
            clear > 0 && band > 0 && linear > 0,
            "clear {clear}, band {band}, linear {linear}"
        );
        let (worst, report) = term_tangent_error(
            &model,
            Terms {
                point: &[&contact],
                constraints: &[],
            },
        );
        println!("worst relative error {worst:.3e}");
        assert!(
            worst < TOLERANCE,
            "worst {worst:.3e}:\n{}",
            report.join("\n")
        );
    }

    /// Two rods of length 2 and diameter 0.2 (E = 2e5, ν = 0.3), clamped at both ends: `low` along x, `high`
    /// along y above it with its ends' centres `0.2 + gap` above `low`'s and pushed down by `push` over t ∈ [0, 1]
    /// (their rotations held), at degree 4 with `elements` elements; the wires' contact with `tolerance`.
    fn crossing_beams(gap: Real, push: Real, elements: usize, tolerance: Real) -> Model {
        let mut b = crossing_rods(0.2 + gap, push, elements, 0.05);
        // The design's default penalty, `E I / d⁴`.
        let penalty = 2.0e5 * std::f64::consts::PI / 64.0;
        b.wire_contact(ContactSettings {
            penalty,
            regularisation: 0.1 * tolerance,
            tolerance,
            max_updates: 10,
        });
        b.build().expect("valid model").model
    }

    /// The force the ends of patch `patch` exert on their nodes, summed: at nodes held there, the reaction on
    /// the patch (the solver's node resultants, not a contact term's report).
    fn end_reaction(sim: &crate::solver::Simulation<'_>, patch: usize) -> Vec3 {
        (sim.model().nodes.iter().enumerate())
            .filter(|(_, n)| n.ends.iter().any(|e| e.patch == patch))
            .flat_map(|(k, _)| sim.node_end_resultants(k))
            .map(|(f, _)| f)
            .sum()
    }

    /// Source: two clamped–clamped beams crossing at right angles and pressed together at their middles are two
    /// springs in series with the contact: the approach of their ends beyond first touch, `push − gap`, is
    /// `w_low + w_high + δ` with each middle's deflection under the contact force `F`, `w = F (L³/(192 E I) +
    /// L/(4 k_s G A))` (Timoshenko beam, central load, small deflection; `k_s` Cowper's factor, the section's),
    /// and the centrelines' penetration `δ` at most the contact tolerance (augmented Lagrange). Measured: the
    /// force in the pushed beam's end reactions (the solver's node resultants, not the contact term's report),
    /// the middles' deflections. The contact force reaches the collocated equations as line forces at the
    /// collocation points around the crossing (module docs): a load spread over about a knot span `h` instead of
    /// a point, which makes the beam stiffer by `O((h/L)²)`. Measured at 8, 16, 32, 64 elements: 19 %, 2.9 %,
    /// 0.63 %, 0.20 % (the deflection of 1/800 of the length keeps the membrane stiffening of the clamped beams
    /// below 0.02 %): the test asserts the error falls at least twofold with each halving of `h` and is under
    /// 0.5 % at 64 elements, the penetration within the tolerance and the two beams deflecting alike.
    #[test]
    fn crossing_rods_pressed_together_deflect_as_clamped_beams_in_series() {
        use crate::material::Section;
        use crate::model::ProbeLocation;
        use crate::solver::Simulation;
        let (gap, push, tolerance) = (0.005, 0.01, 1e-6);
        let section: Section = CircularSection::try_new(0.2).expect("d > 0").into();
        let (e, nu, l): (Real, Real, Real) = (2.0e5, 0.3, 2.0);
        let (i, a) = (section.second_moment(), section.area());
        let g = e / (2.0 * (1.0 + nu));
        let ks = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu);
        let compliance = l.powi(3) / (192.0 * e * i) + l / (4.0 * ks * g * a);
        let closed = (push - gap) / (2.0 * compliance);
        let mut errors = Vec::new();
        for elements in [8, 16, 32, 64] {
            let model = crossing_beams(gap, push, elements, tolerance);
            let mut sim = Simulation::new(&model).expect("simulation");
            while sim.step().expect("converges").is_some() {}
            assert!(sim.warnings().is_empty(), "{:?}", sim.warnings());
            let reaction = end_reaction(&sim, 1).z;
            let middle = |patch| sim.probe_displacement(&ProbeLocation::Patch { patch, u: 0.5 });
            let (w_low, w_high) = (-middle(0).z, middle(1).z + push);
            let force = reaction.abs();
            let error = (force - closed).abs() / closed;
            println!(
                "n = {elements}: reaction {force:.6}, closed form {closed:.6} ({error:.2e}); deflections {w_low:.6e}, {w_high:.6e} against {:.6e}; penetration {:.3e}",
                closed * compliance,
                push - gap - w_low - w_high
            );
            assert!(push - gap - w_low - w_high <= tolerance, "penetration");
            assert!(
                (w_low - w_high).abs() < 1e-6 * w_low,
                "{w_low} against {w_high}"
            );
            errors.push(error);
        }
        assert!(errors.windows(2).all(|e| e[1] < 0.5 * e[0]), "{errors:?}");
        assert!(errors[3] < 5e-3, "{errors:?}");
    }

    /// Source: two parallel rods pressed together along their whole length by opposite uniform line loads `q`
    /// are in equilibrium straight, with the contact carrying `q` at every point: the pressed rod translates
    /// without bending and the rod it lies on carries nothing to its clamps. Exact for this discretisation, not
    /// only in the limit: a uniform pressure along a sampled wire is the same line force at every collocation
    /// point (module docs: `L_g` is the samples' own tributary length). Reference: zero reactions at the lower
    /// rod's clamps and zero bending of the upper rod, to the Newton tolerance (1e-10 of `q L`, 1e-12 of the
    /// length 2); the upper rod's translation, the penetration, within the contact tolerance (augmented
    /// Lagrange brings it to zero: measured 3e-16).
    #[test]
    fn parallel_rods_pressed_along_their_length_carry_a_uniform_line_load() {
        use crate::model::builder::{DistributedLoadSpec, PatchTarget};
        use crate::model::{ProbeLocation, TimeFunction};
        use crate::solver::Simulation;
        let material = ElasticLaw::try_new(2.0e5, 0.3).expect("E > 0, ν = 0.3");
        let section = CircularSection::try_new(0.2).expect("d > 0").into();
        let mut b = ModelBuilder::new("parallel rods", material, section);
        let (q, tolerance) = (2.0, 1e-6);
        for (name, z) in [("low", 0.0), ("high", 0.2)] {
            let line = PatchShape::Line {
                from: Vec3::new(-1.0, 0.0, z),
                to: Vec3::new(1.0, 0.0, z),
            };
            b.patch(name, line, 4, 12);
        }
        b.condition(ConditionSpec::clamp("low.start"));
        b.condition(ConditionSpec::clamp("low.end"));
        for end in ["high.start", "high.end"] {
            b.condition(held_but_z(end));
        }
        let ramp = |v: Real| TimeFunction::try_table(vec![(0.0, 0.0), (1.0, v)]).expect("a ramp");
        for (name, v) in [("low", q), ("high", -q)] {
            b.distributed_load(DistributedLoadSpec {
                patches: PatchTarget::Named(name.into()),
                force: [
                    TimeFunction::constant(0.0),
                    TimeFunction::constant(0.0),
                    ramp(v),
                ],
                couple: std::array::from_fn(|_| TimeFunction::constant(0.0)),
            });
        }
        b.time(TimeSpec::new(1.0, 0.25));
        b.wire_contact(ContactSettings {
            penalty: 2.0e5 * std::f64::consts::PI / 64.0,
            regularisation: 0.1 * tolerance,
            tolerance,
            max_updates: 10,
        });
        let model = b.build().expect("valid model").model;
        let mut sim = Simulation::new(&model).expect("simulation");
        while sim.step().expect("converges").is_some() {}
        assert!(sim.warnings().is_empty(), "{:?}", sim.warnings());
        let reaction = end_reaction(&sim, 0);
        let at = |patch, u| sim.probe_displacement(&ProbeLocation::Patch { patch, u });
        let drop: Vec<Real> = [0.0, 0.1, 0.25, 0.5, 0.8, 1.0]
            .iter()
            .map(|&u| at(1, u).z)
            .collect();
        let bending = drop
            .iter()
            .map(|z| (z - drop[0]).abs())
            .fold(0.0, Real::max);
        println!("reaction {reaction:?} (q L = {}), drops {drop:?}", 2.0 * q);
        assert!(reaction.norm() < 1e-10 * 2.0 * q, "{reaction:?}");
        assert!(bending < 1e-12, "{drop:?}");
        assert!(drop[0].abs() <= tolerance, "{drop:?}");
        let lower = (0..=10)
            .map(|j| at(0, j as Real / 10.0).norm())
            .fold(0.0, Real::max);
        assert!(lower < 1e-10, "the lower rod moved {lower}");
    }

    /// Source: a ring of `N` identical straight struts of diameter `d` parallel to the axis, pushed outward by a
    /// line load and closed on by a crimper, locks when each strut touches its neighbours: their centres on a
    /// regular `N`-gon of side `d` (`N` wire diameters around the circumference at the centres), of
    /// circumradius `R_c = d / (2 sin(π/N))`. The struts follow the crimper (held against it by the load, their
    /// ends free radially only) down to `R_c` and stop there while the crimper closes on 0.01 past it, pressing
    /// the locked ring (a compliant wall: a rigid one would fight the wires' contact, two penalties, for the
    /// same 0.01). Reference: that closed form. Tolerance: the wires' penetration is held within the contact
    /// tolerance `τ` (augmented Lagrange), which lets neighbours' centres come `τ` closer than `d`, the struts
    /// `τ / (2 sin(π/N))` further in.
    #[test]
    fn a_ring_of_struts_locks_at_n_wire_diameters_around() {
        use crate::model::builder::{BasisSpec, DistributedLoadSpec, PatchTarget};
        use crate::model::{Contact, Obstacle, ProbeLocation, Surface, TimeFunction, Wall};
        use crate::solver::Simulation;
        let n = 8;
        let (d, r0, q, tolerance) = (0.2, 0.5, 0.1, 1e-4);
        let locked = d / (2.0 * (std::f64::consts::PI / n as Real).sin());
        let material = ElasticLaw::try_new(2.0e5, 0.3).expect("E > 0, ν = 0.3");
        let section = CircularSection::try_new(d).expect("d > 0").into();
        let mut b = ModelBuilder::new("ring of struts", material, section);
        let constant = TimeFunction::constant;
        for k in 0..n {
            let phi = 2.0 * std::f64::consts::PI * k as Real / n as Real;
            let radial = Vec3::new(0.0, phi.cos(), phi.sin());
            let name = format!("s{k}");
            let line = PatchShape::Line {
                from: Vec3::new(-1.0, 0.0, 0.0) + radial * r0,
                to: Vec3::new(1.0, 0.0, 0.0) + radial * r0,
            };
            b.patch(&name, line, 4, 6);
            let axes = Mat3::from_columns(&[Vec3::x(), radial, Vec3::x().cross(&radial)]);
            for end in ["start", "end"] {
                let mut c = ConditionSpec::at(format!("{name}.{end}"));
                c.basis = Some(BasisSpec::Axes(axes));
                c = c
                    .with_displacement(0, constant(0.0))
                    .with_displacement(2, constant(0.0));
                for i in 0..3 {
                    c = c.with_rotation(i, constant(0.0));
                }
                b.condition(c);
            }
            b.distributed_load(DistributedLoadSpec {
                patches: PatchTarget::Named(name),
                force: [
                    constant(0.0),
                    constant(q * radial.y),
                    constant(q * radial.z),
                ],
                couple: std::array::from_fn(|_| constant(0.0)),
            });
        }
        let settings = ContactSettings {
            penalty: 2.0e5 * std::f64::consts::PI / 64.0,
            regularisation: 0.1 * tolerance,
            tolerance,
            max_updates: 10,
        };
        let closing =
            TimeFunction::try_table(vec![(0.0, r0 + 0.5 * d), (1.0, locked + 0.5 * d - 0.01)])
                .expect("a ramp");
        let crimper = Surface::Cylinder {
            point: Vec3::zeros(),
            axis: Vec3::x(),
            radius: closing,
        };
        // A compliant crimper: closing on past the locked ring it presses with a finite force (its wall's line
        // stiffness `E h b / R²` ≈ 50–150 per unit length times its "penetration").
        let wall = Wall::Compliant {
            modulus: 1e3,
            thickness: 0.1,
            width: d,
        };
        b.contact(Contact {
            obstacles: vec![Obstacle::new("crimper", crimper, wall)],
            settings,
        });
        b.wire_contact(settings);
        b.time(TimeSpec::new(1.0, 0.02));
        let model = b.build().expect("valid model").model;
        let mut sim = Simulation::new(&model).expect("simulation");
        let mut smallest = Real::INFINITY;
        while sim.step().expect("converges").is_some() {
            let middle = sim.probe_displacement(&ProbeLocation::Patch { patch: 0, u: 0.5 });
            smallest = smallest.min((Vec3::new(0.0, r0, 0.0) + middle).norm());
        }
        let within = tolerance / (2.0 * (std::f64::consts::PI / n as Real).sin());
        println!(
            "smallest radius of the struts' centres {smallest:.6}, locked ring {locked:.6} ({:.2e}); warnings {:?}",
            smallest - locked,
            sim.warnings()
        );
        assert!(
            smallest >= locked - within && smallest <= locked + tolerance,
            "{smallest} against {locked}"
        );
    }

    /// A checkpoint keeps the contact's multipliers and record, and the candidates are searched again from the
    /// restored state: a run restored mid-contact ends where the run that went on ends. The crossing beams of
    /// [`crossing_rods_pressed_together_deflect_as_clamped_beams_in_series`] at 16 elements, the checkpoint
    /// after 12 of 20 steps (pressed since the 11th). Reference: the run that went on; tolerance: Newton's
    /// (normalised increments) times the length (the restored run's pattern may be analysed from another set of
    /// candidates, which changes the factorisations' round-off and so where the chord iterations stop, not the
    /// equilibrium).
    #[test]
    fn a_restored_run_ends_where_the_run_that_went_on_ends() {
        use crate::solver::Simulation;
        let model = crossing_beams(0.005, 0.01, 16, 1e-6);
        let mut first = Simulation::new(&model).expect("simulation");
        for _ in 0..12 {
            first.step().expect("converges");
        }
        let checkpoint = first.checkpoint();
        while first.step().expect("converges").is_some() {}
        let mut second = Simulation::new(&model).expect("simulation");
        second.restore(&checkpoint).expect("restores");
        while second.step().expect("converges").is_some() {}
        let apart = (first.state().control.iter().zip(&second.state().control))
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, Real::max);
        println!("apart {apart:.3e}");
        let length = 2.0;
        assert!(apart < model.solver().tolerance * length, "{apart}");
        assert_eq!(first.warnings(), second.warnings());
    }
}
