//! Transfer functions: piecewise-linear density to RGBA, and the built-in presets. The shader
//! model (`units::cube5_shader`) builds its classification table from one.

use crate::error::{ModelError, Result};
use serde::{Deserialize, Serialize};

/// A piecewise-linear transfer function from normalized density (0..1) to RGBA; alpha is the
/// opacity of one unit of path length (one voxel of the smallest spacing).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TransferFunction {
    pub points: Vec<TfPoint>,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TfPoint {
    pub density: f64,
    pub rgba: [f64; 4],
}

/// Names of the built-in transfer functions ([`TransferFunction::preset`]).
pub const TF_PRESETS: &[&str] = &["head", "bone", "cube3-bone", "iso", "grey"];

impl TransferFunction {
    pub fn new(points: Vec<TfPoint>) -> Result<Self> {
        let tf = Self { points };
        tf.validate()?;
        Ok(tf)
    }

    /// Checks the points; the error names the point (`points[i].density`, ...).
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(ModelError::Config(format!("transfer function: {m}")));
        if self.points.is_empty() {
            return bad("points: no points".into());
        }
        if self.points.len() > 4096 {
            return bad(format!(
                "points: {} points (at most 4096)",
                self.points.len()
            ));
        }
        for (i, p) in self.points.iter().enumerate() {
            if !(0.0..=1.0).contains(&p.density) {
                return bad(format!("points[{i}].density: {} outside 0..1", p.density));
            }
            if p.rgba.iter().any(|c| !(0.0..=1.0).contains(c)) {
                return bad(format!("points[{i}].rgba: {:?} outside 0..1", p.rgba));
            }
            if i > 0 && p.density < self.points[i - 1].density {
                return bad(format!(
                    "points[{i}].density: {} is below the previous point's {}; densities must be sorted ascending",
                    p.density,
                    self.points[i - 1].density
                ));
            }
        }
        Ok(())
    }

    /// A built-in transfer function by name (see [`TF_PRESETS`]).
    pub fn preset(name: &str) -> Result<Self> {
        let p = |density, rgba| TfPoint { density, rgba };
        let bone = [0.95, 0.92, 0.85];
        Ok(match name {
            "head" => Self::head_default(),
            // Opaque bone, nothing else.
            "bone" => Self {
                points: vec![
                    p(0.0, [0.0; 4]),
                    p(0.78, [bone[0], bone[1], bone[2], 0.0]),
                    p(0.84, [bone[0], bone[1], bone[2], 0.9]),
                    p(1.0, [bone[0], bone[1], bone[2], 0.9]),
                ],
            },
            // cube3-paper §6.1: alpha 0 below 80 (of 255), a linear ramp to 0.75 at 100, 0.75 above.
            "cube3-bone" => Self {
                points: vec![
                    p(0.0, [bone[0], bone[1], bone[2], 0.0]),
                    p(80.0 / 255.0, [bone[0], bone[1], bone[2], 0.0]),
                    p(100.0 / 255.0, [bone[0], bone[1], bone[2], 0.75]),
                    p(1.0, [bone[0], bone[1], bone[2], 0.75]),
                ],
            },
            // An opaque iso-surface at density 0.5 (the sphere phantom's surface).
            "iso" => Self {
                points: vec![
                    p(0.0, [0.0; 4]),
                    p(0.45, [0.80, 0.85, 0.95, 0.0]),
                    p(0.55, [0.80, 0.85, 0.95, 1.0]),
                    p(1.0, [0.80, 0.85, 0.95, 1.0]),
                ],
            },
            // Grey ramp: brightness and a faint opacity grow with density.
            "grey" => Self {
                points: vec![p(0.0, [0.0; 4]), p(1.0, [1.0, 1.0, 1.0, 0.08])],
            },
            _ => {
                return Err(ModelError::Config(format!(
                    "transfer function: unknown preset `{name}` (known: {})",
                    TF_PRESETS.join(", ")
                )))
            }
        })
    }

    /// The default for the head phantom: translucent skin, faint brain, white bone. Its ramps are
    /// wide (no narrow high-opacity band that every bone edge would cross and paint as a ring at
    /// one sample per slice), so the frame model reaches 40 dB against the f64 reference on the
    /// band-limited phantom (docs/scenes.md).
    pub fn head_default() -> Self {
        let p = |density, rgba| TfPoint { density, rgba };
        let skin = [0.93, 0.70, 0.58];
        let brain = [0.90, 0.62, 0.60];
        let bone = [0.96, 0.94, 0.88];
        Self {
            points: vec![
                p(0.00, [0.0; 4]),
                p(0.15, [skin[0], skin[1], skin[2], 0.0]),
                p(0.22, [skin[0], skin[1], skin[2], 0.035]),
                p(0.30, [brain[0], brain[1], brain[2], 0.004]),
                p(0.38, [brain[0], brain[1], brain[2], 0.008]),
                p(0.50, [bone[0], bone[1], bone[2], 0.03]),
                p(0.86, [bone[0], bone[1], bone[2], 0.35]),
                p(1.00, [bone[0], bone[1], bone[2], 0.5]),
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

    /// True when the opacity is zero over the whole density interval `[lo, hi]`.
    pub fn transparent_between(&self, lo: f64, hi: f64) -> bool {
        if self.lookup(lo)[3] > 0.0 || self.lookup(hi)[3] > 0.0 {
            return false;
        }
        self.points
            .iter()
            .filter(|p| p.density > lo && p.density < hi)
            .all(|p| p.rgba[3] <= 0.0)
    }
}
