//! What `cube5 render` runs for a scene: the frame model (`units::cube5_frame`, bit-exact with the
//! RTL frame) for every scene the hardware can express, else a what-if model named as such.
//!
//! A scene is one frame of `cube5_frame` when its projection is
//! parallel, and its `[quality]` asks for nothing the frame does not compute (bilinear samples on
//! the slices, one sample per slice, one ray per voxel, the 6-neighbourhood gradient at orthogonal
//! positions). Its widths become the frame's parameters (`FrameConfig`), so a width is a knob of
//! the one model, not of a second one. Everything else (sheared or tri-linear interpolation, more
//! samples per slice, supersampling, the 10- and 26-neighbourhood gradients) runs on the what-if
//! pipeline model `render::render_pipeline`, and `plan:` says so. Every render mode is a frame
//! mode (MIP, composite, MinIP, X-ray, first-opaque).

use crate::camera::Camera;
use crate::error::{ModelError, Result};
use crate::geometry::Solid;
use crate::render::{
    CompositeMode, GradientScheme, ImageF64, Interpolation, Projection, RenderParams,
};
use crate::scene::Scene;
use crate::transfer::TransferFunction;
use crate::unit::UnitConfig;
use crate::units::cube5_frame::{
    self, BasePlane, FrameConfig, FrameMode, FrameParams, FrameSetup, FrameUnits, ModeOptions,
    SweepStats, SweepVolume,
};
use crate::units::cube5_shader::{DistantLight, Phong};
use crate::units::cube5_skewmem::BlockLut;
use crate::units::cube5_warp::{self, Affine, WarpConfig, WarpRegs};
use crate::volume::Volume;
use glam::DVec3;

/// Why a scene is not one frame of the hardware: one phrase per setting (empty: it is).
pub fn not_expressible(scene: &Scene) -> Vec<String> {
    let q = scene.quality();
    let mut why = Vec::new();
    if scene.gi.is_some() {
        // `cube5 cosim` on a GI scene: one line, and nothing else to say.
        return vec![
            "the scene has a [gi] section: it is no cube5_frame frame (`cube5 cosim` runs it on gicube_processor)".into(),
        ];
    }
    if scene.view.projection != Projection::Parallel {
        why.push("view.projection = \"perspective\" (the frame is parallel only; the hardware's perspective is ER-perspective on cube5_er: run.renderer = \"er\")".into());
    }
    if q.interpolation != Interpolation::BilinearSlice {
        why.push(format!(
            "quality.interpolation = \"{}\" (the frame samples bilinearly on the slices)",
            q.interpolation.name()
        ));
    }
    if q.samples_per_slice != 1 {
        why.push(format!(
            "quality.samples_per_slice = {} (the frame takes one per slice)",
            q.samples_per_slice
        ));
    }
    if q.supersampling != 1 {
        why.push(format!(
            "quality.supersampling = {} (the frame casts one ray per voxel)",
            q.supersampling
        ));
    }
    if q.gradient != GradientScheme::Six {
        why.push(format!(
            "quality.gradient = {} (the frame's gradient is the 6-neighbourhood)",
            u32::from(q.gradient)
        ));
    }
    for (i, l) in scene.lights.iter().enumerate() {
        if l.colour.iter().any(|&c| c != l.colour[0]) {
            why.push(format!(
                "light[{i}].colour = {:?} (the frame's reflectance map is one intensity per light)",
                l.colour
            ));
        }
    }
    if why.is_empty() {
        if let Err(e) = frame_config(scene) {
            why.push(e.to_string());
        }
    }
    why
}

/// The frame's render mode of a scene's `render.mode` (every mode is one).
pub fn frame_mode(mode: CompositeMode) -> FrameMode {
    match mode {
        CompositeMode::Composite => FrameMode::Composite,
        CompositeMode::Mip => FrameMode::Mip,
        CompositeMode::Minip => FrameMode::Minip,
        CompositeMode::Xray => FrameMode::Xray,
        CompositeMode::FirstOpaque => FrameMode::FirstOpaque,
    }
}

