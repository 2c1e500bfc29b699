//! The host driver of the accelerator's AXI4-Lite registers (docs/accel-regs.md, "Driving it from a
//! host"), built only on the generated map `crate::regs::cube5_accel` (offsets, fields, encodings):
//! write a frame's registers and the AXI4 base addresses, load a table through the window, start,
//! wait for the end of the frame by polling or by the interrupt, read the counters.
//!
//! The bus is a trait, [`RegBus`], so the same driver runs against the register-file model, the
//! RTL in co-simulation (`cube5_tb::axil`) or a real device (a memory-mapped window).

use crate::regmap::Field;
use crate::regs::cube5_accel::{
    REG_CTRL, REG_CTRL_SOFT_RESET, REG_CTRL_START, REG_CYCLE_HI, REG_CYCLE_LO, REG_DIMS, REG_DX,
    REG_DY, REG_IMG_BASE_HI, REG_IMG_BASE_LO, REG_IRQ_ENABLE, REG_IRQ_ENABLE_DONE,
    REG_IRQ_ENABLE_ERROR, REG_IRQ_STATUS, REG_IRQ_STATUS_DONE, REG_IRQ_STATUS_ERROR, REG_MODE,
    REG_SAMPLE_HI, REG_SAMPLE_LO, REG_SKIP, REG_STATUS, REG_STATUS_BUSY, REG_STATUS_DONE,
    REG_STATUS_ERROR, REG_TABLE_ADDR, REG_TABLE_ADDR_INDEX, REG_TABLE_ADDR_TABLE, REG_TABLE_DATA,
    REG_VIEW, REG_VOL_BASE_HI, REG_VOL_BASE_LO, TABLE_BLOCK, TABLE_CLASS, TABLE_OPACITY,
    TABLE_REFLECT,
};
pub use crate::units::cube5_accel_ctrl::FrameRegs;
use std::fmt;

/// Bytes per register: the AXI4-Lite data bus is 32 bits (`cube5-gen` refuses an `axil` map with
/// another `word_bytes`).
pub const WORD_BYTES: u64 = 4;

/// A 32-bit register bus at byte addresses.
pub trait RegBus {
    type Error: fmt::Display;
    fn read(&mut self, addr: u64) -> Result<u32, Self::Error>;
    fn write(&mut self, addr: u64, data: u32) -> Result<(), Self::Error>;
}

/// What went wrong while driving the accelerator.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum HostError<E: fmt::Display> {
    #[error("register bus: {0}")]
    Bus(E),
    #[error("the frame did not finish within {0} polls")]
    Timeout(u64),
    #[error("the accelerator reported an error (Status {0:#x})")]
    Frame(u32),
    #[error("refused: {0}")]
    Refused(String),
}

/// The Status register, decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Status {
    pub busy: bool,
    pub done: bool,
    pub error: bool,
}

/// The counters of the last (or current) frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Counters {
    pub cycles: u64,
    pub samples: u64,
}

/// The tables the window loads (`Table` encodings).
pub const TABLES: [u32; 4] = [TABLE_BLOCK, TABLE_CLASS, TABLE_REFLECT, TABLE_OPACITY];

fn bit(f: Field, word: u32) -> bool {
    f.get(u64::from(word)) != 0
}

fn word(fields: &[(Field, u64)]) -> u32 {
    fields.iter().fold(0u64, |w, &(f, v)| f.set(w, v)) as u32
}

/// The driver: a bus and the byte address of register offset 0.
pub struct AccelHost<B: RegBus> {
    bus: B,
    base: u64,
}

impl<B: RegBus> AccelHost<B> {
    pub fn new(bus: B, base: u64) -> Self {
        Self { bus, base }
    }

    pub fn bus(&mut self) -> &mut B {
        &mut self.bus
    }

    pub fn into_bus(self) -> B {
        self.bus
    }

    /// The byte address of register `offset`.
    pub fn addr(&self, offset: u32) -> u64 {
        self.base + u64::from(offset) * WORD_BYTES
    }

    pub fn read(&mut self, offset: u32) -> Result<u32, HostError<B::Error>> {
        let a = self.addr(offset);
        self.bus.read(a).map_err(HostError::Bus)
    }

