//! Contact of the rods with surfaces ([`crate::model::Obstacle`]: cylinders that keep the rods inside, planes
//! that keep them on one side; rigid or compliant walls) as a point term (issue 33; DESIGN §9).
//!
//! **Where it acts.** The strong form has no quadrature, so contact enters like the distributed loads: a line
//! force per unit reference length `q = p(g) n` at every interior collocation point (Weeger et al. 2017 collocate
//! rod contact at the Greville points the same way). `g` is the gap of the point's centreline position from the
//! surface minus the wire's radius (the patch section's diameter over two), `n = ∇g` the unit normal into the
//! rods' side: a circular section takes no contact moment. At the patch ends the balance laws are the nodes'
//! equilibrium, which a line force does not enter; a node the wire passes through smoothly is kept out of a
//! wall by the contact of the points next to it.
//!
//! **Corners.** Where wires meet at an angle — a Z-ring's crest, where two straight struts meet, a diamond cell's
//! node — the wire is not smooth and the contact is concentrated there: the crest touches the crimper while the
//! struts beside it are clear. The points next to a corner cannot hold it (the crest would go through the wall
//! while they were held on it, bending the strut over the short length between: on the radial bench a Z-ring of
//! the open-stent example read 1.7 N against the calculator's 4e-5 N). So at a node of two or more ends where
//! no two ends continue into each other (their outward tangents in the reference turn by more than
//! [`SMOOTH_TURN`] from opposite), the law acts at each end as a **concentrated force** on the node: the line
//! force at the end's gap times its tributary length, half the reference arc length to the next collocation
//! point, with its own multiplier (and friction anchor) like any point ([`PointTerm::end`]; its tangent
//! `l ∂q/∂c` joins the node's equilibrium rows). The tributary length is the contact report's trapezoidal
//! weight of the end, so the report's force there is the node's force. A node of one end is left out: on a
//! symmetry cut the wire continues into its mirror image, smoothly; a free tip pressed onto a wall is held by
//! the point next to it, as before. Wires that pass through a node smoothly (a sinusoidal crown's crest) keep
//! the interior points alone, so the corners change nothing for them.
//!
//! **Law.** `p = ε Φ(λ/ε − g)` with the penalty `ε` \[force/length²\], the point's augmented-Lagrange multiplier
//! `λ ≥ 0` \[force/length\] and the C¹ ramp `Φ(x) = 0` for `x ≤ −δ`, `(x + δ)² / (4δ)` for `|x| < δ`, `x` for
//! `x ≥ δ` (`2δ` = the settings' `regularisation`). With `λ = 0` it is 4C's linear–quadratic penalty law
//! (beam-to-solid contact) shifted by `δ` towards the wall, so that its force starts at `g = δ` and the
//! augmented Lagrangian below converges to zero gap rather than to `g = δ`: at a fixed point `λ = ε Φ(λ/ε − g)`
//! on the linear branch, `g = 0` exactly. A compliant wall ([`crate::model::Wall::Compliant`]) uses its physical
//! line stiffness `k b = E_w h b / R²` as `ε`, with `λ = 0` and no updates: its "penetration" is the wall's
//! displacement.
//!
//! **Tangent.** `∂q/∂c = (dp/dg) n nᵀ + p ∇²g` with `dp/dg = −ε Φ'(λ/ε − g)`; the balance law takes `Rᵀ q`, whose
//! derivative under the rotation is the assembly's (module docs of [`super`]).
//!
//! **Augmented Lagrange (Uzawa).** Every step starts with one update: each point's multiplier becomes its pressure at
//! the converged state the step starts from, `λ ← p(g)` ([`PointTerm::prepare`]). A point in contact so carries its
//! pressure into the next step (the penalty then only has to answer the change), and a point that lifts off loses its
//! multiplier within a step or two: a multiplier kept from an earlier contact would push a point away from `λ/ε` off
//! the wall, far beyond the tolerance with a soft penalty. After a step converged, if the largest penetration at a
//! rigid wall exceeds the settings' tolerance — at the collocation points, or between them (below) by no more than the
//! tolerance beyond the deepest point, so that lifting the points lifts it under the tolerance — every point's
//! multiplier becomes its pressure again and the step is solved again from where it converged ([`PointTerm::augment`]);
//! at most `max_updates` times. If the penetration is still above the tolerance then, the step is kept and the run's
//! warnings say so (how many steps, the largest penetration, when first: [`PointTerm::warnings`], into summary.json and
//! on stderr). The multipliers, the step's update count, that record, the friction anchors and work, a lumen's
//! closest-point parameters and the record of penetration anywhere (below) are the term's state: the multipliers start
//! the next step from this one's pressures, a roll-back restores them all, a checkpoint keeps them.
//!
//! **Friction.** An obstacle with a Coulomb coefficient `μ > 0` ([`crate::model::Obstacle::friction`]) adds a
//! tangential line force at every point it presses, regularised by a stick stiffness and a return map (the
//! penalty regularisation of Coulomb's law, Wriggers, *Computational Contact Mechanics*, 2nd ed. 2006, §5.2 and
//! §10.5, as in the penalty friction of beam contact codes; PyElastica regularises by a slip-velocity threshold
//! instead, which needs a velocity a quasi-static step has not). Each point keeps an **anchor** `a`, the term's
//! state. With `d = c − a`, the slip is its tangential part `s = d − n (n·d)`, the trial force `−ε_t s` with the
//! stick stiffness `ε_t` = the law's penalty (`ε`, or `k b` for a compliant wall: the elastic slip before
//! sliding, `μ p / ε_t`, is then of the order of the normal law's own penetration), and the limit `μ p`:
//! - **stick**, `ε_t |s| ≤ μ p`: `q_t = −ε_t s`, `∂q_t/∂c = −ε_t ∂s/∂c`;
//! - **slip**, beyond: `q_t = −μ p e`, `e = s/|s|`, `∂q_t/∂c = −μ (dp/dg) e nᵀ − (μ p/|s|)(I − e eᵀ) ∂s/∂c`;
//!
//! with `∂s/∂c = I − n nᵀ − (n·d) H − n (H d)ᵀ` (`H` the distance's Hessian, the derivative of `n`). The tangent
//! is not symmetric (the collocated system is not anyway). In [`PointTerm::commit`] the anchor of a sliding
//! point moves along `e` until the elastic slip is `μ p / ε_t`, `a ← c − (μ p/ε_t) e` (the return map), and the
//! step's **friction work** `Σ_g l_g μ p (|s| − μ p/ε_t)` (the plastic slip times the limit, `l_g` the point's
//! tributary length) is added up ([`SurfaceContact::friction_work`]); a sticking point keeps its anchor; a
//! point without pressure takes its position as anchor, so a point that touches down slips from where it was
//! at the last converged step. The anchors start at the reference positions; only frictional obstacles keep
//! them. The anchor is a point in space: for the surfaces here (a cylinder's radius and a plane's offset move
//! along their normals) a point that sticks while the surface moves has `d` along the normal, hence no slip;
//! a point sliding across a moving cylinder's curvature picks up an error of the order of its slip times the
//! radius change over the radius.
//!
//! **Lumen.** The distance from a vessel's lumen ([`crate::model::Lumen`]) needs the closest point on its
//! centreline: each point's parameter at the last converged step is kept (term state, set in
//! [`PointTerm::commit`], saved with the rest) and starts the Newton projection of the next step's iterations;
//! a point without one (its first step) is searched from the centreline's samples.
//!
//! **Tributary lengths.** A line force acts per unit reference length; the force a point carries is its line
//! force times its tributary length ([`SurfaceContact::lengths`]): half the chord to each neighbouring
//! collocation point of its patch in the reference, a patch end's share given to the interior point next to it
//! (the law does not act at the ends); they add up to the patch's reference chord polygon, its length for a
//! straight rod.
//!
//! **Penetration anywhere.** The law acts at the collocation points alone: a crest between two of them (a crown between
//! Greville points) can pass through a wall unresisted. After every converged step ([`PointTerm::commit`]) the gap is
//! also checked at the patch ends (nodes, where the law does not act: a crown's tip where crowns are split there) and
//! at `SAMPLES_PER_SPAN` = 4 points per knot span of each patch (the midpoints of the span's quarters; a rod's shape
//! between collocation points is polynomial in each span, and four samples bound a smooth crest's missed depth by
//! `|g''| h²/8` with `h` a quarter span — a sixteenth of a span's curvature term — at four times the collocation
//! points' cost, paid once per step, not per iteration), and the largest penetration into a rigid wall anywhere is
//! found with where it is (obstacle, patch, curve parameter; [`SurfaceContact::penetration_anywhere`]). It drives the
//! augmented-Lagrange updates as far as they can help: a multiplier acts only where the law does, but updating them
//! brings the points towards zero gap, and a crest no deeper than the deepest point by more than the tolerance comes
//! out under it with them; a crest deeper than that needs a finer patch, and the updates do not chase it (on
//! `designs/aorta_stent_in_vessel.yaml` at p = 5, n = 24 the updates left crests 7.6e-3 through the wall against the
//! tolerance 4e-3, at n = 30 4.08e-3 in one step; at n = 32 nothing is left above it). A step whose penetration
//! anywhere exceeds the tolerance is recorded (how many, the deepest with where and when, the first) and the run's
//! warnings say so, advising to refine the patch there — unless the augmented-Lagrange warning already tells it: the
//! collocation points' own penetration above the tolerance, and nothing deeper than it by more than the tolerance
//! elsewhere. The collocation points' gaps there are those the commit's Uzawa record finds (one scan; a lumen's from
//! each point's closest-point parameter, as the law finds them), and a sample's closest point on a lumen is searched
//! from that of the collocation point nearest to it along its patch.
//!
//! **Speed.** Most points touch nothing at most iterations, so the assembly asks a cylinder or a plane for its distance
//! alone first and computes the normal, Hessian and law only for a point within the law's band; the commit scans the
//! collocation points once for the Uzawa record and takes the check between points that the last augmented-Lagrange
//! decision made on the same state. The share of the contact term in the crimped straight stent's solver time is
//! measured by `scripts/contact_share.sh` (the README's contact section, *Speed*).
//!
//! **Obstacles put in place later** ([`crate::model::Obstacle::active`]: a sheath, a vessel the programmed
//! device is deployed in) are checked when they arrive: at the converged state of the step that ends at their
//! `from`, a wire deeper through the surface than the tolerance is recorded (the deepest: which obstacle,
//! when, where) and said in the run's warnings — the law would push it out in one step, which is not a
//! deployment. (Obstacles in place from the start are checked by the model's builder, located in the design.)
//!
//! **Switching in and out.** Three things keep Newton going where points enter and leave contact, each
//! measured on the contact map of `stentkit study stability` (one crown crimped by a cylinder closing 5 mm
//! inside it and opening again, 8 cases of time step and penalty) and on `designs/straight_stent_crimped.yaml`:
//! - **A C¹ law**: the tangent is continuous across the band `2δ` (the friction force is continuous too, its
//!   tangent jumps between stick and slip).
//! - **An extrapolated start**: a model with contact starts each step's iteration from the last step's
//!   increment ([`crate::model::SolverSettings::for_contact`]), so a point that a moving surface carries starts
//!   near where the surface will hold it rather than a whole step's travel through it.
//! - **A step limit** ([`PointTerm::step_limit`], applied to the first increment of each Newton solve, the one
//!   that answers the step's change of loads and surfaces with the tangent of the step's start): a point the
//!   law does not act on there (no stiffness in the tangent) cannot be stopped by the linear solve, and an
//!   opening crimper lets a crimped device spring back in one linearised step far through it (the map: a first
//!   increment of 0.6 of a wire's length, the next iterate meeting a penalty force of the step's whole travel).
//!   The increment is scaled so that no such point goes beyond the middle of the law's band (`g = λ/ε`, where
//!   the law's stiffness is half the penalty; the gap along the scaled increment, interpolated linearly); the
//!   iteration then goes on by the chord method's rule (a fresh tangent after a limited step cost more
//!   iterations on the map, up to 23 in a step against 11). Limiting the later corrections too steered the
//!   flattest Z-ring of the open-stent comparison (336 struts at 10°) to another equilibrium, its crests
//!   through the crimper and its contact force 11 % out of the ring's plane: the first increment is where the
//!   overshoot is. IPC's filtered line search (Li et al., *Incremental Potential Contact*, 2020) limits a
//!   step to where the first contact begins in the same way; a penalty law can let the point into its band,
//!   where its stiffness is. The increment's norm that the stopping rule reads is Newton's, before the limit;
//!   [`crate::solver::NewtonReport::limited`] counts the limited iterations.
//!
//! On the map (at p = 4, n = 12 with the paper's rotation field, when these were measured), with all three every
//! case converged without a cut (at n = 24 with the objective field, the map's model since, one case cuts once:
//! docs/speed.md's table); with the
//! extrapolated start and without the limit, the penalty 1 N/mm² cuts 8 to 10 times while opening at every
//! time step and h = 0.05 s with 10 N/mm² fails there; with neither (the map had a ninth case then, 0.025 s at
//! 10 N/mm²), 6 of the 9 failed and 2 crawled through the opening with 606 and 849 cuts. No active-set
//! hysteresis is added: with the limit, a point enters the tangent as soon as it enters the band.

