//! The GI-Cube block processor's step, leap and advance (patent [355], [357]), written from
//! `docs/numerics/gicube_step.md`: the per-ray step `delta = rnd(dir * dr, 14)`, the leap over an
//! empty block to the first grid position outside it, the advance `next = start + k delta`, the
//! exit test against the volume's domain and the re-bucketing of the new position
//! (`gicube_bucket`). A pure function of the item: parts E and O of docs/gicube-rtl.md.
//!
//! `gicube_processor::Processor` advances every ray through [`Stepper::step`], so this is the one
//! description of the step; the RTL is `rtl/gicube/gicube_step.sv` (step 3 of docs/gicube-rtl.md).

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::{param_in, StreamCodec};
use crate::units::gicube_bucket::{BucketConfig, BucketUnit, Distribution, Position};
use crate::units::gicube_packet_loop::{DIR_FRAC_W, POS_FRAC_W, POS_W};

/// Bits of one direction component, `S(2.14)`.
pub const DIR_W: u32 = 16;

/// One configuration of the step (the processor's domain and sample distance).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepConfig {
    /// Block side `n = 2^block_log2` voxels, 2..=8.
    pub block_log2: u32,
    /// Blocks a side `B`, 1..=64 (`N = B n <= 4096`).
    pub vol_blocks: u32,
    /// The sample distance `dr`, `U(4.8)` voxels, 16..=1024.
    pub step: u32,
}

impl StepConfig {
    /// The RTL's parameter defaults: 32^3 blocks, 8 a side (the design point of [370]), `dr` =
    /// 200/256 voxel.
    pub const DEFAULT: Self = Self {
        block_log2: 5,
        vol_blocks: 8,
        step: 200,
    };

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("gicube_step: {what}")));
        param_in("BlockLog2", self.block_log2, 2..=8).or_else(bad)?;
        param_in("VolBlocks", self.vol_blocks, 1..=64).or_else(bad)?;
        if self.vol_blocks << self.block_log2 > 1 << (POS_W - POS_FRAC_W) {
            return bad(format!(
                "the domain side {} exceeds 4096 voxels",
                self.vol_blocks << self.block_log2
            ));
        }
        param_in("Step", self.step, 16..=1024).or_else(bad)?;
        Ok(())
    }

    /// `QueueW = max(1, clog2(B^3))`: `gicube_bucket`'s with one processor.
    pub fn queue_w(&self) -> u32 {
        self.bucket_config().queue_w()
    }

    /// `KW = b + 9`: `k <= n 256`.
    pub fn k_w(&self) -> u32 {
        self.block_log2 + 9
    }

    /// Clocks from input to output: the products, `delta`, the numerators, `b + 8` quotient
    /// stages, `k delta`, `next`, the exit test and re-bucketing (docs/numerics/gicube_step.md).
    pub fn latency(&self) -> u64 {
        u64::from(self.block_log2) + 14
    }

    fn bucket_config(&self) -> BucketConfig {
        BucketConfig {
            block_log2: self.block_log2,
            vol_blocks: self.vol_blocks,
            proc_log2: 0,
            dist: Distribution::Slab,
            lanes: 1,
        }
    }
}

crate::unit_config!(StepConfig, "gicube_step", DEFAULT, {
    "BlockLog2" => block_log2,
    "VolBlocks" => vol_blocks,
    "Step" => step,
});

/// One ray into the step unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepIn {
    /// Start position, raw `U(12.8)` per axis.
    pub start: [u32; 3],
    /// Direction, raw `S(2.14)` per axis.
    pub dir: [i16; 3],
    /// The ray's queue (carried; the block a leap leaves is that of `start`).
    pub queue: u32,
    /// The block is empty and the ray may leap.
    pub leap: bool,
}

/// What the step did to one ray.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepOut {
    /// Grid steps taken: 1, or the leap's count (at least 1).
    pub k: u32,
    /// The ray left the domain `[0, N 256)^3`: it is finished and `next` is its start unchanged.
    pub exit: bool,
    /// The new start position (raw `U(12.8)`), or the old one when `exit`.
    pub next: [u32; 3],
    /// The queue (block) of `next`; the old queue when `exit`.
    pub queue: u32,
}

/// The step unit's model: the bucketing of the processor (slab, one processor).
#[derive(Debug, Clone)]
pub struct Stepper {
    cfg: StepConfig,
    bucket: BucketUnit,
}

/// `(x + 2^(s-1)) >> s`, arithmetic: round half toward +infinity.
#[inline]
fn rnd_signed(x: i64, s: u32) -> i64 {
    (x + (1 << (s - 1))) >> s
}