    pub fn write(&mut self, offset: u32, data: u32) -> Result<(), HostError<B::Error>> {
        let a = self.addr(offset);
        self.bus.write(a, data).map_err(HostError::Bus)
    }

    /// Writes a frame's set-up registers.
    pub fn write_frame(&mut self, f: &FrameRegs) -> Result<(), HostError<B::Error>> {
        for (r, w) in f.writes() {
            self.write(r, w)?;
        }
        Ok(())
    }

    /// Reads the frame's set-up registers back.
    pub fn read_frame(&mut self) -> Result<FrameRegs, HostError<B::Error>> {
        Ok(FrameRegs {
            dims: self.read(REG_DIMS)?,
            view: self.read(REG_VIEW)?,
            dx: self.read(REG_DX)?,
            dy: self.read(REG_DY)?,
            mode: self.read(REG_MODE)?,
            skip: self.read(REG_SKIP)?,
        })
    }

    /// The AXI4 base addresses of the volume and of the base-plane image (low word first).
    pub fn set_bases(&mut self, volume: u64, image: u64) -> Result<(), HostError<B::Error>> {
        self.write(REG_VOL_BASE_LO, volume as u32)?;
        self.write(REG_VOL_BASE_HI, (volume >> 32) as u32)?;
        self.write(REG_IMG_BASE_LO, image as u32)?;
        self.write(REG_IMG_BASE_HI, (image >> 32) as u32)
    }

    /// The image's row pitch in bytes (`ImgPitch`): row `r` starts at the image base + `r pitch`.
    /// 0 asks for the smallest legal pitch (a row of `W` pixels rounded up to `P`); otherwise a
    /// multiple of the row alignment (32 bytes serves every build) and at least the row's bytes,
    /// else the frame is refused with `Status.code` `Pitch`.
    pub fn set_pitch(&mut self, pitch: u32) -> Result<(), HostError<B::Error>> {
        self.write(crate::regs::cube5_accel::REG_IMG_PITCH, pitch)
    }

    /// ParkBase: the scratch area of the parked coxels, for builds with the compositing window
    /// (`Window = 1`; `Wp H Cx` bytes, docs/accel.md); the others ignore it.
    pub fn set_park_base(&mut self, park: u64) -> Result<(), HostError<B::Error>> {
        use crate::regs::cube5_accel::{REG_PARK_BASE_HI, REG_PARK_BASE_LO};
        self.write(REG_PARK_BASE_LO, park as u32)?;
        self.write(REG_PARK_BASE_HI, (park >> 32) as u32)
    }

    /// Loads `words` into entries `first ..` of `table` (a `Table` encoding) through the window:
    /// one TableAddr write, then one TableData write per word (the core steps the index).
    pub fn load_table(
        &mut self,
        table: u32,
        first: u32,
        words: &[u32],
    ) -> Result<(), HostError<B::Error>> {
        let entries = 1u64 << REG_TABLE_ADDR_INDEX.width;
        if !TABLES.contains(&table) {
            return Err(HostError::Refused(format!(
                "table {table} is not a Table encoding"
            )));
        }
        if u64::from(first) + words.len() as u64 > entries {
            return Err(HostError::Refused(format!(
                "entries {first}..{} pass the window's {entries}",
                u64::from(first) + words.len() as u64
            )));
        }
        self.write(
            REG_TABLE_ADDR,
            word(&[
                (REG_TABLE_ADDR_INDEX, u64::from(first)),
                (REG_TABLE_ADDR_TABLE, u64::from(table)),
            ]),
        )?;
        for &w in words {
            self.write(REG_TABLE_DATA, w)?;
        }
        Ok(())
    }

    /// Enables the interrupt for the end of a frame and for an error.
    pub fn enable_irq(&mut self, done: bool, error: bool) -> Result<(), HostError<B::Error>> {
        self.write(
            REG_IRQ_ENABLE,
            word(&[
                (REG_IRQ_ENABLE_DONE, u64::from(done)),
                (REG_IRQ_ENABLE_ERROR, u64::from(error)),
            ]),
        )
    }

