//! GI scenes: a scene with a `[gi]` section renders on the GI-Cube block processor model
//! (`units::gicube_processor`, docs/numerics/gicube_processor.md): a lighting pass of lighting rays
//! from one distant light fills the irradiance field, then rendering rays, one per pixel, are lit
//! by it (volumetric global illumination: single scattering with shadows, or photons that scatter).
//! This module reads the section (`GiSpec`), checks what a GI scene may say, makes the plan, and
//! runs the two passes (`GiJob`); `--compare` is against the processor's f64 reference.
//!
//! `cube5 cosim`, and `cube5 render` with `run.target = "rtl"` or `"both"`, co-simulate it on the
//! `gicube_processor` RTL (cli/src/cosim_gi.rs).

use crate::camera::Camera;
use crate::error::{ModelError, Result};
use crate::render::{CompositeMode, ImageF64, Material, Quality};
use crate::scene::{Plan, PlanEntry, Renderer, Scene, Unit};
use crate::transfer::TransferFunction;
use crate::units::gicube_processor::{
    psnr, GiLight, GiMode, Processor, ProcessorConfig, ProcessorCounts, Projection, CHAN_MAX,
};
use crate::volume::Volume;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// A scene's `[gi]` table (docs/scenes.md, `[gi]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GiSpec {
    /// The direction the light travels (from the light into the scene), physical coordinates.
    pub light: [f64; 3],
    /// Irradiance `E0` of the light; 1 lights a sample at its full classified colour.
    pub energy: f64,
    /// Lighting rays per side of the light's square grid (it covers the volume's bounding sphere);
    /// `None`: two per voxel of the volume's diagonal (more if `energy` needs it).
    pub light_rays: Option<u32>,
    /// 0: low albedo (lighting rays deposit along their whole path, single scattering with
    /// shadows); above 0: photons that scatter isotropically with this probability.
    pub albedo: f64,
    /// Photons (`albedo > 0`): at most this many scatterings (default 8).
    pub bounces: Option<u32>,
    /// 2: the lighting pass, then the rendering pass; 1: the rendering pass only (unlit).
    pub passes: u32,
    /// Block side in voxels (the processor's queues are per block).
    pub block_size: u32,
    /// Rays per block queue; a ray moving into a full queue overflows to the host.
    pub queue_length: u32,
}

impl Default for GiSpec {
    fn default() -> Self {
        Self {
            light: [0.55, 0.25, -0.8],
            energy: 1.0,
            light_rays: None,
            albedo: 0.0,
            bounces: None,
            passes: 2,
            block_size: 16,
            queue_length: 256,
        }
    }
}

/// Photons' default number of scatterings.
pub const DEFAULT_BOUNCES: u32 = 8;

/// The first key whose value differs between two tables of the same type (`None`: equal).
fn first_difference<T: Serialize>(a: &T, b: &T) -> Option<String> {
    let (Ok(toml::Value::Table(a)), Ok(toml::Value::Table(b))) =
        (toml::Value::try_from(a), toml::Value::try_from(b))
    else {
        return Some(String::new());
    };
    a.keys()
        .chain(b.keys())
        .find(|k| a.get(*k) != b.get(*k))
        .cloned()
}

