//! Driving the accelerator top `cube5_accel` (issue 12; docs/accel.md) as a host would: the volume
//! loaded into the test bench's AXI4 memory in the blocked layout the fetch reads
//! (`cube5_vol_fetch::dram_image`), the tables and registers written over AXI4-Lite through the
//! host driver (`cube5_model::accel_host::AccelHost`), a frame started, the interrupt awaited, and
//! the image read back from the memory and compared byte for byte with the frame model's image
//! (`Expected`, the one description of what the hardware computes) turned into pixel codes.
//!
//! The shim (tb/accel_shim.h) runs the AXI4-Lite manager (tb/axil_mgr.h) and the AXI4 memory
//! (tb/axi_mem.h) in one clock loop. The bench queues the host's register writes and sends them in
//! one batch with the next read or wait, so a table load is one run, not one per word.

use crate::error::{Mismatch, TbError};
use crate::frame::{Expected, FrameRtl, REGION_COMPOS, REGION_SHADER};
use crate::rtl::{AxiMemSetup, RtlStream, Traffic};
use crate::variants::{variants_of, Variant};
use cube5_model::accel_host::{AccelHost, FrameRegs, HostError, RegBus};
use cube5_model::regs::cube5_accel::{TABLE_BLOCK, TABLE_CLASS, TABLE_OPACITY, TABLE_REFLECT};
use cube5_model::units::cube5_accel::AccelConfig;
use cube5_model::units::cube5_accel_ctrl::AccelCtrlConfig;
use cube5_model::units::cube5_axil::{AxilCodec, AxilRecordKind, AxilTxn, RESP_OKAY};
use cube5_model::units::cube5_skewmem::BlockLut;
use cube5_model::units::cube5_vol_fetch::{dram_image, FetchCmd, VolFetchConfig};
use cube5_model::volume::Volume;

/// The top whose variants this module drives.
pub const TOP: &str = "cube5_accel";

/// Bytes per pixel of the image in memory: R, G, B, A codes, R at the lowest address.
pub const PIXEL_BYTES: usize = 4;

/// One build of `cube5_accel` and the configurations of the units inside it.
#[derive(Debug, Clone, Copy)]
pub struct AccelRtl {
    pub variant: &'static Variant,
    /// The frame inside (`Source = 1`), with the accelerator's variant: the model's image.
    pub frame: FrameRtl,
    pub fetch: VolFetchConfig,
    /// The control core inside: its plan places the image's rows.
    pub ctrl: AccelCtrlConfig,
    pub p: usize,
    pub section: usize,
    /// The compositing window (`Window = 1`): coxels parked in a scratch area of the memory.
    pub window: bool,
    /// With the window: bytes of a parked coxel's slot (`Cx`).
    pub park_slot: u64,
    /// Bursts the top may have in flight on its port (the memory's declared limit).
    pub port_outstanding: u32,
}

impl AccelRtl {
    pub fn from_variant(variant: &'static Variant) -> Result<Self, TbError> {
        // The top's parameters split into its units' configurations in one place, the model's
        // `AccelConfig` (tests/variant_table.rs holds it to the RTL's parameters).
        let ac: AccelConfig = variant
            .config()
            .map_err(|e| TbError::setup(variant.name, e))?;
        Ok(Self {
            variant,
            frame: FrameRtl {
                variant,
                cfg: ac.frame,
            },
            fetch: ac.fetch,
            ctrl: ac.ctrl(),
            p: ac.frame.p,
            section: ac.section as usize,
            window: ac.window,
            park_slot: ac.park_slot_bytes(),
            port_outstanding: ac.port_outstanding(),
        })
    }

    /// Every build of the top, in `.variants` order, with the window or without.
    fn every(window: bool) -> Vec<AccelRtl> {
        variants_of(TOP)
            .into_iter()
            .map(|v| Self::from_variant(v).unwrap_or_else(|e| panic!("{e}")))
            .filter(|r| r.window == window)
            .collect()
    }

