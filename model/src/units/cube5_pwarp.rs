//! The perspective warp of the base plane onto the final image along parallel-preserving
//! scanlines (`cube5_pwarp`), written from `docs/numerics/pwarp.md`: the host's f64 set-up (the
//! scanline slope, the write template, two projections per scanline and their rounding to
//! `S(15.20)`), the exact per-sample steps along a scanline, the write template's row steps, and
//! `cube5_warp`'s bilinear filter at each sample ([`crate::units::cube5_warp::pixel_at`]).
//! [`reference`] is the ideal f64 projective warp at the pixel centres, [`reference_at_samples`]
//! the same at the scanlines' sample points (what the contract's error bound is stated against),
//! and [`read_counts`] the source reads of patent [84]-[87] against the naive inverse warp's.

use crate::bits::BitReader;
use crate::error::{ModelError, Result};
use crate::regs::cube5_pwarp::{
    OP_LINE, REG_BASE_H, REG_BASE_W, REG_MODE, REG_PHASE, REG_SLOPE, REG_X, REG_XS, REG_Y, REG_YS,
    SLOPE_FRAC_W,
};
use crate::regs::cube5_warp::{COORD_FRAC_W, COORD_LIMIT, COORD_W, OUT_CODE_W, REG_ADDR_W};
use crate::render::ImageF64;
use crate::unit::StreamCodec;
use crate::units::cube5_warp::{
    bilinear_f64, pixel_at, BaseCodes, WarpConfig, WarpIn, WarpKind, WarpUnit,
};
use std::collections::HashSet;

/// One configuration of the `cube5_pwarp` RTL (the parameters of the same names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PwarpConfig {
    /// Bits of a base-plane colour code (`ColorW`).
    pub color_w: u32,
    /// Fraction bits of a bilinear weight (`WeightW`).
    pub weight_w: u32,
    /// Largest base-plane edge the block RAM holds (`MaxBase`, a power of two).
    pub max_base: u32,
    /// Largest output edge (`MaxOut`, a power of two).
    pub max_out: u32,
}

impl PwarpConfig {
    /// The RTL's defaults.
    pub const DEFAULT: Self = Self {
        color_w: 8,
        weight_w: 8,
        max_base: 128,
        max_out: 512,
    };

    pub fn validate(&self) -> Result<()> {
        if !self.max_out.is_power_of_two() || !(4..=2048).contains(&self.max_out) {
            return Err(ModelError::Config(format!(
                "cube5_pwarp: MaxOut {} is not a power of two in 4..=2048",
                self.max_out
            )));
        }
        self.sampler()
            .validate()
            .map_err(|e| ModelError::Config(e.to_string().replace("cube5_warp", "cube5_pwarp")))
    }

    /// `b = log2 MaxBase`.
    pub fn base_log2(&self) -> u32 {
        self.max_base.trailing_zeros()
    }

    /// `o = log2 MaxOut`.
    pub fn out_log2(&self) -> u32 {
        self.max_out.trailing_zeros()
    }

    /// Bits of an input item's payload, `max(CoordW, 3 ColorW)`.
    pub fn pay_w(&self) -> u32 {
        self.sampler().pay_w()
    }

    /// Block RAMs (ECP5 DP16KD) of the four banks: `cube5_warp`'s.
    pub fn dp16kd(&self) -> u32 {
        self.sampler().dp16kd()
    }
}

crate::unit_config!(PwarpConfig, "cube5_pwarp", DEFAULT, {
    "ColorW" => color_w,
    "WeightW" => weight_w,
    "MaxBase" => max_base,
    "MaxOut" => max_out,
});

/// A 2-D projective map: output pixel `(px, py)` (centres at integers) shows base-plane position
/// `(nx . p / w . p, ny . p / w . p)` with `p = (px, py, 1)`; nothing where `w . p <= 0` (behind
/// the eye).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projective {
    pub nx: [f64; 3],
    pub ny: [f64; 3],
    pub w: [f64; 3],
}

impl Projective {
    fn dot(c: &[f64; 3], px: f64, py: f64) -> f64 {
        c[0] * px + c[1] * py + c[2]
    }

    /// The homogeneous figures `(nx, ny, w)` at `(px, py)`.
    pub fn homogeneous(&self, px: f64, py: f64) -> (f64, f64, f64) {
        (
            Self::dot(&self.nx, px, py),
            Self::dot(&self.ny, px, py),
            Self::dot(&self.w, px, py),
        )
    }