/// What a GI scene may say, checked without the volume: `Err((field, message))`.
pub fn validate(scene: &Scene, gi: &GiSpec) -> std::result::Result<(), (String, String)> {
    let bad = |field: &str, m: String| Err((field.to_string(), m));
    let l = gi.light;
    if l.iter().any(|x| !x.is_finite()) || l.iter().map(|x| x * x).sum::<f64>() < 1e-24 {
        return bad("gi.light", format!("{l:?} is zero or not finite"));
    }
    if !(gi.energy > 0.0 && gi.energy <= 4.0) {
        return bad("gi.energy", format!("{} is outside (0, 4]", gi.energy));
    }
    if let Some(n) = gi.light_rays {
        if !(1..=4096).contains(&n) {
            return bad("gi.light_rays", format!("{n} is outside 1..=4096"));
        }
    }
    if !(0.0..=1.0).contains(&gi.albedo) {
        return bad("gi.albedo", format!("{} is outside 0..=1", gi.albedo));
    }
    if let Some(b) = gi.bounces {
        if gi.albedo == 0.0 {
            return bad(
                "gi.bounces",
                "only applies to photons (gi.albedo > 0); at albedo 0 lighting rays do not scatter"
                    .into(),
            );
        }
        if b > 255 {
            return bad("gi.bounces", format!("{b} is outside 0..=255"));
        }
    }
    if !(1..=2).contains(&gi.passes) {
        return bad(
            "gi.passes",
            format!(
                "{} is not 1 (rendering only) or 2 (lighting, then rendering)",
                gi.passes
            ),
        );
    }
    if !(gi.block_size.is_power_of_two() && (4..=256).contains(&gi.block_size)) {
        return bad(
            "gi.block_size",
            format!("{} is not a power of two in 4..=256", gi.block_size),
        );
    }
    if !(1..=65535).contains(&gi.queue_length) {
        return bad(
            "gi.queue_length",
            format!("{} is outside 1..=65535", gi.queue_length),
        );
    }
    // The rest of the scene, as the processor reads it.
    if scene.render.mode != CompositeMode::Composite {
        return bad(
            "render.mode",
            format!(
                "\"{}\": the GI-Cube processor composites front to back only",
                scene.render.mode.name()
            ),
        );
    }
    if !scene.render.shading {
        return bad(
            "render.shading",
            "a [gi] scene is lit by its lighting pass, not shaded; for an unlit image say gi.passes = 1".into(),
        );
    }
    if !(1.0 / 16.0..=4.0).contains(&scene.render.step) {
        return bad(
            "render.step",
            format!(
                "{} is outside the GI-Cube processor's 1/16..=4 voxels",
                scene.render.step
            ),
        );
    }
    for (field, x) in [
        ("image.width", scene.image.width),
        ("image.height", scene.image.height),
    ] {
        if x > 4096 {
            return bad(
                field,
                format!("{x} exceeds the GI-Cube ray packet's 4096 pixels"),
            );
        }
    }
    if !scene.lights.is_empty() {
        return bad(
            "light",
            "a [gi] scene's light is gi.light (the lighting pass); [[light]] is for Phong shading"
                .into(),
        );
    }
    if let Some(k) = first_difference(&scene.shading, &Material::default()) {
        return bad(
            &format!("shading.{k}"),
            "a [gi] scene is lit by its lighting pass, not Phong-shaded".into(),
        );
    }
    if let Some(k) = first_difference(&scene.quality, &Quality::default()) {
        return bad(
            &format!("quality.{k}"),
            "the GI-Cube processor's widths and sampling are fixed (docs/numerics/gicube_processor.md); gi.block_size, gi.queue_length and render.step are its knobs".into(),
        );
    }
    if matches!(scene.run.renderer, Renderer::Slabs | Renderer::Er) {
        return bad(
            "run.renderer",
            format!("\"{}\" renders a perspective frame; a [gi] scene renders on the GI-Cube processor model (\"pipeline\") or its f64 reference", scene.run.renderer.name()),
        );
    }
    if scene.run.renderer == Renderer::Reference && gi.albedo > 0.0 && gi.passes == 2 {
        return bad(
            "run.renderer",
            "photons (gi.albedo > 0) have no f64 reference (their walk is random); use renderer = \"pipeline\"".into(),
        );
    }
    Ok(())
}

/// The scene's error for `field`.
fn scene_err(scene: &Scene, field: &str, m: impl std::fmt::Display) -> ModelError {
    ModelError::Scene {
        path: scene
            .source
            .as_ref()
            .map_or("scene".to_string(), |p| p.display().to_string()),
        message: format!("{field}: {m}"),
    }
}

