// clocked_top.h: what the shims of tops with a bus port share (AxiTopBase in tb/axi_shim.h,
// AxilShim in tb/axil_shim.h): the Verilated top in its own context, the clock, the trace window,
// the cycle count. StreamShim (tb/stream_shim.h) keeps its own copy so that the stream tops'
// cached builds stay valid.
#pragma once

#include <memory>
#include <string>

#include "dut_core.h"
#include "verilated.h"
#include "verilated_vcd_c.h"

namespace cube5 {

template <class V>
class ClockedTop : public DutCore {
 public:
  ~ClockedTop() override {
    if (trace_) trace_->close();
    Verilated::threadContextp(ctx_.get());  // see StreamShim's destructor
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
  /// The top in a context seeded from `seed` (Verilator's random initial values), clock low and
  /// reset released; the derived shim idles its own inputs and evals.
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

  // The clock runs only inside run() and reset().
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
};

}  // namespace cube5
