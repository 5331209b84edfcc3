//! The Williams–Landel–Ferry (WLF) time–temperature shift of relaxation times (paper Eq. `at`).
//!
//! ```text
//! log10 a_T(T) = −C1 (T − Tg) / (C2 + T − Tg),      τ_α(T) = τ_G,α · a_T(T) = τ_G,α · 10^{log10 a_T(T)}.
//! ```
//!
//! Naming: the paper writes `a_T` for the *exponent* (`τ = τ_G 10^{a_T}`); here, as in most of the
//! time–temperature-superposition literature (Ferry 1980), `a_T = τ(T)/τ_G` is the shift *factor* and its
//! exponent is [`Wlf::log10_shift`].
//!
//! # Rates, not times
//!
//! The material layer works with relaxation *rates* `λ_α(T) = 1/τ_α(T) = rate_factor(T) / τ_G,α`, where
//! `rate_factor = 1/a_T = 10^{−log10 a_T}` ([`Wlf::rate_factor`]). Two reasons:
//!
//! * **Freezing.** At and below `T = Tg − C2` the formula is singular (the denominator vanishes, then changes
//!   sign and would predict *fast* relaxation in the cold). As Abaqus' TRS shift does, relaxation freezes there:
//!   `τ = ∞`, i.e. rate `0` — representable without infinities ([`Wlf::is_frozen`] lets a caller warn once).
//! * **Overflow.** Just above `Tg − C2` the exponent `log10 a_T` tends to `+∞`: `a_T` and `τ` overflow to `∞`
//!   (and `1/τ` of an overflowed `τ` is exact only by luck), whereas `10^{−log10 a_T}` underflows gracefully
//!   through the subnormals to `0`, continuously joining the frozen branch. On the other side `log10 a_T > −C1`
//!   for every unfrozen `T`, so `rate_factor < 10^{C1}`: with `C1 ≤` [`MAX_C1`] `= 300` (validated) it never
//!   overflows. No NaN or ∞ can leave this module for a finite temperature.

use super::MaterialError;
use crate::math::Real;

/// Largest accepted `C1` \[-\]. `C1` is a decimal exponent bound (`1/a_T < 10^{C1}`); `10^{300}` is still
/// finite in `f64` (max ≈ `1.8e308`). Measured polymers have `C1` ≈ 8–40 (the "universal" value is 17.44).
pub(crate) const MAX_C1: Real = 300.0;

/// Validated WLF constants: `C1 > 0` \[-\], `C2 > 0` \[K\], reference (glass-transition) temperature `Tg` \[°C\].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Wlf {
    c1: Real,
    c2: Real,
    tg: Real,
}

impl Wlf {
    /// Validates `0 < C1 ≤` `MAX_C1`, `C2 > 0` \[K\] (finite and not subnormal) and a finite `Tg` \[°C\].
    pub fn try_new(c1: Real, c2: Real, tg: Real) -> Result<Self, MaterialError> {
        if !(c1 > 0.0 && c1 <= MAX_C1) {
            return Err(MaterialError::WlfC1 { value: c1 });
        }
        if !(c2.is_normal() && c2 > 0.0) {
            return Err(MaterialError::WlfC2 { value: c2 });
        }
        if !tg.is_finite() {
            return Err(MaterialError::GlassTransition { value: tg });
        }
        Ok(Self { c1, c2, tg })
    }

    /// PLA after van Manen et al. (2021), paper Table `aT_PLA`, first row: `C1 = 14.59`, `C2 = 48.43 K`,
    /// `Tg = 70.0 °C`.
    pub fn van_manen_2021() -> Self {
        Self {
            c1: 14.59,
            c2: 48.43,
            tg: 70.0,
        }
    }

    /// PLA after Lin et al. (2020), paper Table `aT_PLA`, second row: `C1 = 17.44`, `C2 = 51.60 K`,
    /// `Tg = 66.9 °C`.
    pub fn lin_2020() -> Self {
        Self {
            c1: 17.44,
            c2: 51.60,
            tg: 66.9,
        }
    }

    /// `C1` \[-\].
    pub fn c1(&self) -> Real {
        self.c1
    }

    /// `C2` \[K\].
    pub fn c2(&self) -> Real {
        self.c2
    }

    /// Reference (glass-transition) temperature `Tg` \[°C\].
    pub fn tg(&self) -> Real {
        self.tg
    }

    /// The freezing temperature `Tg − C2` \[°C\]: at and below it relaxation stops.
    pub fn frozen_below(&self) -> Real {
        self.tg - self.c2
    }

    /// Whether relaxation is frozen at `T` \[°C\]: `T ≤ Tg − C2` (where paper Eq. `at` is singular). A NaN
    /// temperature is not frozen (it propagates as NaN through [`Self::log10_shift`]; the time-stepping
    /// functions reject it).
    pub fn is_frozen(&self, temperature: Real) -> bool {
        temperature <= self.frozen_below() || self.c2 + (temperature - self.tg) <= 0.0
    }

