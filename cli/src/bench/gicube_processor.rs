//! Benchmark of the GI-Cube block processor (`gicube_processor`) for direct volume rendering and
//! for GI: samples per clock per processor, cache hit rate, queue occupancy and overflow rate.
//! Every built configuration renders its frames on the RTL (`cosim_gi::GiBench`, a DDR-like
//! memory), each pass bit-exact with the model (every pixel, count, burst and, after a lighting
//! pass, memory word); a configuration not built in this cube5 (the `full` 32^3 and 64^3 lines
//! outside `CUBE5_FULL=1`) gets the model's figures at its configuration, without clocks (its
//! counts are the RTL's: the contract's cycle order, docs/numerics/gicube_processor.md, *The
//! ring*).

use crate::cosim_gi::{overflow_rate, GiBench, MemoryKind, PassRun};
use anyhow::{bail, Result};
use cube5_model::camera::Camera;
use cube5_model::phantom::{head_phantom, sphere_floor_phantom};
use cube5_model::transfer::TransferFunction;
use cube5_model::unit::UnitConfig;
use cube5_model::units::gicube_processor::{
    shadow_scene, GiLight, GiMode, Processor, ProcessorCounts, ProcessorFrame, ProcessorRtlConfig,
    Projection,
};
use cube5_tb::variants::Netlist;
use cube5_tb::{Variant, VARIANTS};

pub const TOP: &str = ProcessorRtlConfig::TOP;

/// A view from azimuth `a`, elevation `e` (degrees), `px` pixels a side.
fn camera(vol: &cube5_model::volume::Volume, a: f64, e: f64, px: u32) -> Camera {
    let (a, e) = (a.to_radians(), e.to_radians());
    let dir = [-e.cos() * a.cos(), -e.cos() * a.sin(), -e.sin()];
    Camera::new(dir.into(), vol.dims, vol.spacing, px, px)
}

/// A table row from the model's counts and, when the RTL ran, its clocks and verdict.
fn row(name: &str, what: &str, c: &ProcessorCounts, rtl: Option<&PassRun>) {
    let (clocks, per_clock, exact) = match rtl {
        Some(r) => (
            r.rtl.clocks.to_string(),
            format!("{:.4}", r.samples_per_clock()),
            if r.differences.is_empty() {
                "yes".to_string()
            } else {
                format!("NO: {}", r.differences.join("; "))
            },
        ),
        None => ("-".into(), "-".into(), "model only (not built)".into()),
    };
    println!(
        "| {name} | {what} | {} | {} ({:.1} %) | {} | {} | {} | {:.3} | {clocks} | {per_clock} | {:.4} | {:.1} | {} | {exact} |",
        c.rays_in,
        c.rays_overflowed,
        overflow_rate(c),
        c.samples,
        c.leaps,
        c.cycles,
        c.samples as f64 / c.cycles.max(1) as f64,
        c.cache_hit_rate(),
        c.mean_occupancy(),
        c.max_queue
    );
}

/// One pass: on the RTL when `bench` is given, else the model alone (`model`).
fn pass(
    name: &str,
    what: &str,
    bench: Option<&mut GiBench>,
    run: impl FnOnce(&mut GiBench) -> Result<PassRun>,
    model: impl FnOnce() -> Result<ProcessorFrame>,
) -> Result<()> {
    match bench {
        Some(b) => {
            let r = run(b)?;
            row(name, what, &r.model.counts, Some(&r));
            if !r.differences.is_empty() {
                bail!("{name} {what}: the RTL differs from the model");
            }
        }
        None => row(name, what, &model()?.counts, None),
    }
    Ok(())
}

fn one(v: &'static Variant, rtl: ProcessorRtlConfig) -> Result<()> {
    let n = rtl.side() as usize;
    let name = v.config;
    let open = |proc: &Processor| -> Result<Option<GiBench>> {
        Ok(if v.built {
            Some(GiBench::new(v, rtl, proc, MemoryKind::Ddr, 1)?)
        } else {
            None
        })
    };
    if rtl.light == 0 {
        let vol = head_phantom(n, rtl.voxel_w)?;
        let proc = Processor::new(
            rtl.processor_config(),
            &vol,
            &TransferFunction::head_default(),
        )?;
        let cam = camera(&vol, 65.0, 20.0, rtl.side());
        let mut bench = open(&proc)?;
        for (what, proj) in [
            ("DVR, head, parallel", Projection::Parallel),
            (
                "DVR, head, perspective 30",
                Projection::Perspective { fov_deg: 30.0 },
            ),
        ] {
            pass(
                name,
                what,
                bench.as_mut(),
                |b| b.render(&proc, &cam, proj),
                || Ok(proc.render(&cam, proj)?),
            )?;
        }
        return Ok(());
    }
    let (_, tf, low) = shadow_scene(n)?;
    let vol = sphere_floor_phantom(n, rtl.voxel_w)?;
    let mut lights = vec![("GI low albedo", low)];
    if rtl.scatter == 1 {
        let high = GiLight {
            mode: GiMode::HighAlbedo {
                albedo: 0.8,
                lifetime: 8,
            },
            ..low
        };
        lights.push(("GI high albedo 0.8", high));
    }
    for (what, light) in lights {
        let mut proc = Processor::new(rtl.processor_config(), &vol, &tf)?;
        let mut bench = open(&proc)?;
        let cam = camera(&vol, 30.0, 25.0, rtl.side());
        let lighting = format!("{what}, lighting pass ({}^2 rays)", light.grid);
        match bench.as_mut() {
            Some(b) => {
                let r = b.light(&mut proc, &light)?;
                row(name, &lighting, &r.model.counts, Some(&r));
                if !r.differences.is_empty() {
                    bail!("{name} {lighting}: the RTL differs from the model");
                }
            }
            None => row(name, &lighting, &proc.light(&light)?.counts, None),
        }
        pass(
            name,
            &format!("{what}, rendering pass (lit)"),
            bench.as_mut(),
            |b| b.render(&proc, &cam, Projection::Parallel),
            || Ok(proc.render(&cam, Projection::Parallel)?),
        )?;
    }
    Ok(())
}

pub fn run(_items: usize) -> Result<()> {
    println!("Whole frames, not items (`--items` does not apply): the head phantom (azimuth 65,");
    println!("elevation 20) for direct volume rendering, the shadow scene (`shadow_scene(N)`, its");
    println!(
        "light; rendering pass azimuth 30, elevation 25) for GI, N x N pixels. Built lines run"
    );
    println!(
        "on the RTL against a DDR-like memory (latency 100-120, 12 bytes per cycle), every pass"
    );
    println!("bit-exact with the model; the others are the model at the line's configuration (its");
    println!("counts are the RTL's). Overflow rate: rays returned to the host / rays taken; queue");
    println!(
        "occupancy: rays held in all queues, mean over processor cycles (the model's count).\n"
    );
    println!("| config | run | rays in | overflowed (rate) | samples | leaps | processor cycles | samples/cycle | clocks | samples/clock | cache hit rate | mean queue occupancy | max queue | RTL exact |");
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    for v in VARIANTS
        .iter()
        .filter(|v| v.top == TOP && v.netlist == Netlist::Rtl)
    {
        one(v, v.config()?)?;
    }
    Ok(())
}
