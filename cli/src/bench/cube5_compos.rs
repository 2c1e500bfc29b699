//! Benchmark of cube5_compos: speed, and error over long rays against the f64 reference.

use super::common::{speed_table, Compare, ErrorStats};
use anyhow::Result;
use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_compos::{
    ray_error, Compos, ComposConfig, ComposIn, ComposMode, ComposRegs, Coxel, OpacityLut, Sample,
};
use cube5_tb::variants_of;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = ComposConfig::TOP;

/// Rays are this long in the error table (a 256^3 volume at one sample per voxel).
const RAY: usize = 256;

/// A translucent volume's sample: any colour, mostly faint alpha (below 1/8), sometimes dense.
fn sample(rng: &mut ChaCha8Rng, cfg: &ComposConfig, mode: ComposMode) -> Sample {
    let alpha = if rng.random_bool(0.9) {
        rng.random_range(0..=cfg.alpha_max() / 8)
    } else {
        rng.random_range(0..=cfg.alpha_max())
    };
    Sample {
        rgb: std::array::from_fn(|_| rng.random_range(0..=cfg.color_max())),
        alpha,
        depth: rng.random_range(0..cfg.z_none()),
        mode,
    }
}

/// Items for the speed table: over-state coxels and samples in every mode.
fn items(cfg: &ComposConfig, n: usize, seed: u64) -> Vec<ComposIn> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let a = rng.random_range(0..=cfg.one());
            let coxel = Coxel {
                rgba: [
                    rng.random_range(0..=a),
                    rng.random_range(0..=a),
                    rng.random_range(0..=a),
                    a,
                ],
                z: rng.random_range(0..=cfg.z_none()),
                geo: std::array::from_fn(|_| rng.random_range(0..=cfg.color_max())),
                terminated: false,
            };
            let mode = ComposMode::from_bits(rng.random_range(0..7));
            ComposIn {
                coxel,
                sample: sample(&mut rng, cfg, mode),
            }
        })
        .collect()
}

pub fn run(n_items: usize) -> Result<()> {
    speed_table(
        |cfg: ComposConfig| {
            let model = Compos::new(cfg, OpacityLut::new(0.5, &cfg)?, ComposRegs::defaults(&cfg))?;
            let writes = model.config_writes();
            Ok((model, items(&cfg, n_items, 1), writes))
        },
        Compare::No,
    )?;

    let rays = (n_items / RAY).max(1);
    println!(
        "Error of {TOP} against its f64 reference: {rays} rays of {RAY} samples from an empty \
         coxel (90% of alphas below 1/8), opacity LUT for d/k = 1/2, no early termination; the \
         largest and RMS difference of the final R, G, B, A, in display LSBs (1/255) and in coxel \
         LSBs (2^-AccW):"
    );
    println!();
    println!("| config | mode | max abs (display LSB) | RMS (display LSB) | mean (display LSB) | max abs (coxel LSB) |");
    println!("|--------|------|----------------------:|------------------:|-------------------:|--------------------:|");
    for v in variants_of(TOP) {
        let cfg: ComposConfig = v.config()?;
        let regs = ComposRegs {
            xray_shift: 8,
            ..ComposRegs::without_termination(&cfg)
        };
        let unit = Compos::new(cfg, OpacityLut::new(0.5, &cfg)?, regs)?;
        for mode in [
            ComposMode::FrontToBack,
            ComposMode::BackToFront,
            ComposMode::Max,
            ComposMode::XraySum,
        ] {
            let mut rng = ChaCha8Rng::seed_from_u64(2);
            let mut s = ErrorStats::default();
            let one = cfg.one() as f64;
            for _ in 0..rays {
                let samples: Vec<Sample> = (0..RAY).map(|_| sample(&mut rng, &cfg, mode)).collect();
                let start = Coxel::empty(&cfg);
                let (fixed, refs, _) = ray_error(&unit, &start, &samples);
                let (f, r) = (fixed.last().unwrap(), refs.last().unwrap());
                s.extend((0..4).map(|ch| f.rgba[ch] as f64 / one - r.rgba[ch]));
            }
            println!(
                "| {} | {mode:?} | {:.3} | {:.3} | {:+.3} | {:.1} |",
                v.config,
                s.max_abs * 255.0,
                s.rms() * 255.0,
                s.mean() * 255.0,
                s.max_abs * one
            );
        }
    }
    Ok(())
}
