//! Co-simulation of gicube_processor (the GI-Cube block processor for direct volume rendering:
//! the queue front end, the volume cache, the sample and the step units in the ring, the volume
//! in the test bench's AXI4 memory) against the processor model `Processor::render` at the RTL's
//! ring latency and cache (docs/numerics/gicube_processor.md, *The ring*, *The volume cache*,
//! *The RTL*): whole images, every pixel, the counts (rays in, finished, overflowed, samples,
//! leaps, processor cycles, cache hits and misses) of both, and the AR bursts of the cache's
//! misses, under the subordinate's seeded random latency, gaps and bandwidth limit, its protocol
//! checker silent.
//!
//! The test bench is the host: it offers the head of its list of ray packets, holds it until the
//! RTL takes it, and appends every overflowed ray that comes back to the end of its list.

mod support;

use cube5_model::camera::Camera;
use cube5_model::phantom::sphere_floor_phantom;
use cube5_model::units::cube5_axi_rd::Burst;
use cube5_model::units::gicube_processor::{interaction_draw, ray_bits};
use cube5_model::units::gicube_processor::{
    light_rays, shadow_scene, GiLight, GiMode, Processor, ProcessorFrame, ProcessorOut,
    ProcessorRtlConfig, Projection,
};
use cube5_tb::rtl::{RtlStream, Traffic};
use cube5_tb::Variant;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::processor::{
    check_bursts, check_frame, head_scene, host_packets, load_config, open_proc, random_memory,
    round_trip_clocks, run_host, view_dir, Behaviour, Bits, Memory, RtlFrame, FAST_MEMORY,
    IDLE_AND_STALL,
};
use support::{axi, compare_bursts, configs, seed};

/// A scene: the head phantom in the RTL's processor seen from azimuth 65, elevation 20
/// (`head_scene`: with `Shade` lit and tagged), and the projection.
struct Scene {
    proc: Processor,
    cam: Camera,
    proj: Projection,
}

impl Scene {
    fn new(rtl: &ProcessorRtlConfig, px: u32, proj: Projection) -> Self {
        let (proc, cam) = head_scene(rtl, px);
        Self { proc, cam, proj }
    }

    /// The host's packets, in its order.
    fn packets(&self) -> Vec<Bits> {
        host_packets(&self.proc, &self.cam, self.proj)
    }

    /// The model's frame and the bursts of its cache's misses.
    fn model(&self) -> (ProcessorFrame, Vec<Burst>) {
        self.proc.render_cache_traced(&self.cam, self.proj).unwrap()
    }
}

/// A DDR-like channel (docs/accel.md): latency 100-120 cycles, 12 bytes per cycle.
const DDR_LIKE: Memory = Memory {
    lat: (100, 20),
    gaps: (0, 0),
    bw: (12, 1),
};

const FULL_SPEED: Behaviour = Behaviour {
    idle: 0.0,
    stall: 0.0,
};

/// One frame from reset with the host always offering and the output taken at random with
/// probability `1 - stall`, the memory as `mem` (random when `None`): every pixel, every count
/// and every AR burst equal to the model's.
fn exact_frame(
    variant: &'static Variant,
    rtl: ProcessorRtlConfig,
    px: u32,
    proj: Projection,
    mem: Option<Memory>,
    s: u64,
) -> (RtlFrame, ProcessorFrame) {
    let scene = Scene::new(&rtl, px, proj);
    let (want, bursts) = scene.model();
    let packets = scene.packets();
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let mem = mem.unwrap_or_else(|| random_memory(&mut rng, &rtl));
    let mut dut = open_proc(variant, rtl, &scene.proc, mem, s);
    let b = Behaviour {
        idle: 0.0,
        stall: if mem.lat.1 > 20 { 0.3 } else { 0.0 },
    };
    let what = format!("{variant} seed {s} ({proj:?}, {mem:?}, {b:?})");
    let got = run_host(&mut dut, &packets, (px, px), b, &mut rng, None, &what);
    check_frame(&what, &got, &want, true);
    check_bursts(variant, &rtl, &got, &bursts, s);
    (got, want)
}

