//! Gradient estimation (`cube5_gradient`), written from `docs/numerics/gradient.md`: central
//! differences on the 3x3x3 block of interpolated samples of the previous, current and next slice
//! (cube3-paper §4, the 6-, 10- and 26-neighbourhood schemes), plus a magnitude estimate
//! `(30 max + 13 mid + 9 min) / 32`.

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::{param_in, StreamCodec};

/// `rnd_s(x, s)`: round half up (toward +infinity) of `x / 2^s` for signed `x`.
pub fn round_half_up_signed(x: i64, s: u32) -> i64 {
    if s == 0 {
        x
    } else {
        (x + (1i64 << (s - 1))) >> s
    }
}

/// Sign-extends the low `width` bits of `raw`.
pub(crate) fn sign_extend(raw: u64, width: u32) -> i64 {
    let shift = 64 - width;
    ((raw << shift) as i64) >> shift
}

/// The `N6` components `16 (s(+1) - s(-1))` along x, y and z, raw, from the six orthogonal
/// neighbours `[x-, x+, y-, y+, z-, z+]` (the mode `N6` of `Gradient::components`).
#[inline]
pub fn n6_components(n: [i64; 6]) -> [i64; 3] {
    [16 * (n[1] - n[0]), 16 * (n[3] - n[2]), 16 * (n[5] - n[4])]
}

// =================================================================================================
// cube5_gradient
// =================================================================================================

/// Widths of one `cube5_gradient` configuration (the RTL parameters of the same names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GradientConfig {
    pub voxel_w: u32,
    pub frac_w: u32,
    pub weight_w: u32,
}

impl GradientConfig {
    pub const NARROW: Self = Self {
        voxel_w: 8,
        frac_w: 2,
        weight_w: 6,
    };
    pub const DEFAULT: Self = Self {
        voxel_w: 12,
        frac_w: 4,
        weight_w: 8,
    };
    pub const WIDE: Self = Self {
        voxel_w: 16,
        frac_w: 6,
        weight_w: 10,
    };

    pub fn new(voxel_w: u32, frac_w: u32, weight_w: u32) -> Result<Self> {
        let cfg = Self {
            voxel_w,
            frac_w,
            weight_w,
        };
        cfg.validate()?;
        Ok(cfg)
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("gradient: {what}")));
        param_in("VoxelW", self.voxel_w, 4..=16).or_else(bad)?;
        param_in("FracW", self.frac_w, 0..=8).or_else(bad)?;
        param_in("WeightW", self.weight_w, 2..=12).or_else(bad)?;
        Ok(())
    }

    /// Bits of one sample, `U(VoxelW.FracW)`.
    pub fn sample_w(&self) -> u32 {
        self.voxel_w + self.frac_w
    }

    /// Bits of each output field: components `S(VoxelW.(FracW+5))`, magnitude `U(VoxelW.(FracW+5))`.
    pub fn grad_w(&self) -> u32 {
        self.voxel_w + self.frac_w + 5
    }

    /// Bits of `dx`, `dy`, `S(2.WeightW)`.
    pub fn step_w(&self) -> u32 {
        self.weight_w + 2
    }

    pub fn sample_max(&self) -> u32 {
        (1 << self.sample_w()) - 1
    }

    /// Range of the raw step fields (the whole two's complement range is legal input).
    pub fn step_min(&self) -> i32 {
        -(1 << (self.weight_w + 1))
    }

    pub fn step_max(&self) -> i32 {
        (1 << (self.weight_w + 1)) - 1
    }

    /// Voxel units per output LSB.
    pub fn lsb(&self) -> f64 {
        1.0 / f64::from(1u32 << (self.frac_w + 5))
    }
}

/// The neighbourhood schemes of the 2-bit `mode` field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GradientMode {
    N6 = 0,
    N10 = 1,
    N26 = 2,
    /// Reserved encoding; behaves as `N6` by contract.
    Reserved = 3,
}

impl GradientMode {
    pub fn from_bits(bits: u32) -> Self {
        match bits & 3 {
            0 => Self::N6,
            1 => Self::N10,
            2 => Self::N26,
            _ => Self::Reserved,
        }
    }
}

