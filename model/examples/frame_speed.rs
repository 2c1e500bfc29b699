//! The frame model's speed: samples/s of the fast path (and, with `--reference`, of the
//! per-sample reference) on the head phantom, composite shaded and MIP, at 1 and 2 threads. The
//! fast path's frame is `render_sweep` on a `SweepVolume` made once (as `cube5 render` does).
//! `cargo run --release -p cube5-model --example frame_speed -- [N ...] [--reference]`

use cube5_model::phantom::head_phantom;
use cube5_model::transfer::TransferFunction;
use cube5_model::units::cube5_frame::{
    frame_phong, render_base_plane_reference, render_sweep, FrameMode, FrameSetup, FrameUnits,
    SweepVolume,
};
use glam::DVec3;
use std::time::Instant;

#[path = "support/cpu.rs"]
mod cpu;
use cpu::cpu_secs;

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
        let sv = SweepVolume::new(&p, &vol).ok_or("the phantom does not fit its set-up")?;
        for mode in [FrameMode::Composite, FrameMode::Mip] {
            if args.iter().any(|a| a == "--mip") && mode != FrameMode::Mip
                || args.iter().any(|a| a == "--composite") && mode != FrameMode::Composite
            {
                continue;
            }
            let units = FrameUnits::new(mode, &setup, &tf, &frame_phong(&p, &[]))?;
            for threads in [1, 2] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()?;
                let (secs, cpu, stats) = pool.install(|| {
                    let (t, c0) = (Instant::now(), cpu_secs());
                    let mut runs = 0;
                    let mut st = None;
                    while runs < 3 || t.elapsed().as_secs_f64() < 1.0 {
                        st = Some(render_sweep(&p, &sv, &units).1);
                        runs += 1;
                    }
                    let r = f64::from(runs);
                    (t.elapsed().as_secs_f64() / r, (cpu_secs() - c0) / r, st)
                });
                println!(
                    "{n}^3 {mode:?} threads {threads}: fast {:.1} ms, {:.1} M samples/s, {:.1} M samples per CPU-s  {stats:?}",
                    secs * 1e3,
                    p.samples() as f64 / secs / 1e6,
                    p.samples() as f64 / cpu / 1e6,
                );
                if reference {
                    let (secs, cpu) = pool.install(|| {
                        let (t, c0) = (Instant::now(), cpu_secs());
                        let _ = render_base_plane_reference(&p, &vol, &units);
                        (t.elapsed().as_secs_f64(), cpu_secs() - c0)
                    });
                    println!(
                        "{n}^3 {mode:?} threads {threads}: reference {:.1} ms, {:.2} M samples/s, {:.2} M samples per CPU-s",
                        secs * 1e3,
                        p.samples() as f64 / secs / 1e6,
                        p.samples() as f64 / cpu / 1e6
                    );
                }
            }
        }
    }
    Ok(())
}
