//! Section buffer (`cube5_section_buf`), written from `docs/numerics/section_buf.md`: what the unit
//! stores from `cube5_vol_fetch`'s items (slab by slab, the section's columns and its edge
//! columns, present blocks) and the beams it reads out in the frame's order.
//!
//! The output is a function of the input sequence alone (timing decides only when beams leave),
//! so the unit is modelled as a stream function; `section_beams` is the reference: the beams
//! read straight from a volume and its block LUT.

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::StreamCodec;
use crate::units::cube5_skewmem::BlockLut;
use crate::units::cube5_vol_fetch::{
    dram_image, frame_axes, FetchCmd, FetchItem, Sweep, VolFetch, VolFetchConfig,
};
use crate::volume::Volume;

/// The RTL parameters of one `cube5_section_buf` configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SectionBufConfig {
    /// Voxels per item and per beam.
    pub p: u32,
    /// Voxel bits.
    pub voxel_w: u32,
    /// Largest volume edge (a power of two).
    pub max_dim: u32,
    /// Block edge `B`.
    pub block_dim: u32,
    /// Section width `S` in anchors.
    pub section: u32,
    /// P-groups per input item, `G` (1 or 2): an item is `Q = G P` voxels.
    pub item_groups: u32,
}

impl SectionBufConfig {
    /// The RTL's parameter defaults.
    pub const DEFAULT: Self = Self {
        p: 4,
        voxel_w: 12,
        max_dim: 64,
        block_dim: 8,
        section: 16,
        item_groups: 1,
    };

    /// VoxelW, MaxDim and BlockDim have the ranges of `cube5_vol_fetch`, whose items (of `Q`
    /// voxels) the unit takes (checked by its configuration); P (with `B >= P`), Section and
    /// ItemGroups are the unit's own.
    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("cube5_section_buf: {what}")));
        if let Err(e) = self.fetch().validate() {
            return bad(e.to_string());
        }
        let (b, s) = (self.block_dim, self.section);
        if !s.is_power_of_two() || s < b || s >= self.max_dim {
            return bad(format!(
                "Section {s} is not a power of two with BlockDim <= S < MaxDim"
            ));
        }
        if !(1..=2).contains(&self.item_groups) || (self.item_groups == 2 && s < 2 * self.p) {
            return bad(format!(
                "ItemGroups {} is not 1, or 2 with Section >= 2 P",
                self.item_groups
            ));
        }
        if self.block_dim < self.p.max(2) {
            return bad(format!(
                "BlockDim {b} is not at least max(2, P = {})",
                self.p
            ));
        }
        Ok(())
    }

    /// Voxels per input item, `Q = G P` (the fetch's P).
    pub fn item_p(&self) -> u32 {
        self.item_groups * self.p
    }

    /// A `cube5_vol_fetch` whose items feed this unit: P = `Q`, the same voxel width, largest
    /// edge and block edge, a bus of `2Q` bytes (one item per beat) and the fetch's other
    /// defaults.
    pub fn fetch(&self) -> VolFetchConfig {
        VolFetchConfig {
            p: self.item_p(),
            voxel_w: self.voxel_w,
            max_dim: self.max_dim,
            block_dim: self.block_dim,
            data_w: 16 * self.item_p(),
            ..VolFetchConfig::DEFAULT
        }
    }

    /// The inputs of section `cmd` of `vol` (LUT `lut`): the command, then the items the fetch
    /// model delivers for `sweep(cmd)` from the volume's memory image.
    pub fn section_inputs(
        &self,
        vol: &Volume,
        lut: &BlockLut,
        cmd: &SectionCmd,
    ) -> Result<Vec<SbufIn>> {
        let f = self.fetch();
        let img = dram_image(vol, lut, 0)?;
        let mut cmds = f.lut_writes(lut)?;
        cmds.push(FetchCmd::Sweep(self.sweep(cmd, 0)));
        let items = VolFetch::new(f)?.run(&cmds, &img)?.items;
        let mut input = vec![SbufIn::Section(*cmd)];
        input.extend(items.into_iter().map(SbufIn::Item));
        Ok(input)
    }

    /// `m = log2 MaxDim`.
    pub fn m(&self) -> u32 {
        self.max_dim.trailing_zeros()
    }

    /// `NbW = log2(MaxDim / B)`.
    pub fn nb_w(&self) -> u32 {
        (self.max_dim / self.block_dim).trailing_zeros()
    }

    /// Items per present block, `B^3 / Q`.
    pub fn groups(&self) -> u32 {
        self.block_dim.pow(3) / self.item_p()
    }

    /// `WordW = max(1, log2(B^3 / Q))`.
    pub fn word_w(&self) -> u32 {
        self.groups().trailing_zeros().max(1)
    }

    /// Bits of a fetch item (the payload of op 0).
    pub fn item_w(&self) -> u32 {
        self.item_p() * self.voxel_w + 3 * self.nb_w() + self.word_w() + 4
    }

    /// Bits of a section command (the payload of op 1).
    pub fn cmd_w(&self) -> u32 {
        3 + 3 * (self.m() + 1) + self.m()
    }

    /// Words of one bank (`G P` of them), `2 B MaxDim S / Q`.
    pub fn bank_depth(&self) -> u32 {
        2 * self.block_dim * self.max_dim * self.section / self.item_p()
    }

    /// Words of one edge bank (`3 G P` of them), `2 MaxDim B / Q`.
    pub fn edge_depth(&self) -> u32 {
        2 * self.max_dim * self.block_dim / self.item_p()
    }

    /// The fetch sweep that feeds `cmd` (docs/numerics/section_buf.md, "Protocol").
    pub fn sweep(&self, cmd: &SectionCmd, base: u64) -> Sweep {
        let b = self.block_dim;
        let mut blocks = [0u32; 3];
        let (ai, aj) = frame_axes(cmd.axis_k);
        let ak = cmd.axis_k.min(2) as usize;
        blocks[ai] = cmd.dims[0].div_ceil(b);
        blocks[aj] = cmd.dims[1].div_ceil(b);
        blocks[ak] = cmd.dims[2].div_ceil(b);
        Sweep {
            base,
            blocks,
            axis_k: cmd.axis_k,
            reversed: cmd.reversed,
            sec_lo: 0,
            sec_hi: blocks[ai],
        }
        .with_anchor_section(b, cmd.a0, self.section)
    }
}

