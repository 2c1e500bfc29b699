//! Co-simulation of the accelerator's control core (cube5_accel_ctrl, docs/numerics/accel_ctrl.md)
//! against its transaction-level model (`cube5_model::units::cube5_accel_ctrl`). The host side is
//! the AXI4-Lite manager of tb/axil_mgr.h (random delays on AW, W, AR, back-pressure on B and R,
//! its protocol checker); the four command ports are stream sinks with their own random
//! back-pressure (tb/accel_ctrl_shim.h, which also checks that a stalled command holds), and the
//! frame's done and the writer's completions come after random delays. Per frame: every port's
//! stream equals the model's, command for command; the status code; `Status.busy` in every read
//! sampled while the frame runs and after; the interrupt's rising cycle; the cycle and sample
//! counters; all as the contract states them from the handshake and event cycles.

mod support;

use cube5_model::accel_host::{AccelHost, FrameRegs, RegBus};
use cube5_model::regs::cube5_accel::{
    CODE_ABORTED, CODE_AXIS_K, CODE_DIMS, CODE_FRAME, CODE_IMG_ALIGN, CODE_NONE, CODE_PITCH,
    CODE_RENDER, CODE_SKIP, CODE_SMALL, CODE_STEP, CODE_VOL_ALIGN, CODE_WRITE, REG_CTRL,
    REG_CYCLE_HI, REG_CYCLE_LO, REG_IMG_BASE_HI, REG_IMG_BASE_LO, REG_IMG_PITCH, REG_IRQ_ENABLE,
    REG_IRQ_STATUS, REG_SAMPLE_HI, REG_SAMPLE_LO, REG_STATUS, REG_STATUS_BUSY, REG_STATUS_CODE,
    REG_TABLE_ADDR, REG_TABLE_DATA, REG_TABLE_POS, REG_VIEW, REG_VOL_BASE_HI, REG_VOL_BASE_LO,
    TABLE_CLASS,
};
use cube5_model::units::cube5_accel_ctrl::{
    AccelCtrlCodec, AccelCtrlConfig, CtrlRecord, CtrlRegs, Outcome, CHECK_CYCLES, PORTS,
};
use cube5_model::units::cube5_axil::{AxilRecordKind, AxilTxn, RESP_OKAY};
use cube5_tb::rtl::{RtlStream, Taken, Traffic};
use cube5_tb::variants::Variant;
use cube5_tb::TbError;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::{configs, gate_configs, seed};

/// The shim's knobs (tb/accel_ctrl_shim.h, `kKnob*`).
const KNOB_CPL_DELAY: u32 = 0;
const KNOB_DONE_DELAY: u32 = 1;
const KNOB_FRAME_ERR: u32 = 2;
const KNOB_ERR_ROW: u32 = 3;
const KNOB_LAST_BIT: u32 = 4;
const KNOB_DRAIN_DELAY: u32 = 5;

/// The environment of one frame: delays, injected errors, back-pressure, host delays.
#[derive(Debug, Clone)]
struct Env {
    cpl_delay: u32,
    done_delay: u32,
    frame_err: bool,
    /// Row (from 1) whose completion answers SLVERR; 0 none.
    err_row: u32,
    stall: Vec<u8>,
    host_delay: u32,
}

impl Env {
    fn quiet() -> Self {
        Self {
            cpl_delay: 0,
            done_delay: 0,
            frame_err: false,
            err_row: 0,
            stall: Vec::new(),
            host_delay: 0,
        }
    }

    fn random(rng: &mut ChaCha8Rng) -> Self {
        let p = [0.0, 0.2, 0.5, 0.8][rng.random_range(0..4)];
        Self {
            cpl_delay: rng.random_range(0..40),
            done_delay: rng.random_range(0..60),
            frame_err: rng.random_bool(0.05),
            err_row: if rng.random_bool(0.05) {
                rng.random_range(1..8)
            } else {
                0
            },
            stall: (0..4111).map(|_| u8::from(rng.random_bool(p))).collect(),
            host_delay: rng.random_range(0..8),
        }
    }
}

