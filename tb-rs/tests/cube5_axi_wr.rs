//! Co-simulation of cube5_axi_wr against its model (docs/numerics/axi_wr.md), with the write port
//! of the AXI4 memory subordinate (tb/axi_mem.h) answering AW, W and B in the clock loop: every AW
//! burst (address, length, size, type, ID), every completion (resp, count), the memory's bytes
//! after the run, the W beats and strobed bytes and `err_o` are compared, and the subordinate's
//! protocol checker must stay silent.

mod support;

use cube5_model::units::cube5_axi_rd::AxiMemImage;
use cube5_model::units::cube5_axi_wr::{AxiWrCmd, AxiWrConfig, AxiWrExpect};
use cube5_tb::rtl::{AxiMemSetup, RtlStream, Traffic};
use cube5_tb::{TbError, Variant};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::PathBuf;
use support::{
    axi, axi_protocol_clean, axi_random_image, compare_axi_outputs, compare_bursts, configs, seed,
    with_waves,
};

/// Commands and the items they take.
#[derive(Clone, Default)]
struct Work {
    cmds: Vec<AxiWrCmd>,
    items: Vec<Vec<u8>>,
}

/// One run: the work, the memory, how the subordinate behaves, the command/output traffic and
/// the data stream's idle pattern, and optionally a reset after `reset_at` cycles followed by
/// more work.
#[derive(Clone)]
struct Case {
    work: Work,
    mem: AxiMemImage,
    setup: AxiMemSetup,
    traffic: Traffic,
    data_idle: Vec<u8>,
    reset: Option<(u64, Work)>,
}

/// What a passing run measured.
#[derive(Debug, Default)]
struct Report {
    items: u64,
    beats: u64,
    bytes: u64,
    bursts: u64,
    cycles: u64,
    dropped_at_reset: u64,
}

impl Report {
    fn beats_per_cycle(&self) -> f64 {
        self.beats as f64 / self.cycles.max(1) as f64
    }
    fn bytes_per_cycle(&self) -> f64 {
        self.bytes as f64 / self.cycles.max(1) as f64
    }
}

/// The subordinate: B latency `fixed + U(0..random)`, AW/W/B gaps in per mille, bandwidth `bw`
/// bytes per cycle as `(num, den)` (`num = 0`: unlimited), the unit's declared outstanding limit.
fn mem_setup(
    cfg: AxiWrConfig,
    mem: &AxiMemImage,
    lat: (u32, u32),
    gaps: (u32, u32, u32),
    bw: (u32, u32),
    seed: u64,
) -> AxiMemSetup {
    AxiMemSetup {
        aw_gap_permille: gaps.0,
        w_gap_permille: gaps.1,
        b_gap_permille: gaps.2,
        ..axi::mem_setup(cfg, mem, lat, (0, 0), bw, seed)
    }
}

/// A 64 KB image of random bytes: at 0 for a 16-bit address space (the whole space, so commands
/// that wrap write memory), else at 0x10000; an SLVERR window of 64 bytes inside.
fn random_image(cfg: AxiWrConfig, rng: &mut ChaCha8Rng) -> AxiMemImage {
    axi_random_image(cfg.addr_w, rng)
}

fn random_items(cfg: AxiWrConfig, n: u64, rng: &mut ChaCha8Rng) -> Vec<Vec<u8>> {
    (0..n)
        .map(|_| (0..cfg.item_bytes()).map(|_| rng.random()).collect())
        .collect()
}

