//! The f64 image-order reference renderer: orthographic rays through the volume, tri-linear
//! samples, central-difference gradients, Phong shading with a headlight, front-to-back `over`
//! compositing. It is the ideal the fixed-point pipeline's error is measured against.

use crate::error::{ModelError, Result};
use crate::phantom::Volume;
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// A piecewise-linear transfer function from normalized density (0..1) to RGBA; alpha is the
/// opacity of one unit of path length (one voxel).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TransferFunction {
    pub points: Vec<TfPoint>,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TfPoint {
    pub density: f64,
    pub rgba: [f64; 4],
}

impl TransferFunction {
    pub fn new(points: Vec<TfPoint>) -> Result<Self> {
        let tf = Self { points };
        tf.validate()?;
        Ok(tf)
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(ModelError::Config(format!("transfer function: {m}")));
        if self.points.is_empty() {
            return bad("no points".into());
        }
        for (i, p) in self.points.iter().enumerate() {
            if !(0.0..=1.0).contains(&p.density) {
                return bad(format!("point {i}: density {} outside 0..1", p.density));
            }
            if p.rgba.iter().any(|c| !(0.0..=1.0).contains(c)) {
                return bad(format!("point {i}: rgba {:?} outside 0..1", p.rgba));
            }
            if i > 0 && p.density < self.points[i - 1].density {
                return bad(format!("point {i}: densities must be sorted ascending"));
            }
        }
        Ok(())
    }

    /// The default for the head phantom: faint skin and brain, coloured lesions, white bone.
    pub fn head_default() -> Self {
        let p = |density, rgba| TfPoint { density, rgba };
        Self {
            points: vec![
                p(0.00, [0.0, 0.0, 0.0, 0.0]),
                p(0.17, [0.0, 0.0, 0.0, 0.0]),
                p(0.22, [0.85, 0.60, 0.50, 0.004]),
                p(0.28, [0.0, 0.0, 0.0, 0.0]),
                p(0.33, [0.90, 0.55, 0.55, 0.0]),
                p(0.36, [0.90, 0.55, 0.55, 0.006]),
                p(0.42, [0.0, 0.0, 0.0, 0.0]),
                p(0.50, [0.95, 0.85, 0.20, 0.45]),
                p(0.55, [0.0, 0.0, 0.0, 0.0]),
                p(0.61, [0.30, 0.90, 0.35, 0.55]),
                p(0.67, [0.0, 0.0, 0.0, 0.0]),
                p(0.75, [0.95, 0.25, 0.20, 0.7]),
                p(0.80, [0.95, 0.93, 0.88, 0.0]),
                p(0.86, [0.95, 0.93, 0.88, 0.12]),
                p(0.92, [0.95, 0.93, 0.88, 0.0]),
                p(1.00, [0.40, 0.85, 1.00, 1.0]),
            ],
        }
    }

    /// RGBA at normalized density `d` (clamped to the end points outside their range).
    pub fn lookup(&self, d: f64) -> [f64; 4] {
        let pts = &self.points;
        if d <= pts[0].density {
            return pts[0].rgba;
        }
        for w in pts.windows(2) {
            let (a, b) = (w[0], w[1]);
            if d <= b.density {
                let span = b.density - a.density;
                let t = if span > 0.0 {
                    (d - a.density) / span
                } else {
                    1.0
                };
                return std::array::from_fn(|c| a.rgba[c] + t * (b.rgba[c] - a.rgba[c]));
            }
        }
        pts[pts.len() - 1].rgba
    }
}

/// How the samples along a ray are combined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum CompositeMode {
    /// Front-to-back `over` with shading.
    #[default]
    Composite,
    /// Maximum intensity projection (grey).
    Mip,
}

/// An orthographic view orbiting the volume centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// Degrees around the volume z axis, from +x.
    pub azimuth: f64,
    /// Degrees above the volume xy plane.
    pub elevation: f64,
}

impl View {
    /// Unit vector from the eye toward the volume, in physical coordinates.
    pub fn direction(&self) -> Result<DVec3> {
        if !self.azimuth.is_finite() || !self.elevation.is_finite() {
            return Err(ModelError::View(format!(
                "azimuth {} / elevation {} must be finite",
                self.azimuth, self.elevation
            )));
        }
        let (a, e) = (self.azimuth.to_radians(), self.elevation.to_radians());
        Ok(-DVec3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin()))
    }
}

/// Parameters of one reference rendering.
#[derive(Debug, Clone)]
pub struct RenderParams {
    pub width: u32,
    pub height: u32,
    pub view: View,
    /// Sample spacing along the ray, in voxels.
    pub step: f64,
    pub mode: CompositeMode,
    pub shading: bool,
    /// Rays stop once accumulated opacity reaches this.
    pub early_termination: f64,
}

impl Default for RenderParams {
    fn default() -> Self {
        Self {
            width: 256,
            height: 256,
            view: View {
                azimuth: 30.0,
                elevation: 20.0,
            },
            step: 0.25,
            mode: CompositeMode::Composite,
            shading: true,
            early_termination: 0.995,
        }
    }
}

/// A rendered image, RGB in 0..1, row-major from the top.
#[derive(Debug, Clone)]
pub struct ImageF64 {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<[f64; 3]>,
}

impl ImageF64 {
    pub fn to_rgb8(&self) -> image::RgbImage {
        let mut img = image::RgbImage::new(self.width, self.height);
        for (p, c) in img.pixels_mut().zip(&self.rgb) {
            *p = image::Rgb(c.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8));
        }
        img
    }
}

