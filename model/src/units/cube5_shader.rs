//! The shader (`cube5_shader`), written from `docs/numerics/shader.md`: classification by a LUT
//! (density, or density and gradient magnitude, to RGBA) and illumination by a reflectance map of
//! six cube faces indexed by the gradient direction, interpolated bilinearly (patent [45], [354],
//! [383]). The tables are built here, in one place (`ClassLut`, `ReflectanceMap::from_lights`), and
//! reach the RTL as configuration-port writes (`ShaderTables::config_writes`).

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::transfer::TransferFunction;
use crate::unit::StreamCodec;
use glam::DVec3;

/// Widths of one `cube5_shader` configuration (the RTL parameters of the same names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShaderConfig {
    pub voxel_w: u32,
    pub frac_w: u32,
    pub class_idx_w: u32,
    pub mag_idx_w: u32,
    pub mag_shift: u32,
    pub color_w: u32,
    pub alpha_w: u32,
    pub rm_log2: u32,
    pub rm_frac_w: u32,
    pub diff_w: u32,
    pub spec_w: u32,
    /// Register stages for clock rate: 0, or 1 (the decode in three stages and the output's
    /// products in a register of their own: three cycles more latency, the same bits).
    pub pipe: u32,
}

impl ShaderConfig {
    /// `v8` in the contract's table.
    pub const NARROW: Self = Self {
        voxel_w: 8,
        frac_w: 2,
        class_idx_w: 8,
        mag_idx_w: 2,
        mag_shift: 6,
        color_w: 5,
        alpha_w: 8,
        rm_log2: 2,
        rm_frac_w: 3,
        diff_w: 6,
        spec_w: 5,
        pipe: 0,
    };
    /// `v12`: VolumePro's 4096-entry 8-8-8-12 table on the U(12.4) sample, 8x8-cell faces.
    pub const DEFAULT: Self = Self {
        voxel_w: 12,
        frac_w: 4,
        class_idx_w: 12,
        mag_idx_w: 4,
        mag_shift: 10,
        color_w: 8,
        alpha_w: 12,
        rm_log2: 3,
        rm_frac_w: 4,
        diff_w: 9,
        spec_w: 8,
        pipe: 0,
    };

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("shader: {what}")));
        let range = |name: &str, v: u32, lo: u32, hi: u32| {
            if (lo..=hi).contains(&v) {
                Ok(())
            } else {
                bad(format!("{name} {v} outside {lo}..={hi}"))
            }
        };
        range("VoxelW", self.voxel_w, 4, 16)?;
        range("FracW", self.frac_w, 0, 8)?;
        range("ClassIdxW", self.class_idx_w, 2, 12.min(self.sample_w()))?;
        range("MagIdxW", self.mag_idx_w, 1, self.class_idx_w - 1)?;
        range("MagShift", self.mag_shift, 0, self.grad_w() - 1)?;
        range("ColorW", self.color_w, 1, 12)?;
        range("AlphaW", self.alpha_w, 1, 16)?;
        range("RmLog2", self.rm_log2, 1, 7)?;
        range("RmFracW", self.rm_frac_w, 1, 8)?;
        range("DiffW", self.diff_w, 2, 12)?;
        range("SpecW", self.spec_w, 1, 12)?;
        range("Pipe", self.pipe, 0, 1)?;
        Ok(())
    }

    /// `U(VoxelW.FracW)` sample width.
    pub fn sample_w(&self) -> u32 {
        self.voxel_w + self.frac_w
    }

    /// `S(VoxelW+2 . FracW)` gradient component width (and the magnitude's, unsigned).
    pub fn grad_w(&self) -> u32 {
        self.voxel_w + 2 + self.frac_w
    }

    pub fn sample_max(&self) -> u32 {
        (1 << self.sample_w()) - 1
    }

    /// Largest gradient component; the smallest is `-grad_max() - 1`.
    pub fn grad_max(&self) -> i32 {
        (1 << (self.grad_w() - 1)) - 1
    }

    pub fn mag_max(&self) -> u32 {
        (1 << self.grad_w()) - 1
    }

    pub fn class_entries(&self) -> usize {
        1 << self.class_idx_w
    }

    /// Texels per face side, `2^RmLog2 + 1`.
    pub fn rm_side(&self) -> usize {
        (1 << self.rm_log2) + 1
    }

    /// Texels in the map (six faces), not counting the zero-gradient entry.
    pub fn rm_texels(&self) -> usize {
        6 * self.rm_side() * self.rm_side()
    }

    /// Quotient bits of a face coordinate, `QW = RmLog2 + RmFracW + 1`.
    pub fn quotient_w(&self) -> u32 {
        self.rm_log2 + self.rm_frac_w + 1
    }

    /// Cycles from an input transfer to its output when never stalled.
    pub fn latency(&self) -> u64 {
        9 + u64::from(self.quotient_w()) + 3 * u64::from(self.pipe)
    }

    pub fn color_max(&self) -> u32 {
        (1 << self.color_w) - 1
    }

    pub fn alpha_max(&self) -> u32 {
        (1 << self.alpha_w) - 1
    }

    pub fn diff_max(&self) -> u32 {
        (1 << self.diff_w) - 1
    }

    pub fn spec_max(&self) -> u32 {
        (1 << self.spec_w) - 1
    }

    /// Configuration address width, `2 + max(ClassIdxW, 3 + 2 (RmLog2 + 1))`.
    pub fn cfg_addr_w(&self) -> u32 {
        2 + self.class_idx_w.max(3 + 2 * (self.rm_log2 + 1))
    }

    /// Configuration data width, `max(3 ColorW + AlphaW, DiffW + SpecW)`.
    pub fn cfg_data_w(&self) -> u32 {
        (3 * self.color_w + self.alpha_w).max(self.diff_w + self.spec_w)
    }

    fn region(&self, r: u32) -> u32 {
        r << (self.cfg_addr_w() - 2)
    }

    /// Configuration address of classification entry `idx` (region 0).
    pub fn class_addr(&self, idx: usize) -> u32 {
        self.region(0) | idx as u32
    }

    /// Configuration address of texel `(face, i, j)` (region 1).
    pub fn texel_addr(&self, face: usize, i: usize, j: usize) -> u32 {
        let k1 = self.rm_log2 + 1;
        self.region(1) | (face as u32) << (2 * k1) | (j as u32) << k1 | i as u32
    }

    /// Configuration address of the zero-gradient entry (region 2, offset 0).
    pub fn zero_addr(&self) -> u32 {
        self.region(2)
    }
}

/// One classification entry, or one shaded output: `U(0.ColorW)` colours and an `AlphaW` alpha.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Rgba {
    pub r: u32,
    pub g: u32,
    pub b: u32,
    pub a: u32,
}

impl Rgba {
    fn fits(&self, cfg: &ShaderConfig) -> bool {
        [self.r, self.g, self.b]
            .iter()
            .all(|&c| c <= cfg.color_max())
            && self.a <= cfg.alpha_max()
    }

    fn pack(&self, cfg: &ShaderConfig) -> BitWriter {
        let mut w = BitWriter::new();
        for c in [self.r, self.g, self.b] {
            w.put(u64::from(c), cfg.color_w);
        }
        w.put(u64::from(self.a), cfg.alpha_w);
        w
    }
}

/// One reflectance-map texel: diffuse `U(1.(DiffW-1))` and specular `U(0.SpecW)` intensities.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Texel {
    pub d: u32,
    pub sp: u32,
}

impl Texel {
    fn fits(&self, cfg: &ShaderConfig) -> bool {
        self.d <= cfg.diff_max() && self.sp <= cfg.spec_max()
    }

    fn pack(&self, cfg: &ShaderConfig) -> BitWriter {
        let mut w = BitWriter::new();
        w.put(u64::from(self.d), cfg.diff_w);
        w.put(u64::from(self.sp), cfg.spec_w);
        w
    }

    /// Quantizes intensities (diffuse in `[0, 2)`, specular in `[0, 1)`, saturating above) to the
    /// texel formats, rounding half up.
    pub fn quantize(cfg: &ShaderConfig, diffuse: f64, specular: f64) -> Self {
        let q = |x: f64, frac: u32, max: u32| -> u32 {
            let v = (x.max(0.0) * f64::from(1u32 << frac) + 0.5).floor();
            if v >= f64::from(max) {
                max
            } else {
                v as u32
            }
        };
        Self {
            d: q(diffuse, cfg.diff_w - 1, cfg.diff_max()),
            sp: q(specular, cfg.spec_w, cfg.spec_max()),
        }
    }
}

/// The classification LUT: `2^ClassIdxW` entries.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ClassLut {
    entries: Vec<Rgba>,
}

