//! Cross-section stiffness of a solid circular rod (DESIGN §3).
//!
//! For a branch (or the equilibrium spring) of modulus `E` and `G = E/(2(1+ν))`, with area `A = πd²/4`,
//! second moment `I = πd⁴/64`, polar moment `J = 2I` and shear factor `k_s`:
//!
//! ```text
//! C_N = diag(E A, k_s G A, k_s G A),        C_M = diag(G J, E I, E I)
//! ```
//!
//! (axis `d1` first: axial force / torsion, then the two section directions). Every branch shares `ν`, so
//! `C_Nα = E_α S_N` and `C_Mα = E_α S_M` with fixed diagonal *shapes* ([`SectionShape`]):
//!
//! ```text
//! S_N = (A, k_s A/(2(1+ν)), k_s A/(2(1+ν))) [length²],     S_M = (J/(2(1+ν)), I, I) [length⁴].
//! ```
//!
//! Any sum of branch stiffnesses, in particular the paper's `C̄^{n+1}` (Eqs. `N_constitutive_disc`,
//! `M_constitutive_disc`), is then `S ⊙ Ē` with a scalar effective modulus `Ē`.

use super::MaterialError;
use crate::math::{Mat3, Real, Vec3};
use std::f64::consts::PI;

/// How the transverse-shear correction factor `k_s` is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub enum ShearFactor {
    /// Cowper's factor for a solid circle, `k_s = 6(1+ν)/(7+6ν)` (G. R. Cowper, *The shear coefficient in
    /// Timoshenko's beam theory*, J. Appl. Mech. 33 (1966) 335–340, Table 1); `0.8886` at `ν = 0.33`.
    #[default]
    Cowper,
    /// A given value \[-\], e.g. `0.9` or Timoshenko's `(6+12ν+6ν²)/(7+12ν+4ν²)`.
    Given(Real),
}

impl ShearFactor {
    /// The factor `k_s` \[-\] for Poisson's ratio `ν`.
    pub fn value(&self, poisson: Real) -> Real {
        match *self {
            ShearFactor::Cowper => 6.0 * (1.0 + poisson) / (7.0 + 6.0 * poisson),
            ShearFactor::Given(k) => k,
        }
    }
}

/// A validated solid circular cross-section.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct CircularSection {
    diameter: Real,
    shear_factor: ShearFactor,
}

impl CircularSection {
    /// A section of diameter `d > 0` \[length\] with Cowper's shear factor ([`ShearFactor::Cowper`]).
    pub fn try_new(diameter: Real) -> Result<Self, MaterialError> {
        Self::try_with_shear_factor(diameter, ShearFactor::Cowper)
    }

    /// A section of diameter `d > 0` \[length\] with the given shear-factor rule (a given `k_s` must be
    /// finite and `> 0`).
    pub fn try_with_shear_factor(
        diameter: Real,
        shear_factor: ShearFactor,
    ) -> Result<Self, MaterialError> {
        if !(diameter.is_finite() && diameter > 0.0) {
            return Err(MaterialError::Diameter { value: diameter });
        }
        match shear_factor {
            ShearFactor::Given(k) if !(k.is_finite() && k > 0.0) => {
                return Err(MaterialError::ShearFactor { value: k });
            }
            _ => {}
        }
        Ok(Self {
            diameter,
            shear_factor,
        })
    }

    /// Diameter `d` \[length\].
    pub fn diameter(&self) -> Real {
        self.diameter
    }

    /// The shear-factor rule.
    pub fn shear_factor(&self) -> ShearFactor {
        self.shear_factor
    }

    /// Area `A = πd²/4` \[length²\].
    pub fn area(&self) -> Real {
        PI * self.diameter.powi(2) / 4.0
    }

    /// Second moment of area about a diameter `I = πd⁴/64` \[length⁴\].
    pub fn second_moment(&self) -> Real {
        PI * self.diameter.powi(4) / 64.0
    }

