//! `cube5 cosim` of a `[gi]` scene: its passes on the RTL block processor (`gicube_processor`,
//! Verilator, the volume and the irradiance field in the test bench's AXI4 memory) against the
//! processor model at the RTL's configuration (`ProcessorRtlConfig::processor_config`,
//! docs/numerics/gicube_processor.md, *The RTL*). The lighting pass (`gi.passes = 2`): every
//! lighting ray's count, the AR and AW bursts and, after the flush, every memory word (volume and
//! field); then, from a reset, the rendering pass lit by that field: every pixel, count and AR
//! burst. The host is this program: it offers its next ray packet, holds it until taken, and
//! appends every ray that overflows back to the end of its list. The same runs give the GI-Cube
//! benchmark (`cube5 bench --unit processor`, `bench::gicube_processor`).

use crate::write_png_atomically;
use anyhow::{anyhow, bail, Context, Result};
use cube5_model::camera::Camera;
use cube5_model::render::ImageF64;
use cube5_model::scene::Scene;
use cube5_model::scene_gi::{gi_light, GiSpec};
use cube5_model::scene_render::at_voxel_width;
use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_axi_rd::Burst;
use cube5_model::units::gicube_packet_loop::{RayPacket, PACKET_WORDS};
use cube5_model::units::gicube_processor::{
    host_rays, interaction_draw, light_rays, ray_bits, GiLight, GiMode, Processor, ProcessorCounts,
    ProcessorFrame, ProcessorOut, ProcessorRtlConfig, Projection,
};
use cube5_model::volume::Volume;
use cube5_tb::harness::count_differing;
use cube5_tb::rtl::{AxiMemSetup, RtlStream, Traffic};
use cube5_tb::variants::Netlist;
use cube5_tb::Variant;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;
use std::path::Path;

type Bits = [u32; PACKET_WORDS];

/// How the test bench's memory answers (`cube5 cosim --memory`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MemoryKind {
    /// DDR-like (docs/accel.md): latency 100-120 cycles, 12 bytes per cycle, no gaps, the output
    /// always taken: the figures of docs/measurements.md.
    Ddr,
    /// Random: latency 10-200 cycles, AR/R (and AW/W/B) gaps of up to 30 %, a bandwidth limit on
    /// half the seeds, the output stalled 30 % of clocks.
    Random,
}

/// The memory and the consumer of one run: latency `fixed + U(0..random)`, AR and R gaps per
/// mille (AW and B as AR, W as R), bandwidth `num / den` bytes per cycle (0: none), the
/// probability that the output is not taken in a clock.
#[derive(Debug, Clone, Copy)]
pub struct Memory {
    lat: (u32, u32),
    gaps: (u32, u32),
    bw: (u32, u32),
    stall: f64,
}

impl Memory {
    pub fn new(kind: MemoryKind, rtl: &ProcessorRtlConfig, rng: &mut ChaCha8Rng) -> Self {
        match kind {
            MemoryKind::Ddr => Self {
                lat: (100, 20),
                gaps: (0, 0),
                bw: (12, 1),
                stall: 0.0,
            },
            MemoryKind::Random => Self {
                lat: (10, 190),
                gaps: (rng.random_range(0..300), rng.random_range(0..300)),
                bw: if rng.random_bool(0.5) {
                    (rng.random_range(1..=rtl.data_w / 8), 2)
                } else {
                    (0, 1)
                },
                stall: 0.3,
            },
        }
    }

    fn setup(&self, rtl: &ProcessorRtlConfig, proc: &Processor, seed: u64) -> Result<AxiMemSetup> {
        let img = proc
            .rtl_memory()?
            .context("the processor model has no RTL cache")?;
        Ok(AxiMemSetup {
            data_bytes: rtl.data_w / 8,
            addr_bits: 32,
            latency_fixed: self.lat.0,
            latency_random: self.lat.1,
            ar_gap_permille: self.gaps.0,
            r_gap_permille: self.gaps.1,
            bw_num: self.bw.0,
            bw_den: self.bw.1.max(1),
            max_bursts: 64,
            seed,
            slverr_lo: img.slverr_lo,
            slverr_hi: img.slverr_hi,
            aw_gap_permille: self.gaps.0,
            w_gap_permille: self.gaps.1,
            b_gap_permille: self.gaps.0,
            declared_outstanding: rtl.outstanding,
        })
    }
}