pub(crate) mod report;

pub use report::{Apposition, ContactReport, ObstacleReport};

use super::{EndLoad, InteriorLoad, PointTerm, PointView};
use crate::math::basis::nurbs_basis;
use crate::math::quote::quoted;
use crate::math::{Mat3, Real, Vec3};
use crate::model::{ContactSettings, Distance, End, Model, Obstacle, Surface, Wall};
use crate::solver::assembly::{ARC_LENGTH_PARTS, arc_length_between};
use crate::solver::discretisation::{Discretisation, point_increment, point_position};
use crate::solver::state::State;

/// The C¹ ramp `Φ(x)` of the contact law and its derivative (module docs), with half-width `delta`.
pub(crate) fn ramp(x: Real, delta: Real) -> (Real, Real) {
    if x <= -delta {
        (0.0, 0.0)
    } else if x >= delta {
        (x, 1.0)
    } else {
        (
            (x + delta) * (x + delta) / (4.0 * delta),
            (x + delta) / (2.0 * delta),
        )
    }
}

/// Sample points per knot span where the penetration is checked between the collocation points (module docs).
pub const SAMPLES_PER_SPAN: usize = 4;

/// The tributary reference length of every collocation point (module docs): half the chord to each neighbour
/// of its patch, the share of a patch end where the law does not act given to the interior point next to it
/// (zero at that end); at a corner's end (`acts`), half the reference arc length to its neighbour — the
/// contact report's trapezoidal weight there, so that the report's force is the node's concentrated force.
fn tributary_lengths(
    model: &Model,
    disc: &Discretisation,
    reference: &[Vec3],
    acts: &[bool],
) -> Vec<Real> {
    let mut lengths = vec![0.0; disc.points.len()];
    for (range, patch) in disc.patches.iter().zip(&model.patches) {
        let (first, last) = (range.offset, range.offset + range.n - 1);
        for g in first..last {
            let chord = (reference[g + 1] - reference[g]).norm();
            for (end, inner) in [(g, g + 1), (g + 1, g)] {
                if !disc.is_end(end) {
                    lengths[end] += 0.5 * chord;
                } else if acts[end] {
                    let (a, b) = (disc.points[g].u, disc.points[g + 1].u);
                    lengths[end] += 0.5 * arc_length_between(&patch.curve, a, b, ARC_LENGTH_PARTS);
                } else if !disc.is_end(inner) {
                    lengths[inner] += 0.5 * chord;
                }
            }
        }
    }
    lengths
}

/// The largest turn \[rad\] between two ends of a node that still counts as the wire passing smoothly through it
/// (module docs, *Corners*): well above the fitted patches' own mismatch of end tangents, well below any kink a
/// design draws.
pub const SMOOTH_TURN: Real = 1e-2;

/// Whether the contact law acts at each collocation point (module docs, *Corners*): at every interior point,
/// and at the ends of a corner — a node whose wires, with their mirror images across the symmetry planes the
/// node lies on, meet in two or more directions of which no two continue into each other within [`SMOOTH_TURN`]
/// (a Z-ring's crest, whole or cut by a mirror plane; struts meeting at an angle). Not at a node through which a
/// wire passes smoothly (a sinusoidal crown's crest, also where a bridge joins it or a symmetry plane cuts it),
/// nor at a free tip.
fn acting_points(model: &Model, disc: &Discretisation) -> Vec<bool> {
    let mut acts: Vec<bool> = (0..disc.points.len()).map(|g| !disc.is_end(g)).collect();
    let smooth = -SMOOTH_TURN.cos();
    for node in &model.nodes {
        // The outward unit tangent of each end in the reference, and their mirror images.
        let mut outward: Vec<Vec3> = (node.ends.iter())
            .map(|e| {
                let curve = &model.patches[e.patch].curve;
                let (lo, hi) = curve.knots().domain();
                let (u, sign) = match e.end {
                    End::Start => (lo, -1.0),
                    End::End => (hi, 1.0),
                };
                curve.derivatives(u, 1)[1].normalize() * sign
            })
            .collect();
        for (plane, (_, normal)) in model.symmetry_planes.iter().enumerate() {
            if model.lies_on_symmetry_plane(plane, &node.position) {
                let images: Vec<Vec3> = (outward.iter())
                    .map(|t| t - normal * (2.0 * t.dot(normal)))
                    .collect();
                outward.extend(images);
            }
        }
        let passes = (0..outward.len())
            .any(|a| (a + 1..outward.len()).any(|b| outward[a].dot(&outward[b]) <= smooth));
        if outward.len() >= 2 && !passes {
            for e in &node.ends {
                acts[disc.end_point(*e)] = true;
            }
        }
    }
    acts
}

/// The sample points of every patch (module docs): its two ends, and `SAMPLES_PER_SPAN` per non-empty knot
/// span at the midpoints of its equal parts.
fn samples(model: &Model, disc: &Discretisation) -> Vec<Sample> {
    let mut out = Vec::new();
    for (patch, (p, range)) in model.patches.iter().zip(&disc.patches).enumerate() {
        let knots = p.curve.knots();
        let (lo, hi) = knots.domain();
        let points = &disc.points[range.offset..range.offset + range.n];
        let mut sample = |u: Real| {
            let table = nurbs_basis(knots, p.curve.weights(), u, 0);
            let near = (points.iter().enumerate())
                .min_by(|a, b| (a.1.u - u).abs().total_cmp(&(b.1.u - u).abs()))
                .map_or(range.offset, |(i, _)| range.offset + i);
            out.push(Sample {
                patch,
                u,
                first: range.offset + table.first,
                basis: table.ders[0].clone(),
                near,
            });
        };
        sample(lo);
        sample(hi);
        for w in knots.knots().windows(2) {
            let (a, b) = (w[0], w[1]);
            if !(b > a && a >= lo && b <= hi) {
                continue;
            }
            for j in 0..SAMPLES_PER_SPAN {
                sample(a + (b - a) * (j as Real + 0.5) / SAMPLES_PER_SPAN as Real);
            }
        }
    }
    out
}

/// The contact of one point with one obstacle at the current iterate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointContact {
    /// The gap: distance from the surface minus the wire radius \[length\] (negative: penetration).
    pub gap: Real,
    /// The pressure `p ≥ 0` \[force/length\].
    pub pressure: Real,
    /// `dp/dg` \[force/length²\].
    pub stiffness: Real,
    /// The surface's distance, normal and Hessian at the point.
    pub distance: Distance,
}

/// Contact of every rod with every obstacle (module docs).
#[derive(Debug, Clone)]
pub struct SurfaceContact {
    obstacles: Vec<Obstacle>,
    settings: ContactSettings,
    /// Wire radius per patch \[length\].
    radius: Vec<Real>,
    /// Name of each patch (warnings).
    patches: Vec<String>,
    /// The time the surfaces are at (the end of the step being solved).
    time: Real,
    /// Augmented-Lagrange multipliers per obstacle and collocation point \[force/length\].
    multipliers: Vec<Vec<Real>>,
    /// Augmented-Lagrange updates made in the step being solved.
    updates: usize,
    /// Steps kept with the penetration above the tolerance after every update: how many, the largest
    /// penetration, the first step's time.
    unresolved: Unresolved,
    /// Friction anchors per obstacle and collocation point \[length\] (module docs; empty for a frictionless
    /// obstacle).
    anchors: Vec<Vec<Vec3>>,
    /// Friction work dissipated per obstacle: in the last committed step, and since the start \[force·length\].
    work: Vec<[Real; 2]>,
    /// A lumen's closest centreline parameter per obstacle and collocation point at the last converged step,
    /// the first guess of its search (NaN: none; empty for the other surfaces; module docs).
    hints: Vec<Vec<Real>>,
    /// Tributary reference length of each collocation point \[length\] (module docs; zero at a patch end where
    /// the law does not act).
    lengths: Vec<Real>,
    /// Whether the law acts at each collocation point: the interior points and the corners' ends (module docs,
    /// *Corners*).
    acts: Vec<bool>,
    /// The sample points between the collocation points (module docs).
    samples: Vec<Sample>,
    /// Committed steps whose largest penetration anywhere exceeded the tolerance (module docs).
    between: Between,
    /// Obstacles put in place (after the start) through the wires: how many, and the deepest.
    placed: Placed,
    /// Each point's pressure `(obstacle, point, p)` at the last committed state, which the next step's Uzawa
    /// update takes ([`PointTerm::prepare`]); `None` before the first commit and after the term's state was
    /// restored (found from the state then). Not state: a roll-back returns to the committed state.
    committed: Option<Vec<(usize, usize, Real)>>,
    /// The penetration anywhere that the last [`PointTerm::augment`] of the step in progress found, when it
    /// stopped the updates: the state it judged is the one committed next (the step is committed right after
    /// the updates stop), so the commit's check takes it rather than scanning again. `None` otherwise; cleared
    /// by [`PointTerm::prepare`]. Not state.
    checked: Option<Option<Penetration>>,
}

