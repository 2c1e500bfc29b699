//! The AXI4-Lite register block (`cube5_axil_regs`, in the co-simulation top `cube5_axil`), written
//! from docs/accel-regs.md ("The register block"): a cycle-level model of the register file. Its
//! state changes only at clock edges: [`RegFile::edge`] applies the bus write done in that cycle
//! (if any) and then the hardware's W1C set bits, [`RegFile::read`] answers a read sampled in a
//! cycle. The map comes from the generated constants (`crate::regs`): `REGISTERS` (offset, access,
//! reset), `AXIL_MASK`, `AXIL_IRQ`.
//!
//! Responses depend on when the bus and the hardware meet, so the model is driven by the cycles
//! the test bench observed (the first cycle of BVALID, the cycle of the AR handshake) rather than
//! one output per input; [`AxilCodec`] packs transactions and unpacks records as the test bench's
//! AXI4-Lite manager carries them (tb/axil_mgr.h).

use crate::bits::words_for;
use crate::error::{ModelError, Result};
use crate::regmap::{Access, Register};
use crate::regs::{cube5_accel, cube5_axil_regs};
use crate::unit::StreamCodec;

/// AXI4-Lite response codes.
pub const RESP_OKAY: u32 = 0;
/// An unmapped offset, a write to an RO register, a read of a WO register.
pub const RESP_SLVERR: u32 = 2;

/// The RTL parameters of one `cube5_axil` configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxilConfig {
    /// Which generated map (`cube5_axil_regs::MAP_*`).
    pub map: u32,
    /// Byte address bits of the bus.
    pub addr_w: u32,
}

impl AxilConfig {
    /// The RTL's parameter defaults.
    pub const DEFAULT: Self = Self {
        map: cube5_axil_regs::MAP_ACCEL,
        addr_w: 10,
    };

    pub fn validate(&self) -> Result<()> {
        let map = AxilMap::of(self.map)?;
        if !(3..=32).contains(&self.addr_w) || (map.words() as u64) << 2 > 1u64 << self.addr_w {
            return Err(ModelError::Config(format!(
                "cube5_axil: {} words do not fit AddrW = {}",
                map.words(),
                self.addr_w
            )));
        }
        Ok(())
    }

    pub fn map(&self) -> AxilMap {
        AxilMap::of(self.map).unwrap_or(AxilMap::ACCEL)
    }
}

crate::unit_config!(AxilConfig, "cube5_axil", DEFAULT, {
    "Map" => map,
    "AddrW" => addr_w,
});

/// One generated register map as the block holds it.
#[derive(Debug, Clone, Copy)]
pub struct AxilMap {
    pub registers: &'static [Register],
    /// Per word offset: the bits the register has.
    pub mask: &'static [u32],
    /// (status, enable) offsets of the interrupt.
    pub irq: Option<(u32, u32)>,
}

impl AxilMap {
    pub const ACCEL: Self = Self {
        registers: &cube5_accel::REGISTERS,
        mask: &cube5_accel::AXIL_MASK,
        irq: cube5_accel::AXIL_IRQ,
    };
    pub const EXERCISE: Self = Self {
        registers: &cube5_axil_regs::REGISTERS,
        mask: &cube5_axil_regs::AXIL_MASK,
        irq: cube5_axil_regs::AXIL_IRQ,
    };

    pub fn of(map: u32) -> Result<Self> {
        match map {
            cube5_axil_regs::MAP_ACCEL => Ok(Self::ACCEL),
            cube5_axil_regs::MAP_EXERCISE => Ok(Self::EXERCISE),
            _ => Err(ModelError::Config(format!(
                "cube5_axil: Map = {map} is not a map (0 accel, 1 exercise)"
            ))),
        }
    }

    /// Word offsets 0 .. words() - 1.
    pub fn words(&self) -> u32 {
        self.mask.len() as u32
    }

    /// The register at word `offset`.
    pub fn at(&self, offset: u32) -> Option<&'static Register> {
        self.registers.iter().find(|r| r.offset == offset)
    }
}