    /// Every build of the top without the compositing window (the whole base plane on chip), in
    /// `.variants` order.
    pub fn all() -> Vec<AccelRtl> {
        Self::every(false)
    }

    /// Every build with the compositing window (`Window = 1`), in `.variants` order.
    pub fn windows() -> Vec<AccelRtl> {
        Self::every(true)
    }

    /// The build with `p` pipelines and the smallest memory that holds `n`^3.
    pub fn with(p: usize, n: usize) -> Option<AccelRtl> {
        Self::all()
            .into_iter()
            .filter(|r| r.p == p && (1usize << r.frame.max_dim_log2) >= n)
            .min_by_key(|r| r.frame.max_dim_log2)
    }

    /// The build with `p` pipelines and the widest sections (the throughput configuration), and
    /// among those the largest memory.
    pub fn widest(p: usize) -> Option<AccelRtl> {
        Self::all()
            .into_iter()
            .filter(|r| r.p == p)
            .max_by_key(|r| (r.section, r.frame.max_dim_log2))
    }

    /// The table loads of the frame's configuration writes (shader tables, opacity LUT and
    /// compositing registers): (table, first index, words), runs of consecutive entries.
    pub fn table_loads(&self, writes: &[(u32, Vec<u32>)]) -> Vec<(u32, u32, Vec<u32>)> {
        let off_w = self.frame.addr(1, 0).trailing_zeros();
        let sh_half = 1u32 << (self.frame.shader.cfg_addr_w() - 2);
        let mut loads: Vec<(u32, u32, Vec<u32>)> = Vec::new();
        for (addr, data) in writes {
            let (region, off) = (addr >> off_w, addr & ((1 << off_w) - 1));
            let word = |i: usize| data.get(i).copied().unwrap_or(0);
            let (table, index, words) = match region {
                REGION_SHADER if off < sh_half => (TABLE_CLASS, 2 * off, vec![word(0), word(1)]),
                REGION_SHADER => (TABLE_REFLECT, off - sh_half, vec![word(0)]),
                REGION_COMPOS => (TABLE_OPACITY, off, vec![word(0)]),
                _ => continue,
            };
            match loads.last_mut() {
                Some((t, first, w)) if *t == table && *first + w.len() as u32 == index => {
                    w.extend(words)
                }
                _ => loads.push((table, index, words)),
            }
        }
        loads
    }

    /// The Block table's words for `lut`: `ptr`, `empty`, `masked`, LSB first, at each entry's
    /// index in the fetch's LUT.
    pub fn block_loads(&self, lut: &BlockLut) -> Result<Vec<(u32, u32, Vec<u32>)>, TbError> {
        let nb_w = (self.fetch.max_dim / self.fetch.block_dim).trailing_zeros();
        let writes = self
            .fetch
            .lut_writes(lut)
            .map_err(|e| TbError::setup(self.variant.name, e))?;
        let mut loads: Vec<(u32, u32, Vec<u32>)> = Vec::new();
        for c in writes {
            let FetchCmd::Lut { index, entry } = c else {
                continue;
            };
            let w = entry.ptr
                | u32::from(entry.empty) << (3 * nb_w)
                | u32::from(entry.masked) << (3 * nb_w + 1);
            match loads.last_mut() {
                Some((_, first, ws)) if *first + ws.len() as u32 == index => ws.push(w),
                _ => loads.push((TABLE_BLOCK, index, vec![w])),
            }
        }
        Ok(loads)
    }

    /// The pixel of a coxel channel: `min(2^ColorW - 1, (c (2^ColorW - 1) + 2^(AccW - 1)) >> AccW)`
    /// (docs/numerics/warp.md, "Base-plane codes", on all four channels).
    pub fn code(&self, c: u64) -> u8 {
        let (cw, aw) = (self.frame.compos.color_w, self.frame.compos.acc_w);
        let max = (1u64 << cw) - 1;
        ((c * max + (1 << (aw - 1))) >> aw).min(max) as u8
    }
}

