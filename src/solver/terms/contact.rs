//! Contact of the rods with surfaces ([`crate::model::Obstacle`]: cylinders that keep the rods inside, planes
//! that keep them on one side; rigid or compliant walls) as a point term (issue 33; DESIGN §9).
//!
//! **Where it acts.** The strong form has no quadrature, so contact enters like the distributed loads: a line
//! force per unit reference length `q = p(g) n` at every interior collocation point (Weeger et al. 2017 collocate
//! rod contact at the Greville points the same way). `g` is the gap of the point's centreline position from the
//! surface minus the wire's radius (the patch section's diameter over two), `n = ∇g` the unit normal into the
//! rods' side: a circular section takes no contact moment. At the patch ends the balance laws are the nodes'
//! equilibrium, which a line force does not enter; a node is kept out of a wall by the contact of the points
//! next to it.
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
//! **Augmented Lagrange (Uzawa).** After a step converged, if the largest penetration at a rigid wall exceeds
//! the settings' tolerance, every point's multiplier becomes its pressure, `λ ← p(g)`, and the step is solved
//! again from where it converged ([`PointTerm::augment`]); at most `max_updates` times. If the penetration is
//! still above the tolerance then, the step is kept and the run's warnings say so (how many steps, the largest
//! penetration, when first: [`PointTerm::warnings`], into summary.json and on stderr). The multipliers, the
//! step's update count and that record are the term's state: the multipliers start the next step where this one
//! left them, a roll-back restores all three, a checkpoint keeps them.
//!
//! **Switching in and out.** The law is C¹, so Newton sees a continuous tangent as points enter and leave
//! contact within the transition band `2δ`.

pub(crate) mod report;

pub use report::{ContactReport, ObstacleReport};

use super::{InteriorLoad, PointTerm, PointView};
use crate::math::{Real, Vec3};
use crate::model::{ContactSettings, Distance, Model, Obstacle, Wall};
use crate::solver::discretisation::{Discretisation, point_position};
use crate::solver::state::State;

