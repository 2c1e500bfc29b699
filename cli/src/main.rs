//! `cube5`: render scenes with the golden model, co-simulate the RTL against it, and measure.

mod bench;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use cube5_model::render::render_reference;
use cube5_model::scene::Scene;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

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
    /// Print speed figures: simulated RTL cycles per second and model samples per second.
    Bench(bench::BenchArgs),
}

#[derive(Debug, clap::Args)]
struct RenderArgs {
    /// Scene file (TOML); omit for the embedded head phantom.
    scene: Option<PathBuf>,
    /// Output PNG.
    #[arg(short, long, default_value = "cube5-render.png")]
    output: PathBuf,
    /// Override the view azimuth in degrees.
    #[arg(long, allow_negative_numbers = true)]
    azimuth: Option<f64>,
    /// Override the view elevation in degrees.
    #[arg(long, allow_negative_numbers = true)]
    elevation: Option<f64>,
    /// Override the image width in pixels.
    #[arg(long)]
    width: Option<u32>,
    /// Override the image height in pixels.
    #[arg(long)]
    height: Option<u32>,
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
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render(args) => render(args),
        Command::Bench(args) => bench::run(args),
    }
}

fn load_scene(path: Option<&Path>) -> Result<Scene> {
    Ok(match path {
        Some(p) => Scene::load(p)?,
        None => Scene::default(),
    })
}

fn render(args: RenderArgs) -> Result<()> {
    let mut scene = load_scene(args.scene.as_deref())?;
    if let Some(a) = args.azimuth {
        scene.view.azimuth = a;
    }
    if let Some(e) = args.elevation {
        scene.view.elevation = e;
    }
    if let Some(w) = args.width {
        scene.image.width = w;
    }
    if let Some(h) = args.height {
        scene.image.height = h;
    }
    scene.validate("command line")?;
    if args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
        != Some("png")
    {
        bail!(
            "output {}: the file name must end in .png",
            args.output.display()
        );
    }
    let vol = scene.build_volume()?;
    let params = scene.render_params();
    let start = std::time::Instant::now();
    let img = render_reference(&vol, &scene.transfer_function(), &params)?;
    let secs = start.elapsed().as_secs_f64();
    write_png_atomically(&img.to_rgb8(), &args.output)?;
    println!(
        "rendered {}x{}x{} volume, view azimuth {} elevation {}, {}x{} pixels in {:.2} s (f64 reference renderer)",
        vol.dims[0],
        vol.dims[1],
        vol.dims[2],
        params.view.azimuth,
        params.view.elevation,
        params.width,
        params.height,
        secs
    );
    println!("wrote {}", args.output.display());
    Ok(())
}

/// Writes to a temporary name beside the target and renames, so a failure leaves no partial file.
fn write_png_atomically(img: &image::RgbImage, path: &Path) -> Result<()> {
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
    let tmp = dir.join(format!(
        ".{}.tmp",
        path.file_name()
            .map(|n| n.to_string_lossy())
            .unwrap_or_default()
    ));
    img.save_with_format(&tmp, image::ImageFormat::Png)
        .with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("renaming to {}", path.display()))?;
    Ok(())
}
