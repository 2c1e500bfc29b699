//! Co-simulation of gicube_processor (the GI-Cube block processor for direct volume rendering:
//! the queue front end, the sample and the step units in the ring, the volume in eight on-chip
//! banks) against the processor model `Processor::render` at the RTL's ring latency
//! (docs/numerics/gicube_processor.md, *The ring*, *The RTL*): whole images, every pixel, and the
//! counts (rays in, finished, overflowed, samples, leaps, processor cycles) of both.
//!
//! The test bench is the host: it offers the head of its list of ray packets, holds it until the
//! RTL takes it, and appends every overflowed ray that comes back to the end of its list.

mod support;

use cube5_model::camera::Camera;
use cube5_model::phantom::head_phantom;
use cube5_model::transfer::TransferFunction;
use cube5_model::units::gicube_packet_loop::{RayPacket, PACKET_WORDS};
use cube5_model::units::gicube_processor::{
    host_rays, Processor, ProcessorFrame, ProcessorOut, ProcessorRtlConfig, Projection,
};
use cube5_tb::rtl::{RtlStream, Traffic};
use cube5_tb::Variant;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;
use support::{configs, seed};

type Bits = [u32; PACKET_WORDS];

/// A scene: the head phantom at the RTL's side and voxel width, seen from azimuth 65, elevation
/// 20, `px` pixels a side.
struct Scene {
    proc: Processor,
    cam: Camera,
    proj: Projection,
}

impl Scene {
    fn new(rtl: &ProcessorRtlConfig, px: u32, proj: Projection) -> Self {
        let side = rtl.side() as usize;
        let vol = head_phantom(side, rtl.voxel_w).unwrap();
        let (a, e) = (65f64.to_radians(), 20f64.to_radians());
        let dir = [-e.cos() * a.cos(), -e.cos() * a.sin(), -e.sin()];
        let cam = Camera::new(dir.into(), vol.dims, vol.spacing, px, px);
        let tf = TransferFunction::head_default();
        let proc = Processor::new(rtl.processor_config(), &vol, &tf).unwrap();
        Self { proc, cam, proj }
    }

    /// The host's packets, in its order.
    fn packets(&self) -> Vec<Bits> {
        let cfg = self.proc.config();
        host_rays(self.proc_volume(), &self.cam, self.proj, cfg.host_order)
            .unwrap()
            .iter()
            .map(|r| Processor::packet(r).unwrap().to_bits().unwrap())
            .collect()
    }

    fn proc_volume(&self) -> &cube5_model::volume::Volume {
        self.proc.volume()
    }

    fn model(&self) -> ProcessorFrame {
        self.proc.render(&self.cam, self.proj).unwrap()
    }
}

/// What the RTL rendered: the pixels, the last output's counts, the clocks from the first offer
/// to the last output.
struct RtlFrame {
    rgb: Vec<[u16; 3]>,
    last: ProcessorOut,
    outputs: u64,
    clocks: u64,
}

/// How the host and the consumer behave: the probability that the host, having a ray, does not
/// offer it yet in a clock, and that the output is not taken.
#[derive(Clone, Copy)]
struct Behaviour {
    idle: f64,
    stall: f64,
}

const FULL_SPEED: Behaviour = Behaviour {
    idle: 0.0,
    stall: 0.0,
};

/// The host loop, one clock per call of the RTL: offers the head of its list (held until
/// taken), collects finished rays into the image and appends overflowed rays to its list; stops
/// after `stop_after` clocks if given, else when every ray has finished.
fn run_host(
    dut: &mut RtlStream<ProcessorRtlConfig>,
    rays: &[Bits],
    px: u32,
    b: Behaviour,
    rng: &mut ChaCha8Rng,
    stop_after: Option<u64>,
) -> RtlFrame {
    let name = dut.name();
    let mut list: VecDeque<Bits> = rays.iter().copied().collect();
    let mut rgb = vec![[0u16; 3]; (px * px) as usize];
    let mut seen = vec![false; (px * px) as usize];
    let (mut finished, mut outputs, mut clocks) = (0usize, 0u64, 0u64);
    let mut offering = false;
    let mut last = ProcessorOut::default();
    let limit = 20_000 + 4_000 * rays.len() as u64;
    while finished < rays.len() && stop_after.is_none_or(|s| clocks < s) {
        assert!(clocks < limit, "{name}: no progress after {clocks} clocks");
        if !list.is_empty() && !offering {
            offering = !rng.random_bool(b.idle);
        }
        let items: Vec<Bits> = if offering { vec![list[0]] } else { Vec::new() };
        let traffic = Traffic {
            idle: vec![0],
            stall: vec![u8::from(rng.random_bool(b.stall))],
        };
        let expect = u64::from(items.is_empty());
        let d = dut.drive(&items, &traffic, expect, 1).unwrap();
        clocks += 1;
        if d.stats.consumed == 1 {
            list.pop_front();
            offering = false;
        }
        for o in d.outputs {
            let o = o.value;
            outputs += 1;
            last = o;
            if o.done {
                let r = RayPacket::from_bits(&o.ray);
                let i = (u32::from(r.v) * px + u32::from(r.u)) as usize;
                assert!(!seen[i], "{name}: pixel ({}, {}) finished twice", r.u, r.v);
                seen[i] = true;
                rgb[i] = r.color;
                finished += 1;
            } else {
                let r = RayPacket::from_bits(&o.ray);
                assert!(
                    r.flags & 4 != 0,
                    "{name}: an overflowed ray has OVERFLOW set"
                );
                list.push_back(o.ray);
            }
        }
    }
    RtlFrame {
        rgb,
        last,
        outputs,
        clocks,
    }
}

