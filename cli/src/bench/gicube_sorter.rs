//! Benchmark of the GI-Cube queue sorter (`gicube_sorter`): speed of the RTL and the model; the
//! sorter's choices against an ideal priority queue (median and range over seeds); the end of a
//! frame (arrivals stop, every ray must drain) and the co-simulated drain frames.

use super::common::{speed_table, Compare};
use anyhow::Result;
use cube5_model::unit::UnitConfig;
use cube5_model::units::gicube_sorter::{
    measure_accuracy, AccuracyReport, DrainFrame, Sorter, SorterConfig, SorterIn, SorterOp,
    SorterTraffic, Workload,
};
use cube5_tb::variants_of;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = SorterConfig::TOP;

/// The verified configurations (the `.variants` lines), in table order.
fn verified() -> Result<Vec<SorterConfig>> {
    variants_of(TOP)
        .into_iter()
        .map(|v| Ok(v.config()?))
        .collect()
}

pub fn run(n_items: usize) -> Result<()> {
    println!(
        "Random update traffic (phases of mixed updates, bursts, draining, ties, maxima, clears);"
    );
    println!("one item is one update (or no-op) and one logical sorter cycle, so items/clock is updates/clock.\n");
    speed_table(
        |cfg: SorterConfig| {
            let mut rng = ChaCha8Rng::seed_from_u64(1);
            let mut traffic = SorterTraffic::new(cfg)?;
            let items: Vec<SorterIn> = (0..n_items).map(|_| traffic.next_item(&mut rng)).collect();
            Ok((Sorter::new(cfg)?, items, vec![]))
        },
        Compare::No,
    )?;

    accuracy_table(n_items)?;
    frame_end_table(n_items)?;
    drain_frames_table()?;
    Ok(())
}

/// Seeds of the accuracy rows: every figure is given as the median and range over these.
const SEEDS: u64 = 10;

/// `median [min-max]` of one figure over the seeds.
fn spread(v: &mut [f64], digits: usize, unit: &str) -> String {
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    let med = if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    };
    format!(
        "{med:.digits$}{unit} [{:.digits$}-{:.digits$}]",
        v[0],
        v[n - 1]
    )
}

fn accuracy_table(n_items: usize) -> Result<()> {
    println!(
        "Choices of the pipelined insertion sorter against an ideal priority queue fed the same"
    );
    println!(
        "updates (model, {n_items} cycles per run, {SEEDS} seeds per row: median [min-max] over the"
    );
    println!("seeds; importances from the ideal, exact counters).");
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
        "in importance units (rays, or contribution LSBs), means over the misses. *Unlisted*:"
    );
    println!("non-empty queues the sorter does not hold (mean per cycle).\n");
    println!("| ranks | queues | ImpW | workload | selection miss | mean shortfall | candidate miss | idle cycles | unlisted | drops / 1k cycles |");
    println!("|------:|-------:|-----:|----------|---------------:|---------------:|---------------:|------------:|---------:|------------------:|");
    // Other rank counts at the RTL's default queues and widths (model only).
    let sweep = [4, 8, 16, 64].map(|ranks| SorterConfig {
        ranks,
        ..SorterConfig::DEFAULT
    });
    for cfg in &sweep {
        cfg.validate()?;
    }
    let mut rows: Vec<(SorterConfig, &str, u64, f64, u32)> = Vec::new();
    for cfg in verified()? {
        let preload = 8 * u64::from(cfg.queues());
        rows.push((cfg, "loaded", preload, 0.0, 1));
        rows.push((cfg, "hot", preload, 0.5, 1));
        rows.push((cfg, "contrib", preload, 0.0, 16));
        rows.push((cfg, "light", 0, 0.0, 1));
    }
    for cfg in sweep {
        rows.push((cfg, "loaded", 8 * u64::from(cfg.queues()), 0.0, 1));
    }
    for (cfg, wname, pre, hot, weight) in rows {
        let reps: Vec<AccuracyReport> = (1..=SEEDS)
            .map(|seed| {
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                let mut w = Workload::new(cfg, pre, 0.5, hot, 8, weight as i32)?;
                let items: Vec<SorterIn> = (0..n_items).map(|_| w.next_item(&mut rng)).collect();
                Ok(measure_accuracy(cfg, items)?)
            })
            .collect::<Result<_>>()?;
        let col = |f: &dyn Fn(&AccuracyReport) -> f64| -> Vec<f64> { reps.iter().map(f).collect() };
        println!(
            "| {} | {} | {} | {wname} | {} | {} | {} | {} | {} | {} |",
            cfg.ranks,
            cfg.queues(),
            cfg.imp_w,
            spread(&mut col(&|r| 100.0 * r.selection_miss_rate()), 2, "%"),
            spread(&mut col(&|r| r.selection_mean_shortfall()), 2, ""),
            spread(&mut col(&|r| 100.0 * r.candidate_miss_rate()), 2, "%"),
            spread(&mut col(&|r| 100.0 * r.idle_rate()), 2, "%"),
            spread(&mut col(&|r| r.mean_unlisted()), 1, ""),
            spread(
                &mut col(&|r| 1000.0 * r.dropped as f64 / r.cycles.max(1) as f64),
                2,
                ""
            ),
        );
    }
    println!();
    Ok(())
}

