//! Vessel centrelines from files: the polylines a clinician's pipeline hands over (VMTK, 3D Slicer's VMTK
//! extension, SimVascular), with the local lumen radius where the file has it.
//!
//! | extension | format | radius |
//! |---|---|---|
//! | `.vtp` | VTK XML PolyData: `Lines` cells, any point array as the radius (VMTK: `MaximumInscribedSphereRadius`); arrays `ascii`, `binary` (base64, header `UInt32` or `UInt64`, zlib-compressed or not) or `appended` (`raw` or `base64`); several pieces | the named point array |
//! | `.vtk` | legacy VTK POLYDATA, ASCII or binary (big-endian), `LINES` in the classic (`n size` with counts) or the VTK ≥ 9 (`OFFSETS`/`CONNECTIVITY`) layout; the radius as `SCALARS` or a `FIELD` array | the named point array |
//! | `.pth` | SimVascular path: the `pos` of every `path_point` of every `path` | none |
//! | `.csv` | `x,y,z[,radius]` with an optional header, `#` comments; one polyline | the fourth column |
//!
//! The XML formats are read with quick-xml, base64 and flate2; the binary layout follows VTK's
//! `vtkXMLDataReader` (a header of `UInt32`/`UInt64` words — the byte count, or for compressed data the block
//! count, block size, last block size and each block's compressed size — before the data; VTK writes a base64
//! header and its data as separate streams, which are decoded piece by piece at each padding). vtkio (0.6.3 and
//! 0.7.0-rc2) was tried first and refuses VMTK's files. Every file VTK's own writers make from the aorta
//! centreline in each encoding reads here to the values VTK's reader gives (tests/data/centrelines/).
//!
//! A file is refused with its path and what is wrong: not the format its extension says, no polyline, a point
//! that is not finite, a cell that names a point the file does not have, the radius array missing (when one is
//! asked for; the arrays it does have are listed) or not positive.
//!
//! **Limits.** What reading a file may cost is bounded before it is paid: only a regular file is read (a
//! device such as `/dev/zero` or `/dev/urandom` never ends, a FIFO blocks until someone writes), of at most
//! [`MAX_CENTRELINE_BYTES`]; a file holds at most [`MAX_CENTRELINE_POINTS`]; and a compressed array is
//! inflated no further than its header declares, which must not exceed what the array needs for the points
//! (or cells) the file declares — a zlib block of a few hundred kilobytes can inflate to gigabytes.

use crate::io::input::{InputError, read_regular_file};
use crate::math::{Real, Vec3};
use std::path::{Path, PathBuf};

/// One polyline of a file, in its point order.
#[derive(Debug, Clone, PartialEq)]
pub struct Polyline {
    /// The points [the file's length unit].
    pub points: Vec<Vec3>,
    /// The lumen radius at each point, when the file has it.
    pub radius: Option<Vec<Real>>,
}

impl Polyline {
    /// Length of the polyline [the file's length unit].
    pub fn length(&self) -> Real {
        self.points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
    }
}

/// Largest centreline file stentkit reads \[bytes\]: 4 MiB, the limit of a design file
/// (`crate::design::guard::MAX_DESIGN_BYTES`). VMTK's aorta centreline (409 points, zlib-compressed) is
/// 15 kB; 4 MiB holds about 150 000 points as CSV (5 decimals, 28 bytes a row) and 262 144 in VTK's default
/// inline base64 `Float32` encoding. The file is read once into memory (parsing adds a few times its size), so
/// the limit also bounds what reading costs.
pub const MAX_CENTRELINE_BYTES: u64 = 4 * 1024 * 1024;

/// Most points a centreline file may hold, in all its pieces and polylines: 2¹⁸ (262 144), as many as a
/// file of [`MAX_CENTRELINE_BYTES`] holds in VTK's default encoding (inline base64 `Float32`, 16 bytes a
/// point); a CSV of that size holds about 150 000 (5 decimals). VMTK's centrelines have hundreds to a few
/// thousand points (the aorta's 409). A compressed file could claim any number: this bounds what its arrays
/// inflate to (6 MiB of `Float64` points) and what smoothing them costs (the fit is linear in the points: a
/// segment of 2¹⁸ noisy points is refused as too tight in about 4 s, 2²⁰ took 16 s).
pub const MAX_CENTRELINE_POINTS: usize = 1 << 18;