    /// `log10 a_T = −C1 (T − Tg)/(C2 + T − Tg)` (paper Eq. `at`), so `τ(T) = τ_G · 10^{log10 a_T}`; `0` at
    /// `T = Tg`, strictly decreasing in `T`, `> −C1` and tending to `−C1` as `T → +∞`. `None` when frozen
    /// ([`Self::is_frozen`]: `τ = ∞`). Large but finite just above `Tg − C2`.
    pub fn log10_shift(&self, temperature: Real) -> Option<Real> {
        if self.is_frozen(temperature) {
            return None;
        }
        let x = temperature - self.tg;
        if x == Real::INFINITY {
            return Some(-self.c1); // the limit; ∞/∞ would be NaN
        }
        // Ratio first: −C1·x could overflow for huge x, the ratio lies in (−∞, 1). Just above the freezing
        // point C2 + x is an exact (Sterbenz) difference, a multiple of ulp(C2)/2, so |x/(C2 + x)| ≲ 2^54 and
        // the result stays finite (C1 ≤ 300).
        Some(-self.c1 * (x / (self.c2 + x)))
    }

    /// `d ln(rate_factor)/dT = ln 10 · C1 C2 / (C2 + T − Tg)²` \[1/K\] (the derivative of `−ln a_T`, paper
    /// Eq. `at`): how fast the relaxation rates change with temperature, for a temperature varying along a rod.
    /// `0` when frozen (the rate factor is the constant 0 there).
    pub fn log_rate_slope(&self, temperature: Real) -> Real {
        if self.is_frozen(temperature) {
            return 0.0;
        }
        let denominator = self.c2 + (temperature - self.tg);
        std::f64::consts::LN_10 * self.c1 * self.c2 / (denominator * denominator)
    }

    /// The rate factor `1/a_T = 10^{−log10 a_T}` \[-\] multiplying every relaxation rate:
    /// `λ_α(T) = rate_factor(T)/τ_G,α`. `1` at `Tg`, non-decreasing in `T`, in `[0, 10^{C1})`; `0` when frozen
    /// and, by underflow, just above the freezing temperature. Never NaN or ∞ for a non-NaN temperature.
    pub fn rate_factor(&self, temperature: Real) -> Real {
        self.log10_shift(temperature)
            .map_or(0.0, |s| Real::powf(10.0, -s))
    }
}

#[cfg(test)]
mod tests {
    // Independent reference: hand evaluation of paper Eq. `at` for both rows of Table aT_PLA, computed with
    // python/mpmath at 30 digits, e.g. van Manen at 31.5 °C: x = −38.5, −14.59·(−38.5)/(48.43 − 38.5) =
    // 56.567472306143; Lin at 90 °C: x = 23.1, −17.44·23.1/74.7 = −5.3930923694779116. The formula is a
    // handful of flops, so agreement to 1e-14 relative (a few ulps) is expected; the one test that
    // subtracts nearly equal numbers (T just above Tg − C2) checks only finiteness and sign.
    use super::*;
    use proptest::prelude::*;
    use proptest::test_runner::RngSeed;

    fn close(a: Real, b: Real) -> bool {
        (a - b).abs() <= 1e-14 * b.abs().max(1.0)
    }

    #[test]
    fn log10_shift_matches_hand_values_for_table_at_pla() {
        let vm = Wlf::van_manen_2021();
        let vm_ref = [
            (31.5, 56.567472306143),
            (50.0, 10.263805838902568),
            (60.0, 3.796513140775436),
            (70.0, 0.0),
            (80.0, -2.4970049632038336),
            (90.0, -4.264211603098056),
            (120.0, -7.411358325713705),
        ];
        for (t, want) in vm_ref {
            let got = vm.log10_shift(t).expect("above Tg − C2");
            assert!(close(got, want), "van Manen T = {t}: {got} vs {want}");
        }
        let lin = Wlf::lin_2020();
        let lin_ref = [
            (31.5, 38.10962962962963),
            (50.0, 8.493832853025937),
            (66.9, 0.0),
            (80.0, -3.53112828438949),
            (90.0, -5.393092369477912),
            (120.0, -8.844928366762177),
        ];
        for (t, want) in lin_ref {
            let got = lin.log10_shift(t).expect("above Tg − C2");
            assert!(close(got, want), "Lin T = {t}: {got} vs {want}");
        }
    }

    #[test]
    fn shift_is_identity_at_tg() {
        // τ(Tg) = τ_G exactly: the exponent is exactly 0, so the rate factor is exactly 1.
        for w in [Wlf::van_manen_2021(), Wlf::lin_2020()] {
            assert_eq!(w.log10_shift(w.tg()), Some(0.0));
            assert_eq!(w.rate_factor(w.tg()), 1.0);
        }
    }

