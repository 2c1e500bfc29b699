//! Co-simulation of cube5_skewmem against the golden model (docs/numerics/skewmem.md).
//!
//! The memory is stateful and its RTL contents come up random (Verilator's randReset), so every
//! stream first writes the whole volume; the model's counters and the RTL's are compared through
//! the probe fields of every response.

mod support;

use cube5_model::unit::StreamUnit;
use cube5_model::units::cube5_skewmem::{
    Axis, BlockEntry, BlockLut, SkewConfig, SkewDims, SkewIn, SkewMem, SkewOp, SkewOut,
};
use cube5_model::volume::Volume;
use cube5_tb::harness::{check_stream, must_match, StreamCheck};
use cube5_tb::rtl::{RtlStream, Traffic};
use cube5_tb::{Mismatch, Variant};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::{
    assert_codec_and_config_port, assert_one_item_per_clock, configs, expect_mismatch,
    gate_configs, must_match_across_a_reset, must_match_items, seed, variant_with, MILLION,
};

/// A random volume of `dims` in which about a quarter of the `B^3` blocks are all zero.
fn random_volume(cfg: &SkewConfig, dims: [u32; 3], rng: &mut ChaCha8Rng) -> Volume {
    let d = dims.map(|v| v as usize);
    let b = cfg.block as usize;
    let blocks = d.map(|v| v.div_ceil(b));
    let zero: Vec<bool> = (0..blocks.iter().product())
        .map(|_| rng.random_bool(0.25))
        .collect();
    let mut data = Vec::with_capacity(d.iter().product());
    for z in 0..d[2] {
        for y in 0..d[1] {
            for x in 0..d[0] {
                let blk = x / b + blocks[0] * (y / b + blocks[1] * (z / b));
                data.push(if zero[blk] {
                    0
                } else {
                    rng.random_range(0..=cfg.voxel_max()) as u16
                });
            }
        }
    }
    Volume::new(d, [1.0; 3], cfg.voxel_w, data).unwrap()
}

/// Writes of every voxel of `vol`, x fastest.
fn fill_commands(vol: &Volume) -> Vec<SkewIn> {
    let [nx, ny, nz] = vol.dims;
    let mut cmds = Vec::with_capacity(vol.len());
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let v = vol.get(x as i64, y as i64, z as i64);
                cmds.push(SkewIn::write([x, y, z].map(|c| c as u32), v));
            }
        }
    }
    cmds
}

/// The model of a controller loaded with `dims` and `lut`.
fn controller(cfg: SkewConfig, dims: [u32; 3], lut: BlockLut) -> SkewMem {
    SkewMem::new(cfg, SkewDims::new(&cfg, dims).unwrap(), lut).unwrap()
}

/// A random scene: dimensions, a volume with empty blocks, its LUT (from the volume, a region of
/// interest and shuffled pointers), and the writes that load it.
fn random_scene(cfg: SkewConfig, rng: &mut ChaCha8Rng) -> (SkewMem, Vec<SkewIn>) {
    let m = cfg.max_dim();
    // At least half the largest edge along each axis (a multiple of P).
    let dims = [0, 1, 2].map(|_| cfg.p * rng.random_range((m / 2 / cfg.p).max(1)..=m / cfg.p));
    let vol = random_volume(&cfg, dims, rng);
    let mut lut = BlockLut::from_volume(&vol, cfg.block as usize, 0).unwrap();
    // A region of interest that cuts off up to a quarter at each end of each axis.
    let lo = dims.map(|d| rng.random_range(0..=d / 4));
    let hi = dims.map(|d| rng.random_range((d - d / 4).max(1)..=d));
    if rng.random_bool(0.7) {
        lut.restrict_to(lo, hi);
    }
    // Few blocks in small volumes: make sure some beams are skipped and some are read.
    let pick = rng.random_range(0..lut.entries.len());
    if lut.skipped() == 0 {
        lut.entries[pick].empty = true;
    } else if lut.skipped() == lut.entries.len() {
        lut.entries[pick] = BlockEntry {
            empty: false,
            masked: false,
            ..lut.entries[pick]
        };
    }
    let mut slots: Vec<u32> = (0..cfg.slots()).collect();
    slots.shuffle(rng);
    for (e, &s) in lut.entries.iter_mut().zip(&slots) {
        e.ptr = s;
    }
    (controller(cfg, dims, lut), fill_commands(&vol))
}

