//! The GI-Cube block processor's renderer (direct volume rendering), written from
//! `docs/numerics/gicube_processor.md` (patent [347]-[357], [369]-[374]): ray packets made by the
//! host, bucketed into fixed-size queues per block (overflow returned to the host, never dropped),
//! the active queue chosen by the pipelined insertion sorter (`gicube_sorter`, cycle-accurate) or
//! by the ascending scan, one sample per cycle (tri-linear `cube5_trilin`, classification
//! `cube5_shader`, front-to-back `cube5_compos`), re-queueing to the block the ray enters, space
//! leaping over empty blocks and early ray termination. Plus the f64 reference of the same
//! algorithm (no queues, exact arithmetic).
//!
//! The image is a function of the rays alone: a ray's packet carries its whole state, so the queue
//! order (and which rays overflow to the host and come back) changes the counts, never a pixel.

use std::collections::VecDeque;

use glam::DVec3;

use crate::camera::Camera;
use crate::error::{ModelError, Result};
use crate::transfer::TransferFunction;
use crate::units::cube5_axi_rd::{AxiMemImage, Burst};
use crate::units::cube5_compos::corrected_alpha;
use crate::units::cube5_shader::{ClassLut, Phong, ReflectanceMap, Rgba};
use crate::units::gicube_bucket::{BucketConfig, BucketUnit, Distribution, Position};
use crate::units::gicube_cache::{CacheConfig, CacheItem, CacheReq, VolumeCache};
use crate::units::gicube_deposit as deposit;
use crate::units::gicube_packet_loop::{flag, RayPacket, RayReal, RayType, POS_FRAC_W};
use crate::units::gicube_queue_front::{Chooser, FrontTraffic, QueueFront};
use crate::units::gicube_sample::{
    jitter_index, shader_config_for, GradLut, Jitter, SampleConfig, SampleIn, Sampler, ShadeConfig,
};
use crate::units::gicube_scatter::{jenkins_hash, Scatter, ScatterConfig, ScatterIn};
use crate::units::gicube_step::{StepConfig, Stepper};
use crate::volume::Volume;

// The packet channel's maximum, the sample's and the irradiance's fraction bits and the unit
// configurations of the sample datapath are `gicube_sample`'s (the one description of a sample).
/// The splat's rounding shift (the deposit unit's, `gicube_deposit`).
pub use crate::units::gicube_deposit::DEPOSIT_SHIFT;
/// Sorter steps per pipeline cycle: the sorter is over-clocked by two ([371]).
pub use crate::units::gicube_queue_front::SORTER_SLOTS;
pub use crate::units::gicube_sample::{
    compos_config, shader_config, CHAN_MAX, IRR_FRAC_W, SAMPLE_FRAC_W,
};

/// Largest ring latency, processor cycles (the RTL's `RingLat`: 1..=16).
pub const MAX_RING_LATENCY: u32 = 16;
/// Largest `MaxDim` of the default volume cache (contract, *The volume cache*): a larger domain's
/// padded copy (`M^3` words) is not made, and its samples are not counted.
pub const MAX_DEFAULT_CACHE_DIM: u32 = 256;

/// How the processor picks the next active queue.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QueueOrder {
    /// The pipelined insertion sorter (`gicube_sorter`, cycle-accurate): importance = rays in the
    /// queue ([373] criterion 1); the active queue is the sorter's `S[0]`.
    Sorter,
    /// Keep the active queue until it is empty, then take the next non-empty queue in ascending
    /// cyclic order (a rule without a sorter, for the order-independence test and for small RTL).
    Scan,
}

/// The order in which the host first offers the rays of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HostOrder {
    /// Row by row from the top, left to right.
    RowMajor,
    /// The reverse.
    Reversed,
}

/// Projection of the rendering rays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Rays along `camera.dir` from `camera.ray_origin(px, py)`.
    Parallel,
    /// Rays from one eye through `camera.ray_origin(px, py)`; the top row's pixel centres are
    /// `fov_deg / 2` off the axis.
    Perspective { fov_deg: f64 },
}

/// One processor configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProcessorConfig {
    /// Block side `n = 2^block_log2` voxels.
    pub block_log2: u32,
    /// Rays per queue (the fixed hardware queue length, 256 in [371]).
    pub queue_len: u32,
    /// Ranks of the sorter (clamped to the number of queues).
    pub ranks: u32,
    /// Step `dr` along the ray, `U(4.8)` voxels: 16..=1024 (1/16 to 4 voxels).
    pub step: u32,
    /// Early ray termination threshold on the packet opacity, `U(0.12)`; `None`: off.
    pub et_threshold: Option<u32>,
    /// Space leaping over empty blocks ([357]).
    pub space_leap: bool,
    /// Jitter ([353], [380], `gicube_sample`): each sample's opacity for a step `r dr`, `r` in
    /// `[1/2, 1)` from the random LUT at the position's fraction bits (the advance stays `dr`).
    pub jitter: bool,
    /// Shading ([352], [378], [379], [383]; contract *Shading and jitter in the processor*): the
    /// volume's gradient indices and tags in the voxel words, the gradient LUT, the 2-D
    /// classification by density and the nearest tag, the reflectance map lighting rendering rays
    /// without irradiance. `None`: unlit.
    pub shade: Option<ShadeConfig>,
    pub order: QueueOrder,
    pub host_order: HostOrder,
    /// Ring latency `L` in processor cycles (contract, *The ring*): the ray popped in cycle `t`
    /// is re-queued (or finishes) in cycle `t + L`; 0: in its own cycle (the pipeline inside the
    /// cycle). The RTL `gicube_processor` sets it from its `RingLat` (1..=16).
    pub ring_latency: u32,
    /// The volume cache the samples read through (`gicube_cache`, contract *The volume cache*):
    /// `None`, `CacheConfig::DEFAULT`'s lines and sets at the smallest `MaxDim > N` (at least
    /// 16; none beyond [`MAX_DEFAULT_CACHE_DIM`]); `Some`, exactly this one (`MaxDim > N`).
    pub cache: Option<CacheConfig>,
}

impl ProcessorConfig {
    /// 16^3 blocks, 256-ray queues, 16 ranks, one sample per voxel, termination at
    /// `1 - 2^-8`, space leaping, the sorter.
    pub const DEFAULT: Self = Self {
        block_log2: 4,
        queue_len: 256,
        ranks: 16,
        step: 256,
        et_threshold: Some(CHAN_MAX + 1 - 16),
        space_leap: true,
        jitter: false,
        shade: None,
        order: QueueOrder::Sorter,
        host_order: HostOrder::RowMajor,
        ring_latency: 0,
        cache: None,
    };

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(ModelError::Config(format!("gicube processor: {m}")));
        if !(2..=8).contains(&self.block_log2) {
            return bad(format!("block_log2 {} outside 2..=8", self.block_log2));
        }
        if !(1..=65535).contains(&self.queue_len) {
            return bad(format!("queue_len {} outside 1..=65535", self.queue_len));
        }
        if !(2..=64).contains(&self.ranks) {
            return bad(format!("ranks {} outside 2..=64", self.ranks));
        }
        if !(16..=1024).contains(&self.step) {
            return bad(format!(
                "step {} (1/256 voxel) outside 16..=1024",
                self.step
            ));
        }
        if let Some(t) = self.et_threshold {
            if !(1..=CHAN_MAX + 1).contains(&t) {
                return bad(format!("et_threshold {t} outside 1..=4096"));
            }
        }
        if self.ring_latency > MAX_RING_LATENCY {
            return bad(format!(
                "ring_latency {} outside 0..={MAX_RING_LATENCY}",
                self.ring_latency
            ));
        }
        Ok(())
    }

    /// The step in voxels.
    pub fn step_voxels(&self) -> f64 {
        f64::from(self.step) / f64::from(1u32 << POS_FRAC_W)
    }
}

/// The counts of one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ProcessorCounts {
    /// Pixels whose ray meets the volume (the host makes one ray for each).
    pub rays_made: u64,
    /// Ray packets the processor accepted from the host (first offers and re-offers).
    pub rays_in: u64,
    /// Cycles in which the host's next ray was not accepted because its queue was full.
    pub host_stalls: u64,
    /// Rays that left the processor finished (exited the volume or terminated).
    pub rays_finished: u64,
    /// Rays returned to the host because the queue of the block they entered was full ([372]);
    /// the host offers them again after the rays it holds.
    pub rays_overflowed: u64,
    /// Finished rays that stopped by early termination.
    pub rays_terminated: u64,
    /// Samples taken (one per busy pipeline cycle that does not leap).
    pub samples: u64,
    /// Block visits that leapt over an empty block.
    pub leaps: u64,
    /// Times a queue became active (blocks processed).
    pub activations: u64,
    pub cycles: u64,
    /// Cycles with no ray in the pipeline while rays remained.
    pub idle_cycles: u64,
    /// Sum over cycles of the rays held in all queues (mean occupancy = this / cycles).
    pub occupancy_sum: u64,
    /// Largest number of rays one queue held.
    pub max_queue: u32,
    /// High-albedo photons: interactions that scattered, and that absorbed the photon.
    pub scatterings: u64,
    pub absorbed: u64,
    /// Voxel reads (eight per sample) found in the volume cache, and not found (its lines read
    /// from memory): the `hit` masks of `VolumeCache::request` (contract, *The volume cache*).
    pub cache_hits: u64,
    pub cache_misses: u64,
}

impl ProcessorCounts {
    pub fn mean_occupancy(&self) -> f64 {
        self.occupancy_sum as f64 / self.cycles.max(1) as f64
    }

    pub fn cache_hit_rate(&self) -> f64 {
        self.cache_hits as f64 / (self.cache_hits + self.cache_misses).max(1) as f64
    }
}

/// A rendered frame: the raw `U(0.12)` colour of every pixel (0 where no ray was made), row-major
/// from the top, and the counts.
#[derive(Debug, Clone, PartialEq)]
pub struct ProcessorFrame {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<[u16; 3]>,
    pub counts: ProcessorCounts,
}

impl ProcessorFrame {
    /// Colours as reals, `raw / 4096`.
    pub fn to_f64(&self) -> Vec<[f64; 3]> {
        self.rgb
            .iter()
            .map(|c| c.map(|v| f64::from(v) / 4096.0))
            .collect()
    }
}

/// One ray of the host, before quantization (shared by the processor and the f64 reference).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HostRay {
    pub px: u32,
    pub py: u32,
    /// Entry point into the volume's voxel-centre box, voxel coordinates.
    pub entry: DVec3,
    /// Unit direction, voxel coordinates.
    pub dir: DVec3,
}

/// Domain of a volume on the processor: blocks a side `B`, side `N = B n`.
fn domain(vol: &Volume, block_log2: u32) -> Result<(u32, u32)> {
    let n = 1usize << block_log2;
    let edge = *vol.dims.iter().max().unwrap_or(&1);
    let b = edge.div_ceil(n);
    if b > 64 || b * n > 4096 {
        return Err(ModelError::Config(format!(
            "gicube processor: {edge} voxels a side need {b} blocks of {n} (at most 64 blocks and 4096 voxels)"
        )));
    }
    if b * b * b > 256 {
        return Err(ModelError::Config(format!(
            "gicube processor: {b}^3 = {} blocks exceed the sorter's 256 queues; use blocks of at least {} voxels",
            b * b * b,
            edge.div_ceil(6).next_power_of_two()
        )));
    }
    Ok((b as u32, (b * n) as u32))
}

