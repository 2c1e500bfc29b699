//! Benchmarks of the skewed memory controller (`cube5_skewmem`) and the recursive-blocking
//! addressing unit (`cube5_rblock`): speed, exactness against plain references, what the block LUT
//! threshold trades (module reads saved against error), and what recursive blocking buys a cache.

use anyhow::{anyhow, Result};
use cube5_model::phantom::head_phantom;
use cube5_model::unit::StreamUnit;
use cube5_model::units::cube5_rblock::{BlockingLuts, RBlock, RBlockConfig, RBlockDir, RBlockIn};
use cube5_model::units::cube5_skewmem::{
    Axis, BlockLut, SkewConfig, SkewDims, SkewIn, SkewMem, SkewOp,
};
use cube5_model::volume::Volume;
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

const SKEW_VARIANTS: [(&str, SkewConfig); 5] = [
    ("p1", SkewConfig::P1),
    ("p2", SkewConfig::P2),
    ("p4", SkewConfig::DEFAULT),
    ("p4l4", SkewConfig::P4_L4),
    ("p8", SkewConfig::P8),
];

const RBLOCK_VARIANTS: [(&str, RBlockConfig); 3] = [
    ("c2", RBlockConfig::NARROW),
    ("c8", RBlockConfig::DEFAULT),
    ("r759", RBlockConfig::UNEQUAL),
];

/// A full `M^3` volume of random voxels, its identity LUT, the writes that load it and `n` random
/// commands (55% beam reads along a random axis, 45% writes).
fn skew_workload(cfg: SkewConfig, n: usize, seed: u64) -> Result<(SkewMem, Vec<SkewIn>)> {
    let m = cfg.max_dim();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let dims = SkewDims::new(&cfg, [m; 3])?;
    let lut = BlockLut::identity([m as usize; 3], cfg.block as usize)?;
    let mem = SkewMem::new(cfg, dims, lut)?;
    let mut cmds = Vec::with_capacity(dims.voxels() + n);
    for z in 0..m {
        for y in 0..m {
            for x in 0..m {
                cmds.push(SkewIn::write(
                    [x, y, z],
                    rng.random_range(0..=cfg.voxel_max()),
                ));
            }
        }
    }
    cmds.extend((0..n).map(|_| SkewIn {
        op: if rng.random_bool(0.45) {
            SkewOp::Write
        } else {
            SkewOp::Read
        },
        axis: rng.random_range(0..3),
        pos: [0; 3].map(|_| rng.random_range(0..m)),
        data: rng.random_range(0..=cfg.voxel_max()),
        probe: rng.random_range(0..cfg.p),
    }));
    Ok((mem, cmds))
}

fn speed_row(
    unit: &str,
    name: &str,
    cycles: u64,
    n: u64,
    sim_secs: f64,
    model_secs: f64,
) -> String {
    let sim_rate = cycles as f64 / sim_secs;
    let model_rate = n as f64 / model_secs;
    format!(
        "| {unit} | {name} | {cycles} | {:.4} | {:.2e} | {:.2e} | {:.1}x |",
        n as f64 / cycles as f64,
        sim_rate,
        model_rate,
        model_rate / sim_rate
    )
}

