//! The slice-order frame (`docs/numerics/frame.md`): host set-up of a parallel view in f64,
//! quantized frame parameters, per-slice constants in integers, the samples of every ray in slice
//! order, the base-plane image, and the (model-only) warp onto the final image.

use crate::camera::Camera;
use crate::error::{ModelError, Result};
use crate::render::ImageF64;
use crate::transfer::TransferFunction;
use crate::units::cube5_compos::{
    Compos, ComposConfig, ComposMode, ComposRegs, Coxel, OpacityLut, Sample,
};
use crate::units::cube5_gradient::{
    block_index, n6_components, Gradient, GradientConfig, GradientIn, GradientMode, GradientOut,
};
use crate::units::cube5_shader::{
    ClassLut, DistantLight, Phong, ReflectanceMap, Rgba, Shader, ShaderConfig, ShaderIn,
    ShaderMode, ShaderTables,
};
use crate::units::cube5_skewmem::{module_of, Axis, BlockLut, SkewIn, SkewMem};
use crate::units::cube5_trilin::{Trilin, TrilinConfig, TrilinIn, TrilinMode};
use crate::volume::Volume;
use glam::DVec3;
use rayon::prelude::*;

mod fast;
pub use fast::{
    render_base_plane_stats as render_base_plane_stats_fast, render_sweep, SweepStats, SweepVolume,
};
pub mod ports;
pub mod sections;
pub mod window;

/// Fraction bits of the per-slice ray steps `DX`, `DY` (`S(2.StepW)`).
pub const STEP_W: u32 = 16;

/// Largest volume edge the frame model accepts. It is not an RTL figure: the RTL's `MaxDim`
/// defaults to 64 and stops at 256 (`$fatal`), and a co-simulation refuses a volume larger than its
/// variant's `MaxDim`.
pub const MAX_DIM: usize = 512;

/// The frame's parameters that set the widths of its units (trilin, gradient, shader, compos): the
/// tops built around the same units (`cube5_er`, `cube5_accel`) take them under the same names.
pub const UNIT_WIDTH_PARAMS: &[&str] = &[
    "VoxelW",
    "WeightW",
    "FracW",
    "ClassIdxW",
    "MagIdxW",
    "MagShift",
    "ColorW",
    "AlphaW",
    "RmLog2",
    "RmFracW",
    "DiffW",
    "SpecW",
    "ExtraW",
    "AccW",
    "ZW",
];

/// One configuration of the `cube5_frame` RTL: pipelines, memory and the widths of its units.
/// Several frame parameters set more than one unit (`VoxelW` sets trilin, gradient and shader;
/// `ColorW` and `AlphaW` set shader and compos), so the units always agree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameConfig {
    /// Pipelines (`P`).
    pub p: usize,
    /// log2 of the largest volume edge (`MaxDim = 2^max_dim_log2`).
    pub max_dim_log2: u32,
    /// Block edge of the skewed memory (`BlockDim`).
    pub block: u32,
    /// Read latency of the memory modules (`MemLatency`).
    pub mem_latency: u32,
    pub trilin: TrilinConfig,
    pub gradient: GradientConfig,
    pub shader: ShaderConfig,
    pub compos: ComposConfig,
    /// Gradient and shader in every pipeline (`Shade = 1`), or neither (`Shade = 0`): the frame
    /// then renders the unlit modes only (MIP, MinIP, X-ray), each sample classified by the
    /// shader's 1-D table alone (docs/numerics/frame.md, "A frame without gradient and shader").
    pub shade: bool,
    /// Where the beams come from (`Source`): the skewed memory inside (false), or a beat stream a
    /// section at a time (true; docs/numerics/frame.md, "Sections").
    pub stream: bool,
    /// The depth test against opaque geometry (`DepthTest`): a per-pixel RGBA-Z table that every
    /// ray starts from, and the read-out's flush of the geometry colour under each ray
    /// (docs/numerics/frame.md, "Opaque geometry").
    pub depth_test: bool,
    /// Pixels per output item of the read-out (`OutLanes`): 1, or `p` (P consecutive pixels of a
    /// row per item and per clock, `H ceil(W / P)` items; docs/frame-rtl.md, "The read-out").
    pub out_lanes: usize,
    /// The widest section a frame fed by beats takes (`MaxSection`; `None`: `MaxDim`, the RTL's
    /// default): it sizes the slice FIFOs, `MaxSection MaxDim / P` beats (docs/frame-rtl.md).
    pub max_section: Option<usize>,
    /// The compositing window (`Window = 1`, with a beat stream only): the buffer keeps the active
    /// rays' coxels, the rest leave on the park and final streams and come back on the restore
    /// streams (docs/numerics/compos_window.md; the model: `window::render_window`).
    pub window: bool,
    /// With the window: its descriptor FIFO's depth (`WinDescDepth`, a power of two; 32 admits
    /// at most 0.94 beats per clock, 64 one). Timing only: the image is the same.
    pub win_desc_depth: u32,
}

impl FrameConfig {
    /// The RTL's defaults: four pipelines, 64^3 volumes, the default widths of every unit.
    pub const DEFAULT: Self = Self {
        p: 4,
        max_dim_log2: 6,
        block: 8,
        mem_latency: 1,
        trilin: TrilinConfig::DEFAULT,
        gradient: GradientConfig::DEFAULT,
        shader: ShaderConfig::DEFAULT,
        compos: ComposConfig::DEFAULT,
        shade: true,
        stream: false,
        depth_test: false,
        out_lanes: 1,
        max_section: None,
        window: false,
        win_desc_depth: 32,
    };

    /// The largest volume edge (`MaxDim`).
    pub fn max_dim(&self) -> usize {
        1 << self.max_dim_log2
    }

    /// The RTL's defaults at this configuration's `MaxDim` (a default that depends on it, as
    /// `MaxSection`'s, follows it).
    pub fn rtl_defaults(&self) -> Self {
        Self {
            max_dim_log2: self.max_dim_log2,
            ..Self::DEFAULT
        }
    }

    /// The widest section the frame takes (`MaxSection`): `MaxDim` unless set.
    pub fn max_section(&self) -> usize {
        self.max_section.unwrap_or_else(|| self.max_dim())
    }
}

// The RTL parameters of cube5_frame, each mapped onto every unit it sets.
impl crate::unit::UnitConfig for FrameConfig {
    const TOP: &'static str = "cube5_frame";

    fn from_params(params: &[(&str, i64)]) -> Result<Self> {
        let d = Self::DEFAULT;
        let mut p = d.p as u32;
        let mut max_dim = 1u32 << d.max_dim_log2;
        let (mut block, mut mem_latency) = (d.block, d.mem_latency);
        let (mut t, mut g, mut s, mut c) = (d.trilin, d.gradient, d.shader, d.compos);
        let mut shade = u32::from(d.shade);
        let mut source = u32::from(d.stream);
        let mut depth_test = u32::from(d.depth_test);
        let mut out_lanes = d.out_lanes as u32;
        let mut max_section = 0u32; // 0: not given, MaxDim
        let mut window = 0u32;
        let mut win_desc_depth = d.win_desc_depth;
        crate::unit::set_params(
            Self::TOP,
            params,
            &mut [
                ("P", &mut p),
                ("MaxDim", &mut max_dim),
                ("VoxelW", &mut t.voxel_w),
                ("WeightW", &mut t.weight_w),
                ("FracW", &mut t.frac_w),
                ("BlockDim", &mut block),
                ("MemLatency", &mut mem_latency),
                ("ClassIdxW", &mut s.class_idx_w),
                ("MagIdxW", &mut s.mag_idx_w),
                ("MagShift", &mut s.mag_shift),
                ("ColorW", &mut c.color_w),
                ("AlphaW", &mut c.alpha_w),
                ("RmLog2", &mut s.rm_log2),
                ("RmFracW", &mut s.rm_frac_w),
                ("DiffW", &mut s.diff_w),
                ("SpecW", &mut s.spec_w),
                ("ExtraW", &mut c.extra_w),
                ("AccW", &mut c.acc_w),
                ("ZW", &mut c.z_w),
                ("Shade", &mut shade),
                ("Source", &mut source),
                ("DepthTest", &mut depth_test),
                ("OutLanes", &mut out_lanes),
                ("MaxSection", &mut max_section),
                ("Window", &mut window),
                ("WinDescDepth", &mut win_desc_depth),
            ],
        )?;
        if win_desc_depth < 2 || !win_desc_depth.is_power_of_two() {
            return Err(ModelError::Config(format!(
                "cube5_frame: WinDescDepth = {win_desc_depth} must be a power of two of at least 2"
            )));
        }
        if window > 1 || (window == 1 && (source != 1 || depth_test != 0 || out_lanes != 1)) {
            return Err(ModelError::Config(format!(
                "cube5_frame: Window = {window} must be 0, or 1 with Source = 1, no depth test and OutLanes = 1"
            )));
        }
        if max_section != 0
            && (max_section > max_dim
                || max_section < 2 * p
                || !max_section.is_multiple_of(p)
                || (source == 0 && max_section != max_dim))
        {
            return Err(ModelError::Config(format!(
                "cube5_frame: MaxSection = {max_section} must be a multiple of P = {p} in 2 P ..= MaxDim = {max_dim} (MaxDim when Source = 0)"
            )));
        }
        if out_lanes != 1 && (out_lanes != p || depth_test != 0) {
            return Err(ModelError::Config(format!(
                "cube5_frame: OutLanes = {out_lanes} must be 1, or P = {p} without the depth test"
            )));
        }
        if depth_test > 1 {
            return Err(ModelError::Config(format!(
                "cube5_frame: DepthTest = {depth_test} must be 0 or 1"
            )));
        }
        if source > 1 {
            return Err(ModelError::Config(format!(
                "cube5_frame: Source = {source} must be 0 (the skewed memory) or 1 (a beat stream)"
            )));
        }
        if shade > 1 {
            return Err(ModelError::Config(format!(
                "cube5_frame: Shade = {shade} must be 0 (no gradient, no shader: MIP, MinIP, X-ray) or 1"
            )));
        }
        if !max_dim.is_power_of_two() {
            return Err(ModelError::Config(format!(
                "cube5_frame: MaxDim = {max_dim} is not a power of two"
            )));
        }
        (g.voxel_w, g.weight_w, g.frac_w) = (t.voxel_w, t.weight_w, t.frac_w);
        (s.voxel_w, s.frac_w) = (t.voxel_w, t.frac_w);
        (s.color_w, s.alpha_w) = (c.color_w, c.alpha_w);
        t.validate()?;
        g.validate()?;
        s.validate()?;
        c.validate()?;
        Ok(Self {
            p: p as usize,
            max_dim_log2: max_dim.trailing_zeros(),
            block,
            mem_latency,
            trilin: t,
            gradient: g,
            shader: s,
            compos: c,
            shade: shade == 1,
            stream: source == 1,
            depth_test: depth_test == 1,
            out_lanes: out_lanes as usize,
            max_section: (max_section != 0 && max_section != max_dim)
                .then_some(max_section as usize),
            window: window == 1,
            win_desc_depth,
        })
    }

