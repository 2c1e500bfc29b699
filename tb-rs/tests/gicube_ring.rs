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
use cube5_model::transfer::{TfPoint, TransferFunction};
use cube5_model::units::cube5_axi_rd::Burst;
use cube5_model::units::gicube_packet_loop::RayPacket;
use cube5_model::units::gicube_processor::{Processor, Projection};
use cube5_model::units::gicube_ring::{Ring, RingFrame, RingOut, RingOutCounts, RingRtlConfig};
use cube5_tb::harness::count_differing;
use cube5_tb::rtl::{ArHandshake, RtlStream};
use cube5_tb::Variant;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;
use support::processor::{
    head_scene, host_packets, open_over, random_memory, round_trip_clocks, run_eager_host,
    run_host, view_dir, Behaviour, Bits, Memory, RandomRays, RtlFrame, FAST_MEMORY, IDLE_AND_STALL,
};
use support::{axi, compare_bursts, configs, seed};

/// A scene in a ring of the RTL's processors: the head phantom at the RTL's side and voxel width
/// (`head_scene`: azimuth 65, elevation 20, the head's transfer function, `px` a side, or
/// `Scene::with` another view and transfer function), and the projection.
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

    /// The head phantom seen along `dir` through `tf`.
    fn with(
        rtl: &RingRtlConfig,
        px: u32,
        proj: Projection,
        dir: [f64; 3],
        tf: &TransferFunction,
    ) -> Self {
        let p = rtl.processor();
        let vol = head_phantom(p.side() as usize, p.voxel_w).unwrap();
        let cam = Camera::new(dir.into(), vol.dims, vol.spacing, px, px);
        let proc = Processor::new(p.processor_config(), &vol, tf).unwrap();
        let ring = Ring::new(proc, rtl.procs()).unwrap();
        Self { ring, cam, proj }
    }

    fn packets(&self) -> Vec<Bits> {
        host_packets(self.ring.processor(), &self.cam, self.proj)
    }

    /// The ring model's frame (rays conserved, one processor's image) and each processor's
    /// bursts.
    fn model(&self) -> (RingFrame, Vec<Vec<Burst>>) {
        let (want, bursts) = self.ring.render_cache_traced(&self.cam, self.proj).unwrap();
        want.check_conservation().unwrap();
        let single = self.ring.processor().render(&self.cam, self.proj).unwrap();
        assert_eq!(
            want.rgb, single.rgb,
            "the ring model renders one processor's image"
        );
        (want, bursts)
    }

    /// `rtl`'s ring opened over the scene's memory image, the subordinate answering as `mem`
    /// says.
    fn open(
        &self,
        variant: &'static Variant,
        rtl: RingRtlConfig,
        mem: Memory,
        s: u64,
    ) -> RtlStream<RingRtlConfig> {
        let p = rtl.processor();
        let setup = |img: &_| mem.read_setup(p.data_w / 8, img, s);
        open_over(variant, rtl, &p, self.ring.processor(), setup, s)
    }
}

/// A transfer function of one colour and opacity `alpha` at every density.
fn flat_tf(alpha: f64) -> TransferFunction {
    let p = |density| TfPoint {
        density,
        rgba: [0.9, 0.6, 0.3, alpha],
    };
    TransferFunction::new(vec![p(0.0), p(1.0)]).unwrap()
}

/// The sum over the processors of one count of the last item.
fn sum_of(got: &RtlFrame<RingOut>, f: fn(&RingOutCounts) -> u32) -> u32 {
    got.last.counts.iter().map(f).sum()
}

