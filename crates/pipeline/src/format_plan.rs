//! How a mesh run writes each format: the format and its choices, the float32 origin
//! and the tighter bound that keeps the promise in float32 files (WGS84 for GeoJSON is
//! [`crate::wgs84`]'s).

use std::path::Path;

use serde::Serialize;
use tinsmith_core::Grid;
use tinsmith_formats::{LocalOrigin, MeshFormat, MeshRef, VertexAttribute, WriteOptions};
use tinsmith_georef::readable;
use tinsmith_georef::Placement;
use tinsmith_raster::RasterInfo;

use crate::error::{bail, Context};
use crate::jobs::MeshJob;
use crate::output_paths::NamingFile;
use crate::wgs84::{
    check_no_fold_in_lon_lat, check_wgs84_maps_back, check_wgs84_mesh_possible, file_crs,
    is_geographic, projected_crs, snap_to_antimeridian, Pieces,
};
use crate::Feedback;
use crate::Result;

/// Largest rounding of a float32 position, in pixels, accepted before decimating: 90 % of
/// the 1e-3 pixel within which the verifier maps file positions to samples. Half a float32
/// step is 2^-24 of the offset, so rasters up to about 30,000 samples across pass.
const MAX_POSITION_ROUNDING_PX: f64 = 9e-4;

/// The format `mesh` writes: `--format` or the extension; fails when a format-specific
/// flag is given for another format.
pub fn format(job: &MeshJob) -> Result<MeshFormat> {
    let format = match job.export.format {
        Some(format) => format,
        None => MeshFormat::from_path(out(job))?,
    };
    let e = &job.export;
    let misplaced = [
        (e.base.is_some(), "--base", MeshFormat::Stl),
        (e.normals, "--normals", MeshFormat::Glb),
        (
            e.geojson_source_crs,
            "--geojson-source-crs",
            MeshFormat::GeoJson,
        ),
    ];
    for (given, flag, only) in misplaced {
        if given && format != only {
            bail!(
                "{}: {flag} applies to {only} output only, not {format}",
                out(job).display()
            );
        }
    }
    if let Some(base) = e.base {
        if !base.is_finite() {
            bail!("--base must be a finite number, got {base}");
        }
    }
    Ok(format)
}

/// What the output format needs decided before decimation: the float32 budget. A mesh
/// decimated within `decimation_bound`, with heights as [`FormatPlan::file_height`] gives
/// them, is within the job's `max_error` of every sample in the file itself.
#[derive(Debug, Clone, Copy)]
pub struct FormatPlan {
    /// The format written.
    pub format: MeshFormat,
    /// The float32 formats' origin.
    pub origin: Option<LocalOrigin>,
    /// max |z - stored z| over every valid sample (0 for `f64` formats).
    pub height_rounding: f64,
    /// The bound given to the decimator: `--max-error` less `height_rounding`, so that
    /// the heights as stored are within `--max-error` of every sample.
    pub decimation_bound: f64,
}

/// The float32 part of the `--report` JSON.
#[derive(Debug, Serialize)]
pub struct PlanReport {
    format: &'static str,
    local_origin: Option<[f64; 3]>,
    float32_height_rounding: f64,
    decimation_max_error: f64,
}

impl FormatPlan {
    /// Notes on stderr the float32 formats' origin and height rounding for `output`
    /// (nothing for the double-precision formats).
    pub fn note_origin(&self, output: &Path, feedback: &dyn Feedback) {
        if let Some(origin) = self.origin {
            let [x, y, z] = origin.offset();
            feedback.note(&format!(
                "{}: float32 positions relative to the local origin ({x}, {y}, {z}); \
                 heights round by at most {}",
                output.display(),
                self.height_rounding
            ));
        }
    }

