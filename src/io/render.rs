//! Shaded pictures of tube meshes (PNG), drawn on the CPU by the tiny-skia rasteriser: no GPU, no system
//! library, the same pixels on every machine.
//!
//! **How.** Orthographic projection along a [`View`] of the configuration figures; faces turned away from the
//! viewer culled (the snapshot meshes are closed and wound outward, [`crate::geometry::mesh`]); the opaque
//! layers scan-converted through a depth buffer (edge functions over each triangle's bounding box, Pineda
//! 1988), then the translucent layers' faces far to near, each blended over what is there where no opaque face
//! is nearer; each face lit by a fixed light from the upper left front with Lambert's cosine law over an
//! ambient part, `I = A + (1 − A)·|n·l|`. Edges are smoothed by drawing at [`SUPERSAMPLING`] times the size and
//! averaging each block of pixels. tiny-skia (a pure-Rust rasteriser) holds the pictures, composites the panels
//! and encodes the PNG; its per-path fill was not used for the triangles because it costs about 2 µs a
//! triangle (1 s for the straight stent's picture of 7 × 67 000 front faces, 9 % of its run), the depth buffer
//! a tenth of that, and gives exact occlusion where the painter's algorithm errs at the joints.
//!
//! **What.** One panel per state side by side (or in a grid closest to 16:9), all at one scale framed on every
//! layer that [`Layer::frames`] marks; per panel, layers of triangles each with a colour and an opacity: the
//! device, the initial shape as a light grey ghost, a vessel lumen.
//!
//! The pictures carry no text (tiny-skia draws no glyphs): `stentkit render` and the run name the times in
//! the file name and on the terminal.

use super::configurations::View;
use crate::geometry::mesh::TriangleMesh;
use crate::math::{Real, Vec3};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use tiny_skia::{Color, Pixmap, Transform};

/// Pixels drawn per output pixel along each axis.
pub(crate) const SUPERSAMPLING: u32 = 2;

/// Default width of a panel in pixels.
pub(crate) const PANEL_WIDTH: u32 = 480;

/// Most pixels of a panel (2048²): its supersampled buffers take 16 bytes a sub-pixel, 270 MB at this size.
const MAX_PANEL_PIXELS: u64 = 2048 * 2048;

/// The ambient part `A` of the shading.
const AMBIENT: Real = 0.3;

/// Gap between panels and margin around them, as a fraction of a panel's width.
const GAP: Real = 0.03;

/// Errors of the pictures.
#[derive(Debug, thiserror::Error)]
pub(crate) enum RenderError {
    /// Nothing to frame (no triangle in a framing layer) or no panel.
    #[error("nothing to draw: no triangle in the panels")]
    Empty,
    /// The picture would exceed what tiny-skia allocates.
    #[error("a picture of {width} × {height} pixels cannot be allocated")]
    Size {
        /// Width \[px\].
        width: u32,
        /// Height \[px\].
        height: u32,
    },
    /// A mesh could not be read.
    #[error("{path}: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: super::mesh_format::MeshIoError,
    },
    /// The PNG could not be encoded or written.
    #[error("{path}: {message}")]
    Write {
        /// The file.
        path: PathBuf,
        /// What failed.
        message: String,
    },
}

/// Triangles drawn in one colour.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layer<'a> {
    /// The triangles (closed and wound outward: faces turned away from the viewer are not drawn).
    pub mesh: &'a TriangleMesh,
    /// Colour lit face-on, RGB in [0, 1].
    pub colour: [f32; 3],
    /// Opacity in (0, 1].
    pub opacity: f32,
    /// Whether the picture's frame encloses this layer (a vessel lumen that runs far beyond the device does
    /// not frame; what falls outside the frame is clipped).
    pub frames: bool,
}

/// Colour of a device.
pub(crate) const DEVICE: [f32; 3] = [0.30, 0.45, 0.70];
/// Colour of the initial shape behind it.
pub(crate) const GHOST: [f32; 3] = [0.80, 0.80, 0.80];
/// Colour of a vessel lumen.
pub(crate) const LUMEN: [f32; 3] = [0.85, 0.35, 0.35];

