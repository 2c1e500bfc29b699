//! The host of gicube_processor's and gicube_ring's co-simulations: the head scene, the
//! subordinate's memory conditions, opening a processor (or a ring of them) over a model's memory
//! image with its tables loaded, the host loop (offers its list, collects finished rays, re-offers
//! returned ones) and the checks of a processor's pass against the model (the pixels, rays in =
//! finished + overflowed, the counts, the AR bursts).

use super::{axi, axi_mem_setup, compare_bursts};
use cube5_model::camera::Camera;
use cube5_model::phantom::head_phantom;
use cube5_model::transfer::TransferFunction;
use cube5_model::unit::StreamCodec;
use cube5_model::units::cube5_axi_rd::{AxiMemImage, Burst};
use cube5_model::units::cube5_shader::Phong;
use cube5_model::units::gicube_packet_loop::{RayPacket, PACKET_WORDS};
use cube5_model::units::gicube_processor::{
    half_tags, host_rays, HostOrder, HostRay, Processor, ProcessorFrame, ProcessorOut,
    ProcessorRtlConfig, Projection,
};
use cube5_model::units::gicube_ring::RingOut;
use cube5_model::volume::Volume;
use cube5_tb::harness::count_differing;
use cube5_tb::rtl::{AxiMemSetup, RtlStream, Traffic};
use cube5_tb::Variant;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;

pub type Bits = [u32; PACKET_WORDS];

/// The direction from the eye into the scene at `azimuth` and `elevation` (degrees).
pub fn view_dir(azimuth: f64, elevation: f64) -> [f64; 3] {
    let (a, e) = (azimuth.to_radians(), elevation.to_radians());
    [-e.cos() * a.cos(), -e.cos() * a.sin(), -e.sin()]
}

/// The host's packets of one random frame, drawn from `rng`: a camera's (half the frames: parallel
/// or perspective, `px` pixels a side, a direction from `dir`) or `packets` rays from random starts
/// in the voxel-centre box (a third on one of its faces) in directions from `dir`, pixels in rows
/// of 64. The processor's and the ring's random tests each keep their own ranges (and so their own
/// random streams).
pub struct RandomRays {
    pub px: std::ops::RangeInclusive<u32>,
    pub fov_deg: std::ops::Range<f64>,
    pub packets: std::ops::RangeInclusive<u32>,
    pub dir: fn(&mut ChaCha8Rng) -> [f64; 3],
}

impl RandomRays {
    /// The packets, the image's side and a description; `order`: the camera's host order, or
    /// `None` to draw it after the camera.
    pub fn draw(
        &self,
        rng: &mut ChaCha8Rng,
        vol: &Volume,
        order: Option<HostOrder>,
    ) -> (Vec<RayPacket>, (u32, u32), String) {
        if rng.random_bool(0.5) {
            let px = rng.random_range(self.px.clone());
            let proj = if rng.random_bool(0.5) {
                Projection::Parallel
            } else {
                Projection::Perspective {
                    fov_deg: rng.random_range(self.fov_deg.clone()),
                }
            };
            let cam = Camera::new((self.dir)(rng).into(), vol.dims, vol.spacing, px, px);
            let order = order.unwrap_or_else(|| {
                if rng.random_bool(0.5) {
                    HostOrder::RowMajor
                } else {
                    HostOrder::Reversed
                }
            });
            let rays = host_rays(vol, &cam, proj, order).unwrap();
            let packets = rays.iter().map(|r| Processor::packet(r).unwrap()).collect();
            (packets, (px, px), format!("{proj:?} {px}x{px}"))
        } else {
            let hi = vol.dims[0] as f64 - 1.0;
            let n: u32 = rng.random_range(self.packets.clone());
            let packets = (0..n)
                .map(|i| {
                    let mut entry: [f64; 3] = std::array::from_fn(|_| rng.random_range(0.0..=hi));
                    if rng.random_range(0..3) == 0 {
                        entry[rng.random_range(0..3)] = if rng.random_bool(0.5) { 0.0 } else { hi };
                    }
                    let ray = HostRay {
                        px: i % 64,
                        py: i / 64,
                        entry: entry.into(),
                        dir: (self.dir)(rng).into(),
                    };
                    Processor::packet(&ray).unwrap()
                })
                .collect();
            (packets, (64, n.div_ceil(64)), format!("{n} random packets"))
        }
    }
}

