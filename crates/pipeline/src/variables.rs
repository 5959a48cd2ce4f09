//! Several variables over one mesh (`mesh --bands`, `verify --bands`): which bands are the
//! height and the variables with their bounds, reading them onto one grid whose domain is
//! where every band is valid, naming them in files, and measuring each one independently.

use std::path::{Path, PathBuf};

use serde::Serialize;
use tinsmith_core::{Grid, Tin, Variable};
use tinsmith_georef::Samples;
use tinsmith_raster::{RasterInfo, Resampling};
use tinsmith_verify::{GridRef, MeshRef, Orientation, Report, VerifyOptions};

use crate::error::{bail, Context};
use crate::output_paths::NamingFile;
use crate::Result;

/// One band decimated with the height: every sample's value is within `max_error` of the
/// TIN's interpolation of the band's values at its vertices.
#[derive(Debug, Clone, PartialEq)]
pub struct BandVariable {
    /// The band, 1-based.
    pub band: usize,
    /// Its bound (`f64::INFINITY`: carried, never constraining).
    pub max_error: f64,
    /// The raster it is read from when not the input (`--attributes`): used as it is when
    /// on the input's grid (same size, geotransform and CRS), else resampled onto it.
    pub file: Option<PathBuf>,
    /// How `file` is resampled onto the input's grid when it is not on it.
    pub resampling: Resampling,
    /// Set when the band was read: the method that put `file` on the input's grid, or
    /// `None` when it was on it already (or is the input's own band).
    pub resampled: Option<Resampling>,
}

/// `--attributes FILE[:B,B,...]` with `--attribute-error E` (one bound, or one per band):
/// those bands of another raster (all of them without `:bands`) as variables, resampled
/// onto the input's grid by `resampling` when they are not on it.
pub fn attribute_variables(
    spec: &str,
    bounds: &[f64],
    resampling: Resampling,
) -> Result<Vec<BandVariable>> {
    let (path, bands) = match spec.rsplit_once(':') {
        Some((path, list))
            if !path.is_empty() && list.split(',').all(|b| b.trim().parse::<usize>().is_ok()) =>
        {
            let bands: Vec<usize> = list
                .split(',')
                .map(|b| b.trim().parse().unwrap_or(0))
                .collect();
            (PathBuf::from(path), bands)
        }
        Some((path, list))
            if !path.is_empty() && !Path::new(spec).exists() && Path::new(path).exists() =>
        {
            bail!(
                "{path}: --attributes: after the colon comes a comma-separated list of band \
                 numbers (FILE:1,2,3), not \"{list}\""
            );
        }
        _ => {
            let path = PathBuf::from(spec);
            let count = tinsmith_raster::open_info(&path, 1)?.band_count;
            (path, (1..=count).collect())
        }
    };
    let name = path.display();
    if bands.contains(&0) {
        bail!("{name}: --attributes: bands are numbered from 1");
    }
    if let Some((_, &twice)) = bands
        .iter()
        .enumerate()
        .find(|&(i, b)| bands[..i].contains(b))
    {
        bail!("{name}: --attributes lists band {twice} twice");
    }
    if let Some(&bad) = bounds.iter().find(|e| e.is_nan() || **e < 0.0) {
        bail!("{name}: --attribute-error {bad}: every bound must be a number >= 0");
    }
    if bounds.len() != 1 && bounds.len() != bands.len() {
        bail!(
            "{name}: --attribute-error gives {} bounds for {} bands: give one bound for all, \
             or one per band",
            bounds.len(),
            bands.len()
        );
    }
    Ok(bands
        .iter()
        .enumerate()
        .map(|(i, &band)| BandVariable {
            band,
            max_error: if bounds.len() == 1 {
                bounds[0]
            } else {
                bounds[i]
            },
            file: Some(path.clone()),
            resampling,
            resampled: None,
        })
        .collect())
}

