//! ParaView output: the fields along the rods ([`crate::solver::PointFields`]) as VTK XML PolyData, one file
//! per saved step (`snapshots/step_NNNNN.vtp`), and the collection `run.pvd` that lists them with their
//! simulated times, so that ParaView plays a run on its own time axis.
//!
//! **What a file holds.** One polyline per patch through its collocation points (where the method computes
//! the fields: no interpolation), in the current configuration; point data: `displacement`, `rotation`
//! (rotation vector of `R R0ᵀ`), `strain` (`Γ − Γ0`: axial, shear 2, shear 3), `curvature` (`K − K0`: twist,
//! bending 2, bending 3), `force` and `moment` (material, section frame `d1, d2, d3`), `force_spatial` and
//! `moment_spatial` (global), `viscous_strain` and `viscous_curvature`, `temperature`, `log10_shift_factor`
//! (NaN where relaxation is frozen or the material has no shift), `surface_strain` (the section's most stretched fibre)
//! and `arc_length`, and with contact per obstacle `<name>` `contact_gap@<name>` (the gap: distance from the
//! surface minus the wire radius, negative in penetration; NaN on a cylinder's axis) and
//! `contact_pressure@<name>` (the line pressure per unit reference length; at the patch ends as the contact
//! report measures it, `crate::solver::terms::contact::ContactReport`), and with the wires' contact
//! `wire_contact_pressure` (the magnitude of the wires' line force on each other at the point, per unit
//! reference length); cell data `patch` and `material` (indices into the model's patches, in the order
//! `stentkit check` lists them, and into its materials: `material` first, then the named `materials`); field
//! data `TimeValue` (the simulated time, which ParaView reads) and `probe_point` (per probe of the design, in
//! `history.csv`'s order, the point it sits on; −1 for a probe between collocation points). Every point array
//! carries its
//! unit as VTK's array information key `UNITS_LABEL` (VTK's XML information format, read by VTK ≥ 7.1) and its
//! components' names (`ComponentName0…`).
//!
//! **The model as simulated.** The files hold the (possibly symmetry-reduced) model the solver ran, not the
//! mirrored full device of the STL snapshots: mirroring the material components of strains and stress
//! resultants depends on how the mirrored rod's section frame is chosen, and a field file should hold what was
//! computed. ParaView's *Reflect* filter shows the rest of the device for the scalar fields.
//!
//! **Encoding.** Inline `binary` (base64 of a UInt64 byte count followed by the little-endian values, one
//! block per array), uncompressed: about 0.5 kB per collocation point; written atomically like every run file.
//! The writer is stentkit's own on `base64` (already a dependency): vtkio's writer has no array information
//! keys, so it could not say the units.

use crate::math::{Real, Vec3};
use crate::model::Model;
use crate::solver::PointFields;
use crate::solver::terms::contact::ContactReport;
use crate::solver::terms::wires::WireContactReport;
use base64::Engine;
use std::fmt::Write as _;
use std::path::Path;

/// One point array: name, unit, component names and the values (tuple-major).
struct Array {
    name: String,
    unit: String,
    components: &'static [&'static str],
    values: Vec<Real>,
}

/// The point arrays of `fields` and of `contact` (its gap and pressure per obstacle), in the order written.
fn point_arrays(
    model: &Model,
    fields: &[PointFields],
    contact: Option<&ContactReport>,
    wires: Option<&WireContactReport>,
) -> Vec<Array> {
    let u = model.units;
    let (length, force, moment) = (u.length(), u.force(), u.moment());
    let per_length = format!("1/{length}");
    let xyz: &'static [&'static str] = &["x", "y", "z"];
    let strain_parts: &'static [&'static str] = &["axial", "shear 2", "shear 3"];
    let curvature_parts: &'static [&'static str] = &["twist", "bending 2", "bending 3"];
    let force_parts: &'static [&'static str] = &["axial", "shear 2", "shear 3"];
    let moment_parts: &'static [&'static str] = &["torque", "bending 2", "bending 3"];
    let vector = |name: &str, unit: &str, components, get: fn(&PointFields) -> Vec3| Array {
        name: name.to_string(),
        unit: unit.to_string(),
        components,
        values: fields
            .iter()
            .flat_map(|f| {
                let v = get(f);
                [v.x, v.y, v.z]
            })
            .collect(),
    };
    let scalar = |name: &str, unit: &str, get: fn(&PointFields) -> Real| Array {
        name: name.to_string(),
        unit: unit.to_string(),
        components: &[],
        values: fields.iter().map(get).collect(),
    };
    let mut arrays = vec![
        vector("displacement", length, xyz, |f| f.displacement),
        vector("rotation", "rad", xyz, |f| f.rotation),
        vector("strain", "1", strain_parts, |f| f.strain),
        vector("curvature", &per_length, curvature_parts, |f| f.curvature),
        vector("force", force, force_parts, |f| f.force),
        vector("moment", moment, moment_parts, |f| f.moment),
        vector("force_spatial", force, xyz, |f| f.force_spatial),
        vector("moment_spatial", moment, xyz, |f| f.moment_spatial),
        vector("viscous_strain", "1", strain_parts, |f| f.viscous_strain),
        vector("viscous_curvature", &per_length, curvature_parts, |f| {
            f.viscous_curvature
        }),
        scalar("temperature", "°C", |f| f.temperature),
        scalar("log10_shift_factor", "1", |f| f.log10_shift),
        scalar("surface_strain", "1", |f| f.surface_strain),
        scalar("arc_length", length, |f| f.arc_length),
    ];
    let obstacles = model.contact.iter().flat_map(|c| &c.obstacles);
    for (obstacle, o) in obstacles.zip(contact.iter().flat_map(|r| &r.obstacles)) {
        let name = super::contact::column_name(obstacle);
        for (quantity, unit, values) in [
            ("gap", length.to_string(), &o.gap),
            ("pressure", format!("{force}/{length}"), &o.pressure),
        ] {
            arrays.push(Array {
                name: format!("contact_{quantity}@{name}"),
                unit,
                components: &[],
                values: values.clone(),
            });
        }
    }
    if let Some(w) = wires {
        arrays.push(Array {
            name: "wire_contact_pressure".into(),
            unit: format!("{force}/{length}"),
            components: &[],
            values: w.line_force.clone(),
        });
    }
    arrays
}