/// A frame's line: rays, overflow, samples, clocks, samples per clock, hit rate.
fn frame_line(variant: &'static Variant, what: &str, got: &RtlFrame, want: &ProcessorFrame) {
    let c = &want.counts;
    eprintln!(
        "{variant} {what}: {} rays, {} in, {} overflowed, {} samples, {} leaps, {} processor cycles, {} clocks: {:.3} samples/clock, {:.2} clocks/cycle, cache hit rate {:.4} ({} lines read)",
        c.rays_made,
        c.rays_in,
        c.rays_overflowed,
        c.samples,
        c.leaps,
        c.cycles,
        got.clocks,
        c.samples as f64 / got.clocks as f64,
        got.clocks as f64 / c.cycles as f64,
        c.cache_hit_rate(),
        got.ars.len()
    );
}

/// The flush at the end of a lighting pass (`Light`): the write, then clocks until its output
/// item, the output taken at random with probability `1 - stall`; the item.
fn flush(
    dut: &mut RtlStream<ProcessorRtlConfig>,
    rtl: &ProcessorRtlConfig,
    stall: f64,
    rng: &mut ChaCha8Rng,
) -> ProcessorOut {
    let name = dut.name();
    let (a, d) = Processor::rtl_flush_write(rtl);
    dut.write_config(a, &d).unwrap();
    for _ in 0..2_000_000 {
        let traffic = Traffic {
            idle: vec![0],
            stall: vec![u8::from(rng.random_bool(stall))],
        };
        let d = dut.drive(&[], &traffic, 1, 1).unwrap();
        if let Some(o) = d.outputs.first() {
            assert!(
                o.value.flush,
                "{name}: the item after a flush is the flush's"
            );
            return o.value;
        }
    }
    panic!("{name}: the flush never came out");
}