/// The height band, its bound and the other bands as variables, from `--bands` (empty:
/// the height alone), the bound list (one bound for every band, or one per band, in the
/// order of `bands`) and `--height-band` (default: the first listed band, which must be
/// listed). Fails, naming `input`, on a repeated band, a band 0, a bound list of another
/// length, or a negative or NaN bound.
pub fn resolve_bands(
    input: &Path,
    bands: &[usize],
    bounds: &[f64],
    height_band: Option<usize>,
) -> Result<(usize, Option<f64>, Vec<BandVariable>)> {
    let name = input.display();
    if let Some(&bad) = bounds.iter().find(|e| e.is_nan() || **e < 0.0) {
        bail!("{name}: --max-error {bad}: every bound must be a number >= 0");
    }
    if bands.is_empty() {
        if bounds.len() > 1 {
            bail!(
                "{name}: {} bounds given to --max-error but no --bands: a list of bounds \
                 goes with a list of bands",
                bounds.len()
            );
        }
        return Ok((
            height_band.unwrap_or(1),
            bounds.first().copied(),
            Vec::new(),
        ));
    }
    if bounds.is_empty() {
        bail!(
            "{name}: --bands takes error bounds (--max-error), not --max-triangles or \
             --max-vertices"
        );
    }
    if bands.contains(&0) {
        bail!("{name}: --bands: bands are numbered from 1");
    }
    if let Some((i, b)) = bands
        .iter()
        .enumerate()
        .find(|&(i, b)| bands[..i].contains(b))
    {
        bail!(
            "{name}: --bands lists band {b} twice (at positions {} and {})",
            bands.iter().position(|x| x == b).map_or(0, |p| p + 1),
            i + 1
        );
    }
    if bounds.len() != 1 && bounds.len() != bands.len() {
        bail!(
            "{name}: --max-error gives {} bounds for the {} bands of --bands: give one bound \
             for all, or one per band",
            bounds.len(),
            bands.len()
        );
    }
    let height = height_band.unwrap_or(bands[0]);
    let Some(at) = bands.iter().position(|&b| b == height) else {
        bail!("{name}: --height-band {height} is not among --bands; list it there with its bound");
    };
    let bound = |i: usize| {
        if bounds.len() == 1 {
            bounds[0]
        } else {
            bounds[i]
        }
    };
    if !bound(at).is_finite() {
        bail!(
            "{name}: the height band's bound must be finite, got {}",
            bound(at)
        );
    }
    let variables = bands
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != at)
        .map(|(i, &band)| BandVariable {
            band,
            max_error: bound(i),
            file: None,
            resampling: Resampling::default(),
            resampled: None,
        })
        .collect();
    Ok((height, Some(bound(at)), variables))
}

/// A variable's band and bound, with the name files give it.
pub(crate) type Named = (BandVariable, String);

/// The variables of a mesh read beside its heights `samples` for checking it (`None`
/// without variables), and the grid the verifier measures: the heights where every band
/// is valid, the domain `mesh --bands` made.
pub(crate) fn read_for_check<'a>(
    input: &Path,
    (samples, info): (&'a Samples, &RasterInfo),
    variables: &[BandVariable],
    joined: &'a mut Option<(Grid, Vec<Named>, bool)>,
) -> Result<GridRef<'a>> {
    if !variables.is_empty() {
        *joined = Some(read(input, (samples.clone(), info), variables, false)?);
    }
    Ok(match joined {
        None => GridRef::new(samples.width(), samples.height(), samples.values()),
        Some((grid, _, _)) => GridRef::new(grid.width(), grid.height(), grid.values()),
    })
}