impl ClassLut {
    /// Entry `idx` is `f(idx)`; an entry wider than the formats is an error.
    pub fn from_fn(cfg: &ShaderConfig, mut f: impl FnMut(usize) -> Rgba) -> Result<Self> {
        cfg.validate()?;
        let entries: Vec<Rgba> = (0..cfg.class_entries()).map(&mut f).collect();
        if let Some((i, e)) = entries.iter().enumerate().find(|(_, e)| !e.fits(cfg)) {
            return Err(ModelError::Config(format!(
                "shader: classification entry {i} {e:?} does not fit ColorW {} / AlphaW {}",
                cfg.color_w, cfg.alpha_w
            )));
        }
        Ok(Self { entries })
    }

    /// A 1-D table from a transfer function: entry `idx` is the function at the centre of its
    /// density bin, each channel rounded to the nearest code.
    pub fn from_transfer(cfg: &ShaderConfig, tf: &TransferFunction) -> Result<Self> {
        tf.validate()?;
        let n = cfg.class_entries() as f64;
        let q = |x: f64, max: u32| (x.clamp(0.0, 1.0) * f64::from(max)).round() as u32;
        Self::from_fn(cfg, |idx| {
            let v = tf.lookup((idx as f64 + 0.5) / n);
            Rgba {
                r: q(v[0], cfg.color_max()),
                g: q(v[1], cfg.color_max()),
                b: q(v[2], cfg.color_max()),
                a: q(v[3], cfg.alpha_max()),
            }
        })
    }

    /// The 2-D table of boundary emphasis (docs/numerics/shader.md, "A 2-D table from a transfer
    /// function"), laid out density-major as the 2-D index reads it: entry `(den, m)` is the
    /// transfer function at the centre of density bin `den` (`DenW = ClassIdxW - MagIdxW` bits),
    /// its alpha scaled by `min(1, t_m / boundary)`, where `t_m = (m + 1/2) / 2^MagIdxW` is the
    /// centre of magnitude bin `m` as a fraction of the table's magnitude range (`2^(MagIdxW +
    /// MagShift)` raw magnitude steps; the last bin takes every larger magnitude). So homogeneous
    /// regions fade and boundaries keep their opacity. `boundary` in `(0, 1]`.
    pub fn boundary(cfg: &ShaderConfig, tf: &TransferFunction, boundary: f64) -> Result<Self> {
        tf.validate()?;
        if !(boundary > 0.0 && boundary <= 1.0) {
            return Err(ModelError::Config(format!(
                "shader: boundary {boundary} outside (0, 1]"
            )));
        }
        let den_n = f64::from(1u32 << (cfg.class_idx_w - cfg.mag_idx_w));
        let mag_n = f64::from(1u32 << cfg.mag_idx_w);
        let q = |x: f64, max: u32| (x.clamp(0.0, 1.0) * f64::from(max)).round() as u32;
        Self::from_fn(cfg, |idx| {
            let (den, m) = (idx >> cfg.mag_idx_w, idx & ((1 << cfg.mag_idx_w) - 1));
            let v = tf.lookup((den as f64 + 0.5) / den_n);
            let weight = (((m as f64 + 0.5) / mag_n) / boundary).min(1.0);
            Rgba {
                r: q(v[0], cfg.color_max()),
                g: q(v[1], cfg.color_max()),
                b: q(v[2], cfg.color_max()),
                a: q(v[3] * weight, cfg.alpha_max()),
            }
        })
    }

    pub fn entries(&self) -> &[Rgba] {
        &self.entries
    }
}

/// A distant light: the direction towards the light (any nonzero length) and its intensity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistantLight {
    pub direction: [f64; 3],
    pub intensity: f64,
}

/// Phong illumination with distant lights and a distant viewer (parallel projection).
///
/// The surface normal is `-g / |g|` (it points from dense to less dense material). With
/// `two_sided`, a normal facing away from the viewer is flipped towards it first.
#[derive(Debug, Clone, PartialEq)]
pub struct Phong {
    pub ambient: f64,
    pub diffuse: f64,
    pub specular: f64,
    pub shininess: f64,
    /// Direction towards the viewer.
    pub view: [f64; 3],
    pub two_sided: bool,
    pub lights: Vec<DistantLight>,
}

impl Phong {
    /// A key light above-left of the viewer and a weaker fill light, viewer on +z.
    pub fn two_lights() -> Self {
        Self {
            ambient: 0.2,
            diffuse: 0.7,
            specular: 0.4,
            shininess: 16.0,
            view: [0.0, 0.0, 1.0],
            two_sided: true,
            lights: vec![
                DistantLight {
                    direction: [-0.4, 0.5, 1.0],
                    intensity: 1.0,
                },
                DistantLight {
                    direction: [0.6, -0.2, 0.5],
                    intensity: 0.4,
                },
            ],
        }
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("phong: {what}")));
        let nonneg = [
            ("ambient", self.ambient),
            ("diffuse", self.diffuse),
            ("specular", self.specular),
            ("shininess", self.shininess),
        ];
        for (name, v) in nonneg {
            if !v.is_finite() || v < 0.0 {
                return bad(format!("{name} {v} must be finite and >= 0"));
            }
        }
        let dir_ok =
            |d: &[f64; 3]| d.iter().all(|c| c.is_finite()) && DVec3::from(*d).length() > 0.0;
        if !dir_ok(&self.view) {
            return bad(format!(
                "view direction {:?} must be finite and nonzero",
                self.view
            ));
        }
        for (i, l) in self.lights.iter().enumerate() {
            if !dir_ok(&l.direction) {
                return bad(format!(
                    "light {i}: direction {:?} must be finite and nonzero",
                    l.direction
                ));
            }
            if !l.intensity.is_finite() || l.intensity < 0.0 {
                return bad(format!(
                    "light {i}: intensity {} must be finite and >= 0",
                    l.intensity
                ));
            }
        }
        Ok(())
    }

    /// `(ambient + diffuse, specular)` intensities for gradient `g` (nonzero; any length).
    pub fn intensities(&self, g: [f64; 3]) -> (f64, f64) {
        let view = DVec3::from(self.view).normalize();
        let mut n = -DVec3::from(g).normalize();
        if self.two_sided && n.dot(view) < 0.0 {
            n = -n;
        }
        let mut diffuse = self.ambient;
        let mut specular = 0.0;
        for l in &self.lights {
            let dir = DVec3::from(l.direction).normalize();
            diffuse += self.diffuse * l.intensity * n.dot(dir).max(0.0);
            let half = dir + view;
            if half.length() > 0.0 {
                let nh = n.dot(half.normalize()).max(0.0);
                specular += self.specular * l.intensity * nh.powf(self.shininess);
            }
        }
        (diffuse, specular)
    }
}

/// The reflectance map: six faces of `N x N` texels, plus the zero-gradient entry.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReflectanceMap {
    side: usize,
    /// Texel `(face, i, j)` at `(face * N + j) * N + i`.
    texels: Vec<Texel>,
    zero: Texel,
}

impl ReflectanceMap {
    /// Texel `(face, i, j)` is `f(face, i, j)`; the zero-gradient entry is `zero`.
    pub fn from_fn(
        cfg: &ShaderConfig,
        mut f: impl FnMut(usize, usize, usize) -> Texel,
        zero: Texel,
    ) -> Result<Self> {
        cfg.validate()?;
        let side = cfg.rm_side();
        let mut texels = Vec::with_capacity(cfg.rm_texels());
        for face in 0..6 {
            for j in 0..side {
                for i in 0..side {
                    texels.push(f(face, i, j));
                }
            }
        }
        let bad = texels.iter().chain([&zero]).find(|t| !t.fits(cfg));
        if let Some(t) = bad {
            return Err(ModelError::Config(format!(
                "shader: texel {t:?} does not fit DiffW {} / SpecW {}",
                cfg.diff_w, cfg.spec_w
            )));
        }
        Ok(Self { side, texels, zero })
    }

    /// The gradient direction that texel `(face, i, j)` stands for (contract § Texels).
    pub fn texel_direction(cfg: &ShaderConfig, face: usize, i: usize, j: usize) -> [f64; 3] {
        let cells = f64::from(1u32 << cfg.rm_log2);
        let axis = face / 2;
        let mut g = [0.0; 3];
        g[axis] = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
        g[(axis + 1) % 3] = -1.0 + 2.0 * i as f64 / cells;
        g[(axis + 2) % 3] = -1.0 + 2.0 * j as f64 / cells;
        g
    }

