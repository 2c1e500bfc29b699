//! Driving `cube5_frame`, the slice-order machine, against the golden model: the frame's stream
//! and configuration formats (docs/numerics/frame.md, "RTL configuration map"), its verified
//! configurations, the model's image of a frame, and one loaded DUT that renders a frame and
//! compares every pixel and channel. Used by tb-rs/tests/cube5_frame.rs, `cube5 cosim` and `cube5 bench`.
//!
//! A stream item is a command (`render`); its outputs are the W x H coxels of the base plane, so
//! the 1:1 `check_stream` does not apply: the volume and the tables go in through the
//! configuration port, one command is driven with `RtlStream::drive` (expect_out = W H), and the
//! pixels are compared with the model's image.

use crate::error::{Mismatch, TbError};
use crate::rtl::{RtlStream, Taken, Traffic};
use crate::variants::{variants_of, Variant};
use cube5_model::bits::BitWriter;
use cube5_model::error::ModelError;
use cube5_model::geometry;
use cube5_model::scene_render::{FrameJob, FrameRun};
use cube5_model::transfer::TransferFunction;
use cube5_model::unit::StreamCodec;
use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_compos::{self, Compos, ComposConfig, ComposRegs, Coxel, OpacityLut};
use cube5_model::units::cube5_frame::{
    self, FrameConfig, FrameParams, FrameSetup, FrameUnits, GeometryImage, SweepAccesses,
};
use cube5_model::units::cube5_gradient::{Gradient, GradientConfig};
use cube5_model::units::cube5_shader::{
    ClassLut, ReflectanceMap, Shader, ShaderConfig, ShaderMode, ShaderTables,
};
use cube5_model::units::cube5_skewmem::{BlockLut, SkewConfig, SkewDims, SkewMem};
use cube5_model::units::cube5_trilin::{Trilin, TrilinConfig};
use cube5_model::volume::Volume;
use std::rc::Rc;
use std::sync::Arc;

// -------------------------------------------------------------------------------------------------
// The RTL configurations and the frame's stream and configuration formats
// -------------------------------------------------------------------------------------------------

/// One verified configuration of cube5_frame (a line of `rtl/cube5/cube5_frame.variants`): the
/// variant and the model's configuration built from its parameters (`FrameConfig` derefs, so
/// `rtl.p`, `rtl.trilin` read as before).
#[derive(Debug, Clone, Copy)]
pub struct FrameRtl {
    pub variant: &'static Variant,
    pub cfg: FrameConfig,
}

impl std::ops::Deref for FrameRtl {
    type Target = FrameConfig;

    fn deref(&self) -> &FrameConfig {
        &self.cfg
    }
}

/// The top whose variants this module drives.
pub const TOP: &str = FrameConfig::TOP;

impl FrameRtl {
    /// The configuration of `variant` (which must be a `cube5_frame` variant).
    pub fn from_variant(variant: &'static Variant) -> Result<Self, TbError> {
        let cfg = variant
            .config::<FrameConfig>()
            .map_err(|e| TbError::setup(variant.name, e))?;
        Ok(Self { variant, cfg })
    }

    /// Every RTL build of cube5_frame with its skewed memory (`Source = 0`), in `.variants`
    /// order; the beat-stream ones are `FrameRtl::streams` (frame_stream.rs).
    pub fn all() -> Vec<FrameRtl> {
        variants_of(TOP)
            .into_iter()
            .map(|v| Self::from_variant(v).unwrap_or_else(|e| panic!("{e}")))
            .filter(|r| !r.stream)
            .collect()
    }

    /// The configuration with `p` pipelines and the largest memory: the default widths that
    /// `cube5 cosim` and the whole-frame tests run (with gradient and shader, no depth test).
    pub fn with_pipelines(p: usize) -> Option<FrameRtl> {
        Self::all()
            .into_iter()
            .filter(|r| r.p == p && r.default_widths() && r.shade && !r.depth_test)
            .max_by_key(|r| r.max_dim_log2)
    }

    /// The configuration with `p` pipelines and the smallest memory (the narrow, synthesizable
    /// ones).
    pub fn smallest(p: usize) -> Option<FrameRtl> {
        Self::all()
            .into_iter()
            .filter(|r| r.p == p && r.shade && !r.depth_test)
            .min_by_key(|r| r.max_dim_log2)
    }

    /// The configurations without gradient and shader (`Shade = 0`, MIP only).
    pub fn without_shade() -> Vec<FrameRtl> {
        Self::all()
            .into_iter()
            .filter(|r| !r.shade && !r.depth_test)
            .collect()
    }

    /// The configurations with the depth test (`DepthTest = 1`).
    pub fn with_depth_test() -> Vec<FrameRtl> {
        Self::all().into_iter().filter(|r| r.depth_test).collect()
    }

    /// The pipeline counts of the default-width configurations ([`FrameRtl::with_pipelines`]),
    /// ascending.
    pub fn pipeline_counts() -> Vec<usize> {
        let mut ps: Vec<usize> = Self::all()
            .iter()
            .filter(|r| r.default_widths() && r.shade && !r.depth_test)
            .map(|r| r.p)
            .collect();
        ps.sort_unstable();
        ps.dedup();
        ps
    }
}

