//! Co-simulation of cube5_shader against the golden model (docs/numerics/shader.md).
//!
//! Every run loads the classification LUT, the reflectance map and the zero-gradient entry through
//! the configuration port from tables built in Rust (random contents unless a test says otherwise,
//! so every table bit reaches the output), and the model from the same tables.

mod support;

use cube5_model::transfer::TransferFunction;
use cube5_model::unit::StreamUnit;
use cube5_model::units::cube5_shader::{
    ClassLut, Phong, ReflectanceMap, Rgba, Shader, ShaderConfig, ShaderIn, ShaderMode,
    ShaderTables, Texel,
};
use cube5_tb::harness::{check_stream, must_match, StreamCheck};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::{
    assert_codec_and_config_port, assert_one_item_per_clock, configs, expect_mismatch,
    gate_configs, must_match_across_a_reset, must_match_items, random_items, seed, MILLION,
};

fn random_tables(cfg: &ShaderConfig, seed: u64) -> ShaderTables {
    ShaderTables::random(cfg, &mut ChaCha8Rng::seed_from_u64(seed)).unwrap()
}

/// Every entry at its maximum: every lit channel saturates.
fn max_tables(cfg: &ShaderConfig) -> ShaderTables {
    let e = Rgba {
        r: cfg.color_max(),
        g: cfg.color_max(),
        b: cfg.color_max(),
        a: cfg.alpha_max(),
    };
    let t = Texel {
        d: cfg.diff_max(),
        sp: cfg.spec_max(),
    };
    ShaderTables {
        class: ClassLut::from_fn(cfg, |_| e).unwrap(),
        rmap: ReflectanceMap::from_fn(cfg, |_, _, _| t, t).unwrap(),
    }
}

/// The tables a renderer would load: a transfer function and two Phong lights.
fn lit_tables(cfg: &ShaderConfig) -> ShaderTables {
    ShaderTables {
        class: ClassLut::from_transfer(cfg, &TransferFunction::head_default()).unwrap(),
        rmap: ReflectanceMap::from_lights(cfg, &Phong::two_lights()).unwrap(),
    }
}

/// A gradient component clamped into `S(GradW)`.
fn clamp_grad(cfg: &ShaderConfig, g: i64) -> i32 {
    g.clamp(-i64::from(cfg.grad_max()) - 1, i64::from(cfg.grad_max())) as i32
}

/// Random items: full-range, small, zero, extreme and nearly tied gradients; magnitudes over the
/// whole range and around the 2-D bins; every mode.
fn random_item(cfg: ShaderConfig) -> impl FnMut(&mut ChaCha8Rng) -> ShaderIn {
    move |rng| {
        let gmax = cfg.grad_max();
        let gmin = -gmax - 1;
        let extremes = [gmin, gmin + 1, -1, 0, 1, gmax - 1, gmax];
        let grad: [i32; 3] = match rng.random_range(0..10) {
            0..=3 => std::array::from_fn(|_| rng.random_range(gmin..=gmax)),
            4 | 5 => std::array::from_fn(|_| rng.random_range(-8..=8)),
            6 => [0; 3],
            7 => std::array::from_fn(|_| extremes[rng.random_range(0..extremes.len())]),
            _ => {
                let a = i64::from(rng.random_range(gmin..=gmax));
                std::array::from_fn(|_| {
                    let v = a + rng.random_range(-2..=2);
                    clamp_grad(&cfg, if rng.random_bool(0.5) { -v } else { v })
                })
            }
        };
        let mag = if rng.random_bool(0.5) {
            rng.random_range(0..=cfg.mag_max())
        } else {
            let top = (1u64 << (cfg.mag_shift + cfg.mag_idx_w + 1)).min(u64::from(cfg.mag_max()));
            rng.random_range(0..=top) as u32
        };
        ShaderIn {
            sample: rng.random_range(0..=cfg.sample_max()),
            grad,
            mag,
            mode: ShaderMode::from_bits(rng.random_range(0..4)),
        }
    }
}

