//! Co-simulation of cube5_axi_rd against its model (docs/numerics/axi_rd.md), with the AXI4
//! memory subordinate of tb/axi_mem.h answering the manager port in the clock loop: every output
//! beat (data, last, resp) and every AR burst (address, length, size, type, ID) is compared in
//! order, and the subordinate's protocol checker must stay silent.

mod support;

use cube5_model::units::cube5_axi_rd::{AxiMemImage, AxiRdCmd, AxiRdConfig};
use cube5_tb::rtl::{AxiMemSetup, RtlStream, Traffic};
use cube5_tb::{TbError, Variant};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::PathBuf;
use support::{axi, axi_random_image, configs, seed, with_waves};

/// One run: commands, the memory, how the subordinate behaves, the output traffic, and
/// optionally a reset after `reset_at` cycles followed by `after` commands.
#[derive(Clone)]
struct Case {
    cmds: Vec<AxiRdCmd>,
    mem: AxiMemImage,
    setup: AxiMemSetup,
    traffic: Traffic,
    reset: Option<(u64, Vec<AxiRdCmd>)>,
}

/// What a passing run measured.
#[derive(Debug, Default)]
struct Report {
    beats: u64,
    bursts: u64,
    cycles: u64,
    rready_low: u64,
    dropped_at_reset: u64,
}

impl Report {
    fn beats_per_cycle(&self) -> f64 {
        self.beats as f64 / self.cycles.max(1) as f64
    }
}

/// A 64 KB image of random bytes: at 0 for a 16-bit address space (it is the whole space, so
/// commands that wrap read memory), else at 0x10000; an SLVERR window of 64 bytes inside.
fn random_image(cfg: AxiRdConfig, rng: &mut ChaCha8Rng) -> AxiMemImage {
    axi_random_image(cfg.addr_w, rng)
}