/// The frame configuration of a scene's widths (`[quality]`), on the RTL's defaults otherwise;
/// `voxel_bits` unset keeps the frame's `VoxelW` (volumes are scaled onto it).
pub fn frame_config(scene: &Scene) -> Result<FrameConfig> {
    let q = scene.quality();
    let mut params = FrameConfig::DEFAULT.to_params();
    let widths = [
        ("VoxelW", "voxel_bits", q.voxel_bits),
        ("WeightW", "weight_bits", Some(q.weight_bits)),
        ("FracW", "frac_bits", Some(q.frac_bits)),
        ("ColorW", "colour_bits", Some(q.colour_bits)),
        ("AlphaW", "alpha_bits", Some(q.alpha_bits)),
        ("AccW", "acc_bits", Some(q.acc_bits)),
    ];
    for (name, _, value) in widths {
        if let (Some(v), Some(slot)) = (value, params.iter_mut().find(|(n, _)| *n == name)) {
            slot.1 = i64::from(v);
        }
    }
    FrameConfig::from_params(&params)
        .map(|cfg| FrameConfig {
            // Opaque geometry needs the depth test (`DepthTest = 1`); without it, nothing pays.
            depth_test: scene.geometry.is_some(),
            ..cfg
        })
        .map_err(|e| {
            // Name the scene's fields behind the parameters the frame refuses.
            let e = e.to_string();
            let fields: Vec<String> = widths
                .iter()
                .filter(|(name, _, _)| e.contains(name))
                .map(|(name, field, v)| match v {
                    Some(v) => format!("quality.{field} = {v} ({name})"),
                    None => format!("quality.{field} unset ({name})"),
                })
                .collect();
            ModelError::Config(format!(
                "{}: the frame cannot take these widths: {e}",
                fields.join(", ")
            ))
        })
}

/// The volume at voxel width `w`: `v << (w - bits)` or `v >> (bits - w)`, the same integers the
/// RTL's memory is loaded with.
pub fn at_voxel_width(vol: &Volume, w: u32) -> Result<Volume> {
    let data = vol
        .data
        .iter()
        .map(|&v| {
            if vol.bits <= w {
                v << (w - vol.bits)
            } else {
                v >> (vol.bits - w)
            }
        })
        .collect();
    Volume::new(vol.dims, vol.spacing, w, data)
}

/// `vol` (at the frame's voxel width, as its memory is loaded) after the scene's pre-pass
/// (`volume.prefilter`: the three passes of `cube5_sepconv`'s model), or as it is without one.
pub fn prefiltered(scene: &Scene, vol: &Volume) -> Result<Volume> {
    Ok(crate::prefilter::apply(vol, scene.prefilter())?.map_or_else(|| vol.clone(), |r| r.volume))
}

/// The scene's lights and material in the frame's axes (the reflectance map's input).
pub fn scene_phong(scene: &Scene, params: &FrameParams) -> Phong {
    params_phong(&scene.render_params(), params)
}

/// The lights, material and shading switch of `render` in the frame's axes (what
/// [`scene_phong`] reads from a scene; ER-perspective's studies call it with render parameters).
pub fn params_phong(render: &RenderParams, params: &FrameParams) -> Phong {
    let lights: Vec<DistantLight> = render
        .lights
        .iter()
        .map(|l| DistantLight {
            // The scene gives the direction light travels; the map wants the way to the light.
            direction: l.direction.map(|c| -c),
            intensity: (l.colour.iter().sum::<f64>() / 3.0).clamp(0.0, 4.0),
        })
        .collect();
    let base = cube5_frame::frame_phong(params, &lights);
    if render.shading {
        let m = render.material;
        Phong {
            ambient: m.ambient,
            diffuse: m.diffuse,
            specular: m.specular,
            shininess: m.shininess,
            ..base
        }
    } else {
        // Unlit: the map is 1 everywhere.
        Phong {
            ambient: 1.0,
            diffuse: 0.0,
            specular: 0.0,
            ..base
        }
    }
}

/// The look of a frame: transfer function and lighting (frame axes), early termination, the
/// first-opaque threshold and the 2-D transfer function ([`ModeOptions`]), X-ray's shift and the
/// opaque geometry. A scene's frame ([`FrameJob`]) and the test bench's frames share it.
#[derive(Debug, Clone)]
pub struct Look {
    pub tf: TransferFunction,
    pub phong: Phong,
    /// Early termination (`Composite`) at accumulated opacity `termination_at` (0..1; >= 1: off).
    pub early_termination: bool,
    pub termination_at: f64,
    /// The 2-D transfer function and first-opaque's threshold (`ModeOptions`).
    pub boundary: Option<f64>,
    pub threshold: f64,
    /// X-ray: `XrayShift` in place of the set-up's (a sum that saturates, for the tests).
    pub xray_shift: Option<u32>,
    /// Opaque solids rasterized into the geometry table of a `DepthTest = 1` frame (none: every
    /// pixel at `Znone`).
    pub geometry: Vec<Solid>,
}