/// Index of offset `(di, dj, dk)` (each in -1..=1) in the block: `(di+1) + 3(dj+1) + 9(dk+1)`.
pub const fn block_index(di: i32, dj: i32, dk: i32) -> usize {
    ((di + 1) + 3 * (dj + 1) + 9 * (dk + 1)) as usize
}

/// Offset `(di, dj, dk)` of block index `i` (0..27): the inverse of `block_index`.
pub const fn block_offset(i: usize) -> (i32, i32, i32) {
    let i = i as i32;
    (i % 3 - 1, (i / 3) % 3 - 1, i / 9 - 1)
}

/// A block of samples at `max` wherever `f(di, dj, dk)` holds and at 0 elsewhere: the extreme
/// stimuli of the unit tests and the co-simulation.
pub fn block_where(max: u32, f: impl Fn(i32, i32, i32) -> bool) -> [u32; 27] {
    std::array::from_fn(|i| {
        let (di, dj, dk) = block_offset(i);
        if f(di, dj, dk) {
            max
        } else {
            0
        }
    })
}

/// One input item: the 3x3x3 sample block (raw `U(VoxelW.FracW)`), the ray steps `dx`, `dy` (raw
/// `S(2.WeightW)`), the mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GradientIn {
    pub samples: [u32; 27],
    pub dx: i32,
    pub dy: i32,
    pub mode: GradientMode,
}

impl GradientIn {
    /// The raw sample at offset `(di, dj, dk)`.
    pub fn at(&self, di: i32, dj: i32, dk: i32) -> i64 {
        i64::from(self.samples[block_index(di, dj, dk)])
    }
}

/// One output item, raw: components `S(VoxelW.(FracW+5))`, magnitude `U(VoxelW.(FracW+5))`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GradientOut {
    pub gx: i32,
    pub gy: i32,
    pub gz: i32,
    pub mag: u32,
}

/// The f64 ideal: components in voxel units per sample spacing, and their Euclidean norm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GradientRef {
    pub g: [f64; 3],
    pub norm: f64,
}

/// The golden model of `cube5_gradient`.
#[derive(Debug, Clone)]
pub struct Gradient {
    cfg: GradientConfig,
}

/// `N26` weight of an offset across the difference axis: 2 on the axis, 1 off it.
fn n26_weight(d: i32) -> i64 {
    if d == 0 {
        2
    } else {
        1
    }
}

impl Gradient {
    pub fn new(cfg: GradientConfig) -> Result<Self> {
        cfg.validate()?;
        Ok(Self { cfg })
    }

    pub fn config(&self) -> GradientConfig {
        self.cfg
    }

    /// `(ex, px)`: the clamped step magnitude and the partner offset in the next plane.
    fn step(&self, d: i32) -> (i64, i32) {
        let one = 1i64 << self.cfg.weight_w;
        let e = i64::from(d).abs().min(one);
        (e, if d < 0 { 1 } else { -1 })
    }

    /// `A - B` of the contract (`N10`), exact, on the scale `2^(FracW + 2 WeightW)`.
    pub fn n10_difference(&self, item: &GradientIn) -> i64 {
        let one = 1i64 << self.cfg.weight_w;
        let (ex, px) = self.step(item.dx);
        let (ey, py) = self.step(item.dy);
        let wx = [one - ex, ex];
        let wy = [one - ey, ey];
        let mut a = 0;
        let mut b = 0;
        for u in 0..2 {
            for v in 0..2 {
                let w = wx[u as usize] * wy[v as usize];
                a += item.at(u * px, v * py, 1) * w;
                b += item.at(-u * px, -v * py, -1) * w;
            }
        }
        a - b
    }

    /// The three components, raw.
    pub fn components(&self, item: &GradientIn) -> [i64; 3] {
        let n6 = n6_components([
            item.at(-1, 0, 0),
            item.at(1, 0, 0),
            item.at(0, -1, 0),
            item.at(0, 1, 0),
            item.at(0, 0, -1),
            item.at(0, 0, 1),
        ]);
        match item.mode {
            GradientMode::N6 | GradientMode::Reserved => n6,
            GradientMode::N10 => {
                let s = 2 * self.cfg.weight_w - 4;
                [
                    n6[0],
                    n6[1],
                    round_half_up_signed(self.n10_difference(item), s),
                ]
            }
            GradientMode::N26 => {
                let mut g = [0i64; 3];
                for p in -1..=1 {
                    for q in -1..=1 {
                        let w = n26_weight(p) * n26_weight(q);
                        g[0] += w * (item.at(1, p, q) - item.at(-1, p, q));
                        g[1] += w * (item.at(p, 1, q) - item.at(p, -1, q));
                        g[2] += w * (item.at(p, q, 1) - item.at(p, q, -1));
                    }
                }
                g
            }
        }
    }