/// Any command: coordinates mostly inside the volume `dims` but anywhere in the `M^3` grid one
/// time in six (outside), raw axis 0..=3 (3 is reserved), raw probe bits, and a data field that
/// reads must ignore.
fn random_command(cfg: SkewConfig, dims: [u32; 3], rng: &mut ChaCha8Rng) -> SkewIn {
    let bound = if rng.random_bool(1.0 / 6.0) {
        [cfg.max_dim(); 3]
    } else {
        dims
    };
    SkewIn {
        op: if rng.random_bool(0.45) {
            SkewOp::Write
        } else {
            SkewOp::Read
        },
        axis: rng.random_range(0..4),
        pos: bound.map(|b| rng.random_range(0..b)),
        data: rng.random_range(0..=cfg.voxel_max()),
        probe: rng.random_range(0..1 << cfg.probe_w()),
    }
}

/// The fill, then random commands.
fn scripted(
    prefix: Vec<SkewIn>,
    cfg: SkewConfig,
    dims: [u32; 3],
) -> impl FnMut(&mut ChaCha8Rng) -> SkewIn {
    let mut prefix = prefix.into_iter();
    move |rng| {
        prefix
            .next()
            .unwrap_or_else(|| random_command(cfg, dims, rng))
    }
}

fn random_run(variant: &'static Variant, cfg: SkewConfig, seed_no: u64, items: usize) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed(seed_no) ^ 0x5eed);
    let (mut gold, fill) = random_scene(cfg, &mut rng);
    let check = StreamCheck::long(seed(seed_no), items, 3).with_config_writes(gold.config_writes());
    let dims = gold.dims().n;
    must_match_across_a_reset(
        variant,
        cfg,
        &mut gold,
        &mut scripted(fill, cfg, dims),
        &check,
        64,
    );
    assert_eq!(gold.checker.conflicts, 0);
    eprintln!(
        "{variant}: volume {dims:?}, {} of {} blocks skipped; beams read {}, skipped {}; \
         {} commands accessed the modules",
        gold.lut().skipped(),
        gold.lut().entries.len(),
        gold.beams_read,
        gold.beams_skipped,
        gold.checker.cycles
    );
    assert!(
        gold.beams_read as usize > items / 5 && gold.beams_skipped > 0,
        "beams are both read and skipped"
    );
}

#[test]
fn million_random_commands_p1_with_idle_backpressure_and_reset() {
    random_run(variant_with(SkewConfig::P1), SkewConfig::P1, 100, MILLION);
}

#[test]
fn million_random_commands_p4_with_idle_backpressure_and_reset() {
    random_run(
        variant_with(SkewConfig::DEFAULT),
        SkewConfig::DEFAULT,
        101,
        MILLION,
    );
}

#[test]
fn million_random_commands_p8_with_idle_backpressure_and_reset() {
    random_run(variant_with(SkewConfig::P8), SkewConfig::P8, 102, MILLION);
}

#[test]
fn random_commands_p2_and_dram_like_p4l4() {
    random_run(variant_with(SkewConfig::P2), SkewConfig::P2, 103, 300_000);
    random_run(
        variant_with(SkewConfig::P4_L4),
        SkewConfig::P4_L4,
        104,
        300_000,
    );
}