/// Random commands: mostly inside the image, some just below it (DECERR), lengths mostly up to
/// three bursts, some long, a few zero; any item-aligned address, so first and last beats are
/// often partial.
fn random_work(cfg: AxiWrConfig, mem: &AxiMemImage, n: usize, rng: &mut ChaCha8Rng) -> Work {
    let ib = u64::from(cfg.item_bytes());
    let lanes = cfg.bytes() / cfg.item_bytes();
    let cmds: Vec<AxiWrCmd> = (0..n)
        .map(|_| {
            let len: u32 = match rng.random_range(0..20) {
                0 => 0,
                1..=3 => rng.random_range(1..=300),
                _ => rng.random_range(1..=3 * cfg.max_burst * lanes),
            };
            let lo = mem.base.saturating_sub(512);
            let hi = mem.base + mem.bytes.len() as u64;
            let addr = rng.random_range(lo..hi) / ib * ib;
            AxiWrCmd { addr, len }
        })
        .collect();
    let total = cmds.iter().map(|c| u64::from(c.len)).sum();
    let items = random_items(cfg, total, rng);
    Work { cmds, items }
}

fn check(
    variant: &'static Variant,
    cfg: AxiWrConfig,
    seed: u64,
    case: &Case,
) -> Result<Report, TbError> {
    with_waves(variant, seed, |trace| run(variant, cfg, seed, case, trace))
}

fn must(variant: &'static Variant, cfg: AxiWrConfig, seed: u64, case: &Case) -> Report {
    axi::must_pass(variant, seed, check(variant, cfg, seed, case), |r| {
        format!(
            "{} items, {} beats, {} bursts in {} cycles ({:.4} beats/clock, {:.3} bytes/clock), {} bursts dropped at reset",
            r.items,
            r.beats,
            r.bursts,
            r.cycles,
            r.beats_per_cycle(),
            r.bytes_per_cycle(),
            r.dropped_at_reset
        )
    })
}

/// The command whose completion is number `k` (zero-length commands complete nothing).
fn describe_done(cmds: &[AxiWrCmd], k: usize) -> String {
    cmds.iter()
        .enumerate()
        .filter(|(_, c)| c.len > 0)
        .nth(k)
        .map_or("(no command: an extra completion)".into(), |(i, c)| {
            format!("command #{i} ({c})")
        })
}

/// The last command and item that wrote byte address `addr`, for a mismatch report.
fn describe_byte(cfg: AxiWrConfig, w: &Work, addr: u64) -> String {
    let ib = u64::from(cfg.item_bytes());
    let mut first_item = 0u64;
    let mut found = None;
    for (i, c) in w.cmds.iter().enumerate() {
        let span = u64::from(c.len) * ib;
        let off = addr.wrapping_sub(c.addr) & cfg.address_space().map_or(u64::MAX, |s| s - 1);
        if off < span {
            let item = first_item + off / ib;
            found = Some(format!(
                "byte {addr:#x}: command #{i} ({c}), its item {} (stream item {item}: {:02x?})",
                off / ib,
                w.items[item as usize]
            ));
        }
        first_item += u64::from(c.len);
    }
    found.unwrap_or_else(|| format!("byte {addr:#x}: written by no command"))
}