/// The rays of a frame, one per pixel whose ray meets the box `[0, dims - 1]` (voxel centres), in
/// the host's order.
pub fn host_rays(
    vol: &Volume,
    cam: &Camera,
    proj: Projection,
    order: HostOrder,
) -> Result<Vec<HostRay>> {
    let s = vol.spacing[0];
    if vol.spacing.iter().any(|&x| x != s) {
        return Err(ModelError::Config(format!(
            "gicube processor: anisotropic spacing {:?} is not supported (resample the volume)",
            vol.spacing
        )));
    }
    if cam.width == 0 || cam.height == 0 || cam.width > 4096 || cam.height > 4096 {
        return Err(ModelError::Config(format!(
            "gicube processor: image {}x{} outside 1..=4096 a side (the packet's u, v)",
            cam.width, cam.height
        )));
    }
    let dir = cam.dir;
    if !dir.is_finite() || (dir.length() - 1.0).abs() > 1e-6 {
        return Err(ModelError::Config(format!(
            "gicube processor: camera direction {dir} is not a unit vector"
        )));
    }
    let eye = match proj {
        Projection::Parallel => None,
        Projection::Perspective { fov_deg } => {
            if !(fov_deg > 0.0 && fov_deg < 170.0) {
                return Err(ModelError::Config(format!(
                    "gicube processor: field of view {fov_deg} degrees outside (0, 170)"
                )));
            }
            let (u, v) = cam.pixel_offset(0, 0);
            let c0 = cam.ray_origin(0, 0) - cam.right * u - cam.up * v;
            let focal = v.abs() / (fov_deg.to_radians() * 0.5).tan();
            Some(c0 - dir * focal)
        }
    };
    let hi = DVec3::new(
        vol.dims[0] as f64 - 1.0,
        vol.dims[1] as f64 - 1.0,
        vol.dims[2] as f64 - 1.0,
    );
    let mut rays = Vec::new();
    let mut push = |px: u32, py: u32| {
        let p = cam.ray_origin(px, py) / s;
        let d = match eye {
            None => dir,
            Some(e) => (p - e / s).normalize(),
        };
        if let Some(t) = clip(p, d, hi) {
            rays.push(HostRay {
                px,
                py,
                entry: (p + d * t).clamp(DVec3::ZERO, hi),
                dir: d,
            });
        }
    };
    match order {
        HostOrder::RowMajor => {
            for py in 0..cam.height {
                for px in 0..cam.width {
                    push(px, py);
                }
            }
        }
        HostOrder::Reversed => {
            for py in (0..cam.height).rev() {
                for px in (0..cam.width).rev() {
                    push(px, py);
                }
            }
        }
    }
    Ok(rays)
}

/// Entry parameter `t >= 0` of the ray `p + t d` into the box `[0, hi]`, or `None` if it misses.
fn clip(p: DVec3, d: DVec3, hi: DVec3) -> Option<f64> {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for a in 0..3 {
        if d[a].abs() < 1e-12 {
            if p[a] < 0.0 || p[a] > hi[a] {
                return None;
            }
        } else {
            let (ta, tb) = ((0.0 - p[a]) / d[a], (hi[a] - p[a]) / d[a]);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
    }
    (t0 <= t1).then_some(t0)
}

/// Corner `c` (`x + 2y + 4z`) of the cell whose lowest voxel is `base`.
#[inline]
fn corner(base: [i64; 3], c: usize) -> [i64; 3] {
    [
        base[0] + (c & 1) as i64,
        base[1] + ((c >> 1) & 1) as i64,
        base[2] + ((c >> 2) & 1) as i64,
    ]
}

/// Index of voxel `v` in a field of `dims` (x fastest), `None` outside.
#[inline]
fn voxel_index(dims: [usize; 3], v: [i64; 3]) -> Option<usize> {
    let [nx, ny, nz] = dims.map(|d| d as i64);
    let inside = (0..3).all(|a| v[a] >= 0) && v[0] < nx && v[1] < ny && v[2] < nz;
    inside.then(|| (v[0] + nx * (v[1] + ny * v[2])) as usize)
}

/// The albedo of a high-albedo pass, `U(0.16)` raw: `round(albedo 65536)`, at most 65536.
pub fn albedo_raw(albedo: f64) -> u32 {
    (albedo * 65536.0).round().clamp(0.0, 65536.0) as u32
}

/// Key of the albedo draw (`jenkins_hash(ray_bits ^ ALBEDO_KEY)`, low 16 bits).
pub const ALBEDO_KEY: u32 = 0x2545_f491;
/// Key of the interaction-value draw.
pub const INTERACTION_KEY: u32 = 0x5bd1_e995;

/// A ray's mangling source ([380], [385]): destination and generation bits
/// `u + 2^12 v + 2^24 generation` XOR the position bits `x ^ rotl(y, 10) ^ rotl(z, 20)`.
pub fn ray_bits(r: &RayPacket) -> u32 {
    (u32::from(r.u) | u32::from(r.v) << 12 | u32::from(r.generation) << 24)
        ^ r.start[0]
        ^ r.start[1].rotate_left(10)
        ^ r.start[2].rotate_left(20)
}

/// A fresh interaction value, `U(0.16)`: `min(jenkins_hash(bits ^ INTERACTION_KEY) >> 16, 65520)`
/// (65520 = the largest opacity, 4095, on the interaction's scale, so every photon can interact).
pub fn interaction_draw(bits: u32) -> u16 {
    (jenkins_hash(bits ^ INTERACTION_KEY) >> 16).min(65520) as u16
}

/// The volume cache of one frame (contract, *The volume cache*): the samples' items, in order,
/// and, when traced, the bursts of their misses and write-backs.
#[derive(Debug, Clone)]
pub(crate) struct FrameCache {
    cache: VolumeCache,
    /// The words hold the irradiance field above the voxel (contract, *Splatting through the
    /// cache*): a lighting sample is a deposit item.
    splats: bool,
    trace: Option<CacheTrace>,
}

/// What the volume cache of a traced pass did: the AXI4 bursts of its misses (AR) and of its
/// write-backs (AW) in order, and, after a lighting pass's flush, the words memory holds.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct CacheTrace {
    pub reads: Vec<Burst>,
    pub writes: Vec<Burst>,
    /// `M^3` words, x fastest (`VolumeCache::memory_words`) at the end of the pass.
    pub memory: Vec<u32>,
    /// The rays that left the processor, in order: finished (`true`) or overflowed to the host
    /// (`false`, OVERFLOW set), one a cycle at most (the processor's output port).
    pub outputs: Vec<(bool, RayPacket)>,
}

impl FrameCache {
    /// The eight corner words of the cell at `base` through the cache: a read, or, for a
    /// lighting sample when the words hold the field, a deposit of `energies` (the same voxels:
    /// a deposit adds above them); the corners found and not found are counted.
    fn sample(
        &mut self,
        base: [i64; 3],
        energies: Option<[u32; 8]>,
        counts: &mut ProcessorCounts,
    ) -> [u32; 8] {
        let [x, y, z] = base.map(|a| a as u32);
        let req = CacheReq { x, y, z };
        let item = match energies {
            Some(e) if self.splats => CacheItem::Deposit(req, e),
            _ => CacheItem::Read(req),
        };
        let step = self.cache.item(&item);
        let found = u64::from(step.out.hit.count_ones());
        counts.cache_hits += found;
        counts.cache_misses += 8 - found;
        self.record(step.reads, step.writes);
        step.out.vox
    }

    fn record(&mut self, reads: Vec<Burst>, writes: Vec<Burst>) {
        if let Some(t) = self.trace.as_mut() {
            t.reads.extend(reads);
            t.writes.extend(writes);
        }
    }

    /// The flush at the end of a lighting pass: every dirty line written back.
    fn flush(&mut self) {
        if self.splats {
            let step = self.cache.item(&CacheItem::Flush);
            self.record(step.reads, step.writes);
        }
    }
}

/// One step the frame loop made on its ray queues (`RayQueues`, inside the queue front end): a
/// pop of the active queue, or a push of a ray into a queue (re-queued, moved or from the host).
pub type QueueOp = crate::units::gicube_queue_front::QueueOp<RayPacket>;

/// What a traced frame records: the queue steps and the front end's input of every cycle.
type FrontTrace = crate::units::gicube_queue_front::FrontTrace<RayPacket>;

/// What one pipeline cycle did to a ray.
pub(crate) enum Outcome {
    /// Still in the volume: re-queued through the ring to the block it is in now (the front
    /// end buckets it: the same queue, or the one it entered).
    Next(RayPacket),
    /// Finished: exited the volume or terminated.
    Done(RayPacket),
}

/// The block processor's renderer.
#[derive(Debug, Clone)]
pub struct Processor {
    cfg: ProcessorConfig,
    vol: Volume,
    /// Resampling, classification, lighting by the irradiance and compositing (`gicube_sample`).
    sampler: Sampler,
    bucket: BucketUnit,
    /// Blocks a side, domain side in voxels.
    blocks: u32,
    side: u32,
    /// Empty flag of each queue's block.
    empty: Vec<bool>,
    /// The irradiance field of the last lighting pass, `U(2.14)` per voxel.
    irradiance: Option<Vec<u16>>,
    /// The scattering unit (isotropic scattering of high-albedo photons).
    scatter: Scatter,
    /// During a high-albedo lighting pass: the albedo, `U(0.16)` raw.
    photon_albedo: Option<u32>,
    /// Step, leap, advance and re-bucketing (`gicube_step`).
    stepper: Stepper,
    /// The volume cache after reset over the padded volume (`None`: samples read the volume).
    cache: Option<VolumeCache>,
    /// Shading on: the host's per-voxel fields and lights (contract, *Shading and jitter in the
    /// processor*).
    shading: Option<Shading>,
}

/// What the host computed for a shaded volume: every voxel's gradient index and tag (the fields
/// of its word), the directions the f64 reference interpolates, and the lights of the map.
#[derive(Debug, Clone)]
struct Shading {
    widths: ShadeConfig,
    phong: Phong,
    /// `GradLut::index_of` of the voxel's central differences, x fastest.
    grad_idx: Vec<u16>,
    /// The voxel's tag (`< 2^TagW`), x fastest.
    tags: Vec<u8>,
    /// The unit direction of the voxel's central differences (0 for a zero gradient).
    dirs: Vec<DVec3>,
}

/// The host's gradient of voxel `v` (contract, *Shading and jitter in the processor*): central
/// differences `vol(v + e_a) - vol(v - e_a)` per axis, 0 outside the volume.
pub fn voxel_gradient(vol: &Volume, v: [i64; 3]) -> [f64; 3] {
    std::array::from_fn(|a| {
        let mut hi = v;
        let mut lo = v;
        hi[a] += 1;
        lo[a] -= 1;
        f64::from(vol.get(hi[0], hi[1], hi[2])) - f64::from(vol.get(lo[0], lo[1], lo[2]))
    })
}

/// An example segmentation for the tests and figures: tag 1 in the half `x >= dims.x / 2`, 0
/// elsewhere (one per voxel, x fastest).
pub fn half_tags(vol: &Volume) -> Vec<u8> {
    let nx = vol.dims[0];
    (0..vol.len()).map(|i| u8::from(i % nx >= nx / 2)).collect()
}

/// The colour of tag `t` (contract, *Shading and jitter in the processor*): the transfer
/// function's colour with its channels rotated `t mod 3` places (tag 1: `(b, r, g)`).
pub fn tag_rgb(rgb: [f64; 3], t: u32) -> [f64; 3] {
    let k = (t % 3) as usize;
    std::array::from_fn(|i| rgb[(i + 3 - k) % 3])
}

