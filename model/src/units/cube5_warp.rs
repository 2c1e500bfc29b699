//! The affine warp of the base plane onto the final image (`cube5_warp`), written from
//! `docs/numerics/warp.md`: the host's f64 set-up and its rounding to `S(15.20)` registers, the
//! exact per-pixel coordinate steps, bilinear filtering of the base-plane colour codes at
//! `WeightW`-bit weights, 8-bit RGB out, zero outside the base plane. [`reference`] is the ideal
//! f64 bilinear warp the contract's error bound is stated against.

use crate::bits::{BitReader, BitWriter};
use crate::camera::Camera;
use crate::error::{ModelError, Result};
use crate::regs::cube5_warp::{
    COORD_FRAC_W, COORD_LIMIT, COORD_W, OP_GO, OP_TEXEL, OP_WRITE, OUT_CODE_W, REG_ADDR_W,
    REG_BASE_H, REG_BASE_W, REG_OUT_H, REG_OUT_W, REG_X0, REG_XPX, REG_XPY, REG_Y0, REG_YPX,
    REG_YPY, UNORM_W,
};
use crate::render::ImageF64;
use crate::unit::{param_in, StreamCodec, StreamUnit};
use crate::units::cube5_compos::ComposConfig;
use crate::units::cube5_frame::{BasePlane, FrameParams};
use glam::DVec3;
use rayon::prelude::*;
use std::fmt::Debug;

/// One configuration of the `cube5_warp` RTL (the parameters of the same names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WarpConfig {
    /// Bits of a base-plane colour code (`ColorW`).
    pub color_w: u32,
    /// Fraction bits of a bilinear weight (`WeightW`).
    pub weight_w: u32,
    /// Largest base-plane edge the block RAM holds (`MaxBase`, a power of two).
    pub max_base: u32,
    /// Largest output edge (`MaxOut`, a power of two).
    pub max_out: u32,
}

impl WarpConfig {
    /// The RTL's defaults.
    pub const DEFAULT: Self = Self {
        color_w: 8,
        weight_w: 8,
        max_base: 128,
        max_out: 512,
    };

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("cube5_warp: {what}")));
        param_in("ColorW", self.color_w, 4..=12).or_else(bad)?;
        param_in("WeightW", self.weight_w, 4..=12).or_else(bad)?;
        if !self.max_base.is_power_of_two() || !(4..=1024).contains(&self.max_base) {
            return bad(format!(
                "MaxBase {} is not a power of two in 4..=1024",
                self.max_base
            ));
        }
        if !self.max_out.is_power_of_two() || !(4..=4096).contains(&self.max_out) {
            return bad(format!(
                "MaxOut {} is not a power of two in 4..=4096",
                self.max_out
            ));
        }
        Ok(())
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
        COORD_W.max(3 * self.color_w)
    }

    /// Block RAMs (ECP5 DP16KD, 18 kbit) of the four banks: each `(MaxBase/2)^2` entries of
    /// `3 ColorW` bits, in the widest DP16KD shape whose depth covers the bank (or 16K x 1 banks
    /// cascaded by depth).
    pub fn dp16kd(&self) -> u32 {
        let depth = (self.max_base / 2).pow(2);
        let width = 3 * self.color_w;
        // DP16KD shapes: depth x data bits.
        let shapes = [
            (512u32, 36u32),
            (1024, 18),
            (2048, 9),
            (4096, 4),
            (8192, 2),
            (16384, 1),
        ];
        let per_bank = shapes
            .iter()
            .map(|&(d, w)| depth.div_ceil(d) * width.div_ceil(w))
            .min()
            .unwrap_or(0);
        4 * per_bank
    }
}

crate::unit_config!(WarpConfig, "cube5_warp", DEFAULT, {
    "ColorW" => color_w,
    "WeightW" => weight_w,
    "MaxBase" => max_base,
    "MaxOut" => max_out,
});

/// The ideal affine map of a view: base-plane position `(x, y)` of output pixel `(px, py)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Affine {
    pub x0: f64,
    pub y0: f64,
    pub xpx: f64,
    pub ypx: f64,
    pub xpy: f64,
    pub ypy: f64,
}

impl Affine {
    pub fn at(&self, px: f64, py: f64) -> (f64, f64) {
        (
            self.x0 + px * self.xpx + py * self.xpy,
            self.y0 + px * self.ypx + py * self.ypy,
        )
    }

