//! Two renderers of a scene.
//!
//! - [`render_reference`]: the f64 image-order reference. Rays through pixel centres (parallel or
//!   perspective), samples at a uniform step, exact tri-linear interpolation, central-difference
//!   gradients of interpolated values, Phong shading with distant lights, and the projection modes
//!   (front-to-back `over`, MIP, MinIP, X-ray, first opaque). It is the ideal every fixed-point
//!   setting's error is measured against (`cube5 tradeoff`).
//! - [`render_pipeline`]: the slice-order pipeline at a [`Quality`] setting. The view is set up as
//!   `docs/numerics/frame.md` says (major axis, sweep direction, per-slice steps in `S(2.16)`);
//!   rays start on the base-plane grid and take their samples on the slices (or between them, for
//!   the sheared and full tri-linear schemes of cube3-paper §3 and for more samples per slice);
//!   every sample comes from the bit-accurate `cube5_trilin` model, every gradient from the
//!   bit-accurate `cube5_gradient` model (cube3-paper §4's 6-, 10- and 26-neighbourhoods on the ray
//!   lattice); classification, shading and compositing are f64 rounded to the colour, alpha and
//!   accumulator widths, NOT the `cube5_shader`/`cube5_compos` models: this pipeline is the
//!   what-if renderer for the quality knobs, and the hardware's bits are `frame::render_base_plane`
//!   (making `cube5 render` run the frame model is issue 13); the base-plane image is warped onto
//!   the image. See `docs/scenes.md` § Quality.

use crate::camera::{self, Camera};
use crate::error::{ModelError, Result};
use crate::transfer::TransferFunction;
use crate::units::cube5_gradient::{Gradient, GradientConfig, GradientIn, GradientMode};
use crate::units::cube5_trilin::{Trilin, TrilinConfig, TrilinIn, TrilinMode};
use crate::volume::Volume;
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

// =================================================================================================
// View, lights, parameters
// =================================================================================================

/// How the samples along a ray are combined (cube3-paper §2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum CompositeMode {
    /// Front-to-back `over`, classified by the transfer function, optionally shaded.
    #[default]
    Composite,
    /// Maximum intensity projection (grey).
    Mip,
    /// Minimum intensity projection over the samples inside the volume (grey).
    Minip,
    /// X-ray: the density integrated along the ray over the volume's diagonal (grey).
    Xray,
    /// The colour of the first sample whose opacity reaches `threshold` (shaded if shading is on).
    FirstOpaque,
}

impl CompositeMode {
    pub fn name(self) -> &'static str {
        match self {
            Self::Composite => "composite",
            Self::Mip => "mip",
            Self::Minip => "minip",
            Self::Xray => "xray",
            Self::FirstOpaque => "first-opaque",
        }
    }

    /// Modes that classify samples through the transfer function (and so can be shaded).
    pub fn classifies(self) -> bool {
        matches!(self, Self::Composite | Self::FirstOpaque)
    }
}

/// Parallel (orthographic) or perspective projection.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Projection {
    #[default]
    Parallel,
    Perspective,
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

/// A distant light.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Light {
    /// The direction the light travels (from the light into the scene), physical coordinates.
    pub direction: [f64; 3],
    /// Linear RGB intensity, each 0..=4.
    #[serde(default = "white", alias = "color")]
    pub colour: [f64; 3],
}

fn white() -> [f64; 3] {
    [1.0; 3]
}

/// Phong coefficients (two-sided: the gradient's sign is ignored).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Material {
    pub ambient: f64,
    pub diffuse: f64,
    pub specular: f64,
    pub shininess: f64,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            ambient: 0.25,
            diffuse: 0.65,
            specular: 0.35,
            shininess: 24.0,
        }
    }
}

/// Parameters of one rendering (either renderer).
#[derive(Debug, Clone)]
pub struct RenderParams {
    pub width: u32,
    pub height: u32,
    pub view: View,
    /// View vector (from the eye into the scene); overrides `view`'s angles when set.
    pub direction: Option<[f64; 3]>,
    /// Image up (a hint, made orthogonal to the view); none: the orbit's or the bare direction's
    /// (`camera` module).
    pub up: Option<[f64; 3]>,
    /// Degrees the picture turns counterclockwise about its centre.
    pub roll: f64,
    pub projection: Projection,
    /// Perspective: full field of view across the shorter image side, degrees.
    pub fov: f64,
    /// Magnification (1: the volume's bounding sphere just fits the shorter image side).
    pub zoom: f64,
    /// Sample spacing along the ray of the reference renderer, in voxels of the smallest spacing.
    pub step: f64,
    pub mode: CompositeMode,
    pub shading: bool,
    /// Rays stop once accumulated opacity reaches this (composite).
    pub early_termination: f64,
    /// First-opaque: a sample counts as opaque when its opacity per voxel reaches this.
    pub threshold: f64,
    /// Rays per pixel edge of the reference renderer (anti-aliasing).
    pub supersampling: u32,
    /// Distant lights; none means one white headlight along the view.
    pub lights: Vec<Light>,
    pub material: Material,
}

impl Default for RenderParams {
    fn default() -> Self {
        Self {
            width: 256,
            height: 256,
            view: View {
                azimuth: 65.0,
                elevation: 20.0,
            },
            direction: None,
            up: None,
            roll: 0.0,
            projection: Projection::Parallel,
            fov: 30.0,
            zoom: 1.0,
            step: 0.25,
            mode: CompositeMode::Composite,
            shading: true,
            early_termination: 0.995,
            threshold: 0.5,
            supersampling: 1,
            lights: Vec::new(),
            material: Material::default(),
        }
    }
}

impl RenderParams {
    /// Unit view vector (from the eye into the scene); refuses a zero, NaN or infinite vector.
    pub fn direction(&self) -> Result<DVec3> {
        match self.direction {
            Some(d) => {
                let v = DVec3::from_array(d);
                if !v.is_finite() || v.length() < 1e-12 {
                    return Err(ModelError::View(format!(
                        "direction {d:?} is zero or not finite"
                    )));
                }
                Ok(v.normalize())
            }
            None => self.view.direction(),
        }
    }

