//! The fields along the rods in the current state, at the collocation points — where the method computes them
//! (no interpolation): position and displacement, rotation, material strains `Γ − Γ0` and `K − K0`, section
//! force and moment (material `N`, `M` and spatial `n = R N`, `m = R M`), the viscous strains of the material,
//! temperature and WLF shift, and the peak surface strain of the section ([`peak_surface_strain`]). What
//! ParaView files and the history's peak strain are made of.
//!
//! **Peak surface strain.** A fibre of the section at `Y = (0, y2, y3)` (section frame) lies at `x = c + R Y`,
//! so `x,s = R (Γ + K × Y)`, and in the reference `X,s = R0 (Γ0 + K0 × Y)`. Its stretch is
//! ```text
//! λ(Y) = |Γ + K × Y| / |Γ0 + K0 × Y|,      K × Y = (K2 y3 − K3 y2, −K1 y3, K1 y2),
//! ```
//! exact within the rod theory (rigid sections: no Poisson contraction, no warping). The surface strain is
//! `λ − 1` on the circle `|Y| = r` (the section's outer radius: the wire's, or the drawing diameter's half for a
//! section given by its properties), and the peak is the largest `λ − 1` around it: the most stretched fibre,
//! what a strain limit (elongation at break) is compared with. For a straight rod with small strains it is the familiar
//! `Γ1 − 1 ± r |(K2, K3)|` plus second-order shear and torsion terms; on the crowns' curved wires (`r |K0|` up to
//! 0.13 on the paper's stents) the reference length `|Γ0 + K0 × Y|` matters at that order and is kept.

use super::Simulation;
use crate::material::ConstitutiveLaw;
use crate::math::so3::log;
use crate::math::{Real, Rot3, Vec3};
use crate::model::ProbeLocation;
use crate::solver::assembly::{
    ARC_LENGTH_PARTS, arc_length_between, point_position, point_strains,
};
use rayon::prelude::*;

/// Angles sampled around the section before the peak is refined (every 30°).
const SURFACE_SAMPLES: usize = 12;

/// Largest number of parabolic refinements of the peak's angle ([`peak_surface_strain`]).
const REFINEMENTS: usize = 30;

/// The refinement stops when a vertex moves the angle by less than this \[rad\]: the strain is then within
/// ~1e-16 of its peak (quadratic there).
const ANGLE_TOLERANCE: Real = 1e-8;

/// The fields of one collocation point (material quantities in the section frame `d1, d2, d3`; spatial ones in
/// global coordinates; the model's units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointFields {
    /// Index of the patch ([`crate::model::Model::patches`]).
    pub patch: usize,
    /// Reference arc length from the patch's start \[length\].
    pub arc_length: Real,
    /// Current position \[length\].
    pub position: Vec3,
    /// Displacement from the reference \[length\].
    pub displacement: Vec3,
    /// Rotation vector of `R R0ᵀ` (spatial, `|θ| ≤ π`) \[rad\].
    pub rotation: Vec3,
    /// `Γ − Γ0`: axial strain and the two shear strains \[-\].
    pub strain: Vec3,
    /// `K − K0`: twist and the two bending curvatures \[1/length\].
    pub curvature: Vec3,
    /// Section force `N` (material: axial, two shears) \[force\].
    pub force: Vec3,
    /// Section moment `M` (material: torque, two bending moments) \[force·length\].
    pub moment: Vec3,
    /// Section force `n = R N` (spatial) \[force\].
    pub force_spatial: Vec3,
    /// Section moment `m = R M` (spatial) \[force·length\].
    pub moment_spatial: Vec3,
    /// Viscous strains `Γ_v` matching `strain` ([`ConstitutiveLaw::viscous_strains`]; zero for an elastic
    /// material) \[-\].
    pub viscous_strain: Vec3,
    /// Viscous curvatures `K_v` matching `curvature` \[1/length\].
    pub viscous_curvature: Vec3,
    /// Temperature \[°C\].
    pub temperature: Real,
    /// `log10 a_T` of the material's WLF shift at that temperature; NaN without a shift or where relaxation is
    /// frozen (below `Tg − C2`).
    pub log10_shift: Real,
    /// Peak surface strain of the section (module docs): the largest `λ − 1` around it \[-\].
    pub surface_strain: Real,
}

