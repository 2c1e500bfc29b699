//! `cube5 tradeoff [SCENE]`: runs the sweeps of `cube5_studies::tradeoff` with progress bars and
//! writes the tables (Markdown and CSV) and plots (PNG). `--write-docs` regenerates
//! `docs/tradeoffs.md` and `docs/img/tradeoff-*`.
//!
//! The plots are drawn with `plotters` into an RGB buffer (grid, axes, curves, markers) and their
//! text with `ab_glyph` in DejaVu Sans, embedded in the binary (`cli/assets/fonts/`, with its
//! licence), so no system fonts are needed (CI machines have none; plotters' default font-kit text
//! looks them up). The text is not plotters' own: its `ab_glyph` feature drops each glyph's left
//! side bearing and rounds the pen to whole pixels, so at 15 px the gap between neighbouring letters
//! is off by 0.5 px on average and up to 2 px ("im age"); `draw_text` places glyphs exactly.

use ab_glyph::{point, Font, FontRef, ScaleFont};
use anyhow::{bail, Context, Result};
use cube5_model::render::{Quality, RenderParams};
use cube5_model::scene::Scene;
use cube5_model::transfer::TransferFunction;
use cube5_model::volume_io::write_atomically;
use cube5_studies::tradeoff::{
    run as run_sweeps, Figure, Progress, Report, Series, Setup, Synth, Table, PAPER_VS_IMAGE_ORDER,
    PAPER_VS_TRUE3D,
};
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::RgbImage;
use indicatif::{ProgressBar, ProgressStyle};
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct TradeoffArgs {
    /// Scene whose volume, transfer function, view and quality are the baseline (default: the
    /// embedded head phantom at 64^3).
    scene: Option<PathBuf>,
    /// Directory for the Markdown, CSV and PNG results.
    #[arg(long, default_value = "target/tradeoff")]
    out: PathBuf,
    /// Write docs/tradeoffs.md and docs/img/tradeoff-* instead of --out.
    #[arg(long)]
    write_docs: bool,
    /// A tiny sweep (seconds): a few settings per knob, three angles, small images.
    #[arg(long)]
    tiny: bool,
    /// Phantom edge in voxels (default 64; a scene file's own size when a scene is given).
    #[arg(long)]
    size: Option<usize>,
    /// Image edge in pixels.
    #[arg(long, default_value_t = 128)]
    image: u32,
}

/// The repository root (for `docs/`, `rtl/` and `target/synth/`).
fn repo_root() -> PathBuf {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    here.parent().unwrap_or(here).to_path_buf()
}

/// Progress bars on stderr (hidden when stderr is not a terminal).
struct Bars {
    bar: Mutex<Option<ProgressBar>>,
}

