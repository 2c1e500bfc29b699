//! Queue bucketing (`gicube_bucket`), written from `docs/numerics/gicube_bucket.md`: the ray queue
//! and the owning processor of a ray start position, for the three block distributions of [348].

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::{param_in, StreamCodec};
use crate::units::gicube_packet_loop::{POS_FRAC_W, POS_W};

/// How blocks are distributed among processors ([348]); the `Dist` parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Distribution {
    /// `p` axis-aligned slabs along x, `B / p` blocks thick.
    Slab = 0,
    /// Slabs one block thick, slab `i` to processor `i mod p`.
    RepeatingSlab = 1,
    /// Block `(i, j, k)` to processor `(i + j + k) mod p`.
    Skewed = 2,
}

/// One `gicube_bucket` configuration (the RTL parameters of the same names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BucketConfig {
    pub block_log2: u32,
    pub vol_blocks: u32,
    pub proc_log2: u32,
    pub dist: Distribution,
    pub lanes: u32,
}

impl BucketConfig {
    /// The design point of [370]: 256^3 voxels, 32^3 blocks, four processors, slabs, two rays per
    /// clock.
    pub const SLAB: Self = Self {
        block_log2: 5,
        vol_blocks: 8,
        proc_log2: 2,
        dist: Distribution::Slab,
        lanes: 2,
    };
    pub const SKEW: Self = Self {
        dist: Distribution::Skewed,
        ..Self::SLAB
    };
    pub const REP: Self = Self {
        block_log2: 4,
        vol_blocks: 16,
        proc_log2: 3,
        dist: Distribution::RepeatingSlab,
        lanes: 1,
    };
    pub const SLAB12: Self = Self {
        block_log2: 3,
        vol_blocks: 12,
        proc_log2: 2,
        dist: Distribution::Slab,
        lanes: 1,
    };
    /// Narrow: 24^3 voxels in 4^3 blocks, two processors, skewed, three positions per item.
    pub const SKEW6: Self = Self {
        block_log2: 2,
        vol_blocks: 6,
        proc_log2: 1,
        dist: Distribution::Skewed,
        lanes: 3,
    };

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("bucket: {what}")));
        param_in("BlockLog2", self.block_log2, 1..=8).or_else(bad)?;
        param_in("VolBlocks", self.vol_blocks, 1..=64).or_else(bad)?;
        if self.vol_side() > 1 << (POS_W - POS_FRAC_W) {
            return bad(format!(
                "volume side {} exceeds the 4096 voxels a U(12.8) position reaches",
                self.vol_side()
            ));
        }
        param_in("ProcLog2", self.proc_log2, 0..=4).or_else(bad)?;
        if !self.vol_blocks.is_multiple_of(self.procs()) {
            return bad(format!(
                "VolBlocks {} is not a multiple of the {} processors",
                self.vol_blocks,
                self.procs()
            ));
        }
        param_in("Lanes", self.lanes, 1..=4).or_else(bad)?;
        Ok(())
    }

    /// Block side `n`.
    pub fn block_side(&self) -> u32 {
        1 << self.block_log2
    }

    /// Volume side `N = B * n`.
    pub fn vol_side(&self) -> u32 {
        self.vol_blocks << self.block_log2
    }

    /// Processors `p`.
    pub fn procs(&self) -> u32 {
        1 << self.proc_log2
    }

    /// Queues per processor `Q = B^3 / p`.
    pub fn queues(&self) -> u32 {
        self.vol_blocks.pow(3) / self.procs()
    }

    /// `QueueW = max(1, clog2(Q))`.
    pub fn queue_w(&self) -> u32 {
        clog2(self.queues()).max(1)
    }

    /// `ProcW = max(1, ProcLog2)`.
    pub fn proc_w(&self) -> u32 {
        self.proc_log2.max(1)
    }

    /// Bits of one output lane.
    pub fn lane_out_w(&self) -> u32 {
        self.queue_w() + self.proc_w() + 1
    }
}

fn clog2(x: u32) -> u32 {
    if x <= 1 {
        0
    } else {
        32 - (x - 1).leading_zeros()
    }
}

/// A position in the packet's start-point format, `U(12.8)` per axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Position(pub [u32; 3]);

/// The result for one position.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Bucket {
    pub queue: u32,
    pub proc: u32,
    pub outside: bool,
}

