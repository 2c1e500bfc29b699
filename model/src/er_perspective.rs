//! ER-Perspective (patent [155]-[197]): perspective in slice order with exponential regions and
//! Bartlett ray merging, written from `docs/numerics/er_perspective.md`.
//!
//! The volume is swept slice by slice, back to front, with rays cast from the eye. The sweep is cut
//! into regions at distances `e 2^r` from the eye (`e`: the eye's distance to the first slice); in
//! region `r` the rays are `1/rho` voxels apart at its rear and half that at its front, so every
//! slice is sampled by between `N^2` and `4 N^2` rays ([195]). At each region boundary every ray of
//! the nearer region takes the 3 x 3 Bartlett (tent) filter of the farther region's rays around its
//! continuation ([169]). Samples go through the frame's unit models (`cube5_trilin` bilinear on the
//! slice, `cube5_gradient` N6, `cube5_shader`, `cube5_compos` back to front or MIP), so a frame
//! extension of the RTL can be bit-exact with [`render_er`]. [`render_er_f64`] is the f64 reference
//! of the same algorithm (the fixed point's error); the f64 perspective reference renderer
//! (`render::render_reference`) measures the scheme's.

use crate::error::{ModelError, Result};
use crate::render::{image_of, perspective_eye, CompositeMode, ImageF64, Projection, RenderParams};
use crate::scene_render::{at_voxel_width, params_phong};
use crate::transfer::TransferFunction;
use crate::units::cube5_compos::{corrected_alpha, ComposMode, Coxel, OpacityLut};
use crate::units::cube5_frame::{
    shade_n6, FrameConfig, FrameMode, FrameParams, FrameSetup, FrameUnits, N6_OFFSETS, STEP_W,
};
use crate::units::cube5_pwarp::Projective;
use crate::units::cube5_shader::{Phong, ShaderIn, ShaderMode};
use crate::units::cube5_trilin::Trilin;
use crate::volume::Volume;
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicU64, Ordering};

/// Largest `log2` of the base rate (rays per voxel at a region's rear): 1, 2 or 4 rays.
pub const MAX_RATE_LOG2: u32 = 2;

/// How the rays of a region are merged into the next nearer region's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum ErMerge {
    /// The patent's 3 x 3 Bartlett (tent) filter, weights (1, 2, 1) x (1, 2, 1) / 16.
    #[default]
    Bartlett,
    /// What-if: the continuing ray keeps its own coxel, its neighbours are dropped (no filter).
    Centre,
}

impl ErMerge {
    pub fn name(self) -> &'static str {
        match self {
            Self::Bartlett => "bartlett",
            Self::Centre => "centre",
        }
    }
}

/// The knobs of ER-perspective.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ErScheme {
    /// Rays per voxel (each direction) at a region's rear: 1, 2 or 4 (`rho`).
    pub rays_per_voxel: u32,
    pub merge: ErMerge,
}

impl Default for ErScheme {
    fn default() -> Self {
        Self {
            rays_per_voxel: 1,
            merge: ErMerge::Bartlett,
        }
    }
}

impl ErScheme {
    pub fn validate(&self) -> Result<()> {
        if ![1, 2, 4].contains(&self.rays_per_voxel) {
            return Err(ModelError::Config(format!(
                "rays_per_voxel {}: must be 1, 2 or 4",
                self.rays_per_voxel
            )));
        }
        Ok(())
    }

    fn rate_log2(&self) -> u32 {
        self.rays_per_voxel.trailing_zeros().min(MAX_RATE_LOG2)
    }

    /// One phrase for `plan:` and the tables.
    pub fn describe(&self) -> String {
        format!(
            "{} ray{} per voxel at each region's rear, {} merge",
            self.rays_per_voxel,
            if self.rays_per_voxel == 1 { "" } else { "s" },
            self.merge.name()
        )
    }
}

/// A rectangle of rays `(m, n)`, inclusive bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Extent {
    pub m0: i64,
    pub m1: i64,
    pub n0: i64,
    pub n1: i64,
}

impl Extent {
    pub fn width(&self) -> usize {
        (self.m1 - self.m0 + 1).max(0) as usize
    }
    pub fn height(&self) -> usize {
        (self.n1 - self.n0 + 1).max(0) as usize
    }
    pub fn count(&self) -> u64 {
        (self.width() * self.height()) as u64
    }
    fn union(&self, o: &Extent) -> Extent {
        Extent {
            m0: self.m0.min(o.m0),
            m1: self.m1.max(o.m1),
            n0: self.n0.min(o.n0),
            n1: self.n1.max(o.n1),
        }
    }
    /// The rays of the nearer region that a merge of this extent writes.
    fn merged(&self) -> Extent {
        let ceil2 = |x: i64| -((-x).div_euclid(2));
        Extent {
            m0: ceil2(self.m0 - 1),
            m1: (self.m1 + 1).div_euclid(2),
            n0: ceil2(self.n0 - 1),
            n1: (self.n1 + 1).div_euclid(2),
        }
    }
    fn index(&self, m: i64, n: i64) -> Option<usize> {
        (m >= self.m0 && m <= self.m1 && n >= self.n0 && n <= self.n1)
            .then(|| (n - self.n0) as usize * self.width() + (m - self.m0) as usize)
    }
}

