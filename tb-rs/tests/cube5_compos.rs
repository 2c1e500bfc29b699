//! Co-simulation of cube5_compos against the golden model (docs/numerics/compos.md).

mod support;

use cube5_model::unit::StreamUnit;
use cube5_model::units::cube5_compos::{
    config_writes, correction_ratios, Compos, ComposConfig, ComposIn, ComposMode, ComposRegs,
    Coxel, OpacityLut, Sample,
};
use cube5_tb::harness::{check_stream, must_match, StreamCheck};
use cube5_tb::rtl::RtlStream;
use cube5_tb::Variant;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::{
    assert_foreign_codec_is_refused, assert_one_item_per_clock, configs, expect_mismatch,
    gate_configs, must_match_across_a_reset, must_match_items, random_items, seed, variant_with,
    MILLION,
};

fn unit(cfg: ComposConfig, ratio: f64, regs: ComposRegs) -> Compos {
    Compos::new(cfg, OpacityLut::new(ratio, &cfg).unwrap(), regs).unwrap()
}

/// A check that loads `gold`'s table and registers into the RTL first.
fn check_for(gold: &Compos, seed: u64, items: usize) -> StreamCheck {
    StreamCheck::new(seed, items).with_config_writes(gold.config_writes())
}

/// Runs `items` (in order, once) through `variant` and the model under idle and back-pressure.
fn run_items(variant: &'static Variant, gold: &mut Compos, items: Vec<ComposIn>, seed: u64) {
    let (cfg, writes) = (gold.config(), gold.config_writes());
    must_match_items(
        variant,
        cfg,
        gold,
        items,
        &StreamCheck::directed(seed).with_config_writes(writes),
    );
}

fn pick<T: Copy>(rng: &mut ChaCha8Rng, xs: &[T]) -> T {
    xs[rng.random_range(0..xs.len())]
}

/// Random items that reach every case: over-state coxels (C <= A <= 1) most of the time, any
/// channel code or an extreme otherwise; geometry in front, behind or absent; depths next to the
/// geometry; every mode; alpha and colour extremes.
fn random_item(cfg: ComposConfig) -> impl FnMut(&mut ChaCha8Rng) -> ComposIn {
    move |rng| {
        let one = cfg.one();
        let chan_extremes = [
            0,
            1,
            one - 1,
            one,
            one + 1,
            cfg.chan_max() - 1,
            cfg.chan_max(),
        ];
        let rgba: [u64; 4] = match rng.random_range(0..20) {
            0..=11 => {
                let a = rng.random_range(0..=one);
                [
                    rng.random_range(0..=a),
                    rng.random_range(0..=a),
                    rng.random_range(0..=a),
                    a,
                ]
            }
            12..=16 => std::array::from_fn(|_| rng.random_range(0..=cfg.chan_max())),
            _ => std::array::from_fn(|_| pick(rng, &chan_extremes)),
        };
        let z = if rng.random_bool(0.3) {
            cfg.z_none()
        } else {
            rng.random_range(0..=cfg.z_none())
        };
        let code = |rng: &mut ChaCha8Rng, max: u32| {
            if rng.random_bool(0.15) {
                pick(rng, &[0, 1, max - 1, max])
            } else {
                rng.random_range(0..=max)
            }
        };
        let geo = std::array::from_fn(|_| code(rng, cfg.color_max()));
        let depth = if rng.random_bool(0.5) {
            z.saturating_sub(1)
                + rng
                    .random_range(0..3u32)
                    .min(cfg.z_none() - z.saturating_sub(1))
        } else {
            rng.random_range(0..=cfg.z_none())
        };
        ComposIn {
            coxel: Coxel {
                rgba,
                z,
                geo,
                terminated: rng.random_bool(0.1),
            },
            sample: Sample {
                rgb: std::array::from_fn(|_| code(rng, cfg.color_max())),
                alpha: code(rng, cfg.alpha_max()),
                depth,
                mode: ComposMode::from_bits(rng.random_range(0..8)),
            },
        }
    }
}