/// Reads every variable's band of `input` beside the `height` samples already read, into
/// one grid (the domain is where every band is valid), with each variable's band, bound
/// and the name files give it. For a `float32` file each band is decimated within its
/// bound less the largest float32 rounding of its values, so that the values as stored
/// keep the bound; a bound below that rounding is refused. The flag says whether the
/// variables are exactly three 8-bit (`Byte`) bands: written as vertex colours too.
pub(crate) fn read(
    input: &Path,
    height: (Samples, &RasterInfo),
    variables: &[BandVariable],
    float32: bool,
) -> Result<(Grid, Vec<Named>, bool)> {
    let (height, info) = height;
    let mut bytes = 0;
    let mut read = Vec::with_capacity(variables.len());
    let mut names: Vec<String> = Vec::new();
    let mut variables = variables.to_vec();
    for v in &mut variables {
        let raster = match &v.file {
            None => tinsmith_raster::read_samples(input, v.band)?,
            Some(file) => {
                let resampled = on_input_grid(file, v, input, info)?;
                v.resampled = resampled.as_ref().map(|_| v.resampling);
                let path = resampled
                    .as_ref()
                    .map_or(file.as_path(), ResampledFile::path);
                let mut raster = tinsmith_raster::read_samples(path, v.band)
                    .map_err(|e| no_overlap(e, file, input))?;
                raster.info.path = file.clone();
                if let Some(r) = &resampled {
                    // The band's own name, and its type where resampling kept its values
                    // (nearest: three 8-bit bands stay colours).
                    raster.info.description = r.source.description.clone();
                    if v.resampling == Resampling::Nearest {
                        raster.info.data_type = r.source.data_type.clone();
                    }
                }
                raster
            }
        };
        let fallback = match &v.file {
            None => format!("band_{}", v.band),
            Some(file) => format!(
                "{}_band_{}",
                file.file_stem()
                    .map_or("attribute".into(), |s| s.to_string_lossy()),
                v.band
            ),
        };
        let name = property_name(raster.info.description.as_deref(), &fallback, &names);
        bytes += usize::from(raster.info.data_type == "Byte");
        names.push(name);
        let rounding = match float32 {
            true => raster
                .samples
                .values()
                .iter()
                .filter(|x| x.is_finite())
                .fold(0.0f64, |m, &x| m.max((x - f64::from(x as f32)).abs())),
            false => 0.0,
        };
        if rounding > v.max_error {
            bail!(
                "{}: band {}: float32 rounds its values by up to {rounding}, more than its \
                 bound {}; write PLY (double) instead",
                input.display(),
                v.band,
                v.max_error
            );
        }
        read.push(Variable::new(raster.samples, v.max_error - rounding).naming_file(input)?);
    }
    let grid = Grid::with_variables(height, read).naming_file(input)?;
    let rgb = variables.len() == 3 && bytes == 3;
    Ok((grid, variables.into_iter().zip(names).collect(), rgb))
}

/// Refuses what a tiled run with variables does not do: OBJ tiles (`--per-tile
/// --tile-format obj`), formats without per-vertex values, and count targets.
pub(crate) fn check_tiled(job: &crate::MeshJob) -> Result<()> {
    let input = job.input.display();
    if job.per_tile.is_some() {
        if job.tile_format == Some(crate::TileFormat::Obj) {
            bail!(
                "{input}: --per-tile with --bands writes PLY tiles (one property per band); \
                 OBJ carries no variables"
            );
        }
        return Ok(());
    }
    if job.decimation.has_count_target() {
        bail!("{input}: --bands takes error bounds (--max-error), not --max-triangles or --max-vertices");
    }
    let format = crate::format_plan::format(job)?;
    if !format.carries_attributes() {
        bail!(
            "{input}: a raster larger than --tile-size {} is meshed tile by tile, and then \
             --bands writes PLY (.ply), glTF (.glb), GeoJSON or FlatGeobuf (.geojson, \
             .fgb); {format} is not among them (or raise --tile-size to mesh it in one piece)",
            job.tile_size
        );
    }
    Ok(())
}