impl Default for Look {
    /// The head phantom's transfer function, two lights, no early termination (at
    /// `cube5_frame::ET_DEFAULT` when on), first-opaque at 0.5, the 1-D table.
    fn default() -> Self {
        let opts = ModeOptions::default();
        Self {
            tf: TransferFunction::head_default(),
            phong: Phong::two_lights(),
            early_termination: false,
            termination_at: cube5_frame::ET_DEFAULT,
            threshold: opts.threshold,
            boundary: opts.boundary,
            xray_shift: None,
            geometry: Vec::new(),
        }
    }
}

impl Look {
    /// The frame model's options of this look.
    pub fn options(&self) -> ModeOptions {
        ModeOptions {
            early_termination: self.early_termination.then_some(self.termination_at),
            threshold: self.threshold,
            boundary: self.boundary,
        }
    }
}

/// One frame of a scene, set up as the host sets up the RTL: the volume at the frame's voxel
/// width as the memory returns it, the view, the block LUT and the units.
#[derive(Debug, Clone)]
pub struct FrameJob {
    pub cfg: FrameConfig,
    /// The volume as the memory returns it: voxels of blocks the LUT skips read as 0.
    pub seen: Volume,
    pub dir: DVec3,
    pub setup: FrameSetup,
    pub lut: BlockLut,
    pub look: Look,
    pub units: FrameUnits,
    /// `seen` in the sweep's axis order with its blocks' voxel ranges, made once with the job
    /// (the model's copy; it depends on the slice axis only).
    pub sweep: SweepVolume,
    /// The hardware's counts that depend on the view and the block LUT only, made once with the
    /// job: the empty slices the sweep skips before and after, and the samples of the swept
    /// slices in blocks the LUT skips.
    pub lut_counts: ((usize, usize), u64),
}

/// What one frame of the model computed.
#[derive(Debug, Clone)]
pub struct FrameRun {
    pub base: BasePlane,
    /// Samples the sweep takes (one per voxel of every slice it does not skip).
    pub samples: u64,
    /// Empty slices the sweep skips before and after (`cube5_frame::empty_slices`).
    pub skipped_slices: (usize, usize),
    pub slices: usize,
    /// Samples of the swept slices whose voxels lie in blocks the LUT skips: their memory reads
    /// are not made (they read as 0).
    pub samples_in_skipped_blocks: u64,
    /// Rays the compositing unit terminated early (opaque), of all rays of the base plane.
    pub terminated_rays: usize,
    /// What the model's sweep computed (samples shaded, classified only, after termination).
    pub model: SweepStats,
}

