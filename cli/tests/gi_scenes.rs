//! GI scenes (`[gi]`) on the command line: `cube5 render` runs them on the GI-Cube processor model
//! (the plan line names it and gives the counts of both passes), `--compare` measures them against
//! the processor's f64 reference, the light's shadow shows in the image, and the RTL paths refuse
//! them in one line (there is no GI-Cube RTL yet).

mod support;

use std::path::{Path, PathBuf};
use support::{assert_refused, cube5, render_at, render_scene, scratch, scratch_file, succeeded};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn example() -> PathBuf {
    cube5_model::repo_root().join("scenes/gi-shadow.toml")
}

/// Renders `scene` at 48 x 48 into the scratch PNG `name`, with `extra` arguments; returns the
/// output and the image.
fn render(scene: &Path, name: &str, extra: &[&str]) -> (String, image::RgbImage) {
    let png = scratch(name);
    let stdout = succeeded(&render_at(scene, &png, 48, extra), "render");
    (stdout, image::open(&png).unwrap().to_rgb8())
}

/// The number in `text` after `key` (up to the next space).
fn number_after(text: &str, key: &str) -> f64 {
    let rest = &text[text
        .find(key)
        .unwrap_or_else(|| panic!("no `{key}` in {text}"))
        + key.len()..];
    rest.split_whitespace().next().unwrap().parse().unwrap()
}

#[test]
fn gi_shadow_renders_on_the_processor_with_its_counts() {
    let (stdout, lit) = render(&example(), "gi-shadow.png", &["--compare"]);
    let plan = stdout.lines().find(|l| l.starts_with("plan: ")).unwrap();
    for needle in [
        "plan: GI-Cube processor model",
        "lighting pass: ",
        "rendering pass: ",
        "rays in = ",
        "finished + ",
        "overflowed to the host",
        " samples",
        "mean queue occupancy ",
        "cache hit rate ",
        "; modelled: trilin",
    ] {
        assert!(plan.contains(needle), "`{needle}` missing: {plan}");
    }
    // Conservation, as printed: rays in = finished + overflowed, in both passes.
    let mut passes = 0;
    for pass in plan.split("pass: ") {
        let Some(Ok(rays_in)) = pass.split_whitespace().next().map(str::parse::<f64>) else {
            continue;
        };
        let n = |key: &str| number_after(pass, key);
        assert_eq!(rays_in, n("in = ") + n("finished + "), "{pass}");
        passes += 1;
    }
    assert_eq!(passes, 2, "{plan}");
    let db = number_after(&stdout, "f64 reference: PSNR ");
    assert!(
        db >= 40.0,
        "PSNR {db} dB against the f64 reference: {stdout}"
    );
    assert!(lit.pixels().any(|p| p.0.iter().any(|&c| c > 60)), "black");

    // Without the lighting pass (gi.passes = 1) there is no shadow: the image differs, and the
    // lit image is darker where the sphere shadows the floor.
    let text = std::fs::read_to_string(example()).unwrap();
    assert!(text.contains("passes = 2"));
    let unlit_scene = scratch_file(
        "gi-shadow-unlit.toml",
        text.replace("passes = 2", "passes = 1"),
    );
    let (stdout, unlit) = render(&unlit_scene, "gi-shadow-unlit.png", &["--compare"]);
    assert!(stdout.contains("rendering pass only"), "{stdout}");
    assert!(!stdout.contains("lighting pass: "), "{stdout}");
    let luma = |p: &image::Rgb<u8>| p.0.iter().map(|&c| f64::from(c)).sum::<f64>();
    let darker = lit
        .pixels()
        .zip(unlit.pixels())
        .filter(|(a, b)| luma(a) + 60.0 < luma(b))
        .count();
    assert!(
        darker >= 20,
        "only {darker} pixels are clearly darker with the light's shadow than without"
    );
    // The shadow moves with the light.
    let moved_scene = scratch_file(
        "gi-shadow-moved.toml",
        text.replace("light = [0.55, 0.25, -0.8]", "light = [-0.55, -0.25, -0.8]"),
    );
    let (_, moved) = render(&moved_scene, "gi-shadow-moved.png", &[]);
    assert!(moved != lit, "moving the light changes nothing");
}

#[test]
fn gi_reference_renders() {
    let (stdout, img) = render(&example(), "gi-shadow-ref.png", &["--reference"]);
    assert!(
        stdout.contains("plan: f64 reference of the GI-Cube processor model"),
        "{stdout}"
    );
    assert!(img.pixels().any(|p| p.0.iter().any(|&c| c > 60)));
}

#[test]
fn gi_scenes_refuse_the_rtl_in_one_line() {
    let png = scratch("gi-rtl.png");
    for target in ["rtl", "both"] {
        let out = cube5(&["render", s(&example()), "-o", s(&png), "--target", target]);
        assert_refused(&out, &["run.target", "no GI-Cube RTL"]);
    }
    assert!(!png.exists());
    #[cfg(feature = "rtl")]
    {
        let dir = scratch("gi-cosim");
        let out = cube5(&["cosim", s(&example()), "-o", s(&dir)]);
        assert_refused(&out, &["gi-shadow.toml", "[gi]", "no GI-Cube RTL"]);
    }
}

#[test]
fn bad_gi_fields_are_refused_in_one_line() {
    for (text, field) in [
        ("[gi]\nenergy = -1.0\n", "gi.energy"),
        ("[gi]\npasses = 3\n", "gi.passes"),
        ("[gi]\nblok_size = 8\n", "blok_size"),
        (
            "[gi]\nlight_rays = 2\n[volume]\nsize = 16\n",
            "gi.light_rays",
        ),
        (
            "[gi]\nblock_size = 4\n[volume]\nsize = 64\n",
            "gi.block_size",
        ),
    ] {
        let (out, png) = render_scene("gi-bad", text);
        assert_refused(&out, &["gi-bad.toml", field]);
        assert!(!png.exists(), "{text}");
    }
}
