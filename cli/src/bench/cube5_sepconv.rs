//! Benchmark of cube5_sepconv: speed, and error against the exact real convolution.

use super::common::{speed_table, Compare, ErrorStats};
use anyhow::Result;
use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_sepconv::{Sepconv, SepconvConfig, SepconvIn, SepconvKernel};
use cube5_tb::variants_of;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = SepconvConfig::TOP;

/// Random taps over the whole range, both kernels.
fn sepconv_items(cfg: &SepconvConfig, n: usize, seed: u64) -> Vec<SepconvIn> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| SepconvIn {
            taps: std::array::from_fn(|_| rng.random_range(cfg.tap_min()..=cfg.tap_max())),
            kernel: SepconvKernel::from_bits(rng.random_range(0..2)),
        })
        .collect()
}

pub fn run(n_items: usize) -> Result<()> {
    // A Gaussian of sigma = 1: w = exp(1 / (2 sigma^2)).
    let w_real = 0.5f64.exp();
    speed_table(
        |cfg: SepconvConfig| {
            let gold = Sepconv::new(cfg, cfg.weight_from_f64(w_real))?;
            let writes = gold.config_writes();
            Ok((gold, sepconv_items(&cfg, n_items, 1), writes))
        },
        Compare::No,
    )?;
    println!(
        "Error of {TOP} against the exact real convolution ({n_items} random items, both \
         kernels, w = exp(1/2) rounded to U(4.WeightFracW)), in output LSBs; the contract: exact \
         when OutShift = 0, else within 1/2 LSB:"
    );
    println!();
    println!(
        "| config | w | OutShift | max abs error (LSB) | RMS error (LSB) | mean error (LSB) |"
    );
    println!(
        "|--------|---|---------:|--------------------:|----------------:|-----------------:|"
    );
    for v in variants_of(TOP) {
        let cfg: SepconvConfig = v.config()?;
        let unit = Sepconv::new(cfg, cfg.weight_from_f64(w_real))?;
        let s: ErrorStats = sepconv_items(&cfg, n_items, 2)
            .iter()
            .map(|it| unit.convolve(it) as f64 - unit.reference(it) / unit.out_lsb())
            .collect();
        let w = f64::from(unit.weight()) / f64::from(1u32 << cfg.weight_frac_w);
        println!(
            "| {} | {w} | {} | {:.3} | {:.3} | {:+.4} |",
            v.config,
            cfg.out_shift,
            s.max_abs,
            s.rms(),
            s.mean()
        );
    }
    println!();
    Ok(())
}
