//! Co-simulation of cube5_trilin against the golden model (docs/numerics.md).

mod support;

use cube5_model::trilin::{Trilin, TrilinConfig, TrilinIn, TrilinMode};
use cube5_tb::harness::{check_stream, StreamCheck};
use cube5_tb::rtl::{RtlError, RtlStream, Traffic};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use support::{must_match, seed, MILLION};

const CONFIGS: [(&str, TrilinConfig); 3] = [
    ("cube5_trilin_v8", TrilinConfig::NARROW),
    ("cube5_trilin_v12", TrilinConfig::DEFAULT),
    ("cube5_trilin_v16", TrilinConfig::WIDE),
];

fn random_item(cfg: TrilinConfig) -> impl FnMut(&mut ChaCha8Rng) -> TrilinIn {
    move |rng| TrilinIn {
        voxels: std::array::from_fn(|_| rng.random_range(0..=cfg.voxel_max())),
        weights: std::array::from_fn(|_| rng.random_range(0..=cfg.weight_max())),
        mode: TrilinMode::from_bits(rng.random_range(0..4)),
    }
}

/// Extremes: all 0, all max, weights 0 and max, alternating corners, every mode.
fn directed_items(cfg: TrilinConfig) -> Vec<TrilinIn> {
    let max = cfg.voxel_max();
    let wmax = cfg.weight_max();
    let half = 1 << (cfg.weight_w - 1);
    let voxel_sets: Vec<[u32; 8]> = vec![
        [0; 8],
        [max; 8],
        std::array::from_fn(|c| if c % 2 == 0 { 0 } else { max }),
        std::array::from_fn(|c| if c % 2 == 0 { max } else { 0 }),
        std::array::from_fn(|c| {
            if (c ^ (c >> 1) ^ (c >> 2)) & 1 == 0 {
                0
            } else {
                max
            }
        }),
        std::array::from_fn(|c| if c == 7 { max } else { 0 }),
        std::array::from_fn(|c| if c == 0 { max } else { 0 }),
    ];
    let weight_values = [0, 1, half - 1, half, half + 1, wmax - 1, wmax];
    let mut items = Vec::new();
    for voxels in &voxel_sets {
        for mode in [
            TrilinMode::Lerp,
            TrilinMode::Half,
            TrilinMode::Select,
            TrilinMode::Reserved,
        ] {
            for &wx in &weight_values {
                for &wy in &[0, half, wmax] {
                    for &wz in &[0, half - 1, wmax] {
                        items.push(TrilinIn {
                            voxels: *voxels,
                            weights: [wx, wy, wz],
                            mode,
                        });
                    }
                }
            }
        }
    }
    items
}

#[test]
fn million_random_samples_per_config_with_idle_backpressure_and_reset() {
    for (i, (variant, cfg)) in CONFIGS.iter().enumerate() {
        let check = StreamCheck::new(seed(100 + i as u64), MILLION)
            .with_traffic(0.2, 0.3)
            .with_reset_in_batch(3);
        let r = must_match(
            variant,
            *cfg,
            &mut Trilin::new(*cfg).unwrap(),
            &mut random_item(*cfg),
            &check,
        );
        assert_eq!(r.resets, 1);
        assert!(
            r.compared as usize >= MILLION - 1000,
            "a reset drops at most the items in flight"
        );
    }
}

#[test]
fn directed_extremes() {
    for (variant, cfg) in CONFIGS {
        let items = directed_items(cfg);
        let n = items.len();
        let mut it = items.into_iter().cycle();
        let check = StreamCheck::new(seed(7), n).with_traffic(0.3, 0.3);
        must_match(
            variant,
            cfg,
            &mut Trilin::new(cfg).unwrap(),
            &mut |_| it.next().unwrap(),
            &check,
        );
    }
}

