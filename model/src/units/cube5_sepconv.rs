//! The separable convolution stage (`cube5_sepconv`), written from `docs/numerics/sepconv.md`:
//! one 1-D 3-tap pass `{1 w 1}` or `{-1 0 1}` of a separable 3D filter (patent [205]); three
//! passes make the 3-pass Sobel or Gaussian filter.

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::{param_in, StreamCodec};
use crate::units::cube5_gradient::{round_half_up_signed, sign_extend};
// =================================================================================================
// cube5_sepconv
// =================================================================================================

/// Widths of one `cube5_sepconv` configuration (the RTL parameters of the same names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SepconvConfig {
    pub tap_w: u32,
    pub weight_frac_w: u32,
    pub out_shift: u32,
}

impl SepconvConfig {
    /// Taps are `v8` samples `U(8.2)` zero-extended; rounds back to tap units.
    pub const NARROW: Self = Self {
        tap_w: 11,
        weight_frac_w: 2,
        out_shift: 2,
    };
    /// Taps are `v12` samples `U(12.4)` zero-extended; exact.
    pub const DEFAULT: Self = Self {
        tap_w: 17,
        weight_frac_w: 4,
        out_shift: 0,
    };
    pub const WIDE: Self = Self {
        tap_w: 23,
        weight_frac_w: 6,
        out_shift: 3,
    };

    pub fn new(tap_w: u32, weight_frac_w: u32, out_shift: u32) -> Result<Self> {
        let cfg = Self {
            tap_w,
            weight_frac_w,
            out_shift,
        };
        cfg.validate()?;
        Ok(cfg)
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("sepconv: {what}")));
        param_in("TapW", self.tap_w, 4..=32).or_else(bad)?;
        param_in("WeightFracW", self.weight_frac_w, 0..=8).or_else(bad)?;
        if self.out_shift > self.weight_frac_w + 4 {
            return bad(format!(
                "OutShift {} outside 0..=WeightFracW+4 ({})",
                self.out_shift,
                self.weight_frac_w + 4
            ));
        }
        Ok(())
    }

    /// Bits of `w`, `U(4.WeightFracW)`.
    pub fn weight_w(&self) -> u32 {
        self.weight_frac_w + 4
    }

    /// Bits of the exact result.
    pub fn exact_w(&self) -> u32 {
        self.tap_w + self.weight_frac_w + 5
    }

    /// Bits of the output.
    pub fn out_w(&self) -> u32 {
        self.exact_w() - self.out_shift
    }

    pub fn tap_min(&self) -> i64 {
        -(1i64 << (self.tap_w - 1))
    }

    pub fn tap_max(&self) -> i64 {
        (1i64 << (self.tap_w - 1)) - 1
    }

    pub fn weight_max(&self) -> u32 {
        (1 << self.weight_w()) - 1
    }

    /// Raw `w` of a real weight, rounded to the nearest representable value and clamped.
    pub fn weight_from_f64(&self, w: f64) -> u32 {
        let raw = (w * f64::from(1u32 << self.weight_frac_w)).round();
        raw.clamp(0.0, f64::from(self.weight_max())) as u32
    }
}

/// The kernel of one item (the 1-bit `kernel` field).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SepconvKernel {
    /// `{1 w 1}`.
    Smooth = 0,
    /// `{-1 0 1}`.
    Diff = 1,
}

impl SepconvKernel {
    pub fn from_bits(bits: u32) -> Self {
        if bits & 1 == 0 {
            Self::Smooth
        } else {
            Self::Diff
        }
    }
}

/// One input item: taps at offsets -1, 0, +1 (`TapW`-bit two's complement) and the kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SepconvIn {
    pub taps: [i64; 3],
    pub kernel: SepconvKernel,
}

/// The golden model of `cube5_sepconv`: the configuration and the centre weight register.
#[derive(Debug, Clone)]
pub struct Sepconv {
    cfg: SepconvConfig,
    w: u32,
}

