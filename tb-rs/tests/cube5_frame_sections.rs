//! Co-simulation of cube5_frame fed by a beat stream in sections (`Source = 1`; issue 12,
//! docs/numerics/frame.md, "Sections"): the beats of each section come from the model (the volume
//! read in the section's order with its edge voxels lo, hi0, hi1, as cube5_section_buf delivers
//! them) with random idle cycles, the read-out under random back-pressure, and the whole base plane
//! is compared bit for bit with the frame model's whole-frame image. Driver:
//! `cube5_tb::frame_stream`.

mod support;

use cube5_model::phantom::head_phantom;
use cube5_model::units::cube5_frame::sections::section_order;
use cube5_model::volume::Volume;
use cube5_tb::frame::{Expected, FrameRtl, Look, Render};
use cube5_tb::frame_stream::{items_of, StreamBench, StreamIn};
use cube5_tb::rtl::Traffic;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::rc::Rc;
use support::{must, seed};

/// The stream configuration with `p` pipelines and the largest memory.
fn stream(p: usize) -> FrameRtl {
    FrameRtl::streams()
        .into_iter()
        .filter(|r| r.p == p && r.default_widths())
        .max_by_key(|r| r.max_dim_log2)
        .unwrap_or_else(|| panic!("no cube5_frame variant with Source = 1 and P = {p}"))
}

/// The head phantom of edge `n` (12-bit voxels).
fn phantom(n: usize) -> Rc<Volume> {
    Rc::new(head_phantom(n, 12).unwrap())
}

/// A bench of `rtl` (the DUT seeded with `s`) and random traffic from seed `s`: `idle` of the input
/// cycles idle, `stall` of the output cycles stalled.
fn bench_with_traffic(rtl: FrameRtl, s: u64, idle: f64, stall: f64) -> (StreamBench, Traffic) {
    let bench = must(StreamBench::new(rtl, s as u32));
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    (bench, Traffic::random(&mut rng, idle, stall))
}

/// Faces (DX = 0), 45 degrees, obliques with DX > 0 and DX < 0 along the beam axis.
const VIEWS: &[(&str, [f64; 3])] = &[
    ("+z", [0.0, 0.0, 1.0]),
    ("-x", [-1.0, 0.0, 0.0]),
    ("+y", [0.0, 1.0, 0.0]),
    ("45 xz", [1.0, 0.0, 1.0]),
    ("45 -x-y", [-1.0, -1.0, 0.0]),
    ("oblique dx<0", [-0.6, 0.3, 1.0]),
    ("oblique -z", [0.37, 0.81, -1.0]),
];

fn expect(rtl: &FrameRtl, vol: &Rc<Volume>, view: (&str, [f64; 3]), render: Render) -> Expected {
    Expected::new(rtl, vol, view.0, view.1, render, &Look::default()).unwrap()
}

/// Whole 32^3 frames at P = 4 in sections of 8, 16 and the whole face, MIP and composite (and
/// MinIP in sections of 8), with
/// 30 % idle beats and 30 % back-pressure: every pixel and the beat count as the model's.
#[test]
fn sectioned_frames_bit_exact_p4() {
    let s = seed(1);
    let rtl = stream(4);
    let vol = phantom(32);
    let (mut bench, traffic) = bench_with_traffic(rtl, s, 0.3, 0.3);
    for (n, &view) in VIEWS.iter().enumerate() {
        for render in [Render::Mip, Render::Composite] {
            let e = expect(&rtl, &vol, view, render);
            // Every width on two views, one of them per view otherwise (the CI budget).
            let widths: &[usize] = if n < 2 {
                &[8, 16, 32]
            } else {
                &[[16, 32, 8][n % 3]]
            };
            for &w in widths {
                must(bench.check(&e, w, &traffic, s));
            }
        }
        // MinIP in four sections: a sample past the x far face is left out only in the section
        // that holds the face's last anchor (cube5_frame_cbuf's `far_x_i`).
        let e = expect(&rtl, &vol, view, Render::Minip);
        must(bench.check(&e, 8, &traffic, s));
    }
}

/// P = 1: sections of 16 and the whole face of a 16^3 volume.
#[test]
fn sectioned_frames_bit_exact_p1() {
    let s = seed(2);
    let rtl = stream(1);
    let vol = phantom(16);
    let (mut bench, traffic) = bench_with_traffic(rtl, s, 0.2, 0.3);
    for &view in &VIEWS[3..] {
        for (render, w) in [(Render::Composite, 4), (Render::Mip, 16)] {
            let e = expect(&rtl, &vol, view, render);
            must(bench.check(&e, w, &traffic, s));
        }
    }
}

