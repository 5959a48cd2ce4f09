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

/// How a triangle of `[longitude, latitude, height]` corners is written in RFC 7946
/// GeoJSON: whole, or cut at the antimeridian into a west part (longitudes up to 180) and
/// an east part (from -180), each an open ring in the triangle's orientation.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum TriangleParts {
    /// The corners, longitudes wrapped into [-180, 180] (a corner on the antimeridian on
    /// the side of the others).
    Whole([[f64; 3]; 3]),
    /// West and east parts (3 or 4 positions each).
    Cut(Vec<[f64; 3]>, Vec<[f64; 3]>),
}

/// The RFC 7946 form of a triangle: like [`cut_at_antimeridian`] for lines, corners whose
/// wrapped longitudes lie more than 180° apart are taken to span the antimeridian the
/// short way, and the triangle is cut there unless it only touches it. A cut point's
/// latitude and height are interpolated linearly along the edge. Corners keep their
/// wrapped longitude bit for bit (±180 on the side of their part), so a vertex shared with
/// whole triangles reads back to the same position, 180 and -180 counting as one.
pub(crate) fn triangle_parts(corners: [[f64; 3]; 3]) -> TriangleParts {
    let wrapped = corners.map(|p| [wrap_longitude(p[0]), p[1], p[2]]);
    let (lo, hi) = wrapped
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[0]), hi.max(p[0]))
        });
    if hi - lo <= 180.0 {
        return TriangleParts::Whole(wrapped);
    }
    // Longitudes continued east across 180: [0, 360).
    let east_of = |p: &[f64; 3]| if p[0] < 0.0 { p[0] + 360.0 } else { p[0] };
    let unwrapped = wrapped.map(|p| [east_of(&p), p[1], p[2]]);
    let west = unwrapped.iter().any(|p| p[0] < 180.0);
    let east = unwrapped.iter().any(|p| p[0] > 180.0);
    if !(west && east) {
        // Only touching 180: put corners on it on the side of the others.
        let side = if east { -180.0 } else { 180.0 };
        return TriangleParts::Whole(wrapped.map(|p| {
            if p[0].abs() == 180.0 {
                [side, p[1], p[2]]
            } else {
                p
            }
        }));
    }
    let (mut west_part, mut east_part) = (Vec::with_capacity(4), Vec::with_capacity(4));
    for k in 0..3 {
        let (p, q) = (unwrapped[k], unwrapped[(k + 1) % 3]);
        let corner = wrapped[k];
        if p[0] <= 180.0 {
            west_part.push([if p[0] == 180.0 { 180.0 } else { corner[0] }, p[1], p[2]]);
        }
        if p[0] >= 180.0 {
            east_part.push([if p[0] == 180.0 { -180.0 } else { corner[0] }, p[1], p[2]]);
        }
        if (p[0] - 180.0) * (q[0] - 180.0) < 0.0 {
            let t = (180.0 - p[0]) / (q[0] - p[0]);
            let (lat, height) = (p[1] + t * (q[1] - p[1]), p[2] + t * (q[2] - p[2]));
            west_part.push([180.0, lat, height]);
            east_part.push([-180.0, lat, height]);
        }
    }
    TriangleParts::Cut(west_part, east_part)
}

