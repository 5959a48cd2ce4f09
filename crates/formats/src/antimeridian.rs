//! Longitudes into [-180, 180] and lines cut where they cross the antimeridian, as RFC 7946
//! (§3.1.9, §3.1.10 of GeoJSON) asks of WGS84 coordinates: a raster on 0..360 longitudes
//! (common for global grids) or reprojected across 180° would otherwise give positions
//! beyond 180 or segments that run the long way round the globe.

/// `lon` in degrees moved by whole turns into [-180, 180]; values already in that range
/// (180 and -180 included) are returned unchanged. (The writers move whole pieces by
/// their frame's turns instead; this states what they give, for the tests.)
#[cfg(test)]
pub(crate) fn wrap_longitude(lon: f64) -> f64 {
    if lon > 180.0 {
        lon - 360.0 * ((lon - 180.0) / 360.0).ceil()
    } else if lon < -180.0 {
        lon + 360.0 * ((-180.0 - lon) / 360.0).ceil()
    } else {
        lon
    }
}

/// The whole turns `k` such that `lon - 360 k` lies in [-180, 180], `lon` a longitude
/// strictly inside its frame or the middle of a piece (a point on a meridian 180 + 360 j
/// belongs to the frame east of it: it is only asked for pieces' middles).
fn frame_of(lon: f64) -> f64 {
    ((lon + 180.0) / 360.0).floor()
}

/// The meridians `180 + 360 j` strictly between `a` and `b` (in either order), west first.
fn meridians_between(a: f64, b: f64) -> impl Iterator<Item = f64> {
    let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
    let first = ((lo - 180.0) / 360.0).floor() + 1.0;
    (0..)
        .map(move |j| 180.0 + 360.0 * (first + f64::from(j)))
        .take_while(move |&m| m < hi)
        .filter(move |&m| m > lo)
}

/// The point of segment `p q` at longitude `m`, other values interpolated linearly from
/// the segment's west end (so both sides of a shared edge give the same bits).
fn at_meridian<const N: usize>(p: &[f64; N], q: &[f64; N], m: f64) -> [f64; N] {
    let (w, e) = if p[0] <= q[0] { (p, q) } else { (q, p) };
    let t = (m - w[0]) / (e[0] - w[0]);
    let mut out = *w;
    for k in 1..N {
        out[k] = w[k] + t * (e[k] - w[k]);
    }
    out[0] = m;
    out
}

/// `p` with its longitude moved by `turns` whole turns west.
fn shifted<const N: usize>(p: &[f64; N], turns: f64) -> [f64; N] {
    let mut q = *p;
    q[0] = p[0] - 360.0 * turns;
    q
}

/// The parts of a line of `[longitude, latitude, ...]` points (degrees), the longitudes
/// given in one continuous frame (as a geographic raster's, or a reprojected raster's
/// unwrapped around its centre), for RFC 7946: each segment is cut where it crosses a
/// meridian 180 + 360 j (the latitude and other values interpolated linearly), each piece
/// is moved by whole turns into [-180, 180], and a new part starts where the turns change
/// (so a part ends on 180 and the next starts on -180, or the other way). Repeated points
/// are dropped, and so are parts left with fewer than two points. A closed line (first
/// point equal to last) that is cut has its last and first parts joined when they meet
/// there. A line that never crosses comes back as one part.
pub fn cut_at_antimeridian<const N: usize>(points: &[[f64; N]]) -> Vec<Vec<[f64; N]>> {
    let closed = points.len() > 2 && points.first() == points.last();
    let mut parts: Vec<(f64, Vec<[f64; N]>)> = Vec::new();
    let add_piece = |a: [f64; N], b: [f64; N], parts: &mut Vec<(f64, Vec<[f64; N]>)>| {
        let turns = frame_of((a[0] + b[0]) / 2.0);
        let (a, b) = (shifted(&a, turns), shifted(&b, turns));
        match parts.last_mut() {
            Some((t, part)) if *t == turns => {
                push_distinct(part, a);
                push_distinct(part, b);
            }
            _ => parts.push((turns, vec![a, b])),
        }
    };
    for pair in points.windows(2) {
        let (p, q) = (&pair[0], &pair[1]);
        let mut from = *p;
        let mut cuts: Vec<f64> = meridians_between(p[0], q[0]).collect();
        if q[0] < p[0] {
            cuts.reverse();
        }
        for m in cuts {
            let cut = at_meridian(p, q, m);
            add_piece(from, cut, &mut parts);
            from = cut;
        }
        add_piece(from, *q, &mut parts);
    }
    if closed && parts.len() > 1 && parts[0].0 == parts[parts.len() - 1].0 {
        let (_, last) = parts.pop().expect("more than one part");
        let mut joined = last;
        joined.extend_from_slice(&parts[0].1[1..]);
        parts[0].1 = joined;
    }
    parts
        .into_iter()
        .map(|(_, part)| part)
        .filter(|part| part.len() >= 2)
        .collect()
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

/// The RFC 7946 form of a triangle whose longitudes are given in one continuous frame
/// (see [`cut_at_antimeridian`]): moved by whole turns into [-180, 180] if no meridian
/// 180 + 360 j passes strictly through it, else cut there into a west part (ending on 180)
/// and an east part (starting on -180), the cut points interpolated linearly along the
/// edges from their west ends (so a shared edge gives the same bits). A corner is moved by
/// the turns of its part, so it keeps the same bits wherever it is written, except that a
/// corner on the meridian is 180 in a part west of it and -180 east of it.
pub(crate) fn triangle_parts(corners: [[f64; 3]; 3]) -> TriangleParts {
    let (lo, hi) = corners
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[0]), hi.max(p[0]))
        });
    let Some(m) = meridians_between(lo, hi).next() else {
        let turns = frame_of((lo + hi) / 2.0);
        return TriangleParts::Whole(corners.map(|p| shifted(&p, turns)));
    };
    let west_turns = frame_of(m - 1.0);
    let (mut west, mut east) = (Vec::with_capacity(4), Vec::with_capacity(4));
    for k in 0..3 {
        let (p, q) = (&corners[k], &corners[(k + 1) % 3]);
        if p[0] <= m {
            west.push(shifted(p, west_turns));
        }
        if p[0] >= m {
            east.push(shifted(p, west_turns + 1.0));
        }
        if (p[0] - m) * (q[0] - m) < 0.0 {
            let cut = at_meridian(p, q, m);
            west.push(shifted(&cut, west_turns));
            east.push(shifted(&cut, west_turns + 1.0));
        }
    }
    TriangleParts::Cut(west, east)
}

