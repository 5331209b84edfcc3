//! What the contact term reports about a state: per obstacle the total contact force, its radial part for a
//! cylinder, the points in contact, the largest penetration and the friction work, and per collocation point
//! the gap and the pressure — what `history.csv`, `summary.json`, the field files, `run.mcap` and the charts
//! show of contact (issue 33 item 4). The run's recorders reach it through
//! [`crate::solver::Simulation::contact`].
//!
//! **Integration.** The collocated strong form has no quadrature: the line force `q = p n` acts at the interior
//! collocation points only. Its total is measured with the weights the simulation already keeps for integrals
//! along the rods: the trapezoidal weights of the collocation points in the reference arc length `s`
//! (`w_g = (s_{g+1} − s_{g−1})/2` inside a patch, half an interval at its ends; the arc lengths by
//! Gauss–Legendre on the reference curve), so that
//! ```text
//! F = Σ_g w_g p_g n_g ≈ ∫ q ds,       radial (cylinder) = Σ_g w_g p_g,
//! ```
//! exact for a uniform line force (the weights sum to the patch's reference length) and second order in the
//! spacing of the points otherwise (the trapezoidal rule's error `L h² max|q''| / 12`). The line force is per
//! unit *reference* length, as in the balance laws (module docs of the term), so the integral is over the
//! reference length. At a patch end where the law does not act (a node the wire passes through smoothly: the
//! node's equations hold there) the report measures the pressure with the contact law at the end's own gap and
//! the multiplier of the patch's nearest interior point — the line force the rod carries up to its end — so
//! that a uniformly pressed rod integrates to its pressure times its length, not short of the two end
//! half-intervals; a crown crest pressed at such a node is thus counted by its own penetration, not left out.
//! At a corner's end, where the law acts as a concentrated force on the node (the term's module docs,
//! *Corners*), the end's weight is its tributary length, so the report's sum there is that force exactly.
//!
//! **Radial part.** For a cylinder the force on the rods is along the inward normal `n = −e` (`e` the unit
//! radial direction from the axis to the point), so the inward component of `w_g p_g n_g` is `w_g p_g`: the
//! radial force is the sum of the pressures times their weights, positive when the wires press on the
//! cylinder — a crimper's radial resistive force (loading) or a stent's chronic outward force on its sheath
//! (unloading), of the model as simulated (the share of a symmetry-reduced model).
//!
//! **Points in contact** are the collocation points (ends included, measured as above) with a positive pressure;
//! the **largest penetration** is the most negative gap there (as a positive length, 0 when none; on a
//! compliant wall the wall's displacement, not an error). Extra sample points between the collocation points
//! (a crest between two points) add their gaps in [`largest_penetration`], the one place that takes the
//! maximum. The **friction work** is zero until the contact law has friction.
//!
//! **Apposition** (issue 34 item 3: how a device lies on a vessel wall) is read off the same points and weights:
//! the share of the wires' length in contact `Σ_{p>0} w_g / Σ w_g`, the largest gap of a collocation point from
//! the surface (the largest malapposition; where: its patch and curve parameter), and the largest and the mean
//! line pressure over the length in contact, `Σ w p / Σ_{p>0} w` (per unit reference length of wire, as the law's
//! pressure; over the contact width of the wire's diameter it is a wall pressure). Of the model as simulated:
//! the shares and pressures of a symmetry-reduced model are the device's.

use super::SurfaceContact;
use crate::math::{Real, Vec3};
use crate::model::Surface;
use crate::solver::discretisation::{Discretisation, point_position};
use crate::solver::state::State;

/// The contact of a state with every obstacle (module docs), in the order of the model's obstacles.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactReport {
    /// The time the surfaces are at \[s\] (the end of the last step solved).
    pub time: Real,
    /// Per obstacle.
    pub obstacles: Vec<ObstacleReport>,
}