    /// The map of a parallel view (`docs/numerics/frame.md`, "Warp"): the pixel's ray meets the
    /// front slice at the base-plane position of the ray through it. Evaluated in f64 at pixels
    /// (0, 0), (1, 0), (0, 1).
    pub fn of_view(params: &FrameParams, spacing: [f64; 3], camera: &Camera) -> Self {
        let ((_, max_sx), (_, max_sy)) = params.shift_range();
        let k0 = params.slice(0).k as f64;
        let sp = DVec3::from_array(spacing);
        let dir_v = camera.dir / sp;
        let at = |px: u32, py: u32| {
            let o = camera.ray_origin(px, py) / sp;
            let t = (k0 - o[params.axis_k]) / dir_v[params.axis_k];
            let p = o + dir_v * t;
            (
                p[params.axis_i] + max_sx as f64,
                p[params.axis_j] + max_sy as f64,
            )
        };
        let (o, dx, dy) = (at(0, 0), at(1, 0), at(0, 1));
        Self {
            x0: o.0,
            y0: o.1,
            xpx: dx.0 - o.0,
            ypx: dx.1 - o.1,
            xpy: dy.0 - o.0,
            ypy: dy.1 - o.1,
        }
    }
}

/// The registers of one warp (`docs/numerics/warp.md`, "Registers"): sizes and the six
/// `S(15.20)` coordinate registers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct WarpRegs {
    pub base_w: u32,
    pub base_h: u32,
    pub out_w: u32,
    pub out_h: u32,
    pub x0: i64,
    pub y0: i64,
    pub xpx: i64,
    pub ypx: i64,
    pub xpy: i64,
    pub ypy: i64,
}

impl WarpRegs {
    /// The host's set-up: `affine` rounded to `S(15.20)` (halves away from zero), refused when a
    /// figure is not finite or an output corner maps outside `[-CoordLimit, CoordLimit]`.
    pub fn set_up(
        affine: &Affine,
        (base_w, base_h): (u32, u32),
        (out_w, out_h): (u32, u32),
    ) -> Result<Self> {
        let a = affine;
        let figures = [a.x0, a.y0, a.xpx, a.ypx, a.xpy, a.ypy];
        if figures.iter().any(|f| !f.is_finite()) {
            return Err(ModelError::View(format!(
                "warp: the affine map {a:?} is not finite"
            )));
        }
        let limit = f64::from(COORD_LIMIT);
        let (wm, hm) = (f64::from(out_w.max(1) - 1), f64::from(out_h.max(1) - 1));
        for (px, py) in [(0.0, 0.0), (wm, 0.0), (0.0, hm), (wm, hm)] {
            let (x, y) = a.at(px, py);
            if !(x.abs() <= limit && y.abs() <= limit) {
                return Err(ModelError::View(format!(
                    "warp: output pixel ({px}, {py}) maps to base-plane ({x:.1}, {y:.1}), outside \
                     +-{COORD_LIMIT} texels (zoom too far out?)"
                )));
            }
        }
        let q = |f: f64| (f * f64::from(1u32 << COORD_FRAC_W)).round() as i64;
        Ok(Self {
            base_w,
            base_h,
            out_w,
            out_h,
            x0: q(a.x0),
            y0: q(a.y0),
            xpx: q(a.xpx),
            ypx: q(a.ypx),
            xpy: q(a.xpy),
            ypy: q(a.ypy),
        })
    }

    /// The register writes of these registers, in offset order.
    pub fn writes(&self) -> Vec<WarpIn> {
        let c = |v: i64| (v as u64) & ((1u64 << COORD_W) - 1);
        [
            (REG_BASE_W, u64::from(self.base_w)),
            (REG_BASE_H, u64::from(self.base_h)),
            (REG_OUT_W, u64::from(self.out_w)),
            (REG_OUT_H, u64::from(self.out_h)),
            (REG_X0, c(self.x0)),
            (REG_Y0, c(self.y0)),
            (REG_XPX, c(self.xpx)),
            (REG_YPX, c(self.ypx)),
            (REG_XPY, c(self.xpy)),
            (REG_YPY, c(self.ypy)),
        ]
        .into_iter()
        .map(|(addr, data)| WarpIn::write(addr, data))
        .collect()
    }
}

/// A base plane as the warp reads it: `R, G, B` codes of `ColorW` bits, row-major.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BaseCodes {
    pub width: usize,
    pub height: usize,
    pub codes: Vec<[u32; 3]>,
}

impl BaseCodes {
    /// A `w x h` plane of uniformly random `ColorW`-bit codes (test and benchmark data).
    pub fn random(rng: &mut impl rand::Rng, w: usize, h: usize, color_w: u32) -> Self {
        let max = (1u32 << color_w) - 1;
        Self {
            width: w,
            height: h,
            codes: (0..w * h)
                .map(|_| std::array::from_fn(|_| rng.random_range(0..=max)))
                .collect(),
        }
    }

