//! Mesh files read back onto the raster they were written from, for `verify` and
//! `contour --mesh`: the format, WGS84 GeoJSON transformed back, each vertex mapped to the
//! sample it stands on within its format's rounding, polygon triangles wound as the grid
//! expects.

use std::path::Path;
use tinsmith_raster::VerticalDatum;

use tinsmith_formats::{Mesh, MeshFormat};
use tinsmith_georef::{Placement, PositionError};
use tinsmith_raster::{Raster, RasterInfo};
use tinsmith_verify::Orientation;

use crate::error::Context;
use crate::Result;

/// Reads a mesh file written from `raster` in its file coordinates: RFC 7946 GeoJSON
/// (WGS84 longitude, latitude) is transformed back to the raster's CRS.
///
/// Longitudes in WGS84 files are in [-180, 180] (RFC 7946); for a geographic raster they
/// are moved by whole turns into the raster's own range (0..360 for many global grids).
pub fn read_mesh_file(
    path: &Path,
    format: MeshFormat,
    raster: &RasterInfo,
    placement: Placement,
) -> Result<Mesh> {
    let mut mesh = tinsmith_formats::read_mesh_as(path, format)?;
    let polygons = is_polygon_format(format);
    // A GIS rewrite may keep WGS84 as WKT alone (a shapefile's GCS_WGS_1984).
    if polygons
        && mesh.epsg.is_none()
        && mesh.crs_wkt != raster.crs_wkt
        && mesh
            .crs_wkt
            .as_deref()
            .is_some_and(tinsmith_raster::is_wgs84_lon_lat)
    {
        mesh.epsg = Some(4326);
    }
    if let (Some(4326), Placement::World(transform), Some(wkt)) =
        (mesh.epsg, placement, raster.crs_wkt.as_deref())
    {
        if transformed_from_wgs84(&mesh, raster, placement) {
            tinsmith_raster::from_wgs84(wkt, &mut mesh.vertices).with_context(|| {
                format!(
                    "{}: cannot transform WGS84 back to the raster's CRS",
                    path.display()
                )
            })?;
        }
        if tinsmith_raster::is_geographic(wkt)? {
            if polygons {
                // Placing triangles around the raster's seam needs them counter-clockwise
                // in longitude, latitude, as tinsmith writes them.
                counter_clockwise_in_lon_lat(&mut mesh);
            }
            into_raster_frame(&mut mesh, raster, transform);
        }
    }
    Ok(mesh)
}

/// The sample (column, row) under each vertex of `mesh`, read from `path` in `format`;
/// fails naming the first vertex that is not on a sample centre, to within the rounding
/// of the format's positions (see [`position_tolerance`]), or whose sample lies outside
/// the raster (a mesh of another raster whose lattice this one's extends): either way the
/// mesh is not one of this raster, and nothing is measured.
pub fn sample_positions(
    path: &Path,
    mesh: &Mesh,
    format: MeshFormat,
    raster: &RasterInfo,
    placement: Placement,
) -> Result<Vec<[i64; 2]>> {
    let tolerance = position_tolerance(format, mesh, raster, placement);
    // Other tools rewrite RFC 7946 GeoJSON with 7 decimals (ogr2ogr's default), about
    // 1 cm: too coarse for the mesh's vertices to name their samples on fine rasters.
    let wgs84 = transformed_from_wgs84(mesh, raster, placement);
    let (width, height) = (raster.width, raster.height);
    let outside = |i: usize, [x, y]: [i64; 2]| {
        crate::Error::Refused(format!(
            "{}: vertex {i} is at column {x}, row {y} of {}'s sample lattice, outside its \
             {width} x {height} samples: the mesh is not of this raster (another raster's \
             on the same lattice, or another extent) and cannot be measured against it",
            path.display(),
            raster.path.display()
        ))
    };
    let inside = |[x, y]: [i64; 2]| {
        (0..i64::from(width)).contains(&x) && (0..i64::from(height)).contains(&y)
    };
    mesh.vertices
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let p = [v[0], v[1]];
            let at = placement.sample_at(p, tolerance).map_err(|e| {
                if !matches!(e, PositionError::NearMiss { .. }) {
                    return crate::Error::Refused(format!("{}: vertex {i}: {e:#}", path.display()));
                }
                let ogr2ogr = match wgs84 {
                    true => {
                        " (ogr2ogr writes RFC 7946 GeoJSON with 7 decimals unless given -lco \
                         COORDINATE_PRECISION=15)"
                    }
                    false => "",
                };
                crate::Error::Refused(format!(
                    "{}: vertex {i}: {e:#}: the file's positions were changed after it was \
                     written, and the mesh is measured as written{ogr2ogr}",
                    path.display()
                ))
            })?;
            if inside(at) {
                Ok(at)
            } else {
                Err(outside(i, at))
            }
        })
        .collect()
}

