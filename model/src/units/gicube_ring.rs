//! A ring of GI-Cube block processors (patent [348], [355], [390], [392]): `p` processors, the
//! volume's blocks in slabs along x, rays sent to the neighbour that owns their next block, all
//! processors in lockstep processor cycles. The contract is docs/numerics/gicube_ring.md; every
//! processor is `gicube_processor::Processor` (its per-ray cycle, its queue front end, its ring and
//! its volume cache), run by the ring's cycle loop here.

use std::collections::VecDeque;

use crate::camera::Camera;
use crate::error::{ModelError, Result};
use crate::units::cube5_axi_rd::Burst;
use crate::units::gicube_packet_loop::{flag, RayPacket, PACKET_WORDS};
use crate::units::gicube_processor::{
    FrameCache, Outcome, Processor, ProcessorCounts, ProcessorRtlConfig, Projection, QueueOrder,
    COUNT_W,
};
use crate::units::gicube_queue_front::{Chooser, QueueFront};

/// Processors a ring takes at most (`ProcLog2 <= 2`).
pub const MAX_PROCS: u32 = 4;

/// The counts of one processor's links.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LinkCounts {
    /// Rays taken from its link (sent by a neighbour).
    pub nb_in: u64,
    /// Rays it sent to a neighbour's link.
    pub nb_out: u64,
    /// Rays a neighbour's link refused (full, or taken by a lower processor in the cycle): back
    /// to the host with `OVERFLOW` set, counted in its `rays_overflowed` too (not an RTL count).
    pub nb_refused: u64,
}

/// A frame rendered by the ring: the pixels, and the counts of every processor.
#[derive(Debug, Clone, PartialEq)]
pub struct RingFrame {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<[u16; 3]>,
    /// Rays the host made (one per pixel whose ray meets the volume).
    pub rays_made: u64,
    /// Per processor, processor 0 first (`rays_in`: the host's rays it took).
    pub counts: Vec<ProcessorCounts>,
    pub links: Vec<LinkCounts>,
}

impl RingFrame {
    /// The ring's cycles (every processor makes every cycle).
    pub fn cycles(&self) -> u64 {
        self.counts.first().map_or(0, |c| c.cycles)
    }

    /// `sum rays_in = sum rays_finished + sum rays_overflowed` and every made ray finished once;
    /// the links balance. `Err` names the first that does not hold.
    pub fn check_conservation(&self) -> Result<()> {
        let sum = |f: fn(&ProcessorCounts) -> u64| self.counts.iter().map(f).sum::<u64>();
        let (rin, fin, ovf) = (
            sum(|c| c.rays_in),
            sum(|c| c.rays_finished),
            sum(|c| c.rays_overflowed),
        );
        let nb_in: u64 = self.links.iter().map(|l| l.nb_in).sum();
        let nb_out: u64 = self.links.iter().map(|l| l.nb_out).sum();
        if rin != fin + ovf || fin != self.rays_made || nb_in != nb_out {
            return Err(ModelError::Config(format!(
                "gicube ring: rays in {rin}, finished {fin}, overflowed {ovf}, made {}, sent \
                 {nb_out}, taken from links {nb_in}",
                self.rays_made
            )));
        }
        Ok(())
    }
}

/// What a ring did besides its frame: each processor's AR bursts (its cache's misses) in order,
/// and every ray that left the ring in output order (per cycle, processor 0's first; each
/// processor at most one a cycle): finished (`true`) or returned to the host (`false`,
/// OVERFLOW set), and the processor it came from.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RingTrace {
    pub reads: Vec<Vec<Burst>>,
    pub outputs: Vec<(bool, RayPacket, u32)>,
}

/// `p` block processors in lockstep (contract, *Lockstep*, *One ring cycle*).
#[derive(Debug, Clone)]
pub struct Ring {
    proc: Processor,
    procs: u32,
    /// Blocks of a slab, `S = B / p`.
    slab: u32,
    block_log2: u32,
}

impl Ring {
    /// `procs` copies of `proc` (its volume, tables, configuration), the blocks in slabs along
    /// x. Refused: `procs` not 1, 2 or 4, `B` not a multiple of it, the scan order (the ring
    /// runs the sorter).
    pub fn new(proc: Processor, procs: u32) -> Result<Self> {
        let b = proc.blocks();
        let cfg = proc.config();
        if !(1..=MAX_PROCS).contains(&procs) || !procs.is_power_of_two() || !b.is_multiple_of(procs)
        {
            return Err(ModelError::Config(format!(
                "gicube ring: {procs} processors (1, 2 or 4, dividing the {b} blocks a side)"
            )));
        }
        if cfg.order != QueueOrder::Sorter {
            return Err(ModelError::Config(
                "gicube ring: the processors choose their queues by the sorter".into(),
            ));
        }
        Ok(Self {
            slab: b / procs,
            block_log2: cfg.block_log2,
            proc,
            procs,
        })
    }

