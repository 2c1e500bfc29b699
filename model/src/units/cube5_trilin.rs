//! Tri-linear interpolation (`cube5_trilin`), written from `docs/numerics.md` § Tri-linear
//! interpolation: seven linear interpolations, x then y then z, each rounded half up.

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::StreamCodec;

/// Widths of one `cube5_trilin` configuration (the RTL parameters of the same names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TrilinConfig {
    pub voxel_w: u32,
    pub weight_w: u32,
    pub frac_w: u32,
    /// 0: one register stage per axis (latency 3); 1: three per axis, every multiplier between
    /// registers (latency 9; the frame's interpolators). The same bits either way.
    pub pipe: u32,
}

impl TrilinConfig {
    pub const NARROW: Self = Self {
        voxel_w: 8,
        weight_w: 6,
        frac_w: 2,
        pipe: 0,
    };
    pub const DEFAULT: Self = Self {
        voxel_w: 12,
        weight_w: 8,
        frac_w: 4,
        pipe: 0,
    };
    pub const WIDE: Self = Self {
        voxel_w: 16,
        weight_w: 10,
        frac_w: 6,
        pipe: 0,
    };

    pub fn new(voxel_w: u32, weight_w: u32, frac_w: u32) -> Result<Self> {
        let cfg = Self {
            voxel_w,
            weight_w,
            frac_w,
            pipe: 0,
        };
        cfg.validate()?;
        Ok(cfg)
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |what: &str| Err(ModelError::Config(format!("trilin: {what}")));
        if !(4..=16).contains(&self.voxel_w) {
            return bad(&format!("VoxelW {} outside 4..=16", self.voxel_w));
        }
        if !(1..=12).contains(&self.weight_w) {
            return bad(&format!("WeightW {} outside 1..=12", self.weight_w));
        }
        if self.frac_w > 8 {
            return bad(&format!("FracW {} outside 0..=8", self.frac_w));
        }
        if self.pipe > 1 {
            return bad(&format!("Pipe {} outside 0..=1", self.pipe));
        }
        Ok(())
    }

    /// Cycles from an item in to its sample out: one register stage per axis, or three with
    /// `Pipe = 1` (docs/numerics/trilin.md, "Timing").
    pub fn latency(&self) -> u64 {
        if self.pipe != 0 {
            9
        } else {
            3
        }
    }

    /// Width of the output sample, `U(VoxelW.FracW)`.
    pub fn sample_w(&self) -> u32 {
        self.voxel_w + self.frac_w
    }

    pub fn voxel_max(&self) -> u32 {
        (1 << self.voxel_w) - 1
    }

    pub fn weight_max(&self) -> u32 {
        (1 << self.weight_w) - 1
    }
}

/// The weight modes of `docs/numerics.md` (the 2-bit `mode` field).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrilinMode {
    Lerp = 0,
    Half = 1,
    Select = 2,
    /// Reserved encoding; behaves as `Lerp` by contract.
    Reserved = 3,
}

impl TrilinMode {
    pub fn from_bits(bits: u32) -> Self {
        match bits & 3 {
            0 => Self::Lerp,
            1 => Self::Half,
            2 => Self::Select,
            _ => Self::Reserved,
        }
    }
}

/// One input item: corner voxels indexed `x + 2y + 4z`, weights `U(0.WeightW)`, mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TrilinIn {
    pub voxels: [u32; 8],
    pub weights: [u32; 3],
    pub mode: TrilinMode,
}

/// The golden model of `cube5_trilin`.
#[derive(Debug, Clone)]
pub struct Trilin {
    cfg: TrilinConfig,
}

impl Trilin {
    pub fn new(cfg: TrilinConfig) -> Result<Self> {
        cfg.validate()?;
        Ok(Self { cfg })
    }

    pub fn config(&self) -> TrilinConfig {
        self.cfg
    }

    /// The effective weight on the scale `2^WeightW` = 1.0 (table in the contract).
    #[inline(always)]
    fn effective_weight(&self, w: u32, mode: TrilinMode) -> u64 {
        let one = 1u64 << self.cfg.weight_w;
        match mode {
            TrilinMode::Lerp | TrilinMode::Reserved => u64::from(w),
            TrilinMode::Half => one / 2,
            TrilinMode::Select => {
                if u64::from(w) < one / 2 {
                    0
                } else {
                    one
                }
            }
        }
    }

