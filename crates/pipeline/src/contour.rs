//! `tinsmith contour`: contour lines of a raster's TIN (paper §5), written as GeoJSON or
//! FlatGeobuf by [`tinsmith_formats::write_lines`].
//!
//! The TIN is, in order of precedence: the mesh file given with `--mesh` (its vertices
//! mapped back to grid samples as `tinsmith verify` does, its heights as written); the
//! grid decimated within `--max-error E > 0` (`tinsmith_core::decimate`, whose bound is
//! proved by the verifier in core's tests; it is not re-verified here); or, for
//! `--max-error 0` (the default), the full grid, two triangles per valid cell, built
//! directly ([`tinsmith_contour::ContourMesh::from_grid`]): the same surface decimation at
//! 0 would give, without its cost. A raster wider or taller than `--tile-size` is decimated
//! by the tiled engine instead (a window at a time, in parallel, every tile verified; the
//! same TIN `tinsmith mesh --tile-size` writes), each tile contoured as it is finished and
//! its lines stitched to its neighbours' ([`tinsmith_contour::ContourStitcher`]: the lines
//! of the welded TIN, which is never held), so memory is the lines, not the TIN or the
//! raster.
//! Lines are computed in grid coordinates and mapped to the
//! world position of sample centres through the geotransform, as `tinsmith mesh` writes
//! vertices, so a line through a vertex passes through the mesh file's vertex exactly.
//! With `--simplify D` each line is then simplified by Douglas–Peucker within `D` in those
//! file coordinates ([`tinsmith_contour::simplify_indices`]). GeoJSON is then reprojected
//! to WGS84 unless `--geojson-source-crs`, as `tinsmith mesh` does
//! ([`crate::wgs84::file_crs`]).

use std::path::Path;
use std::time::Instant;

use tinsmith_contour::{
    interval_levels, simplify_indices, sorted_levels, ContourMesh, ContourStitcher, Polyline,
};
use tinsmith_core::{decimate, DecimationOptions, Grid};
use tinsmith_formats::LineFormat;
use tinsmith_georef::readable;
use tinsmith_georef::{Placement, Samples};
use tinsmith_raster::{Raster, RasterInfo};
use tinsmith_tiling::{mesh_tiles, FinishedTile, RasterSource, SinkError, TileOptions, TileSink};
use tinsmith_verify::{GridRef, MeshRef, VerifyOptions};

use crate::error::{bail, Context};
use crate::jobs::ContourJob;
use crate::mesh_file::{expected_orientation, read_mesh_file, sample_positions};
use crate::output_paths::NamingFile;
use crate::output_paths::{check_distinct, check_writable_target};
use crate::wgs84::{file_crs, LineEnd, Pieces};
use crate::Feedback;
use crate::Result;

/// Memory per line segment while contouring and writing: its point in the joiner, the
/// polyline and the file coordinates (measured about 50 bytes on ETOPO5).
const BYTES_PER_SEGMENT: u64 = 64;

