//! The GI-Cube volume cache and miss scheduler (parts F, G, H of docs/gicube-rtl.md; patent
//! [376]-[378]), written from `docs/numerics/gicube_cache.md`: a request is one sample's cell,
//! the eight corners lie in eight banks by parity `(x & 1, y & 1, z & 1)`, each bank a
//! direct-mapped cache of `Sets` lines with its own tags; the misses of a request are read as one
//! AXI4 INCR burst per line, in ascending bank order; out come the eight voxels in corner order,
//! which banks hit, and the running hit and miss counts.
//!
//! It is order-dependent (a hit depends on what earlier requests loaded), so [`VolumeCache`] is
//! stepped one request at a time, as the RTL checks its tags one request at a time; the memory's
//! timing changes only the cycles (`stall`), which the contract pins by an identity the
//! co-simulation checks, not the values.

use rand::Rng;

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::{StreamCodec, StreamUnit};
use crate::units::cube5_axi_rd::{AxiMemImage, AxiRdConfig, Burst};

/// Cycles from taking a request that hits to its output (contract, *Cycles*), `Prefetch = 0`.
pub const HIT_LATENCY: u64 = 2;
/// ... with `Prefetch > 0` (contract, *Prefetch*): take, check, queue, data read.
pub const PREFETCH_HIT_LATENCY: u64 = 4;
/// Largest `Prefetch`: entries of the prefetch queue.
pub const MAX_PREFETCH: u32 = 8;
/// Bits of the running counts `hits`, `misses` in the output item.
pub const COUNT_W: u32 = 32;
/// Bits of the output item's `stall` (saturating).
pub const STALL_W: u32 = 16;
/// Widest irradiance field: `U(2.14)` ([352]).
pub const IRR_MAX_W: u32 = 16;
/// Bits of an item's operation (`Splat = 1`): 0 read, 1 deposit, 2 or 3 flush.
pub const OP_W: u32 = 2;

/// One configuration of the RTL top `gicube_cache`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CacheConfig {
    /// The volume's edge in memory, `M` (a power of two, 4..=1024).
    pub max_dim: u32,
    /// Bits of a voxel word (8, 16 or 32).
    pub word_w: u32,
    /// AXI4 data bus bits (a power of two, 32..=256, at least `2 WordW`).
    pub data_w: u32,
    /// Voxels of a cache line (a power of two).
    pub line_vox: u32,
    /// Lines per bank (a power of two, 2..=4096).
    pub sets: u32,
    /// Line reads in flight at most (a power of two, 2..=8).
    pub outstanding: u32,
    /// Byte address width (13..=64).
    pub addr_w: u32,
    /// 1: the splatting side (deposits, dirty lines, write-back, flush; contract, *Splatting*);
    /// 0: the read-only cache.
    pub splat: u32,
    /// Requests checked ahead of the data read (contract, *Prefetch*): 0 the blocking unit,
    /// 1..=8 the prefetch queue's entries (with `Splat`: *Prefetch with splatting*). Changes
    /// only the cycles.
    pub prefetch: u32,
}

