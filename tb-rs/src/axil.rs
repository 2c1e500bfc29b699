//! Driving the AXI4-Lite register block (`cube5_axil`) against the cycle-level register-file model
//! (`cube5_model::units::cube5_axil`). The manager runs in C++ (tb/axil_mgr.h: per-transaction
//! delays on AW, W, AR, back-pressure on B and R, a protocol checker on all five channels); each
//! batch returns the responses with the cycles they happened in, and [`AxilBench`] replays the
//! model over the same cycles: the write done in the cycle before its first BVALID, the read
//! sampled in its AR cycle, the hardware side's stimulus (`top_stimulus`) every cycle. Every
//! response, every first-cycle `hw_q_o` / strobe and the interrupt level in every cycle observed
//! are compared; the first difference is a [`Mismatch`] naming the transaction, its inputs and
//! both values.

use crate::error::{Mismatch, TbError};
use crate::rtl::{RtlStream, Traffic};
use crate::variants::Variant;
use cube5_model::accel_host::RegBus;
use cube5_model::units::cube5_axil::{
    top_ro, top_set, top_stimulus, AxilCodec, AxilConfig, AxilRecord, AxilRecordKind, AxilTxn,
    BusWrite, RegFile, RESP_OKAY,
};
use rand::Rng;

/// What one batch did.
#[derive(Debug, Clone, Copy, Default)]
pub struct AxilRun {
    /// Transactions whose request was handed over completely.
    pub issued: u64,
    /// Responses taken.
    pub responses: u64,
    pub cycles: u64,
    /// Whether every transaction was answered (false: cut by `max_cycles`).
    pub complete: bool,
}

/// One `cube5_axil` variant and its model, cycle for cycle.
pub struct AxilBench {
    dut: RtlStream<AxilCodec>,
    cfg: AxilConfig,
    file: RegFile,
    seed: u64,
    stim_seed: u32,
    /// The next cycle whose clock edge the model has not applied.
    next_cycle: u64,
    /// The RTL's interrupt level as its records tell it.
    rtl_irq: Option<bool>,
    /// Writes of a cut batch without a response: their registers are forgotten at the reset.
    unanswered: Vec<u32>,
    /// Transactions driven since the bench opened (numbers the items in a mismatch).
    item_base: u64,
    /// Everything driven since the bench opened, to re-run it with a waveform after a mismatch.
    history: Vec<Op>,
}

/// One step of a bench's history.
enum Op {
    Run(Vec<AxilTxn>, Vec<u8>, Option<u64>),
    Reset,
}

impl AxilBench {
    /// Opens `variant` (Verilator's random-reset seed and the hardware stimulus from `seed`).
    pub fn open(variant: &'static Variant, seed: u64) -> Result<Self, TbError> {
        let cfg: AxilConfig = variant
            .config()
            .map_err(|e| TbError::setup(variant.name, e))?;
        let stim_seed = (seed as u32) ^ (seed >> 32) as u32;
        let dut = RtlStream::new(variant, AxilCodec, stim_seed)?;
        let next_cycle = dut.cycle();
        Ok(Self {
            dut,
            cfg,
            file: RegFile::new(cfg.map()),
            seed,
            stim_seed,
            next_cycle,
            rtl_irq: None,
            unanswered: Vec::new(),
            item_base: 0,
            history: Vec::new(),
        })
    }

    pub fn config(&self) -> &AxilConfig {
        &self.cfg
    }

