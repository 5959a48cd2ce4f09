//! `tinsmith verify`: measure a mesh file's true error against its raster.

use tinsmith_verify::{MeshRef, Report, VerifyOptions};

use crate::error::{bail, Context};
use crate::mesh_file::{mesh_format, read_onto_raster, MeshOnRaster};
use crate::{Result, VerifyJob};

/// What [`verify`] measured, with what the caller needs to explain a failure.
#[derive(Debug)]
#[non_exhaustive]
pub struct Verified {
    /// The verifier's report: the error at every valid sample, coverage, conformity.
    pub report: Report,
    /// Bands in the raster (a mesh of another band fails).
    pub band_count: usize,
    /// Each variable of `--bands` (its band, name, bound and measured error) with the
    /// verifier's report of it; empty without variables.
    pub variables: Vec<(crate::VariableReport, Report)>,
}

impl Verified {
    /// Whether the height and every variable passed (see [`Report::passed`]).
    pub fn passed(&self) -> bool {
        self.report.passed() && self.variables.iter().all(|(_, r)| r.passed())
    }
}

/// Reads the mesh file back onto its raster (WGS84 GeoJSON transformed back, each vertex
/// mapped to its sample within its format's rounding) and measures it with the
/// independent verifier. Fails, naming the file, when the mesh cannot be read or mapped,
/// when the raster has no valid cell, or when the whole raster would not fit in memory;
/// a mesh outside the bound is not an error: see [`Report::passed`].
pub fn verify(job: &VerifyJob) -> Result<Verified> {
    let format = mesh_format(&job.mesh, job.format)?;
    crate::memory::check_whole_raster_fits(
        &job.input,
        crate::memory::raster_size(&job.input, job.band)?,
        crate::memory::Need {
            bytes_per_sample: 24,
            extra_bytes: crate::memory::mesh_file_memory(&job.mesh, format),
        },
        "verify",
        "verification has no tiled mode; use a machine with more memory",
    )?;
    let MeshOnRaster {
        raster,
        positions,
        heights,
        triangles,
        orientation,
        attributes,
    } = read_onto_raster(
        &job.input,
        job.band,
        job.vertical_datum.as_ref(),
        &job.mesh,
        format,
        job.pixel_coords,
    )?;
    let mut joined = None;
    let grid = crate::variables::read_for_check(
        &job.input,
        (&raster.samples, &raster.info),
        &job.variables,
        &mut joined,
    )?;
    let mut options = VerifyOptions::new().with_orientation(orientation);
    if let Some(e) = job.max_error {
        options = options.with_max_error(e);
    }
    let report = tinsmith_verify::verify(
        grid,
        MeshRef::new(&positions, &heights, &triangles),
        &options,
    )
    .with_context(|| format!("{}: cannot verify", job.mesh.display()))?;
    if report.domain_samples == 0 {
        // `mesh` refuses such a raster: a pass here would measure nothing.
        bail!(
            "{}: has no valid cell (a 2 x 2 block of valid samples), so no triangle can \
             cover any of its {} valid samples and there is nothing to measure",
            job.input.display(),
            report.valid_samples
        );
    }
    let variables = match &joined {
        None => Vec::new(),
        Some((grid, variables, _)) => crate::variables::verify_file(
            &job.mesh,
            grid,
            variables,
            &positions,
            &triangles,
            &attributes,
            orientation,
        )?,
    };
    Ok(Verified {
        report,
        band_count: raster.info.band_count,
        variables,
    })
}
