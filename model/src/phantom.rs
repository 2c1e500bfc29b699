//! Volumes and the embedded procedural phantoms (no download needed for the default scene).

use crate::error::{ModelError, Result};
use crate::volume::{Volume, MAX_EDGE};
use rayon::prelude::*;

/// Normalized densities of the head phantom's tissues (0 air .. 1 metal). The head transfer
/// function (`TransferFunction::head_default`) has its skin, brain and bone entries at 0.22, 0.36
/// and 0.86; cerebrospinal fluid, fat and the eyes stay below its first entry (transparent).
pub mod tissue {
    pub const AIR: f64 = 0.0;
    pub const CSF: f64 = 0.12;
    pub const EYE: f64 = 0.13;
    pub const FAT: f64 = 0.16;
    pub const SOFT: f64 = 0.22;
    pub const WHITE: f64 = 0.345;
    pub const GREY: f64 = 0.385;
    pub const BONE: f64 = 0.86;
    pub const TOOTH: f64 = 0.90;
}

/// Half the width of every tissue boundary, in voxels of the volume being built: the density
/// ramps across `±EDGE_VOXELS` around each surface (a smoothstep), as a scanner's point-spread
/// function blurs it, so the volume is band-limited at any size and nothing aliases.
pub const EDGE_VOXELS: f64 = 1.5;

/// The head's size: its model coordinates are the volume's normalized ones divided by this.
const HEAD_SCALE: f64 = 1.08;

/// The seed of the phantom's texture (fixed: the phantom is the same on every machine).
const HEAD_SEED: u64 = 0x00c0_be5e_ed13;

type P3 = [f64; 3];

