//! `tinsmith mesh` and `tinsmith verify` on point files (LAS/LAZ, XYZ/CSV text): read,
//! merge duplicates, Delaunay-triangulate, decimate with every point within the bound,
//! verify independently, write. Existing TINs (PLY, OBJ, LandXML, FlatGeobuf) go the
//! same way with their own triangles instead of the Delaunay triangulation. Breaklines
//! (`--breaklines`, an OGR line or polygon layer) make it a constrained Delaunay
//! triangulation whose constrained edges the decimator keeps and the verifier checks.

use std::path::Path;
use std::time::Instant;

use serde::Serialize;
use tinsmith_core::{decimate_scatter_constrained, DecimationOptions, Scatter};
use tinsmith_formats::{LocalOrigin, MeshFormat, MeshRef, WriteOptions};
use tinsmith_points::{ClassChoice, PointCloud, ReadOptions};
use tinsmith_verify::{verify_breaklines, verify_points, PointsReport};

use crate::error::{bail, Context};
use crate::jobs::{MeshJob, PointChoices};
use crate::tin_input::{is_tin_input, read_tin};
use crate::Feedback;
use crate::Result;

/// Whether `path` is read as points (by its extension: `.las`, `.laz`, `.xyz`, `.csv`,
/// `.txt`; or an OGR point layer in `.gpkg`, `.shp`, `.fgb`) or as an existing TIN whose
/// vertices are the points (`.ply`, `.obj`, `.xml`, `.fgb`) rather than as a raster.
pub fn is_point_input(path: &Path) -> bool {
    tinsmith_points::is_point_file(path) || is_tin_input(path) || is_ogr_points(path)
}

/// Whether `path` is an OGR point layer read as points: a GeoPackage, Shapefile or
/// FlatGeobuf (by extension) whose first layer holds points (a FlatGeobuf of triangles
/// is a TIN).
fn is_ogr_points(path: &Path) -> bool {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    matches!(ext.as_deref(), Some("gpkg" | "shp" | "fgb")) && tinsmith_raster::is_point_layer(path)
}

/// The points of `path` after the class filter and the duplicates rule, and how many
/// points were merged away. Notes on `feedback` which classes were kept.
fn read(
    path: &Path,
    choices: &PointChoices,
    feedback: &dyn Feedback,
) -> Result<(PointCloud, usize)> {
    let mut options = ReadOptions::default();
    options.classes = choices.classes.clone();
    options.no_withheld = choices.no_withheld;
    if !path_is_las(path) && (choices.classes.is_some() || choices.no_withheld) {
        feedback.note(&format!(
            "{}: --classes and --no-withheld apply to LAS and LAZ only; every point is read",
            path.display()
        ));
    }
    if choices.z_field.is_some() && !is_ogr_points(path) {
        feedback.note(&format!(
            "{}: --z-field applies to OGR point layers only; ignored",
            path.display()
        ));
    }
    let mut cloud = if is_ogr_points(path) {
        let layer = tinsmith_raster::read_point_layer(path, choices.z_field.as_deref())?;
        let mut cloud = tinsmith_points::world_cloud(path, &layer.points)?;
        cloud.crs.wkt = layer.crs_wkt;
        cloud
    } else {
        tinsmith_points::read_points(path, &options)?
    };
    match &cloud.classes {
        ClassChoice::DefaultGround => feedback.note(&format!(
            "{}: ground points only (class 2, the file has some; --classes to choose)",
            path.display()
        )),
        ClassChoice::All if path_is_las(path) => feedback.note(&format!(
            "{}: every class (the file has no ground points)",
            path.display()
        )),
        _ => {}
    }
    let merged = tinsmith_points::dedupe(&mut cloud, choices.duplicates);
    if merged > 0 {
        feedback.note(&format!(
            "{}: {merged} points merged into others at the same x, y (--duplicates {})",
            path.display(),
            duplicates_name(choices.duplicates)
        ));
    }
    Ok((cloud, merged))
}

