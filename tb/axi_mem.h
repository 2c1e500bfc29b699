// axi_mem.h: an AXI4 memory subordinate for the C++ clock loop, reusable by any top with an AXI4
// manager port (docs/architecture.md, "The AXI4 memory subordinate"). Plain C++ (no Verilator or
// cxx types), so a shim drives it with whatever port types its top has:
//
//   each cycle, before eval:  const auto& o = mem.read.drive(cycle);   // ARREADY, R beat
//                             ...set the top's inputs from o, eval...
//   after eval:               mem.read.observe(cycle, ar_in, rready);  // handshakes + checks
//
// The read port answers from a byte-addressed image (one region, loaded from Rust): a beat wholly
// inside the image is OKAY with the image's bytes (SLVERR with zero data inside the configured
// error window), any other beat DECERR with zero data. Bursts return in the order they were
// accepted, each no earlier than `latency_fixed + U(0..latency_random)` cycles after its AR
// handshake; ARREADY and RVALID have random gaps, and a token bucket limits R to `bw_num / bw_den`
// bytes per cycle (a DDR-like channel). A protocol checker watches what the manager drives (AR
// valid held until ready, payload stable while stalled, burst type/size/alignment legal, no 4 KB
// crossing, address inside the address space) and what this side generates (RLAST exactly at the
// burst end, R held until ready): the first violation is kept, with its cycle, for the Rust side
// to report. Write channels (AW, W, B) will be a second member, `write`, beside `read`, sharing
// the image.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <string>
#include <vector>

namespace cube5 {

/// How the subordinate behaves (mirrors `AxiMemSetup` in tb-rs/src/ffi.rs).
struct AxiMemConfig {
  uint32_t data_bytes = 8;       ///< bytes per beat (the bus width)
  uint32_t addr_bits = 32;       ///< the manager's address width
  uint32_t latency_fixed = 10;   ///< cycles from the AR handshake to the first R beat, at least
  uint32_t latency_random = 0;   ///< plus U(0 .. latency_random)
  uint32_t ar_gap_permille = 0;  ///< chance that ARREADY is low in a cycle
  uint32_t r_gap_permille = 0;   ///< chance that a new R beat is held back in a cycle
  uint32_t bw_num = 0;           ///< bandwidth limit, bytes per bw_den cycles (0: none)
  uint32_t bw_den = 1;
  uint32_t max_bursts = 64;      ///< ARREADY is low while this many bursts are in flight
  uint64_t seed = 1;
  uint64_t slverr_lo = 0, slverr_hi = 0;  ///< beats in [lo, hi) answer SLVERR
};

/// One accepted AR handshake.
struct ArRecord {
  uint64_t cycle;
  uint64_t addr;
  uint32_t len;  ///< ARLEN (beats - 1)
  uint32_t size;
  uint32_t burst;
  uint32_t id;
};

/// What the manager drives on AR in a cycle (sampled after eval).
struct ArIn {
  bool valid;
  uint64_t addr;
  uint32_t len, size, burst, id;
};

/// What the subordinate drives in a cycle.
struct ReadOut {
  bool arready = false;
  bool rvalid = false;
  std::vector<uint8_t> rdata;
  uint32_t rresp = 0;
  bool rlast = false;
  uint32_t rid = 0;
};

/// Counters and the first protocol violation.
struct AxiStats {
  uint64_t ar_accepted = 0;
  uint64_t r_beats = 0;
  uint64_t protocol_errors = 0;
  uint64_t first_error_cycle = 0;
  std::string first_error;
  uint64_t dropped_at_reset = 0;  ///< bursts in flight when a reset cleared them
  uint64_t rready_low = 0;        ///< cycles RVALID was high and RREADY low (bus held by the manager)
};

/// The byte image the ports read (and, later, write).
struct AxiImage {
  uint64_t base = 0;
  std::vector<uint8_t> bytes;
};

class AxiReadPort {
 public:
  AxiReadPort(const AxiImage& image, AxiMemConfig& cfg, AxiStats& stats)
      : image_(image), cfg_(cfg), st_(stats) {}

  void restart() {
    rng_ = cfg_.seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull;
    tokens_ = 0;
  }

  /// Reset: every burst in flight is dropped, nothing is held.
  void reset() {
    st_.dropped_at_reset += bursts_.size();
    bursts_.clear();
    out_.rvalid = false;
    out_.arready = false;
    ar_stalled_ = false;
    tokens_ = 0;
  }

  /// Bursts accepted whose last beat has not been taken.
  size_t in_flight() const { return bursts_.size(); }

  /// This cycle's ARREADY and R beat (a beat offered and not taken is offered again unchanged).
  const ReadOut& drive(uint64_t cycle) {
    out_.arready = bursts_.size() < cfg_.max_bursts && !chance(cfg_.ar_gap_permille);
    if (cfg_.bw_num) {
      const uint64_t cost = uint64_t{cfg_.data_bytes} * cfg_.bw_den;
      tokens_ = std::min<uint64_t>(tokens_ + cfg_.bw_num, 2 * std::max<uint64_t>(cost, cfg_.bw_num));
    }
    if (!out_.rvalid && !bursts_.empty() && cycle >= bursts_.front().ready_at &&
        !chance(cfg_.r_gap_permille)) {
      const uint64_t cost = uint64_t{cfg_.data_bytes} * cfg_.bw_den;
      if (!cfg_.bw_num || tokens_ >= cost) {
        if (cfg_.bw_num) tokens_ -= cost;
        Burst& b = bursts_.front();
        const uint64_t addr = b.addr + uint64_t{b.done} * cfg_.data_bytes;
        beat(addr, out_);
        out_.rlast = b.done == b.len;
        out_.rid = b.id;
        out_.rvalid = true;
      }
    }
    return out_;
  }

