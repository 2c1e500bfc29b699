//! AXI4 burst read unit (`cube5_axi_rd`), written from `docs/numerics/axi_rd.md`: what the output
//! stream of a list of read commands is (the memory's bytes of each command, in command order,
//! beat by beat, with the command's last beat flagged and each beat's RRESP), and the bursts the
//! unit must issue on AR for them (the splitting rule), so a test checks both channels.
//!
//! The unit is not one output per input (a command yields `len` beats), so it is modelled as
//! functions of the command list and the memory rather than as a `StreamUnit`; `StreamCodec`
//! packs commands and unpacks beats as the RTL ports carry them.

use crate::bits::{BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::unit::StreamCodec;
use std::fmt;

/// The RTL parameters of one `cube5_axi_rd` configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxiRdConfig {
    /// Byte address width (13..=64).
    pub addr_w: u32,
    /// Data bus width in bits (a power of two, 8..=1024).
    pub data_w: u32,
    /// Bits of a command's length in beats (1..=32).
    pub len_w: u32,
    /// Longest burst in beats (a power of two, 2..=256, at most 4 KB).
    pub max_burst: u32,
    /// Bursts in flight at most (a power of two >= 2).
    pub outstanding: u32,
    /// ARID / RID width.
    pub id_w: u32,
}

impl AxiRdConfig {
    /// The RTL's parameter defaults.
    pub const DEFAULT: Self = Self {
        addr_w: 32,
        data_w: 64,
        len_w: 16,
        max_burst: 16,
        outstanding: 4,
        id_w: 4,
    };

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("cube5_axi_rd: {what}")));
        if !(8..=1024).contains(&self.data_w) || !self.data_w.is_power_of_two() {
            return bad(format!(
                "DataW {} is not a power of two in 8..=1024",
                self.data_w
            ));
        }
        if !(2..=256).contains(&self.max_burst)
            || !self.max_burst.is_power_of_two()
            || self.max_burst * self.bytes() > 4096
        {
            return bad(format!(
                "MaxBurst {} is not a power of two in 2..=256 with MaxBurst * DataW/8 <= 4096",
                self.max_burst
            ));
        }
        if self.outstanding < 2 || !self.outstanding.is_power_of_two() {
            return bad(format!(
                "Outstanding {} is not a power of two >= 2",
                self.outstanding
            ));
        }
        if !(13..=64).contains(&self.addr_w) {
            return bad(format!("AddrW {} outside 13..=64", self.addr_w));
        }
        if !(1..=32).contains(&self.len_w) {
            return bad(format!("LenW {} outside 1..=32", self.len_w));
        }
        if !(1..=32).contains(&self.id_w) {
            return bad(format!("IdW {} outside 1..=32", self.id_w));
        }
        Ok(())
    }

    /// Bytes per beat, `DataW / 8`.
    pub fn bytes(&self) -> u32 {
        self.data_w / 8
    }

    /// ARSIZE: log2 of the bytes per beat.
    pub fn size(&self) -> u32 {
        self.bytes().trailing_zeros()
    }

    /// Return-FIFO words, `MaxBurst * Outstanding` (the credit pool).
    pub fn fifo_depth(&self) -> u32 {
        self.max_burst * self.outstanding
    }

    /// The address space, `2^AddrW` bytes (`None` for 64 bits).
    pub fn address_space(&self) -> Option<u64> {
        1u64.checked_shl(self.addr_w)
    }

    /// Wraps `a` into the address space.
    pub(crate) fn wrap(&self, a: u64) -> u64 {
        self.address_space().map_or(a, |s| a & (s - 1))
    }

    /// Whether a command is well formed: the address aligned to the bus, inside the address
    /// space, and the length fits `LenW` bits.
    pub fn check_cmd(&self, cmd: &AxiRdCmd) -> Result<()> {
        if !cmd.addr.is_multiple_of(u64::from(self.bytes())) {
            return Err(ModelError::Config(format!(
                "cube5_axi_rd: command address {:#x} not aligned to {} bytes",
                cmd.addr,
                self.bytes()
            )));
        }
        if self.wrap(cmd.addr) != cmd.addr || (self.len_w < 32 && cmd.len >> self.len_w != 0) {
            return Err(ModelError::Config(format!(
                "cube5_axi_rd: command {cmd} does not fit AddrW {} / LenW {}",
                self.addr_w, self.len_w
            )));
        }
        Ok(())
    }

    /// The bursts of one command, in issue order (the splitting rule): from the current address,
    /// `min(remaining, MaxBurst, beats to the next 4 KB boundary)` beats, until none remain.
    /// Addresses wrap at the top of the address space (a 4 KB boundary, so no burst crosses it).
    pub fn bursts(&self, cmd: &AxiRdCmd) -> Vec<Burst> {
        let bytes = u64::from(self.bytes());
        let mut out = Vec::new();
        let mut addr = cmd.addr;
        let mut rem = u64::from(cmd.len);
        while rem > 0 {
            let to_4k = (4096 - (addr & 4095)) / bytes;
            let beats = rem.min(u64::from(self.max_burst)).min(to_4k);
            out.push(Burst {
                addr,
                beats: beats as u32,
            });
            addr = self.wrap(addr + beats * bytes);
            rem -= beats;
        }
        out
    }

    /// The output stream and the AR sequence for `cmds` read from `mem`.
    pub fn expected(&self, cmds: &[AxiRdCmd], mem: &AxiMemImage) -> (Vec<AxiRdBeat>, Vec<Burst>) {
        let bytes = u64::from(self.bytes());
        let mut beats = Vec::new();
        let mut bursts = Vec::new();
        for cmd in cmds {
            let bs = self.bursts(cmd);
            let n = bs.len();
            for (k, b) in bs.iter().enumerate() {
                for i in 0..u64::from(b.beats) {
                    let (data, resp) = mem.beat(b.addr + i * bytes, self.bytes());
                    beats.push(AxiRdBeat {
                        data,
                        last: k + 1 == n && i + 1 == u64::from(b.beats),
                        resp,
                    });
                }
            }
            bursts.extend(bs);
        }
        (beats, bursts)
    }
}