/// Builds the TIN, contours it and writes the lines (see the module documentation for
/// which TIN); fails, naming the file, before any work when the output cannot be written
/// or the lines would not fit in memory.
pub fn contour(job: &ContourJob, feedback: &dyn Feedback) -> Result<()> {
    let started = Instant::now();
    if job.offset.is_some() && job.interval.is_none() {
        bail!("--offset shifts --interval levels; with --levels, give the levels themselves");
    }
    let format = LineFormat::from_path(&job.output)?;
    if job.geojson_source_crs && format != LineFormat::GeoJson {
        bail!(
            "{}: --geojson-source-crs applies to GeoJSON output only",
            job.output.display()
        );
    }
    // The --mesh input first: by any path (a link too) it is the most telling refusal.
    if let Some(mesh) = &job.mesh {
        check_distinct(mesh, &job.output, "the --mesh input")?;
    }
    check_writable_target(&job.output, &job.input)?;
    let e = job.max_error.unwrap_or(0.0);
    let size =
        crate::transform_check::check_input_transform(&job.input, job.band, job.pixel_coords)?;
    let tiled = job.mesh.is_none() && e > 0.0 && (size.0 > job.tile_size || size.1 > job.tile_size);
    // A TIN decimated here is shaped for the levels (fewer segments, same bound), so they
    // come from the raster's height range first; a --mesh file's come from its own heights.
    let (contoured, info, source, levels) = if tiled {
        let info = crate::scan::scan_raster(&job.input, job.band, None, feedback)?;
        let levels = levels_for(job, info.min.zip(info.max))?;
        let (contoured, tiles) = tiled_lines(job, e, &info, &levels, feedback)?;
        let source = format!("TIN within {} ({tiles} tiles)", readable(e));
        (contoured, info, source, levels)
    } else {
        untiled_lines(job, e, size)?
    };
    let placement = Placement::new(info.transform(), job.pixel_coords);
    crate::output_paths::note_gcps_unused(&info, job.pixel_coords, feedback);
    let polylines = contoured.lines;

    let (points, ends) = file_lines(job, &placement, polylines);
    let written = write_file_lines(job, format, &info, points, &ends, feedback)?;
    tinsmith_output::mark_finished();

    feedback.note(&format!(
        "{}: {} lines ({} closed), {} segments{} at {} levels from the {} ({} triangles) in {:.2} s",
        job.output.display(),
        written.lines,
        written.closed,
        written.segments,
        job.simplify
            .map(|d| format!(" (simplified within {})", readable(d)))
            .unwrap_or_default(),
        levels.len(),
        source,
        contoured.triangles,
        started.elapsed().as_secs_f64()
    ));
    if written.lines == 0 {
        if let Some((lo, hi)) = contoured.height_range {
            let why = if levels.is_empty() {
                "no level of the --interval lies within the TIN's heights"
            } else if levels.iter().all(|&l| l < lo || l > hi) {
                "the levels miss the TIN's heights"
            } else {
                "no level crosses the TIN (ground that only touches a level makes no \
                 line, and lines too small to keep a point apart are dropped); its heights"
            };
            feedback.note(&format!(
                "{}: no line: {why}, {} .. {}",
                job.output.display(),
                readable(lo),
                readable(hi)
            ));
        }
    }
    Ok(())
}

/// The lines of a raster that fits one tile (or of a `--mesh` file, or of the full grid),
/// with the raster's metadata, a word on which TIN they were drawn on, and the levels; the
/// whole raster is held, so the run is refused first when it would not fit in memory.
fn untiled_lines(
    job: &ContourJob,
    e: f64,
    size: (u32, u32),
) -> Result<(Contoured, RasterInfo, String, Vec<f64>)> {
    let (need, what, instead) = match &job.mesh {
        Some(mesh) => (
            crate::memory::Need {
                bytes_per_sample: 24,
                extra_bytes: crate::memory::mesh_file_memory(
                    mesh,
                    crate::mesh_file::mesh_format(mesh, job.mesh_format)?,
                ),
            },
            "contouring a --mesh",
            "contour it with --max-error instead (decimated tile by tile, in bounded memory)",
        ),
        None => {
            let (what, instead) = if e == 0.0 {
                (
                    "contouring the full grid",
                    "give --max-error > 0 (decimated tile by tile, in bounded memory)",
                )
            } else {
                (
                    "contouring in one tile (the raster fits --tile-size)",
                    "give a smaller --tile-size",
                )
            };
            let need = crate::memory::Need {
                bytes_per_sample: 120,
                extra_bytes: 0,
            };
            (need, what, instead)
        }
    };
    crate::memory::check_whole_raster_fits(&job.input, size, need, what, instead)?;
    let raster = tinsmith_raster::read_samples(&job.input, job.band)?;
    let (mesh, source, levels, info) = untiled_tin(job, e, raster)?;
    // The lines are held whole before writing: refuse levels that would not fit.
    let segments = mesh.segment_count(&levels);
    crate::memory::check_fits(
        segments.saturating_mul(BYTES_PER_SEGMENT),
        |needed, available| {
            lines_refusal(
                job,
                levels.len(),
                &format!("about {segments} times"),
                needed,
                available,
            )
        },
    )?;
    let lines = tinsmith_contour::contour(&mesh, &levels)
        .with_context(|| format!("{}: contouring failed", job.input.display()))?;
    let contoured = Contoured {
        lines,
        triangles: mesh.triangles().len(),
        height_range: mesh.height_range(),
    };
    Ok((contoured, info, source, levels))
}

