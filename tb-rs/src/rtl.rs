//! A Verilated streaming top behind the same `StreamUnit` trait as the golden model.

use crate::error::TbError;
pub use crate::ffi::bridge::AxiWrCounters;
use crate::ffi::bridge::{self, RunResult, StreamDut};
pub use crate::ffi::bridge::{AxiCounters, AxiMemSetup, WinSetup};
use crate::variants::{Variant, VARIANTS};
use cube5_model::bits::words_for;
use cube5_model::unit::UnitConfig;
use cube5_model::unit::{StreamCodec, StreamUnit};
use cxx::UniquePtr;
use std::path::Path;

/// Configuration-port writes: (address, data words), applied in order.
pub type ConfigWrites = Vec<(u32, Vec<u32>)>;

/// Per-cycle input idling and output back-pressure, as repeating patterns (nonzero = idle/stall).
#[derive(Debug, Clone, Default)]
pub struct Traffic {
    pub idle: Vec<u8>,
    pub stall: Vec<u8>,
}

impl Traffic {
    /// Input always offered, output always taken: the throughput case.
    pub fn full_speed() -> Self {
        Self::default()
    }

    /// Random idle with probability `idle` and back-pressure with probability `stall`, over
    /// patterns of 4099 and 4111 cycles (coprime, so the two never fall into lock-step).
    pub fn random(rng: &mut impl rand::Rng, idle: f64, stall: f64) -> Self {
        let pattern = |rng: &mut dyn rand::RngCore, p: f64, n: usize| -> Vec<u8> {
            (0..n)
                .map(|_| u8::from(rand::Rng::random_bool(rng, p)))
                .collect()
        };
        Self {
            idle: pattern(rng, idle, 4099),
            stall: pattern(rng, stall, 4111),
        }
    }
}

/// One AR handshake as the AXI memory subordinate accepted it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ArHandshake {
    pub cycle: u64,
    pub addr: u64,
    /// ARLEN: beats - 1.
    pub len: u32,
    pub size: u32,
    pub burst: u32,
    pub id: u32,
}

/// Address-channel handshakes as the bridge packs them: (cycle, addr, len | size << 8 |
/// burst << 12 | id << 16) each.
fn handshakes(raw: &[u64]) -> Vec<ArHandshake> {
    raw.chunks_exact(3)
        .map(|r| ArHandshake {
            cycle: r[0],
            addr: r[1],
            len: (r[2] & 0xff) as u32,
            size: ((r[2] >> 8) & 0x7) as u32,
            burst: ((r[2] >> 12) & 0x3) as u32,
            id: (r[2] >> 16) as u32,
        })
        .collect()
}

/// One output as it left the RTL: the cycle it was taken and its value.
#[derive(Debug, Clone)]
pub struct Taken<T> {
    pub cycle: u64,
    pub value: T,
    pub words: Vec<u32>,
}

/// Result of driving a batch.
#[derive(Debug, Clone)]
pub struct Driven<T> {
    pub outputs: Vec<Taken<T>>,
    pub stats: RunResult,
}

pub struct RtlStream<C: StreamCodec> {
    dut: UniquePtr<StreamDut>,
    codec: C,
    variant: &'static Variant,
}

/// The variants built into this test bench.
pub fn built_variants() -> Vec<&'static Variant> {
    let names = bridge::built_variants();
    VARIANTS
        .iter()
        .filter(|v| names.iter().any(|n| n == v.name))
        .collect()
}

impl<C: StreamCodec + UnitConfig> RtlStream<C> {
    /// Opens `variant` with the model's configuration built from its parameters.
    pub fn open(variant: &'static Variant, seed: u32) -> Result<Self, TbError> {
        let codec = variant
            .config::<C>()
            .map_err(|e| TbError::setup(variant.name, e))?;
        Self::new(variant, codec, seed)
    }
}

