//! Co-simulation of cube5_warp against the golden model (docs/numerics/warp.md): whole frames
//! (registers, base plane, `Go`) of random affine warps, the warps of real frame views, directed
//! extremes, random idle and back-pressure on both streams, a mid-stream reset, the throughput of
//! one pixel per clock, and the gate-level smoke run. A `Go` emits a whole image, so the runs are
//! driven here (one item in, many out) rather than through `check_stream` (one out per item).

mod support;

use cube5_model::camera::Camera;
use cube5_model::regs::cube5_warp::{
    COORD_FRAC_W, COORD_LIMIT, OP_RESERVED, REG_BASE_W, REG_OUT_W, WARP_LATENCY,
};
use cube5_model::render::View;
use cube5_model::unit::StreamUnit;
use cube5_model::units::cube5_frame::FrameSetup;
use cube5_model::units::cube5_warp::{
    frame_items, Affine, BaseCodes, Warp, WarpConfig, WarpIn, WarpOut, WarpRegs,
};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::warp::{self, check_frames, random_base, WarpFrame};
use support::{configs, seed};

/// One frame of the warp: registers, base plane, what it is (for a mismatch report).
#[derive(Debug, Clone)]
struct Frame {
    regs: WarpRegs,
    base: BaseCodes,
    what: String,
    /// Items after the frame's own (directed oddities: reserved ops, writes to no register).
    extra: Vec<WarpIn>,
}

impl WarpFrame for Frame {
    type Cfg = WarpConfig;
    const OUT: &'static str = "pixel";

    fn items(&self, cfg: &WarpConfig) -> Vec<WarpIn> {
        let mut items = frame_items(cfg, &self.regs, &self.base);
        items.extend(self.extra.iter().copied());
        items
    }

    /// The pixel's position, coordinates and registers.
    fn describe(&self, i: usize, at: usize) -> String {
        let r = self.regs;
        let (px, py) = (
            at as i64 % i64::from(r.out_w),
            at as i64 / i64::from(r.out_w),
        );
        let (x, y) = (
            r.x0 + px * r.xpx + py * r.xpy,
            r.y0 + px * r.ypx + py * r.ypy,
        );
        let unit = f64::from(1u32 << COORD_FRAC_W);
        format!(
            "frame {i} ({}), base plane {}x{}, pixel ({px}, {py}) at base-plane ({:.6}, {:.6}) = fixed ({x}, {y}), registers {r:?}",
            self.what,
            self.base.width,
            self.base.height,
            x as f64 / unit,
            y as f64 / unit
        )
    }
}

/// A random affine warp of a random base plane onto an image of `out_lo..=out_hi` pixels a side:
/// rotation, anisotropic zoom (0.1x..8x), shear, mirror, an offset that may leave the base plane.
fn random_frame(rng: &mut ChaCha8Rng, cfg: &WarpConfig, out_lo: u32, out_hi: u32) -> Frame {
    random_frame_within(rng, cfg, cfg.max_base as usize, out_lo, out_hi)
}

/// `random_frame` with a base plane of at most `base_hi` texels a side.
fn random_frame_within(
    rng: &mut ChaCha8Rng,
    cfg: &WarpConfig,
    base_hi: usize,
    out_lo: u32,
    out_hi: u32,
) -> Frame {
    let mb = base_hi.min(cfg.max_base as usize);
    let (w, h) = (rng.random_range(1..=mb), rng.random_range(1..=mb));
    let (ow, oh) = (
        rng.random_range(out_lo..=out_hi),
        rng.random_range(out_lo..=out_hi),
    );
    let ang: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    let size = w.max(h) as f64 / f64::from(ow.max(oh));
    let (sx, sy) = (
        size * 2f64.powf(rng.random_range(-3.0..3.3)),
        size * 2f64.powf(rng.random_range(-3.0..3.3)),
    );
    let shear = rng.random_range(-0.5..0.5);
    let mirror = if rng.random_bool(0.2) { -1.0 } else { 1.0 };
    let (c, s) = (ang.cos(), ang.sin());
    let (xpx, ypx) = (c * sx * mirror, s * sx * mirror);
    let (xpy, ypy) = (-s * sy + shear * xpx, c * sy + shear * ypx);
    // Centre of the image on a random point near the base plane.
    let (cx, cy) = (
        rng.random_range(-0.3..1.3) * w as f64,
        rng.random_range(-0.3..1.3) * h as f64,
    );
    let (hx, hy) = (f64::from(ow) / 2.0, f64::from(oh) / 2.0);
    let a = Affine {
        x0: cx - hx * xpx - hy * xpy,
        y0: cy - hx * ypx - hy * ypy,
        xpx,
        ypx,
        xpy,
        ypy,
    };
    let regs = WarpRegs::set_up(&a, (w as u32, h as u32), (ow, oh)).unwrap();
    Frame {
        regs,
        base: random_base(rng, w, h, cfg.color_w),
        what: format!("random warp {a:?}"),
        extra: Vec::new(),
    }
}

