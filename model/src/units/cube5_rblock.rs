//! Recursive-blocking (bit-interleaved) addressing (`cube5_rblock`), written from
//! `docs/numerics/rblock.md`: the linear index `x + 2^X (y + 2^Y z)` and the blocked offset whose
//! bits interleave the coordinates level by level (patent [24], [447]-[450]).
//!
//! Both of the patent's forms are here: the bit form (`to_blocked`, `to_linear`) and the LUT form
//! (`BlockingLuts`: three separable position tables forward, grouped offset tables back). The RTL
//! uses the bit form; the tests prove the two agree.

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::StreamCodec;

/// The volume edges of one `cube5_rblock` configuration, as bit counts (the RTL parameters).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RBlockConfig {
    pub x_bits: u32,
    pub y_bits: u32,
    pub z_bits: u32,
}

impl RBlockConfig {
    /// `c2`: the patent's `4^3` example.
    pub const NARROW: Self = Self {
        x_bits: 2,
        y_bits: 2,
        z_bits: 2,
    };
    /// `c8`: a `256^3` volume.
    pub const DEFAULT: Self = Self {
        x_bits: 8,
        y_bits: 8,
        z_bits: 8,
    };
    /// `r759`: unequal edges.
    pub const UNEQUAL: Self = Self {
        x_bits: 7,
        y_bits: 5,
        z_bits: 9,
    };

    pub fn new(x_bits: u32, y_bits: u32, z_bits: u32) -> Result<Self> {
        let cfg = Self {
            x_bits,
            y_bits,
            z_bits,
        };
        cfg.validate()?;
        Ok(cfg)
    }

    pub fn validate(&self) -> Result<()> {
        for (name, b) in [
            ("XBits", self.x_bits),
            ("YBits", self.y_bits),
            ("ZBits", self.z_bits),
        ] {
            if !(1..=16).contains(&b) {
                return Err(ModelError::Config(format!(
                    "rblock: {name} {b} outside 1..=16"
                )));
            }
        }
        Ok(())
    }

    /// Bits of an index, `T = XBits + YBits + ZBits`.
    pub fn total_bits(&self) -> u32 {
        self.x_bits + self.y_bits + self.z_bits
    }

    pub fn bits(&self) -> [u32; 3] {
        [self.x_bits, self.y_bits, self.z_bits]
    }

    /// Number of voxels, `2^T`.
    pub fn len(&self) -> u64 {
        1u64 << self.total_bits()
    }

    pub fn is_empty(&self) -> bool {
        false
    }

    /// Offset bit of bit `level` of coordinate `axis` (0 = x, 1 = y, 2 = z): `pos(a, l)` of the
    /// contract, counted as the bits placed before it.
    pub fn pos(&self, axis: usize, level: u32) -> u32 {
        let bits = self.bits();
        let below: u32 = (0..level)
            .map(|l| bits.iter().filter(|&&b| b > l).count() as u32)
            .sum();
        below + bits[..axis].iter().filter(|&&b| b > level).count() as u32
    }

    /// The linear index of `(x, y, z)`.
    pub fn linear(&self, [x, y, z]: [u64; 3]) -> u64 {
        x + (y << self.x_bits) + (z << (self.x_bits + self.y_bits))
    }

    /// The coordinates of a linear index.
    pub fn coords(&self, lin: u64) -> [u64; 3] {
        let mask = |b: u32| (1u64 << b) - 1;
        [
            lin & mask(self.x_bits),
            (lin >> self.x_bits) & mask(self.y_bits),
            (lin >> (self.x_bits + self.y_bits)) & mask(self.z_bits),
        ]
    }

    /// Bit form, forward: the blocked offset of coordinates `(x, y, z)`.
    pub fn blocked_of(&self, c: [u64; 3]) -> u64 {
        let mut o = 0u64;
        for (axis, &b) in self.bits().iter().enumerate() {
            for l in 0..b {
                o |= ((c[axis] >> l) & 1) << self.pos(axis, l);
            }
        }
        o
    }