/// A model error's text without its kind (`configuration: `) and the unit's prefix.
fn text(e: &ModelError) -> String {
    let m = match e {
        ModelError::Config(m) | ModelError::View(m) | ModelError::Volume(m) => m.clone(),
        other => other.to_string(),
    };
    ["gicube processor: ", "gicube lighting pass: "]
        .iter()
        .fold(m, |m, p| {
            m.strip_prefix(p).map_or(m.clone(), str::to_string)
        })
}

/// The `[gi]` section of a scene that has one.
fn spec(scene: &Scene) -> Result<&GiSpec> {
    scene
        .gi
        .as_ref()
        .ok_or_else(|| ModelError::Config("the scene has no [gi] section".into()))
}

/// The processor's configuration for a scene: `gi.block_size`, `gi.queue_length`, `render.step`
/// (rounded to 1/256 voxel), `render.early_termination` (on the packet's `U(0.12)` opacity, 1 =
/// off); the sorter, 16 ranks, space leaping.
pub fn processor_config(scene: &Scene) -> Result<ProcessorConfig> {
    let gi = spec(scene)?;
    let et = scene.render.early_termination;
    Ok(ProcessorConfig {
        block_log2: gi.block_size.max(1).trailing_zeros(),
        queue_len: gi.queue_length,
        step: (scene.render.step * 256.0).round().clamp(16.0, 1024.0) as u32,
        et_threshold: (et < 1.0).then(|| ((et * 4096.0).ceil() as u32).clamp(1, CHAN_MAX + 1)),
        ..ProcessorConfig::DEFAULT
    })
}

/// The light of the lighting pass (voxel coordinates: the processor takes isotropic volumes).
pub fn gi_light(gi: &GiSpec, vol: &Volume) -> GiLight {
    let diag = DVec3::from_array(vol.dims.map(|d| d as f64)).length();
    let grid = gi.light_rays.unwrap_or_else(|| {
        // Two rays per voxel, and enough that each carries E0 h^2 < 1 (`light_rays`).
        ((2.0 * diag).ceil() as u32).max((diag * gi.energy.sqrt()).floor() as u32 + 1)
    });
    GiLight {
        dir: DVec3::from_array(gi.light).normalize(),
        energy: gi.energy,
        grid,
        mode: if gi.albedo > 0.0 {
            GiMode::HighAlbedo {
                albedo: gi.albedo,
                lifetime: gi.bounces.unwrap_or(DEFAULT_BOUNCES).min(255) as u8,
            }
        } else {
            GiMode::LowAlbedo
        },
    }
}

/// One GI frame of a scene, set up: the processor (volume and tables loaded), the light, the
/// camera of the rendering rays.
#[derive(Debug, Clone)]
pub struct GiJob {
    pub processor: Processor,
    pub tf: TransferFunction,
    pub light: GiLight,
    /// `gi.passes = 2`: the lighting pass runs.
    pub lit: bool,
    pub camera: Camera,
    pub projection: Projection,
}

/// What one GI frame computed.
#[derive(Debug, Clone)]
pub struct GiRun {
    pub image: ImageF64,
    /// The lighting pass's counts (`None`: `gi.passes = 1`).
    pub lighting: Option<ProcessorCounts>,
    pub rendering: ProcessorCounts,
}

