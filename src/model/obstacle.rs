//! Obstacles: surfaces the rods of a device touch (issue 33) — a cylinder that keeps the rods inside it (a
//! crimper, a catheter sheath, a vessel idealised as a tube), a plane that keeps them on one side (a crush plate,
//! a table), a vessel's lumen around its centreline spline ([`Lumen`]) — with a rigid or a compliant wall (a
//! plane's: rigid), and the contact settings of a model.
//!
//! What an obstacle is, not how the solver enforces it: the geometry gives the signed distance of a point from
//! the surface (positive on the side the rods belong to), its gradient and its Hessian
//! ([`Surface::distance`]); the contact law and the augmented-Lagrange updates are the solver's
//! (`crate::solver::terms::contact`).
//!
//! **Compliant wall.** A thin tube of Young's modulus `E_w`, thickness `h` and radius `R` under an internal
//! pressure `q` widens by `δ = q R² / (E_w h)` (Laplace's law for a thin tube, hoop stress `q R / h`, hoop strain
//! `δ / R`): a radial foundation of stiffness `k = E_w h / R²` \[force/length³\]. A wire presses on the strip of
//! wall it carries, of width `b` (the wall area per unit length of wire), so its line force per unit wire length is
//! `k b` times the wall's displacement: the contact law's penalty becomes the physical `k b`, and the
//! penetration is the wall's displacement, not an error (no augmented-Lagrange updates). On a lumen `R` is the
//! local radius `R(u)` where the wire touches ([`Surface::wall_radius`]): a vessel is stiffer where it is
//! narrower. Each point of wall carries its own wire (a Winkler foundation: the hoop coupling between points
//! along the circumference, which spreads a strut's load over the tube, is left out).
//!
//! **Friction.** Each obstacle has its Coulomb coefficient ([`Obstacle::friction`]): a point in contact carries
//! a tangential line force of at most `μ p` opposing its slip over the surface (the solver's regularised law).

use super::schedule::TimeFunction;
use crate::math::{Mat3, NurbsCurve, Real, Vec3};

/// A surface the rods touch, with its wall (module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Obstacle {
    /// Unique name (history columns, messages).
    pub name: String,
    /// The surface.
    pub surface: Surface,
    /// Rigid, or a compliant wall.
    pub wall: Wall,
    /// The times it acts between, `(from, until)`: from just after `from` (an obstacle put in place at
    /// `from`, such as a vessel the programmed device is deployed in, or a sheath put over it) to `until`
    /// (withdrawn; `None`: never). `(0, None)` acts over the whole run.
    pub active: (Real, Option<Real>),
    /// Coulomb friction coefficient `μ ≥ 0` between the rods and this surface (0: frictionless). Per obstacle,
    /// not in [`ContactSettings`], because it belongs to the pair of materials that touch: one device meets a
    /// polished crimper (μ ≈ 0.1), a sheath and a vessel wall, each with its own; the regularisation of the law
    /// (its stick stiffness) is the solver's (`crate::solver::terms::contact`).
    pub friction: Real,
}

impl Obstacle {
    /// An obstacle acting over the whole run.
    pub fn new(name: impl Into<String>, surface: Surface, wall: Wall) -> Self {
        Self {
            name: name.into(),
            surface,
            wall,
            active: (0.0, None),
            friction: 0.0,
        }
    }

    /// The same obstacle with the Coulomb friction coefficient `μ`.
    pub fn with_friction(mut self, friction: Real) -> Self {
        self.friction = friction;
        self
    }

    /// Whether it acts in a step ending at `t`: after `from` (from the start, the initial state included, when
    /// `from` is 0), up to and including `until`.
    pub fn is_active(&self, t: Real) -> bool {
        let (from, until) = self.active;
        (from <= 0.0 || t > from) && until.is_none_or(|u| t <= u)
    }

    /// The times at which its surface's schedule changes its rate or it is put in place or withdrawn (time
    /// stepping lands on them).
    pub fn breakpoints(&self) -> Vec<Real> {
        let (from, until) = self.active;
        let mut times = self.surface.breakpoints();
        times.extend((from > 0.0).then_some(from));
        times.extend(until);
        times
    }
}

