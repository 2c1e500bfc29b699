//! Co-simulation of gicube_step (step, leap and advance) against the golden model `Stepper`
//! (docs/numerics/gicube_step.md).

mod support;

use cube5_model::units::gicube_bucket::{BucketConfig, BucketUnit, Distribution, Position};
use cube5_model::units::gicube_packet_loop::{POS_FRAC_W, POS_W};
use cube5_model::units::gicube_step::{random_step_in, StepConfig, StepIn, Stepper};
use cube5_tb::harness::{check_stream, StreamCheck};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::{
    assert_one_item_per_clock, configs, directed_on_every_config, expect_mismatch,
    gate_smoke_then_directed, million_across_a_reset, must_match_across_a_reset, random_items,
    seed, variant_with,
};

fn random_item(cfg: StepConfig) -> impl FnMut(&mut ChaCha8Rng) -> StepIn {
    move |rng| random_step_in(rng, &cfg)
}

/// Items in flight that a reset may drop: the pipeline's stages plus the handshake's slack.
fn in_flight(cfg: StepConfig) -> usize {
    cfg.latency() as usize + 2
}

/// The queue of `start` (slab, one processor), as the processor keeps it; 0 outside.
fn queue_of(cfg: StepConfig, start: [u32; 3]) -> u32 {
    let b = BucketUnit::new(BucketConfig {
        block_log2: cfg.block_log2,
        vol_blocks: cfg.vol_blocks,
        proc_log2: 0,
        dist: Distribution::Slab,
        lanes: 1,
    })
    .unwrap()
    .bucket(Position(start));
    if b.outside {
        0
    } else {
        b.queue
    }
}

/// The extremes: starts on the low and high raw position of a block (the first and last block,
/// the domain's faces, the largest `U(12.8)`), directions `-2.0`, `2.0 - 2^-14`, `+-1.0`, the
/// smallest that moves one raw unit a step (the longest leap, `k = n 256`), the largest that
/// rounds to 0, along one axis and along the diagonal, each with and without a leap.
fn directed_items(cfg: StepConfig) -> Vec<StepIn> {
    let blk = 1u32 << (cfg.block_log2 + POS_FRAC_W);
    let limit = (cfg.vol_blocks << cfg.block_log2) << POS_FRAC_W;
    let top = (1u32 << POS_W) - 1;
    let mut coords = vec![0, 1, blk - 1, blk, limit - blk, limit - 1, limit, top];
    if cfg.vol_blocks > 2 {
        coords.extend([blk * (cfg.vol_blocks / 2), blk * (cfg.vol_blocks / 2) - 1]);
    }
    coords.retain(|&c| c <= top);
    // dir with delta = +1 raw: the smallest dir with dir * dr >= 2^13.
    let one = 8192u32.div_ceil(cfg.step) as i16;
    let zero = one - 1; // rounds to 0 (and its negative rounds to 0 too)
    let mags: [i16; 8] = [i16::MIN, i16::MAX, 16384, -16384, one, -one, zero, -zero];
    let mut items = Vec::new();
    for (i, &c) in coords.iter().enumerate() {
        let other = coords[(i * 3 + 1) % coords.len()];
        for &d in &mags {
            for leap in [false, true] {
                for axis in 0..3 {
                    let mut start = [other; 3];
                    start[axis] = c;
                    let mut dir = [0i16; 3];
                    dir[axis] = d;
                    items.push(StepIn {
                        start,
                        dir,
                        queue: queue_of(cfg, start),
                        leap,
                    });
                }
                let start = [c; 3];
                items.push(StepIn {
                    start,
                    dir: [d, d, d],
                    queue: queue_of(cfg, start),
                    leap,
                });
                items.push(StepIn {
                    start,
                    dir: [d, -d, d / 3],
                    queue: queue_of(cfg, start),
                    leap,
                });
            }
        }
    }
    // No axis moves; the largest queue number.
    items.push(StepIn {
        start: [5, 5, 5],
        dir: [0, 0, 0],
        queue: (1 << cfg.queue_w()) - 1,
        leap: true,
    });
    items
}

