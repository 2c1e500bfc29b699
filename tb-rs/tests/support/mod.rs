//! Helpers shared by the co-simulation tests.
#![allow(dead_code)]

use cube5_model::unit::{StreamCodec, StreamUnit};
use cube5_tb::harness::{check_stream, seed_from_env, StreamCheck, StreamReport};
use rand_chacha::ChaCha8Rng;
use std::fmt::Debug;

/// Random items per configuration in the long co-simulation runs (the acceptance figure).
pub const MILLION: usize = 1_000_000;

/// Runs a check and turns a mismatch into a test failure whose message is the full report.
pub fn must_match<C, G>(
    variant: &str,
    codec: C,
    gold: &mut G,
    gen: &mut dyn FnMut(&mut ChaCha8Rng) -> C::In,
    check: &StreamCheck,
) -> StreamReport
where
    C: StreamCodec + Clone,
    C::In: Clone + Debug,
    C::Out: Clone + Debug + PartialEq,
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
