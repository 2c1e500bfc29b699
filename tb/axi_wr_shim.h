// axi_wr_shim.h: DutCore for a Verilated top V with an AXI4 write manager port (m_axi_aw*,
// m_axi_w*, m_axi_b*) and a second input stream for its data (dat_valid_i, dat_ready_o,
// dat_data_i), answered cycle by cycle by the write port of an AxiMem (tb/axi_mem.h). The command
// and output streams behave exactly as StreamShim's (tb/stream_shim.h); the data stream takes the
// items queued by feed_data, with its own idle pattern.
#pragma once

#include "axi_mem.h"
#include "axi_shim.h"
#include "stream_shim.h"

namespace cube5 {

template <class V>
class AxiWrShim final : public AxiTopBase<V> {
  using B = AxiTopBase<V>;
  using B::cycle_;
  using B::mem_;
  using B::top_;

 public:
  AxiWrShim(uint32_t seed, PortWidths widths) : B(seed, widths) {
    idle_inputs();
    top_->eval();
  }

  /// Resets the top and the subordinate together: bursts outstanding are dropped on both sides,
  /// and so are the queued data items. A manager still driving AWVALID or WVALID out of reset is
  /// a protocol error.
  void reset(uint32_t cycles) override {
    data_.clear();
    data_next_ = 0;
    this->reset_with_mem(cycles, [this] { idle_inputs(); }, [this] {
      return top_->m_axi_awvalid_o || top_->m_axi_wvalid_o ? "AWVALID or WVALID high out of reset"
                                                           : nullptr;
    });
  }

  bool feed_data(const uint32_t* items, size_t n, uint32_t words, const uint8_t* idle,
                 size_t idle_len) override {
    data_.assign(items, items + n * words);
    data_words_ = words;
    data_next_ = 0;
    data_idle_.assign(idle, idle + idle_len);
    return true;
  }

  RunStats run(const uint32_t* items, size_t n_items, uint32_t in_words, const uint8_t* idle,
               size_t idle_len, const uint8_t* stall, size_t stall_len, uint64_t expect_out,
               uint64_t max_cycles, std::vector<uint32_t>& out, uint32_t out_words) override {
    RunStats st;
    size_t next = 0;
    const size_t n_data = data_words_ ? data_.size() / data_words_ : 0;
    while (st.cycles < max_cycles && (next < n_items || st.produced < expect_out)) {
      const auto [offer, take] =
          this->drive_stream(items, n_items, in_words, next, idle, idle_len, stall, stall_len);
      const bool dat_offer = data_next_ < n_data &&
                             !(!data_idle_.empty() && data_idle_[cycle_ % data_idle_.size()]);
      top_->dat_valid_i = dat_offer;
      if (dat_offer)
        write_port(top_->dat_data_i, data_.data() + data_next_ * data_words_, data_words_);

      axi_write_drive(*top_, mem_, cycle_);
      top_->eval();
      wobs_.observe(*top_, mem_, cycle_);
      if (dat_offer && top_->dat_ready_o) ++data_next_;
      if (!this->end_cycle(st, offer, next, take, out, out_words)) break;
    }
    top_->dat_valid_i = 0;
    this->idle_stream();
    return st;
  }

 private:
  void idle_inputs() {
    top_->in_valid_i = 0;
    top_->dat_valid_i = 0;
    top_->out_ready_i = 0;
    top_->m_axi_awready_i = 0;
    top_->m_axi_wready_i = 0;
    top_->m_axi_bvalid_i = 0;
  }

  std::vector<uint32_t> data_;
  uint32_t data_words_ = 0;
  size_t data_next_ = 0;
  std::vector<uint8_t> data_idle_;
  AxiWriteObserver wobs_;
};

}  // namespace cube5
