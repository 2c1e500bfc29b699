//! The GI-Cube block processor's ray queues (patent [370]-[372]), written from
//! `docs/numerics/gicube_ray_queues.md`: `Q = 2^QueueW` fixed-size FIFO queues of `QueueLen` rays
//! each, one per block; per item at most one dequeue (the head of the active queue, [371]) and one
//! enqueue (a ray into its block's queue); a ray that finds its queue full is returned, never
//! dropped ([372]); the occupancy of every queue is counted (the importance the sorter sorts,
//! [373] criterion 1).
//!
//! [`RayQueues`] is the one description of the queues: the stream unit [`RayQueuesUnit`] (the
//! model of the RTL top `gicube_ray_queues`) and the processor's frame loop
//! (`gicube_processor::Processor`) both run it. It is order-dependent, so the model is
//! cycle-accurate: one [`RayQueues::step`] is one item of the RTL (one clock when never stalled).

use std::collections::VecDeque;

use rand::Rng;

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::{param_in, StreamCodec, StreamUnit};

/// Largest `DataW`: one 32-byte ray packet ([349], [391]).
pub const MAX_DATA_W: u32 = 256;
/// 32-bit words of a ray as the unit carries it.
pub const DATA_WORDS: usize = (MAX_DATA_W / 32) as usize;

/// What one step did (contract, "One item").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct QueueStep<T> {
    /// The head of the popped queue, if it held a ray.
    pub popped: Option<T>,
    /// The pop took the queue's last ray (the active queue emptied, [374]).
    pub emptied: bool,
    /// The pushed ray when its queue was full at the start of the step ([372]); `None` when it
    /// was written (or nothing was pushed).
    pub overflow: Option<T>,
}

/// `Q` FIFO queues of at most `queue_len` rays each, stepped one item at a time.
#[derive(Debug, Clone)]
pub struct RayQueues<T> {
    queue_len: usize,
    queues: Vec<VecDeque<T>>,
    total: usize,
}

impl<T> RayQueues<T> {
    /// `queues` empty queues of `queue_len` rays (the state after reset).
    pub fn new(queues: u32, queue_len: u32) -> Self {
        Self {
            queue_len: queue_len as usize,
            queues: (0..queues).map(|_| VecDeque::new()).collect(),
            total: 0,
        }
    }

    /// Number of queues.
    pub fn queues(&self) -> u32 {
        self.queues.len() as u32
    }

    /// Rays a queue holds at most.
    pub fn queue_len(&self) -> u32 {
        self.queue_len as u32
    }

    /// Rays in queue `q`.
    pub fn len(&self, q: u32) -> u32 {
        self.queues[q as usize].len() as u32
    }

    /// Queue `q` holds no ray.
    pub fn is_empty(&self, q: u32) -> bool {
        self.queues[q as usize].is_empty()
    }

    /// Queue `q` holds `queue_len` rays: a push to it overflows.
    pub fn is_full(&self, q: u32) -> bool {
        self.queues[q as usize].len() >= self.queue_len
    }

    /// Rays in all queues.
    pub fn total(&self) -> u32 {
        self.total as u32
    }

    /// One item: the pop and the push both see the state at the start of the step, so a push to
    /// a full queue overflows even when the same step pops that queue (the RAM's read and write
    /// ports never meet one slot in one clock). Then the pop removes the head, the push appends.
    pub fn step(&mut self, pop: Option<u32>, push: Option<(u32, T)>) -> QueueStep<T> {
        let accept = push.as_ref().map(|(q, _)| !self.is_full(*q));
        let popped = pop.and_then(|q| self.queues[q as usize].pop_front());
        let emptied = popped.is_some() && pop.is_some_and(|q| self.is_empty(q));
        if popped.is_some() {
            self.total -= 1;
        }
        let overflow = match (push, accept) {
            (Some((q, ray)), Some(true)) => {
                self.queues[q as usize].push_back(ray);
                self.total += 1;
                None
            }
            (Some((_, ray)), _) => Some(ray),
            (None, _) => None,
        };
        QueueStep {
            popped,
            emptied,
            overflow,
        }
    }

    /// A step that only pops `q`: its head, if any.
    pub fn pop(&mut self, q: u32) -> Option<T> {
        self.step(Some(q), None).popped
    }

