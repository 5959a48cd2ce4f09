//! Helpers to run the real `tinsmith` binary in a temporary directory.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A temporary directory to run one test in.
pub struct Dir {
    pub tmp: tempfile::TempDir,
}

impl Dir {
    pub fn new() -> Dir {
        Dir {
            tmp: tempfile::tempdir().expect("temp dir"),
        }
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.tmp.path().join(name)
    }

    /// Runs `tinsmith args...` in this directory.
    pub fn run(&self, args: &[&str]) -> Output {
        Command::new(env!("CARGO_BIN_EXE_tinsmith"))
            .args(args)
            .current_dir(self.tmp.path())
            .output()
            .expect("run tinsmith")
    }

    /// Files in the directory, sorted.
    pub fn files(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(self.tmp.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    pub fn write(&self, name: &str, contents: &str) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, contents).unwrap();
        p
    }
}

/// A committed fixture, by file name.
pub fn fixture(name: &str) -> String {
    let base = Path::new(env!("CARGO_MANIFEST_DIR"));
    for dir in ["tests/fixtures", "crates/raster/tests/fixtures", "data"] {
        let p = base.join(dir).join(name);
        if p.exists() {
            return p.to_string_lossy().into_owned();
        }
    }
    panic!("fixture {name} is missing");
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Asserts a clean failure: non-zero exit, a single-line message naming `names`.
pub fn assert_fails_naming(o: &Output, names: &[&str]) {
    let err = stderr(o);
    assert!(
        !o.status.success(),
        "expected failure, got success; stderr: {err}"
    );
    assert_eq!(o.status.code(), Some(2), "stderr: {err}");
    for n in names {
        assert!(err.contains(n), "stderr should name {n:?}: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}