    /// Bit form, reverse: the coordinates of blocked offset `o`.
    pub fn coords_of_blocked(&self, o: u64) -> [u64; 3] {
        let mut c = [0u64; 3];
        for (axis, &b) in self.bits().iter().enumerate() {
            for l in 0..b {
                c[axis] |= ((o >> self.pos(axis, l)) & 1) << l;
            }
        }
        c
    }

    /// Bit form: linear index to blocked offset.
    pub fn to_blocked(&self, lin: u64) -> u64 {
        self.blocked_of(self.coords(lin))
    }

    /// Bit form: blocked offset to linear index.
    pub fn to_linear(&self, o: u64) -> u64 {
        self.linear(self.coords_of_blocked(o))
    }
}

/// The LUT form of the patent ([449]-[450]): separable position tables forward, and tables over
/// groups of `group_bits` offset bits back.
#[derive(Debug, Clone)]
pub struct BlockingLuts {
    cfg: RBlockConfig,
    group_bits: u32,
    /// `fwd[a][c]`: the offset of coordinate value `c` on axis `a` alone.
    fwd: [Vec<u64>; 3],
    /// `rev[j][v]`: the coordinates of offset `v << (group_bits * j)`.
    rev: Vec<Vec<[u64; 3]>>,
}

impl BlockingLuts {
    /// Builds the tables. `group_bits` (the patent uses 3, one octree level) in 1..=12.
    pub fn new(cfg: RBlockConfig, group_bits: u32) -> Result<Self> {
        cfg.validate()?;
        if !(1..=12).contains(&group_bits) {
            return Err(ModelError::Config(format!(
                "rblock: LUT group of {group_bits} bits outside 1..=12"
            )));
        }
        let fwd = std::array::from_fn(|a| {
            (0..1u64 << cfg.bits()[a])
                .map(|v| {
                    let mut c = [0u64; 3];
                    c[a] = v;
                    cfg.blocked_of(c)
                })
                .collect()
        });
        let groups = cfg.total_bits().div_ceil(group_bits);
        let rev = (0..groups)
            .map(|j| {
                let shift = group_bits * j;
                let width = group_bits.min(cfg.total_bits() - shift);
                (0..1u64 << width)
                    .map(|v| cfg.coords_of_blocked(v << shift))
                    .collect()
            })
            .collect();
        Ok(Self {
            cfg,
            group_bits,
            fwd,
            rev,
        })
    }

    /// Entries in all tables (the storage the LUT form costs).
    pub fn entries(&self) -> usize {
        self.fwd.iter().map(Vec::len).sum::<usize>() + self.rev.iter().map(Vec::len).sum::<usize>()
    }

    /// LUT form: linear index to blocked offset, `LX[x] + LY[y] + LZ[z]`.
    pub fn to_blocked(&self, lin: u64) -> u64 {
        let c = self.cfg.coords(lin);
        self.fwd[0][c[0] as usize] + self.fwd[1][c[1] as usize] + self.fwd[2][c[2] as usize]
    }

    /// LUT form: blocked offset to linear index, the sum of the group tables' positions.
    pub fn to_linear(&self, o: u64) -> u64 {
        let mut p = [0u64; 3];
        for (j, table) in self.rev.iter().enumerate() {
            let v = (o >> (self.group_bits * j as u32)) & (table.len() as u64 - 1);
            let e = table[v as usize];
            for a in 0..3 {
                p[a] += e[a];
            }
        }
        self.cfg.linear(p)
    }
}

/// Conversion direction (the `dir` bit).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RBlockDir {
    /// Linear index to blocked offset.
    ToBlocked = 0,
    /// Blocked offset to linear index.
    ToLinear = 1,
}

/// One input item of `cube5_rblock`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RBlockIn {
    pub value: u64,
    pub dir: RBlockDir,
}

