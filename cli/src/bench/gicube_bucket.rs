//! Benchmark of GI-Cube queue bucketing (`gicube_bucket`): speed of the RTL and the model,
//! bucketing against its f64 reference and the load balance of the three distributions.

use super::common::{speed_table, Compare};
use anyhow::Result;
use cube5_model::unit::UnitConfig;
use cube5_model::units::gicube_bucket::{
    random_position, BucketConfig, BucketIn, BucketUnit, Position,
};
use cube5_model::units::gicube_packet_loop::POS_FRAC_W;
use cube5_tb::variants_of;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = BucketConfig::TOP;

pub fn run(n_items: usize) -> Result<()> {
    println!("One item is `Lanes` positions (2 = the two rays per cycle of [370]).\n");
    speed_table(
        |cfg: BucketConfig| {
            let mut rng = ChaCha8Rng::seed_from_u64(3);
            let items: Vec<BucketIn> = (0..n_items)
                .map(|_| {
                    BucketIn(
                        (0..cfg.lanes)
                            .map(|_| random_position(&mut rng, &cfg))
                            .collect(),
                    )
                })
                .collect();
            Ok((BucketUnit::new(cfg)?, items, vec![]))
        },
        Compare::No,
    )?;

    println!(
        "Against the f64 reference (real coordinates, floor and real division): {n_items} random"
    );
    println!(
        "positions per configuration. Load balance of the schemes of [348] at the design point"
    );
    println!(
        "(256^3, 32^3 blocks, 4 processors) for rays entering through one face of the volume:"
    );
    println!("busiest processor / mean (1.00 = even).\n");
    println!("| config | disagreements with f64 | entry face x = 0 | entry face y = 0 | entry face z = 0 | uniform in volume |");
    println!("|--------|-----------------------:|-----------------:|-----------------:|-----------------:|------------------:|");
    for v in variants_of(TOP) {
        let cfg: BucketConfig = v.config()?;
        let unit = BucketUnit::new(cfg)?;
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let mut bad = 0u64;
        for _ in 0..n_items {
            let p = random_position(&mut rng, &cfg);
            let real = p.0.map(|x| f64::from(x) / f64::from(1u32 << POS_FRAC_W));
            bad += u64::from(unit.bucket(p) != unit.reference(real));
        }
        let n = cfg.vol_side() << POS_FRAC_W;
        let mut balance = Vec::new();
        for face in [Some(0usize), Some(1), Some(2), None] {
            let mut load = vec![0u64; cfg.procs() as usize];
            for _ in 0..n_items.min(100_000) {
                let mut p: [u32; 3] = std::array::from_fn(|_| rng.random_range(0..n));
                if let Some(a) = face {
                    p[a] = rng.random_range(0..1 << POS_FRAC_W); // inside the first voxel
                }
                load[unit.bucket(Position(p)).proc as usize] += 1;
            }
            let mean = load.iter().sum::<u64>() as f64 / load.len() as f64;
            balance.push(*load.iter().max().unwrap() as f64 / mean);
        }
        println!(
            "| {} ({:?}, p = {}) | {bad} | {:.2} | {:.2} | {:.2} | {:.2} |",
            v.config,
            cfg.dist,
            cfg.procs(),
            balance[0],
            balance[1],
            balance[2],
            balance[3]
        );
    }
    println!();
    Ok(())
}
