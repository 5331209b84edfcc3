//! The materials at the collocation points: each patch's points use that patch's material
//! ([`crate::model::Patch::material`]); the solver calls the constitutive interface
//! ([`crate::material::ConstitutiveLaw`]) once per material for a step's preparation, its commit and a
//! roll-back, and keeps the [`SectionLaw`] of every point for the assembly (paper §3.1).

use super::{Simulation, SolverTiming};
use crate::material::{ConstitutiveLaw, MaterialLaw, MaterialState, SectionLaw, StepInput};
use crate::math::Real;
use crate::math::Vec3;
use crate::model::Model;
use crate::solver::SolverError;
use crate::solver::assembly::{StepMaterial, point_position, point_strains};
use crate::solver::discretisation::Discretisation;
use rayon::prelude::*;
use std::time::Instant;

/// The points of one material and their state.
#[derive(Debug, Clone)]
pub(super) struct MaterialPoints {
    /// Index into [`Model::materials`].
    pub(super) material: usize,
    /// The global collocation points made of it, ascending (point `i` of the state is `points[i]`).
    pub(super) points: Vec<usize>,
    /// The law's internal variables at those points.
    pub(super) state: MaterialState,
}

/// Every material's points and state, and the section law of every collocation point for the step being solved
/// (or the last converged step).
#[derive(Debug, Clone)]
pub(super) struct PointMaterials {
    /// One entry per material that some patch uses, in material order.
    pub(super) groups: Vec<MaterialPoints>,
    /// The section law per global collocation point.
    pub(super) laws: Vec<SectionLaw>,
    /// Per global collocation point: its group in `groups` and its index there.
    owner: Vec<(usize, usize)>,
    /// The notices said, as `(material, kind)` ([`crate::material::MaterialNotice::kind`]): each once.
    pub(super) said: Vec<(usize, String)>,
    /// Per global collocation point, its reference position and unit reference tangent, where the model has a
    /// temperature field (empty otherwise).
    places: Vec<(Vec3, Vec3)>,
}