/// The regions and the rays of every slice (contract: *Regions*, *Rays and their positions*).
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Region of slice `s`.
    pub region: Vec<u32>,
    /// Rays sampling slice `s`.
    pub rays: Vec<Extent>,
    /// The coxel buffer of region `r`.
    pub extent: Vec<Extent>,
}

impl Layout {
    fn new(region: Vec<u32>, rays: Vec<Extent>) -> Self {
        let regions = region.last().map_or(0, |&r| r as usize + 1);
        let mut own: Vec<Option<Extent>> = vec![None; regions];
        for (r, e) in region.iter().zip(&rays) {
            let slot = &mut own[*r as usize];
            *slot = Some(slot.map_or(*e, |o| o.union(e)));
        }
        let mut extent = vec![rays[0]; regions];
        let mut behind: Option<Extent> = None;
        for r in (0..regions).rev() {
            let e = match (own[r], behind) {
                (Some(a), Some(b)) => a.union(&b.merged()),
                (Some(a), None) => a,
                (None, Some(b)) => b.merged(),
                (None, None) => rays[0],
            };
            extent[r] = e;
            behind = Some(e);
        }
        Self {
            region,
            rays,
            extent,
        }
    }

    pub fn regions(&self) -> usize {
        self.extent.len()
    }

    /// Samples taken in each slice (processing order, `s = 0` nearest the eye).
    pub fn samples_per_slice(&self) -> Vec<u64> {
        self.rays.iter().map(Extent::count).collect()
    }
}

/// The host's set-up of one ER-perspective frame.
#[derive(Debug, Clone)]
pub struct ErSetup {
    /// The frame set-up of the central view direction: axes, sweep sense, opacity ratio.
    pub frame: FrameSetup,
    pub scheme: ErScheme,
    /// The eye in voxel units, frame axes: lateral `(e_i, e_j)` and distance `e` to slice 0.
    pub eye: [f64; 3],
    /// `EI`, `EJ` (`S(.16)`), `E` (`U(.16)`).
    pub ei: i64,
    pub ej: i64,
    pub e: i64,
    /// The scene's camera direction (physical, unit) and its right and up vectors.
    pub dir: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    pub tan_half: f64,
    pub spacing: [f64; 3],
    /// The image's width and height (the screen's aspect).
    pub size: (u32, u32),
}

const ONE: i64 = 1 << STEP_W;

impl ErSetup {
    /// Sets up the perspective view of `params` on a volume of `dims` and `spacing`.
    pub fn new(
        dims: [usize; 3],
        spacing: [f64; 3],
        params: &RenderParams,
        scheme: ErScheme,
    ) -> Result<Self> {
        params.validate()?;
        scheme.validate()?;
        if params.projection != Projection::Perspective {
            return Err(ModelError::View(
                "projection: ER-perspective renders a perspective view; this one is parallel"
                    .into(),
            ));
        }
        let dir = params.direction()?;
        let frame = FrameSetup::new(dims, spacing, dir, 1)?;
        // The reference renderer's camera (`RenderParams::camera`) for a volume of `dims`.
        let mut cam = crate::camera::Camera::looking(
            dir,
            params.up_hint(dir),
            dims,
            spacing,
            params.width,
            params.height,
        )
        .rolled(params.roll);
        cam.half /= params.zoom;
        let (eye, tan_half) = perspective_eye(params, &cam);
        let mut setup = Self::with_eye(
            frame,
            scheme,
            eye,
            dir,
            (cam.right, cam.up),
            tan_half,
            spacing,
        )?;
        setup.size = (params.width, params.height);
        Ok(setup)
    }

