//! Volumes and the embedded procedural phantoms (no download needed for the default scene).

use crate::error::{ModelError, Result};
use crate::volume::{Volume, MAX_EDGE};
use rayon::prelude::*;

/// One ellipsoid of constant density in normalized coordinates ([-1, 1] across the volume).
struct Blob {
    centre: [f64; 3],
    radii: [f64; 3],
    density: f64,
}

impl Blob {
    fn inside(&self, p: [f64; 3]) -> bool {
        (0..3)
            .map(|a| ((p[a] - self.centre[a]) / self.radii[a]).powi(2))
            .sum::<f64>()
            <= 1.0
    }
}

/// A CT-like head: skin, skull shell, brain, two ventricles and lesions of different densities.
/// Later blobs overwrite earlier ones, so the list reads from the outside in.
fn head_blobs() -> Vec<Blob> {
    let b = |centre, radii, density| Blob {
        centre,
        radii,
        density,
    };
    vec![
        b([0.0, 0.0, 0.0], [0.80, 0.90, 0.95], 0.22), // skin and scalp
        b([0.0, 0.0, 0.0], [0.76, 0.86, 0.91], 0.86), // skull
        b([0.0, 0.0, 0.02], [0.69, 0.79, 0.84], 0.36), // brain
        b([-0.3, -0.8, -0.25], [0.16, 0.16, 0.14], 0.0), // left eye orbit
        b([0.3, -0.8, -0.25], [0.16, 0.16, 0.14], 0.0), // right eye orbit
        b([-0.16, 0.05, 0.1], [0.08, 0.28, 0.12], 0.12), // left ventricle
        b([0.16, 0.05, 0.1], [0.08, 0.28, 0.12], 0.12), // right ventricle
        b([0.32, -0.25, 0.28], [0.15, 0.15, 0.15], 0.50), // lesion
        b([-0.35, -0.2, -0.15], [0.12, 0.12, 0.12], 0.61), // lesion
        b([0.05, 0.42, -0.35], [0.11, 0.11, 0.11], 0.75), // calcification
        b([0.0, -0.5, 0.45], [0.05, 0.05, 0.05], 1.00), // metal marker
    ]
}

/// The embedded head phantom, `n^3` voxels of `bits` bits, edges anti-aliased by 2x2x2 supersampling.
pub fn head_phantom(n: usize, bits: u32) -> Result<Volume> {
    check_phantom_args(n, bits)?;
    let blobs = head_blobs();
    supersampled(n, bits, |p| {
        blobs
            .iter()
            .rev()
            .find(|b| b.inside(p))
            .map_or(0.0, |b| b.density)
    })
}

/// The embedded phantoms by name (scene files say `phantom = "NAME"`).
pub const PHANTOMS: &[&str] = &["head", "sphere", "bubbles"];

/// Builds the embedded phantom `name`, `n^3` voxels of `bits` bits.
pub fn phantom_by_name(name: &str, n: usize, bits: u32) -> Result<Volume> {
    match name {
        "head" => head_phantom(n, bits),
        "sphere" => sphere_phantom(n, bits),
        "bubbles" => bubbles_phantom(n, bits),
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

    #[test]
    fn phantom_has_structure() {
        let v = head_phantom(32, 12).unwrap();
        assert_eq!(v.len(), 32 * 32 * 32);
        assert_eq!(v.get(0, 0, 0), 0, "corners are air");
        assert!(
            v.data.iter().any(|&d| u32::from(d) > 3000),
            "skull is dense"
        );
        assert_eq!(v.get(-1, 5, 5), 0, "outside reads zero");
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
