//! Benchmark of cube5_compos: speed, and error over long rays against the f64 reference.

use anyhow::Result;
use cube5_model::unit::StreamUnit;
use cube5_model::units::cube5_compos::{
    ray_error, Compos, ComposConfig, ComposIn, ComposMode, ComposRegs, Coxel, OpacityLut, Sample,
};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

const CONFIGS: [(&str, ComposConfig); 3] = [
    ("c8", ComposConfig::NARROW),
    ("c12", ComposConfig::DEFAULT),
    ("c10", ComposConfig::WIDE),
];

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
    println!("## cube5_compos\n");
    println!("| unit | config | RTL cycles | items/clock | sim cycles/s | model items/s | model/sim speed |");
    println!("|------|--------|-----------:|------------:|-------------:|--------------:|----------------:|");
    for (name, cfg) in CONFIGS {
        let mut model = Compos::new(cfg, OpacityLut::new(0.5, &cfg)?, ComposRegs::defaults(&cfg))?;
        let items = items(&cfg, n_items, 1);
        let mut dut = RtlStream::new(&format!("cube5_compos_{name}"), cfg, 1)?;
        for (addr, data) in model.config_writes() {
            dut.write_config(addr, &data)?;
        }
        let n = items.len() as u64;
        let packed = dut.pack(&items);
        let t = Instant::now();
        let driven = dut.drive_packed(&packed, &Traffic::full_speed(), n, 2 * n + 1000)?;
        let sim_secs = t.elapsed().as_secs_f64();
        let cycles = driven.stats.cycles;

        let t = Instant::now();
        let out = model.run(&items);
        let model_secs = t.elapsed().as_secs_f64();
        std::hint::black_box(out);

        let sim_rate = cycles as f64 / sim_secs;
        let model_rate = n as f64 / model_secs;
        println!(
            "| cube5_compos | {name} | {cycles} | {:.4} | {:.2e} | {:.2e} | {:.1}x |",
            n as f64 / cycles as f64,
            sim_rate,
            model_rate,
            model_rate / sim_rate
        );
    }

    let rays = (n_items / RAY).max(1);
    println!();
    println!(
        "Error of cube5_compos against its f64 reference: {rays} rays of {RAY} samples from an empty \
         coxel (90% of alphas below 1/8), opacity LUT for d/k = 1/2, no early termination; the \
         largest and RMS difference of the final R, G, B, A, in display LSBs (1/255) and in coxel \
         LSBs (2^-AccW):"
    );
    println!();
    println!("| config | mode | max abs (display LSB) | RMS (display LSB) | mean (display LSB) | max abs (coxel LSB) |");
    println!("|--------|------|----------------------:|------------------:|-------------------:|--------------------:|");
    for (name, cfg) in CONFIGS {
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
            let (mut max, mut sq, mut sum, mut count) = (0.0f64, 0.0f64, 0.0f64, 0usize);
            let one = cfg.one() as f64;
            for _ in 0..rays {
                let samples: Vec<Sample> = (0..RAY).map(|_| sample(&mut rng, &cfg, mode)).collect();
                let start = Coxel::empty(&cfg);
                let (fixed, refs, _) = ray_error(&unit, &start, &samples);
                let (f, r) = (fixed.last().unwrap(), refs.last().unwrap());
                for ch in 0..4 {
                    let e = f.rgba[ch] as f64 / one - r.rgba[ch];
                    max = max.max(e.abs());
                    sq += e * e;
                    sum += e;
                    count += 1;
                }
            }
            let n = count as f64;
            println!(
                "| {name} | {mode:?} | {:.3} | {:.3} | {:+.3} | {:.1} |",
                max * 255.0,
                (sq / n).sqrt() * 255.0,
                sum / n * 255.0,
                max * one
            );
        }
    }
    Ok(())
}