/// Extremes: all-max and all-zero voxels, the corner beams with unaligned starts and the reserved
/// axis, every probe value, the smallest volume with outside, empty and masked blocks.
fn directed_full(cfg: SkewConfig) -> (SkewMem, Vec<SkewIn>) {
    let m = cfg.max_dim();
    let max = cfg.voxel_max();
    let gold = controller(
        cfg,
        [m; 3],
        BlockLut::identity([m as usize; 3], cfg.block as usize).unwrap(),
    );
    let mut cmds = Vec::new();
    for z in 0..m {
        for y in 0..m {
            for x in 0..m {
                // Max everywhere but a checkerboard of zeros in the low half of z.
                let v = if z < m / 2 && (x + y + z) % 2 == 0 {
                    0
                } else {
                    max
                };
                cmds.push(SkewIn::write([x, y, z], v).with_probe((x + y) % (1 << cfg.probe_w())));
            }
        }
    }
    let corners = [0, m - 1];
    for axis_bits in 0..4u32 {
        for &x in &corners {
            for &y in &corners {
                for &z in &corners {
                    for probe in 0..1 << cfg.probe_w() {
                        cmds.push(SkewIn {
                            op: SkewOp::Read,
                            axis: axis_bits,
                            pos: [x, y, z],
                            data: max,
                            probe,
                        });
                    }
                }
            }
        }
    }
    // Overwrite the first and last voxel with the extremes and read them back along every axis.
    cmds.push(SkewIn::write([0, 0, 0], max));
    cmds.push(SkewIn::write([m - 1, m - 1, m - 1], 0));
    for axis in Axis::ALL {
        cmds.push(SkewIn::read([0, 0, 0], axis));
        cmds.push(SkewIn::read([m - 1, m - 1, m - 1], axis));
    }
    (gold, cmds)
}

fn directed_small(cfg: SkewConfig) -> (SkewMem, Vec<SkewIn>) {
    let p = cfg.p;
    let m = cfg.max_dim();
    let mut lut = BlockLut::identity([p as usize; 3], cfg.block as usize).unwrap();
    lut.entries[0].ptr = cfg.slots() - 1; // the last slot
    let mut gold = controller(cfg, [p; 3], lut.clone());
    let mut cmds = Vec::new();
    for z in 0..p {
        for y in 0..p {
            for x in 0..p {
                cmds.push(SkewIn::write(
                    [x, y, z],
                    (x * 7 + y * 3 + z) % (cfg.voxel_max() + 1),
                ));
            }
        }
    }
    for axis in Axis::ALL {
        cmds.push(SkewIn::read([0, 0, 0], axis));
        cmds.push(SkewIn::read([p - 1, p - 1, p - 1], axis));
        cmds.push(SkewIn::read([m - 1, 0, 0], axis)); // outside
        cmds.push(SkewIn::read([0, m - 1, 0], axis));
        cmds.push(SkewIn::read([0, 0, p], axis));
    }
    cmds.push(SkewIn::write([p, 0, 0], 1)); // outside: dropped
    cmds.push(SkewIn::write([m - 1, m - 1, m - 1], 1));
    // The same volume with its only block marked empty, then masked.
    for (empty, masked) in [(true, false), (false, true), (true, true)] {
        let mut l = lut.clone();
        l.entries[0].empty = empty;
        l.entries[0].masked = masked;
        let mut g = controller(cfg, [p; 3], l);
        let mut c: Vec<SkewIn> = cmds.clone();
        c.push(SkewIn::read([0, 0, 0], Axis::Y));
        let out = g.run(&c);
        assert!(out.last().unwrap().voxels.iter().all(|&v| v == 0));
    }
    gold.reset();
    (gold, cmds)
}

fn run_directed(
    variant: &'static Variant,
    cfg: SkewConfig,
    gold: &mut SkewMem,
    cmds: Vec<SkewIn>,
    s: u64,
) {
    let writes = gold.config_writes();
    must_match_items(
        variant,
        cfg,
        gold,
        cmds,
        &StreamCheck::directed(seed(s)).with_config_writes(writes),
    );
}