    /// For STL and glTF: the origin in the middle of the raster's file coordinates and
    /// heights, the largest float32 rounding of a height, and the bound left for the
    /// decimator; fails when float32 cannot hold the positions to a sample or the heights
    /// within `max_error`. With the `grid` in memory and vertices at their samples the
    /// rounding is measured at every valid sample; otherwise (the tiled engine, raised
    /// vertex heights) it is bounded from the height range.
    pub fn new(
        format: MeshFormat,
        info: &RasterInfo,
        grid: Option<&Grid>,
        job: &MeshJob,
        feedback: &dyn Feedback,
    ) -> Result<FormatPlan> {
        let max_error = job.decimation.max_error.unwrap_or(f64::INFINITY);
        if format == MeshFormat::GeoJson && !job.export.geojson_source_crs && !job.pixel_coords {
            // Before any work: what `write` would refuse for the raster as a whole.
            check_wgs84_mesh_possible(info, out(job))?;
        }
        // Decimation refuses such heights, whatever the format: say that, not that float32
        // rounds them beyond the bound.
        if let Some(max_abs) = info
            .max_abs_value()
            .filter(|&v| v > tinsmith_core::MAX_ABS_HEIGHT)
        {
            return Err(tinsmith_core::Error::HeightsTooLarge(max_abs)).naming_file(&job.input);
        }
        if !format.is_float32() {
            return Ok(FormatPlan {
                format,
                origin: None,
                height_rounding: 0.0,
                decimation_bound: max_error,
            });
        }
        if let (Some(base), Some(min)) = (job.export.base, info.min) {
            if base >= min {
                bail!(
                    "{}: --base {base} must be below the lowest height ({min})",
                    out(job).display()
                );
            }
        }
        let placement = Placement::new(info.transform(), job.pixel_coords);
        note_degrees_in_a_3d_format(info, &placement, job, feedback)?;
        let (min, max) = extent(info, &placement);
        let origin = LocalOrigin::around(min, max);
        if let Some(base) = job.export.base {
            // The solid's floor is written as float32 like every other coordinate.
            if !((base - origin.offset()[2]) as f32).is_finite() {
                bail!(
                    "{}: --base {base} is beyond the range of the format's float32 coordinates",
                    out(job).display()
                );
            }
        }
        check_position_rounding(info, &placement, origin, min, max, out(job))?;

        // Raised vertex heights are not samples: bound their rounding from the range, up
        // to the highest sample raised (by at most the raise for the whole bound; the
        // decimation's bound is smaller).
        let samples_only = !job.decimation.raises_vertex_heights(info.min.zip(info.max));
        let raise = if samples_only {
            0.0
        } else {
            tinsmith_core::vertex_raise(max_error, info.max_abs_value().unwrap_or(0.0))
        };
        let height_rounding = match grid.filter(|_| samples_only) {
            Some(grid) => origin.height_rounding(grid.values()),
            None => origin.height_rounding_bound(min[2], max[2] + raise),
        };
        let decimation_bound = max_error - height_rounding;
        if decimation_bound < 0.0 {
            bail!(
                "{}: --max-error {} is smaller than the float32 rounding of the heights ({}) \
                 in {format}; use a larger bound or a double-precision format (.ply, .obj, \
                 .fgb, .geojson, .xml)",
                out(job).display(),
                readable(max_error),
                readable(height_rounding)
            );
        }
        Ok(FormatPlan {
            format,
            origin: Some(origin),
            height_rounding,
            decimation_bound,
        })
    }

    /// The height the file will give back for `z`.
    pub fn file_height(&self, z: f64) -> f64 {
        match self.origin {
            Some(origin) => origin.quantize([0.0, 0.0, z])[2],
            None => z,
        }
    }

    /// What goes into the `--report` JSON.
    pub fn report(&self) -> PlanReport {
        PlanReport {
            format: self.format.name(),
            local_origin: self.origin.map(|o| o.offset()),
            float32_height_rounding: self.height_rounding,
            decimation_max_error: self.decimation_bound,
        }
    }
}

/// For STL and glTF, before reading any sample: fails when the raster is too wide for
/// float32 positions (see [`FormatPlan::new`]; the positions depend only on the size and the
/// geotransform, so a huge raster is refused before its statistics scan).
pub fn check_float32_positions(format: MeshFormat, info: &RasterInfo, job: &MeshJob) -> Result<()> {
    if !format.is_float32() {
        return Ok(());
    }
    let placement = Placement::new(info.transform(), job.pixel_coords);
    let (min, max) = extent(info, &placement);
    let origin = LocalOrigin::around(min, max);
    check_position_rounding(info, &placement, origin, min, max, out(job))
}

