//! The accelerator's control core (`cube5_accel_ctrl`), written from
//! `docs/numerics/accel_ctrl.md`: from the host registers latched at `Ctrl.start`, the refusal
//! code or the frame's plan (its sections in order, the image rows), and the exact command stream
//! of every port: the fetch's sweep commands, the section buffer's section commands, the frame's
//! section commands and the image writer's row commands, plus the planned sample count.
//!
//! The core's streams are a function of the registers alone (back-pressure decides only when a
//! command leaves), so it is modelled as a function; its cycle-level observables (busy, the
//! interrupt, the cycle counter) are stated in the contract as functions of the handshake and
//! event cycles, which `cube5_tb` checks from the shim's records. `AccelCtrlCodec` packs the
//! AXI4-Lite transactions and unpacks the shim's records (tb/accel_ctrl_shim.h).

use crate::bits::{words_for, BitReader, BitWriter};
use crate::error::{ModelError, Result};
use crate::regs::cube5_accel::{
    CODE_ABORTED, CODE_AXIS_K, CODE_DIMS, CODE_FRAME, CODE_IMG_ALIGN, CODE_NONE, CODE_PITCH,
    CODE_RENDER, CODE_SKIP, CODE_SMALL, CODE_STEP, CODE_VOL_ALIGN, CODE_WRITE, REG_DIMS, REG_DX,
    REG_DX_DX, REG_DY, REG_MODE, REG_MODE_RENDER, REG_SKIP, REG_STATUS_CODE, REG_STATUS_DONE,
    REG_STATUS_ERROR, REG_VIEW, REG_VIEW_AXIS_K, REG_VIEW_K_REVERSED,
};
use crate::unit::StreamCodec;
use crate::units::cube5_axil::{AxilCodec, AxilRecord, AxilTxn};
use crate::units::cube5_frame::FrameParams;
use crate::units::cube5_section_buf::SectionBufConfig;
use crate::units::cube5_vol_fetch::{frame_axes, Sweep, VolFetchConfig};

/// `StepW` of the frame's `S(2.StepW)` ray steps.
const STEP_W: u32 = 16;

/// The check cycles after the start strobe `t0` (docs/numerics/accel_ctrl.md, "Start and
/// checks"): a refused frame ends in `te = t0 + CHECK_CYCLES` (`Cycle` reads `CHECK_CYCLES`), an
/// accepted frame's ports offer their first commands from `t0 + CHECK_CYCLES + 1`, and `Sample`
/// is set in `t0 + CHECK_CYCLES`.
pub const CHECK_CYCLES: u64 = 5;

/// The RTL parameters of one `cube5_accel_ctrl` configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AccelCtrlConfig {
    /// Pipelines: voxels per beam.
    pub p: u32,
    /// Largest volume edge (a power of two).
    pub max_dim: u32,
    /// Block edge `B` of the fetch and the section buffer.
    pub block_dim: u32,
    /// Section width `S` in anchors.
    pub section: u32,
    /// Byte address width of the AXI4 ports.
    pub addr_w: u32,
    /// Data width of the AXI4 read port (the volume base must be a multiple of `DataW / 8`).
    pub data_w: u32,
    /// Bytes per base-plane pixel (the unit of the writer's `len`).
    pub pixel_bytes: u32,
    /// Bits of the writer's `len` field.
    pub len_w: u32,
    /// `Window`: 1 when the top has the frame's compositing window; the row commands then go out
    /// from the frame's start (the top writes the rows with the initial coxel's code before the
    /// final pixels), not after the last section. Each port's commands are the same.
    pub window: u32,
}

impl AccelCtrlConfig {
    /// The RTL's parameter defaults.
    pub const DEFAULT: Self = Self {
        p: 4,
        max_dim: 64,
        block_dim: 8,
        section: 16,
        addr_w: 32,
        data_w: 64,
        pixel_bytes: 4,
        len_w: 16,
        window: 0,
    };