/// The lines in the file's coordinates (sample centres through the geotransform, or
/// pixels), the level as z for a reprojection, simplified within `--simplify`; with each
/// line's end in the points, its level and whether it is closed.
fn file_lines(
    job: &ContourJob,
    placement: &Placement,
    polylines: Vec<Polyline>,
) -> (Vec<[f64; 3]>, Vec<LineEnd>) {
    // Grid coordinates -> file coordinates, with the level as z for the reprojection, then
    // --simplify. A north-up raster flips orientation; reverse so the high ground stays on
    // the left in file coordinates.
    let flip = placement.flips_orientation();
    let mut points: Vec<[f64; 3]> =
        Vec::with_capacity(polylines.iter().map(|l| l.points().len()).sum());
    let mut ends = Vec::with_capacity(polylines.len());
    for mut line in polylines {
        if flip {
            line.reverse();
        }
        let level = line.level();
        let closed = line.is_closed();
        let start = points.len();
        points.extend(line.points().iter().map(|&p| {
            let [x, y] = placement.file_point(p);
            [x, y, level]
        }));
        if let Some(tolerance) = job.simplify {
            let file: Vec<[f64; 2]> = points[start..].iter().map(|p| [p[0], p[1]]).collect();
            let kept = simplify_indices(&file, tolerance);
            let count = kept.len();
            // Indices only grow, so the kept points move down in place.
            for (k, i) in kept.into_iter().enumerate() {
                points[start + k] = points[start + i];
            }
            points.truncate(start + count);
        }
        ends.push((points.len(), level, closed));
    }
    (points, ends)
}

/// How many lines, closed rings and segments [`write_file_lines`] wrote.
struct Written {
    lines: usize,
    closed: usize,
    segments: usize,
}

/// Writes the lines (`points` in file coordinates, `ends` as [`file_lines`] gives them):
/// GeoJSON reprojected to WGS84 unless `--geojson-source-crs` (and cut at the
/// antimeridian), repeated points dropped.
fn write_file_lines(
    job: &ContourJob,
    format: LineFormat,
    info: &RasterInfo,
    points: Vec<[f64; 3]>,
    ends: &[LineEnd],
    feedback: &dyn Feedback,
) -> Result<Written> {
    let mut points = points;
    let wgs84 = format == LineFormat::GeoJson && !job.geojson_source_crs;
    let crs = file_crs(
        info,
        job.pixel_coords,
        wgs84,
        &mut points,
        Pieces::Lines(ends),
        &job.output,
        feedback,
    )?;
    if format == LineFormat::GeoJson && crs.epsg == Some(4326) {
        crate::wgs84::snap_to_antimeridian(&mut points);
    }
    let (points, ends) = without_repeated_points(points, ends);
    let closed = ends.iter().filter(|&&(_, _, closed)| closed).count();
    let mut start = 0;
    let lines: Vec<(&[[f64; 2]], f64)> = ends
        .iter()
        .map(|&(end, level, _)| {
            let line = (&points[start..end], level);
            start = end;
            line
        })
        .collect();
    let mut segments = points.len() - lines.len();
    if format == LineFormat::GeoJson && crs.epsg == Some(4326) {
        // RFC 7946 (the coordinates are longitude, latitude): longitudes in [-180, 180],
        // lines cut where they cross the antimeridian.
        let cut: Vec<(Vec<Vec<[f64; 2]>>, f64)> = lines
            .iter()
            .map(|&(line, level)| (tinsmith_formats::cut_at_antimeridian(line), level))
            .filter(|(parts, _)| !parts.is_empty())
            .collect();
        let parts: Vec<Vec<&[[f64; 2]]>> = cut
            .iter()
            .map(|(parts, _)| parts.iter().map(Vec::as_slice).collect())
            .collect();
        segments = parts.iter().flatten().map(|part| part.len() - 1).sum();
        let lines: Vec<(&[&[[f64; 2]]], f64)> = parts
            .iter()
            .zip(&cut)
            .map(|(parts, &(_, level))| (parts.as_slice(), level))
            .collect();
        tinsmith_formats::write_multilines(&job.output, format, &lines, crs)?;
    } else {
        tinsmith_formats::write_lines(&job.output, format, &lines, crs)?;
    }
    Ok(Written {
        lines: lines.len(),
        closed,
        segments,
    })
}

