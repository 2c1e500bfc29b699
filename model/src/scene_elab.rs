//! Scene-driven elaboration (docs/scenes.md, "What a scene builds"): the `cube5_frame`
//! configuration a scene needs, every choice with its reason, and the forms the build takes it in
//! (a `.variants` line, a `CUBE5_TOPS` entry). `cube5 elaborate` prints it, `cube5 cosim` and
//! `run.target = "rtl"` run on exactly it, `make cosim SCENE=...` builds it.

use crate::error::{ModelError, Result};
use crate::prefilter::Prefilter;
use crate::render::CompositeMode;
use crate::scene::{Scene, RTL_MAX_EDGE};
use crate::scene_render::{frame_config, not_expressible};
use crate::unit::UnitConfig;
use crate::units::cube5_frame::FrameConfig;
use crate::units::cube5_sepconv::SepconvConfig;

/// Pipelines when the scene does not say (`run.pipelines`): the patent's design point, four
/// pipelines at 133 MHz for 256^3 at 30 Hz ([250]).
pub const DEFAULT_PIPELINES: usize = 4;

/// One unit the configuration leaves out, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LeftOut {
    pub unit: &'static str,
    pub why: String,
}

/// The `cube5_sepconv` a pre-filtered scene builds beside the frame (`volume.prefilter`): one
/// stage running the three passes over the volume before the frame.
#[derive(Debug, Clone, PartialEq)]
pub struct PrefilterBuild {
    pub kernel: Prefilter,
    pub config: SepconvConfig,
    /// The scene's reason and what the parameters follow from.
    pub why: String,
}

impl PrefilterBuild {
    /// The parameters, all three (each differs from the unit's default).
    pub fn params(&self) -> Vec<(&'static str, i64)> {
        self.config.to_params()
    }

    /// Its name by the naming rule (`t13w0o2`).
    pub fn name(&self) -> String {
        rule_name(&self.params())
    }

    /// The `CUBE5_TOPS` entry that builds it.
    pub fn spec(&self) -> String {
        format!(
            "{}@{}",
            SepconvConfig::TOP,
            assignments(&self.params(), ":")
        )
    }

    /// Its `.variants` line.
    pub fn variants_line(&self) -> String {
        format!("{}  {}", self.name(), assignments(&self.params(), " "))
    }
}

