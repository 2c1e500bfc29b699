//! Co-simulation of cube5_trilin against the golden model (docs/numerics.md).

mod support;

use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_trilin::{Trilin, TrilinConfig, TrilinIn, TrilinMode};
use cube5_tb::harness::{check_stream, StreamCheck};
use cube5_tb::rtl::RtlStream;
use cube5_tb::variants::{mutant_variants_of, variants_of};
use cube5_tb::{Mismatch, TbError, Variant};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use support::{
    assert_one_item_per_clock, configs, directed_on_every_config, expect_mismatch,
    gate_smoke_then_directed, million_across_a_reset, random_items, seed,
};

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
    million_across_a_reset(Trilin::new, random_item, 100, 3, 1000);
}

/// A random run that must mismatch (`why` it must): the mismatch reported.
fn random_run_mismatch(
    variant: &'static Variant,
    cfg: TrilinConfig,
    check: &StreamCheck,
    why: &str,
) -> Mismatch {
    let mut gold = Trilin::new(cfg).unwrap();
    let run = check_stream(variant, cfg, &mut gold, &mut random_item(cfg), check);
    expect_mismatch(run, why)
}

#[test]
fn directed_extremes() {
    directed_on_every_config(Trilin::new, directed_items, |_| {
        StreamCheck::directed(seed(7))
    });
}

/// One sample per clock, each configuration at its own latency (3, or 9 with `Pipe = 1`).
#[test]
fn one_sample_per_cycle_when_never_stalled() {
    for (variant, cfg) in configs::<TrilinConfig>() {
        let items = random_items(seed(11), 100_000, random_item(cfg));
        assert_one_item_per_clock(variant, cfg, &[], &items, cfg.latency());
    }
}

#[test]
fn gate_level_netlist_smoke() {
    gate_smoke_then_directed(Trilin::new, random_item, directed_items, 21);
}

/// The gate-level flow must be able to see a wrong netlist: the same smoke run on a netlist with
/// one inverted cell pin (Yosys `mutate`, variant flag `mutant`) has to mismatch.
#[test]
fn gate_level_netlist_with_a_seeded_fault_is_caught() {
    let mutants = mutant_variants_of(TrilinConfig::TOP);
    assert!(
        !mutants.is_empty(),
        "cube5_trilin.variants has a `mutant` line"
    );
    for variant in mutants {
        let cfg: TrilinConfig = variant.config().unwrap();
        let check = StreamCheck::new(seed(23), 30_000).with_traffic(0.2, 0.3);
        let err = random_run_mismatch(
            variant,
            cfg,
            &check,
            "the mutated netlist must mismatch the model",
        );
        eprintln!("seeded fault caught: {err}");
    }
}

#[test]
fn a_flipped_output_bit_is_reported_with_seed_inputs_outputs_and_waveform() {
    let (variant, cfg) = configs::<TrilinConfig>()[0];
    let mut check = StreamCheck::new(4242, 5_000).with_traffic(0.1, 0.1);
    check.corrupt = Some((1234, 3));
    check.waveform_on_mismatch = true;
    let err = random_run_mismatch(variant, cfg, &check, "a corrupted output must be caught");
    let m = &err;
    assert_eq!(m.item, 1234);
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
    let wave = m.waveform.as_ref().expect("a waveform is written");
    let vcd = std::fs::read_to_string(wave).unwrap();
    assert!(
        vcd.contains("out_data_o") && vcd.contains("#"),
        "VCD has the ports and time steps"
    );
    eprintln!("{report}");
}

#[test]
fn codec_and_variant_are_checked_against_the_rtl() {
    // The narrowest configuration opened with the widest codec: the port widths disagree.
    let all = configs::<TrilinConfig>();
    let (narrow, narrow_cfg) = *all.iter().min_by_key(|(_, c)| c.voxel_w).unwrap();
    let (_, wide_cfg) = *all.iter().max_by_key(|(_, c)| c.voxel_w).unwrap();
    match RtlStream::new(narrow, wide_cfg, 1) {
        Err(TbError::Setup { what, .. }) => {
            assert!(what.contains("in_data_i"), "names the port: {what}");
        }
        other => panic!("expected a width mismatch, got {:?}", other.err()),
    }
    let mut dut = RtlStream::new(narrow, narrow_cfg, 1).unwrap();
    assert!(
        dut.write_config(0, &[1]).is_err(),
        "trilin has no configuration port"
    );
    // Every variant of the table opens with the configuration built from its own parameters.
    for v in variants_of(TrilinConfig::TOP) {
        RtlStream::<TrilinConfig>::open(v, 1).unwrap();
    }
}
