//! Scene files (TOML): the volume (an embedded phantom or a raw, NRRD or NIfTI file), the view and
//! projection, the image, the projection mode, the transfer function (points or a named preset),
//! shading and distant lights, the quality knobs of the pipeline model, and what to run. The
//! embedded default scene needs no file at all. `docs/scenes.md` documents every field.
//!
//! A scene also decides what is modelled: [`Plan::new`] works out which units the scene needs
//! (no gradient or shader for MIP or X-ray, no depth test without geometry, no opacity correction
//! at a step of exactly one voxel, ...) and why the others are left out.

use crate::camera;
use crate::er_perspective::{ErMerge, ErScheme};
use crate::error::{ModelError, Result};
use crate::phantom::{phantom_by_name, PHANTOMS};
use crate::prefilter::Prefilter;
use crate::render::{
    CompositeMode, Light, Material, Projection, Quality, RenderParams, SliceSetup, View,
};
use crate::scene_gi::GiSpec;
use crate::slab_perspective::{SlabSpacing, Slabs};
use crate::transfer::{TfPoint, TransferFunction, TF_PRESETS};
use crate::volume::{Volume, MAX_EDGE};
use crate::volume_io::{self, Endian, Format, RawSpec, VoxelType};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};

/// Largest volume edge of the built slice-order RTL configurations (`MaxDim` of `p1`, `p4`, `p8`
/// in `rtl/cube5/cube5_frame.variants`; tb-rs checks the two agree); scenes that run on the RTL
/// (`run.target = "rtl"` or `"both"`) are refused beyond it.
pub const RTL_MAX_EDGE: usize = 128;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct Scene {
    pub volume: VolumeSpec,
    pub view: ViewSpec,
    pub image: ImageSpec,
    pub render: RenderSpec,
    /// Transfer function; the phantom's default when absent.
    pub transfer: Option<TransferSpec>,
    /// Phong coefficients.
    pub shading: Material,
    /// Distant lights (`[[light]]` tables); none means one white headlight.
    #[serde(rename = "light")]
    pub lights: Vec<Light>,
    pub quality: QualitySpec,
    pub run: RunSpec,
    /// Volumetric global illumination on the GI-Cube processor model (`scene_gi`); none: the
    /// slice-order pipeline.
    pub gi: Option<GiSpec>,
    /// Opaque boxes and spheres mixed with the volume (`[geometry]`): the frame's depth test
    /// ([62], [217]-[218]); none: no geometry.
    pub geometry: Option<GeometrySpec>,
    /// The file the scene was loaded from (relative volume paths start from its directory).
    #[serde(skip)]
    pub source: Option<PathBuf>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VolumeSpec {
    /// Embedded procedural phantom (`head`, `sphere`, `bubbles`); `head` when no file is given.
    pub phantom: Option<String>,
    /// Edge of the cubic phantom in voxels.
    pub size: usize,
    /// Voxel width in bits: the phantom's width; for files, the width asked for (unsigned 8- and
    /// 16-bit data must fit it; other types are mapped onto it).
    pub bits: Option<u32>,
    /// A volume file, relative to the scene file's directory.
    pub file: Option<PathBuf>,
    /// `raw`, `nrrd` or `nifti`; from the file name when absent.
    pub format: Option<FormatSpec>,
    /// Raw files: voxels along x, y, z.
    pub dims: Option<[usize; 3]>,
    /// Raw files: `u8` or `u16`.
    #[serde(rename = "type")]
    pub voxel_type: Option<RawType>,
    /// Raw files: byte order of `u16` voxels.
    pub endian: Option<EndianSpec>,
    /// Physical voxel size; overrides the file's.
    pub spacing: Option<[f64; 3]>,
    /// Raw files: header bytes to skip.
    pub offset: u64,
    /// The 3-pass separable pre-filter over the volume before the frame (`none`, `gauss`,
    /// `gauss-narrow`; `crate::prefilter`). A string so an unknown kernel is refused by name.
    pub prefilter: Option<String>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FormatSpec {
    Raw,
    Nrrd,
    Nifti,
}

impl FormatSpec {
    /// The name a scene spells it with.
    pub fn name(self) -> &'static str {
        match self {
            Self::Raw => "raw",
            Self::Nrrd => "nrrd",
            Self::Nifti => "nifti",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RawType {
    U8,
    U16,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EndianSpec {
    Little,
    Big,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ViewSpec {
    pub azimuth: f64,
    pub elevation: f64,
    /// View vector from the eye into the scene; overrides azimuth and elevation.
    pub direction: Option<[f64; 3]>,
    /// Image up (made orthogonal to the view); none: the orbit's, or the bare direction's
    /// (`camera` module).
    pub up: Option<[f64; 3]>,
    /// Degrees the picture turns counterclockwise about its centre.
    pub roll: f64,
    pub projection: Projection,
    /// `run.renderer = "slabs"`: how many parallel slabs approximate the perspective view.
    pub slabs: u32,
    /// `run.renderer = "slabs"`: how the slabs' thicknesses grow along the view.
    pub slab_spacing: SlabSpacing,
    /// `run.renderer = "er"`: rays per voxel at each exponential region's rear (1, 2, 4).
    pub er_rays_per_voxel: u32,
    /// `run.renderer = "er"`: how rays merge at a region boundary (`bartlett`, or the what-if
    /// `centre`).
    pub er_merge: ErMerge,
    /// Perspective: full field of view across the shorter image side, degrees.
    pub fov: f64,
    pub zoom: f64,
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
    /// Reference renderer: sample spacing along the ray in voxels (samples per voxel = 1/step).
    pub step: f64,
    pub early_termination: f64,
    /// First-opaque: the opacity per voxel that counts as opaque.
    pub threshold: f64,
}

/// A transfer function: a named preset or explicit points.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct TransferSpec {
    pub preset: Option<String>,
    pub points: Option<Vec<TfPoint>>,
    /// The 2-D transfer function (density x gradient magnitude, `cube5_shader`'s `tf2d`):
    /// opacity grows with the gradient magnitude up to this fraction of the table's magnitude
    /// range, in (0, 1] (`ClassLut::boundary`). Frame scenes of composite and first-opaque only.
    pub boundary: Option<f64>,
}

/// Opaque geometry (`[geometry]`, docs/scenes.md): boxes and spheres in voxel coordinates, each
/// with its colour, that the host rasterizes into the base plane's RGBA-Z image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct GeometrySpec {
    /// `[[geometry.box]]`: axis-aligned boxes.
    #[serde(rename = "box")]
    pub boxes: Vec<BoxSpec>,
    /// `[[geometry.sphere]]`.
    #[serde(rename = "sphere")]
    pub spheres: Vec<SphereSpec>,
}

/// An opaque axis-aligned box `min ..= max` (voxel coordinates).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    pub min: [f64; 3],
    pub max: [f64; 3],
    /// R, G, B in 0..=1; white when absent.
    #[serde(default = "white", alias = "color")]
    pub colour: [f64; 3],
}

/// An opaque sphere (voxel coordinates).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereSpec {
    pub centre: [f64; 3],
    pub radius: f64,
    /// R, G, B in 0..=1; white when absent.
    #[serde(default = "white", alias = "color")]
    pub colour: [f64; 3],
}

fn white() -> [f64; 3] {
    [1.0; 3]
}

impl GeometrySpec {
    /// The solids, boxes first.
    pub fn solids(&self) -> Vec<crate::geometry::Solid> {
        use crate::geometry::Solid;
        let boxes = self.boxes.iter().map(|b| Solid::Box {
            min: b.min,
            max: b.max,
            colour: b.colour,
        });
        let spheres = self.spheres.iter().map(|s| Solid::Sphere {
            centre: s.centre,
            radius: s.radius,
            colour: s.colour,
        });
        boxes.chain(spheres).collect()
    }

    /// `2 boxes, 1 sphere`.
    pub fn describe(&self) -> String {
        let n =
            |k: usize, one: &str, many: &str| format!("{k} {}", if k == 1 { one } else { many });
        format!(
            "{}, {}",
            n(self.boxes.len(), "box", "boxes"),
            n(self.spheres.len(), "sphere", "spheres")
        )
    }

    /// The first field that is wrong, and why.
    fn refusal(&self) -> Option<(String, String)> {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        let colour_ok = |c: &[f64; 3]| c.iter().all(|x| (0.0..=1.0).contains(x));
        if self.boxes.is_empty() && self.spheres.is_empty() {
            return Some((
                "geometry".into(),
                "give at least one [[geometry.box]] or [[geometry.sphere]]".into(),
            ));
        }
        for (i, b) in self.boxes.iter().enumerate() {
            let f = |x: &str| format!("geometry.box.{x} (box {i})");
            if !finite(&b.min) {
                return Some((f("min"), format!("{:?} is not finite", b.min)));
            }
            if !finite(&b.max) {
                return Some((f("max"), format!("{:?} is not finite", b.max)));
            }
            if (0..3).any(|a| b.max[a] < b.min[a]) {
                return Some((
                    f("max"),
                    format!("{:?} is below min {:?} on some axis", b.max, b.min),
                ));
            }
            if !colour_ok(&b.colour) {
                return Some((
                    f("colour"),
                    format!("{:?}: each channel must be in 0..=1", b.colour),
                ));
            }
        }
        for (i, s) in self.spheres.iter().enumerate() {
            let f = |x: &str| format!("geometry.sphere.{x} (sphere {i})");
            if !finite(&s.centre) {
                return Some((f("centre"), format!("{:?} is not finite", s.centre)));
            }
            if !(s.radius.is_finite() && s.radius > 0.0) {
                return Some((f("radius"), format!("{} must be finite and > 0", s.radius)));
            }
            if !colour_ok(&s.colour) {
                return Some((
                    f("colour"),
                    format!("{:?}: each channel must be in 0..=1", s.colour),
                ));
            }
        }
        None
    }
}

/// The pipeline model's knobs: a scene's `[quality]` table is read straight into `render::Quality`.
pub type QualitySpec = Quality;

/// What to run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct RunSpec {
    pub target: Target,
    pub renderer: Renderer,
    /// Pipelines of the RTL frame the scene elaborates (`cube5 elaborate`, `cube5 cosim`,
    /// `run.target = "rtl"`): 1, 2, 4 or 8; unset: 4 (`scene_elab`).
    pub pipelines: Option<u32>,
}

/// Where the scene runs: the golden model, the RTL (co-simulated), or both compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Target {
    #[default]
    Model,
    Rtl,
    Both,
}

