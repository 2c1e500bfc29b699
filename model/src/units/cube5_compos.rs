//! Compositing (`cube5_compos`), written from `docs/numerics/compos.md`: one sample meets the coxel
//! of its ray and the unit returns the updated coxel. Over (front to back and back to front),
//! maximum, minimum, X-ray sum, first opaque, the geometry flush; the opacity-correction LUT; the
//! depth test against preloaded geometry; early ray termination. Plus the f64 reference of the
//! same recurrences.

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::regs::cube5_compos as regmap;
use crate::unit::StreamCodec;

/// Widths of one `cube5_compos` configuration (the RTL parameters of the same names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ComposConfig {
    /// Colour code width (sample and geometry R, G, B).
    pub color_w: u32,
    /// Sample alpha code width; the opacity LUT has `2^alpha_w` entries.
    pub alpha_w: u32,
    /// Fraction bits of the corrected alpha beyond `alpha_w`.
    pub extra_w: u32,
    /// Fraction bits of the coxel's R, G, B, A, each `U(1.acc_w)`.
    pub acc_w: u32,
    /// Depth width.
    pub z_w: u32,
}

impl ComposConfig {
    /// `c8`: the patent's 8-bit coxel [240], no guard bits.
    pub const NARROW: Self = Self {
        color_w: 8,
        alpha_w: 8,
        extra_w: 0,
        acc_w: 8,
        z_w: 8,
    };
    /// `c12`: 8-bit colour, 12-bit alpha (VolumePro's widths), 4 extra alpha bits, 20-bit coxel.
    pub const DEFAULT: Self = Self {
        color_w: 8,
        alpha_w: 12,
        extra_w: 4,
        acc_w: 20,
        z_w: 12,
    };

    /// `c10`: 10-bit colour and alpha, 24-bit coxel, 16-bit depth (every width differs).
    pub const WIDE: Self = Self {
        color_w: 10,
        alpha_w: 10,
        extra_w: 2,
        acc_w: 24,
        z_w: 16,
    };

    pub fn new(color_w: u32, alpha_w: u32, extra_w: u32, acc_w: u32, z_w: u32) -> Result<Self> {
        let cfg = Self {
            color_w,
            alpha_w,
            extra_w,
            acc_w,
            z_w,
        };
        cfg.validate()?;
        Ok(cfg)
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("compos: {what}")));
        if !(4..=12).contains(&self.color_w) {
            return bad(format!("ColorW {} outside 4..=12", self.color_w));
        }
        if !(4..=12).contains(&self.alpha_w) {
            return bad(format!("AlphaW {} outside 4..=12", self.alpha_w));
        }
        if self.extra_w > 6 {
            return bad(format!("ExtraW {} outside 0..=6", self.extra_w));
        }
        let acc_min = self.q().max(self.color_w);
        if self.acc_w < acc_min || self.acc_w > 28 {
            return bad(format!(
                "AccW {} outside max(ColorW, AlphaW + ExtraW) ({acc_min}) ..= 28",
                self.acc_w
            ));
        }
        if !(1..=16).contains(&self.z_w) {
            return bad(format!("ZW {} outside 1..=16", self.z_w));
        }
        Ok(())
    }

    /// Fraction bits of the corrected alpha, `Q = AlphaW + ExtraW`.
    pub fn q(&self) -> u32 {
        self.alpha_w + self.extra_w
    }

    /// 1.0 on the coxel scale, `2^F`.
    pub fn one(&self) -> u64 {
        1 << self.acc_w
    }

    /// The coxel channel's all-ones code, `2^(F+1) - 1`, where sums saturate.
    pub fn chan_max(&self) -> u64 {
        (1 << (self.acc_w + 1)) - 1
    }

    pub fn color_max(&self) -> u32 {
        (1 << self.color_w) - 1
    }

    pub fn alpha_max(&self) -> u32 {
        (1 << self.alpha_w) - 1
    }

    /// The all-ones depth: no geometry / infinitely far.
    pub fn z_none(&self) -> u32 {
        (1 << self.z_w) - 1
    }

    /// Bits of one coxel on the stream.
    pub fn coxel_w(&self) -> u32 {
        4 * (self.acc_w + 1) + self.z_w + 3 * self.color_w + 1
    }

    /// Bits of one sample on the stream.
    pub fn sample_w(&self) -> u32 {
        3 * self.color_w + self.alpha_w + self.z_w + 3
    }

    /// Address of register `k` (`REG_CTRL`, `REG_ET_THRESHOLD`, `REG_FO_THRESHOLD` of
    /// `regs::cube5_compos`) on the config port.
    pub fn reg_addr(&self, k: u32) -> u32 {
        (1 << self.alpha_w) + k
    }
}

/// `E_W(r) = r (2^W + 1) + (r >> (W-1))`: a `W`-bit unit-interval code (all-ones = 1.0) on the
/// scale `2^(2W)`, within `2^-(2W+1)` of `r / (2^W - 1)`.
#[inline]
pub fn expand_double(r: u32, w: u32) -> u64 {
    u64::from(r) * ((1 << w) + 1) + u64::from(r >> (w - 1))
}

/// `U(r, W, S)`: a `W`-bit unit-interval code on the scale `2^S` (contract: *Number formats*).
#[inline]
pub fn unit_code(r: u32, w: u32, s: u32) -> u64 {
    let e = expand_double(r, w);
    if s >= 2 * w {
        e << (s - 2 * w)
    } else {
        rnd(e, 2 * w - s)
    }
}

/// `rnd(x, s)`: round half up of `x / 2^s`.
#[inline]
pub fn rnd(x: u64, s: u32) -> u64 {
    if s == 0 {
        x
    } else {
        (x + (1 << (s - 1))) >> s
    }
}

/// The 3-bit `mode` field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ComposMode {
    FrontToBack = regmap::MODE_FRONT_TO_BACK as isize,
    BackToFront = regmap::MODE_BACK_TO_FRONT as isize,
    Max = regmap::MODE_MAX as isize,
    Min = regmap::MODE_MIN as isize,
    XraySum = regmap::MODE_XRAY_SUM as isize,
    FirstOpaque = regmap::MODE_FIRST_OPAQUE as isize,
    Flush = regmap::MODE_FLUSH as isize,
    /// Reserved encoding: passes the coxel unchanged.
    Reserved = regmap::MODE_RESERVED as isize,
}

impl ComposMode {
    pub const ALL: [Self; 8] = [
        Self::FrontToBack,
        Self::BackToFront,
        Self::Max,
        Self::Min,
        Self::XraySum,
        Self::FirstOpaque,
        Self::Flush,
        Self::Reserved,
    ];

    pub fn from_bits(bits: u32) -> Self {
        Self::ALL[(bits & 7) as usize]
    }
}

/// A partial ray result: accumulated `R, G, B, A` (`U(1.AccW)`), the preloaded geometry depth and
/// colour, and the terminated flag.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Coxel {
    pub rgba: [u64; 4],
    pub z: u32,
    pub geo: [u32; 3],
    pub terminated: bool,
}

impl Coxel {
    /// An empty ray in front of no geometry.
    pub fn empty(cfg: &ComposConfig) -> Self {
        Self {
            rgba: [0; 4],
            z: cfg.z_none(),
            geo: [0; 3],
            terminated: false,
        }
    }
}

/// A shaded sample: colour codes, alpha code, depth (slice index), mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sample {
    pub rgb: [u32; 3],
    pub alpha: u32,
    pub depth: u32,
    pub mode: ComposMode,
}

