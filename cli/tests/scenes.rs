//! Scene files as a user meets them: every example in `scenes/` renders; every kind of bad input
//! (docs/scenes.md § Bad input) gets one line naming the file and the field, a non-zero exit code
//! and no output; `cube5 tradeoff` runs a tiny sweep end to end.

mod support;

use std::path::{Path, PathBuf};
use support::{cube5, render_scene, scene_refused, scratch, scratch_file, succeeded};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn every_example_scene_renders() {
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(cube5_model::repo_root().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 10, "{scenes:?}");
    for scene in scenes {
        let name = scene.file_stem().unwrap().to_string_lossy().to_string();
        let png = scratch(&format!("example-{name}.png"));
        let _ = std::fs::remove_file(&png);
        let out = cube5(&[
            "render",
            s(&scene),
            "-o",
            s(&png),
            "--width",
            "64",
            "--height",
            "64",
        ]);
        let stdout = succeeded(&out, &name);
        assert!(stdout.contains("; modelled: trilin"), "{name}: {stdout}");
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (64, 64));
        if name == "head-minip" {
            // Every ray crosses the air around the head: its minimum is 0 (the f64 reference's
            // too), and a ray without samples reads black.
            assert!(
                img.pixels().all(|p| p.0 == [0; 3]),
                "{name}: a MinIP of the head is black"
            );
            continue;
        }
        assert!(
            img.pixels().any(|p| p.0.iter().any(|&c| c > 20)),
            "{name}: the image is black"
        );
    }
}

#[test]
fn missing_volume_file() {
    scene_refused(
        "missing-volume",
        "[volume]\nfile = \"no/such.nrrd\"\n",
        &["volume.file", "no/such.nrrd"],
    );
}

#[test]
fn unreadable_volume_file() {
    // A directory where a file should be (root can read any file, so permissions cannot show it).
    let dir = scratch("a-directory.nii");
    std::fs::create_dir_all(&dir).unwrap();
    scene_refused(
        "unreadable",
        &format!("[volume]\nfile = \"{}\"\n", s(&dir)),
        &["volume.file", "a-directory.nii"],
    );
}

#[test]
fn raw_size_must_equal_dims_times_type() {
    let raw = scratch_file("short.raw", vec![7u8; 1000]);
    scene_refused(
        "raw-size",
        &format!(
            "[volume]\nfile = \"{}\"\ndims = [10, 10, 6]\ntype = \"u16\"\n",
            s(&raw)
        ),
        &["volume.file", "short.raw", "file size", "1000 bytes"],
    );
}

#[test]
fn dims_beyond_the_configured_rtl() {
    scene_refused(
        "rtl-limit",
        "[volume]\nsize = 600\n[run]\ntarget = \"rtl\"\n",
        &["volume.size", "configured RTL", "128"],
    );
    // A file whose header says more than the model takes at all.
    let big = scratch_file(
        "big.nrrd",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2000 4 4\nencoding: raw\n\n",
    );
    scene_refused(
        "too-big",
        &format!("[volume]\nfile = \"{}\"\n", s(&big)),
        &["volume.file", "big.nrrd", "sizes"],
    );
}

#[test]
fn nan_or_zero_view_vector() {
    scene_refused(
        "nan-view",
        "[view]\ndirection = [nan, 0.0, 1.0]\n",
        &["view.direction"],
    );
    scene_refused(
        "zero-view",
        "[view]\ndirection = [0, 0, 0]\n",
        &["view.direction", "zero"],
    );
}

#[test]
fn empty_or_constant_volume() {
    let empty = scratch_file("empty.nrrd", b"");
    scene_refused(
        "empty",
        &format!("[volume]\nfile = \"{}\"\n", s(&empty)),
        &["volume.file", "empty.nrrd", "magic"],
    );
    let flat = scratch_file("flat.raw", vec![0u8; 8 * 8 * 8]);
    scene_refused(
        "constant",
        &format!(
            "[volume]\nfile = \"{}\"\ndims = [8, 8, 8]\ntype = \"u8\"\n",
            s(&flat)
        ),
        &["volume", "every voxel is 0"],
    );
}