/// Where voxel `(ci, j, lk)` of half `h` of a section swept along `axis_k` is stored
/// (docs/numerics/section_buf.md, *Storage and the skew*): `(bank, word)` among the `G P` banks.
/// `ci` is the column inside the section (`0 .. S`).
pub fn bank_of(c: &SectionBufConfig, axis_k: u32, h: u32, ci: u32, j: u32, lk: u32) -> (u32, u32) {
    let (p, b, s) = (c.p, c.block_dim, c.section);
    let r = (ci + j + lk) % p;
    let g = if c.item_groups == 1 {
        0
    } else {
        // The P-group word's parity (x div P when B >= 2P, y when B = P) and bit 0 of ci div P.
        let [x, y] = match axis_k {
            0 => [lk, ci],
            1 => [ci, lk],
            _ => [ci, j],
        };
        let pi = if b >= 2 * p { (x / p) % 2 } else { y % 2 };
        let cbit = (ci / p) % 2;
        if axis_k != 0 && b >= 2 * p {
            pi
        } else {
            pi ^ cbit
        }
    };
    let q = c.item_p();
    let word = ((h * b + lk) * c.max_dim + j) * (s / q) + ci / q;
    (r + p * g, word)
}

/// Where edge voxel `(j, lk)` of half `h` is stored in each edge memory: `(bank, word)` among its
/// `G P` banks (docs/numerics/section_buf.md, *Storage and the skew*).
pub fn edge_bank_of(c: &SectionBufConfig, h: u32, j: u32, lk: u32) -> (u32, u32) {
    let p = c.p;
    let v = (h * c.max_dim + j) * (c.block_dim / p) + lk / p;
    let e = if c.item_groups == 1 { 0 } else { v % 2 };
    (lk % p + p * e, v / c.item_groups)
}