fn dot(a: P3, b: P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Approximate signed distance to the ellipsoid of centre `c` and radii `r` (negative inside;
/// exact on the surface, good to first order near it).
fn ellipsoid(p: P3, c: P3, r: P3) -> f64 {
    let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
    let q = [d[0] / r[0], d[1] / r[1], d[2] / r[2]];
    let q2 = [q[0] / r[0], q[1] / r[1], q[2] / r[2]];
    let k0 = dot(q, q).sqrt();
    let k1 = dot(q2, q2).sqrt();
    if k1 < 1e-12 {
        -r[0].min(r[1]).min(r[2])
    } else {
        k0 * (k0 - 1.0) / k1
    }
}

/// Smooth union of two distances (blend radius `k`).
fn smin(a: f64, b: f64, k: f64) -> f64 {
    let h = (0.5 + 0.5 * (b - a) / k).clamp(0.0, 1.0);
    b + (a - b) * h - k * h * (1.0 - h)
}

/// 1 well inside (`d <= -w`), 0 well outside (`d >= w`), a smoothstep between.
fn inside(d: f64, w: f64) -> f64 {
    let t = ((w - d) / (2.0 * w)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

/// Smooth value noise: random values in -1..1 on a cubic lattice of spacing `cell`, blended with
/// smoothstep weights (irregular, unlike a sum of a few plane waves, which would shade as rings).
struct Noise {
    seed: u64,
    cell: f64,
}

impl Noise {
    fn new(seed: u64, cell: f64) -> Self {
        Self { seed, cell }
    }

    fn lattice(&self, i: i64, j: i64, k: i64) -> f64 {
        // SplitMix64 of the seed and the lattice point.
        let mut h = self.seed
            ^ (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
            ^ (j as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f)
            ^ (k as u64).wrapping_mul(0x1656_67b1_9e37_79f9);
        h = (h ^ (h >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        h = (h ^ (h >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        h ^= h >> 31;
        (h >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    fn at(&self, p: P3) -> f64 {
        let q = p.map(|c| c / self.cell);
        let f = q.map(f64::floor);
        let t = [0, 1, 2].map(|a| {
            let u = q[a] - f[a];
            u * u * (3.0 - 2.0 * u)
        });
        let (i, j, k) = (f[0] as i64, f[1] as i64, f[2] as i64);
        let mut v = 0.0;
        for c in 0..8 {
            let (di, dj, dk) = (c & 1, (c >> 1) & 1, c >> 2);
            let w = [t[0], t[1], t[2]]
                .iter()
                .zip([di, dj, dk])
                .map(|(t, d)| if d == 1 { *t } else { 1.0 - t })
                .product::<f64>();
            v += w * self.lattice(i + di, j + dj, k + dk);
        }
        v
    }

    /// Typical gradient magnitude near a zero crossing (for distances to the zero set).
    fn slope(&self) -> f64 {
        0.8 / self.cell
    }
}

/// The head phantom's geometry in normalized coordinates: x from the patient's left to right, y
/// from back to front (the face looks along +y), z from the neck up (RAS).
struct Head {
    /// Fine texture of every tissue (a few voxels at 96^3).
    texture: Noise,
    /// Slow variation of tissue density across the head.
    shading: Noise,
    /// The zero sheets of this field are the sulci.
    folds: Noise,
    /// Moves the grey/white boundary in and out.
    cortex: Noise,
}

impl Head {
    fn new() -> Self {
        Self {
            texture: Noise::new(HEAD_SEED, 0.07),
            shading: Noise::new(HEAD_SEED + 1, 0.45),
            folds: Noise::new(HEAD_SEED + 2, 0.16),
            cortex: Noise::new(HEAD_SEED + 3, 0.2),
        }
    }

    /// Density (0..1) at `p`; `w` is the half-width of every boundary in normalized units.
    fn density(&self, p: P3, w: f64) -> f64 {
        use tissue::*;
        let [x, y, z] = p;
        let m = [x.abs(), y, z]; // mirrored: paired organs are modelled on the +x side
                                 // ---- The outline: cranium, face and jaw, neck, nose, ears.
        let cranium = ellipsoid(p, [0.0, -0.04, 0.12], [0.62, 0.78, 0.74]);
        let face = ellipsoid(p, [0.0, 0.26, -0.36], [0.46, 0.46, 0.38]);
        let neck = ellipsoid(p, [0.0, -0.10, -1.0], [0.34, 0.36, 0.62]);
        let nose = ellipsoid(p, [0.0, 0.74, -0.24], [0.07, 0.12, 0.15]);
        let jaw = ellipsoid(p, [0.0, 0.10, -0.56], [0.42, 0.48, 0.20]);
        let ear = ellipsoid(m, [0.62, -0.04, -0.06], [0.05, 0.10, 0.15]);
        let lower = smin(face, jaw, 0.1);
        let skin = smin(smin(smin(cranium, lower, 0.15), neck, 0.15), nose, 0.06).min(ear);
        if skin >= w {
            return AIR;
        }
        let tex = self.texture.at(p);
        let slow = self.shading.at(p);
        // Everything below is inside the skin; the outline's ramp multiplies it at the end.
        let mut v = SOFT + 0.012 * tex + 0.01 * slow;

        // ---- Bone: the skull (thicker towards its base), the facial bones, the mandible with
        // its teeth, the cervical spine; the orbits are cut out of it.
        let cerebrum = ellipsoid(p, [0.0, -0.03, 0.21], [0.49, 0.64, 0.51]);
        let cerebellum = ellipsoid(p, [0.0, -0.38, -0.22], [0.38, 0.22, 0.16]);
        let cavity = smin(cerebrum, cerebellum, 0.08);
        let thick = 0.085 + 0.05 * smoothstep(0.0, -0.45, z);
        let skull = (cranium + 0.045).max(-cavity).max(cavity - thick);
        let facial = (face + 0.05)
            .max(-(face + 0.12))
            .max(0.15 - y)
            .max(z + 0.08)
            .max(-0.50 - z);
        let jaw_ring = ellipse_ring([x, y - 0.12], [0.34, 0.40]) - 0.04;
        let mandible = jaw_ring.max(-y).max((z + 0.61).abs() - 0.07);
        let ramus = ellipsoid(m, [0.35, 0.04, -0.42], [0.03, 0.07, 0.18]);
        let teeth_row = ellipse_ring([x, y - 0.14], [0.30, 0.36]) - 0.03;
        let teeth = teeth_row.max(0.2 - y).max((z + 0.49).abs() - 0.05);
        let spine = (x.hypot(y + 0.14) - 0.085).max(z + 0.40);
        let orbit = ellipsoid(m, [0.22, 0.48, -0.12], [0.13, 0.16, 0.12]);
        let bone = skull
            .min(facial)
            .min(mandible)
            .min(ramus)
            .min(spine)
            .max(-orbit);
        let m_bone = inside(bone, w);
        if m_bone > 0.0 {
            // Vertebral bodies with discs between them.
            let disc = if z < -0.40 {
                smoothstep(-0.7, 0.2, ((z + 0.40) * std::f64::consts::TAU / 0.14).cos())
            } else {
                1.0
            };
            let b = lerp(SOFT + 0.08, BONE + 0.012 * tex, disc);
            v = lerp(v, b, m_bone);
        }
        v = lerp(v, TOOTH, inside(teeth.max(-orbit), w));
        // ---- Orbits: fat around the eye globes.
        let m_orbit = inside(orbit, w);
        if m_orbit > 0.0 {
            v = lerp(v, FAT, m_orbit);
            let globe = ellipsoid(m, [0.22, 0.52, -0.12], [0.095, 0.095, 0.09]);
            v = lerp(v, EYE, inside(globe, w));
        }
        // ---- Air: nasal cavity, maxillary sinuses, the airway down the neck.
        let nasal = ellipsoid(p, [0.0, 0.52, -0.26], [0.05, 0.20, 0.11]);
        let sinus = ellipsoid(m, [0.16, 0.44, -0.30], [0.08, 0.10, 0.08]);
        let airway = ellipsoid(p, [0.0, 0.10, -0.95], [0.06, 0.05, 0.62]);
        let air = nasal.min(sinus).min(airway);
        v = lerp(v, AIR, inside(air, w));

        // ---- The brain in its cavity: cerebrospinal fluid around it, cortex (grey matter) with
        // sulci and the longitudinal fissure, white matter, the lateral and third ventricles.
        let m_cavity = inside(cavity, w);
        if m_cavity > 0.0 {
            v = lerp(v, CSF, m_cavity);
            let brain = cavity + 0.025;
            let sulci = (self.folds.at(p).abs() / self.folds.slope() - 0.012).max(-(brain + 0.09));
            let fissure = (x.abs() - 0.012).max(0.18 - z).max(-cerebrum);
            let brain = brain.max(-sulci.min(fissure));
            v = lerp(v, GREY + 0.006 * tex + 0.006 * slow, inside(brain, w));
            let white = (brain + 0.07 + 0.035 * self.cortex.at(p)).max(brain);
            v = lerp(v, WHITE + 0.004 * tex, inside(white, w));
            // Lateral ventricles: bananas bent down at both ends; the third between them.
            let bend = 0.15 * (y / 0.26).powi(2);
            let lateral = ellipsoid(
                [m[0], y, z + bend],
                [0.09, -0.02, 0.17],
                [0.05, 0.26, 0.075],
            );
            let third = ellipsoid(p, [0.0, 0.0, 0.02], [0.015, 0.12, 0.07]);
            v = lerp(v, CSF, inside(lateral.min(third), w));
        }
        (v * inside(skin, w)).clamp(0.0, 1.0)
    }
}

fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Approximate distance (unsigned) from the 2-d point `q` to the ellipse of radii `r` about the
/// origin.
fn ellipse_ring(q: [f64; 2], r: [f64; 2]) -> f64 {
    let e = ellipsoid([q[0], q[1], 0.0], [0.0; 3], [r[0], r[1], 1.0]);
    e.abs()
}

/// The embedded head phantom, `n^3` voxels of `bits` bits: scalp and soft tissue, a skull with a
/// thicker base, facial bones, mandible and teeth, cervical spine, eyes in their orbits, nasal
/// cavity and sinuses, and a brain with grey and white matter, sulci and ventricles. The density
/// is a smooth analytic field (boundaries `±EDGE_VOXELS` voxels wide at any `n`, a fixed-seed
/// texture of a few percent), sampled at voxel centres: band-limited like scanner data.
pub fn head_phantom(n: usize, bits: u32) -> Result<Volume> {
    check_phantom_args(n, bits)?;
    let head = Head::new();
    let w = EDGE_VOXELS * 2.0 / n as f64 / HEAD_SCALE;
    sampled(n, bits, |p| head.density(p.map(|c| c / HEAD_SCALE), w))
}

/// The embedded phantoms by name (scene files say `phantom = "NAME"`).
pub const PHANTOMS: &[&str] = &["head", "sphere", "bubbles", "sphere-floor"];

/// Builds the embedded phantom `name`, `n^3` voxels of `bits` bits.
pub fn phantom_by_name(name: &str, n: usize, bits: u32) -> Result<Volume> {
    match name {
        "head" => head_phantom(n, bits),
        "sphere" => sphere_phantom(n, bits),
        "bubbles" => bubbles_phantom(n, bits),
        "sphere-floor" => sphere_floor_phantom(n, bits),
        _ => Err(ModelError::Volume(format!(
            "unknown phantom `{name}` (known: {})",
            PHANTOMS.join(", ")
        ))),
    }
}

fn check_phantom_args(n: usize, bits: u32) -> Result<()> {
    if !(4..=MAX_EDGE).contains(&n) {
        return Err(ModelError::Volume(format!(
            "phantom size {n}: must be 4..={MAX_EDGE}"
        )));
    }
    if !(1..=16).contains(&bits) {
        return Err(ModelError::Volume(format!(
            "voxel width {bits} bits: must be 1..=16"
        )));
    }
    Ok(())
}

/// The analytic sphere behind [`sphere_phantom`], in voxel coordinates (voxel centres at integers).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereGeometry {
    pub centre: [f64; 3],
    /// Radius of the iso-surface at density 0.5.
    pub radius: f64,
    /// Width of the linear density ramp across the surface, in voxels.
    pub ramp: f64,
}

impl SphereGeometry {
    /// The sphere of an `n^3` phantom: centred, radius `0.375 n`, a two-voxel ramp.
    pub fn for_size(n: usize) -> Self {
        let c = (n as f64 - 1.0) / 2.0;
        Self {
            centre: [c; 3],
            radius: 0.375 * n as f64,
            ramp: 2.0,
        }
    }

    /// Normalized density at `p`: 1 inside, 0 outside, linear across `radius ± ramp/2`.
    pub fn density(&self, p: [f64; 3]) -> f64 {
        let r = (0..3)
            .map(|a| (p[a] - self.centre[a]).powi(2))
            .sum::<f64>()
            .sqrt();
        ((self.radius - r) / self.ramp + 0.5).clamp(0.0, 1.0)
    }

    /// The analytic outward surface normal at `p` (unit length; +z at the centre itself).
    pub fn normal(&self, p: [f64; 3]) -> [f64; 3] {
        let d = [
            p[0] - self.centre[0],
            p[1] - self.centre[1],
            p[2] - self.centre[2],
        ];
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if len < 1e-12 {
            return [0.0, 0.0, 1.0];
        }
        d.map(|v| v / len)
    }
}

/// A voxelized sphere for gradient tests (cube3-paper §6.2): "volume sampling" in the sense of a
/// filtered scan conversion, the density falling linearly from 1 to 0 across a two-voxel shell, so
/// the ideal gradient is exactly radial. Sampled at voxel centres.
pub fn sphere_phantom(n: usize, bits: u32) -> Result<Volume> {
    check_phantom_args(n, bits)?;
    let g = SphereGeometry::for_size(n);
    let max = f64::from((1u32 << bits) - 1);
    let data: Vec<u16> = (0..n * n * n)
        .into_par_iter()
        .map(|idx| {
            let p = [idx % n, (idx / n) % n, idx / (n * n)].map(|v| v as f64);
            (g.density(p) * max).round() as u16
        })
        .collect();
    Volume::new([n; 3], [1.0; 3], bits, data)
}

/// The GI shadow scene's volume (`units::gicube_processor::shadow_scene`, `scenes/gi-shadow.toml`):
/// a translucent floor slab (density 0.45, its top at `0.22 n`, inset 1.5 voxels from the sides)
/// and a denser sphere above it (density 0.9, radius `0.2 n`, centre `(0.5, 0.5, 0.58) (n - 1)`),
/// boundaries ramped over 3 voxels, sampled at voxel centres. A light from above casts the
/// sphere's shadow onto the floor.
pub fn sphere_floor_phantom(n: usize, bits: u32) -> Result<Volume> {
    check_phantom_args(n, bits)?;
    let nf = n as f64;
    let max = f64::from((1u32 << bits) - 1);
    let smooth = |d: f64| (0.5 - d / 3.0).clamp(0.0, 1.0);
    let centre = [0.5, 0.5, 0.58].map(|c| c * (nf - 1.0));
    let radius = 0.2 * nf;
    let floor_top = 0.22 * nf;
    let inset = |c: f64| c.min(nf - 1.0 - c);
    let data: Vec<u16> = (0..n * n * n)
        .map(|idx| {
            let p = [idx % n, (idx / n) % n, idx / (n * n)].map(|v| v as f64);
            let edge = inset(p[0]).min(inset(p[1])) - 1.5;
            let floor = smooth(p[2] - floor_top) * smooth(-edge) * smooth(1.5 - p[2]);
            let r = (0..3)
                .map(|a| (p[a] - centre[a]).powi(2))
                .sum::<f64>()
                .sqrt();
            let sphere = smooth(r - radius);
            let d = (0.45 * floor).max(0.9 * sphere);
            (d * max).round() as u16
        })
        .collect();
    Volume::new([n; 3], [1.0; 3], bits, data)
}

/// A block of foam: density 0.75 everywhere with spherical holes of lower density, the volume
/// filled to its faces. The minimum-intensity projection shows the holes (a phantom padded with
/// air would give a black MinIP).
pub fn bubbles_phantom(n: usize, bits: u32) -> Result<Volume> {
    check_phantom_args(n, bits)?;
    let holes: [([f64; 3], f64, f64); 5] = [
        ([0.0, 0.0, 0.0], 0.35, 0.10),
        ([-0.55, 0.45, 0.2], 0.22, 0.30),
        ([0.5, -0.5, -0.3], 0.25, 0.20),
        ([0.55, 0.5, 0.5], 0.15, 0.45),
        ([-0.5, -0.45, -0.5], 0.18, 0.05),
    ];
    supersampled(n, bits, |p| {
        holes
            .iter()
            .find(|(c, r, _)| (0..3).map(|a| (p[a] - c[a]).powi(2)).sum::<f64>() <= r * r)
            .map_or(0.75, |h| h.2)
    })
}

/// An `n^3` volume of `bits` bits whose voxels are the density `f` (0..=1, at points of the
/// normalized cube -1..1) at the voxel centres.
fn sampled(n: usize, bits: u32, f: impl Fn([f64; 3]) -> f64 + Sync) -> Result<Volume> {
    let max = f64::from((1u32 << bits) - 1);
    let to_norm = |i: usize| (i as f64 + 0.5) / n as f64 * 2.0 - 1.0;
    let data: Vec<u16> = (0..n * n * n)
        .into_par_iter()
        .map(|idx| {
            let p = [
                to_norm(idx % n),
                to_norm((idx / n) % n),
                to_norm(idx / (n * n)),
            ];
            (f(p).clamp(0.0, 1.0) * max).round() as u16
        })
        .collect();
    Volume::new([n; 3], [1.0; 3], bits, data)
}

/// An `n^3` volume of `bits` bits whose voxels are the density `f` (0..=1, at points of the
/// normalized cube -1..1) averaged over 2x2x2 samples at +-1/4 voxel: anti-aliased edges.
fn supersampled(n: usize, bits: u32, f: impl Fn([f64; 3]) -> f64 + Sync) -> Result<Volume> {
    let max = f64::from((1u32 << bits) - 1);
    let to_norm = |i: f64| (i + 0.5) / n as f64 * 2.0 - 1.0;
    let data: Vec<u16> = (0..n * n * n)
        .into_par_iter()
        .map(|idx| {
            let (x, y, z) = (idx % n, (idx / n) % n, idx / (n * n));
            let mut acc = 0.0;
            for s in 0..8 {
                let off = |bit: usize| if (s >> bit) & 1 == 1 { 0.25 } else { -0.25 };
                let p = [
                    to_norm(x as f64 + off(0)),
                    to_norm(y as f64 + off(1)),
                    to_norm(z as f64 + off(2)),
                ];
                acc += f(p) / 8.0;
            }
            (acc * max).round() as u16
        })
        .collect();
    Volume::new([n; 3], [1.0; 3], bits, data)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The density at the voxel nearest the head model's point `p`.
    fn at(v: &Volume, p: [f64; 3]) -> f64 {
        let n = v.dims[0] as f64;
        let i = p.map(|c| ((c * HEAD_SCALE + 1.0) / 2.0 * n - 0.5).round() as i64);
        f64::from(v.get(i[0], i[1], i[2])) / f64::from(v.max_value())
    }

    #[test]
    fn phantom_has_structure() {
        use tissue::*;
        let v = head_phantom(96, 12).unwrap();
        assert_eq!(v.len(), 96 * 96 * 96);
        assert_eq!(v.get(0, 0, 0), 0, "corners are air");
        assert_eq!(v.get(-1, 5, 5), 0, "outside reads zero");
        for (what, p, want) in [
            ("skull vertex", [0.0, -0.03, 0.77], BONE),
            ("white matter", [0.25, -0.2, 0.3], WHITE),
            ("lateral ventricle", [0.09, -0.02, 0.17], CSF),
            ("right eye", [0.22, 0.52, -0.12], EYE),
            ("left eye", [-0.22, 0.52, -0.12], EYE),
            ("nasal cavity", [0.0, 0.52, -0.26], AIR),
            ("neck", [0.2, -0.1, -0.8], SOFT),
            ("vertebra", [0.0, -0.14, -0.82], BONE),
        ] {
            let got = at(&v, p);
            assert!(
                (got - want).abs() < 0.04,
                "{what} at {p:?}: {got}, want {want}"
            );
        }
    }

    /// Band-limited: no boundary is sharper than the smoothstep across `2 EDGE_VOXELS` voxels
    /// allows (a step of 1.5 / (2 EDGE_VOXELS) = 0.5 of the contrast per voxel; the largest
    /// contrast, teeth against air, is 0.9, and where two ramps meet they add a little), where the
    /// hard-edged phantom of old stepped by the whole contrast between neighbours.
    #[test]
    fn head_edges_are_smooth_at_every_size() {
        for n in [32, 64] {
            let v = head_phantom(n, 12).unwrap();
            let max = f64::from(v.max_value());
            let mut steepest = 0.0f64;
            for z in 0..n as i64 {
                for y in 0..n as i64 {
                    for x in 1..n as i64 {
                        let d = f64::from(v.get(x, y, z)).max(0.0) - f64::from(v.get(x - 1, y, z));
                        steepest = steepest.max(d.abs() / max);
                    }
                }
            }
            let bound = 0.5;
            assert!(
                steepest <= bound,
                "{n}^3: a step of {steepest} (bound {bound})"
            );
        }
        let a = head_phantom(24, 12).unwrap();
        assert_eq!(a, head_phantom(24, 12).unwrap(), "deterministic");
    }

    #[test]
    fn bad_volumes_refused() {
        assert!(Volume::new([0, 4, 4], [1.0; 3], 8, vec![]).is_err());
        assert!(Volume::new([2, 2, 2], [1.0; 3], 8, vec![0; 7]).is_err());
        assert!(Volume::new([2, 2, 2], [1.0; 3], 8, vec![256; 8]).is_err());
        assert!(Volume::new([2, 2, 2], [f64::NAN, 1.0, 1.0], 8, vec![0; 8]).is_err());
        assert!(head_phantom(2, 12).is_err());
        assert!(phantom_by_name("teapot", 8, 8).is_err());
        assert!(sphere_phantom(8, 0).is_err());
    }

    #[test]
    fn sphere_is_radial_and_bubbles_fill_the_box() {
        let v = sphere_phantom(32, 12).unwrap();
        let g = SphereGeometry::for_size(32);
        assert_eq!(v.get(0, 0, 0), 0);
        assert_eq!(v.get(16, 16, 16), 4095);
        // Symmetric under axis swaps.
        assert_eq!(v.get(3, 16, 15), v.get(16, 3, 15));
        let n = g.normal([g.centre[0] + 3.0, g.centre[1], g.centre[2] - 4.0]);
        assert!((n[0] - 0.6).abs() < 1e-12 && (n[2] + 0.8).abs() < 1e-12);
        let b = bubbles_phantom(24, 8).unwrap();
        assert!(b.get(0, 0, 0) > 100, "foam reaches the faces");
        assert!(b.get(12, 12, 12) < 60, "a hole in the middle");
    }
}