/// The geometry of an obstacle.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum Surface {
    /// A circular cylinder around the axis through `point` along the unit vector `axis`, of radius `radius(t)`;
    /// the rods are kept inside it (a crimper shrinks, holds and opens through its schedule).
    Cylinder {
        /// A point of the axis \[length\].
        #[serde(serialize_with = "crate::math::serial::components")]
        point: Vec3,
        /// Unit direction of the axis.
        #[serde(serialize_with = "crate::math::serial::components")]
        axis: Vec3,
        /// Radius of the surface as a function of time \[length\].
        radius: TimeFunction,
    },
    /// The plane through `point + offset(t) · normal` with the unit `normal`; the rods are kept on the side
    /// the normal points to (a plate moves along its normal through its schedule).
    Plane {
        /// A point of the plane at zero offset \[length\].
        #[serde(serialize_with = "crate::math::serial::components")]
        point: Vec3,
        /// Unit normal, pointing to the rods' side.
        #[serde(serialize_with = "crate::math::serial::components")]
        normal: Vec3,
        /// Displacement of the plane along its normal as a function of time \[length\].
        offset: TimeFunction,
    },
    /// The lumen of a vessel: the tube around a centreline spline with a radius along it; the rods are kept
    /// inside it ([`Lumen`]).
    Lumen(Lumen),
}

/// The tube around a centreline spline `C(u)` of radius `R(u)` (a vessel's lumen): the distance of a point
/// `x` inside is `R(u*) − |x − C(u*)|` with `u*` its closest point on the centreline (module docs of
/// [`Lumen::distance`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Lumen {
    /// The centreline.
    centreline: NurbsCurve,
    /// The radius `R(u)` at increasing curve parameters, linear between them and constant beyond the ends:
    /// `(u, R)` \[1, length\].
    radius: Vec<(Real, Real)>,
    /// The first guesses of the closest-point search: the centreline sampled at `SEARCH_SAMPLES` points per
    /// knot span, `(u, C(u))`, in increasing `u` (module docs of [`Lumen::distance`]).
    #[serde(skip)]
    samples: Vec<(Real, Vec3)>,
    /// A factor on the radius as a function of time (1 for a vessel; a crimper tube around a curved
    /// centreline closes and opens through it).
    scale: TimeFunction,
}

/// The projection's stopping rule: Newton's step on the centreline's parameter below this fraction of its
/// domain. Newton converges quadratically there, so the step after one this small would be ~1e-20 of the
/// domain: the parameter is as good as round-off makes it. A rule at round-off itself (once 1e-15) is not
/// met where the coordinates are large: a vessel 200 mm from the origin leaves `f = (x − C)·C'` a noise of
/// ~1e-12, and the steps wander by 10–60 ulps of the parameter for ever — 466 of the aorta stent's 8316
/// points found no closest point on its crimper tube, and the contact law dropped them at random.
const PROJECTION_STEP: Real = 1e-10;

/// Centreline samples per knot span for the first guess of a lumen's closest point (module docs of
/// [`Lumen::distance`]).
const SEARCH_SAMPLES: usize = 8;

impl Lumen {
    /// The lumen around `centreline` of the radius table `radius` (`(u, R)` at increasing parameters of the
    /// centreline, linear between them and constant beyond the ends): what the design layer builds from a
    /// fitted centreline (`crate::geometry::fit::smooth_points`) and the file's radii at the parameters of its
    /// points.
    ///
    /// # Errors
    /// A sentence saying what is wrong: an empty table, parameters not increasing or outside the centreline's
    /// domain, a radius not positive and finite.
    pub fn try_new(centreline: NurbsCurve, radius: Vec<(Real, Real)>) -> Result<Self, String> {
        let (lo, hi) = centreline.knots().domain();
        if radius.is_empty() {
            return Err("the lumen's radius table is empty".into());
        }
        for (i, &(u, r)) in radius.iter().enumerate() {
            if !(u.is_finite() && (lo..=hi).contains(&u)) {
                return Err(format!(
                    "the lumen's radius table has the parameter {u} (entry {i}) outside the centreline's domain [{lo}, {hi}]"
                ));
            }
            if !(r.is_finite() && r > 0.0) {
                return Err(format!(
                    "the lumen's radius at u = {u} (entry {i}) is {r}: it must be positive and finite"
                ));
            }
            if i > 0 && u <= radius[i - 1].0 {
                return Err(format!(
                    "the lumen's radius table must have increasing parameters (entry {i}, u = {u}, follows u = {})",
                    radius[i - 1].0
                ));
            }
        }
        let knots = centreline.knots().knots();
        let mut samples = Vec::new();
        for w in knots.windows(2) {
            let (a, b) = (w[0], w[1]);
            if !(b > a && a >= lo && b <= hi) {
                continue;
            }
            for j in 0..SEARCH_SAMPLES {
                let u = a + (b - a) * j as Real / SEARCH_SAMPLES as Real;
                samples.push((u, centreline.point(u)));
            }
        }
        samples.push((hi, centreline.point(hi)));
        Ok(Self {
            centreline,
            radius,
            samples,
            scale: TimeFunction::constant(1.0),
        })
    }