/// The lighting pass of the GI shadow scene (a sphere over a floor, the scene's light) at the
/// RTL's side and voxel width, then its flush: every lighting ray and every count equal to the
/// model's `light`, the AR and AW bursts (the flush's write-backs included) equal to its cache's,
/// and the memory after the flush, the volume with the irradiance field above it, equal to the
/// model's word for word (the field is `irradiance()`). Then, after a reset, the rendering pass
/// lit by that field: every pixel and count. Under random memory latency, gaps on all five
/// channels, bandwidth limits and output back-pressure.
fn two_pass_gi(
    variant: &'static Variant,
    rtl: ProcessorRtlConfig,
    mode: GiMode,
    grid_div: u32,
    s: u64,
) -> ProcessorFrame {
    let n = rtl.side() as usize;
    let light = gi_light(n, mode, grid_div);
    let tf = shadow_scene(n).unwrap().1;
    let vol = sphere_floor_phantom(n, rtl.voxel_w).unwrap();
    let mut proc = Processor::new(rtl.processor_config(), &vol, &tf).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let mem = gi_memory(&mut rng, &rtl, grid_div);
    let mut dut = open_proc(variant, rtl, &proc, mem, s);
    let packets = light_packets(&proc, &light);
    let (want, trace) = proc.light_cache_traced(&light).unwrap();
    let b = Behaviour {
        idle: 0.0,
        stall: 0.3,
    };
    if rtl.scatter == 1 {
        let (a, d) = Processor::rtl_photon_write(&rtl, Some(&light));
        dut.write_config(a, &d).unwrap();
    }
    let what = format!("{variant} seed {s} lighting pass ({mode:?}, {mem:?}, {b:?})");
    let grid = (light.grid, light.grid);
    let got = run_host(&mut dut, &packets, grid, b, &mut rng, None, &what);
    check_frame(&what, &got, &want, true);
    let f = flush(&mut dut, &rtl, 0.3, &mut rng);
    assert_eq!(
        (
            u64::from(f.cache_hits),
            u64::from(f.cache_misses),
            u64::from(f.cycles)
        ),
        (
            want.counts.cache_hits,
            want.counts.cache_misses,
            want.counts.cycles
        ),
        "{variant}: the flush's counts"
    );
    let size = (rtl.data_w / 8).trailing_zeros();
    let mut ars = got.ars.clone();
    ars.extend(dut.axi_take_ar().unwrap());
    let ctx = |k| format!("the lighting pass's burst #{k}");
    let n_ar = compare_bursts(&ars, "AR", &trace.reads, size, variant, s, ctx)
        .unwrap_or_else(|e| panic!("{e}"));
    let aws = dut.axi_take_aw().unwrap();
    let n_aw = compare_bursts(&aws, "AW", &trace.writes, size, variant, s, ctx)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((n_ar, n_aw), (trace.reads.len(), trace.writes.len()));
    let c = dut.axi_counters();
    assert_eq!(
        c.protocol_errors,
        0,
        "{variant}: AXI checker: {}",
        dut.axi_first_error()
    );
    let cache = rtl.cache_config();
    let words = cache.words_of(&dut.axi_image().unwrap());
    let m = cache.max_dim as usize;
    let differ = (0..m * m * m)
        .filter(|&i| words[i] != trace.memory[i])
        .count();
    assert_eq!(
        differ, 0,
        "{variant}: {differ} memory words differ from the model's after the flush"
    );
    let field = proc.irradiance().unwrap();
    let at = |x: usize, y: usize, z: usize| words[x + m * (y + m * z)] >> 16;
    let lit = (0..n * n * n)
        .filter(|&i| {
            assert_eq!(at(i % n, (i / n) % n, i / (n * n)), u32::from(field[i]));
            field[i] > 0
        })
        .count();
    assert_eq!(
        u64::from(f.scatterings),
        want.counts.scatterings,
        "{variant}: the flush's scatterings"
    );
    eprintln!(
        "{variant} lighting pass {mode:?} ({mem:?}): {} rays, {} scattered, {} absorbed, {} samples (deposits), {} processor cycles, {} clocks: {:.3} samples/clock, hit rate {:.4}, {} lines read, {} written back (flush included); {lit} voxels lit; the field in memory equals the model's",
        want.counts.rays_made,
        want.counts.scatterings,
        want.counts.absorbed,
        want.counts.samples,
        want.counts.cycles,
        got.clocks,
        want.counts.samples as f64 / got.clocks as f64,
        want.counts.cache_hit_rate(),
        trace.reads.len(),
        trace.writes.len()
    );
    // The rendering pass from a reset (memory kept), lit by the field.
    dut.reset();
    load_config(&mut dut, &rtl, &proc);
    let px = rtl.side();
    let cam = gi_camera(&vol, px);
    let proj = Projection::Parallel;
    let (want, bursts) = proc.render_cache_traced(&cam, proj).unwrap();
    let packets = host_packets(&proc, &cam, proj);
    let what = format!("{variant} seed {s} GI rendering pass ({mode:?}, {mem:?}, {b:?})");
    let got = run_host(&mut dut, &packets, (px, px), b, &mut rng, None, &what);
    check_frame(&what, &got, &want, true);
    check_bursts(variant, &rtl, &got, &bursts, s);
    assert!(
        want.rgb.iter().any(|p| p.iter().any(|&c| c > 0)),
        "{variant}: a lit image"
    );
    frame_line(variant, &format!("GI rendering pass {mode:?}"), &got, &want);
    want
}

/// The packets of `light`'s lighting rays, as the host sends them (a high-albedo light's with
/// their lifetime and first interaction value).
fn light_packets(proc: &Processor, light: &GiLight) -> Vec<Bits> {
    let (rays, energy) = light_rays(proc.volume(), light, proc.config().host_order).unwrap();
    rays.iter()
        .map(|r| {
            let mut p = Processor::light_packet(r, energy).unwrap();
            if let GiMode::HighAlbedo { lifetime, .. } = light.mode {
                p.lifetime = lifetime;
                p.interaction = interaction_draw(ray_bits(&p));
            }
            p.to_bits().unwrap()
        })
        .collect()
}

/// The shadow scene's light at side `n` in `mode`, its grid divided by `grid_div` (fewer lighting
/// rays, each carrying more energy: a shorter pass for CI).
fn gi_light(n: usize, mode: GiMode, grid_div: u32) -> GiLight {
    let (_, _, light) = shadow_scene(n).unwrap();
    GiLight {
        mode,
        grid: light.grid / grid_div,
        ..light
    }
}

