//! The perspective warp `cube5_pwarp` (docs/numerics/pwarp.md): source reads of its
//! parallel-preserving scanlines against the naive inverse warp's four per pixel (patent
//! [84]-[87]), and its error against the f64 projective warp at the pixel centres and at the
//! samples' own points (docs/measurements.md, "Perspective warp"; docs/tradeoffs.md).
//!
//! `cargo run --release -p cube5-model --example pwarp_reads -- [views per size]` (default 16):
//! random views of a 128 x 128 base plane (field of view 30-60 degrees, tilts up to 35 degrees,
//! any roll, zoom 0.8-1.25: the plane seen within 35 degrees of square on, as ER-perspective sees its base plane) at 64^2, 128^2, 256^2 and 512^2 pixels, seed 14.

use cube5_model::render::image_error;
use cube5_model::units::cube5_pwarp::{
    read_counts, reference, reference_at_samples, warp_image, warp_samples, Projective,
    PwarpConfig, PwarpSetup,
};
use cube5_model::units::cube5_warp::{to_image, BaseCodes};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let views: usize = match std::env::args().nth(1) {
        Some(a) => a.parse()?,
        None => 16,
    };
    let cfg = PwarpConfig::DEFAULT;
    let mut rng = ChaCha8Rng::seed_from_u64(14);
    let (bw, bh) = (128u32, 128u32);
    // A smooth plane with detail: a sum of two sinusoids per channel (an image-like base plane).
    let base = BaseCodes {
        width: bw as usize,
        height: bh as usize,
        codes: (0..bw * bh)
            .map(|i| {
                let (x, y) = (f64::from(i % bw), f64::from(i / bw));
                std::array::from_fn(|ch| {
                    let f = 0.05 + 0.07 * ch as f64;
                    let v = 0.5 + 0.25 * (x * f).sin() + 0.25 * (y * f * 1.3 + ch as f64).cos();
                    (v * 255.0).round().clamp(0.0, 255.0) as u32
                })
            })
            .collect(),
    };
    println!("| image | views | scanlines | pixels | naive reads (4 taps) | scanline reads, 1-line buffer | 2-line buffer | distinct texels | naive / 2-line | PSNR vs f64 at pixel centres (dB) | max abs (codes) | max abs at sample points (codes) |");
    println!("|------:|------:|----------:|-------:|--------------------:|----------:|----------:|---------:|------:|------:|------:|------:|");
    for size in [64u32, 128, 256, 512] {
        let (mut lines, mut c) = (
            0usize,
            cube5_model::units::cube5_pwarp::ReadCounts::default(),
        );
        let (mut mse, mut maxabs, mut maxsample) = (0.0f64, 0.0f64, 0.0f64);
        for _ in 0..views {
            let map = Projective::tilted(
                (size, size),
                (bw, bh),
                rng.random_range(30.0..60.0),
                [
                    rng.random_range(-35.0..35.0),
                    rng.random_range(-35.0..35.0),
                    rng.random_range(-180.0..180.0),
                ],
                rng.random_range(0.8..1.25),
                (f64::from(bw) / 2.0, f64::from(bh) / 2.0),
            );
            let setup = PwarpSetup::new(&map, (bw, bh), (size, size))?;
            let r = read_counts(&setup);
            lines += setup.lines.len();
            c.pixels += r.pixels;
            c.naive += r.naive;
            c.buffered1 += r.buffered1;
            c.buffered2 += r.buffered2;
            c.distinct += r.distinct;
            let img = to_image(size, size, &warp_image(&cfg, &setup, &base)?);
            let e = image_error(&img, &reference(&map, &base, cfg.color_w, (size, size)));
            // The views' mean squared error (a view with no error adds 0).
            mse += 10f64.powf(-e.psnr_db / 10.0) / views as f64;
            maxabs = maxabs.max(e.max_abs * 255.0);
            let got = warp_samples(&cfg, &setup, &base);
            let want = reference_at_samples(&map, &setup, &base, cfg.color_w);
            for (g, w) in got.iter().zip(&want) {
                for (c, i) in g.rgb.iter().zip(w) {
                    maxsample = maxsample.max((f64::from(*c) - 255.0 * i).abs());
                }
            }
        }
        println!(
            "| {size}^2 | {views} | {lines} | {} | {} | {} | {} | {} | {:.2} | {psnr:.1} | {maxabs:.0} | {maxsample:.2} |",
            c.pixels,
            c.naive,
            c.buffered1,
            c.buffered2,
            c.distinct,
            c.naive as f64 / c.buffered2.max(1) as f64,
            psnr = -10.0 * mse.log10()
        );
    }
    Ok(())
}