/// Where the device's surface strain peaks (largest over the collocation points).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeakSurfaceStrain {
    /// The strain (positive: stretched) \[-\].
    pub value: Real,
    /// Its patch ([`crate::model::Model::patches`]).
    pub patch: usize,
    /// Reference arc length from the patch's start \[length\].
    pub arc_length: Real,
}

/// Peak surface strain of a section of radius `r` (module docs): the largest `λ − 1` around the circle (the
/// most stretched fibre; negative only where every fibre is shortened), with `gamma`, `kappa` the current and
/// `gamma0`, `kappa0` the reference strains. Sampled every 30° and refined by successive parabolic
/// interpolation: `λ` is a ratio of square roots of trigonometric polynomials of degree 2, smooth in the angle, so a handful of
/// vertices reach the peak (tests: closed forms and a dense sampling).
pub fn peak_surface_strain(gamma: Vec3, kappa: Vec3, gamma0: Vec3, kappa0: Vec3, r: Real) -> Real {
    SectionStretch::new(gamma, kappa, gamma0, kappa0, r).peak()
}

/// The fibre tangents of a section around its circle, `a + cos φ b + sin φ c` now and `a0 + cos φ b0 +
/// sin φ c0` in the reference (`a = Γ`, `b = r K × d2`, `c = r K × d3` in the section frame; module docs).
#[derive(Debug, Clone, Copy)]
struct SectionStretch {
    now: [Vec3; 3],
    reference: [Vec3; 3],
}

impl SectionStretch {
    fn new(gamma: Vec3, kappa: Vec3, gamma0: Vec3, kappa0: Vec3, r: Real) -> Self {
        Self {
            now: [
                gamma,
                kappa.cross(&Vec3::y()) * r,
                kappa.cross(&Vec3::z()) * r,
            ],
            reference: [
                gamma0,
                kappa0.cross(&Vec3::y()) * r,
                kappa0.cross(&Vec3::z()) * r,
            ],
        }
    }

    /// `λ − 1` of the fibre at angle `phi`.
    fn strain(&self, phi: Real) -> Real {
        let (sin, cos) = phi.sin_cos();
        let [a, b, c] = self.now;
        let [a0, b0, c0] = self.reference;
        (a + b * cos + c * sin).norm() / (a0 + b0 * cos + c0 * sin).norm() - 1.0
    }

    /// An upper bound of `|λ − 1|` around the circle, cheap and zero where nothing is strained: with
    /// `n(φ) = |x,s|²` and `d(φ) = |X,s|²`, `|λ² − 1| = |n − d| / d ≤ q = max |n − d| / min d`, where `n − d`
    /// is a trigonometric polynomial of degree 2 bounded by its coefficients (the constant, the first harmonic's
    /// amplitude, the spectral radius of the quadratic part) and `√d ≥ |a0| − √(|b0|² + |c0|²)`; then
    /// `|λ − 1| = |λ² − 1| / (λ + 1) ≤ q / (1 + √(1 − q))`.
    fn bound(&self) -> Real {
        let [a, b, c] = self.now;
        let [a0, b0, c0] = self.reference;
        let constant = a.norm_squared() - a0.norm_squared();
        let first = 2.0 * Real::hypot(a.dot(&b) - a0.dot(&b0), a.dot(&c) - a0.dot(&c0));
        let (bb, cc, bc) = (
            b.norm_squared() - b0.norm_squared(),
            c.norm_squared() - c0.norm_squared(),
            b.dot(&c) - b0.dot(&c0),
        );
        let quadratic = 0.5 * (bb + cc).abs() + Real::hypot(0.5 * (bb - cc), bc);
        let smallest = a0.norm() - (b0.norm_squared() + c0.norm_squared()).sqrt();
        if smallest <= 0.0 {
            return Real::INFINITY;
        }
        // |λ² − 1| ≤ q, so λ ≥ √(1 − q) and |λ − 1| = |λ² − 1|/(λ + 1) ≤ q/(1 + √(1 − q)).
        let q = (constant.abs() + first + quadratic) / (smallest * smallest);
        q / (1.0 + (1.0 - q).max(0.0).sqrt())
    }

    /// The largest `λ − 1` around the circle ([`peak_surface_strain`]).
    fn peak(&self) -> Real {
        self.extreme(1.0)
    }

