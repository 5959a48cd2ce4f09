//! The tiled engine: tiles decimated in parallel with their shared edges decided first,
//! verified, numbered and handed to a sink in tile order.

use std::time::Instant;

use crate::tin_check::{check_tin, check_variable};
use tinsmith_core::{
    decimate_with_border, effective_limit, DecimationOptions, DecimationReport, ErrorModel, Grid,
    TinVertex, Variable, MAX_ABS_HEIGHT,
};
use tinsmith_georef::Samples;

use crate::edge::{edge_limit, edge_span, EdgeProfile, EdgeRule};
use crate::error::{Error, Result};
use crate::halo::{halo_window, TileInput};
use crate::ordered_pool::run_ordered;
use crate::plan::{TileIndex, TilePlan, TileWindow};
use crate::sink::{FinishedTile, TileSink};
use crate::source::{TileSource, WindowRead};
use crate::vertex_ids::Welder;

/// The default tile size, in samples per side (shared row and column included).
///
/// Chosen by measurement (docs/results.md, "Tiled engine"): per sample, tiles of 256 to
/// 2048 samples decimate at the same speed within a few percent, and their locked edges
/// add at most about 1 % triangles over an untiled mesh. 512 lets rasters of 513 to 1024
/// samples a side use every core (Big Tujunga, 1197 x 643, on 2 cores: 0.72 s instead of
/// 1.16 s in tiles of 1024, +0.2 % triangles) and keeps a tile's working memory near
/// 50 MB (ETOPO5 on 2 cores: 134 MB peak instead of 317 MB).
pub const DEFAULT_TILE_SIZE: u32 = 512;

/// Options of [`mesh_tiles`].
#[derive(Debug, Clone, PartialEq)]
pub struct TileOptions {
    /// How each tile is decimated. The bound must be finite; count targets
    /// (`max_triangles`, `max_vertices`) are not supported; `max_abs_value` is replaced by
    /// the raster's; `initial_mesh` is honoured (the RTIN or strips refined to half cells
    /// along the tile's border, which the edge stitching needs; insertion starts from the
    /// border samples the stitching kept).
    pub decimation: DecimationOptions,
    /// Samples per tile side, shared row and column included (at least 2).
    pub tile_size: u32,
    /// Worker threads; 0 means one per core. No more than there are cores or tiles are
    /// started (see [`worker_count`]).
    pub threads: usize,
    /// The bound of each of the source's variables ([`TileSource::variable_count`]), in
    /// order (`f64::INFINITY`: carried, never constraining); empty for a source without
    /// variables. Each tile is decimated with them (`Grid::with_variables`, paper §6).
    pub variable_errors: Vec<f64>,
}

impl TileOptions {
    /// `decimation` with [`DEFAULT_TILE_SIZE`] and one thread per core.
    pub fn new(decimation: DecimationOptions) -> TileOptions {
        TileOptions {
            decimation,
            tile_size: DEFAULT_TILE_SIZE,
            threads: 0,
            variable_errors: Vec::new(),
        }
    }

    /// Sets the bounds of the source's variables, one per variable.
    pub fn with_variable_errors(mut self, variable_errors: Vec<f64>) -> TileOptions {
        self.variable_errors = variable_errors;
        self
    }

    /// Sets the tile size.
    pub fn with_tile_size(mut self, tile_size: u32) -> TileOptions {
        self.tile_size = tile_size;
        self
    }

    /// Sets the number of worker threads (0 = one per core).
    pub fn with_threads(mut self, threads: usize) -> TileOptions {
        self.threads = threads;
        self
    }
}

/// How far a tiled run is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TileProgress {
    /// Tiles handed to the sink.
    pub done: usize,
    /// Tiles in the plan.
    pub total: usize,
}