struct Bench {
    dut: RtlStream<AccelCtrlCodec>,
    cfg: AccelCtrlConfig,
    seed: u64,
    stall: Vec<u8>,
    host_delay: u32,
    /// Every record since the last `take`.
    recs: Vec<Taken<CtrlRecord>>,
}

fn txn(read: bool, off: u32, data: u32, delay: u32) -> AxilTxn {
    AxilTxn {
        read,
        addr: off * 4,
        data,
        strb: 0xf,
        delay,
        w_delay: delay,
    }
}

impl Bench {
    fn open(v: &'static Variant, cfg: AccelCtrlConfig, seed: u64) -> Self {
        let dut = RtlStream::new(v, AccelCtrlCodec, seed as u32).unwrap_or_else(|e| panic!("{e}"));
        let mut b = Self {
            dut,
            cfg,
            seed,
            stall: Vec::new(),
            host_delay: 0,
            recs: Vec::new(),
        };
        b.knob(KNOB_LAST_BIT, cfg.frame_w() - 1);
        b
    }

    fn knob(&mut self, k: u32, v: u32) {
        self.dut
            .write_config(k, &[v])
            .unwrap_or_else(|e| panic!("{e}"));
    }

    fn env(&mut self, e: &Env) {
        self.knob(KNOB_CPL_DELAY, e.cpl_delay);
        self.knob(KNOB_DONE_DELAY, e.done_delay);
        self.knob(KNOB_FRAME_ERR, u32::from(e.frame_err));
        self.knob(KNOB_ERR_ROW, e.err_row);
        self.stall = e.stall.clone();
        self.host_delay = e.host_delay;
    }

    fn fail(&self, what: String) -> TbError {
        TbError::Protocol {
            variant: self.dut.name().into(),
            seed: self.seed,
            cycle: self.dut.cycle(),
            what,
        }
    }

    /// Drives `txns` (or, with none, `idle` cycles) and keeps the records; the responses.
    fn run(&mut self, txns: &[AxilTxn], idle: u64) -> Result<Vec<Taken<CtrlRecord>>, TbError> {
        let n = txns.len() as u64;
        let limit = if n == 0 { idle } else { 2000 + 400 * n };
        let traffic = Traffic {
            idle: Vec::new(),
            stall: self.stall.clone(),
        };
        let d = self.dut.drive(txns, &traffic, n, limit)?;
        if d.stats.protocol_errors > 0 {
            return Err(TbError::Protocol {
                variant: self.dut.name().into(),
                seed: self.seed,
                cycle: d.stats.first_protocol_error_cycle,
                what: "AXI4-Lite or command-port protocol broken (tb/axil_mgr.h, tb/accel_ctrl_shim.h)"
                    .into(),
            });
        }
        if n > 0 && d.stats.produced != n {
            return Err(self.fail(format!("{} of {n} responses", d.stats.produced)));
        }
        let resp: Vec<_> = d
            .outputs
            .iter()
            .filter(|t| matches!(&t.value, CtrlRecord::Axil(r) if r.kind != AxilRecordKind::Irq))
            .cloned()
            .collect();
        self.recs.extend(d.outputs);
        Ok(resp)
    }

    fn write(&mut self, off: u32, data: u32) -> Result<u64, TbError> {
        let d = self.host_delay;
        let r = self.run(&[txn(false, off, data, d)], 0)?;
        match r.first().map(|t| (&t.value, t.cycle)) {
            Some((CtrlRecord::Axil(b), c)) if b.resp == RESP_OKAY => {
                Ok((c & !0xffff_ffff) | u64::from(b.at))
            }
            other => Err(self.fail(format!("write of offset {off}: {other:?}"))),
        }
    }

    /// A read: (the cycle it was sampled, the data).
    fn read(&mut self, off: u32) -> Result<(u64, u32), TbError> {
        let d = self.host_delay;
        let r = self.run(&[txn(true, off, 0, d)], 0)?;
        match r.first().map(|t| (&t.value, t.cycle)) {
            Some((CtrlRecord::Axil(r), c)) if r.resp == RESP_OKAY => {
                Ok(((c & !0xffff_ffff) | u64::from(r.at), r.data))
            }
            other => Err(self.fail(format!("read of offset {off}: {other:?}"))),
        }
    }