/// Configuration regions, frame registers, commands and the latencies of the units (trilin.md,
/// gradient.md and compos.md; the shader's and the memory's come from their model
/// configurations): generated from `rtl/cube5/cube5_frame.regs.toml` (`make regs`), the same
/// description as `cube5_frame_pkg`. Only the cycle budget and the smallest-volume rule (compos)
/// depend on the latencies.
pub use cube5_model::regs::cube5_frame::{
    BEAT_LATENCY, CLASS_LATENCY, COMPOS_LATENCY, GRADIENT_LATENCY, OP_RENDER, REGION_BLOCK,
    REGION_COMPOS, REGION_FRAME, REGION_GEOMETRY, REGION_SHADER, REGION_VOXEL, REG_DIMS, REG_DX,
    REG_DY, REG_MODE, REG_MODE_RENDER, REG_MODE_TF2D, REG_SKIP, REG_VIEW, SHADER_PIPE,
    TRILIN_LATENCY,
};

/// The frame's renderings (docs/numerics/frame.md, "Render modes"): the model's modes.
pub use cube5_model::units::cube5_frame::FrameMode as Render;

/// A `render` code the frame refuses (the field's top code; the modes take 0..=4).
pub const RENDER_REFUSED: u32 = (1 << REG_MODE_RENDER.width) - 1;

/// One output item: a base-plane coxel and the frame's status (the drivers expand an item of
/// `OutLanes = P` pixels into its pixels with [`pixels_of`], each with an empty `rest`).
pub use cube5_model::units::cube5_frame::ports::FrameOut;

pub use crate::rtl::ConfigWrites;

impl FrameRtl {
    pub fn skew(&self) -> SkewConfig {
        SkewConfig {
            p: self.p as u32,
            voxel_w: self.trilin.voxel_w,
            max_dim_log2: self.max_dim_log2,
            block: self.block,
            read_latency: self.mem_latency,
            cnt_w: 8,
        }
    }

    /// Bits of a region offset: the widest region.
    fn off_w(&self) -> u32 {
        let m = self.max_dim_log2;
        (3 * m)
            .max(self.skew().blk_w())
            .max(self.shader.cfg_addr_w())
            .max(self.compos.alpha_w + 1)
    }

    pub fn addr(&self, region: u32, off: u32) -> u32 {
        region << self.off_w() | off
    }

    /// One frame register, raw (tests also write values the host set-up would never produce).
    pub fn reg(&self, r: u32, value: u32) -> (u32, Vec<u32>) {
        (self.addr(REGION_FRAME, r), vec![value])
    }

    /// The dimensions register.
    pub fn dims_reg(&self, dims: [u32; 3]) -> (u32, Vec<u32>) {
        let m1 = self.max_dim_log2 + 1;
        let mut w = BitWriter::new();
        for d in dims {
            w.put(u64::from(d), m1);
        }
        (self.addr(REGION_FRAME, REG_DIMS), w.finish(3 * m1))
    }

    /// The frame registers of one view; `skip` = empty slices left out before and after the sweep.
    pub fn frame_writes(
        &self,
        params: &FrameParams,
        render: Render,
        tf2d: bool,
        skip: (usize, usize),
    ) -> Vec<(u32, Vec<u32>)> {
        let mut dims = [0u32; 3];
        dims[params.axis_i] = params.ni as u32;
        dims[params.axis_j] = params.nj as u32;
        dims[params.axis_k] = params.nk as u32;
        let step = |d: i32| (d as u32) & ((1 << 18) - 1);
        vec![
            self.dims_reg(dims),
            self.reg(
                REG_VIEW,
                params.axis_k as u32 | u32::from(params.k_reversed) << 2,
            ),
            self.reg(REG_DX, step(params.dx)),
            self.reg(REG_DY, step(params.dy)),
            self.reg(
                REG_MODE,
                render.code() << REG_MODE_RENDER.lsb | u32::from(tf2d) << REG_MODE_TF2D.lsb,
            ),
            self.reg(
                REG_SKIP,
                (skip.0 | skip.1 << (self.max_dim_log2 + 1)) as u32,
            ),
        ]
    }

    /// The skewed memory's model with this volume's dimensions and block LUT (no voxels: for
    /// counting a sweep's accesses).
    fn memory(&self, dims: [usize; 3], lut: &BlockLut) -> Result<SkewMem, ModelError> {
        let skew = self.skew();
        let sd = SkewDims::new(&skew, dims.map(|d| d as u32))?;
        SkewMem::new(skew, sd, lut.clone())
    }

    /// The block LUT's writes (a voxel is written through its block's pointer).
    pub fn block_writes(
        &self,
        dims: [usize; 3],
        lut: &BlockLut,
    ) -> Result<Vec<(u32, Vec<u32>)>, ModelError> {
        let mem = self.memory(dims, lut)?;
        let blk_mask = (1u32 << self.skew().blk_w()) - 1;
        Ok(mem
            .config_writes()
            .into_iter()
            .skip(1)
            .map(|(a, d)| (self.addr(REGION_BLOCK, a & blk_mask), d))
            .collect())
    }

