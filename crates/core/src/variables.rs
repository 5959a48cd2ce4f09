//! Several variables over one mesh (paper §6, "Decimation of non-scalar data"): extra
//! scalar fields on the height's grid, each with its own bound, all honoured by every
//! triangle the exact model accepts.
//!
//! The decimator works in the height's units: its limit, the dynamic program's tightening
//! cap and the order's keys are heights. A variable `k` with enforced limit `L_k` is
//! measured on its own samples and then scaled into height units by `L_0 / L_k`, so a
//! triangle's bound is the largest of its height error and its variables' scaled errors,
//! and "within the limit" means every variable within its own. The scale only orders and
//! caps; acceptance compares each variable's unscaled error with `L_k` itself, so its
//! rounding cannot let a variable pass beyond its bound.

use tinsmith_georef::Samples;

use crate::exact::{corner_samples, error_at, height_error};
use crate::predicates::Point;
use crate::{effective_limit, Error, ErrorBound, Grid, Result, MAX_ABS_HEIGHT};

/// One extra variable: samples on the height's grid and the bound its TIN values must keep
/// at every domain sample (`f64::INFINITY` for a variable carried but not constrained).
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    samples: Samples,
    max_error: f64,
}

impl Variable {
    /// A variable of `samples` (NaN = nodata) within `max_error` of its TIN values; fails
    /// with [`Error::InvalidMaxError`] when the bound is negative or NaN (infinity is
    /// accepted: the variable is carried but never stops a removal).
    pub fn new(samples: Samples, max_error: f64) -> Result<Variable> {
        if max_error.is_nan() || max_error < 0.0 {
            return Err(Error::InvalidMaxError(max_error));
        }
        Ok(Variable { samples, max_error })
    }

    /// The bound asked for.
    pub fn max_error(&self) -> f64 {
        self.max_error
    }

    /// The samples, row-major.
    pub fn values(&self) -> &[f64] {
        self.samples.values()
    }
}

/// A variable as the decimator measures it: its own grid (with its own equal-run and
/// flat-block caches, never raised heights), its bound, and once a run has fixed the
/// height's limit, its own enforced limit and scale.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Measured {
    pub(crate) grid: Grid,
    pub(crate) max_error: f64,
    /// `L_k`: [`effective_limit`] of the bound on this variable's values.
    limit: f64,
    /// `L_0 / L_k` (0 when `L_0` is 0; infinite when only `L_k` is 0).
    scale: f64,
    /// `L_0`: a scaled error within `L_k` is at most this, whatever its rounding.
    height_limit: f64,
}

impl Measured {
    pub(crate) fn new(variable: Variable) -> Measured {
        let grid = Grid::from_samples(variable.samples);
        let limit = effective_limit(variable.max_error, grid.max_abs_value());
        Measured {
            grid,
            max_error: variable.max_error,
            limit,
            scale: 0.0,
            height_limit: 0.0,
        }
    }

    /// The variable for a run whose height limit is `height_limit`.
    pub(crate) fn for_limit(&self, height_limit: f64) -> Measured {
        let scale = if self.limit > 0.0 {
            height_limit / self.limit
        } else if height_limit > 0.0 {
            f64::INFINITY
        } else {
            0.0
        };
        Measured {
            scale,
            height_limit,
            ..self.clone()
        }
    }

    /// The factor that takes the variable's differences into height units when bounds are
    /// propagated (the bounds model): the scale, or infinity when the height's limit is 0
    /// (any change of the variable then refuses, which is stricter than its own limit but
    /// never looser); `None` for a variable that never stops a removal.
    pub(crate) fn propagation_scale(&self) -> Option<f64> {
        if self.unconstrained() {
            None
        } else if self.scale > 0.0 {
            Some(self.scale)
        } else {
            Some(f64::INFINITY)
        }
    }

    /// The largest difference of the variable from a triangle's plane that a triangle
    /// within height limit `limit` may have (unscaled): its own limit, or less where its
    /// scaled error would pass `limit`. A scan may stop as soon as a difference exceeds
    /// it, the verdict then sure to be a refusal.
    pub(crate) fn cap(&self, limit: f64) -> f64 {
        if limit.is_finite() && self.scale > 0.0 {
            self.limit.min(limit / self.scale)
        } else {
            self.limit
        }
    }