    fn write_regs(&mut self, r: &CtrlRegs) -> Result<(), TbError> {
        let d = self.host_delay;
        let t: Vec<AxilTxn> = r
            .frame
            .writes()
            .into_iter()
            .chain([
                (REG_VOL_BASE_LO, r.vol_base as u32),
                (REG_VOL_BASE_HI, (r.vol_base >> 32) as u32),
                (REG_IMG_BASE_LO, r.img_base as u32),
                (REG_IMG_BASE_HI, (r.img_base >> 32) as u32),
                (REG_IMG_PITCH, r.img_pitch),
                (REG_IRQ_ENABLE, 3),
            ])
            .map(|(o, v)| txn(false, o, v, d))
            .collect();
        self.run(&t, 0).map(|_| ())
    }

    /// The command streams received since the last call, per port, trimmed to the port widths.
    fn take_streams(&mut self) -> [Vec<Vec<u32>>; 4] {
        let mut s: [Vec<Vec<u32>>; 4] = Default::default();
        for t in &self.recs {
            if let CtrlRecord::Cmd { port, bits } = &t.value {
                s[*port as usize].push(self.cfg.trim(*port, bits));
            }
        }
        s
    }
}

fn must<T>(r: Result<T, TbError>) -> T {
    r.unwrap_or_else(|e| panic!("{e}"))
}

/// One frame from the registers to the cleared interrupt, checked against the model and the
/// contract's timing. Returns the status code.
fn frame(b: &mut Bench, regs: &CtrlRegs, env: &Env) -> Result<u32, TbError> {
    b.env(env);
    b.write_regs(regs)?;
    b.recs.clear();
    let cfg = b.cfg;
    let plan = cfg.plan(regs);
    let t0 = b.write(REG_CTRL, 1)?;
    // Poll Status until the frame is over.
    let mut polls = Vec::new();
    for _ in 0..5000 {
        let (c, s) = b.read(REG_STATUS)?;
        polls.push((c, s));
        if REG_STATUS_BUSY.get(u64::from(s)) == 0 && c > t0 {
            break;
        }
        b.run(&[], u64::from(b.host_delay) * 4)?;
    }
    let (_, lo) = b.read(REG_CYCLE_LO)?;
    let (_, hi) = b.read(REG_CYCLE_HI)?;
    let (_, s_lo) = b.read(REG_SAMPLE_LO)?;
    let (_, s_hi) = b.read(REG_SAMPLE_HI)?;
    let got = b.take_streams();
    let ctx = |what: String| {
        format!(
            "{what}\n  registers {regs:x?}\n  env {:?}",
            Env {
                stall: Vec::new(),
                ..env.clone()
            }
        )
    };
    // Streams, command for command.
    let (want_streams, refused, samples) = match &plan {
        Ok(p) => (cfg.streams(p), CODE_NONE, p.samples),
        Err(code) => (Default::default(), *code, 0),
    };
    for port in PORTS {
        let (g, w) = (&got[port as usize], &want_streams[port as usize]);
        if g != w {
            let at = g
                .iter()
                .zip(w)
                .position(|(a, b)| a != b)
                .unwrap_or(g.len().min(w.len()));
            return Err(b.fail(ctx(format!(
                "{port:?} stream: {} commands, model {}; first difference at {at}: RTL {:x?}, model {:x?}",
                g.len(),
                w.len(),
                g.get(at),
                w.get(at)
            ))));
        }
    }
    // The end cycle te: one after the last handshake or event (the check cycle t0 + CHECK_CYCLES
    // when refused; accepted frames issue from t0 + CHECK_CYCLES + 1).
    let mut last = t0 + CHECK_CYCLES - 1;
    let mut rows = 0u32;
    for t in &b.recs {
        match &t.value {
            CtrlRecord::Cmd { .. } | CtrlRecord::FrameDone { .. } => last = last.max(t.cycle),
            CtrlRecord::Completion { .. } => {
                rows += 1;
                last = last.max(t.cycle);
            }
            _ => {}
        }
    }
    let te = last + 1;
    let rows_n = plan.as_ref().map_or(0, |p| p.rows.len() as u32);
    let outcome = Outcome {
        refused,
        frame_error: plan.is_ok() && env.frame_err,
        write_error: env.err_row >= 1 && env.err_row <= rows_n,
        aborted: false,
    };
    let want_code = outcome.code();
    if rows != rows_n {
        return Err(b.fail(ctx(format!("{rows} completions for {rows_n} rows"))));
    }
    // Status in every poll: busy from t0 + 1 to te, then the outcome.
    for &(c, s) in &polls {
        let f = |fl: cube5_model::regmap::Field| fl.get(u64::from(s)) as u32;
        let ok = if c <= t0 {
            true
        } else if c <= te {
            f(REG_STATUS_BUSY) == 1 && s >> 1 == 0
        } else {
            s == outcome.status()
        };
        if !ok {
            return Err(b.fail(ctx(format!(
                "Status {s:#x} sampled in cycle {c} (start strobe {t0}, end {te}, code {want_code})"
            ))));
        }
    }
    // The interrupt rises in te + 1.
    let rise = b.recs.iter().find_map(|t| match &t.value {
        CtrlRecord::Axil(r) if r.kind == AxilRecordKind::Irq && r.irq => {
            Some((t.cycle & !0xffff_ffff) | u64::from(r.at))
        }
        _ => None,
    });
    if rise != Some(te + 1) {
        return Err(b.fail(ctx(format!("irq_o rose in {rise:?}, contract {}", te + 1))));
    }
    let cycles = u64::from(lo) | u64::from(hi) << 32;
    let samp = u64::from(s_lo) | u64::from(s_hi) << 32;
    if cycles != te - t0 || samp != samples {
        return Err(b.fail(ctx(format!(
            "counters: cycles {cycles}, samples {samp}; contract {} and {samples}",
            te - t0
        ))));
    }
    b.write(REG_IRQ_STATUS, 3)?;
    b.recs.clear();
    Ok(want_code)
}

