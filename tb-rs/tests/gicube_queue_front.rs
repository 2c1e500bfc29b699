//! Co-simulation of gicube_queue_front (the block processor's queue front end: arbiter,
//! bucketing, ray queues, sorter) against its cycle-accurate model `QueueFrontUnit`
//! (docs/numerics/gicube_queue_front.md): every processor cycle's active queue, flags, queues,
//! counts and both rays (handed to the pipeline, returned to the host) are compared. Plus the
//! conservation of rays under forced overflow, counted on the RTL's outputs and the model's, and
//! the processor model's own traffic of a frame replayed.

mod support;

use cube5_model::camera::Camera;
use cube5_model::phantom::head_phantom;
use cube5_model::unit::StreamUnit;
use cube5_model::units::gicube_processor::{Processor, ProcessorConfig, Projection};
use cube5_model::units::gicube_queue_front::{
    directed_items, position_in, with_start, FrontIn, FrontOut, FrontRay, FrontTrafficGen,
    QueueFrontConfig, QueueFrontUnit, OVERFLOW_BIT,
};
use cube5_model::units::gicube_ray_queues::Ray;
use cube5_tb::harness::{check_stream, StreamCheck};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;
use support::{
    configs, directed_on_every_config, expect_mismatch, gate_smoke_then_directed,
    million_across_a_reset, must_match_across_a_reset, must_match_items, random_items, seed,
};

fn traffic(cfg: QueueFrontConfig) -> impl FnMut(&mut ChaCha8Rng) -> FrontIn {
    let mut t = FrontTrafficGen::new(cfg);
    move |rng| t.next_item(rng)
}

/// Items a reset may drop: the one being processed and the output waiting.
const IN_FLIGHT: usize = 2;

#[test]
#[ignore = "sim-full: a million random processor cycles per configuration (four clocks each)"]
fn million_random_cycles_per_config_with_idle_backpressure_and_reset() {
    million_across_a_reset(QueueFrontUnit::new, traffic, 1700, 7, IN_FLIGHT);
}

#[test]
fn random_cycles_with_idle_backpressure_and_reset() {
    // CI's share of the million above; `take`, `ring` and `host` idle at random within the items
    // (the pipeline's back-pressure, the ring's and the host's idle), the stream idle and stalled.
    for (i, (variant, cfg)) in configs::<QueueFrontConfig>().into_iter().enumerate() {
        let s = seed(1710 + i as u64);
        let check = StreamCheck::long(s, 40_000, 1).with_batch(10_000);
        must_match_across_a_reset(
            variant,
            cfg,
            &mut QueueFrontUnit::new(cfg).unwrap(),
            &mut traffic(cfg),
            &check,
            IN_FLIGHT,
        );
    }
}

#[test]
fn directed_extremes_stay_move_overflow_and_host_slot() {
    directed_on_every_config(QueueFrontUnit::new, directed_items, |n| {
        StreamCheck::new(seed(1720), 3 * n).with_traffic(0.3, 0.3)
    });
}

/// Full speed: one processor cycle per four clocks (contract, "Timing"), outputs four clocks
/// apart, and a ray to the pipeline in every cycle whose active queue holds one.
#[test]
fn one_cycle_per_four_clocks_when_never_stalled() {
    for (variant, cfg) in configs::<QueueFrontConfig>() {
        let items = random_items(seed(1730), 50_000, traffic(cfg));
        let mut dut = RtlStream::new(variant, cfg, 1).unwrap();
        let n = items.len() as u64;
        let k = QueueFrontConfig::CLOCKS_PER_CYCLE;
        let driven = dut
            .drive(&items, &Traffic::full_speed(), n, 10 * k * n)
            .unwrap();
        assert_eq!(driven.stats.consumed, n, "{variant}: every item taken");
        assert_eq!(
            driven.stats.cycles,
            k * (n - 1) + cfg.latency() + 1,
            "{variant}: {k} clocks per processor cycle plus the latency"
        );
        for w in driven.outputs.windows(2) {
            assert_eq!(
                w[1].cycle - w[0].cycle,
                k,
                "{variant}: outputs {k} clocks apart"
            );
        }
        let want = QueueFrontUnit::new(cfg).unwrap().run(&items);
        let got: Vec<FrontOut> = driven.outputs.iter().map(|o| o.value).collect();
        assert!(
            got == want,
            "{variant}: the full-speed run matches the model"
        );
        let busy = got
            .iter()
            .zip(&items)
            .filter(|(o, i)| i.take && o.active)
            .count();
        let popped = got.iter().filter(|o| o.popped).count();
        assert_eq!(
            popped, busy,
            "{variant}: a ray per cycle with an active queue and take"
        );
        eprintln!(
            "{variant}: {n} cycles in {} clocks, {popped} rays to the pipeline",
            driven.stats.cycles
        );
    }
}

