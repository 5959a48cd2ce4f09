//! Telling a gzipped tile from a plain one by its bytes, for stores that keep no record of
//! how each tile was encoded.

use std::io::Read;

use crate::TileEncoding;

/// How `bytes` are encoded: [`TileEncoding::Gzip`] only when they begin with gzip's header
/// (magic `1f 8b`, deflate, no reserved flags) **and** the whole member decompresses with a
/// matching checksum. An uncompressed quantized-mesh tile begins with an `f64` whose low
/// bytes are arbitrary and can match the magic bytes; it must not be labelled gzip.
pub fn detect_encoding(bytes: &[u8]) -> TileEncoding {
    let header_fits = bytes.len() >= 4 && bytes[..3] == [0x1f, 0x8b, 0x08] && bytes[3] & 0xe0 == 0;
    if !header_fits {
        return TileEncoding::Identity;
    }
    let mut decoder = flate2::read::GzDecoder::new(bytes);
    let mut chunk = [0u8; 8192];
    loop {
        match decoder.read(&mut chunk) {
            Ok(0) => return TileEncoding::Gzip,
            Ok(_) => {}
            Err(_) => return TileEncoding::Identity,
        }
    }
}

#[cfg(test)]
mod tests {
    use std::io::Write;

    use super::*;

    #[test]
    fn only_a_whole_gzip_member_is_gzip() {
        let mut encoder = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        encoder.write_all(b"a quantized-mesh tile").unwrap();
        let gzipped = encoder.finish().unwrap();
        assert_eq!(detect_encoding(&gzipped), TileEncoding::Gzip);
        // The magic bytes alone (a plain tile's first f64 can hold them) are not gzip.
        let mut forged = vec![0x1f, 0x8b, 0x08, 0x00];
        forged.extend_from_slice(&[7; 80]);
        assert_eq!(detect_encoding(&forged), TileEncoding::Identity);
        // Nor is a member cut short.
        assert_eq!(
            detect_encoding(&gzipped[..gzipped.len() - 3]),
            TileEncoding::Identity
        );
        assert_eq!(detect_encoding(b""), TileEncoding::Identity);
    }
}