/// Registers that make both outcomes of every compare common in random traffic.
fn busy_regs(cfg: &ComposConfig, xray_shift: u32, lut_bypass: bool) -> ComposRegs {
    ComposRegs {
        lut_bypass,
        xray_shift,
        et_threshold: cfg.one() - (cfg.one() >> 3),
        fo_threshold: 1 << (cfg.q() - 1),
    }
}

#[test]
fn million_random_items_per_config_with_idle_backpressure_and_reset() {
    for (i, ((variant, cfg), ratio)) in configs::<ComposConfig>()
        .into_iter()
        .zip([2.0, 0.5, 3f64.sqrt()])
        .enumerate()
    {
        let mut gold = unit(cfg, ratio, busy_regs(&cfg, 3 + 5 * i as u32, false));
        let check = StreamCheck::long(seed(300 + i as u64), MILLION, 3)
            .with_config_writes(gold.config_writes());
        must_match_across_a_reset(variant, cfg, &mut gold, &mut random_item(cfg), &check, 1000);
    }
}

/// Random table contents over the whole `Q+1`-bit range (entries above 1.0 exercise the clamp),
/// random registers, and the LUT bypass.
#[test]
fn random_tables_registers_and_bypass() {
    let mut rng = ChaCha8Rng::seed_from_u64(seed(310));
    for (variant, cfg) in configs::<ComposConfig>() {
        for bypass in [false, true] {
            let entries = (0..=cfg.alpha_max())
                .map(|_| rng.random_range(0..(2u32 << cfg.q())))
                .collect();
            let regs = ComposRegs {
                lut_bypass: bypass,
                xray_shift: rng.random_range(0..16),
                et_threshold: rng.random_range(0..=cfg.chan_max()),
                fo_threshold: rng.random_range(0..(2u64 << cfg.q())),
            };
            let lut = OpacityLut::from_entries(entries, &cfg).unwrap();
            let mut gold = Compos::new(cfg, lut, regs).unwrap();
            let check = check_for(&gold, rng.random(), 200_000).with_traffic(0.1, 0.1);
            must_match(variant, cfg, &mut gold, &mut random_item(cfg), &check);
        }
    }
}

fn s(rgb: [u32; 3], alpha: u32, depth: u32, mode: ComposMode) -> Sample {
    Sample {
        rgb,
        alpha,
        depth,
        mode,
    }
}

/// A ray through the FIFO: item n carries the coxel the model returned for item n-1, so the RTL,
/// which sees each item alone, must reproduce the whole recurrence bit for bit.
fn chain(gold: &Compos, start: Coxel, samples: &[Sample]) -> Vec<ComposIn> {
    let mut coxel = start;
    samples
        .iter()
        .map(|&sample| {
            let item = ComposIn { coxel, sample };
            coxel = gold.step(&coxel, &sample);
            item
        })
        .collect()
}

/// Coxel states at the edges: empty, half, just below/at the ET threshold, full, past 1.0,
/// all-ones, terminated, geometry in front of and behind the sample.
fn edge_coxels(cfg: &ComposConfig, regs: &ComposRegs) -> Vec<Coxel> {
    let one = cfg.one();
    let e = Coxel::empty(cfg);
    let with = |rgba: [u64; 4]| Coxel { rgba, ..e };
    let et = regs.et_threshold.min(cfg.chan_max());
    vec![
        e,
        with([one / 4, one / 8, 0, one / 2]),
        with([1, 1, 1, et.saturating_sub(1)]),
        with([one / 2, one / 2, one / 2, et]),
        with([one; 4]),
        with([one + 1; 4]),
        with([cfg.chan_max(); 4]),
        Coxel {
            terminated: true,
            ..with([3, 2, 1, one / 3])
        },
        Coxel {
            z: 5,
            geo: [cfg.color_max(), 0, 1],
            ..with([0, 0, 0, one / 2])
        },
        Coxel {
            z: 0,
            geo: [cfg.color_max(); 3],
            ..e
        },
    ]
}