impl Progress for Bars {
    fn start(&self, name: &str, total: u64) {
        let bar = ProgressBar::new(total);
        bar.set_style(
            ProgressStyle::with_template("{msg:>28} [{bar:30}] {pos}/{len} {elapsed}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar.set_message(name.to_string());
        *self.bar.lock().expect("progress lock") = Some(bar);
    }
    fn tick(&self) {
        if let Some(b) = self.bar.lock().expect("progress lock").as_ref() {
            b.inc(1);
        }
    }
    fn finish(&self) {
        if let Some(b) = self.bar.lock().expect("progress lock").take() {
            b.finish();
        }
    }
}

/// Reads target/synth/area.md (and the per-configuration Yosys logs beside it for tops area.md
/// lacks) joined with every rtl/**/*.variants, if the synthesis has been run.
fn load_synth(root: &Path) -> Option<Synth> {
    let synth_dir = root.join("target/synth");
    let area = std::fs::read_to_string(synth_dir.join("area.md")).ok()?;
    let mut variants = Vec::new();
    for dir in ["rtl/cube5", "rtl/gicube"] {
        let Ok(entries) = std::fs::read_dir(root.join(dir)) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.extension().and_then(|x| x.to_str()) == Some("variants") {
                if let (Some(stem), Ok(text)) = (
                    p.file_stem().map(|s| s.to_string_lossy().to_string()),
                    std::fs::read_to_string(&p),
                ) {
                    variants.push((stem, text));
                }
            }
        }
    }
    let mut synth = Synth::parse(&area, &variants);
    let read = |name: &str| std::fs::read_to_string(synth_dir.join(name)).ok();
    synth.add_from_logs(&variants, read);
    synth.fmax_from_logs(read);
    Some(synth)
}

pub fn run(args: TradeoffArgs) -> Result<()> {
    if !(8..=1024).contains(&args.image) {
        bail!("--image {}: must be 8..=1024", args.image);
    }
    let mut scene = match &args.scene {
        Some(p) => Scene::load(p)?,
        None => Scene {
            volume: cube5_model::scene::VolumeSpec {
                size: 64,
                ..Default::default()
            },
            ..Default::default()
        },
    };
    if let Some(s) = args.size {
        scene.volume.size = s;
    }
    if args.tiny && args.size.is_none() && scene.volume.file.is_none() {
        scene.volume.size = 20;
    }
    let image = if args.tiny {
        args.image.min(24)
    } else {
        args.image
    };
    scene.image.width = image;
    scene.image.height = image;
    scene.validate("command line")?;
    let root = repo_root();
    let (out_dir, img_dir) = if args.write_docs {
        (root.join("docs"), root.join("docs/img"))
    } else {
        (args.out.clone(), args.out.clone())
    };
    for d in [&out_dir, &img_dir] {
        std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
    }
    let vol = scene.build_volume()?;
    let tf: TransferFunction = scene.transfer_function();
    let params: RenderParams = scene.render_params();
    let quality: Quality = scene.quality();
    let mut setup = if args.tiny {
        Setup::tiny(vol, tf, params, quality)
    } else {
        Setup::new(vol, tf, params, quality)
    };
    setup.synth = load_synth(&root);
    let started = Instant::now();
    let bars = Bars {
        bar: Mutex::new(None),
    };
    let report = run_sweeps(&setup, &bars)?;
    #[cfg(feature = "rtl")]
    let frame_md = {
        say!("cube5 tradeoff: cycles per frame on the RTL frame (P = 1, 4, 8)");
        crate::cosim::frame_cost_section(&scene)?
    };
    #[cfg(not(feature = "rtl"))]
    let frame_md = String::from(
        "## Cycles per frame (`cube5_frame`, RTL)\n\nThis cube5 was built without the RTL \
         (cargo feature `rtl`): no cycles measured.\n\n",
    );
    let secs = started.elapsed().as_secs_f64();

    // Everything is computed: now write, each file atomically.
    let mut written = Vec::new();
    for t in &report.tables {
        let p = img_dir.join(format!("{}.csv", t.name));
        write_atomically(&p, t.to_csv().as_bytes())?;
        written.push(p);
    }
    for f in &report.figures {
        let p = img_dir.join(format!("{}.png", f.name));
        let png = draw(f);
        let mut bytes = Vec::new();
        // `write_to` compresses fast; the default level makes the anti-aliased plots half as
        // large (100 -> 54 KB) for about 30 ms a plot.
        png.write_with_encoder(PngEncoder::new_with_quality(
            &mut bytes,
            CompressionType::Default,
            FilterType::Adaptive,
        ))
        .context("encoding a plot")?;
        write_atomically(&p, &bytes)?;
        written.push(p);
    }
    let md_name = if args.write_docs {
        "tradeoffs.md"
    } else {
        "tradeoff.md"
    };
    let md_path = out_dir.join(md_name);
    let img_rel = if args.write_docs { "img/" } else { "" };
    let mut md = document(&setup, &scene, &report, secs, img_rel, args.tiny);
    md.push_str(&frame_md);
    write_atomically(&md_path, md.as_bytes())?;
    written.push(md_path.clone());
    say!(
        "cube5 tradeoff: {} tables, {} plots in {secs:.1} s",
        report.tables.len(),
        report.figures.len()
    );
    let p = report.paper_61;
    say!(
        "cube3-paper 6.1: sheared vs image order peaks at {:.3}% ({} deg; paper < {PAPER_VS_IMAGE_ORDER}%), sheared vs True3D at most {:.3}% (paper < {PAPER_VS_TRUE3D}%); smoothed volume: {:.3}% ({} deg) and {:.3}%",
        p[0], p[2], p[1], p[3], p[5], p[4]
    );
    say!(
        "cube3-paper 6.1 with the mean distance over full scale: {:.3}% and {:.3}%",
        report.paper_61_full_scale[0],
        report.paper_61_full_scale[1]
    );
    let g = report.paper_62;
    say!(
        "cube3-paper 6.2: mean angular error at 0/45 deg: 6-nbhd {:.2}/{:.2}, 10-nbhd {:.2}/{:.2}, 26-nbhd {:.2}/{:.2}",
        g[0][0], g[0][1], g[1][0], g[1][1], g[2][0], g[2][1]
    );
    say!("wrote {}", md_path.display());
    Ok(())
}

/// The Markdown report (docs/tradeoffs.md with `--write-docs`).
fn document(
    setup: &Setup,
    scene: &Scene,
    report: &Report,
    secs: f64,
    img: &str,
    tiny: bool,
) -> String {
    let v = &setup.volume;
    let q = &setup.quality;
    let p = &setup.params;
    let table = |name: &str| -> &Table {
        report
            .tables
            .iter()
            .find(|t| t.name == name)
            .expect("every sweep makes its table")
    };
    let mut s = String::new();
    let w = |s: &mut String, t: &str| {
        s.push_str(t);
        s.push('\n');
    };
    // A sweep's table, then its figure (`{img}<table name>.png`), each followed by a blank line.
    let table_and_figure = |s: &mut String, name: &str, alt: &str| {
        s.push_str(&table(name).to_markdown());
        w(s, "");
        w(s, &format!("![{alt}]({img}{name}.png)"));
        w(s, "");
    };
    w(&mut s, "# Speed against accuracy, measured");
    w(&mut s, "");
    w(
        &mut s,
        &format!(
            "Generated by `cube5 tradeoff{}` in {secs:.0} s on this machine (2 cores): do not edit by \
             hand. Every table is also a CSV file beside its plot.",
            if tiny { " --tiny" } else { " --write-docs" }
        ),
    );
    w(&mut s, "");
    w(&mut s, "## Set-up");
    w(&mut s, "");
    w(
        &mut s,
        &format!(
            "- Volume: {} ({} x {} x {} voxels of {} bits); transfer function: {}; view azimuth {} \
             elevation {}; {} x {} pixels; mode {}; shading {}.",
            match (&scene.volume.file, &scene.volume.phantom) {
                (Some(f), _) => format!("`{}`", f.display()),
                (None, Some(ph)) => format!("the `{ph}` phantom"),
                (None, None) => "the `head` phantom".into(),
            },
            v.dims[0],
            v.dims[1],
            v.dims[2],
            v.bits,
            match &scene.transfer {
                Some(t) => t
                    .preset
                    .clone()
                    .map_or("explicit points".into(), |p| format!("preset `{p}`")),
                None => "the scene's default".into(),
            },
            p.view.azimuth,
            p.view.elevation,
            p.width,
            p.height,
            p.mode.name(),
            if p.shading { "on" } else { "off" }
        ),
    );
    w(
        &mut s,
        &format!(
            "- Reference: the f64 image-order ray caster (`render_reference`): rays through pixel \
             centres, step {} voxel, exact tri-linear samples, central-difference gradients, no \
             early termination.",
            p.step
        ),
    );
    w(
        &mut s,
        &format!(
            "- Pipeline model (`render_pipeline`), baseline quality: {}-bit voxels, {}-bit weights, \
             U(.{}) samples, {}-bit colour, {}-bit alpha, {}-bit accumulators, {} sample(s) per slice, \
             {} interpolation, {}-neighbourhood gradient, no early termination. Samples come from \
             the bit-accurate `cube5_trilin` model and gradients from `cube5_gradient`; \
             classification, shading and compositing are f64 rounded to the widths; the base-plane \
             image is warped bilinearly onto the image.",
            q.voxel_width(v.bits),
            q.weight_bits,
            q.frac_bits,
            q.colour_bits,
            q.alpha_bits,
            q.acc_bits,
            q.samples_per_slice,
            q.interpolation.name(),
            u32::from(q.gradient)
        ),
    );
    w(
        &mut s,
        "- Errors: PSNR over R, G, B in 0..1; the largest channel difference in 1/255; and \
         cube3-paper §6.1's relative Euclidean RGB error, the per-pixel Euclidean RGB distance \
         summed over the image and divided by the reference's summed RGB length (the paper does \
         not print its normalisation; this one makes the background count for nothing).",
    );
    w(
        &mut s,
        "- Cost: samples that reach the compositor (inside the volume, before early termination). \
         Every frame of the slice-order sweep also visits each base-plane anchor of every slice.",
    );
    w(
        &mut s,
        &format!(
            "- Area: {}",
            if report.synth_found {
                "generic Yosys cells from `target/synth/area.md` (`make synth`), where a verified \
                 configuration (`rtl/**/*.variants`) has exactly the knob's widths."
            } else {
                "`target/synth/area.md` was not found: run `make synth` and regenerate."
            }
        ),
    );
    w(&mut s, "");
    w(&mut s, "Regenerate: `cargo run --release -p cube5-cli -- tradeoff --write-docs` (the lead's `make tradeoff`).");
    w(&mut s, "");

    w(&mut s, "## Bit widths");
    w(&mut s, "");
    w(
        &mut s,
        "One knob at a time, the others at the baseline. The cells column lists the units whose \
         synthesized configuration has exactly this row's widths (a unit absent from it has no such \
         configuration yet). `PSNR vs precise pipeline` compares with \
         the same pipeline at the widest widths the units allow (16-bit voxels, 12-bit weights, \
         8 fraction bits, 16-bit colour and alpha): it isolates the knob from the pipeline's \
         sampling and warp, which the columns against the reference include.",
    );
    w(&mut s, "");
    table_and_figure(&mut s, "tradeoff-widths", "widths");
    w(&mut s, "### Verified configurations");
    w(&mut s, "");
    s.push_str(&table("tradeoff-configs").to_markdown());
    w(&mut s, "");

    w(&mut s, "## Sample rate and early termination");
    w(&mut s, "");
    s.push_str(&table("tradeoff-sample-rate").to_markdown());
    w(&mut s, "");
    s.push_str(&table("tradeoff-early-termination").to_markdown());
    w(&mut s, "");
    w(&mut s, &format!("![samples]({img}tradeoff-samples.png)"));
    w(&mut s, "");

    let [peak, max_st, peak_at, s_peak, s_max_st, s_peak_at] = report.paper_61;
    w(
        &mut s,
        "## cube3-paper §6.1: sheared tri-linear interpolation",
    );
    w(&mut s, "");
    w(
        &mut s,
        &format!(
            "The paper's experiment on our data: the volume above with the paper's bone transfer \
             function (`cube3-bone`: alpha 0 below 80/255, a ramp to 0.75 at 100/255), tilted 70 \
             degrees (elevation {}), rotated about the vertical axis from 0 to 90 degrees in \
             5-degree steps, shaded, composited. The image-order reference plays VolRen (step {}); \
             `trilinear` is True3D (the pipeline's sample positions, exact 8-neighbourhood); \
             `sheared` is Sheared3D; all three pipeline schemes at precise widths with the \
             10-neighbourhood gradient, as in the paper.",
            setup.paper_elevation, setup.paper_step
        ),
    );
    w(&mut s, "");
    w(&mut s, "| figure | paper | cube5 |");
    w(&mut s, "|---|---:|---:|");
    w(
        &mut s,
        &format!(
            "| sheared vs image order, largest over the angles | < {PAPER_VS_IMAGE_ORDER}% | {peak:.3}% (at {peak_at} deg) |"
        ),
    );
    w(
        &mut s,
        &format!("| sheared vs exact neighbourhood (True3D), largest | < {PAPER_VS_TRUE3D}% | {max_st:.3}% |"),
    );
    let [fs_io, fs_st] = report.paper_61_full_scale;
    w(
        &mut s,
        &format!(
            "| the same two, mean distance over the full scale sqrt 3 | < {PAPER_VS_IMAGE_ORDER}% / < {PAPER_VS_TRUE3D}% | {fs_io:.3}% / {fs_st:.3}% |"
        ),
    );
    w(
        &mut s,
        &format!(
            "| the same two on the smoothed volume | < {PAPER_VS_IMAGE_ORDER}% / < {PAPER_VS_TRUE3D}% | {s_peak:.3}% (at {s_peak_at} deg) / {s_max_st:.3}% |"
        ),
    );
    let t61 = table("tradeoff-interpolation");
    let st45 = t61
        .rows
        .iter()
        .find(|r| r[0] == "45")
        .map_or("-".to_string(), |r| format!("{}%", r[4]));
    w(
        &mut s,
        &format!("| sheared vs True3D at 45 deg | 0 | {st45} |"),
    );
    w(&mut s, "");
    s.push_str(&t61.to_markdown());
    w(&mut s, "");
    w(
        &mut s,
        &format!("![interpolation]({img}tradeoff-interpolation.png)"),
    );
    w(&mut s, "");
    w(&mut s, "Where we agree and where we differ, and why:");
    w(&mut s, "");
    w(
        &mut s,
        "- Zero against True3D at 45 degrees: the admissible offset of eq. (3), `min(1 - |dx|, 1 - |dy|)`, \
         is 0 there, so both schemes sample on the slices and interpolate bilinearly: identical \
         images, as the paper reports.",
    );
    w(
        &mut s,
        "- Against the image-order reference the error depends on the angle through two effects the \
         paper names: the distance between samples along the ray grows as `sqrt(1 + dx^2 + dy^2)` \
         (opacity is corrected for it, but fewer samples see thin structures), and near 45 degrees \
         the offset shrinks to 0 so sheared interpolation degenerates to bilinear. Ours also \
         includes the bilinear warp of the base-plane image (one ray per voxel) onto the image, \
         which the paper's Sheared3D had in its host warp as well.",
    );
    w(
        &mut s,
        &format!(
            "- The normalisation. The paper prints no formula for its percentage. Taken as the mean \
             RGB distance over the full scale sqrt 3 (background pixels count as exact), our largest \
             errors are {fs_io:.2}% (sheared vs image order) and {fs_st:.2}% (sheared vs True3D), \
             against the paper's < {PAPER_VS_IMAGE_ORDER}% and < {PAPER_VS_TRUE3D}%. Our main \
             column divides by the image's own RGB length instead, which ignores the background \
             and so reads several times higher ({peak:.2}% and {max_st:.2}%)."
        ),
    );
    w(
        &mut s,
        &format!(
            "- The data. The phantom's edges are 1.5 voxels wide (band-limited, docs/scenes.md), \
             steeper than a CT head's at this size, so differences of interpolation land on them; and at \
             {}^3 against 256 x 256 x 225 a voxel covers more of the image. Smoothing the phantom \
             with [1 2 1]/4 along each axis (roughly a scanner's point-spread) lowers the errors to \
             {s_peak:.2}% and {s_max_st:.2}%.",
            v.dims[0]
        ),
    );
    w(
        &mut s,
        &format!(
            "- The shape. On the raw phantom the error against image order {}. Against True3D the \
             difference is largest where the admissible offset is largest (0.5, away from 45 \
             degrees): the sheared neighbourhood departs from the cube only where a discrete ray \
             steps between the two slices of a sample, by an amount that grows with the offset.",
            if (peak_at - 45.0).abs() < 1e-9 {
                "peaks at 45 degrees, as in the paper".to_string()
            } else {
                format!("peaks at {peak_at} degrees (the paper: 45)")
            }
        ),
    );
    w(
        &mut s,
        &format!(
            "- On the smoothed volume the image-order curve is flatter and peaks at {s_peak_at} \
             degrees: with soft edges the longer step at 45 degrees costs less. What remains is \
             shared by every pipeline scheme, the longer distance between samples and the \
             bilinear warp of the base plane (one ray per voxel) onto the image: compare \
             `trilinear vs image order`, which has no sheared error."
        ),
    );
    w(&mut s, "");

    let g = report.paper_62;
    w(&mut s, "## cube3-paper §6.2: ABC gradient estimation");
    w(&mut s, "");
    w(
        &mut s,
        &format!(
            "A voxelized sphere ({0}^3, radius {1:.0} voxels, density falling linearly across a \
             two-voxel shell: a filtered scan conversion in the spirit of the paper's \"volume \
             sampling\") is viewed along the horizontal direction at each angle. Rays of the \
             slice-order frame (samples at the sheared offset, exact neighbourhood) stop at the first \
             sample above density 0.5; there the `cube5_gradient` model estimates the gradient from \
             the 3x3x3 block of ray samples, and the angle to the analytic normal is averaged over \
             all surface points. The first three columns use the unit's f64 reference arithmetic on \
             U(16.8) samples (the scheme's own error); the `(v12)` columns are the bit-accurate \
             default configuration (12-bit voxels, U(12.4) samples, 8-bit steps).",
            setup.sphere_size,
            0.375 * setup.sphere_size as f64
        ),
    );
    w(&mut s, "");
    w(
        &mut s,
        "| scheme | 0 deg | 45 deg | largest | paper (Figure 15) |",
    );
    w(&mut s, "|---|---:|---:|---:|---|");
    let words = [
        "rises toward 45 deg (slanted ray differences)",
        "lowest of the three; rises toward 45 deg",
        "a little above 6, not significantly",
    ];
    for (i, name) in ["6-neighbourhood", "10-neighbourhood", "26-neighbourhood"]
        .iter()
        .enumerate()
    {
        w(
            &mut s,
            &format!(
                "| {name} | {:.2} | {:.2} | {:.2} | {} |",
                g[i][0], g[i][1], g[i][2], words[i]
            ),
        );
    }
    w(&mut s, "");
    table_and_figure(&mut s, "tradeoff-gradient", "gradient");
    w(
        &mut s,
        "The paper gives Figure 15 as curves without printed values, so the comparison is of shape: \
         which scheme is better and where the error peaks. Differences from the paper's set-up: the \
         26-neighbourhood here is the contract's (`docs/numerics/gradient.md`): a Sobel-type sum \
         over the two opposite faces of the ray-lattice block, weighted 1, 1/2, 1/4, taken as the \
         axis components without correcting for the slant of the lattice, like the 6-neighbourhood; \
         the sphere's shell is a linear ramp rather than the paper's filter; surface points come \
         from the slice-order rays, not image-order ones.",
    );
    w(&mut s, "");
    w(&mut s, "## Perspective by parallel slabs (what-if)");
    w(&mut s, "");
    w(
        &mut s,
        "The baseline view in perspective (fov 40 degrees) rendered as parallel slabs \
         (`slab_perspective::render_slabs`, docs/numerics/slab_perspective.md: image-aligned \
         slabs, each a parallel projection along the view textured onto its middle plane, \
         blended front to back), against the f64 perspective reference; equal slabs and slabs \
         bounded at exponentially growing distances from the eye (patent [23], [318]). A what-if \
         model: the hardware has no slab pass yet. docs/measurements.md has the same sweep on \
         the 96^3 perspective scene, with MIP, where the geometry alone is measured.",
    );
    w(&mut s, "");
    table_and_figure(&mut s, "tradeoff-slabs", "slabs");
    w(&mut s, "## ER-perspective");
    w(&mut s, "");
    w(
        &mut s,
        "The baseline view in perspective at several fields of view rendered by ER-perspective \
         (`er_perspective::render_er`, docs/numerics/er_perspective.md: rays from the eye, the \
         sweep cut into regions at distances e 2^r from the eye, 3 x 3 Bartlett merging of the \
         rays at each region boundary, samples through the frame's unit models at their default \
         widths, back to front), against the f64 perspective reference; `centre` is the what-if \
         that keeps the continuing ray and drops its neighbours. `PSNR vs its f64` is the fixed \
         point's error alone (the f64 reference of the same algorithm); samples per slice stay \
         within N^2 .. 4N^2 (patent [195]). The eye sits where the bounding sphere fills the field \
         of view (as the reference renderer puts it), at least about 0.2 N in front of the volume: \
         narrow views have one region (no merge); two regions at 90 and 120 degrees here. Times \
         are the model's on a shared two-core machine. No RTL yet.",
    );
    w(&mut s, "");
    table_and_figure(&mut s, "tradeoff-er", "ER-perspective");
    w(
        &mut s,
        &format!(
            "The head scene (`scenes/head-perspective-er.toml`, 96^3, 256 x 256, fov 40), made by \
             `cube5 render scenes/head-perspective-er.toml -o docs/img/er-head-perspective.png`, \
             and the exact perspective (`cube5 render scenes/head-perspective.toml -o \
             docs/img/er-head-reference.png`):\n\n![ER-perspective head]({img}er-head-perspective.png) \
             ![f64 perspective reference]({img}er-head-reference.png)"
        ),
    );
    w(&mut s, "");
    s
}

// =================================================================================================
// Plotting: geometry with `plotters`, text with `ab_glyph` in the embedded DejaVu Sans
// =================================================================================================

/// DejaVu Sans 2.37 from Debian's fonts-dejavu-core (`cli/assets/fonts/`: its licence and where it
/// came from).
static FONT_TTF: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

/// The embedded font, parsed once.
fn font() -> &'static FontRef<'static> {
    static FONT: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT.get_or_init(|| FontRef::try_from_slice(FONT_TTF).expect("the embedded DejaVu Sans parses"))
}

const W: u32 = 900;
const H: u32 = 540;
/// Height of one legend row below the plot (two entries per row).
const LEGEND_ROW: u32 = 24;
const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];
const INK: RGBColor = RGBColor(40, 40, 40);
const GRID: RGBColor = RGBColor(225, 225, 225);
const MARK: RGBColor = RGBColor(110, 110, 110);
/// Text sizes in pixels (line height, as `ab_glyph`'s `PxScale`).
const TITLE_PX: f32 = 22.0;
const LABEL_PX: f32 = 15.0;
const DESC_PX: f32 = 16.0;
const MARK_PX: f32 = 14.0;