fn path_is_las(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("las") || e.eq_ignore_ascii_case("laz"))
}

/// The `--duplicates` name of a rule.
pub fn duplicates_name(rule: tinsmith_points::Duplicates) -> &'static str {
    match rule {
        tinsmith_points::Duplicates::Lowest => "lowest",
        tinsmith_points::Duplicates::Highest => "highest",
        tinsmith_points::Duplicates::Mean => "mean",
        tinsmith_points::Duplicates::First => "first",
    }
}

/// The CRS to write: `--crs`, else the file's (a WKT VLR and GeoTIFF keys must agree, by
/// GDAL's `IsSame`), as WKT.
fn resolve_crs(path: &Path, cloud: &PointCloud, given: Option<&str>) -> Result<Option<String>> {
    if let Some(text) = given {
        return Ok(Some(tinsmith_raster::crs_wkt(text)?));
    }
    let geotiff = cloud.crs.geotiff_epsg.map(|c| format!("EPSG:{c}"));
    // The WKT record, when present, is what LAS 1.4 readers take; the GeoTIFF keys must
    // not contradict it.
    match (&cloud.crs.wkt, &geotiff) {
        (Some(wkt), Some(code)) => {
            let same = tinsmith_raster::same_crs(wkt, code)
                || cloud.crs.geotiff_epsg.map(u32::from) == tinsmith_raster::epsg_code(wkt);
            if !same {
                bail!(
                    "{}: the WKT CRS record and the GeoTIFF keys ({code}) name different CRSs; \
                     give the right one with --crs",
                    path.display()
                );
            }
            Ok(Some(wkt.clone()))
        }
        (Some(wkt), None) => Ok(Some(wkt.clone())),
        (None, Some(code)) => Ok(Some(tinsmith_raster::crs_wkt(code)?)),
        (None, None) => Ok(None),
    }
}

/// Every point in world coordinates with its height (after the duplicates rule).
fn world_points(cloud: &PointCloud) -> Vec<[f64; 3]> {
    (0..cloud.xy.len())
        .map(|i| {
            let [x, y] = cloud.world(i);
            [x, y, cloud.z[i]]
        })
        .collect()
}

/// The `--report` JSON of a point run.
#[derive(Debug, Serialize)]
struct PointsMeshReport<'a> {
    input: &'a Path,
    output: &'a Path,
    max_error: f64,
    points_in_file: u64,
    points_read: usize,
    duplicates_merged: usize,
    duplicates_rule: &'static str,
    classes: String,
    lattice_spacing: [f64; 2],
    /// The Delaunay triangulation's triangles (point files).
    #[serde(skip_serializing_if = "Option::is_none")]
    delaunay_triangles: Option<usize>,
    /// The input TIN's triangles (mesh files).
    #[serde(skip_serializing_if = "Option::is_none")]
    input_triangles: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    breaklines: Option<BreaklinesSummary<'a>>,
    /// The `--boundary` file.
    #[serde(skip_serializing_if = "Option::is_none")]
    boundary: Option<&'a Path>,
    #[serde(skip_serializing_if = "Option::is_none")]
    hull_edge_length: Option<f64>,
    /// Points outside the boundary or the `--hull-edge-length` hull: not in the TIN.
    points_outside: usize,
    triangles: usize,
    vertices: usize,
    max_error_bound: f64,
    measured_max_error: f64,
    sweeps: usize,
    removal_attempts: usize,
    seconds: PointsSeconds,
}

/// The breaklines of a point run, in its `--report`.
#[derive(Debug, Serialize)]
struct BreaklinesSummary<'a> {
    file: &'a Path,
    lines: usize,
    /// "the file's" for a layer with Z, else "interpolated from the points".
    heights: &'static str,
    /// Vertices the lines added to the points (their own and crossings).
    vertices_added: usize,
    crossings: usize,
    constrained_edges: usize,
    /// Vertices the lines lock: their own vertices, crossings, and any end, junction or
    /// bend of the constrained edges (never removed).
    locked_vertices: usize,
    /// Segments checked present as chains of mesh edges.
    segments_verified: usize,
}