    /// The base-plane position of `(px, py)`, `None` behind the eye (`w <= 0`).
    pub fn at(&self, px: f64, py: f64) -> Option<(f64, f64)> {
        let (x, y, w) = self.homogeneous(px, py);
        (w > 0.0).then(|| (x / w, y / w))
    }

    /// A plane seen in perspective: the camera (field of view `fov` degrees across the larger
    /// output edge, pixel centres at integers) turned by `tilt_x`, then `tilt_y`, then `roll`
    /// (degrees) from looking straight at the plane; the plane one unit away, `zoom` base-plane
    /// edges across the field of view at its centre, the view's centre at base-plane `centre`.
    /// Behind the eye (`w <= 0`) once a tilt plus the half field of view passes 90 degrees.
    #[allow(clippy::too_many_arguments)]
    pub fn tilted(
        (out_w, out_h): (u32, u32),
        (base_w, base_h): (u32, u32),
        fov: f64,
        [tilt_x, tilt_y, roll]: [f64; 3],
        zoom: f64,
        centre: (f64, f64),
    ) -> Self {
        let t = (fov.to_radians() / 2.0).tan();
        let f = f64::from(out_w.max(out_h)) / 2.0 / t;
        // The pixel's ray before the turn: M (px, py, 1).
        let m = [
            [1.0, 0.0, -(f64::from(out_w) - 1.0) / 2.0],
            [0.0, 1.0, -(f64::from(out_h) - 1.0) / 2.0],
            [0.0, 0.0, f],
        ];
        let (sx, cx) = tilt_x.to_radians().sin_cos();
        let (sy, cy) = tilt_y.to_radians().sin_cos();
        let (sr, cr) = roll.to_radians().sin_cos();
        let rx = [[1.0, 0.0, 0.0], [0.0, cx, -sx], [0.0, sx, cx]];
        let ry = [[cy, 0.0, sy], [0.0, 1.0, 0.0], [-sy, 0.0, cy]];
        let rz = [[cr, -sr, 0.0], [sr, cr, 0.0], [0.0, 0.0, 1.0]];
        let mul = |a: [[f64; 3]; 3], b: [[f64; 3]; 3]| -> [[f64; 3]; 3] {
            std::array::from_fn(|i| {
                std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum())
            })
        };
        let rows = mul(rz, mul(ry, mul(rx, m)));
        let s = f64::from(base_w.max(base_h)) / zoom / (2.0 * t);
        Self {
            nx: std::array::from_fn(|j| s * rows[0][j] + centre.0 * rows[2][j]),
            ny: std::array::from_fn(|j| s * rows[1][j] + centre.1 * rows[2][j]),
            w: rows[2],
        }
    }

    /// An affine map as a projective one (`w = 1`).
    pub fn affine(x0: f64, y0: f64, xpx: f64, ypx: f64, xpy: f64, ypy: f64) -> Self {
        Self {
            nx: [xpx, xpy, x0],
            ny: [ypx, ypy, y0],
            w: [0.0, 0.0, 1.0],
        }
    }
}

/// One scanline as the unit takes it: the registers `X`, `Y`, `XS`, `YS`, `Phase` and the `Line`
/// item's `U0`, `V0`, `N`; `b` is the line's number (the set-up's, not sent).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PwarpLine {
    pub x: i64,
    pub y: i64,
    pub xs: i64,
    pub ys: i64,
    pub phase: u32,
    pub u0: u32,
    pub v0: u32,
    pub n: u32,
    pub b: i64,
}

/// The host's set-up of one warp (`docs/numerics/pwarp.md`, "Set-up").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PwarpSetup {
    pub base_w: u32,
    pub base_h: u32,
    pub out_w: u32,
    pub out_h: u32,
    /// `K = |k|`, `U(1.SlopeFracW)`.
    pub slope: u32,
    pub neg: bool,
    pub transpose: bool,
    pub lines: Vec<PwarpLine>,
}

const HALF_K: i64 = 1 << (SLOPE_FRAC_W - 1);
const ONE_K: i64 = 1 << SLOPE_FRAC_W;

/// `r(u) = floor((K u + 2^(SlopeFracW - 1)) / 2^SlopeFracW)`: the write template's row offset.
fn template(slope: u32, u: i64) -> i64 {
    (i64::from(slope) * u + HALF_K) >> SLOPE_FRAC_W
}

