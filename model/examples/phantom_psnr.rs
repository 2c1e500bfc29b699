//! PSNR of the default scene's frame model (bit-exact base plane + warp) and of the pipeline
//! model against the f64 reference, over volume edges and image sizes (issue 13).
//!
//! ```text
//! cargo run --release -p cube5-model --example phantom_psnr -- [--sizes 96,128] [--images 384]
//!     [--tf PRESET] [--what frame,pipeline,ss2,spp4,precise,g6,g26,refstep]
//!     [--azimuth DEG] [--unlit] [--no-specular] [--rm-log2 N] [--gen-only] [--png DIR] [--scene FILE]
//! ```
//!
//! `frame` is what the hardware makes; the `pipeline` rows are `render_pipeline`'s what-if knobs
//! (default quality; `ss2` 2x2 base-plane supersampling; `spp4` four samples per slice; `precise`
//! the widest widths; `g26` the 26-neighbourhood gradient); `refstep` is the f64 reference itself
//! at one sample per slice (step = the slice spacing along the ray), which isolates the error of
//! sampling the classified signal once per slice.

use cube5_model::camera::Camera;
use cube5_model::render::image_error;
use cube5_model::render::{
    render_pipeline, render_reference, GradientScheme, ImageF64, Quality, RenderParams, SliceSetup,
};
use cube5_model::scene::Scene;
use cube5_model::transfer::TransferFunction;
use cube5_model::units::cube5_frame::{
    frame_phong, render_base_plane, warp, FrameMode, FrameSetup, FrameUnits,
};
use cube5_model::units::cube5_shader::{
    ClassLut, Phong, ReflectanceMap, Shader, ShaderConfig, ShaderTables,
};
use cube5_model::volume::Volume;
use std::path::PathBuf;
use std::time::Instant;

fn list(s: &str) -> Vec<usize> {
    s.split(',')
        .map(|v| v.trim().parse().expect("a number"))
        .collect()
}

// ---- main's head phantom, for comparison

/// The frame model's image of `vol` at `params`: base plane (bit-exact) warped onto the image.
fn frame_image(
    vol: &Volume,
    tf: &TransferFunction,
    params: &RenderParams,
    rm_log2: Option<u32>,
) -> (ImageF64, f64) {
    let t = Instant::now();
    let dir = params.direction().unwrap();
    let setup = FrameSetup::new(vol.dims, vol.spacing, dir, 4).unwrap();
    let m = params.material;
    // Unlit (shading off): the reflectance map is 1 everywhere, as `cube5 cosim` sets it.
    let (ambient, diffuse, specular) = if params.shading {
        (m.ambient, m.diffuse, m.specular)
    } else {
        (1.0, 0.0, 0.0)
    };
    let phong = Phong {
        ambient,
        diffuse,
        specular,
        shininess: m.shininess,
        ..frame_phong(&setup.params, &[])
    };
    let mut units = FrameUnits::new(FrameMode::Composite, &setup, tf, &phong).unwrap();
    if let Some(r) = rm_log2 {
        // What-if: a finer reflectance map (`RmLog2`), the rest at the defaults.
        let cfg = ShaderConfig {
            rm_log2: r,
            ..ShaderConfig::DEFAULT
        };
        let tables = ShaderTables {
            class: ClassLut::from_transfer(&cfg, tf).unwrap(),
            rmap: ReflectanceMap::from_lights(&cfg, &phong).unwrap(),
        };
        units.shader = Shader::new(cfg, tables).unwrap();
    }
    let bp = render_base_plane(&setup.params, vol, &units);
    let cam = Camera::new(dir, vol.dims, vol.spacing, params.width, params.height);
    let img = warp(
        &setup.params,
        vol.spacing,
        &bp.rgb(&units.compos.config()),
        (bp.width, bp.height),
        &cam,
    );
    (img, t.elapsed().as_secs_f64())
}

/// The three central slices side by side (axial from above, coronal and sagittal with z up),
/// grey levels from the densities.
fn slices(vol: &Volume) -> image::GrayImage {
    let n = vol.dims[0];
    let max = f64::from(vol.max_value());
    let mut img = image::GrayImage::new(3 * n as u32, n as u32);
    let c = (n / 2) as i64;
    for a in 0..n {
        for b in 0..n {
            let (a, b) = (a as i64, b as i64);
            let up = n as i64 - 1 - b;
            let vals = [vol.get(a, up, c), vol.get(a, c, up), vol.get(c, a, up)];
            for (k, v) in vals.iter().enumerate() {
                let g = (f64::from(*v) / max * 255.0).round() as u8;
                img.put_pixel((k * n) as u32 + a as u32, b as u32, image::Luma([g]));
            }
        }
    }
    img
}

/// `--scene FILE`: renders a scene file as `cube5 render` does (the pipeline model, or the
/// reference where the scene asks for it) into the `--png` directory (given before it).
fn render_scene(file: &str, png: Option<&std::path::Path>) {
    let scene = Scene::load(std::path::Path::new(file)).unwrap();
    let vol = scene.build_volume().unwrap();
    let (tf, params) = (scene.transfer_function(), scene.render_params());
    let img = match scene.run.renderer {
        cube5_model::scene::Renderer::Reference => render_reference(&vol, &tf, &params).unwrap(),
        cube5_model::scene::Renderer::Slabs => {
            cube5_model::slab_perspective::render_slabs(&vol, &tf, &params, scene.slabs()).unwrap()
        }
        cube5_model::scene::Renderer::Er => {
            cube5_model::er_perspective::render_er(
                &vol,
                &tf,
                &params,
                &cube5_model::scene_render::frame_config(&scene).unwrap(),
                scene.er(),
            )
            .unwrap()
            .image
        }
        cube5_model::scene::Renderer::Pipeline => {
            render_pipeline(&vol, &tf, &params, &scene.quality())
                .unwrap()
                .image
        }
    };
    let stem = std::path::Path::new(file)
        .file_stem()
        .unwrap()
        .to_string_lossy();
    let dir = png.unwrap_or(std::path::Path::new("."));
    std::fs::create_dir_all(dir).unwrap();
    img.to_rgb8()
        .save(dir.join(format!("scene-{stem}.png")))
        .unwrap();
}

