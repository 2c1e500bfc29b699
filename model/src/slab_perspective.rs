//! Approximate perspective by parallel slabs (patent [22]-[23], [314]-[318]): a what-if model, not
//! the hardware (docs/numerics/slab_perspective.md).
//!
//! The volume's depth range along the view (from the eye of the perspective view) is cut into
//! slabs by planes perpendicular to the view direction (the patent's image-aligned slabs, [315]).
//! Each slab is rendered with a parallel projection along the view direction (the central ray of
//! the frustum, so of every slab) taking only the samples whose depth lies in the slab, and its
//! image is textured onto the slab's middle plane and seen through the perspective projection;
//! the slab images are blended front to back. Here the texture is point-sampled where each
//! pixel's perspective ray meets the middle plane, so the slab's parallel ray is the one through
//! that point: this measures the slabs' approximation alone (the warp's resampling is the warp
//! unit's). Rays are f64, sampled and shaded as the reference renderer does ([`render`]'s
//! `Field` and `RayAcc`), so the error against the reference is the slab scheme's: a parallel ray
//! crosses a slab where the perspective ray would have crossed it only at the middle plane, with
//! the view direction's spacing, opacity correction and headlight instead of the pixel ray's.
//!
//! The slabs are of equal thickness, or bounded by planes at exponentially growing distances from
//! the eye ([`SlabSpacing::Geometric`], [23], [318]: as ER-perspective's regions grow), or each
//! twice as thick as the one before it ([`SlabSpacing::Doubling`]).
//!
//! [`render`]: crate::render

use crate::error::{ModelError, Result};
use crate::render::{image_of, perspective_eye, Field, ImageF64, Projection, RayAcc, RenderParams};
use crate::transfer::TransferFunction;
use crate::volume::Volume;
use serde::{Deserialize, Serialize};

/// Most slabs a scene may ask for.
pub const MAX_SLABS: u32 = 256;

/// How the slabs' thicknesses grow along the view.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum SlabSpacing {
    /// All slabs equally thick.
    #[default]
    Equal,
    /// Bounding planes at exponentially increasing distances from the eye ([23], [318]): each
    /// slab's thickness in proportion to its distance, so each spans the same ray divergence.
    Geometric,
    /// Each slab twice as thick as the one before it, from the volume's near side ([23]'s
    /// preferred reading); the farthest slab is half the depth range whatever the count.
    Doubling,
}

impl SlabSpacing {
    pub fn name(self) -> &'static str {
        match self {
            Self::Equal => "equal",
            Self::Geometric => "geometric",
            Self::Doubling => "doubling",
        }
    }
}

/// A slab scheme: how many slabs and how they are spaced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slabs {
    pub count: u32,
    pub spacing: SlabSpacing,
}

impl Slabs {
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_SLABS).contains(&self.count) {
            return Err(ModelError::Config(format!(
                "slabs {}: must be 1..={MAX_SLABS}",
                self.count
            )));
        }
        Ok(())
    }

    /// The `count + 1` depths bounding the slabs, from `near` to `far`.
    pub fn bounds(&self, near: f64, far: f64) -> Vec<f64> {
        let n = self.count as i32;
        (0..=n)
            .map(|i| match self.spacing {
                SlabSpacing::Equal => near + (far - near) * f64::from(i) / f64::from(n),
                SlabSpacing::Geometric => near * (far / near).powf(f64::from(i) / f64::from(n)),
                SlabSpacing::Doubling => {
                    near + (far - near) * (2f64.powi(i) - 1.0) / (2f64.powi(n) - 1.0)
                }
            })
            .collect()
    }

    /// One line for `plan:` and the tables.
    pub fn describe(&self) -> String {
        format!(
            "{} {} slab{} along the view",
            self.count,
            self.spacing.name(),
            if self.count == 1 { "" } else { "s" }
        )
    }
}

/// Renders the perspective view of `params` as `slabs` parallel slabs, blended front to back.
pub fn render_slabs(
    vol: &Volume,
    tf: &TransferFunction,
    params: &RenderParams,
    slabs: Slabs,
) -> Result<ImageF64> {
    params.validate()?;
    tf.validate()?;
    slabs.validate()?;
    if params.projection != Projection::Perspective {
        return Err(ModelError::View(
            "slab perspective approximates a perspective view; this one is parallel".into(),
        ));
    }
    let dir = params.direction()?;
    let cam = params.camera(vol, dir);
    let field = Field::new(vol, params);
    let (eye, tan_half) = perspective_eye(params, &cam);
    let depths = field.corners().map(|c| (c - eye).dot(dir));
    let far = depths.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    // The eye is outside the bounding sphere, but a corner of the box can reach nearer (small
    // volumes, wide views): the first slab takes every sample nearer than its far bound anyway.
    let near = depths
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
        .max(far * 1e-3);
    let bounds = slabs.bounds(near, far);
    let step = field.step_world;
    // Slab s takes the samples of depth k * step in [bounds[s], bounds[s + 1]) (the last also
    // takes its far bound): every depth of the lattice belongs to exactly one slab.
    let ranges: Vec<(f64, i64, i64)> = (0..slabs.count as usize)
        .map(|s| {
            let k0 = if s == 0 {
                i64::MIN
            } else {
                (bounds[s] / step).ceil() as i64
            };
            let k1 = if s + 1 == slabs.count as usize {
                i64::MAX
            } else {
                (bounds[s + 1] / step).ceil() as i64 - 1
            };
            ((bounds[s] + bounds[s + 1]) / 2.0, k0, k1)
        })
        .collect();
    let aspect = f64::from(params.width) / f64::from(params.height);
    Ok(image_of(params, |ndc_x, ndc_y| {
        let u = ndc_x * tan_half * aspect.max(1.0);
        let v = ndc_y * tan_half / aspect.min(1.0);
        let rd = (dir + cam.right * u + cam.up * v).normalize();
        let mut acc = RayAcc::default();
        'slabs: for &(mid, s0, s1) in &ranges {
            // The slab's parallel ray: through the point where the pixel's ray meets the middle
            // plane, starting on the plane through the eye (so its t is the depth).
            let origin = eye + rd * (mid / rd.dot(dir)) - dir * mid;
            let Some((k0, k1)) = field.clip(origin, dir) else {
                continue;
            };
            for k in k0.max(s0)..=k1.min(s1) {
                let w = origin + dir * (k as f64 * step);
                if acc.add(&field, tf, params, w, dir) {
                    break 'slabs;
                }
            }
        }
        acc.finish(&field, params.mode)
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_cover_the_depth_range() {
        let equal = Slabs {
            count: 4,
            spacing: SlabSpacing::Equal,
        };
        assert_eq!(equal.bounds(10.0, 18.0), vec![10.0, 12.0, 14.0, 16.0, 18.0]);
        let doubling = Slabs {
            count: 3,
            spacing: SlabSpacing::Doubling,
        };
        // Thicknesses 1, 2, 4 (x 14 / 7).
        assert_eq!(doubling.bounds(0.0, 14.0), vec![0.0, 2.0, 6.0, 14.0]);
        let geometric = Slabs {
            count: 2,
            spacing: SlabSpacing::Geometric,
        };
        assert_eq!(geometric.bounds(2.0, 8.0), vec![2.0, 4.0, 8.0]);
        assert!(Slabs {
            count: 0,
            spacing: SlabSpacing::Equal
        }
        .validate()
        .is_err());
    }
}
