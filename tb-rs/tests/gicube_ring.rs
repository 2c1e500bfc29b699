//! Co-simulation of gicube_ring (two GI-Cube block processors in lockstep, the volume's blocks in
//! two slabs, rays sent over the links; docs/numerics/gicube_ring.md) against the ring model
//! `Ring::render` at the RTL's configuration: whole images, every pixel (also equal to one
//! processor's image), every processor's counts in the frame's last output item (rays in,
//! finished, overflowed, samples, leaps, cycles, cache hits and misses, rays taken from and sent
//! to the links), rays in = finished + overflowed summed over the processors, and each
//! processor's AR bursts (ARID = the processor) in its cache's order, under the subordinate's
//! seeded random latency, gaps, bandwidth limit and output back-pressure.
//!
//! The test bench is the host: it offers the head of its list, holds it until the RTL takes it,
//! and appends every returned ray to the end of its list.

mod support;

use cube5_model::camera::Camera;
use cube5_model::phantom::head_phantom;
use cube5_model::transfer::TransferFunction;
use cube5_model::units::gicube_packet_loop::{RayPacket, PACKET_WORDS};
use cube5_model::units::gicube_processor::{host_rays, Processor, Projection};
use cube5_model::units::gicube_ring::{Ring, RingFrame, RingOut, RingOutCounts, RingRtlConfig};
use cube5_tb::rtl::{ArHandshake, RtlStream, Traffic};
use cube5_tb::Variant;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;
use support::{axi, axi_mem_setup, compare_bursts, configs, seed};

type Bits = [u32; PACKET_WORDS];

/// The head phantom at the RTL's side and voxel width, azimuth 65, elevation 20, `px` a side.
struct Scene {
    ring: Ring,
    cam: Camera,
    proj: Projection,
}

impl Scene {
    fn new(rtl: &RingRtlConfig, px: u32, proj: Projection) -> Self {
        let p = rtl.processor();
        let vol = head_phantom(p.side() as usize, p.voxel_w).unwrap();
        let (a, e) = (65f64.to_radians(), 20f64.to_radians());
        let dir = [-e.cos() * a.cos(), -e.cos() * a.sin(), -e.sin()];
        let cam = Camera::new(dir.into(), vol.dims, vol.spacing, px, px);
        let proc = Processor::new(
            p.processor_config(),
            &vol,
            &TransferFunction::head_default(),
        )
        .unwrap();
        let ring = Ring::new(proc, rtl.procs()).unwrap();
        Self { ring, cam, proj }
    }

    fn packets(&self) -> Vec<Bits> {
        let p = self.ring.processor();
        host_rays(p.volume(), &self.cam, self.proj, p.config().host_order)
            .unwrap()
            .iter()
            .map(|r| Processor::packet(r).unwrap().to_bits().unwrap())
            .collect()
    }
}

/// What the RTL rendered: the pixels, the last output item, the clocks, the AR bursts.
struct RtlFrame {
    rgb: Vec<[u16; 3]>,
    last: RingOut,
    clocks: u64,
    ars: Vec<ArHandshake>,
}

/// The host loop, one clock per call: offers the head of its list (held until taken), collects
/// finished rays into the image and appends returned rays to its list, until every ray
/// finished.
fn run_host(
    dut: &mut RtlStream<RingRtlConfig>,
    rays: &[Bits],
    px: u32,
    stall: f64,
    rng: &mut ChaCha8Rng,
) -> RtlFrame {
    let name = dut.name();
    let mut list: VecDeque<Bits> = rays.iter().copied().collect();
    let mut rgb = vec![[0u16; 3]; (px * px) as usize];
    let mut seen = vec![false; (px * px) as usize];
    let (mut finished, mut clocks) = (0usize, 0u64);
    let mut last = RingOut::default();
    let limit = 100_000 + 40_000 * rays.len() as u64;
    while finished < rays.len() {
        assert!(clocks < limit, "{name}: no progress after {clocks} clocks");
        let items: Vec<Bits> = list.front().copied().into_iter().collect();
        let traffic = Traffic {
            idle: vec![0],
            stall: vec![u8::from(rng.random_bool(stall))],
        };
        let d = dut
            .drive(&items, &traffic, u64::from(items.is_empty()), 1)
            .unwrap();
        clocks += 1;
        assert_eq!(
            d.stats.protocol_errors, 0,
            "{name}: a stalled output changed at clock {clocks}"
        );
        if d.stats.consumed == 1 {
            list.pop_front();
        }
        for o in d.outputs {
            let o = o.value;
            let r = RayPacket::from_bits(&o.ray);
            if o.done {
                let i = (u32::from(r.v) * px + u32::from(r.u)) as usize;
                assert!(!seen[i], "{name}: pixel ({}, {}) finished twice", r.u, r.v);
                seen[i] = true;
                rgb[i] = r.color;
                finished += 1;
            } else {
                assert!(r.flags & 4 != 0, "{name}: a returned ray has OVERFLOW set");
                list.push_back(o.ray);
            }
            last = o;
        }
    }
    let c = dut.axi_counters();
    assert_eq!(
        c.protocol_errors,
        0,
        "{name}: AXI: {}",
        dut.axi_first_error()
    );
    RtlFrame {
        rgb,
        last,
        clocks,
        ars: dut.axi_take_ar().unwrap(),
    }
}