/// A bus write as the block does it: word offset, data, WSTRB.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BusWrite {
    pub offset: u32,
    pub data: u32,
    pub strb: u32,
}

/// A read's answer; `data` is `None` where the value is unknown (a register reset does not
/// change, not written since the simulation began or since a reset dropped a write to it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadAnswer {
    pub resp: u32,
    pub data: Option<u32>,
}

/// The register file, cycle by cycle.
#[derive(Debug, Clone)]
pub struct RegFile {
    map: AxilMap,
    /// Per word offset: the kept value (masked), `None` where unknown; 0 where nothing is kept.
    words: Vec<Option<u32>>,
}

/// The four WSTRB bits as a 32-bit byte mask.
pub fn byte_mask(strb: u32) -> u32 {
    (0..4)
        .filter(|b| strb >> b & 1 != 0)
        .fold(0, |m, b| m | 0xff << (8 * b))
}

impl RegFile {
    /// The state out of the first reset: registers without a reset value are unknown.
    pub fn new(map: AxilMap) -> Self {
        let words = (0..map.words())
            .map(|o| match map.at(o) {
                Some(r) if r.access != Access::Ro => {
                    r.reset.map(|v| v as u32 & map.mask[o as usize])
                }
                _ => Some(0),
            })
            .collect();
        Self { map, words }
    }

    pub fn map(&self) -> &AxilMap {
        &self.map
    }

    fn kept(&self, offset: u32) -> Option<&'static Register> {
        self.map.at(offset).filter(|r| r.access != Access::Ro)
    }

    /// A reset: registers with a reset value take it, the others keep theirs.
    pub fn reset(&mut self) {
        for o in 0..self.map.words() {
            if let Some(v) = self.kept(o).and_then(|r| r.reset) {
                self.words[o as usize] = Some(v as u32 & self.map.mask[o as usize]);
            }
        }
    }

    /// A write that a reset may or may not have let through: its register becomes unknown unless
    /// the reset sets it.
    pub fn forget(&mut self, offset: u32) {
        if let Some(r) = self.kept(offset) {
            if r.reset.is_none() {
                self.words[offset as usize] = None;
            }
        }
    }

    /// BRESP of a write to `offset`: OKAY where a value is kept (RW, WO, W1C).
    pub fn write_resp(&self, offset: u32) -> u32 {
        if self.kept(offset).is_some() {
            RESP_OKAY
        } else {
            RESP_SLVERR
        }
    }

    /// A read of `offset` sampled in this cycle; `ro` is the hardware's value for an RO register.
    pub fn read(&self, offset: u32, ro: u32) -> ReadAnswer {
        match self.map.at(offset) {
            Some(r) if r.access == Access::Ro => ReadAnswer {
                resp: RESP_OKAY,
                data: Some(ro & self.map.mask[offset as usize]),
            },
            Some(r) if r.access != Access::Wo => ReadAnswer {
                resp: RESP_OKAY,
                data: self.words[offset as usize],
            },
            _ => ReadAnswer {
                resp: RESP_SLVERR,
                data: Some(0),
            },
        }
    }

    /// The value the hardware side sees for `offset` (0 outside the map or where nothing is kept).
    pub fn hw_word(&self, offset: u32) -> Option<u32> {
        self.words.get(offset as usize).copied().unwrap_or(Some(0))
    }

    /// The interrupt in this cycle (`None` while a bit it depends on is unknown).
    pub fn irq(&self) -> Option<bool> {
        match self.map.irq {
            Some((s, e)) => {
                let (s, e) = (self.words[s as usize]?, self.words[e as usize]?);
                Some(s & e != 0)
            }
            None => Some(false),
        }
    }

    /// One clock edge: the bus write done in this cycle (if any, and if OKAY), then the W1C set
    /// bits `set(offset)` of the hardware (a set and a clear of one bit: the set wins).
    pub fn edge(&mut self, write: Option<BusWrite>, set: &dyn Fn(u32) -> u32) {
        if let Some(w) = write {
            if let Some(r) = self.kept(w.offset) {
                let bm = byte_mask(w.strb);
                let i = w.offset as usize;
                let m = self.map.mask[i];
                self.words[i] = self.words[i].map(|q| match r.access {
                    Access::W1c => q & !(w.data & bm),
                    _ => (q & !bm) | (w.data & bm),
                });
                if r.access != Access::W1c && bm == 0xffff_ffff {
                    self.words[i] = Some(w.data);
                }
                self.words[i] = self.words[i].map(|v| v & m);
            }
        }
        for r in self
            .map
            .registers
            .iter()
            .filter(|r| r.access == Access::W1c)
        {
            let i = r.offset as usize;
            let m = self.map.mask[i];
            self.words[i] = self.words[i].map(|q| (q | set(r.offset)) & m);
        }
    }
}

