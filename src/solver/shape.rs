//! Sampled shapes of the rods for drawing: centreline points and section frames along every patch, in the
//! reference or the current configuration.
//!
//! Positions are the spline `c(u) = Σ N_j(u) p_j` at uniformly spaced parameters. Section frames live at the
//! collocation points; between two neighbouring collocation points `u_a < u < u_b` the frame is interpolated
//! along the geodesic of SO(3), `R(u) = R_a exp(t log(R_aᵀ R_b))`, `t = (u − u_a)/(u_b − u_a)` (exact at the
//! collocation points, and free of the wrap-around of interpolated rotation vectors for rods rolled past π).

use super::Simulation;
use super::discretisation::Discretisation;
use crate::math::basis::nurbs_basis;
use crate::math::so3::{exp, log};
use crate::math::{Mat3, NurbsCurve, Real, Rot3, Vec3};

/// A patch sampled for drawing.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchShape {
    /// Centreline points.
    pub points: Vec<Vec3>,
    /// Section frames (columns `d1, d2, d3`) at the points.
    pub frames: Vec<Mat3>,
}

/// The parameters `0, 1/m, …, 1` for `m = samples_per_point · n` samples.
fn parameters(curve: &NurbsCurve, samples_per_point: usize) -> Vec<Real> {
    let m = (samples_per_point.max(1) * curve.num_points()).max(1);
    (0..=m).map(|k| k as Real / m as Real).collect()
}

/// The frame at `u` interpolated between the collocation points of patch `patch` (rotations `rotations`).
fn frame_at(disc: &Discretisation, rotations: &[Mat3], patch: usize, u: Real) -> Mat3 {
    let range = &disc.patches[patch];
    let points = &disc.points[range.offset..range.offset + range.n];
    // Collocation parameters increase along the patch; find the interval holding u.
    let b = points.partition_point(|p| p.u <= u).clamp(1, range.n - 1);
    let a = b - 1;
    let (ua, ub) = (points[a].u, points[b].u);
    let t = if ub > ua {
        ((u - ua) / (ub - ua)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (ra, rb) = (rotations[range.offset + a], rotations[range.offset + b]);
    let relative = log(&Rot3::from_matrix_unchecked(ra.transpose() * rb));
    ra * exp(&(relative * t)).matrix()
}

/// Samples every patch of the simulation in its current configuration.
pub(crate) fn current_shapes(sim: &Simulation<'_>, samples_per_point: usize) -> Vec<PatchShape> {
    shapes(
        sim.discretisation(),
        sim.model(),
        &sim.state().control,
        &sim.state().rotation,
        samples_per_point,
    )
}

fn shapes(
    disc: &Discretisation,
    model: &crate::model::Model,
    control: &[Vec3],
    rotations: &[Mat3],
    samples_per_point: usize,
) -> Vec<PatchShape> {
    model
        .patches
        .iter()
        .enumerate()
        .map(|(k, patch)| {
            let curve = &patch.curve;
            let offset = disc.patches[k].offset;
            let us = parameters(curve, samples_per_point);
            let points = us
                .iter()
                .map(|&u| {
                    let table = nurbs_basis(curve.knots(), curve.weights(), u, 0);
                    table.ders[0]
                        .iter()
                        .enumerate()
                        .map(|(a, n)| control[offset + table.first + a] * *n)
                        .sum()
                })
                .collect();
            let frames = us
                .iter()
                .map(|&u| frame_at(disc, rotations, k, u))
                .collect();
            PatchShape { points, frames }
        })
        .collect()
}
