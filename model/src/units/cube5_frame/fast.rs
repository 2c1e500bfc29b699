//! The frame's fast path: the same base plane as [`render_base_plane_reference`], bit for bit,
//! computed once per slice instead of seven interpolations per sample, and only where a sample can
//! change its ray (`docs/numerics/frame.md`, "The model's fast path").
//!
//! The sweep reads a [`SweepVolume`]: the voxels in the sweep's axis order (rows along `i`
//! contiguous, a zero column and a zero row past the far faces), and for every block of 8 x 8
//! anchors of every slice plane the range of the voxels its samples read. Per slice `s`, per block:
//! the largest corrected alpha any sample of the block can have (the class entries of the range's
//! class indices); a block whose samples leave every coxel they meet unchanged (alpha 0 where a
//! transparent sample is the identity, or every coxel of its rays terminated or already above it
//! under `Max`) is not interpolated at all. The base plane is split into bands of rows, in
//! parallel, and each band takes every slice in order from the anchor rows that feed it (anchor
//! row `b` feeds base-plane row `b - sy(s) + max(sy)`, a different row for every `b`, so no two
//! threads share a coxel and each ray still sees its samples in slice order). Per anchor, before
//! any gradient: a coxel of a terminated ray, or a sample that the compositing unit would leave
//! without effect (`Compos::leaves_unchanged` on the classified alpha), costs nothing more;
//! otherwise, when the shaded colour depends on the gradient, the in-plane neighbours come from
//! the band's plane rows, `B = S'(s-1)` and `A = S'(s+1)` are interpolated on demand with slice
//! `s`'s weights (a row of the block's anchors at a time), and the sample goes through the `N6`
//! differences, `Shader::shade_lit_lanes` (the bits of [`super::shade_n6`], a row at a time) and
//! `Compos::step`, the unit models' own functions; when it does not (MIP, or a
//! uniform reflectance map), the shaded entry of its class index is the shader's own output for
//! that index. Leading and trailing slices whose voxels are all 0 are left out when a zero sample
//! is the identity of every coxel (the contract's rule for skipping empty slices).

use super::{render_base_plane_reference, BasePlane, FrameMode, FrameParams, FrameUnits, STEP_W};
use crate::units::cube5_compos::{Compos, ComposMode, Coxel, Sample};
use crate::units::cube5_shader::{Shader, ShaderIn, ShaderMode};
use crate::units::cube5_trilin::InSlice;
use crate::volume::Volume;
use rayon::prelude::*;

mod lanes;
use lanes::{LaneRules, RayLanes};

/// What a frame's sweep computed and what it left out (the CLI's `plan:` line). These are the
/// model's own counts: the hardware's (samples, beams of empty blocks, terminated rays) are the
/// frame's (`scene_render::FrameRun`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SweepStats {
    /// Anchors of the frame: one per voxel, `ni nj nk`.
    pub anchors: u64,
    /// Leading and trailing slices left out (all their voxels 0, their samples without effect).
    pub slices_skipped: (usize, usize),
    /// Samples of the swept slices (one per anchor).
    pub samples: u64,
    /// Samples that went through shader and compositing (and the gradient, where it matters).
    pub shaded: u64,
    /// Samples the compositing unit would leave without effect (transparent, or not above the
    /// maximum): interpolated and classified only.
    pub without_effect: u64,
    /// Samples of rays already terminated (early ray termination): not classified.
    pub after_termination: u64,
    /// Samples of blocks that cannot change any coxel they meet (their voxel range classifies
    /// transparent, or every ray they meet is terminated or above them): not interpolated.
    pub in_skipped_blocks: u64,
    /// Rays whose coxel ends terminated.
    pub rays_terminated: u64,
}

impl SweepStats {
    fn add(mut self, o: Self) -> Self {
        self.samples += o.samples;
        self.shaded += o.shaded;
        self.without_effect += o.without_effect;
        self.after_termination += o.after_termination;
        self.in_skipped_blocks += o.in_skipped_blocks;
        self.rays_terminated += o.rays_terminated;
        self
    }
}

/// Anchors per block edge of the sweep's skipping (in `i` and `j`, within one slice plane).
const BLOCK: usize = 8;
/// Anchor rows per parallel task.
const BAND: usize = 16;

/// A volume in the order the frame sweeps it, with the voxel range of every block of anchors
/// (made once per volume and slice axis: `scene_render::FrameJob` keeps one).
#[derive(Clone)]
pub struct SweepVolume {
    /// Volume axes of `i`, `j`, `k` this copy is for, and the volume's dimensions.
    axes: [usize; 3],
    dims: [usize; 3],
    ni: usize,
    nj: usize,
    nk: usize,
    /// Voxel `(i, j, k)` (`k` the volume index along `axes[2]`) at `(j nk + k) (ni + 1) + i`;
    /// column `ni` and row `nj` of every plane are 0 (the frame's zeros past the far faces).
    /// Row `j` of consecutive planes is contiguous: a band of the sweep reads the same few rows
    /// of plane after plane, so it streams through memory rather than jumping a plane a slice.
    data: Vec<u16>,
    /// Blocks per plane along `i` and `j`.
    nbi: usize,
    nbj: usize,
    /// Smallest and largest voxel a block of anchors reads, at `(k nbj + bj) nbi + bi`: columns
    /// `8 bi ..= 8 bi + 8` and rows `8 bj ..= 8 bj + 8` of plane `k` (the zeros past the far faces
    /// included).
    lo: Vec<u16>,
    hi: Vec<u16>,
}

impl std::fmt::Debug for SweepVolume {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "SweepVolume {{ axes: {:?}, ni: {}, nj: {}, nk: {} }}",
            self.axes, self.ni, self.nj, self.nk
        )
    }
}

impl SweepVolume {
    /// `vol` in the sweep order of `params` (its slice axis; any view with the same axes shares
    /// it). `None` when the volume's dimensions are not the parameters'.
    pub fn new(params: &FrameParams, vol: &Volume) -> Option<Self> {
        let axes = [params.axis_i, params.axis_j, params.axis_k];
        let (ni, nj, nk) = (params.ni, params.nj, params.nk);
        if vol.dims[axes[0]] != ni || vol.dims[axes[1]] != nj || vol.dims[axes[2]] != nk {
            return None;
        }
        if vol.data.len() != ni * nj * nk {
            return None;
        }
        let strides = [1, vol.dims[0], vol.dims[0] * vol.dims[1]];
        let (si, sj, sk) = (strides[axes[0]], strides[axes[1]], strides[axes[2]]);
        let (pi, pj) = (ni + 1, nj + 1);
        let mut data = vec![0u16; pi * pj * nk];
        data.par_chunks_mut(pi * nk)
            .take(nj)
            .enumerate()
            .for_each(|(j, rows)| {
                for (k, row) in rows.chunks_mut(pi).enumerate() {
                    let base = j * sj + k * sk;
                    if si == 1 {
                        row[..ni].copy_from_slice(&vol.data[base..base + ni]);
                    } else {
                        for (i, v) in row[..ni].iter_mut().enumerate() {
                            *v = vol.data[base + i * si];
                        }
                    }
                }
            });
        let (nbi, nbj) = (ni.div_ceil(BLOCK), nj.div_ceil(BLOCK));
        let mut lo = vec![0u16; nbi * nbj * nk];
        let mut hi = vec![0u16; nbi * nbj * nk];
        lo.par_chunks_mut(nbi * nbj)
            .zip(hi.par_chunks_mut(nbi * nbj))
            .enumerate()
            .for_each(|(k, (lo, hi))| {
                // Per row (the zero row included), per block column: the range of its columns.
                let mut row_lo = vec![0u16; pj * nbi];
                let mut row_hi = vec![0u16; pj * nbi];
                for j in 0..pj {
                    let row = &data[(j * nk + k) * pi..(j * nk + k + 1) * pi];
                    for bi in 0..nbi {
                        let cols = &row[bi * BLOCK..=(bi * BLOCK + BLOCK).min(ni)];
                        row_lo[j * nbi + bi] = cols.iter().copied().min().unwrap_or(0);
                        row_hi[j * nbi + bi] = cols.iter().copied().max().unwrap_or(0);
                    }
                }
                for bj in 0..nbj {
                    for bi in 0..nbi {
                        let rows = bj * BLOCK..=(bj * BLOCK + BLOCK).min(nj);
                        lo[bj * nbi + bi] = rows
                            .clone()
                            .map(|j| row_lo[j * nbi + bi])
                            .min()
                            .unwrap_or(0);
                        hi[bj * nbi + bi] = rows.map(|j| row_hi[j * nbi + bi]).max().unwrap_or(0);
                    }
                }
            });
        Some(Self {
            axes,
            dims: vol.dims,
            ni,
            nj,
            nk,
            data,
            nbi,
            nbj,
            lo,
            hi,
        })
    }