/// The sizes `(ni, nj, nk)` in frame axes of a volume of `dims` swept along `axis_k` (0..=2).
pub fn frame_dims(dims: [usize; 3], axis_k: u32) -> [u32; 3] {
    let (ai, aj) = frame_axes(axis_k);
    [dims[ai], dims[aj], dims[axis_k as usize]].map(|n| n as u32)
}

/// A section command: frame axes (`axis_k`, direction), sizes `(ni, nj, nk)` in frame axes, and
/// the first anchor `a0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SectionCmd {
    pub axis_k: u32,
    pub reversed: bool,
    pub dims: [u32; 3],
    pub a0: u32,
}

/// One input: a section command or a fetch item.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SbufIn {
    Section(SectionCmd),
    Item(FetchItem),
}

/// One output beam.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Beam {
    pub lanes: Vec<u32>,
    pub lo: u32,
    pub hi0: u32,
    pub hi1: u32,
    pub row_first: bool,
    pub row_last: bool,
    pub slice_last: bool,
    pub last: bool,
    pub error: bool,
}

impl Beam {
    /// Bits of a beam of `p` lanes of `voxel_w` bits (the section buffer's output item and the
    /// beat of a frame fed by a beat stream): lanes, lo, hi0, hi1 (`voxel_w` each), row_first,
    /// row_last, slice_last, last, error, LSB first.
    pub fn width(p: u32, voxel_w: u32) -> u32 {
        (p + 3) * voxel_w + 5
    }

    /// Appends the beam's [`Beam::width`] bits to `w`.
    pub fn pack(&self, w: &mut BitWriter, voxel_w: u32) {
        for &v in self.lanes.iter().chain([&self.lo, &self.hi0, &self.hi1]) {
            w.put(u64::from(v), voxel_w);
        }
        for f in [
            self.row_first,
            self.row_last,
            self.slice_last,
            self.last,
            self.error,
        ] {
            w.put_bool(f);
        }
    }

    /// Reads a beam of `p` lanes back from `r` (the inverse of [`Beam::pack`]).
    pub fn unpack(r: &mut BitReader, p: u32, voxel_w: u32) -> Self {
        let lanes = (0..p).map(|_| r.get(voxel_w) as u32).collect();
        let mut v = || r.get(voxel_w) as u32;
        let (lo, hi0, hi1) = (v(), v(), v());
        Beam {
            lanes,
            lo,
            hi0,
            hi1,
            row_first: r.get_bool(),
            row_last: r.get_bool(),
            slice_last: r.get_bool(),
            last: r.get_bool(),
            error: r.get_bool(),
        }
    }

    fn error(p: u32) -> Self {
        Self {
            lanes: vec![0; p as usize],
            lo: 0,
            hi0: 0,
            hi1: 0,
            row_first: false,
            row_last: false,
            slice_last: false,
            last: true,
            error: true,
        }
    }
}

/// The geometry of an accepted section.
#[derive(Debug, Clone, Copy)]
struct Geometry {
    cmd: SectionCmd,
    ns: u32,
    nbj: u32,
    nbk: u32,
    sec_hi: u32,
}

