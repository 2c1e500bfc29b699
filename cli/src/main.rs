//! `cube5`: render scenes with the golden model, co-simulate the RTL against it, and measure.

/// `println!` that never panics: a closed stdout (`cube5 render | head -1`) loses the text, not the
/// run.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

#[cfg(feature = "rtl")]
mod bench;
#[cfg(feature = "rtl")]
mod cosim;
#[cfg(feature = "rtl")]
mod cosim_gi;
mod elaborate;
mod tradeoff;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use cube5_model::er_perspective::render_er;
use cube5_model::phantom::{phantom_by_name, PHANTOMS};
use cube5_model::render::{
    image_error, render_pipeline, render_reference_geometry, ImageF64, Projection,
};
use cube5_model::scene::{Plan, Renderer, Scene, Target};
use cube5_model::scene_render::{frame_config, not_expressible, FrameJob};
use cube5_model::slab_perspective::render_slabs;
use cube5_model::volume_io::{self, Endian, NrrdEncoding};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Debug, Parser)]
#[command(
    name = "cube5",
    version,
    about = "cube5 volume rendering: golden model, co-simulation, measurements"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Render a scene with the golden model to a PNG (the embedded default scene when none given).
    Render(RenderArgs),
    /// Measure the speed/accuracy trade: sweep the quality knobs against the f64 reference.
    Tradeoff(tradeoff::TradeoffArgs),
    /// Write an embedded phantom as a volume file (.nrrd, .nii, .nii.gz or .raw).
    Phantom(PhantomArgs),
    /// Print a built-in transfer function's points, one a line: density r g b a (densities
    /// normalized to the voxel range, alpha the opacity of one voxel of path).
    Transfer(TransferArgs),
    /// Co-simulate one frame of a scene: the RTL frame against the golden model, bit for bit.
    #[cfg(feature = "rtl")]
    Cosim(cosim::CosimArgs),
    /// Print speed figures: simulated RTL cycles per second and model samples per second.
    #[cfg(feature = "rtl")]
    Bench(bench::BenchArgs),
    /// Print the cube5_frame configuration a scene needs (P, widths, MaxDim, the units it leaves
    /// out and why), its .variants line and CUBE5_TOPS entry, whether it is built, its area.
    Elaborate(elaborate::ElaborateArgs),
}

#[derive(Debug, clap::Args)]
struct TransferArgs {
    /// Preset name (`[transfer] preset` of a scene).
    #[arg(default_value = "head")]
    name: String,
}

#[derive(Debug, clap::Args)]
struct RenderArgs {
    /// Scene file (TOML); omit for the embedded head phantom.
    scene: Option<PathBuf>,
    /// Output PNG.
    #[arg(short, long, default_value = "cube5-render.png")]
    output: PathBuf,
    /// Override the view azimuth in degrees (replaces a scene's view.direction; the elevation not
    /// given is the direction's).
    #[arg(long, allow_negative_numbers = true)]
    azimuth: Option<f64>,
    /// Override the view elevation in degrees (continuous through the poles: past 90 the eye goes
    /// over the top; replaces a scene's view.direction).
    #[arg(long, allow_negative_numbers = true)]
    elevation: Option<f64>,
    /// Override the view roll: degrees the picture turns counterclockwise.
    #[arg(long, allow_negative_numbers = true)]
    roll: Option<f64>,
    /// Override the image up vector, `X,Y,Z` (made orthogonal to the view).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_vec3)]
    up: Option<[f64; 3]>,
    /// Override the image width in pixels.
    #[arg(long)]
    width: Option<u32>,
    /// Override the image height in pixels.
    #[arg(long)]
    height: Option<u32>,
    /// Render with the f64 image-order reference instead of the pipeline model.
    #[arg(long)]
    reference: bool,
    /// Perspective scenes: approximate the perspective by this many parallel slabs (the what-if
    /// slab model, run.renderer = "slabs").
    #[arg(long)]
    slabs: Option<u32>,
    /// Perspective scenes: render with ER-perspective on the frame's unit models (exponential
    /// regions, Bartlett ray merging; run.renderer = "er").
    #[arg(long)]
    er: bool,
    /// Also render the f64 reference and print the pipeline's error against it.
    #[arg(long)]
    compare: bool,
    /// Override run.target: model, rtl (co-simulate the RTL frame) or both.
    #[arg(long, value_parser = parse_target)]
    target: Option<Target>,
    /// Render the frame this many times (volume loaded once) and print the best time.
    #[arg(long, default_value_t = 1)]
    repeat: u32,
}

