//! The cxx bridge to the Verilated tops. Kept small and alone: cxx-build reruns when it changes.

#[cxx::bridge(namespace = "cube5")]
pub mod bridge {
    /// What one `run` call did (mirrors `RunStats` in tb/dut_core.h).
    #[derive(Debug, Clone, Copy, Default)]
    struct RunResult {
        consumed: u64,
        produced: u64,
        cycles: u64,
        protocol_errors: u64,
        first_protocol_error_cycle: u64,
        finished: bool,
    }

    unsafe extern "C++" {
        include!("stream_dut.h");

        type StreamDut;

        fn new_stream_dut(name: &str, seed: u32) -> UniquePtr<StreamDut>;
        fn built_variants() -> Vec<String>;

        fn reset(self: Pin<&mut StreamDut>, cycles: u32);
        #[allow(clippy::too_many_arguments)]
        fn run(
            self: Pin<&mut StreamDut>,
            items: &[u32],
            in_words: u32,
            idle: &[u8],
            stall: &[u8],
            expect_out: u64,
            max_cycles: u64,
            out: &mut Vec<u32>,
            out_words: u32,
        ) -> RunResult;
        fn write_config(self: Pin<&mut StreamDut>, addr: u32, data: &[u32]) -> bool;
        fn trace_window(
            self: Pin<&mut StreamDut>,
            path: &str,
            from_cycle: u64,
            to_cycle: u64,
        ) -> bool;
        fn cycle(self: &StreamDut) -> u64;
        fn in_bits(self: &StreamDut) -> u32;
        fn out_bits(self: &StreamDut) -> u32;
    }
}