/// What a tiled run did: the plan, counts over the welded mesh, and timings.
#[derive(Debug, Clone, PartialEq)]
pub struct TilesReport {
    /// The tile plan.
    pub plan: TilePlan,
    /// Worker threads used.
    pub threads: usize,
    /// Valid samples of the raster (with variables, valid in every band), each counted
    /// once.
    pub valid_samples: u64,
    /// Vertices of the full mesh of the whole raster (domain samples, each counted once).
    pub initial_vertices: u64,
    /// Triangles of the full mesh (two per valid cell).
    pub initial_triangles: u64,
    /// Vertices of the welded mesh (shared edge vertices counted once).
    pub final_vertices: u64,
    /// Triangles of the welded mesh.
    pub final_triangles: u64,
    /// Largest error bound of any kept triangle, over all tiles.
    pub max_bound: f64,
    /// Largest |sample - TIN| the verifier measured, over all tiles.
    pub measured_max_error: f64,
    /// For each variable, the largest |sample - TIN| the verifier measured, over all tiles.
    pub variables_measured_max_error: Vec<f64>,
    /// Seconds spent reading tiles, summed over tiles (thread-seconds).
    pub seconds_read: f64,
    /// Seconds spent decimating tiles (initial mesh included), summed over tiles.
    pub seconds_decimation: f64,
    /// Seconds spent verifying tiles, summed over tiles.
    pub seconds_verify: f64,
    /// Seconds the sink took, on the calling thread.
    pub seconds_sink: f64,
    /// Wall-clock seconds of the whole run.
    pub seconds_total: f64,
}

