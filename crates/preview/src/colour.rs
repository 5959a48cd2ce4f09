//! The diverging colour map of signed errors.

/// Blue for the TIN below the raster, white for no error, red for the TIN above
/// (ColorBrewer's RdBu ends), linear in between: `t` is the error over the bound, clamped
/// to -1..=1.
pub(crate) fn diverging(t: f64) -> [u8; 3] {
    const BELOW: [f64; 3] = [33.0, 102.0, 172.0];
    const ZERO: [f64; 3] = [247.0, 247.0, 247.0];
    const ABOVE: [f64; 3] = [178.0, 24.0, 43.0];
    let t = if t.is_nan() { 0.0 } else { t.clamp(-1.0, 1.0) };
    let (end, w) = if t < 0.0 { (BELOW, -t) } else { (ABOVE, t) };
    [0, 1, 2].map(|k| (ZERO[k] + (end[k] - ZERO[k]) * w).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_and_middle() {
        assert_eq!(diverging(0.0), [247, 247, 247]);
        assert_eq!(diverging(-1.0), [33, 102, 172]);
        assert_eq!(diverging(7.0), [178, 24, 43]);
        let half = diverging(0.5);
        assert!(half[0] > half[2]);
    }
}