    fn to_params(&self) -> Vec<(&'static str, i64)> {
        let (t, s, c) = (&self.trilin, &self.shader, &self.compos);
        let i = i64::from;
        vec![
            ("P", self.p as i64),
            ("MaxDim", 1i64 << self.max_dim_log2),
            ("VoxelW", i(t.voxel_w)),
            ("WeightW", i(t.weight_w)),
            ("FracW", i(t.frac_w)),
            ("BlockDim", i(self.block)),
            ("MemLatency", i(self.mem_latency)),
            ("ClassIdxW", i(s.class_idx_w)),
            ("MagIdxW", i(s.mag_idx_w)),
            ("MagShift", i(s.mag_shift)),
            ("ColorW", i(c.color_w)),
            ("AlphaW", i(c.alpha_w)),
            ("RmLog2", i(s.rm_log2)),
            ("RmFracW", i(s.rm_frac_w)),
            ("DiffW", i(s.diff_w)),
            ("SpecW", i(s.spec_w)),
            ("ExtraW", i(c.extra_w)),
            ("AccW", i(c.acc_w)),
            ("ZW", i(c.z_w)),
            ("Shade", i64::from(self.shade)),
            ("Source", i64::from(self.stream)),
            ("DepthTest", i64::from(self.depth_test)),
            ("OutLanes", self.out_lanes as i64),
            ("MaxSection", self.max_section() as i64),
            ("Window", i64::from(self.window)),
            ("WinDescDepth", i64::from(self.win_desc_depth)),
        ]
    }
}

/// The quantized parameters of one frame: everything the RTL is told about the view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameParams {
    /// Volume axis (0 = x, 1 = y, 2 = z) of the slice axis `k`, beam axis `i`, row axis `j`.
    pub axis_k: usize,
    pub axis_i: usize,
    pub axis_j: usize,
    /// Edges along `i`, `j`, `k`.
    pub ni: usize,
    pub nj: usize,
    pub nk: usize,
    /// True when slice `s` is `k = nk - 1 - s` (the view runs toward -k).
    pub k_reversed: bool,
    /// Per-slice ray steps, `S(2.StepW)`.
    pub dx: i32,
    pub dy: i32,
}

/// Host set-up: the frame parameters plus the f64 figures derived from the same view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameSetup {
    pub params: FrameParams,
    /// Opacity-correction ratio: sample spacing along the ray over the transfer function's unit.
    pub opacity_ratio: f64,
    /// The view direction in voxel space (not normalized).
    pub voxel_dir: DVec3,
    /// The X-ray sum's shift (`XrayShift`, 0..=15): `round(log2(n))` for the `n` samples the
    /// volume's diagonal holds at this view's sample spacing, so a sum reads about as the f64
    /// reference's density integral over the diagonal (docs/numerics/frame.md, "Render modes").
    pub xray_shift: u32,
}

/// Constants of one slice (integers only).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SliceConst {
    /// Slice number in processing order.
    pub s: usize,
    /// Volume index along `k` of this slice.
    pub k: usize,
    pub shift_x: i64,
    pub shift_y: i64,
    /// Fractions, `U(0.StepW)`.
    pub frac_x: u32,
    pub frac_y: u32,
}

impl FrameSetup {
    /// Quantizes a parallel view of a volume of `dims` voxels with `spacing`, for `p` pipelines.
    pub fn new(dims: [usize; 3], spacing: [f64; 3], view: DVec3, p: usize) -> Result<Self> {
        if !(view.is_finite() && view.length_squared() > 0.0) {
            return Err(ModelError::View(format!(
                "view vector {view:?} is zero or not finite"
            )));
        }
        if p == 0 || !p.is_power_of_two() || p > 64 {
            return Err(ModelError::Config(format!(
                "pipelines {p}: must be a power of two 1..=64"
            )));
        }
        for (a, &n) in dims.iter().enumerate() {
            if n == 0 || n > MAX_DIM || n % p != 0 {
                return Err(ModelError::Volume(format!(
                    "dimension {} along {} must be 1..={MAX_DIM} and a multiple of {p} pipelines",
                    n,
                    ["x", "y", "z"][a]
                )));
            }
        }
        if spacing.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(ModelError::Volume(format!(
                "spacing {spacing:?} must be finite and > 0"
            )));
        }
        let d = DVec3::new(
            view.x / spacing[0],
            view.y / spacing[1],
            view.z / spacing[2],
        );
        let mag = d.abs().to_array();
        // Ties go to the later axis: z over y over x.
        let mut axis_k = 2;
        for a in [1, 0] {
            if mag[a] > mag[axis_k] {
                axis_k = a;
            }
        }
        if axis_k == 0 && mag[1] >= mag[0] {
            axis_k = 1;
        }
        if mag[2] >= mag[axis_k] {
            axis_k = 2;
        }
        let (axis_i, axis_j) = match axis_k {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        let dk = d[axis_k];
        let quant = |x: f64| (x * f64::from(1u32 << STEP_W)).round() as i32;
        let (fdx, fdy) = (d[axis_i] / dk.abs(), d[axis_j] / dk.abs());
        let params = FrameParams {
            axis_k,
            axis_i,
            axis_j,
            ni: dims[axis_i],
            nj: dims[axis_j],
            nk: dims[axis_k],
            k_reversed: dk < 0.0,
            dx: quant(fdx),
            dy: quant(fdy),
        };
        let along = DVec3::new(
            fdx * spacing[axis_i],
            fdy * spacing[axis_j],
            spacing[axis_k],
        );
        let min_spacing = spacing.iter().copied().fold(f64::INFINITY, f64::min);
        let diag = DVec3::new(
            dims[0] as f64 * spacing[0],
            dims[1] as f64 * spacing[1],
            dims[2] as f64 * spacing[2],
        )
        .length();
        Ok(Self {
            params,
            opacity_ratio: along.length() / min_spacing,
            voxel_dir: d,
            xray_shift: (diag / along.length()).log2().round().clamp(0.0, 15.0) as u32,
        })
    }
}

impl FrameParams {
    pub fn slice(&self, s: usize) -> SliceConst {
        let mask = (1i64 << STEP_W) - 1;
        let tx = s as i64 * i64::from(self.dx);
        let ty = s as i64 * i64::from(self.dy);
        SliceConst {
            s,
            k: if self.k_reversed { self.nk - 1 - s } else { s },
            shift_x: tx >> STEP_W,
            shift_y: ty >> STEP_W,
            frac_x: (tx & mask) as u32,
            frac_y: (ty & mask) as u32,
        }
    }

    /// Range of shifts over all slices: (min, max) for x and y.
    pub fn shift_range(&self) -> ((i64, i64), (i64, i64)) {
        let first = self.slice(0);
        let last = self.slice(self.nk - 1);
        let mm = |a: i64, b: i64| (a.min(b), a.max(b));
        (
            mm(first.shift_x, last.shift_x),
            mm(first.shift_y, last.shift_y),
        )
    }

    /// Base-plane width and height in rays.
    pub fn base_plane_size(&self) -> (usize, usize) {
        let ((x0, x1), (y0, y1)) = self.shift_range();
        (self.ni + (x1 - x0) as usize, self.nj + (y1 - y0) as usize)
    }

    /// Base-plane pixel of the sample at anchor `(a, b)` in slice `c`.
    pub fn pixel_of(&self, c: &SliceConst, a: usize, b: usize) -> (usize, usize) {
        let ((_, x1), (_, y1)) = self.shift_range();
        (
            (a as i64 - c.shift_x + x1) as usize,
            (b as i64 - c.shift_y + y1) as usize,
        )
    }

    /// The voxel at `(i, j, k)` in frame axes.
    pub fn voxel(&self, vol: &Volume, i: usize, j: usize, k: usize) -> u32 {
        if i >= self.ni || j >= self.nj {
            return 0;
        }
        let mut pos = [0i64; 3];
        pos[self.axis_i] = i as i64;
        pos[self.axis_j] = j as i64;
        pos[self.axis_k] = k as i64;
        vol.get(pos[0], pos[1], pos[2])
    }

    /// Total samples (anchors) in a frame: one per voxel.
    pub fn samples(&self) -> usize {
        self.ni * self.nj * self.nk
    }
}

/// What a frame's sweep asked of the skewed memory (`docs/numerics/frame.md`, "Memory").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SweepAccesses {
    /// Beams fetched from the modules (the RTL's `reads` counter).
    pub beams_read: u64,
    /// Beams whose block the LUT marks empty or masked: no module access, the beam reads as 0.
    pub beams_skipped: u64,
    /// Beams that touched some module twice in one cycle (must be 0).
    pub conflicts: u64,
    /// Module reads, per module.
    pub module_reads: [u64; 16],
}

/// Empty slices a sweep may skip at its front and back (`docs/numerics/frame.md`, "Skipping
/// empty slices"): the leading and trailing slices `s` whose voxel plane `k` lies wholly in blocks
/// the block LUT marks empty or masked (they read as 0). At least one slice is kept. Skipping them
/// leaves every pixel unchanged when a zero sample composites as the identity (MIP; composite with
/// a classification whose entry 0 has alpha 0): their samples are 0, and the zero rules at the
/// ends of the sweep give the neighbouring slices the zeros they would have read.
pub fn empty_slices(params: &FrameParams, lut: &BlockLut) -> (usize, usize) {
    let b = lut.block as usize;
    let empty = |s: usize| -> bool {
        let k = params.slice(s).k;
        let nbi = params.ni.div_ceil(b);
        let nbj = params.nj.div_ceil(b);
        (0..nbi).all(|bi| {
            (0..nbj).all(|bj| {
                let mut blk = [0u32; 3];
                blk[params.axis_i] = bi as u32;
                blk[params.axis_j] = bj as u32;
                blk[params.axis_k] = (k / b) as u32;
                lut.entry(blk).is_none_or(|e| e.empty || e.masked)
            })
        })
    };
    let front = (0..params.nk).take_while(|&s| empty(s)).count();
    if front == params.nk {
        return (params.nk - 1, 0);
    }
    let back = (0..params.nk).rev().take_while(|&s| empty(s)).count();
    (front, back)
}