/// Meshes `source` tile by tile and pushes every finished tile into `sink`, in row-major
/// tile order.
///
/// # Method
/// The raster is cut by [`TilePlan`] into tiles that share their edge rows and columns.
/// Each tile is read with a one-sample halo. Each of its four edges is simplified as a 1-D
/// polyline ([`EdgeProfile::simplify`]) from the edge's own samples and the validity of the
/// cells on both sides, so the two tiles sharing an edge keep the same edge samples
/// without talking to each other; tile corners are always kept. The tile is then decimated
/// with [`tinsmith_core::decimate_with_border`], which removes the other edge samples
/// inside the border strip and locks the kept ones, and checked by the independent
/// verifier (`tinsmith_verify::verify`) against the tile's samples. Tiles run in parallel
/// on a local rayon pool, one raster reader per worker thread; the calling thread numbers
/// the vertices of the welded mesh (see [`FinishedTile`]) and calls the sink.
///
/// # Guarantees
/// - **Bound.** Every tile passed the verifier at `options.decimation.max_error` before
///   reaching the sink, and every cell of the raster lies in exactly one tile: every domain
///   sample of the raster is within the bound of the welded TIN.
/// - **Variables.** With variables, the domain is where every band is valid; each shared
///   edge skips a sample only when the height and every variable stay within their own
///   limits along the edge (one decision for all of them, [`EdgeProfile::simplify_joint`]),
///   each tile is decimated with its windows of every variable, and every variable of
///   every tile passed the verifier at its own bound.
/// - **Crack-free.** Tiles have identical vertices along shared edges, so the welded mesh
///   is conforming: every edge is used by one or two triangles, and by one only on the
///   outline of the raster's domain.
/// - **Determinism.** The sink sees the same tiles, vertices, ids and triangles whatever
///   the number of threads and from run to run.
/// - **Memory.** At most `2 * threads + 1` tiles are being decimated or waiting for the
///   sink; the welder keeps a few ids per raster column.
///
/// # Errors
/// [`Error::Options`] for an infinite bound or count targets, [`Error::TileSize`],
/// [`Error::TooNarrow`], [`Error::Threads`]; then, for the first failing tile in tile
/// order, [`Error::Read`], [`Error::Decimate`], [`Error::Verify`],
/// [`Error::VerifyFailed`], [`Error::TooManyVertices`] or [`Error::Sink`]. The sink has
/// then received the tiles before that one only.
pub fn mesh_tiles<S: TileSource, K: TileSink>(
    source: &S,
    options: &TileOptions,
    sink: &mut K,
    progress: &mut dyn FnMut(TileProgress),
) -> Result<TilesReport> {
    let started = Instant::now();
    let d = &options.decimation;
    if !d.max_error.is_finite() || d.max_error < 0.0 {
        return Err(Error::Options(
            "tiles need a finite error bound (>= 0) to decimate their shared edges",
        ));
    }
    if d.max_triangles.is_some() || d.max_vertices.is_some() {
        return Err(Error::Options(
            "triangle or vertex count targets need the whole raster at once; they do not \
             work with tiles",
        ));
    }
    if options.variable_errors.len() != source.variable_count() {
        return Err(Error::Options(
            "give one bound per variable of the source (TileOptions::variable_errors)",
        ));
    }
    if options
        .variable_errors
        .iter()
        .any(|e| e.is_nan() || *e < 0.0)
    {
        return Err(Error::Options("variable bounds must be >= 0"));
    }
    let plan = TilePlan::new(source.width(), source.height(), options.tile_size)?;
    // More workers than cores or tiles would only start threads that wait.
    let workers = worker_count(options.threads, plan.len());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(workers)
        .thread_name(|i| format!("tinsmith-tiling-{i}"))
        .build()
        .map_err(|source| Error::Threads {
            threads: options.threads,
            source,
        })?;
    let threads = pool.current_num_threads();
    let max_abs_value = source.max_abs_value();
    if max_abs_value > MAX_ABS_HEIGHT {
        return Err(Error::Heights(tinsmith_core::Error::HeightsTooLarge(
            max_abs_value,
        )));
    }
    let job = TileJob {
        plan,
        options: DecimationOptions {
            max_abs_value: Some(max_abs_value),
            ..d.clone()
        },
        edge_limit: edge_limit(d.max_error, max_abs_value),
        variable_errors: options.variable_errors.clone(),
        variable_limits: (options.variable_errors.iter().enumerate())
            .map(|(k, &e)| edge_limit(e, source.variable_max_abs_value(k)))
            .collect(),
        edge_span: edge_span(d.max_edge_length),
        // At a bound of 0 every tile's core decides planarity exactly when the raster's
        // heights are integers and a tile (halo included) is small enough for that; the
        // edges then skip exactly collinear samples, which those cores accept.
        exact_zero_edges: effective_limit(d.max_error, max_abs_value) == 0.0
            && d.error_model == ErrorModel::Exact
            && source.integral_heights()
            && Grid::integral_product_fits(
                options.tile_size.saturating_add(2),
                options.tile_size.saturating_add(2),
                max_abs_value,
            ),
    };

    let mut report = TilesReport {
        plan,
        threads,
        valid_samples: 0,
        initial_vertices: 0,
        initial_triangles: 0,
        final_vertices: 0,
        final_triangles: 0,
        max_bound: 0.0,
        measured_max_error: 0.0,
        variables_measured_max_error: vec![0.0; options.variable_errors.len()],
        seconds_read: 0.0,
        seconds_decimation: 0.0,
        seconds_verify: 0.0,
        seconds_sink: 0.0,
        seconds_total: 0.0,
    };
    let mut welder = Welder::new(plan);
    let total = plan.len();
    run_ordered(
        &pool,
        total,
        2 * threads + 1,
        || None,
        |reader: &mut Option<S::Reader>, i| job.run(source, reader, plan.index(i)),
        &mut |i, result: Result<DoneTile>| {
            let done = result?;
            let (ids, first_new_id) = welder.weld(done.index, &done.vertices)?;
            let tile = FinishedTile {
                index: done.index,
                window: done.window,
                vertices: done.vertices,
                triangles: done.triangles,
                ids,
                first_new_id,
                variables: done.variables,
                report: done.report,
                measured_max_error: done.measured_max_error,
            };
            let t = Instant::now();
            sink.tile(&tile).map_err(|source| Error::Sink {
                tile: tile.index,
                source,
            })?;
            report.seconds_sink += t.elapsed().as_secs_f64();
            let r = &tile.report;
            report.initial_vertices += done.owned_domain_samples;
            report.valid_samples += done.owned_valid_samples;
            report.initial_triangles += r.initial_triangles as u64;
            report.final_triangles += r.final_triangles as u64;
            report.max_bound = report.max_bound.max(r.max_bound);
            report.measured_max_error = report.measured_max_error.max(tile.measured_max_error);
            for (m, e) in (report.variables_measured_max_error.iter_mut())
                .zip(&done.variables_measured_max_error)
            {
                *m = m.max(*e);
            }
            report.seconds_read += done.seconds_read;
            report.seconds_decimation += r.seconds_initial_mesh + r.seconds_decimation;
            report.seconds_verify += done.seconds_verify;
            progress(TileProgress { done: i + 1, total });
            Ok::<(), Error>(())
        },
    )?;
    report.final_vertices = welder.vertex_count() as u64;
    report.seconds_total = started.elapsed().as_secs_f64();
    Ok(report)
}