fn pack_dims(cfg: &AccelCtrlConfig, d: [u32; 3]) -> u32 {
    let m1 = cfg.m() + 1;
    d[0] | d[1] << m1 | d[2] << (2 * m1)
}

/// A legal frame of `dims` (volume axes) seen along `axis_k` (reversed or not) with steps dx, dy.
fn regs_of(
    cfg: &AccelCtrlConfig,
    dims: [u32; 3],
    axis_k: u32,
    rev: bool,
    dx: i32,
    dy: i32,
) -> CtrlRegs {
    CtrlRegs {
        frame: FrameRegs {
            dims: pack_dims(cfg, dims),
            view: axis_k | u32::from(rev) << 2,
            dx: dx as u32 & 0x3_ffff,
            dy: dy as u32 & 0x3_ffff,
            mode: 1,
            skip: 0,
        },
        vol_base: 0x40 * u64::from(cfg.data_w / 8),
        img_base: 0x100 * u64::from(cfg.pixel_bytes),
        img_pitch: 0,
    }
}

/// Random registers: mostly frames the core accepts, some it refuses for each reason.
fn random_regs(rng: &mut ChaCha8Rng, cfg: &AccelCtrlConfig) -> CtrlRegs {
    let p = cfg.p;
    let md = cfg.max_dim.min(96);
    let dim = |rng: &mut ChaCha8Rng| {
        if rng.random_bool(0.03) {
            rng.random_range(0..=cfg.max_dim + 2)
        } else {
            let lo = (2 * p).max(8).div_ceil(p);
            p * rng.random_range(lo..=md / p)
        }
    };
    let dims = [dim(rng), dim(rng), dim(rng)];
    let step = |rng: &mut ChaCha8Rng| -> i32 {
        match rng.random_range(0..20) {
            0 => 1 << 16,
            1 => -(1 << 16),
            2 => 0,
            3 if rng.random_bool(0.3) => rng.random_range(-(1 << 17)..(1 << 17)),
            _ => rng.random_range(-(1 << 16)..=(1 << 16)),
        }
    };
    let m1 = cfg.m() + 1;
    let axis = if rng.random_bool(0.03) {
        3
    } else {
        rng.random_range(0..3)
    };
    let skip = if rng.random_bool(0.2) {
        rng.random_range(0..12) | rng.random_range(0..12) << m1
    } else {
        0
    };
    let mode = if rng.random_bool(0.03) {
        rng.random_range(5..8)
    } else {
        rng.random_range(0..5)
    } | rng.random_range(0..4) << 3;
    let align = |rng: &mut ChaCha8Rng, a: u64| -> u64 {
        let v: u64 = rng.random::<u64>() >> rng.random_range(0..64);
        if rng.random_bool(0.05) {
            v | 1
        } else {
            v & !(a - 1)
        }
    };
    CtrlRegs {
        frame: FrameRegs {
            dims: pack_dims(cfg, dims)
                | if rng.random_bool(0.1) {
                    rng.random::<u32>() & !((1 << (3 * m1)) - 1)
                } else {
                    0
                },
            view: axis | rng.random_range(0..2) << 2,
            dx: step(rng) as u32 & 0x3_ffff,
            dy: step(rng) as u32 & 0x3_ffff,
            mode,
            skip,
        },
        vol_base: align(rng, u64::from(cfg.data_w / 8)),
        img_base: align(rng, cfg.row_align()),
        // ImgPitch: mostly 0 (the smallest), else aligned (some below the row), rarely not.
        img_pitch: match rng.random_range(0..10) {
            0..=4 => 0,
            5 => rng.random::<u32>() >> rng.random_range(0..32),
            _ => {
                rng.random_range(0..=(4 * cfg.max_dim * cfg.pixel_bytes) as u64 / cfg.row_align())
                    as u32
                    * cfg.row_align() as u32
            }
        },
    }
}