impl Sepconv {
    /// A stage with centre weight `w` (raw `U(4.WeightFracW)`), as after writing it to address 0.
    pub fn new(cfg: SepconvConfig, w: u32) -> Result<Self> {
        cfg.validate()?;
        let mut unit = Self { cfg, w: 0 };
        unit.set_weight(w)?;
        Ok(unit)
    }

    pub fn config(&self) -> SepconvConfig {
        self.cfg
    }

    pub fn weight(&self) -> u32 {
        self.w
    }

    pub fn set_weight(&mut self, w: u32) -> Result<()> {
        if w > self.cfg.weight_max() {
            return Err(ModelError::Config(format!(
                "sepconv: w {w} does not fit U(4.{}) (max {})",
                self.cfg.weight_frac_w,
                self.cfg.weight_max()
            )));
        }
        self.w = w;
        Ok(())
    }

    /// A write on the configuration port: address 0 takes `w` from the low `WeightW` data bits;
    /// every other address is ignored.
    pub fn write_config(&mut self, addr: u32, data: u32) {
        if addr & 0xf == 0 {
            self.w = data & self.cfg.weight_max();
        }
    }

    /// The configuration-port writes that load this unit's register into the RTL.
    pub fn config_writes(&self) -> Vec<(u32, Vec<u32>)> {
        vec![(0, vec![self.w])]
    }

    /// The exact result `y` (`ExactW` bits): the 3-tap dot product with the kernel's weights.
    pub fn exact(&self, item: &SepconvIn) -> i64 {
        let one = 1i64 << self.cfg.weight_frac_w;
        let weights = match item.kernel {
            SepconvKernel::Smooth => [one, i64::from(self.w), one],
            SepconvKernel::Diff => [-one, 0, one],
        };
        (0..3).map(|t| weights[t] * item.taps[t]).sum()
    }

    /// The output, `rnd_s(y, OutShift)`.
    pub fn convolve(&self, item: &SepconvIn) -> i64 {
        round_half_up_signed(self.exact(item), self.cfg.out_shift)
    }

    /// The f64 ideal in tap units: `a + w b + c` or `c - a` with `w` as a real.
    pub fn reference(&self, item: &SepconvIn) -> f64 {
        let [a, b, c] = item.taps.map(|t| t as f64);
        match item.kernel {
            SepconvKernel::Smooth => {
                a + f64::from(self.w) / f64::from(1u32 << self.cfg.weight_frac_w) * b + c
            }
            SepconvKernel::Diff => c - a,
        }
    }

    /// Tap units per output LSB.
    pub fn out_lsb(&self) -> f64 {
        f64::from(1u32 << self.cfg.out_shift) / f64::from(1u32 << self.cfg.weight_frac_w)
    }
}

// Reset: the weight register survives reset (docs/numerics/sepconv.md), so the default no-op.
crate::item_by_item!(Sepconv, SepconvIn => i64, |unit, item| unit.convolve(item));

impl StreamCodec for SepconvConfig {
    type In = SepconvIn;
    type Out = i64;

    fn in_width(&self) -> u32 {
        3 * self.tap_w + 1
    }

    fn out_width(&self) -> u32 {
        self.out_w()
    }

    fn pack_in(&self, item: &SepconvIn) -> Vec<u32> {
        let mask = (1u64 << self.tap_w) - 1;
        let mut w = BitWriter::new();
        for t in item.taps {
            w.put(t as u64 & mask, self.tap_w);
        }
        w.put(item.kernel as u64, 1);
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> i64 {
        sign_extend(BitReader::new(words).get(self.out_w()), self.out_w())
    }
}

// The RTL parameters of this unit (the RTL defaults are the model's `DEFAULT`).
crate::unit_config!(SepconvConfig, "cube5_sepconv", DEFAULT, {
    "TapW" => tap_w,
    "WeightFracW" => weight_frac_w,
    "OutShift" => out_shift,
});

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    // The Sobel cross-check runs three sepconv passes against the gradient unit's N26 scheme.
    use crate::units::cube5_gradient::{Gradient, GradientConfig, GradientMode};

