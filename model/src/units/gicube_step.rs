//! The GI-Cube block processor's step, leap and advance (patent [355], [357]), written from
//! `docs/numerics/gicube_step.md`: the per-ray step `delta = rnd(dir * dr, 14)`, the leap over an
//! empty block to the first grid position outside it, the advance `next = start + k delta`, the
//! exit test against the volume's domain and the re-bucketing of the new position
//! (`gicube_bucket`). A pure function of the item: parts E and O of docs/gicube-rtl.md.
//!
//! `gicube_processor::Processor` advances every ray through [`Stepper::step`], so this is the one
//! description of the step. No RTL yet: the next unit on the build order (docs/gicube-rtl.md).

use crate::error::Result;
use crate::units::gicube_bucket::{BucketConfig, BucketUnit, Distribution, Position};
use crate::units::gicube_packet_loop::{DIR_FRAC_W, POS_FRAC_W};

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
        let bucket = BucketUnit::new(BucketConfig {
            block_log2: cfg.block_log2,
            vol_blocks: cfg.vol_blocks,
            proc_log2: 0,
            dist: Distribution::Slab,
            lanes: 1,
        })?;
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

    /// One ray of queue `queue` at `start` with direction `dir`: `k = steps_to_exit` when `leap`
    /// (its block is empty and it may leap), else 1; `next = start + k delta`; outside
    /// `[0, N 256)` on any axis: `exit`; else the queue of `next`.
    pub fn step(&self, start: [u32; 3], dir: [i16; 3], queue: u32, leap: bool) -> StepOut {
        let delta = self.delta(dir);
        let k = if leap {
            self.steps_to_exit(start, delta, self.bucket.block_of(0, queue))
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
        let half = Stepper::new(StepConfig { step: 1, ..CFG }).unwrap();
        assert_eq!(half.delta([8192, -8192, 8191]), [1, 0, 0]);
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
}