/// The host's classification table (contract, *Shading and jitter in the processor*): without
/// tags `ClassLut::from_transfer`; with `TagW` tag bits the 2-D table density-major, entry
/// `(den, t)` the transfer function at the centre of density bin `den` (`ClassIdxW - TagW` bits)
/// in the colour of tag `t` ([`tag_rgb`]), its alpha unchanged.
pub fn class_lut(
    voxel_w: u32,
    shade: Option<ShadeConfig>,
    tf: &TransferFunction,
) -> Result<ClassLut> {
    let cfg = shader_config_for(voxel_w, shade);
    let tag_w = shade.map_or(0, |s| s.tag_w);
    if tag_w == 0 {
        return ClassLut::from_transfer(&cfg, tf);
    }
    tf.validate()?;
    let den_n = f64::from(1u32 << (cfg.class_idx_w - tag_w));
    let q = |x: f64, max: u32| (x.clamp(0.0, 1.0) * f64::from(max)).round() as u32;
    ClassLut::from_fn(&cfg, |idx| {
        let (den, t) = (idx >> tag_w, (idx & ((1 << tag_w) - 1)) as u32);
        let v = tf.lookup((den as f64 + 0.5) / den_n);
        let [r, g, b] = tag_rgb([v[0], v[1], v[2]], t);
        Rgba {
            r: q(r, cfg.color_max()),
            g: q(g, cfg.color_max()),
            b: q(b, cfg.color_max()),
            a: q(v[3], cfg.alpha_max()),
        }
    })
}

impl Processor {
    /// Loads the volume and the tables for `tf`.
    pub fn new(cfg: ProcessorConfig, vol: &Volume, tf: &TransferFunction) -> Result<Self> {
        cfg.validate()?;
        tf.validate()?;
        if vol.bits < 4 {
            return Err(ModelError::Config(format!(
                "gicube processor: {}-bit voxels (4..=16 supported)",
                vol.bits
            )));
        }
        let (blocks, side) = domain(vol, cfg.block_log2)?;
        let class = class_lut(vol.bits, cfg.shade, tf)?;
        let mut sampler = Sampler::new(
            SampleConfig {
                voxel_w: vol.bits,
                step: cfg.step,
                et_threshold: cfg.et_threshold,
                jitter: cfg.jitter,
                shade: cfg.shade,
            },
            class,
        )?;
        // Shading: the LUT of uniform directions the host bins into, the map of two lights.
        let shading = match cfg.shade {
            Some(widths) => {
                let lut = GradLut::directions(widths.grad_idx_w)?;
                let phong = Phong::two_lights();
                let rmap =
                    ReflectanceMap::from_lights(&shader_config_for(vol.bits, cfg.shade), &phong)?;
                sampler = sampler.with_shading(rmap, lut.clone())?;
                let mut grad_idx = Vec::with_capacity(vol.len());
                let mut dirs = Vec::with_capacity(vol.len());
                let [nx, ny, nz] = vol.dims.map(|d| d as i64);
                for z in 0..nz {
                    for y in 0..ny {
                        for x in 0..nx {
                            let g = voxel_gradient(vol, [x, y, z]);
                            grad_idx.push(lut.index_of(g) as u16);
                            dirs.push(DVec3::from(g).normalize_or_zero());
                        }
                    }
                }
                Some(Shading {
                    widths,
                    phong,
                    grad_idx,
                    tags: vec![0; vol.len()],
                    dirs,
                })
            }
            None => None,
        };
        let bucket = BucketUnit::new(BucketConfig {
            block_log2: cfg.block_log2,
            vol_blocks: blocks,
            proc_log2: 0,
            dist: Distribution::Slab,
            lanes: 1,
        })?;
        let mut p = Self {
            cfg,
            vol: vol.clone(),
            sampler,
            bucket,
            blocks,
            side,
            empty: Vec::new(),
            irradiance: None,
            scatter: Scatter::new(ScatterConfig::DEFAULT)?,
            photon_albedo: None,
            stepper: Stepper::new(StepConfig {
                block_log2: cfg.block_log2,
                vol_blocks: blocks,
                step: cfg.step,
            })?,
            cache: None,
            shading,
        };
        p.load_cache()?;
        p.empty = (0..blocks * blocks * blocks)
            .map(|q| p.block_is_empty(q))
            .collect();
        Ok(p)
    }

    pub fn config(&self) -> ProcessorConfig {
        self.cfg
    }

    /// Shading (`cfg.shade`): the reflectance map of `phong`'s lights and the volume's tags
    /// (`None`: every tag 0; else one per voxel, x fastest, each below `2^TagW`), which the
    /// host writes into the voxel words. Refused without shading, or with tags of another
    /// length or width.
    pub fn set_shading(&mut self, phong: &Phong, tags: Option<Vec<u8>>) -> Result<()> {
        let Some(sh) = self.shading.as_mut() else {
            return Err(ModelError::Config(
                "gicube processor: shading tables for a processor without shading".into(),
            ));
        };
        let tags = tags.unwrap_or_else(|| vec![0; self.vol.len()]);
        if tags.len() != self.vol.len()
            || tags.iter().any(|&t| u32::from(t) >> sh.widths.tag_w != 0)
        {
            return Err(ModelError::Config(format!(
                "gicube processor: {} tags for {} voxels, each below 2^{}",
                tags.len(),
                self.vol.len(),
                sh.widths.tag_w
            )));
        }
        let rmap = ReflectanceMap::from_lights(&self.sampler.shader().config(), phong)?;
        let lut = self
            .sampler
            .grad_lut()
            .cloned()
            .unwrap_or(GradLut::zero(2)?);
        self.sampler = self.sampler.clone().with_shading(rmap, lut)?;
        sh.phong = phong.clone();
        sh.tags = tags;
        self.load_cache()?;
        self.empty = (0..self.queues()).map(|q| self.block_is_empty(q)).collect();
        Ok(())
    }

    /// Bits of a voxel word's fields: the density, and with shading the tag and the gradient
    /// index above it.
    fn fields_w(&self) -> u32 {
        self.vol.bits + self.cfg.shade.map_or(0, |s| s.tag_w + s.grad_idx_w)
    }

    /// The voxel word of `v` (contract, *Shading and jitter in the processor*): the density in
    /// bits `0 .. VoxelW`; with shading the tag in `VoxelW .. VoxelW + TagW` and the gradient
    /// index above it; 0 outside the volume.
    fn word_of(&self, v: [i64; 3]) -> u32 {
        let d = self.vol.get(v[0], v[1], v[2]);
        match (&self.shading, voxel_index(self.vol.dims, v)) {
            (Some(sh), Some(i)) => {
                let w = self.vol.bits;
                d | u32::from(sh.tags[i]) << w | u32::from(sh.grad_idx[i]) << (w + sh.widths.tag_w)
            }
            _ => d,
        }
    }

    /// The volume cache's configuration (contract, *The volume cache*): `cfg.cache`, or the
    /// default at the smallest `MaxDim > N` of at least 16 (`None` beyond
    /// [`MAX_DEFAULT_CACHE_DIM`]). Refused: a `MaxDim` not above `N`, a word narrower than a voxel.
    pub fn cache_config(&self) -> Result<Option<CacheConfig>> {
        let Some(c) = self.cfg.cache else {
            let m = (self.side + 1).next_power_of_two().max(16);
            let word_w = if self.fields_w() > CacheConfig::DEFAULT.word_w {
                32
            } else {
                CacheConfig::DEFAULT.word_w
            };
            return Ok((m <= MAX_DEFAULT_CACHE_DIM).then_some(CacheConfig {
                max_dim: m,
                word_w,
                ..CacheConfig::DEFAULT
            }));
        };
        if c.max_dim <= self.side
            || c.word_w < self.fields_w()
            || (self.shading.is_some() && c.splat == 1)
        {
            return Err(ModelError::Config(format!(
                "gicube processor: a volume cache of MaxDim {} and WordW {} (Splat {}) for a domain of {} voxels a side of {}-bit words (need MaxDim above the side, WordW at least the word's fields, no splatting with shading)",
                c.max_dim, c.word_w, c.splat, self.side, self.fields_w()
            )));
        }
        Ok(Some(c))
    }

    /// The volume cache after reset over the memory of the next pass (`padded_words`).
    fn load_cache(&mut self) -> Result<()> {
        self.cache = match self.cache_config()? {
            Some(c) => Some(VolumeCache::new(c, &self.padded_words(c))?),
            None => None,
        };
        Ok(())
    }

    /// The cache's words hold the irradiance field above the voxel (contract, *Splatting
    /// through the cache*): a splatting cache whose field lies above the voxel's bits.
    fn field_in_words(&self, c: &CacheConfig) -> bool {
        c.splat == 1 && c.irr_shift() >= self.vol.bits
    }

    /// The volume padded with zeros to `M^3` words, x fastest (the cache's memory); when the
    /// words hold the field, the loaded irradiance (0 before a lighting pass) above each voxel.
    fn padded_words(&self, c: CacheConfig) -> Vec<u32> {
        let m = i64::from(c.max_dim);
        let field = self
            .irradiance
            .as_deref()
            .filter(|_| self.field_in_words(&c));
        (0..m * m * m)
            .map(|i| {
                let v = [i % m, (i / m) % m, i / (m * m)];
                let irr = field
                    .and_then(|f| voxel_index(self.vol.dims, v).map(|k| u32::from(f[k])))
                    .unwrap_or(0);
                self.word_of(v) | irr << c.irr_shift()
            })
            .collect()
    }

    /// The memory image the RTL's AXI4 port reads (contract, *The RTL*): the padded volume in
    /// the cache's bank-major layout at byte address 0 (`None`: no cache).
    pub fn rtl_memory(&self) -> Result<Option<AxiMemImage>> {
        match self.cache_config()? {
            Some(c) => Ok(Some(c.image(&self.padded_words(c))?)),
            None => Ok(None),
        }
    }

    /// The loaded volume.
    pub fn volume(&self) -> &Volume {
        &self.vol
    }

    /// Number of queues (blocks).
    pub fn queues(&self) -> u32 {
        self.blocks * self.blocks * self.blocks
    }

    /// Empty flags of the blocks, by queue number.
    pub fn empty_flags(&self) -> &[bool] {
        &self.empty
    }

