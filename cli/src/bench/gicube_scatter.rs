//! Benchmark of gicube_scatter: speed, and the angular error against the f64 reference
//! (docs/numerics/gicube_scatter.md § Error) at several bit widths.

use anyhow::Result;
use cube5_model::unit::StreamUnit;
use cube5_model::units::gicube_scatter::{
    angle_deg, random_item, Scatter, ScatterConfig, ScatterEvent, ScatterIn,
};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

/// The verified RTL configurations.
const RTL_CONFIGS: [(&str, ScatterConfig); 2] = [
    ("f8", ScatterConfig::NARROW),
    ("f14", ScatterConfig::DEFAULT),
];

fn items(cfg: &ScatterConfig, n: usize, seed: u64) -> Vec<ScatterIn> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| random_item(cfg, &mut rng)).collect()
}

/// Max, RMS and 99th percentile of a set of errors (degrees).
struct Stats {
    n: usize,
    max: f64,
    rms: f64,
    p99: f64,
}

impl Stats {
    fn of(mut errs: Vec<f64>) -> Self {
        let n = errs.len();
        if n == 0 {
            return Self {
                n,
                max: 0.0,
                rms: 0.0,
                p99: 0.0,
            };
        }
        errs.sort_by(f64::total_cmp);
        let rms = (errs.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
        let p99 = errs[((n as f64 * 0.99) as usize).min(n - 1)];
        Self {
            n,
            max: errs[n - 1],
            rms,
            p99,
        }
    }
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
    println!("## gicube_scatter\n");
    println!("| unit | config | RTL cycles | items/clock | sim cycles/s | model items/s | model/sim speed |");
    println!("|------|--------|-----------:|------------:|-------------:|--------------:|----------------:|");
    for (name, cfg) in RTL_CONFIGS {
        let its = items(&cfg, n_items, 1);
        let mut model = Scatter::new(cfg)?;
        let variant = format!("gicube_scatter_{name}");
        let mut dut = RtlStream::new(&variant, cfg, 1)?;
        for (addr, data) in model.tables().config_writes(&cfg) {
            dut.write_config(addr, &data)?;
        }
        let n = its.len() as u64;
        let packed = dut.pack(&its);
        let t = Instant::now();
        let driven = dut.drive_packed(&packed, &Traffic::full_speed(), n, 2 * n + 1000)?;
        let sim_secs = t.elapsed().as_secs_f64();
        let cycles = driven.stats.cycles;

        let t = Instant::now();
        let out = model.run(&its);
        let model_secs = t.elapsed().as_secs_f64();
        let agree = driven
            .outputs
            .iter()
            .zip(&out)
            .filter(|(r, m)| r.value == **m)
            .count();
        anyhow::ensure!(
            agree == its.len(),
            "{variant}: RTL and model disagree on {} of {} items",
            its.len() - agree,
            its.len()
        );

        let sim_rate = cycles as f64 / sim_secs;
        let model_rate = n as f64 / model_secs;
        println!(
            "| gicube_scatter | {name} | {cycles} | {:.4} | {:.2e} | {:.2e} | {:.1}x |",
            n as f64 / cycles as f64,
            sim_rate,
            model_rate,
            model_rate / sim_rate
        );
    }

    println!();
    println!(
        "Angular error of gicube_scatter against its f64 reference ({n_items} random rays each: \
         random directions and gradients, materials with 0 and 1 well represented, eta in [0, 4)), \
         in degrees and in 2^-F rad (an output LSB). `f8` and `f14` are the verified RTL \
         configurations; the other rows are the model at other widths:"
    );
    println!();
    println!("| config | F | M | A | I | rays | max (deg) | RMS (deg) | p99 (deg) | max (LSB) | RMS (LSB) | p99 (LSB) |");
    println!("|--------|---|---|---|---|-----:|----------:|----------:|----------:|----------:|----------:|----------:|");
    let widths = [
        ("f8", ScatterConfig::NARROW),
        ("f10", ScatterConfig::new(10, 17, 7, 7, 7)?),
        ("f12", ScatterConfig::new(12, 19, 8, 8, 8)?),
        ("f14", ScatterConfig::DEFAULT),
        ("f14a10", ScatterConfig::new(14, 21, 10, 10, 10)?),
    ];
    let mut per_event = Vec::new();
    for (name, cfg) in widths {
        let errs = errors(&cfg, n_items)?;
        let all = Stats::of(errs.iter().flatten().copied().collect());
        let lsb = (1.0 / f64::from(1u32 << cfg.f())).to_degrees();
        println!(
            "| {name} | {} | {} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.1} | {:.2} | {:.2} |",
            cfg.f(),
            cfg.mat_w,
            cfg.ang_w,
            cfg.iso_w,
            all.n,
            all.max,
            all.rms,
            all.p99,
            all.max / lsb,
            all.rms / lsb,
            all.p99 / lsb
        );
        if name == "f8" || name == "f14" {
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
            let s = Stats::of(e);
            println!(
                "| {name} | {ev:?} | {} | {:.4} | {:.4} | {:.4} |",
                s.n, s.max, s.rms, s.p99
            );
        }
    }
    Ok(())
}