    /// Checks everything both renderers need; errors name the parameter.
    pub fn validate(&self) -> Result<()> {
        if self.width == 0 || self.height == 0 || self.width > 8192 || self.height > 8192 {
            return Err(ModelError::Image(format!(
                "size {}x{}: width and height must be 1..=8192",
                self.width, self.height
            )));
        }
        if !(self.step.is_finite() && self.step > 0.0 && self.step <= 4.0) {
            return Err(ModelError::Config(format!(
                "step {}: must be in (0, 4]",
                self.step
            )));
        }
        if !(self.early_termination > 0.0 && self.early_termination <= 1.0) {
            return Err(ModelError::Config(format!(
                "early termination {}: must be in (0, 1]",
                self.early_termination
            )));
        }
        if !(self.threshold > 0.0 && self.threshold <= 1.0) {
            return Err(ModelError::Config(format!(
                "threshold {}: must be in (0, 1]",
                self.threshold
            )));
        }
        if !(self.fov.is_finite() && self.fov > 0.0 && self.fov < 170.0) {
            return Err(ModelError::View(format!(
                "fov {}: must be in (0, 170) degrees",
                self.fov
            )));
        }
        if !(self.zoom.is_finite() && self.zoom > 0.0 && self.zoom <= 100.0) {
            return Err(ModelError::View(format!(
                "zoom {}: must be in (0, 100]",
                self.zoom
            )));
        }
        if !(1..=8).contains(&self.supersampling) {
            return Err(ModelError::Config(format!(
                "supersampling {}: must be 1..=8",
                self.supersampling
            )));
        }
        for (i, l) in self.lights.iter().enumerate() {
            let d = DVec3::from_array(l.direction);
            if !d.is_finite() || d.length() < 1e-12 {
                return Err(ModelError::Config(format!(
                    "light[{i}].direction {:?}: zero or not finite",
                    l.direction
                )));
            }
            if l.colour.iter().any(|c| !(0.0..=4.0).contains(c)) {
                return Err(ModelError::Config(format!(
                    "light[{i}].colour {:?}: each channel must be in 0..=4",
                    l.colour
                )));
            }
        }
        let m = self.material;
        for (name, v, hi) in [
            ("ambient", m.ambient, 4.0),
            ("diffuse", m.diffuse, 4.0),
            ("specular", m.specular, 4.0),
            ("shininess", m.shininess, 1024.0),
        ] {
            if !(0.0..=hi).contains(&v) {
                return Err(ModelError::Config(format!(
                    "shading.{name} {v}: must be in 0..={hi}"
                )));
            }
        }
        let dir = self.direction()?;
        if let Some(u) = self.up {
            if !camera::up_is_usable(dir, DVec3::from_array(u)) {
                return Err(ModelError::View(format!(
                    "up {u:?} is zero, not finite or within {} degrees of the view direction {:?}: it names no image up",
                    camera::MIN_UP_DEGREES,
                    dir.to_array()
                )));
            }
        }
        if !self.roll.is_finite() {
            return Err(ModelError::View(format!(
                "roll {} is not a finite number",
                self.roll
            )));
        }
        Ok(())
    }

    /// The image up (a hint) of a view along `dir`: `up` when set (and usable), else the orbit's
    /// when the view is given by its angles, else the bare direction's (`camera` module).
    pub fn up_hint(&self, dir: DVec3) -> DVec3 {
        match self.up.map(DVec3::from_array) {
            Some(u) if camera::up_is_usable(dir, u) => u,
            _ if self.direction.is_none() => {
                camera::orbit_up_hint(self.view.azimuth, self.view.elevation)
            }
            _ => camera::default_up(dir),
        }
    }

    /// The camera of the view along `dir` (shared with the warp and the slice set-up): its up,
    /// roll and zoom applied.
    pub fn camera(&self, vol: &Volume, dir: DVec3) -> Camera {
        let mut cam = Camera::looking(
            dir,
            self.up_hint(dir),
            vol.dims,
            vol.spacing,
            self.width,
            self.height,
        )
        .rolled(self.roll);
        cam.half /= self.zoom;
        cam
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

/// How far an image is from a reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageError {
    /// `10 log10(1 / MSE)` over the R, G, B channels in 0..1 (infinite for identical images).
    pub psnr_db: f64,
    /// Largest absolute channel difference (0..1).
    pub max_abs: f64,
    /// cube3-paper §6.1: the Euclidean RGB distance per pixel, summed, over the reference's summed
    /// RGB length, percent.
    pub rel_euclid: f64,
    /// The mean Euclidean RGB distance over the largest possible one (`sqrt 3`), percent.
    pub full_scale_euclid: f64,
}

/// The error of `test` against `reference` (same size).
pub fn image_error(test: &ImageF64, reference: &ImageF64) -> ImageError {
    assert_eq!(
        (test.width, test.height),
        (reference.width, reference.height),
        "images of different sizes"
    );
    let (mut se, mut max_abs, mut dist, mut norm) = (0.0, 0.0f64, 0.0, 0.0);
    for (a, b) in test.rgb.iter().zip(&reference.rgb) {
        let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        se += d.iter().map(|x| x * x).sum::<f64>();
        max_abs = d.iter().fold(max_abs, |m, x| m.max(x.abs()));
        dist += d.iter().map(|x| x * x).sum::<f64>().sqrt();
        norm += b.iter().map(|x| x * x).sum::<f64>().sqrt();
    }
    let n = test.rgb.len().max(1) as f64;
    let mse = se / (3.0 * n);
    ImageError {
        psnr_db: if mse > 0.0 {
            10.0 * (1.0 / mse).log10()
        } else {
            f64::INFINITY
        },
        max_abs,
        rel_euclid: if norm > 0.0 { 100.0 * dist / norm } else { 0.0 },
        full_scale_euclid: 100.0 * dist / n / 3f64.sqrt(),
    }
}

/// Phong shading of colour `c` at a sample with `gradient` (physical units), view `dir`.
/// A zero gradient (homogeneous region) is lit as if head-on without specular.
pub fn shade(c: DVec3, gradient: DVec3, dir: DVec3, lights: &[Light], m: &Material) -> DVec3 {
    let len = gradient.length();
    let n = if len < 1e-9 {
        None
    } else {
        Some(gradient / len)
    };
    let to_eye = -dir;
    let mut total = DVec3::splat(m.ambient);
    let mut light = |colour: DVec3, to_light: DVec3| match n {
        None => total += colour * m.diffuse,
        Some(n) => {
            let ndl = n.dot(to_light).abs();
            let h = (to_light + to_eye).normalize_or_zero();
            let ndh = n.dot(h).abs();
            total += colour * (m.diffuse * ndl + m.specular * ndh.powf(m.shininess));
        }
    };
    if lights.is_empty() {
        light(DVec3::ONE, to_eye);
    } else {
        for l in lights {
            light(
                DVec3::from_array(l.colour),
                -DVec3::from_array(l.direction).normalize(),
            );
        }
    }
    c * total
}

// =================================================================================================
// The f64 image-order reference
// =================================================================================================

/// What the f64 renderers sample: the volume normalized to 0..1 (exact tri-linear), its central
/// differences, and the box where interpolation can be non-zero, at the reference's step.
pub(crate) struct Field<'a> {
    vol: &'a Volume,
    spacing: DVec3,
    n: DVec3,
    max_value: f64,
    min_spacing: f64,
    /// Sample spacing along a ray, physical units.
    pub(crate) step_world: f64,
    diag: f64,
}

impl<'a> Field<'a> {
    pub(crate) fn new(vol: &'a Volume, params: &RenderParams) -> Self {
        let spacing = DVec3::from_array(vol.spacing);
        let min_spacing = spacing.min_element();
        let n = DVec3::from_array(vol.dims.map(|d| d as f64));
        Self {
            vol,
            spacing,
            n,
            max_value: f64::from(vol.max_value()),
            min_spacing,
            step_world: params.step * min_spacing,
            diag: (n * spacing).length(),
        }
    }

    fn sample(&self, w: DVec3) -> f64 {
        self.vol.sample_f64((w / self.spacing).to_array()) / self.max_value
    }

    fn gradient(&self, w: DVec3) -> DVec3 {
        let h = self.min_spacing;
        DVec3::new(
            self.sample(w + DVec3::X * h) - self.sample(w - DVec3::X * h),
            self.sample(w + DVec3::Y * h) - self.sample(w - DVec3::Y * h),
            self.sample(w + DVec3::Z * h) - self.sample(w - DVec3::Z * h),
        )
    }