    /// Whether this copy is `vol`'s in the sweep order of `params` (same axes and dimensions).
    pub fn fits(&self, params: &FrameParams, vol: &Volume) -> bool {
        self.axes == [params.axis_i, params.axis_j, params.axis_k] && self.dims == vol.dims
    }

    /// Row `j` (`0 ..= nj`, `nj` the zero row) of plane `k`: `ni + 1` voxels, the last 0.
    #[inline(always)]
    fn row(&self, k: usize, j: usize) -> &[u16] {
        let pi = self.ni + 1;
        let at = (j * self.nk + k) * pi;
        &self.data[at..at + pi]
    }

    /// The voxels back in the volume's order (for the reference; spacing and width are not
    /// kept, and the frame reads neither).
    fn volume(&self) -> Volume {
        let [nx, ny, nz] = self.dims;
        let strides = [1, nx, nx * ny];
        let mut data = vec![0u16; nx * ny * nz];
        for k in 0..self.nk {
            for j in 0..self.nj {
                for (i, &v) in self.row(k, j)[..self.ni].iter().enumerate() {
                    let at = i * strides[self.axes[0]]
                        + j * strides[self.axes[1]]
                        + k * strides[self.axes[2]];
                    data[at] = v;
                }
            }
        }
        Volume {
            dims: self.dims,
            spacing: [1.0; 3],
            bits: 16,
            data,
        }
    }

