//! `tinsmith tiles`: a quantized-mesh terrain pyramid, with its report reserved before
//! the work and per-level notes.

use std::path::Path;

use tinsmith_terrain::{
    build_shard, build_terrain, build_terrain_in, merge_shards, LevelReport, Progress, Shard,
    ShardReport, TerrainOptions, TerrainReport,
};

use tinsmith_store::{is_object_url, BucketStore, DirectoryStore, MbtilesStore, TileStore};

use crate::error::bail;
use crate::output_paths::NamingFile;
use crate::{Feedback, Result};

/// Builds the pyramid of `input` into the directory `output` (moved into place whole when
/// done) and, with `report`, writes the per-level report there; the report's path is
/// checked and its room taken before any tile is made. Notes one line per level, then a
/// summary.
pub fn tiles(
    input: &Path,
    output: &Path,
    report: Option<&Path>,
    options: &TerrainOptions,
    feedback: &dyn Feedback,
) -> Result<TerrainReport> {
    let reserved = reserve_report(output, report, input)?;
    let mut progress = |p: Progress<'_>| show(feedback, p);
    let built = match destination(output) {
        Destination::Bucket(url) => {
            let store = BucketStore::open(url)?;
            store.probe()?;
            build_terrain_in(input, &store, options, &mut progress).naming_file(input)?
        }
        Destination::Mbtiles => {
            if options.format == tinsmith_terrain::TileFormat::ThreeDTiles {
                bail!(
                    "{}: --format 3dtiles is written into a directory or a bucket (tileset.json, \
                     subtrees and GLBs), not into MBTiles, which holds quantized-mesh tiles",
                    output.display()
                );
            }
            if options.update {
                bail!(
                    "{}: --update works on a directory or a bucket; build the MBTiles file \
                     again (it is written whole)",
                    output.display()
                );
            }
            crate::output_paths::check_writable_target(output, input)?;
            let store = MbtilesStore::create(output)?;
            let built =
                build_terrain_in(input, &store, options, &mut progress).naming_file(input)?;
            store.commit()?;
            built
        }
        Destination::Directory => {
            build_terrain(input, output, options, &mut progress).naming_file(input)?
        }
    };
    if let Some(reserved) = reserved {
        reserved.write(&serde_json::to_vec_pretty(&built)?)?;
    }
    tinsmith_output::mark_finished();
    let tiles: u64 = built.levels.iter().map(|l| l.tiles).sum();
    let kept = match built.tiles_kept {
        0 => String::new(),
        n => format!(" ({n} kept as they were: their data had not changed)"),
    };
    feedback.note(&format!(
        "{tiles} tiles{kept}, levels {}..={}, in {}{}",
        built.min_zoom,
        built.max_zoom,
        output.display(),
        if options.gzip && options.format == tinsmith_terrain::TileFormat::QuantizedMesh {
            " (gzipped: serve with Content-Encoding: gzip, e.g. `tinsmith serve`)"
        } else {
            ""
        }
    ));
    Ok(built)
}

/// The vertical datum of `input`'s heights: `choice` (`egm96`, `egm2008`, `ellipsoid` or
/// a geoid grid file) when given, else the vertical CRS `input` declares, else the
/// ellipsoid with a note saying so and how to choose. Checks that PROJ can use the
/// geoid's grid before any work.
///
/// # Errors
/// When the raster declares a vertical CRS tinsmith does not know (and no `choice`), or
/// PROJ cannot find or read the geoid's grid.
pub fn vertical_datum(
    input: &Path,
    band: usize,
    choice: Option<&str>,
    feedback: &dyn Feedback,
) -> Result<tinsmith_raster::VerticalDatum> {
    use tinsmith_raster::VerticalDatum;
    let datum = match choice {
        Some(text) => VerticalDatum::parse(text),
        None => match tinsmith_raster::declared_vertical_datum(input, band)? {
            Some(declared) => {
                feedback.note(&format!(
                    "{}: heights above {} (its vertical CRS), written as heights above the \
                     WGS84 ellipsoid",
                    input.display(),
                    declared.label()
                ));
                declared
            }
            None => {
                feedback.note(&format!(
                    "{}: no vertical CRS; heights are taken as metres above the WGS84 \
                     ellipsoid. Most DEMs (SRTM, Copernicus, national grids) are above a \
                     geoid, tens of metres off: give --vertical-datum egm96, egm2008 or a \
                     geoid grid file (or ellipsoid to keep them as they are)",
                    input.display()
                ));
                VerticalDatum::Ellipsoid
            }
        },
    };
    tinsmith_raster::Geoid::new(&datum)?;
    Ok(datum)
}

