//! The command line as a user meets it: good runs write what they say, bad input gets one line
//! and a non-zero exit code, never a panic, and leaves no partial output.

use std::path::PathBuf;
use std::process::{Command, Output};

fn cube5(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cube5"))
        .args(args)
        .output()
        .expect("run cube5")
}

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli-tests");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Asserts a refusal: non-zero exit, exactly one line on stderr containing `needle`, no panic.
fn assert_refused(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success(),
        "expected failure, got success; stderr: {err}"
    );
    assert!(!err.contains("panicked"), "panic on user input: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "one-line error expected, got:\n{err}"
    );
    assert!(
        err.contains(needle),
        "error should mention `{needle}`: {err}"
    );
}

#[test]
fn renders_the_default_scene_to_png() {
    let png = scratch("default.png");
    let _ = std::fs::remove_file(&png);
    let out = cube5(&[
        "render",
        "-o",
        png.to_str().unwrap(),
        "--width",
        "48",
        "--height",
        "40",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!("wrote {}", png.display())),
        "{stdout}"
    );
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (48, 40));
}

#[test]
fn renders_any_view_angle_from_a_scene_file() {
    let scene = scratch("view.toml");
    std::fs::write(&scene, "[volume]\nsize = 24\n[view]\nazimuth = -135.5\nelevation = 89.9\n[image]\nwidth = 16\nheight = 16\n").unwrap();
    let png = scratch("view.png");
    let out = cube5(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(png.exists());
}

#[test]
fn missing_scene_file() {
    assert_refused(
        &cube5(&["render", "/nonexistent/scene.toml"]),
        "/nonexistent/scene.toml",
    );
}

#[test]
fn unparsable_number() {
    assert_refused(&cube5(&["render", "--azimuth", "north"]), "north");
    assert_refused(&cube5(&["render", "--width", "-3"]), "-3");
}

#[test]
fn zero_size_image() {
    let png = scratch("zero.png");
    let _ = std::fs::remove_file(&png);
    assert_refused(
        &cube5(&["render", "--width", "0", "-o", png.to_str().unwrap()]),
        "image.width",
    );
    assert!(!png.exists(), "no output on failure");
}

#[test]
fn unknown_option() {
    assert_refused(&cube5(&["render", "--colour", "red"]), "--colour");
    assert_refused(&cube5(&["paint"]), "paint");
}

#[test]
fn malformed_scene_names_file_and_line() {
    let scene = scratch("bad.toml");
    std::fs::write(&scene, "[view]\nazimuth = 10\nelevation = [\n").unwrap();
    assert_refused(&cube5(&["render", scene.to_str().unwrap()]), "bad.toml:");
    std::fs::write(&scene, "[view]\nazimuth = nan\n").unwrap();
    assert_refused(&cube5(&["render", scene.to_str().unwrap()]), "view.azimuth");
}

#[test]
fn output_must_be_png_in_an_existing_directory() {
    assert_refused(&cube5(&["render", "-o", "image.jpg"]), ".png");
    assert_refused(
        &cube5(&[
            "render",
            "-o",
            "/nonexistent/dir/x.png",
            "--width",
            "8",
            "--height",
            "8",
        ]),
        "does not exist",
    );
}
