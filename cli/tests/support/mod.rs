//! Helpers shared by the command-line tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
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

/// Writes `contents` to the scratch file `name` (as `scratch`); returns its path.
pub fn scratch_file(name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
    let f = scratch(name);
    std::fs::write(&f, contents).unwrap();
    f
}

/// Asserts that `out` is a successful run (else panics with `what`, the exit status, stdout and
/// stderr); returns its stdout.
pub fn succeeded(out: &Output, what: &str) -> String {
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{what}: {}: {stdout}{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
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

/// `cube5 render SCENE -o PNG`: must succeed; returns its output.
pub fn render_ok(scene: &Path, png: &Path) -> Output {
    let out = cube5(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    succeeded(&out, &format!("render {}", scene.display()));
    out
}

/// `cube5 render SCENE -o PNG` at `px` x `px` pixels with `extra` arguments, PNG removed first.
pub fn render_at(scene: &Path, png: &Path, px: u32, extra: &[&str]) -> Output {
    let _ = std::fs::remove_file(png);
    let px = px.to_string();
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--width",
        &px,
        "--height",
        &px,
    ];
    args.extend_from_slice(extra);
    cube5(&args)
}

/// Writes `scene` as NAME.toml in the scratch directory and renders it at 16 x 16; returns the
/// output and the PNG path (removed first).
pub fn render_scene(name: &str, scene: &str) -> (Output, PathBuf) {
    let toml = scratch_file(&format!("{name}.toml"), scene);
    let png = scratch(&format!("{name}.png"));
    (render_at(&toml, &png, 16, &[]), png)
}

/// Renders `scene` as `render_scene` does: refused (as `assert_refused`) naming NAME.toml and every
/// needle, and no PNG written.
pub fn scene_refused(name: &str, scene: &str, needles: &[&str]) {
    let (out, png) = render_scene(name, scene);
    let file = format!("{name}.toml");
    assert_refused(&out, &[&[file.as_str()], needles].concat());
    assert!(
        !png.exists(),
        "{name}: a refused scene wrote {}",
        png.display()
    );
}

/// The example scene `scenes/NAME.toml` with each `(from, to)` replaced (each `from` must be in
/// it, so a changed scene fails loudly), written to the scratch directory as TAG.toml.
pub fn example_scene_with(name: &str, tag: &str, edits: &[(&str, &str)]) -> PathBuf {
    let path = cube5_model::repo_root().join(format!("scenes/{name}.toml"));
    let mut text = std::fs::read_to_string(&path).unwrap();
    for (from, to) in edits {
        assert!(
            text.contains(from),
            "{name}: the scene has no `{from}` any more"
        );
        text = text.replace(from, to);
    }
    scratch_file(&format!("{tag}.toml"), text)
}

/// `cube5 cosim SCENE -o DIR` (DIR emptied first): must succeed and print MATCH; returns stdout.
pub fn cosim_matches(scene: &std::path::Path, dir: &std::path::Path) -> String {
    let _ = std::fs::remove_dir_all(dir);
    let out = cube5(&[
        "cosim",
        scene.to_str().unwrap(),
        "-o",
        dir.to_str().unwrap(),
    ]);
    let stdout = succeeded(&out, &scene.display().to_string());
    assert!(stdout.contains("MATCH"), "{}: {stdout}", scene.display());
    stdout
}