    /// The largest `sign · (λ − 1)` around the circle, returned as `λ − 1`: sampled every 30°
    /// ([`SURFACE_SAMPLES`]), then refined by successive parabolic interpolation in the bracket of the best
    /// sample's neighbours, each new vertex replacing the bracket's end on its side (or becoming the middle when
    /// it is better).
    fn extreme(&self, sign: Real) -> Real {
        let f = |phi: Real| sign * self.strain(phi);
        let step = std::f64::consts::TAU / SURFACE_SAMPLES as Real;
        let (best, value) = (0..SURFACE_SAMPLES)
            .map(|k| f(k as Real * step))
            .enumerate()
            .fold((0, Real::NEG_INFINITY), |(bk, bv), (k, v)| {
                if v > bv { (k, v) } else { (bk, bv) }
            });
        let b = best as Real * step;
        let (mut a, mut b, mut c) = ((b - step, f(b - step)), (b, value), (b + step, f(b + step)));
        for _ in 0..REFINEMENTS {
            let (ba, bc) = (b.0 - a.0, b.0 - c.0);
            let (da, dc) = (b.1 - a.1, b.1 - c.1);
            let denominator = ba * dc - bc * da;
            if denominator == 0.0 {
                break;
            }
            let v = b.0 - 0.5 * (ba * ba * dc - bc * bc * da) / denominator;
            if !(v > a.0 && v < c.0) || (v - b.0).abs() < ANGLE_TOLERANCE {
                break;
            }
            let new = (v, f(v));
            match (v > b.0, new.1 >= b.1) {
                (true, true) => (a, b) = (b, new),
                (true, false) => c = new,
                (false, true) => (c, b) = (b, new),
                (false, false) => a = new,
            }
        }
        sign * b.1
    }
}

impl Simulation<'_> {
    /// The fields at every collocation point in the current state, in the global numbering (patch by patch,
    /// along each patch).
    pub fn point_fields(&self) -> Vec<PointFields> {
        let (model, disc, state) = (self.model, &self.disc, &self.solution.state);
        let t = self.schedule_time();
        (0..disc.points.len())
            .map(|g| {
                let point = &disc.points[g];
                let position = point_position(disc, &state.control, g);
                let (strain, stretch) = self.stretch_at(g);
                let stress = self.materials.laws[g].stress(&strain);
                let rotation = state.rotation[g];
                let temperature = match &model.temperature_field {
                    Some(field) => {
                        let (x, tangent) = &self.materials.places()[g];
                        field.at(x, tangent, t).0
                    }
                    None => model.temperature().value(t),
                };
                let (viscous_strain, viscous_curvature) = self
                    .materials
                    .viscous_strains(model.materials(), g)
                    .unwrap_or_default();
                let wlf =
                    model.materials()[model.patches[point.patch].material].temperature_shift();
                PointFields {
                    patch: point.patch,
                    arc_length: self.arc_lengths()[g],
                    position,
                    displacement: position - point_position(disc, &disc.control0, g),
                    rotation: log(&Rot3::from_matrix_unchecked(
                        rotation * point.rotation0.transpose(),
                    )),
                    strain: strain.force,
                    curvature: strain.moment,
                    force: stress.force,
                    moment: stress.moment,
                    force_spatial: rotation * stress.force,
                    moment_spatial: rotation * stress.moment,
                    viscous_strain,
                    viscous_curvature,
                    temperature,
                    log10_shift: wlf
                        .and_then(|w| w.log10_shift(temperature))
                        .unwrap_or(Real::NAN),
                    surface_strain: stretch.peak(),
                }
            })
            .collect()
    }

    /// For each probe of the model, the collocation point it sits on (its index in [`Simulation::point_fields`]):
    /// the point of a probe at a node; `None` for a probe inside a patch (between collocation points).
    pub fn probe_points(&self) -> Vec<Option<usize>> {
        self.model
            .probes
            .iter()
            .map(|p| match p.location {
                ProbeLocation::Node(k) => Some(self.disc.end_point(self.model.nodes[k].ends[0])),
                ProbeLocation::Patch { .. } => None,
            })
            .collect()
    }

    /// Where the device's surface strain is largest in the current state ([`peak_surface_strain`] at every
    /// collocation point); `None` for a model without points.
    pub fn peak_surface_strain(&self) -> Option<PeakSurfaceStrain> {
        self.peak_surface_strain_of(None)
    }

    /// [`Simulation::peak_surface_strain`] over the rods of one material (an index into
    /// [`crate::model::Model::materials`]), or of all with `None`; `None` when there are no such points.
    pub fn peak_surface_strain_of(&self, material: Option<usize>) -> Option<PeakSurfaceStrain> {
        let (model, disc) = (self.model, &self.disc);
        let mut candidates: Vec<(usize, SectionStretch, Real)> = (0..disc.points.len())
            .into_par_iter()
            .filter(|&g| material.is_none_or(|m| model.patches[disc.points[g].patch].material == m))
            .map(|g| {
                let stretch = self.stretch_at(g).1;
                (g, stretch, stretch.bound())
            })
            .collect();
        // The points by their bound, largest first: once a bound is below the largest strain found, no point
        // after it can exceed it. Among equal strains the first point wins (the same whatever the threads).
        candidates.sort_by(|x, y| y.2.total_cmp(&x.2).then(x.0.cmp(&y.0)));
        let mut best: Option<(usize, Real)> = None;
        for (g, stretch, bound) in candidates {
            if let Some((k, value)) = best
                && (bound < value || (bound == value && k < g))
            {
                break;
            }
            let value = stretch.peak();
            if best.is_none_or(|(k, v)| value > v || (value == v && g < k)) {
                best = Some((g, value));
            }
        }
        let (g, value) = best?;
        Some(PeakSurfaceStrain {
            value,
            patch: disc.points[g].patch,
            arc_length: self.arc_lengths()[g],
        })
    }
}

