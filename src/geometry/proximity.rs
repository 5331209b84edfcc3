//! Where the wires of a device come closer than their radii allow (issue 35): the broad and narrow phase of
//! wire-on-wire proximity, on polylines sampled along the rods.
//!
//! **What it takes.** Each wire ([`Wire`]) is a polyline of points along a rod's centreline with their curve
//! parameters and reference arc lengths, its radius, and the nodes its two ends belong to (the device's joints:
//! two wires meeting at a node touch there by construction). Symmetry planes ([`Mirror`]) of a reduced model add
//! the mirror images of the wires: a wire touching its own image, or another wire's, across a symmetry cut is a
//! contact of the full device too.
//!
//! **Broad phase.** The axis-aligned box of every run of `CHUNK` = 8 consecutive segments of a wire, grown by the
//! wire's radius, goes into an R*-tree (the `rstar` crate: bulk loading is O(n log n), and the tree's join with
//! itself or with the tree of a mirror image lists the pairs of boxes that intersect without testing all pairs).
//! A pair of runs whose points are all neighbours along the wires (below) is dropped whole: most boxes meet their
//! neighbours'. For an image only the segments within two radii (and the margin, below) of its planes enter.
//!
//! **Narrow phase.** The closest points of two segments (Ericson, *Real-Time Collision Detection*, 2005,
//! §5.1.9) and their distance `d`; the pair overlaps by `r_a + r_b − d` where that is positive. Between
//! polyline points a curved wire lies off its chord by at most `h²/(8ρ)` (segment length `h`, radius of
//! curvature `ρ`): the caller samples densely enough for that to be small against the depths it reports.
//!
//! **Joints are not contacts.** Two points a short way apart *along the wires* are neighbours, not a contact:
//! a pair is left out when its distance along the wires (through the nodes, in the reference arc length: the
//! wires' graph distance, [`Wire::ends`]) is below `2 (r_a + r_b)`. That length is what it takes for a wire to
//! come back onto itself: two struts locked side by side around a crest bent to the wire's own radius are
//! `π r` apart along the wire where they first face each other, so a pair of facing points is a contact from
//! `0.43 r` past the bend on. Two wires that meet at a node at an angle `θ` overlap near it for
//! `r_a + r_b > 2 s sin(θ/2)` (`s` along each from the node); beyond `2 (r_a + r_b)` that needs `θ < 60°`, a joint
//! whose wires lie fused over more than a diameter. So two wires that share a node are also left out where
//! they overlap *without a break from the node* (the reach of the joint's own overlap, walked along the first
//! wire's points from the node to the first one clear of the other wire): the crest of one crown and the trough
//! of the next that meet tangentially at a closed cell's vertex overlap by construction over a length, and an
//! overlap of theirs further on, past a clearance, is a contact.
//!
//! **Slack.** A search can also say how much closer any two places of the wires can come before they overlap
//! by more than the depth asked, up to a margin: the boxes are grown by half the margin more, so two places in
//! boxes that do not meet are further apart than their radii and the margin, and the narrow phase takes the
//! least of `depth − overlap` over the pairs it measures. A place of a polyline moves no more than its
//! wire's control points do (its position is a convex combination of them, `Σ R_a c_a` with `R_a ≥ 0`), so
//! while no control point has moved half the slack since a search, no new overlap deeper than the depth can
//! have come: a run need not search again (the solver's wire-crossing check). Pairs left out as neighbours
//! along the wires or as a joint's own overlap are taken to stay out while the device moves that little.
//!
//! **Candidates.** A search also lists the pairs of segments it measured within their radii and the margin of
//! each other, in the order it measured them. While no control point has moved half the margin since, no other
//! pair can have come within their radii (each of two places moved less than half the margin), so measuring
//! these pairs alone finds every overlap a new search would, the same and in the same order
//! ([`Wires::recheck`]): a wire that lies through its own mirror image for good (whose slack stays below zero)
//! no longer costs an R*-tree join at every step.
//!
//! **Mirror images.** For a set of symmetry planes the images are the device reflected in every non-empty
//! subset of them (one plane: one image; two: three). A pair between a wire and an image is found as between two
//! wires, its distance along the wires through the nodes lying in every plane of the image (where the wire
//! crosses the cut onto its image); a wire lying in a plane of the image is its own mirror there and has no pair
//! with that image.

use crate::math::{Mat3, Real, Vec3};
use rstar::{AABB, Envelope as _, RTree, RTreeObject};

/// One wire: what stays of a polyline along a rod's centreline while the rod moves (module docs); its points are
/// given to each search ([`Wires::overlaps`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Wire {
    /// The curve parameter of each point (reported with an overlap).
    pub parameters: Vec<Real>,
    /// The reference arc length of each point from the first end, increasing \[length\].
    pub arc: Vec<Real>,
    /// The wire's radius \[length\].
    pub radius: Real,
    /// The node each end belongs to (indices into the device's nodes).
    pub ends: [usize; 2],
    /// The symmetry planes (indices into the [`Mirror`]s) the wire lies in: its own mirror image there.
    pub lies_in: Vec<usize>,
}

/// A symmetry plane of a reduced model (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Mirror {
    /// A point of the plane \[length\].
    pub point: Vec3,
    /// Its unit normal.
    pub normal: Vec3,
    /// The nodes lying in the plane (where wires cross the cut onto their images).
    pub nodes: Vec<usize>,
}

impl Mirror {
    /// The mirror image of `x`.
    fn reflect(&self, x: &Vec3) -> Vec3 {
        x - self.normal * (2.0 * (x - self.point).dot(&self.normal))
    }
}