    /// `lerp(a, b, e) = rnd(a * (2^WeightW - e) + b * e, WeightW)`.
    #[inline(always)]
    fn lerp(&self, a: u64, b: u64, e: u64) -> u64 {
        let one = 1u64 << self.cfg.weight_w;
        round_half_up(a * (one - e) + b * e, self.cfg.weight_w)
    }

    /// One sample, `U(VoxelW.FracW)`.
    pub fn sample(&self, item: &TrilinIn) -> u32 {
        let e = item.weights.map(|w| self.effective_weight(w, item.mode));
        self.interpolate(&item.voxels, e)
    }

    /// `sample` of a `Lerp` item whose corners in the slice `z + 1` are 0 and whose `wz` is 0: the
    /// bilinear sample within one slice that the frame takes (`docs/numerics/frame.md`), corners
    /// `[(0,0), (1,0), (0,1), (1,1)]`, for the frame's fast path. The same lerps as `sample` minus
    /// those that cannot change the result: `lerp(0, 0, e) = 0` (the half added by the rounding
    /// is below one LSB) and `lerp(q, 0, 0) = q`, for every `WeightW >= 1` (tested).
    #[inline(always)]
    pub fn sample_in_slice(&self, corners: [u32; 4], wx: u32, wy: u32) -> u32 {
        let wide = |c: usize| u64::from(corners[c]) << self.cfg.frac_w;
        let e = |w| self.effective_weight(w, TrilinMode::Lerp);
        let (ex, ey) = (e(wx), e(wy));
        let p0 = self.lerp(wide(0), wide(1), ex);
        let p1 = self.lerp(wide(2), wide(3), ex);
        self.lerp(p0, p1, ey) as u32
    }

    /// [`Trilin::sample_in_slice`] along a row of anchors: `out[n]` from the corners `top[n]`,
    /// `top[n + 1]`, `bot[n]`, `bot[n + 1]` (`top` and `bot` at least one longer than `out`). The
    /// same three rounded lerps with the weights hoisted, in 32-bit lanes when no intermediate
    /// can pass 2^32 (`VoxelW + FracW + WeightW <= 31`), so that the compiler vectorizes the row.
    #[inline(always)]
    pub fn row_in_slice(&self, top: &[u16], bot: &[u16], wx: u32, wy: u32, out: &mut [u32]) {
        let n = out.len();
        let (top, bot) = (&top[..n + 1], &bot[..n + 1]);
        let (w, f) = (self.cfg.weight_w, self.cfg.frac_w);
        let ex = self.effective_weight(wx, TrilinMode::Lerp);
        let ey = self.effective_weight(wy, TrilinMode::Lerp);
        if self.cfg.sample_w() + w <= 31 {
            let (one, half) = (1u32 << w, 1u32 << (w - 1));
            let (ex, ey) = (ex as u32, ey as u32);
            let (fx, fy) = (one - ex, one - ey);
            let c = |v: u16| u32::from(v) << f;
            for (i, o) in out.iter_mut().enumerate() {
                let p0 = (c(top[i]) * fx + c(top[i + 1]) * ex + half) >> w;
                let p1 = (c(bot[i]) * fx + c(bot[i + 1]) * ex + half) >> w;
                *o = (p0 * fy + p1 * ey + half) >> w;
            }
        } else {
            let c = |v: u16| u64::from(v) << f;
            for (i, o) in out.iter_mut().enumerate() {
                let p0 = self.lerp(c(top[i]), c(top[i + 1]), ex);
                let p1 = self.lerp(c(bot[i]), c(bot[i + 1]), ex);
                *o = self.lerp(p0, p1, ey) as u32;
            }
        }
    }

    /// The weights of one slice for [`InSlice::lanes`]: [`Trilin::row_in_slice`]'s set-up made
    /// once (a frame's slice has one `wx`, `wy` for every anchor).
    pub fn in_slice(&self, wx: u32, wy: u32) -> InSlice {
        let (w, f) = (self.cfg.weight_w, self.cfg.frac_w);
        let ex = self.effective_weight(wx, TrilinMode::Lerp);
        let ey = self.effective_weight(wy, TrilinMode::Lerp);
        let one = 1u64 << w;
        InSlice {
            narrow: self.cfg.sample_w() + w <= 31,
            w,
            f,
            ex: ex as u32,
            ey: ey as u32,
            fx: (one - ex) as u32,
            fy: (one - ey) as u32,
            half: 1u32 << (w - 1),
        }
    }