/// One frame from reset, the memory random (latency 10-200, gaps, a bandwidth limit on half the
/// seeds), the output stalled 30 %: pixels, counts and bursts equal to the model's.
fn exact_frame(
    variant: &'static Variant,
    rtl: RingRtlConfig,
    px: u32,
    proj: Projection,
    s: u64,
) -> (RtlFrame, RingFrame) {
    let scene = Scene::new(&rtl, px, proj);
    let (want, bursts) = scene.ring.render_cache_traced(&scene.cam, proj).unwrap();
    want.check_conservation().unwrap();
    let single = scene.ring.processor().render(&scene.cam, proj).unwrap();
    assert_eq!(
        want.rgb, single.rgb,
        "the ring model renders one processor's image"
    );

    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let p = rtl.processor();
    let img = scene
        .ring
        .processor()
        .rtl_memory()
        .unwrap()
        .expect("a cache");
    let setup = axi_mem_setup(
        (p.data_w / 8, 32),
        &img,
        (10, 190),
        (rng.random_range(0..300), rng.random_range(0..300)),
        axi::random_bandwidth(&mut rng, p.data_w / 8),
        s,
    );
    let mut dut = RtlStream::new(variant, rtl, s as u32).unwrap();
    dut.axi_setup(&setup).unwrap();
    dut.axi_load(img.base, &img.bytes).unwrap();
    for (a, d) in scene.ring.processor().rtl_config_writes(&p).unwrap() {
        dut.write_config(a, &d).unwrap();
    }
    let got = run_host(&mut dut, &scene.packets(), px, 0.3, &mut rng);

    let name = variant.name;
    let differ = got
        .rgb
        .iter()
        .zip(&want.rgb)
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(
        differ, 0,
        "{name} {proj:?} seed {s}: {differ} pixels differ"
    );
    let wanted: Vec<RingOutCounts> = want
        .counts
        .iter()
        .zip(&want.links)
        .map(|(c, l)| RingOutCounts::of(c, l))
        .collect();
    assert_eq!(
        got.last.counts, wanted,
        "{name} {proj:?} seed {s}: every processor's counts equal the model's"
    );
    let sum = |f: fn(&RingOutCounts) -> u32| got.last.counts.iter().map(f).sum::<u32>();
    assert_eq!(
        sum(|c| c.rays_in),
        sum(|c| c.rays_finished) + sum(|c| c.rays_overflowed),
        "{name}: rays in = finished + overflowed over the processors"
    );
    assert!(
        sum(|c| c.nb_out) > 0,
        "{name}: rays crossed between the processors"
    );
    // Each processor's bursts (ARID = the processor) in its cache's order.
    let size = (p.data_w / 8).trailing_zeros();
    for (i, want_i) in bursts.iter().enumerate() {
        let mine: Vec<ArHandshake> = got
            .ars
            .iter()
            .filter(|a| a.id == i as u32)
            .map(|a| ArHandshake { id: 0, ..*a })
            .collect();
        let n = compare_bursts(&mine, "AR", want_i, size, variant, s, |k| {
            format!("processor {i}'s burst #{k}")
        })
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            n,
            want_i.len(),
            "{name}: processor {i} read every missed line once"
        );
    }
    let total: usize = bursts.iter().map(Vec::len).sum::<usize>();
    assert_eq!(got.ars.len(), total, "{name}: no burst of another ID");
    (got, want)
}

fn frame_line(variant: &'static Variant, what: &str, got: &RtlFrame, want: &RingFrame) {
    let per: Vec<String> = want
        .counts
        .iter()
        .zip(&want.links)
        .map(|(c, l)| {
            format!(
                "{} in, {} finished, {} overflowed, {} samples, {} sent, {} taken",
                c.rays_in, c.rays_finished, c.rays_overflowed, c.samples, l.nb_out, l.nb_in
            )
        })
        .collect();
    eprintln!(
        "{variant} {what}: {} rays, {} ring cycles, {} clocks ({:.2} clocks/cycle); {}",
        want.rays_made,
        want.cycles(),
        got.clocks,
        got.clocks as f64 / want.cycles() as f64,
        per.join("; ")
    );
}

#[test]
fn two_processors_render_the_model_frame() {
    let s = seed(0x61_7269);
    for (v, rtl) in configs::<RingRtlConfig>() {
        if rtl.processor().side() > 16 {
            continue;
        }
        for (k, proj) in [
            Projection::Parallel,
            Projection::Perspective { fov_deg: 40.0 },
        ]
        .into_iter()
        .enumerate()
        {
            let (got, want) = exact_frame(v, rtl, 12, proj, s + k as u64);
            frame_line(v, &format!("{proj:?}"), &got, &want);
        }
    }
}

#[test]
#[ignore = "sim-full: the 32^3 ring (p1b3v4, built with CUBE5_FULL=1) renders 32 x 32 frames"]
fn large_ring_frames_equal_the_model() {
    let s = seed(0x61_7270);
    for (v, rtl) in configs::<RingRtlConfig>() {
        for (k, proj) in [
            Projection::Parallel,
            Projection::Perspective { fov_deg: 40.0 },
        ]
        .into_iter()
        .enumerate()
        {
            let (got, want) = exact_frame(v, rtl, 32, proj, s + k as u64);
            frame_line(v, &format!("{proj:?} 32 x 32"), &got, &want);
        }
    }
}