#[test]
fn directed_extremes() {
    for (variant, cfg) in configs::<SkewConfig>() {
        let (mut gold, cmds) = directed_full(cfg);
        run_directed(variant, cfg, &mut gold, cmds, 7);
        let (mut gold, cmds) = directed_small(cfg);
        run_directed(variant, cfg, &mut gold, cmds, 8);
    }
}

/// The default configuration, its largest edge `M` and a random `M^3` volume (seed `s`).
fn default_full_volume(s: u64) -> (SkewConfig, u32, Volume) {
    let cfg = SkewConfig::DEFAULT;
    let m = cfg.max_dim();
    let vol = random_volume(&cfg, [m; 3], &mut ChaCha8Rng::seed_from_u64(s));
    (cfg, m, vol)
}

#[test]
fn skipped_blocks_read_zero_with_flags_in_rtl() {
    let (cfg, m, vol) = default_full_volume(seed(9));
    for (empty, masked) in [(true, false), (false, true)] {
        let mut lut = BlockLut::from_volume(&vol, 8, 0).unwrap();
        lut.entries[3].empty = empty;
        lut.entries[3].masked = masked;
        let gold = controller(cfg, [m; 3], lut);
        let mut dut = RtlStream::new(variant_with(cfg), cfg, 3).unwrap();
        for (a, d) in gold.config_writes() {
            dut.write_config(a, &d).unwrap();
        }
        let mut cmds = fill_commands(&vol);
        // Block 3 is (1, 1, 0): x, y in 8..16, z in 0..8.
        cmds.push(SkewIn::read([8, 9, 2], Axis::X));
        let n = cmds.len() as u64;
        let out = dut.drive(&cmds, &Traffic::full_speed(), n, 4 * n).unwrap();
        let last = &out.outputs.last().unwrap().value;
        assert!(last.is_beam && !last.outside && !last.conflict);
        assert_eq!((last.empty, last.masked), (empty, masked));
        assert_eq!(last.voxels, vec![0; 4]);
    }
}

/// Every aligned beam of a whole `M^3` volume along each axis, on every built variant: the RTL's
/// own conflict check stays 0, and the read counter of the probed module (cycled over all modules)
/// equals the number of beams so far after every beam: each module served each beam exactly once.
#[test]
fn every_beam_of_the_whole_volume_along_each_axis_is_conflict_free() {
    for (variant, cfg) in configs::<SkewConfig>() {
        let m = cfg.max_dim();
        let mut rng = ChaCha8Rng::seed_from_u64(seed(12));
        let vol = random_volume(&cfg, [m; 3], &mut rng);
        let lut = BlockLut::identity([m as usize; 3], cfg.block as usize).unwrap();
        let mut gold = controller(cfg, [m; 3], lut);
        let mut cmds = fill_commands(&vol);
        let n_fill = cmds.len();
        let mut beams = 0u32;
        for axis in Axis::ALL {
            for z in 0..m {
                for y in 0..m {
                    for x in 0..m {
                        let c = [x, y, z];
                        if c[axis.index()] % cfg.p == 0 {
                            cmds.push(SkewIn::read(c, axis).with_probe(beams % cfg.p));
                            beams += 1;
                        }
                    }
                }
            }
        }
        assert_eq!(beams, 3 * m * m * m / cfg.p);

        let mut dut = RtlStream::new(variant, cfg, 5).unwrap();
        for (a, d) in gold.config_writes() {
            dut.write_config(a, &d).unwrap();
        }
        let n = cmds.len() as u64;
        let mut trng = ChaCha8Rng::seed_from_u64(seed(13));
        let out = dut
            .drive(&cmds, &Traffic::random(&mut trng, 0.1, 0.2), n, 10 * n)
            .unwrap();
        assert_eq!(out.stats.produced, n);
        assert_eq!(out.stats.protocol_errors, 0);
        let want = gold.run(&cmds);
        let cnt_mask = ((1u64 << cfg.cnt_w) - 1) as u32;
        for (i, (got, want)) in out.outputs[n_fill..]
            .iter()
            .zip(&want[n_fill..])
            .enumerate()
        {
            let got = &got.value;
            assert!(!got.conflict, "{variant}: beam {i} conflicts");
            assert_eq!(got.rd, (i as u32 + 1) & cnt_mask, "{variant}: beam {i}");
            assert_eq!(got, want, "{variant}: beam {i}: {:?}", cmds[n_fill + i]);
        }
        assert_eq!(gold.checker.conflicts, 0);
        assert_eq!(gold.checker.max_per_module, 1);
        eprintln!("{variant}: {beams} beams along x, y, z without a module conflict");
    }
}

