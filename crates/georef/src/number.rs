//! Numbers for people, as every tinsmith message writes them: `f64`'s `Display` never
//! switches to an exponent, so 1e297 would print as a 298-digit string.

/// `x` as `Display` writes it (the shortest text that reads back as `x`), in scientific
/// notation when it is at least 1e16 or below 1e-5 in magnitude (and not zero).
pub fn readable(x: f64) -> String {
    let magnitude = x.abs();
    if magnitude != 0.0 && magnitude.is_finite() && !(1e-5..1e16).contains(&magnitude) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

#[cfg(test)]
mod tests {
    use super::readable;

    #[test]
    fn long_numbers_get_an_exponent_and_the_rest_stay() {
        assert_eq!(readable(1e297), "1e297");
        assert_eq!(readable(-3.4028234663852886e38), "-3.4028234663852886e38");
        assert_eq!(readable(2.5e-7), "2.5e-7");
        assert_eq!(readable(0.9750000000000227), "0.9750000000000227");
        assert_eq!(readable(1427.0912621359223), "1427.0912621359223");
        assert_eq!(readable(0.0), "0");
        assert_eq!(readable(f64::INFINITY), "inf");
    }
}
