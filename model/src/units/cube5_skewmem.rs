//! Skewed memory controller with hierarchical blocks (`cube5_skewmem`), written from
//! `docs/numerics/skewmem.md` (patent [37], [43], [54]-[57]).
//!
//! Functional model: voxel `(x, y, z)` lives in module `(x + y + z) mod P` at word
//! `ptr * B^3/P + (lx div P) + (B/P) * (ly + B * lz)`, where `ptr` is the block's LUT pointer. A read
//! command fetches an aligned beam of `P` voxels along one axis; the model computes each lane's
//! module and word from the lane's own coordinates, checks that the beam's accesses are
//! conflict-free ([`ConflictChecker`]) and counts reads and writes per module as the RTL does.
//! [`BlockLut::from_volume`] is the one place where the block LUT is computed.

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::{param_in, StreamCodec, StreamUnit};
use crate::volume::Volume;

/// Parameters of one `cube5_skewmem` configuration (the RTL parameters of the same names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SkewConfig {
    /// Memory modules = lanes of a beam (`P`).
    pub p: u32,
    /// Voxel width (`VoxelW`).
    pub voxel_w: u32,
    /// `MaxDimLog2`: the largest edge is `2^MaxDimLog2`.
    pub max_dim_log2: u32,
    /// Block edge (`B`).
    pub block: u32,
    /// Module read latency (`ReadLatency`).
    pub read_latency: u32,
    /// Access counter width (`CntW`).
    pub cnt_w: u32,
}

impl SkewConfig {
    /// `p1`: one module.
    pub const P1: Self = Self {
        p: 1,
        voxel_w: 8,
        max_dim_log2: 4,
        block: 4,
        read_latency: 1,
        cnt_w: 16,
    };
    /// `p2`: two modules, small enough for the gate-level netlist.
    pub const P2: Self = Self {
        p: 2,
        voxel_w: 8,
        max_dim_log2: 3,
        block: 4,
        read_latency: 2,
        cnt_w: 8,
    };
    /// `p4`: the default, 12-bit voxels, SRAM modules.
    pub const DEFAULT: Self = Self {
        p: 4,
        voxel_w: 12,
        max_dim_log2: 4,
        block: 8,
        read_latency: 1,
        cnt_w: 32,
    };
    /// `p4l4`: DRAM-like modules with a read latency of 4.
    pub const P4_L4: Self = Self {
        p: 4,
        voxel_w: 12,
        max_dim_log2: 4,
        block: 4,
        read_latency: 4,
        cnt_w: 16,
    };
    /// `p8`: eight modules, 16-bit voxels.
    pub const P8: Self = Self {
        p: 8,
        voxel_w: 16,
        max_dim_log2: 4,
        block: 8,
        read_latency: 3,
        cnt_w: 24,
    };

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("skewmem: {what}")));
        if !matches!(self.p, 1 | 2 | 4 | 8 | 16) {
            return bad(format!("P {} is not 1, 2, 4, 8 or 16", self.p));
        }
        param_in("VoxelW", self.voxel_w, 4..=16).or_else(bad)?;
        param_in("MaxDimLog2", self.max_dim_log2, 2..=10).or_else(bad)?;
        if !self.block.is_power_of_two() || !(2..=64).contains(&self.block) {
            return bad(format!(
                "block edge B {} is not a power of two in 2..=64",
                self.block
            ));
        }
        if self.block < self.p {
            return bad(format!(
                "block edge B {} is smaller than P {}",
                self.block, self.p
            ));
        }
        if self.block >= self.max_dim() {
            return bad(format!(
                "block edge B {} must be smaller than the largest edge {}",
                self.block,
                self.max_dim()
            ));
        }
        param_in("ReadLatency", self.read_latency, 1..=8).or_else(bad)?;
        param_in("CntW", self.cnt_w, 8..=32).or_else(bad)?;
        Ok(())
    }

    /// `p = log2 P`.
    pub fn log_p(&self) -> u32 {
        self.p.trailing_zeros()
    }

    /// The largest edge `M`.
    pub fn max_dim(&self) -> u32 {
        1 << self.max_dim_log2
    }

    /// Blocks per axis of the RTL's LUT, `NB = M / B`.
    pub fn blocks_per_axis(&self) -> u32 {
        self.max_dim() / self.block
    }

    /// Bits of a block index or pointer, `3 (m - beta)`.
    pub fn blk_w(&self) -> u32 {
        3 * (self.max_dim_log2 - self.block.trailing_zeros())
    }

    /// Physical block slots, `NB^3`.
    pub fn slots(&self) -> u32 {
        self.blocks_per_axis().pow(3)
    }

    /// Words of one block in each module, `B^3 / P`.
    pub fn words_per_block(&self) -> u32 {
        self.block.pow(3) / self.p
    }

    /// Words per module, `M^3 / P`.
    pub fn module_depth(&self) -> u32 {
        self.slots() * self.words_per_block()
    }

    /// Bits of the probe field, `max(1, p)`.
    pub fn probe_w(&self) -> u32 {
        self.log_p().max(1)
    }

    /// Cycles from accepting a command to its response at full speed, `L + 2`.
    pub fn latency(&self) -> u32 {
        self.read_latency + 2
    }

    pub fn voxel_max(&self) -> u32 {
        (1 << self.voxel_w) - 1
    }

    pub(crate) fn cnt_mask(&self) -> u64 {
        (1u64 << self.cnt_w) - 1
    }

    /// Width of `cfg_addr_i`, `1 + BlkW`.
    pub fn cfg_addr_w(&self) -> u32 {
        1 + self.blk_w()
    }

    /// Width of `cfg_data_i`, `max(3 (m + 1), BlkW + 2)`.
    pub fn cfg_data_w(&self) -> u32 {
        (3 * (self.max_dim_log2 + 1)).max(self.blk_w() + 2)
    }
}

