//! Co-simulation of gicube_ray_queues against its cycle-accurate model
//! (docs/numerics/gicube_ray_queues.md): every item's flags, the two queues' counts, the total
//! and both rays (dequeued, overflowed) are compared after every item. Plus the conservation of
//! rays under forced overflow, counted on the RTL's own outputs.

mod support;

use cube5_model::camera::Camera;
use cube5_model::phantom::head_phantom;
use cube5_model::transfer::TransferFunction;
use cube5_model::unit::StreamUnit;
use cube5_model::units::gicube_packet_loop::PACKET_BITS;
use cube5_model::units::gicube_processor::{Processor, ProcessorConfig, Projection, QueueOp};
use cube5_model::units::gicube_ray_queues::{
    directed_items, QueueTraffic, QueuesIn, Ray, RayQueuesConfig, RayQueuesUnit,
};
use cube5_tb::harness::StreamCheck;
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;
use support::{
    configs, directed_on_every_config, gate_smoke_then_directed, million_across_a_reset,
    must_match_items, random_items_one_per_clock, seed,
};

fn traffic(cfg: RayQueuesConfig) -> impl FnMut(&mut ChaCha8Rng) -> QueuesIn {
    let mut t = QueueTraffic::new(cfg);
    move |rng| t.next_item(rng)
}

#[test]
fn million_random_items_per_config_with_idle_backpressure_and_reset() {
    million_across_a_reset(RayQueuesUnit::new, traffic, 620, 7, 2);
}

#[test]
fn directed_extremes_full_empty_wrap_and_same_queue() {
    directed_on_every_config(RayQueuesUnit::new, directed_items, |n| {
        StreamCheck::new(seed(630), 3 * n).with_traffic(0.3, 0.3)
    });
}

#[test]
fn one_item_per_clock_when_never_stalled() {
    random_items_one_per_clock(traffic, 640, RayQueuesConfig::DEFAULT.latency());
}

#[test]
fn gate_level_netlist_smoke() {
    gate_smoke_then_directed(RayQueuesUnit::new, traffic, directed_items, 650);
}

/// A ray tagged `k` (`k < 2^DataW`): the tag is the first word, random words above it.
fn tagged(cfg: RayQueuesConfig, k: u32, rng: &mut ChaCha8Rng) -> Ray {
    let mut r: Ray = std::array::from_fn(|_| rng.random());
    r[0] = k;
    cfg.mask(r)
}

/// Overflow forced: bursts of pushes into three queues (four times what they hold), pops of one
/// of them now and then, under idle and back-pressure; then every queue drained. On the RTL's own
/// outputs: rays in (pushes offered) = rays dequeued + rays overflowed, every ray (a unique tag)
/// comes out exactly once, either dequeued or returned, unchanged; and the run matches the model
/// item for item.
#[test]
fn forced_overflow_loses_no_ray() {
    for (variant, cfg) in configs::<RayQueuesConfig>() {
        let s = seed(660);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let nq = cfg.queues();
        let rays = (4 * 3 * cfg.queue_len).min(1 << cfg.data_w.min(20));
        let hot: [u32; 3] = std::array::from_fn(|i| (i as u32 * 5 + 1) % nq);
        let mut items = Vec::new();
        let mut sent: HashMap<Ray, u32> = HashMap::new();
        for k in 0..rays {
            let data = tagged(cfg, k, &mut rng);
            sent.insert(data, k);
            let pop = rng.random_bool(0.1);
            items.push(QueuesIn {
                pop,
                pop_q: hot[0],
                push: true,
                push_q: hot[rng.random_range(0..3)],
                data,
            });
        }
        for q in 0..nq {
            items.extend((0..=cfg.queue_len).map(|_| QueuesIn {
                pop: true,
                pop_q: q,
                ..Default::default()
            }));
        }
        assert_eq!(sent.len() as u32, rays, "{variant}: unique tags");

        let mut dut = RtlStream::new(variant, cfg, s as u32).unwrap();
        let n = items.len() as u64;
        let out = dut
            .drive(&items, &Traffic::random(&mut rng, 0.2, 0.3), n, 20 * n)
            .unwrap();
        assert_eq!(
            out.outputs.len(),
            items.len(),
            "{variant}: one output per item"
        );
        let mut seen = vec![0u32; rays as usize];
        let (mut dequeued, mut overflowed) = (0u64, 0u64);
        for o in &out.outputs {
            let o = &o.value;
            for (flag, data) in [(o.popped, o.pop_data), (o.overflow, o.ovf_data)] {
                if flag {
                    let k = sent.get(&data).unwrap_or_else(|| {
                        panic!("{variant}: a ray that was never sent: {data:x?}")
                    });
                    seen[*k as usize] += 1;
                }
            }
            dequeued += u64::from(o.popped);
            overflowed += u64::from(o.overflow);
        }
        let last = out.outputs.last().unwrap().value;
        assert_eq!(last.total, 0, "{variant}: every queue drained");
        assert_eq!(
            u64::from(rays),
            dequeued + overflowed,
            "{variant}: rays in = rays dequeued + rays overflowed"
        );
        assert!(
            seen.iter().all(|&c| c == 1),
            "{variant}: every ray out exactly once"
        );
        assert!(
            overflowed * 4 > u64::from(rays),
            "{variant}: the test forced overflow ({overflowed} of {rays})"
        );
        eprintln!(
            "{variant}: {rays} rays in = {dequeued} dequeued + {overflowed} overflowed (seed {s})"
        );
        // The same items against the model, item for item.
        let check = StreamCheck::new(s, items.len()).with_traffic(0.2, 0.3);
        must_match_items(
            variant,
            cfg,
            &mut RayQueuesUnit::new(cfg).unwrap(),
            items,
            &check,
        );
    }
}

