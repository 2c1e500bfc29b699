//! GI scenes (`[gi]`) on the command line: `cube5 render` runs them on the GI-Cube processor model
//! (the plan line names it and gives the counts of both passes), `--compare` measures them against
//! the processor's f64 reference, the light's shadow shows in the image; `cube5 cosim` runs them
//! on the RTL block processor (`gicube_processor`) bit for bit, and so does `cube5 render` with
//! `run.target = "rtl"`/`"both"` (a line not built is named in one line with its build).

mod support;

use std::path::{Path, PathBuf};
#[cfg(feature = "rtl")]
use support::cube5;
use support::{assert_refused, render_at, render_scene, scratch, scratch_file, succeeded};

#[cfg(feature = "rtl")]
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

/// The 16^3 GI scene, a quarter of its lighting rays and 16 x 16 pixels (seconds on the RTL).
#[cfg(feature = "rtl")]
fn short_gi_16() -> String {
    let path = cube5_model::repo_root().join("scenes/gi-shadow-16.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let short = text
        .replace("width = 32", "width = 16")
        .replace("height = 32", "height = 16")
        .replace("albedo = 0.0 ", "light_rays = 28\nalbedo = 0.0 ");
    assert!(short.contains("light_rays = 28"), "{short}");
    short
}

/// `cube5 render --target both` of the 16^3 GI scene: both passes on `gicube_processor` (its
/// `Light = 1` line, in every cube5) MATCH the model at the line's configuration, their images
/// beside the output, and the model's image at the scene's configuration is written; `--target rtl` co-simulates only (no output image). A 24^3 volume
/// (no line) and the 32^3 and 64^3 scenes (lines built only by `CUBE5_FULL=1`) are refused in
/// one line naming what would run them, or (when built) MATCH.
#[cfg(feature = "rtl")]
#[test]
fn gi_scenes_render_on_the_processor_rtl_with_run_target() {
    let scene = scratch_file("gi-render-16.toml", short_gi_16());
    for target in ["both", "rtl"] {
        let png = scratch(&format!("gi-render-16-{target}.png"));
        let dir = scratch(&format!("gi-render-16-{target}-cosim"));
        let _ = std::fs::remove_file(&png);
        let _ = std::fs::remove_dir_all(&dir);
        let out = cube5(&["render", s(&scene), "-o", s(&png), "--target", target]);
        let stdout = succeeded(&out, "render on the RTL");
        for pass in ["MATCH: lighting pass", "MATCH: rendering pass"] {
            assert!(
                stdout.lines().any(|l| l.starts_with(pass)),
                "{target}: no `{pass}`: {stdout}"
            );
        }
        for who in ["model-gi.png", "rtl-gi.png"] {
            let img = image::open(dir.join(who)).unwrap().to_rgb8();
            assert_eq!(img.dimensions(), (16, 16));
        }
        assert_eq!(png.exists(), target == "both", "{target}: {stdout}");
        if target == "both" {
            // The model at the scene's own voxel width (12 bits; the line's is 8).
            let img = image::open(&png).unwrap().to_rgb8();
            assert_eq!(img.dimensions(), (16, 16));
            assert!(stdout.contains("plan: "), "{stdout}");
        }
    }
    let png = scratch("gi-render-rtl.png");
    let _ = std::fs::remove_file(&png);
    let text = std::fs::read_to_string(example()).unwrap();
    let odd = scratch_file("gi-render-24.toml", text.replace("size = 64", "size = 24"));
    let out = cube5(&["render", s(&odd), "-o", s(&png), "--target", "rtl"]);
    assert_refused(
        &out,
        &[
            "run.target = \"rtl\"",
            "gi-render-24.toml",
            "no gicube_processor configuration",
            "24^3",
        ],
    );
    for size in [32, 64] {
        let small = text
            .replace("size = 64", &format!("size = {size}"))
            .replace("# light_rays = 222", "light_rays = 8");
        assert!(small.contains("light_rays = 8"), "{small}");
        let scene = scratch_file(&format!("gi-render-{size}.toml"), small);
        let out = cube5(&[
            "render",
            s(&scene),
            "-o",
            s(&png),
            "--target",
            "rtl",
            "--width",
            "8",
            "--height",
            "8",
        ]);
        if out.status.success() {
            let stdout = String::from_utf8_lossy(&out.stdout);
            assert!(stdout.contains("MATCH: rendering pass"), "{stdout}");
        } else {
            assert_refused(
                &out,
                &[
                    "run.target = \"rtl\"",
                    "is not built",
                    "CUBE5_FULL=1 CUBE5_TOPS=",
                ],
            );
        }
    }
    assert!(!png.exists());
}

/// `cube5 cosim` of the 16^3 GI scene on `gicube_processor` (its `Light = 1` line, in every
/// cube5), a quarter of its lighting rays and 16 x 16 pixels (seconds), under the random memory:
/// both passes MATCH, with rays in = finished + overflowed, and both images written.
#[cfg(feature = "rtl")]
#[test]
fn gi_scene_cosimulates_on_the_processor_rtl() {
    let scene = scratch_file("gi-cosim-16.toml", short_gi_16());
    let dir = scratch("gi-cosim-16");
    let _ = std::fs::remove_dir_all(&dir);
    let out = cube5(&["cosim", s(&scene), "-o", s(&dir), "--memory", "random"]);
    let stdout = succeeded(&out, "cosim");
    for pass in ["MATCH: lighting pass", "MATCH: rendering pass"] {
        let line = stdout
            .lines()
            .find(|l| l.starts_with(pass))
            .unwrap_or_else(|| panic!("no `{pass}`: {stdout}"));
        let rays_in = number_after(line, "): ");
        assert_eq!(
            rays_in,
            number_after(line, "in = ") + number_after(line, "finished + "),
            "{line}"
        );
    }
    assert!(
        stdout.contains("the field in memory after the flush"),
        "{stdout}"
    );
    for png in ["model-gi.png", "rtl-gi.png"] {
        let img = image::open(dir.join(png)).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (16, 16));
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

/// Directed extremes of the RTL block processor through `cube5 cosim` (16^3, a few pixels each,
/// the random memory): a transparent volume (every block empty: rays only leap), an opaque one
/// (every ray terminates at its first sample), views along the axes (direction components 0),
/// one pixel, a wide perspective, and a lit pass over the opaque volume. Every pass MATCHes the
/// model, rays conserved.
#[cfg(feature = "rtl")]
#[test]
fn gi_extremes_cosimulate_on_the_processor_rtl() {
    let path = cube5_model::repo_root().join("scenes/gi-shadow-16.toml");
    let base = std::fs::read_to_string(path).unwrap();
    let unlit = base.replace("passes = 2", "passes = 1");
    let small = |t: &str, w: u32| {
        t.replace("width = 32", &format!("width = {w}"))
            .replace("height = 32", &format!("height = {w}"))
    };
    let points = |alpha: f64| {
        format!(
            "points = [\n  {{ density = 0.0, rgba = [0.9, 0.5, 0.2, {alpha}] }},\n  {{ density = 1.0, rgba = [0.2, 0.5, 0.9, {alpha}] }},\n]\n"
        )
    };
    let with_points = |t: &str, alpha: f64| {
        let start = t.find("points = [").unwrap();
        let end = start + t[start..].find("]\n\n").unwrap() + 3;
        format!("{}{}\n{}", &t[..start], points(alpha), &t[end..])
    };
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "transparent",
            with_points(&small(&unlit, 8), 0.0),
            ", 0 samples, ",
        ),
        ("opaque", with_points(&small(&unlit, 8), 1.0), " samples"),
        (
            "along-z",
            small(&unlit, 8).replace(
                "direction = [0.35, 0.75, -0.55]",
                "direction = [0.0, 0.0, -1.0]",
            ),
            " samples",
        ),
        (
            "along-x",
            small(&unlit, 8).replace(
                "direction = [0.35, 0.75, -0.55]",
                "direction = [1.0, 0.0, 0.0]",
            ),
            " samples",
        ),
        ("one-pixel", small(&unlit, 1), " samples"),
        (
            "wide-perspective",
            small(&unlit, 8).replace(
                "zoom = 1.3",
                "zoom = 1.3\nprojection = \"perspective\"\nfov = 90.0",
            ),
            " samples",
        ),
        (
            "lit-opaque",
            with_points(&small(&base, 8), 1.0)
                .replace("albedo = 0.0 ", "light_rays = 28\nalbedo = 0.0 "),
            "MATCH: lighting pass",
        ),
    ];
    for (name, text, needle) in cases {
        let scene = scratch_file(&format!("gi-extreme-{name}.toml"), &text);
        let dir = scratch(&format!("gi-extreme-{name}"));
        let out = cube5(&[
            "cosim",
            s(&scene),
            "-o",
            s(&dir),
            "--memory",
            "random",
            "--seed",
            "3",
        ]);
        let stdout = succeeded(&out, name);
        let line = stdout
            .lines()
            .find(|l| l.starts_with("MATCH: rendering pass"))
            .unwrap_or_else(|| panic!("{name}: no MATCH: {stdout}"));
        assert!(stdout.contains(needle), "{name}: `{needle}`: {stdout}");
        if name == "opaque" {
            // Every ray terminates at its first sample.
            assert_eq!(
                number_after(line, "%), "),
                number_after(line, "in = "),
                "{name}: one sample per ray: {line}"
            );
        }
        assert_eq!(
            number_after(line, "): "),
            number_after(line, "in = ") + number_after(line, "finished + "),
            "{name}: {line}"
        );
        eprintln!("{name}: {line}");
    }
}
