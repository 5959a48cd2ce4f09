//! Several variables over one mesh (paper §6): on random small grids with random extra
//! variables, the independent verifier measures every variable within its own bound and
//! the height within its bound, and meshes that must coincide do.

use proptest::prelude::*;
use tinsmith_core::{
    decimate, DecimationOptions, Error, ErrorModel, Grid, InitialMesh, Order, Retriangulation, Tin,
    Variable, VertexHeights,
};
use tinsmith_georef::Samples;
use tinsmith_testkit::{small_grid, terrain, GridSpec};
use tinsmith_verify::{
    verify, verify_variable, GridRef, MeshRef, Orientation, Report, VerifyOptions,
};

fn samples(spec: &GridSpec) -> Samples {
    Samples::new(spec.width, spec.height, spec.values.clone()).unwrap()
}

/// A variable on `spec`'s grid: its values mixed with another field by `mix` (0: the
/// same values, 1: unrelated ones), in a unit `scale` times the height's.
fn variable_like(spec: &GridSpec, other: &GridSpec, mix: f64, scale: f64) -> Vec<f64> {
    spec.values
        .iter()
        .zip(&other.values)
        .map(|(a, b)| scale * ((1.0 - mix) * a + mix * b))
        .collect()
}

/// The height's report and each variable's, from the independent verifier.
fn reports(grid: &Grid, tin: &Tin, bound: f64) -> (Report, Vec<Report>) {
    let positions: Vec<[i64; 2]> = tin
        .vertices()
        .iter()
        .map(|v| [v.x as i64, v.y as i64])
        .collect();
    let heights: Vec<f64> = tin.vertices().iter().map(|v| v.z).collect();
    let (w, h) = (grid.width(), grid.height());
    let domain = GridRef::new(w, h, grid.values());
    let options = VerifyOptions::new().with_orientation(Orientation::CounterClockwise);
    let mesh = MeshRef::new(&positions, &heights, tin.triangles());
    let height = verify(domain, mesh, &options.with_max_error(bound)).unwrap();
    let variables = (0..grid.variable_count())
        .map(|k| {
            let (values, max_error) = grid.variable(k);
            let at_vertices: Vec<f64> = tin
                .vertices()
                .iter()
                .map(|v| values[(v.y * w + v.x) as usize])
                .collect();
            let options = options.with_max_error(max_error);
            verify_variable(domain, values, mesh, &at_vertices, &options).unwrap()
        })
        .collect();
    (height, variables)
}

fn options_to_try(bound: f64) -> Vec<DecimationOptions> {
    let mut all = Vec::new();
    for start in [
        InitialMesh::Full,
        InitialMesh::Rtin,
        InitialMesh::Strips,
        InitialMesh::Insert,
        InitialMesh::Auto,
    ] {
        let base = DecimationOptions::new(bound).with_initial_mesh(start);
        all.push(base.clone());
        all.push(base.clone().with_order(Order::Greedy));
        all.push(base.clone().with_retriangulation(Retriangulation::Ears));
        all.push(base.clone().with_vertex_heights(VertexHeights::Samples));
        all.push(base.clone().with_flip_rounds(2).with_extend_rounds(1));
        // The paper's propagated bounds, every variable's folded in.
        let bounds = base.clone().with_error_model(ErrorModel::Bounds);
        all.push(bounds.clone());
        all.push(bounds.clone().with_retriangulation(Retriangulation::Ears));
        all.push(bounds.with_order(Order::Greedy).with_extend_rounds(1));
    }
    all
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn every_variable_within_its_bound(
        spec in small_grid(),
        other in small_grid(),
        mix in 0.0f64..1.0,
        scale in prop_oneof![Just(1.0), 0.01f64..100.0],
        bound in prop_oneof![Just(0.0), 0.01f64..5.0, 5.0f64..200.0],
        variable_bound in prop_oneof![Just(0.0), 0.01f64..5.0, 5.0f64..200.0, Just(f64::INFINITY)],
    ) {
        // The other field on the same grid: resized by repetition.
        let n = spec.values.len();
        let other = GridSpec {
            width: spec.width,
            height: spec.height,
            values: (0..n).map(|i| other.values[i % other.values.len()]).collect(),
        };
        let second = variable_like(&spec, &other, mix, scale);
        let third = variable_like(&spec, &other, 1.0 - mix, 1.0);
        let grid = Grid::with_variables(
            samples(&spec),
            vec![
                Variable::new(Samples::new(spec.width, spec.height, second).unwrap(), variable_bound).unwrap(),
                Variable::new(Samples::new(spec.width, spec.height, third).unwrap(), bound * 2.0).unwrap(),
            ],
        )
        .unwrap();
        for options in options_to_try(bound) {
            let tin = decimate(&grid, &options).unwrap().tin;
            let (height, variables) = reports(&grid, &tin, bound);
            prop_assert!(height.passed(), "{options:?}: {:?}", height.problems);
            for (k, report) in variables.iter().enumerate() {
                prop_assert!(report.passed(), "{options:?} variable {k}: {:?}", report.problems);
            }
        }
    }

    #[test]
    fn identical_variables_give_the_heights_mesh(
        spec in small_grid(),
        bound in prop_oneof![Just(0.0), 0.01f64..5.0, 5.0f64..200.0],
    ) {
        // Vertices at their samples: a variable equal to the height measures exactly as
        // the height does, so it removes nothing the height alone would keep.
        let options = DecimationOptions::new(bound)
            .with_vertex_heights(VertexHeights::Samples)
            .with_initial_mesh(InitialMesh::Strips);
        let alone = decimate(&Grid::from_samples(samples(&spec)), &options).unwrap().tin;
        let variables = vec![Variable::new(samples(&spec), bound).unwrap(); 2];
        let grid = Grid::with_variables(samples(&spec), variables).unwrap();
        let both = decimate(&grid, &options).unwrap().tin;
        prop_assert_eq!(alone, both);
    }

    #[test]
    fn an_unbounded_variable_changes_nothing(spec in small_grid(), bound in 0.01f64..50.0) {
        let options = DecimationOptions::new(bound).with_initial_mesh(InitialMesh::Rtin);
        let alone = decimate(&Grid::from_samples(samples(&spec)), &options).unwrap().tin;
        let noise: Vec<f64> = (0..spec.values.len()).map(|i| ((i * 7919) % 101) as f64).collect();
        let variable =
            Variable::new(Samples::new(spec.width, spec.height, noise).unwrap(), f64::INFINITY)
                .unwrap();
        let grid = Grid::with_variables(samples(&spec), vec![variable]).unwrap();
        let carried = decimate(&grid, &options).unwrap().tin;
        prop_assert_eq!(alone, carried);
    }
}

