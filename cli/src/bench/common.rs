//! What every benchmark shares: opening a variant's DUT, the speed table (simulated RTL cycles per
//! second, items per clock, model items per second) and error statistics.

use anyhow::{ensure, Result};
use cube5_model::unit::{StreamCodec, StreamUnit, UnitConfig};
use cube5_tb::rtl::{RtlStream, Traffic};
use cube5_tb::{variants_of, Variant};
use std::time::Instant;

/// Verilator's random-reset seed of every benchmarked DUT.
const DUT_SEED: u32 = 1;

/// Opens `variant` with the model's configuration `codec` and applies `writes` (tables and
/// registers) on its configuration port.
pub fn open<C: StreamCodec>(
    variant: &'static Variant,
    codec: C,
    writes: &[(u32, Vec<u32>)],
) -> Result<RtlStream<C>> {
    let mut dut = RtlStream::new(variant, codec, DUT_SEED)?;
    for (addr, data) in writes {
        dut.write_config(*addr, data)?;
    }
    Ok(dut)
}

/// The speed table's header; [`speed_row`] prints its rows.
pub fn speed_header() {
    println!(
        "| unit | config | RTL cycles | items/clock | sim cycles/s | model items/s | model/sim speed |"
    );
    println!(
        "|------|--------|-----------:|------------:|-------------:|--------------:|----------------:|"
    );
}

/// Whether [`speed_row`] holds the RTL's outputs to the model's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compare {
    /// Timing only.
    No,
    /// Every item must come out of the RTL and equal the model's output (outside the timing).
    Outputs,
}

/// Times `dut` on `items` at full speed (no idle, no back-pressure; packing outside the timing)
/// and `model` on the same items; prints one row of the speed table.
pub fn speed_row<C, M>(
    dut: &mut RtlStream<C>,
    model: &mut M,
    items: &[C::In],
    compare: Compare,
) -> Result<()>
where
    C: StreamCodec,
    C::In: Clone + std::fmt::Debug,
    C::Out: Clone + std::fmt::Debug + PartialEq,
    M: StreamUnit<In = C::In, Out = C::Out>,
{
    let n = items.len() as u64;
    let packed = dut.pack(items);
    let t = Instant::now();
    let driven = dut.drive_packed(&packed, &Traffic::full_speed(), n, 2 * n + 1000)?;
    let sim_secs = t.elapsed().as_secs_f64();
    let cycles = driven.stats.cycles;

    let t = Instant::now();
    let out = model.run(items);
    let model_secs = t.elapsed().as_secs_f64();
    if compare == Compare::Outputs {
        let variant = dut.variant();
        ensure!(
            driven.stats.produced == n,
            "{variant}: the RTL produced {} of {n} outputs",
            driven.stats.produced
        );
        let differ = driven
            .outputs
            .iter()
            .zip(&out)
            .filter(|(r, m)| r.value != **m)
            .count();
        ensure!(
            differ == 0,
            "{variant}: RTL and model disagree on {differ} of {n} items"
        );
    }
    std::hint::black_box(out);

    let sim_rate = cycles as f64 / sim_secs;
    let model_rate = n as f64 / model_secs;
    let v = dut.variant();
    println!(
        "| {} | {} | {cycles} | {:.4} | {:.2e} | {:.2e} | {:.1}x |",
        v.top,
        v.config,
        n as f64 / cycles as f64,
        sim_rate,
        model_rate,
        model_rate / sim_rate
    );
    Ok(())
}

/// What one variant's speed row runs: the model, its items and the configuration writes (tables,
/// registers) that give the RTL the model's state.
pub type Workload<C, M> = (M, Vec<<C as StreamCodec>::In>, Vec<(u32, Vec<u32>)>);

/// The whole speed table of `C`'s top: the header, one [`speed_row`] per variant on the workload
/// `workload` builds for its configuration, and a blank line.
pub fn speed_table<C, M>(
    workload: impl Fn(C) -> Result<Workload<C, M>>,
    compare: Compare,
) -> Result<()>
where
    C: StreamCodec + UnitConfig + Copy,
    C::In: Clone + std::fmt::Debug,
    C::Out: Clone + std::fmt::Debug + PartialEq,
    M: StreamUnit<In = C::In, Out = C::Out>,
{
    speed_header();
    for v in variants_of(C::TOP) {
        let cfg: C = v.config()?;
        let (mut model, items, writes) = workload(cfg)?;
        let mut dut = open(v, cfg, &writes)?;
        speed_row(&mut dut, &mut model, &items, compare)?;
    }
    println!();
    Ok(())
}

/// The header of an exactness table: values compared with a reference that the unit must equal;
/// [`exactness_row`] prints its rows.
pub fn exactness_header() {
    println!(
        "| unit | config | values compared | mismatches | max abs error (LSB) | RMS error (LSB) |"
    );
    println!(
        "|------|--------|----------------:|-----------:|--------------------:|----------------:|"
    );
}

/// One row of an exactness table: `err` holds the differences from the reference.
pub fn exactness_row(variant: &Variant, err: &ErrorStats) {
    println!(
        "| {} | {} | {} | {} | {:.0} | {:.3} |",
        variant.top,
        variant.config,
        err.n,
        err.nonzero,
        err.max_abs,
        err.rms()
    );
}

/// Error statistics over a sequence of signed errors: count, errors that are not zero, largest
/// magnitude, smallest and largest value, RMS and mean.
#[derive(Debug, Clone, Copy)]
pub struct ErrorStats {
    pub n: u64,
    pub nonzero: u64,
    pub max_abs: f64,
    pub min: f64,
    pub max: f64,
    sq: f64,
    sum: f64,
}

impl Default for ErrorStats {
    fn default() -> Self {
        Self {
            n: 0,
            nonzero: 0,
            max_abs: 0.0,
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            sq: 0.0,
            sum: 0.0,
        }
    }
}

impl ErrorStats {
    pub fn add(&mut self, e: f64) {
        self.n += 1;
        self.nonzero += u64::from(e != 0.0);
        self.max_abs = self.max_abs.max(e.abs());
        self.min = self.min.min(e);
        self.max = self.max.max(e);
        self.sq += e * e;
        self.sum += e;
    }

    /// Root mean square (0 over no errors).
    pub fn rms(&self) -> f64 {
        (self.sq / self.n.max(1) as f64).sqrt()
    }

    /// Mean (0 over no errors).
    pub fn mean(&self) -> f64 {
        self.sum / self.n.max(1) as f64
    }
}

impl Extend<f64> for ErrorStats {
    fn extend<I: IntoIterator<Item = f64>>(&mut self, errs: I) {
        for e in errs {
            self.add(e);
        }
    }
}

impl FromIterator<f64> for ErrorStats {
    fn from_iter<I: IntoIterator<Item = f64>>(errs: I) -> Self {
        let mut s = Self::default();
        s.extend(errs);
        s
    }
}