/// The memory of a GI pass: random (`random_memory`), its latency 10-40 for a short pass
/// (`grid_div > 1`: CI).
fn gi_memory(rng: &mut ChaCha8Rng, rtl: &ProcessorRtlConfig, grid_div: u32) -> Memory {
    let m = random_memory(rng, rtl);
    if grid_div > 1 {
        Memory { lat: (10, 30), ..m }
    } else {
        m
    }
}

/// High albedo (albedo 0.8, up to 8 bounces, the example scene's).
const HIGH_ALBEDO: GiMode = GiMode::HighAlbedo {
    albedo: 0.8,
    lifetime: 8,
};

/// The GI scene's camera: azimuth 30, elevation 25 (the floor and the sphere's shadow in view).
fn gi_camera(vol: &cube5_model::volume::Volume, px: u32) -> Camera {
    let dir = view_dir(30.0, 25.0);
    Camera::new(dir.into(), vol.dims, vol.spacing, px, px)
}

/// The two GI passes on the `Light` configurations at 16^3 (CI).
#[test]
fn gi_lighting_pass_leaves_the_models_field_in_memory_and_lights_the_image() {
    // The Scatter lines' low-albedo pass: in the high-albedo test (a shorter pass).
    for (variant, rtl) in ci_configs().into_iter().filter(|(_, c)| c.light == 1) {
        two_pass_gi(variant, rtl, GiMode::LowAlbedo, 1, seed(1970));
    }
}

/// High albedo (`Scatter = 1`): the photons' lighting pass, whose rays scatter in the ring
/// (gicube_scatter), every photon, count (scatterings too), burst and memory word after the
/// flush equal to the model's, then the rendering pass lit by that field; the same for a
/// low-albedo pass (photons off), whose image differs. The lighting grid is halved (a quarter
/// of the rays) to keep the passes short.
#[test]
fn high_albedo_photons_scatter_in_the_ring_like_the_model() {
    for (variant, rtl) in scatter_configs() {
        let hi = two_pass_gi(variant, rtl, HIGH_ALBEDO, 2, seed(1980));
        let lo = two_pass_gi(variant, rtl, GiMode::LowAlbedo, 2, seed(1981));
        assert_ne!(hi.rgb, lo.rgb, "{variant}: high albedo changes the image");
        // GICUBE_GI_PNG=<file>: the two images (equal to the RTL's), low albedo left, each pixel
        // 8 x 8 (docs/img/gicube-processor-gi-albedo.png).
        if let Ok(path) = std::env::var("GICUBE_GI_PNG") {
            save_side_by_side(&path, &lo, &hi, 8);
        }
    }
}

/// A PNG of two frames of one size side by side, `left` on the left, each pixel `k x k`.
fn save_side_by_side(path: &str, left: &ProcessorFrame, right: &ProcessorFrame, k: u32) {
    let (w, h) = (left.width, left.height);
    let (l, r) = (left.to_f64(), right.to_f64());
    let rgb = (0..h * k)
        .flat_map(|y| (0..2 * w * k).map(move |x| (x / k, y / k)))
        .map(|(x, y)| {
            let f = if x < w { &l } else { &r };
            f[(y * w + x % w) as usize]
        })
        .collect();
    let img = cube5_model::render::ImageF64 {
        width: 2 * w * k,
        height: h * k,
        rgb,
    };
    img.to_rgb8().save(path).unwrap();
}

