//! Co-simulation of gicube_scatter against the golden model (docs/numerics/gicube_scatter.md).

mod support;

use cube5_model::unit::StreamUnit;
use cube5_model::units::gicube_scatter::{
    random_item, Scatter, ScatterConfig, ScatterEvent, ScatterIn, ScatterTables, CFG_SEL_SEED,
};
use cube5_tb::harness::{check_stream, must_match, StreamCheck};
use cube5_tb::rtl::RtlStream;
use cube5_tb::Variant;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::{
    assert_one_item_per_clock, configs, expect_mismatch, gate_configs, must_match_across_a_reset,
    must_match_items, random_items, seed, variant_with, MILLION,
};

/// Register stages (contract § Timing).
const LATENCY: u64 = 42;

fn gen(cfg: ScatterConfig) -> impl FnMut(&mut ChaCha8Rng) -> ScatterIn {
    move |rng| random_item(&cfg, rng)
}

/// The model and the configuration-port writes that load the same tables into the RTL.
fn model_and_tables(cfg: ScatterConfig) -> (Scatter, Vec<(u32, Vec<u32>)>) {
    let tables = ScatterTables::new(&cfg).unwrap();
    let writes = tables.config_writes(&cfg);
    (Scatter::with_tables(cfg, tables).unwrap(), writes)
}

/// Runs `items` (cycled) with idle and back-pressure, tables loaded.
fn run_directed(
    variant: &'static Variant,
    cfg: ScatterConfig,
    items: Vec<ScatterIn>,
    seed_default: u64,
) {
    let (mut model, writes) = model_and_tables(cfg);
    must_match_items(
        variant,
        cfg,
        &mut model,
        items,
        &StreamCheck::directed(seed(seed_default)).with_config_writes(writes),
    );
}

fn base(cfg: &ScatterConfig) -> ScatterIn {
    ScatterIn {
        dir: [1 << cfg.f(), 0, 0],
        grad: [-1000, 0, 0],
        refl: 0,
        refr: 0,
        iso: 0,
        gloss: 0,
        eta: cfg.mat_one(),
        ray_bits: 0,
    }
}

/// Every material extreme on one geometry, over many ray bits.
/// `base` with direction `dir` and gradient `grad`.
fn at(cfg: &ScatterConfig, dir: [i32; 3], grad: [i32; 3]) -> ScatterIn {
    ScatterIn {
        dir,
        grad,
        ..base(cfg)
    }
}

fn with_materials(cfg: &ScatterConfig, geo: ScatterIn, rays: u32) -> Vec<ScatterIn> {
    let one = cfg.mat_one();
    let mut out = Vec::new();
    for k in 0..rays {
        for (refl, refr, iso) in [
            (one, 0, 0),
            (0, one, 0),
            (0, 0, one),
            (0, 0, 0),
            (cfg.mat_max(), cfg.mat_max(), cfg.mat_max()),
            (one / 3, one / 2, one / 2),
        ] {
            for gloss in [0, one / 2, one, cfg.mat_max()] {
                out.push(ScatterIn {
                    refl,
                    refr,
                    iso,
                    gloss,
                    ray_bits: k.wrapping_mul(0x9e37_79b9) ^ refl ^ (gloss << 8),
                    ..geo
                });
            }
        }
    }
    out
}

#[test]
fn million_random_rays_per_config_with_idle_backpressure_and_reset() {
    for (i, (variant, cfg)) in configs::<ScatterConfig>().into_iter().enumerate() {
        let (mut model, writes) = model_and_tables(cfg);
        let check = StreamCheck::long(seed(500 + i as u64), MILLION, 3).with_config_writes(writes);
        must_match_across_a_reset(variant, cfg, &mut model, &mut gen(cfg), &check, 200);
    }
}

#[test]
fn zero_gradient_and_zero_direction() {
    for (variant, cfg) in configs::<ScatterConfig>() {
        let one = 1 << cfg.f();
        let mut items = Vec::new();
        for dir in [[one, 0, 0], [0, 0, 0], [-one, one, -one], [1, 0, 0]] {
            for grad in [[0, 0, 0], [1, 0, 0], [0, 0, -1]] {
                items.extend(with_materials(&cfg, at(&cfg, dir, grad), 8));
            }
        }
        let model = Scatter::new(cfg).unwrap();
        assert!(items.iter().any(|it| model.scatter(it).zero_grad));
        assert!(items.iter().any(|it| model.scatter(it).zero_dir));
        run_directed(variant, cfg, items, 31);
    }
}

