// stream_shim.h: DutCore for any Verilated streaming top V. Included once per variant by the unity
// file that build.rs generates; the clock loop runs here, in C++, so a whole batch costs one FFI call.
#pragma once

#include <cstring>
#include <type_traits>
#include <utility>

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
class StreamShim final : public DutCore {
 public:
  StreamShim(uint32_t seed, PortWidths widths) : widths_(widths) {
    ctx_ = std::make_unique<VerilatedContext>();
    // Uninitialised state comes up random, so a missing reset shows as a mismatch.
    ctx_->randReset(2);
    ctx_->randSeed(static_cast<int>(seed & 0x7fffffff));
    ctx_->traceEverOn(true);
    top_ = std::make_unique<V>(ctx_.get(), "top");
    top_->clk_i = 0;
    top_->rst_ni = 1;
    top_->in_valid_i = 0;
    top_->out_ready_i = 0;
    if constexpr (HasConfigPort<V>::value) top_->cfg_valid_i = 0;
    top_->eval();
  }

  ~StreamShim() override {
    if (trace_) trace_->close();
    // Verilator 5.006 erases a model's scopes through the *thread's* current context, which is
    // whichever model was built last: point it at ours, or the erase locks a dead context's mutex.
    Verilated::threadContextp(ctx_.get());
    top_->final();
    top_.reset();
  }

  void reset(uint32_t cycles) override {
    top_->rst_ni = 0;
    top_->in_valid_i = 0;
    top_->out_ready_i = 0;
    for (uint32_t i = 0; i < cycles; ++i) tick();
    top_->rst_ni = 1;
    top_->eval();
    has_stalled_ = false;
  }

  RunStats run(const uint32_t* items, size_t n_items, uint32_t in_words, const uint8_t* idle,
               size_t idle_len, const uint8_t* stall, size_t stall_len, uint64_t expect_out,
               uint64_t max_cycles, std::vector<uint32_t>& out, uint32_t out_words) override {
    RunStats st;
    size_t next = 0;
    while (st.cycles < max_cycles && (next < n_items || st.produced < expect_out)) {
      const bool offer = next < n_items && !(idle_len && idle[cycle_ % idle_len]);
      const bool take = !(stall_len && stall[cycle_ % stall_len]);
      top_->in_valid_i = offer;
      if (offer) write_port(top_->in_data_i, items + next * in_words, in_words);
      top_->out_ready_i = take;
      top_->eval();

      // Valid/ready rule: an output held back last cycle must still be offered, unchanged.
      if (has_stalled_ && (!top_->out_valid_o || !port_equal(top_->out_data_o, stalled_data_))) {
        if (st.protocol_errors++ == 0) st.first_protocol_error_cycle = cycle_;
      }
      has_stalled_ = top_->out_valid_o && !take;
      if (has_stalled_) stalled_data_ = top_->out_data_o;

      if (offer && top_->in_ready_o) {
        ++next;
        ++st.consumed;
      }
      if (top_->out_valid_o && take) {
        // Each record: the cycle (two words, low first), then the item's words.
        const size_t at = out.size();
        out.resize(at + 2 + out_words);
        out[at] = static_cast<uint32_t>(cycle_);
        out[at + 1] = static_cast<uint32_t>(cycle_ >> 32);
        read_port(top_->out_data_o, out.data() + at + 2, out_words);
        ++st.produced;
      }
      tick();
      ++st.cycles;
      if (ctx_->gotFinish()) {
        st.finished = true;
        break;
      }
    }
    top_->in_valid_i = 0;
    top_->out_ready_i = 0;
    top_->eval();
    return st;
  }

  bool write_config(uint32_t addr, const uint32_t* words, uint32_t n_words) override {
    if constexpr (HasConfigPort<V>::value) {
      top_->in_valid_i = 0;
      top_->out_ready_i = 0;
      top_->cfg_valid_i = 1;
      top_->cfg_addr_i = addr;
      write_port(top_->cfg_data_i, words, n_words);
      tick();
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

 private:
  void dump() {
    if (trace_ && cycle_ >= trace_from_ && cycle_ <= trace_to_) trace_->dump(ctx_->time());
  }

  // One full clock: the falling half first (inputs were set before), then the rising edge.
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

  PortWidths widths_;
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<V> top_;
  std::unique_ptr<VerilatedVcdC> trace_;
  uint64_t trace_from_ = 0, trace_to_ = 0;
  uint64_t cycle_ = 0;
  bool has_stalled_ = false;
  std::remove_reference_t<decltype(V::out_data_o)> stalled_data_{};
};

}  // namespace cube5
