//! The processor's acceptance run (docs/adding-a-unit.md, issue 15): a million random ray
//! packets per configuration through gicube_processor, each frame a new random scene (volume and
//! transfer function, mostly empty so that most rays leap) and a new random host: camera frames
//! (parallel and perspective, random view, field of view and size) and frames of packets with
//! random starts anywhere in the volume and random directions (axis-aligned ones among them),
//! under random memory latency, gaps and bandwidth limits, random output back-pressure and, in a
//! quarter of the frames, a host idle at random; one frame per configuration across a reset.
//!
//! Every frame against `Processor::run_packets_traced` at the RTL's configuration: with the host
//! never idle (the model's cycle order), every ray that left the processor, finished or
//! overflowed, bit for bit and in order, every count and the AR bursts; with the host idle (another
//! order), every finished ray's packet bit for bit but for the OVERFLOW flag, the image, samples
//! and leaps. Every frame: rays in = finished + overflowed, by the RTL and by the model.

mod support;

use cube5_model::transfer::{TfPoint, TransferFunction};
use cube5_model::units::gicube_packet_loop::RayPacket;
use cube5_model::units::gicube_processor::{HostOrder, Processor, ProcessorRtlConfig};
use cube5_model::volume::Volume;
use cube5_tb::Variant;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;
use support::processor::{
    check_bursts, check_frame, open_proc, random_memory, run_host, Behaviour, Bits, Memory,
    RandomRays,
};
use support::{axi, configs, seed};

/// A random volume of side `n`: empty (three in ten: every block leapt), dense noise (one in
/// twenty: early termination), or one or two balls of random density and radius up to `n / 5` in
/// an empty volume (most blocks leapt).
fn random_volume(rng: &mut ChaCha8Rng, n: usize, bits: u32) -> Volume {
    let max = (1u32 << bits) - 1;
    let kind = rng.random_range(0..20);
    let mut data = vec![0u16; n * n * n];
    match kind {
        0..=5 => {}
        6 => data
            .iter_mut()
            .for_each(|v| *v = rng.random_range(max / 2..=max) as u16),
        _ => {
            for _ in 0..rng.random_range(1..=2) {
                let c: [f64; 3] = std::array::from_fn(|_| rng.random_range(0.0..n as f64));
                let r = rng.random_range(0.5..n as f64 / 5.0);
                let d = rng.random_range(max / 3..=max);
                for (i, v) in data.iter_mut().enumerate() {
                    let p = [i % n, (i / n) % n, i / (n * n)].map(|a| a as f64);
                    let dist = (0..3).map(|a| (p[a] - c[a]).powi(2)).sum::<f64>().sqrt();
                    if dist <= r {
                        *v = (*v).max(d as u16);
                    }
                }
            }
        }
    }
    Volume::new([n; 3], [1.0; 3], bits, data).unwrap()
}

/// A random transfer function: transparent below a random threshold (empty blocks leap), then
/// a random colour and opacity.
fn random_tf(rng: &mut ChaCha8Rng) -> TransferFunction {
    let t0 = rng.random_range(0.05..0.5);
    let t1 = rng.random_range(t0..1.0);
    let mut rgba = || -> [f64; 4] {
        [
            rng.random_range(0.0..=1.0),
            rng.random_range(0.0..=1.0),
            rng.random_range(0.0..=1.0),
            rng.random_range(0.02..=1.0),
        ]
    };
    let (a, b) = (rgba(), rgba());
    TransferFunction::new(vec![
        TfPoint {
            density: 0.0,
            rgba: [0.0; 4],
        },
        TfPoint {
            density: t0,
            rgba: [0.0; 4],
        },
        TfPoint {
            density: t1,
            rgba: a,
        },
        TfPoint {
            density: 1.0,
            rgba: b,
        },
    ])
    .unwrap()
}