/// Draws `panels` (each a list of layers) in `view`, each panel `panel_width` pixels wide; the panels are drawn
/// in parallel.
///
/// # Errors
/// [`RenderError::Empty`] without a framing triangle, [`RenderError::Size`] for a picture too large.
pub(crate) fn render(
    panels: &[Vec<Layer<'_>>],
    view: View,
    panel_width: u32,
) -> Result<Pixmap, RenderError> {
    let [right, up, _] = view.axes();
    let (mut lo, mut hi) = ([Real::INFINITY; 2], [Real::NEG_INFINITY; 2]);
    for layer in panels.iter().flatten().filter(|l| l.frames) {
        for x in &layer.mesh.vertices {
            let p = [x.dot(&right), x.dot(&up)];
            for i in 0..2 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
    }
    if panels.is_empty() || lo[0] > hi[0] {
        return Err(RenderError::Empty);
    }
    // One scale for every panel: the larger extent fills the panel; a degenerate extent still gets a frame.
    let extent = [(hi[0] - lo[0]).max(1e-12), (hi[1] - lo[1]).max(1e-12)];
    let aspect = (extent[1] / extent[0]).clamp(0.2, 5.0);
    let panel = (
        panel_width,
        (Real::from(panel_width) * aspect).round() as u32,
    );
    if u64::from(panel.0) * u64::from(panel.1) > MAX_PANEL_PIXELS {
        return Err(RenderError::Size {
            width: panel.0,
            height: panel.1,
        });
    }
    let frame = Frame {
        view,
        centre: [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])],
        scale: Real::from(SUPERSAMPLING)
            * (Real::from(panel.0) / extent[0]).min(Real::from(panel.1) / extent[1])
            / (1.0 + 2.0 * GAP),
        size: (panel.0 * SUPERSAMPLING, panel.1 * SUPERSAMPLING),
    };
    let drawn: Vec<Pixmap> = panels
        .par_iter()
        .map(|layers| draw_panel(layers, &frame))
        .collect::<Option<_>>()
        .ok_or(RenderError::Size {
            width: frame.size.0,
            height: frame.size.1,
        })?;
    let columns = columns(panels.len(), aspect);
    let rows = panels.len().div_ceil(columns);
    let gap = (GAP * Real::from(panel.0)).round() as u32;
    let (width, height) = (
        columns as u32 * (panel.0 + gap) + gap,
        rows as u32 * (panel.1 + gap) + gap,
    );
    let mut picture = Pixmap::new(width, height).ok_or(RenderError::Size { width, height })?;
    picture.fill(Color::WHITE);
    for (k, panel_pixmap) in drawn.iter().enumerate() {
        let (column, row) = ((k % columns) as u32, (k / columns) as u32);
        picture.draw_pixmap(
            (gap + column * (panel.0 + gap)) as i32,
            (gap + row * (panel.1 + gap)) as i32,
            panel_pixmap.as_ref(),
            &tiny_skia::PixmapPaint::default(),
            Transform::identity(),
            None,
        );
    }
    Ok(picture)
}

/// Where a panel looks and at what scale.
struct Frame {
    view: View,
    /// The framed extents' centre on the view plane.
    centre: [Real; 2],
    /// Pixels (supersampled) per length.
    scale: Real,
    /// The panel's supersampled size.
    size: (u32, u32),
}