/// A reset in the middle of a sectioned frame, then the whole frame exact; a frame left without
/// its last section, then a new frame (its first section clears the buffer): exact.
#[test]
fn reset_mid_frame_and_an_abandoned_frame() {
    let s = seed(3);
    let rtl = stream(4);
    let vol = phantom(32);
    let (mut bench, traffic) = bench_with_traffic(rtl, s, 0.2, 0.2);
    let e = expect(&rtl, &vol, VIEWS[6], Render::Composite);
    must(bench.load(&e));
    let order = section_order(&e.params, 16, rtl.p).unwrap();
    let (items, beats) = items_of(&rtl, &e, &order, true);
    // Halfway through the second section.
    let d = must(bench.dut.drive(&items, &traffic, u64::MAX, beats * 3 / 4));
    assert!(d.outputs.is_empty(), "no pixel before the last section");
    bench.dut.reset();
    let got = must(bench.drive(&e, &items, &traffic));
    must(bench.compare(&e, &got, beats, "after a reset mid-frame", s));

    // The first section of a frame alone (no last section), then a whole frame of another view.
    let (first, _) = items_of(&rtl, &e, &order[..1], false);
    let d = must(
        bench
            .dut
            .drive(&first, &traffic, 1, 100 * first.len() as u64),
    );
    assert!(
        d.outputs.is_empty(),
        "a section that is not the last has no output"
    );
    let e2 = expect(&rtl, &vol, VIEWS[4], Render::Mip);
    must(bench.check(&e2, 16, &traffic, s));
}

/// Sections the frame refuses, one error item each: a first anchor or width not a multiple of
/// P, a section past the face, rows of one beat; and a good frame after them.
#[test]
fn bad_sections_refused() {
    let s = seed(4);
    let rtl = stream(4);
    let vol = phantom(32);
    let mut bench = must(StreamBench::new(rtl, s as u32));
    let e = expect(&rtl, &vol, VIEWS[0], Render::Mip);
    must(bench.load(&e));
    for (a0, ns) in [(2, 16), (0, 18), (24, 16), (0, 4), (32, 8)] {
        let cmd = StreamIn::Cmd(cube5_tb::frame_stream::SecCmd {
            op: cube5_tb::frame::OP_RENDER,
            a0,
            ns,
            first: true,
            last: true,
        });
        let d = must(bench.dut.drive(&[cmd], &Traffic::full_speed(), 1, 1000));
        assert!(
            d.outputs.len() == 1 && d.outputs[0].value.error,
            "section ({a0}, {ns}) not refused with one error item"
        );
    }
    must(bench.check(&e, 16, &Traffic::full_speed(), s));
}

/// 64^3 frames in sections of 16, 32 and 64, the views above, MIP and composite.
#[test]
#[ignore = "sim-full: 64^3 sectioned frames, several minutes"]
fn sectioned_frames_64_bit_exact() {
    let s = seed(5);
    let rtl = stream(4);
    let vol = phantom(64);
    let (mut bench, traffic) = bench_with_traffic(rtl, s, 0.135, 0.2);
    for &view in VIEWS {
        for render in [Render::Mip, Render::Composite] {
            let e = expect(&rtl, &vol, view, render);
            for w in [16, 32, 64] {
                must(bench.check(&e, w, &traffic, s));
            }
        }
    }
}

