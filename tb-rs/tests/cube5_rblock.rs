//! Co-simulation of cube5_rblock against the golden model (docs/numerics/rblock.md).

mod support;

use cube5_model::units::cube5_rblock::{BlockingLuts, RBlock, RBlockConfig, RBlockDir, RBlockIn};
use cube5_tb::harness::{check_stream, StreamCheck};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use support::{
    assert_codec_and_config_port, directed_on_every_config, expect_mismatch,
    gate_smoke_then_directed, million_across_a_reset, random_items_one_per_clock, seed,
    variant_with,
};

fn random_item(cfg: RBlockConfig) -> impl FnMut(&mut ChaCha8Rng) -> RBlockIn {
    move |rng| RBlockIn {
        value: rng.random_range(0..cfg.len()),
        dir: if rng.random_bool(0.5) {
            RBlockDir::ToBlocked
        } else {
            RBlockDir::ToLinear
        },
    }
}

/// Extremes: 0, all ones, single bits, each axis at its maximum alone, alternating patterns.
fn directed_items(cfg: RBlockConfig) -> Vec<RBlockIn> {
    let t = cfg.total_bits();
    let all = cfg.len() - 1;
    let mut values = vec![0, all, 0x5555_5555_5555 & all, 0xaaaa_aaaa_aaaa & all];
    values.extend((0..t).map(|b| 1u64 << b));
    values.extend((0..t).map(|b| all ^ (1u64 << b)));
    for axis in 0..3 {
        let mut c = [0u64; 3];
        c[axis] = (1u64 << cfg.bits()[axis]) - 1;
        values.push(cfg.linear(c));
        values.push(cfg.blocked_of(c));
    }
    let mut items = Vec::new();
    for v in values {
        for dir in [RBlockDir::ToBlocked, RBlockDir::ToLinear] {
            items.push(RBlockIn { value: v, dir });
        }
    }
    items
}

#[test]
fn million_random_conversions_per_config_with_idle_backpressure_and_reset() {
    million_across_a_reset(RBlock::new, random_item, 200, 3, 4);
}

#[test]
fn directed_extremes() {
    directed_on_every_config(RBlock::new, directed_items, |_| {
        StreamCheck::directed(seed(7))
    });
}

/// The whole `4^3` volume both ways on the RTL, checked against the patent's LUT form (not the
/// model's bit form) and the round trip.
#[test]
fn every_index_of_the_patent_example_matches_the_lut_form() {
    let cfg = RBlockConfig::NARROW;
    let luts = BlockingLuts::new(cfg, 3).unwrap();
    let mut dut = RtlStream::new(variant_with(cfg), cfg, 3).unwrap();
    let mut items: Vec<RBlockIn> = (0..cfg.len())
        .map(|v| RBlockIn {
            value: v,
            dir: RBlockDir::ToBlocked,
        })
        .collect();
    items.extend((0..cfg.len()).map(|v| RBlockIn {
        value: v,
        dir: RBlockDir::ToLinear,
    }));
    let n = items.len() as u64;
    let out = dut.drive(&items, &Traffic::full_speed(), n, 4 * n).unwrap();
    let got: Vec<u64> = out.outputs.iter().map(|t| t.value).collect();
    let half = cfg.len() as usize;
    for v in 0..cfg.len() {
        let o = got[v as usize];
        assert_eq!(o, luts.to_blocked(v), "linear {v}");
        assert_eq!(got[half + o as usize], v, "round trip of {v}");
        assert_eq!(got[half + v as usize], luts.to_linear(v), "offset {v}");
    }
    // The patent's worked example [450]: (3, 1, 1) <-> 15.
    assert_eq!(got[cfg.linear([3, 1, 1]) as usize], 15);
}

#[test]
fn one_conversion_per_cycle_when_never_stalled() {
    random_items_one_per_clock(random_item, 11, 1);
}

#[test]
fn gate_level_netlist_smoke() {
    gate_smoke_then_directed(RBlock::new, random_item, directed_items, 21);
}

/// The comparison tells the interleave orders apart: a model that interleaves z, y, x (the mirror
/// order, also a valid recursive blocking) differs from the contract's x, y, z on the first item
/// that has two different low coordinate bits.
#[test]
fn the_comparison_tells_interleave_orders_apart() {
    struct MirrorOrder(RBlockConfig);
    impl cube5_model::unit::StreamUnit for MirrorOrder {
        type In = RBlockIn;
        type Out = u64;
        fn run(&mut self, inputs: &[RBlockIn]) -> Vec<u64> {
            // Swap the roles of x and z: convert (z, y, x) with the contract's map.
            let c = self.0;
            let swapped = RBlockConfig::new(c.z_bits, c.y_bits, c.x_bits).unwrap();
            inputs
                .iter()
                .map(|i| match i.dir {
                    RBlockDir::ToBlocked => {
                        let [x, y, z] = c.coords(i.value);
                        swapped.blocked_of([z, y, x])
                    }
                    RBlockDir::ToLinear => {
                        let [z, y, x] = swapped.coords_of_blocked(i.value);
                        c.linear([x, y, z])
                    }
                })
                .collect()
        }
    }
    let cfg = RBlockConfig::DEFAULT;
    let mut check = StreamCheck::new(4242, 1000).with_traffic(0.1, 0.1);
    check.waveform_on_mismatch = false;
    let err = expect_mismatch(
        check_stream(
            variant_with(cfg),
            cfg,
            &mut MirrorOrder(cfg),
            &mut random_item(cfg),
            &check,
        ),
        "the mirror interleave order must be caught",
    );
    assert!(err.item < 10, "caught at once: {err}");
}

#[test]
fn codec_is_checked_against_the_rtl() {
    assert_codec_and_config_port::<RBlockConfig>((0, &[1]), false);
}