/// Feeds `work`, drives it (`max_cycles`: a reset cuts the run, so only prefixes are compared)
/// from the image `mem`, and compares AW, completions, counters and (when exact) the image.
#[allow(clippy::too_many_arguments)]
fn drive_and_compare(
    dut: &mut RtlStream<AxiWrConfig>,
    variant: &'static Variant,
    cfg: AxiWrConfig,
    seed: u64,
    work: &Work,
    rtl_items: &[Vec<u8>],
    mem: &AxiMemImage,
    case: &Case,
    max_cycles: Option<u64>,
    report: &mut Report,
) -> Result<(), TbError> {
    let want: AxiWrExpect = cfg
        .expected(&work.cmds, &work.items, mem, 0)
        .map_err(|e| TbError::setup(variant.name, e))?;
    let packed: Vec<u32> = rtl_items.iter().flat_map(|i| cfg.pack_item(i)).collect();
    let words = cfg.item_w.div_ceil(32);
    dut.axi_feed(&packed, words, &case.data_idle)?;
    let before = dut.axi_wr_counters();
    let exact = max_cycles.is_none();
    let limit = max_cycles.unwrap_or(
        200_000 + 40 * want.beats + 4 * work.items.len() as u64 + 300 * want.bursts.len() as u64,
    );
    let driven = dut.drive(&work.cmds, &case.traffic, want.done.len() as u64, limit)?;
    axi_protocol_clean(dut, &driven.stats, variant, seed)?;
    let cmds = &work.cmds;
    let n_aws = compare_bursts(
        &dut.axi_take_aw()?,
        "AW",
        &want.bursts,
        cfg.size(),
        variant,
        seed,
        |k| {
            let mut at = 0;
            for (i, c) in cmds.iter().enumerate() {
                let n = cfg.bursts(c).len();
                if k < at + n {
                    return format!("burst {} of command #{i} ({c})", k - at);
                }
                at += n;
            }
            "(no command: an extra burst)".into()
        },
    )?;
    compare_axi_outputs(
        dut,
        &driven,
        &want.done,
        (n_aws, want.bursts.len()),
        exact,
        limit,
        (variant, seed),
        "completion",
        |k| describe_done(cmds, k),
    )?;
    let after = dut.axi_wr_counters();
    let mismatch = |input: String, rtl: String, model: String, what: &str| {
        axi::mismatch(dut, (variant, seed), input, rtl, model, what)
    };
    let image = dut.axi_image()?;
    if exact {
        if let Some(at) = (0..image.len()).find(|&i| image[i] != want.image[i]) {
            let addr = mem.base + at as u64;
            return Err(mismatch(
                describe_byte(cfg, work, addr),
                format!("{:#04x}", image[at]),
                format!("{:#04x}", want.image[at]),
                "memory byte differs after every command completed",
            ));
        }
        let (beats, bytes) = (
            after.w_beats - before.w_beats,
            after.w_bytes - before.w_bytes,
        );
        if (beats, bytes) != (want.beats, want.strobed_bytes) {
            return Err(mismatch(
                format!("{} commands", cmds.len()),
                format!("{beats} W beats, {bytes} strobed bytes"),
                format!(
                    "{} W beats, {} strobed bytes",
                    want.beats, want.strobed_bytes
                ),
                "W beat or strobe count differs",
            ));
        }
        axi::err_flag_matches(dut, (variant, seed), cmds.len(), want.any_err, "some BRESP")?;
    } else {
        // Cut by a reset: every byte no command touches is unchanged.
        let ib = u64::from(cfg.item_bytes());
        let mut touched = vec![false; image.len()];
        for c in cmds {
            for k in 0..u64::from(c.len) * ib {
                let a = (c.addr + k) & cfg.address_space().map_or(u64::MAX, |s| s - 1);
                if a >= mem.base && a - mem.base < image.len() as u64 {
                    touched[(a - mem.base) as usize] = true;
                }
            }
        }
        if let Some(at) = (0..image.len()).find(|&i| !touched[i] && image[i] != mem.bytes[i]) {
            return Err(mismatch(
                format!("byte {:#x}, inside no command", mem.base + at as u64),
                format!("{:#04x}", image[at]),
                format!("{:#04x} (unchanged)", mem.bytes[at]),
                "a byte outside every command was written",
            ));
        }
    }
    report.items += work.items.len() as u64;
    report.beats += after.w_beats - before.w_beats;
    report.bytes += after.w_bytes - before.w_bytes;
    report.bursts += n_aws as u64;
    report.cycles += driven.stats.cycles;
    Ok(())
}