#[test]
fn random_register_programs_match_the_model_stream_by_stream() {
    let s = seed(0xacc1);
    for (v, cfg) in configs::<AccelCtrlConfig>() {
        let mut rng = ChaCha8Rng::seed_from_u64(s ^ u64::from(cfg.max_dim));
        let mut b = Bench::open(v, cfg, s);
        let n = if cfg.max_dim > 64 { 400 } else { 1500 };
        let mut codes = [0u32; 13];
        for _ in 0..n {
            let regs = random_regs(&mut rng, &cfg);
            let env = Env::random(&mut rng);
            codes[must(frame(&mut b, &regs, &env)) as usize] += 1;
        }
        assert!(
            codes[CODE_NONE as usize] > n / 3,
            "{v}: too few accepted frames: {codes:?}"
        );
        eprintln!("{v}: {n} frames, codes {codes:?}");
    }
}

#[test]
fn directed_extremes_faces_directions_and_section_counts() {
    let s = seed(0xacc2);
    for (v, cfg) in configs::<AccelCtrlConfig>() {
        let mut b = Bench::open(v, cfg, s);
        let (p, md, sw) = (cfg.p, cfg.max_dim, cfg.section);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        // One section (ni <= S), many sections (ni = MaxDim), and a last section narrower than S.
        let one = sw.max(2 * p).max(8);
        for ni in [one, md, sw + p.max(8)] {
            for axis in 0..3u32 {
                for rev in [false, true] {
                    for dx in [-(1 << 16), -1, 0, 1, 1 << 16] {
                        let mut dims = [16.max(2 * p); 3];
                        let ai = if axis == 0 { 1 } else { 0 };
                        dims[ai] = ni.min(md);
                        let regs = regs_of(&cfg, dims, axis, rev, dx, -dx / 2);
                        let env = Env::random(&mut rng);
                        let code = must(frame(&mut b, &regs, &env));
                        assert!(
                            code == CODE_NONE || code == CODE_FRAME || code == CODE_WRITE,
                            "{v}: {regs:x?} refused {code}"
                        );
                    }
                }
            }
        }
        // Each refusal.
        let ok = regs_of(&cfg, [16, 16, 16], 2, false, 0, 0);
        // `ok` with other frame words.
        let with = |frame: FrameRegs| CtrlRegs { frame, ..ok };
        let dims = |d: [u32; 3]| {
            with(FrameRegs {
                dims: pack_dims(&cfg, d),
                ..ok.frame
            })
        };
        let mut cases: Vec<(CtrlRegs, u32)> = vec![
            (
                with(FrameRegs {
                    view: 3,
                    ..ok.frame
                }),
                CODE_AXIS_K,
            ),
            (dims([16, 16 + p / 2, 16]), CODE_DIMS),
            (dims([16, 0, 16]), CODE_DIMS),
            (dims([16, 2 * md, 16]), CODE_DIMS),
            (
                with(FrameRegs {
                    mode: 5,
                    ..ok.frame
                }),
                CODE_RENDER,
            ),
            (
                with(FrameRegs {
                    dx: (1 << 16) + 1,
                    ..ok.frame
                }),
                CODE_STEP,
            ),
            (
                with(FrameRegs {
                    dy: 1 << 17,
                    ..ok.frame
                }),
                CODE_STEP,
            ),
            (
                with(FrameRegs {
                    skip: 8 | 8 << (cfg.m() + 1),
                    ..ok.frame
                }),
                CODE_SKIP,
            ),
            (dims([p, 16, 16]), CODE_SMALL),
            (
                CtrlRegs {
                    vol_base: ok.vol_base + 2,
                    ..ok
                },
                CODE_VOL_ALIGN,
            ),
        ];
        if cfg.pixel_bytes > 1 {
            cases.push((
                CtrlRegs {
                    img_base: ok.img_base + 1,
                    ..ok
                },
                CODE_IMG_ALIGN,
            ));
        }
        // ImgPitch: not a multiple of the row alignment, below the row (W = 16 pixels here).
        let a = cfg.row_align() as u32;
        let row = 16 * cfg.pixel_bytes;
        if a > 1 {
            cases.push((
                CtrlRegs {
                    img_pitch: row.next_multiple_of(a) + a / 2,
                    ..ok
                },
                CODE_PITCH,
            ));
        }
        cases.push((
            CtrlRegs {
                img_pitch: row - a,
                ..ok
            },
            CODE_PITCH,
        ));
        for (regs, want) in cases {
            let code = must(frame(&mut b, &regs, &Env::quiet()));
            assert_eq!(code, want, "{v}: {regs:x?}");
        }
        // Injected errors: the frame's, a row's.
        let e = Env {
            frame_err: true,
            ..Env::quiet()
        };
        assert_eq!(must(frame(&mut b, &ok, &e)), CODE_FRAME);
        let e = Env {
            err_row: 3,
            ..Env::quiet()
        };
        assert_eq!(must(frame(&mut b, &ok, &e)), CODE_WRITE);
        assert_eq!(must(frame(&mut b, &ok, &Env::quiet())), CODE_NONE);
    }
}