impl Stepper {
    pub fn new(cfg: StepConfig) -> Result<Self> {
        cfg.validate()?;
        let bucket = BucketUnit::new(cfg.bucket_config())?;
        Ok(Self { cfg, bucket })
    }

    pub fn config(&self) -> StepConfig {
        self.cfg
    }

    /// The bucketing unit the step re-buckets with.
    pub fn bucket(&self) -> &BucketUnit {
        &self.bucket
    }

    /// `delta_i = rnd(dir_i * dr, 14)`: the signed step per axis, `S(.8)` voxels.
    pub fn delta(&self, dir: [i16; 3]) -> [i64; 3] {
        dir.map(|d| rnd_signed(i64::from(d) * i64::from(self.cfg.step), DIR_FRAC_W))
    }

    /// The leap's count: the smallest `k >= 1` such that `start + k delta` is outside block
    /// `block` (raw `[b n 256, (b + 1) n 256)` per axis) on some axis; 1 when no axis moves.
    pub fn steps_to_exit(&self, start: [u32; 3], delta: [i64; 3], block: [u32; 3]) -> u32 {
        let n = (1i64 << self.cfg.block_log2) << POS_FRAC_W;
        let mut k = i64::MAX;
        for a in 0..3 {
            let p = i64::from(start[a]);
            let lo = i64::from(block[a]) * n;
            let d = delta[a];
            if d > 0 {
                k = k.min((lo + n - p + d - 1) / d);
            } else if d < 0 {
                k = k.min((p - lo - d) / -d);
            }
        }
        if k == i64::MAX {
            1
        } else {
            k.max(1) as u32
        }
    }

    /// The block of a position: `floor(start_i / (n 256))` per axis (contract, "Input and
    /// output"; in the processor the block of the ray's queue).
    pub fn block_of_start(&self, start: [u32; 3]) -> [u32; 3] {
        start.map(|p| p >> (POS_FRAC_W + self.cfg.block_log2))
    }

    /// One ray of queue `queue` at `start` with direction `dir`: `k = steps_to_exit` from the
    /// block of `start` when `leap` (its block is empty and it may leap), else 1; `next = start +
    /// k delta`; outside `[0, N 256)` on any axis: `exit`; else the queue of `next`.
    pub fn step(&self, start: [u32; 3], dir: [i16; 3], queue: u32, leap: bool) -> StepOut {
        let delta = self.delta(dir);
        let k = if leap {
            self.steps_to_exit(start, delta, self.block_of_start(start))
        } else {
            1
        };
        let limit = i64::from(self.cfg.vol_blocks << self.cfg.block_log2) << POS_FRAC_W;
        let next: [i64; 3] = std::array::from_fn(|a| i64::from(start[a]) + i64::from(k) * delta[a]);
        let out = |exit, next, queue| StepOut {
            k,
            exit,
            next,
            queue,
        };
        if next.iter().any(|&c| c < 0 || c >= limit) {
            return out(true, start, queue);
        }
        let next = next.map(|c| c as u32);
        let b = self.bucket.bucket(Position(next));
        if b.outside {
            out(true, start, queue)
        } else {
            out(false, next, b.queue)
        }
    }
}

crate::item_by_item!(Stepper, StepIn => StepOut, |unit, it| {
    unit.step(it.start, it.dir, it.queue, it.leap)
});

impl Stepper {
    /// The f64 reference of the leap and advance: `delta` as the contract rounds it (it is the
    /// ray's grid, not an approximation), then `k` as the first `j >= 1` whose real position
    /// `start + j delta` (in voxels) leaves the block `[b n, (b + 1) n)` of `start` on some axis,
    /// from real divisions and `ceil`; exit and queue from the real position.
    pub fn reference(&self, it: &StepIn) -> StepOut {
        let c = &self.cfg;
        let n = f64::from(1u32 << c.block_log2);
        let scale = f64::from(1u32 << POS_FRAC_W);
        let delta = self.delta(it.dir).map(|d| d as f64 / scale);
        let start = it.start.map(|p| f64::from(p) / scale);
        let mut k = 1.0f64;
        if it.leap {
            let mut best = f64::INFINITY;
            for a in 0..3 {
                let lo = (start[a] / n).floor() * n;
                let kk = if delta[a] > 0.0 {
                    ((lo + n - start[a]) / delta[a]).ceil()
                } else if delta[a] < 0.0 {
                    // The first position below lo: start + j delta < lo, i.e. j > (start - lo) / -delta.
                    ((start[a] - lo) / -delta[a]).floor() + 1.0
                } else {
                    f64::INFINITY
                };
                best = best.min(kk);
            }
            if best.is_finite() {
                k = best.max(1.0);
            }
        }
        let side = f64::from(c.vol_blocks) * n;
        let next = std::array::from_fn::<f64, 3, _>(|a| start[a] + k * delta[a]);
        let queue = self.bucket.reference(next);
        if next.iter().any(|&x| !(0.0..side).contains(&x)) || queue.outside {
            return StepOut {
                k: k as u32,
                exit: true,
                next: it.start,
                queue: it.queue,
            };
        }
        StepOut {
            k: k as u32,
            exit: false,
            next: next.map(|x| (x * scale) as u32),
            queue: queue.queue,
        }
    }
}

