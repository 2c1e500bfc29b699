// stream_shim.h: what every shim shares, and DutCore for a plain streaming top V (StreamShim).
// Included once per variant by the unity file that build.rs generates; the clock loop runs here, in
// C++, so a whole batch costs one FFI call. The shared pieces live in this header because it enters
// every variant's build stamp (tb-rs/build.rs), so a change to them rebuilds every top that uses
// them:
//   port helpers: write_port, read_port, port_equal, HasConfigPort;
//   ClockedTop<V>: the Verilated top in its own context, the clock, the trace window, the cycle
//     count (AxilTopBase in tb/axil_mgr.h, AccelShim in tb/accel_shim.h, StreamTop);
//   OutWatch<V>: the output stream's valid/ready rule and the record of each output taken;
//   StreamTop<V>: ClockedTop with the command and output streams (in_*, out_*, optional cfg_*)
//     driven and watched (StreamShim here, AxiTopBase in tb/axi_shim.h, WinShim in tb/win_shim.h).
#pragma once

#include <cstring>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "dut_core.h"
#include "verilated.h"
#include "verilated_vcd_c.h"

namespace cube5 {

// Ports up to 64 bits are plain integers; wider ones are VlWide<N> word arrays.
template <typename T>
inline void write_port(T& port, const uint32_t* words, uint32_t n_words) {
  if constexpr (std::is_integral_v<T>) {
    uint64_t v = words[0];
    if (sizeof(T) > 4 && n_words > 1) v |= static_cast<uint64_t>(words[1]) << 32;
    port = static_cast<T>(v);
  } else {
    for (size_t i = 0; i < sizeof(port.m_storage) / sizeof(port.m_storage[0]); ++i)
      port.m_storage[i] = i < n_words ? words[i] : 0;
  }
}

template <typename T>
inline void read_port(const T& port, uint32_t* words, uint32_t n_words) {
  if constexpr (std::is_integral_v<T>) {
    const uint64_t v = static_cast<uint64_t>(port);
    words[0] = static_cast<uint32_t>(v);
    if (n_words > 1) words[1] = static_cast<uint32_t>(v >> 32);
    for (uint32_t i = 2; i < n_words; ++i) words[i] = 0;
  } else {
    const size_t n = sizeof(port.m_storage) / sizeof(port.m_storage[0]);
    for (uint32_t i = 0; i < n_words; ++i) words[i] = i < n ? port.m_storage[i] : 0;
  }
}

template <typename T>
inline bool port_equal(const T& a, const T& b) {
  if constexpr (std::is_integral_v<T>) {
    return a == b;
  } else {
    return std::memcmp(a.m_storage, b.m_storage, sizeof(a.m_storage)) == 0;
  }
}

// Detects the optional configuration port (cfg_valid_i, cfg_addr_i, cfg_data_i).
template <class V, class = void>
struct HasConfigPort : std::false_type {};
template <class V>
struct HasConfigPort<V, std::void_t<decltype(std::declval<V&>().cfg_valid_i),
                                    decltype(std::declval<V&>().cfg_addr_i),
                                    decltype(std::declval<V&>().cfg_data_i)>> : std::true_type {};

template <class V>
class ClockedTop : public DutCore {
 public:
  ~ClockedTop() override {
    if (trace_) trace_->close();
    // Verilator 5.006 erases a model's scopes through the *thread's* current context, which is
    // whichever model was built last: point it at ours, or the erase locks a dead context's mutex.
    Verilated::threadContextp(ctx_.get());
    top_->final();
    top_.reset();
  }

  bool write_config(uint32_t, const uint32_t*, uint32_t) override { return false; }

  bool trace_window(const std::string& path, uint64_t from_cycle, uint64_t to_cycle) override {
    if (trace_) trace_->close();
    trace_ = std::make_unique<VerilatedVcdC>();
    top_->trace(trace_.get(), 99);
    trace_->open(path.c_str());
    trace_from_ = from_cycle;
    trace_to_ = to_cycle;
    return trace_->isOpen();
  }

  uint64_t cycle() const override { return cycle_; }
  PortWidths widths() const override { return widths_; }

 protected:
  /// The top in a context seeded from `seed` (Verilator's random initial values, so a missing
  /// reset shows as a mismatch), clock low and reset released; the derived shim idles its own
  /// inputs and evals.
  ClockedTop(uint32_t seed, PortWidths widths) : widths_(widths) {
    ctx_ = std::make_unique<VerilatedContext>();
    ctx_->randReset(2);
    ctx_->randSeed(static_cast<int>(seed & 0x7fffffff));
    ctx_->traceEverOn(true);
    top_ = std::make_unique<V>(ctx_.get(), "top");
    top_->clk_i = 0;
    top_->rst_ni = 1;
  }

  void dump() {
    if (trace_ && cycle_ >= trace_from_ && cycle_ <= trace_to_) trace_->dump(ctx_->time());
  }

  // One full clock: the falling half first (inputs were set before), then the rising edge. The
  // clock runs only inside run() and reset().
  void tick() {
    top_->clk_i = 0;
    top_->eval();
    dump();
    ctx_->timeInc(1);
    top_->clk_i = 1;
    top_->eval();
    dump();
    ctx_->timeInc(1);
    top_->clk_i = 0;
    top_->eval();
    ++cycle_;
  }

