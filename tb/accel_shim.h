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
#include "axil_mgr.h"
#include "clocked_top.h"
#include "stream_shim.h"

namespace cube5 {

template <class V>
class AccelShim final : public ClockedTop<V>, public AxiHost {
  using C = ClockedTop<V>;
  using C::ctx_;
  using C::cycle_;
  using C::tick;
  using C::top_;

 public:
  AccelShim(uint32_t seed, PortWidths widths) : C(seed, widths) {
    idle_inputs();
    top_->eval();
  }

  AxiMem& axi_mem() override { return mem_; }
  bool axi_err_flag() const override { return top_->err_o; }

  /// Resets the top and the subordinate together: bursts in flight are dropped on both sides, and
  /// so are the host's transactions. A manager still driving a VALID out of reset is a protocol
  /// error.
  void reset(uint32_t cycles) override {
    top_->rst_ni = 0;
    idle_inputs();
    mem_.reset();
    mgr_.reset();
    for (uint32_t i = 0; i < cycles; ++i) {
      top_->eval();
      tick();
    }
    top_->rst_ni = 1;
    top_->eval();
    if (top_->m_axi_arvalid_o || top_->m_axi_awvalid_o || top_->m_axi_wvalid_o)
      violation("ARVALID, AWVALID or WVALID high out of reset");
    if (top_->s_axil_bvalid_o || top_->s_axil_rvalid_o)
      mgr_.error(cycle_, "BVALID or RVALID high out of reset");
  }

  RunStats run(const uint32_t* items, size_t n_items, uint32_t in_words, const uint8_t*, size_t,
               const uint8_t* stall, size_t stall_len, uint64_t expect_out, uint64_t max_cycles,
               std::vector<uint32_t>& out, uint32_t out_words) override {
    RunStats st;
    if (in_words != AxilMgr::kItemWords || out_words != AxilMgr::kRecordWords) {
      st.protocol_errors = 1;
      return st;
    }
    mgr_.load(items, n_items);
    uint64_t responses = 0;
    auto stalled = [&](uint64_t off) { return stall_len && stall[(cycle_ + off) % stall_len]; };
    const uint32_t nb = mem_.cfg.data_bytes;
    std::vector<uint32_t> rwords, wwords((nb + 3) / 4 + 1), swords(nb / 32 + 2);
    WIn w;
    while (st.cycles < max_cycles) {
      if (n_items == 0 ? static_cast<bool>(top_->irq_o) : mgr_.all_issued() && responses >= expect_out)
        break;
      axil_drive(*top_, mgr_.drive(!stalled(0), !stalled(2053)));
      const ReadOut& r = mem_.read.drive(cycle_);
      top_->m_axi_arready_i = r.arready;
      top_->m_axi_rvalid_i = r.rvalid;
      if (r.rvalid) {
        rwords.assign((r.rdata.size() + 3) / 4, 0);
        for (size_t i = 0; i < r.rdata.size(); ++i)
          rwords[i / 4] |= static_cast<uint32_t>(r.rdata[i]) << (8 * (i % 4));
        write_port(top_->m_axi_rdata_i, rwords.data(), static_cast<uint32_t>(rwords.size()));
        top_->m_axi_rresp_i = r.rresp;
        top_->m_axi_rlast_i = r.rlast;
        top_->m_axi_rid_i = r.rid;
      }
      const WriteOut& o = mem_.write.drive(cycle_);
      top_->m_axi_awready_i = o.awready;
      top_->m_axi_wready_i = o.wready;
      top_->m_axi_bvalid_i = o.bvalid;
      top_->m_axi_bresp_i = o.bresp;
      top_->m_axi_bid_i = o.bid;
      top_->eval();

      const SubOut s = axil_sub(*top_);
      responses += mgr_.observe(cycle_, s, out);
      mem_.read.observe(cycle_,
                        ArIn{static_cast<bool>(top_->m_axi_arvalid_o),
                             static_cast<uint64_t>(top_->m_axi_araddr_o),
                             static_cast<uint32_t>(top_->m_axi_arlen_o),
                             static_cast<uint32_t>(top_->m_axi_arsize_o),
                             static_cast<uint32_t>(top_->m_axi_arburst_o),
                             static_cast<uint32_t>(top_->m_axi_arid_o)},
                        top_->m_axi_rready_o);
      w.valid = top_->m_axi_wvalid_o;
      w.last = top_->m_axi_wlast_o;
      read_port(top_->m_axi_wdata_o, wwords.data(), static_cast<uint32_t>(wwords.size()));
      read_port(top_->m_axi_wstrb_o, swords.data(), static_cast<uint32_t>(swords.size()));
      w.data.resize(nb);
      w.strb.resize(nb);
      for (uint32_t i = 0; i < nb; ++i) {
        w.data[i] = static_cast<uint8_t>(wwords[i / 4] >> (8 * (i % 4)));
        w.strb[i] = static_cast<uint8_t>((swords[i / 32] >> (i % 32)) & 1);
      }
      mem_.write.observe(cycle_,
                         ArIn{static_cast<bool>(top_->m_axi_awvalid_o),
                              static_cast<uint64_t>(top_->m_axi_awaddr_o),
                              static_cast<uint32_t>(top_->m_axi_awlen_o),
                              static_cast<uint32_t>(top_->m_axi_awsize_o),
                              static_cast<uint32_t>(top_->m_axi_awburst_o),
                              static_cast<uint32_t>(top_->m_axi_awid_o)},
                         w, top_->m_axi_bready_o);
      tick();
      ++st.cycles;
      if (ctx_->gotFinish()) {
        st.finished = true;
        break;
      }
    }
    st.consumed = mgr_.issued();
    st.produced = responses;
    st.protocol_errors = mgr_.errors();
    st.first_protocol_error_cycle = mgr_.first_error_cycle();
    axil_idle(*top_);
    top_->eval();
    return st;
  }

 private:
  void violation(const char* what) {
    AxiStats& st = mem_.stats;
    if (st.protocol_errors++ == 0) {
      st.first_error_cycle = cycle_;
      st.first_error = what;
    }
  }

  void idle_inputs() {
    axil_idle(*top_);
    top_->m_axi_arready_i = 0;
    top_->m_axi_rvalid_i = 0;
    top_->m_axi_awready_i = 0;
    top_->m_axi_wready_i = 0;
    top_->m_axi_bvalid_i = 0;
  }

  AxilMgr mgr_;
  AxiMem mem_;
};

}  // namespace cube5
