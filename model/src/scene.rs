//! Scene files (TOML). A scene names the volume, the view, the image and the rendering mode; the
//! embedded default scene needs no file at all.

use crate::error::{ModelError, Result};
use crate::phantom::{head_phantom, Volume};
use crate::render::{CompositeMode, RenderParams, TransferFunction, View};
use serde::{Deserialize, Serialize};
use std::path::Path;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct Scene {
    pub volume: VolumeSpec,
    pub view: ViewSpec,
    pub image: ImageSpec,
    pub render: RenderSpec,
    /// Transfer function; the phantom's default when absent.
    pub transfer: Option<TransferFunction>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VolumeSpec {
    /// Embedded procedural phantom: `head`.
    pub phantom: String,
    /// Edge of the cubic phantom in voxels.
    pub size: usize,
    /// Voxel width in bits.
    pub bits: u32,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ViewSpec {
    pub azimuth: f64,
    pub elevation: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ImageSpec {
    pub width: u32,
    pub height: u32,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderSpec {
    pub mode: CompositeMode,
    pub shading: bool,
    /// Samples per voxel of path is 1/step.
    pub step: f64,
    pub early_termination: f64,
}

impl Default for VolumeSpec {
    fn default() -> Self {
        Self {
            phantom: "head".into(),
            size: 96,
            bits: 12,
        }
    }
}

impl Default for ViewSpec {
    fn default() -> Self {
        Self {
            azimuth: 30.0,
            elevation: 20.0,
        }
    }
}

impl Default for ImageSpec {
    fn default() -> Self {
        Self {
            width: 384,
            height: 384,
        }
    }
}

impl Default for RenderSpec {
    fn default() -> Self {
        let p = RenderParams::default();
        Self {
            mode: p.mode,
            shading: p.shading,
            step: p.step,
            early_termination: p.early_termination,
        }
    }
}

impl Scene {
    /// Reads and validates a scene file; errors name the file, the line and the field.
    pub fn load(path: &Path) -> Result<Self> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| ModelError::Io {
            path: name.clone(),
            source,
        })?;
        Self::parse(&text, &name)
    }

    /// Parses scene text; `origin` names it in error messages.
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        let scene: Scene = toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].lines().count().max(1));
            ModelError::Scene {
                path: match line {
                    Some(l) => format!("{origin}:{l}"),
                    None => origin.to_string(),
                },
                message: e.message().replace('\n', " "),
            }
        })?;
        scene.validate(origin)?;
        Ok(scene)
    }

    pub fn validate(&self, origin: &str) -> Result<()> {
        let bad = |field: &str, m: String| {
            Err(ModelError::Scene {
                path: origin.to_string(),
                message: format!("{field}: {m}"),
            })
        };
        if self.volume.phantom != "head" {
            return bad(
                "volume.phantom",
                format!("unknown phantom `{}` (known: head)", self.volume.phantom),
            );
        }
        if !(4..=512).contains(&self.volume.size) {
            return bad(
                "volume.size",
                format!("{} is outside 4..=512", self.volume.size),
            );
        }
        if !(4..=16).contains(&self.volume.bits) {
            return bad(
                "volume.bits",
                format!("{} is outside 4..=16", self.volume.bits),
            );
        }
        for (field, v) in [
            ("view.azimuth", self.view.azimuth),
            ("view.elevation", self.view.elevation),
        ] {
            if !v.is_finite() {
                return bad(field, format!("{v} is not a finite number"));
            }
        }
        for (field, v) in [
            ("image.width", self.image.width),
            ("image.height", self.image.height),
        ] {
            if !(1..=8192).contains(&v) {
                return bad(field, format!("{v} is outside 1..=8192"));
            }
        }
        if !(self.render.step.is_finite() && self.render.step > 0.0 && self.render.step <= 4.0) {
            return bad(
                "render.step",
                format!("{} is outside (0, 4]", self.render.step),
            );
        }
        if !(self.render.early_termination > 0.0 && self.render.early_termination <= 1.0) {
            return bad(
                "render.early_termination",
                format!("{} is outside (0, 1]", self.render.early_termination),
            );
        }
        if let Some(tf) = &self.transfer {
            if let Err(e) = tf.validate() {
                return bad("transfer", e.to_string());
            }
        }
        Ok(())
    }

    pub fn build_volume(&self) -> Result<Volume> {
        head_phantom(self.volume.size, self.volume.bits)
    }

    pub fn transfer_function(&self) -> TransferFunction {
        self.transfer
            .clone()
            .unwrap_or_else(TransferFunction::head_default)
    }

    pub fn render_params(&self) -> RenderParams {
        RenderParams {
            width: self.image.width,
            height: self.image.height,
            view: View {
                azimuth: self.view.azimuth,
                elevation: self.view.elevation,
            },
            step: self.render.step,
            mode: self.render.mode,
            shading: self.render.shading,
            early_termination: self.render.early_termination,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_text_is_the_default_scene() {
        assert_eq!(Scene::parse("", "x").unwrap(), Scene::default());
    }

    #[test]
    fn errors_name_file_line_and_field() {
        let e = Scene::parse("[view]\nazimuth = \"left\"\n", "s.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("s.toml:2"), "{e}");
        let e = Scene::parse("[image]\nwidth = 0\n", "s.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("image.width"), "{e}");
        let e = Scene::parse("[volume]\nsise = 3\n", "s.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("sise"), "{e}");
        let e = Scene::parse("[view]\nazimuth = nan\n", "s.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("view.azimuth"), "{e}");
    }
}