/// The beams of one slab `t` of `g`, reading voxel `(ci, j, lk)` (ci from -1 to ns + 1) with
/// `voxel` (already zero where the block is not present).
fn slab_beams(
    c: &SectionBufConfig,
    g: &Geometry,
    t: u32,
    voxel: impl Fn(i64, u32, u32) -> u32,
) -> Vec<Beam> {
    let b = c.block_dim;
    let [ni, nj, nk] = g.cmd.dims;
    let bk = if g.cmd.reversed { g.nbk - 1 - t } else { t };
    let nkl = b.min(nk - b * bk);
    let beats = g.ns / c.p;
    let a0 = i64::from(g.cmd.a0);
    let outside = |ci: i64| a0 + ci < 0 || a0 + ci >= i64::from(ni);
    let edge = |ci: i64, j: u32, lk: u32| if outside(ci) { 0 } else { voxel(ci, j, lk) };
    let mut out = Vec::new();
    for n in 0..nkl {
        let lk = if g.cmd.reversed { nkl - 1 - n } else { n };
        for j in 0..nj {
            for m in 0..beats {
                let first = m == 0;
                let last_in_row = m + 1 == beats;
                let ci0 = i64::from(m * c.p);
                out.push(Beam {
                    lanes: (0..c.p).map(|l| voxel(ci0 + i64::from(l), j, lk)).collect(),
                    lo: if first { edge(-1, j, lk) } else { 0 },
                    hi0: if last_in_row {
                        edge(i64::from(g.ns), j, lk)
                    } else {
                        0
                    },
                    hi1: if last_in_row {
                        edge(i64::from(g.ns) + 1, j, lk)
                    } else {
                        0
                    },
                    row_first: first,
                    row_last: last_in_row,
                    slice_last: last_in_row && j + 1 == nj,
                    last: last_in_row && j + 1 == nj && n + 1 == nkl && t + 1 == g.nbk,
                    error: false,
                });
            }
        }
    }
    out
}

/// One slab as the unit stores it: voxels by `(lk, j, ci + 1)` and the present blocks by
/// `(b_j, b_i)`.
struct Slab {
    voxels: Vec<u32>,
    present: Vec<bool>,
    cols: usize,
    rows: usize,
    blk_cols: usize,
}

impl Slab {
    fn new(c: &SectionBufConfig) -> Self {
        let cols = c.section as usize + 3;
        let rows = c.max_dim as usize;
        let blk_cols = (c.max_dim / c.block_dim) as usize;
        Self {
            voxels: vec![0; c.block_dim as usize * rows * cols],
            present: vec![false; blk_cols * (c.max_dim / c.block_dim) as usize],
            cols,
            rows,
            blk_cols,
        }
    }

    fn at(&self, ci: i64, j: u32, lk: u32) -> usize {
        (lk as usize * self.rows + j as usize) * self.cols + (ci + 1) as usize
    }
}

/// The unit: the section being written (if any) and the slab it is filling.
pub struct SectionBuf {
    cfg: SectionBufConfig,
    active: Option<Geometry>,
    /// Slab being filled (`t`) and its store.
    t: u32,
    slab: Slab,
}

impl SectionBuf {
    pub fn new(cfg: SectionBufConfig) -> Result<Self> {
        cfg.validate()?;
        Ok(Self {
            cfg,
            active: None,
            t: 0,
            slab: Slab::new(&cfg),
        })
    }

    pub fn config(&self) -> SectionBufConfig {
        self.cfg
    }

    /// The state after reset: no section.
    pub fn reset(&mut self) {
        self.active = None;
    }

    /// Why a section command is refused, or `None`.
    pub fn refusal(&self, cmd: &SectionCmd) -> Option<String> {
        let c = &self.cfg;
        if cmd.axis_k > 2 {
            return Some(format!("axis_k {} is reserved", cmd.axis_k));
        }
        if cmd
            .dims
            .iter()
            .any(|&n| n < c.p || n > c.max_dim || !n.is_multiple_of(c.p))
        {
            return Some(format!(
                "sizes {:?} not multiples of P = {} in P..={}",
                cmd.dims, c.p, c.max_dim
            ));
        }
        if !cmd.a0.is_multiple_of(c.section) || cmd.a0 >= cmd.dims[0] {
            return Some(format!(
                "first anchor {} is not a multiple of S = {} below ni = {}",
                cmd.a0, c.section, cmd.dims[0]
            ));
        }
        None
    }

    fn geometry(&self, cmd: SectionCmd) -> Geometry {
        let b = self.cfg.block_dim;
        let [ni, nj, nk] = cmd.dims;
        Geometry {
            cmd,
            ns: self.cfg.section.min(ni - cmd.a0),
            nbj: nj.div_ceil(b),
            nbk: nk.div_ceil(b),
            sec_hi: ni.div_ceil(b).min((cmd.a0 + self.cfg.section) / b + 1),
        }
    }