/// Wraps to `CoordW`-bit two's complement.
fn wrap(v: i64) -> i64 {
    let sh = 64 - COORD_W;
    (v << sh) >> sh
}

impl PwarpSetup {
    /// The host's set-up of `map` onto an `out_w x out_h` image of a `base_w x base_h` base plane
    /// (contract: *Set-up*). Refused (an error, no warp): a non-finite coefficient, an empty or
    /// larger-than-2048 image.
    pub fn new(
        map: &Projective,
        (base_w, base_h): (u32, u32),
        (out_w, out_h): (u32, u32),
    ) -> Result<Self> {
        let all = map.nx.iter().chain(&map.ny).chain(&map.w);
        if all.clone().any(|c| !c.is_finite()) || map.w.iter().all(|&c| c == 0.0) {
            return Err(ModelError::View(format!(
                "pwarp: the projective map {map:?} is not finite or has w = 0"
            )));
        }
        if out_w == 0 || out_h == 0 || out_w > 2048 || out_h > 2048 {
            return Err(ModelError::View(format!(
                "pwarp: output {out_w}x{out_h} outside 1..=2048 a side"
            )));
        }
        // 1. The primary axis u: the output axis along which w changes less.
        let transpose = map.w[0].abs() > map.w[1].abs();
        let (au, av) = if transpose {
            (map.w[1], map.w[0])
        } else {
            (map.w[0], map.w[1])
        };
        let (nu, nv) = if transpose {
            (out_h, out_w)
        } else {
            (out_w, out_h)
        };
        // 2. The slope k = -au / av (|k| <= 1), quantized.
        let k = if av == 0.0 { 0.0 } else { -au / av };
        let slope = ((k.abs() * ONE_K as f64).round() as i64).min(ONE_K) as u32;
        let neg = k < 0.0 && slope > 0;
        let s: i64 = if neg { -1 } else { 1 };
        let kq = s as f64 * f64::from(slope) / ONE_K as f64;
        let out = |u: f64, v: f64| if transpose { (v, u) } else { (u, v) };
        // 3. Lines b: pixel (u, b + s r(u)) for the u where that row is inside the image.
        let r_max = template(slope, i64::from(nu) - 1);
        let (b_lo, b_hi) = if neg {
            (0, i64::from(nv) - 1 + r_max)
        } else {
            (-r_max, i64::from(nv) - 1)
        };
        let lim = f64::from(COORD_LIMIT) / 2.0;
        let q = |f: f64| (f * f64::from(1u32 << COORD_FRAC_W)).round() as i64;
        let mut lines = Vec::new();
        for b in b_lo..=b_hi {
            let row = |u: i64| b + s * template(slope, u);
            let inside = |u: i64| (0..i64::from(nv)).contains(&row(u));
            let Some(ulo) = (0..i64::from(nu)).find(|&u| inside(u)) else {
                continue;
            };
            let uhi = (ulo..i64::from(nu))
                .take_while(|&u| inside(u))
                .last()
                .unwrap_or(ulo);
            // The sample points on the line v = b + kq u, and their projections.
            let point = |u: i64| {
                let (px, py) = out(u as f64, b as f64 + kq * u as f64);
                map.homogeneous(px, py)
            };
            let seg = |ua: i64, ub: i64, x: i64, y: i64, xs: i64, ys: i64| PwarpLine {
                x,
                y,
                xs,
                ys,
                phase: ((i64::from(slope) * ua + HALF_K) & (ONE_K - 1)) as u32,
                u0: ua as u32,
                v0: row(ua) as u32,
                n: (ub - ua + 1) as u32,
                b,
            };
            let black = |ua: i64, ub: i64| seg(ua, ub, q(-2.0), q(-2.0), 0, 0);
            let (x0, y0, w0) = point(ulo);
            let (x1, y1, w1) = point(uhi);
            let wscale = map.w.iter().map(|c| c.abs()).sum::<f64>() * f64::from(nu.max(nv));
            let tiny = 1e-12 * wscale;
            let n = uhi - ulo;
            let (c0, c1) = ((x0 / w0, y0 / w0), (x1 / w1, y1 / w1));
            let finite = [c0.0, c0.1, c1.0, c1.1].iter().all(|c| c.is_finite());
            if w0 <= tiny || w1 <= tiny || !finite {
                lines.push(black(ulo, uhi));
                continue;
            }
            // The part of the line whose coordinates stay within +-CoordLimit/2 (linear in u).
            let (mut ia, mut ib) = (0.0f64, n as f64);
            for (a, z) in [(c0.0, c1.0), (c0.1, c1.1)] {
                let d = if n == 0 { 0.0 } else { (z - a) / n as f64 };
                if d == 0.0 {
                    if a.abs() > lim {
                        ib = -1.0;
                    }
                } else {
                    let (l, h) = ((-lim - a) / d, (lim - a) / d);
                    ia = ia.max(l.min(h));
                    ib = ib.min(l.max(h));
                }
            }
            let (ia, ib) = (ia.ceil() as i64, ib.floor() as i64);
            if ia > ib {
                lines.push(black(ulo, uhi));
                continue;
            }
            let (ua, ub) = (ulo + ia, ulo + ib);
            if ua > ulo {
                lines.push(black(ulo, ua - 1));
            }
            let (xa, ya, wa) = point(ua);
            let (xb, yb, wb) = point(ub);
            let (pa, pb) = ((xa / wa, ya / wa), (xb / wb, yb / wb));
            let m = (ub - ua).max(1) as f64;
            lines.push(seg(
                ua,
                ub,
                q(pa.0),
                q(pa.1),
                q((pb.0 - pa.0) / m),
                q((pb.1 - pa.1) / m),
            ));
            if ub < uhi {
                lines.push(black(ub + 1, uhi));
            }
        }
        Ok(Self {
            base_w,
            base_h,
            out_w,
            out_h,
            slope,
            neg,
            transpose,
            lines,
        })
    }

