//! The GI-Cube scattering unit (`gicube_scatter`), written from `docs/numerics/gicube_scatter.md`
//! (patent [28], [380], [385]-[386]): event choice from mangled ray bits, reflection, refraction
//! with total internal reflection, isotropic scattering from a direction LUT, glossy rotation, and
//! fixed-point normalization by a LUT-seeded reciprocal square root with one Newton step.
//!
//! The unit is a pure function of its input item (no LFSR, no state): randomness comes from a hash
//! of the item's `ray_bits`. The three tables (`SEED`, `TRIG`, `ISO`) are produced here, in
//! [`ScatterTables::new`], and loaded into the RTL through its configuration port.

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::{StreamCodec, StreamUnit};

/// Widths of one `gicube_scatter` configuration (the RTL parameters of the same names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScatterConfig {
    /// `DirFracW` (`F`): direction components are `S(2.F)`.
    pub dir_frac_w: u32,
    /// `GradW`: gradient components are `S(GradW.0)`.
    pub grad_w: u32,
    /// `MatW` (`M`): fraction bits of the material fields.
    pub mat_w: u32,
    /// `AngW` (`A`): index bits of the quarter-wave trigonometry table.
    pub ang_w: u32,
    /// `IsoW` (`I`): index bits of the isotropic direction LUT.
    pub iso_w: u32,
}

impl ScatterConfig {
    /// `f8`: the narrow verified configuration (gradient of 8-bit voxels with 2 fraction bits).
    pub const NARROW: Self = Self {
        dir_frac_w: 8,
        grad_w: 15,
        mat_w: 6,
        ang_w: 6,
        iso_w: 6,
    };
    /// `f14`: the default (the ray packet's `S(2.14)` direction, gradient of `U(12.4)` samples).
    pub const DEFAULT: Self = Self {
        dir_frac_w: 14,
        grad_w: 21,
        mat_w: 8,
        ang_w: 8,
        iso_w: 8,
    };

    pub fn new(dir_frac_w: u32, grad_w: u32, mat_w: u32, ang_w: u32, iso_w: u32) -> Result<Self> {
        let cfg = Self {
            dir_frac_w,
            grad_w,
            mat_w,
            ang_w,
            iso_w,
        };
        cfg.validate()?;
        Ok(cfg)
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("gicube_scatter: {what}")));
        let check = |name: &str, v: u32, lo: u32, hi: u32| {
            if (lo..=hi).contains(&v) {
                Ok(())
            } else {
                bad(format!("{name} {v} outside {lo}..={hi}"))
            }
        };
        check("DirFracW", self.dir_frac_w, 6, 14)?;
        check("GradW", self.grad_w, 4, 24)?;
        check("MatW", self.mat_w, 4, 10)?;
        check("AngW", self.ang_w, 4, 10)?;
        check("IsoW", self.iso_w, 4, 10)?;
        if self.ang_w > 2 * self.mat_w {
            return bad(format!(
                "AngW {} exceeds 2 * MatW {}",
                self.ang_w,
                2 * self.mat_w
            ));
        }
        Ok(())
    }

    /// `F`.
    pub fn f(&self) -> u32 {
        self.dir_frac_w
    }
    /// Bits of a direction component, `S(2.F)`.
    pub fn dir_w(&self) -> u32 {
        self.dir_frac_w + 2
    }
    /// `SI`: seed table index bits.
    pub fn seed_idx_w(&self) -> u32 {
        (self.dir_frac_w + 4) / 2
    }
    /// `SF`: seed fraction bits.
    pub fn seed_frac_w(&self) -> u32 {
        self.seed_idx_w() + 2
    }
    /// `MF = NF = YF`: mantissa, Newton and result fraction bits.
    pub fn newton_frac_w(&self) -> u32 {
        self.dir_frac_w + 3
    }
    /// `2^M`, the material value 1.0.
    pub fn mat_one(&self) -> u32 {
        1 << self.mat_w
    }
    /// Largest raw value of a `U(1.M)` material field.
    pub fn mat_max(&self) -> u32 {
        (2 << self.mat_w) - 1
    }
    /// Largest raw index ratio, `U(2.M)`.
    pub fn eta_max(&self) -> u32 {
        (4 << self.mat_w) - 1
    }
    /// Most negative and most positive raw direction component.
    pub fn dir_range(&self) -> (i32, i32) {
        let h = 1i32 << (self.dir_frac_w + 1);
        (-h, h - 1)
    }
    /// Most negative and most positive raw gradient component.
    pub fn grad_range(&self) -> (i32, i32) {
        let h = 1i32 << (self.grad_w - 1);
        (-h, h - 1)
    }
    /// Width of the configuration data port, `3 (F + 2)`.
    pub fn cfg_data_w(&self) -> u32 {
        3 * self.dir_w()
    }
}

/// The event a ray undergoes (the 2-bit `event` output field).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ScatterEvent {
    Pass = 0,
    Reflect = 1,
    Refract = 2,
    Isotropic = 3,
}

impl ScatterEvent {
    pub fn from_bits(bits: u64) -> Self {
        match bits & 3 {
            0 => Self::Pass,
            1 => Self::Reflect,
            2 => Self::Refract,
            _ => Self::Isotropic,
        }
    }
}

