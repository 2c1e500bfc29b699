//! Co-simulation of gicube_cache against its model (docs/numerics/gicube_cache.md), with the AXI4
//! memory subordinate of tb/axi_mem.h holding the volume in the bank-major layout: every output
//! item (the eight voxels, the bank hit mask, the running hit and miss counts) and every AR burst
//! (one per missed line, in bank order) is compared in order; a request's `stall` is 0 exactly
//! when the model says it hit in all eight banks, and on every full-speed run the contract's
//! identity `cycles = n + 2 + k + sum(stall)` must hold; the protocol checker must stay silent.

mod support;

use cube5_model::camera::Camera;
use cube5_model::phantom::head_phantom;
use cube5_model::transfer::TransferFunction;
use cube5_model::units::cube5_axi_rd::{AxiMemImage, Burst};
use cube5_model::units::gicube_cache::{
    CacheConfig, CacheOut, CacheReq, CacheTraffic, VolumeCache, HIT_LATENCY,
};
use cube5_model::units::gicube_packet_loop::{RayPacket, RayType, POS_FRAC_W};
use cube5_model::units::gicube_processor::{Processor, ProcessorConfig, Projection, QueueOp};
use cube5_tb::rtl::{AxiMemSetup, RtlStream, Traffic};
use cube5_tb::{TbError, Variant};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::{HashMap, VecDeque};
use std::path::PathBuf;
use support::{
    axi, axi_mem_setup, axi_protocol_clean, compare_axi_outputs, compare_bursts, configs, seed,
    with_waves,
};

/// One run: the volume's words (`M^3`, x fastest), the requests, how the subordinate behaves, the
/// output traffic, and optionally a reset after `reset_at` cycles followed by `after` requests.
#[derive(Clone)]
struct Case {
    words: Vec<u32>,
    reqs: Vec<CacheReq>,
    setup: AxiMemSetup,
    traffic: Traffic,
    reset: Option<(u64, Vec<CacheReq>)>,
}

/// What a passing run measured.
#[derive(Debug, Default)]
struct Report {
    items: u64,
    hits: u64,
    misses: u64,
    missed_requests: u64,
    stall: u64,
    cycles: u64,
    dropped_at_reset: u64,
}

impl Report {
    fn hit_rate(&self) -> f64 {
        self.hits as f64 / (self.hits + self.misses).max(1) as f64
    }
}

/// The subordinate at latency `fixed + U(0..random)`, gaps, bandwidth, the unit's Outstanding as
/// its declared limit.
fn mem_setup(
    cfg: CacheConfig,
    mem: &AxiMemImage,
    lat: (u32, u32),
    gaps: (u32, u32),
    bw: (u32, u32),
    seed: u64,
) -> AxiMemSetup {
    AxiMemSetup {
        declared_outstanding: cfg.outstanding,
        ..axi_mem_setup((cfg.data_w / 8, cfg.addr_w), mem, lat, gaps, bw, seed)
    }
}

/// Random words of `WordW` bits.
fn random_words(cfg: CacheConfig, rng: &mut ChaCha8Rng) -> Vec<u32> {
    let n = (cfg.max_dim as usize).pow(3);
    let mask = ((1u64 << cfg.word_w) - 1) as u32;
    (0..n).map(|_| rng.random::<u32>() & mask).collect()
}

fn random_case(cfg: CacheConfig, s: u64, n: usize) -> Case {
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let words = random_words(cfg, &mut rng);
    let reqs = CacheTraffic::new(cfg).items(&mut rng, n);
    let img = cfg.image(&words).unwrap();
    let bus = (cfg.data_w / 8, cfg.addr_w);
    let (setup, traffic) = axi::random_conditions(&mut rng, bus, &img, cfg.data_w / 4);
    Case {
        words,
        reqs,
        setup: AxiMemSetup {
            declared_outstanding: cfg.outstanding,
            ..setup
        },
        traffic,
        reset: None,
    }
}

/// Runs `case` on `variant` (again with a waveform on a mismatch); a failure panics.
fn must(variant: &'static Variant, cfg: CacheConfig, seed: u64, case: &Case) -> Report {
    let result = with_waves(variant, seed, |trace| run(variant, cfg, seed, case, trace));
    axi::must_pass(variant, seed, result, |r| {
        format!(
            "{} requests, hit rate {:.4}, {} missed requests, {} stall cycles, {} cycles",
            r.items,
            r.hit_rate(),
            r.missed_requests,
            r.stall,
            r.cycles
        )
    })
}