    /// The frame's register writes (sizes, slope, mode).
    pub fn frame_writes(&self) -> Vec<PwarpIn> {
        let mode = u64::from(self.neg) | u64::from(self.transpose) << 1;
        vec![
            PwarpIn::write(REG_BASE_W, u64::from(self.base_w)),
            PwarpIn::write(REG_BASE_H, u64::from(self.base_h)),
            PwarpIn::write(REG_SLOPE, u64::from(self.slope)),
            PwarpIn::write(REG_MODE, mode),
        ]
    }

    /// The items of one scanline: its five registers, then `Line`.
    pub fn line_items(cfg: &PwarpConfig, line: &PwarpLine) -> [PwarpIn; 6] {
        let c = |v: i64| (v as u64) & ((1u64 << COORD_W) - 1);
        [
            PwarpIn::write(REG_X, c(line.x)),
            PwarpIn::write(REG_Y, c(line.y)),
            PwarpIn::write(REG_XS, c(line.xs)),
            PwarpIn::write(REG_YS, c(line.ys)),
            PwarpIn::write(REG_PHASE, u64::from(line.phase)),
            PwarpIn::line(cfg, line.u0, line.v0, line.n),
        ]
    }

    /// The output point `(px, py)` of sample `i` of `line`: column `u0 + i` on the line
    /// `v = b + kq u` (not the pixel it is written to, which is the nearest row).
    pub fn sample_point(&self, line: &PwarpLine, i: u32) -> (f64, f64) {
        let s = if self.neg { -1.0 } else { 1.0 };
        let u = f64::from(line.u0 + i);
        let v = line.b as f64 + s * f64::from(self.slope) / ONE_K as f64 * u;
        if self.transpose {
            (v, u)
        } else {
            (u, v)
        }
    }

    /// Samples (= pixels) of the frame.
    pub fn samples(&self) -> u64 {
        self.lines.iter().map(|l| u64::from(l.n)).sum()
    }
}

/// The items of one whole frame: the frame's registers, `BaseW x BaseH` texels, every scanline.
pub fn frame_items(cfg: &PwarpConfig, setup: &PwarpSetup, base: &BaseCodes) -> Vec<PwarpIn> {
    let mut items = setup.frame_writes();
    items.extend(base.codes.iter().map(|&c| PwarpIn::texel(cfg, c)));
    for l in &setup.lines {
        items.extend(PwarpSetup::line_items(cfg, l));
    }
    items
}

/// One input item: `cube5_warp`'s (`op`, `addr`, `payload`), whose op 2 is `Line` here.
pub type PwarpIn = WarpIn;

