//! Opaque geometry mixed with the volume (patent [62], [217]-[218]; docs/numerics/frame.md,
//! "Opaque geometry"): boxes and spheres in volume coordinates, rasterized by the host into the
//! RGBA-Z image the frame's compositing buffer is preloaded with, and intersected in f64 by the
//! reference renderer.
//!
//! Coordinates are voxel coordinates: voxel `(x, y, z)` of the volume sits at point `(x, y, z)`
//! (the f64 reference's physical point `(x sx, y sy, z sz)`), so a sphere is a sphere in voxels
//! (an ellipsoid in physical space when the spacing is anisotropic).

use crate::units::cube5_compos::ComposConfig;
use crate::units::cube5_frame::{FrameParams, GeoPixel, GeometryImage, STEP_W};
use glam::DVec3;

/// One opaque solid with its colour (each channel in 0..=1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solid {
    /// The axis-aligned box `min ..= max`.
    Box {
        min: [f64; 3],
        max: [f64; 3],
        colour: [f64; 3],
    },
    Sphere {
        centre: [f64; 3],
        radius: f64,
        colour: [f64; 3],
    },
}

impl Solid {
    pub fn colour(&self) -> [f64; 3] {
        match *self {
            Self::Box { colour, .. } | Self::Sphere { colour, .. } => colour,
        }
    }

    /// Where the line `o + t d` (all real `t`) enters the solid: the smallest `t` on its surface,
    /// or `None` when the line misses it.
    pub fn entry(&self, o: DVec3, d: DVec3) -> Option<f64> {
        match *self {
            Self::Box { min, max, .. } => {
                let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
                for a in 0..3 {
                    if d[a] == 0.0 {
                        if o[a] < min[a] || o[a] > max[a] {
                            return None;
                        }
                    } else {
                        let (ta, tb) = ((min[a] - o[a]) / d[a], (max[a] - o[a]) / d[a]);
                        t0 = t0.max(ta.min(tb));
                        t1 = t1.min(ta.max(tb));
                    }
                }
                (t0 <= t1 && t0.is_finite()).then_some(t0)
            }
            Self::Sphere { centre, radius, .. } => {
                let oc = o - DVec3::from_array(centre);
                let a = d.dot(d);
                let b = oc.dot(d);
                let c = oc.dot(oc) - radius * radius;
                let disc = b * b - a * c;
                (a > 0.0 && disc >= 0.0).then(|| (-b - disc.sqrt()) / a)
            }
        }
    }
}

/// The first surface along the line `o + t d` over every solid: its `t` and colour.
pub fn first_hit(solids: &[Solid], o: DVec3, d: DVec3) -> Option<(f64, [f64; 3])> {
    solids
        .iter()
        .filter_map(|s| s.entry(o, d).map(|t| (t, s.colour())))
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// A colour in 0..=1 as a `ColorW`-bit code (`round(c (2^ColorW - 1))`, clamped).
pub fn colour_code(c: f64, cfg: &ComposConfig) -> u32 {
    let max = f64::from((1u32 << cfg.color_w) - 1);
    (c.clamp(0.0, 1.0) * max).round() as u32
}

/// The host's rasterization (docs/numerics/frame.md, "Opaque geometry"): for each base-plane
/// pixel `(R, Q)`, the frame's own ray `r = R - max sx`, `q = Q - max sy` through
/// `(r + t DX / 2^16, q + t DY / 2^16)` in slice `t` (slice `k(t)` of the sweep), meets the first
/// surface at slice `t`; the pixel's depth is `Z = ceil(t)` clamped to `0 ..= Znone - 1` (the
/// samples at `s >= t` are at or behind it), and its colour the solid's. No surface: `Znone`,
/// colour 0.
pub fn rasterize(params: &FrameParams, solids: &[Solid], cfg: &ComposConfig) -> GeometryImage {
    let (w, h) = params.base_plane_size();
    let ((_, max_sx), (_, max_sy)) = params.shift_range();
    let unit = f64::from(1u32 << STEP_W);
    let k0 = params.slice(0).k as f64;
    let dk = if params.k_reversed { -1.0 } else { 1.0 };
    let mut d = DVec3::ZERO;
    d[params.axis_i] = f64::from(params.dx) / unit;
    d[params.axis_j] = f64::from(params.dy) / unit;
    d[params.axis_k] = dk;
    let z_none = cfg.z_none();
    let pixels = (0..w * h)
        .map(|idx| {
            let (r, q) = ((idx % w) as i64 - max_sx, (idx / w) as i64 - max_sy);
            let mut o = DVec3::ZERO;
            o[params.axis_i] = r as f64;
            o[params.axis_j] = q as f64;
            o[params.axis_k] = k0;
            match first_hit(solids, o, d) {
                Some((t, c)) => GeoPixel {
                    z: t.ceil().clamp(0.0, f64::from(z_none - 1)) as u32,
                    rgb: c.map(|x| colour_code(x, cfg)),
                },
                None => GeoPixel {
                    z: z_none,
                    rgb: [0; 3],
                },
            }
        })
        .collect();
    GeometryImage {
        width: w,
        height: h,
        pixels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boxes_and_spheres_are_entered_where_the_line_meets_them() {
        let b = Solid::Box {
            min: [2.0, 2.0, 2.0],
            max: [4.0, 4.0, 4.0],
            colour: [1.0; 3],
        };
        let o = DVec3::new(3.0, 3.0, -10.0);
        assert_eq!(b.entry(o, DVec3::Z), Some(12.0));
        assert_eq!(b.entry(o, -DVec3::Z), Some(-14.0));
        assert_eq!(b.entry(DVec3::new(5.0, 3.0, 0.0), DVec3::Z), None);
        let s = Solid::Sphere {
            centre: [0.0, 0.0, 5.0],
            radius: 2.0,
            colour: [0.5; 3],
        };
        assert_eq!(s.entry(DVec3::ZERO, DVec3::Z), Some(3.0));
        assert_eq!(s.entry(DVec3::ZERO, DVec3::Z * 2.0), Some(1.5));
        assert_eq!(s.entry(DVec3::new(3.0, 0.0, 0.0), DVec3::Z), None);
        let hit = first_hit(&[b, s], DVec3::new(0.0, 0.0, -10.0), DVec3::Z).unwrap();
        assert_eq!(hit, (13.0, [0.5; 3]));
    }
}
