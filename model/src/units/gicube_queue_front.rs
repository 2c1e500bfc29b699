//! The GI-Cube block processor's queue front end (patent [355], [370]-[374]), written from
//! `docs/numerics/gicube_queue_front.md`: the ray input arbiter (the pipeline's re-queued ray
//! before the host's), bucketing (`gicube_bucket`), the ray queues (`gicube_ray_queues`, overflow
//! returned to the host) and the queue sorter (`gicube_sorter`, two updates per cycle).
//!
//! [`QueueFront`] is the one description of a processor cycle's queue traffic: the processor's
//! frame loop (`gicube_processor::Processor`) runs it with its packets and its pipeline, and the
//! stream unit [`QueueFrontUnit`] (the model of the RTL top `gicube_queue_front`) runs it with the
//! contract's items. It is order-dependent, so the model is cycle-accurate: one
//! [`QueueFront::cycle`] is one item of the RTL.

use rand::Rng;

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::{param_in, StreamCodec, StreamUnit};
use crate::units::gicube_bucket::{BucketConfig, BucketUnit, Distribution, Position};
use crate::units::gicube_packet_loop::{flag, RayPacket, LAYOUT, PACKET_BITS, POS_W};
use crate::units::gicube_ray_queues::{get_ray, put_ray, Ray, RayQueues};
use crate::units::gicube_sorter::{Sorter, SorterConfig, SorterIn};

/// Sorter steps per processor cycle: the sorter is over-clocked by two ([371]).
pub const SORTER_SLOTS: usize = 2;
/// Bit of the packet's `OVERFLOW` flag ([372]): the `flags` field's first bit plus the flag's.
pub const OVERFLOW_BIT: u32 = 226 + flag::OVERFLOW.trailing_zeros();
/// First bit of the packet's start point (x, y, z, `U(12.8)` each).
pub const START_LSB: u32 = 24;

/// What the front end needs of a ray: its start point (the bucketing) and its `OVERFLOW` flag.
pub trait FrontRay: Clone {
    /// The start point, raw `U(12.8)` per axis.
    fn start(&self) -> [u32; 3];
    /// Sets or clears the `OVERFLOW` flag.
    fn set_overflow(&mut self, on: bool);
}

impl FrontRay for RayPacket {
    fn start(&self) -> [u32; 3] {
        self.start
    }

    fn set_overflow(&mut self, on: bool) {
        if on {
            self.flags |= flag::OVERFLOW;
        } else {
            self.flags &= !flag::OVERFLOW;
        }
    }
}

impl FrontRay for Ray {
    fn start(&self) -> [u32; 3] {
        std::array::from_fn(|i| {
            let mut r = BitReader::new(self);
            r.get(START_LSB + POS_W * i as u32);
            r.get(POS_W) as u32
        })
    }

    fn set_overflow(&mut self, on: bool) {
        let (w, b) = ((OVERFLOW_BIT / 32) as usize, OVERFLOW_BIT % 32);
        if on {
            self[w] |= 1 << b;
        } else {
            self[w] &= !(1 << b);
        }
    }
}

/// How the active queue is chosen: the sorter's `S[0]` (the RTL), or the processor model's
/// ascending scan (`gicube_processor::QueueOrder::Scan`, a rule without a sorter).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Chooser {
    Sorter,
    Scan,
}

/// One step the front end made on its ray queues (`RayQueues`): a pop of the active queue, or a
/// push of a ray into a queue (the ring's or the host's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum QueueOp<T> {
    Pop(u32),
    Push(u32, T),
}

/// One processor cycle's input (contract, "Input"), the rays as the caller holds them.
#[derive(Debug, Clone, PartialEq)]
pub struct FrontTraffic<T> {
    pub take: bool,
    pub ring: Option<T>,
    pub host: Option<T>,
}

/// What a traced front end records: its queue steps and every cycle's input.
pub type FrontTrace<T> = (Vec<QueueOp<T>>, Vec<FrontTraffic<T>>);

