//! The command line as a user meets it: good runs write what they say, bad input gets one line
//! and a non-zero exit code, never a panic, and leaves no partial output.

mod support;

use std::process::Output;
use support::{cube5, render_at, render_ok, scratch, scratch_file, succeeded};

/// Asserts a refusal naming `needle` (one line, non-zero exit, no panic).
fn assert_refused(out: &Output, needle: &str) {
    support::assert_refused(out, &[needle]);
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
    let stdout = succeeded(&out, "render");
    assert!(
        stdout.contains(&format!("wrote {}", png.display())),
        "{stdout}"
    );
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (48, 40));
}

#[test]
fn renders_any_view_angle_from_a_scene_file() {
    let scene = scratch_file("view.toml", "[volume]\nsize = 24\n[view]\nazimuth = -135.5\nelevation = 89.9\n[image]\nwidth = 16\nheight = 16\n");
    let png = scratch("view.png");
    render_ok(&scene, &png);
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
    let scene = scratch_file("bad.toml", "[view]\nazimuth = 10\nelevation = [\n");
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

/// `cube5 cosim`: a small scene on the RTL frame at P = 1 and 8 (the default scene at P = 4 is
/// `make demo`), then the inputs it refuses.
#[test]
fn cosim_matches_and_refuses_what_the_frame_cannot_render() {
    let scene = scratch_file("cosim-small.toml", "[volume]\nphantom = \"sphere\"\nsize = 32\n[view]\nazimuth = 45.0\nelevation = 0.0\n[image]\nwidth = 64\nheight = 64\n");
    for p in ["1", "8"] {
        let dir = scratch(&format!("cosim-p{p}"));
        let _ = std::fs::remove_dir_all(&dir);
        let out = cube5(&[
            "cosim",
            scene.to_str().unwrap(),
            "-p",
            p,
            "-o",
            dir.to_str().unwrap(),
        ]);
        let stdout = succeeded(&out, p);
        assert!(stdout.contains("MATCH"), "{stdout}");
        assert!(stdout.contains("samples/clock/pipeline"), "{stdout}");
        for f in ["model.png", "rtl.png"] {
            let img = image::open(dir.join(f)).unwrap();
            assert_eq!((img.width(), img.height()), (64, 64));
        }
    }
    let bad = |name: &str, text: &str, extra: &[&str], needle: &str| {
        let f = scratch_file(name, text);
        let dir = scratch(&format!("{name}-out"));
        let _ = std::fs::remove_dir_all(&dir);
        let mut args = vec!["cosim", f.to_str().unwrap(), "-o", dir.to_str().unwrap()];
        args.extend_from_slice(extra);
        let out = cube5(&args);
        assert_refused(&out, needle);
        assert!(!dir.join("rtl.png").exists(), "{name}: no image on refusal");
    };
    bad(
        "cosim-samples.toml",
        "[volume]\nsize = 16\n[quality]\nsamples_per_slice = 2\n",
        &[],
        "quality.samples_per_slice = 2 (the frame takes one per slice)",
    );
    bad(
        "cosim-big.toml",
        "[volume]\nsize = 200\n",
        &[],
        "128 voxels per edge",
    );
    bad(
        "cosim-odd.toml",
        "[volume]\nsize = 18\n",
        &[],
        "multiple of P = 4",
    );
    bad(
        "cosim-p3.toml",
        "[volume]\nsize = 16\n",
        &["-p", "3"],
        "built for P = 1, 4, 8",
    );
}

/// Renders `scene` (written to NAME.toml) with `extra` arguments at 24 x 24; the PNG's bytes.
fn render_view(name: &str, scene: &str, extra: &[&str]) -> (Output, Vec<u8>) {
    let toml = scratch_file(
        &format!("{name}.toml"),
        format!("[volume]\nsize = 24\n{scene}"),
    );
    let png = scratch(&format!("{name}.png"));
    let out = render_at(&toml, &png, 24, extra);
    (out, std::fs::read(&png).unwrap_or_default())
}

/// `--azimuth` and `--elevation` apply over a scene's `view.direction` (they were silently ignored
/// before issue 14): the image is the orbit's, the angle not given read off the direction.
#[test]
fn command_line_angles_apply_over_a_scene_direction() {
    let dir = "[view]\ndirection = [0.0, -1.0, -1.0]\n";
    let (out, with_dir) = render_view("dir", dir, &[]);
    succeeded(&out, "render");
    let (out, both) = render_view("dir-both", dir, &["--azimuth", "10", "--elevation", "30"]);
    let stdout = succeeded(&out, "render");
    assert!(stdout.contains("view azimuth 10 elevation 30"), "{stdout}");
    let (out, orbit) = render_view("orbit", "[view]\nazimuth = 10\nelevation = 30\n", &[]);
    succeeded(&out, "render");
    assert_eq!(
        both, orbit,
        "--azimuth/--elevation must give the orbit's image"
    );
    assert_ne!(both, with_dir, "the angles were ignored");
    // Only the azimuth: the elevation is the direction's (45 degrees).
    let (out, az) = render_view("dir-az", dir, &["--azimuth", "10"]);
    let stdout = succeeded(&out, "render");
    let elevation = stdout
        .split("view azimuth 10 elevation ")
        .nth(1)
        .and_then(|t| t.split(',').next())
        .unwrap_or_else(|| panic!("{stdout}"));
    let e: f64 = elevation.parse().unwrap();
    assert!((e - 45.0).abs() < 1e-9, "{stdout}");
    let (out, orbit) = render_view(
        "orbit-45",
        &format!("[view]\nazimuth = 10\nelevation = {elevation}\n"),
        &[],
    );
    succeeded(&out, "render");
    assert_eq!(az, orbit);
}

/// `--roll` and `--up` apply as the scene's `view.roll` and `view.up` do, and bad values are
/// refused in one line.
#[test]
fn command_line_roll_and_up() {
    let (out, plain) = render_view("plain", "", &[]);
    succeeded(&out, "render");
    let (out, rolled) = render_view("rolled", "", &["--roll", "-30"]);
    let stdout = succeeded(&out, "render");
    assert!(stdout.contains("roll -30"), "{stdout}");
    let (out, scene_rolled) = render_view("scene-rolled", "[view]\nroll = -30\n", &[]);
    succeeded(&out, "render");
    assert_eq!(rolled, scene_rolled);
    assert_ne!(rolled, plain);
    let top = "[view]\ndirection = [0, 0, -1]\n";
    let (out, up) = render_view("up", top, &["--up", "-1,0,0"]);
    succeeded(&out, "render");
    let (out, scene_up) = render_view("scene-up", &format!("{top}up = [-1, 0, 0]\n"), &[]);
    succeeded(&out, "render");
    assert_eq!(up, scene_up);
    let (out, default_up) = render_view("default-up", top, &[]);
    succeeded(&out, "render");
    assert_ne!(up, default_up);
    let (out, png) = render_view("up-parallel", top, &["--up", "0,0,1"]);
    assert_refused(&out, "view.up");
    assert!(png.is_empty());
    let (out, _) = render_view("up-zero", "", &["--up", "0,0,0"]);
    assert_refused(&out, "view.up");
    let (out, _) = render_view("up-short", "", &["--up", "1,2"]);
    assert_refused(&out, "expected three numbers X,Y,Z");
    let (out, _) = render_view("roll-nan", "", &["--roll", "nan"]);
    assert_refused(&out, "view.roll");
}

/// Perspective scenes say which scheme ran: the reference's exact rays, or the what-if slab model
/// (`--slabs N` or `run.renderer = "slabs"`), whose error `--compare` prints.
#[test]
fn perspective_scenes_name_their_scheme() {
    let persp = "[view]\nprojection = \"perspective\"\nfov = 40\n[run]\nrenderer = \"reference\"\n";
    let (out, exact) = render_view("persp", persp, &[]);
    let stdout = succeeded(&out, "render");
    assert!(
        stdout.contains("plan: f64 reference renderer")
            && stdout.contains("perspective (exact rays from the eye"),
        "{stdout}"
    );
    let (out, slabs) = render_view("persp-slabs", persp, &["--slabs", "4", "--compare"]);
    let stdout = succeeded(&out, "render");
    assert!(
        stdout.contains("plan: what-if slab perspective (not the hardware: 4 equal slabs")
            && stdout.contains("error against the f64 reference: PSNR"),
        "{stdout}"
    );
    assert_ne!(exact, slabs);
    let (out, scene_slabs) = render_view(
        "scene-slabs",
        "[view]\nprojection = \"perspective\"\nfov = 40\nslabs = 4\n[run]\nrenderer = \"slabs\"\n",
        &[],
    );
    succeeded(&out, "render");
    assert_eq!(slabs, scene_slabs);
    let (out, _) = render_view("slabs-parallel", "", &["--slabs", "4"]);
    assert_refused(&out, "run.renderer");
    let (out, _) = render_view("slabs-and-ref", persp, &["--slabs", "4", "--reference"]);
    assert_refused(&out, "--reference and --slabs");
}

/// ER-perspective (`--er` or `run.renderer = "er"`): `plan:` names the scheme with its counts
/// (samples per slice against the N^2 .. 4N^2 bound), `--compare` its error against the exact
/// perspective; the scene and the flag render the same image; what it cannot take is refused by
/// the field's name.
#[test]
fn er_perspective_renders_and_names_its_counts() {
    let persp = "[view]\nprojection = \"perspective\"\nfov = 90\n[run]\nrenderer = \"reference\"\n";
    let (out, flag) = render_view("er-flag", persp, &["--er", "--compare"]);
    let stdout = succeeded(&out, "render");
    assert!(
        stdout.contains("plan: ER-perspective model")
            && stdout.contains("against the bound N^2 = ")
            && stdout.contains("perspective (ER-perspective: rays from the eye")
            && stdout.contains("early termination (ER-perspective composites back to front)")
            && stdout.contains("error against the f64 reference: PSNR"),
        "{stdout}"
    );
    let er = "[view]\nprojection = \"perspective\"\nfov = 90\n[run]\nrenderer = \"er\"\n";
    let (out, scene_er) = render_view("er-scene", er, &[]);
    succeeded(&out, "render");
    assert_eq!(flag, scene_er);
    let (out, centre) = render_view(
        "er-centre",
        "[view]\nprojection = \"perspective\"\nfov = 90\ner_merge = \"centre\"\n[run]\nrenderer = \"er\"\n",
        &[],
    );
    succeeded(&out, "render");
    assert_ne!(flag, centre, "two regions: the merge shows");
    for (name, text, field) in [
        ("er-parallel", "[run]\nrenderer = \"er\"\n", "run.renderer"),
        (
            "er-rate",
            "[view]\nprojection = \"perspective\"\ner_rays_per_voxel = 3\n[run]\nrenderer = \"er\"\n",
            "view.er_rays_per_voxel",
        ),
        (
            "er-xray",
            "[view]\nprojection = \"perspective\"\n[render]\nmode = \"xray\"\n[run]\nrenderer = \"er\"\n",
            "render.mode",
        ),
        (
            "er-sheared",
            "[view]\nprojection = \"perspective\"\n[quality]\ninterpolation = \"sheared\"\n[run]\nrenderer = \"er\"\n",
            "quality.interpolation",
        ),
        (
            "er-rtl",
            "[view]\nprojection = \"perspective\"\n[run]\nrenderer = \"er\"\ntarget = \"rtl\"\n",
            "run.renderer",
        ),
        (
            "er-eye-too-close",
            "[view]\nprojection = \"perspective\"\nfov = 169.0\ndirection = [1, 1, 1]\n[run]\nrenderer = \"er\"\n",
            "view.fov",
        ),
    ] {
        let (out, _) = render_view(name, text, &[]);
        assert_refused(&out, field);
    }
    let (out, _) = render_view("er-and-ref", persp, &["--er", "--reference"]);
    assert_refused(&out, "--er and --reference");
}

/// `cube5 transfer NAME` prints the preset's points (the peer benchmark's only copy of the
/// transfer function it hands VTK); an unknown name is refused.
#[test]
fn transfer_prints_a_presets_points() {
    let out = cube5(&["transfer", "head"]);
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    let points: Vec<Vec<f64>> = text
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    let tf = cube5_model::transfer::TransferFunction::head_default();
    assert_eq!(points.len(), tf.points.len(), "{text}");
    for (p, want) in points.iter().zip(&tf.points) {
        assert_eq!(p[0], want.density, "{text}");
        assert_eq!(&p[1..], &want.rgba[..], "{text}");
    }
    assert_refused(&cube5(&["transfer", "nonesuch"]), "nonesuch");
}
