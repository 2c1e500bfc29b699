//! Benchmark of cube5_gradient and cube5_sepconv: speed, and error against the f64 references.

use anyhow::Result;
use cube5_model::unit::{StreamCodec, StreamUnit};
use cube5_model::units::cube5_gradient::{Gradient, GradientConfig, GradientIn, GradientMode};
use cube5_model::units::cube5_sepconv::{Sepconv, SepconvConfig, SepconvIn, SepconvKernel};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

const GRADIENT_CONFIGS: [(&str, GradientConfig); 3] = [
    ("v8", GradientConfig::NARROW),
    ("v12", GradientConfig::DEFAULT),
    ("v16", GradientConfig::WIDE),
];

const SEPCONV_CONFIGS: [(&str, SepconvConfig); 3] = [
    ("v8", SepconvConfig::NARROW),
    ("v12", SepconvConfig::DEFAULT),
    ("v16", SepconvConfig::WIDE),
];

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

/// Times the RTL at full speed and the model on the same items; prints one table row.
fn speed_row<C, G>(
    unit: &str,
    name: &str,
    codec: C,
    gold: &mut G,
    items: &[C::In],
    cfg_writes: &[(u32, Vec<u32>)],
) -> Result<()>
where
    C: StreamCodec + Clone,
    C::In: Clone + std::fmt::Debug,
    C::Out: Clone + std::fmt::Debug + PartialEq,
    G: StreamUnit<In = C::In, Out = C::Out>,
{
    let variant = format!("{unit}_{name}");
    let mut dut = RtlStream::new(&variant, codec, 1)?;
    for (addr, data) in cfg_writes {
        dut.write_config(*addr, data)?;
    }
    let n = items.len() as u64;
    let packed = dut.pack(items);
    let t = Instant::now();
    let driven = dut.drive_packed(&packed, &Traffic::full_speed(), n, 2 * n + 1000)?;
    let sim_secs = t.elapsed().as_secs_f64();
    let cycles = driven.stats.cycles;

    let t = Instant::now();
    let out = gold.run(items);
    let model_secs = t.elapsed().as_secs_f64();
    std::hint::black_box(out);

    let sim_rate = cycles as f64 / sim_secs;
    let model_rate = n as f64 / model_secs;
    println!(
        "| {unit} | {name} | {cycles} | {:.4} | {:.2e} | {:.2e} | {:.1}x |",
        n as f64 / cycles as f64,
        sim_rate,
        model_rate,
        model_rate / sim_rate
    );
    Ok(())
}

/// Max abs, RMS and mean of a list of errors.
fn stats(errs: impl IntoIterator<Item = f64>) -> (f64, f64, f64) {
    let (mut max, mut sq, mut sum, mut n) = (0.0f64, 0.0, 0.0, 0usize);
    for e in errs {
        max = max.max(e.abs());
        sq += e * e;
        sum += e;
        n += 1;
    }
    let n = n.max(1) as f64;
    (max, (sq / n).sqrt(), sum / n)
}

const SPEED_HEADER: &str = "| unit | config | RTL cycles | items/clock | sim cycles/s | model items/s | model/sim speed |\n\
                            |------|--------|-----------:|------------:|-------------:|--------------:|----------------:|";

pub fn run(n_items: usize) -> Result<()> {
    gradient(n_items)?;
    sepconv(n_items)
}

fn gradient(n_items: usize) -> Result<()> {
    println!("## cube5_gradient\n");
    println!("{SPEED_HEADER}");
    for (name, cfg) in GRADIENT_CONFIGS {
        let items = gradient_items(&cfg, n_items, 1, None);
        speed_row(
            "cube5_gradient",
            name,
            cfg,
            &mut Gradient::new(cfg)?,
            &items,
            &[],
        )?;
    }

    println!();
    println!(
        "Component error of cube5_gradient against its f64 reference ({n_items} random items per \
         mode, uniform samples, steps in [-1, 1]), in output LSBs (2^-(FracW+5) voxel units); the \
         contract: exact, except N10's gz within 1/2 LSB:"
    );
    println!();
    println!("| config | mode | max abs error gx, gy (LSB) | max abs error gz (LSB) | RMS gz (LSB) | mean gz (LSB) |");
    println!("|--------|------|---------------------------:|-----------------------:|-------------:|--------------:|");
    for (name, cfg) in GRADIENT_CONFIGS {
        let model = Gradient::new(cfg)?;
        let lsb = cfg.lsb();
        for mode in [GradientMode::N6, GradientMode::N10, GradientMode::N26] {
            let items = gradient_items(&cfg, n_items, 2, Some(mode));
            let mut xy = 0.0f64;
            let mut z = Vec::with_capacity(items.len());
            for it in &items {
                let out = model.gradient(it);
                let r = model.reference(it);
                xy = xy
                    .max((f64::from(out.gx) - r.g[0] / lsb).abs())
                    .max((f64::from(out.gy) - r.g[1] / lsb).abs());
                z.push(f64::from(out.gz) - r.g[2] / lsb);
            }
            let (max, rms, mean) = stats(z);
            println!("| {name} | {mode:?} | {xy:.3} | {max:.3} | {rms:.3} | {mean:+.4} |");
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
    for (name, cfg) in GRADIENT_CONFIGS {
        let model = Gradient::new(cfg)?;
        let lsb = cfg.lsb();
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut rel = Vec::with_capacity(n_items);
        for it in &ramp_items(&cfg, n_items, 3) {
            let r = model.reference(it);
            if r.norm <= 0.0 {
                continue;
            }
            let e = 100.0 * (f64::from(model.gradient(it).mag) * lsb / r.norm - 1.0);
            lo = lo.min(e);
            hi = hi.max(e);
            rel.push(e);
        }
        let (_, rms, mean) = stats(rel);
        println!("| {name} | {lo:+.3} | {hi:+.3} | {rms:.3} | {mean:+.3} |");
    }
    println!();
    Ok(())
}

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

fn sepconv(n_items: usize) -> Result<()> {
    // A Gaussian of sigma = 1: w = exp(1 / (2 sigma^2)).
    let w_real = 0.5f64.exp();
    println!("## cube5_sepconv\n");
    println!("{SPEED_HEADER}");
    for (name, cfg) in SEPCONV_CONFIGS {
        let items = sepconv_items(&cfg, n_items, 1);
        let mut gold = Sepconv::new(cfg, cfg.weight_from_f64(w_real))?;
        let writes = gold.config_writes();
        speed_row("cube5_sepconv", name, cfg, &mut gold, &items, &writes)?;
    }
    println!();
    println!(
        "Error of cube5_sepconv against the exact real convolution ({n_items} random items, both \
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
    for (name, cfg) in SEPCONV_CONFIGS {
        let unit = Sepconv::new(cfg, cfg.weight_from_f64(w_real))?;
        let errs = sepconv_items(&cfg, n_items, 2)
            .iter()
            .map(|it| unit.convolve(it) as f64 - unit.reference(it) / unit.out_lsb())
            .collect::<Vec<_>>();
        let (max, rms, mean) = stats(errs);
        let w = f64::from(unit.weight()) / f64::from(1u32 << cfg.weight_frac_w);
        println!(
            "| {name} | {w} | {} | {max:.3} | {rms:.3} | {mean:+.4} |",
            cfg.out_shift
        );
    }
    println!();
    Ok(())
}