/// A reset in the middle of a high-albedo lighting pass (photons and bursts in flight, some
/// scattered): the memory is loaded again, and the next pass is exact, photons, counts,
/// scatterings and bursts.
#[test]
fn mid_pass_reset_then_an_exact_high_albedo_pass() {
    for (variant, rtl) in scatter_configs() {
        let n = rtl.side() as usize;
        let light = gi_light(n, HIGH_ALBEDO, 2);
        let tf = shadow_scene(n).unwrap().1;
        let vol = sphere_floor_phantom(n, rtl.voxel_w).unwrap();
        let mut proc = Processor::new(rtl.processor_config(), &vol, &tf).unwrap();
        let img = proc.rtl_memory().unwrap().unwrap();
        let s = seed(1985);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let mem = gi_memory(&mut rng, &rtl, 2);
        let mut dut = open_proc(variant, rtl, &proc, mem, s);
        let packets = light_packets(&proc, &light);
        let (want, trace) = proc.light_cache_traced(&light).unwrap();
        let photons = Processor::rtl_photon_write(&rtl, Some(&light));
        dut.write_config(photons.0, &photons.1).unwrap();
        let b = Behaviour {
            idle: 0.2,
            stall: 0.2,
        };
        let what = format!("{variant} seed {s} high albedo ({mem:?}, {b:?})");
        let grid = (light.grid, light.grid);
        let cut = Some(60 * want.counts.cycles);
        let part = run_host(&mut dut, &packets, grid, b, &mut rng, cut, &what);
        assert!(
            part.last.scatterings > 0 && u64::from(part.last.rays_finished) < want.counts.rays_made,
            "{variant}: the reset falls mid-pass, after some scatterings ({:?})",
            part.last
        );
        let dropped = axi::reset_leaves_nothing_in_flight(&mut dut, variant, s, false).unwrap();
        assert_eq!(
            dut.axi_wr_counters().in_flight,
            0,
            "{variant}: no write burst in flight after the reset"
        );
        dut.axi_take_aw().unwrap();
        dut.axi_load(img.base, &img.bytes).unwrap();
        load_config(&mut dut, &rtl, &proc);
        dut.write_config(photons.0, &photons.1).unwrap();
        let what =
            format!("{variant} seed {s} high albedo after a reset ({mem:?}, {FULL_SPEED:?})");
        let got = run_host(&mut dut, &packets, grid, FULL_SPEED, &mut rng, None, &what);
        check_frame(&what, &got, &want, true);
        let size = (rtl.data_w / 8).trailing_zeros();
        compare_bursts(&got.ars, "AR", &trace.reads, size, variant, s, |k| {
            format!("burst #{k}")
        })
        .unwrap_or_else(|e| panic!("{e}"));
        eprintln!(
            "{variant}: reset after {} clocks, {} of {} photons finished, {} scattered, {} bursts dropped; then {} photons, {} scatterings, exact",
            part.clocks,
            part.last.rays_finished,
            want.counts.rays_made,
            part.last.scatterings,
            dropped,
            want.counts.rays_made,
            got.last.scatterings
        );
    }
}

/// The two GI passes at 32^3 and 64^3 (the `full` `Light` configurations).
#[test]
#[ignore = "sim-full: the two GI passes at 32^3 and 64^3 (the `full` variants)"]
fn large_gi_passes_equal_the_model() {
    for (variant, rtl) in configs::<ProcessorRtlConfig>() {
        if rtl.light == 1 && rtl.side() > 16 {
            two_pass_gi(variant, rtl, GiMode::LowAlbedo, 1, seed(1975));
        }
    }
}

/// The CI configurations (16^3) without the photon path (the `Scatter` lines' rendering rays
/// are verified by their GI tests' rendering passes).
fn ci_configs() -> Vec<(&'static Variant, ProcessorRtlConfig)> {
    configs::<ProcessorRtlConfig>()
        .into_iter()
        .filter(|(_, c)| c.side() <= 16 && c.scatter == 0)
        .collect()
}

/// The CI configurations with the photon path (`Scatter = 1`).
fn scatter_configs() -> Vec<(&'static Variant, ProcessorRtlConfig)> {
    configs::<ProcessorRtlConfig>()
        .into_iter()
        .filter(|(_, c)| c.side() <= 16 && c.scatter == 1)
        .collect()
}

/// Parallel and perspective frames of `px = N` (`exact_frame`), each with random memory (seed
/// `seed(s0)`) and a DDR-like one (`seed(s0 + 1)`), and their lines.
fn projections_and_memories(variant: &'static Variant, rtl: ProcessorRtlConfig, s0: u64) {
    let px = rtl.side();
    for proj in [
        Projection::Parallel,
        Projection::Perspective { fov_deg: 30.0 },
    ] {
        for (k, mem) in [None, Some(DDR_LIKE)].into_iter().enumerate() {
            let (got, want) = exact_frame(variant, rtl, px, proj, mem, seed(s0 + k as u64));
            let what = if mem.is_some() {
                "DDR-like"
            } else {
                "random memory"
            };
            frame_line(variant, &format!("{proj:?}, {what}"), &got, &want);
        }
    }
}