/// What the RTL did in one pass: the pixels (`U(0.12)`, by the finished rays' `(u, v)`), the
/// counts of its last output, the clocks from the first offer to the last ray out, the AR
/// handshakes.
pub struct RtlPass {
    pub rgb: Vec<[u16; 3]>,
    pub last: ProcessorOut,
    pub clocks: u64,
    pub ars: Vec<cube5_tb::rtl::ArHandshake>,
}

/// One pass on both: the model's frame and the RTL's, and what differs (empty: bit-exact).
pub struct PassRun {
    pub model: ProcessorFrame,
    pub rtl: RtlPass,
    /// Lines the cache wrote back (the lighting pass's, flush included; 0 otherwise).
    pub written_back: usize,
    pub differences: Vec<String>,
}

impl PassRun {
    /// Samples per clock of the RTL pass (the processor's throughput).
    pub fn samples_per_clock(&self) -> f64 {
        self.model.counts.samples as f64 / self.rtl.clocks.max(1) as f64
    }
}

/// The RTL processor, its memory loaded with `proc`'s volume (and field) and its tables written.
pub struct GiBench {
    pub variant: &'static Variant,
    pub rtl: ProcessorRtlConfig,
    dut: RtlStream<ProcessorRtlConfig>,
    mem: Memory,
    rng: ChaCha8Rng,
    seed: u64,
}