    /// The same tube with its radius scaled by `scale(t)` (a crimper around a curved centreline).
    pub fn with_scale(mut self, scale: TimeFunction) -> Self {
        self.scale = scale;
        self
    }

    /// The factor on the radius as a function of time.
    pub fn scale(&self) -> &TimeFunction {
        &self.scale
    }

    /// The centreline.
    pub fn centreline(&self) -> &NurbsCurve {
        &self.centreline
    }

    /// The radius table `(u, R)`.
    pub fn radius_table(&self) -> &[(Real, Real)] {
        &self.radius
    }

    /// The radius `R(u)` and its derivative `dR/du` (linear between the table's entries, constant beyond).
    pub fn radius(&self, u: Real) -> (Real, Real) {
        let table = &self.radius;
        let i = table.partition_point(|&(v, _)| v <= u);
        if i == 0 {
            return (table[0].1, 0.0);
        }
        if i == table.len() {
            return (table[i - 1].1, 0.0);
        }
        let ((u0, r0), (u1, r1)) = (table[i - 1], table[i]);
        let slope = (r1 - r0) / (u1 - u0);
        (r0 + slope * (u - u0), slope)
    }

    /// The parameter of the point of the centreline closest to `x`: Newton's method on
    /// `f(u) = (x − C(u))·C'(u) = 0` (`f' = −J`, `J = |C'|² − (x − C)·C''`) from `hint` (the point's parameter
    /// at the last converged step) if given and it settles there, else from the nearest of the search samples.
    /// `None` when the closest point is an end of the centreline (the point lies beyond the open tube's ends)
    /// or Newton does not settle on a minimum (`J ≤ 0`: beyond a centre of curvature).
    pub fn closest(&self, x: &Vec3, hint: Option<Real>) -> Option<Real> {
        if let Some(u) = hint.and_then(|u| self.project(x, u)) {
            return Some(u);
        }
        let start = self
            .samples
            .iter()
            .min_by(|a, b| {
                (a.1 - x)
                    .norm_squared()
                    .total_cmp(&(b.1 - x).norm_squared())
            })
            .map(|s| s.0)?;
        self.project(x, start)
    }

    /// Newton's projection of `x` on the centreline from `u` ([`Lumen::closest`]).
    fn project(&self, x: &Vec3, mut u: Real) -> Option<Real> {
        let (lo, hi) = self.centreline.knots().domain();
        let scale = hi - lo;
        for _ in 0..50 {
            let d = self.centreline.derivatives(u, 2);
            let r = x - d[0];
            let f = r.dot(&d[1]);
            let j = d[1].norm_squared() - r.dot(&d[2]);
            if !(j > 0.0) {
                return None;
            }
            let next = (u + f / j).clamp(lo, hi);
            let step = (next - u).abs();
            u = next;
            if step <= PROJECTION_STEP * scale {
                return (u > lo && u < hi).then_some(u);
            }
        }
        None
    }