    fn inside(&self, w: DVec3) -> bool {
        let v = w / self.spacing;
        (0..3).all(|a| v[a] >= 0.0 && v[a] <= self.n[a] - 1.0)
    }

    /// The corners of the box where interpolation can be non-zero (physical).
    pub(crate) fn corners(&self) -> [DVec3; 8] {
        let (lo, hi) = (-self.spacing, self.n * self.spacing);
        std::array::from_fn(|c| {
            DVec3::new(
                if c & 1 == 0 { lo.x } else { hi.x },
                if c & 2 == 0 { lo.y } else { hi.y },
                if c & 4 == 0 { lo.z } else { hi.z },
            )
        })
    }

    /// The sample indices `k0..=k1` of the ray `origin + rd * (k * step)` inside that box (the
    /// sample lattice kept), or none.
    pub(crate) fn clip(&self, origin: DVec3, rd: DVec3) -> Option<(i64, i64)> {
        let (lo, hi) = (-self.spacing, self.n * self.spacing);
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        for a in 0..3 {
            if rd[a].abs() < 1e-15 {
                if origin[a] < lo[a] || origin[a] > hi[a] {
                    return None;
                }
            } else {
                let (ta, tb) = ((lo[a] - origin[a]) / rd[a], (hi[a] - origin[a]) / rd[a]);
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            }
        }
        if t0 > t1 {
            return None;
        }
        Some((
            (t0 / self.step_world).ceil() as i64,
            (t1 / self.step_world).floor() as i64,
        ))
    }
}

/// One ray's projection (the mode's accumulator), fed samples front to back.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RayAcc {
    color: DVec3,
    alpha: f64,
    peak: f64,
    low: f64,
    sum: f64,
    hit: Option<[f64; 3]>,
}

impl Default for RayAcc {
    fn default() -> Self {
        Self {
            color: DVec3::ZERO,
            alpha: 0.0,
            peak: 0.0,
            low: f64::INFINITY,
            sum: 0.0,
            hit: None,
        }
    }
}

impl RayAcc {
    /// Adds the sample at `w` (physical) seen along the unit `rd`; true once the ray is finished
    /// (early termination, or first-opaque's hit).
    pub(crate) fn add(
        &mut self,
        f: &Field,
        tf: &TransferFunction,
        params: &RenderParams,
        w: DVec3,
        rd: DVec3,
    ) -> bool {
        let d = f.sample(w);
        match params.mode {
            CompositeMode::Mip => self.peak = self.peak.max(d),
            CompositeMode::Minip => {
                if f.inside(w) {
                    self.low = self.low.min(d);
                }
            }
            CompositeMode::Xray => self.sum += d * f.step_world,
            CompositeMode::FirstOpaque => {
                let [r, g, b, a] = tf.lookup(d);
                if a >= params.threshold {
                    let mut c = DVec3::new(r, g, b);
                    if params.shading {
                        c = shade(c, f.gradient(w), rd, &params.lights, &params.material);
                    }
                    self.hit = Some(c.to_array());
                    return true;
                }
            }
            CompositeMode::Composite => {
                let [r, g, b, a] = tf.lookup(d);
                if a <= 0.0 {
                    return false;
                }
                // Opacity per voxel of path, corrected to the step length.
                let a = 1.0 - (1.0 - a).powf(params.step);
                let mut c = DVec3::new(r, g, b);
                if params.shading {
                    c = shade(c, f.gradient(w), rd, &params.lights, &params.material);
                }
                self.color += (1.0 - self.alpha) * a * c;
                self.alpha += (1.0 - self.alpha) * a;
                if self.alpha >= params.early_termination {
                    return true;
                }
            }
        }
        false
    }

    /// The ray's colour.
    pub(crate) fn finish(&self, f: &Field, mode: CompositeMode) -> [f64; 3] {
        match mode {
            CompositeMode::Mip => [self.peak; 3],
            CompositeMode::Minip => [if self.low.is_finite() { self.low } else { 0.0 }; 3],
            CompositeMode::Xray => [(self.sum / f.diag).min(1.0); 3],
            CompositeMode::FirstOpaque => self.hit.unwrap_or([0.0; 3]),
            CompositeMode::Composite => self.color.to_array(),
        }
    }

    /// The ray's colour with opaque geometry of colour `geo` behind its samples
    /// (docs/numerics/frame.md, "Opaque geometry"): the compositing unit's flush in f64, the
    /// geometry under the ray's colour, weighted by the transparency `1 - min(A, 1)` the mode's
    /// accumulator leaves (composite: the opacity; MIP, X-ray: the peak, the sum; MinIP: the
    /// minimum, none without a sample; first-opaque: 0 or 1), and nothing once the ray finished
    /// (early termination, first-opaque's hit).
    pub(crate) fn finish_over(
        &self,
        f: &Field,
        mode: CompositeMode,
        finished: bool,
        geo: [f64; 3],
    ) -> [f64; 3] {
        let c = self.finish(f, mode);
        if finished {
            return c;
        }
        let a = match mode {
            CompositeMode::Composite => self.alpha,
            CompositeMode::Mip => self.peak,
            CompositeMode::Minip => self.low,
            CompositeMode::Xray => self.sum / f.diag,
            CompositeMode::FirstOpaque => 0.0,
        };
        let t = 1.0 - a.min(1.0);
        std::array::from_fn(|i| c[i] + t * geo[i])
    }
}

/// The eye of a perspective view and the tangent of half its field of view (zoom applied): the eye
/// sits where the bounding sphere just fills the field of view.
pub(crate) fn perspective_eye(params: &RenderParams, cam: &Camera) -> (DVec3, f64) {
    let tan_half = (params.fov.to_radians() / 2.0).tan() / params.zoom;
    let eye_dist = cam.radius * 1.02 / (params.fov.to_radians() / 2.0).sin();
    (cam.centre - cam.dir * eye_dist, tan_half)
}

/// The image of `params` (supersampled as it asks), each sub-pixel's colour from `ray(ndc_x,
/// ndc_y)`, normalized device coordinates in -1..1 (y up).
pub(crate) fn image_of(
    params: &RenderParams,
    ray: impl Fn(f64, f64) -> [f64; 3] + Sync,
) -> ImageF64 {
    let ss = params.supersampling;
    let rgb: Vec<[f64; 3]> = (0..params.width * params.height)
        .into_par_iter()
        .map(|i| {
            let (px, py) = (i % params.width, i / params.width);
            let mut acc = [0.0; 3];
            for sy in 0..ss {
                for sx in 0..ss {
                    let fx = (f64::from(sx) + 0.5) / f64::from(ss);
                    let fy = (f64::from(sy) + 0.5) / f64::from(ss);
                    let ndc_x = (f64::from(px) + fx) / f64::from(params.width) * 2.0 - 1.0;
                    let ndc_y = 1.0 - (f64::from(py) + fy) / f64::from(params.height) * 2.0;
                    let c = ray(ndc_x, ndc_y);
                    for ch in 0..3 {
                        acc[ch] += c[ch];
                    }
                }
            }
            acc.map(|v| v / f64::from(ss * ss))
        })
        .collect();
    ImageF64 {
        width: params.width,
        height: params.height,
        rgb,
    }
}