#[test]
fn grazing_angles() {
    for (variant, cfg) in configs::<ScatterConfig>() {
        let one = 1 << cfg.f();
        let g = cfg.grad_range().1;
        let mut items = Vec::new();
        // Directions within a few LSB of the surface plane, from both sides, every eta extreme.
        for tilt in [-2, -1, 0, 1, 2, 17] {
            for eta in [0, 1, cfg.mat_one() / 2, cfg.mat_one(), cfg.eta_max()] {
                for grad in [[0, g, 0], [0, -g, 0], [0, 3, 0], [1, g, -1]] {
                    items.extend(with_materials(
                        &cfg,
                        ScatterIn {
                            dir: [one, tilt, 0],
                            grad,
                            eta,
                            ..base(&cfg)
                        },
                        2,
                    ));
                }
            }
        }
        run_directed(variant, cfg, items, 32);
    }
}

#[test]
fn glossiness_zero_and_ninety() {
    for (variant, cfg) in configs::<ScatterConfig>() {
        let one = 1 << cfg.f();
        let mut items = Vec::new();
        for k in 0..400u32 {
            for gloss in [0, cfg.mat_one(), cfg.mat_max()] {
                for (refl, refr) in [(cfg.mat_one(), 0), (0, cfg.mat_one())] {
                    items.push(ScatterIn {
                        dir: [one / 2, -one / 2, one / 2],
                        grad: [-5, 9, 1],
                        refl,
                        refr,
                        gloss,
                        eta: cfg.mat_one() * 3 / 4,
                        ray_bits: k.wrapping_mul(2_654_435_761),
                        ..base(&cfg)
                    });
                }
            }
        }
        run_directed(variant, cfg, items, 33);
    }
}

#[test]
fn refractivity_one_with_total_internal_reflection() {
    for (variant, cfg) in configs::<ScatterConfig>() {
        let model = Scatter::new(cfg).unwrap();
        let one = f64::from(1u32 << cfg.f());
        let mut items = Vec::new();
        // Incidence from 0 to 89 degrees, eta from 1 to 4: crosses the critical angle.
        for deg in (0..90).step_by(3) {
            let a = f64::from(deg).to_radians();
            let dir = [a.sin(), -a.cos(), 0.0].map(|x| (x * one).round() as i32);
            for eta in [
                cfg.mat_one(),
                cfg.mat_one() * 5 / 4,
                cfg.mat_one() * 3 / 2,
                cfg.mat_one() * 2,
                cfg.eta_max(),
            ] {
                for gloss in [0, cfg.mat_one() / 4] {
                    for k in 0..4u32 {
                        items.push(ScatterIn {
                            dir,
                            grad: [0, 4000, 0],
                            refr: cfg.mat_one(),
                            gloss,
                            eta,
                            ray_bits: k ^ (deg << 8) ^ (eta << 16),
                            ..base(&cfg)
                        });
                    }
                }
            }
        }
        let tir = items.iter().filter(|it| model.scatter(it).tir).count();
        assert!(
            tir > 0 && tir < items.len(),
            "both sides of the critical angle"
        );
        assert!(items.iter().all(|it| matches!(
            model.scatter(it).event,
            ScatterEvent::Reflect | ScatterEvent::Refract
        )));
        run_directed(variant, cfg, items, 34);
    }
}

#[test]
fn directions_along_an_axis() {
    for (variant, cfg) in configs::<ScatterConfig>() {
        let one = 1 << cfg.f();
        let (lo, hi) = cfg.dir_range();
        let g = cfg.grad_range();
        let mut items = Vec::new();
        for axis in 0..3 {
            for v in [one, -one, lo, hi, 1, -1] {
                let mut dir = [0; 3];
                dir[axis] = v;
                for gaxis in 0..3 {
                    for gv in [g.0, g.1, 1, -1] {
                        let mut grad = [0; 3];
                        grad[gaxis] = gv;
                        items.extend(with_materials(&cfg, at(&cfg, dir, grad), 1));
                    }
                }
            }
        }
        // The extremes of every field at once.
        items.push(ScatterIn {
            dir: [lo, lo, lo],
            grad: [g.0, g.0, g.0],
            refl: cfg.mat_max(),
            refr: cfg.mat_max(),
            iso: cfg.mat_max(),
            gloss: cfg.mat_max(),
            eta: cfg.eta_max(),
            ray_bits: u32::MAX,
        });
        items.push(ScatterIn {
            dir: [hi, hi, hi],
            grad: [g.1, g.1, g.1],
            refl: 0,
            refr: cfg.mat_max(),
            eta: cfg.eta_max(),
            gloss: cfg.mat_max(),
            ..base(&cfg)
        });
        run_directed(variant, cfg, items, 35);
    }
}