/// Issues every beam of a frame's sweep to the skewed-memory model in the frame's order (slice
/// `s`, row `b`, beat `m`: `P` voxels along axis `i` from `i = P m`), so the model counts the
/// frame's memory accesses and checks each beam for a module conflict, as the RTL's memory does.
/// `skip` = (slices skipped before, after) the sweep ([`empty_slices`]; `(0, 0)` for all).
pub fn sweep_memory(
    params: &FrameParams,
    skip: (usize, usize),
    mem: &mut SkewMem,
) -> Result<SweepAccesses> {
    let cfg = mem.config();
    let p = cfg.p as usize;
    if p > 16 || !params.ni.is_multiple_of(p) {
        return Err(ModelError::Config(format!(
            "frame: ni = {} is not a multiple of P = {p} (at most 16)",
            params.ni
        )));
    }
    if skip.0 + skip.1 >= params.nk {
        return Err(ModelError::Config(format!(
            "frame: skipping {} + {} of {} slices leaves none",
            skip.0, skip.1, params.nk
        )));
    }
    let axis = Axis::ALL[params.axis_i];
    let (read0, skipped0, conflicts0) = (mem.beams_read, mem.beams_skipped, mem.checker.conflicts);
    let rd0: Vec<u32> = (0..p).map(|k| mem.counters(k).0).collect();
    let mut module_reads = [0u64; 16];
    for s in skip.0..params.nk - skip.1 {
        let k = params.slice(s).k;
        for b in 0..params.nj {
            for m in 0..params.ni / p {
                let mut pos = [0u32; 3];
                pos[params.axis_i] = (m * p) as u32;
                pos[params.axis_j] = b as u32;
                pos[params.axis_k] = k as u32;
                let out = mem.command(&SkewIn::read(pos, axis));
                if out.outside {
                    return Err(ModelError::Config(format!(
                        "frame: beam at {pos:?} lies outside the memory's volume"
                    )));
                }
                if !(out.empty || out.masked) {
                    for i in 0..p {
                        let mut c = pos;
                        c[params.axis_i] += i as u32;
                        module_reads[module_of(&cfg, c) as usize] += 1;
                    }
                }
            }
        }
    }
    // The model's own per-module counters wrap at 2^CntW: they agree modulo that width.
    let mask = cfg.cnt_mask();
    for (k, r0) in rd0.iter().enumerate() {
        debug_assert_eq!(
            (u64::from(*r0) + module_reads[k]) & mask,
            u64::from(mem.counters(k).0)
        );
    }
    Ok(SweepAccesses {
        beams_read: mem.beams_read - read0,
        beams_skipped: mem.beams_skipped - skipped0,
        conflicts: mem.checker.conflicts - conflicts0,
        module_reads,
    })
}

/// The interpolation input of the sample at anchor `(a, b)` of slice `c` (frame contract).
pub fn sample_input(
    params: &FrameParams,
    vol: &Volume,
    c: &SliceConst,
    a: usize,
    b: usize,
    cfg: &TrilinConfig,
) -> TrilinIn {
    let v = |da: usize, db: usize| params.voxel(vol, a + da, b + db, c.k);
    bilinear_input(c, [v(0, 0), v(1, 0), v(0, 1), v(1, 1)], cfg)
}

/// The interpolation input of a bilinear sample of the corners `[(a, b), (a+1, b), (a, b+1),
/// (a+1, b+1)]` with slice `c`'s weights (the fractions truncated to `WeightW` bits).
pub fn bilinear_input(c: &SliceConst, corners: [u32; 4], cfg: &TrilinConfig) -> TrilinIn {
    let w = |f: u32| f >> (STEP_W - cfg.weight_w);
    let [v00, v10, v01, v11] = corners;
    TrilinIn {
        voxels: [v00, v10, v01, v11, 0, 0, 0, 0],
        weights: [w(c.frac_x), w(c.frac_y), 0],
        mode: TrilinMode::Lerp,
    }
}

/// The contract's zero rule: slice `t` or anchor `(a, b)` outside the volume's face and slices.
pub fn outside_face(params: &FrameParams, t: i64, a: i64, b: i64) -> bool {
    t < 0
        || t >= params.nk as i64
        || a < 0
        || b < 0
        || a >= params.ni as i64
        || b >= params.nj as i64
}

/// The voxels of `vol` as the samples read them: `(t, i, j)` is voxel `(i, j)` of slice number
/// `t` (processing order), 0 off the face ([`FrameParams::voxel`]).
pub fn volume_voxels<'a>(
    params: &'a FrameParams,
    vol: &'a Volume,
) -> impl Fn(usize, usize, usize) -> u32 + 'a {
    move |t, i, j| params.voxel(vol, i, j, params.slice(t).k)
}

/// `S'(t)` of the contract: the bilinear sample of slice number `t` (processing order; zero
/// outside `0..nk`) at anchor `(a, b)` (zero outside the face) with the weights of slice `c`, from
/// `voxel(t, i, j)` (the whole volume's [`volume_voxels`], or a section's own).
pub fn sample_at(
    params: &FrameParams,
    c: &SliceConst,
    (t, a, b): (i64, i64, i64),
    trilin: &Trilin,
    voxel: &impl Fn(usize, usize, usize) -> u32,
) -> u32 {
    if outside_face(params, t, a, b) {
        return 0;
    }
    let (t, a, b) = (t as usize, a as usize, b as usize);
    let v = |da: usize, db: usize| voxel(t, a + da, b + db);
    let corners = [v(0, 0), v(1, 0), v(0, 1), v(1, 1)];
    trilin.sample(&bilinear_input(c, corners, &trilin.config()))
}

/// The gradient neighbourhood of the contract: `[C, x-, x+, y-, y+, B (slice before), A (after)]`.
pub fn neighbourhood(
    params: &FrameParams,
    vol: &Volume,
    c: &SliceConst,
    a: usize,
    b: usize,
    trilin: &Trilin,
) -> [u32; 7] {
    neighbourhood_from(params, c, (a, b), trilin, &volume_voxels(params, vol))
}

/// The seven samples `S'(t)` of anchor `(a, b)`'s neighbourhood in slice `c`, in [`N6_OFFSETS`]
/// order (`[C, x-, x+, y-, y+, B, A]`), from `voxel` (as [`sample_at`]).
pub fn neighbourhood_from(
    params: &FrameParams,
    c: &SliceConst,
    (a, b): (usize, usize),
    trilin: &Trilin,
    voxel: &impl Fn(usize, usize, usize) -> u32,
) -> [u32; 7] {
    let (a, b, s) = (a as i64, b as i64, c.s as i64);
    N6_OFFSETS.map(|(di, dj, dk)| {
        let at = (s + i64::from(dk), a + i64::from(di), b + i64::from(dj));
        sample_at(params, c, at, trilin, voxel)
    })
}

/// One plane of samples in anchor order (`b` outer, `a` inner), for slice `s`.
pub fn sample_plane(params: &FrameParams, vol: &Volume, s: usize, trilin: &Trilin) -> Vec<u32> {
    let c = params.slice(s);
    let cfg = trilin.config();
    let mut out = Vec::with_capacity(params.ni * params.nj);
    for b in 0..params.nj {
        for a in 0..params.ni {
            out.push(trilin.sample(&sample_input(params, vol, &c, a, b, &cfg)));
        }
    }
    out
}

/// Folds every sample of every ray, in slice order, into a per-ray accumulator: the model's view of
/// the compositing buffer. `init` is the coxel of a ray with no sample yet; `step(coxel, slice,
/// anchor (a, b), sample)` returns the updated coxel.
pub fn fold_rays<T: Clone>(
    params: &FrameParams,
    vol: &Volume,
    trilin: &Trilin,
    init: T,
    mut step: impl FnMut(&T, &SliceConst, (usize, usize), u32) -> T,
) -> (usize, usize, Vec<T>) {
    let (w, h) = params.base_plane_size();
    let mut coxels = vec![init; w * h];
    for s in 0..params.nk {
        let c = params.slice(s);
        let plane = sample_plane(params, vol, s, trilin);
        for b in 0..params.nj {
            for a in 0..params.ni {
                let (r, q) = params.pixel_of(&c, a, b);
                let idx = q * w + r;
                coxels[idx] = step(&coxels[idx], &c, (a, b), plane[b * params.ni + a]);
            }
        }
    }
    (w, h, coxels)
}

/// Warps a base-plane image (`w` x `h` rays, RGB in 0..1) onto the final image seen by `camera`
/// (model only; bilinear, zero outside the base plane). Each output pixel's ray is followed to the
/// front slice; the ray through front-slice point `(i, j)` is base-plane ray `(i, j)`.
pub fn warp(
    params: &FrameParams,
    spacing: [f64; 3],
    base: &[[f64; 3]],
    (w, h): (usize, usize),
    camera: &Camera,
) -> ImageF64 {
    let ((_, max_sx), (_, max_sy)) = params.shift_range();
    let k0 = params.slice(0).k as f64;
    let sp = DVec3::from_array(spacing);
    let dir_v = camera.dir / sp;
    let texel = |x: i64, y: i64| -> [f64; 3] {
        if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
            [0.0; 3]
        } else {
            base[y as usize * w + x as usize]
        }
    };
    // Output rows in parallel, each pixel on its own.
    let mut rgb = vec![[0.0; 3]; (camera.width * camera.height) as usize];
    let row_len = (camera.width as usize).max(1);
    rgb.par_chunks_mut(row_len)
        .enumerate()
        .for_each(|(py, row)| {
            for (px, out) in row.iter_mut().enumerate() {
                let (px, py) = (px as u32, py as u32);
                let o = camera.ray_origin(px, py) / sp;
                let t = (k0 - o[params.axis_k]) / dir_v[params.axis_k];
                let p = o + dir_v * t;
                let (x, y) = (
                    p[params.axis_i] + max_sx as f64,
                    p[params.axis_j] + max_sy as f64,
                );
                *out = crate::units::cube5_warp::bilinear_f64(x, y, texel);
            }
        });
    ImageF64 {
        width: camera.width,
        height: camera.height,
        rgb,
    }
}

/// What the frame composites (docs/numerics/frame.md, "Render modes"; the frame's `render`
/// field, `cube5_frame.regs.toml`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameMode {
    /// Maximum intensity projection: density ramp LUT, unlit, compositing `Max`.
    Mip,
    /// Front-to-back `over` with classification and reflectance-map shading.
    Composite,
    /// Minimum intensity projection: density ramp LUT, unlit, compositing `Min` from a coxel of
    /// `A = 2^(AccW+1) - 1` ([`FrameMode::initial_coxel`]).
    Minip,
    /// X-ray: density ramp LUT, unlit, compositing `XraySum` at the set-up's `XrayShift`.
    Xray,
    /// The shaded colour of the first sample whose classified alpha reaches the threshold:
    /// transfer function, lit, compositing `FirstOpaque`, opacity LUT bypassed.
    FirstOpaque,
}

impl FrameMode {
    pub const ALL: [Self; 5] = [
        Self::Mip,
        Self::Composite,
        Self::Minip,
        Self::Xray,
        Self::FirstOpaque,
    ];

    /// The `render` field's code (`RENDER_*`, generated from `cube5_frame.regs.toml`).
    pub fn code(self) -> u32 {
        use crate::regs::cube5_frame as r;
        match self {
            Self::Mip => r::RENDER_MIP,
            Self::Composite => r::RENDER_COMPOSITE,
            Self::Minip => r::RENDER_MINIP,
            Self::Xray => r::RENDER_XRAY,
            Self::FirstOpaque => r::RENDER_FIRST_OPAQUE,
        }
    }

    /// The shader runs unlit and the class table is the density ramp (MIP, MinIP, X-ray); a
    /// frame without gradient and shader renders exactly these.
    pub fn unlit(self) -> bool {
        matches!(self, Self::Mip | Self::Minip | Self::Xray)
    }