impl GiBench {
    pub fn new(
        variant: &'static Variant,
        rtl: ProcessorRtlConfig,
        proc: &Processor,
        kind: MemoryKind,
        seed: u64,
    ) -> Result<Self> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mem = Memory::new(kind, &rtl, &mut rng);
        let img = proc
            .rtl_memory()?
            .context("the processor model has no RTL cache")?;
        let mut dut = RtlStream::new(variant, rtl, seed as u32)?;
        dut.axi_setup(&mem.setup(&rtl, proc, seed)?)?;
        dut.axi_load(img.base, &img.bytes)?;
        let mut b = Self {
            variant,
            rtl,
            dut,
            mem,
            rng,
            seed,
        };
        b.load_tables(proc)?;
        Ok(b)
    }

    fn load_tables(&mut self, proc: &Processor) -> Result<()> {
        for (a, d) in proc.rtl_config_writes(&self.rtl)? {
            self.dut.write_config(a, &d)?;
        }
        Ok(())
    }

    /// The host loop, one clock per step: offers the head of its list (held until taken),
    /// collects finished rays into the image (`width` x `height`) and appends overflowed rays to
    /// its list, until every ray has finished.
    fn host(&mut self, rays: &[Bits], width: u32, height: u32) -> Result<RtlPass> {
        let name = self.variant.name;
        let mut list: VecDeque<Bits> = rays.iter().copied().collect();
        let mut rgb = vec![[0u16; 3]; (width * height) as usize];
        let mut seen = vec![false; rgb.len()];
        let (mut finished, mut clocks) = (0usize, 0u64);
        let mut last = ProcessorOut::default();
        let limit = 100_000 + 40_000 * rays.len() as u64;
        let mut shown = std::time::Instant::now();
        while finished < rays.len() {
            // Progress on stderr every few seconds (a 64^3 pass runs for minutes).
            if clocks % 4096 == 0 && shown.elapsed().as_secs_f64() > 5.0 {
                eprintln!(
                    "{name}: {finished} of {} rays finished, {} overflowed, after {clocks} clocks",
                    rays.len(),
                    last.rays_overflowed
                );
                shown = std::time::Instant::now();
            }
            if clocks >= limit {
                bail!(
                    "{name}: no progress after {clocks} clocks ({finished} of {} rays finished)",
                    rays.len()
                );
            }
            let items: Vec<Bits> = list.front().copied().into_iter().collect();
            let traffic = Traffic {
                idle: vec![0],
                stall: vec![u8::from(self.rng.random_bool(self.mem.stall))],
            };
            let d = self
                .dut
                .drive(&items, &traffic, u64::from(items.is_empty()), 1)?;
            clocks += 1;
            if d.stats.protocol_errors != 0 {
                bail!("{name}: a stalled output changed at clock {clocks}");
            }
            if d.stats.consumed == 1 {
                list.pop_front();
            }
            for o in d.outputs {
                let o = o.value;
                last = o;
                if o.flush {
                    bail!("{name}: a flush item without a flush at clock {clocks}");
                }
                if !o.done {
                    list.push_back(o.ray);
                    continue;
                }
                let r = RayPacket::from_bits(&o.ray);
                let i = (u32::from(r.v) * width + u32::from(r.u)) as usize;
                if i >= seen.len() || seen[i] {
                    bail!(
                        "{name}: pixel ({}, {}) finished twice or outside the image",
                        r.u,
                        r.v
                    );
                }
                seen[i] = true;
                rgb[i] = r.color;
                finished += 1;
            }
        }
        let c = self.dut.axi_counters();
        if c.protocol_errors != 0 {
            bail!("{name}: AXI checker: {}", self.dut.axi_first_error());
        }
        Ok(RtlPass {
            rgb,
            last,
            clocks,
            ars: self.dut.axi_take_ar()?,
        })
    }

    /// The flush after a lighting pass: clocks until its output item; its counts.
    fn flush(&mut self) -> Result<ProcessorOut> {
        let (a, d) = Processor::rtl_flush_write(&self.rtl);
        self.dut.write_config(a, &d)?;
        for _ in 0..20_000_000 {
            let traffic = Traffic {
                idle: vec![0],
                stall: vec![u8::from(self.rng.random_bool(self.mem.stall))],
            };
            let d = self.dut.drive(&[], &traffic, 1, 1)?;
            if let Some(o) = d.outputs.first() {
                if !o.value.flush {
                    bail!(
                        "{}: the item after a flush is not the flush's",
                        self.variant
                    );
                }
                return Ok(o.value);
            }
        }
        bail!("{}: the flush never came out", self.variant)
    }

    /// A rendering pass (from reset, the memory kept: a lit pass reads the field the lighting
    /// pass left) of `cam` against `proc.render_cache_traced`.
    pub fn render(&mut self, proc: &Processor, cam: &Camera, proj: Projection) -> Result<PassRun> {
        self.dut.reset();
        self.load_tables(proc)?;
        let (model, bursts) = proc.render_cache_traced(cam, proj)?;
        let rays: Vec<Bits> = host_rays(proc.volume(), cam, proj, proc.config().host_order)?
            .iter()
            .map(|r| Ok(Processor::packet(r)?.to_bits()?))
            .collect::<Result<_>>()?;
        let rtl = self.host(&rays, model.width, model.height)?;
        let mut differences = compare(&rtl, &model);
        differences.extend(self.bursts("AR", &rtl.ars, &bursts));
        Ok(PassRun {
            model,
            rtl,
            written_back: 0,
            differences,
        })
    }

    /// The lighting pass of `light` and its flush, against `proc.light_cache_traced` (which
    /// leaves the field in `proc`): rays and counts, the AR and AW bursts, every memory word.
    pub fn light(&mut self, proc: &mut Processor, light: &GiLight) -> Result<PassRun> {
        self.dut.reset();
        self.load_tables(proc)?;
        if self.rtl.scatter == 1 {
            let (a, d) = Processor::rtl_photon_write(&self.rtl, Some(light));
            self.dut.write_config(a, &d)?;
        }
        let (model, trace) = proc.light_cache_traced(light)?;
        let (rays, energy) = light_rays(proc.volume(), light, proc.config().host_order)?;
        let packets: Vec<Bits> = rays
            .iter()
            .map(|r| {
                let mut p = Processor::light_packet(r, energy)?;
                if let GiMode::HighAlbedo { lifetime, .. } = light.mode {
                    p.lifetime = lifetime;
                    p.interaction = interaction_draw(ray_bits(&p));
                }
                Ok(p.to_bits()?)
            })
            .collect::<Result<_>>()?;
        let mut rtl = self.host(&packets, model.width, model.height)?;
        let mut differences = compare(&rtl, &model);
        let f = self.flush()?;
        let c = &model.counts;
        let flushed = (
            u64::from(f.cache_hits),
            u64::from(f.cache_misses),
            u64::from(f.cycles),
        );
        if flushed != (c.cache_hits, c.cache_misses, c.cycles) {
            differences.push(format!(
                "the flush's counts (hits, misses, cycles) {flushed:?}, the model's ({}, {}, {})",
                c.cache_hits, c.cache_misses, c.cycles
            ));
        }
        rtl.ars.extend(self.dut.axi_take_ar()?);
        let aws = self.dut.axi_take_aw()?;
        differences.extend(self.bursts("AR", &rtl.ars, &trace.reads));
        differences.extend(self.bursts("AW", &aws, &trace.writes));
        let cache = self.rtl.cache_config();
        let words = cache.words_of(&self.dut.axi_image()?);
        let differ = count_differing(&words, &trace.memory);
        if differ > 0 || words.len() != trace.memory.len() {
            differences.push(format!(
                "{differ} memory words (volume and irradiance field) differ from the model's after the flush"
            ));
        }
        Ok(PassRun {
            model,
            rtl,
            written_back: aws.len(),
            differences,
        })
    }

    /// The address handshakes of channel `ch` against the model's bursts, in order.
    fn bursts(&self, ch: &str, got: &[cube5_tb::rtl::ArHandshake], want: &[Burst]) -> Vec<String> {
        let size = (self.rtl.data_w / 8).trailing_zeros();
        let first = got.iter().enumerate().find(|(k, a)| {
            want.get(*k)
                != Some(&Burst {
                    addr: a.addr,
                    beats: a.len + 1,
                })
                || a.size != size
                || a.burst != 1
        });
        match first {
            Some((k, a)) => vec![format!(
                "{ch} burst #{k}: RTL {:#x} x {} beats, model {:?} (seed {})",
                a.addr,
                a.len + 1,
                want.get(k),
                self.seed
            )],
            None if got.len() != want.len() => vec![format!(
                "{} {ch} bursts, the model {}",
                got.len(),
                want.len()
            )],
            None => Vec::new(),
        }
    }
}

