//! LAS and LAZ through the `las` crate (LAZ decompressed by its `laz` feature), read in
//! chunks of 65,536 points: positions stay the file's integers (`X`, `Y`, shifted to start
//! at 0), heights become `Z * scale + offset`.

use std::path::Path;

use crate::cloud::{ClassChoice, FileCrs, PointCloud, MAX_LATTICE};
use crate::error::{format_error, Error, Result};
use crate::ReadOptions;

/// ASPRS class 2: ground.
const GROUND: u8 = 2;

/// GeoTIFF's key value for a user-defined CRS.
const USER_DEFINED: u16 = 32767;

/// Points read per call to the reader.
const CHUNK: u64 = 65_536;

pub(crate) fn read_las(path: &Path, options: &ReadOptions) -> Result<PointCloud> {
    let las_error = |source| Error::Las {
        path: path.to_path_buf(),
        source,
    };
    check_point_count(path)?;
    let mut reader = las::Reader::from_path(path).map_err(las_error)?;
    let header = reader.header().clone();
    let declared = header.number_of_points();
    let format = *header.point_format();
    let transforms = *header.transforms();
    let crs = file_crs(&crs_records(path, &header).unwrap_or_else(|_| header.clone()));
    let mut data = las::PointDataBuilder::new().for_header(&header).build();
    let (mut raw, mut z, mut class) = (Vec::new(), Vec::new(), Vec::new());
    let mut read = 0u64;
    loop {
        let n = reader.fill_points(CHUNK, &mut data).map_err(|e| {
            format_error(
                path,
                format!(
                    "the point data is truncated or corrupt after {read} of the {declared} points the header declares ({e})"
                ),
            )
        })?;
        if n == 0 {
            break;
        }
        read += n;
        let len = data.record_len();
        for record in data.raw_bytes().chunks_exact(len) {
            let int =
                |at: usize| i32::from_le_bytes(record[at..at + 4].try_into().expect("4 bytes"));
            let (classification, withheld) = if format.is_extended {
                (record[16], record[15] & 0b100 != 0)
            } else {
                (record[15] & 0b1_1111, record[15] & 0b1000_0000 != 0)
            };
            if withheld && options.no_withheld {
                continue;
            }
            if let Some(list) = &options.classes {
                if !list.contains(&classification) {
                    continue;
                }
            }
            raw.push([i64::from(int(0)), i64::from(int(4))]);
            z.push(transforms.z.direct(int(8)));
            class.push(classification);
        }
    }
    if read != declared {
        return Err(format_error(
            path,
            format!("the header declares {declared} points but the file holds {read}"),
        ));
    }
    drop(data);
    let classes = match &options.classes {
        Some(list) => ClassChoice::Listed(list.clone()),
        None if class.contains(&GROUND) => {
            let mut k = 0;
            raw.retain(|_| {
                k += 1;
                class[k - 1] == GROUND
            });
            let mut k = 0;
            z.retain(|_| {
                k += 1;
                class[k - 1] == GROUND
            });
            ClassChoice::DefaultGround
        }
        None => ClassChoice::All,
    };
    drop(class);
    let (mut lo, mut hi) = ([i64::MAX; 2], [i64::MIN; 2]);
    for p in &raw {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    if raw.is_empty() {
        lo = [0; 2];
    } else if (0..2).any(|a| hi[a] - lo[a] > MAX_LATTICE) {
        return Err(format_error(
            path,
            "the points span more than 2^31 - 1 steps of the file's scale, beyond the exact \
             integer geometry",
        ));
    }
    for p in &mut raw {
        p[0] -= lo[0];
        p[1] -= lo[1];
    }
    Ok(PointCloud {
        xy: raw,
        z,
        origin: [
            transforms.x.scale * lo[0] as f64 + transforms.x.offset,
            transforms.y.scale * lo[1] as f64 + transforms.y.offset,
        ],
        spacing: [transforms.x.scale, transforms.y.scale],
        crs,
        classes,
        points_in_file: read,
    })
}

/// Checks the header's point counts against each other and, for uncompressed data,
/// against the bytes the file holds for its points: a count that says fewer points than
/// the file holds would otherwise read as a smaller cloud without a word. (A count that
/// says more fails when the reader runs out of points.)
fn check_point_count(path: &Path) -> Result<()> {
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let file_len = file.metadata().map_err(io)?.len();
    let raw = las::raw::Header::read_from(&mut file).map_err(|source| Error::Las {
        path: path.to_path_buf(),
        source,
    })?;
    let legacy = u64::from(raw.number_of_point_records);
    let count = match &raw.large_file {
        Some(large) => {
            if legacy != 0 && legacy != large.number_of_point_records {
                return Err(format_error(
                    path,
                    format!(
                        "the header declares {} points and, in its legacy field, {legacy}",
                        large.number_of_point_records
                    ),
                ));
            }
            large.number_of_point_records
        }
        None => legacy,
    };
    let compressed = raw.point_data_record_format & 0b1100_0000 != 0;
    if !compressed {
        let record = u64::from(raw.point_data_record_length).max(1);
        let offset = u64::from(raw.offset_to_point_data);
        // The points end where the first EVLR or internal waveform packet starts, or the
        // file ends.
        let after = [
            raw.evlr
                .as_ref()
                .filter(|e| e.number_of_evlrs > 0)
                .map(|e| e.start_of_first_evlr),
            raw.start_of_waveform_data_packet_record,
        ];
        let end = after
            .into_iter()
            .flatten()
            .filter(|&at| at >= offset)
            .fold(file_len, u64::min);
        let held = end.saturating_sub(offset) / record;
        if held != count {
            return Err(format_error(
                path,
                format!("the header declares {count} points but the file holds {held}"),
            ));
        }
    }
    Ok(())
}

/// A header holding every CRS-bearing record of the file: its VLRs and all its EVLRs.
/// The `las` crate keeps only the first EVLR, while COPC writers put the hierarchy there
/// and the WKT after it (copclib does), so the others are read here. Unreadable records
/// count as none, as everywhere in the CRS lookup.
fn crs_records(path: &Path, header: &las::Header) -> las::Result<las::Header> {
    use std::io::{BufReader, Seek, SeekFrom};
    let mut file = BufReader::new(std::fs::File::open(path)?);
    let raw = las::raw::Header::read_from(&mut file)?;
    let Some(evlr) = raw.evlr.filter(|e| e.number_of_evlrs > 1) else {
        return Ok(header.clone());
    };
    let _ = file.seek(SeekFrom::Start(evlr.start_of_first_evlr))?;
    let mut builder = las::Builder::from((1, 4));
    builder.vlrs = header.vlrs().clone();
    for _ in 0..evlr.number_of_evlrs {
        let record = las::raw::Vlr::read_from(&mut file, true)?;
        builder.evlrs.push(las::Vlr::new(record));
    }
    builder.into_header()
}

/// The CRS the header's VLRs declare (unreadable CRS records count as none).
fn file_crs(header: &las::Header) -> FileCrs {
    let wkt = header.get_wkt_crs_bytes().map(|bytes| {
        String::from_utf8_lossy(bytes)
            .trim_end_matches('\0')
            .trim()
            .to_string()
    });
    // 32767 is GeoTIFF's "user-defined": no EPSG code, the CRS is spelled out in other keys.
    let code = |c: Option<u16>| c.filter(|&c| c != USER_DEFINED);
    let geotiff_epsg = header.get_geotiff_crs().ok().flatten().and_then(|g| {
        code(g.get_projected_crs_geo_key_value())
            .or_else(|| code(g.get_geodetic_crs_geo_key_value()))
    });
    FileCrs {
        wkt: wkt.filter(|w| !w.is_empty()),
        geotiff_epsg,
    }
}
