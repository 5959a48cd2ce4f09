//! What the caller chooses: the error bound and the paper's strategy knobs.

/// How the error of a candidate triangle is estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum ErrorModel {
    /// The paper's §3.3 model: two accumulated bounds per triangle, above and below.
    Bounds,
    /// The true error: a candidate triangle's largest |sample - plane| over the original
    /// samples it covers, measured on the grid. No accumulation.
    #[default]
    Exact,
}

/// The order in which vertices are tried for removal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Order {
    /// The paper's sweeps in row-major order, repeated until nothing can be removed.
    #[default]
    Sweep,
    /// A priority queue: the vertex whose best retriangulation has the smallest error goes
    /// first; neighbours' keys are refreshed after each removal.
    Greedy,
}

/// The mesh decimation starts from. Every start's triangles are measured within the
/// bound, so the guarantee is the same whichever is chosen; they differ in time and, by a
/// few per cent, in the triangles decimation ends with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum InitialMesh {
    /// Every valid cell split into two triangles (the paper's starting point).
    Full,
    /// The coarsest right-triangulated irregular network (longest-edge bisection of a
    /// power-of-two square) whose triangles are all within the bound, measured exactly;
    /// much faster than the full grid when the bound removes most samples.
    Rtin,
    /// Every row (or every column, whichever keeps fewer samples) simplified as a 1-D
    /// polyline within the bound, adjacent lines zipped into triangles: one pass over the
    /// grid, and fewer samples than the RTIN keeps where the bound is small for the
    /// ground's roughness.
    Strips,
    /// Greedy insertion (Garland & Heckbert): from the domain's corners, the sample of
    /// largest exact error is inserted into a Delaunay triangulation until every triangle
    /// is within the bound; far fewer vertices than the other starts where the result
    /// keeps a small share of the samples. Grids with nodata use [`InitialMesh::Auto`]'s
    /// start instead.
    Insert,
    /// [`InitialMesh::Insert`] where the grid has no nodata and the strips would keep at
    /// most one sample in 12 (and insertion places fewer vertices than they keep);
    /// otherwise [`InitialMesh::Strips`], or the RTIN where its probe finds it cheap (few
    /// of the finest squares split) and it has fewer triangles; the RTIN when contour
    /// levels are given ([`DecimationOptions::with_contour_levels`]), which keep fewer
    /// segments from it. The choice depends only on the grid and the options.
    #[default]
    Auto,
}

/// How a hole is retriangulated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Retriangulation {
    /// The paper's greedy ear selection (§3.4), with [`EdgeSelection`].
    Ears,
    /// The min-max-error triangulation of the hole by dynamic programming (optimal for the
    /// error model); holes with more than [`DecimationOptions::dp_max_ring`] vertices use
    /// ears.
    #[default]
    Dp,
}

/// Which candidate edge the hole retriangulation picks next (paper §3.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EdgeSelection {
    /// The edge with the least error bound.
    MinError,
    /// The edge that introduces the least change from the previous triangulation.
    MinIntroduced,
    /// The paper's implementation: `MinIntroduced`, and on a dead end `MinError`.
    #[default]
    Hybrid,
}

/// Where the TIN's vertices sit in height.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VertexHeights {
    /// Every vertex at its sample's value, as the paper and hmm have them.
    Samples,
    /// Each vertex off the grid's outer rows and columns raised above its sample by a hair
    /// (2^-24 of the bound plus the largest |height|, at most
    /// 1/[`crate::RAISED_HEIGHT_SHARE`] of the bound, and whatever the bound at most 2^-24
    /// of three times the largest |height|: see [`crate::vertex_raise`]; exact model with
    /// a bound and no contour levels only; otherwise as `Samples`). The bound still holds at every
    /// sample, the vertices' own included. On integer heights many candidate triangles
    /// have a sample exactly the bound away from their plane (through integer vertices),
    /// which the rounding margin then refuses; raised, those with the sample above the
    /// plane pass with room to spare: 3–10 % fewer triangles at bounds of a unit or less
    /// (docs/results.md).
    #[default]
    Raised,
}

impl ErrorModel {
    /// Its name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Bounds => "bounds",
            Self::Exact => "exact",
        }
    }
}

impl EdgeSelection {
    /// Its name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Hybrid => "hybrid",
            Self::MinError => "min-error",
            Self::MinIntroduced => "min-introduced",
        }
    }
}

impl Order {
    /// Its name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Sweep => "sweep",
            Self::Greedy => "greedy",
        }
    }
}

impl Retriangulation {
    /// Its name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ears => "ears",
            Self::Dp => "dp",
        }
    }
}

impl InitialMesh {
    /// Its name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Full => "full",
            Self::Rtin => "rtin",
            Self::Strips => "strips",
            Self::Insert => "insert",
            Self::Auto => "auto",
        }
    }
}