/// alpha 0, 1 LSB, 1 - 1 LSB and 1 in every mode, on every edge coxel, with the LUT and bypassed.
#[test]
fn directed_alpha_0_1lsb_1minus1lsb_and_1() {
    for (variant, cfg) in configs::<ComposConfig>() {
        for bypass in [false, true] {
            let regs = busy_regs(&cfg, 8, bypass);
            let mut gold = unit(cfg, 1.0, regs);
            let top = cfg.alpha_max();
            let cmax = cfg.color_max();
            let mut items = Vec::new();
            for coxel in edge_coxels(&cfg, &regs) {
                for alpha in [0, 1, top - 1, top] {
                    for rgb in [[0; 3], [cmax; 3], [1, cmax / 2, cmax - 1]] {
                        for mode in ComposMode::ALL {
                            for depth in [0, 4, 5, cfg.z_none()] {
                                items.push(ComposIn {
                                    coxel,
                                    sample: s(rgb, alpha, depth, mode),
                                });
                            }
                        }
                    }
                }
            }
            run_items(variant, &mut gold, items, seed(320));
        }
    }
}

/// Rays of 10,000 samples: opacity saturates at exactly 1.0 (front to back, back to front) and
/// the faintest codes approach it; every step of the chain is compared.
#[test]
fn directed_opacity_saturation_over_10000_samples() {
    for (variant, cfg) in configs::<ComposConfig>() {
        let regs = ComposRegs::without_termination(&cfg);
        let mut gold = unit(cfg, 1.0, regs);
        let top = cfg.alpha_max();
        let mut items = Vec::new();
        for (alpha, mode) in [
            (1, ComposMode::FrontToBack),
            (2, ComposMode::FrontToBack),
            (top / 3, ComposMode::FrontToBack),
            (top - 1, ComposMode::BackToFront),
            (1, ComposMode::BackToFront),
        ] {
            let samples = vec![s([cfg.color_max(), 1, 0], alpha, 0, mode); 10_000];
            let ray = chain(&gold, Coxel::empty(&cfg), &samples);
            let last = gold.step(&ray[9_999].coxel, &samples[9_999]);
            assert!(last.rgba[3] <= cfg.one());
            // Over saturates at exactly 1.0 when a >= 1/2; below that the last LSB of T times a
            // rounds to 0 and front to back stops one LSB short (the stall at T = 2^-F).
            match (alpha, mode) {
                (a, ComposMode::BackToFront) if a == top - 1 => {
                    assert_eq!(last.rgba[3], cfg.one())
                }
                (a, _) if a == top / 3 => assert_eq!(last.rgba[3], cfg.one() - 1),
                _ => {}
            }
            items.extend(ray);
        }
        run_items(variant, &mut gold, items, seed(330));
    }
}

/// The LUT for d/k = 1/16 .. 16 is loaded through the port and read back through the stream:
/// an empty coxel under front to back returns A = Lut[r] on the coxel scale, every code.
#[test]
fn directed_opacity_correction_1_16_to_16_including_sub_lsb() {
    for (variant, cfg) in configs::<ComposConfig>() {
        for ratio in correction_ratios() {
            let regs = ComposRegs::without_termination(&cfg);
            let mut gold = unit(cfg, ratio, regs);
            let items: Vec<ComposIn> = (0..=cfg.alpha_max())
                .flat_map(|alpha| {
                    [ComposMode::FrontToBack, ComposMode::Max].map(|mode| ComposIn {
                        coxel: Coxel::empty(&cfg),
                        sample: s([cfg.color_max(); 3], alpha, 0, mode),
                    })
                })
                .collect();
            // The sub-LSB rule as the RTL sees it: vanished codes leave the coxel empty.
            let vanished = items
                .iter()
                .filter(|it| it.sample.alpha > 0 && it.sample.mode == ComposMode::FrontToBack)
                .filter(|it| gold.step(&it.coxel, &it.sample) == it.coxel)
                .count();
            assert_eq!(vanished, gold.lut().vanished(), "{variant} at {ratio}");
            run_items(variant, &mut gold, items, seed(340));
        }
    }
}