    /// Whether every voxel of plane `k` is 0.
    fn plane_is_zero(&self, k: usize) -> bool {
        let n = self.nbi * self.nbj;
        self.hi[k * n..(k + 1) * n].iter().all(|&h| h == 0)
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
        m => unreachable!(
            "the fast path renders Mip and Composite, not {m:?}: FrameUnits::fast_path"
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

/// Whether the shader's output depends on a sample's gradient: lit, and the reflectance map not
/// one texel everywhere. A uniform map gives every gradient the zero entry's intensity (its
/// bilinear weights sum to one, and `rnd(t 2^(2f), 2f) = t`), so the shaded colour is a function
/// of the class index alone.
fn gradient_matters(shader: &Shader, mode: ShaderMode) -> bool {
    if !Shader::reads_gradient(mode) {
        return false;
    }
    let rmap = &shader.tables().rmap;
    let z = rmap.zero();
    let side = shader.config().rm_side();
    !(0..6).all(|f| (0..side).all(|j| (0..side).all(|i| rmap.texel(f, i, j) == z)))
}

/// Whether a sample of corrected alpha 0 leaves every coxel of a frame unchanged, whatever came
/// before it (`Compos::step` read rule by rule). `Max`: rule 5 keeps a coxel whose alpha is at
/// least the sample's, and every alpha is at least 0. `FrontToBack`: rule 3 could terminate a
/// coxel whose alpha has reached the threshold without the ray being marked terminated; rule 5
/// marks a ray terminated whenever it brings the alpha to the threshold, and every ray starts at
/// `Coxel::empty` (alpha 0), so that coxel exists only when the threshold is 0. Rule 5's channels
/// are saturated at every write, so a zero weight adds nothing.
fn zero_alpha_is_identity(compos: &Compos, init: &Coxel, mode: ComposMode) -> bool {
    match mode {
        ComposMode::Max => true,
        ComposMode::FrontToBack => init.rgba[3] < compos.regs().et_threshold,
        _ => false,
    }
}

/// Range maximum over a table (sparse table: `levels[l][i]` = max of `2^l` entries from `i`).
struct RangeMax {
    levels: Vec<Vec<u64>>,
}

impl RangeMax {
    fn new(t: &[u64]) -> Self {
        let mut levels = vec![t.to_vec()];
        let mut len = 1;
        while 2 * len <= t.len() {
            let prev = levels.last().unwrap();
            let next: Vec<u64> = (0..=t.len() - 2 * len)
                .map(|i| prev[i].max(prev[i + len]))
                .collect();
            levels.push(next);
            len *= 2;
        }
        Self { levels }
    }

    /// The largest entry of `lo ..= hi`.
    #[inline]
    fn max(&self, lo: usize, hi: usize) -> u64 {
        let n = hi - lo + 1;
        let l = (usize::BITS - 1 - n.leading_zeros()) as usize;
        let t = &self.levels[l];
        t[lo].max(t[hi + 1 - (1 << l)])
    }
}

/// Plane rows of one band of anchor rows: rows `b0 - 1 ..= b0 + BAND` of `S_s`, each with the set
/// of its blocks already interpolated.
struct BandRows {
    b0: isize,
    rows: Vec<u32>,
    done: Vec<u64>,
}

impl BandRows {
    fn new(ni: usize) -> Self {
        Self {
            b0: 0,
            rows: vec![0; (BAND + 2) * ni],
            done: vec![0; BAND + 2],
        }
    }
}

/// What the rows of one slice share.
struct SliceWork<'a> {
    units: &'a FrameUnits,
    sv: &'a SweepVolume,
    /// The corrected alpha of each class index (the compositing unit's `corrected` of the class
    /// entry's alpha): a sample's effect is known before its gradient.
    corrected: &'a [u32],
    /// The corrected alpha and the colours of the shaded sample of each class index, coded for
    /// the compositing unit, when the gradient does not matter (one entry a sample reads).
    flat: Option<&'a [[u32; 4]]>,
    /// The compositing unit's rules of this slice, on lanes.
    rules: LaneRules,
    /// `SampleW - ClassIdxW`: a sample's class index is `sample >> shift`.
    shift: u32,
    /// Per block of this slice: the largest corrected alpha its samples can have.
    amax: &'a [u64],
    /// Per block row of this slice, `live_words` words: bit `c` set when block column `c` can
    /// change a coxel that is not terminated (its largest alpha is above 0, or a zero alpha is
    /// not every coxel's identity). The band visits only these blocks.
    live: &'a [u64],
    live_words: usize,
    /// Samples of corrected alpha 0 are the identity of every coxel.
    zero_ok: bool,
    /// Base-plane column of anchor 0 and row of anchor row 0.
    r0: usize,
    q0: usize,
    k: usize,
    wx: u32,
    wy: u32,
    /// The interpolation's weights of this slice (`wx`, `wy` set up once).
    lerp: InSlice,
    /// Volume slices of `s - 1` and `s + 1` (none outside the sweep).
    k_before: Option<usize>,
    k_after: Option<usize>,
}

impl SliceWork<'_> {
    /// Makes sure block column `c` of anchor row `b` is in the band's plane rows (`b` within
    /// `b0 - 1 ..= b0 + BAND`; rows outside the face are left alone: they read as 0).
    #[inline(always)]
    fn ensure(&self, band: &mut BandRows, b: isize, c: usize) {
        if b < 0 || b >= self.sv.nj as isize {
            return;
        }
        let r = (b - band.b0 + 1) as usize;
        if band.done[r] & (1 << c) != 0 {
            return;
        }
        band.done[r] |= 1 << c;
        let ni = self.sv.ni;
        let (a0, a1) = (c * BLOCK, ((c + 1) * BLOCK).min(ni));
        let top = self.sv.row(self.k, b as usize);
        let bot = self.sv.row(self.k, b as usize + 1);
        let out = &mut band.rows[r * ni + a0..r * ni + a1];
        if a1 - a0 == BLOCK {
            // A whole block: a row of constant length, in lanes.
            out.copy_from_slice(&self.lerp.lanes::<BLOCK>(&top[a0..], &bot[a0..]));
        } else {
            let trilin = &self.units.trilin;
            trilin.row_in_slice(&top[a0..], &bot[a0..], self.wx, self.wy, out);
        }
    }

    /// `S'(t)` at anchors `a0 .. a0 + N` of row `b`: slice `k(t)`'s voxels, slice `s`'s
    /// weights (0 outside).
    #[inline(always)]
    fn other_row<const N: usize>(&self, k: Option<usize>, a0: usize, b: usize) -> [u32; N] {
        match k {
            None => [0; N],
            Some(k) => {
                let (top, bot) = (self.sv.row(k, b), self.sv.row(k, b + 1));
                self.lerp.lanes::<N>(&top[a0..], &bot[a0..])
            }
        }
    }

    /// Anchor rows `b0 ..` against their rows of coxels: lanes `at + db w ..` of `rays` for
    /// anchor row `b0 + db` (`n_rows` rows, `w` coxels each). `LIT`: the shaded colour depends
    /// on the gradient.
    #[inline(always)]
    fn band<const LIT: bool, const AVX2: bool>(
        &self,
        b0: usize,
        rays: &mut RayLanes,
        at: usize,
        (n_rows, w): (usize, usize),
        band: &mut BandRows,
    ) -> SweepStats {
        let (ni, nbi, nw) = (self.sv.ni, self.sv.nbi, self.live_words);
        let mut st = SweepStats::default();
        band.b0 = b0 as isize;
        band.done.fill(0);
        for db in 0..n_rows {
            let b = b0 + db;
            st.samples += ni as u64;
            let bj = b / BLOCK;
            let amax = &self.amax[bj * nbi..(bj + 1) * nbi];
            let live = &self.live[bj * nw..(bj + 1) * nw];
            let row_at = at + db * w + self.r0;
            // The two voxel rows of plane `k` that anchor row `b` reads.
            let rows = (self.sv.row(self.k, b), self.sv.row(self.k, b + 1));
            // The blocks of the row that are not transparent, in order (the others leave every
            // coxel they meet unchanged: `zero_alpha_is_identity`).
            let mut visited = 0;
            for (wi, &word) in live.iter().enumerate() {
                let mut bits = word;
                while bits != 0 {
                    let c = wi * 64 + bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    let am = amax[c];
                    let a0 = c * BLOCK;
                    let len = BLOCK.min(ni - a0);
                    visited += len;
                    let lane = row_at + a0;
                    if len == BLOCK {
                        let at = (a0, lane);
                        self.block::<BLOCK, LIT, AVX2>(band, rays, rows, (b, c), at, am, &mut st);
                    } else {
                        // The last block of a row narrower than a block: lane by lane.
                        for n in 0..len {
                            let at = (a0 + n, lane + n);
                            self.block::<1, LIT, AVX2>(band, rays, rows, (b, c), at, am, &mut st);
                        }
                    }
                }
            }
            st.in_skipped_blocks += (ni - visited) as u64;
        }
        st
    }

    /// Block columns `first ..= last` spanning the live blocks of block rows `bj0 ..= bj1` (`None`:
    /// none is live).
    #[inline(always)]
    fn live_span(&self, bj0: usize, bj1: usize) -> Option<(usize, usize)> {
        let nw = self.live_words;
        let (mut first, mut last) = (usize::MAX, 0);
        for bj in bj0..=bj1 {
            let words = &self.live[bj * nw..(bj + 1) * nw];
            if let Some(wi) = words.iter().position(|&x| x != 0) {
                first = first.min(wi * 64 + words[wi].trailing_zeros() as usize);
            }
            if let Some(wi) = words.iter().rposition(|&x| x != 0) {
                last = last.max(wi * 64 + 63 - words[wi].leading_zeros() as usize);
            }
        }
        (first <= last).then_some((first, last))
    }

    /// Asks the memory for the voxel rows anchor rows `b0 .. b1` of this slice read (rows `b0 ..=
    /// b1` of its plane, and of the neighbour planes when `LIT`), ahead of their use: only the
    /// columns of the live blocks of the anchor rows that read them (a hint; any span is right).
    #[inline(always)]
    fn prefetch<const LIT: bool>(&self, b0: usize, b1: usize) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let (ni, nj) = (self.sv.ni, self.sv.nj);
            // The gradient reads a block's neighbours: one block and one row more each side.
            let (grow, gcol) = if LIT { (2, 1) } else { (1, 0) };
            let ks = [Some(self.k), self.k_after];
            for b in b0..=b1.min(nj) {
                // Voxel row `b` is read by anchor rows `b - grow ..= b + grow - 1`.
                let bj0 = b.saturating_sub(grow) / BLOCK;
                let bj1 = (b + grow - 1).min(nj - 1) / BLOCK;
                let Some((c0, c1)) = self.live_span(bj0, bj1) else {
                    continue;
                };
                let lo = c0.saturating_sub(gcol) * BLOCK;
                let hi = ((c1 + 1 + gcol) * BLOCK).min(ni);
                for k in ks.iter().take(if LIT { 2 } else { 1 }).flatten() {
                    let row = &self.sv.row(*k, b)[lo..=hi];
                    for at in (0..row.len()).step_by(32) {
                        // SAFETY: `_mm_prefetch` only hints the cache; the address is inside
                        // `row`.
                        unsafe { _mm_prefetch::<_MM_HINT_T0>(row[at..].as_ptr().cast()) };
                    }
                }
            }
        }
    }

    /// Anchors `a0 .. a0 + N` of anchor row `b` (in block column `c`) against lanes `lane ..` of
    /// `rays`, whose samples have corrected alphas of at most `am`: skipped when they cannot change
    /// a coxel, else interpolated, classified, shaded where the colour depends on the gradient
    /// (`LIT`) and they change their coxel, and composited.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn block<const N: usize, const LIT: bool, const AVX2: bool>(
        &self,
        band: &mut BandRows,
        rays: &mut RayLanes,
        (top, bot): (&[u16], &[u16]),
        (b, c): (usize, usize),
        (a0, lane): (usize, usize),
        am: u64,
        st: &mut SweepStats,
    ) {
        let units = self.units;
        let rules = &self.rules;
        let (ni, nj) = (self.sv.ni, self.sv.nj);
        // Samples that cannot change a coxel they meet: `leaves_unchanged` holds for their
        // largest alpha, so for every smaller one (rules 1-4 do not read the alpha; rule 5 keeps
        // alpha 0 under `FrontToBack`, anything up to the coxel's under `Max`).
        if (am == 0 && self.zero_ok) || rules.all_unchanged::<N>(rays, lane, am) {
            st.in_skipped_blocks += N as u64;
            return;
        }
        let r = (b as isize - band.b0 + 1) as usize;
        let centre: [u32; N] = if LIT {
            // The gradient reads the in-plane neighbours: the band's plane rows keep them.
            self.ensure(band, b as isize, c);
            band.rows[r * ni + a0..r * ni + a0 + N]
                .try_into()
                .expect("N anchors")
        } else {
            // Nothing else reads these anchors: interpolated straight from the voxel rows.
            self.lerp.lanes::<N>(&top[a0..], &bot[a0..])
        };
        let shift = self.shift;
        // A class index is below the table's length (`SampleW - shift = ClassIdxW` bits); the
        // minimum says so to the compiler, which then checks no bound per lane.
        let last = self.corrected.len() - 1;
        let idx: [usize; N] = std::array::from_fn(|n| ((centre[n] >> shift) as usize).min(last));
        if let Some(flat) = self.flat {
            // Without the gradient: the class entries are the samples' coded alphas and colours.
            let (sa, sc) = flat_entries::<N, AVX2>(&flat[..=last], &idx);
            return rules.step_counted::<N>(rays, lane, &sa, &sc);
        }
        let corrected = &self.corrected[..=last];
        let sa: [u32; N] = std::array::from_fn(|n| corrected[idx[n]]);
        // Only the samples that change their coxel go through gradient and shader; a row without
        // one composites with colours that are not read. (Each way calls `step` with its own
        // colours: one array merged from two ways was split into scalar registers.)
        if !(LIT && rules.any_changes::<N>(rays, lane, &sa)) {
            return rules.step_counted::<N>(rays, lane, &sa, &[[0; N]; 3]);
        }
        if c > 0 {
            self.ensure(band, b as isize, c - 1);
        }
        if (c + 1) * BLOCK < ni {
            self.ensure(band, b as isize, c + 1);
        }
        self.ensure(band, b as isize - 1, c);
        self.ensure(band, b as isize + 1, c);
        // `B = S'(s-1)` and `A = S'(s+1)` of the anchors, in lanes.
        let before = self.other_row::<N>(self.k_before, a0, b);
        let after = self.other_row::<N>(self.k_after, a0, b);
        // The `N6` components `16 (s(+1) - s(-1))` through the adapter's `>> 4`
        // (`n6_components`, `shader_in`): the differences themselves, 0 read past the faces. The
        // magnitude is not computed: the frame never classifies in 2-D. Every lane is shaded; a
        // sample that changes nothing has its colours not read.
        let row = |rr: usize| &band.rows[rr * ni..(rr + 1) * ni];
        let (mid, zeros) = (row(r), [0u32; N]);
        let left = if a0 > 0 { mid[a0 - 1] } else { 0 };
        let right = if a0 + N < ni { mid[a0 + N] } else { 0 };
        let xm = |n: usize| if n == 0 { left } else { centre[n - 1] };
        let xp = |n: usize| if n + 1 == N { right } else { centre[n + 1] };
        let up = if b > 0 {
            &row(r - 1)[a0..a0 + N]
        } else {
            &zeros
        };
        let down = if b + 1 < nj {
            &row(r + 1)[a0..a0 + N]
        } else {
            &zeros
        };
        let diff = |p: u32, m: u32| p as i32 - m as i32;
        let grad: [[i32; N]; 3] = [
            std::array::from_fn(|n| diff(xp(n), xm(n))),
            std::array::from_fn(|n| diff(down[n], up[n])),
            std::array::from_fn(|n| diff(after[n], before[n])),
        ];
        // One copy of the rest per illumination width (a constant in each).
        let shaded = (&centre, &grad, &sa);
        if units.shader.lit_in_32_bits() {
            self.shade_step::<N, AVX2, false>(rays, lane, shaded);
        } else {
            self.shade_step::<N, AVX2, true>(rays, lane, shaded);
        }
    }

    /// Samples `centre` with gradients `grad` and corrected alphas `sa` through the shader
    /// (`WIDE`: illumination in 64-bit lanes), coded and composited onto lanes `lane ..`.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    fn shade_step<const N: usize, const AVX2: bool, const WIDE: bool>(
        &self,
        rays: &mut RayLanes,
        lane: usize,
        (centre, grad, sa): (&[u32; N], &[[i32; N]; 3], &[u32; N]),
    ) {
        // SAFETY: `AVX2` is set only in `sweep_band_avx2`'s copy, which runs only on a CPU with
        // AVX2.
        let rgb = unsafe {
            self.units
                .shader
                .shade_lit_lanes_in::<N, AVX2, WIDE>(centre, grad)
        };
        // `Compos::code` of the colours (its alpha is `sa[n]`: lighting keeps alpha).
        let sc = self.rules.colour_codes(&rgb);
        self.rules.step_counted::<N>(rays, lane, sa, &sc);
    }
}