    /// `mag = rnd(30 M + 13 m + 9 n, 5)` of the sorted component magnitudes.
    #[inline]
    pub fn magnitude(&self, g: [i64; 3]) -> u32 {
        let mut a = g.map(i64::abs);
        a.sort_unstable_by(|x, y| y.cmp(x));
        let sum = 30 * a[0] + 13 * a[1] + 9 * a[2];
        round_half_up_signed(sum, 5) as u32
    }

    /// One output item.
    pub fn gradient(&self, item: &GradientIn) -> GradientOut {
        self.output(self.components(item))
    }

    /// The output item of the raw components `g`: the components and their magnitude.
    #[inline]
    pub fn output(&self, g: [i64; 3]) -> GradientOut {
        GradientOut {
            gx: g[0] as i32,
            gy: g[1] as i32,
            gz: g[2] as i32,
            mag: self.magnitude(g),
        }
    }

    /// The f64 ideal with the same weights, from the samples as reals (voxel units).
    pub fn reference(&self, item: &GradientIn) -> GradientRef {
        let unit = f64::from(1u32 << self.cfg.frac_w);
        let s = |di, dj, dk| item.at(di, dj, dk) as f64 / unit;
        let half_diff = |p: f64, m: f64| (p - m) / 2.0;
        let n6 = [
            half_diff(s(1, 0, 0), s(-1, 0, 0)),
            half_diff(s(0, 1, 0), s(0, -1, 0)),
            half_diff(s(0, 0, 1), s(0, 0, -1)),
        ];
        let g = match item.mode {
            GradientMode::N6 | GradientMode::Reserved => n6,
            GradientMode::N10 => {
                let one = f64::from(1u32 << self.cfg.weight_w);
                let (ex, px) = self.step(item.dx);
                let (ey, py) = self.step(item.dy);
                let (fx, fy) = (ex as f64 / one, ey as f64 / one);
                let bilerp = |sx: i32, sy: i32, dk: i32| {
                    let lx = |j: i32| s(0, j, dk) * (1.0 - fx) + s(sx, j, dk) * fx;
                    lx(0) * (1.0 - fy) + lx(sy) * fy
                };
                [
                    n6[0],
                    n6[1],
                    half_diff(bilerp(px, py, 1), bilerp(-px, -py, -1)),
                ]
            }
            GradientMode::N26 => {
                // Face 1, edge 1/2, corner 1/4; the weights of one face sum to 4.
                let w = |p: i32, q: i32| match p.abs() + q.abs() {
                    0 => 1.0,
                    1 => 0.5,
                    _ => 0.25,
                };
                let mut g = [0.0; 3];
                for p in -1..=1 {
                    for q in -1..=1 {
                        g[0] += w(p, q) * (s(1, p, q) - s(-1, p, q)) / 8.0;
                        g[1] += w(p, q) * (s(p, 1, q) - s(p, -1, q)) / 8.0;
                        g[2] += w(p, q) * (s(p, q, 1) - s(p, q, -1)) / 8.0;
                    }
                }
                g
            }
        };
        GradientRef {
            g,
            norm: (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt(),
        }
    }
}

crate::item_by_item!(Gradient, GradientIn => GradientOut, |unit, item| unit.gradient(item));

impl StreamCodec for GradientConfig {
    type In = GradientIn;
    type Out = GradientOut;

    fn in_width(&self) -> u32 {
        27 * self.sample_w() + 2 * self.step_w() + 2
    }

    fn out_width(&self) -> u32 {
        4 * self.grad_w()
    }

