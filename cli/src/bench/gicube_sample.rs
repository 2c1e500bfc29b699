//! Benchmark of the GI-Cube sample datapath (`gicube_sample`): speed of the RTL and the model on
//! random samples with random tables, every output compared with the model's.

use super::common::{speed_table, Compare};
use anyhow::Result;
use cube5_model::unit::UnitConfig;
use cube5_model::units::gicube_sample::{
    random_class_lut, random_sample_in, SampleIn, SampleRtlConfig, Sampler,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = SampleRtlConfig::TOP;

pub fn run(n_items: usize) -> Result<()> {
    println!("## {TOP}\n");
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
    )
}