/// The head phantom at `rtl`'s side and voxel width in `rtl`'s processor, seen from azimuth 65,
/// elevation 20, `px` pixels a side; with `Shade` lit by two lights (the viewer's map) and tagged
/// in two halves (`half_tags`: the tag's colour in the half `x >= N/2`).
pub fn head_scene(rtl: &ProcessorRtlConfig, px: u32) -> (Processor, Camera) {
    let vol = head_phantom(rtl.side() as usize, rtl.voxel_w).unwrap();
    let dir = view_dir(65.0, 20.0);
    let cam = Camera::new(dir.into(), vol.dims, vol.spacing, px, px);
    let tf = TransferFunction::head_default();
    let mut proc = Processor::new(rtl.processor_config(), &vol, &tf).unwrap();
    if rtl.shade == 1 {
        let phong = Phong {
            view: dir.map(|c| -c),
            ..Phong::two_lights()
        };
        let tags = (rtl.tag_w > 0).then(|| half_tags(&vol));
        proc.set_shading(&phong, tags).unwrap();
    }
    (proc, cam)
}

/// The host's packets of `cam`'s rays through `proc`'s volume, in the host's order.
pub fn host_packets(proc: &Processor, cam: &Camera, proj: Projection) -> Vec<Bits> {
    host_rays(proc.volume(), cam, proj, proc.config().host_order)
        .unwrap()
        .iter()
        .map(|r| Processor::packet(r).unwrap().to_bits().unwrap())
        .collect()
}

/// How the memory answers: latency `fixed + U(0..random)` cycles, AR and R gaps (per mille), a
/// bandwidth limit of `num / den` bytes per cycle (0: none).
#[derive(Clone, Copy, Debug)]
pub struct Memory {
    pub lat: (u32, u32),
    pub gaps: (u32, u32),
    pub bw: (u32, u32),
}

impl Memory {
    /// The subordinate of `data_bytes`-wide beats over `img` answering reads as `self` says (no
    /// write gaps, no declared outstanding count).
    pub fn read_setup(self, data_bytes: u32, img: &AxiMemImage, s: u64) -> AxiMemSetup {
        axi_mem_setup((data_bytes, 32), img, self.lat, self.gaps, self.bw, s)
    }
}

/// A memory that answers at once: latency 2, no gaps, no bandwidth limit.
pub const FAST_MEMORY: Memory = Memory {
    lat: (2, 0),
    gaps: (0, 0),
    bw: (0, 1),
};

/// The clocks of a ray's round trip through a processor while its lines hit (gicube_processor.md,
/// *Timing*): the front end's 3, the cache's 2 and the sample's latency (22; 28 with `Shade`, one
/// more with `Jitter`; the deposit's 5 beside it with `Light`).
pub fn round_trip_clocks(rtl: &ProcessorRtlConfig) -> u64 {
    3 + 2 + 22 + 6 * u64::from(rtl.shade) + u64::from(rtl.jitter) + 5 * u64::from(rtl.light)
}

/// Two host behaviours and whether the counts stay exact under them: the output stalled 60 %
/// (the host offering at once: every count), and the host idle half the time (only the image and
/// the ray totals: idle cycles move the sorter).
pub const IDLE_AND_STALL: [(Behaviour, bool); 2] = [
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
];

/// Random conditions: latency 10-200, gaps of up to 30 %, a bandwidth limit on half the seeds.
pub fn random_memory(rng: &mut ChaCha8Rng, rtl: &ProcessorRtlConfig) -> Memory {
    Memory {
        lat: (10, 190),
        gaps: (rng.random_range(0..300), rng.random_range(0..300)),
        bw: axi::random_bandwidth(rng, rtl.data_w / 8),
    }
}

/// An output item of the host's unit (a processor, a ring): a finished ray or one returned with
/// OVERFLOW set, or (a processor's, `Light`) a flush's item.
pub trait HostOut: Default {
    fn done(&self) -> bool;
    fn ray(&self) -> &Bits;
    fn flush(&self) -> bool;
}

impl HostOut for ProcessorOut {
    fn done(&self) -> bool {
        self.done
    }
    fn ray(&self) -> &Bits {
        &self.ray
    }
    fn flush(&self) -> bool {
        self.flush
    }
}

impl HostOut for RingOut {
    fn done(&self) -> bool {
        self.done
    }
    fn ray(&self) -> &Bits {
        &self.ray
    }
    fn flush(&self) -> bool {
        false
    }
}

/// What the RTL did in a pass: the pixels, the last output (its counts), every output ray in
/// order (finished: `true`), the clocks from the first offer to the last output, the AR bursts.
pub struct RtlFrame<O = ProcessorOut> {
    pub rgb: Vec<[u16; 3]>,
    pub last: O,
    pub outputs: u64,
    pub rays: Vec<(bool, Bits)>,
    pub clocks: u64,
    pub ars: Vec<cube5_tb::rtl::ArHandshake>,
}