    /// The map of Phong illumination with `phong`'s distant lights: each texel holds the
    /// intensities at its direction, rounded half up to the texel formats (saturating); the
    /// zero-gradient entry holds the ambient term alone.
    pub fn from_lights(cfg: &ShaderConfig, phong: &Phong) -> Result<Self> {
        phong.validate()?;
        Self::from_fn(
            cfg,
            |face, i, j| {
                let (d, s) = phong.intensities(Self::texel_direction(cfg, face, i, j));
                Texel::quantize(cfg, d, s)
            },
            Texel::quantize(cfg, phong.ambient, 0.0),
        )
    }

    #[inline]
    pub fn texel(&self, face: usize, i: usize, j: usize) -> Texel {
        self.texels[(face * self.side + j) * self.side + i]
    }

    pub fn zero(&self) -> Texel {
        self.zero
    }
}

/// Both tables of a shader.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ShaderTables {
    pub class: ClassLut,
    pub rmap: ReflectanceMap,
}

impl ShaderTables {
    /// Random tables, every field uniform over its range (so every table bit can reach the
    /// output): the classification entries in order, then the zero-gradient texel, then the
    /// reflectance map's texels. Fails only for a configuration that does not validate.
    pub fn random<R: rand::Rng + ?Sized>(cfg: &ShaderConfig, rng: &mut R) -> Result<Self> {
        let class = ClassLut::from_fn(cfg, |_| Rgba {
            r: rng.random_range(0..=cfg.color_max()),
            g: rng.random_range(0..=cfg.color_max()),
            b: rng.random_range(0..=cfg.color_max()),
            a: rng.random_range(0..=cfg.alpha_max()),
        })?;
        let mut texel = || Texel {
            d: rng.random_range(0..=cfg.diff_max()),
            sp: rng.random_range(0..=cfg.spec_max()),
        };
        let zero = texel();
        let rmap = ReflectanceMap::from_fn(cfg, |_, _, _| texel(), zero)?;
        Ok(ShaderTables { class, rmap })
    }

    /// Every configuration-port write that loads these tables (contract § Configuration port):
    /// classification entries, texels, the zero-gradient entry.
    pub fn config_writes(&self, cfg: &ShaderConfig) -> Vec<(u32, Vec<u32>)> {
        let dw = cfg.cfg_data_w();
        let word = |w: BitWriter| w.finish_padded(dw);
        let mut out = Vec::with_capacity(cfg.class_entries() + cfg.rm_texels() + 1);
        for (idx, e) in self.class.entries.iter().enumerate() {
            out.push((cfg.class_addr(idx), word(e.pack(cfg))));
        }
        let side = cfg.rm_side();
        for face in 0..6 {
            for j in 0..side {
                for i in 0..side {
                    let t = self.rmap.texel(face, i, j);
                    out.push((cfg.texel_addr(face, i, j), word(t.pack(cfg))));
                }
            }
        }
        out.push((cfg.zero_addr(), word(self.rmap.zero.pack(cfg))));
        out
    }
}

/// The per-item mode bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ShaderMode {
    /// Bit 0: classify by density and gradient magnitude.
    pub tf2d: bool,
    /// Bit 1: no illumination, the classified colour passes unchanged.
    pub unlit: bool,
}

impl ShaderMode {
    pub fn from_bits(bits: u32) -> Self {
        Self {
            tf2d: bits & 1 != 0,
            unlit: bits & 2 != 0,
        }
    }

    pub fn bits(&self) -> u32 {
        u32::from(self.tf2d) | u32::from(self.unlit) << 1
    }
}

/// One input item.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShaderIn {
    /// `U(VoxelW.FracW)`.
    pub sample: u32,
    /// `gx, gy, gz`, each `S(VoxelW+2 . FracW)`.
    pub grad: [i32; 3],
    /// `U(VoxelW+2 . FracW)`.
    pub mag: u32,
    pub mode: ShaderMode,
}

/// Where a gradient lands on the reflectance map (contract § Face and face coordinates).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaceCoord {
    pub face: usize,
    /// Rounded face coordinates `q_U`, `q_V` (`QW` bits).
    pub q: [u64; 2],
    /// Cell `(i0, j0)`.
    pub cell: [usize; 2],
    /// Weights `eu`, `ev` on the scale `2^RmFracW`.
    pub weight: [u64; 2],
}

/// Major axis, sign, and minor axes of a nonzero gradient; `None` for the zero gradient.
#[inline]
fn major_axis(g: [i64; 3]) -> Option<(usize, bool, usize, usize)> {
    let a = g.map(i64::abs);
    if a == [0, 0, 0] {
        return None;
    }
    let axis = if a[0] >= a[1] && a[0] >= a[2] {
        0
    } else if a[1] >= a[2] {
        1
    } else {
        2
    };
    Some((axis, g[axis] < 0, (axis + 1) % 3, (axis + 2) % 3))
}

/// `floor(x)` of `0 <= x < 2^32`, in operations the compiler takes in vector lanes (Rust's `as`
/// conversion saturates, which it does lane by lane): `floor(x) + 2^52` is exact in f64 (its unit
/// in the last place is 1), and the low 32 bits of its representation are `floor(x)`.
#[inline(always)]
fn floor_to_u32(x: f64) -> u32 {
    (x.floor() + (1u64 << 52) as f64).to_bits() as u32
}

/// Whether [`gather_avx2`] can index the tables with 32-bit lane offsets (its `i32` indices).
#[inline(always)]
fn gather_fits(texels: &[Texel], class: &[Rgba]) -> bool {
    let limit = (i32::MAX as usize) / 16;
    !texels.is_empty() && !class.is_empty() && texels.len() < limit && class.len() < limit
}

/// The reflectance-map texels (`d`, `sp`) of eight lanes' cells, corner `(i0, j0)` at `at[n]`
/// and the others at `+ 1`, `+ side`, `+ side + 1` (the zero texel where `zero[n]` is all ones),
/// and the class entries' colours of indices `idx[n]`: eight-lane gathers of the same words the
/// scalar loop loads. An index past a table (never: the cells and class indices are in range)
/// reads its last entry instead, so no load leaves the tables.
///
/// # Safety
/// The CPU must have AVX2; the tables meet [`gather_fits`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
#[allow(clippy::type_complexity)]
unsafe fn gather_avx2(
    texels: &[Texel],
    zero_texel: Texel,
    class: &[Rgba],
    at: &[u32; 8],
    side: usize,
    zero: &[u32; 8],
    idx: &[u32; 8],
) -> ([[u32; 8]; 4], [[u32; 8]; 4], [[u32; 8]; 3]) {
    use std::arch::x86_64::*;
    use std::mem::{offset_of, size_of};
    // SAFETY (loads and stores below): each array is 32 bytes; `loadu`/`storeu` take any
    // alignment.
    let load = |x: &[u32; 8]| unsafe { _mm256_loadu_si256(x.as_ptr().cast()) };
    let store = |v: __m256i| {
        let mut o = [0u32; 8];
        unsafe { _mm256_storeu_si256(o.as_mut_ptr().cast(), v) };
        o
    };
    let set = |x: usize| _mm256_set1_epi32(x as i32);
    // 32-bit words per entry, and each field's word within it.
    let (tw, cwords) = (size_of::<Texel>() / 4, size_of::<Rgba>() / 4);
    let word = |off: usize| off / 4;
    // The first corner's index, at most the last one whose `+ side + 1` is in the table.
    let at = _mm256_min_epu32(load(at), set(texels.len().saturating_sub(side + 2)));
    let zero = load(zero);
    let tbase = texels.as_ptr().cast::<i32>();
    let fields = [
        (word(offset_of!(Texel, d)), zero_texel.d),
        (word(offset_of!(Texel, sp)), zero_texel.sp),
    ];
    let mut out = [[[0u32; 8]; 4]; 2];
    for (k, off) in [0, 1, side, side + 1].into_iter().enumerate() {
        let ix = _mm256_mullo_epi32(_mm256_add_epi32(at, set(off)), set(tw));
        for (o, &(fw, z)) in out.iter_mut().zip(&fields) {
            // SAFETY: `ix + fw` is a word of `texels` (the index is at most the last entry's).
            let v = unsafe { _mm256_i32gather_epi32::<4>(tbase.add(fw), ix) };
            o[k] = store(_mm256_blendv_epi8(v, set(z as usize), zero));
        }
    }
    let idx = _mm256_min_epu32(load(idx), set(class.len() - 1));
    let ix = _mm256_mullo_epi32(idx, set(cwords));
    let cbase = class.as_ptr().cast::<i32>();
    let colour = [
        word(offset_of!(Rgba, r)),
        word(offset_of!(Rgba, g)),
        word(offset_of!(Rgba, b)),
    ]
    .map(|fw| {
        // SAFETY: `ix + fw` is a word of `class` (the index is at most the last entry's).
        store(unsafe { _mm256_i32gather_epi32::<4>(cbase.add(fw), ix) })
    });
    let [d, sp] = out;
    (d, sp, colour)
}