/// What one processor cycle did (contract, "One cycle" and "Output").
#[derive(Debug, Clone, PartialEq)]
pub struct FrontCycle<T> {
    /// The active queue (`S[0]` at the start of the cycle).
    pub active: Option<u32>,
    /// The ray handed to the pipeline.
    pub popped: Option<T>,
    /// The pop took the active queue's last ray.
    pub emptied: bool,
    /// The ring ray's queue (whether or not there was one), and whether it was written.
    pub ring_q: u32,
    pub ring_pushed: bool,
    /// The ring ray returned to the host, `OVERFLOW` set.
    pub ring_ovf: Option<T>,
    /// The host ray's queue, and whether it was taken or stalled (neither: no sorter slot).
    pub host_q: u32,
    pub host_taken: bool,
    pub host_stall: bool,
    /// The sorter updates of the cycle, in order (at most two).
    pub updates: Vec<SorterIn>,
    /// Rays in the active queue after the cycle (0 when none), and in all queues.
    pub active_len: u32,
    pub total: u32,
}

/// The queue front end: bucketing, queues and the active-queue choice, stepped one processor
/// cycle at a time.
#[derive(Debug, Clone)]
pub struct QueueFront<T> {
    bucket: BucketUnit,
    queues: RayQueues<T>,
    chooser: Chooser,
    sorter: Sorter,
    scan: Option<u32>,
    trace: Option<FrontTrace<T>>,
}

impl<T: FrontRay> QueueFront<T> {
    /// Empty queues (the state after reset): `2^QueueW` queues of `queue_len` rays for the
    /// `vol_blocks^3` blocks of side `2^block_log2`, a sorter of `min(ranks, 2^QueueW)` ranks.
    pub fn new(
        block_log2: u32,
        vol_blocks: u32,
        queue_len: u32,
        ranks: u32,
        chooser: Chooser,
    ) -> Result<Self> {
        let bucket = BucketUnit::new(BucketConfig {
            block_log2,
            vol_blocks,
            proc_log2: 0,
            dist: Distribution::Slab,
            lanes: 2,
        })?;
        let queue_w = bucket.config().queue_w();
        let imp_w = (32 - queue_len.leading_zeros()).max(2);
        let scfg = SorterConfig::new(ranks.min(1 << queue_w), queue_w, imp_w, queue_len)?;
        Ok(Self {
            bucket,
            queues: RayQueues::new(1 << queue_w, queue_len),
            chooser,
            sorter: Sorter::new(scfg)?,
            scan: None,
            trace: None,
        })
    }

    /// Records every queue step and every cycle's input from now on (`take_trace`).
    pub fn trace(&mut self) {
        self.trace = Some((Vec::new(), Vec::new()));
    }

    /// The recorded queue steps and cycle inputs.
    pub fn take_trace(&mut self) -> FrontTrace<T> {
        self.trace.take().unwrap_or_default()
    }

    /// The queues.
    pub fn queues(&self) -> &RayQueues<T> {
        &self.queues
    }

    /// Rays in all queues.
    pub fn total(&self) -> u32 {
        self.queues.total()
    }

    /// The queue of a position (`gicube_bucket`; 0 outside the volume).
    pub fn queue_of(&self, ray: &T) -> u32 {
        self.bucket.bucket(Position(ray.start())).queue
    }

    /// The active queue at the start of the next cycle.
    pub fn active(&mut self) -> Option<u32> {
        match self.chooser {
            Chooser::Sorter => self.sorter.active().map(|e| e.queue),
            Chooser::Scan => {
                let q = &self.queues;
                if self.scan.is_none_or(|a| q.is_empty(a)) && q.total() > 0 {
                    let n = q.queues();
                    let from = self.scan.map_or(0, |a| a + 1);
                    self.scan = (0..n).map(|i| (from + i) % n).find(|&a| !q.is_empty(a));
                }
                self.scan
            }
        }
    }

    fn step(&mut self, pop: Option<u32>, push: Option<(u32, T)>) -> Option<T> {
        if let Some((ops, _)) = &mut self.trace {
            ops.extend(pop.map(QueueOp::Pop));
            ops.extend(push.clone().map(|(q, r)| QueueOp::Push(q, r)));
        }
        let s = self.queues.step(pop, push);
        s.popped.or(s.overflow)
    }

