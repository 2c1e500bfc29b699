//! Benchmark of gicube_scatter: speed, and the angular error against the f64 reference
//! (docs/numerics/gicube_scatter.md § Error) at several bit widths.

use super::common::{speed_table, Compare, ErrorStats};
use anyhow::Result;
use cube5_model::unit::UnitConfig;
use cube5_model::units::gicube_scatter::{
    angle_deg, random_item, Scatter, ScatterConfig, ScatterEvent, ScatterIn,
};
use cube5_tb::variants_of;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = ScatterConfig::TOP;

/// Widths the error table measures on the model alone, besides the verified configurations.
fn model_widths() -> Result<Vec<ScatterConfig>> {
    Ok(vec![
        ScatterConfig::new(10, 17, 7, 7, 7)?,
        ScatterConfig::new(12, 19, 8, 8, 8)?,
        ScatterConfig::new(14, 21, 10, 10, 10)?,
    ])
}

fn items(cfg: &ScatterConfig, n: usize, seed: u64) -> Vec<ScatterIn> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| random_item(cfg, &mut rng)).collect()
}

/// The statistics of a set of errors (degrees, never negative) and their 99th percentile.
fn stats(mut errs: Vec<f64>) -> (ErrorStats, f64) {
    errs.sort_by(f64::total_cmp);
    let n = errs.len();
    let p99 = if n == 0 {
        0.0
    } else {
        errs[((n as f64 * 0.99) as usize).min(n - 1)]
    };
    (errs.into_iter().collect(), p99)
}

/// Angular errors (degrees) per event of the model against its f64 reference.
fn errors(cfg: &ScatterConfig, n: usize) -> Result<[Vec<f64>; 4]> {
    let unit = Scatter::new(*cfg)?;
    let mut out: [Vec<f64>; 4] = Default::default();
    for it in items(cfg, n, 2) {
        let tr = unit.trace(&it);
        if let Some(want) = unit.reference_for(&it, &tr) {
            out[tr.out.event as usize].push(angle_deg(tr.out.dir.map(f64::from), want));
        }
    }
    Ok(out)
}

pub fn run(n_items: usize) -> Result<()> {
    let variants = variants_of(TOP);
    speed_table(
        |cfg: ScatterConfig| {
            let model = Scatter::new(cfg)?;
            let writes = model.tables().config_writes(&cfg);
            Ok((model, items(&cfg, n_items, 1), writes))
        },
        Compare::Outputs,
    )?;

    // The verified configurations (named) and the model at other widths (unnamed), narrowest first.
    let mut widths: Vec<(&str, ScatterConfig)> = Vec::new();
    for &v in &variants {
        widths.push((v.config, v.config()?));
    }
    widths.extend(model_widths()?.into_iter().map(|c| ("model", c)));
    widths.sort_by_key(|(_, c)| (c.f(), c.ang_w));
    let named: Vec<String> = variants.iter().map(|v| format!("`{}`", v.config)).collect();
    println!(
        "Angular error of {TOP} against its f64 reference ({n_items} random rays each: \
         random directions and gradients, materials with 0 and 1 well represented, eta in [0, 4)), \
         in degrees and in 2^-F rad (an output LSB). {} are the verified RTL configurations; the \
         `model` rows are the model at other widths:",
        named.join(" and ")
    );
    println!();
    println!("| config | F | M | A | I | rays | max (deg) | RMS (deg) | p99 (deg) | max (LSB) | RMS (LSB) | p99 (LSB) |");
    println!("|--------|---|---|---|---|-----:|----------:|----------:|----------:|----------:|----------:|----------:|");
    let mut per_event = Vec::new();
    for (name, cfg) in widths {
        let errs = errors(&cfg, n_items)?;
        let (all, p99) = stats(errs.iter().flatten().copied().collect());
        let lsb = (1.0 / f64::from(1u32 << cfg.f())).to_degrees();
        println!(
            "| {name} | {} | {} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.1} | {:.2} | {:.2} |",
            cfg.f(),
            cfg.mat_w,
            cfg.ang_w,
            cfg.iso_w,
            all.n,
            all.max_abs,
            all.rms(),
            p99,
            all.max_abs / lsb,
            all.rms() / lsb,
            p99 / lsb
        );
        if variants.iter().any(|v| v.config == name) {
            per_event.push((name, errs));
        }
    }
    println!();
    println!("Per event (the verified configurations); glossy rotation applies to reflection and refraction:");
    println!();
    println!("| config | event | rays | max (deg) | RMS (deg) | p99 (deg) |");
    println!("|--------|-------|-----:|----------:|----------:|----------:|");
    for (name, errs) in per_event {
        for (ev, e) in [
            ScatterEvent::Pass,
            ScatterEvent::Reflect,
            ScatterEvent::Refract,
            ScatterEvent::Isotropic,
        ]
        .iter()
        .zip(errs)
        {
            let (s, p99) = stats(e);
            println!(
                "| {name} | {ev:?} | {} | {:.4} | {:.4} | {p99:.4} |",
                s.n,
                s.max_abs,
                s.rms()
            );
        }
    }
    Ok(())
}