/// Random commands: mostly inside the image, some just below it (DECERR), lengths mostly up to
/// three bursts, some long, a few zero.
fn random_cmds(
    cfg: AxiRdConfig,
    mem: &AxiMemImage,
    n: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<AxiRdCmd> {
    let bytes = u64::from(cfg.bytes());
    let space = cfg.address_space().unwrap_or(u64::MAX);
    (0..n)
        .map(|_| {
            let len: u32 = match rng.random_range(0..20) {
                0 => 0,
                1..=3 => rng.random_range(1..=300),
                _ => rng.random_range(1..=3 * cfg.max_burst),
            };
            let lo = mem.base.saturating_sub(512);
            let hi = mem.base + mem.bytes.len() as u64;
            let mut addr = rng.random_range(lo..hi) / bytes * bytes;
            if cfg.addr_w > 16 && addr + u64::from(len) * bytes > space {
                addr = 0;
            }
            AxiRdCmd { addr, len }
        })
        .collect()
}

/// Runs `case` on `variant` and compares everything; re-runs with a waveform on a mismatch.
fn check(
    variant: &'static Variant,
    cfg: AxiRdConfig,
    seed: u64,
    case: &Case,
) -> Result<Report, TbError> {
    with_waves(variant, seed, |trace| run(variant, cfg, seed, case, trace))
}

fn must(variant: &'static Variant, cfg: AxiRdConfig, seed: u64, case: &Case) -> Report {
    axi::must_pass(variant, seed, check(variant, cfg, seed, case), |r| {
        format!(
            "{} beats, {} bursts in {} cycles ({:.4} beats/clock), RREADY low {} cycles, {} bursts dropped at reset",
            r.beats,
            r.bursts,
            r.cycles,
            r.beats_per_cycle(),
            r.rready_low,
            r.dropped_at_reset
        )
    })
}

/// The item a beat belongs to, for a mismatch report.
fn describe_beat(cfg: AxiRdConfig, cmds: &[AxiRdCmd], k: usize) -> String {
    let mut at = 0usize;
    for (i, c) in cmds.iter().enumerate() {
        let n = c.len as usize;
        if k < at + n {
            let j = k - at;
            let addr = c.addr + j as u64 * u64::from(cfg.bytes());
            return format!("command #{i} ({c}), beat {j} (byte address {addr:#x})");
        }
        at += n;
    }
    "(no command: an extra beat)".into()
}

/// Drives one list of commands (`max_cycles` bounds it) and compares what came out as a prefix
/// (`exact = false`: a reset cuts the run) or in full.
#[allow(clippy::too_many_arguments)]
fn drive_and_compare(
    dut: &mut RtlStream<AxiRdConfig>,
    variant: &'static Variant,
    cfg: AxiRdConfig,
    seed: u64,
    cmds: &[AxiRdCmd],
    (mem, traffic): (&AxiMemImage, &Traffic),
    max_cycles: Option<u64>,
    report: &mut Report,
) -> Result<(), TbError> {
    let (want, bursts) = cfg.expected(cmds, mem);
    let exact = max_cycles.is_none();
    let limit = max_cycles.unwrap_or(200_000 + 40 * want.len() as u64 + 300 * bursts.len() as u64);
    let (driven, n_ars) = axi::drive_reads(
        dut,
        (variant, seed),
        (cmds, traffic),
        (&want, "beat", |k| describe_beat(cfg, cmds, k)),
        (&bursts, cfg.size(), |k| {
            format!("burst #{k} of commands {cmds:?}")
        }),
        (exact, limit),
    )?;
    if exact {
        let any_err = want.iter().any(|b| b.resp != 0);
        axi::err_flag_matches(
            dut,
            (variant, seed),
            cmds.len(),
            any_err,
            "some beat's RRESP",
        )?;
    }
    report.beats += driven.outputs.len() as u64;
    report.bursts += n_ars as u64;
    report.cycles += driven.stats.cycles;
    Ok(())
}

fn run(
    variant: &'static Variant,
    cfg: AxiRdConfig,
    seed: u64,
    case: &Case,
    trace: Option<(PathBuf, (u64, u64))>,
) -> Result<Report, TbError> {
    for c in case.cmds.iter().chain(case.reset.iter().flat_map(|r| &r.1)) {
        cfg.check_cmd(c)
            .map_err(|e| TbError::setup(variant.name, e))?;
    }
    let mut dut = axi::open(variant, cfg, seed, (&case.setup, &case.mem), &trace)?;
    let mut report = Report::default();
    let io = (&case.mem, &case.traffic);
    report.dropped_at_reset = axi::run_with_reset(
        &mut dut,
        (variant, seed),
        false,
        (&case.cmds, &case.reset),
        |dut, cmds, cut| drive_and_compare(dut, variant, cfg, seed, cmds, io, cut, &mut report),
    )?;
    report.rready_low = dut.axi_counters().rready_low;
    Ok(report)
}

/// A random case at `seed`: random latency 10..200, gaps on AR and R, back-pressure on the output,
/// a bandwidth limit on some seeds.
fn random_case(cfg: AxiRdConfig, seed: u64, n: usize) -> Case {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mem = random_image(cfg, &mut rng);
    let cmds = random_cmds(cfg, &mem, n, &mut rng);
    let bw = axi::random_bandwidth(&mut rng, 2 * cfg.bytes());
    let gaps = (rng.random_range(0..500), rng.random_range(0..500));
    let setup = axi::mem_setup(cfg, &mem, (10, 190), gaps, bw, rng.random());
    let stall = rng.random_range(0.0..0.6);
    let traffic = Traffic::random(&mut rng, 0.3, stall);
    Case {
        cmds,
        mem,
        setup,
        traffic,
        reset: None,
    }
}

#[test]
fn random_commands_with_latency_gaps_backpressure_and_bandwidth_limits() {
    axi::random_runs(4, |variant, cfg: AxiRdConfig, s| {
        let r = must(variant, cfg, s, &random_case(cfg, s, 300));
        assert!(
            r.beats > 1000,
            "{variant}: the case reads enough beats (seed {s})"
        );
        assert_eq!(
            r.rready_low, 0,
            "{variant}: RREADY never holds the bus (seed {s})"
        );
    });
}

/// The acceptance figure (docs/adding-a-unit.md): at least 1,000,000 random beats per
/// configuration, in cases of 2,000 commands each with its own latency, gaps, bandwidth and
/// back-pressure, the third of them reset in mid-stream.
#[test]
fn a_million_random_beats_per_config() {
    axi::a_million_per_config(|variant, cfg: AxiRdConfig, s, k| {
        let mut case = random_case(cfg, s, 2000);
        if k == 2 {
            case.reset = axi::reset_after(s, 1000..100_000, |rng| {
                random_cmds(cfg, &case.mem, 2000, rng)
            });
        }
        let r = must(variant, cfg, s, &case);
        assert_eq!(
            r.rready_low, 0,
            "{variant}: RREADY never holds the bus (seed {s})"
        );
        r.beats
    });
}

/// Length 1, 4 KB crossings, the longest command, the top of the image and of the address space,
/// zero lengths between commands.
fn directed_cmds(cfg: AxiRdConfig, mem: &AxiMemImage) -> Vec<AxiRdCmd> {
    let b = u64::from(cfg.bytes());
    let top = mem.base + mem.bytes.len() as u64;
    let mb = cfg.max_burst;
    let mut c = vec![
        AxiRdCmd {
            addr: mem.base,
            len: 1,
        },
        AxiRdCmd {
            addr: mem.base + 4096 - b,
            len: 1,
        },
        AxiRdCmd {
            addr: mem.base + 4096 - b,
            len: 2,
        },
        AxiRdCmd {
            addr: mem.base + 8192 - 3 * b,
            len: 3 * mb + 1,
        },
        AxiRdCmd {
            addr: mem.base + 4096,
            len: 0,
        },
        AxiRdCmd {
            addr: mem.base + 4096,
            len: mb,
        },
        AxiRdCmd {
            addr: mem.base + 4096 + b,
            len: mb,
        },
        AxiRdCmd {
            addr: mem.base + 4096 - b * u64::from(mb),
            len: 2 * mb,
        },
        AxiRdCmd {
            addr: top - b,
            len: 1,
        },
        AxiRdCmd {
            addr: top - 4 * b,
            len: 4,
        },
        AxiRdCmd {
            addr: top - 2 * b,
            len: 4,
        }, // runs off the image: DECERR beats
        AxiRdCmd {
            addr: mem.base,
            len: 0,
        },
        AxiRdCmd {
            addr: mem.base + 16,
            len: 1,
        },
    ];
    if let Some(space) = cfg.address_space() {
        c.push(AxiRdCmd {
            addr: space - b,
            len: 1,
        });
        c.push(AxiRdCmd {
            addr: space - 4096,
            len: (4096 / b) as u32,
        });
        if cfg.addr_w <= 16 {
            // Wraps from the top of the address space to 0 (a 4 KB boundary).
            c.push(AxiRdCmd {
                addr: space - 2 * b,
                len: 2 * mb + 3,
            });
        }
    }
    // The longest command, 2^LenW - 1 beats, when it stays below 1 M beats.
    if cfg.len_w <= 20 {
        c.push(AxiRdCmd {
            addr: mem.base,
            len: (1u32 << cfg.len_w) - 1,
        });
    }
    c.push(AxiRdCmd {
        addr: mem.base + 8,
        len: 1,
    });
    c.retain(|x| cfg.check_cmd(x).is_ok());
    c
}

#[test]
fn directed_extremes() {
    for (i, (variant, cfg)) in configs::<AxiRdConfig>().into_iter().enumerate() {
        let s = seed(300 + i as u64);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let mem = random_image(cfg, &mut rng);
        let cmds = directed_cmds(cfg, &mem);
        for (lat, gaps, stall) in [((10, 0), (0, 0), 0.0), ((10, 190), (300, 300), 0.4)] {
            let case = Case {
                setup: axi::mem_setup(cfg, &mem, lat, gaps, (0, 1), s),
                traffic: Traffic::random(&mut rng, 0.3, stall),
                cmds: cmds.clone(),
                mem: mem.clone(),
                reset: None,
            };
            must(variant, cfg, s, &case);
        }
    }
}

#[test]
fn reset_in_mid_stream_leaves_nothing_outstanding_and_the_next_commands_are_exact() {
    axi::resets_land_with_bursts_in_flight(|variant, cfg: AxiRdConfig, s| {
        let mut case = random_case(cfg, s, 100);
        // Early enough that bursts are in flight (latency >= 10 cycles).
        case.reset = axi::reset_after(s, 30..3000, |rng| random_cmds(cfg, &case.mem, 100, rng));
        let r = must(variant, cfg, s, &case);
        assert!(r.beats > 0);
        r.dropped_at_reset
    });
}

/// Throughput: fixed latency 100, no gaps, output always taken, long commands. Where the credit
/// pool covers the round trip (`Outstanding * MaxBurst >= latency + MaxBurst + 8` beats: a burst
/// holds its slot from issue to its last beat) the unit must sustain >= 0.95 beats per cycle;
/// every configuration's figure is printed (docs/measurements.md).
#[test]
fn throughput_at_fixed_latency_100() {
    for (variant, cfg) in configs::<AxiRdConfig>() {
        let r = throughput(variant, cfg, 100, (0, 1));
        let covers = cfg.fifo_depth() >= 100 + cfg.max_burst + 8;
        eprintln!(
            "{variant}: latency 100, Outstanding x MaxBurst = {}: {:.4} beats/cycle",
            cfg.fifo_depth(),
            r
        );
        if covers {
            assert!(
                r >= 0.95,
                "{variant}: {r:.4} beats/cycle at latency 100 (want >= 0.95)"
            );
        }
    }
}

/// Beats per cycle over 64 commands of 256 beats at fixed latency `lat` and bandwidth `bw`.
fn throughput(variant: &'static Variant, cfg: AxiRdConfig, lat: u32, bw: (u32, u32)) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mem = random_image(cfg, &mut rng);
    let b = u64::from(cfg.bytes());
    let span = (mem.bytes.len() as u64 / b / 256).max(1);
    let cmds: Vec<AxiRdCmd> = (0..64)
        .map(|k| AxiRdCmd {
            addr: mem.base + (k % span) * 256 * b % mem.bytes.len() as u64,
            len: 256,
        })
        .filter(|c| c.addr + u64::from(c.len) * b <= mem.base + mem.bytes.len() as u64)
        .collect();
    let case = Case {
        setup: axi::mem_setup(cfg, &mem, (lat, 0), (0, 0), bw, 1),
        traffic: Traffic::full_speed(),
        cmds,
        mem,
        reset: None,
    };
    let r = must(variant, cfg, 1, &case);
    r.beats_per_cycle()
}

/// The table in docs/measurements.md: beats/cycle against latency, and under a bandwidth limit
/// (which the measured rate must meet but not exceed).
#[test]
fn throughput_against_latency_and_bandwidth() {
    for (variant, cfg) in configs::<AxiRdConfig>() {
        let row: Vec<String> = [10u32, 50, 100, 200]
            .iter()
            .map(|&lat| format!("{lat}: {:.3}", throughput(variant, cfg, lat, (0, 1))))
            .collect();
        eprintln!("{variant}: beats/cycle by latency {}", row.join(", "));
        // Half the bus width per cycle: at most 0.5 beats/cycle, and close to it.
        let limited = throughput(variant, cfg, 20, (cfg.bytes(), 2));
        eprintln!(
            "{variant}: bandwidth {} bytes/cycle: {limited:.4} beats/cycle",
            cfg.bytes() / 2
        );
        assert!(
            limited <= 0.5 + 1e-9,
            "{variant}: the bandwidth limit holds ({limited})"
        );
        if cfg.fifo_depth() >= 16 {
            assert!(
                limited >= 0.45,
                "{variant}: the unit keeps up with a limited bus ({limited})"
            );
        }
    }
}

#[test]
fn gate_level_netlist_smoke() {
    axi::gate_smoke(
        |variant, cfg: AxiRdConfig, s| {
            must(variant, cfg, s, &random_case(cfg, s, 60));
        },
        |variant, cfg, s, rng| {
            let mut case = random_case(cfg, s, 30);
            case.reset = Some((
                rng.random_range(30..500),
                random_cmds(cfg, &case.mem, 30, rng),
            ));
            must(variant, cfg, s, &case);
        },
    );
}

/// The checks bite: a model whose image differs in one byte disagrees on the beat holding it (the
/// report names the command and beat), and one that splits differently disagrees on AR.
#[test]
fn the_comparison_sees_a_wrong_beat_and_a_wrong_burst() {
    let (variant, cfg) = configs::<AxiRdConfig>()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let mem = random_image(cfg, &mut rng);
    let b = u64::from(cfg.bytes());
    let cmds = vec![AxiRdCmd {
        addr: mem.base + 4096 - b,
        len: 3,
    }];
    let case = Case {
        setup: axi::mem_setup(cfg, &mem, (10, 0), (0, 0), (0, 1), 1),
        traffic: Traffic::full_speed(),
        cmds: cmds.clone(),
        mem: mem.clone(),
        reset: None,
    };
    // The model with one byte of the image changed: the beat differs, and the report names it.
    // Each run on a fresh DUT holding the image, against a model of `model_cfg` over `model_mem`.
    let mismatch = |model_cfg: AxiRdConfig, cmds: &[AxiRdCmd], model_mem: &AxiMemImage| {
        let mut dut = axi::open(variant, cfg, 1, (&case.setup, &case.mem), &None).unwrap();
        let mut report = Report::default();
        let traffic = &case.traffic;
        drive_and_compare(
            &mut dut,
            variant,
            model_cfg,
            1,
            cmds,
            (model_mem, traffic),
            None,
            &mut report,
        )
        .unwrap_err()
    };
    let mut wrong = case.clone();
    wrong.mem.bytes[(4096 - b) as usize] ^= 1;
    let err = mismatch(cfg, &cmds, &wrong.mem);
    let m = err.mismatch().expect("a mismatch");
    assert_eq!(m.item, 0);
    assert!(m.input.contains("command #0"), "{}", m.input);
    // The AR of a 4 KB crossing is two bursts: one beat to the boundary, two after it.
    let (_, bursts) = cfg.expected(&cmds, &mem);
    assert_eq!(bursts.len(), 2);

    // A model that splits at half the RTL's MaxBurst disagrees on the first AR burst.
    let half = AxiRdConfig {
        max_burst: cfg.max_burst / 2,
        ..cfg
    };
    let long = vec![AxiRdCmd {
        addr: mem.base,
        len: cfg.max_burst,
    }];
    let err = mismatch(half, &long, &mem);
    let m = err.mismatch().expect("a mismatch");
    assert!(m.what.starts_with("AR burst differs"), "{err}");
    assert_eq!(m.item, 0);
}

/// The subordinate's protocol checker bites, and its report reaches the test: told the bus is
/// twice as wide as it is, it refuses the unit's ARSIZE; told the address space is 8 KB, it
/// refuses a burst above it; told the unit declares one burst fewer than it keeps in flight, it
/// refuses the AR beyond. Each fails as a protocol error naming the rule and the seed.
#[test]
fn the_axi_checker_reports_a_violation() {
    let (variant, cfg) = configs::<AxiRdConfig>()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mem = random_image(cfg, &mut rng);
    let good = axi::mem_setup(cfg, &mem, (10, 0), (200, 0), (0, 1), 1);
    let cmds = vec![AxiRdCmd {
        addr: mem.base + 0x3000,
        len: 4 * cfg.max_burst,
    }];
    let refusals = vec![
        (
            AxiMemSetup {
                data_bytes: 2 * cfg.bytes(),
                ..good
            },
            "ARSIZE",
        ),
        (
            AxiMemSetup {
                addr_bits: 13,
                ..good
            },
            "past the address space",
        ),
        (
            AxiMemSetup {
                declared_outstanding: cfg.outstanding - 1,
                ..good
            },
            "declares at most",
        ),
    ];
    axi::assert_checker_refuses(variant, refusals, |setup, s| {
        let case = Case {
            setup,
            traffic: Traffic::full_speed(),
            cmds: cmds.clone(),
            mem: mem.clone(),
            reset: None,
        };
        check(variant, cfg, s, &case)
    });
}
