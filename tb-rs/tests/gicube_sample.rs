//! Co-simulation of gicube_sample (the block processor's sample datapath: resampling,
//! classification, irradiance shading, compositing) against the golden model `Sampler`
//! (docs/numerics/gicube_sample.md). The tables (classification, opacity for the sample distance,
//! termination threshold) are loaded into model and RTL alike (`Sampler::config_writes`).

mod support;

use cube5_model::camera::Camera;
use cube5_model::units::cube5_shader::{
    ClassLut, Phong, ReflectanceMap, Rgba, ShaderTables, Texel,
};
use cube5_model::units::gicube_processor::{shadow_scene, Processor, ProcessorConfig, Projection};
use cube5_model::units::gicube_sample::{
    random_class_lut, random_sample_for, shader_config_for, trace_samples, GradLut, SampleIn,
    SampleRtlConfig, Sampler, IRR_FRAC_W,
};
use cube5_tb::harness::{check_stream, StreamCheck};
use cube5_tb::Variant;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::{
    assert_one_item_per_clock, configs, expect_mismatch, gate_configs, must_match_across_a_reset,
    must_match_items, random_items, seed, MILLION,
};

fn random_item(cfg: SampleRtlConfig) -> impl FnMut(&mut ChaCha8Rng) -> SampleIn {
    move |rng| random_sample_for(rng, cfg)
}

/// The shading tables of a `Shade = 1` configuration, by kind: 0 a random reflectance map and
/// gradient LUT, 1 Phong's two lights over the LUT of uniform directions, 2 every gradient zero
/// (the zero-gradient entry alone), 3 a map whose texels are their own coordinates (every texel
/// distinct) over random directions. `sampler` unchanged without shading.
fn shaded(sampler: Sampler, cfg: SampleRtlConfig, kind: usize, rng: &mut ChaCha8Rng) -> Sampler {
    let Some(sh) = cfg.shade_config() else {
        return sampler;
    };
    let scfg = shader_config_for(cfg.voxel_w, Some(sh));
    let (rmap, grad) = match kind % 4 {
        0 => (
            ShaderTables::random(&scfg, rng).unwrap().rmap,
            GradLut::random(rng, sh.grad_idx_w).unwrap(),
        ),
        1 => (
            ReflectanceMap::from_lights(&scfg, &Phong::two_lights()).unwrap(),
            GradLut::directions(sh.grad_idx_w).unwrap(),
        ),
        2 => (
            ShaderTables::random(&scfg, rng).unwrap().rmap,
            GradLut::zero(sh.grad_idx_w).unwrap(),
        ),
        _ => (
            ReflectanceMap::from_fn(
                &scfg,
                |face, i, j| Texel {
                    d: ((face * 81 + j * 9 + i) % 512) as u32,
                    sp: ((face * 37 + i * 9 + j) % 256) as u32,
                },
                Texel { d: 511, sp: 255 },
            )
            .unwrap(),
            GradLut::random(rng, sh.grad_idx_w).unwrap(),
        ),
    };
    sampler.with_shading(rmap, grad).unwrap()
}

/// Items in flight that a reset may drop: the pipeline's stages plus the handshake's slack.
fn in_flight(cfg: SampleRtlConfig) -> usize {
    cfg.latency() as usize + 2
}

/// A sampler with random tables: a random classification table, a sample distance in 16..=1024
/// and a termination threshold (or none), all from `rng`.
fn random_sampler(rng: &mut ChaCha8Rng, cfg: SampleRtlConfig) -> Sampler {
    let step = match rng.random_range(0..4) {
        0 => [16, 1024][rng.random_range(0..2)],
        _ => rng.random_range(16..=1024),
    };
    let et = match rng.random_range(0..3) {
        0 => None,
        1 => Some(rng.random_range(1..=4096)),
        _ => Some(rng.random_range(3000..=4096)),
    };
    let class = random_class_lut(rng, cfg.voxel_w).unwrap();
    let s = Sampler::new(cfg.sample_config(step, et), class).unwrap();
    shaded(s, cfg, 0, rng)
}