    /// One processor cycle (contract, "One cycle"): `take` pops the active queue's head, which
    /// goes to `pipeline` with its queue; what `pipeline` returns is the ring's ray (re-queued
    /// first); then the host's offer. Errors: `pipeline`'s, and a sorter counter that differs
    /// from its queue's length (a model bug).
    pub fn cycle(
        &mut self,
        take: bool,
        pipeline: impl FnOnce(Option<(u32, T)>) -> Result<Option<T>>,
        host: Option<T>,
    ) -> Result<FrontCycle<T>> {
        let active = self.active();
        // 2. Pop.
        let pop_q = active.filter(|_| take);
        let popped = match pop_q {
            Some(a) => self.step(Some(a), None),
            None => None,
        };
        let emptied = popped.is_some() && pop_q.is_some_and(|a| self.queues.is_empty(a));
        let ring = pipeline(popped.clone().zip(pop_q).map(|(r, a)| (a, r)))?;
        if let Some(t) = &mut self.trace {
            t.1.push(FrontTraffic {
                take,
                ring: ring.clone(),
                host: host.clone(),
            });
        }
        // 3. Ring push, before the host.
        let ring_q = ring.as_ref().map_or(0, |r| self.queue_of(r));
        let (mut ring_pushed, mut ring_ovf) = (false, None);
        if let Some(r) = ring {
            match self.step(None, Some((ring_q, r))) {
                None => ring_pushed = true,
                Some(mut r) => {
                    r.set_overflow(true);
                    ring_ovf = Some(r);
                }
            }
        }
        // 4. The pipeline's updates: a ray that stayed in its queue cancels its pop.
        let stayed = popped.is_some() && ring_pushed && pop_q == Some(ring_q);
        let mut updates = Vec::with_capacity(SORTER_SLOTS);
        if let (Some(a), false) = (pop_q.filter(|_| popped.is_some()), stayed) {
            updates.push(SorterIn::add(a, -1));
        }
        if ring_pushed && !stayed {
            updates.push(SorterIn::add(ring_q, 1));
        }
        // 5. The host, in a free sorter slot, if its queue has room.
        let host_q = host.as_ref().map_or(0, |r| self.queue_of(r));
        let (mut host_taken, mut host_stall) = (false, false);
        if let Some(mut r) = host.filter(|_| updates.len() < SORTER_SLOTS) {
            if self.queues.is_full(host_q) {
                host_stall = true;
            } else {
                r.set_overflow(false);
                if self.step(None, Some((host_q, r))).is_some() {
                    return Err(ModelError::Config(format!(
                        "queue front: queue {host_q} refused a ray it had room for"
                    )));
                }
                host_taken = true;
                updates.push(SorterIn::add(host_q, 1));
            }
        }
        // 6. Two sorter steps (the scan has no state to step).
        if self.chooser == Chooser::Sorter {
            for s in 0..SORTER_SLOTS {
                self.sorter.step(updates.get(s).unwrap_or(&SorterIn::NOOP));
            }
            for u in &updates {
                let len = self.queues.len(u.queue);
                if self.sorter.importance(u.queue) != len {
                    return Err(ModelError::Config(format!(
                        "queue front: sorter counter {} of queue {} holds {len} rays",
                        self.sorter.importance(u.queue),
                        u.queue
                    )));
                }
            }
        }
        Ok(FrontCycle {
            active,
            popped,
            emptied,
            ring_q,
            ring_pushed,
            ring_ovf,
            host_q,
            host_taken,
            host_stall,
            updates,
            active_len: active.map_or(0, |a| self.queues.len(a)),
            total: self.queues.total(),
        })
    }

    /// Empties the queues and the sorter (reset).
    pub fn clear(&mut self) {
        self.queues.clear();
        self.sorter = Sorter::new(self.sorter.config()).expect("a valid configuration");
        self.scan = None;
    }
}

