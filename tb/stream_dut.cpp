// stream_dut.cpp: converts between cxx types and DutCore's plain C++ ones.
#include "stream_dut.h"

#include <algorithm>

#include "cube5-tb/src/ffi.rs.h"

namespace cube5 {

void StreamDut::reset(uint32_t cycles) { core_->reset(cycles); }

RunResult StreamDut::run(rust::Slice<const uint32_t> items, uint32_t in_words,
                         rust::Slice<const uint8_t> idle, rust::Slice<const uint8_t> stall,
                         uint64_t expect_out, uint64_t max_cycles, rust::Vec<uint32_t>& out,
                         uint32_t out_words) {
  const size_t n_items = in_words ? items.size() / in_words : 0;
  std::vector<uint32_t> collected;
  collected.reserve(std::min<size_t>(n_items, expect_out) * (2 + out_words));
  const RunStats st = core_->run(items.data(), n_items, in_words, idle.data(), idle.size(),
                                 stall.data(), stall.size(), expect_out, max_cycles, collected,
                                 out_words);
  out.reserve(out.size() + collected.size());
  for (uint32_t w : collected) out.push_back(w);
  return RunResult{st.consumed, st.produced, st.cycles, st.protocol_errors,
                   st.first_protocol_error_cycle, st.finished};
}

bool StreamDut::write_config(uint32_t addr, rust::Slice<const uint32_t> data) {
  return core_->write_config(addr, data.data(), static_cast<uint32_t>(data.size()));
}

bool StreamDut::trace_window(rust::Str path, uint64_t from_cycle, uint64_t to_cycle) {
  return core_->trace_window(std::string(path), from_cycle, to_cycle);
}

uint64_t StreamDut::cycle() const { return core_->cycle(); }
uint32_t StreamDut::in_bits() const { return core_->widths().in_bits; }
uint32_t StreamDut::out_bits() const { return core_->widths().out_bits; }

}  // namespace cube5