    /// Texel `(x, y)`, 0 outside the base plane.
    pub fn texel(&self, x: i64, y: i64) -> [u32; 3] {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            [0; 3]
        } else {
            self.codes[y as usize * self.width + x as usize]
        }
    }
}

/// The frame's coxel colours as `ColorW`-bit codes (`docs/numerics/warp.md`, "Base-plane codes"):
/// `min(2^ColorW - 1, rnd(c (2^ColorW - 1), AccW))`.
pub fn base_codes(base: &BasePlane, cfg: &ComposConfig) -> BaseCodes {
    let max = (1u64 << cfg.color_w) - 1;
    let half = 1u64 << (cfg.acc_w - 1);
    BaseCodes {
        width: base.width,
        height: base.height,
        codes: base
            .coxels
            .iter()
            .map(|c| {
                std::array::from_fn(|i| ((c.rgba[i] * max + half) >> cfg.acc_w).min(max) as u32)
            })
            .collect(),
    }
}

/// The `U(r, W, S)` widening of a `color_w`-bit code to `UnormW` fraction bits, all-ones = 2^UnormW.
pub fn widen(code: u32, color_w: u32) -> u32 {
    let r = u64::from(code);
    let wide = r * ((1 << color_w) + 1) + (r >> (color_w - 1));
    let s = 2 * color_w;
    (if s <= UNORM_W {
        wide << (UNORM_W - s)
    } else {
        (wide + (1 << (s - UNORM_W - 1))) >> (s - UNORM_W)
    }) as u32
}

/// `lerp(a, b, e) = (a 2^WeightW + e (b - a) + 2^(WeightW-1)) >> WeightW`.
fn lerp(a: u32, b: u32, e: u32, weight_w: u32) -> u32 {
    let (a, b, e) = (i64::from(a), i64::from(b), i64::from(e));
    // Arithmetic shift: floor.
    (((a << weight_w) + e * (b - a) + (1 << (weight_w - 1))) >> weight_w) as u32
}

/// Integer part (floor) and rounded `WeightW`-bit weight of an `S(15.20)` coordinate.
fn split(c: i64, weight_w: u32) -> (i64, u32) {
    let f = c & ((1 << COORD_FRAC_W) - 1);
    let drop = COORD_FRAC_W - weight_w;
    (c >> COORD_FRAC_W, ((f + (1 << (drop - 1))) >> drop) as u32)
}

/// One output pixel at fixed-point position `(x, y)`: four taps from `texel`, widened, three lerps
/// per channel, rounded to 8 bits.
pub fn pixel_at(cfg: &WarpConfig, x: i64, y: i64, texel: impl Fn(i64, i64) -> [u32; 3]) -> [u8; 3] {
    let (xi, wx) = split(x, cfg.weight_w);
    let (yi, wy) = split(y, cfg.weight_w);
    let t = [
        texel(xi, yi),
        texel(xi + 1, yi),
        texel(xi, yi + 1),
        texel(xi + 1, yi + 1),
    ];
    std::array::from_fn(|ch| {
        let u = t.map(|tap| widen(tap[ch], cfg.color_w));
        let h0 = lerp(u[0], u[1], wx, cfg.weight_w);
        let h1 = lerp(u[2], u[3], wx, cfg.weight_w);
        let v = u64::from(lerp(h0, h1, wy, cfg.weight_w));
        let max = (1u64 << OUT_CODE_W) - 1;
        ((v * max + (1 << (UNORM_W - 1))) >> UNORM_W) as u8
    })
}