fn skew_speed(n_items: usize) -> Result<()> {
    println!("## cube5_skewmem and cube5_rblock\n");
    println!("Speed at full rate (no idle, no back-pressure). `cube5_skewmem`: the whole `M^3` volume is");
    println!("written first, then {n_items} random commands (55% beam reads, 45% writes); one command is");
    println!(
        "one beam of P voxels or one write, so voxels per clock = P x items/clock for reads.\n"
    );
    println!("| unit | config | RTL cycles | items/clock | sim cycles/s | model items/s | model/sim speed |");
    println!("|------|--------|-----------:|------------:|-------------:|--------------:|----------------:|");
    for (name, cfg) in SKEW_VARIANTS {
        let (mut model, cmds) = skew_workload(cfg, n_items, 1)?;
        let mut dut = RtlStream::new(&format!("cube5_skewmem_{name}"), cfg, 1)?;
        for (a, d) in model.config_writes() {
            dut.write_config(a, &d)?;
        }
        let n = cmds.len() as u64;
        let packed = dut.pack(&cmds);
        let t = Instant::now();
        let driven = dut.drive_packed(&packed, &Traffic::full_speed(), n, 2 * n + 1000)?;
        let sim_secs = t.elapsed().as_secs_f64();
        if driven.stats.produced != n {
            return Err(anyhow!(
                "cube5_skewmem_{name}: RTL produced {} of {n}",
                driven.stats.produced
            ));
        }
        let t = Instant::now();
        let out = model.run(&cmds);
        let model_secs = t.elapsed().as_secs_f64();
        let differ = driven
            .outputs
            .iter()
            .zip(&out)
            .filter(|(r, m)| r.value != **m)
            .count();
        if differ != 0 {
            return Err(anyhow!(
                "cube5_skewmem_{name}: {differ} responses differ from the model"
            ));
        }
        println!(
            "{}",
            speed_row(
                "cube5_skewmem",
                name,
                driven.stats.cycles,
                n,
                sim_secs,
                model_secs
            )
        );
    }
    for (name, cfg) in RBLOCK_VARIANTS {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let items: Vec<RBlockIn> = (0..n_items)
            .map(|_| RBlockIn {
                value: rng.random_range(0..cfg.len()),
                dir: if rng.random_bool(0.5) {
                    RBlockDir::ToBlocked
                } else {
                    RBlockDir::ToLinear
                },
            })
            .collect();
        let mut dut = RtlStream::new(&format!("cube5_rblock_{name}"), cfg, 1)?;
        let n = items.len() as u64;
        let packed = dut.pack(&items);
        let t = Instant::now();
        let driven = dut.drive_packed(&packed, &Traffic::full_speed(), n, 2 * n + 1000)?;
        let sim_secs = t.elapsed().as_secs_f64();
        let mut model = RBlock::new(cfg)?;
        let t = Instant::now();
        let out = model.run(&items);
        let model_secs = t.elapsed().as_secs_f64();
        std::hint::black_box(out);
        println!(
            "{}",
            speed_row(
                "cube5_rblock",
                name,
                driven.stats.cycles,
                n,
                sim_secs,
                model_secs
            )
        );
    }
    println!();
    Ok(())
}

/// Exactness: every beam the model returns against a plain `Vec<u16>` (x fastest), and the bit
/// form of recursive blocking against the patent's LUT form.
fn exactness(n_items: usize) -> Result<()> {
    println!("Error against the plain references ({n_items} random items per configuration): the");
    println!(
        "skewed memory against a `Vec<u16>` volume written alongside it (identity LUT), recursive"
    );
    println!("blocking's bit form (the RTL's) against the patent's LUT form (G = 3) and the round trip.\n");
    println!(
        "| unit | config | values compared | mismatches | max abs error (LSB) | RMS error (LSB) |"
    );
    println!(
        "|------|--------|----------------:|-----------:|--------------------:|----------------:|"
    );
    for (name, cfg) in SKEW_VARIANTS {
        let m = cfg.max_dim();
        let dims = SkewDims::new(&cfg, [m; 3])?;
        let mut mem = SkewMem::new(
            cfg,
            dims,
            BlockLut::identity([m as usize; 3], cfg.block as usize)?,
        )?;
        let mut plain = vec![0u16; dims.voxels()];
        let idx = |c: [u32; 3]| (c[0] + m * (c[1] + m * c[2])) as usize;
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let (mut compared, mut bad, mut max, mut sq) = (0u64, 0u64, 0u32, 0f64);
        for i in 0..n_items {
            let c = [0; 3].map(|_| rng.random_range(0..m));
            if i % 2 == 0 {
                let v = rng.random_range(0..=cfg.voxel_max());
                mem.command(&SkewIn::write(c, v));
                plain[idx(c)] = v as u16;
            } else {
                let axis = Axis::ALL[rng.random_range(0..3)];
                let r = mem.command(&SkewIn::read(c, axis));
                let mut s = c;
                s[axis.index()] &= !(cfg.p - 1);
                for (l, &v) in r.voxels.iter().enumerate() {
                    let mut q = s;
                    q[axis.index()] += l as u32;
                    let e = v.abs_diff(u32::from(plain[idx(q)]));
                    compared += 1;
                    bad += u64::from(e != 0);
                    max = max.max(e);
                    sq += f64::from(e) * f64::from(e);
                }
            }
        }
        println!(
            "| cube5_skewmem | {name} | {compared} | {bad} | {max} | {:.3} |",
            (sq / compared.max(1) as f64).sqrt()
        );
    }
    for (name, cfg) in RBLOCK_VARIANTS {
        let unit = RBlock::new(cfg)?;
        let luts = BlockingLuts::new(cfg, 3)?;
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let (mut compared, mut bad, mut max) = (0u64, 0u64, 0u64);
        for _ in 0..n_items {
            let v = rng.random_range(0..cfg.len());
            let o = unit.convert(&RBlockIn {
                value: v,
                dir: RBlockDir::ToBlocked,
            });
            let l = unit.convert(&RBlockIn {
                value: v,
                dir: RBlockDir::ToLinear,
            });
            let back = unit.convert(&RBlockIn {
                value: o,
                dir: RBlockDir::ToLinear,
            });
            for (got, want) in [(o, luts.to_blocked(v)), (l, luts.to_linear(v)), (back, v)] {
                compared += 1;
                bad += u64::from(got != want);
                max = max.max(got.abs_diff(want));
            }
        }
        println!(
            "| cube5_rblock | {name} | {compared} | {bad} | {max} | {:.3} |",
            0.0
        );
    }
    println!();
    Ok(())
}