/// The base raster `path` of a pyramid (`tiles --base`), its heights above `choice` or its
/// own vertical CRS (as [`vertical_datum`] decides), checked to open as a georeferenced
/// raster before any work.
///
/// # Errors
/// Naming `path`: when it is missing, not a raster, or not georeferenced; as
/// [`vertical_datum`].
pub fn base_raster(
    path: &Path,
    choice: Option<&str>,
    feedback: &dyn Feedback,
) -> Result<tinsmith_terrain::BaseRaster> {
    let checked = vertical_datum(path, 1, choice, feedback)
        .and_then(|datum| Ok((datum, tinsmith_raster::geographic_bounds(path, 1)?)));
    let (vertical_datum, _) = checked.naming_file(path).map_err(|e| e.context("--base"))?;
    Ok(tinsmith_terrain::BaseRaster {
        path: path.to_path_buf(),
        vertical_datum,
    })
}

/// Where the water mask of `input`'s pyramid comes from: `sea-level` (`input` itself,
/// band `band`), a mask raster or a polygon layer, checked to open; `None` without
/// `choice`.
///
/// # Errors
/// When GDAL opens `choice` as neither a raster nor a vector dataset.
pub fn water_source(
    input: &Path,
    band: usize,
    choice: Option<&str>,
) -> Result<Option<tinsmith_terrain::Water>> {
    let Some(choice) = choice else {
        return Ok(None);
    };
    if choice.eq_ignore_ascii_case("sea-level") {
        return Ok(Some(tinsmith_terrain::Water::SeaLevel {
            path: input.to_path_buf(),
            band,
        }));
    }
    let path = Path::new(choice);
    match tinsmith_raster::WindowReader::open(path, 1) {
        Ok(_) => Ok(Some(tinsmith_terrain::Water::Raster {
            path: path.to_path_buf(),
            band: 1,
        })),
        Err(tinsmith_raster::Error::NotARaster { .. }) if tinsmith_raster::is_vector(path) => {
            Ok(Some(tinsmith_terrain::Water::Polygons {
                path: path.to_path_buf(),
            }))
        }
        Err(tinsmith_raster::Error::NotARaster { .. }) => bail!(
            "{}: --water takes `sea-level`, a raster of water (1) and land (0), or a polygon \
             layer of water; GDAL opens this as neither",
            path.display()
        ),
        Err(e) => Err(e.into()),
    }
}

/// Shows a build's progress: a status line of blocks, a note per finished level.
fn show(feedback: &dyn Feedback, progress: Progress<'_>) {
    match progress {
        Progress::Block { done, total } if done < total => {
            feedback.status(&format!("blocks: {done} of {total} built"))
        }
        Progress::Block { .. } => feedback.clear_status(),
        Progress::Planned {
            seconds,
            blocks,
            split,
            anchor,
            shard_blocks,
            share,
        } => feedback.note(&format!(
            "planned in {seconds:.2} s: {blocks} blocks at level {split} (anchor {anchor}), \
             {shard_blocks} of them this shard's, {:.2} % of the weight",
            100.0 * share
        )),
        Progress::Level(level) => note_level(feedback, level),
    }
}

/// One line about a finished level.
fn note_level(feedback: &dyn Feedback, level: &LevelReport) {
    let flat = match level.flat_tiles {
        0 => String::new(),
        n => format!(" ({n} flat: a root tile without data, for the whole globe)"),
    };
    feedback.note(&format!(
        "level {:>2}: {} tiles{flat}, {} bytes, bound {:.3} m, measured {:.3} m, {:.2} s",
        level.level,
        level.tiles,
        level.bytes,
        level.achieved_bound,
        level.measured_max_error,
        level.seconds
    ));
}

