//! ER-perspective (`er_perspective`): its error against the f64 perspective reference renderer and
//! against its own f64 reference, samples per slice against the N^2 .. 4N^2 bound, and time per
//! frame, over fields of view and knob settings, on `scenes/head-perspective.toml`
//! (docs/tradeoffs.md, "ER-perspective").
//!
//! `cargo run --release -p cube5-model --example er_perspective -- [--size N] [--image PX]
//! [--fovs 20,40,60,90] [--rates 1,2] [--mode composite|mip] [--png DIR]`; defaults: the scene's
//! 96^3 and 256^2.

mod support;

use cube5_model::er_perspective::{render_er, render_er_f64, ErMerge, ErScheme};
use cube5_model::render::image_error;
use cube5_model::render::render_reference;
use cube5_model::scene_render::frame_config;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (mut fovs, mut rates) = (vec![20.0, 40.0, 60.0, 90.0], vec![1u32, 2]);
    let (scene, png) = support::perspective_scene(|flag, value| {
        match flag {
            "--fovs" => fovs = support::list(value)?,
            "--rates" => rates = support::list(value)?,
            _ => return Ok(false),
        }
        Ok(true)
    })?;
    let vol = scene.build_volume()?;
    let tf = scene.transfer_function();
    let cfg = frame_config(&scene)?;
    if let Some(dir) = &png {
        std::fs::create_dir_all(dir)?;
    }
    println!(
        "head phantom {}^3, {}, {}x{} pixels, zoom {}; reference step {}",
        vol.dims[0],
        scene.render.mode.name(),
        scene.image.width,
        scene.image.height,
        scene.view.zoom,
        scene.render.step
    );
    println!("| fov | rays/voxel | merge | PSNR vs reference (dB) | max abs (/255) | rel. Euclidean (%) | PSNR vs own f64 (dB) | regions | samples/slice min..max (N^2 = ) | time (s) |");
    println!("|---:|---:|---|---:|---:|---:|---:|---:|---|---:|");
    for &fov in &fovs {
        let mut params = scene.render_params();
        params.fov = fov;
        let reference = render_reference(&vol, &tf, &params)?;
        if let Some(dir) = &png {
            reference
                .to_rgb8()
                .save(dir.join(format!("reference-fov{fov}.png")))?;
        }
        for &rays_per_voxel in &rates {
            for merge in [ErMerge::Bartlett, ErMerge::Centre] {
                let scheme = ErScheme {
                    rays_per_voxel,
                    merge,
                };
                let t = Instant::now();
                let run = render_er(&vol, &tf, &params, &cfg, scheme)?;
                let secs = t.elapsed().as_secs_f64();
                let (f64_img, _) = render_er_f64(&vol, &tf, &params, scheme)?;
                let e = image_error(&run.image, &reference);
                let own = image_error(&run.image, &f64_img);
                if let Some(dir) = &png {
                    run.image.to_rgb8().save(dir.join(format!(
                        "er-fov{fov}-r{rays_per_voxel}-{}.png",
                        merge.name()
                    )))?;
                }
                let s = &run.stats;
                println!(
                    "| {fov} | {rays_per_voxel} | {} | {:.1} | {:.1} | {:.2} | {:.1} | {} | {}..{} ({}) | {secs:.2} |",
                    merge.name(),
                    e.psnr_db,
                    e.max_abs * 255.0,
                    e.rel_euclid,
                    own.psnr_db,
                    s.regions,
                    s.min_per_slice(),
                    s.max_per_slice(),
                    s.n2
                );
            }
        }
    }
    Ok(())
}
