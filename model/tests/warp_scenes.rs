//! Every example scene the frame renders (`scenes/*.toml`): the image `cube5 render` shows (the
//! warp unit's model on the frame's base plane) against the warp's f64 ideal on the same base-plane
//! codes, and against the f64 warp of the unquantized coxels (what `cube5 render` showed before the
//! warp unit): within the contract's bound, and >= 40 dB.

use cube5_model::render::image_error;
use cube5_model::scene::Scene;
use cube5_model::scene_render::{frame_config, not_expressible, FrameJob};
use cube5_model::units::cube5_warp;

#[test]
fn every_frame_scene_is_warped_within_the_contract() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    names.sort();
    let mut warped = 0;
    for path in names {
        let scene = Scene::load(&path).unwrap();
        if !not_expressible(&scene).is_empty() {
            continue;
        }
        let vol = scene.build_volume().unwrap();
        let job = FrameJob::new(&scene, &vol, frame_config(&scene).unwrap(), 1).unwrap();
        let run = job.render();
        let img = job.image(&scene, &run.base).unwrap();
        let ideal = job.image_reference(&scene, &run.base).unwrap();
        let old = job.image_f64_coxels(&scene, &run.base);
        let (e, e_old) = (image_error(&img, &ideal), image_error(&img, &old));
        let cfg = job.warp_config();
        let w = img.width;
        for (i, (a, b)) in img.rgb.iter().zip(&ideal.rgb).enumerate() {
            let bound = cube5_warp::error_bound(&cfg, i as u32 % w, i as u32 / w);
            for ch in 0..3 {
                let err = (a[ch] - b[ch]).abs() * 255.0;
                assert!(
                    err <= bound + 1e-9,
                    "{}: pixel {i} channel {ch}: {err} codes > {bound}",
                    path.display()
                );
            }
        }
        eprintln!(
            "{}: {}x{}: warp vs its f64 ideal PSNR {:.2} dB (max {:.2} codes); vs the f64 warp of the coxels {:.2} dB",
            path.file_name().unwrap().to_string_lossy(),
            img.width,
            img.height,
            e.psnr_db,
            e.max_abs * 255.0,
            e_old.psnr_db
        );
        assert!(e.psnr_db >= 40.0 && e_old.psnr_db >= 40.0);
        warped += 1;
    }
    assert!(warped >= 3, "only {warped} frame scenes");
}
