//! `cube5 cosim scenes/head-geometry.toml`: the geometry scene (opaque boxes and spheres, the
//! frame's depth test; docs/numerics/frame.md, "Opaque geometry") elaborates to a frame with
//! `DepthTest = 1`, runs on the RTL frame with the depth test and MATCHes the model, every pixel
//! and channel; `cube5 render` shows the depth test in its plan.

mod support;

use support::{cube5, scratch};

/// The scene with a small image (the base plane, which the RTL computes, keeps its size).
fn small_image(name: &str) -> std::path::PathBuf {
    let path = cube5_model::repo_root().join(format!("scenes/{name}.toml"));
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("width = 256"),
        "{name}: the image size changed"
    );
    let text = text
        .replace("width = 256", "width = 48")
        .replace("height = 256", "height = 48");
    let f = scratch(&format!("geometry-{name}.toml"));
    std::fs::write(&f, text).unwrap();
    f
}

#[test]
fn the_geometry_scene_matches_the_rtl_frame_with_the_depth_test() {
    let scene = small_image("head-geometry");
    let dir = scratch("geometry-out");
    let _ = std::fs::remove_dir_all(&dir);
    let out = cube5(&[
        "cosim",
        scene.to_str().unwrap(),
        "-o",
        dir.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("MATCH"), "{stdout}");
    assert!(stdout.contains("DepthTest = 1"), "{stdout}");
    assert!(dir.join("rtl.png").exists());

    let png = scratch("geometry.png");
    let out = cube5(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    assert!(
        stdout.contains("depth test ([geometry]: 1 box, 1 sphere"),
        "{stdout}"
    );
}