/// Opens `variant` and loads the scene's tables, empty flags and volume.
fn open(
    variant: &'static Variant,
    rtl: ProcessorRtlConfig,
    scene: &Scene,
    s: u64,
) -> RtlStream<ProcessorRtlConfig> {
    let mut dut = RtlStream::new(variant, rtl, s as u32).unwrap();
    for (a, d) in scene.proc.rtl_config_writes(&rtl).unwrap() {
        dut.write_config(a, &d).unwrap();
    }
    dut
}

/// The image and the conservation of rays; with `exact_counts` every count equals the model's.
fn check_frame(name: &str, what: &str, got: &RtlFrame, want: &ProcessorFrame, exact_counts: bool) {
    let c = &want.counts;
    let l = &got.last;
    let differ = got
        .rgb
        .iter()
        .zip(&want.rgb)
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(
        differ, 0,
        "{name} {what}: {differ} pixels differ from the model"
    );
    assert_eq!(
        u64::from(l.rays_in),
        u64::from(l.rays_finished) + u64::from(l.rays_overflowed),
        "{name} {what}: RTL rays in = finished + overflowed ({l:?})"
    );
    assert_eq!(
        c.rays_in,
        c.rays_finished + c.rays_overflowed,
        "{name} {what}: model rays in = finished + overflowed"
    );
    assert_eq!(
        u64::from(l.rays_finished),
        c.rays_made,
        "{name} {what}: every ray finished"
    );
    // A ray's samples and leaps do not depend on the order.
    assert_eq!(
        (u64::from(l.samples), u64::from(l.leaps)),
        (c.samples, c.leaps),
        "{name} {what}: samples and leaps"
    );
    if exact_counts {
        assert_eq!(
            (
                u64::from(l.rays_in),
                u64::from(l.rays_overflowed),
                u64::from(l.cycles)
            ),
            (c.rays_in, c.rays_overflowed, c.cycles),
            "{name} {what}: rays in, overflowed and processor cycles equal the model's"
        );
    }
}

/// One frame at full speed, every pixel and every count equal to the model's.
fn exact_frame(
    variant: &'static Variant,
    rtl: ProcessorRtlConfig,
    px: u32,
    proj: Projection,
    s: u64,
) -> (RtlFrame, ProcessorFrame) {
    let scene = Scene::new(&rtl, px, proj);
    let want = scene.model();
    let mut dut = open(variant, rtl, &scene, s);
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let got = run_host(&mut dut, &scene.packets(), px, FULL_SPEED, &mut rng, None);
    check_frame(variant.name, &format!("{proj:?}"), &got, &want, true);
    (got, want)
}

fn ci_configs() -> Vec<(&'static Variant, ProcessorRtlConfig)> {
    configs::<ProcessorRtlConfig>()
        .into_iter()
        .filter(|(_, c)| c.side() <= 16)
        .collect()
}

#[test]
fn parallel_and_perspective_frames_equal_the_model_with_every_count() {
    for (variant, rtl) in ci_configs() {
        let px = rtl.side();
        for proj in [
            Projection::Parallel,
            Projection::Perspective { fov_deg: 30.0 },
        ] {
            let (got, want) = exact_frame(variant, rtl, px, proj, seed(1900));
            let c = &want.counts;
            eprintln!(
                "{variant} {proj:?}: {} rays, {} in, {} overflowed, {} samples, {} leaps, {} processor cycles, {} clocks: {:.3} samples/clock, {:.2} clocks/cycle",
                c.rays_made,
                c.rays_in,
                c.rays_overflowed,
                c.samples,
                c.leaps,
                c.cycles,
                got.clocks,
                c.samples as f64 / got.clocks as f64,
                got.clocks as f64 / c.cycles as f64
            );
        }
    }
}

/// Queues of a few rays against a frame of many: rays overflow to the host, come back, and none
/// is lost (every pixel once, rays in = finished + overflowed, equal to the model's).
#[test]
fn forced_overflow_loses_no_ray() {
    let (variant, rtl) = ci_configs()
        .into_iter()
        .min_by_key(|(_, c)| c.queue_len << c.queue_w())
        .unwrap();
    let px = 2 * rtl.side();
    let (got, want) = exact_frame(variant, rtl, px, Projection::Parallel, seed(1910));
    assert!(
        got.last.rays_overflowed > 0 && want.counts.rays_overflowed > 0,
        "{variant}: the frame overflows ({:?})",
        got.last
    );
    eprintln!(
        "{variant}: {} rays through {} queues of {}: {} overflowed and came back, {} outputs",
        want.counts.rays_made,
        1u32 << rtl.queue_w(),
        rtl.queue_len,
        got.last.rays_overflowed,
        got.outputs
    );
}

