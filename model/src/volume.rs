//! A scalar volume of unsigned voxels: the input of every renderer (files: `volume_io`; embedded
//! phantoms: `phantom`).

use crate::error::{ModelError, Result};

/// A scalar volume of unsigned voxels, x fastest. Samples outside the volume read as 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Volume {
    pub dims: [usize; 3],
    /// Physical size of a voxel along each axis (anisotropic CT, say); 1.0 when isotropic.
    pub spacing: [f64; 3],
    /// Voxel width in bits (values are `0 ..= 2^bits - 1`).
    pub bits: u32,
    pub data: Vec<u16>,
}

/// Largest edge accepted anywhere (memory: 1024^3 voxels of 16 bits is 2 GiB).
pub const MAX_EDGE: usize = 1024;

impl Volume {
    pub fn new(dims: [usize; 3], spacing: [f64; 3], bits: u32, data: Vec<u16>) -> Result<Self> {
        if dims.iter().any(|&d| d == 0 || d > MAX_EDGE) {
            return Err(ModelError::Volume(format!(
                "dimensions {dims:?}: each edge must be 1..={MAX_EDGE}"
            )));
        }
        if !(1..=16).contains(&bits) {
            return Err(ModelError::Volume(format!(
                "voxel width {bits} bits: must be 1..=16"
            )));
        }
        if spacing.iter().any(|s| !s.is_finite() || *s <= 0.0) {
            return Err(ModelError::Volume(format!(
                "spacing {spacing:?}: must be finite and > 0"
            )));
        }
        let n = dims[0] * dims[1] * dims[2];
        if data.len() != n {
            return Err(ModelError::Volume(format!(
                "{} voxels given for dimensions {dims:?} ({n} expected)",
                data.len()
            )));
        }
        let max = ((1u32 << bits) - 1) as u16;
        if let Some(i) = data.iter().position(|&v| v > max) {
            return Err(ModelError::Volume(format!(
                "voxel {i} is {} but {bits}-bit voxels stop at {max}",
                data[i]
            )));
        }
        Ok(Self {
            dims,
            spacing,
            bits,
            data,
        })
    }

    pub fn max_value(&self) -> u32 {
        (1u32 << self.bits) - 1
    }

    pub fn len(&self) -> usize {
        self.data.len()
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// Voxel at integer coordinates; 0 outside the volume (the contract's rule for outside samples).
    pub fn get(&self, x: i64, y: i64, z: i64) -> u32 {
        let [nx, ny, nz] = self.dims.map(|d| d as i64);
        if x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz {
            return 0;
        }
        u32::from(self.data[(x + nx * (y + ny * z)) as usize])
    }

    /// Tri-linear interpolation in f64 at continuous voxel coordinates (voxel centres at integers).
    pub fn sample_f64(&self, p: [f64; 3]) -> f64 {
        let f = p.map(f64::floor);
        let t = [p[0] - f[0], p[1] - f[1], p[2] - f[2]];
        let [x, y, z] = f.map(|v| v as i64);
        let mut acc = 0.0;
        for c in 0..8 {
            let (dx, dy, dz) = (c & 1, (c >> 1) & 1, (c >> 2) & 1);
            let w = (if dx == 1 { t[0] } else { 1.0 - t[0] })
                * (if dy == 1 { t[1] } else { 1.0 - t[1] })
                * (if dz == 1 { t[2] } else { 1.0 - t[2] });
            if w != 0.0 {
                acc += w * f64::from(self.get(x + dx, y + dy, z + dz));
            }
        }
        acc
    }
}