/// The streams so far must be prefixes of the model's: no command half-issued, none skipped.
fn assert_prefixes(b: &mut Bench, regs: &CtrlRegs, v: &Variant) {
    let got = b.take_streams();
    let want = b.cfg.streams(&b.cfg.plan(regs).expect("accepted"));
    for port in PORTS {
        let (g, w) = (&got[port as usize], &want[port as usize]);
        assert!(
            g.len() <= w.len() && g[..] == w[..g.len()],
            "{v}: {port:?} not a prefix: {} of {}",
            g.len(),
            w.len()
        );
    }
}

#[test]
fn reset_mid_frame_then_the_next_frame_is_exact() {
    let s = seed(0xacc3);
    for (v, cfg) in configs::<AccelCtrlConfig>() {
        let mut b = Bench::open(v, cfg, s);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        for k in 0..12u32 {
            let regs = regs_of(
                &cfg,
                [cfg.max_dim.min(64), 16, 16],
                2,
                k.is_multiple_of(2),
                if k.is_multiple_of(3) { -300 } else { 300 },
                0,
            );
            let env = Env {
                stall: (0..4111).map(|_| u8::from(rng.random_bool(0.6))).collect(),
                cpl_delay: 30,
                ..Env::quiet()
            };
            b.env(&env);
            must(b.write_regs(&regs));
            b.recs.clear();
            must(b.write(REG_CTRL, 1));
            must(b.run(&[], rng.random_range(1..200)));
            assert_prefixes(&mut b, &regs, v);
            b.dut.reset();
            b.recs.clear();
            // After the reset: registers at their reset values, the core idle, the next frame exact.
            let (_, st) = must(b.read(REG_STATUS));
            assert_eq!(st, 0, "{v}: Status after reset");
            let env = Env::random(&mut rng);
            let r2 = random_regs(&mut rng, &cfg);
            must(frame(&mut b, &r2, &env));
        }
    }
}