    /// P, MaxDim, BlockDim, AddrW and DataW have the fetch's ranges, Section the section
    /// buffer's (the core's commands go to them); PixelBytes and LenW are the core's own.
    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(ModelError::Config(format!("cube5_accel_ctrl: {what}")));
        let fetch = VolFetchConfig {
            addr_w: self.addr_w,
            data_w: self.data_w,
            p: self.p,
            max_dim: self.max_dim,
            block_dim: self.block_dim,
            // The shortest burst: the fetch's burst rule then allows every DataW it allows.
            max_burst: 2,
            ..VolFetchConfig::DEFAULT
        };
        let sbuf = SectionBufConfig {
            p: self.p,
            max_dim: self.max_dim,
            block_dim: self.block_dim,
            section: self.section,
            ..SectionBufConfig::DEFAULT
        };
        if let Err(e) = fetch.validate().and_then(|_| sbuf.validate()) {
            return bad(e.to_string());
        }
        if !self.pixel_bytes.is_power_of_two() || self.pixel_bytes > 128 {
            return bad(format!(
                "PixelBytes {} is not a power of two up to 128",
                self.pixel_bytes
            ));
        }
        if self.len_w < self.m() + 2 || self.len_w > 32 {
            return bad(format!(
                "LenW {} outside m + 2 ..= 32 (a row is up to 2 MaxDim pixels)",
                self.len_w
            ));
        }
        if self.window > 1 {
            return bad(format!("Window {} is not 0 or 1", self.window));
        }
        Ok(())
    }

    /// The row alignment in bytes: the image base and a nonzero `ImgPitch` are multiples of it
    /// (the image writer's item: `P` pixels, or a bus beat where that is narrower).
    pub fn row_align(&self) -> u64 {
        u64::from((self.p * self.pixel_bytes).min(self.data_w / 8))
    }

    /// The pixels of a row as written for a base plane `w` pixels wide: `w` rounded up to `P`
    /// (the frame's read-out items of `P` pixels; the padding's values are unspecified).
    pub fn row_pixels(&self, w: u32) -> u32 {
        w.next_multiple_of(self.p)
    }

    /// The bytes from one row's start to the next for a base plane `w` pixels wide: `ImgPitch`,
    /// or when it is 0 the bytes of a row as written.
    pub fn pitch(&self, img_pitch: u32, w: u32) -> u64 {
        if img_pitch != 0 {
            u64::from(img_pitch)
        } else {
            u64::from(self.row_pixels(w)) * u64::from(self.pixel_bytes)
        }
    }

    /// `m = log2 MaxDim`.
    pub fn m(&self) -> u32 {
        self.max_dim.trailing_zeros()
    }

    /// `NbW = log2(MaxDim / B)`.
    pub fn nb_w(&self) -> u32 {
        (self.max_dim / self.block_dim).trailing_zeros()
    }

    /// Bits of the fetch's sweep payload (docs/numerics/vol_fetch.md, op 1).
    pub fn fetch_w(&self) -> u32 {
        self.addr_w + 3 * (self.nb_w() + 1) + 3 + self.nb_w() + self.nb_w() + 1
    }

    /// Bits of the section buffer's section payload (docs/numerics/section_buf.md, op 1).
    pub fn sbuf_w(&self) -> u32 {
        3 + 3 * (self.m() + 1) + self.m()
    }

    /// Widths of the frame registers' fields at the head of the frame's section command: Dims,
    /// View, Dx, Dy, Mode (render and tf2d), Skip.
    fn frame_reg_widths(&self) -> [u32; 6] {
        let m1 = self.m() + 1;
        [3 * m1, 3, STEP_W + 2, STEP_W + 2, 4, 2 * m1]
    }

    /// Bits of the frame's section command: the frame registers, `sec_a0`, `sec_ns`,
    /// `sec_first`, `sec_last`.
    pub fn frame_w(&self) -> u32 {
        self.frame_reg_widths().iter().sum::<u32>() + self.m() + (self.m() + 1) + 2
    }

    /// Bits of the writer's row command (docs/numerics/axi_wr.md).
    pub fn write_w(&self) -> u32 {
        self.addr_w + self.len_w
    }

    fn addr_mask(&self) -> u64 {
        if self.addr_w >= 64 {
            u64::MAX
        } else {
            (1u64 << self.addr_w) - 1
        }
    }

    /// What the core does with `regs` on `Ctrl.start`: the plan, or the refusal code.
    pub fn plan(&self, regs: &CtrlRegs) -> std::result::Result<Plan, u32> {
        let f = &regs.frame;
        let m1 = self.m() + 1;
        let fmask = (1u32 << m1) - 1;
        let dims = [0, 1, 2].map(|a| (f.dims >> (m1 * a)) & fmask);
        let axis_k = REG_VIEW_AXIS_K.get(u64::from(f.view)) as u32;
        let reversed = REG_VIEW_K_REVERSED.get(u64::from(f.view)) != 0;
        let sext = |w: u32| {
            let v = (w & ((1 << (STEP_W + 2)) - 1)) as i32;
            (v << (32 - STEP_W - 2)) >> (32 - STEP_W - 2)
        };
        let (dx, dy) = (sext(f.dx), sext(f.dy));
        let render = REG_MODE_RENDER.get(u64::from(f.mode));
        let (front, back) = (f.skip & fmask, (f.skip >> m1) & fmask);
        if axis_k == 3 {
            return Err(CODE_AXIS_K);
        }
        let p = self.p;
        if dims
            .iter()
            .any(|&n| n < p || n > self.max_dim || !n.is_multiple_of(p))
        {
            return Err(CODE_DIMS);
        }
        if render >= 5 {
            return Err(CODE_RENDER);
        }
        if dx.unsigned_abs() > 1 << STEP_W || dy.unsigned_abs() > 1 << STEP_W {
            return Err(CODE_STEP);
        }
        let (ai, aj) = frame_axes(axis_k);
        let (ni, nj, nk) = (dims[ai], dims[aj], dims[axis_k as usize]);
        if front + back >= nk {
            return Err(CODE_SKIP);
        }
        if ni < 2 * p || ni * (nj - 1) / p < 9 {
            return Err(CODE_SMALL);
        }
        let vol_base = regs.vol_base & self.addr_mask();
        let img_base = regs.img_base & self.addr_mask();
        if !vol_base.is_multiple_of(u64::from(self.data_w / 8)) {
            return Err(CODE_VOL_ALIGN);
        }
        if !img_base.is_multiple_of(self.row_align()) {
            return Err(CODE_IMG_ALIGN);
        }
        let params = FrameParams {
            axis_k: axis_k as usize,
            axis_i: ai,
            axis_j: aj,
            ni: ni as usize,
            nj: nj as usize,
            nk: nk as usize,
            k_reversed: reversed,
            dx,
            dy,
        };
        let (w, h) = params.base_plane_size();
        let row_bytes = u64::from(self.row_pixels(w as u32)) * u64::from(self.pixel_bytes);
        let pitch = u64::from(regs.img_pitch);
        if pitch != 0 && (!pitch.is_multiple_of(self.row_align()) || pitch < row_bytes) {
            return Err(CODE_PITCH);
        }
        let pitch = self.pitch(regs.img_pitch, w as u32);
        let s = self.section;
        let nsec = ni.div_ceil(s);
        let blocks = dims.map(|n| n.div_ceil(self.block_dim));
        let mut sections = Vec::with_capacity(nsec as usize);
        for n in 0..nsec {
            let idx = if dx >= 0 { n } else { nsec - 1 - n };
            let a0 = idx * s;
            let sweep = Sweep {
                base: vol_base,
                blocks,
                axis_k,
                reversed,
                sec_lo: 0,
                sec_hi: blocks[ai],
            }
            .with_anchor_section(self.block_dim, a0, s);
            sections.push(Section {
                a0,
                ns: s.min(ni - a0),
                first: n == 0,
                last: n + 1 == nsec,
                sweep,
            });
        }
        let rows = (0..h as u64)
            .map(|r| RowCmd {
                addr: img_base.wrapping_add(r.wrapping_mul(pitch)) & self.addr_mask(),
                len: self.row_pixels(w as u32),
            })
            .collect();
        Ok(Plan {
            regs: *regs,
            axis_k,
            reversed,
            frame_dims: [ni, nj, nk],
            base_plane: (w as u32, h as u32),
            sections,
            rows,
            samples: u64::from(ni) * u64::from(nj) * u64::from(nk - front - back),
        })
    }

    /// The fetch's sweep payload of `sec` (docs/numerics/vol_fetch.md, op 1; no `op` bit).
    pub fn pack_fetch(&self, sec: &Section) -> Vec<u32> {
        let (nbw, sw) = (self.nb_w(), &sec.sweep);
        let mut b = BitWriter::new();
        b.put(sw.base, self.addr_w);
        for n in sw.blocks {
            b.put(u64::from(n), nbw + 1);
        }
        b.put(u64::from(sw.axis_k), 2)
            .put_bool(sw.reversed)
            .put(u64::from(sw.sec_lo), nbw)
            .put(u64::from(sw.sec_hi), nbw + 1);
        b.finish(self.fetch_w())
    }

    /// The section buffer's section payload of `sec` (docs/numerics/section_buf.md, op 1).
    pub fn pack_sbuf(&self, plan: &Plan, sec: &Section) -> Vec<u32> {
        let m1 = self.m() + 1;
        let mut b = BitWriter::new();
        b.put(u64::from(plan.axis_k), 2).put_bool(plan.reversed);
        for n in plan.frame_dims {
            b.put(u64::from(n), m1);
        }
        b.put(u64::from(sec.a0), self.m());
        b.finish(self.sbuf_w())
    }

    /// The frame's section command of `sec`: the frame registers as written (fields at their
    /// widths), then `sec_a0`, `sec_ns`, `sec_first`, `sec_last`.
    pub fn pack_frame(&self, plan: &Plan, sec: &Section) -> Vec<u32> {
        let m1 = self.m() + 1;
        let r = &plan.regs.frame;
        let mask = |v: u32, w: u32| u64::from(v) & ((1u64 << w) - 1);
        let mut b = BitWriter::new();
        b.put(mask(r.dims, 3 * m1), 3 * m1)
            .put(mask(r.view, 3), 3)
            .put(REG_DX_DX.get(u64::from(r.dx)), STEP_W + 2)
            .put(mask(r.dy, STEP_W + 2), STEP_W + 2)
            .put(mask(r.mode, 4), 4)
            .put(mask(r.skip, 2 * m1), 2 * m1)
            .put(u64::from(sec.a0), self.m())
            .put(u64::from(sec.ns), m1)
            .put_bool(sec.first)
            .put_bool(sec.last);
        b.finish(self.frame_w())
    }

    /// The writer's row command (docs/numerics/axi_wr.md: `addr`, `len`).
    pub fn pack_row(&self, row: &RowCmd) -> Vec<u32> {
        let mut b = BitWriter::new();
        b.put(row.addr, self.addr_w)
            .put(u64::from(row.len), self.len_w);
        b.finish(self.write_w())
    }

    /// Every port's stream of a plan, packed, in order.
    pub fn streams(&self, plan: &Plan) -> [Vec<Vec<u32>>; 4] {
        [
            plan.sections.iter().map(|s| self.pack_fetch(s)).collect(),
            plan.sections
                .iter()
                .map(|s| self.pack_sbuf(plan, s))
                .collect(),
            plan.sections
                .iter()
                .map(|s| self.pack_frame(plan, s))
                .collect(),
            plan.rows.iter().map(|r| self.pack_row(r)).collect(),
        ]
    }
}

