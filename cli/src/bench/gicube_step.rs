//! Benchmark of the GI-Cube step, leap and advance (`gicube_step`): speed of the RTL and the
//! model, the model against its f64 reference, and how far a leap carries a ray.

use super::common::{speed_table, Compare};
use anyhow::Result;
use cube5_model::unit::UnitConfig;
use cube5_model::units::gicube_step::{random_step_in, StepConfig, StepIn, Stepper};
use cube5_tb::variants_of;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = StepConfig::TOP;

pub fn run(n_items: usize) -> Result<()> {
    println!("One item is one ray (half of them leaping); one ray per clock, leaping or not.\n");
    speed_table(
        |cfg: StepConfig| {
            let mut rng = ChaCha8Rng::seed_from_u64(15);
            let items: Vec<StepIn> = (0..n_items)
                .map(|_| random_step_in(&mut rng, &cfg))
                .collect();
            Ok((Stepper::new(cfg)?, items, vec![]))
        },
        Compare::No,
    )?;

    println!("Against the f64 reference (real divisions and ceil for the leap's count, real");
    println!(
        "positions for the exit test and the queue): {n_items} random rays per configuration;"
    );
    println!("the mean and largest k of the leaps (grid steps one leap replaces).\n");
    println!("| config | disagreements with f64 | leaps | mean k of a leap | largest k | exits |");
    println!("|--------|-----------------------:|------:|-----------------:|----------:|------:|");
    for v in variants_of(TOP) {
        let cfg: StepConfig = v.config()?;
        let unit = Stepper::new(cfg)?;
        let mut rng = ChaCha8Rng::seed_from_u64(16);
        let (mut bad, mut leaps, mut ksum, mut kmax, mut exits) = (0u64, 0u64, 0u64, 0u32, 0u64);
        for _ in 0..n_items {
            let it = random_step_in(&mut rng, &cfg);
            let o = unit.step(it.start, it.dir, it.queue, it.leap);
            bad += u64::from(o != unit.reference(&it));
            if it.leap {
                leaps += 1;
                ksum += u64::from(o.k);
                kmax = kmax.max(o.k);
            }
            exits += u64::from(o.exit);
        }
        println!(
            "| {} | {bad} | {leaps} | {:.1} | {kmax} | {exits} |",
            v.config,
            ksum as f64 / leaps.max(1) as f64
        );
    }
    println!();
    Ok(())
}
