//! Co-simulation of cube5_pwarp against the golden model (docs/numerics/pwarp.md): whole frames
//! (registers, base plane, every scanline) of random perspective views of a plane, directed
//! extremes (no tilt, a 45-degree scanline slope, transposed and negative slopes, views that look
//! past the horizon, raw register values the set-up never writes), random idle and back-pressure
//! on both streams, a mid-stream reset, the throughput of one sample per clock, and the
//! gate-level smoke run. A `Line` emits many samples, so the runs are driven here (one item in,
//! many out) rather than through `check_stream` (one out per item).

mod support;

use cube5_model::regs::cube5_pwarp::{
    OP_RESERVED, PWARP_LATENCY, REG_BASE_W, REG_MODE, REG_PHASE, REG_SLOPE, REG_X, REG_XS, REG_Y,
    REG_YS, SLOPE_FRAC_W,
};
use cube5_model::regs::cube5_warp::COORD_FRAC_W;
use cube5_model::unit::StreamUnit;
use cube5_model::units::cube5_pwarp::{
    frame_items, to_raster, Projective, Pwarp, PwarpConfig, PwarpIn, PwarpOut, PwarpSetup,
};
use cube5_model::units::cube5_warp::BaseCodes;
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::warp::{self, check_frames, random_base, WarpFrame};
use support::{configs, seed};

/// One frame of the warp: its set-up, base plane, what it is (for a mismatch report).
#[derive(Debug, Clone)]
struct Frame {
    setup: PwarpSetup,
    base: BaseCodes,
    what: String,
    /// Items after the frame's own (directed oddities and raw lines).
    extra: Vec<PwarpIn>,
}

impl WarpFrame for Frame {
    type Cfg = PwarpConfig;
    const OUT: &'static str = "sample";

    fn items(&self, cfg: &PwarpConfig) -> Vec<PwarpIn> {
        let mut items = frame_items(cfg, &self.setup, &self.base);
        items.extend(self.extra.iter().copied());
        items
    }

    /// The sample's line, registers and coordinates.
    fn describe(&self, i: usize, mut at: usize) -> String {
        let s = &self.setup;
        for (j, l) in s.lines.iter().enumerate() {
            if at < l.n as usize {
                let i64at = at as i64;
                let unit = f64::from(1u32 << COORD_FRAC_W);
                let (x, y) = (l.x + i64at * l.xs, l.y + i64at * l.ys);
                return format!(
                    "frame {i} ({}), base plane {}x{}, image {}x{}, slope {} neg {} transpose {}, line {j} {l:?}, sample {at} at base-plane ({:.6}, {:.6}) = fixed ({x}, {y})",
                    self.what,
                    self.base.width,
                    self.base.height,
                    s.out_w,
                    s.out_h,
                    s.slope,
                    s.neg,
                    s.transpose,
                    x as f64 / unit,
                    y as f64 / unit
                );
            }
            at -= l.n as usize;
        }
        format!("frame {i} ({}): sample {at} of its extra items", self.what)
    }
}

impl Frame {
    fn new(map: &Projective, base: BaseCodes, out: (u32, u32), what: String) -> Self {
        let size = (base.width as u32, base.height as u32);
        Self {
            setup: PwarpSetup::new(map, size, out).unwrap(),
            base,
            what: format!("{what}: {map:?}"),
            extra: Vec::new(),
        }
    }
}

