//! The 1-D simplification of a shared tile edge, decided once from the edge's own data so
//! that both neighbouring tiles keep the same edge vertices.

use tinsmith_core::effective_limit;

/// Relative margin kept below the core's limit by [`edge_limit`]: the core measures a
/// skipped edge sample's error through a plane, rounded differently from the straight-line
/// interpolation used here; 2^-40 of the data's magnitude is far above either rounding.
const EDGE_MARGIN: f64 = 1.0 / (1u64 << 40) as f64;

/// The largest 1-D error [`EdgeProfile::simplify`] may accept so that the core's
/// [`tinsmith_core::decimate_with_border`] accepts the same removals: the core's
/// [`effective_limit`] less a further `2^-40 (max_error + max_abs_value)`, or 0.
///
/// `max_abs_value` must be the one every tile's
/// [`tinsmith_core::DecimationOptions::max_abs_value`] is set to (the raster's largest
/// |value|). An infinite `max_error` (a variable carried, never constraining) gives an
/// infinite limit.
pub fn edge_limit(max_error: f64, max_abs_value: f64) -> f64 {
    if max_error == f64::INFINITY {
        return f64::INFINITY;
    }
    let limit =
        effective_limit(max_error, max_abs_value) - EDGE_MARGIN * (max_error + max_abs_value);
    if limit > 0.0 {
        limit
    } else {
        0.0
    }
}

/// The longest skip, in samples, between kept edge samples that keeps every new edge of
/// the tile's border strip within `max_edge_length` sample spacings
/// ([`tinsmith_core::DecimationOptions::max_edge_length`]): the fans that replace skipped
/// border samples reach one row inwards, so a skip of `s` makes edges of length
/// `sqrt(s^2 + 1)`. The result is `floor(sqrt(L^2 - 1))` (at least 1), or `usize::MAX`
/// without a cap.
pub fn edge_span(max_edge_length: Option<u32>) -> usize {
    match max_edge_length {
        None => usize::MAX,
        Some(l) => (u64::from(l) * u64::from(l))
            .saturating_sub(1)
            .isqrt()
            .max(1) as usize,
    }
}

/// One tile edge as both tiles beside it see it: its samples in order of increasing raster
/// coordinate, and for each step between consecutive samples whether it is *open*: every
/// cell beside the step (one on each side, or one on the raster's outer border) has four
/// valid corners.
///
/// The two tiles that share the edge build the same profile from the same samples (each
/// reads a one-sample halo around its window to see the other side's cells), so
/// [`EdgeProfile::simplify`] gives them the same kept samples without any exchange.
///
/// A profile may carry the same samples of further variables
/// ([`EdgeProfile::with_variables`]): [`EdgeProfile::simplify_joint`] then skips a sample
/// only when every variable allows it, so the edge's kept samples are decided once for all
/// of them.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeProfile {
    values: Vec<f64>,
    open: Vec<bool>,
    variables: Vec<Vec<f64>>,
}

impl EdgeProfile {
    /// A profile of `values` (NaN = nodata) and `open[k]` for the step from sample `k` to
    /// `k + 1`. A step next to a non-finite sample is never open, whatever `open` says.
    ///
    /// # Panics
    /// When `values` has fewer than 2 samples or `open.len() != values.len() - 1`: tile
    /// edges always join two tile corners.
    pub fn new(values: Vec<f64>, mut open: Vec<bool>) -> EdgeProfile {
        assert!(
            values.len() >= 2 && open.len() + 1 == values.len(),
            "an edge of {} samples with {} steps",
            values.len(),
            open.len()
        );
        for (k, o) in open.iter_mut().enumerate() {
            *o = *o && values[k].is_finite() && values[k + 1].is_finite();
        }
        EdgeProfile {
            values,
            open,
            variables: Vec::new(),
        }
    }

    /// The profile with `variables`' samples along the same edge (each as many as the
    /// heights). Steps are open or not as the heights say: the caller makes a height
    /// nodata wherever a variable is.
    ///
    /// # Panics
    /// When a variable has another number of samples than the heights.
    pub fn with_variables(mut self, variables: Vec<Vec<f64>>) -> EdgeProfile {
        assert!(
            variables.iter().all(|v| v.len() == self.values.len()),
            "an edge's variables have as many samples as its heights"
        );
        self.variables = variables;
        self
    }