/// Beam axis (the 2-bit `axis` field; 3 is reserved and behaves as x).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    X = 0,
    Y = 1,
    Z = 2,
}

impl Axis {
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    pub fn from_bits(bits: u32) -> Self {
        match bits & 3 {
            1 => Axis::Y,
            2 => Axis::Z,
            _ => Axis::X,
        }
    }

    pub fn index(self) -> usize {
        self as usize
    }
}

/// Command kind (the `op` bit).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SkewOp {
    Write = 0,
    Read = 1,
}

/// One command (input item). Fields a command does not use are still packed, so the tests can
/// show that the RTL ignores them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SkewIn {
    pub op: SkewOp,
    /// Raw axis bits, 0..=3.
    pub axis: u32,
    /// `(x, y, z)`, each `< 2^MaxDimLog2`.
    pub pos: [u32; 3],
    /// The voxel a write stores.
    pub data: u32,
    /// Raw probe bits: the response carries the counters of module `probe mod P`.
    pub probe: u32,
}

impl SkewIn {
    pub fn write(pos: [u32; 3], data: u32) -> Self {
        Self {
            op: SkewOp::Write,
            axis: 0,
            pos,
            data,
            probe: 0,
        }
    }

    pub fn read(pos: [u32; 3], axis: Axis) -> Self {
        Self {
            op: SkewOp::Read,
            axis: axis as u32,
            pos,
            data: 0,
            probe: 0,
        }
    }

    pub fn with_probe(mut self, probe: u32) -> Self {
        self.probe = probe;
        self
    }
}

/// One response (output item).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SkewOut {
    /// Lane `i`: the `i`-th voxel of the beam (all 0 for writes, outside or skipped beams).
    pub voxels: Vec<u32>,
    pub is_beam: bool,
    pub outside: bool,
    pub empty: bool,
    pub masked: bool,
    pub conflict: bool,
    /// Reads issued to the probed module so far, modulo `2^CntW`.
    pub rd: u32,
    /// Writes issued to the probed module so far, modulo `2^CntW`.
    pub wr: u32,
}

/// The runtime volume dimensions register.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SkewDims {
    pub n: [u32; 3],
}

impl SkewDims {
    /// Refuses dimensions the contract does not allow: each a multiple of `P` in `P..=M`.
    pub fn new(cfg: &SkewConfig, n: [u32; 3]) -> Result<Self> {
        cfg.validate()?;
        for (a, &d) in n.iter().enumerate() {
            if d == 0 || d % cfg.p != 0 || d > cfg.max_dim() {
                return Err(ModelError::Volume(format!(
                    "skewmem: dimension {} along {} must be a multiple of P = {} in {}..={}",
                    d,
                    ["x", "y", "z"][a],
                    cfg.p,
                    cfg.p,
                    cfg.max_dim()
                )));
            }
        }
        Ok(Self { n })
    }

    pub fn voxels(&self) -> usize {
        self.n.iter().map(|&d| d as usize).product()
    }

    pub fn contains(&self, c: [u32; 3]) -> bool {
        (0..3).all(|a| c[a] < self.n[a])
    }
}

/// One block LUT entry [57].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BlockEntry {
    /// Physical block slot.
    pub ptr: u32,
    /// Every voxel of the block is `<= threshold`: reads are skipped.
    pub empty: bool,
    /// Outside the region of interest: reads are skipped.
    pub masked: bool,
}

/// The block look-up table of a volume: one entry per `B^3` block, x fastest.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BlockLut {
    /// Block edge `B`.
    pub block: u32,
    /// Blocks per axis, `ceil(n / B)`.
    pub blocks: [u32; 3],
    pub entries: Vec<BlockEntry>,
}

impl BlockLut {
    /// Every block present, none empty, none masked, pointers dense from slot 0.
    pub fn identity(dims: [usize; 3], block: usize) -> Result<Self> {
        if !block.is_power_of_two() || !(2..=64).contains(&block) {
            return Err(ModelError::Config(format!(
                "block LUT: block edge {block} is not a power of two in 2..=64"
            )));
        }
        if dims.contains(&0) {
            return Err(ModelError::Volume(format!(
                "block LUT: dimensions {dims:?} must be nonzero"
            )));
        }
        let blocks = dims.map(|d| d.div_ceil(block) as u32);
        let n = blocks.iter().map(|&b| b as usize).product::<usize>();
        let entries = (0..n as u32)
            .map(|ptr| BlockEntry {
                ptr,
                empty: false,
                masked: false,
            })
            .collect();
        Ok(Self {
            block: block as u32,
            blocks,
            entries,
        })
    }