/// Calls `f` with the input of the step `t_n → t_np1` for the points `points` (global indices) of one material:
/// the model's temperature schedule and, with a temperature field, `(T, T,s)` at each of those points.
pub(super) fn with_step_input<R>(
    model: &Model,
    places: &[(Vec3, Vec3)],
    points: &[usize],
    (t_n, t_np1): (Real, Real),
    f: impl FnOnce(&StepInput<'_>) -> R,
) -> R {
    let temperature = |t: Real| model.temperature().value(t);
    match &model.temperature_field {
        Some(field) => {
            let at = |i: usize, t: Real| {
                let (position, tangent) = &places[points[i]];
                field.at(position, tangent, t)
            };
            f(&StepInput {
                t_n,
                t_np1,
                temperature: &temperature,
                field: Some(&at),
            })
        }
        None => f(&StepInput {
            t_n,
            t_np1,
            temperature: &temperature,
            field: None,
        }),
    }
}

/// The reference position and unit tangent `X,s` (the first column of `R0`) of every collocation point.
fn reference_places(disc: &Discretisation) -> Vec<(Vec3, Vec3)> {
    (0..disc.points.len())
        .map(|g| {
            (
                point_position(disc, &disc.control0, g),
                disc.points[g].rotation0.column(0).into_owned(),
            )
        })
        .collect()
}

impl PointMaterials {
    /// The states of the model's materials at rest, and their laws before the first step.
    pub(super) fn new(model: &Model, disc: &Discretisation) -> Self {
        let mut groups: Vec<MaterialPoints> = Vec::new();
        for (material, law) in model.materials().iter().enumerate() {
            let points: Vec<usize> = (0..disc.points.len())
                .filter(|&g| model.patches[disc.points[g].patch].material == material)
                .collect();
            if points.is_empty() {
                continue;
            }
            let shapes = points
                .iter()
                .map(|&g| disc.shapes[disc.points[g].shape])
                .collect();
            groups.push(MaterialPoints {
                material,
                state: law.new_state(shapes),
                points,
            });
        }
        let mut owner = vec![(0, 0); disc.points.len()];
        for (k, group) in groups.iter().enumerate() {
            for (i, &g) in group.points.iter().enumerate() {
                owner[g] = (k, i);
            }
        }
        let mut out = Self {
            groups,
            laws: vec![SectionLaw::default(); disc.points.len()],
            owner,
            said: Vec::new(),
            places: if model.temperature_field.is_some() {
                reference_places(disc)
            } else {
                Vec::new()
            },
        };
        out.refresh_laws(model.materials());
        out
    }

    /// Reads every point's section law from its material's state (in parallel over points).
    pub(super) fn refresh_laws(&mut self, materials: &[MaterialLaw]) {
        let groups = &self.groups;
        self.laws
            .par_iter_mut()
            .zip(&self.owner)
            .for_each(|(law, &(k, i))| {
                let group = &groups[k];
                *law = materials[group.material].section_law(&group.state, i);
            });
    }

    /// Per global collocation point, its reference position and unit tangent (empty without a temperature
    /// field).
    pub(super) fn places(&self) -> &[(Vec3, Vec3)] {
        &self.places
    }

    /// The viscous strains of global point `g` at the last converged step
    /// ([`ConstitutiveLaw::viscous_strains`]); `None` for a law without internal variables.
    pub(super) fn viscous_strains(
        &self,
        materials: &[MaterialLaw],
        g: usize,
    ) -> Option<(Vec3, Vec3)> {
        let (k, i) = self.owner[g];
        let group = &self.groups[k];
        materials[group.material].viscous_strains(&group.state, i)
    }

    /// Every material back to the data of its last converged step.
    pub(super) fn roll_back(&mut self, materials: &[MaterialLaw]) {
        for group in &mut self.groups {
            materials[group.material].roll_back(&mut group.state);
        }
        self.refresh_laws(materials);
    }
}

impl Simulation<'_> {
    /// Prepares the constitutive data of the step `t_n → t_np1` (paper §3.1) for every material: its step
    /// coefficients, effective modulus and history stresses per point (the Ψ-terms of N/M_constitutive_disc for
    /// the Maxwell law), then every point's section law. A material's notice is said once per kind.
    pub(super) fn prepare_step(&mut self, t_n: Real, t_np1: Real) -> Result<(), SolverError> {
        let start = Instant::now();
        let model = self.model;
        let materials = &mut self.materials;
        for group in &mut materials.groups {
            let notice = with_step_input(
                model,
                &materials.places,
                &group.points,
                (t_n, t_np1),
                |step| model.materials()[group.material].prepare_step(&mut group.state, step),
            )?;
            if let Some(notice) = notice {
                let key = (group.material, notice.kind().to_string());
                if !materials.said.contains(&key) {
                    materials.said.push(key);
                    self.record.notices.push(notice.to_string());
                }
            }
        }
        materials.refresh_laws(model.materials());
        SolverTiming::add(&mut self.record.timing.material, start);
        for term in &mut self.terms {
            let start = Instant::now();
            term.prepare(&self.disc, &self.solution.state, t_np1);
            (self.record.timing).add_term(term.name(), start.elapsed().as_secs_f64());
        }
        Ok(())
    }

    /// After a converged step: every material advances its internal variables with the converged strains of
    /// its points.
    pub(super) fn commit_step(&mut self) {
        let start = Instant::now();
        let (disc, state) = (&self.disc, &self.solution.state);
        for group in &mut self.materials.groups {
            let points = &group.points;
            let strains = |i: usize| point_strains(disc, state, points[i]);
            self.model.materials()[group.material].commit_step(&mut group.state, &strains);
        }
        // Counted with the step's preparation.
        self.record.timing.material.1 += start.elapsed().as_secs_f64();
        // The point terms' state after the materials' (module docs of `crate::solver::terms`).
        for term in &mut self.terms {
            let start = Instant::now();
            term.commit(disc, state);
            (self.record.timing).add_term(term.name(), start.elapsed().as_secs_f64());
        }
    }

    /// With a temperature field: the lowest and highest temperature over the collocation points at time `t`
    /// \[°C\]; `None` when the temperature is uniform.
    pub fn temperature_extremes(&self, t: Real) -> Option<(Real, Real)> {
        let field = self.model.temperature_field.as_ref()?;
        Some(self.materials.places.iter().fold(
            (Real::INFINITY, Real::NEG_INFINITY),
            |(lo, hi), (position, tangent)| {
                let value = field.at(position, tangent, t).0;
                (lo.min(value), hi.max(value))
            },
        ))
    }

    /// The constitutive data of the current (or last solved) step: every point's section law.
    pub(super) fn step_material(&self) -> StepMaterial<'_> {
        StepMaterial {
            laws: &self.materials.laws,
        }
    }
}