/// A 1-2-5 step that cuts [lo, hi] into about six parts.
fn tick_step(lo: f64, hi: f64) -> f64 {
    let raw = (hi - lo).max(1e-12) / 6.0;
    let mag = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag)
}

/// Tick positions covering [lo, hi] with a 1-2-5 step.
fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let step = tick_step(lo, hi);
    let mut t = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while t <= hi + 1e-9 * step {
        out.push(if t.abs() < 1e-12 * step { 0.0 } else { t });
        t += step;
    }
    out
}

/// Ticks of a log2 axis as (position in log2 units, label): whole powers of two (every n-th one
/// when there are many), or 1-2-5 ticks of the values when the range spans less than two octaves.
fn log2_ticks(lo: f64, hi: f64) -> Vec<(f64, String)> {
    let (first, last) = (lo.ceil(), hi.floor());
    if last - first < 2.0 {
        let (a, b) = (lo.exp2(), hi.exp2());
        let step = tick_step(a, b);
        return ticks(a, b)
            .into_iter()
            .filter(|v| *v > 0.0)
            .map(|v| (v.log2(), label(v, step)))
            .collect();
    }
    let step = ((last - first) / 8.0).ceil();
    let mut out = Vec::new();
    let mut t = first;
    while t <= last {
        let v = t.exp2();
        // A power of two prints exactly in its shortest form (0.125, 64).
        let l = if (1e-3..1e5).contains(&v) {
            format!("{v}")
        } else {
            format!("{v:.1e}")
        };
        out.push((t, l));
        t += step;
    }
    out
}

