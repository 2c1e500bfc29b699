//! Benchmark of cube5_gradient: speed, the components' error against the f64 reference and the
//! magnitude estimate's against the Euclidean norm.

use super::common::{speed_table, Compare, ErrorStats};
use anyhow::Result;
use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_gradient::{Gradient, GradientConfig, GradientIn, GradientMode};
use cube5_tb::variants_of;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = GradientConfig::TOP;

/// Uniform samples, steps in [-1, 1], the given mode (or every mode when `None`).
fn gradient_items(
    cfg: &GradientConfig,
    n: usize,
    seed: u64,
    mode: Option<GradientMode>,
) -> Vec<GradientIn> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let one = 1i32 << cfg.weight_w;
    (0..n)
        .map(|_| GradientIn {
            samples: std::array::from_fn(|_| rng.random_range(0..=cfg.sample_max())),
            dx: rng.random_range(-one..=one),
            dy: rng.random_range(-one..=one),
            mode: mode.unwrap_or_else(|| GradientMode::from_bits(rng.random_range(0..3))),
        })
        .collect()
}

/// Samples of linear fields whose gradient points in a uniformly random direction, with a random
/// magnitude from 1/16 to all of the range that keeps the 3x3x3 block inside `U(VoxelW.FracW)`.
fn ramp_items(cfg: &GradientConfig, n: usize, seed: u64) -> Vec<GradientIn> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let max = f64::from(cfg.sample_max());
    let gauss = |rng: &mut ChaCha8Rng| {
        // Box-Muller: rand 0.9 without rand_distr has no normal distribution.
        let (u, v): (f64, f64) = (rng.random_range(f64::EPSILON..1.0), rng.random());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    (0..n)
        .map(|_| {
            let d = [gauss(&mut rng), gauss(&mut rng), gauss(&mut rng)];
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            // |a| + |b| + |c| <= max / 2 keeps every sample of the block in range.
            let l1 = (d[0].abs() + d[1].abs() + d[2].abs()) / len;
            let m = rng.random_range(1.0 / 16.0..=1.0) * max / 2.0 / l1;
            let g = d.map(|x| x / len * m);
            GradientIn {
                samples: std::array::from_fn(|i| {
                    let (di, dj, dk) = (
                        i as f64 % 3.0 - 1.0,
                        (i / 3 % 3) as f64 - 1.0,
                        (i / 9) as f64 - 1.0,
                    );
                    (max / 2.0 + g[0] * di + g[1] * dj + g[2] * dk).round() as u32
                }),
                dx: 0,
                dy: 0,
                mode: GradientMode::N6,
            }
        })
        .collect()
}

pub fn run(n_items: usize) -> Result<()> {
    speed_table(
        |cfg: GradientConfig| {
            let items = gradient_items(&cfg, n_items, 1, None);
            Ok((Gradient::new(cfg)?, items, vec![]))
        },
        Compare::No,
    )?;
    println!(
        "Component error of {TOP} against its f64 reference ({n_items} random items per \
         mode, uniform samples, steps in [-1, 1]), in output LSBs (2^-(FracW+5) voxel units); the \
         contract: exact, except N10's gz within 1/2 LSB:"
    );
    println!();
    println!("| config | mode | max abs error gx, gy (LSB) | max abs error gz (LSB) | RMS gz (LSB) | mean gz (LSB) |");
    println!("|--------|------|---------------------------:|-----------------------:|-------------:|--------------:|");
    for v in variants_of(TOP) {
        let cfg: GradientConfig = v.config()?;
        let model = Gradient::new(cfg)?;
        let lsb = cfg.lsb();
        for mode in [GradientMode::N6, GradientMode::N10, GradientMode::N26] {
            let items = gradient_items(&cfg, n_items, 2, Some(mode));
            let (mut xy, mut z) = (ErrorStats::default(), ErrorStats::default());
            for it in &items {
                let out = model.gradient(it);
                let r = model.reference(it);
                xy.add(f64::from(out.gx) - r.g[0] / lsb);
                xy.add(f64::from(out.gy) - r.g[1] / lsb);
                z.add(f64::from(out.gz) - r.g[2] / lsb);
            }
            println!(
                "| {} | {mode:?} | {:.3} | {:.3} | {:.3} | {:+.4} |",
                v.config,
                xy.max_abs,
                z.max_abs,
                z.rms(),
                z.mean()
            );
        }
    }

    println!();
    println!(
        "Magnitude estimate (30 max + 13 mid + 9 min)/32 against the Euclidean norm of the f64 \
         components, relative, in percent ({n_items} linear fields per config, gradient directions \
         uniform on the sphere, magnitudes from 1/16 to the full range; mode N6, exact \
         components). The analytic range of the estimator alone is -6.25 % .. +5.97 %:"
    );
    println!();
    println!("| config | min error (%) | max error (%) | RMS error (%) | mean error (%) |");
    println!("|--------|--------------:|--------------:|--------------:|---------------:|");
    for v in variants_of(TOP) {
        let cfg: GradientConfig = v.config()?;
        let model = Gradient::new(cfg)?;
        let lsb = cfg.lsb();
        let mut rel = ErrorStats::default();
        for it in &ramp_items(&cfg, n_items, 3) {
            let r = model.reference(it);
            if r.norm > 0.0 {
                rel.add(100.0 * (f64::from(model.gradient(it).mag) * lsb / r.norm - 1.0));
            }
        }
        println!(
            "| {} | {:+.3} | {:+.3} | {:.3} | {:+.3} |",
            v.config,
            rel.min,
            rel.max,
            rel.rms(),
            rel.mean()
        );
    }
    println!();
    Ok(())
}
