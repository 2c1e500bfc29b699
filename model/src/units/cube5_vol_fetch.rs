//! Volume fetch unit (`cube5_vol_fetch`), written from `docs/numerics/vol_fetch.md`: the volume's
//! blocked layout in external memory (voxel -> byte address), and what the unit delivers for a
//! list of commands (LUT writes and sweeps): the walk of a sweep's blocks (slabs front to back,
//! block rows, the section's block columns), one skip item per empty or masked block, `B^3 / P`
//! items of P voxels per present block, and the read commands it gives its `cube5_axi_rd` (whose
//! splitting rule then fixes every AR burst).
//!
//! Like `cube5_axi_rd` the unit is not one output per input, so it is modelled as a function of
//! the command list and the memory image; `StreamCodec` packs commands and unpacks items as the RTL
//! ports carry them.

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::{param_in, StreamCodec};
use crate::units::cube5_axi_rd::{AxiMemImage, AxiRdCmd, AxiRdConfig, RESP_OKAY};
use crate::units::cube5_frame::{FrameParams, FrameSetup};
use crate::units::cube5_skewmem::{BlockEntry, BlockLut};
use crate::volume::Volume;
use glam::DVec3;

/// The RTL parameters of one `cube5_vol_fetch` configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VolFetchConfig {
    /// Byte address width (13..=64).
    pub addr_w: u32,
    /// Bus width in bits.
    pub data_w: u32,
    /// Voxels per output item.
    pub p: u32,
    /// Bits of a delivered voxel (the low bits of the stored 16-bit word).
    pub voxel_w: u32,
    /// Largest volume edge (a power of two).
    pub max_dim: u32,
    /// Block edge `B`.
    pub block_dim: u32,
    /// The inner reader's longest burst.
    pub max_burst: u32,
    /// The inner reader's bursts in flight.
    pub outstanding: u32,
    /// ARID / RID width.
    pub id_w: u32,
}