/// Extremes: every face centre, edge and corner at the smallest and largest scales, the most
/// negative component, exact and off-by-one ties, the zero gradient, rounding-sensitive ratios;
/// samples and magnitudes at the ends of the range and of the classification bins; every mode.
fn directed_items(cfg: ShaderConfig) -> Vec<ShaderIn> {
    let gmax = i64::from(cfg.grad_max());
    let gmin = -gmax - 1;
    let mut grads: Vec<[i64; 3]> = vec![
        [0, 0, 0],
        [gmin, gmin, gmin],
        [gmin, gmax, 0],
        [gmax, gmin, gmin],
        [gmin, gmax, gmax],
        [gmax, gmax, gmin + 1],
        [3, 1, 0],
        [6, 1, -1],
        [-7, 3, 5],
        [1, 6, -2],
        [2, -3, 6],
        [gmax, 1, -1],
        [gmax, gmax - 1, gmax - 2],
        [-gmax, gmax - 1, 1 - gmax],
    ];
    for scale in [1, 2, gmax] {
        for axis in 0..3 {
            for sign in [1, -1] {
                let mut centre = [0; 3];
                centre[axis] = sign * scale;
                grads.push(centre);
                let mut edge = [sign * scale; 3];
                edge[(axis + 1) % 3] = 0;
                grads.push(edge);
                let mut off = [sign * scale; 3];
                off[axis] -= sign;
                grads.push(off);
            }
        }
        for signs in 0..8 {
            grads.push(std::array::from_fn(|c| {
                if signs >> c & 1 == 1 {
                    -scale
                } else {
                    scale
                }
            }));
        }
    }
    let smax = cfg.sample_max();
    let bin = 1u32 << (cfg.sample_w() - cfg.class_idx_w);
    let samples = [0, bin - 1, bin, smax / 2, smax];
    let mbin = 1u32 << cfg.mag_shift;
    let top = (1u32 << cfg.mag_idx_w) * mbin;
    let mags = [
        0,
        mbin - 1,
        mbin,
        top - 1,
        top.min(cfg.mag_max()),
        cfg.mag_max(),
    ];
    let mut items = Vec::new();
    for g in &grads {
        let grad = g.map(|c| clamp_grad(&cfg, c));
        for &sample in &samples {
            for &mag in &mags {
                for mode in 0..4 {
                    items.push(ShaderIn {
                        sample,
                        grad,
                        mag,
                        mode: ShaderMode::from_bits(mode),
                    });
                }
            }
        }
    }
    items
}

fn shader(cfg: ShaderConfig, tables: &ShaderTables) -> Shader {
    Shader::new(cfg, tables.clone()).unwrap()
}

#[test]
fn million_random_items_per_config_with_idle_backpressure_and_reset() {
    for (i, (variant, cfg)) in configs::<ShaderConfig>().into_iter().enumerate() {
        let tables = random_tables(&cfg, seed(300 + i as u64));
        let check = StreamCheck::long(seed(100 + i as u64), MILLION, 3)
            .with_config_writes(tables.config_writes(&cfg));
        must_match_across_a_reset(
            variant,
            cfg,
            &mut shader(cfg, &tables),
            &mut random_item(cfg),
            &check,
            1000,
        );
    }
}

#[test]
fn directed_extremes() {
    for (variant, cfg) in configs::<ShaderConfig>() {
        for (name, tables) in [
            ("random", random_tables(&cfg, 7)),
            ("max", max_tables(&cfg)),
            ("lit", lit_tables(&cfg)),
        ] {
            eprintln!("{variant}: {name} tables");
            must_match_items(
                variant,
                cfg,
                &mut shader(cfg, &tables),
                directed_items(cfg),
                &StreamCheck::directed(seed(7)).with_config_writes(tables.config_writes(&cfg)),
            );
        }
    }
}