/// `Param=value`, joined by `sep`.
fn assignments(params: &[(&'static str, i64)], sep: &str) -> String {
    let kv: Vec<String> = params.iter().map(|(k, v)| format!("{k}={v}")).collect();
    kv.join(sep)
}

/// The naming rule (docs/adding-a-unit.md, "Naming a variant"): each parameter's initial and
/// value.
fn rule_name(params: &[(&'static str, i64)]) -> String {
    params
        .iter()
        .map(|(k, v)| format!("{}{v}", k[..1].to_ascii_lowercase()))
        .collect()
}

/// The configuration of `cube5_frame` a scene needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Elaboration {
    pub config: FrameConfig,
    /// Each choice (`P = 4`, `MaxDim = 128`, a width, `Shade = 0`) and the scene's reason.
    pub choices: Vec<(String, String)>,
    /// The units left out of every pipeline, with the reason.
    pub left_out: Vec<LeftOut>,
    /// The pre-pass unit built beside the frame, when the scene asks for one.
    pub prefilter: Option<PrefilterBuild>,
}

impl Elaboration {
    /// The parameters that set the configuration apart: `P` and `MaxDim` always, then every
    /// parameter whose value is not the RTL's default, in the frame's parameter order.
    pub fn params(&self) -> Vec<(&'static str, i64)> {
        let dflt = self.config.rtl_defaults().to_params();
        self.config
            .to_params()
            .into_iter()
            .filter(|(k, v)| matches!(*k, "P" | "MaxDim") || !dflt.contains(&(*k, *v)))
            .collect()
    }

    /// The same configuration with gradient and shader (what leaving them out is measured
    /// against), or `None` when nothing is left out.
    pub fn full(&self) -> Option<Elaboration> {
        if self.config.shade {
            return None;
        }
        Some(Elaboration {
            config: FrameConfig {
                shade: true,
                ..self.config
            },
            choices: Vec::new(),
            left_out: Vec::new(),
            prefilter: None,
        })
    }

    /// Every `CUBE5_TOPS` entry the scene's run needs: the frame's, then the pre-pass unit's.
    pub fn tops(&self) -> String {
        match &self.prefilter {
            Some(pf) => format!("{},{}", self.spec(), pf.spec()),
            None => self.spec(),
        }
    }

    /// The `CUBE5_TOPS` entry that builds exactly this configuration (tb-rs/build.rs:
    /// `top@Param=value:...`, the top's defaults for every other parameter).
    pub fn spec(&self) -> String {
        format!("{}@{}", FrameConfig::TOP, self.assignments(":"))
    }

    /// `Param=value` for each of [`Elaboration::params`], joined by `sep`.
    pub fn assignments(&self, sep: &str) -> String {
        assignments(&self.params(), sep)
    }

    /// The configuration's name by the naming rule (docs/adding-a-unit.md, "Naming a variant"):
    /// each parameter's initial and value, in [`Elaboration::params`] order (`p4m128s0`).
    pub fn name(&self) -> String {
        rule_name(&self.params())
    }

    /// The configuration as a `.variants` line (generated in the build, flag `sim`).
    pub fn variants_line(&self) -> String {
        format!("{}  sim  {}", self.name(), self.assignments(" "))
    }
}

/// The `cube5_frame` configuration that renders `scene` on a volume of `dims` voxels, with
/// `pipelines` overriding `run.pipelines`. Refused, with the scene fields named: a scene the frame
/// cannot express, widths it cannot take, a volume larger than its largest memory or whose edges
/// are not multiples of the pipelines.
pub fn elaborate(scene: &Scene, dims: [usize; 3], pipelines: Option<usize>) -> Result<Elaboration> {
    let why = not_expressible(scene);
    if !why.is_empty() {
        return Err(ModelError::Config(format!(
            "cube5_frame cannot render this scene: {}",
            why.join("; ")
        )));
    }
    let mut config = frame_config(scene)?;
    let mut choices = Vec::new();

    let (p, p_why) = match (pipelines, scene.run.pipelines) {
        (Some(p), _) => (p, format!("--pipelines {p}")),
        (None, Some(p)) => (p as usize, format!("run.pipelines = {p}")),
        (None, None) => (
            DEFAULT_PIPELINES,
            "run.pipelines unset: the patent's design point ([250])".to_string(),
        ),
    };
    let field = match (pipelines, scene.run.pipelines) {
        (Some(_), _) => "--pipelines".to_string(),
        (None, Some(_)) => "run.pipelines".to_string(),
        (None, None) => format!("run.pipelines unset (P = {p})"),
    };
    if ![1, 2, 4, 8].contains(&p) {
        return Err(ModelError::Config(format!(
            "{field}: P = {p}, the frame has 1, 2, 4 or 8 pipelines"
        )));
    }
    if let Some(d) = dims.iter().find(|&&d| d % p != 0) {
        return Err(ModelError::Config(format!(
            "{field}: the volume's edge {d} ({} x {} x {}) is not a multiple of P = {p}",
            dims[0], dims[1], dims[2]
        )));
    }
    config.p = p;
    choices.push((format!("P = {p}"), p_why));

    let edge = dims.iter().copied().max().unwrap_or(1);
    let max_dim = edge.next_power_of_two().max(8).max(2 * p);
    if edge > RTL_MAX_EDGE {
        return Err(ModelError::Config(format!(
            "volume: the largest edge {edge} exceeds the configured RTL's {RTL_MAX_EDGE} voxels per edge (the frame's co-simulated memories)"
        )));
    }
    config.max_dim_log2 = max_dim.trailing_zeros();
    choices.push((
        format!("MaxDim = {max_dim}"),
        format!(
            "the smallest memory (a power of two, at least 8 and 2 P) that holds the volume's largest edge {edge}"
        ),
    ));

    let q = scene.quality();
    let widths = [
        ("VoxelW", "quality.voxel_bits"),
        ("WeightW", "quality.weight_bits"),
        ("FracW", "quality.frac_bits"),
        ("ColorW", "quality.colour_bits"),
        ("AlphaW", "quality.alpha_bits"),
        ("AccW", "quality.acc_bits"),
    ];
    let dflt = config.rtl_defaults().to_params();
    let mine = config.to_params();
    for (name, field) in widths {
        if let Some((_, v)) = mine
            .iter()
            .find(|(k, v)| *k == name && !dflt.contains(&(*k, *v)))
        {
            choices.push((format!("{name} = {v}"), format!("{field} = {v}")));
        }
    }
    if q.voxel_bits.is_none() {
        choices.push((
            format!("VoxelW = {}", config.trilin.voxel_w),
            "quality.voxel_bits unset: the default width (the volume is requantized to it)".into(),
        ));
    }

    let mut left_out = Vec::new();
    if crate::scene_render::frame_mode(scene.render.mode).unlit() {
        config.shade = false;
        let what = match scene.render.mode {
            CompositeMode::Mip => "the maximum",
            CompositeMode::Minip => "the minimum",
            _ => "the sum",
        };
        let why = format!("render.mode = \"{}\": {what} of the classified density (the contract's density ramp), unlit; no reflectance map is read and no gradient is needed", scene.render.mode.name());
        left_out.push(LeftOut {
            unit: "cube5_gradient",
            why: format!("{why} (its neighbours B, A, x-, x+, y-, y+ go with it)"),
        });
        left_out.push(LeftOut {
            unit: "cube5_shader",
            why: format!("{why}; each pipeline keeps the shader's 1-D classification table (cube5_frame_class)"),
        });
        choices.push((
            "Shade = 0".into(),
            format!("render.mode = \"{}\"", scene.render.mode.name()),
        ));
    } else {
        let how = if scene.render.shading {
            "render.shading = true: the reflectance map of the lights, by the gradient"
        } else {
            "render.shading = false: the shader runs with a uniform reflectance map"
        };
        choices.push((
            "Shade = 1".into(),
            format!(
                "render.mode = \"{}\" classifies and shades every sample ({how})",
                scene.render.mode.name()
            ),
        ));
    }
    let kernel = scene.prefilter();
    let prefilter = kernel
        .sepconv_config(config.trilin.voxel_w)
        .map(|sep| PrefilterBuild {
            kernel,
            config: sep,
            why: format!(
                "volume.prefilter = \"{}\": the 3-pass {} filter along x, y, z over the volume before the frame ([204]-[205]); TapW = VoxelW + 1 = {} (voxels zero-extended), WeightFracW = 0 (w = {} is an integer), OutShift = {} (the kernel's sum {} is a shift)",
                kernel.name(),
                kernel.describe(),
                sep.tap_w,
                kernel.weight().unwrap_or(0),
                sep.out_shift,
                kernel.weight().unwrap_or(0) + 2
            ),
        });
    match &scene.geometry {
        Some(g) => choices.push((
            "DepthTest = 1".into(),
            format!(
                "[geometry]: {}: the compositing buffer is preloaded with its RGBA-Z image and every sample is depth-tested",
                g.describe()
            ),
        )),
        None => choices.push((
            "DepthTest = 0".into(),
            "no [geometry] in the scene: the depth test is left out (no Z or geometry colour per coxel, no flush at the read-out)".into(),
        )),
    }
    Ok(Elaboration {
        config,
        choices,
        left_out,
        prefilter,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(text: &str) -> Scene {
        Scene::parse(text, "test.toml").unwrap()
    }

    fn elab(s: &Scene) -> Result<Elaboration> {
        let vol = s.build_volume()?;
        elaborate(s, vol.dims, None)
    }

    /// Every example scene (scenes/*.toml) elaborates to the configuration it needs: the MIP scene
    /// without gradient and shader, the composite ones with them, at their widths, pipelines and
    /// memory; the rest are refused with the fields the frame cannot express. A new example scene
    /// must be added here.
    #[test]
    fn every_example_scene_elaborates_to_what_it_needs() {
        // (scene, P, MaxDim, shade, params of the .variants line) or the refused fields.
        let built: &[(&str, usize, usize, bool, &str)] = &[
            ("head-mip", 4, 128, false, "P=4 MaxDim=128 Shade=0"),
            ("head-minip", 4, 128, false, "P=4 MaxDim=128 Shade=0"),
            ("head-xray", 4, 128, false, "P=4 MaxDim=128 Shade=0"),
            ("bubbles-minip", 4, 32, false, "P=4 MaxDim=32 Shade=0"),
            ("head-first-opaque", 4, 128, true, "P=4 MaxDim=128"),
            ("head-2dtf", 4, 128, true, "P=4 MaxDim=128"),
            ("head-geometry", 4, 64, true, "P=4 MaxDim=64 DepthTest=1"),
            ("head", 4, 128, true, "P=4 MaxDim=128"),
            ("head-nifti", 4, 64, true, "P=4 MaxDim=64"),
            ("head-prefilter", 4, 128, true, "P=4 MaxDim=128"),
            ("head-unshaded", 4, 128, true, "P=4 MaxDim=128"),
            (
                "head-narrow",
                2,
                128,
                true,
                "P=2 MaxDim=128 VoxelW=8 WeightW=4 ColorW=5 AlphaW=8 AccW=12",
            ),
        ];
        let refused: &[(&str, &[&str])] = &[
            ("head-bone-lights", &["light[0].colour"]),
            ("cube3-6.1", &["quality.interpolation", "quality.gradient"]),
            (
                "sphere-sheared",
                &["quality.interpolation", "quality.supersampling"],
            ),
            ("head-nrrd", &["quality.interpolation"]),
            ("head-perspective", &["view.projection"]),
            ("head-perspective-slabs", &["view.projection"]),
            ("head-perspective-er", &["view.projection"]),
            ("gi-shadow", &["[gi]"]),
            ("gi-shadow-16", &["[gi]"]),
        ];
        let dir = crate::repo_root().join("scenes");
        let mut seen = Vec::new();
        for e in std::fs::read_dir(&dir).unwrap() {
            let path = e.unwrap().path();
            if path.extension().is_none_or(|x| x != "toml") {
                continue;
            }
            let name = path.file_stem().unwrap().to_string_lossy().to_string();
            let s = Scene::load(&path).unwrap();
            if let Some(&(_, p, max_dim, shade, line)) = built.iter().find(|b| b.0 == name) {
                let e = elab(&s).unwrap_or_else(|e| panic!("{name}: {e}"));
                assert_eq!(e.config.p, p, "{name}");
                assert_eq!(e.config.max_dim(), max_dim, "{name}");
                assert_eq!(e.config.shade, shade, "{name}");
                assert!(
                    e.variants_line().ends_with(&format!("sim  {line}")),
                    "{name}: {}",
                    e.variants_line()
                );
                assert_eq!(
                    e.spec(),
                    format!("cube5_frame@{}", line.replace(' ', ":")),
                    "{name}"
                );
                // Only the pre-filtered scene builds the pre-pass unit beside the frame.
                let spec = "cube5_sepconv@TapW=13:WeightFracW=0:OutShift=2";
                match &e.prefilter {
                    Some(pf) => {
                        assert_eq!(name, "head-prefilter");
                        assert_eq!(pf.spec(), spec);
                        assert!(pf.why.contains("volume.prefilter = \"gauss\""));
                        assert_eq!(e.tops(), format!("{},{spec}", e.spec()));
                    }
                    None => assert_ne!(name, "head-prefilter"),
                }
                let units: Vec<&str> = e.left_out.iter().map(|l| l.unit).collect();
                if shade {
                    assert!(units.is_empty(), "{name}: {units:?}");
                    assert!(e.full().is_none(), "{name}");
                } else {
                    assert_eq!(units, ["cube5_gradient", "cube5_shader"], "{name}");
                    let mode = format!("render.mode = \"{}\"", s.render.mode.name());
                    assert!(e.left_out.iter().all(|l| l.why.contains(&mode)));
                    assert!(e.full().unwrap().config.shade, "{name}");
                }
            } else if let Some((_, fields)) = refused.iter().find(|r| r.0 == name) {
                let why = elab(&s).unwrap_err().to_string();
                for f in *fields {
                    assert!(why.contains(f), "{name}: `{why}` does not name {f}");
                }
            } else {
                panic!("{name}: an example scene this test does not list");
            }
            seen.push(name);
        }
        assert_eq!(seen.len(), built.len() + refused.len(), "{seen:?}");
    }

    /// The name follows the naming rule, and the choices name the scene fields behind them.
    #[test]
    fn names_and_reasons() {
        let e = elab(&scene(
            "[volume]\nsize = 16\n[render]\nmode = \"mip\"\n[run]\npipelines = 1\n",
        ))
        .unwrap();
        assert_eq!(e.name(), "p1m16s0");
        assert_eq!(e.variants_line(), "p1m16s0  sim  P=1 MaxDim=16 Shade=0");
        let why: Vec<String> = e
            .choices
            .iter()
            .map(|c| format!("{}: {}", c.0, c.1))
            .collect();
        assert!(
            why.iter()
                .any(|w| w.starts_with("P = 1: run.pipelines = 1")),
            "{why:?}"
        );
        assert!(
            why.iter()
                .any(|w| w.starts_with("MaxDim = 16:") && w.contains("16")),
            "{why:?}"
        );
        // The smallest memory is 8 and 2 P.
        let e = elab(&scene("[volume]\nsize = 8\n[run]\npipelines = 8\n")).unwrap();
        assert_eq!(e.config.max_dim(), 16);
        // --pipelines overrides run.pipelines.
        let s = scene("[volume]\nsize = 16\n[run]\npipelines = 1\n");
        let e = elaborate(&s, [16; 3], Some(8)).unwrap();
        assert_eq!(e.config.p, 8);
        assert!(e.choices[0].1.contains("--pipelines 8"));
    }

    /// Refusals name the field: pipelines that do not divide the volume or do not exist, a volume
    /// above the RTL's memory, widths the frame cannot take, a mode it cannot render.
    #[test]
    fn refusals_name_their_field() {
        let why = |text: &str, p: Option<usize>| {
            let s = scene(text);
            let vol = s.build_volume().unwrap();
            elaborate(&s, vol.dims, p).unwrap_err().to_string()
        };
        let w = why("[volume]\nsize = 18\n", None);
        assert!(
            w.contains("run.pipelines unset (P = 4)") && w.contains("18"),
            "{w}"
        );
        let w = why("[volume]\nsize = 12\n[run]\npipelines = 8\n", None);
        assert!(w.contains("run.pipelines") && w.contains("P = 8"), "{w}");
        let w = why("[volume]\nsize = 16\n", Some(3));
        assert!(w.contains("--pipelines") && w.contains("P = 3"), "{w}");
        let w = why("[volume]\nsize = 136\n", None);
        assert!(
            w.contains("volume:") && w.contains("128 voxels per edge"),
            "{w}"
        );
        let w = why("[volume]\nsize = 16\n[quality]\nalpha_bits = 3\n", None);
        assert!(w.contains("quality.alpha_bits"), "{w}");
        let w = why(
            "[volume]\nsize = 16\n[quality]\nsamples_per_slice = 2\n",
            None,
        );
        assert!(w.contains("quality.samples_per_slice"), "{w}");
        let e = Scene::parse("[volume]\nsize = 16\n[run]\npipelines = 3\n", "p3.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("run.pipelines") && e.contains("3"), "{e}");
    }
}