    /// The compositing unit's mode.
    pub fn compos_mode(self) -> ComposMode {
        match self {
            Self::Mip => ComposMode::Max,
            Self::Composite => ComposMode::FrontToBack,
            Self::Minip => ComposMode::Min,
            Self::Xray => ComposMode::XraySum,
            Self::FirstOpaque => ComposMode::FirstOpaque,
        }
    }

    /// The coxel every ray starts from, and what a ray no sample reaches reads out: the empty
    /// coxel, except for MinIP, whose `A` is all ones (above every corrected alpha, so the first
    /// sample always wins `Min`) and whose colour stays 0 (black, as the f64 reference shows a ray
    /// without samples).
    pub fn initial_coxel(self, cfg: &ComposConfig) -> Coxel {
        let mut c = Coxel::empty(cfg);
        if self == Self::Minip {
            c.rgba[3] = cfg.chan_max();
        }
        c
    }

    /// The compositing depth of the sample at anchor `(a, b)` of slice `c`: the slice number `s`,
    /// except that MinIP leaves out the samples past a far face (anchor `a = ni - 1` with
    /// `fx(s) != 0`, or `b = nj - 1` with `fy(s) != 0`: they lie beyond the last voxel and their
    /// interpolation reads the zeros there), giving them depth `Znone`, which the compositing
    /// unit's depth test passes by. The f64 reference takes MinIP over the samples inside the
    /// volume alike.
    pub fn sample_depth(
        self,
        params: &FrameParams,
        c: &SliceConst,
        (a, b): (usize, usize),
        cfg: &ComposConfig,
    ) -> u32 {
        let past = (a + 1 == params.ni && c.frac_x != 0) || (b + 1 == params.nj && c.frac_y != 0);
        if self == Self::Minip && past {
            cfg.z_none()
        } else {
            c.s as u32
        }
    }

    /// The model's fast path (`fast.rs`) renders this mode; the others run the exact per-sample
    /// model ([`render_base_plane_reference`]): the same bits, slower.
    pub fn fast_path(self) -> bool {
        matches!(self, Self::Mip | Self::Composite)
    }
}

/// What a frame's tables depend on beyond the mode and the view (the scene's `[render]` and
/// `[transfer]` fields).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeOptions {
    /// Early termination at this accumulated opacity (`Composite` only; `None` or >= 1: off).
    pub early_termination: Option<f64>,
    /// First-opaque: the classified alpha (0..=1, the transfer function's per-voxel opacity) that
    /// counts as opaque.
    pub threshold: f64,
    /// The 2-D transfer function: opacity grows with the gradient magnitude up to this fraction of
    /// the table's magnitude range ([`ClassLut::boundary`]); `None`: the 1-D table.
    pub boundary: Option<f64>,
}

impl Default for ModeOptions {
    fn default() -> Self {
        Self {
            early_termination: None,
            threshold: 0.5,
            boundary: None,
        }
    }
}

/// The four unit models of one pipeline, with their tables loaded.
#[derive(Debug, Clone)]
pub struct FrameUnits {
    pub trilin: Trilin,
    pub gradient: Gradient,
    pub shader: Shader,
    pub compos: Compos,
    pub mode: FrameMode,
    /// The frame has gradient and shader ([`FrameConfig::shade`]); without them a sample is
    /// classified by the shader's 1-D table alone ([`classify_only`]).
    pub shade: bool,
    /// The shader's 2-D classification (`tf2d`: density and gradient magnitude).
    pub tf2d: bool,
    /// The opaque geometry's RGBA-Z image the compositing buffer is preloaded with (a frame with
    /// `DepthTest = 1`; [`FrameUnits::set_geometry`]); `None`: no geometry, no flush.
    pub geometry: Option<std::sync::Arc<GeometryImage>>,
}

/// One base-plane pixel of the opaque geometry (docs/numerics/frame.md, "Opaque geometry"): the
/// depth `z` in slices from the front of the first opaque surface along the pixel's ray (samples
/// at slices `s >= z` are hidden; `Znone = 2^ZW - 1`: no surface) and its colour codes
/// (`ColorW` bits each).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GeoPixel {
    pub z: u32,
    pub rgb: [u32; 3],
}

/// The RGBA-Z image of the opaque geometry on the base plane, row-major (`q` outer, `r` inner),
/// `width` x `height` = the frame's base plane: the table `DepthTest = 1` preloads per coxel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GeometryImage {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<GeoPixel>,
}

impl GeometryImage {
    /// No geometry anywhere: every pixel at `Znone`, colour 0.
    pub fn none(width: usize, height: usize, cfg: &ComposConfig) -> Self {
        Self {
            width,
            height,
            pixels: vec![
                GeoPixel {
                    z: cfg.z_none(),
                    rgb: [0; 3],
                };
                width * height
            ],
        }
    }

    /// Refuses an image that is not `params`' base plane, or whose depths or colours do not fit
    /// the compositing unit's widths.
    pub fn check(&self, params: &FrameParams, cfg: &ComposConfig) -> Result<()> {
        let (w, h) = params.base_plane_size();
        if (self.width, self.height) != (w, h) || self.pixels.len() != w * h {
            return Err(ModelError::Config(format!(
                "geometry image {} x {} ({} pixels) is not the frame's {w} x {h} base plane",
                self.width,
                self.height,
                self.pixels.len()
            )));
        }
        let cmax = (1u32 << cfg.color_w) - 1;
        if let Some((i, p)) = self
            .pixels
            .iter()
            .enumerate()
            .find(|(_, p)| p.z > cfg.z_none() || p.rgb.iter().any(|&c| c > cmax))
        {
            return Err(ModelError::Config(format!(
                "geometry pixel {i}: depth {} or colour {:?} does not fit ZW = {}, ColorW = {}",
                p.z, p.rgb, cfg.z_w, cfg.color_w
            )));
        }
        Ok(())
    }
}

/// The base-plane image: the final coxel of every ray, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct BasePlane {
    pub width: usize,
    pub height: usize,
    pub coxels: Vec<Coxel>,
}

/// Directions (volume axes) expressed in frame axes `(i, j, s)`, `s` along the sweep.
pub fn to_frame_axes(params: &FrameParams, v: [f64; 3]) -> [f64; 3] {
    let sk = if params.k_reversed { -1.0 } else { 1.0 };
    [v[params.axis_i], v[params.axis_j], sk * v[params.axis_k]]
}

/// The lighting of a frame in frame axes: the viewer looks along +s, rays step `(dx, dy, 1)`.
/// `lights` are given in volume axes (direction towards the light); none means a headlight.
pub fn frame_phong(params: &FrameParams, lights: &[DistantLight]) -> Phong {
    let unit = f64::from(1u32 << STEP_W);
    let to_viewer = [
        -f64::from(params.dx) / unit,
        -f64::from(params.dy) / unit,
        -1.0,
    ];
    let lights = if lights.is_empty() {
        vec![DistantLight {
            direction: to_viewer,
            intensity: 1.0,
        }]
    } else {
        lights
            .iter()
            .map(|l| DistantLight {
                direction: to_frame_axes(params, l.direction),
                ..*l
            })
            .collect()
    };
    Phong {
        view: to_viewer,
        lights,
        ..Phong::two_lights()
    }
}

/// The compositing unit's default early-termination threshold, `1 - 2^-8` of the opacity scale
/// (`ComposRegs::defaults`).
pub const ET_DEFAULT: f64 = 1.0 - 1.0 / 256.0;

/// The MIP classification table of the frame contract: the density ramp, grey.
pub fn density_ramp(cfg: &ShaderConfig) -> Result<ClassLut> {
    let top = (cfg.class_entries() - 1) as u64;
    let scale = |idx: usize, max: u32| ((idx as u64 * u64::from(max)) / top) as u32;
    ClassLut::from_fn(cfg, |idx| Rgba {
        r: scale(idx, cfg.color_max()),
        g: scale(idx, cfg.color_max()),
        b: scale(idx, cfg.color_max()),
        a: scale(idx, cfg.alpha_max()),
    })
}

/// The compositing registers of a frame: MIP bypasses the opacity LUT; composite terminates at
/// `threshold` of the coxel's opacity scale (rounded down), off when absent or >= 1. The other
/// modes: [`mode_regs`].
pub fn compos_regs(cfg: &ComposConfig, mode: FrameMode, threshold: Option<f64>) -> ComposRegs {
    let off = ComposRegs::without_termination(cfg);
    match (mode, threshold) {
        (FrameMode::Composite, Some(t)) if t < 1.0 => ComposRegs {
            et_threshold: (t.max(0.0) * cfg.one() as f64) as u64,
            ..off
        },
        (FrameMode::Composite, _) => off,
        _ => ComposRegs {
            lut_bypass: true,
            ..off
        },
    }
}

/// The compositing registers of a frame in any mode (docs/numerics/frame.md, "Render modes"):
/// [`compos_regs`], with X-ray's shift and first-opaque's threshold `FoThreshold =
/// ceil(threshold 2^Q)`, at most `2^Q` (so a sample is opaque exactly when its alpha code, read
/// as `U(alpha, AlphaW, Q)`, reaches the threshold on the corrected-alpha scale).
pub fn mode_regs(
    cfg: &ComposConfig,
    mode: FrameMode,
    setup: &FrameSetup,
    opts: &ModeOptions,
) -> ComposRegs {
    let regs = compos_regs(cfg, mode, opts.early_termination);
    let one = (1u64 << cfg.q()) as f64;
    ComposRegs {
        xray_shift: if mode == FrameMode::Xray {
            setup.xray_shift
        } else {
            regs.xray_shift
        },
        fo_threshold: if mode == FrameMode::FirstOpaque {
            (opts.threshold.clamp(0.0, 1.0) * one).ceil() as u64
        } else {
            regs.fo_threshold
        },
        ..regs
    }
}

/// A sample of density 0 leaves every coxel of the frame unchanged, so the sweep may leave out
/// empty slices (docs/numerics/frame.md, "Skipping empty slices"): never for MinIP (0 is the
/// minimum), and otherwise when class entry 0 (the 1-D table) composites as the identity: alpha 0
/// under `over` and `FirstOpaque` (below its threshold), colour and alpha 0 under the X-ray sum;
/// always under `Max`.
pub fn zero_sample_is_identity(
    mode: FrameMode,
    tf2d: bool,
    shader: &Shader,
    compos: &Compos,
) -> bool {
    let e = shader.tables().class.entries()[0];
    match mode {
        FrameMode::Mip => true,
        FrameMode::Minip => false,
        FrameMode::Xray => e.r == 0 && e.g == 0 && e.b == 0 && e.a == 0,
        FrameMode::Composite => !tf2d && e.a == 0,
        FrameMode::FirstOpaque => !tf2d && compos.corrected(e.a) < compos.regs().fo_threshold,
    }
}

