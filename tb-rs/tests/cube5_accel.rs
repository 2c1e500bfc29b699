//! Co-simulation of the accelerator top `cube5_accel` (issue 12; docs/accel.md): the volume in the
//! test bench's AXI4 memory in the blocked layout, tables and registers written over AXI4-Lite by
//! the host driver, a frame started, the interrupt awaited, the image read back from the memory
//! and compared byte for byte with the frame model's image in pixel codes. Driver:
//! `cube5_tb::accel`.
//!
//!     CUBE5_TOPS=cube5_accel cargo test --release -p cube5-tb --test cube5_accel

mod support;

use cube5_model::phantom::{bubbles_phantom, head_phantom};
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

/// A volume and its block LUT (empty blocks at threshold 0: they read as zeros, as the model sees
/// them).
fn scene(vol: Volume, block: u32) -> (Rc<Volume>, BlockLut) {
    let lut = BlockLut::from_volume(&vol, block as usize, 0).unwrap();
    (Rc::new(vol), lut)
}

fn report(rtl: &AccelRtl, what: &str, n: usize, run: &FrameRun) {
    eprintln!(
        "{}: {n}^3 {what}: {} cycles, {} samples, {:.3} samples/clock/pipeline; {} read bursts ({} beats), {} write bursts",
        rtl.variant,
        run.cycles,
        run.samples,
        run.rate(rtl.p),
        run.ar,
        run.r_beats,
        run.aw
    );
}

/// One frame of `vol` along `dir`: rendered, read back from memory, compared.
#[allow(clippy::too_many_arguments)]
fn frame(
    bench: &mut AccelBench,
    vol: &Rc<Volume>,
    lut: &BlockLut,
    view: (&str, [f64; 3]),
    render: Render,
    env: &MemEnv,
    s: u64,
) -> FrameRun {
    let e = Expected::new(
        &bench.rtl.frame,
        vol,
        view.0,
        view.1,
        render,
        &Look::default(),
    )
    .unwrap();
    let run = must(bench.frame(&e, vol, lut, env, s));
    let rtl = bench.rtl;
    report(&rtl, &format!("{} {render:?}", view.0), vol.dims[0], &run);
    run
}

/// Faces (DX = DY = 0), exactly 45 degrees (DX = 2^16), obliques with DX < 0 and a reversed sweep.
const VIEWS: &[(&str, [f64; 3])] = &[
    ("+z", [0.0, 0.0, 1.0]),
    ("-x", [-1.0, 0.0, 0.0]),
    ("45 xz", [1.0, 0.0, 1.0]),
    ("oblique dx<0", [-0.6, 0.3, 1.0]),
    ("oblique -z", [0.37, 0.81, -1.0]),
];

/// The 64^3 head phantom at P = 4: every view composite (shaded), three in MIP, each under its
/// own random memory (latency 10..200, gaps on all five channels, the host's B and R
/// back-pressured): the image in memory bit-exact.
#[test]
fn head_64_p4_every_view_composite_and_mip() {
    let s = seed(0xacce1);
    let rtl = rtl(4, 64);
    let (vol, lut) = scene(head_phantom(64, 12).unwrap(), rtl.fetch.block_dim);
    let mut bench = must(AccelBench::new(rtl, s));
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    for (n, &view) in VIEWS.iter().enumerate() {
        let env = MemEnv::random(&mut rng);
        frame(
            &mut bench,
            &vol,
            &lut,
            view,
            Render::Composite,
            &env,
            s + n as u64,
        );
        if n % 2 == 0 {
            frame(
                &mut bench,
                &vol,
                &lut,
                view,
                Render::Mip,
                &env,
                s + 100 + n as u64,
            );
        }
    }
}

/// A blob with holes (the bubbles phantom, 64^3) at P = 4: a face and 45 degrees, both modes.
#[test]
fn bubbles_64_p4() {
    let s = seed(0xacce2);
    let rtl = rtl(4, 64);
    let (vol, lut) = scene(bubbles_phantom(64, 12).unwrap(), rtl.fetch.block_dim);
    let mut bench = must(AccelBench::new(rtl, s));
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    for (view, render) in [
        (VIEWS[1], Render::Composite),
        (VIEWS[2], Render::Mip),
        (VIEWS[3], Render::Composite),
    ] {
        let env = MemEnv::random(&mut rng);
        frame(&mut bench, &vol, &lut, view, render, &env, rng.random());
    }
}

/// P = 1: the 64^3 head at 45 degrees (composite) and an oblique view with DX < 0 (MIP).
#[test]
fn head_64_p1() {
    let s = seed(0xacce3);
    let rtl = rtl(1, 64);
    let (vol, lut) = scene(head_phantom(64, 12).unwrap(), rtl.fetch.block_dim);
    let mut bench = must(AccelBench::new(rtl, s));
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    for (view, render) in [(VIEWS[2], Render::Composite), (VIEWS[3], Render::Mip)] {
        let env = MemEnv::random(&mut rng);
        frame(&mut bench, &vol, &lut, view, render, &env, rng.random());
    }
}

