// axi_shim.h: DutCore for a Verilated streaming top V that also has an AXI4 read manager port
// (m_axi_ar*, m_axi_r*), answered cycle by cycle by an AxiMem (tb/axi_mem.h) in the same clock
// loop. The stream side behaves exactly as StreamShim's (tb/stream_shim.h, whose port helpers it
// uses); StreamShim is left as it is so that the existing tops' cached builds stay valid.
#pragma once

#include "axi_mem.h"
#include "axi_ports.h"
#include "clocked_top.h"
#include "out_watch.h"
#include "stream_shim.h"

namespace cube5 {

// Detects an err_o status output.
template <class V, class = void>
struct HasErrFlag : std::false_type {};
template <class V>
struct HasErrFlag<V, std::void_t<decltype(std::declval<V&>().err_o)>> : std::true_type {};

/// What the shims of tops with an AXI port share (AxiShim here, AxiWrShim in tb/axi_wr_shim.h,
/// AxiRwShim in tb/axi_rw_shim.h) beyond ClockedTop: the subordinate, the configuration write, and
/// the output stream's stall rule and collection. The derived shim idles its own inputs and evals.
template <class V>
class AxiTopBase : public ClockedTop<V>, public AxiHost {
  using C = ClockedTop<V>;

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
  using C::cycle_;
  using C::top_;

  AxiTopBase(uint32_t seed, PortWidths widths) : C(seed, widths) {
    top_->in_valid_i = 0;
    top_->out_ready_i = 0;
    if constexpr (HasConfigPort<V>::value) top_->cfg_valid_i = 0;
  }

  /// One write on the optional configuration port (as StreamShim's): the stream idle and `idle`
  /// idling the AXI4 port (no address or beat taken, no beat or response offered) in that clock.
  /// False when the top has no configuration port.
  template <class Idle>
  bool config_write(uint32_t addr, const uint32_t* words, uint32_t n_words, Idle idle) {
    if constexpr (HasConfigPort<V>::value) {
      top_->in_valid_i = 0;
      top_->out_ready_i = 0;
      idle();
      top_->cfg_valid_i = 1;
      top_->cfg_addr_i = addr;
      write_port(top_->cfg_data_i, words, n_words);
      this->tick();
      top_->cfg_valid_i = 0;
      top_->eval();
      return true;
    } else {
      (void)addr;
      (void)words;
      (void)n_words;
      return false;
    }
  }

  /// Resets the top and the subordinate together (bursts in flight are dropped on both sides):
  /// `idle` idles the top's inputs; a manager for which `still_valid` names a VALID still high
  /// out of reset (else nullptr) breaks the protocol.
  template <class Idle, class StillValid>
  void reset_with_mem(uint32_t cycles, Idle idle, StillValid still_valid) {
    top_->rst_ni = 0;
    top_->in_valid_i = 0;
    top_->out_ready_i = 0;
    idle();
    mem_.reset();
    for (uint32_t i = 0; i < cycles; ++i) this->tick();
    top_->rst_ni = 1;
    top_->eval();
    if (const char* what = still_valid()) axi_violation(what);
    out_watch_.clear();
  }

  /// Records a protocol error of the manager found outside the subordinate's own checks.
  void axi_violation(const char* what) {
    AxiStats& st = mem_.stats;
    if (st.protocol_errors++ == 0) {
      st.first_error_cycle = cycle_;
      st.first_error = what;
    }
  }

  /// Before eval: command `next` offered unless `idle` says idle or none is left, the output
  /// taken unless `stall` says stalled. Returns {offered, taken}.
  std::pair<bool, bool> drive_stream(const uint32_t* items, size_t n_items, uint32_t in_words,
                                     size_t next, const uint8_t* idle, size_t idle_len,
                                     const uint8_t* stall, size_t stall_len) {
    const bool offer = next < n_items && !(idle_len && idle[cycle_ % idle_len]);
    const bool take = !(stall_len && stall[cycle_ % stall_len]);
    top_->in_valid_i = offer;
    if (offer) write_port(top_->in_data_i, items + next * in_words, in_words);
    top_->out_ready_i = take;
    return {offer, take};
  }

  /// After eval and the subordinate's observation: the command taken (if `offered`), the output
  /// watched, the clock ticked. False once the top has called $finish.
  bool end_cycle(RunStats& st, bool offered, size_t& next, bool take, std::vector<uint32_t>& out,
                 uint32_t out_words) {
    if (offered && top_->in_ready_o) {
      ++next;
      ++st.consumed;
    }
    out_watch_.watch(*top_, cycle_, take, st, out, out_words);
    this->tick();
    ++st.cycles;
    if (this->ctx_->gotFinish()) {
      st.finished = true;
      return false;
    }
    return true;
  }

  /// After a run: the stream's inputs idle.
  void idle_stream() {
    top_->in_valid_i = 0;
    top_->out_ready_i = 0;
    top_->eval();
  }

  OutWatch<V> out_watch_;
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