impl StreamCodec for StepConfig {
    type In = StepIn;
    type Out = StepOut;

    fn in_width(&self) -> u32 {
        3 * POS_W + 3 * DIR_W + self.queue_w() + 1
    }

    fn out_width(&self) -> u32 {
        self.k_w() + 1 + 3 * POS_W + self.queue_w()
    }

    fn pack_in(&self, it: &StepIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        for p in it.start {
            w.put(u64::from(p), POS_W);
        }
        for d in it.dir {
            w.put(u64::from(d as u16), DIR_W);
        }
        w.put(u64::from(it.queue), self.queue_w());
        w.put_bool(it.leap);
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> StepOut {
        let mut r = BitReader::new(words);
        let k = r.get(self.k_w()) as u32;
        let exit = r.get_bool();
        let next = std::array::from_fn(|_| r.get(POS_W) as u32);
        let queue = r.get(self.queue_w()) as u32;
        StepOut {
            k,
            exit,
            next,
            queue,
        }
    }
}

/// A random ray for tests and benches: a start inside the domain (a quarter on or next to a block
/// face), sometimes anywhere in `U(12.8)`; the queue of its start (the processor's invariant);
/// directions mostly unit-length-ish, some along one axis, some extreme (`-2.0`, `+2.0 - 2^-14`,
/// 0, tiny); `leap` half the time.
pub fn random_step_in(rng: &mut impl rand::Rng, cfg: &StepConfig) -> StepIn {
    let n_raw = (cfg.vol_blocks << cfg.block_log2) << POS_FRAC_W;
    let blk = 1u32 << (cfg.block_log2 + POS_FRAC_W);
    let axis = |rng: &mut dyn rand::RngCore| -> u32 {
        match rand::Rng::random_range(rng, 0..16) {
            0 => rand::Rng::random_range(rng, 0..1u32 << POS_W),
            1..=4 => {
                let b = rand::Rng::random_range(rng, 0..=cfg.vol_blocks) * blk;
                let off = rand::Rng::random_range(rng, -3i64..=2);
                (i64::from(b) + off).clamp(0, i64::from(n_raw) - 1) as u32
            }
            _ => rand::Rng::random_range(rng, 0..n_raw),
        }
    };
    let start = [axis(rng), axis(rng), axis(rng)];
    let dir_axis = |rng: &mut dyn rand::RngCore| -> i16 {
        match rand::Rng::random_range(rng, 0..12) {
            0 => 0,
            1 => [i16::MIN, i16::MAX, 1, -1, 16384, -16384][rand::Rng::random_range(rng, 0..6)],
            2 => rand::Rng::random_range(rng, -40i16..=40),
            3 => rand::Rng::random_range(rng, i16::MIN..=i16::MAX),
            _ => rand::Rng::random_range(rng, -16384i16..=16384),
        }
    };
    let dir = [dir_axis(rng), dir_axis(rng), dir_axis(rng)];
    let bucket = BucketUnit::new(cfg.bucket_config()).expect("a valid step configuration");
    let b = bucket.bucket(Position(start));
    let queue = if b.outside {
        rand::Rng::random_range(rng, 0..1u32 << cfg.queue_w())
    } else {
        b.queue
    };
    StepIn {
        start,
        dir,
        queue,
        leap: rand::Rng::random_bool(rng, 0.5),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CFG: StepConfig = StepConfig {
        block_log2: 3,
        vol_blocks: 4,
        step: 256,
    };

    #[test]
    fn delta_rounds_half_up() {
        let s = Stepper::new(CFG).unwrap();
        // dir 1.0 = 16384: one voxel per step exactly; -0.5 voxel - half an LSB rounds up.
        assert_eq!(s.delta([16384, -8192, 0]), [256, -128, 0]);
        // dir * 16 = 2^13: exactly half a raw unit.
        let half = Stepper::new(StepConfig { step: 16, ..CFG }).unwrap();
        assert_eq!(half.delta([512, -512, 511]), [1, 0, 0]);
    }

    #[test]
    fn leap_lands_on_the_first_grid_point_outside_the_block() {
        let s = Stepper::new(CFG).unwrap();
        // Block (0, 0, 0) is [0, 8 * 256) per axis; from x = 100 at +256 per step: 8 steps.
        let o = s.step([100, 300, 300], [16384, 0, 0], 0, true);
        assert_eq!(o.k, 8);
        assert_eq!(o.next, [100 + 8 * 256, 300, 300]);
        assert_eq!(o.queue, s.bucket().bucket(Position(o.next)).queue);
        assert!(!o.exit);
        // Backwards from x = 2047 in block 0: the first position below 0 leaves the domain.
        let o = s.step([2047, 0, 0], [-16384, 0, 0], 0, true);
        assert!(o.exit && o.next == [2047, 0, 0]);
        // Without a leap: one step.
        let o = s.step([100, 300, 300], [16384, 0, 0], 0, false);
        assert_eq!((o.k, o.next, o.queue), (1, [356, 300, 300], 0));
    }

    #[test]
    fn exit_at_the_far_face() {
        let s = Stepper::new(CFG).unwrap();
        let top = (4 * 8 * 256) - 1;
        let o = s.step([top, 5, 5], [16384, 0, 0], 63, false);
        assert!(o.exit);
        assert_eq!((o.next, o.queue), ([top, 5, 5], 63));
    }

    #[test]
    fn model_matches_the_f64_reference() {
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(15);
        for cfg in [
            CFG,
            StepConfig::DEFAULT,
            StepConfig {
                block_log2: 8,
                vol_blocks: 16,
                step: 1000,
            },
            StepConfig {
                block_log2: 2,
                vol_blocks: 3,
                step: 77,
            },
        ] {
            let s = Stepper::new(cfg).unwrap();
            let mut leaps = 0;
            for _ in 0..200_000 {
                let it = random_step_in(&mut rng, &cfg);
                let o = s.step(it.start, it.dir, it.queue, it.leap);
                assert_eq!(o, s.reference(&it), "{cfg:?} {it:?}");
                assert!(o.k >= 1 && o.k <= 1 << (cfg.block_log2 + 8));
                leaps += usize::from(o.k > 1);
            }
            assert!(leaps > 10_000, "{cfg:?}: leaps exercised ({leaps})");
        }
    }

    #[test]
    fn the_block_is_that_of_start_and_the_queue_is_carried() {
        let s = Stepper::new(CFG).unwrap();
        // Start in block (1, 0, 0) with a foreign queue: the leap leaves block 1 (x < 4096).
        let o = s.step([2048 + 100, 0, 0], [16384, 0, 0], 5, true);
        assert_eq!((o.k, o.next), (8, [2048 + 100 + 8 * 256, 0, 0]));
        // An exit keeps the queue given.
        let o = s.step([8191, 0, 0], [16384, 0, 0], 5, true);
        assert!(o.exit && o.queue == 5 && o.k == 1);
        // No axis moves: k = 1, next = start.
        let o = s.step([300, 300, 300], [0, 0, 0], 0, true);
        assert_eq!((o.k, o.exit, o.next), (1, false, [300, 300, 300]));
    }

    #[test]
    fn codec_widths_and_round_trip() {
        let c = StepConfig {
            block_log2: 8,
            vol_blocks: 16,
            step: 1000,
        };
        assert_eq!(
            (c.in_width(), c.out_width(), c.queue_w(), c.k_w()),
            (121, 90, 12, 17)
        );
        assert_eq!(c.latency(), 22);
        let it = StepIn {
            start: [0xfffff, 1, 0x80000],
            dir: [-1, i16::MIN, i16::MAX],
            queue: 0xabc,
            leap: true,
        };
        let w = c.pack_in(&it);
        let mut r = BitReader::new(&w);
        assert_eq!(r.get(20), 0xfffff);
        r.get(40);
        assert_eq!(r.get(16), 0xffff);
        r.get(32);
        assert_eq!((r.get(12), r.get_bool()), (0xabc, true));
    }

    #[test]
    fn config_validation() {
        use crate::unit::UnitConfig;
        assert!(StepConfig::DEFAULT.validate().is_ok());
        for bad in [
            StepConfig {
                block_log2: 1,
                ..CFG
            },
            StepConfig {
                block_log2: 9,
                ..CFG
            },
            StepConfig {
                vol_blocks: 0,
                ..CFG
            },
            StepConfig {
                block_log2: 8,
                vol_blocks: 17,
                ..CFG
            },
            StepConfig { step: 15, ..CFG },
            StepConfig { step: 1025, ..CFG },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
            assert!(Stepper::new(bad).is_err());
        }
        assert!(StepConfig::from_params(&[("Step", 2000)]).is_err());
        assert_eq!(
            StepConfig::from_params(&StepConfig::DEFAULT.to_params()).unwrap(),
            StepConfig::DEFAULT
        );
    }
}
