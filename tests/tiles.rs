//! `tinsmith tiles`: every tile of small pyramids decoded by an independent decoder (npm
//! `@here/quantized-mesh-decoder`, `make oracles`), checked against the spec, against its
//! neighbours, and at the finest level against GDAL's own warp of the tile's lattice.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

use crate::util::{assert_fails_naming, fixture, stderr, Dir};

/// The cells a side of a tile's lattice tinsmith may choose (both divide 32767).
const LATTICE_CELLS: [i64; 2] = [217, 151];
const E0: f64 = 77_067.34;

#[derive(Clone)]
pub(crate) struct Tile {
    pub(crate) u: Vec<i64>,
    pub(crate) v: Vec<i64>,
    /// Decoded heights.
    pub(crate) h: Vec<f64>,
    /// The header's minimum and maximum heights.
    header: (f64, f64),
    pub(crate) triangles: Vec<[usize; 3]>,
    pub(crate) edges: [Vec<usize>; 4],
    normals: Option<Vec<u64>>,
    /// The water mask extension's bytes, as decoded.
    pub(crate) water_mask: Option<Vec<u64>>,
    metadata: Value,
    /// `u` (and `v`) per lattice step of the pyramid's tiles: 32767 over the lattice's
    /// cells a side, inferred from every decoded vertex of the pyramid.
    pub(crate) u_step: i64,
}

impl Tile {
    /// Cells a side of the tile's lattice.
    pub(crate) fn cells(&self) -> i64 {
        32767 / self.u_step
    }
}

fn gcd(a: i64, b: i64) -> i64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

fn numbers(v: &Value) -> Vec<i64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_i64().unwrap())
        .collect()
}

/// Every `z/x/y.terrain` under `dir`, decoded by the oracle.
pub(crate) fn decode_pyramid(dir: &Path) -> BTreeMap<(u32, u32, u32), Tile> {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    assert!(
        repo.join(".tools/node_modules/@here/quantized-mesh-decoder/package.json")
            .exists(),
        "the quantized-mesh oracle is missing: run `make oracles` (needs node and npm)"
    );
    let mut files: Vec<(PathBuf, (u32, u32, u32))> = Vec::new();
    for z in std::fs::read_dir(dir).unwrap() {
        let z = z.unwrap().path();
        // Levels only (not the records in tinsmith/).
        let level = z.file_name().unwrap().to_str().unwrap().parse::<u32>();
        if !z.is_dir() || level.is_err() {
            continue;
        }
        for x in std::fs::read_dir(&z).unwrap() {
            let x = x.unwrap().path();
            for y in std::fs::read_dir(&x).unwrap() {
                let y = y.unwrap().path();
                let name =
                    |p: &Path| -> u32 { p.file_stem().unwrap().to_str().unwrap().parse().unwrap() };
                files.push((y.clone(), (name(&z), name(&x), name(&y))));
            }
        }
    }
    let out = Command::new("node")
        .arg(repo.join("tests/oracle/qm_decode.cjs"))
        .args(files.iter().map(|f| &f.0))
        .output()
        .expect("node runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut tiles = BTreeMap::new();
    for (line, (_, key)) in text.lines().zip(&files) {
        let t: Value = serde_json::from_str(line).unwrap();
        assert_eq!(t["gzipped"], true);
        let (min, max) = (
            t["header"]["minHeight"].as_f64().unwrap(),
            t["header"]["maxHeight"].as_f64().unwrap(),
        );
        let h = numbers(&t["h"])
            .iter()
            .map(|&q| min + q as f64 / 32767.0 * (max - min))
            .collect();
        let idx = numbers(&t["triangles"]);
        let tile = Tile {
            u: numbers(&t["u"]),
            v: numbers(&t["v"]),
            h,
            header: (min, max),
            triangles: idx
                .chunks(3)
                .map(|c| [c[0] as usize, c[1] as usize, c[2] as usize])
                .collect(),
            edges: ["west", "south", "east", "north"]
                .map(|k| numbers(&t[k]).iter().map(|&i| i as usize).collect()),
            normals: t["normals"]
                .as_array()
                .map(|a| a.iter().map(|x| x.as_u64().unwrap()).collect()),
            water_mask: t["waterMask"]
                .as_array()
                .map(|a| a.iter().map(|x| x.as_u64().unwrap()).collect()),
            metadata: t["metadata"].clone(),
            u_step: 0,
        };
        tiles.insert(*key, tile);
    }
    assert_eq!(tiles.len(), files.len());
    // The lattice: the largest step every vertex of the pyramid lies on, which must be
    // one of the lattices tinsmith may choose.
    let u_step = tiles
        .values()
        .flat_map(|t| t.u.iter().chain(&t.v))
        .fold(0, |g, &q| gcd(g, q));
    assert!(
        LATTICE_CELLS.iter().any(|&cells| 32767 == u_step * cells),
        "vertices on a lattice of step {u_step}, not on one of {LATTICE_CELLS:?} cells"
    );
    for t in tiles.values_mut() {
        t.u_step = u_step;
    }
    tiles
}

/// Spec checks on one tile: ranges, counter-clockwise triangles, vertices on the tile's
/// sample lattice, edge lists = border vertices.
pub(crate) fn check_tile(key: (u32, u32, u32), t: &Tile) {
    let n = t.u.len();
    assert!(n >= 3 && !t.triangles.is_empty(), "{key:?} is empty");
    for i in 0..n {
        for q in [t.u[i], t.v[i]] {
            assert!((0..=32767).contains(&q), "{key:?}");
            assert_eq!(q % t.u_step, 0, "{key:?}: vertex off the sample lattice");
        }
    }
    for tri in &t.triangles {
        let [a, b, c] = *tri;
        assert!(a < n && b < n && c < n);
        let orient = (t.u[b] - t.u[a]) * (t.v[c] - t.v[a]) - (t.v[b] - t.v[a]) * (t.u[c] - t.u[a]);
        assert!(
            orient > 0,
            "{key:?}: triangle {tri:?} is not counter-clockwise"
        );
    }
    let border = |f: &dyn Fn(usize) -> bool| -> Vec<usize> { (0..n).filter(|&i| f(i)).collect() };
    let want = [
        border(&|i| t.u[i] == 0),
        border(&|i| t.v[i] == 0),
        border(&|i| t.u[i] == 32767),
        border(&|i| t.v[i] == 32767),
    ];
    for (k, list) in t.edges.iter().enumerate() {
        let mut got = list.clone();
        got.sort();
        assert_eq!(got, want[k], "{key:?}: edge list {k}");
    }
}

/// The vertices along one edge of a tile as (position along the edge, decoded height).
fn edge(t: &Tile, side: usize) -> Vec<(i64, f64)> {
    let mut e: Vec<(i64, f64)> = t.edges[side]
        .iter()
        .map(|&i| {
            (
                if side.is_multiple_of(2) {
                    t.v[i]
                } else {
                    t.u[i]
                },
                t.h[i],
            )
        })
        .collect();
    e.sort_by_key(|p| p.0);
    e
}

/// The segments of one edge that triangles cover: pairs of positions along the edge.
fn edge_segments(t: &Tile, side: usize) -> Vec<(i64, i64)> {
    let on: std::collections::BTreeSet<usize> = t.edges[side].iter().copied().collect();
    let pos = |i: usize| {
        if side.is_multiple_of(2) {
            t.v[i]
        } else {
            t.u[i]
        }
    };
    let mut segments = Vec::new();
    for tri in &t.triangles {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            if on.contains(&a) && on.contains(&b) {
                segments.push((pos(a).min(pos(b)), pos(a).max(pos(b))));
            }
        }
    }
    segments.sort();
    segments
}

/// Same-level neighbours share their edge: where both have an edge vertex, positions and
/// heights agree; where their triangles both reach the edge, they end at the same
/// vertices (no T-junction: no vertex of one inside a border segment of the other). A
/// vertex only one side has lies where the other has no data.
pub(crate) fn check_shared_edges(tiles: &BTreeMap<(u32, u32, u32), Tile>) -> usize {
    let mut shared = 0;
    for (&(z, x, y), t) in tiles {
        for (dx, dy, mine, theirs) in [(1, 0, 2, 0), (0, 1, 3, 1)] {
            let Some(other) = tiles.get(&(z, x + dx, y + dy)) else {
                continue;
            };
            let (a, b) = (edge(t, mine), edge(other, theirs));
            let b_at: BTreeMap<i64, f64> = b.iter().copied().collect();
            for (p, h) in &a {
                if let Some(hb) = b_at.get(p) {
                    assert!(
                        (h - hb).abs() < 1e-6,
                        "{z}/{x}/{y}: edge heights {h} vs {hb}"
                    );
                    shared += 1;
                }
            }
            for (one, other_edge) in [
                (&a, edge_segments(other, theirs)),
                (&b, edge_segments(t, mine)),
            ] {
                for (p, _) in one.iter() {
                    assert!(
                        !other_edge.iter().any(|&(s, e)| s < *p && *p < e),
                        "{z}/{x}/{y}: T-junction at {p} on its edge with the neighbour"
                    );
                }
            }
        }
    }
    shared
}

/// The largest |decoded mesh - sample| over the tile's lattice (`samples[j][i]`, row 0
/// the southernmost, NaN = nodata) and whether every valid sample of a valid cell is
/// covered.
pub(crate) fn max_error(t: &Tile, samples: &[Vec<f64>]) -> f64 {
    let mut err: BTreeMap<(i64, i64), f64> = BTreeMap::new();
    for tri in &t.triangles {
        let p = tri.map(|k| (t.u[k], t.v[k], t.h[k]));
        let det =
            ((p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[1].1 - p[0].1) * (p[2].0 - p[0].0)) as f64;
        let step = t.u_step;
        let lo_i = p.iter().map(|q| q.0).min().unwrap() / step;
        let hi_i = p.iter().map(|q| q.0).max().unwrap() / step;
        let lo_j = p.iter().map(|q| q.1).min().unwrap() / step;
        let hi_j = p.iter().map(|q| q.1).max().unwrap() / step;
        for j in lo_j..=hi_j {
            for i in lo_i..=hi_i {
                let (u, v) = (i * step, j * step);
                let w = |a: (i64, i64, f64), b: (i64, i64, f64)| {
                    ((b.0 - a.0) * (v - a.1) - (b.1 - a.1) * (u - a.0)) as f64
                };
                let (w0, w1, w2) = (w(p[1], p[2]), w(p[2], p[0]), w(p[0], p[1]));
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let z = (w0 * p[0].2 + w1 * p[1].2 + w2 * p[2].2) / det;
                let s = samples[j as usize][i as usize];
                if s.is_finite() {
                    err.insert((i, j), (z - s).abs());
                }
            }
        }
    }
    err.values().fold(0.0, |m, &e| m.max(e))
}