#[test]
fn one_sample_per_cycle_when_never_stalled() {
    const LATENCY: u64 = 3;
    for (variant, cfg) in CONFIGS {
        let mut dut = RtlStream::new(variant, cfg, 1).unwrap();
        let mut rng = rand::SeedableRng::seed_from_u64(seed(11));
        let mut gen = random_item(cfg);
        let items: Vec<TrilinIn> = (0..100_000).map(|_| gen(&mut rng)).collect();
        let n = items.len() as u64;
        let driven = dut
            .drive(&items, &Traffic::full_speed(), n, 10 * n)
            .unwrap();
        assert_eq!(driven.stats.consumed, n);
        assert_eq!(
            driven.stats.cycles,
            n + LATENCY,
            "{variant}: one item per clock plus the pipeline fill"
        );
        let first = driven.outputs.first().unwrap().cycle;
        let last = driven.outputs.last().unwrap().cycle;
        assert_eq!(last - first + 1, n, "{variant}: outputs leave back to back");
    }
}

#[test]
fn gate_level_netlist_smoke() {
    let cfg = TrilinConfig::NARROW;
    let check = StreamCheck::new(seed(21), 30_000)
        .with_traffic(0.2, 0.2)
        .with_batch(10_000)
        .with_reset_in_batch(1);
    must_match(
        "cube5_trilin_v8_gate",
        cfg,
        &mut Trilin::new(cfg).unwrap(),
        &mut random_item(cfg),
        &check,
    );
    let items = directed_items(cfg);
    let n = items.len();
    let mut it = items.into_iter().cycle();
    let check = StreamCheck::new(seed(22), n).with_traffic(0.3, 0.3);
    must_match(
        "cube5_trilin_v8_gate",
        cfg,
        &mut Trilin::new(cfg).unwrap(),
        &mut |_| it.next().unwrap(),
        &check,
    );
}

#[test]
fn a_flipped_output_bit_is_reported_with_seed_inputs_outputs_and_waveform() {
    let cfg = TrilinConfig::DEFAULT;
    let mut check = StreamCheck::new(4242, 5_000).with_traffic(0.1, 0.1);
    check.corrupt = Some((1234, 3));
    check.waveform_on_mismatch = true;
    let err = check_stream(
        "cube5_trilin_v12",
        cfg,
        &mut Trilin::new(cfg).unwrap(),
        &mut random_item(cfg),
        &check,
    )
    .expect_err("a corrupted output must be caught");
    assert_eq!(err.item, 1234);
    let report = err.to_string();
    for needle in [
        "MISMATCH",
        "seed 4242",
        "item   #1234",
        "input  Some(TrilinIn",
        "rtl ",
        "model ",
        "CUBE5_SEED=4242",
    ] {
        assert!(
            report.contains(needle),
            "report lacks `{needle}`:\n{report}"
        );
    }
    let wave = err.waveform.as_ref().expect("a waveform is written");
    let vcd = std::fs::read_to_string(wave).unwrap();
    assert!(
        vcd.contains("out_data_o") && vcd.contains("#"),
        "VCD has the ports and time steps"
    );
    eprintln!("{report}");
}

#[test]
fn codec_and_variant_are_checked_against_the_rtl() {
    match RtlStream::new("cube5_trilin_v8", TrilinConfig::DEFAULT, 1) {
        Err(RtlError::WidthMismatch {
            port, rtl, model, ..
        }) => {
            assert_eq!((port, rtl, model), ("in_data_i", 84, 122));
        }
        other => panic!("expected a width mismatch, got {:?}", other.err()),
    }
    let mut dut = RtlStream::new("cube5_trilin_v8", TrilinConfig::NARROW, 1).unwrap();
    assert!(
        dut.write_config(0, &[1]).is_err(),
        "trilin has no configuration port"
    );
    assert!(matches!(
        RtlStream::new("cube5_trilin_nonexistent", TrilinConfig::DEFAULT, 1),
        Err(RtlError::NotBuilt { .. })
    ));
}