    /// The host's empty flag ([357]): every classification entry between the smallest and the
    /// largest voxel the block's samples can read (its `n + 1` voxels a side) has alpha 0.
    fn block_is_empty(&self, q: u32) -> bool {
        let [bx, by, bz] = self.bucket.block_of(0, q);
        let n = 1i64 << self.cfg.block_log2;
        let (mut lo, mut hi) = (u32::MAX, 0u32);
        for z in 0..=n {
            for y in 0..=n {
                for x in 0..=n {
                    let v = self.vol.get(
                        i64::from(bx) * n + x,
                        i64::from(by) * n + y,
                        i64::from(bz) * n + z,
                    );
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
        }
        // With tags the 2-D index is density-major: every tag's entry of the density bins.
        let tw = self.cfg.shade.map_or(0, |s| s.tag_w);
        let idx = |v: u32| self.sampler.class_index_of_voxel(v) >> tw << tw;
        self.sampler.shader().tables().class.entries()[idx(lo)..=idx(hi) | ((1 << tw) - 1)]
            .iter()
            .all(|e| e.a == 0)
    }

    /// The packet the host makes for a ray (`RayPacket::from_real`: round half up, saturate).
    pub fn packet(ray: &HostRay) -> Result<RayPacket> {
        RayPacket::from_real(&RayReal {
            u: ray.px as u16,
            v: ray.py as u16,
            start: ray.entry.to_array(),
            dir: ray.dir.to_array(),
            color: [0.0; 3],
            opacity: 0.0,
            contribution: 1.0,
            interaction: 0.0,
            lifetime: 0,
            generation: 0,
            ray_type: RayType::Rendering,
            flags: 0,
        })
    }

    fn queue_of(&self, pos: [u32; 3]) -> Option<u32> {
        let b = self.bucket.bucket(Position(pos));
        (!b.outside).then_some(b.queue)
    }

    /// The per-ray step `delta = rnd(dir * step, 14)`, `S(.8)` voxels per axis (`gicube_step`).
    pub fn delta(&self, ray: &RayPacket) -> [i64; 3] {
        self.stepper.delta(ray.dir)
    }

    /// The classified, composited sample at the ray's position (the pipeline's datapath) from
    /// the cell's eight voxel words (the density, with shading the tag and gradient index). A
    /// lighting ray adds its `energies` into `irr` first; a rendering ray is lit by the loaded
    /// irradiance.
    fn sample(
        &self,
        ray: &mut RayPacket,
        words: [u32; 8],
        energies: Option<[u32; 8]>,
        irr: Option<&mut [u16]>,
    ) -> bool {
        let p = ray.start;
        let base = p.map(|c| i64::from(c >> POS_FRAC_W));
        let mask = (1u32 << POS_FRAC_W) - 1;
        let weights = p.map(|c| c & mask);
        let lighting = ray.ray_type == RayType::Lighting;
        let vw = self.vol.bits;
        let field = |sh: u32, w: u32| words.map(|x| (x >> sh) & ((1 << w) - 1));
        let (tag_w, grad_w) = self.cfg.shade.map_or((0, 0), |s| (s.tag_w, s.grad_idx_w));
        let voxels = field(0, vw);
        if let (Some(irr), Some(e)) = (irr, energies) {
            for (c, &ec) in e.iter().enumerate() {
                if let Some(i) = voxel_index(self.vol.dims, corner(base, c)) {
                    irr[i] = (u32::from(irr[i]) + ec).min(u32::from(u16::MAX)) as u16;
                }
            }
        }
        let lit = match (&self.irradiance, lighting) {
            (Some(field), false) => {
                let mut corners = [0u32; 8];
                for (c, v) in corners.iter_mut().enumerate() {
                    *v = voxel_index(self.vol.dims, corner(base, c))
                        .map_or(0, |i| u32::from(field[i]));
                }
                Some(corners)
            }
            _ => None,
        };
        let out = self.sampler.sample(&SampleIn {
            voxels,
            weights,
            irr: lit,
            color: ray.color,
            opacity: ray.opacity,
            lighting,
            grad_idx: field(vw + tag_w, grad_w),
            tags: field(vw, tag_w),
        });
        ray.color = out.color;
        ray.opacity = out.opacity;
        out.terminated
    }

    /// The splat of a lighting ray's sample ([362], [381]; contract, *Global illumination*): the
    /// energy of corner `c` of the sample's cell, `min(rnd(E * T * dr * w_c, 42), 2^16 - 1)`
    /// (`U(2.14)`), `E` the ray's energy (`red`), `T = 4096 - opacity` the light left before this
    /// sample (4096 for a photon), `w_c` the product of the corner's three weights (`256 - f` or
    /// `f`, `U(1.8)` each); 0 for a corner outside the volume. A function of the packet alone.
    pub fn deposit_energies(&self, ray: &RayPacket) -> [u32; 8] {
        let base = ray.start.map(|c| i64::from(c >> POS_FRAC_W));
        let f = ray.start.map(|c| c & ((1 << POS_FRAC_W) - 1));
        let t = if self.photon_albedo.is_some() {
            CHAN_MAX + 1
        } else {
            CHAN_MAX + 1 - u32::from(ray.opacity)
        };
        let inside = std::array::from_fn(|c| voxel_index(self.vol.dims, corner(base, c)).is_some());
        deposit::energies(u32::from(ray.color[0]), t, self.cfg.step, f, inside)
    }

    /// One pipeline cycle on a ray of queue `q`: a sample (or a leap), then the advance.
    fn advance(
        &self,
        mut ray: RayPacket,
        q: u32,
        counts: &mut ProcessorCounts,
        cache: Option<&mut FrameCache>,
        irr: Option<&mut [u16]>,
    ) -> Outcome {
        let leap =
            ray.ray_type == RayType::Rendering && self.cfg.space_leap && self.empty[q as usize];
        if leap {
            counts.leaps += 1;
        } else {
            counts.samples += 1;
            // A lighting ray's deposit in a lighting pass: a function of the packet before
            // this sample (contract, *Global illumination*).
            let energies = (irr.is_some() && ray.ray_type == RayType::Lighting)
                .then(|| self.deposit_energies(&ray));
            // The cell's eight words, through the volume cache (contract, *The volume cache*):
            // a read, or the deposit itself when the words hold the field.
            let base = ray.start.map(|c| i64::from(c >> POS_FRAC_W));
            let words = match cache {
                Some(cache) => cache.sample(base, energies, counts),
                None => std::array::from_fn(|c| self.word_of(corner(base, c))),
            };
            let terminated = self.sample(&mut ray, words, energies, irr);
            if let Some(albedo) = self.photon_albedo {
                // A photon interacts when its opacity reaches its interaction value [364].
                if u32::from(ray.opacity) << 4 >= u32::from(ray.interaction) {
                    let bits = ray_bits(&ray);
                    if jenkins_hash(bits ^ ALBEDO_KEY) & 0xffff < albedo && ray.lifetime > 0 {
                        let out = self.scatter.scatter(&ScatterIn {
                            dir: ray.dir.map(i32::from),
                            grad: [0; 3],
                            refl: 0,
                            refr: 0,
                            iso: 1 << ScatterConfig::DEFAULT.mat_w,
                            gloss: 0,
                            eta: 1 << ScatterConfig::DEFAULT.mat_w,
                            ray_bits: bits,
                        });
                        ray.dir = out.dir.map(|d| d as i16);
                        ray.opacity = 0;
                        ray.generation = ray.generation.saturating_add(1);
                        ray.lifetime -= 1;
                        ray.interaction = interaction_draw(ray_bits(&ray));
                        counts.scatterings += 1;
                    } else {
                        counts.absorbed += 1;
                        return Outcome::Done(ray);
                    }
                }
            } else if terminated && self.cfg.et_threshold.is_some() {
                ray.flags |= flag::TERMINATED;
                counts.rays_terminated += 1;
                return Outcome::Done(ray);
            }
        }
        // Leap (k steps) or one step, exit test and re-bucketing: the step unit (gicube_step).
        let s = self.stepper.step(ray.start, ray.dir, q, leap);
        if s.exit {
            return Outcome::Done(ray);
        }
        ray.start = s.next;
        Outcome::Next(ray)
    }

    /// The host's packets of a frame, in its order.
    fn frame_packets(&self, cam: &Camera, proj: Projection) -> Result<Vec<RayPacket>> {
        let rays = host_rays(&self.vol, cam, proj, self.cfg.host_order)?;
        rays.iter().map(Self::packet).collect()
    }

    /// Renders a frame: the host makes the rays (`host_rays`), offers the head of its list in
    /// every cycle with a free sorter slot (accepted when its queue has room), and takes back
    /// finished and overflowed rays (appending the latter to its list) until every ray finished.
    pub fn render(&self, cam: &Camera, proj: Projection) -> Result<ProcessorFrame> {
        let packets = self.frame_packets(cam, proj)?;
        self.run(packets, cam.width, cam.height, None, None, None)
    }

    /// `render`, and every step the frame loop made on its ray queues, in order: the frame's queue
    /// traffic, which the RTL queues (`gicube_ray_queues`) replay in the co-simulation.
    pub fn render_traced(
        &self,
        cam: &Camera,
        proj: Projection,
    ) -> Result<(ProcessorFrame, Vec<QueueOp>)> {
        let packets = self.frame_packets(cam, proj)?;
        let mut trace = FrontTrace::default();
        let f = self.run(packets, cam.width, cam.height, None, Some(&mut trace), None)?;
        Ok((f, trace.0))
    }

    /// `render`, and every processor cycle's input to the queue front end (`take`, the ring's
    /// ray, the host's offer), in order: the traffic that the RTL front end
    /// (`gicube_queue_front`) replays in the co-simulation.
    pub fn render_front_traced(
        &self,
        cam: &Camera,
        proj: Projection,
    ) -> Result<(ProcessorFrame, Vec<FrontTraffic<RayPacket>>)> {
        let packets = self.frame_packets(cam, proj)?;
        let mut trace = FrontTrace::default();
        let f = self.run(packets, cam.width, cam.height, None, Some(&mut trace), None)?;
        Ok((f, trace.1))
    }

    /// `render`, and the AXI4 bursts of the volume cache's misses in order (contract, *The volume
    /// cache*): the AR stream of the RTL's memory port (empty without a cache).
    pub fn render_cache_traced(
        &self,
        cam: &Camera,
        proj: Projection,
    ) -> Result<(ProcessorFrame, Vec<Burst>)> {
        let packets = self.frame_packets(cam, proj)?;
        let mut t = CacheTrace::default();
        let f = self.run(packets, cam.width, cam.height, None, None, Some(&mut t))?;
        Ok((f, t.reads))
    }

    /// The frame loop over the host's `packets` (rendering rays made by any host, not only
    /// `host_rays`: each starts inside the volume, its pixel `(u, v)` inside `w x h` and its own),
    /// the bursts of its cache's misses and every ray that left the processor, in order
    /// (`CacheTrace::outputs`): the million-ray co-simulation's reference.
    pub fn run_packets_traced(
        &self,
        packets: Vec<RayPacket>,
        w: u32,
        h: u32,
    ) -> Result<(ProcessorFrame, CacheTrace)> {
        let mut seen = vec![false; (w as usize) * (h as usize)];
        for p in &packets {
            let (u, v) = (u32::from(p.u), u32::from(p.v));
            let i = (v as usize) * (w as usize) + u as usize;
            if u >= w || v >= h || std::mem::replace(&mut seen[i], true) {
                return Err(ModelError::Config(format!(
                    "gicube processor: packet pixel ({u}, {v}) outside {w}x{h} or given twice"
                )));
            }
        }
        let mut t = CacheTrace::default();
        let f = self.run(packets, w, h, None, None, Some(&mut t))?;
        Ok((f, t))
    }

    /// The lighting pass of volumetric GI ([358]-[363], low albedo, single scattering): lighting
    /// rays from `light` through the same queues and pipeline, each splatting into a fresh
    /// irradiance field, which then lights every rendering ray of `render` (until the next
    /// `light`). Returns the pass's counts (its image is the lighting grid, all 0).
    pub fn light(&mut self, light: &GiLight) -> Result<ProcessorFrame> {
        self.light_pass(light, None)
    }

    /// `light`, and what its volume cache did (contract, *Splatting through the cache*): the AR
    /// and AW bursts in order, the flush's included, and the words memory holds after the flush
    /// (the volume and, above it when the words hold the field, the irradiance).
    pub fn light_cache_traced(&mut self, light: &GiLight) -> Result<(ProcessorFrame, CacheTrace)> {
        let mut t = CacheTrace::default();
        let f = self.light_pass(light, Some(&mut t))?;
        Ok((f, t))
    }

    fn light_pass(
        &mut self,
        light: &GiLight,
        trace: Option<&mut CacheTrace>,
    ) -> Result<ProcessorFrame> {
        let (rays, energy) = light_rays(&self.vol, light, self.cfg.host_order)?;
        let mut packets = rays
            .iter()
            .map(|r| Self::light_packet(r, energy))
            .collect::<Result<Vec<_>>>()?;
        self.photon_albedo = match light.mode {
            GiMode::LowAlbedo => None,
            GiMode::HighAlbedo { albedo, lifetime } => {
                for p in &mut packets {
                    p.lifetime = lifetime;
                    p.interaction = interaction_draw(ray_bits(p));
                }
                Some(albedo_raw(albedo))
            }
        };
        let mut field = vec![0u16; self.vol.len()];
        // The field starts at 0: memory holds the volume alone.
        self.irradiance = None;
        self.load_cache()?;
        let f = self.run(
            packets,
            light.grid,
            light.grid,
            Some(&mut field),
            None,
            trace,
        );
        self.photon_albedo = None;
        self.irradiance = Some(field);
        self.load_cache()?;
        f
    }

    /// The loaded irradiance field (`U(2.14)` per voxel, x fastest), if a lighting pass ran.
    pub fn irradiance(&self) -> Option<&[u16]> {
        self.irradiance.as_deref()
    }

    /// The packet of a lighting ray: type `Lighting`, energy in `red` (`U(0.12)`).
    pub fn light_packet(ray: &HostRay, energy: f64) -> Result<RayPacket> {
        let mut p = Self::packet(ray)?;
        p.ray_type = RayType::Lighting;
        p.color = [0; 3];
        p.color[0] = RayPacket::from_real(&RayReal {
            color: [energy, 0.0, 0.0],
            ..p.to_real()
        })?
        .color[0];
        Ok(p)
    }

    /// The frame loop (contract § The frame) over the host's packets.
    fn run(
        &self,
        packets: Vec<RayPacket>,
        w: u32,
        h: u32,
        mut irr: Option<&mut Vec<u16>>,
        trace: Option<&mut FrontTrace>,
        cache_trace: Option<&mut CacheTrace>,
    ) -> Result<ProcessorFrame> {
        let rays = packets.len();
        let packets_lives = packets
            .iter()
            .map(|p| u64::from(p.lifetime) + 1)
            .max()
            .unwrap_or(1);
        let mut feed: VecDeque<RayPacket> = packets.into();
        let nq = self.queues();
        // The queue front end (arbiter, bucketing, ray queues, sorter): the one description of a
        // processor cycle's queue traffic (`gicube_queue_front`, the RTL's model).
        let chooser = match self.cfg.order {
            QueueOrder::Sorter => Chooser::Sorter,
            QueueOrder::Scan => Chooser::Scan,
        };
        let mut front: QueueFront<RayPacket> = QueueFront::new(
            self.cfg.block_log2,
            self.blocks,
            self.cfg.queue_len,
            self.cfg.ranks,
            chooser,
        )?;
        if trace.is_some() {
            front.trace();
        }
        let mut counts = ProcessorCounts {
            rays_made: rays as u64,
            ..Default::default()
        };
        let mut rgb = vec![[0u16; 3]; (w * h) as usize];
        let mut done = vec![false; (w * h) as usize];
        // The volume cache from reset (contract, *The volume cache*).
        let mut cache = self.frame_cache(cache_trace.is_some());
        let mut outputs = cache_trace.is_some().then(Vec::new);
        let mut last_active: Option<u32> = None;
        // A cycle bound far above any frame: a livelock is a model bug, reported, not a hang.
        // Per ray and life: at most 2 N 256 / step samples along a path (sqrt 3 N < 2 N), plus
        // waiting for the queues; a photon has `lifetime + 1` paths.
        let lives = packets_lives;
        let per_path =
            2 * u64::from(self.side) * 256 / u64::from(self.cfg.step) + u64::from(nq) + 64;
        let lat = self.cfg.ring_latency as usize;
        let bound = 64 + 8 * rays as u64 * lives * per_path * (1 + lat as u64);
        // The ring (contract, *The ring*): `ring_latency` slots, each the outcome of one cycle's
        // popped ray (or none), oldest first.
        let mut ring: VecDeque<Option<Outcome>> = (0..lat).map(|_| None).collect();

        while !feed.is_empty() || front.total() > 0 || ring.iter().any(Option::is_some) {
            let held = u64::from(front.total());
            counts.cycles += 1;
            if counts.cycles > bound {
                return Err(ModelError::Config(format!(
                    "gicube processor: no progress after {bound} cycles ({held} rays queued)"
                )));
            }
            counts.occupancy_sum += held;
            // The host offers the head of its list (it clips its rays to the volume: a packet
            // outside it is a bug); a ray it is not taken stays at the head.
            let offer = match feed.front() {
                Some(ray) if self.queue_of(ray.start).is_none() => {
                    return Err(ModelError::Config(format!(
                        "gicube processor: host ray of pixel ({}, {}) starts outside the volume",
                        ray.u, ray.v
                    )))
                }
                o => o.copied(),
            };
            let c = front.cycle(
                true,
                |popped| {
                    // The popped ray's cycle (sample or leap, advance) enters the ring; the
                    // outcome leaving it now is the one that entered `ring_latency` cycles ago.
                    let entered = match popped {
                        Some((q, ray)) => {
                            let irr = irr.as_deref_mut().map(|v| v.as_mut_slice());
                            Some(self.advance(ray, q, &mut counts, cache.as_mut(), irr))
                        }
                        None => None,
                    };
                    ring.push_back(entered);
                    match ring.pop_front().flatten() {
                        None => Ok(None),
                        Some(Outcome::Next(ray)) => Ok(Some(ray)),
                        Some(Outcome::Done(ray)) => {
                            counts.rays_finished += 1;
                            let i = (u32::from(ray.v) * w + u32::from(ray.u)) as usize;
                            if done[i] {
                                return Err(ModelError::Config(format!(
                                    "gicube processor: pixel ({}, {}) finished twice",
                                    ray.u, ray.v
                                )));
                            }
                            done[i] = true;
                            rgb[i] = ray.color;
                            if let Some(o) = outputs.as_mut() {
                                o.push((true, ray));
                            }
                            Ok(None)
                        }
                    }
                },
                offer,
            )?;
            if c.active.is_some() && c.active != last_active {
                counts.activations += 1;
            }
            last_active = c.active;
            if c.popped.is_none() && held > 0 {
                counts.idle_cycles += 1;
            }
            if let Some(ray) = c.ring_ovf {
                // Returned with OVERFLOW set; the host offers it again after the rays it holds.
                counts.rays_overflowed += 1;
                if let Some(o) = outputs.as_mut() {
                    o.push((false, ray));
                }
                feed.push_back(ray);
            }
            if c.host_taken {
                feed.pop_front();
                counts.rays_in += 1;
            }
            counts.host_stalls += u64::from(c.host_stall);
            for u in &c.updates {
                counts.max_queue = counts.max_queue.max(front.queues().len(u.queue));
            }
        }
        if let Some(t) = trace {
            *t = front.take_trace();
        }
        if let Some(c) = cache.as_mut() {
            // A lighting pass ends with a flush: memory holds every deposit (contract,
            // *Splatting through the cache*).
            if irr.is_some() {
                c.flush();
            }
        }
        if let (Some(t), Some(c)) = (cache_trace, cache) {
            *t = CacheTrace {
                memory: c.cache.memory_words().to_vec(),
                outputs: outputs.unwrap_or_default(),
                ..c.trace.unwrap_or_default()
            };
        }
        Ok(ProcessorFrame {
            width: w,
            height: h,
            rgb,
            counts,
        })
    }

    /// The f64 reference of the same algorithm: the host's rays before quantization, samples at
    /// `entry + k dr dir` until the point leaves `[0, N)^3`, f64 tri-linear density, the transfer
    /// function itself, `alpha' = 1 - (1 - alpha)^dr`, front-to-back over in f64, termination at
    /// the same threshold. No queues, no leaping (leaping is exact).
    pub fn reference(
        &self,
        tf: &TransferFunction,
        cam: &Camera,
        proj: Projection,
    ) -> Result<Vec<[f64; 3]>> {
        self.reference_with(tf, cam, proj, None)
    }

    /// `reference`, each sample's colour multiplied by the f64 irradiance `irr` (clamped to 1).
    fn reference_with(
        &self,
        tf: &TransferFunction,
        cam: &Camera,
        proj: Projection,
        irr: Option<&[f64]>,
    ) -> Result<Vec<[f64; 3]>> {
        let rays = host_rays(&self.vol, cam, proj, HostOrder::RowMajor)?;
        let mut img = vec![[0.0; 3]; (cam.width * cam.height) as usize];
        let dr = self.cfg.step_voxels();
        let n = f64::from(self.side);
        let max = f64::from(self.vol.max_value());
        let thr = self.cfg.et_threshold.map(|t| f64::from(t) / 4096.0);
        let jit = self.cfg.jitter.then(|| Jitter::new(self.cfg.step));
        for r in &rays {
            let (mut c, mut a) = ([0.0f64; 3], 0.0f64);
            for k in 0.. {
                let p = r.entry + r.dir * (k as f64 * dr);
                if p.to_array().iter().any(|&x| !(0.0..n).contains(&x)) {
                    break;
                }
                let rgba = tf.lookup(self.vol.sample_f64(p.to_array()) / max);
                // Jitter: the factor at the position's 8 fraction bits, as the packet has them.
                let r_j = jit.as_ref().map_or(1.0, |j| {
                    j.factor(jitter_index(
                        p.to_array()
                            .map(|x| (x.fract() * f64::from(1u32 << POS_FRAC_W)) as u32),
                    ))
                });
                let w = (1.0 - a) * corrected_alpha(rgba[3], r_j * dr);
                let light = irr.map_or(1.0, |f| field_f64(f, self.vol.dims, p));
                let rgb = match &self.shading {
                    Some(sh) => self.shade_f64(sh, [rgba[0], rgba[1], rgba[2]], p, irr.is_some()),
                    None => [rgba[0], rgba[1], rgba[2]],
                };
                for i in 0..3 {
                    c[i] += w * (rgb[i] * light).min(1.0);
                }
                a += w;
                if thr.is_some_and(|t| a >= t) {
                    break;
                }
            }
            img[(r.py * cam.width + r.px) as usize] = c;
        }
        Ok(img)
    }
}

impl Processor {
    /// The f64 reference's shading of a sample at `p` (contract, *Shading and jitter in the
    /// processor*): the colour of the nearest voxel's tag; unless the ray is lit by irradiance,
    /// Phong with the map's lights at the tri-linear interpolation of the voxels' unit gradient
    /// directions (the ambient term alone where it is zero), `rgb d + sp 256/255`, the
    /// intensities capped at the texels' largest codes.
    fn shade_f64(&self, sh: &Shading, rgb: [f64; 3], p: DVec3, lit: bool) -> [f64; 3] {
        let near = (p + DVec3::splat(0.5)).floor().as_i64vec3().to_array();
        let t = voxel_index(self.vol.dims, near).map_or(0, |i| u32::from(sh.tags[i]));
        let rgb = tag_rgb(rgb, t);
        if lit {
            return rgb;
        }
        let f = p.floor();
        let mut g = DVec3::ZERO;
        for (c, w) in corner_weights(p - f) {
            if let Some(i) = voxel_index(self.vol.dims, corner(f.as_i64vec3().to_array(), c)) {
                g += w * sh.dirs[i];
            }
        }
        let scfg = self.sampler.shader().config();
        let (d, sp) = if g == DVec3::ZERO {
            (sh.phong.ambient, 0.0)
        } else {
            sh.phong.intensities(g.to_array())
        };
        let d = d.min(f64::from(scfg.diff_max()) / f64::from(1u32 << (scfg.diff_w - 1)));
        let sp = sp.min(f64::from(scfg.spec_max()) / f64::from(1u32 << scfg.spec_w));
        let k = f64::from(1u32 << scfg.color_w) / f64::from(scfg.color_max());
        rgb.map(|c| c * d + sp * k)
    }
}

/// PSNR (dB, peak 1.0) and largest channel error of `a` against `b`.
pub fn psnr(a: &[[f64; 3]], b: &[[f64; 3]]) -> (f64, f64) {
    let mut se = 0.0;
    let mut max = 0.0f64;
    for (x, y) in a.iter().zip(b) {
        for i in 0..3 {
            let d = x[i] - y[i];
            se += d * d;
            max = max.max(d.abs());
        }
    }
    let mse = se / (3 * a.len().max(1)) as f64;
    let p = if mse > 0.0 {
        -10.0 * mse.log10()
    } else {
        f64::INFINITY
    };
    (p, max)
}

/// How lighting rays carry energy ([363], [364]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GiMode {
    /// Bundles that deposit along the whole ray, attenuated by their opacity; no scattering.
    LowAlbedo,
    /// Photons of indivisible energy: they deposit unattenuated until their opacity reaches their
    /// interaction value, then scatter isotropically with probability `albedo` (at most
    /// `lifetime` times) or are absorbed.
    HighAlbedo { albedo: f64, lifetime: u8 },
}

/// A distant light for the lighting pass: a square grid of parallel lighting rays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GiLight {
    /// Unit direction the light travels (from the light into the volume), voxel coordinates.
    pub dir: DVec3,
    /// Irradiance `E0` on a plane facing the light; 1.0 lights a sample at its full classified
    /// colour.
    pub energy: f64,
    /// Lighting rays per side of the grid (the grid covers the volume's bounding sphere).
    pub grid: u32,
    pub mode: GiMode,
}