/// How a frame ended, as the core reports it (docs/numerics/accel_ctrl.md, "Events, end of frame,
/// status").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Outcome {
    /// The refusal code, or 0 for an accepted frame.
    pub refused: u32,
    /// The frame's done carried an error.
    pub frame_error: bool,
    /// A row's completion answered other than OKAY.
    pub write_error: bool,
    /// `Ctrl.soft_reset` ended the frame.
    pub aborted: bool,
}

impl Outcome {
    /// `Status.code` after the frame: the refusal, else Aborted, Frame, Write, in this order.
    pub fn code(&self) -> u32 {
        if self.refused != CODE_NONE {
            self.refused
        } else if self.aborted {
            CODE_ABORTED
        } else if self.frame_error {
            CODE_FRAME
        } else if self.write_error {
            CODE_WRITE
        } else {
            CODE_NONE
        }
    }

    /// `Status` after the frame (busy 0): `done` [1], `error` [2], `code` [7:4]; `IrqStatus` gets
    /// `done` [0] or `error` [1].
    pub fn status(&self) -> u32 {
        let code = self.code();
        let w = REG_STATUS_CODE.set(0, u64::from(code));
        let w = if code == CODE_NONE {
            REG_STATUS_DONE.set(w, 1)
        } else {
            REG_STATUS_ERROR.set(w, 1)
        };
        w as u32
    }
}