/// `rnd(x, s)`: round half up of `x / 2^s`.
#[inline]
fn rnd(x: u64, s: u32) -> u64 {
    if s == 0 {
        x
    } else {
        (x + (1 << (s - 1))) >> s
    }
}

/// The golden model of `cube5_shader`.
#[derive(Debug, Clone)]
pub struct Shader {
    cfg: ShaderConfig,
    tables: ShaderTables,
}

impl Shader {
    /// A shader with both tables loaded.
    pub fn new(cfg: ShaderConfig, tables: ShaderTables) -> Result<Self> {
        cfg.validate()?;
        let fits = tables.class.entries.len() == cfg.class_entries()
            && tables.rmap.side == cfg.rm_side()
            && tables.class.entries.iter().all(|e| e.fits(&cfg))
            && tables
                .rmap
                .texels
                .iter()
                .chain([&tables.rmap.zero])
                .all(|t| t.fits(&cfg));
        if !fits {
            return Err(ModelError::Config(
                "shader: tables were built for a different configuration".into(),
            ));
        }
        Ok(Self { cfg, tables })
    }

    /// A shader whose tables are all zero (as the RTL's are undefined until loaded).
    pub fn zeroed(cfg: ShaderConfig) -> Result<Self> {
        let class = ClassLut::from_fn(&cfg, |_| Rgba::default())?;
        let rmap = ReflectanceMap::from_fn(&cfg, |_, _, _| Texel::default(), Texel::default())?;
        Self::new(cfg, ShaderTables { class, rmap })
    }

    pub fn config(&self) -> ShaderConfig {
        self.cfg
    }

    pub fn tables(&self) -> &ShaderTables {
        &self.tables
    }

    /// One configuration-port write, decoded by the contract's address map. Returns whether it
    /// wrote anything (unmapped addresses are ignored, as in the RTL).
    pub fn write_config(&mut self, addr: u32, data: &[u32]) -> bool {
        let cfg = self.cfg;
        let aw = cfg.cfg_addr_w();
        let addr = addr & ((1 << aw) - 1);
        let region = addr >> (aw - 2);
        let off = (addr & ((1 << (aw - 2)) - 1)) as usize;
        let mut rd = BitReader::new(data);
        let texel = |rd: &mut BitReader| Texel {
            d: rd.get(cfg.diff_w) as u32,
            sp: rd.get(cfg.spec_w) as u32,
        };
        match region {
            0 if off < cfg.class_entries() => {
                let mut c = || rd.get(cfg.color_w) as u32;
                let (r, g, b) = (c(), c(), c());
                let a = rd.get(cfg.alpha_w) as u32;
                self.tables.class.entries[off] = Rgba { r, g, b, a };
                true
            }
            1 => {
                let k1 = cfg.rm_log2 + 1;
                let i = off & ((1 << k1) - 1);
                let j = (off >> k1) & ((1 << k1) - 1);
                let face = off >> (2 * k1);
                let side = cfg.rm_side();
                if face < 6 && i < side && j < side {
                    self.tables.rmap.texels[(face * side + j) * side + i] = texel(&mut rd);
                    true
                } else {
                    false
                }
            }
            2 if off == 0 => {
                self.tables.rmap.zero = texel(&mut rd);
                true
            }
            _ => false,
        }
    }

    /// Whether `shade` reads an item's gradient or magnitude: lit items do, and so does 2-D
    /// classification. When it does not, `shade` of any gradient is the classified entry.
    pub fn reads_gradient(mode: ShaderMode) -> bool {
        !mode.unlit || mode.tf2d
    }

    /// The classified entry of an item. `shade(item).a` is always its alpha (illumination leaves
    /// alpha alone), so without `tf2d` the alpha of a sample is known before its gradient.
    #[inline]
    pub fn classify(&self, item: &ShaderIn) -> Rgba {
        self.tables.class.entries[self.class_index(item)]
    }

    /// The classification index (contract § Classification).
    #[inline]
    pub fn class_index(&self, item: &ShaderIn) -> usize {
        let c = &self.cfg;
        if item.mode.tf2d {
            let den_w = c.class_idx_w - c.mag_idx_w;
            let den = item.sample >> (c.sample_w() - den_w);
            let mag = (item.mag >> c.mag_shift).min((1 << c.mag_idx_w) - 1);
            ((den << c.mag_idx_w) | mag) as usize
        } else {
            (item.sample >> (c.sample_w() - c.class_idx_w)) as usize
        }
    }

    /// Face, rounded face coordinates, cell and weights; `None` for the zero gradient.
    #[inline]
    pub fn face_coord(&self, grad: [i32; 3]) -> Option<FaceCoord> {
        let c = &self.cfg;
        let g = grad.map(i64::from);
        let (axis, negative, u, v) = major_axis(g)?;
        let m = g[axis].unsigned_abs();
        let p = c.rm_log2 + c.rm_frac_w - 1;
        let top = 1u64 << (c.rm_log2 + c.rm_frac_w);
        let mut fc = FaceCoord {
            face: 2 * axis + usize::from(negative),
            q: [0; 2],
            cell: [0; 2],
            weight: [0; 2],
        };
        for (k, minor) in [u, v].into_iter().enumerate() {
            let num = (g[minor] + m as i64) as u64; // in [0, 2m]
            let q = ((num << (p + 1)) + m) / (2 * m);
            fc.q[k] = q;
            if q == top {
                fc.cell[k] = (1 << c.rm_log2) - 1;
                fc.weight[k] = 1 << c.rm_frac_w;
            } else {
                fc.cell[k] = (q >> c.rm_frac_w) as usize;
                fc.weight[k] = q & ((1 << c.rm_frac_w) - 1);
            }
        }
        Some(fc)
    }

    /// Diffuse and specular intensity for a gradient: bilinear on the map, or the zero entry.
    #[inline]
    pub fn intensity(&self, grad: [i32; 3]) -> Texel {
        let Some(fc) = self.face_coord(grad) else {
            return self.tables.rmap.zero;
        };
        let f = self.cfg.rm_frac_w;
        let one = 1u64 << f;
        let wu = [one - fc.weight[0], fc.weight[0]];
        let wv = [one - fc.weight[1], fc.weight[1]];
        let (mut d, mut sp) = (0u64, 0u64);
        for (a, wa) in wu.iter().enumerate() {
            for (b, wb) in wv.iter().enumerate() {
                let t = self
                    .tables
                    .rmap
                    .texel(fc.face, fc.cell[0] + a, fc.cell[1] + b);
                d += u64::from(t.d) * wa * wb;
                sp += u64::from(t.sp) * wa * wb;
            }
        }
        Texel {
            d: rnd(d, 2 * f) as u32,
            sp: rnd(sp, 2 * f) as u32,
        }
    }

    /// [`Shader::shade`] of `N` lit items without 2-D classification at once (item `n`: sample
    /// `sample[n]`, gradient `(grad[0][n], grad[1][n], grad[2][n])`), their colours `[r, g, b]`
    /// as lanes; alpha is the class entry's (illumination keeps it). The same bits as `shade`,
    /// written without a data-dependent branch, in 32-bit lanes where the widths allow, so that
    /// the compiler takes the lanes together (the frame's sweep shades a row of anchors at once).
    ///
    /// Why each step is `shade`'s:
    /// - The major axis, its sign and the minor axes are `major_axis`'s, the ties as there.
    /// - A face coordinate's quotient `floor(n / d)` (`n = num 2^(p+1) + m`, `d = 2m`) is the
    ///   floor of the f64 quotient: `num <= 2m < 2^GradW <= 2^26` and `2^(p+1) <= 2^15` are exact
    ///   in f64, so is their product and `n < 2^42`; the division is correctly rounded, so an
    ///   integer quotient comes out exact, and an inexact one lies at least `1/d >= 2^-GradW`
    ///   below the next integer while its rounding error is at most `(n/d) 2^-53 <= 2^(p+1-53)`:
    ///   truncating it never moves up. The quotient is at most `2^(p+1) <= 2^15`.
    /// - `q = top` gives the last cell and the weight `2^RmFracW`: `top >> RmFracW` is one past the
    ///   last cell and `top & (2^RmFracW - 1)` is 0, so subtracting and adding the flag gives both.
    /// - The zero gradient (`m = 0`) divides by 1 instead (the lane's quotient is not used) and
    ///   reads the zero-gradient texel at all four corners: the weights sum to `2^(2 RmFracW)`,
    ///   so the rounded sum is that texel.
    /// - The bilinear sums fit 32 bits: the four weights sum to `2^(2 RmFracW) <= 2^16` and a
    ///   texel field is below `2^12`.
    /// - Illumination (`lit`) in 64 bits: `c d 2^SpecW` and `sp 2^(ColorW + DiffW - 1)` reach
    ///   `2^36`; the rounding shift `DiffW - 1 + SpecW` is at least 2.
    #[inline(always)]
    pub fn shade_lit_lanes<const N: usize>(
        &self,
        sample: &[u32; N],
        grad: &[[i32; N]; 3],
    ) -> [[u32; N]; 3] {
        // SAFETY: without `AVX2`, no requirement.
        unsafe {
            if self.lit_in_32_bits() {
                self.shade_lit_lanes_in::<N, false, false>(sample, grad)
            } else {
                self.shade_lit_lanes_in::<N, false, true>(sample, grad)
            }
        }
    }