fn main() {
    let mut sizes = vec![96];
    let mut images = vec![384];
    let mut tf_name = String::from("head");
    let mut what = vec!["frame".to_string(), "pipeline".to_string()];
    let mut png: Option<PathBuf> = None;
    let mut azimuth: Option<f64> = None;
    let mut gen_only = false;
    let mut unlit = false;
    let mut no_specular = false;
    let mut rm_log2: Option<u32> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut val = || args.next().expect("a value");
        match a.as_str() {
            "--sizes" => sizes = list(&val()),
            "--images" => images = list(&val()),
            "--tf" => tf_name = val(),
            "--what" => what = val().split(',').map(str::to_string).collect(),
            "--png" => png = Some(PathBuf::from(val())),
            "--scene" => {
                render_scene(&val(), png.as_deref());
                return;
            }
            "--gen-only" => gen_only = true,
            "--unlit" => unlit = true,
            "--no-specular" => no_specular = true,
            "--rm-log2" => rm_log2 = Some(val().parse().unwrap()),
            "--azimuth" => azimuth = Some(val().parse().unwrap()),
            other => panic!("unknown argument {other}"),
        }
    }
    let tf = TransferFunction::preset(&tf_name).unwrap();
    let scene = Scene::default();
    println!(
        "| phantom+TF | edge | image | model | PSNR (dB) | rel. Eucl. (%) | max abs | time (s) |"
    );
    println!("|---|---:|---:|---|---:|---:|---:|---:|");
    for &n in &sizes {
        let mut s = scene.clone();
        s.volume.size = n;
        let t = Instant::now();
        let vol = s.build_volume().unwrap();
        let gen = t.elapsed().as_secs_f64();
        eprintln!("phantom {n}^3 built in {gen:.2} s");
        if let Some(dir) = &png {
            std::fs::create_dir_all(dir).unwrap();
            slices(&vol)
                .save(dir.join(format!("slices-{n}.png")))
                .unwrap();
        }
        if gen_only {
            continue;
        }
        for &px in &images {
            let mut params = s.render_params();
            params.shading = !unlit;
            if no_specular {
                params.material.specular = 0.0;
            }
            if let Some(a) = azimuth {
                params.view.azimuth = a;
            }
            params.width = px as u32;
            params.height = px as u32;
            let t = Instant::now();
            let reference = render_reference(&vol, &tf, &params).unwrap();
            let tref = t.elapsed().as_secs_f64();
            let row = |name: &str, img: &ImageF64, secs: f64| {
                let e = image_error(img, &reference);
                println!(
                    "| {tf_name} | {n} | {px} | {name} | {:.1} | {:.2} | {:.3} | {secs:.2} |",
                    e.psnr_db, e.rel_euclid, e.max_abs
                );
            };
            row("reference (step 0.25)", &reference, tref);
            if let Some(dir) = &png {
                std::fs::create_dir_all(dir).unwrap();
                reference
                    .to_rgb8()
                    .save(dir.join(format!("{tf_name}-{n}-{px}-reference.png")))
                    .unwrap();
            }
            for w in &what {
                let t = Instant::now();
                let img = match w.as_str() {
                    "frame" => {
                        let (img, secs) = frame_image(&vol, &tf, &params, rm_log2);
                        row("frame (bit-exact) + warp", &img, secs);
                        if let Some(dir) = &png {
                            let diff = ImageF64 {
                                rgb: img
                                    .rgb
                                    .iter()
                                    .zip(&reference.rgb)
                                    .map(|(a, b)| {
                                        std::array::from_fn(|c| 4.0 * (a[c] - b[c]).abs())
                                    })
                                    .collect(),
                                ..img.clone()
                            };
                            diff.to_rgb8()
                                .save(dir.join(format!("{tf_name}-{n}-{px}-diff4.png")))
                                .unwrap();
                            img.to_rgb8()
                                .save(dir.join(format!("{tf_name}-{n}-{px}-frame.png")))
                                .unwrap();
                        }
                        continue;
                    }
                    "refstep" => {
                        let setup = SliceSetup::new(&vol, params.direction().unwrap()).unwrap();
                        let p = RenderParams {
                            step: setup.ratio,
                            ..params.clone()
                        };
                        render_reference(&vol, &tf, &p).unwrap()
                    }
                    "ss2" | "spp4" | "precise" | "g26" | "pipeline" | "g6" => {
                        let q = match w.as_str() {
                            "ss2" => Quality {
                                supersampling: 2,
                                ..Quality::default()
                            },
                            "spp4" => Quality {
                                samples_per_slice: 4,
                                ..Quality::default()
                            },
                            "precise" => Quality::precise(),
                            "g26" => Quality {
                                gradient: GradientScheme::TwentySix,
                                ..Quality::default()
                            },
                            "g6" => Quality {
                                gradient: GradientScheme::Six,
                                ..Quality::default()
                            },
                            _ => Quality::default(),
                        };
                        let mut p = params.clone();
                        p.supersampling = 1;
                        render_pipeline(&vol, &tf, &p, &q).unwrap().image
                    }
                    other => panic!("unknown model {other}"),
                };
                row(w, &img, t.elapsed().as_secs_f64());
            }
        }
    }
}
