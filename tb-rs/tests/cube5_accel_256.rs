//! Co-simulation of the synthesized 256^3 lines of the accelerator top `cube5_accel` (the
//! `.variants` lines flagged `synthfull`: the window's MaxDim 256 memory system with 16-anchor
//! sections and the widths narrowed so that the LFE5UM-85F holds it; docs/accel.md, *Synthesis*,
//! *The 256^3 lines*). The lines are `full` (only `make sim-full` builds them: minutes of Verilator
//! each), so every test here is `sim-full`. The driver and the comparison are the other accelerator
//! tests' (`cube5_tb::accel`): the image in the memory bit-exact against the frame model at the
//! line's widths.
//!
//!     CUBE5_FULL=1 CUBE5_TOPS=cube5_accel:Section=16:AccW=16:ClassIdxW=10 \
//!       cargo test --release -p cube5-tb --test cube5_accel_256 -- --include-ignored
//!
//! (`CUBE5_TOPS=cube5_accel:...:P=4` builds and runs one line.)

mod support;

use cube5_model::phantom::head_phantom;
use cube5_model::units::cube5_skewmem::BlockLut;
use cube5_tb::accel::{count_by_id, AccelBench, AccelRtl, FrameRun, IdCount, MemEnv, TOP};
use cube5_tb::frame::{Expected, Look, Render, OBLIQUE_Z, VIEWS};
use cube5_tb::variants::variants_of;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;
use std::rc::Rc;
use support::{must, seed};

/// The synthesized lines that this run built (`synthfull`, in `.variants` order).
fn synthesized() -> Vec<AccelRtl> {
    let builds: Vec<AccelRtl> = variants_of(TOP)
        .into_iter()
        .filter(|v| v.has_flag("synthfull"))
        .map(|v| must(AccelRtl::from_variant(v)))
        .collect();
    assert!(
        !builds.is_empty(),
        "no `synthfull` line of {TOP} built (CUBE5_FULL=1 builds them)"
    );
    builds
}