/// A random unit direction; one in eight along an axis, one in eight in a coordinate plane.
fn random_dir(rng: &mut ChaCha8Rng) -> [f64; 3] {
    let sign = |rng: &mut ChaCha8Rng| if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    let mut d = [0.0f64; 3];
    match rng.random_range(0..8) {
        0 => d[rng.random_range(0..3)] = sign(rng),
        1 => {
            let a = rng.random_range(0..3);
            d[a] = rng.random_range(-1.0..1.0);
            d[(a + 1) % 3] = sign(rng) * rng.random_range(0.1..1.0);
        }
        _ => loop {
            d = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
            let l = d.iter().map(|c| c * c).sum::<f64>().sqrt();
            if (0.1..1.0).contains(&l) {
                break;
            }
        },
    }
    let l = d.iter().map(|c| c * c).sum::<f64>().sqrt();
    d.map(|c| c / l)
}

/// The host's rays of one frame: a camera's (8-48 pixels a side, fields of view 10-150 degrees)
/// or 256-4,096 random packets, in directions from `random_dir`.
const RAYS: RandomRays = RandomRays {
    px: 8..=48,
    fov_deg: 10.0..150.0,
    packets: 256..=4096,
    dir: random_dir,
};

/// A ray's packet without the OVERFLOW flag (the one field the order may change).
fn unflagged(bits: &Bits) -> RayPacket {
    let mut r = RayPacket::from_bits(bits);
    r.flags &= !4;
    r
}

/// The totals of one configuration's run.
#[derive(Default, Debug)]
struct Totals {
    frames: u64,
    rays: u64,
    packets_in: u64,
    finished: u64,
    overflowed: u64,
    samples: u64,
    leaps: u64,
    clocks: u64,
    idle_frames: u64,
}

/// One random frame (seed `s`): the model, then the RTL; `reset`: the frame is cut at a random
/// clock first, the processor reset (nothing may stay in flight), and run again from the start.
fn random_frame(
    variant: &'static Variant,
    rtl: ProcessorRtlConfig,
    s: u64,
    reset: bool,
    t: &mut Totals,
) {
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let n = rtl.side() as usize;
    let vol = random_volume(&mut rng, n, rtl.voxel_w);
    let tf = random_tf(&mut rng);
    let proc = Processor::new(rtl.processor_config(), &vol, &tf).unwrap();
    let order = if rng.random_bool(0.5) {
        HostOrder::RowMajor
    } else {
        HostOrder::Reversed
    };
    let (packets, (w, h), kind) = RAYS.draw(&mut rng, &vol, Some(order));
    if packets.is_empty() {
        return;
    }
    let bits: Vec<Bits> = packets.iter().map(|p| p.to_bits().unwrap()).collect();
    let (want, trace) = proc.run_packets_traced(packets, w, h).unwrap();
    let mem = match rng.random_range(0..8) {
        0 => random_memory(&mut rng, &rtl),
        _ => Memory {
            lat: (rng.random_range(1..10), rng.random_range(0..20)),
            gaps: (rng.random_range(0..300), rng.random_range(0..300)),
            bw: axi::random_bandwidth(&mut rng, rtl.data_w / 8),
        },
    };
    let idle = if rng.random_range(0..4) == 0 {
        rng.random_range(0.1..0.6)
    } else {
        0.0
    };
    let b = Behaviour {
        idle,
        stall: rng.random_range(0.0..0.6),
    };
    let what = format!("{variant} seed {s} ({kind}, {mem:?}, {b:?})");
    let mut dut = open_proc(variant, rtl, &proc, mem, s);
    if reset {
        let cut = rng.random_range(1..=3 * want.counts.cycles.max(1));
        let part = run_host(&mut dut, &bits, (w, h), b, &mut rng, Some(cut), &what);
        let dropped = axi::reset_leaves_nothing_in_flight(&mut dut, variant, s, false).unwrap();
        eprintln!(
            "{what}: reset after {} clocks, {} of {} rays finished, {} overflowed, {} bursts dropped",
            part.clocks,
            part.last.rays_finished,
            want.counts.rays_made,
            part.last.rays_overflowed,
            dropped
        );
    }
    let got = run_host(&mut dut, &bits, (w, h), b, &mut rng, None, &what);
    let exact = idle == 0.0;
    check_frame(&what, &got, &want, exact);
    let model: Vec<(bool, Bits)> = trace
        .outputs
        .iter()
        .map(|(d, r)| (*d, r.to_bits().unwrap()))
        .collect();
    if exact {
        assert_eq!(got.rays.len(), model.len(), "{what}: outputs");
        for (k, (g, m)) in got.rays.iter().zip(&model).enumerate() {
            assert_eq!(g, m, "{what}: output #{k} (finished, ray bits) differs");
        }
        check_bursts(variant, &rtl, &got, &trace.reads, s);
    } else {
        let key = |r: &RayPacket| (r.v, r.u);
        let mut g: Vec<RayPacket> = got
            .rays
            .iter()
            .filter(|(d, _)| *d)
            .map(|(_, r)| unflagged(r))
            .collect();
        let mut m: Vec<RayPacket> = model
            .iter()
            .filter(|(d, _)| *d)
            .map(|(_, r)| unflagged(r))
            .collect();
        g.sort_by_key(key);
        m.sort_by_key(key);
        assert_eq!(g.len(), m.len(), "{what}: finished rays");
        for (a, b) in g.iter().zip(&m) {
            assert_eq!(a, b, "{what}: a finished ray differs from the model's");
        }
        t.idle_frames += 1;
    }
    let l = &got.last;
    t.frames += 1;
    t.rays += want.counts.rays_made;
    t.packets_in += u64::from(l.rays_in);
    t.finished += u64::from(l.rays_finished);
    t.overflowed += u64::from(l.rays_overflowed);
    t.samples += u64::from(l.samples);
    t.leaps += u64::from(l.leaps);
    t.clocks += got.clocks;
}