/// One input item (raw values, formats as in the contract).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScatterIn {
    /// Ray direction, `S(2.F)` raw.
    pub dir: [i32; 3],
    /// Estimated gradient, `S(GradW.0)`.
    pub grad: [i32; 3],
    /// Reflectivity, `U(1.M)`.
    pub refl: u32,
    /// Refractivity, `U(1.M)`.
    pub refr: u32,
    /// Isotropic-scattering probability, `U(1.M)`.
    pub iso: u32,
    /// Glossiness, `U(1.M)` in units of 90 degrees.
    pub gloss: u32,
    /// Index ratio `n_incoming / n_outgoing`, `U(2.M)`.
    pub eta: u32,
    /// The ray's mangling source.
    pub ray_bits: u32,
}

/// One output item.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScatterOut {
    /// New direction, `S(2.F)` raw.
    pub dir: [i32; 3],
    pub event: ScatterEvent,
    pub tir: bool,
    pub zero_grad: bool,
    pub zero_dir: bool,
}

/// The random fields drawn from the 96-bit pool.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScatterRandoms {
    pub r1: u32,
    pub r2: u32,
    pub r3: u32,
    pub u: [u32; 4],
    pub phi: u32,
    pub iso_idx: u32,
}

/// The discrete decisions of one item, which the f64 reference shares with the fixed-point unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScatterTrace {
    pub out: ScatterOut,
    pub randoms: ScatterRandoms,
    /// The glossy angle index `theta` actually used (0 when there is no rotation).
    pub theta: u32,
    /// The folded Irwin-Hall value `h`.
    pub h: u32,
    /// The axis `i` of the perpendicular basis.
    pub axis: usize,
    /// The normal was turned (`dn > 0`).
    pub flip: bool,
}

/// `rnd(x, s)`: round half up (towards +infinity) of `x / 2^s`, for signed `x`.
pub fn rnd(x: i64, s: u32) -> i64 {
    if s == 0 {
        x
    } else {
        (x + (1i64 << (s - 1))) >> s
    }
}

/// `rndf(x) = floor(x + 1/2)`, for table generation.
fn rndf(x: f64) -> i64 {
    (x + 0.5).floor() as i64
}

/// Robert Jenkins' 32-bit integer hash (the contract's `H`).
pub fn jenkins_hash(mut a: u32) -> u32 {
    a = a.wrapping_add(0x7ed5_5d16).wrapping_add(a << 12);
    a = (a ^ 0xc761_c23c) ^ (a >> 19);
    a = a.wrapping_add(0x1656_67b1).wrapping_add(a << 5);
    a = a.wrapping_add(0xd3a2_646c) ^ (a << 9);
    a = a.wrapping_add(0xfd70_46c5).wrapping_add(a << 3);
    a = (a ^ 0xb55a_4f09) ^ (a >> 16);
    a
}

/// The 96-bit random pool `w0 + 2^32 w1 + 2^64 w2`.
pub fn random_pool(ray_bits: u32) -> u128 {
    let w0 = jenkins_hash(ray_bits);
    let w1 = jenkins_hash(ray_bits ^ 0x9e37_79b9);
    let w2 = jenkins_hash(ray_bits ^ 0x7f4a_7c15);
    u128::from(w0) | u128::from(w1) << 32 | u128::from(w2) << 64
}

/// The three loadable tables.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScatterTables {
    /// `SEED[idx]`, `U(0.SF)`, `2^SI` entries.
    pub seed: Vec<u32>,
    /// `TRIG[r] = (C, S)`, `U(1.F)` each, `2^A` entries.
    pub trig: Vec<(u32, u32)>,
    /// `ISO[n]`, `S(2.F)` each, `2^I` entries.
    pub iso: Vec<[i32; 3]>,
}

/// Configuration-port table selects (`cfg_addr_i[11:10]`).
pub const CFG_SEL_SEED: u32 = 0;
pub const CFG_SEL_TRIG: u32 = 1;
pub const CFG_SEL_ISO: u32 = 2;

impl ScatterTables {
    /// The tables of the contract, from their f64 formulas.
    pub fn new(cfg: &ScatterConfig) -> Result<Self> {
        cfg.validate()?;
        let f = cfg.f();
        let si = cfg.seed_idx_w();
        let sf = cfg.seed_frac_w();
        let quarter = f64::from(1u32 << (si - 2));
        let seed = (0..1u32 << si)
            .map(|idx| {
                if idx < 1 << (si - 2) {
                    0
                } else {
                    let lo = f64::from(idx) / quarter;
                    let hi = f64::from(idx + 1) / quarter;
                    rndf(f64::from(1u32 << sf) * 2.0 / (lo.sqrt() + hi.sqrt())) as u32
                }
            })
            .collect();
        let one = f64::from(1u32 << f);
        let trig = (0..1u32 << cfg.ang_w)
            .map(|r| {
                let a = std::f64::consts::PI * f64::from(r) / f64::from(2u32 << cfg.ang_w);
                (rndf(one * a.cos()) as u32, rndf(one * a.sin()) as u32)
            })
            .collect();
        let iso = (0..1u32 << cfg.iso_w)
            .map(|n| {
                let v = fibonacci_direction(cfg.iso_w, n);
                v.map(|x| rndf(one * x) as i32)
            })
            .collect();
        Ok(Self { seed, trig, iso })
    }

