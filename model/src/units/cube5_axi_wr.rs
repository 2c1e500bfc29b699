//! AXI4 burst write unit (`cube5_axi_wr`), written from `docs/numerics/axi_wr.md`: for a list of
//! write commands and the item stream, the bytes the memory holds afterwards, the bursts the unit
//! must issue on AW (the splitting rule, the same as the read unit's over the beats a command
//! covers), the beats and strobed bytes on W, and the completion stream (one per command of
//! nonzero length, in order, with the first non-OKAY BRESP of its bursts and a running count).
//!
//! Like `cube5_axi_rd` the unit is not one output per input, so it is modelled as functions of
//! the command list, the items and the memory; `StreamCodec` packs commands and unpacks
//! completions as the RTL ports carry them, and `pack_item` packs the data stream.

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::StreamCodec;
use crate::units::cube5_axi_rd::{AxiMemImage, AxiRdCmd, AxiRdConfig, Burst, RESP_OKAY};
use std::fmt;

/// The RTL parameters of one `cube5_axi_wr` configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxiWrConfig {
    /// Byte address width (13..=64).
    pub addr_w: u32,
    /// Data bus width in bits (a power of two, 8..=1024).
    pub data_w: u32,
    /// Item width in bits (a power of two, 8..=DataW).
    pub item_w: u32,
    /// Bits of a command's length in items (1..=32).
    pub len_w: u32,
    /// Longest burst in beats (a power of two, 2..=256, at most 4 KB).
    pub max_burst: u32,
    /// Bursts in flight at most (a power of two >= 2).
    pub outstanding: u32,
    /// AWID / BID width.
    pub id_w: u32,
}

impl AxiWrConfig {
    /// The RTL's parameter defaults.
    pub const DEFAULT: Self = Self {
        addr_w: 32,
        data_w: 64,
        item_w: 32,
        len_w: 16,
        max_burst: 16,
        outstanding: 4,
        id_w: 4,
    };

    /// The read unit with the same bus: its parameter rules and splitting rule are this unit's.
    fn bus(&self) -> AxiRdConfig {
        AxiRdConfig {
            addr_w: self.addr_w,
            data_w: self.data_w,
            len_w: self.len_w,
            max_burst: self.max_burst,
            outstanding: self.outstanding,
            id_w: self.id_w,
        }
    }

    pub fn validate(&self) -> Result<()> {
        self.bus().validate().map_err(|e| {
            ModelError::Config(e.to_string().replace("cube5_axi_rd", "cube5_axi_wr"))
        })?;
        if self.item_w < 8 || self.item_w > self.data_w || !self.item_w.is_power_of_two() {
            return Err(ModelError::Config(format!(
                "cube5_axi_wr: ItemW {} is not a power of two in 8..=DataW ({})",
                self.item_w, self.data_w
            )));
        }
        Ok(())
    }

    /// Bytes per beat, `DataW / 8`.
    pub fn bytes(&self) -> u32 {
        self.bus().bytes()
    }

    /// Bytes per item, `ItemW / 8`.
    pub fn item_bytes(&self) -> u32 {
        self.item_w / 8
    }

    /// AWSIZE: log2 of the bytes per beat (ARSIZE's rule).
    pub fn size(&self) -> u32 {
        self.bus().size()
    }

    /// The address space, `2^AddrW` bytes (`None` for 64 bits).
    pub fn address_space(&self) -> Option<u64> {
        self.bus().address_space()
    }

    fn wrap(&self, a: u64) -> u64 {
        self.bus().wrap(a)
    }

    /// Whether a command is well formed: the address aligned to an item, inside the address
    /// space, and the length fits `LenW` bits (the read unit's rule with an item for a beat).
    pub fn check_cmd(&self, cmd: &AxiWrCmd) -> Result<()> {
        let items = AxiRdConfig {
            data_w: self.item_w,
            ..self.bus()
        };
        items
            .check_cmd(&AxiRdCmd {
                addr: cmd.addr,
                len: cmd.len,
            })
            .map_err(|e| {
                let why = e.to_string();
                let why = why.rsplit("cube5_axi_rd: ").next().unwrap_or_default();
                ModelError::Config(format!("cube5_axi_wr: command {cmd}: {why}"))
            })
    }

    /// The beats a command covers: from its address rounded down to the bus, `ceil((lane + len)
    /// / Lanes)` beats, where `lane` is the item lane of the address in its beat.
    pub fn beats(&self, cmd: &AxiWrCmd) -> AxiRdCmd {
        let b = u64::from(self.bytes());
        let ib = u64::from(self.item_bytes());
        let lanes = b / ib;
        let lane = (cmd.addr % b) / ib;
        AxiRdCmd {
            addr: cmd.addr - cmd.addr % b,
            len: if cmd.len == 0 {
                0
            } else {
                (lane + u64::from(cmd.len)).div_ceil(lanes) as u32
            },
        }
    }