/// The host idle and the output stalled at random: the image is exact and no ray is lost (the
/// stalls alone keep the model's cycle order, so with the host never idle every count is equal).
#[test]
fn idle_host_and_stalled_output_keep_the_image() {
    for (variant, rtl) in ci_configs() {
        let px = rtl.side();
        let scene = Scene::new(&rtl, px, Projection::Perspective { fov_deg: 30.0 });
        let want = scene.model();
        let s = seed(1920);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let mut dut = open(variant, rtl, &scene, s);
        for (b, exact) in [
            (
                Behaviour {
                    idle: 0.0,
                    stall: 0.6,
                },
                true,
            ),
            (
                Behaviour {
                    idle: 0.5,
                    stall: 0.3,
                },
                false,
            ),
        ] {
            dut.reset();
            let got = run_host(&mut dut, &scene.packets(), px, b, &mut rng, None);
            check_frame(variant.name, "idle/stall", &got, &want, exact);
        }
    }
}

/// A reset in the middle of a frame (after three clocks per processor cycle of the whole frame: a
/// cycle takes at least five) drops the rays in the processor; the tables, flags and
/// volume survive it, and the next frame is exact, counts and all.
#[test]
fn mid_frame_reset_then_an_exact_frame() {
    for (variant, rtl) in ci_configs() {
        let px = rtl.side();
        let scene = Scene::new(&rtl, px, Projection::Parallel);
        let want = scene.model();
        let s = seed(1930);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let mut dut = open(variant, rtl, &scene, s);
        let part = run_host(
            &mut dut,
            &scene.packets(),
            px,
            Behaviour {
                idle: 0.2,
                stall: 0.2,
            },
            &mut rng,
            Some(3 * want.counts.cycles),
        );
        assert!(
            part.outputs > 0 && (part.last.rays_finished as u64) < want.counts.rays_made,
            "{variant}: the reset falls mid-frame"
        );
        dut.reset();
        let got = run_host(&mut dut, &scene.packets(), px, FULL_SPEED, &mut rng, None);
        check_frame(variant.name, "after a reset", &got, &want, true);
    }
}

/// A model with another ring latency gives the same image but other counts (the scoreboard of
/// the counts bites).
#[test]
fn a_model_with_another_ring_latency_counts_other_cycles() {
    let (variant, rtl) = ci_configs()[0];
    let px = rtl.side();
    let scene = Scene::new(&rtl, px, Projection::Parallel);
    let other = ProcessorRtlConfig {
        ring_lat: rtl.ring_lat + 1,
        ..rtl
    };
    let want = Scene::new(&other, px, Projection::Parallel).model();
    let s = seed(1940);
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let mut dut = open(variant, rtl, &scene, s);
    let got = run_host(&mut dut, &scene.packets(), px, FULL_SPEED, &mut rng, None);
    check_frame(variant.name, "other latency: image", &got, &want, false);
    assert_ne!(
        u64::from(got.last.cycles),
        want.counts.cycles,
        "{variant}: a ring of {} cycles counts other cycles",
        other.ring_lat
    );
}

#[test]
#[ignore = "sim-full: 32^3 and 64^3 frames (the `full` variants), parallel and perspective"]
fn large_frames_equal_the_model_with_every_count() {
    for (variant, rtl) in configs::<ProcessorRtlConfig>() {
        if rtl.side() <= 16 {
            continue;
        }
        let px = rtl.side();
        for proj in [
            Projection::Parallel,
            Projection::Perspective { fov_deg: 30.0 },
        ] {
            let (got, want) = exact_frame(variant, rtl, px, proj, seed(1950));
            eprintln!(
                "{variant} {proj:?}: {} rays, {} in, {} overflowed, {} samples, {} leaps, {} processor cycles, {} clocks: {:.3} samples/clock",
                want.counts.rays_made,
                want.counts.rays_in,
                want.counts.rays_overflowed,
                want.counts.samples,
                want.counts.leaps,
                want.counts.cycles,
                got.clocks,
                want.counts.samples as f64 / got.clocks as f64
            );
        }
    }
}

/// The gate-level netlist (Yosys) of the tiny configuration renders an exact frame, counts and
/// all.
#[test]
#[ignore = "sim-full: the gate-level netlist is a `full` build (minutes of Yosys and Verilator)"]
fn gate_level_netlist_renders_an_exact_frame() {
    for (variant, rtl) in support::gate_configs::<ProcessorRtlConfig>() {
        let px = 2 * rtl.side();
        let (got, want) = exact_frame(variant, rtl, px, Projection::Parallel, seed(1960));
        eprintln!(
            "{variant}: {} rays, {} overflowed, {} samples in {} clocks",
            want.counts.rays_made, want.counts.rays_overflowed, want.counts.samples, got.clocks
        );
    }
}