/// `n` random warps per configuration, images `lo..=hi` pixels a side (bounded by `MaxOut`),
/// base planes up to `base_hi` texels a side but every tenth up to `MaxBase` (loading a large
/// base plane costs a clock per texel).
fn random_warps(n: usize, lo: u32, hi: u32, base_hi: usize, seed_no: u64) {
    for (i, (variant, cfg)) in configs::<WarpConfig>().into_iter().enumerate() {
        let s = seed(seed_no + i as u64);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let hi = hi.min(cfg.max_out);
        let frames: Vec<Frame> = (0..n)
            .map(|k| {
                let b = if k % 10 == 9 {
                    cfg.max_base as usize
                } else {
                    base_hi
                };
                random_frame_within(&mut rng, &cfg, b, lo.min(hi), hi)
            })
            .collect();
        let t = Traffic::random(&mut rng, 0.2, 0.3);
        let cycles = check_frames(variant, cfg, &frames, &t, s, None);
        let pixels: u64 = frames
            .iter()
            .map(|f| u64::from(f.regs.out_w * f.regs.out_h))
            .sum();
        eprintln!("{variant}: seed {s}: {n} random warps, {pixels} pixels bit-exact in {cycles} cycles under idle and back-pressure");
    }
}

#[test]
fn two_hundred_random_affine_warps_with_idle_and_backpressure() {
    random_warps(200, 16, 64, 96, 1400);
}

#[test]
#[ignore = "sim-full: 200 random warps per configuration at 64^2..512^2 pixels (minutes)"]
fn random_affine_warps_up_to_512_squared() {
    random_warps(200, 64, 512, 1024, 1410);
}

/// The warps of frame views: the set-up `cube5 render` does, on random base-plane codes of the
/// frame's base-plane size (volumes of MaxBase / 2 voxels a side, so the base plane fits).
fn view_frames(cfg: &WarpConfig, rng: &mut ChaCha8Rng, out: u32) -> Vec<Frame> {
    let n = (cfg.max_base / 2) as usize;
    // (azimuth, elevation) in degrees: axis-aligned, obliques, near a pole, reversed sweeps.
    let views = [
        (0.0, 0.0),
        (35.0, 25.0),
        (-120.0, -40.0),
        (45.0, 35.26),
        (10.0, 89.0),
        (225.0, -35.0),
    ];
    views
        .iter()
        .enumerate()
        .map(|(i, &(azimuth, elevation))| {
            let dir = View { azimuth, elevation }.direction().unwrap();
            let spacing = [1.0, 1.0, if i % 2 == 0 { 1.0 } else { 1.5 }];
            let setup = FrameSetup::new([n; 3], spacing, dir, 1).unwrap();
            let (bw, bh) = setup.params.base_plane_size();
            let mut camera = Camera::new(dir, [n; 3], spacing, out, out - (i as u32 % 3));
            camera.half /= [1.0, 1.6, 0.7][i % 3];
            let a = Affine::of_view(&setup.params, spacing, &camera);
            let regs = WarpRegs::set_up(&a, (bw as u32, bh as u32), (camera.width, camera.height))
                .unwrap();
            Frame {
                regs,
                base: random_base(rng, bw, bh, cfg.color_w),
                what: format!("view {dir:?}, spacing {spacing:?}"),
                extra: Vec::new(),
            }
        })
        .collect()
}