    /// The LUT of `vol` with blocks of edge `block`: a block is empty when every voxel of it that
    /// lies inside the volume is `<= threshold`. Pointers are dense (`bx + LX (by + LY bz)`).
    pub fn from_volume(vol: &Volume, block: usize, threshold: u32) -> Result<Self> {
        let mut lut = Self::identity(vol.dims, block)?;
        let [lx, ly, _] = lut.blocks.map(|b| b as usize);
        let mut max = vec![0u16; lut.entries.len()];
        let [nx, ny, nz] = vol.dims;
        for z in 0..nz {
            for y in 0..ny {
                let row = &vol.data[nx * (y + ny * z)..][..nx];
                let base = lx * (y / block + ly * (z / block));
                for (x, &v) in row.iter().enumerate() {
                    let m = &mut max[base + x / block];
                    *m = (*m).max(v);
                }
            }
        }
        for (e, &m) in lut.entries.iter_mut().zip(&max) {
            e.empty = u32::from(m) <= threshold;
        }
        Ok(lut)
    }

    fn index(&self, b: [u32; 3]) -> usize {
        (b[0] + self.blocks[0] * (b[1] + self.blocks[1] * b[2])) as usize
    }

    /// The entry of block `(bx, by, bz)`, if it is within the LUT.
    pub fn entry(&self, b: [u32; 3]) -> Option<BlockEntry> {
        (0..3)
            .all(|a| b[a] < self.blocks[a])
            .then(|| self.entries[self.index(b)])
    }

    /// Changes the pointer of block `b` (relocation, or several volumes sharing the memory [57]).
    pub fn set_pointer(&mut self, b: [u32; 3], ptr: u32) -> Result<()> {
        if !(0..3).all(|a| b[a] < self.blocks[a]) {
            return Err(ModelError::Config(format!(
                "block LUT: block {b:?} outside {:?}",
                self.blocks
            )));
        }
        let i = self.index(b);
        self.entries[i].ptr = ptr;
        Ok(())
    }

    /// Masks every block that does not meet the voxel box `[lo, hi)`: the region of interest.
    pub fn restrict_to(&mut self, lo: [u32; 3], hi: [u32; 3]) {
        let b = self.block;
        for bz in 0..self.blocks[2] {
            for by in 0..self.blocks[1] {
                for bx in 0..self.blocks[0] {
                    let c = [bx, by, bz];
                    let meets = (0..3).all(|a| c[a] * b < hi[a] && lo[a] < (c[a] + 1) * b);
                    if !meets {
                        let i = self.index(c);
                        self.entries[i].masked = true;
                    }
                }
            }
        }
    }

    /// Blocks whose reads are skipped (empty or masked).
    pub fn skipped(&self) -> usize {
        self.entries.iter().filter(|e| e.empty || e.masked).count()
    }
}

/// Checks that the module accesses issued in one cycle touch each module at most once.
#[derive(Debug, Clone, Default)]
pub struct ConflictChecker {
    /// Cycles with at least one access.
    pub cycles: u64,
    /// Cycles in which some module was accessed more than once.
    pub conflicts: u64,
    /// The most accesses any module saw in one cycle.
    pub max_per_module: u32,
}

impl ConflictChecker {
    /// Records one cycle's accesses (module numbers); true if they conflict.
    pub fn issue(&mut self, p: u32, modules: &[u32]) -> bool {
        let mut count = vec![0u32; p as usize];
        for &m in modules {
            count[m as usize] += 1;
        }
        let most = count.iter().copied().max().unwrap_or(0);
        self.cycles += 1;
        self.max_per_module = self.max_per_module.max(most);
        let conflict = most > 1;
        self.conflicts += u64::from(conflict);
        conflict
    }
}

/// The module numbers of the beam of `P` voxels from `start` along `axis` (no alignment applied).
pub fn beam_modules(cfg: &SkewConfig, start: [u32; 3], axis: Axis) -> Vec<u32> {
    (0..cfg.p)
        .map(|i| {
            let mut c = start;
            c[axis.index()] += i;
            module_of(cfg, c)
        })
        .collect()
}

/// `k = (x + y + z) mod P`.
pub fn module_of(cfg: &SkewConfig, c: [u32; 3]) -> u32 {
    (c[0] + c[1] + c[2]) % cfg.p
}

/// The golden model of `cube5_skewmem`.
#[derive(Debug, Clone)]
pub struct SkewMem {
    cfg: SkewConfig,
    dims: SkewDims,
    lut: BlockLut,
    banks: Vec<Vec<u16>>,
    rd: Vec<u64>,
    wr: Vec<u64>,
    /// Every cycle's module accesses, checked for conflicts.
    pub checker: ConflictChecker,
    /// Read commands whose beam was fetched from the modules.
    pub beams_read: u64,
    /// Read commands inside the volume whose block was empty or masked (no module access).
    pub beams_skipped: u64,
}

