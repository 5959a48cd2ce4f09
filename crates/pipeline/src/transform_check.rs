//! Whether a raster's geotransform can place every sample at its own position in the
//! written files, checked before any long work.

use std::path::Path;

use tinsmith_georef::{Placement, PlacementProblem};

use crate::error::bail;
use crate::Result;

/// Fails (before any long work) when world coordinates are to be written and the raster's
/// geotransform cannot give every sample its own: a non-finite coefficient, a singular map
/// (every sample on one point or line), or pixels so small against the origin that `f64`
/// positions no longer map back to their samples (checked at the grid's corners, where
/// positions are largest). The mesh could not be read back. `--pixel-coords` needs no
/// geotransform.
pub fn check_transform(info: &tinsmith_raster::RasterInfo, pixel_coords: bool) -> Result<()> {
    let Some(t) = info.transform().filter(|_| !pixel_coords) else {
        return Ok(());
    };
    let input = info.path.display();
    let fix = "assign a real one (e.g. `gdal_translate -of VRT -a_ullr ULX ULY LRX LRY IN \
               OUT.vrt`) or write --pixel-coords";
    match Placement::World(t).check_places_samples(info.width, info.height) {
        Ok(()) => {}
        Err(PlacementProblem::NotFinite) => bail!(
            "{input}: its geotransform {:?} has a coefficient that is not a finite number; {fix}",
            t.0
        ),
        Err(PlacementProblem::Singular) => bail!(
            "{input}: its geotransform {:?} is singular (a pixel size of 0: samples have no \
             distinct positions); {fix}",
            t.0
        ),
        Err(PlacementProblem::PixelsTooSmall { x, y }) => bail!(
            "{input}: its geotransform {:?} has pixels too small for its origin: in f64 \
             the position of sample ({x}, {y}) does not map back to it, so samples would \
             share positions; {fix}",
            t.0
        ),
    }
    Ok(())
}

/// [`check_transform`] on the band's metadata alone (no sample is read); returns the
/// raster's width and height.
pub fn check_input_transform(input: &Path, band: usize, pixel_coords: bool) -> Result<(u32, u32)> {
    let reader = tinsmith_raster::WindowReader::open(input, band)?;
    check_transform(reader.info(), pixel_coords)?;
    Ok((reader.width(), reader.height()))
}
