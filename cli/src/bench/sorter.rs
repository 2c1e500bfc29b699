//! Benchmark of the GI-Cube queue units: the queue sorter (`gicube_sorter`), queue bucketing
//! (`gicube_bucket`) and the ray packet round trip (`gicube_packet_loop`). Speed of the RTL and
//! the model; the sorter's choices against an ideal priority queue; bucketing against its f64
//! reference and the load balance of the three distributions; packet quantization error.

use anyhow::Result;
use cube5_model::gicube::bucket::{random_position, BucketConfig, BucketIn, BucketUnit, Position};
use cube5_model::gicube::packet::{
    random_packet, PacketLoop, PacketLoopConfig, RayPacket, RayReal, RayType, POS_FRAC_W,
};
use cube5_model::gicube::sorter::{
    measure_accuracy, AccuracyReport, DrainFrame, Sorter, SorterConfig, SorterIn, SorterTraffic,
    Workload,
};
use cube5_model::unit::{StreamCodec, StreamUnit};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Debug;
use std::time::Instant;

/// One speed row: the RTL at full speed and the model on the same items.
fn speed_row<C, M>(unit: &str, name: &str, cfg: C, model: &mut M, items: &[C::In]) -> Result<()>
where
    C: StreamCodec,
    C::In: Clone + Debug,
    C::Out: Clone + Debug + PartialEq,
    M: StreamUnit<In = C::In, Out = C::Out>,
{
    let variant = format!("{unit}_{name}");
    let mut dut = RtlStream::new(&variant, cfg, 1)?;
    let n = items.len() as u64;
    let packed = dut.pack(items);
    let t = Instant::now();
    let driven = dut.drive_packed(&packed, &Traffic::full_speed(), n, 2 * n + 1000)?;
    let sim_secs = t.elapsed().as_secs_f64();
    let cycles = driven.stats.cycles;

    let t = Instant::now();
    let out = model.run(items);
    let model_secs = t.elapsed().as_secs_f64();
    std::hint::black_box(out);

    let sim_rate = cycles as f64 / sim_secs;
    let model_rate = n as f64 / model_secs;
    println!(
        "| {unit} | {name} | {cycles} | {:.4} | {:.2e} | {:.2e} | {:.1}x |",
        n as f64 / cycles as f64,
        sim_rate,
        model_rate,
        model_rate / sim_rate
    );
    Ok(())
}

fn speed_header() {
    println!(
        "| unit | config | RTL cycles | items/clock | sim cycles/s | model items/s | model/sim speed |"
    );
    println!(
        "|------|--------|-----------:|------------:|-------------:|--------------:|----------------:|"
    );
}