/// The scoreboard bites: a model whose sorter has two ranks fewer (another active queue now and
/// then, so other rays to the pipeline) is caught.
#[test]
fn a_model_with_fewer_sorter_ranks_is_caught() {
    let (variant, cfg) = configs::<QueueFrontConfig>()[0];
    let other = QueueFrontConfig {
        ranks: cfg.ranks - 2,
        ..cfg
    };
    let mut check = StreamCheck::new(seed(1770), 20_000).with_traffic(0.1, 0.1);
    check.waveform_on_mismatch = false;
    let err = expect_mismatch(
        check_stream(
            variant,
            cfg,
            &mut QueueFrontUnit::new(other).unwrap(),
            &mut traffic(cfg),
            &check,
        ),
        "a sorter of fewer ranks picks another active queue",
    );
    eprintln!(
        "{variant}: a model of {} ranks caught at item {}",
        other.ranks, err.item
    );
}

#[test]
fn gate_level_netlist_smoke() {
    gate_smoke_then_directed(QueueFrontUnit::new, traffic, directed_items, 1740);
}

/// A ray tagged `k` in its `u`, `v` bits (24 bits), random bits elsewhere, its `OVERFLOW` flag
/// random, at a random position in block `q`.
fn tagged(cfg: &QueueFrontConfig, k: u32, q: u32, rng: &mut ChaCha8Rng) -> Ray {
    let mut r: Ray = std::array::from_fn(|_| rng.random());
    r[0] = (r[0] & !0xff_ffff) | k;
    with_start(r, position_in(cfg, q, rng))
}

/// The tag of a ray (its `u`, `v` bits).
fn tag_of(r: &Ray) -> u32 {
    r[0] & 0xff_ffff
}

/// A ray with its `OVERFLOW` flag cleared (what the host sends again).
fn unflagged(mut r: Ray) -> Ray {
    r.set_overflow(false);
    r
}

/// All rays into one queue until it overflows: every ring ray and every host offer goes to one
/// block's queue, the pipeline takes now and then (the ring's rays arrive four times faster than
/// the queue drains), under idle and back-pressure; then the queues are drained. Counted on the
/// RTL's outputs and on the model's: rays in (ring pushes + host rays taken) = rays out (to the
/// pipeline) + rays overflowed (returned with `OVERFLOW` set); every ray that entered comes out
/// exactly once, unchanged but for its flag; and the run matches the model item for item.
#[test]
fn forced_overflow_into_one_queue_loses_no_ray() {
    for (variant, cfg) in configs::<QueueFrontConfig>() {
        let s = seed(1750);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let hot = cfg.vol_blocks.pow(3) / 2;
        let n = 20 * cfg.queue_len + 200;
        let mut items = Vec::new();
        let mut sent: HashMap<u32, Ray> = HashMap::new();
        for k in 0..n {
            // The ring's rays without OVERFLOW, the host's with it at random (taken: cleared).
            let (ring_ray, host_ray) = (
                unflagged(tagged(&cfg, 2 * k, hot, &mut rng)),
                tagged(&cfg, 2 * k + 1, hot, &mut rng),
            );
            sent.insert(2 * k, unflagged(ring_ray));
            sent.insert(2 * k + 1, unflagged(host_ray));
            items.push(FrontIn {
                take: rng.random_bool(0.25),
                ring: true,
                host: true,
                ring_ray,
                host_ray,
            });
        }
        let drain = (cfg.queues() * cfg.queue_len + 8) as usize;
        items.extend(std::iter::repeat_n(
            FrontIn {
                take: true,
                ..Default::default()
            },
            drain,
        ));
        let want = QueueFrontUnit::new(cfg).unwrap().run(&items);

        let mut dut = RtlStream::new(variant, cfg, s as u32).unwrap();
        let m = items.len() as u64;
        let out = dut
            .drive(&items, &Traffic::random(&mut rng, 0.2, 0.3), m, 40 * m)
            .unwrap();
        let got: Vec<FrontOut> = out.outputs.iter().map(|o| o.value).collect();
        assert_eq!(got.len(), items.len(), "{variant}: one output per item");
        for (who, outs) in [("RTL", &got), ("model", &want)] {
            let mut seen: HashMap<u32, u32> = HashMap::new();
            let (mut rays_in, mut rays_out, mut overflowed) = (0u64, 0u64, 0u64);
            for (i, o) in items.iter().zip(outs.iter()) {
                rays_in += u64::from(i.ring) + u64::from(o.host_taken);
                rays_out += u64::from(o.popped);
                overflowed += u64::from(o.ring_ovf);
                for (flag, ray, ovf) in
                    [(o.popped, o.pop_ray, false), (o.ring_ovf, o.ovf_ray, true)]
                {
                    if !flag {
                        continue;
                    }
                    let bit = ray[(OVERFLOW_BIT / 32) as usize] >> (OVERFLOW_BIT % 32) & 1;
                    assert_eq!(
                        bit == 1,
                        ovf,
                        "{who} {variant}: OVERFLOW set on returns only"
                    );
                    let k = tag_of(&ray);
                    assert_eq!(
                        sent.get(&k),
                        Some(&unflagged(ray)),
                        "{who} {variant}: ray {k} out unchanged"
                    );
                    *seen.entry(k).or_default() += 1;
                }
            }
            assert_eq!(
                outs.last().map(|o| o.total),
                Some(0),
                "{who} {variant}: drained"
            );
            assert_eq!(
                rays_in,
                rays_out + overflowed,
                "{who} {variant}: rays in = rays out + rays overflowed"
            );
            assert!(
                seen.values().all(|&c| c == 1),
                "{who} {variant}: each ray once"
            );
            assert_eq!(
                seen.len() as u64,
                rays_in,
                "{who} {variant}: every ray in came out"
            );
            assert!(
                overflowed * 2 > u64::from(n),
                "{who} {variant}: overflow forced"
            );
            eprintln!(
                "{who} {variant}: {rays_in} rays in = {rays_out} out + {overflowed} overflowed (seed {s})"
            );
        }
        assert!(
            got == want,
            "{variant}: the run matches the model item for item"
        );
        let check = StreamCheck::new(s, items.len()).with_traffic(0.2, 0.3);
        must_match_items(
            variant,
            cfg,
            &mut QueueFrontUnit::new(cfg).unwrap(),
            items,
            &check,
        );
    }
}

