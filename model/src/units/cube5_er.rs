//! `cube5_er`, the ER-Perspective sweep top: its configuration (the RTL's parameters), the item
//! codec, and the host's items of one frame (docs/numerics/er_perspective.md, "The RTL:
//! cube5_er"). There is no separate unit model: the RTL's base plane is held to
//! [`ErJob::render`](crate::er_perspective::ErJob::render), the contract's model.

use crate::bits::{BitReader, BitWriter};
use crate::er_perspective::{ErJob, ErMerge, Extent};
use crate::error::{ModelError, Result};
use crate::regs::cube5_er::{
    CNT_W, OP_CLEAR, OP_COMPOS, OP_EMIT, OP_MERGE, OP_SHADER, OP_SLICE, OP_VOXEL, OP_WRITE, PAY_W,
    POS_W, RAY_W, REG_ADDR_W, REG_DIMS, REG_DIMS_NI, REG_DIMS_NJ, REG_DIMS_NK, REG_EI, REG_EJ,
    REG_MODE, REG_MODE_CENTRE, REG_MODE_MIP, SLICE_W, SPACING_W,
};
use crate::unit::{StreamCodec, UnitConfig};
use crate::units::cube5_compos::{self, ComposConfig, Coxel};
use crate::units::cube5_frame::UNIT_WIDTH_PARAMS;
use crate::units::cube5_frame::{FrameConfig, FrameMode};
use crate::units::cube5_gradient::GradientConfig;
use crate::units::cube5_shader::ShaderConfig;
use crate::units::cube5_trilin::TrilinConfig;

/// One configuration of the `cube5_er` RTL.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ErConfig {
    /// log2 of the largest volume edge (`MaxDim`).
    pub max_dim_log2: u32,
    /// Largest region extent edge in rays (`MaxRays`).
    pub max_rays: u32,
    pub trilin: TrilinConfig,
    pub gradient: GradientConfig,
    pub shader: ShaderConfig,
    pub compos: ComposConfig,
}

impl ErConfig {
    /// The RTL's defaults: 64^3 volumes, extents up to 132 rays, the frame's default widths.
    pub const DEFAULT: Self = Self {
        max_dim_log2: 6,
        max_rays: 132,
        trilin: TrilinConfig::DEFAULT,
        gradient: GradientConfig::DEFAULT,
        shader: ShaderConfig::DEFAULT,
        compos: ComposConfig::DEFAULT,
    };

    pub fn max_dim(&self) -> usize {
        1 << self.max_dim_log2
    }

    /// The frame configuration with these unit widths (what `ErJob::new` takes).
    pub fn frame_config(&self) -> FrameConfig {
        FrameConfig {
            p: 1,
            trilin: self.trilin,
            gradient: self.gradient,
            shader: self.shader,
            compos: self.compos,
            ..FrameConfig::DEFAULT
        }
    }
}

impl UnitConfig for ErConfig {
    const TOP: &'static str = "cube5_er";

    fn from_params(params: &[(&str, i64)]) -> Result<Self> {
        let d = Self::DEFAULT;
        let mut max_dim = 1u32 << d.max_dim_log2;
        let mut max_rays = d.max_rays;
        // The units' widths are the frame's parameters of the same names: mapped onto the units
        // (and derived between them) once, by `FrameConfig`.
        let mut widths = Vec::new();
        for &(name, value) in params {
            if UNIT_WIDTH_PARAMS.contains(&name) {
                widths.push((name, value));
            } else {
                crate::unit::set_params(
                    Self::TOP,
                    &[(name, value)],
                    &mut [("MaxDim", &mut max_dim), ("MaxRays", &mut max_rays)],
                )?;
            }
        }
        let f = FrameConfig::from_params(&widths)?;
        let c = f.compos;
        if !max_dim.is_power_of_two() || !(4..=512).contains(&max_dim) {
            return Err(ModelError::Config(format!(
                "cube5_er: MaxDim = {max_dim} must be a power of two in 4..=512"
            )));
        }
        if !(4..1 << (RAY_W - 1)).contains(&max_rays) {
            return Err(ModelError::Config(format!(
                "cube5_er: MaxRays = {max_rays} must be in 4..2^{}",
                RAY_W - 1
            )));
        }
        if c.z_w > 16 || (1u64 << c.z_w) < u64::from(max_dim) {
            return Err(ModelError::Config(format!(
                "cube5_er: ZW = {} must hold every slice number of MaxDim = {max_dim}",
                c.z_w
            )));
        }
        Ok(Self {
            max_dim_log2: max_dim.trailing_zeros(),
            max_rays,
            trilin: f.trilin,
            gradient: f.gradient,
            shader: f.shader,
            compos: c,
        })
    }