/// The warped image of `base` under `regs` (`OutW x OutH` pixels, row-major): the closed form
/// `X0 + px XPx + py XPy` of the contract's exact steps, rows in parallel. [`pixel_at`] per pixel,
/// the same bits, with the per-frame work hoisted out of the pixel loop: the codes are widened
/// once into a copy with a border of zero texels (so a tap needs no bounds test), and a pixel
/// whose four taps all lie outside that border is 0 (three lerps of zeros round to 0).
pub fn warp_image(cfg: &WarpConfig, regs: &WarpRegs, base: &BaseCodes) -> Vec<[u8; 3]> {
    let (w, h) = (regs.out_w as usize, regs.out_h as usize);
    let mut out = vec![[0u8; 3]; w * h];
    if w == 0 {
        return out;
    }
    let (bw, bh) = (base.width, base.height);
    // Texel `(x, y)` of the base plane at `(y + 1) pw + x + 1`, for `x` in `-1 ..= bw`.
    let pw = bw + 2;
    let mut wide = vec![[0u32; 3]; pw * (bh + 2)];
    for (y, row) in base.codes.chunks_exact(bw.max(1)).take(bh).enumerate() {
        let at = (y + 1) * pw + 1;
        for (o, c) in wide[at..at + bw].iter_mut().zip(row) {
            *o = c.map(|c| widen(c, cfg.color_w));
        }
    }
    let ww = cfg.weight_w;
    let max = (1u64 << OUT_CODE_W) - 1;
    out.par_chunks_mut(w).enumerate().for_each(|(py, row)| {
        let py = py as i64;
        let mut x = regs.x0 + py * regs.xpy;
        let mut y = regs.y0 + py * regs.ypy;
        for o in row.iter_mut() {
            let (xi, wx) = split(x, ww);
            let (yi, wy) = split(y, ww);
            x += regs.xpx;
            y += regs.ypx;
            if xi < -1 || yi < -1 || xi >= bw as i64 || yi >= bh as i64 {
                continue;
            }
            let at = (yi + 1) as usize * pw + (xi + 1) as usize;
            let t = [wide[at], wide[at + 1], wide[at + pw], wide[at + pw + 1]];
            *o = std::array::from_fn(|ch| {
                let h0 = lerp(t[0][ch], t[1][ch], wx, ww);
                let h1 = lerp(t[2][ch], t[3][ch], wx, ww);
                let v = u64::from(lerp(h0, h1, wy, ww));
                ((v * max + (1 << (UNORM_W - 1))) >> UNORM_W) as u8
            });
        }
    });
    out
}

/// 8-bit pixels as an image in 0..1 (`code / 255`; `to_rgb8` gives the codes back).
pub fn to_image(width: u32, height: u32, pixels: &[[u8; 3]]) -> ImageF64 {
    ImageF64 {
        width,
        height,
        rgb: pixels
            .iter()
            .map(|p| p.map(|c| f64::from(c) / f64::from((1u32 << OUT_CODE_W) - 1)))
            .collect(),
    }
}

/// The f64 bilinear interpolation at `(x, y)` of the RGB texels `texel(x, y)` (integer texel
/// coordinates): the ideal both f64 warps use.
pub fn bilinear_f64(x: f64, y: f64, texel: impl Fn(i64, i64) -> [f64; 3]) -> [f64; 3] {
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (xi, yi) = (x0 as i64, y0 as i64);
    let mut c = [0.0; 3];
    for (dx, dy, wgt) in [
        (0, 0, (1.0 - fx) * (1.0 - fy)),
        (1, 0, fx * (1.0 - fy)),
        (0, 1, (1.0 - fx) * fy),
        (1, 1, fx * fy),
    ] {
        let t = texel(xi + dx, yi + dy);
        for ch in 0..3 {
            c[ch] += wgt * t[ch];
        }
    }
    c
}

/// The ideal: the f64 bilinear warp of `base` (codes on the unit interval) under `affine`, zero
/// outside the base plane, `out_w x out_h` pixels in 0..1.
pub fn reference(
    affine: &Affine,
    base: &BaseCodes,
    color_w: u32,
    (out_w, out_h): (u32, u32),
) -> ImageF64 {
    let max = f64::from((1u32 << color_w) - 1);
    let mut rgb = vec![[0.0; 3]; (out_w * out_h) as usize];
    if out_w > 0 {
        rgb.par_chunks_mut(out_w as usize)
            .enumerate()
            .for_each(|(py, row)| {
                for (px, o) in row.iter_mut().enumerate() {
                    let (x, y) = affine.at(px as f64, py as f64);
                    *o = bilinear_f64(x, y, |tx, ty| {
                        base.texel(tx, ty).map(|c| f64::from(c) / max)
                    });
                }
            });
    }
    ImageF64 {
        width: out_w,
        height: out_h,
        rgb,
    }
}

/// The contract's bound on `|out - 255 ideal|` at pixel `(px, py)` (`docs/numerics/warp.md`,
/// "Error bound against the ideal").
pub fn error_bound(cfg: &WarpConfig, px: u32, py: u32) -> f64 {
    let p2 = |e: i32| 2f64.powi(e);
    // The widening is within half a unit of 2^(2 ColorW), plus its rounding to UnormW bits.
    let e_u = p2(-(2 * cfg.color_w as i32 + 1))
        + if 2 * cfg.color_w > UNORM_W {
            p2(-(UNORM_W as i32 + 1))
        } else {
            0.0
        };
    let e_l = p2(-(UNORM_W as i32));
    let e_w = p2(-(cfg.weight_w as i32 + 1));
    let e_c = p2(-(COORD_FRAC_W as i32 + 1)) * (1.0 + f64::from(px) + f64::from(py)) + p2(-40);
    0.5 + 255.0 * (e_u + e_l + 2.0 * e_w + 2.0 * e_c)
}

