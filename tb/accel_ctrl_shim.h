// accel_ctrl_shim.h: DutCore for the control core cube5_accel_ctrl: an AXI4-Lite manager
// (tb/axil_mgr.h) on its host port, stream sinks with back-pressure on its four command ports, a
// table-port monitor, and the events the core waits for: the frame's done (after the frame command
// that carries `sec_last`) and one writer completion per row command, each after a random delay.
//
// Items are AxilMgr transactions. Records are kRecordWords words after the two cycle words:
//   AxilMgr's B / R / irq records (its four words, then zeros; w0 bit 31 clear), or, w0 bit 31 set,
//   w0 = 1 << 31 | kind | port << 4 | flag << 8:
//     kind 0: a command handshake on `port` (0 fetch, 1 section buffer, 2 frame, 3 writer),
//             w1.. the payload, LSB first;
//     kind 1: the frame's done driven in this cycle, flag = error;
//     kind 2: a writer completion driven in this cycle, flag = resp;
//     kind 3: a table-port write, w1 = index | table << 16, w2 = data;
//     kind 4: `drained_i` driven in this cycle (the answer to `flush_o` after a random delay: the
//             data path's units reset, so pending completions and the frame's done are dropped).
// `stall` back-pressures B and R (as AxilShim) and each command port at its own offset; `idle` is
// unused. write_config sets the environment's knobs (kKnob*). With no items, run() runs
// `max_cycles` cycles (the host idle).
#pragma once

#include <deque>
#include <type_traits>

#include "axil_mgr.h"
#include "stream_shim.h"

namespace cube5 {

template <class V>
class AccelCtrlShim final : public AxilTopBase<V> {
  using B = AxilTopBase<V>;
  using B::cycle_;
  using B::mgr_;
  using B::seed_;
  using B::top_;

 public:
  static constexpr uint32_t kRecordWords = 6;
  /// Knobs (write_config address): the longest extra delay of a completion after its command and
  /// of the frame's done after its last section; the error flag the frame's done carries; the
  /// row (from 1, counted from the frame's first section command; 0 none) whose completion answers
  /// SLVERR; the bit of the frame command that is `sec_last`; the longest extra delay of
  /// `drained_i` after `flush_o` rises.
  static constexpr uint32_t kKnobCplDelay = 0, kKnobDoneDelay = 1, kKnobFrameErr = 2,
                            kKnobErrRow = 3, kKnobLastBit = 4, kKnobDrainDelay = 5;

  AccelCtrlShim(uint32_t seed, PortWidths widths) : B(seed, widths) {
    idle_inputs();
    top_->eval();
  }

  bool write_config(uint32_t addr, const uint32_t* words, uint32_t n) override {
    if (n < 1 || addr > kKnobDrainDelay) return false;
    knob_[addr] = words[0];
    return true;
  }

  void reset(uint32_t cycles) override {
    cpl_.clear();
    done_at_ = kNever;
    drain_at_ = kNever;
    for (auto& h : held_) h.valid = false;
    this->reset_with_mgr(cycles, [this] { idle_inputs(); }, [] {});
  }

  RunStats run(const uint32_t* items, size_t n_items, uint32_t in_words, const uint8_t*, size_t,
               const uint8_t* stall, size_t stall_len, uint64_t expect_out, uint64_t max_cycles,
               std::vector<uint32_t>& out, uint32_t out_words) override {
    RunStats st;
    if (!this->start_run(st, items, n_items, in_words, out_words, kRecordWords)) return st;
    uint64_t responses = 0;
    auto stalled = [&](uint64_t off) { return stall_len && stall[(cycle_ + off) % stall_len]; };
    while (st.cycles < max_cycles && (n_items == 0 || !mgr_.all_issued() || responses < expect_out)) {
      axil_drive(*top_, mgr_.drive(!stalled(0), !stalled(2053)));
      top_->fetch_cmd_ready_i = !stalled(17);
      top_->sbuf_cmd_ready_i = !stalled(101);
      top_->frame_cmd_ready_i = !stalled(409);
      top_->wr_cmd_ready_i = !stalled(1013);
      // Events due in this cycle.
      const bool done = done_at_ <= cycle_;
      top_->frame_done_valid_i = done;
      top_->frame_done_error_i = done && knob_[kKnobFrameErr] != 0;
      const bool cpl = !cpl_.empty() && cpl_.front().due <= cycle_;
      top_->wr_cpl_valid_i = cpl;
      top_->wr_cpl_resp_i = cpl ? cpl_.front().resp : 0;
      const bool drained = drain_at_ <= cycle_;
      top_->drained_i = drained;
      top_->eval();
      const SubOut s = axil_sub(*top_);
      tmp_.clear();
      responses += mgr_.observe(cycle_, s, tmp_);
      for (size_t i = 0; i + 2 + AxilMgr::kRecordWords <= tmp_.size(); i += 2 + AxilMgr::kRecordWords) {
        out.insert(out.end(), tmp_.begin() + i, tmp_.begin() + i + 2 + AxilMgr::kRecordWords);
        for (uint32_t k = AxilMgr::kRecordWords; k < kRecordWords; ++k) out.push_back(0);
      }
      if (done) {
        record(out, 1, 0, top_->frame_done_error_i, nullptr);
        done_at_ = kNever;
      }
      if (cpl) {
        record(out, 2, 0, cpl_.front().resp, nullptr);
        cpl_.pop_front();
      }
      port(out, 0, top_->fetch_cmd_valid_o, top_->fetch_cmd_ready_i, top_->fetch_cmd_data_o);
      port(out, 1, top_->sbuf_cmd_valid_o, top_->sbuf_cmd_ready_i, top_->sbuf_cmd_data_o);
      const bool frame_fire = port(out, 2, top_->frame_cmd_valid_o, top_->frame_cmd_ready_i, top_->frame_cmd_data_o);
      const bool wr_fire = port(out, 3, top_->wr_cmd_valid_o, top_->wr_cmd_ready_i, top_->wr_cmd_data_o);
      if (frame_fire) {
        uint32_t w[kRecordWords - 1];
        words_of(top_->frame_cmd_data_o, w);
        const uint32_t lb = knob_[kKnobLastBit];
        const bool first = lb > 0 && ((w[(lb - 1) / 32] >> ((lb - 1) % 32)) & 1);
        const bool last = lb > 0 && lb / 32 < kRecordWords - 1 && ((w[lb / 32] >> (lb % 32)) & 1);
        if (first) rows_ = 0;
        if (last) done_at_ = cycle_ + 1 + rand(1) % (knob_[kKnobDoneDelay] + 1);
      }
      if (wr_fire) {
        ++rows_;
        const uint64_t due = cycle_ + 1 + rand(2) % (knob_[kKnobCplDelay] + 1);
        const uint64_t prev = cpl_.empty() ? 0 : cpl_.back().due + 1;
        cpl_.push_back(Cpl{due > prev ? due : prev, rows_ == knob_[kKnobErrRow] ? 2u : 0u});
      }
      if (drained) {
        record(out, 4, 0, 0, nullptr);
        drain_at_ = kNever;
        done_at_ = kNever;
        cpl_.clear();
        for (auto& h : held_) h.valid = false;
      } else if (top_->flush_o && drain_at_ == kNever) {
        drain_at_ = cycle_ + 1 + rand(3) % (knob_[kKnobDrainDelay] + 1);
      }
      if (top_->table_valid_o) {
        uint32_t w[2] = {static_cast<uint32_t>(top_->table_index_o) | static_cast<uint32_t>(top_->table_id_o) << 16,
                         static_cast<uint32_t>(top_->table_data_o)};
        record(out, 3, 0, 0, w, 2);
      }
      if (!this->clock_cycle(st)) break;
    }
    this->end_run(st, responses, port_errors_, first_port_error_);
    idle_inputs();
    top_->eval();
    return st;
  }