/// A place on a wire.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WirePoint {
    /// The wire's index.
    pub wire: usize,
    /// The curve parameter there.
    pub parameter: Real,
    /// The reference arc length from the wire's first end \[length\].
    pub arc: Real,
    /// The position (on the image for the second point of a pair with a mirror image) \[length\].
    pub position: Vec3,
}

/// Two wires closer than their radii allow (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Overlap {
    /// `r_a + r_b − d` \[length\], positive.
    pub depth: Real,
    /// The closest point on the first wire.
    pub a: WirePoint,
    /// The closest point on the second wire (on its mirror image when `image > 0`).
    pub b: WirePoint,
    /// 0: the wires themselves; otherwise the image: bit `k − 1`… of `image` set for each plane `k` reflected
    /// (`image = 1` the first plane, `2` the second, `3` both).
    pub image: usize,
}

/// Segments per box of the R*-tree (module docs): a run of consecutive segments of one wire.
const CHUNK: usize = 8;

/// A run of at most [`CHUNK`] consecutive segments of one wire in the R*-tree: its wire, the range of its points
/// (`first ..= last`, segments `first .. last`) and its box grown by the wire's radius.
struct Chunk {
    wire: usize,
    first: usize,
    last: usize,
    envelope: AABB<[Real; 3]>,
}

impl RTreeObject for Chunk {
    type Envelope = AABB<[Real; 3]>;

    fn envelope(&self) -> Self::Envelope {
        self.envelope
    }
}

/// The chunks of `points` (one polyline per wire, already reflected for an image) with their boxes grown by the
/// wire's radius and half the margin, of the segments for which `keep(wire, index)` holds.
fn chunks(
    wires: &[Wire],
    points: &[Vec<Vec3>],
    margin: Real,
    keep: impl Fn(usize, usize) -> bool,
) -> Vec<Chunk> {
    let mut out = Vec::new();
    for (w, (wire, pts)) in wires.iter().zip(points).enumerate() {
        let mut open: Option<Chunk> = None;
        for i in 0..pts.len().saturating_sub(1) {
            if !keep(w, i) {
                out.extend(open.take());
                continue;
            }
            let grow = wire.radius + 0.5 * margin;
            let lo = pts[i].inf(&pts[i + 1]).add_scalar(-grow);
            let hi = pts[i].sup(&pts[i + 1]).add_scalar(grow);
            let segment = AABB::from_corners([lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z]);
            match &mut open {
                Some(c) if c.last == i && c.last - c.first < CHUNK => {
                    c.last = i + 1;
                    c.envelope.merge(&segment);
                }
                _ => {
                    out.extend(open.take());
                    open = Some(Chunk {
                        wire: w,
                        first: i,
                        last: i + 1,
                        envelope: segment,
                    });
                }
            }
        }
        out.extend(open);
    }
    out
}