/// A random perspective view of a random base plane of at most `base_hi` texels a side on an
/// image of `out_lo..=out_hi` pixels a side: field of view 20-80 degrees, tilts up to 75 degrees
/// about both axes (past the horizon at the image's edge for the steepest), any roll, zoom 1/3 to
/// 4 planes across the view, the view's centre near the plane.
fn random_frame(
    rng: &mut ChaCha8Rng,
    cfg: &PwarpConfig,
    base_hi: usize,
    out_lo: u32,
    out_hi: u32,
) -> Frame {
    let mb = base_hi.min(cfg.max_base as usize);
    let (w, h) = (rng.random_range(1..=mb), rng.random_range(1..=mb));
    let hi = out_hi.min(cfg.max_out);
    let lo = out_lo.min(hi);
    let out = (rng.random_range(lo..=hi), rng.random_range(lo..=hi));
    let map = Projective::tilted(
        out,
        (w as u32, h as u32),
        rng.random_range(20.0..80.0),
        [
            rng.random_range(-75.0..75.0),
            rng.random_range(-75.0..75.0),
            rng.random_range(-180.0..180.0),
        ],
        2f64.powf(rng.random_range(-1.6..2.0)),
        (
            rng.random_range(-0.3..1.3) * w as f64,
            rng.random_range(-0.3..1.3) * h as f64,
        ),
    );
    let base = random_base(rng, w, h, cfg.color_w);
    Frame::new(&map, base, out, "random view".into())
}

/// `n` random views per configuration, images `lo..=hi` pixels a side (bounded by `MaxOut`),
/// base planes up to `base_hi` texels a side.
fn random_views(n: usize, lo: u32, hi: u32, base_hi: usize, seed_no: u64) {
    for (i, (variant, cfg)) in configs::<PwarpConfig>().into_iter().enumerate() {
        let s = seed(seed_no + i as u64);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let frames: Vec<Frame> = (0..n)
            .map(|_| random_frame(&mut rng, &cfg, base_hi, lo, hi))
            .collect();
        for f in &frames {
            let img = to_raster(
                f.setup.out_w,
                f.setup.out_h,
                &Pwarp::new(cfg).unwrap().run(&f.items(&cfg)),
            );
            assert!(
                img.is_some(),
                "{variant}: {}: the samples do not cover the image once",
                f.what
            );
        }
        let t = Traffic::random(&mut rng, 0.2, 0.3);
        let cycles = check_frames(variant, cfg, &frames, &t, s, None);
        let samples: u64 = frames.iter().map(|f| f.setup.samples()).sum();
        let lines: usize = frames.iter().map(|f| f.setup.lines.len()).sum();
        eprintln!("{variant}: seed {s}: {n} perspective views, {lines} scanlines, {samples} samples bit-exact in {cycles} cycles under idle and back-pressure");
    }
}

#[test]
fn fifty_random_perspective_views_with_idle_and_backpressure() {
    random_views(50, 64, 256, 128, 1500);
}

#[test]
#[ignore = "sim-full: 50 random views per configuration at 256^2..512^2 pixels (minutes)"]
fn random_perspective_views_up_to_512_squared() {
    random_views(50, 256, 512, 256, 1510);
}

/// A raw line: random registers and `Line` fields the set-up never writes (any slope up to the
/// register's top, any phase, mode, coordinates across the base plane's edges, pixel addresses that
/// wrap at MaxOut).
fn raw_lines(cfg: &PwarpConfig, rng: &mut ChaCha8Rng, n: usize) -> Vec<PwarpIn> {
    let unit = 1i64 << COORD_FRAC_W;
    let c = |v: i64| (v as u64) & ((1u64 << 36) - 1);
    let mut items = Vec::new();
    for _ in 0..n {
        let span = i64::from(cfg.max_base) + 4;
        items.extend([
            PwarpIn::write(REG_SLOPE, rng.random_range(0..1u64 << (SLOPE_FRAC_W + 1))),
            PwarpIn::write(REG_MODE, rng.random_range(0..4)),
            PwarpIn::write(REG_X, c(rng.random_range(-4 * unit..span * unit))),
            PwarpIn::write(REG_Y, c(rng.random_range(-4 * unit..span * unit))),
            PwarpIn::write(REG_XS, c(rng.random_range(-unit..unit))),
            PwarpIn::write(REG_YS, c(rng.random_range(-unit..unit))),
            PwarpIn::write(REG_PHASE, rng.random_range(0..1u64 << SLOPE_FRAC_W)),
            PwarpIn::line(
                cfg,
                rng.random_range(0..cfg.max_out),
                rng.random_range(0..cfg.max_out),
                rng.random_range(0..=cfg.max_out.min(40)),
            ),
        ]);
    }
    items
}