    /// The dimensions (the memory ignores voxels outside them) and the block LUT first, then
    /// every voxel of the volume.
    pub fn volume_writes(
        &self,
        vol: &Volume,
        lut: &BlockLut,
    ) -> Result<Vec<(u32, Vec<u32>)>, ModelError> {
        let m = self.max_dim_log2;
        let [nx, ny, nz] = vol.dims;
        let mut out = Vec::with_capacity(nx * ny * nz + 1024);
        out.push(self.dims_reg(vol.dims.map(|d| d as u32)));
        out.extend(self.block_writes(vol.dims, lut)?);
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let off = (x | y << m | z << (2 * m)) as u32;
                    out.push((
                        self.addr(REGION_VOXEL, off),
                        vec![vol.get(x as i64, y as i64, z as i64)],
                    ));
                }
            }
        }
        Ok(out)
    }

    pub fn shader_writes(&self, tables: &ShaderTables) -> Vec<(u32, Vec<u32>)> {
        tables
            .config_writes(&self.shader)
            .into_iter()
            .map(|(a, d)| (self.addr(REGION_SHADER, a), d))
            .collect()
    }

    pub fn compos_writes(&self, lut: &OpacityLut, regs: &ComposRegs) -> Vec<(u32, Vec<u32>)> {
        cube5_compos::config_writes(&self.compos, lut, regs)
            .into_iter()
            .map(|(a, d)| (self.addr(REGION_COMPOS, a), d))
            .collect()
    }

    /// The geometry table's writes (`DepthTest = 1`, configuration region 5): one word
    /// `{Z, gR, gG, gB}` per base-plane pixel `(R, Q)` at offset `R + 2^(m+1) Q`.
    pub fn geometry_writes(&self, g: &GeometryImage) -> Vec<(u32, Vec<u32>)> {
        let (m1, zw, cw) = (self.max_dim_log2 + 1, self.compos.z_w, self.compos.color_w);
        g.pixels
            .iter()
            .enumerate()
            .map(|(i, px)| {
                let (r, q) = ((i % g.width) as u32, (i / g.width) as u32);
                let mut w = BitWriter::new();
                w.put(u64::from(px.z), zw);
                for c in px.rgb {
                    w.put(u64::from(c), cw);
                }
                (
                    self.addr(REGION_GEOMETRY, r | q << m1),
                    w.finish(zw + 3 * cw),
                )
            })
            .collect()
    }

    /// Cycles from a sample's neighbourhood to its shaded sample: gradient and shader, or the
    /// classification table alone without them (`Shade = 0`).
    pub fn shade_latency(&self) -> u64 {
        if self.shade {
            // The frame's shaders have `Pipe = ShaderPipe` (cube5_frame.regs.toml).
            let shader = ShaderConfig {
                pipe: SHADER_PIPE,
                ..self.shader
            };
            GRADIENT_LATENCY + shader.latency()
        } else {
            CLASS_LATENCY
        }
    }

    /// Cycles from a beat taken to its samples' write-back count in the compositing buffer: the
    /// beat register, the corner register 1, trilin, the sample window's register 1, gradient and
    /// shader (or the table), the buffer read 1, compos, the write-back count 1 (docs/frame-rtl.md,
    /// "Cycle budget").
    pub fn pipeline_latency(&self) -> u64 {
        BEAT_LATENCY + 1 + TRILIN_LATENCY + 1 + self.shade_latency() + 1 + COMPOS_LATENCY + 1
    }

    /// The default unit widths, the only ones `cube5_model::units::cube5_frame::FrameUnits` builds.
    pub fn default_widths(&self) -> bool {
        self.trilin == TrilinConfig::DEFAULT
            && self.gradient == GradientConfig::DEFAULT
            && self.shader == ShaderConfig::DEFAULT
            && self.compos == ComposConfig::DEFAULT
    }

    /// Refuses a volume this configuration cannot hold, naming the limit.
    pub fn check_volume(&self, vol: &Volume) -> Result<(), String> {
        let max = self.max_dim();
        if vol.dims.iter().any(|&d| d > max) {
            return Err(format!(
                "volume {:?} exceeds {}'s memory ({max} voxels per edge)",
                vol.dims, self.variant.name
            ));
        }
        if vol.dims.iter().any(|&d| !d.is_multiple_of(self.p)) {
            return Err(format!(
                "volume {:?}: every edge must be a multiple of P = {} for {}",
                vol.dims, self.p, self.variant.name
            ));
        }
        if vol.bits != self.trilin.voxel_w {
            return Err(format!(
                "volume of {}-bit voxels; {} takes {}-bit voxels",
                vol.bits, self.variant.name, self.trilin.voxel_w
            ));
        }
        Ok(())
    }
}

// -------------------------------------------------------------------------------------------------
// The model side: the base-plane image of a frame, from the unit models along each ray
// -------------------------------------------------------------------------------------------------

/// The units of one rendering, configured as the frame contract says.
pub struct Units {
    pub trilin: Trilin,
    pub gradient: Gradient,
    pub shader: Shader,
    pub compos: Compos,
    pub render: Render,
    pub tf2d: bool,
}

pub use cube5_model::units::cube5_frame::density_ramp;

/// The look of a rendering: the model's, one description for scenes and the test bench.
pub use cube5_model::scene_render::Look;