/// The co-simulation top's hardware side (docs/accel-regs.md, "The co-simulation top"): the RO
/// value of offset `i` is `hw` rotated left by 5i mod 32.
pub fn top_ro(offset: u32, hw: u32) -> u32 {
    hw.rotate_left((5 * offset) % 32)
}

/// The W1C set bits of offset `i`: `hw` rotated left by 7i mod 32 while `hw_set` is high.
pub fn top_set(offset: u32, hw: u32, hw_set: bool) -> u32 {
    if hw_set {
        hw.rotate_left((7 * offset) % 32)
    } else {
        0
    }
}

/// One host transaction as the test bench's manager issues it (tb/axil_mgr.h).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxilTxn {
    pub read: bool,
    pub addr: u32,
    pub data: u32,
    pub strb: u32,
    /// Cycles AW (AR) waits after the channel's previous handshake.
    pub delay: u32,
    /// Cycles W waits after its previous handshake.
    pub w_delay: u32,
}

/// What a record reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AxilRecordKind {
    B,
    R,
    Irq,
}

/// One record of the manager: a response or an interrupt level change.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxilRecord {
    pub kind: AxilRecordKind,
    pub resp: u32,
    /// `hw_wr_stb_o` (B) or `hw_rd_stb_o` (R) in the response's first cycle.
    pub stb: bool,
    pub irq: bool,
    /// B: `hw_q_o` of the written offset in the first cycle of BVALID; R: RDATA.
    pub data: u32,
    /// B: first cycle of BVALID; R: cycle of the AR handshake; irq: the cycle (low 32 bits).
    pub at: u32,
    /// B: the later of the AW and W handshakes; R: the first cycle of RVALID.
    pub aux: u32,
}

/// Packs transactions and unpacks records (tb/axil_mgr.h).
#[derive(Debug, Clone, Copy, Default)]
pub struct AxilCodec;

impl StreamCodec for AxilCodec {
    type In = AxilTxn;
    type Out = AxilRecord;

    fn in_width(&self) -> u32 {
        128
    }

    fn out_width(&self) -> u32 {
        128
    }

    fn pack_in(&self, t: &AxilTxn) -> Vec<u32> {
        let mut w = vec![0u32; words_for(self.in_width())];
        w[0] = u32::from(t.read)
            | (t.strb & 0xf) << 4
            | (t.delay & 0xff) << 8
            | (t.w_delay & 0xff) << 16;
        w[1] = t.addr;
        w[2] = t.data;
        w
    }

    fn unpack_out(&self, w: &[u32]) -> AxilRecord {
        let at = |i: usize| w.get(i).copied().unwrap_or(0);
        let kind = match at(0) & 3 {
            0 => AxilRecordKind::B,
            1 => AxilRecordKind::R,
            _ => AxilRecordKind::Irq,
        };
        AxilRecord {
            kind,
            resp: at(0) >> 2 & 3,
            stb: at(0) >> 4 & 1 != 0,
            irq: at(0) >> 5 & 1 != 0,
            data: at(1),
            at: at(2),
            aux: at(3),
        }
    }
}