type View = (&'static str, [f64; 3]);

/// Exactly 45 degrees between +x and +z (`cube5_tb::frame::VIEWS`).
fn view_45() -> View {
    *VIEWS
        .iter()
        .find(|v| v.0 == "45 xz")
        .expect("the 45 degree view")
}

/// Bursts and beats per AXI4 ID, from the memory's handshake log.
type ById = BTreeMap<u32, IdCount>;

/// What one frame of [`head_frames`] did: the run, and its read and write bursts and beats per
/// ID (reads: 0 the volume, 1 the ring; writes: 0 the clear, 1 the ring, 2 the final pixels).
struct Frame {
    run: FrameRun,
    reads: ById,
    writes: ById,
}

/// The head phantom (12-bit voxels) at `n`^3 in the memory of `rtl`, and `frames` rendered in
/// turn (the default look: composite is shaded), each under its memory (`None`: a random one,
/// `MemEnv::random`) and bit-exact; their figures printed and returned.
fn head_frames(
    rtl: AccelRtl,
    n: usize,
    s: u64,
    frames: &[(View, Render, Option<&MemEnv>)],
) -> Vec<Frame> {
    let vol = Rc::new(head_phantom(n, 12).unwrap());
    let lut = BlockLut::from_volume(&vol, rtl.fetch.block_dim as usize, 0).unwrap();
    let mut bench = must(AccelBench::new(rtl, s));
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let mut out = Vec::new();
    for &((name, dir), render, env) in frames {
        let e = Expected::new(&rtl.frame, &vol, name, dir, render, &Look::default())
            .unwrap_or_else(|err| panic!("{}: {err}", rtl.variant));
        let (env, what) = match env {
            Some(env) => (env.clone(), "the given memory"),
            None => (MemEnv::random(&mut rng), "a random memory"),
        };
        let mem_seed = rng.random();
        must(bench.dut.axi_take_ar());
        must(bench.dut.axi_take_aw());
        let img_base = must(bench.start(&e, &vol, &lut, &env, mem_seed));
        let run = must(bench.finish(&e, img_base, mem_seed));
        let (reads, writes) = (
            count_by_id(&must(bench.dut.axi_take_ar())),
            count_by_id(&must(bench.dut.axi_take_aw())),
        );
        eprintln!(
            "{}: {n}^3 head {name} {render:?}, {what} (latency {:?}, bytes/cycle {:?}): {:.3} samples/clock/pipeline, {run:?}; by ID (bursts, beats): reads {reads:?}, writes {writes:?}",
            rtl.variant,
            env.latency,
            env.bw,
            run.rate(rtl.p)
        );
        out.push(Frame { run, reads, writes });
    }
    out
}

/// Every synthesized line: the 64^3 head at exactly 45 degrees composite (shaded) and at an
/// oblique view (DX < 0, a reversed sweep) in MIP, each under its own random memory (latency
/// 10..200, gaps on all five channels, the host's B and R back-pressured); bit-exact.
#[test]
#[ignore = "sim-full: the synthesized 256^3 lines are `full` (minutes of Verilator each)"]
fn synthesized_lines_64() {
    let s = seed(0xacce256);
    for rtl in synthesized() {
        let frames = [
            (view_45(), Render::Composite, None),
            (OBLIQUE_Z, Render::Mip, None),
        ];
        head_frames(rtl, 64, s, &frames);
    }
}

/// The benchmark's DDR-like memory at `bytes` bytes per cycle shared by reads and writes: latency
/// 100 + U(0..20) cycles on every burst, no gaps.
fn ddr(bytes: u32) -> MemEnv {
    MemEnv {
        latency: (100, 20),
        gaps: [0; 5],
        bw: (bytes, 1),
        host_stall: Vec::new(),
    }
}

/// Every synthesized line: the `n`^3 head at exactly 45 degrees, composite (shaded), under the
/// DDR-like memory at each of `bytes` bytes per cycle, each frame on its own bench with the same
/// seed (so the same memory seed at every bandwidth): bit-exact, its cycles printed. The
/// volume's reads (ID 0) are the same bursts and beats at every bandwidth.
fn head_45_ddr(n: usize, s: u64, bytes: &[u32]) {
    let mut table = Vec::new();
    for rtl in synthesized() {
        let mut volume = None;
        for &b in bytes {
            let f = head_frames(rtl, n, s, &[(view_45(), Render::Composite, Some(&ddr(b)))]);
            let f = &f[0];
            let vol = f.reads.get(&0).copied().unwrap_or_default();
            assert_eq!(
                *volume.get_or_insert(vol),
                vol,
                "{}: the volume's read bursts and beats at {b} bytes/cycle",
                rtl.variant
            );
            let r = f.run;
            let fin = f.writes.get(&2).copied().unwrap_or_default();
            let bytes_moved = (r.r_beats + r.w_beats) * u64::from(rtl.fetch.data_w / 8);
            table.push(format!(
                "| {} | {b} | {} | {:.3} | {} / {} | {} / {} | {} / {} | {:.2} ({:.0} %) |",
                rtl.p,
                r.cycles,
                r.rate(rtl.p),
                r.ar,
                r.r_beats,
                r.aw,
                r.w_beats,
                fin.bursts,
                fin.beats,
                bytes_moved as f64 / r.cycles as f64,
                100.0 * bytes_moved as f64 / (r.cycles as f64 * f64::from(b)),
            ));
        }
    }
    eprintln!(
        "{n}^3 head, 45 xz, composite, DDR-like memory:\n| P | bytes/cycle | cycles | samples/clock/pipeline | read bursts / beats | write bursts / beats | of which final pixels (ID 2) | channel bytes/cycle (of the limit) |\n|--:|--:|--:|--:|--:|--:|--:|--:|\n{}",
        table.join("\n")
    );
}

/// Every synthesized line: the 128^3 head at 45 degrees under the DDR-like memory, an eighth of
/// the 256^3 frame's simulation for the throughput work (docs/accel.md, *The 256^3 lines*).
#[test]
#[ignore = "sim-full: 128^3 frames on the synthesized lines, a minute each"]
fn synthesized_lines_128() {
    head_45_ddr(128, seed(0xacce128), &[12]);
}

/// Every synthesized line at its size: the 256^3 head at 45 degrees under the DDR-like memory:
/// the cycles the frames per second at the placed Fmax come from (docs/accel.md, *The 256^3
/// lines*).
#[test]
#[ignore = "sim-full: 256^3 frames on the synthesized lines, minutes each"]
fn synthesized_lines_256() {
    head_45_ddr(256, seed(0xacce257), &[12]);
}

/// Every synthesized line: the 128^3 head at exactly 45 degrees, composite, under the DDR-like
/// memory at 12, 16 and 24 bytes per cycle (the same latency, the same memory seed as
/// `synthesized_lines_128`): where the whole frame's throughput goes with the memory's
/// bandwidth (docs/accel.md, *Throughput against memory bandwidth*).
#[test]
#[ignore = "sim-full: 128^3 frames on the synthesized lines, a minute each"]
fn bandwidth_sweep_128() {
    head_45_ddr(128, seed(0xacce128), &[12, 16, 24]);
}

/// Every synthesized line at its size: the 256^3 head at 45 degrees, composite, under the
/// DDR-like memory at 12, 16 and 24 bytes per cycle (the same memory seed as
/// `synthesized_lines_256`; docs/accel.md, *Throughput against memory bandwidth*).
#[test]
#[ignore = "sim-full: 256^3 frames on the synthesized lines, minutes each"]
fn bandwidth_sweep_256() {
    head_45_ddr(256, seed(0xacce257), &[12, 16, 24]);
}