    /// Whether illumination's sums fit 32-bit lanes (`ColorW + DiffW + SpecW < 32`): `c d
    /// 2^SpecW + sp 2^(ColorW + DiffW - 1) < 2^(ColorW + DiffW + SpecW + 1)`.
    #[inline(always)]
    pub fn lit_in_32_bits(&self) -> bool {
        self.cfg.color_w + self.cfg.diff_w + self.cfg.spec_w < 32
    }

    /// [`Shader::shade_lit_lanes`]; with `AVX2` and eight lanes, the texels and class entries are
    /// gathered by AVX2 instructions ([`gather_avx2`]: the same loads, so the same bits) instead
    /// of lane by lane (scalar stores that the vector arithmetic then reloads whole: a
    /// store-forwarding stall per row). `WIDE`: illumination in 64-bit lanes; without it the
    /// widths must allow 32 ([`Shader::lit_in_32_bits`], else a panic). A constant, so that the
    /// caller's code after it is one way, not two merged.
    ///
    /// # Safety
    /// With `AVX2`, the CPU must have AVX2.
    #[inline(always)]
    pub unsafe fn shade_lit_lanes_in<const N: usize, const AVX2: bool, const WIDE: bool>(
        &self,
        sample: &[u32; N],
        grad: &[[i32; N]; 3],
    ) -> [[u32; N]; 3] {
        let c = &self.cfg;
        let rm = &self.tables.rmap;
        let f = c.rm_frac_w;
        let p1 = c.rm_log2 + f;
        let scale = f64::from(1u32 << p1);
        let frac_mask = (1u32 << f) - 1;
        let side = rm.side as u32;
        // Per lane: the texel of the cell's corner `(i0, j0)`, the weights `eu`, `ev`, and whether
        // the gradient is zero.
        let mut at = [0u32; N];
        let mut eu = [0u32; N];
        let mut ev = [0u32; N];
        let mut zero = [false; N];
        for n in 0..N {
            let g = [grad[0][n], grad[1][n], grad[2][n]];
            let a = g.map(i32::unsigned_abs);
            let x_major = a[0] >= a[1] && a[0] >= a[2];
            let y_major = !x_major && a[1] >= a[2];
            let (axis, major, gu, gv) = if x_major {
                (0, g[0], g[1], g[2])
            } else if y_major {
                (1, g[1], g[2], g[0])
            } else {
                (2, g[2], g[0], g[1])
            };
            let m = major.unsigned_abs();
            zero[n] = m == 0;
            let d = f64::from(2 * m.max(1));
            // `num = g_minor + m` in `[0, 2m]`; the cell and the weight of its quotient.
            let cell_weight = |minor: i32| {
                let num = f64::from(minor + m as i32);
                let q = floor_to_u32((num * scale + f64::from(m as i32)) / d);
                let is_top = u32::from(q == 1 << p1);
                ((q >> f) - is_top, (q & frac_mask) + (is_top << f))
            };
            let ((i0, wu), (j0, wv)) = (cell_weight(gu), cell_weight(gv));
            let face = 2 * axis + u32::from(major < 0);
            at[n] = (face * side + j0) * side + i0;
            (eu[n], ev[n]) = (wu, wv);
        }
        // The four texels of each lane's cell and its class entry's colours, gathered (loads,
        // lane by lane), then the arithmetic on whole lanes.
        let s = side as usize;
        let corner = [0, 1, s, s + 1];
        let mut td = [[0u32; N]; 4];
        let mut tsp = [[0u32; N]; 4];
        let mut colour = [[0u32; N]; 3];
        let class = &self.tables.class.entries;
        let shift = c.sample_w() - c.class_idx_w;
        #[cfg(target_arch = "x86_64")]
        if AVX2 && N == 8 && gather_fits(&rm.texels, class) {
            let lanes = |x: &[u32; N]| -> [u32; 8] { x.as_slice().try_into().expect("8 lanes") };
            let zero8: [u32; 8] = std::array::from_fn(|n| 0u32.wrapping_sub(u32::from(zero[n])));
            let idx: [u32; 8] = std::array::from_fn(|n| sample[n] >> shift);
            // SAFETY: `AVX2` is set only where the CPU has it (this function's contract);
            // `gather_avx2` reads within the tables' bounds.
            let (d8, sp8, c8) =
                unsafe { gather_avx2(&rm.texels, rm.zero, class, &lanes(&at), s, &zero8, &idx) };
            for k in 0..4 {
                td[k].copy_from_slice(&d8[k][..N]);
                tsp[k].copy_from_slice(&sp8[k][..N]);
            }
            for ch in 0..3 {
                colour[ch].copy_from_slice(&c8[ch][..N]);
            }
            return self.lit_lanes::<N, WIDE>(&td, &tsp, &colour, &eu, &ev);
        }
        for n in 0..N {
            for (k, off) in corner.iter().enumerate() {
                let t = if zero[n] {
                    rm.zero
                } else {
                    rm.texels[at[n] as usize + off]
                };
                (td[k][n], tsp[k][n]) = (t.d, t.sp);
            }
            let e = class[(sample[n] >> shift) as usize];
            [colour[0][n], colour[1][n], colour[2][n]] = [e.r, e.g, e.b];
        }
        self.lit_lanes::<N, WIDE>(&td, &tsp, &colour, &eu, &ev)
    }

    /// The bilinear sums of the texels `td`, `tsp` (corners `(i0, j0)`, `(i0 + 1, j0)`, `(i0, j0 +
    /// 1)`, `(i0 + 1, j0 + 1)`) at weights `eu`, `ev`, and the class colours lit by them
    /// ([`Shader::shade_lit_lanes`]'s arithmetic, on whole lanes).
    #[inline(always)]
    fn lit_lanes<const N: usize, const WIDE: bool>(
        &self,
        td: &[[u32; N]; 4],
        tsp: &[[u32; N]; 4],
        colour: &[[u32; N]; 3],
        eu: &[u32; N],
        ev: &[u32; N],
    ) -> [[u32; N]; 3] {
        let c = &self.cfg;
        let f = c.rm_frac_w;
        let one = 1u32 << f;
        let half = 1u32 << (2 * f - 1);
        let (mut d, mut sp) = ([0u32; N], [0u32; N]);
        for n in 0..N {
            let (eu, ev) = (eu[n], ev[n]);
            let w = [
                (one - eu) * (one - ev),
                eu * (one - ev),
                (one - eu) * ev,
                eu * ev,
            ];
            let (mut dsum, mut spsum) = (0u32, 0u32);
            for k in 0..4 {
                dsum += td[k][n] * w[k];
                spsum += tsp[k][n] * w[k];
            }
            (d[n], sp[n]) = ((dsum + half) >> (2 * f), (spsum + half) >> (2 * f));
        }
        let (cw, dw, sw) = (c.color_w, c.diff_w, c.spec_w);
        let (lit_half, lit_shift) = (1u64 << (dw + sw - 2), dw - 1 + sw);
        let mut rgb = [[0u32; N]; 3];
        if !WIDE {
            assert!(self.lit_in_32_bits(), "shade_lit_lanes_in: 64-bit widths");
            // `c d 2^SpecW + sp 2^(ColorW + DiffW - 1) < 2^(ColorW + DiffW + SpecW + 1)`: 32 bits.
            for ch in 0..3 {
                for n in 0..N {
                    let sum = ((colour[ch][n] * d[n]) << sw) + (sp[n] << (cw + dw - 1));
                    rgb[ch][n] = ((sum + lit_half as u32) >> lit_shift).min(c.color_max());
                }
            }
        } else {
            for ch in 0..3 {
                for n in 0..N {
                    let specular = u64::from(sp[n]) << (cw + dw - 1);
                    let sum = (u64::from(colour[ch][n] * d[n]) << sw) + specular;
                    let out = ((sum + lit_half) >> lit_shift).min(u64::from(c.color_max()));
                    rgb[ch][n] = out as u32;
                }
            }
        }
        rgb
    }