#[test]
fn soft_reset_ends_the_frame_when_the_data_path_has_drained() {
    let s = seed(0xacc4);
    for (v, cfg) in configs::<AccelCtrlConfig>() {
        let mut b = Bench::open(v, cfg, s);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        let mut aborted = 0;
        for _ in 0..10 {
            let regs = regs_of(&cfg, [cfg.max_dim.min(64), 32, 16], 1, false, 1000, 0);
            let env = Env {
                stall: (0..4111).map(|_| u8::from(rng.random_bool(0.7))).collect(),
                cpl_delay: 20,
                ..Env::quiet()
            };
            b.env(&env);
            b.knob(KNOB_DRAIN_DELAY, rng.random_range(0..100));
            must(b.write_regs(&regs));
            b.recs.clear();
            let t0 = must(b.write(REG_CTRL, 1));
            must(b.run(&[], rng.random_range(1..120)));
            must(b.write(REG_CTRL, 2));
            let mut st = 0;
            for _ in 0..2000 {
                st = must(b.read(REG_STATUS)).1;
                if REG_STATUS_BUSY.get(u64::from(st)) == 0 {
                    break;
                }
            }
            assert_eq!(
                REG_STATUS_BUSY.get(u64::from(st)),
                0,
                "{v}: still busy after the soft reset"
            );
            let code = REG_STATUS_CODE.get(u64::from(st)) as u32;
            assert!(
                code == CODE_ABORTED || code == CODE_NONE,
                "{v}: code {code}"
            );
            if code == CODE_ABORTED {
                aborted += 1;
                // The frame ends in the cycle of drained_i (te): no command after it, the
                // interrupt in te + 1, the cycle counter te - t0, the plan's samples.
                let drained: Vec<u64> = b
                    .recs
                    .iter()
                    .filter(|t| matches!(&t.value, CtrlRecord::Drained))
                    .map(|t| t.cycle)
                    .collect();
                assert_eq!(drained.len(), 1, "{v}: one drain per soft reset");
                let te = drained[0];
                let late = b
                    .recs
                    .iter()
                    .find(|t| t.cycle > te && matches!(&t.value, CtrlRecord::Cmd { .. }));
                assert!(late.is_none(), "{v}: a command after the drain: {late:?}");
                let rise = b.recs.iter().find_map(|t| match &t.value {
                    CtrlRecord::Axil(r) if r.kind == AxilRecordKind::Irq && r.irq => {
                        Some((t.cycle & !0xffff_ffff) | u64::from(r.at))
                    }
                    _ => None,
                });
                assert_eq!(rise, Some(te + 1), "{v}: the interrupt (start {t0})");
                let (_, lo) = must(b.read(REG_CYCLE_LO));
                let (_, hi) = must(b.read(REG_CYCLE_HI));
                assert_eq!(u64::from(lo) | u64::from(hi) << 32, te - t0, "{v}: cycles");
                let (_, s_lo) = must(b.read(REG_SAMPLE_LO));
                let samples = cfg.plan(&regs).expect("accepted").samples;
                assert_eq!(u64::from(s_lo), samples, "{v}: samples");
            }
            assert_prefixes(&mut b, &regs, v);
            // Let a late frame done pass, clear, and check the next frame is exact.
            must(b.run(&[], 200));
            must(b.write(REG_IRQ_STATUS, 3));
            b.recs.clear();
            must(frame(&mut b, &regs, &Env::random(&mut rng)));
        }
        assert!(aborted > 0, "{v}: no frame was aborted");
    }
}