/// Worker threads for `jobs` independent jobs: `asked`, or one per core for 0, but never
/// more than the cores the process may use (`available_parallelism`: affinity and cgroup
/// quota) nor than there are jobs; at least 1. More workers than cores only add thread
/// starts, raster readers and tiles in flight: 1024 on 2 cores took 17 s and 1.19 GB
/// instead of 0.31 s and 60 MB (`mesh` of becmodel in tiles of 16). The output does not
/// depend on the count.
pub fn worker_count(asked: usize, jobs: usize) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
    let asked = match asked {
        0 => cores,
        n => n.min(cores),
    };
    asked.min(jobs.max(1))
}

/// What every tile of a run shares.
struct TileJob {
    plan: TilePlan,
    options: DecimationOptions,
    edge_limit: f64,
    /// The bound of each variable.
    variable_errors: Vec<f64>,
    /// The 1-D limit of each variable along shared edges (see [`edge_limit`]).
    variable_limits: Vec<f64>,
    /// Longest skip along a shared edge (see [`edge_span`]).
    edge_span: usize,
    /// At `edge_limit` 0: skip exactly collinear edge samples (integer heights).
    exact_zero_edges: bool,
}

/// A tile decimated and verified on a worker thread, not yet numbered.
struct DoneTile {
    index: TileIndex,
    window: TileWindow,
    /// In raster coordinates.
    vertices: Vec<TinVertex>,
    triangles: Vec<[u32; 3]>,
    report: DecimationReport,
    measured_max_error: f64,
    /// Each variable's values at the vertices (one list per variable).
    variables: Vec<Vec<f64>>,
    /// Each variable's largest error the verifier measured.
    variables_measured_max_error: Vec<f64>,
    owned_domain_samples: u64,
    owned_valid_samples: u64,
    seconds_read: f64,
    seconds_verify: f64,
}