pub fn run(n_items: usize) -> Result<()> {
    sorter_section(n_items)?;
    bucket_section(n_items)?;
    packet_section(n_items)?;
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// gicube_sorter
// ---------------------------------------------------------------------------------------------

fn sorter_section(n_items: usize) -> Result<()> {
    println!("## gicube_sorter\n");
    println!(
        "Random update traffic (phases of mixed updates, bursts, draining, ties, maxima, clears);"
    );
    println!("one item is one update (or no-op) and one logical sorter cycle, so items/clock is updates/clock.\n");
    speed_header();
    for (name, cfg) in [("r8", SorterConfig::R8), ("r32", SorterConfig::R32)] {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut traffic = SorterTraffic::new(cfg)?;
        let items: Vec<SorterIn> = (0..n_items).map(|_| traffic.next_item(&mut rng)).collect();
        speed_row("gicube_sorter", name, cfg, &mut Sorter::new(cfg)?, &items)?;
    }
    println!();

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
    let sweep = [
        SorterConfig::new(4, 7, 16, 256)?,
        SorterConfig::new(8, 7, 16, 256)?,
        SorterConfig::new(16, 7, 16, 256)?,
        SorterConfig::new(64, 7, 16, 256)?,
    ];
    let mut rows: Vec<(SorterConfig, &str, u64, f64, u32)> = Vec::new();
    for cfg in [SorterConfig::R8, SorterConfig::R32] {
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
    for (name, cfg) in [("r8", SorterConfig::R8), ("r32", SorterConfig::R32)] {
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
                if item.op != cube5_model::gicube::sorter::SorterOp::Noop {
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
    println!("Drain frames of the co-simulation test (`DrainFrame::random`, {FRAMES} frames per config):");
    println!("each queue empty (40 %) or 1..=max(6, 512/Q) rays, one full queue (256) in a frame of ten,");
    println!(
        "preloaded with `Set`, then drained one ray per cycle. Overhead = drain cycles - rays.\n"
    );
    println!("| config | rays per frame (mean) | overhead mean | overhead max | longest idle stretch | bound per stretch (Q + R + 1) | rays left |");
    println!("|--------|----------------------:|--------------:|-------------:|---------------------:|------------------------------:|----------:|");
    for (name, cfg) in [("r8", SorterConfig::R8), ("r32", SorterConfig::R32)] {
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

// ---------------------------------------------------------------------------------------------
// gicube_bucket
// ---------------------------------------------------------------------------------------------

const BUCKETS: [(&str, BucketConfig); 5] = [
    ("slab", BucketConfig::SLAB),
    ("skew", BucketConfig::SKEW),
    ("rep", BucketConfig::REP),
    ("slab12", BucketConfig::SLAB12),
    ("skew6", BucketConfig::SKEW6),
];

fn bucket_section(n_items: usize) -> Result<()> {
    println!("## gicube_bucket\n");
    println!("One item is `Lanes` positions (2 = the two rays per cycle of [370]).\n");
    speed_header();
    for (name, cfg) in BUCKETS {
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
        speed_row(
            "gicube_bucket",
            name,
            cfg,
            &mut BucketUnit::new(cfg)?,
            &items,
        )?;
    }
    println!();

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
    for (name, cfg) in BUCKETS {
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
            "| {name} ({:?}, p = {}) | {bad} | {:.2} | {:.2} | {:.2} | {:.2} |",
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

// ---------------------------------------------------------------------------------------------
// gicube_packet_loop
// ---------------------------------------------------------------------------------------------

fn packet_section(n_items: usize) -> Result<()> {
    println!("## gicube_packet\n");
    println!("The round-trip fixture (unpack into the SV struct, repack, per-field probe).\n");
    speed_header();
    for (name, cfg) in [("s1", PacketLoopConfig::S1), ("s2", PacketLoopConfig::S2)] {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let items: Vec<RayPacket> = (0..n_items).map(|_| random_packet(&mut rng)).collect();
        speed_row(
            "gicube_packet_loop",
            name,
            cfg,
            &mut PacketLoop::new(cfg)?,
            &items,
        )?;
    }
    println!();

    println!(
        "Quantization of real ray fields into the packet (round half up, `RayPacket::from_real`)"
    );
    println!(
        "against the f64 values, {n_items} random rays, in LSBs of each field; the bound is 0.5:\n"
    );
    println!("| field | format | max abs error (LSB) | RMS error (LSB) |");
    println!("|-------|--------|--------------------:|----------------:|");
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let mut acc = [(0.0f64, 0.0f64); 4];
    for _ in 0..n_items {
        let r = RayReal {
            u: rng.random_range(0..4096),
            v: rng.random_range(0..4096),
            start: std::array::from_fn(|_| rng.random_range(0.0..4095.99)),
            dir: std::array::from_fn(|_| rng.random_range(-1.0..=1.0)),
            color: std::array::from_fn(|_| rng.random_range(0.0..0.9998)),
            opacity: rng.random_range(0.0..0.9998),
            contribution: rng.random_range(0.0..0.9998),
            interaction: rng.random_range(0.0..0.99999),
            lifetime: rng.random(),
            generation: rng.random(),
            ray_type: RayType::Rendering,
            flags: 0,
        };
        let back = RayPacket::from_real(&r)?.to_real();
        let mut add = |k: usize, got: f64, want: f64, frac: u32| {
            let e = (got - want).abs() * f64::from(1u32 << frac);
            acc[k].0 = acc[k].0.max(e);
            acc[k].1 += e * e;
        };
        for a in 0..3 {
            add(0, back.start[a], r.start[a], 8);
            add(1, back.dir[a], r.dir[a], 14);
            add(2, back.color[a], r.color[a], 12);
        }
        add(3, back.interaction, r.interaction, 16);
    }
    for (k, (field, format, per)) in [
        ("start x, y, z", "U(12.8)", 3.0),
        ("dir x, y, z", "S(2.14)", 3.0),
        ("red, green, blue", "U(0.12)", 3.0),
        ("interaction", "U(0.16)", 1.0),
    ]
    .into_iter()
    .enumerate()
    {
        println!(
            "| {field} | {format} | {:.4} | {:.4} |",
            acc[k].0,
            (acc[k].1 / (per * n_items as f64)).sqrt()
        );
    }
    println!();
    Ok(())
}