    /// A step that only pushes `ray` into `q`: `Err(ray)` when `q` was full (the overflow).
    pub fn push(&mut self, q: u32, ray: T) -> std::result::Result<(), T> {
        match self.step(None, Some((q, ray))).overflow {
            None => Ok(()),
            Some(ray) => Err(ray),
        }
    }

    /// Empties every queue (reset).
    pub fn clear(&mut self) {
        self.queues.iter_mut().for_each(VecDeque::clear);
        self.total = 0;
    }
}

/// One configuration of the RTL top `gicube_ray_queues`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RayQueuesConfig {
    /// Queue number width, 1..=8: `2^QueueW` queues.
    pub queue_w: u32,
    /// Rays per queue, 1..=4096 (256 in [371]).
    pub queue_len: u32,
    /// Bits of one ray, 1..=256 (256: the packet of [349]).
    pub data_w: u32,
}

impl RayQueuesConfig {
    /// The RTL's parameter defaults: 64 queues of 64 rays of the 256-bit packet.
    pub const DEFAULT: Self = Self {
        queue_w: 6,
        queue_len: 64,
        data_w: MAX_DATA_W,
    };

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(ModelError::Config(format!("gicube_ray_queues: {m}")));
        param_in("QueueW", self.queue_w, 1..=8).or_else(bad)?;
        param_in("QueueLen", self.queue_len, 1..=4096).or_else(bad)?;
        if !(1..=MAX_DATA_W).contains(&self.data_w) {
            return bad(format!("DataW {} outside 1..={MAX_DATA_W}", self.data_w));
        }
        Ok(())
    }

    /// `Q = 2^QueueW`.
    pub fn queues(&self) -> u32 {
        1 << self.queue_w
    }

    /// `LenW = bitlen(QueueLen)`: a queue's count, 0..=QueueLen.
    pub fn len_w(&self) -> u32 {
        32 - self.queue_len.leading_zeros()
    }

    /// `TotW = bitlen(Q QueueLen)`: the rays in all queues.
    pub fn tot_w(&self) -> u32 {
        32 - (self.queues() * self.queue_len).leading_zeros()
    }

    /// `SlotW = max(1, clog2(QueueLen))`: slot address within a queue's region of the RAM.
    pub fn slot_w(&self) -> u32 {
        (32 - (self.queue_len - 1).leading_zeros()).max(1)
    }

    /// Latency in clocks (one output register).
    pub fn latency(&self) -> u64 {
        1
    }

    /// A ray's words with the bits above `DataW` cleared.
    pub fn mask(&self, ray: Ray) -> Ray {
        std::array::from_fn(|i| {
            let lo = 32 * i as u32;
            match self.data_w.saturating_sub(lo) {
                0 => 0,
                n if n >= 32 => ray[i],
                n => ray[i] & ((1u32 << n) - 1),
            }
        })
    }
}

crate::unit_config!(RayQueuesConfig, "gicube_ray_queues", DEFAULT, {
    "QueueW" => queue_w,
    "QueueLen" => queue_len,
    "DataW" => data_w,
});

/// A ray as the unit carries it: `DataW` bits, LSB first in 32-bit words (a whole packet when
/// `DataW = 256`: `RayPacket::to_bits`).
pub type Ray = [u32; DATA_WORDS];

/// One input item (contract, "Input").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct QueuesIn {
    /// Dequeue the head of `pop_q`.
    pub pop: bool,
    pub pop_q: u32,
    /// Enqueue `data` into `push_q`.
    pub push: bool,
    pub push_q: u32,
    pub data: Ray,
}

/// One output item (contract, "Output").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct QueuesOut {
    pub popped: bool,
    pub emptied: bool,
    pub pushed: bool,
    pub overflow: bool,
    /// Rays in `pop_q`, and in `push_q`, after the item (reported for every item: a probe).
    pub pop_len: u32,
    pub push_len: u32,
    /// Rays in all queues after the item.
    pub total: u32,
    /// The dequeued ray (0 unless `popped`).
    pub pop_data: Ray,
    /// The ray returned to the host (0 unless `overflow`).
    pub ovf_data: Ray,
}

/// The golden model of `gicube_ray_queues`: [`RayQueues`] behind the stream interface.
#[derive(Debug, Clone)]
pub struct RayQueuesUnit {
    cfg: RayQueuesConfig,
    queues: RayQueues<Ray>,
}

impl RayQueuesUnit {
    pub fn new(cfg: RayQueuesConfig) -> Result<Self> {
        cfg.validate()?;
        Ok(Self {
            cfg,
            queues: RayQueues::new(cfg.queues(), cfg.queue_len),
        })
    }