    /// The variables' samples, in the order given to [`EdgeProfile::with_variables`].
    pub fn variables(&self) -> &[Vec<f64>] {
        &self.variables
    }

    /// The samples, in increasing raster coordinate.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Whether each step (sample `k` to `k + 1`) is open.
    pub fn open(&self) -> &[bool] {
        &self.open
    }

    /// Which samples the edge keeps at 1-D error `limit` (see [`edge_limit`]), skipping at
    /// most `max_span - 1` samples at a time (`usize::MAX`: no cap; the core removes
    /// skipped samples as fans, in time linear in the run).
    ///
    /// Kept: both ends (the tile corners); both samples of every step that is not open
    /// (so the domain's outline along the edge is kept exactly, on both sides); and, along
    /// each run of open steps, greedily from its start in increasing coordinate, the
    /// farthest sample, at most `max_span` steps on, such that the straight line from the
    /// last kept sample to it is within `limit` of every sample it skips. With `limit` 0
    /// only exactly collinear samples are skipped.
    ///
    /// # Guarantee
    /// For consecutive kept samples `a < b`: `b - a <= max_span.max(1)`, and if
    /// `b > a + 1` every step between them is open and every sample `m` between them has `|v[m] - (v[a] + (m - a) / (b - a) (v[b] - v[a]))| <=
    /// limit`.
    ///
    /// # Determinism
    /// The result depends only on the profile and `limit`.
    ///
    /// # Runtime
    /// O(n) for n samples (O(n * min(n, max_span)) in the worst case, only where rounding
    /// puts a sample at exactly `limit` from a line; see `chord_reach`).
    pub fn simplify(&self, limit: f64, max_span: usize) -> Vec<bool> {
        self.simplify_with(max_span, |v, a, end| chord_reach(v, a, end, limit))
    }

    /// Which samples the edge keeps when only samples exactly on the straight line between
    /// kept ones may be skipped, decided in integer arithmetic: [`EdgeProfile::simplify`]
    /// at `limit` 0, exact. For edges of integer values below 2^50 in magnitude (the core
    /// then measures an error of 0 exactly too; see `tinsmith_core::Grid::integral_heights`).
    pub fn simplify_collinear(&self, max_span: usize) -> Vec<bool> {
        self.simplify_with(max_span, collinear_reach)
    }

    /// Which samples the edge keeps when the heights follow `height` and every variable
    /// `k` (see [`EdgeProfile::with_variables`]) must stay within `variable_limits[k]`
    /// (its [`edge_limit`]; 0 keeps every sample as far as that variable is concerned):
    /// from each kept sample the next is the farthest that every variable and the height
    /// reach, so a sample is skipped only when dropping it keeps all of them within their
    /// limits along the edge. Without variables, the same as [`EdgeProfile::simplify`],
    /// [`EdgeProfile::simplify_collinear`] or keeping every sample.
    ///
    /// # Guarantee
    /// As [`EdgeProfile::simplify`], for the heights at `height`'s rule and for each
    /// variable at its limit.
    ///
    /// # Panics
    /// When `variable_limits` does not have one limit per variable.
    pub fn simplify_joint(
        &self,
        height: EdgeRule,
        variable_limits: &[f64],
        max_span: usize,
    ) -> Vec<bool> {
        assert_eq!(
            variable_limits.len(),
            self.variables.len(),
            "one limit per variable"
        );
        self.simplify_with(max_span, |v, a, end| {
            let mut b = match height {
                EdgeRule::Limit(limit) => chord_reach(v, a, end, limit),
                EdgeRule::Collinear => collinear_reach(v, a, end),
                EdgeRule::KeepAll => a + 1,
            };
            // Each reach is a prefix of `a + 1..=end`: the joint one is the shortest.
            for (values, &limit) in self.variables.iter().zip(variable_limits) {
                if b == a + 1 {
                    break;
                }
                b = if limit > 0.0 {
                    chord_reach(values, a, b, limit)
                } else {
                    a + 1
                };
            }
            b
        })
    }