    /// Starts a frame with the registers as they are.
    pub fn start(&mut self) -> Result<(), HostError<B::Error>> {
        self.write(REG_CTRL, word(&[(REG_CTRL_START, 1)]))
    }

    /// Abandons the frame in progress.
    pub fn soft_reset(&mut self) -> Result<(), HostError<B::Error>> {
        self.write(REG_CTRL, word(&[(REG_CTRL_SOFT_RESET, 1)]))
    }

    pub fn status(&mut self) -> Result<Status, HostError<B::Error>> {
        let s = self.read(REG_STATUS)?;
        Ok(Status {
            busy: bit(REG_STATUS_BUSY, s),
            done: bit(REG_STATUS_DONE, s),
            error: bit(REG_STATUS_ERROR, s),
        })
    }

    /// Whether the interrupt line is high: (IrqStatus & IrqEnable) != 0, read over the bus.
    pub fn irq_pending(&mut self) -> Result<bool, HostError<B::Error>> {
        Ok(self.read(REG_IRQ_STATUS)? & self.read(REG_IRQ_ENABLE)? != 0)
    }

    /// Polls IrqStatus until the frame is done or failed (at most `max_polls` reads), clears the
    /// bits it saw (write 1 to clear) and returns the Status; an error bit is an error.
    pub fn wait_done(&mut self, max_polls: u64) -> Result<Status, HostError<B::Error>> {
        let mask = word(&[(REG_IRQ_STATUS_DONE, 1), (REG_IRQ_STATUS_ERROR, 1)]);
        for _ in 0..max_polls {
            let s = self.read(REG_IRQ_STATUS)? & mask;
            if s != 0 {
                self.write(REG_IRQ_STATUS, s)?;
                if bit(REG_IRQ_STATUS_ERROR, s) {
                    let st = self.read(REG_STATUS)?;
                    return Err(HostError::Frame(st));
                }
                return self.status();
            }
        }
        Err(HostError::Timeout(max_polls))
    }

    /// The cycle and sample counters: each low word first (reading it latches the high word).
    pub fn counters(&mut self) -> Result<Counters, HostError<B::Error>> {
        let c_lo = self.read(REG_CYCLE_LO)?;
        let c_hi = self.read(REG_CYCLE_HI)?;
        let s_lo = self.read(REG_SAMPLE_LO)?;
        let s_hi = self.read(REG_SAMPLE_HI)?;
        Ok(Counters {
            cycles: u64::from(c_hi) << 32 | u64::from(c_lo),
            samples: u64::from(s_hi) << 32 | u64::from(s_lo),
        })
    }
}

/// Additions for the control core `cube5_accel_ctrl` (docs/numerics/accel_ctrl.md): the reason a
/// frame was refused or stopped, and the table window's position.
impl<B: RegBus> AccelHost<B> {
    /// `Status.code`: a `Code` encoding (`crate::regs::cube5_accel::CODE_*`), 0 while busy and
    /// after a frame without error.
    pub fn status_code(&mut self) -> Result<u32, HostError<B::Error>> {
        let s = self.read(crate::regs::cube5_accel::REG_STATUS)?;
        Ok(crate::regs::cube5_accel::REG_STATUS_CODE.get(u64::from(s)) as u32)
    }