    pub fn processor(&self) -> &Processor {
        &self.proc
    }

    pub fn procs(&self) -> u32 {
        self.procs
    }

    /// The processor that owns the block of `start` (`floor(bx / S)`, contract *Which processor
    /// owns a block*).
    pub fn owner(&self, start: [u32; 3]) -> u32 {
        let bx = start[0] >> (crate::units::gicube_packet_loop::POS_FRAC_W + self.block_log2);
        (bx / self.slab).min(self.procs - 1)
    }

    /// Renders a frame (contract, *One ring cycle*).
    pub fn render(&self, cam: &Camera, proj: Projection) -> Result<RingFrame> {
        self.run(cam, proj, false).map(|(f, _)| f)
    }

    /// `render`, and each processor's AR bursts (its cache's misses) in order.
    pub fn render_cache_traced(
        &self,
        cam: &Camera,
        proj: Projection,
    ) -> Result<(RingFrame, Vec<Vec<Burst>>)> {
        self.run(cam, proj, true)
    }

    fn run(
        &self,
        cam: &Camera,
        proj: Projection,
        traced: bool,
    ) -> Result<(RingFrame, Vec<Vec<Burst>>)> {
        let packets = self.proc.ring_packets(cam, proj)?;
        let (f, t) = self.run_packets(packets, cam.width, cam.height, traced)?;
        Ok((f, t.reads))
    }

    /// The frame loop over the host's `packets` (rendering rays made by any host: each starts
    /// inside the volume, its pixel `(u, v)` inside `w x h` and its own), each processor's
    /// bursts and every ray that left the ring in the order of its output (`RingTrace`): the
    /// million-ray co-simulation's reference.
    pub fn run_packets_traced(
        &self,
        packets: Vec<RayPacket>,
        w: u32,
        h: u32,
    ) -> Result<(RingFrame, RingTrace)> {
        if let Some(p) = packets
            .iter()
            .find(|p| u32::from(p.u) >= w || u32::from(p.v) >= h)
        {
            return Err(ModelError::Config(format!(
                "gicube ring: packet pixel ({}, {}) outside {w}x{h}",
                p.u, p.v
            )));
        }
        self.run_packets(packets, w, h, true)
    }