/// Renders `vol` with the f64 image-order ray caster.
pub fn render_reference(
    vol: &Volume,
    tf: &TransferFunction,
    params: &RenderParams,
) -> Result<ImageF64> {
    render_reference_geometry(vol, tf, params, &[])
}

/// [`render_reference`] with opaque solids in the volume (`geometry`, voxel coordinates): each
/// ray's samples at or behind the first surface it meets are left out, and the surface's colour
/// goes under the ray's ([`RayAcc::finish_over`]).
pub fn render_reference_geometry(
    vol: &Volume,
    tf: &TransferFunction,
    params: &RenderParams,
    geometry: &[crate::geometry::Solid],
) -> Result<ImageF64> {
    params.validate()?;
    tf.validate()?;
    let dir = params.direction()?;
    let cam = params.camera(vol, dir);
    let field = Field::new(vol, params);
    let (eye, tan_half) = perspective_eye(params, &cam);
    let aspect = f64::from(params.width) / f64::from(params.height);

    // One ray: origin, unit direction; samples at origin + dir * (k * step).
    let spacing = DVec3::from_array(vol.spacing);
    let trace = |origin: DVec3, rd: DVec3| -> [f64; 3] {
        let mut acc = RayAcc::default();
        // The first opaque surface: samples at t >= t_hit are hidden.
        let hit = crate::geometry::first_hit(geometry, origin / spacing, rd / spacing);
        let t_hit = hit.map_or(f64::INFINITY, |h| h.0);
        let mut finished = false;
        if let Some((k0, k1)) = field.clip(origin, rd) {
            for k in k0..=k1 {
                let t = k as f64 * field.step_world;
                if t >= t_hit {
                    break;
                }
                if acc.add(&field, tf, params, origin + rd * t, rd) {
                    finished = true;
                    break;
                }
            }
        }
        match hit {
            Some((_, geo)) => acc.finish_over(&field, params.mode, finished, geo),
            None => acc.finish(&field, params.mode),
        }
    };

    Ok(image_of(params, |ndc_x, ndc_y| match params.projection {
        Projection::Parallel => {
            let u = ndc_x * cam.half * aspect.max(1.0);
            let v = ndc_y * cam.half / aspect.min(1.0);
            let origin = cam.centre + cam.right * u + cam.up * v - dir * cam.radius;
            trace(origin, dir)
        }
        Projection::Perspective => {
            let u = ndc_x * tan_half * aspect.max(1.0);
            let v = ndc_y * tan_half / aspect.min(1.0);
            let rd = (dir + cam.right * u + cam.up * v).normalize();
            trace(eye, rd)
        }
    }))
}

// =================================================================================================
// The slice-order pipeline at a quality setting
// =================================================================================================

/// Where the samples of a ray are taken and which voxels interpolate them (cube3-paper §3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Interpolation {
    /// Samples on the slices (no offset): bilinear in the slice (`cube5_frame`); with more than one
    /// sample per slice the samples between slices are tri-linear (patent [212]).
    #[default]
    BilinearSlice,
    /// Samples offset from the slices along the major axis, interpolated between the four
    /// neighbouring discrete rays (an oblique parallelepiped where a discrete ray steps).
    Sheared,
    /// The same sample positions as `sheared`, from the exact 8-neighbourhood (cube3's True3D).
    Trilinear,
}

impl Interpolation {
    pub fn name(self) -> &'static str {
        match self {
            Self::BilinearSlice => "bilinear-slice",
            Self::Sheared => "sheared",
            Self::Trilinear => "trilinear",
        }
    }
}

/// The ABC gradient schemes of cube3-paper §4 (`cube5_gradient`'s modes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(try_from = "u32", into = "u32")]
pub enum GradientScheme {
    /// The frame's: central differences of the six orthogonal neighbours.
    #[default]
    Six,
    Ten,
    TwentySix,
}

impl TryFrom<u32> for GradientScheme {
    type Error = String;
    fn try_from(v: u32) -> std::result::Result<Self, String> {
        match v {
            6 => Ok(Self::Six),
            10 => Ok(Self::Ten),
            26 => Ok(Self::TwentySix),
            _ => Err(format!("gradient neighbourhood {v}: must be 6, 10 or 26")),
        }
    }
}

impl From<GradientScheme> for u32 {
    fn from(g: GradientScheme) -> u32 {
        match g {
            GradientScheme::Six => 6,
            GradientScheme::Ten => 10,
            GradientScheme::TwentySix => 26,
        }
    }
}

impl GradientScheme {
    pub fn mode(self) -> GradientMode {
        match self {
            Self::Six => GradientMode::N6,
            Self::Ten => GradientMode::N10,
            Self::TwentySix => GradientMode::N26,
        }
    }

    /// The block offsets `(di, dj, dk)` the scheme reads (the rest of the 3x3x3 block is unused).
    pub fn offsets(self, dx: i32, dy: i32) -> Vec<(i32, i32, i32)> {
        let mut v = vec![(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)];
        match self {
            Self::Six => v.extend([(0, 0, 1), (0, 0, -1)]),
            Self::Ten => {
                let px = if dx < 0 { 1 } else { -1 };
                let py = if dy < 0 { 1 } else { -1 };
                for u in 0..2 {
                    for w in 0..2 {
                        v.push((u * px, w * py, 1));
                        v.push((-u * px, -w * py, -1));
                    }
                }
            }
            Self::TwentySix => {
                v.clear();
                for dk in -1..=1 {
                    for dj in -1..=1 {
                        for di in -1..=1 {
                            if (di, dj, dk) != (0, 0, 0) {
                                v.push((di, dj, dk));
                            }
                        }
                    }
                }
            }
        }
        v
    }
}

/// The knobs that trade accuracy for speed or area in the pipeline model (a scene's `[quality]`
/// table, every key optional).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Quality {
    /// Voxel width fed to interpolation (`VoxelW`); `None`: the volume's own width (at least 4).
    pub voxel_bits: Option<u32>,
    /// Interpolation weight width (`WeightW`, 2..=12): also the width of the gradient unit's steps.
    pub weight_bits: u32,
    /// Fraction bits of a sample (`FracW`, 0..=8).
    pub frac_bits: u32,
    /// R, G, B code width (classification and shading output), 2..=16.
    #[serde(alias = "color_bits")]
    pub colour_bits: u32,
    /// Sample alpha code width, 2..=16.
    pub alpha_bits: u32,
    /// Fraction bits of the compositing accumulators, 8..=28.
    pub acc_bits: u32,
    /// Samples per slice along the ray (the sample rate), 1..=16.
    pub samples_per_slice: u32,
    /// Base-plane rays per voxel edge (supersampling, patent [212]), 1..=8.
    pub supersampling: u32,
    pub interpolation: Interpolation,
    pub gradient: GradientScheme,
}

impl Default for Quality {
    fn default() -> Self {
        Self {
            voxel_bits: None,
            weight_bits: 8,
            frac_bits: 4,
            colour_bits: 8,
            alpha_bits: 12,
            acc_bits: 20,
            samples_per_slice: 1,
            supersampling: 1,
            interpolation: Interpolation::BilinearSlice,
            gradient: GradientScheme::Six,
        }
    }
}

impl Quality {
    /// The most precise setting the units support (for measuring a scheme's own error).
    pub fn precise() -> Self {
        Self {
            voxel_bits: Some(16),
            weight_bits: 12,
            frac_bits: 8,
            colour_bits: 16,
            alpha_bits: 16,
            acc_bits: 28,
            ..Self::default()
        }
    }

