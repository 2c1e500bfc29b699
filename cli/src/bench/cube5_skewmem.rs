//! Benchmark of the skewed memory controller (`cube5_skewmem`): speed, exactness against a plain
//! volume, and what the block LUT threshold trades (module reads saved against error).

use super::common::{exactness_header, exactness_row, speed_table, Compare, ErrorStats};
use anyhow::Result;
use cube5_model::phantom::head_phantom;
use cube5_model::unit::{StreamUnit, UnitConfig};
use cube5_model::units::cube5_skewmem::{
    Axis, BlockLut, SkewConfig, SkewDims, SkewIn, SkewMem, SkewOp,
};
use cube5_model::volume::Volume;
use cube5_tb::variants_of;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub const TOP: &str = SkewConfig::TOP;

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

fn speed(n_items: usize) -> Result<()> {
    println!(
        "Speed at full rate (no idle, no back-pressure): the whole `M^3` volume is written first,"
    );
    println!(
        "then {n_items} random commands (55% beam reads, 45% writes); one command is one beam of P"
    );
    println!("voxels or one write, so voxels per clock = P x items/clock for reads.\n");
    speed_table(
        |cfg: SkewConfig| {
            let (model, cmds) = skew_workload(cfg, n_items, 1)?;
            let writes = model.config_writes();
            Ok((model, cmds, writes))
        },
        Compare::Outputs,
    )
}

/// Exactness: every beam the model returns against a plain `Vec<u16>` (x fastest).
fn exactness(n_items: usize) -> Result<()> {
    println!("Error against the plain reference ({n_items} random items per configuration): the");
    println!("skewed memory against a `Vec<u16>` volume written alongside it (identity LUT).\n");
    exactness_header();
    for variant in variants_of(TOP) {
        let cfg: SkewConfig = variant.config()?;
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
        let mut err = ErrorStats::default();
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
                    err.add(f64::from(v.abs_diff(u32::from(plain[idx(q)]))));
                }
            }
        }
        exactness_row(variant, &err);
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
        let mut err = ErrorStats::default();
        for z in 0..n {
            for y in 0..n {
                for x in (0..n).step_by(cfg.p as usize) {
                    let r = mem.command(&SkewIn::read([x, y, z], Axis::X));
                    for (i, &v) in r.voxels.iter().enumerate() {
                        let want = vol.get(i64::from(x) + i as i64, i64::from(y), i64::from(z));
                        err.add(f64::from(v.abs_diff(want)));
                    }
                }
            }
        }
        let reads: u64 = (0..cfg.p as usize)
            .map(|k| u64::from(mem.counters(k).0))
            .sum();
        println!(
            "| {threshold} | {skipped} / {blocks} | {reads} | {:.1}% | {:.0} | {:.3} |",
            100.0 * (1.0 - reads as f64 / full_reads as f64),
            err.max_abs,
            err.rms()
        );
    }
    println!();
    Ok(())
}

pub fn run(n_items: usize) -> Result<()> {
    speed(n_items)?;
    exactness(n_items)?;
    threshold_tradeoff()
}