/// Renders `vol` with the f64 image-order ray caster.
pub fn render_reference(
    vol: &Volume,
    tf: &TransferFunction,
    params: &RenderParams,
) -> Result<ImageF64> {
    if params.width == 0 || params.height == 0 || params.width > 8192 || params.height > 8192 {
        return Err(ModelError::Image(format!(
            "size {}x{}: width and height must be 1..=8192",
            params.width, params.height
        )));
    }
    if !(params.step.is_finite() && params.step > 0.0 && params.step <= 4.0) {
        return Err(ModelError::Config(format!(
            "step {}: must be in (0, 4]",
            params.step
        )));
    }
    tf.validate()?;
    let dir = params.view.direction()?;
    let spacing = DVec3::from_array(vol.spacing);
    let extent = DVec3::new(vol.dims[0] as f64, vol.dims[1] as f64, vol.dims[2] as f64) * spacing;
    let centre = (extent - spacing) * 0.5; // voxel centres run 0 ..= n-1
    let world_up = if dir.z.abs() > 0.999 {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let right = dir.cross(world_up).normalize();
    let up = right.cross(dir);
    let radius = extent.length() * 0.5;
    let half = radius * 1.02;
    let aspect = f64::from(params.width) / f64::from(params.height);
    let min_spacing = spacing.min_element();
    let step_world = params.step * min_spacing;
    let max_value = f64::from(vol.max_value());

    let to_voxel = |w: DVec3| (w / spacing).to_array();
    let sample = |w: DVec3| vol.sample_f64(to_voxel(w)) / max_value;
    let gradient = |w: DVec3| {
        let h = min_spacing;
        DVec3::new(
            sample(w + DVec3::X * h) - sample(w - DVec3::X * h),
            sample(w + DVec3::Y * h) - sample(w - DVec3::Y * h),
            sample(w + DVec3::Z * h) - sample(w - DVec3::Z * h),
        )
    };

    let rgb: Vec<[f64; 3]> = (0..params.width * params.height)
        .into_par_iter()
        .map(|i| {
            let (px, py) = (i % params.width, i / params.width);
            let u = ((f64::from(px) + 0.5) / f64::from(params.width) * 2.0 - 1.0)
                * half
                * aspect.max(1.0);
            let v = (1.0 - (f64::from(py) + 0.5) / f64::from(params.height) * 2.0) * half
                / aspect.min(1.0);
            let origin = centre + right * u + up * v - dir * radius;
            let steps = (2.0 * radius / step_world).ceil() as usize;
            let mut color = DVec3::ZERO;
            let mut alpha = 0.0;
            let mut peak: f64 = 0.0;
            for k in 0..=steps {
                let w = origin + dir * (k as f64 * step_world);
                let d = sample(w);
                match params.mode {
                    CompositeMode::Mip => peak = peak.max(d),
                    CompositeMode::Composite => {
                        let [r, g, b, a] = tf.lookup(d);
                        if a <= 0.0 {
                            continue;
                        }
                        // Opacity per voxel of path, corrected to the step length.
                        let a = 1.0 - (1.0 - a).powf(params.step);
                        let mut c = DVec3::new(r, g, b);
                        if params.shading {
                            c *= shade(gradient(w), dir);
                        }
                        color += (1.0 - alpha) * a * c;
                        alpha += (1.0 - alpha) * a;
                        if alpha >= params.early_termination {
                            break;
                        }
                    }
                }
            }
            match params.mode {
                CompositeMode::Mip => [peak; 3],
                CompositeMode::Composite => color.to_array(),
            }
        })
        .collect();
    Ok(ImageF64 {
        width: params.width,
        height: params.height,
        rgb,
    })
}

/// Phong intensity for a headlight (light along the view): ambient + diffuse + specular, two-sided.
/// A zero gradient (homogeneous region) gets ambient + diffuse as if lit head-on.
fn shade(gradient: DVec3, dir: DVec3) -> f64 {
    const AMBIENT: f64 = 0.25;
    const DIFFUSE: f64 = 0.65;
    const SPECULAR: f64 = 0.35;
    const SHININESS: i32 = 24;
    let len = gradient.length();
    if len < 1e-9 {
        return AMBIENT + DIFFUSE;
    }
    let n_dot_l = (gradient / len).dot(-dir).abs();
    AMBIENT + DIFFUSE * n_dot_l + SPECULAR * n_dot_l.powi(SHININESS)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::head_phantom;

    #[test]
    fn renders_something_with_a_dark_border() {
        let vol = head_phantom(24, 12).unwrap();
        let params = RenderParams {
            width: 32,
            height: 32,
            ..Default::default()
        };
        let img = render_reference(&vol, &TransferFunction::head_default(), &params).unwrap();
        let lum: Vec<f64> = img.rgb.iter().map(|c| c.iter().sum()).collect();
        assert!(lum[0] < 1e-6, "corner pixel is background");
        assert!(lum[16 * 32 + 16] > 0.1, "centre pixel sees the head");
    }

    #[test]
    fn bad_params_refused() {
        let vol = head_phantom(8, 12).unwrap();
        let tf = TransferFunction::head_default();
        let zero = RenderParams {
            width: 0,
            ..Default::default()
        };
        assert!(render_reference(&vol, &tf, &zero).is_err());
        let nan = RenderParams {
            view: View {
                azimuth: f64::NAN,
                elevation: 0.0,
            },
            ..Default::default()
        };
        assert!(render_reference(&vol, &tf, &nan).is_err());
        let unsorted = TransferFunction {
            points: vec![
                TfPoint {
                    density: 0.5,
                    rgba: [0.0; 4],
                },
                TfPoint {
                    density: 0.2,
                    rgba: [0.0; 4],
                },
            ],
        };
        assert!(unsorted.validate().is_err());
    }
}
