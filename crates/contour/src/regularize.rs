//! Removing the zero-width parts of the lines: segments walked once in each direction.
//!
//! Under the perturbation rule (a height at the level counts as above it), a ridge of
//! edges exactly at the level between lower ground is a region of no width at or above
//! the level, and the lines around it run along it twice, once each way. Within one line,
//! back and forth in a row (`A, B, A`), [`crate::join`] already drops the excursion; what
//! is left are the same ridges met by two different lines (a ring and a line on either
//! side of it), by a line at two distant places (a ridge joining two blobs), or reaching
//! the domain's boundary (two lines ending at the same boundary point, each along the
//! ridge). Those segments would be written twice.
//!
//! [`without_zero_width_parts`] cancels every pair of opposite segments of a level and
//! reconnects what is left where the cancelled pair was (each side's line before the pair
//! continues with the other side's line after it). The result is the boundary of the
//! region at or above the level without its parts of no width: every segment once, lines
//! and rings as before elsewhere.

use crate::Polyline;

const NONE: u32 = u32::MAX;

/// One segment of a line at the level being regularized, with its neighbours along the
/// line (`NONE` at an open line's ends).
#[derive(Debug, Clone, Copy)]
struct Segment {
    from: [f64; 2],
    to: [f64; 2],
    from_edge: [u32; 2],
    to_edge: [u32; 2],
    pred: u32,
    succ: u32,
    alive: bool,
}

/// `lines` (of any levels, in any order) with every pair of opposite segments at one
/// level removed and the lines reconnected around them; lines with no such segment are
/// kept as they are. A ring rebuilt after a removal starts at its smallest edge; a rebuilt
/// open line starts where the high ground is on its left, like every line. Lines left with
/// no segment (an open line) or fewer than three distinct points (a ring) go.
///
/// The result depends only on the lines and their order within each level.
pub(crate) fn without_zero_width_parts(mut lines: Vec<Polyline>) -> Vec<Polyline> {
    // Lines are moved, never copied: a tiled run holds all of them.
    lines.sort_by(|a, b| a.level.total_cmp(&b.level));
    let mut out = Vec::with_capacity(lines.len());
    let mut level_lines = Vec::new();
    let mut lines = lines.into_iter().peekable();
    while let Some(line) = lines.next() {
        let level = line.level;
        level_lines.push(line);
        while let Some(next) = lines.next_if(|l| l.level.total_cmp(&level).is_eq()) {
            level_lines.push(next);
        }
        regularize_level(&mut level_lines, &mut out);
    }
    out
}

/// [`without_zero_width_parts`] on the lines of one level, moved to `out`.
fn regularize_level(lines: &mut Vec<Polyline>, out: &mut Vec<Polyline>) {
    // Every segment, keyed by its two ends (the lower first) and direction.
    let mut keys: Vec<([u64; 4], bool, u32)> = Vec::new();
    let mut first_segment = Vec::with_capacity(lines.len() + 1);
    for line in lines.iter() {
        first_segment.push(keys.len() as u32);
        for w in line.points.windows(2) {
            let (a, b) = (bits(w[0]), bits(w[1]));
            let forward = a <= b;
            let (lo, hi) = if forward { (a, b) } else { (b, a) };
            keys.push(([lo[0], lo[1], hi[0], hi[1]], forward, keys.len() as u32));
        }
    }
    first_segment.push(keys.len() as u32);
    keys.sort_unstable();
    // Opposite pairs: within a run of equal ends, forward ones (in segment order) paired
    // with backward ones.
    let mut pairs = Vec::new();
    let mut i = 0;
    while i < keys.len() {
        let mut j = i + 1;
        while j < keys.len() && keys[j].0 == keys[i].0 {
            j += 1;
        }
        if j - i >= 2 {
            let backward: Vec<u32> = keys[i..j].iter().filter(|k| !k.1).map(|k| k.2).collect();
            let forward: Vec<u32> = keys[i..j].iter().filter(|k| k.1).map(|k| k.2).collect();
            pairs.extend(forward.into_iter().zip(backward));
        }
        i = j;
    }
    if pairs.is_empty() {
        out.append(lines);
        return;
    }
    drop(keys);
    let line_of = |s: u32| first_segment.partition_point(|&f| f <= s) as u32 - 1;
    let mut touched = vec![false; lines.len()];
    for &(s, t) in &pairs {
        touched[line_of(s) as usize] = true;
        touched[line_of(t) as usize] = true;
    }
    // The touched lines' segments, linked along their lines.
    let mut segments: Vec<Segment> = Vec::new();
    let mut local = vec![NONE; first_segment[lines.len()] as usize];
    let level = lines[0].level;
    for (l, line) in lines.drain(..).enumerate() {
        if !touched[l] {
            out.push(line);
            continue;
        }
        let base = segments.len() as u32;
        let n = line.points.len() - 1;
        for k in 0..n {
            local[first_segment[l] as usize + k] = base + k as u32;
            let pred = if k > 0 {
                base + k as u32 - 1
            } else if line.closed {
                base + n as u32 - 1
            } else {
                NONE
            };
            let succ = if k + 1 < n {
                base + k as u32 + 1
            } else if line.closed {
                base
            } else {
                NONE
            };
            segments.push(Segment {
                from: line.points[k],
                to: line.points[k + 1],
                from_edge: line.edges[k],
                to_edge: line.edges[k + 1],
                pred,
                succ,
                alive: true,
            });
        }
    }
    for &(s, t) in &pairs {
        cancel(&mut segments, local[s as usize], local[t as usize]);
    }
    rebuild(level, &mut segments, out);
}

