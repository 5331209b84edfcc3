//! Sample centrelines and settings shared by the geometry modules' tests.

use std::f64::consts::PI;

use super::tube::TubeSettings;
use crate::math::{Mat3, Real, Vec3};

/// `sin(2π/x) / (2π/x)`: the area of the regular x-gon inscribed in a circle over the circle's area.
pub(crate) fn polygon_factor(x: usize) -> Real {
    let a = 2.0 * PI / x as Real;
    a.sin() / a
}

/// Samples `0, L/(n−1), …, L` along `axis` from `origin`, with the frame `rotation` (columns d1, d2, d3)
/// at every sample.
pub(crate) fn straight(
    origin: Vec3,
    rotation: &Mat3,
    length: Real,
    n: usize,
) -> (Vec<Vec3>, Vec<Mat3>) {
    let axis = rotation.column(0).into_owned();
    let centre = (0..n)
        .map(|i| origin + axis * (length * i as Real / (n - 1) as Real))
        .collect();
    (centre, vec![*rotation; n])
}

/// A full circle of radius `big_r` in the xy plane, `segments` chords (first sample repeated at the
/// end), with the analytic frame d1 = e_θ, d2 = e_r, d3 = d1 × d2 = −e_z.
pub(crate) fn ring(big_r: Real, segments: usize) -> (Vec<Vec3>, Vec<Mat3>) {
    (0..=segments)
        .map(|i| {
            let (s, c) = (2.0 * PI * i as Real / segments as Real).sin_cos();
            let (e_r, e_t) = (Vec3::new(c, s, 0.0), Vec3::new(-s, c, 0.0));
            (
                big_r * e_r,
                Mat3::from_columns(&[e_t, e_r, e_t.cross(&e_r)]),
            )
        })
        .unzip()
}

/// `n` samples of the helix `(R cos t, R sin t, h t)`, `t ∈ [0, turns·2π]`.
pub(crate) fn helix(big_r: Real, h: Real, turns: Real, n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|i| {
            let t = turns * 2.0 * PI * i as Real / (n - 1) as Real;
            Vec3::new(big_r * t.cos(), big_r * t.sin(), h * t)
        })
        .collect()
}

/// Numbers in scientific notation, for the measured-value printouts.
pub(crate) fn sci(values: &[Real]) -> String {
    let parts: Vec<String> = values.iter().map(|v| format!("{v:.3e}")).collect();
    format!("[{}]", parts.join(", "))
}

pub(crate) fn settings(m: usize) -> TubeSettings {
    TubeSettings {
        segments_around: m,
        ..TubeSettings::default()
    }
}

/// Negates d3 (and keeps d1, d2), so that d2 × d3 = −d1: a left-handed frame.
pub(crate) fn flip_d3(f: &Mat3) -> Mat3 {
    Mat3::from_columns(&[
        f.column(0).into_owned(),
        f.column(1).into_owned(),
        -f.column(2).into_owned(),
    ])
}