    /// The signed distance of `x` from the lumen's wall (positive inside), its gradient and its Hessian; `None`
    /// where [`Lumen::closest`] finds no closest point or `x` is on the centreline.
    ///
    /// With `u*` the closest parameter, `r = x − C(u*)`, `ρ = |r|`, `e = r/ρ` and `J = |C'|² − r·C''`, the
    /// distance is `g = R(u*) − ρ`. By the stationarity `r·C' = 0` the implicit derivative of the closest point is
    /// `∇u* = C'/J`, and
    /// `∇g = −e + R' C'/J`, `∇²g = −(I − e eᵀ − C'C'ᵀ/J)/ρ + R' ∇²u*`,
    /// `∇²u* = (C''C'ᵀ + C'C''ᵀ)/J² − (3 C'·C'' − r·C''') C'C'ᵀ/J³` (`R'' = 0` on the linear table; the
    /// derivative of `J` along `u` is `3 C'·C'' − r·C'''` and across `x` is `−C''`). For a straight centreline
    /// of unit speed and a constant radius these are the cylinder's ([`Surface::distance`]). The gradient is
    /// unit only where `R' = 0` (a tapering lumen tilts its wall by `R' |∇u*|`); the contact law takes it as it
    /// is, its tangent consistent with it.
    ///
    /// The first guess is `hint`, the point's closest parameter at the last converged step (the contact term
    /// keeps one per point), from which Newton's method takes a few iterations as the point moves little per
    /// step; without one, or where Newton does not settle from it, a linear scan of the centreline's samples
    /// (`SEARCH_SAMPLES` = 8 per knot span). A linear scan, not the spatial index (a k-d tree) the issue proposed:
    /// a vessel's fitted centreline has a few tens of spans, so the scan is a few hundred points, paid only where
    /// a point has no hint (its first contact check) or Newton does not settle from it; the contact term starts
    /// every other search from a hint (the point's own, or for a check between collocation points its nearest
    /// point's). Measured with perf on `designs/aorta_stent_in_vessel.yaml` (2026-11-27), while the checks
    /// between points still scanned every step: the scan was 0.1 % of the run's samples against 18.5 % for the
    /// Newton projections, so a tree could save at most that 0.1 % and would add a dependency.
    /// A hint can lead to a local, not global, closest point where a vessel folds back within one step's
    /// motion; a fitted vessel centreline does not.
    ///
    /// At time `t` the radius is `R(u)` times the tube's scale ([`Lumen::with_scale`]).
    ///
    /// Beyond the centreline's ends (no interior closest point) the tube goes on straight along its end
    /// tangent with its end radius: the distance is the cylinder's ([`Surface::distance`]) around the end's
    /// tangent line, so a crown at the end of a vessel segment is kept inside it rather than let through.
    pub fn distance(&self, x: &Vec3, hint: Option<Real>, t: Real) -> Option<Distance> {
        let Some(u) = self.closest(x, hint) else {
            return self.beyond_ends(x, t);
        };
        let d = self.centreline.derivatives(u, 3);
        let (c1, c2, c3) = (d[1], d[2], d[3]);
        let r = x - d[0];
        let rho = r.norm();
        let factor = self.scale.value(t);
        let (radius, slope) = self.radius(u);
        let (radius, slope) = (radius * factor, slope * factor);
        if rho <= Real::EPSILON * radius {
            return None;
        }
        let e = r / rho;
        let j = c1.norm_squared() - r.dot(&c2);
        let t = c1 * c1.transpose();
        let dj = 3.0 * c1.dot(&c2) - r.dot(&c3);
        let hess_u = (c2 * c1.transpose() + c1 * c2.transpose()) / (j * j) - t * (dj / (j * j * j));
        Some(Distance {
            value: radius - rho,
            normal: -e + c1 * (slope / j),
            hessian: -(Mat3::identity() - e * e.transpose() - t / j) / rho + hess_u * slope,
        })
    }
}

impl Lumen {
    /// The distance from the straight continuation of the tube beyond the end of its centreline nearer to
    /// `x` ([`Lumen::distance`]), when `x` lies beyond that end's cross-section; `None` otherwise.
    fn beyond_ends(&self, x: &Vec3, t: Real) -> Option<Distance> {
        let (lo, hi) = self.centreline.knots().domain();
        let ends = [(lo, -1.0), (hi, 1.0)];
        let (u, outward) = ends.into_iter().min_by(|a, b| {
            let da = (self.centreline.point(a.0) - x).norm_squared();
            let db = (self.centreline.point(b.0) - x).norm_squared();
            da.total_cmp(&db)
        })?;
        let d = self.centreline.derivatives(u, 1);
        let axis = d[1].normalize();
        let r = x - d[0];
        if r.dot(&axis) * outward < 0.0 {
            return None;
        }
        cylinder_distance(&r, &axis, self.radius(u).0 * self.scale.value(t))
    }
}

/// The part of `d` normal to the unit `axis` and its length `ρ`; `None` on the axis (`ρ` within round-off of 0
/// against `radius`), where a cylinder's distance has no gradient.
fn off_axis(d: &Vec3, axis: &Vec3, radius: Real) -> Option<(Vec3, Real)> {
    let perp = d - axis * axis.dot(d);
    let rho = perp.norm();
    (rho > Real::EPSILON * radius.abs().max(1.0)).then_some((perp, rho))
}