/// A sample as the compositing's rule 5 reads it ([`Compos::code`]): the corrected alpha `U(1.Q)`,
/// the colours as unit codes on the coxel's scale `2^F`, depth and mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CodedSample {
    pub a: u64,
    pub c_w: [u64; 3],
    pub depth: u32,
    pub mode: ComposMode,
}

/// One stream item: the coxel of a ray and its next sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ComposIn {
    pub coxel: Coxel,
    pub sample: Sample,
}

/// The configuration registers (contract: *Configuration port*).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ComposRegs {
    pub lut_bypass: bool,
    /// 0..=15.
    pub xray_shift: u32,
    /// `F+1` bits, coxel `A` scale.
    pub et_threshold: u64,
    /// `Q+1` bits, corrected-alpha scale.
    pub fo_threshold: u64,
}

impl ComposRegs {
    /// LUT in use, X-ray sum of up to 256 full samples to 1.0, early termination at
    /// `1 - 2^-8` (below half an 8-bit display LSB of what remains), first opaque at alpha 0.5.
    pub fn defaults(cfg: &ComposConfig) -> Self {
        Self {
            lut_bypass: false,
            xray_shift: 8,
            et_threshold: cfg.one() - (cfg.one() >> 8),
            fo_threshold: 1 << (cfg.q() - 1),
        }
    }

    /// Early termination off.
    pub fn without_termination(cfg: &ComposConfig) -> Self {
        Self {
            et_threshold: cfg.chan_max(),
            ..Self::defaults(cfg)
        }
    }

    pub fn validate(&self, cfg: &ComposConfig) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("compos registers: {what}")));
        if self.xray_shift > 15 {
            return bad(format!("XrayShift {} outside 0..=15", self.xray_shift));
        }
        if self.et_threshold > cfg.chan_max() {
            return bad(format!(
                "EtThreshold {} wider than {} bits",
                self.et_threshold,
                cfg.acc_w + 1
            ));
        }
        if self.fo_threshold >> (cfg.q() + 1) != 0 {
            return bad(format!(
                "FoThreshold {} wider than {} bits",
                self.fo_threshold,
                cfg.q() + 1
            ));
        }
        Ok(())
    }
}

/// The step ratios `d/k` the opacity-correction tables are checked at: 1/16 to 16 by powers of two,
/// and the diagonal step `sqrt(3)`.
pub fn correction_ratios() -> [f64; 10] {
    [
        1.0 / 16.0,
        1.0 / 8.0,
        1.0 / 4.0,
        0.5,
        1.0,
        3f64.sqrt(),
        2.0,
        4.0,
        8.0,
        16.0,
    ]
}

/// The opacity-correction table `alpha' = 1 - (1 - alpha)^(d/k)`, `2^AlphaW` entries of `U(1.Q)`.
/// Produced here and nowhere else; loaded into the model directly and into the RTL through the
/// configuration port (`config_writes`).
#[derive(Debug, Clone, PartialEq)]
pub struct OpacityLut {
    entries: Vec<u32>,
    ratio: Option<f64>,
    vanished: usize,
}

impl OpacityLut {
    /// Smallest and largest `d/k` accepted.
    pub const RATIO_MIN: f64 = 1.0 / 16.0;
    pub const RATIO_MAX: f64 = 16.0;

    /// The table for `ratio = d/k`: `floor(alpha'(r) * 2^Q + 1/2)` with
    /// `alpha'(r) = 1 - (1 - r/(2^AlphaW-1))^ratio` in f64.
    pub fn new(ratio: f64, cfg: &ComposConfig) -> Result<Self> {
        cfg.validate()?;
        if !ratio.is_finite() || !(Self::RATIO_MIN..=Self::RATIO_MAX).contains(&ratio) {
            return Err(ModelError::Config(format!(
                "opacity LUT: ratio d/k = {ratio} outside 1/16..=16"
            )));
        }
        let scale = f64::from(1u32 << cfg.q());
        let entries: Vec<u32> = (0..=cfg.alpha_max())
            .map(|r| (corrected_alpha(alpha_value(r, cfg), ratio) * scale + 0.5).floor() as u32)
            .collect();
        let vanished = entries.iter().skip(1).filter(|&&e| e == 0).count();
        Ok(Self {
            entries,
            ratio: Some(ratio),
            vanished,
        })
    }

    /// A table with arbitrary contents (`Q+1` bits each; the unit clamps entries above `2^Q`).
    pub fn from_entries(entries: Vec<u32>, cfg: &ComposConfig) -> Result<Self> {
        cfg.validate()?;
        if entries.len() != 1 << cfg.alpha_w {
            return Err(ModelError::Config(format!(
                "opacity LUT: {} entries, expected {}",
                entries.len(),
                1u32 << cfg.alpha_w
            )));
        }
        if let Some(i) = entries.iter().position(|&e| e >> (cfg.q() + 1) != 0) {
            return Err(ModelError::Config(format!(
                "opacity LUT: entry {i} = {} wider than {} bits",
                entries[i],
                cfg.q() + 1
            )));
        }
        Ok(Self {
            entries,
            ratio: None,
            vanished: 0,
        })
    }

    pub fn entries(&self) -> &[u32] {
        &self.entries
    }

    /// The ratio the table was built for (`None` for `from_entries`).
    pub fn ratio(&self) -> Option<f64> {
        self.ratio
    }

    /// Nonzero alpha codes whose corrected alpha rounded to 0 (the *values under one LSB* rule).
    pub fn vanished(&self) -> usize {
        self.vanished
    }
}

/// The value of alpha code `r`: `r / (2^AlphaW - 1)`.
pub fn alpha_value(r: u32, cfg: &ComposConfig) -> f64 {
    f64::from(r) / f64::from(cfg.alpha_max())
}

/// The value of colour code `c`: `c / (2^ColorW - 1)`.
pub fn color_value(c: u32, cfg: &ComposConfig) -> f64 {
    f64::from(c) / f64::from(cfg.color_max())
}

/// `1 - (1 - alpha)^ratio`, accurate for tiny alpha.
pub fn corrected_alpha(alpha: f64, ratio: f64) -> f64 {
    if alpha >= 1.0 {
        1.0
    } else {
        -(ratio * (-alpha).ln_1p()).exp_m1()
    }
}

/// The golden model of `cube5_compos`.
#[derive(Debug, Clone)]
pub struct Compos {
    cfg: ComposConfig,
    lut: OpacityLut,
    regs: ComposRegs,
}

impl Compos {
    pub fn new(cfg: ComposConfig, lut: OpacityLut, regs: ComposRegs) -> Result<Self> {
        cfg.validate()?;
        regs.validate(&cfg)?;
        if lut.entries.len() != 1 << cfg.alpha_w {
            return Err(ModelError::Config(format!(
                "compos: opacity LUT has {} entries, the configuration {}",
                lut.entries.len(),
                1u32 << cfg.alpha_w
            )));
        }
        Ok(Self { cfg, lut, regs })
    }

    pub fn config(&self) -> ComposConfig {
        self.cfg
    }

    pub fn regs(&self) -> ComposRegs {
        self.regs
    }

    pub fn lut(&self) -> &OpacityLut {
        &self.lut
    }

    /// The configuration-port writes that load this unit's table and registers into the RTL.
    pub fn config_writes(&self) -> Vec<(u32, Vec<u32>)> {
        config_writes(&self.cfg, &self.lut, &self.regs)
    }

