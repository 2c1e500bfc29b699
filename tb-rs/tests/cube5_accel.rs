//! Co-simulation of the accelerator top `cube5_accel` (issue 12; docs/accel.md): the volume in the
//! test bench's AXI4 memory in the blocked layout, tables and registers written over AXI4-Lite by
//! the host driver, a frame started, the interrupt awaited, the image read back from the memory
//! and compared byte for byte with the frame model's image in pixel codes. Driver:
//! `cube5_tb::accel`.
//!
//!     CUBE5_TOPS=cube5_accel cargo test --release -p cube5-tb --test cube5_accel

mod support;

use cube5_model::accel_host::{AccelHost, HostError};
use cube5_model::phantom::{bubbles_phantom, head_phantom};
use cube5_model::regs::cube5_accel::CODE_FRAME;
use cube5_model::units::cube5_skewmem::BlockLut;
use cube5_model::volume::Volume;
use cube5_tb::accel::{AccelBench, AccelRtl, FrameRun, MemEnv};
use cube5_tb::frame::{Expected, Look, Render};
use cube5_tb::TbError;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::rc::Rc;
use support::seed;

fn must<T>(r: Result<T, TbError>) -> T {
    r.unwrap_or_else(|e| panic!("{e}"))
}

fn rtl(p: usize, n: usize) -> AccelRtl {
    AccelRtl::with(p, n).unwrap_or_else(|| panic!("no cube5_accel variant with P = {p} for {n}^3"))
}

/// Faces (DX = DY = 0), exactly 45 degrees (DX = 2^16), obliques with DX < 0 and a reversed sweep.
const VIEWS: &[(&str, [f64; 3])] = &[
    ("+z", [0.0, 0.0, 1.0]),
    ("-x", [-1.0, 0.0, 0.0]),
    ("45 xz", [1.0, 0.0, 1.0]),
    ("oblique dx<0", [-0.6, 0.3, 1.0]),
    ("oblique -z", [0.37, 0.81, -1.0]),
];