/// The lighting rays of `light` that meet the voxel-centre box, and the energy of each,
/// `E0 h^2` (`h` = the grid spacing in voxels: each ray stands for `h^2` of the light's area).
/// The grid: `c` = the volume's centre, `r` = half its diagonal, `h = 2r / grid`; axes
/// `right = normalize(dir x z)` (`x y` when `|dir.z| > 0.999`) and `up = right x dir`; ray
/// `(i, j)` starts at `c + right ((i + 1/2) h - r) + up (r - (j + 1/2) h) - dir (r + 1)`.
pub fn light_rays(vol: &Volume, light: &GiLight, order: HostOrder) -> Result<(Vec<HostRay>, f64)> {
    let bad = |m: String| Err(ModelError::Config(format!("gicube lighting pass: {m}")));
    let d = light.dir;
    if !d.is_finite() || (d.length() - 1.0).abs() > 1e-6 {
        return bad(format!("light direction {d} is not a unit vector"));
    }
    if !(1..=4096).contains(&light.grid) {
        return bad(format!("grid {} outside 1..=4096", light.grid));
    }
    if !(light.energy.is_finite() && light.energy >= 0.0) {
        return bad(format!("energy {} must be finite and >= 0", light.energy));
    }
    if let GiMode::HighAlbedo { albedo, .. } = light.mode {
        if !(0.0..=1.0).contains(&albedo) {
            return bad(format!("albedo {albedo} outside 0..=1"));
        }
    }
    let dims = DVec3::new(vol.dims[0] as f64, vol.dims[1] as f64, vol.dims[2] as f64);
    let c = (dims - DVec3::ONE) * 0.5;
    let r = dims.length() * 0.5;
    let h = 2.0 * r / f64::from(light.grid);
    let energy = light.energy * h * h;
    if energy >= 1.0 {
        return bad(format!(
            "energy per ray E0 h^2 = {energy:.3} is not below 1 (the packet's U(0.12)): use a grid of at least {} rays",
            (2.0 * r * light.energy.sqrt()).floor() as u32 + 1
        ));
    }
    let a = if d.z.abs() > 0.999 {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let right = d.cross(a).normalize();
    let up = right.cross(d);
    let hi = dims - DVec3::ONE;
    let mut rays = Vec::new();
    let mut push = |i: u32, j: u32| {
        let o = c + right * ((f64::from(i) + 0.5) * h - r) + up * (r - (f64::from(j) + 0.5) * h)
            - d * (r + 1.0);
        if let Some(t) = clip(o, d, hi) {
            rays.push(HostRay {
                px: i,
                py: j,
                entry: (o + d * t).clamp(DVec3::ZERO, hi),
                dir: d,
            });
        }
    };
    let n = light.grid;
    match order {
        HostOrder::RowMajor => (0..n).for_each(|j| (0..n).for_each(|i| push(i, j))),
        HostOrder::Reversed => (0..n)
            .rev()
            .for_each(|j| (0..n).rev().for_each(|i| push(i, j))),
    }
    Ok((rays, energy))
}

/// The eight corners' exact tri-linear weights for the fraction `t`.
fn corner_weights(t: DVec3) -> impl Iterator<Item = (usize, f64)> {
    (0..8usize).map(move |c| {
        let w = (0..3).fold(1.0, |acc, a| {
            acc * if (c >> a) & 1 == 1 { t[a] } else { 1.0 - t[a] }
        });
        (c, w)
    })
}

/// Tri-linear interpolation of an f64 field over the volume's voxels (0 outside).
fn field_f64(field: &[f64], dims: [usize; 3], p: DVec3) -> f64 {
    let f = p.floor();
    let t = p - f;
    let mut acc = 0.0;
    for (c, w) in corner_weights(t) {
        if let Some(i) = voxel_index(dims, corner(f.as_i64vec3().to_array(), c)) {
            acc += w * field[i];
        }
    }
    acc
}

impl Processor {
    /// The f64 reference of the lighting pass: the same lighting rays before quantization,
    /// samples at `entry + k dr dir` in `[0, N)^3`, each splatting `E T dr w_c` (exact weights)
    /// into the voxels of its cell, then `T *= 1 - alpha'`, stopping at the termination threshold.
    pub fn reference_irradiance(&self, tf: &TransferFunction, light: &GiLight) -> Result<Vec<f64>> {
        if light.mode != GiMode::LowAlbedo {
            return Err(ModelError::Config(
                "gicube lighting pass: the f64 reference is low albedo only (high albedo: compare with the Monte Carlo reference)".into(),
            ));
        }
        let (rays, energy) = light_rays(&self.vol, light, HostOrder::RowMajor)?;
        let mut field = vec![0.0; self.vol.len()];
        let dr = self.cfg.step_voxels();
        let n = f64::from(self.side);
        let max = f64::from(self.vol.max_value());
        let thr = self.cfg.et_threshold.map(|t| f64::from(t) / 4096.0);
        for r in &rays {
            let mut t_left = 1.0f64;
            for k in 0.. {
                let p = r.entry + r.dir * (k as f64 * dr);
                if p.to_array().iter().any(|&x| !(0.0..n).contains(&x)) {
                    break;
                }
                let f = p.floor();
                for (c, w) in corner_weights(p - f) {
                    if let Some(i) =
                        voxel_index(self.vol.dims, corner(f.as_i64vec3().to_array(), c))
                    {
                        field[i] += energy * t_left * dr * w;
                    }
                }
                let a = corrected_alpha(tf.lookup(self.vol.sample_f64(p.to_array()) / max)[3], dr);
                t_left *= 1.0 - a;
                if thr.is_some_and(|t| 1.0 - t_left >= t) {
                    break;
                }
            }
        }
        Ok(field)
    }

    /// The f64 reference of a GI frame: `reference_irradiance`, then the rendering rays of
    /// `reference` with each sample's colour `min(1, rgb * irradiance(p))`.
    pub fn reference_gi(
        &self,
        tf: &TransferFunction,
        light: &GiLight,
        cam: &Camera,
        proj: Projection,
    ) -> Result<Vec<[f64; 3]>> {
        let field = self.reference_irradiance(tf, light)?;
        self.reference_with(tf, cam, proj, Some(&field))
    }
}

/// The error of a fixed-point irradiance field (`U(2.14)`) against the f64 one: the largest
/// absolute error over the voxels not on the volume's faces (a face voxel gets deposits from one
/// side only, and whether a ray's last sample falls before the face or past it differs between
/// the fixed-point and the exact position: a whole sample's deposit), and the mean over all.
pub fn irradiance_error(field: &[u16], reference: &[f64], dims: [usize; 3]) -> (f64, f64) {
    let scale = f64::from(1u32 << IRR_FRAC_W);
    let (mut max, mut sum) = (0.0f64, 0.0);
    for (i, (&a, &b)) in field.iter().zip(reference).enumerate() {
        let e = (f64::from(a) / scale - b).abs();
        sum += e;
        let v = [
            i % dims[0],
            (i / dims[0]) % dims[1],
            i / (dims[0] * dims[1]),
        ];
        if (0..3).all(|k| v[k] > 0 && v[k] + 1 < dims[k]) {
            max = max.max(e);
        }
    }
    (max, sum / field.len().max(1) as f64)
}

/// Extinction per voxel of a transfer function's opacity: `sigma = -ln(1 - alpha)` (alpha is the
/// opacity of one voxel of path, so `1 - exp(-sigma d) = 1 - (1 - alpha)^d`).
fn extinction(alpha: f64) -> f64 {
    -(-alpha.min(1.0 - 1e-12)).ln_1p()
}

/// A Monte Carlo reference in f64 of the physics the GI method approximates, per pixel the mean
/// of `paths` estimates of `L = int T_eye(s) sigma(x) rgb(x) phi(x) ds` over the rendering ray
/// from its entry to `[0, N)^3`'s exit (the eye-side phase function and albedo folded into
/// `rgb`), with `sigma = -ln(1 - alpha)` of the continuous tri-linear density and `phi` the
/// fluence: low albedo (single scattering with shadows) `phi = E0 T_light(x)`; high albedo
/// `phi(x) = E0 T_light(x) + albedo * phi(y)`, `y` the next collision along a uniformly random
/// direction (isotropic scattering), at most `lifetime` bounces. Delta tracking with the majorant
/// `max sigma` of the transfer function's points; ratio tracking of `T_light` toward the light.
/// Seeded: the same seed gives the same image.
#[allow(clippy::too_many_arguments)]
pub fn monte_carlo_gi(
    vol: &Volume,
    tf: &TransferFunction,
    light: &GiLight,
    cam: &Camera,
    proj: Projection,
    block_log2: u32,
    paths: u32,
    seed: u64,
) -> Result<Vec<[f64; 3]>> {
    use rand::{Rng, SeedableRng};
    let (_, side) = domain(vol, block_log2)?;
    let n = f64::from(side);
    let rays = host_rays(vol, cam, proj, HostOrder::RowMajor)?;
    let max = f64::from(vol.max_value());
    let sigma_max = tf
        .points
        .iter()
        .map(|p| extinction(p.rgba[3]))
        .fold(0.0, f64::max);
    let mut img = vec![[0.0; 3]; (cam.width * cam.height) as usize];
    if sigma_max <= 0.0 || paths == 0 {
        return Ok(img);
    }
    let inside = |p: DVec3| p.to_array().iter().all(|&x| (0.0..n).contains(&x));
    let sigma = |p: DVec3| extinction(tf.lookup(vol.sample_f64(p.to_array()) / max)[3]);
    // From `p` along `w`: with `collide`, delta tracking to the next collision (`None` if the
    // path leaves the volume first); without, ratio tracking of the transmittance to the exit.
    let track = |rng: &mut rand_chacha::ChaCha8Rng, p: DVec3, w: DVec3, collide: Option<()>| {
        let (mut s, mut t) = (0.0, 1.0);
        loop {
            s -= (1.0 - rng.random::<f64>()).ln() / sigma_max;
            let y = p + w * s;
            if !inside(y) {
                return (None, t);
            }
            let ratio = sigma(y) / sigma_max;
            if collide.is_some() {
                if rng.random::<f64>() < ratio {
                    return (Some(y), 0.0);
                }
            } else {
                t *= 1.0 - ratio;
            }
        }
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    for r in &rays {
        let mut acc = [0.0; 3];
        for _ in 0..paths {
            let mut t = 0.0;
            loop {
                t -= (1.0 - rng.random::<f64>()).ln() / sigma_max;
                let x = r.entry + r.dir * t;
                if !inside(x) {
                    break;
                }
                let rgba = tf.lookup(vol.sample_f64(x.to_array()) / max);
                if rng.random::<f64>() * sigma_max < extinction(rgba[3]) {
                    // The fluence at the collision, in units of E0: the light left on the
                    // straight path, plus (high albedo) `albedo` times the fluence at the next
                    // collision along an isotropic direction, up to `lifetime` bounces.
                    let mut fluence = 0.0;
                    let mut y = x;
                    let mut bounce = 0u32;
                    loop {
                        fluence += track(&mut rng, y, -light.dir, None).1;
                        let GiMode::HighAlbedo { albedo, lifetime } = light.mode else {
                            break;
                        };
                        if bounce >= u32::from(lifetime) || rng.random::<f64>() >= albedo {
                            break;
                        }
                        bounce += 1;
                        let z = 2.0 * rng.random::<f64>() - 1.0;
                        let phi = std::f64::consts::TAU * rng.random::<f64>();
                        let s = (1.0 - z * z).max(0.0).sqrt();
                        let w = DVec3::new(s * phi.cos(), s * phi.sin(), z);
                        match track(&mut rng, y, w, Some(())).0 {
                            Some(next) => y = next,
                            None => break,
                        }
                    }
                    for c in 0..3 {
                        acc[c] += rgba[c] * light.energy * fluence;
                    }
                    break;
                }
            }
        }
        img[(r.py * cam.width + r.px) as usize] = acc.map(|a| a / f64::from(paths));
    }
    Ok(img)
}

/// The example GI scene: a translucent floor slab and a denser sphere above it, on `n^3` voxels of
/// 12 bits (`phantom::sphere_floor_phantom`, boundaries 1.5 voxels wide), its transfer function, and a light from the upper left
/// that casts the sphere's shadow onto the floor.
pub fn shadow_scene(n: usize) -> Result<(Volume, TransferFunction, GiLight)> {
    let nf = n as f64;
    let vol = crate::phantom::sphere_floor_phantom(n, 12)?;
    let pt = |density, rgba| crate::transfer::TfPoint { density, rgba };
    let tf = TransferFunction::new(vec![
        pt(0.0, [0.0; 4]),
        pt(0.25, [0.95, 0.9, 0.8, 0.0]),
        pt(0.45, [0.95, 0.9, 0.8, 0.35]),
        pt(0.6, [0.55, 0.75, 0.95, 0.5]),
        pt(1.0, [0.55, 0.75, 0.95, 0.8]),
    ])?;
    let light = GiLight {
        dir: DVec3::new(0.55, 0.25, -0.8).normalize(),
        energy: 0.95,
        grid: (2.0 * nf * 3f64.sqrt()).ceil() as u32,
        mode: GiMode::LowAlbedo,
    };
    Ok((vol, tf, light))
}

/// What a ring of processors (`gicube_ring`, docs/numerics/gicube_ring.md) uses of one: each
/// of its processors is this one, its cycle's parts called by the ring's cycle loop.
impl Processor {
    /// The volume cache of a frame from reset (contract, *The volume cache*); `traced`: it
    /// records its bursts.
    pub(crate) fn frame_cache(&self, traced: bool) -> Option<FrameCache> {
        self.cache.as_ref().map(|c| FrameCache {
            cache: c.clone(),
            splats: self.field_in_words(&c.config()),
            trace: traced.then(CacheTrace::default),
        })
    }

    /// The AR bursts a traced frame cache recorded, in order.
    pub(crate) fn frame_cache_reads(cache: FrameCache) -> Vec<Burst> {
        cache.trace.map(|t| t.reads).unwrap_or_default()
    }

    /// One pipeline cycle on a ray of queue `q` of a rendering frame (no lighting pass).
    pub(crate) fn ring_advance(
        &self,
        ray: RayPacket,
        q: u32,
        counts: &mut ProcessorCounts,
        cache: Option<&mut FrameCache>,
    ) -> Outcome {
        self.advance(ray, q, counts, cache, None)
    }

    /// The host's packets of a frame, in its order.
    pub(crate) fn ring_packets(&self, cam: &Camera, proj: Projection) -> Result<Vec<RayPacket>> {
        self.frame_packets(cam, proj)
    }

    /// Blocks a side `B`.
    pub fn blocks(&self) -> u32 {
        self.blocks
    }

    /// The queue of a position inside the volume (`None` outside).
    pub(crate) fn ring_queue_of(&self, pos: [u32; 3]) -> Option<u32> {
        self.queue_of(pos)
    }
}

/// The RTL top `gicube_processor`'s parameters (contract, *The RTL*): the front end's, the voxel
/// width, the sample distance, the ring latency and the volume cache's. Every parameter is a
/// field of the model ([`ProcessorRtlConfig::processor_config`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProcessorRtlConfig {
    /// Block side `n = 2^block_log2` voxels, 2..=8.
    pub block_log2: u32,
    /// Blocks a side `B`, 1..=6; `N = B n <= 64` voxels a side.
    pub vol_blocks: u32,
    /// Rays per queue, 1..=4096.
    pub queue_len: u32,
    /// Sorter ranks, 2..=64 and at most the queues.
    pub ranks: u32,
    /// Bits per voxel, 4..=16.
    pub voxel_w: u32,
    /// Sample distance `dr`, `U(4.8)` voxels, 16..=1024.
    pub step: u32,
    /// Ring latency, processor cycles, 1..=16 (the model's `ring_latency`).
    pub ring_lat: u32,
    /// The volume cache's AXI4 data bus, line, sets and bursts in flight (`gicube_cache`'s
    /// `DataW`, `LineVox`, `Sets`, `Outstanding`; the others derived: [`Self::cache_config`]).
    pub data_w: u32,
    pub line_vox: u32,
    pub sets: u32,
    pub outstanding: u32,
    /// The cache's `Prefetch` (requests checked ahead of the data read): clocks
    /// only, never a pixel or a count.
    pub prefetch: u32,
    /// 1: the lighting pass of GI (contract, *Splatting through the cache*): 32-bit words with
    /// the irradiance field above the voxel, the cache's `Splat = 1` and its AXI4 write port, the
    /// deposit energies, the flush; the rendering rays lit by the field. 0: direct volume
    /// rendering only.
    pub light: u32,
    /// 1 (with `light`): high-albedo photons scatter in the ring (contract, *Photons in the
    /// ring*): the scattering unit, the photon registers, the scatterings count in the output.
    pub scatter: u32,
    /// 1: jitter (the model's `jitter`: `gicube_sample`'s random, log and power LUTs).
    pub jitter: u32,
    /// 1 (`light = 0`): shading (contract, *Shading and jitter in the processor*): voxel words
    /// of density, tag and gradient index, `gicube_sample`'s `Shade = 1`.
    pub shade: u32,
    /// Gradient index bits of a voxel word (`shade`), 2..=11.
    pub grad_idx_w: u32,
    /// Tag bits of a voxel word (`shade`), 0..=4; 0 without `shade`.
    pub tag_w: u32,
    /// Processors of the ring this one is in (docs/numerics/gicube_ring.md: 1 alone, 2 or 4 in
    /// `gicube_ring`) and its index there; a processor's own lines are 1 and 0.
    pub procs: u32,
    pub proc_id: u32,
}

/// Region of a configuration address (its top two bits): `gicube_sample`'s tables, the empty
/// flags.
pub const CFG_REGION_SAMPLE: u32 = 0;
pub const CFG_REGION_EMPTY: u32 = 1;
/// `Light = 1`: the volume's dimensions (7 bits each, x lowest) and, in bit 21, `lit` (rendering
/// rays are lit by the field in the words).
pub const CFG_REGION_GI: u32 = 2;
/// `Light = 1`: a flush of the cache's dirty lines (the end of a lighting pass).
pub const CFG_REGION_FLUSH: u32 = 3;
/// `Scatter = 1`, region 2: the photon registers (the albedo `U(0.16)` in bits 0..=16, photons
/// on in bit 17).
pub const CFG_GI_PHOTONS: u32 = 1;
/// `Scatter = 1`, region 2: the bits of the next scattering-table entry above the 36 of a
/// configuration word.
pub const CFG_GI_SCATTER_HI: u32 = 2;
/// `Scatter = 1`, region 2: the scattering unit's table address `a` at `CFG_GI_SCATTER + a`.
pub const CFG_GI_SCATTER: u32 = 1 << 13;
/// Address bits of `gicube_sample`'s configuration port.
const SAMPLE_CFG_ADDR_W: u32 = 14;
/// Bits of a configuration word (`gicube_sample`'s).
const CFG_WORD_W: u32 = 36;
/// Bits of each count in an output item.
pub const COUNT_W: u32 = 32;
/// Counts in an output item (rays in, finished, overflowed, samples, leaps, cycles, cache hits,
/// cache misses).
pub const OUT_COUNTS: u32 = 8;
/// Byte address bits of the RTL's AXI4 port.
pub const RTL_ADDR_W: u32 = 32;

impl ProcessorRtlConfig {
    /// The RTL's parameter defaults.
    pub const DEFAULT: Self = Self {
        block_log2: 2,
        vol_blocks: 4,
        queue_len: 16,
        ranks: 8,
        voxel_w: 8,
        step: 256,
        ring_lat: 8,
        data_w: 64,
        line_vox: 16,
        sets: 32,
        outstanding: 8,
        prefetch: 0,
        light: 0,
        scatter: 0,
        jitter: 0,
        shade: 0,
        grad_idx_w: 11,
        tag_w: 0,
        procs: 1,
        proc_id: 0,
    };

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(ModelError::Config(format!("gicube_processor: {m}")));
        if self.jitter > 1 {
            return bad(format!("Jitter {} is not 0 or 1", self.jitter));
        }
        if self.shade > 1
            || (self.shade == 1 && self.light == 1)
            || (self.shade == 0 && self.tag_w != 0)
        {
            return bad(format!(
                "Shade {} is not 0 or 1, or with Light {}, or TagW {} without it",
                self.shade, self.light, self.tag_w
            ));
        }
        if let Some(sh) = self.shade_config() {
            sh.validate(self.voxel_w)?;
        }
        if ![1, 2, 4].contains(&self.procs)
            || self.proc_id >= self.procs
            || !self.vol_blocks.is_multiple_of(self.procs)
            || (self.procs > 1 && self.light != 0)
        {
            return bad(format!(
                "Procs {} (1, 2 or 4, dividing VolBlocks, Light 0) or ProcId {} (below it)",
                self.procs, self.proc_id
            ));
        }
        if self.light > 1 {
            return bad(format!("Light {} is not 0 or 1", self.light));
        }
        if self.scatter > self.light {
            return bad(format!(
                "Scatter {} needs Light = 1 and is 0 or 1",
                self.scatter
            ));
        }
        if !(2..=8).contains(&self.block_log2) {
            return bad(format!("BlockLog2 {} outside 2..=8", self.block_log2));
        }
        if !(1..=6).contains(&self.vol_blocks) || self.side() > 64 {
            return bad(format!(
                "VolBlocks {} outside 1..=6 or N = {} above 64",
                self.vol_blocks,
                self.side()
            ));
        }
        if !(1..=4096).contains(&self.queue_len) {
            return bad(format!("QueueLen {} outside 1..=4096", self.queue_len));
        }
        if !(2..=64).contains(&self.ranks) || self.ranks > 1 << self.queue_w() {
            return bad(format!(
                "Ranks {} outside 2..=64 or above the {} queues",
                self.ranks,
                1u32 << self.queue_w()
            ));
        }
        if !(4..=16).contains(&self.voxel_w) {
            return bad(format!("VoxelW {} outside 4..=16", self.voxel_w));
        }
        if !(16..=1024).contains(&self.step) {
            return bad(format!("Step {} outside 16..=1024", self.step));
        }
        if !(1..=MAX_RING_LATENCY).contains(&self.ring_lat) {
            return bad(format!(
                "RingLat {} outside 1..={MAX_RING_LATENCY}",
                self.ring_lat
            ));
        }
        self.cache_config().validate()
    }

    /// The shading widths (`shade`).
    pub fn shade_config(&self) -> Option<ShadeConfig> {
        (self.shade == 1).then_some(ShadeConfig {
            grad_idx_w: self.grad_idx_w,
            tag_w: self.tag_w,
        })
    }

    /// Bits of a voxel word's fields: `VoxelW`, with `shade` plus `TagW + GradIdxW`.
    pub fn fields_w(&self) -> u32 {
        self.voxel_w + self.shade * (self.tag_w + self.grad_idx_w)
    }

    /// The volume cache (contract, *The RTL*): `MaxDim` the smallest power of two above `N` (at
    /// least 4), `WordW` the smallest of 8, 16, 32 that holds the word's fields (the voxel;
    /// with `Shade` its tag and gradient index too; 32 and `Splat = 1` with `Light`), `AddrW =
    /// 32`, the rest the RTL's.
    pub fn cache_config(&self) -> CacheConfig {
        CacheConfig {
            max_dim: (self.side() + 1).next_power_of_two().max(4),
            word_w: if self.light == 1 || self.fields_w() > 16 {
                32
            } else if self.fields_w() <= 8 {
                8
            } else {
                16
            },
            data_w: self.data_w,
            line_vox: self.line_vox,
            sets: self.sets,
            outstanding: self.outstanding,
            addr_w: RTL_ADDR_W,
            splat: self.light,
            prefetch: self.prefetch,
        }
    }

    /// `N = B n`, voxels a side.
    pub fn side(&self) -> u32 {
        self.vol_blocks << self.block_log2
    }

    /// `QueueW = max(1, clog2(B^3))`.
    pub fn queue_w(&self) -> u32 {
        (self.vol_blocks.pow(3))
            .next_power_of_two()
            .trailing_zeros()
            .max(1)
    }

    /// Configuration address bits: two region bits over `gicube_sample`'s address (one more
    /// with `Shade`: its shading tables at bit 14).
    pub fn cfg_addr_w(&self) -> u32 {
        2 + SAMPLE_CFG_ADDR_W + self.shade
    }

    /// The model's configuration that this RTL renders exactly (frames and counts): the RTL's
    /// front end, step, ring latency, volume cache, jitter and shading, the model's defaults
    /// otherwise (termination at `1 - 2^-8`, space leaping, the sorter).
    pub fn processor_config(&self) -> ProcessorConfig {
        ProcessorConfig {
            block_log2: self.block_log2,
            queue_len: self.queue_len,
            ranks: self.ranks,
            step: self.step,
            ring_latency: self.ring_lat,
            cache: Some(self.cache_config()),
            jitter: self.jitter == 1,
            shade: self.shade_config(),
            ..ProcessorConfig::DEFAULT
        }
    }
}