impl Simulation<'_> {
    /// The strains of collocation point `g` and its section's fibre stretches around the circle of its
    /// section's radius (half the wire's diameter, or of the drawing diameter of a section given by properties).
    fn stretch_at(&self, g: usize) -> (crate::material::SectionStrains, SectionStretch) {
        let (model, disc, state) = (self.model, &self.disc, &self.solution.state);
        let point = &disc.points[g];
        let strain = point_strains(disc, state, g);
        let radius = model.wire_radius(point.patch);
        let stretch = SectionStretch::new(
            point.gamma0 + strain.force,
            state.kappa[g],
            point.gamma0,
            point.kappa0,
            radius,
        );
        (strain, stretch)
    }

    /// The reference arc length of every collocation point from its patch's start (computed once,
    /// [`super::measures::Measures::arc_lengths`]).
    pub(super) fn arc_lengths(&self) -> &[Real] {
        self.measures.arc_lengths(self.model, &self.disc)
    }
}

/// The reference arc length of every collocation point from its patch's start (Gauss–Legendre between
/// successive points, [`ARC_LENGTH_PARTS`] parts each).
pub(super) fn arc_lengths(
    model: &crate::model::Model,
    disc: &crate::solver::discretisation::Discretisation,
) -> Vec<Real> {
    let mut out = vec![0.0; disc.points.len()];
    for (range, patch) in disc.patches.iter().zip(&model.patches) {
        for g in range.offset + 1..range.offset + range.n {
            let (a, b) = (disc.points[g - 1].u, disc.points[g].u);
            out[g] = out[g - 1] + arc_length_between(&patch.curve, a, b, ARC_LENGTH_PARTS);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Source: a straight rod (Γ0 = d1, K0 = 0) bent to curvature κ about d2 without stretch: the fibre at
    /// `y3` has `x,s = (1 + κ y3) d1`, so the peak is `κ r` exactly (the issue's `Γ1 − 1 + r |K2,3|`).
    #[test]
    fn bending_a_straight_rod_strains_its_surface_by_kappa_r() {
        let e1 = Vec3::x();
        for (k2, k3) in [(0.1, 0.0), (0.0, -0.2), (0.3, 0.4)] {
            let kappa = Vec3::new(0.0, k2, k3);
            let peak = peak_surface_strain(e1, kappa, e1, Vec3::zeros(), 0.3);
            let expected = 0.3 * Real::hypot(k2, k3);
            assert!((peak - expected).abs() < 1e-12, "{peak} vs {expected}");
        }
        // Stretch adds to it: Γ1 = 1.01.
        let peak = peak_surface_strain(
            Vec3::new(1.01, 0.0, 0.0),
            Vec3::new(0.0, 0.1, 0.0),
            e1,
            Vec3::zeros(),
            0.3,
        );
        assert!((peak - 0.04).abs() < 1e-12, "{peak}");
    }

    /// Source: curved-beam (Winkler) kinematics: a wire of curvature κ0 bent to κ1 about d3 without stretching
    /// its centreline; the fibre at `y2` has length ∝ `1 − κ y2` before and after, so
    /// `λ = (1 − κ1 y2)/(1 − κ0 y2)`, largest in magnitude at `y2 = ±r`. Tolerance: round-off.
    #[test]
    fn a_curved_wire_measures_strain_against_its_curved_reference() {
        let (k0, k1, r) = (0.45, 0.6, 0.3);
        let peak = peak_surface_strain(
            Vec3::x(),
            Vec3::new(0.0, 0.0, k1),
            Vec3::x(),
            Vec3::new(0.0, 0.0, k0),
            r,
        );
        let at = |y: Real| (1.0 - k1 * y) / (1.0 - k0 * y) - 1.0;
        let expected = if at(r) > at(-r) { at(r) } else { at(-r) };
        assert!((peak - expected).abs() < 1e-12, "{peak} vs {expected}");
        // The straight-rod formula r |ΔK| is off by the reference curvature's share.
        let naive = r * (k1 - k0);
        assert!((peak - naive).abs() > 0.01 * naive);
    }

    /// Source: a dense sampling (every 0.01°) of the stretch formula itself, for strains of every kind at once on
    /// a curved wire: the refined peak is the sampled maximum to 1e-9 (the sampling's own error is ~1e-10).
    #[test]
    fn the_refined_peak_matches_a_dense_sampling() {
        let cases = [
            (
                Vec3::new(1.02, 0.01, -0.03),
                Vec3::new(0.3, -0.5, 0.8),
                Vec3::new(0.0, 0.2, 0.45),
            ),
            (
                Vec3::new(0.97, 0.0, 0.0),
                Vec3::new(-0.1, 0.05, 0.02),
                Vec3::new(0.0, 0.0, 0.3),
            ),
            (
                Vec3::new(1.0, 0.05, 0.05),
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::zeros(),
            ),
        ];
        for (gamma, kappa, kappa0) in cases {
            let r = 0.3;
            let peak = peak_surface_strain(gamma, kappa, Vec3::x(), kappa0, r);
            let dense = (0..36_000)
                .map(|k| {
                    let phi = k as Real * std::f64::consts::TAU / 36_000.0;
                    let y = Vec3::new(0.0, r * phi.cos(), r * phi.sin());
                    (gamma + kappa.cross(&y)).norm() / (Vec3::x() + kappa0.cross(&y)).norm() - 1.0
                })
                .fold(Real::NEG_INFINITY, Real::max);
            assert!((peak - dense).abs() < 1e-9, "{peak} vs {dense}");
        }
    }

    /// The pruning bound of the device's peak ([`SectionStretch::bound`]) is never below the peak it bounds
    /// (pseudo-random strains of every kind, on straight and curved wires) and is zero where nothing is strained.
    #[test]
    fn the_bound_is_above_the_peak_and_zero_at_rest() {
        let mut seed = 0x2545_f491_u64;
        let mut next = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            ((seed >> 11) as Real / (1u64 << 53) as Real) * 2.0 - 1.0
        };
        for _ in 0..2000 {
            let kappa0 = Vec3::new(0.1 * next(), 0.5 * next(), 0.5 * next());
            let gamma = Vec3::new(1.0 + 0.05 * next(), 0.05 * next(), 0.05 * next());
            let kappa = kappa0 + Vec3::new(next(), next(), next());
            let stretch = SectionStretch::new(gamma, kappa, Vec3::x(), kappa0, 0.3);
            assert!(stretch.bound() >= stretch.peak().abs() * (1.0 - 1e-12));
            let rest = SectionStretch::new(Vec3::x(), kappa0, Vec3::x(), kappa0, 0.3);
            assert_eq!(rest.bound(), 0.0);
        }
    }

    /// Source: twist alone (K1 = τ) stretches the surface fibres, which become helices: `λ = √(1 + τ² r²)`
    /// everywhere around the circle, so the peak is found between samples too.
    #[test]
    fn twist_stretches_the_surface_as_a_helix() {
        let tau = 0.5;
        let peak = peak_surface_strain(
            Vec3::x(),
            Vec3::new(tau, 0.0, 0.0),
            Vec3::x(),
            Vec3::zeros(),
            0.3,
        );
        let expected = (1.0 + (tau * 0.3) * (tau * 0.3)).sqrt() - 1.0;
        assert!((peak - expected).abs() < 1e-14, "{peak} vs {expected}");
    }
}
