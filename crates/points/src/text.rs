//! XYZ/CSV text: `x y z` columns, an optional header line, the delimiter detected from the
//! first line (comma, semicolon, tab, else runs of spaces). Read line by line.

use std::io::BufRead;
use std::path::Path;

use crate::cloud::{ClassChoice, FileCrs, PointCloud, MAX_LATTICE};
use crate::error::{format_error, Error, Result};

/// The most decimals a coordinate may carry: the lattice spacing is `10^-decimals`.
const MAX_DECIMALS: u32 = 12;

/// Reads a text point file into a [`PointCloud`] on the lattice of spacing `10^-d`, `d`
/// the most decimals any x or y has (so every position is exactly a lattice point up to
/// `f64` rounding).
pub(crate) fn read_text(path: &Path) -> Result<PointCloud> {
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let mut reader = std::io::BufReader::with_capacity(1 << 20, file);
    let mut line = String::new();
    let mut delimiter: Option<Delimiter> = None;
    let mut columns = [0usize, 1, 2];
    let (mut world, mut z): (Vec<[f64; 2]>, Vec<f64>) = (Vec::new(), Vec::new());
    let mut decimals = 0u32;
    let mut number = 0usize;
    loop {
        line.clear();
        if reader.read_line(&mut line).map_err(io)? == 0 {
            break;
        }
        number += 1;
        let text = line.trim();
        if text.is_empty() || text.starts_with('#') || text.starts_with("//") {
            continue;
        }
        let delim = *delimiter.get_or_insert_with(|| Delimiter::detect(text));
        let mut fields: Vec<&str> = Vec::with_capacity(8);
        delim.split(text, &mut fields);
        let first_data = world.is_empty();
        if first_data && fields.len() >= 3 && fields[..3].iter().any(|f| f.parse::<f64>().is_err())
        {
            // A header: x, y, z by name when named so, else the first three columns.
            let find = |names: &[&str]| {
                fields.iter().position(|f| {
                    let f = f.trim_matches('"').to_ascii_lowercase();
                    names.contains(&f.as_str())
                })
            };
            if let (Some(x), Some(y), Some(zc)) = (
                find(&["x", "easting", "east", "lon", "longitude"]),
                find(&["y", "northing", "north", "lat", "latitude"]),
                find(&["z", "elevation", "height", "elev", "h"]),
            ) {
                columns = [x, y, zc];
            }
            continue;
        }
        let need = columns.iter().max().copied().unwrap_or(2) + 1;
        if fields.len() < need {
            return Err(format_error(
                path,
                format!(
                    "line {number}: {} columns, expected at least {need}",
                    fields.len()
                ),
            ));
        }
        let mut value = [0.0f64; 3];
        for (k, &c) in columns.iter().enumerate() {
            let f = fields[c];
            let v: f64 = f
                .parse()
                .map_err(|_| format_error(path, format!("line {number}: {f:?} is not a number")))?;
            if !v.is_finite() {
                return Err(format_error(
                    path,
                    format!("line {number}: coordinate {f} is not finite"),
                ));
            }
            if k < 2 {
                decimals = decimals.max(decimals_of(f));
            }
            value[k] = v;
        }
        world.push([value[0], value[1]]);
        z.push(value[2]);
    }
    if decimals > MAX_DECIMALS {
        return Err(format_error(
            path,
            format!("coordinates carry {decimals} decimals; at most {MAX_DECIMALS} are taken"),
        ));
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &world {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let per_unit = 10f64.powi(decimals as i32);
    if world.is_empty() {
        lo = [0.0; 2];
    } else if (0..2).any(|a| ((hi[a] - lo[a]) * per_unit).round() > MAX_LATTICE as f64) {
        return Err(format_error(
            path,
            format!(
                "the points span {} x {} at a spacing of 1e-{decimals} (the decimals given): \
                 more than {MAX_LATTICE} lattice steps, beyond the exact integer geometry; \
                 write fewer decimals",
                hi[0] - lo[0],
                hi[1] - lo[1]
            ),
        ));
    }
    let xy = world
        .into_iter()
        .map(|p| {
            [
                ((p[0] - lo[0]) * per_unit).round() as i64,
                ((p[1] - lo[1]) * per_unit).round() as i64,
            ]
        })
        .collect();
    let points_in_file = z.len() as u64;
    Ok(PointCloud {
        xy,
        z,
        origin: lo,
        spacing: [1.0 / per_unit; 2],
        crs: FileCrs::default(),
        classes: ClassChoice::All,
        points_in_file,
    })
}

/// Decimal places of a number as written: `12.340` has 3, `1.5e-2` has 3, `100` has 0.
fn decimals_of(text: &str) -> u32 {
    let (mantissa, exponent) = match text.find(['e', 'E']) {
        Some(i) => (&text[..i], text[i + 1..].parse::<i32>().unwrap_or(0)),
        None => (text, 0),
    };
    let fraction = mantissa.find('.').map_or(0, |i| mantissa.len() - i - 1) as i32;
    (fraction - exponent).max(0) as u32
}

#[derive(Debug, Clone, Copy)]
enum Delimiter {
    Char(char),
    Whitespace,
}

impl Delimiter {
    fn detect(line: &str) -> Delimiter {
        [',', ';', '\t']
            .into_iter()
            .find(|&c| line.contains(c))
            .map_or(Delimiter::Whitespace, Delimiter::Char)
    }

    fn split<'a>(self, line: &'a str, out: &mut Vec<&'a str>) {
        match self {
            Delimiter::Char(c) => out.extend(line.split(c).map(str::trim)),
            Delimiter::Whitespace => out.extend(line.split_whitespace()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<PointCloud> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.csv");
        std::fs::write(&path, text).unwrap();
        read_text(&path)
    }

    #[test]
    fn decimals_as_written() {
        assert_eq!(decimals_of("12.340"), 3);
        assert_eq!(decimals_of("1.5e-2"), 3);
        assert_eq!(decimals_of("100"), 0);
        assert_eq!(decimals_of("1.25E1"), 1);
    }

    #[test]
    fn delimiters_and_headers() {
        for text in [
            "x,y,z\n1.5,2,3\n4,5.25,6\n",
            "1.5;2;3\n4;5.25;6\n",
            "X\tY\tZ\n1.5\t2\t3\n4\t5.25\t6\n",
            "# survey\n1.5  2 3\n 4 5.25    6\n",
        ] {
            let c = read(text).unwrap();
            assert_eq!(c.z, vec![3.0, 6.0], "{text:?}");
            assert_eq!(c.spacing, [0.01, 0.01]);
            assert_eq!(c.xy, vec![[0, 0], [250, 325]], "{text:?}");
            assert_eq!(c.world(1), [4.0, 5.25]);
        }
        // Named columns in another order.
        let c = read("id,z,y,x\n7,10,2,1\n8,20,3,5\n").unwrap();
        assert_eq!(c.z, vec![10.0, 20.0]);
        assert_eq!(c.xy, vec![[0, 0], [4, 1]]);
    }

    #[test]
    fn bad_numbers_name_the_line() {
        let e = read("1,2,3\n4,nan,6\n").unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("not finite"), "{e}");
        let e = read("1,2,3\n4,inf,6\n").unwrap_err().to_string();
        assert!(e.contains("line 2"), "{e}");
        let e = read("1,2,3\n4,5\n").unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("columns"), "{e}");
        let e = read("1,2,3\n4,abc,6\n").unwrap_err().to_string();
        assert!(e.contains("not a number"), "{e}");
    }

    #[test]
    fn too_wide_for_the_lattice_is_refused() {
        let e = read("0.000001,0,1\n5000,0,2\n").unwrap_err().to_string();
        assert!(e.contains("lattice"), "{e}");
    }
}