    /// Processes `inputs` in order; returns the beams they produce.
    pub fn run(&mut self, inputs: &[SbufIn]) -> Vec<Beam> {
        let mut out = Vec::new();
        for input in inputs {
            self.step(input, &mut out);
        }
        out
    }

    fn step(&mut self, input: &SbufIn, out: &mut Vec<Beam>) {
        let c = self.cfg;
        match (input, self.active) {
            (SbufIn::Section(cmd), None) => {
                if self.refusal(cmd).is_some() {
                    out.push(Beam::error(c.p));
                } else {
                    self.active = Some(self.geometry(*cmd));
                    self.t = 0;
                    self.slab.present.fill(false);
                }
            }
            (SbufIn::Section(_), Some(_)) | (SbufIn::Item(_), None) => {} // dropped
            (SbufIn::Item(it), Some(g)) => {
                if it.error {
                    return;
                }
                self.store(&g, it);
                let (ai, aj) = frame_axes(g.cmd.axis_k);
                let closes = it.blk[aj] == g.nbj - 1
                    && it.blk[ai] == g.sec_hi - 1
                    && (it.skip || it.word + 1 == c.groups());
                if closes {
                    let slab = &self.slab;
                    let b = c.block_dim;
                    let a0 = i64::from(g.cmd.a0);
                    let voxel = |ci: i64, j: u32, lk: u32| {
                        let i = a0 + ci;
                        let (bi, bj) = (i.div_euclid(i64::from(b)), j / b);
                        let present = i >= 0
                            && (bi as usize) < slab.blk_cols
                            && slab.present[bj as usize * slab.blk_cols + bi as usize];
                        if present {
                            slab.voxels[slab.at(ci, j, lk)]
                        } else {
                            0
                        }
                    };
                    out.extend(slab_beams(&c, &g, self.t, voxel));
                    self.t += 1;
                    self.slab.present.fill(false);
                    if self.t == g.nbk {
                        self.active = None;
                    }
                }
            }
        }
    }

    fn store(&mut self, g: &Geometry, it: &FetchItem) {
        let c = self.cfg;
        let b = c.block_dim;
        let (ai, aj) = frame_axes(g.cmd.axis_k);
        let ak = g.cmd.axis_k as usize;
        let slab = &mut self.slab;
        if !it.skip {
            let (bi, bj) = (it.blk[ai] as usize, it.blk[aj] as usize);
            slab.present[bj * slab.blk_cols + bi] = true;
        }
        if it.skip {
            return;
        }
        for (l, &v) in it.lanes.iter().enumerate() {
            let w = it.word * c.item_p() + l as u32;
            let local = [w % b, (w / b) % b, w / (b * b)];
            let pos: [u32; 3] = std::array::from_fn(|a| it.blk[a] * b + local[a]);
            let ci = i64::from(pos[ai]) - i64::from(g.cmd.a0);
            if (-1..=i64::from(g.ns) + 1).contains(&ci) {
                let at = slab.at(ci, pos[aj], pos[ak] % b);
                slab.voxels[at] = v;
            }
        }
    }
}

/// The reference: the beams of section `cmd` read straight from `vol` (voxels in blocks that
/// `lut` marks empty or masked read zero), or the error beam of a refused section.
pub fn section_beams(
    cfg: &SectionBufConfig,
    vol: &Volume,
    lut: &BlockLut,
    cmd: &SectionCmd,
) -> Result<Vec<Beam>> {
    let unit = SectionBuf::new(*cfg)?;
    if unit.refusal(cmd).is_some() {
        return Ok(vec![Beam::error(cfg.p)]);
    }
    let g = unit.geometry(*cmd);
    let (ai, aj) = frame_axes(cmd.axis_k);
    let ak = cmd.axis_k as usize;
    let b = cfg.block_dim;
    let mut out = Vec::new();
    for t in 0..g.nbk {
        let bk = if cmd.reversed { g.nbk - 1 - t } else { t };
        let voxel = |ci: i64, j: u32, lk: u32| {
            let i = i64::from(cmd.a0) + ci;
            let mut pos = [0i64; 3];
            pos[ai] = i;
            pos[aj] = i64::from(j);
            pos[ak] = i64::from(bk * b + lk);
            if i < 0 {
                return 0;
            }
            let blk = pos.map(|v| (v as u32) / b);
            match lut.entry(blk) {
                Some(e) if !e.empty && !e.masked => vol.get(pos[0], pos[1], pos[2]),
                _ => 0,
            }
        };
        out.extend(slab_beams(cfg, &g, t, voxel));
    }
    Ok(out)
}

