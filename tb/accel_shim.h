// accel_shim.h: DutCore for the accelerator top cube5_accel: an AXI4-Lite manager (tb/axil_mgr.h)
// on its host port and the AXI4 memory subordinate (tb/axi_mem.h) on its manager port, read
// channels (the volume) and write channels (the image) answered from the one image in the same
// clock loop, with the subordinate's latency, gaps, bandwidth limit and protocol checks.
//
// Items are AxilMgr transactions and records are AxilMgr's (B, R and irq records), as AxilShim's:
// `stall` back-pressures B and R. With no items, run() runs until irq_o is high (the host waiting
// for the interrupt) or `max_cycles` have passed; the irq record of the rising edge is in the
// output.
#pragma once

#include "axi_mem.h"
#include "axi_ports.h"
#include "axil_mgr.h"
#include "stream_shim.h"

namespace cube5 {

template <class V>
class AccelShim final : public AxilTopBase<V>, public AxiHost {
  using B = AxilTopBase<V>;
  using B::cycle_;
  using B::mgr_;
  using B::top_;

 public:
  AccelShim(uint32_t seed, PortWidths widths) : B(seed, widths) {
    idle_inputs();
    top_->eval();
  }

  AxiMem& axi_mem() override { return mem_; }
  bool axi_err_flag() const override { return top_->err_o; }

  /// Resets the top and the subordinate together: bursts in flight are dropped on both sides, and
  /// so are the host's transactions. A manager still driving a VALID out of reset is a protocol
  /// error.
  void reset(uint32_t cycles) override {
    this->reset_with_mgr(cycles, [this] {
      idle_inputs();
      mem_.reset();
    }, [] {});
    if (top_->m_axi_arvalid_o || top_->m_axi_awvalid_o || top_->m_axi_wvalid_o)
      mem_.stats.violation(cycle_, "ARVALID, AWVALID or WVALID high out of reset");
  }

  RunStats run(const uint32_t* items, size_t n_items, uint32_t in_words, const uint8_t*, size_t,
               const uint8_t* stall, size_t stall_len, uint64_t expect_out, uint64_t max_cycles,
               std::vector<uint32_t>& out, uint32_t out_words) override {
    RunStats st;
    if (!this->start_run(st, items, n_items, in_words, out_words, AxilMgr::kRecordWords)) return st;
    uint64_t responses = 0;
    auto stalled = [&](uint64_t off) { return stall_len && stall[(cycle_ + off) % stall_len]; };
    std::vector<uint32_t> rwords;
    while (st.cycles < max_cycles) {
      if (n_items == 0 ? static_cast<bool>(top_->irq_o) : mgr_.all_issued() && responses >= expect_out)
        break;
      axil_drive(*top_, mgr_.drive(!stalled(0), !stalled(2053)));
      axi_read_drive(*top_, mem_, cycle_, rwords);
      axi_write_drive(*top_, mem_, cycle_);
      top_->eval();

      const SubOut s = axil_sub(*top_);
      responses += mgr_.observe(cycle_, s, out);
      axi_read_observe(*top_, mem_, cycle_);
      wobs_.observe(*top_, mem_, cycle_);
      if (!this->clock_cycle(st)) break;
    }
    this->end_run(st, responses);
    axil_idle(*top_);
    top_->eval();
    return st;
  }

 private:
  void idle_inputs() {
    axil_idle(*top_);
    top_->m_axi_arready_i = 0;
    top_->m_axi_rvalid_i = 0;
    top_->m_axi_awready_i = 0;
    top_->m_axi_wready_i = 0;
    top_->m_axi_bvalid_i = 0;
  }

  AxiMem mem_;
  AxiWriteObserver wobs_;
};

}  // namespace cube5