/// `loaded` until the middle of the run, then the end of the frame: no arrivals, the active queue
/// gives one ray per cycle, until every queue is empty and the sorter idle.
fn frame_end_table(n_items: usize) -> Result<()> {
    println!(
        "End of a frame (`Workload::with_stop`): the `loaded` workload for {} cycles, then no",
        n_items / 2
    );
    println!(
        "arrivals; each cycle the active queue gives one ray to the pipeline, until every queue is"
    );
    println!("empty. Ideal: one ray per cycle, `drain cycles = rays at the stop`. {SEEDS} seeds per row.\n");
    println!("| config | rays at the stop | drain cycles over ideal | overhead / rays | longest idle stretch | rays left | selection miss in the drain |");
    println!("|--------|-----------------:|------------------------:|----------------:|---------------------:|----------:|----------------------------:|");
    for v in variants_of(TOP) {
        let (name, cfg): (_, SorterConfig) = (v.config, v.config()?);
        let (mut rays, mut over, mut rel, mut idle, mut miss) =
            (vec![], vec![], vec![], vec![], vec![]);
        let mut left_max = 0u64;
        for seed in 1..=SEEDS {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let stop = (n_items / 2) as u64;
            let mut w =
                Workload::new(cfg, 8 * u64::from(cfg.queues()), 0.5, 0.0, 8, 1)?.with_stop(stop);
            let mut items: Vec<SorterIn> = (0..stop).map(|_| w.next_item(&mut rng)).collect();
            let at_stop: u64 = w.shadow().counters().iter().map(|&c| u64::from(c)).sum();
            let limit = u64::from(cfg.idle_stretch_bound());
            let (mut cycles, mut last_ray, mut quiet, mut run, mut longest) =
                (0u64, 0u64, 0u64, 0u64, 0u64);
            let drain_start = items.len();
            while quiet < limit {
                let left: u64 = w.shadow().counters().iter().map(|&c| u64::from(c)).sum();
                let item = w.next_item(&mut rng);
                items.push(item);
                cycles += 1;
                if item.op != SorterOp::Noop {
                    last_ray = cycles;
                    run = 0;
                } else if left > 0 {
                    run += 1;
                    longest = longest.max(run);
                }
                let s = w.shadow();
                quiet = if s.active().is_none() && s.is_empty() {
                    quiet + 1
                } else {
                    0
                };
            }
            let left: u64 = w.shadow().counters().iter().map(|&c| u64::from(c)).sum();
            left_max = left_max.max(left);
            let full = measure_accuracy(cfg, items.iter().copied())?;
            let head = measure_accuracy(cfg, items[..drain_start].iter().copied())?;
            let sel = full.selections - head.selections;
            let missed = full.selection_misses - head.selection_misses;
            rays.push(at_stop as f64);
            over.push((last_ray - at_stop) as f64);
            rel.push(100.0 * (last_ray - at_stop) as f64 / at_stop.max(1) as f64);
            idle.push(longest as f64);
            miss.push(100.0 * missed as f64 / sel.max(1) as f64);
        }
        println!(
            "| {name} | {} | {} | {} | {} | {left_max} | {} |",
            spread(&mut rays, 0, ""),
            spread(&mut over, 0, ""),
            spread(&mut rel, 2, "%"),
            spread(&mut idle, 0, ""),
            spread(&mut miss, 2, "%"),
        );
    }
    println!();
    Ok(())
}

/// The drain test's frames (`DrainFrame::random`): every queue preloaded with a random count.
fn drain_frames_table() -> Result<()> {
    const FRAMES: u64 = 1000;
    println!("Drain frames like the co-simulation test's (`DrainFrame::random`, {FRAMES} frames per config):");
    println!("each queue empty (40 %) or 1..=max(6, 512/Q) rays, one full queue (256) in a frame of ten,");
    println!(
        "preloaded with `Set`, then drained one ray per cycle. Overhead = drain cycles - rays.\n"
    );
    println!("| config | rays per frame (mean) | overhead mean | overhead max | longest idle stretch | bound per stretch (Q + R + 1) | rays left |");
    println!("|--------|----------------------:|--------------:|-------------:|---------------------:|------------------------------:|----------:|");
    for v in variants_of(TOP) {
        let (name, cfg): (_, SorterConfig) = (v.config, v.config()?);
        let mut rng = ChaCha8Rng::seed_from_u64(18);
        let (mut rays, mut over, mut worst, mut idle, mut left) = (0u64, 0u64, 0u64, 0u64, 0u64);
        for _ in 0..FRAMES {
            let f = DrainFrame::random(cfg, &mut rng)?;
            rays += f.rays;
            over += f.overhead();
            worst = worst.max(f.overhead());
            idle = idle.max(f.longest_idle);
            left += f.rays_left;
        }
        println!(
            "| {name} | {:.1} | {:.2} | {worst} | {idle} | {} | {left} |",
            rays as f64 / FRAMES as f64,
            over as f64 / FRAMES as f64,
            cfg.idle_stretch_bound()
        );
    }
    println!();
    Ok(())
}