/// One configuration of the RTL top `gicube_queue_front`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct QueueFrontConfig {
    /// Block side `2^BlockLog2` voxels, 1..=8.
    pub block_log2: u32,
    /// Blocks a side, 1..=64 with `VolBlocks^3 <= 256`: one queue per block.
    pub vol_blocks: u32,
    /// Rays per queue, 1..=4096.
    pub queue_len: u32,
    /// Sorter ranks, 2..=64 and at most `2^QueueW`.
    pub ranks: u32,
}

impl QueueFrontConfig {
    /// The RTL's parameter defaults: 64 blocks of 16^3 voxels (a 64^3 volume), 64-ray queues, 16
    /// ranks.
    pub const DEFAULT: Self = Self {
        block_log2: 4,
        vol_blocks: 4,
        queue_len: 64,
        ranks: 16,
    };

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(ModelError::Config(format!("gicube_queue_front: {m}")));
        param_in("BlockLog2", self.block_log2, 1..=8).or_else(bad)?;
        if !(1..=6).contains(&self.vol_blocks) {
            return bad(format!(
                "VolBlocks {} outside 1..=6 (VolBlocks^3 <= 256 queues)",
                self.vol_blocks
            ));
        }
        if self.vol_blocks << self.block_log2 > 4096 {
            return bad("the volume side VolBlocks << BlockLog2 exceeds 4096".into());
        }
        param_in("QueueLen", self.queue_len, 1..=4096).or_else(bad)?;
        if !(2..=64).contains(&self.ranks) || self.ranks > self.queues() {
            return bad(format!(
                "Ranks {} outside 2..=min(64, {} queues)",
                self.ranks,
                self.queues()
            ));
        }
        Ok(())
    }

    /// `QueueW = max(1, clog2(VolBlocks^3))`.
    pub fn queue_w(&self) -> u32 {
        let n = self.vol_blocks.pow(3);
        if n <= 2 {
            1
        } else {
            32 - (n - 1).leading_zeros()
        }
    }

    /// `Q = 2^QueueW`.
    pub fn queues(&self) -> u32 {
        1 << self.queue_w()
    }

    /// `LenW = bitlen(QueueLen)`.
    pub fn len_w(&self) -> u32 {
        32 - self.queue_len.leading_zeros()
    }

    /// `TotW = bitlen(Q QueueLen)`.
    pub fn tot_w(&self) -> u32 {
        32 - (self.queues() * self.queue_len).leading_zeros()
    }

    /// Clocks per processor cycle at full speed (contract, "Timing").
    pub const CLOCKS_PER_CYCLE: u64 = 4;

    /// Clocks from an item's transfer to its output item's first offer.
    pub fn latency(&self) -> u64 {
        4
    }
}

crate::unit_config!(QueueFrontConfig, "gicube_queue_front", DEFAULT, {
    "BlockLog2" => block_log2,
    "VolBlocks" => vol_blocks,
    "QueueLen" => queue_len,
    "Ranks" => ranks,
});

/// One input item (contract, "Input").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FrontIn {
    pub take: bool,
    pub ring: bool,
    pub host: bool,
    pub ring_ray: Ray,
    pub host_ray: Ray,
}

/// One output item (contract, "Output").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FrontOut {
    pub active: bool,
    pub active_q: u32,
    pub popped: bool,
    pub emptied: bool,
    pub ring_pushed: bool,
    pub ring_ovf: bool,
    pub host_taken: bool,
    pub host_stall: bool,
    pub ring_q: u32,
    pub host_q: u32,
    pub active_len: u32,
    pub total: u32,
    pub pop_ray: Ray,
    pub ovf_ray: Ray,
}

/// The golden model of `gicube_queue_front`: [`QueueFront`] behind the stream interface.
#[derive(Debug, Clone)]
pub struct QueueFrontUnit {
    cfg: QueueFrontConfig,
    front: QueueFront<Ray>,
}

impl QueueFrontUnit {
    pub fn new(cfg: QueueFrontConfig) -> Result<Self> {
        cfg.validate()?;
        Ok(Self {
            cfg,
            front: QueueFront::new(
                cfg.block_log2,
                cfg.vol_blocks,
                cfg.queue_len,
                cfg.ranks,
                Chooser::Sorter,
            )?,
        })
    }