    /// The bursts of one command, in issue order: the read unit's rule over the command's beats.
    pub fn bursts(&self, cmd: &AxiWrCmd) -> Vec<Burst> {
        self.bus().bursts(&self.beats(cmd))
    }

    /// Everything the unit does for `cmds` with `items` (each `ItemW / 8` bytes, lowest address
    /// first) on the test bench memory `mem`, the first completion counted `done_before + 1`.
    /// Refuses items that do not match the commands' lengths.
    pub fn expected(
        &self,
        cmds: &[AxiWrCmd],
        items: &[Vec<u8>],
        mem: &AxiMemImage,
        done_before: u16,
    ) -> Result<AxiWrExpect> {
        let need: u64 = cmds.iter().map(|c| u64::from(c.len)).sum();
        let ib = self.item_bytes() as usize;
        if need != items.len() as u64 || items.iter().any(|i| i.len() != ib) {
            return Err(ModelError::Config(format!(
                "cube5_axi_wr: the commands take {need} items of {ib} bytes; {} given",
                items.len()
            )));
        }
        let b = u64::from(self.bytes());
        let mut out = AxiWrExpect {
            image: mem.bytes.clone(),
            ..Default::default()
        };
        let mut count = done_before;
        let mut next = 0usize;
        // The memory's answer for the beat at `a` (tb/axi_mem.h): DECERR outside the image,
        // SLVERR inside the window, else OKAY (written).
        let resp_of = |a: u64| mem.beat(a, self.bytes()).1;
        for cmd in cmds {
            if cmd.len == 0 {
                continue;
            }
            let bursts = self.bursts(cmd);
            let mut first_err = RESP_OKAY;
            for br in &bursts {
                let resp = (0..u64::from(br.beats))
                    .map(|i| resp_of(br.addr + i * b))
                    .max()
                    .unwrap_or(RESP_OKAY);
                if first_err == RESP_OKAY {
                    first_err = resp;
                }
                out.beats += u64::from(br.beats);
            }
            for k in 0..u64::from(cmd.len) {
                let at = self.wrap(cmd.addr + k * ib as u64);
                let item = &items[next];
                next += 1;
                out.strobed_bytes += ib as u64;
                if resp_of(at - at % b) == RESP_OKAY {
                    let off = (at - mem.base) as usize;
                    out.image[off..off + ib].copy_from_slice(item);
                }
            }
            count = count.wrapping_add(1);
            out.any_err |= first_err != RESP_OKAY;
            out.done.push(AxiWrDone {
                resp: first_err,
                count,
            });
            out.bursts.extend(bursts);
        }
        Ok(out)
    }

    /// One item as the RTL's `dat_data_i` words (its byte at the lowest address in bits 7:0).
    pub fn pack_item(&self, item: &[u8]) -> Vec<u32> {
        let mut w = BitWriter::new();
        for &x in item.iter().take(self.item_bytes() as usize) {
            w.put(u64::from(x), 8);
        }
        w.finish(self.item_w)
    }
}

/// A write command: `len` items to byte address `addr`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxiWrCmd {
    pub addr: u64,
    pub len: u32,
}

impl fmt::Display for AxiWrCmd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} items at {:#x}", self.len, self.addr)
    }
}

/// One completion: the first non-OKAY BRESP of the command's bursts (else OKAY) and the count of
/// commands completed since reset, this one included, mod 2^16.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxiWrDone {
    pub resp: u8,
    pub count: u16,
}

/// What a list of commands does: the memory afterwards, the AW bursts in order, the completions,
/// the W beats and strobed bytes, and whether `err_o` ends up set.
#[derive(Debug, Clone, Default)]
pub struct AxiWrExpect {
    pub image: Vec<u8>,
    pub bursts: Vec<Burst>,
    pub done: Vec<AxiWrDone>,
    pub beats: u64,
    pub strobed_bytes: u64,
    pub any_err: bool,
}

impl StreamCodec for AxiWrConfig {
    type In = AxiWrCmd;
    type Out = AxiWrDone;

    /// addr (AddrW), len (LenW), LSB first.
    fn in_width(&self) -> u32 {
        self.addr_w + self.len_w
    }

    /// resp (2), count (16), LSB first.
    fn out_width(&self) -> u32 {
        18
    }

    fn pack_in(&self, cmd: &AxiWrCmd) -> Vec<u32> {
        self.bus().pack_in(&AxiRdCmd {
            addr: cmd.addr,
            len: cmd.len,
        })
    }

    fn unpack_out(&self, words: &[u32]) -> AxiWrDone {
        let mut r = BitReader::new(words);
        let resp = r.get(2) as u8;
        let count = r.get(16) as u16;
        AxiWrDone { resp, count }
    }
}

