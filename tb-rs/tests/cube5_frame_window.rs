//! Co-simulation of cube5_frame with the compositing window (`Window = 1`; issue 12,
//! docs/numerics/compos_window.md, *RTL*): a frame fed by a beat stream in sections that keeps
//! only the section's active rays on chip. The test bench plays DRAM for the window's streams
//! (tb/win_shim.h): it stores every parked coxel, answers the restore requests in order after a
//! random latency, collects the final pixels, each output under its own random back-pressure.
//! Every park item, final pixel and restore request must be the model's
//! (`cube5_frame::window::render_window`), in the model's order, and the image assembled from the
//! final pixels (the initial coxel where no sample reached) the whole-plane frame model's, bit for
//! bit.

mod support;

use cube5_model::phantom::head_phantom;
use cube5_model::units::cube5_compos::Coxel;
use cube5_model::units::cube5_frame::sections::section_order;
use cube5_model::units::cube5_frame::window::{render_window, WindowTraffic};
use cube5_model::volume::Volume;
use cube5_tb::error::Mismatch;
use cube5_tb::frame::{Expected, FrameRtl, Look, Render};
use cube5_tb::frame_stream::{items_of, StreamBench};
use cube5_tb::rtl::{Traffic, WinSetup};
use cube5_tb::TbError;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::rc::Rc;
use support::{must, seed};

/// The builds with the compositing window, `p` pipelines.
fn window(p: usize) -> FrameRtl {
    FrameRtl::windows()
        .into_iter()
        .find(|r| r.p == p)
        .unwrap_or_else(|| panic!("no cube5_frame variant with Window = 1 and P = {p}"))
}

/// Faces, 45 degrees both ways, obliques with DX > 0 and DX < 0.
const VIEWS: &[(&str, [f64; 3])] = &[
    ("+z", [0.0, 0.0, 1.0]),
    ("-x", [-1.0, 0.0, 0.0]),
    ("45 xz", [1.0, 0.0, 1.0]),
    ("45 -x-y", [-1.0, -1.0, 0.0]),
    ("oblique dx<0", [-0.6, 0.3, 1.0]),
    ("oblique -z", [0.37, 0.81, -1.0]),
    ("(1, 1, 1)", [1.0, 1.0, 1.0]),
];

/// The window DRAM's traffic: stalls on the three outputs, idle and latency on the restores.
fn dram(rng: &mut ChaCha8Rng, busy: bool) -> WinSetup {
    use rand::Rng;
    let pm = |rng: &mut ChaCha8Rng| if busy { rng.random_range(100..400) } else { 0 };
    WinSetup {
        seed: rng.random(),
        park_stall: pm(rng),
        fin_stall: pm(rng),
        rq_stall: pm(rng),
        rs_idle: pm(rng),
        lat_fixed: if busy { rng.random_range(5..60) } else { 0 },
        lat_random: if busy { rng.random_range(0..100) } else { 0 },
        expect_final: 0,
    }
}

/// A frame: the expected image and the model's window streams for sections of `width`.
struct Case {
    e: Expected,
    t: WindowTraffic,
    width: usize,
}

fn case(
    rtl: &FrameRtl,
    vol: &Rc<Volume>,
    view: (&str, [f64; 3]),
    render: Render,
    width: usize,
) -> Case {
    let look = Look::default();
    let e = Expected::new(rtl, vol, view.0, view.1, render, &look).unwrap();
    let (_, fu) = Expected::model_units(rtl, vol, view.1, render, &look).unwrap();
    let order = section_order(&e.params, width, rtl.p).unwrap();
    let (bp, t) = render_window(&e.params, vol, &fu, &order, rtl.p).unwrap();
    assert!(
        bp.coxels == e.want,
        "the window model's image is the frame's"
    );
    Case { e, t, width }
}

/// The stored fields of a coxel ({terminated, A, B, G, R}, R lowest) from record words.
fn stored(rtl: &FrameRtl, words: &[u32], lane: usize) -> Coxel {
    let cw = rtl.compos.acc_w + 1;
    let base = lane as u32 * (4 * cw + 1);
    let bit = |i: u32| (words[(i / 32) as usize] >> (i % 32)) & 1;
    let field = |at: u32, n: u32| (0..n).fold(0u64, |v, i| v | (u64::from(bit(at + i)) << i));
    Coxel {
        rgba: std::array::from_fn(|c| field(base + c as u32 * cw, cw)),
        terminated: bit(base + 4 * cw) == 1,
        ..Coxel::empty(&rtl.compos)
    }
}

fn same(a: &Coxel, b: &Coxel) -> bool {
    a.rgba == b.rgba && a.terminated == b.terminated
}