impl GiJob {
    /// Loads `vol` and the scene's transfer function into the processor; errors name the field.
    pub fn new(scene: &Scene, vol: &Volume) -> Result<Self> {
        let gi = spec(scene)?;
        let s = vol.spacing[0];
        if vol.spacing.iter().any(|&x| x != s) {
            return Err(scene_err(
                scene,
                "volume.spacing",
                format!(
                    "{:?}: the GI-Cube processor steps rays in voxels and takes isotropic volumes only",
                    vol.spacing
                ),
            ));
        }
        if vol.bits < 4 {
            return Err(scene_err(
                scene,
                "volume.bits",
                format!(
                    "{}-bit voxels: the GI-Cube processor takes 4..=16",
                    vol.bits
                ),
            ));
        }
        let cfg = processor_config(scene)?;
        let tf = scene.transfer_function();
        let processor = Processor::new(cfg, vol, &tf).map_err(|e| {
            let m = text(&e);
            let field = if m.contains("blocks") {
                "gi.block_size"
            } else {
                "gi"
            };
            scene_err(scene, field, m)
        })?;
        let params = scene.render_params();
        let dir = params.direction()?;
        let camera = params.camera(vol, dir);
        let projection = match scene.view.projection {
            crate::render::Projection::Parallel => Projection::Parallel,
            crate::render::Projection::Perspective => Projection::Perspective {
                fov_deg: scene.view.fov,
            },
        };
        let light = gi_light(gi, vol);
        // The lighting pass's checks (energy per ray below 1) before any work.
        if gi.passes == 2 {
            crate::units::gicube_processor::light_rays(vol, &light, cfg.host_order)
                .map_err(|e| scene_err(scene, "gi.light_rays", text(&e)))?;
        }
        Ok(Self {
            processor,
            tf,
            light,
            lit: gi.passes == 2,
            camera,
            projection,
        })
    }

    /// The lighting pass (`gi.passes = 2`), then the rendering pass.
    pub fn run(&mut self) -> Result<GiRun> {
        let lighting = if self.lit {
            Some(self.processor.light(&self.light)?.counts)
        } else {
            None
        };
        let f = self.processor.render(&self.camera, self.projection)?;
        Ok(GiRun {
            image: ImageF64 {
                width: f.width,
                height: f.height,
                rgb: f.to_f64(),
            },
            lighting,
            rendering: f.counts,
        })
    }

    /// The processor's f64 reference of the same frame (`reference_gi`, or `reference` unlit);
    /// `None` for photons (no f64 reference of a random walk).
    pub fn reference(&self) -> Result<Option<ImageF64>> {
        let rgb = match (self.lit, self.light.mode) {
            (false, _) => self
                .processor
                .reference(&self.tf, &self.camera, self.projection)?,
            (true, GiMode::LowAlbedo) => {
                self.processor
                    .reference_gi(&self.tf, &self.light, &self.camera, self.projection)?
            }
            (true, GiMode::HighAlbedo { .. }) => return Ok(None),
        };
        Ok(Some(ImageF64 {
            width: self.camera.width,
            height: self.camera.height,
            rgb,
        }))
    }
}

/// PSNR (dB, peak 1) and largest channel error of `image` against `reference`.
pub fn compare(image: &ImageF64, reference: &ImageF64) -> (f64, f64) {
    psnr(&image.rgb, &reference.rgb)
}

/// One pass's counts: `rays in = finished + overflowed`, samples, leaps, queue occupancy, cache.
pub fn counts_text(c: &ProcessorCounts) -> String {
    format!(
        "{} rays in = {} finished + {} overflowed to the host, {} samples, {} leaps, {} terminated, {} cycles, mean queue occupancy {:.0}, max queue {}, cache hit rate {:.3}",
        c.rays_in,
        c.rays_finished,
        c.rays_overflowed,
        c.samples,
        c.leaps,
        c.rays_terminated,
        c.cycles,
        c.mean_occupancy(),
        c.max_queue,
        c.cache_hit_rate()
    )
}

/// The counts of a GI frame, both passes.
pub fn run_counts_text(run: &GiRun) -> String {
    let render = format!("rendering pass: {}", counts_text(&run.rendering));
    match &run.lighting {
        Some(l) => format!("lighting pass: {}; {render}", counts_text(l)),
        None => render,
    }
}