#[derive(Debug, clap::Args)]
struct PhantomArgs {
    /// Phantom name (head, sphere, bubbles, sphere-floor).
    name: String,
    /// Output file: .nrrd (gzip-encoded), .nii, .nii.gz or .raw (u8/u16, little endian).
    #[arg(short, long)]
    output: PathBuf,
    /// Edge in voxels.
    #[arg(long, default_value_t = 64)]
    size: usize,
    /// Voxel width in bits (at most 8 stores u8, else u16).
    #[arg(long, default_value_t = 8)]
    bits: u32,
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                print!("{e}");
                return ExitCode::SUCCESS;
            }
            // One line: clap's first line names the problem; the usage block would bury it.
            let text = e.render().to_string();
            eprintln!(
                "{} (see `cube5 --help`)",
                text.lines().next().unwrap_or("bad arguments")
            );
            return ExitCode::from(2);
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One line, whatever the chain holds.
            eprintln!("error: {}", format!("{e:#}").replace('\n', " "));
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render(args) => render(args),
        Command::Tradeoff(args) => tradeoff::run(args),
        Command::Phantom(args) => phantom(args),
        Command::Transfer(args) => transfer(args),
        #[cfg(feature = "rtl")]
        Command::Bench(args) => bench::run(args),
        #[cfg(feature = "rtl")]
        Command::Cosim(args) => cosim::run(args),
        Command::Elaborate(args) => elaborate::run(args),
    }
}

fn parse_target(s: &str) -> std::result::Result<Target, String> {
    match s {
        "model" => Ok(Target::Model),
        "rtl" => Ok(Target::Rtl),
        "both" => Ok(Target::Both),
        _ => Err(format!("`{s}`: must be model, rtl or both")),
    }
}

fn parse_vec3(s: &str) -> std::result::Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|e| format!("`{s}`: {e}; expected three numbers X,Y,Z"))?;
    <[f64; 3]>::try_from(v)
        .map_err(|v| format!("`{s}`: {} numbers; expected three numbers X,Y,Z", v.len()))
}

fn load_scene(path: Option<&Path>) -> Result<Scene> {
    Ok(match path {
        Some(p) => Scene::load(p)?,
        None => Scene::default(),
    })
}

/// Refuses an output name that is not `.png` or whose directory does not exist, before any work.
fn check_png_path(path: &Path) -> Result<()> {
    if path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
        != Some("png")
    {
        bail!("output {}: the file name must end in .png", path.display());
    }
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !dir.is_dir() {
        bail!(
            "output {}: directory {} does not exist",
            path.display(),
            dir.display()
        );
    }
    Ok(())
}