impl FrameJob {
    /// Sets up one frame of `scene` on `raw` at `cfg` for `p` pipelines (the set-up refuses
    /// dimensions that are not multiples of `p`; the image does not depend on `p`).
    pub fn new(scene: &Scene, raw: &Volume, cfg: FrameConfig, p: usize) -> Result<Self> {
        let mode = frame_mode(scene.render.mode);
        let vol = prefiltered(scene, &at_voxel_width(raw, cfg.trilin.voxel_w)?)?;
        let dir = scene.render_params().direction()?;
        let setup = FrameSetup::new(vol.dims, vol.spacing, dir, p)?;
        // Blocks whose voxels are all 0 are marked empty: the memory skips their beams.
        let lut = BlockLut::from_volume(&vol, cfg.block as usize, 0)?;
        let seen = seen_through(&vol, &lut)?;
        let look = Look {
            tf: scene.transfer_function(),
            phong: scene_phong(scene, &setup.params),
            early_termination: mode == FrameMode::Composite,
            termination_at: scene.render.early_termination,
            threshold: scene.render.threshold,
            boundary: scene.boundary(),
            xray_shift: None,
            geometry: scene
                .geometry
                .as_ref()
                .map(|g| g.solids())
                .unwrap_or_default(),
        };
        let mut units =
            FrameUnits::with_options(&cfg, mode, &setup, &look.tf, &look.phong, &look.options())?;
        // The depth test: the buffer is preloaded with the geometry's RGBA-Z image (none: every
        // pixel at Znone), rasterized by the host on this view's base plane.
        match (&scene.geometry, cfg.depth_test) {
            (Some(_), true) => {
                let img = crate::geometry::rasterize(&setup.params, &look.geometry, &cfg.compos);
                units.set_geometry(&setup.params, img)?;
            }
            (None, true) => {
                let (w, h) = setup.params.base_plane_size();
                units.set_geometry(
                    &setup.params,
                    cube5_frame::GeometryImage::none(w, h, &cfg.compos),
                )?;
            }
            (Some(_), false) => {
                return Err(ModelError::Config(
                    "geometry: this cube5_frame configuration has no depth test (DepthTest = 0)"
                        .into(),
                ))
            }
            (None, false) => {}
        }
        let sweep = SweepVolume::new(&setup.params, &seen).ok_or_else(|| {
            ModelError::Volume(format!(
                "volume of {:?} voxels does not fit the frame's set-up",
                seen.dims
            ))
        })?;
        let lut_counts = lut_counts(&setup.params, &lut);
        Ok(Self {
            cfg,
            seen,
            dir,
            setup,
            lut,
            look,
            units,
            sweep,
            lut_counts,
        })
    }

    /// The base plane, bit-exact with the RTL frame, and what the sweep did.
    pub fn render(&self) -> FrameRun {
        let params = &self.setup.params;
        let (base, model) = if self.units.fast_path() {
            cube5_frame::render_sweep(params, &self.sweep, &self.units)
        } else {
            // The fast path lacks this mode (or the 2-D table): the exact model, same bits.
            cube5_frame::render_exact_stats(params, &self.seen, &self.units)
        };
        let (skipped_slices, in_skipped) = self.lut_counts;
        let swept = params.nk - skipped_slices.0 - skipped_slices.1;
        FrameRun {
            samples: (swept * params.ni * params.nj) as u64,
            samples_in_skipped_blocks: in_skipped,
            skipped_slices,
            slices: params.nk,
            // The sweep counted them (its coxels are the base plane).
            terminated_rays: model.rays_terminated as usize,
            model,
            base,
        }
    }

    /// The camera of the scene's image (the view of this frame, the scene's up, roll, size and zoom).
    pub fn camera(&self, scene: &Scene) -> Camera {
        // The scene's camera (up, roll, zoom): the reference renderer's.
        scene.render_params().camera(&self.seen, self.dir)
    }

    /// The warp of this frame onto the scene's image: the ideal affine map and the registers the
    /// host sets up from it (`docs/numerics/warp.md`, "Set-up").
    pub fn warp_setup(&self, scene: &Scene, base: &BasePlane) -> Result<(Affine, WarpRegs)> {
        let camera = self.camera(scene);
        let affine = Affine::of_view(&self.setup.params, self.seen.spacing, &camera);
        let size = |n: usize| {
            u32::try_from(n)
                .map_err(|_| ModelError::Image(format!("base plane edge {n} is too large")))
        };
        let regs = WarpRegs::set_up(
            &affine,
            (size(base.width)?, size(base.height)?),
            (camera.width, camera.height),
        )?;
        Ok((affine, regs))
    }

    /// The warp unit's configuration for this frame: the frame's `ColorW`, the RTL's weights.
    pub fn warp_config(&self) -> WarpConfig {
        WarpConfig {
            color_w: self.cfg.compos.color_w,
            ..WarpConfig::DEFAULT
        }
    }

    /// The final image: the base plane's codes through the warp model (`units::cube5_warp`, the
    /// hardware's 8-bit pixels).
    pub fn image(&self, scene: &Scene, base: &BasePlane) -> Result<ImageF64> {
        let (_, regs) = self.warp_setup(scene, base)?;
        let codes = cube5_warp::base_codes(base, &self.cfg.compos);
        let pixels = cube5_warp::warp_image(&self.warp_config(), &regs, &codes);
        Ok(cube5_warp::to_image(regs.out_w, regs.out_h, &pixels))
    }