impl VolFetchConfig {
    /// The RTL's parameter defaults.
    pub const DEFAULT: Self = Self {
        addr_w: 32,
        data_w: 64,
        p: 4,
        voxel_w: 12,
        max_dim: 64,
        block_dim: 8,
        max_burst: 16,
        outstanding: 8,
        id_w: 4,
    };

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("cube5_vol_fetch: {what}")));
        if ![1, 2, 4, 8].contains(&self.p) {
            return bad(format!("P {} is not 1, 2, 4 or 8", self.p));
        }
        param_in("VoxelW", self.voxel_w, 4..=16).or_else(bad)?;
        if !self.max_dim.is_power_of_two() || !(8..=1024).contains(&self.max_dim) {
            return bad(format!(
                "MaxDim {} is not a power of two in 8..=1024",
                self.max_dim
            ));
        }
        let b = self.block_dim;
        if !b.is_power_of_two() || b < (self.p / 2).max(2) || b > 16 || b >= self.max_dim {
            return bad(format!(
                "BlockDim {b} is not a power of two with max(2, P / 2) <= B <= 16 and B < MaxDim"
            ));
        }
        if !self.data_w.is_power_of_two()
            || self.data_w < 16 * self.p
            || self.data_w > 16 * b * b * b
        {
            return bad(format!(
                "DataW {} is not a power of two in 16 P ..= 16 B^3",
                self.data_w
            ));
        }
        self.axi_rd().validate()
    }

    /// The inner `cube5_axi_rd`.
    pub fn axi_rd(&self) -> AxiRdConfig {
        AxiRdConfig {
            addr_w: self.addr_w,
            data_w: self.data_w,
            len_w: self.beats_per_block().trailing_zeros() + 1,
            max_burst: self.max_burst,
            outstanding: self.outstanding,
            id_w: self.id_w,
        }
    }

    /// Blocks per axis, `NB = MaxDim / B`.
    pub fn nb(&self) -> u32 {
        self.max_dim / self.block_dim
    }

    /// One sweep for each rule of [`VolFetch::refusal`], each otherwise `ok` (a sweep the unit
    /// takes): a reserved axis, a volume edge of 0 blocks and one of NB + 1, an empty section, a
    /// section past the volume, a base off the bus. The model's tests and the co-simulation's
    /// use the same list.
    pub fn refused_sweeps(&self, ok: Sweep) -> [Sweep; 6] {
        let (ai, _) = frame_axes(ok.axis_k);
        let [_, by, bz] = ok.blocks;
        [
            Sweep { axis_k: 3, ..ok },
            Sweep {
                blocks: [0, by, bz],
                ..ok
            },
            Sweep {
                blocks: [self.nb() + 1, by, bz],
                ..ok
            },
            Sweep {
                sec_lo: 1,
                sec_hi: 1,
                ..ok
            },
            Sweep {
                sec_hi: ok.blocks[ai] + 1,
                ..ok
            },
            Sweep {
                base: ok.base + u64::from(self.data_w / 16),
                ..ok
            },
        ]
    }

    /// `NbW = log2 NB`.
    pub fn nb_w(&self) -> u32 {
        self.nb().trailing_zeros()
    }

    /// `BlkW = 3 NbW`: a LUT index or block pointer.
    pub fn blk_w(&self) -> u32 {
        3 * self.nb_w()
    }

    /// Bytes per block, `2 B^3`.
    pub fn block_bytes(&self) -> u64 {
        2 * u64::from(self.block_dim).pow(3)
    }

    /// Bus beats per block.
    pub fn beats_per_block(&self) -> u32 {
        (self.block_bytes() / u64::from(self.data_w / 8)) as u32
    }

    /// Output items per present block, `B^3 / P`.
    pub fn groups(&self) -> u32 {
        self.block_dim.pow(3) / self.p
    }

    /// Bits of the `word` field.
    pub fn word_w(&self) -> u32 {
        self.groups().trailing_zeros().max(1)
    }

    /// Tag FIFO depth: blocks the walker may run ahead of the data.
    pub fn tag_depth(&self) -> u32 {
        (self.outstanding * self.max_burst / self.beats_per_block() + 4).next_power_of_two()
    }

    /// The byte address of voxel `c` (volume coordinates) for a volume at `base` with LUT `lut`
    /// (its pointer of the voxel's block), wrapped to the address space.
    pub fn voxel_addr(&self, base: u64, ptr: u32, c: [u32; 3]) -> u64 {
        let b = self.block_dim;
        let l = c.map(|v| u64::from(v % b));
        let b = u64::from(b);
        let a = base + u64::from(ptr) * self.block_bytes() + 2 * (l[0] + b * (l[1] + b * l[2]));
        self.wrap(a)
    }

    fn wrap(&self, a: u64) -> u64 {
        self.axi_rd().address_space().map_or(a, |s| a & (s - 1))
    }

    /// LUT index of block `(bx, by, bz)`: `bx + NB (by + NB bz)`.
    pub fn lut_index(&self, blk: [u32; 3]) -> u32 {
        let nb = self.nb();
        blk[0] + nb * (blk[1] + nb * blk[2])
    }

    fn cmd_w(&self) -> u32 {
        let lut = 2 * self.blk_w() + 2;
        let sweep = self.addr_w + 3 * (self.nb_w() + 1) + 3 + self.nb_w() + self.nb_w() + 1;
        1 + lut.max(sweep)
    }

    /// The LUT writes that load `lut` (the model's `BlockLut`, over the volume's blocks).
    pub fn lut_writes(&self, lut: &BlockLut) -> Result<Vec<FetchCmd>> {
        if lut.block != self.block_dim {
            return Err(ModelError::Config(format!(
                "cube5_vol_fetch: the LUT's blocks are {} voxels, the unit's {}",
                lut.block, self.block_dim
            )));
        }
        if lut.blocks.iter().any(|&n| n > self.nb()) {
            return Err(ModelError::Config(format!(
                "cube5_vol_fetch: {:?} blocks per axis exceed NB = {}",
                lut.blocks,
                self.nb()
            )));
        }
        let [lx, ly, lz] = lut.blocks;
        let mut out = Vec::with_capacity(lut.entries.len());
        for bz in 0..lz {
            for by in 0..ly {
                for bx in 0..lx {
                    let e = lut.entries[(bx + lx * (by + ly * bz)) as usize];
                    if u64::from(e.ptr) >> self.blk_w() != 0 {
                        return Err(ModelError::Config(format!(
                            "cube5_vol_fetch: block pointer {} does not fit {} bits",
                            e.ptr,
                            self.blk_w()
                        )));
                    }
                    out.push(FetchCmd::Lut {
                        index: self.lut_index([bx, by, bz]),
                        entry: e,
                    });
                }
            }
        }
        Ok(out)
    }
}