#[test]
fn a_tighter_variable_keeps_more_and_a_looser_one_no_fewer_than_its_own_mesh() {
    // Two unrelated terrains: the joint mesh keeps at least the vertices each needs
    // alone, more than either, and tightening one bound never keeps fewer.
    let a = terrain(60, 50, 4.0, 1);
    let b = terrain(60, 50, 4.0, 2);
    let options = DecimationOptions::new(2.0).with_vertex_heights(VertexHeights::Samples);
    let count = |height: &GridSpec, variable: Option<(&GridSpec, f64)>| {
        let grid = match variable {
            None => Grid::from_samples(samples(height)),
            Some((v, e)) => {
                Grid::with_variables(samples(height), vec![Variable::new(samples(v), e).unwrap()])
                    .unwrap()
            }
        };
        decimate(&grid, &options).unwrap().tin.vertices().len()
    };
    let (alone_a, alone_b) = (count(&a, None), count(&b, None));
    let joint = count(&a, Some((&b, 2.0)));
    assert!(joint > alone_a.max(alone_b), "{joint} {alone_a} {alone_b}");
    let tighter = count(&a, Some((&b, 1.0)));
    assert!(tighter > joint, "{tighter} {joint}");
}

#[test]
fn the_domain_is_where_every_variable_is_valid() {
    let spec = terrain(20, 16, 2.0, 3);
    let mut holed = spec.values.clone();
    for i in [5 * 20 + 5, 5 * 20 + 6, 6 * 20 + 5, 6 * 20 + 6] {
        holed[i] = f64::NAN;
    }
    let variable = Variable::new(Samples::new(20, 16, holed).unwrap(), 1.0).unwrap();
    let grid = Grid::with_variables(samples(&spec), vec![variable]).unwrap();
    assert_eq!(grid.valid_count(), 20 * 16 - 4);
    assert_eq!(grid.valid_cell_count(), 19 * 15 - 9);
    let tin = decimate(&grid, &DecimationOptions::new(1.0)).unwrap().tin;
    let (height, variables) = reports(&grid, &tin, 1.0);
    assert!(height.passed() && variables[0].passed());
}

#[test]
fn bad_variables_are_refused() {
    let spec = terrain(8, 6, 1.0, 4);
    let wrong = Samples::new(6, 8, spec.values.clone()).unwrap();
    let err =
        Grid::with_variables(samples(&spec), vec![Variable::new(wrong, 1.0).unwrap()]).unwrap_err();
    assert!(matches!(err, Error::VariableSize { index: 0, .. }), "{err}");
    assert_eq!(
        err.to_string(),
        "variable 0 is a 6x8 grid; the height's is 8x6"
    );
    for bad in [-1.0, f64::NAN] {
        assert!(matches!(
            Variable::new(samples(&spec), bad),
            Err(Error::InvalidMaxError(_))
        ));
    }
    let grid = Grid::with_variables(
        samples(&spec),
        vec![Variable::new(samples(&spec), 1.0).unwrap()],
    )
    .unwrap();
    let count = DecimationOptions::new(1.0)
        .with_order(Order::Greedy)
        .with_max_triangles(10);
    assert!(matches!(
        decimate(&grid, &count),
        Err(Error::VariablesUnsupported(_))
    ));
}

/// A flat height with a variable held at 0 error that its full cells cannot keep (its
/// stars carry infinite bounds): ears' ring-edge errors meet those bounds, and every
/// variable still holds. Found by `every_variable_within_its_bound`.
#[test]
fn a_variable_beyond_its_limit_in_the_start_is_left_as_it_is() {
    let spec = GridSpec {
        width: 2,
        height: 3,
        values: vec![8.833108082136427; 6],
    };
    let other = GridSpec {
        width: 2,
        height: 3,
        values: vec![
            -434.1381659372532,
            -173.44175884180288,
            143.10328245598248,
            62.27499232529169,
            338.25492746876137,
            162.6423939532723,
        ],
    };
    let mix = 0.2146527761007418;
    let grid = Grid::with_variables(
        samples(&spec),
        vec![
            Variable::new(
                Samples::new(2, 3, variable_like(&spec, &other, mix, 1.0)).unwrap(),
                0.0,
            )
            .unwrap(),
            Variable::new(
                Samples::new(2, 3, variable_like(&spec, &other, 1.0 - mix, 1.0)).unwrap(),
                0.02,
            )
            .unwrap(),
        ],
    )
    .unwrap();
    for options in options_to_try(0.01) {
        let tin = decimate(&grid, &options).unwrap().tin;
        let (height, variables) = reports(&grid, &tin, 0.01);
        assert!(height.passed(), "{options:?}: {:?}", height.problems);
        for report in &variables {
            assert!(report.passed(), "{options:?}: {:?}", report.problems);
        }
    }
}