    pub fn name(&self) -> &'static str {
        self.dut.name()
    }

    pub fn cycle(&self) -> u64 {
        self.dut.cycle()
    }

    /// The model's register file (what the block holds now).
    pub fn model(&self) -> &RegFile {
        &self.file
    }

    /// The model, to make it disagree on purpose (the test that the scoreboard can fail).
    pub fn model_mut(&mut self) -> &mut RegFile {
        &mut self.file
    }

    /// Resets the RTL (four cycles) and the model; responses in flight are dropped.
    pub fn reset(&mut self) {
        self.history.push(Op::Reset);
        self.dut.reset();
        for o in std::mem::take(&mut self.unanswered) {
            self.file.forget(o);
        }
        self.file.reset();
        self.next_cycle = self.dut.cycle();
    }

    /// Drives `txns` with B/R back-pressure from `stall` until every one is answered, or until
    /// `max_cycles` (then `complete` is false and the next call must be [`AxilBench::reset`]).
    pub fn run(
        &mut self,
        txns: &[AxilTxn],
        stall: &[u8],
        max_cycles: Option<u64>,
    ) -> Result<AxilRun, TbError> {
        self.run_records(txns, stall, max_cycles).map(|(r, _)| r)
    }

    /// One transaction at full speed, checked like any other; its response.
    pub fn transact(&mut self, txn: AxilTxn) -> Result<AxilRecord, TbError> {
        let (_, recs) = self.run_records(&[txn], &[], None)?;
        recs.into_iter()
            .find(|r| r.kind != AxilRecordKind::Irq)
            .ok_or_else(|| TbError::setup(self.dut.name(), "no response"))
    }

    fn run_records(
        &mut self,
        txns: &[AxilTxn],
        stall: &[u8],
        max_cycles: Option<u64>,
    ) -> Result<(AxilRun, Vec<AxilRecord>), TbError> {
        self.history
            .push(Op::Run(txns.to_vec(), stall.to_vec(), max_cycles));
        let name = self.dut.name();
        let start = self.dut.cycle();
        let expect = txns.len() as u64;
        let limit = max_cycles.unwrap_or(1000 + expect * 600);
        let traffic = Traffic {
            idle: Vec::new(),
            stall: stall.to_vec(),
        };
        let driven = self.dut.drive(txns, &traffic, expect, limit)?;
        let st = driven.stats;
        let end = self.dut.cycle();
        if st.protocol_errors > 0 {
            return Err(TbError::Protocol {
                variant: name.into(),
                seed: self.seed,
                cycle: st.first_protocol_error_cycle,
                what: "AXI4-Lite protocol rule broken (tb/axil_mgr.h: VALID held until READY, \
                       payload stable, one response per request)"
                    .into(),
            });
        }
        let complete = st.produced == expect;
        if !complete && max_cycles.is_none() {
            return Err(TbError::Deadlock {
                variant: name.into(),
                seed: self.seed,
                cycle: end,
                what: format!("{} of {expect} responses after {limit} cycles", st.produced),
            });
        }
        if let Err(e) = self.replay(txns, &driven.outputs, start, end, complete) {
            return Err(self.with_waves(e));
        }
        self.item_base += expect;
        let run = AxilRun {
            issued: st.consumed,
            responses: st.produced,
            cycles: st.cycles,
            complete,
        };
        Ok((run, driven.outputs.into_iter().map(|t| t.value).collect()))
    }

    /// A mismatch with the waveform of the 64 cycles before it: the whole history re-run on a
    /// fresh instance of the same variant and seed, traced around the mismatch
    /// (`target/cube5-waves/`; `CUBE5_NO_WAVES=1` turns this off).
    fn with_waves(&self, e: TbError) -> TbError {
        let TbError::Mismatch(mut m) = e else {
            return e;
        };
        if std::env::var_os("CUBE5_NO_WAVES").is_some() {
            return TbError::Mismatch(m);
        }
        let dir = std::path::PathBuf::from(
            std::env::var("CARGO_TARGET_DIR").unwrap_or_else(|_| "target".into()),
        )
        .join("cube5-waves");
        let _ = std::fs::create_dir_all(&dir);
        let path = dir.join(format!("{}-seed{}.vcd", m.variant, self.seed));
        if let Ok(mut dut) = RtlStream::new(self.dut.variant(), AxilCodec, self.stim_seed) {
            dut.trace_window(&path, m.cycle.saturating_sub(64), m.cycle + 8);
            for op in &self.history {
                match op {
                    Op::Run(t, stall, max) => {
                        let traffic = Traffic {
                            idle: Vec::new(),
                            stall: stall.clone(),
                        };
                        let n = t.len() as u64;
                        let _ = dut.drive(t, &traffic, n, max.unwrap_or(1000 + n * 600));
                    }
                    Op::Reset => dut.reset(),
                }
            }
            // The file is complete when the instance closes it.
            drop(dut);
            m.waveform = path.exists().then_some(path);
        }
        TbError::Mismatch(m)
    }

    fn offset(&self, addr: u32) -> u32 {
        (addr & ((1u32 << self.cfg.addr_w.min(31)) - 1)) >> 2
    }

    /// Replays the model over cycles `[self.next_cycle, end)`; cycles from `start` were observed.
    fn replay(
        &mut self,
        txns: &[AxilTxn],
        outputs: &[crate::rtl::Taken<AxilRecord>],
        start: u64,
        end: u64,
        complete: bool,
    ) -> Result<(), TbError> {
        let writes: Vec<(usize, &AxilTxn)> =
            txns.iter().enumerate().filter(|(_, t)| !t.read).collect();
        let reads: Vec<(usize, &AxilTxn)> =
            txns.iter().enumerate().filter(|(_, t)| t.read).collect();
        let full = |at: u32| (start & !0xffff_ffff) | u64::from(at);
        let mut bs = Vec::new();
        let mut rs = Vec::new();
        let mut irqs = Vec::new();
        for o in outputs {
            match o.value.kind {
                AxilRecordKind::B => bs.push((o.cycle, o.value)),
                AxilRecordKind::R => rs.push((o.cycle, o.value)),
                AxilRecordKind::Irq => irqs.push(o.value),
            }
        }
        // A cut batch is exact up to its last B handshake (a write without a response can land
        // no earlier than the cycle after it).
        let exact_to = if complete {
            end
        } else {
            bs.last().map_or(start, |b| b.0 + 1)
        };
        if !complete {
            self.unanswered = writes[bs.len()..]
                .iter()
                .map(|(_, t)| self.offset(t.addr))
                .collect();
        }
        let (mut bi, mut ri, mut qi) = (0, 0, 0);
        let mut c = self.next_cycle;
        while c < end {
            let (hw, hw_set) = top_stimulus(self.stim_seed, c);
            // Interrupt records of this cycle, then the level against the model.
            while qi < irqs.len() && full(irqs[qi].at) == c {
                self.rtl_irq = Some(irqs[qi].irq);
                qi += 1;
            }
            if c >= start && c < exact_to {
                if let Some(want) = self.file.irq() {
                    if self.rtl_irq != Some(want) {
                        return Err(self.mismatch(
                            self.item_base,
                            c,
                            "irq_o",
                            "the interrupt level".into(),
                            format!("{:?}", self.rtl_irq),
                            format!("{want}"),
                        ));
                    }
                }
            }
            // Reads sampled in this cycle.
            while ri < rs.len() && full(rs[ri].1.at) == c {
                let (taken, r) = rs[ri];
                let (item, t) = reads[ri];
                let off = self.offset(t.addr);
                let want = self.file.read(off, top_ro(off, hw));
                if r.aux != r.at.wrapping_add(1) {
                    return Err(self.mismatch_txn(
                        item,
                        taken,
                        t,
                        &r,
                        "RVALID not in the cycle after AR".into(),
                    ));
                }
                if c < exact_to {
                    let data_ok = want.data.is_none_or(|d| d == r.data);
                    if r.resp != want.resp || !data_ok || r.stb != (want.resp == RESP_OKAY) {
                        return Err(self.mismatch_txn(
                            item,
                            taken,
                            t,
                            &r,
                            format!(
                                "RRESP {}, RDATA {}, rd_stb {}",
                                want.resp,
                                want.data.map_or("unknown".into(), |d| format!("{d:#010x}")),
                                want.resp == RESP_OKAY
                            ),
                        ));
                    }
                }
                ri += 1;
            }
            // The first cycle of a B: the write landed at the last edge.
            while bi < bs.len() && full(bs[bi].1.at) == c {
                let (taken, b) = bs[bi];
                let (item, t) = writes[bi];
                let off = self.offset(t.addr);
                let resp = self.file.write_resp(off);
                let hw_q = self.file.hw_word(off);
                let late = u64::from(b.at.wrapping_sub(b.aux)) < 2;
                if late
                    || b.resp != resp
                    || b.stb != (resp == RESP_OKAY)
                    || hw_q.is_some_and(|q| q != b.data)
                {
                    return Err(self.mismatch_txn(
                        item,
                        taken,
                        t,
                        &b,
                        format!(
                            "BRESP {resp}, hw_q {}, wr_stb {}, BVALID >= 2 cycles after AW and W",
                            hw_q.map_or("unknown".into(), |d| format!("{d:#010x}")),
                            resp == RESP_OKAY
                        ),
                    ));
                }
                bi += 1;
            }
            // This cycle's edge: the write whose B starts next cycle, then the hardware's sets.
            let write = bs.get(bi).filter(|b| full(b.1.at) == c + 1).map(|_| {
                let t = writes[bi].1;
                BusWrite {
                    offset: self.offset(t.addr),
                    data: t.data,
                    strb: t.strb,
                }
            });
            self.file.edge(write, &|o| top_set(o, hw, hw_set));
            c += 1;
        }
        self.next_cycle = end;
        if bi != bs.len() || ri != rs.len() {
            return Err(TbError::Protocol {
                variant: self.dut.name().into(),
                seed: self.seed,
                cycle: end,
                what: format!(
                    "{} B and {} R records fall outside the cycles run",
                    bs.len() - bi,
                    rs.len() - ri
                ),
            });
        }
        Ok(())
    }

    fn mismatch(
        &self,
        item: u64,
        cycle: u64,
        what: &str,
        input: String,
        rtl: String,
        model: String,
    ) -> TbError {
        Mismatch {
            variant: self.dut.name().into(),
            seed: self.seed,
            item,
            cycle,
            input,
            rtl,
            model,
            what: what.into(),
            ..Default::default()
        }
        .into()
    }

    fn mismatch_txn(
        &self,
        item: usize,
        cycle: u64,
        t: &AxilTxn,
        r: &AxilRecord,
        model: String,
    ) -> TbError {
        self.mismatch(
            self.item_base + item as u64,
            cycle,
            if t.read { "read" } else { "write" },
            format!("{t:?} (offset {})", self.offset(t.addr)),
            format!("{r:?}"),
            model,
        )
    }
}

