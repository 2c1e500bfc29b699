//! Every scene field either changes what the hardware's run computes (its configuration, the base
//! plane, or the image warped from it) or is refused with a message that names the field: nothing
//! is dropped without a word (issue 17).
//!
//! The fields are not listed by hand: each table's field names come from the scene parser itself
//! (the error `deny_unknown_fields` gives for an unknown key lists every known one), and the test
//! fails when a field has no case below. A case gives the scene the field acts in (`context`), a
//! changed value, and where the change must show. The RTL run and `cube5 render` share
//! `scene_render::FrameJob` (cli/src/cosim.rs), and the RTL's base plane is bit-exact with it
//! (tb-rs/tests/cube5_frame.rs, cli/tests/scenes.rs), so the frame model stands in for the RTL here.

use cube5_model::render::{render_reference, ImageF64};
use cube5_model::scene::{Plan, Renderer, Scene};
use cube5_model::scene_gi::{processor_config, run_counts_text, GiJob};
use cube5_model::scene_render::{frame_config, not_expressible, FrameJob};
use cube5_model::slab_perspective::render_slabs;
use std::collections::BTreeSet;
use std::path::Path;

/// Where a changed value must show.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Shows {
    /// The hardware run: the frame's configuration, its base plane or the warped image changes.
    Frame,
    /// The scene is refused (by the parser, or as not one frame of the hardware) with a message
    /// naming the field.
    Refused,
    /// What runs: the plan's target or renderer (the field chooses the run, not its bits).
    Run,
    /// The f64 reference renderer's image (`renderer = "reference"`, `cube5 render --compare`);
    /// the frame refuses the scene when it asks for what the field serves (named by `because`).
    Reference { because: &'static str },
    /// The what-if slab-perspective model's image (`renderer = "slabs"`), likewise.
    Slabs { because: &'static str },
    /// The ER-perspective model's image (`renderer = "er"`), likewise.
    Er { because: &'static str },
    /// A `[gi]` scene's run on the GI-Cube processor model: its configuration, the counts of its
    /// passes or its image change.
    Processor,
}

struct Case {
    field: &'static str,
    /// Scene text the field acts in (added to the base scene).
    context: &'static str,
    /// The same with the field changed.
    changed: &'static str,
    shows: Shows,
}

/// A small expressible scene: a 24^3 head, a 48^2 image.
const BASE: &str = "[volume]\nsize = 24\n[image]\nwidth = 48\nheight = 48\n";

/// The raw file the `volume.file` cases read (written by the test): 20 x 18 x 16 little-endian
/// 16-bit voxels, `RAW_BYTES` bytes.
const RAW_NAME: &str = "fields.raw";
const RAW_DIMS: [usize; 3] = [20, 18, 16];

fn cases() -> Vec<Case> {
    use Shows::*;
    let c = |field, context, changed, shows| Case {
        field,
        context,
        changed,
        shows,
    };
    vec![
        // [volume]: an embedded phantom ...
        c("volume.phantom", "", "[volume]\nphantom = \"sphere\"\n", Frame),
        c("volume.size", "", "[volume]\nsize = 28\n", Frame),
        c("volume.bits", "", "[volume]\nbits = 8\n", Frame),
        // ... or a file.
        c("volume.file", "", "[volume]\nfile = \"fields.raw\"\ndims = [20, 18, 16]\ntype = \"u16\"\n", Frame),
        c("volume.format", RAW_FILE, "[volume]\nformat = \"nifti\"\ndims = ~\ntype = ~\n", Refused),
        c("volume.dims", RAW_FILE, "[volume]\nfile = \"fields.raw\"\ndims = [20, 16, 18]\ntype = \"u16\"\n", Frame),
        c("volume.type", RAW_FILE, "[volume]\nfile = \"fields.raw\"\ndims = [20, 18, 32]\ntype = \"u8\"\n", Frame),
        c("volume.endian", RAW_FILE, "[volume]\nfile = \"fields.raw\"\ndims = [20, 18, 16]\ntype = \"u16\"\nendian = \"big\"\n", Frame),
        c("volume.spacing", RAW_FILE, "[volume]\nfile = \"fields.raw\"\ndims = [20, 18, 16]\ntype = \"u16\"\nspacing = [1.0, 1.0, 2.0]\n", Frame),
        c("volume.offset", RAW_FILE, "[volume]\nfile = \"fields.raw\"\ndims = [20, 18, 15]\ntype = \"u16\"\noffset = 720\n", Frame),
        // The 3-pass pre-filter before the frame; an unknown kernel, and a GI scene, refuse it.
        c("volume.prefilter", "", "[volume]\nprefilter = \"gauss\"\n", Frame),
        c("volume.prefilter", "", "[volume]\nprefilter = \"gauss-narrow\"\n", Frame),
        c("volume.prefilter", "", "[volume]\nprefilter = \"sobel\"\n", Refused),
        c("volume.prefilter", GI, "[volume]\nprefilter = \"gauss\"\n", Refused),
        // [view]
        c("view.azimuth", "", "[view]\nazimuth = 10.0\n", Frame),
        c("view.elevation", "", "[view]\nelevation = 40.0\n", Frame),
        c("view.direction", "", "[view]\ndirection = [1.0, 0.3, -0.2]\n", Frame),
        c("view.projection", "", "[view]\nprojection = \"perspective\"\n", Refused),
        c("view.fov", PERSPECTIVE, "[view]\nprojection = \"perspective\"\nfov = 50.0\n", Reference { because: "view.projection" }),
        c("view.zoom", "", "[view]\nzoom = 1.5\n", Frame),
        c("view.up", "[view]\ndirection = [1.0, 0.3, -0.2]\n", "[view]\ndirection = [1.0, 0.3, -0.2]\nup = [0.0, 1.0, 0.0]\n", Frame),
        c("view.roll", "", "[view]\nroll = 30.0\n", Frame),
        c("view.slabs", SLABS, "[view]\nprojection = \"perspective\"\nslabs = 3\n", Slabs { because: "view.projection" }),
        c("view.slab_spacing", SLABS, "[view]\nprojection = \"perspective\"\nslab_spacing = \"geometric\"\n", Slabs { because: "view.projection" }),
        c("view.er_rays_per_voxel", ER, "[view]\ner_rays_per_voxel = 2\n", Er { because: "view.projection" }),
        c("view.er_merge", ER, "[view]\ner_merge = \"centre\"\n", Er { because: "view.projection" }),
        // [image]: the warp's output.
        c("image.width", "", "[image]\nwidth = 40\n", Frame),
        c("image.height", "", "[image]\nheight = 40\n", Frame),
        // [render]
        c("render.mode", "", "[render]\nmode = \"mip\"\n", Frame),
        c("render.shading", "", "[render]\nshading = false\n", Frame),
        c("render.step", "", "[render]\nstep = 0.5\n", Reference { because: "" }),
        c("render.early_termination", "", "[render]\nearly_termination = 0.3\n", Frame),
        c("render.threshold", "[render]\nmode = \"first-opaque\"\n", "[render]\nmode = \"first-opaque\"\nthreshold = 0.2\n", Frame),
        // [transfer]
        c("transfer.preset", "", "[transfer]\npreset = \"bone\"\n", Frame),
        c("transfer.points", "", "[transfer]\npoints = [{ density = 0.0, rgba = [0, 0, 0, 0] }, { density = 1.0, rgba = [1, 1, 1, 0.5] }]\n", Frame),
        c("transfer.points.density", "[transfer]\npoints = [{ density = 0.0, rgba = [0, 0, 0, 0] }, { density = 1.0, rgba = [1, 1, 1, 0.5] }]\n", "[transfer]\npoints = [{ density = 0.2, rgba = [0, 0, 0, 0] }, { density = 1.0, rgba = [1, 1, 1, 0.5] }]\n", Frame),
        c("transfer.points.rgba", "[transfer]\npoints = [{ density = 0.0, rgba = [0, 0, 0, 0] }, { density = 1.0, rgba = [1, 1, 1, 0.5] }]\n", "[transfer]\npoints = [{ density = 0.0, rgba = [0, 0, 0, 0] }, { density = 1.0, rgba = [1, 0, 1, 0.5] }]\n", Frame),
        c("transfer.boundary", "", "[transfer]\nboundary = 0.25\n", Frame),
        c("transfer.boundary", "[render]\nmode = \"mip\"\n", "[render]\nmode = \"mip\"\n[transfer]\nboundary = 0.25\n", Refused),
        // [shading]: the Phong coefficients.
        c("shading.ambient", "", "[shading]\nambient = 0.5\n", Frame),
        c("shading.diffuse", "", "[shading]\ndiffuse = 0.2\n", Frame),
        c("shading.specular", "", "[shading]\nspecular = 0.9\n", Frame),
        c("shading.shininess", "", "[shading]\nshininess = 4.0\n", Frame),
        // [[light]]
        c("light", "", "[[light]]\ndirection = [0.0, 0.0, -1.0]\n", Frame),
        c("light.direction", "[[light]]\ndirection = [0.0, 0.0, -1.0]\n", "[[light]]\ndirection = [1.0, 0.0, 0.0]\n", Frame),
        c("light.colour", "[[light]]\ndirection = [0.0, 0.0, -1.0]\n", "[[light]]\ndirection = [0.0, 0.0, -1.0]\ncolour = [2.0, 2.0, 2.0]\n", Frame),
        // American spellings (aliases).
        c("light.color", "[[light]]\ndirection = [0.0, 0.0, -1.0]\n", "[[light]]\ndirection = [0.0, 0.0, -1.0]\ncolor = [2.0, 2.0, 2.0]\n", Frame),
        c("quality.color_bits", "", "[quality]\ncolor_bits = 5\n", Frame),
        // [quality]: widths are the frame's parameters; the rest it does not compute.
        c("quality.voxel_bits", "", "[quality]\nvoxel_bits = 8\n", Frame),
        c("quality.weight_bits", "", "[quality]\nweight_bits = 4\n", Frame),
        c("quality.frac_bits", "", "[quality]\nfrac_bits = 2\n", Frame),
        c("quality.colour_bits", "", "[quality]\ncolour_bits = 5\n", Frame),
        c("quality.alpha_bits", "", "[quality]\nalpha_bits = 8\n", Frame),
        c("quality.acc_bits", "", "[quality]\nacc_bits = 24\n", Frame),
        c("quality.acc_bits", "", "[quality]\nacc_bits = 12\n", Refused),
        c("quality.samples_per_slice", "", "[quality]\nsamples_per_slice = 2\n", Refused),
        c("quality.supersampling", "", "[quality]\nsupersampling = 2\n", Refused),
        c("quality.interpolation", "", "[quality]\ninterpolation = \"sheared\"\n", Refused),
        c("quality.gradient", "", "[quality]\ngradient = 26\n", Refused),
        // [run]: what runs.
        c("run.target", "", "[run]\ntarget = \"rtl\"\n", Run),
        c("run.renderer", "", "[run]\nrenderer = \"reference\"\n", Run),
        // run.pipelines sets the RTL configuration's P (scene_elab's tests); here its refusal.
        c("run.pipelines", "", "[run]\npipelines = 3\n", Refused),
        // [gi]: the GI-Cube processor model's lighting and rendering passes.
        c("gi.light", GI, "[gi]\nlight = [-0.55, 0.25, -0.8]\n", Processor),
        c("gi.light", GI, "[gi]\nlight = [0.0, 0.0, 0.0]\n", Refused),
        c("gi.energy", GI, "[gi]\nenergy = 0.5\n", Processor),
        c("gi.energy", GI, "[gi]\nenergy = 0.0\n", Refused),
        c("gi.light_rays", GI, "[gi]\nlight_rays = 60\n", Processor),
        c("gi.light_rays", GI, "[gi]\nlight_rays = 20\n", Refused),
        c("gi.albedo", GI, "[gi]\nalbedo = 0.8\n", Processor),
        c("gi.albedo", GI, "[gi]\nalbedo = 1.5\n", Refused),
        c("gi.bounces", GI_PHOTONS, "[gi]\nbounces = 0\n", Processor),
        c("gi.bounces", GI, "[gi]\nbounces = 2\n", Refused),
        c("gi.passes", GI, "[gi]\npasses = 1\n", Processor),
        c("gi.passes", GI, "[gi]\npasses = 3\n", Refused),
        c("gi.block_size", GI, "[gi]\nblock_size = 8\n", Processor),
        c("gi.block_size", GI, "[gi]\nblock_size = 12\n", Refused),
        c("gi.queue_length", GI, "[gi]\nqueue_length = 3\n", Processor),
        c("gi.queue_length", GI, "[gi]\nqueue_length = 0\n", Refused),
        // What the rest of a scene means in a [gi] scene.
        c("render.step", GI, "[render]\nstep = 0.5\n", Processor),
        c("render.early_termination", GI, "[render]\nearly_termination = 0.3\n", Processor),
        c("view.projection", GI, "[view]\nprojection = \"perspective\"\n", Processor),
        c("view.fov", GI_PERSPECTIVE, "[view]\nfov = 50.0\n", Processor),
        c("view.zoom", GI, "[view]\nzoom = 1.5\n", Processor),
        c("render.mode", GI, "[render]\nmode = \"mip\"\n", Refused),
        c("transfer.boundary", GI, "[transfer]\nboundary = 0.25\n", Refused),
        c("render.shading", GI, "[render]\nshading = false\n", Refused),
        c("shading.ambient", GI, "[shading]\nambient = 0.5\n", Refused),
        c("light", GI, "[[light]]\ndirection = [0.0, 0.0, -1.0]\n", Refused),
        c("quality.supersampling", GI, "[quality]\nsupersampling = 2\n", Refused),
        c("run.target", GI, "[run]\ntarget = \"rtl\"\n", Run),
        c("run.renderer", GI, "[run]\nrenderer = \"reference\"\n", Processor),
        // [geometry]: opaque boxes and spheres, rasterized into the depth test's RGBA-Z table.
        c("geometry.box", "", BOX, Frame),
        c("geometry.box.min", BOX, "[[geometry.box]]\nmin = [2.0, 6.0, 2.0]\nmax = [16.0, 12.0, 14.0]\n", Frame),
        c("geometry.box.max", BOX, "[[geometry.box]]\nmin = [4.0, 4.0, 4.0]\nmax = [20.0, 12.0, 14.0]\n", Frame),
        c("geometry.box.max", BOX, "[[geometry.box]]\nmin = [4.0, 4.0, 4.0]\nmax = [16.0, 1.0, 14.0]\n", Refused),
        c("geometry.box.colour", BOX, "[[geometry.box]]\nmin = [4.0, 4.0, 4.0]\nmax = [16.0, 12.0, 14.0]\ncolour = [1.0, 0.0, 0.0]\n", Frame),
        c("geometry.box.colour", BOX, "[[geometry.box]]\nmin = [4.0, 4.0, 4.0]\nmax = [16.0, 12.0, 14.0]\ncolour = [1.5, 0.0, 0.0]\n", Refused),
        c("geometry.box.color", BOX, "[[geometry.box]]\nmin = [4.0, 4.0, 4.0]\nmax = [16.0, 12.0, 14.0]\ncolor = [1.0, 0.0, 0.0]\n", Frame),
        c("geometry.sphere", "", SPHERE, Frame),
        c("geometry.sphere.centre", SPHERE, "[[geometry.sphere]]\ncentre = [10.0, 14.0, 12.0]\nradius = 6.0\n", Frame),
        c("geometry.sphere.radius", SPHERE, "[[geometry.sphere]]\ncentre = [12.0, 12.0, 12.0]\nradius = 4.0\n", Frame),
        c("geometry.sphere.radius", SPHERE, "[[geometry.sphere]]\ncentre = [12.0, 12.0, 12.0]\nradius = 0.0\n", Refused),
        c("geometry.sphere.colour", SPHERE, "[[geometry.sphere]]\ncentre = [12.0, 12.0, 12.0]\nradius = 6.0\ncolour = [0.0, 1.0, 0.0]\n", Frame),
        c("geometry.sphere.color", SPHERE, "[[geometry.sphere]]\ncentre = [12.0, 12.0, 12.0]\nradius = 6.0\ncolor = [0.0, 1.0, 0.0]\n", Frame),
    ]
}

/// An opaque box cutting the 24^3 head (voxel coordinates), white.
const BOX: &str = "[[geometry.box]]\nmin = [4.0, 4.0, 4.0]\nmax = [16.0, 12.0, 14.0]\n";
/// An opaque sphere in the 24^3 head, white.
const SPHERE: &str = "[[geometry.sphere]]\ncentre = [12.0, 12.0, 12.0]\nradius = 6.0\n";

/// A GI scene (the GI-Cube processor model): the head, its default light, one sample per voxel.
const GI: &str = "[render]\nstep = 1.0\n[gi]\npasses = 2\n";
/// ... with photons.
const GI_PHOTONS: &str = "[render]\nstep = 1.0\n[gi]\nalbedo = 0.8\n";
/// ... in perspective.
const GI_PERSPECTIVE: &str =
    "[view]\nprojection = \"perspective\"\n[render]\nstep = 1.0\n[gi]\npasses = 2\n";

/// A perspective scene (the f64 reference renderer's only).
const PERSPECTIVE: &str = "[view]\nprojection = \"perspective\"\n[run]\nrenderer = \"reference\"\n";

/// A perspective scene on the what-if slab model.
const SLABS: &str = "[view]\nprojection = \"perspective\"\n[run]\nrenderer = \"slabs\"\n";

/// A wide perspective scene on the ER-perspective model (fov 120: the eye close enough for two
/// regions, so the merge acts).
const ER: &str = "[view]\nprojection = \"perspective\"\nfov = 120.0\n[run]\nrenderer = \"er\"\n";

/// The context of the `volume.*` file cases.
const RAW_FILE: &str = "[volume]\nfile = \"fields.raw\"\ndims = [20, 18, 16]\ntype = \"u16\"\n";

/// Field names of one table, from the parser's own list (`probe` is TOML whose `__probe` key is
/// unknown in that table).
fn field_names(probe: &str) -> Vec<String> {
    let e = Scene::parse(probe, "probe.toml")
        .expect_err(probe)
        .to_string();
    let list = e
        .split_once("expected ")
        .unwrap_or_else(|| panic!("no field list in `{e}`"))
        .1;
    list.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// Every leaf field of a scene, `table.field` (the points of a transfer function as
/// `transfer.points.density`, lights as `light.direction`).
fn every_field() -> BTreeSet<String> {
    let mut all = BTreeSet::new();
    for (table, probe) in [
        ("volume", "[volume]\n__probe = 1\n"),
        ("view", "[view]\n__probe = 1\n"),
        ("image", "[image]\n__probe = 1\n"),
        ("render", "[render]\n__probe = 1\n"),
        ("transfer", "[transfer]\n__probe = 1\n"),
        ("shading", "[shading]\n__probe = 1\n"),
        ("light", "[[light]]\ndirection = [0, 0, 1]\n__probe = 1\n"),
        ("quality", "[quality]\n__probe = 1\n"),
        ("run", "[run]\n__probe = 1\n"),
        ("gi", "[gi]\n__probe = 1\n"),
        ("geometry", "[geometry]\n__probe = 1\n"),
        (
            "geometry.box",
            "[[geometry.box]]\nmin = [0, 0, 0]\nmax = [1, 1, 1]\n__probe = 1\n",
        ),
        (
            "geometry.sphere",
            "[[geometry.sphere]]\ncentre = [0, 0, 0]\nradius = 1\n__probe = 1\n",
        ),
        (
            "transfer.points",
            "[transfer]\npoints = [{ density = 0.0, rgba = [0, 0, 0, 0], __probe = 1 }]\n",
        ),
    ] {
        for f in field_names(probe) {
            all.insert(format!("{table}.{f}"));
        }
    }
    // The tables themselves are the top level's fields; `light` is also a field (a list).
    for f in field_names("__probe = 1\n") {
        assert!(
            all.iter().any(|a| a.starts_with(&format!("{f}."))),
            "top-level field `{f}` has no table probe in every_field()"
        );
    }
    all.insert("light".into());
    all
}

/// What a scene's run computes, for comparison; `Err` is the refusal, with its message.
#[derive(Debug, PartialEq)]
struct Outcome {
    /// The frame's configuration and its base plane's coxels (bits).
    frame: String,
    image: Vec<u8>,
    run: String,
}

fn parse(text: &str, dir: &Path) -> Result<Scene, String> {
    let origin = dir.join("scene.toml");
    std::fs::write(&origin, text).unwrap();
    Scene::load(&origin).map_err(|e| e.to_string())
}

/// The run of a `[gi]` scene on the GI-Cube processor model (or its f64 reference), or the
/// refusal.
fn gi_outcome(scene: &Scene) -> Result<Outcome, String> {
    let e = |e: cube5_model::error::ModelError| e.to_string();
    let vol = scene.build_volume().map_err(e)?;
    let plan = Plan::new(scene, &vol).map_err(e)?;
    let mut job = GiJob::new(scene, &vol).map_err(e)?;
    let (counts, image) = match scene.run.renderer {
        Renderer::Pipeline => {
            let run = job.run().map_err(e)?;
            (run_counts_text(&run), run.image)
        }
        Renderer::Reference => (
            "f64 reference".to_string(),
            job.reference().map_err(e)?.ok_or("no f64 reference")?,
        ),
        Renderer::Slabs => return Err("run.renderer = \"slabs\" in a [gi] scene".into()),
        Renderer::Er => return Err("run.renderer = \"er\" in a [gi] scene".into()),
    };
    Ok(Outcome {
        frame: format!("{:?} {counts}", processor_config(scene).map_err(e)?),
        image: image.to_rgb8().into_raw(),
        run: format!("{:?} {:?}", plan.target, plan.renderer),
    })
}

/// The hardware run of `scene` (frame model, or the GI-Cube processor model for a `[gi]` scene),
/// or the refusal.
fn frame_outcome(scene: &Scene) -> Result<Outcome, String> {
    if scene.gi.is_some() {
        return gi_outcome(scene);
    }
    let why = not_expressible(scene);
    if !why.is_empty() {
        return Err(why.join("; "));
    }
    let vol = scene.build_volume().map_err(|e| e.to_string())?;
    let plan = Plan::new(scene, &vol).map_err(|e| e.to_string())?;
    let cfg = frame_config(scene).map_err(|e| e.to_string())?;
    let job = FrameJob::new(scene, &vol, cfg, 1).map_err(|e| e.to_string())?;
    let run = job.render();
    let img = job.image(scene, &run.base).map_err(|e| e.to_string())?;
    Ok(Outcome {
        frame: format!("{cfg:?} {:?}", run.base.coxels),
        image: img.to_rgb8().into_raw(),
        run: format!("{:?} {:?}", plan.target, plan.renderer),
    })
}

/// The image of a what-if model: the f64 reference, the slab perspective or ER-perspective.
fn what_if_image(scene: &Scene, shows: Shows) -> Result<ImageF64, String> {
    let vol = scene.build_volume().map_err(|e| e.to_string())?;
    let (tf, params) = (scene.transfer_function(), scene.render_params());
    match shows {
        Shows::Slabs { .. } => render_slabs(&vol, &tf, &params, scene.slabs()),
        Shows::Er { .. } => cube5_model::scene_render::frame_config(scene).and_then(|cfg| {
            cube5_model::er_perspective::render_er(&vol, &tf, &params, &cfg, scene.er())
                .map(|run| run.image)
        }),
        _ => render_reference(&vol, &tf, &params),
    }
    .map_err(|e| e.to_string())
}

/// `BASE`, then `extra`, then `more`, merged table by table (a later key wins, `key = ~` removes
/// it).
fn scene_text(extra: &str, more: &str) -> String {
    // TOML forbids a table twice: merge the three texts table by table.
    let mut tables: Vec<(String, Vec<String>)> = Vec::new();
    for text in [BASE, extra, more] {
        let mut current = String::new();
        let mut arrays_seen = BTreeSet::new();
        for line in text.lines() {
            if line.starts_with('[') {
                current = line.to_string();
                // A later text's `[[light]]` list replaces an earlier one.
                if line.starts_with("[[") && arrays_seen.insert(current.clone()) {
                    tables.retain(|(t, _)| *t != current);
                }
                if line.starts_with("[[") || !tables.iter().any(|(t, _)| *t == current) {
                    tables.push((current.clone(), Vec::new()));
                }
                continue;
            }
            let (key, value) = line.split_once('=').unwrap();
            let slot = &mut tables
                .iter_mut()
                .rev()
                .find(|(t, _)| *t == current)
                .unwrap()
                .1;
            slot.retain(|l| l.split('=').next().unwrap().trim() != key.trim());
            // `key = ~` removes the key.
            if value.trim() != "~" {
                slot.push(line.to_string());
            }
        }
    }
    tables
        .into_iter()
        .map(|(t, lines)| format!("{t}\n{}\n", lines.join("\n")))
        .collect()
}

#[test]
fn every_scene_field_changes_the_run_or_is_refused_by_name() {
    let dir = std::env::temp_dir().join(format!("cube5-scene-fields-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let n: usize = RAW_DIMS.iter().product();
    let raw: Vec<u8> = (0..n)
        .flat_map(|i| {
            let (x, y, z) = (i % 20, (i / 20) % 18, i / 360);
            let d = (x as i64 - 10).pow(2) + (y as i64 - 9).pow(2) + (z as i64 - 8).pow(2);
            ((4000 - 40 * d).clamp(0, 4095) as u16 + (i % 7) as u16).to_le_bytes()
        })
        .collect();
    std::fs::write(dir.join(RAW_NAME), raw).unwrap();

    let cases = cases();
    let covered: BTreeSet<String> = cases.iter().map(|c| c.field.to_string()).collect();
    let fields = every_field();
    let missing: Vec<_> = fields.difference(&covered).collect();
    assert!(
        missing.is_empty(),
        "scene fields with no case in tests/scene_fields.rs (say how each reaches the run): {missing:?}"
    );
    let unknown: Vec<_> = covered.difference(&fields).collect();
    assert!(
        unknown.is_empty(),
        "cases for fields the parser does not know: {unknown:?}"
    );

    let mut failures = Vec::new();
    for case in &cases {
        let before_text = scene_text(case.context, "");
        let after_text = scene_text(case.context, case.changed);
        let last = case.field.rsplit('.').next().unwrap();
        let names_it = |m: &str| m.contains(case.field) || m.contains(&format!("{last} ="));
        let before = parse(&before_text, &dir).unwrap_or_else(|e| panic!("{}: {e}", case.field));
        let after = parse(&after_text, &dir);
        let verdict = match case.shows {
            Shows::Refused => match after.map(|s| frame_outcome(&s)) {
                Err(m) | Ok(Err(m)) if names_it(&m) => Ok(()),
                Err(m) | Ok(Err(m)) => Err(format!("refused without naming it: {m}")),
                Ok(Ok(_)) => Err("accepted: the field is dropped without a word".to_string()),
            },
            Shows::Frame | Shows::Run | Shows::Processor => {
                let after = after.map_err(|e| e.to_string());
                match (
                    frame_outcome(&before),
                    after.and_then(|s| frame_outcome(&s)),
                ) {
                    (Ok(b), Ok(a)) => {
                        let changed = if case.shows == Shows::Run {
                            a.run != b.run
                        } else {
                            a.frame != b.frame || a.image != b.image
                        };
                        if changed {
                            Ok(())
                        } else {
                            Err("the run computes the same bits: the field was dropped".into())
                        }
                    }
                    (Err(m), _) => Err(format!("context refused: {m}")),
                    (_, Err(m)) if names_it(&m) => Ok(()),
                    (_, Err(m)) => Err(format!("refused without naming it: {m}")),
                }
            }
            Shows::Reference { because } | Shows::Slabs { because } | Shows::Er { because } => {
                let after = after.unwrap_or_else(|e| panic!("{}: {e}", case.field));
                let refused_by = frame_outcome(&after).err().unwrap_or_default();
                let a = what_if_image(&after, case.shows);
                let b = what_if_image(&before, case.shows);
                match (a, b) {
                    (Ok(a), Ok(b)) if a.to_rgb8() == b.to_rgb8() => {
                        Err("the what-if model renders the same image".into())
                    }
                    (Ok(_), Ok(_)) if !because.is_empty() && !refused_by.contains(because) => {
                        Err(format!(
                            "the frame does not refuse the scene by `{because}`: {refused_by:?}"
                        ))
                    }
                    (Ok(_), Ok(_)) => Ok(()),
                    (a, b) => Err(format!("what-if model failed: {:?} {:?}", a.err(), b.err())),
                }
            }
        };
        if let Err(why) = verdict {
            failures.push(format!("{}: {why}", case.field));
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