    pub fn config(&self) -> QueueFrontConfig {
        self.cfg
    }

    pub fn front(&self) -> &QueueFront<Ray> {
        &self.front
    }

    /// One item.
    pub fn step(&mut self, item: &FrontIn) -> FrontOut {
        let ring = item.ring.then_some(item.ring_ray);
        let c = self
            .front
            .cycle(item.take, |_| Ok(ring), item.host.then_some(item.host_ray))
            .expect("the stream unit's pipeline never fails, and the counters follow the queues");
        FrontOut {
            active: c.active.is_some(),
            active_q: c.active.unwrap_or(0),
            popped: c.popped.is_some(),
            emptied: c.emptied,
            ring_pushed: c.ring_pushed,
            ring_ovf: c.ring_ovf.is_some(),
            host_taken: c.host_taken,
            host_stall: c.host_stall,
            ring_q: self.front.queue_of(&item.ring_ray),
            host_q: self.front.queue_of(&item.host_ray),
            active_len: c.active_len,
            total: c.total,
            pop_ray: c.popped.unwrap_or_default(),
            ovf_ray: c.ring_ovf.unwrap_or_default(),
        }
    }
}

impl StreamUnit for QueueFrontUnit {
    type In = FrontIn;
    type Out = FrontOut;

    fn run(&mut self, inputs: &[FrontIn]) -> Vec<FrontOut> {
        inputs.iter().map(|i| self.step(i)).collect()
    }

    fn reset(&mut self) {
        self.front.clear();
    }
}

impl StreamCodec for QueueFrontConfig {
    type In = FrontIn;
    type Out = FrontOut;

    fn in_width(&self) -> u32 {
        3 + 2 * PACKET_BITS
    }

    fn out_width(&self) -> u32 {
        7 + 3 * self.queue_w() + self.len_w() + self.tot_w() + 2 * PACKET_BITS
    }

    fn pack_in(&self, item: &FrontIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        w.put_bool(item.take)
            .put_bool(item.ring)
            .put_bool(item.host);
        put_ray(&mut w, &item.ring_ray, PACKET_BITS);
        put_ray(&mut w, &item.host_ray, PACKET_BITS);
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> FrontOut {
        let mut r = BitReader::new(words);
        let qw = self.queue_w();
        let active = r.get_bool();
        let active_q = r.get(qw) as u32;
        let flags: [bool; 6] = std::array::from_fn(|_| r.get_bool());
        FrontOut {
            active,
            active_q,
            popped: flags[0],
            emptied: flags[1],
            ring_pushed: flags[2],
            ring_ovf: flags[3],
            host_taken: flags[4],
            host_stall: flags[5],
            ring_q: r.get(qw) as u32,
            host_q: r.get(qw) as u32,
            active_len: r.get(self.len_w()) as u32,
            total: r.get(self.tot_w()) as u32,
            pop_ray: get_ray(&mut r, PACKET_BITS),
            ovf_ray: get_ray(&mut r, PACKET_BITS),
        }
    }
}

/// `ray` with its start point set to `pos` (raw `U(12.8)`).
pub fn with_start(mut ray: Ray, pos: [u32; 3]) -> Ray {
    for (i, p) in pos.iter().enumerate() {
        let lsb = START_LSB + POS_W * i as u32;
        for b in 0..POS_W {
            let (w, k) = (((lsb + b) / 32) as usize, (lsb + b) % 32);
            ray[w] = (ray[w] & !(1 << k)) | (((p >> b) & 1) << k);
        }
    }
    ray
}

/// A position in block `q` of `cfg`'s volume, random within the block.
pub fn position_in(cfg: &QueueFrontConfig, q: u32, rng: &mut impl Rng) -> [u32; 3] {
    let blocks = cfg.vol_blocks;
    let q = q % blocks.pow(3);
    let b = [q / (blocks * blocks), (q / blocks) % blocks, q % blocks];
    let side = 256 << cfg.block_log2;
    b.map(|c| c * side + rng.random_range(0..side))
}

/// Random cycles of processor-like traffic: phases of a few hundred cycles, each `Fill` (the host
/// offers rays of a few hot blocks, the pipeline takes rarely), `Drain` (the pipeline takes
/// nearly every cycle and re-queues most rays, to their own hot block or to another: stays and
/// moves) or `Mixed` (every port at random). Every ray carries random bits (flags included), a
/// position in a hot block, any block, or now and then outside the volume (queue 0).
#[derive(Debug, Clone)]
pub struct FrontTrafficGen {
    cfg: QueueFrontConfig,
    phase: u32,
    left: u32,
    hot: [u32; 3],
}

impl FrontTrafficGen {
    pub fn new(cfg: QueueFrontConfig) -> Self {
        Self {
            cfg,
            phase: 0,
            left: 0,
            hot: [0; 3],
        }
    }