impl StreamCodec for SectionBufConfig {
    type In = SbufIn;
    type Out = Beam;

    fn in_width(&self) -> u32 {
        1 + self.item_w().max(self.cmd_w())
    }

    /// A beam ([`Beam::width`]).
    fn out_width(&self) -> u32 {
        Beam::width(self.p, self.voxel_w)
    }

    fn pack_in(&self, input: &SbufIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        match input {
            SbufIn::Item(it) => {
                w.put(0, 1);
                for &v in &it.lanes {
                    w.put(u64::from(v), self.voxel_w);
                }
                for &b in &it.blk {
                    w.put(u64::from(b), self.nb_w());
                }
                w.put(u64::from(it.word), self.word_w());
                for f in [it.skip, it.last, it.error, it.resp_err] {
                    w.put_bool(f);
                }
            }
            SbufIn::Section(cmd) => {
                w.put(1, 1);
                w.put(u64::from(cmd.axis_k), 2);
                w.put_bool(cmd.reversed);
                for &n in &cmd.dims {
                    w.put(u64::from(n), self.m() + 1);
                }
                w.put(u64::from(cmd.a0), self.m());
            }
        }
        w.finish_padded(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> Beam {
        Beam::unpack(&mut BitReader::new(words), self.p, self.voxel_w)
    }
}

// The RTL parameters of this unit (the RTL defaults are the model's `DEFAULT`).
crate::unit_config!(SectionBufConfig, "cube5_section_buf", DEFAULT, {
    "P" => p,
    "VoxelW" => voxel_w,
    "MaxDim" => max_dim,
    "BlockDim" => block_dim,
    "Section" => section,
    "ItemGroups" => item_groups,
});

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::head_phantom;

    /// `(P, B, S, G)` of the model's checks: one and two P-groups per item, `B = P` and `B > P`.
    const SHAPES: &[(u32, u32, u32, u32)] = &[
        (1, 2, 4, 1),
        (2, 4, 8, 1),
        (4, 4, 16, 1),
        (8, 8, 8, 1),
        (4, 8, 16, 1),
        (1, 2, 4, 2),
        (2, 2, 4, 2),
        (2, 4, 8, 2),
        (4, 4, 8, 2),
        (4, 8, 16, 2),
    ];

    /// A configuration of 12-bit voxels: `(P, B, S, G)` and the largest edge.
    fn config(
        (p, block_dim, section, item_groups): (u32, u32, u32, u32),
        max_dim: u32,
    ) -> SectionBufConfig {
        SectionBufConfig {
            p,
            voxel_w: 12,
            max_dim,
            block_dim,
            section,
            item_groups,
        }
    }

    /// DRAM -> fetch model -> section buffer model equals the beams read from the volume, for
    /// every axis both ways, every section of the face, P = 1 .. 8, with empty blocks.
    #[test]
    fn fetched_sections_are_the_volumes_beams() {
        let vol = head_phantom(32, 12).unwrap();
        let vol = Volume::new([32, 24, 16], [1.0; 3], 12, {
            let mut d = Vec::new();
            for z in 0..16 {
                for y in 0..24 {
                    for x in 0..32 {
                        d.push(vol.get(x, y, z) as u16);
                    }
                }
            }
            d
        })
        .unwrap();
        for &(p, b, s, g) in SHAPES {
            let c = config((p, b, s, g), 32);
            let lut = BlockLut::from_volume(&vol, b as usize, 0).unwrap();
            assert!(lut.entries.iter().any(|e| e.empty));
            for axis_k in 0..3 {
                for reversed in [false, true] {
                    let dims = frame_dims(vol.dims, axis_k);
                    let mut unit = SectionBuf::new(c).unwrap();
                    let mut total = 0;
                    for a0 in (0..dims[0]).step_by(s as usize) {
                        let cmd = SectionCmd {
                            axis_k,
                            reversed,
                            dims,
                            a0,
                        };
                        let got = unit.run(&c.section_inputs(&vol, &lut, &cmd).unwrap());
                        let want = section_beams(&c, &vol, &lut, &cmd).unwrap();
                        assert_eq!(got.len(), want.len());
                        for (k, (gb, w)) in got.iter().zip(&want).enumerate() {
                            assert_eq!(gb, w, "P {p} B {b} S {s} G {g} {cmd:?}: beam {k}");
                        }
                        total += got.len() as u32;
                    }
                    assert_eq!(total, dims.iter().product::<u32>() / p);
                }
            }
        }
    }

    /// The skew of *Storage and the skew*: every item writes each bank (and each edge bank) at
    /// most once, every beam reads each bank at most once at one word, and no two voxels share a
    /// bank word, for every axis and both item widths.
    #[test]
    fn the_banks_are_conflict_free() {
        use std::collections::HashSet;
        for &(p, b, s, g) in SHAPES.iter().chain(&[(2, 16, 32, 2)]) {
            let c = config((p, b, s, g), 64);
            let q = c.item_p();
            let nj = 2 * b;
            for axis_k in 0..3u32 {
                let mut seen = HashSet::new();
                for h in 0..2 {
                    for lk in 0..b {
                        for j in 0..nj {
                            for ci in 0..s {
                                let (bank, word) = bank_of(&c, axis_k, h, ci, j, lk);
                                assert!(bank < g * p && word < c.bank_depth());
                                assert!(seen.insert((bank, word)), "{c:?} axis {axis_k}");
                            }
                            for m in 0..s / p {
                                let at: Vec<_> = (0..p)
                                    .map(|l| bank_of(&c, axis_k, h, m * p + l, j, lk))
                                    .collect();
                                assert!(at.iter().all(|a| a.1 == at[0].1));
                                let banks: HashSet<_> = at.iter().map(|a| a.0).collect();
                                assert_eq!(banks.len(), p as usize);
                            }
                        }
                    }
                }
                // Items: the Q voxels of local indices u Q .. u Q + Q - 1 of a block at the
                // section's columns (frame coordinates by the axis), main and edge banks.
                let mut eseen = HashSet::new();
                for h in 0..2 {
                    for j in 0..nj {
                        for lk in 0..b {
                            let (bank, word) = edge_bank_of(&c, h, j, lk);
                            assert!(bank < g * p && word < c.edge_depth());
                            assert!(eseen.insert((bank, word)));
                        }
                    }
                }
                for bi in 0..s / b + 2 {
                    for u in 0..b * b * b / q {
                        let mut main = HashSet::new();
                        let mut edge = HashSet::new();
                        for l in 0..q {
                            let w = u * q + l;
                            let local = [w % b, (w / b) % b, w / (b * b)];
                            let (i, jj, k) = match axis_k {
                                0 => (local[1], local[2], local[0]),
                                1 => (local[0], local[2], local[1]),
                                _ => (local[0], local[1], local[2]),
                            };
                            let ci = (bi * b + i) as i64 - b as i64;
                            if (0..s as i64).contains(&ci) {
                                assert!(main.insert(bank_of(&c, axis_k, 0, ci as u32, jj, k).0));
                            } else if [-1, s as i64, s as i64 + 1].contains(&ci) {
                                let bank = edge_bank_of(&c, 0, jj, k).0;
                                assert!(edge.insert((ci, bank)), "{c:?} axis {axis_k}");
                            }
                        }
                    }
                }
            }
        }
    }

    /// The edges are the neighbouring sections' voxels: `lo` of section `a0` is the last lane of
    /// the previous section's row end, `hi0`/`hi1` the first two voxels of the next section.
    #[test]
    fn edges_are_the_neighbouring_columns() {
        let dims = [24usize, 8, 8];
        let data: Vec<u16> = (0..dims.iter().product::<usize>())
            .map(|n| (n % 4000 + 1) as u16)
            .collect();
        let vol = Volume::new(dims, [1.0; 3], 12, data).unwrap();
        let c = SectionBufConfig {
            p: 2,
            voxel_w: 12,
            max_dim: 32,
            block_dim: 4,
            section: 8,
            item_groups: 1,
        };
        let lut = BlockLut::from_volume(&vol, 4, 0).unwrap();
        let cmd = |a0| SectionCmd {
            axis_k: 2,
            reversed: false,
            dims: [24, 8, 8],
            a0,
        };
        let mid = section_beams(&c, &vol, &lut, &cmd(8)).unwrap();
        // Row (j = 3, k = 5): the first beam of the row has lo = voxel (7, 3, 5).
        let row = (5 * 8 + 3) * 4;
        assert!(mid[row].row_first);
        assert_eq!(mid[row].lo, vol.get(7, 3, 5));
        assert!(mid[row + 3].row_last);
        assert_eq!(mid[row + 3].hi0, vol.get(16, 3, 5));
        assert_eq!(mid[row + 3].hi1, vol.get(17, 3, 5));
        assert_eq!(
            mid[row + 3].lanes,
            vec![vol.get(14, 3, 5), vol.get(15, 3, 5)]
        );
        // The first section has no left column, the last none on the right.
        let first = section_beams(&c, &vol, &lut, &cmd(0)).unwrap();
        let last = section_beams(&c, &vol, &lut, &cmd(16)).unwrap();
        assert!(first.iter().all(|b| b.lo == 0));
        assert!(last.iter().all(|b| b.hi0 == 0 && b.hi1 == 0));
        assert!(mid.iter().any(|b| b.lo != 0) && mid.iter().any(|b| b.hi1 != 0));
    }

    #[test]
    fn refused_sections_answer_one_error_beam_and_stray_inputs_are_dropped() {
        let c = SectionBufConfig::DEFAULT;
        let mut unit = SectionBuf::new(c).unwrap();
        let ok = SectionCmd {
            axis_k: 2,
            reversed: false,
            dims: [32, 16, 16],
            a0: 16,
        };
        for bad in [
            SectionCmd { axis_k: 3, ..ok },
            SectionCmd {
                dims: [32, 6, 16],
                ..ok
            },
            SectionCmd {
                dims: [32, 16, 128],
                ..ok
            },
            SectionCmd { a0: 8, ..ok },
            SectionCmd { a0: 32, ..ok },
        ] {
            assert!(unit.refusal(&bad).is_some(), "{bad:?}");
            let out = unit.run(&[SbufIn::Section(bad)]);
            assert_eq!(out, vec![Beam::error(c.p)]);
        }
        let stray = FetchItem::stray(4);
        assert!(unit.run(&[SbufIn::Item(stray)]).is_empty());
    }

    #[test]
    fn codec_round_trips_the_packing() {
        let c = SectionBufConfig::DEFAULT;
        assert_eq!(c.in_width(), 1 + c.item_w().max(c.cmd_w()));
        assert_eq!(c.out_width(), 7 * 12 + 5);
        let beam = Beam {
            lanes: vec![1, 2, 3, 4095],
            lo: 5,
            hi0: 6,
            hi1: 7,
            row_first: true,
            row_last: false,
            slice_last: true,
            last: false,
            error: true,
        };
        let mut w = BitWriter::new();
        for v in [1u64, 2, 3, 4095, 5, 6, 7] {
            w.put(v, 12);
        }
        for f in [true, false, true, false, true] {
            w.put_bool(f);
        }
        assert_eq!(c.unpack_out(&w.finish(c.out_width())), beam);
        assert_eq!(c.bank_depth(), 2 * 8 * 64 * 16 / 4);
    }
}