type View = (&'static str, [f64; 3]);

/// A DDR-like memory: latency `lat` + U(0..20), no gaps, `bw` bytes per cycle shared by reads and
/// writes (0: unlimited).
fn ddr(lat: u32, bw: u32) -> MemEnv {
    MemEnv {
        latency: (lat, 20),
        gaps: [0; 5],
        bw: (bw, 1),
        host_stall: Vec::new(),
    }
}

/// A bench on one build with a volume in its memory and a seeded generator for the memories.
struct Case {
    bench: AccelBench,
    vol: Rc<Volume>,
    /// The volume's block LUT (empty blocks at threshold 0: they read as zeros, as the model
    /// sees them).
    lut: BlockLut,
    rng: ChaCha8Rng,
}

impl Case {
    fn new(rtl: AccelRtl, vol: Volume, s: u64) -> Self {
        let lut = BlockLut::from_volume(&vol, rtl.fetch.block_dim as usize, 0).unwrap();
        Self {
            bench: must(AccelBench::new(rtl, s)),
            vol: Rc::new(vol),
            lut,
            rng: ChaCha8Rng::seed_from_u64(s),
        }
    }

    /// Another volume in the memory.
    fn with(mut self, vol: Volume) -> Self {
        self.lut = BlockLut::from_volume(&vol, self.bench.rtl.fetch.block_dim as usize, 0).unwrap();
        self.vol = Rc::new(vol);
        self
    }

    fn expect(&self, view: View, render: Render) -> Expected {
        let rtl = &self.bench.rtl.frame;
        Expected::new(rtl, &self.vol, view.0, view.1, render, &Look::default()).unwrap()
    }

    /// One frame under `env`: rendered, read back from memory, compared; its figures printed.
    fn frame(&mut self, view: View, render: Render, env: &MemEnv, what: &str) -> FrameRun {
        let e = self.expect(view, render);
        let mem_seed = self.rng.random();
        let img_base = must(self.bench.start(&e, &self.vol, &self.lut, env, mem_seed));
        let run = must(self.bench.finish(&e, img_base, mem_seed));
        let rtl = self.bench.rtl;
        eprintln!(
            "{}: {}^3 {} {render:?}{what}: {} cycles, {} samples, {:.3} samples/clock/pipeline; {} read bursts ({} beats), {} write bursts",
            rtl.variant,
            self.vol.dims[0],
            view.0,
            run.cycles,
            run.samples,
            run.rate(rtl.p),
            run.ar,
            run.r_beats,
            run.aw
        );
        run
    }

    /// Frames each under its own random memory (latency 10..200, gaps on all five channels, the
    /// host's B and R back-pressured).
    fn random(&mut self, frames: &[(View, Render)]) {
        for &(view, render) in frames {
            let env = MemEnv::random(&mut self.rng);
            self.frame(view, render, &env, "");
        }
    }
}

use Render::{Composite, Mip};

/// The 64^3 head phantom at P = 4: every view composite (shaded), three in MIP: the image in
/// memory bit-exact.
#[test]
fn head_64_p4_every_view_composite_and_mip() {
    let s = seed(0xacce1);
    let mut c = Case::new(rtl(4, 64), head_phantom(64, 12).unwrap(), s);
    let mut frames: Vec<(View, Render)> = VIEWS.iter().map(|&v| (v, Composite)).collect();
    frames.extend([VIEWS[0], VIEWS[2], VIEWS[4]].map(|v| (v, Mip)));
    c.random(&frames);
}

/// A blob with holes (the bubbles phantom, 64^3) at P = 4: a face, 45 degrees, an oblique view.
#[test]
fn bubbles_64_p4() {
    let s = seed(0xacce2);
    let mut c = Case::new(rtl(4, 64), bubbles_phantom(64, 12).unwrap(), s);
    c.random(&[
        (VIEWS[1], Composite),
        (VIEWS[2], Mip),
        (VIEWS[3], Composite),
    ]);
}

/// P = 1: the 64^3 head at 45 degrees (composite) and an oblique view with DX < 0 (MIP).
#[test]
fn head_64_p1() {
    let s = seed(0xacce3);
    let mut c = Case::new(rtl(1, 64), head_phantom(64, 12).unwrap(), s);
    c.random(&[(VIEWS[2], Composite), (VIEWS[3], Mip)]);
}

/// The synthesizable configuration (16^3, the frame's narrow widths): the 16^3 head in every
/// view, composite and MIP.
#[test]
fn narrow_16_p4() {
    let s = seed(0xacce9);
    let mut c = Case::new(rtl(4, 16), head_phantom(16, 8).unwrap(), s);
    let frames: Vec<(View, Render)> = VIEWS
        .iter()
        .flat_map(|&v| [(v, Composite), (v, Mip)])
        .collect();
    c.random(&frames);
}

/// A reset in the middle of a frame (reads and writes in flight are dropped on both sides; none
/// is outstanding after it), then the tables reloaded and the same frame exact.
#[test]
fn reset_mid_frame_then_an_exact_frame() {
    let s = seed(0xacce4);
    let mut c = Case::new(rtl(4, 64), head_phantom(64, 12).unwrap(), s);
    let env = MemEnv::random(&mut c.rng);
    let e = c.expect(VIEWS[4], Composite);
    must(c.bench.start(&e, &c.vol, &c.lut, &env, s));
    must(c.bench.idle(30_000));
    assert!(
        c.bench.dut.axi_counters().in_flight > 0,
        "reads in flight at the reset"
    );
    c.bench.reset();
    assert_eq!(
        c.bench.dut.axi_counters().in_flight,
        0,
        "no read outstanding after the reset"
    );
    let wr = c.bench.dut.axi_wr_counters();
    assert_eq!(wr.in_flight, 0, "no write outstanding after the reset");
    c.frame(VIEWS[4], Composite, &env, " after a reset mid-frame");
}

/// A frame whose last section the frame refuses (36 anchors in sections of 16: the last has 4,
/// fewer than 2P): the frame ends with IrqStatus.error and code Frame (the writer is fed zeros
/// for the rows the core commanded, nothing hangs) only once the data path has drained, and the
/// next frame (new volume, new block LUT) is exact without a reset.
#[test]
fn a_section_the_frame_refuses_ends_the_frame_with_an_error() {
    let s = seed(0xacceb);
    let mut c = Case::new(rtl(4, 64), head_phantom(36, 12).unwrap(), s);
    let e = c.expect(VIEWS[0], Composite);
    must(c.bench.start(&e, &c.vol, &c.lut, &MemEnv::quiet(), s));
    must(c.bench.wait_irq(400_000));
    let mut host = AccelHost::new(&mut c.bench, 0);
    assert!(
        matches!(host.wait_done(1), Err(HostError::Frame(_))),
        "the frame ends with an error"
    );
    assert_eq!(host.status_code().unwrap(), CODE_FRAME);
    let mut c = c.with(head_phantom(32, 12).unwrap());
    c.frame(
        VIEWS[2],
        Composite,
        &MemEnv::quiet(),
        " after a refused section",
    );
}

/// The comparison fails when the model disagrees: a MIP frame against the composite image.
#[test]
fn the_check_fails_when_the_model_disagrees() {
    let s = seed(0xacce5);
    let mut c = Case::new(rtl(4, 64), head_phantom(64, 12).unwrap(), s);
    let (e, other) = (c.expect(VIEWS[0], Mip), c.expect(VIEWS[0], Composite));
    let img_base = must(c.bench.start(&e, &c.vol, &c.lut, &MemEnv::quiet(), s));
    match c.bench.finish(&other, img_base, s) {
        Err(TbError::Mismatch(m)) => eprintln!("as it should: {}", m.what),
        other => panic!("a MIP image passed as the composite one: {other:?}"),
    }
}

/// Whole-frame cycles of the throughput configuration (P = 4, 4^3 blocks, 32-anchor sections,
/// 128-bit bus) on the 64^3 head: a fast memory and a DDR-like one (latency 100..120, 12
/// bytes/cycle), a face and 45 degrees; every image exact.
#[test]
fn throughput_of_the_wide_configuration() {
    let s = seed(0xacce6);
    let rtl = AccelRtl::widest(4).expect("a P = 4 build of cube5_accel");
    let mut c = Case::new(rtl, head_phantom(64, 12).unwrap(), s);
    for (env, what) in [
        (ddr(20, 0), ", fast memory"),
        (ddr(100, 12), ", DDR-like 12 B/cycle"),
    ] {
        for view in [VIEWS[0], VIEWS[2]] {
            let rate = c.frame(view, Composite, &env, what).rate(rtl.p);
            assert!(
                rate > 0.8,
                "{}: {rate:.3} samples/clock/pipeline",
                rtl.variant
            );
        }
    }
}

/// 128^3 frames (head phantom and bubbles) at P = 4 on the throughput configuration: every view,
/// composite and MIP alternately, random memories; then 45 degrees with the DDR-like memory.
#[test]
#[ignore = "sim-full: 128^3 frames, about 20 s each"]
fn frames_128_p4() {
    let s = seed(0xacce7);
    let rtl = AccelRtl::widest(4).expect("a P = 4 build of cube5_accel");
    let frames: Vec<(View, Render)> = VIEWS
        .iter()
        .enumerate()
        .map(|(n, &v)| (v, [Composite, Mip][n % 2]))
        .collect();
    let mut c = Case::new(rtl, head_phantom(128, 12).unwrap(), s);
    for next in [Some(bubbles_phantom(128, 12).unwrap()), None] {
        c.random(&frames);
        c.frame(VIEWS[2], Composite, &ddr(100, 12), ", DDR-like 12 B/cycle");
        if let Some(v) = next {
            c = c.with(v);
        }
    }
}

/// P = 8 at 128^3 (head, 45 degrees and an oblique view, composite and MIP) and one 256^3 head
/// frame at 45 degrees with the DDR-like memory.
#[test]
#[ignore = "sim-full: P = 8 and 256^3 frames, minutes each"]
fn frames_p8_and_256() {
    let s = seed(0xacce8);
    let rtl = AccelRtl::widest(8).expect("a P = 8 build of cube5_accel");
    let mut c = Case::new(rtl, head_phantom(128, 12).unwrap(), s);
    c.random(&[(VIEWS[2], Composite), (VIEWS[3], Mip)]);
    let mut c = c.with(head_phantom(256, 12).unwrap());
    c.frame(VIEWS[2], Composite, &ddr(100, 12), ", DDR-like 12 B/cycle");
}