/// Builds shard `shard` of the pyramid of `input` into the directory `output` that every
/// shard shares (see [`tinsmith_terrain::build_shard`]) and, with `report`, writes what it
/// built there. Notes each block, then a summary.
pub fn tiles_shard(
    input: &Path,
    output: &Path,
    report: Option<&Path>,
    options: &TerrainOptions,
    shard: Shard,
    feedback: &dyn Feedback,
) -> Result<ShardReport> {
    let reserved = reserve_report(output, report, input)?;
    let store = pyramid_store(output)?;
    let built = build_shard(input, &*store, options, shard, &mut |p| show(feedback, p))
        .naming_file(input)?;
    if let Some(reserved) = reserved {
        reserved.write(&serde_json::to_vec_pretty(&built)?)?;
    }
    tinsmith_output::mark_finished();
    feedback.note(&format!(
        "shard {}: {} blocks, {} tiles ({} kept from an earlier run), {:.1} % of the plan's \
         work, in {}; when every shard is done: tinsmith tiles merge {}",
        built.shard,
        built.blocks,
        built.tiles,
        built.tiles_kept,
        100.0 * built.weight as f64 / built.total_weight.max(1) as f64,
        output.display(),
        output.display()
    ));
    Ok(built)
}

/// Finishes the sharded pyramid in `dir` (see [`tinsmith_terrain::merge_shards`]) and,
/// with `report`, writes the per-level report there. Notes one line per level, then a
/// summary.
pub fn merge_tiles(
    dir: &Path,
    threads: usize,
    report: Option<&Path>,
    feedback: &dyn Feedback,
) -> Result<TerrainReport> {
    if let Some(report) = report {
        crate::output_paths::check_not_inside(dir, report, "the pyramid directory")?;
    }
    let reserved = report
        .map(crate::output_paths::ReservedReport::reserve)
        .transpose()?;
    let store = pyramid_store(dir)?;
    let built = merge_shards(&*store, threads, &mut |p| show(feedback, p))?;
    if let Some(reserved) = reserved {
        reserved.write(&serde_json::to_vec_pretty(&built)?)?;
    }
    tinsmith_output::mark_finished();
    let tiles: u64 = built.levels.iter().map(|l| l.tiles).sum();
    feedback.note(&format!(
        "{tiles} tiles, levels {}..={}, in {} (layer.json written)",
        built.min_zoom,
        built.max_zoom,
        dir.display()
    ));
    Ok(built)
}

/// Where `-o` puts a pyramid.
enum Destination<'a> {
    /// An object store (`s3://bucket/prefix`, `gs://...`, `az://...`).
    Bucket(&'a str),
    /// One MBTiles file (`.mbtiles`).
    Mbtiles,
    /// A local directory.
    Directory,
}

fn destination(output: &Path) -> Destination<'_> {
    match output.to_str() {
        Some(url) if is_object_url(url) => Destination::Bucket(url),
        _ if output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mbtiles")) =>
        {
            Destination::Mbtiles
        }
        _ => Destination::Directory,
    }
}

/// The store a pyramid built in shards goes to: an object store for an `s3://`, `gs://` or
/// `az://` URL (checked reachable before any work), else the directory `output` (made when
/// missing).
/// Shards cannot share one MBTiles file.
fn pyramid_store(output: &Path) -> Result<Box<dyn TileStore>> {
    match destination(output) {
        Destination::Bucket(url) => {
            let store = BucketStore::open(url)?;
            store.probe()?;
            Ok(Box::new(store))
        }
        Destination::Mbtiles => bail!(
            "{}: shards write into a directory or a bucket that they share, not one MBTiles \
             file; give a directory",
            output.display()
        ),
        Destination::Directory => Ok(Box::new(DirectoryStore::open(output)?)),
    }
}

/// Checks the report's path (outside the pyramid, writable, not the input) and takes its
/// room before any tile is made.
fn reserve_report(
    output: &Path,
    report: Option<&Path>,
    input: &Path,
) -> Result<Option<crate::output_paths::ReservedReport>> {
    if let Some(report) = report {
        crate::output_paths::check_not_inside(output, report, "the pyramid directory")?;
        crate::output_paths::check_writable_target(report, input)?;
    }
    Ok(report
        .map(crate::output_paths::ReservedReport::reserve)
        .transpose()?)
}