/// `must_match` with `gold`'s tables loaded into the RTL first.
fn check_for(gold: &Sampler, check: StreamCheck) -> StreamCheck {
    check.with_config_writes(gold.config_writes())
}

/// Random samples through `variant` with a random table set seeded by `s` (loaded into model and
/// RTL), shaped by `check` (which resets once).
fn random_run_across_a_reset(
    variant: &'static Variant,
    cfg: SampleRtlConfig,
    s: u64,
    check: StreamCheck,
) {
    let mut gold = random_sampler(&mut ChaCha8Rng::seed_from_u64(s), cfg);
    let check = check_for(&gold, check);
    must_match_across_a_reset(
        variant,
        cfg,
        &mut gold,
        &mut random_item(cfg),
        &check,
        in_flight(cfg),
    );
}

#[test]
#[ignore = "sim-full: a million samples per configuration with idle, back-pressure and a reset"]
fn million_random_samples_per_config_with_idle_backpressure_and_reset() {
    for (i, (variant, cfg)) in configs::<SampleRtlConfig>().into_iter().enumerate() {
        let s = seed(1600 + i as u64);
        random_run_across_a_reset(variant, cfg, s, StreamCheck::long(s, MILLION, 5));
    }
}

#[test]
fn random_samples_with_idle_backpressure_and_reset() {
    // CI's share of the million above, over several random table sets.
    for (i, (variant, cfg)) in configs::<SampleRtlConfig>().into_iter().enumerate() {
        for t in 0..3u64 {
            let s = seed(1610 + 10 * i as u64 + t);
            let check = StreamCheck::long(s, 20_000, 0).with_batch(5_000);
            random_run_across_a_reset(variant, cfg, s, check);
        }
    }
}

/// The output stalled nine clocks in ten and the input never idle: every stage and both FIFOs
/// full most of the time (15 items between the input and the shade stage, the FIFOs' most), the
/// irradiance trilin still never stalled (its assertion is on in the simulation).
#[test]
fn a_full_pipeline_under_heavy_back_pressure() {
    for (i, (variant, cfg)) in configs::<SampleRtlConfig>().into_iter().enumerate() {
        let s = seed(1680 + i as u64);
        let check = StreamCheck::new(s, 10_000)
            .with_traffic(0.0, 0.9)
            .with_reset_in_batch(0)
            .with_batch(2_500);
        random_run_across_a_reset(variant, cfg, s, check);
    }
}

/// Tables at the extremes: every entry opaque white, or alpha 1 code, or the entry equal to its
/// index's bits (so every index bit reaches the output), with `dr` at 16 and 1024 and the
/// threshold at 1, 4096 or off.
fn extreme_samplers(cfg: SampleRtlConfig) -> Vec<Sampler> {
    let scfg = shader_config_for(cfg.voxel_w, cfg.shade_config());
    let mut rng = ChaCha8Rng::seed_from_u64(seed(1625));
    let luts: [fn(usize) -> Rgba; 3] = [
        |_| Rgba {
            r: 255,
            g: 255,
            b: 255,
            a: 4095,
        },
        |_| Rgba {
            r: 1,
            g: 0,
            b: 255,
            a: 1,
        },
        |i| Rgba {
            r: (i & 0xff) as u32,
            g: (i >> 4 & 0xff) as u32,
            b: 255 - (i & 0xff) as u32,
            a: (i & 0xfff) as u32,
        },
    ];
    let mut out = Vec::new();
    for (k, f) in luts.iter().enumerate() {
        for (step, et) in [(16, None), (1024, Some(1)), (256, Some(4096)), (1024, None)] {
            if k == 2 || step == 1024 || et.is_none() {
                let class = ClassLut::from_fn(&scfg, f).unwrap();
                let s = Sampler::new(cfg.sample_config(step, et), class).unwrap();
                let kind = out.len();
                out.push(shaded(s, cfg, kind, &mut rng));
            }
        }
    }
    out
}