/// The memory image of `vol` in the blocked layout: slot `ptr` of every block of `lut` holds that
/// block's voxels as 16-bit little-endian words, x fastest (0 beyond the volume); the image spans
/// slots `0 ..= max ptr` from `base`.
pub fn dram_image(vol: &Volume, lut: &BlockLut, base: u64) -> Result<AxiMemImage> {
    let b = lut.block as usize;
    let blocks = lut.blocks.map(|n| n as usize);
    if vol
        .dims
        .iter()
        .zip(blocks)
        .any(|(&n, nb)| n.div_ceil(b) != nb)
    {
        return Err(ModelError::Config(format!(
            "dram_image: the LUT's {blocks:?} blocks do not cover the volume {:?}",
            vol.dims
        )));
    }
    let slots = lut
        .entries
        .iter()
        .map(|e| e.ptr as usize + 1)
        .max()
        .unwrap_or(0);
    let block_bytes = 2 * b * b * b;
    let mut bytes = vec![0u8; slots * block_bytes];
    for bz in 0..blocks[2] {
        for by in 0..blocks[1] {
            for bx in 0..blocks[0] {
                let e = lut.entries[bx + blocks[0] * (by + blocks[1] * bz)];
                let at = e.ptr as usize * block_bytes;
                for lz in 0..b {
                    for ly in 0..b {
                        for lx in 0..b {
                            let (x, y, z) = (bx * b + lx, by * b + ly, bz * b + lz);
                            let v = vol.get(x as i64, y as i64, z as i64) as u16;
                            let o = at + 2 * (lx + b * (ly + b * lz));
                            bytes[o..o + 2].copy_from_slice(&v.to_le_bytes());
                        }
                    }
                }
            }
        }
    }
    Ok(AxiMemImage {
        base,
        bytes,
        ..Default::default()
    })
}

/// One sweep: the volume at `base`, its size in blocks, the slice axis and direction, and the
/// section's block columns `[sec_lo, sec_hi)` along the beam axis `i`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sweep {
    pub base: u64,
    pub blocks: [u32; 3],
    pub axis_k: u32,
    pub reversed: bool,
    pub sec_lo: u32,
    pub sec_hi: u32,
}

impl Sweep {
    /// The sweep over every block of a volume of `blocks` at `base`: along z, front to back.
    pub fn whole(base: u64, blocks: [u32; 3]) -> Self {
        Self {
            base,
            blocks,
            axis_k: 2,
            reversed: false,
            sec_lo: 0,
            sec_hi: blocks[0],
        }
    }

    /// The whole-face sweep of a frame (`FrameParams`: slice axis and direction) over a volume
    /// of `dims` voxels in blocks of `block`.
    pub fn of_frame(params: &FrameParams, dims: [usize; 3], block: u32, base: u64) -> Self {
        let blocks = dims.map(|n| n.div_ceil(block as usize) as u32);
        Self {
            base,
            blocks,
            axis_k: params.axis_k as u32,
            reversed: params.k_reversed,
            sec_lo: 0,
            sec_hi: blocks[params.axis_i],
        }
    }

    /// The whole-face sweep of the parallel view `view` (voxel units, unit spacing) for `p`
    /// pipelines: the frame set-up's slice axis and direction (`FrameSetup`).
    pub fn of_view(
        dims: [usize; 3],
        view: [f64; 3],
        p: u32,
        block: u32,
        base: u64,
    ) -> Result<(Self, FrameParams)> {
        let params = FrameSetup::new(dims, [1.0; 3], DVec3::from(view), p as usize)?.params;
        Ok((Self::of_frame(&params, dims, block, base), params))
    }

    /// The block columns a section of anchors `[a0, a0 + s)` needs (docs/accel.md): `(a0 - 1)
    /// div B ..= (a0 + s) div B`, clamped to the volume.
    pub fn with_anchor_section(mut self, block: u32, a0: u32, s: u32) -> Self {
        let (ai, _) = frame_axes(self.axis_k);
        let nbi = self.blocks[ai];
        self.sec_lo = a0.saturating_sub(1) / block;
        self.sec_hi = ((a0 + s) / block + 1).min(nbi);
        self
    }

    /// The blocks of the walk, in order (docs/numerics/vol_fetch.md, "The walk").
    pub fn blocks_in_order(&self) -> Vec<[u32; 3]> {
        let (ai, aj) = frame_axes(self.axis_k);
        let ak = self.axis_k as usize;
        let nk = self.blocks[ak];
        let mut out = Vec::new();
        for t in 0..nk {
            let bk = if self.reversed { nk - 1 - t } else { t };
            for bj in 0..self.blocks[aj] {
                for bi in self.sec_lo..self.sec_hi {
                    let mut b = [0u32; 3];
                    b[ai] = bi;
                    b[aj] = bj;
                    b[ak] = bk;
                    out.push(b);
                }
            }
        }
        out
    }
}

/// The beam axis `i` and row axis `j` of slice axis `k` (the other two, ascending).
pub fn frame_axes(axis_k: u32) -> (usize, usize) {
    match axis_k {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// A command: a LUT write or a sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FetchCmd {
    Lut { index: u32, entry: BlockEntry },
    Sweep(Sweep),
}

/// One output item: P voxels of a present block (a P-group, `word` its index in the block), or
/// the skip item of an empty block, or the error item of a refused sweep.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FetchItem {
    pub lanes: Vec<u32>,
    pub blk: [u32; 3],
    pub word: u32,
    pub skip: bool,
    pub last: bool,
    pub error: bool,
    pub resp_err: bool,
}