    /// The kept samples, given `reach(values, a, end)`: the sample in `a + 1..=end` that
    /// the kept sample `a` is joined to, all samples between them skipped.
    fn simplify_with(
        &self,
        max_span: usize,
        reach: impl Fn(&[f64], usize, usize) -> usize,
    ) -> Vec<bool> {
        let v = &self.values;
        let n = v.len();
        let mut keep = vec![false; n];
        keep[0] = true;
        keep[n - 1] = true;
        for (k, &open) in self.open.iter().enumerate() {
            if !open {
                keep[k] = true;
                keep[k + 1] = true;
            }
        }
        // For each sample, the first sample after it that must be kept.
        let mut next_kept = vec![n - 1; n];
        for i in (0..n - 1).rev() {
            next_kept[i] = if keep[i + 1] { i + 1 } else { next_kept[i + 1] };
        }
        let mut a = 0;
        while a < n - 1 {
            let end = next_kept[a].min(a.saturating_add(max_span.max(1)));
            let b = reach(v, a, end);
            debug_assert!(a < b && b <= end);
            keep[b] = true;
            a = b;
        }
        keep
    }
}

/// How [`EdgeProfile::simplify_joint`] treats the heights.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EdgeRule {
    /// Within this 1-D limit, as [`EdgeProfile::simplify`].
    Limit(f64),
    /// Only exactly collinear samples skipped, as [`EdgeProfile::simplify_collinear`].
    Collinear,
    /// Every sample kept.
    KeepAll,
}

/// The farthest `b` in `a + 1..=end` such that for every `c` in `a + 2..=b` the straight
/// line from `a` to `c` is within `limit` of every sample between them, found in time
/// linear in `b - a`.
///
/// The line from `a` to `c` passes within `limit` of sample `m` when its slope lies in
/// `[(v[m] - v[a] - limit) / (m - a), (v[m] - v[a] + limit) / (m - a)]`; the samples up
/// to `c - 1` narrow that interval step by step. Rounding can make that test disagree with
/// the direct one at the interval's ends, so the line to the `b` found is then checked
/// directly; should it fail, each `c` is checked directly from `a` instead (quadratic, and
/// only then).
fn chord_reach(v: &[f64], a: usize, end: usize, limit: f64) -> usize {
    let za = v[a];
    let (mut low, mut high) = (f64::NEG_INFINITY, f64::INFINITY);
    let mut b = a + 1;
    while b < end {
        let c = b + 1;
        let k = (b - a) as f64;
        low = low.max((v[b] - za - limit) / k);
        high = high.min((v[b] - za + limit) / k);
        let slope = (v[c] - za) / (c - a) as f64;
        if !(low <= slope && slope <= high) {
            break;
        }
        b = c;
    }
    if b == a + 1 || chord_fits(v, a, b, limit) {
        return b;
    }
    let mut b = a + 1;
    while b < end && chord_fits(v, a, b + 1, limit) {
        b += 1;
    }
    b
}

/// The farthest `b` in `a + 1..=end` such that every sample from `a` to `b` lies exactly on
/// one straight line, for integer values: `v[m] - v[a] == (m - a) (v[a + 1] - v[a])` in
/// `i128` (two samples always do).
fn collinear_reach(v: &[f64], a: usize, end: usize) -> usize {
    let int = |x: f64| x as i128;
    let rise = int(v[a + 1]) - int(v[a]);
    let mut b = a + 1;
    while b < end && int(v[b + 1]) - int(v[a]) == (b + 1 - a) as i128 * rise {
        b += 1;
    }
    b
}