/// The plan of a GI scene: what the processor models and what it leaves out.
pub fn plan(scene: &Scene, vol: &Volume) -> Result<Plan> {
    let gi = spec(scene)?;
    let cfg = processor_config(scene)?;
    let light = gi_light(gi, vol);
    let lit = gi.passes == 2;
    let empty = match Processor::new(cfg, vol, &scene.transfer_function()) {
        Ok(p) => {
            let f = p.empty_flags();
            f.iter().filter(|&&e| e).count() as f64 / f.len().max(1) as f64
        }
        Err(_) => 0.0,
    };
    let mut entries = Vec::new();
    let mut add = |unit, needed, detail| entries.push(PlanEntry::new(unit, needed, detail));
    add(
        Unit::Trilin,
        true,
        format!(
            "tri-linear at U(12.8) ray positions, U({}.4) samples, 8-bit weights{}",
            vol.bits,
            if lit {
                "; the irradiance tri-linear too"
            } else {
                ""
            }
        ),
    );
    add(
        Unit::Gradient,
        false,
        "the lighting pass lights the samples, no Phong".into(),
    );
    add(
        Unit::Shader,
        true,
        if lit {
            "classification, colour x irradiance".into()
        } else {
            "classification only (gi.passes = 1: unlit)".into()
        },
    );
    add(
        Unit::Compos,
        true,
        "composite, front to back on the ray packet".into(),
    );
    let step = cfg.step_voxels();
    add(
        Unit::OpacityCorrection,
        cfg.step != 256,
        if cfg.step == 256 {
            "the step is exactly one voxel".into()
        } else {
            format!("step {step} voxel")
        },
    );
    add(
        Unit::EarlyTermination,
        cfg.et_threshold.is_some(),
        match cfg.et_threshold {
            Some(t) => format!("at packet opacity {t}/4096"),
            None => "threshold 1.0 (off)".into(),
        },
    );
    add(Unit::DepthTest, false, "no geometry in the scene".into());
    add(Unit::Supersampling, false, "1 ray per pixel".into());
    add(
        Unit::EmptySpaceSkip,
        empty > 0.0,
        format!(
            "space leaping of rendering rays: {:.0}% of {}^3 blocks are transparent",
            100.0 * empty,
            gi.block_size
        ),
    );
    add(
        Unit::Warp,
        false,
        "rays start at the image's pixels (image order)".into(),
    );
    add(
        Unit::Perspective,
        scene.view.projection == crate::render::Projection::Perspective,
        match scene.view.projection {
            crate::render::Projection::Perspective => format!("fov {} degrees", scene.view.fov),
            crate::render::Projection::Parallel => "parallel projection".into(),
        },
    );
    let passes = if lit {
        let d = light.dir;
        format!(
            "lighting pass: distant light along [{:.3}, {:.3}, {:.3}], E0 {}, {}^2 lighting rays, {}; then the rendering pass",
            d.x,
            d.y,
            d.z,
            light.energy,
            light.grid,
            match light.mode {
                GiMode::LowAlbedo => "low albedo (single scattering with shadows)".to_string(),
                GiMode::HighAlbedo { albedo, lifetime } => format!(
                    "photons, albedo {albedo}, at most {lifetime} bounces"
                ),
            }
        )
    } else {
        "rendering pass only (gi.passes = 1: no lighting pass; gi.light, energy, light_rays, albedo, bounces unused)".into()
    };
    let model = match scene.run.renderer {
        Renderer::Reference => format!(
            "f64 reference of the GI-Cube processor model (not the hardware; {passes})"
        ),
        // Slabs and ER are refused by validate (above).
        Renderer::Pipeline | Renderer::Slabs | Renderer::Er => format!(
            "GI-Cube processor model (units::gicube_processor: {}^3 blocks, {}-ray queues, the queue sorter; {passes})",
            gi.block_size, gi.queue_length
        ),
    };
    Ok(Plan {
        model,
        entries,
        renderer: scene.run.renderer,
        target: scene.run.target,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::tests::err;

    #[test]
    fn an_empty_gi_table_is_the_default_section() {
        let s = Scene::parse("[gi]\n", "s").unwrap();
        assert_eq!(s.gi, Some(GiSpec::default()));
        assert_eq!(Scene::parse("", "s").unwrap().gi, None);
    }

    #[test]
    fn bad_values_are_refused_in_one_line_naming_the_field() {
        for (text, field) in [
            ("[gi]\nlight = [0, 0, 0]\n", "gi.light"),
            ("[gi]\nlight = [nan, 0, 1]\n", "gi.light"),
            ("[gi]\nenergy = 5.0\n", "gi.energy"),
            ("[gi]\nlight_rays = 0\n", "gi.light_rays"),
            ("[gi]\nalbedo = -0.1\n", "gi.albedo"),
            ("[gi]\nalbedo = 0.5\nbounces = 300\n", "gi.bounces"),
            ("[gi]\nbounces = 3\n", "gi.bounces"),
            ("[gi]\npasses = 0\n", "gi.passes"),
            ("[gi]\nblock_size = 6\n", "gi.block_size"),
            ("[gi]\nqueue_length = 70000\n", "gi.queue_length"),
            ("[gi]\ncolour = 1\n", "colour"),
            ("[gi]\n[render]\nmode = \"xray\"\n", "render.mode"),
            ("[gi]\n[render]\nstep = 0.05\n", "render.step"),
            ("[gi]\n[image]\nwidth = 5000\n", "image.width"),
            ("[gi]\n[quality]\nweight_bits = 6\n", "quality.weight_bits"),
            ("[gi]\n[shading]\nshininess = 3.0\n", "shading.shininess"),
            (
                "[gi]\nalbedo = 0.5\n[run]\nrenderer = \"reference\"\n",
                "run.renderer",
            ),
        ] {
            let e = err(text);
            assert!(e.contains(field), "{text}: {e}");
            assert_eq!(e.lines().count(), 1, "{e}");
        }
        // Perspective is the processor's: accepted in a GI scene.
        Scene::parse("[gi]\n[view]\nprojection = \"perspective\"\n", "s").unwrap();
    }

    #[test]
    fn the_scene_sets_the_processor() {
        let s = Scene::parse(
            "[render]\nstep = 0.3\nearly_termination = 0.5\n[gi]\nblock_size = 8\nqueue_length = 9\n",
            "s",
        )
        .unwrap();
        let c = processor_config(&s).unwrap();
        assert_eq!((c.block_log2, c.queue_len), (3, 9));
        assert_eq!(c.step, 77); // 0.3 x 256 = 76.8, rounded
        assert_eq!(c.et_threshold, Some(2048));
        let s = Scene::parse("[render]\nearly_termination = 1.0\n[gi]\n", "s").unwrap();
        assert_eq!(processor_config(&s).unwrap().et_threshold, None);
        // cube5 cosim refuses a GI scene in one line.
        let why = crate::scene_render::not_expressible(&s);
        assert!(
            why.len() == 1 && why[0].contains("gicube_processor"),
            "{why:?}"
        );
    }

    #[test]
    fn the_example_scene_is_the_processors_shadow_scene() {
        // scenes/gi-shadow.toml at 64^3 is `shadow_scene(64)`: same volume, transfer function and
        // light (the example and the measurements use it).
        let path = crate::repo_root().join("scenes/gi-shadow.toml");
        let scene = Scene::load(&path).unwrap();
        let vol = scene.build_volume().unwrap();
        let (v, tf, light) = crate::units::gicube_processor::shadow_scene(64).unwrap();
        assert!(vol.data == v.data && vol.bits == v.bits);
        assert_eq!(scene.transfer_function(), tf);
        let l = gi_light(scene.gi.as_ref().unwrap(), &vol);
        assert!((l.dir - light.dir).length() < 1e-12);
        assert_eq!(
            (l.energy, l.grid, l.mode),
            (light.energy, light.grid, light.mode)
        );
    }
}
