//! Where a `cube5 render` frame's time goes, stage by stage, on a scene file (the peer
//! benchmark's scenes): the sweep (`render_sweep`), the rest of `FrameJob::render` (the hardware's
//! counts), and the image (codes, warp, 8-bit to f64). Best of N frames per stage, one thread
//! unless `RAYON_NUM_THREADS` says otherwise.
//! `cargo run --release -p cube5-model --example peer_profile -- SCENE.toml [N] [sweep]`; with
//! `sweep`, only the sweep, N times (for `perf record`).

use cube5_model::scene::Scene;
use cube5_model::scene_render::{frame_config, FrameJob};
use cube5_model::units::cube5_frame::render_sweep;
use cube5_model::units::cube5_warp;
use std::path::Path;
use std::time::Instant;

#[path = "support/cpu.rs"]
mod cpu;
use cpu::cpu_secs;

/// Best wall ms and mean CPU ms of `n` runs of `f` (after one more), and its last output.
fn best_ms<T>(n: usize, mut f: impl FnMut() -> T) -> ((f64, f64), T) {
    let mut best = f64::INFINITY;
    let mut out = f();
    let c0 = cpu_secs();
    for _ in 0..n {
        let t = Instant::now();
        out = f();
        best = best.min(t.elapsed().as_secs_f64() * 1e3);
    }
    ((best, (cpu_secs() - c0) * 1e3 / n as f64), out)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene = Scene::load(Path::new(
        args.first().ok_or("usage: peer_profile SCENE [N]")?,
    ))?;
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(7);
    let vol = scene.build_volume()?;
    let job = FrameJob::new(&scene, &vol, frame_config(&scene)?, 1)?;
    let params = &job.setup.params;
    if args.get(2).map(String::as_str) == Some("sweep") {
        let ((wall, cpu), (_, stats)) = best_ms(n, || render_sweep(params, &job.sweep, &job.units));
        println!("sweep {wall:.2} ms (CPU {cpu:.1}); {stats:?}");
        return Ok(());
    }
    let (sweep, (base, stats)) = best_ms(n, || render_sweep(params, &job.sweep, &job.units));
    let (render, _) = best_ms(n, || job.render());
    let (_, regs) = job.warp_setup(&scene, &base)?;
    let (codes_ms, codes) = best_ms(n, || cube5_warp::base_codes(&base, &job.cfg.compos));
    let (warp_ms, pixels) = best_ms(n, || {
        cube5_warp::warp_image(&job.warp_config(), &regs, &codes)
    });
    let (img_ms, _) = best_ms(n, || cube5_warp::to_image(regs.out_w, regs.out_h, &pixels));
    let (image_ms, _) = best_ms(n, || job.image(&scene, &base));
    let ms = |(wall, cpu): (f64, f64)| format!("{wall:.2} ms (CPU {cpu:.1})");
    println!(
        "sweep {}, render (sweep + counts) {}, image {} (codes {}, warp {}, to_image {}); threads {}; {stats:?}",
        ms(sweep),
        ms(render),
        ms(image_ms),
        ms(codes_ms),
        ms(warp_ms),
        ms(img_ms),
        rayon::current_num_threads()
    );
    Ok(())
}