impl WarpIn {
    /// `Line` with `U0`, `V0` (`o` bits each) and `N` (`o + 1` bits), LSB first.
    pub fn line(cfg: &PwarpConfig, u0: u32, v0: u32, n: u32) -> Self {
        let o = cfg.out_log2();
        let m = |v: u32, w: u32| u64::from(v) & ((1u64 << w) - 1);
        Self {
            op: OP_LINE,
            addr: 0,
            payload: m(u0, o) | m(v0, o) << o | m(n, o + 1) << (2 * o),
        }
    }
}

/// One output sample: 8-bit R, G, B, the pixel `(px, py)` it is written to, `last` (the line's
/// last sample).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PwarpOut {
    pub rgb: [u8; 3],
    pub px: u32,
    pub py: u32,
    pub last: bool,
}

/// The registers of the unit (`docs/numerics/pwarp.md`, "Registers").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PwarpRegs {
    pub base_w: u32,
    pub base_h: u32,
    pub slope: u32,
    pub neg: bool,
    pub transpose: bool,
    pub x: i64,
    pub y: i64,
    pub xs: i64,
    pub ys: i64,
    pub phase: u32,
}

/// The samples of one `Line` (`u0`, `v0`, `n`) under `regs`, each filtered by `texel`: exact
/// coordinate steps (wrapping at `CoordW` bits), the template's row steps, `o`-bit pixel
/// coordinates (wrapping).
pub fn line_samples(
    cfg: &PwarpConfig,
    regs: &PwarpRegs,
    (u0, v0, n): (u32, u32, u32),
    texel: impl Fn(i64, i64) -> [u32; 3],
    out: &mut Vec<PwarpOut>,
) {
    let mask = cfg.max_out - 1;
    let sampler = cfg.sampler();
    let (mut x, mut y, mut u, mut v, mut phase) = (regs.x, regs.y, u0, v0, i64::from(regs.phase));
    for i in 0..n {
        let (px, py) = if regs.transpose { (v, u) } else { (u, v) };
        out.push(PwarpOut {
            rgb: pixel_at(&sampler, x, y, &texel),
            px,
            py,
            last: i + 1 == n,
        });
        x = wrap(x + regs.xs);
        y = wrap(y + regs.ys);
        u = (u + 1) & mask;
        let sum = phase + i64::from(regs.slope);
        if sum >= ONE_K {
            v = (if regs.neg { v.wrapping_sub(1) } else { v + 1 }) & mask;
        }
        phase = sum & (ONE_K - 1);
    }
}

/// The warped samples of `base` under `setup` (every line, in order), as the unit emits them.
pub fn warp_samples(cfg: &PwarpConfig, setup: &PwarpSetup, base: &BaseCodes) -> Vec<PwarpOut> {
    let mut regs = PwarpRegs {
        base_w: setup.base_w,
        base_h: setup.base_h,
        slope: setup.slope,
        neg: setup.neg,
        transpose: setup.transpose,
        ..Default::default()
    };
    let mut out = Vec::with_capacity(setup.samples() as usize);
    for l in &setup.lines {
        (regs.x, regs.y, regs.xs, regs.ys, regs.phase) = (l.x, l.y, l.xs, l.ys, l.phase);
        line_samples(
            cfg,
            &regs,
            (l.u0, l.v0, l.n),
            |x, y| base.texel(x, y),
            &mut out,
        );
    }
    out
}

/// The samples written into an `out_w x out_h` raster image (row-major), or `None` unless every
/// pixel is written exactly once.
pub fn to_raster(out_w: u32, out_h: u32, samples: &[PwarpOut]) -> Option<Vec<[u8; 3]>> {
    let mut img = vec![[0u8; 3]; (out_w * out_h) as usize];
    let mut seen = vec![false; img.len()];
    for s in samples {
        if s.px >= out_w || s.py >= out_h {
            return None;
        }
        let at = (s.py * out_w + s.px) as usize;
        if std::mem::replace(&mut seen[at], true) {
            return None;
        }
        img[at] = s.rgb;
    }
    seen.iter().all(|&s| s).then_some(img)
}

/// The image of `base` under `setup` in raster order (the set-up writes every pixel once).
pub fn warp_image(cfg: &PwarpConfig, setup: &PwarpSetup, base: &BaseCodes) -> Result<Vec<[u8; 3]>> {
    to_raster(setup.out_w, setup.out_h, &warp_samples(cfg, setup, base)).ok_or_else(|| {
        ModelError::View("pwarp: the scanlines do not cover the image once (set-up bug)".into())
    })
}