/// Ticks of a linear axis as (position, label).
fn linear_ticks(lo: f64, hi: f64) -> Vec<(f64, String)> {
    let step = tick_step(lo, hi);
    ticks(lo, hi)
        .into_iter()
        .map(|t| (t, label(t, step)))
        .collect()
}

/// A tick label: as many decimals as the tick step needs, exponent notation far from 1.
fn label(v: f64, step: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.1e}");
    }
    let decimals = (-step.abs().log10() - 1e-9).ceil().clamp(0.0, 4.0) as usize;
    format!("{v:.decimals$}")
}

/// A linear axis with our own ticks as its grid lines.
struct Axis {
    coord: RangedCoordf64,
    ticks: Vec<f64>,
}

impl Axis {
    fn new(range: Range<f64>, ticks: Vec<f64>) -> Self {
        Self {
            coord: range.into(),
            ticks,
        }
    }
}

impl Ranged for Axis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.coord.map(value, limit)
    }

    /// The ticks as the bold grid lines; no light ones.
    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.coord.range()
    }
}

/// Where a text's anchor point sits on it.
#[derive(Clone, Copy, PartialEq)]
enum Align {
    Start,
    Centre,
    End,
}

/// One line of text to draw: anchored at `at` (pixels), horizontal or running bottom to top.
struct Text {
    s: String,
    at: (i32, i32),
    px: f32,
    colour: RGBColor,
    /// Along the text and across it.
    align: (Align, Align),
    vertical: bool,
}