/// The C¹ ramp `Φ(x)` of the contact law and its derivative (module docs), with half-width `delta`.
fn ramp(x: Real, delta: Real) -> (Real, Real) {
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
    /// The time the surfaces are at (the end of the step being solved).
    time: Real,
    /// Augmented-Lagrange multipliers per obstacle and collocation point \[force/length\].
    multipliers: Vec<Vec<Real>>,
    /// Augmented-Lagrange updates made in the step being solved.
    updates: usize,
    /// Steps kept with the penetration above the tolerance after every update: how many, the largest
    /// penetration, the first step's time.
    unresolved: Unresolved,
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
        Self {
            obstacles,
            settings,
            radius,
            time: 0.0,
            multipliers,
            updates: 0,
            unresolved: Unresolved::default(),
        }
    }

    /// The obstacles.
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// The penalty and multiplier of obstacle `k` at point `g` (a compliant wall: its line stiffness, no
    /// multiplier).
    pub(crate) fn law(&self, k: usize, g: usize) -> (Real, Real) {
        let obstacle = &self.obstacles[k];
        match obstacle
            .surface
            .radius(self.time)
            .and_then(|r| obstacle.wall.line_stiffness(r))
        {
            Some(stiffness) => (stiffness, 0.0),
            None => (self.settings.penalty, self.multipliers[k][g]),
        }
    }

    /// The contact of the point at `x` on patch `patch` (collocation point `g`) with obstacle `k`; `None` where
    /// the surface has no normal there (a cylinder's axis).
    pub fn at(&self, k: usize, g: usize, patch: usize, x: &Vec3) -> Option<PointContact> {
        let distance = self.obstacles[k].surface.distance(x, self.time)?;
        let gap = distance.value - self.radius[patch];
        let (penalty, multiplier) = self.law(k, g);
        let delta = 0.5 * self.settings.regularisation;
        let (phi, slope) = ramp(multiplier / penalty - gap, delta);
        Some(PointContact {
            gap,
            pressure: penalty * phi,
            stiffness: -penalty * slope,
            distance,
        })
    }

    /// The largest penetration at the rigid walls (most negative gap, as a positive length; 0 if none) over
    /// the interior collocation points of `state` (where the law acts), and each such point's pressure
    /// `(obstacle, point, p)`.
    fn rigid_contact(
        &self,
        disc: &Discretisation,
        state: &State,
    ) -> (Real, Vec<(usize, usize, Real)>) {
        let mut worst: Real = 0.0;
        let mut pressures = Vec::new();
        for (k, obstacle) in self.obstacles.iter().enumerate() {
            if obstacle.wall != Wall::Rigid {
                continue;
            }
            for (g, point) in disc.points.iter().enumerate() {
                if disc.is_end(g) {
                    continue;
                }
                let x = point_position(disc, &state.control, g);
                let c = self.at(k, g, point.patch, &x);
                worst = worst.max(c.map_or(0.0, |c| -c.gap));
                pressures.push((k, g, c.map_or(0.0, |c| c.pressure)));
            }
        }
        (worst, pressures)
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
        let x = at.position();
        for k in 0..self.obstacles.len() {
            let Some(c) = self.at(k, at.g, at.point.patch, &x) else {
                continue;
            };
            if c.pressure == 0.0 && c.stiffness == 0.0 {
                continue;
            }
            let n = c.distance.normal;
            load.add_force(n * c.pressure);
            if at.tangent {
                let dq = n * n.transpose() * c.stiffness + c.distance.hessian * c.pressure;
                load.add_force_position(at.rotation_t * dq);
            }
        }
    }

    fn prepare(&mut self, t: Real) {
        self.time = t;
        self.updates = 0;
    }

    fn augment(&mut self, disc: &Discretisation, state: &State) -> bool {
        let (worst, pressures) = self.rigid_contact(disc, state);
        if worst <= self.settings.tolerance {
            return false;
        }
        if self.updates == self.settings.max_updates {
            let u = &mut self.unresolved;
            if u.steps == 0 {
                u.first = self.time;
            }
            u.steps += 1;
            u.largest = u.largest.max(worst);
            return false;
        }
        self.updates += 1;
        for (k, g, pressure) in pressures {
            self.multipliers[k][g] = pressure;
        }
        true
    }

    fn warnings(&self) -> Vec<String> {
        let u = &self.unresolved;
        if u.steps == 0 {
            return Vec::new();
        }
        vec![format!(
            "contact: in {} step(s) the penetration stayed above its tolerance {:e} after {} augmented-Lagrange update(s), by up to {:.3e} (first at t = {}): raise `max_updates` or the penalty",
            u.steps, self.settings.tolerance, self.settings.max_updates, u.largest, u.first
        )]
    }

    fn save(&self, out: &mut Vec<Real>) {
        let u = &self.unresolved;
        out.extend([
            self.time,
            self.updates as Real,
            u.steps as Real,
            u.largest,
            u.first,
        ]);
        for m in &self.multipliers {
            out.extend_from_slice(m);
        }
    }

    fn restore(&mut self, values: &[Real]) -> Result<(), usize> {
        const HEAD: usize = 5;
        let expected = HEAD + self.multipliers.iter().map(Vec::len).sum::<usize>();
        if values.len() != expected {
            return Err(expected);
        }
        // Counts are saved as reals: exact below 2^53.
        self.time = values[0];
        self.updates = values[1] as usize;
        self.unresolved = Unresolved {
            steps: values[2] as usize,
            largest: values[3],
            first: values[4],
        };
        let mut rest = &values[HEAD..];
        for m in &mut self.multipliers {
            let (mine, tail) = rest.split_at(m.len());
            m.copy_from_slice(mine);
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
    use crate::solver::discretisation::point_position;
    use crate::solver::simulation::NoObserver;
    use std::f64::consts::FRAC_PI_2;

    /// Reference radius, wire diameter, Young's modulus of the ring tests.
    pub(super) const R0: Real = 10.0;
    pub(super) const D: Real = 0.5;
    pub(super) const E: Real = 1000.0;

    /// A quarter of a circular ring of radius `R0` in the plane z = 0, its ends on the symmetry planes y = 0
    /// and x = 0 (each end: the displacement normal to its plane, the out-of-plane displacement and every
    /// rotation held), elastic, 20 steps over t ∈ [0, 1], with `contact`.
    pub(super) fn quarter_ring(contact: Contact) -> Model {
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
            ConditionSpec::at(node)
                .with_displacement(normal, zero())
                .with_displacement(2, zero())
                .with_rotation(0, zero())
                .with_rotation(1, zero())
                .with_rotation(2, zero())
        };
        b.condition(symmetric("ring.start", 1));
        b.condition(symmetric("ring.end", 0));
        b.time(TimeSpec::new(1.0, 0.05));
        b.contact(contact);
        b.build().expect("valid ring").model
    }

    /// A cylinder around the z axis whose radius goes linearly from `from` at t = 0 to `to` at t = 1.
    pub(super) fn cylinder(from: Real, to: Real, wall: Wall) -> Obstacle {
        Obstacle {
            name: "crimper".into(),
            surface: Surface::Cylinder {
                point: Vec3::zeros(),
                axis: Vec3::z(),
                radius: TimeFunction::try_table(vec![(0.0, from), (1.0, to)])
                    .expect("increasing times"),
            },
            wall,
        }
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
        let settings = ContactSettings {
            penalty: 1e3,
            regularisation: 1e-4,
            tolerance: 1e-6,
            max_updates: 10,
        };
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

    /// The same crimp without augmented-Lagrange updates: the penalty alone leaves a penetration of about
    /// `q/ε ≈ 1e-3` in every step of contact, above the 1e-6 tolerance, and the run says so in its warnings
    /// instead of completing silently; the warning names the largest penetration, which lies between the
    /// tolerance and the penalty's estimate with a margin of ten (q ≈ 0.98 at the end, ε = 1e3).
    #[test]
    fn a_crimp_left_above_its_penetration_tolerance_is_warned_about() {
        let r = D / 2.0;
        let settings = ContactSettings {
            penalty: 1e3,
            regularisation: 1e-4,
            tolerance: 1e-6,
            max_updates: 0,
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
        assert!((1e-4..1e-2).contains(&largest), "{largest}");
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
        let r = D / 2.0;
        let (modulus, thickness, width) = (100.0, 1.0, 2.0);
        let settings = ContactSettings {
            penalty: 1e3,
            regularisation: 1e-4,
            tolerance: 1e-6,
            max_updates: 10,
        };
        let wall = Wall::Compliant {
            modulus,
            thickness,
            width,
        };
        let tube = R0 + r - 0.5;
        let (radii, _, _) = crimp(cylinder(R0 + r + 0.2, tube, wall), settings);
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
