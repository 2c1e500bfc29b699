//! The GI-Cube block processor's sample datapath (`gicube_sample`; parts I, J, K and L of
//! docs/gicube-rtl.md, patent [353], [379]-[380], [383]), written from
//! `docs/numerics/gicube_sample.md`: the tri-linear sample of the eight corner voxels
//! (`cube5_trilin`), its classification (`cube5_shader`, unlit), the irradiance of a lit rendering
//! ray (a second `cube5_trilin` and the multiply), and one front-to-back compositing step onto the
//! packet's colour and opacity (`cube5_compos`, with its opacity LUT and termination threshold),
//! optionally jittered ([`Jitter`]: the random, log and power LUTs of [353], [380]). A pure
//! function of the item.
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
    /// Jitter ([353], [380]): each sample's opacity is corrected for a step `r dr`, `r` in
    /// `[1/2, 1)` from the random LUT at the mangled position bits ([`Jitter`]); off: `r = 1`.
    pub jitter: bool,
    /// Shading by reflectance map with the gradient of the gradient LUT and the nearest tag
    /// ([352], [378], [379], [383]; contract *Gradient, tag and reflectance map*); `None`: unlit.
    pub shade: Option<ShadeConfig>,
}

/// The widths of the shaded datapath (`Shade = 1`): the gradient index and the tag.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShadeConfig {
    /// Bits of a voxel's gradient index, 2..=11 (the patent's 11): `2^GradIdxW` LUT entries.
    pub grad_idx_w: u32,
    /// Bits of a voxel's tag, 0..=4 and below the classification index bits; 0: no tag.
    pub tag_w: u32,
}

/// Bits of one decoded gradient component, two's complement ([378]: three 10-bit components).
pub const GRAD_COMP_W: u32 = 10;
/// The largest gradient index width ([378]) and tag width.
pub const GRAD_IDX_W_MAX: u32 = 11;
pub const TAG_W_MAX: u32 = 4;

impl ShadeConfig {
    pub fn validate(&self, voxel_w: u32) -> Result<()> {
        let class_idx_w = shader_config(voxel_w).class_idx_w;
        if !(2..=GRAD_IDX_W_MAX).contains(&self.grad_idx_w)
            || self.tag_w > TAG_W_MAX
            || self.tag_w >= class_idx_w
        {
            return Err(ModelError::Config(format!(
                "gicube_sample: GradIdxW {} outside 2..={GRAD_IDX_W_MAX} or TagW {} outside \
                 0..={} (below ClassIdxW {class_idx_w})",
                self.grad_idx_w,
                self.tag_w,
                TAG_W_MAX.min(class_idx_w - 1)
            )));
        }
        Ok(())
    }
}

/// Fraction bits of the interpolated gradient, `min(4, VoxelW - 4)`: the `S(10.Fg)` components
/// fit the shader's `VoxelW + 6`-bit gradient inputs.
pub fn grad_frac_w(voxel_w: u32) -> u32 {
    SAMPLE_FRAC_W.min(voxel_w.saturating_sub(4))
}

/// The corner nearest the sample ([352], [379]: the tag is zero-order interpolated): bit `a` of
/// the corner is the top bit of axis `a`'s weight (`w >= 1/2`).
pub fn nearest_corner(weights: [u32; 3]) -> usize {
    (0..3).fold(0, |c, a| {
        c | (((weights[a] >> (POS_FRAC_W - 1)) & 1) as usize) << a
    })
}

/// The gradient LUT ([378]): `2^GradIdxW` entries of three `S(10)` components, the decoding of a
/// voxel's gradient index; loaded by the host (eight identical copies in the RTL).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GradLut {
    idx_w: u32,
    entries: Vec<[i32; 3]>,
}

impl GradLut {
    /// Entry `i` is `f(i)`; every component in `-512..=511`.
    pub fn from_fn(idx_w: u32, f: impl FnMut(usize) -> [i32; 3]) -> Result<Self> {
        let entries: Vec<[i32; 3]> = (0..1usize << idx_w.min(GRAD_IDX_W_MAX)).map(f).collect();
        let half = 1i32 << (GRAD_COMP_W - 1);
        if !(2..=GRAD_IDX_W_MAX).contains(&idx_w)
            || entries
                .iter()
                .flatten()
                .any(|&g| !(-half..half).contains(&g))
        {
            return Err(ModelError::Config(format!(
                "gicube_sample: a gradient LUT of {idx_w} index bits with components in \
                 -{half}..{half}"
            )));
        }
        Ok(Self { idx_w, entries })
    }

    /// Every entry zero (every gradient zero: the reflectance map's zero-gradient entry).
    pub fn zero(idx_w: u32) -> Result<Self> {
        Self::from_fn(idx_w, |_| [0; 3])
    }

    /// Quantized directions for a host that bins its gradients ([352]): entry 0 is the zero
    /// gradient, entries `1..2^GradIdxW` are the points of a Fibonacci sphere (uniform
    /// directions), each component `511` times the unit vector's, rounded to nearest.
    pub fn directions(idx_w: u32) -> Result<Self> {
        let n = ((1usize << idx_w.min(GRAD_IDX_W_MAX)) - 1) as f64;
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        Self::from_fn(idx_w, |i| {
            if i == 0 {
                return [0; 3];
            }
            let k = (i - 1) as f64;
            let z = 1.0 - 2.0 * (k + 0.5) / n;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * k;
            [r * phi.cos(), r * phi.sin(), z].map(|v| (v * 511.0).round() as i32)
        })
    }

