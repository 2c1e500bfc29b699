//! Co-simulation of cube5_frame, the slice-order rendering machine (docs/numerics/frame.md,
//! docs/frame-rtl.md), against the golden model: whole base-plane images, bit for bit. The driver
//! (formats, configurations, the model's image, the comparison) is `cube5_tb::frame`.

mod support;

use cube5_model::phantom::head_phantom;
use cube5_model::transfer::{TfPoint, TransferFunction};
use cube5_model::units::cube5_compos::Coxel;
use cube5_model::units::cube5_frame::{self, FrameMode, FrameParams, FrameSetup, FrameUnits};
use cube5_model::units::cube5_skewmem::BlockLut;
use cube5_model::volume::Volume;
use cube5_tb::frame::*;
use cube5_tb::rtl::ConfigWrites;
use cube5_tb::rtl::Traffic;
use cube5_tb::variants::gate_variants_of;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::rc::Rc;
use std::time::Instant;
use support::{must, seed};

/// The largest-memory configuration with `n` pipelines (default widths).
fn p(n: usize) -> FrameRtl {
    FrameRtl::with_pipelines(n).unwrap_or_else(|| panic!("no cube5_frame variant with P = {n}"))
}

/// The smallest-memory configuration with `n` pipelines (narrow widths, synthesizable).
fn narrow(n: usize) -> FrameRtl {
    FrameRtl::smallest(n).unwrap_or_else(|| panic!("no cube5_frame variant with P = {n}"))
}

// -------------------------------------------------------------------------------------------------
// Volumes and views
// -------------------------------------------------------------------------------------------------

/// The test volumes of the acceptance list: 16^3, 32^3, 64^3 head phantoms and a 48 x 32 x 40 blob.
fn volumes(s: u64) -> Vec<(&'static str, Volume)> {
    vec![
        ("head 16^3", head_phantom(16, 12).unwrap()),
        ("head 32^3", head_phantom(32, 12).unwrap()),
        ("head 64^3", head_phantom(64, 12).unwrap()),
        ("blob 48x32x40", blob_volume([48, 32, 40], 12, s)),
    ]
}

// -------------------------------------------------------------------------------------------------
// Driving frames
// -------------------------------------------------------------------------------------------------