/// Obstacles put in place through the wires (module docs): how many, and where the deepest went in.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Placed {
    count: usize,
    /// The deepest penetration \[length\], the obstacle's index, the time, and the point.
    largest: Real,
    obstacle: usize,
    time: Real,
    at: Vec3,
}

/// A point of a patch between its collocation points where the penetration is checked (module docs): its
/// patch, curve parameter, basis values `N` of the control points `first ..= first + p`, and the collocation
/// point nearest to it along the patch (whose closest point on a lumen starts its search).
#[derive(Debug, Clone)]
struct Sample {
    patch: usize,
    u: Real,
    first: usize,
    basis: Vec<Real>,
    near: usize,
}

/// The largest penetration of the rods into a rigid wall anywhere along them, at the collocation points or
/// between them (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Penetration {
    /// The penetration (the gap's negative) \[length\]; positive into the wall.
    pub depth: Real,
    /// The obstacle's index.
    pub obstacle: usize,
    /// The patch's index.
    pub patch: usize,
    /// The parameter of the patch's curve where it is.
    pub u: Real,
}

impl Penetration {
    /// `current`, or the penetration `depth` of obstacle `obstacle` at curve parameter `u` of patch `patch` where
    /// that is positive and deeper.
    fn deeper(
        current: Option<Penetration>,
        depth: Real,
        obstacle: usize,
        patch: usize,
        u: Real,
    ) -> Option<Penetration> {
        if depth > 0.0 && current.is_none_or(|d| depth > d.depth) {
            Some(Penetration {
                depth,
                obstacle,
                patch,
                u,
            })
        } else {
            current
        }
    }
}

/// Committed steps whose penetration anywhere exceeded the tolerance: how many, the deepest (where, when), the
/// first step's time.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Between {
    steps: usize,
    deepest: Option<Penetration>,
    deepest_time: Real,
    first: Real,
}

/// The friction of one point at the current iterate (module docs): the tangential line force, its derivative
/// with respect to the point's position, and the slip from the anchor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Traction {
    /// Tangential line force on the rod \[force/length\].
    pub force: Vec3,
    /// Its derivative with respect to the point's position \[force/length²\].
    pub derivative: Mat3,
    /// The slip `s` from the anchor (tangential) \[length\].
    pub slip: Vec3,
    /// The limit `μ p` \[force/length\].
    pub limit: Real,
    /// Whether the point slides (`ε_t |s| > μ p`) rather than sticks.
    pub sliding: bool,
}

/// Steps that ran out of augmented-Lagrange updates (module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Unresolved {
    steps: usize,
    largest: Real,
    first: Real,
}

impl SurfaceContact {
    /// The contact of `model`'s rods with `obstacles` under `settings`, multipliers zero, surfaces at `t = 0`.
    pub fn new(
        model: &Model,
        disc: &Discretisation,
        obstacles: Vec<Obstacle>,
        settings: ContactSettings,
    ) -> Self {
        let radius = model
            .patches
            .iter()
            .map(|p| 0.5 * model.sections[p.section].diameter())
            .collect();
        let multipliers = vec![vec![0.0; disc.points.len()]; obstacles.len()];
        let reference: Vec<Vec3> = (0..disc.points.len())
            .map(|g| point_position(disc, &disc.control0, g))
            .collect();
        let anchors = obstacles
            .iter()
            .map(|o| {
                if o.friction > 0.0 {
                    reference.clone()
                } else {
                    Vec::new()
                }
            })
            .collect();
        let work = vec![[0.0; 2]; obstacles.len()];
        let acts = acting_points(model, disc);
        let hints = obstacles
            .iter()
            .map(|o| match o.surface {
                Surface::Lumen(_) => vec![Real::NAN; disc.points.len()],
                _ => Vec::new(),
            })
            .collect();
        Self {
            obstacles,
            settings,
            radius,
            patches: model.patches.iter().map(|p| p.name.clone()).collect(),
            time: 0.0,
            multipliers,
            updates: 0,
            unresolved: Unresolved::default(),
            anchors,
            work,
            hints,
            lengths: tributary_lengths(model, disc, &reference, &acts),
            acts,
            samples: samples(model, disc),
            between: Between::default(),
            placed: Placed::default(),
            committed: None,
            checked: None,
        }
    }

    /// The tributary reference length of each collocation point (module docs) \[length\]: a line force at
    /// point `g` times `lengths()[g]`, summed, is the force on the rods.
    pub fn lengths(&self) -> &[Real] {
        &self.lengths
    }

    /// Whether the law acts at collocation point `g`: an interior point, or a corner's end (module docs,
    /// *Corners*).
    pub fn acts_at(&self, g: usize) -> bool {
        self.acts[g]
    }

    /// Friction work dissipated at obstacle `k` in the last committed step and since the start
    /// \[force·length\] (module docs).
    pub fn friction_work(&self, k: usize) -> (Real, Real) {
        let [step, total] = self.work[k];
        (step, total)
    }

    /// The friction of the point at `x` (collocation point `g`) with obstacle `k`, in contact `c` (module
    /// docs); `None` for a frictionless obstacle or a point without pressure.
    pub fn friction(&self, k: usize, g: usize, x: &Vec3, c: &PointContact) -> Option<Traction> {
        let mu = self.obstacles[k].friction;
        if mu == 0.0 || c.pressure == 0.0 {
            return None;
        }
        let stick = self.law(k, g).0;
        let (n, h) = (c.distance.normal, c.distance.hessian);
        let d = x - self.anchors[k][g];
        let normal = n.dot(&d);
        let slip = d - n * normal;
        // s = d − n (n·d), ∂n/∂x = H: ∂s/∂x = I − n nᵀ − (n·d) H − n (H d)ᵀ.
        let ds = Mat3::identity() - n * n.transpose() - h * normal - n * (h * d).transpose();
        let limit = mu * c.pressure;
        let length = slip.norm();
        if stick * length <= limit {
            return Some(Traction {
                force: -slip * stick,
                derivative: -ds * stick,
                slip,
                limit,
                sliding: false,
            });
        }
        let e = slip / length;
        // q = −μ p e with ∂p/∂x = (dp/dg) n and ∂e/∂s = (I − e eᵀ) / |s|.
        let derivative = -e * n.transpose() * (mu * c.stiffness)
            - (Mat3::identity() - e * e.transpose()) * ds * (limit / length);
        Some(Traction {
            force: -e * limit,
            derivative,
            slip,
            limit,
            sliding: true,
        })
    }

    /// The largest penetration into a rigid wall anywhere along the rods of `state`: at the interior collocation
    /// points and at the sample points between them (module docs); `None` where nothing penetrates.
    pub fn penetration_anywhere(
        &self,
        disc: &Discretisation,
        state: &State,
    ) -> Option<Penetration> {
        self.penetration_between(state, self.rigid_contact(disc, state).0)
    }

    /// The deeper of `deepest` (the collocation points' own, [`SurfaceContact::rigid_contact`]) and the largest
    /// penetration into a rigid wall at the sample points of `state` between the collocation points.
    fn penetration_between(
        &self,
        state: &State,
        mut deepest: Option<Penetration>,
    ) -> Option<Penetration> {
        let walls: Vec<usize> = (self.obstacles.iter().enumerate())
            .filter(|(_, o)| o.wall == Wall::Rigid && o.is_active(self.time))
            .map(|(k, _)| k)
            .collect();
        if walls.is_empty() {
            return deepest;
        }
        for sample in &self.samples {
            let x: Vec3 = sample
                .basis
                .iter()
                .enumerate()
                .map(|(a, n)| state.control[sample.first + a] * *n)
                .sum();
            for &k in &walls {
                let hint = self.hint(k, sample.near);
                if let Some(d) = self.obstacles[k]
                    .surface
                    .distance_value(&x, self.time, hint)
                {
                    let depth = self.radius[sample.patch] - d;
                    deepest = Penetration::deeper(deepest, depth, k, sample.patch, sample.u);
                }
            }
        }
        deepest
    }

    /// The obstacles.
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// The penalty and multiplier of obstacle `k` at point `g` (a compliant wall: its line stiffness, no
    /// multiplier; on a lumen, of the radius where the point's closest point was at the last converged step —
    /// the foundation's stiffness lags the point's slide along the vessel by a step).
    pub(crate) fn law(&self, k: usize, g: usize) -> (Real, Real) {
        let obstacle = &self.obstacles[k];
        if obstacle.wall == Wall::Rigid {
            return (self.settings.penalty, self.multipliers[k][g]);
        }
        match obstacle
            .surface
            .wall_radius(self.time, self.hint(k, g))
            .and_then(|r| obstacle.wall.line_stiffness(r))
        {
            Some(stiffness) => (stiffness, 0.0),
            None => (self.settings.penalty, self.multipliers[k][g]),
        }
    }

    /// The law's pressure `p` and `dp/dg` at point `g` of obstacle `k` for the gap `gap` (module docs).
    fn pressure(&self, k: usize, g: usize, gap: Real) -> (Real, Real) {
        let (penalty, multiplier) = self.law(k, g);
        let (phi, slope) = ramp(
            multiplier / penalty - gap,
            0.5 * self.settings.regularisation,
        );
        (penalty * phi, -penalty * slope)
    }

    /// The contact of the point at `x` on patch `patch` (collocation point `g`) with obstacle `k`; `None` where
    /// the surface has no normal there (a cylinder's axis) and while the obstacle is not in place
    /// ([`Obstacle::is_active`]).
    pub fn at(&self, k: usize, g: usize, patch: usize, x: &Vec3) -> Option<PointContact> {
        let obstacle = &self.obstacles[k];
        if !obstacle.is_active(self.time) {
            return None;
        }
        let hint = self.hint(k, g);
        let distance = obstacle.surface.distance_near(x, self.time, hint)?;
        let gap = distance.value - self.radius[patch];
        let (pressure, stiffness) = self.pressure(k, g, gap);
        Some(PointContact {
            gap,
            pressure,
            stiffness,
            distance,
        })
    }

