//! The splatting unit's energies (`gicube_deposit`, part M of docs/gicube-rtl.md, [362], [381]),
//! written from docs/numerics/gicube_processor.md (*Global illumination*, *Splatting through the
//! cache*): the volume cache's item of a sampling ray's cell, with, for a lighting ray's deposit,
//! the energy of each of the cell's eight corners
//! `e[c] = min(rnd(E T dr w_c, 42), 2^16 - 1)`, 0 for a corner outside the volume; a read or a
//! flush passes with its cell and operation and no energy.

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::StreamCodec;
use crate::units::cube5_compos::rnd;
use crate::units::gicube_cache::{CacheItem, CacheReq};
use crate::units::gicube_packet_loop::POS_FRAC_W;
use crate::units::gicube_sample::{CHAN_MAX, IRR_FRAC_W};

/// `E (12) + T (12) + dr (8) + w_c (24) - IRR_FRAC_W`: the splat's rounding shift.
pub const DEPOSIT_SHIFT: u32 = 12 + 12 + POS_FRAC_W + 3 * POS_FRAC_W - IRR_FRAC_W;
/// Bits of an energy (the cache's irradiance field at `WordW = 32`).
pub const ENERGY_W: u32 = 16;
/// Bits of each of the volume's dimensions in an item.
pub const DIM_W: u32 = 7;
/// Bits of the packet's channels (`E`, the opacity).
const CHAN_W: u32 = 12;
/// The stages of the RTL pipeline.
pub const LATENCY: u64 = 5;

/// Operations of an item (the cache's `op`): 0 read, 1 deposit, 2 flush.
pub const OP_READ: u32 = 0;
pub const OP_DEPOSIT: u32 = 1;
pub const OP_FLUSH: u32 = 2;

/// One configuration of the RTL top `gicube_deposit`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DepositConfig {
    /// Bits of a cell coordinate (`log2 MaxDim` of the cache), 2..=7.
    pub mw: u32,
    /// Sample distance `dr`, `U(4.8)` voxels, 16..=1024.
    pub step: u32,
}

impl DepositConfig {
    /// The RTL's parameter defaults.
    pub const DEFAULT: Self = Self { mw: 5, step: 256 };

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(ModelError::Config(format!("gicube_deposit: {m}")));
        if !(2..=7).contains(&self.mw) {
            return bad(format!("MW {} outside 2..=7", self.mw));
        }
        if !(16..=1024).contains(&self.step) {
            return bad(format!("Step {} outside 16..=1024", self.step));
        }
        Ok(())
    }

    /// The cache item of `it` (contract, *Splatting through the cache*).
    pub fn deposit(&self, it: &DepositIn) -> DepositOut {
        let inside: [bool; 8] = std::array::from_fn(|c| {
            (0..3).all(|a| it.cell[a] + ((c as u32 >> a) & 1) < it.dims[a])
        });
        let e = if it.op == OP_DEPOSIT {
            let t = CHAN_MAX + 1 - u32::from(it.opacity);
            energies(u32::from(it.energy), t, self.step, it.frac, inside)
        } else {
            [0; 8]
        };
        DepositOut {
            cell: it.cell,
            op: it.op,
            e,
        }
    }
}

crate::unit_config!(DepositConfig, "gicube_deposit", DEFAULT, {
    "MW" => mw,
    "Step" => step,
});

/// The energies of the eight corners of a cell, corner `c = cx + 2 cy + 4 cz`:
/// `min(rnd(E T dr w_c, 42), 2^16 - 1)` where `inside[c]`, else 0; `w_c` the product of the
/// corner's three weights, `256 - f` (bit 0) or `f` (bit 1), `U(1.8)` each.
pub fn energies(e: u32, t: u32, step: u32, f: [u32; 3], inside: [bool; 8]) -> [u32; 8] {
    let ets = u64::from(e) * u64::from(t) * u64::from(step);
    std::array::from_fn(|c| {
        if !inside[c] {
            return 0;
        }
        let w = (0..3).fold(1u64, |acc, a| {
            let fa = u64::from(f[a]);
            acc * if (c >> a) & 1 == 1 { fa } else { 256 - fa }
        });
        rnd(ets * w, DEPOSIT_SHIFT).min((1 << ENERGY_W) - 1) as u32
    })
}

/// One item into the unit: the sample's cell and what its deposit needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DepositIn {
    /// The cell's lowest voxel (`MW` bits each).
    pub cell: [u32; 3],
    /// The ray's energy `E` (its `red`, `U(0.12)`).
    pub energy: u16,
    /// The ray's opacity before this sample (`U(0.12)`): `T = 4096 - opacity`.
    pub opacity: u16,
    /// The start's fraction bits per axis (the weights, `U(0.8)`).
    pub frac: [u32; 3],
    /// `OP_READ`, `OP_DEPOSIT` or `OP_FLUSH`.
    pub op: u32,
    /// The volume's dimensions (7 bits each): a corner at or above one gets nothing.
    pub dims: [u32; 3],
}

