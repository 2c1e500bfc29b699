//! PSNR of the default scene's frame model (bit-exact base plane + warp) and of the pipeline
//! model against the f64 reference, over volume edges and image sizes (issue 13).
//!
//! ```text
//! cargo run --release -p cube5-model --example phantom_psnr -- [--sizes 96,128] [--images 384]
//!     [--tf head|proposed|PRESET] [--what frame,pipeline,ss2,spp4,precise,g6,g26,refstep]
//!     [--azimuth DEG] [--unlit] [--no-specular] [--rm-log2 N] [--old] [--gen-only] [--png DIR] [--scene FILE]
//! ```
//!
//! `frame` is what the hardware makes; the `pipeline` rows are `render_pipeline`'s what-if knobs
//! (default quality; `ss2` 2x2 base-plane supersampling; `spp4` four samples per slice; `precise`
//! the widest widths; `g26` the 26-neighbourhood gradient); `refstep` is the f64 reference itself
//! at one sample per slice (step = the slice spacing along the ray), which isolates the error of
//! sampling the classified signal once per slice.

use cube5_model::camera::Camera;
use cube5_model::render::{
    render_pipeline, render_reference, GradientScheme, ImageF64, Quality, RenderParams, SliceSetup,
};
use cube5_model::scene::Scene;
use cube5_model::studies::tradeoff::image_error;
use cube5_model::transfer::TransferFunction;
use cube5_model::units::cube5_frame::{
    frame_phong, render_base_plane, warp, FrameMode, FrameSetup, FrameUnits,
};
use cube5_model::units::cube5_shader::{
    ClassLut, Phong, ReflectanceMap, Shader, ShaderConfig, ShaderTables,
};
use cube5_model::volume::Volume;
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

fn list(s: &str) -> Vec<usize> {
    s.split(',')
        .map(|v| v.trim().parse().expect("a number"))
        .collect()
}

// ---- main's head phantom, for comparison

/// One ellipsoid of constant density in normalized coordinates ([-1, 1] across the volume).
struct Blob {
    centre: [f64; 3],
    radii: [f64; 3],
    density: f64,
}

impl Blob {
    fn inside(&self, p: [f64; 3]) -> bool {
        (0..3)
            .map(|a| ((p[a] - self.centre[a]) / self.radii[a]).powi(2))
            .sum::<f64>()
            <= 1.0
    }
}

/// A CT-like head: skin, skull shell, brain, two ventricles and lesions of different densities.
/// Later blobs overwrite earlier ones, so the list reads from the outside in.
fn head_blobs() -> Vec<Blob> {
    let b = |centre, radii, density| Blob {
        centre,
        radii,
        density,
    };
    vec![
        b([0.0, 0.0, 0.0], [0.80, 0.90, 0.95], 0.22), // skin and scalp
        b([0.0, 0.0, 0.0], [0.76, 0.86, 0.91], 0.86), // skull
        b([0.0, 0.0, 0.02], [0.69, 0.79, 0.84], 0.36), // brain
        b([-0.3, -0.8, -0.25], [0.16, 0.16, 0.14], 0.0), // left eye orbit
        b([0.3, -0.8, -0.25], [0.16, 0.16, 0.14], 0.0), // right eye orbit
        b([-0.16, 0.05, 0.1], [0.08, 0.28, 0.12], 0.12), // left ventricle
        b([0.16, 0.05, 0.1], [0.08, 0.28, 0.12], 0.12), // right ventricle
        b([0.32, -0.25, 0.28], [0.15, 0.15, 0.15], 0.50), // lesion
        b([-0.35, -0.2, -0.15], [0.12, 0.12, 0.12], 0.61), // lesion
        b([0.05, 0.42, -0.35], [0.11, 0.11, 0.11], 0.75), // calcification
        b([0.0, -0.5, 0.45], [0.05, 0.05, 0.05], 1.00), // metal marker
    ]
}