impl SkewMem {
    /// A controller with dimensions `dims` and block LUT `lut` loaded. Memory reads as 0 until
    /// written (the RTL's is undefined: tests write the volume first).
    pub fn new(cfg: SkewConfig, dims: SkewDims, lut: BlockLut) -> Result<Self> {
        cfg.validate()?;
        let dims = SkewDims::new(&cfg, dims.n)?;
        if lut.block != cfg.block {
            return Err(ModelError::Config(format!(
                "skewmem: block LUT has edge {} but B is {}",
                lut.block, cfg.block
            )));
        }
        let want = dims.n.map(|d| d.div_ceil(cfg.block));
        if lut.blocks != want {
            return Err(ModelError::Config(format!(
                "skewmem: block LUT covers {:?} blocks but the volume has {want:?}",
                lut.blocks
            )));
        }
        if let Some(e) = lut.entries.iter().find(|e| e.ptr >= cfg.slots()) {
            return Err(ModelError::Config(format!(
                "skewmem: block pointer {} beyond the {} slots",
                e.ptr,
                cfg.slots()
            )));
        }
        Ok(Self {
            cfg,
            dims,
            lut,
            banks: vec![vec![0; cfg.module_depth() as usize]; cfg.p as usize],
            rd: vec![0; cfg.p as usize],
            wr: vec![0; cfg.p as usize],
            checker: ConflictChecker::default(),
            beams_read: 0,
            beams_skipped: 0,
        })
    }

    pub fn config(&self) -> SkewConfig {
        self.cfg
    }

    pub fn dims(&self) -> SkewDims {
        self.dims
    }

    pub fn lut(&self) -> &BlockLut {
        &self.lut
    }

    /// Reads and writes issued to module `k` (modulo `2^CntW`).
    pub fn counters(&self, k: usize) -> (u32, u32) {
        (self.rd[k] as u32, self.wr[k] as u32)
    }

    /// The configuration-port writes that load the dimensions and the LUT into the RTL
    /// (`docs/numerics/skewmem.md`, configuration port), in the order they are applied.
    pub fn config_writes(&self) -> Vec<(u32, Vec<u32>)> {
        let cfg = &self.cfg;
        let m1 = cfg.max_dim_log2 + 1;
        let mut w = BitWriter::new();
        for d in self.dims.n {
            w.put(u64::from(d), m1);
        }
        w.put(0, cfg.cfg_data_w() - 3 * m1);
        let mut writes = vec![(0u32, w.finish(cfg.cfg_data_w()))];
        let nb = cfg.blocks_per_axis();
        let filler = BlockEntry {
            ptr: 0,
            empty: false,
            masked: true,
        };
        for i in 0..cfg.slots() {
            let b = [i % nb, (i / nb) % nb, i / (nb * nb)];
            let e = self.lut.entry(b).unwrap_or(filler);
            let mut w = BitWriter::new();
            w.put(u64::from(e.ptr), cfg.blk_w())
                .put_bool(e.empty)
                .put_bool(e.masked);
            w.put(0, cfg.cfg_data_w() - cfg.blk_w() - 2);
            writes.push(((1 << cfg.blk_w()) | i, w.finish(cfg.cfg_data_w())));
        }
        writes
    }

    /// Module and word of voxel `c` (inside the volume): the contract's address formula.
    pub fn locate(&self, c: [u32; 3]) -> (u32, u32) {
        let b = self.cfg.block;
        let entry = self
            .lut
            .entry(c.map(|v| v / b))
            .expect("voxel inside the volume");
        let [lx, ly, lz] = c.map(|v| v % b);
        let word = entry.ptr * self.cfg.words_per_block()
            + lx / self.cfg.p
            + (b / self.cfg.p) * (ly + b * lz);
        (module_of(&self.cfg, c), word)
    }

    fn probe(&self, raw: u32) -> (u32, u32) {
        let k = (raw % self.cfg.p) as usize;
        self.counters(k)
    }

    /// Executes one command and returns its response.
    pub fn command(&mut self, cmd: &SkewIn) -> SkewOut {
        let cfg = self.cfg;
        let mask = cfg.cnt_mask();
        let mut out = SkewOut {
            voxels: vec![0; cfg.p as usize],
            is_beam: cmd.op == SkewOp::Read,
            outside: false,
            empty: false,
            masked: false,
            conflict: false,
            rd: 0,
            wr: 0,
        };
        match cmd.op {
            SkewOp::Write => {
                let c = cmd.pos;
                if !self.dims.contains(c) {
                    out.outside = true;
                } else {
                    let e = self.lut.entry(c.map(|v| v / cfg.block)).unwrap();
                    out.empty = e.empty;
                    out.masked = e.masked;
                    let (k, word) = self.locate(c);
                    self.banks[k as usize][word as usize] = (cmd.data & cfg.voxel_max()) as u16;
                    self.wr[k as usize] = (self.wr[k as usize] + 1) & mask;
                    self.checker.issue(cfg.p, &[k]);
                }
            }
            SkewOp::Read => {
                let axis = Axis::from_bits(cmd.axis).index();
                let mut start = cmd.pos;
                start[axis] &= !(cfg.p - 1);
                let lanes: Vec<[u32; 3]> = (0..cfg.p)
                    .map(|i| {
                        let mut c = start;
                        c[axis] += i;
                        c
                    })
                    .collect();
                if !lanes.iter().all(|&c| self.dims.contains(c)) {
                    out.outside = true;
                } else {
                    let e = self.lut.entry(start.map(|v| v / cfg.block)).unwrap();
                    out.empty = e.empty;
                    out.masked = e.masked;
                    if e.empty || e.masked {
                        self.beams_skipped += 1;
                    } else {
                        self.beams_read += 1;
                        let modules: Vec<u32> = lanes.iter().map(|&c| module_of(&cfg, c)).collect();
                        out.conflict = self.checker.issue(cfg.p, &modules);
                        for (i, &c) in lanes.iter().enumerate() {
                            let (k, word) = self.locate(c);
                            out.voxels[i] = u32::from(self.banks[k as usize][word as usize]);
                            self.rd[k as usize] = (self.rd[k as usize] + 1) & mask;
                        }
                    }
                }
            }
        }
        (out.rd, out.wr) = self.probe(cmd.probe);
        out
    }
}