    /// `TablePos`: the (table, index) the next TableData write goes to, as the core holds them.
    pub fn table_pos(&mut self) -> Result<(u32, u32), HostError<B::Error>> {
        use crate::regs::cube5_accel::{REG_TABLE_POS, REG_TABLE_POS_INDEX, REG_TABLE_POS_TABLE};
        let w = u64::from(self.read(REG_TABLE_POS)?);
        Ok((
            REG_TABLE_POS_TABLE.get(w) as u32,
            REG_TABLE_POS_INDEX.get(w) as u32,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::cube5_axil::{AxilMap, BusWrite, RegFile, RESP_OKAY};

    /// The register-file model with a pretend core behind it: `start` makes it busy for `frame`
    /// bus accesses, then it sets done (or error) in IrqStatus; counters count accesses.
    struct FakeAccel {
        file: RegFile,
        frame: u32,
        left: Option<u32>,
        fail: bool,
        accesses: u64,
        table_log: Vec<(u32, u32, u32)>,
        table_at: (u32, u32),
    }

    impl FakeAccel {
        fn new(frame: u32, fail: bool) -> Self {
            Self {
                file: RegFile::new(AxilMap::ACCEL),
                frame,
                left: None,
                fail,
                accesses: 0,
                table_log: Vec::new(),
                table_at: (0, 0),
            }
        }

        fn tick(&mut self, write: Option<BusWrite>) {
            self.accesses += 1;
            let mut set = 0;
            if let Some(n) = self.left {
                if n == 0 {
                    set = if self.fail { 2 } else { 1 };
                    self.left = None;
                } else {
                    self.left = Some(n - 1);
                }
            }
            self.file
                .edge(write, &|o| if o == REG_IRQ_STATUS { set } else { 0 });
        }
    }

    impl RegBus for FakeAccel {
        type Error = String;
        fn read(&mut self, addr: u64) -> Result<u32, String> {
            let o = (addr / WORD_BYTES) as u32;
            let ro = match o {
                REG_STATUS => u32::from(self.left.is_some()) | u32::from(self.fail) << 2,
                REG_CYCLE_LO => self.accesses as u32,
                REG_CYCLE_HI => 7,
                _ => 0,
            };
            let a = self.file.read(o, ro);
            self.tick(None);
            match (a.resp, a.data) {
                (RESP_OKAY, Some(d)) => Ok(d),
                (r, _) => Err(format!("read {addr:#x}: resp {r}")),
            }
        }
        fn write(&mut self, addr: u64, data: u32) -> Result<(), String> {
            let o = (addr / WORD_BYTES) as u32;
            if self.file.write_resp(o) != RESP_OKAY {
                return Err(format!("write {addr:#x}: SLVERR"));
            }
            if o == REG_CTRL && data & 1 != 0 {
                self.left = Some(self.frame);
            }
            if o == REG_TABLE_ADDR {
                self.table_at = (data >> 16, data & 0xffff);
            }
            if o == REG_TABLE_DATA {
                self.table_log
                    .push((self.table_at.0, self.table_at.1, data));
                self.table_at.1 += 1;
            }
            self.tick(Some(BusWrite {
                offset: o,
                data,
                strb: 0xf,
            }));
            Ok(())
        }
    }

    #[test]
    fn a_frame_through_the_driver() {
        let mut h = AccelHost::new(FakeAccel::new(5, false), 0);
        let f = FrameRegs::EXAMPLE;
        h.write_frame(&f).unwrap();
        assert_eq!(h.read_frame().unwrap(), f);
        h.set_bases(0x1_2345_6780, 0x8000_0000).unwrap();
        assert_eq!(h.read(REG_VOL_BASE_HI).unwrap(), 1);
        h.set_pitch(2048).unwrap();
        assert_eq!(
            h.read(crate::regs::cube5_accel::REG_IMG_PITCH).unwrap(),
            2048
        );
        h.load_table(TABLE_CLASS, 10, &[1, 2, 3]).unwrap();
        assert_eq!(h.bus().table_log, vec![(1, 10, 1), (1, 11, 2), (1, 12, 3)]);
        assert!(h.load_table(9, 0, &[1]).is_err());
        assert!(h.load_table(TABLE_BLOCK, 65535, &[1, 2]).is_err());
        h.enable_irq(true, true).unwrap();
        h.start().unwrap();
        assert!(h.status().unwrap().busy);
        let st = h.wait_done(100).unwrap();
        assert!(!st.busy);
        assert!(!h.irq_pending().unwrap(), "wait_done cleared the interrupt");
        let c = h.counters().unwrap();
        assert_eq!(c.cycles >> 32, 7);
    }

    #[test]
    fn errors_and_timeouts_are_reported() {
        let mut h = AccelHost::new(FakeAccel::new(3, true), 0);
        h.start().unwrap();
        assert!(matches!(h.wait_done(50), Err(HostError::Frame(_))));
        let mut h = AccelHost::new(FakeAccel::new(1000, false), 0);
        h.start().unwrap();
        assert_eq!(h.wait_done(10), Err(HostError::Timeout(10)));
    }
}