    /// The corrected alpha `a` of alpha code `r`, `U(1.Q)`.
    #[inline]
    pub fn corrected(&self, r: u32) -> u64 {
        if self.regs.lut_bypass {
            unit_code(r, self.cfg.alpha_w, self.cfg.q())
        } else {
            u64::from(self.lut.entries[r as usize]).min(1 << self.cfg.q())
        }
    }

    /// Whether `step(coxel, s)` returns `coxel` itself for every colour of a sample `s` with this
    /// alpha code, depth and mode (a transparent sample, one that does not win a `Max`, any sample
    /// of a terminated ray, ...). It reads `step`'s rules in order and says `false` wherever a rule
    /// could write the coxel, so it may answer `false` for a sample that changes nothing, never
    /// `true` for one that changes something (the frame's fast path skips shading on `true`).
    #[inline]
    pub fn leaves_unchanged(
        &self,
        coxel: &Coxel,
        alpha: u32,
        depth: u32,
        mode: ComposMode,
    ) -> bool {
        self.leaves_unchanged_corrected(coxel, self.corrected(alpha), depth, mode)
    }

    /// [`Compos::leaves_unchanged`] of a sample whose corrected alpha `self.corrected(alpha)` is
    /// `a` (for callers that keep the corrected alpha of each alpha code at hand).
    #[inline(always)]
    pub fn leaves_unchanged_corrected(
        &self,
        coxel: &Coxel,
        a: u64,
        depth: u32,
        mode: ComposMode,
    ) -> bool {
        let cfg = &self.cfg;
        // Rule 1.
        if mode == ComposMode::Reserved || coxel.terminated {
            return true;
        }
        // Rules 2 and 3.
        if mode == ComposMode::Flush
            || (mode == ComposMode::FrontToBack && coxel.rgba[3] >= self.regs.et_threshold)
        {
            return false;
        }
        // Rule 4.
        if depth >= coxel.z {
            return true;
        }
        // Rule 5.
        let a_in = coxel.rgba[3];
        match mode {
            // A zero weight adds 0 and saturates what is already in range.
            ComposMode::FrontToBack => {
                a == 0 && coxel.rgba[..3].iter().all(|&c| c <= cfg.chan_max())
            }
            ComposMode::Max => (a << (cfg.acc_w - cfg.q())) <= a_in,
            ComposMode::Min => (a << (cfg.acc_w - cfg.q())) >= a_in,
            _ => false,
        }
    }

    /// A sample as rule 5 reads it: its corrected alpha and its colours on the coxel's scale.
    #[inline(always)]
    pub fn code(&self, s: &Sample) -> CodedSample {
        let (f, cw) = (self.cfg.acc_w, self.cfg.color_w);
        CodedSample {
            a: self.corrected(s.alpha),
            c_w: s.rgb.map(|c| unit_code(c, cw, f)),
            depth: s.depth,
            mode: s.mode,
        }
    }

    /// One item: the coxel after this sample.
    #[inline]
    pub fn step(&self, coxel: &Coxel, s: &Sample) -> Coxel {
        self.step_coded(coxel, &self.code(s))
    }

    /// [`Compos::step`] of a sample already coded ([`Compos::code`]; a caller that meets the same
    /// sample values many times codes them once). Always inlined: at a call site with a constant
    /// mode (the frame's sweep) the other modes' rules fold away.
    #[inline(always)]
    pub fn step_coded(&self, coxel: &Coxel, s: &CodedSample) -> Coxel {
        let cfg = &self.cfg;
        let (f, q, cw) = (cfg.acc_w, cfg.q(), cfg.color_w);
        let mut out = *coxel;
        let [r_in, g_in, b_in, a_in] = coxel.rgba;
        let c_in = [r_in, g_in, b_in];
        let t = cfg.one() - a_in.min(cfg.one());
        let sat = |x: u64| x.min(cfg.chan_max());

        // 1. Reserved mode, or a ray that is already done.
        if s.mode == ComposMode::Reserved || coxel.terminated {
            return out;
        }
        // 2. End of the ray: the opaque geometry goes under the coxel.
        if s.mode == ComposMode::Flush {
            out.terminated = true;
            if coxel.z != cfg.z_none() {
                for (i, &g) in coxel.geo.iter().enumerate() {
                    let g_w = unit_code(g, cw, f);
                    out.rgba[i] = sat(c_in[i] + rnd(t * g_w, f));
                }
                out.rgba[3] = a_in + t;
            }
            return out;
        }
        // 3. Early termination (front to back only).
        if s.mode == ComposMode::FrontToBack && a_in >= self.regs.et_threshold {
            out.terminated = true;
            return out;
        }
        // 4. Depth test against the preloaded geometry.
        if s.depth >= coxel.z {
            return out;
        }
        // 5. The sample contributes.
        let (a, c_w) = (s.a, s.c_w);
        let a_w = a << (f - q);
        let w = rnd(t * a, q);
        match s.mode {
            ComposMode::FrontToBack => {
                for i in 0..3 {
                    out.rgba[i] = sat(c_in[i] + rnd(w * c_w[i], f));
                }
                out.rgba[3] = a_in + w;
                out.terminated = out.rgba[3] >= self.regs.et_threshold;
            }
            ComposMode::BackToFront => {
                let one_q = 1u64 << q;
                for i in 0..3 {
                    out.rgba[i] = rnd(a * c_w[i] + (one_q - a) * c_in[i], q);
                }
                out.rgba[3] = a_in + w;
            }
            ComposMode::Max | ComposMode::Min => {
                let wins = if s.mode == ComposMode::Max {
                    a_w > a_in
                } else {
                    a_w < a_in
                };
                if wins {
                    out.rgba = [c_w[0], c_w[1], c_w[2], a_w];
                }
            }
            ComposMode::XraySum => {
                let sh = self.regs.xray_shift;
                for i in 0..3 {
                    out.rgba[i] = sat(c_in[i] + rnd(c_w[i], sh));
                }
                out.rgba[3] = sat(a_in + rnd(a_w, sh));
            }
            ComposMode::FirstOpaque => {
                if a >= self.regs.fo_threshold {
                    out.rgba = [c_w[0], c_w[1], c_w[2], cfg.one()];
                    out.terminated = true;
                }
            }
            ComposMode::Flush | ComposMode::Reserved => unreachable!("handled above"),
        }
        out
    }

    /// Composites `samples` in order onto `coxel` (a ray through the FIFO), returning every
    /// intermediate coxel: element `n` is the coxel after sample `n`.
    pub fn ray(&self, coxel: &Coxel, samples: &[Sample]) -> Vec<Coxel> {
        let mut cur = *coxel;
        samples
            .iter()
            .map(|s| {
                cur = self.step(&cur, s);
                cur
            })
            .collect()
    }
}