impl Units {
    /// The units of `render` for the view of `setup`: the MIP and composite tables written out
    /// here (the test bench's own reading of the contract), the other modes' compositing
    /// registers from the model's `cube5_frame::mode_regs`.
    pub fn new(
        rtl: &FrameRtl,
        render: Render,
        setup: &FrameSetup,
        look: &Look,
    ) -> Result<Self, ModelError> {
        let rmap = ReflectanceMap::from_lights(&rtl.shader, &look.phong)?;
        let class = match (render, look.boundary) {
            (Render::Mip, _) => density_ramp(&rtl.shader)?,
            (Render::Composite, None) => ClassLut::from_transfer(&rtl.shader, &look.tf)?,
            _ => cube5_frame::class_table(&rtl.shader, render, &look.tf, look.boundary)?,
        };
        let tables = ShaderTables { class, rmap };
        let c = rtl.compos;
        let (lut, regs) = match render {
            Render::Mip => (
                OpacityLut::new(1.0, &c)?,
                ComposRegs {
                    lut_bypass: true,
                    ..ComposRegs::without_termination(&c)
                },
            ),
            Render::Composite => (
                OpacityLut::new(setup.opacity_ratio, &c)?,
                if look.early_termination {
                    ComposRegs::defaults(&c)
                } else {
                    ComposRegs::without_termination(&c)
                },
            ),
            m => (
                OpacityLut::new(1.0, &c)?,
                cube5_frame::mode_regs(&c, m, setup, &look.options()),
            ),
        };
        Ok(Self {
            trilin: Trilin::new(rtl.trilin)?,
            gradient: Gradient::new(rtl.gradient)?,
            shader: Shader::new(rtl.shader, tables)?,
            compos: Compos::new(c, lut, regs)?,
            render,
            tf2d: look.boundary.is_some(),
        })
    }

    pub fn config_writes(&self, rtl: &FrameRtl) -> Vec<(u32, Vec<u32>)> {
        let mut w = rtl.shader_writes(self.shader.tables());
        w.extend(rtl.compos_writes(self.compos.lut(), &self.compos.regs()));
        w
    }

    /// One sample's way through gradient, adapter, shader: the compositing unit's sample at
    /// `depth` (the slice number, or MinIP's `Znone` past a far face: `FrameMode::sample_depth`).
    pub fn shaded(&self, nb: [u32; 7], depth: u32) -> cube5_compos::Sample {
        let mode = ShaderMode {
            tf2d: self.tf2d,
            unlit: self.render.unlit(),
        };
        cube5_compos::Sample {
            mode: self.render.compos_mode(),
            ..cube5_frame::shade_n6(&self.gradient, &self.shader, &nb, mode, depth)
        }
    }

    /// The compositing depth of the sample at anchor `ab` of slice `c`.
    pub fn depth(
        &self,
        params: &FrameParams,
        c: &cube5_frame::SliceConst,
        ab: (usize, usize),
    ) -> u32 {
        self.render
            .sample_depth(params, c, ab, &self.compos.config())
    }

    /// The coxel every ray starts from (MinIP: `A` all ones).
    pub fn initial_coxel(&self) -> Coxel {
        self.render.initial_coxel(&self.compos.config())
    }
}

/// The acceptance views of whole frames (one list for every frame-level test bench: cube5_frame,
/// cube5_accel): the six faces, exactly 45 degrees and 45 +- 1e-3, 45 degrees between two
/// negative axes, the space diagonal, obliques (DX < 0 and reversed sweeps among them).
pub const VIEWS: &[(&str, [f64; 3])] = &[
    ("+z", [0.0, 0.0, 1.0]),
    ("-z", [0.0, 0.0, -1.0]),
    ("+x", [1.0, 0.0, 0.0]),
    ("-x", [-1.0, 0.0, 0.0]),
    ("+y", [0.0, 1.0, 0.0]),
    ("-y", [0.0, -1.0, 0.0]),
    ("45 xz", [1.0, 0.0, 1.0]),
    ("45+1e-3 xz", [1.0 + 1e-3, 0.0, 1.0]),
    ("45-1e-3 xz", [1.0 - 1e-3, 0.0, 1.0]),
    ("45 -x-y", [-1.0, -1.0, 0.0]),
    ("diagonal", [1.0, 1.0, 1.0]),
    OBLIQUE_Z,
    ("oblique y", [0.6, -1.0, 0.3]),
    ("oblique x", [0.9, 0.45, -0.2]),
];

/// The oblique view most single-frame tests render.
pub const OBLIQUE_Z: (&str, [f64; 3]) = ("oblique z", [-0.37, 0.81, -1.0]);

/// A non-cubic volume: two overlapping soft ellipsoids, some noise, and an empty corner (so the
/// block LUT has empty blocks to skip).
pub fn blob_volume(dims: [usize; 3], bits: u32, seed: u64) -> Volume {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let max = f64::from((1u32 << bits) - 1);
    let [nx, ny, nz] = dims;
    let c = [nx as f64 * 0.55, ny as f64 * 0.45, nz as f64 * 0.5];
    let mut data = Vec::with_capacity(nx * ny * nz);
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let p = [x as f64, y as f64, z as f64];
                let d1 = ((p[0] - c[0]) / (nx as f64 * 0.35)).powi(2)
                    + ((p[1] - c[1]) / (ny as f64 * 0.3)).powi(2)
                    + ((p[2] - c[2]) / (nz as f64 * 0.4)).powi(2);
                let d2 = ((p[0] - c[0] * 0.6) / (nx as f64 * 0.15)).powi(2)
                    + ((p[1] - c[1] * 1.4) / (ny as f64 * 0.2)).powi(2)
                    + ((p[2] - c[2]) / (nz as f64 * 0.25)).powi(2);
                let mut v = 0.45 * (1.0 - d1).max(0.0) + 0.6 * (1.0 - d2).max(0.0);
                if x < nx / 4 && y < ny / 4 {
                    v = 0.0;
                } else if v > 0.0 {
                    v += rng.random_range(0.0..0.08);
                }
                data.push((v.min(1.0) * max).round() as u16);
            }
        }
    }
    Volume::new(dims, [1.0; 3], bits, data).expect("a valid volume")
}