fn run(
    variant: &'static Variant,
    cfg: AxiWrConfig,
    seed: u64,
    case: &Case,
    trace: Option<(PathBuf, (u64, u64))>,
) -> Result<Report, TbError> {
    for c in case
        .work
        .cmds
        .iter()
        .chain(case.reset.iter().flat_map(|r| &r.1.cmds))
    {
        cfg.check_cmd(c)
            .map_err(|e| TbError::setup(variant.name, e))?;
    }
    let mut dut = axi::open(variant, cfg, seed, (&case.setup, &case.mem), &trace)?;
    let mut report = Report::default();
    report.dropped_at_reset = axi::run_with_reset(
        &mut dut,
        (variant, seed),
        true,
        (&case.work, &case.reset),
        |dut, work, cut| {
            // The work after a reset starts from the memory as the cut run left it.
            let mem = if std::ptr::eq(work, &case.work) {
                case.mem.clone()
            } else {
                AxiMemImage {
                    bytes: dut.axi_image()?,
                    ..case.mem.clone()
                }
            };
            let items = &work.items;
            drive_and_compare(
                dut,
                variant,
                cfg,
                seed,
                work,
                items,
                &mem,
                case,
                cut,
                &mut report,
            )
        },
    )?;
    Ok(report)
}

/// A random case at `seed`: B latency 10..200, gaps on AW, W and B, back-pressure on the
/// completions, idle on commands and items, a bandwidth limit on some seeds.
fn random_case(cfg: AxiWrConfig, seed: u64, n: usize) -> Case {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mem = random_image(cfg, &mut rng);
    let work = random_work(cfg, &mem, n, &mut rng);
    let bw = axi::random_bandwidth(&mut rng, 2 * cfg.bytes());
    let gaps = (
        rng.random_range(0..500),
        rng.random_range(0..500),
        rng.random_range(0..500),
    );
    let setup = mem_setup(cfg, &mem, (10, 190), gaps, bw, rng.random());
    let stall = rng.random_range(0.0..0.6);
    let traffic = Traffic::random(&mut rng, 0.3, stall);
    let idle = rng.random_range(0.0..0.5);
    let data_idle = (0..4093).map(|_| u8::from(rng.random_bool(idle))).collect();
    Case {
        work,
        mem,
        setup,
        traffic,
        data_idle,
        reset: None,
    }
}

#[test]
fn random_commands_with_latency_gaps_backpressure_and_bandwidth_limits() {
    axi::random_runs(4, |variant, cfg: AxiWrConfig, s| {
        let r = must(variant, cfg, s, &random_case(cfg, s, 200));
        assert!(
            r.items > 1000,
            "{variant}: the case writes enough items (seed {s})"
        );
    });
}

/// The acceptance figure (docs/adding-a-unit.md): at least 1,000,000 random items per
/// configuration, in cases of 2,000 commands each with its own latency, gaps, bandwidth, idle and
/// back-pressure, the third of them reset in mid-stream.
#[test]
fn a_million_random_items_per_config() {
    axi::a_million_per_config(|variant, cfg: AxiWrConfig, s, k| {
        let mut case = random_case(cfg, s, 2000);
        if k == 2 {
            case.reset = axi::reset_after(s, 1000..100_000, |rng| {
                random_work(cfg, &case.mem, 2000, rng)
            });
        }
        must(variant, cfg, s, &case).items
    });
}