    /// The configuration-port writes that load these tables into the RTL (address, data words).
    pub fn config_writes(&self, cfg: &ScatterConfig) -> Vec<(u32, Vec<u32>)> {
        let dw = cfg.cfg_data_w();
        let fw = cfg.dir_w();
        let word = |fill: &dyn Fn(&mut BitWriter)| {
            let mut w = BitWriter::new();
            fill(&mut w);
            let used = w.len();
            w.put(0, dw - used);
            w.finish(dw)
        };
        let mut out = Vec::new();
        for (idx, &s) in self.seed.iter().enumerate() {
            out.push((
                CFG_SEL_SEED << 10 | idx as u32,
                word(&|w| {
                    w.put(u64::from(s), cfg.seed_frac_w());
                }),
            ));
        }
        for (r, &(c, s)) in self.trig.iter().enumerate() {
            out.push((
                CFG_SEL_TRIG << 10 | r as u32,
                word(&|w| {
                    w.put(u64::from(c), fw - 1);
                    w.put(u64::from(s), fw - 1);
                }),
            ));
        }
        for (n, v) in self.iso.iter().enumerate() {
            out.push((
                CFG_SEL_ISO << 10 | n as u32,
                word(&|w| {
                    for &x in v {
                        w.put(to_field(i64::from(x), fw), fw);
                    }
                }),
            ));
        }
        out
    }
}

/// Spherical Fibonacci direction `n` of `2^iso_w` (exact, f64).
pub fn fibonacci_direction(iso_w: u32, n: u32) -> [f64; 3] {
    let count = f64::from(1u32 << iso_w);
    let z = 1.0 - (2.0 * f64::from(n) + 1.0) / count;
    let rho = (1.0 - z * z).sqrt();
    let lon = f64::from(n) * std::f64::consts::PI * (3.0 - 5f64.sqrt());
    [rho * lon.cos(), rho * lon.sin(), z]
}

/// Two's complement bits of `x` in a `w`-bit field.
fn to_field(x: i64, w: u32) -> u64 {
    (x as u64) & ((1u64 << w) - 1)
}

/// Sign-extends a `w`-bit field.
fn from_field(bits: u64, w: u32) -> i32 {
    ((bits << (64 - w)) as i64 >> (64 - w)) as i32
}

/// The golden model of `gicube_scatter`.
#[derive(Debug, Clone)]
pub struct Scatter {
    cfg: ScatterConfig,
    tables: ScatterTables,
}

impl Scatter {
    /// The unit with the contract's tables.
    pub fn new(cfg: ScatterConfig) -> Result<Self> {
        let tables = ScatterTables::new(&cfg)?;
        Self::with_tables(cfg, tables)
    }

    /// The unit with given tables (sizes checked against the configuration).
    pub fn with_tables(cfg: ScatterConfig, tables: ScatterTables) -> Result<Self> {
        cfg.validate()?;
        if tables.seed.len() != 1 << cfg.seed_idx_w()
            || tables.trig.len() != 1 << cfg.ang_w
            || tables.iso.len() != 1 << cfg.iso_w
        {
            return Err(ModelError::Config(
                "gicube_scatter: table sizes do not match the configuration".into(),
            ));
        }
        Ok(Self { cfg, tables })
    }

    pub fn config(&self) -> ScatterConfig {
        self.cfg
    }

    pub fn tables(&self) -> &ScatterTables {
        &self.tables
    }

    /// `rsq(q) = (y, kk, m)` with `1/sqrt(q) ~ y 2^-(YF + kk)`.
    pub fn rsq(&self, q: u64) -> (i64, u32, i64) {
        if q == 0 {
            return (0, 0, 0);
        }
        let mf = self.cfg.newton_frac_w();
        let (nf, yf) = (mf, mf);
        let si = self.cfg.seed_idx_w();
        let sf = self.cfg.seed_frac_w();
        let p = 63 - q.leading_zeros();
        let kk = p / 2;
        let m = if mf >= 2 * kk {
            (q << (mf - 2 * kk)) as i64
        } else {
            (q >> (2 * kk - mf)) as i64
        };
        let idx = (m >> (mf + 2 - si)) as usize;
        let y0 = i64::from(self.tables.seed[idx]);
        let pp = rnd(m * y0, mf + sf - nf);
        let b = rnd(pp * y0, sf);
        let c3 = (3i64 << nf) - b;
        let y = rnd(y0 * c3, sf + nf + 1 - yf);
        (y, kk, m)
    }

    /// `normalize(V)`: `S(2.F)` components of unit length (zero for a zero vector).
    pub fn normalize(&self, v: [i64; 3]) -> [i64; 3] {
        let q: u64 = v.iter().map(|&c| (c * c) as u64).sum();
        let (y, kk, _) = self.rsq(q);
        let s = self.cfg.newton_frac_w() + kk - self.cfg.f();
        v.map(|c| rnd(c * y, s))
    }

    /// The random fields of an item.
    pub fn randoms(&self, ray_bits: u32) -> ScatterRandoms {
        let mut pool = random_pool(ray_bits);
        let mut take = |w: u32| {
            let v = (pool & ((1u128 << w) - 1)) as u32;
            pool >>= w;
            v
        };
        let m = self.cfg.mat_w;
        let r1 = take(m);
        let r2 = take(m);
        let r3 = take(m);
        let u = [take(m), take(m), take(m), take(m)];
        let phi = take(self.cfg.ang_w + 2);
        let iso_idx = take(self.cfg.iso_w);
        ScatterRandoms {
            r1,
            r2,
            r3,
            u,
            phi,
            iso_idx,
        }
    }

    /// The unit's output for one item.
    pub fn scatter(&self, item: &ScatterIn) -> ScatterOut {
        self.trace(item).out
    }