/// `vol` resampled to `dims` (nearest voxel: the voxel whose centre is nearest along each axis),
/// for the non-cubic acceptance volumes made from the cubic phantoms.
pub fn resampled(vol: &Volume, dims: [usize; 3]) -> Volume {
    let src = vol.dims;
    let at = |a: usize, d: usize| ((2 * d + 1) * src[a] / (2 * dims[a])).min(src[a] - 1);
    let mut data = Vec::with_capacity(dims.iter().product());
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                data.push(vol.data[at(0, x) + src[0] * (at(1, y) + src[1] * at(2, z))]);
            }
        }
    }
    Volume::new(dims, [1.0; 3], vol.bits, data).expect("a valid volume")
}

/// A transfer function with opaque tissue: first-opaque needs samples that reach the threshold, and
/// the 2-D table changes the image (the mode tests of cube5_frame and cube5_accel).
pub fn dense_tf() -> TransferFunction {
    use cube5_model::transfer::TfPoint;
    let p = |density, rgba| TfPoint { density, rgba };
    TransferFunction {
        points: vec![
            p(0.0, [0.0; 4]),
            p(0.1, [0.9, 0.7, 0.6, 0.0]),
            p(0.4, [0.9, 0.6, 0.5, 0.55]),
            p(1.0, [1.0, 1.0, 1.0, 0.95]),
        ],
    }
}

/// A sparse scene for the empty-space figures: an `n`^3 volume whose voxels are random (seeded)
/// inside the box `lo..hi` and 0 elsewhere.
pub fn sparse_box_volume(n: usize, lo: [usize; 3], hi: [usize; 3], seed: u64) -> Volume {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut data = vec![0u16; n * n * n];
    for z in lo[2]..hi[2] {
        for y in lo[1]..hi[1] {
            for x in lo[0]..hi[0] {
                data[x + n * (y + n * z)] = rng.random_range(0..4096);
            }
        }
    }
    Volume::new([n; 3], [1.0; 3], 12, data).expect("a valid volume")
}

/// The sparse scene of the tests and the benchmark: 64^3 with data in [20, 44) x [14, 50) x [22, 41).
pub fn sparse_scene(seed: u64) -> Volume {
    sparse_box_volume(64, [20, 14, 22], [44, 50, 41], seed)
}

/// What the memory returns: the volume with the voxels of skipped blocks (empty or masked) read as
/// 0 (docs/numerics/skewmem.md).
pub use cube5_model::scene_render::seen_through as as_seen;

/// The base-plane image from the unit models along each ray (`cube5_frame::fold_rays`): the test
/// bench's own fold, a cross-check of `cube5_frame::render_base_plane` (tests/cube5_frame.rs).
pub fn model_image(
    params: &FrameParams,
    vol: &Volume,
    units: &Units,
) -> (usize, usize, Vec<Coxel>) {
    let init = units.initial_coxel();
    cube5_frame::fold_rays(params, vol, &units.trilin, init, |cox, c, (a, b), _| {
        let nb = cube5_frame::neighbourhood(params, vol, c, a, b, &units.trilin);
        units
            .compos
            .step(cox, &units.shaded(nb, units.depth(params, c, (a, b))))
    })
}

/// The samples of ray (r, q) (base-plane pixel), for a mismatch report.
pub fn ray_trail(params: &FrameParams, vol: &Volume, units: &Units, r: usize, q: usize) -> String {
    let mut trail = String::new();
    let init = units.initial_coxel();
    let _ = cube5_frame::fold_rays(params, vol, &units.trilin, init, |cox, c, (a, b), x| {
        if params.pixel_of(c, a, b) != (r, q) {
            return *cox;
        }
        let nb = cube5_frame::neighbourhood(params, vol, c, a, b, &units.trilin);
        let smp = units.shaded(nb, units.depth(params, c, (a, b)));
        let next = units.compos.step(cox, &smp);
        if trail.len() < 4000 {
            trail.push_str(&format!(
                "\n      slice {:3} (k {:3}) anchor ({:3}, {:3}) sample {:6} nb {:?} -> rgb {:?} a {} -> coxel {:?} a {}",
                c.s, c.k, a, b, x, nb, smp.rgb, smp.alpha, next.rgba, next.terminated
            ));
        }
        next
    });
    trail
}

/// One frame as the model sees it: the view, the units and the base-plane image. Independent of P.
pub struct Expected {
    /// The volume as the memory returns it (skipped blocks read as 0).
    pub seen: Rc<Volume>,
    pub view: String,
    pub dir: [f64; 3],
    pub params: FrameParams,
    pub units: Units,
    pub w: usize,
    pub h: usize,
    pub want: Vec<Coxel>,
    /// The geometry table of a `DepthTest = 1` frame (the model's preload).
    pub geometry: Option<Arc<GeometryImage>>,
}

impl Expected {
    /// The model's image of `seen` viewed along `dir`.
    pub fn new(
        rtl: &FrameRtl,
        seen: &Rc<Volume>,
        view: &str,
        dir: [f64; 3],
        render: Render,
        look: &Look,
    ) -> Result<Self, ModelError> {
        let (params, fu) = Self::model_units(rtl, seen, dir, render, look)?;
        let geometry = fu.geometry.clone();
        // The model's own base plane at the variant's widths
        // (cube5_model::units::cube5_frame::render_base_plane): what `cube5 render` computes.
        let bp = cube5_frame::render_base_plane(&params, seen, &fu);
        let units = Units {
            trilin: fu.trilin,
            gradient: fu.gradient,
            shader: fu.shader,
            compos: fu.compos,
            render,
            tf2d: fu.tf2d,
        };
        let (w, h, want) = (bp.width, bp.height, bp.coxels);
        Ok(Expected {
            seen: seen.clone(),
            view: view.to_string(),
            dir,
            params,
            units,
            w,
            h,
            want,
            geometry,
        })
    }
}