    /// Whether obstacle `k` certainly does nothing to the point at `x` (collocation point `g` on `patch`): not
    /// in place, or a cylinder or plane whose distance alone (without the normal and Hessian that
    /// [`SurfaceContact::at`] computes) puts the point beyond the law's band or on the axis. The assembly asks this
    /// first at every point of every iteration, where most points touch nothing (module docs, *Speed*); a lumen's
    /// distance costs its closest-point search either way, so it is not asked twice.
    fn out_of_reach(&self, k: usize, g: usize, patch: usize, x: &Vec3) -> bool {
        let obstacle = &self.obstacles[k];
        if !obstacle.is_active(self.time) {
            return true;
        }
        if matches!(obstacle.surface, Surface::Lumen(_)) {
            return false;
        }
        obstacle
            .surface
            .distance_value(x, self.time, None)
            .is_none_or(|d| self.pressure(k, g, d - self.radius[patch]) == (0.0, 0.0))
    }

    /// Calls `visit(obstacle, point, gap)` with the gap (distance from the surface minus the wire radius; `None`
    /// where it has none or the obstacle is not in place) of every interior collocation point of `state` at
    /// every rigid wall: the distances alone (no normal, no Hessian), as [`SurfaceContact::at`] finds them. A
    /// point's position is computed once for all the walls, and not at all while none is in place.
    fn rigid_gaps(
        &self,
        disc: &Discretisation,
        state: &State,
        mut visit: impl FnMut(usize, usize, Option<Real>),
    ) {
        let rigid: Vec<(usize, bool)> = (self.obstacles.iter().enumerate())
            .filter(|(_, o)| o.wall == Wall::Rigid)
            .map(|(k, o)| (k, o.is_active(self.time)))
            .collect();
        let any = rigid.iter().any(|&(_, active)| active);
        for (g, point) in disc.points.iter().enumerate() {
            if !self.acts[g] {
                continue;
            }
            let x = any.then(|| point_position(disc, &state.control, g));
            for &(k, active) in &rigid {
                let gap = x
                    .filter(|_| active)
                    .and_then(|x| {
                        self.obstacles[k]
                            .surface
                            .distance_value(&x, self.time, self.hint(k, g))
                    })
                    .map(|d| d - self.radius[point.patch]);
                visit(k, g, gap);
            }
        }
    }

    /// The largest penetration at the rigid walls over the interior collocation points of `state` (where the
    /// law acts; `None` if none), and each such point's pressure `(obstacle, point, p)` into `pressures` if
    /// given.
    fn rigid_points(
        &self,
        disc: &Discretisation,
        state: &State,
        mut pressures: Option<&mut Vec<(usize, usize, Real)>>,
    ) -> Option<Penetration> {
        let mut deepest = None;
        self.rigid_gaps(disc, state, |k, g, gap| {
            if let Some(gap) = gap {
                let point = &disc.points[g];
                deepest = Penetration::deeper(deepest, -gap, k, point.patch, point.u);
            }
            if let Some(out) = pressures.as_deref_mut() {
                out.push((k, g, gap.map_or(0.0, |gap| self.pressure(k, g, gap).0)));
            }
        });
        deepest
    }

    /// [`SurfaceContact::rigid_points`] with the pressures.
    fn rigid_contact(
        &self,
        disc: &Discretisation,
        state: &State,
    ) -> (Option<Penetration>, Vec<(usize, usize, Real)>) {
        let mut pressures = Vec::new();
        let deepest = self.rigid_points(disc, state, Some(&mut pressures));
        (deepest, pressures)
    }

    /// A lumen's closest-point parameter of point `g` at the last converged step (obstacle `k`), if it has one.
    fn hint(&self, k: usize, g: usize) -> Option<Real> {
        self.hints[k].get(g).copied().filter(|u| !u.is_nan())
    }

    /// Calls `add(q, ∂q/∂c)` with the spatial line force `q` of every obstacle that acts on the point `at` (normal
    /// pressure and friction) and, when the tangent is wanted, its derivative with respect to the point's position.
    fn line_force(&self, at: &PointView<'_>, mut add: impl FnMut(Vec3, Option<Mat3>)) {
        let x = at.position();
        for k in 0..self.obstacles.len() {
            if self.out_of_reach(k, at.g, at.point.patch, &x) {
                continue;
            }
            let Some(c) = self.at(k, at.g, at.point.patch, &x) else {
                continue;
            };
            if c.pressure == 0.0 && c.stiffness == 0.0 {
                continue;
            }
            let n = c.distance.normal;
            let friction = self.friction(k, at.g, &x, &c);
            let q = n * c.pressure + friction.map_or(Vec3::zeros(), |f| f.force);
            let dq = at.tangent.then(|| {
                let dq = n * n.transpose() * c.stiffness + c.distance.hessian * c.pressure;
                friction.map_or(dq, |f| dq + f.derivative)
            });
            add(q, dq);
        }
    }

    /// Records an obstacle put in place at the end of the step that converged at `state` with a wire deeper
    /// through it than the tolerance (module docs).
    fn record_placed(&mut self, disc: &Discretisation, state: &State) {
        let t = self.time;
        for (k, obstacle) in self.obstacles.iter().enumerate() {
            let from = obstacle.active.0;
            if !(from > 0.0 && (from - t).abs() <= 1e-9 * from.max(1.0)) {
                continue;
            }
            let mut deepest: Option<(Real, Vec3)> = None;
            for (g, point) in disc.points.iter().enumerate() {
                if !self.acts[g] {
                    continue;
                }
                let x = point_position(disc, &state.control, g);
                let Some(d) = obstacle.surface.distance(&x, t) else {
                    continue;
                };
                let depth = self.radius[point.patch] - d.value;
                if depth > self.settings.tolerance && deepest.is_none_or(|(w, _)| depth > w) {
                    deepest = Some((depth, x));
                }
            }
            if let Some((depth, x)) = deepest {
                let p = &mut self.placed;
                p.count += 1;
                if depth > p.largest {
                    (p.largest, p.obstacle, p.time, p.at) = (depth, k, t, x);
                }
            }
        }
    }
}

