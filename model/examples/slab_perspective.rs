//! Approximate perspective by parallel slabs (`slab_perspective`): its error against the f64
//! perspective reference as a function of the slab count, for equal, geometric and doubling slabs, on
//! `scenes/head-perspective.toml` (docs/measurements.md, "Slab perspective").
//!
//! `cargo run --release -p cube5-model --example slab_perspective -- [--size N] [--image PX]
//! [--counts 1,2,4,8,16,32] [--png DIR] [--mode composite|mip]`; defaults: the scene's 96^3 and 256^2.

mod support;

use cube5_model::render::image_error;
use cube5_model::render::render_reference;
use cube5_model::slab_perspective::{render_slabs, SlabSpacing, Slabs};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut counts = vec![1u32, 2, 4, 8, 16, 32];
    let (scene, png) = support::perspective_scene(|flag, value| {
        if flag != "--counts" {
            return Ok(false);
        }
        counts = support::list(value)?;
        Ok(true)
    })?;
    let vol = scene.build_volume()?;
    let tf = scene.transfer_function();
    let params = scene.render_params();
    let t = Instant::now();
    let reference = render_reference(&vol, &tf, &params)?;
    if let Some(dir) = &png {
        std::fs::create_dir_all(dir)?;
        reference.to_rgb8().save(dir.join("reference.png"))?;
    }
    println!(
        "head phantom {}^3, {}, {}x{} pixels, fov {}, zoom {}, step {}; reference {:.2} s",
        vol.dims[0],
        params.mode.name(),
        params.width,
        params.height,
        params.fov,
        params.zoom,
        params.step,
        t.elapsed().as_secs_f64()
    );
    println!(
        "| slabs | spacing | PSNR (dB) | max abs (/255) | relative Euclidean (%) | time (s) |"
    );
    println!("|---:|---|---:|---:|---:|---:|");
    for spacing in [
        SlabSpacing::Equal,
        SlabSpacing::Geometric,
        SlabSpacing::Doubling,
    ] {
        for &count in &counts {
            let t = Instant::now();
            let img = render_slabs(&vol, &tf, &params, Slabs { count, spacing })?;
            let secs = t.elapsed().as_secs_f64();
            let e = image_error(&img, &reference);
            if let Some(dir) = &png {
                img.to_rgb8()
                    .save(dir.join(format!("slabs-{}-{count}.png", spacing.name())))?;
            }
            println!(
                "| {count} | {} | {:.1} | {:.1} | {:.2} | {secs:.2} |",
                spacing.name(),
                e.psnr_db,
                e.max_abs * 255.0,
                e.rel_euclid
            );
        }
    }
    Ok(())
}
