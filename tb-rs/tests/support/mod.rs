//! Helpers shared by the co-simulation tests.
#![allow(dead_code)]

use cube5_model::unit::{StreamCodec, StreamUnit};
use cube5_tb::harness::{check_stream, seed_from_env, StreamCheck, StreamReport};
use cube5_tb::rtl::{Driven, RtlStream, Traffic};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::fmt::Debug;

/// Random items per configuration in the long co-simulation runs (the acceptance figure).
pub const MILLION: usize = 1_000_000;

pub use cube5_tb::rtl::ConfigWrites;

/// A codec the scoreboard can run: inputs it can replay and print, outputs it can compare.
pub trait Scored: StreamCodec<In: Clone + Debug, Out: Clone + Debug + PartialEq> + Clone {}

impl<C: StreamCodec<In: Clone + Debug, Out: Clone + Debug + PartialEq> + Clone> Scored for C {}

/// Runs a check and turns a mismatch into a test failure whose message is the full report.
pub fn must_match<C, G>(
    variant: &str,
    codec: C,
    gold: &mut G,
    gen: &mut dyn FnMut(&mut ChaCha8Rng) -> C::In,
    check: &StreamCheck,
) -> StreamReport
where
    C: Scored,
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
        Err(m) => panic!("{m}"),
    }
}

/// The seed of a test: `CUBE5_SEED` if set, else a fixed default per test.
pub fn seed(default: u64) -> u64 {
    seed_from_env(default)
}

/// `n` items from `gen`, seeded with `seed`.
pub fn random_items<T>(seed: u64, n: usize, mut gen: impl FnMut(&mut ChaCha8Rng) -> T) -> Vec<T> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| gen(&mut rng)).collect()
}

/// `must_match` on `items` in order, started over as often as `check.items` asks.
pub fn must_match_cycled<C, G>(
    variant: &str,
    codec: C,
    gold: &mut G,
    items: Vec<C::In>,
    check: &StreamCheck,
) -> StreamReport
where
    C: Scored,
    G: StreamUnit<In = C::In, Out = C::Out>,
{
    let mut it = items.into_iter().cycle();
    must_match(variant, codec, gold, &mut |_| it.next().unwrap(), check)
}

/// One pass over directed `items` under heavy idle and back-pressure: a short list still meets
/// the handshake's corner cases.
pub fn must_match_items<C, G>(
    variant: &str,
    codec: C,
    gold: &mut G,
    items: Vec<C::In>,
    seed: u64,
) -> StreamReport
where
    C: Scored,
    G: StreamUnit<In = C::In, Out = C::Out>,
{
    must_match_items_with_config(variant, codec, gold, items, seed, Vec::new())
}

/// `must_match_items` with `writes` loaded into the RTL first (the model holds the same tables).
pub fn must_match_items_with_config<C, G>(
    variant: &str,
    codec: C,
    gold: &mut G,
    items: Vec<C::In>,
    seed: u64,
    writes: ConfigWrites,
) -> StreamReport
where
    C: Scored,
    G: StreamUnit<In = C::In, Out = C::Out>,
{
    let check = StreamCheck::new(seed, items.len())
        .with_traffic(0.3, 0.3)
        .with_config_writes(writes);
    must_match_cycled(variant, codec, gold, items, &check)
}

/// Drives `items` at full speed and asserts the throughput contract: every item taken, the run
/// lasts exactly one clock per item plus `latency`, and the outputs leave back to back. Returns
/// the outputs for any comparison the caller adds.
pub fn assert_one_item_per_clock<C: StreamCodec>(
    variant: &str,
    codec: C,
    items: &[C::In],
    latency: u64,
) -> Driven<C::Out> {
    assert_one_item_per_clock_with_config(variant, codec, &[], items, latency)
}

/// `assert_one_item_per_clock` with `writes` loaded into the RTL first.
pub fn assert_one_item_per_clock_with_config<C: StreamCodec>(
    variant: &str,
    codec: C,
    writes: &[(u32, Vec<u32>)],
    items: &[C::In],
    latency: u64,
) -> Driven<C::Out> {
    let mut dut = RtlStream::new(variant, codec, 1).unwrap();
    for (addr, data) in writes {
        dut.write_config(*addr, data).unwrap();
    }
    let n = items.len() as u64;
    let driven = dut.drive(items, &Traffic::full_speed(), n, 10 * n).unwrap();
    assert_eq!(driven.stats.consumed, n, "{variant}: every item taken");
    assert_eq!(
        driven.stats.cycles,
        n + latency,
        "{variant}: one item per clock plus the pipeline fill"
    );
    let first = driven.outputs.first().unwrap().cycle;
    let last = driven.outputs.last().unwrap().cycle;
    assert_eq!(last - first + 1, n, "{variant}: outputs leave back to back");
    eprintln!(
        "{variant}: {n} items in {} cycles ({:.4} items/clock)",
        driven.stats.cycles,
        n as f64 / driven.stats.cycles as f64
    );
    driven
}

/// The gate-level netlist run: 30,000 random items under idle and back-pressure, in batches of
/// 10,000 (netlists simulate slowly), with a reset in the middle one.
pub fn gate_smoke<C, G>(
    variant: &str,
    codec: C,
    gold: &mut G,
    gen: &mut dyn FnMut(&mut ChaCha8Rng) -> C::In,
    seed: u64,
) -> StreamReport
where
    C: Scored,
    G: StreamUnit<In = C::In, Out = C::Out>,
{
    gate_smoke_with_config(variant, codec, gold, gen, seed, Vec::new())
}

/// `gate_smoke` with `writes` loaded into the netlist first.
pub fn gate_smoke_with_config<C, G>(
    variant: &str,
    codec: C,
    gold: &mut G,
    gen: &mut dyn FnMut(&mut ChaCha8Rng) -> C::In,
    seed: u64,
    writes: ConfigWrites,
) -> StreamReport
where
    C: Scored,
    G: StreamUnit<In = C::In, Out = C::Out>,
{
    let check = StreamCheck::new(seed, 30_000)
        .with_traffic(0.2, 0.2)
        .with_batch(10_000)
        .with_reset_in_batch(1)
        .with_config_writes(writes);
    must_match(variant, codec, gold, gen, &check)
}

/// A long random run: `items` items under idle and back-pressure, reset once in batch
/// `reset_in_batch`.
pub fn long_run(seed: u64, items: usize, reset_in_batch: usize) -> StreamCheck {
    StreamCheck::new(seed, items)
        .with_traffic(0.2, 0.3)
        .with_reset_in_batch(reset_in_batch)
}

/// `must_match` on a check with one reset: asserts the reset happened and dropped no more than
/// `in_flight` items (those the pipeline held at the time).
pub fn must_match_across_a_reset<C, G>(
    variant: &str,
    codec: C,
    gold: &mut G,
    gen: &mut dyn FnMut(&mut ChaCha8Rng) -> C::In,
    check: &StreamCheck,
    in_flight: usize,
) -> StreamReport
where
    C: Scored,
    G: StreamUnit<In = C::In, Out = C::Out>,
{
    let r = must_match(variant, codec, gold, gen, check);
    assert_eq!(r.resets, 1, "{variant}: one reset");
    assert!(
        r.compared as usize >= check.items - in_flight,
        "{variant}: a reset drops at most the items in flight"
    );
    r
}