    /// The set-up for an eye at `eye` (physical), for tests and studies that place it.
    pub fn with_eye(
        frame: FrameSetup,
        scheme: ErScheme,
        eye: DVec3,
        dir: DVec3,
        (right, up): (DVec3, DVec3),
        tan_half: f64,
        spacing: [f64; 3],
    ) -> Result<Self> {
        let p = &frame.params;
        let v = eye / DVec3::from_array(spacing);
        let k0 = if p.k_reversed { p.nk - 1 } else { 0 } as f64;
        let e = if p.k_reversed {
            v[p.axis_k] - k0
        } else {
            k0 - v[p.axis_k]
        };
        if !(e.is_finite() && e >= 1.0) {
            return Err(ModelError::View(format!(
                "the eye is {e:.2} slices in front of the volume's first slice; ER-perspective needs it at least one slice in front (a narrower view.fov moves the eye out)"
            )));
        }
        let (e_i, e_j) = (v[p.axis_i], v[p.axis_j]);
        let q = |x: f64| (x * ONE as f64).round() as i64;
        Ok(Self {
            frame,
            scheme,
            eye: [e_i, e_j, e],
            ei: q(e_i),
            ej: q(e_j),
            e: q(e),
            dir,
            right,
            up,
            tan_half,
            spacing,
            size: (1, 1),
        })
    }

    /// This set-up with the eye moved to `eye` (physical coordinates), the view's axes, scheme
    /// and image size kept (tests and hosts that place the eye, e.g. inside the bounding sphere).
    pub fn with_eye_at(&self, eye: [f64; 3]) -> Result<Self> {
        let mut s = Self::with_eye(
            self.frame,
            self.scheme,
            DVec3::from_array(eye),
            self.dir,
            (self.right, self.up),
            self.tan_half,
            self.spacing,
        )?;
        s.size = self.size;
        Ok(s)
    }

    pub fn params(&self) -> &FrameParams {
        &self.frame.params
    }

    /// Region of slice `s` and the ray spacing `H(s)` (contract, integers only).
    pub fn slice_spacing(&self, s: usize) -> (u32, i64) {
        self.spacing_at(self.e + s as i64 * ONE)
    }

    /// Region and ray spacing (`U(1.16)`) at distance `d` (`U(.16)`, `d >= E`) from the eye.
    pub fn spacing_at(&self, d: i64) -> (u32, i64) {
        let mut r = 0u32;
        while (self.e << (r + 1)) <= d {
            r += 1;
        }
        let big = i128::from(self.e) << (r + 1);
        let h = (2 * i128::from(self.g()) * i128::from(d) + big) / (2 * big);
        (r, h as i64)
    }

    /// `G`: the ray spacing at a region's rear, `U(.16)`.
    pub fn g(&self) -> i64 {
        ONE >> self.scheme.rate_log2()
    }

    /// The counts of this set-up's frame that do not depend on the volume's values (regions,
    /// samples, samples per slice against the bound), for `plan:`.
    pub fn counts(&self) -> ErStats {
        ErStats::new(self, &self.layout(), 0)
    }

    /// The fixed-point layout: regions, rays per slice, buffers.
    pub fn layout(&self) -> Layout {
        let p = self.params();
        let range = |e0: i64, h: i64, n: usize| {
            let lo = -e0.div_euclid(h); // ceil(-e0 / h)
            let hi = (n as i64 * ONE - 1 - e0).div_euclid(h);
            (lo, hi)
        };
        let (mut region, mut rays) = (Vec::new(), Vec::new());
        for s in 0..p.nk {
            let (r, h) = self.slice_spacing(s);
            let (m0, m1) = range(self.ei, h, p.ni);
            let (n0, n1) = range(self.ej, h, p.nj);
            region.push(r);
            rays.push(Extent { m0, m1, n0, n1 });
        }
        Layout::new(region, rays)
    }

    /// The f64 layout: exact eye, exact spacing `g d / (e 2^(r+1))`; also returns the spacings.
    pub fn layout_f64(&self) -> (Layout, Vec<f64>) {
        let p = self.params();
        let [e_i, e_j, e] = self.eye;
        let g = 1.0 / f64::from(self.scheme.rays_per_voxel);
        let (mut region, mut rays, mut hs) = (Vec::new(), Vec::new(), Vec::new());
        for s in 0..p.nk {
            let d = e + s as f64;
            let mut r = 0u32;
            while e * f64::from(1u32 << (r + 1)) <= d {
                r += 1;
            }
            let h = g * d / (e * f64::from(1u32 << (r + 1)));
            let range = |e0: f64, n: usize| {
                (
                    (-e0 / h).ceil() as i64,
                    ((n as f64 - e0) / h).ceil() as i64 - 1,
                )
            };
            let ((m0, m1), (n0, n1)) = (range(e_i, p.ni), range(e_j, p.nj));
            region.push(r);
            rays.push(Extent { m0, m1, n0, n1 });
            hs.push(h);
        }
        (Layout::new(region, rays), hs)
    }

