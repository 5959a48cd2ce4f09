//! Parsers of the numeric flags, each refusing what its flag cannot take.

pub(super) fn parse_max_error(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a number"))?;
    if !v.is_finite() || v < 0.0 {
        return Err(format!("must be a finite number >= 0, got {s}"));
    }
    Ok(positive_zero(v))
}

/// `v`, with -0 as 0 (so that reports, summaries and `elev` values never say "-0").
fn positive_zero(v: f64) -> f64 {
    if v == 0.0 {
        0.0
    } else {
        v
    }
}

pub(super) fn parse_interval(s: &str) -> Result<f64, String> {
    let v = parse_finite(s)?;
    if v <= 0.0 {
        return Err(format!("must be a finite number > 0, got {s}"));
    }
    Ok(v)
}

pub(super) fn parse_finite(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a number"))?;
    if !v.is_finite() {
        return Err(format!("must be a finite number, got {s}"));
    }
    Ok(positive_zero(v))
}

/// `--threads` of `tiles`: 0 (one per core) to 1024.
pub(super) fn threads_or_all(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if n <= 1024 => Ok(n),
        _ => Err(format!(
            "{s} is not a thread count from 0 (one per core) to 1024"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minus_zero_is_read_as_zero() {
        for parsed in [
            parse_max_error("-0"),
            parse_finite("-0"),
            parse_finite("-0.0"),
        ] {
            let v = parsed.expect("a number");
            assert!(v == 0.0 && v.is_sign_positive(), "{v}");
        }
        assert!(parse_max_error("-1").is_err());
        assert_eq!(parse_finite("-2.5"), Ok(-2.5));
    }
}