impl VertexHeights {
    /// Its name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Samples => "samples",
            Self::Raised => "raised",
        }
    }
}

/// Options of [`crate::decimate`].
#[derive(Debug, Clone, PartialEq)]
pub struct DecimationOptions {
    /// The promised bound on |sample - TIN| at every domain sample.
    pub max_error: f64,
    /// Candidate-edge selection rule.
    pub selection: EdgeSelection,
    /// Error model.
    pub error_model: ErrorModel,
    /// Removal order.
    pub order: Order,
    /// The mesh decimation starts from.
    pub initial_mesh: InitialMesh,
    /// Hole retriangulation.
    pub retriangulation: Retriangulation,
    /// Largest hole (ring vertices) that [`Retriangulation::Dp`] handles; larger ones use
    /// ears. The dynamic program costs O(n^3) triangle evaluations.
    pub dp_max_ring: usize,
    /// The largest |value| the rounding slack is computed from (see
    /// [`crate::effective_limit`]); `None` uses the grid's own. Tiles of one raster set the
    /// raster's value so that they all enforce the same limit.
    pub max_abs_value: Option<f64>,
    /// Stop once the mesh has at most this many triangles (greedy order only; with
    /// `max_vertices` too, once both are met).
    pub max_triangles: Option<usize>,
    /// Stop once the mesh has at most this many vertices (greedy order only; with
    /// `max_triangles` too, once both are met).
    pub max_vertices: Option<usize>,
    /// Longest edge allowed in the output, in sample spacings (at least 2; measured by
    /// [`DecimationOptions::edge_metric`]): a removal that
    /// would need a longer edge is refused. For renderers that interpolate in another space
    /// than the grid's (e.g. terrain on a globe, where long edges cut below the surface).
    pub max_edge_length: Option<u32>,
    /// How an edge's length is measured against `max_edge_length`. On a sphere
    /// ([`crate::EdgeMetric::Sphere`]) no triangle may turn over as drawn, with a length
    /// limit or without one.
    pub edge_metric: crate::EdgeMetric,
    /// Contour levels to shape the TIN for (see [`DecimationOptions::with_contour_levels`]);
    /// sorted, finite, without duplicates.
    pub contour_levels: Option<std::sync::Arc<[f64]>>,
    /// Rounds of error-lowering edge flips, each followed by another sweep (see
    /// [`DecimationOptions::with_flip_rounds`]); 0 (the default) for none.
    pub flip_rounds: usize,
    /// Rounds of removal through extended holes, each followed by another sweep (see
    /// [`DecimationOptions::with_extend_rounds`]); 0 (the default) for none.
    pub extend_rounds: usize,
    /// Where the vertices sit in height.
    pub vertex_heights: VertexHeights,
}

impl DecimationOptions {
    /// Options with the given error bound and the defaults chosen by measurement
    /// (docs/results.md): exact error, the `auto` start (greedy insertion where few samples
    /// stay, else strips, or the RTIN where it is cheap), row-major sweeps, DP holes. [`DecimationOptions::paper`] gives the paper's
    /// configuration.
    pub fn new(max_error: f64) -> DecimationOptions {
        DecimationOptions {
            max_error,
            selection: EdgeSelection::default(),
            error_model: ErrorModel::default(),
            order: Order::default(),
            initial_mesh: InitialMesh::default(),
            retriangulation: Retriangulation::default(),
            dp_max_ring: 8,
            max_abs_value: None,
            max_triangles: None,
            max_vertices: None,
            max_edge_length: None,
            edge_metric: crate::EdgeMetric::Grid,
            contour_levels: None,
            flip_rounds: 0,
            extend_rounds: 0,
            vertex_heights: VertexHeights::default(),
        }
    }

    /// The paper's configuration: accumulated bounds (§3.3), the full grid as the start,
    /// sweeps (§3.1), ear selection with the hybrid rule (§3.4).
    pub fn paper(max_error: f64) -> DecimationOptions {
        DecimationOptions {
            error_model: ErrorModel::Bounds,
            initial_mesh: InitialMesh::Full,
            order: Order::Sweep,
            retriangulation: Retriangulation::Ears,
            selection: EdgeSelection::Hybrid,
            ..DecimationOptions::new(max_error)
        }
    }

    /// Options that decimate until at most `max_triangles` triangles remain, whatever the
    /// error (greedy order: the smallest-error removals go first).
    pub fn with_max_triangles(mut self, max_triangles: usize) -> DecimationOptions {
        self.max_triangles = Some(max_triangles);
        self.order = Order::Greedy;
        self
    }

    /// Options that decimate until at most `max_vertices` vertices remain (greedy order).
    pub fn with_max_vertices(mut self, max_vertices: usize) -> DecimationOptions {
        self.max_vertices = Some(max_vertices);
        self.order = Order::Greedy;
        self
    }