/// The closest points of segments `p0 p1` and `q0 q1`: their parameters `(s, t)` in `[0, 1]` (Ericson 2005,
/// §5.1.9, `ClosestPtSegmentSegment`).
pub fn closest_points(p0: &Vec3, p1: &Vec3, q0: &Vec3, q1: &Vec3) -> (Real, Real) {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let tiny = Real::EPSILON * (a + e).max(Real::MIN_POSITIVE);
    if a <= tiny && e <= tiny {
        return (0.0, 0.0);
    }
    if a <= tiny {
        return (0.0, (f / e).clamp(0.0, 1.0));
    }
    let c = d1.dot(&r);
    if e <= tiny {
        return ((-c / a).clamp(0.0, 1.0), 0.0);
    }
    let b = d1.dot(&d2);
    let denom = a * e - b * b;
    // Parallel segments (denominator zero): any s; 0 is as good as another, t follows.
    let mut s = if denom > tiny * (a + e) {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    (s, t)
}

/// Distances along the wires between the nodes, up to a cutoff (module docs): for each node, the nodes
/// within `cutoff` of it through the wires and how far.
struct Graph {
    near: Vec<Vec<(usize, Real)>>,
}

impl Graph {
    /// Dijkstra from every node over the wires' reference lengths, stopped at `cutoff`.
    fn new(wires: &[Wire], nodes: usize, cutoff: Real) -> Self {
        let mut adjacent = vec![Vec::new(); nodes];
        for w in wires {
            let length =
                w.arc.last().copied().unwrap_or(0.0) - w.arc.first().copied().unwrap_or(0.0);
            let [a, b] = w.ends;
            adjacent[a].push((b, length));
            adjacent[b].push((a, length));
        }
        let near = (0..nodes)
            .map(|start| {
                let mut found: Vec<(usize, Real)> = vec![(start, 0.0)];
                let mut frontier = vec![(start, 0.0)];
                while let Some((node, d)) = frontier.pop() {
                    for &(next, l) in &adjacent[node] {
                        let dn = d + l;
                        if dn >= cutoff {
                            continue;
                        }
                        match found.iter_mut().find(|(k, _)| *k == next) {
                            Some(entry) if entry.1 <= dn => {}
                            Some(entry) => {
                                entry.1 = dn;
                                frontier.push((next, dn));
                            }
                            None => {
                                found.push((next, dn));
                                frontier.push((next, dn));
                            }
                        }
                    }
                }
                found
            })
            .collect();
        Self { near }
    }

    /// The distance along the wires from node `a` to node `b`, or infinity beyond the cutoff.
    fn between(&self, a: usize, b: usize) -> Real {
        (self.near[a].iter())
            .find(|(k, _)| *k == b)
            .map_or(Real::INFINITY, |&(_, d)| d)
    }
}

/// An upper bound of the distance along the wires between any point of wire `a.0` between its points `a.1 ..=
/// a.2` and any of wire `b.0` between its points `b.1 ..= b.2` (the far points of both): along one wire, or
/// through a node the wires' ends share (`through` as in [`along`]); infinity if neither.
fn near_along(
    wires: &[Wire],
    a: (usize, usize, usize),
    b: (usize, usize, usize),
    through: Option<&[usize]>,
) -> Real {
    let far = |(w, lo, hi): (usize, usize, usize), end: usize| {
        let arc = &wires[w].arc;
        if end == 0 {
            arc[hi] - arc[0]
        } else {
            arc[arc.len() - 1] - arc[lo]
        }
    };
    let mut best = Real::INFINITY;
    if through.is_none() && a.0 == b.0 {
        let arc = &wires[a.0].arc;
        best = arc[a.2.max(b.2)] - arc[a.1.min(b.1)];
    }
    for ea in 0..2 {
        let node = wires[a.0].ends[ea];
        if through.is_some_and(|nodes| !nodes.contains(&node)) {
            continue;
        }
        for eb in 0..2 {
            if wires[b.0].ends[eb] == node && (a.0 != b.0 || ea != eb || through.is_some()) {
                best = best.min(far(a, ea) + far(b, eb));
            }
        }
    }
    best
}

/// How far along wire `a` from its end `end` (at a node wire `b` shares) the two overlap without a break: the
/// reference arc length from that end to the first point of `a` at least `r_a + r_b` from `b`'s polyline (the
/// whole wire's length if there is none). An overlap nearer the node than that is the joint's own (module docs).
fn joint_reach(wires: &[Wire], a: (usize, &[Vec3]), end: usize, b: (usize, &[Vec3])) -> Real {
    let (wire, points) = (&wires[a.0], a.1);
    let clear = wire.radius + wires[b.0].radius;
    let distance = |x: &Vec3| {
        (b.1.windows(2))
            .map(|q| {
                let (_, t) = closest_points(x, x, &q[0], &q[1]);
                (x - (q[0] + (q[1] - q[0]) * t)).norm()
            })
            .fold(Real::INFINITY, Real::min)
    };
    let n = points.len();
    let (first, last) = (wire.arc[0], wire.arc[n - 1]);
    let order: Vec<usize> = if end == 0 {
        (0..n).collect()
    } else {
        (0..n).rev().collect()
    };
    for i in order {
        if distance(&points[i]) >= clear {
            return if end == 0 {
                wire.arc[i] - first
            } else {
                last - wire.arc[i]
            };
        }
    }
    last - first
}

/// The distance along the wires from the point at arc length `s` of wire `w` to each of its end nodes.
fn to_ends(wires: &[Wire], w: usize, s: Real) -> [(usize, Real); 2] {
    let wire = &wires[w];
    let (first, last) = (wire.arc[0], wire.arc[wire.arc.len() - 1]);
    [(wire.ends[0], s - first), (wire.ends[1], last - s)]
}

/// The distance along the wires between two wire points (module docs), through the nodes `through` (every node
/// when `None`: the wires themselves; the nodes in the image's planes for an image).
fn along(
    wires: &[Wire],
    graph: &Graph,
    a: (usize, Real),
    b: (usize, Real),
    through: Option<&[usize]>,
) -> Real {
    let mut best = Real::INFINITY;
    if through.is_none() && a.0 == b.0 {
        best = (a.1 - b.1).abs();
    }
    for (na, da) in to_ends(wires, a.0, a.1) {
        for (nb, db) in to_ends(wires, b.0, b.1) {
            let via = match through {
                None => graph.between(na, nb),
                // Across the cut: from a's end to a node in the planes, and from there to b's end (b's image's
                // path is the mirror of b's own).
                Some(nodes) => nodes
                    .iter()
                    .map(|&m| graph.between(na, m) + graph.between(m, nb))
                    .fold(Real::INFINITY, Real::min),
            };
            best = best.min(da + via + db);
        }
    }
    best
}

/// The wires of a device with its symmetry planes and the distances along them between its nodes: what the
/// searches of its overlaps share (module docs).
pub struct Wires {
    wires: Vec<Wire>,
    mirrors: Vec<Mirror>,
    graph: Graph,
}

impl Wires {
    /// The wires, the symmetry planes and the number of the device's nodes (the largest index in
    /// [`Wire::ends`] and [`Mirror::nodes`] plus one at least).
    pub fn new(wires: Vec<Wire>, mirrors: Vec<Mirror>, nodes: usize) -> Self {
        let largest = wires.iter().map(|w| w.radius).fold(0.0, Real::max);
        let graph = Graph::new(&wires, nodes, 4.0 * largest);
        Self {
            wires,
            mirrors,
            graph,
        }
    }

    /// The wires.
    pub fn wires(&self) -> &[Wire] {
        &self.wires
    }

    /// The image `image` (as [`Overlap::image`]) as an affine map `x ↦ M x + b`: `M` (symmetric, its own
    /// inverse for the orthogonal planes of a reduced model) and `b`.
    pub fn image_map(&self, image: usize) -> (Mat3, Vec3) {
        (self.mirrors.iter().enumerate())
            .filter(|(k, _)| image & (1 << k) != 0)
            .fold((Mat3::identity(), Vec3::zeros()), |(m, b), (_, mirror)| {
                let r = Mat3::identity() - mirror.normal * mirror.normal.transpose() * 2.0;
                let shift = mirror.normal * (2.0 * mirror.point.dot(&mirror.normal));
                (r * m, r * b + shift)
            })
    }

    /// Every pair of places on the wires at `points` (one polyline per wire, as many points as its
    /// parameters) closer than their radii allow by more than `depth`, the deepest per pair of wires and image,
    /// deepest first (module docs).
    pub fn overlaps(&self, points: &[Vec<Vec3>], depth: Real) -> Vec<Overlap> {
        self.search(points, depth, 0.0).overlaps
    }

    /// [`Wires::overlaps`], and how much closer any two places of the wires (that are not neighbours along
    /// them) can come before they overlap by more than `depth`, at most `margin` (module docs, *Slack*).
    pub fn search(&self, points: &[Vec<Vec3>], depth: Real, margin: Real) -> Search {
        search(
            &self.wires,
            &self.mirrors,
            &self.graph,
            points,
            depth,
            margin,
        )
    }

    /// [`Wires::search`] over the `candidates` of an earlier search with the same `depth` and `margin` only,
    /// which finds the same overlaps while no control point has moved half the margin since (module docs,
    /// *Candidates*); its slack is that of the candidates (the caller bounds the others').
    pub fn recheck(
        &self,
        points: &[Vec<Vec3>],
        depth: Real,
        margin: Real,
        candidates: &[Candidate],
    ) -> Search {
        recheck(
            &self.wires,
            &self.mirrors,
            &self.graph,
            points,
            depth,
            margin,
            candidates,
        )
    }
}

impl Wires {
    /// Every point of the wires at `points` within `r_a + r_b + margin` of a segment of another wire, or of the
    /// same wire further along it, or of an image (module docs), the two not neighbours along the wires nor a
    /// joint's own overlap: each point with each such segment, both ways round (a point of `a` near a segment of
    /// `b`, and the points of that segment near the segment of `a`), sorted.
    pub fn near(&self, points: &[Vec<Vec3>], margin: Real) -> Vec<Near> {
        let mut out = Vec::new();
        let mut reaches = std::collections::HashMap::new();
        let wires = &self.wires;
        scan(
            wires,
            &self.mirrors,
            &self.graph,
            points,
            margin,
            &mut |context, pair| {
                let (wa, wb) = (pair.a.wire, pair.b.wire);
                if pair.distance >= wires[wa].radius + wires[wb].radius + margin
                    || context.joined(&pair, &mut reaches)
                {
                    return;
                }
                let image = pair.image;
                for point in [pair.i, pair.i + 1] {
                    out.push(Near {
                        wire: wa,
                        point,
                        other: wb,
                        segment: pair.j,
                        image,
                    });
                }
                for point in [pair.j, pair.j + 1] {
                    out.push(Near {
                        wire: wb,
                        point,
                        other: wa,
                        segment: pair.i,
                        image,
                    });
                }
            },
        );
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// What [`Wires::search`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct Search {
    /// The overlaps deeper than the depth asked, deepest first.
    pub overlaps: Vec<Overlap>,
    /// How much closer any two places can come before they overlap by more than the depth (negative where they
    /// do), at most the margin asked \[length\].
    pub slack: Real,
    /// The pairs of segments within their radii and the margin of each other, in the order measured (module
    /// docs, *Candidates*; empty from [`Wires::recheck`]).
    pub candidates: Vec<Candidate>,
}

/// Two segments a search found within reach of each other (module docs, *Candidates*): segment `a.1` of wire
/// `a.0` and segment `b.1` of wire `b.0` of the image `image`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Candidate {
    a: (usize, usize),
    b: (usize, usize),
    image: usize,
}

/// Two segments within reach of each other (their radii and the scan's margin, by their boxes), not
/// neighbours along the wires as wholes: the first's `i`-th segment of wire `wa`, the second's `j`-th of wire `wb`
/// (of the image `image`), their closest points and where those lie on the wires.
struct SegmentPair {
    i: usize,
    j: usize,
    image: usize,
    /// Distance of the closest points \[length\].
    distance: Real,
    a: WirePoint,
    b: WirePoint,
}

/// What the scan of one image shares with its visitor: the wires, the distances along them and, for an image,
/// the nodes a path across its planes goes through.
struct ScanContext<'a> {
    wires: &'a [Wire],
    graph: &'a Graph,
    own: &'a [Vec<Vec3>],
    other: &'a [Vec<Vec3>],
    through: Option<&'a [usize]>,
}