    /// The base-plane position of a screen ray in homogeneous form `(x w, y w, w)` (before the
    /// extent's offset), `w = q_k`: linear in `ndc`, so the screen-to-base-plane map is
    /// projective (contract: *The base-plane image and the final image*).
    fn base_homogeneous(&self, ndc: (f64, f64), e: f64, g: f64) -> [f64; 3] {
        let aspect = f64::from(self.size.0) / f64::from(self.size.1);
        let u = ndc.0 * self.tan_half * aspect.max(1.0);
        let v = ndc.1 * self.tan_half / aspect.min(1.0);
        let rd = (self.dir + self.right * u + self.up * v) / DVec3::from_array(self.spacing);
        let p = self.params();
        let qk = if p.k_reversed {
            -rd[p.axis_k]
        } else {
            rd[p.axis_k]
        };
        [rd[p.axis_i] * 2.0 * e / g, rd[p.axis_j] * 2.0 * e / g, qk]
    }

    /// The projective map from the pixels of an `ss`-times supersampled `width x height` image
    /// (centres at integers, the sub-pixels `image_of` takes) to the base plane's texels
    /// (`x - m_lo(0)`, `y - n_lo(0)`): what `cube5_pwarp`'s set-up takes.
    pub fn projective(
        &self,
        (width, height): (u32, u32),
        ss: u32,
        ext: &Extent,
        e: f64,
        g: f64,
    ) -> Projective {
        let (w, h) = (f64::from(width * ss), f64::from(height * ss));
        let at = |px: f64, py: f64| {
            let ndc = ((px + 0.5) / w * 2.0 - 1.0, 1.0 - (py + 0.5) / h * 2.0);
            let [x, y, q] = self.base_homogeneous(ndc, e, g);
            [x - ext.m0 as f64 * q, y - ext.n0 as f64 * q, q]
        };
        let (o, dx, dy) = (at(0.0, 0.0), at(1.0, 0.0), at(0.0, 1.0));
        let row = |i: usize| [dx[i] - o[i], dy[i] - o[i], o[i]];
        Projective {
            nx: row(0),
            ny: row(1),
            w: row(2),
        }
    }

    /// The f64 mapping of a screen ray to base-plane coordinates (before the extent's offset):
    /// `None` when the ray does not go forward along the sweep. `e` and `g` are the model's or
    /// the reference's.
    fn base_coords(&self, ndc: (f64, f64), e: f64, g: f64) -> Option<(f64, f64)> {
        let [x, y, q] = self.base_homogeneous(ndc, e, g);
        (q > 0.0).then(|| (x / q, y / q))
    }
}

/// What one ER-perspective frame did.
#[derive(Debug, Clone, PartialEq)]
pub struct ErStats {
    pub regions: usize,
    /// First slice (processing order, `s = 0` nearest the eye) of each region.
    pub region_starts: Vec<usize>,
    pub samples_per_slice: Vec<u64>,
    pub samples: u64,
    /// Samples that went through the gradient and the lit shader (the others are transparent under
    /// back-to-front, or MIP's, whose shading ignores the gradient).
    pub shaded: u64,
    /// `N^2 = ni nj rho^2`: the bound is `N^2 ..= 4 N^2` samples per slice.
    pub n2: u64,
    /// Distance from the eye to the first slice, voxels.
    pub eye_distance: f64,
    pub base: (usize, usize),
}

impl ErStats {
    fn new(setup: &ErSetup, layout: &Layout, shaded: u64) -> Self {
        let p = setup.params();
        let spl = layout.samples_per_slice();
        let mut starts = vec![0usize];
        for s in 1..layout.region.len() {
            if layout.region[s] != layout.region[s - 1] {
                starts.push(s);
            }
        }
        let rho = u64::from(setup.scheme.rays_per_voxel);
        Self {
            regions: layout.regions(),
            region_starts: starts,
            samples: spl.iter().sum(),
            samples_per_slice: spl,
            shaded,
            n2: (p.ni * p.nj) as u64 * rho * rho,
            eye_distance: setup.eye[2],
            base: (layout.extent[0].width(), layout.extent[0].height()),
        }
    }

    pub fn min_per_slice(&self) -> u64 {
        self.samples_per_slice.iter().copied().min().unwrap_or(0)
    }
    pub fn max_per_slice(&self) -> u64 {
        self.samples_per_slice.iter().copied().max().unwrap_or(0)
    }

    /// One phrase for `plan:`: regions, samples, per slice against the bound (and the samples
    /// shaded, once a frame has run).
    pub fn describe(&self) -> String {
        format!(
            "eye {:.1} slices in front of the first slice, {} region{} (first slices {:?}), base plane {}x{}, {} samples{}, per slice {}..{} against the bound N^2 = {} .. 4N^2 = {}",
            self.eye_distance,
            self.regions,
            if self.regions == 1 { "" } else { "s" },
            self.region_starts,
            self.base.0,
            self.base.1,
            self.samples,
            if self.shaded > 0 {
                format!(" ({} shaded)", self.shaded)
            } else {
                String::new()
            },
            self.min_per_slice(),
            self.max_per_slice(),
            self.n2,
            4 * self.n2
        )
    }
}

