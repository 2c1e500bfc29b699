//! Benchmark of the GI-Cube sample datapath (`gicube_sample`): speed of the RTL and the model on
//! random samples with random tables, every output compared with the model's; one sample's error
//! against its f64 reference (`Sampler::reference`).

use super::common::{speed_table, Compare, ErrorStats};
use anyhow::Result;
use cube5_model::unit::UnitConfig;
use cube5_model::units::gicube_sample::{
    random_class_lut, random_sample_in, SampleIn, SampleRtlConfig, Sampler,
};
use cube5_tb::variants_of;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = SampleRtlConfig::TOP;

pub fn run(n_items: usize) -> Result<()> {
    println!(
        "One item is one sample of one ray (a fifth lighting rays, half of the rendering rays lit"
    );
    println!("by an irradiance); a random classification table, dr = 200/256, termination at");
    println!("4032. One sample per clock, latency 22; every RTL output equals the model's.\n");
    speed_table(
        |cfg: SampleRtlConfig| {
            let mut rng = ChaCha8Rng::seed_from_u64(17);
            let class = random_class_lut(&mut rng, cfg.voxel_w)?;
            let model = Sampler::new(cfg.sample_config(200, Some(4032)), class)?;
            let items: Vec<SampleIn> = (0..n_items)
                .map(|_| random_sample_in(&mut rng, cfg.voxel_w))
                .collect();
            let writes = model.config_writes();
            Ok((model, items, writes))
        },
        Compare::Outputs,
    )?;

    println!("One sample against its f64 reference (the same classification entry; irradiance,");
    println!("opacity correction and the front-to-back step in reals): {n_items} random samples");
    println!("per configuration with random tables, the error of the colour channels and the");
    println!("opacity in LSB of the packet's U(0.12) (outputs that saturate at 4095 left out).\n");
    println!("| config | dr | colour max / RMS / mean (LSB) | opacity max / RMS / mean (LSB) |");
    println!("|--------|---:|------------------------------:|-------------------------------:|");
    for v in variants_of(TOP) {
        let cfg: SampleRtlConfig = v.config()?;
        for step in [32, 200, 1024] {
            let mut rng = ChaCha8Rng::seed_from_u64(18);
            let class = random_class_lut(&mut rng, cfg.voxel_w)?;
            let model = Sampler::new(cfg.sample_config(step, None), class)?;
            let (mut col, mut op) = (ErrorStats::default(), ErrorStats::default());
            for _ in 0..n_items {
                let it = random_sample_in(&mut rng, cfg.voxel_w);
                let out = model.sample(&it);
                let r = model.reference(&it);
                let got = [out.color[0], out.color[1], out.color[2], out.opacity];
                for (ch, (&g, &x)) in got.iter().zip(&r).enumerate() {
                    if x < 4095.0 {
                        let e = f64::from(g) - x;
                        if ch < 3 {
                            col.add(e)
                        } else {
                            op.add(e)
                        }
                    }
                }
            }
            println!(
                "| {} | {step} | {:.2} / {:.3} / {:+.3} | {:.2} / {:.3} / {:+.3} |",
                v.config,
                col.max_abs,
                col.rms(),
                col.mean(),
                op.max_abs,
                op.rms(),
                op.mean()
            );
        }
    }
    println!();
    Ok(())
}