/// The cycle budget of a sectioned frame (docs/frame-rtl.md, *Cycle budget*, `Source = 1`): per
/// section set-up 3 + its beats + the flush `nbs + 2 nbr + 2` (its own row and slice lengths) + the
/// pipeline (the units' latencies, no memory), at full speed exactly; the read-out one pixel per
/// clock. With 13.5 % of the input cycles idle (0.865 beams per clock, what cube5_section_buf
/// delivers with every block present) the sweep stretches by the idle beats only.
fn budget(
    rtl: &FrameRtl,
    vol: &Rc<Volume>,
    view: (&str, [f64; 3]),
    w: usize,
    idle: f64,
    s: u64,
) -> (u64, u64, u64) {
    let (mut bench, traffic) = bench_with_traffic(*rtl, s, idle, 0.0);
    let e = expect(rtl, vol, view, Render::Composite);
    must(bench.load(&e));
    let order = section_order(&e.params, w, rtl.p).unwrap();
    let (items, beats) = items_of(rtl, &e, &order, true);
    let got = must(bench.drive(&e, &items, &traffic));
    let (_, sweep) = must(bench.compare(&e, &got, beats, &format!("S = {w}, idle {idle}"), s));
    let pipeline = rtl.pipeline_latency();
    let ideal: u64 = order
        .iter()
        .map(|sec| {
            let (nbr, nbs) = (sec.ns / rtl.p, sec.ns * e.params.nj / rtl.p);
            3 + (nbs * e.params.nk) as u64 + (nbs + 2 * nbr + 2) as u64 + pipeline
        })
        .sum();
    // The read-out: one item per clock, OutLanes pixels of a row each.
    let n = cube5_tb::frame::items_for(e.w, e.h, rtl.out_lanes);
    assert_eq!(
        got.taken_at[got.taken_at.len() - 1] - got.taken_at[0] + 1,
        n,
        "one item of {} pixels per clock",
        rtl.out_lanes
    );
    eprintln!(
        "{} S = {w}: read-out {n} cycles for {} x {} pixels ({} per item; {} at one per clock)",
        rtl.variant,
        e.w,
        e.h,
        rtl.out_lanes,
        e.w * e.h
    );
    (u64::from(sweep), ideal, beats)
}

#[test]
fn cycle_budget_of_a_sectioned_frame() {
    let s = seed(6);
    let vol = phantom(32);
    for rtl in [stream(4), stream(1)] {
        for w in [16, 32] {
            let (sweep, ideal, beats) = budget(&rtl, &vol, VIEWS[6], w, 0.0, s);
            assert_eq!(
                sweep, ideal,
                "{} S = {w}: sweep cycles at full speed",
                rtl.variant
            );
            let (slow, _, _) = budget(&rtl, &vol, VIEWS[6], w, 0.135, s);
            let samples = (beats * rtl.p as u64) as f64;
            eprintln!(
                "{} 32^3 S = {w}: sweep {sweep} cycles at full speed ({:.3} samples/clock/pipeline), {slow} at 0.865 beams/clock ({:.3})",
                rtl.variant,
                samples / rtl.p as f64 / sweep as f64,
                samples / rtl.p as f64 / slow as f64
            );
            // The idle cycles fall on beats only: at most beats / 0.8 more than the ideal.
            assert!(
                slow > sweep && slow < ideal + beats / 4,
                "{} S = {w}: {slow} cycles",
                rtl.variant
            );
        }
    }
}

/// The figures of docs/measurements.md (*cube5_frame fed by a beat stream*): 64^3, S = 16, 32, 64.
#[test]
#[ignore = "sim-full: the measurement of docs/measurements.md, 64^3 frames"]
fn measure_sectioned_frames_64() {
    let s = seed(7);
    let vol = phantom(64);
    let rtl = stream(4);
    for w in [16, 32, 64] {
        for idle in [0.0, 0.135] {
            let (sweep, ideal, beats) = budget(&rtl, &vol, VIEWS[6], w, idle, s);
            let samples = (beats * rtl.p as u64) as f64;
            eprintln!(
                "MEASURE {} 64^3 oblique S = {w} idle {idle}: sweep {sweep} cycles (ideal {ideal}), {:.3} samples/clock/pipeline",
                rtl.variant,
                samples / rtl.p as f64 / sweep as f64
            );
        }
    }
}