    /// The seven interpolations of the contract with the effective weights `[ex, ey, ez]`.
    #[inline]
    fn interpolate(&self, voxels: &[u32; 8], [ex, ey, ez]: [u64; 3]) -> u32 {
        let wide = |c: usize| u64::from(voxels[c]) << self.cfg.frac_w;
        let p = [
            self.lerp(wide(0), wide(1), ex),
            self.lerp(wide(2), wide(3), ex),
            self.lerp(wide(4), wide(5), ex),
            self.lerp(wide(6), wide(7), ex),
        ];
        let q = [self.lerp(p[0], p[1], ey), self.lerp(p[2], p[3], ey)];
        self.lerp(q[0], q[1], ez) as u32
    }

    /// The f64 ideal with the same effective weights, in voxel units.
    pub fn reference(&self, item: &TrilinIn) -> f64 {
        let one = f64::from(1u32 << self.cfg.weight_w);
        let e = item
            .weights
            .map(|w| self.effective_weight(w, item.mode) as f64 / one);
        (0..8)
            .map(|c| {
                let f = |axis: usize| {
                    if (c >> axis) & 1 == 1 {
                        e[axis]
                    } else {
                        1.0 - e[axis]
                    }
                };
                f64::from(item.voxels[c]) * f(0) * f(1) * f(2)
            })
            .sum()
    }
}

/// One slice's weights of the in-slice interpolation ([`Trilin::in_slice`]).
#[derive(Debug, Clone, Copy)]
pub struct InSlice {
    /// No intermediate passes `2^32` (`VoxelW + FracW + WeightW <= 31`): 32-bit lanes.
    narrow: bool,
    w: u32,
    f: u32,
    ex: u32,
    ey: u32,
    fx: u32,
    fy: u32,
    half: u32,
}

impl InSlice {
    /// [`Trilin::row_in_slice`] of `N` anchors (`top`, `bot` at least `N + 1` voxels): the same
    /// three rounded lerps with the slice's weights made once.
    #[inline(always)]
    pub fn lanes<const N: usize>(&self, top: &[u16], bot: &[u16]) -> [u32; N] {
        let (t, b) = (&top[..N + 1], &bot[..N + 1]);
        let (w, f) = (self.w, self.f);
        let mut out = [0u32; N];
        if self.narrow {
            let (ex, ey, fx, fy, half) = (self.ex, self.ey, self.fx, self.fy, self.half);
            // An indexed loop of constant length, which the loop vectorizer makes whole vectors
            // of (`array::from_fn` stayed a call per element).
            let c = |v: u16| u32::from(v) << f;
            for i in 0..N {
                let p0 = (c(t[i]) * fx + c(t[i + 1]) * ex + half) >> w;
                let p1 = (c(b[i]) * fx + c(b[i + 1]) * ex + half) >> w;
                out[i] = (p0 * fy + p1 * ey + half) >> w;
            }
        } else {
            let lerp = |a: u64, b: u64, e: u32| {
                let e = u64::from(e);
                round_half_up(a * ((1 << w) - e) + b * e, w)
            };
            let c = |v: u16| u64::from(v) << f;
            for i in 0..N {
                let p0 = lerp(c(t[i]), c(t[i + 1]), self.ex);
                let p1 = lerp(c(b[i]), c(b[i + 1]), self.ex);
                out[i] = lerp(p0, p1, self.ey) as u32;
            }
        }
        out
    }
}

/// `rnd(x, s)`: round half up of `x / 2^s`.
#[inline(always)]
pub fn round_half_up(x: u64, s: u32) -> u64 {
    if s == 0 {
        x
    } else {
        (x + (1 << (s - 1))) >> s
    }
}

crate::item_by_item!(Trilin, TrilinIn => u32, |unit, item| unit.sample(item));

impl StreamCodec for TrilinConfig {
    type In = TrilinIn;
    type Out = u32;

    fn in_width(&self) -> u32 {
        8 * self.voxel_w + 3 * self.weight_w + 2
    }