/// Parallel and perspective frames under random memory latency (10-200), gaps, bandwidth limits
/// and output back-pressure, then with a DDR-like memory at full speed (the figures of
/// docs/measurements.md).
#[test]
fn parallel_and_perspective_frames_equal_the_model_with_every_count() {
    for (variant, rtl) in ci_configs() {
        projections_and_memories(variant, rtl, 1900);
    }
}

/// Queues of a few rays against a frame of many: rays overflow to the host, come back, and none
/// is lost (every pixel once, rays in = finished + overflowed, equal to the model's).
#[test]
fn forced_overflow_loses_no_ray() {
    let (variant, rtl) = ci_configs()
        .into_iter()
        .min_by_key(|(_, c)| c.queue_len << c.queue_w())
        .unwrap();
    let px = 2 * rtl.side();
    let (got, want) = exact_frame(variant, rtl, px, Projection::Parallel, None, seed(1910));
    assert!(
        got.last.rays_overflowed > 0 && want.counts.rays_overflowed > 0,
        "{variant}: the frame overflows ({:?})",
        got.last
    );
    eprintln!(
        "{variant}: {} rays through {} queues of {}: {} overflowed and came back, {} outputs",
        want.counts.rays_made,
        1u32 << rtl.queue_w(),
        rtl.queue_len,
        got.last.rays_overflowed,
        got.outputs
    );
}

/// Shading and jitter (`Shade = 1`, `Jitter = 1`): the frames of the tests above are the
/// model's bit for bit; here the shaded, jittered image differs from the same processor's
/// without them (the map and the tags light and colour it). `GICUBE_SHADE_PNG=<file>` writes the
/// model's unshaded image (left) and the RTL's shaded, jittered one (right), `4 N` pixels a side
/// (docs/img/gicube-processor-shaded.png).
#[test]
fn shaded_jittered_frame_is_lit_and_equals_the_model() {
    for (variant, rtl) in ci_configs().into_iter().filter(|(_, c)| c.shade == 1) {
        let png = std::env::var("GICUBE_SHADE_PNG").ok();
        let px = if png.is_some() { 4 } else { 1 } * rtl.side();
        let proj = Projection::Perspective { fov_deg: 30.0 };
        let (got, want) = exact_frame(variant, rtl, px, proj, None, seed(1915));
        frame_line(variant, "shaded, jittered", &got, &want);
        let plain = ProcessorRtlConfig {
            shade: 0,
            tag_w: 0,
            jitter: 0,
            ..rtl
        };
        let (flat, _) = Scene::new(&plain, px, proj).model();
        let differ = want
            .rgb
            .iter()
            .zip(&flat.rgb)
            .filter(|(a, b)| a != b)
            .count();
        let rays = want.counts.rays_made as usize;
        eprintln!("{variant}: {differ} of {rays} rays' pixels differ from the unshaded image");
        assert!(
            differ * 4 > rays,
            "{variant}: shading changes the image ({differ} of {rays} rays' pixels)"
        );
        if let Some(path) = png {
            save_side_by_side(&path, &flat, &want, 2);
        }
    }
}

/// The host idle and the output stalled at random: the image is exact and no ray is lost (the
/// stalls alone keep the model's cycle order, so with the host never idle every count is equal).
#[test]
fn idle_host_and_stalled_output_keep_the_image() {
    for (variant, rtl) in ci_configs() {
        let px = rtl.side();
        let scene = Scene::new(&rtl, px, Projection::Perspective { fov_deg: 30.0 });
        let (want, _) = scene.model();
        let packets = scene.packets();
        let s = seed(1920);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let mem = random_memory(&mut rng, &rtl);
        let mut dut = open_proc(variant, rtl, &scene.proc, mem, s);
        for (b, exact) in IDLE_AND_STALL {
            dut.reset();
            let what = format!("{variant} seed {s} idle/stall ({mem:?}, {b:?})");
            let got = run_host(&mut dut, &packets, (px, px), b, &mut rng, None, &what);
            check_frame(&what, &got, &want, exact);
        }
    }
}

