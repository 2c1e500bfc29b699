//! The GI-Cube block processor's sample datapath (`gicube_sample`; parts I, J, K and L of
//! docs/gicube-rtl.md, patent [353], [379]-[380], [383]), written from
//! `docs/numerics/gicube_sample.md`: the tri-linear sample of the eight corner voxels
//! (`cube5_trilin`), its classification (`cube5_shader`, unlit), the irradiance of a lit rendering
//! ray (a second `cube5_trilin` and the multiply), and one front-to-back compositing step onto the
//! packet's colour and opacity (`cube5_compos`, with its opacity LUT and termination threshold).
//! A pure function of the item.
//!
//! `gicube_processor::Processor` takes every sample through [`Sampler::sample`], so this is the
//! one description of the sample. The RTL is `rtl/gicube/gicube_sample.sv` (step 4 of the build
//! order, docs/gicube-rtl.md): its parameters are [`SampleRtlConfig`] (the voxel width), its
//! stream packs as the contract's *The RTL* says ([`StreamCodec`] on [`SampleRtlConfig`]), and its
//! tables load through [`Sampler::config_writes`].

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::StreamCodec;
use crate::units::cube5_compos::{
    alpha_value, color_value, corrected_alpha, rnd, Compos, ComposConfig, ComposMode, ComposRegs,
    Coxel, OpacityLut, Sample,
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

    /// Rules 1 and 2: the tri-linear density sample's classification entry.
    fn classified(&self, it: &SampleIn) -> crate::units::cube5_shader::Rgba {
        let s = self.trilin.sample(&TrilinIn {
            voxels: it.voxels,
            weights: it.weights,
            mode: TrilinMode::Lerp,
        });
        self.shader.classify(&ShaderIn {
            sample: s,
            grad: [0; 3],
            mag: 0,
            mode: unlit(),
        })
    }

    /// One sample (contract rules 1-5).
    pub fn sample(&self, it: &SampleIn) -> SampleOut {
        TRACE.with(|t| {
            if let Some(tr) = t.borrow_mut().as_mut() {
                tr.record(self, it);
            }
        });
        let e = self.classified(it);
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

impl Sampler {
    /// The f64 reference of one sample with the same classification entry (the table is the
    /// host's, so its index is the fixed-point sample's): the irradiance tri-linear in reals,
    /// `rgb = min(1, e I)`, the opacity correction `1 - (1 - a)^(dr / 256)` and the front-to-back
    /// step `A' = A + (1 - A) a'`, `C' = C + (1 - A) a' rgb` in reals, the packet read as `raw /
    /// 4096`; termination compares the input opacity with the threshold (the compositor's rule).
    /// Returns red, green, blue, opacity on the packet's scale (`4096 = 1.0`), unsaturated.
    pub fn reference(&self, it: &SampleIn) -> [f64; 4] {
        let e = self.classified(it);
        let one = f64::from(CHAN_MAX + 1);
        let c_in = it.color.map(|c| f64::from(c) / one);
        let a_in = f64::from(it.opacity) / one;
        if self
            .cfg
            .et_threshold
            .is_some_and(|t| u32::from(it.opacity) >= t)
        {
            return [c_in[0], c_in[1], c_in[2], a_in].map(|v| v * one);
        }
        let w = it
            .weights
            .map(|x| f64::from(x) / f64::from(1u32 << POS_FRAC_W));
        let irr = it.irr.map(|corners| {
            (0..8).fold(0.0, |acc, c| {
                let k = (0..3).fold(1.0, |k, a| {
                    k * if (c >> a) & 1 == 1 { w[a] } else { 1.0 - w[a] }
                });
                acc + k * f64::from(corners[c]) / f64::from(1u32 << IRR_FRAC_W)
            })
        });
        let ccfg = compos_config();
        let rgb = [e.r, e.g, e.b].map(|c| {
            if it.lighting {
                0.0
            } else {
                (color_value(c, &ccfg) * irr.unwrap_or(1.0)).min(1.0)
            }
        });
        let a = corrected_alpha(
            alpha_value(e.a, &ccfg),
            f64::from(self.cfg.step) / f64::from(1u32 << POS_FRAC_W),
        );
        let t = (1.0 - a_in).max(0.0);
        let color = if it.lighting {
            c_in
        } else {
            std::array::from_fn(|i| c_in[i] + t * a * rgb[i])
        };
        [color[0], color[1], color[2], a_in + t * a].map(|v| v * one)
    }
}

thread_local! {
    static TRACE: std::cell::RefCell<Option<SampleTrace>> = const { std::cell::RefCell::new(None) };
}

/// The samples a model took inside [`trace_samples`], in order, with the datapath that took the
/// first of them (its tables, for [`Sampler::config_writes`]): the processor model's real sample
/// traffic, which a test replays on the RTL.
#[derive(Debug, Clone, Default)]
pub struct SampleTrace {
    /// The datapath of the first sample.
    pub sampler: Option<Sampler>,
    /// Every sample, in the order taken.
    pub items: Vec<SampleIn>,
    /// Samples taken by a datapath of another configuration than the first's.
    pub others: usize,
}

impl SampleTrace {
    fn record(&mut self, s: &Sampler, it: &SampleIn) {
        match &self.sampler {
            None => self.sampler = Some(s.clone()),
            Some(first) if first.cfg != s.cfg => {
                self.others += 1;
                return;
            }
            Some(_) => {}
        }
        self.items.push(*it);
    }
}

/// Runs `f` with every [`Sampler::sample`] on this thread recorded; returns its result and the
/// samples (the processor model runs on one thread).
pub fn trace_samples<R>(f: impl FnOnce() -> R) -> (R, SampleTrace) {
    TRACE.with(|t| *t.borrow_mut() = Some(SampleTrace::default()));
    let r = f();
    let trace = TRACE.with(|t| t.borrow_mut().take()).unwrap_or_default();
    (r, trace)
}

/// Bits of a classification entry on the configuration port: r, g, b (8 each), a (12).
pub const CFG_DATA_W: u32 = 36;
/// The configuration address's region bit: set for a `cube5_compos` word.
pub const CFG_REGION_COMPOS: u32 = 1 << 13;

impl Sampler {
    /// The writes that load this datapath's tables and registers into the RTL's configuration
    /// port (contract, *The RTL*): every classification entry at its index, then `cube5_compos`'s
    /// opacity table and registers at `CFG_REGION_COMPOS +` their word address.
    pub fn config_writes(&self) -> Vec<(u32, Vec<u32>)> {
        let scfg = self.shader.config();
        let mut writes: Vec<(u32, Vec<u32>)> = self
            .shader
            .tables()
            .class
            .entries()
            .iter()
            .enumerate()
            .map(|(idx, e)| {
                let mut w = BitWriter::new();
                for c in [e.r, e.g, e.b] {
                    w.put(u64::from(c), scfg.color_w);
                }
                w.put(u64::from(e.a), scfg.alpha_w);
                (idx as u32, w.finish(CFG_DATA_W))
            })
            .collect();
        writes.extend(
            self.compos
                .config_writes()
                .into_iter()
                .map(|(addr, data)| (CFG_REGION_COMPOS | addr, data)),
        );
        writes
    }
}

/// The RTL top's parameters: the voxel width alone (the sample distance and the termination
/// threshold are the opacity table and a register, loaded with the tables).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleRtlConfig {
    /// Bits per voxel, 4..=16.
    pub voxel_w: u32,
}

impl SampleRtlConfig {
    /// The RTL's parameter default.
    pub const DEFAULT: Self = Self { voxel_w: 8 };

    pub fn validate(&self) -> Result<()> {
        if !(4..=16).contains(&self.voxel_w) {
            return Err(ModelError::Config(format!(
                "gicube_sample: VoxelW {} outside 4..=16",
                self.voxel_w
            )));
        }
        Ok(())
    }

    /// Clocks from input to output: density trilin 3, shader 12 (its divider at the smallest
    /// reflectance map), shade 1, compositor 6 (contract, *The RTL*).
    pub fn latency(&self) -> u64 {
        22
    }

    /// The model's configuration of this voxel width with a sample distance and threshold.
    pub fn sample_config(&self, step: u32, et_threshold: Option<u32>) -> SampleConfig {
        SampleConfig {
            voxel_w: self.voxel_w,
            step,
            et_threshold,
        }
    }
}

crate::unit_config!(SampleRtlConfig, "gicube_sample", DEFAULT, {
    "VoxelW" => voxel_w,
});

/// Bits of one packet channel, `U(0.12)`.
const CHAN_W: u32 = 12;
/// Bits of one irradiance value, `U(2.14)`.
const IRR_W: u32 = 16;

impl StreamCodec for SampleRtlConfig {
    type In = SampleIn;
    type Out = SampleOut;

    fn in_width(&self) -> u32 {
        8 * self.voxel_w + 3 * POS_FRAC_W + 1 + 8 * IRR_W + 4 * CHAN_W + 1
    }

    fn out_width(&self) -> u32 {
        4 * CHAN_W + 1
    }

    fn pack_in(&self, it: &SampleIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        for v in it.voxels {
            w.put(u64::from(v), self.voxel_w);
        }
        for x in it.weights {
            w.put(u64::from(x), POS_FRAC_W);
        }
        w.put_bool(it.irr.is_some());
        for v in it.irr.unwrap_or([0; 8]) {
            w.put(u64::from(v), IRR_W);
        }
        for c in it.color {
            w.put(u64::from(c), CHAN_W);
        }
        w.put(u64::from(it.opacity), CHAN_W);
        w.put_bool(it.lighting);
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> SampleOut {
        let mut r = BitReader::new(words);
        let color = std::array::from_fn(|_| r.get(CHAN_W) as u16);
        let opacity = r.get(CHAN_W) as u16;
        SampleOut {
            color,
            opacity,
            terminated: r.get_bool(),
        }
    }
}

/// Random classification entries (every field uniform over its range, a quarter of the alphas
/// 0 so that empty samples are common) for the voxel width's table.
pub fn random_class_lut(rng: &mut impl rand::Rng, voxel_w: u32) -> Result<ClassLut> {
    use crate::units::cube5_shader::Rgba;
    let scfg = shader_config(voxel_w);
    ClassLut::from_fn(&scfg, |_| Rgba {
        r: rng.random_range(0..=255),
        g: rng.random_range(0..=255),
        b: rng.random_range(0..=255),
        a: if rng.random_bool(0.25) {
            0
        } else {
            rng.random_range(0..=4095)
        },
    })
}

/// A random sample for tests and benches: voxels uniform, all equal, or at the extremes; weights
/// uniform or 0 / 255; the irradiance absent, uniform or extreme; the packet's colour and opacity
/// uniform or at 0 / 4095; a lighting ray one time in five.
pub fn random_sample_in(rng: &mut impl rand::Rng, voxel_w: u32) -> SampleIn {
    let vmax = (1u32 << voxel_w) - 1;
    let voxels: [u32; 8] = match rng.random_range(0..8) {
        0 => [rng.random_range(0..=vmax); 8],
        1 => std::array::from_fn(|_| [0, vmax][rng.random_range(0..2)]),
        2 => [0; 8],
        _ => std::array::from_fn(|_| rng.random_range(0..=vmax)),
    };
    let weights = std::array::from_fn(|_| match rng.random_range(0..8) {
        0 => 0,
        1 => 255,
        _ => rng.random_range(0..=255),
    });
    let irr = match rng.random_range(0..4) {
        0 | 1 => None,
        2 => Some(std::array::from_fn(|_| {
            rng.random_range(0..=u16::MAX as u32)
        })),
        _ => Some(std::array::from_fn(|_| {
            [0, 1 << IRR_FRAC_W, u32::from(u16::MAX)][rng.random_range(0..3)]
        })),
    };
    let chan = |rng: &mut dyn rand::RngCore| -> u16 {
        match rand::Rng::random_range(rng, 0..8) {
            0 => 0,
            1 => CHAN_MAX as u16,
            _ => rand::Rng::random_range(rng, 0..=CHAN_MAX as u16),
        }
    };
    SampleIn {
        voxels,
        weights,
        irr,
        color: [chan(rng), chan(rng), chan(rng)],
        opacity: chan(rng),
        lighting: rng.random_bool(0.2),
    }
}

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

    #[test]
    fn the_stream_packs_at_the_contract_widths_and_the_tables_load_in_one_list() {
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for voxel_w in [4, 8, 12, 16] {
            let rtl = SampleRtlConfig { voxel_w };
            rtl.validate().unwrap();
            assert_eq!(rtl.in_width(), 8 * voxel_w + 202);
            assert_eq!(rtl.out_width(), 49);
            let it = random_sample_in(&mut rng, voxel_w);
            assert_eq!(rtl.pack_in(&it).len(), rtl.in_width().div_ceil(32) as usize);
            let class = random_class_lut(&mut rng, voxel_w).unwrap();
            let s = Sampler::new(rtl.sample_config(200, None), class).unwrap();
            let w = s.config_writes();
            let entries = 1usize << 12.min(voxel_w + SAMPLE_FRAC_W);
            assert_eq!(
                w.len(),
                entries + 4096 + 3,
                "class, opacity table, registers"
            );
            assert!(w[..entries]
                .iter()
                .all(|(a, d)| *a < 1 << 12 && d.len() == 2));
            assert!(w[entries..].iter().all(|(a, _)| a & CFG_REGION_COMPOS != 0));
        }
        assert!(SampleRtlConfig { voxel_w: 3 }.validate().is_err());
    }

    #[test]
    fn a_trace_records_every_sample_in_order() {
        let s = sampler(None);
        let items = [item(0, 0), item(200, 10), item(255, 4000)];
        let (outs, trace) =
            trace_samples(|| items.iter().map(|it| s.sample(it)).collect::<Vec<_>>());
        assert_eq!(outs.len(), 3);
        assert_eq!(trace.items, items);
        assert_eq!(trace.others, 0);
        assert!(trace.sampler.is_some());
        // Outside trace_samples nothing is recorded.
        s.sample(&items[0]);
        let ((), empty) = trace_samples(|| ());
        assert!(empty.items.is_empty());
    }

    #[test]
    fn one_step_is_within_a_lsb_of_opacity_and_an_8_bit_colour_code_of_its_f64_reference() {
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        for step in [16, 200, 1024] {
            let class = random_class_lut(&mut rng, 8).unwrap();
            let s =
                Sampler::new(SampleRtlConfig::DEFAULT.sample_config(step, None), class).unwrap();
            for _ in 0..20_000 {
                let it = random_sample_in(&mut rng, 8);
                let o = s.sample(&it);
                let r = s.reference(&it);
                let got = [o.color[0], o.color[1], o.color[2], o.opacity].map(f64::from);
                for ch in 0..4 {
                    if r[ch] < f64::from(CHAN_MAX) {
                        // Half an 8-bit colour code is 4096 / 510 = 8.03 LSB.
                        let bound = if ch < 3 { 4096.0 / 510.0 + 1.5 } else { 1.0 };
                        assert!((got[ch] - r[ch]).abs() <= bound, "{it:?}: {got:?} vs {r:?}");
                    }
                }
            }
        }
    }
}