    /// The classified entry `e` lit by the intensities `t`: `c d + sp` per channel, rounded and
    /// saturated (contract § Illumination); alpha unchanged.
    #[inline(always)]
    fn lit(&self, e: Rgba, t: Texel) -> Rgba {
        let c = &self.cfg;
        let (cw, dw, sw) = (c.color_w, c.diff_w, c.spec_w);
        let lit = |ch: u32| -> u32 {
            let sum = ((u64::from(ch) * u64::from(t.d)) << sw) + (u64::from(t.sp) << (cw + dw - 1));
            rnd(sum, dw - 1 + sw).min(u64::from(c.color_max())) as u32
        };
        Rgba {
            r: lit(e.r),
            g: lit(e.g),
            b: lit(e.b),
            a: e.a,
        }
    }

    /// One shaded sample. Always inlined: at a call site with a constant mode (the frame's sweep)
    /// the classification's 2-D branch and the unlit return fold away.
    #[inline(always)]
    pub fn shade(&self, item: &ShaderIn) -> Rgba {
        let e = self.classify(item);
        if item.mode.unlit {
            return e;
        }
        self.lit(e, self.intensity(item.grad))
    }

    /// The colour `c * d + sp` of one channel in output LSBs, saturated, from real intensities.
    fn light_f64(&self, ch: u32, d: f64, sp: f64) -> f64 {
        let out = f64::from(ch) * d + sp * f64::from(1u32 << self.cfg.color_w);
        out.clamp(0.0, f64::from(self.cfg.color_max()))
    }

    /// The f64 reference with the same tables: exact face coordinates `g_U / m`, exact bilinear
    /// weights and sums, exact `c * d + sp`, saturated; `r, g, b` in output LSBs.
    pub fn reference_exact(&self, item: &ShaderIn) -> [f64; 3] {
        let c = &self.cfg;
        let e = self.tables.class.entries[self.class_index(item)];
        let rgb = [e.r, e.g, e.b];
        if item.mode.unlit {
            return rgb.map(f64::from);
        }
        let dscale = f64::from(1u32 << (c.diff_w - 1));
        let sscale = f64::from(1u32 << c.spec_w);
        let g = item.grad.map(i64::from);
        let (d, sp) = match major_axis(g) {
            None => {
                let z = self.tables.rmap.zero;
                (f64::from(z.d) / dscale, f64::from(z.sp) / sscale)
            }
            Some((axis, negative, u, v)) => {
                let m = g[axis].abs() as f64;
                let face = 2 * axis + usize::from(negative);
                let cells = f64::from(1u32 << c.rm_log2);
                let pos = |minor: usize| {
                    let s = (g[minor] as f64 / m + 1.0) / 2.0 * cells;
                    let i0 = s.floor().min(cells - 1.0);
                    (i0 as usize, s - i0)
                };
                let ((i0, fu), (j0, fv)) = (pos(u), pos(v));
                let (mut d, mut sp) = (0.0, 0.0);
                for (a, wa) in [1.0 - fu, fu].into_iter().enumerate() {
                    for (b, wb) in [1.0 - fv, fv].into_iter().enumerate() {
                        let t = self.tables.rmap.texel(face, i0 + a, j0 + b);
                        d += f64::from(t.d) * wa * wb;
                        sp += f64::from(t.sp) * wa * wb;
                    }
                }
                (d / dscale, sp / sscale)
            }
        };
        rgb.map(|ch| self.light_f64(ch, d, sp))
    }

    /// Direct f64 Phong with `phong`'s lights at the exact gradient direction (no map, no
    /// quantization of intensities); the zero gradient gets the ambient term alone, as the map's
    /// zero entry. `r, g, b` in output LSBs. This measures the reflectance-map approach itself.
    pub fn reference_phong(&self, item: &ShaderIn, phong: &Phong) -> [f64; 3] {
        let e = self.tables.class.entries[self.class_index(item)];
        let rgb = [e.r, e.g, e.b];
        if item.mode.unlit {
            return rgb.map(f64::from);
        }
        let (d, sp) = if item.grad == [0, 0, 0] {
            (phong.ambient, 0.0)
        } else {
            phong.intensities(item.grad.map(f64::from))
        };
        rgb.map(|ch| self.light_f64(ch, d, sp))
    }
}

// Reset leaves the tables alone (contract § Configuration port): the default no-op.
crate::item_by_item!(Shader, ShaderIn => Rgba, |unit, item| unit.shade(item));

impl StreamCodec for ShaderConfig {
    type In = ShaderIn;
    type Out = Rgba;

    fn in_width(&self) -> u32 {
        self.sample_w() + 4 * self.grad_w() + 2
    }

    fn out_width(&self) -> u32 {
        3 * self.color_w + self.alpha_w
    }

    fn pack_in(&self, item: &ShaderIn) -> Vec<u32> {
        let gw = self.grad_w();
        let mut w = BitWriter::new();
        w.put(u64::from(item.sample), self.sample_w());
        for g in item.grad {
            w.put((g as i64 as u64) & ((1 << gw) - 1), gw);
        }
        w.put(u64::from(item.mag), gw);
        w.put(u64::from(item.mode.bits()), 2);
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> Rgba {
        let mut r = BitReader::new(words);
        let mut c = || r.get(self.color_w) as u32;
        let (red, green, blue) = (c(), c(), c());
        Rgba {
            r: red,
            g: green,
            b: blue,
            a: r.get(self.alpha_w) as u32,
        }
    }
}

// The RTL parameters of this unit (the RTL defaults are the model's `DEFAULT`).
crate::unit_config!(ShaderConfig, "cube5_shader", DEFAULT, {
    "VoxelW" => voxel_w,
    "FracW" => frac_w,
    "ClassIdxW" => class_idx_w,
    "MagIdxW" => mag_idx_w,
    "MagShift" => mag_shift,
    "ColorW" => color_w,
    "AlphaW" => alpha_w,
    "RmLog2" => rm_log2,
    "RmFracW" => rm_frac_w,
    "DiffW" => diff_w,
    "SpecW" => spec_w,
    "Pipe" => pipe,
});

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const CONFIGS: [ShaderConfig; 2] = [ShaderConfig::NARROW, ShaderConfig::DEFAULT];

    fn random_item(cfg: &ShaderConfig, rng: &mut ChaCha8Rng) -> ShaderIn {
        let gmax = cfg.grad_max();
        // Mixed magnitudes: full range, and small gradients where rounding matters most.
        let lim = if rng.random_bool(0.5) {
            gmax
        } else {
            rng.random_range(0..=8)
        };
        ShaderIn {
            sample: rng.random_range(0..=cfg.sample_max()),
            grad: std::array::from_fn(|_| rng.random_range(-lim - 1..=lim)),
            mag: rng.random_range(0..=cfg.mag_max()),
            mode: ShaderMode::from_bits(rng.random_range(0..4)),
        }
    }

    fn lit_tables(cfg: &ShaderConfig) -> ShaderTables {
        let class = ClassLut::from_transfer(cfg, &TransferFunction::head_default()).unwrap();
        let rmap = ReflectanceMap::from_lights(cfg, &Phong::two_lights()).unwrap();
        ShaderTables { class, rmap }
    }

    #[test]
    fn config_validation() {
        for c in CONFIGS {
            c.validate().unwrap();
        }
        let d = ShaderConfig::DEFAULT;
        let bad = [
            ShaderConfig { voxel_w: 3, ..d },
            ShaderConfig { frac_w: 9, ..d },
            ShaderConfig {
                class_idx_w: 13,
                ..d
            },
            ShaderConfig {
                class_idx_w: 1,
                ..d
            },
            ShaderConfig {
                voxel_w: 4,
                frac_w: 0,
                class_idx_w: 5,
                mag_idx_w: 2,
                mag_shift: 0,
                ..d
            },
            ShaderConfig { mag_idx_w: 0, ..d },
            ShaderConfig { mag_idx_w: 12, ..d },
            ShaderConfig { mag_shift: 18, ..d },
            ShaderConfig { color_w: 0, ..d },
            ShaderConfig { alpha_w: 17, ..d },
            ShaderConfig { rm_log2: 0, ..d },
            ShaderConfig { rm_log2: 8, ..d },
            ShaderConfig { rm_frac_w: 0, ..d },
            ShaderConfig { diff_w: 1, ..d },
            ShaderConfig { spec_w: 13, ..d },
        ];
        for c in bad {
            assert!(c.validate().is_err(), "{c:?} must be refused");
            assert!(Shader::zeroed(c).is_err());
        }
        // Tables of one configuration do not fit another.
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let t = ShaderTables::random(&ShaderConfig::DEFAULT, &mut rng).unwrap();
        assert!(Shader::new(ShaderConfig::NARROW, t).is_err());
        let too_wide = ClassLut::from_fn(&d, |_| Rgba {
            r: 256,
            ..Rgba::default()
        });
        assert!(too_wide.is_err());
        let mut p = Phong::two_lights();
        p.lights[0].direction = [0.0; 3];
        assert!(ReflectanceMap::from_lights(&d, &p).is_err());
        p = Phong::two_lights();
        p.shininess = f64::NAN;
        assert!(p.validate().is_err());
    }

