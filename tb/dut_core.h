// dut_core.h: the plain C++ face of one Verilator-compiled streaming top, free of cxx types so the
// per-variant objects compile (and are cached) independently of the Rust bridge.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace cube5 {

/// What one call to `DutCore::run` did.
struct RunStats {
  uint64_t consumed = 0;         ///< input items accepted (valid & ready)
  uint64_t produced = 0;         ///< output items taken (valid & ready)
  uint64_t cycles = 0;           ///< clock cycles simulated in this call
  uint64_t protocol_errors = 0;  ///< cycles where a stalled output dropped valid or changed data
  uint64_t first_protocol_error_cycle = 0;
  bool finished = false;         ///< the RTL executed $finish or a fatal assertion
};

/// Static facts about a variant, read back by the Rust side to check its own codec against them.
struct PortWidths {
  uint32_t in_bits;
  uint32_t out_bits;
};

/// One streaming top: clk_i, rst_ni, in_valid_i/in_ready_o/in_data_i, out_valid_o/out_ready_i/out_data_o.
class DutCore {
 public:
  virtual ~DutCore() = default;

  /// Holds rst_ni low for `cycles` clock cycles with all inputs idle, then releases it.
  virtual void reset(uint32_t cycles) = 0;

  /// Drives up to `n_items` items (each `in_words` 32-bit words) into the unit and collects outputs
  /// (records of 2 + `out_words` words appended to `out`: the cycle it was taken, low word first,
  /// then the item), one clock per iteration, until every item is consumed
  /// and `expect_out` outputs were taken, or `max_cycles` cycles have passed. In cycle c (counted
  /// from construction) the input is idle when idle[c % idle_len] is nonzero and the output is
  /// stalled when stall[c % stall_len] is nonzero.
  virtual RunStats run(const uint32_t* items, size_t n_items, uint32_t in_words, const uint8_t* idle,
                       size_t idle_len, const uint8_t* stall, size_t stall_len, uint64_t expect_out,
                       uint64_t max_cycles, std::vector<uint32_t>& out, uint32_t out_words) = 0;

  /// One write on the optional configuration port (cfg_valid_i, cfg_addr_i, cfg_data_i) that loads
  /// LUTs and registers: one clock with the stream idle. False if the top has no such port.
  virtual bool write_config(uint32_t addr, const uint32_t* words, uint32_t n_words) = 0;

  /// Starts a VCD trace to `path` that records cycles [from_cycle, to_cycle]; false if tracing
  /// was not compiled in.
  virtual bool trace_window(const std::string& path, uint64_t from_cycle, uint64_t to_cycle) = 0;

  /// Cycles simulated since construction (resets included).
  virtual uint64_t cycle() const = 0;

  virtual PortWidths widths() const = 0;
};

}  // namespace cube5
