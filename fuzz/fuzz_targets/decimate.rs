//! The decimation core on arbitrary small grids (up to 12 x 12, heights that may be nodata,
//! huge or tiny) with an arbitrary bound and options, judged by the independent verifier:
//! the result must be a valid mesh of the domain with every valid sample within the bound
//! (within the reported bound for count targets), and an error only for the documented
//! bad inputs. A panic or a failed check is a finding.
#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use tinsmith_core::{
    decimate, DecimationOptions, EdgeSelection, Error, ErrorModel, Grid, InitialMesh, Order,
    Retriangulation, VertexHeights, MAX_ABS_HEIGHT,
};
use tinsmith_verify::{verify, GridRef, MeshRef, Orientation, VerifyOptions};

/// Largest grid side.
const MAX_SIDE: u8 = 12;

/// A sample: mostly small multiples of 1/4 (so that planes, flats and ties are common),
/// sometimes nodata or any `f64`.
#[derive(Debug, Arbitrary)]
enum Height {
    Quarters(i8),
    Nodata,
    Any(f64),
}

impl Height {
    fn value(&self) -> f64 {
        match *self {
            Height::Quarters(q) => f64::from(q) / 4.0,
            Height::Nodata => f64::NAN,
            Height::Any(v) => v,
        }
    }
}

/// The error bound: mostly sixteenths, sometimes any `f64`.
#[derive(Debug, Arbitrary)]
enum Bound {
    Sixteenths(u8),
    Any(f64),
}

#[derive(Debug, Arbitrary)]
struct Input {
    width: u8,
    height: u8,
    heights: Vec<Height>,
    bound: Bound,
    bounds_model: bool,
    greedy: bool,
    initial_mesh: u8,
    ears: bool,
    selection: u8,
    samples_heights: bool,
    dp_max_ring: u8,
    max_abs_value: Option<f64>,
    max_triangles: Option<u8>,
    max_vertices: Option<u8>,
    max_edge_length: Option<u8>,
    contour_levels: Option<Vec<i8>>,
    flip_rounds: u8,
    extend_rounds: u8,
}

impl Input {
    fn options(&self) -> DecimationOptions {
        let max_error = match self.bound {
            Bound::Sixteenths(n) => f64::from(n) / 16.0,
            Bound::Any(v) => v,
        };
        let mut options = DecimationOptions::new(max_error)
            .with_error_model(if self.bounds_model {
                ErrorModel::Bounds
            } else {
                ErrorModel::Exact
            })
            .with_order(if self.greedy {
                Order::Greedy
            } else {
                Order::Sweep
            })
            .with_initial_mesh(match self.initial_mesh % 4 {
                0 => InitialMesh::Full,
                1 => InitialMesh::Rtin,
                2 => InitialMesh::Strips,
                _ => InitialMesh::Auto,
            })
            .with_retriangulation(if self.ears {
                Retriangulation::Ears
            } else {
                Retriangulation::Dp
            })
            .with_selection(match self.selection % 3 {
                0 => EdgeSelection::MinError,
                1 => EdgeSelection::MinIntroduced,
                _ => EdgeSelection::Hybrid,
            })
            .with_vertex_heights(if self.samples_heights {
                VertexHeights::Samples
            } else {
                VertexHeights::Raised
            })
            .with_flip_rounds(usize::from(self.flip_rounds % 3))
            .with_extend_rounds(usize::from(self.extend_rounds % 3));
        options.dp_max_ring = usize::from(self.dp_max_ring % 16);
        options.max_abs_value = self.max_abs_value;
        if let Some(n) = self.max_triangles {
            options = options.with_max_triangles(usize::from(n));
        }
        if let Some(n) = self.max_vertices {
            options = options.with_max_vertices(usize::from(n));
        }
        if let Some(n) = self.max_edge_length {
            options = options.with_max_edge_length(u32::from(n % 16));
        }
        if let Some(levels) = &self.contour_levels {
            let levels: Vec<f64> = levels.iter().map(|&l| f64::from(l) / 2.0).collect();
            options = options.with_contour_levels(&levels);
        }
        options
    }
}

fuzz_target!(|input: Input| {
    let width = u32::from(input.width % MAX_SIDE + 1);
    let height = u32::from(input.height % MAX_SIDE + 1);
    let n = (width * height) as usize;
    let values: Vec<f64> = (0..n)
        .map(|i| input.heights.get(i).map_or(0.0, Height::value))
        .collect();
    let options = input.options();
    let grid = Grid::new(width, height, values.clone()).expect("a grid of the right size");

    // The documented errors, and only they.
    let count_target = options.max_triangles.is_some() || options.max_vertices.is_some();
    let bound = options.max_error;
    let bad_bound = bound.is_nan() || bound < 0.0 || (bound.is_infinite() && !count_target);
    let bad_length = options.max_edge_length.is_some_and(|l| l < 2);
    let max_abs = values
        .iter()
        .filter(|v| v.is_finite())
        .fold(options.max_abs_value.unwrap_or(0.0), |m, v| m.max(v.abs()));
    let too_high = max_abs > MAX_ABS_HEIGHT;
    let result = match decimate(&grid, &options) {
        Ok(result) => {
            assert!(
                !bad_bound && !bad_length && !too_high,
                "{options:?} was accepted"
            );
            result
        }
        Err(Error::InvalidMaxError(_)) if bad_bound => return,
        Err(Error::InvalidMaxEdgeLength(_)) if bad_length => return,
        Err(Error::HeightsTooLarge(_)) if too_high => return,
        Err(error) => panic!("{options:?}: {error}"),
    };

    let tin = &result.tin;
    let positions: Vec<[i64; 2]> = tin
        .vertices()
        .iter()
        .map(|v| [i64::from(v.x), i64::from(v.y)])
        .collect();
    let heights: Vec<f64> = tin.vertices().iter().map(|v| v.z).collect();
    let mut verify_options = VerifyOptions::new().with_orientation(Orientation::CounterClockwise);
    if !count_target {
        verify_options = verify_options.with_max_error(bound);
    }
    let report = verify(
        GridRef::new(width, height, &values),
        MeshRef::new(&positions, &heights, tin.triangles()),
        &verify_options,
    )
    .expect("consistent lengths");
    assert!(report.passed(), "{options:?}: {:?}", report.problems);
    // The reported bound is exact; the measurement rounds (by far less than this slack).
    let rounding = (result.report.max_bound + max_abs.max(0.0)) / (1u64 << 40) as f64;
    assert!(
        report.max_error <= result.report.max_bound + rounding,
        "{options:?}: measured {} above the reported bound {}",
        report.max_error,
        result.report.max_bound
    );
    assert_eq!(result.report.final_triangles, tin.triangles().len());
    assert_eq!(result.report.final_vertices, tin.vertices().len());
    if let Some(length) = options.max_edge_length {
        let longest = tin
            .triangles()
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .map(|(a, b)| {
                let (p, q) = (positions[a as usize], positions[b as usize]);
                (p[0] - q[0]).pow(2) + (p[1] - q[1]).pow(2)
            })
            .max()
            .unwrap_or(0);
        assert!(
            longest <= i64::from(length).pow(2),
            "{options:?}: edge² {longest}"
        );
    }
});