/// One input item (`docs/numerics/warp.md`, "Input item"): `op`, `addr`, `payload`; also
/// `cube5_pwarp`'s (`PwarpIn`), whose op 2 is `Line`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WarpIn {
    pub op: u32,
    pub addr: u32,
    pub payload: u64,
}

impl WarpIn {
    pub fn write(addr: u32, data: u64) -> Self {
        Self {
            op: OP_WRITE,
            addr,
            payload: data,
        }
    }

    /// `Texel` with codes `rgb` of the configuration's `ColorW` bits.
    pub fn texel(cfg: &impl WarpKind, rgb: [u32; 3]) -> Self {
        let c = cfg.sampler().color_w;
        let m = (1u64 << c) - 1;
        Self {
            op: OP_TEXEL,
            addr: 0,
            payload: (u64::from(rgb[0]) & m)
                | (u64::from(rgb[1]) & m) << c
                | (u64::from(rgb[2]) & m) << (2 * c),
        }
    }

    pub fn go() -> Self {
        Self {
            op: OP_GO,
            addr: 0,
            payload: 0,
        }
    }

    /// The item as the RTL's `in_data_i`: payload (`pay_w` bits), addr, op, LSB first.
    pub fn pack(&self, pay_w: u32) -> Vec<u32> {
        let mut w = BitWriter::new();
        w.put(self.payload, pay_w);
        w.put(u64::from(self.addr), REG_ADDR_W);
        w.put(u64::from(self.op), 2);
        w.finish(pay_w + REG_ADDR_W + 2)
    }
}

/// What sets the two warps (`cube5_warp`, `cube5_pwarp`) apart in their stream model: the
/// registers and what an op-2 item (`Go`, `Line`) emits. Everything else they do alike
/// ([`WarpUnit`]): a `Write` restarts the texel position, a `Texel` stores and advances it, op 2
/// emits and restarts it, op 3 does nothing.
pub trait WarpKind: Copy {
    /// The unit's registers, 0 at reset.
    type Regs: Copy + Default + Debug;
    /// One output item.
    type Out: Clone + Debug + PartialEq;
    /// The configuration's own checks.
    fn check(&self) -> Result<()>;
    /// The banks and bilinear stage: `cube5_warp`'s at the same `ColorW`, `WeightW`, `MaxBase`.
    fn sampler(&self) -> WarpConfig;
    /// `BaseW`, `BaseH` in `regs`.
    fn base_size(regs: &Self::Regs) -> (u32, u32);
    /// Register `addr` of `regs` written with `data`.
    fn write(&self, regs: &mut Self::Regs, addr: u32, data: u64);
    /// The outputs of an op-2 item with `payload`, the base plane's taps read by `texel`.
    fn emit(
        &self,
        regs: &Self::Regs,
        payload: u64,
        texel: impl Fn(i64, i64) -> [u32; 3],
        out: &mut Vec<Self::Out>,
    );
}

/// The golden model of a warp as a stream unit: registers, the block RAM's base plane and the
/// texel position, driven by input items ([`Warp`], [`crate::units::cube5_pwarp::Pwarp`]).
#[derive(Debug, Clone)]
pub struct WarpUnit<K: WarpKind> {
    cfg: K,
    regs: K::Regs,
    tex: TexelMem,
}

/// The golden model of `cube5_warp`: a `Go` emits its image.
pub type Warp = WarpUnit<WarpConfig>;

impl<K: WarpKind> WarpUnit<K> {
    pub fn new(cfg: K) -> Result<Self> {
        cfg.check()?;
        Ok(Self {
            cfg,
            regs: K::Regs::default(),
            tex: TexelMem::new(cfg.sampler().max_base),
        })
    }

    pub fn config(&self) -> K {
        self.cfg
    }

    pub fn regs(&self) -> K::Regs {
        self.regs
    }
}

impl<K: WarpKind> StreamUnit for WarpUnit<K> {
    type In = WarpIn;
    type Out = K::Out;

    /// The outputs of the op-2 items among `inputs` (a `Go` emits `OutW x OutH` pixels, a `Line`
    /// its samples).
    fn run(&mut self, inputs: &[WarpIn]) -> Vec<K::Out> {
        let mut out = Vec::new();
        for it in inputs {
            match it.op & 3 {
                OP_WRITE => {
                    let addr = it.addr & ((1 << REG_ADDR_W) - 1);
                    self.cfg.write(&mut self.regs, addr, it.payload);
                    self.tex.restart();
                }
                OP_TEXEL => {
                    let (base_w, _) = K::base_size(&self.regs);
                    self.tex
                        .store(it.payload, self.cfg.sampler().color_w, base_w);
                }
                OP_GO => {
                    let size = K::base_size(&self.regs);
                    let texel = |x, y| self.tex.stored(x, y, size);
                    self.cfg.emit(&self.regs, it.payload, texel, &mut out);
                    self.tex.restart();
                }
                _ => {}
            }
        }
        out
    }