/// The lines (`ends`: each line's end in `points`, its level, whether it is a closed ring)
/// in the file's coordinates without consecutive repeated points: crossings a hair's breadth
/// apart in the grid (a sample within rounding of a level) can land on the same map
/// coordinate. A line left with fewer than two points, or a ring with fewer than three
/// distinct ones, is dropped (gdal_contour writes none there either). Takes `points` so that
/// they are freed before the lines are written.
fn without_repeated_points(
    points: Vec<[f64; 3]>,
    ends: &[LineEnd],
) -> (Vec<[f64; 2]>, Vec<LineEnd>) {
    let mut kept: Vec<[f64; 2]> = Vec::with_capacity(points.len());
    let mut kept_ends = Vec::with_capacity(ends.len());
    let mut start = 0;
    for &(end, level, closed) in ends {
        let first = kept.len();
        for p in &points[start..end] {
            let p = [p[0], p[1]];
            if kept.len() == first || kept[kept.len() - 1] != p {
                kept.push(p);
            }
        }
        let line = &kept[first..];
        let enough = match closed {
            // Three distinct points: one that is neither the first nor the next other one.
            true => line
                .iter()
                .find(|&&p| p != line[0])
                .is_some_and(|&second| line.iter().any(|&p| p != line[0] && p != second)),
            false => line.len() >= 2,
        };
        if enough {
            kept_ends.push((kept.len(), level, closed));
        } else {
            kept.truncate(first);
        }
        start = end;
    }
    (kept, kept_ends)
}

/// The levels to contour: `--levels`, or `--interval` levels over the height range `lo,
/// hi` (none without a range).
fn levels_for(job: &ContourJob, range: Option<(f64, f64)>) -> Result<Vec<f64>> {
    match job.interval {
        Some(interval) => match range {
            Some((lo, hi)) => {
                interval_levels(interval, job.offset.unwrap_or(0.0), lo, hi).naming_file(&job.input)
            }
            None => Ok(Vec::new()),
        },
        None => Ok(sorted_levels(&job.levels)?),
    }
}

/// The TIN to contour from the whole raster in memory, with a word on where it came from,
/// the levels and the raster's metadata: the `--mesh` file (levels over its heights), the
/// full grid for `e = 0`, or the grid decimated within `e > 0` and shaped for the levels
/// (over the raster's heights). The grid takes the raster's samples over.
fn untiled_tin(
    job: &ContourJob,
    e: f64,
    raster: Raster,
) -> Result<(ContourMesh, String, Vec<f64>, RasterInfo)> {
    if let Some(path) = &job.mesh {
        let placement = Placement::new(raster.info.transform(), job.pixel_coords);
        let format = crate::mesh_file::mesh_format(path, job.mesh_format)?;
        let mesh = mesh_from_file(path, format, &raster, placement, job.band)?;
        let levels = levels_for(job, mesh.height_range())?;
        return Ok((mesh, "mesh file".to_owned(), levels, raster.info));
    }
    let Raster { samples, info, .. } = raster;
    let levels = levels_for(job, info.min.zip(info.max))?;
    if samples.valid_cell_count() == 0 {
        return Err(nothing_to_contour(job));
    }
    if e == 0.0 {
        let mesh = ContourMesh::from_grid(samples.width(), samples.height(), samples.values())
            .naming_file(&job.input)?;
        return Ok((mesh, "full grid".to_owned(), levels, info));
    }
    let options = DecimationOptions::new(e).with_contour_levels(&levels);
    let grid = &Grid::from_samples(samples);
    let tin = decimate(grid, &options).naming_file(&job.input)?.tin;
    let vertices = tin
        .vertices()
        .iter()
        .map(|v| [v.x as f64, v.y as f64, v.z])
        .collect();
    let mesh = ContourMesh::new(vertices, tin.triangles().to_vec())
        .with_context(|| format!("{}: decimated TIN", job.input.display()))?;
    Ok((mesh, format!("TIN within {}", readable(e)), levels, info))
}

/// Contour lines and what they were drawn on: the TIN's triangle count and height range.
struct Contoured {
    lines: Vec<Polyline>,
    triangles: usize,
    height_range: Option<(f64, f64)>,
}