impl FetchItem {
    /// `p` voxels of 1 in block (0, 0, 0), word 0, no flags: an item no section asked for.
    pub fn stray(p: u32) -> Self {
        Self {
            lanes: vec![1; p as usize],
            blk: [0; 3],
            word: 0,
            skip: false,
            last: false,
            error: false,
            resp_err: false,
        }
    }
}

/// What a command list produces: the output items and the reader's commands, in order.
#[derive(Debug, Clone, Default)]
pub struct FetchRun {
    pub items: Vec<FetchItem>,
    pub reads: Vec<AxiRdCmd>,
    /// Present blocks read and empty or masked blocks skipped.
    pub blocks_read: u64,
    pub blocks_skipped: u64,
}

/// The unit's state: the block LUT (an entry not yet written is `None`).
#[derive(Debug, Clone)]
pub struct VolFetch {
    cfg: VolFetchConfig,
    lut: Vec<Option<BlockEntry>>,
}

impl VolFetch {
    pub fn new(cfg: VolFetchConfig) -> Result<Self> {
        cfg.validate()?;
        Ok(Self {
            cfg,
            lut: vec![None; (cfg.nb() as usize).pow(3)],
        })
    }

    pub fn config(&self) -> VolFetchConfig {
        self.cfg
    }

    /// Why a sweep is refused, or `None` (docs/numerics/vol_fetch.md, "Commands").
    pub fn refusal(&self, s: &Sweep) -> Option<String> {
        let c = &self.cfg;
        if s.axis_k > 2 {
            return Some(format!("axis_k {} is reserved", s.axis_k));
        }
        if s.blocks.iter().any(|&n| n == 0 || n > c.nb()) {
            return Some(format!("blocks {:?} outside 1..={}", s.blocks, c.nb()));
        }
        let (ai, _) = frame_axes(s.axis_k);
        if s.sec_lo >= s.sec_hi || s.sec_hi > s.blocks[ai] {
            return Some(format!(
                "section [{}, {}) is not inside 0..{}",
                s.sec_lo, s.sec_hi, s.blocks[ai]
            ));
        }
        if !s.base.is_multiple_of(u64::from(c.data_w / 8)) || c.wrap(s.base) != s.base {
            return Some(format!("base {:#x} is not a bus-aligned address", s.base));
        }
        None
    }

    /// Runs `cmds` against the memory `mem`. A sweep that reads a LUT entry never written is a
    /// test-bench error (the RTL's entry would be undefined).
    pub fn run(&mut self, cmds: &[FetchCmd], mem: &AxiMemImage) -> Result<FetchRun> {
        let c = self.cfg;
        let p = c.p as usize;
        let bbus = c.data_w / 8;
        let mask = (1u32 << c.voxel_w) - 1;
        let mut run = FetchRun::default();
        for cmd in cmds {
            match *cmd {
                FetchCmd::Lut { index, entry } => {
                    let slot = self.lut.get_mut(index as usize).ok_or_else(|| {
                        ModelError::Config(format!("cube5_vol_fetch: LUT index {index} too large"))
                    })?;
                    *slot = Some(BlockEntry {
                        ptr: entry.ptr & ((1u32 << c.blk_w()) - 1),
                        ..entry
                    });
                }
                FetchCmd::Sweep(s) => {
                    if self.refusal(&s).is_some() {
                        run.items.push(FetchItem {
                            lanes: vec![0; p],
                            blk: [0; 3],
                            word: 0,
                            skip: false,
                            last: true,
                            error: true,
                            resp_err: false,
                        });
                        continue;
                    }
                    let order = s.blocks_in_order();
                    let n = order.len();
                    for (k, blk) in order.into_iter().enumerate() {
                        let e = self.lut[c.lut_index(blk) as usize].ok_or_else(|| {
                            ModelError::Config(format!(
                                "cube5_vol_fetch: the sweep reads block {blk:?}, whose LUT entry was never written"
                            ))
                        })?;
                        let final_block = k + 1 == n;
                        if e.empty || e.masked {
                            run.blocks_skipped += 1;
                            run.items.push(FetchItem {
                                lanes: vec![0; p],
                                blk,
                                word: 0,
                                skip: true,
                                last: final_block,
                                error: false,
                                resp_err: false,
                            });
                            continue;
                        }
                        run.blocks_read += 1;
                        let addr = c.wrap(s.base + u64::from(e.ptr) * c.block_bytes());
                        run.reads.push(AxiRdCmd {
                            addr,
                            len: c.beats_per_block(),
                        });
                        let groups = c.groups();
                        let per_beat = (c.data_w / (16 * c.p)) as usize;
                        for g in 0..groups {
                            let beat = g as usize / per_beat;
                            let beat_addr = c.wrap(addr + beat as u64 * u64::from(bbus));
                            let (data, resp) = mem.beat(beat_addr, bbus);
                            let off = (g as usize % per_beat) * 2 * p;
                            let lanes = (0..p)
                                .map(|l| {
                                    let o = off + 2 * l;
                                    u32::from(u16::from_le_bytes([data[o], data[o + 1]])) & mask
                                })
                                .collect();
                            run.items.push(FetchItem {
                                lanes,
                                blk,
                                word: g,
                                skip: false,
                                last: final_block && g + 1 == groups,
                                error: false,
                                resp_err: resp != RESP_OKAY,
                            });
                        }
                    }
                }
            }
        }
        Ok(run)
    }
}

