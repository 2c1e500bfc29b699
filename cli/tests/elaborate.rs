//! `cube5 elaborate`: the frame configuration a scene needs, with its reasons (docs/scenes.md,
//! "What a scene builds"), and `cube5 cosim` running on it.

mod support;

use support::{assert_refused, cube5, scratch_file, succeeded};

fn scene_path(name: &str) -> String {
    cube5_model::repo_root()
        .join(format!("scenes/{name}.toml"))
        .to_string_lossy()
        .into_owned()
}

fn stdout_of(args: &[&str]) -> String {
    succeeded(&cube5(args), &format!("{args:?}"))
}

/// The MIP example scene leaves gradient and shader out and says why; the composite one keeps
/// them; `--spec` prints the CUBE5_TOPS entry alone; `-p` overrides the pipelines.
#[test]
fn elaborate_prints_the_configuration_and_why() {
    let mip = stdout_of(&["elaborate", &scene_path("head-mip")]);
    for needle in [
        "needs cube5_frame p4m128s0 (P=4 MaxDim=128 Shade=0)",
        "P = 4: run.pipelines unset",
        "MaxDim = 128:",
        "largest edge 96",
        "left out: cube5_gradient: render.mode = \"mip\"",
        "left out: cube5_shader: render.mode = \"mip\"",
        ".variants line: p4m128s0  sim  P=4 MaxDim=128 Shade=0",
        "CUBE5_TOPS=cube5_frame@P=4:MaxDim=128:Shade=0",
        "the full frame (p4m128)",
    ] {
        assert!(mip.contains(needle), "`{needle}` missing:\n{mip}");
    }
    let head = stdout_of(&["elaborate", &scene_path("head")]);
    assert!(
        head.contains("needs cube5_frame p4m128 (P=4 MaxDim=128)"),
        "{head}"
    );
    assert!(head.contains("left out: nothing"), "{head}");
    assert!(
        head.contains("Shade = 1: render.mode = \"composite\""),
        "{head}"
    );
    let narrow = stdout_of(&["elaborate", &scene_path("head-narrow")]);
    assert!(narrow.contains("P = 2: run.pipelines = 2"), "{narrow}");
    assert!(
        narrow.contains("VoxelW = 8: quality.voxel_bits = 8"),
        "{narrow}"
    );
    let spec = stdout_of(&["elaborate", "--spec", &scene_path("head-mip"), "-p", "8"]);
    assert_eq!(spec.trim(), "cube5_frame@P=8:MaxDim=128:Shade=0");
}

/// Refusals name the field, in one line.
#[test]
fn elaborate_refuses_naming_the_field() {
    assert_refused(
        &cube5(&["elaborate", &scene_path("head-bone-lights")]),
        &["head-bone-lights.toml", "light[0].colour"],
    );
    assert_refused(
        &cube5(&["elaborate", &scene_path("head-mip"), "-p", "3"]),
        &["--pipelines", "P = 3"],
    );
    let odd = scratch_file(
        "elab-odd.toml",
        "[volume]\nsize = 20\n[run]\npipelines = 8\n",
    );
    assert_refused(
        &cube5(&["elaborate", odd.to_str().unwrap()]),
        &["run.pipelines", "multiple of P = 8"],
    );
    let bad = scratch_file(
        "elab-p5.toml",
        "[volume]\nsize = 20\n[run]\npipelines = 5\n",
    );
    assert_refused(
        &cube5(&["elaborate", bad.to_str().unwrap()]),
        &["run.pipelines"],
    );
}

/// `cube5 cosim` on a small MIP scene: elaborated without gradient and shader, run on the built
/// `Shade = 0` frame with the larger memory, bit-exact.
#[cfg(feature = "rtl")]
#[test]
fn cosim_runs_a_mip_scene_on_the_frame_without_gradient_and_shader() {
    let scene = scratch_file("elab-mip.toml", "[volume]\nphantom = \"head\"\nsize = 16\n[render]\nmode = \"mip\"\n[image]\nwidth = 32\nheight = 32\n");
    let dir = support::scratch("elab-mip-out");
    let out = stdout_of(&[
        "cosim",
        scene.to_str().unwrap(),
        "-o",
        dir.to_str().unwrap(),
    ]);
    for needle in [
        "needs cube5_frame p4m16s0",
        "left out: cube5_gradient",
        "(MaxDim 128 >= 16)",
        "MATCH",
    ] {
        assert!(out.contains(needle), "`{needle}` missing:\n{out}");
    }
}