fn ideal(map: &Projective, base: &BaseCodes, color_w: u32, px: f64, py: f64) -> [f64; 3] {
    let max = f64::from((1u32 << color_w) - 1);
    match map.at(px, py) {
        Some((x, y)) => bilinear_f64(x, y, |tx, ty| {
            base.texel(tx, ty).map(|c| f64::from(c) / max)
        }),
        None => [0.0; 3],
    }
}

/// The ideal: the f64 bilinear projective warp of `base` (codes on the unit interval) at the pixel
/// centres, zero outside the base plane and behind the eye, in 0..1.
pub fn reference(
    map: &Projective,
    base: &BaseCodes,
    color_w: u32,
    (out_w, out_h): (u32, u32),
) -> ImageF64 {
    let rgb = (0..out_w * out_h)
        .map(|i| {
            ideal(
                map,
                base,
                color_w,
                f64::from(i % out_w),
                f64::from(i / out_w),
            )
        })
        .collect();
    ImageF64 {
        width: out_w,
        height: out_h,
        rgb,
    }
}

/// The ideal at each sample's own point on its scanline, in the order the unit emits them.
pub fn reference_at_samples(
    map: &Projective,
    setup: &PwarpSetup,
    base: &BaseCodes,
    color_w: u32,
) -> Vec<[f64; 3]> {
    let mut out = Vec::with_capacity(setup.samples() as usize);
    for l in &setup.lines {
        for i in 0..l.n {
            let (px, py) = setup.sample_point(l, i);
            out.push(ideal(map, base, color_w, px, py));
        }
    }
    out
}

/// The contract's bound on `|out - 255 ideal|` at sample `i` of a scanline segment, the ideal
/// taken at the sample's own point (`docs/numerics/pwarp.md`, "Error bound"): `cube5_warp`'s bound
/// after `i` steps, plus `1/16` code for the f64 projections and the line's slope rounding.
pub fn error_bound(cfg: &PwarpConfig, i: u32) -> f64 {
    crate::units::cube5_warp::error_bound(&cfg.sampler(), i, 0) + 1.0 / 16.0
}

/// Source reads of one frame (patent [84]-[87]; contract: *Source reads*).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ReadCounts {
    /// Output pixels.
    pub pixels: u64,
    /// The naive inverse warp: every pixel reads its four taps (those inside the base plane).
    pub naive: u64,
    /// Scanline order with a buffer of the previous scanline's texels: a texel is read when the
    /// line needs it and the line before did not.
    pub buffered1: u64,
    /// The same with the previous two scanlines' texels buffered.
    pub buffered2: u64,
    /// Distinct texels read at all (each read once: the lower bound).
    pub distinct: u64,
}

/// The source reads of `setup`'s scanlines on a `base_w x base_h` plane (taps outside it are not
/// reads).
pub fn read_counts(setup: &PwarpSetup) -> ReadCounts {
    let (bw, bh) = (i64::from(setup.base_w), i64::from(setup.base_h));
    let frac = |c: i64| c >> COORD_FRAC_W;
    let mut counts = ReadCounts::default();
    let mut all: HashSet<(i64, i64)> = HashSet::new();
    type Texels = HashSet<(i64, i64)>;
    let (mut prev1, mut prev2) = (Texels::new(), Texels::new());
    for l in &setup.lines {
        let mut cur = HashSet::new();
        let (mut x, mut y) = (l.x, l.y);
        for _ in 0..l.n {
            // The taps of the sample: `split`'s integer part (the rounded weight may make a tap's
            // weight 0; it is read all the same).
            let (xi, yi) = (frac(x), frac(y));
            for (tx, ty) in [(xi, yi), (xi + 1, yi), (xi, yi + 1), (xi + 1, yi + 1)] {
                if (0..bw).contains(&tx) && (0..bh).contains(&ty) {
                    counts.naive += 1;
                    cur.insert((tx, ty));
                }
            }
            x = wrap(x + l.xs);
            y = wrap(y + l.ys);
        }
        counts.pixels += u64::from(l.n);
        counts.buffered1 += cur.iter().filter(|t| !prev1.contains(t)).count() as u64;
        counts.buffered2 += cur
            .iter()
            .filter(|t| !prev1.contains(t) && !prev2.contains(t))
            .count() as u64;
        all.extend(cur.iter().copied());
        prev2 = std::mem::replace(&mut prev1, cur);
    }
    counts.distinct = all.len() as u64;
    counts
}