/// Densities (alpha) and colours 0 and max, every mode, on empty and full coxels.
#[test]
fn directed_densities_and_colours_0_and_max() {
    for (variant, cfg) in configs::<ComposConfig>() {
        let mut gold = unit(cfg, 1.0, ComposRegs::defaults(&cfg));
        let full = Coxel {
            rgba: [cfg.one(); 4],
            ..Coxel::empty(&cfg)
        };
        let mut items = Vec::new();
        for coxel in [Coxel::empty(&cfg), full] {
            for c in [0, cfg.color_max()] {
                for alpha in [0, cfg.alpha_max()] {
                    for mode in ComposMode::ALL {
                        items.push(ComposIn {
                            coxel,
                            sample: s([c; 3], alpha, 0, mode),
                        });
                    }
                }
            }
        }
        run_items(variant, &mut gold, items, seed(350));
    }
}

/// X-ray sums of full samples overflow the channel and saturate at its all-ones code, for
/// shifts 0, 1, 8 and 15.
#[test]
fn directed_xray_sum_overflow() {
    for (variant, cfg) in configs::<ComposConfig>() {
        for shift in [0, 1, 8, 15] {
            let regs = ComposRegs {
                xray_shift: shift,
                ..ComposRegs::defaults(&cfg)
            };
            let mut gold = unit(cfg, 1.0, regs);
            let n = (3usize << shift.min(10)).min(4000);
            let samples = vec![
                s(
                    [cfg.color_max(); 3],
                    cfg.alpha_max(),
                    0,
                    ComposMode::XraySum
                );
                n
            ];
            let items = chain(&gold, Coxel::empty(&cfg), &samples);
            if shift <= 10 {
                let last = gold.step(&items[n - 1].coxel, &samples[n - 1]);
                assert_eq!(last.rgba, [cfg.chan_max(); 4]);
            }
            run_items(variant, &mut gold, items, seed(360));
        }
    }
}

/// Alpha 0.002 front to back: the RTL of the 8-bit coxel stalls half transparent, the default
/// reaches the target colour within half an 8-bit display LSB (the contract's stalling table).
#[test]
fn directed_eight_bit_alpha_stalling() {
    for (variant, cfg) in configs::<ComposConfig>() {
        let regs = ComposRegs::without_termination(&cfg);
        let gold = unit(cfg, 1.0, regs);
        let code = (0.002 * f64::from(cfg.alpha_max())).round() as u32;
        let samples = vec![s([cfg.color_max(); 3], code, 0, ComposMode::FrontToBack); 8_000];
        let items = chain(&gold, Coxel::empty(&cfg), &samples);
        let mut dut = RtlStream::new(variant, cfg, 1).unwrap();
        for (addr, data) in gold.config_writes() {
            dut.write_config(addr, &data).unwrap();
        }
        let rtl = dut.run(&items);
        let model = gold.clone().run(&items);
        assert_eq!(rtl, model);
        let colour = rtl.last().unwrap().rgba[0] as f64 / cfg.one() as f64;
        eprintln!("{variant}: colour after 8000 samples of alpha 0.002: {colour:.5}");
        if cfg == ComposConfig::NARROW {
            assert!((colour - 0.5).abs() < 0.01, "stalls at 0.5");
        } else {
            assert!(1.0 - colour < 0.5 / 255.0, "reaches the target");
        }
    }
}

