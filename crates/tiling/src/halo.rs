//! A tile read with a one-sample halo: its own samples, and the four edge profiles that
//! need the cells just outside it.

use tinsmith_core::Grid;
use tinsmith_georef::Samples;

use crate::edge::EdgeProfile;
use crate::plan::{TileIndex, TilePlan, TileWindow};

/// The rectangle to read for tile `window`: the window grown by one sample on each side
/// where the raster has one.
pub(crate) fn halo_window(plan: &TilePlan, window: TileWindow) -> TileWindow {
    let x0 = window.x0.saturating_sub(1);
    let y0 = window.y0.saturating_sub(1);
    let x1 = (window.x1() + 1).min(plan.width() - 1);
    let y1 = (window.y1() + 1).min(plan.height() - 1);
    TileWindow {
        x0,
        y0,
        width: x1 - x0 + 1,
        height: y1 - y0 + 1,
    }
}

/// What the decimation of one tile needs, cut from its halo read.
#[derive(Debug, Clone)]
pub(crate) struct TileInput {
    /// The tile's own samples (its window), NaN = nodata.
    pub(crate) grid: Grid,
    /// Edge profiles: top and bottom rows (left to right), left and right columns (top to
    /// bottom).
    pub(crate) top: EdgeProfile,
    pub(crate) bottom: EdgeProfile,
    pub(crate) left: EdgeProfile,
    pub(crate) right: EdgeProfile,
    /// Each variable's samples of the tile's window (NaN = nodata), empty without
    /// variables; the edge profiles carry theirs too.
    pub(crate) variables: Vec<Samples>,
    /// Samples the tile owns (see [`TileInput::cut`]) that are corners of a valid cell of
    /// the raster: summed over tiles, the full mesh's vertex count.
    pub(crate) owned_domain_samples: u64,
    /// Valid samples the tile owns (valid in every band): summed over tiles, the raster's.
    pub(crate) owned_valid_samples: u64,
}

impl TileInput {
    /// Cuts tile `index`'s input from `halo`, the samples of [`halo_window`].
    ///
    /// A tile *owns* its samples except those on its top row (below tile row 0) and left
    /// column (right of tile column 0), which belong to earlier tiles.
    ///
    /// `variables` are the same halo of each variable: the height is then nodata wherever
    /// a variable is (the domain is where every band is valid), and the tile's windows and
    /// edge profiles carry the variables' samples.
    pub(crate) fn cut(
        plan: &TilePlan,
        index: TileIndex,
        halo: &Samples,
        variables: &[Samples],
        halo_window: TileWindow,
    ) -> TileInput {
        let window = plan.window(index);
        let masked;
        let halo = if variables.is_empty() {
            halo
        } else {
            let mut values = halo.values().to_vec();
            for v in variables {
                for (h, x) in values.iter_mut().zip(v.values()) {
                    if !x.is_finite() {
                        *h = f64::NAN;
                    }
                }
            }
            masked = Samples::new(halo.width(), halo.height(), values)
                .expect("the same size as the halo read");
            &masked
        };
        let views: Vec<HaloView<'_>> = variables
            .iter()
            .map(|grid| HaloView {
                grid,
                window: halo_window,
                raster_width: plan.width(),
                raster_height: plan.height(),
            })
            .collect();
        let view = HaloView {
            grid: halo,
            window: halo_window,
            raster_width: plan.width(),
            raster_height: plan.height(),
        };
        let values = (window.y0..=window.y1())
            .flat_map(|y| (window.x0..=window.x1()).map(move |x| (x, y)))
            .map(|(x, y)| view.sample(x, y))
            .collect();
        let grid = Grid::new(window.width, window.height, values)
            .expect("a tile window has at least 2x2 samples and fits the halo grid");
        let owned_x0 = if index.col == 0 {
            window.x0
        } else {
            window.x0 + 1
        };
        let owned_y0 = if index.row == 0 {
            window.y0
        } else {
            window.y0 + 1
        };
        let mut owned_domain_samples = 0;
        let mut owned_valid_samples = 0;
        for y in owned_y0..=window.y1() {
            for x in owned_x0..=window.x1() {
                owned_domain_samples += u64::from(view.is_domain_sample(x, y));
                owned_valid_samples += u64::from(view.sample(x, y).is_finite());
            }
        }
        let rows = |y: u32| {
            let profile = view.row_profile(y, window.x0, window.x1());
            if views.is_empty() {
                return profile;
            }
            profile.with_variables(
                views
                    .iter()
                    .map(|v| (window.x0..=window.x1()).map(|x| v.sample(x, y)).collect())
                    .collect(),
            )
        };
        let columns = |x: u32| {
            let profile = view.column_profile(x, window.y0, window.y1());
            if views.is_empty() {
                return profile;
            }
            profile.with_variables(
                views
                    .iter()
                    .map(|v| (window.y0..=window.y1()).map(|y| v.sample(x, y)).collect())
                    .collect(),
            )
        };
        let variables = views
            .iter()
            .map(|v| {
                let values = (window.y0..=window.y1())
                    .flat_map(|y| (window.x0..=window.x1()).map(move |x| (x, y)))
                    .map(|(x, y)| v.sample(x, y))
                    .collect();
                Samples::new(window.width, window.height, values)
                    .expect("a tile window has at least 2x2 samples")
            })
            .collect();
        TileInput {
            grid,
            top: rows(window.y0),
            bottom: rows(window.y1()),
            left: columns(window.x0),
            right: columns(window.x1()),
            variables,
            owned_domain_samples,
            owned_valid_samples,
        }
    }
}

