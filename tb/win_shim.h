// win_shim.h: DutCore for cube5_frame with the compositing window (Window = 1): the command and
// output streams as StreamShim's (StreamTop in tb/stream_shim.h), and the window's streams played as DRAM in
// the same clock loop: park items (key {Q, R}, coxel) stored by key, restore requests answered in
// order from that store after a random latency, final pixels collected; each output under its own
// random back-pressure, the restore input with random idle cycles. Every item taken on the three
// outputs is recorded for the Rust side (win_take).
#pragma once

#include <deque>
#include <unordered_map>

#include "stream_shim.h"
#include "win_host.h"

namespace cube5 {

template <class V>
class WinShim final : public StreamTop<V>, public WinHost {
  using S = StreamTop<V>;
  using S::cycle_;
  using S::out_watch_;
  using S::top_;
  static constexpr uint32_t kCoxWords = sizeof(V::park_cox_o) > 8 ? sizeof(V::park_cox_o) / 4 : 2;
  static constexpr uint32_t kFinWords = sizeof(V::fin_cox_o) > 8 ? sizeof(V::fin_cox_o) / 4 : 2;

 public:
  static constexpr uint32_t kRecordWords = 4 + kFinWords;

  WinShim(uint32_t seed, PortWidths widths) : S(seed, widths) {
    idle_inputs();
    top_->eval();
  }

  bool write_config(uint32_t addr, const uint32_t* words, uint32_t n_words) override {
    return this->config_write(addr, words, n_words, [this] { idle_inputs(); });
  }

  void reset(uint32_t cycles) override {
    this->reset_stream(cycles, [this] { idle_inputs(); });
    dram_.clear();
    answers_.clear();
    park_held_ = fin_held_ = rq_held_ = false;
  }

  void win_setup(const WinConfig& c) override {
    cfg_ = c;
    rng_ = c.seed | 1;
    finals_ = 0;
  }

  uint32_t win_take(std::vector<uint32_t>& out) override {
    out.insert(out.end(), records_.begin(), records_.end());
    records_.clear();
    return kRecordWords;
  }

  uint64_t win_errors() const override { return errors_; }

  RunStats run(const uint32_t* items, size_t n_items, uint32_t in_words, const uint8_t* idle,
               size_t idle_len, const uint8_t* stall, size_t stall_len, uint64_t expect_out,
               uint64_t max_cycles, std::vector<uint32_t>& out, uint32_t out_words) override {
    RunStats st;
    size_t next = 0;
    while (st.cycles < max_cycles &&
           (next < n_items || st.produced < expect_out || finals_ < cfg_.expect_final)) {
      const auto [offer, take] =
          this->drive_stream(items, n_items, in_words, next, idle, idle_len, stall, stall_len);
      const bool park_take = !chance(cfg_.park_stall);
      const bool fin_take = !chance(cfg_.fin_stall);
      const bool rq_take = !chance(cfg_.rq_stall);
      top_->park_ready_i = park_take;
      top_->fin_ready_i = fin_take;
      top_->rq_ready_i = rq_take;
      const bool rs_offer =
          !answers_.empty() && answers_.front().at <= cycle_ && !chance(cfg_.rs_idle);
      top_->rs_valid_i = rs_offer;
      if (rs_offer) write_port(top_->rs_cox_i, answers_.front().cox.data(), kCoxWords);
      top_->eval();

      // The valid/ready rule on the window's three outputs (the output stream's in end_cycle).
      held(park_held_, top_->park_valid_o, park_take, top_->park_key_o, park_key_, top_->park_cox_o,
           park_cox_);
      held(fin_held_, top_->fin_valid_o, fin_take, top_->fin_key_o, fin_key_, top_->fin_cox_o,
           fin_cox_);
      held(rq_held_, top_->rq_valid_o, rq_take, top_->rq_key_o, rq_key_, top_->rq_key_o, rq_key2_);

      if (top_->park_valid_o && park_take) {
        uint32_t* r = record(kWinPark, top_->park_key_o, 0);
        read_port(top_->park_cox_o, r + 4, kCoxWords);
        dram_[top_->park_key_o].assign(r + 4, r + 4 + kCoxWords);
      }
      if (top_->fin_valid_o && fin_take) {
        uint32_t* r = record(kWinFinal, top_->fin_key_o, top_->fin_mask_o);
        read_port(top_->fin_cox_o, r + 4, kFinWords);
        finals_ += __builtin_popcount(static_cast<uint32_t>(top_->fin_mask_o));
      }
      if (top_->rq_valid_o && rq_take) {
        record(kWinRequest, top_->rq_key_o, 0);
        Answer a;
        a.at = cycle_ + 1 + cfg_.lat_fixed + (cfg_.lat_random ? next_rand() % (cfg_.lat_random + 1) : 0);
        auto it = dram_.find(top_->rq_key_o);
        if (it == dram_.end()) {
          ++errors_;
          a.cox.assign(kCoxWords, 0);
        } else {
          a.cox = it->second;
        }
        answers_.push_back(std::move(a));
      }
      if (rs_offer && top_->rs_ready_o) answers_.pop_front();
      if (!this->end_cycle(st, offer, next, take, out, out_words)) break;
    }
    idle_inputs();
    top_->eval();
    return st;
  }

 private:
  struct Answer {
    uint64_t at = 0;
    std::vector<uint32_t> cox;
  };

  void idle_inputs() {
    top_->in_valid_i = 0;
    top_->out_ready_i = 0;
    top_->cfg_valid_i = 0;
    top_->park_ready_i = 0;
    top_->fin_ready_i = 0;
    top_->rq_ready_i = 0;
    top_->rs_valid_i = 0;
  }

  uint64_t next_rand() {
    rng_ ^= rng_ << 13;
    rng_ ^= rng_ >> 7;
    rng_ ^= rng_ << 17;
    return rng_;
  }

  bool chance(uint32_t permille) { return permille && next_rand() % 1000 < permille; }

  uint32_t* record(uint32_t kind, uint64_t key, uint64_t mask) {
    const size_t at = records_.size();
    records_.resize(at + kRecordWords, 0);
    records_[at] = kind;
    records_[at + 1] = static_cast<uint32_t>(cycle_);
    records_[at + 2] = static_cast<uint32_t>(key);
    records_[at + 3] = static_cast<uint32_t>(mask);
    return records_.data() + at;
  }

  // An output stalled last cycle must still be valid with the same key and data.
  template <class K, class D>
  void held(bool& stalled, bool valid, bool take, const K& key, K& key_q, const D& data, D& data_q) {
    if (stalled && (!valid || key != key_q || !port_equal(data, data_q))) ++errors_;
    stalled = valid && !take;
    if (stalled) {
      key_q = key;
      data_q = data;
    }
  }

  WinConfig cfg_;
  uint64_t rng_ = 1;
  uint64_t finals_ = 0;
  uint64_t errors_ = 0;
  std::vector<uint32_t> records_;
  std::unordered_map<uint64_t, std::vector<uint32_t>> dram_;
  std::deque<Answer> answers_;
  bool park_held_ = false, fin_held_ = false, rq_held_ = false;
  std::remove_reference_t<decltype(V::park_key_o)> park_key_{}, fin_key_{}, rq_key_{}, rq_key2_{};
  std::remove_reference_t<decltype(V::park_cox_o)> park_cox_{};
  std::remove_reference_t<decltype(V::fin_cox_o)> fin_cox_{};
};

}  // namespace cube5