    /// The index whose direction is nearest `g` (largest cosine); 0 for the zero vector.
    pub fn index_of(&self, g: [f64; 3]) -> u32 {
        if g == [0.0; 3] {
            return 0;
        }
        let cos = |e: &[i32; 3]| {
            let len = e.iter().map(|&c| f64::from(c).powi(2)).sum::<f64>().sqrt();
            if len == 0.0 {
                return f64::NEG_INFINITY;
            }
            (0..3).map(|a| f64::from(e[a]) * g[a]).sum::<f64>() / len
        };
        (0..self.entries.len())
            .max_by(|&a, &b| cos(&self.entries[a]).total_cmp(&cos(&self.entries[b])))
            .unwrap_or(0) as u32
    }

    /// Random entries (one in eight zero, else every component uniform) for tests.
    pub fn random(rng: &mut impl rand::Rng, idx_w: u32) -> Result<Self> {
        let half = 1i32 << (GRAD_COMP_W - 1);
        Self::from_fn(idx_w, |_| {
            if rng.random_range(0..8) == 0 {
                [0; 3]
            } else {
                std::array::from_fn(|_| rng.random_range(-half..half))
            }
        })
    }

    pub fn idx_w(&self) -> u32 {
        self.idx_w
    }

    pub fn entries(&self) -> &[[i32; 3]] {
        &self.entries
    }

