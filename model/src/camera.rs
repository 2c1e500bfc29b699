//! The camera shared by the f64 reference renderer, the warp of the base plane and the RTL set-up,
//! so every renderer frames the volume identically and their images compare pixel for pixel.
//!
//! A view is a direction and an up vector (then a roll about the direction), and the image's axes
//! are `right = normalize(dir x up)`, `up = right x dir`. Where the up vector comes from
//! (docs/scenes.md § `[view]`):
//! - `view.up` when the scene gives one (refused within [`MIN_UP_DEGREES`] of the direction);
//! - an orbit (azimuth and elevation): [`orbit_up_hint`], the direction the eye moves as the
//!   elevation grows, so the image turns continuously through the poles and past them (over the
//!   top, the image is upside down, as the orbit's eye is);
//! - a bare `view.direction`: [`default_up`], +z as seen along the view, and +y when looking
//!   exactly along z. Every rule that takes an up from the direction alone is singular somewhere
//!   (hairy-ball theorem); this one only at the two poles, and a view near them should name its
//!   `up` or be an orbit.
//!
//! `roll` (degrees) turns the picture counterclockwise about its centre (the camera clockwise).

use glam::DVec3;

/// The closest an explicit up vector may come to the view direction, in degrees: nearer than this
/// it names no image up, and a small change of either would turn the image by much more.
pub const MIN_UP_DEGREES: f64 = 0.1;

/// The six principal view directions (+z, -z, +x, -x, +y, -y): the axis-aligned views, each a
/// face of the volume, that every test of a view-dependent unit includes.
pub const FACE_DIRECTIONS: [[f64; 3]; 6] = [
    [0.0, 0.0, 1.0],
    [0.0, 0.0, -1.0],
    [1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
];

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Unit vector from the eye into the scene (physical coordinates).
    pub dir: DVec3,
    /// Unit vector along the image's rows, left to right (`dir x up`).
    pub right: DVec3,
    /// Unit vector along the image's columns, bottom to top.
    pub up: DVec3,
    /// Centre of the volume (physical; voxel centres at integer multiples of the spacing).
    pub centre: DVec3,
    /// Radius of the volume's bounding sphere.
    pub radius: f64,
    /// Half the image extent along the shorter image side.
    pub half: f64,
    pub width: u32,
    pub height: u32,
}

/// The up vector of a bare view direction `dir`: +z as seen along the view; +y when the view is
/// along z (where +z is the direction itself), so looking down -z shows +x right and +y up.
pub fn default_up(dir: DVec3) -> DVec3 {
    if dir.cross(DVec3::Z).length() > 1e-100 {
        DVec3::Z
    } else {
        DVec3::Y
    }
}

/// The up vector (a hint, not unit, to be made orthogonal by [`Camera::looking`]) of an orbit at
/// `azimuth` and `elevation` (degrees): the direction the eye moves as the elevation grows. On the
/// near side of the poles (cos(elevation) > 0) it is +z, past them -z, and at a pole itself the
/// meridian's tangent; the image's right stays the azimuth's tangent `(-sin a, cos a, 0)` for every
/// elevation, so the image turns continuously over the top.
pub fn orbit_up_hint(azimuth: f64, elevation: f64) -> DVec3 {
    let (a, e) = (azimuth.to_radians(), elevation.to_radians());
    let c = e.cos();
    if c.abs() > 1e-9 {
        // Same vectors as the tangent below, and bit for bit the camera of the scenes rendered
        // before roll and up existed (which used +z here).
        DVec3::Z * c.signum()
    } else {
        DVec3::new(-e.sin() * a.cos(), -e.sin() * a.sin(), c)
    }
}

/// Whether the hint `up` names an image up for the unit view `dir`: finite, not zero and at least
/// [`MIN_UP_DEGREES`] away from `dir` and from `-dir`.
pub fn up_is_usable(dir: DVec3, up: DVec3) -> bool {
    let len = up.length();
    up.is_finite()
        && len > 1e-12
        && dir.cross(up / len).length() >= MIN_UP_DEGREES.to_radians().sin()
}

impl Camera {
    /// A camera looking along `dir` (unit) at a volume of `dims` voxels with `spacing`, with the
    /// bare direction's up ([`default_up`]).
    pub fn new(dir: DVec3, dims: [usize; 3], spacing: [f64; 3], width: u32, height: u32) -> Self {
        Self::looking(dir, default_up(dir), dims, spacing, width, height)
    }

    /// A camera looking along `dir` (unit) with image up `up_hint` made orthogonal to `dir`
    /// (`up_hint` must not be parallel to `dir`: see [`up_is_usable`]).
    pub fn looking(
        dir: DVec3,
        up_hint: DVec3,
        dims: [usize; 3],
        spacing: [f64; 3],
        width: u32,
        height: u32,
    ) -> Self {
        let spacing = DVec3::from_array(spacing);
        let extent = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) * spacing;
        let centre = (extent - spacing) * 0.5;
        let right = dir.cross(up_hint).normalize();
        let up = right.cross(dir);
        let radius = extent.length() * 0.5;
        Self {
            dir,
            right,
            up,
            centre,
            radius,
            half: radius * 1.02,
            width,
            height,
        }
    }

    /// The camera turned about its view direction so the picture turns `degrees` counterclockwise
    /// (0: unchanged, bit for bit).
    pub fn rolled(mut self, degrees: f64) -> Self {
        if degrees != 0.0 {
            let (s, c) = degrees.to_radians().sin_cos();
            let (right, up) = (self.right, self.up);
            self.right = right * c - up * s;
            self.up = up * c + right * s;
        }
        self
    }

    /// Image-plane offsets `(u, v)` of pixel `(px, py)` (centre of the pixel).
    pub fn pixel_offset(&self, px: u32, py: u32) -> (f64, f64) {
        let aspect = f64::from(self.width) / f64::from(self.height);
        let u = ((f64::from(px) + 0.5) / f64::from(self.width) * 2.0 - 1.0)
            * self.half
            * aspect.max(1.0);
        let v = (1.0 - (f64::from(py) + 0.5) / f64::from(self.height) * 2.0) * self.half
            / aspect.min(1.0);
        (u, v)
    }

    /// Start of the ray of pixel `(px, py)`, outside the volume's bounding sphere.
    pub fn ray_origin(&self, px: u32, py: u32) -> DVec3 {
        let (u, v) = self.pixel_offset(px, py);
        self.centre + self.right * u + self.up * v - self.dir * self.radius
    }
}