/// How the host and the consumer behave: the probability that the host, having a ray, does not
/// offer it yet in a clock, and that the output is not taken.
#[derive(Clone, Copy, Debug)]
pub struct Behaviour {
    pub idle: f64,
    pub stall: f64,
}

/// The subordinate as `mem` says, the write channels' gaps as the read channels' (AW and B as
/// AR, W as R).
pub fn mem_setup(rtl: &ProcessorRtlConfig, img: &AxiMemImage, mem: Memory, s: u64) -> AxiMemSetup {
    AxiMemSetup {
        declared_outstanding: rtl.outstanding,
        aw_gap_permille: mem.gaps.0,
        w_gap_permille: mem.gaps.1,
        b_gap_permille: mem.gaps.0,
        ..mem.read_setup(rtl.data_w / 8, img, s)
    }
}

/// Opens `variant` over `proc`'s memory image (`Processor::rtl_memory`) and loads its tables,
/// flags and (`Light`) GI registers.
pub fn open_proc(
    variant: &'static Variant,
    rtl: ProcessorRtlConfig,
    proc: &Processor,
    mem: Memory,
    s: u64,
) -> RtlStream<ProcessorRtlConfig> {
    open_over(
        variant,
        rtl,
        &rtl,
        proc,
        |img| mem_setup(&rtl, img, mem, s),
        s,
    )
}

/// Opens `variant` (`codec`: a processor's or a ring's) over `proc`'s memory image, the
/// subordinate as `setup` makes it for the image, and loads `proc`'s registers at `rtl` (the
/// processor's configuration, each of a ring's).
pub fn open_over<C: StreamCodec>(
    variant: &'static Variant,
    codec: C,
    rtl: &ProcessorRtlConfig,
    proc: &Processor,
    setup: impl FnOnce(&AxiMemImage) -> AxiMemSetup,
    s: u64,
) -> RtlStream<C> {
    let img = proc.rtl_memory().unwrap().expect("the RTL's cache");
    let setup = setup(&img);
    let mut dut = RtlStream::new(variant, codec, s as u32).unwrap();
    dut.axi_setup(&setup).unwrap();
    dut.axi_load(img.base, &img.bytes).unwrap();
    load_config(&mut dut, rtl, proc);
    dut
}

/// The tables, empty flags and GI registers of `proc` written to the processor's registers.
pub fn load_config<C: StreamCodec>(
    dut: &mut RtlStream<C>,
    rtl: &ProcessorRtlConfig,
    proc: &Processor,
) {
    for (a, d) in proc.rtl_config_writes(rtl).unwrap() {
        dut.write_config(a, &d).unwrap();
    }
}

/// The host loop, one clock per call of the RTL: offers the head of its list (held until
/// taken), collects finished rays into the `w`-wide image of `h` rows and appends overflowed rays
/// to its list; stops after `stop_after` clocks if given, else when every ray has finished.
/// `what` names the pass in every failure (variant, seed).
#[allow(clippy::too_many_arguments)]
pub fn run_host<C: StreamCodec<In = Bits, Out: HostOut>>(
    dut: &mut RtlStream<C>,
    rays: &[Bits],
    (w, h): (u32, u32),
    b: Behaviour,
    rng: &mut ChaCha8Rng,
    stop_after: Option<u64>,
    what: &str,
) -> RtlFrame<C::Out> {
    host_loop(
        dut,
        rays,
        (w, h),
        Some(b.idle),
        b.stall,
        rng,
        stop_after,
        what,
    )
}

/// The host loop of `run_host` with a host that offers its head at once, never idle (and draws
/// nothing for it), until every ray has finished.
pub fn run_eager_host<C: StreamCodec<In = Bits, Out: HostOut>>(
    dut: &mut RtlStream<C>,
    rays: &[Bits],
    (w, h): (u32, u32),
    stall: f64,
    rng: &mut ChaCha8Rng,
    what: &str,
) -> RtlFrame<C::Out> {
    host_loop(dut, rays, (w, h), None, stall, rng, None, what)
}

