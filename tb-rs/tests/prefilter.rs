//! The 3-pass pre-filter over a volume on the RTL (`cube5_tb::prefilter`: one `cube5_sepconv`,
//! three passes along x, y, z with the contract's edge rule) against the model
//! (`cube5_model::prefilter`), voxel for voxel (docs/numerics/sepconv.md, *Over a volume*).

mod support;

use cube5_model::prefilter::{apply, pass_items, Prefilter};
use cube5_model::volume::Volume;
use cube5_tb::prefilter::{run, sepconv_variant};
use support::seed;

/// A random volume (`prefilter::random_volume`).
fn random_volume(dims: [usize; 3], bits: u32, seed: u64) -> Volume {
    cube5_model::prefilter::random_volume(dims, bits, seed).unwrap()
}

/// Checkerboard of 0 and the largest voxel: every tap sum at its extremes, every rounding tie.
fn checkerboard(dims: [usize; 3], bits: u32) -> Volume {
    let max = ((1u32 << bits) - 1) as u16;
    let data = (0..dims.iter().product::<usize>())
        .map(|i| {
            let (x, y, z) = (
                i % dims[0],
                (i / dims[0]) % dims[1],
                i / (dims[0] * dims[1]),
            );
            if (x + y + z) % 2 == 0 {
                max
            } else {
                0
            }
        })
        .collect();
    Volume::new(dims, [1.0; 3], bits, data).unwrap()
}

/// The kernels whose configuration for `bits`-bit voxels this test bench has built.
fn built_kernels(bits: u32) -> Vec<Prefilter> {
    [Prefilter::Gauss, Prefilter::GaussNarrow]
        .into_iter()
        .filter(|k| sepconv_variant(&k.sepconv_config(bits).unwrap()).is_ok())
        .collect()
}

fn must_match(vol: &Volume, kernel: Prefilter, what: &str, seed: u32) {
    let want = apply(vol, kernel).unwrap().unwrap();
    let got = run(vol, kernel, seed).unwrap().unwrap();
    let n = vol.data.len();
    for (i, (g, w)) in got.data.iter().zip(&want.volume.data).enumerate() {
        assert_eq!(
            *g,
            i64::from(*w),
            "{what} ({kernel:?} on {}, seed {seed}): voxel {i} of {n} (dims {:?}): rtl {g} model {w}",
            got.variant,
            vol.dims
        );
    }
    assert_eq!(got.data.len(), n);
    // One sample a clock: each pass is its items plus the latency, as the contract says.
    assert_eq!(got.cycles(), want.cycles(), "{what}: {:?}", got.pass_cycles);
}

#[test]
fn the_rtl_pre_pass_is_the_models_voxel_for_voxel() {
    // The checked-in configuration of the default 12-bit voxels.
    let kernels = built_kernels(12);
    assert!(
        kernels.contains(&Prefilter::Gauss),
        "the pre-pass of 12-bit voxels (gauss) is built"
    );
    let s = seed(700);
    for kernel in kernels {
        for (k, dims) in [[13, 7, 9], [1, 5, 3], [4, 1, 6], [2, 2, 1]]
            .into_iter()
            .enumerate()
        {
            let vol = random_volume(dims, 12, s + k as u64);
            must_match(&vol, kernel, "random", s as u32 + k as u32);
        }
        must_match(&checkerboard([9, 6, 5], 12), kernel, "checkerboard", 3);
        for v in [0u16, 4095] {
            let vol = Volume::new([5, 3, 4], [1.0; 3], 12, vec![v; 60]).unwrap();
            must_match(&vol, kernel, "constant", 4);
        }
    }
}

/// The edges are the contract's (replicated): a model that took zeros beyond the edge differs
/// from the RTL, on a volume whose border is not zero.
#[test]
fn the_edge_rule_is_checked() {
    let vol = random_volume([6, 5, 4], 12, seed(701));
    let got = run(&vol, Prefilter::Gauss, 5).unwrap().unwrap();
    let cfg = Prefilter::Gauss.sepconv_config(12).unwrap();
    let unit = cube5_model::units::cube5_sepconv::Sepconv::new(cfg, 2).unwrap();
    let mut data: Vec<i64> = vol.data.iter().map(|&v| i64::from(v)).collect();
    for axis in 0..3 {
        let n = vol.dims[axis];
        let s: usize = vol.dims[..axis].iter().product();
        data = pass_items(&data, vol.dims, axis)
            .into_iter()
            .enumerate()
            .map(|(i, mut it)| {
                let k = (i / s) % n;
                if k == 0 {
                    it.taps[0] = 0;
                }
                if k + 1 == n {
                    it.taps[2] = 0;
                }
                unit.convolve(&it)
            })
            .collect();
    }
    assert_ne!(got.data, data, "zero edges must be caught");
}