/// The image and the conservation of rays (every ray finished once; rays in = finished +
/// overflowed over the processors); with `exact` every processor's counts equal the model's.
fn check_frame(what: &str, got: &RtlFrame<RingOut>, want: &RingFrame, exact: bool) {
    let differ = count_differing(&got.rgb, &want.rgb);
    assert_eq!(differ, 0, "{what}: {differ} pixels differ");
    assert_eq!(
        sum_of(got, |c| c.rays_in),
        sum_of(got, |c| c.rays_finished) + sum_of(got, |c| c.rays_overflowed),
        "{what}: rays in = finished + overflowed over the processors"
    );
    assert_eq!(
        u64::from(sum_of(got, |c| c.rays_finished)),
        want.rays_made,
        "{what}: every ray finished"
    );
    assert_eq!(
        sum_of(got, |c| c.nb_in),
        sum_of(got, |c| c.nb_out),
        "{what}: every ray sent was taken from its link"
    );
    // A ray's samples and leaps are its own, wherever and whenever it is processed.
    let total = |f: fn(&cube5_model::units::gicube_processor::ProcessorCounts) -> u64| {
        want.counts.iter().map(f).sum::<u64>()
    };
    assert_eq!(
        (
            u64::from(sum_of(got, |c| c.samples)),
            u64::from(sum_of(got, |c| c.leaps))
        ),
        (total(|c| c.samples), total(|c| c.leaps)),
        "{what}: samples and leaps"
    );
    if exact {
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
    }
}

/// Each processor's bursts (ARID = the processor) in its cache's order, every missed line once.
fn check_bursts(
    variant: &'static Variant,
    rtl: &RingRtlConfig,
    got: &RtlFrame<RingOut>,
    bursts: &[Vec<Burst>],
    s: u64,
) {
    let name = variant.name;
    let size = (rtl.proc.data_w / 8).trailing_zeros();
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
}

/// One frame of `scene` from reset, the host never idle, the memory as `mem` (random when
/// `None`: latency 10-200, gaps, a bandwidth limit on half the seeds), the output stalled with
/// probability `stall`: pixels, every count and the bursts equal to the model's.
fn exact_scene(
    variant: &'static Variant,
    rtl: RingRtlConfig,
    scene: &Scene,
    mem: Option<Memory>,
    stall: f64,
    s: u64,
) -> (RtlFrame<RingOut>, RingFrame) {
    let (want, bursts) = scene.model();
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let mem = mem.unwrap_or_else(|| random_memory(&mut rng, &rtl.processor()));
    let mut dut = scene.open(variant, rtl, mem, s);
    let proj = scene.proj;
    let what = format!("{variant} seed {s} ({proj:?}, {mem:?}, stall {stall})");
    let px = scene.cam.width;
    let got = run_eager_host(&mut dut, &scene.packets(), (px, px), stall, &mut rng, &what);
    check_frame(&what, &got, &want, true);
    check_bursts(variant, &rtl, &got, &bursts, s);
    (got, want)
}

/// `exact_scene` of the head scene under random memory, the output stalled 30 %; rays crossed
/// between the processors.
fn exact_frame(
    variant: &'static Variant,
    rtl: RingRtlConfig,
    px: u32,
    proj: Projection,
    s: u64,
) -> (RtlFrame<RingOut>, RingFrame) {
    let scene = Scene::new(&rtl, px, proj);
    let (got, want) = exact_scene(variant, rtl, &scene, None, 0.3, s);
    assert!(
        sum_of(&got, |c| c.nb_out) > 0,
        "{variant}: rays crossed between the processors"
    );
    (got, want)
}