    fn pack_in(&self, item: &GradientIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        for s in item.samples {
            w.put(u64::from(s), self.sample_w());
        }
        let step_mask = (1u64 << self.step_w()) - 1;
        w.put(item.dx as i64 as u64 & step_mask, self.step_w());
        w.put(item.dy as i64 as u64 & step_mask, self.step_w());
        w.put(item.mode as u64, 2);
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> GradientOut {
        let mut r = BitReader::new(words);
        let gw = self.grad_w();
        let mut comp = || sign_extend(r.get(gw), gw) as i32;
        let (gx, gy, gz) = (comp(), comp(), comp());
        GradientOut {
            gx,
            gy,
            gz,
            mag: r.get(gw) as u32,
        }
    }
}

// The RTL parameters of this unit (the RTL defaults are the model's `DEFAULT`).
crate::unit_config!(GradientConfig, "cube5_gradient", DEFAULT, {
    "VoxelW" => voxel_w,
    "FracW" => frac_w,
    "WeightW" => weight_w,
});

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const CONFIGS: [GradientConfig; 3] = [
        GradientConfig::NARROW,
        GradientConfig::DEFAULT,
        GradientConfig::WIDE,
    ];

    fn random_item(rng: &mut ChaCha8Rng, cfg: &GradientConfig) -> GradientIn {
        GradientIn {
            samples: std::array::from_fn(|_| rng.random_range(0..=cfg.sample_max())),
            dx: rng.random_range(cfg.step_min()..=cfg.step_max()),
            dy: rng.random_range(cfg.step_min()..=cfg.step_max()),
            mode: GradientMode::from_bits(rng.random_range(0..4)),
        }
    }

    /// Samples of the linear field `c0 + a*di + b*dj + c*dk` (raw units), which must stay in range.
    fn ramp(c0: i64, a: i64, b: i64, c: i64) -> [u32; 27] {
        std::array::from_fn(|i| {
            let (di, dj, dk) = block_offset(i);
            (c0 + a * i64::from(di) + b * i64::from(dj) + c * i64::from(dk)) as u32
        })
    }

    #[test]
    fn error_within_contract_bound() {
        for cfg in CONFIGS {
            let unit = Gradient::new(cfg).unwrap();
            let mut rng = ChaCha8Rng::seed_from_u64(3);
            let lsb = cfg.lsb();
            for _ in 0..100_000 {
                let item = random_item(&mut rng, &cfg);
                let out = unit.gradient(&item);
                let r = unit.reference(&item);
                let got = [out.gx, out.gy, out.gz].map(|g| f64::from(g) * lsb);
                for (axis, (g, ideal)) in got.iter().zip(r.g).enumerate() {
                    let bound = if item.mode == GradientMode::N10 && axis == 2 {
                        0.5 * lsb
                    } else {
                        0.0
                    };
                    let err = (g - ideal).abs();
                    assert!(err <= bound + 1e-12, "{cfg:?} {item:?} axis {axis}: {err}");
                }
                // The estimate against the Euclidean norm of the output components.
                let norm = got.iter().map(|g| g * g).sum::<f64>().sqrt();
                let est = f64::from(out.mag) * lsb;
                assert!(est >= norm * (30.0 / 32.0) - 0.5 * lsb - 1e-9);
                assert!(est <= norm * (1150f64.sqrt() / 32.0) + 0.5 * lsb + 1e-9);
            }
        }
    }

    #[test]
    fn linear_fields_give_their_slope() {
        // A field linear in the block's (ray-space) offsets with slopes (a, b, c) per sample step.
        // N6 and N26 return the slopes. N10 resamples the next and previous planes at the
        // orthogonal point, (-dx, -dy) and (+dx, +dy), so its z is the volume's z derivative
        // c - a dx - b dy. Raw units: slope * 2^5, here exact because every step is a multiple of 8.
        let cfg = GradientConfig::DEFAULT;
        let unit = Gradient::new(cfg).unwrap();
        let (a, b, c) = (1000i64, -700i64, 300i64);
        let samples = ramp(30_000, a, b, c);
        for (dx, dy) in [(0, 0), (256, -256), (-77, 190), (-256, 256)] {
            for mode in [GradientMode::N6, GradientMode::N10, GradientMode::N26] {
                let out = unit.gradient(&GradientIn {
                    samples,
                    dx,
                    dy,
                    mode,
                });
                assert_eq!((out.gx, out.gy), (32_000, -22_400), "{mode:?}");
                let gz = if mode == GradientMode::N10 {
                    32 * (256 * c - a * i64::from(dx) - b * i64::from(dy)) / 256
                } else {
                    32 * c
                };
                assert_eq!(i64::from(out.gz), gz, "{mode:?} {dx} {dy}");
            }
        }
    }

