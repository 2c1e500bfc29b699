//! Helpers shared by the command-line tests.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};

/// Runs the `cube5` binary with `args`.
pub fn cube5(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cube5"))
        .args(args)
        .output()
        .expect("run cube5")
}

/// A path `name` in this test target's scratch directory (`<target tmp>/<test>-tests/`).
pub fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("{}-tests", env!("CARGO_CRATE_NAME")));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A refusal: non-zero exit, exactly one line on stderr containing every needle, no panic.
pub fn assert_refused(out: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "expected failure; stderr: {err}");
    assert!(!err.contains("panicked"), "panic on user input: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "one-line error expected:\n{err}"
    );
    for n in needles {
        assert!(err.contains(n), "error should mention `{n}`: {err}");
    }
}

/// Writes `scene` as NAME.toml in the scratch directory and renders it; returns the output and
/// the PNG path (removed first).
pub fn render_scene(name: &str, scene: &str) -> (Output, PathBuf) {
    let toml = scratch(&format!("{name}.toml"));
    std::fs::write(&toml, scene).unwrap();
    let png = scratch(&format!("{name}.png"));
    let _ = std::fs::remove_file(&png);
    let out = cube5(&[
        "render",
        toml.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--width",
        "16",
        "--height",
        "16",
    ]);
    (out, png)
}