/// `run_host`; `idle: None`, the host offers its head at once without a draw.
#[allow(clippy::too_many_arguments)]
fn host_loop<C: StreamCodec<In = Bits, Out: HostOut>>(
    dut: &mut RtlStream<C>,
    rays: &[Bits],
    (w, h): (u32, u32),
    idle: Option<f64>,
    stall: f64,
    rng: &mut ChaCha8Rng,
    stop_after: Option<u64>,
    what: &str,
) -> RtlFrame<C::Out> {
    let mut list: VecDeque<Bits> = rays.iter().copied().collect();
    let mut rgb = vec![[0u16; 3]; (w * h) as usize];
    let mut seen = vec![false; (w * h) as usize];
    let (mut finished, mut outputs, mut clocks) = (0usize, 0u64, 0u64);
    let mut out = Vec::new();
    let mut offering = false;
    let mut last = C::Out::default();
    let limit = 100_000 + 40_000 * rays.len() as u64;
    while finished < rays.len() && stop_after.is_none_or(|s| clocks < s) {
        assert!(clocks < limit, "{what}: no progress after {clocks} clocks");
        if !list.is_empty() && !offering {
            offering = idle.is_none_or(|p| !rng.random_bool(p));
        }
        let items: Vec<Bits> = if offering { vec![list[0]] } else { Vec::new() };
        let traffic = Traffic {
            idle: vec![0],
            stall: vec![u8::from(rng.random_bool(stall))],
        };
        let expect = u64::from(items.is_empty());
        let d = dut.drive(&items, &traffic, expect, 1).unwrap();
        clocks += 1;
        assert_eq!(
            d.stats.protocol_errors, 0,
            "{what}: a stalled output changed at clock {clocks}"
        );
        if d.stats.consumed == 1 {
            list.pop_front();
            offering = false;
        }
        for o in d.outputs {
            let o = o.value;
            assert!(!o.flush(), "{what}: a flush item without a flush");
            outputs += 1;
            let (done, ray) = (o.done(), *o.ray());
            out.push((done, ray));
            let r = RayPacket::from_bits(&ray);
            if done {
                let i = (u32::from(r.v) * w + u32::from(r.u)) as usize;
                assert!(!seen[i], "{what}: pixel ({}, {}) finished twice", r.u, r.v);
                seen[i] = true;
                rgb[i] = r.color;
                finished += 1;
            } else {
                assert!(
                    r.flags & 4 != 0,
                    "{what}: an overflowed ray has OVERFLOW set"
                );
                list.push_back(ray);
            }
            last = o;
        }
    }
    let c = dut.axi_counters();
    assert_eq!(
        c.protocol_errors,
        0,
        "{what}: AXI checker: {}",
        dut.axi_first_error()
    );
    RtlFrame {
        rgb,
        last,
        outputs,
        rays: out,
        clocks,
        ars: dut.axi_take_ar().unwrap(),
    }
}

/// The image and the conservation of rays; with `exact_counts` every count equals the model's.
pub fn check_frame(what: &str, got: &RtlFrame, want: &ProcessorFrame, exact_counts: bool) {
    let c = &want.counts;
    let l = &got.last;
    let differ = count_differing(&got.rgb, &want.rgb);
    assert_eq!(differ, 0, "{what}: {differ} pixels differ from the model");
    assert_eq!(
        u64::from(l.rays_in),
        u64::from(l.rays_finished) + u64::from(l.rays_overflowed),
        "{what}: RTL rays in = finished + overflowed ({l:?})"
    );
    assert_eq!(
        c.rays_in,
        c.rays_finished + c.rays_overflowed,
        "{what}: model rays in = finished + overflowed"
    );
    assert_eq!(
        u64::from(l.rays_finished),
        c.rays_made,
        "{what}: every ray finished"
    );
    // A ray's samples and leaps do not depend on the order.
    assert_eq!(
        (u64::from(l.samples), u64::from(l.leaps)),
        (c.samples, c.leaps),
        "{what}: samples and leaps"
    );
    if exact_counts {
        assert_eq!(
            (
                u64::from(l.rays_in),
                u64::from(l.rays_overflowed),
                u64::from(l.cycles)
            ),
            (c.rays_in, c.rays_overflowed, c.cycles),
            "{what}: rays in, overflowed and processor cycles equal the model's"
        );
        assert_eq!(
            (u64::from(l.cache_hits), u64::from(l.cache_misses)),
            (c.cache_hits, c.cache_misses),
            "{what}: cache hits and misses equal the model's"
        );
    }
    // Photons scattered (Scatter = 1; a function of each ray's packets, whatever the order).
    assert_eq!(
        u64::from(l.scatterings),
        c.scatterings,
        "{what}: scatterings equal the model's"
    );
}

/// The AR bursts of a pass from reset equal the model cache's, in order.
pub fn check_bursts(
    variant: &'static Variant,
    rtl: &ProcessorRtlConfig,
    got: &RtlFrame,
    want: &[Burst],
    s: u64,
) {
    let size = (rtl.data_w / 8).trailing_zeros();
    let n = compare_bursts(&got.ars, "AR", want, size, variant, s, |k| {
        format!("the frame's burst #{k}")
    })
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(n, want.len(), "{variant}: every missed line read once");
}
