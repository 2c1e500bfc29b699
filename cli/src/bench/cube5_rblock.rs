//! Benchmark of the recursive-blocking addressing unit (`cube5_rblock`): speed, exactness against
//! the patent's LUT form, and what recursive blocking buys a cache.

use super::common::{exactness_header, exactness_row, speed_table, Compare, ErrorStats};
use anyhow::Result;
use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_rblock::{BlockingLuts, RBlock, RBlockConfig, RBlockDir, RBlockIn};
use cube5_tb::variants_of;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = RBlockConfig::TOP;

/// Speed at full rate: random conversions, both directions.
fn speed(n_items: usize) -> Result<()> {
    println!("Speed at full rate (no idle, no back-pressure): {n_items} random addresses, half converted");
    println!("to the blocked layout, half back to the linear one.\n");
    speed_table(
        |cfg: RBlockConfig| {
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
            Ok((RBlock::new(cfg)?, items, vec![]))
        },
        Compare::No,
    )
}

/// Exactness: the bit form of recursive blocking (the RTL's) against the patent's LUT form.
fn exactness(n_items: usize) -> Result<()> {
    println!(
        "Error against the plain reference ({n_items} random items per configuration): recursive"
    );
    println!("blocking's bit form (the RTL's) against the patent's LUT form (G = 3) and the round trip.\n");
    exactness_header();
    for variant in variants_of(TOP) {
        let cfg: RBlockConfig = variant.config()?;
        let unit = RBlock::new(cfg)?;
        let luts = BlockingLuts::new(cfg, 3)?;
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut err = ErrorStats::default();
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
                err.add(got.abs_diff(want) as f64);
            }
        }
        exactness_row(variant, &err);
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
    speed(n_items)?;
    exactness(n_items)?;
    cache_experiment()
}
