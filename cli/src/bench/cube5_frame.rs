//! Benchmark of cube5_frame, the slice-order machine: cycles per frame, samples per clock per
//! pipeline against the one-sample-per-clock limit, where the cycles go, simulated cycles per
//! second, and the golden model's speed on the same frames (docs/frame-rtl.md, "Cycle budget").
//! The frames are driven and checked by `cube5_tb::frame`; 64^3 images are compared bit for bit.

use anyhow::{anyhow, Result};
use cube5_model::phantom::head_phantom;
use cube5_model::transfer::TransferFunction;
use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_frame::{
    frame_phong, render_base_plane_reference, render_base_plane_stats, FrameConfig, FrameMode,
    FrameSetup, FrameUnits, SweepStats,
};
use cube5_model::units::cube5_skewmem::BlockLut;
use cube5_model::volume::Volume;
use cube5_tb::frame::{as_seen, sparse_scene, Expected, FrameBench, FrameRtl, Look, Render};
use cube5_tb::rtl::Traffic;
use std::rc::Rc;
use std::time::Instant;

pub const TOP: &str = FrameConfig::TOP;

/// One measured frame.
struct Row {
    config: &'static str,
    p: usize,
    n: usize,
    samples: u64,
    cycles: u64,
    beats: u64,
    flush: u64,
    setup_pipe: u64,
    readout: u64,
    sim_secs: f64,
    load_secs: f64,
    model_secs: f64,
    checked: bool,
}

fn measure(rtl: FrameRtl, vol: &Volume, view: [f64; 3], check: bool) -> Result<Row> {
    let n = vol.dims[0];
    let lut = BlockLut::identity(vol.dims, rtl.block as usize)?;
    let seen = Rc::new(as_seen(vol, &lut)?);
    let t = Instant::now();
    let e = Expected::new(
        &rtl,
        &seen,
        "oblique",
        view,
        Render::Composite,
        &Look::default(),
    )?;
    let model_secs = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut bench = FrameBench::new(rtl, vol, &lut, 1)?;
    bench.load(&e)?;
    let load_secs = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let (cycles, sweep) = if check {
        let st = bench.render_and_compare(&e, &Traffic::full_speed(), 1)?;
        (st.cycles, u64::from(st.sweep))
    } else {
        let got = bench.render(&e, &Traffic::full_speed())?;
        match got.pixels.first() {
            Some(first) if got.pixels.len() == e.w * e.h => (got.cycles, u64::from(first.cycles)),
            _ => {
                return Err(anyhow!(
                    "{}: {} of {} pixels",
                    rtl.variant,
                    got.pixels.len(),
                    e.w * e.h
                ))
            }
        }
    };
    let sim_secs = t.elapsed().as_secs_f64();
    let params = e.params;
    let samples = params.samples() as u64;
    let p = rtl.p as u64;
    let (nbr, nbs) = (
        (params.ni / rtl.p) as u64,
        (params.ni * params.nj / rtl.p) as u64,
    );
    let beats = samples / p;
    let flush = nbs + 2 * nbr + 2;
    Ok(Row {
        config: rtl.variant.config,
        p: rtl.p,
        n,
        samples,
        cycles,
        beats,
        flush,
        setup_pipe: sweep - beats - flush,
        readout: cycles - sweep,
        sim_secs,
        load_secs,
        model_secs,
        checked: check,
    })
}