    #[test]
    fn n10_uses_the_orthogonal_point_of_a_sheared_field() {
        // Samples of a field that varies only along volume x, seen on rays that step by
        // (dx, dy) = (0.5, -0.25) per slice: the sample at ray offset (di, dj) in slice dk sits at
        // volume x = di + 0.5 dk. A field f = 64 x (in raw units) then reads 64 (di + 0.5 dk).
        let cfg = GradientConfig::DEFAULT;
        let unit = Gradient::new(cfg).unwrap();
        let samples: [u32; 27] = std::array::from_fn(|i| {
            let (di, dk) = (i as i64 % 3 - 1, i as i64 / 9 - 1);
            (10_000 + 64 * (2 * di + dk) / 2) as u32
        });
        let base = GradientIn {
            samples,
            dx: 128,
            dy: -64,
            mode: GradientMode::N6,
        };
        // N6 differentiates along the ray and sees the x slope in z; N10 does not.
        assert_eq!(unit.gradient(&base).gz, 32 * 32);
        let n10 = unit.gradient(&GradientIn {
            mode: GradientMode::N10,
            ..base
        });
        assert_eq!((n10.gx, n10.gz), (64 * 32, 0));
    }

    #[test]
    fn n10_with_zero_step_is_n6_and_reserved_is_n6() {
        let cfg = GradientConfig::NARROW;
        let unit = Gradient::new(cfg).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..10_000 {
            let mut item = random_item(&mut rng, &cfg);
            item.mode = GradientMode::N6;
            let n6 = unit.gradient(&item);
            for (mode, dx, dy) in [
                (GradientMode::N10, 0, 0),
                (GradientMode::Reserved, item.dx, item.dy),
            ] {
                assert_eq!(
                    unit.gradient(&GradientIn {
                        mode,
                        dx,
                        dy,
                        ..item
                    }),
                    n6
                );
            }
        }
    }

    #[test]
    fn centre_sample_is_never_read() {
        let cfg = GradientConfig::DEFAULT;
        let unit = Gradient::new(cfg).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        for _ in 0..10_000 {
            let item = random_item(&mut rng, &cfg);
            let mut other = item;
            other.samples[13] ^= cfg.sample_max();
            assert_eq!(unit.gradient(&item), unit.gradient(&other));
        }
    }

    #[test]
    fn steps_beyond_one_voxel_clamp() {
        let cfg = GradientConfig::NARROW;
        let unit = Gradient::new(cfg).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let one = 1 << cfg.weight_w;
        for _ in 0..10_000 {
            let mut item = random_item(&mut rng, &cfg);
            item.mode = GradientMode::N10;
            let clamp = |d: i32| d.clamp(-one, one);
            let clamped = GradientIn {
                dx: clamp(item.dx),
                dy: clamp(item.dy),
                ..item
            };
            assert_eq!(unit.gradient(&item), unit.gradient(&clamped));
        }
    }

    /// Blocks at the extremes: all 0, all max, and max wherever a predicate on the offset holds.
    fn extreme_blocks(max: u32) -> Vec<[u32; 27]> {
        vec![
            [0; 27],
            [max; 27],
            block_where(max, |di, dj, dk| di + dj + dk > 0),
            block_where(max, |di, dj, dk| di + dj + dk < 0),
            block_where(max, |di, dj, dk| di >= 0 && dj >= 0 && dk >= 0),
            block_where(max, |di, dj, dk| di > 0 || dj > 0 || dk > 0),
            block_where(max, |di, dj, dk| di < 0 || dj < 0 || dk < 0),
            block_where(max, |di, dj, dk| (di + dj + dk) & 1 == 0),
        ]
    }

