//! The values of the decimation flags, each the core option of the same name.

use clap::ValueEnum;
use tinsmith_core::{
    EdgeSelection, ErrorModel, InitialMesh, Order, Retriangulation, VertexHeights,
};

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ErrorModelArg {
    /// The paper's accumulated bounds above and below each triangle.
    Bounds,
    /// The true max |sample - plane| over the samples a candidate triangle covers.
    Exact,
}

impl From<ErrorModelArg> for ErrorModel {
    fn from(m: ErrorModelArg) -> ErrorModel {
        match m {
            ErrorModelArg::Bounds => ErrorModel::Bounds,
            ErrorModelArg::Exact => ErrorModel::Exact,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum VertexHeightsArg {
    /// Every vertex at its sample's value.
    Samples,
    /// Each vertex raised above its sample by a hair: 2^-24 of (--max-error + the largest
    /// |height|), at most 1/64 of --max-error (exact model, no count target, no contour
    /// levels): fewer triangles on integer heights at small bounds.
    /// Vertices on the raster's edges (and tiles') stay at their samples.
    Raised,
}

impl From<VertexHeightsArg> for VertexHeights {
    fn from(h: VertexHeightsArg) -> VertexHeights {
        match h {
            VertexHeightsArg::Samples => VertexHeights::Samples,
            VertexHeightsArg::Raised => VertexHeights::Raised,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum OrderArg {
    /// The paper's row-major sweeps, repeated until nothing can be removed.
    Sweep,
    /// Smallest-error removal first (priority queue).
    Greedy,
}

impl From<OrderArg> for Order {
    fn from(o: OrderArg) -> Order {
        match o {
            OrderArg::Sweep => Order::Sweep,
            OrderArg::Greedy => Order::Greedy,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum InitialMeshArg {
    /// Two triangles per valid cell (the paper's start).
    Full,
    /// The coarsest right-triangulated network within the bound (measured exactly).
    Rtin,
    /// Rows or columns simplified as 1-D lines within the bound, zipped into triangles.
    Strips,
    /// Greedy insertion: the sample of largest error inserted into a Delaunay
    /// triangulation until all are within the bound (grids without nodata; others take
    /// auto's start).
    Insert,
    /// Insert where the grid has no nodata and the strips would keep at most 1 sample in
    /// 12 (on a whole raster estimated from every 8th line where that is clear, on a tile counted); else strips, or the RTIN where it is cheap to build and has fewer triangles; the
    /// RTIN with contour levels.
    Auto,
}

impl From<InitialMeshArg> for InitialMesh {
    fn from(m: InitialMeshArg) -> InitialMesh {
        match m {
            InitialMeshArg::Full => InitialMesh::Full,
            InitialMeshArg::Rtin => InitialMesh::Rtin,
            InitialMeshArg::Strips => InitialMesh::Strips,
            InitialMeshArg::Insert => InitialMesh::Insert,
            InitialMeshArg::Auto => InitialMesh::Auto,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum RetriangulateArg {
    /// The paper's greedy ear selection, with --selection.
    Ears,
    /// Min-max-error triangulation by dynamic programming (holes up to --dp-max-ring
    /// vertices; larger ones by ears).
    Dp,
}

impl From<RetriangulateArg> for Retriangulation {
    fn from(r: RetriangulateArg) -> Retriangulation {
        match r {
            RetriangulateArg::Ears => Retriangulation::Ears,
            RetriangulateArg::Dp => Retriangulation::Dp,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum SelectionArg {
    /// Least-introduced first, least-error on a dead end (the paper's choice).
    Hybrid,
    /// The candidate edge with the least error bound.
    MinError,
    /// The candidate edge that changes the surface least.
    MinIntroduced,
}

impl From<SelectionArg> for EdgeSelection {
    fn from(s: SelectionArg) -> EdgeSelection {
        match s {
            SelectionArg::Hybrid => EdgeSelection::Hybrid,
            SelectionArg::MinError => EdgeSelection::MinError,
            SelectionArg::MinIntroduced => EdgeSelection::MinIntroduced,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The report names each choice as the core does; the flag must take the same name.
    #[test]
    fn flag_values_are_the_core_names() {
        fn check<A: ValueEnum + Copy, C>(into: impl Fn(A) -> C, name: impl Fn(C) -> &'static str) {
            for v in A::value_variants() {
                let flag = v.to_possible_value().expect("not skipped");
                assert_eq!(flag.get_name(), name(into(*v)));
            }
        }
        check::<ErrorModelArg, _>(ErrorModel::from, ErrorModel::name);
        check::<SelectionArg, _>(EdgeSelection::from, EdgeSelection::name);
        check::<OrderArg, _>(Order::from, Order::name);
        check::<RetriangulateArg, _>(Retriangulation::from, Retriangulation::name);
        check::<InitialMeshArg, _>(InitialMesh::from, InitialMesh::name);
        check::<VertexHeightsArg, _>(VertexHeights::from, VertexHeights::name);
    }
}

#[derive(Debug, Clone, Copy, Default, ValueEnum)]
pub enum TilingArg {
    /// EPSG:4326 (CesiumJS's default): two root tiles, tiles square in degrees.
    #[default]
    Geographic,
    /// EPSG:3857 (Web Mercator): one root tile, tiles square in Web Mercator; the part of
    /// the raster beyond ±85.0511° latitude is left out.
    Mercator,
}

impl From<TilingArg> for tinsmith_terrain::Tiling {
    fn from(t: TilingArg) -> tinsmith_terrain::Tiling {
        match t {
            TilingArg::Geographic => tinsmith_terrain::Tiling::Geographic,
            TilingArg::Mercator => tinsmith_terrain::Tiling::Mercator,
        }
    }
}