/// The bench as the host driver's bus (`cube5_model::accel_host`): each access is one transaction
/// at full speed, checked against the model; an error response is an error.
impl RegBus for AxilBench {
    type Error = TbError;

    fn read(&mut self, addr: u64) -> Result<u32, TbError> {
        let r = self.transact(AxilTxn {
            read: true,
            addr: addr as u32,
            data: 0,
            strb: 0,
            delay: 0,
            w_delay: 0,
        })?;
        self.okay(addr, r).map(|r| r.data)
    }

    fn write(&mut self, addr: u64, data: u32) -> Result<(), TbError> {
        let r = self.transact(AxilTxn {
            read: false,
            addr: addr as u32,
            data,
            strb: 0xf,
            delay: 0,
            w_delay: 0,
        })?;
        self.okay(addr, r).map(|_| ())
    }
}

impl AxilBench {
    fn okay(&self, addr: u64, r: AxilRecord) -> Result<AxilRecord, TbError> {
        if r.resp == RESP_OKAY {
            Ok(r)
        } else {
            Err(TbError::setup(
                self.dut.name(),
                format!("{:?} of {addr:#x} answered {}", r.kind, r.resp),
            ))
        }
    }
}

/// How random transactions are drawn.
#[derive(Debug, Clone, Copy)]
pub struct TxnMix {
    /// Probability that a channel waits before a transaction, and the longest wait.
    pub p_delay: f64,
    pub max_delay: u32,
}