/// One item at every lane, 4 KB crossings, commands sharing a beat, the longest command, the top
/// of the image and of the address space (wrapping to 0), errors, zero lengths between.
fn directed_cmds(cfg: AxiWrConfig, mem: &AxiMemImage) -> Vec<AxiWrCmd> {
    let b = u64::from(cfg.bytes());
    let ib = u64::from(cfg.item_bytes());
    let lanes = (b / ib) as u32;
    let top = mem.base + mem.bytes.len() as u64;
    let mb = cfg.max_burst * lanes;
    let base = mem.base;
    let mut c: Vec<AxiWrCmd> = (0..u64::from(lanes))
        .map(|l| AxiWrCmd {
            addr: base + 64 + l * ib,
            len: 1,
        })
        .collect();
    c.extend([
        AxiWrCmd {
            addr: base + 4096 - ib,
            len: 1,
        },
        AxiWrCmd {
            addr: base + 4096 - ib,
            len: 2,
        },
        AxiWrCmd {
            addr: base + 8192 - 3 * ib,
            len: 3 * mb + 1,
        },
        AxiWrCmd {
            addr: base + 4096,
            len: 0,
        },
        AxiWrCmd {
            addr: base + 4096,
            len: mb,
        },
        AxiWrCmd {
            addr: base + 4096 + ib,
            len: mb,
        },
        AxiWrCmd {
            addr: base + 4096 + ib,
            len: mb - 1,
        },
        AxiWrCmd {
            addr: base + 4096 - b * u64::from(cfg.max_burst),
            len: 2 * mb,
        },
        // Two commands into one beat, back to back.
        AxiWrCmd {
            addr: base + 0x300,
            len: 1,
        },
        AxiWrCmd {
            addr: base + 0x300 + ib,
            len: lanes.max(2) - 1,
        },
        AxiWrCmd {
            addr: top - ib,
            len: 1,
        },
        AxiWrCmd {
            addr: top - 4 * b,
            len: 4 * lanes,
        },
        AxiWrCmd {
            addr: top - 2 * ib,
            len: 4,
        }, // runs off the image: DECERR
        AxiWrCmd {
            addr: mem.slverr_lo - ib,
            len: 2,
        }, // into the SLVERR window
        AxiWrCmd { addr: base, len: 0 },
        AxiWrCmd {
            addr: base + 16,
            len: 1,
        },
    ]);
    if let Some(space) = cfg.address_space() {
        c.push(AxiWrCmd {
            addr: space - ib,
            len: 1,
        });
        if cfg.addr_w <= 16 {
            // Wraps from the top of the address space to 0 (a 4 KB boundary).
            c.push(AxiWrCmd {
                addr: space - 2 * ib,
                len: 2 * mb + 3,
            });
        }
    }
    // The longest command, 2^LenW - 1 items, when it stays below 1 M items and inside the image.
    if cfg.len_w <= 20 && ((1u64 << cfg.len_w) - 1) * ib <= mem.bytes.len() as u64 {
        c.push(AxiWrCmd {
            addr: base,
            len: (1u32 << cfg.len_w) - 1,
        });
    }
    c.push(AxiWrCmd {
        addr: base + 8,
        len: 1,
    });
    c.retain(|x| cfg.check_cmd(x).is_ok());
    c
}

#[test]
fn directed_extremes() {
    for (i, (variant, cfg)) in configs::<AxiWrConfig>().into_iter().enumerate() {
        let s = seed(300 + i as u64);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let mem = random_image(cfg, &mut rng);
        let cmds = directed_cmds(cfg, &mem);
        let total = cmds.iter().map(|c| u64::from(c.len)).sum();
        let work = Work {
            items: random_items(cfg, total, &mut rng),
            cmds,
        };
        for (lat, gaps, stall, idle) in [
            ((10, 0), (0, 0, 0), 0.0, 0.0),
            ((10, 190), (300, 300, 300), 0.4, 0.3),
        ] {
            let case = Case {
                setup: mem_setup(cfg, &mem, lat, gaps, (0, 1), s),
                traffic: Traffic::random(&mut rng, 0.3, stall),
                data_idle: (0..4093).map(|_| u8::from(rng.random_bool(idle))).collect(),
                work: work.clone(),
                mem: mem.clone(),
                reset: None,
            };
            must(variant, cfg, s, &case);
        }
    }
}

#[test]
fn reset_in_mid_stream_leaves_nothing_outstanding_and_the_next_commands_are_exact() {
    axi::resets_land_with_bursts_in_flight(|variant, cfg: AxiWrConfig, s| {
        let mut case = random_case(cfg, s, 100);
        // Early enough that bursts are in flight (B latency >= 10 cycles).
        case.reset = axi::reset_after(s, 30..3000, |rng| random_work(cfg, &case.mem, 100, rng));
        let r = must(variant, cfg, s, &case);
        assert!(r.items > 0);
        r.dropped_at_reset
    });
}