/// Removes the opposite segments `s` and `t` and reconnects their lines: the line before
/// `s` continues with the one after `t` (where `s` started and `t` ended), and the line
/// before `t` with the one after `s`.
fn cancel(segments: &mut [Segment], s: u32, t: u32) {
    let (ss, ts) = (segments[s as usize], segments[t as usize]);
    if ss.succ == t && ts.succ == s {
        // A ring of the two: nothing is left.
    } else if ss.succ == t {
        // `s` then `t` (out and back): before `s` meets after `t`.
        join_at(segments, ss.pred, ts.succ, ts.to_edge, ss.from_edge);
    } else if ts.succ == s {
        join_at(segments, ts.pred, ss.succ, ss.to_edge, ts.from_edge);
    } else {
        join_at(segments, ss.pred, ts.succ, ts.to_edge, ss.from_edge);
        join_at(segments, ts.pred, ss.succ, ss.to_edge, ts.from_edge);
    }
    segments[s as usize].alive = false;
    segments[t as usize].alive = false;
}

/// Makes `y` follow `x` at a point where both lines met. Either may be `NONE`: the other
/// then ends (or starts) there, on the edge the removed segment's line ended (`end_edge`)
/// or started (`start_edge`) on, so open lines keep ending on boundary edges.
fn join_at(segments: &mut [Segment], x: u32, y: u32, end_edge: [u32; 2], start_edge: [u32; 2]) {
    if x != NONE {
        segments[x as usize].succ = y;
        if y == NONE {
            segments[x as usize].to_edge = end_edge;
        }
    }
    if y != NONE {
        segments[y as usize].pred = x;
        if x == NONE {
            segments[y as usize].from_edge = start_edge;
        }
    }
}

/// The lines the live segments form: open ones from each segment with no predecessor (in
/// segment order), then rings.
fn rebuild(level: f64, segments: &mut [Segment], out: &mut Vec<Polyline>) {
    let mut visited = vec![false; segments.len()];
    for open in [true, false] {
        for s in 0..segments.len() {
            let seg = segments[s];
            if !seg.alive || visited[s] || (open && seg.pred != NONE) {
                continue;
            }
            let mut points = Vec::new();
            let mut edges = Vec::new();
            let mut cur = s as u32;
            let closed = loop {
                visited[cur as usize] = true;
                let seg = segments[cur as usize];
                points.push(seg.from);
                edges.push(seg.from_edge);
                if seg.succ == NONE {
                    points.push(seg.to);
                    edges.push(seg.to_edge);
                    break false;
                }
                if seg.succ == s as u32 {
                    break true;
                }
                cur = seg.succ;
            };
            debug_assert!(closed != open, "line kinds found in their pass");
            if closed {
                let m = (0..edges.len()).min_by_key(|&i| edges[i]).unwrap_or(0);
                points.rotate_left(m);
                edges.rotate_left(m);
                if points.len() < 3 {
                    continue;
                }
                points.push(points[0]);
                edges.push(edges[0]);
            }
            out.push(Polyline {
                level,
                points,
                edges,
                closed,
            });
        }
    }
}

fn bits(p: [f64; 2]) -> [u64; 2] {
    // +0.0 and -0.0 are one point.
    [(p[0] + 0.0).to_bits(), (p[1] + 0.0).to_bits()]
}