/// Which model renders: the slice-order pipeline at the quality knobs, the f64 reference,
/// perspective approximated by parallel slabs (a what-if, `slab_perspective`), or ER-perspective
/// on the frame's units (`er_perspective`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Renderer {
    #[default]
    Pipeline,
    Reference,
    Slabs,
    Er,
}

impl Renderer {
    pub fn name(self) -> &'static str {
        match self {
            Self::Pipeline => "pipeline",
            Self::Reference => "reference",
            Self::Slabs => "slabs",
            Self::Er => "er",
        }
    }
}

impl Default for VolumeSpec {
    fn default() -> Self {
        Self {
            phantom: None,
            size: 96,
            bits: None,
            file: None,
            format: None,
            dims: None,
            voxel_type: None,
            endian: None,
            spacing: None,
            offset: 0,
            prefilter: None,
        }
    }
}

impl Default for ViewSpec {
    fn default() -> Self {
        let p = RenderParams::default();
        Self {
            azimuth: p.view.azimuth,
            elevation: p.view.elevation,
            direction: p.direction,
            up: p.up,
            roll: p.roll,
            projection: p.projection,
            slabs: 8,
            slab_spacing: SlabSpacing::Equal,
            er_rays_per_voxel: 1,
            er_merge: ErMerge::Bartlett,
            fov: p.fov,
            zoom: p.zoom,
        }
    }
}

impl ViewSpec {
    /// Command-line angles (`--azimuth`, `--elevation`): they apply. A scene that gives a view
    /// `direction` has it replaced by the orbit at the given angles, the angle not given read off
    /// the direction (a zero or non-finite direction stays, for validation to name).
    pub fn set_angles(&mut self, azimuth: Option<f64>, elevation: Option<f64>) {
        if azimuth.is_none() && elevation.is_none() {
            return;
        }
        if let Some(d) = self.direction {
            let eye = -DVec3::from_array(d);
            let len = eye.length();
            let known = eye.is_finite() && len > 1e-12;
            if !known && (azimuth.is_none() || elevation.is_none()) {
                return;
            }
            if known {
                let eye = eye / len;
                self.azimuth = eye.y.atan2(eye.x).to_degrees();
                self.elevation = eye.z.clamp(-1.0, 1.0).asin().to_degrees();
            }
            self.direction = None;
        }
        if let Some(a) = azimuth {
            self.azimuth = a;
        }
        if let Some(e) = elevation {
            self.elevation = e;
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
            threshold: p.threshold,
        }
    }
}

impl Target {
    pub fn name(self) -> &'static str {
        match self {
            Self::Model => "model",
            Self::Rtl => "rtl",
            Self::Both => "both",
        }
    }

    pub fn uses_rtl(self) -> bool {
        self != Self::Model
    }
}