/// W beats and bytes per cycle over 64 commands of 256 beats at fixed B latency `lat` and
/// bandwidth `bw`, items always offered, completions always taken.
fn throughput(variant: &'static Variant, cfg: AxiWrConfig, lat: u32, bw: (u32, u32)) -> Report {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mem = random_image(cfg, &mut rng);
    let b = u64::from(cfg.bytes());
    let lanes = cfg.bytes() / cfg.item_bytes();
    let span = (mem.bytes.len() as u64 / b / 256).max(1);
    let cmds: Vec<AxiWrCmd> = (0..64)
        .map(|k| AxiWrCmd {
            addr: mem.base + (k % span) * 256 * b % mem.bytes.len() as u64,
            len: 256 * lanes,
        })
        .filter(|c| {
            c.addr + u64::from(c.len) * u64::from(cfg.item_bytes())
                <= mem.base + mem.bytes.len() as u64
        })
        .collect();
    let total = cmds.iter().map(|c| u64::from(c.len)).sum();
    let case = Case {
        setup: mem_setup(cfg, &mem, (lat, 0), (0, 0, 0), bw, 1),
        traffic: Traffic::full_speed(),
        data_idle: Vec::new(),
        work: Work {
            items: random_items(cfg, total, &mut rng),
            cmds,
        },
        mem,
        reset: None,
    };
    must(variant, cfg, 1, &case)
}

/// Throughput: fixed B latency 100, no gaps. The item stream (one item per cycle) limits the bus
/// to `ItemW / DataW` beats per cycle; where the bursts in flight cover the round trip
/// (`Outstanding * MaxBurst >= latency + MaxBurst + 8` beats: a burst holds its slot from issue
/// to its B) the unit must sustain >= 0.95 of that; every configuration's figure is printed.
#[test]
fn throughput_at_fixed_latency_100() {
    for (variant, cfg) in configs::<AxiWrConfig>() {
        let r = throughput(variant, cfg, 100, (0, 1));
        let limit = f64::from(cfg.item_w) / f64::from(cfg.data_w);
        let covers = cfg.outstanding * cfg.max_burst >= 100 + cfg.max_burst + 8;
        eprintln!(
            "{variant}: B latency 100, Outstanding x MaxBurst = {}: {:.4} beats/cycle (item limit {limit})",
            cfg.outstanding * cfg.max_burst,
            r.beats_per_cycle()
        );
        if covers {
            assert!(
                r.beats_per_cycle() >= 0.95 * limit,
                "{variant}: {:.4} beats/cycle at latency 100 (want >= 0.95 x {limit})",
                r.beats_per_cycle()
            );
        }
    }
}

/// The table in docs/measurements.md: bytes per cycle against B latency, and under a bandwidth
/// limit of half the bus (which the measured rate must meet but not exceed).
#[test]
fn throughput_against_latency_and_bandwidth() {
    for (variant, cfg) in configs::<AxiWrConfig>() {
        let row: Vec<String> = [10u32, 50, 100, 200]
            .iter()
            .map(|&lat| {
                let r = throughput(variant, cfg, lat, (0, 1));
                format!("{lat}: {:.3}", r.bytes_per_cycle())
            })
            .collect();
        eprintln!("{variant}: bytes/cycle by B latency {}", row.join(", "));
        let half = f64::from(cfg.bytes()) / 2.0;
        let r = throughput(variant, cfg, 20, (cfg.bytes(), 2));
        let item_limit = f64::from(cfg.item_bytes());
        eprintln!(
            "{variant}: bandwidth {half} bytes/cycle: {:.3} bytes/cycle",
            r.bytes_per_cycle()
        );
        assert!(
            r.beats_per_cycle() <= 0.5 + 1e-9,
            "{variant}: the bandwidth limit holds ({})",
            r.beats_per_cycle()
        );
        if cfg.outstanding * cfg.max_burst >= 64 {
            assert!(
                r.bytes_per_cycle() >= 0.9 * half.min(item_limit),
                "{variant}: the unit keeps up with a limited bus ({})",
                r.bytes_per_cycle()
            );
        }
    }
}