    /// `L_k`, the limit the variable's own errors are held to.
    pub(crate) fn own_limit(&self) -> f64 {
        self.limit
    }

    /// A difference `x` within the variable's own limit, in height units: scaled, and
    /// clamped to the height's limit, so the scale's rounding refuses nothing the
    /// variable allows.
    fn scaled(&self, x: f64) -> f64 {
        if x == 0.0 {
            0.0
        } else {
            (x * self.scale).min(self.height_limit)
        }
    }

    /// Whether the variable, held at 0 below its rounding slack, cannot be measured over
    /// the plane through `corners` (its values there): only an exactly flat plane is
    /// measured exactly (its differences are all zero), as the height's stars are at 0.
    fn unmeasurable(&self, corners: &[Point; 3]) -> bool {
        let flat = corners[0].z == corners[1].z && corners[1].z == corners[2].z;
        self.limit == 0.0 && !self.grid.integral_heights() && !flat
    }

    /// Whether the variable never stops a removal.
    pub(crate) fn unconstrained(&self) -> bool {
        self.limit == f64::INFINITY
    }
}

/// Checks `variables` against the height samples and makes the height nodata wherever a
/// variable is: the domain is where every variable is valid.
///
/// # Errors
/// [`Error::VariableSize`] when a variable's grid is not the height's size;
/// [`Error::HeightsTooLarge`] when a variable's |value| exceeds [`MAX_ABS_HEIGHT`].
pub(crate) fn joined(
    height: Samples,
    variables: Vec<Variable>,
) -> Result<(Samples, Vec<Measured>)> {
    let (width, rows) = (height.width(), height.height());
    for (index, v) in variables.iter().enumerate() {
        if (v.samples.width(), v.samples.height()) != (width, rows) {
            return Err(Error::VariableSize {
                index,
                width: v.samples.width(),
                height: v.samples.height(),
                expected_width: width,
                expected_height: rows,
            });
        }
    }
    let mut values = height.values().to_vec();
    for v in &variables {
        for (h, x) in values.iter_mut().zip(v.samples.values()) {
            if !x.is_finite() {
                *h = f64::NAN;
            }
        }
    }
    let height = Samples::new(width, rows, values)?;
    let measured: Vec<Measured> = variables.into_iter().map(Measured::new).collect();
    if let Some(m) = measured
        .iter()
        .map(|m| m.grid.max_abs_value())
        .find(|&m| m > MAX_ABS_HEIGHT)
    {
        return Err(Error::HeightsTooLarge(m));
    }
    Ok((height, measured))
}

/// The bound of counter-clockwise triangle `abc` whose height error is `height`, with every
/// variable of `grid` measured too (in height units, see the module doc), or `None` when a
/// variable exceeds its own limit or its scaled error exceeds `limit`.
///
/// With `limit` infinite (callers storing the bound of a triangle they know is within the
/// limit) a variable beyond its own limit gives an infinite bound rather than `None`.
pub(crate) fn with_variables(
    grid: &Grid,
    a: &Point,
    b: &Point,
    c: &Point,
    limit: f64,
    height: ErrorBound,
) -> Option<ErrorBound> {
    let mut bound = height;
    for v in grid.variables() {
        if v.unconstrained() {
            continue;
        }
        let corners = corner_samples(&v.grid, [a, b, c]);
        let [va, vb, vc] = &corners;
        let measured = if v.unmeasurable(&corners) {
            None
        } else {
            height_error(&v.grid, va, vb, vc, v.cap(limit))
        };
        let Some(e) = measured.filter(|e| e.above <= v.limit && e.below <= v.limit) else {
            if limit.is_finite() {
                return None;
            }
            return Some(ErrorBound {
                above: f64::INFINITY,
                below: f64::INFINITY,
            });
        };
        bound.above = bound.above.max(v.scaled(e.above));
        bound.below = bound.below.max(v.scaled(e.below));
    }
    (bound.above <= limit && bound.below <= limit).then_some(bound)
}