    fn run_packets(
        &self,
        packets: Vec<RayPacket>,
        w: u32,
        h: u32,
        traced: bool,
    ) -> Result<(RingFrame, RingTrace)> {
        let p = self.procs as usize;
        let cfg = self.proc.config();
        let rays = packets.len();
        let mut outputs: Vec<(bool, RayPacket, u32)> = Vec::new();
        let mut feed: VecDeque<RayPacket> = packets.into();
        let mut fronts = (0..p)
            .map(|_| {
                QueueFront::new(
                    cfg.block_log2,
                    self.proc.blocks(),
                    cfg.queue_len,
                    cfg.ranks,
                    Chooser::Sorter,
                )
            })
            .collect::<Result<Vec<QueueFront<RayPacket>>>>()?;
        let mut caches: Vec<Option<FrameCache>> =
            (0..p).map(|_| self.proc.frame_cache(traced)).collect();
        let lat = cfg.ring_latency as usize;
        let mut rings: Vec<VecDeque<Option<Outcome>>> =
            (0..p).map(|_| (0..lat).map(|_| None).collect()).collect();
        let mut links: Vec<Option<RayPacket>> = vec![None; p];
        let mut counts = vec![ProcessorCounts::default(); p];
        let mut lc = vec![LinkCounts::default(); p];
        let mut last_active: Vec<Option<u32>> = vec![None; p];
        let mut rgb = vec![[0u16; 3]; (w * h) as usize];
        let mut done = vec![false; (w * h) as usize];
        let per_path = 2 * u64::from(self.proc.blocks() << cfg.block_log2) * 256
            / u64::from(cfg.step)
            + u64::from(self.proc.queues())
            + 64;
        let bound = 64 + 8 * rays as u64 * per_path * (1 + lat as u64) * p as u64;
        let mut cycles = 0u64;

        while !feed.is_empty()
            || fronts.iter().any(|f| f.total() > 0)
            || rings.iter().flatten().any(Option::is_some)
            || links.iter().any(Option::is_some)
        {
            cycles += 1;
            if cycles > bound {
                return Err(ModelError::Config(format!(
                    "gicube ring: no progress after {bound} cycles"
                )));
            }
            let head = match feed.front() {
                Some(ray) if self.proc.ring_queue_of(ray.start).is_none() => {
                    return Err(ModelError::Config(format!(
                        "gicube ring: host ray of pixel ({}, {}) starts outside the volume",
                        ray.u, ray.v
                    )))
                }
                o => o.copied(),
            };
            let host_owner = head.map(|r| self.owner(r.start) as usize);
            // The links as they are at the start of the cycle: what a sender may fill.
            let full_at_start: Vec<bool> = links.iter().map(Option::is_some).collect();
            let mut fills: Vec<Option<RayPacket>> = vec![None; p];
            // Rays returned to the host in this cycle, in processor order.
            let mut returned: Vec<RayPacket> = Vec::new();
            for i in 0..p {
                let held = u64::from(fronts[i].total());
                let c_i = &mut counts[i];
                c_i.cycles += 1;
                c_i.occupancy_sum += held;
                let from_link = links[i].is_some();
                let offer = if from_link {
                    links[i]
                } else if host_owner == Some(i) {
                    head
                } else {
                    None
                };
                let (ring, cache) = (&mut rings[i], caches[i].as_mut());
                let mut sent_or_returned: Option<(Option<usize>, RayPacket)> = None;
                let mut finished: Option<RayPacket> = None;
                let c = fronts[i].cycle(
                    true,
                    |popped| {
                        let entered =
                            popped.map(|(q, ray)| self.proc.ring_advance(ray, q, c_i, cache));
                        ring.push_back(entered);
                        match ring.pop_front().flatten() {
                            None => Ok(None),
                            Some(Outcome::Next(ray)) => {
                                let j = self.owner(ray.start) as usize;
                                if j == i {
                                    return Ok(Some(ray));
                                }
                                // Sent to the owner's link if it was empty at the start of the
                                // cycle and nobody before sent to it; else back to the host.
                                if !full_at_start[j] && fills[j].is_none() {
                                    fills[j] = Some(ray);
                                    sent_or_returned = Some((Some(j), ray));
                                } else {
                                    let mut r = ray;
                                    r.flags |= flag::OVERFLOW;
                                    sent_or_returned = Some((None, r));
                                }
                                Ok(None)
                            }
                            Some(Outcome::Done(ray)) => {
                                c_i.rays_finished += 1;
                                let k = (u32::from(ray.v) * w + u32::from(ray.u)) as usize;
                                if done[k] {
                                    return Err(ModelError::Config(format!(
                                        "gicube ring: pixel ({}, {}) finished twice",
                                        ray.u, ray.v
                                    )));
                                }
                                done[k] = true;
                                rgb[k] = ray.color;
                                finished = Some(ray);
                                Ok(None)
                            }
                        }
                    },
                    offer,
                )?;
                let c_i = &mut counts[i];
                match sent_or_returned {
                    Some((Some(_), _)) => lc[i].nb_out += 1,
                    Some((None, r)) => {
                        c_i.rays_overflowed += 1;
                        lc[i].nb_refused += 1;
                        returned.push(r);
                        outputs.push((false, r, i as u32));
                    }
                    None => {}
                }
                if let Some(ray) = finished {
                    outputs.push((true, ray, i as u32));
                }
                if c.active.is_some() && c.active != last_active[i] {
                    c_i.activations += 1;
                }
                last_active[i] = c.active;
                if c.popped.is_none() && held > 0 {
                    c_i.idle_cycles += 1;
                }
                if let Some(ray) = c.ring_ovf {
                    c_i.rays_overflowed += 1;
                    returned.push(ray);
                    outputs.push((false, ray, i as u32));
                }
                if c.host_taken {
                    if from_link {
                        links[i] = None;
                        lc[i].nb_in += 1;
                    } else {
                        feed.pop_front();
                        c_i.rays_in += 1;
                    }
                }
                if !from_link {
                    c_i.host_stalls += u64::from(c.host_stall);
                }
                for u in &c.updates {
                    c_i.max_queue = c_i.max_queue.max(fronts[i].queues().len(u.queue));
                }
            }
            for (l, f) in links.iter_mut().zip(fills) {
                if f.is_some() {
                    *l = f;
                }
            }
            feed.extend(returned);
        }
        let reads = caches
            .into_iter()
            .map(|c| c.map(Processor::frame_cache_reads).unwrap_or_default())
            .collect();
        Ok((
            RingFrame {
                width: w,
                height: h,
                rgb,
                rays_made: rays as u64,
                counts,
                links: lc,
            },
            RingTrace { reads, outputs },
        ))
    }
}