impl Expected {
    /// The frame's parameters and the model's units at the variant's widths for `seen` viewed
    /// along `dir` with `look` (the geometry table rasterized when the variant has the depth test).
    /// The set-up is that of P = 1: the image does not depend on P (only the set-up's check that
    /// the dimensions are multiples of P does).
    pub fn model_units(
        rtl: &FrameRtl,
        seen: &Volume,
        dir: [f64; 3],
        render: Render,
        look: &Look,
    ) -> Result<(FrameParams, FrameUnits), ModelError> {
        let mut setup = FrameSetup::new(seen.dims, seen.spacing, dir.into(), 1)?;
        if let Some(x) = look.xray_shift {
            setup.xray_shift = x;
        }
        let params = setup.params;
        let mut fu = FrameUnits::with_options(
            &rtl.cfg,
            render,
            &setup,
            &look.tf,
            &look.phong,
            &look.options(),
        )?;
        if rtl.depth_test {
            let g = geometry::rasterize(&params, &look.geometry, &rtl.compos);
            fu.set_geometry(&params, g)?;
        }
        Ok((params, fu))
    }

    /// The model's frame of a scene, exactly what `cube5 render` computes for it
    /// (`cube5_model::scene_render::FrameJob`): the RTL is compared with that image.
    pub fn from_job(job: &FrameJob, run: FrameRun, view: &str) -> Self {
        let u = job.units.clone();
        Expected {
            seen: Rc::new(job.seen.clone()),
            view: view.to_string(),
            dir: job.dir.to_array(),
            params: job.setup.params,
            units: Units {
                trilin: u.trilin,
                gradient: u.gradient,
                shader: u.shader,
                compos: u.compos,
                render: u.mode,
                tf2d: u.tf2d,
            },
            w: run.base.width,
            h: run.base.height,
            want: run.base.coxels,
            geometry: u.geometry.clone(),
        }
    }
}

// -------------------------------------------------------------------------------------------------
// Driving frames
// -------------------------------------------------------------------------------------------------

/// What one frame took.
#[derive(Debug, Clone, Copy)]
pub struct FrameStats {
    /// Cycles of the drive call: command offered to last pixel taken.
    pub cycles: u64,
    /// The frame's own sweep counter (set-up and sweep, command accepted to read-out start).
    pub sweep: u32,
    /// Cycles at which the first and the last pixel left.
    pub first_out: u64,
    pub last_out: u64,
    /// The model's count of the sweep's memory accesses (equal to the RTL's, or the frame fails).
    pub accesses: SweepAccesses,
    /// Empty slices the sweep skipped (before, after).
    pub skip: (usize, usize),
}

/// A loaded DUT: one variant with one volume in its memory.
pub struct FrameBench {
    pub rtl: FrameRtl,
    pub dut: RtlStream<FrameConfig>,
    pub dims: [usize; 3],
    pub lut: BlockLut,
    /// The tables loaded last (render mode, 2-D table, opacity ratio, compositing registers):
    /// reloaded on change.
    pub loaded: Option<(Render, bool, u64, ComposRegs)>,
    /// Skip the empty slices before and after each sweep (`cube5_frame::empty_slices`) when a zero
    /// sample composites as the identity.
    pub skip_empty: bool,
    /// The slices the last loaded frame skips (before, after).
    pub skip: (usize, usize),
}

impl FrameBench {
    pub fn new(
        rtl: FrameRtl,
        vol: &Volume,
        lut: &BlockLut,
        dut_seed: u32,
    ) -> Result<Self, TbError> {
        let mut dut = RtlStream::new(rtl.variant, rtl.cfg, dut_seed)?;
        for (a, d) in rtl.volume_writes(vol, lut)? {
            dut.write_config(a, &d)?;
        }
        let mut bench = Self {
            rtl,
            dut,
            dims: vol.dims,
            lut: lut.clone(),
            loaded: None,
            skip_empty: false,
            skip: (0, 0),
        };
        // After reset the compositing buffer clears its valid bits (4 MaxDim^2 / P cycles) before
        // it takes a command; a command refused for a reserved render mode waits that out, so the
        // frames measured after it are steady-state frames. `load` rewrites the mode register.
        bench.write(&[rtl.reg(REG_MODE, RENDER_REFUSED)])?;
        bench.refused(OP_RENDER)?;
        Ok(bench)
    }

    pub fn write(&mut self, writes: &[(u32, Vec<u32>)]) -> Result<(), TbError> {
        for (a, d) in writes {
            self.dut.write_config(*a, d)?;
        }
        Ok(())
    }

    /// Loads a new block LUT (same pointers: only the empty and masked flags change).
    pub fn set_lut(&mut self, lut: &BlockLut) -> Result<(), TbError> {
        let writes = self.rtl.block_writes(self.dims, lut)?;
        self.write(&writes)?;
        self.lut = lut.clone();
        Ok(())
    }