/// The classification table of a frame: the density ramp for the unlit modes, else the transfer
/// function, as a 1-D table or (with `boundary`) the 2-D table of [`ClassLut::boundary`].
pub fn class_table(
    cfg: &ShaderConfig,
    mode: FrameMode,
    tf: &TransferFunction,
    boundary: Option<f64>,
) -> Result<ClassLut> {
    match (mode.unlit(), boundary) {
        (true, None) => density_ramp(cfg),
        (true, Some(_)) => Err(ModelError::Config(
            "cube5_frame: the 2-D transfer function classifies by the transfer function: composite and first-opaque only".into(),
        )),
        (false, None) => ClassLut::from_transfer(cfg, tf),
        (false, Some(b)) => ClassLut::boundary(cfg, tf, b),
    }
}

impl FrameUnits {
    /// The default widths (trilin v12, gradient v12, shader v12, compos c12) with the tables of
    /// `mode`: for `Composite` the transfer function, the reflectance map of `phong` and the
    /// opacity correction of the set-up; for `Mip` the density ramp and no correction.
    pub fn new(
        mode: FrameMode,
        setup: &FrameSetup,
        tf: &TransferFunction,
        phong: &Phong,
    ) -> Result<Self> {
        Self::with_config(&FrameConfig::DEFAULT, mode, setup, tf, phong, None)
    }

    /// As [`FrameUnits::new`], with the unit widths of `cfg` and early termination at
    /// `early_termination` of the accumulated opacity (`Composite` only; `None` or >= 1: off;
    /// [`ET_DEFAULT`] is the compositing unit's default `1 - 2^-8`). The opacity-correction ratio is
    /// clamped to the LUT's range.
    pub fn with_config(
        cfg: &FrameConfig,
        mode: FrameMode,
        setup: &FrameSetup,
        tf: &TransferFunction,
        phong: &Phong,
        early_termination: Option<f64>,
    ) -> Result<Self> {
        let opts = ModeOptions {
            early_termination,
            ..ModeOptions::default()
        };
        Self::with_options(cfg, mode, setup, tf, phong, &opts)
    }

    /// As [`FrameUnits::with_config`], for every mode: first-opaque's threshold and the 2-D
    /// transfer function in `opts`.
    pub fn with_options(
        cfg: &FrameConfig,
        mode: FrameMode,
        setup: &FrameSetup,
        tf: &TransferFunction,
        phong: &Phong,
        opts: &ModeOptions,
    ) -> Result<Self> {
        if !cfg.shade && !mode.unlit() {
            return Err(ModelError::Config(format!(
                "cube5_frame: Shade = 0 (no gradient, no shader) renders MIP, MinIP and X-ray only; a {mode:?} frame needs Shade = 1"
            )));
        }
        let rmap = ReflectanceMap::from_lights(&cfg.shader, phong)?;
        let class = class_table(&cfg.shader, mode, tf, opts.boundary)?;
        let ratio = if mode == FrameMode::Composite {
            setup
                .opacity_ratio
                .clamp(OpacityLut::RATIO_MIN, OpacityLut::RATIO_MAX)
        } else {
            1.0
        };
        Ok(Self {
            trilin: Trilin::new(cfg.trilin)?,
            gradient: Gradient::new(cfg.gradient)?,
            shader: Shader::new(cfg.shader, ShaderTables { class, rmap })?,
            compos: Compos::new(
                cfg.compos,
                OpacityLut::new(ratio, &cfg.compos)?,
                mode_regs(&cfg.compos, mode, setup, opts),
            )?,
            mode,
            shade: cfg.shade,
            tf2d: opts.boundary.is_some(),
            geometry: None,
        })
    }

    /// Preloads the compositing buffer with the opaque geometry's RGBA-Z image (`DepthTest = 1`):
    /// every ray starts from its pixel's depth and colour, and the read-out flushes the geometry
    /// colour under the ray. The image must be `params`' base plane.
    pub fn set_geometry(&mut self, params: &FrameParams, g: GeometryImage) -> Result<()> {
        g.check(params, &self.compos.config())?;
        self.geometry = Some(std::sync::Arc::new(g));
        Ok(())
    }

    /// The coxel ray `idx` (row-major base-plane pixel) starts from: the mode's initial coxel,
    /// with the geometry's depth and colour where the buffer is preloaded.
    pub fn initial_coxel_at(&self, idx: usize) -> Coxel {
        let mut c = self.initial_coxel();
        if let Some(p) = self.geometry.as_ref().and_then(|g| g.pixels.get(idx)) {
            c.z = p.z;
            c.geo = p.rgb;
        }
        c
    }

    /// The read-out of a preloaded buffer: one `Flush` item per coxel, which composites the
    /// geometry colour under the ray (compos rule 2; `Znone`: only `terminated` is set). Without
    /// geometry the coxel leaves as it is.
    pub fn read_out(&self, c: &Coxel) -> Coxel {
        if self.geometry.is_none() {
            return *c;
        }
        self.compos.step(
            c,
            &Sample {
                rgb: [0; 3],
                alpha: 0,
                depth: 0,
                mode: ComposMode::Flush,
            },
        )
    }

    /// The shader's mode of every sample of this frame.
    pub fn shader_mode(&self) -> ShaderMode {
        ShaderMode {
            tf2d: self.tf2d,
            unlit: self.mode.unlit(),
        }
    }

    /// The fast path renders this frame (its mode, the 1-D table, no geometry: a frame with
    /// geometry runs the exact per-sample model).
    pub fn fast_path(&self) -> bool {
        self.mode.fast_path() && !self.tf2d && self.geometry.is_none()
    }

    /// The coxel every ray starts from ([`FrameMode::initial_coxel`]).
    pub fn initial_coxel(&self) -> Coxel {
        self.mode.initial_coxel(&self.compos.config())
    }

    /// The shaded sample of anchor `(a, b)` in slice `c` (steps 1-4 of the contract).
    pub fn shaded_sample(
        &self,
        params: &FrameParams,
        vol: &Volume,
        c: &SliceConst,
        a: usize,
        b: usize,
    ) -> Sample {
        self.shaded_from(params, c, (a, b), &volume_voxels(params, vol))
    }

    /// [`Self::shaded_sample`] from `voxel` (as [`sample_at`]: the whole volume's, or a section's
    /// own voxels): every mode (MinIP's depth past a far face, the unlit modes, the 2-D table).
    pub fn shaded_from(
        &self,
        params: &FrameParams,
        c: &SliceConst,
        (a, b): (usize, usize),
        voxel: &impl Fn(usize, usize, usize) -> u32,
    ) -> Sample {
        let mode = self.mode.compos_mode();
        let depth = self
            .mode
            .sample_depth(params, c, (a, b), &self.compos.config());
        if !self.shade {
            let centre = sample_at(
                params,
                c,
                (c.s as i64, a as i64, b as i64),
                &self.trilin,
                voxel,
            );
            return Sample {
                mode,
                ..classify_only(&self.shader, centre, depth)
            };
        }
        let n = neighbourhood_from(params, c, (a, b), &self.trilin, voxel);
        Sample {
            mode,
            ..shade_n6(&self.gradient, &self.shader, &n, self.shader_mode(), depth)
        }
    }
}

/// The offsets of the seven samples of a neighbourhood (`neighbourhood`), in the order the seven
/// interpolations are made: the centre, then -/+ along i, j and k.
pub const N6_OFFSETS: [(i32, i32, i32); 7] = [
    (0, 0, 0),
    (-1, 0, 0),
    (1, 0, 0),
    (0, -1, 0),
    (0, 1, 0),
    (0, 0, -1),
    (0, 0, 1),
];

/// The gradient unit's input for the seven samples `nb` of a neighbourhood (in `N6_OFFSETS`
/// order): N6 on the orthogonal neighbours, zero steps.
pub fn n6_gradient_in(nb: &[u32]) -> GradientIn {
    let mut samples = [0u32; 27];
    for (v, (di, dj, dk)) in nb.iter().zip(N6_OFFSETS) {
        samples[block_index(di, dj, dk)] = *v;
    }
    GradientIn {
        samples,
        dx: 0,
        dy: 0,
        mode: GradientMode::N6,
    }
}

/// The frame's adapter from the gradient unit to the shader (components and magnitude `>> 4`).
#[inline]
pub fn shader_in(sample: u32, g: &GradientOut, mode: ShaderMode) -> ShaderIn {
    ShaderIn {
        sample,
        grad: [g.gx >> 4, g.gy >> 4, g.gz >> 4],
        mag: g.mag >> 4,
        mode,
    }
}

/// One sample's way through gradient, adapter and shader: the compositing unit's sample at slice
/// `depth` (MIP when the shader runs unlit, front to back otherwise).
#[inline]
pub fn shade_n6(
    gradient: &Gradient,
    shader: &Shader,
    nb: &[u32; 7],
    mode: ShaderMode,
    depth: u32,
) -> Sample {
    // `gradient.gradient(&n6_gradient_in(nb))`, without building the 27-sample block.
    let [_, xm, xp, ym, yp, zm, zp] = nb.map(i64::from);
    let g = gradient.output(n6_components([xm, xp, ym, yp, zm, zp]));
    let shaded = shader.shade(&shader_in(nb[0], &g, mode));
    Sample {
        rgb: [shaded.r, shaded.g, shaded.b],
        alpha: shaded.a,
        depth,
        mode: if mode.unlit {
            ComposMode::Max
        } else {
            ComposMode::FrontToBack
        },
    }
}

/// A sample's way through a frame without gradient and shader (`Shade = 0`, MIP only;
/// docs/numerics/frame.md, "A frame without gradient and shader"): the entry of the 1-D
/// classification table at the sample's top `ClassIdxW` bits, as it is, composited by `Max` at
/// slice `depth`. The shader's reflectance map is not read.
pub fn classify_only(shader: &Shader, sample: u32, depth: u32) -> Sample {
    let cfg = shader.config();
    let idx = (sample >> (cfg.sample_w() - cfg.class_idx_w)) as usize;
    let e = shader.tables().class.entries()[idx];
    Sample {
        rgb: [e.r, e.g, e.b],
        alpha: e.a,
        depth,
        mode: ComposMode::Max,
    }
}

/// The base-plane image of a frame, bit-exact with `cube5_frame` (docs/numerics/frame.md): the
/// reference, written sample by sample from the contract (seven interpolations per sample through
/// [`neighbourhood`], then gradient, shader and compositing). [`render_base_plane`] is the fast
/// path everything uses; the test `fast_path_equals_the_reference` holds the two equal.
pub fn render_base_plane_reference(
    params: &FrameParams,
    vol: &Volume,
    units: &FrameUnits,
) -> BasePlane {
    let mut bp = render_rays(params, vol, units);
    if units.geometry.is_some() {
        bp.coxels = bp.coxels.iter().map(|c| units.read_out(c)).collect();
    }
    bp
}