/// What one window frame did: cycles of the drive.
fn run(
    bench: &mut StreamBench,
    c: &Case,
    traffic: &Traffic,
    win: WinSetup,
    seed: u64,
) -> Result<u64, TbError> {
    let rtl = bench.rtl;
    let e = &c.e;
    bench.load(e)?;
    let order = section_order(&e.params, c.width, rtl.p).unwrap();
    let (items, _) = items_of(&rtl, e, &order, true);
    bench.dut.win_setup(&WinSetup {
        expect_final: c.t.final_out,
        ..win
    })?;
    let start = bench.dut.cycle();
    let limit = 60 * items.len() as u64 + 200_000;
    let d = bench.dut.drive(&items, traffic, 0, limit)?;
    let cycles = bench.dut.cycle() - start;
    let (raw, words) = bench.dut.win_take();
    let ctx = format!(
        "{} view {} {:?} S = {}, seed {seed}",
        rtl.variant, e.view, e.units.render, c.width
    );
    let fail = |what: String| {
        Err(TbError::from(Mismatch {
            variant: rtl.variant.name.to_string(),
            seed,
            input: ctx.clone(),
            what,
            ..Default::default()
        }))
    };
    if d.stats.protocol_errors > 0 || bench.dut.win_errors() > 0 || !d.outputs.is_empty() {
        return fail(format!(
            "protocol errors {}, window errors {}, {} output items",
            d.stats.protocol_errors,
            bench.dut.win_errors(),
            d.outputs.len()
        ));
    }
    let dim_w = rtl.max_dim_log2 + 1;
    let key = |k: u32| ((k & ((1 << dim_w) - 1)) as usize, (k >> dim_w) as usize);
    let (mut parks, mut finals, mut requests) = (Vec::new(), Vec::new(), Vec::new());
    for r in raw.chunks(words) {
        let (x, q) = key(r[2]);
        match r[0] {
            0 => parks.push((x, q, stored(&rtl, &r[4..], 0))),
            1 => {
                for k in 0..rtl.p {
                    if r[3] >> k & 1 == 1 {
                        finals.push((x + k, q, stored(&rtl, &r[4..], k)));
                    }
                }
            }
            _ => requests.push((x, q)),
        }
    }
    let st = &c.t.streams;
    let seq = |name: &str, got: &[(usize, usize, Coxel)], want: &[(usize, usize, Coxel)]| {
        if got.len() != want.len() {
            return Some(format!(
                "{} {name} items, the model {}",
                got.len(),
                want.len()
            ));
        }
        got.iter()
            .zip(want)
            .position(|(g, w)| (g.0, g.1) != (w.0, w.1) || !same(&g.2, &w.2))
            .map(|n| format!("{name} item {n}: RTL {:?}, model {:?}", got[n], want[n]))
    };
    if let Some(w) = seq("park", &parks, &st.parked) {
        return fail(w);
    }
    if requests != st.restores {
        return fail(format!(
            "restore requests: RTL {} {:?}.., model {} {:?}..",
            requests.len(),
            &requests[..requests.len().min(4)],
            st.restores.len(),
            &st.restores[..st.restores.len().min(4)]
        ));
    }
    if let Some(w) = seq("final", &finals, &st.finals) {
        return fail(w);
    }
    // The image: the final pixels over the initial coxel.
    let mut image = vec![e.units.initial_coxel(); e.w * e.h];
    for (x, q, cx) in &finals {
        image[q * e.w + x] = *cx;
    }
    if let Some(i) = (0..image.len()).find(|&i| !same(&image[i], &e.want[i])) {
        return fail(format!(
            "pixel ({}, {}): RTL {:?}, frame model {:?}",
            i % e.w,
            i / e.w,
            image[i],
            e.want[i]
        ));
    }
    Ok(cycles)
}

/// 32^3 frames at P = 4 in sections of 8 and 16 (and 4 at P = 1 below): faces, 45 degrees,
/// obliques, MIP and composite; 30 % idle beats and back-pressure, the DRAM slow and stalling.
/// `w1p4` is a `full` line (CI's build budget): the accelerator's CI line `w1v8p4s8` runs the
/// window at P = 4 in CI.
#[test]
#[ignore = "sim-full: the P = 4 window build (w1p4) is not in CI's build budget"]
fn window_frames_bit_exact_p4() {
    let s = seed(11);
    let rtl = window(4);
    let vol = Rc::new(head_phantom(32, 12).unwrap());
    let mut bench = must(StreamBench::new(rtl, s as u32));
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let traffic = Traffic::random(&mut rng, 0.3, 0.3);
    let mut parked = 0;
    for (n, &view) in VIEWS.iter().enumerate() {
        for (m, render) in [Render::Mip, Render::Composite].into_iter().enumerate() {
            let width = [8, 16][(n + m) % 2];
            let c = case(&rtl, &vol, view, render, width);
            parked += c.t.parked;
            let win = dram(&mut rng, true);
            must(run(&mut bench, &c, &traffic, win, s));
        }
    }
    // MinIP: its initial coxel (A all ones) for the fresh pixels, and the samples past the x far
    // face left out in the section that holds the face's last anchor only.
    let c = case(&rtl, &vol, VIEWS[4], Render::Minip, 8);
    must(run(&mut bench, &c, &traffic, dram(&mut rng, true), s));
    assert!(parked > 0, "no frame parked a coxel");
}