impl Bucket {
    const OUTSIDE: Self = Self {
        queue: 0,
        proc: 0,
        outside: true,
    };
}

/// One input item: `Lanes` positions.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BucketIn(pub Vec<Position>);

/// One output item: `Lanes` results.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BucketOut(pub Vec<Bucket>);

/// The golden model of `gicube_bucket`.
#[derive(Debug, Clone)]
pub struct BucketUnit {
    cfg: BucketConfig,
}

impl BucketUnit {
    pub fn new(cfg: BucketConfig) -> Result<Self> {
        cfg.validate()?;
        Ok(Self { cfg })
    }

    pub fn config(&self) -> BucketConfig {
        self.cfg
    }

    /// Queue selection for one position (steps 1-5 of the contract).
    pub fn bucket(&self, pos: Position) -> Bucket {
        let c = &self.cfg;
        let [ix, iy, iz] = pos.0.map(|x| x >> POS_FRAC_W);
        let n = c.vol_side();
        if ix >= n || iy >= n || iz >= n {
            return Bucket::OUTSIDE;
        }
        let [bx, by, bz] = [ix, iy, iz].map(|i| i >> c.block_log2);
        let (b, p) = (c.vol_blocks, c.procs());
        let (proc, xl) = match c.dist {
            Distribution::Slab => {
                let s = b / p;
                (bx / s, bx % s)
            }
            Distribution::RepeatingSlab => (bx % p, bx / p),
            Distribution::Skewed => ((bx + by + bz) % p, bx / p),
        };
        Bucket {
            queue: (xl * b + by) * b + bz,
            proc,
            outside: false,
        }
    }

    /// The f64 reference: the schemes of [348] read on real coordinates, real division and
    /// remainder, and the queue as the base-`B` number `(xl, by, bz)`.
    pub fn reference(&self, pos: [f64; 3]) -> Bucket {
        let c = &self.cfg;
        let n = f64::from(c.vol_side());
        if pos.iter().any(|&x| !(0.0..n).contains(&x)) {
            return Bucket::OUTSIDE;
        }
        let side = f64::from(c.block_side());
        let [bx, by, bz] = pos.map(|x| (x / side).floor());
        let (b, p) = (f64::from(c.vol_blocks), f64::from(c.procs()));
        let (proc, xl) = match c.dist {
            Distribution::Slab => {
                let thick = b / p;
                ((bx / thick).floor(), bx.rem_euclid(thick))
            }
            Distribution::RepeatingSlab => (bx.rem_euclid(p), (bx / p).floor()),
            Distribution::Skewed => ((bx + by + bz).rem_euclid(p), (bx / p).floor()),
        };
        Bucket {
            queue: (xl * b * b + by * b + bz) as u32,
            proc: proc as u32,
            outside: false,
        }
    }

    /// The block a (processor, queue) pair stands for: the inverse of the selection (contract,
    /// "bijection").
    pub fn block_of(&self, proc: u32, queue: u32) -> [u32; 3] {
        let c = &self.cfg;
        let (b, p) = (c.vol_blocks, c.procs());
        let (xl, by, bz) = (queue / (b * b), (queue / b) % b, queue % b);
        let bx = match c.dist {
            Distribution::Slab => proc * (b / p) + xl,
            Distribution::RepeatingSlab => xl * p + proc,
            Distribution::Skewed => xl * p + (proc + 2 * p * b - by - bz) % p,
        };
        [bx, by, bz]
    }
}

crate::item_by_item!(BucketUnit, BucketIn => BucketOut, |unit, item| {
    BucketOut(item.0.iter().map(|&p| unit.bucket(p)).collect())
});

impl StreamCodec for BucketConfig {
    type In = BucketIn;
    type Out = BucketOut;

    fn in_width(&self) -> u32 {
        3 * POS_W * self.lanes
    }

    fn out_width(&self) -> u32 {
        self.lane_out_w() * self.lanes
    }

