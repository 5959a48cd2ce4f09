//! The picture: a base layer per pixel (hillshade, error colours, or both), the TIN's
//! edges stroked over it, and the error legend.

use tiny_skia::{LineCap, Paint, PathBuilder, Pixmap, Stroke, Transform};

use crate::colour::diverging;
use crate::hillshade::hillshade;
use crate::legend::{draw_error_legend, Canvas};
use crate::PreviewError;

/// The largest picture side drawn, in pixels.
const MAX_SIZE: u32 = 16_384;

/// Where nodata shows: a light grey.
const NODATA: [u8; 3] = [236, 236, 236];

/// The TIN's edges: dark blue, mostly opaque.
const EDGE: [u8; 4] = [16, 38, 92, 210];

/// The samples a picture of a `width x height` grid shows, `size` pixels on its longer
/// side: each pixel shows the sample nearest its centre, so a picture smaller than the
/// grid shows a sparse lattice of it (every `samples_per_pixel`-th sample or so) and a
/// larger one every sample, several pixels each. Only these samples need to be read.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnSamples {
    /// Samples across and down of the whole grid.
    pub grid: [u32; 2],
    /// Pixels across and down.
    pub pixels: [u32; 2],
    /// The grid columns shown, strictly increasing.
    pub columns: Vec<u32>,
    /// The grid rows shown, strictly increasing.
    pub rows: Vec<u32>,
    /// Grid samples per pixel along each axis (below 1 when the picture is larger).
    pub samples_per_pixel: f64,
    /// Pixels per grid sample spacing.
    pixels_per_sample: f64,
    /// For each pixel column, its place in `columns`.
    pixel_columns: Vec<u32>,
    /// For each pixel row, its place in `rows`.
    pixel_rows: Vec<u32>,
}

impl DrawnSamples {
    /// The samples a picture of `size` pixels on its longer side shows of a
    /// `width x height` grid.
    ///
    /// # Errors
    /// [`PreviewError::Size`] for a size below 16 or above 16,384; [`PreviewError::Scene`]
    /// for an empty grid.
    pub fn new(width: u32, height: u32, size: u32) -> Result<DrawnSamples, PreviewError> {
        if !(16..=MAX_SIZE).contains(&size) {
            return Err(PreviewError::Size {
                size,
                max: MAX_SIZE,
            });
        }
        if width == 0 || height == 0 {
            return Err(PreviewError::Scene(format!(
                "a {width} x {height} grid has no sample to draw"
            )));
        }
        // Pixels per sample spacing: the longer side of the grid becomes `size` pixels.
        let scale = f64::from(size) / f64::from(width.max(height));
        let pixels = |n: u32| ((f64::from(n) * scale).round() as u32).clamp(1, size);
        let (pw, ph) = (pixels(width), pixels(height));
        let sample_of = |p: u32, n: u32| (((f64::from(p) + 0.5) / scale) as u32).min(n - 1);
        let lattice = |count: u32, n: u32| {
            let mut picked: Vec<u32> = Vec::new();
            let mut place = Vec::with_capacity(count as usize);
            for p in 0..count {
                let sample = sample_of(p, n);
                if picked.last() != Some(&sample) {
                    picked.push(sample);
                }
                place.push(picked.len() as u32 - 1);
            }
            (picked, place)
        };
        let (columns, pixel_columns) = lattice(pw, width);
        let (rows, pixel_rows) = lattice(ph, height);
        Ok(DrawnSamples {
            grid: [width, height],
            pixels: [pw, ph],
            columns,
            rows,
            samples_per_pixel: 1.0 / scale,
            pixels_per_sample: scale,
            pixel_columns,
            pixel_rows,
        })
    }

    /// Samples shown: `columns.len() * rows.len()`.
    pub fn len(&self) -> usize {
        self.columns.len() * self.rows.len()
    }

    /// Whether no sample is shown (never, for a lattice [`DrawnSamples::new`] made).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The grid spacing between neighbouring shown samples, across and down, on average.
    fn spacing(&self) -> [f64; 2] {
        let mean = |picked: &[u32]| match picked {
            [first, .., last] => f64::from(last - first) / (picked.len() - 1) as f64,
            _ => 1.0,
        };
        [mean(&self.columns), mean(&self.rows)]
    }
}

/// A raster, seen at the samples a picture shows, and its TIN.
#[derive(Debug, Clone, Copy)]
pub struct Scene<'a> {
    /// The samples shown.
    pub drawn: &'a DrawnSamples,
    /// The shown samples' values, row-major over `drawn.rows` x `drawn.columns`; NaN for
    /// nodata.
    pub values: &'a [f64],
    /// Sample spacing `[east-west, north-south]` of the whole grid in the heights' unit
    /// (the second negative for a north-up raster), for the hillshade.
    pub resolution: [f64; 2],
    /// Each vertex's sample `[column, row]` in the whole grid.
    pub positions: &'a [[i64; 2]],
    /// Vertex indices of each triangle.
    pub triangles: &'a [[u32; 3]],
    /// The TIN's height at each shown sample (NaN where no triangle covers it), for the
    /// error map: `tinsmith_verify::surface_at`.
    pub surface: Option<&'a [f64]>,
}