/// `n_items` bounds the volumes: 128^3 frames (2.1 M samples each) run when `n_items >= 100_000`.
/// Every configuration that holds the volume (edge, voxel width) renders it.
pub fn run(n_items: usize) -> Result<()> {
    let sizes: Vec<usize> = if n_items >= 100_000 {
        vec![64, 128]
    } else {
        vec![64]
    };
    let view = [-0.37, 0.81, -1.0];
    let all = FrameRtl::all();
    let volumes = sizes
        .iter()
        .map(|&n| head_phantom(n, 12))
        .collect::<Result<Vec<Volume>, _>>()?;
    // The frame model builds the default unit widths only.
    let holds =
        |rtl: &FrameRtl, vol: &Volume| rtl.default_widths() && rtl.check_volume(vol).is_ok();
    let measured: Vec<&str> = all
        .iter()
        .filter(|r| volumes.iter().any(|vol| holds(r, vol)))
        .map(|r| r.variant.config)
        .collect();
    println!(
        "One composite frame (head phantom, 12-bit voxels, view (-0.37, 0.81, -1), all blocks \
         present) per row, on every configuration that holds the volume ({}). Cycles from the \
         command to the last pixel; samples/clock/pipeline = samples / (cycles * P), the limit is \
         1.0. 64^3 images are checked against the model bit for bit.\n",
        measured.join(", ")
    );
    println!(
        "| config | P | volume | samples | cycles/frame | samples/clock/pipeline | without read-out | sweep beats | flush | set-up + pipeline | read-out | sim cycles/s | model samples/s | volume load (s) |"
    );
    println!(
        "|--------|--:|--------|--------:|-------------:|-----------------------:|-----------------:|------------:|------:|------------------:|---------:|-------------:|----------------:|----------------:|"
    );
    for vol in &volumes {
        let n = vol.dims[0];
        for rtl in all.iter().filter(|r| holds(r, vol)) {
            let r = measure(*rtl, vol, view, n <= 64)?;
            let pp = r.p as f64;
            println!(
                "| {} | {} | {}^3 | {} | {} | {:.3} | {:.3} | {} | {} | {} | {} | {:.2e} | {:.2e}{} | {:.1} |",
                r.config,
                r.p,
                r.n,
                r.samples,
                r.cycles,
                r.samples as f64 / (r.cycles as f64 * pp),
                r.samples as f64 / ((r.cycles - r.readout) as f64 * pp),
                r.beats,
                r.flush,
                r.setup_pipe,
                r.readout,
                r.cycles as f64 / r.sim_secs,
                r.samples as f64 / r.model_secs,
                if r.checked { " (bit-exact)" } else { "" },
                r.load_secs
            );
        }
    }
    println!();
    for rtl in all.iter().filter(|r| !measured.contains(&r.variant.config)) {
        let why = match volumes.iter().find_map(|vol| rtl.check_volume(vol).err()) {
            Some(limit) => limit,
            None => "unit widths other than the frame model's".to_string(),
        };
        println!("Not measured: `{}` ({why}).", rtl.variant.config);
    }
    println!();
    println!(
        "Where the cycles go: `sweep beats` = samples / P (one beam per clock: the limit), `flush` = \
         ni nj / P + 2 ni / P + 2 (the voxel and sample windows' lag, docs/frame-rtl.md), `set-up + \
         pipeline` = 3 + memory, trilin, gradient, shader, buffer and compos latencies, `read-out` \
         = W H + 2 (one pixel per clock; a double-buffered compositing buffer would overlap it with \
         the next frame's sweep)."
    );
    println!();
    skipping()?;
    model_speed(n_items)?;
    Ok(())
}

/// Best wall-clock seconds of `f` over at least `runs` runs and at least `min_secs` in all.
fn best_secs<T>(runs: usize, min_secs: f64, mut f: impl FnMut() -> T) -> (f64, T) {
    let start = Instant::now();
    let mut best = f64::INFINITY;
    let mut n = 0;
    loop {
        let t = Instant::now();
        let out = f();
        best = best.min(t.elapsed().as_secs_f64());
        n += 1;
        if n >= runs && start.elapsed().as_secs_f64() >= min_secs {
            return (best, out);
        }
    }
}

