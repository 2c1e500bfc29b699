// axil_mgr.h: an AXI4-Lite manager for the C++ clock loop, with per-transaction delays on AW, W and
// AR, back-pressure on B and R, and a protocol checker on all five channels: a VALID held until its
// READY with the payload stable (both sides), one B per write and one R per read (no response
// without a request; responses are in request order, which AXI4-Lite without IDs makes the only
// order, so the k-th B answers the k-th write), BVALID and RVALID low out of reset.
//
// Transaction (kItemWords words): w0 = read (bit 0) | WSTRB << 4 | delay << 8 | W delay << 16,
// w1 = byte address, w2 = write data, w3 = 0. `delay` is the cycles AW (or AR) waits after the
// channel's previous handshake (or the start of the run) before it raises VALID; W waits `W delay`.
// Record (kRecordWords words, after the two words of the cycle it was taken, low first):
//   B:   w0 = 0 | BRESP << 2 | hw_wr_stb_o << 4, w1 = hw_q_o, w2 = first cycle of BVALID,
//        w3 = cycle of the later of the write's AW and W handshakes (wsel_i = the write's offset);
//   R:   w0 = 1 | RRESP << 2 | hw_rd_stb_o << 4, w1 = RDATA, w2 = cycle of the AR handshake,
//        w3 = first cycle of RVALID (rsel_i = the read's offset);
//   irq: w0 = 2 | irq_o << 5, w1 = 0, w2 = the cycle, w3 = 0: irq_o in a cycle of a run where it
//        differs from the last cycle observed (the first cycle ever observed is recorded too).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "stream_shim.h"

namespace cube5 {

/// The hardware-side stimulus of cube5_axil in `cycle` for a shim seeded `seed`: bits 31:0 drive
/// `hw_i`, bit 32 `hw_set_i` (one cycle in eight). tb-rs/src/axil.rs computes the same function.
inline uint64_t axil_hw(uint32_t seed, uint64_t cycle) {
  uint64_t z = (static_cast<uint64_t>(seed) << 32 ^ cycle) + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return (z & 0xffffffffull) | (static_cast<uint64_t>(((z >> 32) & 7) == 0) << 32);
}

/// What the manager drives in one cycle.
struct MgrOut {
  bool awvalid = false, wvalid = false, bready = false, arvalid = false, rready = false;
  uint32_t awaddr = 0, wdata = 0, wstrb = 0, araddr = 0, wsel = 0, rsel = 0;
};

/// What the subordinate (and the top's hardware side) drives in one cycle.
struct SubOut {
  bool awready = false, wready = false, bvalid = false, arready = false, rvalid = false;
  uint32_t bresp = 0, rdata = 0, rresp = 0, hw_q = 0;
  bool wr_stb = false, rd_stb = false, irq = false;
};

/// Drives the manager's outputs of this cycle onto a top's AXI4-Lite subordinate port (s_axil_*).
template <class V>
void axil_drive(V& top, const MgrOut& m) {
  top.s_axil_awvalid_i = m.awvalid;
  top.s_axil_awaddr_i = m.awaddr;
  top.s_axil_wvalid_i = m.wvalid;
  top.s_axil_wdata_i = m.wdata;
  top.s_axil_wstrb_i = m.wstrb;
  top.s_axil_bready_i = m.bready;
  top.s_axil_arvalid_i = m.arvalid;
  top.s_axil_araddr_i = m.araddr;
  top.s_axil_rready_i = m.rready;
}

/// The manager's side of the port idle (no VALID, no READY).
template <class V>
void axil_idle(V& top) {
  top.s_axil_awvalid_i = 0;
  top.s_axil_wvalid_i = 0;
  top.s_axil_bready_i = 0;
  top.s_axil_arvalid_i = 0;
  top.s_axil_rready_i = 0;
}

/// What a top's AXI4-Lite subordinate port drives in this cycle (the hardware-side fields 0) and
/// its interrupt.
template <class V>
SubOut axil_sub(const V& top) {
  SubOut s;
  s.awready = top.s_axil_awready_o;
  s.wready = top.s_axil_wready_o;
  s.bvalid = top.s_axil_bvalid_o;
  s.bresp = top.s_axil_bresp_o;
  s.arready = top.s_axil_arready_o;
  s.rvalid = top.s_axil_rvalid_o;
  s.rdata = top.s_axil_rdata_o;
  s.rresp = top.s_axil_rresp_o;
  s.irq = top.irq_o;
  return s;
}

class AxilMgr {
 public:
  static constexpr uint32_t kItemWords = 4;
  static constexpr uint32_t kRecordWords = 4;