/// Directed items: corners all 0, all max, alternating, each alone at max; weights 0, 128, 255;
/// the irradiance absent, 0, 1.0, the largest, one corner alone; the packet's colour and opacity
/// 0, 4095 and next to the threshold; rendering and lighting; with shading the corners' gradient
/// indices all 0, all the largest, or distinct, and their tags distinct.
fn directed_items(cfg: SampleRtlConfig) -> Vec<SampleIn> {
    let vmax = (1u32 << cfg.voxel_w) - 1;
    let imax = (1u32 << cfg.grad_idx_w) - 1;
    let tmask = (1u32 << cfg.tag_w) - 1;
    let mut corner_sets: Vec<[u32; 8]> = vec![
        [0; 8],
        [vmax; 8],
        [1; 8],
        [vmax - 1; 8],
        std::array::from_fn(|c| if c % 2 == 0 { 0 } else { vmax }),
        std::array::from_fn(|c| if c < 4 { vmax } else { 0 }),
    ];
    for c in 0..8 {
        let mut v = [0; 8];
        v[c] = vmax;
        corner_sets.push(v);
    }
    let irrs: [Option<[u32; 8]>; 6] = [
        None,
        Some([0; 8]),
        Some([1 << IRR_FRAC_W; 8]),
        Some([u16::MAX as u32; 8]),
        Some(std::array::from_fn(|c| {
            if c == 7 {
                u16::MAX as u32
            } else {
                0
            }
        })),
        Some(std::array::from_fn(|c| (c as u32 + 1) * 8000)),
    ];
    let packets: [([u16; 3], u16); 6] = [
        ([0; 3], 0),
        ([4095; 3], 4095),
        ([100, 2000, 4095], 2048),
        ([4095, 0, 1], 4094),
        ([1, 1, 1], 1),
        ([3000, 3000, 3000], 4000),
    ];
    let mut items = Vec::new();
    for (vi, &voxels) in corner_sets.iter().enumerate() {
        for (wi, weights) in [[0, 0, 0], [255, 255, 255], [128, 0, 255], [1, 254, 128]]
            .into_iter()
            .enumerate()
        {
            for (ii, &irr) in irrs.iter().enumerate() {
                let (color, opacity) = packets[(vi + wi + ii) % packets.len()];
                for lighting in [false, true] {
                    let grad_idx = match (vi + ii) % 3 {
                        0 => [0; 8],
                        1 => [imax; 8],
                        _ => std::array::from_fn(|c| (c as u32 * (vi as u32 + 3) + 1) & imax),
                    };
                    items.push(SampleIn {
                        voxels,
                        weights,
                        irr: if lighting { None } else { irr },
                        color,
                        opacity,
                        lighting,
                        grad_idx: if cfg.shade != 0 { grad_idx } else { [0; 8] },
                        tags: std::array::from_fn(|c| (c as u32 + wi as u32) & tmask),
                    });
                }
            }
        }
    }
    items
}

#[test]
fn directed_extreme_tables_corners_irradiance_and_packets() {
    for (i, (variant, cfg)) in configs::<SampleRtlConfig>().into_iter().enumerate() {
        let items = directed_items(cfg);
        assert!(items.len() > 500);
        for (k, mut gold) in extreme_samplers(cfg).into_iter().enumerate() {
            let check = check_for(
                &gold,
                StreamCheck::directed(seed(1620 + 10 * i as u64 + k as u64)),
            );
            must_match_items(variant, cfg, &mut gold, items.clone(), &check);
        }
    }
}

#[test]
fn one_sample_per_clock() {
    for (variant, cfg) in configs::<SampleRtlConfig>() {
        let s = seed(1630);
        let gold = random_sampler(&mut ChaCha8Rng::seed_from_u64(s), cfg);
        let items = random_items(s, 50_000, random_item(cfg));
        let out =
            assert_one_item_per_clock(variant, cfg, &gold.config_writes(), &items, cfg.latency());
        for (i, (it, o)) in items.iter().zip(&out.outputs).enumerate() {
            assert_eq!(o.value, gold.sample(it), "{variant}: item {i} {it:?}");
        }
    }
}

#[test]
fn gate_level_netlist_smoke() {
    for (variant, cfg) in gate_configs::<SampleRtlConfig>() {
        let s = seed(1640);
        random_run_across_a_reset(variant, cfg, s, StreamCheck::gate_smoke(s));
        let mut gold = extreme_samplers(cfg).swap_remove(2);
        let check = check_for(&gold, StreamCheck::directed(seed(1641)));
        must_match_items(variant, cfg, &mut gold, directed_items(cfg), &check);
    }
}