    /// The output with the decisions that the f64 reference shares.
    pub fn trace(&self, item: &ScatterIn) -> ScatterTrace {
        let cfg = &self.cfg;
        let f = cfg.f();
        let m = cfg.mat_w;
        let one = cfg.mat_one();
        let rn = self.randoms(item.ray_bits);

        // Event draw.
        let refl = item.refl.min(one);
        let refr = item.refr.min(one);
        let iso = item.iso.min(one);
        let gloss = item.gloss.min(one);
        let drawn = if rn.r1 < refl {
            ScatterEvent::Reflect
        } else if rn.r2 < refr {
            ScatterEvent::Refract
        } else if rn.r3 < iso {
            ScatterEvent::Isotropic
        } else {
            ScatterEvent::Pass
        };

        // The normal, turned to face the ray.
        let d = item.dir.map(i64::from);
        let g = item.grad.map(i64::from);
        let zero_g = g == [0; 3];
        let n = self.normalize(g);
        let dn: i64 = (0..3).map(|c| d[c] * n[c]).sum();
        let flip = dn > 0;
        let np = if flip { n.map(|x| -x) } else { n };
        let c = rnd(dn.abs(), f);

        // Reflection.
        let r: [i64; 3] = std::array::from_fn(|l| d[l] + rnd(c * np[l], f - 1));

        // Refraction.
        let e = i64::from(item.eta);
        let l2: i64 = d.iter().map(|x| x * x).sum();
        let c2 = c * c;
        let s2 = (l2 - c2).max(0);
        let t = rnd(e * e * s2, 2 * m);
        let k = l2 - t;
        let tir_cond = k < 0;
        let (y, kk, mm) = self.rsq(k.max(0) as u64);
        let sqrtk = rnd(mm * y, 2 * cfg.newton_frac_w() - kk);
        let ec = rnd(e * c, m);
        let coef = ec - sqrtk;
        let tv: [i64; 3] = std::array::from_fn(|l| rnd(e * d[l], m) + rnd(coef * np[l], f));

        // Final event.
        let mut event = drawn;
        let mut tir = false;
        let mut zero_grad = false;
        if matches!(drawn, ScatterEvent::Reflect | ScatterEvent::Refract) && zero_g {
            event = ScatterEvent::Pass;
            zero_grad = true;
        } else if drawn == ScatterEvent::Refract && tir_cond {
            event = ScatterEvent::Reflect;
            tir = true;
        }
        let ev = match event {
            ScatterEvent::Pass => d,
            ScatterEvent::Reflect => r,
            ScatterEvent::Refract => tv,
            ScatterEvent::Isotropic => self.tables.iso[rn.iso_idx as usize].map(i64::from),
        };
        let eh = self.normalize(ev);

        // Glossy angle (folded Irwin-Hall) and trigonometry.
        let s: i64 = rn.u.iter().map(|&x| i64::from(x)).sum();
        let h = (s + 2 - (2i64 << m)).abs();
        let glossy = matches!(event, ScatterEvent::Reflect | ScatterEvent::Refract);
        let theta = if glossy {
            rnd(i64::from(gloss) * h, 2 * m + 1 - cfg.ang_w).min((1i64 << cfg.ang_w) - 1)
        } else {
            0
        };
        let (ct, st) = self.tables.trig[theta as usize];
        let (ct, st) = (i64::from(ct), i64::from(st));
        let quadrant = rn.phi >> cfg.ang_w;
        let (cs, sn) = self.tables.trig[(rn.phi & ((1 << cfg.ang_w) - 1)) as usize];
        let (cs, sn) = (i64::from(cs), i64::from(sn));
        let (cp, sp) = match quadrant {
            0 => (cs, sn),
            1 => (-sn, cs),
            2 => (-cs, -sn),
            _ => (sn, -cs),
        };

        // Perpendicular basis and rotation.
        let mut axis = 0;
        for l in 1..3 {
            if eh[l].abs() < eh[axis].abs() {
                axis = l;
            }
        }
        let (i, j, kx) = (axis, (axis + 1) % 3, (axis + 2) % 3);
        let (a, b, cc) = (eh[i], eh[j], eh[kx]);
        let w = b * b + cc * cc;
        let mut u = [0i64; 3];
        let mut v = [0i64; 3];
        u[j] = -cc;
        u[kx] = b;
        v[i] = rnd(w, f);
        v[j] = rnd(-a * b, f);
        v[kx] = rnd(-a * cc, f);
        let bvec: [i64; 3] = std::array::from_fn(|l| rnd(cp * u[l] + sp * v[l], f));
        let (yw, kw, _) = self.rsq(w as u64);
        let sig = rnd(st * yw, kw + cfg.newton_frac_w() - f);
        let dp: [i64; 3] = std::array::from_fn(|l| rnd(ct * eh[l] + sig * bvec[l], f));
        let out = self.normalize(dp);

        ScatterTrace {
            out: ScatterOut {
                dir: out.map(|x| x as i32),
                event,
                tir,
                zero_grad,
                zero_dir: dp == [0; 3],
            },
            randoms: rn,
            theta: theta as u32,
            h: h as u32,
            axis,
            flip,
        }
    }

    /// The f64 reference with the unit's decisions and random numbers (contract § Error). `None`
    /// where no direction is defined (zero input direction with a non-isotropic event).
    pub fn reference(&self, item: &ScatterIn) -> Option<[f64; 3]> {
        let tr = self.trace(item);
        self.reference_for(item, &tr)
    }