    #[test]
    fn widths_match_contract_table() {
        let n = ShaderConfig::NARROW;
        let d = ShaderConfig::DEFAULT;
        assert_eq!((n.in_width(), n.out_width(), n.latency()), (60, 23, 15));
        assert_eq!((d.in_width(), d.out_width(), d.latency()), (90, 36, 17));
        assert_eq!((d.cfg_addr_w(), d.cfg_data_w()), (14, 36));
        assert_eq!((n.cfg_addr_w(), n.cfg_data_w()), (11, 23));
        assert_eq!((d.rm_side(), d.rm_texels()), (9, 486));
    }

    #[test]
    fn classification_index() {
        let cfg = ShaderConfig::DEFAULT;
        let s = Shader::zeroed(cfg).unwrap();
        let item = |sample, mag, tf2d| ShaderIn {
            sample,
            grad: [0; 3],
            mag,
            mode: ShaderMode { tf2d, unlit: false },
        };
        // 1-D: the 12 integer bits of the U(12.4) sample.
        assert_eq!(s.class_index(&item(0xabcd, 0, false)), 0xabc);
        assert_eq!(s.class_index(&item(0xffff, 0, false)), 0xfff);
        // 2-D: 8 density bits over 4 magnitude bits, magnitude >> 10 saturated at 15.
        assert_eq!(s.class_index(&item(0xabcd, 0, true)), 0xab0);
        assert_eq!(s.class_index(&item(0xabcd, 3 << 10, true)), 0xab3);
        assert_eq!(s.class_index(&item(0xabcd, (3 << 10) + 1023, true)), 0xab3);
        assert_eq!(s.class_index(&item(0xabcd, 16 << 10, true)), 0xabf);
        assert_eq!(s.class_index(&item(0xabcd, cfg.mag_max(), true)), 0xabf);
    }