/// A read command: `len` beats from byte address `addr`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxiRdCmd {
    pub addr: u64,
    pub len: u32,
}

impl fmt::Display for AxiRdCmd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} beats at {:#x}", self.len, self.addr)
    }
}

/// One burst on AR: ARADDR and the beat count (ARLEN + 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Burst {
    pub addr: u64,
    pub beats: u32,
}

/// RRESP encodings (AXI4).
pub const RESP_OKAY: u8 = 0;
pub const RESP_SLVERR: u8 = 2;
pub const RESP_DECERR: u8 = 3;

/// One output beat: the bus word (bytes, lowest address first), whether it ends its command, and
/// the RRESP it came with.
#[derive(Clone, PartialEq, Eq)]
pub struct AxiRdBeat {
    pub data: Vec<u8>,
    pub last: bool,
    pub resp: u8,
}

impl fmt::Debug for AxiRdBeat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "AxiRdBeat {{ data: 0x")?;
        for b in self.data.iter().rev() {
            write!(f, "{b:02x}")?;
        }
        write!(f, ", last: {}, resp: {} }}", self.last, self.resp)
    }
}

/// The test bench memory's answers (tb/axi_mem.h): one image of bytes from `base`; a beat wholly
/// inside it is OKAY with its bytes (SLVERR with zero data inside `[slverr_lo, slverr_hi)`), any
/// other beat DECERR with zero data.
#[derive(Debug, Clone, Default)]
pub struct AxiMemImage {
    pub base: u64,
    pub bytes: Vec<u8>,
    pub slverr_lo: u64,
    pub slverr_hi: u64,
}

impl AxiMemImage {
    /// The data and RRESP of the `n`-byte beat at `addr`.
    pub fn beat(&self, addr: u64, n: u32) -> (Vec<u8>, u8) {
        let n64 = u64::from(n);
        let zero = vec![0u8; n as usize];
        if addr < self.base || addr - self.base + n64 > self.bytes.len() as u64 {
            (zero, RESP_DECERR)
        } else if addr >= self.slverr_lo && addr < self.slverr_hi {
            (zero, RESP_SLVERR)
        } else {
            let at = (addr - self.base) as usize;
            (self.bytes[at..at + n as usize].to_vec(), RESP_OKAY)
        }
    }
}

impl StreamCodec for AxiRdConfig {
    type In = AxiRdCmd;
    type Out = AxiRdBeat;

    /// addr (AddrW), len (LenW), LSB first.
    fn in_width(&self) -> u32 {
        self.addr_w + self.len_w
    }

    /// data (DataW), last (1), resp (2), LSB first.
    fn out_width(&self) -> u32 {
        self.data_w + 3
    }

