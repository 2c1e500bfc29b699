//! The GI-Cube block processor's sample datapath (`gicube_sample`; parts I, J, K and L of
//! docs/gicube-rtl.md, patent [353], [379]-[380], [383]), written from
//! `docs/numerics/gicube_sample.md`: the tri-linear sample of the eight corner voxels
//! (`cube5_trilin`), its classification (`cube5_shader`, unlit), the irradiance of a lit rendering
//! ray (a second `cube5_trilin` and the multiply), and one front-to-back compositing step onto the
//! packet's colour and opacity (`cube5_compos`, with its opacity LUT and termination threshold).
//! A pure function of the item.
//!
//! `gicube_processor::Processor` takes every sample through [`Sampler::sample`], so this is the
//! one description of the sample; no RTL yet (step 4 of the build order, docs/gicube-rtl.md).

use crate::error::Result;
use crate::units::cube5_compos::{
    rnd, Compos, ComposConfig, ComposMode, ComposRegs, Coxel, OpacityLut, Sample,
};
use crate::units::cube5_shader::{
    ClassLut, ReflectanceMap, Shader, ShaderConfig, ShaderIn, ShaderMode, ShaderTables, Texel,
};
use crate::units::cube5_trilin::{Trilin, TrilinConfig, TrilinIn, TrilinMode};
use crate::units::gicube_packet_loop::POS_FRAC_W;

/// Largest value of a `U(0.12)` packet channel.
pub const CHAN_MAX: u32 = 4095;
/// Fraction bits of the tri-linear sample (`cube5_trilin` `FracW`).
pub const SAMPLE_FRAC_W: u32 = 4;
/// Fraction bits of the irradiance, `U(2.14)`.
pub const IRR_FRAC_W: u32 = 14;

/// One configuration of the sample datapath: the processor's voxel width, sample distance and
/// termination threshold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleConfig {
    /// Bits per voxel, 4..=16.
    pub voxel_w: u32,
    /// The sample distance `dr`, `U(4.8)` voxels, 16..=1024 (the opacity LUT's `d/k`).
    pub step: u32,
    /// Early ray termination threshold on the opacity, `U(0.12)` scale, 1..=4096; `None`: off.
    pub et_threshold: Option<u32>,
}

/// One sample: the cell's eight voxels and weights, the packet's colour and opacity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleIn {
    /// Corner `c` is voxel `floor(start) + (c & 1, c >> 1 & 1, c >> 2 & 1)`; 0 outside the volume.
    pub voxels: [u32; 8],
    /// The 8 fraction bits of `start` per axis, `U(0.8)`.
    pub weights: [u32; 3],
    /// The irradiance at the eight corners (`U(2.14)`), for a lit rendering ray; `None`: unlit.
    pub irr: Option<[u32; 8]>,
    /// The packet's `red, green, blue`, `U(0.12)`.
    pub color: [u16; 3],
    /// The packet's `opacity`, `U(0.12)`.
    pub opacity: u16,
    /// A lighting ray: its colour is its energy and is not composited (`rgb = 0`, colour kept).
    pub lighting: bool,
}

/// What the sample did to the packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleOut {
    /// The new `red, green, blue` (unchanged for a lighting ray).
    pub color: [u16; 3],
    /// The new opacity.
    pub opacity: u16,
    /// The compositor's termination flag (`opacity' >= et_threshold` when termination is on).
    pub terminated: bool,
}

/// The sample datapath's model.
#[derive(Debug, Clone)]
pub struct Sampler {
    cfg: SampleConfig,
    trilin: Trilin,
    irr_trilin: Trilin,
    shader: Shader,
    compos: Compos,
}

fn unlit() -> ShaderMode {
    ShaderMode {
        tf2d: false,
        unlit: true,
    }
}

/// The classification the processor uses: `cube5_shader` on the `U(VoxelW.4)` sample, 1-D,
/// `min(12, VoxelW + 4)` index bits, 8-bit colour, 12-bit alpha.
pub fn shader_config(voxel_w: u32) -> ShaderConfig {
    ShaderConfig {
        voxel_w,
        frac_w: SAMPLE_FRAC_W,
        class_idx_w: 12.min(voxel_w + SAMPLE_FRAC_W),
        mag_shift: 10.min(voxel_w + 1 + SAMPLE_FRAC_W),
        ..ShaderConfig::DEFAULT
    }
}

/// The compositing the processor uses: `cube5_compos` with the packet's widths, coxel `U(1.12)`,
/// corrected alpha `U(1.12)`, 8-bit sample colour, no depth.
pub fn compos_config() -> ComposConfig {
    ComposConfig {
        color_w: 8,
        alpha_w: 12,
        extra_w: 0,
        acc_w: 12,
        z_w: 1,
    }
}

impl Sampler {
    /// The datapath for `cfg` with the classification table `class` (built for
    /// [`shader_config`]`(cfg.voxel_w)`).
    pub fn new(cfg: SampleConfig, class: ClassLut) -> Result<Self> {
        let trilin = Trilin::new(TrilinConfig::new(cfg.voxel_w, POS_FRAC_W, SAMPLE_FRAC_W)?)?;
        let scfg = shader_config(cfg.voxel_w);
        let rmap = ReflectanceMap::from_fn(&scfg, |_, _, _| Texel::default(), Texel::default())?;
        let shader = Shader::new(scfg, ShaderTables { class, rmap })?;
        let ccfg = compos_config();
        let lut = OpacityLut::new(f64::from(cfg.step) / f64::from(1u32 << POS_FRAC_W), &ccfg)?;
        let regs = match cfg.et_threshold {
            Some(t) => ComposRegs {
                et_threshold: u64::from(t),
                ..ComposRegs::defaults(&ccfg)
            },
            None => ComposRegs::without_termination(&ccfg),
        };
        Ok(Self {
            cfg,
            trilin,
            irr_trilin: Trilin::new(TrilinConfig::new(16, POS_FRAC_W, 0)?)?,
            shader,
            compos: Compos::new(ccfg, lut, regs)?,
        })
    }