/// The golden model of `cube5_pwarp`: a `Line` emits its samples.
pub type Pwarp = WarpUnit<PwarpConfig>;

impl WarpKind for PwarpConfig {
    type Regs = PwarpRegs;
    type Out = PwarpOut;

    fn check(&self) -> Result<()> {
        self.validate()
    }

    /// The filter's configuration: `cube5_warp`'s bilinear stage at the same widths.
    fn sampler(&self) -> WarpConfig {
        WarpConfig {
            color_w: self.color_w,
            weight_w: self.weight_w,
            max_base: self.max_base,
            max_out: self.max_out,
        }
    }

    fn base_size(regs: &PwarpRegs) -> (u32, u32) {
        (regs.base_w, regs.base_h)
    }

    fn write(&self, r: &mut PwarpRegs, addr: u32, data: u64) {
        let field = |w: u32| (data & ((1u64 << w) - 1)) as u32;
        let coord = |d: u64| wrap(d as i64);
        let b1 = self.base_log2() + 1;
        match addr {
            REG_BASE_W => r.base_w = field(b1),
            REG_BASE_H => r.base_h = field(b1),
            REG_SLOPE => r.slope = field(SLOPE_FRAC_W + 1),
            REG_MODE => {
                r.neg = data & 1 != 0;
                r.transpose = data & 2 != 0;
            }
            REG_X => r.x = coord(data),
            REG_Y => r.y = coord(data),
            REG_XS => r.xs = coord(data),
            REG_YS => r.ys = coord(data),
            REG_PHASE => r.phase = field(SLOPE_FRAC_W),
            _ => {}
        }
    }

    /// The samples of a `Line`: `U0`, `V0` (`o` bits each), `N` (`o + 1` bits), LSB first.
    fn emit(
        &self,
        regs: &PwarpRegs,
        payload: u64,
        texel: impl Fn(i64, i64) -> [u32; 3],
        out: &mut Vec<PwarpOut>,
    ) {
        let o = self.out_log2();
        let f = |lsb: u32, w: u32| ((payload >> lsb) & ((1u64 << w) - 1)) as u32;
        let line = (f(0, o), f(o, o), f(2 * o, o + 1));
        line_samples(self, regs, line, texel, out);
    }
}

impl StreamCodec for PwarpConfig {
    type In = PwarpIn;
    type Out = PwarpOut;

    fn in_width(&self) -> u32 {
        self.pay_w() + REG_ADDR_W + 2
    }

    fn out_width(&self) -> u32 {
        3 * OUT_CODE_W + 2 * self.out_log2() + 1
    }

    fn pack_in(&self, item: &PwarpIn) -> Vec<u32> {
        item.pack(self.pay_w())
    }