/// How a pyramid's tiles divide the globe (`--tiling`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Tiling {
    Geographic,
    Mercator,
}

impl Tiling {
    /// The `--tiling` value.
    pub(crate) fn arg(self) -> &'static str {
        match self {
            Tiling::Geographic => "geographic",
            Tiling::Mercator => "mercator",
        }
    }

    /// Tile `z/x/y` (TMS y) as `[west, south, east, north]` degrees. A Web Mercator tile
    /// is square in EPSG:3857 (spherical: y = ln tan(pi/4 + lat/2)); its southern and
    /// northern edges are the latitudes of its y edges.
    pub(crate) fn rectangle(self, z: u32, x: u32, y: u32) -> [f64; 4] {
        let n = (1u64 << z) as f64;
        match self {
            Tiling::Geographic => {
                let size = 180.0 / n;
                let (west, south) = (-180.0 + x as f64 * size, -90.0 + y as f64 * size);
                [west, south, west + size, south + size]
            }
            Tiling::Mercator => {
                let lat = |k: f64| {
                    let y = std::f64::consts::PI * (2.0 * k / n - 1.0);
                    y.sinh().atan().to_degrees()
                };
                let size = 360.0 / n;
                let west = -180.0 + x as f64 * size;
                [west, lat(y as f64), west + size, lat(y as f64 + 1.0)]
            }
        }
    }

    /// Cesium's geometric error of level `z`: its level-0 error divides by the root
    /// tiles' columns (2 geographic, 1 Web Mercator).
    pub(crate) fn level_error(self, z: u32) -> f64 {
        let e0 = match self {
            Tiling::Geographic => E0,
            Tiling::Mercator => 2.0 * E0,
        };
        e0 / (1u64 << z) as f64
    }
}

/// The geographic tile's lattice of `cells` cells a side warped by the gdalwarp program
/// (bilinear), row 0 the southernmost.
pub(crate) fn gdal_samples(
    dir: &Dir,
    input: &str,
    cells: i64,
    z: u32,
    x: u32,
    y: u32,
) -> Vec<Vec<f64>> {
    tiled_gdal_samples(dir, input, Tiling::Geographic, cells, z, x, y)
}

/// The lattice of tile `z/x/y` of `tiling` (`cells + 1` points a side evenly spaced in
/// longitude and in latitude across the tile's rectangle, as CesiumJS places `u` and `v`)
/// warped by the gdalwarp program (bilinear), row 0 the southernmost.
pub(crate) fn tiled_gdal_samples(
    dir: &Dir,
    input: &str,
    tiling: Tiling,
    cells: i64,
    z: u32,
    x: u32,
    y: u32,
) -> Vec<Vec<f64>> {
    warped_samples(dir, &[input], &[], (tiling, cells), z, x, y)
}

/// As [`tiled_gdal_samples`], of several `inputs` warped in turn into the one lattice:
/// each input's valid samples over those of the inputs before it (the last wins). The
/// bilinear kernel is not widened where the lattice is coarser than an input (`-wo
/// XSCALE=1`): each point interpolated between the four pixel centres around it, as
/// tinsmith samples the levels from the base's own down.
pub(crate) fn stacked_gdal_samples(
    dir: &Dir,
    inputs: &[&str],
    tiling: Tiling,
    cells: i64,
    z: u32,
    x: u32,
    y: u32,
) -> Vec<Vec<f64>> {
    let point = ["-wo", "XSCALE=1", "-wo", "YSCALE=1"];
    warped_samples(dir, inputs, &point, (tiling, cells), z, x, y)
}

/// `inputs` warped by gdalwarp (bilinear, with `extra` options) into the lattice of tile
/// `z/x/y` of `cells` cells a side, row 0 the southernmost.
fn warped_samples(
    dir: &Dir,
    inputs: &[&str],
    extra: &[&str],
    (tiling, cells): (Tiling, i64),
    z: u32,
    x: u32,
    y: u32,
) -> Vec<Vec<f64>> {
    let [west, south, east, north] = tiling.rectangle(z, x, y);
    let (dx, dy) = ((east - west) / cells as f64, (north - south) / cells as f64);
    let out = dir.path(&format!("warp_{}_{z}_{x}_{y}.asc", tiling.arg()));
    let status = Command::new("gdalwarp")
        .args([
            "-q",
            "-overwrite",
            "-et",
            "0",
            "-t_srs",
            "EPSG:4326",
            "-r",
            "bilinear",
            "-ot",
            "Float64",
        ])
        .args(["-of", "AAIGrid", "-dstnodata", "-99999", "-te"])
        .args(
            [
                west - dx / 2.0,
                south - dy / 2.0,
                east + dx / 2.0,
                north + dy / 2.0,
            ]
            .map(|v| format!("{v:.17}")),
        )
        .args(["-ts", &(cells + 1).to_string(), &(cells + 1).to_string()])
        .args(extra)
        .args(inputs)
        .arg(&out)
        .status()
        .expect("gdalwarp runs");
    assert!(status.success());
    let text = std::fs::read_to_string(&out).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip_while(|l| {
            l.split_whitespace()
                .next()
                .is_some_and(|w| w.chars().next().unwrap().is_alphabetic())
        })
        .map(|l| {
            l.split_whitespace()
                .map(|w| {
                    let v: f64 = w.parse().unwrap();
                    if v == -99999.0 {
                        f64::NAN
                    } else {
                        v
                    }
                })
                .collect()
        })
        .collect();
    assert_eq!(rows.len() as i64, cells + 1);
    rows.into_iter().rev().collect()
}