/// The advance width of `s` at `px` (with kerning).
fn text_width(s: &str, px: f32) -> f32 {
    let f = font().as_scaled(px);
    let mut w = 0.0;
    let mut prev = None;
    for c in s.chars() {
        let id = f.glyph_id(c);
        if let Some(p) = prev {
            w += f.kern(p, id);
        }
        w += f.h_advance(id);
        prev = Some(id);
    }
    w
}

/// Draws `t` anti-aliased: each glyph outlined at its sub-pixel pen position (advance, kerning,
/// side bearing), its coverage blended over the image.
fn draw_text(img: &mut RgbImage, t: &Text) {
    let f = font().as_scaled(t.px);
    let width = text_width(&t.s, t.px);
    // Local frame: x along the text from its start, y down from the top of the line box.
    let x0 = match t.align.0 {
        Align::Start => 0.0,
        Align::Centre => -width / 2.0,
        Align::End => -width,
    };
    // Centre on the capitals' middle rather than the line box's, which looks centred.
    let cap = f.ascent() * 0.75;
    let baseline = match t.align.1 {
        Align::Start => f.ascent(),
        Align::Centre => cap / 2.0,
        Align::End => f.descent(),
    };
    let (w, h) = (img.width() as i32, img.height() as i32);
    let colour = [t.colour.0, t.colour.1, t.colour.2];
    let mut pen = x0;
    let mut prev = None;
    for c in t.s.chars() {
        let id = f.glyph_id(c);
        if let Some(p) = prev {
            pen += f.kern(p, id);
        }
        prev = Some(id);
        let glyph = id.with_scale_and_position(t.px, point(pen, baseline));
        pen += f.h_advance(id);
        let Some(outline) = f.outline_glyph(glyph) else {
            continue;
        };
        let b = outline.px_bounds();
        outline.draw(|gx, gy, cover| {
            let (lx, ly) = (b.min.x as i32 + gx as i32, b.min.y as i32 + gy as i32);
            let (x, y) = if t.vertical {
                (t.at.0 + ly, t.at.1 - lx)
            } else {
                (t.at.0 + lx, t.at.1 + ly)
            };
            if (0..w).contains(&x) && (0..h).contains(&y) {
                let p = img.get_pixel_mut(x as u32, y as u32);
                let a = cover.clamp(0.0, 1.0);
                for (d, s) in p.0.iter_mut().zip(colour) {
                    *d = (f32::from(*d) * (1.0 - a) + f32::from(s) * a).round() as u8;
                }
            }
        });
    }
}

