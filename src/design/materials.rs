//! A design's materials: the `material` block and the named `materials`, validated by the material
//! constructors with their errors located at the design's fields, and material names resolved to the model's
//! indices (for patches and stent parts).

use super::dto::*;
use super::issue::{Issue, Result, issue};
use crate::material::{Integrator, Material, MaterialError, MaterialLaw, Prony, PronyBranch, Wlf};
use crate::model::builder::{DEFAULT_MATERIAL_NAME, ModelBuilder};

/// The design's material, validated once, by the material constructors ([`Prony::try_new`], [`Wlf::try_new`],
/// [`Material::try_new`]); their errors are mapped to the design's fields by [`material_issue`].
pub(super) fn material(m: &MaterialDto, base: &str) -> Result<(Material, Integrator)> {
    let branches = m
        .prony
        .iter()
        .map(|[Finite(e), Finite(tau)]| PronyBranch {
            modulus: *e,
            tau_g: *tau,
        })
        .collect();
    let prony = Prony::try_new(m.e_inf.0, branches).map_err(|e| material_issue(e, base))?;
    let wlf = m
        .wlf
        .as_ref()
        .map(|w| Wlf::try_new(w.c1.0, w.c2.0, w.tg.0))
        .transpose();
    let material = match wlf {
        Ok(wlf) => Material::try_new(prony, m.nu.0, wlf),
        // ν precedes the WLF constants in a design and is reported first.
        Err(e) => Material::try_new(prony, m.nu.0, None).and(Err(e)),
    }
    .map_err(|e| material_issue(e, base))?;
    let integrator = match m.integrator {
        None | Some(IntegratorDto::Trapezoidal) => Integrator::Trapezoidal,
        Some(IntegratorDto::BackwardEuler) => Integrator::BackwardEuler,
        Some(IntegratorDto::Exponential) => Integrator::Exponential,
    };
    Ok((material, integrator))
}

/// The design field a material constructor's error is about (`material.prony[k][0]`, `material.wlf.C2`, …),
/// with the constructor's message. Errors count Prony branches `α` from 1, the design's list from 0.
fn material_issue(e: MaterialError, base: &str) -> Issue {
    let path = match e {
        MaterialError::BranchModulus { branch, .. } => format!("{base}.prony[{}][0]", branch - 1),
        MaterialError::BranchRelaxationTime { branch, .. } => {
            format!("{base}.prony[{}][1]", branch - 1)
        }
        MaterialError::EquilibriumModulus { .. } | MaterialError::InstantaneousModulus { .. } => {
            format!("{base}.E_inf")
        }
        MaterialError::PoissonRatio { .. } => format!("{base}.nu"),
        MaterialError::WlfC1 { .. } => format!("{base}.wlf.C1"),
        MaterialError::WlfC2 { .. } => format!("{base}.wlf.C2"),
        MaterialError::GlassTransition { .. } => format!("{base}.wlf.Tg"),
        _ => base.into(),
    };
    issue(path, e.to_string())
}

/// Adds the design's `materials` to the builder; returns every material's name in model order (`material`'s
/// first).
pub(super) fn named_materials(dto: &DesignDto, builder: &mut ModelBuilder) -> Result<Vec<String>> {
    let mut names = vec![
        dto.material
            .name
            .clone()
            .unwrap_or_else(|| DEFAULT_MATERIAL_NAME.to_string()),
    ];
    for (k, m) in dto.materials.iter().enumerate() {
        let base = format!("materials[{k}]");
        let Some(name) = &m.name else {
            return Err(issue(
                format!("{base}.name"),
                "missing: every entry of `materials` needs a `name` for patches and stent parts to refer to",
            ));
        };
        if names.contains(name) {
            return Err(issue(
                format!("{base}.name"),
                format!("a material named `{name}` exists already: names must be unique"),
            ));
        }
        let (material, integrator) = material(m, &base)?;
        builder.named_material(
            name.clone(),
            MaterialLaw::from_material(material, integrator),
        );
        names.push(name.clone());
    }
    Ok(names)
}

/// The index of the material named `name`, or an error at `path` listing the names there are.
pub(super) fn material_index(name: &str, names: &[String], path: &str) -> Result<usize> {
    names.iter().position(|n| n == name).ok_or_else(|| {
        issue(
            path,
            format!(
                "no material is named `{name}`; the design has {}",
                names
                    .iter()
                    .map(|n| format!("`{n}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )
    })
}
