// axil_shim.h: DutCore for a Verilated top V with an AXI4-Lite subordinate port (s_axil_*) and the
// narrow hardware side of cube5_axil (hw_i, hw_set_i, wsel_i, rsel_i, hw_q_o, hw_wr_stb_o,
// hw_rd_stb_o, irq_o). An AXI4-Lite manager (tb/axil_mgr.h) runs in the clock loop; the
// DutCore stream interface carries its transactions in and its responses out (formats in
// tb/axil_mgr.h and tb-rs/src/axil.rs), so the existing bridge serves it unchanged.
#pragma once

#include "axil_mgr.h"
#include "stream_shim.h"

namespace cube5 {

template <class V>
class AxilShim final : public AxilTopBase<V> {
  using B = AxilTopBase<V>;
  using B::cycle_;
  using B::mgr_;
  using B::seed_;
  using B::top_;

 public:
  AxilShim(uint32_t seed, PortWidths widths) : B(seed, widths) {
    idle_inputs();
    top_->eval();
  }

  /// Resets the top and the manager together: transactions in flight are dropped on both sides.
  /// A subordinate still driving BVALID or RVALID out of reset is a protocol error.
  void reset(uint32_t cycles) override {
    this->reset_with_mgr(cycles, [this] { idle_inputs(); }, [this] { drive_hw(); });
  }

  /// Items are transactions (AxilMgr::kItemWords words each), outputs are response and interrupt
  /// records (AxilMgr::kRecordWords words after the two cycle words). `idle` is unused (each
  /// transaction carries its own delays); `stall[c % len]` holds BREADY low, `stall[(c + 2053) %
  /// len]` RREADY. `expect_out` counts B and R responses; interrupt records come on top.
  RunStats run(const uint32_t* items, size_t n_items, uint32_t in_words, const uint8_t*, size_t,
               const uint8_t* stall, size_t stall_len, uint64_t expect_out, uint64_t max_cycles,
               std::vector<uint32_t>& out, uint32_t out_words) override {
    RunStats st;
    if (!this->start_run(st, items, n_items, in_words, out_words, AxilMgr::kRecordWords)) return st;
    uint64_t responses = 0;
    while (st.cycles < max_cycles && (!mgr_.all_issued() || responses < expect_out)) {
      const bool bready = !(stall_len && stall[cycle_ % stall_len]);
      const bool rready = !(stall_len && stall[(cycle_ + 2053) % stall_len]);
      const MgrOut m = mgr_.drive(bready, rready);
      axil_drive(*top_, m);
      top_->wsel_i = m.wsel;
      top_->rsel_i = m.rsel;
      drive_hw();
      top_->eval();
      SubOut s = axil_sub(*top_);
      s.hw_q = top_->hw_q_o;
      s.wr_stb = top_->hw_wr_stb_o;
      s.rd_stb = top_->hw_rd_stb_o;
      responses += mgr_.observe(cycle_, s, out);
      if (!this->clock_cycle(st)) break;
    }
    this->end_run(st, responses);
    idle_inputs();
    drive_hw();
    top_->eval();
    return st;
  }

 private:
  void idle_inputs() { axil_idle(*top_); }

  // The hardware side's stimulus of this cycle (axil_hw in tb/axil_mgr.h).
  void drive_hw() {
    const uint64_t h = axil_hw(seed_, cycle_);
    top_->hw_i = static_cast<uint32_t>(h);
    top_->hw_set_i = static_cast<bool>((h >> 32) & 1);  // bit 32: the set flag
  }
};

}  // namespace cube5