/// Why a centreline file was refused.
#[derive(Debug, thiserror::Error)]
pub enum CentrelineError {
    /// The file could not be read.
    #[error("{}: cannot read the centreline: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// The file's content is not a usable centreline.
    #[error("{}: {message}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// Reads the polylines of the centreline file at `path` (module docs), the radius from the point array
/// `radius_array` (`.vtp`, `.vtk`) when given.
///
/// # Errors
/// [`CentrelineError`] naming the file and what is wrong.
pub fn read_centreline(
    path: &Path,
    radius_array: Option<&str>,
) -> Result<Vec<Polyline>, CentrelineError> {
    let invalid = |message: String| CentrelineError::Invalid {
        path: path.to_path_buf(),
        message,
    };
    let bytes = read_regular_file(path, MAX_CENTRELINE_BYTES).map_err(|e| match e {
        InputError::Io(source) => CentrelineError::Read {
            path: path.to_path_buf(),
            source,
        },
        InputError::NotRegular(what) => invalid(format!(
            "{what}, not a regular file: a centreline is read from a file of at most {} MiB",
            MAX_CENTRELINE_BYTES >> 20
        )),
        InputError::TooLarge(bytes) => invalid(format!(
            "the file has {bytes} bytes ({:.1} MiB), more than stentkit's limit of {} MiB ({MAX_CENTRELINE_BYTES} bytes) for a centreline file; a VMTK centreline is tens of kB",
            bytes as f64 / (1024.0 * 1024.0),
            MAX_CENTRELINE_BYTES >> 20
        )),
    })?;
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let result = match extension.as_deref() {
        Some("vtp") => vtp::read(&bytes, radius_array),
        Some("vtk") => legacy::read(&bytes, radius_array),
        Some("pth") => read_pth(&bytes),
        Some("csv") => read_csv(&bytes),
        _ => Err("unknown centreline format: give a .vtp, .vtk, .pth or .csv file".to_string()),
    };
    result
        .and_then(|polylines| validate(polylines, radius_array))
        .map_err(invalid)
}

/// Checks what every format must give: at least one polyline of two points or more, finite points, and the
/// radius (when asked for) finite and positive.
fn validate(polylines: Vec<Polyline>, radius_array: Option<&str>) -> Result<Vec<Polyline>, String> {
    if polylines.iter().all(|p| p.points.len() < 2) {
        return Err("no polyline of two or more points (a centreline needs `Lines` cells)".into());
    }
    let total: usize = polylines.iter().map(|p| p.points.len()).sum();
    if total > MAX_CENTRELINE_POINTS {
        return Err(format!(
            "the polylines hold {total} points, more than stentkit's limit of {MAX_CENTRELINE_POINTS} for a centreline"
        ));
    }
    for (k, line) in polylines.iter().enumerate() {
        if let Some(i) = line
            .points
            .iter()
            .position(|p| !p.iter().all(|x| x.is_finite()))
        {
            return Err(format!(
                "polyline {k}: point {i} is not finite ({:?})",
                line.points[i].as_slice()
            ));
        }
        if let (Some(name), Some(radius)) = (radius_array, &line.radius)
            && let Some(i) = radius.iter().position(|r| !(r.is_finite() && *r > 0.0))
        {
            return Err(format!(
                "polyline {k}: the radius `{name}` at point {i} is {}, not a positive number",
                radius[i]
            ));
        }
    }
    Ok(polylines)
}

/// `x,y,z[,radius]` rows, one polyline. A UTF-8 byte-order mark before the first row is skipped (spreadsheet
/// programs write one); `#` starts a comment. The first row may be a header: a row with no number in it
/// (`x,y,z,radius`). Any other field that is not a number is an error at its line and column — a first row
/// `0.0,0.0,O.0,6.0` (a letter O) is a mistyped point, not a header.
fn read_csv(bytes: &[u8]) -> Result<Vec<Polyline>, String> {
    let text = std::str::from_utf8(bytes).map_err(|_| "not a text file (CSV)".to_string())?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let (mut points, mut radius) = (Vec::new(), Vec::new());
    let (mut columns, mut header) = (None, false);
    for (number, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or("");
        if content.trim().is_empty() {
            continue;
        }
        // Each field with the column (from 1, in characters) where its text starts.
        let mut fields = Vec::new();
        let mut at = 0;
        for field in content.split(',') {
            let lead = field.len() - field.trim_start().len();
            let column = content[..at + lead].chars().count() + 1;
            fields.push((field.trim(), column));
            at += field.len() + 1;
        }
        let values: Vec<Option<Real>> = fields.iter().map(|(f, _)| f.parse().ok()).collect();
        if values.iter().all(Option::is_none) {
            if points.is_empty() && !header {
                header = true;
                continue;
            }
            return Err(format!(
                "line {}: `{}` has no number (only the first row may be a header)",
                number + 1,
                content.trim()
            ));
        }
        if let Some(k) = values.iter().position(Option::is_none) {
            let (text, column) = fields[k];
            return Err(format!(
                "line {}, column {column}: `{text}` (field {} of {}) is not a number; a header is a row with no number in it",
                number + 1,
                k + 1,
                fields.len()
            ));
        }
        let values: Vec<Real> = values.into_iter().flatten().collect();
        if !(3..=4).contains(&values.len()) || columns.is_some_and(|c| c != values.len()) {
            return Err(format!(
                "line {}: expected x,y,z or x,y,z,radius{}, found {} values",
                number + 1,
                columns.map_or(String::new(), |c| format!(
                    " ({c} values as the rows before)"
                )),
                values.len()
            ));
        }
        columns = Some(values.len());
        points.push(Vec3::new(values[0], values[1], values[2]));
        if let Some(&r) = values.get(3) {
            radius.push(r);
        }
    }
    let radius = (columns == Some(4)).then_some(radius);
    Ok(vec![Polyline { points, radius }])
}

/// A SimVascular path file: the `pos` of every `path_point`, one polyline per `path`.
fn read_pth(bytes: &[u8]) -> Result<Vec<Polyline>, String> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_reader(bytes);
    let mut buf = Vec::new();
    let (mut polylines, mut current, mut in_path_point) = (Vec::new(), Vec::new(), false);
    let mut seen_path = false;
    loop {
        let event = reader
            .read_event_into(&mut buf)
            .map_err(|e| format!("not a SimVascular path file (XML): {e}"))?;
        match event {
            Event::Start(e) | Event::Empty(e) => match e.name().as_ref() {
                b"path" => seen_path = true,
                b"path_point" => in_path_point = true,
                b"pos" if in_path_point => {
                    let attrs = attributes(&e)?;
                    let coordinate = |k: &str| {
                        attrs
                            .iter()
                            .find(|(n, _)| n == k)
                            .and_then(|(_, v)| v.trim().parse::<Real>().ok())
                            .ok_or_else(|| format!("a path point's `pos` has no number `{k}`"))
                    };
                    current.push(Vec3::new(
                        coordinate("x")?,
                        coordinate("y")?,
                        coordinate("z")?,
                    ));
                }
                _ => {}
            },
            Event::End(e) => match e.name().as_ref() {
                b"path_point" => in_path_point = false,
                b"path" if !current.is_empty() => polylines.push(Polyline {
                    points: std::mem::take(&mut current),
                    radius: None,
                }),
                _ => {}
            },
            Event::Eof => break,
            _ => {}
        }
        buf.clear();
    }
    if !seen_path {
        return Err("not a SimVascular path file: no <path> element".into());
    }
    if !current.is_empty() {
        polylines.push(Polyline {
            points: current,
            radius: None,
        });
    }
    Ok(polylines)
}