#[test]
#[ignore = "sim-full: a million rays per configuration with idle, back-pressure and a reset"]
fn million_random_rays_per_config_with_idle_backpressure_and_reset() {
    million_across_a_reset(Stepper::new, random_item, 1500, 5, 32);
}

#[test]
fn random_rays_with_idle_backpressure_and_reset() {
    // CI's share of the million above.
    for (i, (variant, cfg)) in configs::<StepConfig>().into_iter().enumerate() {
        let check = StreamCheck::long(seed(1510 + i as u64), 40_000, 0).with_batch(10_000);
        must_match_across_a_reset(
            variant,
            cfg,
            &mut Stepper::new(cfg).unwrap(),
            &mut random_item(cfg),
            &check,
            in_flight(cfg),
        );
    }
}

#[test]
fn directed_block_faces_domain_edges_and_extreme_directions() {
    directed_on_every_config(Stepper::new, directed_items, |n| {
        assert!(n > 300);
        StreamCheck::directed(seed(1520))
    });
}

#[test]
fn one_ray_per_clock_leaping_or_not() {
    for (variant, cfg) in configs::<StepConfig>() {
        let mut gen = random_item(cfg);
        let items = random_items(seed(1530), 50_000, |rng| {
            let mut it = gen(rng);
            it.leap = rng.random_bool(0.5);
            it
        });
        let out = assert_one_item_per_clock(variant, cfg, &[], &items, cfg.latency());
        let model = Stepper::new(cfg).unwrap();
        for (i, (it, o)) in items.iter().zip(&out.outputs).enumerate() {
            assert_eq!(
                o.value,
                model.step(it.start, it.dir, it.queue, it.leap),
                "{variant}: item {i} {it:?}"
            );
        }
        let leaps = out.outputs.iter().filter(|o| o.value.k > 1).count();
        assert!(leaps > 5_000, "{variant}: leaps at full speed ({leaps})");
    }
}

#[test]
fn gate_level_netlist_smoke() {
    gate_smoke_then_directed(Stepper::new, random_item, directed_items, 1540);
}

#[test]
fn a_model_with_another_step_is_caught() {
    // Same widths, dr one raw unit longer: the scoreboard must see it within a few rays.
    let (variant, cfg) = configs::<StepConfig>()[0];
    let other = StepConfig {
        step: cfg.step + 1,
        ..cfg
    };
    let mut check = StreamCheck::new(seed(1550), 5_000).with_traffic(0.1, 0.1);
    check.waveform_on_mismatch = false;
    let err = expect_mismatch(
        check_stream(
            variant_with(cfg),
            cfg,
            &mut Stepper::new(other).unwrap(),
            &mut random_item(cfg),
            &check,
        ),
        "a different dr changes delta",
    );
    assert!(err.item < 100, "{variant}: caught at item {}", err.item);
}

#[test]
fn the_longest_leap_crosses_a_whole_block() {
    // delta = +1 raw from the first raw position of block 0: k = n 256 on the RTL.
    for (variant, cfg) in configs::<StepConfig>() {
        let one = 8192u32.div_ceil(cfg.step) as i16;
        let model = Stepper::new(cfg).unwrap();
        assert_eq!(model.delta([one, 0, 0]), [1, 0, 0]);
        let mut rng = ChaCha8Rng::seed_from_u64(seed(1560));
        let items: Vec<StepIn> = (0..64)
            .map(|_| StepIn {
                start: [0, rng.random_range(0..256), 0],
                dir: [one, 0, 0],
                queue: 0,
                leap: true,
            })
            .collect();
        let mut dut = cube5_tb::rtl::RtlStream::new(variant, cfg, 1).unwrap();
        let out = dut
            .drive(&items, &cube5_tb::rtl::Traffic::full_speed(), 64, 10_000)
            .unwrap();
        for o in &out.outputs {
            assert_eq!(o.value.k, 1 << (cfg.block_log2 + 8), "{variant}");
        }
    }
}