#[test]
fn gate_level_netlist_smoke() {
    axi::gate_smoke(
        |variant, cfg: AxiWrConfig, s| {
            must(variant, cfg, s, &random_case(cfg, s, 60));
        },
        |variant, cfg, s, rng| {
            let mut case = random_case(cfg, s, 30);
            case.reset = Some((
                rng.random_range(30..500),
                random_work(cfg, &case.mem, 30, rng),
            ));
            must(variant, cfg, s, &case);
        },
    );
}

/// The checks bite: RTL items with one byte changed disagree with the model on the memory byte
/// (the report names the command and item), a model that splits at half the RTL's MaxBurst
/// disagrees on AW, and the subordinate's checker refuses an AWSIZE it was told is not the bus
/// width, an address space too small, and more bursts outstanding than declared.
#[test]
fn the_comparison_and_the_checker_bite() {
    let (variant, cfg) = configs::<AxiWrConfig>()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let mem = random_image(cfg, &mut rng);
    let ib = u64::from(cfg.item_bytes());
    let lanes = cfg.bytes() / cfg.item_bytes();
    let long = AxiWrCmd {
        addr: mem.base + 0x2000,
        len: 4 * cfg.max_burst * lanes,
    };
    let work = Work {
        cmds: vec![
            AxiWrCmd {
                addr: mem.base + 4096 - ib,
                len: 3,
            },
            long,
        ],
        items: random_items(cfg, 3 + u64::from(long.len), &mut rng),
    };
    let case = Case {
        setup: mem_setup(cfg, &mem, (100, 0), (0, 0, 0), (0, 1), 1),
        traffic: Traffic::full_speed(),
        data_idle: Vec::new(),
        work: work.clone(),
        mem: mem.clone(),
        reset: None,
    };
    must(variant, cfg, 1, &case);
    // Each run on a fresh DUT holding the image, its RTL items against a model of `model_cfg`.
    let mismatch = |model_cfg: AxiWrConfig, rtl_items: &[Vec<u8>]| {
        let mut dut = axi::open(variant, cfg, 1, (&case.setup, &case.mem), &None).unwrap();
        let mut report = Report::default();
        let mem = &case.mem;
        drive_and_compare(
            &mut dut,
            variant,
            model_cfg,
            1,
            &work,
            rtl_items,
            mem,
            &case,
            None,
            &mut report,
        )
        .unwrap_err()
    };

    // The RTL's item 1 differs in its first byte.
    let mut rtl_items = work.items.clone();
    rtl_items[1][0] ^= 1;
    let err = mismatch(cfg, &rtl_items);
    let m = err.mismatch().expect("a mismatch");
    assert!(m.what.starts_with("memory byte differs"), "{err}");
    assert!(
        m.input.contains("command #0") && m.input.contains("its item 1"),
        "{}",
        m.input
    );

    // A model that splits at half the RTL's MaxBurst disagrees on the long command's first AW.
    let half = AxiWrConfig {
        max_burst: cfg.max_burst / 2,
        ..cfg
    };
    let err = mismatch(half, &work.items);
    let m = err.mismatch().expect("a mismatch");
    assert!(m.what.starts_with("AW burst differs"), "{err}");

    // The checker.
    let refusals = vec![
        (
            AxiMemSetup {
                data_bytes: 2 * cfg.bytes(),
                ..case.setup
            },
            "WSTRB lane",
        ),
        (
            AxiMemSetup {
                addr_bits: 13,
                ..case.setup
            },
            "past the address space",
        ),
        (
            AxiMemSetup {
                declared_outstanding: cfg.outstanding - 1,
                ..case.setup
            },
            "declares at most",
        ),
    ];
    axi::assert_checker_refuses(variant, refusals, |setup, s| {
        let bad = Case {
            setup,
            ..case.clone()
        };
        check(variant, cfg, s, &bad)
    });
}