    /// Checks the ranges; the error names the knob (`quality.NAME`).
    pub fn validate(&self) -> Result<()> {
        let checks: [(&str, u32, u32, u32); 8] = [
            ("voxel_bits", self.voxel_bits.unwrap_or(12), 4, 16),
            ("weight_bits", self.weight_bits, 2, 12),
            ("frac_bits", self.frac_bits, 0, 8),
            ("colour_bits", self.colour_bits, 2, 16),
            ("alpha_bits", self.alpha_bits, 2, 16),
            ("acc_bits", self.acc_bits, 8, 28),
            ("samples_per_slice", self.samples_per_slice, 1, 16),
            ("supersampling", self.supersampling, 1, 8),
        ];
        for (name, v, lo, hi) in checks {
            if !(lo..=hi).contains(&v) {
                return Err(ModelError::Config(format!(
                    "quality.{name} {v}: must be {lo}..={hi}"
                )));
            }
        }
        Ok(())
    }

    /// The voxel width used for a volume of `bits` bits.
    pub fn voxel_width(&self, bits: u32) -> u32 {
        self.voxel_bits.unwrap_or(bits.max(4))
    }
}

/// The view set up as `docs/numerics/frame.md` says, in f64 and quantized.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SliceSetup {
    /// Volume axes of `i` (beam), `j` (row) and `k` (slice, the major axis).
    pub axes: [usize; 3],
    /// Edges along `i`, `j`, `k`.
    pub n: [usize; 3],
    /// Slice `s` is `k = nk - 1 - s`.
    pub k_reversed: bool,
    /// Per-slice ray steps `S(2.16)`, raw.
    pub dx_raw: i32,
    pub dy_raw: i32,
    /// Physical distance between slices along a ray over the smallest spacing.
    pub ratio: f64,
    /// Physical distance between slices along a ray.
    pub slice_step: f64,
}

/// Fraction bits of the per-slice steps (`StepW` of the frame contract).
pub const STEP_W: u32 = 16;

impl SliceSetup {
    pub fn new(vol: &Volume, dir: DVec3) -> Result<Self> {
        if !dir.is_finite() || dir.length() < 1e-12 {
            return Err(ModelError::View(format!(
                "view vector {dir:?} is zero or not finite"
            )));
        }
        let d = dir / DVec3::from_array(vol.spacing);
        let mag = d.abs();
        // Ties go to the later axis: z over y over x.
        let k = if mag.z >= mag.x && mag.z >= mag.y {
            2
        } else if mag.y >= mag.x {
            1
        } else {
            0
        };
        let (i, j) = match k {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        let (fdx, fdy) = (d[i] / d[k].abs(), d[j] / d[k].abs());
        let q = |x: f64| (x * f64::from(1u32 << STEP_W)).round() as i32;
        let sp = vol.spacing;
        let along = DVec3::new(fdx * sp[i], fdy * sp[j], sp[k]);
        let min_spacing = sp.iter().copied().fold(f64::INFINITY, f64::min);
        Ok(Self {
            axes: [i, j, k],
            n: [vol.dims[i], vol.dims[j], vol.dims[k]],
            k_reversed: d[k] < 0.0,
            dx_raw: q(fdx),
            dy_raw: q(fdy),
            ratio: along.length() / min_spacing,
            slice_step: along.length(),
        })
    }

    pub fn dx(&self) -> f64 {
        f64::from(self.dx_raw) / f64::from(1u32 << STEP_W)
    }

    pub fn dy(&self) -> f64 {
        f64::from(self.dy_raw) / f64::from(1u32 << STEP_W)
    }

    /// cube3-paper eq. (3): the largest offset from the slices for which every sample stays inside
    /// its sheared neighbourhood, `min(1 - |dx|, 1 - |dy|)`.
    pub fn max_offset(&self) -> f64 {
        (1.0 - self.dx().abs()).min(1.0 - self.dy().abs()).max(0.0)
    }

    /// The offset of the samples from the slices for `scheme`: 0 on the slices; otherwise one half,
    /// halved until it satisfies eq. (3) (cube3-paper §3: "iteratively reduced"), 0 when none does
    /// at `weight_bits`.
    pub fn offset(&self, scheme: Interpolation, weight_bits: u32) -> f64 {
        if scheme == Interpolation::BilinearSlice {
            return 0.0;
        }
        let limit = self.max_offset();
        let lsb = 1.0 / f64::from(1u32 << weight_bits);
        let mut o = 0.5;
        while o > limit && o > lsb {
            o /= 2.0;
        }
        if o > limit {
            0.0
        } else {
            o
        }
    }
}

/// Work and geometry of one pipeline rendering.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PipelineStats {
    /// Base-plane rays (width, height).
    pub base_plane: [usize; 2],
    /// Interpolated samples that reached the compositor (inside the volume, before termination).
    pub samples: u64,
    /// Samples that changed a ray's colour (composite: non-zero opacity).
    pub composited: u64,
    /// Gradients computed.
    pub gradients: u64,
    /// Every sample the slice-order sweep visits: base-plane anchors x slices x samples per slice.
    pub frame_samples: u64,
    /// Offset of the samples from the slices (fraction of a slice).
    pub offset: f64,
    /// Opacity-correction exponent of one sample (physical step over the transfer function's unit).
    pub ratio: f64,
    /// Major (slice) axis: 0 = x, 1 = y, 2 = z.
    pub major_axis: usize,
}

/// A pipeline rendering: the warped image and the work it took.
#[derive(Debug, Clone)]
pub struct PipelineImage {
    pub image: ImageF64,
    pub stats: PipelineStats,
}

/// The volume re-laid in sweep order (i fastest, then j, then slice number), requantized.
struct SweepVolume {
    n: [i64; 3],
    data: Vec<u16>,
}

impl SweepVolume {
    fn new(vol: &Volume, setup: &SliceSetup, voxel_bits: u32) -> Self {
        let [ni, nj, nk] = setup.n;
        let [ai, aj, ak] = setup.axes;
        let from = f64::from(vol.max_value());
        let to = f64::from((1u32 << voxel_bits) - 1);
        let requant = |v: u32| -> u16 {
            if voxel_bits == vol.bits {
                v as u16
            } else {
                (f64::from(v) * to / from).round() as u16
            }
        };
        let mut data = Vec::with_capacity(ni * nj * nk);
        for s in 0..nk {
            let k = if setup.k_reversed { nk - 1 - s } else { s };
            for j in 0..nj {
                for i in 0..ni {
                    let mut p = [0i64; 3];
                    p[ai] = i as i64;
                    p[aj] = j as i64;
                    p[ak] = k as i64;
                    data.push(requant(vol.get(p[0], p[1], p[2])));
                }
            }
        }
        Self {
            n: [ni as i64, nj as i64, nk as i64],
            data,
        }
    }

    fn get(&self, i: i64, j: i64, s: i64) -> u32 {
        let [ni, nj, nk] = self.n;
        if i < 0 || j < 0 || s < 0 || i >= ni || j >= nj || s >= nk {
            return 0;
        }
        u32::from(self.data[(i + ni * (j + nj * s)) as usize])
    }
}