/// Directed extremes: no tilt (rows, slope 0), a scanline slope of exactly 45 degrees (slope
/// 2^20), the four slope signs and transposes, a view looking past the horizon (black lines), a
/// one-pixel image, raw lines, and the item oddities of the contract (an empty line, a write to no
/// register, a reserved op, a base plane wider than the block RAM).
fn directed_frames(cfg: &PwarpConfig, rng: &mut ChaCha8Rng) -> Vec<Frame> {
    let mb = cfg.max_base;
    let (w, h) = (mb.clamp(3, 13), mb.clamp(3, 9));
    let out = cfg.max_out.min(32);
    let base = random_base(rng, w as usize, h as usize, cfg.color_w);
    let size = (w, h);
    let centre = (f64::from(w) / 2.0, f64::from(h) / 2.0);
    let mut frames = Vec::new();
    let mut push = |map: Projective, o: (u32, u32), base: &BaseCodes, what: &str| {
        frames.push(Frame::new(&map, base.clone(), o, what.into()));
    };
    push(
        Projective::affine(0.0, 0.0, 1.0, 0.0, 0.0, 1.0),
        size,
        &base,
        "identity",
    );
    push(
        Projective::tilted((out, out), size, 40.0, [0.0, 0.0, 0.0], 1.0, centre),
        (out, out),
        &base,
        "no tilt",
    );
    for (t, what) in [
        ([40.0, 0.0, 0.0], "tilt about x: rows (slope 0)"),
        (
            [0.0, 40.0, 0.0],
            "tilt about y: columns (transposed, slope 0)",
        ),
        ([30.0, 0.0, 45.0], "rolled 45 degrees: slope 2^20"),
        ([30.0, 0.0, -45.0], "rolled -45 degrees: slope -2^20"),
        ([30.0, 20.0, 20.0], "slope > 0"),
        ([30.0, -20.0, 20.0], "slope < 0"),
        ([20.0, 40.0, 10.0], "transposed, slope > 0"),
        ([-20.0, 40.0, 10.0], "transposed, slope < 0"),
        ([80.0, 5.0, 3.0], "past the horizon: black lines"),
    ] {
        push(
            Projective::tilted((out, out - 3), size, 60.0, t, 1.0, centre),
            (out, out - 3),
            &base,
            what,
        );
    }
    push(
        Projective::tilted((1, 1), size, 40.0, [10.0, 10.0, 10.0], 1.0, centre),
        (1, 1),
        &base,
        "a one-pixel image",
    );
    for (flat, what) in warp::flat_bases(w as usize, h as usize, cfg.color_w) {
        push(
            Projective::tilted((out, out), size, 50.0, [35.0, 15.0, 30.0], 1.5, centre),
            (out, out),
            &flat,
            what,
        );
    }
    let mut f = frames[2].clone();
    f.what = "raw lines: register values the set-up never writes".into();
    f.extra = raw_lines(cfg, rng, 24);
    frames.push(f);
    let mut f = frames[0].clone();
    f.what = "N = 0 (no samples), then a write to no register and a reserved op".into();
    f.extra = vec![
        PwarpIn::line(cfg, 3, 4, 0),
        PwarpIn::write(15, 0xabc),
        PwarpIn {
            op: OP_RESERVED,
            addr: 3,
            payload: 0x123,
        },
        PwarpIn::line(cfg, 1, 2, 3),
    ];
    frames.push(f);
    let wide = random_base(rng, mb as usize + 2, 2, cfg.color_w);
    let mut f = Frame::new(
        &Projective::affine(f64::from(mb) - 3.0, -0.5, 0.25, 0.0, 0.0, 0.5),
        wide,
        (20, 4),
        "BaseW = MaxBase + 2: the last two columns are not stored".into(),
    );
    f.extra = vec![
        PwarpIn::write(REG_BASE_W, u64::from(2 * mb + 5)),
        PwarpIn::line(cfg, 0, 0, 9),
    ];
    frames.push(f);
    frames
}