crate::unit_config!(ProcessorRtlConfig, "gicube_processor", DEFAULT, {
    "BlockLog2" => block_log2,
    "VolBlocks" => vol_blocks,
    "QueueLen" => queue_len,
    "Ranks" => ranks,
    "VoxelW" => voxel_w,
    "Step" => step,
    "RingLat" => ring_lat,
    "DataW" => data_w,
    "LineVox" => line_vox,
    "Sets" => sets,
    "Outstanding" => outstanding,
    "Prefetch" => prefetch,
    "Light" => light,
    "Scatter" => scatter,
    "Jitter" => jitter,
    "Shade" => shade,
    "GradIdxW" => grad_idx_w,
    "TagW" => tag_w,
    "Procs" => procs,
    "ProcId" => proc_id,
});

/// One output item of the RTL: a finished or an overflowed ray, and the counts after it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ProcessorOut {
    /// Finished (exited or terminated); else returned to the host with `OVERFLOW` set.
    pub done: bool,
    /// The packet's bits.
    pub ray: [u32; crate::units::gicube_packet_loop::PACKET_WORDS],
    pub rays_in: u32,
    pub rays_finished: u32,
    pub rays_overflowed: u32,
    pub samples: u32,
    pub leaps: u32,
    /// Processor cycles in which the host offered a ray or a ray was in the processor.
    pub cycles: u32,
    /// The volume cache's corner reads found and not found since reset.
    pub cache_hits: u32,
    pub cache_misses: u32,
    /// The item of a flush (`Light = 1`): memory holds every deposit; `done` and the ray are 0.
    pub flush: bool,
    /// Photons scattered since reset (`Scatter = 1`; 0 otherwise).
    pub scatterings: u32,
}

