//! The GI-Cube processor's figures for docs/measurements.md (issue 15): PSNR of the fixed-point
//! renderer against its f64 reference on the head phantom (parallel and perspective, 32^3 and
//! 64^3), the frame counts, the model's speed; the GI shadow scene: irradiance and image against
//! the f64 GI, the GI method against the Monte Carlo reference, and the PNG.
//!
//! ```text
//! cargo run --release -p cube5-model --example gicube_processor -- [--png FILE] [--mc-paths N]
//! ```

use cube5_model::camera::Camera;
use cube5_model::phantom::head_phantom;
use cube5_model::render::ImageF64;
use cube5_model::transfer::TransferFunction;
use cube5_model::units::gicube_processor::{
    irradiance_error, monte_carlo_gi, psnr, shadow_scene, GiLight, GiMode, Processor,
    ProcessorConfig, Projection,
};
use glam::DVec3;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let opt = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let png = opt("--png");
    let mc_paths: u32 = opt("--mc-paths").map_or(Ok(256), |s| s.parse())?;

    // Direct volume rendering of the head phantom.
    let (a, e) = (65f64.to_radians(), 20f64.to_radians());
    let dir = -DVec3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin());
    let tf = TransferFunction::head_default();
    println!("| volume | image | projection | PSNR dB | max | rays | overflowed | samples | leaps | terminated | cycles | samples/clock | activations | mean occupancy | max queue | cache hit rate | model Msamples/s |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (n, px, block_log2) in [(32usize, 64u32, 3u32), (64, 128, 4)] {
        let vol = head_phantom(n, 12)?;
        let cam = Camera::new(dir, vol.dims, vol.spacing, px, px);
        let cfg = ProcessorConfig {
            block_log2,
            ..ProcessorConfig::DEFAULT
        };
        let p = Processor::new(cfg, &vol, &tf)?;
        for proj in [
            Projection::Parallel,
            Projection::Perspective { fov_deg: 30.0 },
        ] {
            let t0 = Instant::now();
            let f = p.render(&cam, proj)?;
            let secs = t0.elapsed().as_secs_f64();
            let r = p.reference(&tf, &cam, proj)?;
            let (db, max) = psnr(&f.to_f64(), &r);
            let c = f.counts;
            let name = match proj {
                Projection::Parallel => "parallel".to_string(),
                Projection::Perspective { fov_deg } => format!("perspective {fov_deg}"),
            };
            println!(
                "| {n}^3 (blocks {}^3) | {px}^2 | {name} | {db:.1} | {max:.3} | {} | {} | {} | {} | {} | {} | {:.3} | {} | {:.0} | {} | {:.3} | {:.2} |",
                1 << block_log2,
                c.rays_made,
                c.rays_overflowed,
                c.samples,
                c.leaps,
                c.rays_terminated,
                c.cycles,
                c.samples as f64 / c.cycles as f64,
                c.activations,
                c.mean_occupancy(),
                c.max_queue,
                c.cache_hit_rate(),
                c.samples as f64 / secs / 1e6
            );
        }
    }

    // The GI shadow scene.
    let n = 64;
    let (vol, tf, light) = shadow_scene(n)?;
    let cfg = ProcessorConfig {
        block_log2: 4,
        ..ProcessorConfig::DEFAULT
    };
    let mut p = Processor::new(cfg, &vol, &tf)?;
    let px = 128;
    let cam = Camera::new(
        DVec3::new(0.35, 0.75, -0.55).normalize(),
        vol.dims,
        vol.spacing,
        px,
        px,
    );
    let unlit = p.render(&cam, Projection::Parallel)?;
    let t0 = Instant::now();
    let lc = p.light(&light)?;
    let t_light = t0.elapsed().as_secs_f64();
    let field = p.irradiance().unwrap_or_default().to_vec();
    let rf = p.reference_irradiance(&tf, &light)?;
    let (imax, imean) = irradiance_error(&field, &rf, vol.dims);
    let gi = p.render(&cam, Projection::Parallel)?;
    let rgi = p.reference_gi(&tf, &light, &cam, Projection::Parallel)?;
    let (db, max) = psnr(&gi.to_f64(), &rgi);
    let c = lc.counts;
    println!("\nGI shadow scene {n}^3, light grid {}^2:", light.grid);
    println!(
        "lighting pass: {} rays, {} overflowed, {} samples, {} terminated, {} cycles, mean occupancy {:.0}, max queue {}, cache hit rate {:.3}, {:.2} Msamples/s",
        c.rays_made,
        c.rays_overflowed,
        c.samples,
        c.rays_terminated,
        c.cycles,
        c.mean_occupancy(),
        c.max_queue,
        c.cache_hit_rate(),
        c.samples as f64 / t_light / 1e6
    );
    println!("irradiance vs f64: interior max {imax:.4}, mean {imean:.5}");
    println!("GI image ({px}^2) vs f64 GI: PSNR {db:.1} dB, max {max:.3}");
    let t0 = Instant::now();
    let mc_seed = |seed| {
        monte_carlo_gi(
            &vol,
            &tf,
            &light,
            &cam,
            Projection::Parallel,
            4,
            mc_paths,
            seed,
        )
    };
    let (mc, mc2) = (mc_seed(1)?, mc_seed(2)?);
    let (db_mc, max_mc) = psnr(&rgi, &mc);
    let (db_fx, _) = psnr(&gi.to_f64(), &mc);
    let (db_noise, _) = psnr(&mc2, &mc);
    let (db_unlit, _) = psnr(&unlit.to_f64(), &mc);
    println!(
        "Monte Carlo ({mc_paths} paths/pixel, {:.1} s for two seeds): f64 GI vs MC {db_mc:.1} dB (max {max_mc:.3}); fixed-point GI vs MC {db_fx:.1} dB; MC seed 1 vs seed 2 {db_noise:.1} dB (noise floor: the GI-vs-MC figure is bounded by about this + 3 dB); unshadowed DVR vs MC {db_unlit:.1} dB",
        t0.elapsed().as_secs_f64()
    );
    // High albedo: photons that scatter (albedo 0.8, up to 8 bounces).
    let hi = GiLight {
        mode: GiMode::HighAlbedo {
            albedo: 0.8,
            lifetime: 8,
        },
        ..light
    };
    let t0 = Instant::now();
    let hc = p.light(&hi)?.counts;
    let t_hi = t0.elapsed().as_secs_f64();
    let gi_hi = p.render(&cam, Projection::Parallel)?;
    let t0 = Instant::now();
    let mc_hi = monte_carlo_gi(&vol, &tf, &hi, &cam, Projection::Parallel, 4, mc_paths, 1)?;
    let t_mc = t0.elapsed().as_secs_f64();
    let (db_hi, max_hi) = psnr(&gi_hi.to_f64(), &mc_hi);
    let (db_hi_single, _) = psnr(&gi_hi.to_f64(), &mc);
    let (db_hi_noise, _) = psnr(
        &mc_hi,
        &monte_carlo_gi(&vol, &tf, &hi, &cam, Projection::Parallel, 4, mc_paths, 2)?,
    );
    println!(
        "high albedo 0.8: {} photons, {} scatterings, {} absorbed, {} overflowed, {} samples, {:.2} Msamples/s; GI vs MC (high albedo, {mc_paths} paths, {t_mc:.1} s) {db_hi:.1} dB (max {max_hi:.3}), MC seed 1 vs 2 {db_hi_noise:.1} dB; high-albedo GI vs single-scattering MC {db_hi_single:.1} dB",
        hc.rays_made,
        hc.scatterings,
        hc.absorbed,
        hc.rays_overflowed,
        hc.samples,
        hc.samples as f64 / t_hi / 1e6
    );
    if let Some(path) = png {
        // Four panels: unshadowed DVR | GI-Cube GI low albedo | Monte Carlo single scattering |
        // GI-Cube GI high albedo.
        let panels = [unlit.to_f64(), gi.to_f64(), mc, gi_hi.to_f64()];
        let mut img = image::RgbImage::new(px * 4, px);
        for (k, rgb) in panels.into_iter().enumerate() {
            let one = ImageF64 {
                width: px,
                height: px,
                rgb,
            }
            .to_rgb8();
            for (x, y, pix) in one.enumerate_pixels() {
                img.put_pixel(x + px * k as u32, y, *pix);
            }
        }
        img.save(&path)?;
        println!("wrote {path}");
    }
    Ok(())
}
