//! `tinsmith tiles --shard I/N` and `tinsmith tiles merge`: the union of the shards and the
//! merge is the one-process pyramid byte for byte, whatever the shard count; a merge with
//! shards missing or foreign refuses, naming them, and writes no `layer.json`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::util::{assert_fails_naming, fixture, stderr, Dir};

/// Every file under `root` by relative path, without the shards' records.
pub(crate) fn pyramid_files(root: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let relative = path.strip_prefix(root).unwrap().to_path_buf();
            if relative.starts_with("tinsmith") {
                continue;
            }
            if path.is_dir() {
                stack.push(path);
            } else {
                out.insert(relative, std::fs::read(&path).unwrap());
            }
        }
    }
    out
}

/// The relative paths where two pyramids' files (as [`pyramid_files`] gives them)
/// differ: in one only, or with other bytes.
pub(crate) fn differences(
    a: &BTreeMap<PathBuf, Vec<u8>>,
    b: &BTreeMap<PathBuf, Vec<u8>>,
) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = a
        .keys()
        .chain(b.keys())
        .filter(|k| a.get(*k) != b.get(*k))
        .cloned()
        .collect();
    out.sort();
    out.dedup();
    out
}

pub(crate) fn run_ok(dir: &Dir, args: &[&str]) -> String {
    let o = dir.run(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    stderr(&o)
}

/// Builds `input`'s pyramid in one process (`one`) and in `n` shards then a merge
/// (`sharded-n`), with `extra` options, and asserts they are the same files.
pub(crate) fn check_shards(dir: &Dir, input: &str, extra: &[&str], counts: &[u32]) {
    let mut args = vec!["tiles", input, "-o", "one", "-q"];
    args.extend_from_slice(extra);
    run_ok(dir, &args);
    let one = pyramid_files(&dir.path("one"));
    let last = if extra.contains(&"3dtiles") {
        "tileset.json"
    } else {
        "layer.json"
    };
    assert!(one.contains_key(Path::new(last)) && one.len() > 5);
    for &n in counts {
        let out = format!("sharded-{n}");
        // Shards in an order that is not their index order.
        for i in (0..n).rev() {
            let shard = format!("{i}/{n}");
            let mut args = vec!["tiles", input, "-o", &out, "--shard", &shard, "-q"];
            args.extend_from_slice(extra);
            run_ok(dir, &args);
        }
        assert!(
            !dir.path(&out).join(last).exists(),
            "no {last} before the merge"
        );
        run_ok(dir, &["tiles", "merge", &out, "-q"]);
        let sharded = pyramid_files(&dir.path(&out));
        let differ = differences(&one, &sharded);
        assert!(differ.is_empty(), "{n} shards differ in {differ:?}");
    }
}

#[test]
fn shards_and_their_merge_are_the_one_process_pyramid() {
    let dir = Dir::new();
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    check_shards(&dir, &input, &["--normals", "--metadata"], &[1, 2, 7, 64]);
}

#[test]
fn shards_keep_the_vertical_datum_through_the_merge() {
    let dir = Dir::new();
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    check_shards(&dir, &input, &["--vertical-datum", "egm96"], &[3]);
    // And the datum shapes the tiles: a shard of another datum is another plan, refused
    // before it overwrites the finished pyramid's tiles.
    let before = pyramid_files(&dir.path("sharded-3"));
    let o = dir.run(&["tiles", &input, "-o", "sharded-3", "--shard", "0/3", "-q"]);
    assert_fails_naming(&o, &["another plan", "vertical_datum", "egm96"]);
    assert!(pyramid_files(&dir.path("sharded-3")) == before);
}

#[test]
fn web_mercator_shards_and_updates_are_the_one_process_pyramid_and_keep_their_tiling() {
    let dir = Dir::new();
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    let mercator = ["--tiling", "mercator", "--normals"];
    check_shards(&dir, &input, &mercator, &[2, 7]);
    // The tiling shapes the tiles: a geographic shard is another plan, refused before it
    // writes into the Web Mercator one.
    let before = pyramid_files(&dir.path("sharded-2"));
    let o = dir.run(&["tiles", &input, "-o", "sharded-2", "--shard", "0/2", "-q"]);
    assert_fails_naming(&o, &["another plan", "tiling", "mercator"]);
    assert!(pyramid_files(&dir.path("sharded-2")) == before);
    // An update to the other tiling rebuilds every tile and leaves none of the old one:
    // the pyramid is the one built afresh.
    run_ok(
        &dir,
        &["tiles", &input, "-o", "geographic", "--normals", "-q"],
    );
    let mut args = vec!["tiles", input.as_str(), "-o", "one", "--update", "-q"];
    args.extend_from_slice(&["--normals"]);
    run_ok(&dir, &args);
    assert!(pyramid_files(&dir.path("one")) == pyramid_files(&dir.path("geographic")));
}

#[test]
fn shards_of_a_globe_meet_across_the_antimeridian() {
    let dir = Dir::new();
    let input = fixture("etopo5_2deg_i16.tif");
    check_shards(&dir, &input, &["--max-zoom", "3"], &[2, 7]);
}

#[test]
fn a_globe_on_0_360_is_whole_and_the_same_in_shards() {
    // A global raster stored on 0..360 (as ETOPO5 is): a block at column 0 reads its
    // window a turn east of the last column. That part once came back empty, so the
    // pyramid lacked tiles west of 0 (with ETOPO5, 310 of 682, fewer the more shards), and
    // the tiles built there had their header and normals computed a turn east, off in the
    // last bits (2 of the 10 tiles at the 0.5-degree globe's own level differed from a
    // 3-shard run's).
    let dir = Dir::new();
    let relabelled = crate::tiles::relabelled(
        &dir,
        "etopo5_2deg_i16.tif",
        "globe360.tif",
        ["-1", "90", "358.99999999999", "-90"],
    );
    let status = std::process::Command::new("gdal_translate")
        .args([
            "-q",
            "-outsize",
            "720",
            "360",
            "-r",
            "bilinear",
            &relabelled,
        ])
        .arg(dir.path("globe360_half_degree.tif"))
        .status()
        .expect("gdal_translate runs");
    assert!(status.success());
    let input = dir.path("globe360_half_degree.tif");
    let input = input.to_str().unwrap();
    for (max_zoom, tiles) in [("1", 2 + 8), ("3", 2 + 8 + 32 + 128)] {
        check_shards(&dir, input, &["--max-zoom", max_zoom, "--normals"], &[3]);
        let one = pyramid_files(&dir.path("one"));
        let count = one
            .keys()
            .filter(|p| p.extension().is_some_and(|e| e == "terrain" || e == "glb"))
            .count();
        assert_eq!(count, tiles, "every tile of levels 0 to {max_zoom}");
        std::fs::remove_dir_all(dir.path("one")).unwrap();
        std::fs::remove_dir_all(dir.path("sharded-3")).unwrap();
    }
}

#[test]
fn a_merge_names_missing_and_foreign_shards_and_writes_no_layer_json() {
    let dir = Dir::new();
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    run_ok(&dir, &["tiles", &input, "-o", "p", "--shard", "0/3", "-q"]);
    run_ok(&dir, &["tiles", &input, "-o", "p", "--shard", "2/3", "-q"]);
    let o = dir.run(&["tiles", "merge", "p"]);
    assert_fails_naming(&o, &["1/3", "missing", "no layer.json"]);
    assert!(!dir.path("p/layer.json").exists());
    // A shard of another plan (another count) in the same directory is refused before it
    // writes a tile; one that got there anyway (a copy) is refused by the merge.
    let before = pyramid_files(&dir.path("p"));
    let o = dir.run(&["tiles", &input, "-o", "p", "--shard", "1/2", "-q"]);
    assert_fails_naming(&o, &["0-of-3.json", "another plan", "3 vs 2 shards"]);
    assert!(
        pyramid_files(&dir.path("p")) == before,
        "the refused shard wrote files"
    );
    run_ok(&dir, &["tiles", &input, "-o", "q", "--shard", "1/2", "-q"]);
    std::fs::copy(
        dir.path("q/tinsmith/shards/1-of-2.json"),
        dir.path("p/tinsmith/shards/1-of-2.json"),
    )
    .unwrap();
    let o = dir.run(&["tiles", "merge", "p"]);
    assert_fails_naming(&o, &["1-of-2.json", "different plans"]);
    assert!(!dir.path("p/layer.json").exists());
    // Nothing to merge.
    std::fs::create_dir(dir.path("empty")).unwrap();
    let o = dir.run(&["tiles", "merge", "empty"]);
    assert_fails_naming(&o, &["empty", "no shard records", "--shard"]);
    // Bad shard specs.
    for bad in ["3/3", "1", "a/b", "0/0"] {
        let o = dir.run(&["tiles", &input, "-o", "q", "--shard", bad]);
        assert_fails_naming(&o, &[bad, "I/N"]);
    }
}

#[test]
fn a_shard_run_again_keeps_the_tiles_it_finished() {
    let dir = Dir::new();
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    run_ok(&dir, &["tiles", &input, "-o", "one", "-q"]);
    run_ok(&dir, &["tiles", &input, "-o", "p", "--shard", "0/1", "-q"]);
    // As if killed before its last blocks were recorded: their records are gone and one
    // of their tiles is cut short.
    let blocks = dir.path("p/tinsmith/blocks");
    let mut records: Vec<PathBuf> = std::fs::read_dir(&blocks)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    records.sort();
    let total = records.len();
    assert!(total >= 4, "{total} blocks");
    let entries = |record: &PathBuf| -> Vec<serde_json::Value> {
        let text: serde_json::Value =
            serde_json::from_slice(&std::fs::read(record).unwrap()).unwrap();
        text["tiles"].as_array().unwrap().clone()
    };
    let kept: usize = records[..total - 2].iter().map(|r| entries(r).len()).sum();
    for record in &records[total - 2..] {
        if let Some(tile) = entries(record).iter().find(|t| t["written"] == true) {
            let path = dir.path(&format!(
                "p/{}/{}/{}.terrain",
                tile["z"], tile["x"], tile["y"]
            ));
            std::fs::write(&path, b"cut short").unwrap();
        }
        std::fs::remove_file(record).unwrap();
    }
    std::fs::remove_file(dir.path("p/tinsmith/shards/0-of-1.json")).unwrap();
    let log = run_ok(&dir, &["tiles", &input, "-o", "p", "--shard", "0/1"]);
    assert!(
        log.contains(&format!("({kept} kept from an earlier run)")),
        "{log}"
    );
    run_ok(&dir, &["tiles", "merge", "p", "-q"]);
    assert!(pyramid_files(&dir.path("one")) == pyramid_files(&dir.path("p")));
}

/// `input` with heights raised by `rise` m in the `size` x `size` window at `x0`, `y0`
/// (a VRT over it).
pub(crate) fn patched(dir: &Dir, input: &str, name: &str, window: [u32; 3], rise: f64) -> String {
    let [x0, y0, size] = window;
    let info = std::process::Command::new("gdalinfo")
        .args(["-json", input])
        .output()
        .unwrap();
    let info: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    let [w, h] = [0, 1].map(|k| info["size"][k].as_u64().unwrap());
    let vrt = dir.path(name);
    let status = std::process::Command::new("gdal_translate")
        .args(["-q", "-of", "VRT", input])
        .arg(&vrt)
        .status()
        .unwrap();
    assert!(status.success());
    let text = std::fs::read_to_string(&vrt).unwrap();
    let source = format!(
        "<ComplexSource><SourceFilename relativeToVRT=\"0\">{input}</SourceFilename>\
         <SourceBand>1</SourceBand><SrcRect xOff=\"{x0}\" yOff=\"{y0}\" xSize=\"{size}\" \
         ySize=\"{size}\"/><DstRect xOff=\"{x0}\" yOff=\"{y0}\" xSize=\"{size}\" \
         ySize=\"{size}\"/><ScaleOffset>{rise}</ScaleOffset><ScaleRatio>1</ScaleRatio>\
         </ComplexSource>"
    );
    assert!(x0 + size <= w as u32 && y0 + size <= h as u32);
    let text = text.replacen("</VRTRasterBand>", &format!("{source}</VRTRasterBand>"), 1);
    std::fs::write(&vrt, text).unwrap();
    vrt.to_string_lossy().into_owned()
}

/// Each tile file's (`.terrain` or `.glb`) identity on disk (inode and modification
/// time), by path.
pub(crate) fn identities(root: &Path) -> BTreeMap<PathBuf, (u64, std::time::SystemTime)> {
    use std::os::unix::fs::MetadataExt;
    pyramid_files(root)
        .into_keys()
        .filter(|p| p.extension().is_some_and(|e| e == "terrain" || e == "glb"))
        .map(|p| {
            let meta = std::fs::metadata(root.join(&p)).unwrap();
            (p, (meta.ino(), meta.modified().unwrap()))
        })
        .collect()
}

#[test]
fn an_update_rebuilds_only_the_tiles_a_changed_patch_reaches() {
    let dir = Dir::new();
    // The Albers DEM at 4 times its resolution (1720 x 2064 samples, own level 13).
    let big = dir.path("big.tif");
    let status = std::process::Command::new("gdal_translate")
        .args(["-q", "-outsize", "400%", "400%", "-r", "bilinear"])
        .arg(fixture("becmodel_dem_bc_albers_50m.tif"))
        .arg(&big)
        .status()
        .unwrap();
    assert!(status.success());
    let big = big.to_string_lossy().into_owned();
    let before = patched(&dir, &big, "dem.vrt", [1500, 1800, 100], 0.0);
    run_ok(&dir, &["tiles", &before, "-o", "p", "--normals", "-q"]);
    let old = identities(&dir.path("p"));
    // The same file name changed in place, as a DEM is re-surveyed.
    let after = patched(&dir, &big, "dem.vrt", [1500, 1800, 100], 40.0);
    assert_eq!(before, after);
    let log = run_ok(&dir, &["tiles", &after, "-o", "p", "--normals", "--update"]);
    run_ok(&dir, &["tiles", &after, "-o", "fresh", "--normals", "-q"]);
    let (updated, fresh) = (
        pyramid_files(&dir.path("p")),
        pyramid_files(&dir.path("fresh")),
    );
    let differ = differences(&fresh, &updated);
    assert!(
        differ.is_empty(),
        "the update differs from a fresh build in {differ:?}"
    );
    let new = identities(&dir.path("p"));
    let rewritten: Vec<_> = new
        .iter()
        .filter(|(p, id)| old.get(*p) != Some(id))
        .collect();
    let total = new.len();
    assert!(!rewritten.is_empty(), "the patch changed no tile");
    assert!(
        rewritten.len() * 4 < total,
        "{} of {total} tiles rewritten",
        rewritten.len()
    );
    // The patch is near the south-east corner: the finest level's tiles at the other
    // corner are untouched.
    let finest = new
        .keys()
        .map(|p| {
            p.iter()
                .next()
                .unwrap()
                .to_str()
                .unwrap()
                .parse::<u32>()
                .unwrap()
        })
        .max()
        .unwrap();
    let far: Vec<_> = new
        .keys()
        .filter(|p| p.starts_with(finest.to_string()))
        .collect();
    assert!(far.iter().any(|p| old.get(*p) == new.get(*p)));
    assert!(log.contains("kept"), "{log}");
}
