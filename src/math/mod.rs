//! Mathematical vocabulary and kernels: the crate's small types, knot vectors, B-spline and NURBS basis
//! functions with derivatives, curves (evaluation, knot insertion, degree elevation, interpolation) and the SO(3)
//! maps the rod kinematics needs, and how numbers and user values are quoted in messages ([`quote`], [`Short`]).
//!
//! Everything here is pure and allocation-light; algorithms cite their source (Piegl & Tiller, *The NURBS
//! Book*, 2nd ed., algorithm numbers A2.1 …).

pub(crate) mod approx;
pub mod basis;
pub mod curve;
pub(crate) mod interp;
pub mod knots;
pub mod quaternion_field;
pub mod quote;
pub(crate) mod serial;
pub mod so3;

pub use basis::BasisTable;
pub use curve::NurbsCurve;
pub use knots::KnotVector;

/// The floating-point type of every computation.
pub type Real = f64;
/// A vector (position, displacement, force, rotation vector …) in 3-D.
pub type Vec3 = nalgebra::Vector3<Real>;
/// A 3×3 matrix (stiffness block, skew matrix, rotation stored as its matrix).
pub type Mat3 = nalgebra::Matrix3<Real>;
/// A rotation; its matrix columns are the directors `d1, d2, d3` in global coordinates.
pub type Rot3 = nalgebra::Rotation3<Real>;

/// A number for messages: Rust's shortest round-trip form, in exponent notation outside `[1e-5, 1e15)` so that a
/// time of `1e300` (a typo) prints as `1e300`, not as 301 digits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Short(pub Real);

impl std::fmt::Display for Short {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let x = self.0;
        if x == 0.0 || !x.is_finite() || (1e-5..1e15).contains(&x.abs()) {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

impl Short {
    /// `x` rounded to `digits` significant digits, for a message (`0.1`, not `0.09999999999999999`, for a
    /// third of 0.3).
    pub fn rounded(x: Real, digits: usize) -> Short {
        Short(
            format!("{:.*e}", digits.saturating_sub(1), x)
                .parse()
                .unwrap_or(x),
        )
    }
}

/// Whether one of the sorted values `sorted` lies within `tolerance` of `x` (one binary search).
pub fn near_one_of(sorted: &[Real], x: Real, tolerance: Real) -> bool {
    let at = sorted.partition_point(|&v| v < x - tolerance);
    sorted.get(at).is_some_and(|&v| v <= x + tolerance)
}

/// Errors raised by the math layer when data (not the programmer) is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MathError {
    /// A knot vector failed validation.
    #[error("invalid knot vector: {reason}")]
    InvalidKnots {
        /// What is wrong, with the offending values.
        reason: String,
    },
    /// A curve's data are inconsistent (counts, weights, degree).
    #[error("invalid curve: {reason}")]
    InvalidCurve {
        /// What is wrong, with the offending values.
        reason: String,
    },
    /// A parameter lies outside the knot vector's domain.
    #[error("parameter {u} lies outside the domain [{lo}, {hi}]")]
    OutOfDomain {
        /// The parameter asked for.
        u: Real,
        /// Lower end of the domain.
        lo: Real,
        /// Upper end of the domain.
        hi: Real,
    },
    /// A linear system (interpolation) was singular.
    #[error("singular system in {context}")]
    Singular {
        /// Which computation.
        context: String,
    },
}

#[cfg(test)]
mod tests {
    use super::Short;

    /// Shortest round-trip digits in the usual range, exponent notation far from it.
    #[test]
    fn short_numbers_stay_short() {
        let shown = |x: f64| Short(x).to_string();
        assert_eq!(shown(1.75), "1.75");
        assert_eq!(shown(0.1), "0.1");
        assert_eq!(shown(0.0), "0");
        assert_eq!(shown(1e300), "1e300");
        assert_eq!(shown(-2.5e-7), "-2.5e-7");
        assert_eq!(shown(f64::NAN), "NaN");
        assert_eq!(shown(f64::INFINITY), "inf");
    }
}