/// The contact of a state with one obstacle (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct ObstacleReport {
    /// The total force the obstacle exerts on the rods, `Σ w p n` \[force\].
    pub force: Vec3,
    /// For a cylinder and a lumen, the inward radial part of that force: positive when the wires press on the
    /// wall \[force\]; `None` for a plane.
    pub radial_force: Option<Real>,
    /// Collocation points with a positive pressure.
    pub points: usize,
    /// The largest penetration, as a positive length (0 when none) \[length\].
    pub penetration: Real,
    /// Work dissipated by friction since the start \[force·length\] ([`SurfaceContact::friction_work`]; zero
    /// for a frictionless obstacle).
    pub friction_work: Real,
    /// The gap at every collocation point (distance from the surface minus the wire radius; NaN on a
    /// cylinder's axis, where it has no normal) \[length\].
    pub gap: Vec<Real>,
    /// The pressure at every collocation point, per unit reference length (module docs for the patch ends)
    /// \[force/length\].
    pub pressure: Vec<Real>,
    /// How the wires lie on the surface (module docs, *Apposition*).
    pub apposition: Apposition,
}

/// How the wires lie on a surface at a state (module docs, *Apposition*): the share of their length in contact,
/// the widest gap of a wire from the surface and where, and the line pressure on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Apposition {
    /// The wires' length in contact (the collocation points' trapezoidal weights where the pressure is positive)
    /// over their whole length, in \[0, 1\].
    pub contact_fraction: Real,
    /// The largest finite gap of a wire from the surface (the largest malapposition) \[length\], with the patch
    /// and curve parameter of its collocation point; `None` when no point has a gap (a plane's far side).
    pub largest_gap: Option<(Real, usize, Real)>,
    /// The largest line pressure \[force/length\] (0 when nothing touches).
    pub peak_pressure: Real,
    /// The mean line pressure over the length in contact \[force/length\] (0 when nothing touches).
    pub mean_pressure: Real,
}

impl SurfaceContact {
    /// The report of `state` (module docs), with `weights` the trapezoidal weights of the collocation points
    /// in the reference arc length (one per point of `disc`).
    pub fn report(&self, disc: &Discretisation, state: &State, weights: &[Real]) -> ContactReport {
        let positions: Vec<Vec3> = (0..disc.points.len())
            .map(|g| point_position(disc, &state.control, g))
            .collect();
        let obstacles = (0..self.obstacles.len())
            .map(|k| self.obstacle_report(k, disc, &positions, weights))
            .collect();
        ContactReport {
            time: self.time,
            obstacles,
        }
    }

    /// The report of obstacle `k` at the points' `positions`.
    fn obstacle_report(
        &self,
        k: usize,
        disc: &Discretisation,
        positions: &[Vec3],
        weights: &[Real],
    ) -> ObstacleReport {
        let n = positions.len();
        let (mut gap, mut pressure) = (vec![Real::NAN; n], vec![0.0; n]);
        let mut force = Vec3::zeros();
        let mut radial = 0.0;
        let (mut touching, mut total) = (0.0, 0.0);
        for (g, x) in positions.iter().enumerate() {
            total += weights[g];
            let patch = disc.points[g].patch;
            let Some(c) = self.at(k, law_point(disc, &self.acts, g), patch, x) else {
                continue;
            };
            gap[g] = c.gap;
            pressure[g] = c.pressure;
            force += c.distance.normal * (weights[g] * c.pressure);
            radial += weights[g] * c.pressure;
            if c.pressure > 0.0 {
                touching += weights[g];
            }
        }
        let largest_gap = (gap.iter().enumerate())
            .filter(|(_, g)| g.is_finite())
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map(|(g, &value)| (value, disc.points[g].patch, disc.points[g].u));
        let apposition = Apposition {
            contact_fraction: if total > 0.0 { touching / total } else { 0.0 },
            largest_gap,
            peak_pressure: pressure.iter().fold(0.0, |m: Real, &p| m.max(p)),
            mean_pressure: if touching > 0.0 {
                radial / touching
            } else {
                0.0
            },
        };
        let radial_force = match self.obstacles[k].surface {
            Surface::Cylinder { .. } | Surface::Lumen(_) => Some(radial),
            Surface::Plane { .. } => None,
        };
        ObstacleReport {
            force,
            radial_force,
            points: pressure.iter().filter(|&&p| p > 0.0).count(),
            penetration: largest_penetration(&gap),
            friction_work: self.friction_work(k).1,
            gap,
            pressure,
            apposition,
        }
    }
}