/// One panel, drawn at the supersampled size and reduced: `None` when it cannot be allocated. Opaque layers
/// first, through the depth buffer; then the translucent faces far to near, each blended where no opaque
/// face is nearer.
fn draw_panel(layers: &[Layer<'_>], frame: &Frame) -> Option<Pixmap> {
    let [right, up, toward] = frame.view.axes();
    let light = light(frame.view);
    let mut canvas = Canvas::new(frame.size);
    let half = (
        0.5 * Real::from(frame.size.0),
        0.5 * Real::from(frame.size.1),
    );
    // Pixel coordinates (rows grow downward) and depth toward the viewer.
    let place = |x: &Vec3| {
        [
            (half.0 + frame.scale * (x.dot(&right) - frame.centre[0])) as f32,
            (half.1 - frame.scale * (x.dot(&up) - frame.centre[1])) as f32,
            x.dot(&toward) as f32,
        ]
    };
    let colour = |layer: &Layer<'_>, shade: f32| layer.colour.map(|c| (c * shade).clamp(0.0, 1.0));
    let opaque = |layer: &&Layer<'_>| layer.opacity >= 1.0;
    for (l, layer) in layers.iter().enumerate().filter(|(_, l)| opaque(l)) {
        for face in front_faces(l, layer, toward, light, &place) {
            canvas.fill(face.corners, colour(layer, face.shade), None);
        }
    }
    let mut translucent: Vec<_> = layers
        .iter()
        .enumerate()
        .filter(|(_, l)| !opaque(l))
        .flat_map(|(l, layer)| front_faces(l, layer, toward, light, &place))
        .collect();
    translucent.sort_unstable_by(|a, b| a.depth.total_cmp(&b.depth));
    for face in translucent {
        let layer = &layers[face.layer];
        canvas.fill(
            face.corners,
            colour(layer, face.shade),
            Some(layer.opacity.max(0.0)),
        );
    }
    canvas.downsampled(SUPERSAMPLING)
}

/// The direction of the fixed light from the upper left front of `view` (unit vector).
fn light(view: View) -> Vec3 {
    let [right, up, toward] = view.axes();
    (0.35 * right + 0.6 * up + 0.75 * toward).normalize()
}

/// A face turned toward the viewer, ready to draw.
struct Face {
    /// Depth of its centroid toward the viewer, times 3 (the sort key of translucent faces).
    depth: Real,
    /// Index of its layer.
    layer: usize,
    /// Its corners placed on the canvas, `[x, y, depth]`.
    corners: [[f32; 3]; 3],
    /// Its shade under the light.
    shade: f32,
}

/// The faces of `layer` (index `l`) turned toward the viewer, placed on the canvas by `place` and shaded under
/// `light`.
fn front_faces(
    l: usize,
    layer: &Layer<'_>,
    toward: Vec3,
    light: Vec3,
    place: &impl Fn(&Vec3) -> [f32; 3],
) -> Vec<Face> {
    (0..layer.mesh.triangles.len())
        .filter_map(|t| {
            let normal = layer.mesh.triangle_normal(t);
            (normal.dot(&toward) > 0.0).then(|| {
                let corners = layer.mesh.corners(t);
                Face {
                    depth: corners.iter().map(|c| c.dot(&toward)).sum::<Real>(),
                    layer: l,
                    corners: corners.map(|x| place(&x)),
                    shade: (AMBIENT + (1.0 - AMBIENT) * normal.dot(&light).abs()) as f32,
                }
            })
        })
        .collect()
}

/// A colour and depth buffer.
struct Canvas {
    size: (u32, u32),
    /// RGB per pixel, row by row.
    colour: Vec<[f32; 3]>,
    /// Depth toward the viewer per pixel (−∞: background).
    depth: Vec<f32>,
}

impl Canvas {
    /// A white canvas.
    fn new(size: (u32, u32)) -> Self {
        let n = size.0 as usize * size.1 as usize;
        Self {
            size,
            colour: vec![[1.0; 3]; n],
            depth: vec![f32::NEG_INFINITY; n],
        }
    }

    /// Scan-converts the triangle with pixel corners `[x, y, depth]`: every pixel whose centre it covers and
    /// where it is nearer than the depth buffer takes `rgb` (opaque: the depth too) or, with `opacity`, is
    /// blended with it (depth unchanged). Edge functions on the bounding box (Pineda 1988), depth interpolated
    /// linearly (orthographic projection).
    fn fill(&mut self, corners: [[f32; 3]; 3], rgb: [f32; 3], opacity: Option<f32>) {
        let [a, b, c] = corners;
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if area.abs() <= f32::EPSILON || !area.is_finite() {
            return;
        }
        let (w, h) = (self.size.0 as f32, self.size.1 as f32);
        let lo = |i: usize| a[i].min(b[i]).min(c[i]);
        let hi = |i: usize| a[i].max(b[i]).max(c[i]);
        // Pixel centres at k + 1/2 inside the box, clipped to the canvas.
        let (x0, x1) = (
            (lo(0) - 0.5).ceil().max(0.0),
            (hi(0) - 0.5).floor().min(w - 1.0),
        );
        let (y0, y1) = (
            (lo(1) - 0.5).ceil().max(0.0),
            (hi(1) - 0.5).floor().min(h - 1.0),
        );
        if x0 > x1 || y0 > y1 {
            return;
        }
        let edge = |p: [f32; 3], q: [f32; 3], x: f32, y: f32| {
            ((q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0])) / area
        };
        for y in y0 as u32..=y1 as u32 {
            let py = y as f32 + 0.5;
            for x in x0 as u32..=x1 as u32 {
                let px = x as f32 + 0.5;
                // Barycentric weights of a, b, c.
                let (wa, wb, wc) = (edge(b, c, px, py), edge(c, a, px, py), edge(a, b, px, py));
                if wa < 0.0 || wb < 0.0 || wc < 0.0 {
                    continue;
                }
                let depth = wa * a[2] + wb * b[2] + wc * c[2];
                let at = y as usize * self.size.0 as usize + x as usize;
                if depth < self.depth[at] {
                    continue;
                }
                match opacity {
                    None => {
                        self.colour[at] = rgb;
                        self.depth[at] = depth;
                    }
                    Some(alpha) => {
                        let old = self.colour[at];
                        self.colour[at] =
                            [0, 1, 2].map(|i| alpha * rgb[i] + (1.0 - alpha) * old[i]);
                    }
                }
            }
        }
    }

    /// The picture reduced by `factor` along each axis, each pixel the mean of its block; `None` when it cannot
    /// be allocated.
    fn downsampled(&self, factor: u32) -> Option<Pixmap> {
        let (width, height) = (self.size.0 / factor, self.size.1 / factor);
        let mut out = Pixmap::new(width, height)?;
        let f = factor as usize;
        let stride = self.size.0 as usize;
        let count = (f * f) as f32;
        for (i, pixel) in out.data_mut().chunks_exact_mut(4).enumerate() {
            let (x, y) = (i % width as usize, i / width as usize);
            let mut sum = [0f32; 3];
            for dy in 0..f {
                for dx in 0..f {
                    let rgb = self.colour[(y * f + dy) * stride + x * f + dx];
                    for (s, v) in sum.iter_mut().zip(rgb) {
                        *s += v;
                    }
                }
            }
            let [r, g, b] = sum.map(|s| (255.0 * s / count).round().clamp(0.0, 255.0) as u8);
            pixel.copy_from_slice(&[r, g, b, 255]);
        }
        Some(out)
    }
}

