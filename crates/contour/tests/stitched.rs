//! `ContourStitcher` against `contour` on the whole mesh: the mesh's triangles are dealt out
//! to pieces (contiguous blocks, as tiles are, or at random, so that lines cross pieces at
//! every edge), the pieces are added in a shuffled order, and the lines must be exactly
//! those of the whole mesh, in the same order.

use proptest::prelude::*;
use tinsmith_contour::{contour, ContourMesh, ContourStitcher, Polyline};
use tinsmith_testkit::{max_error, small_grid, GridSpec, SplitMix};

mod common;
use common::{levels_for, meshes};

/// The piece of `mesh` holding the triangles `pick` selects: its own vertex numbering, and
/// each vertex's index in `mesh` as its id.
fn piece(mesh: &ContourMesh, pick: impl Fn(usize, &[u32; 3]) -> bool) -> (ContourMesh, Vec<u32>) {
    let mut local = vec![u32::MAX; mesh.vertices().len()];
    let (mut vertices, mut ids, mut triangles) = (Vec::new(), Vec::new(), Vec::new());
    for (t, tri) in mesh.triangles().iter().enumerate() {
        if !pick(t, tri) {
            continue;
        }
        triangles.push(tri.map(|v| {
            if local[v as usize] == u32::MAX {
                local[v as usize] = vertices.len() as u32;
                vertices.push(mesh.vertices()[v as usize]);
                ids.push(v);
            }
            local[v as usize]
        }));
    }
    (ContourMesh::new(vertices, triangles).unwrap(), ids)
}

/// Stitches `mesh` dealt into `count` pieces by `which` (triangle -> piece), added in an
/// order shuffled by `seed`.
fn stitched(
    mesh: &ContourMesh,
    levels: &[f64],
    count: usize,
    which: impl Fn(usize, &[u32; 3]) -> usize,
    seed: u64,
) -> Vec<Polyline> {
    let mut order: Vec<usize> = (0..count).collect();
    let mut rng = SplitMix::new(seed);
    for i in (1..order.len()).rev() {
        order.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
    }
    let mut stitcher = ContourStitcher::new(levels).unwrap();
    for k in order {
        let (part, ids) = piece(mesh, |t, tri| which(t, tri) == k);
        stitcher.add(&part, &ids).unwrap();
    }
    stitcher.finish()
}

/// Contiguous blocks: a triangle goes to the block of its first corner's position.
fn blocks(mesh: &ContourMesh, side: f64) -> impl Fn(usize, &[u32; 3]) -> usize + '_ {
    move |_, tri| {
        let c: Vec<[f64; 3]> = tri.iter().map(|&v| mesh.vertices()[v as usize]).collect();
        let (x, y) = (
            (c[0][0] + c[1][0] + c[2][0]) / 3.0,
            (c[0][1] + c[1][1] + c[2][1]) / 3.0,
        );
        ((x / side) as usize).min(3) + 4 * ((y / side) as usize).min(3)
    }
}

fn check(mesh: &ContourMesh, levels: &[f64], seed: u64) -> Result<(), TestCaseError> {
    let whole = contour(mesh, levels).unwrap();
    let side = mesh
        .vertices()
        .iter()
        .map(|v| v[0].max(v[1]))
        .fold(1.0, f64::max)
        / 3.0;
    prop_assert_eq!(
        &stitched(mesh, levels, 16, blocks(mesh, side), seed),
        &whole
    );
    let deal = |t: usize, _: &[u32; 3]| (SplitMix::new(seed ^ t as u64).next_u64() % 5) as usize;
    prop_assert_eq!(&stitched(mesh, levels, 5, deal, seed), &whole);
    Ok(())
}

proptest! {
    #[test]
    fn stitched_pieces_give_the_whole_mesh_lines(
        spec in small_grid(),
        e in max_error(),
        seed in any::<u64>(),
    ) {
        let levels = levels_for(&spec, seed);
        for mesh in meshes(&spec, e) {
            check(&mesh, &levels, seed)?;
        }
    }
}

#[test]
fn stitched_terrain_with_holes_and_quantized_heights() {
    let spec = tinsmith_testkit::with_nodata_disc(
        tinsmith_testkit::terrain(60, 45, 4.0, 7),
        20.0,
        20.0,
        6.0,
    );
    // Quantized heights: levels land exactly on many samples, rings cross pieces.
    let q = GridSpec {
        values: spec
            .values
            .iter()
            .map(|v| (v / 10.0).round() * 10.0)
            .collect(),
        ..spec
    };
    let levels: Vec<f64> = (0..80).map(|k| 300.0 + 10.0 * k as f64).collect();
    for (i, mesh) in meshes(&q, 2.0).iter().enumerate() {
        let whole = contour(mesh, &levels).unwrap();
        // The case this test is for, on the meshes with vertices at their samples.
        assert!(
            i == 2 || whole.iter().any(Polyline::is_closed) && whole.iter().any(|l| !l.is_closed())
        );
        check(mesh, &levels, 3).unwrap();
    }
}

#[test]
fn a_piece_added_twice_is_refused() {
    let values: Vec<f64> = (0..25).map(|i| (i % 5) as f64).collect();
    let mesh = ContourMesh::from_grid(5, 5, &values).unwrap();
    let (all, ids) = piece(&mesh, |_, _| true);
    let mut stitcher = ContourStitcher::new(&[1.5]).unwrap();
    stitcher.add(&all, &ids).unwrap();
    assert!(stitcher.add(&all, &ids).is_err());
}
