// out_watch.h: the output stream's watch that the clocked shims share (AxiTopBase in
// tb/axi_shim.h, WinShim in tb/win_shim.h): the valid/ready rule on out_valid_o/out_data_o and the
// record of every output taken. StreamShim (tb/stream_shim.h) keeps its own copy so that the stream
// tops' cached builds stay valid.
#pragma once

#include <cstdint>
#include <type_traits>
#include <vector>

#include "dut_core.h"
#include "stream_shim.h"

namespace cube5 {

template <class V>
class OutWatch {
 public:
  /// After eval, in clock `cycle`: an output held back last cycle must still be offered,
  /// unchanged (else a protocol error in `st`); the output taken this cycle (if `take`) is appended
  /// to `out` as DutCore::run describes (the cycle, two words, low first, then the item's words).
  void watch(const V& top, uint64_t cycle, bool take, RunStats& st, std::vector<uint32_t>& out,
             uint32_t out_words) {
    if (has_stalled_ && (!top.out_valid_o || !port_equal(top.out_data_o, stalled_data_))) {
      if (st.protocol_errors++ == 0) st.first_protocol_error_cycle = cycle;
    }
    has_stalled_ = top.out_valid_o && !take;
    if (has_stalled_) stalled_data_ = top.out_data_o;
    if (top.out_valid_o && take) {
      const size_t at = out.size();
      out.resize(at + 2 + out_words);
      out[at] = static_cast<uint32_t>(cycle);
      out[at + 1] = static_cast<uint32_t>(cycle >> 32);
      read_port(top.out_data_o, out.data() + at + 2, out_words);
      ++st.produced;
    }
  }

  /// Reset: nothing is held back.
  void clear() { has_stalled_ = false; }

 private:
  bool has_stalled_ = false;
  std::remove_reference_t<decltype(V::out_data_o)> stalled_data_{};
};

}  // namespace cube5