/// The pictures of a run: the initial shape (`initial`, an STL of the full device) alone, then each of
/// `states` (STLs) over it as a ghost; a vessel's lumen (`lumen`) translucent in every panel, clipped to the
/// device's frame.
///
/// # Errors
/// [`RenderError::Read`] for a mesh that cannot be read, otherwise as [`render`].
pub(crate) fn render_snapshots(
    initial: &Path,
    states: &[PathBuf],
    lumen: Option<&Path>,
    view: View,
    panel_width: u32,
) -> Result<Pixmap, RenderError> {
    let read = |path: &Path| {
        super::stl::read_stl(path).map_err(|source| RenderError::Read {
            path: path.to_path_buf(),
            source,
        })
    };
    let initial = read(initial)?;
    let states = states
        .par_iter()
        .map(|p| read(p))
        .collect::<Result<Vec<_>, _>>()?;
    let lumen = lumen.map(read).transpose()?;
    let layer = |mesh, colour, opacity, frames| Layer {
        mesh,
        colour,
        opacity,
        frames,
    };
    let panels: Vec<Vec<Layer<'_>>> = std::iter::once(None)
        .chain(states.iter().map(Some))
        .map(|state| {
            let mut layers = Vec::new();
            if let Some(lumen) = &lumen {
                layers.push(layer(lumen, LUMEN, 0.25, false));
            }
            match state {
                None => layers.push(layer(&initial, DEVICE, 1.0, true)),
                Some(state) => {
                    layers.push(layer(&initial, GHOST, 0.45, true));
                    layers.push(layer(state, DEVICE, 1.0, true));
                }
            }
            layers
        })
        .collect();
    render(&panels, view, panel_width)
}

/// The number of columns that brings `n` panels of height/width `aspect` closest to a 16:9 picture, among the
/// grids whose empty cells are at most half a row.
fn columns(n: usize, aspect: Real) -> usize {
    let target = (16.0f64 / 9.0).ln();
    (1..=n.max(1))
        .filter(|&c| 2 * (n.div_ceil(c) * c - n) <= c)
        .min_by(|&a, &b| {
            let misfit = |c: usize| {
                let rows = n.div_ceil(c) as Real;
                ((c as Real) / (rows * aspect)).ln() - target
            };
            misfit(a).abs().total_cmp(&misfit(b).abs())
        })
        .unwrap_or(1)
}