/// What the picture shows.
#[derive(Debug, Clone, PartialEq)]
pub struct Layers {
    /// The raster as a hillshade (grey), or under the error colours.
    pub hillshade: bool,
    /// The TIN's edges.
    pub wireframe: bool,
    /// The signed error TIN − raster in colours from `-bound` (blue) to `+bound` (red),
    /// with a legend: `Some(bound)`, which must be positive.
    pub error: Option<f64>,
    /// The legend's title (`error, TIN - raster`).
    pub title: String,
}

/// A picture: opaque RGBA pixels, row-major from the top-left.
#[derive(Debug, Clone, PartialEq)]
pub struct Picture {
    /// Pixels across.
    pub width: u32,
    /// Pixels down.
    pub height: u32,
    /// Raster samples per pixel along each axis (below 1 when the picture is larger than
    /// the raster).
    pub samples_per_pixel: f64,
    /// `width * height * 4` bytes, alpha always 255.
    pub rgba: Vec<u8>,
}

/// Draws `scene` with `layers` at the size its [`DrawnSamples`] were chosen for. The
/// hillshade is computed over the shown samples (neighbours a lattice step apart), so it
/// shows the relief at the picture's scale.
///
/// # Errors
/// [`PreviewError::Scene`] when the slices do not fit the shown samples (values,
/// surface), a triangle names a missing vertex, or the error layer lacks the surface or a
/// positive bound.
pub fn render(scene: &Scene<'_>, layers: &Layers) -> Result<Picture, PreviewError> {
    let drawn = scene.drawn;
    let (w, h) = (drawn.columns.len(), drawn.rows.len());
    let samples = drawn.len();
    if scene.values.len() != samples {
        return Err(PreviewError::Scene(format!(
            "{} values for {w} x {h} shown samples",
            scene.values.len()
        )));
    }
    if let Some(bad) = scene
        .triangles
        .iter()
        .flatten()
        .find(|&&i| i as usize >= scene.positions.len())
    {
        return Err(PreviewError::Scene(format!(
            "a triangle names vertex {bad} of {}",
            scene.positions.len()
        )));
    }
    let errors = match (layers.error, scene.surface) {
        (None, _) => None,
        (Some(bound), Some(surface)) if bound > 0.0 && surface.len() == samples => {
            Some((bound, surface))
        }
        (Some(bound), _) => {
            return Err(PreviewError::Scene(format!(
                "the error map needs the TIN's height at each of the {samples} shown samples \
                 and a positive bound (got {bound})"
            )))
        }
    };
    let [pw, ph] = drawn.pixels;
    let spacing = drawn.spacing();
    let shade = layers.hillshade.then(|| {
        let resolution = [
            scene.resolution[0] * spacing[0],
            scene.resolution[1] * spacing[1],
        ];
        hillshade(scene.values, w, h, resolution)
    });
    let mut pixmap = Pixmap::new(pw, ph).expect("a picture of 1 to 16,384 pixels a side");
    {
        let data = pixmap.data_mut();
        for (y, &row) in drawn.pixel_rows.iter().enumerate() {
            for (x, &column) in drawn.pixel_columns.iter().enumerate() {
                let k = row as usize * w + column as usize;
                let colour = base_colour(
                    scene.values[k],
                    shade.as_deref().map(|s| s[k]),
                    errors.map(|(b, s)| (b, s[k])),
                );
                let at = (y * pw as usize + x) * 4;
                data[at..at + 3].copy_from_slice(&colour);
                data[at + 3] = 255;
            }
        }
    }
    if layers.wireframe {
        stroke_edges(&mut pixmap, scene, drawn.pixels_per_sample);
    }
    let mut rgba = pixmap.take();
    if let Some((bound, _)) = errors {
        let mut canvas = Canvas {
            rgba: &mut rgba,
            width: pw,
            height: ph,
        };
        draw_error_legend(&mut canvas, bound, &layers.title);
    }
    Ok(Picture {
        width: pw,
        height: ph,
        samples_per_pixel: drawn.samples_per_pixel,
        rgba,
    })
}

/// A pixel's colour from its sample: nodata grey; else the error colour (shaded when the
/// hillshade is on), the hillshade's grey, or a plain light grey.
fn base_colour(value: f64, shade: Option<f32>, error: Option<(f64, f64)>) -> [u8; 3] {
    if !value.is_finite() {
        return NODATA;
    }
    let light = shade.map(|s| f64::from(s) / 255.0);
    match error {
        Some((bound, tin)) if tin.is_finite() => {
            let c = diverging((tin - value) / bound);
            let f = light.map_or(1.0, |l| 0.45 + 0.55 * l);
            c.map(|v| (f64::from(v) * f).round() as u8)
        }
        Some(_) => NODATA,
        None => match light {
            Some(l) => {
                let g = (l * 255.0).round() as u8;
                [g, g, g]
            }
            None => [210, 210, 210],
        },
    }
}