    /// The f64 warp of the unquantized coxel colours (`cube5_frame::warp`, what `cube5 render`
    /// showed before the warp unit): a reference, not the hardware's image.
    pub fn image_f64_coxels(&self, scene: &Scene, base: &BasePlane) -> ImageF64 {
        cube5_frame::warp(
            &self.setup.params,
            self.seen.spacing,
            &base.rgb(&self.cfg.compos),
            (base.width, base.height),
            &self.camera(scene),
        )
    }

    /// The ideal f64 bilinear warp of the same base-plane codes (the warp's reference).
    pub fn image_reference(&self, scene: &Scene, base: &BasePlane) -> Result<ImageF64> {
        let (affine, regs) = self.warp_setup(scene, base)?;
        let codes = cube5_warp::base_codes(base, &self.cfg.compos);
        Ok(cube5_warp::reference(
            &affine,
            &codes,
            self.cfg.compos.color_w,
            (regs.out_w, regs.out_h),
        ))
    }
}

/// The empty slices the sweep of `params` skips before and after (`cube5_frame::empty_slices`),
/// and the samples of the swept slices whose voxels lie in blocks `lut` skips (their memory reads
/// are not made).
fn lut_counts(params: &FrameParams, lut: &BlockLut) -> ((usize, usize), u64) {
    let skipped_slices = cube5_frame::empty_slices(params, lut);
    let b = lut.block as usize;
    let mut in_skipped = 0u64;
    for s in skipped_slices.0..params.nk - skipped_slices.1 {
        let k = params.slice(s).k;
        for bj in 0..params.nj.div_ceil(b) {
            for bi in 0..params.ni.div_ceil(b) {
                let mut blk = [0u32; 3];
                blk[params.axis_i] = bi as u32;
                blk[params.axis_j] = bj as u32;
                blk[params.axis_k] = (k / b) as u32;
                if lut.entry(blk).is_none_or(|e| e.empty || e.masked) {
                    let w = b.min(params.ni - bi * b) * b.min(params.nj - bj * b);
                    in_skipped += w as u64;
                }
            }
        }
    }
    (skipped_slices, in_skipped)
}