#[derive(Debug, Serialize)]
struct PointsSeconds {
    read: f64,
    triangulate: f64,
    decimate: f64,
    verify: f64,
    write: f64,
}

/// `tinsmith mesh` on a point file: the TIN within `job.decimation.max_error` of every point (after
/// the duplicates rule), verified independently in memory as the file will hold it, then
/// written; nothing is written when any step fails.
pub(crate) fn mesh_points(job: &MeshJob, feedback: &dyn Feedback) -> Result<()> {
    let input = &job.input;
    let Some(output) = job.output.as_deref() else {
        bail!("{}: point input writes one mesh: give -o", input.display());
    };
    let Some(max_error) = job.decimation.max_error else {
        bail!(
            "{}: point input needs --max-error (count targets are for rasters)",
            input.display()
        );
    };
    if job.per_tile.is_some()
        || job.preview.is_some()
        || job.decimation.contour_interval.is_some()
        || job.vertical_datum.is_some()
    {
        bail!(
            "{}: --per-tile, --preview, --contour-interval and --vertical-datum apply to \
             rasters only",
            input.display()
        );
    }
    refuse_raster_only_choices(input, &job.decimation)?;
    crate::output_paths::check_writable_target(output, input)?;
    let format = crate::format_plan::format(job)?;
    let reserved = crate::mesh::reserve_report(job, Some((output, format)))?;

    let t = Instant::now();
    let tin_input = is_tin_input(input) && !is_ogr_points(input);
    let (cloud, merged, crs, tin) = if tin_input {
        if job.points.classes.is_some() || job.points.no_withheld {
            feedback.note(&format!(
                "{}: --classes and --no-withheld apply to LAS and LAZ only",
                input.display()
            ));
        }
        let (tin, file_crs) = read_tin(input, feedback)?;
        let crs = match job.points.crs.as_deref() {
            Some(text) => Some(tinsmith_raster::crs_wkt(text)?),
            None => file_crs,
        };
        let cloud = tin.cloud.clone();
        (cloud, tin.merged, crs, Some((tin.world, tin.triangles)))
    } else if !is_point_input(input) {
        // A raster with breaklines or a boundary: its valid samples are the points.
        let mut cloud = raster_cloud(input, job.band)?;
        tinsmith_points::dedupe(&mut cloud, job.points.duplicates);
        let crs = match job.points.crs.as_deref() {
            Some(text) => Some(tinsmith_raster::crs_wkt(text)?),
            None => cloud.crs.wkt.clone(),
        };
        (cloud, 0, crs, None)
    } else {
        let (cloud, merged) = read(input, &job.points, feedback)?;
        let crs = resolve_crs(input, &cloud, job.points.crs.as_deref())?;
        (cloud, merged, crs, None)
    };
    let read_seconds = t.elapsed().as_secs_f64();

    let breaklines = match &job.points.breaklines {
        Some(_) if tin_input => bail!(
            "{}: --breaklines applies to point files and rasters, not to a TIN (it keeps its own edges)",
            input.display()
        ),
        Some(path) => Some((path.as_path(), read_layer(path, input, crs.as_deref())?)),
        None => None,
    };
    let boundary = match &job.points.boundary {
        Some(_) if tin_input => bail!(
            "{}: --boundary applies to point files and rasters, not to a TIN (it keeps its own outline)",
            input.display()
        ),
        Some(path) => {
            let layer = read_layer(path, input, crs.as_deref())?;
            if !layer.polygons {
                bail!(
                    "{}: holds lines, not polygons: --boundary takes a polygon layer (the \
                     TIN's outline and holes)",
                    path.display()
                );
            }
            Some((path.as_path(), layer))
        }
        None => None,
    };
    if tin_input && job.points.hull_edge_length.is_some() {
        bail!(
            "{}: --hull-edge-length applies to point files and rasters, not to a TIN (it \
             keeps its own outline)",
            input.display()
        );
    }
    let constrain =
        breaklines.is_some() || boundary.is_some() || job.points.hull_edge_length.is_some();
    let mut cloud = cloud;
    let points_read = cloud.xy.len();

    let t = Instant::now();
    let mut constrained = None;
    let (points, triangles, constrained_edges, line_vertices) = match tin {
        // The TIN's own triangles; its vertices exactly as the file has them.
        Some((world, triangles)) => (world, triangles, Vec::new(), Vec::new()),
        None if !constrain => match tinsmith_points::delaunay(&cloud) {
            Ok(triangles) => (world_points(&cloud), triangles, Vec::new(), Vec::new()),
            Err(e) => bail!("{}: cannot triangulate: {e}", input.display()),
        },
        None => {
            let mut constraints = tinsmith_points::Constraints::default();
            if let Some((_, layer)) = &breaklines {
                constraints.breaklines = &layer.lines;
                constraints.breaklines_have_z = layer.has_z;
            }
            if let Some((_, layer)) = &boundary {
                constraints.boundary = &layer.lines;
                constraints.boundary_has_z = layer.has_z;
            }
            constraints.max_edge_length = job.points.hull_edge_length;
            match tinsmith_points::constrained_delaunay(&mut cloud, &constraints) {
                Ok(mut c) => {
                    let (triangles, edges, line_vertices) = (
                        std::mem::take(&mut c.triangles),
                        std::mem::take(&mut c.edges),
                        std::mem::take(&mut c.line_vertices),
                    );
                    constrained = Some((c, edges.len()));
                    (world_points(&cloud), triangles, edges, line_vertices)
                }
                Err(tinsmith_points::BreaklineError::Points(e)) => {
                    bail!("{}: cannot triangulate: {e}", input.display())
                }
                Err(
                    e @ (tinsmith_points::BreaklineError::BoundaryOutside { .. }
                    | tinsmith_points::BreaklineError::BoundaryCrossed { .. }
                    | tinsmith_points::BreaklineError::Empty),
                ) => {
                    let file = boundary.as_ref().map_or(input.as_path(), |b| b.0);
                    bail!("{}: {e}", file.display())
                }
                Err(e) => {
                    let file = breaklines.as_ref().map_or(input.as_path(), |b| b.0);
                    bail!("{}: {e}", file.display())
                }
            }
        }
    };
    if let Some((c, _)) = constrained.as_ref().filter(|(c, _)| c.dropped > 0) {
        feedback.note(&format!(
            "{}: {} points outside the {} dropped: not in the TIN, not measured",
            input.display(),
            c.dropped,
            if boundary.is_some() {
                "boundary"
            } else {
                "--hull-edge-length hull"
            }
        ));
    }
    // The points the file gave (after the duplicates rule): the breaklines' vertices
    // follow them and are kept, not measured.
    let measured = constrained.as_ref().map_or(points.len(), |(c, _)| c.points);
    let triangulate_seconds = t.elapsed().as_secs_f64();
    let input_triangles = triangles.len();

    let t = Instant::now();
    // Float32 formats store positions and heights relative to the points' middle: the
    // decimator keeps the heights' rounding, measured at every point, off the bound.
    let origin = format.is_float32().then(|| LocalOrigin::of_points(&points));
    let rounding = origin.map_or(0.0, |o| o.height_rounding(&cloud.z));
    if max_error.is_finite() && rounding > 0.0 && rounding >= max_error {
        bail!(
            "{}: float32 rounds heights by up to {rounding}, not less than --max-error \
             {max_error}; write .ply, .obj, .fgb or .xml",
            output.display()
        );
    }
    let options = DecimationOptions::new(max_error - rounding)
        .with_selection(job.decimation.selection)
        .with_error_model(job.decimation.error_model)
        .with_retriangulation(job.decimation.retriangulate)
        .with_order(job.decimation.order);
    let mut options = options;
    options.dp_max_ring = job.decimation.dp_max_ring as usize;
    let PointCloud {
        xy,
        z,
        spacing,
        points_in_file,
        classes,
        ..
    } = cloud;
    let points_total = xy.len();
    let scatter = Scatter::new(xy, z).with_context(|| format!("{}", input.display()))?;
    let (tin, report) = decimate_scatter_constrained(
        &scatter,
        triangles,
        &constrained_edges,
        &line_vertices,
        &options,
    )
    .with_context(|| format!("{}", input.display()))?;
    let decimate_seconds = t.elapsed().as_secs_f64();

    let mut vertices: Vec<[f64; 3]> = tin.vertices().iter().map(|&v| points[v as usize]).collect();
    if let Some(origin) = origin {
        // Verified as the float32 file will hold the positions and heights.
        for v in &mut vertices {
            *v = origin.quantize(*v);
        }
    }
    let t = Instant::now();
    let tolerance = position_tolerance(format, &vertices);
    let mut check = verify_points(
        &points[..measured],
        &vertices,
        tin.triangles(),
        max_error,
        tolerance,
    );
    if let Some((_, layer)) = &breaklines {
        check.breaklines = Some(verify_breaklines(
            &plan_lines(layer),
            &vertices,
            tin.triangles(),
            breakline_tolerance(spacing, tolerance),
        ));
    }
    let verify_seconds = t.elapsed().as_secs_f64();
    if !check.passed() {
        bail!(
            "{}: the mesh failed verification ({}); nothing written",
            input.display(),
            describe(&check)
        );
    }

    let t = Instant::now();
    let mut written = vertices.clone();
    let epsg = None;
    if format == MeshFormat::GeoJson && !job.export.geojson_source_crs {
        let Some(wkt) = crs.as_deref() else {
            bail!(
                "{}: GeoJSON is written in WGS84 and the points have no CRS; give --crs or \
                 --geojson-source-crs",
                input.display()
            );
        };
        tinsmith_raster::to_wgs84(wkt, &mut written)?;
    }
    let wgs84 = format == MeshFormat::GeoJson && !job.export.geojson_source_crs;
    let write_options = WriteOptions::new()
        .with_origin(origin)
        .with_base(job.export.base)
        .with_normals(job.export.normals);
    let mesh = MeshRef::new(&written, tin.triangles())
        .with_crs_wkt(if wgs84 { None } else { crs.as_deref() })
        .with_epsg(if wgs84 { Some(4326) } else { epsg });
    tinsmith_formats::write_mesh_with(output, format, mesh, &write_options)?;
    let crs_written = !wgs84 && crs.as_deref().is_some_and(|w| !w.trim().is_empty());
    crate::output_paths::note_prj_left_beside(output, format, crs_written, feedback);
    let write_seconds = t.elapsed().as_secs_f64();

    feedback.note(&format!(
        "{}: {} points ({} {} triangles) -> {} triangles, {} vertices; largest error \
         {} (bound {max_error}), verified at every point",
        output.display(),
        measured,
        input_triangles,
        if tin_input {
            "input"
        } else if constrained.is_some() {
            "constrained Delaunay"
        } else {
            "Delaunay"
        },
        report.final_triangles,
        report.final_vertices,
        crate::readable(check.max_error),
    ));
    if let (Some((path, layer)), Some((c, edges))) = (&breaklines, &constrained) {
        feedback.note(&format!(
            "{}: {} lines ({} heights), {edges} constrained edges ({} crossings split), \
             every segment a chain of mesh edges",
            path.display(),
            layer.lines.len(),
            if layer.has_z {
                "their own"
            } else {
                "the points'"
            },
            c.crossings
        ));
    }
    let summary = PointsMeshReport {
        input,
        output,
        max_error,
        points_in_file,
        points_read,
        duplicates_merged: merged,
        duplicates_rule: if tin_input {
            "identical copies only"
        } else {
            duplicates_name(job.points.duplicates)
        },
        classes: match classes {
            ClassChoice::All => "all".into(),
            ClassChoice::DefaultGround => "2 (ground, the default)".into(),
            ClassChoice::Listed(list) => format!("{list:?}"),
        },
        lattice_spacing: spacing,
        boundary: boundary.as_ref().map(|b| b.0),
        hull_edge_length: job.points.hull_edge_length,
        points_outside: constrained.as_ref().map_or(0, |(c, _)| c.dropped),
        breaklines: breaklines.as_ref().zip(constrained.as_ref()).map(
            |((path, layer), (c, edges))| BreaklinesSummary {
                file: path,
                lines: layer.lines.len(),
                heights: if layer.has_z {
                    "the file's"
                } else {
                    "interpolated from the points"
                },
                vertices_added: points_total - c.points,
                crossings: c.crossings,
                constrained_edges: *edges,
                locked_vertices: report.locked_vertices,
                segments_verified: check.breaklines.as_ref().map_or(0, |b| b.segments),
            },
        ),
        delaunay_triangles: (!tin_input).then_some(input_triangles),
        input_triangles: tin_input.then_some(input_triangles),
        triangles: report.final_triangles,
        vertices: report.final_vertices,
        max_error_bound: report.max_bound,
        measured_max_error: check.max_error,
        sweeps: report.sweeps,
        removal_attempts: report.attempts,
        seconds: PointsSeconds {
            read: read_seconds,
            triangulate: triangulate_seconds,
            decimate: decimate_seconds,
            verify: verify_seconds,
            write: write_seconds,
        },
    };
    if let Some(reserved) = reserved {
        reserved.write(&serde_json::to_vec_pretty(&summary)?)?;
    }
    tinsmith_output::mark_finished();
    Ok(())
}