  /// Appends a batch (the previous one is dropped if it was complete).
  void load(const uint32_t* items, size_t n) {
    if (complete()) clear_lists();
    issued_at_load_ = issued_count();
    for (size_t i = 0; i < n; ++i) {
      const uint32_t* w = items + i * kItemWords;
      Txn t{w[0], w[1], w[2]};
      if (w[0] & 1) reads_.push_back(Rd{t});
      else writes_.push_back(Wr{t});
    }
    restart_waits();
  }

  /// Drops every transaction (a reset of the top).
  void reset() {
    clear_lists();
    issued_at_load_ = 0;
    prev_ = Prev{};
  }

  bool all_issued() const { return w_next_ == writes_.size() && aw_next_ == writes_.size() && ar_next_ == reads_.size(); }
  uint64_t issued() const { return issued_count() - issued_at_load_; }
  uint64_t errors() const { return errors_; }
  uint64_t first_error_cycle() const { return first_error_cycle_; }
  const std::string& first_error() const { return first_error_; }

  /// Counts a violation; the first is also printed (the bridge carries only its cycle).
  void error(uint64_t cycle, const std::string& what) {
    if (errors_++ == 0) {
      first_error_cycle_ = cycle;
      first_error_ = what;
      std::fprintf(stderr, "axil_mgr: protocol violation at cycle %llu: %s\n",
                   static_cast<unsigned long long>(cycle), what.c_str());
    }
  }

  /// The manager's outputs in this cycle.
  const MgrOut& drive(bool bready, bool rready) {
    MgrOut& m = out_;
    m.awvalid = aw_next_ < writes_.size() && aw_wait_ == 0;
    m.awaddr = m.awvalid ? writes_[aw_next_].t.addr : 0;
    m.wvalid = w_next_ < writes_.size() && w_wait_ == 0;
    m.wdata = m.wvalid ? writes_[w_next_].t.data : 0;
    m.wstrb = m.wvalid ? (writes_[w_next_].t.ctl >> 4) & 0xf : 0;
    m.arvalid = ar_next_ < reads_.size() && ar_wait_ == 0;
    m.araddr = m.arvalid ? reads_[ar_next_].t.addr : 0;
    m.bready = bready;
    m.rready = rready;
    m.wsel = b_next_ < writes_.size() ? (writes_[b_next_].t.addr >> 2) & 0xff : 0;
    m.rsel = r_next_ < reads_.size() ? (reads_[r_next_].t.addr >> 2) & 0xff : 0;
    return m;
  }