/// Raster-coordinate access to a halo read.
struct HaloView<'a> {
    grid: &'a Samples,
    window: TileWindow,
    raster_width: u32,
    raster_height: u32,
}

impl HaloView<'_> {
    /// Sample `(x, y)` of the raster, which must lie in the halo window.
    fn sample(&self, x: u32, y: u32) -> f64 {
        let (hx, hy) = (x - self.window.x0, y - self.window.y0);
        self.grid.values()[(hy * self.window.width + hx) as usize]
    }

    /// Whether the raster cell with top-left sample `(cx, cy)` exists and has four valid
    /// corners.
    fn cell_is_valid(&self, cx: i64, cy: i64) -> bool {
        if cx < 0
            || cy < 0
            || cx + 1 >= self.raster_width as i64
            || cy + 1 >= self.raster_height as i64
        {
            return false;
        }
        let (x, y) = (cx as u32, cy as u32);
        [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)]
            .iter()
            .all(|&(sx, sy)| self.sample(sx, sy).is_finite())
    }

    fn is_domain_sample(&self, x: u32, y: u32) -> bool {
        let (x, y) = (x as i64, y as i64);
        self.cell_is_valid(x - 1, y - 1)
            || self.cell_is_valid(x, y - 1)
            || self.cell_is_valid(x - 1, y)
            || self.cell_is_valid(x, y)
    }

    /// Row `y` from column `x0` to `x1`: a step is open when the cells above and below it
    /// (those the raster has) are valid.
    fn row_profile(&self, y: u32, x0: u32, x1: u32) -> EdgeProfile {
        let values = (x0..=x1).map(|x| self.sample(x, y)).collect();
        let y = y as i64;
        let open = (x0..x1)
            .map(|cx| {
                let cx = cx as i64;
                (y == 0 || self.cell_is_valid(cx, y - 1))
                    && (y + 1 >= self.raster_height as i64 || self.cell_is_valid(cx, y))
            })
            .collect();
        EdgeProfile::new(values, open)
    }

    /// Column `x` from row `y0` to `y1`: a step is open when the cells left and right of it
    /// (those the raster has) are valid.
    fn column_profile(&self, x: u32, y0: u32, y1: u32) -> EdgeProfile {
        let values = (y0..=y1).map(|y| self.sample(x, y)).collect();
        let x = x as i64;
        let open = (y0..y1)
            .map(|cy| {
                let cy = cy as i64;
                (x == 0 || self.cell_is_valid(x - 1, cy))
                    && (x + 1 >= self.raster_width as i64 || self.cell_is_valid(x, cy))
            })
            .collect();
        EdgeProfile::new(values, open)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raster(w: u32, h: u32, f: impl Fn(u32, u32) -> f64) -> Grid {
        let values = (0..h).flat_map(|y| (0..w).map(move |x| (x, y)));
        Grid::new(w, h, values.map(|(x, y)| f(x, y)).collect()).expect("grid")
    }

    fn crop(g: &Grid, t: TileWindow) -> Samples {
        let values = (t.y0..=t.y1())
            .flat_map(|y| (t.x0..=t.x1()).map(move |x| (x, y)))
            .map(|(x, y)| g.values()[(y * g.width() + x) as usize])
            .collect();
        Samples::new(t.width, t.height, values).expect("crop")
    }

    fn inputs(g: &Grid, size: u32) -> (TilePlan, Vec<TileInput>) {
        let plan = TilePlan::new(g.width(), g.height(), size).expect("plan");
        let inputs = plan
            .indices()
            .map(|index| {
                let halo = halo_window(&plan, plan.window(index));
                TileInput::cut(&plan, index, &crop(g, halo), &[], halo)
            })
            .collect();
        (plan, inputs)
    }

    fn holey(x: u32, y: u32) -> f64 {
        if (x * 13 + y * 7).is_multiple_of(9) {
            f64::NAN
        } else {
            (x * y) as f64
        }
    }

    #[test]
    fn neighbours_build_identical_shared_profiles() {
        let g = raster(17, 14, holey);
        let (plan, inputs) = inputs(&g, 5);
        for index in plan.indices() {
            let me = &inputs[plan.position(index)];
            if index.col + 1 < plan.columns() {
                let right = &inputs[plan.position(TileIndex {
                    col: index.col + 1,
                    ..index
                })];
                assert_eq!(format!("{:?}", me.right), format!("{:?}", right.left));
            }
            if index.row + 1 < plan.rows() {
                let below = &inputs[plan.position(TileIndex {
                    row: index.row + 1,
                    ..index
                })];
                assert_eq!(format!("{:?}", me.bottom), format!("{:?}", below.top));
            }
        }
    }

    #[test]
    fn owned_domain_samples_add_up_to_the_full_mesh() {
        for size in [2, 3, 4, 6, 40] {
            let g = raster(17, 14, holey);
            let (_, inputs) = inputs(&g, size);
            let total: u64 = inputs.iter().map(|i| i.owned_domain_samples).sum();
            assert_eq!(total as usize, g.domain_sample_count(), "size {size}");
            let valid: u64 = inputs.iter().map(|i| i.owned_valid_samples).sum();
            assert_eq!(valid as usize, g.valid_count(), "size {size}");
        }
    }

    #[test]
    fn steps_beside_nodata_cells_are_closed_on_either_side() {
        // A nodata sample just above a tile's top row closes the two steps under it.
        let g = raster(9, 9, |x, y| if (x, y) == (3, 3) { f64::NAN } else { 1.0 });
        let (plan, inputs) = inputs(&g, 5);
        let below = &inputs[plan.position(TileIndex { col: 0, row: 1 })];
        assert_eq!(below.top.open(), &[true, true, false, false]);
        let above = &inputs[plan.position(TileIndex { col: 0, row: 0 })];
        assert_eq!(above.bottom.open(), below.top.open());
        // Outer borders see one side only.
        assert!(above.top.open().iter().all(|&o| o));
        assert!(above.left.open().iter().all(|&o| o));
        assert_eq!(above.right.open(), &[true, true, false, false]);
    }
}