    fn unpack_out(&self, words: &[u32]) -> PwarpOut {
        let mut r = BitReader::new(words);
        let o = self.out_log2();
        let rgb = std::array::from_fn(|_| r.get(OUT_CODE_W) as u8);
        let px = r.get(o) as u32;
        let py = r.get(o) as u32;
        PwarpOut {
            rgb,
            px,
            py,
            last: r.get_bool(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::unit::StreamUnit;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_map(rng: &mut ChaCha8Rng, out: (u32, u32), base: (u32, u32)) -> Projective {
        Projective::tilted(
            out,
            base,
            rng.random_range(20.0..70.0),
            [
                rng.random_range(-70.0..70.0),
                rng.random_range(-70.0..70.0),
                rng.random_range(-180.0..180.0),
            ],
            2f64.powf(rng.random_range(-1.5..2.0)),
            (
                rng.random_range(-0.2..1.2) * f64::from(base.0),
                rng.random_range(-0.2..1.2) * f64::from(base.1),
            ),
        )
    }

    #[test]
    fn every_pixel_is_written_once() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..200 {
            let out = (rng.random_range(1..80), rng.random_range(1..80));
            let map = random_map(&mut rng, out, (40, 30));
            let setup = PwarpSetup::new(&map, (40, 30), out).unwrap();
            assert_eq!(setup.samples(), u64::from(out.0 * out.1), "{map:?}");
            let cfg = PwarpConfig::DEFAULT;
            let base = BaseCodes::random(&mut rng, 40, 30, 8);
            assert!(warp_image(&cfg, &setup, &base).is_ok(), "{map:?} {out:?}");
        }
    }

    #[test]
    fn the_stream_model_equals_the_set_up_samples() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let cfg = PwarpConfig {
            color_w: 6,
            weight_w: 7,
            max_base: 32,
            max_out: 64,
        };
        let mut unit = Pwarp::new(cfg).unwrap();
        for _ in 0..30 {
            let (bw, bh) = (rng.random_range(1..=32), rng.random_range(1..=32));
            let out = (rng.random_range(1..=64), rng.random_range(1..=64));
            let map = random_map(&mut rng, out, (bw, bh));
            let setup = PwarpSetup::new(&map, (bw, bh), out).unwrap();
            let base = BaseCodes::random(&mut rng, bw as usize, bh as usize, cfg.color_w);
            let got = unit.run(&frame_items(&cfg, &setup, &base));
            assert_eq!(got, warp_samples(&cfg, &setup, &base));
        }
    }

    /// The contract's bound against the ideal at each sample's own point.
    #[test]
    fn within_the_bound_of_the_reference_at_the_sample_points() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let cfg = PwarpConfig::DEFAULT;
        let mut worst = 0.0f64;
        for _ in 0..60 {
            let (bw, bh) = (rng.random_range(2..=128), rng.random_range(2..=128));
            let out = (rng.random_range(8..=256), rng.random_range(8..=256));
            let map = random_map(&mut rng, out, (bw, bh));
            let setup = PwarpSetup::new(&map, (bw, bh), out).unwrap();
            let base = BaseCodes::random(&mut rng, bw as usize, bh as usize, cfg.color_w);
            let got = warp_samples(&cfg, &setup, &base);
            let want = reference_at_samples(&map, &setup, &base, cfg.color_w);
            let mut k = 0;
            for l in &setup.lines {
                for i in 0..l.n {
                    let bound = error_bound(&cfg, i);
                    for (g, w) in got[k].rgb.iter().zip(want[k]) {
                        let e = (f64::from(*g) - 255.0 * w).abs();
                        worst = worst.max(e);
                        assert!(e <= bound, "{map:?}: line {l:?} sample {i}: {e} > {bound}");
                    }
                    k += 1;
                }
            }
        }
        eprintln!("worst error at the sample points: {worst:.3} codes");
    }

    #[test]
    fn an_affine_map_scans_rows_at_the_pixel_centres() {
        let map = Projective::affine(3.25, -1.5, 0.75, 0.125, -0.25, 0.5);
        let setup = PwarpSetup::new(&map, (20, 20), (17, 9)).unwrap();
        assert_eq!((setup.slope, setup.neg, setup.transpose), (0, false, false));
        assert_eq!(setup.lines.len(), 9);
        for l in &setup.lines {
            assert_eq!((l.u0, l.v0 as i64, l.n), (0, l.b, 17));
            assert_eq!(setup.sample_point(l, 5), (5.0, l.b as f64));
        }
    }

    #[test]
    fn scanline_reads_are_fewer_than_the_naive_warps() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for _ in 0..20 {
            let out = (64, 64);
            let map = random_map(&mut rng, out, (64, 64));
            let setup = PwarpSetup::new(&map, (64, 64), out).unwrap();
            let c = read_counts(&setup);
            assert!(c.distinct <= c.buffered2 && c.buffered2 <= c.buffered1);
            assert!(c.buffered1 <= c.naive && c.naive <= 4 * c.pixels);
        }
    }

    #[test]
    fn bad_set_ups_are_refused() {
        let ok = Projective::affine(0.0, 0.0, 1.0, 0.0, 0.0, 1.0);
        let mut nan = ok;
        nan.nx[0] = f64::NAN;
        assert!(PwarpSetup::new(&nan, (4, 4), (4, 4)).is_err());
        let mut zero = ok;
        zero.w = [0.0; 3];
        assert!(PwarpSetup::new(&zero, (4, 4), (4, 4)).is_err());
        assert!(PwarpSetup::new(&ok, (4, 4), (0, 4)).is_err());
        assert!(PwarpSetup::new(&ok, (4, 4), (4, 4096)).is_err());
        assert!(PwarpConfig {
            max_out: 4096,
            ..PwarpConfig::DEFAULT
        }
        .validate()
        .is_err());
    }
}