/// Every view, sections of 8 and 16, MIP, composite and MinIP, at P = 4 (and P = 1 on 16^3).
#[test]
#[ignore = "sim-full: every view, width and mode through the window, a minute"]
fn window_frames_every_view_and_mode() {
    let s = seed(15);
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    for (p, n, widths) in [(4, 32, &[8, 16][..]), (1, 16, &[4, 8, 16][..])] {
        let rtl = window(p);
        let vol = Rc::new(head_phantom(n, 12).unwrap());
        let mut bench = must(StreamBench::new(rtl, s as u32));
        let traffic = Traffic::random(&mut rng, 0.2, 0.2);
        for &view in VIEWS {
            for render in [Render::Mip, Render::Composite, Render::Minip] {
                for &width in widths {
                    let c = case(&rtl, &vol, view, render, width);
                    must(run(&mut bench, &c, &traffic, dram(&mut rng, true), s));
                }
            }
        }
    }
}

/// P = 1, 16^3: sections of 4 (many boundaries), 8 and 16.
#[test]
fn window_frames_bit_exact_p1() {
    let s = seed(12);
    let rtl = window(1);
    let vol = Rc::new(head_phantom(16, 12).unwrap());
    let mut bench = must(StreamBench::new(rtl, s as u32));
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let traffic = Traffic::random(&mut rng, 0.2, 0.3);
    for (n, &view) in VIEWS.iter().enumerate() {
        let render = [Render::Composite, Render::Mip][n % 2];
        let c = case(&rtl, &vol, view, render, [4, 8, 16][n % 3]);
        let win = dram(&mut rng, true);
        must(run(&mut bench, &c, &traffic, win, s));
    }
}

/// A reset in the middle of a frame (parks and restores in flight), then the frame exact.
#[test]
fn window_reset_mid_frame() {
    let s = seed(13);
    let rtl = window(1);
    let vol = Rc::new(head_phantom(16, 12).unwrap());
    let mut bench = must(StreamBench::new(rtl, s as u32));
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let traffic = Traffic::random(&mut rng, 0.2, 0.2);
    let c = case(&rtl, &vol, VIEWS[4], Render::Composite, 4);
    assert!(c.t.parked > 0);
    must(bench.load(&c.e));
    let order = section_order(&c.e.params, 4, rtl.p).unwrap();
    let (items, _) = items_of(&rtl, &c.e, &order, true);
    must(bench.dut.win_setup(&dram(&mut rng, true)));
    let _ = must(
        bench
            .dut
            .drive(&items[..items.len() * 5 / 8], &traffic, 0, 1_000_000),
    );
    bench.dut.reset();
    let _ = bench.dut.win_take();
    let win = dram(&mut rng, true);
    must(run(&mut bench, &c, &traffic, win, s));
}

/// Throughput: a 45-degree and an oblique frame at full speed (no idle, no stall, DRAM at once
/// and at 40 cycles), against the same frame through the whole-plane build (`Window = 0`) with
/// the same P: the sweep's samples per clock per pipeline. P = 1 on 16^3 in CI (`w1p1`).
#[test]
fn window_throughput_against_the_whole_plane() {
    let s = seed(14);
    let rtl = window(1);
    let whole = FrameRtl::streams()
        .into_iter()
        .filter(|r| r.p == rtl.p && r.default_widths())
        .min_by_key(|r| r.max_dim_log2)
        .expect("a Window = 0 stream frame with the window's P");
    let n = 1 << rtl.max_dim_log2;
    let vol = Rc::new(head_phantom(n, 12).unwrap());
    let mut bench = must(StreamBench::new(rtl, s as u32));
    let mut wbench = must(StreamBench::new(whole, s as u32));
    for view in [VIEWS[2], VIEWS[5]] {
        for width in [4, 8] {
            let c = case(&rtl, &vol, view, Render::Composite, width);
            let samples = (c.e.params.ni * c.e.params.nj * c.e.params.nk) as f64;
            let fast = must(run(
                &mut bench,
                &c,
                &Traffic::full_speed(),
                WinSetup::default(),
                s,
            ));
            let slow = must(run(
                &mut bench,
                &c,
                &Traffic::full_speed(),
                WinSetup {
                    lat_fixed: 40,
                    ..WinSetup::default()
                },
                s,
            ));
            let (w0, _) = must(wbench.check(&c.e, width, &Traffic::full_speed(), s));
            let per = |cy: u64| samples / rtl.p as f64 / cy as f64;
            eprintln!(
                "MEASURE {} {n}^3 {} S = {width}: window {fast} cycles ({:.3} samples/clock/pipeline), DRAM latency 40: {slow} ({:.3}); whole plane {} with read-out: {w0} ({:.3}); parked {}",
                rtl.variant,
                view.0,
                per(fast),
                per(slow),
                whole.variant,
                per(w0),
                c.t.parked
            );
            assert!(
                fast < w0 + w0 / 10,
                "the window is not much slower than the whole plane"
            );
        }
    }
}