/// The memory's behaviour for a frame: latency, channel gaps, bandwidth, host back-pressure.
#[derive(Debug, Clone)]
pub struct MemEnv {
    pub latency: (u32, u32),
    /// AR, R, AW, W, B gaps in per mille.
    pub gaps: [u32; 5],
    /// Bytes per cycle as (num, den); num 0: unlimited.
    pub bw: (u32, u32),
    /// B and R back-pressure on the host port.
    pub host_stall: Vec<u8>,
}

impl MemEnv {
    pub fn quiet() -> Self {
        Self {
            latency: (10, 0),
            gaps: [0; 5],
            bw: (0, 1),
            host_stall: Vec::new(),
        }
    }

    /// Latency 10 + U(0..190), every channel with gaps, the host's B and R back-pressured.
    pub fn random(rng: &mut impl rand::Rng) -> Self {
        Self {
            latency: (10, 190),
            gaps: [0; 5].map(|_| rng.random_range(50..250)),
            bw: (0, 1),
            host_stall: Traffic::random(rng, 0.0, 0.3).stall,
        }
    }
}

/// What one frame did.
#[derive(Debug, Clone, Copy)]
pub struct FrameRun {
    /// The core's cycle counter: start to end of frame.
    pub cycles: u64,
    pub samples: u64,
    /// Read bursts and beats, write bursts and beats of the frame.
    pub ar: u64,
    pub r_beats: u64,
    pub aw: u64,
    pub w_beats: u64,
}

impl FrameRun {
    /// Samples per clock per pipeline over the whole frame (read-out included).
    pub fn rate(&self, p: usize) -> f64 {
        self.samples as f64 / (self.cycles as f64 * p as f64)
    }
}

/// The accelerator with its memory and host.
pub struct AccelBench {
    pub rtl: AccelRtl,
    pub dut: RtlStream<AxilCodec>,
    seed: u64,
    queued: Vec<AxilTxn>,
    host_stall: Vec<u8>,
    /// What the tables hold: (volume LUT loaded, the frame's configuration writes).
    loaded: Option<Vec<(u32, Vec<u32>)>>,
    lut_loaded: Option<Vec<(u32, u32, Vec<u32>)>>,
    /// The memory's AR, R, AW and W counters when the frame started.
    at_start: (u64, u64, u64, u64),
    /// The `ImgPitch` register the next frames are started with (0: the smallest pitch).
    pub pitch: u32,
    /// The window's scratch area of the frame being run (`Window = 1`): base and bytes.
    pub park: (u64, u64),
}

/// The image's place in memory: right after the volume, 4 KB aligned.
pub const VOL_BASE: u64 = 0x1000;

fn txn(read: bool, addr: u64, data: u32) -> AxilTxn {
    AxilTxn {
        read,
        addr: addr as u32,
        data,
        strb: 0xf,
        delay: 0,
        w_delay: 0,
    }
}

impl AccelBench {
    pub fn new(rtl: AccelRtl, seed: u64) -> Result<Self, TbError> {
        let dut = RtlStream::new(rtl.variant, AxilCodec, seed as u32)?;
        Ok(Self {
            rtl,
            dut,
            seed,
            queued: Vec::new(),
            host_stall: Vec::new(),
            loaded: None,
            lut_loaded: None,
            at_start: (0, 0, 0, 0),
            pitch: 0,
            park: (0, 0),
        })
    }