impl crate::unit::StreamCodec for ProcessorRtlConfig {
    /// A host ray's bits.
    type In = [u32; crate::units::gicube_packet_loop::PACKET_WORDS];
    type Out = ProcessorOut;

    fn in_width(&self) -> u32 {
        256
    }

    fn out_width(&self) -> u32 {
        1 + 256 + OUT_COUNTS * COUNT_W + 1 + self.scatter * COUNT_W
    }

    fn pack_in(&self, item: &Self::In) -> Vec<u32> {
        item.to_vec()
    }

    fn unpack_out(&self, words: &[u32]) -> ProcessorOut {
        let mut r = crate::bits::BitReader::new(words);
        let done = r.get_bool();
        let ray = std::array::from_fn(|_| r.get(32) as u32);
        let mut c = || r.get(COUNT_W) as u32;
        ProcessorOut {
            done,
            ray,
            rays_in: c(),
            rays_finished: c(),
            rays_overflowed: c(),
            samples: c(),
            leaps: c(),
            cycles: c(),
            cache_hits: c(),
            cache_misses: c(),
            flush: r.get_bool(),
            scatterings: if self.scatter == 1 {
                r.get(COUNT_W) as u32
            } else {
                0
            },
        }
    }
}

impl Processor {
    /// The writes that load this processor's tables and empty flags into the RTL `rtl`
    /// (contract, *The RTL*): `gicube_sample`'s tables (region 0), every queue's empty flag
    /// (region 1: the flags when leaping is on, else 0); the volume is in memory
    /// ([`Processor::rtl_memory`]). Refused: another voxel width, step, block size or cache.
    pub fn rtl_config_writes(&self, rtl: &ProcessorRtlConfig) -> Result<Vec<(u32, Vec<u32>)>> {
        rtl.validate()?;
        if self.vol.bits != rtl.voxel_w
            || self.cfg.step != rtl.step
            || self.cfg.block_log2 != rtl.block_log2
            || self.blocks != rtl.vol_blocks
            || self.cache_config()? != Some(rtl.cache_config())
            || self.cfg.jitter != (rtl.jitter == 1)
            || self.cfg.shade != rtl.shade_config()
        {
            return Err(ModelError::Config(format!(
                "gicube_processor: a {}-bit volume of {} blocks of 2^{} at step {} does not fit {rtl:?}",
                self.vol.bits, self.blocks, self.cfg.block_log2, self.cfg.step
            )));
        }
        let top = rtl.cfg_addr_w() - 2;
        let region = |r: u32, a: u32| (r << top) | a;
        let word = |v: u32| {
            let mut w = crate::bits::BitWriter::new();
            w.put(u64::from(v), CFG_WORD_W);
            w.finish(CFG_WORD_W)
        };
        let mut writes: Vec<(u32, Vec<u32>)> = self
            .sampler
            .config_writes()
            .into_iter()
            .map(|(a, d)| (region(CFG_REGION_SAMPLE, a), d))
            .collect();
        debug_assert!(writes.iter().all(|(a, _)| *a < 1 << top));
        for q in 0..1u32 << rtl.queue_w() {
            let e = self.cfg.space_leap && self.empty.get(q as usize).copied().unwrap_or(false);
            writes.push((region(CFG_REGION_EMPTY, q), word(u32::from(e))));
        }
        if rtl.light == 1 {
            let [x, y, z] = self.vol.dims.map(|d| d as u32);
            let lit = u32::from(self.irradiance.is_some());
            writes.push((
                region(CFG_REGION_GI, 0),
                word(x | y << 7 | z << 14 | lit << 21),
            ));
        }
        if rtl.scatter == 1 {
            // The scattering unit's tables (contract, *Photons in the ring*): each entry's bits
            // above the word's 36 first, then the entry.
            let cfg = self.scatter.config();
            for (a, d) in self.scatter.tables().config_writes(&cfg) {
                let mut r = crate::bits::BitReader::new(&d);
                let lo = r.get(CFG_WORD_W);
                let hi = r.get(cfg.cfg_data_w() - CFG_WORD_W);
                writes.push((region(CFG_REGION_GI, CFG_GI_SCATTER_HI), word(hi as u32)));
                let mut w = crate::bits::BitWriter::new();
                w.put(lo, CFG_WORD_W);
                writes.push((
                    region(CFG_REGION_GI, CFG_GI_SCATTER + a),
                    w.finish(CFG_WORD_W),
                ));
            }
            writes.push(Self::rtl_photon_write(rtl, None));
        }
        Ok(writes)
    }