/// An XML element's attributes as (name, value) strings.
fn attributes(e: &quick_xml::events::BytesStart<'_>) -> Result<Vec<(String, String)>, String> {
    e.attributes()
        .map(|a| {
            let a = a.map_err(|e| format!("bad XML attribute: {e}"))?;
            let value = a
                .unescape_value()
                .map_err(|e| format!("bad XML attribute value: {e}"))?;
            Ok((
                String::from_utf8_lossy(a.key.as_ref()).into_owned(),
                value.into_owned(),
            ))
        })
        .collect()
}

/// The numeric types of VTK arrays.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    /// From an XML `type` (`Float32`) or a legacy type name (`float`, `vtktypeint64`).
    fn parse(name: &str) -> Option<Self> {
        Some(match name.to_ascii_lowercase().as_str() {
            "int8" | "char" | "signed_char" => Self::I8,
            "uint8" | "unsigned_char" | "bit" => Self::U8,
            "int16" | "short" => Self::I16,
            "uint16" | "unsigned_short" => Self::U16,
            "int32" | "int" => Self::I32,
            "uint32" | "unsigned_int" => Self::U32,
            "int64" | "long" | "vtktypeint64" | "vtkidtype" => Self::I64,
            "uint64" | "unsigned_long" | "vtktypeuint64" => Self::U64,
            "float32" | "float" => Self::F32,
            "float64" | "double" => Self::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::I64 | Self::U64 | Self::F64 => 8,
        }
    }

    /// The value of a number written as text, held as this type (a `Float32` array's text is rounded to
    /// single precision, as VTK's reader does).
    fn parse_text(self, word: &str) -> Option<Real> {
        match self {
            Self::F32 => word.parse::<f32>().ok().map(Real::from),
            Self::F64 => word.parse::<f64>().ok(),
            _ => word.parse::<i64>().ok().map(|i| i as Real),
        }
    }

    /// The values of `bytes` (whole elements only), little-endian unless `big`.
    fn values(self, bytes: &[u8], big: bool) -> Vec<Real> {
        let n = self.size();
        bytes
            .chunks_exact(n)
            .map(|c| {
                let mut b = [0u8; 8];
                b[..n].copy_from_slice(c);
                if big {
                    b[..n].reverse();
                }
                match self {
                    Self::I8 => Real::from(b[0] as i8),
                    Self::U8 => Real::from(b[0]),
                    Self::I16 => Real::from(i16::from_le_bytes([b[0], b[1]])),
                    Self::U16 => Real::from(u16::from_le_bytes([b[0], b[1]])),
                    Self::I32 => Real::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    Self::U32 => Real::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    Self::I64 => i64::from_le_bytes(b) as Real,
                    Self::U64 => u64::from_le_bytes(b) as Real,
                    Self::F32 => Real::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    Self::F64 => f64::from_le_bytes(b),
                }
            })
            .collect()
    }
}

/// Polylines from cell connectivity and per-cell end offsets (XML and VTK ≥ 9 layout: `offsets[k]` is where
/// cell `k` ends; a leading 0 is allowed).
fn polylines_from_offsets(
    points: &[Vec3],
    radius: Option<&[Real]>,
    connectivity: &[Real],
    offsets: &[Real],
) -> Result<Vec<Polyline>, String> {
    let mut start = 0usize;
    let mut lines = Vec::new();
    for &end in offsets {
        let end = end as usize;
        if end == 0 && start == 0 {
            continue;
        }
        if end < start || end > connectivity.len() {
            return Err(format!(
                "a line's offset {end} is outside its {} connectivity entries",
                connectivity.len()
            ));
        }
        lines.push(polyline(points, radius, &connectivity[start..end])?);
        start = end;
    }
    Ok(lines)
}

/// One polyline through the point ids `ids`.
fn polyline(points: &[Vec3], radius: Option<&[Real]>, ids: &[Real]) -> Result<Polyline, String> {
    let ids: Vec<usize> = ids
        .iter()
        .map(|&i| {
            (i >= 0.0 && (i as usize) < points.len())
                .then_some(i as usize)
                .ok_or_else(|| {
                    format!(
                        "a line names point {i}, but the file has {} points",
                        points.len()
                    )
                })
        })
        .collect::<Result<_, _>>()?;
    Ok(Polyline {
        points: ids.iter().map(|&i| points[i]).collect(),
        radius: radius.map(|r| ids.iter().map(|&i| r[i]).collect()),
    })
}