/// The distance from the inside of a cylinder of `radius` around the line along the unit `axis` through the
/// point from which `d` is measured ([`Surface::distance`]); `None` on the axis.
fn cylinder_distance(d: &Vec3, axis: &Vec3, radius: Real) -> Option<Distance> {
    let (perp, rho) = off_axis(d, axis, radius)?;
    let e = perp / rho;
    Some(Distance {
        value: radius - rho,
        normal: -e,
        hessian: -(Mat3::identity() - axis * axis.transpose() - e * e.transpose()) / rho,
    })
}

/// The signed distance of a point from a surface (positive on the rods' side), with its gradient (the unit
/// normal pointing to the rods' side) and Hessian.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Distance {
    /// Signed distance \[length\].
    pub value: Real,
    /// Its gradient: unit, pointing away from the surface into the rods' side.
    pub normal: Vec3,
    /// Its Hessian \[1/length\] (zero for a plane).
    pub hessian: Mat3,
}

impl Surface {
    /// The signed distance of the point `x` from the surface at time `t` (module docs). For a cylinder, `None`
    /// on its axis, where the distance has no gradient (a point there is a radius away from the wall).
    ///
    /// Cylinder: with `d = x − point`, `x⊥ = d − (d·a) a`, `ρ = |x⊥|` and `e = x⊥ / ρ`, the distance is
    /// `R(t) − ρ`, its gradient `−e` and its Hessian `−(I − a aᵀ − e eᵀ) / ρ` (the Hessian of `ρ` is the
    /// projector onto the plane normal to both `a` and `e`, over `ρ`). Plane: `n · (x − point) − offset(t)`,
    /// gradient `n`, Hessian zero.
    pub fn distance(&self, x: &Vec3, t: Real) -> Option<Distance> {
        match self {
            Surface::Cylinder {
                point,
                axis,
                radius,
            } => cylinder_distance(&(x - point), axis, radius.value(t)),
            Surface::Plane {
                point,
                normal,
                offset,
            } => Some(Distance {
                value: normal.dot(&(x - point)) - offset.value(t),
                normal: *normal,
                hessian: Mat3::zeros(),
            }),
            Surface::Lumen(lumen) => lumen.distance(x, None, t),
        }
    }

    /// [`Surface::distance`] with a lumen's closest-point search started from `hint` ([`Lumen::distance`]);
    /// the other surfaces ignore it.
    pub fn distance_near(&self, x: &Vec3, t: Real, hint: Option<Real>) -> Option<Distance> {
        match self {
            Surface::Lumen(lumen) => lumen.distance(x, hint, t),
            _ => self.distance(x, t),
        }
    }

    /// The value alone of [`Surface::distance_near`] (no normal, no Hessian: what the checks of a gap need);
    /// `None` where that is `None`.
    pub fn distance_value(&self, x: &Vec3, t: Real, hint: Option<Real>) -> Option<Real> {
        match self {
            Surface::Cylinder {
                point,
                axis,
                radius,
            } => {
                let r = radius.value(t);
                off_axis(&(x - point), axis, r).map(|(_, rho)| r - rho)
            }
            Surface::Plane {
                point,
                normal,
                offset,
            } => Some(normal.dot(&(x - point)) - offset.value(t)),
            Surface::Lumen(lumen) => lumen.distance(x, hint, t).map(|d| d.value),
        }
    }

    /// A lumen's closest parameter to `x` ([`Lumen::closest`]); `None` for the other surfaces.
    pub fn parameter(&self, x: &Vec3, hint: Option<Real>) -> Option<Real> {
        match self {
            Surface::Lumen(lumen) => lumen.closest(x, hint),
            _ => None,
        }
    }

    /// The radius of a cylinder at time `t` (`None` for a plane and a lumen, whose radius varies along it).
    pub fn radius(&self, t: Real) -> Option<Real> {
        match self {
            Surface::Cylinder { radius, .. } => Some(radius.value(t)),
            Surface::Plane { .. } | Surface::Lumen(_) => None,
        }
    }

    /// The `R` of a compliant wall's stiffness at time `t` where a point touches it: a cylinder's radius, a
    /// lumen's radius at the centreline parameter `parameter` of the point's closest point (scaled), or — for a
    /// point whose parameter is not known yet — the lumen's mean tabulated radius; `None` for a plane.
    pub fn wall_radius(&self, t: Real, parameter: Option<Real>) -> Option<Real> {
        match self {
            Surface::Cylinder { radius, .. } => Some(radius.value(t)),
            Surface::Plane { .. } => None,
            Surface::Lumen(lumen) => {
                let table = lumen.radius_table();
                let radius = match parameter {
                    Some(u) => lumen.radius(u).0,
                    None => table.iter().map(|r| r.1).sum::<Real>() / table.len() as Real,
                };
                Some(radius * lumen.scale().value(t))
            }
        }
    }