/// The refusal for lines that would not fit in memory: `crossing` says how often the
/// levels cross the TIN.
fn lines_refusal(
    job: &ContourJob,
    levels: usize,
    crossing: &str,
    needed: f64,
    available: f64,
) -> String {
    format!(
        "{}: the {levels} levels cross the TIN {crossing}; the lines would need about \
         {needed:.1} GB and {available:.1} GB is available; give a larger --interval or fewer \
         --levels (or a larger --max-error)",
        job.input.display(),
    )
}

/// The lines of a raster larger than `--tile-size`: decimated within `e` and shaped for
/// `levels` by the tiled engine (windowed reads, in parallel, each tile verified), each
/// tile contoured as it is finished and its lines stitched to its neighbours' through
/// their shared edges (the lines `contour` gives on the welded TIN, which is never held).
/// Returns them with the number of tiles.
fn tiled_lines(
    job: &ContourJob,
    e: f64,
    info: &RasterInfo,
    levels: &[f64],
    feedback: &dyn Feedback,
) -> Result<(Contoured, usize)> {
    let source = RasterSource::new(info)?;
    let options = TileOptions::new(DecimationOptions::new(e).with_contour_levels(levels))
        .with_tile_size(job.tile_size)
        .with_threads(job.threads.map_or(0, |n| n as usize));
    let mut sink = StitchingSink {
        stitcher: ContourStitcher::new(levels).naming_file(&job.input)?,
        levels,
        triangles: 0,
        height_range: None,
        stopped: None,
        job,
    };
    feedback.tiles_start("tiles");
    let mut progress = |p: tinsmith_tiling::TileProgress| {
        feedback.tiles_done(p.done as u64, p.total as u64);
    };
    let report = mesh_tiles(&source, &options, &mut sink, &mut progress);
    feedback.tiles_end();
    if let Some(stopped) = sink.stopped.take() {
        return Err(stopped);
    }
    let report = report.naming_file(&job.input)?;
    if report.final_triangles == 0 {
        return Err(nothing_to_contour(job));
    }
    let contoured = Contoured {
        lines: sink.stitcher.finish(),
        triangles: sink.triangles,
        height_range: sink.height_range,
    };
    Ok((contoured, report.plan.len()))
}

/// Contours each finished tile and stitches its lines to the earlier tiles', holding the
/// lines but not the TIN; stops the run once the lines would outgrow the memory available.
struct StitchingSink<'a> {
    stitcher: ContourStitcher,
    levels: &'a [f64],
    triangles: usize,
    height_range: Option<(f64, f64)>,
    /// Why the run was stopped (lines that would not fit, or a contouring failure), for the
    /// caller to report as is.
    stopped: Option<crate::Error>,
    job: &'a ContourJob,
}

/// Bytes a held crossing takes while tiles are still coming (its edge and point).
const BYTES_PER_HELD_CROSSING: u64 = 24;

impl StitchingSink<'_> {
    fn contour_tile(&mut self, tile: &FinishedTile) -> Result<()> {
        let input = self.job.input.display();
        let vertices = tile
            .vertices()
            .iter()
            .map(|v| [f64::from(v.x), f64::from(v.y), v.z])
            .collect();
        let mesh = ContourMesh::new(vertices, tile.triangles().to_vec())
            .with_context(|| format!("{input}: contouring failed"))?;
        // The lines will need BYTES_PER_SEGMENT a segment by the time they are written, of
        // which the held crossings already take their share. The memory available is read
        // again for every tile: the engine's threads and tiles in flight take some too.
        let held = self.stitcher.crossings_held();
        let segments = held + mesh.segment_count(self.levels);
        let needed = segments.saturating_mul(BYTES_PER_SEGMENT);
        let in_use = held * BYTES_PER_HELD_CROSSING;
        if let Some(available) = tinsmith_tiling::available_bytes() {
            if needed > available.saturating_add(in_use) {
                bail!(
                    "{}",
                    lines_refusal(
                        self.job,
                        self.levels.len(),
                        &format!("about {segments} times or more"),
                        needed as f64 / 1e9,
                        (available + in_use) as f64 / 1e9,
                    )
                );
            }
        }
        self.stitcher
            .add(&mesh, tile.ids())
            .with_context(|| format!("{input}: contouring failed"))?;
        self.triangles += mesh.triangles().len();
        if let Some((lo, hi)) = mesh.height_range() {
            let (l, h) = self.height_range.unwrap_or((lo, hi));
            self.height_range = Some((l.min(lo), h.max(hi)));
        }
        Ok(())
    }
}