/// The RTL top `gicube_ring`'s parameters (contract, *The RTL*): `ProcLog2` and one
/// processor's (`gicube_processor`'s, `Light = 0`, alone: `Procs = 1`, `ProcId = 0`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RingRtlConfig {
    /// `p = 2^proc_log2` processors, 1..=2.
    pub proc_log2: u32,
    /// The processor each of the ring's is.
    pub proc: ProcessorRtlConfig,
}

/// Counts per processor in an output item.
pub const RING_COUNTS: u32 = 10;
/// Bits of an output item's `proc` field.
pub const PROC_FIELD_W: u32 = 2;

impl RingRtlConfig {
    pub const DEFAULT: Self = Self {
        proc_log2: 1,
        proc: ProcessorRtlConfig::DEFAULT,
    };

    /// The processor each of the ring's is.
    pub fn processor(&self) -> ProcessorRtlConfig {
        self.proc
    }

    pub fn procs(&self) -> u32 {
        1 << self.proc_log2
    }

    pub fn validate(&self) -> Result<()> {
        if self.proc_log2 > 2 || !self.proc.vol_blocks.is_multiple_of(self.procs()) {
            return Err(ModelError::Config(format!(
                "gicube_ring: ProcLog2 {} outside 0..=2 or VolBlocks {} not a multiple of {}",
                self.proc_log2,
                self.proc.vol_blocks,
                self.procs()
            )));
        }
        self.proc.validate()
    }
}

crate::unit_config!(RingRtlConfig, "gicube_ring", DEFAULT, { "ProcLog2" => proc_log2 },
    proc: [
        "BlockLog2",
        "VolBlocks",
        "QueueLen",
        "Ranks",
        "VoxelW",
        "Step",
        "RingLat",
        "DataW",
        "LineVox",
        "Sets",
        "Outstanding",
        "Prefetch",
    ]
);

/// One processor's counts in an output item (contract, *Output item*).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RingOutCounts {
    pub rays_in: u32,
    pub rays_finished: u32,
    pub rays_overflowed: u32,
    pub samples: u32,
    pub leaps: u32,
    pub cycles: u32,
    pub cache_hits: u32,
    pub cache_misses: u32,
    pub nb_in: u32,
    pub nb_out: u32,
}

impl RingOutCounts {
    /// The model's counts of a processor as the RTL reports them (modulo `2^32`).
    pub fn of(c: &ProcessorCounts, l: &LinkCounts) -> Self {
        Self {
            rays_in: c.rays_in as u32,
            rays_finished: c.rays_finished as u32,
            rays_overflowed: c.rays_overflowed as u32,
            samples: c.samples as u32,
            leaps: c.leaps as u32,
            cycles: c.cycles as u32,
            cache_hits: c.cache_hits as u32,
            cache_misses: c.cache_misses as u32,
            nb_in: l.nb_in as u32,
            nb_out: l.nb_out as u32,
        }
    }
}

/// One output item of the RTL: a finished or returned ray, the processor it came from, every
/// processor's counts (exact in a frame's last item).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct RingOut {
    pub done: bool,
    pub ray: [u32; PACKET_WORDS],
    pub proc: u32,
    pub counts: Vec<RingOutCounts>,
}

impl crate::unit::StreamCodec for RingRtlConfig {
    type In = [u32; PACKET_WORDS];
    type Out = RingOut;

    fn in_width(&self) -> u32 {
        256
    }

    fn out_width(&self) -> u32 {
        1 + 256 + PROC_FIELD_W + self.procs() * RING_COUNTS * COUNT_W
    }

    fn pack_in(&self, item: &Self::In) -> Vec<u32> {
        item.to_vec()
    }

    fn unpack_out(&self, words: &[u32]) -> RingOut {
        let mut r = crate::bits::BitReader::new(words);
        let done = r.get_bool();
        let ray = std::array::from_fn(|_| r.get(32) as u32);
        let proc = r.get(PROC_FIELD_W) as u32;
        let counts = (0..self.procs())
            .map(|_| {
                let mut c = || r.get(COUNT_W) as u32;
                RingOutCounts {
                    rays_in: c(),
                    rays_finished: c(),
                    rays_overflowed: c(),
                    samples: c(),
                    leaps: c(),
                    cycles: c(),
                    cache_hits: c(),
                    cache_misses: c(),
                    nb_in: c(),
                    nb_out: c(),
                }
            })
            .collect();
        RingOut {
            done,
            ray,
            proc,
            counts,
        }
    }
}
