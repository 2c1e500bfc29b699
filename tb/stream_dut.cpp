// stream_dut.cpp: converts between cxx types and DutCore's plain C++ ones.
#include "stream_dut.h"

#include <algorithm>

#include "axi_mem.h"
#include "win_host.h"

#include "cube5-tb/src/ffi.rs.h"

namespace cube5 {

void StreamDut::reset(uint32_t cycles) { core_->reset(cycles); }

RunResult StreamDut::run(rust::Slice<const uint32_t> items, uint32_t in_words,
                         rust::Slice<const uint8_t> idle, rust::Slice<const uint8_t> stall,
                         uint64_t expect_out, uint64_t max_cycles, rust::Vec<uint32_t>& out,
                         uint32_t out_words) {
  const size_t n_items = in_words ? items.size() / in_words : 0;
  std::vector<uint32_t> collected;
  collected.reserve(std::min<size_t>(n_items, expect_out) * (2 + out_words));
  const RunStats st = core_->run(items.data(), n_items, in_words, idle.data(), idle.size(),
                                 stall.data(), stall.size(), expect_out, max_cycles, collected,
                                 out_words);
  out.reserve(out.size() + collected.size());
  for (uint32_t w : collected) out.push_back(w);
  return RunResult{st.consumed, st.produced, st.cycles, st.protocol_errors,
                   st.first_protocol_error_cycle, st.finished};
}

bool StreamDut::write_config(uint32_t addr, rust::Slice<const uint32_t> data) {
  return core_->write_config(addr, data.data(), static_cast<uint32_t>(data.size()));
}

bool StreamDut::trace_window(rust::Str path, uint64_t from_cycle, uint64_t to_cycle) {
  return core_->trace_window(std::string(path), from_cycle, to_cycle);
}

AxiHost* StreamDut::axi() const { return dynamic_cast<AxiHost*>(core_.get()); }

WinHost* StreamDut::win() const { return dynamic_cast<WinHost*>(core_.get()); }

bool StreamDut::axi_setup(const AxiMemSetup& s) {
  AxiHost* h = axi();
  if (!h) return false;
  AxiMemConfig c;
  c.data_bytes = s.data_bytes;
  c.addr_bits = s.addr_bits;
  c.latency_fixed = s.latency_fixed;
  c.latency_random = s.latency_random;
  c.ar_gap_permille = s.ar_gap_permille;
  c.r_gap_permille = s.r_gap_permille;
  c.bw_num = s.bw_num;
  c.bw_den = s.bw_den;
  c.max_bursts = s.max_bursts;
  c.seed = s.seed;
  c.slverr_lo = s.slverr_lo;
  c.slverr_hi = s.slverr_hi;
  c.aw_gap_permille = s.aw_gap_permille;
  c.w_gap_permille = s.w_gap_permille;
  c.b_gap_permille = s.b_gap_permille;
  c.declared_outstanding = s.declared_outstanding;
  h->axi_mem().configure(c);
  return true;
}

bool StreamDut::axi_load(uint64_t base, rust::Slice<const uint8_t> bytes) {
  AxiHost* h = axi();
  if (!h) return false;
  h->axi_mem().load(base, bytes.data(), bytes.size());
  return true;
}

bool StreamDut::axi_take_ar(rust::Vec<uint64_t>& out) {
  AxiHost* h = axi();
  if (!h) return false;
  for (const ArRecord& r : h->axi_mem().read.take_records()) {
    out.push_back(r.cycle);
    out.push_back(r.addr);
    out.push_back(uint64_t{r.len} | uint64_t{r.size} << 8 | uint64_t{r.burst} << 12 |
                  uint64_t{r.id} << 16);
  }
  return true;
}

AxiCounters StreamDut::axi_counters() const {
  AxiHost* h = axi();
  if (!h) return AxiCounters{};
  const AxiStats& s = h->axi_mem().stats;
  return AxiCounters{s.ar_accepted,      s.r_beats,    s.protocol_errors,
                     s.first_error_cycle, s.dropped_at_reset, s.rready_low,
                     h->axi_mem().read.in_flight(), h->axi_err_flag()};
}

rust::String StreamDut::axi_first_error() const {
  AxiHost* h = axi();
  return rust::String(h ? h->axi_mem().stats.first_error : std::string());
}

bool StreamDut::axi_feed(rust::Slice<const uint32_t> items, uint32_t words,
                         rust::Slice<const uint8_t> idle) {
  AxiHost* h = axi();
  if (!h || words == 0) return false;
  return h->feed_data(items.data(), items.size() / words, words, idle.data(), idle.size());
}

bool StreamDut::axi_take_aw(rust::Vec<uint64_t>& out) {
  AxiHost* h = axi();
  if (!h) return false;
  for (const ArRecord& r : h->axi_mem().write.take_records()) {
    out.push_back(r.cycle);
    out.push_back(r.addr);
    out.push_back(uint64_t{r.len} | uint64_t{r.size} << 8 | uint64_t{r.burst} << 12 |
                  uint64_t{r.id} << 16);
  }
  return true;
}

bool StreamDut::axi_image(rust::Vec<uint8_t>& out) const {
  AxiHost* h = axi();
  if (!h) return false;
  const std::vector<uint8_t>& b = h->axi_mem().image.bytes;
  out.reserve(out.size() + b.size());
  for (uint8_t x : b) out.push_back(x);
  return true;
}

AxiWrCounters StreamDut::axi_wr_counters() const {
  AxiHost* h = axi();
  if (!h) return AxiWrCounters{};
  const AxiStats& s = h->axi_mem().stats;
  return AxiWrCounters{s.aw_accepted, s.w_beats,           s.w_bytes,
                       s.b_responses, s.w_dropped_at_reset, s.bready_low,
                       h->axi_mem().write.in_flight()};
}

bool StreamDut::win_setup(const WinSetup& s) {
  WinHost* h = win();
  if (!h) return false;
  WinConfig c;
  c.seed = s.seed;
  c.park_stall = s.park_stall;
  c.fin_stall = s.fin_stall;
  c.rq_stall = s.rq_stall;
  c.rs_idle = s.rs_idle;
  c.lat_fixed = s.lat_fixed;
  c.lat_random = s.lat_random;
  c.expect_final = s.expect_final;
  h->win_setup(c);
  return true;
}

uint32_t StreamDut::win_take(rust::Vec<uint32_t>& out) {
  WinHost* h = win();
  if (!h) return 0;
  std::vector<uint32_t> rec;
  const uint32_t words = h->win_take(rec);
  out.reserve(out.size() + rec.size());
  for (uint32_t w : rec) out.push_back(w);
  return words;
}

uint64_t StreamDut::win_errors() const {
  WinHost* h = win();
  return h ? h->win_errors() : 0;
}

uint64_t StreamDut::cycle() const { return core_->cycle(); }
uint32_t StreamDut::in_bits() const { return core_->widths().in_bits; }
uint32_t StreamDut::out_bits() const { return core_->widths().out_bits; }

}  // namespace cube5