#[test]
fn table_writes_step_the_index() {
    let s = seed(0xacc5);
    for (v, cfg) in configs::<AccelCtrlConfig>() {
        let mut b = Bench::open(v, cfg, s);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        for _ in 0..4 {
            let table = rng.random_range(0..16u32);
            let first = if rng.random_bool(0.5) {
                0xfffc
            } else {
                rng.random_range(0..1000u32)
            };
            b.host_delay = rng.random_range(0..3);
            must(b.write(REG_TABLE_ADDR, first | table << 16));
            b.recs.clear();
            let data: Vec<u32> = (0..9).map(|_| rng.random()).collect();
            for &d in &data {
                must(b.write(REG_TABLE_DATA, d));
            }
            let got: Vec<(u32, u32, u32)> = b
                .recs
                .iter()
                .filter_map(|t| match t.value {
                    CtrlRecord::Table { table, index, data } => Some((table, index, data)),
                    _ => None,
                })
                .collect();
            let want: Vec<(u32, u32, u32)> = data
                .iter()
                .enumerate()
                .map(|(i, &d)| (table, (first + i as u32) & 0xffff, d))
                .collect();
            assert_eq!(got, want, "{v}");
            let (_, pos) = must(b.read(REG_TABLE_POS));
            assert_eq!(pos, ((first + 9) & 0xffff) | table << 16, "{v}: TablePos");
        }
    }
}

/// The host driver (`AccelHost`) over the bench.
impl RegBus for Bench {
    type Error = TbError;
    fn read(&mut self, addr: u64) -> Result<u32, TbError> {
        Bench::read(self, (addr / 4) as u32).map(|r| r.1)
    }
    fn write(&mut self, addr: u64, data: u32) -> Result<(), TbError> {
        Bench::write(self, (addr / 4) as u32, data).map(|_| ())
    }
}

#[test]
fn the_host_driver_renders_a_frame_on_the_rtl() {
    let s = seed(0xacc6);
    let (v, cfg) = configs::<AccelCtrlConfig>()[0];
    let mut b = Bench::open(v, cfg, s);
    b.env(&Env {
        cpl_delay: 5,
        done_delay: 10,
        ..Env::quiet()
    });
    let regs = regs_of(&cfg, [32, 16, 24], 0, true, -5000, 7000);
    let mut host = AccelHost::new(b, 0);
    host.write_frame(&regs.frame).unwrap();
    host.set_bases(regs.vol_base, regs.img_base).unwrap();
    host.load_table(TABLE_CLASS, 5, &[1, 2, 3]).unwrap();
    assert_eq!(host.table_pos().unwrap(), (TABLE_CLASS, 8));
    host.enable_irq(true, true).unwrap();
    host.start().unwrap();
    let st = host.wait_done(10_000).unwrap();
    assert!(st.done && !st.error);
    let c = host.counters().unwrap();
    let plan = cfg.plan(&regs).unwrap();
    assert_eq!(c.samples, plan.samples);
    let mut b = host.into_bus();
    assert_eq!(b.take_streams(), cfg.streams(&plan));
    // A refused frame is an error from the driver, with its code in Status.
    let mut host = AccelHost::new(b, 0);
    host.write(REG_VIEW, 3).unwrap();
    host.start().unwrap();
    assert!(host.wait_done(1000).is_err());
    assert_eq!(host.status_code().unwrap(), CODE_AXIS_K);
}

#[test]
fn gate_level_smoke() {
    let s = seed(0xacc7);
    for (v, cfg) in gate_configs::<AccelCtrlConfig>() {
        let mut b = Bench::open(v, cfg, s);
        let mut rng = ChaCha8Rng::seed_from_u64(s);
        for _ in 0..12 {
            let regs = random_regs(&mut rng, &cfg);
            let env = Env::random(&mut rng);
            must(frame(&mut b, &regs, &env));
        }
        let regs = regs_of(&cfg, [cfg.max_dim, 16, 16], 2, false, -(1 << 16), 0);
        assert_eq!(must(frame(&mut b, &regs, &Env::quiet())), CODE_NONE);
    }
}

#[test]
fn the_check_fails_when_the_model_disagrees() {
    let s = seed(0xacc8);
    let (v, cfg) = configs::<AccelCtrlConfig>()[0];
    let mut b = Bench::open(v, cfg, s);
    let regs = regs_of(&cfg, [cfg.max_dim, 16, 16], 2, false, 100, 0);
    assert_eq!(must(frame(&mut b, &regs, &Env::quiet())), CODE_NONE);
    // A model with twice the section width plans other sections: the comparison must fail.
    b.cfg.section *= 2;
    let e = frame(&mut b, &regs, &Env::quiet()).expect_err("a wrong model passed");
    assert!(e.to_string().contains("stream"), "{e}");
}