impl ScanContext<'_> {
    /// Whether the closest points of `pair` are neighbours along the wires or a joint's own overlap (module
    /// docs): no contact. `reaches` keeps each joint's reach across the calls of one scan.
    fn joined(
        &self,
        pair: &SegmentPair,
        reaches: &mut std::collections::HashMap<(usize, usize, usize, usize), Real>,
    ) -> bool {
        let (wires, (a, b)) = (self.wires, (&pair.a, &pair.b));
        let (wa, wb, image) = (a.wire, b.wire, pair.image);
        let threshold = 2.0 * (wires[wa].radius + wires[wb].radius);
        if along(wires, self.graph, (wa, a.arc), (wb, b.arc), self.through) < threshold {
            return true;
        }
        let joined = |m: &usize| self.through.is_none_or(|nodes| nodes.contains(m));
        // The ends of wire a at a node wire b shares (a wire shares its own end with itself only where its two
        // ends are one node, or across a cut with its image).
        let shares = |ea: usize| {
            let node = wires[wa].ends[ea];
            joined(&node)
                && if wa == wb && image == 0 {
                    wires[wa].ends[1 - ea] == node
                } else {
                    wires[wb].ends.contains(&node)
                }
        };
        (0..2).filter(|&ea| shares(ea)).any(|ea| {
            let reach = *reaches.entry((wa, wb, image, ea)).or_insert_with(|| {
                joint_reach(wires, (wa, &self.own[wa]), ea, (wb, &self.other[wb]))
            });
            let from_end = if ea == 0 {
                a.arc - wires[wa].arc[0]
            } else {
                wires[wa].arc[wires[wa].arc.len() - 1] - a.arc
            };
            from_end < reach
        })
    }
}