/// Writes `pixmap` as a PNG at `path`.
///
/// # Errors
/// [`RenderError::Write`] when encoding or writing fails.
pub(crate) fn write_png(path: &Path, pixmap: &Pixmap) -> Result<(), RenderError> {
    let bytes = pixmap.encode_png().map_err(|e| RenderError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    super::atomic::write_bytes_atomically(path, &bytes).map_err(|e| RenderError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::sphere::sphere;
    use crate::geometry::tube::TubeSettings;

    fn ball(centre: Vec3, radius: Real, segments: usize) -> TriangleMesh {
        let settings = TubeSettings {
            segments_around: segments,
            ..TubeSettings::default()
        };
        sphere(&centre, radius, &settings).expect("sphere")
    }

    /// The darkness `1 − v/255` of the red channel summed over the picture: the covered area in pixels² of a
    /// black layer (each pixel holds the fraction of its sub-pixels the layer covers).
    fn covered_area(pixmap: &Pixmap) -> Real {
        pixmap
            .data()
            .chunks_exact(4)
            .map(|p| 1.0 - Real::from(p[0]) / 255.0)
            .sum()
    }

    /// Source: seen along its polar axis, a UV sphere's silhouette is its equator, the regular m-gon inscribed
    /// in the circle of radius R, of area `(m/2) sin(2π/m) R²`; the frame maps the extent 2R onto the panel's
    /// width over `1 + 2·GAP`, so `R = W / (2 (1 + 2·GAP))` pixels. Tolerance: a sub-pixel is misclassified
    /// only where the outline crosses it; an outline of length L (output pixels) crosses at most about
    /// `2·L·SUPERSAMPLING` sub-pixels of area `1/SUPERSAMPLING²`, so the error is below `2L/SUPERSAMPLING` px²
    /// — 1.1 % here (measured: 7e-5).
    #[test]
    fn a_sphere_covers_its_silhouette_area() {
        let m = 64;
        let mesh = ball(Vec3::zeros(), 3.0, m);
        let layer = Layer {
            mesh: &mesh,
            colour: [0.0; 3],
            opacity: 1.0,
            frames: true,
        };
        let width = 400;
        let pixmap = render(&[vec![layer]], View::Plane(0, 1), width).expect("render");
        let r = Real::from(width) / (2.0 * (1.0 + 2.0 * GAP));
        let m = m as Real;
        let expected = 0.5 * m * (std::f64::consts::TAU / m).sin() * r * r;
        let perimeter = 2.0 * m * (std::f64::consts::PI / m).sin() * r;
        let bound = 2.0 * perimeter / Real::from(SUPERSAMPLING);
        let area = covered_area(&pixmap);
        assert!(
            (area - expected).abs() <= bound,
            "area {area} against {expected} ± {bound}"
        );
        assert!(bound / expected < 1.1e-2);
    }

    /// Source: the depth buffer. A sphere nearer the viewer (view x1–x2 looks down −x3) hides a farther one
    /// where they overlap, whichever is listed first; the farther one shows beside it.
    #[test]
    fn the_nearer_sphere_hides_the_farther() {
        let near = ball(Vec3::new(0.0, 0.0, 5.0), 1.0, 32);
        let far = ball(Vec3::new(0.5, 0.0, -5.0), 1.0, 32);
        let layer = |mesh, colour| Layer {
            mesh,
            colour,
            opacity: 1.0,
            frames: true,
        };
        for order in [[0, 1], [1, 0]] {
            let layers = [layer(&near, [1.0, 0.0, 0.0]), layer(&far, [0.0, 0.0, 1.0])];
            let panel = vec![layers[order[0]], layers[order[1]]];
            let pixmap = render(&[panel], View::Plane(0, 1), 300).expect("render");
            // x = 0.5 (both spheres, the near one in front) and x = 1.25 (the far one only) in the framed
            // extent [−1, 1.5].
            let (w, h) = (pixmap.width(), pixmap.height());
            let at = |x: Real| {
                let u = 0.5 + (x - 0.25) / 2.5 / (1.0 + 2.0 * GAP);
                pixmap
                    .pixel((Real::from(w) * u) as u32, h / 2)
                    .expect("pixel")
            };
            let (front, side) = (at(0.5), at(1.25));
            assert!(front.red() > 100 && front.blue() == 0, "{front:?}");
            assert!(side.blue() > 100 && side.red() == 0, "{side:?}");
        }
    }

    /// Source: Lambert's law as the module docs state it. A square facing the viewer is lit `A + (1 − A)|l·n|`
    /// of its colour (to the rounding of 8 bits); the same square wound the other way faces away and is not
    /// drawn.
    #[test]
    fn a_face_is_lit_by_lambert_and_a_back_face_is_culled() {
        let square = |flip: bool| {
            let mut mesh = TriangleMesh {
                vertices: vec![
                    Vec3::new(0.0, 0.0, 0.0),
                    Vec3::new(1.0, 0.0, 0.0),
                    Vec3::new(1.0, 1.0, 0.0),
                    Vec3::new(0.0, 1.0, 0.0),
                ],
                triangles: vec![[0, 1, 2], [0, 2, 3]],
            };
            if flip {
                mesh.triangles.iter_mut().for_each(|t| t.swap(1, 2));
            }
            mesh
        };
        let toward = View::Plane(0, 1).axes()[2];
        let shade = AMBIENT + (1.0 - AMBIENT) * light(View::Plane(0, 1)).dot(&toward);
        for (flip, expected) in [(false, 255.0 * shade), (true, 255.0)] {
            let mesh = square(flip);
            let layer = Layer {
                mesh: &mesh,
                colour: [1.0; 3],
                opacity: 1.0,
                frames: true,
            };
            let pixmap = render(&[vec![layer]], View::Plane(0, 1), 100).expect("render");
            let pixel = pixmap
                .pixel(pixmap.width() / 2, pixmap.height() / 2)
                .expect("pixel");
            assert!(
                (Real::from(pixel.green()) - expected).abs() <= 0.5,
                "{pixel:?} against {expected}"
            );
        }
    }

    /// Source: "over" compositing. A black layer of opacity ½ over the white background leaves half the white
    /// (127.5, to the rounding of 8 bits); behind an opaque face nothing of it shows.
    #[test]
    fn a_translucent_layer_lets_half_the_background_through() {
        let ghost = ball(Vec3::zeros(), 1.0, 32);
        let wall = ball(Vec3::new(3.0, 0.0, 10.0), 1.0, 32);
        let panel = vec![
            Layer {
                mesh: &ghost,
                colour: [0.0; 3],
                opacity: 0.5,
                frames: true,
            },
            Layer {
                mesh: &wall,
                colour: [1.0; 3],
                opacity: 1.0,
                frames: true,
            },
        ];
        let pixmap = render(&[panel], View::Plane(0, 1), 300).expect("render");
        // The ghost's centre: x = 0 in the framed extent [−1, 4].
        let (w, h) = (pixmap.width(), pixmap.height());
        let x = (Real::from(w) * (0.5 - 1.5 / 5.0 / (1.0 + 2.0 * GAP))).round() as u32;
        let pixel = pixmap.pixel(x, h / 2).expect("pixel");
        assert!((i32::from(pixel.red()) - 128).abs() <= 1, "{pixel:?}");
    }

    #[test]
    fn nothing_to_frame_is_an_error() {
        assert!(matches!(
            render(&[vec![]], View::Axonometric, 100),
            Err(RenderError::Empty)
        ));
        assert!(matches!(
            render(&[], View::Axonometric, 100),
            Err(RenderError::Empty)
        ));
    }

    /// Four square panels make a 2 × 2 grid (a 3 + 1 grid, nearer 16:9, leaves more than half a row empty),
    /// seven tall ones a 4 + 3 grid, four panels five times as wide as high one column.
    #[test]
    fn panels_are_laid_out_near_sixteen_to_nine() {
        assert_eq!(columns(1, 1.0), 1);
        assert_eq!(columns(4, 1.0), 2);
        assert_eq!(columns(7, 1.9), 4);
        assert_eq!(columns(4, 0.2), 1);
    }
}
