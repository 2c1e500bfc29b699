//! Benchmark of the GI-Cube queue units: the queue sorter (`gicube_sorter`), queue bucketing
//! (`gicube_bucket`) and the ray packet round trip (`gicube_packet_loop`). Speed of the RTL and
//! the model; the sorter's choices against an ideal priority queue; bucketing against its f64
//! reference and the load balance of the three distributions; packet quantization error.

use anyhow::Result;
use cube5_model::unit::{StreamCodec, StreamUnit};
use cube5_model::units::gicube_bucket::{
    random_position, BucketConfig, BucketIn, BucketUnit, Position,
};
use cube5_model::units::gicube_packet_loop::{
    random_packet, PacketLoop, PacketLoopConfig, RayPacket, RayReal, RayType, POS_FRAC_W,
};
use cube5_model::units::gicube_sorter::{
    measure_accuracy, Sorter, SorterConfig, SorterIn, SorterTraffic, Workload,
};
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
