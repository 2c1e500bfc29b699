// axi_shim.h: DutCore for a Verilated streaming top V that also has an AXI4 read manager port
// (m_axi_ar*, m_axi_r*), answered cycle by cycle by an AxiMem (tb/axi_mem.h) in the same clock
// loop. The stream side is StreamShim's (StreamTop in tb/stream_shim.h).
#pragma once

#include "axi_mem.h"
#include "axi_ports.h"
#include "stream_shim.h"

namespace cube5 {

// Detects an err_o status output.
template <class V, class = void>
struct HasErrFlag : std::false_type {};
template <class V>
struct HasErrFlag<V, std::void_t<decltype(std::declval<V&>().err_o)>> : std::true_type {};

/// What the shims of tops with an AXI port share (AxiShim here, AxiWrShim in tb/axi_wr_shim.h,
/// AxiRwShim in tb/axi_rw_shim.h) beyond StreamTop: the subordinate and the reset with it. The
/// derived shim idles its own inputs and evals.
template <class V>
class AxiTopBase : public StreamTop<V>, public AxiHost {
  using S = StreamTop<V>;

 public:
  AxiMem& axi_mem() override { return mem_; }
  bool axi_err_flag() const override {
    if constexpr (HasErrFlag<V>::value) {
      return top_->err_o;
    } else {
      return false;
    }
  }

 protected:
  using S::cycle_;
  using S::top_;

  AxiTopBase(uint32_t seed, PortWidths widths) : S(seed, widths) {}

  /// Resets the top and the subordinate together (bursts in flight are dropped on both sides):
  /// `idle` idles the top's inputs; a manager for which `still_valid` names a VALID still high
  /// out of reset (else nullptr) breaks the protocol.
  template <class Idle, class StillValid>
  void reset_with_mem(uint32_t cycles, Idle idle, StillValid still_valid) {
    this->reset_stream(cycles, [&] {
      idle();
      mem_.reset();
    });
    // A protocol error of the manager found outside the subordinate's own checks.
    if (const char* what = still_valid()) mem_.stats.violation(cycle_, what);
  }

  AxiMem mem_;
};

/// A streaming top with an AXI4 manager port answered by one AxiMem: AxiShim (`Write` false) a
/// read port (m_axi_ar*, m_axi_r*); AxiRwShim (tb/axi_rw_shim.h, `Write` true) a port that also
/// writes (m_axi_aw*, m_axi_w*, m_axi_b*) into the same image (gicube_cache's write-back).
template <class V, bool Write>
class AxiManagerShim final : public AxiTopBase<V> {
  using B = AxiTopBase<V>;
  using B::cycle_;
  using B::mem_;
  using B::top_;

 public:
  AxiManagerShim(uint32_t seed, PortWidths widths) : B(seed, widths) {
    idle_axi();
    top_->eval();
  }

  bool write_config(uint32_t addr, const uint32_t* words, uint32_t n_words) override {
    return this->config_write(addr, words, n_words, [this] { idle_axi(); });
  }

  /// Resets the top and the subordinate together: bursts in flight are dropped on both sides. A
  /// manager still driving ARVALID (or, writing, AWVALID or WVALID) out of reset is a protocol
  /// error.
  void reset(uint32_t cycles) override {
    this->reset_with_mem(cycles, [this] { idle_axi(); }, [this]() -> const char* {
      if constexpr (Write) {
        return top_->m_axi_arvalid_o || top_->m_axi_awvalid_o || top_->m_axi_wvalid_o
                   ? "ARVALID, AWVALID or WVALID high out of reset"
                   : nullptr;
      } else {
        return top_->m_axi_arvalid_o ? "ARVALID high out of reset" : nullptr;
      }
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
      if constexpr (Write) axi_write_drive(*top_, mem_, cycle_);
      top_->eval();
      axi_read_observe(*top_, mem_, cycle_);
      if constexpr (Write) wobs_.observe(*top_, mem_, cycle_);
      if (!this->end_cycle(st, offer, next, take, out, out_words)) break;
    }
    this->idle_stream();
    return st;
  }

 private:
  void idle_axi() {
    top_->m_axi_arready_i = 0;
    top_->m_axi_rvalid_i = 0;
    if constexpr (Write) {
      top_->m_axi_awready_i = 0;
      top_->m_axi_wready_i = 0;
      top_->m_axi_bvalid_i = 0;
    }
  }

  AxiWriteObserver wobs_;  // unused without Write
};

template <class V>
using AxiShim = AxiManagerShim<V, false>;

}  // namespace cube5