    /// Registers and texel position to 0; the block RAM keeps its contents (not reset).
    fn reset(&mut self) {
        self.regs = K::Regs::default();
        self.tex.restart();
    }
}

/// One output pixel: 8-bit R, G, B, `last` (end of a row, `tlast`), `user` (frame start, `tuser`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WarpOut {
    pub rgb: [u8; 3],
    pub last: bool,
    pub user: bool,
}

/// The items of one whole frame: the registers, `BaseW x BaseH` texels, `Go`.
pub fn frame_items(cfg: &WarpConfig, regs: &WarpRegs, base: &BaseCodes) -> Vec<WarpIn> {
    let mut items = regs.writes();
    items.extend(base.codes.iter().map(|&c| WarpIn::texel(cfg, c)));
    items.push(WarpIn::go());
    items
}

/// The base plane's block RAM and texel position as both warps keep them (`docs/numerics/warp.md`,
/// "Interface": a `Texel` item stores at the position, then advances it in raster order over
/// `BaseW`; taps outside `BaseW x BaseH` or `MaxBase` read 0). Not reset.
#[derive(Debug, Clone)]
pub struct TexelMem {
    max_base: u32,
    mem: Vec<[u32; 3]>,
    pos: (u32, u32),
}

impl TexelMem {
    pub fn new(max_base: u32) -> Self {
        Self {
            max_base,
            mem: vec![[0; 3]; (max_base * max_base) as usize],
            pos: (0, 0),
        }
    }

    /// Texel `(x, y)` of a `base_w x base_h` plane, 0 outside it or beyond `MaxBase`.
    pub fn stored(&self, x: i64, y: i64, (base_w, base_h): (u32, u32)) -> [u32; 3] {
        let mb = i64::from(self.max_base);
        let inside =
            x >= 0 && y >= 0 && x < i64::from(base_w) && y < i64::from(base_h) && x < mb && y < mb;
        if inside {
            self.mem[(y * mb + x) as usize]
        } else {
            [0; 3]
        }
    }

    /// A `Texel` item's payload (`R, G, B` codes, `color_w` bits each) stored at the position
    /// (dropped beyond `MaxBase`), then the position advanced over a `base_w`-wide plane.
    pub fn store(&mut self, payload: u64, color_w: u32, base_w: u32) {
        let c = color_w;
        let rgb: [u32; 3] =
            std::array::from_fn(|i| ((payload >> (i as u32 * c)) & ((1 << c) - 1)) as u32);
        let (x, y) = self.pos;
        let mb = self.max_base;
        if x < mb && y < mb {
            self.mem[(y * mb + x) as usize] = rgb;
        }
        self.pos = if x + 1 >= base_w {
            (0, (y + 1).min(mb))
        } else {
            (x + 1, y)
        };
    }

    /// The position back to `(0, 0)` (reset, `Write`, `Go`, `Line`).
    pub fn restart(&mut self) {
        self.pos = (0, 0);
    }
}

impl WarpKind for WarpConfig {
    type Regs = WarpRegs;
    type Out = WarpOut;

    fn check(&self) -> Result<()> {
        self.validate()
    }

    fn sampler(&self) -> WarpConfig {
        *self
    }

    fn base_size(regs: &WarpRegs) -> (u32, u32) {
        (regs.base_w, regs.base_h)
    }

    fn write(&self, r: &mut WarpRegs, addr: u32, data: u64) {
        let field = |w: u32| (data & ((1u64 << w) - 1)) as u32;
        let coord = |d: u64| {
            let sh = 64 - COORD_W;
            ((d << sh) as i64) >> sh
        };
        let (b1, o1) = (self.base_log2() + 1, self.out_log2() + 1);
        match addr {
            REG_BASE_W => r.base_w = field(b1),
            REG_BASE_H => r.base_h = field(b1),
            REG_OUT_W => r.out_w = field(o1),
            REG_OUT_H => r.out_h = field(o1),
            REG_X0 => r.x0 = coord(data),
            REG_Y0 => r.y0 = coord(data),
            REG_XPX => r.xpx = coord(data),
            REG_YPX => r.ypx = coord(data),
            REG_XPY => r.xpy = coord(data),
            REG_YPY => r.ypy = coord(data),
            _ => {}
        }
    }