impl StreamUnit for SkewMem {
    type In = SkewIn;
    type Out = SkewOut;

    fn run(&mut self, inputs: &[SkewIn]) -> Vec<SkewOut> {
        inputs.iter().map(|c| self.command(c)).collect()
    }

    /// Reset clears the counters only: memory, LUT and dimensions are kept.
    fn reset(&mut self) {
        self.rd.iter_mut().for_each(|c| *c = 0);
        self.wr.iter_mut().for_each(|c| *c = 0);
    }
}

impl StreamCodec for SkewConfig {
    type In = SkewIn;
    type Out = SkewOut;

    fn in_width(&self) -> u32 {
        3 + 3 * self.max_dim_log2 + self.voxel_w + self.probe_w()
    }

    fn out_width(&self) -> u32 {
        self.p * self.voxel_w + 5 + 2 * self.cnt_w
    }

    fn pack_in(&self, item: &SkewIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        w.put(item.op as u64, 1).put(u64::from(item.axis), 2);
        for c in item.pos {
            w.put(u64::from(c), self.max_dim_log2);
        }
        w.put(u64::from(item.data), self.voxel_w)
            .put(u64::from(item.probe), self.probe_w());
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> SkewOut {
        let mut r = BitReader::new(words);
        let voxels = (0..self.p).map(|_| r.get(self.voxel_w) as u32).collect();
        SkewOut {
            voxels,
            is_beam: r.get_bool(),
            outside: r.get_bool(),
            empty: r.get_bool(),
            masked: r.get_bool(),
            conflict: r.get_bool(),
            rd: r.get(self.cnt_w) as u32,
            wr: r.get(self.cnt_w) as u32,
        }
    }
}

// The RTL parameters: `MaxDim` is the largest edge (a power of two), the model keeps its log2.
impl crate::unit::UnitConfig for SkewConfig {
    const TOP: &'static str = "cube5_skewmem";

    fn from_params(params: &[(&str, i64)]) -> Result<Self> {
        let mut c = Self::DEFAULT;
        let mut max_dim = 1u32 << c.max_dim_log2;
        crate::unit::set_params(
            Self::TOP,
            params,
            &mut [
                ("P", &mut c.p),
                ("VoxelW", &mut c.voxel_w),
                ("MaxDim", &mut max_dim),
                ("BlockDim", &mut c.block),
                ("MemLatency", &mut c.read_latency),
                ("CntW", &mut c.cnt_w),
            ],
        )?;
        if !max_dim.is_power_of_two() {
            return Err(ModelError::Config(format!(
                "cube5_skewmem: MaxDim = {max_dim} is not a power of two"
            )));
        }
        c.max_dim_log2 = max_dim.trailing_zeros();
        c.validate()?;
        Ok(c)
    }

    fn to_params(&self) -> Vec<(&'static str, i64)> {
        vec![
            ("P", i64::from(self.p)),
            ("VoxelW", i64::from(self.voxel_w)),
            ("MaxDim", 1i64 << self.max_dim_log2),
            ("BlockDim", i64::from(self.block)),
            ("MemLatency", i64::from(self.read_latency)),
            ("CntW", i64::from(self.cnt_w)),
        ]
    }
}

/// A `SkewMem` with the identity block LUT and a plain `Vec<u16>` volume written alongside it:
/// every beam read is checked against what was written (the model's tests, `cube5 bench`).
pub struct Mirrored {
    pub mem: SkewMem,
    cfg: SkewConfig,
    n: [u32; 3],
    plain: Vec<u16>,
}

impl Mirrored {
    /// A controller of dimensions `n` and its mirror, both reading 0.
    pub fn new(cfg: SkewConfig, n: [u32; 3]) -> Result<Self> {
        let dims = SkewDims::new(&cfg, n)?;
        let lut = BlockLut::identity(n.map(|d| d as usize), cfg.block as usize)?;
        Ok(Self {
            mem: SkewMem::new(cfg, dims, lut)?,
            cfg,
            n,
            plain: vec![0u16; dims.voxels()],
        })
    }

    fn idx(&self, c: [u32; 3]) -> usize {
        (c[0] + self.n[0] * (c[1] + self.n[1] * c[2])) as usize
    }