#[test]
fn unsorted_transfer_function_points() {
    scene_refused("unsorted", "[transfer]\npoints = [\n  { density = 0.0, rgba = [0, 0, 0, 0] },\n  { density = 0.6, rgba = [1, 1, 1, 0.5] },\n  { density = 0.4, rgba = [1, 1, 1, 1] },\n]\n", &["transfer.points[2].density", "sorted"]);
}

#[test]
fn malformed_headers_name_the_field() {
    let bad = scratch_file(
        "bad-header.nrrd",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: bzip2\n\n",
    );
    scene_refused(
        "bad-nrrd",
        &format!("[volume]\nfile = \"{}\"\n", s(&bad)),
        &["bad-header.nrrd", "encoding"],
    );
    let nii = scratch("bad.nii");
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    h[344..348].copy_from_slice(b"n+1\0");
    std::fs::write(&nii, &h).unwrap();
    scene_refused(
        "bad-nifti",
        &format!("[volume]\nfile = \"{}\"\n", s(&nii)),
        &["bad.nii", "dim[0]"],
    );
}

#[test]
fn bad_knobs_and_combinations() {
    scene_refused(
        "knob",
        "[quality]\nweight_bits = 20\n",
        &["quality.weight_bits"],
    );
    scene_refused(
        "persp",
        "[view]\nprojection = \"perspective\"\n",
        &["view.projection", "reference"],
    );
    scene_refused(
        "both",
        "[volume]\nphantom = \"head\"\nfile = \"x.nrrd\"\n",
        &["volume", "not both"],
    );
}

#[test]
fn rtl_target_cosimulates_the_frame() {
    let (out, png) = render_scene(
        "rtl",
        "[volume]\nsize = 16\n[render]\nmode = \"mip\"\n[run]\ntarget = \"both\"\n",
    );
    let stdout = succeeded(&out, "rtl");
    assert!(
        stdout.contains("gradient (MIP is unlit; its frame has Shade = 0, no gradient unit)"),
        "{stdout}"
    );
    assert!(stdout.contains("MATCH"), "{stdout}");
    assert!(
        stdout.contains("(the only RTL variant this scene needs"),
        "{stdout}"
    );
    assert!(png.exists(), "target both also renders the model image");
    let cosim = png.with_file_name(format!(
        "{}-cosim",
        png.file_stem().unwrap().to_string_lossy()
    ));
    for f in [
        "model.png",
        "rtl.png",
        "model-base-plane.png",
        "rtl-base-plane.png",
    ] {
        assert!(cosim.join(f).exists(), "{f}");
    }
}

/// Renders the example scene `name` with `--target both`: the RTL frame must match the model, and
/// the PNG `cube5 render` writes must be, byte for byte, the RTL's base plane warped (the cosim's
/// `rtl.png`) — the image a user renders is the hardware's.
fn example_scene_is_the_rtl_frame(name: &str) {
    let scene = cube5_model::repo_root().join(format!("scenes/{name}.toml"));
    let png = scratch(&format!("cosim-{name}.png"));
    let out = cube5(&["render", s(&scene), "-o", s(&png), "--target", "both"]);
    let stdout = succeeded(&out, name);
    assert!(stdout.contains("plan: frame"), "{name}: {stdout}");
    assert!(stdout.contains("MATCH"), "{name}: {stdout}");
    let rtl = png
        .with_file_name(format!("cosim-{name}-cosim"))
        .join("rtl.png");
    assert!(
        std::fs::read(&png).unwrap() == std::fs::read(&rtl).unwrap(),
        "{name}: the rendered image is not the RTL frame's"
    );
}

/// The example scenes the frame renders, from their `plan:` line (the rest name the what-if model
/// that ran instead).
fn frame_scenes() -> Vec<String> {
    let mut names = Vec::new();
    for e in std::fs::read_dir(cube5_model::repo_root().join("scenes")).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let scene = cube5_model::scene::Scene::parse(&text, s(&path)).unwrap();
        if cube5_model::scene_render::not_expressible(&scene).is_empty() {
            names.push(path.file_stem().unwrap().to_string_lossy().to_string());
        }
    }
    names.sort();
    names
}