    /// The times at which the surface's schedule changes its rate (time stepping lands on them).
    pub fn breakpoints(&self) -> Vec<Real> {
        match self {
            Surface::Cylinder { radius: f, .. } | Surface::Plane { offset: f, .. } => {
                f.breakpoints().collect()
            }
            Surface::Lumen(lumen) => lumen.scale.breakpoints().collect(),
        }
    }
}

/// The wall of an obstacle.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum Wall {
    /// Rigid: the contact law's penalty with augmented-Lagrange updates drives the penetration below the
    /// model's tolerance ([`ContactSettings`]).
    Rigid,
    /// A thin elastic tube (or plate) acting as a radial foundation (module docs).
    Compliant {
        /// Young's modulus of the wall `E_w` \[stress\].
        modulus: Real,
        /// Thickness `h` \[length\].
        thickness: Real,
        /// Width of wall each unit length of wire carries, `b` \[length\].
        width: Real,
    },
}

impl Wall {
    /// The line stiffness of a compliant wall of radius `radius`, `k b = E_w h b / R²` \[force/length²\]
    /// (module docs); `None` for a rigid wall.
    pub fn line_stiffness(&self, radius: Real) -> Option<Real> {
        match *self {
            Wall::Rigid => None,
            Wall::Compliant {
                modulus,
                thickness,
                width,
            } => Some(modulus * thickness * width / (radius * radius)),
        }
    }
}

/// The obstacles of a model and how contact with them is enforced.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Contact {
    /// The surfaces the rods touch.
    pub obstacles: Vec<Obstacle>,
    /// The contact law's settings.
    pub settings: ContactSettings,
}

/// How contact with rigid walls is enforced (the solver's `contact` term).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ContactSettings {
    /// Penalty `ε` \[force/length²\]: line force per unit length of wire per unit penetration.
    pub penalty: Real,
    /// Width of the law's quadratic transition `2δ` \[length\] (C¹ at zero force).
    pub regularisation: Real,
    /// Largest penetration a converged step may keep \[length\]: beyond it the augmented-Lagrange multipliers
    /// are updated and the step solved again.
    pub tolerance: Real,
    /// Most augmented-Lagrange updates per step.
    pub max_updates: usize,
}

#[cfg(test)]
mod tests {
    use super::{Distance, Lumen, Surface};
    use crate::geometry::primitives::arc;
    use crate::math::{KnotVector, Mat3, NurbsCurve, Real, Vec3};
    use crate::model::TimeFunction;

    /// The largest entry of `a − b` over the largest of `b` (and 1e-300).
    fn relative(a: &Mat3, b: &Mat3) -> Real {
        (a - b).abs().max() / b.abs().max().max(1e-300)
    }

    /// The gradient and Hessian of `f` at `x` by central differences of step `h`.
    fn differences(f: &dyn Fn(&Vec3) -> Real, x: &Vec3, h: Real) -> (Vec3, Mat3) {
        let e = |i: usize| Vec3::ith(i, h);
        let gradient = Vec3::from_fn(|i, _| (f(&(x + e(i))) - f(&(x - e(i)))) / (2.0 * h));
        let hessian = Mat3::from_fn(|i, j| {
            (f(&(x + e(i) + e(j))) - f(&(x + e(i) - e(j))) - f(&(x - e(i) + e(j)))
                + f(&(x - e(i) - e(j))))
                / (4.0 * h * h)
        });
        (gradient, hessian)
    }

    /// A straight cubic centreline from `a` to `b` (collinear control points, non-uniform on purpose: the
    /// distance must not depend on the parametrisation).
    fn straight(a: Vec3, b: Vec3) -> NurbsCurve {
        let knots = KnotVector::clamped_uniform(3, 6).expect("a knot vector");
        let points = [0.0, 0.1, 0.3, 0.6, 0.8, 1.0]
            .iter()
            .map(|&t| a + (b - a) * t)
            .collect();
        NurbsCurve::try_bspline(knots, points).expect("a curve")
    }