/// The triangle a [`TriangleParts::Cut`] came from, given its parts' positions (either
/// part first): of the positions, the three spanning the largest area once negative
/// longitudes (the east part's) are continued across 180 (the corners; cut points lie on
/// its sides), counter-clockwise, with their written (wrapped) coordinates and -180 read
/// as 180. `None` when there are fewer than three positions or they span no area.
pub(crate) fn triangle_from_parts(parts: &[&[[f64; 3]]]) -> Option<[[f64; 3]; 3]> {
    let points: Vec<([f64; 3], [f64; 2])> = parts
        .iter()
        .flat_map(|part| part.iter())
        .map(|p| (*p, [if p[0] < 0.0 { p[0] + 360.0 } else { p[0] }, p[1]]))
        .collect();
    let area = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let mut best: Option<(f64, [usize; 3])> = None;
    for i in 0..points.len() {
        for j in i + 1..points.len() {
            for k in j + 1..points.len() {
                let doubled = area(points[i].1, points[j].1, points[k].1);
                if best.is_none_or(|(b, _)| doubled.abs() > b) {
                    let order = if doubled > 0.0 { [i, j, k] } else { [i, k, j] };
                    best = Some((doubled.abs(), order));
                }
            }
        }
    }
    let (doubled, order) = best?;
    (doubled > 0.0).then(|| {
        order.map(|i| {
            let p = points[i].0;
            [if p[0] == -180.0 { 180.0 } else { p[0] }, p[1], p[2]]
        })
    })
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
    fn triangles_across_180_are_cut_and_read_back() {
        // Counter-clockwise on 0..360 longitudes: (179, 0), (182, 0), (180.5, 3).
        let t = [[179.0, 0.0, 10.0], [182.0, 0.0, 40.0], [180.5, 3.0, 25.0]];
        let TriangleParts::Cut(west, east) = triangle_parts(t) else {
            panic!("not cut");
        };
        assert!(west.iter().all(|p| p[0] > 0.0 && p[0] <= 180.0), "{west:?}");
        assert!(
            east.iter().all(|p| p[0] < 0.0 && p[0] >= -180.0),
            "{east:?}"
        );
        // The cut of the bottom edge is a third of the way along.
        assert!(west.contains(&[180.0, 0.0, 20.0]) && east.contains(&[-180.0, 0.0, 20.0]));
        assert_eq!(west.len() + east.len(), 3 + 4);
        let back = triangle_from_parts(&[&west, &east]).expect("a triangle");
        let expected = t.map(|p| [wrap_longitude(p[0]), p[1], p[2]]);
        // Same corners, counter-clockwise, starting anywhere.
        assert!(
            (0..3).any(|r| (0..3).all(|k| back[(k + r) % 3] == expected[k])),
            "{back:?}"
        );
    }

    #[test]
    fn triangles_that_do_not_cross_stay_whole() {
        let t = [[10.0, 0.0, 1.0], [12.0, 0.0, 1.0], [11.0, 1.0, 1.0]];
        assert_eq!(triangle_parts(t), TriangleParts::Whole(t));
        let beyond = [[190.0, 0.0, 1.0], [192.0, 0.0, 1.0], [191.0, 1.0, 1.0]];
        assert_eq!(
            triangle_parts(beyond),
            TriangleParts::Whole([[-170.0, 0.0, 1.0], [-168.0, 0.0, 1.0], [-169.0, 1.0, 1.0]])
        );
        // A corner on 180 goes to the side of the others.
        let touching = [[180.0, 0.0, 1.0], [181.0, 0.0, 1.0], [181.0, 1.0, 1.0]];
        assert_eq!(
            triangle_parts(touching),
            TriangleParts::Whole([[-180.0, 0.0, 1.0], [-179.0, 0.0, 1.0], [-179.0, 1.0, 1.0]])
        );
        let touching = [[-180.0, 0.0, 1.0], [179.0, 1.0, 1.0], [179.0, 0.0, 1.0]];
        assert_eq!(
            triangle_parts(touching),
            TriangleParts::Whole([[180.0, 0.0, 1.0], [179.0, 1.0, 1.0], [179.0, 0.0, 1.0]])
        );
    }

    #[test]
    fn a_corner_on_180_between_the_others_is_kept_in_both_parts() {
        let t = [[179.0, 0.0, 0.0], [181.0, 0.0, 0.0], [180.0, 2.0, 0.0]];
        let TriangleParts::Cut(west, east) = triangle_parts(t) else {
            panic!("not cut");
        };
        assert!(west.contains(&[180.0, 2.0, 0.0]) && east.contains(&[-180.0, 2.0, 0.0]));
        let back = triangle_from_parts(&[&east, &west]).expect("a triangle");
        for corner in [[179.0, 0.0, 0.0], [-179.0, 0.0, 0.0], [180.0, 2.0, 0.0]] {
            assert!(back.contains(&corner), "{back:?}");
        }
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