#[test]
fn two_example_scenes_are_the_rtl_frame() {
    let frame = frame_scenes();
    for name in ["head-mip", "head-nifti"] {
        assert!(
            frame.iter().any(|n| n == name),
            "{name} is not a frame scene: {frame:?}"
        );
        example_scene_is_the_rtl_frame(name);
    }
}

#[test]
#[ignore = "sim-full: every example scene the frame renders, co-simulated on the variant with its widths (about a minute)"]
fn every_frame_example_scene_is_the_rtl_frame() {
    let frame = frame_scenes();
    assert!(frame.len() >= 4, "{frame:?}");
    for name in frame {
        example_scene_is_the_rtl_frame(&name);
    }
}

#[test]
fn phantom_files_round_trip_through_render() {
    // The phantom written as NIfTI and NRRD renders exactly as the embedded phantom.
    let mut images = Vec::new();
    for (name, volume) in [
        (
            "embedded",
            "phantom = \"head\"\nsize = 24\nbits = 8\n".to_string(),
        ),
        ("nifti", String::new()),
        ("nrrd", String::new()),
    ] {
        let volume = match name {
            "nifti" | "nrrd" => {
                let file = scratch(&format!(
                    "rt-head.{}",
                    if name == "nifti" { "nii.gz" } else { "nrrd" }
                ));
                let out = cube5(&[
                    "phantom",
                    "head",
                    "--size",
                    "24",
                    "--bits",
                    "8",
                    "-o",
                    s(&file),
                ]);
                succeeded(&out, "phantom");
                format!("file = \"{}\"\n", s(&file))
            }
            _ => volume,
        };
        let (out, png) = render_scene(
            &format!("rt-{name}"),
            &format!("[volume]\n{volume}[transfer]\npreset = \"head\"\n"),
        );
        succeeded(&out, name);
        images.push(image::open(&png).unwrap().to_rgb8());
    }
    assert_eq!(images[0], images[1], "NIfTI");
    assert_eq!(images[0], images[2], "NRRD");
}

#[test]
fn tradeoff_tiny_sweep_end_to_end() {
    let dir = scratch("tradeoff");
    let _ = std::fs::remove_dir_all(&dir);
    let out = cube5(&["tradeoff", "--tiny", "--out", s(&dir)]);
    let stdout = succeeded(&out, "tradeoff");
    assert!(stdout.contains("cube3-paper 6.1"), "{stdout}");
    for f in [
        "tradeoff.md",
        "tradeoff-widths.csv",
        "tradeoff-configs.csv",
        "tradeoff-sample-rate.csv",
        "tradeoff-early-termination.csv",
        "tradeoff-interpolation.csv",
        "tradeoff-gradient.csv",
        "tradeoff-widths.png",
        "tradeoff-samples.png",
        "tradeoff-interpolation.png",
        "tradeoff-gradient.png",
        "tradeoff-slabs.csv",
        "tradeoff-slabs.png",
        "tradeoff-er.csv",
        "tradeoff-er.png",
    ] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    let md = std::fs::read_to_string(dir.join("tradeoff.md")).unwrap();
    assert!(
        md.contains("cube3-paper §6.2") && md.contains("| 45 |"),
        "{md}"
    );
    let csv = std::fs::read_to_string(dir.join("tradeoff-interpolation.csv")).unwrap();
    assert!(csv.lines().count() == 4, "{csv}");
    // 900 x 540 and a legend row per two series; the title in anti-aliased text (grey edge
    // pixels), which needs the embedded font.
    let png = image::open(dir.join("tradeoff-gradient.png"))
        .unwrap()
        .to_rgb8();
    assert_eq!(png.dimensions(), (900, 540 + 2 * 24 + 6));
    let title: Vec<[u8; 3]> = (250..650)
        .flat_map(|x| (8..44).map(move |y| (x, y)))
        .map(|(x, y)| png.get_pixel(x, y).0)
        .collect();
    let grey = title.iter().filter(|p| p[0] > 60 && p[0] < 200).count();
    assert!(grey > 100, "no anti-aliased title text: {grey} grey pixels");
}
