//! `cube5 cosim [SCENE]`: one frame of a scene through the RTL frame (`cube5_frame`, Verilator)
//! and the golden model, compared pixel by pixel and channel by channel. Prints MATCH or the first
//! mismatch (pixel, channel, both values, the model's sample trail of that ray), the cycles per
//! frame and samples per clock per pipeline, and writes both base planes and both warped images.

use crate::write_png_atomically;
use anyhow::{anyhow, bail, Context, Result};
use cube5_model::render::ImageF64;
use cube5_model::scene::Scene;
use cube5_model::scene_render::{at_voxel_width, frame_config, not_expressible, FrameJob};
use cube5_model::units::cube5_compos::{ComposConfig, Coxel};
use cube5_model::units::cube5_frame::{BasePlane, FrameConfig};
use cube5_tb::frame::{Expected, FrameBench, FrameRtl};
use cube5_tb::rtl::Traffic;
use cube5_tb::TbError;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct CosimArgs {
    /// Scene file (TOML); omit for the embedded default scene.
    scene: Option<PathBuf>,
    /// Pipelines, overriding the scene's run.pipelines (default 4): a P this build has.
    #[arg(short, long)]
    pipelines: Option<usize>,
    /// Directory for the images (created if missing).
    #[arg(short, long, default_value = "cube5-cosim")]
    out_dir: PathBuf,
    /// Seed of the DUT's random initial state (randReset).
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// `[gi]` scenes: how the test bench's AXI4 memory answers the GI-Cube processor.
    #[arg(long, value_enum, default_value_t = crate::cosim_gi::MemoryKind::Ddr)]
    memory: crate::cosim_gi::MemoryKind,
}

/// What a co-simulated frame showed.
pub struct CosimResult {
    pub matched: bool,
}