/// The processor model's own front-end traffic replayed on the RTL: the head phantom at the
/// configuration's volume side (`VolBlocks << BlockLog2`), rendered by `gicube_processor` with
/// the configuration's blocks, queue length and ranks; every processor cycle's input to its
/// queue front end (`render_front_traced`: take, the ring's ray, the host's offer) is one item,
/// with the packets as 256-bit rays, under idle and back-pressure. The RTL must match the model
/// item for item, and the replay must reproduce the frame's counts: one ray to the pipeline per
/// busy cycle, its overflows, the host's rays taken and its stalls.
#[test]
fn processor_frame_front_traffic_replays_on_the_rtl() {
    for (variant, cfg) in configs::<QueueFrontConfig>() {
        let side = (cfg.vol_blocks << cfg.block_log2) as usize;
        let vol = head_phantom(side, 12).unwrap();
        let (a, e) = (65f64.to_radians(), 20f64.to_radians());
        let dir = [-e.cos() * a.cos(), -e.cos() * a.sin(), -e.sin()];
        let px = (3 * side) as u32;
        let cam = Camera::new(dir.into(), vol.dims, vol.spacing, px, px);
        let tf = cube5_model::transfer::TransferFunction::head_default();
        let pcfg = ProcessorConfig {
            block_log2: cfg.block_log2,
            queue_len: cfg.queue_len,
            ranks: cfg.ranks,
            ..ProcessorConfig::DEFAULT
        };
        let proc = Processor::new(pcfg, &vol, &tf).unwrap();
        let (frame, traffic) = proc
            .render_front_traced(&cam, Projection::Parallel)
            .unwrap();
        let bits = |r: &cube5_model::units::gicube_packet_loop::RayPacket| r.to_bits().unwrap();
        let items: Vec<FrontIn> = traffic
            .iter()
            .map(|t| FrontIn {
                take: t.take,
                ring: t.ring.is_some(),
                host: t.host.is_some(),
                ring_ray: t.ring.as_ref().map(bits).unwrap_or_default(),
                host_ray: t.host.as_ref().map(bits).unwrap_or_default(),
            })
            .collect();
        let c = &frame.counts;
        assert_eq!(
            items.len() as u64,
            c.cycles,
            "{variant}: one item per cycle"
        );
        let outs = QueueFrontUnit::new(cfg).unwrap().run(&items);
        let count = |f: fn(&FrontOut) -> bool| outs.iter().filter(|o| f(o)).count() as u64;
        assert_eq!(
            count(|o| o.popped),
            c.samples + c.leaps,
            "{variant}: busy cycles"
        );
        assert_eq!(
            count(|o| o.ring_ovf),
            c.rays_overflowed,
            "{variant}: overflows"
        );
        assert_eq!(
            count(|o| o.host_taken),
            c.rays_in,
            "{variant}: host rays taken"
        );
        assert_eq!(
            count(|o| o.host_stall),
            c.host_stalls,
            "{variant}: host stalls"
        );
        assert!(
            c.rays_overflowed > 0,
            "{variant}: the frame overflowed some queue"
        );
        assert_eq!(outs.last().map(|o| o.total), Some(0), "{variant}: drained");
        let check = StreamCheck::new(seed(1760), items.len()).with_traffic(0.2, 0.3);
        let r = must_match_items(
            variant,
            cfg,
            &mut QueueFrontUnit::new(cfg).unwrap(),
            items,
            &check,
        );
        eprintln!(
            "{variant}: processor frame at {side}^3 ({} rays, {} overflowed, {} host stalls): {} cycles replayed in {} clocks",
            c.rays_made, c.rays_overflowed, c.host_stalls, r.compared, r.cycles
        );
    }
}