    fn pack_in(&self, item: &BucketIn) -> Vec<u32> {
        assert_eq!(item.0.len(), self.lanes as usize, "one position per lane");
        let mut w = BitWriter::new();
        for p in &item.0 {
            for x in p.0 {
                w.put(u64::from(x), POS_W);
            }
        }
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> BucketOut {
        let mut r = BitReader::new(words);
        BucketOut(
            (0..self.lanes)
                .map(|_| Bucket {
                    queue: r.get(self.queue_w()) as u32,
                    proc: r.get(self.proc_w()) as u32,
                    outside: r.get_bool(),
                })
                .collect(),
        )
    }
}

/// A random position for tests and benches: mostly inside the volume, some on block and volume
/// edges, some anywhere in the 12-bit range.
pub fn random_position(rng: &mut impl rand::Rng, cfg: &BucketConfig) -> Position {
    let n = cfg.vol_side();
    let max = (1u32 << POS_W) - 1;
    let axis = |rng: &mut dyn rand::RngCore| -> u32 {
        let kind = rand::Rng::random_range(rng, 0..20);
        let frac = rand::Rng::random_range(rng, 0..1u32 << POS_FRAC_W);
        match kind {
            0 => rand::Rng::random_range(rng, 0..=max),
            1 => {
                let edge = [0, n - 1, n, n + 1, (1 << 12) - 1];
                (edge[rand::Rng::random_range(rng, 0..edge.len())].min(4095) << POS_FRAC_W) | frac
            }
            2 => {
                let k = rand::Rng::random_range(rng, 0..=cfg.vol_blocks);
                let i = (k << cfg.block_log2) as i64 + rand::Rng::random_range(rng, -1..=0);
                ((i.clamp(0, 4095) as u32) << POS_FRAC_W) | frac
            }
            _ => (rand::Rng::random_range(rng, 0..n) << POS_FRAC_W) | frac,
        }
    };
    Position([axis(rng), axis(rng), axis(rng)])
}

// The RTL parameters (`Dist` is the [`Distribution`] code); the RTL defaults are `SLAB`.
impl crate::unit::UnitConfig for BucketConfig {
    const TOP: &'static str = "gicube_bucket";

    fn from_params(params: &[(&str, i64)]) -> Result<Self> {
        let mut c = Self::SLAB;
        let mut dist = c.dist as u32;
        crate::unit::set_params(
            Self::TOP,
            params,
            &mut [
                ("BlockLog2", &mut c.block_log2),
                ("VolBlocks", &mut c.vol_blocks),
                ("ProcLog2", &mut c.proc_log2),
                ("Dist", &mut dist),
                ("Lanes", &mut c.lanes),
            ],
        )?;
        c.dist = match dist {
            0 => Distribution::Slab,
            1 => Distribution::RepeatingSlab,
            2 => Distribution::Skewed,
            d => {
                return Err(ModelError::Config(format!(
                    "gicube_bucket: Dist = {d} (0 slab, 1 repeating slab, 2 skewed)"
                )))
            }
        };
        c.validate()?;
        Ok(c)
    }