pub fn run(args: CosimArgs) -> Result<()> {
    let (scene, origin) = crate::elaborate::load_valid(args.scene.as_deref())?;
    if scene.gi.is_some() {
        // The GI-Cube block processor (gicube_processor), not cube5_frame.
        if !crate::cosim_gi::run(&scene, &origin, &args.out_dir, args.seed, args.memory)? {
            bail!("the RTL GI-Cube processor differs from the model (report above)");
        }
        return Ok(());
    }
    if let Some(p) = args.pipelines {
        if !FrameRtl::all().iter().any(|r| r.p == p && r.variant.built) {
            bail!(
                "--pipelines {p}: cube5_frame is built for P = {} (rtl/cube5/cube5_frame.variants)",
                FrameRtl::pipeline_counts()
                    .iter()
                    .map(|p| p.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    if scene.run.renderer == cube5_model::scene::Renderer::Er {
        // ER-perspective runs on its own top, cube5_er, not on cube5_frame.
        let matched = cosim_er(&scene, &origin, &args.out_dir, args.seed)?;
        if !matched {
            bail!("the RTL ER-perspective base plane differs from the model (report above)");
        }
        return Ok(());
    }
    let rtl = variant_for(&scene, &origin, args.pipelines)?;
    let result = cosim_scene(&scene, &origin, rtl, &args.out_dir, args.seed)?;
    if !result.matched {
        bail!("the RTL frame differs from the model (report above)");
    }
    Ok(())
}

/// The cube5_frame variant a scene co-simulates on: the configuration the scene elaborates to
/// (`cube5 elaborate`: P, widths, units, MaxDim), built in this cube5; where only a larger memory
/// of the same configuration is built, that one (it holds the volume, and the image does not
/// depend on MaxDim), said so. Prints what was elaborated and why, and the area where a synthesis
/// of it is cached. Refused, naming the `make cosim` that builds it, when neither is built.
pub fn variant_for(scene: &Scene, origin: &str, pipelines: Option<usize>) -> Result<FrameRtl> {
    let e = crate::elaborate::derive(scene, origin, pipelines)?;
    for line in crate::elaborate::report(&e, origin) {
        say!("{line}");
    }
    match crate::elaborate::area_lines(&e, false) {
        Ok(lines) => lines.iter().for_each(|l| say!("{l}")),
        Err(why) => say!("area: {why}"),
    }
    let same = |r: &FrameRtl| {
        r.variant.built
            && r.max_dim_log2 >= e.config.max_dim_log2
            && r.cfg
                == FrameConfig {
                    max_dim_log2: r.max_dim_log2,
                    ..e.config
                }
    };
    let rtl = FrameRtl::all()
        .into_iter()
        .filter(same)
        .min_by_key(|r| r.max_dim_log2)
        .ok_or_else(|| {
            anyhow!(
                "{origin}: cube5_frame {} is not built in this cube5: `make cosim SCENE={origin}` builds it (CUBE5_TOPS={})",
                e.name(),
                e.tops()
            )
        })?;
    if rtl.cfg != e.config {
        say!(
            "runs on {}: the same configuration with a larger memory (MaxDim {} >= {}); `make cosim SCENE={origin}` builds the exact one",
            rtl.variant,
            rtl.max_dim(),
            e.config.max_dim()
        );
    }
    Ok(rtl)
}

/// One frame of `scene` on `rtl` and on the model (`FrameJob`, what `cube5 render` computes);
/// prints the comparison and the figures and writes the images into `out_dir`.
pub fn cosim_scene(
    scene: &Scene,
    origin: &str,
    rtl: FrameRtl,
    out_dir: &Path,
    seed: u32,
) -> Result<CosimResult> {
    let why = not_expressible(scene);
    if !why.is_empty() {
        bail!(
            "{origin}: cube5_frame cannot render this scene: {}",
            why.join("; ")
        );
    }
    let params_r = scene.render_params();
    let dir = params_r.direction().context(origin.to_string())?;
    std::fs::create_dir_all(out_dir)
        .with_context(|| format!("output directory {}", out_dir.display()))?;
    let want = frame_config(scene)?;
    if (want.trilin, want.gradient, want.shader, want.compos)
        != (rtl.trilin, rtl.gradient, rtl.shader, rtl.compos)
    {
        // `cube5 cosim -p P` names the variant by P; the scene's widths must be its widths.
        bail!(
            "{origin}: the scene's widths ([quality]) are not those of {} (the defaults): co-simulate it on a cube5_frame variant with its widths",
            rtl.variant
        );
    }
    let raw = scene.build_volume()?;
    // The variant's limits first (memory size, multiples of P), named by the variant.
    rtl.check_volume(&at_voxel_width(&raw, rtl.trilin.voxel_w)?)
        .map_err(|e| anyhow!("{origin}: volume: {e}"))?;
    prepass_on_the_rtl(scene, origin, &raw, rtl.trilin.voxel_w, seed)?;
    let job = FrameJob::new(scene, &raw, rtl.cfg, rtl.p)?;
    let vol = &job.seen;
    say!(
        "cosim: {} volume {}x{}x{} ({}-bit, as {}-bit), {} on {} ({} pipelines), view {:.4?}",
        origin,
        vol.dims[0],
        vol.dims[1],
        vol.dims[2],
        raw.bits,
        vol.bits,
        scene.render.mode.name(),
        rtl.variant,
        rtl.p,
        dir.to_array()
    );

    let t = Instant::now();
    let e = Expected::from_job(&job, job.render(), "scene");
    let model_secs = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut bench = FrameBench::new(rtl, vol, &job.lut, seed)?;
    bench.skip_empty = true;
    bench.load(&e)?;
    let load_secs = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let got = bench.render(&e, &Traffic::full_speed())?;
    let sim_secs = t.elapsed().as_secs_f64();
    let verdict = bench.compare(&e, &got, u64::from(seed));

    let samples = e.params.samples() as u64;
    let matched = match &verdict {
        Ok(st) => {
            say!(
                "MATCH: {} x {} base-plane pixels, every channel bit-exact; {} + {} of {} slices skipped (empty); memory beats read {} (model = RTL), {} not read (empty blocks), no module conflict",
                e.w,
                e.h,
                st.skip.0,
                st.skip.1,
                e.params.nk,
                st.accesses.beams_read,
                st.accesses.beams_skipped
            );
            true
        }
        Err(TbError::Mismatch(report)) => {
            say!("{report}");
            false
        }
        Err(other) => return Err(anyhow!("{other}")),
    };
    let cycles = got.cycles;
    let sweep = got.pixels.first().map_or(0, |p| u64::from(p.cycles));
    let swept = (e.params.nk - bench.skip.0 - bench.skip.1) * e.params.ni * e.params.nj;
    let per_clock = |n: usize, c: u64| n as f64 / (c.max(1) as f64 * rtl.p as f64);
    say!(
        "cycles per frame {cycles} (sweep {sweep}, read-out {}); {swept} of the volume's {samples} samples swept: {:.3} samples/clock/pipeline ({:.3} over the sweep alone; limit 1); with the skipped slices, {:.3} volume samples/clock/pipeline",
        cycles.saturating_sub(sweep),
        per_clock(swept, cycles),
        per_clock(swept, sweep),
        per_clock(samples as usize, cycles)
    );
    say!(
        "simulated {:.2} Mcycles/s ({:.2} s); volume and tables loaded in {:.2} s; model {:.2e} samples/s ({:.2} s)",
        cycles as f64 / sim_secs / 1e6,
        sim_secs,
        load_secs,
        samples as f64 / model_secs,
        model_secs
    );

    // The images: both base planes as they are, and both warped onto the scene's image.
    let cfg = rtl.compos;
    let model_bp = BasePlane {
        width: e.w,
        height: e.h,
        coxels: e.want.clone(),
    };
    let mut rtl_coxels: Vec<Coxel> = got.pixels.iter().map(|p| p.coxel).collect();
    rtl_coxels.resize(e.w * e.h, Coxel::empty(&cfg));
    let rtl_bp = BasePlane {
        width: e.w,
        height: e.h,
        coxels: rtl_coxels,
    };
    for (who, bp) in [("model", &model_bp), ("rtl", &rtl_bp)] {
        let base = base_plane_png(bp, &cfg);
        let path = out_dir.join(format!("{who}-base-plane.png"));
        write_png_atomically(&base, &path)?;
        let warped = job.image(scene, bp)?;
        let path2 = out_dir.join(format!("{who}.png"));
        write_png_atomically(&warped.to_rgb8(), &path2)?;
        say!("wrote {} and {}", path.display(), path2.display());
    }
    Ok(CosimResult { matched })
}

/// The scene's pre-pass (`volume.prefilter`) through the `cube5_sepconv` RTL: the volume as the
/// frame's memory holds it (`voxel_w`), streamed through the unit along x, y, z with the
/// contract's edge rule, checked voxel for voxel against the model's three passes (what
/// `FrameJob` renders) before the frame runs. Prints what ran and its cycles; refused when the
/// filtered volumes differ. Nothing to do without a pre-filter.
fn prepass_on_the_rtl(
    scene: &Scene,
    origin: &str,
    raw: &cube5_model::volume::Volume,
    voxel_w: u32,
    seed: u32,
) -> Result<()> {
    let kernel = scene.prefilter();
    let vol = at_voxel_width(raw, voxel_w)?;
    let Some(model) = cube5_model::prefilter::apply(&vol, kernel)? else {
        return Ok(());
    };
    let t = Instant::now();
    let got = cube5_tb::prefilter::run(&vol, kernel, seed)
        .map_err(|e| anyhow!("{origin}: volume.prefilter: {e}"))?
        .ok_or_else(|| anyhow!("{origin}: volume.prefilter: no pre-pass on the RTL"))?;
    let secs = t.elapsed().as_secs_f64();
    let want = &model.volume.data;
    if let Some(i) = (0..want.len()).find(|&i| got.data[i] != i64::from(want[i])) {
        let [nx, ny, _] = vol.dims;
        bail!(
            "{origin}: volume.prefilter: the RTL pre-pass ({}) differs from the model at voxel ({}, {}, {}): rtl {} model {} (the frame does not run)",
            got.variant,
            i % nx,
            (i / nx) % ny,
            i / (nx * ny),
            got.data[i],
            want[i]
        );
    }
    say!(
        "prefilter: MATCH: {} on {}, every one of the {} filtered voxels bit-exact with the model; RTL cycles {} (x {}, y {}, z {}) for {} samples, {:.3} samples/clock; contract {} cycles; simulated in {:.2} s",
        model.describe(),
        got.variant,
        want.len(),
        got.cycles(),
        got.pass_cycles[0],
        got.pass_cycles[1],
        got.pass_cycles[2],
        model.samples(),
        model.samples() as f64 / got.cycles().max(1) as f64,
        model.cycles(),
        secs
    );
    Ok(())
}

/// The base plane as an image, one pixel per coxel.
fn base_plane_png(bp: &BasePlane, cfg: &ComposConfig) -> image::RgbImage {
    ImageF64 {
        width: bp.width as u32,
        height: bp.height as u32,
        rgb: bp.rgb(cfg),
    }
    .to_rgb8()
}

/// The cost side of the trade in cycles: one frame of `scene` on `cube5_frame` at P = 1, 4, 8,
/// measured on the RTL with and without empty-slice skipping, each image compared with the model
/// bit for bit. A Markdown section for `cube5 tradeoff`.
pub fn frame_cost_section(scene: &Scene) -> Result<String> {
    let mut md = String::from("## Cycles per frame (`cube5_frame`, RTL)\n\n");
    let why = not_expressible(scene);
    if !why.is_empty() {
        md.push_str(&format!(
            "cube5_frame cannot render this scene: {}.\n\n",
            why.join("; ")
        ));
        return Ok(md);
    }
    md.push_str(
        "The baseline scene's volume and view on the verified frame configurations (default widths): \
         cycles from the render command to the last base-plane pixel, measured in simulation; the \
         limit is one sample per clock per pipeline. Independent of the width knobs above (they \
         change area and error, not the schedule); the sample rate of the slice-order machine is \
         one sample per voxel of every slice. Every frame's image equals the model's, bit for bit.\n\n",
    );
    md.push_str("| P | samples | cycles/frame | samples/clock/pipeline | skipping empty slices: cycles/frame | ratio |\n");
    md.push_str("|--:|--------:|-------------:|-----------------------:|------------------------------------:|------:|\n");
    let raw = scene.build_volume()?;
    for rtl in FrameRtl::pipeline_counts()
        .into_iter()
        .filter_map(FrameRtl::with_pipelines)
    {
        let job = match FrameJob::new(scene, &raw, rtl.cfg, rtl.p) {
            Ok(job) => job,
            Err(why) => {
                md.push_str(&format!("| {} | | n/a: {why} | | | |\n", rtl.p));
                continue;
            }
        };
        if let Err(why) = rtl.check_volume(&job.seen) {
            md.push_str(&format!("| {} | | n/a: {why} | | | |\n", rtl.p));
            continue;
        }
        let e = Expected::from_job(&job, job.render(), "scene");
        let mut bench = FrameBench::new(rtl, &job.seen, &job.lut, 1)?;
        let full = bench.check(&e, &Traffic::full_speed(), 1)?;
        bench.skip_empty = true;
        let cut = bench.check(&e, &Traffic::full_speed(), 1)?;
        let samples = e.params.samples() as u64;
        md.push_str(&format!(
            "| {} | {samples} | {} | {:.3} | {} | {:.3} |\n",
            rtl.p,
            full.cycles,
            samples as f64 / (full.cycles as f64 * rtl.p as f64),
            cut.cycles,
            cut.cycles as f64 / full.cycles as f64
        ));
    }
    md.push_str(
        "\nWhere the cycles go (docs/frame-rtl.md, *Cycle budget*): one beat of P samples per clock, \
         the windows' flush, the pipeline latency, and the read-out of the base plane at one pixel \
         per clock, which does not shrink with P.\n",
    );
    Ok(md)
}

/// One ER-perspective frame of `scene` (`run.renderer = "er"`) on `cube5_er` and on the model
/// (`ErJob::render`, what `cube5 render` computes), compared coxel by coxel; prints the samples
/// per slice against the N^2 .. 4N^2 bound and the clocks, writes both base planes. Refused,
/// naming the build, when no built cube5_er configuration holds the scene.
pub fn cosim_er(scene: &Scene, origin: &str, out_dir: &Path, seed: u32) -> Result<bool> {
    use cube5_model::er_perspective::ErJob;
    use cube5_tb::er::{er_variants, first_difference, ErBench};
    let raw = scene.build_volume()?;
    let params = scene.render_params();
    let tf = scene.transfer_function();
    let want = frame_config(scene)?;
    let mut refusals = Vec::new();
    let mut chosen = None;
    for v in er_variants().into_iter().filter(|v| v.built) {
        let bench = ErBench::new(v, seed)?;
        if (bench.cfg.trilin, bench.cfg.shader, bench.cfg.compos)
            != (want.trilin, want.shader, want.compos)
        {
            refusals.push(format!("{v}: other unit widths than the scene's"));
            continue;
        }
        let job = ErJob::new(&raw, &tf, &params, &bench.cfg.frame_config(), scene.er())?;
        match bench.check(&job) {
            Ok(()) => {
                chosen = Some((bench, job));
                break;
            }
            Err(e) => refusals.push(e),
        }
    }
    let Some((mut bench, job)) = chosen else {
        bail!(
            "{origin}: no built cube5_er configuration runs this scene ({}); `CUBE5_TOPS=cube5_er` builds them",
            if refusals.is_empty() {
                "none built".to_string()
            } else {
                refusals.join("; ")
            }
        );
    };
    std::fs::create_dir_all(out_dir)
        .with_context(|| format!("output directory {}", out_dir.display()))?;
    let v = bench.variant();
    say!(
        "cosim: {origin}: ER-perspective ({}), {} on {v}",
        scene.er().describe(),
        scene.render.mode.name()
    );
    let t = Instant::now();
    let want = job.render();
    let model_secs = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let load = bench.load(&job)?;
    let got = bench.frame(&job, &Traffic::full_speed())?;
    let sim_secs = t.elapsed().as_secs_f64();
    let st = &want.stats;
    let matched = match first_difference(&got, &want) {
        None => {
            say!(
                "MATCH: {} x {} base-plane coxels, every field bit-exact",
                want.extent.width(),
                want.extent.height()
            );
            true
        }
        Some(d) => {
            say!("MISMATCH: {d}");
            false
        }
    };
    say!(
        "plan: ER-perspective model (cube5_er RTL): {}",
        st.describe()
    );
    say!(
        "cycles: volume load {load}, sweep {} ({:.2} clocks per sample; {} samples), frame {} with read-out; simulated {:.2} Mcycles/s; model {:.2} s",
        got.sweep_cycles,
        got.sweep_cycles as f64 / st.samples.max(1) as f64,
        st.samples,
        got.cycles,
        (load + got.cycles) as f64 / sim_secs / 1e6,
        model_secs
    );
    let cfg = bench.cfg.compos;
    let (w, h) = (want.extent.width(), want.extent.height());
    let mut rtl_coxels = got.coxels.clone();
    rtl_coxels.resize(w * h, Coxel::empty(&cfg));
    for (who, coxels) in [("model", &want.coxels), ("rtl", &rtl_coxels)] {
        let bp = BasePlane {
            width: w,
            height: h,
            coxels: coxels.clone(),
        };
        let path = out_dir.join(format!("{who}-er-base-plane.png"));
        write_png_atomically(&base_plane_png(&bp, &cfg), &path)?;
        say!("wrote {}", path.display());
    }
    Ok(matched)
}
