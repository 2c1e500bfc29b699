//! Benchmark of cube5_trilin: speed, and error against the f64 reference.

use anyhow::Result;
use cube5_model::unit::StreamUnit;
use cube5_model::units::cube5_trilin::{Trilin, TrilinConfig, TrilinIn, TrilinMode};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

fn trilin_items(cfg: &TrilinConfig, n: usize, seed: u64) -> Vec<TrilinIn> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| TrilinIn {
            voxels: std::array::from_fn(|_| rng.random_range(0..=cfg.voxel_max())),
            weights: std::array::from_fn(|_| rng.random_range(0..=cfg.weight_max())),
            mode: TrilinMode::Lerp,
        })
        .collect()
}

pub fn run(n_items: usize) -> Result<()> {
    println!("## cube5_trilin\n");
    println!("| unit | config | RTL cycles | items/clock | sim cycles/s | model items/s | model/sim speed |");
    println!("|------|--------|-----------:|------------:|-------------:|--------------:|----------------:|");
    for (name, cfg) in [
        ("v8", TrilinConfig::NARROW),
        ("v12", TrilinConfig::DEFAULT),
        ("v16", TrilinConfig::WIDE),
    ] {
        let items = trilin_items(&cfg, n_items, 1);
        let variant = format!("cube5_trilin_{name}");
        let mut dut = RtlStream::new(&variant, cfg, 1)?;
        let n = items.len() as u64;
        let packed = dut.pack(&items);
        let t = Instant::now();
        let driven = dut.drive_packed(&packed, &Traffic::full_speed(), n, 2 * n + 1000)?;
        let sim_secs = t.elapsed().as_secs_f64();
        let cycles = driven.stats.cycles;

        let mut model = Trilin::new(cfg)?;
        let t = Instant::now();
        let out = model.run(&items);
        let model_secs = t.elapsed().as_secs_f64();
        std::hint::black_box(out);

        let sim_rate = cycles as f64 / sim_secs;
        let model_rate = n as f64 / model_secs;
        println!(
            "| cube5_trilin | {name} | {cycles} | {:.4} | {:.2e} | {:.2e} | {:.1}x |",
            n as f64 / cycles as f64,
            sim_rate,
            model_rate,
            model_rate / sim_rate
        );
    }
    println!();
    println!("Error of cube5_trilin against its f64 reference ({} random items, all weights, mode Lerp),", n_items);
    println!("in output LSBs (2^-FracW voxel units); the contract bound is 1.5 LSB:");
    println!();
    println!("| config | max abs error (LSB) | RMS error (LSB) | mean error (LSB) |");
    println!("|--------|--------------------:|----------------:|-----------------:|");
    for (name, cfg) in [
        ("v8", TrilinConfig::NARROW),
        ("v12", TrilinConfig::DEFAULT),
        ("v16", TrilinConfig::WIDE),
    ] {
        let model = Trilin::new(cfg)?;
        let lsb = f64::from(1u32 << cfg.frac_w);
        let (mut max, mut sq, mut sum) = (0.0f64, 0.0, 0.0);
        let items = trilin_items(&cfg, n_items, 2);
        for it in &items {
            let e = f64::from(model.sample(it)) - model.reference(it) * lsb;
            max = max.max(e.abs());
            sq += e * e;
            sum += e;
        }
        let n = items.len() as f64;
        println!(
            "| {name} | {max:.3} | {:.3} | {:+.3} |",
            (sq / n).sqrt(),
            sum / n
        );
    }
    Ok(())
}