/// A reset in the middle of a frame (reads and writes in flight are dropped on both sides; none
/// is outstanding after it), then the tables reloaded and the same frame exact.
#[test]
fn reset_mid_frame_then_an_exact_frame() {
    let s = seed(0xacce4);
    let rtl = rtl(4, 64);
    let (vol, lut) = scene(head_phantom(64, 12).unwrap(), rtl.fetch.block_dim);
    let mut bench = must(AccelBench::new(rtl, s));
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let env = MemEnv::random(&mut rng);
    let view = VIEWS[4];
    let e = Expected::new(
        &rtl.frame,
        &vol,
        view.0,
        view.1,
        Render::Composite,
        &Look::default(),
    )
    .unwrap();
    must(bench.start(&e, &vol, &lut, &env, s));
    must(bench.idle(30_000));
    let before = bench.dut.axi_counters();
    assert!(before.in_flight > 0, "reads in flight at the reset");
    bench.reset();
    let after = bench.dut.axi_counters();
    assert_eq!(after.in_flight, 0, "no read outstanding after the reset");
    assert_eq!(
        bench.dut.axi_wr_counters().in_flight,
        0,
        "no write outstanding after the reset"
    );
    let run = must(bench.frame(&e, &vol, &lut, &env, s + 1));
    report(&rtl, "after a reset mid-frame", 64, &run);
}

/// The comparison fails when the model disagrees: a frame of one view against another's image.
#[test]
fn the_check_fails_when_the_model_disagrees() {
    let s = seed(0xacce5);
    let rtl = rtl(4, 64);
    let (vol, lut) = scene(head_phantom(64, 12).unwrap(), rtl.fetch.block_dim);
    let mut bench = must(AccelBench::new(rtl, s));
    let look = Look::default();
    let e = Expected::new(&rtl.frame, &vol, "+z", [0.0, 0.0, 1.0], Render::Mip, &look).unwrap();
    let other = Expected::new(
        &rtl.frame,
        &vol,
        "+z",
        [0.0, 0.0, 1.0],
        Render::Composite,
        &look,
    )
    .unwrap();
    let img_base = must(bench.start(&e, &vol, &lut, &MemEnv::quiet(), s));
    match bench.finish(&other, img_base, s) {
        Err(TbError::Mismatch(m)) => eprintln!("as it should: {}", m.what),
        other => panic!("a MIP image passed as the composite one: {other:?}"),
    }
}

/// A DDR-like memory: latency `lat` + U(0..20), no gaps, `bw` bytes per cycle shared by reads and
/// writes.
fn ddr(lat: u32, bw: u32) -> MemEnv {
    MemEnv {
        latency: (lat, 20),
        gaps: [0; 5],
        bw: (bw, 1),
        host_stall: Vec::new(),
    }
}

/// Whole-frame cycles of the throughput configuration (P = 4, 4^3 blocks, 32-anchor sections,
/// 128-bit bus) on the 64^3 head: a fast memory and a DDR-like one (latency 100..120, 12
/// bytes/cycle), a face and 45 degrees; every image exact.
#[test]
fn throughput_of_the_wide_configuration() {
    let s = seed(0xacce6);
    let rtl = AccelRtl::widest(4).expect("a P = 4 build of cube5_accel");
    let (vol, lut) = scene(head_phantom(64, 12).unwrap(), rtl.fetch.block_dim);
    let mut bench = must(AccelBench::new(rtl, s));
    for (env, what) in [
        (ddr(20, 0), "fast memory"),
        (ddr(100, 12), "DDR-like 12 B/cycle"),
    ] {
        for view in [VIEWS[0], VIEWS[2]] {
            let run = frame(&mut bench, &vol, &lut, view, Render::Composite, &env, s);
            eprintln!("  ({what})");
            assert!(
                run.rate(rtl.p) > 0.3,
                "{}: {:.3}",
                rtl.variant,
                run.rate(rtl.p)
            );
        }
    }
}

/// 128^3 frames (head phantom and bubbles) at P = 4 on the throughput configuration, faces, 45
/// degrees and an oblique view, composite and MIP, random memory.
#[test]
#[ignore = "sim-full: 128^3 frames, about 10 s each"]
fn frames_128_p4() {
    let s = seed(0xacce7);
    let rtl = AccelRtl::widest(4).expect("a P = 4 build of cube5_accel");
    let mut bench = must(AccelBench::new(rtl, s));
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    for vol in [
        head_phantom(128, 12).unwrap(),
        bubbles_phantom(128, 12).unwrap(),
    ] {
        let (vol, lut) = scene(vol, rtl.fetch.block_dim);
        for (n, &view) in VIEWS.iter().enumerate() {
            let render = [Render::Composite, Render::Mip][n % 2];
            let env = MemEnv::random(&mut rng);
            frame(&mut bench, &vol, &lut, view, render, &env, rng.random());
        }
        frame(
            &mut bench,
            &vol,
            &lut,
            VIEWS[2],
            Render::Composite,
            &ddr(100, 12),
            s,
        );
    }
}

/// P = 8 at 128^3 (head, 45 degrees and an oblique view, composite and MIP) and one 256^3 head
/// frame at 45 degrees with the DDR-like memory.
#[test]
#[ignore = "sim-full: P = 8 and 256^3 frames, minutes each"]
fn frames_p8_and_256() {
    let s = seed(0xacce8);
    let rtl = AccelRtl::widest(8).expect("a P = 8 build of cube5_accel");
    let mut bench = must(AccelBench::new(rtl, s));
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let (vol, lut) = scene(head_phantom(128, 12).unwrap(), rtl.fetch.block_dim);
    for (view, render) in [(VIEWS[2], Render::Composite), (VIEWS[3], Render::Mip)] {
        let env = MemEnv::random(&mut rng);
        frame(&mut bench, &vol, &lut, view, render, &env, rng.random());
    }
    let (vol, lut) = scene(head_phantom(256, 12).unwrap(), rtl.fetch.block_dim);
    frame(
        &mut bench,
        &vol,
        &lut,
        VIEWS[2],
        Render::Composite,
        &ddr(100, 12),
        s,
    );
}