/// The collocation point whose multiplier the report uses at point `g`: `g` itself where the law acts (inside a
/// patch, a corner's end), the nearest interior point at another patch end (module docs), the end itself for a
/// patch without interior points.
fn law_point(disc: &Discretisation, acts: &[bool], g: usize) -> usize {
    let range = &disc.patches[disc.points[g].patch];
    if acts[g] || range.n < 3 {
        g
    } else if g == range.offset {
        g + 1
    } else if g == range.offset + range.n - 1 {
        g - 1
    } else {
        g
    }
}

/// The largest penetration over the collocation points' `gaps` (the most negative finite gap, as a positive
/// length; 0 when none). Sample points between the collocation points join the maximum here (module docs).
fn largest_penetration(gaps: &[Real]) -> Real {
    gaps.iter()
        .filter(|g| g.is_finite())
        .fold(0.0, |worst: Real, &g| worst.max(-g))
}

#[cfg(test)]
pub(crate) mod tests {
    pub(crate) use super::super::tests::RING as SETTINGS;
    use super::super::tests::{D, E, R0, cylinder, quarter_ring};
    use crate::math::{Real, Vec3};
    use crate::model::{Contact, Model, Wall};
    use crate::solver::Simulation;
    use crate::solver::discretisation::point_position;
    use crate::solver::simulation::NoObserver;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// The radius the crimper reaches at t = 1, from 0.2 clear of the wires at t = 0: 0.5 into them.
    pub(crate) const CRIMPED: Real = R0 + D / 2.0 - 0.5;

    /// The quarter ring of the term's tests crimped by a rigid cylinder `crimper` ([`CRIMPED`], [`SETTINGS`]).
    pub(crate) fn crimped_ring() -> Model {
        quarter_ring(Contact {
            obstacles: vec![cylinder(R0 + D / 2.0 + 0.2, CRIMPED, Wall::Rigid)],
            settings: SETTINGS,
        })
    }

