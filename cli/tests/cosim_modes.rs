//! `cube5 cosim` on downsized versions of the example scenes of each render mode beyond MIP and
//! composite (MinIP, X-ray, first-opaque), of the 2-D transfer function, of opaque geometry (the
//! depth test) and of ER-perspective: the RTL the scene elaborates to (or the built one with a
//! larger memory) MATCHes the model, every pixel and channel (docs/numerics/frame.md, "Render
//! modes" and "Opaque geometry"; docs/numerics/er_perspective.md).

mod support;

use support::{cosim_matches, cube5, example_scene_with, scratch};

/// The scene `name` at a 16^3 volume and a 48 x 48 image.
fn downsized(name: &str) -> std::path::PathBuf {
    example_scene_with(
        name,
        &format!("modes-{name}"),
        &[
            ("size = 96", "size = 16"),
            ("width = 256", "width = 48"),
            ("height = 256", "height = 48"),
        ],
    )
}

#[test]
fn every_mode_scene_downsized_matches_the_rtl_frame() {
    for (name, mode, shade) in [
        ("head-minip", "minip", "Shade = 0"),
        ("head-xray", "xray", "Shade = 0"),
        ("head-first-opaque", "first-opaque", "Shade = 1"),
        ("head-2dtf", "composite", "Shade = 1"),
    ] {
        let dir = scratch(&format!("modes-{name}-out"));
        let stdout = cosim_matches(&downsized(name), &dir);
        assert!(
            stdout.contains(mode) && stdout.contains(shade),
            "{name}: {stdout}"
        );
        assert!(dir.join("rtl.png").exists(), "{name}");
    }
}

/// The geometry scene (opaque boxes and spheres, the frame's depth test; docs/numerics/frame.md,
/// "Opaque geometry") elaborates to a frame with `DepthTest = 1`, runs on it and MATCHes the
/// model; `cube5 render` shows the depth test in its plan.
#[test]
fn the_geometry_scene_matches_the_rtl_frame_with_the_depth_test() {
    // A small image: the base plane, which the RTL computes, keeps its size.
    let scene = example_scene_with(
        "head-geometry",
        "geometry-head-geometry",
        &[
            ("width = 256", "width = 48"),
            ("height = 256", "height = 48"),
        ],
    );
    let dir = scratch("geometry-out");
    let stdout = cosim_matches(&scene, &dir);
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

/// The ER-perspective example scene at 32^3 (issue 14): it runs on `cube5_er`, not on the frame,
/// and its base plane MATCHes the model's, every coxel field.
#[test]
fn the_er_perspective_scene_downsized_matches_the_rtl() {
    let scene = example_scene_with(
        "head-perspective-er",
        "modes-head-perspective-er",
        &[("size = 96", "size = 32")],
    );
    let stdout = cosim_matches(&scene, &scratch("modes-head-perspective-er-out"));
    assert!(stdout.contains("cube5_er"), "{stdout}");
    assert!(stdout.contains("plan: ER-perspective"), "{stdout}");
}