/// Depth test at k = Z - 1, Z, Z + 1, the flush with and without geometry, early termination at
/// and around the threshold, the first-opaque threshold and Max/Min ties at their edges, front to
/// back then flush over a whole ray.
#[test]
fn directed_depth_test_flush_and_early_termination() {
    for (variant, cfg) in configs::<ComposConfig>() {
        // FoThreshold exactly at the corrected alpha of the middle code, for the >= edge.
        let mid = cfg.alpha_max() / 2;
        let lut = OpacityLut::new(1.0, &cfg).unwrap();
        let regs = ComposRegs {
            fo_threshold: u64::from(lut.entries()[mid as usize]),
            ..ComposRegs::defaults(&cfg)
        };
        let mut gold = Compos::new(cfg, lut, regs).unwrap();
        let mut items = Vec::new();
        for alpha in [mid - 1, mid, mid + 1] {
            for mode in [ComposMode::FirstOpaque, ComposMode::Max, ComposMode::Min] {
                let half = Coxel {
                    rgba: [1, 2, 3, gold.corrected(mid) << (cfg.acc_w - cfg.q())],
                    ..Coxel::empty(&cfg)
                };
                items.push(ComposIn {
                    coxel: half,
                    sample: s([7, 8, 9], alpha, 0, mode),
                });
            }
        }
        let geo = Coxel {
            z: 7,
            geo: [cfg.color_max(), cfg.color_max() / 2, 0],
            ..Coxel::empty(&cfg)
        };
        for mode in ComposMode::ALL {
            for k in [0, 6, 7, 8, cfg.z_none() - 1, cfg.z_none()] {
                for coxel in [geo, Coxel::empty(&cfg)] {
                    items.push(ComposIn {
                        coxel,
                        sample: s([1, 2, 3], cfg.alpha_max() / 2, k, mode),
                    });
                }
            }
        }
        for a in [
            regs.et_threshold - 2,
            regs.et_threshold - 1,
            regs.et_threshold,
            regs.et_threshold + 1,
        ] {
            let c = Coxel {
                rgba: [a / 2, a / 3, a / 4, a],
                ..geo
            };
            for alpha in [0, 1, cfg.alpha_max()] {
                for mode in [ComposMode::FrontToBack, ComposMode::Flush] {
                    items.push(ComposIn {
                        coxel: c,
                        sample: s([9, 9, 9], alpha, 0, mode),
                    });
                }
            }
        }
        // A ray of 12 slices in front of geometry at 12, then its flush.
        let mut ray: Vec<Sample> = (0..14)
            .map(|k| {
                s(
                    [200, 100, 50],
                    cfg.alpha_max() / 8,
                    k,
                    ComposMode::FrontToBack,
                )
            })
            .collect();
        ray.push(s([0; 3], 0, 0, ComposMode::Flush));
        let start = Coxel { z: 12, ..geo };
        items.extend(chain(&gold, start, &ray));
        run_items(variant, &mut gold, items, seed(370));
    }
}

#[test]
fn one_item_per_cycle_when_never_stalled() {
    const LATENCY: u64 = 6;
    for (variant, cfg) in configs::<ComposConfig>() {
        let gold = unit(cfg, 1.0, ComposRegs::defaults(&cfg));
        let writes = gold.config_writes();
        let items = random_items(seed(11), 100_000, random_item(cfg));
        let driven = assert_one_item_per_clock(variant, cfg, &writes, &items, LATENCY);
        let values: Vec<Coxel> = driven.outputs.into_iter().map(|t| t.value).collect();
        assert_eq!(values, gold.clone().run(&items));
    }
}

#[test]
fn gate_level_netlist_smoke() {
    let (variant, cfg) = gate_configs::<ComposConfig>()[0];
    let mut gold = unit(cfg, 2.0, busy_regs(&cfg, 2, false));
    let writes = gold.config_writes();
    let smoke = StreamCheck::gate_smoke(seed(21)).with_config_writes(writes);
    must_match(variant, cfg, &mut gold, &mut random_item(cfg), &smoke);
    let regs = busy_regs(&cfg, 0, true);
    let mut gold = unit(cfg, 0.5, regs);
    let mut items = Vec::new();
    for coxel in edge_coxels(&cfg, &regs) {
        for alpha in [0, 1, cfg.alpha_max() - 1, cfg.alpha_max()] {
            for mode in ComposMode::ALL {
                items.push(ComposIn {
                    coxel,
                    sample: s([cfg.color_max(), 0, 77], alpha, 4, mode),
                });
            }
        }
    }
    run_items(variant, &mut gold, items, seed(22));
}