/// Strips the error kind's prefix (`configuration: `, ...) from a model error's text.
fn inner(e: &ModelError) -> String {
    match e {
        ModelError::Config(m)
        | ModelError::View(m)
        | ModelError::Image(m)
        | ModelError::Volume(m) => m.clone(),
        other => other.to_string(),
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
        let mut scene = Self::parse(&text, &name)?;
        scene.source = Some(path.to_path_buf());
        Ok(scene)
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

    /// The name errors use for this scene: its file, or `origin`.
    fn origin_or(&self, origin: &str) -> String {
        self.source
            .as_ref()
            .map_or(origin.to_string(), |p| p.display().to_string())
    }

    /// Checks every field that can be checked without reading the volume; the error names the
    /// field (`view.direction`, `transfer.points[2].density`, `quality.weight_bits`, ...).
    pub fn validate(&self, origin: &str) -> Result<()> {
        let origin = self.origin_or(origin);
        let bad = |field: &str, m: String| {
            Err(ModelError::Scene {
                path: origin.clone(),
                message: format!("{field}: {m}"),
            })
        };
        let v = &self.volume;
        match (&v.phantom, &v.file) {
            (Some(_), Some(_)) => {
                return bad("volume", "give either `phantom` or `file`, not both".into())
            }
            (_, None) => {
                let name = v.phantom.as_deref().unwrap_or("head");
                if !PHANTOMS.contains(&name) {
                    return bad(
                        "volume.phantom",
                        format!("unknown phantom `{name}` (known: {})", PHANTOMS.join(", ")),
                    );
                }
                if !(4..=MAX_EDGE).contains(&v.size) {
                    return bad(
                        "volume.size",
                        format!("{} is outside 4..={MAX_EDGE}", v.size),
                    );
                }
                for (field, set) in [
                    ("volume.dims", v.dims.is_some()),
                    ("volume.type", v.voxel_type.is_some()),
                    ("volume.endian", v.endian.is_some()),
                    ("volume.format", v.format.is_some()),
                ] {
                    if set {
                        return bad(field, "only applies to a volume `file`".into());
                    }
                }
            }
            (None, Some(file)) => {
                let format = match v.format {
                    Some(FormatSpec::Raw) => Format::Raw,
                    Some(FormatSpec::Nrrd) => Format::Nrrd,
                    Some(FormatSpec::Nifti) => Format::Nifti,
                    None => match Format::from_path(file) {
                        Some(f) => f,
                        None => {
                            return bad(
                                "volume.format",
                                format!(
                                    "cannot tell the format of `{}` from its name; say `format = \"raw\"`, `\"nrrd\"` or `\"nifti\"`",
                                    file.display()
                                ),
                            )
                        }
                    },
                };
                if format == Format::Raw {
                    let Some(dims) = v.dims else {
                        return bad(
                            "volume.dims",
                            "a raw file needs `dims = [nx, ny, nz]`".into(),
                        );
                    };
                    if dims.iter().any(|&d| d == 0 || d > MAX_EDGE) {
                        return bad(
                            "volume.dims",
                            format!("{dims:?}: each edge must be 1..={MAX_EDGE}"),
                        );
                    }
                    if v.voxel_type.is_none() {
                        return bad(
                            "volume.type",
                            "a raw file needs `type = \"u8\"` or `\"u16\"`".into(),
                        );
                    }
                } else {
                    for (field, set) in [
                        ("volume.dims", v.dims.is_some()),
                        ("volume.type", v.voxel_type.is_some()),
                        ("volume.endian", v.endian.is_some()),
                        ("volume.offset", v.offset != 0),
                    ] {
                        if set {
                            return bad(
                                field,
                                "only applies to raw files (the header says it)".into(),
                            );
                        }
                    }
                }
            }
        }
        if let Some(b) = v.bits {
            if !(1..=16).contains(&b) {
                return bad("volume.bits", format!("{b} is outside 1..=16"));
            }
        }
        if let Some(s) = v.spacing {
            if s.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
                return bad(
                    "volume.spacing",
                    format!("{s:?}: each must be finite and > 0"),
                );
            }
        }
        for (field, x) in [
            ("view.azimuth", self.view.azimuth),
            ("view.elevation", self.view.elevation),
            ("view.roll", self.view.roll),
        ] {
            if !x.is_finite() {
                return bad(field, format!("{x} is not a finite number"));
            }
        }
        if let Some(d) = self.view.direction {
            if d.iter().any(|x| !x.is_finite()) {
                return bad("view.direction", format!("{d:?} is not finite"));
            }
            if d.iter().map(|x| x * x).sum::<f64>() < 1e-24 {
                return bad("view.direction", format!("{d:?} is the zero vector"));
            }
        }
        if let Some(u) = self.view.up {
            if u.iter().any(|x| !x.is_finite()) || u.iter().map(|x| x * x).sum::<f64>() < 1e-24 {
                return bad("view.up", format!("{u:?} is zero or not finite"));
            }
            if let Ok(dir) = self.render_params().direction() {
                if !camera::up_is_usable(dir, DVec3::from_array(u)) {
                    return bad(
                        "view.up",
                        format!(
                            "{u:?} is within {} degrees of the view direction {:?}: it names no image up",
                            camera::MIN_UP_DEGREES,
                            dir.to_array()
                        ),
                    );
                }
            }
        }
        if !(self.view.fov.is_finite() && self.view.fov > 0.0 && self.view.fov < 170.0) {
            return bad(
                "view.fov",
                format!("{} is outside (0, 170) degrees", self.view.fov),
            );
        }
        if !(self.view.zoom.is_finite() && self.view.zoom > 0.0 && self.view.zoom <= 100.0) {
            return bad(
                "view.zoom",
                format!("{} is outside (0, 100]", self.view.zoom),
            );
        }
        for (field, x) in [
            ("image.width", self.image.width),
            ("image.height", self.image.height),
        ] {
            if !(1..=8192).contains(&x) {
                return bad(field, format!("{x} is outside 1..=8192"));
            }
        }
        let r = &self.render;
        if !(r.step.is_finite() && r.step > 0.0 && r.step <= 4.0) {
            return bad("render.step", format!("{} is outside (0, 4]", r.step));
        }
        if !(r.early_termination > 0.0 && r.early_termination <= 1.0) {
            return bad(
                "render.early_termination",
                format!("{} is outside (0, 1]", r.early_termination),
            );
        }
        if !(r.threshold > 0.0 && r.threshold <= 1.0) {
            return bad(
                "render.threshold",
                format!("{} is outside (0, 1]", r.threshold),
            );
        }
        if let Some(t) = &self.transfer {
            match (&t.preset, &t.points) {
                (Some(_), Some(_)) => {
                    return bad(
                        "transfer",
                        "give either `preset` or `points`, not both".into(),
                    )
                }
                (None, None) if t.boundary.is_none() => {
                    return bad("transfer", "give `preset` or `points`".into())
                }
                (None, None) => {}
                (Some(p), None) => {
                    if !TF_PRESETS.contains(&p.as_str()) {
                        return bad(
                            "transfer.preset",
                            format!("unknown preset `{p}` (known: {})", TF_PRESETS.join(", ")),
                        );
                    }
                }
                (None, Some(points)) => {
                    let tf = TransferFunction {
                        points: points.clone(),
                    };
                    if let Err(e) = tf.validate() {
                        let m = inner(&e);
                        let m = m.strip_prefix("transfer function: ").unwrap_or(&m);
                        let (field, rest) = m.split_once(": ").unwrap_or(("points", m));
                        return bad(&format!("transfer.{field}"), rest.to_string());
                    }
                }
            }
        }
        if let Some(name) = &v.prefilter {
            if Prefilter::from_name(name).is_none() {
                return bad(
                    "volume.prefilter",
                    format!(
                        "unknown kernel `{name}` (known: {})",
                        crate::prefilter::PREFILTER_NAMES.join(", ")
                    ),
                );
            }
            if self.gi.is_some() && self.prefilter() != Prefilter::None {
                return bad(
                    "volume.prefilter",
                    "the GI-Cube processor model has no pre-pass (the pre-filter runs before cube5_frame)".into(),
                );
            }
        }
        if let Some(b) = self.transfer.as_ref().and_then(|t| t.boundary) {
            if !(b > 0.0 && b <= 1.0) {
                return bad("transfer.boundary", format!("{b} is outside (0, 1]"));
            }
            if self.gi.is_some() {
                return bad(
                    "transfer.boundary",
                    "the GI-Cube processor model classifies by density alone (no 2-D transfer function)".into(),
                );
            }
            if !r.mode.classifies() {
                return bad(
                    "transfer.boundary",
                    format!(
                        "the 2-D transfer function classifies by the transfer function (composite, first-opaque); render.mode = \"{}\" classifies by density alone",
                        r.mode.name()
                    ),
                );
            }
        }
        let m = &self.shading;
        for (name, x, hi) in [
            ("ambient", m.ambient, 4.0),
            ("diffuse", m.diffuse, 4.0),
            ("specular", m.specular, 4.0),
            ("shininess", m.shininess, 1024.0),
        ] {
            if !(0.0..=hi).contains(&x) {
                return bad(
                    &format!("shading.{name}"),
                    format!("{x} is outside 0..={hi}"),
                );
            }
        }
        for (i, l) in self.lights.iter().enumerate() {
            if l.direction.iter().any(|x| !x.is_finite())
                || l.direction.iter().map(|x| x * x).sum::<f64>() < 1e-24
            {
                return bad(
                    &format!("light[{i}].direction"),
                    format!("{:?} is zero or not finite", l.direction),
                );
            }
            if l.colour.iter().any(|c| !(0.0..=4.0).contains(c)) {
                return bad(
                    &format!("light[{i}].colour"),
                    format!("{:?}: each channel must be in 0..=4", l.colour),
                );
            }
        }
        if let Err(e) = self.quality().validate() {
            let m = inner(&e);
            let (field, rest) = m.split_once(' ').unwrap_or((&m, ""));
            return bad(field, rest.to_string());
        }
        if let Some(gi) = &self.gi {
            if let Err((field, m)) = crate::scene_gi::validate(self, gi) {
                return bad(&field, m);
            }
        }
        if let Some(g) = &self.geometry {
            if let Some((field, m)) = g.refusal() {
                return bad(&field, m);
            }
            if self.gi.is_some() {
                return bad(
                    "geometry",
                    "the GI-Cube processor model has no depth test (no opaque geometry)".into(),
                );
            }
            if matches!(self.run.renderer, Renderer::Slabs | Renderer::Er) {
                return bad(
                    "geometry",
                    format!(
                        "opaque geometry renders on the frame (renderer \"pipeline\") and the f64 reference (\"reference\"), not on renderer \"{}\"",
                        self.run.renderer.name()
                    ),
                );
            }
        }
        if self.run.renderer == Renderer::Pipeline
            && self.view.projection == Projection::Perspective
            && self.gi.is_none()
        {
            return bad(
                "view.projection",
                "perspective is rendered by the reference renderer (the slice-order pipeline model is parallel); set `run.renderer = \"reference\"` (exact), `\"er\"` (ER-perspective on the frame's units) or `\"slabs\"` (parallel slabs, a what-if)".into(),
            );
        }
        if self.run.renderer == Renderer::Slabs {
            if self.view.projection != Projection::Perspective {
                return bad(
                    "run.renderer",
                    "`slabs` approximates a perspective view; set `view.projection = \"perspective\"`".into(),
                );
            }
            if let Err(e) = self.slabs().validate() {
                return bad("view.slabs", inner(&e));
            }
        }
        if self.run.renderer == Renderer::Er && self.gi.is_none() {
            if let Err((field, m)) = self.er_refusal() {
                return bad(&field, m);
            }
        }
        if self.run.target.uses_rtl() && self.run.renderer != Renderer::Pipeline {
            return bad(
                "run.renderer",
                format!(
                    "target `{}` runs the RTL pipeline, which renderer `{}` is not; use `renderer = \"pipeline\"`",
                    self.run.target.name(),
                    self.run.renderer.name()
                ),
            );
        }
        if let Some(p) = self.run.pipelines {
            if ![1, 2, 4, 8].contains(&p) {
                return bad(
                    "run.pipelines",
                    format!("{p}: the RTL frame has 1, 2, 4 or 8 pipelines"),
                );
            }
        }
        if self.run.target.uses_rtl() && v.file.is_none() && v.size > RTL_MAX_EDGE {
            return bad(
                "volume.size",
                format!(
                    "{} exceeds the configured RTL's {RTL_MAX_EDGE} voxels per edge (run.target = \"{}\")",
                    v.size,
                    self.run.target.name()
                ),
            );
        }
        Ok(())
    }

    /// The volume file's path, resolved against the scene file's directory.
    pub fn volume_path(&self) -> Option<PathBuf> {
        let file = self.volume.file.as_ref()?;
        Some(match &self.source {
            Some(src) if file.is_relative() => src
                .parent()
                .filter(|p| !p.as_os_str().is_empty())
                .map_or(file.clone(), |d| d.join(file)),
            _ => file.clone(),
        })
    }

    /// Builds (phantom) or reads (file) the volume and checks it: not constant, and within the RTL's
    /// limit when the scene runs on the RTL. Errors name the scene file and the field.
    pub fn build_volume(&self) -> Result<Volume> {
        let origin = self.origin_or("scene");
        let scene_err = |field: &str, m: String| ModelError::Scene {
            path: origin.clone(),
            message: format!("{field}: {m}"),
        };
        let v = &self.volume;
        let mut vol = match self.volume_path() {
            None => {
                let name = v.phantom.as_deref().unwrap_or("head");
                phantom_by_name(name, v.size, v.bits.unwrap_or(12))
                    .map_err(|e| scene_err("volume.phantom", inner(&e)))?
            }
            Some(path) => {
                let format = match v.format {
                    Some(FormatSpec::Raw) => Format::Raw,
                    Some(FormatSpec::Nrrd) => Format::Nrrd,
                    Some(FormatSpec::Nifti) => Format::Nifti,
                    None => Format::from_path(&path).unwrap_or(Format::Raw),
                };
                let read = match format {
                    Format::Raw => volume_io::read_raw(
                        &path,
                        &RawSpec {
                            dims: v.dims.unwrap_or([0; 3]),
                            voxel_type: match v.voxel_type {
                                Some(RawType::U16) => VoxelType::U16,
                                _ => VoxelType::U8,
                            },
                            endian: match v.endian {
                                Some(EndianSpec::Big) => Endian::Big,
                                _ => Endian::Little,
                            },
                            spacing: v.spacing.unwrap_or([1.0; 3]),
                            offset: v.offset,
                        },
                        v.bits,
                    ),
                    Format::Nrrd => volume_io::read_nrrd(&path, v.bits),
                    Format::Nifti => volume_io::read_nifti(&path, v.bits),
                };
                // An explicit format is named: it decided how the file was read.
                let field = match v.format {
                    Some(f) => format!("volume.file (as volume.format = \"{}\")", f.name()),
                    None => "volume.file".to_string(),
                };
                read.map_err(|e| scene_err(&field, inner(&e)))?
            }
        };
        if let Some(s) = v.spacing {
            vol.spacing = s;
        }
        let first = vol.data.first().copied();
        if vol.is_empty() {
            return Err(scene_err("volume", "the volume has no voxels".into()));
        }
        if let Some(c) = first {
            if vol.data.iter().all(|&x| x == c) {
                return Err(scene_err(
                    "volume",
                    format!(
                        "every voxel is {c}: a constant volume renders as a flat image (nothing to see)"
                    ),
                ));
            }
        }
        if self.run.target.uses_rtl() && vol.dims.iter().any(|&d| d > RTL_MAX_EDGE) {
            return Err(scene_err(
                if v.file.is_some() { "volume.file" } else { "volume.size" },
                format!(
                    "{} x {} x {} exceeds the configured RTL's {RTL_MAX_EDGE} voxels per edge (run.target = \"{}\")",
                    vol.dims[0],
                    vol.dims[1],
                    vol.dims[2],
                    self.run.target.name()
                ),
            ));
        }
        Ok(vol)
    }

    /// The pre-filter `volume.prefilter` asks for (`Prefilter::None` when unset; `validate`
    /// refuses unknown names).
    pub fn prefilter(&self) -> Prefilter {
        self.volume
            .prefilter
            .as_deref()
            .and_then(Prefilter::from_name)
            .unwrap_or_default()
    }

    /// The 2-D transfer function's `transfer.boundary`, if asked for.
    pub fn boundary(&self) -> Option<f64> {
        self.transfer.as_ref().and_then(|t| t.boundary)
    }

    pub fn transfer_function(&self) -> TransferFunction {
        match &self.transfer {
            Some(TransferSpec {
                points: Some(points),
                ..
            }) => TransferFunction {
                points: points.clone(),
            },
            Some(TransferSpec {
                preset: Some(p), ..
            }) => TransferFunction::preset(p).unwrap_or_else(|_| TransferFunction::head_default()),
            _ => match (self.volume.file.is_some(), self.volume.phantom.as_deref()) {
                (false, Some("sphere")) => {
                    TransferFunction::preset("iso").expect("built-in preset")
                }
                (false, Some("bubbles")) => {
                    TransferFunction::preset("grey").expect("built-in preset")
                }
                _ => TransferFunction::head_default(),
            },
        }
    }

    pub fn render_params(&self) -> RenderParams {
        RenderParams {
            width: self.image.width,
            height: self.image.height,
            view: View {
                azimuth: self.view.azimuth,
                elevation: self.view.elevation,
            },
            direction: self.view.direction,
            up: self.view.up,
            roll: self.view.roll,
            projection: self.view.projection,
            fov: self.view.fov,
            zoom: self.view.zoom,
            step: self.render.step,
            mode: self.render.mode,
            shading: self.render.shading,
            early_termination: self.render.early_termination,
            threshold: self.render.threshold,
            supersampling: self.quality.supersampling.clamp(1, 8),
            lights: self.lights.clone(),
            material: self.shading,
        }
    }

    pub fn quality(&self) -> Quality {
        self.quality
    }

    /// The ER-perspective scheme of `run.renderer = "er"` (`view.er_rays_per_voxel`,
    /// `view.er_merge`).
    pub fn er(&self) -> ErScheme {
        ErScheme {
            rays_per_voxel: self.view.er_rays_per_voxel,
            merge: self.view.er_merge,
        }
    }

    /// What `run.renderer = "er"` cannot take, as (field, message): a parallel view, a mode other
    /// than composite and MIP, a base rate other than 1, 2, 4, quality knobs other than the
    /// frame's sampling, widths the frame refuses.
    fn er_refusal(&self) -> std::result::Result<(), (String, String)> {
        let no = |f: &str, m: &str| Err((f.to_string(), m.to_string()));
        if self.view.projection != Projection::Perspective {
            return no(
                "run.renderer",
                "`er` renders a perspective view; set `view.projection = \"perspective\"`",
            );
        }
        if let Err(e) = self.er().validate() {
            return no("view.er_rays_per_voxel", &inner(&e));
        }
        if !matches!(
            self.render.mode,
            CompositeMode::Composite | CompositeMode::Mip
        ) {
            return no(
                "render.mode",
                &format!(
                    "\"{}\": ER-perspective composites back to front (composite) or takes maxima (mip)",
                    self.render.mode.name()
                ),
            );
        }
        let q = self.quality();
        let frame = Quality::default();
        for (field, differs) in [
            ("interpolation", q.interpolation != frame.interpolation),
            ("samples_per_slice", q.samples_per_slice != 1),
            ("gradient", q.gradient != frame.gradient),
        ] {
            if differs {
                return no(
                    &format!("quality.{field}"),
                    "ER-perspective samples as the frame does (bilinear on the slices, one sample per slice, the 6-neighbourhood gradient)",
                );
            }
        }
        if let Err(e) = crate::scene_render::frame_config(self) {
            return no("quality", &inner(&e));
        }
        Ok(())
    }

    /// The slab scheme of `run.renderer = "slabs"` (`view.slabs`, `view.slab_spacing`).
    pub fn slabs(&self) -> Slabs {
        Slabs {
            count: self.view.slabs,
            spacing: self.view.slab_spacing,
        }
    }
}