/// The bound each variable is decimated within in a tiled run: its own, less what float32
/// may round its values by when the file holds them as float32 (`float32`): at most half
/// a unit in the last place of its largest |value| (the band's statistics), 2^-24 of it,
/// since a tiled run never holds a whole band to measure the rounding exactly. Refuses,
/// naming the band, a bound that rounding alone would use up.
pub(crate) fn tiled_variable_errors(
    input: &Path,
    variables: &[Named],
    largest: &[f64],
    float32: bool,
) -> Result<Vec<f64>> {
    variables
        .iter()
        .zip(largest)
        .map(|((v, name), &largest)| {
            if !float32 {
                return Ok(v.max_error);
            }
            let rounding = largest / f64::from(1u32 << 24);
            if rounding >= v.max_error {
                bail!(
                    "{}: band {} ({name}): float32 rounds its values by up to {rounding} \
                     (2^-24 of its largest |value| {largest}), not less than its bound {}; \
                     write PLY (double) instead",
                    input.display(),
                    v.band,
                    v.max_error
                );
            }
            Ok(v.max_error - rounding)
        })
        .collect()
}

/// The variables of a tiled run: the engine's source reading every band, each variable's
/// band, bound and name, each one's largest |value|, and the resampled files the source
/// reads from, to keep until the run ends.
pub(crate) struct TiledVariables {
    pub(crate) source: tinsmith_tiling::RasterSource,
    pub(crate) named: Vec<Named>,
    pub(crate) largest: Vec<f64>,
    pub(crate) resampled: Vec<ResampledFile>,
}

/// The tiled engine's source for `height` with every variable's band (each scanned once
/// for its statistics, windows read per tile).
pub(crate) fn tiled_source(
    input: &Path,
    height: (tinsmith_tiling::RasterSource, &RasterInfo),
    variables: &[BandVariable],
) -> Result<TiledVariables> {
    let (mut source, info) = height;
    let mut names: Vec<String> = Vec::new();
    let mut variables = variables.to_vec();
    let mut kept = Vec::new();
    let mut largest = Vec::new();
    for v in &mut variables {
        let file = v.file.clone().unwrap_or_else(|| input.to_path_buf());
        let band = if v.file.is_some() {
            let resampled = on_input_grid(&file, v, input, info)?;
            v.resampled = resampled.as_ref().map(|_| v.resampling);
            let path = resampled
                .as_ref()
                .map_or(file.clone(), |r| r.path().to_path_buf());
            let description = resampled.as_ref().map(|r| r.source.description.clone());
            kept.extend(resampled);
            let mut band = tinsmith_raster::open_info(&path, v.band)?;
            if let Some(description) = description {
                band.description = description;
            }
            if band.valid_samples == 0 {
                return Err(no_overlap(
                    tinsmith_raster::Error::AllNodata { path, band: v.band },
                    &file,
                    input,
                ));
            }
            band
        } else {
            tinsmith_raster::open_info(&file, v.band)?
        };
        if v.file.is_none() && (band.width, band.height) != (info.width, info.height) {
            bail!(
                "{}: band {} is not the height band's size",
                input.display(),
                v.band
            );
        }
        let fallback = match &v.file {
            None => format!("band_{}", v.band),
            Some(file) => format!(
                "{}_band_{}",
                file.file_stem()
                    .map_or("attribute".into(), |s| s.to_string_lossy()),
                v.band
            ),
        };
        names.push(property_name(
            band.description.as_deref(),
            &fallback,
            &names,
        ));
        largest.push(band.max_abs_value().unwrap_or(0.0));
        source = source.with_variable(&band).naming_file(&file)?;
    }
    Ok(TiledVariables {
        source,
        named: variables.into_iter().zip(names).collect(),
        largest,
        resampled: kept,
    })
}

