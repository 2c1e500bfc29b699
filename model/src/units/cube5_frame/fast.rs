//! The frame's fast path: the same base plane as [`render_base_plane_reference`], bit for bit,
//! computed once per slice instead of seven interpolations per sample (`docs/numerics/frame.md`,
//! "The model's fast path").
//!
//! Per slice `s`: the plane of samples `S_s` (one bilinear sample per anchor, rows in parallel);
//! then every row of anchors, in parallel, against its own row of coxels (anchor row `b` feeds
//! base-plane row `b - sy(s) + max(sy)`, a different row for every `b`, so no two threads share a
//! coxel and each ray still sees its samples in slice order). Per anchor, before any gradient:
//! a coxel of a terminated ray, or a sample that the compositing unit would leave without effect
//! (`Compos::leaves_unchanged` on the classified alpha), costs nothing more; otherwise the
//! in-plane neighbours come from the plane, `B = S'(s-1)` and `A = S'(s+1)` are interpolated on
//! demand with slice `s`'s weights, and the sample goes through [`shade_n6`] and `Compos::step`,
//! the unit models' own functions. Leading and trailing slices whose voxels are all 0 are left
//! out when their zero samples leave every coxel they meet unchanged (the contract's rule for
//! skipping empty slices, checked coxel by coxel).

use super::{
    render_base_plane_reference, shade_n6, BasePlane, FrameMode, FrameParams, FrameUnits, STEP_W,
};
use crate::units::cube5_compos::{ComposMode, Coxel};
use crate::units::cube5_shader::{Shader, ShaderIn, ShaderMode};
use crate::volume::Volume;
use rayon::prelude::*;

/// What a frame's sweep computed and what it left out (the CLI's `plan:` line).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SweepStats {
    /// Anchors of the frame: one per voxel, `ni nj nk`.
    pub anchors: u64,
    /// Leading and trailing slices left out (all their voxels 0, their samples without effect).
    pub slices_skipped: (usize, usize),
    /// Samples interpolated in the swept slices' planes (`S_s`, one per anchor).
    pub samples: u64,
    /// Samples that went through gradient, shader and compositing.
    pub shaded: u64,
    /// Samples the compositing unit would leave without effect (transparent, or not above the
    /// maximum): classified only.
    pub without_effect: u64,
    /// Samples of rays already terminated (early ray termination): not classified.
    pub after_termination: u64,
    /// Rays whose coxel ends terminated.
    pub rays_terminated: u64,
}

impl SweepStats {
    fn add(mut self, o: Self) -> Self {
        self.samples += o.samples;
        self.shaded += o.shaded;
        self.without_effect += o.without_effect;
        self.after_termination += o.after_termination;
        self
    }
}

/// Voxels of the volume in frame axes: index `i si + j sj + k sk`.
struct Frame<'a> {
    data: &'a [u16],
    ni: usize,
    nj: usize,
    si: usize,
    sj: usize,
    sk: usize,
}

impl Frame<'_> {
    /// The corners `(i, j)`, `(i+1, j)`, `(i, j+1)`, `(i+1, j+1)` of slice plane `k` for anchor
    /// `(i, j)` of the face, 0 beyond the far faces (frame contract).
    #[inline]
    fn corners(&self, i: usize, j: usize, k: usize) -> [u32; 4] {
        let at = i * self.si + j * self.sj + k * self.sk;
        let v = |o: usize| u32::from(self.data[at + o]);
        match (i + 1 < self.ni, j + 1 < self.nj) {
            (true, true) => [v(0), v(self.si), v(self.sj), v(self.si + self.sj)],
            (true, false) => [v(0), v(self.si), 0, 0],
            (false, true) => [v(0), 0, v(self.sj), 0],
            (false, false) => [v(0), 0, 0, 0],
        }
    }

    /// Row `j` of plane `k` into `out` (`ni + 1` entries, the last one 0); zeros past the far face.
    fn row(&self, j: usize, k: usize, out: &mut [u32]) {
        out.fill(0);
        if j >= self.nj {
            return;
        }
        let base = j * self.sj + k * self.sk;
        if self.si == 1 {
            for (o, &v) in out.iter_mut().zip(&self.data[base..base + self.ni]) {
                *o = u32::from(v);
            }
        } else {
            for (i, o) in out[..self.ni].iter_mut().enumerate() {
                *o = u32::from(self.data[base + i * self.si]);
            }
        }
    }

    fn plane_is_zero(&self, k: usize) -> bool {
        (0..self.nj).all(|j| {
            let base = j * self.sj + k * self.sk;
            if self.si == 1 {
                self.data[base..base + self.ni].iter().all(|&v| v == 0)
            } else {
                (0..self.ni).all(|i| self.data[base + i * self.si] == 0)
            }
        })
    }
}