    /// The entry of index `i` (its low `GradIdxW` bits: the field's width).
    pub fn entry(&self, i: u32) -> [i32; 3] {
        self.entries[(i & ((1 << self.idx_w) - 1)) as usize]
    }
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
    /// The corners' gradient indices (`GradIdxW` bits each; read only with shading).
    pub grad_idx: [u32; 8],
    /// The corners' tags (`TagW` bits each; read only with shading and `TagW > 0`).
    pub tags: [u32; 8],
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
    jitter: Option<Jitter>,
    grad_trilin: Trilin,
    grad: Option<GradLut>,
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

/// The classification and reflectance map of a datapath with `shade`: [`shader_config`], and with
/// a tag the 2-D index of density bits over `TagW` tag bits (the shader's magnitude input
/// carries the tag: `MagIdxW = TagW`, `MagShift = 0`).
pub fn shader_config_for(voxel_w: u32, shade: Option<ShadeConfig>) -> ShaderConfig {
    let base = shader_config(voxel_w);
    match shade {
        Some(s) if s.tag_w > 0 => ShaderConfig {
            mag_idx_w: s.tag_w,
            mag_shift: 0,
            ..base
        },
        _ => base,
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

/// Jitter ([353], [380]; contract *Jitter and the power LUT*): index bits of the random LUT.
pub const JIT_IDX_W: u32 = 8;
/// Bits of a random LUT entry `J`: the factor is `r = (2^7 + J) / 2^8`, in `[1/2, 1)`.
pub const JIT_W: u32 = 7;
/// Bits of a log LUT entry, `U(4.12)`: `-ln(1 - alpha) dr / 256`.
pub const LOG_W: u32 = 16;
/// Fraction bits of the log LUT entry and of the product `p`.
pub const LOG_FRAC_W: u32 = 12;
/// The log LUT's "infinite" entry (alpha code 4095: opaque at any step).
pub const LOG_OPAQUE: u32 = (1 << LOG_W) - 1;
/// Index bits of the power (exp) LUT: `p >> EXP_SHIFT`.
pub const EXP_IDX_W: u32 = 10;
/// Bits of `p` below the power LUT's index, the interpolation fraction.
pub const EXP_SHIFT: u32 = LOG_W - EXP_IDX_W;
/// Bits of a power LUT entry's code `E` (an alpha code, `/ 4095`) and of its difference `D`.
pub const EXP_CODE_W: u32 = 12;
pub const EXP_DIFF_W: u32 = 7;
/// The largest alpha code.
const ALPHA_MAX: u32 = 4095;
/// Largest error of [`Jitter::alpha`] against `4095 (1 - (1 - a/4095)^(r dr/256))`, in alpha
/// codes (contract, *Jitter and the power LUT*: the log entry's and the product's rounding, 1 code
/// together; the power entries' rounding and interpolation, 1.13; an entry capped at 16, 1.4).
pub const JITTER_ALPHA_BOUND: f64 = 2.6;

/// The mangled position bits that index the random LUT: the sample position's fraction bits
/// (the weights), `wx ^ rotl8(wy, 3) ^ rotl8(wz, 5)`.
pub fn jitter_index(weights: [u32; 3]) -> usize {
    let rotl8 = |x: u32, k: u32| ((x << k) | (x >> (8 - k))) & 0xFF;
    ((weights[0] & 0xFF) ^ rotl8(weights[1] & 0xFF, 3) ^ rotl8(weights[2] & 0xFF, 5)) as usize
}

/// The random LUT's contents (fixed; the one source of the RTL's table, loaded through the
/// configuration port): entry `i` is the top `JIT_W` bits of SplitMix64's output for `i`.
pub fn jitter_table() -> Vec<u32> {
    (0..1u64 << JIT_IDX_W)
        .map(|i| {
            let mut z = i.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> (64 - JIT_W)) as u32
        })
        .collect()
}

/// The log LUT for sample distance `step` (`U(4.8)`): entry `a` is `min(LOG_OPAQUE - 1,
/// rnd(-ln(1 - a / 4095) step / 256 * 2^12))`, and `LOG_OPAQUE` at `a = 4095`.
pub fn log_table(step: u32) -> Vec<u32> {
    let ratio = f64::from(step) / f64::from(1u32 << POS_FRAC_W);
    (0..=ALPHA_MAX)
        .map(|a| {
            if a == ALPHA_MAX {
                return LOG_OPAQUE;
            }
            let l = -(-f64::from(a) / f64::from(ALPHA_MAX)).ln_1p() * ratio;
            ((l * f64::from(1u32 << LOG_FRAC_W) + 0.5).floor()).min(f64::from(LOG_OPAQUE - 1))
                as u32
        })
        .collect()
}

/// The power LUT (fixed): entry `i` is `(E_i, E_(i+1) - E_i)` with `E_i = rnd(4095 (1 -
/// exp(-i 2^(EXP_SHIFT - 12))))`, the alpha code of `1 - exp(-p)` at the entry's `p`.
pub fn exp_table() -> Vec<(u32, u32)> {
    let e = |i: u32| {
        let p = f64::from(i << EXP_SHIFT) / f64::from(1u32 << LOG_FRAC_W);
        (-(-p).exp_m1() * f64::from(ALPHA_MAX) + 0.5).floor() as u32
    };
    (0..1u32 << EXP_IDX_W)
        .map(|i| (e(i), e(i + 1) - e(i)))
        .collect()
}

/// The jitter tables of one sample distance: random, log and power LUTs.
#[derive(Debug, Clone)]
pub struct Jitter {
    jit: Vec<u32>,
    log: Vec<u32>,
    exp: Vec<(u32, u32)>,
}

impl Jitter {
    pub fn new(step: u32) -> Self {
        Self {
            jit: jitter_table(),
            log: log_table(step),
            exp: exp_table(),
        }
    }

    /// The factor `r = (2^7 + J) / 2^8` of random LUT entry `idx`.
    pub fn factor(&self, idx: usize) -> f64 {
        f64::from((1 << JIT_W) + self.jit[idx]) / f64::from(1u32 << (JIT_W + 1))
    }

    /// The alpha code of `1 - (1 - a / 4095)^(r dr / 256)`: `L = log[a]` (opaque stays 4095),
    /// `p = rnd(L (2^7 + J), 8)`, `E, D = exp[p >> 6]`, `E + rnd(D (p & 63), 6)`.
    pub fn alpha(&self, a: u32, idx: usize) -> u32 {
        let l = self.log[a as usize];
        if l == LOG_OPAQUE {
            return ALPHA_MAX;
        }
        let p = rnd(
            u64::from(l) * u64::from((1 << JIT_W) + self.jit[idx]),
            JIT_W + 1,
        ) as u32;
        let (e, d) = self.exp[(p >> EXP_SHIFT) as usize];
        e + rnd(
            u64::from(d) * u64::from(p & ((1 << EXP_SHIFT) - 1)),
            EXP_SHIFT,
        ) as u32
    }
}

impl Sampler {
    /// The datapath for `cfg` with the classification table `class` (built for
    /// [`shader_config`]`(cfg.voxel_w)`).
    pub fn new(cfg: SampleConfig, class: ClassLut) -> Result<Self> {
        let trilin = Trilin::new(TrilinConfig::new(cfg.voxel_w, POS_FRAC_W, SAMPLE_FRAC_W)?)?;
        if let Some(sh) = cfg.shade {
            sh.validate(cfg.voxel_w)?;
        }
        let scfg = shader_config_for(cfg.voxel_w, cfg.shade);
        let rmap = ReflectanceMap::from_fn(&scfg, |_, _, _| Texel::default(), Texel::default())?;
        let shader = Shader::new(scfg, ShaderTables { class, rmap })?;
        let ccfg = compos_config();
        let lut = OpacityLut::new(f64::from(cfg.step) / f64::from(1u32 << POS_FRAC_W), &ccfg)?;
        let mut regs = match cfg.et_threshold {
            Some(t) => ComposRegs {
                et_threshold: u64::from(t),
                ..ComposRegs::defaults(&ccfg)
            },
            None => ComposRegs::without_termination(&ccfg),
        };
        // With jitter the alpha code the compositor sees is already corrected: it reads it as
        // `U(code, 12, 12)` (its LUT bypass).
        regs.lut_bypass = cfg.jitter;
        Ok(Self {
            cfg,
            trilin,
            irr_trilin: Trilin::new(TrilinConfig::new(16, POS_FRAC_W, 0)?)?,
            shader,
            compos: Compos::new(ccfg, lut, regs)?,
            jitter: cfg.jitter.then(|| Jitter::new(cfg.step)),
            grad_trilin: Trilin::new(TrilinConfig::new(
                GRAD_COMP_W,
                POS_FRAC_W,
                grad_frac_w(cfg.voxel_w),
            )?)?,
            grad: cfg.shade.map(|s| GradLut::zero(s.grad_idx_w)).transpose()?,
        })
    }

    /// The shading tables of a datapath with `shade`: the reflectance map (built for
    /// [`shader_config_for`]) and the gradient LUT (of `GradIdxW` index bits).
    pub fn with_shading(mut self, rmap: ReflectanceMap, grad: GradLut) -> Result<Self> {
        match self.cfg.shade {
            Some(s) if s.grad_idx_w == grad.idx_w => {}
            _ => {
                return Err(ModelError::Config(
                    "gicube_sample: shading tables for a datapath without them or of another \
                     GradIdxW"
                        .into(),
                ))
            }
        }
        let class = self.shader.tables().class.clone();
        self.shader = Shader::new(self.shader.config(), ShaderTables { class, rmap })?;
        self.grad = Some(grad);
        Ok(self)
    }

    /// The gradient LUT (shading on).
    pub fn grad_lut(&self) -> Option<&GradLut> {
        self.grad.as_ref()
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

    /// The shader's item: rule 1's density sample; with shading, rule 1's gradient (S(10.Fg)),
    /// the nearest corner's tag as the magnitude (the 2-D index) and the mode: lit for a
    /// rendering ray without irradiance, unlit otherwise.
    fn shader_in(&self, it: &SampleIn) -> ShaderIn {
        let sample = self.trilin.sample(&TrilinIn {
            voxels: it.voxels,
            weights: it.weights,
            mode: TrilinMode::Lerp,
        });
        match self.cfg.shade {
            None => ShaderIn {
                sample,
                grad: [0; 3],
                mag: 0,
                mode: unlit(),
            },
            Some(sh) => ShaderIn {
                sample,
                grad: self.gradient(it),
                mag: it.tags[nearest_corner(it.weights)] & ((1 << sh.tag_w) - 1),
                mode: ShaderMode {
                    tf2d: sh.tag_w > 0,
                    unlit: it.lighting || it.irr.is_some(),
                },
            },
        }
    }

    /// Rule 1's gradient (shading on; zero otherwise): per axis, the corners' LUT components
    /// offset by `2^9` (unsigned), tri-linear at `VoxelW = 10`, `FracW = Fg`, the offset
    /// `2^(9 + Fg)` taken off again: `S(10.Fg)`, exactly the signed tri-linear interpolation.
    pub fn gradient(&self, it: &SampleIn) -> [i32; 3] {
        let Some(lut) = &self.grad else {
            return [0; 3];
        };
        let half = 1i32 << (GRAD_COMP_W - 1);
        let fg = self.grad_trilin.config().frac_w;
        std::array::from_fn(|a| {
            let voxels = std::array::from_fn(|c| (lut.entry(it.grad_idx[c])[a] + half) as u32);
            self.grad_trilin.sample(&TrilinIn {
                voxels,
                weights: it.weights,
                mode: TrilinMode::Lerp,
            }) as i32
                - (half << fg)
        })
    }

    /// The f64 gradient (shading on): the corners' LUT components tri-linear in reals, in
    /// units of the LUT's integers.
    pub fn gradient_f64(&self, it: &SampleIn) -> [f64; 3] {
        let Some(lut) = &self.grad else {
            return [0.0; 3];
        };
        let w = it
            .weights
            .map(|x| f64::from(x) / f64::from(1u32 << POS_FRAC_W));
        std::array::from_fn(|a| {
            (0..8).fold(0.0, |acc, c| {
                let k = (0..3).fold(1.0, |k, ax| {
                    k * if (c >> ax) & 1 == 1 {
                        w[ax]
                    } else {
                        1.0 - w[ax]
                    }
                });
                acc + k * f64::from(lut.entry(it.grad_idx[c])[a])
            })
        })
    }

    /// One sample (contract rules 1-5).
    pub fn sample(&self, it: &SampleIn) -> SampleOut {
        TRACE.with(|t| {
            if let Some(tr) = t.borrow_mut().as_mut() {
                tr.record(self, it);
            }
        });
        // Rules 2 and 3's reflectance map: the classified entry, lit when the shader's mode is.
        let e = self.shader.shade(&self.shader_in(it));
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
        let alpha = match &self.jitter {
            Some(j) => j.alpha(e.a, jitter_index(it.weights)),
            None => e.a,
        };
        let out = self.compos.step(
            &coxel,
            &Sample {
                rgb,
                alpha,
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
    /// With jitter the step is `r dr` with the datapath's factor `r` of the item's position bits.
    /// Returns red, green, blue, opacity on the packet's scale (`4096 = 1.0`), unsaturated.
    /// With shading, a rendering ray without irradiance takes its colour from the shader's f64
    /// reference (`Shader::reference_exact`: exact face coordinates, bilinear weights and
    /// `c d + sp`) at the f64 gradient ([`Sampler::gradient_f64`]).
    pub fn reference(&self, it: &SampleIn) -> [f64; 4] {
        let si = self.shader_in(it);
        let e = self.shader.classify(&si);
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
        let mut rgb = [e.r, e.g, e.b].map(|c| {
            if it.lighting {
                0.0
            } else {
                (color_value(c, &ccfg) * irr.unwrap_or(1.0)).min(1.0)
            }
        });
        if !si.mode.unlit {
            // The f64 gradient on a fine integer grid (2^16 per LUT unit: exact to 2^-17 of a
            // unit, the direction is all the map reads).
            let g = self
                .gradient_f64(it)
                .map(|v| (v * f64::from(1u32 << 16)).round() as i32);
            let lit = self.shader.reference_exact(&ShaderIn { grad: g, ..si });
            rgb = lit.map(|v| v / f64::from(ccfg.color_max()));
        }
        let r = self
            .jitter
            .as_ref()
            .map_or(1.0, |j| j.factor(jitter_index(it.weights)));
        let a = corrected_alpha(
            alpha_value(e.a, &ccfg),
            r * f64::from(self.cfg.step) / f64::from(1u32 << POS_FRAC_W),
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
/// Jitter tables (`Jitter = 1`): the log LUT at `CFG_LOG + a` (region 0 above the classification
/// index), the power LUT at `CFG_EXP + i` and the random LUT at `CFG_JIT + i` (the compositor's
/// region above its registers: it ignores them).
pub const CFG_LOG: u32 = 1 << 12;
pub const CFG_EXP: u32 = CFG_REGION_COMPOS | 0x1800;
pub const CFG_JIT: u32 = CFG_REGION_COMPOS | 0x1C00;
/// Shading tables (`Shade = 1`, address bit 14): the gradient LUT at `CFG_GRAD + i`, the texels
/// at `CFG_TEXEL +` the shader's region-1 offset, the zero-gradient entry at `CFG_ZERO`.
pub const CFG_GRAD: u32 = 1 << 14;
pub const CFG_TEXEL: u32 = CFG_GRAD | 1 << 12;
pub const CFG_ZERO: u32 = CFG_GRAD | 2 << 12;

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
        if let Some(j) = &self.jitter {
            let word = |v: u32| {
                let mut w = BitWriter::new();
                w.put(u64::from(v), CFG_DATA_W);
                w.finish(CFG_DATA_W)
            };
            writes.extend((0u32..).zip(&j.log).map(|(a, &l)| (CFG_LOG + a, word(l))));
            writes.extend(
                (0u32..)
                    .zip(&j.exp)
                    .map(|(i, &(e, d))| (CFG_EXP + i, word(e | d << EXP_CODE_W))),
            );
            writes.extend((0u32..).zip(&j.jit).map(|(i, &r)| (CFG_JIT + i, word(r))));
        }
        if let Some(g) = &self.grad {
            let mask = (1u64 << GRAD_COMP_W) - 1;
            writes.extend((0u32..).zip(g.entries()).map(|(i, e)| {
                let mut w = BitWriter::new();
                for c in e {
                    w.put(i64::from(*c) as u64 & mask, GRAD_COMP_W);
                }
                (CFG_GRAD + i, w.finish_padded(CFG_DATA_W))
            }));
            // The shader's texel and zero-gradient writes, moved from its regions 1 and 2.
            let scfg = self.shader.config();
            let region_shift = scfg.cfg_addr_w() - 2;
            for (addr, data) in self.shader.tables().config_writes(&scfg) {
                let off = addr & ((1 << region_shift) - 1);
                match addr >> region_shift {
                    1 => writes.push((CFG_TEXEL + off, data)),
                    2 => writes.push((CFG_ZERO + off, data)),
                    _ => {}
                }
            }
        }
        writes
    }
}

/// The RTL top's parameters: the voxel width alone (the sample distance and the termination
/// threshold are the opacity table and a register, loaded with the tables).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleRtlConfig {
    /// Bits per voxel, 4..=16.
    pub voxel_w: u32,
    /// 1: the jitter stage (random, log and power LUTs) before the compositor; 0: none.
    pub jitter: u32,
    /// 1: the gradient LUTs, the gradient tri-linear and the reflectance map (shading); 0: unlit.
    pub shade: u32,
    /// Gradient index bits (`Shade = 1`), 2..=11.
    pub grad_idx_w: u32,
    /// Tag bits (`Shade = 1`), 0..=4; 0 with `Shade = 0`.
    pub tag_w: u32,
}

impl SampleRtlConfig {
    /// The RTL's parameter default.
    pub const DEFAULT: Self = Self {
        voxel_w: 8,
        jitter: 0,
        shade: 0,
        grad_idx_w: 11,
        tag_w: 0,
    };

    pub fn validate(&self) -> Result<()> {
        if !(4..=16).contains(&self.voxel_w) {
            return Err(ModelError::Config(format!(
                "gicube_sample: VoxelW {} outside 4..=16",
                self.voxel_w
            )));
        }
        if self.jitter > 1 {
            return Err(ModelError::Config(format!(
                "gicube_sample: Jitter {} is not 0 or 1",
                self.jitter
            )));
        }
        if self.shade > 1 || (self.shade == 0 && self.tag_w != 0) {
            return Err(ModelError::Config(format!(
                "gicube_sample: Shade {} is not 0 or 1, or TagW {} without Shade",
                self.shade, self.tag_w
            )));
        }
        self.shade_config()
            .unwrap_or(ShadeConfig {
                grad_idx_w: self.grad_idx_w,
                tag_w: 0,
            })
            .validate(self.voxel_w)
    }

    /// The shading widths (`Shade = 1`).
    pub fn shade_config(&self) -> Option<ShadeConfig> {
        (self.shade != 0).then_some(ShadeConfig {
            grad_idx_w: self.grad_idx_w,
            tag_w: self.tag_w,
        })
    }

    /// Clocks from input to output: density trilin 3, shader 12 (its divider at the smallest
    /// reflectance map), shade 1, the jitter stage 1 (`Jitter = 1`), compositor 6 (contract,
    /// *The RTL*); with `Shade = 1` the gradient LUT stage 1 and the shader 17 (its divider at
    /// the 8 x 8-cell map): 6 more.
    pub fn latency(&self) -> u64 {
        22 + u64::from(self.jitter) + 6 * u64::from(self.shade)
    }

    /// The model's configuration of this voxel width with a sample distance and threshold.
    pub fn sample_config(&self, step: u32, et_threshold: Option<u32>) -> SampleConfig {
        SampleConfig {
            voxel_w: self.voxel_w,
            step,
            et_threshold,
            jitter: self.jitter != 0,
            shade: self.shade_config(),
        }
    }
}

crate::unit_config!(SampleRtlConfig, "gicube_sample", DEFAULT, {
    "VoxelW" => voxel_w,
    "Jitter" => jitter,
    "Shade" => shade,
    "GradIdxW" => grad_idx_w,
    "TagW" => tag_w,
});

/// Bits of one packet channel, `U(0.12)`.
const CHAN_W: u32 = 12;
/// Bits of one irradiance value, `U(2.14)`.
const IRR_W: u32 = 16;

impl StreamCodec for SampleRtlConfig {
    type In = SampleIn;
    type Out = SampleOut;

    fn in_width(&self) -> u32 {
        8 * self.voxel_w
            + 3 * POS_FRAC_W
            + 1
            + 8 * IRR_W
            + 4 * CHAN_W
            + 1
            + self.shade * 8 * (self.grad_idx_w + self.tag_w)
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
        if self.shade != 0 {
            for (fields, width) in [(it.grad_idx, self.grad_idx_w), (it.tags, self.tag_w)] {
                for v in fields {
                    w.put(u64::from(v) & ((1 << width) - 1), width);
                }
            }
        }
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
        grad_idx: [0; 8],
        tags: [0; 8],
    }
}

/// [`random_sample_in`] for a datapath of `cfg`: with shading, the corners' gradient indices
/// uniform, all one index, or 0 (the zero gradient) one time in eight, and the tags uniform.
pub fn random_sample_for(rng: &mut impl rand::Rng, cfg: SampleRtlConfig) -> SampleIn {
    let mut it = random_sample_in(rng, cfg.voxel_w);
    if cfg.shade != 0 {
        let imax = (1u32 << cfg.grad_idx_w) - 1;
        it.grad_idx = match rng.random_range(0..8) {
            0 => [0; 8],
            1 => [rng.random_range(0..=imax); 8],
            _ => std::array::from_fn(|_| rng.random_range(0..=imax)),
        };
        it.tags = std::array::from_fn(|_| rng.random_range(0..1u32 << cfg.tag_w));
    }
    it
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
            jitter: false,
            shade: None,
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
            grad_idx: [0; 8],
            tags: [0; 8],
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
            let rtl = SampleRtlConfig {
                voxel_w,
                ..SampleRtlConfig::DEFAULT
            };
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
        // With jitter the three tables follow, each address written once.
        let rtl = SampleRtlConfig {
            jitter: 1,
            ..SampleRtlConfig::DEFAULT
        };
        assert_eq!(rtl.latency(), 23);
        let class = random_class_lut(&mut rng, 8).unwrap();
        let w = Sampler::new(rtl.sample_config(200, None), class)
            .unwrap()
            .config_writes();
        assert_eq!(w.len(), 4096 + 4096 + 3 + 4096 + 1024 + 256);
        let mut addrs: Vec<u32> = w.iter().map(|(a, _)| *a).collect();
        addrs.sort_unstable();
        addrs.dedup();
        assert_eq!(addrs.len(), w.len(), "no address written twice");
        assert!(SampleRtlConfig {
            voxel_w: 3,
            ..SampleRtlConfig::DEFAULT
        }
        .validate()
        .is_err());
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

    /// 3 x 20,000 random samples (`dr` 16, 200, 1024) within `extra` more than one opacity LSB
    /// and half an 8-bit colour code (4096 / 510 = 8.03 LSB, plus 1.5) of the f64 reference.
    fn one_step_against_f64(jitter: u32, seed: u64, extra: f64) {
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let rtl = SampleRtlConfig {
            jitter,
            ..SampleRtlConfig::DEFAULT
        };
        for step in [16, 200, 1024] {
            let class = random_class_lut(&mut rng, 8).unwrap();
            let s = Sampler::new(rtl.sample_config(step, None), class).unwrap();
            for _ in 0..20_000 {
                let it = random_sample_in(&mut rng, 8);
                let o = s.sample(&it);
                let r = s.reference(&it);
                let got = [o.color[0], o.color[1], o.color[2], o.opacity].map(f64::from);
                for ch in 0..4 {
                    if r[ch] < f64::from(CHAN_MAX) {
                        let bound = extra + if ch < 3 { 4096.0 / 510.0 + 1.5 } else { 1.0 };
                        assert!((got[ch] - r[ch]).abs() <= bound, "{it:?}: {got:?} vs {r:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn one_step_is_within_a_lsb_of_opacity_and_an_8_bit_colour_code_of_its_f64_reference() {
        one_step_against_f64(0, 9, 0.0);
    }

    #[test]
    fn the_jitter_tables_hold_what_the_contract_says() {
        let jit = jitter_table();
        assert_eq!(jit.len(), 1 << JIT_IDX_W);
        assert!(jit.iter().all(|&j| j < 1 << JIT_W));
        let mean = jit.iter().map(|&j| f64::from(j)).sum::<f64>() / jit.len() as f64;
        assert!(
            (mean - 63.5).abs() < 6.0,
            "uniform over 0..128: mean {mean}"
        );
        for step in [16, 256, 1024] {
            let log = log_table(step);
            assert_eq!((log[0], log[4095]), (0, LOG_OPAQUE));
            assert!(log.windows(2).all(|w| w[0] <= w[1]), "monotone");
        }
        let exp = exp_table();
        assert_eq!(exp.len(), 1 << EXP_IDX_W);
        assert_eq!(exp[0].0, 0);
        assert!(exp
            .iter()
            .all(|&(e, d)| d < 1 << EXP_DIFF_W && e + d <= 4095));
        // Every position byte pattern reaches the LUT.
        let mut seen = [false; 256];
        for w in 0..256 {
            seen[jitter_index([w, 0, 0])] = true;
        }
        assert!(seen.iter().all(|&b| b));
    }

    #[test]
    fn a_jittered_empty_cell_leaves_the_packet_unchanged_and_an_opaque_one_stays_opaque() {
        let j = Jitter::new(1024);
        for idx in 0..256 {
            assert_eq!(j.alpha(0, idx), 0);
            assert_eq!(j.alpha(4095, idx), 4095);
        }
        let mut cfg = SampleRtlConfig::DEFAULT.sample_config(256, None);
        cfg.jitter = true;
        let class =
            ClassLut::from_transfer(&shader_config(8), &TransferFunction::head_default()).unwrap();
        let s = Sampler::new(cfg, class).unwrap();
        let it = item(0, 1000);
        let o = s.sample(&it);
        assert_eq!((o.color, o.opacity, o.terminated), (it.color, 1000, false));
    }

    #[test]
    fn the_jittered_alpha_is_within_its_bound_of_f64() {
        for step in [16, 100, 256, 1024] {
            let j = Jitter::new(step);
            let mut worst = 0.0f64;
            for a in 0..=4095u32 {
                for idx in (0..256).step_by(7) {
                    let x = f64::from(a) / 4095.0;
                    let want = corrected_alpha(x, j.factor(idx) * f64::from(step) / 256.0) * 4095.0;
                    worst = worst.max((f64::from(j.alpha(a, idx)) - want).abs());
                }
            }
            assert!(worst <= JITTER_ALPHA_BOUND, "step {step}: {worst} codes");
        }
    }

    #[test]
    fn one_jittered_step_is_within_its_bound_of_the_f64_reference() {
        one_step_against_f64(1, 11, JITTER_ALPHA_BOUND);
    }

    fn shaded_sampler(voxel_w: u32, tag_w: u32, step: u32) -> Sampler {
        use crate::units::cube5_shader::Phong;
        let shade = ShadeConfig {
            grad_idx_w: 11,
            tag_w,
        };
        let cfg = SampleConfig {
            voxel_w,
            step,
            et_threshold: None,
            jitter: false,
            shade: Some(shade),
        };
        let scfg = shader_config_for(voxel_w, Some(shade));
        let class = ClassLut::from_transfer(&scfg, &TransferFunction::head_default()).unwrap();
        let rmap = ReflectanceMap::from_lights(&scfg, &Phong::two_lights()).unwrap();
        Sampler::new(cfg, class)
            .unwrap()
            .with_shading(rmap, GradLut::directions(11).unwrap())
            .unwrap()
    }

    #[test]
    fn the_gradient_lut_of_directions_finds_its_own_entries() {
        let lut = GradLut::directions(11).unwrap();
        assert_eq!(lut.entries().len(), 2048);
        assert_eq!(lut.index_of([0.0; 3]), 0);
        for k in [1u32, 2, 100, 1000, 2047] {
            let e = lut.entry(k).map(f64::from);
            assert_eq!(lut.index_of(e), k, "entry {k}");
        }
        assert!(lut.entries().iter().skip(1).all(|e| e
            .iter()
            .map(|&c| f64::from(c).powi(2))
            .sum::<f64>()
            .sqrt()
            > 509.0));
        assert!(GradLut::from_fn(4, |_| [512, 0, 0]).is_err());
        assert!(GradLut::zero(12).is_err());
    }

    #[test]
    fn the_gradient_is_the_signed_trilinear_interpolation_of_the_lut_entries() {
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
        for voxel_w in [4, 6, 8, 12] {
            let rtl = SampleRtlConfig {
                voxel_w,
                shade: 1,
                grad_idx_w: 6,
                ..SampleRtlConfig::DEFAULT
            };
            let class = random_class_lut(&mut rng, voxel_w).unwrap();
            let scfg = shader_config_for(voxel_w, rtl.shade_config());
            let rmap = crate::units::cube5_shader::ShaderTables::random(&scfg, &mut rng)
                .unwrap()
                .rmap;
            let s = Sampler::new(rtl.sample_config(256, None), class)
                .unwrap()
                .with_shading(rmap, GradLut::random(&mut rng, 6).unwrap())
                .unwrap();
            let fg = grad_frac_w(voxel_w);
            for _ in 0..5000 {
                let it = random_sample_for(&mut rng, rtl);
                let g = s.gradient(&it);
                let r = s.gradient_f64(&it);
                for a in 0..3 {
                    let err = f64::from(g[a]) - r[a] * f64::from(1u32 << fg);
                    // Three roundings of half an output LSB (the trilin's bound).
                    assert!(err.abs() <= 1.5, "{voxel_w}: {g:?} vs {r:?}");
                }
                if it.grad_idx.iter().all(|&i| i == it.grad_idx[0]) {
                    let e = s.grad_lut().unwrap().entry(it.grad_idx[0]);
                    assert_eq!(g, e.map(|c| c << fg), "one entry at every corner is exact");
                }
            }
        }
    }

    #[test]
    fn a_shaded_rendering_ray_is_lit_by_the_map_and_lit_or_lighting_rays_are_not() {
        let s = shaded_sampler(8, 0, 256);
        let plain = sampler(None);
        let mut it = item(200, 0);
        it.color = [0; 3];
        // Every corner the direction of entry 5: the gradient is that entry, exactly.
        it.grad_idx = [5; 8];
        let si = s.shader_in(&it);
        assert!(!si.mode.unlit);
        let want = s.shader().shade(&si);
        let o = s.sample(&it);
        let e = plain.sample(&it);
        assert_eq!(o.opacity, e.opacity, "shading changes no opacity");
        assert_ne!(o.color, e.color, "the map lights the colour");
        let lit_alone = Sampler::new(
            SampleConfig {
                shade: None,
                ..s.config()
            },
            ClassLut::from_fn(&s.shader().config(), |_| want).unwrap(),
        )
        .unwrap()
        .sample(&it);
        assert_eq!(
            o, lit_alone,
            "the composited colour is the shader's lit entry"
        );
        // With irradiance, or as a lighting ray, the unshaded datapath's result.
        let mut lit = it;
        lit.irr = Some([3 << 13; 8]);
        assert_eq!(s.sample(&lit), plain.sample(&lit));
        let mut light = it;
        light.lighting = true;
        assert_eq!(s.sample(&light), plain.sample(&light));
    }

    #[test]
    fn the_tag_of_the_nearest_corner_indexes_the_classification() {
        let s = shaded_sampler(8, 2, 256);
        let mut it = item(200, 0);
        it.tags = [0, 1, 2, 3, 3, 2, 1, 0];
        for (w, corner) in [
            ([0, 0, 0], 0),
            ([128, 0, 0], 1),
            ([127, 255, 0], 2),
            ([200, 200, 0], 3),
            ([0, 0, 128], 4),
            ([255, 0, 255], 5),
            ([0, 255, 255], 6),
            ([255, 255, 255], 7),
        ] {
            it.weights = w;
            assert_eq!(nearest_corner(w), corner);
            let si = s.shader_in(&it);
            assert_eq!(si.mag, it.tags[corner]);
            let idx = s.shader().class_index(&si);
            assert_eq!(
                idx & 3,
                it.tags[corner] as usize,
                "the tag's bits under the density"
            );
        }
    }

    /// One shaded step against the f64 reference (the gradient in reals, the map's exact face
    /// coordinates and bilinear sums): the measured error, and a bound on it.
    #[test]
    fn one_shaded_step_against_its_f64_reference() {
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(23);
        for voxel_w in [4, 12] {
            let s = shaded_sampler(voxel_w, 0, 256);
            let rtl = SampleRtlConfig {
                voxel_w,
                shade: 1,
                ..SampleRtlConfig::DEFAULT
            };
            let (mut worst, mut sq, mut n) = (0.0f64, 0.0, 0u32);
            for _ in 0..50_000 {
                let mut it = random_sample_for(&mut rng, rtl);
                it.lighting = false;
                it.irr = None;
                it.opacity = 0;
                it.color = [0; 3];
                let o = s.sample(&it);
                let r = s.reference(&it);
                for (&got, &want) in o.color.iter().zip(&r) {
                    let e = f64::from(got) - want;
                    worst = worst.max(e.abs());
                    sq += e * e;
                    n += 1;
                }
            }
            let rms = (sq / f64::from(n)).sqrt();
            eprintln!("shaded step, VoxelW {voxel_w}: max {worst:.2} RMS {rms:.3} (U(0.12) LSB)");
            // An 8-bit colour code is 16 LSB of the packet: its rounding (half a code), the
            // map's face-coordinate rounding and the gradient's (a step of `2^-Fg` turns a
            // short gradient most) measured at most 1.6 codes (22.8 and 25.2 LSB at VoxelW 4
            // and 12, RMS 1.5 and 1.6 LSB): bounded at 2 codes and a quarter code RMS.
            assert!(rms < 4.0 && worst <= 32.0, "{voxel_w}: {worst} {rms}");
        }
    }
}