impl<C: StreamCodec> RtlStream<C> {
    /// Instantiates `variant` with Verilator's random-reset seed `seed`, resets it, and checks
    /// its port widths against `codec`.
    pub fn new(variant: &'static Variant, codec: C, seed: u32) -> Result<Self, TbError> {
        let dut = bridge::new_stream_dut(variant.name, seed);
        if dut.is_null() {
            let built: Vec<&str> = built_variants().iter().map(|v| v.name).collect();
            return Err(TbError::setup(
                variant.name,
                format!(
                    "not built into this test bench (built: {}); check rtl/**/*.variants and CUBE5_TOPS",
                    built.join(", ")
                ),
            ));
        }
        let mut s = Self {
            dut,
            codec,
            variant,
        };
        for (port, rtl, model) in [
            ("in_data_i", s.dut.in_bits(), s.codec.in_width()),
            ("out_data_o", s.dut.out_bits(), s.codec.out_width()),
        ] {
            if rtl != model {
                return Err(TbError::setup(
                    variant.name,
                    format!(
                        "{port} is {rtl} bits in the RTL but {model} bits in the model's codec"
                    ),
                ));
            }
        }
        s.reset();
        Ok(s)
    }

    pub fn name(&self) -> &'static str {
        self.variant.name
    }

    pub fn variant(&self) -> &'static Variant {
        self.variant
    }

    pub fn codec(&self) -> &C {
        &self.codec
    }

    /// Four cycles of reset with idle inputs.
    pub fn reset(&mut self) {
        self.dut.pin_mut().reset(4);
    }

    pub fn cycle(&self) -> u64 {
        self.dut.cycle()
    }

    /// One write on the configuration port (LUT and register loads; see the unit's contract).
    pub fn write_config(&mut self, addr: u32, data: &[u32]) -> Result<(), TbError> {
        if self.dut.pin_mut().write_config(addr, data) {
            Ok(())
        } else {
            Err(TbError::setup(
                self.variant.name,
                "this top has no configuration port (cfg_valid_i, cfg_addr_i, cfg_data_i)",
            ))
        }
    }

    /// Sets up the AXI memory subordinate of a top with an AXI port (tb/axi_mem.h).
    pub fn axi_setup(&mut self, setup: &AxiMemSetup) -> Result<(), TbError> {
        let present = self.dut.pin_mut().axi_setup(setup);
        self.axi_present(present)
    }

    /// Loads the subordinate's memory image: `bytes` from byte address `base` (replaces the last).
    pub fn axi_load(&mut self, base: u64, bytes: &[u8]) -> Result<(), TbError> {
        let present = self.dut.pin_mut().axi_load(base, bytes);
        self.axi_present(present)
    }

    /// The AR handshakes the subordinate accepted since the last call, in order.
    pub fn axi_take_ar(&mut self) -> Result<Vec<ArHandshake>, TbError> {
        let mut raw = Vec::new();
        let present = self.dut.pin_mut().axi_take_ar(&mut raw);
        self.axi_present(present).map(|()| handshakes(&raw))
    }

    /// The subordinate's counters and the top's `err_o`.
    pub fn axi_counters(&self) -> AxiCounters {
        self.dut.axi_counters()
    }

    /// The subordinate's first protocol violation (empty if none).
    pub fn axi_first_error(&self) -> String {
        self.dut.axi_first_error()
    }

    /// Queues `items` (packed, `words` words each) for the data stream of a top with an AXI write
    /// port, offered except where `idle` (a repeating pattern) is nonzero; replaces the last.
    pub fn axi_feed(&mut self, items: &[u32], words: u32, idle: &[u8]) -> Result<(), TbError> {
        let present = self.dut.pin_mut().axi_feed(items, words, idle);
        self.axi_present(present)
    }

    /// The AW handshakes the subordinate accepted since the last call, in order.
    pub fn axi_take_aw(&mut self) -> Result<Vec<ArHandshake>, TbError> {
        let mut raw = Vec::new();
        let present = self.dut.pin_mut().axi_take_aw(&mut raw);
        self.axi_present(present).map(|()| handshakes(&raw))
    }

    /// The subordinate's memory image as it is now (the bytes from the loaded base).
    pub fn axi_image(&self) -> Result<Vec<u8>, TbError> {
        let mut out = Vec::new();
        let present = self.dut.axi_image(&mut out);
        self.axi_present(present).map(|()| out)
    }

    /// The subordinate's write-port counters.
    pub fn axi_wr_counters(&self) -> AxiWrCounters {
        self.dut.axi_wr_counters()
    }

    /// Sets up the DRAM that a `cube5_frame` with `Window = 1` parks in (tb/win_shim.h).
    pub fn win_setup(&mut self, setup: &WinSetup) -> Result<(), TbError> {
        if self.dut.pin_mut().win_setup(setup) {
            Ok(())
        } else {
            Err(TbError::setup(
                self.variant.name,
                "this build has no window streams",
            ))
        }
    }

    /// The window streams' records since the last call (tb/win_host.h), and words per record.
    pub fn win_take(&mut self) -> (Vec<u32>, usize) {
        let mut raw = Vec::new();
        let words = self.dut.pin_mut().win_take(&mut raw);
        (raw, words as usize)
    }

    /// Restore requests for pixels never parked, and stalled window outputs that changed.
    pub fn win_errors(&self) -> u64 {
        self.dut.win_errors()
    }

    /// `Ok` where the top has the AXI4 manager port the call went to, else the set-up error.
    fn axi_present(&self, present: bool) -> Result<(), TbError> {
        if present {
            Ok(())
        } else {
            Err(TbError::setup(
                self.variant.name,
                "this top has no AXI4 manager port (m_axi_ar*, m_axi_r*)",
            ))
        }
    }

    /// Records cycles `[from, to]` into a VCD file.
    pub fn trace_window(&mut self, path: &Path, from: u64, to: u64) -> bool {
        self.dut
            .pin_mut()
            .trace_window(&path.to_string_lossy(), from, to)
    }

    /// Drives `items` under `traffic` until all are consumed and `expect_out` outputs were taken,
    /// or `max_cycles` pass.
    pub fn drive(
        &mut self,
        items: &[C::In],
        traffic: &Traffic,
        expect_out: u64,
        max_cycles: u64,
    ) -> Result<Driven<C::Out>, TbError> {
        let flat = self.pack(items);
        self.drive_packed(&flat, traffic, expect_out, max_cycles)
    }

    /// Items packed as the RTL's `in_data_i` words, back to back.
    pub fn pack(&self, items: &[C::In]) -> Vec<u32> {
        let mut flat = Vec::with_capacity(items.len() * words_for(self.codec.in_width()));
        for it in items {
            flat.extend(self.codec.pack_in(it));
        }
        flat
    }

    /// `drive` for items already packed by `pack` (benchmarks time the simulation alone).
    pub fn drive_packed(
        &mut self,
        flat: &[u32],
        traffic: &Traffic,
        expect_out: u64,
        max_cycles: u64,
    ) -> Result<Driven<C::Out>, TbError> {
        let in_words = words_for(self.codec.in_width());
        let out_words = words_for(self.codec.out_width());
        let mut raw = Vec::new();
        let stats = self.dut.pin_mut().run(
            flat,
            in_words as u32,
            &traffic.idle,
            &traffic.stall,
            expect_out,
            max_cycles,
            &mut raw,
            out_words as u32,
        );
        if stats.finished {
            return Err(TbError::Protocol {
                variant: self.variant.name.to_string(),
                seed: 0,
                cycle: self.dut.cycle(),
                what: "the RTL stopped the simulation ($finish or a failed assertion)".into(),
            });
        }
        let outputs = raw
            .chunks_exact(2 + out_words)
            .map(|rec| Taken {
                cycle: u64::from(rec[0]) | u64::from(rec[1]) << 32,
                value: self.codec.unpack_out(&rec[2..]),
                words: rec[2..].to_vec(),
            })
            .collect();
        Ok(Driven { outputs, stats })
    }
}

impl<C: StreamCodec> StreamUnit for RtlStream<C>
where
    C::In: Clone + std::fmt::Debug,
    C::Out: Clone + std::fmt::Debug + PartialEq,
{
    type In = C::In;
    type Out = C::Out;

    /// Full speed, no stalls; panics only if the RTL deadlocks (a bug in the RTL, not user input).
    fn run(&mut self, inputs: &[C::In]) -> Vec<C::Out> {
        let n = inputs.len() as u64;
        let driven = self
            .drive(inputs, &Traffic::full_speed(), n, 1000 + 100 * n)
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            driven.stats.produced, n,
            "{}: RTL did not produce every output",
            self.variant.name
        );
        driven.outputs.into_iter().map(|t| t.value).collect()
    }

    fn reset(&mut self) {
        RtlStream::reset(self);
    }
}
