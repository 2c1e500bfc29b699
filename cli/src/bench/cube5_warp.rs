//! Benchmark of cube5_warp: load and warp speed (texels and pixels per clock, simulated cycles per
//! second, model pixels per second), and the error against the f64 bilinear warp.

use super::common::{open, ErrorStats};
use anyhow::{ensure, Result};
use cube5_model::unit::{StreamUnit, UnitConfig};
use cube5_model::units::cube5_warp::{
    self, frame_items, Affine, BaseCodes, Warp, WarpConfig, WarpOut, WarpRegs,
};
use cube5_tb::rtl::Traffic;
use cube5_tb::variants_of;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

pub const TOP: &str = WarpConfig::TOP;

/// The base plane rotated by `deg` and magnified `zoom` times about its centre onto `out^2` pixels.
fn rotation(side: usize, out: u32, deg: f64, zoom: f64) -> Affine {
    let s = side as f64 / f64::from(out) / zoom;
    let (c, si) = (deg.to_radians().cos() * s, deg.to_radians().sin() * s);
    let (h, o) = (side as f64 / 2.0, f64::from(out) / 2.0);
    Affine {
        x0: h - o * c + o * si,
        y0: h - o * si - o * c,
        xpx: c,
        ypx: si,
        xpy: -si,
        ypy: c,
    }
}

pub fn run(n_items: usize) -> Result<()> {
    println!("One frame per configuration: a random base plane of min(MaxBase, 128)^2 texels loaded, then");
    println!("warped (rotated 30 degrees, zoom 1.3) onto an image of about `--items` pixels (at most MaxOut^2),");
    println!("at full speed; the RTL's pixels are compared with the model's.\n");
    println!("| unit | config | texels | load cycles | texels/clock | pixels | warp cycles | pixels/clock | sim cycles/s | model pixels/s | DP16KD (4 banks) |");
    println!("|------|--------|-------:|------------:|-------------:|-------:|------------:|-------------:|-------------:|---------------:|-----------------:|");
    for v in variants_of(TOP) {
        let cfg: WarpConfig = v.config()?;
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let side = cfg.max_base.min(128) as usize;
        let out = ((n_items as f64).sqrt() as u32).clamp(4, cfg.max_out);
        let base = BaseCodes::random(&mut rng, side, side, cfg.color_w);
        let regs = WarpRegs::set_up(
            &rotation(side, out, 30.0, 1.3),
            (side as u32, side as u32),
            (out, out),
        )?;
        let mut items = frame_items(&cfg, &regs, &base);
        let go = items.pop().expect("a frame ends with Go");
        let mut dut = open(v, cfg, &[])?;
        let texels = items.len() as u64;
        let load = dut.drive(&items, &Traffic::full_speed(), 0, 4 * texels + 1000)?;
        ensure!(
            load.stats.consumed == texels,
            "{v}: the base plane was not taken"
        );
        let n = u64::from(out * out);
        let t = Instant::now();
        let driven = dut.drive(&[go], &Traffic::full_speed(), n, 2 * n + 1000)?;
        let sim_secs = t.elapsed().as_secs_f64();
        let mut model = Warp::new(cfg)?;
        let t = Instant::now();
        let want = model.run(&frame_items(&cfg, &regs, &base));
        let model_secs = t.elapsed().as_secs_f64();
        let got: Vec<WarpOut> = driven.outputs.iter().map(|t| t.value).collect();
        ensure!(got == want, "{v}: RTL and model images differ");
        let cycles = driven.stats.cycles;
        println!(
            "| {TOP} | {} | {texels} | {} | {:.4} | {n} | {cycles} | {:.4} | {:.2e} | {:.2e} | {} |",
            v.config,
            load.stats.cycles,
            texels as f64 / load.stats.cycles as f64,
            n as f64 / cycles as f64,
            cycles as f64 / sim_secs,
            n as f64 / model_secs,
            cfg.dp16kd()
        );
    }
    println!();
    println!(
        "Error of {TOP} against the f64 bilinear warp (`cube5_warp::reference`) over 20 random"
    );
    println!(
        "rotations and zooms (0.5..4) of random base planes, in output codes (1/255); the contract"
    );
    println!("bound at the image's far corner is in the last column:");
    println!();
    println!("| config | values | max abs error (codes) | RMS error (codes) | mean error (codes) | bound |");
    println!("|--------|-------:|----------------------:|------------------:|-------------------:|------:|");
    for v in variants_of(TOP) {
        let cfg: WarpConfig = v.config()?;
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let side = cfg.max_base.min(64) as usize;
        let out = cfg.max_out.min(128);
        let mut s = ErrorStats::default();
        for _ in 0..20 {
            let base = BaseCodes::random(&mut rng, side, side, cfg.color_w);
            let a = rotation(
                side,
                out,
                rng.random_range(0.0..360.0),
                rng.random_range(0.5..4.0),
            );
            let regs = WarpRegs::set_up(&a, (side as u32, side as u32), (out, out))?;
            let got = cube5_warp::warp_image(&cfg, &regs, &base);
            let ideal = cube5_warp::reference(&a, &base, cfg.color_w, (out, out));
            for (g, r) in got.iter().zip(&ideal.rgb) {
                for ch in 0..3 {
                    s.add(f64::from(g[ch]) - 255.0 * r[ch]);
                }
            }
        }
        println!(
            "| {} | {} | {:.3} | {:.3} | {:+.4} | {:.3} |",
            v.config,
            s.n,
            s.max_abs,
            s.rms(),
            s.mean(),
            cube5_warp::error_bound(&cfg, out - 1, out - 1)
        );
    }
    Ok(())
}