fn render(args: RenderArgs) -> Result<()> {
    let mut scene = load_scene(args.scene.as_deref())?;
    scene.view.set_angles(args.azimuth, args.elevation);
    if let Some(r) = args.roll {
        scene.view.roll = r;
    }
    if let Some(u) = args.up {
        scene.view.up = Some(u);
    }
    if let Some(w) = args.width {
        scene.image.width = w;
    }
    if let Some(h) = args.height {
        scene.image.height = h;
    }
    if args.reference && args.slabs.is_some() {
        bail!("--reference and --slabs name two renderers; give one");
    }
    if args.er && (args.reference || args.slabs.is_some()) {
        bail!("--er and --reference or --slabs name two renderers; give one");
    }
    if args.er {
        scene.run.renderer = Renderer::Er;
    }
    if args.reference {
        scene.run.renderer = Renderer::Reference;
    }
    if let Some(n) = args.slabs {
        scene.run.renderer = Renderer::Slabs;
        scene.view.slabs = n;
    }
    if let Some(t) = args.target {
        scene.run.target = t;
    }
    scene.validate("command line")?;
    check_png_path(&args.output)?;
    let vol = scene.build_volume()?;
    if scene.gi.is_some() {
        return render_gi(&scene, &vol, &args);
    }
    let plan = Plan::new(&scene, &vol)?;
    say!("plan: {plan}");
    // The f64 reference sees the pre-filter's f64 ideal (`volume.prefilter`; the frame filters
    // its own memory's voxels on the sepconv model).
    let ref_vol = cube5_model::prefilter::reference_volume(&vol, scene.prefilter())?;
    if scene.run.target.uses_rtl() {
        let done = cosim_for_render(&scene, &args)?;
        if done {
            return Ok(());
        }
    }
    let params = scene.render_params();
    let tf = scene.transfer_function();
    let what_if = not_expressible(&scene);
    let repeat = args.repeat.max(1);
    // Opaque geometry ([geometry]): the f64 reference intersects it exactly.
    let solids = scene
        .geometry
        .as_ref()
        .map(|g| g.solids())
        .unwrap_or_default();
    // The frame's set-up (volume at VoxelW, block LUT, tables) is made once; a frame is the sweep
    // and the warp.
    let job = match scene.run.renderer {
        Renderer::Pipeline if what_if.is_empty() => {
            Some(FrameJob::new(&scene, &vol, frame_config(&scene)?, 1)?)
        }
        _ => None,
    };
    let mut best = f64::INFINITY;
    let mut frame = || -> Result<(ImageF64, String, u64)> {
        let start = std::time::Instant::now();
        let out = match scene.run.renderer {
            Renderer::Reference => {
                let img = render_reference_geometry(&ref_vol, &tf, &params, &solids)?;
                let what = format!(
                    "f64 reference renderer, step {}{}",
                    params.step,
                    if params.projection == Projection::Perspective {
                        ", perspective: exact rays from the eye"
                    } else {
                        ""
                    }
                );
                (img, what, 0)
            }
            Renderer::Slabs => {
                let slabs = scene.slabs();
                let img = render_slabs(&vol, &tf, &params, slabs)?;
                let what = format!(
                    "what-if slab perspective, not the hardware: {}, f64 parallel ray casts, step {}",
                    slabs.describe(),
                    params.step
                );
                (img, what, 0)
            }
            Renderer::Er => {
                let run = render_er(&vol, &tf, &params, &frame_config(&scene)?, scene.er())?;
                let what = format!(
                    "ER-perspective model on the frame's unit models, {}: {}",
                    scene.er().describe(),
                    run.stats.describe()
                );
                (run.image, what, run.stats.samples)
            }
            Renderer::Pipeline if let Some(job) = &job => {
                // The one golden model: the frame the RTL computes, then the warp.
                let run = job.render();
                let img = job.image(&scene, &run.base)?;
                let what = format!(
                    "frame model = cube5_frame's bits, warped by the cube5_warp model: base plane {}x{}, {} samples ({} in empty blocks, not read), {} + {} of {} slices skipped (empty), {} of {} rays terminated early; the model shaded {} samples, classified {} only (no effect), skipped {} after termination and {} in blocks that cannot change their rays",
                    run.base.width,
                    run.base.height,
                    run.samples,
                    run.samples_in_skipped_blocks,
                    run.skipped_slices.0,
                    run.skipped_slices.1,
                    run.slices,
                    run.terminated_rays,
                    run.base.coxels.len(),
                    run.model.shaded,
                    run.model.without_effect,
                    run.model.after_termination,
                    run.model.in_skipped_blocks
                );
                (img, what, run.samples)
            }
            Renderer::Pipeline => {
                let q = scene.quality();
                let out = render_pipeline(&vol, &tf, &params, &q)?;
                let s = out.stats;
                let what = format!(
                    "what-if pipeline model, not the hardware ({}): {} interpolation, {}-neighbourhood gradient, base plane {}x{}, {} samples",
                    what_if.join("; "),
                    q.interpolation.name(),
                    u32::from(q.gradient),
                    s.base_plane[0],
                    s.base_plane[1],
                    s.samples
                );
                (out.image, what, s.samples)
            }
        };
        best = best.min(start.elapsed().as_secs_f64());
        Ok(out)
    };
    let (img, what, samples) = frame()?;
    let mut last = Instant::now();
    for n in 1..repeat {
        frame()?;
        if last.elapsed().as_secs_f64() > 2.0 {
            eprintln!("frame {} of {repeat}", n + 1);
            last = Instant::now();
        }
    }
    if args.repeat > 1 {
        say!(
            "time: frame {:.2} ms (best of {repeat}), {:.1} M samples/s, {} threads",
            best * 1e3,
            samples as f64 / best / 1e6,
            rayon::current_num_threads()
        );
    }
    let secs = best;
    if args.compare && scene.run.renderer != Renderer::Reference {
        let reference = render_reference_geometry(&ref_vol, &tf, &params, &solids)?;
        let e = image_error(&img, &reference);
        say!(
            "error against the f64 reference: PSNR {:.1} dB, max abs {:.1}/255, relative Euclidean {:.3}%",
            e.psnr_db,
            e.max_abs * 255.0,
            e.rel_euclid
        );
    }
    write_png_atomically(&img.to_rgb8(), &args.output)?;
    let mut view = match params.direction {
        Some(d) => format!("view direction {d:?}"),
        None => format!(
            "view azimuth {} elevation {}",
            params.view.azimuth, params.view.elevation
        ),
    };
    if let Some(u) = params.up {
        view += &format!(" up {u:?}");
    }
    if params.roll != 0.0 {
        view += &format!(" roll {}", params.roll);
    }
    say!(
        "rendered {}x{}x{} volume, {view}, {}x{} pixels in {:.4} s ({what})",
        vol.dims[0],
        vol.dims[1],
        vol.dims[2],
        params.width,
        params.height,
        secs
    );
    say!("wrote {}", args.output.display());
    Ok(())
}