/// The model's image of one of the test views at the default look (head transfer function, two
/// lights) or with early termination.
fn expect(
    rtl: &FrameRtl,
    seen: &Rc<Volume>,
    view: (&'static str, [f64; 3]),
    render: Render,
    et: bool,
) -> Expected {
    // With early termination, tissue made nearly opaque: rays must reach the threshold.
    let look = Look {
        early_termination: et,
        tf: if et {
            let p = |density, rgba| TfPoint { density, rgba };
            TransferFunction {
                points: vec![
                    p(0.0, [0.0; 4]),
                    p(0.15, [0.9, 0.7, 0.6, 0.0]),
                    p(0.3, [0.9, 0.7, 0.6, 0.6]),
                    p(1.0, [1.0, 1.0, 1.0, 0.9]),
                ],
            }
        } else {
            TransferFunction::head_default()
        },
        ..Look::default()
    };
    Expected::new(rtl, seen, view.0, view.1, render, &look).unwrap()
}

/// The volume as the memory returns it.
fn seen_of(vol: &Volume, lut: &BlockLut) -> Rc<Volume> {
    Rc::new(as_seen(vol, lut).unwrap())
}

fn bench(rtl: FrameRtl, vol: &Volume, lut: &BlockLut, s: u64) -> FrameBench {
    must(FrameBench::new(rtl, vol, lut, s as u32))
}

/// A bench of `rtl` loaded with `vol` (blocks of 0 empty), and the volume as the RTL sees it.
fn loaded(rtl: FrameRtl, vol: &Volume, s: u64) -> (FrameBench, Rc<Volume>) {
    let lut = BlockLut::from_volume(vol, rtl.block as usize, 0).unwrap();
    let seen = seen_of(vol, &lut);
    (bench(rtl, vol, &lut, s), seen)
}

/// A P = 4 bench loaded with the `n`^3 head phantom, and its oblique composite frame (early
/// termination `et`).
fn oblique_head_p4(n: usize, et: bool, s: u64) -> (FrameRtl, FrameBench, Expected) {
    let rtl = p(4);
    let vol = head_phantom(n, 12).unwrap();
    let (bench, seen) = loaded(rtl, &vol, s);
    (
        rtl,
        bench,
        expect(&rtl, &seen, OBLIQUE_Z, Render::Composite, et),
    )
}

/// Renders views of the acceptance volumes in one rendering on the configurations of `plan`
/// (variant, volume index, view indices or all), every pixel and channel compared; back-pressure on
/// every other frame. The model's image is computed once per volume and view and shared by the
/// configurations (it does not depend on P).
fn frames_bit_exact(render: Render, plan: &[(FrameRtl, usize, Option<&[usize]>)], seed_base: u64) {
    let t0 = Instant::now();
    let mut rng = ChaCha8Rng::seed_from_u64(seed_base);
    let traffic = [Traffic::full_speed(), Traffic::random(&mut rng, 0.0, 0.25)];
    let all = volumes(seed_base);
    let mut samples = 0;
    for (vi, (vname, vol)) in all.iter().enumerate() {
        let runs: Vec<_> = plan.iter().filter(|r| r.1 == vi).collect();
        if runs.is_empty() {
            continue;
        }
        let lut = BlockLut::from_volume(vol, runs[0].0.block as usize, 0).unwrap();
        let seen = seen_of(vol, &lut);
        let t = Instant::now();
        let expected: Vec<Expected> = VIEWS
            .iter()
            .map(|v| expect(&runs[0].0, &seen, *v, render, false))
            .collect();
        let model_secs = t.elapsed().as_secs_f64();
        for (rtl, _, picks) in runs {
            let t = Instant::now();
            let mut bench = bench(*rtl, vol, &lut, seed_base);
            let load_secs = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let mut cycles = 0;
            let idx: Vec<usize> =
                picks.map_or_else(|| (0..expected.len()).collect(), |p| p.to_vec());
            for (n, &i) in idx.iter().enumerate() {
                let s = seed_base + 1000 * vi as u64 + i as u64;
                let st = must(bench.check(&expected[i], &traffic[n % 2], s));
                cycles += st.cycles;
                samples += expected[i].params.samples();
            }
            let secs = t.elapsed().as_secs_f64();
            eprintln!(
                "{} {vname} {render:?}: {} views bit-exact, {cycles} cycles in {secs:.2} s ({:.2} Mcycles/s; volume load {load_secs:.2} s, model {model_secs:.2} s)",
                rtl.variant,
                idx.len(),
                cycles as f64 / secs / 1e6
            );
        }
    }
    eprintln!(
        "{render:?}: {samples} samples compared in {:.1} s",
        t0.elapsed().as_secs_f64()
    );
}

/// Views for the lighter runs: +z, exactly 45 degrees, the space diagonal, an oblique view.
const SOME_VIEWS: &[usize] = &[0, 6, 10, 11];

// -------------------------------------------------------------------------------------------------
// Tests
// -------------------------------------------------------------------------------------------------

/// P = 1 and 4: every acceptance volume at all 14 views; P = 8: all views of the smaller volumes,
/// four of 64^3 (MIP only), to keep the test time down.
fn plan(render: Render) -> Vec<(FrameRtl, usize, Option<&'static [usize]>)> {
    let mut plan = Vec::new();
    for v in 0..4 {
        plan.push((p(1), v, None));
        plan.push((p(4), v, None));
        if v != 2 {
            plan.push((p(8), v, None));
        } else if render == Render::Mip {
            plan.push((p(8), v, Some(SOME_VIEWS)));
        }
    }
    plan
}

#[test]
fn mip_frames_bit_exact_p1_p4_p8() {
    frames_bit_exact(Render::Mip, &plan(Render::Mip), seed(1));
}

#[test]
fn composite_frames_bit_exact_p1_p4_p8() {
    frames_bit_exact(Render::Composite, &plan(Render::Composite), seed(2));
}

/// The frame's rule for the smallest volumes (docs/frame-rtl.md): rows of two beats at least, and
/// a coxel reuse distance of at least ComposLatency + 2 beats.
fn accepted(p: &FrameParams, pipes: usize) -> bool {
    p.ni >= 2 * pipes && p.ni * (p.nj - 1) / pipes >= COMPOS_LATENCY as usize + 3
}

#[test]
fn backpressure_and_mid_frame_reset() {
    let s = seed(3);
    let rtl = p(4);
    let vol = blob_volume([48, 32, 40], 12, s);
    let (mut bench, seen) = loaded(rtl, &vol, s);
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let heavy = Traffic::random(&mut rng, 0.0, 0.6);
    let comp = expect(&rtl, &seen, OBLIQUE_Z, Render::Composite, false);
    let mip = expect(
        &rtl,
        &seen,
        ("oblique y", [0.6, -1.0, 0.3]),
        Render::Mip,
        false,
    );

    // A reset in the middle of the sweep: nothing comes out, and the next frame is whole.
    must(bench.load(&comp));
    let cut = (comp.params.samples() / rtl.p / 2) as u64;
    let d = bench
        .dut
        .drive(&[OP_RENDER], &heavy, u64::MAX, cut)
        .unwrap();
    assert!(d.outputs.is_empty(), "no pixel before the sweep ends");
    bench.dut.reset();
    must(bench.render_and_compare(&comp, &heavy, s));

    // A reset in the middle of the read-out: the pixels before it were right, the next frame (a
    // different view and rendering, so stale coxels would show) is whole.
    let n = comp.w * comp.h;
    let sweep = comp.params.samples() / rtl.p + comp.params.ni * comp.params.nj / rtl.p + 200;
    let d = bench
        .dut
        .drive(&[OP_RENDER], &heavy, u64::MAX, (sweep + n) as u64)
        .unwrap();
    assert!(
        !d.outputs.is_empty() && d.outputs.len() < n,
        "the reset lands in the read-out ({} of {n} pixels out)",
        d.outputs.len()
    );
    for (i, t) in d.outputs.iter().enumerate() {
        assert_eq!(t.value.coxel, comp.want[i], "pixel #{i} before the reset");
    }
    bench.dut.reset();
    bench.loaded = None;
    must(bench.check(&mip, &heavy, s + 1));
    must(bench.check(&comp, &Traffic::full_speed(), s + 2));
    eprintln!("mid-sweep and mid-read-out resets: later frames bit-exact");
}

#[test]
fn refused_configurations_answer_one_error_item() {
    let s = seed(4);
    let rtl = p(4);
    let vol = head_phantom(16, 12).unwrap();
    let (mut bench, seen) = loaded(rtl, &vol, s);
    let good = expect(
        &rtl,
        &seen,
        ("diagonal", [1.0, 1.0, 1.0]),
        Render::Mip,
        false,
    );
    must(bench.load(&good));
    assert_eq!(
        good.params.dx,
        1 << 16,
        "the diagonal steps exactly one voxel"
    );
    must(bench.render_and_compare(&good, &Traffic::full_speed(), s));

    let bad: Vec<(&str, ConfigWrites)> = vec![
        ("DX above one voxel", vec![rtl.reg(REG_DX, (1 << 16) + 1)]),
        (
            "DY below minus one voxel",
            vec![rtl.reg(REG_DY, ((-(1i32 << 16) - 1) as u32) & 0x3ffff)],
        ),
        ("slice axis 3", vec![rtl.reg(REG_VIEW, 3)]),
        (
            "every slice skipped",
            vec![rtl.reg(REG_SKIP, 8 | 8 << (rtl.max_dim_log2 + 1))],
        ),
        ("render mode 5", vec![rtl.reg(REG_MODE, 5)]),
        ("render mode 7", vec![rtl.reg(REG_MODE, RENDER_REFUSED)]),
        (
            "a dimension not a multiple of P",
            vec![rtl.dims_reg([16, 18, 16])],
        ),
        (
            "a dimension above MaxDim",
            vec![rtl.dims_reg([16, 16, 132])],
        ),
        ("a zero dimension", vec![rtl.dims_reg([0, 16, 16])]),
        ("rows of one beam (ni = P)", vec![rtl.dims_reg([4, 16, 16])]),
    ];
    for (what, writes) in &bad {
        must(bench.load(&good));
        must(bench.write(writes));
        let out = must(bench.refused(OP_RENDER));
        assert!(out.error, "{what}: refused with the error flag");
        assert_eq!(
            out.coxel,
            Coxel::default(),
            "{what}: the error item's coxel is 0"
        );
        eprintln!("refused: {what}");
    }
    for op in 1..4 {
        must(bench.load(&good));
        let out = must(bench.refused(op));
        assert!(out.error, "reserved op {op} is refused");
    }
    // Nothing of the refusals stays behind.
    must(bench.load(&good));
    must(bench.render_and_compare(&good, &Traffic::full_speed(), s + 1));
}

/// A random volume of `dims` (12-bit).
fn noise_volume(dims: [usize; 3], seed: u64) -> Volume {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let n = dims.iter().product();
    let data = (0..n).map(|_| rng.random_range(0..4096u16)).collect();
    Volume::new(dims, [1.0; 3], 12, data).unwrap()
}

#[test]
fn smallest_volumes_render_and_smaller_are_refused() {
    // The rule (docs/frame-rtl.md): ni >= 2 P and the reuse distance nbs - nbr - 1 =
    // ni (nj - 1) / P - 1 >= ComposLatency + 2 = 8. The accepted faces below sit exactly at the
    // bound, and DX = DY = -1 (the view (-1, -1, 1) and its mirrors) makes every coxel's reuse
    // distance that bound.
    let s = seed(5);
    for (rtl, dims, ok_views, bad_views) in [
        (
            p(1),
            [3usize, 4, 3],
            vec![
                ("-1 -1 +1", [-1.0, -1.0, 1.0]),
                ("+1 +1 -1", [1.0, 1.0, -1.0]),
                ("diagonal", [1.0, 1.0, 1.0]),
            ],
            vec![("+y (ni 3, nj 3)", [0.0, 1.0, 0.0])],
        ),
        (
            p(1),
            [3, 3, 3],
            vec![],
            vec![("-1 -1 +1", [-1.0, -1.0, 1.0]), ("+x", [1.0, 0.0, 0.0])],
        ),
        (
            p(4),
            [12, 4, 4],
            vec![("-1 -1 +1", [-1.0, -1.0, 1.0]), ("-z", [0.0, 0.0, -1.0])],
            vec![("+x (ni 4)", [1.0, 0.0, 0.0])],
        ),
        (
            p(4),
            [8, 4, 8],
            vec![("+y (ni 8, nj 8)", [0.1, 1.0, -0.3])],
            vec![("+z (ni 8, nj 4)", [0.0, 0.0, 1.0])],
        ),
    ] {
        let vol = noise_volume(dims, s);
        let (mut bench, seen) = loaded(rtl, &vol, s);
        for render in [Render::Mip, Render::Composite] {
            for v in &ok_views {
                let e = expect(&rtl, &seen, *v, render, false);
                assert!(accepted(&e.params, rtl.p));
                must(bench.check(&e, &Traffic::full_speed(), s));
                eprintln!(
                    "{} {dims:?} {} {render:?}: ni {} nj {}, reuse distance {} beats: bit-exact",
                    rtl.variant,
                    v.0,
                    e.params.ni,
                    e.params.nj,
                    e.params.ni * (e.params.nj - 1) / rtl.p - 1
                );
            }
            for v in &bad_views {
                let e = expect(&rtl, &seen, *v, render, false);
                assert!(!accepted(&e.params, rtl.p));
                must(bench.load(&e));
                let out = must(bench.refused(OP_RENDER));
                assert!(out.error, "{dims:?} {} is below the rule", v.0);
                eprintln!(
                    "{} {dims:?} {} {render:?}: ni {} nj {}: refused",
                    rtl.variant, v.0, e.params.ni, e.params.nj
                );
            }
        }
    }
}

#[test]
fn block_lut_skips_empty_blocks_and_restricts_to_a_region() {
    let s = seed(6);
    let rtl = p(4);
    let vol = blob_volume([48, 32, 40], 12, s);
    let view = ("oblique x", [0.9, 0.45, -0.2]);
    let full = BlockLut::from_volume(&vol, rtl.block as usize, 0).unwrap();
    assert!(
        full.skipped() > 0,
        "the blob's empty corner makes empty blocks"
    );
    let mut bench = bench(rtl, &vol, &full, s);
    let mut roi = full.clone();
    roi.restrict_to([8, 4, 8], [40, 28, 30]);
    let thresholded = BlockLut::from_volume(&vol, rtl.block as usize, 1200).unwrap();
    for (what, lut) in [
        ("empty blocks", &full),
        ("region of interest", &roi),
        ("threshold 1200", &thresholded),
    ] {
        must(bench.set_lut(lut));
        let seen = seen_of(&vol, lut);
        let mut accesses = None;
        for render in [Render::Mip, Render::Composite] {
            let e = expect(&rtl, &seen, view, render, false);
            accesses = Some(must(bench.check(&e, &Traffic::full_speed(), s)).accesses);
        }
        let a = accesses.unwrap();
        assert!(a.beams_skipped > 0, "{what}: some beams skipped");
        eprintln!(
            "{what}: {} of {} blocks skipped, {} of {} beats read (RTL = model); bit-exact",
            lut.skipped(),
            lut.entries.len(),
            a.beams_read,
            a.beams_read + a.beams_skipped
        );
    }
}

#[test]
fn sweep_and_readout_cycles_follow_the_budget() {
    // Set-up 3 + beats + flush (nbs + 2 nbr + 2) + the pipeline; then one pixel per clock.
    let s = seed(7);
    let vol = head_phantom(32, 12).unwrap();
    // With and without gradient and shader (MIP only: the classification table alone).
    let bare = FrameRtl::without_shade()
        .into_iter()
        .filter(|r| r.max_dim() >= 32);
    for rtl in [p(1), p(4), p(8)].into_iter().chain(bare) {
        let (mut bench, seen) = loaded(rtl, &vol, s);
        // Memory L + 2, then the frame's pipeline from the beat taken.
        let pipeline = u64::from(rtl.skew().latency()) + rtl.pipeline_latency();
        let render = if rtl.shade {
            Render::Composite
        } else {
            Render::Mip
        };
        for v in [("+z", [0.0, 0.0, 1.0]), OBLIQUE_Z] {
            let e = expect(&rtl, &seen, v, render, false);
            let st = must(bench.check(&e, &Traffic::full_speed(), s));
            let p = &e.params;
            let (nbr, nbs) = (p.ni / rtl.p, p.ni * p.nj / rtl.p);
            let beats = (p.samples() / rtl.p) as u64;
            let flush = (nbs + 2 * nbr + 2) as u64;
            assert_eq!(
                u64::from(st.sweep) - beats - flush - 3,
                pipeline,
                "{} {}: sweep cycles {} = set-up 3 + beats {beats} + flush {flush} + the pipeline, \
                 which should be the sum of the units' latencies",
                rtl.variant,
                v.0,
                st.sweep
            );
            let n = (e.w * e.h) as u64;
            assert_eq!(st.last_out - st.first_out + 1, n, "one pixel per clock");
            eprintln!(
                "{} 32^3 {}: {} cycles = set-up 3 + beats {beats} + flush {flush} + pipeline {pipeline} + read-out {n} + {}",
                rtl.variant,
                v.0,
                st.cycles,
                st.cycles - 3 - beats - flush - pipeline - n
            );
        }
    }
}

#[test]
fn narrow_configurations_s1_s4() {
    let s = seed(8);
    for render in [Render::Mip, Render::Composite] {
        for (rtl, vol) in [
            (narrow(1), head_phantom(8, 8).unwrap()),
            (narrow(1), blob_volume([8, 4, 8], 8, s)),
            (narrow(4), head_phantom(8, 8).unwrap()),
        ] {
            let (mut bench, seen) = loaded(rtl, &vol, s);
            let mut rng = ChaCha8Rng::seed_from_u64(s);
            let traffic = Traffic::random(&mut rng, 0.0, 0.3);
            let mut n = 0;
            for &v in VIEWS {
                let e = expect(&rtl, &seen, v, render, false);
                if !accepted(&e.params, rtl.p) {
                    continue; // refused by the rule; see smallest_volumes_*
                }
                must(bench.check(&e, &traffic, s));
                n += 1;
            }
            eprintln!(
                "{} {:?} {render:?}: {n} views bit-exact",
                rtl.variant, vol.dims
            );
        }
    }
}

/// The frames without gradient and shader (`Shade = 0`): MIP frames bit-exact at every accepted
/// view, with idle and back-pressure, on a volume of each configuration's memory; composite and
/// the 2-D classification are refused with one error item, and nothing of them stays behind.
#[test]
fn frames_without_gradient_and_shader_mip_bit_exact_composite_refused() {
    let s = seed(12);
    let bare = FrameRtl::without_shade();
    assert!(!bare.is_empty(), "a cube5_frame variant with Shade = 0");
    for rtl in bare {
        let vols = if rtl.max_dim() >= 32 {
            vec![
                head_phantom(32, 12).unwrap(),
                blob_volume([16, 8, 24], 12, s),
            ]
        } else {
            let w = rtl.trilin.voxel_w;
            vec![head_phantom(8, w).unwrap(), blob_volume([8, 4, 8], w, s)]
        };
        for vol in &vols {
            let (mut bench, seen) = loaded(rtl, vol, s);
            let mut rng = ChaCha8Rng::seed_from_u64(s);
            let traffic = [Traffic::full_speed(), Traffic::random(&mut rng, 0.0, 0.3)];
            let mut rendered = Vec::new();
            for &v in VIEWS {
                let e = expect(&rtl, &seen, v, Render::Mip, false);
                if !accepted(&e.params, rtl.p) {
                    continue;
                }
                let n = rendered.len();
                must(bench.check(&e, &traffic[n % 2], s + n as u64));
                rendered.push(e);
            }
            let n = rendered.len();
            assert!(n >= 4, "{}: {n} views rendered", rtl.variant);
            eprintln!("{} {:?} Mip: {n} views bit-exact", rtl.variant, vol.dims);
            // The last view the frame accepts: refused in the other modes, then rendered again.
            let good = rendered.pop().unwrap();
            for (what, mode) in [
                ("composite", Render::Composite.code()),
                ("first-opaque", Render::FirstOpaque.code()),
                (
                    "MIP with the 2-D classification",
                    Render::Mip.code() | 1 << REG_MODE_TF2D.lsb,
                ),
            ] {
                must(bench.load(&good));
                must(bench.write(&[rtl.reg(REG_MODE, mode)]));
                let out = must(bench.refused(OP_RENDER));
                assert!(out.error, "{}: {what} is refused", rtl.variant);
            }
            must(bench.load(&good));
            must(bench.render_and_compare(&good, &Traffic::full_speed(), s + 1));
        }
    }
}

#[test]
#[ignore = "sim-full: the gate-level netlist is `gatefull` (141 s of build; docs/ci.md)"]
fn gate_level_netlist_smoke() {
    let s = seed(9);
    let gate = gate_variants_of(TOP);
    assert_eq!(gate.len(), 1, "one gate-level frame netlist");
    let rtl = FrameRtl::from_variant(gate[0]).unwrap();
    let vol = head_phantom(8, 8).unwrap();
    let (mut bench, seen) = loaded(rtl, &vol, s);
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let traffic = Traffic::random(&mut rng, 0.0, 0.3);
    for render in [Render::Mip, Render::Composite] {
        for &i in SOME_VIEWS {
            let e = expect(&rtl, &seen, VIEWS[i], render, false);
            must(bench.check(&e, &traffic, s));
        }
    }
    // A reset in mid-sweep, then a whole frame.
    let e = expect(&rtl, &seen, VIEWS[11], Render::Composite, false);
    must(bench.load(&e));
    let d = bench
        .dut
        .drive(&[OP_RENDER], &traffic, u64::MAX, 300)
        .unwrap();
    assert!(d.outputs.is_empty());
    bench.dut.reset();
    must(bench.render_and_compare(&e, &traffic, s));
}

#[test]
fn early_termination_flag_reaches_the_image() {
    let s = seed(10);
    let (_, mut bench, e) = oblique_head_p4(32, true, s);
    let terminated = e.want.iter().filter(|c| c.terminated).count();
    assert!(terminated > 0, "some rays reach the threshold");
    must(bench.check(&e, &Traffic::full_speed(), s));
    eprintln!(
        "{terminated} of {} rays terminated early; bit-exact",
        e.want.len()
    );
}

#[test]
fn a_step_one_weight_lsb_off_in_the_rtl_is_reported_with_pixel_channel_and_trail() {
    // The comparison bites on the frame's own arithmetic (slice constants, rays, rotation), not
    // just on the units': a DY one weight LSB off in the RTL's register alone must be caught.
    let s = seed(11);
    let (rtl, mut bench, e) = oblique_head_p4(16, false, s);
    must(bench.load(&e));
    let lsb = 1 << (16 - rtl.trilin.weight_w);
    must(bench.write(&[rtl.reg(REG_DY, ((e.params.dy + lsb) as u32) & 0x3ffff)]));
    let err = bench
        .render_and_compare(&e, &Traffic::full_speed(), 4242)
        .expect_err("a wrong step must be caught")
        .to_string();
    for needle in [
        "MISMATCH",
        "pixel (r, q)",
        "channel",
        "slice",
        "anchor",
        "CUBE5_SEED=4242",
    ] {
        assert!(err.contains(needle), "report lacks `{needle}`:\n{err}");
    }
    eprintln!("{}", &err[..err.len().min(1500)]);
}

#[test]
fn test_side_fold_agrees_with_the_model_base_plane() {
    // The narrow and early-termination tests compare with this file's fold of the unit models;
    // where the model's render_base_plane applies, the two must be the same image.
    let vol = head_phantom(32, 12).unwrap();
    for (render, mode) in [
        (Render::Mip, FrameMode::Mip),
        (Render::Composite, FrameMode::Composite),
    ] {
        for (v, et) in [
            (VIEWS[6], false),
            (VIEWS[11], false),
            (VIEWS[13], false),
            (VIEWS[6], true),
            (VIEWS[13], true),
        ] {
            let setup = FrameSetup::new(vol.dims, vol.spacing, v.1.into(), 1).unwrap();
            let p = setup.params;
            let look = Look {
                early_termination: et,
                ..Look::default()
            };
            let fu = FrameUnits::with_config(
                &self::p(1).cfg,
                mode,
                &setup,
                &look.tf,
                &look.phong,
                et.then_some(cube5_frame::ET_DEFAULT),
            )
            .unwrap();
            let bp = cube5_frame::render_base_plane(&p, &vol, &fu);
            let units = Units::new(&self::p(1), render, &setup, &look).unwrap();
            let (w, h, mine) = model_image(&p, &vol, &units);
            assert_eq!((w, h), (bp.width, bp.height));
            assert!(
                mine == bp.coxels,
                "{render:?} {} et {et}: images differ",
                v.0
            );
        }
    }
}

#[test]
fn the_scene_limit_is_the_largest_frame_memory() {
    // The model's parameters of every variant are checked against the RTL's in
    // tests/variant_table.rs; here only the scene limit, which restates the largest MaxDim.
    let largest = FrameRtl::all().iter().map(|r| r.max_dim()).max().unwrap();
    assert_eq!(largest, cube5_model::scene::RTL_MAX_EDGE);
}

#[test]
fn empty_slice_skipping_cuts_cycles_without_changing_a_pixel() {
    let s = seed(12);
    let vol = sparse_scene(s);
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let traffic = Traffic::random(&mut rng, 0.0, 0.2);
    for rtl in [p(1), p(4)] {
        let (mut bench, seen) = loaded(rtl, &vol, s);
        let (mut plain, mut skipping) = (0u64, 0u64);
        for (i, &v) in VIEWS.iter().enumerate() {
            for render in [Render::Mip, Render::Composite] {
                let e = expect(&rtl, &seen, v, render, false);
                bench.skip_empty = false;
                let full = must(bench.check(&e, &traffic, s + i as u64));
                bench.skip_empty = true;
                let cut = must(bench.check(&e, &traffic, s + i as u64));
                assert!(
                    cut.skip.0 + cut.skip.1 > 0,
                    "{} {}: slices skipped",
                    rtl.variant,
                    v.0
                );
                assert!(cut.sweep < full.sweep);
                plain += u64::from(full.sweep);
                skipping += u64::from(cut.sweep);
                if render == Render::Composite && i % 5 == 0 {
                    eprintln!(
                        "{} {:>12}: skip {:?} of {} slices, sweep {} -> {} cycles ({:.3}), frame {} -> {} cycles",
                        rtl.variant, v.0, cut.skip, e.params.nk, full.sweep, cut.sweep,
                        f64::from(cut.sweep) / f64::from(full.sweep), full.cycles, cut.cycles
                    );
                }
            }
        }
        eprintln!(
            "{}: 14 views x MIP/composite bit-exact with and without skipping; sweep cycles {skipping} / {plain} = {:.3}",
            rtl.variant,
            skipping as f64 / plain as f64
        );
    }
}