impl TileSink for StitchingSink<'_> {
    fn tile(&mut self, tile: &FinishedTile) -> std::result::Result<(), SinkError> {
        self.contour_tile(tile).map_err(|e| {
            let message = e.chain_text();
            self.stopped = Some(e);
            message.into()
        })
    }
}

/// The error for a band without a valid 2x2 block of samples.
fn nothing_to_contour(job: &ContourJob) -> crate::Error {
    crate::Error::Refused(format!(
        "{}: band {} has no 2x2 block of valid samples, so there is nothing to contour",
        job.input.display(),
        job.band
    ))
}

/// Reads a mesh file written from `raster` (as `tinsmith verify` reads it: GeoJSON in
/// WGS84 back to the raster's CRS) and maps its vertices back to grid positions, one
/// vertex per position, with its sample's height (or its raised height, see below).
///
/// The mesh must be a TIN of this raster and band: every vertex's height is its sample's
/// (within a millionth of the sample's magnitude or the mesh's height range, for text
/// rounded by other tools; for STL and glTF, which store `f32` offsets from a local
/// origin, within 2^-23 of the range more), or, off the raster's outer rows and columns,
/// that raised by one amount for all (`mesh --vertex-heights raised`: in an f64 format to
/// within f64 rounding, however small the raise; in STL and glTF beyond and within their
/// rounding; such vertices keep the file's height), and the verifier finds it a valid
/// triangulation of the domain (no triangle over nodata, no gap, no overlap; GeoJSON and
/// FlatGeobuf triangles may be wound either way). Otherwise its lines would not be the
/// raster's.
fn mesh_from_file(
    path: &Path,
    format: tinsmith_formats::MeshFormat,
    raster: &Raster,
    placement: Placement,
    band: usize,
) -> Result<ContourMesh> {
    let grid: &Samples = &raster.samples;
    let file = read_mesh_file(path, format, &raster.info, placement)?;
    let (lo, hi) = file
        .vertices
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v[2]), hi.max(v[2]))
        });
    // STL and glTF store heights as float32 offsets from a local origin within the mesh's
    // height range: off by up to range * 2^-24 (twice that allowed). Text written by
    // other tools may round to about six decimals or significant digits: a millionth of
    // the sample's magnitude or of the range is allowed for that, far below any DEM's
    // precision. A vertex within it takes its sample's height.
    let float32 = format.is_float32();
    let range = if hi >= lo { hi - lo } else { 0.0 };
    let slack = if float32 {
        range / f64::from(1u32 << 23)
    } else {
        0.0
    };
    // Each file vertex's sample, as its row-major index.
    let mut samples: Vec<u64> = Vec::with_capacity(file.vertices.len());
    // Each file vertex's height: its sample's, or the file's where it is raised.
    let mut file_heights: Vec<f64> = Vec::with_capacity(file.vertices.len());
    let mut first_raise: Option<f64> = None;
    let at = sample_positions(path, &file, format, &raster.info, placement)?;
    let is_inner = |x: i64, y: i64| {
        (1..grid.width() as i64 - 1).contains(&x) && (1..grid.height() as i64 - 1).contains(&y)
    };
    // A file in an f64 format whose inner vertices off their samples are all above them
    // by one amount, to within the f64 rounding of height + raise, was raised by `mesh`
    // (by a hair, possibly less than the tolerance below); those vertices keep the file's
    // heights, the TIN that was measured within the bound. Heights rounded by another
    // tool scatter both ways and are taken as their samples.
    let magnitude = lo.abs().max(hi.abs());
    let exact_spread = 16.0 * f64::EPSILON * magnitude;
    let common_raise = if float32 {
        None
    } else {
        let mut excess = (f64::INFINITY, f64::NEG_INFINITY);
        let mut below = false;
        for (v, &[x, y]) in file.vertices.iter().zip(&at) {
            if !is_inner(x, y) {
                continue;
            }
            let sample = grid.values()[y as usize * grid.width() as usize + x as usize];
            let d = v[2] - sample;
            if d > 0.0 {
                excess = (excess.0.min(d), excess.1.max(d));
            } else if d < 0.0 {
                below = true;
            }
        }
        (!below && excess.0 <= excess.1 && excess.1 - excess.0 <= exact_spread).then_some(excess.0)
    };
    for (i, (v, &[x, y])) in file.vertices.iter().zip(&at).enumerate() {
        if !(0..grid.width() as i64).contains(&x) || !(0..grid.height() as i64).contains(&y) {
            bail!(
                "{}: vertex {i} is at column {x}, row {y}, outside the {} x {} raster",
                path.display(),
                grid.width(),
                grid.height()
            );
        }
        let sample = grid.values()[y as usize * grid.width() as usize + x as usize];
        let tolerance = slack + 1e-6 * sample.abs().max(range);
        // Raised heights (off the raster's outer rows and columns) are all the same amount
        // above their samples: `common_raise` in an f64 format, else (float32, whose
        // rounding hides a small raise) the first one's beyond the rounding.
        let inner = is_inner(x, y);
        let raised = inner
            && v[2] > sample
            && match common_raise {
                Some(raise) => (v[2] - sample - raise).abs() <= exact_spread,
                None => {
                    float32 && (v[2] - sample).abs() > tolerance && {
                        let raise = *first_raise.get_or_insert(v[2] - sample);
                        (v[2] - sample - raise).abs() <= 2.0 * tolerance
                    }
                }
            };
        // False for a NaN sample (nodata under a vertex) too.
        let matches = !raised && (v[2] - sample).abs() <= tolerance;
        if !matches && !raised {
            bail!(
                "{}: vertex {i} at column {x}, row {y} has height {}, but band {band} of {} \
                 has {} there (more than {:.2e} apart): `contour --mesh` needs a TIN of this \
                 raster and band{}{}",
                path.display(),
                v[2],
                raster.info.path.display(),
                sample,
                tolerance,
                if raster.info.band_count > 1 {
                    " (written from another band? give that one with --band)"
                } else {
                    ""
                },
                if matches!(placement, Placement::Pixel) {
                    " (or was it written without --pixel-coords?)"
                } else {
                    " (or was it written with --pixel-coords?)"
                }
            );
        }
        samples.push(y as u64 * u64::from(grid.width()) + x as u64);
        file_heights.push(if raised { v[2] } else { sample });
    }
    if file.triangles.is_empty() {
        bail!("{}: the mesh has no triangles", path.display());
    }
    // One vertex per sample, numbered in row-major order: files that repeat a vertex for
    // every triangle using it (unindexed glTF, STL, a PLY written triangle by triangle)
    // share it again, so lines join across every edge, and the lines come out the same
    // whatever order the file lists its vertices in.
    let mut used = samples.clone();
    used.sort_unstable();
    used.dedup();
    let width = u64::from(grid.width());
    let positions: Vec<[i64; 2]> = used
        .iter()
        .map(|&s| [(s % width) as i64, (s / width) as i64])
        .collect();
    let index: Vec<u32> = samples
        .iter()
        .map(|s| used.binary_search(s).expect("every sample is listed") as u32)
        .collect();
    // Copies of one vertex (repeated per triangle) carry the same height: the last wins.
    let mut heights = vec![0.0; used.len()];
    for (&i, &z) in index.iter().zip(&file_heights) {
        heights[i as usize] = z;
    }
    let mut triangles: Vec<[u32; 3]> = file
        .triangles
        .iter()
        .map(|t| t.map(|v| index[v as usize]))
        .collect();
    let orientation = expected_orientation(&placement);
    crate::mesh_file::orient_polygon_triangles(format, &positions, &mut triangles, orientation);
    let options = VerifyOptions::new().with_orientation(orientation);
    let report = tinsmith_verify::verify(
        GridRef::new(grid.width(), grid.height(), grid.values()),
        MeshRef::new(&positions, &heights, &triangles),
        &options,
    )
    .with_context(|| format!("{}: cannot check the mesh", path.display()))?;
    if !report.mesh_is_valid() {
        bail!(
            "{}: not a valid triangulation of band {band} of {}'s domain ({}); see \
             `tinsmith verify`",
            path.display(),
            raster.info.path.display(),
            report.problems.join("; ")
        );
    }
    let vertices = positions
        .iter()
        .zip(&heights)
        .map(|(&[x, y], &z)| [x as f64, y as f64, z])
        .collect();
    ContourMesh::new(vertices, triangles)
        .with_context(|| format!("{}: cannot contour this mesh", path.display()))
}