#[test]
fn the_warps_of_frame_views() {
    for (i, (variant, cfg)) in configs::<WarpConfig>().into_iter().enumerate() {
        let s = seed(1420 + i as u64);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let frames = view_frames(&cfg, &mut rng, cfg.max_out.min(64));
        let t = Traffic::random(&mut rng, 0.2, 0.2);
        check_frames(variant, cfg, &frames, &t, s, None);
        eprintln!("{variant}: {} frame views bit-exact", frames.len());
    }
}

/// Directed extremes: identity, 90-degree rotation, the largest zoom in (a step of one coordinate
/// unit) and out (the corners at the coordinate limit), positions at exactly the last texel, just
/// inside and just outside every edge, all-ones and all-zero planes, the register and item oddities
/// of the contract (an empty image, a write to no register, a reserved op, a base plane wider than
/// the block RAM).
fn directed_frames(cfg: &WarpConfig, rng: &mut ChaCha8Rng) -> Vec<Frame> {
    let mb = cfg.max_base;
    let (w, h) = (mb.clamp(3, 13), mb.clamp(3, 9));
    let out = cfg.max_out.min(32);
    let base = random_base(rng, w as usize, h as usize, cfg.color_w);
    let ulp = 1.0 / f64::from(1u32 << COORD_FRAC_W);
    let affine = |x0: f64, y0: f64, xpx: f64, ypx: f64, xpy: f64, ypy: f64| Affine {
        x0,
        y0,
        xpx,
        ypx,
        xpy,
        ypy,
    };
    let mut frames = Vec::new();
    let mut push = |a: Affine, (ow, oh): (u32, u32), base: &BaseCodes, what: &str| {
        frames.push(Frame {
            regs: WarpRegs::set_up(&a, (base.width as u32, base.height as u32), (ow, oh)).unwrap(),
            base: base.clone(),
            what: what.into(),
            extra: Vec::new(),
        })
    };
    push(
        affine(0.0, 0.0, 1.0, 0.0, 0.0, 1.0),
        (w, h),
        &base,
        "identity",
    );
    push(
        affine(f64::from(w - 1), 0.0, 0.0, 1.0, -1.0, 0.0),
        (h, w),
        &base,
        "90-degree rotation",
    );
    push(
        affine(f64::from(w) / 2.0, f64::from(h) / 2.0, ulp, 0.0, 0.0, ulp),
        (out, out),
        &base,
        "largest zoom in: one coordinate unit per pixel",
    );
    let step = f64::from(COORD_LIMIT) * 2.0 / f64::from(out - 1) * 0.999;
    let lim = -f64::from(COORD_LIMIT) * 0.999;
    push(
        affine(lim, lim, step, 0.0, 0.0, step),
        (out, out),
        &base,
        "largest zoom out: corners at the coordinate limit",
    );
    // Each row a position at an edge, each column a tiny step across it.
    for (x0, y0, what) in [
        (f64::from(w - 1), f64::from(h - 1), "exactly the last texel"),
        (f64::from(w - 1) + ulp, 0.5, "just past the last column"),
        (
            f64::from(w) - ulp,
            0.5,
            "just inside the zero beyond the last column",
        ),
        (
            f64::from(w),
            f64::from(h),
            "just outside (the first zero texel)",
        ),
        (-ulp, -ulp, "just before texel (0, 0)"),
        (-1.0, -1.0, "one texel before (0, 0)"),
        (-1.0 + ulp, 0.25, "just inside the zero before column 0"),
        (0.5, f64::from(h - 1) + ulp, "just past the last row"),
    ] {
        push(
            affine(x0, y0, ulp, 0.0, 0.0, ulp),
            (3, 3),
            &base,
            &format!("{what}, steps of one unit"),
        );
    }
    for (flat, what) in warp::flat_bases(w as usize, h as usize, cfg.color_w) {
        push(
            affine(-0.5, -0.5, 0.37, 0.11, -0.13, 0.41),
            (out, out),
            &flat,
            what,
        );
    }
    // Oddities: an empty image, writes to no register, a reserved op, a base plane wider than
    // the block RAM (the texels beyond MaxBase are dropped and read as 0).
    let mut f = frames[0].clone();
    f.what = "OutW = 0 (no pixels), then a write to no register and a reserved op".into();
    f.extra = vec![
        WarpIn::write(REG_OUT_W, 0),
        WarpIn::go(),
        WarpIn::write(15, 0xabc),
        WarpIn {
            op: OP_RESERVED,
            addr: 3,
            payload: 0x123,
        },
        WarpIn::go(),
    ];
    frames.push(f);
    let wide = random_base(rng, mb as usize + 2, 2, cfg.color_w);
    let mut f = Frame {
        regs: WarpRegs::set_up(
            &affine(f64::from(mb) - 3.0, -0.5, 0.25, 0.0, 0.0, 0.5),
            (mb + 2, 2),
            (20, 4),
        )
        .unwrap(),
        base: wide,
        what: "BaseW = MaxBase + 2: the last two columns are not stored".into(),
        extra: Vec::new(),
    };
    f.extra = vec![
        WarpIn::write(REG_BASE_W, u64::from(2 * mb + 5)),
        WarpIn::go(),
    ];
    frames.push(f);
    frames
}

