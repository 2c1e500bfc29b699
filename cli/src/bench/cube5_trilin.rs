//! Benchmark of cube5_trilin: speed, and error against the f64 reference.

use super::common::{speed_table, Compare, ErrorStats};
use anyhow::Result;
use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_trilin::{Trilin, TrilinConfig, TrilinIn, TrilinMode};
use cube5_tb::variants_of;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = TrilinConfig::TOP;

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
    speed_table(
        |cfg: TrilinConfig| Ok((Trilin::new(cfg)?, trilin_items(&cfg, n_items, 1), vec![])),
        Compare::No,
    )?;
    println!("Error of {TOP} against its f64 reference ({n_items} random items, all weights, mode Lerp),");
    println!("in output LSBs (2^-FracW voxel units); the contract bound is 1.5 LSB:");
    println!();
    println!("| config | max abs error (LSB) | RMS error (LSB) | mean error (LSB) |");
    println!("|--------|--------------------:|----------------:|-----------------:|");
    for v in variants_of(TOP) {
        let cfg: TrilinConfig = v.config()?;
        let model = Trilin::new(cfg)?;
        let lsb = f64::from(1u32 << cfg.frac_w);
        let s: ErrorStats = trilin_items(&cfg, n_items, 2)
            .iter()
            .map(|it| f64::from(model.sample(it)) - model.reference(it) * lsb)
            .collect();
        println!(
            "| {} | {:.3} | {:.3} | {:+.3} |",
            v.config,
            s.max_abs,
            s.rms(),
            s.mean()
        );
    }
    Ok(())
}