/// The configuration-port writes for `lut` and `regs`: every LUT entry, then Ctrl, EtThreshold
/// and FoThreshold (contract: *Configuration port*).
pub fn config_writes(
    cfg: &ComposConfig,
    lut: &OpacityLut,
    regs: &ComposRegs,
) -> Vec<(u32, Vec<u32>)> {
    let data = |v: u64| vec![v as u32];
    let mut writes: Vec<(u32, Vec<u32>)> = lut
        .entries
        .iter()
        .enumerate()
        .map(|(r, &e)| (r as u32, data(u64::from(e))))
        .collect();
    let ctrl = regmap::REG_CTRL_LUT_BYPASS.set(0, u64::from(regs.lut_bypass));
    let ctrl = regmap::REG_CTRL_XRAY_SHIFT.set(ctrl, u64::from(regs.xray_shift));
    writes.push((cfg.reg_addr(regmap::REG_CTRL), data(ctrl)));
    writes.push((
        cfg.reg_addr(regmap::REG_ET_THRESHOLD),
        data(regs.et_threshold),
    ));
    writes.push((
        cfg.reg_addr(regmap::REG_FO_THRESHOLD),
        data(regs.fo_threshold),
    ));
    writes
}

crate::item_by_item!(Compos, ComposIn => Coxel, |unit, it| unit.step(&it.coxel, &it.sample));

impl StreamCodec for ComposConfig {
    type In = ComposIn;
    type Out = Coxel;

    fn in_width(&self) -> u32 {
        self.coxel_w() + self.sample_w()
    }

    fn out_width(&self) -> u32 {
        self.coxel_w()
    }

    fn pack_in(&self, item: &ComposIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        put_coxel(&mut w, self, &item.coxel);
        let s = &item.sample;
        for c in s.rgb {
            w.put(u64::from(c), self.color_w);
        }
        w.put(u64::from(s.alpha), self.alpha_w);
        w.put(u64::from(s.depth), self.z_w);
        w.put(s.mode as u64, 3);
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> Coxel {
        get_coxel(&mut BitReader::new(words), self)
    }
}

/// Reads a coxel in the stream layout of `put_coxel` (`coxel_w` bits): R, G, B, A, Z, GEO, T.
pub fn get_coxel(r: &mut BitReader, cfg: &ComposConfig) -> Coxel {
    Coxel {
        rgba: std::array::from_fn(|_| r.get(cfg.acc_w + 1)),
        z: r.get(cfg.z_w) as u32,
        geo: std::array::from_fn(|_| r.get(cfg.color_w) as u32),
        terminated: r.get_bool(),
    }
}

fn put_coxel(w: &mut BitWriter, cfg: &ComposConfig, c: &Coxel) {
    for v in c.rgba {
        w.put(v, cfg.acc_w + 1);
    }
    w.put(u64::from(c.z), cfg.z_w);
    for g in c.geo {
        w.put(u64::from(g), cfg.color_w);
    }
    w.put_bool(c.terminated);
}

// -------------------------------------------------------------------------------------------------
// f64 reference
// -------------------------------------------------------------------------------------------------

/// A coxel in f64: channels as reals (1.0 = opaque / full intensity).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefCoxel {
    pub rgba: [f64; 4],
    pub z: u32,
    pub geo: [f64; 3],
    pub terminated: bool,
}

impl RefCoxel {
    /// The real value of a fixed-point coxel.
    pub fn from_coxel(c: &Coxel, cfg: &ComposConfig) -> Self {
        let one = cfg.one() as f64;
        Self {
            rgba: c.rgba.map(|v| v as f64 / one),
            z: c.z,
            geo: c.geo.map(|g| color_value(g, cfg)),
            terminated: c.terminated,
        }
    }
}

/// The f64 reference of one item: the contract's recurrences on reals, codes read as
/// `r / (2^W - 1)`, `alpha' = 1 - (1 - alpha)^ratio` unquantized (`alpha` itself with
/// `ratio = None`, the bypass), no rounding; thresholds and saturation at their real values.
pub fn reference_step(
    cfg: &ComposConfig,
    regs: &ComposRegs,
    ratio: Option<f64>,
    coxel: &RefCoxel,
    s: &Sample,
) -> RefCoxel {
    let one = cfg.one() as f64;
    let chan_max = cfg.chan_max() as f64 / one;
    let et = regs.et_threshold as f64 / one;
    let fo = regs.fo_threshold as f64 / f64::from(1u32 << cfg.q());
    let mut out = *coxel;
    let [r_in, g_in, b_in, a_in] = coxel.rgba;
    let c_in = [r_in, g_in, b_in];
    let t = 1.0 - a_in.min(1.0);
    if s.mode == ComposMode::Reserved || coxel.terminated {
        return out;
    }
    if s.mode == ComposMode::Flush {
        out.terminated = true;
        if coxel.z != cfg.z_none() {
            for (i, &g) in coxel.geo.iter().enumerate() {
                out.rgba[i] = (c_in[i] + t * g).min(chan_max);
            }
            out.rgba[3] = a_in + t;
        }
        return out;
    }
    if s.mode == ComposMode::FrontToBack && a_in >= et {
        out.terminated = true;
        return out;
    }
    if s.depth >= coxel.z {
        return out;
    }
    let alpha = alpha_value(s.alpha, cfg);
    let a = ratio.map_or(alpha, |k| corrected_alpha(alpha, k));
    let c = s.rgb.map(|v| color_value(v, cfg));
    let w = t * a;
    match s.mode {
        ComposMode::FrontToBack => {
            for i in 0..3 {
                out.rgba[i] = (c_in[i] + w * c[i]).min(chan_max);
            }
            out.rgba[3] = a_in + w;
            out.terminated = out.rgba[3] >= et;
        }
        ComposMode::BackToFront => {
            for i in 0..3 {
                out.rgba[i] = a * c[i] + (1.0 - a) * c_in[i];
            }
            out.rgba[3] = a_in + w;
        }
        ComposMode::Max | ComposMode::Min => {
            let wins = if s.mode == ComposMode::Max {
                a > a_in
            } else {
                a < a_in
            };
            if wins {
                out.rgba = [c[0], c[1], c[2], a];
            }
        }
        ComposMode::XraySum => {
            let div = f64::from(1u32 << regs.xray_shift);
            for i in 0..3 {
                out.rgba[i] = (c_in[i] + c[i] / div).min(chan_max);
            }
            out.rgba[3] = (a_in + a / div).min(chan_max);
        }
        ComposMode::FirstOpaque => {
            if a >= fo {
                out.rgba = [c[0], c[1], c[2], 1.0];
                out.terminated = true;
            }
        }
        ComposMode::Flush | ComposMode::Reserved => unreachable!("handled above"),
    }
    out
}

/// Error of a fixed-point ray against its f64 reference: the largest absolute difference over the
/// four channels of every coxel along the ray, in units of 1.0 (multiply by `2^F` for coxel LSBs).
pub fn ray_error(
    unit: &Compos,
    start: &Coxel,
    samples: &[Sample],
) -> (Vec<Coxel>, Vec<RefCoxel>, f64) {
    let cfg = unit.config();
    let ratio = if unit.regs().lut_bypass {
        None
    } else {
        unit.lut().ratio()
    };
    let fixed = unit.ray(start, samples);
    let mut cur = RefCoxel::from_coxel(start, &cfg);
    let mut refs = Vec::with_capacity(samples.len());
    let mut max = 0.0f64;
    let one = cfg.one() as f64;
    for (s, fx) in samples.iter().zip(&fixed) {
        cur = reference_step(&cfg, &unit.regs(), ratio, &cur, s);
        for ch in 0..4 {
            max = max.max((fx.rgba[ch] as f64 / one - cur.rgba[ch]).abs());
        }
        refs.push(cur);
    }
    (fixed, refs, max)
}