/// The block LUT's threshold: beams whose block is "empty" (all voxels <= threshold) are skipped,
/// saving module reads and returning zeros. Every x beam of the head phantom is read once.
fn threshold_tradeoff() -> Result<()> {
    let cfg = SkewConfig {
        max_dim_log2: 6,
        ..SkewConfig::DEFAULT
    };
    let n = 64u32;
    let vol: Volume = head_phantom(n as usize, cfg.voxel_w)?;
    println!(
        "Block LUT threshold on the {n}^3 head phantom (12-bit voxels, B = 8, P = 4): every x beam"
    );
    println!("of the volume read once; error in voxel LSBs against the stored volume, over all voxels.\n");
    println!("| threshold | blocks skipped | module reads | reads saved | max abs error (LSB) | RMS error (LSB) |");
    println!("|----------:|---------------:|-------------:|------------:|--------------------:|----------------:|");
    let dims = SkewDims::new(&cfg, [n; 3])?;
    let full_reads = u64::from(n * n * n);
    for threshold in [0u32, 40, 205, 410, 900] {
        let lut = BlockLut::from_volume(&vol, 8, threshold)?;
        let skipped = lut.skipped();
        let blocks = lut.entries.len();
        let mut mem = SkewMem::new(cfg, dims, lut)?;
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let v = vol.get(i64::from(x), i64::from(y), i64::from(z));
                    mem.command(&SkewIn::write([x, y, z], v));
                }
            }
        }
        mem.reset();
        let (mut max, mut sq) = (0u32, 0f64);
        for z in 0..n {
            for y in 0..n {
                for x in (0..n).step_by(cfg.p as usize) {
                    let r = mem.command(&SkewIn::read([x, y, z], Axis::X));
                    for (i, &v) in r.voxels.iter().enumerate() {
                        let want = vol.get(i64::from(x) + i as i64, i64::from(y), i64::from(z));
                        let e = v.abs_diff(want);
                        max = max.max(e);
                        sq += f64::from(e) * f64::from(e);
                    }
                }
            }
        }
        let reads: u64 = (0..cfg.p as usize)
            .map(|k| u64::from(mem.counters(k).0))
            .sum();
        println!(
            "| {threshold} | {skipped} / {blocks} | {reads} | {:.1}% | {max} | {:.3} |",
            100.0 * (1.0 - reads as f64 / full_reads as f64),
            (sq / full_reads as f64).sqrt()
        );
    }
    println!();
    Ok(())
}