/// The class entries `flat[idx[n]]` of `N` lanes as rows of lanes: the corrected alphas and the
/// three colour codes (`AVX2` with eight lanes: [`entries_avx2`]).
#[inline(always)]
fn flat_entries<const N: usize, const AVX2: bool>(
    flat: &[[u32; 4]],
    idx: &[usize; N],
) -> ([u32; N], [[u32; N]; 3]) {
    let mut sa = [0u32; N];
    let mut sc = [[0u32; N]; 3];
    #[cfg(target_arch = "x86_64")]
    if AVX2 && N == 8 {
        let idx8: &[usize; 8] = idx.as_slice().try_into().expect("8 lanes");
        // SAFETY: `AVX2` is set only in `sweep_band_avx2`'s copy, which runs only on a CPU with
        // AVX2; `entries_avx2` reads `flat` within its bounds.
        let [a, r, g, bl] = unsafe { entries_avx2(flat, idx8) };
        sa.copy_from_slice(&a[..N]);
        for (sc, e) in sc.iter_mut().zip([r, g, bl]) {
            sc.copy_from_slice(&e[..N]);
        }
        return (sa, sc);
    }
    for n in 0..N {
        let e = flat[idx[n]];
        sa[n] = e[0];
        for ch in 0..3 {
            sc[ch][n] = e[ch + 1];
        }
    }
    (sa, sc)
}

/// One band of the base plane: rows `q ..` (`rows`, `w` coxels each), and the plane rows that its
/// anchor rows read.
struct Band<'a> {
    q: usize,
    /// Not yet written: the band writes every coxel once, at its end.
    rows: &'a mut [std::mem::MaybeUninit<Coxel>],
    w: usize,
    /// Every frame coxel's start (`Coxel::empty`).
    init: Coxel,
    plane: BandRows,
}

