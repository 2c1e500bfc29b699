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

    /// The AXI memory subordinate's set-up (mirrors `AxiMemConfig` in tb/axi_mem.h).
    #[derive(Debug, Clone, Copy, Default)]
    struct AxiMemSetup {
        data_bytes: u32,
        addr_bits: u32,
        latency_fixed: u32,
        latency_random: u32,
        ar_gap_permille: u32,
        r_gap_permille: u32,
        bw_num: u32,
        bw_den: u32,
        max_bursts: u32,
        seed: u64,
        slverr_lo: u64,
        slverr_hi: u64,
        /// Write port (AW, W, B): channel gaps in per mille; the manager's declared limit of
        /// bursts in flight per direction, checked on AR and AW (0: not checked).
        aw_gap_permille: u32,
        w_gap_permille: u32,
        b_gap_permille: u32,
        declared_outstanding: u32,
    }

    /// The subordinate's write-port counters (mirrors `AxiStats` in tb/axi_mem.h).
    #[derive(Debug, Clone, Copy, Default)]
    struct AxiWrCounters {
        aw_accepted: u64,
        w_beats: u64,
        w_bytes: u64,
        b_responses: u64,
        dropped_at_reset: u64,
        bready_low: u64,
        in_flight: u64,
    }

    /// The subordinate's counters (mirrors `AxiStats` in tb/axi_mem.h) and the top's `err_o`.
    #[derive(Debug, Clone, Copy, Default)]
    struct AxiCounters {
        ar_accepted: u64,
        r_beats: u64,
        protocol_errors: u64,
        first_error_cycle: u64,
        dropped_at_reset: u64,
        rready_low: u64,
        in_flight: u64,
        err_flag: bool,
    }

    /// The compositing window's streams as DRAM (mirrors `WinConfig` in tb/win_host.h).
    #[derive(Debug, Clone, Copy, Default)]
    struct WinSetup {
        seed: u64,
        park_stall: u32,
        fin_stall: u32,
        rq_stall: u32,
        rs_idle: u32,
        lat_fixed: u32,
        lat_random: u32,
        expect_final: u64,
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
        /// False if the top has no AXI port (tb/axi_shim.h).
        fn axi_setup(self: Pin<&mut StreamDut>, setup: &AxiMemSetup) -> bool;
        fn axi_load(self: Pin<&mut StreamDut>, base: u64, bytes: &[u8]) -> bool;
        /// Appends the AR handshakes since the last call: (cycle, addr, len | size << 8 |
        /// burst << 12 | id << 16) each.
        fn axi_take_ar(self: Pin<&mut StreamDut>, out: &mut Vec<u64>) -> bool;
        fn axi_counters(self: &StreamDut) -> AxiCounters;
        fn axi_first_error(self: &StreamDut) -> String;
        /// The write port (tb/axi_mem.h, tb/axi_wr_shim.h): items for the data stream, the AW
        /// handshakes (as `axi_take_ar`), the memory image, the write counters.
        fn axi_feed(self: Pin<&mut StreamDut>, items: &[u32], words: u32, idle: &[u8]) -> bool;
        fn axi_take_aw(self: Pin<&mut StreamDut>, out: &mut Vec<u64>) -> bool;
        fn axi_image(self: &StreamDut, out: &mut Vec<u8>) -> bool;
        fn axi_wr_counters(self: &StreamDut) -> AxiWrCounters;
        /// cube5_frame with Window = 1 (tb/win_shim.h): its DRAM's traffic; false otherwise.
        fn win_setup(self: Pin<&mut StreamDut>, setup: &WinSetup) -> bool;
        /// The window records since the last call; the words per record (0: no window).
        fn win_take(self: Pin<&mut StreamDut>, out: &mut Vec<u32>) -> u32;
        fn win_errors(self: &StreamDut) -> u64;
        fn in_bits(self: &StreamDut) -> u32;
        fn out_bits(self: &StreamDut) -> u32;
    }
}