    // ---------------------------------------------------------------------------------------------
    // cube5_sepconv
    // ---------------------------------------------------------------------------------------------

    const SEP_CONFIGS: [SepconvConfig; 3] = [
        SepconvConfig::NARROW,
        SepconvConfig::DEFAULT,
        SepconvConfig::WIDE,
    ];

    fn random_taps(rng: &mut ChaCha8Rng, cfg: &SepconvConfig) -> SepconvIn {
        SepconvIn {
            taps: std::array::from_fn(|_| rng.random_range(cfg.tap_min()..=cfg.tap_max())),
            kernel: SepconvKernel::from_bits(rng.random_range(0..2)),
        }
    }

    #[test]
    fn sepconv_error_within_contract_bound_and_output_fits() {
        for cfg in SEP_CONFIGS {
            let mut rng = ChaCha8Rng::seed_from_u64(9);
            for w in [0, 1, cfg.weight_max() / 3, cfg.weight_max()] {
                let unit = Sepconv::new(cfg, w).unwrap();
                let bound = if cfg.out_shift == 0 { 0.0 } else { 0.5 };
                let half = 1i64 << (cfg.out_w() - 1);
                for _ in 0..20_000 {
                    let item = random_taps(&mut rng, &cfg);
                    let out = unit.convolve(&item);
                    assert!((-half..half).contains(&out));
                    let err = out as f64 - unit.reference(&item) / unit.out_lsb();
                    assert!(err.abs() <= bound + 1e-9, "{cfg:?} {item:?}: {err}");
                }
            }
        }
    }

    #[test]
    fn sepconv_extremes_fit_the_output() {
        for cfg in SEP_CONFIGS {
            let unit = Sepconv::new(cfg, cfg.weight_max()).unwrap();
            let half = 1i64 << (cfg.out_w() - 1);
            for t in [cfg.tap_min(), cfg.tap_max()] {
                for kernel in [SepconvKernel::Smooth, SepconvKernel::Diff] {
                    for taps in [[t; 3], [t, -t - 1, t], [-t - 1, t, t]] {
                        let out = unit.convolve(&SepconvIn { taps, kernel });
                        assert!((-half..half).contains(&out), "{cfg:?} {taps:?} {out}");
                    }
                }
            }
        }
    }

    #[test]
    fn sepconv_rounds_half_up() {
        let cfg = SepconvConfig::NARROW; // F = 2, OutShift = 2: y = 4a + w b + 4c, out = rnd_s(y, 2)
        let unit = Sepconv::new(cfg, 2).unwrap(); // w = 0.5
        let item = |b| SepconvIn {
            taps: [0, b, 0],
            kernel: SepconvKernel::Smooth,
        };
        assert_eq!(unit.convolve(&item(1)), 1); // 2/4 = 0.5 -> 1
        assert_eq!(unit.convolve(&item(-1)), 0); // -0.5 -> 0
        assert_eq!(unit.convolve(&item(-3)), -1); // -1.5 -> -1
        assert_eq!(unit.convolve(&item(3)), 2); // 1.5 -> 2
    }