/// How far (in pixels) a vertex of `mesh`, read in `format`, may be from its sample
/// centre: the rounding of float32 positions for STL and glTF, of the transforms for a
/// GeoJSON file in WGS84 read back into a projected raster's CRS, else of `f64`. A vertex
/// further off is not taken for its sample: verify measures the mesh as written.
pub fn position_tolerance(
    format: MeshFormat,
    mesh: &Mesh,
    raster: &RasterInfo,
    placement: Placement,
) -> f64 {
    use tinsmith_georef::{F32_SAMPLE_TOLERANCE, F64_SAMPLE_TOLERANCE, WGS84_SAMPLE_TOLERANCE};
    if format.is_float32() {
        F32_SAMPLE_TOLERANCE
    } else if transformed_from_wgs84(mesh, raster, placement) {
        WGS84_SAMPLE_TOLERANCE
    } else {
        F64_SAMPLE_TOLERANCE
    }
}

/// Whether [`read_mesh_file`] transforms `mesh`'s vertices from WGS84 into the raster's
/// CRS: a WGS84 mesh, world coordinates, and a raster with a CRS of its own other than
/// EPSG:4326.
fn transformed_from_wgs84(mesh: &Mesh, raster: &RasterInfo, placement: Placement) -> bool {
    mesh.epsg == Some(4326)
        && matches!(placement, Placement::World(_))
        && raster.epsg != Some(4326)
        && raster.crs_wkt.is_some()
}

/// Moves longitudes read from RFC 7946 GeoJSON (in [-180, 180]) by whole turns into a
/// geographic raster's own frame (0..360 for many global grids), triangle by triangle:
/// the whole triangle by the shift that puts it inside the raster's extent, counter-
/// clockwise, when there is one; otherwise a corner outside the raster's extent into
/// [west, west + 360), then, of the placements with corners a turn further east where that
/// stays within the raster (the east edge of a grid whose first and last columns are the
/// same meridian), the counter-clockwise one spanning the fewest degrees; corners are then
/// welded again by position.
fn into_raster_frame(
    mesh: &mut Mesh,
    raster: &RasterInfo,
    transform: tinsmith_georef::GeoTransform,
) {
    let (w, h) = (f64::from(raster.width), f64::from(raster.height));
    let xs: Vec<f64> = [
        (-0.5, -0.5),
        (w - 0.5, -0.5),
        (-0.5, h - 0.5),
        (w - 0.5, h - 0.5),
    ]
    .into_iter()
    .map(|(x, y)| transform.sample_centre(x, y)[0])
    .collect();
    let west = xs.iter().copied().fold(f64::INFINITY, f64::min);
    let east = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let base = |lon: f64| {
        if lon < west || lon > east {
            west + (lon - west).rem_euclid(360.0)
        } else {
            lon
        }
    };
    let mut welded: std::collections::HashMap<[u64; 3], u32> = Default::default();
    let mut vertices: Vec<[f64; 3]> = Vec::with_capacity(mesh.vertices.len());
    let ccw = |lons: [f64; 3], corners: &[[f64; 3]; 3]| {
        let [a, b, c] = [0, 1, 2].map(|k| [lons[k], corners[k][1]]);
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0.0
    };
    for triangle in &mut mesh.triangles {
        let corners = triangle.map(|i| mesh.vertices[i as usize]);
        // The writers move each triangle (or cut part) as a whole by turns into
        // [-180, 180]: the whole-turn shift that puts it back inside the raster is the
        // one (a second would need a triangle no wider than the columns the raster
        // repeats). Only when none fits are corners placed one by one.
        let whole = [0.0, 1.0, -1.0, 2.0, -2.0]
            .into_iter()
            .map(|turns| corners.map(|v| v[0] + 360.0 * turns))
            .find(|lons| lons.iter().all(|&l| l >= west && l <= east) && ccw(*lons, &corners));
        let placed = whole.unwrap_or_else(|| {
            let lons = corners.map(|v| base(v[0]));
            // Of the placements (each corner as is, or a turn east if that stays within
            // the raster), the counter-clockwise one (as written) spanning the fewest
            // degrees.
            let mut best: Option<(f64, [f64; 3])> = None;
            for turns in 0..8u32 {
                let placed = [0, 1, 2].map(|k| lons[k] + 360.0 * f64::from((turns >> k) & 1));
                if placed.iter().any(|&lon| lon > east) || !ccw(placed, &corners) {
                    continue;
                }
                let span = placed.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                    - placed.iter().copied().fold(f64::INFINITY, f64::min);
                if best.is_none_or(|(s, _)| span < s) {
                    best = Some((span, placed));
                }
            }
            best.map_or(lons, |(_, placed)| placed)
        });
        for (index, lon) in triangle.iter_mut().zip(placed) {
            let v = mesh.vertices[*index as usize];
            let p = [lon, v[1], v[2]];
            *index = *welded.entry(p.map(f64::to_bits)).or_insert_with(|| {
                vertices.push(p);
                (vertices.len() - 1) as u32
            });
        }
    }
    mesh.vertices = vertices;
}