/// A band through every swept slice in order: the anchor rows of each slice that feed it.
#[inline(always)]
fn sweep_band<const LIT: bool, const AVX2: bool>(slices: &[SliceWork], band: Band) -> SweepStats {
    let Band {
        q,
        rows,
        w,
        init,
        plane: mut band,
    } = band;
    let mut st = SweepStats::default();
    let n_rows = rows.len() / w;
    let mut rays = RayLanes::new(rows.len());
    // Anchor rows `b` with `q <= b + q0 < q + n_rows`, within `0 .. nj`.
    let rows_of = |work: &SliceWork| {
        let nj = work.sv.nj;
        let b0 = q.saturating_sub(work.q0);
        let b1 = (q + n_rows).saturating_sub(work.q0).min(nj);
        (b0, b1)
    };
    for (n, work) in slices.iter().enumerate() {
        if let Some(next) = slices.get(n + 1) {
            let (b0, b1) = rows_of(next);
            if b0 < b1 {
                next.prefetch::<LIT>(b0, b1);
            }
        }
        let (b0, b1) = rows_of(work);
        if b0 >= b1 {
            continue;
        }
        let at = b0 + work.q0 - q;
        st = st.add(work.band::<LIT, AVX2>(b0, &mut rays, at * w, (b1 - b0, w), &mut band));
    }
    rays.write(&init, rows);
    let k = rays.row_counts();
    st.shaded += k.shaded;
    st.without_effect += k.without_effect;
    st.after_termination += k.after_termination;
    st.rays_terminated = rays.term.iter().filter(|&&t| t != 0).count() as u64;
    st
}

/// [`sweep_band`] compiled for AVX2: the same code, so the same bits, in wider vector
/// instructions (the 32-bit lane products of the interpolation and the compositing have no
/// SSE2 instruction).
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn sweep_band_avx2<const LIT: bool>(slices: &[SliceWork], band: Band) -> SweepStats {
    sweep_band::<LIT, true>(slices, band)
}

/// The class entries `flat[idx[n]]` of eight lanes as four rows of lanes (corrected alpha and
/// the three colour codes): four 256-bit loads of two entries each and a 4 x 4 transpose in both
/// halves, instead of 32 scalar moves. A gather only: the same values as the scalar loop.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn entries_avx2(flat: &[[u32; 4]], idx: &[usize; 8]) -> [[u32; 8]; 4] {
    use std::arch::x86_64::*;
    let last = flat.len() - 1;
    // Entry `n` as 128 bits (an index past the table reads its last entry: never, the indices
    // are clamped already).
    let e = |n: usize| {
        let entry = &flat[idx[n].min(last)];
        // SAFETY: `entry` is 16 readable bytes; `loadu` takes any alignment.
        unsafe { _mm_loadu_si128(entry.as_ptr().cast()) }
    };
    // Lanes 0-3 in the low halves, 4-7 in the high ones.
    let r04 = _mm256_set_m128i(e(4), e(0));
    let r15 = _mm256_set_m128i(e(5), e(1));
    let r26 = _mm256_set_m128i(e(6), e(2));
    let r37 = _mm256_set_m128i(e(7), e(3));
    // Per half: `e0.0 e1.0 e0.1 e1.1`, `e0.2 e1.2 e0.3 e1.3`, the same of `e2`, `e3`.
    let t0 = _mm256_unpacklo_epi32(r04, r15);
    let t1 = _mm256_unpackhi_epi32(r04, r15);
    let t2 = _mm256_unpacklo_epi32(r26, r37);
    let t3 = _mm256_unpackhi_epi32(r26, r37);
    // Field `f` of entries 0-3 | 4-7.
    let rows = [
        _mm256_unpacklo_epi64(t0, t2),
        _mm256_unpackhi_epi64(t0, t2),
        _mm256_unpacklo_epi64(t1, t3),
        _mm256_unpackhi_epi64(t1, t3),
    ];
    let mut out = [[0u32; 8]; 4];
    for (o, r) in out.iter_mut().zip(rows) {
        // SAFETY: `o` is 32 writable bytes; `storeu` takes any alignment.
        unsafe { _mm256_storeu_si256(o.as_mut_ptr().cast(), r) };
    }
    out
}

/// Set by a test: every sweep takes the portable code even where the CPU has AVX2, so that the
/// code a CPU without AVX2 runs is checked against the reference on any machine (both give the
/// same bits, so a sweep running beside that test is not disturbed).
#[cfg(test)]
static PORTABLE_ONLY: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// [`sweep_band`], in AVX2 where the CPU has it.
fn sweep_band_dispatch<const LIT: bool>(slices: &[SliceWork], band: Band) -> SweepStats {
    #[cfg(test)]
    if PORTABLE_ONLY.load(std::sync::atomic::Ordering::Relaxed) {
        return sweep_band::<LIT, false>(slices, band);
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (detected just above), `sweep_band_avx2`'s one requirement.
        return unsafe { sweep_band_avx2::<LIT>(slices, band) };
    }
    sweep_band::<LIT, false>(slices, band)
}

/// The base-plane image of a frame and the counts of what its sweep computed and skipped,
/// bit-exact with `cube5_frame` (docs/numerics/frame.md): the fast path, equal to
/// [`render_base_plane_reference`] coxel for coxel (`super::render_base_plane_stats` of a frame
/// the fast path covers).
pub fn render_base_plane_stats(
    params: &FrameParams,
    vol: &Volume,
    units: &FrameUnits,
) -> (BasePlane, SweepStats) {
    match SweepVolume::new(params, vol) {
        Some(sv) => render_sweep(params, &sv, units),
        None => {
            // Not a volume of these parameters: only the reference reads it (as zeros outside).
            let bp = render_base_plane_reference(params, vol, units);
            let anchors = params.samples() as u64;
            let stats = SweepStats {
                anchors,
                samples: anchors,
                shaded: anchors,
                rays_terminated: bp.coxels.iter().filter(|c| c.terminated).count() as u64,
                ..SweepStats::default()
            };
            (bp, stats)
        }
    }
}