    /// [`Scatter::reference`] for an already computed trace.
    pub fn reference_for(&self, item: &ScatterIn, tr: &ScatterTrace) -> Option<[f64; 3]> {
        let cfg = &self.cfg;
        let one = f64::from(cfg.mat_one());
        let unit = |v: [f64; 3]| -> Option<[f64; 3]> {
            let l = dot(v, v).sqrt();
            (l > 0.0).then(|| v.map(|x| x / l))
        };
        let event = tr.out.event;
        let e = if event == ScatterEvent::Isotropic {
            fibonacci_direction(cfg.iso_w, tr.randoms.iso_idx)
        } else {
            let d = unit(item.dir.map(f64::from))?;
            match event {
                ScatterEvent::Pass => d,
                ScatterEvent::Reflect => {
                    let n = unit(item.grad.map(f64::from))?;
                    let dn = dot(d, n);
                    std::array::from_fn(|l| d[l] - 2.0 * dn * n[l])
                }
                _ => {
                    // The unit's side of the surface (a discrete decision at grazing incidence).
                    let mut n = unit(item.grad.map(f64::from))?;
                    if tr.flip {
                        n = n.map(|x| -x);
                    }
                    let c = -dot(d, n);
                    let eta = f64::from(item.eta) / one;
                    let k = (1.0 - eta * eta * (1.0 - c * c)).max(0.0);
                    std::array::from_fn(|l| eta * d[l] + (eta * c - k.sqrt()) * n[l])
                }
            }
        };
        let eh = unit(e)?;
        let dp = if matches!(event, ScatterEvent::Reflect | ScatterEvent::Refract) {
            let gloss = f64::from(item.gloss.min(cfg.mat_one())) / one;
            let theta = std::f64::consts::FRAC_PI_2 * gloss * f64::from(tr.h)
                / f64::from(2u32 << cfg.mat_w);
            let phi = 2.0 * std::f64::consts::PI * f64::from(tr.randoms.phi)
                / f64::from(4u32 << cfg.ang_w);
            let (i, j, k) = (tr.axis, (tr.axis + 1) % 3, (tr.axis + 2) % 3);
            let (a, b, cc) = (eh[i], eh[j], eh[k]);
            let w = b * b + cc * cc;
            let mut u = [0.0; 3];
            let mut v = [0.0; 3];
            u[j] = -cc;
            u[k] = b;
            v[i] = w;
            v[j] = -a * b;
            v[k] = -a * cc;
            let sw = w.sqrt();
            std::array::from_fn(|l| {
                theta.cos() * eh[l] + theta.sin() * (phi.cos() * u[l] + phi.sin() * v[l]) / sw
            })
        } else {
            eh
        };
        unit(dp)
    }

    /// Angle in degrees between the unit's direction and the f64 reference (`None` where the
    /// reference has no direction).
    pub fn angle_error_deg(&self, item: &ScatterIn) -> Option<f64> {
        let tr = self.trace(item);
        let want = self.reference_for(item, &tr)?;
        let got = tr.out.dir.map(f64::from);
        Some(angle_deg(got, want))
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The angle between two nonzero vectors, in degrees (robust for small angles).
pub fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    dot(cross, cross).sqrt().atan2(dot(a, b)).to_degrees()
}

impl StreamUnit for Scatter {
    type In = ScatterIn;
    type Out = ScatterOut;

    fn run(&mut self, inputs: &[ScatterIn]) -> Vec<ScatterOut> {
        inputs.iter().map(|item| self.scatter(item)).collect()
    }
}

impl StreamCodec for ScatterConfig {
    type In = ScatterIn;
    type Out = ScatterOut;

    fn in_width(&self) -> u32 {
        3 * self.dir_w() + 3 * self.grad_w + 5 * self.mat_w + 6 + 32
    }

    fn out_width(&self) -> u32 {
        3 * self.dir_w() + 5
    }

    fn pack_in(&self, item: &ScatterIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        for &x in &item.dir {
            w.put(to_field(i64::from(x), self.dir_w()), self.dir_w());
        }
        for &x in &item.grad {
            w.put(to_field(i64::from(x), self.grad_w), self.grad_w);
        }
        for x in [item.refl, item.refr, item.iso, item.gloss] {
            w.put(u64::from(x), self.mat_w + 1);
        }
        w.put(u64::from(item.eta), self.mat_w + 2);
        w.put(u64::from(item.ray_bits), 32);
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> ScatterOut {
        let mut r = BitReader::new(words);
        let dir = std::array::from_fn(|_| from_field(r.get(self.dir_w()), self.dir_w()));
        let event = ScatterEvent::from_bits(r.get(2));
        ScatterOut {
            dir,
            event,
            tir: r.get_bool(),
            zero_grad: r.get_bool(),
            zero_dir: r.get_bool(),
        }
    }
}

/// A random item: directions and gradients on (and, for a quarter of the items, off) the unit
/// sphere, random materials with the extremes 0 and 1 well represented. Shared by the tests and
/// the bench so that the error figures describe the co-simulated stimulus.
pub fn random_item(cfg: &ScatterConfig, rng: &mut impl rand::Rng) -> ScatterIn {
    let f = cfg.f();
    let (dlo, dhi) = cfg.dir_range();
    let (glo, ghi) = cfg.grad_range();
    let sphere = |rng: &mut dyn rand::RngCore| -> [f64; 3] {
        loop {
            let v: [f64; 3] = std::array::from_fn(|_| rand::Rng::random_range(rng, -1.0..1.0));
            let l = dot(v, v).sqrt();
            if l > 1e-3 && l <= 1.0 {
                return v.map(|x| x / l);
            }
        }
    };
    let dir = if rng.random_bool(0.75) {
        sphere(rng).map(|x| rndf(x * f64::from(1u32 << f)) as i32)
    } else {
        std::array::from_fn(|_| rng.random_range(dlo..=dhi))
    };
    let grad = match rng.random_range(0..4) {
        0 => std::array::from_fn(|_| rng.random_range(glo..=ghi)),
        1 => {
            // Small gradients: few significant bits.
            std::array::from_fn(|_| rng.random_range(-3..=3))
        }
        _ => {
            let scale = f64::from(ghi) * rng.random_range(0.01..1.0);
            sphere(rng).map(|x| rndf(x * scale) as i32)
        }
    };
    let one = cfg.mat_one();
    let prob = |rng: &mut dyn rand::RngCore| match rand::Rng::random_range(rng, 0..8) {
        0 => 0,
        1 => one,
        2 => cfg.mat_max(),
        _ => rand::Rng::random_range(rng, 0..=one),
    };
    ScatterIn {
        dir,
        grad,
        refl: prob(rng) / 2,
        refr: prob(rng),
        iso: prob(rng),
        gloss: prob(rng),
        eta: rng.random_range(0..=cfg.eta_max()),
        ray_bits: rng.random(),
    }
}

// The RTL parameters of this unit (the RTL defaults are the model's `DEFAULT`).
crate::unit_config!(ScatterConfig, "gicube_scatter", DEFAULT, {
    "DirFracW" => dir_frac_w,
    "GradW" => grad_w,
    "MatW" => mat_w,
    "AngW" => ang_w,
    "IsoW" => iso_w,
});

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn units() -> Vec<Scatter> {
        [ScatterConfig::NARROW, ScatterConfig::DEFAULT]
            .into_iter()
            .map(|c| Scatter::new(c).unwrap())
            .collect()
    }