/// The image `image` of the wires at `own` (module docs, *Mirror images*): the planes it reflects in, the nodes a
/// path across all of them goes through, and its points (`None` for the wires themselves, `image = 0`).
struct Image {
    planes: Vec<usize>,
    through: Option<Vec<usize>>,
    points: Option<Vec<Vec<Vec3>>>,
}

impl Image {
    fn of(mirrors: &[Mirror], own: &[Vec<Vec3>], image: usize) -> Self {
        let planes: Vec<usize> = (0..mirrors.len())
            .filter(|k| image & (1 << k) != 0)
            .collect();
        let through = (image > 0).then(|| {
            let mut nodes = mirrors[planes[0]].nodes.clone();
            nodes.retain(|m| planes.iter().all(|&k| mirrors[k].nodes.contains(m)));
            nodes
        });
        let reflect = |x: &Vec3| planes.iter().fold(*x, |y, &k| mirrors[k].reflect(&y));
        let points = (image > 0).then(|| {
            own.iter()
                .map(|pts| pts.iter().map(reflect).collect())
                .collect()
        });
        Self {
            planes,
            through,
            points,
        }
    }

    /// The scan's context for this image of the wires at `own`.
    fn context<'a>(
        &'a self,
        wires: &'a [Wire],
        graph: &'a Graph,
        own: &'a [Vec<Vec3>],
    ) -> ScanContext<'a> {
        ScanContext {
            wires,
            graph,
            own,
            other: self.points.as_deref().unwrap_or(own),
            through: self.through.as_deref(),
        }
    }
}

/// Segment `i` of wire `wa` and segment `j` of wire `wb` of the image `image` of `context`, measured: their
/// closest points, or `None` where their own boxes grown by their radii and `margin` do not meet or they are
/// neighbours along the wires (module docs: narrow phase).
fn measure(
    context: &ScanContext<'_>,
    image: usize,
    (wa, i): (usize, usize),
    (wb, j): (usize, usize),
    margin: Real,
) -> Option<SegmentPair> {
    let wires = context.wires;
    let (ra, rb) = (wires[wa].radius, wires[wb].radius);
    let (p0, p1) = (&context.own[wa][i], &context.own[wa][i + 1]);
    let (q0, q1) = (&context.other[wb][j], &context.other[wb][j + 1]);
    // The segments' own boxes, grown by the radii and the margin, first.
    let reach = Vec3::repeat(ra + rb + margin);
    if (p0.inf(p1) - q0.sup(q1) - reach).max() > 0.0
        || (q0.inf(q1) - p0.sup(p1) - reach).max() > 0.0
    {
        return None;
    }
    if near_along(wires, (wa, i, i + 1), (wb, j, j + 1), context.through) < 2.0 * (ra + rb) {
        return None;
    }
    let (s, t) = closest_points(p0, p1, q0, q1);
    let (x, y) = (p0 + (p1 - p0) * s, q0 + (q1 - q0) * t);
    let point = |w: usize, i: usize, f: Real, position: Vec3| {
        let wire = &wires[w];
        let lerp = |v: &[Real]| v[i] + (v[i + 1] - v[i]) * f;
        WirePoint {
            wire: w,
            parameter: lerp(&wire.parameters),
            arc: lerp(&wire.arc),
            position,
        }
    };
    Some(SegmentPair {
        i,
        j,
        image,
        distance: (x - y).norm(),
        a: point(wa, i, s, x),
        b: point(wb, j, t, y),
    })
}