/// The valid samples of band `band` of the raster at `path` as points on the sample
/// lattice (x right, y up from the southernmost row), at the samples' centres, with the
/// raster's CRS. Only north-up geotransforms (no rotation) are taken.
fn raster_cloud(path: &Path, band: usize) -> Result<PointCloud> {
    let raster = tinsmith_raster::read_samples(path, band)?;
    let gt = raster
        .info
        .geo_transform
        .unwrap_or([0.0, 1.0, 0.0, 0.0, 0.0, -1.0]);
    if gt[2] != 0.0 || gt[4] != 0.0 || gt[1] <= 0.0 || gt[5] >= 0.0 {
        bail!(
            "{}: --breaklines and --boundary on a raster need a north-up geotransform (no \
             rotation, rows from north to south); warp it first (gdalwarp)",
            path.display()
        );
    }
    let samples = &raster.samples;
    let (w, h) = (samples.width(), samples.height());
    let (mut xy, mut z) = (Vec::new(), Vec::new());
    for row in 0..h {
        for col in 0..w {
            if let Some(v) = samples.get(col, row).filter(|v| v.is_finite()) {
                xy.push([i64::from(col), i64::from(h - 1 - row)]);
                z.push(v);
            }
        }
    }
    let mut crs = tinsmith_points::FileCrs::default();
    crs.wkt = raster.info.crs_wkt.filter(|w| !w.trim().is_empty());
    Ok(PointCloud {
        points_in_file: xy.len() as u64,
        xy,
        z,
        origin: [gt[0] + 0.5 * gt[1], gt[3] + (f64::from(h) - 0.5) * gt[5]],
        spacing: [gt[1], -gt[5]],
        crs,
        classes: ClassChoice::All,
    })
}