fn frame_line(variant: &'static Variant, what: &str, got: &RtlFrame<RingOut>, want: &RingFrame) {
    let per: Vec<String> = want
        .counts
        .iter()
        .zip(&want.links)
        .map(|(c, l)| {
            format!(
                "{} in, {} finished, {} overflowed ({} refused by a link), {} samples, {} leaps, {} sent, {} taken, {} misses",
                c.rays_in,
                c.rays_finished,
                c.rays_overflowed,
                l.nb_refused,
                c.samples,
                c.leaps,
                l.nb_out,
                l.nb_in,
                c.cache_misses
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

/// The CI configurations (16^3 and below).
fn ci_configs() -> Vec<(&'static Variant, RingRtlConfig)> {
    configs::<RingRtlConfig>()
        .into_iter()
        .filter(|(_, c)| c.processor().side() <= 16)
        .collect()
}

#[test]
fn two_processors_render_the_model_frame() {
    let s = seed(0x61_7269);
    for (v, rtl) in ci_configs() {
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

/// Directed extremes on every CI line (12 x 12, parallel, random memory, the output stalled
/// 30 %): a transparent volume (every block empty: rays only leap, no sample), an opaque one
/// (every ray ends at its first sample), views along -x and +x (every ray crosses every slab:
/// rays sent both ways), and a link full: rays a neighbour's link refuses come back to the host
/// with OVERFLOW set and none is lost. Every frame's pixels, counts and bursts are the model's.
#[test]
fn directed_extremes_leap_terminate_cross_every_slab_and_fill_the_link() {
    let s = seed(0x61_7271);
    for (v, rtl) in ci_configs() {
        let head = TransferFunction::head_default();
        let cases = [
            ("transparent", view_dir(65.0, 20.0), flat_tf(0.0)),
            ("opaque", view_dir(65.0, 20.0), flat_tf(1.0)),
            ("along -x", view_dir(0.0, 0.0), head.clone()),
            ("along +x", view_dir(180.0, 0.0), head),
        ];
        let mut refused = 0;
        let mut along = vec![0u32; rtl.procs() as usize];
        for (k, (name, dir, tf)) in cases.iter().enumerate() {
            let scene = Scene::with(&rtl, 12, Projection::Parallel, *dir, tf);
            let (got, want) = exact_scene(v, rtl, &scene, None, 0.3, s + k as u64);
            frame_line(v, name, &got, &want);
            let (samples, leaps) = (sum_of(&got, |c| c.samples), sum_of(&got, |c| c.leaps));
            let sent: Vec<u32> = got.last.counts.iter().map(|c| c.nb_out).collect();
            match *name {
                "transparent" => assert!(
                    samples == 0 && leaps > 0,
                    "{v} {name}: rays only leap ({samples} samples, {leaps} leaps)"
                ),
                "opaque" => assert_eq!(
                    u64::from(samples),
                    want.rays_made,
                    "{v} {name}: every ray ends at its first sample"
                ),
                _ => {
                    // Along x every ray that does not end early crosses into the next slab.
                    assert!(
                        sent.iter().any(|&n| n > 0),
                        "{v} {name}: rays cross the slabs ({sent:?})"
                    );
                    for (a, n) in along.iter_mut().zip(&sent) {
                        *a += n;
                    }
                }
            }
            refused += want.links.iter().map(|l| l.nb_refused).sum::<u64>();
        }
        assert!(
            along.iter().all(|&n| n > 0),
            "{v}: along -x and +x every processor sends rays on ({along:?})"
        );
        assert!(
            refused > 0,
            "{v}: some link was full and returned rays to the host"
        );
    }
}

/// The host idle at random and the output stalled: the image is exact and no ray is lost (the
/// stalls alone keep the model's cycle order, so with the host never idle every count is equal).
#[test]
fn idle_host_and_stalled_output_keep_the_image() {
    let s = seed(0x61_7272);
    for (v, rtl) in ci_configs() {
        let scene = Scene::new(&rtl, 12, Projection::Perspective { fov_deg: 40.0 });
        let (want, _) = scene.model();
        let packets = scene.packets();
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let mem = random_memory(&mut rng, &rtl.processor());
        let mut dut = scene.open(v, rtl, mem, s);
        for (b, exact) in IDLE_AND_STALL {
            dut.reset();
            let what = format!("{v} seed {s} idle/stall ({mem:?}, {b:?})");
            let got = run_host(&mut dut, &packets, (12, 12), b, &mut rng, None, &what);
            check_frame(&what, &got, &want, exact);
            eprintln!("{what}: {} clocks, exact", got.clocks);
        }
    }
}

/// A reset in the middle of a frame (at half the clocks a whole frame took under the same
/// conditions) drops the rays in the processors, the links and the caches' bursts in flight (the
/// subordinate is reset with it: no burst left outstanding); the tables, flags and memory survive
/// it, and the next frame is exact, every count and burst.
#[test]
fn mid_frame_reset_then_an_exact_frame() {
    let s = seed(0x61_7273);
    for (v, rtl) in ci_configs() {
        let scene = Scene::new(&rtl, 12, Projection::Parallel);
        let (want, bursts) = scene.model();
        let packets = scene.packets();
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let mem = random_memory(&mut rng, &rtl.processor());
        let mut dut = scene.open(v, rtl, mem, s);
        let b = Behaviour {
            idle: 0.2,
            stall: 0.2,
        };
        let what = format!("{v} seed {s} a whole frame ({mem:?}, {b:?})");
        let whole = run_host(&mut dut, &packets, (12, 12), b, &mut rng, None, &what);
        check_frame(&what, &whole, &want, false);
        dut.reset();
        let what = format!("{v} seed {s} before a reset ({mem:?}, {b:?})");
        let cut = Some(whole.clocks / 2);
        let part = run_host(&mut dut, &packets, (12, 12), b, &mut rng, cut, &what);
        let finished = sum_of(&part, |c| c.rays_finished);
        assert!(
            part.outputs > 0 && u64::from(finished) < want.rays_made,
            "{v}: the reset falls mid-frame ({finished} of {} rays finished)",
            want.rays_made
        );
        let dropped = axi::reset_leaves_nothing_in_flight(&mut dut, v, s, false).unwrap();
        eprintln!(
            "{v}: reset after {} clocks, {finished} of {} rays finished, {} rays sent, {dropped} bursts in flight dropped",
            part.clocks,
            want.rays_made,
            sum_of(&part, |c| c.nb_out)
        );
        let b = Behaviour {
            idle: 0.0,
            stall: 0.0,
        };
        let what = format!("{v} seed {s} after a reset ({mem:?}, {b:?})");
        let got = run_host(&mut dut, &packets, (12, 12), b, &mut rng, None, &what);
        check_frame(&what, &got, &want, true);
        check_bursts(v, &rtl, &got, &bursts, s);
    }
}

/// Throughput at full speed (the host never idle, the output never stalled, a memory answering
/// after 2 clocks): the ring makes exactly the model's cycles (the counts), and its clocks are
/// within the contract's timing (*Lockstep*: a ring cycle is every processor's cycle): a cycle
/// while the lines hit takes the processor's `max(5, round trip / RingLat)` clocks and one for the
/// output merge, and each line a processor misses holds the cycle at most the memory's latency,
/// the line's beats and two clocks more. The clocks of a frame are at most the sum of both.
#[test]
fn full_speed_clocks_within_the_lockstep_bound() {
    let s = seed(0x61_7274);
    for (v, rtl) in ci_configs() {
        let p = rtl.processor();
        let cache = p.cache_config();
        let beats = u64::from(cache.line_vox * cache.word_w / cache.data_w);
        let per_cycle = 1 + round_trip_clocks(&p)
            .div_ceil(u64::from(rtl.proc.ring_lat))
            .max(5);
        let per_miss = u64::from(FAST_MEMORY.lat.0) + beats + 2;
        let transparent = Scene::with(
            &rtl,
            12,
            Projection::Parallel,
            view_dir(65.0, 20.0),
            &flat_tf(0.0),
        );
        let scenes = [
            ("parallel", Scene::new(&rtl, 12, Projection::Parallel)),
            (
                "perspective",
                Scene::new(&rtl, 12, Projection::Perspective { fov_deg: 40.0 }),
            ),
            ("transparent", transparent),
        ];
        for (name, scene) in scenes {
            let (got, want) = exact_scene(v, rtl, &scene, Some(FAST_MEMORY), 0.0, s);
            let misses: u64 = want.counts.iter().map(|c| c.cache_misses).sum();
            let bound = want.cycles() * per_cycle + misses * per_miss;
            eprintln!(
                "{v} {name} at full speed: {} clocks for {} ring cycles ({:.2} a cycle) and {misses} lines missed; bound {bound} ({per_cycle} a cycle, {per_miss} a miss): {:.2} of it",
                got.clocks,
                want.cycles(),
                got.clocks as f64 / want.cycles() as f64,
                got.clocks as f64 / bound as f64
            );
            assert!(
                got.clocks <= bound,
                "{v} {name}: {} clocks above the lockstep bound {bound}",
                got.clocks
            );
        }
    }
}

/// A random transfer function: transparent below a threshold `t0` (above 0.9 in one frame in
/// eight: the whole head transparent, every ray leaps), then a ramp to a random opacity (1 in
/// one frame in eight: rays end at their first sample).
fn random_tf(rng: &mut ChaCha8Rng) -> TransferFunction {
    let t0 = match rng.random_range(0..8) {
        0 => 0.95,
        _ => rng.random_range(0.05..0.6),
    };
    let alpha = match rng.random_range(0..8) {
        0 => 1.0,
        _ => rng.random_range(0.01..=1.0),
    };
    let mut colour = || std::array::from_fn::<f64, 3, _>(|_| rng.random_range(0.0..=1.0));
    let (a, b) = (colour(), colour());
    let p = |density, c: [f64; 3], alpha| TfPoint {
        density,
        rgba: [c[0], c[1], c[2], alpha],
    };
    TransferFunction::new(vec![p(0.0, [0.0; 3], 0.0), p(t0, a, 0.0), p(1.0, b, alpha)]).unwrap()
}

/// A random view: azimuth and elevation anywhere, or (one in four) along an axis (x, the slabs'
/// axis, half of those).
fn random_view(rng: &mut ChaCha8Rng) -> [f64; 3] {
    if rng.random_range(0..4) == 0 {
        let (az, el) = [(0.0, 0.0), (180.0, 0.0), (90.0, 0.0), (0.0, 90.0)][rng.random_range(0..4)];
        view_dir(az, el)
    } else {
        view_dir(rng.random_range(0.0..360.0), rng.random_range(-90.0..90.0))
    }
}

/// The host's packets of one random frame: a camera's (8-32 pixels a side, fields of view 10-120
/// degrees, either host order) or 256-2,048 random packets, in directions from `random_view`.
const RAYS: RandomRays = RandomRays {
    px: 8..=32,
    fov_deg: 10.0..120.0,
    packets: 256..=2048,
    dir: random_view,
};

/// The totals of one configuration's random frames.
#[derive(Default, Debug)]
struct Totals {
    frames: u64,
    idle_frames: u64,
    rays: u64,
    packets_in: u64,
    finished: u64,
    overflowed: u64,
    sent: u64,
    clocks: u64,
}

/// One random frame (seed `s`) on the ring: the model (`Ring::run_packets_traced`), then the
/// RTL under random memory, output stalls and (a quarter of the frames) an idle host; `reset`:
/// the frame is cut at a random clock first and the ring reset (nothing left in flight). With the
/// host never idle every output ray (finished or returned) is the model's bit for bit and in
/// order, every count and burst; with it idle, every finished ray's packet but the OVERFLOW flag.
fn random_frame(
    variant: &'static Variant,
    rtl: RingRtlConfig,
    s: u64,
    reset: bool,
    t: &mut Totals,
) {
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let p = rtl.processor();
    let vol = head_phantom(p.side() as usize, p.voxel_w).unwrap();
    let proc = Processor::new(p.processor_config(), &vol, &random_tf(&mut rng)).unwrap();
    let (packets, (w, h), kind) = RAYS.draw(&mut rng, proc.volume(), None);
    if packets.is_empty() {
        return;
    }
    let bits: Vec<Bits> = packets.iter().map(|r| r.to_bits().unwrap()).collect();
    let ring = Ring::new(proc, rtl.procs()).unwrap();
    let (want, trace) = ring.run_packets_traced(packets, w, h).unwrap();
    want.check_conservation().unwrap();
    let mem = match rng.random_range(0..4) {
        0 => random_memory(&mut rng, &p),
        _ => Memory {
            lat: (rng.random_range(1..10), rng.random_range(0..20)),
            gaps: (rng.random_range(0..300), rng.random_range(0..300)),
            bw: axi::random_bandwidth(&mut rng, p.data_w / 8),
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
    let setup = |img: &_| mem.read_setup(p.data_w / 8, img, s);
    let mut dut = open_over(variant, rtl, &p, ring.processor(), setup, s);
    if reset {
        let cut = rng.random_range(1..=40 * want.cycles().max(1));
        let part = run_host(&mut dut, &bits, (w, h), b, &mut rng, Some(cut), &what);
        let dropped = axi::reset_leaves_nothing_in_flight(&mut dut, variant, s, false).unwrap();
        eprintln!(
            "{what}: reset after {} clocks, {} of {} rays finished, {dropped} bursts dropped",
            part.clocks,
            sum_of(&part, |c| c.rays_finished),
            want.rays_made
        );
    }
    let got = run_host(&mut dut, &bits, (w, h), b, &mut rng, None, &what);
    let exact = idle == 0.0;
    check_frame(&what, &got, &want, exact);
    let model: Vec<(bool, Bits)> = trace
        .outputs
        .iter()
        .map(|(d, r, _)| (*d, r.to_bits().unwrap()))
        .collect();
    if exact {
        assert_eq!(got.rays.len(), model.len(), "{what}: outputs");
        for (k, (g, m)) in got.rays.iter().zip(&model).enumerate() {
            assert_eq!(g, m, "{what}: output #{k} (finished, ray bits) differs");
        }
        check_bursts(variant, &rtl, &got, &trace.reads, s);
    } else {
        let finished = |rays: &[(bool, Bits)]| {
            let mut f: Vec<RayPacket> = rays
                .iter()
                .filter(|(d, _)| *d)
                .map(|(_, r)| {
                    let mut r = RayPacket::from_bits(r);
                    r.flags &= !4;
                    r
                })
                .collect();
            f.sort_by_key(|r| (r.v, r.u));
            f
        };
        assert!(
            finished(&got.rays) == finished(&model),
            "{what}: the finished rays differ from the model's"
        );
        t.idle_frames += 1;
    }
    t.frames += 1;
    t.rays += want.rays_made;
    t.packets_in += u64::from(sum_of(&got, |c| c.rays_in));
    t.finished += u64::from(sum_of(&got, |c| c.rays_finished));
    t.overflowed += u64::from(sum_of(&got, |c| c.rays_overflowed));
    t.sent += u64::from(sum_of(&got, |c| c.nb_out));
    t.clocks += got.clocks;
}

/// Random frames on the first two built ring configurations of 16^3 and below, up to `rays` rays
/// each (seeds from 8000 + 10,000 x the configuration's index; the third frame across a reset);
/// the totals.
fn random_frames(rays: u64) {
    let small = configs::<RingRtlConfig>()
        .into_iter()
        .filter(|(_, c)| c.processor().side() <= 16)
        .take(2);
    for (i, (variant, rtl)) in small.enumerate() {
        let start = Instant::now();
        let mut t = Totals::default();
        let mut k = 0u64;
        while t.rays < rays {
            let s = seed(8000 + 10_000 * i as u64 + k);
            random_frame(variant, rtl, s, k == 2, &mut t);
            k += 1;
        }
        assert_eq!(t.packets_in, t.finished + t.overflowed, "{variant}: {t:?}");
        eprintln!(
            "{variant}: {} frames (seeds {}..{}; {} with the host idle, one across a reset): {} rays, {} packets in = {} finished + {} overflowed, {} sent between the processors, {} clocks, every output exact; {:.0} s",
            t.frames,
            seed(8000 + 10_000 * i as u64),
            seed(8000 + 10_000 * i as u64 + k - 1),
            t.idle_frames,
            t.rays,
            t.packets_in,
            t.finished,
            t.overflowed,
            t.sent,
            t.clocks,
            start.elapsed().as_secs_f64()
        );
    }
}

/// The acceptance figure: at least 1,000,000 random rays per 16^3-and-below ring configuration
/// (`p1b2v2`, and `p1b2v4` with CUBE5_FULL=1).
#[test]
#[ignore = "sim-full: a million random rays per ring configuration take tens of minutes"]
fn a_million_random_rays_per_config() {
    random_frames(1_000_000);
}

/// The same, 10,000 rays a configuration (the estimate of the million's time).
#[test]
#[ignore = "sim-full: the million's first 10,000 rays (its time estimate)"]
fn ten_thousand_random_rays_per_config() {
    random_frames(10_000);
}

/// The gate-level netlist (Yosys) of the smallest ring renders an exact frame: every pixel,
/// every processor's counts and bursts, rays sent between the processors.
#[test]
#[ignore = "sim-full: the ring's gate-level netlist is a `full` build (many minutes of Yosys and Verilator)"]
fn gate_level_netlist_renders_an_exact_frame() {
    for (v, rtl) in support::gate_configs::<RingRtlConfig>() {
        let t = Instant::now();
        let (got, want) = exact_frame(v, rtl, 12, Projection::Parallel, seed(0x61_7275));
        frame_line(v, "gate level", &got, &want);
        eprintln!(
            "{v}: the frame on the netlist in {:.1} s",
            t.elapsed().as_secs_f64()
        );
    }
}