/// Every pair of segments of the wires at `own` (and of the wires with each mirror image) whose boxes, grown by
/// their radii and `margin`, meet and that are not neighbours along the wires segment by segment, each pair once,
/// given to `visit` with the scan's context (module docs: broad and narrow phase).
fn scan(
    wires: &[Wire],
    mirrors: &[Mirror],
    graph: &Graph,
    own: &[Vec<Vec3>],
    margin: Real,
    visit: &mut dyn FnMut(&ScanContext<'_>, SegmentPair),
) {
    let largest = wires.iter().map(|w| w.radius).fold(0.0, Real::max);
    let tree = RTree::bulk_load(chunks(wires, own, margin, |_, _| true));
    for image in 0..(1usize << mirrors.len()) {
        let this = Image::of(mirrors, own, image);
        let planes = &this.planes;
        // A segment can touch an image only within the two largest radii of each of its planes: the image is on
        // the other side.
        let near_planes = |w: usize, i: usize| {
            planes.iter().all(|&k| {
                let m = &mirrors[k];
                let (d0, d1) = (
                    (own[w][i] - m.point).dot(&m.normal),
                    (own[w][i + 1] - m.point).dot(&m.normal),
                );
                d0 * d1 <= 0.0 || d0.abs().min(d1.abs()) < 2.0 * largest + margin
            })
        };
        let context = this.context(wires, graph, own);
        let (near_tree, image_tree);
        let candidates = if image == 0 {
            tree.intersection_candidates_with_other_tree(&tree)
        } else {
            near_tree = RTree::bulk_load(chunks(wires, own, margin, near_planes));
            image_tree = RTree::bulk_load(chunks(wires, context.other, margin, near_planes));
            near_tree.intersection_candidates_with_other_tree(&image_tree)
        };
        let through = this.through.as_deref();
        // Each pair once: (a, b) and (b, a) are the same contact, with an image as without (the chunks of an
        // image are those of the wires); a segment and itself are no pair, but a segment and its own mirror
        // image are.
        let chunk_pairs = candidates.filter(|(ca, cb)| {
            let (wa, wb) = (ca.wire, cb.wire);
            (wa, ca.first) <= (wb, cb.first)
                && !planes
                    .iter()
                    .any(|k| wires[wa].lies_in.contains(k) || wires[wb].lies_in.contains(k))
                // Neighbours along the wires wherever their closest points fall: most candidates (a chunk's
                // box meets those of its neighbours on its own wire and across its nodes).
                && near_along(wires, (wa, ca.first, ca.last), (wb, cb.first, cb.last), through)
                    >= 2.0 * (wires[wa].radius + wires[wb].radius)
        });
        let pairs = chunk_pairs.flat_map(|(ca, cb)| {
            (ca.first..ca.last).flat_map(move |i| (cb.first..cb.last).map(move |j| (ca, i, cb, j)))
        });
        for (ca, i, cb, j) in pairs {
            let (wa, wb) = (ca.wire, cb.wire);
            if (wa, i) > (wb, j) || ((wa, i) == (wb, j) && image == 0) {
                continue;
            }
            if let Some(pair) = measure(&context, image, (wa, i), (wb, j), margin) {
                visit(&context, pair);
            }
        }
    }
}

/// What a search or a recheck gathers from the pairs it measures (module docs, *Slack* and *Candidates*): the
/// deepest overlap beyond `depth` per pair of wires and image, the slack, and for a search the pairs within reach.
struct Gather {
    depth: Real,
    margin: Real,
    slack: Real,
    found: Vec<Overlap>,
    /// How far from a shared node two wires overlap without a break (joint_reach), per wire, other wire, image
    /// and end.
    reaches: std::collections::HashMap<(usize, usize, usize, usize), Real>,
    /// The pairs within reach, kept by a search (`None` for a recheck, which measures an earlier search's).
    candidates: Option<Vec<Candidate>>,
}

impl Gather {
    fn new(depth: Real, margin: Real, candidates: Option<Vec<Candidate>>) -> Self {
        Self {
            depth,
            margin,
            slack: margin,
            found: Vec::new(),
            reaches: std::collections::HashMap::new(),
            candidates,
        }
    }

    fn visit(&mut self, context: &ScanContext<'_>, pair: SegmentPair) {
        let wires = context.wires;
        let (wa, wb, image) = (pair.a.wire, pair.b.wire, pair.image);
        let radii = wires[wa].radius + wires[wb].radius;
        if let Some(candidates) =
            (self.candidates.as_mut()).filter(|_| pair.distance < radii + self.margin)
        {
            candidates.push(Candidate {
                a: (wa, pair.i),
                b: (wb, pair.j),
                image,
            });
        }
        let overlap = radii - pair.distance;
        if overlap <= self.depth {
            self.slack = self.slack.min(self.depth - overlap);
            return;
        }
        // A pair no deeper than the one already kept for its wires and image changes nothing: the tests of
        // neighbours and joints are only made for a pair that would be kept.
        let key = (wa, wb, image);
        let kept = (self.found.iter()).position(|o| (o.a.wire, o.b.wire, o.image) == key);
        if kept.is_some_and(|k| self.found[k].depth >= overlap)
            || context.joined(&pair, &mut self.reaches)
        {
            return;
        }
        let o = Overlap {
            depth: overlap,
            a: pair.a,
            b: pair.b,
            image,
        };
        match kept {
            Some(k) => self.found[k] = o,
            None => self.found.push(o),
        }
    }

    fn finish(mut self) -> Search {
        self.found.sort_by(|x, y| y.depth.total_cmp(&x.depth));
        if let Some(deepest) = self.found.first() {
            self.slack = self.slack.min(self.depth - deepest.depth);
        }
        Search {
            overlaps: self.found,
            slack: self.slack,
            candidates: self.candidates.unwrap_or_default(),
        }
    }
}

/// [`Wires::search`].
fn search(
    wires: &[Wire],
    mirrors: &[Mirror],
    graph: &Graph,
    own: &[Vec<Vec3>],
    depth: Real,
    margin: Real,
) -> Search {
    let mut gather = Gather::new(depth, margin, Some(Vec::new()));
    scan(wires, mirrors, graph, own, margin, &mut |context, pair| {
        gather.visit(context, pair);
    });
    gather.finish()
}

/// [`Wires::recheck`]: the candidates measured again at `own`, in the order the search found them (so a tie
/// between two equally deep pairs is kept as the search would), image by image.
fn recheck(
    wires: &[Wire],
    mirrors: &[Mirror],
    graph: &Graph,
    own: &[Vec<Vec3>],
    depth: Real,
    margin: Real,
    candidates: &[Candidate],
) -> Search {
    let mut gather = Gather::new(depth, margin, None);
    for run in candidates.chunk_by(|x, y| x.image == y.image) {
        let image = Image::of(mirrors, own, run[0].image);
        let context = image.context(wires, graph, own);
        for c in run {
            if let Some(pair) = measure(&context, c.image, c.a, c.b, margin) {
                gather.visit(&context, pair);
            }
        }
    }
    gather.finish()
}

/// A point of one wire within reach of a segment of another wire (or of a mirror image), for contact between
/// them ([`Wires::near`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Near {
    /// The wire of the point.
    pub wire: usize,
    /// The point's index in its wire's polyline.
    pub point: usize,
    /// The other wire.
    pub other: usize,
    /// The segment of the other wire (between its points `segment` and `segment + 1`).
    pub segment: usize,
    /// The image of the other wire the segment belongs to (as [`Overlap::image`]).
    pub image: usize,
}