/// The sweep shared by the model and the reference: back to front, region buffers, merges.
/// `sample(s, m, n, coxel)` composites ray `(m, n)`'s sample of slice `s`; `merge(nb)` makes the
/// nearer region's coxel from the 3 x 3 farther ones (`nb[v][u]` at `(2m' + u - 1, 2n' + v - 1)`).
fn sweep<C: Copy + Send + Sync>(
    layout: &Layout,
    empty: C,
    merge: impl Fn(&[[C; 3]; 3]) -> C + Sync,
    sample: impl Fn(usize, i64, i64, &C) -> C + Sync,
) -> Vec<C> {
    let nk = layout.region.len();
    let mut r = layout.region[nk - 1] as usize;
    let mut ext = layout.extent[r];
    let mut buf = vec![empty; ext.width() * ext.height()];
    for s in (0..nk).rev() {
        while (layout.region[s] as usize) < r {
            let new = layout.extent[r - 1];
            let old = &buf;
            let next: Vec<C> = (0..new.width() * new.height())
                .into_par_iter()
                .map(|idx| {
                    let m = new.m0 + (idx % new.width()) as i64;
                    let n = new.n0 + (idx / new.width()) as i64;
                    let nb: [[C; 3]; 3] = std::array::from_fn(|v| {
                        std::array::from_fn(|u| {
                            ext.index(2 * m + u as i64 - 1, 2 * n + v as i64 - 1)
                                .map_or(empty, |i| old[i])
                        })
                    });
                    merge(&nb)
                })
                .collect();
            buf = next;
            ext = new;
            r -= 1;
        }
        let rays = layout.rays[s];
        let w = ext.width();
        buf.par_chunks_mut(w).enumerate().for_each(|(row, cells)| {
            let n = ext.n0 + row as i64;
            if n < rays.n0 || n > rays.n1 {
                return;
            }
            for m in rays.m0..=rays.m1 {
                let cell = &mut cells[(m - ext.m0) as usize];
                *cell = sample(s, m, n, cell);
            }
        });
    }
    buf
}

/// An ER-perspective frame of the model: the base plane (region 0's coxels), its extent, the
/// counts and the final image.
#[derive(Debug, Clone)]
pub struct ErRun {
    pub coxels: Vec<Coxel>,
    pub extent: Extent,
    pub stats: ErStats,
    /// The final image through `cube5_pwarp`'s bit-exact perspective warp (8-bit samples).
    pub image: ImageF64,
    /// The same base plane through the f64 projective warp (`cube5_warp::bilinear_f64` at each
    /// pixel's exact position): the frame's fixed point without the warp's error.
    pub image_f64_warp: ImageF64,
}

/// The volume-dependent part of a frame: the volume at the frame's voxel width and the units.
pub struct ErJob {
    pub setup: ErSetup,
    pub vol: Volume,
    pub units: FrameUnits,
    pub cfg: FrameConfig,
    params: RenderParams,
}

fn frame_mode(mode: CompositeMode) -> Result<FrameMode> {
    match mode {
        CompositeMode::Composite => Ok(FrameMode::Composite),
        CompositeMode::Mip => Ok(FrameMode::Mip),
        m => Err(ModelError::Config(format!(
            "mode \"{}\": ER-perspective composites back to front and takes maxima (composite, mip)",
            m.name()
        ))),
    }
}

impl ErJob {
    pub fn new(
        vol: &Volume,
        tf: &TransferFunction,
        params: &RenderParams,
        cfg: &FrameConfig,
        scheme: ErScheme,
    ) -> Result<Self> {
        tf.validate()?;
        let mode = frame_mode(params.mode)?;
        let setup = ErSetup::new(vol.dims, vol.spacing, params, scheme)?;
        let phong = params_phong(params, &setup.frame.params);
        let units = FrameUnits::with_config(cfg, mode, &setup.frame, tf, &phong, None)?;
        Ok(Self {
            vol: at_voxel_width(vol, cfg.trilin.voxel_w)?,
            setup,
            units,
            cfg: *cfg,
            params: params.clone(),
        })
    }

    /// The job with another set-up of the same volume axes (an eye placed by
    /// [`ErSetup::with_eye`]); the units' tables stay those of the scene's view.
    pub fn with_setup(mut self, mut setup: ErSetup) -> Result<Self> {
        if setup.frame.params != self.setup.frame.params {
            return Err(ModelError::View(
                "the placed eye's frame set-up differs from the job's view".into(),
            ));
        }
        setup.size = self.setup.size;
        self.setup = setup;
        Ok(self)
    }

