//! The co-simulation scoreboard: seeded stimulus into an RTL variant and the golden model, outputs
//! compared in order with no tolerance, under random idle, back-pressure and a mid-stream reset.

use crate::error::{Mismatch, TbError};
use crate::rtl::{Driven, RtlStream, Traffic};
use crate::variants::Variant;
use cube5_model::unit::{StreamCodec, StreamUnit};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt;
use std::path::PathBuf;

/// The seed for a test: `CUBE5_SEED` from the environment if set, else `default`.
pub fn seed_from_env(default: u64) -> u64 {
    std::env::var("CUBE5_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// How one co-simulation run is shaped.
#[derive(Debug, Clone)]
pub struct StreamCheck {
    pub seed: u64,
    /// Items generated in all.
    pub items: usize,
    /// Items per FFI batch (bounds memory; the clock keeps running between batches).
    pub batch: usize,
    /// Probability that the input is idle in a cycle.
    pub idle: f64,
    /// Probability that the output is stalled in a cycle.
    pub stall: f64,
    /// Reset the RTL (and the model) in the middle of this batch.
    pub reset_in_batch: Option<usize>,
    /// Flip this bit of the RTL's output for this item before comparing: proves the scoreboard
    /// bites (only the self-test of the harness sets it).
    pub corrupt: Option<(u64, u32)>,
    /// Write a VCD of the window around the first mismatch (re-runs the case with tracing on).
    pub waveform_on_mismatch: bool,
    /// Configuration-port writes (address, data words) applied after construction, before any
    /// item: LUT contents that the test loaded into the model as well. They survive resets.
    pub config_writes: Vec<(u32, Vec<u32>)>,
}

impl StreamCheck {
    pub fn new(seed: u64, items: usize) -> Self {
        Self {
            seed,
            items,
            batch: 1 << 16,
            idle: 0.0,
            stall: 0.0,
            reset_in_batch: None,
            corrupt: None,
            waveform_on_mismatch: std::env::var_os("CUBE5_NO_WAVES").is_none(),
            config_writes: Vec::new(),
        }
    }

    /// A directed list under heavy idle and back-pressure (a short list still meets the
    /// handshake's corner cases). `items` is 0: `support::must_match_items` runs the list once.
    pub fn directed(seed: u64) -> Self {
        Self::new(seed, 0).with_traffic(0.3, 0.3)
    }

    /// A long random run under idle and back-pressure, reset once in batch `reset_in_batch`.
    pub fn long(seed: u64, items: usize, reset_in_batch: usize) -> Self {
        Self::new(seed, items)
            .with_traffic(0.2, 0.3)
            .with_reset_in_batch(reset_in_batch)
    }

    /// The gate-level netlist run: 30,000 random items under idle and back-pressure, in batches
    /// of 10,000 (netlists simulate slowly), with a reset in the middle one.
    pub fn gate_smoke(seed: u64) -> Self {
        Self::new(seed, 30_000)
            .with_traffic(0.2, 0.2)
            .with_batch(10_000)
            .with_reset_in_batch(1)
    }

    pub fn with_config_writes(mut self, writes: Vec<(u32, Vec<u32>)>) -> Self {
        self.config_writes = writes;
        self
    }

    pub fn with_traffic(mut self, idle: f64, stall: f64) -> Self {
        self.idle = idle;
        self.stall = stall;
        self
    }

    pub fn with_reset_in_batch(mut self, batch: usize) -> Self {
        self.reset_in_batch = Some(batch);
        self
    }

    pub fn with_batch(mut self, batch: usize) -> Self {
        self.batch = batch.max(1);
        self
    }
}

/// What a passing run did.
#[derive(Debug, Clone, Default)]
pub struct StreamReport {
    pub variant: String,
    pub seed: u64,
    /// Items accepted by the RTL.
    pub consumed: u64,
    /// Outputs compared (fewer than consumed when a reset dropped items in flight).
    pub compared: u64,
    pub cycles: u64,
    pub resets: u64,
}

impl StreamReport {
    /// Adds a driven batch's items, outputs and clocks.
    fn count<T>(&mut self, driven: &Driven<T>) {
        self.consumed += driven.stats.consumed;
        self.compared += driven.stats.produced;
        self.cycles += driven.stats.cycles;
    }

    /// Items accepted per clock.
    pub fn items_per_cycle(&self) -> f64 {
        self.consumed as f64 / self.cycles.max(1) as f64
    }
}

/// At how many places of two lists (pixels, coxels, memory words) the RTL's item differs from the
/// model's; places beyond the shorter list are not counted.
pub fn count_differing<T: PartialEq>(got: &[T], want: &[T]) -> usize {
    got.iter().zip(want).filter(|(a, b)| a != b).count()
}

/// Runs a check and turns any failure into a panic whose message is the full report (the
/// tests' one entry point); prints what the run did when it passes.
pub fn must_match<C, G>(
    variant: &'static Variant,
    codec: C,
    gold: &mut G,
    gen: &mut dyn FnMut(&mut ChaCha8Rng) -> C::In,
    check: &StreamCheck,
) -> StreamReport
where
    C: StreamCodec + Clone,
    C::In: Clone + fmt::Debug,
    C::Out: Clone + fmt::Debug + PartialEq,
    G: StreamUnit<In = C::In, Out = C::Out>,
{
    match check_stream(variant, codec, gold, gen, check) {
        Ok(r) => {
            eprintln!(
                "{variant}: seed {} consumed {} compared {} in {} cycles ({:.4} items/clock), {} reset(s)",
                r.seed,
                r.consumed,
                r.compared,
                r.cycles,
                r.items_per_cycle(),
                r.resets
            );
            r
        }
        Err(e) => panic!("{e}"),
    }
}

/// Runs `check` on RTL variant `variant` against `gold`, drawing inputs from `gen`.
///
/// Deterministic in `check.seed`: the stimulus, the traffic, Verilator's random reset values and
/// the reset point all derive from it, so a mismatch re-runs identically with a waveform.
pub fn check_stream<C, G>(
    variant: &'static Variant,
    codec: C,
    gold: &mut G,
    gen: &mut dyn FnMut(&mut ChaCha8Rng) -> C::In,
    check: &StreamCheck,
) -> Result<StreamReport, TbError>
where
    C: StreamCodec + Clone,
    C::In: Clone + fmt::Debug,
    C::Out: Clone + fmt::Debug + PartialEq,
    G: StreamUnit<In = C::In, Out = C::Out>,
{
    match run_check(variant, codec.clone(), gold, gen, check, None) {
        Ok(r) => Ok(r),
        Err(TbError::Mismatch(mut m)) => {
            if check.waveform_on_mismatch {
                let dir = PathBuf::from(
                    std::env::var("CARGO_TARGET_DIR").unwrap_or_else(|_| "target".into()),
                )
                .join("cube5-waves");
                let _ = std::fs::create_dir_all(&dir);
                let path = dir.join(format!("{variant}-seed{}.vcd", check.seed));
                let window = (m.cycle.saturating_sub(64), m.cycle + 8);
                gold.reset();
                let _ = run_check(
                    variant,
                    codec,
                    gold,
                    gen,
                    check,
                    Some((path.clone(), window)),
                );
                m.waveform = path.exists().then_some(path);
            }
            Err(TbError::Mismatch(m))
        }
        Err(e) => Err(e),
    }
}

fn run_check<C, G>(
    variant: &'static Variant,
    codec: C,
    gold: &mut G,
    gen: &mut dyn FnMut(&mut ChaCha8Rng) -> C::In,
    check: &StreamCheck,
    trace: Option<(PathBuf, (u64, u64))>,
) -> Result<StreamReport, TbError>
where
    C: StreamCodec,
    C::In: Clone + fmt::Debug,
    C::Out: Clone + fmt::Debug + PartialEq,
    G: StreamUnit<In = C::In, Out = C::Out>,
{
    let mut rng = ChaCha8Rng::seed_from_u64(check.seed);
    let traffic = Traffic::random(&mut rng, check.idle, check.stall);
    let verilator_seed = rng.random::<u32>();
    let fail = |item: u64, cycle: u64, what: String| Mismatch {
        variant: variant.name.to_string(),
        seed: check.seed,
        item,
        cycle,
        what,
        ..Default::default()
    };
    // A run error carries the seed of this check.
    let compare_batch =
        |codec: &C, driven: &Driven<C::Out>, want: &[C::Out], items: &[C::In], base: u64| {
            compare(codec, &driven.outputs, want, items, base, check, &fail)
        };
    let seeded = |e: TbError| match e {
        TbError::Protocol {
            variant,
            cycle,
            what,
            ..
        } => TbError::Protocol {
            variant,
            seed: check.seed,
            cycle,
            what,
        },
        other => other,
    };
    let mut dut = RtlStream::new(variant, codec, verilator_seed)?;
    for (addr, data) in &check.config_writes {
        dut.write_config(*addr, data)?;
    }
    if let Some((path, (from, to))) = &trace {
        dut.trace_window(path, *from, *to);
    }
    gold.reset();

    let mut report = StreamReport {
        variant: variant.name.to_string(),
        seed: check.seed,
        ..Default::default()
    };
    let mut item_base = 0u64; // global index of pending[0]
    let mut batch_no = 0usize;
    let mut generated = 0usize;
    while generated < check.items {
        let n = check.batch.min(check.items - generated);
        let mut pending: Vec<C::In> = (0..n).map(|_| gen(&mut rng)).collect();
        generated += n;

        // A reset lands after a random number of cycles into this batch.
        if check.reset_in_batch == Some(batch_no) {
            let cut = rng.random_range(1..=(n as u64).max(2));
            let driven = dut
                .drive(&pending, &traffic, u64::MAX, cut)
                .map_err(seeded)?;
            let consumed = driven.stats.consumed as usize;
            let expected = gold.run(&pending[..consumed]);
            compare_batch(dut.codec(), &driven, &expected, &pending, item_base)?;
            report.count(&driven);
            // Items accepted but not yet out are lost with the reset, in RTL and model alike.
            dut.reset();
            gold.reset();
            report.resets += 1;
            item_base += consumed as u64;
            pending.drain(..consumed);
        }

        let expected = gold.run(&pending);
        let want = pending.len() as u64;
        let driven = dut
            .drive(&pending, &traffic, want, 64 * want + 10_000)
            .map_err(seeded)?;
        if driven.stats.protocol_errors > 0 {
            return Err(TbError::Protocol {
                variant: variant.name.to_string(),
                seed: check.seed,
                cycle: driven.stats.first_protocol_error_cycle,
                what: format!(
                    "valid/ready violated {} times: a stalled output dropped valid or changed",
                    driven.stats.protocol_errors
                ),
            });
        }
        compare_batch(dut.codec(), &driven, &expected, &pending, item_base)?;
        if driven.stats.produced != want {
            return Err(TbError::Deadlock {
                variant: variant.name.to_string(),
                seed: check.seed,
                cycle: dut.cycle(),
                what: format!(
                    "RTL produced {} of {} outputs of the batch from item #{item_base} within the cycle limit (deadlock or lost item)",
                    driven.stats.produced, want
                ),
            });
        }
        report.count(&driven);
        item_base += want;
        batch_no += 1;
    }
    Ok(report)
}

#[allow(clippy::too_many_arguments)]
fn compare<C: StreamCodec>(
    codec: &C,
    got: &[crate::rtl::Taken<C::Out>],
    expected: &[C::Out],
    inputs: &[C::In],
    item_base: u64,
    check: &StreamCheck,
    fail: &dyn Fn(u64, u64, String) -> Mismatch,
) -> Result<(), TbError>
where
    C::In: fmt::Debug,
    C::Out: Clone + fmt::Debug + PartialEq,
{
    for (k, taken) in got.iter().enumerate() {
        let item = item_base + k as u64;
        let mut words = taken.words.clone();
        let mut value = taken.value.clone();
        if let Some((at, bit)) = check.corrupt {
            if at == item {
                words[(bit / 32) as usize] ^= 1 << (bit % 32);
                value = codec.unpack_out(&words);
            }
        }
        if expected.get(k) != Some(&value) {
            return Err(TbError::from(Mismatch {
                input: format!("{:?}", inputs.get(k)),
                rtl: format!("{value:?}"),
                model: expected
                    .get(k)
                    .map_or_else(|| "(no output expected)".into(), |e| format!("{e:?}")),
                rtl_words: words,
                ..fail(item, taken.cycle, "output differs".into())
            }));
        }
    }
    Ok(())
}