    fn item(cfg: &ScatterConfig, dir: [i32; 3], grad: [i32; 3]) -> ScatterIn {
        ScatterIn {
            dir,
            grad,
            refl: 0,
            refr: 0,
            iso: 0,
            gloss: 0,
            eta: cfg.mat_one(),
            ray_bits: 12345,
        }
    }

    fn unit_len(cfg: &ScatterConfig, v: [i32; 3]) -> f64 {
        v.iter()
            .map(|&x| f64::from(x) * f64::from(x))
            .sum::<f64>()
            .sqrt()
            / f64::from(1u32 << cfg.f())
    }

    #[test]
    fn config_validation() {
        assert!(ScatterConfig::new(5, 15, 6, 6, 6).is_err());
        assert!(ScatterConfig::new(15, 15, 6, 6, 6).is_err());
        assert!(ScatterConfig::new(8, 3, 6, 6, 6).is_err());
        assert!(ScatterConfig::new(8, 15, 3, 6, 6).is_err());
        assert!(ScatterConfig::new(8, 15, 4, 9, 6).is_err(), "AngW > 2 MatW");
        assert!(ScatterConfig::new(8, 15, 6, 6, 11).is_err());
        assert!(ScatterConfig::NARROW.validate().is_ok());
        assert!(ScatterConfig::DEFAULT.validate().is_ok());
        let cfg = ScatterConfig::NARROW;
        let mut t = ScatterTables::new(&cfg).unwrap();
        t.iso.pop();
        assert!(Scatter::with_tables(cfg, t).is_err());
    }

    #[test]
    fn packing_widths_match_contract_table() {
        assert_eq!(ScatterConfig::NARROW.in_width(), 143);
        assert_eq!(ScatterConfig::NARROW.out_width(), 35);
        assert_eq!(ScatterConfig::DEFAULT.in_width(), 189);
        assert_eq!(ScatterConfig::DEFAULT.out_width(), 53);
    }

    #[test]
    fn hash_known_values_and_pool_layout() {
        // H(0) computed by hand from the six steps.
        let mut a: u32 = 0x7ed5_5d16;
        a = (a ^ 0xc761_c23c) ^ (a >> 19);
        a = a.wrapping_add(0x1656_67b1).wrapping_add(a << 5);
        a = a.wrapping_add(0xd3a2_646c) ^ (a << 9);
        a = a.wrapping_add(0xfd70_46c5).wrapping_add(a << 3);
        a = (a ^ 0xb55a_4f09) ^ (a >> 16);
        assert_eq!(jenkins_hash(0), a);
        let p = random_pool(77);
        assert_eq!(p as u32, jenkins_hash(77));
        assert_eq!((p >> 64) as u32, jenkins_hash(77 ^ 0x7f4a_7c15));
    }

    #[test]
    fn rsq_relative_error_is_below_an_output_lsb() {
        for s in units() {
            let cfg = s.config();
            let yf = cfg.newton_frac_w();
            let mut worst = 0.0f64;
            let mut q = 1u64;
            while q < 1 << 48 {
                for dq in [0, 1, q / 3, q / 2, q - 1] {
                    let x = q + dq;
                    let (y, kk, _) = s.rsq(x);
                    let got = y as f64 / f64::from(1u32 << yf) / f64::from(1u32 << kk);
                    let want = 1.0 / (x as f64).sqrt();
                    worst = worst.max((got / want - 1.0).abs());
                }
                q = q * 5 / 4 + 1;
            }
            let lsb = 1.0 / f64::from(1u32 << cfg.f());
            assert!(worst < 0.5 * lsb, "{cfg:?}: rsq rel error {worst}");
        }
    }

    #[test]
    fn normalize_gives_unit_vectors() {
        for s in units() {
            let cfg = s.config();
            let mut rng = ChaCha8Rng::seed_from_u64(3);
            let lsb = 1.0 / f64::from(1u32 << cfg.f());
            for _ in 0..20_000 {
                let bits = rng.random_range(1..=cfg.grad_w);
                let h = 1i64 << (bits - 1);
                let v: [i64; 3] = std::array::from_fn(|_| rng.random_range(-h..h));
                if v == [0; 3] {
                    assert_eq!(s.normalize(v), [0; 3]);
                    continue;
                }
                let n = s.normalize(v).map(|x| x as i32);
                let len = unit_len(&cfg, n);
                assert!((len - 1.0).abs() < 2.0 * lsb, "{v:?} -> {n:?} length {len}");
            }
        }
    }

