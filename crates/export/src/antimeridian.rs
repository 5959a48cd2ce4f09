//! Longitudes into [-180, 180] and lines cut where they cross the antimeridian, as RFC 7946
//! (§3.1.9, §3.1.10 of GeoJSON) asks of WGS84 coordinates: a raster on 0..360 longitudes
//! (common for global grids) or reprojected across 180° would otherwise give positions
//! beyond 180 or segments that run the long way round the globe.

/// `lon` in degrees moved by whole turns into [-180, 180]; values already in that range
/// (180 and -180 included) are returned unchanged.
pub fn wrap_longitude(lon: f64) -> f64 {
    if lon > 180.0 {
        lon - 360.0 * ((lon - 180.0) / 360.0).ceil()
    } else if lon < -180.0 {
        lon + 360.0 * ((-180.0 - lon) / 360.0).ceil()
    } else {
        lon
    }
}

/// The parts of a line of `[longitude, latitude, ...]` points (degrees) with longitudes
/// wrapped into [-180, 180] and cut wherever a segment crosses the antimeridian: a segment
/// whose wrapped ends lie more than 180° apart is taken to cross it the short way, ends
/// its part at ±180 and starts the next at ∓180 (the latitude of the crossing interpolated
/// linearly, other values kept from the segment's start). Repeated points at a cut are
/// dropped, and so are parts left with fewer than two points. A closed line (first point
/// equal to last) that is cut has its last and first parts joined, since they meet at the
/// first point. A line that never crosses comes back as one part with wrapped longitudes.
pub fn cut_at_antimeridian<const N: usize>(points: &[[f64; N]]) -> Vec<Vec<[f64; N]>> {
    let wrapped: Vec<[f64; N]> = points
        .iter()
        .map(|p| {
            let mut q = *p;
            q[0] = wrap_longitude(p[0]);
            q
        })
        .collect();
    let closed = points.len() > 2 && points.first() == points.last();
    let mut parts: Vec<Vec<[f64; N]>> = Vec::new();
    let mut part: Vec<[f64; N]> = Vec::new();
    for (k, &p) in wrapped.iter().enumerate() {
        if let Some(&q) = k.checked_sub(1).map(|k| &wrapped[k]) {
            if (p[0] - q[0]).abs() > 180.0 {
                // East across 180 when the previous point is in the east, else west.
                let east = q[0] > p[0];
                let (edge, shifted) = if east {
                    (180.0, p[0] + 360.0)
                } else {
                    (-180.0, p[0] - 360.0)
                };
                // Ends on both sides of the same meridian (180 and -180): cut at the start.
                let t = if shifted == q[0] {
                    0.0
                } else {
                    (edge - q[0]) / (shifted - q[0])
                };
                let mut cut = q;
                cut[0] = edge;
                cut[1] = q[1] + t * (p[1] - q[1]);
                push_distinct(&mut part, cut);
                parts.push(std::mem::take(&mut part));
                cut[0] = -edge;
                part.push(cut);
            }
        }
        push_distinct(&mut part, p);
    }
    parts.push(part);
    if closed && parts.len() > 1 {
        let last = parts.pop().expect("more than one part");
        let mut joined = last;
        joined.extend_from_slice(&parts[0][1..]);
        parts[0] = joined;
    }
    parts.retain(|part| part.len() >= 2);
    parts
}

fn push_distinct<const N: usize>(part: &mut Vec<[f64; N]>, p: [f64; N]) {
    if part.last() != Some(&p) {
        part.push(p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn longitudes_wrap_by_whole_turns() {
        assert_eq!(wrap_longitude(180.0), 180.0);
        assert_eq!(wrap_longitude(-180.0), -180.0);
        assert_eq!(wrap_longitude(190.0), -170.0);
        assert_eq!(wrap_longitude(359.5), -0.5);
        assert_eq!(wrap_longitude(-190.0), 170.0);
        assert_eq!(wrap_longitude(720.0 + 10.0), 10.0);
        assert_eq!(wrap_longitude(12.25), 12.25);
    }

    #[test]
    fn a_line_across_180_is_cut_at_the_interpolated_latitude() {
        let parts = cut_at_antimeridian(&[[170.0, 0.0], [190.0, 10.0], [200.0, 10.0]]);
        assert_eq!(
            parts,
            vec![
                vec![[170.0, 0.0], [180.0, 5.0]],
                vec![[-180.0, 5.0], [-170.0, 10.0], [-160.0, 10.0]],
            ]
        );
        // Westward, in already wrapped longitudes.
        let parts = cut_at_antimeridian(&[[-175.0, 2.0], [175.0, 4.0]]);
        assert_eq!(
            parts,
            vec![
                vec![[-175.0, 2.0], [-180.0, 3.0]],
                vec![[180.0, 3.0], [175.0, 4.0]]
            ]
        );
    }

    #[test]
    fn lines_that_do_not_cross_stay_whole() {
        let line = [[10.0, 1.0, 7.0], [20.0, 2.0, 7.0], [-30.0, 3.0, 7.0]];
        assert_eq!(cut_at_antimeridian(&line), vec![line.to_vec()]);
        let east = cut_at_antimeridian(&[[200.0, 1.0], [210.0, 1.0]]);
        assert_eq!(east, vec![vec![[-160.0, 1.0], [-150.0, 1.0]]]);
    }

    #[test]
    fn a_closed_ring_across_180_becomes_two_parts_joined_at_its_start() {
        // A square around (180, 0) given on 0..360 longitudes, starting west of 180.
        let ring = [
            [179.0, -1.0],
            [181.0, -1.0],
            [181.0, 1.0],
            [179.0, 1.0],
            [179.0, -1.0],
        ];
        let parts = cut_at_antimeridian(&ring);
        assert_eq!(
            parts,
            vec![
                vec![[180.0, 1.0], [179.0, 1.0], [179.0, -1.0], [180.0, -1.0]],
                vec![[-180.0, -1.0], [-179.0, -1.0], [-179.0, 1.0], [-180.0, 1.0]],
            ]
        );
    }

    #[test]
    fn a_segment_from_180_to_minus_180_is_cut_at_its_start() {
        let parts = cut_at_antimeridian(&[[179.0, 0.0], [180.0, 1.0], [-180.0, 2.0]]);
        assert_eq!(
            parts,
            vec![
                vec![[179.0, 0.0], [180.0, 1.0]],
                vec![[-180.0, 1.0], [-180.0, 2.0]]
            ]
        );
    }

    #[test]
    fn a_point_on_180_makes_no_empty_part() {
        let parts = cut_at_antimeridian(&[[179.0, 0.0], [180.0, 0.0], [181.0, 0.0]]);
        assert_eq!(
            parts,
            vec![
                vec![[179.0, 0.0], [180.0, 0.0]],
                vec![[-180.0, 0.0], [-179.0, 0.0]]
            ]
        );
    }
}