/// The buffer's RTL into the frame's RTL (issue 12, the accelerator's data path without DRAM):
/// the fetch's items (its model, over the volume's blocked DRAM image with the empty blocks
/// skipped) go into `cube5_section_buf`'s RTL with each section command, and the beams that RTL
/// delivers, unchanged, go into the frame behind the frame's section commands; random idle and
/// back-pressure on both. The image is the frame model's, bit for bit. Runs on each build of the
/// buffer that agrees with a stream frame on P and the voxel width.
#[test]
fn section_buffer_rtl_into_the_frame() {
    use cube5_model::units::cube5_section_buf::{frame_dims, SectionBufConfig, SectionCmd};
    use cube5_model::units::cube5_skewmem::BlockLut;
    use cube5_model::units::cube5_vol_fetch::{dram_image, FetchCmd, VolFetch};
    use cube5_tb::frame_stream::SecCmd;
    let s = seed(8);
    let mut pairs = 0;
    for rtl in FrameRtl::streams()
        .into_iter()
        .filter(|r| r.default_widths())
    {
        for (sv, scfg) in support::configs::<SectionBufConfig>() {
            let (p, vw) = (rtl.p as u32, rtl.trilin.voxel_w);
            if (scfg.p, scfg.voxel_w) != (p, vw) || 2 * scfg.section as usize > rtl.max_dim() {
                continue;
            }
            pairs += 1;
            // Two sections along i (x), a view with DX < 0 (right to left) and one with DX > 0.
            let n = 2 * scfg.section as usize;
            let big = head_phantom(n, 12).unwrap();
            let dims = [n, 32, 32];
            let data = (0..n * 32 * 32)
                .map(|q| {
                    big.get((q % n) as i64, ((q / n) % 32) as i64, (q / (n * 32)) as i64) as u16
                })
                .collect();
            let vol = Volume::new(dims, [1.0; 3], 12, data).unwrap();
            let lut = BlockLut::from_volume(&vol, scfg.block_dim as usize, 0).unwrap();
            let seen = Rc::new(cube5_tb::frame::as_seen(&vol, &lut).unwrap());
            let fcfg = scfg.fetch();
            let img = dram_image(&vol, &lut, 0).unwrap();
            let mut rng = ChaCha8Rng::seed_from_u64(s);
            let mut bench = must(StreamBench::new(rtl, s as u32));
            for (view, render) in [
                (("dx<0", [-0.3, 0.2, 1.0]), Render::Composite),
                (("dx>0", [0.5, -0.4, -1.0]), Render::Mip),
            ] {
                let e = expect(&rtl, &seen, view, render);
                assert!(
                    e.want.iter().any(|c| c.rgba[3] > 0),
                    "{}: an empty image",
                    view.0
                );
                let order = section_order(&e.params, scfg.section as usize, rtl.p).unwrap();
                let fd = frame_dims(vol.dims, e.params.axis_k as u32);
                let cmds: Vec<SectionCmd> = order
                    .iter()
                    .map(|sec| SectionCmd {
                        axis_k: e.params.axis_k as u32,
                        reversed: e.params.k_reversed,
                        dims: fd,
                        a0: sec.a0 as u32,
                    })
                    .collect();
                let mut fetch_in = fcfg.lut_writes(&lut).unwrap();
                fetch_in.extend(cmds.iter().map(|c| FetchCmd::Sweep(scfg.sweep(c, 0))));
                let items = VolFetch::new(fcfg)
                    .unwrap()
                    .run(&fetch_in, &img)
                    .unwrap()
                    .items;
                let input = support::section_buf_input(&cmds, items);
                let beats: usize = order
                    .iter()
                    .map(|sec| e.params.nk * e.params.nj * sec.ns / rtl.p)
                    .sum();
                let mut sbuf = cube5_tb::RtlStream::new(sv, scfg, s as u32).unwrap();
                let traffic = Traffic::random(&mut rng, 0.1, 0.135);
                let d = sbuf
                    .drive(
                        &input,
                        &traffic,
                        beats as u64,
                        200_000 + 20 * (beats + input.len()) as u64,
                    )
                    .unwrap();
                assert_eq!(d.outputs.len(), beats, "{sv}: every beam out");
                // The frame: each section's command, then the buffer's beams of that section.
                let mut frame_in = Vec::new();
                let mut out = d.outputs.into_iter().map(|t| t.value);
                for (k, sec) in order.iter().enumerate() {
                    frame_in.push(StreamIn::Cmd(SecCmd {
                        op: cube5_tb::frame::OP_RENDER,
                        a0: sec.a0 as u32,
                        ns: sec.ns as u32,
                        first: k == 0,
                        last: k + 1 == order.len(),
                    }));
                    let nbeats = e.params.nk * e.params.nj * sec.ns / rtl.p;
                    frame_in.extend(out.by_ref().take(nbeats).map(StreamIn::Beat));
                }
                must(bench.load(&e));
                let traffic = Traffic::random(&mut rng, 0.2, 0.3);
                let got = must(bench.drive(&e, &frame_in, &traffic));
                must(bench.compare(
                    &e,
                    &got,
                    beats as u64,
                    &format!("{sv} -> {}", rtl.variant),
                    s,
                ));
                eprintln!(
                    "{sv} -> {}: {:?} {} in {} sections of {}: every pixel the model's",
                    rtl.variant,
                    vol.dims,
                    view.0,
                    order.len(),
                    scfg.section
                );
            }
        }
    }
    assert!(
        pairs > 0,
        "no build of cube5_section_buf agrees with a stream frame on P and VoxelW"
    );
}