/// The cache's item: the cell, the operation, the eight energies (0 unless a deposit).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DepositOut {
    pub cell: [u32; 3],
    pub op: u32,
    pub e: [u32; 8],
}

impl DepositOut {
    /// The `gicube_cache` item it is.
    pub fn item(&self) -> CacheItem {
        let [x, y, z] = self.cell;
        let r = CacheReq { x, y, z };
        match self.op {
            OP_READ => CacheItem::Read(r),
            OP_DEPOSIT => CacheItem::Deposit(r, self.e),
            _ => CacheItem::Flush,
        }
    }
}

crate::item_by_item!(DepositConfig, DepositIn => DepositOut, |unit, it| unit.deposit(it));

impl StreamCodec for DepositConfig {
    type In = DepositIn;
    type Out = DepositOut;

    fn in_width(&self) -> u32 {
        3 * self.mw + 2 * CHAN_W + 3 * POS_FRAC_W + 2 + 3 * DIM_W
    }

    fn out_width(&self) -> u32 {
        3 * self.mw + 2 + 8 * ENERGY_W
    }

    fn pack_in(&self, it: &DepositIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        for c in it.cell {
            w.put(u64::from(c), self.mw);
        }
        w.put(u64::from(it.energy), CHAN_W);
        w.put(u64::from(it.opacity), CHAN_W);
        for f in it.frac {
            w.put(u64::from(f), POS_FRAC_W);
        }
        w.put(u64::from(it.op), 2);
        for d in it.dims {
            w.put(u64::from(d), DIM_W);
        }
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> DepositOut {
        let mut r = BitReader::new(words);
        let cell = std::array::from_fn(|_| r.get(self.mw) as u32);
        let op = r.get(2) as u32;
        let e = std::array::from_fn(|_| r.get(ENERGY_W) as u32);
        DepositOut { cell, op, e }
    }
}

/// A random item for tests: a cell anywhere in the cache's `2^MW` (a quarter at the volume's
/// far faces), dimensions up to `min(64, 2^MW)` (sometimes 0 or the largest), energies and
/// opacities over their whole range with the extremes often, fractions with 0 and 255 often;
/// mostly deposits, some reads and flushes.
pub fn random_deposit_in(rng: &mut impl rand::Rng, cfg: &DepositConfig) -> DepositIn {
    let side = 1u32 << cfg.mw;
    let dmax = side.min((1 << DIM_W) - 1);
    let dims: [u32; 3] = std::array::from_fn(|_| match rng.random_range(0..10) {
        0 => 0,
        1 => dmax,
        _ => rng.random_range(1..=dmax),
    });
    let cell = std::array::from_fn(|a| match rng.random_range(0..4) {
        0 => dims[a]
            .saturating_sub(rng.random_range(1..=2))
            .min(side - 1),
        _ => rng.random_range(0..side),
    });
    let chan = |rng: &mut dyn rand::RngCore| -> u16 {
        match rand::Rng::random_range(rng, 0..8) {
            0 => 0,
            1 => CHAN_MAX as u16,
            _ => rand::Rng::random_range(rng, 0..=CHAN_MAX) as u16,
        }
    };
    let frac = std::array::from_fn(|_| match rng.random_range(0..8) {
        0 => 0,
        1 => 255,
        _ => rng.random_range(0..256),
    });
    let op = match rng.random_range(0..16) {
        0 => OP_READ,
        1 => OP_FLUSH,
        _ => OP_DEPOSIT,
    };
    DepositIn {
        cell,
        energy: chan(rng),
        opacity: chan(rng),
        frac,
        op,
        dims,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_largest_energy_split_weights_and_corners_outside() {
        let cfg = DepositConfig { mw: 5, step: 1024 };
        let all = [true; 8];
        // E = 4095, T = 4096, dr = 4 voxels, all weight on corner 0: the largest energy (below
        // the clamp).
        let e = energies(4095, 4096, 1024, [0; 3], all);
        assert_eq!(e[0], 65_520);
        assert!(e[1..].iter().all(|&v| v == 0));
        // Every weight split: the sum is the whole within the rounding.
        let e = energies(2048, 4096, 256, [128; 3], all);
        let sum: u32 = e.iter().sum();
        assert_eq!(sum, 8 * e[0]);
        assert_eq!(sum, 2048 * 4);
        let it = DepositIn {
            cell: [31, 0, 0],
            energy: 4095,
            opacity: 0,
            frac: [255; 3],
            op: OP_DEPOSIT,
            dims: [32, 32, 32],
        };
        let o = cfg.deposit(&it);
        // The corners at x = 32 are outside; (0, 1, 1) weighs 1 x 255 x 255.
        assert!(o.e.iter().enumerate().all(|(c, &v)| c & 1 == 0 || v == 0));
        assert_eq!(o.e[6], 254);
        assert_eq!(cfg.deposit(&DepositIn { op: OP_READ, ..it }).e, [0; 8]);
    }
}