/// Drives `reqs` on `dut` (cut after `max_cycles` when a reset follows) and compares outputs and
/// AR against `model` (stepped here). A missed request's `stall` is the RTL's (memory timing) once
/// it is at least the fixed latency plus a line's beats; a hit's must be 0.
#[allow(clippy::too_many_arguments)]
fn drive_and_compare(
    dut: &mut RtlStream<CacheConfig>,
    (variant, cfg, seed): (&'static Variant, CacheConfig, u64),
    model: &mut VolumeCache,
    reqs: &[CacheReq],
    setup: &AxiMemSetup,
    traffic: &Traffic,
    max_cycles: Option<u64>,
    report: &mut Report,
) -> Result<(), TbError> {
    let (mut want, bursts): (Vec<CacheOut>, Vec<Burst>) = model.run_all(reqs);
    let exact = max_cycles.is_none();
    let limit = max_cycles.unwrap_or(100_000 + 20 * reqs.len() as u64 + 600 * bursts.len() as u64);
    let driven = dut.drive(reqs, traffic, want.len() as u64, limit)?;
    axi_protocol_clean(dut, &driven.stats, variant, seed)?;
    let size = (cfg.data_w / 8).trailing_zeros();
    let n_ars = compare_bursts(
        &dut.axi_take_ar()?,
        "AR",
        &bursts,
        size,
        variant,
        seed,
        |k| format!("burst #{k}"),
    )?;
    // The memory's timing: a missed request's stall is the RTL's when plausible.
    let least = setup.latency_fixed + cfg.bpl();
    for (w, got) in want.iter_mut().zip(&driven.outputs) {
        if w.hit != 0xff && got.value.stall >= least {
            w.stall = got.value.stall;
        }
    }
    compare_axi_outputs(
        dut,
        &driven,
        &want,
        (n_ars, bursts.len()),
        exact,
        limit,
        (variant, seed),
        "item",
        |k| format!("request #{k} {:?}", reqs[k]),
    )?;
    if exact {
        // The volume lies inside the subordinate's image: no beat may come back with an error.
        axi::err_flag_matches(dut, (variant, seed), reqs.len(), false, "some fill's RRESP")?;
    }
    let outs = &want[..driven.outputs.len()];
    let missed = outs.iter().filter(|o| o.hit != 0xff).count() as u64;
    let stall: u64 = outs.iter().map(|o| u64::from(o.stall)).sum();
    if exact && traffic.idle.is_empty() && traffic.stall.is_empty() {
        // The contract's identity at full speed.
        let n = reqs.len() as u64;
        let expect = if n == 0 {
            0
        } else {
            n + HIT_LATENCY + missed + stall
        };
        if driven.stats.cycles != expect {
            return Err(axi::mismatch(
                dut,
                (variant, seed),
                format!("{n} requests at full speed, {missed} with misses"),
                format!("{} cycles", driven.stats.cycles),
                format!("n + 2 + k + sum(stall) = {expect} cycles"),
                "the cycle identity fails",
            ));
        }
    }
    if let Some(last) = outs.last() {
        report.hits = u64::from(last.hits);
        report.misses = u64::from(last.misses);
    }
    report.items += outs.len() as u64;
    report.missed_requests += missed;
    report.stall += stall;
    report.cycles += driven.stats.cycles;
    Ok(())
}

fn run(
    variant: &'static Variant,
    cfg: CacheConfig,
    seed: u64,
    case: &Case,
    trace: Option<(PathBuf, (u64, u64))>,
) -> Result<Report, TbError> {
    let img = cfg
        .image(&case.words)
        .map_err(|e| TbError::setup(variant.name, e))?;
    let mut model =
        VolumeCache::new(cfg, &case.words).map_err(|e| TbError::setup(variant.name, e))?;
    let mut dut = axi::open(variant, cfg, seed, (&case.setup, &img), &trace)?;
    let mut report = Report::default();
    let ctx = (variant, cfg, seed);
    drive_and_compare(
        &mut dut,
        ctx,
        &mut model,
        &case.reqs,
        &case.setup,
        &case.traffic,
        case.reset.as_ref().map(|r| r.0),
        &mut report,
    )?;
    if let Some((_, after)) = &case.reset {
        report.dropped_at_reset =
            axi::reset_leaves_nothing_in_flight(&mut dut, variant, seed, false)?;
        model.clear();
        drive_and_compare(
            &mut dut,
            ctx,
            &mut model,
            after,
            &case.setup,
            &case.traffic,
            None,
            &mut report,
        )?;
    }
    Ok(report)
}

#[test]
fn random_streams_with_latency_gaps_backpressure_and_bandwidth_limits() {
    axi::random_runs(3, |variant, cfg: CacheConfig, s| {
        let r = must(variant, cfg, s, &random_case(cfg, s, 1500));
        assert!(r.missed_requests > 50, "{variant}: misses (seed {s})");
        assert!(r.hits > 1000, "{variant}: hits (seed {s})");
    });
}

/// The acceptance figure (docs/adding-a-unit.md): 1,000,000 random requests per configuration,
/// in runs of 20,000 each with its own latency, gaps, bandwidth and back-pressure, the third reset
/// in mid-stream.
#[test]
#[ignore = "sim-full: a million requests per configuration at memory latencies of 10-200 cycles take minutes"]
fn a_million_random_requests_per_config() {
    axi::a_million_per_config(|variant, cfg: CacheConfig, s, k| {
        let mut case = random_case(cfg, s, 20_000);
        if k == 2 {
            let mut rng = ChaCha8Rng::seed_from_u64(s ^ 0x5eed);
            let after = CacheTraffic::new(cfg).items(&mut rng, 20_000);
            case.reset = Some((rng.random_range(1000..100_000), after));
        }
        must(variant, cfg, s, &case).items
    });
}

/// All hits (one cell, then its neighbours inside the same lines), all misses (two cells of one
/// set in every bank, in turn), the far faces (corners wrap to 0), line ends, the origin.
fn directed_reqs(cfg: CacheConfig) -> Vec<CacheReq> {
    let t = CacheTraffic::new(cfg);
    let m = cfg.max_dim;
    let a = CacheReq { x: 2, y: 4, z: 6 };
    let b = t.conflicting(a).expect("a cell of the same sets");
    let mut r = vec![a; 40];
    for _ in 0..20 {
        r.push(a);
        r.push(b);
    }
    r.extend([
        CacheReq {
            x: m - 1,
            y: m - 1,
            z: m - 1,
        },
        CacheReq { x: 0, y: 0, z: 0 },
        CacheReq {
            x: m - 1,
            y: 0,
            z: m - 1,
        },
        CacheReq {
            x: 2 * cfg.line_vox - 1,
            y: 1,
            z: 1,
        },
        CacheReq {
            x: 2 * cfg.line_vox,
            y: 1,
            z: 1,
        },
    ]);
    r.extend(vec![
        CacheReq {
            x: m - 1,
            y: m - 1,
            z: m - 1
        };
        20
    ]);
    r
}

#[test]
fn directed_extremes_all_hits_all_misses_one_set_and_the_far_faces() {
    for (i, (variant, cfg)) in configs::<CacheConfig>().into_iter().enumerate() {
        let s = seed(300 + i as u64);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let words = random_words(cfg, &mut rng);
        let img = cfg.image(&words).unwrap();
        let reqs = directed_reqs(cfg);
        // The model's view: the conflicting pair misses everywhere, the repeats hit everywhere.
        let (outs, _) = VolumeCache::new(cfg, &words).unwrap().run_all(&reqs);
        assert!(outs[1..40].iter().all(|o| o.hit == 0xff));
        assert!(outs[41..80].iter().all(|o| o.hit == 0));
        for (lat, gaps, stall) in [((10, 0), (0, 0), 0.0), ((10, 190), (300, 300), 0.5)] {
            let case = Case {
                words: words.clone(),
                reqs: reqs.clone(),
                setup: mem_setup(cfg, &img, lat, gaps, (0, 1), s),
                traffic: if stall == 0.0 {
                    Traffic::full_speed()
                } else {
                    Traffic::random(&mut rng, 0.3, stall)
                },
                reset: None,
            };
            must(variant, cfg, s, &case);
        }
    }
}

#[test]
fn reset_in_mid_stream_forgets_the_tags_and_the_next_requests_are_exact() {
    axi::resets_land_with_bursts_in_flight(|variant, cfg: CacheConfig, s| {
        let mut case = random_case(cfg, s, 300);
        let mut rng = ChaCha8Rng::seed_from_u64(s ^ 0x5eed);
        let after = CacheTraffic::new(cfg).items(&mut rng, 300);
        case.reset = Some((rng.random_range(30..3000), after));
        let r = must(variant, cfg, s, &case);
        assert!(r.items > 0);
        r.dropped_at_reset
    });
}

/// Throughput: requests always offered, outputs always taken. The identity holds at any memory
/// timing (checked in `drive_and_compare`); a stream that hits after its first request takes one
/// clock per request.
#[test]
fn throughput_one_request_per_clock_while_hitting_and_the_cycle_identity() {
    for (variant, cfg) in configs::<CacheConfig>() {
        let mut rng = ChaCha8Rng::seed_from_u64(seed(700));
        let words = random_words(cfg, &mut rng);
        let img = cfg.image(&words).unwrap();
        let n = 4000u64;
        let reqs = vec![CacheReq { x: 5, y: 6, z: 7 }; n as usize];
        let case = Case {
            words: words.clone(),
            reqs,
            setup: mem_setup(cfg, &img, (100, 0), (0, 0), (0, 1), 1),
            traffic: Traffic::full_speed(),
            reset: None,
        };
        let r = must(variant, cfg, 1, &case);
        assert_eq!(r.missed_requests, 1);
        assert_eq!(r.cycles, n + HIT_LATENCY + 1 + r.stall);
        // Random traffic at full speed: the identity, and the clocks per request.
        for lat in [10u32, 100] {
            let reqs = CacheTraffic::new(cfg).items(&mut rng, 3000);
            let case = Case {
                words: words.clone(),
                reqs,
                setup: mem_setup(cfg, &img, (lat, 0), (0, 0), (0, 1), 2),
                traffic: Traffic::full_speed(),
                reset: None,
            };
            let r = must(variant, cfg, 2, &case);
            eprintln!(
                "{variant}: latency {lat}: hit rate {:.3}, {:.2} clocks per request, {:.1} stall cycles per missed request",
                r.hit_rate(),
                r.cycles as f64 / r.items as f64,
                r.stall as f64 / r.missed_requests.max(1) as f64
            );
        }
    }
}

/// The sample requests of a processor frame: the rays its frame loop pops (`render_traced`'s
/// queue steps replayed on plain FIFOs of `queue_len` rays: a push into a full one overflows to
/// the host); a popped rendering ray of a block that is not empty samples the cell `start >> 8`
/// (an empty block's ray leaps, [357]).
fn processor_requests(proc: &Processor, ops: &[QueueOp]) -> Vec<CacheReq> {
    let leap = proc.config().space_leap;
    let len = proc.config().queue_len as usize;
    let empty = proc.empty_flags();
    let mut queues: HashMap<u32, VecDeque<RayPacket>> = HashMap::new();
    let mut reqs = Vec::new();
    for op in ops {
        match op {
            QueueOp::Push(q, ray) => {
                let fifo = queues.entry(*q).or_default();
                if fifo.len() < len {
                    fifo.push_back(*ray);
                }
            }
            QueueOp::Pop(q) => {
                let Some(ray) = queues.get_mut(q).and_then(VecDeque::pop_front) else {
                    continue;
                };
                if ray.ray_type == RayType::Rendering && leap && empty[*q as usize] {
                    continue;
                }
                let [x, y, z] = ray.start.map(|c| c >> POS_FRAC_W);
                reqs.push(CacheReq { x, y, z });
            }
        }
    }
    reqs
}

/// The processor model's own sample traffic replayed on the RTL: the 32^3 head phantom (blocks of
/// 8) rendered by `gicube_processor`, its samples' cells as requests over the volume padded to
/// `MaxDim`, under random latency, gaps and back-pressure. The hit rate is printed
/// (docs/measurements.md); on the processor model's own cache configuration its hits and misses
/// are the frame's.
#[test]
fn processor_frame_sample_traffic_replays_on_the_rtl() {
    let vol = head_phantom(32, 12).unwrap();
    let (a, e) = (65f64.to_radians(), 20f64.to_radians());
    let dir = [-e.cos() * a.cos(), -e.cos() * a.sin(), -e.sin()];
    let cam = Camera::new(dir.into(), vol.dims, vol.spacing, 64, 64);
    let tf = TransferFunction::head_default();
    let pcfg = ProcessorConfig {
        block_log2: 3,
        queue_len: 64,
        ..ProcessorConfig::DEFAULT
    };
    let proc = Processor::new(pcfg, &vol, &tf).unwrap();
    let (frame, ops) = proc.render_traced(&cam, Projection::Parallel).unwrap();
    let reqs = processor_requests(&proc, &ops);
    assert_eq!(
        reqs.len() as u64,
        frame.counts.samples,
        "one request per sample"
    );
    let fit = configs::<CacheConfig>()
        .into_iter()
        .filter(|(_, c)| c.max_dim > 32 && c.word_w >= 12);
    let mut ran = 0;
    for (variant, cfg) in fit {
        let m = i64::from(cfg.max_dim);
        let words: Vec<u32> = (0..m * m * m)
            .map(|i| vol.get(i % m, (i / m) % m, i / (m * m)))
            .collect();
        let img = cfg.image(&words).unwrap();
        let s = seed(1500);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let case = Case {
            words,
            reqs: reqs.clone(),
            setup: mem_setup(cfg, &img, (10, 190), (200, 200), (0, 1), s),
            traffic: Traffic::random(&mut rng, 0.2, 0.3),
            reset: None,
        };
        let r = must(variant, cfg, s, &case);
        eprintln!(
            "{variant}: processor frame ({} samples): this cache's hit rate {:.4} ({} lines read), the processor model's {:.4}",
            reqs.len(),
            r.hit_rate(),
            r.misses,
            frame.counts.cache_hit_rate()
        );
        if proc.cache_config().unwrap() == Some(cfg) {
            assert_eq!(
                (r.hits, r.misses),
                (frame.counts.cache_hits, frame.counts.cache_misses),
                "{variant}: the processor model's cache counts are this replay's"
            );
        }
        ran += 1;
    }
    assert!(ran > 0, "a configuration holds the padded 32^3 volume");
}

#[test]
fn gate_level_netlist_smoke() {
    axi::gate_smoke(
        |variant, cfg: CacheConfig, s| {
            must(variant, cfg, s, &random_case(cfg, s, 200));
        },
        |variant, cfg, s, rng| {
            let mut case = random_case(cfg, s, 100);
            case.reset = Some((
                rng.random_range(30..500),
                CacheTraffic::new(cfg).items(rng, 100),
            ));
            must(variant, cfg, s, &case);
        },
    );
}

/// The checks bite: a model over a volume that differs in one word disagrees on the item that
/// reads it, and a model with half the sets disagrees on the AR stream.
#[test]
fn the_comparison_sees_a_wrong_voxel_and_a_wrong_tag() {
    let (variant, cfg) = configs::<CacheConfig>()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let words = random_words(cfg, &mut rng);
    let img = cfg.image(&words).unwrap();
    let setup = mem_setup(cfg, &img, (10, 0), (0, 0), (0, 1), 1);
    let reqs = CacheTraffic::new(cfg).items(&mut rng, 300);
    let fails = |model: &mut VolumeCache| {
        let mut dut = axi::open(variant, cfg, 1, (&setup, &img), &None).unwrap();
        let mut report = Report::default();
        drive_and_compare(
            &mut dut,
            (variant, cfg, 1),
            model,
            &reqs,
            &setup,
            &Traffic::full_speed(),
            None,
            &mut report,
        )
        .unwrap_err()
    };
    let mut wrong = words.clone();
    let r = reqs[0];
    let m = cfg.max_dim;
    wrong[(r.x + m * (r.y + m * r.z)) as usize] ^= 1;
    let err = fails(&mut VolumeCache::new(cfg, &wrong).unwrap());
    let mm = err.mismatch().expect("a mismatch");
    assert_eq!(mm.item, 0, "{err}");
    let half = CacheConfig {
        sets: cfg.sets / 2,
        ..cfg
    };
    let err = fails(&mut VolumeCache::new(half, &words).unwrap());
    assert!(err.mismatch().is_some(), "{err}");
}