    /// Source: the quarter ring of the term's tests (reference radius `R0`, `EA` from the wire's diameter)
    /// crimped by a rigid cylinder to 5 % hoop strain. Rod theory (the term's ring test) gives the hoop force
    /// `N = EA (ρ/R0 − 1)` and the line pressure per reference length `q = −N/R0`, uniform. Integrated over the
    /// quarter's reference length `R0 π/2` (the line force is per reference length; per current length it is
    /// `q R0/ρ` over `ρ π/2`, the same total), the inward radial force is `q R0 π/2` and the force vector
    /// `∫ q n ds = −q R0 ∫₀^{π/2} (cos θ, sin θ, 0) dθ = −q R0 (1, 1, 0)`.
    ///
    /// Tolerances: the radial force integrates a uniform pressure, which the weights integrate exactly (their sum
    /// is the reference length); what is left is how uniform the converged pressure is, which the solver's
    /// tolerance (1e-9 normalised) bounds: 1e-8 relative (measured: the pressures spread by 4e-12, the radial
    /// force off by 6e-13). `q` is taken both from the hoop force at the ring's end (the node's reaction,
    /// independent of the report) and from the closed form at the radius reached. The force vector's components
    /// carry the trapezoidal rule's error on `q R0 cos θ`, at most `q R0 (π/2) h² / 12` with `h` the largest
    /// angle between successive points (measured here: h = 0.21, a bound of 5.6e-2 against the 2.7e-2 found),
    /// plus the same 1e-8. Every point is pressed, and the largest penetration is the one measured from the
    /// points' radii.
    #[test]
    fn a_crimped_ring_reports_its_uniform_pressure_integrated_over_the_quarter() {
        let (r, crimped) = (D / 2.0, CRIMPED);
        let model = crimped_ring();
        let mut sim = Simulation::new(&model).expect("discretised");
        sim.run(&mut [&mut NoObserver])
            .expect("the crimp converges");
        let report = sim.contact().expect("a model with contact reports it");
        assert_eq!(report.time, 1.0);
        assert_eq!(report.obstacles.len(), 1);
        let o = &report.obstacles[0];

        let disc = sim.discretisation();
        let radius = |control: &[Vec3], g: usize| {
            let x = point_position(disc, control, g);
            (x.x * x.x + x.y * x.y).sqrt()
        };
        let radii: Vec<Real> = (0..disc.points.len())
            .map(|g| radius(&sim.state().control, g))
            .collect();
        let rho = radii.iter().sum::<Real>() / radii.len() as Real;
        let area = PI * D * D / 4.0;
        let q_closed = E * area * (1.0 - rho / R0) / R0;
        let start = model
            .nodes
            .iter()
            .position(|n| n.name == "ring.start")
            .expect("node at the start");
        // The rod's start pushes on its node with −N in y (the term's ring test).
        let q_hoop = sim.node_end_resultants(start)[0].0.y / R0;
        assert!(
            (q_hoop - q_closed).abs() <= 1e-6 * q_closed,
            "{q_hoop} {q_closed}"
        );

        let radial = o.radial_force.expect("a cylinder has a radial force");
        let expected = q_closed * R0 * FRAC_PI_2;
        assert!(
            (radial - expected).abs() <= 1e-8 * expected,
            "radial force {radial} against q R0 π/2 = {expected}"
        );

        let angles: Vec<Real> = (0..disc.points.len())
            .map(|g| {
                let x = point_position(disc, &disc.control0, g);
                x.y.atan2(x.x)
            })
            .collect();
        let h = angles.windows(2).map(|w| w[1] - w[0]).fold(0.0, Real::max);
        let bound = q_closed * R0 * FRAC_PI_2 * h * h / 12.0 + 1e-8 * q_closed * R0;
        for (c, value) in [(0, o.force.x), (1, o.force.y)] {
            assert!(
                (value + q_closed * R0).abs() <= bound,
                "force component {c}: {value} against −q R0 = {} (bound {bound:.3e}, h = {h:.3})",
                -q_closed * R0
            );
        }
        assert!(o.force.z.abs() <= 1e-9 * q_closed * R0, "{}", o.force.z);
        assert_eq!(o.points, disc.points.len());
        assert!(
            o.pressure
                .iter()
                .all(|&p| (p - q_closed).abs() <= 1e-8 * q_closed)
        );
        let penetration = radii
            .iter()
            .map(|rho| rho + r - crimped)
            .fold(0.0, Real::max);
        assert!((o.penetration - penetration).abs() <= 1e-12 * R0);
        assert!(o.penetration <= SETTINGS.tolerance);
        for (g, gap) in o.gap.iter().enumerate() {
            assert!((gap - (crimped - radii[g] - r)).abs() <= 1e-12 * R0);
        }
        assert_eq!(
            o.friction_work, 0.0,
            "a frictionless crimper dissipates nothing"
        );
        // Apposition: the whole ring presses on the crimper with the uniform pressure; its widest gap is its
        // smallest penetration (the gaps were checked above).
        let a = &o.apposition;
        assert_eq!(a.contact_fraction, 1.0);
        assert!((a.mean_pressure - q_closed).abs() <= 1e-8 * q_closed);
        assert!((a.peak_pressure - q_closed).abs() <= 1e-8 * q_closed);
        let widest = o.gap.iter().copied().fold(Real::NEG_INFINITY, Real::max);
        assert_eq!(a.largest_gap.map(|(g, _, _)| g), Some(widest));
    }

    /// Source: geometry. The same ring inside a cylinder 0.2 clear of its wires touches nothing: no length in
    /// contact, no pressure, and every point's gap is the clearance (to round-off: the ring is exact).
    #[test]
    fn a_ring_clear_of_its_cylinder_reports_no_apposition_and_its_clearance() {
        let clear = R0 + D / 2.0 + 0.2;
        let model = quarter_ring(Contact {
            obstacles: vec![cylinder(clear, clear, Wall::Rigid)],
            settings: SETTINGS,
        });
        let sim = Simulation::new(&model).expect("discretised");
        let report = sim.contact().expect("a model with contact reports it");
        let a = &report.obstacles[0].apposition;
        assert_eq!(
            (a.contact_fraction, a.peak_pressure, a.mean_pressure),
            (0.0, 0.0, 0.0)
        );
        let (gap, patch, u) = a.largest_gap.expect("every point has a gap");
        assert!((gap - 0.2).abs() <= 1e-12 * R0, "{gap}");
        assert!(patch == 0 && (0.0..=1.0).contains(&u));
    }

    /// A model without contact has no report: nothing for the outputs to write.
    #[test]
    fn a_model_without_contact_reports_none() {
        let mut model = crimped_ring();
        model.contact = None;
        let sim = Simulation::new(&model).expect("discretised");
        assert!(sim.contact().is_none());
    }
}
