// stream_dut.h: the cxx-bridged wrapper around a DutCore (see tb-rs/src/ffi.rs).
#pragma once

#include <memory>

#include "dut_core.h"
#include "rust/cxx.h"

namespace cube5 {

struct RunResult;
struct AxiMemSetup;
struct AxiCounters;
struct AxiWrCounters;
struct WinSetup;
class AxiHost;
class WinHost;

class StreamDut {
 public:
  explicit StreamDut(std::unique_ptr<DutCore> core) : core_(std::move(core)) {}

  void reset(uint32_t cycles);
  RunResult run(rust::Slice<const uint32_t> items, uint32_t in_words, rust::Slice<const uint8_t> idle,
                rust::Slice<const uint8_t> stall, uint64_t expect_out, uint64_t max_cycles,
                rust::Vec<uint32_t>& out, uint32_t out_words);
  bool write_config(uint32_t addr, rust::Slice<const uint32_t> data);
  bool trace_window(rust::Str path, uint64_t from_cycle, uint64_t to_cycle);
  uint64_t cycle() const;
  // The AXI memory subordinate of a top with an AXI port (tb/axi_shim.h); false/empty otherwise.
  bool axi_setup(const AxiMemSetup& setup);
  bool axi_load(uint64_t base, rust::Slice<const uint8_t> bytes);
  bool axi_take_ar(rust::Vec<uint64_t>& out);
  AxiCounters axi_counters() const;
  rust::String axi_first_error() const;
  bool axi_feed(rust::Slice<const uint32_t> items, uint32_t words, rust::Slice<const uint8_t> idle);
  bool axi_take_aw(rust::Vec<uint64_t>& out);
  bool axi_image(rust::Vec<uint8_t>& out) const;
  AxiWrCounters axi_wr_counters() const;
  // The window streams of cube5_frame Window = 1 (tb/win_shim.h); false/0 otherwise.
  bool win_setup(const WinSetup& setup);
  uint32_t win_take(rust::Vec<uint32_t>& out);
  uint64_t win_errors() const;
  uint32_t in_bits() const;
  uint32_t out_bits() const;

 private:
  AxiHost* axi() const;
  WinHost* win() const;

  std::unique_ptr<DutCore> core_;
};

/// The variant named `name` (e.g. "cube5_trilin_v12"), or null if it was not built.
std::unique_ptr<StreamDut> new_stream_dut(rust::Str name, uint32_t seed);
/// Names of every variant compiled into this test bench.
rust::Vec<rust::String> built_variants();

}  // namespace cube5