// The RTL parameters of this unit (the RTL defaults are the model's `DEFAULT`).
crate::unit_config!(ComposConfig, "cube5_compos", DEFAULT, {
    "ColorW" => color_w,
    "AlphaW" => alpha_w,
    "ExtraW" => extra_w,
    "AccW" => acc_w,
    "ZW" => z_w,
});

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn unit(cfg: ComposConfig, ratio: f64, regs: ComposRegs) -> Compos {
        Compos::new(cfg, OpacityLut::new(ratio, &cfg).unwrap(), regs).unwrap()
    }

    fn sample(rgb: [u32; 3], alpha: u32, depth: u32, mode: ComposMode) -> Sample {
        Sample {
            rgb,
            alpha,
            depth,
            mode,
        }
    }

    const CONFIGS: [ComposConfig; 3] = [
        ComposConfig::NARROW,
        ComposConfig::DEFAULT,
        ComposConfig::WIDE,
    ];

    #[test]
    fn code_reading_is_exact_at_the_ends_and_within_the_contract_bound() {
        for w in 4..=12 {
            let top = (1u32 << w) - 1;
            for s in [w, w + 4, 2 * w, 2 * w + 3, 28] {
                assert_eq!(unit_code(0, w, s), 0);
                assert_eq!(unit_code(top, w, s), 1 << s, "all-ones is 1.0");
                let bound = 0.5f64.powi(2 * w as i32 + 1)
                    + if s < 2 * w {
                        0.5f64.powi(s as i32 + 1)
                    } else {
                        0.0
                    };
                for r in 0..=top {
                    let got = unit_code(r, w, s) as f64 / 2f64.powi(s as i32);
                    let err = got - f64::from(r) / f64::from(top);
                    assert!(err.abs() <= bound + 1e-15, "w {w} s {s} r {r}: {err}");
                }
            }
        }
    }

    /// alpha 0, 1 LSB, 1 - 1 LSB and 1, front to back and back to front, LUT and bypass.
    #[test]
    fn alpha_0_1lsb_1minus1lsb_and_1() {
        for cfg in CONFIGS {
            let top = cfg.alpha_max();
            for bypass in [false, true] {
                let regs = ComposRegs {
                    lut_bypass: bypass,
                    ..ComposRegs::without_termination(&cfg)
                };
                let u = unit(cfg, 1.0, regs);
                let q1 = 1u64 << cfg.q();
                // The corrected alpha of the four codes (ratio 1 is the identity up to rounding).
                assert_eq!(u.corrected(0), 0);
                assert_eq!(u.corrected(top), q1, "alpha 1 is exactly opaque");
                assert_eq!(u.corrected(1), 1 << cfg.extra_w, "1 LSB");
                assert_eq!(u.corrected(top - 1), q1 - (1 << cfg.extra_w), "1 - 1 LSB");
                let white = [cfg.color_max(); 3];
                let empty = Coxel::empty(&cfg);
                // alpha 0: nothing changes in either over mode.
                for mode in [ComposMode::FrontToBack, ComposMode::BackToFront] {
                    let mut c = empty;
                    c.rgba = [100, 200, 300, 400];
                    assert_eq!(u.step(&c, &sample(white, 0, 0, mode)), c);
                }
                // alpha 1: front to back takes all of what remains, back to front replaces.
                let mut half = empty;
                half.rgba = [0, 0, 0, cfg.one() / 2];
                let out = u.step(&half, &sample(white, top, 0, ComposMode::FrontToBack));
                assert_eq!(
                    out.rgba,
                    [cfg.one() / 2, cfg.one() / 2, cfg.one() / 2, cfg.one()]
                );
                let out = u.step(&half, &sample(white, top, 0, ComposMode::BackToFront));
                assert_eq!(out.rgba, [cfg.one(); 4]);
                // 1 LSB on an empty ray: exactly 1 LSB of alpha, and of a white colour.
                let lsb = (cfg.one() >> cfg.q()) << cfg.extra_w;
                let out = u.step(&empty, &sample(white, 1, 0, ComposMode::FrontToBack));
                assert_eq!(out.rgba, [lsb; 4]);
                // 1 - 1 LSB then again: remaining transparency (1 LSB)^2.
                let once = u.step(&empty, &sample(white, top - 1, 0, ComposMode::FrontToBack));
                assert_eq!(once.rgba[3], cfg.one() - lsb);
                let twice = u.step(&once, &sample(white, top - 1, 0, ComposMode::FrontToBack));
                let t2 = (lsb as f64 / cfg.one() as f64).powi(2);
                let want = cfg.one() - (t2 * cfg.one() as f64).round() as u64;
                assert_eq!(twice.rgba[3], want, "{cfg:?}");
            }
        }
    }

    /// 10,000 samples of every alpha code class: A rises monotonically, never passes 1.0, and
    /// matches the f64 closed form until the ray stalls.
    #[test]
    fn accumulated_opacity_saturates_over_10000_samples() {
        for cfg in CONFIGS {
            let u = unit(cfg, 1.0, ComposRegs::without_termination(&cfg));
            for alpha in [
                1,
                2,
                7,
                cfg.alpha_max() / 3,
                cfg.alpha_max() - 1,
                cfg.alpha_max(),
            ] {
                let s = sample([cfg.color_max(); 3], alpha, 0, ComposMode::FrontToBack);
                let ray = u.ray(&Coxel::empty(&cfg), &vec![s; 10_000]);
                let mut prev = 0;
                for c in &ray {
                    assert!(c.rgba[3] >= prev && c.rgba[3] <= cfg.one());
                    assert!(c.rgba[..3].iter().all(|&x| x <= c.rgba[3]), "C <= A");
                    prev = c.rgba[3];
                }
                // Where it ends: each step rounds T by at most half an LSB, and the (1 - a)
                // factor shrinks old errors, so |T - T_exact| <= 2^-(F+1) / a = T_stall.
                let a = u.corrected(alpha) as f64 / f64::from(1u32 << cfg.q());
                let t_end = 1.0 - prev as f64 / cfg.one() as f64;
                let t_exact = (1.0 - a).powi(10_000);
                let t_stall = 0.5f64.powi(cfg.acc_w as i32 + 1) / a;
                assert!(
                    (t_end - t_exact).abs() <= t_stall + 1e-12,
                    "{cfg:?} alpha {alpha}: T {t_end} exact {t_exact} stall {t_stall}"
                );
                // Saturation is exact: an opaque code ends the ray at 1.0.
                if alpha == cfg.alpha_max() {
                    assert_eq!(prev, cfg.one());
                }
            }
            // Back to front over many opaque-ish samples also stays within [0, 1].
            let s = sample(
                [cfg.color_max(); 3],
                cfg.alpha_max() - 1,
                0,
                ComposMode::BackToFront,
            );
            let last = *u.ray(&Coxel::empty(&cfg), &vec![s; 10_000]).last().unwrap();
            assert!(last.rgba.iter().all(|&x| x <= cfg.one()));
            assert_eq!(last.rgba[3], cfg.one(), "back to front converges to opaque");
        }
    }

    /// The LUT for d/k from 1/16 to 16: exact ends, monotone, within half an LSB of the f64
    /// value, and the documented behaviour for values under one LSB.
    #[test]
    fn opacity_correction_1_16_to_16_including_sub_lsb() {
        for cfg in CONFIGS {
            let scale = f64::from(1u32 << cfg.q());
            for ratio in correction_ratios() {
                let lut = OpacityLut::new(ratio, &cfg).unwrap();
                let e = lut.entries();
                assert_eq!(e[0], 0);
                assert_eq!(e[cfg.alpha_max() as usize], 1 << cfg.q(), "alpha 1 stays 1");
                assert!(e.windows(2).all(|p| p[0] <= p[1]), "monotone at {ratio}");
                let mut vanished = 0;
                for (r, &v) in e.iter().enumerate() {
                    let exact = corrected_alpha(alpha_value(r as u32, &cfg), ratio) * scale;
                    assert!((f64::from(v) - exact).abs() <= 0.5 + 1e-9, "{ratio} r {r}");
                    if r > 0 && v == 0 {
                        vanished += 1;
                        assert!(exact < 0.5, "only values under half an LSB vanish");
                    }
                }
                assert_eq!(lut.vanished(), vanished);
                if cfg == ComposConfig::DEFAULT {
                    assert_eq!(
                        vanished, 0,
                        "ExtraW = 4 keeps every code alive down to 1/16"
                    );
                }
            }
            // Ratio 1 is the identity up to rounding.
            let id = OpacityLut::new(1.0, &cfg).unwrap();
            for (r, &v) in id.entries().iter().enumerate() {
                let exact = r as f64 / f64::from(cfg.alpha_max()) * scale;
                assert!((f64::from(v) - exact).abs() <= 0.5);
            }
        }
        // The narrow configuration (no extra bits) loses the faintest codes at 1/16.
        let narrow = OpacityLut::new(1.0 / 16.0, &ComposConfig::NARROW).unwrap();
        assert_eq!(
            narrow.vanished(),
            7,
            "codes 1..=7 of 255 fall under half an 8-bit LSB"
        );
        assert_eq!(narrow.entries()[8], 1);
        // The smallest default entry at 1/16 is one LSB (1.0003 of the exact value).
        let d = OpacityLut::new(1.0 / 16.0, &ComposConfig::DEFAULT).unwrap();
        assert_eq!(d.entries()[1], 1);
        // Sub-LSB rule in the ray: 16 samples at 1/16 add about the opacity of one at ratio 1.
        let cfg = ComposConfig::DEFAULT;
        let one = unit(cfg, 1.0, ComposRegs::without_termination(&cfg));
        let sixteenth = unit(cfg, 1.0 / 16.0, ComposRegs::without_termination(&cfg));
        for alpha in [1, 2, 10, 100, 1000] {
            let s = sample([255; 3], alpha, 0, ComposMode::FrontToBack);
            let a1 = one.step(&Coxel::empty(&cfg), &s).rgba[3] as f64;
            let a16 = sixteenth.ray(&Coxel::empty(&cfg), &[s; 16])[15].rgba[3] as f64;
            assert!(
                (a16 - a1).abs() <= 16.0 * 16.0,
                "alpha {alpha}: {a16} vs {a1} (within 16 Q-LSB)"
            );
        }
        assert!(OpacityLut::new(1.0 / 17.0, &cfg).is_err());
        assert!(OpacityLut::new(16.5, &cfg).is_err());
        assert!(OpacityLut::new(f64::NAN, &cfg).is_err());
    }

    /// Densities (alpha codes) and colours 0 and max in every mode.
    #[test]
    fn densities_and_colours_0_and_max() {
        for cfg in CONFIGS {
            let u = unit(cfg, 1.0, ComposRegs::defaults(&cfg));
            let (cmax, amax) = (cfg.color_max(), cfg.alpha_max());
            let one = cfg.one();
            let e = Coxel::empty(&cfg);
            let ftb = |c: u32, a: u32| u.step(&e, &sample([c; 3], a, 0, ComposMode::FrontToBack));
            assert_eq!(ftb(0, 0).rgba, [0; 4]);
            assert_eq!(ftb(cmax, 0).rgba, [0; 4]);
            assert_eq!(ftb(0, amax).rgba, [0, 0, 0, one]);
            assert_eq!(ftb(cmax, amax).rgba, [one; 4]);
            assert!(
                ftb(cmax, amax).terminated,
                "opaque reaches the ET threshold"
            );
            let btf = |c: u32, a: u32| u.step(&e, &sample([c; 3], a, 0, ComposMode::BackToFront));
            assert_eq!(btf(cmax, amax).rgba, [one; 4]);
            assert_eq!(btf(0, amax).rgba, [0, 0, 0, one]);
            // Max/Min with full and empty keys.
            let mip = u.step(&e, &sample([cmax; 3], amax, 0, ComposMode::Max));
            assert_eq!(mip.rgba, [one; 4]);
            let full = Coxel {
                rgba: [one; 4],
                ..e
            };
            let min = u.step(&full, &sample([0; 3], 0, 0, ComposMode::Min));
            assert_eq!(min.rgba, [0; 4]);
            assert_eq!(
                u.step(&full, &sample([0; 3], amax, 0, ComposMode::Min)),
                full
            );
            // First opaque: alpha max always qualifies, alpha 0 never (threshold 0.5).
            let fo = u.step(&e, &sample([cmax; 3], amax, 0, ComposMode::FirstOpaque));
            assert!(fo.terminated && fo.rgba == [one; 4]);
            assert_eq!(
                u.step(&e, &sample([cmax; 3], 0, 0, ComposMode::FirstOpaque)),
                e
            );
        }
    }

    /// X-ray sums of full values saturate at the channel's all-ones code, never wrap.
    #[test]
    fn xray_sum_overflow_saturates() {
        for cfg in CONFIGS {
            for shift in [0, 1, 8, 15] {
                let regs = ComposRegs {
                    xray_shift: shift,
                    ..ComposRegs::defaults(&cfg)
                };
                let u = unit(cfg, 1.0, regs);
                let s = sample(
                    [cfg.color_max(); 3],
                    cfg.alpha_max(),
                    0,
                    ComposMode::XraySum,
                );
                let n = 3 << shift.min(10);
                let ray = u.ray(&Coxel::empty(&cfg), &vec![s; n]);
                let mut prev = 0;
                for c in &ray {
                    assert!(c.rgba[0] >= prev, "monotone");
                    prev = c.rgba[0];
                }
                let last = ray.last().unwrap();
                if shift <= 10 {
                    assert_eq!(last.rgba, [cfg.chan_max(); 4], "shift {shift}");
                }
            }
            // 256 full samples at shift 8 sum to exactly 1.0.
            let u = unit(cfg, 1.0, ComposRegs::defaults(&cfg));
            let s = sample(
                [cfg.color_max(); 3],
                cfg.alpha_max(),
                0,
                ComposMode::XraySum,
            );
            let last = *u.ray(&Coxel::empty(&cfg), &[s; 256]).last().unwrap();
            assert_eq!(last.rgba, [cfg.one(); 4]);
            // A coxel at the top code stays there.
            let top = Coxel {
                rgba: [cfg.chan_max(); 4],
                ..Coxel::empty(&cfg)
            };
            assert_eq!(u.step(&top, &s).rgba, [cfg.chan_max(); 4]);
        }
    }

    /// Alpha 0.002 (a faint gel) and white, front to back: the final colour after N samples for an
    /// 8-bit coxel, a 12-bit one without guard bits, and the default widths, against the f64
    /// target `1 - (1 - 0.002)^N`. Prints the table of the contract page.
    #[test]
    fn eight_bit_alpha_stalls_and_default_widths_do_not() {
        let alpha = 0.002f64;
        let twelve_no_guard = ComposConfig::new(8, 12, 0, 12, 12).unwrap();
        let configs = [
            ("8-bit coxel (c8)", ComposConfig::NARROW),
            ("12-bit alpha, AccW 12", twelve_no_guard),
            ("default (c12)", ComposConfig::DEFAULT),
        ];
        let ns = [256usize, 1024, 4096, 10_000, 100_000];
        println!("| widths | alpha code (value) | stall T | {} |", {
            ns.iter()
                .map(|n| format!("N = {n}"))
                .collect::<Vec<_>>()
                .join(" | ")
        });
        println!(
            "| f64 target | 0.002 | 0 | {} |",
            ns.iter()
                .map(|&n| format!("{:.4}", 1.0 - (1.0 - alpha).powi(n as i32)))
                .collect::<Vec<_>>()
                .join(" | ")
        );
        let mut finals = Vec::new();
        for (name, cfg) in configs {
            let u = unit(cfg, 1.0, ComposRegs::without_termination(&cfg));
            let code = (alpha * f64::from(cfg.alpha_max())).round() as u32;
            let s = sample([cfg.color_max(); 3], code, 0, ComposMode::FrontToBack);
            let ray = u.ray(&Coxel::empty(&cfg), &vec![s; *ns.last().unwrap()]);
            let val = |n: usize| ray[n - 1].rgba[0] as f64 / cfg.one() as f64;
            let a = u.corrected(code) as f64 / f64::from(1u32 << cfg.q());
            let t_stall = 0.5f64.powi(cfg.acc_w as i32 + 1) / a;
            println!(
                "| {name} | {code} ({:.5}) | {t_stall:.2e} | {} |",
                alpha_value(code, &cfg),
                ns.iter()
                    .map(|&n| format!("{:.4}", val(n)))
                    .collect::<Vec<_>>()
                    .join(" | ")
            );
            finals.push(val(100_000));
        }
        // The 8-bit coxel stays half transparent forever; the default reaches the target colour
        // within half an 8-bit display LSB.
        assert!(
            (finals[0] - 0.5).abs() < 0.01,
            "8-bit stalls at 0.5: {}",
            finals[0]
        );
        assert!(
            finals[1] < 0.95,
            "12-bit without guard bits stalls short of 1"
        );
        assert!(1.0 - finals[2] < 0.5 / 255.0, "default: {}", finals[2]);
    }

    /// For every 12-bit alpha code at ratio 1 the stall transparency of the default widths is at
    /// most 2^-9: the guard bits make 12-bit alpha not stall visibly.
    #[test]
    fn default_widths_stall_below_half_an_8bit_lsb_for_every_12bit_alpha() {
        let cfg = ComposConfig::DEFAULT;
        let u = unit(cfg, 1.0, ComposRegs::without_termination(&cfg));
        let s = sample([255; 3], 1, 0, ComposMode::FrontToBack);
        // Start close to the stall point to keep the ray short: T = 2^-8.
        let start = Coxel {
            rgba: [0, 0, 0, cfg.one() - (cfg.one() >> 8)],
            ..Coxel::empty(&cfg)
        };
        let ray = u.ray(&start, &vec![s; 40_000]);
        let t = cfg.one() - ray.last().unwrap().rgba[3];
        assert!(t <= cfg.one() >> 9, "T at stall {t} > 2^-9");
        assert_eq!(ray[ray.len() - 1], ray[ray.len() - 2], "stalled");
    }

    #[test]
    fn depth_test_and_geometry_flush() {
        let cfg = ComposConfig::DEFAULT;
        let u = unit(cfg, 1.0, ComposRegs::defaults(&cfg));
        let geo = Coxel {
            z: 10,
            geo: [255, 0, 0],
            ..Coxel::empty(&cfg)
        };
        let s = |k| sample([0, 0, 255], 2048, k, ComposMode::FrontToBack);
        for mode in ComposMode::ALL {
            for k in [10, 11, 4094] {
                let mut t = s(k);
                t.mode = mode;
                if mode != ComposMode::Flush {
                    assert_eq!(u.step(&geo, &t), geo, "{mode:?} at k {k} is hidden");
                }
            }
        }
        // In front: contributes, then the flush puts the red geometry under the blue sample.
        let front = u.step(&geo, &s(9));
        assert!(front.rgba[2] > 0 && front.rgba[0] == 0);
        let flushed = u.step(&front, &sample([0; 3], 0, 0, ComposMode::Flush));
        assert!(flushed.terminated);
        assert_eq!(flushed.rgba[3], cfg.one());
        let t = cfg.one() - front.rgba[3];
        assert_eq!(flushed.rgba[0], t, "white-red geometry under: R += T");
        assert_eq!(flushed.rgba[2], front.rgba[2]);
        // A second flush, or any later sample, changes nothing.
        assert_eq!(
            u.step(&flushed, &sample([0; 3], 0, 0, ComposMode::Flush)),
            flushed
        );
        assert_eq!(u.step(&flushed, &s(0)), flushed);
        // No geometry: the flush only marks the ray done.
        let e = Coxel::empty(&cfg);
        let f = u.step(&e, &sample([0; 3], 0, 0, ComposMode::Flush));
        assert_eq!(
            f,
            Coxel {
                terminated: true,
                ..e
            }
        );
        // Znone never lets a sample at depth Znone contribute.
        let s_far = sample([255; 3], 4095, cfg.z_none(), ComposMode::FrontToBack);
        assert_eq!(u.step(&e, &s_far), e);
    }

    /// `leaves_unchanged` never says so of a sample that changes the coxel, and does say so of
    /// transparent samples, samples below a maximum and samples of terminated rays.
    #[test]
    fn leaves_unchanged_only_when_step_changes_nothing() {
        use rand::{Rng, SeedableRng};
        let cfg = ComposConfig::DEFAULT;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(31);
        let mut said = [0usize; 8];
        for (n, regs) in [
            ComposRegs::defaults(&cfg),
            ComposRegs::without_termination(&cfg),
            ComposRegs {
                et_threshold: 0,
                ..ComposRegs::defaults(&cfg)
            },
        ]
        .into_iter()
        .enumerate()
        {
            for ratio in [0.5, 1.0, 3f64.sqrt()] {
                let c = unit(cfg, ratio, regs);
                for _ in 0..20_000 {
                    let mode = ComposMode::from_bits(rng.random_range(0..8));
                    // Small alphas and colours, often 0, so that every rule is reached.
                    let pick = |rng: &mut rand_chacha::ChaCha8Rng, max: u64| -> u64 {
                        match rng.random_range(0..4) {
                            0 => 0,
                            1 => rng.random_range(0..=4.min(max)),
                            _ => rng.random_range(0..=max),
                        }
                    };
                    let coxel = Coxel {
                        rgba: std::array::from_fn(|_| pick(&mut rng, cfg.chan_max())),
                        z: if rng.random_bool(0.7) {
                            cfg.z_none()
                        } else {
                            rng.random_range(0..=cfg.z_none())
                        },
                        geo: std::array::from_fn(|_| rng.random_range(0..=cfg.color_max())),
                        terminated: rng.random_bool(0.1),
                    };
                    let alpha = pick(&mut rng, u64::from(cfg.alpha_max())) as u32;
                    let depth = rng.random_range(0..=cfg.z_none());
                    if c.leaves_unchanged(&coxel, alpha, depth, mode) {
                        said[mode as usize] += 1;
                        for _ in 0..4 {
                            let rgb =
                                std::array::from_fn(|_| rng.random_range(0..=cfg.color_max()));
                            let s = sample(rgb, alpha, depth, mode);
                            assert_eq!(c.step(&coxel, &s), coxel, "regs {n} {s:?} on {coxel:?}");
                        }
                    }
                }
            }
        }
        for mode in [ComposMode::FrontToBack, ComposMode::Max, ComposMode::Min] {
            assert!(said[mode as usize] > 100, "{mode:?}: {said:?}");
        }
    }

    #[test]
    fn early_termination() {
        let cfg = ComposConfig::DEFAULT;
        let regs = ComposRegs::defaults(&cfg);
        let u = unit(cfg, 1.0, regs);
        let at = Coxel {
            rgba: [5, 6, 7, regs.et_threshold],
            ..Coxel::empty(&cfg)
        };
        let s = sample([255; 3], 4095, 0, ComposMode::FrontToBack);
        let out = u.step(&at, &s);
        assert_eq!(
            out,
            Coxel {
                terminated: true,
                ..at
            },
            "unchanged, marked"
        );
        // Just below: composites and marks on the way past the threshold.
        let below = Coxel {
            rgba: [5, 6, 7, regs.et_threshold - 1],
            ..at
        };
        let out = u.step(&below, &s);
        assert!(out.terminated && out.rgba[3] == cfg.one());
        // Other modes ignore the threshold but respect the flag.
        let b = u.step(&at, &sample([255; 3], 4095, 0, ComposMode::BackToFront));
        assert!(!b.terminated && b.rgba[3] == cfg.one());
        let done = Coxel {
            terminated: true,
            ..below
        };
        for mode in ComposMode::ALL {
            let mut t = s;
            t.mode = mode;
            assert_eq!(u.step(&done, &t), done);
        }
    }

    #[test]
    fn max_min_ties_keep_the_coxel() {
        let cfg = ComposConfig::DEFAULT;
        let u = unit(cfg, 1.0, ComposRegs::defaults(&cfg));
        let a = u.corrected(1000) << (cfg.acc_w - cfg.q());
        let c = Coxel {
            rgba: [1, 2, 3, a],
            ..Coxel::empty(&cfg)
        };
        for mode in [ComposMode::Max, ComposMode::Min] {
            assert_eq!(u.step(&c, &sample([255; 3], 1000, 0, mode)), c);
        }
        assert_eq!(
            u.step(&c, &sample([255; 3], 1001, 0, ComposMode::Max)).rgba[0],
            cfg.one()
        );
        assert_eq!(
            u.step(&c, &sample([0; 3], 999, 0, ComposMode::Min)).rgba[0],
            0
        );
    }

    #[test]
    fn lut_entries_above_one_are_clamped() {
        let cfg = ComposConfig::NARROW;
        let lut = OpacityLut::from_entries(vec![(1 << (cfg.q() + 1)) - 1; 256], &cfg).unwrap();
        let u = Compos::new(cfg, lut, ComposRegs::defaults(&cfg)).unwrap();
        assert_eq!(u.corrected(3), 1 << cfg.q());
        let bad = OpacityLut::from_entries(vec![1 << (cfg.q() + 1); 256], &cfg);
        assert!(bad.is_err());
        assert!(OpacityLut::from_entries(vec![0; 255], &cfg).is_err());
    }

    /// Over random 256-sample rays the fixed-point result stays close to the f64 reference.
    #[test]
    fn f64_reference_error_over_256_sample_rays() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for cfg in CONFIGS {
            let u = unit(cfg, 0.5, ComposRegs::without_termination(&cfg));
            let mut worst = 0.0f64;
            for _ in 0..200 {
                let samples: Vec<Sample> = (0..256)
                    .map(|_| {
                        sample(
                            std::array::from_fn(|_| rng.random_range(0..=cfg.color_max())),
                            rng.random_range(0..=cfg.alpha_max() / 16),
                            0,
                            ComposMode::FrontToBack,
                        )
                    })
                    .collect();
                let (_, _, err) = ray_error(&u, &Coxel::empty(&cfg), &samples);
                worst = worst.max(err);
            }
            // Default widths: well within one 8-bit display LSB; the 8-bit coxel is not.
            if cfg == ComposConfig::DEFAULT {
                assert!(worst < 0.5 / 255.0, "default worst {worst}");
            }
            println!("{cfg:?}: worst {:.2} display LSB", worst * 255.0);
        }
    }

    #[test]
    fn config_validation() {
        assert!(ComposConfig::new(8, 12, 4, 20, 12).is_ok());
        assert!(ComposConfig::new(3, 12, 4, 20, 12).is_err());
        assert!(ComposConfig::new(8, 13, 4, 20, 12).is_err());
        assert!(ComposConfig::new(8, 12, 7, 20, 12).is_err());
        assert!(ComposConfig::new(8, 12, 4, 15, 12).is_err(), "AccW < Q");
        assert!(ComposConfig::new(8, 12, 4, 29, 12).is_err());
        assert!(
            ComposConfig::new(12, 8, 0, 10, 12).is_err(),
            "AccW < ColorW"
        );
        assert!(
            ComposConfig::new(12, 8, 0, 12, 12).is_ok(),
            "ColorW > Q is fine"
        );
        assert!(ComposConfig::new(8, 12, 4, 20, 0).is_err());
        assert!(ComposConfig::new(8, 12, 4, 20, 17).is_err());
        let cfg = ComposConfig::DEFAULT;
        let mut regs = ComposRegs::defaults(&cfg);
        assert!(regs.validate(&cfg).is_ok());
        regs.xray_shift = 16;
        assert!(regs.validate(&cfg).is_err());
        let regs = ComposRegs {
            et_threshold: cfg.chan_max() + 1,
            ..ComposRegs::defaults(&cfg)
        };
        assert!(Compos::new(cfg, OpacityLut::new(1.0, &cfg).unwrap(), regs).is_err());
        let narrow_lut = OpacityLut::new(1.0, &ComposConfig::NARROW).unwrap();
        assert!(Compos::new(cfg, narrow_lut, ComposRegs::defaults(&cfg)).is_err());
    }

    #[test]
    fn packing_width_matches_contract_table() {
        assert_eq!(ComposConfig::NARROW.in_width(), 112);
        assert_eq!(ComposConfig::NARROW.out_width(), 69);
        assert_eq!(ComposConfig::DEFAULT.in_width(), 172);
        assert_eq!(ComposConfig::DEFAULT.out_width(), 121);
        assert_eq!(ComposConfig::WIDE.in_width(), 206);
        assert_eq!(ComposConfig::WIDE.out_width(), 147);
        let cfg = ComposConfig::DEFAULT;
        let c = Coxel {
            rgba: [1, cfg.chan_max(), 3, 1 << 20],
            z: 4094,
            geo: [1, 2, 255],
            terminated: true,
        };
        let item = ComposIn {
            coxel: c,
            sample: sample([9, 8, 7], 4095, 17, ComposMode::Flush),
        };
        // The output packing is the first coxel_w bits of the input packing.
        let words = cfg.pack_in(&item);
        assert_eq!(cfg.unpack_out(&words), c);
        let w = config_writes(
            &cfg,
            &OpacityLut::new(2.0, &cfg).unwrap(),
            &ComposRegs::defaults(&cfg),
        );
        assert_eq!(w.len(), 4096 + 3);
        assert_eq!(w[4096], (4096, vec![8 << 1]), "Ctrl: no bypass, shift 8");
    }
}