/// main's head phantom (before issue 13), `n^3` voxels of `bits` bits, edges anti-aliased by 2x2x2 supersampling.
fn old_head_phantom(n: usize, bits: u32) -> Volume {
    let blobs = head_blobs();
    supersampled(n, bits, |p| {
        blobs
            .iter()
            .rev()
            .find(|b| b.inside(p))
            .map_or(0.0, |b| b.density)
    })
}

/// An `n^3` volume of `bits` bits whose voxels are the density `f` (0..=1, at points of the
/// normalized cube -1..1) averaged over 2x2x2 samples at +-1/4 voxel: anti-aliased edges.
fn supersampled(n: usize, bits: u32, f: impl Fn([f64; 3]) -> f64 + Sync) -> Volume {
    let max = f64::from((1u32 << bits) - 1);
    let to_norm = |i: f64| (i + 0.5) / n as f64 * 2.0 - 1.0;
    let data: Vec<u16> = (0..n * n * n)
        .into_par_iter()
        .map(|idx| {
            let (x, y, z) = (idx % n, (idx / n) % n, idx / (n * n));
            let mut acc = 0.0;
            for s in 0..8 {
                let off = |bit: usize| if (s >> bit) & 1 == 1 { 0.25 } else { -0.25 };
                let p = [
                    to_norm(x as f64 + off(0)),
                    to_norm(y as f64 + off(1)),
                    to_norm(z as f64 + off(2)),
                ];
                acc += f(p) / 8.0;
            }
            (acc * max).round() as u16
        })
        .collect();
    Volume::new([n; 3], [1.0; 3], bits, data).unwrap()
}

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

/// The head transfer function of main (`TransferFunction::head_default`, this study's proposal).
fn proposed_tf() -> TransferFunction {
    TransferFunction::head_default()
}

/// `--scene FILE`: renders a scene file as `cube5 render` does (the pipeline model, or the
/// reference where the scene asks for it) into the `--png` directory (given before it).
fn render_scene(file: &str, png: Option<&std::path::Path>) {
    let scene = Scene::load(std::path::Path::new(file)).unwrap();
    let vol = scene.build_volume().unwrap();
    let (tf, params) = (scene.transfer_function(), scene.render_params());
    let img = match scene.run.renderer {
        cube5_model::scene::Renderer::Reference => render_reference(&vol, &tf, &params).unwrap(),
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
    let mut old = false;
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
            "--old" => old = true,
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
    let tf = if tf_name == "proposed" {
        proposed_tf()
    } else {
        TransferFunction::preset(&tf_name).unwrap()
    };
    let scene = Scene::default();
    let tag = if old { "old-" } else { "" };
    println!(
        "| phantom+TF | edge | image | model | PSNR (dB) | rel. Eucl. (%) | max abs | time (s) |"
    );
    println!("|---|---:|---:|---|---:|---:|---:|---:|");
    for &n in &sizes {
        let mut s = scene.clone();
        s.volume.size = n;
        let t = Instant::now();
        let vol = if old {
            old_head_phantom(n, 12)
        } else {
            s.build_volume().unwrap()
        };
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
                    "| {tag}{tf_name} | {n} | {px} | {name} | {:.1} | {:.2} | {:.3} | {secs:.2} |",
                    e.psnr_db, e.rel_euclid, e.max_abs
                );
            };
            row("reference (step 0.25)", &reference, tref);
            if let Some(dir) = &png {
                std::fs::create_dir_all(dir).unwrap();
                reference
                    .to_rgb8()
                    .save(dir.join(format!("{tag}{tf_name}-{n}-{px}-reference.png")))
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
                                .save(dir.join(format!("{tag}{tf_name}-{n}-{px}-diff4.png")))
                                .unwrap();
                            img.to_rgb8()
                                .save(dir.join(format!("{tag}{tf_name}-{n}-{px}-frame.png")))
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