/// Strokes every edge of the TIN once, one pixel wide, anti-aliased.
fn stroke_edges(pixmap: &mut Pixmap, scene: &Scene<'_>, scale: f64) {
    let mut edges: Vec<(u32, u32)> = scene
        .triangles
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let point = |i: u32| {
        let p = scene.positions[i as usize];
        (
            ((p[0] as f64 + 0.5) * scale) as f32,
            ((p[1] as f64 + 0.5) * scale) as f32,
        )
    };
    let mut path = PathBuilder::new();
    for (a, b) in edges {
        let (pa, pb) = (point(a), point(b));
        path.move_to(pa.0, pa.1);
        path.line_to(pb.0, pb.1);
    }
    let Some(path) = path.finish() else {
        return;
    };
    let mut paint = Paint::default();
    paint.set_color_rgba8(EDGE[0], EDGE[1], EDGE[2], EDGE[3]);
    paint.anti_alias = true;
    let stroke = Stroke {
        width: 1.0,
        line_cap: LineCap::Round,
        ..Stroke::default()
    };
    pixmap.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene<'a>(
        drawn: &'a DrawnSamples,
        values: &'a [f64],
        positions: &'a [[i64; 2]],
        triangles: &'a [[u32; 3]],
    ) -> Scene<'a> {
        Scene {
            drawn,
            values,
            resolution: [1.0, -1.0],
            positions,
            triangles,
            surface: None,
        }
    }

    #[test]
    fn edges_darken_the_pixels_they_cross_and_no_others() {
        let values = vec![0.0; 100];
        let positions = [[0, 0], [9, 0], [9, 9], [0, 9]];
        let triangles = [[0, 1, 2], [0, 2, 3]];
        let plain = Layers {
            hillshade: true,
            wireframe: false,
            error: None,
            title: "error".into(),
        };
        let wired = Layers {
            wireframe: true,
            ..plain.clone()
        };
        let drawn = DrawnSamples::new(10, 10, 100).unwrap();
        assert_eq!((drawn.columns.len(), drawn.rows.len()), (10, 10));
        let s = scene(&drawn, &values, &positions, &triangles);
        let a = render(&s, &plain).unwrap();
        let b = render(&s, &wired).unwrap();
        assert_eq!((b.width, b.height, b.samples_per_pixel), (100, 100, 0.1));
        let px = |p: &Picture, x: u32, y: u32| {
            let k = ((y * p.width + x) * 4) as usize;
            [p.rgba[k], p.rgba[k + 1], p.rgba[k + 2]]
        };
        // The diagonal's midpoint, sample (4.5, 4.5): pixel 50, 50.
        assert_ne!(px(&a, 50, 50), px(&b, 50, 50));
        assert!(px(&b, 50, 50)[2] > px(&b, 50, 50)[0]);
        // Inside a triangle, away from every edge.
        assert_eq!(px(&a, 70, 30), px(&b, 70, 30));
        // Same input, same pixels.
        assert_eq!(render(&s, &wired).unwrap(), b);
    }

    #[test]
    fn bad_sizes_and_scenes_are_refused() {
        let values = vec![0.0; 100];
        let positions = [[0, 0], [9, 0], [9, 9]];
        for size in [8, 16_385] {
            assert!(matches!(
                DrawnSamples::new(10, 10, size),
                Err(PreviewError::Size { .. })
            ));
        }
        let drawn = DrawnSamples::new(10, 10, 100).unwrap();
        let s = scene(&drawn, &values, &positions, &[[0, 1, 3]]);
        let layers = Layers {
            hillshade: true,
            wireframe: true,
            error: None,
            title: "error".into(),
        };
        assert!(matches!(render(&s, &layers), Err(PreviewError::Scene(_))));
        let s = scene(&drawn, &values, &positions, &[[0, 1, 2]]);
        let error = Layers {
            error: Some(1.0),
            ..layers.clone()
        };
        assert!(matches!(render(&s, &error), Err(PreviewError::Scene(_))));
        let s = scene(&drawn, &values[..99], &positions, &[[0, 1, 2]]);
        assert!(matches!(render(&s, &layers), Err(PreviewError::Scene(_))));
    }

    #[test]
    fn a_smaller_picture_shows_the_sample_nearest_each_pixel_centre() {
        // 1000 x 250 samples in 100 x 25 pixels: every tenth sample, from the fifth.
        let drawn = DrawnSamples::new(1000, 250, 100).unwrap();
        assert_eq!(drawn.pixels, [100, 25]);
        assert_eq!(
            drawn.columns,
            (0..100).map(|i| i * 10 + 5).collect::<Vec<_>>()
        );
        assert_eq!(drawn.rows, (0..25).map(|i| i * 10 + 5).collect::<Vec<_>>());
        assert_eq!(drawn.samples_per_pixel, 10.0);
        // Larger than the grid: every sample, each on several pixels.
        let drawn = DrawnSamples::new(7, 3, 70).unwrap();
        assert_eq!(drawn.columns, (0..7).collect::<Vec<_>>());
        assert_eq!(drawn.rows, (0..3).collect::<Vec<_>>());
        assert_eq!(drawn.pixels, [70, 30]);
    }
}