#[test]
fn one_item_per_cycle_when_never_stalled() {
    for (variant, cfg) in configs::<ShaderConfig>() {
        let tables = random_tables(&cfg, 11);
        let writes = tables.config_writes(&cfg);
        let items = random_items(seed(11), 100_000, random_item(cfg));
        let driven = assert_one_item_per_clock(variant, cfg, &writes, &items, cfg.latency());
        let want = shader(cfg, &tables).run(&items);
        let got: Vec<Rgba> = driven.outputs.into_iter().map(|t| t.value).collect();
        assert!(
            got == want,
            "{variant}: full-speed outputs differ from the model"
        );
    }
}

#[test]
fn gate_level_netlist_smoke() {
    // Every `gate` line: v8 (Pipe = 0) and v8p1 (the pipelined decode and products).
    for (variant, cfg) in gate_configs::<ShaderConfig>() {
        let tables = random_tables(&cfg, 21);
        must_match(
            variant,
            cfg,
            &mut shader(cfg, &tables),
            &mut random_item(cfg),
            &StreamCheck::gate_smoke(seed(21)).with_config_writes(tables.config_writes(&cfg)),
        );
        must_match_items(
            variant,
            cfg,
            &mut shader(cfg, &tables),
            directed_items(cfg),
            &StreamCheck::directed(seed(22)).with_config_writes(tables.config_writes(&cfg)),
        );
    }
}

/// Drives `items` under `traffic` and compares every output with `gold`; with `cut`, stops after
/// that many cycles (items in flight stay in the pipeline) and returns how many were consumed.
fn drive_and_compare(
    dut: &mut RtlStream<ShaderConfig>,
    gold: &mut Shader,
    items: &[ShaderIn],
    traffic: &Traffic,
    cut: Option<u64>,
) -> usize {
    let n = items.len() as u64;
    let driven = match cut {
        Some(c) => dut.drive(items, traffic, u64::MAX, c).unwrap(),
        None => dut.drive(items, traffic, n, 64 * n + 1000).unwrap(),
    };
    assert_eq!(
        driven.stats.protocol_errors,
        0,
        "{}: valid/ready",
        dut.name()
    );
    let consumed = driven.stats.consumed as usize;
    let want = gold.run(&items[..consumed]);
    for (k, t) in driven.outputs.iter().enumerate() {
        assert_eq!(
            t.value,
            want[k],
            "{}: item {k} {:?} at cycle {}",
            dut.name(),
            items[k],
            t.cycle
        );
    }
    if cut.is_none() {
        assert_eq!(driven.stats.produced, n, "{}: every output", dut.name());
    }
    consumed
}

#[test]
fn tables_survive_resets_and_reload_between_batches() {
    for (variant, cfg) in configs::<ShaderConfig>() {
        let mut rng = ChaCha8Rng::seed_from_u64(seed(31));
        let traffic = Traffic::random(&mut rng, 0.2, 0.3);
        let mut gen = random_item(cfg);
        let mut batch = |rng: &mut ChaCha8Rng| (0..20_000).map(|_| gen(rng)).collect::<Vec<_>>();
        let tables = random_tables(&cfg, 32);
        let mut gold = shader(cfg, &tables);
        let mut dut = RtlStream::new(variant, cfg, 33).unwrap();
        for (addr, data) in tables.config_writes(&cfg) {
            dut.write_config(addr, &data).unwrap();
        }
        drive_and_compare(&mut dut, &mut gold, &batch(&mut rng), &traffic, None);

        // Reset with items in flight: they are lost, the tables are not.
        let items = batch(&mut rng);
        let consumed = drive_and_compare(&mut dut, &mut gold, &items, &traffic, Some(5_000));
        assert!(consumed > 0 && consumed < items.len());
        dut.reset();
        drive_and_compare(&mut dut, &mut gold, &items[consumed..], &traffic, None);
        dut.reset();
        dut.reset();
        drive_and_compare(&mut dut, &mut gold, &batch(&mut rng), &traffic, None);

        // Reload part of the tables (pipeline drained), including the zero-gradient entry; the
        // model takes the same writes through its own decoder of the address map.
        let other = random_tables(&cfg, 34).config_writes(&cfg);
        let mut written = 0;
        for (addr, data) in other.iter().filter(|_| rng.random_bool(0.3)) {
            dut.write_config(*addr, data).unwrap();
            assert!(gold.write_config(*addr, data));
            written += 1;
        }
        let (zero_addr, zero_data) = other.last().unwrap();
        dut.write_config(*zero_addr, zero_data).unwrap();
        gold.write_config(*zero_addr, zero_data);
        assert!(written > 100);
        drive_and_compare(&mut dut, &mut gold, &batch(&mut rng), &traffic, None);
        dut.reset();
        drive_and_compare(&mut dut, &mut gold, &batch(&mut rng), &traffic, None);
    }
}