    /// The model's frame (contract: every step in integers up to the base plane).
    pub fn render(&self) -> ErRun {
        let setup = &self.setup;
        let p = setup.params();
        let layout = setup.layout();
        let hs: Vec<i64> = (0..p.nk).map(|s| setup.slice_spacing(s).1).collect();
        let units = &self.units;
        let cfg = self.cfg.compos;
        let empty = Coxel::empty(&cfg);
        let unlit = units.mode == FrameMode::Mip;
        let smode = ShaderMode { tf2d: false, unlit };
        let cmode = if unlit {
            ComposMode::Max
        } else {
            ComposMode::BackToFront
        };
        let shaded = AtomicU64::new(0);
        let wshift = STEP_W - self.cfg.trilin.weight_w;
        let vol = &self.vol;
        let sample = |s: usize, m: i64, n: i64, cox: &Coxel| -> Coxel {
            let (x, y) = (setup.ei + m * hs[s], setup.ej + n * hs[s]);
            let (a, b) = (x >> STEP_W, y >> STEP_W);
            let (wx, wy) = (
                ((x & (ONE - 1)) >> wshift) as u32,
                ((y & (ONE - 1)) >> wshift) as u32,
            );
            let at = |t: i64, da: i64, db: i64| {
                plane_sample(p, vol, &units.trilin, t, a + da, b + db, wx, wy)
            };
            let s_i = s as i64;
            let c = at(s_i, 0, 0);
            let class = units.shader.classify(&ShaderIn {
                sample: c,
                grad: [0; 3],
                mag: 0,
                mode: smode,
            });
            let mut smp = if unlit || units.compos.corrected(class.a) == 0 {
                crate::units::cube5_compos::Sample {
                    rgb: [class.r, class.g, class.b],
                    alpha: class.a,
                    depth: s as u32,
                    mode: cmode,
                }
            } else {
                shaded.fetch_add(1, Ordering::Relaxed);
                let nb = N6_OFFSETS.map(|(di, dj, dk)| match (di, dj, dk) {
                    (0, 0, 0) => c,
                    _ => at(s_i + i64::from(dk), i64::from(di), i64::from(dj)),
                });
                shade_n6(&units.gradient, &units.shader, &nb, smode, s as u32)
            };
            smp.mode = cmode;
            units.compos.step(cox, &smp)
        };
        let merge_kind = setup.scheme.merge;
        let merge = |nb: &[[Coxel; 3]; 3]| merge_coxels(nb, merge_kind, &empty);
        let coxels = sweep(&layout, empty, merge, sample);
        let extent = layout.extent[0];
        let rgb: Vec<[f64; 3]> = {
            let one = cfg.one() as f64;
            coxels
                .iter()
                .map(|c| std::array::from_fn(|i| (c.rgba[i] as f64 / one).min(1.0)))
                .collect()
        };
        let e = setup.e as f64 / ONE as f64;
        let g = setup.g() as f64 / ONE as f64;
        let image_f64_warp = warp(setup, &self.params, &rgb, &extent, e, g);
        let image = match warp_pwarp(setup, &self.params, &cfg, &coxels, &extent, e, g) {
            Ok(image) => image,
            // Images beyond cube5_pwarp's 2048 pixels a side (supersampled): the f64 warp.
            Err(_) => image_f64_warp.clone(),
        };
        ErRun {
            stats: ErStats::new(setup, &layout, shaded.into_inner()),
            coxels,
            extent,
            image,
            image_f64_warp,
        }
    }
}

const TENT: [u64; 3] = [1, 2, 1];

/// The merge of 3 x 3 coxels of the farther region (`nb[v][u]` at `(2m' + u - 1, 2n' + v - 1)`)
/// into ray `(m', n')` of the nearer one (contract: *Merge at a region boundary*): each of `R, G,
/// B, A` the tent-weighted sum `+ 8 >> 4` (Bartlett) or the centre's (the what-if); the other fields
/// those of `empty`.
pub fn merge_coxels(nb: &[[Coxel; 3]; 3], merge: ErMerge, empty: &Coxel) -> Coxel {
    let mut out = *empty;
    match merge {
        ErMerge::Centre => out.rgba = nb[1][1].rgba,
        ErMerge::Bartlett => {
            for ch in 0..4 {
                let mut sum = 0u64;
                for (v, row) in nb.iter().enumerate() {
                    for (u, c) in row.iter().enumerate() {
                        sum += TENT[u] * TENT[v] * c.rgba[ch];
                    }
                }
                out.rgba[ch] = (sum + 8) >> 4;
            }
        }
    }
    out
}