/// A scene with `[gi]`: the GI-Cube processor model (lighting pass, then rendering pass), or its
/// f64 reference. The plan line follows the run, with the passes' counts.
fn render_gi(scene: &Scene, vol: &cube5_model::volume::Volume, args: &RenderArgs) -> Result<()> {
    use cube5_model::scene_gi::{compare, run_counts_text, GiJob};
    if scene.run.target.uses_rtl() && cosim_for_render(scene, args)? {
        return Ok(());
    }
    let mut plan = Plan::new(scene, vol)?;
    let mut job = GiJob::new(scene, vol)?;
    let repeat = args.repeat.max(1);
    let mut best = f64::INFINITY;
    let mut run = None;
    for _ in 0..repeat {
        let start = Instant::now();
        let out = match scene.run.renderer {
            Renderer::Pipeline => job.run()?,
            // Refused by the scene's validation; kept here so no renderer falls through.
            Renderer::Slabs => bail!("run.renderer = \"slabs\": a [gi] scene has no slab model"),
            Renderer::Er => {
                bail!("run.renderer = \"er\": a [gi] scene has no ER-perspective model")
            }
            Renderer::Reference => {
                let image = job
                    .reference()?
                    .context("the f64 reference of photons (gi.albedo > 0) does not exist")?;
                cube5_model::scene_gi::GiRun {
                    image,
                    lighting: None,
                    rendering: Default::default(),
                }
            }
        };
        best = best.min(start.elapsed().as_secs_f64());
        run = Some(out);
    }
    let run = run.context("no frame rendered")?;
    if scene.run.renderer == Renderer::Pipeline {
        plan.model = format!("{} [counts: {}]", plan.model, run_counts_text(&run));
    }
    say!("plan: {plan}");
    let samples = run.rendering.samples + run.lighting.map_or(0, |c| c.samples);
    if repeat > 1 {
        say!(
            "time: frame {:.2} ms (best of {repeat}), {:.2} M samples/s",
            best * 1e3,
            samples as f64 / best / 1e6
        );
    }
    if args.compare && scene.run.renderer == Renderer::Pipeline {
        match job.reference()? {
            Some(reference) => {
                let (db, max) = compare(&run.image, &reference);
                say!(
                    "error against the GI-Cube processor's f64 reference: PSNR {db:.1} dB, max abs {:.1}/255",
                    max * 255.0
                );
            }
            None => say!(
                "no f64 reference for photons (gi.albedo > 0): their walk is random (docs/numerics/gicube_processor.md compares them with Monte Carlo)"
            ),
        }
    }
    write_png_atomically(&run.image.to_rgb8(), &args.output)?;
    say!(
        "rendered {}x{}x{} volume, {}x{} pixels in {:.4} s ({})",
        vol.dims[0],
        vol.dims[1],
        vol.dims[2],
        scene.image.width,
        scene.image.height,
        best,
        match scene.run.renderer {
            Renderer::Pipeline | Renderer::Slabs | Renderer::Er => "GI-Cube processor model",
            Renderer::Reference => "f64 reference of the GI-Cube processor model",
        }
    );
    say!("wrote {}", args.output.display());
    Ok(())
}