/// Base64 of a UInt64 byte count followed by the little-endian bytes of `bytes` (VTK's inline binary block).
fn binary_block(bytes: &[u8]) -> String {
    let mut raw = Vec::with_capacity(8 + bytes.len());
    raw.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
    raw.extend_from_slice(bytes);
    base64::engine::general_purpose::STANDARD.encode(raw)
}

/// [`binary_block`] of `values`, each as its little-endian bytes (`to_le`: `f64::to_le_bytes`, …).
fn le_block<T: Copy, const N: usize>(values: &[T], to_le: fn(T) -> [u8; N]) -> String {
    binary_block(&values.iter().flat_map(|&v| to_le(v)).collect::<Vec<u8>>())
}

fn f64_block(values: &[Real]) -> String {
    le_block(values, f64::to_le_bytes)
}

/// Escapes the five XML special characters of an attribute or text value (also for the 3MF writer).
pub(crate) fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
}

/// The VTK XML PolyData text of `fields` (from [`crate::solver::Simulation::point_fields`], patch by patch) at
/// time `time` (module docs).
pub fn polydata(
    model: &Model,
    fields: &[PointFields],
    contact: Option<&ContactReport>,
    wires: Option<&WireContactReport>,
    probe_points: &[Option<usize>],
    time: Real,
) -> String {
    // Patches in the order of the points, each a polyline of its points.
    let mut offsets: Vec<i64> = Vec::new();
    let mut patches: Vec<i32> = Vec::new();
    for (k, f) in fields.iter().enumerate() {
        if k > 0 && fields[k - 1].patch != f.patch {
            offsets.push(k as i64);
        }
        if k == 0 || fields[k - 1].patch != f.patch {
            patches.push(f.patch as i32);
        }
    }
    if !fields.is_empty() {
        offsets.push(fields.len() as i64);
    }
    let materials: Vec<i32> = patches
        .iter()
        .map(|&k| model.patches[k as usize].material as i32)
        .collect();
    let connectivity: Vec<i64> = (0..fields.len() as i64).collect();
    let points: Vec<Real> = fields
        .iter()
        .flat_map(|f| [f.position.x, f.position.y, f.position.z])
        .collect();
    let mut x = String::new();
    // Writing to a String cannot fail.
    let _ = writeln!(x, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        x,
        "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
    );
    let _ = writeln!(x, "  <PolyData>");
    let _ = writeln!(x, "    <FieldData>");
    let _ = writeln!(
        x,
        "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">{time:e}</DataArray>"
    );
    let probes: Vec<i64> = probe_points
        .iter()
        .map(|p| p.map_or(-1, |g| g as i64))
        .collect();
    if !probes.is_empty() {
        let _ = writeln!(
            x,
            "      <DataArray type=\"Int64\" Name=\"probe_point\" NumberOfTuples=\"{}\" format=\"binary\">\n        {}\n      </DataArray>",
            probes.len(),
            le_block(&probes, i64::to_le_bytes)
        );
    }
    let _ = writeln!(x, "    </FieldData>");
    let _ = writeln!(
        x,
        "    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"{}\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">",
        fields.len(),
        patches.len()
    );
    let _ = writeln!(
        x,
        "      <PointData Vectors=\"displacement\" Scalars=\"surface_strain\">"
    );
    for array in point_arrays(model, fields, contact, wires) {
        let count = array.components.len().max(1);
        let _ = write!(
            x,
            "        <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{count}\"",
            escape(&array.name)
        );
        for (i, c) in array.components.iter().enumerate() {
            let _ = write!(x, " ComponentName{i}=\"{}\"", escape(c));
        }
        let _ = writeln!(x, " format=\"binary\">");
        let _ = writeln!(x, "          {}", f64_block(&array.values));
        let _ = writeln!(
            x,
            "          <InformationKey name=\"UNITS_LABEL\" location=\"vtkDataArray\">{}</InformationKey>",
            escape(&array.unit)
        );
        let _ = writeln!(x, "        </DataArray>");
    }
    let _ = writeln!(x, "      </PointData>");
    let _ = writeln!(x, "      <CellData Scalars=\"patch\">");
    for (name, values) in [("patch", &patches), ("material", &materials)] {
        let _ = writeln!(
            x,
            "        <DataArray type=\"Int32\" Name=\"{name}\" format=\"binary\">\n          {}\n        </DataArray>",
            le_block(values, i32::to_le_bytes)
        );
    }
    let _ = writeln!(x, "      </CellData>");
    let _ = writeln!(
        x,
        "      <Points>\n        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"binary\">\n          {}\n          <InformationKey name=\"UNITS_LABEL\" location=\"vtkDataArray\">{}</InformationKey>\n        </DataArray>\n      </Points>",
        f64_block(&points),
        model.units.length()
    );
    let _ = writeln!(
        x,
        "      <Lines>\n        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"binary\">\n          {}\n        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"binary\">\n          {}\n        </DataArray>\n      </Lines>",
        le_block(&connectivity, i64::to_le_bytes),
        le_block(&offsets, i64::to_le_bytes)
    );
    let _ = writeln!(x, "    </Piece>");
    let _ = writeln!(x, "  </PolyData>");
    let _ = writeln!(x, "</VTKFile>");
    x
}