/// What the memory returns: `vol` with the voxels of blocks the LUT skips (empty or masked) read
/// as 0 (docs/numerics/skewmem.md).
pub fn seen_through(vol: &Volume, lut: &BlockLut) -> Result<Volume> {
    let b = lut.block as usize;
    let [nx, ny, _] = vol.dims;
    let mut data = vol.data.clone();
    for (i, v) in data.iter_mut().enumerate() {
        let (x, y, z) = (i % nx, (i / nx) % ny, i / (nx * ny));
        let e = lut.entry([(x / b) as u32, (y / b) as u32, (z / b) as u32]);
        if e.is_none_or(|e| e.empty || e.masked) {
            *v = 0;
        }
    }
    Volume::new(vol.dims, vol.spacing, vol.bits, data)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(text: &str) -> Scene {
        Scene::parse(text, "s.toml").unwrap()
    }

    #[test]
    fn the_default_scene_is_one_frame() {
        assert!(not_expressible(&Scene::default()).is_empty());
        assert_eq!(
            frame_config(&Scene::default()).unwrap(),
            FrameConfig::DEFAULT
        );
    }

    #[test]
    fn what_the_frame_cannot_do_is_named() {
        let why = not_expressible(&scene(
            "[quality]\ninterpolation = \"sheared\"\nsamples_per_slice = 2\ngradient = 10\n",
        ));
        assert_eq!(why.len(), 3, "{why:?}");
        assert!(why[0].contains("sheared") && why[2].contains("gradient = 10"));
        for mode in ["minip", "xray", "first-opaque"] {
            let why = not_expressible(&scene(&format!("[render]\nmode = \"{mode}\"\n")));
            assert!(why.is_empty(), "{mode} is a frame mode: {why:?}");
        }
        let why = not_expressible(&scene(
            "[[light]]\ndirection = [1, 0, 0]\ncolour = [1.0, 0.5, 0.5]\n[[light]]\ndirection = [0, 1, 0]\ncolour = [2.0, 2.0, 2.0]\n",
        ));
        assert_eq!(why.len(), 1, "{why:?}");
        assert!(why[0].contains("light[0].colour"), "{why:?}");
        let why = not_expressible(&scene("[quality]\nacc_bits = 8\n"));
        assert!(why[0].contains("widths"), "{why:?}");
    }

    #[test]
    fn the_2d_transfer_function_is_refused_off_the_frame() {
        let vol = crate::phantom::head_phantom(16, 12).unwrap();
        for (text, names) in [
            (
                "[quality]\nsamples_per_slice = 2\n",
                "quality.samples_per_slice",
            ),
            ("[run]\nrenderer = \"reference\"\n", "run.renderer"),
        ] {
            let s = scene(&format!("[transfer]\nboundary = 0.5\n{text}"));
            let e = crate::scene::Plan::new(&s, &vol).unwrap_err().to_string();
            assert!(e.contains("transfer.boundary") && e.contains(names), "{e}");
        }
        let s = scene("[transfer]\nboundary = 0.5\n");
        let plan = crate::scene::Plan::new(&s, &vol).unwrap().to_string();
        assert!(
            plan.contains("transfer.boundary: the exact per-sample frame model"),
            "{plan}"
        );
    }

    #[test]
    fn widths_are_frame_parameters() {
        let cfg = frame_config(&scene("[quality]\ncolour_bits = 10\nvoxel_bits = 16\n")).unwrap();
        assert_eq!((cfg.compos.color_w, cfg.shader.color_w), (10, 10));
        assert_eq!((cfg.trilin.voxel_w, cfg.gradient.voxel_w), (16, 16));
    }

    #[test]
    fn units_at_the_default_widths_are_the_frame_models() {
        // frame_units at FrameConfig::DEFAULT without termination builds what FrameUnits::new does.
        let vol = crate::phantom::head_phantom(16, 12).unwrap();
        for mode in ["composite", "mip"] {
            let s = scene(&format!(
                "[render]\nmode = \"{mode}\"\nearly_termination = 1.0\n"
            ));
            let job = FrameJob::new(&s, &vol, FrameConfig::DEFAULT, 1).unwrap();
            let fu =
                FrameUnits::new(job.units.mode, &job.setup, &job.look.tf, &job.look.phong).unwrap();
            let a = cube5_frame::render_base_plane(&job.setup.params, &job.seen, &job.units);
            let b = cube5_frame::render_base_plane(&job.setup.params, &job.seen, &fu);
            assert!(a.coxels == b.coxels, "{mode}");
        }
    }

    #[test]
    fn early_termination_follows_the_scene() {
        let vol = crate::phantom::head_phantom(24, 12).unwrap();
        let on = FrameJob::new(
            &scene("[render]\nearly_termination = 0.3\n"),
            &vol,
            FrameConfig::DEFAULT,
            1,
        )
        .unwrap();
        let off = FrameJob::new(
            &scene("[render]\nearly_termination = 1.0\n"),
            &vol,
            FrameConfig::DEFAULT,
            1,
        )
        .unwrap();
        let (a, b) = (on.render(), off.render());
        assert!(a.terminated_rays > 0 && b.terminated_rays == 0);
    }

    #[test]
    fn samples_in_skipped_blocks_are_the_memory_model_s_skipped_beams() {
        use crate::units::cube5_skewmem::{SkewConfig, SkewDims, SkewMem};
        let vol = crate::phantom::head_phantom(32, 12).unwrap();
        for view in [
            "[view]\nazimuth = 30.0\n",
            "[view]\ndirection = [1, 0.2, -0.4]\n",
        ] {
            let job = FrameJob::new(&scene(view), &vol, FrameConfig::DEFAULT, 4).unwrap();
            let run = job.render();
            assert!(run.samples_in_skipped_blocks > 0, "{view}");
            let cfg = SkewConfig {
                p: 4,
                voxel_w: 12,
                max_dim_log2: 5,
                block: 8,
                read_latency: 1,
                cnt_w: 16,
            };
            let dims = SkewDims::new(&cfg, job.seen.dims.map(|d| d as u32)).unwrap();
            let mut mem = SkewMem::new(cfg, dims, job.lut.clone()).unwrap();
            let acc =
                cube5_frame::sweep_memory(&job.setup.params, run.skipped_slices, &mut mem).unwrap();
            assert_eq!(
                run.samples_in_skipped_blocks,
                acc.beams_skipped * 4,
                "{view}"
            );
            assert_eq!(
                run.samples,
                (acc.beams_read + acc.beams_skipped) * 4,
                "{view}"
            );
        }
    }
}