impl PointTerm for SurfaceContact {
    fn name(&self) -> &'static str {
        "surface contact"
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }

    fn interior(&self, at: &PointView<'_>, load: &mut InteriorLoad) {
        self.line_force(at, |q, dq| {
            load.add_force(q);
            if let Some(dq) = dq {
                load.add_force_position(at.rotation_t * dq);
            }
        });
    }

    fn end(&self, at: &PointView<'_>, load: &mut EndLoad) {
        if !self.acts[at.g] {
            return;
        }
        // A corner's end (module docs, *Corners*): the line force over the end's tributary length, concentrated
        // on its node.
        let length = self.lengths[at.g];
        self.line_force(at, |q, dq| {
            load.add_force(q * length);
            if let Some(dq) = dq {
                load.add_force_position(dq * length);
            }
        });
    }

    fn prepare(&mut self, disc: &Discretisation, state: &State, t: Real) {
        // One Uzawa update between steps (module docs): the pressures of the converged state, at its time (as
        // the commit of that state found them, or found again after a checkpoint was restored).
        if self.committed.is_none() {
            self.committed = Some(self.rigid_contact(disc, state).1);
        }
        for &(k, g, pressure) in self.committed.iter().flatten() {
            self.multipliers[k][g] = pressure;
        }
        self.time = t;
        self.updates = 0;
        self.checked = None;
    }

    fn step_limit(&self, disc: &Discretisation, state: &State, delta: &[Real]) -> Real {
        let mut alpha: Real = 1.0;
        for (g, point) in disc.points.iter().enumerate() {
            if !self.acts[g] {
                continue;
            }
            let x = point_position(disc, &state.control, g);
            let mut step: Option<Vec3> = None;
            for (k, obstacle) in self.obstacles.iter().enumerate() {
                if !obstacle.is_active(self.time) {
                    continue;
                }
                let hint = self.hint(k, g);
                let Some(distance) = obstacle.surface.distance_value(&x, self.time, hint) else {
                    continue;
                };
                let gap = distance - self.radius[point.patch];
                // Only a point the law does not act on yet (no stiffness): its contact is not in the tangent.
                if self.pressure(k, g, gap).1 != 0.0 {
                    continue;
                }
                // The stop is the middle of the law's band, where its stiffness is half the penalty.
                let (penalty, multiplier) = self.law(k, g);
                let stop = multiplier / penalty;
                let dx = *step.get_or_insert_with(|| point_increment(disc, delta, g).0);
                // The distance moves by at most |dx|: a point that cannot reach the stop is not searched.
                if gap - dx.norm() >= stop {
                    continue;
                }
                let Some(moved) = obstacle.surface.distance_value(&(x + dx), self.time, hint)
                else {
                    continue;
                };
                let moved = moved - self.radius[point.patch];
                if moved < stop {
                    alpha = alpha.min((gap - stop) / (gap - moved));
                }
            }
        }
        alpha
    }

    fn augment(&mut self, disc: &Discretisation, state: &State) -> bool {
        let tolerance = self.settings.tolerance;
        let at_points = self.rigid_points(disc, state, None);
        let worst = at_points.map_or(0.0, |d| d.depth);
        self.checked = None;
        if worst <= tolerance {
            // A crest between the points deeper than the tolerance comes out with the points around it, as far
            // as it is not deeper than they are by more than the tolerance (beyond that only a finer patch helps).
            let anywhere = self.penetration_between(state, at_points);
            let between = worst > 0.0
                && anywhere.is_some_and(|d| d.depth > tolerance && d.depth - worst <= tolerance);
            if !between || self.updates == self.settings.max_updates {
                self.checked = Some(anywhere);
                return false;
            }
        } else if self.updates == self.settings.max_updates {
            let u = &mut self.unresolved;
            if u.steps == 0 {
                u.first = self.time;
            }
            u.steps += 1;
            u.largest = u.largest.max(worst);
            return false;
        }
        self.updates += 1;
        for (k, g, pressure) in self.rigid_contact(disc, state).1 {
            self.multipliers[k][g] = pressure;
        }
        true
    }

    fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        let p = &self.placed;
        if p.count > 0 {
            out.push(format!(
                "contact: {} obstacle(s) were put in place through the wires, the deepest `{}` at t = {} by {:.3e} at ({:.4}, {:.4}, {:.4}), beyond the penetration tolerance {:e}: the first step after it pushed the wires out at once; put it in place where the device is clear of it",
                p.count,
                self.obstacles[p.obstacle].name,
                p.time,
                p.largest,
                p.at.x,
                p.at.y,
                p.at.z,
                self.settings.tolerance
            ));
        }
        let u = &self.unresolved;
        if u.steps > 0 {
            out.push(format!(
                "contact: in {} step(s) the penetration stayed above its tolerance {:e} after {} augmented-Lagrange update(s), by up to {:.3e} (first at t = {}): raise `max_updates` or the penalty",
                u.steps, self.settings.tolerance, self.settings.max_updates, u.largest, u.first
            ));
        }
        let b = &self.between;
        if let Some(d) = b.deepest {
            out.push(format!(
                "contact: in {} step(s) the rods penetrated obstacle {} beyond the tolerance {:e} somewhere along them (checked at the patch ends and {SAMPLES_PER_SPAN} points per knot span besides the collocation points, where alone the law acts), by up to {:.3e} on patch {} at curve parameter u = {:.4} at t = {} (first at t = {}): refine the patch there",
                b.steps,
                quoted(&self.obstacles[d.obstacle].name),
                self.settings.tolerance,
                d.depth,
                quoted(&self.patches[d.patch]),
                d.u,
                b.deepest_time,
                b.first
            ));
        }
        out
    }

    fn commit(&mut self, disc: &Discretisation, state: &State) {
        self.record_placed(disc, state);
        for (k, hints) in self.hints.iter_mut().enumerate() {
            let surface = &self.obstacles[k].surface;
            for (g, hint) in hints.iter_mut().enumerate() {
                let x = point_position(disc, &state.control, g);
                let last = Some(*hint).filter(|u| !u.is_nan());
                *hint = surface.parameter(&x, last).unwrap_or(Real::NAN);
            }
        }
        for k in 0..self.obstacles.len() {
            if self.anchors[k].is_empty() {
                continue;
            }
            let mut step = 0.0;
            for (g, point) in disc.points.iter().enumerate() {
                if !self.acts[g] {
                    continue;
                }
                let x = point_position(disc, &state.control, g);
                let traction = self
                    .at(k, g, point.patch, &x)
                    .and_then(|c| self.friction(k, g, &x, &c));
                match traction {
                    // Free: the anchor follows the point, so a point that touches down slips from where it was.
                    None => self.anchors[k][g] = x,
                    // Return map: the anchor moves along the slip until the elastic part is `μ p / ε_t`; the
                    // rest of the slip dissipates `μ p` per unit length.
                    Some(f) if f.sliding => {
                        let length = f.slip.norm();
                        let elastic = f.limit / self.law(k, g).0;
                        step += self.lengths[g] * f.limit * (length - elastic);
                        self.anchors[k][g] = x - f.slip * (elastic / length);
                    }
                    Some(_) => {}
                }
            }
            self.work[k] = [step, self.work[k][1] + step];
        }
        // Recorded unless the augmented-Lagrange record already tells it: the points' own penetration above the
        // tolerance, and nothing deeper than it by more than the tolerance between them (module docs).
        let tolerance = self.settings.tolerance;
        let (at_points, pressures) = self.rigid_contact(disc, state);
        self.committed = Some(pressures);
        let anywhere = match self.checked.take() {
            Some(anywhere) => anywhere,
            None => self.penetration_between(state, at_points),
        };
        let at_points = at_points.map_or(0.0, |d| d.depth);
        if let Some(d) = anywhere
            && d.depth > tolerance
            && (at_points <= tolerance || d.depth - at_points > tolerance)
        {
            let b = &mut self.between;
            if b.steps == 0 {
                b.first = self.time;
            }
            b.steps += 1;
            if b.deepest.is_none_or(|old| d.depth > old.depth) {
                b.deepest = Some(d);
                b.deepest_time = self.time;
            }
        }
    }

    fn save(&self, out: &mut Vec<Real>) {
        let u = &self.unresolved;
        let b = &self.between;
        let d = b.deepest.unwrap_or(Penetration {
            depth: 0.0,
            obstacle: 0,
            patch: 0,
            u: 0.0,
        });
        let p = &self.placed;
        out.extend([
            self.time,
            self.updates as Real,
            u.steps as Real,
            u.largest,
            u.first,
            b.steps as Real,
            d.depth,
            d.obstacle as Real,
            d.patch as Real,
            d.u,
            b.deepest_time,
            b.first,
            p.count as Real,
            p.largest,
            p.obstacle as Real,
            p.time,
            p.at.x,
            p.at.y,
            p.at.z,
        ]);
        for m in &self.multipliers {
            out.extend_from_slice(m);
        }
        for a in &self.anchors {
            out.extend(a.iter().flat_map(|x| x.iter().copied()));
        }
        out.extend(self.work.iter().flatten());
        for h in &self.hints {
            out.extend_from_slice(h);
        }
    }

    fn restore(&mut self, values: &[Real]) -> Result<(), usize> {
        const HEAD: usize = 19;
        let expected = HEAD
            + self.multipliers.iter().map(Vec::len).sum::<usize>()
            + 3 * self.anchors.iter().map(Vec::len).sum::<usize>()
            + 2 * self.work.len()
            + self.hints.iter().map(Vec::len).sum::<usize>();
        if values.len() != expected {
            return Err(expected);
        }
        // Counts and indices are saved as reals: exact below 2^53.
        self.committed = None;
        self.checked = None;
        self.time = values[0];
        self.updates = values[1] as usize;
        self.unresolved = Unresolved {
            steps: values[2] as usize,
            largest: values[3],
            first: values[4],
        };
        let steps = values[5] as usize;
        self.between = Between {
            steps,
            deepest: (steps > 0).then(|| Penetration {
                depth: values[6],
                obstacle: values[7] as usize,
                patch: values[8] as usize,
                u: values[9],
            }),
            deepest_time: values[10],
            first: values[11],
        };
        self.placed = Placed {
            count: values[12] as usize,
            largest: values[13],
            obstacle: values[14] as usize,
            time: values[15],
            at: Vec3::new(values[16], values[17], values[18]),
        };
        let mut rest = &values[HEAD..];
        for m in &mut self.multipliers {
            let (mine, tail) = rest.split_at(m.len());
            m.copy_from_slice(mine);
            rest = tail;
        }
        for a in &mut self.anchors {
            let (mine, tail) = rest.split_at(3 * a.len());
            for (x, v) in a.iter_mut().zip(mine.chunks_exact(3)) {
                *x = Vec3::new(v[0], v[1], v[2]);
            }
            rest = tail;
        }
        let (work, mut rest) = rest.split_at(2 * self.work.len());
        for (w, v) in self.work.iter_mut().zip(work.chunks_exact(2)) {
            *w = [v[0], v[1]];
        }
        for h in &mut self.hints {
            let (mine, tail) = rest.split_at(h.len());
            h.copy_from_slice(mine);
            rest = tail;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::ramp;
    use crate::material::{CircularSection, ElasticLaw};
    use crate::math::{Real, Vec3};
    use crate::model::builder::{ConditionSpec, ModelBuilder, PatchShape, TimeSpec};
    use crate::model::{Contact, ContactSettings, Model, Obstacle, Surface, TimeFunction, Wall};
    use crate::solver::Simulation;
    use crate::solver::discretisation::{Discretisation, point_position};
    use crate::solver::simulation::NoObserver;
    use crate::solver::state::State;
    use std::f64::consts::FRAC_PI_2;

    /// Reference radius, wire diameter, Young's modulus of the ring tests.
    pub(super) const R0: Real = 10.0;
    pub(super) const D: Real = 0.5;
    pub(super) const E: Real = 1000.0;

    /// A quarter of a circular ring of radius `R0` in the plane z = 0, its ends on the symmetry planes y = 0
    /// and x = 0 (each end: the displacement normal to its plane, the out-of-plane displacement and every
    /// rotation held), elastic, 20 steps over t ∈ [0, 1], with `contact`.
    pub(super) fn quarter_ring(contact: Contact) -> Model {
        quarter_ring_held(contact, true, None)
    }

    /// [`quarter_ring`] whose ends hold their out-of-plane displacement (z, along the cylinders' axis) only
    /// if `axial`, with a line load `push` along z if given.
    fn quarter_ring_held(contact: Contact, axial: bool, push: Option<TimeFunction>) -> Model {
        let material = ElasticLaw::try_new(E, 0.3).expect("E > 0");
        let section = CircularSection::try_new(D).expect("d > 0").into();
        let mut b = ModelBuilder::new("ring", material, section);
        b.patch(
            "ring",
            PatchShape::Arc {
                centre: Vec3::zeros(),
                start: Vec3::new(R0, 0.0, 0.0),
                axis: Vec3::z(),
                angle: FRAC_PI_2,
            },
            4,
            12,
        );
        let zero = || TimeFunction::constant(0.0);
        let symmetric = |node: &str, normal: usize| {
            let held = ConditionSpec::at(node).with_displacement(normal, zero());
            let held = if axial {
                held.with_displacement(2, zero())
            } else {
                held
            };
            held.with_rotation(0, zero())
                .with_rotation(1, zero())
                .with_rotation(2, zero())
        };
        b.condition(symmetric("ring.start", 1));
        b.condition(symmetric("ring.end", 0));
        if let Some(push) = push {
            let constant = TimeFunction::constant;
            b.distributed_load(crate::model::builder::DistributedLoadSpec {
                patches: crate::model::builder::PatchTarget::All,
                force: [constant(0.0), constant(0.0), push],
                couple: [constant(0.0), constant(0.0), constant(0.0)],
            });
        }
        b.time(TimeSpec::new(1.0, 0.05));
        b.contact(contact);
        b.build().expect("valid ring").model
    }

    /// Source: the step limit's rule (module docs), worked out for the quarter ring (radius `R0`, wire radius
    /// `D/2`) inside a fixed cylinder of radius `R0 + D/2 + 0.5`: every point is 0.5 clear of it, outside the
    /// law's band. An increment that scales the control points by 1.1 moves every point of the ring radially out
    /// by `0.1 R0 = 1` (a NURBS curve follows an affine map of its control points), through the wall to a gap of
    /// −0.5; the limit stops the deepest at the band's middle, `g = λ/ε = 0`: the fraction `0.5 / 1`. Two
    /// fifths of that increment stop short of the wall (no limit); with the cylinder 2δ/4 clear (the point inside
    /// the band, its stiffness in the tangent) the increment is not limited either.
    #[test]
    fn the_step_limit_stops_a_point_not_yet_in_contact_in_the_middle_of_the_band() {
        use crate::solver::terms::PointTerm;
        let limit = |clearance: Real, scale: Real| {
            let outer = R0 + 0.5 * D + clearance;
            let obstacle = cylinder(outer, outer, Wall::Rigid);
            let contact = Contact {
                obstacles: vec![obstacle.clone()],
                settings: RING,
            };
            let model = quarter_ring(contact);
            let disc = Discretisation::new(&model).expect("discretised");
            let state = State::reference(&disc);
            let mut term = super::SurfaceContact::new(&model, &disc, vec![obstacle], RING);
            term.prepare(&disc, &state, 0.5);
            let mut delta = vec![0.0; disc.num_unknowns()];
            for (j, p) in state.control.iter().enumerate() {
                for i in 0..3 {
                    delta[6 * j + i] = (scale - 1.0) * p[i];
                }
            }
            term.step_limit(&disc, &state, &delta)
        };
        let alpha = limit(0.5, 1.1);
        assert!((alpha - 0.5).abs() < 1e-9, "limited to {alpha}");
        assert_eq!(limit(0.5, 1.04), 1.0, "short of the wall");
        assert_eq!(limit(0.25 * RING.regularisation, 1.1), 1.0, "in the band");
    }

    /// A cylinder around the z axis whose radius goes linearly from `from` at t = 0 to `to` at t = 1.
    pub(super) fn cylinder(from: Real, to: Real, wall: Wall) -> Obstacle {
        Obstacle::new(
            "crimper",
            Surface::Cylinder {
                point: Vec3::zeros(),
                axis: Vec3::z(),
                radius: TimeFunction::try_table(vec![(0.0, from), (1.0, to)])
                    .expect("increasing times"),
            },
            wall,
        )
    }

    /// Runs the quarter ring inside `obstacle` to t = 1; returns the collocation points' distances from the
    /// axis, the y component of the force the rod's start (on y = 0) exerts on its node, and the run's
    /// warnings.
    fn crimp(obstacle: Obstacle, settings: ContactSettings) -> (Vec<Real>, Real, Vec<String>) {
        let model = quarter_ring(Contact {
            obstacles: vec![obstacle],
            settings,
        });
        let mut sim = Simulation::new(&model).expect("discretised");
        sim.run(&mut [&mut NoObserver])
            .expect("the crimp converges");
        let disc = sim.discretisation();
        let radii = (0..disc.points.len())
            .map(|g| {
                let x = point_position(disc, &sim.state().control, g);
                (x.x * x.x + x.y * x.y).sqrt()
            })
            .collect();
        let start = model
            .nodes
            .iter()
            .position(|n| n.name == "ring.start")
            .expect("node at the start");
        let hoop = sim.node_end_resultants(start)[0].0.y;
        (radii, hoop, sim.warnings())
    }

    /// Source: a Simo–Reissner ring of reference radius `R0` pressed uniformly to radius `ρ` keeps its
    /// curvature per reference length (`2π` over `2π R0`) and stretches its centreline by `ρ/R0`: hoop force
    /// `N = EA (ρ/R0 − 1)`, no moment change, and equilibrium of a piece, `N' + q = 0` per reference length with
    /// `|t'| = 1/R0`, gives the line pressure `q = −N/R0` (derived here; a uniform moment, such as the
    /// `EI(1/ρ − 1/R0)` of an inextensible reading, has no derivative and does not enter it). Here: a
    /// rigid crimper shrinks from a clear 0.2 to 0.5 below the wire's reach (5 % hoop strain); augmented
    /// Lagrange must bring the penetration below its tolerance 1e-6 (the penalty alone leaves
    /// `q/ε ≈ 1e-3`), the points stay on one circle (uniform pressure), and the hoop force is the closed form's
    /// for the radius reached, to the solver's tolerance (1e-9 normalised: 1e-7 relative is far above it).
    #[test]
    fn a_ring_crimped_by_a_rigid_cylinder_is_uniformly_pressed_to_its_radius() {
        let r = D / 2.0;
        let settings = RING;
        let crimped = R0 + r - 0.5;
        let (radii, hoop, warnings) = crimp(cylinder(R0 + r + 0.2, crimped, Wall::Rigid), settings);
        assert!(warnings.is_empty(), "{warnings:?}");
        let target = crimped - r;
        for (g, rho) in radii.iter().enumerate() {
            assert!(
                (rho - target).abs() <= settings.tolerance,
                "point {g}: radius {rho}, the crimper allows {target} (penetration {:.3e})",
                rho - target
            );
        }
        let rho = radii.iter().sum::<Real>() / radii.len() as Real;
        let area = std::f64::consts::PI * D * D / 4.0;
        let expected = E * area * (rho / R0 - 1.0);
        // The rod's start pushes on its node with σ N t, σ = −1 and t = +y there: −N in y.
        assert!(
            (hoop + expected).abs() <= 1e-7 * expected.abs(),
            "hoop force {} against the closed form {expected}",
            -hoop
        );
    }

    /// The same crimp without augmented-Lagrange updates within a step: only the update between steps
    /// ([`PointTerm::prepare`]) carries each step's pressure into the next, so a step leaves the penetration of
    /// its change of pressure over the penalty, `Δq/ε`, above the 1e-6 tolerance, and the run says so in its
    /// warnings instead of completing silently. The pressure rises to `q ≈ 0.98` (the ring test) over the ~14.3
    /// steps of 0.05 s from first contact (the crimper, closing 0.7 in 1 s, meets the ring at t = 0.2/0.7),
    /// `Δq ≈ 0.069`, `Δq/ε ≈ 6.9e-5` with ε = 1e3: the warning's largest penetration within a factor of 3 of
    /// it.
    #[test]
    fn a_crimp_left_above_its_penetration_tolerance_is_warned_about() {
        let r = D / 2.0;
        let settings = ContactSettings {
            max_updates: 0,
            ..RING
        };
        let (_, _, warnings) = crimp(cylinder(R0 + r + 0.2, R0 + r - 0.5, Wall::Rigid), settings);
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(
            warnings[0].contains("penetration stayed above its tolerance"),
            "{}",
            warnings[0]
        );
        let largest: Real = warnings[0]
            .split("by up to ")
            .nth(1)
            .and_then(|t| t.split_whitespace().next())
            .and_then(|t| t.parse().ok())
            .expect("the largest penetration in the warning");
        assert!((2.3e-5..2.1e-4).contains(&largest), "{largest}");
    }

    /// Source: the same ring pressed into a compliant tube: the wall is a foundation of line stiffness
    /// `k b = E_w h b / R²` (Laplace's law; module docs of `crate::model::obstacle`) in series with the ring's
    /// radial stiffness `EA/R0²` (from `q = EA (1 − ρ/R0)/R0` above), so the balanced radius solves
    /// `EA (1 − ρ/R0)/R0 = k b (ρ + r − R_c)`:
    /// `ρ = (EA/R0 + k b (R_c − r)) / (EA/R0² + k b)`. The wall here is about as stiff as the ring (each takes
    /// about half the 0.5 interference); the law's linear branch is exact beyond its 1e-4 band, so the
    /// tolerance is the solver's (1e-8 relative).
    #[test]
    fn a_ring_in_a_compliant_tube_balances_as_two_springs_in_series() {
        springs_in_series(cylinder);
    }

    /// Source: as [`a_ring_in_a_compliant_tube_balances_as_two_springs_in_series`], the tube given as a
    /// vessel's lumen: a straight centreline along the axis (a cubic with uneven control points) with a
    /// constant radius, closing through its scale. The wall's stiffness takes the lumen's local radius where
    /// each point touches, here the same everywhere: the same balance, to the same 1e-8.
    #[test]
    fn a_ring_in_a_compliant_lumen_balances_as_two_springs_in_series() {
        springs_in_series(|from, to, wall| {
            let knots = crate::math::KnotVector::clamped_uniform(3, 6).expect("a knot vector");
            let points = [0.0, 0.1, 0.3, 0.6, 0.8, 1.0]
                .iter()
                .map(|&t| Vec3::new(0.0, 0.0, -20.0 + 40.0 * t))
                .collect();
            let centreline = crate::math::NurbsCurve::try_bspline(knots, points).expect("a curve");
            let scale = TimeFunction::try_table(vec![(0.0, from / to), (1.0, 1.0)])
                .expect("increasing times");
            let lumen = crate::model::Lumen::try_new(centreline, vec![(0.0, to), (1.0, to)])
                .expect("a lumen")
                .with_scale(scale);
            Obstacle::new("vessel", Surface::Lumen(lumen), wall)
        });
    }

    /// The ring crimped into the compliant tube that `tube(from, to, wall)` makes (its radius closing from
    /// `from` to `to` over the run) balances as the two springs in series (the tests above).
    fn springs_in_series(tube_of: impl Fn(Real, Real, Wall) -> Obstacle) {
        let r = D / 2.0;
        let (modulus, thickness, width) = (100.0, 1.0, 2.0);
        let settings = RING;
        let wall = Wall::Compliant {
            modulus,
            thickness,
            width,
        };
        let tube = R0 + r - 0.5;
        let (radii, _, _) = crimp(tube_of(R0 + r + 0.2, tube, wall), settings);
        let area = std::f64::consts::PI * D * D / 4.0;
        let ring = E * area / (R0 * R0);
        let k = modulus * thickness * width / (tube * tube);
        let expected = (ring * R0 + k * (tube - r)) / (ring + k);
        for (g, rho) in radii.iter().enumerate() {
            assert!(
                (rho - expected).abs() <= 1e-8 * R0,
                "point {g}: radius {rho}, closed form {expected}"
            );
        }
        // Both springs take a real share: the test would not tell a stiff wall from a rigid one otherwise.
        let wall_share = (expected + r - tube) / 0.5;
        assert!((0.2..0.8).contains(&wall_share), "{wall_share}");
    }

    /// A straight rod of length `L` along x lying on the plane z = 0 (its centreline a wire radius above it),
    /// pressed by a distributed load `w` per unit length in −z and pulled along x by a prescribed displacement
    /// `U(t)` of its end `bar.end` (y held; both ends' rotations held, which a straight rod on a plane does not
    /// load, to remove its free twist), the other end free, friction `μ` on the plane.
    fn rod_on_a_plane(friction: Real, w: Real, pull: TimeFunction) -> Model {
        let table = Surface::Plane {
            point: Vec3::zeros(),
            normal: Vec3::z(),
            offset: TimeFunction::constant(0.0),
        };
        rod_on(table, friction, w, pull)
    }

    /// Radius of the trough the sliding rod lies in instead of the plane.
    const TROUGH: Real = 3.0;

    /// The inside of a tube of radius `TROUGH` along x whose lowest generator is the plane's line z = 0, y = 0
    /// under the sliding rod: a cylinder, or the same as a lumen around a straight centreline (x from −10 to 20,
    /// beyond the rod and its slide).
    fn trough(lumen: bool) -> Surface {
        let point = Vec3::new(0.0, 0.0, TROUGH);
        if !lumen {
            return Surface::Cylinder {
                point,
                axis: Vec3::x(),
                radius: TimeFunction::constant(TROUGH),
            };
        }
        let knots = crate::math::KnotVector::clamped_uniform(3, 4).expect("a knot vector");
        let points = (0..4)
            .map(|i| point + Vec3::x() * (-10.0 + 10.0 * i as Real))
            .collect();
        let centreline = crate::math::NurbsCurve::try_bspline(knots, points).expect("a line");
        let (lo, hi) = centreline.knots().domain();
        Surface::Lumen(
            crate::model::Lumen::try_new(centreline, vec![(lo, TROUGH), (hi, TROUGH)])
                .expect("a lumen"),
        )
    }

    /// [`rod_on_a_plane`] on the surface `table` instead, which must touch the rod's underside along its length.
    fn rod_on(table: Surface, friction: Real, w: Real, pull: TimeFunction) -> Model {
        use crate::model::builder::{DistributedLoadSpec, PatchTarget};
        let material = ElasticLaw::try_new(E, 0.3).expect("E > 0");
        let section = CircularSection::try_new(D).expect("d > 0").into();
        let mut b = ModelBuilder::new("sliding rod", material, section);
        let z = D / 2.0;
        b.patch(
            "bar",
            PatchShape::Line {
                from: Vec3::new(0.0, 0.0, z),
                to: Vec3::new(ROD, 0.0, z),
            },
            4,
            24,
        );
        let zero = || TimeFunction::constant(0.0);
        let rotations = |c: ConditionSpec| {
            c.with_rotation(0, zero())
                .with_rotation(1, zero())
                .with_rotation(2, zero())
        };
        b.condition(rotations(ConditionSpec::at("bar.start")));
        b.condition(rotations(
            ConditionSpec::at("bar.end")
                .with_displacement(0, pull)
                .with_displacement(1, zero()),
        ));
        let constant = TimeFunction::constant;
        b.distributed_load(DistributedLoadSpec {
            patches: PatchTarget::All,
            force: [constant(0.0), constant(0.0), constant(-w)],
            couple: [constant(0.0), constant(0.0), constant(0.0)],
        });
        b.time(TimeSpec::new(1.0, 0.05));
        b.contact(Contact {
            obstacles: vec![Obstacle::new("table", table, Wall::Rigid).with_friction(friction)],
            settings: SLIDING,
        });
        b.build().expect("valid rod").model
    }

    /// Length of the sliding rod.
    const ROD: Real = 10.0;

    /// The sliding rod's contact settings: a soft penalty (`ε = 10`, also the stick stiffness) so that the
    /// sticking rod is a bar on a foundation of moderate `βL` that the discretisation resolves, and augmented
    /// Lagrange to take the normal penetration `w/ε` out.
    const SLIDING: ContactSettings = ContactSettings {
        penalty: 10.0,
        regularisation: 1e-4,
        tolerance: 1e-8,
        max_updates: 10,
    };

    /// Source: Coulomb friction regularised by a stick stiffness `ε_t` (module docs). A rod of `EA` on a plane
    /// under the line load `w` (pressure `p = w` at every point) with friction `μ`, its far end free, its end
    /// `x = L` pulled by `U`:
    /// - **sticking** (every point's elastic slip below `μ w / ε_t`): a bar on a Winkler foundation of stiffness
    ///   `ε_t`, `EA u'' = ε_t u`, `u'(0) = 0`, `u(L) = U`, so `u = U cosh(βx)/cosh(βL)`, `β = √(ε_t/EA)`, and
    ///   the pull `N(L) = EA β U tanh(βL)` (the same closed form as the spring test of `terms::tests`). Here
    ///   `U = 0.01`, `ε_t U = 0.1 < μ w = 0.3`: every point sticks. Tolerance 1e-5 relative: degree-4
    ///   collocation on 24 points (`βh ≈ 0.1`) resolves the exponential profile to about `(βh)⁴ ≈ 1e-4` of
    ///   its curvature's scale and far better in the end force; a missing friction is a 100 % error;
    /// - **sliding** (every point past its elastic slip): `N' = μ w` at every interior point and `N(0) = 0`,
    ///   so `N(L) = μ w L` — Coulomb's law for the whole rod — exactly in the spline space (a linear `N`):
    ///   tolerance the solver's, 1e-7 relative;
    /// - and in steady sliding every point moves by the step's `ΔU`, so the step's friction work is
    ///   `μ w L ΔU` (the tributary lengths add up to `L` on a straight rod): same tolerance.
    ///
    /// The run is checkpointed while sliding and continued from the checkpoint in a fresh simulation: the anchors
    /// are the term's state, so the two end bit for bit.
    #[test]
    fn a_rod_on_a_plane_sticks_below_coulombs_limit_and_slides_at_it() {
        let (mu, w) = (0.3, 1.0);
        let pull = TimeFunction::try_table(vec![(0.0, 0.0), (0.05, 0.01), (1.0, 1.0)])
            .expect("increasing times");
        let model = rod_on_a_plane(mu, w, pull);
        let end = model
            .nodes
            .iter()
            .position(|n| n.name == "bar.end")
            .expect("node bar.end");
        let mut sim = Simulation::new(&model).expect("discretised");
        let reaction = |sim: &Simulation| -> Real { sim.node_end_resultants(end)[0].0.x };
        sim.step().expect("the first step converges");
        let area = std::f64::consts::PI * D * D / 4.0;
        let ea = E * area;
        let beta = (SLIDING.penalty / ea).sqrt();
        let sticking = ea * beta * 0.01 * (beta * ROD).tanh();
        // The rod's end at x = L (outward tangent +x) acts on its node with N(L) in x.
        let measured = reaction(&sim);
        println!("sticking: pull {measured:.9e}, closed form {sticking:.9e}");
        assert!(
            ((measured - sticking) / sticking).abs() < 1e-5,
            "sticking: pull {measured}, closed form {sticking}"
        );
        for _ in 0..9 {
            sim.step().expect("converges");
        }
        let checkpoint = sim.checkpoint();
        while sim.step().expect("converges").is_some() {}
        let sliding = mu * w * ROD;
        let measured = reaction(&sim);
        println!("sliding: pull {measured:.9e}, Coulomb {sliding:.9e}");
        assert!(
            ((measured - sliding) / sliding).abs() < 1e-7,
            "sliding: pull {measured}, Coulomb μ w L = {sliding}"
        );
        // The term's saved state ends with each obstacle's friction work (last step, total), then a lumen's
        // closest-point parameters (none here).
        let terms = &sim.checkpoint().snapshot.terms;
        let saved = terms.last().expect("the contact term's state");
        let step_work = saved[saved.len() - 2];
        let expected = mu * w * ROD * 0.05 * (1.0 - 0.01) / 0.95;
        println!("friction work of the last step {step_work:.9e}, μ w L ΔU = {expected:.9e}");
        assert!(
            ((step_work - expected) / expected).abs() < 1e-7,
            "friction work {step_work}, μ w L ΔU = {expected}"
        );
        assert!(sim.warnings().is_empty(), "{:?}", sim.warnings());
        let mut continued = Simulation::new(&model).expect("discretised");
        continued.restore(&checkpoint).expect("restores");
        while continued.step().expect("converges").is_some() {}
        assert_eq!(sim.state(), continued.state(), "continued bit for bit");
    }

    /// Source: the sliding rod in a trough (the inside of a tube along it) instead of on the plane: the same
    /// Coulomb limit `μ w L` when it slides (the pressure is still `w`, the slip along the generator; solver's
    /// tolerance, 1e-7), and the lumen around a straight centreline gives the cylinder's run to round-off (every
    /// control point within 1e-9 of the rod's length: the two distances agree to 1e-12, see
    /// `crate::model::obstacle`'s tests; Newton's last iterate carries their difference).
    #[test]
    fn a_rod_sliding_in_a_straight_lumen_is_the_rod_in_the_cylinder() {
        let (mu, w) = (0.3, 1.0);
        let pull = TimeFunction::try_table(vec![(0.0, 0.0), (0.05, 0.01), (1.0, 1.0)])
            .expect("increasing times");
        let mut states = Vec::new();
        for lumen in [false, true] {
            let model = rod_on(trough(lumen), mu, w, pull.clone());
            let end = model
                .nodes
                .iter()
                .position(|n| n.name == "bar.end")
                .expect("node bar.end");
            let mut sim = Simulation::new(&model).expect("discretised");
            sim.run(&mut [&mut NoObserver]).expect("slides");
            let measured = sim.node_end_resultants(end)[0].0.x;
            println!("trough (lumen: {lumen}): pull {measured:.9e}");
            assert!(
                ((measured - mu * w * ROD) / (mu * w * ROD)).abs() < 1e-7,
                "pull {measured}, μ w L = {}",
                mu * w * ROD
            );
            assert!(sim.warnings().is_empty(), "{:?}", sim.warnings());
            states.push(sim.state().control.clone());
        }
        let worst = states[0]
            .iter()
            .zip(&states[1])
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, Real::max);
        println!("lumen against cylinder: largest difference {worst:e}");
        assert!(worst < 1e-9 * ROD, "{worst}");
    }

    /// Source: equilibrium. Automatic stabilisation judges a damped step by the damping's force against what acts
    /// on the device from outside (module docs of `simulation::stabilisation`, *The force*), and a wall's contact
    /// is such a force: the frictionless rod pressed on the plane by the line load `w` (nothing pulled) bears
    /// `w` from the plane at every point, so the loads and the plane give `|n̄| = w` each per unit length, and
    /// the node resultants vanish (the rod lies flat: no axial force, no moment). A damping opposing a uniform
    /// motion `δ` along the rod is `(c/h) A δ` per unit length, so its share is `(c/h) A δ / (2 w)`, here 1 %.
    /// The law acts at the interior points only, so the end points' weights (under a span of 24 on this
    /// degree-4 rod: at most 4.2 % of its length) carry the load but no contact: tolerance 5 %. Without the
    /// contact in the reckoning the share is twice as large, a 100 % error (the judgement before this check).
    #[test]
    fn a_damping_beside_a_wall_is_judged_against_the_wall_s_reaction_too() {
        use crate::solver::terms::damping::Damping;
        let w = 1.0;
        let model = rod_on_a_plane(0.0, w, TimeFunction::constant(0.0));
        let mut sim = Simulation::new(&model).expect("discretised");
        sim.run(&mut [&mut NoObserver]).expect("the rod settles");
        let area = std::f64::consts::PI * D * D / 4.0;
        let (share, delta) = (0.01, 1e-3);
        let rate = share * 2.0 * w / (area * delta);
        let mut previous = sim.state().clone();
        for c in &mut previous.control {
            c.x -= delta;
        }
        let damping = Damping {
            previous: &previous,
            rate,
        };
        let measured = sim.damping_force_share(sim.time(), damping);
        println!("damping force share beside the plane {measured:.6e}, closed form {share:.6e}");
        assert!(
            ((measured - share) / share).abs() < 0.05,
            "share {measured}, closed form {share}"
        );
    }

    /// Source: the same rod without friction slides freely, so the pull it needs is zero (to the solver's
    /// tolerance, against the `μ w L = 3` above): friction is what carried the load there.
    #[test]
    fn without_friction_the_rod_slides_for_nothing() {
        let pull = TimeFunction::try_table(vec![(0.0, 0.0), (1.0, 0.2)]).expect("a ramp");
        let model = rod_on_a_plane(0.0, 1.0, pull);
        let end = model
            .nodes
            .iter()
            .position(|n| n.name == "bar.end")
            .expect("node bar.end");
        let mut sim = Simulation::new(&model).expect("discretised");
        // Nothing holds the rod along x but its pulled end: a frictionless run must still converge.
        while sim.step().expect("converges").is_some() {}
        let pull = sim.node_end_resultants(end)[0].0.x;
        assert!(pull.abs() < 1e-6, "pull {pull}");
    }

    /// Source: contact acts at the collocation points alone, so a crest between them can pass through a wall
    /// unresisted; the term's check at `SAMPLES_PER_SPAN` points per knot span must find it. An arc of radius
    /// `R0` over 60° (degree 2, 4 control points: collocation points at u = 0, 0.25, 0.75, 1), its apex at u =
    /// 0.5 on the y axis, and a plate (normal −y) moved by t = 1 to `δ = 0.05` through the apex: at the
    /// collocation points the wire stays ≈ `R0 (1 − cos 15°) − δ ≈ 0.29` clear, so the law sees nothing, while
    /// the apex penetrates by `δ` (closed form). The samples nearest the apex (u = 0.4375, 0.5625) are about
    /// 3.75° from it, where the arc has dropped `R0 (1 − cos 3.75°) ≈ 0.021`, so the reported depth lies in
    /// `[δ − 0.03, δ]` (the bound of sampling at that spacing) and at a sample, not a collocation point; and a
    /// committed step with it says so in the run's warnings, with the patch and where.
    #[test]
    fn a_crest_between_collocation_points_is_found_and_warned_about() {
        use crate::solver::discretisation::Discretisation;
        use crate::solver::state::State;
        use crate::solver::terms::PointTerm;
        use crate::solver::terms::contact::SurfaceContact;
        let delta = 0.05;
        let r = D / 2.0;
        let material = ElasticLaw::try_new(E, 0.3).expect("E > 0");
        let section = CircularSection::try_new(D).expect("d > 0").into();
        let mut b = ModelBuilder::new("crest", material, section);
        let start = Vec3::new(R0 * 0.5, R0 * 0.75_f64.sqrt(), 0.0);
        b.patch(
            "arc",
            PatchShape::Arc {
                centre: Vec3::zeros(),
                start,
                axis: Vec3::z(),
                angle: std::f64::consts::FRAC_PI_3,
            },
            2,
            4,
        );
        b.condition(ConditionSpec::clamp("arc.start"));
        let plate = Obstacle::new(
            "plate",
            Surface::Plane {
                point: Vec3::new(0.0, R0 + r + 0.5, 0.0),
                normal: -Vec3::y(),
                offset: TimeFunction::try_table(vec![(0.0, 0.0), (1.0, 0.5 + delta)])
                    .expect("a ramp"),
            },
            Wall::Rigid,
        );
        let settings = ContactSettings {
            tolerance: 1e-3,
            ..RING
        };
        b.contact(Contact {
            obstacles: vec![plate.clone()],
            settings,
        });
        let model = b.build().expect("clear at the start").model;
        let disc = Discretisation::new(&model).expect("discretised");
        let state = State::reference(&disc);
        let mut term = SurfaceContact::new(&model, &disc, vec![plate], settings);
        term.time = 1.0;
        let (at_points, _) = term.rigid_contact(&disc, &state);
        assert!(at_points.is_none(), "the collocation points are clear");
        let found = term
            .penetration_anywhere(&disc, &state)
            .expect("the crest penetrates");
        println!("crest: depth {:.6} at u = {}", found.depth, found.u);
        assert!(
            (delta - 0.03..=delta).contains(&found.depth),
            "depth {}",
            found.depth
        );
        assert!((found.u - 0.5).abs() < 0.1, "at u = {}", found.u);
        assert!(
            disc.points.iter().all(|p| p.u != found.u),
            "at a sample, not a collocation point"
        );
        assert!(term.warnings().is_empty());
        term.commit(&disc, &state);
        let warnings = term.warnings();
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(
            warnings[0].contains("somewhere along them")
                && warnings[0].contains("`arc`")
                && warnings[0].contains("at t = 1"),
            "{}",
            warnings[0]
        );
    }

    /// The quarter ring of `quarter_ring` with its ends free along the axis z (the symmetry planes hold only
    /// their normal displacement and the rotations), crimped by a rigid cylinder with friction `mu` that touches
    /// it at the start, shrinks by 0.5 by t = 0.5 and holds; from t = 0.5 a line load along the axis grows to
    /// `axial` at t = 1. Nothing but friction holds the ring along z.
    fn ring_pushed_along_the_axis(mu: Real, axial: Real) -> Model {
        let r = D / 2.0;
        let mut crimper = cylinder(R0 + r, R0 + r - 0.5, Wall::Rigid);
        crimper.friction = mu;
        if let Surface::Cylinder { radius, .. } = &mut crimper.surface {
            *radius = TimeFunction::try_table(vec![
                (0.0, R0 + r),
                (0.5, R0 + r - 0.5),
                (1.0, R0 + r - 0.5),
            ])
            .expect("increasing times");
        }
        let push = TimeFunction::try_table(vec![(0.0, 0.0), (0.5, 0.0), (1.0, axial)])
            .expect("increasing times");
        quarter_ring_held(
            Contact {
                obstacles: vec![crimper],
                settings: RING,
            },
            false,
            Some(push),
        )
    }

    /// The ring tests' contact settings (penalty 1e3, transition 1e-4, penetration tolerance 1e-6, 10 updates).
    pub(crate) const RING: ContactSettings = ContactSettings {
        penalty: 1e3,
        regularisation: 1e-4,
        tolerance: 1e-6,
        max_updates: 10,
    };

    /// Source: friction removes the rigid-body motion a cylinder leaves a device (here the translation along
    /// its axis). The crimped ring (pressure `p ≈ 0.98` per unit length at the end, from the ring test above)
    /// pushed along the axis by `w = 0.05` per unit length, below `μ p ≈ 0.2`, sticks: every point carries
    /// `q_t = −ε_t s = w`, so the ring translates rigidly by the elastic slip `w/ε_t = 5e-5` (closed form of the
    /// regularised law; uniform, so no bending), to the solver's tolerance (1e-6 relative). Without friction
    /// nothing balances the load and the step fails (no equilibrium exists); what we saw before this test:
    /// with no load along the axis the frictionless ring also "converges" (the free mode has a zero right-hand
    /// side), so the load is what tells the two apart.
    #[test]
    fn friction_holds_a_crimped_ring_against_a_push_along_the_axis() {
        let w = 0.05;
        let model = ring_pushed_along_the_axis(0.2, w);
        let mut sim = Simulation::new(&model).expect("discretised");
        sim.run(&mut [&mut NoObserver]).expect("held by friction");
        let disc = sim.discretisation();
        let expected = w / RING.penalty;
        for g in 0..disc.points.len() {
            let z = point_position(disc, &sim.state().control, g).z;
            assert!(
                (z - expected).abs() <= 1e-6 * expected,
                "point {g}: z = {z:e}, elastic slip w/ε = {expected:e}"
            );
        }
        let model = ring_pushed_along_the_axis(0.0, w);
        let mut sim = Simulation::new(&model).expect("discretised");
        assert!(
            sim.run(&mut [&mut NoObserver]).is_err(),
            "a frictionless ring pushed along the axis has no equilibrium"
        );
    }

    /// Switching in and out (module docs): the crimped ring released in one step (the crimper opens by 0.8, every
    /// point leaves contact and the ring springs back 0.5) and pushed back in the next (every point enters
    /// again, 5 % hoop strain in one step), with and without friction. Newton must take every step without a
    /// cut or a rejected step, in at most 8 iterations counted with the step's augmented-Lagrange re-solves (its
    /// tolerance here is 1e-6, a thousandth of the penalty's penetration; measured: 3 for the release, 6 for the
    /// push back, with and without friction), and the ring must end pressed to the crimper's radius as in the
    /// ring test.
    #[test]
    fn a_ring_released_and_pushed_back_in_one_step_each_does_not_stall_newton() {
        let r = D / 2.0;
        let mut crimper = cylinder(R0 + r + 0.2, R0 + r - 0.5, Wall::Rigid);
        if let Surface::Cylinder { radius, .. } = &mut crimper.surface {
            *radius = TimeFunction::try_table(vec![
                (0.0, R0 + r + 0.2),
                (0.5, R0 + r - 0.5),
                (0.55, R0 + r + 0.3),
                (0.6, R0 + r - 0.5),
                (1.0, R0 + r - 0.5),
            ])
            .expect("increasing times");
        }
        for mu in [0.0, 0.2] {
            let model = quarter_ring(Contact {
                obstacles: vec![Obstacle {
                    friction: mu,
                    ..crimper.clone()
                }],
                settings: RING,
            });
            let mut sim = Simulation::new(&model).expect("discretised");
            while let Some(step) = sim.step().expect("every step converges") {
                if step.time > 0.5 && step.time < 0.65 {
                    println!(
                        "μ = {mu}, t = {:.2}: {} iterations",
                        step.time, step.newton.iterations
                    );
                }
                assert!(
                    step.cuts == 0 && step.rejected == 0 && step.newton.iterations <= 8,
                    "μ = {mu}, t = {}: {} cuts, {} rejected, {} iterations",
                    step.time,
                    step.cuts,
                    step.rejected,
                    step.newton.iterations
                );
            }
            let disc = sim.discretisation();
            for g in 0..disc.points.len() {
                let x = point_position(disc, &sim.state().control, g);
                let rho = (x.x * x.x + x.y * x.y).sqrt();
                assert!(
                    (rho - (R0 - 0.5)).abs() <= RING.tolerance,
                    "μ = {mu}, point {g}: radius {rho}"
                );
            }
        }
    }

    /// The ramp is C¹ at both ends of its transition and is the identity beyond it: the law's continuity that
    /// Newton relies on (module docs).
    #[test]
    fn the_ramp_is_continuous_with_its_slope() {
        let delta = 0.3;
        for x in [-delta, delta] {
            let (below, slope_below) = ramp(x - 1e-12, delta);
            let (above, slope_above) = ramp(x + 1e-12, delta);
            assert!((below - above).abs() < 1e-11, "value at {x}");
            assert!((slope_below - slope_above).abs() < 1e-10, "slope at {x}");
        }
        assert_eq!(ramp(2.0, delta), (2.0, 1.0));
        assert_eq!(ramp(-2.0, delta), (0.0, 0.0));
    }
}