    /// Loads the tables and registers of a frame.
    pub fn load(&mut self, e: &Expected) -> Result<(), TbError> {
        let u = &e.units;
        let key = (
            u.render,
            u.tf2d,
            u.compos.lut().ratio().unwrap_or(0.0).to_bits(),
            u.compos.regs(),
        );
        if self.loaded != Some(key) {
            let w = u.config_writes(&self.rtl);
            self.write(&w)?;
            self.loaded = Some(key);
        }
        // Only when a zero sample leaves every coxel unchanged may empty slices be left out
        // (docs/numerics/frame.md, "Skipping empty slices").
        let zero_is_identity =
            cube5_frame::zero_sample_is_identity(u.render, u.tf2d, &u.shader, &u.compos);
        self.skip = if self.skip_empty && zero_is_identity {
            cube5_frame::empty_slices(&e.params, &self.lut)
        } else {
            (0, 0)
        };
        let w = self
            .rtl
            .frame_writes(&e.params, u.render, u.tf2d, self.skip);
        self.write(&w)?;
        // The depth test's table, every frame (it is the view's base plane).
        if self.rtl.depth_test {
            let none;
            let g = match &e.geometry {
                Some(g) => g.as_ref(),
                None => {
                    none = GeometryImage::none(e.w, e.h, &self.rtl.compos);
                    &none
                }
            };
            let w = self.rtl.geometry_writes(g);
            self.write(&w)?;
        }
        Ok(())
    }

    /// Renders one frame on the RTL and compares every pixel and channel with the model's image.
    pub fn check(
        &mut self,
        e: &Expected,
        traffic: &Traffic,
        seed: u64,
    ) -> Result<FrameStats, TbError> {
        self.load(e)?;
        self.render_and_compare(e, traffic, seed)
    }

    /// The render command alone (frame registers already written), then the comparison.
    pub fn render_and_compare(
        &mut self,
        e: &Expected,
        traffic: &Traffic,
        seed: u64,
    ) -> Result<FrameStats, TbError> {
        let got = self.render(e, traffic)?;
        self.compare(e, &got, seed)
    }

    /// Drives the render command until the W H pixels of `e`'s base plane are out (or a cycle
    /// limit far beyond the frame's budget passes).
    pub fn render(&mut self, e: &Expected, traffic: &Traffic) -> Result<Rendered, TbError> {
        let n = items_for(e.w, e.h, self.rtl.out_lanes);
        let limit = 40 * (e.params.samples() as u64 + n) + 100_000;
        drive_pixels(
            &mut self.dut,
            &[OP_RENDER],
            e,
            self.rtl.out_lanes,
            traffic,
            limit,
        )
    }

    /// Compares a rendered frame with the model's: every pixel and channel, the error flag, and
    /// the memory beats read against the model's sweep of the skewed memory (which must find no
    /// module conflict). The first difference is reported with the ray's trail.
    pub fn compare(&self, e: &Expected, got: &Rendered, seed: u64) -> Result<FrameStats, TbError> {
        let rtl = self.rtl;
        let mut mem = rtl.memory(self.dims, &self.lut)?;
        let accesses = cube5_frame::sweep_memory(&e.params, self.skip, &mut mem)?;
        let ctx = || {
            format!(
                "{} view {} {:?}, {:?}, volume {:?}, {:?}, seed {seed}",
                rtl.variant, e.view, e.dir, e.units.render, self.dims, e.params
            )
        };
        let fail = |what: String| {
            Err(TbError::from(Mismatch {
                variant: rtl.variant.name.to_string(),
                seed,
                input: ctx(),
                what,
                ..Default::default()
            }))
        };
        if accesses.conflicts != 0 {
            return fail(format!(
                "the model's sweep has {} beams with a module conflict",
                accesses.conflicts
            ));
        }
        if got.protocol_errors > 0 {
            return Err(TbError::Protocol {
                variant: rtl.variant.name.to_string(),
                seed,
                cycle: got.cycles,
                what: format!("a stalled output changed ({})", ctx()),
            });
        }
        let reads = accesses.beams_read as u32;
        for (i, px) in got.pixels.iter().enumerate() {
            let (r, q) = (i % e.w, i / e.w);
            if px.error {
                return fail(format!("pixel ({r}, {q}) carries the error flag"));
            }
            if px.reads != reads {
                return fail(format!(
                    "pixel ({r}, {q}) reports {} memory beats read, the model {reads}",
                    px.reads
                ));
            }
            if i < e.want.len() && px.coxel != e.want[i] {
                return Err(TbError::from(mismatch_report(
                    rtl.variant,
                    &ctx(),
                    e,
                    PixelAt {
                        r,
                        q,
                        item: i,
                        cycle: got.taken_at[i],
                    },
                    &px.coxel,
                    seed,
                )));
            }
        }
        got.all_out(e, rtl.variant, seed, &ctx())?;
        let n = e.w * e.h;
        Ok(FrameStats {
            cycles: got.cycles,
            sweep: got.pixels[0].cycles,
            skip: self.skip,
            first_out: got.taken_at[0],
            last_out: got.taken_at[n - 1],
            accesses,
        })
    }
}