crate::unit_config!(AccelCtrlConfig, "cube5_accel_ctrl", DEFAULT, {
    "P" => p,
    "MaxDim" => max_dim,
    "BlockDim" => block_dim,
    "Section" => section,
    "AddrW" => addr_w,
    "DataW" => data_w,
    "PixelBytes" => pixel_bytes,
    "LenW" => len_w,
    "Window" => window,
});

/// A frame's set-up words, as cube5_frame's registers carry them (cube5_frame.regs.toml: Dims,
/// View, Dx, Dy, Mode, Skip); the accelerator's registers of the same names hold them unchanged.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FrameRegs {
    pub dims: u32,
    pub view: u32,
    pub dx: u32,
    pub dy: u32,
    pub mode: u32,
    pub skip: u32,
}

impl FrameRegs {
    /// An example frame for tests and docs: a 64^3 volume at `m` = 7 (8-bit dimension fields),
    /// slices along z swept in reverse, steps -2 / 65536 and 12 / 65536, composite with the 2-D
    /// transfer function, two empty slices skipped in front and three behind.
    pub const EXAMPLE: Self = Self {
        dims: 0x0040_4040,
        view: 6,
        dx: 0x3_fffe,
        dy: 12,
        mode: 9,
        skip: 0x0302,
    };

