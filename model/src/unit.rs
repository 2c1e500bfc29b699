//! The interface every streaming unit stands behind, model and RTL alike, so one test drives
//! either and a scoreboard compares them in order.

use std::fmt::Debug;

/// A streaming unit: items in, items out, one output per input, in order.
///
/// The golden model implements it directly; the test bench wraps a Verilator model in it. Timing
/// (latency, stalls) is not part of this view: only the sequence of values is.
pub trait StreamUnit {
    type In: Clone + Debug;
    type Out: Clone + Debug + PartialEq;

    /// Processes `inputs` in order and returns one output per input.
    fn run(&mut self, inputs: &[Self::In]) -> Vec<Self::Out>;

    /// Returns the unit to its state after reset (a no-op for stateless units).
    fn reset(&mut self) {}
}

/// How a unit's items become the flat bit vectors on the RTL ports (`docs/numerics.md`).
pub trait StreamCodec {
    type In;
    type Out;

    fn in_width(&self) -> u32;
    fn out_width(&self) -> u32;
    fn pack_in(&self, item: &Self::In) -> Vec<u32>;
    fn unpack_out(&self, words: &[u32]) -> Self::Out;
}