/// `run.target = "rtl"` or `"both"`: the RTL frame (P = 4) against the model, or for a `[gi]`
/// scene both passes on the `gicube_processor` line of its size (`cube5 cosim`'s run, the DDR-like
/// memory), images beside the output. True when the scene asks for the RTL only (nothing more to
/// render).
#[cfg(feature = "rtl")]
fn cosim_for_render(scene: &Scene, args: &RenderArgs) -> Result<bool> {
    let origin = args
        .scene
        .as_ref()
        .map_or("the default scene".to_string(), |p| p.display().to_string());
    let stem = args
        .output
        .file_stem()
        .map_or("cube5".into(), |s| s.to_string_lossy().into_owned());
    let dir = args.output.with_file_name(format!("{stem}-cosim"));
    let target = scene.run.target.name();
    if scene.gi.is_some() {
        let memory = cosim_gi::MemoryKind::Ddr;
        let matched = cosim_gi::run(scene, &origin, &dir, 1, memory)
            .with_context(|| format!("run.target = \"{target}\""))?;
        if !matched {
            bail!("run.target = \"{target}\": the RTL GI-Cube processor differs from the model (report above)");
        }
        return Ok(scene.run.target == Target::Rtl);
    }
    // The RTL frame the scene elaborates to (`cube5 elaborate`) against the model, images beside
    // the output.
    let rtl = cosim::variant_for(scene, &origin, None)?;
    say!(
        "rtl: {} (the only RTL variant this scene needs; `make cosim SCENE=...` builds just it)",
        rtl.variant
    );
    let r = cosim::cosim_scene(scene, &origin, rtl, &dir, 1)?;
    if !r.matched {
        bail!("run.target = \"{target}\": the RTL frame differs from the model (report above)");
    }
    Ok(scene.run.target == Target::Rtl)
}

#[cfg(not(feature = "rtl"))]
fn cosim_for_render(scene: &Scene, _args: &RenderArgs) -> Result<bool> {
    bail!(
        "run.target = \"{}\": this cube5 was built without the RTL (cargo feature `rtl`); render with run.target = \"model\" or build with the default features",
        scene.run.target.name()
    )
}

fn transfer(args: TransferArgs) -> Result<()> {
    let tf = cube5_model::transfer::TransferFunction::preset(&args.name)?;
    for p in &tf.points {
        let [r, g, b, a] = p.rgba;
        say!("{} {r} {g} {b} {a}", p.density);
    }
    Ok(())
}

fn phantom(args: PhantomArgs) -> Result<()> {
    if !PHANTOMS.contains(&args.name.as_str()) {
        bail!(
            "phantom `{}`: unknown (known: {})",
            args.name,
            PHANTOMS.join(", ")
        );
    }
    let vol = phantom_by_name(&args.name, args.size, args.bits)?;
    let name = args
        .output
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let what = format!(
        "cube5 {} phantom, {}^3 voxels of {} bits (cube5 phantom {} --size {} --bits {})",
        args.name, args.size, args.bits, args.name, args.size, args.bits
    );
    if name.ends_with(".nrrd") {
        volume_io::write_nrrd(&args.output, &vol, NrrdEncoding::Gzip, &what)?;
    } else if name.ends_with(".nii") || name.ends_with(".nii.gz") {
        volume_io::write_nifti(&args.output, &vol, &what)?;
    } else if name.ends_with(".raw") {
        let t = volume_io::write_raw(&args.output, &vol, Endian::Little)?;
        say!(
            "raw: dims = [{0}, {0}, {0}], type = \"{1}\", endian = \"little\"",
            args.size,
            t.name()
        );
    } else {
        bail!(
            "output {}: the name must end in .nrrd, .nii, .nii.gz or .raw",
            args.output.display()
        );
    }
    say!("wrote {} ({what})", args.output.display());
    Ok(())
}

/// Encodes the PNG, then writes it to a temporary name beside the target and renames, so a failure
/// leaves no partial file.
fn write_png_atomically(img: &image::RgbImage, path: &Path) -> Result<()> {
    check_png_path(path)?;
    let mut png = std::io::Cursor::new(Vec::new());
    img.write_to(&mut png, image::ImageFormat::Png)
        .with_context(|| format!("encoding {}", path.display()))?;
    volume_io::write_atomically(path, png.get_ref())?;
    Ok(())
}
