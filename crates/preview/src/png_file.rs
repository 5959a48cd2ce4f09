//! PNG bytes of a picture, with text chunks that say what it shows.

use crate::Picture;

/// The picture as an 8-bit RGB PNG (it is opaque), with one `tEXt` chunk per
/// `(keyword, text)` (PNG
/// keywords are 1 to 79 Latin-1 characters; others are left out). No time chunk: the
/// same picture and text give the same bytes.
pub fn encode_png(picture: &Picture, text: &[(&str, String)]) -> Vec<u8> {
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, picture.width, picture.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        // Pictures go into docs and repositories: the smallest files the encoder makes.
        encoder.set_compression(png::Compression::High);
        encoder.set_filter(png::Filter::Adaptive);
        for (keyword, value) in text {
            // Refused keywords and non-Latin-1 text are left out rather than failing.
            let _ = encoder.add_text_chunk(keyword.to_string(), value.clone());
        }
        let mut writer = encoder.write_header().expect("writing to memory");
        let rgb: Vec<u8> = picture
            .rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        writer
            .write_image_data(&rgb)
            .expect("width x height x 3 bytes");
    }
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_bytes_decode_to_the_pixels_and_carry_the_text() {
        let picture = Picture {
            width: 3,
            height: 2,
            samples_per_pixel: 1.0,
            rgba: (0..24).map(|v| v as u8 * 10).collect(),
        };
        let bytes = encode_png(&picture, &[("Title", "a test".into())]);
        assert_eq!(bytes, encode_png(&picture, &[("Title", "a test".into())]));
        let decoder = png::Decoder::new(std::io::Cursor::new(&bytes));
        let mut reader = decoder.read_info().unwrap();
        let mut out = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut out).unwrap();
        assert_eq!((info.width, info.height), (3, 2));
        let rgb: Vec<u8> = picture
            .rgba
            .chunks(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        assert_eq!(&out[..info.buffer_size()], &rgb[..]);
        let texts = &reader.info().uncompressed_latin1_text;
        assert!(texts
            .iter()
            .any(|t| t.keyword == "Title" && t.text == "a test"));
    }
}