// =================================================================================================
// The plan: which units a scene needs
// =================================================================================================

/// A unit of the pipeline, as the plan names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Unit {
    /// `cube5_trilin`: interpolation of every sample.
    Trilin,
    /// `cube5_gradient`: ABC gradients, for shading.
    Gradient,
    /// `cube5_shader`: classification LUT and reflectance map.
    Shader,
    /// `cube5_compos`: the projection mode.
    Compos,
    /// Opacity correction `1 - (1 - a)^ratio` in the compositing unit's LUT.
    OpacityCorrection,
    /// Rays stop once opaque.
    EarlyTermination,
    /// Depth test against opaque geometry in the compositing buffer.
    DepthTest,
    /// More base-plane rays per voxel.
    Supersampling,
    /// Skipping blocks the transfer function makes transparent.
    EmptySpaceSkip,
    /// Warp of the base-plane image onto the image.
    Warp,
    /// ER-perspective (exponential regions).
    Perspective,
    /// The 3-pass separable pre-filter over the volume (`cube5_sepconv`, `volume.prefilter`).
    Prefilter,
}

impl Unit {
    pub fn name(self) -> &'static str {
        match self {
            Self::Trilin => "trilin",
            Self::Gradient => "gradient",
            Self::Shader => "shader",
            Self::Compos => "compos",
            Self::OpacityCorrection => "opacity correction",
            Self::EarlyTermination => "early termination",
            Self::DepthTest => "depth test",
            Self::Supersampling => "supersampling",
            Self::EmptySpaceSkip => "empty-space skip",
            Self::Warp => "warp",
            Self::Perspective => "perspective",
            Self::Prefilter => "prefilter",
        }
    }
}