    /// `shade_lit_lanes` (the frame's sweep) is `shade` of a lit item bit for bit, eight lanes at
    /// once and one: random tables, gradients over the full range, small ones, near-ties and the
    /// extremes (every combination of the smallest, -1, 0, 1 and the largest component), at the
    /// narrow, default and widest widths (`VoxelW` 16, `FracW` 8, `RmLog2` 7, `RmFracW` 8: the
    /// largest dividends), and the widest texels and colours (`DiffW`, `SpecW`, `ColorW` 12).
    #[test]
    fn shading_in_lanes_is_shade() {
        let widest = ShaderConfig {
            voxel_w: 16,
            frac_w: 8,
            class_idx_w: 12,
            rm_log2: 7,
            rm_frac_w: 8,
            ..ShaderConfig::DEFAULT
        };
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        let widest_texels = ShaderConfig {
            color_w: 12,
            diff_w: 12,
            spec_w: 12,
            ..widest
        };
        for cfg in [
            ShaderConfig::NARROW,
            ShaderConfig::DEFAULT,
            widest,
            widest_texels,
        ] {
            // Random tables, and every entry and texel at its largest (the widest sums).
            let (c, t) = (
                cfg.color_max(),
                Texel {
                    d: cfg.diff_max(),
                    sp: cfg.spec_max(),
                },
            );
            let full = ShaderTables {
                class: ClassLut::from_fn(&cfg, |_| Rgba {
                    r: c,
                    g: c,
                    b: c,
                    a: cfg.alpha_max(),
                })
                .unwrap(),
                rmap: ReflectanceMap::from_fn(&cfg, |_, _, _| t, t).unwrap(),
            };
            let shaders = [ShaderTables::random(&cfg, &mut rng).unwrap(), full]
                .map(|tables| Shader::new(cfg, tables).unwrap());
            let lit = ShaderMode {
                tf2d: false,
                unlit: false,
            };
            let (gmin, gmax) = (-cfg.grad_max() - 1, cfg.grad_max());
            let edges = [gmin, gmin + 1, -1, 0, 1, gmax - 1, gmax];
            let mut grads: Vec<[i32; 3]> = Vec::new();
            for &x in &edges {
                for &y in &edges {
                    for &z in &edges {
                        grads.push([x, y, z]);
                    }
                }
            }
            for _ in 0..200_000 {
                let lim = match rng.random_range(0..3) {
                    0 => gmax,
                    1 => rng.random_range(1..=64),
                    _ => 1 << rng.random_range(0..cfg.grad_w() - 1),
                };
                let mut g: [i32; 3] = std::array::from_fn(|_| rng.random_range(-lim - 1..=lim));
                if rng.random_bool(0.2) {
                    // A near-tie between the major axis and a minor one.
                    g[1] = g[0]
                        .saturating_add(rng.random_range(-1..=1))
                        .clamp(gmin, gmax);
                }
                grads.push(g);
            }
            const N: usize = 8;
            for lanes in grads.chunks(N) {
                let g: [[i32; 3]; N] = std::array::from_fn(|n| lanes[n % lanes.len()]);
                let sample: [u32; N] =
                    std::array::from_fn(|_| rng.random_range(0..=cfg.sample_max()));
                let grad: [[i32; N]; 3] = std::array::from_fn(|k| g.map(|g| g[k]));
                for s in &shaders {
                    let got = s.shade_lit_lanes(&sample, &grad);
                    for n in 0..N {
                        let want = s.shade(&ShaderIn {
                            sample: sample[n],
                            grad: g[n],
                            mag: 0,
                            mode: lit,
                        });
                        let one = s.shade_lit_lanes(&[sample[n]], &grad.map(|c| [c[n]]));
                        for (ch, w) in [want.r, want.g, want.b].into_iter().enumerate() {
                            assert_eq!(got[ch][n], w, "{cfg:?} {:?} lane {n}", g[n]);
                            assert_eq!(one[ch][0], w, "{cfg:?} {:?}", g[n]);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn faces_ties_and_extremes() {
        let cfg = ShaderConfig::DEFAULT;
        let s = Shader::zeroed(cfg).unwrap();
        let face = |g| s.face_coord(g).map(|f| f.face);
        assert_eq!(face([0, 0, 0]), None);
        assert_eq!(face([5, 0, 0]), Some(0));
        assert_eq!(face([-5, 0, 0]), Some(1));
        assert_eq!(face([0, 5, -5]), Some(2)); // tie y/z goes to y
        assert_eq!(face([-5, -5, -5]), Some(1)); // three-way tie goes to x
        assert_eq!(face([1, 2, -3]), Some(5));
        let gmin = -cfg.grad_max() - 1;
        let top = 1u64 << (cfg.rm_log2 + cfg.rm_frac_w);
        // The most negative component is a valid major axis; the far edge is q = top.
        // (1 part in 2^17 below the edge rounds to the edge.)
        let fc = s.face_coord([gmin, gmin, -gmin - 1]).unwrap();
        assert_eq!(fc.face, 1);
        assert_eq!(fc.q, [0, top]);
        assert_eq!(fc.cell, [0, (1 << cfg.rm_log2) - 1]);
        assert_eq!(fc.weight, [0, 1 << cfg.rm_frac_w]);
        let fc = s.face_coord([7, 7, -7]).unwrap();
        assert_eq!((fc.face, fc.q), (0, [top, 0]));
        assert_eq!(fc.cell, [(1 << cfg.rm_log2) - 1, 0]);
        assert_eq!(fc.weight, [1 << cfg.rm_frac_w, 0]);
        // The centre of a face.
        let fc = s.face_coord([0, 0, 9]).unwrap();
        assert_eq!((fc.face, fc.q), (4, [top / 2, top / 2]));
        // Major z: U = x, V = y. q = rnd((g + m) * 2^P / m) with P = 6: 3 * 64 / 3 = 64 and
        // 4 * 64 / 3 = 85.33 -> 85.
        let fc = s.face_coord([0, 1, 3]).unwrap();
        assert_eq!(fc.q, [64, 85]);
        // 5 * 64 / 6 = 53.33 -> 53 and 7 * 64 / 6 = 74.67 -> 75 (U = z, V = x for major y).
        let fc = s.face_coord([1, -6, -1]).unwrap();
        assert_eq!((fc.face, fc.q), (3, [53, 75]));
    }

    #[test]
    fn zero_gradient_unlit_and_saturation() {
        for cfg in CONFIGS {
            let mut rng = ChaCha8Rng::seed_from_u64(3);
            let mut t = ShaderTables::random(&cfg, &mut rng).unwrap();
            let idx = 5;
            let e = Rgba {
                r: cfg.color_max(),
                g: 0,
                b: 1,
                a: cfg.alpha_max(),
            };
            t.class.entries[idx] = e;
            let one = 1 << (cfg.diff_w - 1);
            t.rmap.zero = Texel { d: one, sp: 0 };
            let s = Shader::new(cfg, t.clone()).unwrap();
            let sample = (idx as u32) << (cfg.sample_w() - cfg.class_idx_w);
            let mut item = ShaderIn {
                sample,
                grad: [0; 3],
                mag: 0,
                mode: ShaderMode::default(),
            };
            // Zero gradient with the zero entry at 1.0 and no specular: colour unchanged.
            assert_eq!(s.shade(&item), e);
            // Unlit: the classified entry, whatever the gradient.
            item.mode.unlit = true;
            item.grad = [3, -100, 7];
            assert_eq!(s.shade(&item), e);
            // Everything at maximum saturates every channel; alpha passes through.
            let mut t2 = t.clone();
            t2.rmap = ReflectanceMap::from_fn(
                &cfg,
                |_, _, _| Texel {
                    d: cfg.diff_max(),
                    sp: cfg.spec_max(),
                },
                Texel::default(),
            )
            .unwrap();
            let s2 = Shader::new(cfg, t2).unwrap();
            item.mode.unlit = false;
            let out = s2.shade(&item);
            assert_eq!(out.r, cfg.color_max());
            assert_eq!(
                out.g,
                cfg.color_max(),
                "full specular alone reaches full scale"
            );
            assert_eq!(out.a, cfg.alpha_max());
            // Zero entry all zero: black.
            let mut t3 = t;
            t3.rmap.zero = Texel::default();
            let s3 = Shader::new(cfg, t3).unwrap();
            item.grad = [0; 3];
            assert_eq!(
                s3.shade(&item),
                Rgba {
                    r: 0,
                    g: 0,
                    b: 0,
                    a: e.a
                }
            );
        }
    }

    #[test]
    fn identity_map_passes_colour_exactly() {
        for cfg in CONFIGS {
            let mut rng = ChaCha8Rng::seed_from_u64(4);
            let mut t = ShaderTables::random(&cfg, &mut rng).unwrap();
            let one = Texel {
                d: 1 << (cfg.diff_w - 1),
                sp: 0,
            };
            t.rmap = ReflectanceMap::from_fn(&cfg, |_, _, _| one, one).unwrap();
            let s = Shader::new(cfg, t).unwrap();
            for _ in 0..10_000 {
                let mut item = random_item(&cfg, &mut rng);
                let lit = s.shade(&item);
                item.mode.unlit = true;
                assert_eq!(lit, s.shade(&item));
            }
        }
    }

    #[test]
    fn error_against_exact_reference_is_bounded() {
        for cfg in CONFIGS {
            let s = Shader::new(cfg, lit_tables(&cfg)).unwrap();
            let mut rng = ChaCha8Rng::seed_from_u64(5);
            // The largest difference between neighbouring texels bounds the coordinate rounding.
            let side = cfg.rm_side();
            let mut step: f64 = 0.0;
            for face in 0..6 {
                for j in 0..side {
                    for i in 0..side {
                        let t = s.tables.rmap.texel(face, i, j);
                        for (di, dj) in [(1, 0), (0, 1)] {
                            if i + di < side && j + dj < side {
                                let n = s.tables.rmap.texel(face, i + di, j + dj);
                                let c = f64::from(cfg.color_max());
                                let dd = f64::from(t.d.abs_diff(n.d)) * c
                                    / f64::from(1u32 << (cfg.diff_w - 1));
                                let ds = f64::from(t.sp.abs_diff(n.sp))
                                    * f64::from(1u32 << cfg.color_w)
                                    / f64::from(1u32 << cfg.spec_w);
                                step = step.max(dd + ds);
                            }
                        }
                    }
                }
            }
            let coord = step * 0.5 / f64::from(1u32 << cfg.rm_frac_w);
            let bound = 0.5
                + f64::from(1u32 << cfg.color_w) / f64::from(1u32 << cfg.diff_w)
                + f64::from(1u32 << cfg.color_w) / f64::from(2u32 << cfg.spec_w)
                + 2.0 * coord;
            for _ in 0..100_000 {
                let item = random_item(&cfg, &mut rng);
                let out = s.shade(&item);
                let r = s.reference_exact(&item);
                for (got, want) in [out.r, out.g, out.b].into_iter().zip(r) {
                    let err = (f64::from(got) - want).abs();
                    assert!(err <= bound + 1e-9, "{cfg:?} {item:?}: {got} vs {want}");
                }
            }
        }
    }

    #[test]
    fn constant_map_error_is_rounding_only() {
        for cfg in CONFIGS {
            let mut rng = ChaCha8Rng::seed_from_u64(6);
            let mut t = ShaderTables::random(&cfg, &mut rng).unwrap();
            let k = Texel {
                d: cfg.diff_max() / 3,
                sp: cfg.spec_max() / 5,
            };
            t.rmap = ReflectanceMap::from_fn(&cfg, |_, _, _| k, k).unwrap();
            let s = Shader::new(cfg, t).unwrap();
            for _ in 0..20_000 {
                let item = random_item(&cfg, &mut rng);
                let out = s.shade(&item);
                for (got, want) in [out.r, out.g, out.b]
                    .into_iter()
                    .zip(s.reference_exact(&item))
                {
                    assert!((f64::from(got) - want).abs() <= 0.5 + 1e-9);
                }
            }
        }
    }

    #[test]
    fn phong_map_follows_the_lights() {
        let cfg = ShaderConfig::DEFAULT;
        let phong = Phong {
            ambient: 0.25,
            diffuse: 0.5,
            specular: 0.5,
            shininess: 8.0,
            view: [0.0, 0.0, 1.0],
            two_sided: false,
            lights: vec![DistantLight {
                direction: [0.0, 0.0, 1.0],
                intensity: 1.0,
            }],
        };
        let m = ReflectanceMap::from_lights(&cfg, &phong).unwrap();
        let half = 1 << (cfg.rm_log2 - 1);
        // Gradient -z: normal +z, facing the light and the viewer: 0.25 + 0.5, specular 0.5.
        assert_eq!(m.texel(5, half, half), Texel { d: 192, sp: 128 });
        // Gradient +z: normal away from light, one-sided: ambient only.
        assert_eq!(m.texel(4, half, half), Texel { d: 64, sp: 0 });
        assert_eq!(m.zero(), Texel { d: 64, sp: 0 });
        // Shared edges of adjacent faces see the same direction.
        let n = cfg.rm_side() - 1;
        for k in 0..=n {
            // +x face, i = N-1 (u = y = +1)  ==  +y face, j = N-1 (v = x = +1), i = z.
            assert_eq!(m.texel(0, n, k), m.texel(2, k, n));
        }
        // The shader at an exact texel direction returns the texel.
        let class = ClassLut::from_fn(&cfg, |_| Rgba::default()).unwrap();
        let s = Shader::new(
            cfg,
            ShaderTables {
                class,
                rmap: m.clone(),
            },
        )
        .unwrap();
        assert_eq!(s.intensity([0, 0, -77]), m.texel(5, half, half));
        assert_eq!(s.intensity([64, 64, 64]), m.texel(0, n, n));
    }

    #[test]
    fn config_writes_load_the_model_like_direct_tables() {
        for cfg in CONFIGS {
            let mut rng = ChaCha8Rng::seed_from_u64(8);
            let tables = ShaderTables::random(&cfg, &mut rng).unwrap();
            let mut s = Shader::zeroed(cfg).unwrap();
            for (addr, data) in tables.config_writes(&cfg) {
                assert!(s.write_config(addr, &data), "address {addr:#x} is mapped");
            }
            assert_eq!(s.tables(), &tables);
            // Unmapped addresses change nothing.
            let junk = vec![u32::MAX; 2];
            let aw = cfg.cfg_addr_w();
            let k1 = cfg.rm_log2 + 1;
            for addr in [
                3 << (aw - 2),
                (3 << (aw - 2)) | 5,
                cfg.zero_addr() | 1,
                cfg.texel_addr(6, 0, 0),
                cfg.texel_addr(7, 0, 0),
                cfg.texel_addr(0, cfg.rm_side(), 0),
                cfg.texel_addr(0, 0, cfg.rm_side()),
                cfg.texel_addr(0, (1 << k1) - 1, 0),
            ] {
                assert!(
                    !s.write_config(addr, &junk),
                    "address {addr:#x} is unmapped"
                );
            }
            if cfg.class_idx_w < aw - 2 {
                assert!(!s.write_config(1 << cfg.class_idx_w, &junk));
            }
            assert_eq!(s.tables(), &tables);
        }
    }
}