/// Random writes then reads on the RTL alone, compared with a plain `Vec<u16>` (not the model).
#[test]
fn random_writes_then_reads_match_a_plain_vector() {
    for (variant, cfg) in configs::<SkewConfig>() {
        let m = cfg.max_dim();
        let dims = [m, m - cfg.p.min(m / 2), m / 2];
        let mut rng = ChaCha8Rng::seed_from_u64(seed(14));
        let lut = BlockLut::identity(dims.map(|d| d as usize), cfg.block as usize).unwrap();
        let gold = controller(cfg, dims, lut);
        let idx = |c: [u32; 3]| (c[0] + dims[0] * (c[1] + dims[1] * c[2])) as usize;
        let mut plain = vec![0u16; dims.iter().map(|&d| d as usize).product()];
        let mut cmds = Vec::new();
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    cmds.push(SkewIn::write([x, y, z], 0));
                }
            }
        }
        for _ in 0..20_000 {
            let c = [0, 1, 2].map(|a| rng.random_range(0..dims[a]));
            let v = rng.random_range(0..=cfg.voxel_max());
            plain[idx(c)] = v as u16;
            cmds.push(SkewIn::write(c, v));
        }
        let reads: Vec<SkewIn> = (0..20_000)
            .map(|_| {
                let c = [0, 1, 2].map(|a| rng.random_range(0..dims[a]));
                SkewIn::read(c, Axis::ALL[rng.random_range(0..3)])
            })
            .collect();
        let first_read = cmds.len();
        cmds.extend(&reads);

        let mut dut = RtlStream::new(variant, cfg, 6).unwrap();
        for (a, d) in gold.config_writes() {
            dut.write_config(a, &d).unwrap();
        }
        let n = cmds.len() as u64;
        let out = dut
            .drive(&cmds, &Traffic::random(&mut rng, 0.2, 0.3), n, 10 * n)
            .unwrap();
        assert_eq!(out.stats.produced, n);
        for (r, got) in reads.iter().zip(&out.outputs[first_read..]) {
            let a = Axis::from_bits(r.axis).index();
            let mut q = r.pos;
            q[a] &= !(cfg.p - 1);
            for (i, &v) in got.value.voxels.iter().enumerate() {
                let mut c = q;
                c[a] += i as u32;
                assert_eq!(v, u32::from(plain[idx(c)]), "{variant}: {r:?} lane {i}");
            }
        }
    }
}

#[test]
fn one_command_per_cycle_when_never_stalled() {
    for (variant, cfg) in configs::<SkewConfig>() {
        let latency = u64::from(cfg.latency()); // the pipeline fill: ReadLatency + 2
        let mut rng = ChaCha8Rng::seed_from_u64(seed(11));
        let (gold, fill) = random_scene(cfg, &mut rng);
        let mut items = fill;
        items.extend((0..50_000).map(|_| random_command(cfg, gold.dims().n, &mut rng)));
        let writes = gold.config_writes();
        assert_one_item_per_clock(variant, cfg, &writes, &items, latency);
    }
}

#[test]
fn gate_level_netlist_smoke() {
    let (variant, cfg) = gate_configs::<SkewConfig>()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(seed(21));
    let (mut gold, fill) = random_scene(cfg, &mut rng);
    let dims = gold.dims().n;
    let writes = gold.config_writes();
    must_match(
        variant,
        cfg,
        &mut gold,
        &mut scripted(fill, cfg, dims),
        &StreamCheck::gate_smoke(seed(21)).with_config_writes(writes),
    );
    let (mut gold, cmds) = directed_full(cfg);
    run_directed(variant, cfg, &mut gold, cmds, 22);
}