/// The image size [`draw`] makes for `f`: 900 x 540 and one legend row per two series.
fn size(f: &Figure) -> (u32, u32) {
    (W, H + f.series.len().div_ceil(2) as u32 * LEGEND_ROW + 6)
}

/// Draws a line plot: title, axes with grid and tick labels, the series in the palette with point
/// markers, the marks as dashed horizontal lines labelled at the right, and the legend below.
pub fn draw(f: &Figure) -> RgbImage {
    let (w, h) = size(f);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let texts = plot(f, &mut buf, (w, h)).expect("plotting into a bitmap of the right size");
    let mut img = RgbImage::from_raw(w, h, buf).expect("the buffer holds w x h RGB pixels");
    for t in &texts {
        draw_text(&mut img, t);
    }
    img
}

/// Draws everything but the text with plotters and returns the text to draw over it (the module
/// comment says why plotters does not draw the text).
fn plot(f: &Figure, buf: &mut [u8], (w, h): (u32, u32)) -> Result<Vec<Text>> {
    let root = BitMapBackend::with_buffer(buf, (w, h)).into_drawing_area();
    let (upper, _) = root.split_vertically(H);
    let mut texts = Vec::new();
    let text = |s: &str, at: (i32, i32), px: f32, align: (Align, Align)| Text {
        s: s.to_string(),
        at,
        px,
        colour: INK,
        align,
        vertical: false,
    };

    // Data ranges; x in log2 units on a log axis (points at x <= 0 cannot be shown there).
    let fx = |x: f64| if f.log_x { x.log2() } else { x };
    let points = |s: &Series| -> Vec<(f64, f64)> {
        s.points
            .iter()
            .map(|&(x, y)| (fx(x), y))
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect()
    };
    let all: Vec<(f64, f64)> = f.series.iter().flat_map(points).collect();
    let (mut x_lo, mut x_hi) = all
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.0), hi.max(p.0))
        });
    if !x_lo.is_finite() {
        (x_lo, x_hi) = (0.0, 1.0);
    }
    if x_hi - x_lo < 1e-12 {
        x_hi = x_lo + 1.0;
    }
    let ys = all
        .iter()
        .map(|p| p.1)
        .chain(f.marks.iter().map(|m| m.0))
        .filter(|v| v.is_finite());
    let (y_min, y_max) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| {
        (lo.min(y), hi.max(y))
    });
    let y_lo = 0.0f64.min(y_min);
    let mut y_hi = y_max * 1.05;
    if !y_hi.is_finite() || y_hi <= y_lo {
        y_hi = y_lo + 1.0;
    }
    // The y axis ends on a tick.
    let y_step = tick_step(y_lo, y_hi);
    y_hi = (y_hi / y_step - 1e-9).ceil() * y_step;
    let y_ticks = linear_ticks(y_lo, y_hi);
    let x_ticks = if f.log_x {
        log2_ticks(x_lo, x_hi)
    } else {
        linear_ticks(x_lo, x_hi)
    };
    // A little room left and right so that the end points' markers are not cut.
    let pad = (x_hi - x_lo) * 0.02;
    let (x_lo, x_hi) = (x_lo - pad, x_hi + pad);

    let mut chart = ChartBuilder::on(&upper)
        .margin_top(48)
        .margin_left(16)
        .margin_right(30)
        .margin_bottom(8)
        .x_label_area_size(56)
        .y_label_area_size(72)
        .build_cartesian_2d(
            Axis::new(x_lo..x_hi, x_ticks.iter().map(|t| t.0).collect()),
            Axis::new(y_lo..y_hi, y_ticks.iter().map(|t| t.0).collect()),
        )?;
    let (px, py) = chart.plotting_area().get_pixel_range();
    let (left, right, top, bottom) = (px.start, px.end - 1, py.start, py.end - 1);

    // Grid, axes, ticks and their labels.
    chart
        .configure_mesh()
        .bold_line_style(GRID)
        .light_line_style(TRANSPARENT)
        .disable_x_axis()
        .disable_y_axis()
        .draw()?;
    for (t, l) in &x_ticks {
        let (x, _) = chart.backend_coord(&(*t, y_lo));
        root.draw(&PathElement::new([(x, bottom), (x, bottom + 5)], INK))?;
        texts.push(text(
            l,
            (x, bottom + 9),
            LABEL_PX,
            (Align::Centre, Align::Start),
        ));
    }
    for (t, l) in &y_ticks {
        let (_, y) = chart.backend_coord(&(x_lo, *t));
        root.draw(&PathElement::new([(left - 5, y), (left, y)], INK))?;
        texts.push(text(
            l,
            (left - 9, y),
            LABEL_PX,
            (Align::End, Align::Centre),
        ));
    }
    root.draw(&PathElement::new(
        [(left, top), (left, bottom), (right, bottom)],
        INK.stroke_width(2),
    ))?;
    texts.push(text(
        &f.title,
        (W as i32 / 2, 14),
        TITLE_PX,
        (Align::Centre, Align::Start),
    ));
    texts.push(text(
        &f.x_label,
        ((left + right) / 2, bottom + 32),
        DESC_PX,
        (Align::Centre, Align::Start),
    ));
    texts.push(Text {
        vertical: true,
        ..text(
            &f.y_label,
            (14, (top + bottom) / 2),
            DESC_PX,
            (Align::Centre, Align::Start),
        )
    });

    // Marks and series; the marks' labels go on a veil over the series so that both show.
    for (value, _) in &f.marks {
        chart.draw_series(DashedLineSeries::new(
            [(x_lo, *value), (x_hi, *value)],
            8,
            6,
            MARK.stroke_width(1),
        ))?;
    }
    for (i, s) in f.series.iter().enumerate() {
        let c = PALETTE[i % PALETTE.len()];
        let p = points(s);
        chart.draw_series(LineSeries::new(p.iter().copied(), c.stroke_width(2)))?;
        chart.draw_series(p.iter().map(|&q| Circle::new(q, 3, c.filled())))?;
    }
    for (value, name) in &f.marks {
        let (_, y) = chart.backend_coord(&(x_hi, *value));
        let tw = text_width(name, MARK_PX).ceil() as i32;
        let (tx, ty) = (right - 6, y - 4);
        root.draw(&Rectangle::new(
            [(tx - tw - 3, ty - MARK_PX as i32), (tx + 3, ty + 1)],
            WHITE.mix(0.85).filled(),
        ))?;
        texts.push(Text {
            colour: MARK,
            ..text(name, (tx, ty), MARK_PX, (Align::End, Align::End))
        });
    }

    // Legend below the plot, two entries per row, aligned with the plotting area.
    let col_w = (right - left) / 2;
    for (i, s) in f.series.iter().enumerate() {
        let c = PALETTE[i % PALETTE.len()];
        let lx = left + (i as i32 % 2) * col_w;
        let ly = H as i32 + (i as i32 / 2) * LEGEND_ROW as i32 + LEGEND_ROW as i32 / 2;
        root.draw(&PathElement::new(
            [(lx, ly), (lx + 28, ly)],
            c.stroke_width(3),
        ))?;
        root.draw(&Circle::new((lx + 14, ly), 3, c.filled()))?;
        texts.push(text(
            &s.name,
            (lx + 38, ly),
            LABEL_PX,
            (Align::Start, Align::Centre),
        ));
    }
    root.present()?;
    Ok(texts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_cover_the_range() {
        let t = ticks(0.0, 93.0);
        assert_eq!(t.first(), Some(&0.0));
        assert!(*t.last().unwrap() >= 80.0 && t.len() <= 12);
        assert_eq!(label(0.25, 0.05), "0.25");
        assert_eq!(label(45.0, 5.0), "45");
        assert_eq!(label(1.5, 0.5), "1.5");
        assert_eq!(label(5.0, 5.0), "5");
        assert_eq!(label(0.004, 0.001), "0.004");
        let pos = |t: Vec<(f64, String)>| t.into_iter().map(|t| t.0).collect::<Vec<_>>();
        assert_eq!(pos(log2_ticks(1.0, 10.0)), vec![1.0, 3.0, 5.0, 7.0, 9.0]);
        assert_eq!(pos(log2_ticks(2.0, 6.5)), vec![2.0, 3.0, 4.0, 5.0, 6.0]);
        let labels: Vec<String> = log2_ticks(-3.0, 0.5).into_iter().map(|t| t.1).collect();
        assert_eq!(labels, ["0.125", "0.25", "0.5", "1"]);
        // Less than two octaves: 1-2-5 ticks of the values.
        let labels: Vec<String> = log2_ticks(-1.0, 0.0).into_iter().map(|t| t.1).collect();
        assert_eq!(labels, ["0.5", "0.6", "0.7", "0.8", "0.9", "1.0"]);
    }

    fn figure(title: &str, series: usize, log_x: bool) -> Figure {
        Figure {
            name: "t".into(),
            title: title.into(),
            x_label: "x".into(),
            y_label: "y".into(),
            series: (0..series)
                .map(|i| Series {
                    name: format!("series {i}"),
                    points: vec![(1.0, 1.0 + i as f64), (64.0, 2.0 + i as f64)],
                })
                .collect(),
            marks: vec![(1.5, "mark".into())],
            log_x,
        }
    }

    /// Pixels in the title's band (above the plotting area) that are not white, and of those the
    /// grey ones that only anti-aliased text makes.
    fn title_ink(img: &RgbImage) -> (usize, usize) {
        let band = (250..650).flat_map(|x| (8..44).map(move |y| (x, y)));
        let px: Vec<[u8; 3]> = band.map(|(x, y)| img.get_pixel(x, y).0).collect();
        let inked = px.iter().filter(|p| **p != [255; 3]).count();
        let grey = px.iter().filter(|p| p[0] > 60 && p[0] < 200).count();
        (inked, grey)
    }

    #[test]
    fn draw_makes_the_size_and_writes_the_title_in_the_embedded_font() {
        for (series, log_x, h) in [(1, false, 570), (3, true, 594), (6, false, 618)] {
            let img = draw(&figure("Error vs samples (%)", series, log_x));
            assert_eq!(img.dimensions(), (900, h), "{series} series");
            let (inked, grey) = title_ink(&img);
            assert!(
                inked > 400 && grey > 100,
                "title: {inked} inked, {grey} grey pixels"
            );
            let plot = img.pixels().filter(|p| p.0 == [31, 119, 180]).count();
            assert!(plot > 500, "the first series is drawn: {plot} pixels");
        }
        assert_eq!(title_ink(&draw(&figure("", 2, false))), (0, 0), "no title");
    }
}
