//! The 3-pass separable pre-filter over a volume (patent [204]-[205]; docs/numerics/sepconv.md,
//! *Over a volume: the 3-pass pre-filter*): one `cube5_sepconv` runs three passes, along x, then
//! y, then z, each over the output of the pass before, with the `{1 w 1}` kernel normalised by
//! its `OutShift`. `volume.prefilter` chooses the kernel; the frame then renders the filtered
//! volume. The model here is the unit's model ([`Sepconv`]) fed the items the RTL is fed, so the
//! RTL pre-pass (`cube5_tb::prefilter`) is checked against exactly these values.

use crate::error::{ModelError, Result};
use crate::units::cube5_sepconv::{Sepconv, SepconvConfig, SepconvIn, SepconvKernel};
use crate::volume::Volume;

/// The kernels a scene can ask for (`volume.prefilter`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Prefilter {
    /// No pre-pass: the frame renders the volume as the memory holds it.
    #[default]
    None,
    /// The binomial kernel `{1 2 1} / 4` along each axis: the 3x3x3 binomial, a Gaussian of
    /// variance 1/2 voxel^2 per axis ([205]: "changing the x-weights to {1 w 1}").
    Gauss,
    /// `{1 6 1} / 8` along each axis: the sampled Gaussian of `sigma = 0.53` (`w = 6 =
    /// exp(1 / (2 sigma^2))`), variance 1/4 voxel^2: a lighter smoothing.
    GaussNarrow,
}

/// The names a scene spells the kernels with, in [`Prefilter`] order.
pub const PREFILTER_NAMES: [&str; 3] = ["none", "gauss", "gauss-narrow"];

/// The stage's latency in cycles (docs/numerics/sepconv.md, *Timing*).
pub const SEPCONV_LATENCY: u64 = 2;

/// The axes of the three passes, in order.
pub const PASS_AXES: [char; 3] = ['x', 'y', 'z'];

impl Prefilter {
    /// The kernel a scene names (`volume.prefilter`); `None` for a name that is not one.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "none" => Some(Self::None),
            "gauss" => Some(Self::Gauss),
            "gauss-narrow" => Some(Self::GaussNarrow),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::None => PREFILTER_NAMES[0],
            Self::Gauss => PREFILTER_NAMES[1],
            Self::GaussNarrow => PREFILTER_NAMES[2],
        }
    }

    /// The centre weight `w` of `{1 w 1}` (an integer: `WeightFracW = 0`), or `None` without a
    /// pre-pass.
    pub fn weight(self) -> Option<u32> {
        match self {
            Self::None => None,
            Self::Gauss => Some(2),
            Self::GaussNarrow => Some(6),
        }
    }

    /// The kernel as it is written, e.g. `{1 2 1}/4`.
    pub fn describe(self) -> String {
        match self.weight() {
            None => "none".into(),
            Some(w) => format!("{{1 {w} 1}}/{}", w + 2),
        }
    }

    /// The `cube5_sepconv` configuration that runs this pre-pass over `voxel_w`-bit voxels:
    /// taps are the voxels zero-extended (`TapW = VoxelW + 1`, at least the unit's 4), the weight an integer
    /// (`WeightFracW = 0`), and the output normalised by the kernel's sum `w + 2`, a power of
    /// two (`OutShift = log2(w + 2)`), so every pass returns voxels of the same width.
    pub fn sepconv_config(self, voxel_w: u32) -> Option<SepconvConfig> {
        let w = self.weight()?;
        Some(SepconvConfig {
            tap_w: (voxel_w + 1).max(4),
            weight_frac_w: 0,
            out_shift: (w + 2).trailing_zeros(),
        })
    }
}

/// The three passes' items and figures of one pre-pass over a volume.
#[derive(Debug, Clone, PartialEq)]
pub struct PrefilterRun {
    pub kernel: Prefilter,
    pub cfg: SepconvConfig,
    /// The filtered volume (same dimensions, spacing and width).
    pub volume: Volume,
    /// Samples (items) per pass: one per voxel.
    pub samples_per_pass: u64,
}

impl PrefilterRun {
    /// Samples of all three passes.
    pub fn samples(&self) -> u64 {
        3 * self.samples_per_pass
    }

    /// The cycles the contract gives one `cube5_sepconv` for the three passes, never stalled:
    /// one item a clock, then the latency to drain each pass.
    pub fn cycles(&self) -> u64 {
        3 * (self.samples_per_pass + SEPCONV_LATENCY)
    }

