//! `cube5 cosim` on downsized versions of the example scenes of each render mode beyond MIP and
//! composite (MinIP, X-ray, first-opaque) and of the 2-D transfer function: the RTL frame the
//! scene elaborates to (or the built one with a larger memory) MATCHes the model, every pixel and
//! channel (docs/numerics/frame.md, "Render modes").

mod support;

use support::{cube5, scratch};

/// The scene `name` at a 16^3 volume and a 48 x 48 image.
fn downsized(name: &str) -> std::path::PathBuf {
    let path = cube5_model::repo_root().join(format!("scenes/{name}.toml"));
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("size = 96"),
        "{name}: the scene's volume size changed"
    );
    let text = text
        .replace("size = 96", "size = 16")
        .replace("width = 256", "width = 48")
        .replace("height = 256", "height = 48");
    let f = scratch(&format!("modes-{name}.toml"));
    std::fs::write(&f, text).unwrap();
    f
}

#[test]
fn every_mode_scene_downsized_matches_the_rtl_frame() {
    for (name, mode, shade) in [
        ("head-minip", "minip", "Shade = 0"),
        ("head-xray", "xray", "Shade = 0"),
        ("head-first-opaque", "first-opaque", "Shade = 1"),
        ("head-2dtf", "composite", "Shade = 1"),
    ] {
        let scene = downsized(name);
        let dir = scratch(&format!("modes-{name}-out"));
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
            "{name}: {stdout}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(stdout.contains("MATCH"), "{name}: {stdout}");
        assert!(
            stdout.contains(mode) && stdout.contains(shade),
            "{name}: {stdout}"
        );
        assert!(dir.join("rtl.png").exists(), "{name}");
    }
}

/// `cube5 cosim` of the ER-perspective example scene at 32^3 (issue 14): it runs on `cube5_er`,
/// not on the frame, and its base plane MATCHes the model's, every coxel field.
#[test]
fn the_er_perspective_scene_downsized_matches_the_rtl() {
    let path = cube5_model::repo_root().join("scenes/head-perspective-er.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("size = 96"),
        "the scene's volume size changed"
    );
    let scene = scratch("modes-head-perspective-er.toml");
    std::fs::write(&scene, text.replace("size = 96", "size = 32")).unwrap();
    let dir = scratch("modes-head-perspective-er-out");
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
    assert!(
        stdout.contains("MATCH") && stdout.contains("cube5_er"),
        "{stdout}"
    );
    assert!(stdout.contains("plan: ER-perspective"), "{stdout}");
}
