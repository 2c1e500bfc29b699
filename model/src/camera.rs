//! The orthographic camera shared by the f64 reference renderer and the warp of the base plane,
//! so both frame the volume identically and their images compare pixel for pixel.

use glam::DVec3;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Unit vector from the eye into the scene (physical coordinates).
    pub dir: DVec3,
    pub right: DVec3,
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

impl Camera {
    /// A camera looking along `dir` (unit) at a volume of `dims` voxels with `spacing`.
    pub fn new(dir: DVec3, dims: [usize; 3], spacing: [f64; 3], width: u32, height: u32) -> Self {
        let spacing = DVec3::from_array(spacing);
        let extent = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) * spacing;
        let centre = (extent - spacing) * 0.5;
        let world_up = if dir.z.abs() > 0.999 {
            DVec3::Y
        } else {
            DVec3::Z
        };
        let right = dir.cross(world_up).normalize();
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