/// The bilinear sample of slice `t` (processing order; 0 outside `0..nk`) at anchor `(a, b)` (0
/// outside the face) with weights `(wx, wy)`: the frame's rules with a ray's own weights.
#[allow(clippy::too_many_arguments)]
fn plane_sample(
    p: &FrameParams,
    vol: &Volume,
    trilin: &Trilin,
    t: i64,
    a: i64,
    b: i64,
    wx: u32,
    wy: u32,
) -> u32 {
    if t < 0 || t >= p.nk as i64 || a < 0 || b < 0 || a >= p.ni as i64 || b >= p.nj as i64 {
        return 0;
    }
    let k = p.slice(t as usize).k;
    let (a, b) = (a as usize, b as usize);
    let v = |da: usize, db: usize| p.voxel(vol, a + da, b + db, k);
    trilin.sample_in_slice([v(0, 0), v(1, 0), v(0, 1), v(1, 1)], wx, wy)
}

/// The final image: each screen ray meets the base plane (the plane `2e` from the eye) where the
/// base plane's colours are sampled bilinearly (contract: *The base-plane image and the final
/// image*).
fn warp(
    setup: &ErSetup,
    params: &RenderParams,
    rgb: &[[f64; 3]],
    ext: &Extent,
    e: f64,
    g: f64,
) -> ImageF64 {
    let (w, h) = (ext.width() as i64, ext.height() as i64);
    let texel = |x: i64, y: i64| {
        if x < 0 || y < 0 || x >= w || y >= h {
            [0.0; 3]
        } else {
            rgb[(y * w + x) as usize]
        }
    };
    image_of(params, |ndc_x, ndc_y| {
        match setup.base_coords((ndc_x, ndc_y), e, g) {
            Some((x, y)) => {
                crate::units::cube5_warp::bilinear_f64(x - ext.m0 as f64, y - ext.n0 as f64, texel)
            }
            None => [0.0; 3],
        }
    })
}

/// The final image by `cube5_pwarp`'s bit-exact perspective warp (docs/numerics/pwarp.md): the
/// coxels as `ColorW` codes (`cube5_warp::base_codes`), the set-up of the projective map of
/// [`ErSetup::projective`], 8-bit samples on the `ss`-times supersampled grid, averaged per pixel
/// as `image_of` averages its sub-pixels. Refused beyond 2048 sub-pixels a side.
fn warp_pwarp(
    setup: &ErSetup,
    params: &RenderParams,
    cfg: &crate::units::cube5_compos::ComposConfig,
    coxels: &[Coxel],
    ext: &Extent,
    e: f64,
    g: f64,
) -> Result<ImageF64> {
    use crate::units::cube5_pwarp::{warp_image, PwarpConfig, PwarpSetup};
    let ss = params.supersampling;
    let (bw, bh) = (ext.width(), ext.height());
    let plane = crate::units::cube5_frame::BasePlane {
        width: bw,
        height: bh,
        coxels: coxels.to_vec(),
    };
    let base = crate::units::cube5_warp::base_codes(&plane, cfg);
    let (ow, oh) = (params.width * ss, params.height * ss);
    let map = setup.projective((params.width, params.height), ss, ext, e, g);
    let pw = PwarpSetup::new(&map, (bw as u32, bh as u32), (ow, oh))?;
    let pcfg = PwarpConfig {
        color_w: cfg.color_w,
        weight_w: 8,
        max_base: (bw.max(bh) as u32).next_power_of_two().clamp(4, 1024),
        max_out: ow.max(oh).next_power_of_two().clamp(4, 2048),
    };
    let px = warp_image(&pcfg, &pw, &base)?;
    let n = f64::from(ss * ss) * 255.0;
    let rgb = (0..params.width * params.height)
        .map(|i| {
            let (x, y) = (i % params.width, i / params.width);
            let mut acc = [0.0; 3];
            for sy in 0..ss {
                for sx in 0..ss {
                    let p = px[((y * ss + sy) * ow + x * ss + sx) as usize];
                    for ch in 0..3 {
                        acc[ch] += f64::from(p[ch]);
                    }
                }
            }
            acc.map(|v| v / n)
        })
        .collect();
    Ok(ImageF64 {
        width: params.width,
        height: params.height,
        rgb,
    })
}

/// Renders the perspective view of `params` with ER-perspective on the frame's unit models at the
/// widths of `cfg`.
pub fn render_er(
    vol: &Volume,
    tf: &TransferFunction,
    params: &RenderParams,
    cfg: &FrameConfig,
    scheme: ErScheme,
) -> Result<ErRun> {
    Ok(ErJob::new(vol, tf, params, cfg, scheme)?.render())
}