/// [`render_base_plane_stats`] on a volume already in the sweep's order (`SweepVolume::new` of
/// the frame's volume for these parameters; one with other axes or dimensions is refused by a
/// panic, as a programming error).
pub fn render_sweep(
    params: &FrameParams,
    sv: &SweepVolume,
    units: &FrameUnits,
) -> (BasePlane, SweepStats) {
    assert!(
        units.fast_path(),
        "render_sweep: {:?} (tf2d {}) is not a fast-path frame",
        units.mode,
        units.tf2d
    );
    assert!(
        sv.axes == [params.axis_i, params.axis_j, params.axis_k]
            && [sv.ni, sv.nj, sv.nk] == [params.ni, params.nj, params.nk],
        "render_sweep: {sv:?} is not in the sweep order of {params:?}"
    );
    let anchors = params.samples() as u64;
    let (ni, nk) = (params.ni, params.nk);
    let (w, h) = params.base_plane_size();
    let ((_, max_sx), (_, max_sy)) = params.shift_range();
    let init = Coxel::empty(&units.compos.config());
    let (smode, cmode) = modes(units.mode);
    let ww = units.trilin.config().weight_w;
    let weight = |f: u32| f >> (STEP_W - ww);
    let scfg = units.shader.config();
    let shift = scfg.sample_w() - scfg.class_idx_w;
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
    let range_max = RangeMax::new(&corrected);
    let lit = gradient_matters(&units.shader, smode);
    // Without the gradient, a sample's way through the shader and the compositing unit's coding
    // is a function of its class index: the units' own outputs, once per index.
    let flat: Option<Vec<[u32; 4]>> = (!lit).then(|| {
        (0..corrected.len())
            .map(|idx| {
                let e = units.shader.shade(&class_in((idx as u32) << shift, smode));
                let [r, g, b] = lanes::colours(&units.compos.code(&Sample {
                    rgb: [e.r, e.g, e.b],
                    alpha: e.a,
                    depth: 0,
                    mode: cmode,
                }));
                [corrected[idx] as u32, r, g, b]
            })
            .collect()
    });
    // The corrected alphas in lanes (`<= 2^Q`).
    let corrected32: Vec<u32> = corrected.iter().map(|&a| a as u32).collect();
    let zero_ok = zero_alpha_is_identity(&units.compos, &init, cmode);
    // A voxel range's class indices (samples lie between their corners' smallest and largest).
    let frac = units.trilin.config().frac_w;
    let idx_of = |v: u16| ((u32::from(v) << frac) >> shift) as usize;

    // Leading and trailing slices with every voxel 0 (their samples, and their neighbours' reads
    // of them, are 0 with or without them), left out when a zero sample is every coxel's identity.
    let zero_sample = units.trilin.sample_in_slice([0; 4], 0, 0);
    let alpha0 = corrected[(zero_sample >> shift) as usize];
    let (front_zero, back_zero) = if zero_ok && alpha0 == 0 {
        let front = (0..nk)
            .take_while(|&s| sv.plane_is_zero(params.slice(s).k))
            .count();
        let back = if front == nk {
            0
        } else {
            (0..nk)
                .rev()
                .take_while(|&s| sv.plane_is_zero(params.slice(s).k))
                .count()
        };
        (front, back)
    } else {
        (0, 0)
    };

    let mut stats = SweepStats {
        anchors,
        slices_skipped: (front_zero, back_zero),
        ..SweepStats::default()
    };
    let swept = front_zero..nk - back_zero;
    // Per swept slice, per block: the largest corrected alpha its samples can have.
    let nb = sv.nbi * sv.nbj;
    let mut amax = vec![0u64; swept.len() * nb];
    amax.par_chunks_mut(nb).enumerate().for_each(|(n, amax)| {
        let k = params.slice(front_zero + n).k;
        let (lo, hi) = (&sv.lo[k * nb..(k + 1) * nb], &sv.hi[k * nb..(k + 1) * nb]);
        for (m, (&lo, &hi)) in amax.iter_mut().zip(lo.iter().zip(hi)) {
            *m = range_max.max(idx_of(lo), idx_of(hi));
        }
    });
    // Per swept slice, per block row: the blocks a band visits (bit `c` of word `c / 64`).
    let live_words = sv.nbi.div_ceil(64);
    let nl = sv.nbj * live_words;
    let mut live = vec![0u64; swept.len() * nl];
    for (live, amax) in live.chunks_exact_mut(nl).zip(amax.chunks_exact(nb)) {
        for (bj, row) in amax.chunks_exact(sv.nbi).enumerate() {
            for (c, &am) in row.iter().enumerate() {
                if am != 0 || !zero_ok {
                    live[bj * live_words + c / 64] |= 1 << (c % 64);
                }
            }
        }
    }
    // The lanes code the shader's colours as the compositing unit's (`LaneRules::colour_codes`):
    // one `ColorW` for both, as every frame configuration has it.
    let same_colours = scfg.color_w == units.compos.config().color_w;
    let slices: Option<Vec<SliceWork>> = swept
        .clone()
        .zip(amax.chunks_exact(nb).zip(live.chunks_exact(nl)))
        .map(|(s, (amax, live))| {
            let c = params.slice(s);
            same_colours.then_some(())?;
            Some(SliceWork {
                units,
                sv,
                corrected: &corrected32,
                flat: flat.as_deref(),
                rules: LaneRules::new(&units.compos, cmode, s as u32)?,
                shift,
                amax,
                live,
                live_words,
                zero_ok,
                r0: (max_sx - c.shift_x) as usize,
                q0: (max_sy - c.shift_y) as usize,
                k: c.k,
                wx: weight(c.frac_x),
                wy: weight(c.frac_y),
                lerp: units.trilin.in_slice(weight(c.frac_x), weight(c.frac_y)),
                k_before: (s > 0).then(|| params.slice(s - 1).k),
                k_after: (s + 1 < nk).then(|| params.slice(s + 1).k),
            })
        })
        .collect();
    let Some(slices) = slices else {
        // Not a mode the lanes take (the frame's modes always are): the reference.
        let bp = render_base_plane_reference(params, &sv.volume(), units);
        return (bp, stats);
    };
    // Bands of base-plane rows in parallel, each through every slice in order (a ray's samples
    // arrive in slice order; anchor row `b` of slice `s` feeds row `b + q0(s)` only, so no two
    // bands share a coxel): one parallel split per frame, and a band's coxels stay in the
    // thread's cache across the slices. One copy of the band loop per mode and lighting, so that
    // the units' mode branches fold away.
    // The base plane is not filled first (8 MB a frame at 256^3, on one thread): each band writes
    // its rows once, at its end.
    let mut coxels: Vec<Coxel> = Vec::with_capacity(w * h);
    let part = coxels.spare_capacity_mut()[..w * h]
        .par_chunks_mut(BAND * w)
        .enumerate()
        .map(|(n, rows)| {
            let band = Band {
                q: n * BAND,
                rows,
                w,
                init,
                plane: BandRows::new(ni),
            };
            if lit {
                sweep_band_dispatch::<true>(&slices, band)
            } else {
                sweep_band_dispatch::<false>(&slices, band)
            }
        })
        .reduce(SweepStats::default, SweepStats::add);
    // SAFETY: the chunks cover the first `w h` elements of the capacity, and every band wrote
    // each element of its chunk (`RayLanes::write` of the band's whole slice).
    unsafe { coxels.set_len(w * h) };
    stats = stats.add(part);
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

    /// The compositing unit's registers with early termination at the default threshold, off,
    /// and at threshold 0 (a sample ends every ray it meets).
    pub(super) fn thresholds(cfg: &crate::units::cube5_compos::ComposConfig) -> [ComposRegs; 3] {
        [
            ComposRegs::defaults(cfg),
            ComposRegs::without_termination(cfg),
            ComposRegs {
                et_threshold: 0,
                ..ComposRegs::defaults(cfg)
            },
        ]
    }

    /// The seed of the random views: `CUBE5_SEED` or a fixed default, printed on failure.
    pub(super) fn seed() -> u64 {
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
        let mut v = crate::camera::FACE_DIRECTIONS.to_vec();
        v.extend([
            [1.0, 0.0, 1.0],
            [-1.0, 1.0, 0.0],
            [1.0, -1.0, -1.0],
            [-0.37, 0.81, -1.0],
        ]);
        for _ in 0..n_random {
            v.push(std::array::from_fn(|_| rng.random_range(-1.0..1.0)));
        }
        v
    }

    /// The fast path and the reference render `vol` alike from view `v` at `p` pipelines in
    /// `mode`, early termination at `et` (`None`: off); returns the fast path's stats.
    fn check_one(
        what: &str,
        vol: &Volume,
        cfg: &FrameConfig,
        tf: &TransferFunction,
        et: Option<f64>,
        view: ([f64; 3], usize, FrameMode),
    ) -> SweepStats {
        check_one_lit(what, vol, cfg, tf, et, view, true)
    }

    /// [`check_one`] lit by the headlight (`lit`) or unlit (a reflectance map of 1 everywhere,
    /// as a scene with `shading = false` makes it).
    fn check_one_lit(
        what: &str,
        vol: &Volume,
        cfg: &FrameConfig,
        tf: &TransferFunction,
        et: Option<f64>,
        (v, p, mode): ([f64; 3], usize, FrameMode),
        lit: bool,
    ) -> SweepStats {
        let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(v), p).unwrap();
        let params = setup.params;
        let mut phong = frame_phong(&params, &[]);
        if !lit {
            (phong.ambient, phong.diffuse, phong.specular) = (1.0, 0.0, 0.0);
        }
        let units = FrameUnits::with_config(cfg, mode, &setup, tf, &phong, et).unwrap();
        let want = render_base_plane_reference(&params, vol, &units);
        let (got, st) = render_base_plane_stats(&params, vol, &units);
        assert_eq!((got.width, got.height), (want.width, want.height));
        if let Some(i) = (0..want.coxels.len()).find(|&i| got.coxels[i] != want.coxels[i]) {
            panic!(
                "{what}, view {v:?}, P {p}, {mode:?}, termination {et:?} (CUBE5_SEED={}): coxel \
                 ({}, {}) is {:?}, the reference {:?}",
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
            st.shaded + st.without_effect + st.after_termination + st.in_skipped_blocks,
            st.samples
        );
        let reached = got.coxels.iter().filter(|c| c.terminated).count() as u64;
        assert_eq!(st.rays_terminated, reached);
        st
    }

    /// [`check_one_lit`] composite lit and unlit at each termination of `ets`, then MIP, from
    /// view `v` at `p` pipelines; returns the summed stats.
    fn check_modes(
        what: &str,
        vol: &Volume,
        cfg: &FrameConfig,
        tf: &TransferFunction,
        ets: &[Option<f64>],
        (v, p): ([f64; 3], usize),
    ) -> SweepStats {
        let mut total = SweepStats::default();
        for &et in ets {
            for lit in [true, false] {
                let view = (v, p, FrameMode::Composite);
                total = total.add(check_one_lit(what, vol, cfg, tf, et, view, lit));
            }
        }
        total.add(check_one(what, vol, cfg, tf, None, (v, p, FrameMode::Mip)))
    }

    /// [`check_one`] from every view, P = 1, 4, 8 in turn, MIP and composite; returns the summed
    /// stats (to check that the skips were exercised).
    fn check_equal(
        what: &str,
        vol: &Volume,
        cfg: &FrameConfig,
        tf: &TransferFunction,
        early_termination: Option<f64>,
        views: &[[f64; 3]],
    ) -> SweepStats {
        let mut total = SweepStats::default();
        for (n, v) in views.iter().enumerate() {
            let p = [1, 4, 8][n % 3];
            if vol.dims.iter().any(|d| d % p != 0) {
                continue;
            }
            for mode in [FrameMode::Mip, FrameMode::Composite] {
                let st = check_one(what, vol, cfg, tf, early_termination, (*v, p, mode));
                total = total.add(st);
                total.slices_skipped.0 += st.slices_skipped.0 + st.slices_skipped.1;
            }
        }
        total
    }

    /// `vol` with every voxel at least `floor` (no block of zeros left).
    fn lifted(vol: &Volume, floor: u16) -> Volume {
        let data = vol.data.iter().map(|&v| v.max(floor)).collect();
        Volume::new(vol.dims, vol.spacing, vol.bits, data).unwrap()
    }

    /// The portable sweep (what a CPU without AVX2 runs; this machine may take the AVX2 code
    /// everywhere else): lit composite and MIP, unlit composite, from faces, 45 degrees and random views,
    /// with early termination, equal to the reference.
    #[test]
    fn portable_sweep_equals_the_reference() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed() + 9);
        let vs = views(2, &mut rng);
        let head = head_phantom(32, 12).unwrap();
        let tf = TransferFunction::head_default();
        super::PORTABLE_ONLY.store(true, std::sync::atomic::Ordering::Relaxed);
        let cfg = FrameConfig::DEFAULT;
        let mut st = check_equal("head, portable", &head, &cfg, &tf, Some(ET_DEFAULT), &vs);
        for (n, v) in vs.iter().enumerate() {
            let view = (*v, [1, 4, 8][n % 3], FrameMode::Composite);
            st = st.add(check_one_lit(
                "head unlit, portable",
                &head,
                &cfg,
                &tf,
                None,
                view,
                false,
            ));
        }
        super::PORTABLE_ONLY.store(false, std::sync::atomic::Ordering::Relaxed);
        assert!(st.shaded > 0, "{st:?}");
    }

    /// The sweep's block skipping, directed: a transfer function with transparent bands over a
    /// volume without a zero voxel (only the classification can make a block transparent), early
    /// termination at several thresholds, and MIP over a volume whose every block has some
    /// alpha (only the rays' maxima can make a block skippable). Each equals the reference and
    /// each skips blocks.
    #[test]
    fn block_skipping_equals_the_reference() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed() + 2);
        let vs = views(4, &mut rng);
        let cfg = FrameConfig::DEFAULT;
        let head = head_phantom(32, 12).unwrap();
        let p = |density, rgba| crate::transfer::TfPoint { density, rgba };
        let band = TransferFunction {
            points: vec![
                p(0.0, [0.0; 4]),
                p(0.45, [0.9, 0.8, 0.7, 0.0]),
                p(0.5, [0.9, 0.8, 0.7, 0.4]),
                p(0.55, [0.9, 0.8, 0.7, 0.0]),
                p(0.8, [0.9, 0.9, 0.9, 0.0]),
                p(0.9, [0.9, 0.9, 0.9, 0.6]),
                p(1.0, [0.9, 0.9, 0.9, 0.6]),
            ],
        };
        let no_zeros = lifted(&head, 40);
        for et in [None, Some(ET_DEFAULT)] {
            let st = check_equal("lifted head, bands", &no_zeros, &cfg, &band, et, &vs);
            assert!(st.in_skipped_blocks > 0 && st.shaded > 0, "{st:?}");
        }
        // Early termination at several thresholds (0: every ray ends at its first sample).
        let tf = TransferFunction::head_default();
        let opaque = TransferFunction::preset("iso").unwrap();
        for t in [0.0, 0.05, 0.3, 0.7, 0.9, ET_DEFAULT] {
            let mut st = SweepStats::default();
            for (name, tf) in [("head", &tf), ("head, iso", &opaque)] {
                for (n, v) in vs.iter().enumerate() {
                    let p = [1, 4, 8][n % 3];
                    let one = check_one(
                        name,
                        &head,
                        &cfg,
                        tf,
                        Some(t),
                        (*v, p, FrameMode::Composite),
                    );
                    st = st.add(one);
                }
            }
            assert!(
                st.rays_terminated > 0 && st.after_termination > 0,
                "{t}: {st:?}"
            );
            if t > 0.0 {
                assert!(st.in_skipped_blocks > 0, "{t}: {st:?}");
            }
        }
        // MIP: every block has alpha above 0 (voxels >= 256 classify above index 0), so only the
        // maxima already on the rays let a block go.
        let bright = lifted(&head, 256);
        let mut st = SweepStats::default();
        for (n, v) in vs.iter().enumerate() {
            st = st.add(check_one(
                "bright head, MIP",
                &bright,
                &cfg,
                &tf,
                None,
                (*v, [1, 4, 8][n % 3], FrameMode::Mip),
            ));
        }
        assert!(st.in_skipped_blocks > 0 && st.shaded > 0, "{st:?}");
    }

    /// Random transfer functions (transparent bands of random width between random colours and
    /// alphas, some opaque enough to end rays) over a volume with empty blocks and empty margins,
    /// from faces (both sweep directions), 45 degrees and random views: MIP, composite lit and
    /// unlit, with and without early termination at random thresholds. A block skipped, a row of
    /// blocks left out or a ray ended that the reference would change shows as a coxel that
    /// differs.
    #[test]
    fn random_transfer_functions_equal_the_reference() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed() + 5);
        let cfg = FrameConfig::DEFAULT;
        // The head inside a larger box: empty blocks around it, and a bright cube with a hole in
        // one corner (blocks opaque next to blocks empty).
        let mut vol = window(
            &head_phantom(24, 12).unwrap(),
            [-4, -2, -6],
            [32, 28, 36],
            [1.0; 3],
        );
        for z in 26..34 {
            for y in 2..10 {
                for x in 22..30 {
                    if (x + y + z) % 5 != 0 {
                        let at = (z * 28 + y) * 32 + x;
                        vol.data[at] = 3000 + ((x * 37 + y * 11) % 900) as u16;
                    }
                }
            }
        }
        let p = |density, rgba| crate::transfer::TfPoint { density, rgba };
        let vs = views(3, &mut rng);
        let mut total = SweepStats::default();
        for n in 0..6 {
            let mut densities: Vec<f64> = (0..rng.random_range(2..7))
                .map(|_| rng.random_range(0.02..0.98))
                .collect();
            densities.sort_by(f64::total_cmp);
            let mut points = vec![p(0.0, [0.0; 4])];
            for d in densities {
                let alpha = match rng.random_range(0..3) {
                    0 => 0.0,
                    1 => rng.random_range(0.0..0.2),
                    _ => rng.random_range(0.5..1.0),
                };
                let [r, g, b] = std::array::from_fn(|_| rng.random_range(0.0..1.0));
                points.push(p(d, [r, g, b, alpha]));
            }
            points.push(p(1.0, [1.0, 1.0, 1.0, rng.random_range(0.0..1.0)]));
            let tf = TransferFunction { points };
            for (m, v) in vs.iter().enumerate() {
                let pipes = [1, 4][(n + m) % 2];
                let et = [None, Some(rng.random_range(0.3..1.0))][(n + m) % 2];
                let st = check_modes("random TF", &vol, &cfg, &tf, &[et], (*v, pipes));
                total = total.add(st);
            }
        }
        assert!(
            total.in_skipped_blocks > 0
                && total.shaded > 0
                && total.without_effect > 0
                && total.after_termination > 0,
            "{total:?}"
        );
    }

    /// The block skipping's premise: `Compos::leaves_unchanged_corrected` is monotone in the
    /// alpha (true for alpha `a` implies true for every smaller one) under the frame's modes.
    #[test]
    fn leaves_unchanged_is_monotone_in_alpha() {
        use crate::units::cube5_compos::{ComposConfig, OpacityLut};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed() + 3);
        let cfg = ComposConfig::DEFAULT;
        let one = cfg.one();
        for regs in thresholds(&cfg) {
            let c = Compos::new(cfg, OpacityLut::new(1.0, &cfg).unwrap(), regs).unwrap();
            for _ in 0..50_000 {
                let coxel = Coxel {
                    rgba: std::array::from_fn(|_| match rng.random_range(0..3) {
                        0 => 0,
                        1 => rng.random_range(0..=one),
                        _ => rng.random_range(0..=cfg.chan_max()),
                    }),
                    z: if rng.random_bool(0.8) {
                        cfg.z_none()
                    } else {
                        rng.random_range(0..=cfg.z_none())
                    },
                    geo: [0; 3],
                    terminated: rng.random_bool(0.2),
                };
                let depth = rng.random_range(0..=cfg.z_none());
                let top = 1u64 << cfg.q();
                let hi = match rng.random_range(0..3) {
                    0 => 0,
                    _ => rng.random_range(0..=top),
                };
                let lo = rng.random_range(0..=hi);
                for mode in [ComposMode::FrontToBack, ComposMode::Max] {
                    if c.leaves_unchanged_corrected(&coxel, hi, depth, mode) {
                        assert!(
                            c.leaves_unchanged_corrected(&coxel, lo, depth, mode),
                            "{mode:?} {coxel:?} {lo} {hi}"
                        );
                    }
                }
            }
        }
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
        let mut total = check_equal("head 24^3", &head, &cfg, &tf, None, &vs);
        let noncubic = window(&head, [0, 4, -4], [24, 16, 32], [1.0; 3]);
        total = total.add(check_equal(
            "head 24x16x32",
            &noncubic,
            &cfg,
            &tf,
            None,
            &vs,
        ));
        let aniso = window(&head, [4, 0, 2], [16, 24, 16], [1.0, 0.7, 1.6]);
        total = total.add(check_equal(
            "head anisotropic",
            &aniso,
            &cfg,
            &tf,
            None,
            &vs,
        ));
        // Empty slices around the data on every side: the skipping.
        let padded = window(
            &head_phantom(16, 12).unwrap(),
            [-4, -8, -8],
            [24, 32, 32],
            [1.0; 3],
        );
        let st = check_equal("head padded", &padded, &cfg, &tf, None, &vs);
        assert!(st.slices_skipped.0 > 0, "no slice skipped: {st:?}");
        total = total.add(st);
        let iso = TransferFunction::preset("iso").unwrap();
        for (name, vol) in [
            ("sphere", sphere_phantom(16, 12).unwrap()),
            ("bubbles", bubbles_phantom(16, 12).unwrap()),
        ] {
            total = total.add(check_equal(name, &vol, &cfg, &iso, None, &vs[..8]));
        }
        // Early termination: opaque surfaces end rays.
        let mut et = SweepStats::default();
        for (name, vol, tf) in [
            ("sphere, ET", sphere_phantom(24, 12).unwrap(), &iso),
            ("head, ET", head.clone(), &tf),
        ] {
            let st = check_equal(name, &vol, &cfg, tf, Some(ET_DEFAULT), &vs);
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
        total = total.add(check_equal("noise", &noise, &cfg, &grey, None, &vs[..8]));
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
            for et in [None, Some(ET_DEFAULT)] {
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

    /// An MRI-like volume (the head phantom with a smooth bias field and seeded noise, so that
    /// no voxel is 0 and most blocks are neither empty nor opaque), rows not a whole number of
    /// blocks (20 x 28 x 36: the last block of a row goes lane by lane), random views, MIP and
    /// composite lit and unlit (the shaded and the flat path), with and without early
    /// termination: the fast path equals the reference.
    #[test]
    fn fast_path_equals_the_reference_on_an_mri_like_volume() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed() + 4);
        let head = head_phantom(32, 12).unwrap();
        let dims = [20, 28, 36];
        let mut data = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let v = head.get(x as i64 + 6, y as i64 + 2, z as i64 - 2) as f64;
                    let bias = 1.0 + 0.2 * ((x + 2 * y) as f64 / 20.0).sin();
                    let noise = rng.random_range(0.0..300.0);
                    data.push((v * bias + noise).clamp(1.0, 4095.0) as u16);
                }
            }
        }
        let mri = Volume::new(dims, [1.0, 1.0, 1.3], 12, data).unwrap();
        let vs = views(6, &mut rng);
        let tf = TransferFunction::head_default();
        let cfg = FrameConfig::DEFAULT;
        let mut total = SweepStats::default();
        for (n, v) in vs.iter().enumerate() {
            let ets = [None, Some(ET_DEFAULT)];
            let st = check_modes("MRI-like", &mri, &cfg, &tf, &ets, (*v, [1, 4][n % 2]));
            total = total.add(st);
        }
        assert!(
            total.shaded > 0 && total.without_effect > 0 && total.in_skipped_blocks > 0,
            "{total:?}"
        );
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
        assert!(super::super::render_base_plane(&setup.params, &vol, &units) == want);
    }
}
