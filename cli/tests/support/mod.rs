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