/// One line of a plan: a unit, whether the scene needs it, and its setting or the reason it is
/// left out.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanEntry {
    pub unit: Unit,
    pub needed: bool,
    pub detail: String,
}

impl PlanEntry {
    pub fn new(unit: Unit, needed: bool, detail: String) -> Self {
        Self {
            unit,
            needed,
            detail,
        }
    }
}

/// What a scene needs modelled (and, later, built and simulated on the RTL side).
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The model that renders: the frame (the hardware's bits) or a what-if, with the reasons.
    pub model: String,
    pub entries: Vec<PlanEntry>,
    pub renderer: Renderer,
    pub target: Target,
}

/// Edge of the blocks the empty-space count uses.
pub const SKIP_BLOCK: usize = 8;

impl Plan {
    /// Works out the plan of `scene` for `vol` (the volume decides empty-space skipping).
    pub fn new(scene: &Scene, vol: &Volume) -> Result<Self> {
        if scene.gi.is_some() {
            return crate::scene_gi::plan(scene, vol);
        }
        let params = scene.render_params();
        let q = scene.quality();
        let mode = params.mode;
        let tf = scene.transfer_function();
        let dir = params.direction()?;
        let setup = SliceSetup::new(vol, dir)?;
        let ratio = setup.ratio / f64::from(q.samples_per_slice);
        let mut entries = Vec::new();
        let mut add = |unit, needed, detail| entries.push(PlanEntry::new(unit, needed, detail));
        let mname = mode.name().to_uppercase();
        let vb = q.voxel_width(vol.bits);
        let offset = setup.offset(q.interpolation, q.weight_bits);
        add(
            Unit::Trilin,
            true,
            format!(
                "{}{}, U({vb}.{}) samples, {}-bit weights{}",
                q.interpolation.name(),
                if offset > 0.0 {
                    format!(" (offset {offset})")
                } else {
                    String::new()
                },
                q.frac_bits,
                q.weight_bits,
                if q.samples_per_slice > 1 {
                    format!(", {} samples per slice", q.samples_per_slice)
                } else {
                    String::new()
                }
            ),
        );
        let shaded = mode.classifies() && params.shading;
        add(
            Unit::Gradient,
            shaded,
            if shaded {
                format!("{}-neighbourhood", u32::from(q.gradient))
            } else if mode.classifies() {
                "shading is off".into()
            } else {
                format!("{mname} needs no shading")
            },
        );
        add(
            Unit::Shader,
            mode.classifies(),
            if !mode.classifies() {
                format!("{mname} projects densities, nothing to classify or light")
            } else if params.shading {
                format!(
                    "classification + {}",
                    match params.lights.len() {
                        0 => "headlight".to_string(),
                        1 => "1 light".to_string(),
                        n => format!("{n} lights"),
                    }
                )
            } else {
                "classification only (shading off)".into()
            },
        );
        add(Unit::Compos, true, mode.name().into());
        let blends = mode == CompositeMode::Composite;
        let unit_step = (ratio - 1.0).abs() < 1e-12;
        add(
            Unit::OpacityCorrection,
            blends && !unit_step,
            if !blends {
                format!("{mname} does not blend opacities")
            } else if unit_step {
                "the step is exactly one voxel".into()
            } else {
                format!("exponent {ratio:.3}")
            },
        );
        let (et, et_detail) = match mode {
            CompositeMode::Composite if params.early_termination < 1.0 => {
                (true, format!("at opacity {}", params.early_termination))
            }
            CompositeMode::Composite => (false, "threshold 1.0 (off)".into()),
            CompositeMode::FirstOpaque => (true, "the first opaque sample ends the ray".into()),
            _ => (false, format!("{mname} must see every sample")),
        };
        add(Unit::EarlyTermination, et, et_detail);
        match &scene.geometry {
            Some(g) => add(
                Unit::DepthTest,
                true,
                format!(
                    "[geometry]: {}, rasterized into the base plane's RGBA-Z image; samples at or behind it are left out, its colour goes under each ray",
                    g.describe()
                ),
            ),
            None => add(Unit::DepthTest, false, "no geometry in the scene".into()),
        }
        add(
            Unit::Supersampling,
            q.supersampling > 1,
            if q.supersampling > 1 {
                format!("{0}x{0} rays per voxel", q.supersampling)
            } else {
                "1 ray per voxel".into()
            },
        );
        let (skip, skip_detail) = if mode.classifies() {
            let empty = empty_block_fraction(vol, &tf);
            if empty > 0.0 {
                (
                    true,
                    format!(
                        "{:.0}% of {SKIP_BLOCK}^3 blocks are transparent",
                        100.0 * empty
                    ),
                )
            } else {
                (false, "no block is transparent".into())
            }
        } else {
            (false, format!("{mname} reads every sample"))
        };
        add(Unit::EmptySpaceSkip, skip, skip_detail);
        add(Unit::Warp, true, "base plane to image, bilinear".into());
        add(
            Unit::Perspective,
            params.projection == Projection::Perspective,
            if params.projection == Projection::Perspective {
                match scene.run.renderer {
                    Renderer::Slabs => format!("approximated by {}", scene.slabs().describe()),
                    Renderer::Er => format!(
                        "ER-perspective: rays from the eye, exponential regions, {}",
                        scene.er().describe()
                    ),
                    _ => "exact rays from the eye (reference renderer)".into(),
                }
            } else {
                "parallel projection".into()
            },
        );
        let what_if = crate::scene_render::not_expressible(scene);
        if scene.geometry.is_some()
            && scene.run.renderer == Renderer::Pipeline
            && !what_if.is_empty()
        {
            return Err(ModelError::Config(format!(
                "geometry: opaque geometry runs on the frame model and the f64 reference, and this scene renders on the what-if pipeline ({})",
                what_if.join("; ")
            )));
        }
        let kernel = scene.prefilter();
        if kernel != Prefilter::None
            && !matches!(scene.run.renderer, Renderer::Pipeline | Renderer::Reference)
        {
            return Err(ModelError::Config(format!(
                "volume.prefilter: the pre-pass runs before the frame model (and, as its f64 ideal, the reference); this scene renders on the {} model (run.renderer)",
                scene.run.renderer.name()
            )));
        }
        if kernel != Prefilter::None
            && scene.run.renderer == Renderer::Pipeline
            && !what_if.is_empty()
        {
            return Err(ModelError::Config(format!(
                "volume.prefilter: the pre-pass runs before the frame model only, and this scene renders on the what-if pipeline ({})",
                what_if.join("; ")
            )));
        }
        // The frame's memory width (the pre-pass filters what the memory holds).
        let voxel_w = crate::scene_render::frame_config(scene)
            .map_or(q.voxel_width(vol.bits), |c| c.trilin.voxel_w);
        match kernel.sepconv_config(voxel_w) {
            None => add(Unit::Prefilter, false, "volume.prefilter unset".into()),
            Some(cfg) if scene.run.renderer == Renderer::Reference => add(
                Unit::Prefilter,
                true,
                format!(
                    "{} {}, the f64 ideal (TapW would be {})",
                    kernel.name(),
                    kernel.describe(),
                    cfg.tap_w
                ),
            ),
            Some(cfg) => {
                let n = vol.data.len() as u64;
                add(
                    Unit::Prefilter,
                    true,
                    format!(
                        "ran: 3-pass {} {} along x, y, z on one cube5_sepconv (TapW={} WeightFracW=0 OutShift={}), edges replicated: {} samples, {} cycles",
                        kernel.name(),
                        kernel.describe(),
                        cfg.tap_w,
                        cfg.out_shift,
                        3 * n,
                        3 * (n + crate::prefilter::SEPCONV_LATENCY)
                    ),
                )
            }
        }
        if scene.boundary().is_some()
            && !(scene.run.renderer == Renderer::Pipeline && what_if.is_empty())
        {
            return Err(ModelError::Config(format!(
                "transfer.boundary: the 2-D transfer function runs on the frame model only, and this scene renders on {} ({})",
                match scene.run.renderer {
                    Renderer::Pipeline => "the what-if pipeline",
                    Renderer::Reference => "the f64 reference",
                    Renderer::Slabs => "the slab model",
                    Renderer::Er => "the ER-perspective model",
                },
                if what_if.is_empty() {
                    "run.renderer".to_string()
                } else {
                    what_if.join("; ")
                }
            )));
        }
        let model = match scene.run.renderer {
            Renderer::Reference => "f64 reference renderer (not the hardware)".to_string(),
            Renderer::Slabs => format!(
                "what-if slab perspective (not the hardware: {}, each an f64 parallel ray cast along the view, textured onto its middle plane through the perspective, blended front to back; docs/numerics/slab_perspective.md)",
                scene.slabs().describe()
            ),
            Renderer::Er => {
                // Back to front: no ray terminates; the model takes every sample of every slice.
                for e in entries.iter_mut() {
                    match e.unit {
                        Unit::EarlyTermination => {
                            e.needed = false;
                            e.detail = "ER-perspective composites back to front".into();
                        }
                        Unit::EmptySpaceSkip => {
                            e.needed = false;
                            e.detail = "ER-perspective samples every slice".into();
                        }
                        _ => {}
                    }
                }
                let setup = crate::er_perspective::ErSetup::new(
                    vol.dims,
                    vol.spacing,
                    &params,
                    scene.er(),
                )?;
                format!(
                    "ER-perspective model (the frame's unit models: cube5_trilin, cube5_gradient, cube5_shader, cube5_compos back to front; {}; base plane warped in f64; no RTL yet; docs/numerics/er_perspective.md) [counts: {}]",
                    scene.er().describe(),
                    setup.counts().describe()
                )
            }
            Renderer::Pipeline if what_if.is_empty() => {
                frame_entries(&mut entries, scene, vol);
                if matches!(mode, CompositeMode::Composite | CompositeMode::Mip)
                    && scene.boundary().is_none()
                    && scene.geometry.is_none()
                {
                    "frame (cube5_frame's bits, then the warp)".to_string()
                } else {
                    format!(
                        "frame (cube5_frame's bits, then the warp; {}: the exact per-sample frame model, since the fast path covers MIP and composite with the 1-D table and no geometry: the same bits, slower)",
                        if scene.boundary().is_some() {
                            "transfer.boundary"
                        } else if scene.geometry.is_some() {
                            "[geometry]"
                        } else {
                            mode.name()
                        }
                    )
                }
            }
            Renderer::Pipeline => format!(
                "what-if pipeline (not the hardware: {})",
                what_if.join("; ")
            ),
        };
        Ok(Self {
            model,
            entries,
            renderer: scene.run.renderer,
            target: scene.run.target,
        })
    }