#[test]
fn every_configuration_address_decodes_as_the_model() {
    for (i, (variant, cfg)) in configs::<ShaderConfig>().into_iter().enumerate() {
        let tables = random_tables(&cfg, 41 + i as u64);
        let mut gold = shader(cfg, &tables);
        let mut writes = tables.config_writes(&cfg);
        // Random writes over the whole address space: mapped ones change the tables, the rest
        // (region 3, offsets out of range, face 6 and 7, i or j beyond the grid) must not.
        let mut rng = ChaCha8Rng::seed_from_u64(seed(42));
        let words = cfg.cfg_data_w().div_ceil(32) as usize;
        let (mut mapped, mut unmapped) = (0, 0);
        for _ in 0..20_000 {
            let addr = rng.random_range(0..1u32 << cfg.cfg_addr_w());
            let mut data: Vec<u32> = (0..words).map(|_| rng.random()).collect();
            let pad = 32 * words as u32 - cfg.cfg_data_w();
            *data.last_mut().unwrap() &= u32::MAX >> pad;
            if gold.write_config(addr, &data) {
                mapped += 1;
            } else {
                unmapped += 1;
            }
            writes.push((addr, data));
        }
        assert!(
            mapped > 1000 && unmapped > 1000,
            "{mapped} mapped, {unmapped} unmapped"
        );
        let check = StreamCheck::new(seed(43), 100_000)
            .with_traffic(0.1, 0.1)
            .with_config_writes(writes);
        must_match(variant, cfg, &mut gold, &mut random_item(cfg), &check);
    }
}

/// Beyond trilin's scoreboard: a table that reaches the RTL different from the model's, in one
/// texel of each bank, one classification entry or the zero-gradient entry, is caught.
#[test]
fn a_table_entry_loaded_wrong_is_caught() {
    let (variant, cfg) = configs::<ShaderConfig>()[1];
    let tables = random_tables(&cfg, 51);
    let writes = tables.config_writes(&cfg);
    let find = |addr: u32| writes.iter().position(|w| w.0 == addr).unwrap();
    let side = cfg.rm_side();
    let mut cases = vec![
        (
            "classification entry 1234",
            find(cfg.class_addr(1234)),
            3 * cfg.color_w,
        ),
        ("zero-gradient entry", find(cfg.zero_addr()), cfg.diff_w - 1),
    ];
    for (i, j) in [(4, 4), (5, 4), (4, 5), (5, 5)] {
        cases.push(("a texel", find(cfg.texel_addr(3, i, j)), cfg.diff_w - 1));
    }
    assert_eq!(side, 9);
    for (what, at, bit) in cases {
        let mut bad = writes.clone();
        bad[at].1[(bit / 32) as usize] ^= 1 << (bit % 32);
        let mut check = StreamCheck::new(seed(52), 50_000)
            .with_traffic(0.1, 0.1)
            .with_config_writes(bad);
        check.waveform_on_mismatch = false;
        let err = expect_mismatch(
            check_stream(
                variant,
                cfg,
                &mut shader(cfg, &tables),
                &mut random_item(cfg),
                &check,
            ),
            "a wrong table entry must be caught",
        );
        assert!(err.to_string().contains("MISMATCH"), "{err}");
        eprintln!(
            "{what} (address {:#x}): caught at item {}",
            writes[at].0, err.item
        );
    }
}

#[test]
fn codec_and_config_port_are_checked_against_the_rtl() {
    assert_codec_and_config_port::<ShaderConfig>((0, &[1]), true);
}