    #[test]
    fn zero_gradient_passes_with_flag() {
        for s in units() {
            let cfg = s.config();
            let one = 1i32 << cfg.f();
            for (refl, refr) in [(cfg.mat_one(), 0), (0, cfg.mat_one())] {
                let it = ScatterIn {
                    refl,
                    refr,
                    gloss: cfg.mat_one(),
                    ..item(&cfg, [one, 0, 0], [0, 0, 0])
                };
                let o = s.scatter(&it);
                assert_eq!(o.event, ScatterEvent::Pass);
                assert!(o.zero_grad && !o.tir && !o.zero_dir);
                assert_eq!(o.dir, [one, 0, 0], "a pass is not made glossy");
            }
        }
    }

    #[test]
    fn zero_direction_is_flagged_unless_isotropic() {
        for s in units() {
            let cfg = s.config();
            let o = s.scatter(&ScatterIn {
                refl: cfg.mat_one(),
                ..item(&cfg, [0; 3], [1, 2, 3])
            });
            assert!(o.zero_dir);
            assert_eq!(o.dir, [0; 3]);
            let o = s.scatter(&ScatterIn {
                iso: cfg.mat_one(),
                ..item(&cfg, [0; 3], [1, 2, 3])
            });
            assert_eq!(o.event, ScatterEvent::Isotropic);
            assert!(!o.zero_dir);
        }
    }

    #[test]
    fn axis_directions_reflect_and_pass_exactly() {
        for s in units() {
            let cfg = s.config();
            let one = 1i32 << cfg.f();
            let g = cfg.grad_range().1;
            for axis in 0..3 {
                for sign in [1, -1] {
                    let mut d = [0; 3];
                    d[axis] = sign * one;
                    let mut n = [0; 3];
                    n[axis] = g;
                    let pass = s.scatter(&item(&cfg, d, n));
                    assert_eq!(pass.event, ScatterEvent::Pass);
                    assert_eq!(pass.dir, d);
                    let refl = s.scatter(&ScatterIn {
                        refl: cfg.mat_one(),
                        ..item(&cfg, d, n)
                    });
                    assert_eq!(refl.event, ScatterEvent::Reflect);
                    assert_eq!(refl.dir, d.map(|x| -x), "normal incidence reflects back");
                    // eta 1: refraction goes straight through.
                    let refr = s.scatter(&ScatterIn {
                        refr: cfg.mat_one(),
                        ..item(&cfg, d, n)
                    });
                    assert_eq!(refr.event, ScatterEvent::Refract);
                    assert_eq!(refr.dir, d);
                }
            }
        }
    }

    #[test]
    fn total_internal_reflection_falls_back_to_reflection() {
        for s in units() {
            let cfg = s.config();
            let one = f64::from(1u32 << cfg.f());
            // 60 degrees incidence, eta 1.5: sin = 0.866 * 1.5 > 1.
            let d = [0.866f64, -0.5, 0.0].map(|x| rndf(x * one) as i32);
            let it = ScatterIn {
                refr: cfg.mat_one(),
                eta: cfg.mat_one() * 3 / 2,
                ..item(&cfg, d, [0, 1000, 0])
            };
            let o = s.scatter(&it);
            assert!(o.tir);
            assert_eq!(o.event, ScatterEvent::Reflect);
            let refl = s.scatter(&ScatterIn {
                refl: cfg.mat_one(),
                refr: 0,
                ..it
            });
            assert_eq!(o.dir, refl.dir, "TIR is exactly the reflection");
            // eta 1/1.5 at the same angle refracts, bending towards the surface.
            let o = s.scatter(&ScatterIn {
                eta: cfg.mat_one() * 2 / 3,
                ..it
            });
            assert_eq!(o.event, ScatterEvent::Refract);
            assert!(!o.tir);
            assert!(s.angle_error_deg(&it).unwrap() < 0.5);
        }
    }

    #[test]
    fn grazing_incidence() {
        for s in units() {
            let cfg = s.config();
            let one = f64::from(1u32 << cfg.f());
            let tiny = 1.0 / one;
            let d = [1.0, -tiny, 0.0].map(|x| rndf(x * one) as i32);
            for (refl, refr, eta) in [
                (cfg.mat_one(), 0, cfg.mat_one()),
                (0, cfg.mat_one(), cfg.mat_one() / 2),
                (0, cfg.mat_one(), cfg.mat_one() * 2),
            ] {
                let it = ScatterIn {
                    refl,
                    refr,
                    eta,
                    ..item(&cfg, d, [0, 5000, 3])
                };
                let o = s.scatter(&it);
                let len = unit_len(&cfg, o.dir);
                assert!((len - 1.0).abs() < 4.0 / one, "{o:?}");
                let err = s.angle_error_deg(&it).unwrap();
                assert!(err < 2.0, "grazing {it:?}: {err} degrees");
            }
        }
    }