  /// The clock of a run's cycle, counted in `st`. False once the top has called $finish.
  bool clock_cycle(RunStats& st) {
    tick();
    ++st.cycles;
    if (ctx_->gotFinish()) {
      st.finished = true;
      return false;
    }
    return true;
  }

  PortWidths widths_;
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<V> top_;
  std::unique_ptr<VerilatedVcdC> trace_;
  uint64_t trace_from_ = 0, trace_to_ = 0;
  uint64_t cycle_ = 0;
};

template <class V>
class OutWatch {
 public:
  /// After eval, in clock `cycle`: an output held back last cycle must still be offered,
  /// unchanged (else a protocol error in `st`); the output taken this cycle (if `take`) is appended
  /// to `out` as DutCore::run describes (the cycle, two words, low first, then the item's words).
  void watch(const V& top, uint64_t cycle, bool take, RunStats& st, std::vector<uint32_t>& out,
             uint32_t out_words) {
    if (has_stalled_ && (!top.out_valid_o || !port_equal(top.out_data_o, stalled_data_))) {
      if (st.protocol_errors++ == 0) st.first_protocol_error_cycle = cycle;
    }
    has_stalled_ = top.out_valid_o && !take;
    if (has_stalled_) stalled_data_ = top.out_data_o;
    if (top.out_valid_o && take) {
      const size_t at = out.size();
      out.resize(at + 2 + out_words);
      out[at] = static_cast<uint32_t>(cycle);
      out[at + 1] = static_cast<uint32_t>(cycle >> 32);
      read_port(top.out_data_o, out.data() + at + 2, out_words);
      ++st.produced;
    }
  }

  /// Reset: nothing is held back.
  void clear() { has_stalled_ = false; }

 private:
  bool has_stalled_ = false;
  std::remove_reference_t<decltype(V::out_data_o)> stalled_data_{};
};

/// A top with the command stream (in_valid_i, in_ready_o, in_data_i), the output stream
/// (out_valid_o, out_ready_i, out_data_o) and maybe the configuration port: the pieces of a run
/// that StreamShim, AxiTopBase and WinShim share. The derived shim idles its own inputs and evals.
template <class V>
class StreamTop : public ClockedTop<V> {
  using C = ClockedTop<V>;

 protected:
  using C::cycle_;
  using C::top_;

  StreamTop(uint32_t seed, PortWidths widths) : C(seed, widths) {
    top_->in_valid_i = 0;
    top_->out_ready_i = 0;
    if constexpr (HasConfigPort<V>::value) top_->cfg_valid_i = 0;
  }

  /// One write on the optional configuration port: the stream idle and `idle` idling the shim's
  /// other inputs in that clock. False when the top has no configuration port.
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
      (void)idle;
      return false;
    }
  }

  /// `cycles` clocks of reset with the stream idle and `idle` idling (and resetting) the shim's
  /// own side; then reset released and evaluated, nothing held back on the output.
  template <class Idle>
  void reset_stream(uint32_t cycles, Idle idle) {
    top_->rst_ni = 0;
    top_->in_valid_i = 0;
    top_->out_ready_i = 0;
    idle();
    for (uint32_t i = 0; i < cycles; ++i) this->tick();
    top_->rst_ni = 1;
    top_->eval();
    out_watch_.clear();
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

  /// After eval (and whatever else the shim observes): the command taken (if `offered`), the
  /// output watched, the clock ticked. False once the top has called $finish.
  bool end_cycle(RunStats& st, bool offered, size_t& next, bool take, std::vector<uint32_t>& out,
                 uint32_t out_words) {
    if (offered && top_->in_ready_o) {
      ++next;
      ++st.consumed;
    }
    out_watch_.watch(*top_, cycle_, take, st, out, out_words);
    return this->clock_cycle(st);
  }

  /// After a run: the stream's inputs idle.
  void idle_stream() {
    top_->in_valid_i = 0;
    top_->out_ready_i = 0;
    top_->eval();
  }

  OutWatch<V> out_watch_;
};

template <class V>
class StreamShim final : public StreamTop<V> {
  using S = StreamTop<V>;
  using S::top_;

 public:
  StreamShim(uint32_t seed, PortWidths widths) : S(seed, widths) { top_->eval(); }

  void reset(uint32_t cycles) override {
    this->reset_stream(cycles, [] {});
  }

  RunStats run(const uint32_t* items, size_t n_items, uint32_t in_words, const uint8_t* idle,
               size_t idle_len, const uint8_t* stall, size_t stall_len, uint64_t expect_out,
               uint64_t max_cycles, std::vector<uint32_t>& out, uint32_t out_words) override {
    RunStats st;
    size_t next = 0;
    while (st.cycles < max_cycles && (next < n_items || st.produced < expect_out)) {
      const auto [offer, take] =
          this->drive_stream(items, n_items, in_words, next, idle, idle_len, stall, stall_len);
      top_->eval();
      if (!this->end_cycle(st, offer, next, take, out, out_words)) break;
    }
    this->idle_stream();
    return st;
  }

  bool write_config(uint32_t addr, const uint32_t* words, uint32_t n_words) override {
    return this->config_write(addr, words, n_words, [] {});
  }
};

}  // namespace cube5