/// Beyond trilin's corrupted-output check: the scoreboard also catches a table entry or a register
/// that reached the RTL through the configuration port with a different value than the model has.
#[test]
fn a_config_write_that_differs_from_the_model_is_caught() {
    let cfg = ComposConfig::DEFAULT;
    let variant = variant_with(cfg);
    let regs = ComposRegs::defaults(&cfg);
    let gold_unit = unit(cfg, 1.0, regs);
    let item = |i: usize, a: u64| ComposIn {
        coxel: Coxel {
            rgba: [0, 0, 0, a],
            ..Coxel::empty(&cfg)
        },
        sample: s([255; 3], (i as u32 * 7) % 4096, 0, ComposMode::FrontToBack),
    };
    // One LUT entry off by one LSB: on an empty coxel A' = Lut[r] << (F - Q) shows it; item 500
    // is the first to read code 3500.
    let entry = 3500usize;
    let lut_items: Vec<ComposIn> = (0..2000).map(|i| item(i, 0)).collect();
    let mut writes = gold_unit.config_writes();
    writes.push((entry as u32, vec![gold_unit.lut().entries()[entry] + 1]));
    // The early-termination threshold one LSB low: a coxel at EtThreshold - 1 terminates early.
    let et_items: Vec<ComposIn> = (0..2000).map(|i| item(i, regs.et_threshold - 1)).collect();
    let mut writes_et = gold_unit.config_writes();
    writes_et.push((cfg.reg_addr(1), vec![regs.et_threshold as u32 - 1]));
    for (what, items, writes, first_bad) in [
        ("LUT entry", lut_items, writes, 500u64),
        ("EtThreshold", et_items, writes_et, 0),
    ] {
        let mut it = items.clone().into_iter().cycle();
        let mut check = StreamCheck::new(4343, items.len()).with_traffic(0.1, 0.1);
        check.config_writes = writes;
        check.waveform_on_mismatch = false;
        let mut gold = gold_unit.clone();
        let err = expect_mismatch(
            check_stream(variant, cfg, &mut gold, &mut |_| it.next().unwrap(), &check),
            "a differing configuration write must be caught",
        );
        assert_eq!(err.item, first_bad, "{what}");
        let report = err.to_string();
        assert!(
            report.contains("MISMATCH") && report.contains("ComposIn"),
            "{report}"
        );
        eprintln!("{what}:\n{report}");
    }
    // And a corrupted output bit in the terminated flag, the last field of the coxel.
    let mut check = StreamCheck::new(4344, 3000).with_traffic(0.1, 0.1);
    check.config_writes = gold_unit.config_writes();
    check.corrupt = Some((1234, cfg.coxel_w() - 1));
    check.waveform_on_mismatch = false;
    let err = expect_mismatch(
        check_stream(
            variant,
            cfg,
            &mut gold_unit.clone(),
            &mut random_item(cfg),
            &check,
        ),
        "a flipped terminated flag must be caught",
    );
    assert_eq!(err.item, 1234);
}

#[test]
fn codec_and_variant_are_checked_against_the_rtl() {
    assert_foreign_codec_is_refused::<ComposConfig>();
    let cfg = ComposConfig::NARROW;
    let mut dut = RtlStream::new(variant_with(cfg), cfg, 1).unwrap();
    let writes = config_writes(
        &cfg,
        &OpacityLut::new(1.0, &cfg).unwrap(),
        &ComposRegs::defaults(&cfg),
    );
    assert_eq!(writes.len(), 256 + 3);
    for (addr, data) in writes {
        dut.write_config(addr, &data)
            .expect("compos has a configuration port");
    }
}