/// Everything a ray needs to take samples, shared by all rays of a frame.
struct Sampler<'a> {
    vol: SweepVolume,
    trilin: Trilin,
    scheme: Interpolation,
    dx: f64,
    dy: f64,
    weight_bits: u32,
    _tf: &'a TransferFunction,
}

impl Sampler<'_> {
    /// Truncates a fraction in [0, 1) to `U(0.WeightW)` (frame contract: floor).
    fn weight(&self, f: f64) -> u32 {
        let one = f64::from(1u32 << self.weight_bits);
        ((f * one).floor() as u32).min((1 << self.weight_bits) - 1)
    }

    /// The raw sample (`U(VoxelW.FracW)`) of the ray through base-plane point `(a, b)` at depth
    /// `t` slices (fractional), by the frame's interpolation scheme.
    fn sample(&self, a: f64, b: f64, t: f64) -> u32 {
        let s = t.floor();
        let w = t - s;
        let si = s as i64;
        let mut voxels = [0u32; 8];
        let weights;
        match self.scheme {
            // On the slices (offset 0) the z weight is 0 and this is bilinear in the slice, exactly
            // (lerp with weight 0 returns its first operand); between slices (more than one
            // sample per slice, patent [212]) the TriLin unit gets the new z weight.
            Interpolation::Trilinear | Interpolation::BilinearSlice => {
                let (x, y) = (a + t * self.dx, b + t * self.dy);
                let (x0, y0) = (x.floor(), y.floor());
                let (i0, j0) = (x0 as i64, y0 as i64);
                for (c, v) in voxels.iter_mut().enumerate() {
                    let (cx, cy, cz) = ((c & 1) as i64, ((c >> 1) & 1) as i64, (c >> 2) as i64);
                    *v = self.vol.get(i0 + cx, j0 + cy, si + cz);
                }
                weights = [self.weight(x - x0), self.weight(y - y0), self.weight(w)];
            }
            Interpolation::Sheared => {
                let (xf, yf) = (a + s * self.dx, b + s * self.dy);
                let (xb, yb) = (xf + self.dx, yf + self.dy);
                let fl = |v: f64| (v.floor() as i64, v - v.floor());
                let ((i_f, fx_f), (j_f, fy_f)) = (fl(xf), fl(yf));
                let ((i_b, fx_b), (j_b, fy_b)) = (fl(xb), fl(yb));
                for (c, v) in voxels.iter_mut().enumerate() {
                    let (cx, cy) = ((c & 1) as i64, ((c >> 1) & 1) as i64);
                    *v = if c < 4 {
                        self.vol.get(i_f + cx, j_f + cy, si)
                    } else {
                        self.vol.get(i_b + cx, j_b + cy, si + 1)
                    };
                }
                let dxw = (1.0 - w) * fx_f + w * fx_b;
                let dyw = (1.0 - w) * fy_f + w * fy_b;
                weights = [self.weight(dxw), self.weight(dyw), self.weight(w)];
            }
        }
        self.trilin.sample(&TrilinIn {
            voxels,
            weights,
            mode: TrilinMode::Lerp,
        })
    }
}

/// Rounds `x` in [0, 1] to a unit-interval code of `bits` bits (`r / (2^bits - 1)`).
fn code(x: f64, bits: u32) -> f64 {
    let m = f64::from(((1u64 << bits) - 1) as u32);
    (x.clamp(0.0, 1.0) * m).round() / m
}

/// Rounds `x` to `bits` fraction bits (an accumulator `U(1.F)`).
fn acc(x: f64, bits: u32) -> f64 {
    let m = f64::from(1u32 << bits);
    (x * m).round() / m
}

