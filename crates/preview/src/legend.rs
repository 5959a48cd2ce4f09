//! The error map's legend: a colour bar from -bound to +bound with its labels, in the
//! bundled font (DejaVu Sans Mono, fonts/LICENSE-DejaVu.txt).

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};

use crate::colour::diverging;

/// The bundled font.
const FONT: &[u8] = include_bytes!("../fonts/DejaVuSansMono.ttf");

/// An opaque RGBA canvas the legend is drawn on.
pub(crate) struct Canvas<'a> {
    pub(crate) rgba: &'a mut [u8],
    pub(crate) width: u32,
    pub(crate) height: u32,
}

impl Canvas<'_> {
    /// Blends `colour` over pixel (x, y) with `alpha` (0..=1); outside, nothing.
    fn blend(&mut self, x: i64, y: i64, colour: [u8; 3], alpha: f32) {
        if x < 0 || y < 0 || x >= i64::from(self.width) || y >= i64::from(self.height) {
            return;
        }
        let k = (y as usize * self.width as usize + x as usize) * 4;
        let a = alpha.clamp(0.0, 1.0);
        for (slot, &target) in self.rgba[k..k + 3].iter_mut().zip(&colour) {
            let old = f32::from(*slot);
            *slot = (old + (f32::from(target) - old) * a).round() as u8;
        }
    }

    fn fill(&mut self, x0: i64, y0: i64, w: i64, h: i64, colour: [u8; 3], alpha: f32) {
        for y in y0..y0 + h {
            for x in x0..x0 + w {
                self.blend(x, y, colour, alpha);
            }
        }
    }

    /// Draws `text` with its baseline's left end at (x, y), `size` pixels high; returns
    /// its advance.
    fn text(&mut self, text: &str, x: f32, y: f32, size: f32, colour: [u8; 3]) -> f32 {
        let font = FontRef::try_from_slice(FONT).expect("the bundled font parses");
        let scaled = font.as_scaled(PxScale::from(size));
        let mut pen = x;
        for c in text.chars() {
            let glyph = scaled.scaled_glyph(c);
            let advance = scaled.h_advance(glyph.id);
            let glyph = glyph
                .id
                .with_scale_and_position(size, ab_glyph::point(pen, y));
            if let Some(outline) = font.outline_glyph(glyph) {
                let bounds = outline.px_bounds();
                outline.draw(|gx, gy, coverage| {
                    self.blend(
                        bounds.min.x as i64 + i64::from(gx),
                        bounds.min.y as i64 + i64::from(gy),
                        colour,
                        coverage,
                    );
                });
            }
            pen += advance;
        }
        pen - x
    }

    /// The advance of `text` at `size`, without drawing it.
    fn measure(text: &str, size: f32) -> f32 {
        let font = FontRef::try_from_slice(FONT).expect("the bundled font parses");
        let scaled = font.as_scaled(PxScale::from(size));
        text.chars()
            .map(|c| scaled.h_advance(scaled.glyph_id(c)))
            .sum()
    }
}

/// Draws the legend of an error map spanning `-bound..=bound` in the canvas's lower-left
/// corner: `title`, the colour bar, and its labels (`-bound`, `0`, `+bound`).
pub(crate) fn draw_error_legend(canvas: &mut Canvas<'_>, bound: f64, title: &str) {
    let scale = (canvas.width.min(canvas.height) as f32 / 600.0).clamp(0.6, 3.0);
    let size = 13.0 * scale;
    let bar_w = (canvas.width as f32 * 0.35).clamp(60.0, 420.0);
    let bar_h = 10.0 * scale;
    let pad = 6.0 * scale;
    let box_w = bar_w + 2.0 * pad;
    let box_h = bar_h + 2.0 * size + 4.0 * pad;
    let x0 = pad;
    let y0 = canvas.height as f32 - box_h - pad;
    canvas.fill(
        x0 as i64,
        y0 as i64,
        box_w.ceil() as i64,
        box_h.ceil() as i64,
        [255, 255, 255],
        0.85,
    );
    canvas.text(title, x0 + pad, y0 + pad + size * 0.8, size, [20, 20, 20]);
    let bar_y = y0 + 2.0 * pad + size;
    for k in 0..bar_w.round() as i64 {
        let t = 2.0 * (k as f64 + 0.5) / f64::from(bar_w) - 1.0;
        let colour = diverging(t);
        canvas.fill(
            (x0 + pad) as i64 + k,
            bar_y as i64,
            1,
            bar_h.ceil() as i64,
            colour,
            1.0,
        );
    }
    let label_y = bar_y + bar_h + pad + size * 0.8;
    let labels = [
        (format!("-{}", short(bound)), 0.0),
        ("0".to_owned(), 0.5),
        (format!("+{}", short(bound)), 1.0),
    ];
    for (text, at) in labels {
        let w = Canvas::measure(&text, size);
        let x = (x0 + pad + bar_w * at - w * at).max(x0 + pad);
        canvas.text(&text, x, label_y, size, [20, 20, 20]);
    }
}

/// A bound as a short label: up to 4 significant digits, no trailing zeros.
fn short(v: f64) -> String {
    let text = format!("{:.4}", v);
    let trimmed = text.trim_end_matches('0').trim_end_matches('.');
    if v != 0.0 && (v.abs() >= 1e6 || v.abs() < 1e-3) {
        format!("{v:.3e}")
    } else {
        trimmed.to_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_are_short() {
        assert_eq!(short(5.0), "5");
        assert_eq!(short(0.25), "0.25");
        assert_eq!(short(1e7), "1.000e7");
    }

    #[test]
    fn the_legend_draws_text_and_the_bar() {
        let (w, h) = (400u32, 300u32);
        let mut rgba = vec![128u8; (w * h * 4) as usize];
        let mut canvas = Canvas {
            rgba: &mut rgba,
            width: w,
            height: h,
        };
        draw_error_legend(&mut canvas, 5.0, "error, TIN - raster");
        // Some pixels are near the bar's blue end, some the dark text.
        let pixels: Vec<&[u8]> = rgba.chunks(4).collect();
        let blue = diverging(-1.0);
        assert!(pixels
            .iter()
            .any(|p| (0..3).all(|c| p[c].abs_diff(blue[c]) <= 3)));
        assert!(pixels.iter().any(|p| p[0] < 60 && p[1] < 60 && p[2] < 60));
    }
}