/// The scoreboard bites: a model one raw unit of `dr` off (its opacity table differs) is caught.
#[test]
fn a_model_with_another_step_is_caught() {
    let (variant, cfg) = configs::<SampleRtlConfig>()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(seed(1650));
    let class = random_class_lut(&mut rng, cfg.voxel_w).unwrap();
    let rtl = Sampler::new(cfg.sample_config(300, None), class.clone()).unwrap();
    let mut other = Sampler::new(cfg.sample_config(301, None), class).unwrap();
    let mut check = check_for(
        &rtl,
        StreamCheck::new(seed(1651), 5_000).with_traffic(0.1, 0.1),
    );
    check.waveform_on_mismatch = false;
    let err = expect_mismatch(
        check_stream(variant, cfg, &mut other, &mut random_item(cfg), &check),
        "a different dr changes the opacity table",
    );
    assert!(err.item < 200, "{variant}: caught at item {}", err.item);
}

/// The scoreboard bites on the jitter: a jitter configuration's RTL with its tables loaded
/// against a model whose random LUT entries are all another value (a model without the jitter's
/// factor, `r` constant) is caught.
#[test]
fn a_model_with_another_jitter_is_caught() {
    let mut ran = 0;
    for (variant, cfg) in configs::<SampleRtlConfig>() {
        if cfg.jitter == 0 {
            continue;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed(1652));
        let class = random_class_lut(&mut rng, cfg.voxel_w).unwrap();
        let rtl = Sampler::new(cfg.sample_config(300, None), class.clone()).unwrap();
        // The same datapath without jitter at the mean factor's step (3/4 of 400 = 300).
        let plain = SampleRtlConfig { jitter: 0, ..cfg };
        let mut other = Sampler::new(plain.sample_config(400, None), class).unwrap();
        let mut check = check_for(
            &rtl,
            StreamCheck::new(seed(1653), 5_000).with_traffic(0.1, 0.1),
        );
        check.waveform_on_mismatch = false;
        let err = expect_mismatch(
            check_stream(variant, cfg, &mut other, &mut random_item(cfg), &check),
            "a constant factor misses the jitter",
        );
        assert!(err.item < 200, "{variant}: caught at item {}", err.item);
        ran += 1;
    }
    assert!(ran > 0, "a jitter configuration");
}

/// The scoreboard bites on the shading: a `Shade = 1` configuration's RTL loaded with one
/// gradient LUT against a model with another (every entry's x component negated), and against a
/// model whose reflectance map differs, is caught.
#[test]
fn a_model_with_another_gradient_or_map_is_caught() {
    let mut ran = 0;
    for (variant, cfg) in configs::<SampleRtlConfig>() {
        let Some(sh) = cfg.shade_config() else {
            continue;
        };
        let mut rng = ChaCha8Rng::seed_from_u64(seed(1654));
        let class = random_class_lut(&mut rng, cfg.voxel_w).unwrap();
        let base = Sampler::new(cfg.sample_config(300, None), class).unwrap();
        let rtl = shaded(base.clone(), cfg, 1, &mut rng);
        let scfg = shader_config_for(cfg.voxel_w, Some(sh));
        let good = ReflectanceMap::from_lights(&scfg, &Phong::two_lights()).unwrap();
        let dirs = GradLut::directions(sh.grad_idx_w).unwrap();
        let mirrored = GradLut::from_fn(sh.grad_idx_w, |i| {
            let e = dirs.entries()[i];
            [-e[0].max(-511), e[1], e[2]]
        })
        .unwrap();
        let dark =
            ReflectanceMap::from_fn(&scfg, |_, _, _| Texel::default(), Texel::default()).unwrap();
        for (what, mut other) in [
            (
                "a mirrored gradient",
                base.clone().with_shading(good, mirrored).unwrap(),
            ),
            (
                "a dark map",
                base.clone().with_shading(dark, dirs.clone()).unwrap(),
            ),
        ] {
            let mut check = check_for(
                &rtl,
                StreamCheck::new(seed(1655), 5_000).with_traffic(0.1, 0.1),
            );
            check.waveform_on_mismatch = false;
            let err = expect_mismatch(
                check_stream(variant, cfg, &mut other, &mut random_item(cfg), &check),
                what,
            );
            assert!(
                err.item < 200,
                "{variant}: {what} caught at item {}",
                err.item
            );
        }
        ran += 1;
    }
    assert!(ran > 0, "a shading configuration");
}