  /// Observes the cycle after eval; appends records to `out`; returns the responses taken.
  uint64_t observe(uint64_t cycle, const SubOut& s, std::vector<uint32_t>& out) {
    const MgrOut& m = out_;
    check(cycle, s);
    uint64_t taken = 0;
    // Interrupt level.
    if (!irq_seen_ || s.irq != last_irq_) {
      push(out, cycle, 2u | uint32_t{s.irq} << 5, 0, static_cast<uint32_t>(cycle), 0);
      irq_seen_ = true;
      last_irq_ = s.irq;
    }
    // B: the first cycle of a response, then its handshake.
    if (s.bvalid) {
      if (b_next_ >= writes_.size() || !writes_[b_next_].requested()) {
        error(cycle, "B without an outstanding write");
      } else {
        Wr& w = writes_[b_next_];
        if (!b_seen_) {
          b_seen_ = true;
          w.first = cycle;
          w.hw_q = s.hw_q;
          w.stb = s.wr_stb;
        }
        if (m.bready) {
          const uint64_t req = w.aw_cycle > w.w_cycle ? w.aw_cycle : w.w_cycle;
          push(out, cycle, 0u | s.bresp << 2 | uint32_t{w.stb} << 4, w.hw_q, static_cast<uint32_t>(w.first),
               static_cast<uint32_t>(req));
          ++b_next_;
          b_seen_ = false;
          ++taken;
        }
      }
    }
    if (s.rvalid) {
      if (r_next_ >= ar_next_) {
        error(cycle, "R without an outstanding read");
      } else {
        Rd& r = reads_[r_next_];
        if (!r_seen_) {
          r_seen_ = true;
          r.first = cycle;
          r.stb = s.rd_stb;
        }
        if (m.rready) {
          push(out, cycle, 1u | s.rresp << 2 | uint32_t{r.stb} << 4, s.rdata, static_cast<uint32_t>(r.ar_cycle),
               static_cast<uint32_t>(r.first));
          ++r_next_;
          r_seen_ = false;
          ++taken;
        }
      }
    }
    // Request handshakes, then the next transaction's wait.
    if (m.awvalid && s.awready) {
      writes_[aw_next_].aw_cycle = cycle;
      writes_[aw_next_].aw_done = true;
      ++aw_next_;
      aw_wait_ = aw_next_ < writes_.size() ? (writes_[aw_next_].t.ctl >> 8) & 0xff : 0;
    } else if (aw_wait_) {
      --aw_wait_;
    }
    if (m.wvalid && s.wready) {
      writes_[w_next_].w_cycle = cycle;
      writes_[w_next_].w_done = true;
      ++w_next_;
      w_wait_ = w_next_ < writes_.size() ? (writes_[w_next_].t.ctl >> 16) & 0xff : 0;
    } else if (w_wait_) {
      --w_wait_;
    }
    if (m.arvalid && s.arready) {
      reads_[ar_next_].ar_cycle = cycle;
      ++ar_next_;
      ar_wait_ = ar_next_ < reads_.size() ? (reads_[ar_next_].t.ctl >> 8) & 0xff : 0;
    } else if (ar_wait_) {
      --ar_wait_;
    }
    return taken;
  }

 private:
  struct Txn {
    uint32_t ctl, addr, data;
  };
  struct Wr {
    Txn t;
    uint64_t aw_cycle = 0, w_cycle = 0, first = 0;
    bool aw_done = false, w_done = false, stb = false;
    uint32_t hw_q = 0;
    bool requested() const { return aw_done && w_done; }
  };
  struct Rd {
    Txn t;
    uint64_t ar_cycle = 0, first = 0;
    bool stb = false;
  };
  // Last cycle's handshake state of each channel, for the VALID-held and payload-stable rules.
  struct Prev {
    bool aw_stall = false, w_stall = false, ar_stall = false, b_stall = false, r_stall = false;
    uint32_t awaddr = 0, wdata = 0, wstrb = 0, araddr = 0, bresp = 0, rdata = 0, rresp = 0;
  };

  void check(uint64_t cycle, const SubOut& s) {
    const MgrOut& m = out_;
    Prev& p = prev_;
    if (p.aw_stall && (!m.awvalid || m.awaddr != p.awaddr)) error(cycle, "AW dropped or changed while stalled");
    if (p.w_stall && (!m.wvalid || m.wdata != p.wdata || m.wstrb != p.wstrb)) error(cycle, "W dropped or changed while stalled");
    if (p.ar_stall && (!m.arvalid || m.araddr != p.araddr)) error(cycle, "AR dropped or changed while stalled");
    if (p.b_stall && (!s.bvalid || s.bresp != p.bresp)) error(cycle, "B dropped or changed while stalled");
    if (p.r_stall && (!s.rvalid || s.rdata != p.rdata || s.rresp != p.rresp)) error(cycle, "R dropped or changed while stalled");
    p.aw_stall = m.awvalid && !s.awready;
    p.w_stall = m.wvalid && !s.wready;
    p.ar_stall = m.arvalid && !s.arready;
    p.b_stall = s.bvalid && !m.bready;
    p.r_stall = s.rvalid && !m.rready;
    p.awaddr = m.awaddr;
    p.wdata = m.wdata;
    p.wstrb = m.wstrb;
    p.araddr = m.araddr;
    p.bresp = s.bresp;
    p.rdata = s.rdata;
    p.rresp = s.rresp;
  }