/// The golden model of `cube5_rblock` (bit form, with `pos` tabulated once for speed).
#[derive(Debug, Clone)]
pub struct RBlock {
    cfg: RBlockConfig,
    /// `(linear bit, blocked bit)` for every coordinate bit.
    moves: Vec<(u32, u32)>,
}

impl RBlock {
    pub fn new(cfg: RBlockConfig) -> Result<Self> {
        cfg.validate()?;
        let mut moves = Vec::new();
        let mut base = 0;
        for (axis, &b) in cfg.bits().iter().enumerate() {
            for l in 0..b {
                moves.push((base + l, cfg.pos(axis, l)));
            }
            base += b;
        }
        Ok(Self { cfg, moves })
    }

    pub fn config(&self) -> RBlockConfig {
        self.cfg
    }

    pub fn convert(&self, item: &RBlockIn) -> u64 {
        let mut out = 0u64;
        for &(lin_bit, blk_bit) in &self.moves {
            let (from, to) = match item.dir {
                RBlockDir::ToBlocked => (lin_bit, blk_bit),
                RBlockDir::ToLinear => (blk_bit, lin_bit),
            };
            out |= ((item.value >> from) & 1) << to;
        }
        out
    }
}

crate::item_by_item!(RBlock, RBlockIn => u64, |unit, i| unit.convert(i));

impl StreamCodec for RBlockConfig {
    type In = RBlockIn;
    type Out = u64;

    fn in_width(&self) -> u32 {
        self.total_bits() + 1
    }

    fn out_width(&self) -> u32 {
        self.total_bits()
    }

    fn pack_in(&self, item: &RBlockIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        w.put(item.value, self.total_bits());
        w.put(item.dir as u64, 1);
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> u64 {
        BitReader::new(words).get(self.total_bits())
    }
}

// The RTL parameters of this unit (the RTL defaults are the model's `DEFAULT`).
crate::unit_config!(RBlockConfig, "cube5_rblock", DEFAULT, {
    "XBits" => x_bits,
    "YBits" => y_bits,
    "ZBits" => z_bits,
});

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn patent_example() {
        let cfg = RBlockConfig::NARROW;
        let lin = cfg.linear([3, 1, 1]);
        assert_eq!(lin, 23);
        assert_eq!(cfg.to_blocked(lin), 15);
        assert_eq!(cfg.to_linear(15), 23);
        let luts = BlockingLuts::new(cfg, 3).unwrap();
        assert_eq!((luts.fwd[0][3], luts.fwd[1][1], luts.fwd[2][1]), (9, 2, 4));
        assert_eq!(luts.rev[1][1], [2, 0, 0]);
        assert_eq!(luts.rev[0][7], [1, 1, 1]);
        assert_eq!(luts.to_blocked(23), 15);
        assert_eq!(luts.to_linear(15), 23);
    }

    #[test]
    fn cube_interleaves_x_y_z() {
        let cfg = RBlockConfig::DEFAULT;
        for l in 0..8 {
            assert_eq!(cfg.pos(0, l), 3 * l);
            assert_eq!(cfg.pos(1, l), 3 * l + 1);
            assert_eq!(cfg.pos(2, l), 3 * l + 2);
        }
        // The 2^3 block at the origin is offsets 0..8; the 4^3 block 0..64 (recursive octants).
        let mut seen = [false; 64];
        for z in 0..4 {
            for y in 0..4 {
                for x in 0..4 {
                    let o = cfg.blocked_of([x, y, z]) as usize;
                    assert!(o < 64);
                    assert!(!seen[o]);
                    seen[o] = true;
                    if x < 2 && y < 2 && z < 2 {
                        assert!(o < 8);
                    }
                }
            }
        }
    }

    #[test]
    fn unequal_edges_follow_the_contract_example() {
        let cfg = RBlockConfig::new(3, 2, 1).unwrap();
        // O = (x2, y1, x1, z0, y0, x0).
        let expect = [
            (0, 0, 0),
            (1, 0, 1),
            (2, 0, 2),
            (0, 1, 3),
            (1, 1, 4),
            (0, 2, 5),
        ];
        for (axis, level, bit) in expect {
            assert_eq!(cfg.pos(axis, level), bit);
        }
    }