    /// (accelerator register, word) in the order the driver writes them.
    pub fn writes(&self) -> [(u32, u32); 6] {
        [
            (REG_DIMS, self.dims),
            (REG_VIEW, self.view),
            (REG_DX, self.dx),
            (REG_DY, self.dy),
            (REG_MODE, self.mode),
            (REG_SKIP, self.skip),
        ]
    }
}

/// The registers the core latches on `Ctrl.start` (words as the host wrote them; bases 64-bit).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CtrlRegs {
    /// The frame's set-up words (`Dims` .. `Skip`).
    pub frame: FrameRegs,
    pub vol_base: u64,
    pub img_base: u64,
    /// `ImgPitch` (0: the smallest legal pitch).
    pub img_pitch: u32,
}

/// One section of the plan, in issue order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Section {
    pub a0: u32,
    pub ns: u32,
    pub first: bool,
    pub last: bool,
    pub sweep: Sweep,
}

/// One image row's write command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RowCmd {
    pub addr: u64,
    pub len: u32,
}

/// An accepted frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Plan {
    pub regs: CtrlRegs,
    pub axis_k: u32,
    pub reversed: bool,
    /// `(ni, nj, nk)`.
    pub frame_dims: [u32; 3],
    /// `(W, H)`.
    pub base_plane: (u32, u32),
    pub sections: Vec<Section>,
    pub rows: Vec<RowCmd>,
    /// Anchors swept: `ni nj (nk - front - back)`.
    pub samples: u64,
}

/// A command port of the core.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Port {
    Fetch = 0,
    Sbuf = 1,
    Frame = 2,
    Write = 3,
}

pub const PORTS: [Port; 4] = [Port::Fetch, Port::Sbuf, Port::Frame, Port::Write];