    #[test]
    fn freezes_at_and_below_tg_minus_c2_without_nan() {
        let w = Wlf::van_manen_2021();
        let tf = w.frozen_below();
        assert!((tf - 21.57).abs() < 1e-12);
        for t in [tf, tf - 1e-9, tf - 1.0, -273.15, -1e300, Real::NEG_INFINITY] {
            assert!(w.is_frozen(t), "T = {t}");
            assert_eq!(w.log10_shift(t), None);
            assert_eq!(w.rate_factor(t), 0.0);
        }
        // Just above: exponent huge but finite, rate factor underflows to (nearly) zero, never NaN/∞.
        for dt in [1e-14, 1e-12, 1e-9, 1e-6, 1e-3, 1e-1] {
            let t = tf + dt;
            assert!(!w.is_frozen(t), "T = Tg − C2 + {dt}");
            let s = w.log10_shift(t).expect("unfrozen");
            assert!(
                s.is_finite() && s > 0.0,
                "T = Tg − C2 + {dt}: log10 a_T = {s}"
            );
            let r = w.rate_factor(t);
            assert!(
                r.is_finite() && (0.0..1.0).contains(&r),
                "T = Tg − C2 + {dt}: rate {r}"
            );
        }
        // The hot limit: log10 a_T → −C1, rate factor → 10^{C1} (finite).
        assert_eq!(w.log10_shift(Real::INFINITY), Some(-w.c1()));
        assert!(w.rate_factor(Real::INFINITY).is_finite());
        assert!(w.rate_factor(1e300) <= Real::powf(10.0, w.c1()));
    }

    #[test]
    fn rejects_bad_constants() {
        assert!(matches!(
            Wlf::try_new(0.0, 50.0, 70.0),
            Err(MaterialError::WlfC1 { .. })
        ));
        assert!(matches!(
            Wlf::try_new(301.0, 50.0, 70.0),
            Err(MaterialError::WlfC1 { .. })
        ));
        assert!(matches!(
            Wlf::try_new(Real::NAN, 50.0, 70.0),
            Err(MaterialError::WlfC1 { .. })
        ));
        assert!(matches!(
            Wlf::try_new(17.0, -1.0, 70.0),
            Err(MaterialError::WlfC2 { .. })
        ));
        assert!(matches!(
            Wlf::try_new(17.0, 1e-310, 70.0),
            Err(MaterialError::WlfC2 { .. })
        ));
        assert!(matches!(
            Wlf::try_new(17.0, 50.0, Real::NAN),
            Err(MaterialError::GlassTransition { .. })
        ));
        // The largest admissible C1 keeps the rate factor finite in the hot limit.
        let w = Wlf::try_new(MAX_C1, 1.0, 0.0).expect("C1 = MAX_C1 is valid");
        assert!(w.rate_factor(Real::MAX).is_finite());
        assert_eq!(w.log10_shift(Real::MAX), Some(-MAX_C1));
        // T − Tg overflowing to +∞ takes the hot limit, not NaN.
        let w = Wlf::try_new(17.0, 50.0, -1e308).expect("valid");
        assert_eq!(w.log10_shift(1e308), Some(-17.0));
        // The largest exponent near the freezing point: one ulp above Tg − C2 it is huge but finite.
        let w = Wlf::van_manen_2021();
        let t = Real::from_bits(w.frozen_below().to_bits() + 1); // next float up (21.57 > 0)
        let s = w.log10_shift(t).expect("unfrozen");
        assert!(s.is_finite() && s > 1e14, "{s}");
        assert_eq!(w.rate_factor(t), 0.0);
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: 512,
            rng_seed: RngSeed::Fixed(0x5713_0001),
            failure_persistence: None,
            ..ProptestConfig::default()
        })]

        /// τ(T) = τ_G 10^{log10 a_T} is strictly decreasing in T above Tg − C2 (d/dT log10 a_T =
        /// −C1 C2/(C2 + T − Tg)² < 0), the rate factor is non-decreasing everywhere, and nothing is NaN/∞.
        #[test]
        fn relaxation_time_decreases_with_temperature(
            c1 in 1.0..40.0f64,
            c2 in 10.0..200.0f64,
            tg in -50.0..200.0f64,
            a in -400.0..600.0f64,
            gap in 1e-3..50.0f64,
        ) {
            let w = Wlf::try_new(c1, c2, tg).expect("constants in range");
            let (t1, t2) = (a, a + gap);
            let (r1, r2) = (w.rate_factor(t1), w.rate_factor(t2));
            prop_assert!(r1.is_finite() && r2.is_finite() && r1 >= 0.0);
            prop_assert!(r1 <= r2, "rate factor decreased: {} at {}, {} at {}", r1, t1, r2, t2);
            if let (Some(s1), Some(s2)) = (w.log10_shift(t1), w.log10_shift(t2)) {
                prop_assert!(s1.is_finite() && s2.is_finite());
                prop_assert!(s1 > s2, "log10 a_T not decreasing: {} at {}, {} at {}", s1, t1, s2, t2);
            }
            if w.is_frozen(t2) {
                prop_assert!(w.is_frozen(t1));
            }
        }
    }
}