    /// Source: a straight lumen of constant radius is a cylinder, whose distance, normal and Hessian have their
    /// own closed form ([`Surface::distance`] of a cylinder); the two must agree to round-off (1e-12) at points
    /// inside it, near its wall and outside it, with an oblique axis.
    #[test]
    fn a_straight_lumen_is_the_cylinder() {
        let (point, axis, radius) = (
            Vec3::new(1.0, -2.0, 0.5),
            Vec3::new(0.3, 0.4, 1.0).normalize(),
            1.5,
        );
        let lumen = Lumen::try_new(
            straight(point - axis * 10.0, point + axis * 10.0),
            vec![(0.0, radius), (1.0, radius)],
        )
        .expect("a lumen");
        let cylinder = Surface::Cylinder {
            point,
            axis,
            radius: TimeFunction::constant(radius),
        };
        for x in [
            Vec3::new(1.2, -1.9, 0.7),
            Vec3::new(2.0, -3.0, 2.0),
            Vec3::new(-1.0, 0.5, -3.0),
            Vec3::new(3.0, -2.0, 0.0),
        ] {
            let a: Distance = lumen
                .distance(&x, None, 0.0)
                .expect("inside the tube's span");
            let b = cylinder.distance(&x, 0.0).expect("off the axis");
            assert!((a.value - b.value).abs() < 1e-12, "{a:?} {b:?}");
            assert!((a.normal - b.normal).norm() < 1e-12, "{a:?} {b:?}");
            assert!(relative(&a.hessian, &b.hessian) < 1e-12, "{a:?} {b:?}");
        }
    }

    /// Source: a circular centreline of radius `Rc` (a NURBS arc, exact) with a constant radius `R` is a torus
    /// section: distance `R − √((√(x² + y²) − Rc)² + z²)` (closed form). The lumen's value must be the closed
    /// form's to round-off (1e-12), its gradient and Hessian those of the closed form by central differences
    /// (step 1e-4: truncation ~1e-8, round-off ~1e-16/1e-8 = 1e-8 of the Hessian; tolerance 1e-6 relative).
    #[test]
    fn a_circular_lumen_is_the_torus() {
        let (rc, radius) = (10.0, 2.0);
        let centreline = arc(
            Vec3::zeros(),
            Vec3::new(rc, 0.0, 0.0),
            Vec3::z(),
            2.0 * std::f64::consts::FRAC_PI_3,
            3,
            9,
        )
        .expect("an arc");
        let (lo, hi) = centreline.knots().domain();
        let lumen = Lumen::try_new(centreline, vec![(lo, radius), (hi, radius)]).expect("a lumen");
        let torus = |x: &Vec3| radius - ((x.x.hypot(x.y) - rc).powi(2) + x.z * x.z).sqrt();
        for angle in [0.3_f64, 1.0, 1.7] {
            for (dr, dz) in [(0.5, 0.2), (-1.2, 0.7), (0.1, -1.9), (2.5, 1.0)] {
                let x = Vec3::new((rc + dr) * angle.cos(), (rc + dr) * angle.sin(), dz);
                let d = lumen
                    .distance(&x, None, 0.0)
                    .expect("inside the arc's span");
                assert!(
                    (d.value - torus(&x)).abs() < 1e-12,
                    "{} {}",
                    d.value,
                    torus(&x)
                );
                let (gradient, hessian) = differences(&torus, &x, 1e-4);
                assert!((d.normal - gradient).norm() < 1e-6, "{d:?} {gradient:?}");
                assert!(relative(&d.hessian, &hessian) < 1e-6, "{d:?} {hessian:?}");
            }
        }
    }

    /// Source: the gradient and Hessian of a tapering lumen (radius linear in the parameter over a circular
    /// centreline, so `R' ≠ 0` and the closest point's own derivatives enter) are those of its distance by
    /// central differences (the same step and tolerance as above), away from the radius table's kinks.
    #[test]
    fn a_tapering_lumens_gradient_and_hessian_are_its_distances() {
        let centreline = arc(
            Vec3::zeros(),
            Vec3::new(8.0, 0.0, 0.0),
            Vec3::z(),
            2.0,
            3,
            12,
        )
        .expect("an arc");
        let (lo, hi) = centreline.knots().domain();
        let lumen = Lumen::try_new(centreline, vec![(lo, 2.5), (hi, 1.5)]).expect("a lumen");
        let value = |x: &Vec3| lumen.distance(x, None, 0.0).expect("inside").value;
        for angle in [0.4_f64, 1.1, 1.6] {
            for (dr, dz) in [(0.5, 0.2), (-1.0, 0.6), (0.3, -1.2)] {
                let x = Vec3::new((8.0 + dr) * angle.cos(), (8.0 + dr) * angle.sin(), dz);
                let d = lumen.distance(&x, None, 0.0).expect("inside");
                let (gradient, hessian) = differences(&value, &x, 1e-4);
                assert!((d.normal - gradient).norm() < 1e-6, "{d:?} {gradient:?}");
                assert!(relative(&d.hessian, &hessian) < 1e-6, "{d:?} {hessian:?}");
            }
        }
    }