/// Tables survive a reset: loaded once, a reset in the first batch, the rest still matches (the
/// long runs above reset too; this one resets before most items).
#[test]
fn tables_survive_an_early_reset() {
    for (variant, cfg) in configs::<SampleRtlConfig>().into_iter().take(1) {
        let s = seed(1660);
        let check = StreamCheck::long(s, 6_000, 0)
            .with_batch(1_000)
            .with_traffic(0.5, 0.5);
        random_run_across_a_reset(variant, cfg, s, check);
    }
}

/// The processor model's own sample traffic replayed on the RTL: the shadow scene at 16^3
/// (12-bit voxels) rendered by `gicube_processor` unlit, then its lighting pass (lighting rays),
/// then rendered again lit by the irradiance; every sample the three passes took
/// (`trace_samples`) goes through the RTL with the processor's own tables, under idle and
/// back-pressure, and must equal the model's item for item. The replay's counts equal the
/// frames': one sample per `samples` count.
#[test]
fn processor_gi_frame_sample_traffic_replays_on_the_rtl() {
    let (vol, tf, light) = shadow_scene(16).unwrap();
    let d = [0.35f64, 0.75, -0.55];
    let len = d.iter().map(|x| x * x).sum::<f64>().sqrt();
    let cam = Camera::new(d.map(|x| x / len).into(), vol.dims, vol.spacing, 32, 32);
    let pcfg = ProcessorConfig {
        block_log2: 3,
        ..ProcessorConfig::DEFAULT
    };
    let mut p = Processor::new(pcfg, &vol, &tf).unwrap();
    let (unlit, t0) = trace_samples(|| p.render(&cam, Projection::Parallel).unwrap());
    let (lighting, t1) = trace_samples(|| p.light(&light).unwrap());
    let (lit, t2) = trace_samples(|| p.render(&cam, Projection::Parallel).unwrap());
    let counts = [
        unlit.counts.samples,
        lighting.counts.samples,
        lit.counts.samples,
    ];
    let traced = [t0.items.len(), t1.items.len(), t2.items.len()].map(|n| n as u64);
    assert_eq!(traced, counts, "one traced item per sample of each pass");
    assert_eq!(t0.others + t1.others + t2.others, 0, "one datapath");
    let gold = t0.sampler.clone().unwrap();
    let items: Vec<SampleIn> = [t0.items, t1.items, t2.items].concat();
    let n_lighting = items.iter().filter(|it| it.lighting).count();
    let n_lit = items.iter().filter(|it| it.irr.is_some()).count();
    assert!(
        n_lighting > 1000 && n_lit > 1000,
        "{n_lighting} lighting, {n_lit} lit samples"
    );
    let mut ran = 0;
    for (variant, cfg) in configs::<SampleRtlConfig>() {
        // The processor's traffic is unjittered and unshaded (ProcessorConfig::jitter off).
        if cfg.voxel_w != vol.bits || cfg.jitter != 0 || cfg.shade != 0 {
            continue;
        }
        let check = check_for(
            &gold,
            StreamCheck::new(seed(1670), items.len()).with_traffic(0.2, 0.3),
        );
        let r = must_match_items(variant, cfg, &mut gold.clone(), items.clone(), &check);
        eprintln!(
            "{variant}: processor GI frames ({} unlit, {n_lighting} lighting, {n_lit} lit samples): {} replayed in {} cycles",
            counts[0], r.compared, r.cycles
        );
        ran += 1;
    }
    assert!(
        ran > 0,
        "a configuration of the scene's {}-bit voxels",
        vol.bits
    );
}
