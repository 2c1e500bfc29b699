//! Benchmark of cube5_shader: speed, the error of the fixed-point unit against the f64 reference
//! with the same tables, and the error of the reflectance-map approach against direct f64 Phong.

use anyhow::Result;
use cube5_model::transfer::TransferFunction;
use cube5_model::unit::StreamUnit;
use cube5_model::units::cube5_shader::{
    ClassLut, Phong, ReflectanceMap, Rgba, Shader, ShaderConfig, ShaderIn, ShaderMode, ShaderTables,
};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

const CONFIGS: [(&str, ShaderConfig); 2] =
    [("v8", ShaderConfig::NARROW), ("v12", ShaderConfig::DEFAULT)];

/// Lit items with gradients of random direction (uniform on the sphere) and a random length
/// between a quarter of full scale and full scale; one item in 64 has a zero gradient.
fn lit_items(cfg: &ShaderConfig, n: usize, seed: u64) -> Vec<ShaderIn> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let gmax = f64::from(cfg.grad_max());
    (0..n)
        .map(|_| {
            let grad = if rng.random_range(0..64) == 0 {
                [0; 3]
            } else {
                let z: f64 = rng.random_range(-1.0..=1.0);
                let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
                let r = (1.0 - z * z).sqrt();
                let len = rng.random_range(0.25..=1.0) * gmax;
                [r * phi.cos(), r * phi.sin(), z].map(|c| (c * len).round() as i32)
            };
            ShaderIn {
                sample: rng.random_range(0..=cfg.sample_max()),
                grad,
                mag: rng.random_range(0..=cfg.mag_max()),
                mode: ShaderMode::default(),
            }
        })
        .collect()
}

/// Error statistics in output LSBs over every r, g, b channel.
#[derive(Default)]
struct Stats {
    max: f64,
    sq: f64,
    sum: f64,
    n: f64,
}

impl Stats {
    fn add(&mut self, got: [f64; 3], want: [f64; 3]) {
        for (g, w) in got.into_iter().zip(want) {
            let e = g - w;
            self.max = self.max.max(e.abs());
            self.sq += e * e;
            self.sum += e;
            self.n += 1.0;
        }
    }

    fn rms(&self) -> f64 {
        (self.sq / self.n.max(1.0)).sqrt()
    }

    fn mean(&self) -> f64 {
        self.sum / self.n.max(1.0)
    }
}

fn rgb(o: Rgba) -> [f64; 3] {
    [o.r, o.g, o.b].map(f64::from)
}

/// Mid-grey classification (every colour at half scale, so products rarely saturate) with the
/// two-light Phong map: the tables for the error figures.
fn grey_tables(cfg: &ShaderConfig, phong: &Phong) -> Result<ShaderTables> {
    let half = 1 << (cfg.color_w - 1);
    Ok(ShaderTables {
        class: ClassLut::from_fn(cfg, |_| Rgba {
            r: half,
            g: half,
            b: half,
            a: cfg.alpha_max(),
        })?,
        rmap: ReflectanceMap::from_lights(cfg, phong)?,
    })
}