/// Min and max of the raster's file coordinates (sample centres) and valid heights.
fn extent(info: &RasterInfo, placement: &Placement) -> ([f64; 3], [f64; 3]) {
    let ([x0, y0], [x1, y1]) = placement.extent(info.width, info.height);
    let (mut min, mut max) = ([x0, y0, 0.0], [x1, y1, 0.0]);
    // The statistics of the heights decimation sees (after scale and offset).
    min[2] = info.min.unwrap_or(0.0);
    max[2] = info.max.unwrap_or(0.0);
    (min, max)
}

/// Fails when float32 offsets from `origin` cannot place every sample within
/// [`MAX_POSITION_ROUNDING_PX`] of its centre (a bound: half a float32 step at the largest
/// offset, plus the `f64` roundings, in pixels through the inverse geotransform).
fn check_position_rounding(
    info: &RasterInfo,
    placement: &Placement,
    origin: LocalOrigin,
    min: [f64; 3],
    max: [f64; 3],
    output: &Path,
) -> Result<()> {
    let o = origin.offset();
    let mut world = 0.0f64;
    for axis in 0..2 {
        let offset = (max[axis] - o[axis]).abs().max((min[axis] - o[axis]).abs());
        let magnitude = max[axis].abs().max(min[axis].abs());
        world = world.max(offset * 2f64.powi(-24) + magnitude * 2f64.powi(-51));
    }
    // Pixels per world unit: the inverse geotransform's largest row sum.
    let per_unit = match placement {
        Placement::Pixel => 1.0,
        Placement::World(t) => {
            let c = &t.0;
            let det = (c[1] * c[5] - c[2] * c[4]).abs();
            ((c[5].abs() + c[2].abs()).max(c[4].abs() + c[1].abs())) / det
        }
    };
    let pixels = world * per_unit;
    if !pixels.is_finite() || pixels > MAX_POSITION_ROUNDING_PX {
        bail!(
            "{}: a {}x{} raster is too large for float32 positions relative to one origin \
             (rounding up to {pixels:.2e} pixel); use a double-precision format (.ply, \
             .obj, .fgb, .geojson, .xml)",
            output.display(),
            info.width,
            info.height
        );
    }
    Ok(())
}