/// The breaklines or boundary file at `path` as lines, refused when its CRS is not the
/// points' (`points_crs`, from `input`): such layers are not reprojected.
fn read_layer(
    path: &Path,
    input: &Path,
    points_crs: Option<&str>,
) -> Result<tinsmith_raster::LineLayer> {
    let layer = tinsmith_raster::read_lines(path)?;
    if let (Some(lines), Some(points)) = (layer.crs_wkt.as_deref(), points_crs) {
        if !tinsmith_raster::same_crs(lines, points)
            && tinsmith_raster::epsg_code(lines) != tinsmith_raster::epsg_code(points)
        {
            bail!(
                "{}: its CRS is not the one of {}; reproject the layer to it first \
                 (ogr2ogr -t_srs)",
                path.display(),
                input.display()
            );
        }
    }
    Ok(layer)
}

/// The lines' x, y.
fn plan_lines(layer: &tinsmith_raster::LineLayer) -> Vec<Vec<[f64; 2]>> {
    layer
        .lines
        .iter()
        .map(|l| l.iter().map(|p| [p[0], p[1]]).collect())
        .collect()
}

/// How far a breakline's vertex may be from the mesh vertex that stands for it: half a
/// lattice cell's diagonal (vertices are rounded to the points' lattice), plus the
/// format's position rounding.
fn breakline_tolerance(spacing: [f64; 2], position_tolerance: f64) -> f64 {
    0.5 * spacing[0].hypot(spacing[1]) + position_tolerance
}