    /// Sets the longest edge allowed, in sample spacings (see
    /// [`DecimationOptions::max_edge_length`]).
    pub fn with_max_edge_length(mut self, samples: u32) -> DecimationOptions {
        self.max_edge_length = Some(samples);
        self
    }

    /// Sets how an edge's length is measured (see [`DecimationOptions::edge_metric`]).
    pub fn with_edge_metric(mut self, metric: crate::EdgeMetric) -> DecimationOptions {
        self.edge_metric = metric;
        self
    }

    /// Shapes the TIN for contour lines at `levels` (non-finite values are dropped): among
    /// the hole triangulations within the bound, the dynamic program picks one whose
    /// triangles span the fewest levels; a removal that would still span more levels than
    /// the star it replaces is not made (to a bound; count targets remove regardless);
    /// and once no vertex can go, edges are flipped where the new edge spans fewer levels
    /// and both new triangles stay within the bound. Each triangle a level passes through
    /// gives a contour line one segment, so the lines get fewer segments (for a few more
    /// triangles); the bound is kept exactly as without levels. No finite level leaves
    /// the options as they were.
    pub fn with_contour_levels(mut self, levels: &[f64]) -> DecimationOptions {
        let mut levels: Vec<f64> = levels.iter().copied().filter(|l| l.is_finite()).collect();
        levels.sort_by(f64::total_cmp);
        levels.dedup();
        self.contour_levels = (!levels.is_empty()).then(|| levels.into());
        self
    }

    /// Once no vertex can go, runs up to `rounds` rounds of: flip every interior edge whose
    /// quadrilateral is strictly convex into the other diagonal when both new triangles'
    /// exact errors are within the bound and below 0.9 times the larger error of the two
    /// old ones, then sweep again for the vertices that can now go. Fewer triangles at
    /// small bounds (2–5 % in two to eight rounds at ε ≤ 1 on real DEMs), at 2–5 × the time;
    /// the bound is kept. A round that flips nothing ends them. Ignored with count targets.
    pub fn with_flip_rounds(mut self, rounds: usize) -> DecimationOptions {
        self.flip_rounds = rounds;
        self
    }

    /// Once no vertex can go, tries each remaining vertex again with its hole extended
    /// across its ring edges (the triangle beyond a ring edge joins the hole, one edge at a
    /// time, then all at once), which gives the retriangulation more freedom; then sweeps
    /// again. Repeats `rounds` times, or until a round removes nothing. Fewer triangles at
    /// every bound (3–7 % on real DEMs at ε from 0.5 to 5), for 3–6 × the time; the bound
    /// is kept (every new triangle is measured as in a sweep). Ignored with count targets.
    pub fn with_extend_rounds(mut self, rounds: usize) -> DecimationOptions {
        self.extend_rounds = rounds;
        self
    }

    /// Sets the initial mesh.
    pub fn with_initial_mesh(mut self, initial_mesh: InitialMesh) -> DecimationOptions {
        self.initial_mesh = initial_mesh;
        self
    }

    /// Sets the removal order.
    pub fn with_order(mut self, order: Order) -> DecimationOptions {
        self.order = order;
        self
    }

    /// Sets the hole retriangulation.
    pub fn with_retriangulation(mut self, retriangulation: Retriangulation) -> DecimationOptions {
        self.retriangulation = retriangulation;
        self
    }

    /// Sets the edge selection rule.
    pub fn with_selection(mut self, selection: EdgeSelection) -> DecimationOptions {
        self.selection = selection;
        self
    }

    /// Sets where the vertices sit in height.
    pub fn with_vertex_heights(mut self, vertex_heights: VertexHeights) -> DecimationOptions {
        self.vertex_heights = vertex_heights;
        self
    }

    /// Sets the error model.
    pub fn with_error_model(mut self, error_model: ErrorModel) -> DecimationOptions {
        self.error_model = error_model;
        self
    }

    /// Whether decimation with these options raises the vertex heights on data whose
    /// largest |value| is `max_abs_value` (the larger of it and
    /// [`DecimationOptions::max_abs_value`] counts): [`VertexHeights::Raised`] asked for,
    /// under the exact model (the paper's bounds start from vertices at their samples),
    /// with a bound to take the room from (above the rounding slack of
    /// [`crate::effective_limit`]; count targets have none), and without contour levels
    /// (`contour --mesh` reads a level-shaped TIN back with its vertices at their samples).
    /// Where this is false, every vertex sits at its sample.
    pub fn raises_vertex_heights(&self, max_abs_value: f64) -> bool {
        let max_abs = self.max_abs_value.unwrap_or(0.0).max(max_abs_value);
        self.vertex_heights == VertexHeights::Raised
            && self.contour_levels.is_none()
            && self.error_model == ErrorModel::Exact
            && self.max_triangles.is_none()
            && self.max_vertices.is_none()
            && crate::effective_limit(self.max_error, max_abs) > 0.0
    }
}