    fn pack_in(&self, cmd: &AxiRdCmd) -> Vec<u32> {
        let mut w = BitWriter::new();
        if self.addr_w > 32 {
            w.put(cmd.addr & 0xffff_ffff, 32);
            w.put(cmd.addr >> 32, self.addr_w - 32);
        } else {
            w.put(cmd.addr, self.addr_w);
        }
        w.put(u64::from(cmd.len), self.len_w);
        w.finish(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> AxiRdBeat {
        let mut r = BitReader::new(words);
        let data = (0..self.bytes()).map(|_| r.get(8) as u8).collect();
        let last = r.get_bool();
        let resp = r.get(2) as u8;
        AxiRdBeat { data, last, resp }
    }
}

// The RTL parameters of this unit (the RTL defaults are the model's `DEFAULT`).
crate::unit_config!(AxiRdConfig, "cube5_axi_rd", DEFAULT, {
    "AddrW" => addr_w,
    "DataW" => data_w,
    "LenW" => len_w,
    "MaxBurst" => max_burst,
    "Outstanding" => outstanding,
    "IdW" => id_w,
});

#[cfg(test)]
mod tests {
    use super::*;

    const C: AxiRdConfig = AxiRdConfig::DEFAULT; // 8-byte beats, bursts of 16

    #[test]
    fn a_command_splits_at_max_burst_and_at_4k() {
        // 40 beats from 0xf80: 16 beats to 0x1000 (the 4 KB boundary), then 16, then 8.
        let b = C.bursts(&AxiRdCmd {
            addr: 0xf80,
            len: 40,
        });
        let want = [(0xf80, 16), (0x1000, 16), (0x1080, 8)];
        assert_eq!(b.len(), 3);
        for (got, (a, n)) in b.iter().zip(want) {
            assert_eq!((got.addr, got.beats), (a, n));
        }
        // 3 beats before the boundary: a short burst first.
        let b = C.bursts(&AxiRdCmd {
            addr: 0x1fe8,
            len: 20,
        });
        assert_eq!(
            b[0],
            Burst {
                addr: 0x1fe8,
                beats: 3
            }
        );
        assert_eq!(
            b[1],
            Burst {
                addr: 0x2000,
                beats: 16
            }
        );
        assert_eq!(
            b[2],
            Burst {
                addr: 0x2080,
                beats: 1
            }
        );
        for x in &b {
            assert!((x.addr & 4095) + u64::from(x.beats) * 8 <= 4096);
        }
    }

    #[test]
    fn zero_length_issues_nothing_and_length_one_is_one_beat() {
        assert!(C.bursts(&AxiRdCmd { addr: 8, len: 0 }).is_empty());
        let mem = AxiMemImage {
            base: 0,
            bytes: (0..64).collect(),
            ..Default::default()
        };
        let (beats, bursts) = C.expected(&[AxiRdCmd { addr: 8, len: 1 }], &mem);
        assert_eq!(bursts, vec![Burst { addr: 8, beats: 1 }]);
        assert_eq!(beats.len(), 1);
        assert_eq!(beats[0].data, (8..16).collect::<Vec<u8>>());
        assert!(beats[0].last);
        assert_eq!(beats[0].resp, RESP_OKAY);
    }

    #[test]
    fn addresses_wrap_at_the_top_of_the_address_space() {
        let c = AxiRdConfig {
            addr_w: 16,
            data_w: 32,
            max_burst: 4,
            outstanding: 2,
            ..AxiRdConfig::DEFAULT
        };
        let b = c.bursts(&AxiRdCmd {
            addr: 0xfff8,
            len: 4,
        });
        assert_eq!(
            b,
            vec![
                Burst {
                    addr: 0xfff8,
                    beats: 2
                },
                Burst { addr: 0, beats: 2 }
            ]
        );
    }

    #[test]
    fn beats_outside_the_image_are_decerr_and_the_error_window_slverr() {
        let mem = AxiMemImage {
            base: 0x100,
            bytes: vec![0xab; 0x100],
            slverr_lo: 0x180,
            slverr_hi: 0x188,
        };
        assert_eq!(mem.beat(0xf8, 8).1, RESP_DECERR);
        assert_eq!(mem.beat(0x100, 8), (vec![0xab; 8], RESP_OKAY));
        assert_eq!(mem.beat(0x180, 8), (vec![0; 8], RESP_SLVERR));
        assert_eq!(mem.beat(0x1f8, 8).1, RESP_OKAY);
        assert_eq!(mem.beat(0x200, 8).1, RESP_DECERR);
    }

    #[test]
    fn the_codec_packs_address_then_length_and_unpacks_data_last_resp() {
        let c = AxiRdConfig { data_w: 128, ..C };
        let w = c.pack_in(&AxiRdCmd {
            addr: 0x1234_5670,
            len: 0xbeef,
        });
        assert_eq!(w, vec![0x1234_5670, 0xbeef]);
        let beat = c.unpack_out(&[0x0302_0100, 0x0706_0504, 0x0b0a_0908, 0x0f0e_0d0c, 0b101]);
        assert_eq!(beat.data, (0..16).collect::<Vec<u8>>());
        assert!(beat.last);
        assert_eq!(beat.resp, 2);
    }

    #[test]
    fn bad_parameters_are_refused() {
        for bad in [
            AxiRdConfig { data_w: 48, ..C },
            AxiRdConfig { max_burst: 12, ..C },
            AxiRdConfig {
                max_burst: 256,
                data_w: 256,
                ..C
            },
            AxiRdConfig {
                outstanding: 1,
                ..C
            },
            AxiRdConfig { addr_w: 12, ..C },
            AxiRdConfig { max_burst: 1, ..C },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        assert!(C.check_cmd(&AxiRdCmd { addr: 4, len: 1 }).is_err());
    }
}
