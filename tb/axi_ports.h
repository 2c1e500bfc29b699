// axi_ports.h: one cycle of a Verilated top's AXI4 manager port (m_axi_ar*, m_axi_r*; m_axi_aw*,
// m_axi_w*, m_axi_b*) against an AxiMem (tb/axi_mem.h): the subordinate's outputs onto the top
// before eval, the manager's outputs into the subordinate's checker after it. What AxiShim,
// AxiWrShim (tb/axi_shim.h, tb/axi_wr_shim.h) and AccelShim (tb/accel_shim.h) share.
#pragma once

#include <vector>

#include "axi_mem.h"
#include "stream_shim.h"

namespace cube5 {

/// Before eval: ARREADY and this cycle's R beat.
template <class V>
void axi_read_drive(V& top, AxiMem& mem, uint64_t cycle, std::vector<uint32_t>& rwords) {
  const ReadOut& r = mem.read.drive(cycle);
  top.m_axi_arready_i = r.arready;
  top.m_axi_rvalid_i = r.rvalid;
  if (r.rvalid) {
    rwords.assign((r.rdata.size() + 3) / 4, 0);
    for (size_t i = 0; i < r.rdata.size(); ++i)
      rwords[i / 4] |= static_cast<uint32_t>(r.rdata[i]) << (8 * (i % 4));
    write_port(top.m_axi_rdata_i, rwords.data(), static_cast<uint32_t>(rwords.size()));
    top.m_axi_rresp_i = r.rresp;
    top.m_axi_rlast_i = r.rlast;
    top.m_axi_rid_i = r.rid;
  }
}

/// After eval: AR and RREADY into the read port's handshakes and checks.
template <class V>
void axi_read_observe(const V& top, AxiMem& mem, uint64_t cycle) {
  mem.read.observe(cycle,
                   ArIn{static_cast<bool>(top.m_axi_arvalid_o), static_cast<uint64_t>(top.m_axi_araddr_o),
                        static_cast<uint32_t>(top.m_axi_arlen_o), static_cast<uint32_t>(top.m_axi_arsize_o),
                        static_cast<uint32_t>(top.m_axi_arburst_o), static_cast<uint32_t>(top.m_axi_arid_o)},
                   top.m_axi_rready_o);
}

/// Before eval: AWREADY, WREADY and this cycle's B.
template <class V>
void axi_write_drive(V& top, AxiMem& mem, uint64_t cycle) {
  const WriteOut& o = mem.write.drive(cycle);
  top.m_axi_awready_i = o.awready;
  top.m_axi_wready_i = o.wready;
  top.m_axi_bvalid_i = o.bvalid;
  top.m_axi_bresp_i = o.bresp;
  top.m_axi_bid_i = o.bid;
}

/// After eval: AW, W and BREADY into the write port's handshakes, writes and checks.
class AxiWriteObserver {
 public:
  template <class V>
  void observe(const V& top, AxiMem& mem, uint64_t cycle) {
    const uint32_t nb = mem.cfg.data_bytes;
    wwords_.resize((nb + 3) / 4 + 1);
    swords_.resize(nb / 32 + 2);
    w_.valid = top.m_axi_wvalid_o;
    w_.last = top.m_axi_wlast_o;
    read_port(top.m_axi_wdata_o, wwords_.data(), static_cast<uint32_t>(wwords_.size()));
    read_port(top.m_axi_wstrb_o, swords_.data(), static_cast<uint32_t>(swords_.size()));
    w_.data.resize(nb);
    w_.strb.resize(nb);
    for (uint32_t i = 0; i < nb; ++i) {
      w_.data[i] = static_cast<uint8_t>(wwords_[i / 4] >> (8 * (i % 4)));
      w_.strb[i] = static_cast<uint8_t>((swords_[i / 32] >> (i % 32)) & 1);
    }
    mem.write.observe(cycle,
                      ArIn{static_cast<bool>(top.m_axi_awvalid_o), static_cast<uint64_t>(top.m_axi_awaddr_o),
                           static_cast<uint32_t>(top.m_axi_awlen_o), static_cast<uint32_t>(top.m_axi_awsize_o),
                           static_cast<uint32_t>(top.m_axi_awburst_o), static_cast<uint32_t>(top.m_axi_awid_o)},
                      w_, top.m_axi_bready_o);
  }

 private:
  std::vector<uint32_t> wwords_, swords_;
  WIn w_;
};

}  // namespace cube5