/// The processor model's own queue traffic replayed on the RTL: the head phantom at 32^3 (blocks
/// of 8: 64 queues) rendered by `gicube_processor` with queues of the RTL's `QueueLen`, every pop
/// and push its frame loop made (`render_traced`) sent as one item each, with the packets as the
/// 256-bit rays, under idle and back-pressure. The RTL must match the model item for item, and the
/// replay must reproduce the frame's counts: one pop per busy cycle, the rays it overflowed.
#[test]
fn processor_frame_queue_traffic_replays_on_the_rtl() {
    let vol = head_phantom(32, 12).unwrap();
    let (a, e) = (65f64.to_radians(), 20f64.to_radians());
    let dir = [-e.cos() * a.cos(), -e.cos() * a.sin(), -e.sin()];
    let cam = Camera::new(dir.into(), vol.dims, vol.spacing, 96, 96);
    let tf = TransferFunction::head_default();
    let fit = configs::<RayQueuesConfig>()
        .into_iter()
        .filter(|(_, c)| c.data_w == PACKET_BITS && c.queues() >= 64);
    let mut ran = 0;
    for (variant, cfg) in fit {
        let pcfg = ProcessorConfig {
            block_log2: 3,
            queue_len: cfg.queue_len,
            ..ProcessorConfig::DEFAULT
        };
        let proc = Processor::new(pcfg, &vol, &tf).unwrap();
        let (frame, ops) = proc.render_traced(&cam, Projection::Parallel).unwrap();
        let items: Vec<QueuesIn> = ops
            .iter()
            .map(|op| match *op {
                QueueOp::Pop(q) => QueuesIn {
                    pop: true,
                    pop_q: q,
                    ..Default::default()
                },
                QueueOp::Push(q, ray) => QueuesIn {
                    push: true,
                    push_q: q,
                    data: ray.to_bits().unwrap(),
                    ..Default::default()
                },
            })
            .collect();
        let outs = RayQueuesUnit::new(cfg).unwrap().run(&items);
        let c = &frame.counts;
        let pops = outs.iter().filter(|o| o.popped).count() as u64;
        let ovf = outs.iter().filter(|o| o.overflow).count() as u64;
        assert_eq!(
            pops,
            c.samples + c.leaps,
            "{variant}: one ray per busy cycle"
        );
        assert_eq!(ovf, c.rays_overflowed, "{variant}: the frame's overflows");
        assert!(ovf > 0, "{variant}: the frame overflowed some queue");
        assert_eq!(outs.last().map(|o| o.total), Some(0), "{variant}: drained");
        let check = StreamCheck::new(seed(670), items.len()).with_traffic(0.2, 0.3);
        let r = must_match_items(
            variant,
            cfg,
            &mut RayQueuesUnit::new(cfg).unwrap(),
            items,
            &check,
        );
        eprintln!(
            "{variant}: processor frame ({} rays, {} overflowed, {} cycles): {} queue items replayed",
            c.rays_made, c.rays_overflowed, c.cycles, r.compared
        );
        ran += 1;
    }
    assert!(
        ran > 0,
        "a configuration that holds the packet and 64 queues"
    );
}
