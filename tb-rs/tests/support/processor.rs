//! The host of gicube_processor's co-simulations: the subordinate's memory conditions, opening a
//! processor over a model's memory image with its tables loaded, the host loop (offers its list,
//! collects finished rays, re-offers overflowed ones) and the checks of a pass against the model
//! (the pixels, rays in = finished + overflowed, the counts, the AR bursts).

use super::{axi, axi_mem_setup, compare_bursts};
use cube5_model::units::cube5_axi_rd::{AxiMemImage, Burst};
use cube5_model::units::gicube_packet_loop::{RayPacket, PACKET_WORDS};
use cube5_model::units::gicube_processor::{
    Processor, ProcessorFrame, ProcessorOut, ProcessorRtlConfig,
};
use cube5_tb::rtl::{AxiMemSetup, RtlStream, Traffic};
use cube5_tb::Variant;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;

pub type Bits = [u32; PACKET_WORDS];

/// How the memory answers: latency `fixed + U(0..random)` cycles, AR and R gaps (per mille), a
/// bandwidth limit of `num / den` bytes per cycle (0: none).
#[derive(Clone, Copy, Debug)]
pub struct Memory {
    pub lat: (u32, u32),
    pub gaps: (u32, u32),
    pub bw: (u32, u32),
}

/// Random conditions: latency 10-200, gaps of up to 30 %, a bandwidth limit on half the seeds.
pub fn random_memory(rng: &mut ChaCha8Rng, rtl: &ProcessorRtlConfig) -> Memory {
    Memory {
        lat: (10, 190),
        gaps: (rng.random_range(0..300), rng.random_range(0..300)),
        bw: axi::random_bandwidth(rng, rtl.data_w / 8),
    }
}

/// What the RTL did in a pass: the pixels, the last output's counts, every output ray in order
/// (finished: `true`), the clocks from the first offer to the last output, the AR bursts.
pub struct RtlFrame {
    pub rgb: Vec<[u16; 3]>,
    pub last: ProcessorOut,
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
        ..axi_mem_setup((rtl.data_w / 8, 32), img, mem.lat, mem.gaps, mem.bw, s)
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
    let img = proc.rtl_memory().unwrap().expect("the RTL's cache");
    let setup = mem_setup(&rtl, &img, mem, s);
    let mut dut = RtlStream::new(variant, rtl, s as u32).unwrap();
    dut.axi_setup(&setup).unwrap();
    dut.axi_load(img.base, &img.bytes).unwrap();
    load_config(&mut dut, &rtl, proc);
    dut
}

/// The tables, empty flags and GI registers of `proc` written to the processor's registers.
pub fn load_config(
    dut: &mut RtlStream<ProcessorRtlConfig>,
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
pub fn run_host(
    dut: &mut RtlStream<ProcessorRtlConfig>,
    rays: &[Bits],
    (w, h): (u32, u32),
    b: Behaviour,
    rng: &mut ChaCha8Rng,
    stop_after: Option<u64>,
    what: &str,
) -> RtlFrame {
    let mut list: VecDeque<Bits> = rays.iter().copied().collect();
    let mut rgb = vec![[0u16; 3]; (w * h) as usize];
    let mut seen = vec![false; (w * h) as usize];
    let (mut finished, mut outputs, mut clocks) = (0usize, 0u64, 0u64);
    let mut out = Vec::new();
    let mut offering = false;
    let mut last = ProcessorOut::default();
    let limit = 100_000 + 40_000 * rays.len() as u64;
    while finished < rays.len() && stop_after.is_none_or(|s| clocks < s) {
        assert!(clocks < limit, "{what}: no progress after {clocks} clocks");
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
            assert!(!o.flush, "{what}: a flush item without a flush");
            outputs += 1;
            last = o;
            out.push((o.done, o.ray));
            let r = RayPacket::from_bits(&o.ray);
            if o.done {
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
                list.push_back(o.ray);
            }
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
    let differ = got
        .rgb
        .iter()
        .zip(&want.rgb)
        .filter(|(a, b)| a != b)
        .count();
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