#[test]
fn directed_extremes_under_idle_and_backpressure() {
    warp::directed_under_idle_and_backpressure(directed_frames, 1530);
}

#[test]
fn a_reset_in_mid_stream() {
    warp::a_reset_in_mid_stream(
        |rng, cfg: &PwarpConfig| random_frame(rng, cfg, 12, 8, 32),
        1540,
    );
}

/// Full speed: texels loaded, then every line's items back to back. Lines of at least six samples
/// (the items a line takes) leave their samples back to back; shorter lines at a slanted image's
/// corners wait for their items.
#[test]
fn one_sample_per_clock_over_a_frame() {
    for (variant, cfg) in configs::<PwarpConfig>() {
        let out = cfg.max_out.min(64);
        let (bw, bh) = (cfg.max_base.min(48), cfg.max_base.min(40));
        let mut rng = ChaCha8Rng::seed_from_u64(seed(1550));
        let base = random_base(&mut rng, bw as usize, bh as usize, cfg.color_w);
        let centre = (f64::from(bw) / 2.0, f64::from(bh) / 2.0);
        for (tilt, what) in [([35.0, 0.0, 0.0], "rows"), ([30.0, 20.0, 25.0], "slanted")] {
            let map = Projective::tilted((out, out), (bw, bh), 50.0, tilt, 1.0, centre);
            let frame = Frame::new(&map, base.clone(), (out, out), what.into());
            let s = &frame.setup;
            let mut load = s.frame_writes();
            load.extend(base.codes.iter().map(|&c| PwarpIn::texel(&cfg, c)));
            let lines: Vec<PwarpIn> = s
                .lines
                .iter()
                .flat_map(|l| PwarpSetup::line_items(&cfg, l))
                .collect();
            let mut dut = RtlStream::new(variant, cfg, 1).unwrap();
            let loaded = dut
                .drive(&load, &Traffic::full_speed(), 0, 1 << 24)
                .unwrap();
            assert_eq!(loaded.stats.consumed, load.len() as u64);
            let n = s.samples();
            let driven = dut
                .drive(&lines, &Traffic::full_speed(), n, 10 * n + 1000)
                .unwrap();
            let want = Pwarp::new(cfg).unwrap().run(&frame.items(&cfg));
            let got: Vec<PwarpOut> = driven.outputs.iter().map(|t| t.value).collect();
            assert!(
                got == want,
                "{variant}: {what}: the full-speed frame differs from the model"
            );
            // Bubbles a line of n < 6 samples leaves: its six items take six clocks.
            let short: u64 = s
                .lines
                .iter()
                .map(|l| 6u64.saturating_sub(u64::from(l.n)))
                .sum();
            let rate = n as f64 / driven.stats.cycles as f64;
            eprintln!(
                "{variant}: {what}: {n} samples on {} scanlines in {} cycles ({rate:.4} samples/clock; short-line bubbles {short})",
                s.lines.len(),
                driven.stats.cycles
            );
            assert!(
                driven.stats.cycles <= n + short + 6 + PWARP_LATENCY + 1,
                "{variant}: {what}: one sample per clock after the first line's items"
            );
            if short == 0 {
                let first = driven.outputs.first().unwrap().cycle;
                let last = driven.outputs.last().unwrap().cycle;
                assert_eq!(
                    last - first + 1,
                    n,
                    "{variant}: {what}: samples leave back to back"
                );
            }
        }
    }
}

#[test]
fn gate_level_smoke() {
    warp::gate_level_smoke(
        8,
        |rng, cfg: &PwarpConfig| random_frame(rng, cfg, 16, 8, 24),
        directed_frames,
        1560,
    );
}

#[test]
fn a_model_with_the_wrong_weight_width_is_caught() {
    warp::a_wrong_model_is_caught(
        |rng, cfg: &PwarpConfig| random_frame(rng, cfg, 32, 16, 32),
        |cfg| PwarpConfig {
            weight_w: cfg.weight_w - 1,
            ..cfg
        },
        "a one-bit-narrower weight",
        1570,
    );
}