fn pyramid(dir: &Dir, input: &str, out: &str, extra: &[&str]) {
    let mut args = vec!["tiles", input, "-o", out];
    args.extend_from_slice(extra);
    let o = dir.run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// `DIR/layer.json` of a pyramid, and its `bounds` as numbers.
pub(crate) fn layer_json(root: &Path) -> (Value, Vec<f64>) {
    let layer: Value =
        serde_json::from_slice(&std::fs::read(root.join("layer.json")).unwrap()).unwrap();
    let bounds = layer["bounds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    (layer, bounds)
}

/// Every directory under `root`, relative to it.
fn all_directories(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(p) = stack.pop() {
        for e in std::fs::read_dir(&p).unwrap() {
            let e = e.unwrap().path();
            if e.is_dir() {
                out.push(e.strip_prefix(root).unwrap().to_path_buf());
                stack.push(e);
            }
        }
    }
    out.sort();
    out
}

#[test]
fn an_update_that_drops_tiles_leaves_the_tree_of_a_fresh_build() {
    // The DEM, then its western third alone: the update removes the tiles east of it,
    // and with a column's or a level's last tile its directory, as a fresh build has none.
    let dir = Dir::new();
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    let west = dir.path("west.tif");
    let status = Command::new("gdal_translate")
        .args(["-q", "-srcwin", "0", "0", "140", "516"])
        .arg(&input)
        .arg(&west)
        .status()
        .expect("gdal_translate runs");
    assert!(status.success());
    let west = west.to_string_lossy().into_owned();
    pyramid(&dir, &input, "p", &["-q"]);
    let before = all_directories(&dir.path("p"));
    pyramid(&dir, &west, "p", &["-q", "--update"]);
    pyramid(&dir, &west, "fresh", &["-q"]);
    let after = all_directories(&dir.path("p"));
    assert!(
        after.len() < before.len(),
        "the update removed no directory"
    );
    assert_eq!(after, all_directories(&dir.path("fresh")));
    assert_eq!(all_files(&dir.path("p")), all_files(&dir.path("fresh")));
}

pub(crate) fn all_files(root: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(p) = stack.pop() {
        for e in std::fs::read_dir(&p).unwrap() {
            let e = e.unwrap().path();
            if e.is_dir() {
                stack.push(e);
            } else {
                out.insert(
                    e.strip_prefix(root).unwrap().to_path_buf(),
                    std::fs::read(&e).unwrap(),
                );
            }
        }
    }
    out
}

/// Checks the pyramid of `input` at `quality`; `flat_roots` root tiles have no data.
fn check_pyramid(input: &str, quality: f64, flat_roots: usize) {
    check_tiled_pyramid(input, quality, flat_roots, Tiling::Geographic);
}

/// Checks the pyramid of `input` at `quality` with `tiling`; `flat_roots` root tiles have
/// no data.
fn check_tiled_pyramid(input: &str, quality: f64, flat_roots: usize, tiling: Tiling) {
    let dir = Dir::new();
    let q = quality.to_string();
    let report = dir.path("one.json").to_string_lossy().into_owned();
    let common = [
        "--quality",
        &q,
        "--normals",
        "--metadata",
        "--tiling",
        tiling.arg(),
    ];
    let with = |extra: &[&'static str]| [&common[..], extra].concat();
    pyramid(
        &dir,
        input,
        "one",
        &[
            &with(&["--threads", "1", "--report"])[..],
            &[report.as_str()],
        ]
        .concat(),
    );
    pyramid(&dir, input, "two", &with(&["--threads", "2"]));
    let (one, two) = (all_files(&dir.path("one")), all_files(&dir.path("two")));
    assert!(one == two, "1 and 2 threads wrote different bytes");
    #[cfg(unix)]
    {
        // A web server running as another user must read them: the umask decides, as
        // for `File::create`, not tempfile's private 0600.
        use std::os::unix::fs::PermissionsExt;
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        let reference = dir.path("reference");
        std::fs::File::create(&reference).unwrap();
        for file in one.keys() {
            assert_eq!(
                mode(&dir.path("one").join(file)),
                mode(&reference),
                "{file:?}"
            );
        }
    }

    let layer: Value = serde_json::from_slice(&one[Path::new("layer.json")]).unwrap();
    assert_eq!(layer["format"], "quantized-mesh-1.0");
    assert_eq!(layer["scheme"], "tms");
    let projection = match tiling {
        Tiling::Geographic => "EPSG:4326",
        Tiling::Mercator => "EPSG:3857",
    };
    assert_eq!(layer["projection"], projection);
    assert_eq!(layer["metadataAvailability"], 10);
    let max_zoom = layer["maxzoom"].as_u64().unwrap() as u32;

    let tiles = decode_pyramid(&dir.path("one"));
    // Availability lists exactly the tiles written.
    let available = layer["available"].as_array().unwrap();
    let mut listed = 0;
    for (z, rects) in available.iter().enumerate() {
        for r in rects.as_array().unwrap() {
            let c = |k: &str| r[k].as_u64().unwrap() as u32;
            for x in c("startX")..=c("endX") {
                for y in c("startY")..=c("endY") {
                    assert!(
                        tiles.contains_key(&(z as u32, x, y)),
                        "{z}/{x}/{y} listed, missing"
                    );
                    listed += 1;
                }
            }
        }
    }
    assert_eq!(listed, tiles.len());

    // Both root tiles are written (the whole globe; CesiumJS requests both with
    // metadataAvailability too): one the raster does not reach is flat at height 0, with
    // no tile below it.
    let roots: &[(u32, u32, u32)] = match tiling {
        Tiling::Geographic => &[(0, 0, 0), (0, 1, 0)],
        Tiling::Mercator => &[(0, 0, 0)],
    };
    let empty: Vec<_> = roots
        .iter()
        .copied()
        .filter(|&(_, x, _)| !tiles.keys().any(|&(z, cx, _)| z == 1 && cx / 2 == x))
        .collect();
    assert_eq!(
        empty.len(),
        flat_roots,
        "root tiles the raster does not reach"
    );
    for key in empty {
        let t = tiles
            .get(&key)
            .unwrap_or_else(|| panic!("{key:?} is missing"));
        assert!(t.h.iter().all(|&h| h == 0.0), "{key:?} is not flat");
        let below = &t.metadata["available"];
        assert!(
            below
                .as_array()
                .unwrap()
                .iter()
                .all(|level| level.as_array().unwrap().is_empty()),
            "a root without data lists tiles below it: {below}"
        );
    }
    for (&key, t) in &tiles {
        check_tile(key, t);
        assert_eq!(t.normals.as_ref().map(|n| n.len()), Some(2 * t.u.len()));
        if key.0.is_multiple_of(10) {
            assert!(t.metadata["available"].is_array(), "{key:?}: no metadata");
        } else {
            assert!(t.metadata.is_null());
        }
    }
    assert!(check_shared_edges(&tiles) > 0, "no shared edges tested");

    // The header's height range bounds the tile's heights (the spec), and CesiumJS builds
    // the tile's bounding box from it: within twice the tile's own relief plus a height
    // step, unless float32 could not hold a finer division of the 16-bit range exactly.
    // It used to be 32767 steps whatever the relief, steps the level's widest tile sets.
    let report: Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    let step_of = |z: u32| {
        report["levels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|l| l["level"] == z)
            .and_then(|l| l["height_step"].as_f64())
            .expect("level in the report")
    };
    let mut tight = 0;
    for (&key, t) in &tiles {
        let (min, max) = t.header;
        let s = step_of(key.0);
        let relief = t.h.iter().fold(f64::NEG_INFINITY, |m, &h| m.max(h)) - min;
        assert!(max - min >= relief - 1e-9, "{key:?}: header below a vertex");
        let quanta = 32767.0 * s / (max - min);
        assert!(
            (quanta - quanta.round()).abs() < 1e-6 && (quanta.round() as u32).is_power_of_two(),
            "{key:?}: {quanta} quanta a step"
        );
        let finer_is_inexact = 2.0 * quanta * (min / s).abs() + 32767.0 >= 16_777_216.0;
        if max - min <= 2.0 * relief + 2.0 * s {
            tight += 1;
        } else {
            assert!(
                quanta.round() == 16384.0 || finer_is_inexact,
                "{key:?}: header range {} for relief {relief} (step {s})",
                max - min
            );
        }
    }
    assert!(tight > 0);

    // The finest level against GDAL's own warp of each tile's lattice.
    let mut checked = 0;
    for (&(z, x, y), t) in tiles.range((max_zoom, 0, 0)..) {
        let bound = quality * tiling.level_error(z);
        let samples = tiled_gdal_samples(&dir, input, tiling, t.cells(), z, x, y);
        let e = max_error(t, &samples);
        assert!(e <= bound + 1e-3, "{z}/{x}/{y}: error {e} above {bound}");
        checked += 1;
    }
    assert!(checked > 0);
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_mercator_pyramid_decodes_stitches_and_keeps_its_bound() {
    check_pyramid(&fixture("tintn_valid_raster_3857.tif"), 1.0, 1);
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn an_albers_pyramid_decodes_stitches_and_keeps_its_bound() {
    check_pyramid(&fixture("becmodel_dem_bc_albers_50m.tif"), 0.5, 1);
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn web_mercator_pyramids_decode_stitch_and_keep_their_bound() {
    // At 49°N a Web Mercator tile's latitude middle is well south of its Web Mercator
    // middle, where it splits; the lattice stays even in latitude inside each tile.
    check_tiled_pyramid(
        &fixture("becmodel_dem_bc_albers_50m.tif"),
        0.5,
        0,
        Tiling::Mercator,
    );
    check_tiled_pyramid(
        &fixture("tintn_valid_raster_3857.tif"),
        1.0,
        0,
        Tiling::Mercator,
    );
}

/// Great-circle angle, in radians, between two decoded vertices of tile `z/x/y`.
fn arc(key: (u32, u32, u32), t: &Tile, a: usize, b: usize) -> f64 {
    let (z, x, y) = key;
    let size = 180.0 / f64::from(1u32 << z);
    let lon_lat = |i: usize| {
        let lon = -180.0 + size * (f64::from(x) + t.u[i] as f64 / 32767.0);
        let lat = -90.0 + size * (f64::from(y) + t.v[i] as f64 / 32767.0);
        (lon.to_radians(), lat.to_radians())
    };
    let ((l1, p1), (l2, p2)) = (lon_lat(a), lon_lat(b));
    let h = ((p2 - p1) / 2.0).sin().powi(2) + p1.cos() * p2.cos() * ((l2 - l1) / 2.0).sin().powi(2);
    2.0 * h.sqrt().min(1.0).asin()
}

/// Every triangle of geographic tile `key` faces outwards as drawn (flat between its
/// corners on the globe): none turned over. Corners at one point (a pole) have no face.
fn assert_faces_out(key: (u32, u32, u32), t: &Tile) {
    let size = 180.0 / f64::from(1u32 << key.0);
    let unit = |i: usize| {
        let lon = (-180.0 + size * (f64::from(key.1) + t.u[i] as f64 / 32767.0)).to_radians();
        let lat = (-90.0 + size * (f64::from(key.2) + t.v[i] as f64 / 32767.0)).to_radians();
        [lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin()]
    };
    for tri in &t.triangles {
        let [a, b, c] = tri.map(unit);
        let cross = [
            b[1] * c[2] - b[2] * c[1],
            b[2] * c[0] - b[0] * c[2],
            b[0] * c[1] - b[1] * c[0],
        ];
        let triple = a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2];
        assert!(
            triple > -1e-12,
            "{key:?}: triangle {tri:?} is turned over ({triple:e})"
        );
    }
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn no_triangle_turns_over_on_levels_without_an_edge_cap() {
    // Svalbard at 5', the sea at 0 m: flat sea lets a level-8 tile keep a sliver of
    // doubled lattice area 1 under a 40-sample edge, which at 78 degrees north turned
    // over as drawn (the edge's chord bulges poleward past the third corner) while the
    // grid saw it counter-clockwise. Levels past the edge cap are checked on the globe too.
    let dir = Dir::new();
    let input = fixture("svalbard_5min_sea0_i16.tif");
    pyramid(&dir, &input, "p", &["--max-zoom", "9", "-q"]);
    let tiles = decode_pyramid(&dir.path("p"));
    assert!(tiles.keys().any(|k| k.0 == 9), "level 9 is built");
    for (&key, t) in &tiles {
        check_tile(key, t);
        assert_faces_out(key, t);
    }
    assert!(check_shared_edges(&tiles) > 0);
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_global_pyramid_bends_with_the_globe() {
    // A whole globe at 2 degrees: at levels 0 and 1 a bound of tens of kilometres lets a
    // tile go nearly flat, but CesiumJS draws triangles as chords between ECEF corners,
    // so no edge may span an arc whose chord sinks deeper than the level's bound.
    let dir = Dir::new();
    let input = fixture("etopo5_2deg_i16.tif");
    pyramid(&dir, &input, "globe", &["--max-zoom", "1", "-q"]);
    let tiles = decode_pyramid(&dir.path("globe"));
    assert_eq!(tiles.len(), 2 + 8, "every tile of levels 0 and 1 has data");
    const RADIUS: f64 = 6_378_137.0;
    for (&key, t) in &tiles {
        check_tile(key, t);
        let bound = E0 / f64::from(1u32 << key.0);
        let longest = t
            .triangles
            .iter()
            .flat_map(|tri| (0..3).map(move |k| (tri[k], tri[(k + 1) % 3])))
            .map(|(a, b)| arc(key, t, a, b))
            .fold(0.0f64, f64::max);
        let sag = RADIUS * (1.0 - (longest / 2.0).cos());
        assert!(
            sag <= bound,
            "{key:?}: an edge of {:.1} degrees sinks {sag:.0} m below the ellipsoid (bound {bound:.0} m)",
            longest.to_degrees()
        );
        assert_faces_out(key, t);
        // Edges of at most ~17 degrees across a 180-degree tile need many vertices.
        if key.0 == 0 {
            assert!(t.u.len() >= 100, "{key:?}: only {} vertices", t.u.len());
        }
    }
    assert!(check_shared_edges(&tiles) > 0);
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_pyramid_across_the_antimeridian_wraps_its_columns() {
    // A UTM zone 60 raster whose east part lies past 180 degrees: its tiles are the last
    // columns and the first ones, stitched across the antimeridian. (Its extent used to
    // come out as west > east, and the lattice over it as petabytes.)
    let dir = Dir::new();
    let input = dir.path("utm60.tif");
    let status = Command::new("gdal_translate")
        .args(["-q", "-a_srs", "EPSG:32760", "-a_ullr"])
        .args(["805000", "8000000", "817900", "7984520"])
        .arg(fixture("becmodel_dem_bc_albers_50m.tif"))
        .arg(&input)
        .status()
        .expect("gdal_translate runs");
    assert!(status.success());
    let input = input.to_string_lossy().into_owned();
    // Both sides of 180 degrees: both root tiles have data.
    check_pyramid(&input, 1.0, 0);

    let dir = Dir::new();
    pyramid(&dir, &input, "p", &["-q"]);
    let (layer, bounds) = layer_json(&dir.path("p"));
    assert!(bounds[0] > 179.0 && bounds[2] < -179.0, "bounds {bounds:?}");
    let tiles = decode_pyramid(&dir.path("p"));
    let max_zoom = layer["maxzoom"].as_u64().unwrap() as u32;
    let last = (2u32 << max_zoom) - 1;
    let mut seams = 0;
    for (&(z, x, y), t) in tiles.range((max_zoom, 0, 0)..) {
        assert!(
            x <= 4 || x >= last - 4,
            "{z}/{x}/{y} is far from 180 degrees"
        );
        if x != last {
            continue;
        }
        // The east edge of the last column is the west edge of column 0.
        let Some(other) = tiles.get(&(z, 0, y)) else {
            continue;
        };
        let (a, b) = (edge(t, 2), edge(other, 0));
        let b_at: BTreeMap<i64, f64> = b.iter().copied().collect();
        for (p, h) in &a {
            let hb = b_at
                .get(p)
                .unwrap_or_else(|| panic!("{z}/{x}/{y}: no vertex at {p} across 180"));
            assert!(
                (h - hb).abs() < 1e-6,
                "{z}/{x}/{y}: heights {h} vs {hb} across 180"
            );
            seams += 1;
        }
        assert_eq!(a.len(), b.len(), "{z}/{x}/{y}: edges differ across 180");
    }
    assert!(seams > 0, "no tile pair across 180 degrees");
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn normals_agree_across_the_antimeridian() {
    // Flat ground from 179 to 181 degrees: every normal points up, and its east
    // component, 0 up to rounding, used to round to either side of the oct encoding's 0
    // on the two sides of 180 degrees (+180 and -180 of one point).
    let dir = Dir::new();
    let input = dir.path("flat.tif");
    let status = Command::new("gdal_create")
        .args([
            "-q", "-outsize", "40", "40", "-bands", "1", "-burn", "5", "-ot", "Int16",
        ])
        .args(["-a_srs", "EPSG:4326", "-a_ullr", "179", "1", "181", "-1"])
        .arg(&input)
        .status()
        .expect("gdal_create runs");
    assert!(status.success());
    let input = input.to_string_lossy().into_owned();
    pyramid(&dir, &input, "p", &["-q", "--normals", "--max-zoom", "6"]);
    let tiles = decode_pyramid(&dir.path("p"));
    let mut seams = 0;
    for (&(z, x, y), t) in &tiles {
        if x != (2u32 << z) - 1 {
            continue;
        }
        let other = &tiles[&(z, 0, y)];
        let normals = |t: &Tile, side: usize| -> BTreeMap<i64, (u64, u64)> {
            let n = t.normals.as_ref().expect("normals");
            t.edges[side]
                .iter()
                .map(|&i| (t.v[i], (n[2 * i], n[2 * i + 1])))
                .collect()
        };
        let (east, west) = (normals(t, 2), normals(other, 0));
        assert_eq!(east, west, "{z}/{x}/{y}: normals differ across 180 degrees");
        seams += east.len();
    }
    assert!(seams > 0, "no tile pair across 180 degrees");
}

/// The share of the tile's square its triangles cover.
fn covered(t: &Tile) -> f64 {
    let doubled: i64 = t
        .triangles
        .iter()
        .map(|&[a, b, c]| {
            (t.u[b] - t.u[a]) * (t.v[c] - t.v[a]) - (t.v[b] - t.v[a]) * (t.u[c] - t.u[a])
        })
        .sum();
    doubled as f64 / 2.0 / (32767.0 * 32767.0)
}

/// `input` relabelled as EPSG:4326 over `[west, north, east, south]` (`gdal_translate
/// -a_ullr`).
pub(crate) fn relabelled(dir: &Dir, input: &str, name: &str, ullr: [&str; 4]) -> String {
    let out = dir.path(name);
    let status = Command::new("gdal_translate")
        .args(["-q", "-a_srs", "EPSG:4326", "-a_ullr"])
        .args(ullr)
        .arg(fixture(input))
        .arg(&out)
        .status()
        .expect("gdal_translate runs");
    assert!(status.success());
    out.to_string_lossy().into_owned()
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_pyramid_wider_than_half_the_globe_keeps_its_data_at_every_level() {
    // A raster over longitudes -10..300: at levels 0 and 1 its tiles go all the way round,
    // and the coarse tile west of 0 degrees holds both its own part and the part past 180.
    // (Each level used to stop at a full turn from its first tile, so level 0 lost the
    // part past 180 that level 1 had: 0/0/0 covered 13 % of its square, not 40 %.)
    let dir = Dir::new();
    let input = relabelled(
        &dir,
        "becmodel_dem_bc_albers_50m.tif",
        "wide.tif",
        ["-10", "50", "300", "-50"],
    );
    pyramid(&dir, &input, "p", &["--max-zoom", "2", "-q"]);
    let tiles = decode_pyramid(&dir.path("p"));
    // The tiles west of 0 degrees hold the raster's own first columns (-10..0) as well as
    // its part past 180 (a block meeting the domain on both sides of its gap used to build
    // only the second): their data reaches their east edge.
    for key in [(0, 0, 0), (1, 1, 0), (1, 1, 1), (2, 3, 1), (2, 3, 2)] {
        let t = tiles
            .get(&key)
            .unwrap_or_else(|| panic!("{key:?} is missing"));
        assert!(
            !t.edges[2].is_empty(),
            "{key:?} has no vertex on its east edge (0 degrees)"
        );
    }
    for (&(z, x, y), t) in tiles.range(..(2, 0, 0)) {
        check_tile((z, x, y), t);
        let children: f64 = [(0, 0), (1, 0), (0, 1), (1, 1)]
            .iter()
            .filter_map(|(dx, dy)| tiles.get(&(z + 1, 2 * x + dx, 2 * y + dy)))
            .map(covered)
            .sum();
        assert!(
            covered(t) >= 0.98 * children / 4.0,
            "{z}/{x}/{y} covers {:.3} of its square, its children {:.3}",
            covered(t),
            children / 4.0
        );
    }
    assert!(check_shared_edges(&tiles) > 0);
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_whole_turn_of_longitudes_is_a_globe_stitched_across_180_at_every_level() {
    // A global grid in 0..360 longitudes whose extent comes out a rounding error short of
    // 360 degrees (as ETOPO5's does): still the whole globe. Every tile is covered, and at
    // every level the last column's east edge is the first column's west edge, vertex for
    // vertex and height for height. (It used to be taken for a raster across the
    // antimeridian just short of a turn: root tile 0/0/0 covered a sliver, and the coarse
    // levels did not filter across 180 degrees, so the seam's heights differed.) Level 3
    // is built in blocks whose windows lie west of 0 degrees too: GDAL's warper, given
    // such a window of a 0..360 raster, left it empty (102 of the 170 tiles were written).
    let dir = Dir::new();
    let input = relabelled(
        &dir,
        "etopo5_2deg_i16.tif",
        "globe360.tif",
        ["-1", "90", "358.99999999999", "-90"],
    );
    pyramid(&dir, &input, "p", &["--max-zoom", "3", "-q"]);
    let tiles = decode_pyramid(&dir.path("p"));
    assert_eq!(tiles.len(), 2 + 8 + 32 + 128, "every tile of levels 0 to 3");
    let mut seams = 0;
    for (&(z, x, y), t) in &tiles {
        check_tile((z, x, y), t);
        assert!(covered(t) > 0.95, "{z}/{x}/{y} covers {:.3}", covered(t));
        if x + 1 != 2 << z {
            continue;
        }
        let first = &tiles[&(z, 0, y)];
        assert_eq!(
            edge(t, 2),
            edge(first, 0),
            "{z}/{x}/{y}: the seam at 180 degrees"
        );
        seams += 1;
    }
    assert_eq!(seams, 1 + 2 + 4 + 8);
    assert!(check_shared_edges(&tiles) > 0);
}

/// The `.terrain` files of a pyramid (not `layer.json`, which names its input).
fn terrain_files(root: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = all_files(root);
    files.retain(|p, _| p.extension().is_some_and(|e| e == "terrain"));
    assert!(!files.is_empty(), "no tiles under {}", root.display());
    files
}

/// A VRT over the 2-degree globe (EPSG:4326), with the given bands' XML.
fn globe_vrt(dir: &Dir, name: &str, bands: &str) -> String {
    let xml = format!(
        "<VRTDataset rasterXSize=\"180\" rasterYSize=\"90\"><SRS>EPSG:4326</SRS>\
         <GeoTransform>-180,2,0,90,0,-2</GeoTransform>{bands}</VRTDataset>"
    );
    dir.write(name, &xml).to_string_lossy().into_owned()
}

/// A VRT band `n` of type `kind` reading the 2-degree globe through `source_extra` (a
/// `ComplexSource`'s scaling or lookup table), with `extra` before the source.
fn globe_band(n: u32, kind: &str, extra: &str, source_extra: &str) -> String {
    format!(
        "<VRTRasterBand dataType=\"{kind}\" band=\"{n}\">{extra}<ComplexSource>\
         <SourceFilename relativeToVRT=\"0\">{}</SourceFilename><SourceBand>1</SourceBand>\
         {source_extra}</ComplexSource></VRTRasterBand>",
        fixture("etopo5_2deg_i16.tif")
    )
}

#[test]
fn the_band_asked_for_is_the_band_tiled() {
    // GDAL's warper warps band 1 of its source, so `--band 2` used to tile band 1.
    let dir = Dir::new();
    let doubled = "<ScaleOffset>1000</ScaleOffset><ScaleRatio>2</ScaleRatio>";
    let two = globe_vrt(
        &dir,
        "two.vrt",
        &(globe_band(1, "Float32", "", "") + &globe_band(2, "Float32", "", doubled)),
    );
    let second = globe_vrt(&dir, "second.vrt", &globe_band(1, "Float32", "", doubled));
    for (input, band, out) in [
        (&two, "2", "two2"),
        (&two, "1", "two1"),
        (&second, "1", "second"),
    ] {
        pyramid(&dir, input, out, &["--band", band, "--max-zoom", "1", "-q"]);
    }
    let band2 = terrain_files(&dir.path("two2"));
    assert_eq!(band2, terrain_files(&dir.path("second")));
    assert_ne!(band2, terrain_files(&dir.path("two1")));
}

#[test]
fn nan_is_nodata_in_tiles_whether_declared_or_not() {
    // The same grid with a block of NaN, with NODATA_value nan, without, and with
    // NODATA_value -9999 (half the block -9999, half NaN): the same tiles. (A NaN the warp
    // did not know as nodata spread to the samples beside it, and those tiles lost them.)
    let dir = Dir::new();
    let mut rows = Vec::new();
    for r in 0..30 {
        let row: Vec<String> = (0..40)
            .map(|c| {
                if (10..16).contains(&r) && (12..20).contains(&c) {
                    "nan".to_owned()
                } else {
                    let v = 100.0 + 3.0 * f64::from(c) + 0.5 * f64::from(r);
                    format!("{:.3}", v + 10.0 * (f64::from(c) / 3.0).sin())
                }
            })
            .collect();
        rows.push(row.join(" "));
    }
    let header = "ncols 40\nnrows 30\nxllcorner 10.0\nyllcorner 40.0\ncellsize 0.01\n";
    let wgs84 = "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],\
                 PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]";
    let mixed: Vec<String> = rows
        .iter()
        .enumerate()
        .map(|(r, row)| {
            if r < 13 {
                row.replace("nan", "-9999")
            } else {
                row.clone()
            }
        })
        .collect();
    for (name, nodata, rows) in [
        ("undeclared", "", &rows),
        ("declared", "NODATA_value nan\n", &rows),
        ("mixed", "NODATA_value -9999\n", &mixed),
    ] {
        dir.write(
            &format!("{name}.asc"),
            &format!("{header}{nodata}{}\n", rows.join("\n")),
        );
        dir.write(&format!("{name}.prj"), wgs84);
        let input = format!("{name}.asc");
        pyramid(
            &dir,
            &input,
            name,
            &["--min-zoom", "11", "--max-zoom", "11", "-q"],
        );
    }
    let declared = terrain_files(&dir.path("declared"));
    assert_eq!(terrain_files(&dir.path("undeclared")), declared);
    assert_eq!(terrain_files(&dir.path("mixed")), declared);
}

/// `masked.vrt` in `dir`: the Float32 globe with its oceans (heights below 0) masked by a
/// GDAL mask band of 0 and 255.
fn masked_globe(dir: &Dir) -> String {
    let mask = globe_band(
        1,
        "Byte",
        "",
        "<LUT>-100000:0,-0.5:0,0:255,100000:255</LUT>",
    )
    .replace(" band=\"1\"", "");
    let band = globe_band(1, "Float32", "", "").replace(
        "</VRTRasterBand>",
        &format!("<MaskBand>{mask}</MaskBand></VRTRasterBand>"),
    );
    globe_vrt(dir, "masked.vrt", &band)
}

#[test]
fn an_alpha_band_of_any_type_masks_tiles_as_a_mask_band_does() {
    // The globe with its oceans masked: by a Float32 or Byte alpha band of 0 and 1 (as
    // gdalwarp -dstalpha can write), and by a mask band of 0 and 255. Same tiles. (The
    // warper took an alpha of 1 for 1/255 and lost every sample.)
    let dir = Dir::new();
    let land = "<LUT>-100000:0,-0.5:0,0:1,100000:1</LUT>";
    let alpha = |kind: &str| {
        globe_vrt(
            &dir,
            &format!("alpha_{kind}.vrt"),
            &(globe_band(1, "Float32", "", "")
                + &globe_band(2, kind, "<ColorInterp>Alpha</ColorInterp>", land)),
        )
    };
    let (float_alpha, byte_alpha) = (alpha("Float32"), alpha("Byte"));
    let masked = masked_globe(&dir);
    for (input, out) in [
        (&float_alpha, "float"),
        (&byte_alpha, "byte"),
        (&masked, "masked"),
    ] {
        pyramid(&dir, input, out, &["--max-zoom", "1", "-q"]);
    }
    let masked = terrain_files(&dir.path("masked"));
    assert_eq!(terrain_files(&dir.path("float")), masked);
    assert_eq!(terrain_files(&dir.path("byte")), masked);
}

#[test]
fn a_rounded_float32_nodata_tag_masks_tiles_as_it_masks_meshes() {
    // Oceans filled with -FLT_MAX under a nodata tag of -3.40282e+38 (as gdalinfo prints
    // it): GDAL's statistics and every other command take the fill as nodata, and so do
    // tiles now, the same tiles as with the oceans masked. (The warp compared exactly and
    // took the fill for heights: "beyond what quantized-mesh tiles can hold".)
    let dir = Dir::new();
    let fill =
        "<LUT>-100000:-3.4028234663852886e38,-0.5:-3.4028234663852886e38,0:0,100000:100000</LUT>";
    let filled = globe_vrt(
        &dir,
        "filled.vrt",
        &globe_band(
            1,
            "Float32",
            "<NoDataValue>-3.40282e+38</NoDataValue>",
            fill,
        ),
    );
    let masked = masked_globe(&dir);
    for (input, out) in [(&filled, "filled"), (&masked, "masked")] {
        pyramid(&dir, input, out, &["--max-zoom", "1", "-q"]);
    }
    assert_eq!(
        terrain_files(&dir.path("filled")),
        terrain_files(&dir.path("masked"))
    );
}

#[test]
fn zoom_and_quality_out_of_range_are_refused_saying_why() {
    let dir = Dir::new();
    let input = fixture("etopo5_2deg_i16.tif");
    for (extra, names) in [
        // The bound would overflow (it left tiles undecimated, with a bound of null).
        (
            &["--quality", "1e305"][..],
            &["--quality", "1e6", "1e305"][..],
        ),
        // The raster's own level is 0: the message says --max-zoom defaulted to it.
        (
            &["--min-zoom", "3"][..],
            &["--min-zoom 3", "default --max-zoom 0"][..],
        ),
        // Given both the wrong way round: said so (it said "not within 0..=24").
        (
            &["--min-zoom", "3", "--max-zoom", "2"][..],
            &["--min-zoom 3 is above --max-zoom 2"][..],
        ),
    ] {
        let mut args = vec!["tiles", &input, "-o", "p", "-q"];
        args.extend_from_slice(extra);
        let o = dir.run(&args);
        crate::util::assert_fails_naming(&o, names);
        assert!(!dir.path("p").exists());
    }
}

#[test]
fn very_tall_pixels_choose_a_level_from_their_area_not_their_width() {
    // 0.1 by 20 degrees per pixel: the default level followed the finer axis (level 4,
    // each pixel cut into about 400 lattice rows); a 100000 x 10 global raster ran for
    // hours. The lattice now holds at most 64 times the samples: level 3 here.
    let dir = Dir::new();
    let row: String = (0..320).map(|c| format!("{} ", c % 7)).collect();
    let rows = format!("{row}\n").repeat(4);
    dir.write(
        "tall.asc",
        &format!("ncols 320\nnrows 4\nxllcorner -16\nyllcorner -40\ndx 0.1\ndy 20\n{rows}"),
    );
    dir.write("tall.prj", "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]");
    pyramid(&dir, "tall.asc", "p", &["-q"]);
    let (layer, _) = layer_json(&dir.path("p"));
    assert_eq!(layer["maxzoom"].as_u64(), Some(3));
}

#[test]
fn a_failed_pyramid_leaves_no_directory_it_made() {
    // The missing parents of -o are made (as mkdir -p); a run that then fails (here: no
    // valid sample at all) removes them again. They used to stay.
    let dir = Dir::new();
    dir.write("void.asc", "ncols 4\nnrows 4\nxllcorner 10\nyllcorner 40\ncellsize 0.01\nNODATA_value -9999\n-9999 -9999 -9999 -9999\n-9999 -9999 -9999 -9999\n-9999 -9999 -9999 -9999\n-9999 -9999 -9999 -9999\n");
    dir.write("void.prj", "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]");
    std::fs::create_dir(dir.path("kept")).unwrap();
    for out in ["made/deeper/p", "kept/made/p"] {
        let o = dir.run(&["tiles", "void.asc", "-o", out, "-q"]);
        crate::util::assert_fails_naming(&o, &["void.asc", "no terrain"]);
    }
    assert!(!dir.path("made").exists());
    assert!(dir.path("kept").is_dir() && !dir.path("kept/made").exists());
}

#[test]
fn a_pyramid_needs_a_2x2_block_of_valid_samples() {
    // One valid sample, and a 3 x 1 raster: `mesh` finds no 2x2 block of valid samples to
    // triangulate, and neither does `tiles`. The coarser levels, made from the finest by a
    // filter that reaches a sample further out, used to smear them into terrain anyway (a
    // flat square some degrees wide at level 0).
    let dir = Dir::new();
    let prj = "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]";
    let one: String = (0..36)
        .map(|i| if i == 14 { "250 " } else { "-9999 " })
        .collect();
    // At 10 m in UTM the default finest level is finer than the raster: the warp alone
    // would fill a 2x2 block of the lattice from the one sample.
    let utm = "PROJCS[\"WGS 84 / UTM zone 11N\",GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]],PROJECTION[\"Transverse_Mercator\"],PARAMETER[\"latitude_of_origin\",0],PARAMETER[\"central_meridian\",-117],PARAMETER[\"scale_factor\",0.9996],PARAMETER[\"false_easting\",500000],PARAMETER[\"false_northing\",0],UNIT[\"metre\",1]]";
    let rasters = [
        (
            "fine",
            format!(
                "ncols 5\nnrows 5\nxllcorner 400000\nyllcorner 3800000\ncellsize 10\n\
                 NODATA_value -9999\n{}\n",
                (0..25)
                    .map(|i| if i == 12 { "250 " } else { "-9999 " })
                    .collect::<String>()
            ),
        ),
        (
            "one",
            format!(
                "ncols 6\nnrows 6\nxllcorner 10\nyllcorner 40\ncellsize 0.01\n\
                 NODATA_value -9999\n{one}\n"
            ),
        ),
        (
            "row",
            "ncols 3\nnrows 1\nxllcorner 10\nyllcorner 40\ncellsize 0.01\n1 2 3\n".to_string(),
        ),
    ];
    for (name, text) in rasters {
        dir.write(&format!("{name}.asc"), &text);
        dir.write(
            &format!("{name}.prj"),
            if name == "fine" { utm } else { prj },
        );
        let input = format!("{name}.asc");
        let o = dir.run(&["mesh", &input, "-o", "m.ply", "--max-error", "1"]);
        crate::util::assert_fails_naming(&o, &[&input, "2x2"]);
        let o = dir.run(&["tiles", &input, "-o", "p", "-q"]);
        crate::util::assert_fails_naming(&o, &[&input, "2x2", "no terrain"]);
        assert!(!dir.path("p").exists());
    }
}

#[test]
fn metadata_without_level_zero_is_refused() {
    // CesiumJS learns availability from the level-0 tiles' metadata: without them it
    // would find no tile at all.
    let dir = Dir::new();
    let input = fixture("etopo5_2deg_i16.tif");
    let o = dir.run(&[
        "tiles",
        &input,
        "-o",
        "p",
        "--metadata",
        "--min-zoom",
        "1",
        "-q",
    ]);
    crate::util::assert_fails_naming(&o, &["--metadata", "--min-zoom 0"]);
    assert!(!dir.path("p").exists());
}

#[test]
fn a_level_far_finer_than_memory_allows_is_refused_up_front() {
    // A globe of 16 M x 8 M samples (a VRT that resamples the 2-degree one, read by no
    // one): its own level's tile rows span 131072 tiles, hundreds of GB. Refused
    // before any work, naming the level, with nothing left behind.
    let dir = Dir::new();
    let o = Command::new("gdal_translate")
        .args(["-q", "-of", "VRT", "-outsize", "16777216", "8388608"])
        .arg(fixture("etopo5_2deg_i16.tif"))
        .arg(dir.path("huge.vrt"))
        .output()
        .expect("gdal_translate (Debian gdal-bin) must be on PATH");
    assert!(o.status.success(), "{}", stderr(&o));
    let o = dir.run(&["tiles", "huge.vrt", "-o", "deep", "-q"]);
    assert_fails_naming(&o, &["huge.vrt", "level 16", "in memory", "coarser copy"]);
    let left: Vec<_> = std::fs::read_dir(dir.path("."))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|n| {
            n.to_string_lossy().contains("deep") || n.to_string_lossy().contains(".tinsmith")
        })
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}");
}

#[test]
fn a_max_zoom_far_finer_than_the_raster_is_refused_with_one_that_works() {
    // A 6 x 6 raster of 0.5° cells asked for level 20: 305 M tiles of interpolation. It
    // was not refused, and its tile records grew to 18 GB before any tile was written.
    let dir = Dir::new();
    let mut asc = String::from("ncols 6\nnrows 6\nxllcorner 10\nyllcorner 40\ncellsize 0.5\n");
    for row in 0..6 {
        let line: Vec<String> = (0..6).map(|col| (100 * row + col).to_string()).collect();
        asc.push_str(&line.join(" "));
        asc.push('\n');
    }
    dir.write("small.asc", &asc);
    dir.write("small.prj", "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]");
    let o = dir.run(&["tiles", "small.asc", "-o", "p", "--max-zoom", "20"]);
    assert_fails_naming(&o, &["small.asc", "--max-zoom 20", "own resolution"]);
    assert!(!dir.path("p").exists());
    // The level it suggests is accepted (checked up front; level 6 is built to show it).
    let said = stderr(&o);
    let suggested: u8 = said
        .split("choose --max-zoom ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no suggestion in {said}"));
    assert!((6..20).contains(&suggested), "{said}");
    pyramid(&dir, "small.asc", "p", &["--max-zoom", "6", "-q"]);
    assert!(dir.path("p/6").is_dir());
}

#[test]
fn a_raster_without_a_crs_is_refused_saying_what_is_missing() {
    // An ESRI grid without its .prj has a geotransform but no CRS; the message said "no
    // CRS or geotransform".
    let dir = Dir::new();
    dir.write(
        "nocrs.asc",
        "ncols 3\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 5 6\n7 8 9\n",
    );
    let o = dir.run(&["tiles", "nocrs.asc", "-o", "p"]);
    assert_fails_naming(&o, &["nocrs.asc: no CRS,", "-a_srs"]);
    assert!(!dir.path("p").exists());
}

#[test]
fn a_rotated_raster_is_tiled_whole() {
    // A geotransform rotated by 30 degrees: the extent came from two opposite corners
    // only, so layer.json's bounds missed the other two and the finest level lost more
    // than half of the samples, silently (and its level came out two finer).
    let dir = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let o = Command::new("gdal_translate")
        .args(["-q", "-of", "VRT", &dem])
        .arg(dir.path("plain.vrt"))
        .output()
        .expect("gdal_translate runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let plain = std::fs::read_to_string(dir.path("plain.vrt")).expect("vrt");
    let (x0, y0) = (1443887.5, 491087.5);
    let (c, s) = (
        50.0 * 30f64.to_radians().cos(),
        50.0 * 30f64.to_radians().sin(),
    );
    let start = plain.find("<GeoTransform>").expect("a geotransform");
    let end = plain.find("</GeoTransform>").expect("its end") + "</GeoTransform>".len();
    let rotated = format!(
        "{}<GeoTransform>{x0:?}, {c:?}, {s:?}, {y0:?}, {s:?}, {:?}</GeoTransform>{}",
        &plain[..start],
        -c,
        &plain[end..]
    );
    dir.write("rotated.vrt", &rotated);
    pyramid(&dir, "plain.vrt", "plain", &[]);
    pyramid(&dir, "rotated.vrt", "rotated", &[]);
    let (plain, _) = layer_json(&dir.path("plain"));
    let (rotated, bounds) = layer_json(&dir.path("rotated"));
    assert_eq!(rotated["maxzoom"], plain["maxzoom"]);
    let (w, h) = (430.0, 516.0);
    let corners: Vec<[f64; 3]> = [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)]
        .iter()
        .map(|&(col, row)| [x0 + col * c + row * s, y0 + col * s - row * c, 0.0])
        .collect();
    for [lon, lat, _] in crate::util::gdaltransform("EPSG:3005", "EPSG:4326", &corners) {
        assert!(
            bounds[0] <= lon && lon <= bounds[2] && bounds[1] <= lat && lat <= bounds[3],
            "corner ({lon}, {lat}) outside layer.json bounds {bounds:?}"
        );
    }
}

#[test]
fn layer_bounds_are_longitudes_in_range_for_a_raster_east_of_180() {
    // A 0..360 grid's part past 180 alone: layer.json's west was 185 (not a longitude),
    // and west > east read as a crossing of the antimeridian it does not make.
    let dir = Dir::new();
    let input = relabelled(
        &dir,
        "becmodel_dem_bc_albers_50m.tif",
        "east.tif",
        ["185", "-30", "195", "-40"],
    );
    pyramid(&dir, &input, "p", &["-q", "--max-zoom", "3"]);
    let (_, bounds) = layer_json(&dir.path("p"));
    let expected = [-175.0, -40.0, -165.0, -30.0];
    for (got, want) in bounds.iter().zip(expected) {
        assert!(
            (got - want).abs() < 1e-9,
            "bounds {bounds:?}, expected {expected:?}"
        );
    }
}

#[test]
fn a_raster_placed_only_by_gcps_is_refused_and_noted_saying_so() {
    // GCPs without a geotransform: tiles said "no CRS and no geotransform" and suggested
    // `-a_ullr`, which would throw the GCP fit away; mesh wrote pixel coordinates silently.
    let dir = Dir::new();
    let status = Command::new("gdal_translate")
        .args(["-q", "-a_srs", "EPSG:32611"])
        .args(["-gcp", "0", "0", "500000", "4000000"])
        .args(["-gcp", "430", "0", "521500", "4000000"])
        .args(["-gcp", "0", "516", "500000", "3974200"])
        .arg(fixture("becmodel_dem_bc_albers_50m.tif"))
        .arg(dir.path("gcps.tif"))
        .status()
        .expect("gdal_translate runs");
    assert!(status.success());
    let o = dir.run(&["tiles", "gcps.tif", "-o", "p"]);
    assert_fails_naming(&o, &["gcps.tif", "ground control points", "gdalwarp"]);
    assert!(!dir.path("p").exists());
    let o = dir.run(&["mesh", "gcps.tif", "-o", "m.ply", "--max-error", "5"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("gcps.tif: georeferenced only by 3 ground control points")
            && stderr(&o).contains("pixel (column, row) coordinates"),
        "{}",
        stderr(&o)
    );
}

/// Oct-decodes a quantized-mesh normal (two bytes, extension 1) to a unit vector.
fn oct_decode(x: u64, y: u64) -> [f64; 3] {
    let (mut x, mut y) = (x as f64 / 255.0 * 2.0 - 1.0, y as f64 / 255.0 * 2.0 - 1.0);
    let z = 1.0 - x.abs() - y.abs();
    if z < 0.0 {
        let (ox, oy) = (x, y);
        x = (1.0 - oy.abs()) * if ox >= 0.0 { 1.0 } else { -1.0 };
        y = (1.0 - ox.abs()) * if oy >= 0.0 { 1.0 } else { -1.0 };
    }
    let len = (x * x + y * y + z * z).sqrt();
    [x / len, y / len, z / len]
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn normals_at_a_pole_point_up_on_flat_ground() {
    // Antarctic polar stereographic around the pole: on the pole's row every sample is
    // one point, and the east-west difference over its zero spacing tilted normals up to
    // 86 degrees off vertical on the flat plateau, at every coarse level.
    let dir = Dir::new();
    let input = crate::util::south_polar_fixture(&dir, "pole.tif", "1000000", "100");
    pyramid(&dir, &input, "p", &["-q", "--normals", "--max-zoom", "3"]);
    let mut at_pole = 0;
    for (&(z, x, y), t) in &decode_pyramid(&dir.path("p")) {
        let n = 2u32 << z;
        let size = 360.0 / f64::from(n);
        let (west, south) = (-180.0 + f64::from(x) * size, -90.0 + f64::from(y) * size);
        let normals = t.normals.as_ref().expect("normals");
        for (k, (&u, &v)) in t.u.iter().zip(&t.v).enumerate() {
            let lon = (west + size * u as f64 / 32767.0).to_radians();
            let lat = (south + size * v as f64 / 32767.0).to_radians();
            let up = [lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin()];
            let normal = oct_decode(normals[2 * k], normals[2 * k + 1]);
            let cos: f64 = (0..3).map(|i| up[i] * normal[i]).sum();
            if lat.to_degrees() < -89.999 {
                at_pole += 1;
            }
            // The plateau around the pole is nearly flat; 2-degree ETOPO warped this far
            // has no slope near 45 degrees anywhere.
            assert!(
                cos > 0.7,
                "{z}/{x}/{y} vertex {k} at lat {}: normal {normal:?}, cos {cos}",
                lat.to_degrees()
            );
        }
    }
    assert!(at_pole > 10, "{at_pole} vertices on the pole");
}

/// The `.terrain` files of levels `levels` under `root`.
fn level_files(root: &Path, levels: std::ops::RangeInclusive<u32>) -> BTreeMap<PathBuf, Vec<u8>> {
    terrain_files(root)
        .into_iter()
        .filter(|(path, _)| {
            let z: u32 = path
                .iter()
                .next()
                .unwrap()
                .to_str()
                .unwrap()
                .parse()
                .unwrap();
            levels.contains(&z)
        })
        .collect()
}

#[test]
fn a_tile_does_not_depend_on_the_zoom_range_or_the_threads() {
    // The Albers DEM's own level is 11: levels up to it are filtered from it whatever
    // --max-zoom is, and levels beyond are each sampled from the raster alone.
    let dir = Dir::new();
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    pyramid(&dir, &input, "own", &["-q", "--normals"]);
    pyramid(
        &dir,
        &input,
        "coarse",
        &["-q", "--normals", "--max-zoom", "8", "--threads", "1"],
    );
    pyramid(
        &dir,
        &input,
        "deep",
        &["-q", "--normals", "--max-zoom", "13"],
    );
    pyramid(
        &dir,
        &input,
        "middle",
        &["-q", "--normals", "--min-zoom", "6", "--max-zoom", "12"],
    );
    let own = level_files(&dir.path("own"), 0..=11);
    // The 18 tiles with data, and 2 the projected raster's lon/lat box reaches without
    // data, flat (the whole globe is drawn).
    assert_eq!(own.keys().filter(|p| p.starts_with("11")).count(), 20);
    assert!(level_files(&dir.path("coarse"), 0..=8) == level_files(&dir.path("own"), 0..=8));
    assert!(level_files(&dir.path("deep"), 0..=11) == own);
    assert!(level_files(&dir.path("middle"), 6..=11) == level_files(&dir.path("own"), 6..=11));
    assert!(level_files(&dir.path("middle"), 12..=12) == level_files(&dir.path("deep"), 12..=12));
    assert!(level_files(&dir.path("middle"), 0..=5).is_empty());
    assert!(!level_files(&dir.path("deep"), 13..=13).is_empty());
}

/// The geoid's height above the WGS84 ellipsoid at each point of a tile's lattice (row 0
/// the southernmost), from the gdaltransform program: PROJ's own choice of operation from
/// EPSG:4326 + EGM96 height to EPSG:4979.
pub(crate) fn egm96_undulations(cells: i64, z: u32, x: u32, y: u32) -> Vec<Vec<f64>> {
    use std::io::Write as _;
    let size = 180.0 / (1u64 << z) as f64;
    let d = size / cells as f64;
    let (west, south) = (-180.0 + x as f64 * size, -90.0 + y as f64 * size);
    let mut points = String::new();
    for j in 0..=cells {
        for i in 0..=cells {
            points += &format!(
                "{:.12} {:.12} 0\n",
                west + i as f64 * d,
                south + j as f64 * d
            );
        }
    }
    let mut child = Command::new("gdaltransform")
        .args(["-s_srs", "EPSG:4326+5773", "-t_srs", "EPSG:4979"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("gdaltransform runs");
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(points.as_bytes()).unwrap());
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert!(out.status.success());
    let n: Vec<f64> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().nth(2).unwrap().parse().unwrap())
        .collect();
    assert_eq!(n.len(), ((cells + 1) * (cells + 1)) as usize);
    n.chunks((cells + 1) as usize).map(|r| r.to_vec()).collect()
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_geoid_datum_writes_the_ellipsoidal_heights_proj_gives() {
    let dir = Dir::new();
    let input = fixture("tintn_valid_raster_3857.tif");
    let o = dir.run(&["tiles", &input, "-o", "plain"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("no vertical CRS") && stderr(&o).contains("--vertical-datum"),
        "{}",
        stderr(&o)
    );
    pyramid(&dir, &input, "egm96", &["--vertical-datum", "egm96"]);
    let (layer, _) = layer_json(&dir.path("egm96"));
    let max_zoom = layer["maxzoom"].as_u64().unwrap() as u32;
    let (plain, tiles) = (
        decode_pyramid(&dir.path("plain")),
        decode_pyramid(&dir.path("egm96")),
    );
    assert!(check_shared_edges(&tiles) > 0);
    let mut checked = 0;
    for (&(z, x, y), t) in tiles.range((max_zoom, 0, 0)..) {
        check_tile((z, x, y), t);
        let bound = E0 / (1u64 << z) as f64;
        let mut samples = gdal_samples(&dir, &input, t.cells(), z, x, y);
        let n = egm96_undulations(t.cells(), z, x, y);
        let shift = n
            .iter()
            .flatten()
            .fold(f64::INFINITY, |m, v| m.min(v.abs()));
        assert!(
            shift > 2.0 * bound,
            "{z}/{x}/{y}: the geoid ({shift} m) must matter"
        );
        for (row, n_row) in samples.iter_mut().zip(&n) {
            for (s, n) in row.iter_mut().zip(n_row) {
                *s += n;
            }
        }
        let e = max_error(t, &samples);
        assert!(e <= bound + 1e-3, "{z}/{x}/{y}: error {e} above {bound}");
        // The ellipsoid pyramid's tile is that far from the geoid one's samples.
        let e = max_error(&plain[&(z, x, y)], &samples);
        assert!(e > bound, "{z}/{x}/{y}: heights not shifted");
        checked += 1;
    }
    assert!(checked > 0);

    // A raster that declares EGM96 heights gets them without the option.
    let declared = dir.path("declared.tif").to_string_lossy().into_owned();
    let status = Command::new("gdal_translate")
        .args(["-q", "-a_srs", "EPSG:3857+5773", &input, &declared])
        .status()
        .expect("gdal_translate runs");
    assert!(status.success());
    let o = dir.run(&["tiles", &declared, "-o", "declared"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("egm96"), "{}", stderr(&o));
    assert!(
        terrain_files(&dir.path("declared")) == terrain_files(&dir.path("egm96")),
        "a declared EGM96 raster must give the tiles --vertical-datum egm96 gives"
    );

    // A vertical CRS tinsmith cannot shift by itself, and a missing grid: refused by
    // name, nothing written.
    let navd = dir.path("navd88.tif").to_string_lossy().into_owned();
    let status = Command::new("gdal_translate")
        .args(["-q", "-a_srs", "EPSG:3857+5703", &input, &navd])
        .status()
        .expect("gdal_translate runs");
    assert!(status.success());
    let o = dir.run(&["tiles", &navd, "-o", "navd"]);
    assert_fails_naming(&o, &["navd88.tif", "NAVD88", "--vertical-datum"]);
    let o = dir.run(&[
        "tiles",
        &input,
        "-o",
        "nogrid",
        "--vertical-datum",
        "nogrid.gtx",
    ]);
    assert_fails_naming(&o, &["nogrid.gtx"]);
    assert!(!dir.path("navd").exists() && !dir.path("nogrid").exists());
}

/// An ESRI ASCII grid in EPSG:4326 of `width` x `height` cells of `cell` degrees from
/// (`west`, `south`), each cell's value `value(lon, lat)` at its centre (NaN: nodata).
pub(crate) fn ascii_grid(
    dir: &Dir,
    name: &str,
    (west, south, cell): (f64, f64, f64),
    (width, height): (usize, usize),
    value: impl Fn(f64, f64) -> f64,
) -> String {
    let mut text = format!(
        "ncols {width}\nnrows {height}\nxllcorner {west}\nyllcorner {south}\ncellsize {cell}\n\
         NODATA_value -9999\n"
    );
    for j in (0..height).rev() {
        let row: Vec<String> = (0..width)
            .map(|i| {
                let v = value(
                    west + (i as f64 + 0.5) * cell,
                    south + (j as f64 + 0.5) * cell,
                );
                if v.is_nan() {
                    "-9999".to_owned()
                } else {
                    v.to_string()
                }
            })
            .collect();
        text += &row.join(" ");
        text += "\n";
    }
    dir.write(name, &text);
    dir.write(
        &name.replace(".asc", ".prj"),
        "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],\
         PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]",
    );
    dir.path(name).to_string_lossy().into_owned()
}

/// Every mask cell of every tile whose centre is clearly on one side of `is_water` (as
/// `clear(lon, lat)` says) has that side's value; returns how many were checked.
fn check_water_masks<'a>(
    tiles: impl IntoIterator<Item = (&'a (u32, u32, u32), &'a Tile)>,
    is_water: impl Fn(f64, f64) -> Option<bool>,
) -> (usize, usize) {
    let (mut water, mut land) = (0, 0);
    for (&(z, x, y), t) in tiles {
        let mask = t.water_mask.as_ref().expect("every tile has a water mask");
        let size = 180.0 / (1u64 << z) as f64;
        let (west, north) = (-180.0 + x as f64 * size, -90.0 + (y + 1) as f64 * size);
        let cell = size / 256.0;
        for j in 0..256 {
            for i in 0..256 {
                let (lon, lat) = (
                    west + (i as f64 + 0.5) * cell,
                    north - (j as f64 + 0.5) * cell,
                );
                let Some(expected) = is_water(lon, lat) else {
                    continue;
                };
                let got = match mask.len() {
                    1 => mask[0],
                    65536 => mask[j * 256 + i],
                    n => panic!("{z}/{x}/{y}: a water mask of {n} bytes"),
                };
                assert_eq!(
                    got,
                    if expected { 255 } else { 0 },
                    "{z}/{x}/{y}: cell {i}, {j} at {lon}, {lat}"
                );
                if expected {
                    water += 1;
                } else {
                    land += 1;
                }
            }
        }
    }
    (water, land)
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn water_masks_mark_the_sea_a_mask_or_the_dem_itself_says() {
    let dir = Dir::new();
    // Land west of 10.6°E (a 5 m deep polder round 10.3°E, 45.5°N), then a strip 0.02°
    // wide at -1 m, then nodata sea.
    let dem = ascii_grid(
        &dir,
        "coast.asc",
        (10.0, 45.0, 0.01),
        (100, 100),
        |lon, lat| {
            if lon > 10.62 {
                f64::NAN
            } else if lon > 10.6 {
                -1.0
            } else if (lon - 10.3).abs() < 0.05 && (lat - 45.5).abs() < 0.05 {
                -5.0
            } else {
                50.0 + 100.0 * (lon - 10.0)
            }
        },
    );
    let o = dir.run(&["tiles", &dem, "-o", "sea", "--water", "sea-level", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (layer, _) = layer_json(&dir.path("sea"));
    assert!(layer["extensions"]
        .as_array()
        .unwrap()
        .contains(&"watermask".into()));
    let tiles = decode_pyramid(&dir.path("sea"));
    let max_zoom = layer["maxzoom"].as_u64().unwrap() as u32;
    let finest = tiles.range((max_zoom, 0, 0)..);
    let inside = |lon: f64, lat: f64| (10.0..11.0).contains(&lon) && (45.0..46.0).contains(&lat);
    let (water, land) = check_water_masks(finest, |lon, lat| {
        let margin = 0.02;
        if !inside(lon, lat) {
            // Outside the DEM: no data, so sea, away from its edges.
            return (lon > 11.0 + margin
                || lon < 10.0 - margin
                || lat > 46.0 + margin
                || lat < 45.0 - margin)
                .then_some(true);
        }
        if lon > 10.62 + margin {
            Some(true)
        } else if lon < 10.6 - margin {
            // Land, the polder too: below 0 but away from the sea.
            (lon > 10.0 + margin && lat > 45.0 + margin && lat < 46.0 - margin).then_some(false)
        } else {
            None
        }
    });
    assert!(
        water > 1000 && land > 1000,
        "{water} water, {land} land cells checked"
    );

    // A mask raster: water south of 45.5°N.
    let mask = ascii_grid(&dir, "mask.asc", (9.5, 44.5, 0.02), (100, 100), |_, lat| {
        f64::from(u8::from(lat < 45.5))
    });
    let o = dir.run(&["tiles", &dem, "-o", "masked", "--water", &mask, "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let tiles = decode_pyramid(&dir.path("masked"));
    let (water, land) = check_water_masks(&tiles, |lon, lat| {
        let inside = (9.5..11.5).contains(&lon) && (44.5..46.5).contains(&lat);
        let margin = 0.03;
        if !inside {
            (lon > 11.5 + margin
                || lon < 9.5 - margin
                || lat > 46.5 + margin
                || lat < 44.5 - margin)
                .then_some(false)
        } else if lat < 45.5 - margin {
            Some(true)
        } else if lat > 45.5 + margin {
            Some(false)
        } else {
            None
        }
    });
    assert!(
        water > 1000 && land > 1000,
        "{water} water, {land} land cells checked"
    );

    // The same water as a polygon layer, in another CRS (Web Mercator): the same cells.
    dir.write(
        "water.geojson",
        r#"{"type":"FeatureCollection","features":[{"type":"Feature","properties":{},
        "geometry":{"type":"Polygon","coordinates":[[[9.5,44.5],[11.5,44.5],[11.5,45.5],
        [9.5,45.5],[9.5,44.5]]]}}]}"#,
    );
    let status = Command::new("ogr2ogr")
        .args(["-t_srs", "EPSG:3857", "-f", "GPKG"])
        .arg(dir.path("water.gpkg"))
        .arg(dir.path("water.geojson"))
        .status()
        .expect("ogr2ogr runs");
    assert!(status.success());
    let o = dir.run(&[
        "tiles",
        &dem,
        "-o",
        "polygons",
        "--water",
        "water.gpkg",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let polygons = decode_pyramid(&dir.path("polygons"));
    let (water, land) = check_water_masks(&polygons, |lon, lat| {
        let margin = 0.03;
        let inside = (9.5 + margin..11.5 - margin).contains(&lon)
            && (44.5 + margin..45.5 - margin).contains(&lat);
        let outside = !(9.5 - margin..11.5 + margin).contains(&lon)
            || !(44.5 - margin..45.5 + margin).contains(&lat);
        if inside {
            Some(true)
        } else if outside {
            Some(false)
        } else {
            None
        }
    });
    assert!(
        water > 1000 && land > 1000,
        "{water} water, {land} land cells checked"
    );

    // Neither a raster nor a vector dataset: refused by name, nothing written.
    dir.write("water.txt", "not water");
    let o = dir.run(&["tiles", &dem, "-o", "bad", "--water", "water.txt"]);
    assert_fails_naming(&o, &["water.txt", "--water"]);
    assert!(!dir.path("bad").exists());
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_regional_pyramid_draws_the_whole_globe_with_its_data_on_it() {
    let dir = Dir::new();
    // A 1 x 1 degree DEM without nodata, 50 to 150 m.
    let dem = ascii_grid(
        &dir,
        "patch.asc",
        (10.0, 45.0, 0.01),
        (100, 100),
        |lon, lat| 50.0 + 100.0 * (lon - 10.0) * (lat - 45.0),
    );
    pyramid(
        &dir,
        &dem,
        "globe",
        &["-q", "--vertical-datum", "ellipsoid"],
    );
    pyramid(
        &dir,
        &dem,
        "data",
        &["-q", "--vertical-datum", "ellipsoid", "--data-only"],
    );
    let (globe, data) = (
        decode_pyramid(&dir.path("globe")),
        decode_pyramid(&dir.path("data")),
    );
    // Both roots, and every tile covers its whole square: the globe beyond the raster is
    // flat at 0, so a client draws it all.
    assert!(globe.contains_key(&(0, 0, 0)) && globe.contains_key(&(0, 1, 0)));
    for (&key, t) in &globe {
        check_tile(key, t);
        assert!(
            (covered(t) - 1.0).abs() < 1e-9,
            "{key:?} covers {}",
            covered(t)
        );
        let outside = t.h.iter().filter(|&&h| h == 0.0).count();
        assert!(outside > 0, "{key:?}: no vertex on the flat globe");
    }
    assert!(check_shared_edges(&globe) > 0);
    // The same tiles hold the data: at the finest level the bound is tight enough for the
    // data to stand above the flat globe.
    let finest = *globe.keys().next_back().unwrap();
    assert!(
        globe[&finest].h.iter().any(|&h| h > 40.0),
        "{finest:?} lost its data"
    );
    // --data-only: tiles end where the raster does, and only the root it reaches exists.
    assert!(!data.contains_key(&(0, 0, 0)));
    assert!(covered(&data[&(0, 1, 0)]) < 0.01);
    assert_eq!(
        globe.keys().collect::<Vec<_>>()[1..],
        data.keys().collect::<Vec<_>>()[..],
        "the same tiles but the root without data"
    );
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn web_mercator_tiles_the_part_of_a_raster_within_85_degrees_and_refuses_one_beyond() {
    let dir = Dir::new();
    let hills = |lon: f64, lat: f64| 500.0 + 300.0 * (lon * 3.0).sin() * (lat * 5.0).cos();
    // 83..88°N: the part up to 85.0511° (Web Mercator's edge) is tiled.
    let arctic = ascii_grid(&dir, "arctic.asc", (10.0, 83.0, 0.02), (200, 250), hills);
    pyramid(&dir, &arctic, "p", &["--tiling", "mercator", "-q"]);
    let (layer, bounds) = layer_json(&dir.path("p"));
    assert_eq!(layer["projection"], "EPSG:3857");
    let edge = Tiling::Mercator.rectangle(0, 0, 0)[3];
    assert!((edge - 85.051_128_779_806_6).abs() < 1e-9, "{edge}");
    assert!(
        (bounds[3] - edge).abs() < 1e-9 && bounds[1] == 83.0,
        "{bounds:?}"
    );
    let max_zoom = layer["maxzoom"].as_u64().unwrap() as u32;
    let tiles = decode_pyramid(&dir.path("p"));
    let mut top_row = 0;
    for (&(z, x, y), t) in tiles.range((max_zoom, 0, 0)..) {
        top_row += usize::from(y + 1 == 1 << z);
        let samples = tiled_gdal_samples(&dir, &arctic, Tiling::Mercator, t.cells(), z, x, y);
        let bound = Tiling::Mercator.level_error(z);
        let e = max_error(t, &samples);
        assert!(e <= bound + 1e-3, "{z}/{x}/{y}: error {e} above {bound}");
    }
    assert!(top_row > 0, "no tile reaches the edge");
    // 86..89°N: nothing to tile.
    let pole = ascii_grid(&dir, "pole.asc", (10.0, 86.0, 0.02), (100, 150), hills);
    let o = dir.run(&["tiles", &pole, "-o", "q", "--tiling", "mercator"]);
    assert_fails_naming(&o, &["pole.asc", "85.0511", "--tiling geographic"]);
    assert!(!dir.path("q").exists());
}