/// The shader's and the compositing unit's modes of a frame mode (frame contract, steps 4, 5).
#[inline(always)]
fn modes(mode: FrameMode) -> (ShaderMode, ComposMode) {
    match mode {
        FrameMode::Mip => (
            ShaderMode {
                tf2d: false,
                unlit: true,
            },
            ComposMode::Max,
        ),
        FrameMode::Composite => (
            ShaderMode {
                tf2d: false,
                unlit: false,
            },
            ComposMode::FrontToBack,
        ),
    }
}

/// The shader's input for classifying a sample (no 2-D classification: gradient unused).
#[inline(always)]
fn class_in(sample: u32, mode: ShaderMode) -> ShaderIn {
    ShaderIn {
        sample,
        grad: [0; 3],
        mag: 0,
        mode,
    }
}

/// What the rows of one slice share.
struct SliceWork<'a> {
    units: &'a FrameUnits,
    frame: &'a Frame<'a>,
    /// `S_s`, anchor order.
    plane: &'a [u32],
    /// The corrected alpha of each class index (the compositing unit's `corrected` of the class
    /// entry's alpha): a sample's effect is known before its gradient.
    corrected: &'a [u64],
    /// Base-plane column of anchor 0.
    r0: usize,
    depth: u32,
    wx: u32,
    wy: u32,
    /// Volume slices of `s - 1` and `s + 1` (none outside the sweep).
    k_before: Option<usize>,
    k_after: Option<usize>,
}

impl SliceWork<'_> {
    /// Anchor row `b` against its row of coxels (`row`, one base-plane row). Inlined at a
    /// constant `mode` so that the unit functions' mode branches fold.
    #[inline(always)]
    fn row(&self, b: usize, row: &mut [Coxel], mode: FrameMode) -> SweepStats {
        let (smode, cmode) = modes(mode);
        let (units, frame, plane) = (self.units, self.frame, self.plane);
        let (ni, nj, depth) = (frame.ni, frame.nj, self.depth);
        let mut st = SweepStats {
            samples: ni as u64,
            ..SweepStats::default()
        };
        let at = |a: usize, b: usize| plane[b * ni + a];
        // S'(t) at anchor (a, b): slice k(t)'s voxels, slice s's weights.
        let other = |k: Option<usize>, a: usize| match k {
            None => 0,
            Some(k) => units
                .trilin
                .sample_in_slice(frame.corners(a, b, k), self.wx, self.wy),
        };
        let lit = Shader::reads_gradient(smode);
        for (a, cox) in row[self.r0..self.r0 + ni].iter_mut().enumerate() {
            if cox.terminated {
                st.after_termination += 1;
                continue;
            }
            let centre = at(a, b);
            let corrected = self.corrected[units.shader.class_index(&class_in(centre, smode))];
            if units
                .compos
                .leaves_unchanged_corrected(cox, corrected, depth, cmode)
            {
                st.without_effect += 1;
                continue;
            }
            // Unlit without tf2d, the shader reads no gradient: the neighbours stay 0.
            let nb = if lit {
                [
                    centre,
                    if a > 0 { at(a - 1, b) } else { 0 },
                    if a + 1 < ni { at(a + 1, b) } else { 0 },
                    if b > 0 { at(a, b - 1) } else { 0 },
                    if b + 1 < nj { at(a, b + 1) } else { 0 },
                    other(self.k_before, a),
                    other(self.k_after, a),
                ]
            } else {
                [centre, 0, 0, 0, 0, 0, 0]
            };
            let sample = shade_n6(&units.gradient, &units.shader, &nb, smode, depth);
            *cox = units.compos.step(cox, &sample);
            st.shaded += 1;
        }
        st
    }
}

