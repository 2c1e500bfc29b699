//! Co-simulation of cube5_trilin against the golden model (docs/numerics.md).

mod support;

use cube5_model::units::cube5_trilin::{Trilin, TrilinConfig, TrilinIn, TrilinMode};
use cube5_tb::harness::{check_stream, StreamCheck};
use cube5_tb::rtl::{RtlError, RtlStream};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use support::{
    assert_one_item_per_clock, gate_smoke, long_run, must_match_across_a_reset, must_match_items,
    random_items, seed, MILLION,
};

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
        must_match_across_a_reset(
            variant,
            *cfg,
            &mut Trilin::new(*cfg).unwrap(),
            &mut random_item(*cfg),
            &long_run(seed(100 + i as u64), MILLION, 3),
            1000,
        );
    }
}

#[test]
fn directed_extremes() {
    for (variant, cfg) in CONFIGS {
        let mut gold = Trilin::new(cfg).unwrap();
        must_match_items(variant, cfg, &mut gold, directed_items(cfg), seed(7));
    }
}

#[test]
fn one_sample_per_cycle_when_never_stalled() {
    const LATENCY: u64 = 3;
    for (variant, cfg) in CONFIGS {
        let items = random_items(seed(11), 100_000, random_item(cfg));
        assert_one_item_per_clock(variant, cfg, &items, LATENCY);
    }
}

#[test]
fn gate_level_netlist_smoke() {
    let (variant, cfg) = ("cube5_trilin_v8_gate", TrilinConfig::NARROW);
    let mut gold = Trilin::new(cfg).unwrap();
    gate_smoke(variant, cfg, &mut gold, &mut random_item(cfg), seed(21));
    let mut gold = Trilin::new(cfg).unwrap();
    must_match_items(variant, cfg, &mut gold, directed_items(cfg), seed(22));
}

/// The gate-level flow must be able to see a wrong netlist: the same smoke run on a netlist with
/// one inverted cell pin (Yosys `mutate`, variant flag `mutant`) has to mismatch.
#[test]
fn gate_level_netlist_with_a_seeded_fault_is_caught() {
    let (variant, cfg) = ("cube5_trilin_v8_mutant", TrilinConfig::NARROW);
    let check = StreamCheck::new(seed(23), 30_000).with_traffic(0.2, 0.3);
    let err = check_stream(
        variant,
        cfg,
        &mut Trilin::new(cfg).unwrap(),
        &mut random_item(cfg),
        &check,
    )
    .expect_err("the mutated netlist must mismatch the model");
    assert_ne!(err.item, u64::MAX, "the mutant did not run: {err}");
    eprintln!("seeded fault caught: {err}");
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
