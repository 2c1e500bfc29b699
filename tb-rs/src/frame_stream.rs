//! Driving `cube5_frame` with `Source = 1`: the frame fed by a beat stream a section at a time
//! (issue 12; docs/numerics/frame.md, "Sections"). One input stream carries the section commands
//! and the beats of each section (a kind bit first): the volume read in the section's order with
//! its edge voxels (`cube5_frame::sections::section_beats`, the beams `cube5_section_buf`
//! delivers). The image is compared with the frame model's whole-frame base plane
//! (`render_base_plane`, what [`Expected`] holds): sections must change no bit.

use crate::error::{Mismatch, TbError};
use crate::frame::{
    drive_pixels, items_for, ray_trail, Expected, FrameOut, FrameRtl, Render, Rendered, REG_MODE,
};
use crate::rtl::{RtlStream, Traffic};
use crate::variants::variants_of;
use cube5_model::regs::cube5_frame::OP_RENDER;
use cube5_model::units::cube5_frame::sections::{section_beats, section_order, Section};

impl FrameRtl {
    /// The configurations fed by a beat stream (`Source = 1`) with the whole base plane and its
    /// read-out (`Window = 0`), in `.variants` order.
    pub fn streams() -> Vec<FrameRtl> {
        Self::beat_fed().filter(|r| !r.window).collect()
    }

    /// The configurations with the compositing window (`Window = 1`; tests/cube5_frame_window.rs).
    pub fn windows() -> Vec<FrameRtl> {
        Self::beat_fed().filter(|r| r.window).collect()
    }

    fn beat_fed() -> impl Iterator<Item = FrameRtl> {
        variants_of(crate::frame::TOP)
            .into_iter()
            .map(|v| FrameRtl::from_variant(v).unwrap_or_else(|e| panic!("{e}")))
            .filter(|r| r.stream)
    }
}

/// The stream frame's items and codec: the model's (`cube5_frame::ports`).
pub use cube5_model::units::cube5_frame::ports::{SecCmd, StreamFrame, StreamIn};

/// The input items of a whole frame swept in sections of `width` anchors (in the order of
/// `section_order`), and the beats among them.
pub fn frame_items(
    rtl: &FrameRtl,
    e: &Expected,
    width: usize,
) -> Result<(Vec<StreamIn>, u64), TbError> {
    let order =
        section_order(&e.params, width, rtl.p).map_err(|x| TbError::setup(rtl.variant.name, x))?;
    Ok(items_of(rtl, e, &order, true))
}

/// The items of `order`'s sections: each command then its beats; the first section starts the
/// frame, the last (when `last`) ends it with the read-out.
pub fn items_of(
    rtl: &FrameRtl,
    e: &Expected,
    order: &[Section],
    last: bool,
) -> (Vec<StreamIn>, u64) {
    let mut items = Vec::new();
    let mut beats = 0u64;
    for (n, sec) in order.iter().enumerate() {
        items.push(StreamIn::Cmd(SecCmd {
            op: OP_RENDER,
            a0: sec.a0 as u32,
            ns: sec.ns as u32,
            first: n == 0,
            last: last && n + 1 == order.len(),
        }));
        let b = section_beats(&e.params, &e.seen, *sec, rtl.p);
        beats += b.len() as u64;
        items.extend(b.into_iter().map(StreamIn::Beat));
    }
    (items, beats)
}

/// A stream frame with its tables loaded.
pub struct StreamBench {
    pub rtl: FrameRtl,
    pub dut: RtlStream<StreamFrame>,
    loaded: Option<(Render, u64, bool)>,
}

impl StreamBench {
    /// Opens the DUT and waits out the compositing buffer's clear pass after reset (a command
    /// refused for a reserved render mode; `load` rewrites the mode register).
    pub fn new(rtl: FrameRtl, dut_seed: u32) -> Result<Self, TbError> {
        let dut = RtlStream::new(rtl.variant, StreamFrame(rtl.cfg), dut_seed)?;
        let mut bench = Self {
            rtl,
            dut,
            loaded: None,
        };
        bench.write(&[rtl.reg(REG_MODE, 3)])?;
        let out = bench.refused()?;
        if !out.error {
            return Err(TbError::from(Mismatch {
                variant: rtl.variant.name.to_string(),
                what: "a render in a reserved mode was not refused".into(),
                ..Default::default()
            }));
        }
        Ok(bench)
    }