  /// The manager's AR and RREADY this cycle, after eval: handshakes and protocol checks.
  void observe(uint64_t cycle, const ArIn& ar, bool rready) {
    // AR: valid held until ready, payload stable while stalled (AXI4 A3.2.1).
    if (ar_stalled_) {
      if (!ar.valid)
        fail(cycle, "ARVALID dropped before ARREADY");
      else if (ar.addr != ar_last_.addr || ar.len != ar_last_.len || ar.size != ar_last_.size ||
               ar.burst != ar_last_.burst || ar.id != ar_last_.id)
        fail(cycle, "AR payload changed while ARVALID && !ARREADY");
    }
    if (ar.valid) check_ar(cycle, ar);
    ar_stalled_ = ar.valid && !out_.arready;
    ar_last_ = ar;
    if (ar.valid && out_.arready) {
      const uint32_t extra =
          cfg_.latency_random ? static_cast<uint32_t>(next() % (cfg_.latency_random + 1)) : 0;
      bursts_.push_back(Burst{ar.addr, ar.len, 0, ar.id, cycle + cfg_.latency_fixed + extra});
      records_.push_back(ArRecord{cycle, ar.addr, ar.len, ar.size, ar.burst, ar.id});
      ++st_.ar_accepted;
    }
    // R: a beat offered stays until taken; RLAST exactly on the burst's last beat.
    if (out_.rvalid && !rready) ++st_.rready_low;
    if (out_.rvalid && rready) {
      Burst& b = bursts_.front();
      if (out_.rlast != (b.done == b.len)) fail(cycle, "RLAST not on the burst's last beat");
      ++st_.r_beats;
      out_.rvalid = false;
      if (b.done++ == b.len) bursts_.pop_front();
    }
  }

  /// The AR handshakes since the last call.
  std::vector<ArRecord> take_records() { return std::move(records_); }

 private:
  struct Burst {
    uint64_t addr;
    uint32_t len;   // ARLEN
    uint32_t done;  // beats taken
    uint32_t id;
    uint64_t ready_at;
  };

  void check_ar(uint64_t cycle, const ArIn& ar) {
    const uint64_t bytes = uint64_t{1} << ar.size;
    const uint64_t span = (uint64_t{ar.len} + 1) * bytes;
    if (ar.burst != 1)
      fail(cycle, "ARBURST " + std::to_string(ar.burst) + " (this memory answers INCR only)");
    else if (bytes != cfg_.data_bytes)
      fail(cycle, "ARSIZE " + std::to_string(ar.size) + " is not the bus width");
    else if (ar.addr % bytes)
      fail(cycle, "ARADDR " + hex(ar.addr) + " not aligned to ARSIZE");
    else if (ar.len > 255)
      fail(cycle, "ARLEN above 255");
    else if ((ar.addr & 4095) + span > 4096)
      fail(cycle, "burst at " + hex(ar.addr) + " of " + std::to_string(ar.len + 1) +
                      " beats crosses a 4 KB boundary");
    else if (cfg_.addr_bits < 64 && ar.addr + span > (uint64_t{1} << cfg_.addr_bits))
      fail(cycle, "burst at " + hex(ar.addr) + " runs past the address space");
  }

  void beat(uint64_t addr, ReadOut& o) const {
    o.rdata.assign(cfg_.data_bytes, 0);
    const uint64_t n = cfg_.data_bytes;
    if (addr < image_.base || addr - image_.base + n > image_.bytes.size()) {
      o.rresp = 3;  // DECERR: no memory there
    } else if (addr >= cfg_.slverr_lo && addr < cfg_.slverr_hi) {
      o.rresp = 2;  // SLVERR
    } else {
      o.rresp = 0;
      for (uint64_t i = 0; i < n; ++i) o.rdata[i] = image_.bytes[addr - image_.base + i];
    }
  }

  void fail(uint64_t cycle, const std::string& what) {
    if (st_.protocol_errors++ == 0) {
      st_.first_error_cycle = cycle;
      st_.first_error = what;
    }
  }

  static std::string hex(uint64_t v) {
    char buf[24];
    snprintf(buf, sizeof buf, "0x%llx", static_cast<unsigned long long>(v));
    return buf;
  }

  bool chance(uint32_t permille) { return permille && next() % 1000 < permille; }

  uint64_t next() {  // splitmix64
    uint64_t z = (rng_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }

  const AxiImage& image_;
  AxiMemConfig& cfg_;
  AxiStats& st_;
  std::deque<Burst> bursts_;
  ReadOut out_;
  bool ar_stalled_ = false;
  ArIn ar_last_{};
  std::vector<ArRecord> records_;
  uint64_t rng_ = 1;
  uint64_t tokens_ = 0;
};

/// The subordinate: one image, its configuration and counters, and the channels.
class AxiMem {
 public:
  AxiMem() : read(image, cfg, stats) { read.restart(); }

  void configure(const AxiMemConfig& c) {
    cfg = c;
    if (cfg.bw_den == 0) cfg.bw_den = 1;
    read.restart();
  }
  void load(uint64_t base, const uint8_t* data, size_t n) {
    image.base = base;
    image.bytes.assign(data, data + n);
  }
  void reset() { read.reset(); }

  AxiImage image;
  AxiMemConfig cfg;
  AxiStats stats;
  AxiReadPort read;
};

/// What a shim with an AXI port offers the Rust side (found by dynamic_cast from a DutCore).
class AxiHost {
 public:
  virtual ~AxiHost() = default;
  virtual AxiMem& axi_mem() = 0;
  /// The top's sticky error output (err_o), or false if it has none.
  virtual bool axi_err_flag() const = 0;
};

}  // namespace cube5