    fn name(&self) -> &'static str {
        self.rtl.variant.name
    }

    fn protocol(&self, cycle: u64, what: String) -> TbError {
        TbError::Protocol {
            variant: self.name().into(),
            seed: self.seed,
            cycle,
            what,
        }
    }

    /// The queued writes and `extra`, in one run; the records of `extra`'s response.
    fn flush(&mut self, extra: Option<AxilTxn>) -> Result<Option<u32>, TbError> {
        let mut t = std::mem::take(&mut self.queued);
        t.extend(extra);
        if t.is_empty() {
            return Ok(None);
        }
        let n = t.len() as u64;
        let traffic = Traffic {
            idle: Vec::new(),
            stall: self.host_stall.clone(),
        };
        let d = self.dut.drive(&t, &traffic, n, 2000 + 200 * n)?;
        self.clean(&d.stats)?;
        let resp: Vec<_> = d
            .outputs
            .iter()
            .filter(|o| o.value.kind != AxilRecordKind::Irq)
            .collect();
        if resp.len() as u64 != n {
            return Err(TbError::Deadlock {
                variant: self.name().into(),
                seed: self.seed,
                cycle: self.dut.cycle(),
                what: format!("{} of {n} AXI4-Lite responses", resp.len()),
            });
        }
        if let Some(bad) = resp.iter().find(|r| r.value.resp != RESP_OKAY) {
            return Err(self.protocol(bad.cycle, format!("an error response {:?}", bad.value)));
        }
        Ok(resp
            .iter()
            .rev()
            .find(|r| r.value.kind == AxilRecordKind::R)
            .map(|r| r.value.data))
    }

    /// The AXI4-Lite manager's and the AXI4 memory's protocol checkers.
    fn clean(&self, st: &crate::ffi::bridge::RunResult) -> Result<(), TbError> {
        if st.protocol_errors > 0 {
            return Err(self.protocol(
                st.first_protocol_error_cycle,
                "AXI4-Lite protocol rule broken (tb/axil_mgr.h)".into(),
            ));
        }
        let c = self.dut.axi_counters();
        if c.protocol_errors > 0 {
            return Err(self.protocol(
                c.first_error_cycle,
                format!("AXI4 checker: {}", self.dut.axi_first_error()),
            ));
        }
        Ok(())
    }

    /// Runs with the host idle until the interrupt is high, at most `max_cycles`; the cycles run.
    pub fn wait_irq(&mut self, max_cycles: u64) -> Result<u64, TbError> {
        self.flush(None)?;
        let traffic = Traffic {
            idle: Vec::new(),
            stall: self.host_stall.clone(),
        };
        let d = self.dut.drive(&[], &traffic, 0, max_cycles)?;
        self.clean(&d.stats)?;
        Ok(d.stats.cycles)
    }

    /// Resets the accelerator and its memory (transactions in flight are dropped on both sides);
    /// the tables must be loaded again.
    pub fn reset(&mut self) {
        self.queued.clear();
        self.dut.reset();
        self.loaded = None;
        self.lut_loaded = None;
    }

    /// The memory loaded with `vol` (blocked by `lut`) and set up as `env`, the tables, registers
    /// and bases written, the frame of `e` started; the image base. [`AccelBench::finish`] then
    /// waits for its end and compares the image in memory with the model's.
    pub fn start(
        &mut self,
        e: &Expected,
        vol: &Volume,
        lut: &BlockLut,
        env: &MemEnv,
        mem_seed: u64,
    ) -> Result<u64, TbError> {
        let rtl = self.rtl;
        let img_base = self.load_memory(e, vol, lut, env, mem_seed)?;
        self.host_stall = env.host_stall.clone();
        let (c, w) = (self.dut.axi_counters(), self.dut.axi_wr_counters());
        self.at_start = (c.ar_accepted, c.r_beats, w.aw_accepted, w.w_beats);
        let pitch = self.pitch;
        let park = self.park.0;
        let mut host = AccelHost::new(&mut *self, 0);
        start_frame(&mut host, &rtl, e, lut, (img_base, park), pitch).map_err(host_err)?;
        self.flush(None)?;
        Ok(img_base)
    }

    /// Waits for the interrupt, reads the status and the counters, compares the image.
    pub fn finish(&mut self, e: &Expected, img_base: u64, seed: u64) -> Result<FrameRun, TbError> {
        let limit = 200_000 + 40 * (e.params.ni * e.params.nj * e.params.nk / self.rtl.p) as u64;
        self.wait_irq(limit)?;
        let mut host = AccelHost::new(&mut *self, 0);
        let st = host.wait_done(1).map_err(host_err)?;
        let c = host.counters().map_err(host_err)?;
        if st.busy || !st.done {
            return Err(self.protocol(self.dut.cycle(), format!("status {st:?} after the irq")));
        }
        let (after, w) = (self.dut.axi_counters(), self.dut.axi_wr_counters());
        let run = FrameRun {
            cycles: c.cycles,
            samples: c.samples,
            ar: after.ar_accepted - self.at_start.0,
            r_beats: after.r_beats - self.at_start.1,
            aw: w.aw_accepted - self.at_start.2,
            w_beats: w.w_beats - self.at_start.3,
        };
        self.compare(e, img_base, seed)?;
        Ok(run)
    }

    /// `cycles` clock cycles with the host idle (stops early at the interrupt).
    pub fn idle(&mut self, cycles: u64) -> Result<(), TbError> {
        let d = self.dut.drive(&[], &Traffic::full_speed(), 0, cycles)?;
        self.clean(&d.stats)
    }

    /// The volume and a filled image area in the memory, the memory's behaviour; the image base.
    fn load_memory(
        &mut self,
        e: &Expected,
        vol: &Volume,
        lut: &BlockLut,
        env: &MemEnv,
        seed: u64,
    ) -> Result<u64, TbError> {
        let rtl = self.rtl;
        let mut img = dram_image(vol, lut, VOL_BASE).map_err(|x| TbError::setup(self.name(), x))?;
        let mut end = img.base + img.bytes.len() as u64;
        // With the window, the parked coxels' scratch area between the volume and the image:
        // `Wp H Cx` bytes.
        self.park = (0, 0);
        if rtl.window {
            let park = end.div_ceil(4096) * 4096;
            let bytes = u64::from(rtl.ctrl.row_pixels(e.w as u32)) * e.h as u64 * rtl.park_slot;
            self.park = (park, bytes);
            end = park + bytes;
        }
        let img_base = end.div_ceil(4096) * 4096;
        let img_bytes = self.pitch_bytes(e) * e.h;
        img.bytes
            .resize((img_base - img.base) as usize + img_bytes + 64, 0xee);
        let setup = AxiMemSetup {
            data_bytes: rtl.fetch.data_w / 8,
            addr_bits: rtl.fetch.addr_w,
            latency_fixed: env.latency.0,
            latency_random: env.latency.1,
            ar_gap_permille: env.gaps[0],
            r_gap_permille: env.gaps[1],
            bw_num: env.bw.0,
            bw_den: env.bw.1.max(1),
            max_bursts: 64,
            seed,
            slverr_lo: 0,
            slverr_hi: 0,
            aw_gap_permille: env.gaps[2],
            w_gap_permille: env.gaps[3],
            b_gap_permille: env.gaps[4],
            declared_outstanding: rtl.port_outstanding,
        };
        self.dut.axi_setup(&setup)?;
        self.dut.axi_load(img.base, &img.bytes)?;
        Ok(img_base)
    }

    /// The bytes from one image row to the next for the frame of `e` (`ImgPitch`, or the smallest
    /// pitch when it is 0: the control core's rule).
    pub fn pitch_bytes(&self, e: &Expected) -> usize {
        self.rtl.ctrl.pitch(self.pitch, e.w as u32) as usize
    }

    /// Every byte of the image in memory against the model's pixels: pixel `(r, q)` at the image
    /// base + `q` pitch + 4 `r`; nothing written outside the rows (each `W` rounded up to `P`
    /// pixels: the padding's values are unspecified).
    pub fn compare(&self, e: &Expected, img_base: u64, seed: u64) -> Result<(), TbError> {
        let mem = self.dut.axi_image()?;
        let at = (img_base - VOL_BASE) as usize;
        let pitch = self.pitch_bytes(e);
        let row = self.rtl.ctrl.row_pixels(e.w as u32) as usize * PIXEL_BYTES;
        for (q, line) in mem[at..at + pitch * e.h].chunks(pitch).enumerate() {
            if line[row..].iter().any(|&b| b != 0xee) {
                return Err(self.protocol(
                    self.dut.cycle(),
                    format!(
                        "bytes written between rows {q} and {} (pitch {pitch})",
                        q + 1
                    ),
                ));
            }
        }
        for (i, c) in e.want.iter().enumerate() {
            let want: Vec<u8> = c.rgba.iter().map(|&v| self.rtl.code(v)).collect();
            let o = at + pitch * (i / e.w) + PIXEL_BYTES * (i % e.w);
            let got = &mem[o..o + PIXEL_BYTES];
            if got != want.as_slice() {
                let (r, q) = (i % e.w, i / e.w);
                return Err(TbError::from(Mismatch {
                    variant: self.name().into(),
                    seed,
                    item: i as u64,
                    input: format!(
                        "view {} {:?}, {:?}, {:?}",
                        e.view, e.dir, e.units.render, e.params
                    ),
                    what: format!(
                        "pixel ({r}, {q}) of {} x {}: memory {got:?}, model {want:?} (coxel {c:?})",
                        e.w, e.h
                    ),
                    ..Default::default()
                }));
            }
        }
        // Nothing written past the image.
        let past = &mem[at + pitch * e.h..];
        if past.iter().any(|&b| b != 0xee) {
            return Err(self.protocol(self.dut.cycle(), "bytes written past the image".into()));
        }
        Ok(())
    }
}