  static void push(std::vector<uint32_t>& out, uint64_t cycle, uint32_t w0, uint32_t w1, uint32_t w2,
                   uint32_t w3) {
    out.push_back(static_cast<uint32_t>(cycle));
    out.push_back(static_cast<uint32_t>(cycle >> 32));
    out.push_back(w0);
    out.push_back(w1);
    out.push_back(w2);
    out.push_back(w3);
  }

  bool complete() const { return all_issued() && b_next_ == writes_.size() && r_next_ == reads_.size(); }

  uint64_t issued_count() const {
    uint64_t n = ar_next_;
    for (size_t i = 0; i < writes_.size() && i < aw_next_ && i < w_next_; ++i) ++n;
    return n;
  }

  void clear_lists() {
    writes_.clear();
    reads_.clear();
    aw_next_ = w_next_ = b_next_ = ar_next_ = r_next_ = 0;
    b_seen_ = r_seen_ = false;
  }

  void restart_waits() {
    aw_wait_ = aw_next_ < writes_.size() ? (writes_[aw_next_].t.ctl >> 8) & 0xff : 0;
    w_wait_ = w_next_ < writes_.size() ? (writes_[w_next_].t.ctl >> 16) & 0xff : 0;
    ar_wait_ = ar_next_ < reads_.size() ? (reads_[ar_next_].t.ctl >> 8) & 0xff : 0;
  }

  std::vector<Wr> writes_;
  std::vector<Rd> reads_;
  size_t aw_next_ = 0, w_next_ = 0, b_next_ = 0, ar_next_ = 0, r_next_ = 0;
  uint32_t aw_wait_ = 0, w_wait_ = 0, ar_wait_ = 0;
  bool b_seen_ = false, r_seen_ = false;
  bool irq_seen_ = false, last_irq_ = false;
  uint64_t issued_at_load_ = 0;
  uint64_t errors_ = 0, first_error_cycle_ = 0;
  std::string first_error_;
  Prev prev_;
  MgrOut out_;
};

/// What the shims of tops with an AXI4-Lite subordinate port share (AxilShim in tb/axil_shim.h,
/// AccelCtrlShim in tb/accel_ctrl_shim.h) beyond ClockedTop: the manager, the reset of both, and
/// a run's start, clock and counts.
template <class V>
class AxilTopBase : public ClockedTop<V> {
  using C = ClockedTop<V>;

 protected:
  using C::cycle_;
  using C::tick;
  using C::top_;

  AxilTopBase(uint32_t seed, PortWidths widths) : C(seed, widths), seed_(seed) {}

  /// Resets the top and the manager together (transactions in flight are dropped on both sides):
  /// `idle` idles the top's inputs, `settle` drives what it needs before each eval. A subordinate
  /// still driving BVALID or RVALID out of reset is a protocol error.
  template <class Idle, class Settle>
  void reset_with_mgr(uint32_t cycles, Idle idle, Settle settle) {
    top_->rst_ni = 0;
    idle();
    mgr_.reset();
    for (uint32_t i = 0; i < cycles; ++i) {
      settle();
      top_->eval();
      tick();
    }
    top_->rst_ni = 1;
    settle();
    top_->eval();
    if (top_->s_axil_bvalid_o || top_->s_axil_rvalid_o)
      mgr_.error(cycle_, "BVALID or RVALID high out of reset");
  }

  /// A run's start: the transactions loaded; false (a protocol error in `st`) when the item or
  /// record words are not the shim's.
  bool start_run(RunStats& st, const uint32_t* items, size_t n_items, uint32_t in_words,
                 uint32_t out_words, uint32_t record_words) {
    if (in_words != AxilMgr::kItemWords || out_words != record_words) {
      st.protocol_errors = 1;
      return false;
    }
    mgr_.load(items, n_items);
    return true;
  }

  /// A run's counts: `responses` B and R responses, the manager's protocol errors and `extra`
  /// more (the shim's own, the first at `first_extra`).
  void end_run(RunStats& st, uint64_t responses, uint64_t extra = 0, uint64_t first_extra = 0) {
    st.consumed = mgr_.issued();
    st.produced = responses;
    st.protocol_errors = mgr_.errors() + extra;
    st.first_protocol_error_cycle = extra ? first_extra : mgr_.first_error_cycle();
  }

  uint32_t seed_;
  AxilMgr mgr_;
};

}  // namespace cube5