/// The RTL pass against the model's frame: every pixel, and every count (rays in, finished,
/// overflowed, samples, leaps, processor cycles, cache hits and misses, scatterings), with rays
/// in = finished + overflowed on both sides.
fn compare(got: &RtlPass, want: &ProcessorFrame) -> Vec<String> {
    let mut d = Vec::new();
    let differ = count_differing(&got.rgb, &want.rgb);
    if differ > 0 {
        d.push(format!("{differ} pixels differ from the model's"));
    }
    let l = &got.last;
    let c = &want.counts;
    if l.rays_in != l.rays_finished + l.rays_overflowed {
        d.push(format!(
            "RTL: rays in {} != finished {} + overflowed {}",
            l.rays_in, l.rays_finished, l.rays_overflowed
        ));
    }
    if c.rays_in != c.rays_finished + c.rays_overflowed {
        d.push("model: rays in != finished + overflowed".into());
    }
    let rtl = [
        l.rays_in,
        l.rays_finished,
        l.rays_overflowed,
        l.samples,
        l.leaps,
        l.cycles,
        l.cache_hits,
        l.cache_misses,
        l.scatterings,
    ]
    .map(u64::from);
    let model = [
        c.rays_in,
        c.rays_finished,
        c.rays_overflowed,
        c.samples,
        c.leaps,
        c.cycles,
        c.cache_hits,
        c.cache_misses,
        c.scatterings,
    ];
    if rtl != model {
        d.push(format!(
            "counts (rays in, finished, overflowed, samples, leaps, cycles, hits, misses, scatterings): RTL {rtl:?}, model {model:?}"
        ));
    }
    d
}

