//! Benchmark of the GI-Cube queue sorter (`gicube_sorter`): speed of the RTL and the model, and
//! the sorter's choices against an ideal priority queue.

use super::common::{open, speed_header, speed_row, Compare};
use anyhow::Result;
use cube5_model::unit::UnitConfig;
use cube5_model::units::gicube_sorter::{
    measure_accuracy, Sorter, SorterConfig, SorterIn, SorterTraffic, Workload,
};
use cube5_tb::variants_of;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = SorterConfig::TOP;

pub fn run(n_items: usize) -> Result<()> {
    println!("## {TOP}\n");
    println!(
        "Random update traffic (phases of mixed updates, bursts, draining, ties, maxima, clears);"
    );
    println!("one item is one update (or no-op) and one logical sorter cycle, so items/clock is updates/clock.\n");
    speed_header();
    for v in variants_of(TOP) {
        let cfg: SorterConfig = v.config()?;
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut traffic = SorterTraffic::new(cfg)?;
        let items: Vec<SorterIn> = (0..n_items).map(|_| traffic.next_item(&mut rng)).collect();
        let mut dut = open(v, cfg, &[])?;
        speed_row(&mut dut, &mut Sorter::new(cfg)?, &items, Compare::No)?;
    }
    println!();

    println!(
        "Choices of the pipelined insertion sorter against an ideal priority queue fed the same"
    );
    println!(
        "updates (model, {n_items} cycles per row; importances from the ideal, exact counters)."
    );
    println!(
        "Workloads (`Workload`): `loaded`: the host first brings in 8 rays per queue on average,"
    );
    println!(
        "then each cycle the active queue loses a ray with probability 0.5, else a ray arrives at"
    );
    println!(
        "any queue; `hot`: as loaded, half of the arrivals at 8 queues; `contrib`: as loaded, each"
    );
    println!(
        "ray's importance is a contribution 1..16; `light`: no preload (small queues, a new active"
    );
    println!(
        "queue every few cycles: the stress case). *Selection miss*: a new active queue whose"
    );
    println!(
        "importance is below the best other non-empty queue (per selection). *Candidate miss*: per"
    );
    println!("cycle, the entry the shift-up would promote is below the best non-active queue. Shortfalls");
    println!(
        "in importance units (rays, or contribution LSBs), relative = shortfall / best, means over"
    );
    println!(
        "the misses. *Unlisted*: non-empty queues the sorter does not hold (mean per cycle).\n"
    );
    println!("| ranks | queues | ImpW | workload | selections | selection miss | mean / max shortfall | mean rel. | candidate miss | cand. mean rel. | idle cycles | unlisted | drops / 1k cycles |");
    println!("|------:|-------:|-----:|----------|-----------:|---------------:|---------------------:|----------:|---------------:|----------------:|------------:|---------:|------------------:|");
    let configs = [
        SorterConfig::R8,
        SorterConfig::new(4, 7, 16)?,
        SorterConfig::new(8, 7, 16)?,
        SorterConfig::new(16, 7, 16)?,
        SorterConfig::R32,
        SorterConfig::new(64, 7, 16)?,
        SorterConfig::new(64, 6, 16)?,
    ];
    for cfg in configs {
        let preload = 8 * u64::from(cfg.queues());
        for (wname, pre, hot, weight) in [
            ("loaded", preload, 0.0, 1),
            ("hot", preload, 0.5, 1),
            ("contrib", preload, 0.0, 16),
            ("light", 0, 0.0, 1),
        ] {
            let mut rng = ChaCha8Rng::seed_from_u64(2);
            let mut w = Workload::new(cfg, pre, 0.5, hot, 8, weight)?;
            let items: Vec<SorterIn> = (0..n_items).map(|_| w.next_item(&mut rng)).collect();
            let r = measure_accuracy(cfg, items)?;
            println!(
                "| {} | {} | {} | {wname} | {} | {:.2}% | {:.2} / {:.0} | {:.1}% | {:.2}% | {:.1}% | {:.2}% | {:.2} | {:.2} |",
                cfg.ranks,
                cfg.queues(),
                cfg.imp_w,
                r.selections,
                100.0 * r.selection_miss_rate(),
                r.selection_mean_shortfall(),
                r.selection_shortfall_max,
                100.0 * r.selection_mean_rel(),
                100.0 * r.candidate_miss_rate(),
                100.0 * r.candidate_mean_rel(),
                100.0 * r.idle_rate(),
                r.mean_unlisted(),
                1000.0 * r.dropped as f64 / r.cycles.max(1) as f64
            );
        }
    }
    println!();
    Ok(())
}