/// [`crate::exact::triangle_worst`] with every variable of `grid` measured too, for
/// greedy insertion: `height` is the height's bound and worst sample over counter-clockwise
/// triangle `abc`; each constrained variable's are measured on its own samples and scaled
/// into height units, and the triangle's bound and worst sample become the largest of all.
/// A variable beyond its own limit gets a scaled bound and worst error above `limit`
/// whatever the scale's rounding, so insertion splits the triangle; a variable within it
/// gets [`with_variables`]'s clamp, so a triangle insertion keeps has the bound the exact
/// model would store.
pub(crate) fn worst_with_variables(
    grid: &Grid,
    a: &Point,
    b: &Point,
    c: &Point,
    is_vertex: &[bool],
    limit: f64,
    height: (ErrorBound, Option<(usize, f64)>),
) -> (ErrorBound, Option<(usize, f64)>) {
    let (mut bound, mut worst) = height;
    let beyond = |x: f64| x.max(limit.next_up());
    for v in grid.variables() {
        if v.unconstrained() {
            continue;
        }
        let corners = corner_samples(&v.grid, [a, b, c]);
        let [va, vb, vc] = &corners;
        let (e, w) = crate::exact::triangle_worst(&v.grid, va, vb, vc, is_vertex);
        // A difference in height units: above `limit` where the variable cannot be
        // measured or is beyond its own limit (the triangle must split), else scaled.
        let unmeasurable = v.unmeasurable(&corners);
        let in_height = |x: f64| {
            if unmeasurable {
                beyond(0.0)
            } else if x > v.limit {
                beyond(x * v.scale)
            } else {
                v.scaled(x)
            }
        };
        bound.above = bound.above.max(in_height(e.above));
        bound.below = bound.below.max(in_height(e.below));
        if let Some((sample, e_worst)) = w {
            let key = in_height(e_worst);
            if worst.is_none_or(|(_, best)| key > best) {
                worst = Some((sample, key));
            }
        }
    }
    (bound, worst)
}

/// Whether some variable's value at `centre` (a sample in the closed triangle `abc`) is
/// beyond `cap` (in height units, as [`with_variables`] takes it) or its own limit from
/// the plane through its values at the corners: then the triangle's scan would refuse it
/// too (the same arithmetic on one of its samples), so it need not run. Variables held
/// exactly at 0 are left to the scan.
pub(crate) fn centre_exceeds(
    grid: &Grid,
    a: &Point,
    b: &Point,
    c: &Point,
    centre: &Point,
    cap: f64,
) -> bool {
    grid.variables().iter().any(|v| {
        if v.unconstrained() || v.limit == 0.0 {
            return false;
        }
        let cap = v.cap(cap);
        let [va, vb, vc, vm] = corner_samples(&v.grid, [a, b, c, centre]);
        error_at(&va, &vb, &vc, [&vm], cap).is_none()
    })
}

/// Whether some variable's value at `centre` lies further than its own limit outside the
/// range of its values at the `ring` vertices: every retriangulation of the hole
/// interpolates the centre from ring values, so its removal can never pass (the cheap
/// exact rejection the height gets too).
pub(crate) fn centre_outside_ring(grid: &Grid, centre: &Point, ring: &[Point]) -> bool {
    grid.variables().iter().any(|v| {
        if v.unconstrained() {
            return false;
        }
        let width = v.grid.width() as i64;
        let value = |p: &Point| v.grid.values()[(p.y * width + p.x) as usize];
        let (lo, hi) = ring
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                let z = value(p);
                (lo.min(z), hi.max(z))
            });
        let z = value(centre);
        z - hi > v.limit || lo - z > v.limit
    })
}

/// Whether some variable held at a limit of 0 (a bound below its rounding slack) changes
/// between `centre` and its `ring`: under the bounds model only exactly flat stars of such
/// a variable may go, as for the height (their propagated differences are all exactly 0).
pub(crate) fn held_variable_not_flat(grid: &Grid, centre: &Point, ring: &[Point]) -> bool {
    grid.variables().iter().any(|v| {
        if v.unconstrained() || v.limit > 0.0 {
            return false;
        }
        let width = v.grid.width() as i64;
        let value = |p: &Point| v.grid.values()[(p.y * width + p.x) as usize];
        let z = value(centre);
        ring.iter().any(|p| value(p) != z)
    })
}