    /// Polar (torsion) constant `J = 2I = πd⁴/32` \[length⁴\] (exact for a circle: no warping).
    pub fn polar_moment(&self) -> Real {
        2.0 * self.second_moment()
    }
}

/// A cross-section given by its properties rather than its shape: for verification problems stated in terms
/// of `A`, `I`, `J` and `k_s` (e.g. the unit square section of Bathe & Bolourchi's 45° bend). Both bending
/// axes share `I`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SectionProperties {
    /// Area `A` \[length²\].
    pub area: Real,
    /// Second moment of area about either section axis `I` \[length⁴\].
    pub second_moment: Real,
    /// Torsion constant `J` \[length⁴\].
    pub polar_moment: Real,
    /// Shear correction factor `k_s` \[-\].
    pub shear_factor: Real,
    /// Diameter of the circular tube drawn for this section \[length\] (exports only).
    pub drawing_diameter: Real,
}

/// A rod cross-section: a solid circle, or given properties.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum Section {
    /// A solid circle (the devices' wires).
    Circular(CircularSection),
    /// Given `A, I, J, k_s`.
    Properties(SectionProperties),
}

impl Section {
    /// A section from properties, each finite and `> 0`.
    pub fn try_from_properties(p: SectionProperties) -> Result<Self, MaterialError> {
        for (value, ok) in [
            (p.area, p.area > 0.0),
            (p.second_moment, p.second_moment > 0.0),
            (p.polar_moment, p.polar_moment > 0.0),
            (p.drawing_diameter, p.drawing_diameter > 0.0),
        ] {
            if !(value.is_finite() && ok) {
                return Err(MaterialError::Diameter { value });
            }
        }
        if !(p.shear_factor.is_finite() && p.shear_factor > 0.0) {
            return Err(MaterialError::ShearFactor {
                value: p.shear_factor,
            });
        }
        Ok(Section::Properties(p))
    }

    /// Area `A` \[length²\].
    pub fn area(&self) -> Real {
        match self {
            Section::Circular(c) => c.area(),
            Section::Properties(p) => p.area,
        }
    }

    /// Second moment of area `I` \[length⁴\].
    pub fn second_moment(&self) -> Real {
        match self {
            Section::Circular(c) => c.second_moment(),
            Section::Properties(p) => p.second_moment,
        }
    }

    /// Torsion constant `J` \[length⁴\].
    pub fn polar_moment(&self) -> Real {
        match self {
            Section::Circular(c) => c.polar_moment(),
            Section::Properties(p) => p.polar_moment,
        }
    }

    /// Shear correction factor `k_s` for Poisson's ratio `ν`.
    pub fn shear_factor(&self, poisson: Real) -> Real {
        match self {
            Section::Circular(c) => c.shear_factor().value(poisson),
            Section::Properties(p) => p.shear_factor,
        }
    }

    /// Diameter of the tube that draws the rod \[length\].
    pub fn diameter(&self) -> Real {
        match self {
            Section::Circular(c) => c.diameter(),
            Section::Properties(p) => p.drawing_diameter,
        }
    }
}

impl From<CircularSection> for Section {
    fn from(c: CircularSection) -> Self {
        Section::Circular(c)
    }
}

/// The stiffness shapes of a section for a given `ν`: the diagonals of `C_N/E` and `C_M/E`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionShape {
    /// `S_N = (A, k_s A/(2(1+ν)), k_s A/(2(1+ν)))` \[length²\]: `C_N = E · diag(S_N)`.
    pub force: Vec3,
    /// `S_M = (J/(2(1+ν)), I, I)` \[length⁴\]: `C_M = E · diag(S_M)`.
    pub moment: Vec3,
}

impl SectionShape {
    /// The shapes of `section` for Poisson's ratio `ν` (validated by [`super::Material`]).
    pub fn new(section: &Section, poisson: Real) -> Self {
        let a = section.area();
        let i = section.second_moment();
        let j = section.polar_moment();
        let k_s = section.shear_factor(poisson);
        let g_per_e = 1.0 / (2.0 * (1.0 + poisson));
        Self {
            force: Vec3::new(a, k_s * g_per_e * a, k_s * g_per_e * a),
            moment: Vec3::new(g_per_e * j, i, i),
        }
    }

