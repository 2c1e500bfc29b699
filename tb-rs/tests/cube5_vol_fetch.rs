//! Co-simulation of cube5_vol_fetch against its model (docs/numerics/vol_fetch.md), with the AXI4
//! memory subordinate of tb/axi_mem.h holding the volume in the blocked layout: every output item
//! (P voxels, block, word, skip, last, error, resp_err) and every AR burst is compared in order,
//! and the subordinate's protocol checker must stay silent.

mod support;

use cube5_model::phantom::head_phantom;
use cube5_model::units::cube5_axi_rd::{AxiMemImage, Burst};
use cube5_model::units::cube5_skewmem::{BlockEntry, BlockLut};
use cube5_model::units::cube5_vol_fetch::{
    dram_image, frame_axes, FetchCmd, FetchItem, FetchRun, Sweep, VolFetch, VolFetchConfig,
};
use cube5_tb::rtl::{AxiMemSetup, RtlStream, Traffic};
use cube5_tb::{TbError, Variant};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::PathBuf;
use support::{axi, axi_mem_setup, configs, seed, with_waves};

/// One run: LUT writes (loaded first, in full), then commands (sweeps and more LUT writes), the
/// memory, how the subordinate behaves, the output traffic, and optionally a reset after
/// `reset_at` cycles of the commands followed by `after` commands.
#[derive(Clone)]
struct Case {
    lut: Vec<FetchCmd>,
    cmds: Vec<FetchCmd>,
    mem: AxiMemImage,
    setup: AxiMemSetup,
    traffic: Traffic,
    reset: Option<(u64, Vec<FetchCmd>)>,
}

/// What a passing run measured.
#[derive(Debug, Default)]
struct Report {
    items: u64,
    voxels: u64,
    bursts: u64,
    cycles: u64,
    blocks_read: u64,
    blocks_skipped: u64,
    dropped_at_reset: u64,
}

impl Report {
    fn voxels_per_clock(&self) -> f64 {
        self.voxels as f64 / self.cycles.max(1) as f64
    }
}

/// The bus the subordinate serves: bytes per beat, address bits.
fn bus(cfg: VolFetchConfig) -> (u32, u32) {
    (cfg.data_w / 8, cfg.addr_w)
}

/// A random volume image: `slots` blocks of random bytes at a random bus-aligned base (not
/// 4 KB-aligned, so blocks straddle 4 KB boundaries), sometimes with an SLVERR window.
fn random_image(cfg: VolFetchConfig, slots: u32, rng: &mut ChaCha8Rng) -> AxiMemImage {
    let bbus = u64::from(cfg.data_w / 8);
    let len = u64::from(slots) * cfg.block_bytes();
    let space = cfg.axi_rd().address_space().unwrap_or(u64::MAX);
    let top = (space - len).min(0x10_0000);
    let base = rng.random_range(0..=top / bbus) * bbus;
    let bytes: Vec<u8> = (0..len).map(|_| rng.random()).collect();
    let (lo, hi) = if rng.random_bool(0.3) {
        let lo = base + rng.random_range(0..len / 64) * 64;
        (lo, lo + 64)
    } else {
        (0, 0)
    };
    AxiMemImage {
        base,
        bytes,
        slverr_lo: lo,
        slverr_hi: hi,
    }
}

/// Random volume size in blocks, at most `max_blocks` in all.
fn random_blocks(cfg: VolFetchConfig, max_blocks: u32, rng: &mut ChaCha8Rng) -> [u32; 3] {
    loop {
        let b = [0; 3].map(|_: u32| rng.random_range(1..=cfg.nb().min(8)));
        if b.iter().product::<u32>() <= max_blocks {
            return b;
        }
    }
}