impl CacheConfig {
    /// The RTL's parameter defaults.
    pub const DEFAULT: Self = Self {
        max_dim: 64,
        word_w: 16,
        data_w: 64,
        line_vox: 16,
        sets: 32,
        outstanding: 8,
        addr_w: 32,
        splat: 0,
        prefetch: 0,
    };

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(ModelError::Config(format!("gicube_cache: {m}")));
        let pow2 = |v: u32| v.is_power_of_two();
        if !(4..=1024).contains(&self.max_dim) || !pow2(self.max_dim) {
            return bad(format!(
                "MaxDim {} is not a power of two in 4..=1024",
                self.max_dim
            ));
        }
        if ![8, 16, 32].contains(&self.word_w) {
            return bad(format!("WordW {} is not 8, 16 or 32", self.word_w));
        }
        if !(32..=256).contains(&self.data_w) || !pow2(self.data_w) || self.data_w < 2 * self.word_w
        {
            return bad(format!(
                "DataW {} is not a power of two in 32..=256 at least 2 WordW",
                self.data_w
            ));
        }
        if !pow2(self.line_vox) || self.line_vox < self.per_beat() {
            return bad(format!(
                "LineVox {} is not a power of two of whole beats",
                self.line_vox
            ));
        }
        if !(2..=256).contains(&self.bpl()) || self.line_bytes() > 4096 {
            return bad(format!(
                "a line of {} beats ({} bytes): need 2..=256 beats, at most 4096 bytes",
                self.bpl(),
                self.line_bytes()
            ));
        }
        if !(2..=4096).contains(&self.sets) || !pow2(self.sets) {
            return bad(format!(
                "Sets {} is not a power of two in 2..=4096",
                self.sets
            ));
        }
        if u64::from(self.sets) * u64::from(self.line_vox) > self.bank_voxels() {
            return bad(format!(
                "Sets {} x LineVox {} exceed a bank's {} voxels",
                self.sets,
                self.line_vox,
                self.bank_voxels()
            ));
        }
        if !(2..=8).contains(&self.outstanding) || !pow2(self.outstanding) {
            return bad(format!(
                "Outstanding {} is not a power of two in 2..=8",
                self.outstanding
            ));
        }
        let need = 64 - (self.volume_bytes() - 1).leading_zeros();
        if !(13..=64).contains(&self.addr_w) || self.addr_w < need {
            return bad(format!(
                "AddrW {} outside {}..=64 (the volume's {} bytes at 0)",
                self.addr_w,
                need.max(13),
                self.volume_bytes()
            ));
        }
        if self.splat > 1 {
            return bad(format!("Splat {} is not 0 or 1", self.splat));
        }
        if self.prefetch > MAX_PREFETCH {
            return bad(format!(
                "Prefetch {} outside 0..={MAX_PREFETCH}",
                self.prefetch
            ));
        }
        Ok(())
    }

    /// Bits of the irradiance field, the word's top `min(WordW, 16)` bits (contract,
    /// *Splatting*).
    pub fn irr_w(&self) -> u32 {
        self.word_w.min(IRR_MAX_W)
    }

    /// The irradiance field's lowest bit in the word.
    pub fn irr_shift(&self) -> u32 {
        self.word_w - self.irr_w()
    }

    /// Bits of a request's operation and energies in the input item (0 without `Splat`).
    fn splat_in_w(&self) -> u32 {
        if self.splat == 1 {
            OP_W + 8 * self.irr_w()
        } else {
            0
        }
    }

    /// Cycles from taking a request that hits to its output (contract, *Cycles*, *Prefetch*).
    pub fn hit_latency(&self) -> u64 {
        if self.prefetch == 0 {
            HIT_LATENCY
        } else {
            PREFETCH_HIT_LATENCY
        }
    }

    /// Requests the unit holds at most (taken, not yet out of its output register): the
    /// blocking unit's check and output; with `Prefetch`, the check, the queue, the data read and
    /// the output. A consumer that keeps a record per request sizes its FIFO by this.
    pub fn held_max(&self) -> u32 {
        if self.prefetch == 0 {
            2
        } else {
            self.prefetch + 3
        }
    }

    /// `m = log2 M`: bits of a coordinate.
    pub fn coord_w(&self) -> u32 {
        self.max_dim.trailing_zeros()
    }

    /// `H = M / 2`: a bank's edge.
    pub fn half(&self) -> u32 {
        self.max_dim / 2
    }

    /// Voxels of one bank's sub-volume, `H^3`.
    pub fn bank_voxels(&self) -> u64 {
        u64::from(self.half()).pow(3)
    }

    /// Bytes of the volume in memory, `M^3 WordW / 8`.
    pub fn volume_bytes(&self) -> u64 {
        u64::from(self.max_dim).pow(3) * u64::from(self.word_w / 8)
    }

    /// `V = DataW / WordW`: voxels per beat.
    pub fn per_beat(&self) -> u32 {
        self.data_w / self.word_w
    }

    /// `BPL = LineVox / V`: beats per line.
    pub fn bpl(&self) -> u32 {
        self.line_vox / self.per_beat()
    }

    /// Bytes of a line.
    pub fn line_bytes(&self) -> u32 {
        self.line_vox * self.word_w / 8
    }

    /// Bits of a line number within a bank, `3 (m - 1) - log2 LineVox`.
    pub fn line_w(&self) -> u32 {
        3 * (self.coord_w() - 1) - self.line_vox.trailing_zeros()
    }

    /// `s = log2 Sets`.
    pub fn set_w(&self) -> u32 {
        self.sets.trailing_zeros()
    }

    /// `TagW = max(1, line bits - s)`.
    pub fn tag_w(&self) -> u32 {
        self.line_w().saturating_sub(self.set_w()).max(1)
    }

    /// The read unit behind the miss scheduler: one burst of `BPL` beats per line.
    pub fn axi_rd(&self) -> AxiRdConfig {
        AxiRdConfig {
            addr_w: self.addr_w,
            data_w: self.data_w,
            len_w: self.bpl().trailing_zeros() + 1,
            max_burst: self.bpl(),
            outstanding: self.outstanding,
            id_w: 4,
        }
    }

    /// Bank index (sub-volume, x fastest) of bank coordinates `b`.
    fn bank_index(&self, b: [u32; 3]) -> u64 {
        let h = u64::from(self.half());
        u64::from(b[0]) + h * (u64::from(b[1]) + h * u64::from(b[2]))
    }

    /// Word index in memory of voxel `v` (contract, *The volume in memory*).
    pub fn word_index(&self, v: [u32; 3]) -> u64 {
        let p = (v[0] & 1) | (v[1] & 1) << 1 | (v[2] & 1) << 2;
        u64::from(p) * self.bank_voxels() + self.bank_index(v.map(|a| a >> 1))
    }

    /// Byte address of line `l` of bank `p`.
    pub fn line_addr(&self, p: u32, l: u64) -> u64 {
        (u64::from(p) * self.bank_voxels() + l * u64::from(self.line_vox))
            * u64::from(self.word_w / 8)
    }

    /// The line, set and tag of the corner in bank `p` of the cell at `base` (contract, *Tags*):
    /// per axis the corner `a` or `a + 1` of bank `p`'s parity, wrapped, halved; the line's low
    /// bits folded with its tag's for the set.
    pub fn slot(&self, p: u32, base: [u32; 3]) -> (u64, usize, u64) {
        let mask = self.max_dim - 1;
        let b: [u32; 3] = std::array::from_fn(|a| {
            let pa = (p >> a) & 1;
            ((base[a] + ((base[a] & 1) ^ pa)) & mask) >> 1
        });
        let line = self.bank_index(b) >> self.line_vox.trailing_zeros();
        let tag = line >> self.set_w();
        let set = ((line ^ tag) & u64::from(self.sets - 1)) as usize;
        (line, set, tag)
    }

    /// The memory image of a volume of `M^3` words (x fastest), at byte address 0.
    pub fn image(&self, words: &[u32]) -> Result<AxiMemImage> {
        let m = self.max_dim as usize;
        if words.len() != m * m * m {
            return Err(ModelError::Config(format!(
                "gicube_cache: a volume of {} words for MaxDim {m} (need {})",
                words.len(),
                m * m * m
            )));
        }
        let wb = (self.word_w / 8) as usize;
        let mut bytes = vec![0u8; self.volume_bytes() as usize];
        for (i, &w) in words.iter().enumerate() {
            let v = [i % m, (i / m) % m, i / (m * m)].map(|a| a as u32);
            let at = self.word_index(v) as usize * wb;
            bytes[at..at + wb].copy_from_slice(&w.to_le_bytes()[..wb]);
        }
        Ok(AxiMemImage {
            base: 0,
            bytes,
            slverr_lo: 0,
            slverr_hi: 0,
        })
    }
}