/// The name a file gives a band's values: its description made a PLY property name
/// (whitespace and anything but ASCII letters, digits, `_` and `-` as `_`), or `band_N`
/// when it has none, it would read as a position (`x`, `y`, `z`), or another band took it.
fn property_name(description: Option<&str>, fallback: &str, taken: &[String]) -> String {
    let clean = |d: &str| -> String {
        d.trim()
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                    c
                } else {
                    '_'
                }
            })
            .collect()
    };
    let usable = |name: &String| {
        !name.is_empty() && !["x", "y", "z"].contains(&name.as_str()) && !taken.contains(name)
    };
    if let Some(name) = description.map(clean).filter(usable) {
        return name;
    }
    let mut name = clean(fallback);
    while !usable(&name) {
        name.push('_');
    }
    name
}

/// An attribute raster resampled onto the input's grid: a temporary GeoTIFF, removed when
/// this is dropped (and by the output layer on Ctrl-C before then).
pub(crate) struct ResampledFile {
    tif: PathBuf,
    /// The band's own metadata, in the file resampled.
    source: RasterInfo,
    _dir: tinsmith_output::ScratchDir,
}

impl ResampledFile {
    /// The GeoTIFF.
    pub(crate) fn path(&self) -> &Path {
        &self.tif
    }
}

/// `None` when attribute raster `file` is on the input's grid (`info`) and its bands are
/// read from it; else a copy of it resampled onto that grid by `v.resampling`, to read
/// them from. Refuses, naming both, a file whose extent shares no area with the input's
/// in the same CRS, or one that cannot be placed on its grid.
fn on_input_grid(
    file: &Path,
    v: &BandVariable,
    input: &Path,
    info: &RasterInfo,
) -> Result<Option<ResampledFile>> {
    // The band's metadata only: its samples are read once, afterwards.
    let other = tinsmith_raster::WindowReader::open(file, v.band)?
        .info()
        .clone();
    if tinsmith_raster::on_same_grid(&other, info) {
        return Ok(None);
    }
    let same_crs = match (&other.crs_wkt, &info.crs_wkt) {
        (Some(a), Some(b)) => tinsmith_raster::same_crs(a, b),
        (None, None) => true,
        _ => false,
    };
    if let (true, Some(o), Some(i)) = (same_crs, extent(&other), extent(info)) {
        if o[1] <= i[0] || i[1] <= o[0] || o[3] <= i[2] || i[3] <= o[2] {
            bail!(
                "{}: --attributes: does not overlap {} (extents x {}..{}, y {}..{} against \
                 x {}..{}, y {}..{})",
                file.display(),
                input.display(),
                o[0],
                o[1],
                o[2],
                o[3],
                i[0],
                i[1],
                i[2],
                i[3]
            );
        }
    }
    let dir = tinsmith_output::ScratchDir::new().with_context(|| {
        format!(
            "{}: cannot make a temporary directory to resample it in",
            file.display()
        )
    })?;
    let tif = dir.path().join("resampled.tif");
    tinsmith_raster::resample_onto(file, info, v.resampling, &tif)?;
    Ok(Some(ResampledFile {
        tif,
        source: other,
        _dir: dir,
    }))
}

/// `[x_min, x_max, y_min, y_max]` of a raster's samples' cells, when it has a geotransform.
fn extent(info: &RasterInfo) -> Option<[f64; 4]> {
    let g = info.geo_transform?;
    let (w, h) = (f64::from(info.width), f64::from(info.height));
    let xs = [g[0], g[0] + g[1] * w + g[2] * h];
    let ys = [g[3], g[3] + g[4] * w + g[5] * h];
    Some([
        xs[0].min(xs[1]),
        xs[0].max(xs[1]),
        ys[0].min(ys[1]),
        ys[0].max(ys[1]),
    ])
}

/// An attribute band with no valid sample on the input's grid (after resampling) reported
/// as not overlapping the input; any other error as it is, naming `file`.
fn no_overlap(error: tinsmith_raster::Error, file: &Path, input: &Path) -> crate::Error {
    match error {
        tinsmith_raster::Error::AllNodata { band, .. } => crate::Error::Refused(format!(
            "{}: --attributes: band {band} has no valid sample on {}'s grid (it does not \
             overlap it, or only with nodata)",
            file.display(),
            input.display()
        )),
        other => other.into(),
    }
}