    #[test]
    fn glossiness_zero_and_ninety() {
        for s in units() {
            let cfg = s.config();
            let one = 1i32 << cfg.f();
            let mut rng = ChaCha8Rng::seed_from_u64(5);
            let mut max_angle = 0.0f64;
            for _ in 0..2000 {
                let d = [one, 0, 0];
                let base = ScatterIn {
                    refl: cfg.mat_one(),
                    ray_bits: rng.random(),
                    ..item(&cfg, [one, 0, 0], [-1000, 0, 0])
                };
                let sharp = s.scatter(&base);
                assert_eq!(sharp.dir, d.map(|x| -x), "gloss 0: exact mirror");
                let wide = ScatterIn {
                    gloss: cfg.mat_max(),
                    ..base
                };
                let o = s.scatter(&wide);
                let a = angle_deg(o.dir.map(f64::from), [-1.0, 0.0, 0.0]);
                assert!(a <= 90.5, "{a}");
                max_angle = max_angle.max(a);
                assert!(s.angle_error_deg(&wide).unwrap() < 1.5);
            }
            assert!(max_angle > 45.0, "gloss 90 spreads widely: {max_angle}");
        }
    }

    #[test]
    fn event_frequencies_follow_the_material() {
        let s = Scatter::new(ScatterConfig::DEFAULT).unwrap();
        let cfg = s.config();
        let one = cfg.mat_one();
        let n = 40_000u32;
        let mut counts = [0u32; 4];
        for k in 0..n {
            let it = ScatterIn {
                refl: one / 4,
                refr: one / 2,
                iso: one / 2,
                ray_bits: k, // sequential ray bits: the hash must decorrelate them
                ..item(&cfg, [1 << cfg.f(), 0, 0], [-7, 3, 1])
            };
            counts[s.scatter(&it).event as usize] += 1;
        }
        // Reflect 1/4; refract 3/8 (TIR impossible at eta 1); isotropic 3/16; pass 3/16.
        let want = [3.0 / 16.0, 0.25, 3.0 / 8.0, 3.0 / 16.0];
        for e in 0..4 {
            let got = f64::from(counts[e]) / f64::from(n);
            assert!(
                (got - want[e]).abs() < 0.01,
                "event {e}: {got} want {}",
                want[e]
            );
        }
    }

    #[test]
    fn isotropic_directions_cover_the_sphere() {
        let s = Scatter::new(ScatterConfig::DEFAULT).unwrap();
        let cfg = s.config();
        let mut sum = [0.0f64; 3];
        let n = 20_000;
        for k in 0..n {
            let it = ScatterIn {
                iso: cfg.mat_one(),
                ray_bits: k * 7919,
                ..item(&cfg, [1 << cfg.f(), 0, 0], [0, 0, 0])
            };
            let o = s.scatter(&it);
            assert_eq!(o.event, ScatterEvent::Isotropic);
            for (acc, &x) in sum.iter_mut().zip(&o.dir) {
                *acc += f64::from(x) / f64::from(1u32 << cfg.f());
            }
        }
        for x in sum {
            assert!((x / f64::from(n)).abs() < 0.03, "mean direction {sum:?}");
        }
    }

    /// Error bounds per event, in output LSBs of angle (`2^-F` rad) plus half a `theta` step for
    /// glossy events. Refraction is bounded away from the critical angle only: there the error
    /// grows as the square root of the rounding of `k` (contract § Error).
    #[test]
    fn random_items_stay_close_to_the_reference() {
        for s in units() {
            let cfg = s.config();
            let lsb = (1.0 / f64::from(1u32 << cfg.f())).to_degrees();
            let half_step = 45.0 / f64::from(1u32 << cfg.ang_w);
            let mut rng = ChaCha8Rng::seed_from_u64(9);
            let mut worst = [0.0f64; 4];
            for _ in 0..50_000 {
                let it = random_item(&cfg, &mut rng);
                let tr = s.trace(&it);
                let o = tr.out;
                if !o.zero_dir {
                    let len = unit_len(&cfg, o.dir);
                    assert!((len - 1.0).abs() < 3.0 / f64::from(1u32 << cfg.f()));
                }
                let Some(want) = s.reference_for(&it, &tr) else {
                    continue;
                };
                let err = angle_deg(o.dir.map(f64::from), want);
                if o.event == ScatterEvent::Refract {
                    let d = it.dir.map(f64::from);
                    let g = it.grad.map(f64::from);
                    let c = dot(d, g) / (dot(d, d) * dot(g, g)).sqrt();
                    let eta = f64::from(it.eta) / f64::from(cfg.mat_one());
                    if 1.0 - eta * eta * (1.0 - c * c) < 0.1 || eta > 2.0 {
                        continue;
                    }
                }
                let e = o.event as usize;
                worst[e] = worst[e].max(err);
            }
            eprintln!("{cfg:?}: worst angle error per event {worst:?} degrees");
            let bound = [
                2.0 * lsb,
                half_step + 8.0 * lsb,
                half_step + 16.0 * lsb,
                2.0 * lsb,
            ];
            for e in 0..4 {
                assert!(
                    worst[e] <= bound[e],
                    "{cfg:?} event {e}: {} > {}",
                    worst[e],
                    bound[e]
                );
            }
        }
    }

    #[test]
    fn tables_load_words_have_the_data_port_width() {
        let cfg = ScatterConfig::DEFAULT;
        let t = ScatterTables::new(&cfg).unwrap();
        assert_eq!(t.trig[0], (1 << cfg.f(), 0));
        let writes = t.config_writes(&cfg);
        assert_eq!(writes.len(), (1 << 9) + (1 << 8) + (1 << 8));
        for (_, data) in &writes {
            assert_eq!(data.len(), crate::bits::words_for(cfg.cfg_data_w()));
        }
        for v in &t.iso {
            let len = unit_len(&cfg, *v);
            assert!((len - 1.0).abs() < 1e-3);
        }
    }
}