 private:
  static constexpr uint64_t kNever = ~0ull;

  struct Cpl {
    uint64_t due;
    uint32_t resp;
  };
  struct Held {
    bool valid = false;
    uint32_t w[kRecordWords - 1] = {};
  };

  template <class T>
  static void words_of(const T& v, uint32_t* w) {
    for (uint32_t i = 0; i < kRecordWords - 1; ++i) w[i] = 0;
    if constexpr (std::is_integral_v<T>) {
      const uint64_t x = v;
      w[0] = static_cast<uint32_t>(x);
      w[1] = static_cast<uint32_t>(x >> 32);
    } else {
      constexpr size_t n = sizeof(T) / sizeof(EData);
      for (size_t i = 0; i < n && i < kRecordWords - 1; ++i) w[i] = v.at(i);
    }
  }

  // One command port this cycle: the stream rule (a stalled command holds its valid and data),
  // and a record on a handshake. Returns whether it fired.
  template <class T>
  bool port(std::vector<uint32_t>& out, uint32_t p, bool valid, bool ready, const T& data) {
    uint32_t w[kRecordWords - 1];
    words_of(data, w);
    Held& h = held_[p];
    if (h.valid) {
      bool same = valid;
      for (uint32_t i = 0; i < kRecordWords - 1; ++i) same = same && w[i] == h.w[i];
      if (!same) {
        if (!port_errors_) {
          first_port_error_ = cycle_;
          std::fprintf(stderr, "accel_ctrl_shim: cycle %llu: command port %u dropped or changed a stalled command\n",
                       static_cast<unsigned long long>(cycle_), p);
        }
        ++port_errors_;
      }
    }
    h.valid = valid && !ready;
    for (uint32_t i = 0; i < kRecordWords - 1; ++i) h.w[i] = w[i];
    if (valid && ready) {
      record(out, 0, p, 0, w, kRecordWords - 1);
      return true;
    }
    return false;
  }

  void record(std::vector<uint32_t>& out, uint32_t kind, uint32_t p, uint32_t flag, const uint32_t* w,
              uint32_t n = 0) {
    out.push_back(static_cast<uint32_t>(cycle_));
    out.push_back(static_cast<uint32_t>(cycle_ >> 32));
    out.push_back(1u << 31 | kind | p << 4 | flag << 8);
    for (uint32_t i = 0; i < kRecordWords - 1; ++i) out.push_back(i < n ? w[i] : 0);
  }

  uint64_t rand(uint64_t salt) const { return axil_hw(seed_ ^ static_cast<uint32_t>(salt * 0x9e3779b9u), cycle_); }

  void idle_inputs() {
    axil_idle(*top_);
    top_->fetch_cmd_ready_i = 0;
    top_->sbuf_cmd_ready_i = 0;
    top_->frame_cmd_ready_i = 0;
    top_->wr_cmd_ready_i = 0;
    top_->frame_done_valid_i = 0;
    top_->frame_done_error_i = 0;
    top_->wr_cpl_valid_i = 0;
    top_->wr_cpl_resp_i = 0;
    top_->drained_i = 0;
  }

  std::vector<uint32_t> tmp_;
  std::deque<Cpl> cpl_;
  uint64_t done_at_ = kNever;
  uint64_t drain_at_ = kNever;
  uint32_t rows_ = 0;
  uint32_t knob_[kKnobDrainDelay + 1] = {0, 0, 0, 0, 0, 0};
  Held held_[4];
  uint64_t port_errors_ = 0, first_port_error_ = 0;
};

}  // namespace cube5
