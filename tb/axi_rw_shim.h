// axi_rw_shim.h: DutCore for a Verilated streaming top V with an AXI4 manager port that both reads
// (m_axi_ar*, m_axi_r*) and writes (m_axi_aw*, m_axi_w*, m_axi_b*), answered cycle by cycle by
// both ports of one AxiMem (tb/axi_mem.h) over one image: what gicube_cache's write-back needs
// (reads of lines, write-backs of dirty ones). The stream side behaves exactly as AxiShim's.
#pragma once

#include "axi_mem.h"
#include "axi_ports.h"
#include "axi_shim.h"

namespace cube5 {

template <class V>
class AxiRwShim final : public AxiTopBase<V> {
  using B = AxiTopBase<V>;
  using B::cycle_;
  using B::mem_;
  using B::top_;

 public:
  AxiRwShim(uint32_t seed, PortWidths widths) : B(seed, widths) {
    idle_axi();
    top_->eval();
  }

  bool write_config(uint32_t addr, const uint32_t* words, uint32_t n_words) override {
    return this->config_write(addr, words, n_words, [this] { idle_axi(); });
  }

  /// Resets the top and the subordinate together: bursts in flight are dropped on both sides. A
  /// manager still driving ARVALID, AWVALID or WVALID out of reset is a protocol error.
  void reset(uint32_t cycles) override {
    this->reset_with_mem(cycles, [this] { idle_axi(); }, [this] {
      return top_->m_axi_arvalid_o || top_->m_axi_awvalid_o || top_->m_axi_wvalid_o
                 ? "ARVALID, AWVALID or WVALID high out of reset"
                 : nullptr;
    });
  }

  RunStats run(const uint32_t* items, size_t n_items, uint32_t in_words, const uint8_t* idle,
               size_t idle_len, const uint8_t* stall, size_t stall_len, uint64_t expect_out,
               uint64_t max_cycles, std::vector<uint32_t>& out, uint32_t out_words) override {
    RunStats st;
    size_t next = 0;
    std::vector<uint32_t> rwords;
    while (st.cycles < max_cycles && (next < n_items || st.produced < expect_out)) {
      const auto [offer, take] =
          this->drive_stream(items, n_items, in_words, next, idle, idle_len, stall, stall_len);
      axi_read_drive(*top_, mem_, cycle_, rwords);
      axi_write_drive(*top_, mem_, cycle_);
      top_->eval();
      axi_read_observe(*top_, mem_, cycle_);
      wobs_.observe(*top_, mem_, cycle_);
      if (!this->end_cycle(st, offer, next, take, out, out_words)) break;
    }
    this->idle_stream();
    return st;
  }

 private:
  void idle_axi() {
    top_->m_axi_arready_i = 0;
    top_->m_axi_rvalid_i = 0;
    top_->m_axi_awready_i = 0;
    top_->m_axi_wready_i = 0;
    top_->m_axi_bvalid_i = 0;
  }

  AxiWriteObserver wobs_;
};

}  // namespace cube5