    /// The write that sets the RTL's photon registers for a lighting pass of `light` (`Scatter =
    /// 1`, contract, *Photons in the ring*): photons on with the albedo `round(albedo 65536)`
    /// for a high-albedo light, off otherwise (`None`: off). Made after `rtl_config_writes`.
    pub fn rtl_photon_write(rtl: &ProcessorRtlConfig, light: Option<&GiLight>) -> (u32, Vec<u32>) {
        let v = match light.map(|l| l.mode) {
            Some(GiMode::HighAlbedo { albedo, .. }) => 1 << 17 | albedo_raw(albedo),
            _ => 0,
        };
        let mut w = crate::bits::BitWriter::new();
        w.put(u64::from(v), CFG_WORD_W);
        (
            (CFG_REGION_GI << (rtl.cfg_addr_w() - 2)) | CFG_GI_PHOTONS,
            w.finish(CFG_WORD_W),
        )
    }

    /// The write that flushes the RTL's cache at the end of a lighting pass (`Light = 1`,
    /// contract, *Splatting through the cache*): made when every lighting ray has finished; its
    /// output item (`flush`) comes when memory holds every deposit.
    pub fn rtl_flush_write(rtl: &ProcessorRtlConfig) -> (u32, Vec<u32>) {
        let mut w = crate::bits::BitWriter::new();
        w.put(0, CFG_WORD_W);
        (
            (CFG_REGION_FLUSH << (rtl.cfg_addr_w() - 2)),
            w.finish(CFG_WORD_W),
        )
    }
}