    #[test]
    fn sepconv_config_port_and_validation() {
        let cfg = SepconvConfig::DEFAULT;
        let mut unit = Sepconv::new(cfg, 32).unwrap();
        unit.write_config(1, 7);
        assert_eq!(unit.weight(), 32, "address 1 is ignored");
        unit.write_config(0, 0xffff_ff05);
        assert_eq!(unit.weight(), 0x05, "data bits above WeightW are ignored");
        assert_eq!(unit.config_writes(), vec![(0, vec![5])]);
        assert!(Sepconv::new(cfg, cfg.weight_max() + 1).is_err());
        assert!(SepconvConfig::new(3, 4, 0).is_err());
        assert!(SepconvConfig::new(33, 4, 0).is_err());
        assert!(SepconvConfig::new(17, 9, 0).is_err());
        assert!(SepconvConfig::new(17, 4, 9).is_err());
        assert!(SepconvConfig::new(17, 4, 8).is_ok());
        assert_eq!(cfg.weight_from_f64(2.0), 32);
        assert_eq!(cfg.weight_from_f64(99.0), cfg.weight_max());
        assert_eq!(
            (
                SepconvConfig::NARROW.in_width(),
                SepconvConfig::NARROW.out_w()
            ),
            (34, 16)
        );
        assert_eq!(
            (
                SepconvConfig::DEFAULT.in_width(),
                SepconvConfig::DEFAULT.out_w()
            ),
            (52, 26)
        );
        assert_eq!(
            (SepconvConfig::WIDE.in_width(), SepconvConfig::WIDE.out_w()),
            (70, 31)
        );
    }

    /// Three passes along x, y, z over a 3x3x3 block (the last pass yields one value).
    fn three_passes(block: &[u32; 27], axis: usize, kernels: [SepconvKernel; 3], w: u32) -> i64 {
        // Pass p runs along axis order[p]; the diff axis goes first.
        let order = [axis, (axis + 1) % 3, (axis + 2) % 3];
        let mut cur: Vec<i64> = block.iter().map(|&s| i64::from(s)).collect();
        let mut dims = [3usize; 3];
        let mut tap_w = GradientConfig::DEFAULT.sample_w() + 1;
        for p in 0..3 {
            let cfg = SepconvConfig::new(tap_w, 0, 0).unwrap();
            let unit = Sepconv::new(cfg, w).unwrap();
            let a = order[p];
            let mut next_dims = dims;
            next_dims[a] = 1;
            let idx = |d: [usize; 3], dims: [usize; 3]| d[0] + dims[0] * (d[1] + dims[1] * d[2]);
            let mut next = vec![0i64; next_dims.iter().product()];
            for z in 0..next_dims[2] {
                for y in 0..next_dims[1] {
                    for x in 0..next_dims[0] {
                        let taps = std::array::from_fn(|t| {
                            let mut d = [x, y, z];
                            d[a] = t;
                            cur[idx(d, dims)]
                        });
                        next[idx([x, y, z], next_dims)] = unit.convolve(&SepconvIn {
                            taps,
                            kernel: kernels[p],
                        });
                    }
                }
            }
            cur = next;
            dims = next_dims;
            tap_w = cfg.out_w();
        }
        cur[0]
    }

    #[test]
    fn three_sepconv_passes_are_the_n26_sobel_gradient() {
        let cfg = GradientConfig::DEFAULT;
        let grad = Gradient::new(cfg).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(10);
        use SepconvKernel::{Diff, Smooth};
        for _ in 0..2_000 {
            let item = crate::units::cube5_gradient::GradientIn {
                samples: std::array::from_fn(|_| rng.random_range(0..=cfg.sample_max())),
                dx: rng.random_range(cfg.step_min()..=cfg.step_max()),
                dy: rng.random_range(cfg.step_min()..=cfg.step_max()),
                mode: GradientMode::N26,
            };
            let g = grad.components(&item);
            for (axis, want) in g.iter().enumerate() {
                let got = three_passes(&item.samples, axis, [Diff, Smooth, Smooth], 2);
                assert_eq!(got, *want, "axis {axis}");
            }
        }
    }

    #[test]
    fn three_smooth_passes_of_a_constant_scale_by_the_kernel_sum_cubed() {
        let block = [1000u32; 27];
        use SepconvKernel::Smooth;
        for w in [0, 1, 2, 6, 15] {
            let got = three_passes(&block, 0, [Smooth; 3], w);
            assert_eq!(got, 1000 * i64::from(w + 2).pow(3));
        }
    }
}