    fn ray(&self, rng: &mut impl Rng, hot: f64) -> Ray {
        let blocks = self.cfg.vol_blocks.pow(3);
        let pos = if rng.random_bool(0.01) {
            [0; 3].map(|_| rng.random_range(0..1 << POS_W))
        } else {
            let q = if rng.random_bool(hot) {
                self.hot[rng.random_range(0..3)]
            } else {
                rng.random_range(0..blocks)
            };
            position_in(&self.cfg, q, rng)
        };
        with_start(std::array::from_fn(|_| rng.random()), pos)
    }

    pub fn next_item(&mut self, rng: &mut impl Rng) -> FrontIn {
        if self.left == 0 {
            self.phase = rng.random_range(0..3);
            self.left = rng.random_range(16..=4 * self.cfg.queue_len.max(64));
            let blocks = self.cfg.vol_blocks.pow(3);
            self.hot = std::array::from_fn(|_| rng.random_range(0..blocks));
        }
        self.left -= 1;
        let (take, ring, host) = match self.phase {
            0 => (0.1, 0.3, 0.9),
            1 => (0.95, 0.8, 0.5),
            _ => (0.5, 0.5, 0.5),
        };
        FrontIn {
            take: rng.random_bool(take),
            ring: rng.random_bool(ring),
            host: rng.random_bool(host),
            ring_ray: self.ray(rng, 0.7),
            host_ray: self.ray(rng, 0.7),
        }
    }
}

/// Directed extremes (contract, "Directed extremes"), chosen by running the model alongside: the
/// active queue is whatever the sorter says, so a stay, a move and an overflow are made on the
/// queue the next cycle will pop.
pub fn directed_items(cfg: QueueFrontConfig) -> Vec<FrontIn> {
    let mut unit = QueueFrontUnit::new(cfg).expect("a valid configuration");
    let blocks = cfg.vol_blocks.pow(3);
    let last = blocks - 1;
    // Deterministic rays: all-ones, alternating and tagged bits, positions at block corners.
    let mut tag = 0u32;
    let mut ray = |q: u32, kind: u32| {
        tag += 1;
        let bits: Ray = match kind % 3 {
            0 => [u32::MAX; 8],
            1 => [0xaaaa_5555; 8],
            _ => std::array::from_fn(|i| tag.rotate_left(5 * i as u32) ^ 0x0f0f_5a5a),
        };
        let blocks = cfg.vol_blocks;
        let b = [q / (blocks * blocks), (q / blocks) % blocks, q % blocks];
        let side = 256 << cfg.block_log2;
        let corner = if kind.is_multiple_of(2) { side - 1 } else { 0 };
        with_start(bits, b.map(|c| c * side + corner))
    };
    let mut v: Vec<FrontIn> = Vec::new();
    fn go(unit: &mut QueueFrontUnit, v: &mut Vec<FrontIn>, item: FrontIn) {
        v.push(item);
        unit.step(&item);
    }
    let idle = FrontIn::default();
    go(&mut unit, &mut v, idle);
    go(&mut unit, &mut v, FrontIn { take: true, ..idle });
    fn host_only(host_ray: Ray) -> FrontIn {
        FrontIn {
            host: true,
            host_ray,
            ..FrontIn::default()
        }
    }
    // The host fills the first and the last block's queue, and one more each (stalls).
    for q in [0, last] {
        for k in 0..=cfg.queue_len {
            go(&mut unit, &mut v, host_only(ray(q, k)));
        }
    }
    // Stays, moves and overflows on the active queue, the host offering to a full queue or an
    // empty one, with the OVERFLOW flag set.
    let other = |a: u32| if a == 0 { last } else { 0 };
    for round in 0..6 * cfg.queue_len + 8 {
        let a = unit.front.sorter.active().map_or(0, |e| e.queue);
        let (ring_q, host_q) = match round % 6 {
            0 => (a, a),                 // stay; the host's queue is full again
            1 => (other(a), 1 % blocks), // move into a full queue: overflow; host taken
            2 => ((a + 1) % blocks, a),  // move: two updates, the host waits
            3 => (a, (a + 2) % blocks),  // stay; the host takes a slot elsewhere
            4 => (other(a), other(a)),   // ring without take (below)
            _ => (a, last),
        };
        let mut host_ray = ray(host_q, round);
        host_ray.set_overflow(true);
        go(
            &mut unit,
            &mut v,
            FrontIn {
                take: round % 6 != 4,
                ring: round % 7 != 6,
                host: true,
                ring_ray: ray(ring_q, round + 1),
                host_ray,
            },
        );
    }
    // Every block's queue filled by the host, then everything drained with nothing re-queued.
    for q in 0..blocks {
        for k in 0..cfg.queue_len {
            go(&mut unit, &mut v, host_only(ray(q, k + q)));
        }
    }
    let drain = FrontIn { take: true, ..idle };
    while unit.front.total() > 0 {
        go(&mut unit, &mut v, drain);
    }
    // A ring push into an empty queue with no pop, then drained.
    let r = ray(last, 2);
    go(
        &mut unit,
        &mut v,
        FrontIn {
            ring: true,
            ring_ray: r,
            ..idle
        },
    );
    for _ in 0..3 {
        go(&mut unit, &mut v, drain);
    }
    v
}

/// Bits of the packet layout the front end reads and writes: the start point and the flags.
pub fn layout_bits_used() -> [(u32, u32); 2] {
    let start = LAYOUT
        .iter()
        .find(|f| f.name == "start_x")
        .map_or(0, |f| f.lsb);
    let flags = LAYOUT
        .iter()
        .find(|f| f.name == "flags")
        .map_or(0, |f| f.lsb);
    [(start, 3 * POS_W), (flags, 6)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    const SMALL: QueueFrontConfig = QueueFrontConfig {
        block_log2: 2,
        vol_blocks: 2,
        queue_len: 3,
        ranks: 4,
    };

    #[test]
    fn packet_constants_match_the_layout() {
        assert_eq!(layout_bits_used(), [(START_LSB, 60), (OVERFLOW_BIT - 2, 6)]);
        let p = RayPacket {
            start: [0x12345, 0xfffff, 7],
            flags: flag::OVERFLOW | flag::TERMINATED,
            ..RayPacket::from_bits(&[0; 8])
        };
        let mut bits = p.to_bits().unwrap();
        assert_eq!(bits.start(), p.start);
        bits.set_overflow(false);
        assert_eq!(RayPacket::from_bits(&bits).flags, flag::TERMINATED);
        assert_eq!(with_start([0; 8], p.start), {
            let q = RayPacket { flags: 0, ..p };
            q.to_bits().unwrap()
        });
    }

    #[test]
    fn stay_move_overflow_and_the_host_slot() {
        let mut f: QueueFront<Ray> = QueueFront::new(2, 2, 2, 4, Chooser::Sorter).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let at = |q: u32, rng: &mut ChaCha8Rng| with_start([q; 8], position_in(&SMALL, q, rng));
        // The host fills queue 3 (two rays), the third stalls.
        for k in 0..3 {
            let c = f.cycle(false, |_| Ok(None), Some(at(3, &mut rng))).unwrap();
            assert_eq!((c.host_taken, c.host_stall), (k < 2, k == 2));
        }
        assert_eq!(f.active(), Some(3));
        // A stay: pop 3 and re-queue to 3 (the freed slot), no update; the host (to 3) stalls.
        let r3 = at(3, &mut rng);
        let c = f
            .cycle(true, |p| Ok(p.map(|_| r3)), Some(at(3, &mut rng)))
            .unwrap();
        assert!(c.popped.is_some() && c.ring_pushed && c.host_stall);
        assert!(c.updates.is_empty());
        // A move into 5: two updates, the host waits (neither taken nor stalled).
        let r5 = at(5, &mut rng);
        let c = f
            .cycle(true, |_| Ok(Some(r5)), Some(at(6, &mut rng)))
            .unwrap();
        assert_eq!(c.updates.len(), 2);
        assert!(!c.host_taken && !c.host_stall);
        // A ring ray into full 5 after filling it: overflow with OVERFLOW set; the host gets in.
        let (r5, r5b, r6) = (at(5, &mut rng), at(5, &mut rng), at(6, &mut rng));
        f.cycle(false, |_| Ok(Some(r5)), None).unwrap();
        let c = f.cycle(true, |_| Ok(Some(r5b)), Some(r6)).unwrap();
        let ovf = c.ring_ovf.expect("queue 5 is full");
        assert_eq!(
            ovf[(OVERFLOW_BIT / 32) as usize] >> (OVERFLOW_BIT % 32) & 1,
            1
        );
        assert!(c.host_taken, "one update (the pop): the host has a slot");
    }

    #[test]
    fn conservation_under_random_traffic() {
        for cfg in [SMALL, QueueFrontConfig::DEFAULT] {
            let mut unit = QueueFrontUnit::new(cfg).unwrap();
            let mut g = FrontTrafficGen::new(cfg);
            let mut rng = ChaCha8Rng::seed_from_u64(9);
            let (mut rays_in, mut out, mut ovf, mut stalls) = (0u64, 0u64, 0u64, 0u64);
            for _ in 0..200_000 {
                let i = g.next_item(&mut rng);
                let o = unit.step(&i);
                rays_in += u64::from(i.ring) + u64::from(o.host_taken);
                out += u64::from(o.popped);
                ovf += u64::from(o.ring_ovf);
                stalls += u64::from(o.host_stall);
                assert!(!(o.host_taken && o.host_stall));
                assert_eq!(o.ring_pushed, i.ring && !o.ring_ovf);
            }
            assert!(
                ovf > 1000 && stalls > 1000,
                "overflows {ovf}, host stalls {stalls}"
            );
            let held = u64::from(unit.front().total());
            assert_eq!(
                rays_in,
                out + ovf + held,
                "rays in = out + overflowed + held"
            );
        }
    }

    #[test]
    fn directed_items_reach_every_extreme() {
        for cfg in [SMALL, QueueFrontConfig::DEFAULT] {
            let mut unit = QueueFrontUnit::new(cfg).unwrap();
            let outs = unit.run(&directed_items(cfg));
            assert!(outs.iter().any(|o| o.ring_ovf && o.host_taken));
            assert!(outs
                .iter()
                .any(|o| o.host_stall && o.popped && o.ring_pushed));
            assert!(outs.iter().any(|o| o.emptied));
            let full = cfg.vol_blocks.pow(3) * cfg.queue_len;
            assert_eq!(outs.iter().map(|o| o.total).max(), Some(full));
            assert_eq!(outs.last().map(|o| o.total), Some(0));
        }
    }

    #[test]
    fn bad_parameters_are_refused() {
        for c in [
            QueueFrontConfig {
                vol_blocks: 7,
                ..SMALL
            },
            QueueFrontConfig {
                queue_len: 0,
                ..SMALL
            },
            QueueFrontConfig { ranks: 9, ..SMALL },
            QueueFrontConfig {
                block_log2: 9,
                ..SMALL
            },
        ] {
            assert!(QueueFrontUnit::new(c).is_err(), "{c:?}");
        }
    }
}