/// Output items of a `w`-pixel-wide image, `lanes` pixels per item (a row's last item keeps only
/// the pixels up to its end): one `FrameOut` per pixel, each with the cycle its item was taken.
pub fn pixels_of(items: &[Taken<FrameOut>], w: usize, lanes: usize) -> (Vec<FrameOut>, Vec<u64>) {
    let (mut pixels, mut taken_at) = (Vec::new(), Vec::new());
    let per_row = w.div_ceil(lanes.max(1)).max(1);
    for (n, t) in items.iter().enumerate() {
        let keep = if t.value.error {
            1
        } else {
            lanes.min(w - (n % per_row) * lanes)
        };
        for c in std::iter::once(t.value.coxel)
            .chain(t.value.rest.iter().copied())
            .take(keep)
        {
            pixels.push(FrameOut {
                coxel: c,
                rest: Vec::new(),
                ..t.value.clone()
            });
            taken_at.push(t.cycle);
        }
    }
    (pixels, taken_at)
}

/// Output items of a `w x h` image with `lanes` pixels per item.
pub fn items_for(w: usize, h: usize, lanes: usize) -> u64 {
    (w.div_ceil(lanes.max(1)) * h) as u64
}

/// Drives `items` on `dut` until the W H pixels of `e`'s base plane are out in items of `lanes`
/// pixels (or `limit` cycles pass): the frame of the command stream (`FrameBench`) or of the
/// section stream (`StreamBench`).
pub(crate) fn drive_pixels<C: StreamCodec<Out = FrameOut>>(
    dut: &mut RtlStream<C>,
    items: &[C::In],
    e: &Expected,
    lanes: usize,
    traffic: &Traffic,
    limit: u64,
) -> Result<Rendered, TbError> {
    let start = dut.cycle();
    let driven = dut.drive(items, traffic, items_for(e.w, e.h, lanes), limit)?;
    let (pixels, taken_at) = pixels_of(&driven.outputs, e.w, lanes);
    Ok(Rendered {
        pixels,
        taken_at,
        cycles: dut.cycle() - start,
        protocol_errors: driven.stats.protocol_errors,
        limit,
    })
}

/// The RTL's output of one render command.
#[derive(Debug, Clone)]
pub struct Rendered {
    pub pixels: Vec<FrameOut>,
    /// The cycle each pixel was taken.
    pub taken_at: Vec<u64>,
    /// Cycles from the command offered to the last pixel taken.
    pub cycles: u64,
    pub protocol_errors: u64,
    pub limit: u64,
}

impl Rendered {
    /// All W H pixels of `e` came out, else a `Deadlock` (`ctx`: the frame, for the report).
    pub fn all_out(
        &self,
        e: &Expected,
        variant: &Variant,
        seed: u64,
        ctx: &str,
    ) -> Result<(), TbError> {
        let n = e.w * e.h;
        if self.pixels.len() == n {
            return Ok(());
        }
        Err(TbError::Deadlock {
            variant: variant.name.to_string(),
            seed,
            cycle: self.cycles,
            what: format!(
                "{} of {n} pixels within {} cycles (deadlock or lost pixel; {ctx})",
                self.pixels.len(),
                self.limit
            ),
        })
    }
}

impl FrameBench {
    /// Drives one command that must be refused: exactly one output item, with the error flag, and
    /// nothing after it. (After a reset the command waits for the compositing buffer's clear
    /// pass, 4 MaxDim^2 / P cycles.)
    pub fn refused(&mut self, op: u32) -> Result<FrameOut, TbError> {
        let d = self.dut.drive(&[op], &Traffic::full_speed(), 1, 100_000)?;
        let more = self.dut.drive(&[], &Traffic::full_speed(), 1, 200)?;
        match (d.outputs.as_slice(), more.outputs.is_empty()) {
            ([one], true) => Ok(one.value.clone()),
            _ => Err(TbError::from(Mismatch {
                variant: self.rtl.variant.name.to_string(),
                input: format!("command {op}"),
                what: format!(
                    "answered {} item(s), then {} more; a refused command has one",
                    d.outputs.len(),
                    more.outputs.len()
                ),
                ..Default::default()
            })),
        }
    }
}

/// Where the first differing pixel is.
struct PixelAt {
    r: usize,
    q: usize,
    item: usize,
    cycle: u64,
}

/// The first differing pixel: where, which channel, both values, and the model's trail of the ray.
fn mismatch_report(
    variant: &Variant,
    ctx: &str,
    e: &Expected,
    at: PixelAt,
    got: &Coxel,
    seed: u64,
) -> Mismatch {
    let exp = &e.want[at.item];
    let names = ["R", "G", "B", "A"];
    let mut what: Vec<String> = names
        .iter()
        .enumerate()
        .filter(|&(ch, _)| got.rgba[ch] != exp.rgba[ch])
        .map(|(_, name)| format!("channel {name}"))
        .collect();
    if got.z != exp.z || got.geo != exp.geo {
        what.push("Z / geometry".into());
    }
    if got.terminated != exp.terminated {
        what.push("terminated".into());
    }
    Mismatch {
        variant: variant.name.to_string(),
        seed,
        item: at.item as u64,
        cycle: at.cycle,
        input: format!(
            "{ctx}; pixel (r, q) = ({}, {}) of the {} x {} base plane",
            at.r, at.q, e.w, e.h
        ),
        rtl: format!("{got:?}"),
        model: format!("{exp:?}"),
        what: format!("{} differ", what.join(", ")),
        trail: format!(
            "the model's samples of this ray (slice, anchor, sample, neighbourhood C x- x+ y- y+ B A, shaded, coxel after):{}",
            ray_trail(&e.params, &e.seen, &e.units, at.r, at.q)
        ),
        ..Default::default()
    }
}