    /// Writes a random voxel value (one draw) at `c`, to both.
    pub fn write_random(&mut self, c: [u32; 3], rng: &mut (impl rand::Rng + ?Sized)) {
        let v = rng.random_range(0..=self.cfg.voxel_max());
        self.mem.command(&SkewIn::write(c, v));
        let at = self.idx(c);
        self.plain[at] = v as u16;
    }

    /// Reads the beam through `c` along a random axis (one draw): `(position, read, written)` for
    /// each of its `P` voxels.
    pub fn read_random(
        &mut self,
        c: [u32; 3],
        rng: &mut (impl rand::Rng + ?Sized),
    ) -> Vec<([u32; 3], u32, u32)> {
        let axis = Axis::ALL[rng.random_range(0..3)];
        let r = self.mem.command(&SkewIn::read(c, axis));
        let mut s = c;
        s[axis.index()] &= !(self.cfg.p - 1);
        r.voxels
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                let mut q = s;
                q[axis.index()] += i as u32;
                (q, v, u32::from(self.plain[self.idx(q)]))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::head_phantom;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The default with a `32^3` maximum (the contract's example).
    const BIG: SkewConfig = SkewConfig {
        max_dim_log2: 5,
        ..SkewConfig::DEFAULT
    };

    const ALL: [SkewConfig; 5] = [
        SkewConfig::P1,
        SkewConfig::P2,
        SkewConfig::DEFAULT,
        SkewConfig::P4_L4,
        SkewConfig::P8,
    ];

    /// A controller holding `vol` (written through commands), with LUT `lut`.
    fn loaded(cfg: SkewConfig, vol: &Volume, lut: BlockLut) -> SkewMem {
        let dims = SkewDims::new(&cfg, vol.dims.map(|d| d as u32)).unwrap();
        let mut mem = SkewMem::new(cfg, dims, lut).unwrap();
        let [nx, ny, nz] = vol.dims;
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let c = [x, y, z].map(|v| v as u32);
                    let v = vol.get(x as i64, y as i64, z as i64);
                    let r = mem.command(&SkewIn::write(c, v));
                    assert!(!r.outside && !r.is_beam);
                }
            }
        }
        mem
    }

    fn random_volume(rng: &mut ChaCha8Rng, dims: [usize; 3], bits: u32) -> Volume {
        let n = dims.iter().product();
        let data = (0..n)
            .map(|_| rng.random_range(0..=((1u32 << bits) - 1)) as u16)
            .collect();
        Volume::new(dims, [1.0; 3], bits, data).unwrap()
    }

    #[test]
    fn contract_example_address() {
        let cfg = BIG;
        let dims = SkewDims::new(&cfg, [32; 3]).unwrap();
        let mem = SkewMem::new(cfg, dims, BlockLut::identity([32; 3], 8).unwrap()).unwrap();
        assert_eq!(mem.locate([13, 2, 9]), (0, 2197));
        assert_eq!(cfg.module_depth(), 8192);
    }

    #[test]
    fn address_map_is_a_bijection_onto_the_modules() {
        for cfg in ALL {
            let m = cfg.max_dim();
            let dims = SkewDims::new(&cfg, [m; 3]).unwrap();
            let lut = BlockLut::identity([m as usize; 3], cfg.block as usize).unwrap();
            let mem = SkewMem::new(cfg, dims, lut).unwrap();
            let mut seen = vec![false; (cfg.p * cfg.module_depth()) as usize];
            for z in 0..m {
                for y in 0..m {
                    for x in 0..m {
                        let (k, w) = mem.locate([x, y, z]);
                        assert!(w < cfg.module_depth());
                        let slot = (k * cfg.module_depth() + w) as usize;
                        assert!(!seen[slot], "{cfg:?}: ({x},{y},{z}) collides");
                        seen[slot] = true;
                    }
                }
            }
        }
    }