/// The coxels of every ray after its last sample, before the read-out (with geometry, the
/// read-out's flush follows: [`FrameUnits::read_out`]).
fn render_rays(params: &FrameParams, vol: &Volume, units: &FrameUnits) -> BasePlane {
    let (w, h) = params.base_plane_size();
    let mut coxels: Vec<Coxel> = (0..w * h).map(|i| units.initial_coxel_at(i)).collect();
    for s in 0..params.nk {
        let c = params.slice(s);
        // Samples of one plane are independent: shade them in parallel, composite in order.
        let plane: Vec<Sample> = (0..params.ni * params.nj)
            .into_par_iter()
            .map(|idx| units.shaded_sample(params, vol, &c, idx % params.ni, idx / params.ni))
            .collect();
        for (idx, sample) in plane.iter().enumerate() {
            let (r, q) = params.pixel_of(&c, idx % params.ni, idx / params.ni);
            let at = q * w + r;
            coxels[at] = units.compos.step(&coxels[at], sample);
        }
    }
    BasePlane {
        width: w,
        height: h,
        coxels,
    }
}

/// The base-plane image of a frame, bit-exact with `cube5_frame`: the fast path where it covers the
/// frame ([`FrameUnits::fast_path`]), else the exact per-sample model
/// ([`render_base_plane_reference`]: the same bits, slower).
pub fn render_base_plane(params: &FrameParams, vol: &Volume, units: &FrameUnits) -> BasePlane {
    render_base_plane_stats(params, vol, units).0
}

/// [`render_base_plane`] with the counts of what its sweep computed and skipped.
pub fn render_base_plane_stats(
    params: &FrameParams,
    vol: &Volume,
    units: &FrameUnits,
) -> (BasePlane, SweepStats) {
    if units.fast_path() {
        render_base_plane_stats_fast(params, vol, units)
    } else {
        render_exact_stats(params, vol, units)
    }
}

/// The exact per-sample model with the counts of a sweep that skips nothing (every sample shaded).
pub fn render_exact_stats(
    params: &FrameParams,
    vol: &Volume,
    units: &FrameUnits,
) -> (BasePlane, SweepStats) {
    // Rays the compositing unit terminated: counted before the read-out's flush (which marks
    // every ray of a frame with geometry terminated).
    let mut bp = render_rays(params, vol, units);
    let rays_terminated = bp.coxels.iter().filter(|c| c.terminated).count() as u64;
    if units.geometry.is_some() {
        bp.coxels = bp.coxels.iter().map(|c| units.read_out(c)).collect();
    }
    let anchors = params.samples() as u64;
    let stats = SweepStats {
        anchors,
        samples: anchors,
        shaded: anchors,
        rays_terminated,
        ..SweepStats::default()
    };
    (bp, stats)
}

impl BasePlane {
    /// Colour of each ray in 0..1 (the coxel's R, G, B on its `2^AccW` scale, clamped).
    pub fn rgb(&self, cfg: &ComposConfig) -> Vec<[f64; 3]> {
        let one = cfg.one() as f64;
        self.coxels
            .iter()
            .map(|c| std::array::from_fn(|i| (c.rgba[i] as f64 / one).min(1.0)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::cube5_skewmem::{SkewConfig, SkewDims};

    /// A volume whose voxels are 0 outside `lo..hi` along each axis (a noisy blob inside).
    fn slab_volume(n: usize, lo: [usize; 3], hi: [usize; 3]) -> Volume {
        let mut data = vec![0u16; n * n * n];
        for z in lo[2]..hi[2] {
            for y in lo[1]..hi[1] {
                for x in lo[0]..hi[0] {
                    data[x + n * (y + n * z)] = (((x * 7 + y * 13 + z * 29) % 97) * 40) as u16;
                }
            }
        }
        Volume::new([n; 3], [1.0; 3], 12, data).unwrap()
    }

    /// The f64 bilinear density of anchor `(a, b)` in slice `c` at the exact fractions (zeros
    /// past the far faces), on 0..1.
    fn f64_sample(params: &FrameParams, vol: &Volume, c: &SliceConst, a: usize, b: usize) -> f64 {
        let unit = f64::from(1u32 << STEP_W);
        let (fx, fy) = (f64::from(c.frac_x) / unit, f64::from(c.frac_y) / unit);
        let v = |i: usize, j: usize| f64::from(params.voxel(vol, i, j, c.k));
        let top = v(a, b) * (1.0 - fx) + v(a + 1, b) * fx;
        let bot = v(a, b + 1) * (1.0 - fx) + v(a + 1, b + 1) * fx;
        (top * (1.0 - fy) + bot * fy) / f64::from((1u32 << vol.bits) - 1)
    }

    /// MinIP and X-ray against the f64 ideal of the same samples: the minimum over the samples
    /// inside the volume (none: 0) and the sum over every sample, divided by `2^XrayShift`. The
    /// bound per sample is the truncated 8-bit weights (`2 * 2^-8` of the full scale), the class
    /// index (`2^-12`), the ramp's colour code (`1/255`), and for X-ray the shifted sum's rounding
    /// (half a coxel LSB per sample); the measured maxima are printed.
    #[test]
    fn minip_and_xray_follow_the_f64_samples() {
        let cfg = FrameConfig::DEFAULT;
        let one = cfg.compos.one() as f64;
        let per_sample = 2.0 / 256.0 + 1.0 / 4095.0 + 1.0 / 255.0;
        let tf = TransferFunction::head_default();
        for vol in [
            crate::phantom::bubbles_phantom(24, 12).unwrap(),
            crate::phantom::head_phantom(24, 12).unwrap(),
        ] {
            for v in [[0.3, -0.7, 1.0], [-1.0, 0.4, 0.2], [0.1, 1.0, -0.45]] {
                let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(v), 4).unwrap();
                let params = setup.params;
                let phong = frame_phong(&params, &[]);
                let unit =
                    |mode| FrameUnits::with_config(&cfg, mode, &setup, &tf, &phong, None).unwrap();
                let (umin, uxr) = (unit(FrameMode::Minip), unit(FrameMode::Xray));
                let (bmin, bxr) = (
                    render_base_plane(&params, &vol, &umin),
                    render_base_plane(&params, &vol, &uxr),
                );
                let lo = fold_rays(
                    &params,
                    &vol,
                    &umin.trilin,
                    f64::INFINITY,
                    |m, c, (a, b), _| {
                        let inside = !((a + 1 == params.ni && c.frac_x != 0)
                            || (b + 1 == params.nj && c.frac_y != 0));
                        if inside {
                            m.min(f64_sample(&params, &vol, c, a, b))
                        } else {
                            *m
                        }
                    },
                )
                .2;
                let sum = fold_rays(
                    &params,
                    &vol,
                    &uxr.trilin,
                    (0.0, 0usize),
                    |m, c, (a, b), _| (m.0 + f64_sample(&params, &vol, c, a, b), m.1 + 1),
                )
                .2;
                let scale = f64::from(1u32 << setup.xray_shift);
                let (mut emin, mut exr) = (0.0f64, 0.0f64);
                for i in 0..lo.len() {
                    let want = if lo[i].is_finite() { lo[i] } else { 0.0 };
                    let got = bmin.coxels[i].rgba[0] as f64 / one;
                    assert!(
                        (got - want).abs() <= per_sample,
                        "{v:?} ray {i}: MinIP {got} vs f64 {want}"
                    );
                    emin = emin.max((got - want).abs());
                    if !lo[i].is_finite() {
                        assert_eq!(bmin.coxels[i], umin.initial_coxel(), "{v:?} ray {i}");
                    }
                    let (s, n) = sum[i];
                    let got = bxr.coxels[i].rgba[0] as f64 / one;
                    let bound = n as f64 / scale * per_sample + n as f64 / one;
                    assert!(
                        (got - s / scale).abs() <= bound,
                        "{v:?} ray {i}: X-ray {got} vs f64 {}",
                        s / scale
                    );
                    exr = exr.max((got - s / scale).abs());
                }
                eprintln!(
                    "{:?} {v:?}: MinIP max |error| {emin:.5}, X-ray (shift {}) {exr:.5} (of 1.0)",
                    vol.dims, setup.xray_shift
                );
            }
        }
    }

    /// The unlit modes render the same with and without gradient and shader; the lit ones are
    /// refused without them.
    #[test]
    fn unlit_modes_render_the_same_without_gradient_and_shader() {
        use crate::unit::UnitConfig;
        let vol = crate::phantom::bubbles_phantom(16, 12).unwrap();
        let tf = TransferFunction::head_default();
        let full = FrameConfig::DEFAULT;
        let bare = FrameConfig::from_params(&[("Shade", 0)]).unwrap();
        let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::new(0.4, -0.2, 1.0), 4).unwrap();
        let phong = frame_phong(&setup.params, &[]);
        for mode in FrameMode::ALL {
            let units =
                |cfg: &FrameConfig| FrameUnits::with_config(cfg, mode, &setup, &tf, &phong, None);
            if mode.unlit() {
                let (uf, ub) = (units(&full).unwrap(), units(&bare).unwrap());
                assert_eq!(
                    render_base_plane(&setup.params, &vol, &uf),
                    render_base_plane(&setup.params, &vol, &ub),
                    "{mode:?}"
                );
            } else {
                let e = units(&bare).unwrap_err().to_string();
                assert!(e.contains("Shade = 0"), "{mode:?}: {e}");
            }
        }
    }

    /// First-opaque: each ray's coxel is the shaded sample of the first anchor (in slice order)
    /// whose classified alpha, read as `U(alpha, AlphaW, Q)`, reaches `ceil(threshold 2^Q)`, with
    /// `A = 1.0` and the ray terminated; a ray without one stays empty. The threshold compares
    /// with the classified alpha as the transfer function's per-voxel opacity (the f64
    /// reference's `a >= threshold`) to within one alpha code.
    #[test]
    fn first_opaque_takes_the_first_sample_at_the_threshold() {
        use crate::units::cube5_compos::unit_code;
        let vol = crate::phantom::head_phantom(24, 12).unwrap();
        let cfg = FrameConfig::DEFAULT;
        let c = cfg.compos;
        let pt = |density, rgba| crate::transfer::TfPoint { density, rgba };
        let tf = TransferFunction {
            points: vec![
                pt(0.0, [0.0; 4]),
                pt(0.15, [0.9, 0.7, 0.6, 0.0]),
                pt(0.5, [0.9, 0.6, 0.5, 0.6]),
                pt(1.0, [1.0, 1.0, 1.0, 0.95]),
            ],
        };
        for (v, t) in [([0.3, -0.7, 1.0], 0.5), ([-1.0, 0.4, 0.2], 0.2)] {
            let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(v), 4).unwrap();
            let params = setup.params;
            let phong = frame_phong(&params, &[]);
            let opts = ModeOptions {
                threshold: t,
                ..ModeOptions::default()
            };
            let u =
                FrameUnits::with_options(&cfg, FrameMode::FirstOpaque, &setup, &tf, &phong, &opts)
                    .unwrap();
            let fo = u.compos.regs().fo_threshold;
            let q1 = (1u64 << c.q()) as f64;
            assert!(fo as f64 >= t * q1 && (fo as f64) < t * q1 + 1.0);
            let bp = render_base_plane(&params, &vol, &u);
            let want = fold_rays(&params, &vol, &u.trilin, None, |hit, sc, (a, b), _| {
                if hit.is_some() {
                    return *hit;
                }
                let smp = u.shaded_sample(&params, &vol, sc, a, b);
                (unit_code(smp.alpha, c.alpha_w, c.q()) >= fo).then_some(smp.rgb)
            })
            .2;
            let mut hits = 0;
            for (i, (got, w)) in bp.coxels.iter().zip(&want).enumerate() {
                match w {
                    Some(rgb) => {
                        hits += 1;
                        let cw = rgb.map(|x| unit_code(x, c.color_w, c.acc_w));
                        assert_eq!(got.rgba, [cw[0], cw[1], cw[2], c.one()], "{v:?} ray {i}");
                        assert!(got.terminated, "{v:?} ray {i}");
                    }
                    None => assert_eq!(*got, u.initial_coxel(), "{v:?} ray {i}"),
                }
            }
            assert!(hits > 0 && hits < want.len(), "{v:?}: {hits} hits");
        }
    }