/// The triangle a [`TriangleParts::Cut`] came from, given its parts' positions (either
/// part first): of the positions, the three spanning the largest area once the east part
/// (the one cut on -180) is continued a turn east (the corners; cut points lie on its
/// sides), counter-clockwise, with their written (wrapped) coordinates. `None` when there
/// are fewer than three positions or they span no area.
pub(crate) fn triangle_from_parts(parts: &[&[[f64; 3]]]) -> Option<[[f64; 3]; 3]> {
    // The east part is the one cut on -180; continued a turn east, it meets the west one.
    let points: Vec<([f64; 3], [f64; 2])> = parts
        .iter()
        .flat_map(|part| {
            let turn = if part.iter().any(|p| p[0] == -180.0) {
                360.0
            } else {
                0.0
            };
            part.iter().map(move |p| (*p, [p[0] + turn, p[1]]))
        })
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
    (doubled > 0.0).then(|| order.map(|i| points[i].0))
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
        // Westward across -180.
        let parts = cut_at_antimeridian(&[[-175.0, 2.0], [-185.0, 4.0]]);
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
    fn a_segment_along_180_belongs_to_the_east() {
        let parts = cut_at_antimeridian(&[[179.0, 0.0], [180.0, 1.0], [180.0, 2.0]]);
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
        let touching = [[180.0, 0.0, 1.0], [179.0, 1.0, 1.0], [179.0, 0.0, 1.0]];
        assert_eq!(
            triangle_parts(touching),
            TriangleParts::Whole([[180.0, 0.0, 1.0], [179.0, 1.0, 1.0], [179.0, 0.0, 1.0]])
        );
    }

    #[test]
    fn wide_triangles_are_cut_where_they_are_not_the_short_way() {
        // 10 -> 300 degrees east in a 0..360 frame: through 180, not through 0.
        let t = [[10.0, 0.0, 0.0], [300.0, 0.0, 0.0], [150.0, 40.0, 0.0]];
        let TriangleParts::Cut(west, east) = triangle_parts(t) else {
            panic!("not cut");
        };
        assert!(west.contains(&[10.0, 0.0, 0.0]) && west.contains(&[150.0, 40.0, 0.0]));
        assert!(east.contains(&[-60.0, 0.0, 0.0]), "{east:?}");
        // -170 -> 100 in a -180..180 frame never crosses 180: whole, unchanged.
        let t = [[-170.0, 0.0, 0.0], [100.0, 0.0, 0.0], [0.0, 40.0, 0.0]];
        assert_eq!(triangle_parts(t), TriangleParts::Whole(t));
        let line = cut_at_antimeridian(&[[-170.0, 0.0], [100.0, 0.0]]);
        assert_eq!(line, vec![vec![[-170.0, 0.0], [100.0, 0.0]]]);
    }

    #[test]
    fn a_corner_on_180_between_the_others_is_kept_in_both_parts() {
        let t = [[179.0, 0.0, 0.0], [181.0, 0.0, 0.0], [180.0, 2.0, 0.0]];
        let TriangleParts::Cut(west, east) = triangle_parts(t) else {
            panic!("not cut");
        };
        assert!(west.contains(&[180.0, 2.0, 0.0]) && east.contains(&[-180.0, 2.0, 0.0]));
        let back = triangle_from_parts(&[&east, &west]).expect("a triangle");
        for corner in [[179.0, 0.0, 0.0], [-179.0, 0.0, 0.0]] {
            assert!(back.contains(&corner), "{back:?}");
        }
        // The corner on the meridian, as written in either part.
        assert!(
            back.iter().any(|p| p[0].abs() == 180.0 && p[1] == 2.0),
            "{back:?}"
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