impl CacheConfig {
    /// The volume's `M^3` words (x fastest) in a memory image's bytes at address 0 (the inverse of
    /// [`CacheConfig::image`]); bytes missing read as 0.
    pub fn words_of(&self, bytes: &[u8]) -> Vec<u32> {
        let m = self.max_dim as usize;
        let wb = (self.word_w / 8) as usize;
        (0..m * m * m)
            .map(|i| {
                let v = [i % m, (i / m) % m, i / (m * m)].map(|a| a as u32);
                let at = self.word_index(v) as usize * wb;
                (0..wb).fold(0u32, |w, k| {
                    w | u32::from(bytes.get(at + k).copied().unwrap_or(0)) << (8 * k)
                })
            })
            .collect()
    }
}

crate::unit_config!(CacheConfig, "gicube_cache", DEFAULT, {
    "MaxDim" => max_dim,
    "WordW" => word_w,
    "DataW" => data_w,
    "LineVox" => line_vox,
    "Sets" => sets,
    "Outstanding" => outstanding,
    "AddrW" => addr_w,
    "Splat" => splat,
    "Prefetch" => prefetch,
});

/// One request: the cell whose lowest voxel is `(x, y, z)` (taken modulo `M`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CacheReq {
    pub x: u32,
    pub y: u32,
    pub z: u32,
}

/// One output item (contract, *A request and what comes out*).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CacheOut {
    /// The corner voxels, corner `c = cx + 2 cy + 4 cz`.
    pub vox: [u32; 8],
    /// Bit `p`: bank `p`'s line was in the cache at the tag check.
    pub hit: u8,
    /// Corner reads found and not found since reset (modulo `2^32`).
    pub hits: u32,
    pub misses: u32,
    /// The request's stall cycles (memory timing: 0 from the model, which predicts it only as 0
    /// for a request that hits in all eight banks).
    pub stall: u32,
}

/// What one request did: its output and the bursts of its misses, in issue order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CacheStep {
    pub out: CacheOut,
    pub bursts: Vec<Burst>,
}

/// One item of a `Splat = 1` configuration (contract, *Splatting*): a read (as [`CacheReq`]), a
/// deposit of eight corner energies (`IrrW` bits each, corner `c = cx + 2 cy + 4 cz`) into the
/// cell's irradiance fields, or a flush of every dirty line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CacheItem {
    Read(CacheReq),
    Deposit(CacheReq, [u32; 8]),
    Flush,
}

/// What one item did: its output, the lines it read (AR, in issue order) and the lines it wrote
/// back (AW, in issue order).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ItemStep {
    pub out: CacheOut,
    pub reads: Vec<Burst>,
    pub writes: Vec<Burst>,
}

/// The golden model of `gicube_cache`: tags, valid and dirty bits and counts, stepped per item,
/// over a volume of `M^3` words: what the cache and memory hold together (`words`, which reads
/// return) and what memory holds (`mem`: a dirty line's words differ until it is written back).
#[derive(Debug, Clone)]
pub struct VolumeCache {
    cfg: CacheConfig,
    words: Vec<u32>,
    mem: Vec<u32>,
    /// Per bank and set (`8 set + p`): the tag of the line held, `None` when invalid.
    tags: Vec<Option<u64>>,
    /// Per bank and set: the line holds deposits not yet written back.
    dirty: Vec<bool>,
    hits: u32,
    misses: u32,
}

impl VolumeCache {
    /// The cache after reset over `words` (`M^3`, x fastest; each masked to `WordW` bits).
    pub fn new(cfg: CacheConfig, words: &[u32]) -> Result<Self> {
        cfg.validate()?;
        let m = cfg.max_dim as usize;
        if words.len() != m * m * m {
            return Err(ModelError::Config(format!(
                "gicube_cache: a volume of {} words for MaxDim {m}",
                words.len()
            )));
        }
        let mask = word_mask(cfg.word_w);
        let words: Vec<u32> = words.iter().map(|w| w & mask).collect();
        Ok(Self {
            cfg,
            mem: words.clone(),
            words,
            tags: vec![None; 8 * cfg.sets as usize],
            dirty: vec![false; 8 * cfg.sets as usize],
            hits: 0,
            misses: 0,
        })
    }