/// One pass's line: the counts both agree on, the RTL's clocks, the model's queue figures.
pub fn pass_line(what: &str, run: &PassRun) -> String {
    let c = &run.model.counts;
    format!(
        "{what}: {} rays in = {} finished + {} overflowed to the host (RTL and model; overflow rate {:.1} %), {} samples, {} leaps{}, {} processor cycles, {} clocks ({:.1} clocks/cycle, {:.4} samples/clock), cache hit rate {:.4}, {} lines read{}, queue occupancy mean {:.1} rays (max queue {})",
        c.rays_in,
        c.rays_finished,
        c.rays_overflowed,
        overflow_rate(c),
        c.samples,
        c.leaps,
        if c.scatterings > 0 {
            format!(", {} scatterings, {} absorbed", c.scatterings, c.absorbed)
        } else {
            String::new()
        },
        c.cycles,
        run.rtl.clocks,
        run.rtl.clocks as f64 / c.cycles.max(1) as f64,
        run.samples_per_clock(),
        c.cache_hit_rate(),
        run.rtl.ars.len(),
        if run.written_back > 0 {
            format!(", {} written back", run.written_back)
        } else {
            String::new()
        },
        c.mean_occupancy(),
        c.max_queue
    )
}

/// Rays returned to the host, % of the rays the processor took.
pub fn overflow_rate(c: &ProcessorCounts) -> f64 {
    100.0 * c.rays_overflowed as f64 / c.rays_in.max(1) as f64
}