    fn out_width(&self) -> u32 {
        self.sample_w()
    }

    fn pack_in(&self, item: &TrilinIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        for v in item.voxels {
            w.put(u64::from(v), self.voxel_w);
        }
        for x in item.weights {
            w.put(u64::from(x), self.weight_w);
        }
        w.put(item.mode as u64, 2);
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> u32 {
        BitReader::new(words).get(self.sample_w()) as u32
    }
}

// The RTL parameters of this unit (the RTL defaults are the model's `DEFAULT`).
crate::unit_config!(TrilinConfig, "cube5_trilin", DEFAULT, {
    "VoxelW" => voxel_w,
    "WeightW" => weight_w,
    "FracW" => frac_w,
    "Pipe" => pipe,
});

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_item(rng: &mut ChaCha8Rng, cfg: &TrilinConfig) -> TrilinIn {
        TrilinIn {
            voxels: std::array::from_fn(|_| rng.random_range(0..=cfg.voxel_max())),
            weights: std::array::from_fn(|_| rng.random_range(0..=cfg.weight_max())),
            mode: TrilinMode::from_bits(rng.random_range(0..4)),
        }
    }

    #[test]
    fn the_frames_trilin_latency_is_its_pipe_s() {
        // cube5_frame.regs.toml's TrilinLatency follows TrilinPipe (the frame's interpolators).
        use crate::regs::cube5_frame::{TRILIN_LATENCY, TRILIN_PIPE};
        let cfg = TrilinConfig {
            pipe: TRILIN_PIPE,
            ..TrilinConfig::DEFAULT
        };
        assert_eq!(cfg.latency(), TRILIN_LATENCY);
    }

    #[test]
    fn error_within_contract_bound() {
        for cfg in [
            TrilinConfig::NARROW,
            TrilinConfig::DEFAULT,
            TrilinConfig::WIDE,
        ] {
            let unit = Trilin::new(cfg).unwrap();
            let mut rng = ChaCha8Rng::seed_from_u64(7);
            let lsb = 1.0 / f64::from(1u32 << cfg.frac_w);
            for _ in 0..100_000 {
                let item = random_item(&mut rng, &cfg);
                let got = f64::from(unit.sample(&item)) * lsb;
                let err = (got - unit.reference(&item)).abs();
                let bound = if item.mode == TrilinMode::Select {
                    0.0
                } else {
                    1.5 * lsb
                };
                assert!(
                    err <= bound + 1e-9,
                    "{cfg:?} {item:?}: error {err} > {bound}"
                );
            }
        }
    }

    #[test]
    fn extremes() {
        let cfg = TrilinConfig::DEFAULT;
        let unit = Trilin::new(cfg).unwrap();
        let max = cfg.voxel_max();
        for mode in [TrilinMode::Lerp, TrilinMode::Half, TrilinMode::Select] {
            for w in [0, cfg.weight_max()] {
                let all = |v| TrilinIn {
                    voxels: [v; 8],
                    weights: [w; 3],
                    mode,
                };
                assert_eq!(unit.sample(&all(0)), 0);
                assert_eq!(unit.sample(&all(max)), max << cfg.frac_w);
            }
        }
        // Weight 0 selects corner 0, Select with max weight selects corner 7.
        let ramp = TrilinIn {
            voxels: [1, 2, 3, 4, 5, 6, 7, 8],
            weights: [0; 3],
            mode: TrilinMode::Lerp,
        };
        assert_eq!(unit.sample(&ramp), 1 << cfg.frac_w);
        let sel = TrilinIn {
            weights: [cfg.weight_max(); 3],
            mode: TrilinMode::Select,
            ..ramp
        };
        assert_eq!(unit.sample(&sel), 8 << cfg.frac_w);
        let half = TrilinIn {
            mode: TrilinMode::Half,
            ..ramp
        };
        assert_eq!(unit.sample(&half), (9 << cfg.frac_w) / 2);
    }