/// Stateful checks that trilin's scoreboard never needed: a LUT entry, a dimension or one write
/// that differs between RTL and model is caught downstream, by a later beam or counter.
#[test]
fn the_comparison_bites_on_state_lut_and_counters() {
    let (cfg, m, vol) = default_full_volume(4242);
    let lut = BlockLut::identity([m as usize; 3], 8).unwrap();
    let fill = fill_commands(&vol);
    // The fill, then 5000 random commands, on an RTL configured by `writes` against `gold`: the
    // mismatch that must be reported.
    fn caught<G: StreamUnit<In = SkewIn, Out = SkewOut>>(
        cfg: SkewConfig,
        gold: &mut G,
        fill: &[SkewIn],
        writes: Vec<(u32, Vec<u32>)>,
        why: &str,
    ) -> Mismatch {
        let m = cfg.max_dim();
        let mut check = StreamCheck::new(4242, fill.len() + 5_000)
            .with_traffic(0.1, 0.1)
            .with_config_writes(writes);
        check.waveform_on_mismatch = false;
        let mut gen = scripted(fill.to_vec(), cfg, [m; 3]);
        expect_mismatch(
            check_stream(variant_with(cfg), cfg, gold, &mut gen, &check),
            why,
        )
    }

    // 1. The RTL gets a LUT in which block 5 is empty; the model does not know.
    let mut rtl_lut = lut.clone();
    rtl_lut.entries[5].empty = true;
    let writes = controller(cfg, [m; 3], rtl_lut).config_writes();
    let mut gold = controller(cfg, [m; 3], lut.clone());
    let why = "a LUT difference must be caught";
    let err = caught(cfg, &mut gold, &fill, writes, why);
    assert!(err.rtl.contains("empty: true"), "{err}");

    // 2. The RTL was told a smaller volume (nz = 8): writes and reads beyond are dropped there.
    let writes = controller(
        cfg,
        [m, m, 8],
        BlockLut::identity([m as usize, m as usize, 8], 8).unwrap(),
    )
    .config_writes();
    let mut gold = controller(cfg, [m; 3], lut.clone());
    let why = "a dimension difference must be caught";
    let err = caught(cfg, &mut gold, &fill, writes, why);
    assert!(err.rtl.contains("outside: true"), "{err}");

    // 3. One write of the fill lands elsewhere in the model (a corrupted address, say): the
    //    counters of the probed module or a later beam differ.
    struct MisplacesOneWrite {
        inner: SkewMem,
        seen: usize,
        lose: usize,
    }
    impl StreamUnit for MisplacesOneWrite {
        type In = SkewIn;
        type Out = SkewOut;
        fn run(&mut self, inputs: &[SkewIn]) -> Vec<Self::Out> {
            inputs
                .iter()
                .map(|c| {
                    self.seen += 1;
                    let mut c = *c;
                    if self.seen == self.lose + 1 {
                        c.pos = [0, 0, 0];
                        c.data = (c.data + 1) & 0xfff;
                        c.op = SkewOp::Write;
                    }
                    self.inner.command(&c)
                })
                .collect()
        }
        fn reset(&mut self) {
            self.inner.reset();
        }
    }
    let mut gold = MisplacesOneWrite {
        inner: controller(cfg, [m; 3], lut.clone()),
        seen: 0,
        lose: 1000,
    };
    let writes = gold.inner.config_writes();
    let why = "a misplaced write must be caught";
    let err = caught(cfg, &mut gold, &fill, writes, why);
    eprintln!("{err}");
    assert!(err.item >= 1000, "{err}");
}

#[test]
fn codec_and_config_port_are_checked_against_the_rtl() {
    assert_codec_and_config_port::<SkewConfig>((0, &[16 | 16 << 5 | 16 << 10]), true);
}