    #[test]
    fn extremes_stay_in_range() {
        for cfg in CONFIGS {
            let unit = Gradient::new(cfg).unwrap();
            let max = cfg.sample_max();
            let bound = 16 * i64::from(max);
            for samples in extreme_blocks(max) {
                for mode in [GradientMode::N6, GradientMode::N10, GradientMode::N26] {
                    for (dx, dy) in [(0, 0), (cfg.step_min(), cfg.step_max()), (-1, 1)] {
                        let out = unit.gradient(&GradientIn {
                            samples,
                            dx,
                            dy,
                            mode,
                        });
                        for g in [out.gx, out.gy, out.gz] {
                            assert!(i64::from(g).abs() <= bound, "{cfg:?} {mode:?} {g}");
                        }
                        assert!(i64::from(out.mag) <= 26 * i64::from(max));
                    }
                }
            }
            // The largest components and magnitude: a full step along all three axes.
            let samples = extreme_blocks(max)[5];
            let out = unit.gradient(&GradientIn {
                samples,
                dx: 0,
                dy: 0,
                mode: GradientMode::N6,
            });
            assert_eq!([out.gx, out.gy, out.gz], [16 * max as i32; 3]);
            assert_eq!(out.mag, 26 * max);
            assert!(u64::from(out.mag) < 1 << cfg.grad_w());
        }
    }

    #[test]
    fn n10_rounds_half_up_on_the_output_scale() {
        // WeightW = 6: gz = rnd_s(A - B, 8). With dx = 2 (1/32) and dy = 0 the x partner weighs
        // 2 * 64 = 128 = 2^7, so a single partner sample of 1 lands exactly on half an LSB.
        let cfg = GradientConfig::NARROW;
        let unit = Gradient::new(cfg).unwrap();
        let mut samples = [0u32; 27];
        samples[block_index(-1, 0, 1)] = 1; // A - B = +128: +1/2 LSB
        let item = GradientIn {
            samples,
            dx: 2,
            dy: 0,
            mode: GradientMode::N10,
        };
        assert_eq!(unit.gradient(&item).gz, 1, "+1/2 rounds up");
        let mut below = [0u32; 27];
        below[block_index(1, 0, -1)] = 1; // A - B = -128: -1/2 rounds up to 0.
        assert_eq!(
            unit.gradient(&GradientIn {
                samples: below,
                ..item
            })
            .gz,
            0,
            "-1/2 rounds up"
        );
    }

    #[test]
    fn magnitude_estimate_worst_cases() {
        let unit = Gradient::new(GradientConfig::DEFAULT).unwrap();
        assert_eq!(unit.magnitude([3200, 0, 0]), 3000);
        assert_eq!(unit.magnitude([0, -3200, 0]), 3000);
        assert_eq!(unit.magnitude([-3200, 3200, 3200]), 5200);
        assert_eq!(unit.magnitude([16, 16, 0]), 22); // (480 + 208) / 32 = 21.5 rounds up
        assert_eq!(unit.magnitude([0, 0, 0]), 0);
    }

    #[test]
    fn gradient_config_validation() {
        assert!(GradientConfig::new(3, 4, 8).is_err());
        assert!(GradientConfig::new(17, 4, 8).is_err());
        assert!(GradientConfig::new(12, 9, 8).is_err());
        assert!(GradientConfig::new(12, 4, 1).is_err());
        assert!(GradientConfig::new(12, 4, 13).is_err());
        assert!(GradientConfig::new(12, 4, 2).is_ok());
    }

    #[test]
    fn gradient_packing_width_matches_contract_table() {
        assert_eq!(
            (
                GradientConfig::NARROW.in_width(),
                GradientConfig::NARROW.out_width()
            ),
            (288, 60)
        );
        assert_eq!(
            (
                GradientConfig::DEFAULT.in_width(),
                GradientConfig::DEFAULT.out_width()
            ),
            (454, 84)
        );
        assert_eq!(
            (
                GradientConfig::WIDE.in_width(),
                GradientConfig::WIDE.out_width()
            ),
            (620, 108)
        );
    }

    #[test]
    fn gradient_output_codec_round_trips_signs() {
        let cfg = GradientConfig::NARROW;
        let out = GradientOut {
            gx: -16 * 1023,
            gy: 16 * 1023,
            gz: -1,
            mag: 26 * 1023,
        };
        let gw = cfg.grad_w();
        let mut w = BitWriter::new();
        for g in [out.gx, out.gy, out.gz] {
            w.put(g as i64 as u64 & ((1 << gw) - 1), gw);
        }
        w.put(u64::from(out.mag), gw);
        assert_eq!(cfg.unpack_out(&w.finish(4 * gw)), out);
    }
}