    pub fn config(&self) -> SampleConfig {
        self.cfg
    }

    /// The classification unit (its table and index, for the host's empty-block flags).
    pub fn shader(&self) -> &Shader {
        &self.shader
    }

    /// The classification index of a voxel value `v` (the sample `v << 4` of a cell whose corners
    /// are all `v`).
    pub fn class_index_of_voxel(&self, v: u32) -> usize {
        self.shader.class_index(&ShaderIn {
            sample: v << SAMPLE_FRAC_W,
            grad: [0; 3],
            mag: 0,
            mode: unlit(),
        })
    }

    /// One sample (contract rules 1-5).
    pub fn sample(&self, it: &SampleIn) -> SampleOut {
        let s = self.trilin.sample(&TrilinIn {
            voxels: it.voxels,
            weights: it.weights,
            mode: TrilinMode::Lerp,
        });
        let e = self.shader.classify(&ShaderIn {
            sample: s,
            grad: [0; 3],
            mag: 0,
            mode: unlit(),
        });
        let rgb = if it.lighting {
            [0; 3]
        } else if let Some(corners) = it.irr {
            let irr_s = u64::from(self.irr_trilin.sample(&TrilinIn {
                voxels: corners,
                weights: it.weights,
                mode: TrilinMode::Lerp,
            }));
            [e.r, e.g, e.b].map(|c| (rnd(u64::from(c) * irr_s, IRR_FRAC_W) as u32).min(255))
        } else {
            [e.r, e.g, e.b]
        };
        let coxel = Coxel {
            rgba: [
                u64::from(it.color[0]),
                u64::from(it.color[1]),
                u64::from(it.color[2]),
                u64::from(it.opacity),
            ],
            z: 1,
            geo: [0; 3],
            terminated: false,
        };
        let out = self.compos.step(
            &coxel,
            &Sample {
                rgb,
                alpha: e.a,
                depth: 0,
                mode: ComposMode::FrontToBack,
            },
        );
        let sat = |x: u64| x.min(u64::from(CHAN_MAX)) as u16;
        SampleOut {
            color: if it.lighting {
                it.color
            } else {
                [sat(out.rgba[0]), sat(out.rgba[1]), sat(out.rgba[2])]
            },
            opacity: sat(out.rgba[3]),
            terminated: out.terminated,
        }
    }
}

crate::item_by_item!(Sampler, SampleIn => SampleOut, |unit, it| unit.sample(it));

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::TransferFunction;

    fn sampler(et: Option<u32>) -> Sampler {
        let cfg = SampleConfig {
            voxel_w: 8,
            step: 256,
            et_threshold: et,
        };
        let tf = TransferFunction::head_default();
        let class = ClassLut::from_transfer(&shader_config(8), &tf).unwrap();
        Sampler::new(cfg, class).unwrap()
    }

    fn item(v: u32, opacity: u16) -> SampleIn {
        SampleIn {
            voxels: [v; 8],
            weights: [17, 200, 128],
            irr: None,
            color: [100, 200, 300],
            opacity,
            lighting: false,
        }
    }

    #[test]
    fn empty_voxels_leave_the_packet_unchanged() {
        let s = sampler(None);
        let it = item(0, 1000);
        let o = s.sample(&it);
        assert_eq!((o.color, o.opacity, o.terminated), (it.color, 1000, false));
    }

    #[test]
    fn opacity_grows_and_terminates_at_the_threshold() {
        let s = sampler(Some(CHAN_MAX + 1 - 16));
        let mut it = item(255, 0);
        let mut last = 0;
        for _ in 0..200 {
            let o = s.sample(&it);
            assert!(o.opacity >= last, "monotone");
            last = o.opacity;
            it.color = o.color;
            it.opacity = o.opacity;
            if o.terminated {
                assert!(u32::from(o.opacity) >= CHAN_MAX + 1 - 16);
                return;
            }
        }
        panic!("an opaque ramp never terminated");
    }

    #[test]
    fn a_lighting_ray_keeps_its_energy_and_gains_opacity() {
        let s = sampler(None);
        let mut it = item(200, 0);
        it.lighting = true;
        let o = s.sample(&it);
        assert_eq!(o.color, it.color);
        assert!(o.opacity > 0);
    }

    #[test]
    fn zero_irradiance_darkens_and_unit_irradiance_keeps_the_colour() {
        let s = sampler(None);
        let lit = |irr: u32| {
            let mut it = item(200, 0);
            it.color = [0; 3];
            it.irr = Some([irr; 8]);
            s.sample(&it)
        };
        let unlit = s.sample(&SampleIn {
            color: [0; 3],
            ..item(200, 0)
        });
        assert_eq!(lit(0).color, [0; 3]);
        assert_eq!(lit(1 << IRR_FRAC_W).color, unlit.color);
        assert_eq!(lit(0).opacity, unlit.opacity, "light changes no opacity");
    }
}