    /// Every beam of a whole volume, along each axis, at P = 1, 2, 4, 8, 16: no module conflict,
    /// and (with any start, aligned or not) the beam's modules are a rotation of 0..P-1.
    #[test]
    fn every_beam_of_a_whole_volume_is_conflict_free_at_each_p() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for p in [1, 2, 4, 8, 16] {
            let cfg = SkewConfig {
                p,
                voxel_w: 12,
                max_dim_log2: 5,
                block: p.max(8),
                read_latency: 1,
                cnt_w: 32,
            };
            cfg.validate().unwrap();
            let n = [32usize, 16, 48 / p as usize * p as usize].map(|d| d.min(32));
            let vol = random_volume(&mut rng, n, 12);
            let mut mem = loaded(
                cfg,
                &vol,
                BlockLut::identity(n, cfg.block as usize).unwrap(),
            );
            let mut beams = 0u64;
            for axis in Axis::ALL {
                let a = axis.index();
                for z in 0..n[2] as u32 {
                    for y in 0..n[1] as u32 {
                        for x in 0..n[0] as u32 {
                            let c = [x, y, z];
                            // Unaligned starts: the pure map is conflict-free anyway.
                            let mods = beam_modules(&cfg, c, axis);
                            let s = module_of(&cfg, c);
                            for (i, &k) in mods.iter().enumerate() {
                                assert_eq!(k, (s + i as u32) % p);
                            }
                            if c[a] % p != 0 || c[a] as usize + p as usize > n[a] {
                                continue;
                            }
                            let r = mem.command(&SkewIn::read(c, axis));
                            beams += 1;
                            assert!(!r.conflict && !r.outside);
                            for (i, &v) in r.voxels.iter().enumerate() {
                                let mut q = c.map(i64::from);
                                q[a] += i as i64;
                                assert_eq!(v, vol.get(q[0], q[1], q[2]), "P={p} {axis:?} {c:?}");
                            }
                        }
                    }
                }
            }
            assert_eq!(mem.checker.conflicts, 0);
            assert_eq!(mem.checker.max_per_module, 1);
            assert_eq!(beams, 3 * vol.len() as u64 / u64::from(p));
            // Every module served every beam exactly once.
            for k in 0..p as usize {
                assert_eq!(u64::from(mem.counters(k).0), beams, "P={p} module {k}");
            }
        }
    }

    #[test]
    fn random_writes_then_reads_match_a_plain_vector() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for cfg in ALL {
            let m = cfg.max_dim();
            let n = [m, m - cfg.p, (m / 2).max(cfg.p)];
            let mut mirror = Mirrored::new(cfg, n).unwrap();
            for round in 0..20_000 {
                let c = [0, 1, 2].map(|a| rng.random_range(0..n[a]));
                if round % 3 != 2 {
                    mirror.write_random(c, &mut rng);
                } else {
                    for (q, got, want) in mirror.read_random(c, &mut rng) {
                        assert_eq!(got, want, "{cfg:?} {q:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn outside_and_skipped_beams_read_zero_without_access() {
        let cfg = BIG;
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let vol = random_volume(&mut rng, [24, 32, 16], 12);
        let mut lut = BlockLut::identity(vol.dims, 8).unwrap();
        lut.entries[0].empty = true;
        lut.restrict_to([0, 0, 0], [24, 32, 8]);
        let mut mem = loaded(cfg, &vol, lut);
        let before: Vec<_> = (0..4).map(|k| mem.counters(k)).collect();
        // Beyond nx = 24: outside.
        let r = mem.command(&SkewIn::read([24, 0, 0], Axis::X));
        assert!(r.outside && r.is_beam && !r.empty && !r.masked);
        assert_eq!(r.voxels, vec![0; 4]);
        // Block 0 is empty.
        let r = mem.command(&SkewIn::read([0, 3, 5], Axis::Y));
        assert!(!r.outside && r.empty && !r.masked);
        assert_eq!(r.voxels, vec![0; 4]);
        // z >= 8 is outside the ROI.
        let r = mem.command(&SkewIn::read([8, 3, 9], Axis::Z));
        assert!(r.masked && !r.empty);
        assert_eq!(r.voxels, vec![0; 4]);
        let after: Vec<_> = (0..4).map(|k| mem.counters(k)).collect();
        assert_eq!(before, after, "no module was accessed");
        // A normal beam reads; the start's low bits along the axis are ignored.
        let r = mem.command(&SkewIn::read([9, 3, 2], Axis::X).with_probe(6));
        assert!(!r.outside && !r.empty && !r.masked);
        let want: Vec<u32> = (8..12).map(|x| vol.get(x, 3, 2)).collect();
        assert_eq!(r.voxels, want);
        assert_eq!(r.rd, before[2].0 + 1, "probe 6 mod 4 = module 2");
        // Writes go through the pointer whatever the flags; outside writes are dropped.
        let r = mem.command(&SkewIn::write([1, 1, 1], 77));
        assert!(r.empty && !r.is_beam && r.voxels == vec![0; 4]);
        let r = mem.command(&SkewIn::write([1, 40 % 32, 16], 77));
        assert!(r.outside);
    }

    #[test]
    fn pointers_relocate_and_share_blocks() {
        let cfg = SkewConfig::P8;
        let n = [16u32, 16, 8];
        let dims = SkewDims::new(&cfg, n).unwrap();
        let mut lut = BlockLut::identity([16, 16, 8], 8).unwrap();
        // Block (1, 0, 0) shares the slot of block (0, 0, 0); block (1, 1, 0) moves to slot 7.
        lut.set_pointer([1, 0, 0], 0).unwrap();
        lut.set_pointer([1, 1, 0], 7).unwrap();
        assert!(lut.set_pointer([2, 0, 0], 0).is_err());
        let mut mem = SkewMem::new(cfg, dims, lut).unwrap();
        mem.command(&SkewIn::write([3, 4, 5], 1234));
        let r = mem.command(&SkewIn::read([8, 4, 5], Axis::X));
        assert_eq!(r.voxels[3], 1234, "the aliased block sees the write");
        mem.command(&SkewIn::write([9, 9, 1], 99));
        assert_eq!(mem.locate([9, 9, 1]).1 / cfg.words_per_block(), 7);
        let r = mem.command(&SkewIn::read([9, 8, 1], Axis::Y));
        assert_eq!(r.voxels[1], 99);
    }

    #[test]
    fn counters_wrap_and_reset_keeps_memory() {
        let cfg = SkewConfig::P2; // CntW = 8
        let dims = SkewDims::new(&cfg, [8; 3]).unwrap();
        let mut mem = SkewMem::new(cfg, dims, BlockLut::identity([8; 3], 4).unwrap()).unwrap();
        mem.command(&SkewIn::write([2, 0, 0], 200));
        for _ in 0..300 {
            mem.command(&SkewIn::read([2, 0, 0], Axis::X));
        }
        assert_eq!(mem.counters(0), ((300 % 256) as u32, 1));
        mem.reset();
        assert_eq!(mem.counters(0), (0, 0));
        let r = mem.command(&SkewIn::read([2, 0, 0], Axis::X));
        assert_eq!(r.voxels, vec![200, 0]);
        assert_eq!((r.rd, r.wr), (1, 0));
    }

    #[test]
    fn block_lut_from_the_head_phantom() {
        let vol = head_phantom(32, 12).unwrap();
        let lut = BlockLut::from_volume(&vol, 8, 0).unwrap();
        assert_eq!(lut.blocks, [4, 4, 4]);
        assert!(lut.entries[0].empty, "the corner block is air");
        assert!(
            !lut.entries[lut.index([1, 1, 1])].empty,
            "the centre is not"
        );
        let all = BlockLut::from_volume(&vol, 8, 4095).unwrap();
        assert_eq!(all.skipped(), 64);
        let mut roi = BlockLut::from_volume(&vol, 8, 0).unwrap();
        roi.restrict_to([8, 8, 8], [16, 16, 17]);
        let unmasked: Vec<usize> = (0..64).filter(|&i| !roi.entries[i].masked).collect();
        assert_eq!(unmasked, vec![21, 37]);
        // Partial edge blocks consider only the voxels inside the volume.
        let odd = Volume::new([12, 4, 4], [1.0; 3], 8, vec![0; 12 * 16]).unwrap();
        let lut = BlockLut::from_volume(&odd, 8, 0).unwrap();
        assert_eq!(lut.blocks, [2, 1, 1]);
        assert_eq!(lut.skipped(), 2);
    }

    #[test]
    fn config_writes_follow_the_address_map() {
        let cfg = SkewConfig::P2;
        let dims = SkewDims::new(&cfg, [8, 6, 4]).unwrap();
        let mut lut = BlockLut::identity([8, 6, 4], 4).unwrap();
        lut.entries[1].empty = true;
        let mem = SkewMem::new(cfg, dims, lut).unwrap();
        let w = mem.config_writes();
        assert_eq!(w.len(), 1 + 8);
        assert_eq!(cfg.cfg_data_w(), 12);
        assert_eq!(w[0], (0, vec![8 | 6 << 4 | 4 << 8]));
        assert_eq!(w[1], (8, vec![0]));
        assert_eq!(w[2], (9, vec![1 | 1 << 3]));
        assert_eq!(w[3], (10, vec![2]));
        assert_eq!(
            w[5],
            (12, vec![1 << 4]),
            "block (0,0,1) is beyond nz = 4: masked filler"
        );
    }

    #[test]
    fn config_validation() {
        let ok = BIG;
        assert!(ok.validate().is_ok());
        for bad in [
            SkewConfig { p: 3, ..ok },
            SkewConfig { voxel_w: 17, ..ok },
            SkewConfig { block: 2, ..ok },
            SkewConfig { block: 12, ..ok },
            SkewConfig { block: 32, ..ok },
            SkewConfig {
                read_latency: 0,
                ..ok
            },
            SkewConfig { cnt_w: 33, ..ok },
            SkewConfig {
                max_dim_log2: 11,
                ..ok
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        assert!(SkewDims::new(&ok, [32, 30, 32]).is_err());
        assert!(SkewDims::new(&ok, [32, 0, 32]).is_err());
        assert!(SkewDims::new(&ok, [64, 32, 32]).is_err());
        let dims = SkewDims::new(&ok, [32, 32, 16]).unwrap();
        let wrong = BlockLut::identity([32, 32, 32], 8).unwrap();
        assert!(SkewMem::new(ok, dims, wrong).is_err());
        let mut far = BlockLut::identity([32, 32, 16], 8).unwrap();
        far.entries[0].ptr = 64;
        assert!(SkewMem::new(ok, dims, far).is_err());
        assert!(BlockLut::identity([4, 4, 4], 3).is_err());
    }

    #[test]
    fn packing_width_matches_contract_table() {
        let widths: Vec<(u32, u32)> = ALL.iter().map(|c| (c.in_width(), c.out_width())).collect();
        assert_eq!(
            widths,
            vec![(24, 45), (21, 37), (29, 117), (29, 85), (34, 181)]
        );
    }

    #[test]
    fn codec_round_trip_of_a_response() {
        let cfg = SkewConfig::P8;
        let r = SkewOut {
            voxels: (0..8).map(|i| 1000 * i + 7).collect(),
            is_beam: true,
            outside: false,
            empty: true,
            masked: false,
            conflict: true,
            rd: 0xabcdef,
            wr: 0x123456,
        };
        let mut w = BitWriter::new();
        for &v in &r.voxels {
            w.put(u64::from(v), 16);
        }
        w.put_bool(true)
            .put_bool(false)
            .put_bool(true)
            .put_bool(false)
            .put_bool(true);
        w.put(0xabcdef, 24).put(0x123456, 24);
        assert_eq!(cfg.unpack_out(&w.finish(cfg.out_width())), r);
    }
}