#[test]
fn one_ray_per_cycle_when_never_stalled() {
    for (variant, cfg) in configs::<ScatterConfig>() {
        let (model, writes) = model_and_tables(cfg);
        let items = random_items(seed(41), 100_000, gen(cfg));
        let driven = assert_one_item_per_clock(variant, cfg, &writes, &items, LATENCY);
        for (k, (got, it)) in driven.outputs.iter().zip(&items).enumerate() {
            assert_eq!(got.value, model.scatter(it), "{variant}: item {k}");
        }
    }
}

/// Yosys's gate-level netlists (lines flagged `gate`) through the same comparison.
#[test]
#[ignore = "sim-full: the gate-level netlist is `gatefull` (155 s of build; docs/ci.md)"]
fn gate_level_netlist_smoke() {
    let gates = gate_configs::<ScatterConfig>();
    assert!(!gates.is_empty(), "no gate-level build of gicube_scatter");
    for (variant, cfg) in gates {
        let (mut model, writes) = model_and_tables(cfg);
        let check = StreamCheck::gate_smoke(seed(51)).with_config_writes(writes);
        must_match(variant, cfg, &mut model, &mut gen(cfg), &check);
    }
}

/// Beyond trilin's corrupted-output check: the tables are part of the comparison. One wrong SEED
/// entry in the RTL (written through the port, the model keeps the contract's table) must show up
/// as a mismatch, so the co-simulation would catch a table that model and RTL load differently.
#[test]
fn a_wrong_table_entry_in_the_rtl_is_caught() {
    let cfg = ScatterConfig::DEFAULT;
    let (mut model, mut writes) = model_and_tables(cfg);
    let si = cfg.seed_idx_w();
    // The seed used for mantissas near 2.0, which every normalization of a diagonal vector reads.
    let idx = 1u32 << (si - 1);
    let entry = writes
        .iter_mut()
        .find(|(addr, _)| *addr == (CFG_SEL_SEED << 10 | idx))
        .unwrap();
    entry.1[0] ^= 1 << 3;
    let mut check = StreamCheck::new(4343, 20_000).with_config_writes(writes);
    check.waveform_on_mismatch = false;
    let err = expect_mismatch(
        check_stream(variant_with(cfg), cfg, &mut model, &mut gen(cfg), &check),
        "a wrong SEED entry must be caught",
    );
    let report = err.to_string();
    assert!(
        report.contains("MISMATCH") && report.contains("seed 4343"),
        "{report}"
    );
    eprintln!("{report}");

    // And a write outside every table changes nothing.
    let (mut model, mut writes) = model_and_tables(cfg);
    writes.push((3 << 10, vec![u32::MAX; 2]));
    writes.push((CFG_SEL_SEED << 10 | (1 << si), vec![u32::MAX; 2]));
    let check = StreamCheck::new(seed(52), 20_000).with_config_writes(writes);
    must_match(variant_with(cfg), cfg, &mut model, &mut gen(cfg), &check);
}

/// The output depends only on the item: the same rays in a different order, with a reset in the
/// middle, give the same results (no hidden random state in either reading).
#[test]
fn results_do_not_depend_on_order_or_reset() {
    let (variant, cfg) = configs::<ScatterConfig>()[0];
    let (model, writes) = model_and_tables(cfg);
    let mut rng = ChaCha8Rng::seed_from_u64(seed(61));
    let items: Vec<ScatterIn> = (0..5000).map(|_| random_item(&cfg, &mut rng)).collect();
    let mut dut = RtlStream::new(variant, cfg, 7).unwrap();
    for (addr, data) in &writes {
        dut.write_config(*addr, data).unwrap();
    }
    let forward = dut.run(&items);
    dut.reset();
    let mut rev = items.clone();
    rev.reverse();
    let mut backward = dut.run(&rev);
    backward.reverse();
    assert_eq!(forward, backward);
    let mut shuffled: Vec<usize> = (0..items.len()).collect();
    for k in (1..shuffled.len()).rev() {
        shuffled.swap(k, rng.random_range(0..=k));
    }
    for &k in shuffled.iter().take(100) {
        assert_eq!(model.scatter(&items[k]), forward[k]);
    }
}