/// A reset in the middle of a frame (after three clocks per processor cycle of the whole frame: a
/// cycle takes at least five) drops the rays in the processor and the cache's bursts in flight
/// (the subordinate is reset with it); the tables, flags and memory survive it, and the next
/// frame is exact, counts, cache and bursts and all.
#[test]
fn mid_frame_reset_then_an_exact_frame() {
    for (variant, rtl) in ci_configs() {
        let px = rtl.side();
        let scene = Scene::new(&rtl, px, Projection::Parallel);
        let (want, bursts) = scene.model();
        let packets = scene.packets();
        let s = seed(1930);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let mem = random_memory(&mut rng, &rtl);
        let mut dut = open_proc(variant, rtl, &scene.proc, mem, s);
        let b = Behaviour {
            idle: 0.2,
            stall: 0.2,
        };
        let what = format!("{variant} seed {s} before a reset ({mem:?}, {b:?})");
        let cut = Some(3 * want.counts.cycles);
        let part = run_host(&mut dut, &packets, (px, px), b, &mut rng, cut, &what);
        assert!(
            part.outputs > 0 && (part.last.rays_finished as u64) < want.counts.rays_made,
            "{variant}: the reset falls mid-frame"
        );
        let dropped = axi::reset_leaves_nothing_in_flight(&mut dut, variant, s, false).unwrap();
        eprintln!(
            "{variant}: reset after {} clocks, {} of {} rays finished, {} bursts in flight dropped",
            part.clocks, part.last.rays_finished, want.counts.rays_made, dropped
        );
        let b = FULL_SPEED;
        let what = format!("{variant} seed {s} after a reset ({mem:?}, {b:?})");
        let got = run_host(&mut dut, &packets, (px, px), b, &mut rng, None, &what);
        check_frame(&what, &got, &want, true);
        check_bursts(variant, &rtl, &got, &bursts, s);
    }
}

/// A model with another ring latency gives the same image but other counts (the scoreboard of
/// the counts bites).
#[test]
fn a_model_with_another_ring_latency_counts_other_cycles() {
    let (variant, rtl) = ci_configs()[0];
    let px = rtl.side();
    let scene = Scene::new(&rtl, px, Projection::Parallel);
    let packets = scene.packets();
    let other = ProcessorRtlConfig {
        ring_lat: rtl.ring_lat + 1,
        ..rtl
    };
    let (want, _) = Scene::new(&other, px, Projection::Parallel).model();
    let s = seed(1940);
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let mem = random_memory(&mut rng, &rtl);
    let mut dut = open_proc(variant, rtl, &scene.proc, mem, s);
    let b = FULL_SPEED;
    let what = format!("{variant} seed {s} other latency: image ({mem:?}, {b:?})");
    let got = run_host(&mut dut, &packets, (px, px), b, &mut rng, None, &what);
    check_frame(&what, &got, &want, false);
    assert_ne!(
        u64::from(got.last.cycles),
        want.counts.cycles,
        "{variant}: a ring of {} cycles counts other cycles",
        other.ring_lat
    );
}

#[test]
#[ignore = "sim-full: 32^3 and 64^3 frames (the `full` variants), parallel and perspective"]
fn large_frames_equal_the_model_with_every_count() {
    for (variant, rtl) in configs::<ProcessorRtlConfig>() {
        if rtl.side() <= 16 || rtl.light == 1 {
            continue;
        }
        projections_and_memories(variant, rtl, 1950);
    }
}

/// The gate-level netlist (Yosys) of the tiny configuration renders an exact frame, counts and
/// all.
#[test]
#[ignore = "sim-full: the gate-level netlist is a `full` build (minutes of Yosys and Verilator)"]
fn gate_level_netlist_renders_an_exact_frame() {
    for (variant, rtl) in support::gate_configs::<ProcessorRtlConfig>() {
        let px = 2 * rtl.side();
        let (got, want) = exact_frame(variant, rtl, px, Projection::Parallel, None, seed(1960));
        eprintln!(
            "{variant}: {} rays, {} overflowed, {} samples in {} clocks",
            want.counts.rays_made, want.counts.rays_overflowed, want.counts.samples, got.clocks
        );
    }
}