    #[test]
    fn bijection_and_lut_form_agree_on_every_index_of_small_volumes() {
        for cfg in [
            RBlockConfig::NARROW,
            RBlockConfig::new(3, 2, 1).unwrap(),
            RBlockConfig::new(1, 4, 2).unwrap(),
            RBlockConfig::new(4, 4, 4).unwrap(),
            RBlockConfig::new(2, 5, 5).unwrap(),
        ] {
            for g in [1, 2, 3, 5, 6] {
                let luts = BlockingLuts::new(cfg, g).unwrap();
                let mut seen = vec![false; cfg.len() as usize];
                for lin in 0..cfg.len() {
                    let o = cfg.to_blocked(lin);
                    assert!(!seen[o as usize], "{cfg:?}: offset {o} twice");
                    seen[o as usize] = true;
                    assert_eq!(cfg.to_linear(o), lin);
                    assert_eq!(luts.to_blocked(lin), o, "{cfg:?} G={g} lin {lin}");
                    assert_eq!(luts.to_linear(o), lin, "{cfg:?} G={g} offset {o}");
                }
            }
        }
    }

    #[test]
    fn lut_form_agrees_on_random_indices_of_large_volumes() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for cfg in [
            RBlockConfig::DEFAULT,
            RBlockConfig::UNEQUAL,
            RBlockConfig::new(16, 16, 16).unwrap(),
            RBlockConfig::new(16, 1, 9).unwrap(),
        ] {
            let luts = BlockingLuts::new(cfg, 3).unwrap();
            for _ in 0..100_000 {
                let lin = rng.random_range(0..cfg.len());
                let o = cfg.to_blocked(lin);
                assert_eq!(luts.to_blocked(lin), o);
                assert_eq!(luts.to_linear(o), lin);
                assert_eq!(cfg.to_linear(o), lin);
            }
            assert_eq!(cfg.to_blocked(cfg.len() - 1), cfg.len() - 1);
            assert_eq!(cfg.to_blocked(0), 0);
        }
    }

    #[test]
    fn unit_agrees_with_both_forms() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        for cfg in [
            RBlockConfig::NARROW,
            RBlockConfig::DEFAULT,
            RBlockConfig::UNEQUAL,
        ] {
            let unit = RBlock::new(cfg).unwrap();
            let luts = BlockingLuts::new(cfg, 3).unwrap();
            for _ in 0..20_000 {
                let v = rng.random_range(0..cfg.len());
                let fwd = RBlockIn {
                    value: v,
                    dir: RBlockDir::ToBlocked,
                };
                let rev = RBlockIn {
                    value: v,
                    dir: RBlockDir::ToLinear,
                };
                assert_eq!(unit.convert(&fwd), cfg.to_blocked(v));
                assert_eq!(unit.convert(&fwd), luts.to_blocked(v));
                assert_eq!(unit.convert(&rev), cfg.to_linear(v));
                assert_eq!(unit.convert(&rev), luts.to_linear(v));
            }
        }
    }

    #[test]
    fn config_validation() {
        assert!(RBlockConfig::new(0, 2, 2).is_err());
        assert!(RBlockConfig::new(2, 17, 2).is_err());
        assert!(RBlockConfig::new(16, 16, 16).is_ok());
        assert!(BlockingLuts::new(RBlockConfig::NARROW, 0).is_err());
        assert!(BlockingLuts::new(RBlockConfig::NARROW, 13).is_err());
    }

    #[test]
    fn packing_width_matches_contract_table() {
        assert_eq!(RBlockConfig::NARROW.in_width(), 7);
        assert_eq!(RBlockConfig::DEFAULT.in_width(), 25);
        assert_eq!(RBlockConfig::UNEQUAL.in_width(), 22);
        assert_eq!(RBlockConfig::UNEQUAL.out_width(), 21);
    }
}