    pub fn config(&self) -> RayQueuesConfig {
        self.cfg
    }

    pub fn queues(&self) -> &RayQueues<Ray> {
        &self.queues
    }

    /// One item.
    pub fn step(&mut self, item: &QueuesIn) -> QueuesOut {
        let qmask = self.cfg.queues() - 1;
        let (pop_q, push_q) = (item.pop_q & qmask, item.push_q & qmask);
        let data = self.cfg.mask(item.data);
        let s = self.queues.step(
            item.pop.then_some(pop_q),
            item.push.then_some((push_q, data)),
        );
        QueuesOut {
            popped: s.popped.is_some(),
            emptied: s.emptied,
            pushed: item.push && s.overflow.is_none(),
            overflow: s.overflow.is_some(),
            pop_len: self.queues.len(pop_q),
            push_len: self.queues.len(push_q),
            total: self.queues.total(),
            pop_data: s.popped.unwrap_or_default(),
            ovf_data: s.overflow.unwrap_or_default(),
        }
    }
}

impl StreamUnit for RayQueuesUnit {
    type In = QueuesIn;
    type Out = QueuesOut;

    fn run(&mut self, inputs: &[QueuesIn]) -> Vec<QueuesOut> {
        inputs.iter().map(|i| self.step(i)).collect()
    }

    fn reset(&mut self) {
        self.queues.clear();
    }
}

pub(crate) fn put_ray(w: &mut BitWriter, ray: &Ray, width: u32) {
    let mut left = width;
    for word in ray {
        if left == 0 {
            break;
        }
        let n = left.min(32);
        w.put(u64::from(*word) & ((1u64 << n) - 1), n);
        left -= n;
    }
}

pub(crate) fn get_ray(r: &mut BitReader, width: u32) -> Ray {
    let mut ray = [0u32; DATA_WORDS];
    let mut left = width;
    for word in &mut ray {
        if left == 0 {
            break;
        }
        let n = left.min(32);
        *word = r.get(n) as u32;
        left -= n;
    }
    ray
}

impl StreamCodec for RayQueuesConfig {
    type In = QueuesIn;
    type Out = QueuesOut;

    fn in_width(&self) -> u32 {
        2 + 2 * self.queue_w + self.data_w
    }

    fn out_width(&self) -> u32 {
        4 + 2 * self.len_w() + self.tot_w() + 2 * self.data_w
    }

    fn pack_in(&self, item: &QueuesIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        w.put_bool(item.pop)
            .put(u64::from(item.pop_q), self.queue_w)
            .put_bool(item.push)
            .put(u64::from(item.push_q), self.queue_w);
        put_ray(&mut w, &item.data, self.data_w);
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> QueuesOut {
        let mut r = BitReader::new(words);
        QueuesOut {
            popped: r.get_bool(),
            emptied: r.get_bool(),
            pushed: r.get_bool(),
            overflow: r.get_bool(),
            pop_len: r.get(self.len_w()) as u32,
            push_len: r.get(self.len_w()) as u32,
            total: r.get(self.tot_w()) as u32,
            pop_data: get_ray(&mut r, self.data_w),
            ovf_data: get_ray(&mut r, self.data_w),
        }
    }
}

/// Random traffic that fills queues to overflow and drains them to empty: phases of a few hundred
/// items, each `Fill` (pushes into a few hot queues, rare pops), `Drain` (the active queue popped
/// until empty, then the fullest of a few random queues, as a sorter would pick; some pushes) or
/// `Mixed` (pops and pushes at random queues). Every ray carries random bits.
#[derive(Debug, Clone)]
pub struct QueueTraffic {
    cfg: RayQueuesConfig,
    /// The counts the unit will hold (the generator steps its own copy of the queues).
    shadow: RayQueues<()>,
    phase: Phase,
    left: u32,
    hot: [u32; 3],
    active: u32,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Fill,
    Drain,
    Mixed,
}

impl QueueTraffic {
    pub fn new(cfg: RayQueuesConfig) -> Self {
        Self {
            cfg,
            shadow: RayQueues::new(cfg.queues(), cfg.queue_len),
            phase: Phase::Mixed,
            left: 0,
            hot: [0; 3],
            active: 0,
        }
    }

    /// Forget the counts (the unit was reset).
    pub fn reset(&mut self) {
        self.shadow.clear();
    }