    /// One line for `plan:` and `cosim`.
    pub fn describe(&self) -> String {
        format!(
            "3-pass {} {} along x, y, z on one cube5_sepconv (TapW={} WeightFracW={} OutShift={}), edges replicated: 3 x {} samples, {} cycles at one sample a clock",
            self.kernel.name(),
            self.kernel.describe(),
            self.cfg.tap_w,
            self.cfg.weight_frac_w,
            self.cfg.out_shift,
            self.samples_per_pass,
            self.cycles()
        )
    }
}

/// The stride of `axis` (0 = x) in a volume of `dims` stored x fastest.
fn stride(dims: [usize; 3], axis: usize) -> usize {
    dims[..axis].iter().product()
}

/// The items of one pass along `axis` over `data`, in storage order (x fastest): each voxel with
/// its neighbours at -1 and +1 along the axis, a neighbour beyond the volume's edge replaced by
/// the edge voxel itself (the contract's edge rule: replicate).
pub fn pass_items(data: &[i64], dims: [usize; 3], axis: usize) -> Vec<SepconvIn> {
    let s = stride(dims, axis);
    let n = dims[axis];
    (0..data.len())
        .map(|i| {
            let k = (i / s) % n;
            let lo = if k == 0 { i } else { i - s };
            let hi = if k + 1 == n { i } else { i + s };
            SepconvIn {
                taps: [data[lo], data[i], data[hi]],
                kernel: SepconvKernel::Smooth,
            }
        })
        .collect()
}

/// The three passes of `kernel` over `vol` (at the width the frame's memory holds) on the unit's
/// model; `None` for [`Prefilter::None`].
pub fn apply(vol: &Volume, kernel: Prefilter) -> Result<Option<PrefilterRun>> {
    let (Some(cfg), Some(w)) = (kernel.sepconv_config(vol.bits), kernel.weight()) else {
        return Ok(None);
    };
    let unit = Sepconv::new(cfg, w)?;
    let mut data: Vec<i64> = vol.data.iter().map(|&v| i64::from(v)).collect();
    for axis in 0..3 {
        data = pass_items(&data, vol.dims, axis)
            .iter()
            .map(|it| unit.convolve(it))
            .collect();
    }
    let volume = volume_of(vol, &data)?;
    Ok(Some(PrefilterRun {
        kernel,
        cfg,
        volume,
        samples_per_pass: vol.data.len() as u64,
    }))
}

/// `vol` with its voxels replaced by `data` (the output of the last pass), refused if a value
/// left the voxel range (it cannot: the kernel is normalised and its weights are positive).
pub fn volume_of(vol: &Volume, data: &[i64]) -> Result<Volume> {
    let max = i64::from(vol.max_value());
    let mut out = Vec::with_capacity(data.len());
    for (i, &v) in data.iter().enumerate() {
        if !(0..=max).contains(&v) {
            return Err(ModelError::Volume(format!(
                "prefilter: voxel {i} filtered to {v}, outside 0..={max}"
            )));
        }
        out.push(v as u16);
    }
    Volume::new(vol.dims, vol.spacing, vol.bits, out)
}

/// The f64 ideal of the pre-pass: the same three passes and edge rule, `(a + w b + c) / (w + 2)`
/// in f64 with no rounding; voxels in the volume's integer units. Empty for `Prefilter::None`.
pub fn reference(vol: &Volume, kernel: Prefilter) -> Vec<f64> {
    let Some(w) = kernel.weight() else {
        return vol.data.iter().map(|&v| f64::from(v)).collect();
    };
    let (w, norm) = (f64::from(w), f64::from(w + 2));
    let mut data: Vec<f64> = vol.data.iter().map(|&v| f64::from(v)).collect();
    for axis in 0..3 {
        let s = stride(vol.dims, axis);
        let n = vol.dims[axis];
        data = (0..data.len())
            .map(|i| {
                let k = (i / s) % n;
                let lo = if k == 0 { i } else { i - s };
                let hi = if k + 1 == n { i } else { i + s };
                (data[lo] + w * data[i] + data[hi]) / norm
            })
            .collect();
    }
    data
}

/// The reference renderer's volume of a pre-filtered scene: the f64 ideal rounded to the nearest
/// voxel value at the volume's width (the reference renderer reads integer voxels).
pub fn reference_volume(vol: &Volume, kernel: Prefilter) -> Result<Volume> {
    if kernel == Prefilter::None {
        return Ok(vol.clone());
    }
    let data: Vec<i64> = reference(vol, kernel)
        .iter()
        .map(|v| v.round() as i64)
        .collect();
    volume_of(vol, &data)
}