fn host_err(e: HostError<TbError>) -> TbError {
    match e {
        HostError::Bus(t) => t,
        other => TbError::setup(TOP, other.to_string()),
    }
}

/// The tables (when they changed), the frame registers, the bases, the interrupt, start.
fn start_frame(
    host: &mut AccelHost<&mut AccelBench>,
    rtl: &AccelRtl,
    e: &Expected,
    lut: &BlockLut,
    (img_base, park_base): (u64, u64),
    pitch: u32,
) -> Result<(), HostError<TbError>> {
    let lut_loads = rtl.block_loads(lut).map_err(HostError::Bus)?;
    if host.bus().lut_loaded.as_ref() != Some(&lut_loads) {
        for (t, first, w) in &lut_loads {
            host.load_table(*t, *first, w)?;
        }
        host.bus().lut_loaded = Some(lut_loads);
    }
    let writes = e.units.config_writes(&rtl.frame);
    if host.bus().loaded.as_ref() != Some(&writes) {
        for (t, first, w) in rtl.table_loads(&writes) {
            host.load_table(t, first, &w)?;
        }
        host.bus().loaded = Some(writes);
    }
    let regs = rtl
        .frame
        .frame_writes(&e.params, e.units.render, e.units.tf2d, (0, 0));
    let word = |i: usize| regs[i].1[0];
    host.write_frame(&FrameRegs {
        dims: word(0),
        view: word(1),
        dx: word(2),
        dy: word(3),
        mode: word(4),
        skip: word(5),
    })?;
    host.set_bases(VOL_BASE, img_base)?;
    host.set_pitch(pitch)?;
    if rtl.window {
        host.set_park_base(park_base)?;
    }
    host.enable_irq(true, true)?;
    host.start()
}

/// The host driver's bus: writes are queued and go out with the next read (or wait).
impl RegBus for &mut AccelBench {
    type Error = TbError;

    fn read(&mut self, addr: u64) -> Result<u32, TbError> {
        self.flush(Some(txn(true, addr, 0)))?
            .ok_or_else(|| TbError::setup(TOP, "a read without its response"))
    }

    fn write(&mut self, addr: u64, data: u32) -> Result<(), TbError> {
        self.queued.push(txn(false, addr, data));
        Ok(())
    }
}

/// Bursts and beats of one AXI ID.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct IdCount {
    pub bursts: u64,
    pub beats: u64,
}

/// Bursts and beats per AXI ID of a memory's handshake log (`axi_take_ar`, `axi_take_aw`).
pub fn count_by_id(hs: &[crate::rtl::ArHandshake]) -> std::collections::BTreeMap<u32, IdCount> {
    let mut m = std::collections::BTreeMap::<u32, IdCount>::new();
    for h in hs {
        let e = m.entry(h.id).or_default();
        e.bursts += 1;
        e.beats += u64::from(h.len) + 1;
    }
    m
}