// The RTL parameters of this unit (the RTL defaults are the model's `DEFAULT`).
crate::unit_config!(AxiWrConfig, "cube5_axi_wr", DEFAULT, {
    "AddrW" => addr_w,
    "DataW" => data_w,
    "ItemW" => item_w,
    "LenW" => len_w,
    "MaxBurst" => max_burst,
    "Outstanding" => outstanding,
    "IdW" => id_w,
});

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::cube5_axi_rd::{RESP_DECERR, RESP_SLVERR};

    const C: AxiWrConfig = AxiWrConfig::DEFAULT; // 4-byte items in 8-byte beats, bursts of 16

    #[test]
    fn a_command_covers_the_beats_its_items_touch() {
        // 3 items from byte 4: lanes 1, 0, 1 of beats 0, 1: two beats from 0.
        assert_eq!(
            C.beats(&AxiWrCmd { addr: 4, len: 3 }),
            AxiRdCmd { addr: 0, len: 2 }
        );
        assert_eq!(
            C.beats(&AxiWrCmd { addr: 8, len: 2 }),
            AxiRdCmd { addr: 8, len: 1 }
        );
        assert_eq!(
            C.beats(&AxiWrCmd { addr: 12, len: 1 }),
            AxiRdCmd { addr: 8, len: 1 }
        );
        assert_eq!(C.beats(&AxiWrCmd { addr: 12, len: 0 }).len, 0);
        // 4 KB rule over beats: 33 items from 0xffc cover 17 beats from 0xff8: 1 + 16.
        let b = C.bursts(&AxiWrCmd {
            addr: 0xffc,
            len: 33,
        });
        assert_eq!(
            b,
            vec![
                Burst {
                    addr: 0xff8,
                    beats: 1
                },
                Burst {
                    addr: 0x1000,
                    beats: 16
                }
            ]
        );
    }

    #[test]
    fn items_land_at_their_addresses_and_errors_write_nothing() {
        let mem = AxiMemImage {
            base: 0x100,
            bytes: vec![0; 0x100],
            slverr_lo: 0x180,
            slverr_hi: 0x188,
        };
        let cmds = [
            AxiWrCmd {
                addr: 0x104,
                len: 3,
            },
            AxiWrCmd { addr: 0, len: 0 },
            AxiWrCmd {
                addr: 0x17c,
                len: 2,
            }, // second item in the SLVERR beat
            AxiWrCmd {
                addr: 0x1fc,
                len: 2,
            }, // second item outside the image
        ];
        let items: Vec<Vec<u8>> = (1..=7u8).map(|k| vec![k; 4]).collect();
        let e = C.expected(&cmds, &items, &mem, 65535).unwrap();
        assert_eq!(&e.image[4..16], &[1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3]);
        assert_eq!(&e.image[0x7c..0x80], &[4; 4]);
        assert_eq!(&e.image[0x80..0x84], &[0; 4]);
        assert_eq!(&e.image[0xfc..0x100], &[6; 4]);
        assert_eq!(
            e.done,
            vec![
                AxiWrDone {
                    resp: RESP_OKAY,
                    count: 0
                },
                AxiWrDone {
                    resp: RESP_SLVERR,
                    count: 1
                },
                AxiWrDone {
                    resp: RESP_DECERR,
                    count: 2
                }
            ]
        );
        assert!(e.any_err);
        assert_eq!(e.strobed_bytes, 28);
        assert_eq!(e.beats, 2 + 2 + 2);
        assert!(C.expected(&cmds, &items[1..], &mem, 0).is_err());
    }

    #[test]
    fn the_codec_packs_commands_items_and_unpacks_completions() {
        assert_eq!(
            C.pack_in(&AxiWrCmd {
                addr: 0x1234_5670,
                len: 0xbeef
            }),
            vec![0x1234_5670, 0xbeef]
        );
        assert_eq!(C.pack_item(&[1, 2, 3, 4]), vec![0x0403_0201]);
        assert_eq!(
            C.unpack_out(&[0b1_0000_0000_0000_0111]),
            AxiWrDone {
                resp: 3,
                count: 0x4001
            }
        );
    }

    #[test]
    fn bad_parameters_and_commands_are_refused() {
        for bad in [
            AxiWrConfig { item_w: 128, ..C },
            AxiWrConfig { item_w: 24, ..C },
            AxiWrConfig { item_w: 4, ..C },
            AxiWrConfig { max_burst: 12, ..C },
            AxiWrConfig { addr_w: 12, ..C },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        assert!(C.validate().is_ok());
        assert!(C.check_cmd(&AxiWrCmd { addr: 2, len: 1 }).is_err());
        assert!(C.check_cmd(&AxiWrCmd { addr: 4, len: 1 }).is_ok());
        assert!(C
            .check_cmd(&AxiWrCmd {
                addr: 0,
                len: 1 << 16
            })
            .is_err());
    }
}