    /// True when the scene needs `unit`.
    pub fn needs(&self, unit: Unit) -> bool {
        self.entries.iter().any(|e| e.unit == unit && e.needed)
    }
}

impl fmt::Display for Plan {
    /// One line: `modelled: trilin (...), ...; left out: gradient (MIP needs no shading), ...`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let list = |needed: bool| {
            self.entries
                .iter()
                .filter(|e| e.needed == needed)
                .map(|e| format!("{} ({})", e.unit.name(), e.detail))
                .collect::<Vec<_>>()
                .join(", ")
        };
        write!(
            f,
            "{}; modelled: {}; left out: {}",
            self.model,
            list(true),
            list(false)
        )
    }
}

/// The plan's entries as the frame computes them: every unit runs for every sample, except that a
/// MIP frame (`Shade = 0`) has no gradient and classifies by the table alone (the density ramp,
/// unlit); the gradient is the 6-neighbourhood at orthogonal positions, and the
/// sweep skips whole empty slices at its ends (blocks of zeros), not transparent blocks.
fn frame_entries(entries: &mut [PlanEntry], scene: &Scene, vol: &Volume) {
    // MIP, MinIP and X-ray are unlit: their frames have no gradient and no shader.
    let mip = crate::scene_render::frame_mode(scene.render.mode).unlit();
    let name = match scene.render.mode {
        CompositeMode::Mip => "MIP",
        CompositeMode::Minip => "MinIP",
        _ => "X-ray",
    };
    for e in entries.iter_mut() {
        match e.unit {
            Unit::Gradient if mip => {
                e.needed = false;
                e.detail = format!("{name} is unlit; its frame has Shade = 0, no gradient unit");
            }
            Unit::Gradient => {
                e.detail = "6-neighbourhood at orthogonal positions".into();
                e.needed = true;
            }
            Unit::Shader if mip => {
                e.needed = true;
                e.detail = "classification table only (the density ramp), unlit".into();
            }
            Unit::Shader if !scene.render.shading => {
                e.detail = "classification, reflectance map 1 (shading off)".into();
            }
            Unit::EmptySpaceSkip => {
                let zero = zero_block_fraction(vol);
                e.needed = zero > 0.0;
                e.detail = if e.needed {
                    format!(
                        "{:.0}% of {SKIP_BLOCK}^3 blocks are zero: their beams are not read, {}",
                        100.0 * zero,
                        if scene.render.mode == CompositeMode::Minip {
                            "every slice is swept (a zero sample is MinIP's minimum)"
                        } else {
                            "whole empty slices at the sweep's ends are skipped"
                        }
                    )
                } else {
                    "no block is zero".into()
                };
            }
            _ => {}
        }
    }
}

