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
use rand::SeedableRng;
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

/// The first step: the 64^3 head phantom at P = 4, a face view, composite, a quiet memory.
#[test]
fn head_64_p4_face_composite() {
    let s = seed(0xacce1);
    let rtl = rtl(4, 64);
    let (vol, lut) = scene(head_phantom(64, 12).unwrap(), rtl.fetch.block_dim);
    let mut bench = must(AccelBench::new(rtl, s));
    frame(
        &mut bench,
        &vol,
        &lut,
        ("+z", [0.0, 0.0, 1.0]),
        Render::Composite,
        &MemEnv::quiet(),
        s,
    );
    let _ = (bubbles_phantom, ChaCha8Rng::seed_from_u64(s));
}
