//! `tools/dask_tiles.py`: the shards of a pyramid as Dask tasks on a `LocalCluster` of
//! worker processes talking over TCP, then the merge; and the deployment files of
//! `deploy/` (docs/scale-out.md). The driver's pyramid is the one-process pyramid byte
//! for byte; a failed shard is named, nothing is merged, and a re-run keeps its blocks.
//!
//! Dask and PyYAML are oracles `make deps` installs into `.venv/`: these tests are
//! `#[ignore]`d for a bare `cargo test`, and fail (never skip) when they are missing.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

use crate::shards::pyramid_files;
use crate::util::{fixture, stderr, stdout, Dir};

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// `.venv`'s Python, with Dask and PyYAML; fails the test when either is missing.
fn python() -> PathBuf {
    let python = repo().join(".venv/bin/python");
    assert!(
        python.exists(),
        "oracle missing: {}; run `make deps`",
        python.display()
    );
    let o = Command::new(&python)
        .args(["-c", "import distributed, yaml"])
        .output()
        .expect("python runs");
    assert!(
        o.status.success(),
        "oracle missing: dask[distributed] or pyyaml in .venv ({}); run `make deps`",
        stderr(&o)
    );
    python
}

/// Runs the driver in `dir` on a LocalCluster of 2 worker processes with the test's
/// `tinsmith`: `INPUT -o OUT --shards N`, then `extra` (`--` and tinsmith's options).
fn driver(dir: &Dir, input: &str, out: &str, shards: u32, extra: &[&str]) -> Output {
    Command::new(python())
        .arg(repo().join("tools/dask_tiles.py"))
        .args([
            input,
            "-o",
            out,
            "--shards",
            &shards.to_string(),
            "--workers",
            "2",
        ])
        .args(["--tinsmith", env!("CARGO_BIN_EXE_tinsmith")])
        .args(extra)
        .current_dir(dir.path(""))
        .output()
        .expect("the driver runs")
}

/// The driver's JSON summary, asserting it succeeded.
fn summary_of(o: &Output) -> Value {
    assert!(o.status.success(), "the driver failed: {}", stderr(o));
    serde_json::from_str(&stdout(o)).unwrap_or_else(|e| panic!("{e}: {}", stdout(o)))
}

/// `tinsmith tiles INPUT -o OUT` with `extra`, in one process.
fn one_process(dir: &Dir, input: &str, out: &str, extra: &[&str]) {
    let mut args = vec!["tiles", input, "-o", out, "-q"];
    args.extend_from_slice(extra);
    let o = dir.run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
}

fn as_u64(v: &Value) -> u64 {
    v.as_u64().unwrap_or_else(|| panic!("{v} is not a count"))
}