/// Fraction of `SKIP_BLOCK`^3 blocks whose voxels are all 0 (the frame's block LUT marks them
/// empty).
pub fn zero_block_fraction(vol: &Volume) -> f64 {
    match crate::units::cube5_skewmem::BlockLut::from_volume(vol, SKIP_BLOCK, 0) {
        Ok(lut) => {
            let empty = lut.entries.iter().filter(|e| e.empty).count();
            empty as f64 / lut.entries.len().max(1) as f64
        }
        Err(_) => 0.0,
    }
}

/// Fraction of `SKIP_BLOCK`^3 blocks (with a one-voxel apron, as interpolation reads it) whose
/// density range the transfer function maps to zero opacity.
pub fn empty_block_fraction(vol: &Volume, tf: &TransferFunction) -> f64 {
    let nb = vol.dims.map(|d| d.div_ceil(SKIP_BLOCK));
    let max = f64::from(vol.max_value());
    let mut empty = 0usize;
    for bz in 0..nb[2] {
        for by in 0..nb[1] {
            for bx in 0..nb[0] {
                let (mut lo, mut hi) = (u32::MAX, 0u32);
                let b = [bx, by, bz].map(|v| (v * SKIP_BLOCK) as i64);
                for z in b[2] - 1..=b[2] + SKIP_BLOCK as i64 {
                    for y in b[1] - 1..=b[1] + SKIP_BLOCK as i64 {
                        for x in b[0] - 1..=b[0] + SKIP_BLOCK as i64 {
                            let v = vol.get(x, y, z);
                            lo = lo.min(v);
                            hi = hi.max(v);
                        }
                    }
                }
                if tf.transparent_between(f64::from(lo) / max, f64::from(hi) / max) {
                    empty += 1;
                }
            }
        }
    }
    empty as f64 / (nb[0] * nb[1] * nb[2]) as f64
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The one-line error of parsing `text` (the tests of scene_gi.rs use it too).
    pub(crate) fn err(text: &str) -> String {
        Scene::parse(text, "s.toml").unwrap_err().to_string()
    }

    #[test]
    fn empty_text_is_the_default_scene() {
        assert_eq!(Scene::parse("", "x").unwrap(), Scene::default());
    }

    #[test]
    fn errors_name_file_line_and_field() {
        let e = err("[view]\nazimuth = \"left\"\n");
        assert!(e.starts_with("s.toml:2"), "{e}");
        assert!(err("[image]\nwidth = 0\n").contains("image.width"));
        assert!(err("[volume]\nsise = 3\n").contains("sise"));
        assert!(err("[view]\nazimuth = nan\n").contains("view.azimuth"));
        assert!(err("[view]\ndirection = [0.0, 0.0, 0.0]\n").contains("view.direction"));
        assert!(err("[view]\ndirection = [nan, 0.0, 1.0]\n").contains("view.direction"));
        let e = err("[transfer]\npoints = [{ density = 0.5, rgba = [0,0,0,0] }, { density = 0.2, rgba = [0,0,0,0] }]\n");
        assert!(e.contains("s.toml: transfer.points[1].density"), "{e}");
        assert!(err("[transfer]\npreset = \"glow\"\n").contains("transfer.preset"));
        assert!(err("[quality]\nweight_bits = 13\n").contains("quality.weight_bits"));
        assert!(err("[quality]\ngradient = 8\n").contains("gradient"));
        assert!(err("[quality]\ninterpolation = \"cubic\"\n").contains("cubic"));
        assert!(err("[volume]\nfile = \"a.raw\"\n").contains("volume.dims"));
        assert!(err("[volume]\nfile = \"a.raw\"\ndims = [2, 2, 2]\n").contains("volume.type"));
        assert!(err("[volume]\nfile = \"a.dat\"\n").contains("volume.format"));
        assert!(err("[volume]\nfile = \"a.nrrd\"\nphantom = \"head\"\n").contains("not both"));
        assert!(err("[[light]]\ndirection = [0, 0, 0]\n").contains("light[0].direction"));
        assert!(err("[view]\nprojection = \"perspective\"\n").contains("view.projection"));
        assert!(err("[run]\ntarget = \"rtl\"\n[volume]\nsize = 600\n").contains("configured RTL"));
    }

    #[test]
    fn plans_follow_the_mode() {
        let vol = crate::phantom::head_phantom(32, 12).unwrap();
        let scene = Scene::parse("[render]\nmode = \"mip\"\n", "s").unwrap();
        let plan = Plan::new(&scene, &vol).unwrap();
        // A MIP frame has no gradient (Shade = 0) and classifies by the table alone.
        assert!(plan.model.starts_with("frame"), "{}", plan.model);
        assert!(!plan.needs(Unit::Gradient) && plan.needs(Unit::Shader));
        let text = plan.to_string();
        assert!(
            text.contains("gradient (MIP is unlit; its frame has Shade = 0, no gradient unit)"),
            "{text}"
        );
        // The what-if pipeline leaves them out.
        let what_if = "[render]\nmode = \"mip\"\n[quality]\ninterpolation = \"sheared\"\n";
        let plan = Plan::new(&Scene::parse(what_if, "s").unwrap(), &vol).unwrap();
        assert!(plan.model.starts_with("what-if"), "{}", plan.model);
        assert!(plan.needs(Unit::Trilin) && plan.needs(Unit::Compos));
        assert!(!plan.needs(Unit::Gradient) && !plan.needs(Unit::Shader));
        let text = plan.to_string();
        assert!(text.contains("gradient (MIP needs no shading)"), "{text}");
        assert!(
            text.contains("depth test (no geometry in the scene)"),
            "{text}"
        );
        // Axis-aligned composite at one sample per slice: no opacity correction.
        let scene = Scene::parse("[view]\ndirection = [0, 0, 1]\n", "s").unwrap();
        let plan = Plan::new(&scene, &vol).unwrap();
        assert!(plan.needs(Unit::Gradient) && !plan.needs(Unit::OpacityCorrection));
        let sphere = crate::phantom::sphere_phantom(32, 12).unwrap();
        let scene = Scene::parse("[volume]\nphantom = \"sphere\"\nsize = 32\n", "s").unwrap();
        let plan = Plan::new(&scene, &sphere).unwrap();
        assert!(plan.needs(Unit::EmptySpaceSkip), "{plan}");
        let scene = Scene::parse("[view]\ndirection = [1, 0.5, 0.2]\n", "s").unwrap();
        assert!(Plan::new(&scene, &vol)
            .unwrap()
            .needs(Unit::OpacityCorrection));
    }
}