/// A random LUT over `blocks` (pointers a random permutation of the slots, ~30 % empty, ~10 %
/// masked) as LUT writes.
fn random_lut(cfg: VolFetchConfig, blocks: [u32; 3], rng: &mut ChaCha8Rng) -> Vec<FetchCmd> {
    let n = blocks.iter().product::<u32>();
    let mut ptrs: Vec<u32> = (0..n).collect();
    for i in (1..ptrs.len()).rev() {
        ptrs.swap(i, rng.random_range(0..=i));
    }
    let mut out = Vec::new();
    for bz in 0..blocks[2] {
        for by in 0..blocks[1] {
            for bx in 0..blocks[0] {
                let k = bx + blocks[0] * (by + blocks[1] * bz);
                out.push(FetchCmd::Lut {
                    index: cfg.lut_index([bx, by, bz]),
                    entry: BlockEntry {
                        ptr: ptrs[k as usize],
                        empty: rng.random_bool(0.3),
                        masked: rng.random_bool(0.1),
                    },
                });
            }
        }
    }
    out
}

/// Marks every block of LUT writes present (neither empty nor masked).
fn all_present(lut: &mut [FetchCmd]) {
    for c in lut {
        if let FetchCmd::Lut { entry, .. } = c {
            entry.empty = false;
            entry.masked = false;
        }
    }
}

fn random_sweep(blocks: [u32; 3], base: u64, rng: &mut ChaCha8Rng) -> Sweep {
    let axis_k = rng.random_range(0..3u32);
    let (ai, _) = frame_axes(axis_k);
    let lo = rng.random_range(0..blocks[ai]);
    let hi = rng.random_range(lo + 1..=blocks[ai]);
    Sweep {
        base,
        blocks,
        axis_k,
        reversed: rng.random_bool(0.5),
        sec_lo: lo,
        sec_hi: hi,
    }
}

