//! The frame model's speed: samples/s of the fast path (and, with `--reference`, of the
//! per-sample reference) on the head phantom, composite shaded and MIP, at 1 and 2 threads.
//! `cargo run --release -p cube5-model --example frame_speed -- [N ...] [--reference]`

use cube5_model::phantom::head_phantom;
use cube5_model::transfer::TransferFunction;
use cube5_model::units::cube5_frame::{
    frame_phong, render_base_plane_reference, render_base_plane_stats, FrameMode, FrameSetup,
    FrameUnits,
};
use glam::DVec3;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let reference = args.iter().any(|a| a == "--reference");
    let sizes: Vec<usize> = args.iter().filter_map(|a| a.parse().ok()).collect();
    let sizes = if sizes.is_empty() {
        vec![128, 256]
    } else {
        sizes
    };
    let tf = TransferFunction::head_default();
    for n in sizes {
        let vol = head_phantom(n, 12)?;
        let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::new(-0.37, 0.81, -1.0), 4)?;
        let p = setup.params;
        for mode in [FrameMode::Composite, FrameMode::Mip] {
            let units = FrameUnits::new(mode, &setup, &tf, &frame_phong(&p, &[]))?;
            for threads in [1, 2] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()?;
                let (secs, stats) = pool.install(|| {
                    let t = Instant::now();
                    let (_, st) = render_base_plane_stats(&p, &vol, &units);
                    (t.elapsed().as_secs_f64(), st)
                });
                println!(
                    "{n}^3 {mode:?} threads {threads}: fast {:.1} ms, {:.1} M samples/s  {stats:?}",
                    secs * 1e3,
                    p.samples() as f64 / secs / 1e6
                );
                if reference {
                    let secs = pool.install(|| {
                        let t = Instant::now();
                        let _ = render_base_plane_reference(&p, &vol, &units);
                        t.elapsed().as_secs_f64()
                    });
                    println!(
                        "{n}^3 {mode:?} threads {threads}: reference {:.1} ms, {:.2} M samples/s",
                        secs * 1e3,
                        p.samples() as f64 / secs / 1e6
                    );
                }
            }
        }
    }
    Ok(())
}