    /// Diagonal of `C_N = diag(E A, k_s G A, k_s G A)` \[force\] for a modulus `E` \[stress\].
    pub fn force_stiffness(&self, modulus: Real) -> Vec3 {
        self.force * modulus
    }

    /// Diagonal of `C_M = diag(G J, E I, E I)` \[force·length²\] for a modulus `E` \[stress\].
    pub fn moment_stiffness(&self, modulus: Real) -> Vec3 {
        self.moment * modulus
    }

    /// `C_N` as a matrix \[force\].
    pub fn force_matrix(&self, modulus: Real) -> Mat3 {
        Mat3::from_diagonal(&self.force_stiffness(modulus))
    }

    /// `C_M` as a matrix \[force·length²\].
    pub fn moment_matrix(&self, modulus: Real) -> Mat3 {
        Mat3::from_diagonal(&self.moment_stiffness(modulus))
    }
}

#[cfg(test)]
mod tests {
    // Reference: hand values for the paper's arch section (d = 0.05 m, ν = 0.33, §4.1): A = π·0.05²/4 =
    // 0.001963495408493621 m², I = π·0.05⁴/64 = 3.0679615757712823e-7 m⁴, Cowper k_s = 7.98/8.98 =
    // 0.88864142538975501. Closed forms of a few flops: 1e-14 relative.
    use super::*;

    fn rel(a: Real, b: Real) -> Real {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn circular_section_properties() {
        let s = CircularSection::try_new(0.05).expect("valid diameter");
        assert!(rel(s.area(), 0.001963495408493621) < 1e-14);
        assert!(rel(s.second_moment(), 3.0679615757712823e-07) < 1e-14);
        assert_eq!(s.polar_moment(), 2.0 * s.second_moment());
        assert!(rel(ShearFactor::Cowper.value(0.33), 0.888641425389755) < 1e-14);
        // ν = 0.3 gives Cowper's tabulated 0.886 for a solid circle.
        assert!((ShearFactor::Cowper.value(0.3) - 0.886).abs() < 5e-4);
    }

    #[test]
    fn stiffness_is_modulus_times_shape() {
        let nu = 0.33;
        let e = 2394.4e6;
        let s = CircularSection::try_new(0.05).expect("valid diameter");
        let shape = SectionShape::new(&s.into(), nu);
        let g = e / (2.0 * (1.0 + nu));
        let k = ShearFactor::Cowper.value(nu);
        let cn = shape.force_matrix(e);
        let cm = shape.moment_matrix(e);
        let want_n = [e * s.area(), k * g * s.area(), k * g * s.area()];
        let want_m = [
            g * s.polar_moment(),
            e * s.second_moment(),
            e * s.second_moment(),
        ];
        for i in 0..3 {
            assert!(rel(cn[(i, i)], want_n[i]) < 1e-14);
            assert!(rel(cm[(i, i)], want_m[i]) < 1e-14);
            for j in 0..3 {
                if i != j {
                    assert_eq!(cn[(i, j)], 0.0);
                    assert_eq!(cm[(i, j)], 0.0);
                }
            }
        }
    }

    #[test]
    fn rejects_bad_sections() {
        assert!(matches!(
            CircularSection::try_new(0.0),
            Err(MaterialError::Diameter { .. })
        ));
        assert!(matches!(
            CircularSection::try_new(Real::NAN),
            Err(MaterialError::Diameter { .. })
        ));
        assert!(matches!(
            CircularSection::try_with_shear_factor(1.0, ShearFactor::Given(-0.1)),
            Err(MaterialError::ShearFactor { .. })
        ));
        let s =
            CircularSection::try_with_shear_factor(1.0, ShearFactor::Given(0.9)).expect("valid");
        assert_eq!(
            SectionShape::new(&s.into(), 0.0).force[1],
            0.9 * s.area() / 2.0
        );
    }
}