/// Renders `vol` with the slice-order pipeline at quality `q` (parallel projection only).
pub fn render_pipeline(
    vol: &Volume,
    tf: &TransferFunction,
    params: &RenderParams,
    q: &Quality,
) -> Result<PipelineImage> {
    params.validate()?;
    tf.validate()?;
    q.validate()?;
    if params.projection != Projection::Parallel {
        return Err(ModelError::Config(
            "view.projection: the slice-order pipeline model renders parallel projections only \
             (perspective needs the ER-perspective unit); render with the reference renderer"
                .into(),
        ));
    }
    let dir = params.direction()?;
    let setup = SliceSetup::new(vol, dir)?;
    let vb = q.voxel_width(vol.bits);
    let trilin = Trilin::new(TrilinConfig::new(vb, q.weight_bits, q.frac_bits)?)?;
    let grad_unit = Gradient::new(GradientConfig::new(vb, q.frac_bits, q.weight_bits)?)?;
    let sampler = Sampler {
        vol: SweepVolume::new(vol, &setup, vb),
        trilin,
        scheme: q.interpolation,
        dx: setup.dx(),
        dy: setup.dy(),
        weight_bits: q.weight_bits,
        _tf: tf,
    };
    let [ni, nj, nk] = setup.n;
    let (dx, dy) = (setup.dx(), setup.dy());
    let ss = f64::from(q.supersampling);
    let r = f64::from(q.samples_per_slice);
    let offset = setup.offset(q.interpolation, q.weight_bits);
    // Base-plane rays: every ray whose path meets the face of any slice.
    let span = |n: usize, d: f64| {
        let travel = (nk as f64 - 1.0) * d;
        let lo = (-(travel.max(0.0)) - 1.0) * ss;
        let hi = (n as f64 - travel.min(0.0)) * ss;
        (lo.floor() as i64, hi.ceil() as i64)
    };
    let (a_lo, a_hi) = span(ni, dx);
    let (b_lo, b_hi) = span(nj, dy);
    let (bw, bh) = ((a_hi - a_lo + 1) as usize, (b_hi - b_lo + 1) as usize);
    let samples_per_ray = ((nk as f64 - 1.0 - offset / r) * r).floor() as u64 + 1;
    let unit_scale = 1.0 / (f64::from(1u32 << q.frac_bits) * f64::from((1u32 << vb) - 1));
    let step_len = setup.ratio / r; // opacity-correction exponent per sample
    let world_step = setup.slice_step / r;
    let diag =
        (DVec3::from_array(vol.dims.map(|d| d as f64)) * DVec3::from_array(vol.spacing)).length();
    // The gradient unit's steps, S(2.WeightW), rounded from the frame's S(2.16).
    let step_raw =
        |raw: i32| (f64::from(raw) / f64::from(1u32 << (STEP_W - q.weight_bits))).round() as i32;
    let (gdx, gdy) = (step_raw(setup.dx_raw), step_raw(setup.dy_raw));
    let offsets = q.gradient.offsets(gdx, gdy);
    let sp = DVec3::from_array(vol.spacing);
    let [ai, aj, ak] = setup.axes;
    let to_world = |g: [i64; 3]| {
        let mut v = DVec3::ZERO;
        v[ai] = g[0] as f64;
        v[aj] = g[1] as f64;
        v[ak] = if setup.k_reversed {
            -(g[2] as f64)
        } else {
            g[2] as f64
        };
        v / sp
    };
    let mode = params.mode;
    let (cb, ab, fb) = (q.colour_bits, q.alpha_bits, q.acc_bits);

    let rays: Vec<([f64; 3], [u64; 3])> = (0..bw * bh)
        .into_par_iter()
        .map(|idx| {
            let a = (a_lo + (idx % bw) as i64) as f64 / ss;
            let b = (b_lo + (idx / bw) as i64) as f64 / ss;
            let mut counts = [0u64; 3];
            let mut color = DVec3::ZERO;
            let mut alpha = 0.0;
            let mut peak = 0u32;
            let mut low = u32::MAX;
            let mut sum = 0.0;
            for m in 0..samples_per_ray {
                let t = (m as f64 + offset) / r;
                let (x, y) = (a + t * dx, b + t * dy);
                // Samples exist at anchors of the face only (frame contract).
                if x < 0.0 || y < 0.0 || x >= ni as f64 || y >= nj as f64 {
                    continue;
                }
                counts[0] += 1;
                let raw = sampler.sample(a, b, t);
                match mode {
                    CompositeMode::Mip => peak = peak.max(raw),
                    CompositeMode::Minip => {
                        if x <= ni as f64 - 1.0 && y <= nj as f64 - 1.0 {
                            low = low.min(raw);
                        }
                    }
                    CompositeMode::Xray => sum += f64::from(raw) * unit_scale * world_step,
                    CompositeMode::Composite | CompositeMode::FirstOpaque => {
                        let d = f64::from(raw) * unit_scale;
                        let [cr, cg, cbl, ca] = tf.lookup(d);
                        let a_code = code(ca, ab);
                        if a_code <= 0.0 {
                            continue;
                        }
                        if mode == CompositeMode::FirstOpaque && ca < params.threshold {
                            continue;
                        }
                        let mut c = DVec3::new(code(cr, cb), code(cg, cb), code(cbl, cb));
                        if params.shading {
                            let mut block = [0u32; 27];
                            for &(di, dj, dk) in &offsets {
                                block[crate::units::cube5_gradient::block_index(di, dj, dk)] =
                                    sampler.sample(
                                        a + f64::from(di),
                                        b + f64::from(dj),
                                        t + f64::from(dk),
                                    );
                            }
                            let g = grad_unit.components(&GradientIn {
                                samples: block,
                                dx: gdx,
                                dy: gdy,
                                mode: q.gradient.mode(),
                            });
                            counts[2] += 1;
                            let lit = shade(c, to_world(g), dir, &params.lights, &params.material);
                            c = DVec3::new(code(lit.x, cb), code(lit.y, cb), code(lit.z, cb));
                        }
                        counts[1] += 1;
                        if mode == CompositeMode::FirstOpaque {
                            color = c;
                            break;
                        }
                        // Opacity correction to the sample spacing, then the over operator.
                        let a_corr = if (step_len - 1.0).abs() < 1e-12 {
                            a_code
                        } else {
                            acc(1.0 - (1.0 - a_code).powf(step_len), ab + 4)
                        };
                        let tr = 1.0 - alpha;
                        color = DVec3::new(
                            acc(color.x + tr * a_corr * c.x, fb),
                            acc(color.y + tr * a_corr * c.y, fb),
                            acc(color.z + tr * a_corr * c.z, fb),
                        );
                        alpha = acc(alpha + tr * a_corr, fb);
                        if alpha >= params.early_termination {
                            break;
                        }
                    }
                }
            }
            let out = match mode {
                CompositeMode::Mip => [f64::from(peak) * unit_scale; 3],
                CompositeMode::Minip => {
                    [if low == u32::MAX {
                        0.0
                    } else {
                        f64::from(low) * unit_scale
                    }; 3]
                }
                CompositeMode::Xray => [acc((sum / diag).min(1.0), fb); 3],
                CompositeMode::Composite | CompositeMode::FirstOpaque => {
                    color.to_array().map(|v| v.min(1.0))
                }
            };
            (out, counts)
        })
        .collect();

    let mut stats = PipelineStats {
        base_plane: [bw, bh],
        frame_samples: (ni * nj) as u64 * (q.supersampling as u64).pow(2) * samples_per_ray,
        offset,
        ratio: step_len,
        major_axis: ak,
        ..Default::default()
    };
    for (_, c) in &rays {
        stats.samples += c[0];
        stats.composited += c[1];
        stats.gradients += c[2];
    }
    let base: Vec<[f64; 3]> = rays.into_iter().map(|(c, _)| c).collect();

    // Warp: follow each pixel's ray back to the front slice and sample the base plane bilinearly.
    let cam = params.camera(vol, dir);
    let dir_v = dir / sp;
    let rgb: Vec<[f64; 3]> = (0..params.width * params.height)
        .into_par_iter()
        .map(|i| {
            let o = cam.ray_origin(i % params.width, i / params.width) / sp;
            let k_front = if setup.k_reversed {
                (nk - 1) as f64
            } else {
                0.0
            };
            let tt = (k_front - o[ak]) / dir_v[ak];
            let p = o + dir_v * tt;
            let u = p[ai] * ss - a_lo as f64;
            let v = p[aj] * ss - b_lo as f64;
            let (u0, v0) = (u.floor(), v.floor());
            let (fu, fv) = (u - u0, v - v0);
            let (u0, v0) = (u0 as i64, v0 as i64);
            let texel = |x: i64, y: i64| {
                if x < 0 || y < 0 || x >= bw as i64 || y >= bh as i64 {
                    [0.0; 3]
                } else {
                    base[y as usize * bw + x as usize]
                }
            };
            let mut c = [0.0; 3];
            for (du, dv, wgt) in [
                (0, 0, (1.0 - fu) * (1.0 - fv)),
                (1, 0, fu * (1.0 - fv)),
                (0, 1, (1.0 - fu) * fv),
                (1, 1, fu * fv),
            ] {
                if wgt == 0.0 {
                    continue;
                }
                let t = texel(u0 + du, v0 + dv);
                for ch in 0..3 {
                    c[ch] += wgt * t[ch];
                }
            }
            c
        })
        .collect();
    Ok(PipelineImage {
        image: ImageF64 {
            width: params.width,
            height: params.height,
            rgb,
        },
        stats,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{head_phantom, sphere_phantom};
    use crate::transfer::TfPoint;

    #[test]
    fn error_measures() {
        let a = ImageF64 {
            width: 2,
            height: 1,
            rgb: vec![[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]],
        };
        let b = ImageF64 {
            rgb: vec![[0.5, 0.0, 0.0], [0.0, 0.0, 0.0]],
            ..a.clone()
        };
        let e = image_error(&b, &a);
        assert!((e.max_abs - 0.5).abs() < 1e-12);
        assert!((e.rel_euclid - 50.0).abs() < 1e-9);
        assert!((e.psnr_db - 10.0 * (1.0f64 / (0.25 / 6.0)).log10()).abs() < 1e-9);
        assert!(image_error(&a, &a).psnr_db.is_infinite());
    }

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

    /// Opaque geometry in the f64 reference: a box that wraps the whole volume hides every sample
    /// (each ray enters it before the volume), so every ray that meets it shows its colour, in
    /// every mode but MinIP (no sample: `A` above 1, nothing shows); rays that miss it see nothing.
    #[test]
    fn geometry_around_the_volume_hides_it() {
        let vol = head_phantom(24, 12).unwrap();
        let boxed = [crate::geometry::Solid::Box {
            min: [-2.0; 3],
            max: [26.0; 3],
            colour: [0.2, 0.4, 0.6],
        }];
        for mode in [
            CompositeMode::Composite,
            CompositeMode::Mip,
            CompositeMode::Xray,
            CompositeMode::FirstOpaque,
            CompositeMode::Minip,
        ] {
            let params = RenderParams {
                width: 32,
                height: 32,
                mode,
                ..Default::default()
            };
            let tf = TransferFunction::head_default();
            let img = render_reference_geometry(&vol, &tf, &params, &boxed).unwrap();
            let centre = img.rgb[16 * 32 + 16];
            let want = if mode == CompositeMode::Minip {
                [0.0; 3]
            } else {
                [0.2, 0.4, 0.6]
            };
            assert!(
                centre.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-12),
                "{mode:?}: {centre:?}"
            );
            assert_eq!(img.rgb[0], [0.0; 3], "{mode:?}: the corner misses the box");
            // Without the box the centre shows the head (MinIP's minimum crosses air: black).
            if mode != CompositeMode::Minip {
                let plain = render_reference(&vol, &tf, &params).unwrap();
                assert_ne!(plain.rgb[16 * 32 + 16], centre, "{mode:?}");
            }
        }
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
        let zero_dir = RenderParams {
            direction: Some([0.0; 3]),
            ..Default::default()
        };
        assert!(render_reference(&vol, &tf, &zero_dir).is_err());
        assert!(render_pipeline(&vol, &tf, &zero_dir, &Quality::default()).is_err());
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
        let e = unsorted.validate().unwrap_err().to_string();
        assert!(e.contains("points[1].density"), "{e}");
        let persp = RenderParams {
            projection: Projection::Perspective,
            ..Default::default()
        };
        assert!(render_pipeline(&vol, &tf, &persp, &Quality::default()).is_err());
        let q = Quality {
            weight_bits: 13,
            ..Quality::default()
        };
        let e = render_pipeline(&vol, &tf, &RenderParams::default(), &q)
            .unwrap_err()
            .to_string();
        assert!(e.contains("quality.weight_bits"), "{e}");
    }

    #[test]
    fn every_mode_renders_in_both_renderers() {
        let vol = sphere_phantom(20, 12).unwrap();
        let tf = TransferFunction::preset("iso").unwrap();
        for mode in [
            CompositeMode::Composite,
            CompositeMode::Mip,
            CompositeMode::Minip,
            CompositeMode::Xray,
            CompositeMode::FirstOpaque,
        ] {
            let params = RenderParams {
                width: 24,
                height: 24,
                mode,
                step: 1.0,
                ..Default::default()
            };
            let a = render_reference(&vol, &tf, &params).unwrap();
            let b = render_pipeline(&vol, &tf, &params, &Quality::default()).unwrap();
            let centre = |img: &ImageF64| img.rgb[12 * 24 + 12].iter().sum::<f64>();
            if mode != CompositeMode::Minip {
                assert!(centre(&a) > 0.01, "{mode:?} reference");
                assert!(centre(&b.image) > 0.01, "{mode:?} pipeline");
            }
            assert!(
                a.rgb[0].iter().sum::<f64>() < 1e-9,
                "{mode:?}: corner is background"
            );
        }
    }

    #[test]
    fn pipeline_tracks_the_reference_on_an_axis_aligned_view() {
        // Looking straight down z, every scheme samples exactly on the slices, so with precise
        // widths the pipeline image equals the reference's up to the warp and the edges.
        let vol = sphere_phantom(24, 12).unwrap();
        let tf = TransferFunction::preset("grey").unwrap();
        let params = RenderParams {
            width: 24,
            height: 24,
            direction: Some([0.0, 0.0, -1.0]),
            mode: CompositeMode::Mip,
            step: 1.0,
            ..Default::default()
        };
        let a = render_reference(&vol, &tf, &params).unwrap();
        for scheme in [
            Interpolation::BilinearSlice,
            Interpolation::Sheared,
            Interpolation::Trilinear,
        ] {
            let q = Quality {
                interpolation: scheme,
                ..Quality::precise()
            };
            let b = render_pipeline(&vol, &tf, &params, &q).unwrap();
            let worst = a
                .rgb
                .iter()
                .zip(&b.image.rgb)
                .map(|(x, y)| (x[0] - y[0]).abs())
                .fold(0.0, f64::max);
            assert!(worst < 0.02, "{scheme:?}: {worst}");
        }
    }

    #[test]
    fn sheared_equals_trilinear_where_no_discrete_ray_steps_and_at_45_degrees() {
        let vol = head_phantom(16, 12).unwrap();
        let tf = TransferFunction::preset("grey").unwrap();
        let at = |dir: [f64; 3], scheme| {
            let params = RenderParams {
                width: 20,
                height: 20,
                direction: Some(dir),
                mode: CompositeMode::Mip,
                ..Default::default()
            };
            let q = Quality {
                interpolation: scheme,
                ..Quality::default()
            };
            render_pipeline(&vol, &tf, &params, &q).unwrap().image.rgb
        };
        // Exactly 45 degrees: the admissible offset is 0, both schemes are bilinear.
        let d45 = [1.0, 1.0, 0.0];
        assert_eq!(
            at(d45, Interpolation::Sheared),
            at(d45, Interpolation::Trilinear)
        );
        // Axis aligned: discrete rays never step.
        let d0 = [0.0, 0.0, 1.0];
        assert_eq!(
            at(d0, Interpolation::Sheared),
            at(d0, Interpolation::Trilinear)
        );
        // In between they differ.
        let d = [0.3, 0.1, 1.0];
        assert_ne!(
            at(d, Interpolation::Sheared),
            at(d, Interpolation::Trilinear)
        );
    }

    #[test]
    fn slice_setup_follows_the_frame_contract() {
        let vol = head_phantom(8, 12).unwrap();
        let s = SliceSetup::new(&vol, DVec3::new(1.0, 1.0, 0.0)).unwrap();
        assert_eq!(s.axes[2], 1, "ties go to the later axis");
        let s = SliceSetup::new(&vol, DVec3::new(-1.0, 0.25, -0.5)).unwrap();
        assert_eq!((s.axes, s.k_reversed), ([1, 2, 0], true));
        assert_eq!((s.dx_raw, s.dy_raw), (1 << 14, -(1 << 15)));
        assert!((s.ratio - (1.0f64 + 0.0625 + 0.25).sqrt()).abs() < 1e-12);
        assert_eq!(s.offset(Interpolation::Sheared, 8), 0.5);
        assert_eq!(s.offset(Interpolation::BilinearSlice, 8), 0.0);
        let s45 = SliceSetup::new(&vol, DVec3::new(1.0, 0.999, 0.0)).unwrap();
        assert!(s45.offset(Interpolation::Sheared, 8) <= s45.max_offset());
    }

    #[test]
    fn lights_colour_the_shading() {
        let m = Material::default();
        let dir = DVec3::new(0.0, 0.0, -1.0);
        let head_on = shade(DVec3::ONE, DVec3::Z, dir, &[], &m);
        assert!((head_on.x - (0.25 + 0.65 + 0.35)).abs() < 1e-12);
        let red = [Light {
            direction: [0.0, 0.0, -1.0],
            colour: [1.0, 0.0, 0.0],
        }];
        let c = shade(DVec3::ONE, DVec3::Z, dir, &red, &m);
        assert!(c.x > 1.0 && (c.y - 0.25).abs() < 1e-12);
    }
}