/// A set-associative LRU cache of `sets x ways` lines of `line` bytes; counts misses.
struct Cache {
    line_shift: u32,
    sets: usize,
    ways: usize,
    tags: Vec<u64>,
    age: Vec<u64>,
    clock: u64,
    misses: u64,
    accesses: u64,
}

impl Cache {
    fn new(bytes: usize, line: usize, ways: usize) -> Self {
        let sets = bytes / line / ways;
        Self {
            line_shift: line.trailing_zeros(),
            sets,
            ways,
            tags: vec![u64::MAX; sets * ways],
            age: vec![0; sets * ways],
            clock: 0,
            misses: 0,
            accesses: 0,
        }
    }

    fn access(&mut self, addr: u64) {
        self.clock += 1;
        self.accesses += 1;
        let tag = addr >> self.line_shift;
        let set = (tag as usize) % self.sets;
        let ways = &mut self.tags[set * self.ways..][..self.ways];
        let ages = &mut self.age[set * self.ways..][..self.ways];
        if let Some(w) = ways.iter().position(|&t| t == tag) {
            ages[w] = self.clock;
            return;
        }
        self.misses += 1;
        let victim = (0..self.ways).min_by_key(|&w| ages[w]).unwrap_or(0);
        ways[victim] = tag;
        ages[victim] = self.clock;
    }
}

/// The patent's argument for recursive blocking [448], [452]: a 5^3 box filter over a volume of
/// 8-bit voxels, traversed in storage order, source and destination through one small L1 cache.
fn cache_experiment() -> Result<()> {
    let cfg = RBlockConfig::new(6, 6, 6)?;
    let n = 64u64;
    let unit = RBlock::new(cfg)?;
    println!("What recursive blocking is for [448], [452]: a 5^3 box filter over a {n}^3 volume of 8-bit");
    println!("voxels, traversed in storage order; the source and the destination volume (256 KB each) through");
    println!("one L1 cache with LRU replacement. Misses per voxel filtered (126 accesses each):\n");
    println!("| cache | linear layout misses/voxel | recursive blocking misses/voxel | ratio |");
    println!("|-------|---------------------------:|--------------------------------:|------:|");
    for (label, bytes, line, ways) in [
        ("16 KB, 2-way, 32 B lines", 16 << 10, 32, 2),
        ("16 KB, 4-way, 64 B lines", 16 << 10, 64, 4),
        ("32 KB, 8-way, 64 B lines", 32 << 10, 64, 8),
    ] {
        let mut misses = [0f64; 2];
        for (k, blocked) in [false, true].into_iter().enumerate() {
            let addr = |lin: u64| -> u64 {
                if blocked {
                    unit.convert(&RBlockIn {
                        value: lin,
                        dir: RBlockDir::ToBlocked,
                    })
                } else {
                    lin
                }
            };
            let mut cache = Cache::new(bytes, line, ways);
            for i in 0..cfg.len() {
                // Storage order: offset i holds voxel `lin`.
                let lin = if blocked {
                    unit.convert(&RBlockIn {
                        value: i,
                        dir: RBlockDir::ToLinear,
                    })
                } else {
                    i
                };
                let [x, y, z] = cfg.coords(lin);
                for dz in -2i64..=2 {
                    for dy in -2i64..=2 {
                        for dx in -2i64..=2 {
                            let q = [x as i64 + dx, y as i64 + dy, z as i64 + dz];
                            if q.iter().all(|&c| (0..n as i64).contains(&c)) {
                                cache.access(addr(cfg.linear(q.map(|c| c as u64))));
                            }
                        }
                    }
                }
                cache.access((1 << 18) + addr(lin)); // the destination volume
            }
            misses[k] = cache.misses as f64 / cfg.len() as f64;
        }
        println!(
            "| {label} | {:.3} | {:.3} | {:.1}x |",
            misses[0],
            misses[1],
            misses[0] / misses[1].max(1e-9)
        );
    }
    println!();
    Ok(())
}

pub fn run(n_items: usize) -> Result<()> {
    skew_speed(n_items)?;
    exactness(n_items)?;
    threshold_tradeoff()?;
    cache_experiment()?;
    Ok(())
}