/// One record of the co-simulation shim (tb/accel_ctrl_shim.h).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CtrlRecord {
    /// An AXI4-Lite response or interrupt change (tb/axil_mgr.h).
    Axil(AxilRecord),
    /// A command handshake on `port`.
    Cmd { port: Port, bits: Vec<u32> },
    /// The shim's frame reported done (with `error`).
    FrameDone { error: bool },
    /// The shim's writer completed a row with `resp`.
    Completion { resp: u32 },
    /// A write on the table port.
    Table { table: u32, index: u32, data: u32 },
    /// The shim drove `drained_i` (its answer to `flush_o`).
    Drained,
}

/// Words of a record after its two cycle words.
pub const RECORD_WORDS: usize = 6;

/// Packs transactions (as `AxilCodec`) and unpacks the shim's records.
#[derive(Debug, Clone, Copy, Default)]
pub struct AccelCtrlCodec;

impl StreamCodec for AccelCtrlCodec {
    type In = AxilTxn;
    type Out = CtrlRecord;

    fn in_width(&self) -> u32 {
        AxilCodec.in_width()
    }

    fn out_width(&self) -> u32 {
        32 * RECORD_WORDS as u32
    }

    fn pack_in(&self, t: &AxilTxn) -> Vec<u32> {
        AxilCodec.pack_in(t)
    }

    fn unpack_out(&self, w: &[u32]) -> CtrlRecord {
        let at = |i: usize| w.get(i).copied().unwrap_or(0);
        if at(0) >> 31 == 0 {
            return CtrlRecord::Axil(AxilCodec.unpack_out(&w[..4.min(w.len())]));
        }
        let (kind, port, flag) = (at(0) & 0xf, at(0) >> 4 & 0xf, at(0) >> 8 & 0xf);
        match kind {
            0 => CtrlRecord::Cmd {
                port: PORTS[(port & 3) as usize],
                bits: w[1..].to_vec(),
            },
            1 => CtrlRecord::FrameDone { error: flag != 0 },
            2 => CtrlRecord::Completion { resp: flag & 3 },
            4 => CtrlRecord::Drained,
            _ => CtrlRecord::Table {
                table: at(1) >> 16 & 0xf,
                index: at(1) & 0xffff,
                data: at(2),
            },
        }
    }
}

impl AccelCtrlConfig {
    /// `bits` of a `Cmd` record trimmed to the port's width (the shim pads to `RECORD_WORDS - 1`).
    pub fn trim(&self, port: Port, bits: &[u32]) -> Vec<u32> {
        let w = match port {
            Port::Fetch => self.fetch_w(),
            Port::Sbuf => self.sbuf_w(),
            Port::Frame => self.frame_w(),
            Port::Write => self.write_w(),
        };
        let mut v: Vec<u32> = bits.iter().copied().take(words_for(w)).collect();
        v.resize(words_for(w), 0);
        if !w.is_multiple_of(32) {
            if let Some(last) = v.last_mut() {
                *last &= (1u32 << (w % 32)) - 1;
            }
        }
        v
    }