/// The f64 reference of the same algorithm (contract: *The f64 reference*): the image and the
/// counts of its own (f64) layout.
pub fn render_er_f64(
    vol: &Volume,
    tf: &TransferFunction,
    params: &RenderParams,
    scheme: ErScheme,
) -> Result<(ImageF64, ErStats)> {
    let setup = ErSetup::new(vol.dims, vol.spacing, params, scheme)?;
    render_er_f64_with(&setup, vol, tf, params)
}

/// [`render_er_f64`] on a set-up made beforehand (an eye placed by [`ErSetup::with_eye`]; its
/// `size` is the image's).
pub fn render_er_f64_with(
    setup: &ErSetup,
    vol: &Volume,
    tf: &TransferFunction,
    params: &RenderParams,
) -> Result<(ImageF64, ErStats)> {
    tf.validate()?;
    let mode = frame_mode(params.mode)?;
    let scheme = setup.scheme;
    let p = *setup.params();
    let phong: Phong = params_phong(params, &p);
    let ratio = setup
        .frame
        .opacity_ratio
        .clamp(OpacityLut::RATIO_MIN, OpacityLut::RATIO_MAX);
    let (layout, hs) = setup.layout_f64();
    let max = f64::from(vol.max_value());
    let [e_i, e_j, _] = setup.eye;
    let shaded = AtomicU64::new(0);
    let plane = |t: i64, x: f64, y: f64| -> f64 {
        let (a, b) = (x.floor(), y.floor());
        if t < 0 || t >= p.nk as i64 || a < 0.0 || b < 0.0 || a >= p.ni as f64 || b >= p.nj as f64 {
            return 0.0;
        }
        let (fx, fy) = (x - a, y - b);
        let k = p.slice(t as usize).k;
        let (a, b) = (a as usize, b as usize);
        let v = |da: usize, db: usize| f64::from(p.voxel(vol, a + da, b + db, k)) / max;
        let top = v(0, 0) + fx * (v(1, 0) - v(0, 0));
        let bot = v(0, 1) + fx * (v(1, 1) - v(0, 1));
        top + fy * (bot - top)
    };
    let sample = |s: usize, m: i64, n: i64, c: &[f64; 4]| -> [f64; 4] {
        let (x, y) = (e_i + m as f64 * hs[s], e_j + n as f64 * hs[s]);
        let t = s as i64;
        let d = plane(t, x, y);
        match mode {
            FrameMode::Mip => {
                if d > c[3] {
                    [d, d, d, d]
                } else {
                    *c
                }
            }
            // Composite (`frame_mode` refuses the other modes).
            _ => {
                let [r, g, b, a] = tf.lookup(d);
                if a <= 0.0 {
                    return *c;
                }
                shaded.fetch_add(1, Ordering::Relaxed);
                let grad = [
                    plane(t, x + 1.0, y) - plane(t, x - 1.0, y),
                    plane(t, x, y + 1.0) - plane(t, x, y - 1.0),
                    plane(t + 1, x, y) - plane(t - 1, x, y),
                ];
                let (di, sp) = if grad == [0.0; 3] {
                    (phong.ambient, 0.0)
                } else {
                    phong.intensities(grad)
                };
                let lit = |ch: f64| (ch * di + sp).clamp(0.0, 1.0);
                let a = corrected_alpha(a, ratio);
                [
                    a * lit(r) + (1.0 - a) * c[0],
                    a * lit(g) + (1.0 - a) * c[1],
                    a * lit(b) + (1.0 - a) * c[2],
                    c[3] + (1.0 - c[3]) * a,
                ]
            }
        }
    };
    let merge_kind = scheme.merge;
    let merge = |nb: &[[[f64; 4]; 3]; 3]| -> [f64; 4] {
        match merge_kind {
            ErMerge::Centre => nb[1][1],
            ErMerge::Bartlett => std::array::from_fn(|ch| {
                let mut sum = 0.0;
                for (v, row) in nb.iter().enumerate() {
                    for (u, c) in row.iter().enumerate() {
                        sum += (TENT[u] * TENT[v]) as f64 * c[ch];
                    }
                }
                sum / 16.0
            }),
        }
    };
    let base = sweep(&layout, [0.0; 4], merge, sample);
    let rgb: Vec<[f64; 3]> = base.iter().map(|c| [c[0], c[1], c[2]]).collect();
    let ext = layout.extent[0];
    let image = warp(
        setup,
        params,
        &rgb,
        &ext,
        setup.eye[2],
        1.0 / f64::from(scheme.rays_per_voxel),
    );
    Ok((image, ErStats::new(setup, &layout, shaded.into_inner())))
}