/// Writes [`polydata`] to `path`, atomically.
///
/// # Errors
/// The I/O error; the target is then left as it was.
pub fn write_polydata(
    path: &Path,
    model: &Model,
    fields: &[PointFields],
    contact: Option<&ContactReport>,
    wires: Option<&WireContactReport>,
    probe_points: &[Option<usize>],
    time: Real,
) -> std::io::Result<()> {
    super::atomic::write_bytes_atomically(
        path,
        polydata(model, fields, contact, wires, probe_points, time).as_bytes(),
    )
}

/// The text of a ParaView collection (`.pvd`) of `entries`: `(time, file relative to the collection)`.
pub fn collection(entries: &[(Real, String)]) -> String {
    let mut x = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (time, file) in entries {
        let _ = writeln!(
            x,
            "    <DataSet timestep=\"{time:e}\" group=\"\" part=\"0\" file=\"{}\"/>",
            escape(file)
        );
    }
    x.push_str("  </Collection>\n</VTKFile>\n");
    x
}

/// Writes [`collection`] to `path`, atomically.
///
/// # Errors
/// The I/O error; the target is then left as it was.
pub fn write_collection(path: &Path, entries: &[(Real, String)]) -> std::io::Result<()> {
    super::atomic::write_bytes_atomically(path, collection(entries).as_bytes())
}

/// The `(time, file)` entries of a collection's text as [`write_collection`] writes it (the times in full).
pub fn collection_entries(text: &str) -> Vec<(Real, String)> {
    let attribute = |line: &str, name: &str| -> Option<String> {
        Some(
            line.split(&format!("{name}=\""))
                .nth(1)?
                .split('"')
                .next()?
                .to_string(),
        )
    };
    text.lines()
        .filter_map(|line| {
            let time = attribute(line, "timestep")?.parse().ok()?;
            Some((time, attribute(line, "file")?))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A collection read back gives its entries, the times to the bit (`stentkit repair` takes a snapshot's
    /// time from it: history.csv's 11 digits would round 0.5000000000000003 to 0.5).
    #[test]
    fn a_collection_reads_back_to_its_entries() {
        let entries = vec![
            (0.0, "snapshots/t0.000_initial.vtp".to_string()),
            (
                0.5000000000000003,
                "snapshots/t0.500_programming.vtp".to_string(),
            ),
        ];
        assert_eq!(collection_entries(&collection(&entries)), entries);
    }

    /// Source: VTK's XML format (header UInt64 little-endian byte count, then the data, base64 together).
    #[test]
    fn a_binary_block_is_the_byte_count_then_the_values() {
        let block = f64_block(&[1.0, -2.5]);
        let raw = base64::engine::general_purpose::STANDARD
            .decode(block)
            .expect("base64");
        assert_eq!(raw.len(), 8 + 16);
        assert_eq!(u64::from_le_bytes(raw[..8].try_into().expect("8")), 16);
        assert_eq!(f64::from_le_bytes(raw[8..16].try_into().expect("8")), 1.0);
        assert_eq!(f64::from_le_bytes(raw[16..].try_into().expect("8")), -2.5);
    }

    #[test]
    fn a_collection_lists_times_and_files_in_order() {
        let text = collection(&[
            (0.0, "snapshots/step_00000.vtp".into()),
            (1.5, "snapshots/step_00010.vtp".into()),
        ]);
        let a = text.find("timestep=\"0e0\"").expect("first");
        let b = text.find("timestep=\"1.5e0\"").expect("second");
        assert!(a < b);
        assert!(text.contains("file=\"snapshots/step_00010.vtp\""));
    }
}