    /// The image of a `Go`: exact steps from `X0, Y0`, raster order.
    fn emit(
        &self,
        r: &WarpRegs,
        _payload: u64,
        texel: impl Fn(i64, i64) -> [u32; 3],
        out: &mut Vec<WarpOut>,
    ) {
        let (mut row_x, mut row_y) = (r.x0, r.y0);
        for py in 0..r.out_h {
            let (mut x, mut y) = (row_x, row_y);
            for px in 0..r.out_w {
                out.push(WarpOut {
                    rgb: pixel_at(self, x, y, &texel),
                    last: px + 1 == r.out_w,
                    user: px == 0 && py == 0,
                });
                x += r.xpx;
                y += r.ypx;
            }
            row_x += r.xpy;
            row_y += r.ypy;
        }
    }
}

impl StreamCodec for WarpConfig {
    type In = WarpIn;
    type Out = WarpOut;

    fn in_width(&self) -> u32 {
        self.pay_w() + REG_ADDR_W + 2
    }

    fn out_width(&self) -> u32 {
        3 * OUT_CODE_W + 2
    }

    fn pack_in(&self, item: &WarpIn) -> Vec<u32> {
        item.pack(self.pay_w())
    }

    fn unpack_out(&self, words: &[u32]) -> WarpOut {
        let mut r = BitReader::new(words);
        let rgb = std::array::from_fn(|_| r.get(OUT_CODE_W) as u8);
        WarpOut {
            rgb,
            last: r.get_bool(),
            user: r.get_bool(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_affine(rng: &mut ChaCha8Rng, w: usize, h: usize, out: u32) -> Affine {
        let ang: f64 = rng.random_range(0.0..std::f64::consts::TAU);
        let zoom: f64 = rng.random_range(0.25..4.0);
        let s = zoom * (w.max(h) as f64) / f64::from(out);
        let (c, si) = (ang.cos() * s, ang.sin() * s);
        let (cx, cy) = (w as f64 / 2.0, h as f64 / 2.0);
        let o = f64::from(out) / 2.0;
        Affine {
            x0: cx - o * c + o * si + rng.random_range(-3.0..3.0),
            y0: cy - o * si - o * c + rng.random_range(-3.0..3.0),
            xpx: c,
            ypx: si,
            xpy: -si,
            ypy: c,
        }
    }

    #[test]
    fn widening_puts_all_ones_at_one() {
        for c in 4..=12 {
            assert_eq!(widen((1 << c) - 1, c), 1 << UNORM_W, "ColorW {c}");
            assert_eq!(widen(0, c), 0);
            // Within half a unit of 2^(2c), plus the rounding to UnormW bits.
            let tol = 2f64.powi(UNORM_W as i32 - 2 * c as i32 - 1) + 0.5;
            for r in 0..1u32 << c {
                let ideal = f64::from(r) / f64::from((1u32 << c) - 1) * 65536.0;
                let e = (f64::from(widen(r, c)) - ideal).abs();
                assert!(e <= tol, "ColorW {c} code {r}: {e} > {tol}");
            }
        }
    }

    #[test]
    fn identity_returns_the_codes() {
        let cfg = WarpConfig::DEFAULT;
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let base = BaseCodes::random(&mut rng, 9, 7, 8);
        let regs = WarpRegs::set_up(
            &Affine {
                x0: 0.0,
                y0: 0.0,
                xpx: 1.0,
                ypx: 0.0,
                xpy: 0.0,
                ypy: 1.0,
            },
            (9, 7),
            (9, 7),
        )
        .unwrap();
        let img = warp_image(&cfg, &regs, &base);
        for (p, c) in img.iter().zip(&base.codes) {
            assert_eq!(p.map(u32::from), *c);
        }
    }

    #[test]
    fn the_stream_model_equals_the_closed_form() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        for cfg in [
            WarpConfig::DEFAULT,
            WarpConfig {
                color_w: 10,
                weight_w: 5,
                max_base: 16,
                max_out: 32,
            },
        ] {
            for _ in 0..20 {
                let mb = cfg.max_base as usize;
                let (w, h) = (rng.random_range(1..=mb), rng.random_range(1..=mb));
                let out = rng.random_range(1..=cfg.max_out.min(40));
                let base = BaseCodes::random(&mut rng, w, h, cfg.color_w);
                let a = random_affine(&mut rng, w, h, out);
                let regs = WarpRegs::set_up(&a, (w as u32, h as u32), (out, out + 1)).unwrap();
                let mut unit = Warp::new(cfg).unwrap();
                let got = unit.run(&frame_items(&cfg, &regs, &base));
                let want = warp_image(&cfg, &regs, &base);
                assert_eq!(got.len(), want.len());
                for (i, (g, w)) in got.iter().zip(&want).enumerate() {
                    assert_eq!(g.rgb, *w, "pixel {i}");
                    assert_eq!(g.last, (i as u32 + 1).is_multiple_of(out));
                    assert_eq!(g.user, i == 0);
                }
            }
        }
    }

    /// The default, wide colour with narrow weights, and narrow colour with wide weights.
    const FILTER_CONFIGS: [WarpConfig; 3] = [
        WarpConfig::DEFAULT,
        WarpConfig {
            color_w: 12,
            weight_w: 4,
            ..WarpConfig::DEFAULT
        },
        WarpConfig {
            color_w: 5,
            weight_w: 12,
            ..WarpConfig::DEFAULT
        },
    ];

    /// `warp_image` is `pixel_at` of every pixel (the per-pixel form the stream model uses),
    /// with affine maps that reach far outside the base plane on every side.
    #[test]
    fn the_image_is_pixel_at_of_every_pixel() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for cfg in FILTER_CONFIGS {
            for _ in 0..40 {
                let (w, h) = (rng.random_range(1..=24), rng.random_range(1..=24));
                let out = rng.random_range(1..=64);
                let base = BaseCodes::random(&mut rng, w, h, cfg.color_w);
                let mut a = random_affine(&mut rng, w, h, out);
                a.x0 += rng.random_range(-2.0 * w as f64..2.0 * w as f64);
                a.y0 += rng.random_range(-2.0 * h as f64..2.0 * h as f64);
                let regs = WarpRegs::set_up(&a, (w as u32, h as u32), (out, out + 2)).unwrap();
                let got = warp_image(&cfg, &regs, &base);
                for (i, g) in got.iter().enumerate() {
                    let (px, py) = ((i % out as usize) as i64, (i / out as usize) as i64);
                    let x = regs.x0 + px * regs.xpx + py * regs.xpy;
                    let y = regs.y0 + px * regs.ypx + py * regs.ypy;
                    let want = pixel_at(&cfg, x, y, |tx, ty| base.texel(tx, ty));
                    assert_eq!(*g, want, "{cfg:?} pixel ({px}, {py})");
                }
            }
        }
    }

    #[test]
    fn within_the_bound_of_the_reference() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut worst: f64 = 0.0;
        for cfg in FILTER_CONFIGS {
            for _ in 0..30 {
                let (w, h) = (rng.random_range(1..=40), rng.random_range(1..=40));
                let out = rng.random_range(1..=96);
                let base = BaseCodes::random(&mut rng, w, h, cfg.color_w);
                let a = random_affine(&mut rng, w, h, out);
                let regs = WarpRegs::set_up(&a, (w as u32, h as u32), (out, out)).unwrap();
                let got = warp_image(&cfg, &regs, &base);
                let ideal = reference(&a, &base, cfg.color_w, (out, out));
                for (i, (g, r)) in got.iter().zip(&ideal.rgb).enumerate() {
                    let (px, py) = (i as u32 % out, i as u32 / out);
                    let bound = error_bound(&cfg, px, py);
                    for ch in 0..3 {
                        let e = (f64::from(g[ch]) - 255.0 * r[ch]).abs();
                        worst = worst.max(e);
                        assert!(
                            e <= bound,
                            "{cfg:?} pixel ({px}, {py}): error {e} > {bound}"
                        );
                    }
                }
            }
        }
        eprintln!("worst error {worst:.3} codes");
    }

    #[test]
    fn bad_set_ups_are_refused() {
        let a = Affine {
            x0: f64::NAN,
            y0: 0.0,
            xpx: 1.0,
            ypx: 0.0,
            xpy: 0.0,
            ypy: 1.0,
        };
        assert!(WarpRegs::set_up(&a, (4, 4), (4, 4)).is_err());
        let far = Affine {
            x0: 0.0,
            xpx: 100.0,
            ..a
        };
        let far = Affine { y0: 0.0, ..far };
        let e = WarpRegs::set_up(&far, (4, 4), (512, 4)).unwrap_err();
        assert!(e.to_string().contains("outside"), "{e}");
    }

    #[test]
    fn base_codes_round_and_saturate() {
        let cfg = ComposConfig::DEFAULT;
        let mut c = crate::units::cube5_compos::Coxel::empty(&cfg);
        c.rgba = [cfg.one(), cfg.one() * 2 - 1, cfg.one() / 2, 0];
        let b = base_codes(
            &BasePlane {
                width: 1,
                height: 1,
                coxels: vec![c],
            },
            &cfg,
        );
        let max = (1u32 << cfg.color_w) - 1;
        assert_eq!(b.codes[0], [max, max, max / 2 + 1]);
    }
}