    pub fn config(&self) -> CacheConfig {
        self.cfg
    }

    /// Corner reads found in the cache since reset.
    pub fn hits(&self) -> u32 {
        self.hits
    }

    /// Corner reads not found since reset.
    pub fn misses(&self) -> u32 {
        self.misses
    }

    fn at(&self, v: [u32; 3]) -> usize {
        let m = self.cfg.max_dim as usize;
        v[0] as usize + m * (v[1] as usize + m * v[2] as usize)
    }

    /// The voxel word at `v` (coordinates `< M`): what a read returns.
    pub fn voxel(&self, v: [u32; 3]) -> u32 {
        self.words[self.at(v)]
    }

    /// The words memory holds (`M^3`, x fastest): the volume with every written-back deposit.
    pub fn memory_words(&self) -> &[u32] {
        &self.mem
    }

    /// Lines holding deposits not yet written back.
    pub fn dirty_lines(&self) -> usize {
        self.dirty.iter().filter(|d| **d).count()
    }

    /// One request: the tag check of its eight banks (allocating the misses), its output and the
    /// bursts of its misses in ascending bank order.
    pub fn request(&mut self, req: &CacheReq) -> CacheStep {
        let s = self.item(&CacheItem::Read(*req));
        CacheStep {
            out: s.out,
            bursts: s.reads,
        }
    }

    /// Every request of `reqs`: the outputs and all bursts, in order.
    pub fn run_all(&mut self, reqs: &[CacheReq]) -> (Vec<CacheOut>, Vec<Burst>) {
        let mut outs = Vec::with_capacity(reqs.len());
        let mut bursts = Vec::new();
        for r in reqs {
            let s = self.request(r);
            outs.push(s.out);
            bursts.extend(s.bursts);
        }
        (outs, bursts)
    }

    /// Every item of `items`: the outputs, all reads and all write-backs, in order.
    pub fn run_items(&mut self, items: &[CacheItem]) -> (Vec<CacheOut>, Vec<Burst>, Vec<Burst>) {
        let mut outs = Vec::with_capacity(items.len());
        let (mut reads, mut writes) = (Vec::new(), Vec::new());
        for it in items {
            let s = self.item(it);
            outs.push(s.out);
            reads.extend(s.reads);
            writes.extend(s.writes);
        }
        (outs, reads, writes)
    }

    /// Writes line `line` of bank `p` back: its words into memory, its burst.
    fn write_back(&mut self, p: u32, line: u64) -> Burst {
        let cfg = self.cfg;
        let h = u64::from(cfg.half());
        for k in 0..u64::from(cfg.line_vox) {
            let i = line * u64::from(cfg.line_vox) + k;
            let b = [i % h, (i / h) % h, i / (h * h)];
            let v: [u32; 3] = std::array::from_fn(|a| (2 * b[a]) as u32 | ((p >> a) & 1));
            let at = self.at(v);
            self.mem[at] = self.words[at];
        }
        Burst {
            addr: cfg.line_addr(p, line),
            beats: cfg.bpl(),
        }
    }

    /// The line that set `set` holds under `tag` (`l mod Sets = set xor (t mod Sets)`).
    fn line_of(&self, set: usize, tag: u64) -> u64 {
        let sets = u64::from(self.cfg.sets);
        tag * sets + ((set as u64 ^ tag) & (sets - 1))
    }

    /// One item (contract, *Splatting*): a read or a deposit checks its eight banks in order,
    /// writing back each dirty line it evicts and reading each line it misses; a deposit then adds
    /// its energies into the corners' irradiance fields (saturating) and marks the eight lines
    /// dirty; a flush writes back every dirty line, bank by bank, set by set.
    pub fn item(&mut self, item: &CacheItem) -> ItemStep {
        let cfg = self.cfg;
        let (req, energies) = match *item {
            CacheItem::Read(r) => (r, None),
            CacheItem::Deposit(r, e) => (r, Some(e)),
            CacheItem::Flush => {
                let mut writes = Vec::new();
                for p in 0..8u32 {
                    for set in 0..cfg.sets as usize {
                        let k = 8 * set + p as usize;
                        if self.dirty[k] {
                            let tag = self.tags[k].expect("a dirty line is valid");
                            let line = self.line_of(set, tag);
                            writes.push(self.write_back(p, line));
                            self.dirty[k] = false;
                        }
                    }
                }
                return ItemStep {
                    out: CacheOut {
                        hits: self.hits,
                        misses: self.misses,
                        ..CacheOut::default()
                    },
                    reads: Vec::new(),
                    writes,
                };
            }
        };
        let mask = cfg.max_dim - 1;
        let base = [req.x, req.y, req.z].map(|a| a & mask);
        let mut hit = 0u8;
        let (mut reads, mut writes) = (Vec::new(), Vec::new());
        for p in 0..8u32 {
            let (line, set, tag) = cfg.slot(p, base);
            let k = 8 * set + p as usize;
            if self.tags[k] == Some(tag) {
                hit |= 1 << p;
                self.hits = self.hits.wrapping_add(1);
            } else {
                if self.dirty[k] {
                    let victim = self.line_of(set, self.tags[k].expect("a dirty line is valid"));
                    writes.push(self.write_back(p, victim));
                    self.dirty[k] = false;
                }
                self.tags[k] = Some(tag);
                self.misses = self.misses.wrapping_add(1);
                reads.push(Burst {
                    addr: cfg.line_addr(p, line),
                    beats: cfg.bpl(),
                });
            }
        }
        let corner = |c: usize| -> [u32; 3] {
            std::array::from_fn(|a| (base[a] + ((c as u32 >> a) & 1)) & mask)
        };
        if let Some(e) = energies {
            let (w, shift) = (cfg.irr_w(), cfg.irr_shift());
            let top = word_mask(w);
            for (c, &ec) in e.iter().enumerate() {
                let at = self.at(corner(c));
                let word = self.words[at];
                let sum = ((word >> shift) + (ec & top)).min(top);
                self.words[at] = (word & word_mask(shift)) | sum << shift;
            }
            for p in 0..8u32 {
                let (_, set, _) = cfg.slot(p, base);
                self.dirty[8 * set + p as usize] = true;
            }
        }
        let vox = std::array::from_fn(|c| self.voxel(corner(c)));
        ItemStep {
            out: CacheOut {
                vox,
                hit,
                hits: self.hits,
                misses: self.misses,
                stall: 0,
            },
            reads,
            writes,
        }
    }