    /// The fields of a frame section command (for messages): `sec_a0, sec_ns, first, last`.
    pub fn frame_section_fields(&self, bits: &[u32]) -> (u32, u32, bool, bool) {
        let m1 = self.m() + 1;
        let mut r = BitReader::new(bits);
        for w in self.frame_reg_widths() {
            r.get(w);
        }
        let a0 = r.get(self.m()) as u32;
        let ns = r.get(m1) as u32;
        (a0, ns, r.get(1) != 0, r.get(1) != 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outcome_codes_in_order() {
        let o = Outcome {
            frame_error: true,
            write_error: true,
            ..Outcome::default()
        };
        assert_eq!(o.code(), CODE_FRAME);
        assert_eq!(o.status(), 0x94);
        assert_eq!(Outcome::default().status(), 0x2);
        let o = Outcome {
            refused: CODE_STEP,
            aborted: true,
            ..o
        };
        assert_eq!(o.code(), CODE_STEP);
        // A soft reset reports Aborted before the frame's and the writer's errors (docs,
        // "Soft reset": after the strobe they are not awaited).
        let o = Outcome {
            aborted: true,
            frame_error: true,
            write_error: true,
            ..Outcome::default()
        };
        assert_eq!(o.code(), CODE_ABORTED);
        assert_eq!(o.status(), CODE_ABORTED << 4 | 0x4);
    }

    fn regs(dims: [u32; 3], view: u32, dx: i32) -> CtrlRegs {
        let m1 = AccelCtrlConfig::DEFAULT.m() + 1;
        CtrlRegs {
            frame: FrameRegs {
                dims: dims[0] | dims[1] << m1 | dims[2] << (2 * m1),
                view,
                dx: (dx as u32) & 0x3_ffff,
                dy: 0,
                mode: 1,
                skip: 0,
            },
            vol_base: 0x1000,
            img_base: 0x8000,
            img_pitch: 0,
        }
    }

    #[test]
    fn sections_run_left_to_right_or_right_to_left_by_the_sign_of_dx() {
        let c = AccelCtrlConfig::DEFAULT;
        let p = c.plan(&regs([40, 32, 24], 2, 100)).unwrap();
        let a0: Vec<(u32, u32)> = p.sections.iter().map(|s| (s.a0, s.ns)).collect();
        assert_eq!(a0, vec![(0, 16), (16, 16), (32, 8)]);
        assert!(p.sections[0].first && p.sections[2].last && !p.sections[1].last);
        let p = c.plan(&regs([40, 32, 24], 2, -1)).unwrap();
        let a0: Vec<u32> = p.sections.iter().map(|s| s.a0).collect();
        assert_eq!(a0, vec![32, 16, 0]);
        assert!(p.sections[0].first && p.sections[2].last);
        // dx = 0 counts as >= 0.
        assert_eq!(c.plan(&regs([40, 32, 24], 2, 0)).unwrap().sections[0].a0, 0);
    }

    #[test]
    fn sweeps_take_the_anchor_sections_block_columns() {
        let c = AccelCtrlConfig::DEFAULT;
        let p = c.plan(&regs([40, 32, 24], 2, 0)).unwrap();
        let cols: Vec<(u32, u32)> = p
            .sections
            .iter()
            .map(|s| (s.sweep.sec_lo, s.sweep.sec_hi))
            .collect();
        // B = 8, S = 16, nb_i = 5: [0, 3), [1, 5), [3, 5).
        assert_eq!(cols, vec![(0, 3), (1, 5), (3, 5)]);
        assert_eq!(p.sections[0].sweep.blocks, [5, 4, 3]);
    }

    #[test]
    fn base_plane_rows_follow_the_frame_set_up() {
        let c = AccelCtrlConfig::DEFAULT;
        // nk = 24, DX = -1: sx(23) = floor(-23 / 65536) = -1, so W = ni + 1.
        let p = c.plan(&regs([40, 32, 24], 2, -1)).unwrap();
        assert_eq!(p.base_plane, (41, 32));
        assert_eq!(p.rows.len(), 32);
        // W = 41 pixels: rows of 44 pixels (P = 4) 176 bytes apart, unless ImgPitch says
        // otherwise (a multiple of the row alignment, a 64-bit beat here: P = 4 pixels are 16
        // bytes, wider than the bus).
        assert_eq!(c.row_align(), 8);
        assert_eq!((p.rows[1].addr, p.rows[1].len), (0x8000 + 176, 44));
        let mut r = regs([40, 32, 24], 2, -1);
        r.img_pitch = 1024;
        assert_eq!(c.plan(&r).unwrap().rows[2].addr, 0x8000 + 2048);
        r.img_pitch = 1028;
        assert_eq!(c.plan(&r), Err(CODE_PITCH), "not a multiple of 8");
        r.img_pitch = 168;
        assert_eq!(c.plan(&r), Err(CODE_PITCH), "below 44 pixels");
        r.img_pitch = 176;
        assert!(c.plan(&r).is_ok());
        // DX = 2^16: W = ni + nk - 1.
        let p = c.plan(&regs([40, 32, 24], 2, 1 << 16)).unwrap();
        assert_eq!(p.base_plane.0, 40 + 23);
        assert_eq!(p.samples, 40 * 32 * 24);
    }

    #[test]
    fn refusals_in_order() {
        let c = AccelCtrlConfig::DEFAULT;
        assert_eq!(c.plan(&regs([40, 32, 24], 3, 0)), Err(CODE_AXIS_K));
        assert_eq!(c.plan(&regs([40, 30, 24], 2, 0)), Err(CODE_DIMS));
        assert_eq!(c.plan(&regs([40, 128, 24], 2, 0)), Err(CODE_DIMS));
        assert_eq!(c.plan(&regs([40, 0, 24], 2, 0)), Err(CODE_DIMS));
        let mut r = regs([40, 32, 24], 2, 0);
        r.frame.mode = 5;
        assert_eq!(c.plan(&r), Err(CODE_RENDER));
        r.frame.mode = 4 | 1 << 3;
        assert!(c.plan(&r).is_ok(), "first-opaque with the 2-D table");
        assert_eq!(
            c.plan(&regs([40, 32, 24], 2, (1 << 16) + 1)),
            Err(CODE_STEP)
        );
        assert_eq!(c.plan(&regs([40, 32, 24], 2, -(1 << 17))), Err(CODE_STEP));
        assert!(c.plan(&regs([40, 32, 24], 2, -(1 << 16))).is_ok());
        let mut r = regs([40, 32, 24], 2, 0);
        r.frame.skip = 12 | 12 << 7;
        assert_eq!(c.plan(&r), Err(CODE_SKIP));
        assert_eq!(c.plan(&regs([4, 32, 24], 2, 0)), Err(CODE_SMALL));
        // ni (nj - 1) / P: 12 x 3 / 4 = 9 passes, 8 x 3 / 4 = 6 fails.
        assert_eq!(c.plan(&regs([8, 4, 24], 2, 0)), Err(CODE_SMALL));
        assert!(c.plan(&regs([12, 4, 24], 2, 0)).is_ok());
        assert_eq!(c.plan(&regs([8, 5, 24], 2, 0)), Err(CODE_DIMS));
        let mut r = regs([40, 32, 24], 2, 0);
        r.vol_base = 4;
        assert_eq!(c.plan(&r), Err(CODE_VOL_ALIGN));
        let mut r = regs([40, 32, 24], 2, 0);
        r.img_base = 4;
        assert_eq!(
            c.plan(&r),
            Err(CODE_IMG_ALIGN),
            "rows start at multiples of 8 bytes"
        );
        // Address bits above AddrW are dropped before the checks.
        let mut r = regs([40, 32, 24], 2, 0);
        r.vol_base = 1 << 40;
        assert!(c.plan(&r).is_ok());
        assert_ne!(CODE_NONE, CODE_AXIS_K);
    }

    #[test]
    fn one_section_and_packing_widths() {
        let c = AccelCtrlConfig::DEFAULT;
        let p = c.plan(&regs([16, 16, 16], 0, 0)).unwrap();
        assert_eq!(p.sections.len(), 1);
        assert!(p.sections[0].first && p.sections[0].last);
        let s = c.streams(&p);
        assert_eq!(s[0].len(), 1);
        assert_eq!(s[3].len(), 16);
        let (a0, ns, first, last) = c.frame_section_fields(&s[2][0]);
        assert_eq!((a0, ns, first, last), (0, 16, true, true));
        assert_eq!(c.trim(Port::Frame, &s[2][0]), s[2][0]);
    }

    #[test]
    fn configurations_are_checked() {
        let mut c = AccelCtrlConfig::DEFAULT;
        assert!(c.validate().is_ok());
        c.section = 4;
        assert!(c.validate().is_err());
        c = AccelCtrlConfig::DEFAULT;
        c.len_w = 6;
        assert!(c.validate().is_err());
    }
}