/// Whether the straight line from sample `a` to sample `c` is within `limit` of every
/// sample between them.
fn chord_fits(v: &[f64], a: usize, c: usize, limit: f64) -> bool {
    let (za, zc) = (v[a], v[c]);
    let span = (c - a) as f64;
    (a + 1..c).all(|m| {
        let t = (m - a) as f64 / span;
        (v[m] - (za + t * (zc - za))).abs() <= limit
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn kept(values: &[f64], open: &[bool], limit: f64) -> Vec<usize> {
        EdgeProfile::new(values.to_vec(), open.to_vec())
            .simplify(limit, usize::MAX)
            .iter()
            .enumerate()
            .filter_map(|(i, &k)| k.then_some(i))
            .collect()
    }

    #[test]
    fn a_straight_edge_keeps_its_ends() {
        let values: Vec<f64> = (0..50).map(|i| 3.0 + 0.37 * i as f64).collect();
        assert_eq!(kept(&values, &[true; 49], 1e-9), vec![0, 49]);
        assert_eq!(kept(&[7.0; 9], &[true; 8], 0.0), vec![0, 8]);
    }

    #[test]
    fn runs_are_capped_at_the_span() {
        let values = [5.0; 10];
        assert_eq!(kept(&values, &[true; 9], 0.0), vec![0, 9]);
        let edge = EdgeProfile::new(values.to_vec(), vec![true; 9]);
        let keep = edge.simplify(1.0, 4);
        let kept: Vec<usize> = (0..10).filter(|&i| keep[i]).collect();
        assert_eq!(kept, vec![0, 4, 8, 9]);
    }

    #[test]
    fn spans_leave_room_for_the_strip_fans() {
        assert_eq!(edge_span(None), usize::MAX);
        assert_eq!(edge_span(Some(2)), 1);
        assert_eq!(edge_span(Some(10)), 9);
        for l in 2u32..200 {
            let s = edge_span(Some(l)) as u64;
            assert!(s * s < u64::from(l * l));
            assert!(s == 1 || (s + 1) * (s + 1) + 1 > u64::from(l * l));
        }
    }

    #[test]
    fn two_samples_are_both_kept() {
        assert_eq!(kept(&[1.0, 9.0], &[true], 100.0), vec![0, 1]);
    }

    #[test]
    fn a_peak_is_kept_when_it_exceeds_the_limit() {
        let values = [0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0];
        assert_eq!(kept(&values, &[true; 6], 1.0), vec![0, 2, 3, 4, 6]);
        assert_eq!(kept(&values, &[true; 6], 5.0), vec![0, 6]);
    }

    #[test]
    fn closed_steps_keep_both_samples() {
        let values = [0.0; 8];
        let open = [true, true, false, true, true, true, true];
        assert_eq!(kept(&values, &open, 1.0), vec![0, 2, 3, 7]);
        // A nodata sample closes both of its steps.
        let values = [0.0, 0.0, 0.0, f64::NAN, 0.0, 0.0, 0.0];
        assert_eq!(kept(&values, &[true; 6], 1.0), vec![0, 2, 3, 4, 6]);
    }

    #[test]
    fn greedy_runs_forward_from_the_low_end() {
        // From 0 the chord reaches 2 (error 1 at sample 1) but not 3 (error 2 at sample
        // 2); from 2 it cannot reach 4 (error 1.5 at 3).
        let values = [0.0, 1.0, 0.0, 3.0, 3.0];
        assert_eq!(kept(&values, &[true; 4], 1.0), vec![0, 2, 3, 4]);
        // The same samples reversed are simplified from their own low end.
        let values = [3.0, 3.0, 0.0, 1.0, 0.0];
        assert_eq!(kept(&values, &[true; 4], 1.0), vec![0, 1, 2, 4]);
    }

    #[test]
    fn edge_limit_stays_below_the_core_limit() {
        for (e, m) in [(1.0, 0.0), (1.0, 8848.0), (0.01, 1e6), (30.0, 32767.0)] {
            let limit = edge_limit(e, m);
            assert!(limit > 0.0 && limit < effective_limit(e, m), "{e} {m}");
            assert!(e - limit < 1e-9 * (e + m));
        }
        assert_eq!(edge_limit(0.0, 100.0), 0.0);
        assert_eq!(edge_limit(1e-20, 100.0), 0.0);
    }

    #[test]
    fn every_variable_decides_the_kept_samples() {
        let flat = vec![0.0; 7];
        let bump = vec![0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0];
        let edge = EdgeProfile::new(flat.clone(), vec![true; 6]);
        let alone = edge.simplify(1.0, usize::MAX);
        assert_eq!(
            edge.simplify_joint(EdgeRule::Limit(1.0), &[], usize::MAX),
            alone
        );
        let kept = |limits: &[f64]| -> Vec<usize> {
            let edge = EdgeProfile::new(flat.clone(), vec![true; 6])
                .with_variables(vec![flat.clone(), bump.clone()]);
            let keep = edge.simplify_joint(EdgeRule::Limit(1.0), limits, usize::MAX);
            (0..7).filter(|&i| keep[i]).collect()
        };
        // The bump in the second variable is kept at its tight bound only.
        assert_eq!(kept(&[1.0, 1.0]), vec![0, 2, 3, 4, 6]);
        assert_eq!(kept(&[1.0, 5.0]), vec![0, 6]);
        assert_eq!(kept(&[1.0, f64::INFINITY]), vec![0, 6]);
        // A limit of 0 keeps every sample.
        assert_eq!(kept(&[0.0, 5.0]), (0..7).collect::<Vec<_>>());
        assert_eq!(edge_limit(f64::INFINITY, 10.0), f64::INFINITY);
    }

    #[test]
    #[should_panic(expected = "an edge of 1 samples")]
    fn a_single_sample_is_not_an_edge() {
        EdgeProfile::new(vec![1.0], vec![]);
    }

    fn profile() -> impl Strategy<Value = (Vec<f64>, Vec<bool>)> {
        (2usize..60).prop_flat_map(|n| {
            (
                prop::collection::vec(
                    prop_oneof![
                        8 => (-50i32..50).prop_map(|v| v as f64 * 0.25),
                        1 => Just(f64::NAN),
                    ],
                    n,
                ),
                prop::collection::vec(prop::bool::weighted(0.9), n - 1),
            )
        })
    }

    proptest! {
        #[test]
        fn the_kept_polyline_is_within_the_limit(
            (values, open) in profile(),
            limit in prop_oneof![Just(0.0), 0.0f64..6.0],
            max_span in prop_oneof![Just(usize::MAX), 1usize..8],
        ) {
            let edge = EdgeProfile::new(values.clone(), open.clone());
            let keep = edge.simplify(limit, max_span);
            let n = values.len();
            prop_assert!(keep[0] && keep[n - 1]);
            let kept: Vec<usize> = (0..n).filter(|&i| keep[i]).collect();
            for pair in kept.windows(2) {
                let (a, b) = (pair[0], pair[1]);
                prop_assert!(b - a <= max_span.max(1), "span {a}..{b}");
                for m in (a..b).filter(|_| b > a + 1) {
                    prop_assert!(open[m] && values[m].is_finite() && values[m + 1].is_finite(),
                        "skipped over a closed step {m}");
                }
                for m in a + 1..b {
                    let t = (m - a) as f64 / (b - a) as f64;
                    let line = values[a] + t * (values[b] - values[a]);
                    prop_assert!((values[m] - line).abs() <= limit,
                        "sample {m}: {} vs line {line}", values[m]);
                }
            }
            // Deterministic: the same profile gives the same answer.
            prop_assert_eq!(keep, EdgeProfile::new(values, open).simplify(limit, max_span));
        }

        #[test]
        fn every_variable_is_within_its_limit_along_the_joint_edge(
            (values, open) in profile(),
            seeds in prop::collection::vec((1u32..7, -4i32..4), 1..4),
            height_limit in 0.0f64..6.0,
            max_span in prop_oneof![Just(usize::MAX), 1usize..8],
        ) {
            let n = values.len();
            // Variables: other integer patterns over the same samples, each with a limit.
            let variables: Vec<Vec<f64>> = (seeds.iter())
                .map(|&(p, s)| (0..n).map(|i| f64::from((i as i32 * s).rem_euclid(p as i32 + 1)) * 0.5).collect())
                .collect();
            let limits: Vec<f64> = seeds.iter().map(|&(p, _)| f64::from(p) * 0.2 - 0.2).collect();
            let edge = EdgeProfile::new(values.clone(), open.clone()).with_variables(variables.clone());
            let keep = edge.simplify_joint(EdgeRule::Limit(height_limit), &limits, max_span);
            prop_assert!(keep[0] && keep[n - 1]);
            let kept: Vec<usize> = (0..n).filter(|&i| keep[i]).collect();
            for pair in kept.windows(2) {
                let (a, b) = (pair[0], pair[1]);
                prop_assert!(b - a <= max_span.max(1));
                let series = std::iter::once((&values, height_limit)).chain(variables.iter().zip(limits.iter().copied()));
                for (v, limit) in series {
                    for m in a + 1..b {
                        let t = (m - a) as f64 / (b - a) as f64;
                        let line = v[a] + t * (v[b] - v[a]);
                        prop_assert!(limit > 0.0 || v.as_ptr() == values.as_ptr(), "a zero limit skipped {m}");
                        prop_assert!((v[m] - line).abs() <= limit, "sample {m}: {} vs line {line}", v[m]);
                    }
                }
            }
        }
    }
}