/// One variable's line of the `--report` JSON.
#[derive(Debug, Clone, Serialize)]
pub struct VariableReport {
    /// Its band, 1-based.
    pub band: usize,
    /// The name the file gives it.
    pub name: String,
    /// The bound asked for.
    pub max_error: f64,
    /// The independent verifier's largest |sample - TIN| over every domain sample.
    pub measured_max_error: f64,
    /// GDAL's resampling method when the band came from another raster not on the
    /// input's grid (`--attributes`), resampled onto it; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resampled: Option<&'static str>,
}

impl VariableReport {
    /// The line of `variable`, named `name`, measured at `measured_max_error`.
    pub(crate) fn new(variable: &BandVariable, name: &str, measured_max_error: f64) -> Self {
        VariableReport {
            band: variable.band,
            name: name.to_owned(),
            max_error: variable.max_error,
            measured_max_error,
            resampled: variable.resampled.map(Resampling::name),
        }
    }
}

/// Each variable's values at the TIN's vertices (in vertex order), rounded to float32 for
/// a `float32` file (as it will hold them).
pub(crate) fn vertex_values(grid: &Grid, tin: &Tin, float32: bool) -> Vec<Vec<f64>> {
    let width = grid.width() as usize;
    (0..grid.variable_count())
        .map(|k| {
            let (values, _) = grid.variable(k);
            tin.vertices()
                .iter()
                .map(|v| values[v.y as usize * width + v.x as usize])
                .map(|x| if float32 { f64::from(x as f32) } else { x })
                .collect()
        })
        .collect()
}

/// Measures every variable of `grid` (`variables` their bands and names) on `tin` (vertex values `at_vertices`) with the
/// independent verifier; fails, naming `input`, when one exceeds its bound.
pub(crate) fn check(
    input: &Path,
    grid: &Grid,
    variables: &[(BandVariable, String)],
    tin: &Tin,
    at_vertices: &[Vec<f64>],
) -> Result<Vec<VariableReport>> {
    let positions: Vec<[i64; 2]> = tin
        .vertices()
        .iter()
        .map(|v| [i64::from(v.x), i64::from(v.y)])
        .collect();
    let mut reports = Vec::with_capacity(at_vertices.len());
    for (k, ((variable, name), values)) in variables.iter().zip(at_vertices).enumerate() {
        let report = measure(
            grid,
            grid.variable(k).0,
            MeshRef::new(&positions, values, tin.triangles()),
            variable.max_error,
            None,
        )?;
        if !report.passed() {
            bail!(
                "{}: internal error, band {} ({name}) of the decimated mesh failed \
                 verification ({}); nothing written",
                input.display(),
                variable.band,
                report.problems.join("; ")
            );
        }
        reports.push(VariableReport::new(variable, name, report.max_error));
    }
    Ok(reports)
}

/// The verifier's report of one variable's `values` over `grid`'s domain, the mesh
/// holding the variable's vertex values as heights.
fn measure(
    grid: &Grid,
    values: &[f64],
    mesh: MeshRef<'_>,
    max_error: f64,
    orientation: Option<Orientation>,
) -> Result<Report> {
    let mut options = VerifyOptions::new();
    if let Some(orientation) = orientation {
        options = options.with_orientation(orientation);
    }
    if max_error.is_finite() {
        options = options.with_max_error(max_error);
    }
    Ok(tinsmith_verify::verify_variable(
        GridRef::new(grid.width(), grid.height(), grid.values()),
        values,
        MeshRef::new(mesh.positions, &[], mesh.triangles),
        mesh.heights,
        &options,
    )?)
}