/// The format of the mesh file at `path`: `given` (a `--format` option), or the one its
/// extension names.
pub fn mesh_format(path: &Path, given: Option<MeshFormat>) -> Result<MeshFormat> {
    match given {
        Some(format) => Ok(format),
        None => Ok(MeshFormat::from_path(path)?),
    }
}

/// Whether `format` is GeoJSON or FlatGeobuf: triangles stored as polygons, whose winding
/// says nothing (see [`orient_polygon_triangles`]).
fn is_polygon_format(format: MeshFormat) -> bool {
    matches!(format, MeshFormat::GeoJson | MeshFormat::FlatGeobuf)
}

/// Reverses every triangle when most are clockwise in longitude, latitude as written (a
/// file wound the other way round, as shapefiles wind polygons). Triangle by triangle the
/// winding cannot be told near the raster's seam or a pole, where a triangle may span
/// more than half a turn; across the file it can.
fn counter_clockwise_in_lon_lat(mesh: &mut Mesh) {
    let (mut cw, mut ccw) = (0usize, 0usize);
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| mesh.vertices[v as usize]);
        let area_x2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if area_x2 < 0.0 {
            cw += 1;
        } else if area_x2 > 0.0 {
            ccw += 1;
        }
    }
    if cw > ccw {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
}

/// Turns each triangle of a GeoJSON or FlatGeobuf mesh (`positions` on the grid) to
/// `orientation`: those formats hold triangles as polygons, whose winding says nothing
/// (RFC 7946 asks readers not to reject rings against its right-hand rule; shapefiles wind
/// them clockwise), so a triangle wound the other way is the same triangle. Other formats
/// are left as they are: their winding says which way a face points.
pub fn orient_polygon_triangles(
    format: MeshFormat,
    positions: &[[i64; 2]],
    triangles: &mut [[u32; 3]],
    orientation: Orientation,
) {
    if !is_polygon_format(format) {
        return;
    }
    for t in triangles {
        let [a, b, c] = t.map(|v| positions[v as usize].map(i128::from));
        let area_x2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if area_x2.signum() == -orientation.sign() {
            t.swap(1, 2);
        }
    }
}

/// Mesh files hold triangles counter-clockwise in file coordinates (normals up), which is
/// clockwise in grid coordinates when the georeference flips orientation.
pub fn expected_orientation(placement: &Placement) -> Orientation {
    if placement.flips_orientation() {
        Orientation::Clockwise
    } else {
        Orientation::CounterClockwise
    }
}