/// The gate-level netlists of the `Light` configurations without the photon path (`b2v2l1`): a
/// short lighting pass (the shadow scene's grid halved: a quarter of its rays, the fewest its
/// energy allows), its flush and the rendering pass lit by the field, every ray, count, burst and
/// memory word after the flush and every pixel equal to the model's (`two_pass_gi`).
#[test]
#[ignore = "sim-full: the gate-level netlist is a `full` build (minutes of Yosys and Verilator)"]
fn gate_level_netlist_runs_an_exact_lighting_pass() {
    gate_level_gi_passes(0, GiMode::LowAlbedo, seed(1990));
}

/// Both GI passes (`two_pass_gi`, the lighting grid halved) in `mode` on every gate-level netlist
/// of a `Light` configuration with `Scatter = scatter`, timed.
fn gate_level_gi_passes(scatter: u32, mode: GiMode, s: u64) {
    let lit: Vec<_> = support::gate_configs::<ProcessorRtlConfig>()
        .into_iter()
        .filter(|(_, c)| c.light == 1 && c.scatter == scatter)
        .collect();
    assert!(
        !lit.is_empty(),
        "a gate-level line with Light = 1, Scatter = {scatter}"
    );
    for (variant, rtl) in lit {
        let t = std::time::Instant::now();
        two_pass_gi(variant, rtl, mode, 2, s);
        eprintln!(
            "{variant}: both GI passes ({mode:?}) on the netlist in {:.1} s",
            t.elapsed().as_secs_f64()
        );
    }
}

/// The gate-level netlist of the photon path (`b2v2s1`: `gicube_scatter`, the albedo and
/// interaction draws, the second step unit): a high-albedo lighting pass (albedo 0.8, up to 8
/// bounces; a quarter of the shadow scene's photons), its flush and the rendering pass lit by the
/// field, every photon, count (scatterings too), burst, memory word and pixel equal to the
/// model's (`two_pass_gi`).
#[test]
#[ignore = "sim-full: the gate-level netlist is a `full` build (minutes of Yosys and Verilator)"]
fn gate_level_netlist_runs_an_exact_photon_pass() {
    gate_level_gi_passes(1, HIGH_ALBEDO, seed(1995));
}

/// Throughput at full speed (the host never idle, the output never stalled, a memory answering
/// after 2 clocks): every frame makes exactly the model's cycles (`check_frame`), and its clocks
/// are within the contract's *Timing*: a cycle while the lines hit takes `max(5, round trip /
/// RingLat)` clocks (`round_trip_clocks`), and each line the
/// cache misses holds the dispatch at most the memory's latency, the line's beats and two clocks
/// more. A frame's clocks are at most the sum of both.
#[test]
fn full_speed_clocks_within_the_timing_bound() {
    for (variant, rtl) in ci_configs() {
        let per_cycle = round_trip_clocks(&rtl)
            .div_ceil(u64::from(rtl.ring_lat))
            .max(5);
        let cache = rtl.cache_config();
        let beats = u64::from(cache.line_vox * cache.word_w / cache.data_w);
        let per_miss = u64::from(FAST_MEMORY.lat.0) + beats + 2;
        for proj in [
            Projection::Parallel,
            Projection::Perspective { fov_deg: 40.0 },
        ] {
            let (got, want) = exact_frame(
                variant,
                rtl,
                rtl.side(),
                proj,
                Some(FAST_MEMORY),
                seed(0x7468),
            );
            let c = &want.counts;
            let bound = c.cycles * per_cycle + c.cache_misses * per_miss;
            eprintln!(
                "{variant} {proj:?} at full speed: {} clocks for {} cycles ({:.2} a cycle) and {} lines missed; bound {bound} ({per_cycle} a cycle, {per_miss} a miss): {:.2} of it",
                got.clocks,
                c.cycles,
                got.clocks as f64 / c.cycles as f64,
                c.cache_misses,
                got.clocks as f64 / bound as f64
            );
            assert!(
                got.clocks <= bound,
                "{variant} {proj:?}: {} clocks exceed the timing bound {bound} ({} cycles x {per_cycle} + {} misses x {per_miss})",
                got.clocks,
                c.cycles,
                c.cache_misses
            );
        }
    }
}