    /// Reset: every set invalid and clean (deposits not written back are lost: reads return
    /// memory's words again), the counts 0.
    pub fn clear(&mut self) {
        self.tags.fill(None);
        self.dirty.fill(false);
        self.words.clone_from(&self.mem);
        self.hits = 0;
        self.misses = 0;
    }
}

/// The low `w` bits (`w <= 32`).
fn word_mask(w: u32) -> u32 {
    if w >= 32 {
        u32::MAX
    } else {
        (1 << w) - 1
    }
}

impl StreamUnit for VolumeCache {
    type In = CacheReq;
    type Out = CacheOut;

    fn run(&mut self, inputs: &[CacheReq]) -> Vec<CacheOut> {
        inputs.iter().map(|r| self.request(r).out).collect()
    }

    fn reset(&mut self) {
        self.clear();
    }
}

impl StreamCodec for CacheConfig {
    type In = CacheReq;
    type Out = CacheOut;

    /// x, y, z (`m` bits each), LSB first; with `Splat`, then op (2) and eight energies (`IrrW`
    /// each), zero for a read.
    fn in_width(&self) -> u32 {
        3 * self.coord_w() + self.splat_in_w()
    }

    /// vox[0..8] (`WordW` each), hit (8), hits (32), misses (32), stall (16), LSB first.
    fn out_width(&self) -> u32 {
        8 * self.word_w + 8 + 2 * COUNT_W + STALL_W
    }

    fn pack_in(&self, r: &CacheReq) -> Vec<u32> {
        SplatCodec(*self).pack_in(&CacheItem::Read(*r))
    }

    fn unpack_out(&self, words: &[u32]) -> CacheOut {
        let mut r = BitReader::new(words);
        let vox = std::array::from_fn(|_| r.get(self.word_w) as u32);
        CacheOut {
            vox,
            hit: r.get(8) as u8,
            hits: r.get(COUNT_W) as u32,
            misses: r.get(COUNT_W) as u32,
            stall: r.get(STALL_W) as u32,
        }
    }
}

/// The codec of a `Splat = 1` configuration's items ([`CacheItem`]: reads, deposits, flushes);
/// the output item is [`CacheOut`] as for a read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SplatCodec(pub CacheConfig);

impl StreamCodec for SplatCodec {
    type In = CacheItem;
    type Out = CacheOut;

    fn in_width(&self) -> u32 {
        self.0.in_width()
    }

    fn out_width(&self) -> u32 {
        self.0.out_width()
    }