/// Writes the mesh (`vertices` in file coordinates, counter-clockwise `triangles`) as the
/// plan's format with the raster's CRS: reprojected to WGS84 for GeoJSON unless
/// `--geojson-source-crs`; a `.prj` sidecar for OBJ, STL and glTF. `attributes` (one
/// value per vertex each) and `colours` go where [`tinsmith_formats::MeshRef`] says.
pub fn write(
    plan: &FormatPlan,
    job: &MeshJob,
    info: &RasterInfo,
    (mut vertices, triangles): (Vec<[f64; 3]>, &[[u32; 3]]),
    (attributes, colours): (&[VertexAttribute<'_>], Option<&[[u8; 3]]>),
    feedback: &dyn Feedback,
) -> Result<()> {
    let path = out(job);
    if plan.format == MeshFormat::FlatGeobuf {
        check_flatgeobuf_fits(path, triangles.len())?;
    }
    let wgs84 = plan.format == MeshFormat::GeoJson && !job.export.geojson_source_crs;
    // A projected raster's positions, to check they come back from WGS84.
    let projected = match wgs84 {
        true => projected_crs(info)?,
        false => None,
    };
    let world = projected.map(|_| vertices.clone());
    let crs = file_crs(
        info,
        job.pixel_coords,
        wgs84,
        &mut vertices,
        Pieces::Mesh,
        path,
        feedback,
    )?;
    if plan.format == MeshFormat::GeoJson && crs.epsg == Some(4326) {
        snap_to_antimeridian(&mut vertices);
    }
    if let (Some(world), Some(crs_of_raster), Some(4326)) = (&world, projected, crs.epsg) {
        check_wgs84_maps_back(world, &vertices, crs_of_raster, path)?;
        check_no_fold_in_lon_lat(&vertices, triangles, path)?;
    }
    if let Some(origin) = plan.origin {
        check_positions_map_back(&vertices, origin, info, job)?;
    }
    let options = WriteOptions::new()
        .with_origin(plan.origin)
        .with_base(job.export.base)
        .with_normals(job.export.normals);
    let mesh = MeshRef::new(&vertices, triangles)
        .with_attributes(attributes)
        .with_colours(colours)
        .with_crs_wkt(crs.wkt)
        .with_epsg(crs.epsg);
    tinsmith_formats::write_mesh_with(path, plan.format, mesh, &options)?;
    let crs_written = crs.wkt.is_some_and(|w| !w.trim().is_empty());
    crate::output_paths::note_prj_left_beside(path, plan.format, crs_written, feedback);
    Ok(())
}

/// Notes that STL and glTF, formats for 3D viewers and printers, get
/// positions in degrees beside heights in metres from a geographic raster: true to the
/// raster, but drawn stretched by about 100,000 vertically.
fn note_degrees_in_a_3d_format(
    info: &RasterInfo,
    placement: &Placement,
    job: &MeshJob,
    feedback: &dyn Feedback,
) -> Result<()> {
    let Placement::World(_) = placement else {
        return Ok(());
    };
    let geographic = match info.crs_wkt.as_deref() {
        Some(wkt) => is_geographic(info, wkt)?,
        None => false,
    };
    if geographic {
        feedback.note(&format!(
            "{}: the raster's CRS is geographic, so x and y are written in degrees and z in \
             its height unit: a 3D viewer draws the TIN stretched (for true proportions, \
             reproject the raster to a projected CRS first, e.g. with gdalwarp -t_srs)",
            out(job).display()
        ));
    }
    Ok(())
}

/// Memory the FlatGeobuf writer takes per triangle on top of the mesh (its spatial index and
/// the features it reorders along the index), rounded up from 136 bytes measured on
/// ETOPO5 (9.4 M triangles) and 153 on a 16384² raster (35.8 M).
const FLATGEOBUF_BYTES_PER_TRIANGLE: u64 = 160;

/// Fails, naming `path`, when writing `triangles` triangles as FlatGeobuf would take more
/// memory than is available (it was killed partway, or took the machine's swap, where a
/// 100 M-triangle mesh needed about 16 GB); the streamed formats need none.
fn check_flatgeobuf_fits(path: &Path, triangles: usize) -> Result<()> {
    let needed = (triangles as u64).saturating_mul(FLATGEOBUF_BYTES_PER_TRIANGLE);
    crate::memory::check_fits(needed, |needed, available| {
        format!(
            "{}: writing {triangles} triangles as FlatGeobuf needs about {needed:.1} GB for \
             its spatial index, and {available:.1} GB is available; write .ply or .obj \
             (streamed to disk), or give a larger --max-error",
            path.display()
        )
    })
}

/// The last gate for float32 files: every stored position maps back to a sample centre
/// as `tinsmith verify` will map it.
fn check_positions_map_back(
    vertices: &[[f64; 3]],
    origin: LocalOrigin,
    info: &RasterInfo,
    job: &MeshJob,
) -> Result<()> {
    let placement = Placement::new(info.transform(), job.pixel_coords);
    for (i, &v) in vertices.iter().enumerate() {
        let q = origin.quantize(v);
        let tolerance = tinsmith_georef::F32_SAMPLE_TOLERANCE;
        placement
            .sample_at([q[0], q[1]], tolerance)
            .with_context(|| {
                format!(
                    "{}: vertex {i} would not map back to its sample in float32; nothing written",
                    out(job).display()
                )
            })?;
    }
    Ok(())
}

/// `--format NAME`.
pub fn parse_format(name: &str) -> std::result::Result<MeshFormat, String> {
    MeshFormat::from_name(name).map_err(|e| e.to_string())
}

/// The output path of a `mesh` run that writes one file (`--per-tile` runs do not come
/// here).
fn out(job: &MeshJob) -> &std::path::Path {
    job.output.as_deref().unwrap_or(std::path::Path::new("-"))
}