pub fn run(n_items: usize) -> Result<()> {
    let phong = Phong::two_lights();
    println!("## cube5_shader\n");
    println!("| unit | config | RTL cycles | items/clock | sim cycles/s | model items/s | model/sim speed |");
    println!("|------|--------|-----------:|------------:|-------------:|--------------:|----------------:|");
    for (name, cfg) in CONFIGS {
        let tables = ShaderTables {
            class: ClassLut::from_transfer(&cfg, &TransferFunction::head_default())?,
            rmap: ReflectanceMap::from_lights(&cfg, &phong)?,
        };
        let items = lit_items(&cfg, n_items, 1);
        let variant = format!("cube5_shader_{name}");
        let mut dut = RtlStream::new(&variant, cfg, 1)?;
        for (addr, data) in tables.config_writes(&cfg) {
            dut.write_config(addr, &data)?;
        }
        let n = items.len() as u64;
        let packed = dut.pack(&items);
        let t = Instant::now();
        let driven = dut.drive_packed(&packed, &Traffic::full_speed(), n, 2 * n + 1000)?;
        let sim_secs = t.elapsed().as_secs_f64();
        let cycles = driven.stats.cycles;

        let mut model = Shader::new(cfg, tables)?;
        let t = Instant::now();
        let out = model.run(&items);
        let model_secs = t.elapsed().as_secs_f64();
        let agree = driven.outputs.iter().zip(&out).all(|(d, m)| d.value == *m);
        anyhow::ensure!(
            agree,
            "{variant}: RTL and model disagree in the benchmark run"
        );

        let sim_rate = cycles as f64 / sim_secs;
        let model_rate = n as f64 / model_secs;
        println!(
            "| cube5_shader | {name} | {cycles} | {:.4} | {:.2e} | {:.2e} | {:.1}x |",
            n as f64 / cycles as f64,
            sim_rate,
            model_rate,
            model_rate / sim_rate
        );
    }

    println!();
    println!(
        "Error of cube5_shader ({n_items} lit items, gradient directions uniform on the sphere, \
         1/64 zero gradients, mid-grey colour, two distant Phong lights), in output LSBs \
         (2^-ColorW): `exact` is the f64 reference with the same tables (exact face coordinates, \
         bilinear weights and products), `Phong` is direct f64 Phong at the exact gradient \
         direction; `map vs Phong` is the f64 reference against Phong (the reflectance-map \
         approach without the unit's rounding):"
    );
    println!();
    println!("| config | max vs exact | RMS vs exact | mean vs exact | max vs Phong | RMS vs Phong | map vs Phong: max | map vs Phong: RMS |");
    println!("|--------|-------------:|-------------:|--------------:|-------------:|-------------:|------------------:|------------------:|");
    for (name, cfg) in CONFIGS {
        let model = Shader::new(cfg, grey_tables(&cfg, &phong)?)?;
        let (mut exact, mut direct, mut map) =
            (Stats::default(), Stats::default(), Stats::default());
        for it in &lit_items(&cfg, n_items, 2) {
            let got = rgb(model.shade(it));
            let e = model.reference_exact(it);
            let p = model.reference_phong(it, &phong);
            exact.add(got, e);
            direct.add(got, p);
            map.add(e, p);
        }
        println!(
            "| {name} | {:.3} | {:.3} | {:+.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
            exact.max,
            exact.rms(),
            exact.mean(),
            direct.max,
            direct.rms(),
            map.max,
            map.rms()
        );
    }

    println!();
    println!(
        "Reflectance-map resolution against direct Phong (model only, v12 widths otherwise, \
         same items and lights; texels = 6 (2^RmLog2 + 1)^2). Two-sided lighting flips the \
         normal towards the viewer, a jump in intensity along the silhouette (n.v = 0) that no \
         interpolated map represents, so its maximum stays put; one-sided lighting is continuous:"
    );
    println!();
    println!("| RmLog2 | cells per face | texels | two-sided: max (LSB) | two-sided: RMS (LSB) | one-sided: max (LSB) | one-sided: RMS (LSB) |");
    println!("|-------:|---------------:|-------:|---------------------:|---------------------:|---------------------:|---------------------:|");
    let items = lit_items(&ShaderConfig::DEFAULT, n_items.min(200_000), 3);
    let one_sided = Phong {
        two_sided: false,
        ..phong.clone()
    };
    for rm_log2 in 2..=7 {
        let cfg = ShaderConfig {
            rm_log2,
            ..ShaderConfig::DEFAULT
        };
        let mut row = Vec::new();
        for p in [&phong, &one_sided] {
            let model = Shader::new(cfg, grey_tables(&cfg, p)?)?;
            let mut s = Stats::default();
            for it in &items {
                s.add(rgb(model.shade(it)), model.reference_phong(it, p));
            }
            row.push(format!("{:.3} | {:.3}", s.max, s.rms()));
        }
        let cells = 1 << rm_log2;
        println!(
            "| {rm_log2} | {cells} x {cells} | {} | {} | {} |",
            cfg.rm_texels(),
            row[0],
            row[1]
        );
    }
    println!();
    Ok(())
}
