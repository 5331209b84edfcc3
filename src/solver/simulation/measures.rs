//! What a simulation measures once on its model and discretisation and never changes: the lengths that
//! normalise increments, the schedule breakpoints, and (at their first use) the reference arc length and the
//! trapezoidal weights of the collocation points.

use crate::math::Real;
use crate::model::Model;
use crate::solver::discretisation::Discretisation;
use std::sync::OnceLock;

/// The increment norm's length of a patch whose ends coincide (a closed loop) is its chord floored at this
/// fraction of the model size: a translation increment is measured against a length of the order of the
/// patch, never against zero.
const CLOSED_PATCH_LENGTH_FRACTION: Real = 1e-3;

/// The simulation's fixed measures of its model (module docs): a part that no step changes, so neither a
/// roll-back nor a checkpoint saves it.
#[derive(Debug)]
pub(super) struct Measures {
    /// Length of the patch of each control point, for increment norms.
    pub(super) control_length: Vec<Real>,
    /// The schedule breakpoints the steps land on ([`Model::schedule_breakpoints`]), sorted.
    pub(super) breakpoints: Vec<Real>,
    /// The record times an error-controlled run reaches by its continuous extension (module `dense`), sorted;
    /// empty for a fixed-step run, whose steps land on them.
    pub(super) requested: Vec<Real>,
    /// Reference arc length of every collocation point from its patch's start, for the fields
    /// ([`super::fields`]): computed at the first use (a run without field outputs never needs it).
    arc_length: OnceLock<Vec<Real>>,
    /// Trapezoidal weights of the collocation points in the reference arc length (computed at the first use).
    point_weights: OnceLock<Vec<Real>>,
}

impl Measures {
    /// The measures of `model` discretised as `disc` (the lazy ones not yet computed).
    pub(super) fn new(model: &Model, disc: &Discretisation) -> Self {
        let control_length = disc
            .patches
            .iter()
            .flat_map(|r| {
                let length = (disc.control0[r.offset + r.n - 1] - disc.control0[r.offset]).norm();
                // Chord length, floored by the model size for closed patches.
                std::iter::repeat_n(
                    length.max(CLOSED_PATCH_LENGTH_FRACTION * disc.length_scale),
                    r.n,
                )
            })
            .collect();
        Self {
            control_length,
            breakpoints: model.schedule_breakpoints(),
            requested: if model.time().tolerance.is_some() {
                model.record_times().to_vec()
            } else {
                Vec::new()
            },
            arc_length: OnceLock::new(),
            point_weights: OnceLock::new(),
        }
    }

    /// The reference arc length of every collocation point from its patch's start
    /// ([`super::fields::arc_lengths`], computed once).
    pub(super) fn arc_lengths(&self, model: &Model, disc: &Discretisation) -> &[Real] {
        self.arc_length
            .get_or_init(|| super::fields::arc_lengths(model, disc))
    }

    /// Trapezoidal weights of the collocation points in the reference arc length, patch by patch (computed
    /// once).
    pub(super) fn point_weights(&self, model: &Model, disc: &Discretisation) -> &[Real] {
        self.point_weights.get_or_init(|| {
            let s = self.arc_lengths(model, disc);
            let mut w = vec![0.0; s.len()];
            for range in &disc.patches {
                for g in range.offset..range.offset + range.n {
                    let before = if g > range.offset {
                        s[g] - s[g - 1]
                    } else {
                        0.0
                    };
                    let after = if g + 1 < range.offset + range.n {
                        s[g + 1] - s[g]
                    } else {
                        0.0
                    };
                    w[g] = 0.5 * (before + after);
                }
            }
            w
        })
    }
}