    /// The presets, the extreme widths, `extra`, and every weight width at 12-bit voxels.
    fn in_slice_configs(extra: &[TrilinConfig]) -> Vec<TrilinConfig> {
        [
            TrilinConfig::NARROW,
            TrilinConfig::DEFAULT,
            TrilinConfig::WIDE,
            TrilinConfig::new(16, 12, 8).unwrap(),
            TrilinConfig::new(4, 1, 0).unwrap(),
        ]
        .into_iter()
        .chain(extra.iter().copied())
        .chain((1..=12).map(|w| TrilinConfig::new(12, w, 4).unwrap()))
        .collect()
    }

    /// `row_in_slice` is `sample_in_slice` at every anchor of a row, in both lane widths, and so
    /// is `InSlice::lanes` (8 lanes and 1) with the same weights.
    #[test]
    fn row_in_slice_is_sample_in_slice_along_a_row() {
        for cfg in in_slice_configs(&[TrilinConfig::new(16, 7, 8).unwrap()]) {
            let unit = Trilin::new(cfg).unwrap();
            let mut rng = ChaCha8Rng::seed_from_u64(12);
            for _ in 0..200 {
                let n = rng.random_range(1..40);
                let mut voxel = || match rng.random_range(0..4) {
                    0 => 0,
                    1 => cfg.voxel_max() as u16,
                    _ => rng.random_range(0..=cfg.voxel_max()) as u16,
                };
                let top: Vec<u16> = (0..=n).map(|_| voxel()).collect();
                let bot: Vec<u16> = (0..=n).map(|_| voxel()).collect();
                let mut w = || match rng.random_range(0..4) {
                    0 => 0,
                    1 => cfg.weight_max(),
                    _ => rng.random_range(0..=cfg.weight_max()),
                };
                let (wx, wy) = (w(), w());
                let mut out = vec![0; n];
                unit.row_in_slice(&top, &bot, wx, wy, &mut out);
                let lanes = unit.in_slice(wx, wy);
                assert_eq!(lanes.lanes::<1>(&top, &bot), [out[0]], "{cfg:?} {wx} {wy}");
                if n >= 8 {
                    assert_eq!(
                        lanes.lanes::<8>(&top, &bot)[..],
                        out[..8],
                        "{cfg:?} {wx} {wy}"
                    );
                }
                for (i, &o) in out.iter().enumerate() {
                    let c = [top[i], top[i + 1], bot[i], bot[i + 1]].map(u32::from);
                    assert_eq!(
                        o,
                        unit.sample_in_slice(c, wx, wy),
                        "{cfg:?} {c:?} {wx} {wy}"
                    );
                }
            }
        }
    }

    /// `sample_in_slice` is `sample` of the frame's items (`Lerp`, `wz = 0`, upper corners 0).
    #[test]
    fn sample_in_slice_is_sample_of_a_lerp_item_in_one_slice() {
        for cfg in in_slice_configs(&[]) {
            let unit = Trilin::new(cfg).unwrap();
            let mut rng = ChaCha8Rng::seed_from_u64(11);
            for _ in 0..20_000 {
                let c: [u32; 4] = std::array::from_fn(|_| match rng.random_range(0..4) {
                    0 => 0,
                    1 => cfg.voxel_max(),
                    _ => rng.random_range(0..=cfg.voxel_max()),
                });
                let mut w = || match rng.random_range(0..4) {
                    0 => 0,
                    1 => cfg.weight_max(),
                    _ => rng.random_range(0..=cfg.weight_max()),
                };
                let (wx, wy) = (w(), w());
                let item = TrilinIn {
                    voxels: [c[0], c[1], c[2], c[3], 0, 0, 0, 0],
                    weights: [wx, wy, 0],
                    mode: TrilinMode::Lerp,
                };
                assert_eq!(
                    unit.sample_in_slice(c, wx, wy),
                    unit.sample(&item),
                    "{item:?}"
                );
            }
        }
    }

    #[test]
    fn config_validation() {
        assert!(TrilinConfig::new(3, 8, 4).is_err());
        assert!(TrilinConfig::new(12, 0, 4).is_err());
        assert!(TrilinConfig::new(12, 8, 9).is_err());
        assert!(TrilinConfig::new(12, 8, 4).is_ok());
    }

    #[test]
    fn packing_width_matches_contract_table() {
        assert_eq!(TrilinConfig::NARROW.in_width(), 84);
        assert_eq!(TrilinConfig::DEFAULT.in_width(), 122);
        assert_eq!(TrilinConfig::WIDE.in_width(), 160);
    }
}