    /// x, y, z (`m` bits each), then with `Splat` op (2: 0 read, 1 deposit, 2 flush) and the
    /// energies `e[0..8]` (`IrrW` bits each, zero unless a deposit), LSB first.
    fn pack_in(&self, item: &CacheItem) -> Vec<u32> {
        let cfg = self.0;
        let m = cfg.coord_w();
        let mask = u64::from(cfg.max_dim - 1);
        let (r, op, e) = match *item {
            CacheItem::Read(r) => (r, 0, [0; 8]),
            CacheItem::Deposit(r, e) => (r, 1, e),
            CacheItem::Flush => (CacheReq::default(), 2, [0; 8]),
        };
        let mut w = BitWriter::new();
        w.put(u64::from(r.x) & mask, m)
            .put(u64::from(r.y) & mask, m)
            .put(u64::from(r.z) & mask, m);
        if cfg.splat == 1 {
            w.put(op, OP_W);
            for ec in e {
                w.put(u64::from(ec & word_mask(cfg.irr_w())), cfg.irr_w());
            }
        }
        w.finish(cfg.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> CacheOut {
        self.0.unpack_out(words)
    }
}

/// Random request streams with the locality of rays: runs along a random direction (steps of
/// under one voxel: most requests hit), jumps to random cells (misses), a cell repeated, and
/// runs that alternate between two cells of one set (conflicts).
#[derive(Debug, Clone)]
pub struct CacheTraffic {
    cfg: CacheConfig,
    /// The walk's position and step, `U(.8)` voxels.
    pos: [i64; 3],
    step: [i64; 3],
    left: u32,
    kind: u32,
    other: CacheReq,
}

impl CacheTraffic {
    pub fn new(cfg: CacheConfig) -> Self {
        Self {
            cfg,
            pos: [0; 3],
            step: [0; 3],
            left: 0,
            kind: 0,
            other: CacheReq::default(),
        }
    }

    fn random_cell(&self, rng: &mut impl Rng) -> CacheReq {
        let m = self.cfg.max_dim;
        CacheReq {
            x: rng.random_range(0..m),
            y: rng.random_range(0..m),
            z: rng.random_range(0..m),
        }
    }

    /// A cell whose corners fall in the same set as `r`'s in every bank, with other tags: the
    /// first of `r` moved by `(0, 2 dy, 2 dz)` (parities kept) that does so, if any.
    pub fn conflicting(&self, r: CacheReq) -> Option<CacheReq> {
        let cfg = self.cfg;
        let m = cfg.max_dim;
        let base = [r.x, r.y, r.z].map(|a| a & (m - 1));
        let slots: Vec<_> = (0..8).map(|p| cfg.slot(p, base)).collect();
        (1..cfg.half())
            .flat_map(|dz| (0..cfg.half()).map(move |dy| (dy, dz)))
            .map(|(dy, dz)| [base[0], (base[1] + 2 * dy) % m, (base[2] + 2 * dz) % m])
            .find(|c| {
                (0..8).all(|p| {
                    let (_, set, tag) = cfg.slot(p, *c);
                    let (_, s0, t0) = slots[p as usize];
                    set == s0 && tag != t0
                })
            })
            .map(|[x, y, z]| CacheReq { x, y, z })
    }

    pub fn next_item(&mut self, rng: &mut impl Rng) -> CacheReq {
        let m = i64::from(self.cfg.max_dim) << 8;
        if self.left == 0 {
            self.kind = rng.random_range(0..10);
            self.left = rng.random_range(1..=200);
            let c = self.random_cell(rng);
            self.pos = [c.x, c.y, c.z].map(|a| i64::from(a) << 8);
            self.step = std::array::from_fn(|_| rng.random_range(-256..=256));
            self.other = self.conflicting(c).unwrap_or(c);
        }
        self.left -= 1;
        match self.kind {
            // Jumps: every request a random cell.
            0 => self.random_cell(rng),
            // Two cells of one set in turn.
            1 => {
                let c = self.other;
                self.other = CacheReq {
                    x: (self.pos[0] >> 8) as u32,
                    y: (self.pos[1] >> 8) as u32,
                    z: (self.pos[2] >> 8) as u32,
                };
                self.pos = [c.x, c.y, c.z].map(|a| i64::from(a) << 8);
                c
            }
            // A ray: steps of under a voxel per axis, wrapping.
            _ => {
                for a in 0..3 {
                    self.pos[a] = (self.pos[a] + self.step[a]).rem_euclid(m);
                }
                let [x, y, z] = self.pos.map(|p| (p >> 8) as u32);
                CacheReq { x, y, z }
            }
        }
    }

    /// `n` requests.
    pub fn items(&mut self, rng: &mut impl Rng, n: usize) -> Vec<CacheReq> {
        (0..n).map(|_| self.next_item(rng)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    const SMALL: CacheConfig = CacheConfig {
        max_dim: 16,
        word_w: 16,
        data_w: 32,
        line_vox: 4,
        sets: 4,
        outstanding: 2,
        addr_w: 16,
        splat: 0,
        prefetch: 0,
    };

    fn ramp(cfg: CacheConfig) -> Vec<u32> {
        let n = (cfg.max_dim as usize).pow(3);
        (0..n as u32)
            .map(|i| i.wrapping_mul(2_654_435_761) >> 7)
            .collect()
    }

    #[test]
    fn the_defaults_and_the_small_configuration_are_valid() {
        CacheConfig::DEFAULT.validate().unwrap();
        SMALL.validate().unwrap();
        assert_eq!(SMALL.bpl(), 2);
        assert_eq!(SMALL.line_w(), 7);
        assert_eq!(SMALL.tag_w(), 5);
        let bad = [
            CacheConfig {
                max_dim: 12,
                ..SMALL
            },
            CacheConfig {
                word_w: 12,
                ..SMALL
            },
            CacheConfig {
                line_vox: 2,
                ..SMALL
            },
            CacheConfig {
                sets: 1024,
                ..SMALL
            },
            CacheConfig {
                addr_w: 12,
                ..SMALL
            },
            CacheConfig {
                outstanding: 16,
                ..SMALL
            },
            CacheConfig {
                prefetch: 9,
                ..SMALL
            },
        ];
        CacheConfig {
            prefetch: 8,
            ..SMALL
        }
        .validate()
        .unwrap();
        // Prefetch with Splat (contract, *Prefetch with splatting*).
        CacheConfig {
            prefetch: 2,
            splat: 1,
            ..SMALL
        }
        .validate()
        .unwrap();
        for c in bad {
            assert!(c.validate().is_err(), "{c:?}");
        }
    }

    #[test]
    fn the_layout_puts_each_voxel_once_and_the_corners_in_eight_banks() {
        let cfg = SMALL;
        let m = cfg.max_dim;
        let mut seen = vec![false; (m * m * m) as usize];
        for z in 0..m {
            for y in 0..m {
                for x in 0..m {
                    let i = cfg.word_index([x, y, z]) as usize;
                    assert!(!seen[i]);
                    seen[i] = true;
                }
            }
        }
        // The image holds each word at its index, little-endian.
        let words = ramp(cfg);
        let img = cfg.image(&words).unwrap();
        let v = [5, 6, 7];
        let at = 2 * cfg.word_index(v) as usize;
        let w = u32::from(img.bytes[at]) | u32::from(img.bytes[at + 1]) << 8;
        assert_eq!(w, words[5 + 16 * (6 + 16 * 7)] & 0xffff);
    }

    #[test]
    fn a_cold_request_misses_eight_lines_then_hits() {
        let cfg = SMALL;
        let words = ramp(cfg);
        let mut c = VolumeCache::new(cfg, &words).unwrap();
        let r = CacheReq { x: 3, y: 8, z: 15 };
        let s = c.request(&r);
        assert_eq!(s.out.hit, 0);
        assert_eq!((s.out.hits, s.out.misses), (0, 8));
        assert_eq!(s.bursts.len(), 8);
        // One burst per bank, ascending, each a line of its bank's sub-volume.
        for (p, b) in s.bursts.iter().enumerate() {
            let bank_bytes = cfg.bank_voxels() * 2;
            assert_eq!(b.addr / bank_bytes, p as u64);
            assert_eq!(b.addr % u64::from(cfg.line_bytes()), 0);
            assert_eq!(b.beats, 2);
        }
        // Corners wrap: z + 1 = 16 is z = 0.
        assert_eq!(s.out.vox[4], c.voxel([3, 8, 0]));
        assert_eq!(s.out.vox[7], c.voxel([4, 9, 0]));
        let s2 = c.request(&r);
        assert_eq!((s2.out.hit, s2.out.hits, s2.out.misses), (0xff, 8, 8));
        assert!(s2.bursts.is_empty());
        assert_eq!(s.out.vox, s2.out.vox);
        // Four cells on, the even banks' line ends (bank x 4 is the next line), the odd banks'
        // does not.
        let s3 = c.request(&CacheReq { x: 7, y: 8, z: 15 });
        assert_eq!(s3.out.hit, 0xaa);
        assert_ne!(s3.out.hit, 0xff);
        assert!(s3.out.hit != 0);
    }

    #[test]
    fn the_set_folds_the_tag_so_a_set_and_a_tag_name_one_line() {
        let cfg = SMALL;
        let mut seen = std::collections::HashSet::new();
        let h = cfg.half();
        for bz in 0..h {
            for by in 0..h {
                for bx in (0..h).step_by(cfg.line_vox as usize) {
                    let (line, set, tag) = cfg.slot(0, [2 * bx, 2 * by, 2 * bz]);
                    assert!(seen.insert((set, tag)), "line {line}");
                    assert_eq!(set as u64, (line ^ tag) % u64::from(cfg.sets));
                }
            }
        }
        // Lines `Sets` apart (rows two apart here) meet in other sets: the tag's low bits differ.
        let (l0, s0, _) = cfg.slot(0, [0, 0, 0]);
        let (l1, s1, _) = cfg.slot(0, [0, 4, 0]);
        assert_eq!(l1 - l0, u64::from(cfg.sets));
        assert_eq!((s0, s1), (0, 1));
    }

    #[test]
    fn two_cells_of_one_set_evict_each_other() {
        let cfg = SMALL;
        let mut c = VolumeCache::new(cfg, &ramp(cfg)).unwrap();
        let t = CacheTraffic::new(cfg);
        let a = CacheReq { x: 2, y: 4, z: 6 };
        let b = t.conflicting(a).unwrap();
        for _ in 0..4 {
            assert_eq!(c.request(&a).out.hit, 0);
            assert_eq!(c.request(&b).out.hit, 0);
        }
        c.clear();
        assert_eq!((c.hits(), c.misses()), (0, 0));
        assert_eq!(c.request(&a).out.hit, 0);
    }

    #[test]
    fn the_voxels_are_the_corners_whatever_the_history() {
        let cfg = CacheConfig::DEFAULT;
        let words = ramp(cfg);
        let mut c = VolumeCache::new(cfg, &words).unwrap();
        let mut t = CacheTraffic::new(cfg);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let reqs = t.items(&mut rng, 20_000);
        let (outs, bursts) = c.run_all(&reqs);
        let m = cfg.max_dim;
        for (r, o) in reqs.iter().zip(&outs) {
            for (k, &v) in o.vox.iter().enumerate() {
                let k = k as u32;
                let at = [r.x + (k & 1), r.y + (k >> 1 & 1), r.z + (k >> 2 & 1)].map(|a| a % m);
                assert_eq!(
                    v,
                    words[(at[0] + m * (at[1] + m * at[2])) as usize] & 0xffff
                );
            }
        }
        let last = outs.last().unwrap();
        assert_eq!(u64::from(last.misses), bursts.len() as u64);
        assert_eq!(u64::from(last.hits + last.misses), 8 * reqs.len() as u64);
        // Ray-like traffic mostly hits.
        let rate = f64::from(last.hits) / f64::from(last.hits + last.misses);
        assert!(rate > 0.3, "hit rate {rate}");
    }

    #[test]
    fn the_codec_round_trips_the_output() {
        let cfg = SMALL;
        let o = CacheOut {
            vox: [1, 2, 3, 4, 0xffff, 6, 7, 8],
            hit: 0xa5,
            hits: 0xdead_beef,
            misses: 7,
            stall: 0xffff,
        };
        let mut w = BitWriter::new();
        for v in o.vox {
            w.put(u64::from(v), 16);
        }
        w.put(0xa5, 8)
            .put(0xdead_beef, 32)
            .put(7, 32)
            .put(0xffff, 16);
        assert_eq!(cfg.unpack_out(&w.finish(cfg.out_width())), o);
        assert_eq!(
            cfg.pack_in(&CacheReq { x: 1, y: 2, z: 3 }),
            vec![1 | 2 << 4 | 3 << 8]
        );
    }

    const SPLAT: CacheConfig = CacheConfig {
        max_dim: 8,
        word_w: 32,
        data_w: 64,
        line_vox: 4,
        sets: 4,
        outstanding: 2,
        addr_w: 13,
        splat: 1,
        prefetch: 0,
    };

    #[test]
    fn a_deposit_adds_into_the_top_half_saturating_and_memory_changes_at_the_write_back() {
        let cfg = SPLAT;
        cfg.validate().unwrap();
        assert_eq!((cfg.irr_w(), cfg.irr_shift()), (16, 16));
        let words = ramp(cfg);
        let mut c = VolumeCache::new(cfg, &words).unwrap();
        let a = CacheReq { x: 2, y: 4, z: 6 };
        let before = c.request(&a).out.vox;
        let e = [1, 2, 3, 4, 5, 6, 7, 0xffff];
        let s = c.item(&CacheItem::Deposit(a, e));
        assert_eq!(s.out.hit, 0xff);
        assert!(s.reads.is_empty() && s.writes.is_empty());
        for k in 0..8 {
            let f = ((before[k] >> 16) + e[k]).min(0xffff);
            assert_eq!(s.out.vox[k], f << 16 | (before[k] & 0xffff), "corner {k}");
        }
        assert_eq!(c.dirty_lines(), 8);
        // Memory is unchanged until the flush writes the eight lines back, bank by bank.
        assert_eq!(c.memory_words(), &words[..]);
        let f = c.item(&CacheItem::Flush);
        assert_eq!(f.writes.len(), 8);
        assert!(f.writes.windows(2).all(|w| w[0].addr < w[1].addr));
        assert_eq!(f.out.vox, [0; 8]);
        assert_eq!((f.out.hits, f.out.misses), (8, 8));
        assert_eq!(c.dirty_lines(), 0);
        let m = cfg.max_dim;
        let at = |v: [u32; 3]| (v[0] + m * (v[1] + m * v[2])) as usize;
        assert_eq!(c.memory_words()[at([2, 4, 6])], s.out.vox[0]);
        assert_eq!(c.memory_words()[at([3, 5, 7])], s.out.vox[7]);
        assert!(c.item(&CacheItem::Flush).writes.is_empty());
    }

    #[test]
    fn an_evicted_dirty_line_is_written_back_before_the_reads_and_read_again_later() {
        let cfg = SPLAT;
        let words = ramp(cfg);
        let mut c = VolumeCache::new(cfg, &words).unwrap();
        let t = CacheTraffic::new(cfg);
        let a = CacheReq { x: 2, y: 4, z: 6 };
        let b = t.conflicting(a).unwrap();
        let d = c.item(&CacheItem::Deposit(a, [9; 8])).out.vox;
        let s = c.item(&CacheItem::Read(b));
        assert_eq!(s.out.hit, 0);
        assert_eq!(s.writes.len(), 8);
        assert_eq!(s.reads.len(), 8);
        // The victims are a's lines.
        for (p, w) in s.writes.iter().enumerate() {
            let (line, _, _) = cfg.slot(p as u32, [2, 4, 6]);
            assert_eq!(w.addr, cfg.line_addr(p as u32, line));
        }
        assert_eq!(c.item(&CacheItem::Read(a)).out.vox, d);
        // A reset loses what was not written back.
        c.item(&CacheItem::Deposit(a, [1; 8]));
        c.clear();
        assert_eq!(c.item(&CacheItem::Read(a)).out.vox, d);
    }

    #[test]
    fn the_splat_codec_packs_op_and_energies_and_a_read_leaves_them_zero() {
        let cfg = CacheConfig { splat: 1, ..SMALL };
        assert_eq!(cfg.in_width(), 12 + 2 + 8 * 16);
        let r = CacheReq { x: 1, y: 2, z: 3 };
        let words = SplatCodec(cfg).pack_in(&CacheItem::Deposit(r, [0xabcd; 8]));
        assert_eq!(words[0] & 0xfff, 1 | 2 << 4 | 3 << 8);
        assert_eq!(words[0] >> 12 & 3, 1);
        assert_eq!(words[0] >> 14 & 0xffff, 0xabcd);
        let read = cfg.pack_in(&r);
        assert_eq!(read[0], 1 | 2 << 4 | 3 << 8);
        assert!(read[1..].iter().all(|w| *w == 0));
        assert_eq!(SplatCodec(cfg).pack_in(&CacheItem::Flush)[0], 2 << 12);
        let img = cfg.image(&ramp(cfg)).unwrap();
        let back = cfg.words_of(&img.bytes);
        assert_eq!(
            back,
            ramp(cfg).iter().map(|w| w & 0xffff).collect::<Vec<_>>()
        );
    }
}