    fn to_params(&self) -> Vec<(&'static str, i64)> {
        let mut out = vec![
            ("MaxDim", 1i64 << self.max_dim_log2),
            ("MaxRays", i64::from(self.max_rays)),
        ];
        out.extend(
            self.frame_config()
                .to_params()
                .into_iter()
                .filter(|(n, _)| UNIT_WIDTH_PARAMS.contains(n)),
        );
        out
    }
}

/// One input item: `op`, `addr` and `payload` (`PayW` bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ErIn {
    pub op: u32,
    pub addr: u32,
    pub payload: u128,
}

/// One output item: a coxel of an `Emit` and the cycles from the frame's `Clear` to the `Emit`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ErOut {
    pub coxel: Coxel,
    pub cycles: u32,
}

impl StreamCodec for ErConfig {
    type In = ErIn;
    type Out = ErOut;

    fn in_width(&self) -> u32 {
        PAY_W + REG_ADDR_W + 3
    }

    fn out_width(&self) -> u32 {
        self.compos.coxel_w() + CNT_W
    }

    fn pack_in(&self, item: &ErIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        w.put(item.payload as u64, 64);
        w.put((item.payload >> 64) as u64, PAY_W - 64);
        w.put(u64::from(item.addr), REG_ADDR_W);
        w.put(u64::from(item.op), 3);
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> ErOut {
        let mut r = BitReader::new(words);
        ErOut {
            coxel: cube5_compos::get_coxel(&mut r, &self.compos),
            cycles: r.get(CNT_W) as u32,
        }
    }
}

fn item(op: u32, addr: u32, payload: u128) -> ErIn {
    ErIn { op, addr, payload }
}

/// Fields packed LSB first into a payload: `(value, width)`, values two's complement.
fn fields(f: &[(i64, u32)]) -> u128 {
    let mut p = 0u128;
    let mut at = 0;
    for &(v, w) in f {
        p |= (v as u128 & ((1u128 << w) - 1)) << at;
        at += w;
    }
    p
}

/// The payload of a `Clear` or `Merge`: the extent's `M0`, `N0`, `W`, `H`.
fn extent_payload(e: &Extent) -> u128 {
    let w = RAY_W;
    fields(&[
        (e.m0, w),
        (e.n0, w),
        (e.width() as i64, w),
        (e.height() as i64, w),
    ])
}

/// A register write.
pub fn reg(r: u32, value: u64) -> ErIn {
    item(OP_WRITE, r, u128::from(value))
}

/// The `Dims` register of `(ni, nj, nk)`: written first, it restarts the voxel load position.
pub fn dims_item(ni: usize, nj: usize, nk: usize) -> ErIn {
    let mut v = 0u64;
    v = REG_DIMS_NI.set(v, ni as u64);
    v = REG_DIMS_NJ.set(v, nj as u64);
    v = REG_DIMS_NK.set(v, nk as u64);
    reg(REG_DIMS, v)
}

/// Refuses a job this configuration cannot run, naming the limit.
pub fn check_job(cfg: &ErConfig, job: &ErJob) -> Result<()> {
    let p = job.setup.params();
    let max = cfg.max_dim();
    if [p.ni, p.nj, p.nk].iter().any(|&d| d > max) {
        return Err(ModelError::Config(format!(
            "cube5_er: volume {}x{}x{} (frame axes) exceeds MaxDim = {max}",
            p.ni, p.nj, p.nk
        )));
    }
    if job.cfg.trilin != cfg.trilin || job.cfg.shader != cfg.shader || job.cfg.compos != cfg.compos
    {
        return Err(ModelError::Config(
            "cube5_er: the job's unit widths are not this configuration's".into(),
        ));
    }
    let layout = job.setup.layout();
    let lim = 1i64 << (RAY_W - 1);
    for e in &layout.extent {
        if e.width() > cfg.max_rays as usize || e.height() > cfg.max_rays as usize {
            return Err(ModelError::Config(format!(
                "cube5_er: a region of {}x{} rays exceeds MaxRays = {} (fewer rays per voxel or a larger MaxRays)",
                e.width(),
                e.height(),
                cfg.max_rays
            )));
        }
        if [e.m0, e.m1 + 1, e.n0, e.n1 + 1]
            .iter()
            .any(|&v| v < -lim || v >= lim)
        {
            return Err(ModelError::Config(format!(
                "cube5_er: ray indices {e:?} do not fit {RAY_W} bits"
            )));
        }
    }
    let pos = 1i64 << (POS_W - 1);
    let s = &job.setup;
    for (t, rays) in layout.rays.iter().enumerate() {
        let h = s.slice_spacing(t).1;
        for (e0, m) in [
            (s.ei, rays.m0),
            (s.ei, rays.m1),
            (s.ej, rays.n0),
            (s.ej, rays.n1),
        ] {
            let x = e0 + m * h;
            if !(-pos..pos).contains(&x) || !(-pos..pos).contains(&e0) {
                return Err(ModelError::Config(format!(
                    "cube5_er: a ray position does not fit S({}.16)",
                    POS_W - 17
                )));
            }
        }
    }
    Ok(())
}

/// The volume's items: `Dims`, then every voxel in frame axes, slice `t` in processing order
/// (`s = 0` nearest the eye), `i` fastest.
pub fn volume_items(cfg: &ErConfig, job: &ErJob) -> Result<Vec<ErIn>> {
    check_job(cfg, job)?;
    let p = job.setup.params();
    let mut out = Vec::with_capacity(p.ni * p.nj * p.nk + 1);
    out.push(dims_item(p.ni, p.nj, p.nk));
    for t in 0..p.nk {
        let k = p.slice(t).k;
        for j in 0..p.nj {
            for i in 0..p.ni {
                out.push(item(OP_VOXEL, 0, u128::from(p.voxel(&job.vol, i, j, k))));
            }
        }
    }
    Ok(out)
}

/// The items of one frame after its volume: registers, the shader's and the compositing unit's
/// tables, `Clear` with the farthest region's extent, the sweep back to front (a `Merge` at each
/// region boundary, a `Slice` per slice), `Emit`.
pub fn frame_items(cfg: &ErConfig, job: &ErJob) -> Result<Vec<ErIn>> {
    check_job(cfg, job)?;
    let s = &job.setup;
    let p = s.params();
    let layout = s.layout();
    let mut out = vec![
        dims_item(p.ni, p.nj, p.nk),
        reg(REG_EI, s.ei as u64 & ((1 << POS_W) - 1)),
        reg(REG_EJ, s.ej as u64 & ((1 << POS_W) - 1)),
        reg(
            REG_MODE,
            REG_MODE_CENTRE.set(
                REG_MODE_MIP.set(0, u64::from(job.units.mode == FrameMode::Mip)),
                u64::from(s.scheme.merge == ErMerge::Centre),
            ),
        ),
    ];
    let word = |d: &[u32]| d.iter().rev().fold(0u128, |a, &w| a << 32 | u128::from(w));
    for (a, d) in job.units.shader.tables().config_writes(&cfg.shader) {
        out.push(item(OP_SHADER, a, word(&d)));
    }
    for (a, d) in job.units.compos.config_writes() {
        out.push(item(OP_COMPOS, a, word(&d)));
    }
    let nk = p.nk;
    let mut r = layout.region[nk - 1] as usize;
    out.push(item(OP_CLEAR, 0, extent_payload(&layout.extent[r])));
    for t in (0..nk).rev() {
        while (layout.region[t] as usize) < r {
            r -= 1;
            out.push(item(OP_MERGE, 0, extent_payload(&layout.extent[r])));
        }
        let rays = layout.rays[t];
        let h = s.slice_spacing(t).1;
        let w = RAY_W;
        out.push(item(
            OP_SLICE,
            0,
            fields(&[
                (rays.m0, w),
                (rays.m1, w),
                (rays.n0, w),
                (rays.n1, w),
                (h, SPACING_W),
                (t as i64, SLICE_W),
            ]),
        ));
    }
    out.push(item(OP_EMIT, 0, 0));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::er_perspective::{ErMerge, ErScheme};
    use crate::phantom::head_phantom;
    use crate::render::{Projection, RenderParams};
    use crate::transfer::TransferFunction;

    fn job(n: usize, fov: f64) -> ErJob {
        let params = RenderParams {
            width: 16,
            height: 16,
            direction: Some([0.2, -0.1, 1.0]),
            projection: Projection::Perspective,
            fov,
            ..RenderParams::default()
        };
        let scheme = ErScheme {
            rays_per_voxel: 1,
            merge: ErMerge::Bartlett,
        };
        let vol = head_phantom(n, 12).unwrap();
        let tf = TransferFunction::head_default();
        ErJob::new(
            &vol,
            &tf,
            &params,
            &ErConfig::DEFAULT.frame_config(),
            scheme,
        )
        .unwrap()
    }

    #[test]
    fn parameters_round_trip_and_bad_ones_are_refused() {
        let cfg = ErConfig::DEFAULT;
        assert_eq!(ErConfig::from_params(&cfg.to_params()).unwrap(), cfg);
        for bad in [
            ("MaxDim", 48),
            ("MaxRays", 2),
            ("MaxRays", 1 << 15),
            ("Nope", 1),
        ] {
            assert!(ErConfig::from_params(&[bad]).is_err(), "{bad:?}");
        }
        // ZW must number every slice.
        assert!(ErConfig::from_params(&[("MaxDim", 512), ("ZW", 8)]).is_err());
    }

    /// The sweep's items: the frame's registers and tables, one `Clear` with the farthest
    /// region's extent, a `Merge` per region boundary just before the first slice of the nearer
    /// region, the slices from `nk - 1` down to 0, one `Emit`; fields where the contract puts them.
    #[test]
    fn a_frame_is_clear_slices_and_merges_back_to_front_then_emit() {
        let j = job(16, 90.0);
        let cfg = ErConfig::DEFAULT;
        let items = frame_items(&cfg, &j).unwrap();
        let layout = j.setup.layout();
        let ops: Vec<u32> = items.iter().map(|i| i.op).collect();
        let clear = ops.iter().position(|&o| o == OP_CLEAR).unwrap();
        assert!(ops[..clear]
            .iter()
            .all(|&o| [OP_WRITE, OP_SHADER, OP_COMPOS].contains(&o)));
        assert_eq!(ops.last(), Some(&OP_EMIT));
        let sweep = &items[clear + 1..items.len() - 1];
        let merges = sweep.iter().filter(|i| i.op == OP_MERGE).count();
        assert_eq!(merges, layout.regions() - 1);
        let slices: Vec<u128> = sweep
            .iter()
            .filter(|i| i.op == OP_SLICE)
            .map(|i| i.payload >> (4 * RAY_W + SPACING_W))
            .collect();
        let nk = j.setup.params().nk;
        assert_eq!(slices, (0..nk as u128).rev().collect::<Vec<_>>());
        let first = &items[clear];
        let e = layout.extent[layout.regions() - 1];
        assert_eq!(first.payload & 0xffff, (e.m0 as u128) & 0xffff);
        assert_eq!((first.payload >> 32) & 0xffff, e.width() as u128);
        // The volume: Dims, then ni nj nk voxels.
        let p = j.setup.params();
        let vol = volume_items(&cfg, &j).unwrap();
        assert_eq!(vol.len(), 1 + p.ni * p.nj * p.nk);
        assert_eq!(REG_DIMS_NK.get(vol[0].payload as u64), p.nk as u64);
    }

    #[test]
    fn a_volume_or_region_beyond_the_configuration_is_refused() {
        let small = ErConfig {
            max_dim_log2: 3,
            ..ErConfig::DEFAULT
        };
        let err = check_job(&small, &job(16, 40.0)).unwrap_err().to_string();
        assert!(err.contains("MaxDim"), "{err}");
        let narrow = ErConfig {
            max_rays: 8,
            ..ErConfig::DEFAULT
        };
        let err = check_job(&narrow, &job(16, 40.0)).unwrap_err().to_string();
        assert!(err.contains("MaxRays"), "{err}");
    }
}
