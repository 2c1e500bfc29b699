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
use cube5_model::regs::cube5_accel::{CODE_ABORTED, CODE_FRAME};
use cube5_model::units::cube5_skewmem::BlockLut;
use cube5_model::volume::Volume;
use cube5_tb::accel::{AccelBench, AccelRtl, FrameRun, MemEnv, TOP};
use cube5_tb::frame::{blob_volume, dense_tf, resampled, Expected, Look, Render, VIEWS};
use cube5_tb::variants::gate_variants_of;
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

/// The acceptance view called `name` (`cube5_tb::frame::VIEWS`: the six faces, exactly 45
/// degrees, obliques with DX < 0 and reversed sweeps).
fn view(name: &str) -> View {
    *VIEWS
        .iter()
        .find(|v| v.0 == name)
        .unwrap_or_else(|| panic!("no view {name}"))
}

/// The views of the lighter runs: a face, another face (a sweep along x), exactly 45 degrees, an
/// oblique view with DX < 0 and a reversed sweep, an oblique view with a reversed sweep.
fn some_views() -> [View; 5] {
    ["+z", "-x", "45 xz", "oblique z", "oblique x"].map(view)
}

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
        self.expect_with(view, render, &Look::default())
    }

    fn expect_with(&self, view: View, render: Render, look: &Look) -> Expected {
        let rtl = &self.bench.rtl.frame;
        Expected::new(rtl, &self.vol, view.0, view.1, render, look).unwrap()
    }

    /// One frame under `env`: rendered, read back from memory, compared; its figures printed.
    fn frame(&mut self, view: View, render: Render, env: &MemEnv, what: &str) -> FrameRun {
        let e = self.expect(view, render);
        self.frame_of(&e, env, what)
    }

    /// The frame of `e` under `env`; the image's rows packed (ImgPitch 0) or, one frame in
    /// three, a random legal pitch up to 7 row alignments longer than a row.
    fn frame_of(&mut self, e: &Expected, env: &MemEnv, what: &str) -> FrameRun {
        let ctrl = self.bench.rtl.ctrl;
        let row = ctrl.row_pixels(e.w as u32) as u64 * ctrl.pixel_bytes as u64;
        self.bench.pitch = if self.rng.random_bool(0.3) {
            (row + ctrl.row_align() * self.rng.random_range(1..8)) as u32
        } else {
            0
        };
        let mem_seed = self.rng.random();
        let img_base = must(self.bench.start(e, &self.vol, &self.lut, env, mem_seed));
        let run = must(self.bench.finish(e, img_base, mem_seed));
        let rtl = self.bench.rtl;
        let [nx, ny, nz] = self.vol.dims;
        let render = e.units.render;
        eprintln!(
            "{}: {nx}x{ny}x{nz} {} {render:?}{}{what}, pitch {}: {} cycles, {} samples, {:.3} samples/clock/pipeline; {} read bursts ({} beats), {} write bursts",
            rtl.variant,
            e.view,
            if e.units.tf2d { " 2-D TF" } else { "" },
            self.bench.pitch_bytes(e),
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
    let mut frames: Vec<(View, Render)> =
        some_views().into_iter().map(|v| (v, Composite)).collect();
    frames.extend([view("+z"), view("45 xz"), view("oblique x")].map(|v| (v, Mip)));
    c.random(&frames);
}

/// A blob with holes (the bubbles phantom, 64^3) at P = 4: a face, 45 degrees, an oblique view.
#[test]
fn bubbles_64_p4() {
    let s = seed(0xacce2);
    let mut c = Case::new(rtl(4, 64), bubbles_phantom(64, 12).unwrap(), s);
    c.random(&[
        (view("-x"), Composite),
        (view("45 xz"), Mip),
        (view("oblique z"), Composite),
    ]);
}

/// P = 1: the 64^3 head at 45 degrees (composite) and an oblique view with DX < 0 (MIP).
#[test]
fn head_64_p1() {
    let s = seed(0xacce3);
    let mut c = Case::new(rtl(1, 64), head_phantom(64, 12).unwrap(), s);
    c.random(&[(view("45 xz"), Composite), (view("oblique z"), Mip)]);
}

/// The synthesizable configuration (16^3, the frame's narrow widths): the 16^3 head in every
/// view, composite and MIP.
#[test]
fn narrow_16_p4() {
    let s = seed(0xacce9);
    let mut c = Case::new(rtl(4, 16), head_phantom(16, 8).unwrap(), s);
    let frames: Vec<(View, Render)> = some_views()
        .into_iter()
        .flat_map(|v| [(v, Composite), (v, Mip)])
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
    let e = c.expect(view("oblique x"), Composite);
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
    c.frame(
        view("oblique x"),
        Composite,
        &env,
        " after a reset mid-frame",
    );
}

/// `Ctrl.soft_reset` at random points of frames under random memories (latency 10..200, gaps on
/// every channel): the frame ends with IrqStatus.error and code Aborted (or done, when it had
/// ended already), the Sample counter holds the plan's count, no AXI4 burst is left outstanding
/// on either direction (the memory's checker saw every transaction complete), and the next frame,
/// started without a reset or a table reload, is exact. On the 64^3 build (a 64-bit bus, the
/// read-out in two writer items per P pixels) and on the narrow 16^3 one (many resets).
#[test]
fn soft_reset_mid_frame_drains_then_an_exact_frame() {
    let s = seed(0xacce19);
    for (n, bits, resets, span) in [(64, 12, 4, 140_000u64), (16, 8, 12, 9_000)] {
        soft_resets(rtl(4, n), bits, resets, span, s);
    }
}

/// `resets` soft resets, each at a random point (up to `span` cycles) of a frame of the head
/// phantom at the build's largest size under a random memory, and the exact frame after each.
fn soft_resets(rtl: AccelRtl, bits: u32, resets: usize, span: u64, s: u64) {
    let n = 1usize << rtl.frame.max_dim_log2;
    let mut c = Case::new(rtl, head_phantom(n, bits).unwrap(), s);
    let views = some_views();
    let mut aborted = 0;
    for k in 0..resets {
        let env = MemEnv::random(&mut c.rng);
        let e = c.expect(views[k % views.len()], [Composite, Mip][k % 2]);
        let mem_seed = c.rng.random();
        must(c.bench.start(&e, &c.vol, &c.lut, &env, mem_seed));
        let at = c.rng.random_range(1..span);
        must(c.bench.idle(at));
        AccelHost::new(&mut c.bench, 0).soft_reset().unwrap();
        must(c.bench.wait_irq(200_000));
        let mut host = AccelHost::new(&mut c.bench, 0);
        let ended = host.wait_done(1);
        let code = host.status_code().unwrap();
        let counters = host.counters().unwrap();
        match ended {
            Err(HostError::Frame(_)) => {
                assert_eq!(code, CODE_ABORTED, "soft reset after {at} cycles");
                aborted += 1;
            }
            Ok(_) => eprintln!("the frame had ended before the soft reset ({at} cycles)"),
            Err(other) => panic!("soft reset after {at} cycles: {other}"),
        }
        let [ni, nj, nk] = [e.params.ni, e.params.nj, e.params.nk];
        assert_eq!(
            counters.samples,
            (ni * nj * nk) as u64,
            "the plan's samples"
        );
        let (rd, wr) = (c.bench.dut.axi_counters(), c.bench.dut.axi_wr_counters());
        assert_eq!(
            (rd.in_flight, wr.in_flight),
            (0, 0),
            "read and write bursts outstanding after the soft reset at {at} cycles"
        );
        eprintln!(
            "{}: soft reset {at} cycles into the frame, ended after {} cycles",
            c.bench.rtl.variant, counters.cycles
        );
        c.frame(
            views[(k + 1) % views.len()],
            Composite,
            &env,
            " after a soft reset",
        );
    }
    assert!(aborted > 0, "no frame was aborted");
}

/// A frame whose last section the frame refuses (36 anchors in sections of 16: the last has 4,
/// fewer than 2P): the frame ends with IrqStatus.error and code Frame (the writer is fed zeros
/// for the rows the core commanded, nothing hangs) only once the data path has drained, and the
/// next frame (new volume, new block LUT) is exact without a reset.
#[test]
fn a_section_the_frame_refuses_ends_the_frame_with_an_error() {
    let s = seed(0xacceb);
    let mut c = Case::new(rtl(4, 64), head_phantom(36, 12).unwrap(), s);
    let e = c.expect(view("+z"), Composite);
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
        view("45 xz"),
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
    let (e, other) = (c.expect(view("+z"), Mip), c.expect(view("+z"), Composite));
    let img_base = must(c.bench.start(&e, &c.vol, &c.lut, &MemEnv::quiet(), s));
    match c.bench.finish(&other, img_base, s) {
        Err(TbError::Mismatch(m)) => eprintln!("as it should: {}", m.what),
        other => panic!("a MIP image passed as the composite one: {other:?}"),
    }
}

/// X-ray (the set-up's shift, and 0: sums that saturate), first-opaque, the 2-D transfer function
/// in composite (with early termination) and in first-opaque.
fn newer_modes() -> Vec<(Render, Look)> {
    let dense = Look {
        tf: dense_tf(),
        ..Look::default()
    };
    vec![
        (Render::Xray, Look::default()),
        (
            Render::Xray,
            Look {
                xray_shift: Some(0),
                ..Look::default()
            },
        ),
        (
            Render::FirstOpaque,
            Look {
                threshold: 0.3,
                ..dense.clone()
            },
        ),
        (
            Composite,
            Look {
                boundary: Some(0.25),
                early_termination: true,
                ..dense.clone()
            },
        ),
        (
            Render::FirstOpaque,
            Look {
                boundary: Some(0.25),
                threshold: 0.3,
                ..dense
            },
        ),
    ]
}

/// The frame's other modes through the accelerator's registers (`Mode.render` 3 and 4 and
/// `Mode.tf2d`; their compositing registers, XrayShift and FoThreshold, through the Opacity table
/// window): X-ray with the set-up's shift and with 0 (sums that saturate), first-opaque, the 2-D
/// transfer function in composite (with early termination) and in first-opaque; bit-exact on the
/// narrow 16^3 configuration and at 64^3. MinIP: `minip_through_the_registers`.
#[test]
fn newer_modes_through_the_registers() {
    let s = seed(0xacce10);
    modes_bit_exact(&newer_modes(), s);
}

/// MinIP (`Mode.render` 2) through the registers, as `newer_modes_through_the_registers`. The
/// obliques cross section boundaries (64^3: two sections), where the frame leaves out a sample
/// past the x far face only in the section that holds the face's last anchor (cube5_frame_cbuf's
/// `far_x_i`); before that fix every section's last anchor was taken for the face's.
#[test]
fn minip_through_the_registers() {
    modes_bit_exact(&[(Render::Minip, Look::default())], seed(0xacce18));
}

/// The frames of `modes` ((render, look)) on the 16^3 head (narrow configuration, two views) and
/// the 64^3 head (one view), each under its own random memory.
fn modes_bit_exact(modes: &[(Render, Look)], s: u64) {
    for (n, bits, views) in [
        (16, 8, &["45 xz", "oblique z"][..]),
        (64, 12, &["oblique x"][..]),
    ] {
        let mut c = Case::new(rtl(4, n), head_phantom(n, bits).unwrap(), s);
        for (render, look) in modes {
            for &v in views {
                let e = c.expect_with(view(v), *render, look);
                let env = MemEnv::random(&mut c.rng);
                c.frame_of(&e, &env, "");
            }
        }
    }
}

/// Frames of a non-cubic volume at `p` pipelines, each under its own random memory: the head
/// phantom resampled to `dims` (faces along each axis, 45 degrees, obliques; composite and MIP),
/// then the blob (a face, 45 degrees between two negative axes, an oblique view).
fn non_cubic(p: usize, dims: [usize; 3], s: u64) {
    let n = dims.into_iter().max().unwrap();
    let head = resampled(&head_phantom(n, 12).unwrap(), dims);
    let mut c = Case::new(rtl(p, n), head, s);
    c.random(&[
        (view("+z"), Composite),
        (view("+x"), Mip),
        (view("-y"), Composite),
        (view("45 xz"), Composite),
        (view("oblique z"), Mip),
        (view("oblique y"), Composite),
    ]);
    let mut c = c.with(blob_volume(dims, 12, s));
    c.random(&[
        (view("-z"), Composite),
        (view("45 -x-y"), Composite),
        (view("oblique x"), Mip),
    ]);
}

/// A non-cubic volume whose edges are no power of two and not all multiples of the block edge
/// (60 x 44 x 28 at P = 4 with 8^3 blocks and 16-anchor sections: partial blocks on every axis,
/// a last section of 12 anchors).
#[test]
fn non_cubic_60x44x28_p4() {
    non_cubic(4, [60, 44, 28], seed(0xacce11));
}

/// Whole-frame cycles of the throughput configuration (P = 4, 4^3 blocks, 32-anchor sections,
/// 128-bit bus) on the 64^3 head: a fast memory and a DDR-like one (latency 100..120, 12
/// bytes/cycle), a face and 45 degrees; every image exact.
#[test]
fn throughput_of_the_wide_configuration() {
    let s = seed(0xacce6);
    let rtl = rtl(4, 128);
    let mut c = Case::new(rtl, head_phantom(64, 12).unwrap(), s);
    for (env, what) in [
        (ddr(20, 0), ", fast memory"),
        (ddr(100, 12), ", DDR-like 12 B/cycle"),
    ] {
        for view in [view("+z"), view("45 xz")] {
            let rate = c.frame(view, Composite, &env, what).rate(rtl.p);
            assert!(
                rate > 0.8,
                "{}: {rate:.3} samples/clock/pipeline",
                rtl.variant
            );
        }
    }
}

/// 128^3 frames (head phantom and bubbles) at P = 4 on the throughput configuration: five views,
/// composite and MIP alternately, random memories; then 45 degrees with the DDR-like memory.
#[test]
#[ignore = "sim-full: 128^3 frames, about 20 s each"]
fn frames_128_p4() {
    let s = seed(0xacce7);
    let frames: Vec<(View, Render)> = some_views()
        .into_iter()
        .enumerate()
        .map(|(n, v)| (v, [Composite, Mip][n % 2]))
        .collect();
    let mut c = Case::new(rtl(4, 128), head_phantom(128, 12).unwrap(), s);
    for next in [Some(bubbles_phantom(128, 12).unwrap()), None] {
        c.random(&frames);
        c.frame(
            view("45 xz"),
            Composite,
            &ddr(100, 12),
            ", DDR-like 12 B/cycle",
        );
        if let Some(v) = next {
            c = c.with(v);
        }
    }
}

/// The 14 acceptance views (`cube5_tb::frame::VIEWS`) on the 128^3 head at `p` pipelines, each
/// under its own random memory: composite (shaded) and MIP at every view (`both`), or the two
/// alternately.
fn views_14_at_128(p: usize, both: bool, s: u64) {
    let mut c = Case::new(rtl(p, 128), head_phantom(128, 12).unwrap(), s);
    let frames: Vec<(View, Render)> = VIEWS
        .iter()
        .enumerate()
        .flat_map(|(n, &v)| {
            let first = [Composite, Mip][n % 2];
            let other = [Mip, Composite][n % 2];
            std::iter::once((v, first)).chain(both.then_some((v, other)))
        })
        .collect();
    c.random(&frames);
}

#[test]
#[ignore = "sim-full: 14 frames of 128^3 at P = 1, about 2.2 M cycles each"]
fn views_14_128_p1() {
    views_14_at_128(1, false, seed(0xacce12));
}

#[test]
#[ignore = "sim-full: 28 frames of 128^3 at P = 4"]
fn views_14_128_p4() {
    views_14_at_128(4, true, seed(0xacce13));
}

#[test]
#[ignore = "sim-full: 28 frames of 128^3 at P = 8"]
fn views_14_128_p8() {
    views_14_at_128(8, true, seed(0xacce14));
}

/// 256^3 head frames at P = 4 and 8: 45 degrees composite with the DDR-like memory, an oblique
/// view (DX < 0, reversed sweep) in MIP under a random memory.
#[test]
#[ignore = "sim-full: 256^3 frames, minutes each"]
fn frames_256_p4_p8() {
    let s = seed(0xacce8);
    let head = head_phantom(256, 12).unwrap();
    for p in [4, 8] {
        let mut c = Case::new(rtl(p, 256), head.clone(), s);
        c.frame(
            view("45 xz"),
            Composite,
            &ddr(100, 12),
            ", DDR-like 12 B/cycle",
        );
        c.random(&[(view("oblique z"), Mip)]);
    }
}

/// The non-cubic 160 x 128 x 96 volume of the acceptance list (no edge a power of two but 128)
/// at P = 4 and 8 (the MaxDim 256 builds).
#[test]
#[ignore = "sim-full: 160 x 128 x 96 frames on the MaxDim 256 configurations"]
fn non_cubic_160x128x96_p4_p8() {
    for p in [4, 8] {
        non_cubic(p, [160, 128, 96], seed(0xacce15));
    }
}

/// A gate-level smoke run: every `gate` configuration of the top (its Yosys netlist; `full`, so
/// built by `make sim-full` only), the head phantom at its largest size, composite at 45 degrees
/// and MIP at an oblique view, bit-exact, under random memories.
#[test]
#[ignore = "sim-full: the gate-level netlist is on a `full` line (minutes of build)"]
fn gate_level_smoke() {
    let s = seed(0xacce16);
    let gates = gate_variants_of(TOP);
    assert!(!gates.is_empty(), "no gate-level build of {TOP}");
    for g in gates {
        let rtl = must(AccelRtl::from_variant(g));
        let n = 1 << rtl.frame.max_dim_log2;
        let bits = rtl.frame.cfg.trilin.voxel_w;
        let mut c = Case::new(rtl, head_phantom(n, bits).unwrap(), s);
        c.random(&[(view("45 xz"), Composite), (view("oblique z"), Mip)]);
    }
}

/// The lowest placed Fmax (MHz) among the accelerator (its placed configuration `v8p4s8`) and the
/// units inside it, from the generated ECP5 table of docs/measurements.md (`make synth`,
/// nextpnr-ecp5 routed): the bound the benchmark's frames per second use, and what sets it.
fn placed_fmax_bound() -> (f64, String) {
    const UNITS: &[&str] = &[
        "cube5_accel",
        "cube5_frame",
        "cube5_section_buf",
        "cube5_vol_fetch",
        "cube5_axi_rd",
        "cube5_axi_wr",
        "cube5_axil",
        "cube5_accel_ctrl",
    ];
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/measurements.md");
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let table = text
        .split("<!-- BEGIN generated")
        .nth(1)
        .and_then(|t| t.split("<!-- END generated").next())
        .expect("the generated ECP5 table in docs/measurements.md");
    table
        .lines()
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            let fmax: f64 = cells.get(cells.len().checked_sub(2)?)?.parse().ok()?;
            UNITS
                .contains(&cells.get(1)?)
                .then(|| (fmax, format!("{} {}", cells[1], cells[2])))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .expect("a placed Fmax of the accelerator's units")
}

/// The benchmark (`make bench-accel`; docs/accel.md, *Measured*): whole frames of the head
/// phantom, start to interrupt (read-out and the image's writes included), at P = 1, 2, 4, 8 on
/// the MaxDim 256 configurations (8^3 blocks, 32-anchor sections, a 128-bit bus, 16 bursts in
/// flight), without and with the compositing window (`w1` builds), with the DDR-like memory (latency 100..120 cycles, 12 bytes per cycle shared by reads
/// and writes): samples per clock per pipeline, and frames per second at the lowest placed Fmax
/// of the accelerator and its units. Every image bit-exact. Prints a Markdown table (also written to
/// target/bench-accel.md). Cycle counts are exact whatever the machine's load.
#[test]
#[ignore = "sim-full: the benchmark, 128^3 and 256^3 frames at P = 1, 2, 4, 8 (tens of minutes)"]
fn benchmark_table() {
    let s = seed(0xacce17);
    let (fmax, unit) = placed_fmax_bound();
    let env = ddr(100, 12);
    let mut table = format!(
        "| P | configuration | volume | view | cycles | samples | samples/clock/pipeline | frames/s at {fmax} MHz |\n|--:|---|---|---|--:|--:|--:|--:|\n"
    );
    let heads = [128, 256].map(|n| head_phantom(n, 12).unwrap());
    // The fastest first: P = 1 at 256^3 alone is 17 M cycles. The whole-plane builds, then the
    // same memory systems with the compositing window (`Window = 1`).
    let builds = [8, 4, 2, 1]
        .map(|p| rtl(p, 256))
        .into_iter()
        .chain([8, 4, 2, 1].map(window_full));
    for rtl in builds {
        let p = rtl.p;
        let mut c = Case::new(rtl, heads[0].clone(), s);
        for (head, views) in heads.iter().zip([&["+z", "45 xz"][..], &["45 xz"][..]]) {
            c = c.with(head.clone());
            for &v in views {
                let run = c.frame(view(v), Composite, &env, ", DDR-like 12 B/cycle");
                let n = head.dims[0];
                table += &format!(
                    "| {p} | `{}` | {n}^3 head | {v} | {} | {} | {:.3} | {:.1} |\n",
                    rtl.variant.config,
                    run.cycles,
                    run.samples,
                    run.rate(p),
                    fmax * 1e6 / run.cycles as f64
                );
            }
        }
    }
    table += &format!(
        "\nFmax bound: {fmax} MHz, the lowest placed Fmax among the accelerator and its units ({unit}, docs/measurements.md).\n"
    );
    eprintln!("\n{table}");
    let out = concat!(env!("CARGO_MANIFEST_DIR"), "/../target/bench-accel.md");
    if let Err(e) = std::fs::write(out, &table) {
        eprintln!("{out}: {e} (the table is printed above)");
    }
}

// ---------------------------------------------------------------------------------------------
// The compositing window in the top (`Window = 1`; docs/accel.md, *The compositing window in
// the top*): parks and restores through the scratch area at ParkBase, the final pixels written
// during the sweep, the rows first written with the initial coxel's code.
// ---------------------------------------------------------------------------------------------

/// The CI build with the window (the smallest memory), `p` pipelines.
fn window_rtl(p: usize) -> AccelRtl {
    AccelRtl::windows()
        .into_iter()
        .filter(|r| r.p == p && !r.variant.has_flag("full"))
        .min_by_key(|r| r.frame.max_dim_log2)
        .unwrap_or_else(|| panic!("no cube5_accel variant with Window = 1 and P = {p} in CI"))
}

/// The window's narrow build: the 16^3 head in all 14 acceptance views (the six faces, exactly
/// 45 degrees, obliques with DX < 0 and reversed sweeps), composite (shaded) and MIP at each,
/// every frame under its own random memory (latency 10..200, gaps on all five channels, the
/// host's B and R back-pressured): the image in memory bit-exact, pixels no ray reaches included.
#[test]
fn window_16_every_view_composite_and_mip() {
    let s = seed(0xacce21);
    let rtl = window_rtl(4);
    let n = 1usize << rtl.frame.max_dim_log2;
    let mut c = Case::new(rtl, head_phantom(n, 8).unwrap(), s);
    let frames: Vec<(View, Render)> = VIEWS
        .iter()
        .flat_map(|&v| [(v, Composite), (v, Mip)])
        .collect();
    c.random(&frames);
}

/// The window under the DDR-like memory (latency 100..120) with a bandwidth limit shared by reads
/// and writes, 12 and 3 bytes per cycle, and the blob with holes (few empty blocks): exact.
#[test]
fn window_16_bandwidth_limit_and_bubbles() {
    let s = seed(0xacce22);
    let rtl = window_rtl(4);
    let n = 1usize << rtl.frame.max_dim_log2;
    let mut c = Case::new(rtl, head_phantom(n, 8).unwrap(), s);
    for bw in [12, 3] {
        for v in ["45 xz", "oblique z", "-y"] {
            c.frame(
                view(v),
                Composite,
                &ddr(100, bw),
                &format!(", DDR-like {bw} B/cycle"),
            );
        }
    }
    let mut c = c.with(bubbles_phantom(n, 8).unwrap());
    c.random(&[(view("45 xz"), Composite), (view("oblique x"), Mip)]);
}

/// The modes whose initial coxel differs (MinIP: A all ones) or that composite otherwise (X-ray,
/// first-opaque, the 2-D transfer function) through the window: the untouched pixels carry the
/// initial coxel's code.
#[test]
fn window_16_modes() {
    let s = seed(0xacce23);
    let rtl = window_rtl(4);
    let n = 1usize << rtl.frame.max_dim_log2;
    let mut c = Case::new(rtl, head_phantom(n, 8).unwrap(), s);
    let mut modes = newer_modes();
    modes.push((Render::Minip, Look::default()));
    for (k, (render, look)) in modes.iter().enumerate() {
        let v = [view("45 xz"), view("oblique z"), view("diagonal")][k % 3];
        let e = c.expect_with(v, *render, look);
        let env = MemEnv::random(&mut c.rng);
        c.frame_of(&e, &env, "");
    }
}

/// A reset in the middle of a window frame (parks, restores and final writes in flight are
/// dropped on both sides; none is outstanding after it), then the tables reloaded and an exact
/// frame; at several points of the frame.
#[test]
fn window_reset_mid_frame_then_an_exact_frame() {
    let s = seed(0xacce24);
    let rtl = window_rtl(4);
    let n = 1usize << rtl.frame.max_dim_log2;
    let mut c = Case::new(rtl, head_phantom(n, 8).unwrap(), s);
    for k in 0..4 {
        let env = MemEnv::random(&mut c.rng);
        let e = c.expect(view("45 xz"), Composite);
        let mem_seed = c.rng.random();
        must(c.bench.start(&e, &c.vol, &c.lut, &env, mem_seed));
        must(c.bench.idle(c.rng.random_range(500..8_000)));
        c.bench.reset();
        let (rd, wr) = (c.bench.dut.axi_counters(), c.bench.dut.axi_wr_counters());
        assert_eq!(
            (rd.in_flight, wr.in_flight),
            (0, 0),
            "bursts outstanding after the reset"
        );
        let v = [view("45 xz"), view("oblique x")][k % 2];
        c.frame(v, Composite, &env, " after a reset mid-frame");
    }
}

/// `Ctrl.soft_reset` at random points of window frames: code Aborted, no burst outstanding in
/// either direction (parks, restores, final pixels, the clear), the next frame exact.
#[test]
fn window_soft_reset_mid_frame_drains_then_an_exact_frame() {
    soft_resets(window_rtl(4), 8, 12, 9_000, seed(0xacce25));
}

/// Window frames at 128^3 on the MaxDim 256 builds at P = 1, 2, 4, 8 (the head phantom): the +z
/// face and 45 degrees composite with the DDR-like memory, an oblique view in MIP under a random
/// memory.
#[test]
#[ignore = "sim-full: 128^3 window frames at P = 1, 2, 4, 8 (the MaxDim 256 builds)"]
fn window_frames_128() {
    let s = seed(0xacce26);
    let head = head_phantom(128, 12).unwrap();
    for p in [4, 8, 2, 1] {
        let mut c = Case::new(window_full(p), head.clone(), s);
        for v in ["+z", "45 xz"] {
            c.frame(view(v), Composite, &ddr(100, 12), ", DDR-like 12 B/cycle");
        }
        c.random(&[(view("oblique z"), Mip)]);
    }
}

/// Window frames at 256^3 at P = 4 and 8: 45 degrees composite with the DDR-like memory.
#[test]
#[ignore = "sim-full: 256^3 window frames, minutes each"]
fn window_frames_256() {
    let s = seed(0xacce27);
    let head = head_phantom(256, 12).unwrap();
    for p in [4, 8] {
        let mut c = Case::new(window_full(p), head.clone(), s);
        c.frame(
            view("45 xz"),
            Composite,
            &ddr(100, 12),
            ", DDR-like 12 B/cycle",
        );
    }
}

/// The window build with `p` pipelines and the largest memory.
fn window_full(p: usize) -> AccelRtl {
    AccelRtl::windows()
        .into_iter()
        .filter(|r| r.p == p)
        .max_by_key(|r| r.frame.max_dim_log2)
        .unwrap_or_else(|| panic!("no cube5_accel variant with Window = 1 and P = {p}"))
}

// ---------------------------------------------------------------------------------------------
// The window's bursts by AXI ID against the contract (docs/numerics/compos_window.md, *The ring
// in park order*, *Final pixels in bursts*): the memory logs every AR and AW handshake with its
// ID (`axi_take_ar`, `axi_take_aw`); the model's window streams give what they must be.
// ---------------------------------------------------------------------------------------------

use cube5_tb::accel::IdCount;

/// The bursts of ID `id` in `hs`.
fn of_id(hs: &[cube5_tb::rtl::ArHandshake], id: u32) -> Vec<(u64, u64)> {
    hs.iter()
        .filter(|h| h.id == id)
        .map(|h| (h.addr, u64::from(h.len) + 1))
        .collect()
}

fn count(bursts: &[(u64, u64)]) -> IdCount {
    IdCount {
        bursts: bursts.len() as u64,
        beats: bursts.iter().map(|b| b.1).sum(),
    }
}

/// The contract's final bursts: the final pixels' bus beats in stream order, a run continuing
/// while each beat is the run's last or the next one inside an aligned block of `fin_burst`
/// beats; (bursts, beats) with no run closed by the idle wait.
fn final_runs(finals: &[(u64, u64)], fin_burst: u64) -> IdCount {
    let mut n = IdCount::default();
    let mut prev: Option<u64> = None;
    for &(addr, len) in finals {
        for b in addr..addr + len {
            match prev {
                Some(p) if b == p => {}
                Some(p) if b == p + 1 && !b.is_multiple_of(fin_burst) => n.beats += 1,
                _ => {
                    n.bursts += 1;
                    n.beats += 1;
                }
            }
            prev = Some(b);
        }
    }
    n
}

/// What the window's IDs did in one frame, against the contract.
struct WindowBursts {
    /// ID 1 writes and reads (the ring's), ID 2 writes (the final pixels).
    ring_w: IdCount,
    ring_r: IdCount,
    fin: IdCount,
    /// The contract: ring beats `ceil(Wn StoreW / DataW)` (exact when the zero-park FIFO never
    /// fills), its bursts cut at `RingBurst` beats and the ring's end; the finals' runs.
    ring_beats: u64,
    ring_segments: u64,
    fin_runs: IdCount,
    run: FrameRun,
}

/// One 45-degree composite frame of `c` under `env` (packed rows), its bursts by ID checked
/// against the contract's rules: every ring burst continues the previous one in the ring and
/// crosses no `RingBurst` boundary nor the ring's end; reads the same beats as writes; every
/// final burst inside an aligned block of `WinFinBurst` beats; the final beats and bursts at
/// least the contract's runs, and each run the idle wait closed early costs one burst and at
/// most one beat.
fn window_bursts(c: &mut Case, view: View, env: &MemEnv) -> WindowBursts {
    use cube5_model::units::cube5_accel::{AccelConfig, ID_FINAL, ID_PARK};
    use cube5_model::units::cube5_frame::sections::section_order;
    use cube5_model::units::cube5_frame::window::render_window;
    let rtl = c.bench.rtl;
    let ac: AccelConfig = rtl.variant.config().unwrap();
    assert!(
        ac.win_ring && ac.win_fin_burst != 0,
        "{}: no ring",
        rtl.variant
    );
    let e = c.expect(view, Composite);
    let look = Look::default();
    let (_, fu) = Expected::model_units(&rtl.frame, &e.seen, e.dir, Composite, &look).unwrap();
    let order = section_order(&e.params, rtl.section, rtl.p).unwrap();
    let (_, t) = render_window(&e.params, &e.seen, &fu, &order, rtl.p).unwrap();
    c.bench.pitch = 0;
    must(c.bench.dut.axi_take_ar());
    must(c.bench.dut.axi_take_aw());
    let mem_seed = c.rng.random();
    let img_base = must(c.bench.start(&e, &c.vol, &c.lut, env, mem_seed));
    let run = must(c.bench.finish(&e, img_base, mem_seed));
    let (ars, aws) = (
        must(c.bench.dut.axi_take_ar()),
        must(c.bench.dut.axi_take_aw()),
    );
    let bus = u64::from(rtl.fetch.data_w / 8);
    let store_w = 4 * (u64::from(rtl.frame.compos.acc_w) + 1) + 1;
    // The ring: beats at ParkBase' + (m mod RB) bytes-per-beat, RB = Wp nj PkBeats.
    let base = c.bench.park.0 / rtl.park_slot * rtl.park_slot / bus;
    let rb = u64::from(rtl.ctrl.row_pixels(e.w as u32)) * e.params.nj as u64 * rtl.park_slot / bus;
    let rburst = u64::from(ac.win_ring_burst);
    let cut = |pos: u64| pos == 0 || (base + pos).is_multiple_of(rburst);
    let check_ring = |bursts: &[(u64, u64)], what: &str| -> u64 {
        let mut pos = 0u64;
        let mut short = 0;
        for (k, &(addr, len)) in bursts.iter().enumerate() {
            assert_eq!(
                addr / bus,
                base + pos,
                "{}: ring {what} burst {k}",
                rtl.variant
            );
            let end = pos + len;
            assert!(
                end <= rb && (base + pos) % rburst + len <= rburst,
                "{}: ring {what} burst {k} crosses a {rburst}-beat boundary",
                rtl.variant
            );
            pos = end % rb;
            if !cut(pos) && k + 1 < bursts.len() {
                short += 1;
            }
        }
        short
    };
    let (w1, r1) = (of_id(&aws, ID_PARK), of_id(&ars, ID_PARK));
    let short_w = check_ring(&w1, "write");
    check_ring(&r1, "read");
    let zero = |x: &cube5_model::units::cube5_compos::Coxel| {
        !x.terminated && x.rgba.iter().all(|&v| v == 0)
    };
    let wn = t.streams.parked.iter().filter(|p| !zero(&p.2)).count() as u64;
    let ring_beats = (wn * store_w).div_ceil(8 * bus);
    let segments = |beats: u64| (0..beats).filter(|&m| cut(m % rb)).count() as u64;
    let ring_segments = segments(ring_beats);
    let (ring_w, ring_r) = (count(&w1), count(&r1));
    assert_eq!(
        ring_w.beats, ring_r.beats,
        "{}: ring beats written and read",
        rtl.variant
    );
    // Every burst ends at a cut but those a flush ended.
    assert_eq!(
        ring_w.bursts,
        segments(ring_w.beats) + short_w,
        "{}: ring write bursts against the segments of its beats ({short_w} cut short)",
        rtl.variant
    );
    // The final pixels: each pixel's bytes as (first beat, beats) in stream order.
    let pitch = c.bench.pitch_bytes(&e) as u64;
    let finals: Vec<(u64, u64)> = t
        .streams
        .finals
        .iter()
        .map(|&(r, q, _)| {
            let a = img_base + q as u64 * pitch + 4 * r as u64;
            (a / bus, (a + 3) / bus - a / bus + 1)
        })
        .collect();
    // Final pixels with neither stream neighbour next to them in memory (a run of one pixel).
    let at: Vec<u64> = t
        .streams
        .finals
        .iter()
        .map(|&(r, q, _)| q as u64 * pitch + 4 * r as u64)
        .collect();
    let alone = (0..at.len())
        .filter(|&i| {
            (i == 0 || at[i - 1] + 4 != at[i]) && (i + 1 == at.len() || at[i] + 4 != at[i + 1])
        })
        .count();
    let fb = u64::from(ac.win_fin_burst);
    let fin_runs = final_runs(&finals, fb);
    let f2 = of_id(&aws, ID_FINAL);
    for (k, &(addr, len)) in f2.iter().enumerate() {
        assert!(
            (addr / bus) % fb + len <= fb,
            "{}: final burst {k} ({addr:#x}, {len} beats) crosses a {fb}-beat block",
            rtl.variant
        );
    }
    let fin = count(&f2);
    let split = fin.bursts.checked_sub(fin_runs.bursts).unwrap_or_else(|| {
        panic!(
            "{}: {fin:?} final bursts, fewer than the contract's runs {fin_runs:?}",
            rtl.variant
        )
    });
    assert!(
        fin.beats >= fin_runs.beats && fin.beats - fin_runs.beats <= split,
        "{}: final {fin:?} against the runs {fin_runs:?}",
        rtl.variant
    );
    // Where the channel is busy: beats per 2,048-cycle window (by their address handshake),
    // against the memory's limit (bytes per cycle / bytes per beat).
    if env.bw.0 != 0 {
        let win = 2048u64;
        let t0 = ars.iter().chain(&aws).map(|h| h.cycle).min().unwrap_or(0);
        let t1 = ars.iter().chain(&aws).map(|h| h.cycle).max().unwrap_or(0);
        let nw = ((t1 - t0) / win + 1) as usize;
        let (mut rd, mut wr) = (vec![0u64; nw], vec![0u64; nw]);
        for h in &ars {
            rd[((h.cycle - t0) / win) as usize] += u64::from(h.len) + 1;
        }
        for h in &aws {
            wr[((h.cycle - t0) / win) as usize] += u64::from(h.len) + 1;
        }
        let cap = win as f64 * env.bw.0 as f64 / env.bw.1.max(1) as f64 / bus as f64;
        let busy: Vec<usize> = (0..nw)
            .filter(|&k| (rd[k] + wr[k]) as f64 >= 0.9 * cap)
            .collect();
        let sum = |v: &[u64]| busy.iter().map(|&k| v[k]).sum::<u64>() as f64;
        // The volume's reads against its present blocks (each block's bytes once).
        let present = c
            .lut
            .entries
            .iter()
            .filter(|b| !b.empty && !b.masked)
            .count() as u64;
        let voxel = u64::from(rtl.fetch.voxel_w.div_ceil(8).next_power_of_two());
        let block = u64::from(rtl.fetch.block_dim).pow(3) * voxel / bus;
        let vol = count(&of_id(&ars, 0)).beats;
        eprintln!(
            "{}: volume reads {vol} beats for {present} present blocks of {block} beats: each read {:.2} times",
            rtl.variant,
            vol as f64 / (present * block).max(1) as f64
        );
        let per = (busy.len() as u64 * win).max(1) as f64;
        eprintln!(
            "{}: {} windows of {win} cycles, {} with the channel at >= 90 % of {cap:.0} beats: read {:.3}, write {:.3} beats/clock there",
            rtl.variant,
            nw,
            busy.len(),
            sum(&rd) / per,
            sum(&wr) / per
        );
    }
    eprintln!(
        "{}: {} {}: {} cycles ({:.3} samples/clock/pipeline); ring: written {ring_w:?}, read {ring_r:?}, contract {ring_beats} beats in {ring_segments} segments ({wn} written parks, {short_w} bursts cut short); finals {fin:?} ({} pixels, {alone} alone), contract runs {fin_runs:?}; volume reads {:?}; clear {:?}",
        rtl.variant,
        e.view,
        c.vol.dims[0],
        run.cycles,
        run.rate(rtl.p),
        at.len(),
        count(&of_id(&ars, 0)),
        count(&of_id(&aws, 0)),
    );
    WindowBursts {
        ring_w,
        ring_r,
        fin,
        ring_beats,
        ring_segments,
        fin_runs,
        run,
    }
}

/// CI's window build (`w1v8p4s8`: the ring, bursts of up to 8 beats, a 16-bit zero-park FIFO
/// that fills, so the written parks depend on timing): the 16^3 head at 45 degrees and the
/// blob under the DDR-like memory and a random one: every ring and final burst by the
/// contract's rules, the ring's beats read back as written, the final bursts the contract's
/// runs (plus the runs the idle wait closed).
#[test]
fn window_16_bursts_by_id_follow_the_contract() {
    let s = seed(0xacce28);
    let rtl = window_rtl(4);
    let n = 1usize << rtl.frame.max_dim_log2;
    let mut c = Case::new(rtl, head_phantom(n, 8).unwrap(), s);
    for env in [ddr(100, 12), MemEnv::random(&mut c.rng)] {
        for v in ["45 xz", "oblique x"] {
            let b = window_bursts(&mut c, view(v), &env);
            assert!(b.ring_w.beats >= b.ring_beats, "{b:?}", b = b.ring_w);
        }
    }
}

/// Every MaxDim 256 window line with the ring and the finals in bursts that this run built
/// (`w1p*m256s16d128a16c10`, `w1p4m256s32d128`) on the 128^3 head at 45 degrees under the
/// DDR-like memory: the ring's beats exactly `ceil(Wn StoreW / DataW)` each way (the zero-park
/// FIFO never fills), its bursts the contract's segments, the final bursts exactly the
/// contract's runs; where the channel is busy and how often the volume's blocks are read.
#[test]
#[ignore = "sim-full: 128^3 frames on `full` MaxDim 256 lines"]
fn window_128_bursts_by_id_equal_the_contract() {
    let s = seed(0xacce29);
    let lines: Vec<AccelRtl> = AccelRtl::windows()
        .into_iter()
        .filter(|r| {
            r.frame.max_dim_log2 == 8
                && r.variant
                    .config::<cube5_model::units::cube5_accel::AccelConfig>()
                    .is_ok_and(|a| a.win_fin_burst != 0 && a.win_ring)
        })
        .collect();
    assert!(
        !lines.is_empty(),
        "no MaxDim 256 line with the ring built (CUBE5_FULL=1)"
    );
    for rtl in lines {
        let mut c = Case::new(rtl, head_phantom(128, 12).unwrap(), s);
        let b = window_bursts(&mut c, view("45 xz"), &ddr(100, 12));
        let v = rtl.variant;
        assert_eq!(b.ring_w.beats, b.ring_beats, "{v}: ring beats written");
        assert_eq!(b.ring_r.beats, b.ring_beats, "{v}: ring beats read");
        assert_eq!(
            b.ring_w.bursts, b.ring_segments,
            "{v}: ring write bursts (no flush cut one short)"
        );
        assert_eq!(b.ring_r.bursts, b.ring_segments, "{v}: ring read bursts");
        assert_eq!(
            b.fin, b.fin_runs,
            "{v}: final bursts and beats: the contract's runs"
        );
        assert!(b.run.cycles > 0);
    }
}