/// The golden model alone: samples/s of the frame model's fast path (`render_base_plane`) at 1
/// and 2 threads, and of the per-sample reference it is tested against, on the head phantom
/// (12-bit voxels, view (-0.37, 0.81, -1), default widths), composite shaded and MIP. 256^3 runs
/// when `n_items >= 100_000`; the reference only at 128^3 and below (it takes seconds a frame).
fn model_speed(n_items: usize) -> Result<()> {
    let sizes: Vec<usize> = if n_items >= 100_000 {
        vec![128, 256]
    } else {
        vec![64, 128]
    };
    println!("### The frame model's speed (no RTL)\n");
    println!(
        "Head phantom, 12-bit voxels, view (-0.37, 0.81, -1), default widths, no early \
         termination; best wall-clock time of several frames (on a shared machine, the threads get what \
         the other jobs leave). `fast` is `render_base_plane` (the model everything uses), `reference` \
         the per-sample `render_base_plane_reference`; both give the same base plane bit for bit (model \
         test `fast_path_equals_the_reference`). Shaded: samples that went through gradient and \
         shader; without effect: samples the compositing would leave unchanged (classified only).\n"
    );
    println!("| volume | render | threads | fast ms/frame | fast samples/s | reference samples/s | speed-up | shaded | without effect | slices skipped |");
    println!("|--------|--------|--------:|--------------:|---------------:|--------------------:|---------:|-------:|---------------:|---------------:|");
    let tf = TransferFunction::head_default();
    for n in sizes {
        let vol = head_phantom(n, 12)?;
        let setup = FrameSetup::new(vol.dims, vol.spacing, [-0.37, 0.81, -1.0].into(), 4)?;
        let p = setup.params;
        let samples = p.samples() as f64;
        for mode in [FrameMode::Composite, FrameMode::Mip] {
            let units = FrameUnits::new(mode, &setup, &tf, &frame_phong(&p, &[]))?;
            for threads in [1, 2] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()?;
                let (fast, st): (f64, SweepStats) = pool
                    .install(|| best_secs(3, 1.0, || render_base_plane_stats(&p, &vol, &units).1));
                let reference = (n <= 128).then(|| {
                    pool.install(|| {
                        best_secs(1, 0.0, || render_base_plane_reference(&p, &vol, &units)).0
                    })
                });
                println!(
                    "| {n}^3 | {} | {threads} | {:.1} | {:.3e} | {} | {} | {:.1} % | {:.1} % | {} + {} |",
                    if mode == FrameMode::Mip { "MIP" } else { "composite shaded" },
                    fast * 1e3,
                    samples / fast,
                    reference.map_or("-".into(), |r| format!("{:.3e}", samples / r)),
                    reference.map_or("-".into(), |r| format!("{:.1}x", r / fast)),
                    100.0 * st.shaded as f64 / samples,
                    100.0 * st.without_effect as f64 / samples,
                    st.slices_skipped.0,
                    st.slices_skipped.1,
                );
            }
        }
    }
    println!();
    Ok(())
}

/// Empty-slice skipping on the sparse scene (64^3, data in a box inside): sweep and frame cycles
/// with and without it, P = 4, images compared bit for bit with the model's full sweep.
fn skipping() -> Result<()> {
    let rtl = FrameRtl::with_pipelines(4).ok_or_else(|| anyhow!("no P = 4 frame"))?;
    println!(
        "### Empty-slice skipping (sparse scene, P = 4: `{}`)\n",
        rtl.variant.config
    );
    println!(
        "64^3 volume with data only in [20, 44) x [14, 50) x [22, 41), blocks of 8^3; composite; \
         both frames compared with the model's full sweep, bit for bit.\n"
    );
    println!("| view | slices skipped (front + back of nk) | sweep cycles | with skipping | ratio | frame cycles | with skipping | ratio |");
    println!("|------|------------------------------------|-------------:|--------------:|------:|-------------:|--------------:|------:|");
    let vol = sparse_scene(7);
    let lut = BlockLut::from_volume(&vol, rtl.block as usize, 0)?;
    let seen = Rc::new(as_seen(&vol, &lut)?);
    let mut bench = FrameBench::new(rtl, &vol, &lut, 1)?;
    for (name, view) in [
        ("+z", [0.0, 0.0, 1.0]),
        ("-y", [0.0, -1.0, 0.0]),
        ("+x", [1.0, 0.0, 0.0]),
        ("oblique", [-0.37, 0.81, -1.0]),
    ] {
        let e = Expected::new(&rtl, &seen, name, view, Render::Composite, &Look::default())?;
        bench.skip_empty = false;
        let full = bench.check(&e, &Traffic::full_speed(), 1)?;
        bench.skip_empty = true;
        let cut = bench.check(&e, &Traffic::full_speed(), 1)?;
        println!(
            "| {name} | {} + {} of {} | {} | {} | {:.3} | {} | {} | {:.3} |",
            cut.skip.0,
            cut.skip.1,
            e.params.nk,
            full.sweep,
            cut.sweep,
            f64::from(cut.sweep) / f64::from(full.sweep),
            full.cycles,
            cut.cycles,
            cut.cycles as f64 / full.cycles as f64
        );
    }
    println!();
    Ok(())
}
