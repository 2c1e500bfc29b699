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
use cube5_model::units::gicube_processor::Projection;
use cube5_model::units::gicube_ring::{Ring, RingFrame, RingOut, RingOutCounts, RingRtlConfig};
use cube5_tb::harness::count_differing;
use cube5_tb::rtl::ArHandshake;
use cube5_tb::Variant;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use support::processor::{
    head_scene, host_packets, open_over, random_memory, run_eager_host, Bits, RtlFrame,
};
use support::{compare_bursts, configs, seed};

/// The head phantom at the RTL's side and voxel width, azimuth 65, elevation 20, `px` a side
/// (`head_scene`), in a ring of the RTL's processors.
struct Scene {
    ring: Ring,
    cam: Camera,
    proj: Projection,
}

impl Scene {
    fn new(rtl: &RingRtlConfig, px: u32, proj: Projection) -> Self {
        let (proc, cam) = head_scene(&rtl.processor(), px);
        let ring = Ring::new(proc, rtl.procs()).unwrap();
        Self { ring, cam, proj }
    }

    fn packets(&self) -> Vec<Bits> {
        host_packets(self.ring.processor(), &self.cam, self.proj)
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
) -> (RtlFrame<RingOut>, RingFrame) {
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
    let mem = random_memory(&mut rng, &p);
    let proc = scene.ring.processor();
    let setup = |img: &_| mem.read_setup(p.data_w / 8, img, s);
    let mut dut = open_over(variant, rtl, &p, proc, setup, s);
    let what = format!("{variant} seed {s} ({proj:?}, {mem:?}, stall 0.3)");
    let got = run_eager_host(&mut dut, &scene.packets(), (px, px), 0.3, &mut rng, &what);

    let name = variant.name;
    let differ = count_differing(&got.rgb, &want.rgb);
    assert_eq!(differ, 0, "{what}: {differ} pixels differ");
    let wanted: Vec<RingOutCounts> = want
        .counts
        .iter()
        .zip(&want.links)
        .map(|(c, l)| RingOutCounts::of(c, l))
        .collect();
    assert_eq!(
        got.last.counts, wanted,
        "{what}: every processor's counts equal the model's"
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

fn frame_line(variant: &'static Variant, what: &str, got: &RtlFrame<RingOut>, want: &RingFrame) {
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