/// The built `gicube_processor` configuration a GI scene runs on: side `N` equal to the volume's,
/// `Light = 1` for a lighting pass, `Scatter = 1` for photons (`gi.albedo > 0`); of those, the one
/// with the fewest units (no photon path when not needed), the scene's step first; never a shaded
/// or jittered line (a `[gi]` scene is unshaded). Refused in one line naming what would run it.
fn variant_for(
    gi: &GiSpec,
    side: usize,
    step: u32,
    origin: &str,
) -> Result<(&'static Variant, ProcessorRtlConfig)> {
    let lit = gi.passes == 2;
    let photons = lit && gi.albedo > 0.0;
    let mut fits: Vec<(&'static Variant, ProcessorRtlConfig)> = Vec::new();
    let mut near = Vec::new();
    let mut sides = Vec::new();
    let lines = cube5_tb::VARIANTS
        .iter()
        .filter(|v| v.top == ProcessorRtlConfig::TOP && v.netlist == Netlist::Rtl);
    for v in lines {
        let rtl: ProcessorRtlConfig = v.config()?;
        if (!lit || rtl.light == 1) && !sides.contains(&rtl.side()) {
            sides.push(rtl.side());
        }
        if rtl.side() as usize != side
            || (lit && rtl.light == 0)
            || (photons && rtl.scatter == 0)
            || rtl.shade != 0
            || rtl.jitter != 0
        {
            continue;
        }
        if v.built {
            fits.push((v, rtl));
        } else {
            near.push(v.config);
        }
    }
    fits.sort_by_key(|(_, r)| (r.step != step, r.scatter, r.light));
    fits.into_iter().next().ok_or_else(|| {
        let what = format!(
            "{side}^3{}{}",
            if lit { ", Light = 1" } else { "" },
            if photons { ", Scatter = 1" } else { "" }
        );
        if near.is_empty() {
            sides.sort_unstable();
            let sides: Vec<String> = sides.iter().map(|n| format!("{n}^3")).collect();
            anyhow!(
                "{origin}: no gicube_processor configuration in rtl/gicube/gicube_processor.variants renders this scene ({what}); its lines for it are {}",
                sides.join(", ")
            )
        } else {
            anyhow!(
                "{origin}: gicube_processor {} ({what}) is not built in this cube5: CUBE5_FULL=1 CUBE5_TOPS={} builds it",
                near.join(", "),
                near.iter().map(|n| format!("{}_{n}", ProcessorRtlConfig::TOP)).collect::<Vec<_>>().join(",")
            )
        }
    })
}

/// `cube5 cosim` of a `[gi]` scene. True when every pass is bit-exact.
pub fn run(
    scene: &Scene,
    origin: &str,
    out_dir: &Path,
    seed: u32,
    kind: MemoryKind,
) -> Result<bool> {
    let gi = scene.gi.as_ref().context("the scene has no [gi] section")?;
    let raw = scene.build_volume()?;
    let side = raw.dims[0];
    if raw.dims.iter().any(|&d| d != side) {
        bail!(
            "{origin}: volume: {:?}: the GI-Cube RTL renders cubes (N x N x N)",
            raw.dims
        );
    }
    let wanted = cube5_model::scene_gi::processor_config(scene)?;
    let (variant, rtl) = variant_for(gi, side, wanted.step, origin)?;
    let vol: Volume = at_voxel_width(&raw, rtl.voxel_w)?;
    let tf = scene.transfer_function();
    let mut proc =
        Processor::new(rtl.processor_config(), &vol, &tf).map_err(|e| anyhow!("{origin}: {e}"))?;
    let cfg = proc.config();
    if (wanted.step, wanted.et_threshold) != (cfg.step, cfg.et_threshold) {
        bail!(
            "{origin}: render.step and render.early_termination give step {} and termination {:?}; {variant} has step {} (its Step parameter) and termination {:?}",
            wanted.step, wanted.et_threshold, cfg.step, cfg.et_threshold
        );
    }
    say!(
        "cosim: {origin}: GI on {variant}: {side}^3 at {} bits (the scene's {}), blocks of {}^3, {} queues of {} rays, ring latency {}, cache {} sets of {} voxels{}",
        rtl.voxel_w,
        raw.bits,
        1 << rtl.block_log2,
        1u32 << rtl.queue_w(),
        rtl.queue_len,
        rtl.ring_lat,
        rtl.sets,
        rtl.line_vox,
        if (wanted.block_log2, wanted.queue_len) != (rtl.block_log2, rtl.queue_len) {
            format!(
                " (the scene's gi.block_size {} and gi.queue_length {} are the RTL's here: the model runs at the RTL's configuration)",
                1 << wanted.block_log2,
                wanted.queue_len
            )
        } else {
            String::new()
        }
    );
    let params = scene.render_params();
    let camera = params.camera(&vol, params.direction().context(origin.to_string())?);
    let proj = match scene.view.projection {
        cube5_model::render::Projection::Parallel => Projection::Parallel,
        cube5_model::render::Projection::Perspective => Projection::Perspective {
            fov_deg: scene.view.fov,
        },
    };
    let mut bench = GiBench::new(variant, rtl, &proc, kind, u64::from(seed))?;
    say!("memory: {kind:?} ({:?})", bench.mem);
    let mut matched = true;
    let mut report = |what: &str, run: &PassRun| {
        if run.differences.is_empty() {
            say!("MATCH: {}", pass_line(what, run));
        } else {
            matched = false;
            say!("MISMATCH: {what}: {}", run.differences.join("; "));
            say!("  {}", pass_line(what, run));
        }
    };
    if gi.passes == 2 {
        let light = gi_light(gi, &vol);
        let run = bench.light(&mut proc, &light)?;
        report(
            &format!(
                "lighting pass ({}^2 lighting rays, {}; the field in memory after the flush)",
                light.grid,
                match light.mode {
                    GiMode::LowAlbedo => "low albedo".to_string(),
                    GiMode::HighAlbedo { albedo, .. } => format!("photons, albedo {albedo}"),
                }
            ),
            &run,
        );
    }
    let run = bench.render(&proc, &camera, proj)?;
    report(
        &format!(
            "rendering pass ({}x{} pixels{})",
            run.model.width,
            run.model.height,
            if gi.passes == 2 {
                ", lit by the field"
            } else {
                ", unlit"
            }
        ),
        &run,
    );
    std::fs::create_dir_all(out_dir)
        .with_context(|| format!("output directory {}", out_dir.display()))?;
    let image = |rgb: &[[u16; 3]]| ImageF64 {
        width: run.model.width,
        height: run.model.height,
        rgb: ProcessorFrame {
            rgb: rgb.to_vec(),
            ..run.model.clone()
        }
        .to_f64(),
    };
    for (who, rgb) in [("model", &run.model.rgb), ("rtl", &run.rtl.rgb)] {
        let path = out_dir.join(format!("{who}-gi.png"));
        write_png_atomically(&image(rgb).to_rgb8(), &path)?;
        say!("wrote {}", path.display());
    }
    Ok(matched)
}