/// The hardware-side stimulus of the co-simulation top in `cycle` for a test bench seeded `seed`
/// (tb/axil_mgr.h, `axil_hw`): `hw_i` and `hw_set_i`.
pub fn top_stimulus(seed: u32, cycle: u64) -> (u32, bool) {
    let mut z = ((u64::from(seed) << 32) ^ cycle).wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    (z as u32, (z >> 32) & 7 == 0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::regs::cube5_axil_regs::{
        REG_ARG, REG_EVENTS, REG_EVENT_EN, REG_GO, REG_KEPT, REG_LIMITS, REG_SCRATCH, REG_SENSE,
    };

    fn none(_: u32) -> u32 {
        0
    }

    #[test]
    fn access_rules_of_the_exercise_map() {
        let mut f = RegFile::new(AxilMap::EXERCISE);
        assert_eq!(f.read(REG_SCRATCH, 0).data, Some(0xdead_beef));
        assert_eq!(f.read(REG_KEPT, 0).data, None);
        assert_eq!(f.read(REG_GO, 0).resp, RESP_SLVERR);
        assert_eq!(f.read(2, 0).resp, RESP_SLVERR);
        assert_eq!(f.write_resp(REG_SENSE), RESP_SLVERR);
        assert_eq!(f.write_resp(REG_ARG), RESP_OKAY);
        assert_eq!(f.read(REG_SENSE, u32::MAX).data, Some(0xc0ff_f007));
        // Byte strobes and the field mask.
        let w = |offset, data, strb| Some(BusWrite { offset, data, strb });
        f.edge(w(REG_LIMITS, 0xffff_ffff, 0b0010), &none);
        assert_eq!(f.read(REG_LIMITS, 0).data, Some(0xff05));
        // W1C: write 1 clears; a set in the same cycle wins.
        f.edge(None, &|o| if o == REG_EVENTS { 0xff00_00ff } else { 0 });
        assert_eq!(f.read(REG_EVENTS, 0).data, Some(0xff00_00ff));
        f.edge(w(REG_EVENT_EN, 0x01, 0xf), &none);
        assert_eq!(f.irq(), Some(true));
        f.edge(w(REG_EVENTS, 0x0000_0003, 0xf), &|o| {
            if o == REG_EVENTS {
                0x2
            } else {
                0
            }
        });
        assert_eq!(f.read(REG_EVENTS, 0).data, Some(0xff00_00fe));
        assert_eq!(f.irq(), Some(false));
        // Reset keeps a kept register, resets the others.
        f.edge(w(REG_KEPT, 7, 0xf), &none);
        f.reset();
        assert_eq!(f.read(REG_KEPT, 0).data, Some(7));
        assert_eq!(f.read(REG_LIMITS, 0).data, Some(0xa05));
        f.forget(REG_KEPT);
        assert_eq!(f.read(REG_KEPT, 0).data, None);
    }

    #[test]
    fn codec_round_trip_and_stimulus() {
        let c = AxilCodec;
        let t = AxilTxn {
            read: true,
            addr: 0x3c,
            data: 5,
            strb: 0xa,
            delay: 3,
            w_delay: 200,
        };
        assert_eq!(c.pack_in(&t), vec![0x00c8_03a1, 0x3c, 5, 0]);
        let r = c.unpack_out(&[1 | 2 << 2 | 1 << 4, 9, 10, 11]);
        assert_eq!(
            (r.kind, r.resp, r.stb, r.data),
            (AxilRecordKind::R, 2, true, 9)
        );
        assert_eq!(top_ro(1, 1), 32);
        assert_eq!(top_set(5, 1, true), 1 << 3);
        let sets = (0..8000).filter(|&c| top_stimulus(7, c).1).count();
        assert!((800..1200).contains(&sets), "{sets}");
        assert!(AxilConfig { map: 3, addr_w: 10 }.validate().is_err());
        assert!(AxilConfig { map: 1, addr_w: 5 }.validate().is_err());
    }
}