#[cfg(test)]
mod tests {
    use super::{Mirror, Overlap, Wire, Wires, closest_points};
    use crate::math::{Real, Vec3};

    /// A straight wire from `a` to `b` in `n` segments between nodes `ends`, and its points.
    fn straight(a: Vec3, b: Vec3, n: usize, radius: Real, ends: [usize; 2]) -> (Wire, Vec<Vec3>) {
        let points: Vec<Vec3> = (0..=n)
            .map(|i| a + (b - a) * (i as Real / n as Real))
            .collect();
        let length = (b - a).norm();
        let wire = Wire {
            parameters: (0..=n).map(|i| i as Real / n as Real).collect(),
            arc: (0..=n).map(|i| length * i as Real / n as Real).collect(),
            radius,
            ends,
            lies_in: Vec::new(),
        };
        (wire, points)
    }

    /// The overlaps of `wires` (with their points) deeper than zero.
    fn overlaps(wires: &[(Wire, Vec<Vec3>)], mirrors: &[Mirror], nodes: usize) -> Vec<Overlap> {
        let points: Vec<Vec<Vec3>> = wires.iter().map(|w| w.1.clone()).collect();
        let wires = wires.iter().map(|w| w.0.clone()).collect();
        Wires::new(wires, mirrors.to_vec(), nodes).overlaps(&points, 0.0)
    }