/// The summary lists `n` shards, in order, each run by a worker process (not the
/// driver's) that reports its own costs; their blocks and weights add up to the plan's.
fn check_summary(summary: &Value, n: u32) {
    let driver = as_u64(&summary["driver_pid"]);
    let results = summary["results"].as_array().expect("results");
    assert_eq!(results.len(), n as usize, "{summary}");
    let mut pids = std::collections::BTreeSet::new();
    let mut weight = 0;
    for (i, r) in results.iter().enumerate() {
        assert_eq!(r["shard"], format!("{i}/{n}"));
        assert_eq!(r["exit"], 0);
        let pid = as_u64(&r["pid"]);
        assert_ne!(pid, driver, "shard {i} ran in the driver's process");
        pids.insert(pid);
        assert!(r["worker"]
            .as_str()
            .unwrap()
            .starts_with("tcp://127.0.0.1:"));
        assert!(r["wall_s"].as_f64().unwrap() > 0.0);
        assert!(r["cpu_s"].as_f64().unwrap() > 0.0);
        // A tinsmith process with GDAL loaded, not an empty measurement, and measured
        // alone by GNU time (`make deps` installs it), not with its worker's memory.
        assert!(r["max_rss_mb"].as_f64().unwrap() > 5.0, "{r}");
        assert_eq!(
            r["rss_includes_parent"], false,
            "/usr/bin/time missing? {r}"
        );
        weight += as_u64(&r["weight"]);
        assert_eq!(r["total_weight"], results[0]["total_weight"]);
    }
    assert_eq!(weight, as_u64(&results[0]["total_weight"]));
    assert!(pids.len() <= 2, "2 worker processes ran them: {pids:?}");
    let totals = &summary["totals"];
    let shards_cpu: f64 = results.iter().map(|r| r["cpu_s"].as_f64().unwrap()).sum();
    assert!((totals["shards_cpu_s"].as_f64().unwrap() - shards_cpu).abs() < 0.01);
    assert!(summary["merge"]["cpu_s"].as_f64().unwrap() > 0.0);
    assert_eq!(
        summary["merge"]["pid"], summary["driver_pid"],
        "the merge runs locally"
    );
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn dask_runs_the_shards_on_worker_processes_and_the_merge_is_the_one_process_pyramid() {
    let dir = Dir::new();
    let cases: [(&str, &[&str]); 2] = [
        (
            "becmodel_dem_bc_albers_50m.tif",
            &["--normals", "--metadata"],
        ),
        ("etopo5_2deg_i16.tif", &["--max-zoom", "3"]),
    ];
    for (k, (name, options)) in cases.into_iter().enumerate() {
        let input = fixture(name);
        let (one, sharded) = (format!("one-{k}"), format!("dask-{k}"));
        one_process(&dir, &input, &one, options);
        let mut extra = vec!["--"];
        extra.extend_from_slice(options);
        let summary = summary_of(&driver(&dir, &input, &sharded, 4, &extra));
        check_summary(&summary, 4);
        let (one, sharded) = (
            pyramid_files(&dir.path(&one)),
            pyramid_files(&dir.path(&sharded)),
        );
        assert!(one.contains_key(Path::new("layer.json")) && one.len() > 5);
        let differ: Vec<_> = one
            .keys()
            .chain(sharded.keys())
            .filter(|p| one.get(*p) != sharded.get(*p))
            .collect();
        assert!(differ.is_empty(), "{name}: differ in {differ:?}");
    }
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_failed_shard_is_named_nothing_is_merged_and_a_rerun_keeps_its_tiles() {
    let dir = Dir::new();
    // A bad input: every shard fails, each is named, no merge runs.
    let bad = dir.write("bad.tif", "not a raster");
    let o = driver(&dir, bad.to_str().unwrap(), "bad", 4, &[]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    for i in 0..4 {
        assert!(
            err.contains(&format!("shard {i}/4 failed (tinsmith exit 2)")),
            "{err}"
        );
    }
    assert!(
        err.contains("not a raster GDAL can read") && err.contains("no merge"),
        "{err}"
    );
    assert!(!dir.path("bad/layer.json").exists());

    // One shard fails (its record's place is taken by a directory): that one is named,
    // the others finish, and nothing is merged.
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    std::fs::create_dir_all(dir.path("p/tinsmith/shards/2-of-4.json/in-the-way")).unwrap();
    let o = driver(&dir, &input, "p", 4, &[]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("shard 2/4 failed (tinsmith exit 2)"), "{err}");
    assert!(err.contains("2-of-4.json"), "{err}");
    assert!(err.contains("1 of 4 shards failed"), "{err}");
    for i in [0, 1, 3] {
        assert!(!err.contains(&format!("shard {i}/4 failed")), "{err}");
        assert!(dir
            .path(&format!("p/tinsmith/shards/{i}-of-4.json"))
            .is_file());
    }
    assert!(!dir.path("p/layer.json").exists());

    // Cleared and run again: every tile was finished and is kept; the pyramid is whole.
    std::fs::remove_dir_all(dir.path("p/tinsmith/shards/2-of-4.json")).unwrap();
    let summary = summary_of(&driver(&dir, &input, "p", 4, &[]));
    check_summary(&summary, 4);
    for r in summary["results"].as_array().unwrap() {
        let (kept, tiles) = (
            r["tiles_kept"].as_u64().unwrap(),
            r["tiles"].as_u64().unwrap(),
        );
        assert!(kept >= tiles && tiles > 0, "{r}");
    }
    one_process(&dir, &input, "one", &[]);
    assert!(pyramid_files(&dir.path("one")) == pyramid_files(&dir.path("p")));
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn the_deploy_files_parse_and_run_every_shard_then_the_merge() {
    // Kubernetes: an Indexed Job of N completions whose pods each run shard
    // JOB_COMPLETION_INDEX of N, then a Job that runs the merge.
    let check = r#"
import json, sys, yaml
docs = list(yaml.safe_load_all(open(sys.argv[1])))
out = []
for d in docs:
    spec = d["spec"]
    c = spec["template"]["spec"]["containers"][0]
    env = {e["name"]: e["value"] for e in c["env"]}
    out.append({"kind": d["kind"], "mode": spec.get("completionMode"),
                "completions": spec.get("completions"), "shards": env.get("SHARDS"),
                "run": " ".join(c["command"] + c["args"]),
                "restart": spec["template"]["spec"]["restartPolicy"],
                "claims": [v["persistentVolumeClaim"]["claimName"]
                           for v in spec["template"]["spec"]["volumes"]]})
print(json.dumps(out))
"#;
    let yaml = repo().join("deploy/kubernetes/tiles-job.yaml");
    let o = Command::new(python())
        .args(["-c", check])
        .arg(&yaml)
        .output()
        .expect("python runs");
    assert!(o.status.success(), "{}: {}", yaml.display(), stderr(&o));
    let jobs: Value = serde_json::from_str(&stdout(&o)).unwrap();
    let jobs = jobs.as_array().unwrap();
    assert_eq!(jobs.len(), 2, "{jobs:?}");
    let (shards, merge) = (&jobs[0], &jobs[1]);
    assert_eq!(shards["kind"], "Job");
    assert_eq!(shards["mode"], "Indexed");
    let n = as_u64(&shards["completions"]);
    assert_eq!(shards["shards"], n.to_string(), "SHARDS = completions");
    let run = shards["run"].as_str().unwrap();
    assert!(
        run.contains("tinsmith tiles \"$INPUT\" -o \"$DEST\"")
            && run.contains("--shard \"${JOB_COMPLETION_INDEX}/${SHARDS}\""),
        "{run}"
    );
    assert_eq!(merge["kind"], "Job");
    assert_eq!(merge["shards"], n.to_string());
    assert!(merge["run"]
        .as_str()
        .unwrap()
        .contains("tinsmith tiles merge \"$DEST\""));
    assert_eq!(shards["claims"], merge["claims"], "one shared volume");
    for job in jobs {
        assert_eq!(job["restart"], "Never");
    }

    // Slurm: an array of N tasks each running shard SLURM_ARRAY_TASK_ID of N; the merge
    // is submitted after it with afterok.
    let sbatch = repo().join("deploy/slurm/tiles.sbatch");
    let o = Command::new("bash")
        .arg("-n")
        .arg(&sbatch)
        .output()
        .expect("bash runs");
    assert!(o.status.success(), "{}: {}", sbatch.display(), stderr(&o));
    let text = std::fs::read_to_string(&sbatch).unwrap();
    let array = text
        .lines()
        .find_map(|l| l.strip_prefix("#SBATCH --array=0-"))
        .expect("an #SBATCH --array=0-(N-1) line");
    let last: u64 = array.trim().parse().unwrap();
    assert!(
        text.contains(&format!("\nSHARDS={} ", last + 1)),
        "SHARDS = N"
    );
    assert!(text.contains("--shard \"${SLURM_ARRAY_TASK_ID}/${SHARDS}\""));
    assert!(text.contains("--dependency=afterok:${jobid}") && text.contains("tiles merge"));
}