    pub fn write(&mut self, writes: &[(u32, Vec<u32>)]) -> Result<(), TbError> {
        for (a, d) in writes {
            self.dut.write_config(*a, d)?;
        }
        Ok(())
    }

    /// One whole-face command that must be refused: its one output item.
    pub fn refused(&mut self) -> Result<FrameOut, TbError> {
        let cmd = StreamIn::Cmd(SecCmd {
            op: OP_RENDER,
            a0: 0,
            ns: 0,
            first: true,
            last: true,
        });
        let d = self.dut.drive(&[cmd], &Traffic::full_speed(), 1, 200_000)?;
        match d.outputs.as_slice() {
            [one] => Ok(one.value.clone()),
            _ => Err(TbError::from(Mismatch {
                variant: self.rtl.variant.name.to_string(),
                what: format!("{} items for a refused command", d.outputs.len()),
                ..Default::default()
            })),
        }
    }

    /// The tables and frame registers of `e` (no empty slices skipped: Source = 1 ignores Skip).
    pub fn load(&mut self, e: &Expected) -> Result<(), TbError> {
        let u = &e.units;
        let key = (
            u.render,
            u.compos.lut().ratio().unwrap_or(0.0).to_bits(),
            u.compos.regs()
                == cube5_model::units::cube5_compos::ComposRegs::defaults(&self.rtl.compos),
        );
        if self.loaded != Some(key) {
            let w = u.config_writes(&self.rtl);
            self.write(&w)?;
            self.loaded = Some(key);
        }
        let w = self.rtl.frame_writes(&e.params, u.render, u.tf2d, (0, 0));
        self.write(&w)
    }

    /// Drives a frame's items until its W H pixels are out.
    pub fn drive(
        &mut self,
        e: &Expected,
        items: &[StreamIn],
        traffic: &Traffic,
    ) -> Result<Rendered, TbError> {
        let n = items_for(e.w, e.h, self.rtl.out_lanes);
        let limit = 60 * (items.len() as u64 + n) + 200_000;
        drive_pixels(&mut self.dut, items, e, self.rtl.out_lanes, traffic, limit)
    }

    /// Loads `e`, renders it in sections of `width` and compares every pixel with the frame
    /// model's image; returns the cycles of the drive and the frame's own sweep counter.
    pub fn check(
        &mut self,
        e: &Expected,
        width: usize,
        traffic: &Traffic,
        seed: u64,
    ) -> Result<(u64, u32), TbError> {
        self.load(e)?;
        let (items, beats) = frame_items(&self.rtl, e, width)?;
        let got = self.drive(e, &items, traffic)?;
        self.compare(e, &got, beats, &format!("S = {width}"), seed)
    }

    /// Every pixel and channel, the error flag and the beats counted, against the model.
    pub fn compare(
        &self,
        e: &Expected,
        got: &Rendered,
        beats: u64,
        how: &str,
        seed: u64,
    ) -> Result<(u64, u32), TbError> {
        let rtl = self.rtl;
        let ctx = format!(
            "{} view {} {:?}, {:?}, {how}, {:?}, seed {seed}",
            rtl.variant, e.view, e.dir, e.units.render, e.params
        );
        let fail = |item: usize, what: String, trail: String| {
            Err(TbError::from(Mismatch {
                variant: rtl.variant.name.to_string(),
                seed,
                item: item as u64,
                input: ctx.clone(),
                what,
                trail,
                ..Default::default()
            }))
        };
        if got.protocol_errors > 0 {
            return fail(0, "a stalled output changed".into(), String::new());
        }
        got.all_out(e, rtl.variant, seed, &ctx)?;
        for (i, px) in got.pixels.iter().enumerate() {
            let (r, q) = (i % e.w, i / e.w);
            if px.error {
                return fail(
                    i,
                    format!("pixel ({r}, {q}) carries the error flag"),
                    String::new(),
                );
            }
            if u64::from(px.reads) != beats {
                return fail(
                    i,
                    format!(
                        "pixel ({r}, {q}) counts {} beats, the stream had {beats}",
                        px.reads
                    ),
                    String::new(),
                );
            }
            if px.coxel != e.want[i] {
                return fail(
                    i,
                    format!(
                        "pixel ({r}, {q}) of {} x {}: RTL {:?}, model {:?}",
                        e.w, e.h, px.coxel, e.want[i]
                    ),
                    ray_trail(&e.params, &e.seen, &e.units, r, q),
                );
            }
        }
        Ok((got.cycles, got.pixels[0].cycles))
    }
}