    fn random_ray(&self, rng: &mut impl Rng) -> Ray {
        self.cfg.mask(std::array::from_fn(|_| rng.random()))
    }

    pub fn next_item(&mut self, rng: &mut impl Rng) -> QueuesIn {
        let nq = self.cfg.queues();
        if self.left == 0 {
            self.phase = match rng.random_range(0..3) {
                0 => Phase::Fill,
                1 => Phase::Drain,
                _ => Phase::Mixed,
            };
            self.left = rng.random_range(16..=4 * self.cfg.queue_len.max(64));
            self.hot = std::array::from_fn(|_| rng.random_range(0..nq));
        }
        self.left -= 1;
        let rnd_q = |rng: &mut dyn rand::RngCore| rng.random_range(0..nq);
        let (pop, pop_q, push, push_q) = match self.phase {
            Phase::Fill => (
                rng.random_bool(0.1),
                self.hot[rng.random_range(0..3)],
                rng.random_bool(0.9),
                if rng.random_bool(0.8) {
                    self.hot[rng.random_range(0..3)]
                } else {
                    rnd_q(rng)
                },
            ),
            Phase::Drain => {
                if self.shadow.is_empty(self.active) {
                    // The fullest of a few candidates (a sorter's choice, roughly).
                    self.active = (0..4)
                        .map(|_| rnd_q(rng))
                        .max_by_key(|&q| self.shadow.len(q))
                        .unwrap_or(0);
                }
                (
                    rng.random_bool(0.95),
                    self.active,
                    rng.random_bool(0.3),
                    if rng.random_bool(0.5) {
                        self.active
                    } else {
                        rnd_q(rng)
                    },
                )
            }
            Phase::Mixed => (
                rng.random_bool(0.5),
                rnd_q(rng),
                rng.random_bool(0.5),
                rnd_q(rng),
            ),
        };
        let item = QueuesIn {
            pop,
            pop_q,
            push,
            push_q,
            data: self.random_ray(rng),
        };
        self.shadow
            .step(item.pop.then_some(pop_q), item.push.then_some((push_q, ())));
        item
    }
}

/// Directed extremes (contract, "Directed"): pop an empty queue; fill the last and the first queue
/// to exactly `QueueLen` and push one more (overflow); pop and push one full queue in one item
/// (the push overflows, the pop takes the head); pop and push one empty queue in one item (the
/// push is written); wrap every pointer twice with all-ones and alternating data; fill every queue
/// (the largest total), then drain them all to 0.
pub fn directed_items(cfg: RayQueuesConfig) -> Vec<QueuesIn> {
    let nq = cfg.queues();
    let last = nq - 1;
    let ones = cfg.mask([u32::MAX; DATA_WORDS]);
    let alt = cfg.mask([0xaaaa_5555; DATA_WORDS]);
    let tag = |k: u32| {
        cfg.mask(std::array::from_fn(|i| {
            k.rotate_left(7 * i as u32) ^ 0x5a5a_0f0f
        }))
    };
    let push = |q: u32, data: Ray| QueuesIn {
        push: true,
        push_q: q,
        data,
        ..Default::default()
    };
    let pop = |q: u32| QueuesIn {
        pop: true,
        pop_q: q,
        ..Default::default()
    };
    let both = |pq: u32, uq: u32, data: Ray| QueuesIn {
        pop: true,
        pop_q: pq,
        push: true,
        push_q: uq,
        data,
    };
    let mut v = vec![QueuesIn::default(), pop(0), pop(last)];
    for q in [last, 0] {
        v.extend((0..cfg.queue_len).map(|k| push(q, tag(k + q))));
        v.push(push(q, ones));
        v.push(both(q, q, alt));
        v.push(push(q, alt));
    }
    for q in [last, 0] {
        v.extend((0..=cfg.queue_len).map(|_| pop(q)));
        v.push(both(q, q, ones));
        v.push(pop(q));
    }
    // Wrap the pointers of queue 1 (or 0) twice, one ray in, one out.
    let w = 1 & last;
    for k in 0..2 * cfg.queue_len + 3 {
        v.push(both(w, w, if k % 2 == 0 { ones } else { alt }));
    }
    v.push(pop(w));
    // Every queue full, then all drained.
    for q in 0..nq {
        v.extend((0..cfg.queue_len).map(|k| push(q, tag(k ^ q << 12))));
    }
    v.push(both(nq / 2, nq / 2, ones));
    for q in (0..nq).rev() {
        v.extend((0..=cfg.queue_len).map(|_| pop(q)));
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    const SMALL: RayQueuesConfig = RayQueuesConfig {
        queue_w: 2,
        queue_len: 3,
        data_w: 12,
    };

    #[test]
    fn fifo_order_overflow_and_counts() {
        let mut q: RayQueues<u32> = RayQueues::new(4, 3);
        assert_eq!(q.pop(1), None);
        for k in 0..3 {
            assert_eq!(q.push(1, k), Ok(()));
        }
        assert_eq!(q.push(1, 9), Err(9), "the fourth ray overflows");
        assert_eq!((q.len(1), q.total()), (3, 3));
        // A pop and a push of the full queue in one step: the push still overflows.
        let s = q.step(Some(1), Some((1, 7)));
        assert_eq!((s.popped, s.emptied, s.overflow), (Some(0), false, Some(7)));
        // A pop and a push of an empty queue in one step: the push is written.
        let s = q.step(Some(2), Some((2, 8)));
        assert_eq!((s.popped, s.overflow), (None, None));
        assert_eq!(q.pop(1), Some(1));
        let s = q.step(Some(1), None);
        assert_eq!((s.popped, s.emptied), (Some(2), true));
        assert_eq!(q.pop(2), Some(8));
        assert_eq!(q.total(), 0);
    }

    #[test]
    fn codec_round_trip_and_widths() {
        let cfg = RayQueuesConfig::DEFAULT;
        assert_eq!(cfg.in_width(), 2 + 12 + 256);
        assert_eq!(cfg.out_width(), 4 + 14 + 13 + 512);
        assert_eq!((SMALL.len_w(), SMALL.tot_w(), SMALL.slot_w()), (2, 4, 2));
        let out = QueuesOut {
            popped: true,
            emptied: false,
            pushed: true,
            overflow: true,
            pop_len: 3,
            push_len: 1,
            total: 12,
            pop_data: SMALL.mask([0xfff; DATA_WORDS]),
            ovf_data: SMALL.mask([0xabc; DATA_WORDS]),
        };
        let mut w = BitWriter::new();
        w.put(0b1101, 4).put(3, 2).put(1, 2).put(12, 4);
        put_ray(&mut w, &out.pop_data, 12);
        put_ray(&mut w, &out.ovf_data, 12);
        assert_eq!(SMALL.unpack_out(&w.finish(SMALL.out_width())), out);
    }

    #[test]
    fn conservation_under_random_traffic() {
        for cfg in [SMALL, RayQueuesConfig::DEFAULT] {
            let mut unit = RayQueuesUnit::new(cfg).unwrap();
            let mut t = QueueTraffic::new(cfg);
            let mut rng = ChaCha8Rng::seed_from_u64(7);
            let (mut offered, mut popped, mut ovf) = (0u64, 0u64, 0u64);
            for _ in 0..200_000 {
                let i = t.next_item(&mut rng);
                let o = unit.step(&i);
                offered += u64::from(i.push);
                popped += u64::from(o.popped);
                ovf += u64::from(o.overflow);
                assert_eq!(o.pushed, i.push && !o.overflow);
            }
            assert!(ovf > 1000, "the traffic forces overflow ({ovf})");
            let held = u64::from(unit.queues().total());
            assert_eq!(
                offered,
                popped + ovf + held,
                "rays in = out + overflowed + held"
            );
        }
    }

    #[test]
    fn directed_items_reach_every_extreme() {
        for cfg in [SMALL, RayQueuesConfig::DEFAULT] {
            let mut unit = RayQueuesUnit::new(cfg).unwrap();
            let outs = unit.run(&directed_items(cfg));
            let max_total = outs.iter().map(|o| o.total).max().unwrap();
            assert_eq!(max_total, cfg.queues() * cfg.queue_len);
            assert!(outs.iter().any(|o| o.overflow && o.popped));
            assert!(outs.iter().any(|o| o.emptied));
            assert_eq!(outs.last().unwrap().total, 0);
        }
    }

    #[test]
    fn bad_parameters_are_refused() {
        for c in [
            RayQueuesConfig {
                queue_w: 0,
                ..SMALL
            },
            RayQueuesConfig {
                queue_len: 0,
                ..SMALL
            },
            RayQueuesConfig {
                data_w: 257,
                ..SMALL
            },
        ] {
            assert!(RayQueuesUnit::new(c).is_err());
        }
    }
}