/// Random frames on every configuration up to `rays` rays each (seeds from 7000 + 10,000 x the
/// configuration's index; the third frame across a reset); the totals.
fn random_frames(rays: u64) {
    for (i, (variant, rtl)) in configs::<ProcessorRtlConfig>().into_iter().enumerate() {
        if rtl.side() > 16 || rtl.light == 1 {
            continue;
        }
        let start = Instant::now();
        let mut t = Totals::default();
        let mut k = 0u64;
        while t.rays < rays {
            let s = seed(7000 + 10_000 * i as u64 + k);
            random_frame(variant, rtl, s, k == 2, &mut t);
            k += 1;
        }
        assert_eq!(t.packets_in, t.finished + t.overflowed, "{variant}: {t:?}");
        eprintln!(
            "{variant}: {} frames (seeds {}..{}; {} with the host idle, one across a reset): {} rays, {} packets in = {} finished + {} overflowed, {} samples, {} leaps, {} clocks, every output exact; {:.0} s",
            t.frames,
            seed(7000 + 10_000 * i as u64),
            seed(7000 + 10_000 * i as u64 + k - 1),
            t.idle_frames,
            t.rays,
            t.packets_in,
            t.finished,
            t.overflowed,
            t.samples,
            t.leaps,
            t.clocks,
            start.elapsed().as_secs_f64()
        );
    }
}

/// The acceptance figure: at least 1,000,000 random rays per 16^3 DVR configuration (CI's
/// `b2v4` and `b3v2`; the gate, `Light` and `Scatter` lines have their own tests).
#[test]
#[ignore = "sim-full: a million random rays per configuration take tens of minutes"]
fn a_million_random_rays_per_config() {
    random_frames(1_000_000);
}

/// The same, 10,000 rays a configuration (the estimate of the million's time).
#[test]
#[ignore = "sim-full: the million's first 10,000 rays (its time estimate)"]
fn ten_thousand_random_rays_per_config() {
    random_frames(10_000);
}
