//! `tinsmith info`: describe a raster band.

use anyhow::Result;
use tinsmith_pipeline::readable;

use crate::args::InfoArgs;
use crate::progress::Stderr;

/// Prints the band's metadata and value statistics; always `Ok(true)` on success.
pub fn run(args: &InfoArgs) -> Result<bool> {
    let info =
        tinsmith_pipeline::scan_raster(&args.input, args.band, None, &Stderr::new(args.quiet))?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&info)?);
        return Ok(true);
    }
    println!("file:          {}", info.path.display());
    println!("driver:        {}", info.driver);
    println!(
        "size:          {} x {} ({} band(s), showing band {})",
        info.width, info.height, info.band_count, info.band
    );
    println!("type:          {}", info.data_type);
    if info.scale != 1.0 || info.offset != 0.0 {
        println!(
            "scale, offset: {}, {} (heights = sample x scale + offset)",
            readable(info.scale),
            readable(info.offset)
        );
    }
    match info.nodata {
        Some(n) => println!("nodata:        {}", readable(n)),
        None if info.nodata_samples > 0 => {
            println!("nodata:        none declared (NaN or infinite samples are nodata)")
        }
        None => println!("nodata:        none"),
    }
    if let Some(mask) = &info.mask {
        println!("mask:          {mask} (its zeros are nodata)");
    }
    println!(
        "valid samples: {} ({} nodata)",
        info.valid_samples, info.nodata_samples
    );
    match (info.min, info.max) {
        (Some(lo), Some(hi)) => println!("value range:   {} .. {}", readable(lo), readable(hi)),
        _ => println!("value range:   no valid sample"),
    }
    match info.epsg {
        Some(code) => println!("crs:           EPSG:{code}"),
        None if info.crs_wkt.is_some() => println!("crs:           (WKT, no EPSG code)"),
        None => println!("crs:           none"),
    }
    match info.geo_transform {
        Some(g) => println!("geotransform:  {g:?}"),
        None if info.gcp_count > 0 => println!(
            "geotransform:  none (pixel coordinates); {} GCPs, not used: warp onto a grid \
             first, e.g. `gdalwarp IN OUT.tif`",
            info.gcp_count
        ),
        None if info.geolocation => println!(
            "geotransform:  none (pixel coordinates); geolocation arrays, not used: warp \
             onto a grid first (gdalwarp -geoloc)"
        ),
        None => println!("geotransform:  none (pixel coordinates)"),
    }
    Ok(true)
}
