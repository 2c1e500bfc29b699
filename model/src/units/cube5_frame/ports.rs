//! The frame's stream ports as the RTL carries them (docs/numerics/frame.md, "RTL configuration
//! map" and "Sections"): with `Source = 0` one input item is a command (`op`, 2 bits); with
//! `Source = 1` an item is a section command or a beat of the section's voxels (a kind bit
//! first). Either way an output item is `OutLanes` coxels of a row with the frame's status.

use crate::bits::{BitReader, BitWriter};
use crate::regs::cube5_frame::{KIND_BEAT, KIND_CMD};
use crate::unit::StreamCodec;
use crate::units::cube5_compos::{self, Coxel};
use crate::units::cube5_frame::FrameConfig;
use crate::units::cube5_section_buf::Beam;

/// One output item: a base-plane coxel and the frame's status. With `OutLanes = P` an item holds
/// P pixels of a row: `coxel` is the first, `rest` the others.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameOut {
    pub coxel: Coxel,
    pub rest: Vec<Coxel>,
    pub error: bool,
    /// Memory beats the sweep read from the modules.
    pub reads: u32,
    /// The sweep counter: command accepted to read-out start.
    pub cycles: u32,
}

/// A section command: `op`, the first anchor, the columns, first and last section of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SecCmd {
    pub op: u32,
    pub a0: u32,
    pub ns: u32,
    pub first: bool,
    pub last: bool,
}

/// One input item of a stream frame (`Source = 1`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StreamIn {
    Cmd(SecCmd),
    Beat(Beam),
}

/// `Source = 0`: a command in (`op`), the frame's output items out.
impl StreamCodec for FrameConfig {
    type In = u32;
    type Out = FrameOut;

    fn in_width(&self) -> u32 {
        2
    }

    fn out_width(&self) -> u32 {
        self.out_lanes as u32 * self.compos.coxel_w() + 1 + 64
    }

    fn pack_in(&self, op: &u32) -> Vec<u32> {
        let mut w = BitWriter::new();
        w.put(u64::from(*op), 2);
        w.finish(2)
    }

    fn unpack_out(&self, words: &[u32]) -> FrameOut {
        let mut r = BitReader::new(words);
        let coxel = cube5_compos::get_coxel(&mut r, &self.compos);
        let rest = (1..self.out_lanes)
            .map(|_| cube5_compos::get_coxel(&mut r, &self.compos))
            .collect();
        FrameOut {
            coxel,
            rest,
            error: r.get_bool(),
            reads: r.get(32) as u32,
            cycles: r.get(32) as u32,
        }
    }
}

/// The stream frame's codec: commands and beats in, the frame's output items out.
#[derive(Debug, Clone, Copy)]
pub struct StreamFrame(pub FrameConfig);

impl StreamFrame {
    fn m(&self) -> u32 {
        self.0.max_dim_log2
    }

    /// `op` (2), `a0` (m), `ns` (m + 1), first and last (1 each).
    fn cmd_w(&self) -> u32 {
        2 + self.m() + (self.m() + 1) + 2
    }

    fn beat_w(&self) -> u32 {
        Beam::width(self.0.p as u32, self.0.trilin.voxel_w)
    }
}

impl StreamCodec for StreamFrame {
    type In = StreamIn;
    type Out = FrameOut;

    fn in_width(&self) -> u32 {
        1 + self.cmd_w().max(self.beat_w())
    }

    fn out_width(&self) -> u32 {
        self.0.out_width()
    }

    fn pack_in(&self, item: &StreamIn) -> Vec<u32> {
        let mut w = BitWriter::new();
        match item {
            StreamIn::Cmd(c) => {
                w.put(u64::from(KIND_CMD), 1);
                w.put(u64::from(c.op), 2);
                w.put(u64::from(c.a0), self.m());
                w.put(u64::from(c.ns), self.m() + 1);
                w.put(u64::from(c.first), 1);
                w.put(u64::from(c.last), 1);
            }
            StreamIn::Beat(b) => {
                w.put(u64::from(KIND_BEAT), 1);
                b.pack(&mut w, self.0.trilin.voxel_w);
            }
        }
        w.finish_padded(self.in_width())
    }

    fn unpack_out(&self, words: &[u32]) -> FrameOut {
        self.0.unpack_out(words)
    }
}
