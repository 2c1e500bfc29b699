//! Approximate perspective by parallel slabs (`slab_perspective`, docs/numerics/slab_perspective.md):
//! its error against the f64 perspective reference falls as the slab count grows.

use cube5_model::render::image_error;
use cube5_model::render::{render_reference, CompositeMode, Projection, RenderParams};
use cube5_model::scene::Scene;
use cube5_model::slab_perspective::{render_slabs, SlabSpacing, Slabs};

/// `scenes/head-perspective.toml` at 48^3 and 97 x 97 pixels (an odd size: one pixel on the axis).
fn scene(mode: &str) -> Scene {
    let mut scene = Scene::load(&cube5_model::repo_root().join("scenes/head-perspective.toml"))
        .expect("the example scene");
    scene.volume.size = 48;
    scene.image.width = 97;
    scene.image.height = 97;
    scene.render.mode = match mode {
        "mip" => CompositeMode::Mip,
        _ => CompositeMode::Composite,
    };
    scene
}

fn psnr_by_count(scene: &Scene, spacing: SlabSpacing, counts: &[u32]) -> Vec<f64> {
    let vol = scene.build_volume().unwrap();
    let tf = scene.transfer_function();
    let params = scene.render_params();
    let reference = render_reference(&vol, &tf, &params).unwrap();
    counts
        .iter()
        .map(|&count| {
            let img = render_slabs(&vol, &tf, &params, Slabs { count, spacing }).unwrap();
            // The axis is the parallel ray of every slab: its pixel is the reference's.
            let centre = (params.width * params.height / 2) as usize;
            assert_eq!(img.rgb[centre], reference.rgb[centre], "{count} slabs");
            image_error(&img, &reference).psnr_db
        })
        .collect()
}

#[test]
fn the_error_falls_as_the_slab_count_grows() {
    let counts = [2, 4, 8, 16, 32];
    for (mode, spacing, at_32) in [
        ("composite", SlabSpacing::Equal, 38.0),
        ("composite", SlabSpacing::Geometric, 38.0),
        ("mip", SlabSpacing::Equal, 39.0),
    ] {
        let psnr = psnr_by_count(&scene(mode), spacing, &counts);
        eprintln!("{mode} {}: {psnr:.1?}", spacing.name());
        for (w, c) in psnr.windows(2).zip(counts.windows(2)) {
            assert!(
                w[1] > w[0],
                "{mode}, {} slabs: {} -> {} slabs: PSNR {:.2} -> {:.2} dB",
                spacing.name(),
                c[0],
                c[1],
                w[0],
                w[1]
            );
        }
        assert!(
            psnr[4] > at_32,
            "{mode}, 32 {} slabs: {:.2} dB",
            spacing.name(),
            psnr[4]
        );
    }
}

#[test]
fn only_perspective_views_and_sane_counts() {
    let scene = scene("composite");
    let vol = scene.build_volume().unwrap();
    let tf = scene.transfer_function();
    let parallel = RenderParams {
        projection: Projection::Parallel,
        ..scene.render_params()
    };
    let slabs = Slabs {
        count: 4,
        spacing: SlabSpacing::Equal,
    };
    assert!(render_slabs(&vol, &tf, &parallel, slabs).is_err());
    let none = Slabs { count: 0, ..slabs };
    assert!(render_slabs(&vol, &tf, &scene.render_params(), none).is_err());
    let err = |text: &str| Scene::parse(text, "s.toml").unwrap_err().to_string();
    assert!(err("[run]\nrenderer = \"slabs\"\n").contains("run.renderer"));
    let e =
        err("[view]\nprojection = \"perspective\"\nslabs = 1000\n[run]\nrenderer = \"slabs\"\n");
    assert!(e.contains("view.slabs"), "{e}");
    let e = err(
        "[view]\nprojection = \"perspective\"\n[run]\nrenderer = \"slabs\"\ntarget = \"rtl\"\n",
    );
    assert!(e.contains("run.renderer") && e.contains("slabs"), "{e}");
}