/// `verify --bands`: each variable of a mesh file read back (its values from the file's
/// vertex attribute of the band's name) measured against its band over `bands`' domain.
/// Fails, naming the mesh file, when it holds no values for a band.
pub(crate) fn verify_file(
    mesh_path: &Path,
    grid: &Grid,
    variables: &[(BandVariable, String)],
    positions: &[[i64; 2]],
    triangles: &[[u32; 3]],
    attributes: &[(String, Vec<f64>)],
    orientation: Orientation,
) -> Result<Vec<(VariableReport, Report)>> {
    let mut out = Vec::new();
    for (k, (variable, name)) in variables.iter().enumerate() {
        // glTF semantics are in capitals.
        let found = attributes.iter().find(|(n, _)| n == name).or_else(|| {
            attributes
                .iter()
                .find(|(n, _)| n.eq_ignore_ascii_case(name))
        });
        let Some((_, values)) = found else {
            let held: Vec<&str> = attributes.iter().map(|(n, _)| n.as_str()).collect();
            bail!(
                "{}: holds no per-vertex values `{name}` for band {} (it holds {})",
                mesh_path.display(),
                variable.band,
                if held.is_empty() {
                    "none; only PLY and glTF files carry variables".to_owned()
                } else {
                    held.join(", ")
                }
            );
        };
        let report = measure(
            grid,
            grid.variable(k).0,
            MeshRef::new(positions, values, triangles),
            variable.max_error,
            Some(orientation),
        )
        .with_context(|| format!("{}: cannot verify", mesh_path.display()))?;
        out.push((
            VariableReport::new(variable, name, report.max_error),
            report,
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_and_bounds_resolve_or_are_refused() {
        let p = Path::new("in.tif");
        let (h, e, v) = resolve_bands(p, &[1, 2, 3], &[1.0, 0.5, 0.25], None).unwrap();
        assert_eq!((h, e), (1, Some(1.0)));
        assert_eq!(
            (v[0].band, v[0].max_error, v[1].band, v[1].max_error),
            (2, 0.5, 3, 0.25)
        );
        let (h, e, v) = resolve_bands(p, &[1, 2, 3], &[2.0], Some(3)).unwrap();
        assert_eq!((h, e, v.len()), (3, Some(2.0), 2));
        assert_eq!((v[0].band, v[1].band), (1, 2));
        let refused = |bands: &[usize], bounds: &[f64], height: Option<usize>| {
            resolve_bands(p, bands, bounds, height)
                .unwrap_err()
                .to_string()
        };
        assert!(refused(&[1, 2], &[1.0, 2.0, 3.0], None).contains("3 bounds for the 2 bands"));
        assert!(refused(&[1, 2], &[f64::NAN], None).contains(">= 0"));
        assert!(refused(&[1, 2], &[-1.0], None).contains(">= 0"));
        assert!(refused(&[1, 1], &[1.0], None).contains("twice"));
        assert!(refused(&[1, 2], &[1.0], Some(3)).contains("not among --bands"));
        assert!(refused(&[0, 2], &[1.0], None).contains("from 1"));
        assert!(refused(&[], &[1.0, 2.0], None).contains("no --bands"));
        assert!(refused(&[1, 2], &[f64::INFINITY, 1.0], None).contains("finite"));
    }

    #[test]
    fn names_come_from_descriptions_unless_unusable() {
        assert_eq!(property_name(None, "band_2", &[]), "band_2");
        assert_eq!(
            property_name(Some("surface temp (K)"), "band_2", &[]),
            "surface_temp__K_"
        );
        assert_eq!(property_name(Some("z"), "band_3", &[]), "band_3");
        let taken = ["dtm".to_owned(), "band_3".to_owned()];
        assert_eq!(property_name(Some("dtm"), "band_3", &taken), "band_3_");
        assert_eq!(property_name(None, "dem_band_1", &taken), "dem_band_1");
    }
}
