//! Benchmark of cube5_shader: speed, the error of the fixed-point unit against the f64 reference
//! with the same tables, and the error of the reflectance-map approach against direct f64 Phong.

use super::common::{speed_table, Compare, ErrorStats};
use anyhow::Result;
use cube5_model::transfer::TransferFunction;
use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_shader::{
    ClassLut, Phong, ReflectanceMap, Rgba, Shader, ShaderConfig, ShaderIn, ShaderMode, ShaderTables,
};
use cube5_tb::variants_of;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = ShaderConfig::TOP;

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

/// Adds the errors of every r, g, b channel (output LSBs) to `s`.
fn add_rgb(s: &mut ErrorStats, got: [f64; 3], want: [f64; 3]) {
    s.extend(got.into_iter().zip(want).map(|(g, w)| g - w));
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
    speed_table(
        |cfg: ShaderConfig| {
            let tables = ShaderTables {
                class: ClassLut::from_transfer(&cfg, &TransferFunction::head_default())?,
                rmap: ReflectanceMap::from_lights(&cfg, &phong)?,
            };
            let writes = tables.config_writes(&cfg);
            Ok((
                Shader::new(cfg, tables)?,
                lit_items(&cfg, n_items, 1),
                writes,
            ))
        },
        Compare::Outputs,
    )?;
    println!(
        "Error of {TOP} ({n_items} lit items, gradient directions uniform on the sphere, \
         1/64 zero gradients, mid-grey colour, two distant Phong lights), in output LSBs \
         (2^-ColorW): `exact` is the f64 reference with the same tables (exact face coordinates, \
         bilinear weights and products), `Phong` is direct f64 Phong at the exact gradient \
         direction; `map vs Phong` is the f64 reference against Phong (the reflectance-map \
         approach without the unit's rounding):"
    );
    println!();
    println!("| config | max vs exact | RMS vs exact | mean vs exact | max vs Phong | RMS vs Phong | map vs Phong: max | map vs Phong: RMS |");
    println!("|--------|-------------:|-------------:|--------------:|-------------:|-------------:|------------------:|------------------:|");
    for v in variants_of(TOP) {
        let cfg: ShaderConfig = v.config()?;
        let model = Shader::new(cfg, grey_tables(&cfg, &phong)?)?;
        let [mut exact, mut direct, mut map] = [ErrorStats::default(); 3];
        for it in &lit_items(&cfg, n_items, 2) {
            let got = rgb(model.shade(it));
            let e = model.reference_exact(it);
            let p = model.reference_phong(it, &phong);
            add_rgb(&mut exact, got, e);
            add_rgb(&mut direct, got, p);
            add_rgb(&mut map, e, p);
        }
        println!(
            "| {} | {:.3} | {:.3} | {:+.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
            v.config,
            exact.max_abs,
            exact.rms(),
            exact.mean(),
            direct.max_abs,
            direct.rms(),
            map.max_abs,
            map.rms()
        );
    }

    println!();
    // The RTL's default widths, named after the variant that has them, if one does.
    let default_is = variants_of(TOP)
        .into_iter()
        .find(|v| v.config::<ShaderConfig>().ok() == Some(ShaderConfig::DEFAULT))
        .map_or(String::new(), |v| format!(" (`{}`)", v.config));
    println!(
        "Reflectance-map resolution against direct Phong (model only, the default widths{default_is} \
         otherwise, same items and lights; texels = 6 (2^RmLog2 + 1)^2). Two-sided lighting flips the \
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
            let mut s = ErrorStats::default();
            for it in &items {
                add_rgb(&mut s, rgb(model.shade(it)), model.reference_phong(it, p));
            }
            row.push(format!("{:.3} | {:.3}", s.max_abs, s.rms()));
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
