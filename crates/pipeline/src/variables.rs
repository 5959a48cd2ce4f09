//! Several variables over one mesh (`mesh --bands`, `verify --bands`): which bands are the
//! height and the variables with their bounds, reading them onto one grid whose domain is
//! where every band is valid, naming them in files, and measuring each one independently.

use std::path::Path;

use serde::Serialize;
use tinsmith_core::{Grid, Tin, Variable};
use tinsmith_georef::Samples;
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
        })
        .collect();
    Ok((height, Some(bound(at)), variables))
}

/// Reads every variable's band of `input` beside the `height` samples already read, into
/// one grid (the domain is where every band is valid), with each variable's band, bound
/// and the name files give it. For a `float32` file each band is decimated within its
/// bound less the largest float32 rounding of its values, so that the values as stored
/// keep the bound; a bound below that rounding is refused.
pub(crate) fn read(
    input: &Path,
    height: Samples,
    variables: &[BandVariable],
    float32: bool,
) -> Result<(Grid, Vec<(BandVariable, String)>)> {
    let mut read = Vec::with_capacity(variables.len());
    let mut names: Vec<String> = Vec::new();
    for v in variables {
        let raster = tinsmith_raster::read_samples(input, v.band)?;
        let name = property_name(raster.info.description.as_deref(), v.band, &names);
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
    Ok((grid, variables.iter().cloned().zip(names).collect()))
}

/// The name a file gives a band's values: its description made a PLY property name
/// (whitespace and anything but ASCII letters, digits, `_` and `-` as `_`), or `band_N`
/// when it has none, it would read as a position (`x`, `y`, `z`), or another band took it.
fn property_name(description: Option<&str>, band: usize, taken: &[String]) -> String {
    let fallback = format!("band_{band}");
    let Some(d) = description else {
        return fallback;
    };
    let name: String = d
        .trim()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if name.is_empty() || ["x", "y", "z"].contains(&name.as_str()) || taken.contains(&name) {
        fallback
    } else {
        name
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
        reports.push(VariableReport {
            band: variable.band,
            name: name.clone(),
            max_error: variable.max_error,
            measured_max_error: report.max_error,
        });
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
            VariableReport {
                band: variable.band,
                name: name.clone(),
                max_error: variable.max_error,
                measured_max_error: report.max_error,
            },
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
            v,
            [
                BandVariable {
                    band: 2,
                    max_error: 0.5
                },
                BandVariable {
                    band: 3,
                    max_error: 0.25
                }
            ]
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
        assert_eq!(property_name(None, 2, &[]), "band_2");
        assert_eq!(
            property_name(Some("surface temp (K)"), 2, &[]),
            "surface_temp__K_"
        );
        assert_eq!(property_name(Some("z"), 3, &[]), "band_3");
        assert_eq!(property_name(Some("dtm"), 3, &["dtm".to_owned()]), "band_3");
    }
}