/// A volume of `bits`-bit voxels, random with a quarter at each extreme (0 and the largest): the
/// stimulus of the pre-filter's tests, on the model and on the RTL.
pub fn random_volume(dims: [usize; 3], bits: u32, seed: u64) -> Result<Volume> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let max = (1u32 << bits) - 1;
    let data = (0..dims.iter().product::<usize>())
        .map(|_| match rng.random_range(0..4) {
            0 => 0,
            1 => max as u16,
            _ => rng.random_range(0..=max) as u16,
        })
        .collect();
    Volume::new(dims, [1.0; 3], bits, data)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each pass rounds once, by at most half a voxel LSB, and a normalised kernel of positive
    /// weights passes an earlier error on without growing it: at most 1.5 LSB in all.
    #[test]
    fn the_model_is_within_one_and_a_half_lsb_of_the_f64_ideal() {
        for kernel in [Prefilter::Gauss, Prefilter::GaussNarrow] {
            for (bits, dims) in [(8, [7, 5, 6]), (12, [9, 8, 10]), (16, [4, 6, 5])] {
                let vol = random_volume(dims, bits, u64::from(bits)).unwrap();
                let run = apply(&vol, kernel).unwrap().unwrap();
                let ideal = reference(&vol, kernel);
                let worst = run
                    .volume
                    .data
                    .iter()
                    .zip(&ideal)
                    .map(|(&m, &r)| (f64::from(m) - r).abs())
                    .fold(0.0, f64::max);
                assert!(worst <= 1.5, "{kernel:?} {bits} bits: {worst}");
                assert!(
                    worst > 0.0,
                    "{kernel:?} {bits} bits: the rounding is exercised"
                );
            }
        }
    }

    /// A constant volume stays constant (edges replicated, kernel normalised), extremes
    /// included; a single voxel spreads into the 3x3x3 binomial.
    #[test]
    fn constants_stay_and_an_impulse_spreads_into_the_kernel() {
        for bits in [1, 8, 12, 16] {
            for v in [0, (1u32 << bits) - 1] {
                let vol = Volume::new([5, 4, 3], [1.0; 3], bits, vec![v as u16; 60]).unwrap();
                for kernel in [Prefilter::Gauss, Prefilter::GaussNarrow] {
                    assert_eq!(apply(&vol, kernel).unwrap().unwrap().volume.data, vol.data);
                }
            }
        }
        // 64 at the centre of 3^3 (replicated edges reach none of it): 64 * {1 2 1}^3 / 64.
        let mut data = vec![0u16; 27];
        data[13] = 64;
        let vol = Volume::new([3, 3, 3], [1.0; 3], 12, data).unwrap();
        let out = apply(&vol, Prefilter::Gauss).unwrap().unwrap().volume.data;
        let k = [1u16, 2, 1];
        for z in 0..3 {
            for y in 0..3 {
                for x in 0..3 {
                    assert_eq!(out[x + 3 * (y + 3 * z)], k[x] * k[y] * k[z], "{x} {y} {z}");
                }
            }
        }
    }

    /// The items of a pass: neighbours along the axis, the edge voxel itself beyond the edge.
    #[test]
    fn pass_items_replicate_the_edges() {
        let data: Vec<i64> = (0..24).collect(); // 4 x 3 x 2
        let dims = [4, 3, 2];
        let taps = |axis, i: usize| pass_items(&data, dims, axis)[i].taps;
        assert_eq!(taps(0, 0), [0, 0, 1]);
        assert_eq!(taps(0, 3), [2, 3, 3]);
        assert_eq!(taps(1, 5), [1, 5, 9]);
        assert_eq!(taps(1, 9), [5, 9, 9]);
        assert_eq!(taps(2, 5), [5, 5, 17]);
        assert_eq!(taps(2, 17), [5, 17, 17]);
        assert!(apply(
            &Volume::new(dims, [1.0; 3], 8, vec![0; 24]).unwrap(),
            Prefilter::None
        )
        .unwrap()
        .is_none());
    }

    #[test]
    fn names_and_configurations() {
        for name in PREFILTER_NAMES {
            assert_eq!(Prefilter::from_name(name).unwrap().name(), name);
        }
        assert_eq!(Prefilter::from_name("sobel"), None);
        let cfg = Prefilter::Gauss.sepconv_config(12).unwrap();
        assert_eq!((cfg.tap_w, cfg.weight_frac_w, cfg.out_shift), (13, 0, 2));
        assert!(cfg.validate().is_ok());
        let cfg = Prefilter::GaussNarrow.sepconv_config(8).unwrap();
        assert_eq!((cfg.tap_w, cfg.out_shift), (9, 3));
        assert!(Prefilter::None.sepconv_config(12).is_none());
    }
}