/// How far a float32 format may move a position (x, y): its rounding of the TIN's extent,
/// doubled; 0 for formats that keep `f64` positions.
fn position_tolerance(format: MeshFormat, vertices: &[[f64; 3]]) -> f64 {
    if !format.is_float32() {
        return 0.0;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in vertices {
        for a in 0..2 {
            lo[a] = lo[a].min(v[a]);
            hi[a] = hi[a].max(v[a]);
        }
    }
    2.0 * f64::from(f32::EPSILON) * (hi[0] - lo[0]).max(hi[1] - lo[1]).max(0.0)
}

/// What failed, in a line.
fn describe(r: &PointsReport) -> String {
    let mut parts = Vec::new();
    if r.uncovered > 0 {
        parts.push(format!("{} points outside the mesh", r.uncovered));
    }
    if r.bad_triangles > 0 {
        parts.push(format!(
            "{} degenerate or clockwise triangles",
            r.bad_triangles
        ));
    }
    if r.max_error > r.bound {
        if let Some((i, p, s)) = r.worst {
            parts.push(format!(
                "point {i} at ({}, {}) has z {} and the mesh {s}: error {} > {}",
                p[0],
                p[1],
                p[2],
                crate::readable(r.max_error),
                r.bound
            ));
        }
    }
    if let Some(b) = r.breaklines.as_ref().filter(|b| !b.passed()) {
        let [a, e] = b.first_missing.unwrap_or_default();
        parts.push(format!(
            "{} of {} breakline segments are not chains of mesh edges, the first from \
             ({}, {}) to ({}, {})",
            b.missing, b.segments, a[0], a[1], e[0], e[1]
        ));
    }
    parts.join("; ")
}

/// `tinsmith verify` on a point file (or on band `band` of a raster meshed with breaklines
/// or a boundary, its valid samples as points): reads the points (with the same class
/// filter and duplicates rule `mesh` used) and the mesh file, and measures every point against the
/// mesh with the independent verifier. A mesh outside the bound is not an error: see
/// [`PointsReport::passed`].
pub fn verify_points_file(
    points_path: &Path,
    mesh_path: &Path,
    format: Option<MeshFormat>,
    max_error: f64,
    choices: &PointChoices,
    band: usize,
    feedback: &dyn Feedback,
) -> Result<PointsReport> {
    let (points, spacing) = if is_tin_input(points_path) && !is_ogr_points(points_path) {
        if choices.breaklines.is_some() {
            bail!(
                "{}: --breaklines applies to point files and rasters, not to a TIN (it keeps its own edges)",
                points_path.display()
            );
        }
        (read_tin(points_path, feedback)?.0.world, [0.0; 2])
    } else if !is_point_input(points_path) {
        // A raster meshed with breaklines or a boundary: its valid samples are the points.
        let cloud = raster_cloud(points_path, band)?;
        (world_points(&cloud), cloud.spacing)
    } else {
        let cloud = read(points_path, choices, feedback)?.0;
        (world_points(&cloud), cloud.spacing)
    };
    let breaklines = match &choices.breaklines {
        Some(path) => Some(plan_lines(&tinsmith_raster::read_lines(path)?)),
        None => None,
    };
    let outline = match &choices.boundary {
        Some(path) => {
            let layer = tinsmith_raster::read_lines(path)?;
            if !layer.polygons {
                bail!(
                    "{}: holds lines, not polygons: --boundary takes a polygon layer",
                    path.display()
                );
            }
            Some(plan_lines(&layer))
        }
        None => None,
    };
    let format = crate::mesh_file::mesh_format(mesh_path, format)?;
    if format == MeshFormat::GeoJson {
        bail!(
            "{}: verify reads point meshes from PLY, OBJ, STL, glTF, FlatGeobuf or LandXML \
             (GeoJSON is in WGS84)",
            mesh_path.display()
        );
    }
    let mesh = tinsmith_formats::read_mesh_as(mesh_path, format)?;
    let tolerance = position_tolerance(format, &mesh.vertices);
    let points: Vec<[f64; 3]> = match &outline {
        // Points outside the boundary are not the TIN's (mesh dropped them).
        Some(rings) => {
            let inside = tinsmith_verify::inside_outline(
                rings,
                &points,
                breakline_tolerance(spacing, tolerance),
            );
            points
                .iter()
                .zip(inside)
                .filter(|(_, i)| *i)
                .map(|(p, _)| *p)
                .collect()
        }
        None => points,
    };
    let mut report = verify_points(
        &points,
        &mesh.vertices,
        &mesh.triangles,
        max_error,
        tolerance,
    );
    if let Some(lines) = breaklines {
        report.breaklines = Some(verify_breaklines(
            &lines,
            &mesh.vertices,
            &mesh.triangles,
            breakline_tolerance(spacing, tolerance),
        ));
    }
    Ok(report)
}

/// Text for a points verification, as `tinsmith verify` prints it.
pub fn points_summary(r: &PointsReport) -> String {
    if r.passed() {
        let lines = r.breaklines.as_ref().map_or(String::new(), |b| {
            format!(", {} breakline segments present", b.segments)
        });
        format!(
            "{} points, largest error {} <= {}{lines}: passed",
            r.points,
            crate::readable(r.max_error),
            r.bound
        )
    } else {
        format!("{} points: FAILED: {}", r.points, describe(r))
    }
}

/// Refuses the decimation choices a triangulation of points does not take, rather than
/// ignoring them: its start is the triangulation itself, with no flips or extended holes.
fn refuse_raster_only_choices(
    input: &std::path::Path,
    choices: &tinsmith_choices::DecimationChoices,
) -> Result<()> {
    use tinsmith_core::InitialMesh;
    let mut refused = Vec::new();
    if !matches!(choices.initial_mesh, InitialMesh::Auto | InitialMesh::Full) {
        refused.push("--initial-mesh (points start from their whole triangulation)");
    }
    if choices.flip_rounds > 0 {
        refused.push("--flip-rounds");
    }
    if choices.extend_rounds > 0 {
        refused.push("--extend-rounds");
    }
    if !refused.is_empty() {
        bail!(
            "{}: {} apply to rasters meshed on their grid only; points, TINs and rasters \
             with --breaklines, --boundary or --hull-edge-length are decimated from their \
             triangulation",
            input.display(),
            refused.join(", ")
        );
    }
    Ok(())
}