impl StreamCodec for VolFetchConfig {
    type In = FetchCmd;
    type Out = FetchItem;

    fn in_width(&self) -> u32 {
        self.cmd_w()
    }

    /// lanes (P x VoxelW), blk x, y, z (NbW each), word (WordW), skip, last, error, resp_err.
    fn out_width(&self) -> u32 {
        self.p * self.voxel_w + 3 * self.nb_w() + self.word_w() + 4
    }

    fn pack_in(&self, cmd: &FetchCmd) -> Vec<u32> {
        let mut w = BitWriter::new();
        match *cmd {
            FetchCmd::Lut { index, entry } => {
                w.put(0, 1);
                w.put(u64::from(index), self.blk_w());
                w.put(u64::from(entry.ptr), self.blk_w());
                w.put(u64::from(entry.empty), 1);
                w.put(u64::from(entry.masked), 1);
            }
            FetchCmd::Sweep(s) => {
                w.put(1, 1);
                if self.addr_w > 32 {
                    w.put(s.base & 0xffff_ffff, 32);
                    w.put(s.base >> 32, self.addr_w - 32);
                } else {
                    w.put(s.base, self.addr_w);
                }
                for n in s.blocks {
                    w.put(u64::from(n), self.nb_w() + 1);
                }
                w.put(u64::from(s.axis_k), 2);
                w.put(u64::from(s.reversed), 1);
                w.put(u64::from(s.sec_lo), self.nb_w());
                w.put(u64::from(s.sec_hi), self.nb_w() + 1);
            }
        }
        // Zero padding up to the longer payload.
        w.finish_padded(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> FetchItem {
        let mut r = BitReader::new(words);
        let lanes = (0..self.p).map(|_| r.get(self.voxel_w) as u32).collect();
        let blk = [0; 3].map(|_: u32| r.get(self.nb_w()) as u32);
        let word = r.get(self.word_w()) as u32;
        FetchItem {
            lanes,
            blk,
            word,
            skip: r.get_bool(),
            last: r.get_bool(),
            error: r.get_bool(),
            resp_err: r.get_bool(),
        }
    }
}

// The RTL parameters of this unit (the RTL defaults are the model's `DEFAULT`).
crate::unit_config!(VolFetchConfig, "cube5_vol_fetch", DEFAULT, {
    "AddrW" => addr_w,
    "DataW" => data_w,
    "P" => p,
    "VoxelW" => voxel_w,
    "MaxDim" => max_dim,
    "BlockDim" => block_dim,
    "MaxBurst" => max_burst,
    "Outstanding" => outstanding,
    "IdW" => id_w,
});

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::head_phantom;
    use crate::units::cube5_skewmem::{Axis, SkewConfig, SkewDims, SkewIn, SkewMem};
    use std::collections::{HashMap, HashSet};

    const C: VolFetchConfig = VolFetchConfig::DEFAULT;

    fn cfg(p: u32, block_dim: u32, data_w: u32) -> VolFetchConfig {
        VolFetchConfig {
            p,
            block_dim,
            data_w,
            ..C
        }
    }

    /// A volume of `dims` with a pseudo-random but reproducible density, zero in some blocks.
    fn test_volume(dims: [usize; 3], block: usize) -> Volume {
        let mut data = Vec::with_capacity(dims.iter().product());
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let blk = (x / block) + 3 * (y / block) + 5 * (z / block);
                    let v = if blk % 3 == 1 {
                        0
                    } else {
                        ((x * 7 + y * 13 + z * 29) % 4093 + 1) as u16
                    };
                    data.push(v);
                }
            }
        }
        Volume::new(dims, [1.0; 3], 12, data).unwrap()
    }

    #[test]
    fn the_layout_is_a_bijection_onto_the_used_slots() {
        for (dims, b) in [
            ([24usize, 16, 40], 8u32),
            ([20, 12, 9], 4),
            ([16, 16, 16], 2),
        ] {
            let c = VolFetchConfig {
                block_dim: b,
                p: 2,
                data_w: 32,
                ..C
            };
            let blocks = dims.map(|n| n.div_ceil(b as usize) as u32);
            let n: u32 = blocks.iter().product();
            // A scrambled pointer assignment: ptr = (index * 7 + 3) mod n, a permutation when
            // gcd(7, n) = 1; else the identity.
            let mul = if n.is_multiple_of(7) { 1 } else { 7 };
            let mut seen = HashSet::new();
            let base = 0x4000;
            for z in 0..blocks[2] * b {
                for y in 0..blocks[1] * b {
                    for x in 0..blocks[0] * b {
                        let idx = x / b + blocks[0] * (y / b + blocks[1] * (z / b));
                        let ptr = (idx * mul + 3) % n;
                        let a = c.voxel_addr(base, ptr, [x, y, z]);
                        assert!(a >= base && a < base + u64::from(n) * c.block_bytes());
                        assert_eq!(a % 2, 0);
                        assert!(
                            seen.insert(a),
                            "{dims:?} B {b}: ({x}, {y}, {z}) shares {a:#x}"
                        );
                    }
                }
            }
            assert_eq!(seen.len() as u64, u64::from(n) * c.block_bytes() / 2);
        }
    }

    #[test]
    fn the_image_holds_each_voxel_at_its_address() {
        let vol = test_volume([20, 12, 9], 4);
        let lut = BlockLut::from_volume(&vol, 4, 0).unwrap();
        let img = dram_image(&vol, &lut, 0x1000).unwrap();
        let c = cfg(2, 4, 32);
        for z in 0..12u32 {
            for y in 0..12u32 {
                for x in 0..20u32 {
                    let e = lut.entry([x / 4, y / 4, z / 4]).unwrap();
                    let a = (c.voxel_addr(0x1000, e.ptr, [x, y, z]) - img.base) as usize;
                    let v = u16::from_le_bytes([img.bytes[a], img.bytes[a + 1]]);
                    assert_eq!(u32::from(v), vol.get(x as i64, y as i64, z as i64));
                }
            }
        }
    }

    fn frame_params(dims: [usize; 3], view: [f64; 3], p: u32) -> FrameParams {
        FrameSetup::new(dims, [1.0; 3], DVec3::from(view), p as usize)
            .unwrap()
            .params
    }

    /// The six faces, exactly 45 degrees, and an oblique view.
    fn views() -> impl Iterator<Item = [f64; 3]> {
        crate::camera::FACE_DIRECTIONS
            .into_iter()
            .chain([[1.0, 0.0, 1.0], [-0.4, 0.8, -1.0]])
    }

    /// The whole data path against the frame: the delivered stream, put into a buffer that keeps
    /// one slab (the blocks delivered since the slab began; skip items read as zeros), serves every
    /// beam the frame model reads from the skewed memory (`SkewMem`, the same LUT), in the frame's
    /// order, slab by slab; every item is used, and no beam needs a block not yet delivered.
    #[test]
    fn the_delivered_stream_is_what_the_frame_reads_in_slab_order() {
        let vol = head_phantom(32, 12).unwrap();
        let dims = vol.dims;
        for (p, b, data_w) in [(1u32, 4u32, 16u32), (2, 4, 64), (4, 8, 64), (8, 8, 128)] {
            let c = VolFetchConfig {
                max_dim: 32,
                ..cfg(p, b, data_w)
            };
            let lut = BlockLut::from_volume(&vol, b as usize, 0).unwrap();
            assert!(
                lut.entries.iter().any(|e| e.empty),
                "the head has empty blocks"
            );
            let img = dram_image(&vol, &lut, 0x2_0000).unwrap();
            let skew = SkewConfig {
                p,
                voxel_w: 12,
                max_dim_log2: 5,
                block: b,
                read_latency: 1,
                cnt_w: 16,
            };
            let sd = SkewDims::new(&skew, dims.map(|d| d as u32)).unwrap();
            let mut mem = SkewMem::new(skew, sd, lut.clone()).unwrap();
            for z in 0..32u32 {
                for y in 0..32u32 {
                    for x in 0..32u32 {
                        let v = vol.get(x as i64, y as i64, z as i64);
                        mem.command(&SkewIn::write([x, y, z], v));
                    }
                }
            }
            for view in views() {
                let params = frame_params(dims, view, p);
                // The whole face, then a section of anchors [8, 16) (its blocks and overlap).
                for section in [None, Some((8u32, 8u32))] {
                    let mut sweep = Sweep::of_frame(&params, dims, b, img.base);
                    if let Some((a0, s)) = section {
                        sweep = sweep.with_anchor_section(b, a0, s);
                    }
                    let mut unit = VolFetch::new(c).unwrap();
                    let mut cmds = c.lut_writes(&lut).unwrap();
                    cmds.push(FetchCmd::Sweep(sweep));
                    let run = unit.run(&cmds, &img).unwrap();
                    check_against_frame(c, &params, &sweep, section, &run, &mut mem, view);
                }
            }
        }
    }

    /// One slab of the test's section buffer: the voxels of each block delivered, by block.
    type Slab = HashMap<[u32; 3], Vec<u32>>;

    fn check_against_frame(
        c: VolFetchConfig,
        params: &FrameParams,
        sweep: &Sweep,
        section: Option<(u32, u32)>,
        run: &FetchRun,
        mem: &mut SkewMem,
        view: [f64; 3],
    ) {
        let (b, p) = (c.block_dim, c.p);
        // Group the items by slab (the block's coordinate along k), in arrival order.
        let ak = params.axis_k;
        let mut slabs: Vec<(u32, Slab)> = Vec::new();
        for it in &run.items {
            assert!(!it.error && !it.resp_err, "{view:?}: {it:?}");
            let bk = it.blk[ak];
            if slabs.last().is_none_or(|(k, _)| *k != bk) {
                assert!(
                    slabs.iter().all(|(k, _)| *k != bk),
                    "{view:?}: slab {bk} comes back"
                );
                slabs.push((bk, HashMap::new()));
            }
            let blk = slabs.last_mut().unwrap().1.entry(it.blk).or_default();
            if it.skip {
                assert!(blk.is_empty());
                blk.extend(std::iter::repeat_n(0, (b * b * b) as usize));
            } else {
                assert_eq!(
                    it.word as usize * p as usize,
                    blk.len(),
                    "P-groups in order"
                );
                blk.extend(&it.lanes);
            }
        }
        assert!(run.items.last().unwrap().last);
        assert_eq!(run.items.iter().filter(|i| i.last).count(), 1);
        // The slabs come front to back.
        let order: Vec<u32> = slabs.iter().map(|s| s.0).collect();
        let want: Vec<u32> = (0..sweep.blocks[ak])
            .map(|t| {
                if params.k_reversed {
                    sweep.blocks[ak] - 1 - t
                } else {
                    t
                }
            })
            .collect();
        assert_eq!(order, want, "{view:?}");
        // Every beam the frame reads in the section's anchors, in the frame's order.
        let (lo, hi) = match section {
            None => (0, params.ni as u32),
            Some((a0, s)) => (a0 - 1, a0 + s + 1),
        };
        let axis = Axis::ALL[params.axis_i];
        let mut used = HashSet::new();
        let mut slab_at = 0;
        for s in 0..params.nk {
            let k = params.slice(s).k as u32;
            while slabs[slab_at].0 != k / b {
                slab_at += 1; // the buffer moves on to the next slab, never back
            }
            let slab = &slabs[slab_at].1;
            for bj in 0..params.nj as u32 {
                for m in (lo / p)..hi.div_ceil(p) {
                    let mut pos = [0u32; 3];
                    pos[params.axis_i] = m * p;
                    pos[params.axis_j] = bj;
                    pos[ak] = k;
                    let beam = mem.command(&SkewIn::read(pos, axis)).voxels;
                    let blk = pos.map(|v| v / b);
                    let got = slab.get(&blk).unwrap_or_else(|| {
                        panic!(
                            "{view:?}: beam {pos:?} needs block {blk:?}, not in slab {}",
                            k / b
                        )
                    });
                    for (l, want) in beam.iter().enumerate() {
                        let mut q = pos;
                        q[params.axis_i] += l as u32;
                        let loc = q.map(|v| v % b);
                        let at = (loc[0] + b * (loc[1] + b * loc[2])) as usize;
                        assert_eq!(got[at], *want, "{view:?}: voxel {q:?}");
                    }
                    used.insert(blk);
                }
            }
        }
        // Every delivered block is used by the frame (no burst brings voxels nobody reads).
        let delivered: usize = slabs.iter().map(|s| s.1.len()).sum();
        assert_eq!(
            delivered,
            used.len(),
            "{view:?}: blocks delivered but unused"
        );
    }

    /// Every burst the unit issues holds voxels of the sweep: its bytes fall in one present
    /// block's slot, that block is in the section, and each burst lies inside a block.
    #[test]
    fn every_burst_holds_voxels_of_the_sweep_and_empty_blocks_cost_none() {
        let vol = head_phantom(32, 12).unwrap();
        let c = VolFetchConfig { max_dim: 32, ..C };
        let lut = BlockLut::from_volume(&vol, 8, 0).unwrap();
        let img = dram_image(&vol, &lut, 0).unwrap();
        let params = frame_params(vol.dims, [-0.4, 0.8, -1.0], 4);
        let sweep = Sweep::of_frame(&params, vol.dims, 8, 0).with_anchor_section(8, 8, 8);
        let mut unit = VolFetch::new(c).unwrap();
        let mut cmds = c.lut_writes(&lut).unwrap();
        cmds.push(FetchCmd::Sweep(sweep));
        let run = unit.run(&cmds, &img).unwrap();
        let in_sweep: HashSet<u32> = sweep
            .blocks_in_order()
            .iter()
            .map(|&b| lut.entry(b).unwrap())
            .filter(|e| !e.empty)
            .map(|e| e.ptr)
            .collect();
        let axi = c.axi_rd();
        let mut n = 0;
        for r in &run.reads {
            for burst in axi.bursts(r) {
                let slot = (burst.addr / c.block_bytes()) as u32;
                let end = burst.addr + u64::from(burst.beats) * u64::from(c.data_w / 8);
                assert_eq!((end - 1) / c.block_bytes(), u64::from(slot));
                assert!(
                    in_sweep.contains(&slot),
                    "burst {burst:?} outside the sweep"
                );
                n += 1;
            }
        }
        let total = sweep.blocks_in_order().len() as u64;
        assert_eq!(run.blocks_read + run.blocks_skipped, total);
        assert_eq!(run.blocks_read as usize, in_sweep.len());
        assert!(run.blocks_skipped > 0);
        assert_eq!(
            n as u64,
            run.blocks_read * u64::from(c.beats_per_block() / 16)
        );
    }

    #[test]
    fn refused_sweeps_answer_one_error_item() {
        let c = VolFetchConfig { max_dim: 32, ..C };
        let mut unit = VolFetch::new(c).unwrap();
        let ok = Sweep::whole(0, [4, 4, 4]);
        assert!(unit.refusal(&ok).is_none());
        for bad in c.refused_sweeps(ok) {
            assert!(unit.refusal(&bad).is_some(), "{bad:?}");
            let run = unit
                .run(&[FetchCmd::Sweep(bad)], &AxiMemImage::default())
                .unwrap();
            assert_eq!(run.items.len(), 1);
            assert!(run.items[0].error && run.items[0].last);
            assert!(run.reads.is_empty());
        }
        // A valid sweep over LUT entries never written is the test bench's error.
        assert!(unit
            .run(&[FetchCmd::Sweep(ok)], &AxiMemImage::default())
            .is_err());
    }

    #[test]
    fn the_codec_round_trips_and_widths_follow_the_contract() {
        let c = C; // NB = 8: NbW 3, BlkW 9, Groups 128: WordW 7
        assert_eq!(c.out_width(), 4 * 12 + 9 + 7 + 4);
        assert_eq!(c.in_width(), 1 + 32 + 12 + 3 + 3 + 4);
        let w = c.pack_in(&FetchCmd::Lut {
            index: 0x1a5,
            entry: BlockEntry {
                ptr: 0x0f3,
                empty: true,
                masked: false,
            },
        });
        assert_eq!(w[0] & 0x7ffff, (0x0f3 << 10) | (0x1a5 << 1));
        assert_eq!((w[0] >> 19) & 3, 1);
        let mut words = vec![0u32; 3];
        // lanes 1, 2, 3, 4; blk (5, 6, 7); word 99; skip, last.
        let mut bw = BitWriter::new();
        for l in 1..=4 {
            bw.put(l, 12);
        }
        for b in 5..=7 {
            bw.put(b, 3);
        }
        bw.put(99, 7);
        bw.put(0b0011, 4);
        words.copy_from_slice(&bw.finish(c.out_width()));
        let it = c.unpack_out(&words);
        assert_eq!(it.lanes, vec![1, 2, 3, 4]);
        assert_eq!(it.blk, [5, 6, 7]);
        assert_eq!(it.word, 99);
        assert!(it.skip && it.last && !it.error && !it.resp_err);
        assert_eq!(c.axi_rd().len_w, 8); // 128 beats per block
        assert_eq!(c.tag_depth(), 8);
    }

    #[test]
    fn bad_parameters_are_refused() {
        for bad in [
            VolFetchConfig { p: 3, ..C },
            VolFetchConfig {
                p: 8,
                block_dim: 2,
                data_w: 128,
                ..C
            },
            VolFetchConfig { data_w: 32, ..C },
            VolFetchConfig {
                block_dim: 64,
                max_dim: 64,
                ..C
            },
            VolFetchConfig { voxel_w: 17, ..C },
            VolFetchConfig { max_dim: 48, ..C },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        C.validate().unwrap();
    }
}