    fn to_params(&self) -> Vec<(&'static str, i64)> {
        vec![
            ("BlockLog2", i64::from(self.block_log2)),
            ("VolBlocks", i64::from(self.vol_blocks)),
            ("ProcLog2", i64::from(self.proc_log2)),
            ("Dist", self.dist as i64),
            ("Lanes", i64::from(self.lanes)),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    const ALL: [BucketConfig; 5] = [
        BucketConfig::SLAB,
        BucketConfig::SKEW,
        BucketConfig::REP,
        BucketConfig::SLAB12,
        BucketConfig::SKEW6,
    ];

    fn at_voxel(x: u32, y: u32, z: u32) -> Position {
        Position([x << POS_FRAC_W, y << POS_FRAC_W, z << POS_FRAC_W])
    }

    #[test]
    fn patent_formula_at_the_design_point() {
        // [370]: x' = (x >> 5) mod 2, y' = y >> 5, z' = z >> 5, q = (x' << 6) + (y' << 3) + z'.
        let unit = BucketUnit::new(BucketConfig::SLAB).unwrap();
        assert_eq!(BucketConfig::SLAB.queues(), 128, "[371]: 128 queues");
        for x in (0..256).step_by(3) {
            for y in (0..256).step_by(7) {
                for z in (0..256).step_by(5) {
                    let q = (((x >> 5) % 2) << 6) + ((y >> 5) << 3) + (z >> 5);
                    let b = unit.bucket(at_voxel(x, y, z));
                    assert_eq!((b.queue, b.proc, b.outside), (q, x >> 6, false));
                }
            }
        }
    }

    #[test]
    fn every_block_maps_to_a_distinct_queue_and_back() {
        for cfg in ALL {
            let unit = BucketUnit::new(cfg).unwrap();
            let b = cfg.vol_blocks;
            let mut seen = vec![false; (cfg.procs() * cfg.queues()) as usize];
            let mut per_proc = vec![0u32; cfg.procs() as usize];
            for bx in 0..b {
                for by in 0..b {
                    for bz in 0..b {
                        let n = cfg.block_side();
                        let r = unit.bucket(at_voxel(bx * n, by * n + n - 1, bz * n));
                        assert!(!r.outside && r.queue < cfg.queues() && r.proc < cfg.procs());
                        assert!(r.queue < 1 << cfg.queue_w());
                        let slot = (r.proc * cfg.queues() + r.queue) as usize;
                        assert!(!seen[slot], "{cfg:?}: block {bx},{by},{bz} shares a queue");
                        seen[slot] = true;
                        per_proc[r.proc as usize] += 1;
                        assert_eq!(unit.block_of(r.proc, r.queue), [bx, by, bz]);
                    }
                }
            }
            assert!(per_proc.iter().all(|&c| c == cfg.queues()), "equal shares");
        }
    }

    #[test]
    fn distributions_follow_their_definitions() {
        let skew = BucketUnit::new(BucketConfig::SKEW).unwrap();
        let rep = BucketUnit::new(BucketConfig::REP).unwrap();
        let slab12 = BucketUnit::new(BucketConfig::SLAB12).unwrap();
        for (i, j, k) in [(0, 0, 0), (1, 2, 3), (7, 7, 7), (5, 0, 6)] {
            let r = skew.bucket(at_voxel(i * 32 + 31, j * 32, k * 32 + 1));
            assert_eq!(r.proc, (i + j + k) % 4);
        }
        for i in 0..16 {
            assert_eq!(rep.bucket(at_voxel(i * 16, 0, 0)).proc, i % 8);
        }
        for i in 0..12 {
            assert_eq!(slab12.bucket(at_voxel(i * 8 + 7, 95, 0)).proc, i / 3);
        }
    }

    #[test]
    fn outside_positions_and_fractions() {
        for cfg in ALL {
            let unit = BucketUnit::new(cfg).unwrap();
            let n = cfg.vol_side();
            let last = (n << POS_FRAC_W) - 1; // N - 2^-8: inside
            assert!(!unit.bucket(Position([last, last, last])).outside);
            for a in 0..3 {
                let mut p = [0; 3];
                p[a] = n << POS_FRAC_W;
                assert_eq!(unit.bucket(Position(p)), Bucket::OUTSIDE);
                p[a] = (1 << POS_W) - 1;
                assert_eq!(unit.bucket(Position(p)), Bucket::OUTSIDE);
            }
        }
    }

    #[test]
    fn model_matches_the_f64_reference() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for cfg in ALL {
            let unit = BucketUnit::new(cfg).unwrap();
            for _ in 0..100_000 {
                let p = random_position(&mut rng, &cfg);
                let real = p.0.map(|x| f64::from(x) / 256.0);
                assert_eq!(unit.bucket(p), unit.reference(real), "{cfg:?} {p:?}");
            }
        }
    }

    #[test]
    fn config_validation() {
        let ok = BucketConfig::SLAB;
        assert!(ok.validate().is_ok());
        for bad in [
            BucketConfig {
                block_log2: 0,
                ..ok
            },
            BucketConfig {
                vol_blocks: 6,
                ..ok
            },
            BucketConfig { proc_log2: 5, ..ok },
            BucketConfig { lanes: 0, ..ok },
            BucketConfig { lanes: 5, ..ok },
            BucketConfig {
                block_log2: 8,
                vol_blocks: 32,
                ..ok
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
    }

    #[test]
    fn widths_match_the_contract_table() {
        let w = |c: BucketConfig| (c.in_width(), c.out_width(), c.queue_w(), c.queues());
        assert_eq!(w(BucketConfig::SLAB), (120, 20, 7, 128));
        assert_eq!(w(BucketConfig::SKEW), (120, 20, 7, 128));
        assert_eq!(w(BucketConfig::REP), (60, 13, 9, 512));
        assert_eq!(w(BucketConfig::SLAB12), (60, 12, 9, 432));
        assert_eq!(w(BucketConfig::SKEW6), (180, 27, 7, 108));
    }
}