    #[test]
    fn closest_points_of_segments_match_their_closed_forms() {
        // Crossing at right angles, 2 apart along z: the closest points are the crossing's, at the middles.
        let (s, t) = closest_points(
            &Vec3::new(-1.0, 0.0, 0.0),
            &Vec3::new(1.0, 0.0, 0.0),
            &Vec3::new(0.0, -1.0, 2.0),
            &Vec3::new(0.0, 3.0, 2.0),
        );
        assert!(
            (s - 0.5).abs() < 1e-15 && (t - 0.25).abs() < 1e-15,
            "{s} {t}"
        );
        // Parallel, overlapping in x from 1 to 2: a closest pair with the same x in the overlap.
        let (p0, p1) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0));
        let (q0, q1) = (Vec3::new(1.0, 1.0, 0.0), Vec3::new(3.0, 1.0, 0.0));
        let (s, t) = closest_points(&p0, &p1, &q0, &q1);
        let (x, y) = (p0 + (p1 - p0) * s, q0 + (q1 - q0) * t);
        assert!(((x - y).norm() - 1.0).abs() < 1e-15, "{x} {y}");
        // Apart along their line: the facing ends.
        let (s, t) = closest_points(
            &p0,
            &p1,
            &Vec3::new(5.0, 0.0, 0.0),
            &Vec3::new(7.0, 0.0, 0.0),
        );
        assert_eq!((s, t), (1.0, 0.0));
    }

    #[test]
    fn two_crossing_wires_overlap_by_the_sum_of_radii_less_their_distance() {
        // Two free wires crossing 0.15 apart with radii 0.1: overlap 0.05 at the crossing.
        let a = straight(
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            7,
            0.1,
            [0, 1],
        );
        let b = straight(
            Vec3::new(0.0, -1.0, 0.15),
            Vec3::new(0.0, 1.0, 0.15),
            9,
            0.1,
            [2, 3],
        );
        let found = overlaps(&[a.clone(), b], &[], 4);
        assert_eq!(found.len(), 1);
        let o = found[0];
        assert!((o.depth - 0.05).abs() < 1e-14, "{o:?}");
        assert!((o.a.position - Vec3::new(0.0, 0.0, 0.0)).norm() < 1e-14);
        assert!((o.a.parameter - 0.5).abs() < 1e-14 && (o.b.arc - 1.0).abs() < 1e-14);
        // 0.25 apart they clear each other.
        let c = straight(
            Vec3::new(0.0, -1.0, 0.25),
            Vec3::new(0.0, 1.0, 0.25),
            9,
            0.1,
            [2, 3],
        );
        assert!(overlaps(&[a, c], &[], 4).is_empty());
    }

    #[test]
    fn wires_meeting_at_a_node_overlap_only_beyond_the_joint() {
        // Two wires from one node at 90°: near the node by construction, nowhere beyond twice the radii.
        let r = 0.05;
        let a = straight(Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0), 40, r, [0, 1]);
        let b = straight(Vec3::zeros(), Vec3::new(0.0, 1.0, 0.0), 40, r, [0, 2]);
        assert!(overlaps(&[a.clone(), b], &[], 3).is_empty());
        // At 20° they lie within 2r of each other out to s = r / sin 10° = 5.76 r along each, past 4r apart
        // along the wires, but without a break from the node: the joint's own overlap.
        let angle: Real = 20f64.to_radians();
        let c = straight(
            Vec3::zeros(),
            Vec3::new(angle.cos(), angle.sin(), 0.0),
            400,
            r,
            [0, 2],
        );
        assert!(overlaps(&[a.clone(), c], &[], 3).is_empty());
        // Up from the node and back down onto the first wire, its free end 0.05 above it: clear of it in
        // between, so the overlap there (2r − 0.05 = 0.05) is a contact.
        let (mut d, mut points) = straight(Vec3::zeros(), Vec3::new(0.0, 0.5, 0.0), 20, r, [0, 2]);
        let (back, more) = straight(
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::new(1.0, 0.05, 0.0),
            40,
            r,
            [0, 2],
        );
        points.extend_from_slice(&more[1..]);
        let length = d.arc[20];
        d.arc.extend(back.arc[1..].iter().map(|s| s + length));
        d.parameters = (0..points.len()).map(|i| i as Real).collect();
        let found = overlaps(&[a, (d, points)], &[], 3);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!((found[0].depth - 0.05).abs() < 1e-14, "{:?}", found[0]);
        assert!((found[0].b.position - Vec3::new(1.0, 0.05, 0.0)).norm() < 1e-14);
    }

    #[test]
    fn a_wire_bent_back_onto_itself_touches_itself() {
        // A hairpin: out along x, a half circle of centreline radius 0.08, back 0.16 above; radius 0.1 each, so
        // the legs overlap by 0.2 − 0.16 = 0.04 beyond the bend.
        let r = 0.1;
        let rho = 0.08;
        let mut points = Vec::new();
        for i in 0..=50 {
            points.push(Vec3::new(2.0 - 2.0 * i as Real / 50.0, 0.0, 0.0));
        }
        for i in 1..=60 {
            let phi = std::f64::consts::PI * i as Real / 60.0;
            points.push(Vec3::new(-rho * phi.sin(), rho - rho * phi.cos(), 0.0));
        }
        for i in 1..=50 {
            points.push(Vec3::new(2.0 * i as Real / 50.0, 2.0 * rho, 0.0));
        }
        let mut arc = vec![0.0];
        for w in points.windows(2) {
            arc.push(arc[arc.len() - 1] + (w[1] - w[0]).norm());
        }
        let wire = Wire {
            parameters: arc.clone(),
            arc,
            radius: r,
            ends: [0, 1],
            lies_in: Vec::new(),
        };
        let found = overlaps(&[(wire, points)], &[], 2);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!((found[0].depth - 0.04).abs() < 1e-12, "{:?}", found[0]);
    }

    #[test]
    fn a_wire_near_a_symmetry_plane_touches_its_mirror_image() {
        // A wire along x at y = 0.07 with radius 0.1 and the plane y = 0: its image at y = −0.07 overlaps by 0.06.
        // A wire crossing the plane at a node on it is its image's continuation there, not a contact.
        let a = straight(
            Vec3::new(0.0, 0.07, 0.0),
            Vec3::new(1.0, 0.07, 0.0),
            10,
            0.1,
            [0, 1],
        );
        let cut = straight(
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(3.0, 1.0, 0.0),
            10,
            0.1,
            [2, 3],
        );
        let plane = Mirror {
            point: Vec3::zeros(),
            normal: Vec3::y(),
            nodes: vec![2],
        };
        let found = overlaps(&[a.clone(), cut.clone()], std::slice::from_ref(&plane), 4);
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(
            (found[0].a.wire, found[0].b.wire, found[0].image),
            (0, 0, 1)
        );
        assert!((found[0].depth - 0.06).abs() < 1e-14);
        // A wire lying in the plane is its own mirror: no pair with its image.
        let mut inside = straight(
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            10,
            0.1,
            [4, 5],
        );
        inside.0.lies_in = vec![0];
        assert!(overlaps(&[cut, inside], &[plane], 6).is_empty());
    }

    #[test]
    fn a_recheck_of_the_candidates_finds_what_a_new_search_finds_after_a_small_motion() {
        // Radii 0.1, margin 0.1: `a` and `b` cross 0.15 apart (overlap 0.05); `c` runs beside `a`'s end 0.27 away
        // (within reach, no overlap); `d` lies 0.07 from the plane y = −1 (through its image by 0.06). Then `a`
        // moves 0.045 towards `c` and `c` 0.045 towards `a` (under half the margin each): they overlap by 0.02,
        // a pair the first search found within reach but not overlapping.
        let a = straight(
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            10,
            0.1,
            [0, 1],
        );
        let b = straight(
            Vec3::new(0.0, -0.9, 0.15),
            Vec3::new(0.0, 0.9, 0.15),
            10,
            0.1,
            [2, 3],
        );
        let c = straight(
            Vec3::new(0.5, 0.27, 0.0),
            Vec3::new(2.0, 0.27, 0.0),
            10,
            0.1,
            [4, 5],
        );
        let d = straight(
            Vec3::new(3.0, -0.93, 0.0),
            Vec3::new(4.0, -0.93, 0.0),
            10,
            0.1,
            [6, 7],
        );
        let plane = Mirror {
            point: Vec3::new(0.0, -1.0, 0.0),
            normal: Vec3::y(),
            nodes: Vec::new(),
        };
        let all = [a, b, c, d];
        let wires = Wires::new(all.iter().map(|w| w.0.clone()).collect(), vec![plane], 8);
        let before: Vec<Vec<Vec3>> = all.iter().map(|w| w.1.clone()).collect();
        let (depth, margin) = (0.0, 0.1);
        let first = wires.search(&before, depth, margin);
        assert_eq!(first.overlaps.len(), 2, "{:?}", first.overlaps);
        let mut after = before.clone();
        for (w, shift) in [(0, 0.045), (2, -0.045)] {
            for x in &mut after[w] {
                x.y += shift;
            }
        }
        let again = wires.search(&after, depth, margin);
        let rechecked = wires.recheck(&after, depth, margin, &first.candidates);
        assert_eq!(again.overlaps.len(), 3, "{:?}", again.overlaps);
        assert_eq!(rechecked.overlaps, again.overlaps);
        let ac = (again.overlaps.iter()).find(|o| (o.a.wire, o.b.wire) == (0, 2));
        assert!(ac.is_some_and(|o| (o.depth - 0.02).abs() < 1e-12), "{ac:?}");
        // The candidates' slack is below zero where they overlap, as the search's.
        assert!(rechecked.slack < 0.0 && again.slack < 0.0);
    }
}