    /// Source: every point inside a tube has a closest interior point on its centreline (the distance is
    /// continuous there). A centreline fitted through points the way a vessel's and a curved crimper's are
    /// (`smooth_points`) where the aorta file's lies (~200 mm from the origin), projected from the scan and
    /// from a hint near the answer, must settle for every point of a ring around it at a few radii of the
    /// tube ([`PROJECTION_STEP`]: with the old rule at round-off, 1e-15, this test misses points).
    #[test]
    fn every_point_inside_a_fitted_tube_has_a_closest_point() {
        let points: Vec<Vec3> = (0..=200)
            .map(|i| {
                let s = i as Real * 0.25;
                let local = Vec3::new(
                    30.0 * (s / 30.0).sin(),
                    4.0 * (s / 9.0).sin(),
                    30.0 * (1.0 - (s / 30.0).cos()) + s,
                );
                // Where the aorta file's centreline lies: coordinates of ~200 mm.
                local + Vec3::new(215.0, 150.0, 25.0)
            })
            .collect();
        let fit = crate::geometry::fit::smooth_points(&points, 1e-5).expect("a fit");
        let (lo, hi) = fit.curve.knots().domain();
        let lumen = Lumen::try_new(fit.curve, vec![(lo, 6.0)]).expect("a lumen");
        let mut missed = 0;
        let mut total = 0;
        for i in 1..100 {
            let u = lo + (hi - lo) * i as Real / 100.0;
            let d = lumen.centreline().derivatives(u, 1);
            let tangent = d[1].normalize();
            let a = tangent.cross(&Vec3::x()).normalize();
            let b = tangent.cross(&a);
            for k in 0..24 {
                let phi = k as Real * std::f64::consts::TAU / 24.0;
                for radius in [2.0, 5.5, 6.0] {
                    let x = d[0] + (a * phi.cos() + b * phi.sin()) * radius;
                    total += 2;
                    missed += usize::from(lumen.closest(&x, None).is_none());
                    missed += usize::from(lumen.closest(&x, Some(u + 1e-6)).is_none());
                }
            }
        }
        assert_eq!(
            missed, 0,
            "{missed} of {total} projections found no closest point"
        );
    }

    /// A point beyond the tube's ends has no closest interior point; the tube goes on straight there with its
    /// end radius (the point 0.1 off the axis, 2 beyond the end: 1 − 0.1 from the wall, normal −x, as the
    /// cylinder's); and a bad table is refused with its reason.
    #[test]
    fn a_lumen_ends_and_refuses_bad_tables() {
        let lumen = Lumen::try_new(
            straight(Vec3::zeros(), Vec3::new(0.0, 0.0, 10.0)),
            vec![(0.0, 1.0)],
        )
        .expect("a lumen");
        let beyond = Vec3::new(0.1, 0.0, 12.0);
        assert!(lumen.closest(&beyond, None).is_none());
        let d = lumen
            .distance(&beyond, None, 0.0)
            .expect("the straight continuation");
        assert!(
            (d.value - 0.9).abs() < 1e-12 && (d.normal + Vec3::x()).norm() < 1e-12,
            "{d:?}"
        );
        let inside = Vec3::new(0.1, 0.0, 5.0);
        let u = lumen.closest(&inside, None).expect("inside the span");
        // From a hint near the answer Newton lands on the same parameter; from a far one too.
        for hint in [u + 1e-3, 0.05] {
            let v = lumen.closest(&inside, Some(hint)).expect("inside");
            assert!((u - v).abs() < 1e-12, "{u} from a scan, {v} from {hint}");
        }
        let curve = || straight(Vec3::zeros(), Vec3::new(0.0, 0.0, 10.0));
        for (table, reason) in [
            (vec![], "empty"),
            (vec![(0.5, 1.0), (0.2, 1.0)], "increasing"),
            (vec![(0.5, -1.0)], "positive"),
            (vec![(2.0, 1.0)], "outside"),
        ] {
            let error = Lumen::try_new(curve(), table).expect_err("refused");
            assert!(error.contains(reason), "{error}");
        }
    }
}