/// The base-plane image of a frame, bit-exact with `cube5_frame` (docs/numerics/frame.md): the
/// fast path, equal to [`render_base_plane_reference`] coxel for coxel.
pub fn render_base_plane(params: &FrameParams, vol: &Volume, units: &FrameUnits) -> BasePlane {
    render_base_plane_stats(params, vol, units).0
}

/// [`render_base_plane`] with the counts of what its sweep computed and skipped.
pub fn render_base_plane_stats(
    params: &FrameParams,
    vol: &Volume,
    units: &FrameUnits,
) -> (BasePlane, SweepStats) {
    let anchors = params.samples() as u64;
    let dims = vol.dims;
    if dims[params.axis_i] != params.ni
        || dims[params.axis_j] != params.nj
        || dims[params.axis_k] != params.nk
    {
        // Not a volume of these parameters: only the reference reads it (as zeros outside).
        let bp = render_base_plane_reference(params, vol, units);
        let stats = SweepStats {
            anchors,
            samples: anchors,
            shaded: anchors,
            rays_terminated: bp.coxels.iter().filter(|c| c.terminated).count() as u64,
            ..SweepStats::default()
        };
        return (bp, stats);
    }
    let strides = [1, dims[0], dims[0] * dims[1]];
    let frame = Frame {
        data: &vol.data,
        ni: params.ni,
        nj: params.nj,
        si: strides[params.axis_i],
        sj: strides[params.axis_j],
        sk: strides[params.axis_k],
    };
    let (ni, nj, nk) = (params.ni, params.nj, params.nk);
    let (w, h) = params.base_plane_size();
    let ((_, max_sx), (_, max_sy)) = params.shift_range();
    let init = Coxel::empty(&units.compos.config());
    let mut coxels = vec![init; w * h];
    let (smode, cmode) = modes(units.mode);
    let ww = units.trilin.config().weight_w;
    let weight = |f: u32| f >> (STEP_W - ww);
    // The corrected alpha of a sample, known before its gradient (no 2-D classification in the
    // frame): the compositing unit's correction of the classified alpha, per class index.
    let corrected: Vec<u64> = units
        .shader
        .tables()
        .class
        .entries()
        .iter()
        .map(|e| units.compos.corrected(e.a))
        .collect();

    // Leading and trailing slices with every voxel 0 (their samples, and their neighbours' reads
    // of them, are 0 with or without them).
    let front_zero = (0..nk)
        .take_while(|&s| frame.plane_is_zero(params.slice(s).k))
        .count();
    let back_zero = if front_zero == nk {
        0
    } else {
        (0..nk)
            .rev()
            .take_while(|&s| frame.plane_is_zero(params.slice(s).k))
            .count()
    };

    let mut stats = SweepStats {
        anchors,
        ..SweepStats::default()
    };
    let mut plane = vec![0u32; ni * nj];
    for s in 0..nk {
        let c = params.slice(s);
        let depth = s as u32;
        let r0 = (max_sx - c.shift_x) as usize;
        let q0 = (max_sy - c.shift_y) as usize;
        let rows = &mut coxels[q0 * w..(q0 + nj) * w];
        let (wx, wy) = (weight(c.frac_x), weight(c.frac_y));
        // The sample of four zero voxels (a row of them is filled without interpolating) and
        // its corrected alpha.
        let zero_sample = units.trilin.sample_in_slice([0; 4], wx, wy);
        let alpha0 = corrected[units.shader.class_index(&class_in(zero_sample, smode))];
        let empty = s < front_zero || s >= nk - back_zero;
        if empty
            && rows.par_chunks(w).all(|row| {
                row[r0..r0 + ni].iter().all(|cox| {
                    units
                        .compos
                        .leaves_unchanged_corrected(cox, alpha0, depth, cmode)
                })
            })
        {
            if s < front_zero {
                stats.slices_skipped.0 += 1;
            } else {
                stats.slices_skipped.1 += 1;
            }
            continue;
        }
        // 1. The plane of samples S_s.
        plane.par_chunks_mut(ni).enumerate().for_each_init(
            || (vec![0u32; ni + 1], vec![0u32; ni + 1]),
            |(top, bot), (b, out)| {
                frame.row(b, c.k, top);
                frame.row(b + 1, c.k, bot);
                if top.iter().chain(bot.iter()).all(|&v| v == 0) {
                    out.fill(zero_sample);
                    return;
                }
                for (a, o) in out.iter_mut().enumerate() {
                    *o = units.trilin.sample_in_slice(
                        [top[a], top[a + 1], bot[a], bot[a + 1]],
                        wx,
                        wy,
                    );
                }
            },
        );
        // 2. Every anchor against the coxel of its ray, rows in parallel.
        let work = SliceWork {
            units,
            frame: &frame,
            plane: &plane,
            corrected: &corrected,
            r0,
            depth,
            wx,
            wy,
            k_before: (s > 0).then(|| params.slice(s - 1).k),
            k_after: (s + 1 < nk).then(|| params.slice(s + 1).k),
        };
        // One copy of the row loop per mode, so that the units' mode branches fold away.
        let part = rows
            .par_chunks_mut(w)
            .enumerate()
            .map(|(b, row)| match units.mode {
                FrameMode::Mip => work.row(b, row, FrameMode::Mip),
                FrameMode::Composite => work.row(b, row, FrameMode::Composite),
            })
            .reduce(SweepStats::default, SweepStats::add);
        stats = stats.add(part);
    }
    stats.rays_terminated = coxels.iter().filter(|c| c.terminated).count() as u64;
    (
        BasePlane {
            width: w,
            height: h,
            coxels,
        },
        stats,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{bubbles_phantom, head_phantom, sphere_phantom};
    use crate::transfer::TransferFunction;
    use crate::unit::UnitConfig;
    use crate::units::cube5_compos::{Compos, ComposRegs};
    use crate::units::cube5_frame::ET_DEFAULT;
    use crate::units::cube5_frame::{frame_phong, FrameConfig, FrameSetup};
    use glam::DVec3;
    use rand::{Rng, SeedableRng};

    /// The seed of the random views: `CUBE5_SEED` or a fixed default, printed on failure.
    fn seed() -> u64 {
        std::env::var("CUBE5_SEED")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(1313)
    }

    /// The voxels of `vol` in the box `lo .. lo + dims`, zeros where the box leaves the volume
    /// (so a box larger than the volume pads it with empty slices).
    fn window(vol: &Volume, lo: [i64; 3], dims: [usize; 3], spacing: [f64; 3]) -> Volume {
        let mut data = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
        for z in 0..dims[2] as i64 {
            for y in 0..dims[1] as i64 {
                for x in 0..dims[0] as i64 {
                    data.push(vol.get(lo[0] + x, lo[1] + y, lo[2] + z) as u16);
                }
            }
        }
        Volume::new(dims, spacing, vol.bits, data).unwrap()
    }

    /// Six faces, exact 45 degrees (the tie rule), reversed sweeps and seeded obliques.
    fn views(n_random: usize, rng: &mut rand_chacha::ChaCha8Rng) -> Vec<[f64; 3]> {
        let mut v = vec![
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [1.0, 0.0, 1.0],
            [-1.0, 1.0, 0.0],
            [1.0, -1.0, -1.0],
            [-0.37, 0.81, -1.0],
        ];
        for _ in 0..n_random {
            v.push(std::array::from_fn(|_| rng.random_range(-1.0..1.0)));
        }
        v
    }

    /// The fast path and the reference render `vol` alike from every view, P = 1, 4, 8, MIP and
    /// composite; returns the summed stats (to check that the skips were exercised).
    fn check_equal(
        what: &str,
        vol: &Volume,
        cfg: &FrameConfig,
        tf: &TransferFunction,
        early_termination: bool,
        views: &[[f64; 3]],
    ) -> SweepStats {
        let mut total = SweepStats::default();
        for (n, v) in views.iter().enumerate() {
            let p = [1, 4, 8][n % 3];
            if vol.dims.iter().any(|d| d % p != 0) {
                continue;
            }
            let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(*v), p).unwrap();
            let params = setup.params;
            for mode in [FrameMode::Mip, FrameMode::Composite] {
                let units = FrameUnits::with_config(
                    cfg,
                    mode,
                    &setup,
                    tf,
                    &frame_phong(&params, &[]),
                    early_termination.then_some(ET_DEFAULT),
                )
                .unwrap();
                let want = render_base_plane_reference(&params, vol, &units);
                let (got, st) = render_base_plane_stats(&params, vol, &units);
                assert_eq!((got.width, got.height), (want.width, want.height));
                if let Some(i) = (0..want.coxels.len()).find(|&i| got.coxels[i] != want.coxels[i]) {
                    panic!(
                        "{what}, view {v:?}, P {p}, {mode:?} (CUBE5_SEED={}): coxel ({}, {}) is \
                         {:?}, the reference {:?}",
                        seed(),
                        i % want.width,
                        i / want.width,
                        got.coxels[i],
                        want.coxels[i]
                    );
                }
                let swept = (params.nk - st.slices_skipped.0 - st.slices_skipped.1) as u64;
                assert_eq!(st.samples, swept * (params.ni * params.nj) as u64);
                assert_eq!(
                    st.shaded + st.without_effect + st.after_termination,
                    st.samples
                );
                total = total.add(st);
                total.slices_skipped.0 += st.slices_skipped.0 + st.slices_skipped.1;
                total.rays_terminated += st.rays_terminated;
            }
        }
        total
    }

    /// The fast path equals the per-sample reference bit for bit: phantoms, non-cubic and
    /// anisotropic volumes, empty margins, every face, 45 degrees and obliques, MIP and
    /// composite, with and without early termination.
    #[test]
    fn fast_path_equals_the_reference() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed());
        let cfg = FrameConfig::DEFAULT;
        let head = head_phantom(24, 12).unwrap();
        let tf = TransferFunction::head_default();
        let vs = views(6, &mut rng);
        let mut total = check_equal("head 24^3", &head, &cfg, &tf, false, &vs);
        let noncubic = window(&head, [0, 4, -4], [24, 16, 32], [1.0; 3]);
        total = total.add(check_equal(
            "head 24x16x32",
            &noncubic,
            &cfg,
            &tf,
            false,
            &vs,
        ));
        let aniso = window(&head, [4, 0, 2], [16, 24, 16], [1.0, 0.7, 1.6]);
        total = total.add(check_equal(
            "head anisotropic",
            &aniso,
            &cfg,
            &tf,
            false,
            &vs,
        ));
        // Empty slices around the data on every side: the skipping.
        let padded = window(
            &head_phantom(16, 12).unwrap(),
            [-4, -8, -8],
            [24, 32, 32],
            [1.0; 3],
        );
        let st = check_equal("head padded", &padded, &cfg, &tf, false, &vs);
        assert!(st.slices_skipped.0 > 0, "no slice skipped: {st:?}");
        total = total.add(st);
        let iso = TransferFunction::preset("iso").unwrap();
        for (name, vol) in [
            ("sphere", sphere_phantom(16, 12).unwrap()),
            ("bubbles", bubbles_phantom(16, 12).unwrap()),
        ] {
            total = total.add(check_equal(name, &vol, &cfg, &iso, false, &vs[..8]));
        }
        // Early termination: opaque surfaces end rays.
        let mut et = SweepStats::default();
        for (name, vol, tf) in [
            ("sphere, ET", sphere_phantom(24, 12).unwrap(), &iso),
            ("head, ET", head.clone(), &tf),
        ] {
            let st = check_equal(name, &vol, &cfg, tf, true, &vs);
            et.after_termination += st.after_termination;
            et.rays_terminated += st.rays_terminated;
        }
        assert!(et.after_termination > 0 && et.rays_terminated > 0, "{et:?}");
        // Random dense voxels: nothing transparent, every rule of the sweep at once.
        let noise: Vec<u16> = (0..16 * 8 * 24)
            .map(|_| rng.random_range(0..4096))
            .collect();
        let noise = Volume::new([16, 8, 24], [1.0; 3], 12, noise).unwrap();
        let grey = TransferFunction::preset("grey").unwrap();
        total = total.add(check_equal("noise", &noise, &cfg, &grey, false, &vs[..8]));
        assert!(total.shaded > 0 && total.without_effect > 0, "{total:?}");
    }

    /// The same at the narrow (`v8`) and wide widths, and with a termination threshold of 0 (a
    /// front-to-back sample then ends every ray it meets, transparent or not).
    #[test]
    fn fast_path_equals_the_reference_at_other_widths() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed() + 1);
        let vs = views(3, &mut rng);
        let params = |s: &str| -> Vec<(&'static str, i64)> {
            s.split_whitespace()
                .map(|kv| {
                    let (k, v) = kv.split_once('=').unwrap();
                    let k: &'static str = Box::leak(k.to_string().into_boxed_str());
                    (k, v.parse().unwrap())
                })
                .collect()
        };
        let narrow = FrameConfig::from_params(&params(
            "VoxelW=8 WeightW=6 FracW=2 ClassIdxW=8 MagIdxW=2 MagShift=6 ColorW=8 AlphaW=8 \
             RmLog2=2 RmFracW=3 DiffW=6 SpecW=5 ExtraW=0 AccW=8 ZW=8",
        ))
        .unwrap();
        let wide = FrameConfig::from_params(&params(
            "VoxelW=16 WeightW=10 FracW=6 ColorW=10 AlphaW=10 ExtraW=2 AccW=24 ZW=16",
        ))
        .unwrap();
        let tf = TransferFunction::head_default();
        for (name, cfg) in [("narrow", narrow), ("wide", wide)] {
            let vol = head_phantom(16, cfg.trilin.voxel_w).unwrap();
            // Narrow depth (ZW = 8) is smaller than the slice count here: samples past it fail
            // the depth test.
            let long = window(&vol, [0, 0, -4], [16, 16, 24], [1.0; 3]);
            for et in [false, true] {
                check_equal(name, &vol, &cfg, &tf, et, &vs);
                check_equal(name, &long, &cfg, &tf, et, &vs[..4]);
            }
        }
        // Threshold 0.
        let vol = head_phantom(16, 12).unwrap();
        let cfg = FrameConfig::DEFAULT;
        for v in &vs {
            let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(*v), 4).unwrap();
            let p = setup.params;
            let mut units = FrameUnits::with_config(
                &cfg,
                FrameMode::Composite,
                &setup,
                &tf,
                &frame_phong(&p, &[]),
                Some(ET_DEFAULT),
            )
            .unwrap();
            let c = &units.compos;
            let regs = ComposRegs {
                et_threshold: 0,
                ..c.regs()
            };
            units.compos = Compos::new(c.config(), c.lut().clone(), regs).unwrap();
            let (got, st) = render_base_plane_stats(&p, &vol, &units);
            assert!(
                got == render_base_plane_reference(&p, &vol, &units),
                "{v:?}"
            );
            // Every ray that meets a sample ends at its first one.
            let reached = got.coxels.iter().filter(|c| c.terminated).count() as u64;
            assert!(reached >= (p.ni * p.nj) as u64, "{v:?} {st:?}");
            assert_eq!(st.rays_terminated, reached);
            assert_eq!(st.shaded + st.without_effect, reached, "{v:?} {st:?}");
        }
    }

    /// A volume that does not match the parameters goes to the reference, which reads it as
    /// zeros outside (no panic).
    #[test]
    fn a_volume_of_other_dimensions_takes_the_reference() {
        let vol = head_phantom(16, 12).unwrap();
        let setup = FrameSetup::new([16, 16, 24], [1.0; 3], DVec3::Z, 4).unwrap();
        let units = FrameUnits::new(
            FrameMode::Mip,
            &setup,
            &TransferFunction::head_default(),
            &frame_phong(&setup.params, &[]),
        )
        .unwrap();
        let want = render_base_plane_reference(&setup.params, &vol, &units);
        assert!(render_base_plane(&setup.params, &vol, &units) == want);
    }
}