#[test]
fn directed_extremes_under_idle_and_backpressure() {
    warp::directed_under_idle_and_backpressure(directed_frames, 1430);
}

#[test]
fn a_reset_in_mid_stream() {
    // Small base planes, so the reset lands as often in an image as in a base plane's load.
    warp::a_reset_in_mid_stream(
        |rng, cfg: &WarpConfig| random_frame_within(rng, cfg, 12, 8, cfg.max_out.min(32)),
        1440,
    );
}

#[test]
fn one_pixel_per_clock_over_a_frame() {
    for (variant, cfg) in configs::<WarpConfig>() {
        let s = seed(1450);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let out = cfg.max_out.min(64);
        let frame = random_frame(&mut rng, &cfg, out, out);
        let mut items = frame.items(&cfg);
        let go = items.pop().unwrap();
        let mut dut = RtlStream::new(variant, cfg, 1).unwrap();
        let load = dut
            .drive(&items, &Traffic::full_speed(), 0, 1 << 24)
            .unwrap();
        assert_eq!(load.stats.consumed, items.len() as u64);
        let n = u64::from(out * out);
        let driven = dut.drive(&[go], &Traffic::full_speed(), n, 10 * n).unwrap();
        let want = Warp::new(cfg).unwrap().run(&frame.items(&cfg));
        let got: Vec<WarpOut> = driven.outputs.iter().map(|t| t.value).collect();
        assert!(
            got == want,
            "{variant}: the full-speed frame differs from the model"
        );
        let first = driven.outputs.first().unwrap().cycle;
        let last = driven.outputs.last().unwrap().cycle;
        assert_eq!(last - first + 1, n, "{variant}: pixels leave back to back");
        let rate = n as f64 / driven.stats.cycles as f64;
        eprintln!(
            "{variant}: {n} pixels in {} cycles from Go ({rate:.4} pixels/clock)",
            driven.stats.cycles
        );
        assert_eq!(
            driven.stats.cycles,
            n + WARP_LATENCY + 1,
            "{variant}: Go, then one pixel per clock after the pipeline fill"
        );
        assert!(rate >= 0.99);
    }
}

#[test]
fn gate_level_smoke() {
    warp::gate_level_smoke(
        12,
        |rng, cfg: &WarpConfig| random_frame(rng, cfg, 8, cfg.max_out.min(24)),
        directed_frames,
        1460,
    );
}

#[test]
fn a_model_with_the_wrong_weight_width_is_caught() {
    // The comparison bites: the default configuration's RTL against a model one weight bit
    // narrower must differ on random warps.
    warp::a_wrong_model_is_caught(
        |rng, cfg: &WarpConfig| random_frame(rng, cfg, 16, cfg.max_out.min(32)),
        |cfg| WarpConfig {
            weight_w: cfg.weight_w - 1,
            ..cfg
        },
        "a one-bit-narrower weight",
        1470,
    );
}