/// A mesh file read back onto the raster it was made from: the raster, each vertex's
/// sample, its height as the file holds it, and the triangles wound as the grid expects.
pub(crate) struct MeshOnRaster {
    pub(crate) raster: Raster,
    pub(crate) positions: Vec<[i64; 2]>,
    pub(crate) heights: Vec<f64>,
    pub(crate) triangles: Vec<[u32; 3]>,
    /// The winding expected in grid coordinates.
    pub(crate) orientation: Orientation,
    /// The file's per-vertex attributes (PLY's other vertex properties).
    pub(crate) attributes: Vec<(String, Vec<f64>)>,
}

/// Band `band` of `input` read whole, its heights converted from `datum` to heights
/// above the ellipsoid when given.
pub(crate) fn read_raster(
    input: &Path,
    band: usize,
    datum: Option<&VerticalDatum>,
) -> Result<tinsmith_raster::Raster> {
    let datum = datum.unwrap_or(&VerticalDatum::Ellipsoid);
    Ok(tinsmith_raster::read_samples_on(input, band, datum)?)
}

/// A reader of windows of band `band` of `input`, its heights converted from `datum` to
/// heights above the ellipsoid when given.
pub(crate) fn window_reader(
    input: &Path,
    band: usize,
    datum: Option<&VerticalDatum>,
) -> Result<tinsmith_raster::WindowReader> {
    let datum = datum.unwrap_or(&VerticalDatum::Ellipsoid);
    Ok(tinsmith_raster::WindowReader::open_on(input, band, datum)?)
}

/// Reads band `band` of `input` whole and the mesh file `mesh` (in `format`) onto it, as
/// `verify` measures it: see [`read_onto_lattice`].
pub(crate) fn read_onto_raster(
    input: &Path,
    band: usize,
    datum: Option<&VerticalDatum>,
    mesh: &Path,
    format: MeshFormat,
    pixel_coords: bool,
) -> Result<MeshOnRaster> {
    let raster = read_raster(input, band, datum)?;
    let on = read_onto_lattice(&raster.info, mesh, format, pixel_coords)?;
    Ok(MeshOnRaster {
        raster,
        positions: on.positions,
        heights: on.heights,
        triangles: on.triangles,
        orientation: on.orientation,
        attributes: on.attributes,
    })
}

/// A mesh file's vertices on a raster's sample lattice, without the samples.
pub(crate) struct MeshOnLattice {
    pub(crate) positions: Vec<[i64; 2]>,
    pub(crate) heights: Vec<f64>,
    pub(crate) triangles: Vec<[u32; 3]>,
    /// The winding expected in grid coordinates.
    pub(crate) orientation: Orientation,
    /// The file's per-vertex attributes, in vertex order.
    pub(crate) attributes: Vec<(String, Vec<f64>)>,
}

/// Reads the mesh file `mesh` (in `format`) onto the lattice of the raster `info`
/// describes, as `verify` measures it: the transform checked, WGS84 transformed back,
/// every vertex mapped to its sample (a vertex off the lattice or outside the raster is
/// refused), polygon triangles wound as the grid expects. Reads no sample.
pub(crate) fn read_onto_lattice(
    info: &RasterInfo,
    mesh: &Path,
    format: MeshFormat,
    pixel_coords: bool,
) -> Result<MeshOnLattice> {
    crate::transform_check::check_transform(info, pixel_coords)?;
    let placement = Placement::new(info.transform(), pixel_coords);
    let mut read = read_mesh_file(mesh, format, info, placement)?;
    let attributes = std::mem::take(&mut read.attributes);
    let positions = sample_positions(mesh, &read, format, info, placement)?;
    let heights: Vec<f64> = read.vertices.iter().map(|v| v[2]).collect();
    let orientation = expected_orientation(&placement);
    let mut triangles = read.triangles;
    orient_polygon_triangles(format, &positions, &mut triangles, orientation);
    Ok(MeshOnLattice {
        positions,
        heights,
        triangles,
        orientation,
        attributes,
    })
}