/// The point triples of a flat array.
fn triples(values: &[Real], what: &str) -> Result<Vec<Vec3>, String> {
    if !values.len().is_multiple_of(3) {
        return Err(format!(
            "{what} holds {} numbers, not a multiple of 3",
            values.len()
        ));
    }
    Ok(values
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect())
}

/// The radius array `name` among `arrays` (name, components, values) of `count` points.
fn radius_values(
    arrays: &[(String, usize, Vec<Real>)],
    name: Option<&str>,
    count: usize,
) -> Result<Option<Vec<Real>>, String> {
    let Some(name) = name else {
        return Ok(None);
    };
    match arrays.iter().find(|(n, _, _)| n == name) {
        Some((_, 1, values)) if values.len() == count => Ok(Some(values.clone())),
        Some((_, c, values)) => Err(format!(
            "the radius array `{name}` has {c} components and {} values for {count} points",
            values.len()
        )),
        None => Err(format!(
            "no point array `{name}` (the lumen radius); the file's point arrays: {}",
            if arrays.is_empty() {
                "none".to_string()
            } else {
                arrays
                    .iter()
                    .map(|(n, _, _)| format!("`{n}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        )),
    }
}

mod vtp {
    //! VTK XML PolyData (module docs of [`super`]).

    use super::{
        MAX_CENTRELINE_POINTS, Polyline, Scalar, attributes, polylines_from_offsets, radius_values,
        triples,
    };
    use crate::math::Real;
    use base64::Engine as _;
    use quick_xml::events::Event;
    use std::io::Read as _;

    /// One `DataArray` as written.
    struct Array {
        /// The enclosing element: `Points`, `PointData`, `Lines`, `Verts`, …
        section: String,
        /// Its attributes.
        attrs: Vec<(String, String)>,
        /// Its text (ascii or inline base64).
        text: String,
    }

    impl Array {
        fn attr(&self, name: &str) -> Option<&str> {
            self.attrs
                .iter()
                .find(|(n, _)| n == name)
                .map(|(_, v)| v.as_str())
        }
    }

    /// The most bytes an array may hold, and what they are for (in messages): what the points or cells the
    /// piece declares need.
    struct Need {
        bytes: usize,
        what: String,
    }

    impl Need {
        /// `count` tuples of `components` values of `scalar` for `what`; `None` on overflow.
        fn of(count: usize, components: usize, scalar: Scalar, what: String) -> Option<Self> {
            let bytes = count.checked_mul(components)?.checked_mul(scalar.size())?;
            Some(Self { bytes, what })
        }
    }

    /// How the file encodes its binary data.
    struct Layout<'a> {
        big: bool,
        header: Scalar,
        compressed: bool,
        /// The bytes after `_` in `<AppendedData>`, and whether they are base64.
        appended: Option<(&'a [u8], bool)>,
    }

    pub(super) fn read(bytes: &[u8], radius_array: Option<&str>) -> Result<Vec<Polyline>, String> {
        // Appended raw data is binary: the XML parser reads only what comes before it.
        let appended_at = find(bytes, b"<AppendedData");
        let head = &bytes[..appended_at.unwrap_or(bytes.len())];
        let mut reader = quick_xml::Reader::from_reader(head);
        let mut buf = Vec::new();
        let (mut stack, mut arrays) = (Vec::<String>::new(), Vec::new());
        // Each piece: where its arrays start, and its attributes.
        let mut pieces: Vec<(usize, Vec<(String, String)>)> = Vec::new();
        let mut root: Option<Vec<(String, String)>> = None;
        let mut current: Option<Array> = None;
        // Elements open inside the current DataArray (VTK writes <InformationKey> there): their text is not data.
        let mut nested = 0usize;
        loop {
            let event = match reader.read_event_into(&mut buf) {
                Ok(e) => e,
                // A document cut before its appended data ends early: what was read stands.
                Err(_) if appended_at.is_some() && root.is_some() => break,
                Err(e) => return Err(format!("not VTK XML PolyData: {e}")),
            };
            let empty = matches!(event, Event::Empty(_));
            match event {
                Event::Start(e) | Event::Empty(e) => {
                    let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
                    match name.as_str() {
                        "VTKFile" => root = Some(attributes(&e)?),
                        "Piece" => pieces.push((arrays.len(), attributes(&e)?)),
                        "DataArray" => {
                            let array = Array {
                                section: stack.last().cloned().unwrap_or_default(),
                                attrs: attributes(&e)?,
                                text: String::new(),
                            };
                            if empty {
                                arrays.push(array);
                            } else {
                                current = Some(array);
                            }
                        }
                        _ => {}
                    }
                    if !empty && name != "DataArray" {
                        if current.is_some() {
                            nested += 1;
                        }
                        stack.push(name);
                    }
                }
                Event::Text(t) if nested == 0 => {
                    if let Some(a) = &mut current {
                        a.text.push_str(&String::from_utf8_lossy(&t));
                    }
                }
                Event::End(e) => {
                    if e.name().as_ref() == b"DataArray" {
                        arrays.extend(current.take());
                    } else {
                        nested = nested.saturating_sub(1);
                        stack.pop();
                    }
                }
                Event::Eof => break,
                _ => {}
            }
            buf.clear();
        }
        let root = root.ok_or("not VTK XML PolyData: no <VTKFile> element")?;
        let get = |n: &str| root.iter().find(|(k, _)| k == n).map(|(_, v)| v.as_str());
        if get("type") != Some("PolyData") {
            return Err(format!(
                "a VTK XML file of type `{}`, not PolyData",
                get("type").unwrap_or("?")
            ));
        }
        let compressed = match get("compressor") {
            None | Some("") => false,
            Some("vtkZLibDataCompressor") => true,
            Some(other) => {
                return Err(format!(
                    "compressed with {other}: only zlib (vtkZLibDataCompressor) or no compression is read"
                ));
            }
        };
        let header = match get("header_type") {
            None | Some("UInt32") => Scalar::U32,
            Some("UInt64") => Scalar::U64,
            Some(other) => return Err(format!("header_type {other}: expected UInt32 or UInt64")),
        };
        let appended = match appended_at {
            Some(at) => Some(appended_data(&bytes[at..])?),
            None => None,
        };
        let layout = Layout {
            big: get("byte_order") == Some("BigEndian"),
            header,
            compressed,
            appended,
        };
        let mut polylines = Vec::new();
        let mut points = 0usize;
        for (k, (start, attrs)) in pieces.iter().enumerate() {
            let end = pieces.get(k + 1).map_or(arrays.len(), |p| p.0);
            // As VTK's reader: a piece must say its points; no `NumberOfLines` is none.
            let declared = |name: &str, default: Option<&str>| -> Result<usize, String> {
                let text = attrs
                    .iter()
                    .find(|(n, _)| n == name)
                    .map(|(_, v)| v.as_str())
                    .or(default)
                    .ok_or_else(|| format!("piece {k} has no {name}"))?;
                text.trim()
                    .parse()
                    .map_err(|_| format!("piece {k}: {name}=\"{text}\" is not a count"))
            };
            let counts = (
                declared("NumberOfPoints", None)?,
                declared("NumberOfLines", Some("0"))?,
            );
            points = points.saturating_add(counts.0);
            if let Some((n, what)) = [(points, "points"), (counts.1, "lines")]
                .into_iter()
                .find(|&(n, _)| n > MAX_CENTRELINE_POINTS)
            {
                return Err(format!(
                    "the file declares {n} {what}, more than stentkit's limit of {MAX_CENTRELINE_POINTS} points for a centreline"
                ));
            }
            polylines.extend(piece(&arrays[*start..end], counts, &layout, radius_array)?);
        }
        Ok(polylines)
    }

    /// The polylines of one piece of `(points, lines)` as it declares (`NumberOfPoints`, `NumberOfLines`).
    /// Only the arrays needed are decoded: the points, the radius array asked for, the lines' offsets and
    /// connectivity; each no further than those counts need ([`Need`]).
    fn piece(
        arrays: &[Array],
        (count, lines): (usize, usize),
        layout: &Layout<'_>,
        radius_array: Option<&str>,
    ) -> Result<Vec<Polyline>, String> {
        fn in_section<'a>(
            arrays: &'a [Array],
            section: &'a str,
        ) -> impl Iterator<Item = &'a Array> {
            arrays.iter().filter(move |a| a.section == section)
        }
        let Some(points) = in_section(arrays, "Points").next() else {
            return Ok(Vec::new());
        };
        let need = |a: &Array, count: usize, components: usize, what: &str| {
            let scalar = scalar(a)?;
            Need::of(count, components, scalar, what.to_string()).ok_or_else(|| {
                format!(
                    "array `{}`: {count} × {components} values overflow",
                    a.attr("Name").unwrap_or("(unnamed)")
                )
            })
        };
        let what = format!("{count} points");
        let points = triples(
            &values(points, layout, &need(points, count, 3, &what)?)?,
            "the Points array",
        )?;
        let mut point_arrays = Vec::new();
        for a in in_section(arrays, "PointData") {
            let components = a
                .attr("NumberOfComponents")
                .and_then(|c| c.parse().ok())
                .unwrap_or(1);
            let name = a.attr("Name").unwrap_or("").to_string();
            // Only the radius asked for is decoded (and only as one value per point): the names of the
            // others are listed when it is missing.
            let decoded = if radius_array == Some(name.as_str()) && components == 1 {
                values(a, layout, &need(a, count, 1, &what)?)?
            } else {
                Vec::new()
            };
            point_arrays.push((name, components, decoded));
        }
        let radius = radius_values(&point_arrays, radius_array, points.len())?;
        let named = |name: &str| in_section(arrays, "Lines").find(|a| a.attr("Name") == Some(name));
        let (Some(connectivity), Some(offsets)) = (named("connectivity"), named("offsets")) else {
            return Ok(Vec::new());
        };
        // A leading 0 is allowed (module docs of `polylines_from_offsets`).
        let offsets = values(
            offsets,
            layout,
            &need(offsets, lines + 1, 1, &format!("{lines} lines"))?,
        )?;
        let entries = offsets.iter().fold(0.0, |a: Real, &b| a.max(b));
        if entries > MAX_CENTRELINE_POINTS as Real {
            return Err(format!(
                "the lines' offsets reach {entries}: the lines would hold more than stentkit's limit of {MAX_CENTRELINE_POINTS} points for a centreline"
            ));
        }
        let entries = entries as usize;
        let connectivity = values(
            connectivity,
            layout,
            &need(
                connectivity,
                entries,
                1,
                &format!("{entries} point ids (the lines' last offset)"),
            )?,
        )?;
        polylines_from_offsets(&points, radius.as_deref(), &connectivity, &offsets)
    }

    /// The numeric type of an array.
    fn scalar(a: &Array) -> Result<Scalar, String> {
        a.attr("type").and_then(Scalar::parse).ok_or_else(|| {
            format!(
                "array `{}`: unknown type {:?}",
                a.attr("Name").unwrap_or("(unnamed)"),
                a.attr("type")
            )
        })
    }

    /// The values of an array, whatever its format; binary data no more than `need` bytes.
    fn values(a: &Array, layout: &Layout<'_>, need: &Need) -> Result<Vec<Real>, String> {
        let name = a.attr("Name").unwrap_or("(unnamed)");
        let scalar = scalar(a)?;
        let unpack = |bytes: &[u8]| {
            block(bytes, layout, need).map_err(|message| format!("array `{name}`: {message}"))
        };
        let bytes = match a.attr("format").unwrap_or("ascii") {
            "ascii" => {
                return a
                    .text
                    .split_whitespace()
                    .map(|t| {
                        scalar
                            .parse_text(t)
                            .ok_or_else(|| format!("array `{name}`: `{t}` is not a number"))
                    })
                    .collect();
            }
            "binary" => unpack(&decode_base64(a.text.trim().as_bytes())?)?,
            "appended" => {
                let (data, base64) = layout.appended.ok_or_else(|| {
                    format!("array `{name}` is appended, but the file has no <AppendedData>")
                })?;
                let offset: usize = a
                    .attr("offset")
                    .and_then(|o| o.parse().ok())
                    .ok_or_else(|| format!("array `{name}` is appended without an offset"))?;
                let data = data.get(offset..).ok_or_else(|| {
                    format!("array `{name}`: offset {offset} is past the appended data")
                })?;
                if base64 {
                    // Up to the next array (decoding stops at the first block's end anyway).
                    let end = data.iter().position(|&c| c == b'<').unwrap_or(data.len());
                    unpack(&decode_base64(&data[..end])?)?
                } else {
                    unpack(data)?
                }
            }
            other => return Err(format!("array `{name}`: unknown format `{other}`")),
        };
        Ok(scalar.values(&bytes, layout.big))
    }

    /// The data of one binary block (header and data, module docs of [`super`]), refused when its header
    /// declares more than `need` bytes; a compressed block is inflated no further than its header declares.
    fn block(bytes: &[u8], layout: &Layout<'_>, need: &Need) -> Result<Vec<u8>, String> {
        let size = layout.header.size();
        let word = |k: usize| -> Result<usize, String> {
            k.checked_mul(size)
                .and_then(|at| bytes.get(at..at.checked_add(size)?))
                .map(|w| layout.header.values(w, layout.big)[0] as usize)
                .ok_or_else(|| "it ends inside its header".to_string())
        };
        let too_much = |declared: Option<usize>| {
            format!(
                "its header declares {} bytes, more than the {} bytes its {} need (a damaged or hostile file); nothing was inflated",
                declared.map_or_else(|| "more than 2⁶⁴".to_string(), |d| d.to_string()),
                need.bytes,
                need.what
            )
        };
        if !layout.compressed {
            let n = word(0)?;
            if n > need.bytes {
                return Err(too_much(Some(n)));
            }
            return bytes
                .get(size..size + n)
                .map(<[u8]>::to_vec)
                .ok_or_else(|| format!("it says {n} bytes but holds fewer"));
        }
        // VTK's compressed header: block count, block size, size of the last block (0: a full block), then
        // each block's compressed size.
        let (blocks, block_size, last) = (word(0)?, word(1)?, word(2)?);
        let last = if last == 0 { block_size } else { last };
        let declared = blocks.checked_sub(1).map_or(Some(0), |full| {
            full.checked_mul(block_size)?.checked_add(last)
        });
        if declared.is_none_or(|d| d > need.bytes) {
            return Err(too_much(declared));
        }
        let mut at = blocks
            .checked_add(3)
            .and_then(|w| w.checked_mul(size))
            .ok_or_else(|| "it ends inside its header".to_string())?;
        let mut out = Vec::with_capacity(declared.unwrap_or(0));
        for k in 0..blocks {
            let compressed = word(3 + k)?;
            let chunk = at
                .checked_add(compressed)
                .and_then(|end| bytes.get(at..end))
                .ok_or("it ends inside a compressed block")?;
            let expected = if k + 1 == blocks { last } else { block_size };
            let inflated = flate2::read::ZlibDecoder::new(chunk)
                .take(expected as u64 + 1)
                .read_to_end(&mut out)
                .map_err(|e| format!("a compressed block does not inflate: {e}"))?;
            if inflated > expected {
                return Err(format!(
                    "compressed block {} of {blocks} inflates to more than the {expected} bytes its header declares (a damaged or hostile file); inflating stopped there",
                    k + 1
                ));
            }
            at += compressed;
        }
        Ok(out)
    }

    /// Base64 text that may be several streams, each padded (VTK encodes a header and its data separately):
    /// decoded piece by piece at each padding.
    fn decode_base64(text: &[u8]) -> Result<Vec<u8>, String> {
        let clean: Vec<u8> = text
            .iter()
            .copied()
            .filter(|c| !c.is_ascii_whitespace())
            .collect();
        let mut out = Vec::new();
        let mut start = 0;
        while start < clean.len() {
            // A piece ends after its padding, or at a multiple of 4 before a padded group.
            let mut end = start;
            while end < clean.len() && clean[end] != b'=' {
                end += 1;
            }
            while end < clean.len() && clean[end] == b'=' {
                end += 1;
            }
            base64::engine::general_purpose::STANDARD
                .decode_vec(&clean[start..end], &mut out)
                .map_err(|e| format!("bad base64 data: {e}"))?;
            start = end;
        }
        Ok(out)
    }

    /// The appended bytes after `_`, and whether they are base64 (`encoding="base64"`).
    fn appended_data(from: &[u8]) -> Result<(&[u8], bool), String> {
        let tag_end = from
            .iter()
            .position(|&c| c == b'>')
            .ok_or("an unfinished <AppendedData> tag")?;
        let tag = String::from_utf8_lossy(&from[..tag_end]);
        let base64 = !tag.contains("\"raw\"");
        let rest = &from[tag_end + 1..];
        let underscore = rest
            .iter()
            .position(|&c| c == b'_')
            .ok_or("<AppendedData> without the `_` that starts its data")?;
        Ok((&rest[underscore + 1..], base64))
    }

    /// The first position of `needle` in `haystack`.
    fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
        haystack.windows(needle.len()).position(|w| w == needle)
    }

    #[cfg(test)]
    mod tests {
        use super::decode_base64;
        use base64::Engine as _;

        /// Source: RFC 4648 base64; two separately padded streams decode to their concatenation.
        #[test]
        fn separately_padded_streams_decode_in_turn() {
            let e = |b: &[u8]| base64::engine::general_purpose::STANDARD.encode(b);
            let text = format!("{}{}", e(&[1, 2, 3, 4]), e(b"hello world"));
            assert_eq!(
                decode_base64(text.as_bytes()).expect("decodes"),
                [&[1u8, 2, 3, 4][..], b"hello world"].concat()
            );
            let single = e(&[7u8; 10]);
            assert_eq!(
                decode_base64(single.as_bytes()).expect("decodes"),
                vec![7u8; 10]
            );
        }
    }
}

mod legacy {
    //! Legacy VTK POLYDATA, ASCII or binary (module docs of [`super`]).

    use super::{
        MAX_CENTRELINE_POINTS, Polyline, Scalar, polyline, polylines_from_offsets, radius_values,
        triples,
    };
    use crate::math::Real;

    /// A cursor over the file: words in ASCII sections, raw big-endian values in binary ones.
    struct Cursor<'a> {
        bytes: &'a [u8],
        at: usize,
        binary: bool,
    }

    impl<'a> Cursor<'a> {
        /// The next line (without its end), or `None` at the end.
        fn line(&mut self) -> Option<&'a str> {
            if self.at >= self.bytes.len() {
                return None;
            }
            let rest = &self.bytes[self.at..];
            let end = rest.iter().position(|&c| c == b'\n').unwrap_or(rest.len());
            self.at += end + 1;
            Some(std::str::from_utf8(&rest[..end]).unwrap_or("").trim())
        }

        /// The next non-empty line.
        fn keyword_line(&mut self) -> Option<&'a str> {
            loop {
                let l = self.line()?;
                if !l.is_empty() {
                    return Some(l);
                }
            }
        }

        /// The next whitespace-separated word.
        fn word(&mut self) -> Option<&'a str> {
            while self.at < self.bytes.len() && self.bytes[self.at].is_ascii_whitespace() {
                self.at += 1;
            }
            let start = self.at;
            while self.at < self.bytes.len() && !self.bytes[self.at].is_ascii_whitespace() {
                self.at += 1;
            }
            (self.at > start)
                .then(|| std::str::from_utf8(&self.bytes[start..self.at]).unwrap_or(""))
        }

        /// `count` values of type `scalar`.
        fn values(&mut self, count: usize, scalar: Scalar) -> Result<Vec<Real>, String> {
            if self.binary {
                let bytes = count
                    .checked_mul(scalar.size())
                    .and_then(|n| self.bytes.get(self.at..self.at.checked_add(n)?))
                    .ok_or("the binary data ends early")?;
                let n = bytes.len();
                self.at += n;
                // The line break after the binary block.
                if self.bytes.get(self.at) == Some(&b'\n') {
                    self.at += 1;
                }
                return Ok(scalar.values(bytes, true));
            }
            (0..count)
                .map(|_| {
                    let w = self.word().ok_or("the data ends early")?;
                    scalar
                        .parse_text(w)
                        .ok_or_else(|| format!("`{w}` is not a number"))
                })
                .collect()
        }
    }

    /// The count and type after a keyword (`POINTS 409 float`).
    fn count(words: &[&str], k: usize, line: &str) -> Result<usize, String> {
        words
            .get(k)
            .and_then(|w| w.parse().ok())
            .ok_or_else(|| format!("`{line}`: expected a count"))
    }

    /// The cells after a `LINES`/`VERTICES`/… line (`words`): VTK ≥ 9 writes `KEY nOffsets nConnectivity`
    /// and then `OFFSETS type` and `CONNECTIVITY type` arrays; earlier versions `KEY nCells size` and `size`
    /// integers, a count before each cell's point ids.
    enum Cells {
        Offsets(Vec<Real>, Vec<Real>),
        Counted(Vec<Real>),
    }

    fn cell_block(c: &mut Cursor<'_>, words: &[&str], line: &str) -> Result<Cells, String> {
        let (a, b) = (count(words, 1, line)?, count(words, 2, line)?);
        let save = c.at;
        let typed = |header: &str, key: &str| {
            header
                .strip_prefix(key)
                .and_then(|rest| rest.split_whitespace().next())
                .and_then(Scalar::parse)
                .ok_or_else(|| format!("expected `{key} type`, found `{header}`"))
        };
        match c.keyword_line() {
            Some(next) if next.starts_with("OFFSETS") => {
                let offsets = c.values(a, typed(next, "OFFSETS")?)?;
                let header = c.keyword_line().unwrap_or("");
                let connectivity = c.values(b, typed(header, "CONNECTIVITY")?)?;
                Ok(Cells::Offsets(offsets, connectivity))
            }
            _ => {
                c.at = save;
                Ok(Cells::Counted(c.values(b, Scalar::I32)?))
            }
        }
    }

    pub(super) fn read(bytes: &[u8], radius_array: Option<&str>) -> Result<Vec<Polyline>, String> {
        let mut c = Cursor {
            bytes,
            at: 0,
            binary: false,
        };
        if !c.line().is_some_and(|l| l.starts_with("# vtk DataFile")) {
            return Err("not a legacy VTK file: no `# vtk DataFile` first line".into());
        }
        c.line(); // the title
        c.binary = match c.keyword_line() {
            Some(l) if l.eq_ignore_ascii_case("ASCII") => false,
            Some(l) if l.eq_ignore_ascii_case("BINARY") => true,
            other => return Err(format!("expected ASCII or BINARY, found {other:?}")),
        };
        let (mut points, mut cells, mut offsets, mut connectivity) = (None, None, None, None);
        let mut arrays: Vec<(String, usize, Vec<Real>)> = Vec::new();
        while let Some(line) = c.keyword_line() {
            let words: Vec<&str> = line.split_whitespace().collect();
            match words[0].to_ascii_uppercase().as_str() {
                "DATASET"
                    if words
                        .get(1)
                        .is_some_and(|w| !w.eq_ignore_ascii_case("POLYDATA")) =>
                {
                    return Err(format!("a legacy VTK {} dataset, not POLYDATA", words[1]));
                }
                "POINTS" => {
                    let n = count(&words, 1, line)?;
                    if n > MAX_CENTRELINE_POINTS {
                        return Err(format!(
                            "`{line}`: {n} points, more than stentkit's limit of {MAX_CENTRELINE_POINTS} for a centreline"
                        ));
                    }
                    let scalar = words
                        .get(2)
                        .and_then(|t| Scalar::parse(t))
                        .ok_or("POINTS: unknown type")?;
                    points = Some(triples(&c.values(3 * n, scalar)?, "POINTS")?);
                }
                "LINES" => match cell_block(&mut c, &words, line)? {
                    Cells::Offsets(o, k) => (offsets, connectivity) = (Some(o), Some(k)),
                    Cells::Counted(v) => cells = Some(v),
                },
                "VERTICES" | "POLYGONS" | "TRIANGLE_STRIPS" => {
                    cell_block(&mut c, &words, line)?;
                }
                "SCALARS" => {
                    let name = words.get(1).copied().unwrap_or("").to_string();
                    let scalar = words
                        .get(2)
                        .and_then(|t| Scalar::parse(t))
                        .ok_or("SCALARS: unknown type")?;
                    let components: usize = words.get(3).and_then(|w| w.parse().ok()).unwrap_or(1);
                    let save = c.at;
                    if !c
                        .keyword_line()
                        .is_some_and(|l| l.starts_with("LOOKUP_TABLE"))
                    {
                        c.at = save;
                    }
                    let n = points.as_ref().map_or(0, Vec::len);
                    let values = n
                        .checked_mul(components)
                        .ok_or_else(|| format!("`{line}`: too many components"))?;
                    arrays.push((name, components, c.values(values, scalar)?));
                }
                "FIELD" => {
                    let k = count(&words, 2, line)?;
                    for _ in 0..k {
                        let mut head = c.keyword_line().ok_or("FIELD: an array is missing")?;
                        // VTK ≥ 8 writes a METADATA block (information keys, up to an empty line) after an array.
                        while head.starts_with("METADATA") {
                            while c.line().is_some_and(|l| !l.is_empty()) {}
                            head = c.keyword_line().ok_or("FIELD: an array is missing")?;
                        }
                        let w: Vec<&str> = head.split_whitespace().collect();
                        let (components, tuples) = (count(&w, 1, head)?, count(&w, 2, head)?);
                        let scalar = w
                            .get(3)
                            .and_then(|t| Scalar::parse(t))
                            .ok_or("FIELD: unknown type")?;
                        let values = components
                            .checked_mul(tuples)
                            .ok_or_else(|| format!("`{head}`: too many values"))?;
                        arrays.push((w[0].to_string(), components, c.values(values, scalar)?));
                    }
                }
                "METADATA" => {
                    // Information keys up to an empty line.
                    while c.line().is_some_and(|l| !l.is_empty()) {}
                }
                _ => {}
            }
        }
        let points = points.ok_or("no POINTS")?;
        let radius = radius_values(&arrays, radius_array, points.len())?;
        if let (Some(offsets), Some(connectivity)) = (&offsets, &connectivity) {
            return polylines_from_offsets(&points, radius.as_deref(), connectivity, offsets);
        }
        let mut polylines = Vec::new();
        let cells = cells.unwrap_or_default();
        let mut at = 0;
        while at < cells.len() {
            let n = cells[at] as usize;
            let ids = n
                .checked_add(at + 1)
                .and_then(|end| cells.get(at + 1..end))
                .ok_or("LINES: a cell runs past its data")?;
            polylines.push(polyline(&points, radius.as_deref(), ids)?);
            at += 1 + n;
        }
        Ok(polylines)
    }
}