    /// The 2-D table of boundary emphasis: each density bin's colour is the 1-D transfer
    /// function's at its centre, its alpha grows with the magnitude bin to the function's alpha
    /// at `boundary` of the range and stays there; the frame reads the 2-D index (the image
    /// changes) and the exact model renders it (no fast path).
    #[test]
    fn the_boundary_table_grows_with_the_magnitude() {
        let cfg = FrameConfig::DEFAULT.shader;
        let tf = TransferFunction::head_default();
        let t = ClassLut::boundary(&cfg, &tf, 0.25).unwrap();
        let mags = 1usize << cfg.mag_idx_w;
        let den_n = (cfg.class_entries() / mags) as f64;
        for den in 0..cfg.class_entries() / mags {
            let row = &t.entries()[den * mags..(den + 1) * mags];
            let f = tf.lookup((den as f64 + 0.5) / den_n);
            let full = (f[3].clamp(0.0, 1.0) * f64::from(cfg.alpha_max())).round() as u32;
            assert!(row.windows(2).all(|w| w[0].a <= w[1].a), "den {den}");
            assert_eq!(row[mags - 1].a, full, "den {den}");
            assert_eq!(row[mags / 4].a, full, "den {den}: at the boundary");
            assert!(row
                .iter()
                .all(|e| e.r == row[0].r && e.g == row[0].g && e.b == row[0].b));
        }
        assert!(ClassLut::boundary(&cfg, &tf, 0.0).is_err());
        let vol = crate::phantom::head_phantom(16, 12).unwrap();
        let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::new(0.3, 0.2, 1.0), 4).unwrap();
        let phong = frame_phong(&setup.params, &[]);
        let fc = FrameConfig::DEFAULT;
        let one = FrameUnits::with_options(
            &fc,
            FrameMode::Composite,
            &setup,
            &tf,
            &phong,
            &ModeOptions::default(),
        )
        .unwrap();
        let opts = ModeOptions {
            boundary: Some(0.25),
            ..ModeOptions::default()
        };
        let two = FrameUnits::with_options(&fc, FrameMode::Composite, &setup, &tf, &phong, &opts)
            .unwrap();
        assert!(one.fast_path() && !two.fast_path() && two.tf2d);
        assert_ne!(
            render_base_plane(&setup.params, &vol, &one),
            render_base_plane(&setup.params, &vol, &two)
        );
        assert!(
            FrameUnits::with_options(&fc, FrameMode::Mip, &setup, &tf, &phong, &opts).is_err(),
            "MIP classifies by density alone"
        );
    }

    /// Skipping the empty slices before and after the sweep (leaving their samples out of the
    /// compositing) changes no pixel, MIP and composite, at views from several faces; and the
    /// rule counts whole empty block planes only.
    #[test]
    fn skipping_empty_slices_changes_no_pixel() {
        let vol = slab_volume(32, [4, 9, 10], [27, 22, 19]);
        let lut = BlockLut::from_volume(&vol, 8, 0).unwrap();
        let tf = TransferFunction::head_default();
        let mut skipped_any = false;
        for v in [
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [0.3, -0.2, 1.0],
            [1.0, 0.1, 0.4],
            [-0.2, -1.0, 0.5],
            [1.0, 0.0, 1.0],
        ] {
            let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(v), 1).unwrap();
            let params = setup.params;
            let (front, back) = empty_slices(&params, &lut);
            // Block planes: z has data in 10..19 -> blocks 1, 2 (8..24): 8 slices before and after.
            if params.axis_k == 2 {
                assert_eq!((front, back), (8, 8), "{v:?}");
            }
            skipped_any |= front + back > 0;
            for mode in [FrameMode::Mip, FrameMode::Composite] {
                let units = FrameUnits::new(mode, &setup, &tf, &frame_phong(&params, &[])).unwrap();
                let full = render_base_plane(&params, &vol, &units);
                let init = Coxel::empty(&units.compos.config());
                let (_, _, part) =
                    fold_rays(&params, &vol, &units.trilin, init, |cox, c, (a, b), _| {
                        if c.s < front || c.s >= params.nk - back {
                            return *cox;
                        }
                        units
                            .compos
                            .step(cox, &units.shaded_sample(&params, &vol, c, a, b))
                    });
                assert!(
                    part == full.coxels,
                    "{mode:?} {v:?}: skipping changed the image"
                );
            }
        }
        assert!(skipped_any);
    }

    /// Every beam of a frame, at every view of the six faces and the 45-degree cases, at P = 1, 2,
    /// 4, 8: no module conflict, each module read equally, one beam per P voxels; an empty block
    /// costs no module access.
    #[test]
    fn every_beam_of_a_frame_is_conflict_free_at_each_p() {
        let dims = [16, 24, 32];
        let views = crate::camera::FACE_DIRECTIONS.into_iter().chain([
            [1.0, 0.0, 1.0],
            [1.0 + 1e-3, 0.0, 1.0],
            [-1.0, -1.0, 1.0],
        ]);
        let views: Vec<[f64; 3]> = views.collect();
        for p in [1u32, 2, 4, 8] {
            let cfg = SkewConfig {
                p,
                voxel_w: 12,
                max_dim_log2: 5,
                block: 8,
                read_latency: 1,
                cnt_w: 16,
            };
            for &v in &views {
                let lut = BlockLut::identity(dims, 8).unwrap();
                let sd = SkewDims::new(&cfg, dims.map(|d| d as u32)).unwrap();
                let mut mem = SkewMem::new(cfg, sd, lut).unwrap();
                let params = FrameSetup::new(dims, [1.0; 3], DVec3::from(v), p as usize)
                    .unwrap()
                    .params;
                let acc = sweep_memory(&params, (0, 0), &mut mem).unwrap();
                let voxels = (dims[0] * dims[1] * dims[2]) as u64;
                assert_eq!(acc.conflicts, 0, "P {p} view {v:?}");
                assert_eq!(acc.beams_read, voxels / u64::from(p));
                for k in 0..p as usize {
                    assert_eq!(acc.module_reads[k], voxels / u64::from(p), "module {k}");
                }
                let mut sparse = BlockLut::identity(dims, 8).unwrap();
                sparse.restrict_to([0, 0, 0], [8, 24, 32]);
                let mut mem = SkewMem::new(cfg, sd, sparse.clone()).unwrap();
                let acc = sweep_memory(&params, (0, 0), &mut mem).unwrap();
                assert_eq!(acc.beams_read + acc.beams_skipped, voxels / u64::from(p));
                assert_eq!(acc.beams_read, voxels / 2 / u64::from(p), "half the blocks");
            }
        }
    }

    /// `shade_n6` takes the gradient unit's `N6` output of the seven samples.
    #[test]
    fn shade_n6_uses_the_units_n6_gradient() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let g = Gradient::new(GradientConfig::DEFAULT).unwrap();
        let max = GradientConfig::DEFAULT.sample_max();
        for _ in 0..10_000 {
            let nb: [u32; 7] = std::array::from_fn(|_| match rng.random_range(0..3) {
                0 => 0,
                _ => rng.random_range(0..=max),
            });
            let [_, xm, xp, ym, yp, zm, zp] = nb.map(i64::from);
            assert_eq!(
                g.output(n6_components([xm, xp, ym, yp, zm, zp])),
                g.gradient(&n6_gradient_in(&nb)),
                "{nb:?}"
            );
        }
    }

    #[test]
    fn major_axis_and_ties() {
        let p = |v: DVec3| FrameSetup::new([16; 3], [1.0; 3], v, 4).unwrap().params;
        assert_eq!(p(DVec3::new(0.0, 0.0, 1.0)).axis_k, 2);
        assert_eq!(p(DVec3::new(1.0, 0.2, 0.1)).axis_k, 0);
        assert_eq!(p(DVec3::new(0.1, -1.0, 0.3)).axis_k, 1);
        // Exactly 45 degrees: the later axis wins.
        assert_eq!(p(DVec3::new(1.0, 1.0, 0.0)).axis_k, 1);
        assert_eq!(p(DVec3::new(1.0, 0.0, 1.0)).axis_k, 2);
        assert_eq!(p(DVec3::new(0.0, -1.0, 1.0)).axis_k, 2);
        assert_eq!(p(DVec3::new(1.0, 1.0, 1.0)).axis_k, 2);
        // 45 degrees +- a little.
        assert_eq!(p(DVec3::new(1.0 + 1e-3, 1.0, 0.0)).axis_k, 0);
        let q = p(DVec3::new(-1.0, 0.0, -1.0));
        assert!(q.k_reversed && q.dx == -(1 << STEP_W));
    }

    #[test]
    fn bad_views_refused() {
        assert!(FrameSetup::new([16; 3], [1.0; 3], DVec3::ZERO, 4).is_err());
        assert!(FrameSetup::new([16; 3], [1.0; 3], DVec3::new(f64::NAN, 0.0, 1.0), 4).is_err());
        assert!(FrameSetup::new([18, 16, 16], [1.0; 3], DVec3::Z, 4).is_err());
        assert!(FrameSetup::new([16; 3], [1.0; 3], DVec3::Z, 3).is_err());
    }

    #[test]
    fn slice_constants_match_f64_positions() {
        let setup = FrameSetup::new([32; 3], [1.0; 3], DVec3::new(0.37, -0.81, 1.0), 4).unwrap();
        let p = setup.params;
        let (fdx, fdy) = (0.37, -0.81);
        for s in 0..p.nk {
            let c = p.slice(s);
            let x = c.shift_x as f64 + f64::from(c.frac_x) / 65536.0;
            let y = c.shift_y as f64 + f64::from(c.frac_y) / 65536.0;
            // Quantized step error accumulates at most half an LSB per slice.
            let tol = (s as f64 + 1.0) * 0.5 / 65536.0;
            assert!((x - s as f64 * fdx).abs() <= tol && (y - s as f64 * fdy).abs() <= tol);
        }
        let (w, h) = p.base_plane_size();
        let ((x0, x1), (y0, y1)) = p.shift_range();
        assert_eq!((w, h), (32 + (x1 - x0) as usize, 32 + (y1 - y0) as usize));
    }

    #[test]
    fn neighbourhood_is_zero_outside_and_matches_the_plane_inside() {
        let vol = crate::phantom::head_phantom(16, 12).unwrap();
        let p = FrameSetup::new([16; 3], [1.0; 3], DVec3::new(0.2, 0.7, 1.0), 4)
            .unwrap()
            .params;
        let trilin = Trilin::new(TrilinConfig::DEFAULT).unwrap();
        let c = p.slice(5);
        let plane = sample_plane(&p, &vol, 5, &trilin);
        let n = neighbourhood(&p, &vol, &c, 7, 8, &trilin);
        assert_eq!(n[0], plane[8 * 16 + 7]);
        assert_eq!(n[1], plane[8 * 16 + 6]);
        assert_eq!(n[4], plane[9 * 16 + 7]);
        let edge = neighbourhood(&p, &vol, &p.slice(0), 0, 15, &trilin);
        assert_eq!(
            (edge[1], edge[4], edge[5]),
            (0, 0, 0),
            "outside the face and before slice 0"
        );
    }

    #[test]
    fn warped_mip_of_the_phantom_matches_the_reference_mip() {
        // Unquantized MIP of the frame's samples, warped, against the f64 image-order MIP: the
        // same framing and close values prove the geometry of set-up, base plane and warp.
        use crate::render::{render_reference, CompositeMode, RenderParams, View};
        let vol = crate::phantom::head_phantom(32, 12).unwrap();
        let view = View {
            azimuth: 35.0,
            elevation: 25.0,
        };
        let dir = view.direction().unwrap();
        let setup = FrameSetup::new([32; 3], [1.0; 3], dir, 4).unwrap();
        let trilin = Trilin::new(TrilinConfig::DEFAULT).unwrap();
        let (w, h, peaks) = fold_rays(&setup.params, &vol, &trilin, 0u32, |m, _, _, x| (*m).max(x));
        let scale = f64::from(vol.max_value() << 4);
        let base: Vec<[f64; 3]> = peaks.iter().map(|&m| [f64::from(m) / scale; 3]).collect();
        let cam = Camera::new(dir, vol.dims, vol.spacing, 48, 48);
        let warped = warp(&setup.params, vol.spacing, &base, (w, h), &cam);
        let params = RenderParams {
            width: 48,
            height: 48,
            view,
            mode: CompositeMode::Mip,
            ..Default::default()
        };
        let reference = render_reference(&vol, &TransferFunction::head_default(), &params).unwrap();
        let err: f64 = warped
            .rgb
            .iter()
            .zip(&reference.rgb)
            .map(|(a, b)| (a[0] - b[0]).abs())
            .sum::<f64>()
            / warped.rgb.len() as f64;
        eprintln!("mean absolute MIP difference {err}");
        assert!(err < 0.015, "mean absolute MIP difference {err}");
    }

    #[test]
    fn every_ray_gets_its_samples_in_slice_order() {
        let vol = crate::phantom::head_phantom(16, 12).unwrap();
        let setup = FrameSetup::new([16; 3], [1.0; 3], DVec3::new(0.6, 0.3, -1.0), 4).unwrap();
        let trilin = Trilin::new(TrilinConfig::DEFAULT).unwrap();
        let (_, _, trails) = fold_rays(&setup.params, &vol, &trilin, Vec::new(), |t, c, _, _| {
            let mut t = t.clone();
            t.push(c.s);
            t
        });
        let total: usize = trails.iter().map(Vec::len).sum();
        assert_eq!(total, 16 * 16 * 16, "one sample per anchor");
        for t in &trails {
            assert!(
                t.windows(2).all(|w| w[1] == w[0] + 1),
                "consecutive slices: {t:?}"
            );
        }
    }

    /// `Shade = 0`: the frame without gradient and shader. Its MIP image (the 1-D table read at
    /// every sample, `classify_only`) is the full frame's MIP image, through the reference and
    /// the fast path, at the default and the narrow widths; it refuses composite frames and the
    /// parameter takes only 0 and 1, each refusal naming `Shade`.
    #[test]
    fn a_frame_without_gradient_and_shader_renders_the_same_mip() {
        use crate::unit::UnitConfig;
        let vol = crate::phantom::head_phantom(24, 12).unwrap();
        let tf = TransferFunction::head_default();
        let narrow = [
            ("VoxelW", 8),
            ("WeightW", 6),
            ("FracW", 2),
            ("ClassIdxW", 8),
            ("ColorW", 8),
            ("AlphaW", 8),
            ("ExtraW", 0),
            ("AccW", 8),
        ];
        for base in [&[][..], &narrow[..]] {
            let mut with = base.to_vec();
            let full = FrameConfig::from_params(&with).unwrap();
            with.push(("Shade", 0));
            let bare = FrameConfig::from_params(&with).unwrap();
            assert!(full.shade && !bare.shade);
            assert!(bare.to_params().contains(&("Shade", 0)));
            let vol = crate::scene_render::at_voxel_width(&vol, full.trilin.voxel_w).unwrap();
            for v in [[0.0, 0.0, 1.0], [0.3, -0.7, 1.0], [-1.0, 0.4, 0.2]] {
                let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(v), 4).unwrap();
                let params = setup.params;
                let phong = frame_phong(&params, &[]);
                let units = |cfg: &FrameConfig| {
                    FrameUnits::with_config(cfg, FrameMode::Mip, &setup, &tf, &phong, None).unwrap()
                };
                let (uf, ub) = (units(&full), units(&bare));
                let want = render_base_plane_reference(&params, &vol, &uf);
                assert_eq!(
                    render_base_plane_reference(&params, &vol, &ub),
                    want,
                    "{v:?}"
                );
                assert_eq!(render_base_plane(&params, &vol, &ub), want, "{v:?}");
                assert!(
                    want.coxels.iter().any(|c| c.rgba[3] > 0),
                    "{v:?}: an empty image"
                );
                let e =
                    FrameUnits::with_config(&bare, FrameMode::Composite, &setup, &tf, &phong, None)
                        .unwrap_err()
                        .to_string();
                assert!(e.contains("Shade = 0"), "{e}");
            }
        }
        let e = FrameConfig::from_params(&[("Shade", 2)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("Shade = 2"), "{e}");
    }

    /// The depth test (docs/numerics/frame.md, "Opaque geometry"): geometry at depth 0 hides every
    /// sample and the pixel is the geometry colour, opaque; at depth `Z` the ray keeps exactly the
    /// samples of slices `s < Z` (the same frame over a volume whose slices `s >= Z` are cut off
    /// would differ only where the cut slices reach back through interpolation, so the check is on
    /// the samples themselves: every coxel equals the fold of its samples before `Z`, then the
    /// flush); `Znone` everywhere is the frame without geometry, each ray terminated by the flush.
    #[test]
    fn geometry_hides_the_samples_behind_it_and_shows_under_the_ray() {
        use crate::units::cube5_compos::unit_code;
        let vol = crate::phantom::head_phantom(16, 12).unwrap();
        let tf = TransferFunction::head_default();
        let cfg = FrameConfig {
            depth_test: true,
            ..FrameConfig::DEFAULT
        };
        let c = cfg.compos;
        for v in [[0.3, -0.7, 1.0], [-1.0, 0.4, 0.2]] {
            let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::from(v), 4).unwrap();
            let params = setup.params;
            let (w, h) = params.base_plane_size();
            let phong = frame_phong(&params, &[]);
            for mode in FrameMode::ALL {
                let base = FrameUnits::with_options(
                    &cfg,
                    mode,
                    &setup,
                    &tf,
                    &phong,
                    &ModeOptions::default(),
                )
                .unwrap();
                let plain = render_base_plane_reference(&params, &vol, &base);
                // Znone everywhere: the plain frame, terminated.
                let mut u = base.clone();
                u.set_geometry(&params, GeometryImage::none(w, h, &c))
                    .unwrap();
                let none = render_base_plane_reference(&params, &vol, &u);
                for (a, b) in none.coxels.iter().zip(&plain.coxels) {
                    assert_eq!(
                        *a,
                        Coxel {
                            terminated: true,
                            ..*b
                        },
                        "{mode:?}"
                    );
                }
                // Depth 0: the geometry colour, opaque (MinIP: its A stays all ones, T = 0).
                let g = GeoPixel {
                    z: 0,
                    rgb: [40, 200, 255],
                };
                let mut u = base.clone();
                u.set_geometry(
                    &params,
                    GeometryImage {
                        width: w,
                        height: h,
                        pixels: vec![g; w * h],
                    },
                )
                .unwrap();
                let front = render_base_plane_reference(&params, &vol, &u);
                for px in &front.coxels {
                    if mode == FrameMode::Minip {
                        assert_eq!(px.rgba, [0, 0, 0, c.chan_max()]);
                    } else {
                        let want: [u64; 3] = g.rgb.map(|x| unit_code(x, c.color_w, c.acc_w));
                        assert_eq!(px.rgba[..3], want, "{mode:?}");
                        assert_eq!(px.rgba[3], c.one(), "{mode:?}");
                    }
                }
                // A depth per pixel: the fold of the ray's samples before it, then the flush.
                let pixels: Vec<GeoPixel> = (0..w * h)
                    .map(|i| GeoPixel {
                        z: if i % 7 == 3 {
                            c.z_none()
                        } else {
                            (i * 5 % 19) as u32
                        },
                        rgb: [(i % 256) as u32, 9, 200],
                    })
                    .collect();
                let mut u = base.clone();
                let gi = GeometryImage {
                    width: w,
                    height: h,
                    pixels,
                };
                u.set_geometry(&params, gi.clone()).unwrap();
                let got = render_base_plane_reference(&params, &vol, &u);
                let mut want: Vec<Coxel> = (0..w * h).map(|i| u.initial_coxel_at(i)).collect();
                for s in 0..params.nk {
                    let sc = params.slice(s);
                    for b in 0..params.nj {
                        for a in 0..params.ni {
                            let (r, q) = params.pixel_of(&sc, a, b);
                            let at = q * w + r;
                            if (s as u32) < gi.pixels[at].z {
                                let smp = base.shaded_sample(&params, &vol, &sc, a, b);
                                want[at] = base.compos.step(&want[at], &smp);
                            }
                        }
                    }
                }
                let want: Vec<Coxel> = want.iter().map(|x| u.read_out(x)).collect();
                assert!(got.coxels == want, "{mode:?} {v:?}");
                assert!(!u.fast_path());
            }
        }
        // The image must be the frame's base plane, its codes within the widths.
        let setup = FrameSetup::new(vol.dims, vol.spacing, DVec3::Z, 4).unwrap();
        let mut u = FrameUnits::new(FrameMode::Mip, &setup, &tf, &Phong::two_lights()).unwrap();
        assert!(u
            .set_geometry(&setup.params, GeometryImage::none(3, 3, &c))
            .is_err());
        let (w, h) = setup.params.base_plane_size();
        let mut g = GeometryImage::none(w, h, &c);
        g.pixels[0].rgb[1] = 256;
        assert!(u.set_geometry(&setup.params, g).is_err());
    }
}