impl TxnMix {
    /// No waits: the throughput case.
    pub const FULL_SPEED: Self = Self {
        p_delay: 0.0,
        max_delay: 0,
    };
    /// Waits on a quarter of the transactions, up to 6 cycles.
    pub const RANDOM: Self = Self {
        p_delay: 0.25,
        max_delay: 6,
    };
}

/// A random transaction on `cfg`'s map: mostly registers, some holes, offsets past the map and
/// unaligned addresses; full and random byte strobes; random, all-ones and zero data.
pub fn random_txn(rng: &mut impl Rng, cfg: &AxilConfig, mix: TxnMix) -> AxilTxn {
    let map = cfg.map();
    let words = map.words();
    let span = 1u32 << cfg.addr_w.min(31);
    let offset = match rng.random_range(0..20) {
        0..=15 => map.registers[rng.random_range(0..map.registers.len())].offset,
        16 | 17 => rng.random_range(0..words),
        _ => rng.random_range(0..span / 4),
    };
    let low = if rng.random_bool(0.05) {
        rng.random_range(0..4)
    } else {
        0
    };
    let data = match rng.random_range(0..10) {
        0 | 1 => u32::MAX,
        2 => 0,
        _ => rng.random(),
    };
    let mut delay = || {
        if mix.max_delay > 0 && rng.random_bool(mix.p_delay) {
            rng.random_range(1..=mix.max_delay)
        } else {
            0
        }
    };
    let (d0, d1) = (delay(), delay());
    AxilTxn {
        read: rng.random_bool(0.5),
        addr: offset * 4 + low,
        data,
        strb: if rng.random_bool(0.7) {
            0xf
        } else {
            rng.random_range(0..16)
        },
        delay: d0,
        w_delay: d1,
    }
}

/// A back-pressure pattern for B and R: each cycle stalled with probability `p`.
pub fn stall_pattern(rng: &mut impl Rng, p: f64) -> Vec<u8> {
    if p <= 0.0 {
        return Vec::new();
    }
    (0..4111).map(|_| u8::from(rng.random_bool(p))).collect()
}