impl TileJob {
    fn run<S: TileSource>(
        &self,
        source: &S,
        reader: &mut Option<S::Reader>,
        index: TileIndex,
    ) -> Result<DoneTile> {
        let read_error = |source| Error::Read {
            tile: index,
            source,
        };
        let reader = match reader {
            Some(reader) => reader,
            None => reader.insert(source.reader().map_err(read_error)?),
        };
        let t = Instant::now();
        let window = self.plan.window(index);
        let halo = halo_window(&self.plan, window);
        let input = {
            let grid = reader
                .read_window(halo.x0, halo.y0, halo.width, halo.height)
                .map_err(read_error)?;
            let variables = (0..self.variable_errors.len())
                .map(|k| reader.read_variable_window(k, halo.x0, halo.y0, halo.width, halo.height))
                .collect::<std::result::Result<Vec<Samples>, _>>()
                .map_err(read_error)?;
            TileInput::cut(&self.plan, index, &grid, &variables, halo)
        };
        let seconds_read = t.elapsed().as_secs_f64();

        let keep = |edge: &EdgeProfile| {
            if !self.variable_limits.is_empty() {
                let rule = if self.edge_limit > 0.0 {
                    EdgeRule::Limit(self.edge_limit)
                } else if self.exact_zero_edges {
                    EdgeRule::Collinear
                } else {
                    EdgeRule::KeepAll
                };
                edge.simplify_joint(rule, &self.variable_limits, self.edge_span)
            } else if self.edge_limit > 0.0 {
                edge.simplify(self.edge_limit, self.edge_span)
            } else if self.exact_zero_edges {
                edge.simplify_collinear(self.edge_span)
            } else {
                // Below the rounding slack on other heights the core removes only exactly
                // flat stars, within f64 rounding: keep every edge sample.
                vec![true; edge.values().len()]
            }
        };
        let (top, bottom) = (keep(&input.top), keep(&input.bottom));
        let (left, right) = (keep(&input.left), keep(&input.right));
        let (w, h) = (window.width, window.height);
        let keep_border = |x: u32, y: u32| {
            if y == 0 {
                top[x as usize]
            } else if y == h - 1 {
                bottom[x as usize]
            } else if x == 0 {
                left[y as usize]
            } else if x == w - 1 {
                right[y as usize]
            } else {
                true
            }
        };
        let joined;
        let grid = if input.variables.is_empty() {
            &input.grid
        } else {
            let height =
                Samples::new(w, h, input.grid.values().to_vec()).expect("the tile's own samples");
            let variables = (input.variables.iter().zip(&self.variable_errors))
                .map(|(samples, &e)| Variable::new(samples.clone(), e))
                .collect::<tinsmith_core::Result<Vec<Variable>>>()
                .and_then(|variables| Grid::with_variables(height, variables))
                .map_err(|source| Error::Decimate {
                    tile: index,
                    source,
                })?;
            joined = variables;
            &joined
        };
        let decimation = decimate_with_border(grid, &self.options, &keep_border, &mut |_| {})
            .map_err(|source| Error::Decimate {
                tile: index,
                source,
            })?;

        // The promise is checked, independently, before the tile goes anywhere.
        let t = Instant::now();
        let tin = &decimation.tin;
        let check = check_tin(grid, tin, |_, v| v.z, self.options.max_error).map_err(|source| {
            Error::Verify {
                tile: index,
                source,
            }
        })?;
        if !check.passed() {
            return Err(Error::VerifyFailed {
                tile: index,
                problems: check.problems.join("; "),
            });
        }
        let mut variables = Vec::with_capacity(input.variables.len());
        let mut variables_measured_max_error = Vec::with_capacity(input.variables.len());
        for (k, samples) in input.variables.iter().enumerate() {
            let values: Vec<f64> = (tin.vertices().iter())
                .map(|v| samples.values()[(v.y * w + v.x) as usize])
                .collect();
            let check = check_variable(
                grid,
                samples.values(),
                tin,
                &values,
                self.variable_errors[k],
            )
            .map_err(|source| Error::Verify {
                tile: index,
                source,
            })?;
            if !check.passed() {
                return Err(Error::VerifyFailed {
                    tile: index,
                    problems: format!("variable {}: {}", k + 1, check.problems.join("; ")),
                });
            }
            variables.push(values);
            variables_measured_max_error.push(check.max_error);
        }
        let seconds_verify = t.elapsed().as_secs_f64();

        let vertices = tin
            .vertices()
            .iter()
            .map(|v| TinVertex {
                x: v.x + window.x0,
                y: v.y + window.y0,
                z: v.z,
            })
            .collect();
        Ok(DoneTile {
            index,
            window,
            vertices,
            triangles: tin.triangles().to_vec(),
            report: decimation.report,
            measured_max_error: check.max_error,
            variables,
            variables_measured_max_error,
            owned_domain_samples: input.owned_domain_samples,
            owned_valid_samples: input.owned_valid_samples,
            seconds_read,
            seconds_verify,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{GridSource, MeshCollector};
    use tinsmith_verify::{GridRef, MeshRef, VerifyOptions};

    /// The grid, the welded vertices and triangles, and the variable's vertex values.
    type Run = (Grid, Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<f64>);

    /// A 37 x 29 grid (tiles of 8: shared edges at multiples of 7) with one variable of
    /// other detail within `bound`, meshed in tiles on `threads` threads.
    fn two_variable_run(bound: f64, threads: usize) -> Run {
        let (w, h) = (37u32, 29u32);
        let at = |f: &dyn Fn(f64, f64) -> f64| -> Samples {
            let values = (0..h).flat_map(|y| (0..w).map(move |x| (f64::from(x), f64::from(y))));
            Samples::new(w, h, values.map(|(x, y)| f(x, y)).collect()).expect("samples")
        };
        let height = at(&|x, y| (0.3 * x).sin() * 4.0 + 0.1 * y);
        let variable = at(&|x, y| {
            if x == 20.0 || y == 13.0 {
                3.0
            } else {
                (0.5 * y).cos()
            }
        });
        let grid =
            Grid::with_variables(height, vec![Variable::new(variable, bound).expect("bound")])
                .expect("grid");
        let options = TileOptions::new(DecimationOptions::new(0.5))
            .with_tile_size(8)
            .with_threads(threads)
            .with_variable_errors(vec![bound]);
        let mut collector = MeshCollector::new();
        let report = mesh_tiles(
            &GridSource::new(&grid),
            &options,
            &mut collector,
            &mut |_| {},
        )
        .expect("tiles");
        assert!(report.variables_measured_max_error[0] <= bound);
        let mut variables = collector.take_variables();
        let (vertices, triangles) = collector.into_parts();
        (grid, vertices, triangles, variables.remove(0))
    }

    #[test]
    fn variables_keep_their_bound_over_welded_tiles() {
        for bound in [0.05, 0.5, f64::INFINITY] {
            let (grid, vertices, triangles, values) = two_variable_run(bound, 2);
            assert_eq!(values.len(), vertices.len());
            let positions: Vec<[i64; 2]> = vertices
                .iter()
                .map(|v| [v[0] as i64, v[1] as i64])
                .collect();
            let heights: Vec<f64> = vertices.iter().map(|v| v[2]).collect();
            let domain = GridRef::new(grid.width(), grid.height(), grid.values());
            let report = tinsmith_verify::verify(
                domain,
                MeshRef::new(&positions, &heights, &triangles),
                &VerifyOptions::new().with_max_error(0.5),
            )
            .expect("verify");
            assert!(report.passed(), "{:?}", report.problems);
            let mut options = VerifyOptions::new();
            if bound.is_finite() {
                options = options.with_max_error(bound);
            }
            let report = tinsmith_verify::verify_variable(
                domain,
                grid.variable(0).0,
                MeshRef::new(&positions, &[], &triangles),
                &values,
                &options,
            )
            .expect("verify the variable");
            assert!(report.passed(), "bound {bound}: {:?}", report.problems);
        }
        let one = two_variable_run(0.05, 1);
        let two = two_variable_run(0.05, 2);
        assert_eq!((one.1, one.2, one.3), (two.1, two.2, two.3));
    }

    #[test]
    fn a_tight_variable_keeps_more_shared_edge_vertices() {
        let on_edges = |bound: f64| {
            let (_, vertices, _, _) = two_variable_run(bound, 1);
            let shared = |c: f64| c > 0.0 && c < 36.0 && c % 7.0 == 0.0;
            (vertices.iter())
                .filter(|v| shared(v[0]) || (shared(v[1]) && v[1] < 28.0))
                .count()
        };
        assert!(on_edges(0.05) > on_edges(f64::INFINITY));
    }

    #[test]
    fn workers_are_no_more_than_cores_or_jobs() {
        let cores = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
        assert_eq!(worker_count(1024, 100_000), cores);
        assert_eq!(worker_count(0, 100_000), cores);
        assert_eq!(worker_count(1, 100_000), 1);
        assert_eq!(worker_count(1024, 1), 1);
        assert_eq!(worker_count(0, 0), 1);
    }
}