/// Sweeps (about one in ten refused), with a few LUT rewrites between them.
fn random_cmds(
    cfg: VolFetchConfig,
    blocks: [u32; 3],
    base: u64,
    lut: &[FetchCmd],
    n: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<FetchCmd> {
    let mut out = Vec::new();
    for _ in 0..n {
        let mut s = random_sweep(blocks, base, rng);
        match rng.random_range(0..20) {
            0 => s.axis_k = 3,
            1 => s.sec_hi = cfg.nb() + 1,
            _ => {}
        }
        out.push(FetchCmd::Sweep(s));
        for _ in 0..rng.random_range(0..3) {
            if let FetchCmd::Lut { index, mut entry } = lut[rng.random_range(0..lut.len())] {
                entry.empty = !entry.empty;
                out.push(FetchCmd::Lut { index, entry });
            }
        }
    }
    out
}

fn random_case(cfg: VolFetchConfig, seed: u64, sweeps: usize, max_blocks: u32) -> Case {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let blocks = random_blocks(cfg, max_blocks, &mut rng);
    let lut = random_lut(cfg, blocks, &mut rng);
    let mem = random_image(cfg, blocks.iter().product(), &mut rng);
    let cmds = random_cmds(cfg, blocks, mem.base, &lut, sweeps, &mut rng);
    let bw = axi::random_bandwidth(&mut rng, cfg.data_w / 4);
    let gaps = (rng.random_range(0..400), rng.random_range(0..400));
    let setup = axi_mem_setup(bus(cfg), &mem, (10, 190), gaps, bw, rng.random());
    let stall = rng.random_range(0.0..0.6);
    let traffic = Traffic::random(&mut rng, 0.3, stall);
    Case {
        lut,
        cmds,
        mem,
        setup,
        traffic,
        reset: None,
    }
}

fn check(
    variant: &'static Variant,
    cfg: VolFetchConfig,
    seed: u64,
    case: &Case,
) -> Result<Report, TbError> {
    with_waves(variant, seed, |trace| run(variant, cfg, seed, case, trace))
}

fn must(variant: &'static Variant, cfg: VolFetchConfig, seed: u64, case: &Case) -> Report {
    axi::must_pass(variant, seed, check(variant, cfg, seed, case), |r| {
        format!(
            "{} items ({} blocks read, {} skipped), {} bursts in {} cycles ({:.3} voxels/clock), {} bursts dropped at reset",
            r.items,
            r.blocks_read,
            r.blocks_skipped,
            r.bursts,
            r.cycles,
            r.voxels_per_clock(),
            r.dropped_at_reset
        )
    })
}

/// `sweeps` random sweeps over the volume of `case`'s first sweep (a case starts with one), its
/// memory and LUT: the commands after a reset.
fn random_after(
    cfg: VolFetchConfig,
    case: &Case,
    sweeps: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<FetchCmd> {
    let blocks = match case.cmds[0] {
        FetchCmd::Sweep(sw) => sw.blocks,
        FetchCmd::Lut { .. } => unreachable!("a case starts with a sweep"),
    };
    random_cmds(cfg, blocks, case.mem.base, &case.lut, sweeps, rng)
}

/// The command an item belongs to, for a mismatch report.
fn describe_item(cmds: &[FetchCmd], want: &[FetchItem], k: usize) -> String {
    let sweeps: Vec<&Sweep> = cmds
        .iter()
        .filter_map(|c| match c {
            FetchCmd::Sweep(s) => Some(s),
            FetchCmd::Lut { .. } => None,
        })
        .collect();
    let n = want.iter().take(k).filter(|i| i.last).count();
    match (sweeps.get(n), want.get(k)) {
        (Some(s), Some(it)) => format!("sweep #{n} {s:?}, block {:?}, word {}", it.blk, it.word),
        _ => "(no sweep: an extra item)".into(),
    }
}

/// Drives `cmds` (bounded by `max_cycles` when a reset will cut the run) and compares the items
/// and the AR bursts with the model `gold` (whose LUT carries over between calls, as the RTL's).
#[allow(clippy::too_many_arguments)]
fn drive_and_compare(
    dut: &mut RtlStream<VolFetchConfig>,
    gold: &mut VolFetch,
    variant: &'static Variant,
    seed: u64,
    cmds: &[FetchCmd],
    (mem, traffic): (&AxiMemImage, &Traffic),
    max_cycles: Option<u64>,
    report: &mut Report,
) -> Result<(), TbError> {
    let cfg = gold.config();
    let setup_err = |e| TbError::setup(variant.name, e);
    let before = gold.clone();
    let run: FetchRun = gold.run(cmds, mem).map_err(setup_err)?;
    let want = &run.items;
    let bursts: Vec<Burst> = run
        .reads
        .iter()
        .flat_map(|r| cfg.axi_rd().bursts(r))
        .collect();
    let exact = max_cycles.is_none();
    let limit = max_cycles.unwrap_or(100_000 + 8 * want.len() as u64 + 400 * bursts.len() as u64);
    let (driven, n_ars) = axi::drive_reads(
        dut,
        (variant, seed),
        (cmds, traffic),
        (want, "item", |k| describe_item(cmds, want, k)),
        (&bursts, cfg.axi_rd().size(), |k| {
            format!("burst #{k} of {} read commands", run.reads.len())
        }),
        (exact, limit),
    )?;
    if !exact {
        // Cut by a reset: the model's LUT is what the RTL took before the cut (LUT writes apply
        // when taken; the commands taken are a prefix).
        *gold = before;
        let taken = driven.stats.consumed as usize;
        gold.run(
            &cmds[..taken]
                .iter()
                .filter(|c| matches!(c, FetchCmd::Lut { .. }))
                .copied()
                .collect::<Vec<_>>(),
            mem,
        )
        .map_err(setup_err)?;
    }
    report.items += driven.outputs.len() as u64;
    report.voxels += driven
        .outputs
        .iter()
        .filter(|t| !t.value.skip && !t.value.error)
        .count() as u64
        * u64::from(cfg.p);
    report.bursts += n_ars as u64;
    report.cycles += driven.stats.cycles;
    if exact {
        report.blocks_read += run.blocks_read;
        report.blocks_skipped += run.blocks_skipped;
    }
    Ok(())
}

fn run(
    variant: &'static Variant,
    cfg: VolFetchConfig,
    seed: u64,
    case: &Case,
    trace: Option<(PathBuf, (u64, u64))>,
) -> Result<Report, TbError> {
    let mut dut = axi::open(variant, cfg, seed, (&case.setup, &case.mem), &trace)?;
    let mut gold = VolFetch::new(cfg).map_err(|e| TbError::setup(variant.name, e))?;
    let mut report = Report::default();
    let io = (&case.mem, &case.traffic);
    let mut go = |dut: &mut RtlStream<VolFetchConfig>, cmds: &Vec<FetchCmd>, cut: Option<u64>| {
        drive_and_compare(dut, &mut gold, variant, seed, cmds, io, cut, &mut report)
    };
    go(&mut dut, &case.lut, None)?;
    let cmds = (&case.cmds, &case.reset);
    let dropped = axi::run_with_reset(&mut dut, (variant, seed), false, cmds, go)?;
    report.dropped_at_reset = dropped;
    Ok(report)
}

#[test]
fn random_sweeps_with_latency_gaps_backpressure_and_bandwidth_limits() {
    axi::random_runs(3, |variant, cfg: VolFetchConfig, s| {
        let r = must(variant, cfg, s, &random_case(cfg, s, 4, 48));
        assert!(
            r.items > 100,
            "{variant}: the case delivers enough (seed {s})"
        );
    });
}

/// The acceptance figure (docs/adding-a-unit.md): at least 1,000,000 random items per
/// configuration, every third case reset in mid-stream.
#[test]
#[ignore = "sim-full: a million items per configuration, about 40 s of simulation"]
fn a_million_random_items_per_config() {
    axi::a_million_per_config(|variant, cfg: VolFetchConfig, s, k| {
        let mut case = random_case(cfg, s, 12, 128);
        if k % 3 == 2 {
            case.reset = axi::reset_after(s, 100..20_000, |rng| random_after(cfg, &case, 6, rng));
        }
        must(variant, cfg, s, &case).items
    });
}

/// All blocks present, all empty, a one-block section at each end, the largest volume the LUT
/// holds (at most 512 blocks), every axis both ways, refused sweeps between good ones.
#[test]
fn directed_extremes() {
    for (i, (variant, cfg)) in configs::<VolFetchConfig>().into_iter().enumerate() {
        let s = seed(300 + i as u64);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let nb = cfg.nb().min(8);
        let blocks = [nb, nb.min(4), nb];
        let mem = random_image(cfg, blocks.iter().product(), &mut rng);
        let base = mem.base;
        let lut = random_lut(cfg, blocks, &mut rng);
        let set_all = |empty: bool| -> Vec<FetchCmd> {
            lut.iter()
                .map(|c| match *c {
                    FetchCmd::Lut { index, entry } => FetchCmd::Lut {
                        index,
                        entry: BlockEntry {
                            empty,
                            masked: false,
                            ..entry
                        },
                    },
                    other => other,
                })
                .collect()
        };
        let mut cmds = set_all(false);
        for axis_k in 0..3u32 {
            let (ai, _) = frame_axes(axis_k);
            for reversed in [false, true] {
                let whole = Sweep {
                    base,
                    blocks,
                    axis_k,
                    reversed,
                    sec_lo: 0,
                    sec_hi: blocks[ai],
                };
                cmds.push(FetchCmd::Sweep(whole));
                cmds.push(FetchCmd::Sweep(Sweep {
                    sec_lo: blocks[ai] - 1,
                    ..whole
                }));
                cmds.push(FetchCmd::Sweep(Sweep { sec_hi: 1, ..whole }));
            }
        }
        let ok = Sweep::whole(base, blocks);
        for bad in cfg.refused_sweeps(ok) {
            cmds.push(FetchCmd::Sweep(bad));
            cmds.push(FetchCmd::Sweep(Sweep { sec_hi: 1, ..ok }));
        }
        cmds.extend(set_all(true));
        cmds.push(FetchCmd::Sweep(ok));
        cmds.push(FetchCmd::Sweep(Sweep {
            axis_k: 0,
            reversed: true,
            sec_hi: blocks[1],
            ..ok
        }));
        for (lat, gaps, stall) in [((10, 0), (0, 0), 0.0), ((10, 190), (300, 300), 0.5)] {
            let case = Case {
                lut: lut.clone(),
                cmds: cmds.clone(),
                setup: axi_mem_setup(bus(cfg), &mem, lat, gaps, (0, 1), s),
                traffic: Traffic::random(&mut rng, 0.3, stall),
                mem: mem.clone(),
                reset: None,
            };
            must(variant, cfg, s, &case);
        }
    }
}

#[test]
fn reset_in_mid_sweep_leaves_nothing_outstanding_and_the_next_sweeps_are_exact() {
    axi::resets_land_with_bursts_in_flight(|variant, cfg: VolFetchConfig, s| {
        let mut case = random_case(cfg, s, 3, 48);
        let mut rng = ChaCha8Rng::seed_from_u64(s ^ 0x5eed);
        case.setup.r_gap_permille = 0;
        let after = random_after(cfg, &case, 2, &mut rng);
        // Early enough that bursts are in flight (latency >= 10 cycles).
        case.reset = Some((rng.random_range(30..1500), after));
        must(variant, cfg, s, &case).dropped_at_reset
    });
}

/// A volume of `blocks` with every block present: its LUT writes and its image (no SLVERR
/// window).
fn present_volume(
    cfg: VolFetchConfig,
    blocks: [u32; 3],
    rng: &mut ChaCha8Rng,
) -> (Vec<FetchCmd>, AxiMemImage) {
    let mut lut = random_lut(cfg, blocks, rng);
    all_present(&mut lut);
    let mut mem = random_image(cfg, blocks.iter().product(), rng);
    (mem.slverr_lo, mem.slverr_hi) = (0, 0);
    (lut, mem)
}

/// Voxels per clock over a whole-volume sweep with every block present, full-speed output,
/// fixed latency `lat` and bandwidth `bw` bytes/cycle as `(num, den)` (`num = 0`: the bus).
fn throughput(variant: &'static Variant, cfg: VolFetchConfig, lat: u32, bw: (u32, u32)) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let nb = cfg.nb().min(4);
    let blocks = [nb, nb, nb.min(4)];
    let (lut, mut mem) = present_volume(cfg, blocks, &mut rng);
    mem.base = 0x1000 * u64::from(cfg.addr_w > 16);
    let sweep = Sweep::whole(mem.base, blocks);
    let case = Case {
        lut,
        cmds: vec![FetchCmd::Sweep(sweep); 2],
        setup: axi_mem_setup(bus(cfg), &mem, (lat, 0), (0, 0), bw, 1),
        traffic: Traffic::full_speed(),
        mem,
        reset: None,
    };
    must(variant, cfg, 1, &case).voxels_per_clock()
}

/// The table in docs/measurements.md, and the full-rate check: where the bus carries P voxels a
/// beat or more and the credit covers the latency (`Outstanding MaxBurst >= L + MaxBurst + 8`),
/// the unit delivers >= 0.9 P voxels per clock; under a bandwidth limit it meets the limit's rate.
#[test]
fn throughput_against_latency_and_bandwidth() {
    for (variant, cfg) in configs::<VolFetchConfig>() {
        let p = f64::from(cfg.p);
        let axi = cfg.axi_rd();
        let mut row = Vec::new();
        for lat in [10u32, 50, 100, 200] {
            let v = throughput(variant, cfg, lat, (0, 1));
            row.push(format!("{lat}: {v:.3}"));
            if axi.fifo_depth() >= lat + cfg.max_burst + 8 {
                assert!(
                    v >= 0.9 * p,
                    "{variant}: {v:.3} voxels/clock at latency {lat} (want >= {:.2})",
                    0.9 * p
                );
            }
        }
        eprintln!("{variant}: voxels/clock by latency {}", row.join(", "));
        // A DDR-like channel of P bytes per cycle: half the voxels the pipelines take.
        let limited = throughput(variant, cfg, 20, (cfg.p, 1));
        eprintln!(
            "{variant}: {} bytes/cycle at latency 20: {limited:.3} voxels/clock (limit {:.1})",
            cfg.p,
            p / 2.0
        );
        assert!(limited <= p / 2.0 + 1e-9, "{variant}: the limit holds");
        if axi.fifo_depth() >= 16 {
            assert!(limited >= 0.9 * p / 2.0, "{variant}: keeps up ({limited})");
        }
    }
}

/// A whole-face sweep of the `n`^3 head phantom (blocks of the first configuration that holds
/// it, LUT at threshold 0) at an oblique view, compared item by item, under a memory of latency
/// `lat` (fixed, random part) and `bw` bytes per cycle; prints the share of bursts the block LUT
/// skips and the voxels per clock (delivered, and of the whole volume).
fn head_phantom_sweep(n: usize, lat: (u32, u32), bw: u32) {
    let Some((variant, cfg)) = configs::<VolFetchConfig>()
        .into_iter()
        .find(|(_, c)| c.max_dim as usize >= n)
    else {
        panic!("no cube5_vol_fetch configuration holds a {n}^3 volume");
    };
    let vol = head_phantom(n, cfg.voxel_w).unwrap();
    let lut = BlockLut::from_volume(&vol, cfg.block_dim as usize, 0).unwrap();
    let mem = dram_image(&vol, &lut, 0x4_0000).unwrap();
    let (sweep, _) = Sweep::of_view(
        vol.dims,
        [-0.37, 0.81, -1.0],
        cfg.p,
        cfg.block_dim,
        mem.base,
    )
    .unwrap();
    let case = Case {
        lut: cfg.lut_writes(&lut).unwrap(),
        cmds: vec![FetchCmd::Sweep(sweep)],
        setup: axi_mem_setup(bus(cfg), &mem, lat, (0, 0), (bw, 1), 3),
        traffic: Traffic::full_speed(),
        mem,
        reset: None,
    };
    let r = must(variant, cfg, 3, &case);
    let per_block = cfg
        .axi_rd()
        .bursts(&cube5_model::units::cube5_axi_rd::AxiRdCmd {
            addr: 0,
            len: cfg.beats_per_block(),
        });
    let blocks = r.blocks_read + r.blocks_skipped;
    let total = blocks * per_block.len() as u64;
    let skipped = total - r.bursts;
    let volume = blocks * u64::from(cfg.block_dim).pow(3);
    eprintln!(
        "{variant}: head phantom {n}^3, B = {}, latency {}+U(0..{}), {bw} bytes/cycle: {} of {blocks} blocks empty, {skipped} of {total} bursts skipped ({:.1} %), {} cycles, {:.3} voxels/clock delivered, {:.3} volume voxels/clock",
        cfg.block_dim,
        lat.0,
        lat.1,
        r.blocks_skipped,
        100.0 * skipped as f64 / total as f64,
        r.cycles,
        r.voxels_per_clock(),
        volume as f64 / r.cycles as f64
    );
    assert_eq!(r.bursts, r.blocks_read * per_block.len() as u64);
    assert!(r.blocks_skipped > 0);
}

#[test]
fn head_phantom_sweep_skips_the_empty_blocks_bursts() {
    head_phantom_sweep(64, (100, 0), 2 * 4);
}

/// The 128^3 and 256^3 heads on the P = 8 configuration behind a DDR-like channel: latency
/// 60..200 cycles, 12 bytes per cycle (a 16-bit DDR3 interface at 800 Mb/s per pin against a
/// 133 MHz core), less than the 16 the pipelines would take.
#[test]
#[ignore = "sim-full: 0.3 M and 2.4 M items of whole 128^3 and 256^3 sweeps"]
fn head_phantom_128_and_256_behind_a_ddr_like_channel() {
    head_phantom_sweep(128, (60, 140), 12);
    head_phantom_sweep(256, (60, 140), 12);
}

#[test]
fn gate_level_netlist_smoke() {
    axi::gate_smoke(
        |variant, cfg: VolFetchConfig, s| {
            must(variant, cfg, s, &random_case(cfg, s, 2, 16));
        },
        |variant, cfg, s, rng| {
            let mut case = random_case(cfg, s, 1, 16);
            let after = random_after(cfg, &case, 1, rng);
            case.reset = Some((rng.random_range(30..300), after));
            must(variant, cfg, s, &case);
        },
    );
}

/// The checks bite: a model whose memory differs in one byte disagrees on the item holding it,
/// and one whose LUT marks a present block empty disagrees on that block's first burst.
#[test]
fn the_comparison_sees_a_wrong_voxel_and_a_wrong_skip() {
    let (variant, cfg) = configs::<VolFetchConfig>()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let blocks = [2, 2, 2];
    let (lut, mem) = present_volume(cfg, blocks, &mut rng);
    let sweep = Sweep::whole(mem.base, blocks);
    let traffic = Traffic::full_speed();
    let setup = axi_mem_setup(bus(cfg), &mem, (10, 0), (0, 0), (0, 1), 1);
    let open = || axi::open(variant, cfg, 1, (&setup, &mem), &None).unwrap();
    // One byte of the first block's slot changed in the model's memory.
    let first_ptr = match lut[0] {
        FetchCmd::Lut { entry, .. } => entry.ptr,
        FetchCmd::Sweep(_) => unreachable!(),
    };
    let mut wrong = mem.clone();
    wrong.bytes[(u64::from(first_ptr) * cfg.block_bytes()) as usize] ^= 1;
    let io = (&mem, &traffic);
    let mut dut = open();
    let mut gold = VolFetch::new(cfg).unwrap();
    let mut rep = Report::default();
    drive_and_compare(&mut dut, &mut gold, variant, 1, &lut, io, None, &mut rep).unwrap();
    let cmds = [FetchCmd::Sweep(sweep)];
    let wrong_io = (&wrong, &traffic);
    let err = drive_and_compare(
        &mut dut, &mut gold, variant, 1, &cmds, wrong_io, None, &mut rep,
    )
    .unwrap_err();
    let m = err.mismatch().expect("a mismatch");
    assert_eq!(m.item, 0);
    assert!(m.input.contains("block [0, 0, 0], word 0"), "{}", m.input);

    // The model's LUT marks block (1, 0, 0) empty; the RTL's does not.
    let mut dut = open();
    let mut gold = VolFetch::new(cfg).unwrap();
    drive_and_compare(&mut dut, &mut gold, variant, 1, &lut, io, None, &mut rep).unwrap();
    if let FetchCmd::Lut { index, mut entry } = lut[1] {
        entry.empty = true;
        gold.run(&[FetchCmd::Lut { index, entry }], &mem).unwrap();
    }
    let err =
        drive_and_compare(&mut dut, &mut gold, variant, 1, &cmds, io, None, &mut rep).unwrap_err();
    // AR is compared first: the model issues no burst for the block it thinks empty, so the
    // first burst of that block (the RTL's) is the first difference.
    let m = err.mismatch().expect("a mismatch");
    let per_block = cfg
        .axi_rd()
        .bursts(&cube5_model::units::cube5_axi_rd::AxiRdCmd {
            addr: 0,
            len: cfg.beats_per_block(),
        });
    assert!(m.what.starts_with("AR burst differs"), "{err}");
    assert_eq!(m.item, per_block.len() as u64, "{err}");
}

#[test]
fn a_codec_of_another_configuration_is_refused() {
    support::assert_foreign_codec_is_refused::<VolFetchConfig>();
}

#[test]
fn the_frame_axes_match_the_frame_model() {
    for v in [[1.0, 0.2, 0.1], [0.1, -1.0, 0.3], [0.2, 0.1, -1.0]] {
        let (_, params) = Sweep::of_view([16, 24, 32], v, 4, 8, 0).unwrap();
        assert_eq!(
            frame_axes(params.axis_k as u32),
            (params.axis_i, params.axis_j)
        );
    }
}
