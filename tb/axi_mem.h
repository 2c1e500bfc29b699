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
// to report. The write port (`write`, beside `read`, sharing the image and the bandwidth) takes AW
// and W and answers B; see AxiWritePort.
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
  uint32_t aw_gap_permille = 0;  ///< chance that AWREADY is low in a cycle
  uint32_t w_gap_permille = 0;   ///< chance that WREADY is low in a cycle
  uint32_t b_gap_permille = 0;   ///< chance that a due B response is held back in a cycle
  uint32_t declared_outstanding = 0;  ///< the manager's declared limit of bursts in flight, per
                                      ///< direction (0: not checked)
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
  uint64_t aw_accepted = 0;
  uint64_t w_beats = 0;
  uint64_t w_bytes = 0;           ///< strobed bytes accepted on W (written or refused with an error)
  uint64_t b_responses = 0;
  uint64_t w_dropped_at_reset = 0;  ///< write bursts outstanding when a reset cleared them

  /// Counts a protocol violation in clock `cycle`, keeping the first one's cycle and text.
  void violation(uint64_t cycle, const std::string& what) {
    if (protocol_errors++ == 0) {
      first_error_cycle = cycle;
      first_error = what;
    }
  }
  uint64_t bready_low = 0;        ///< cycles BVALID was high and BREADY low
};

/// The DDR-like channel: a token bucket of `bw_num / bw_den` bytes per cycle that reads and writes
/// share (0: unlimited). Refilled once per cycle by whichever port asks first; the read port is
/// served before the write port in a cycle.
struct AxiBandwidth {
  uint64_t tokens = 0;
  uint64_t refilled_at = ~uint64_t{0};
  void reset() {
    tokens = 0;
    refilled_at = ~uint64_t{0};
  }
  void refill(const AxiMemConfig& cfg, uint64_t cycle) {
    if (!cfg.bw_num || refilled_at == cycle) return;
    refilled_at = cycle;
    const uint64_t cost = uint64_t{cfg.data_bytes} * cfg.bw_den;
    tokens = std::min<uint64_t>(tokens + cfg.bw_num, 2 * std::max<uint64_t>(cost, cfg.bw_num));
  }
  /// Whether a beat may pass now (tokens are taken by `take`).
  bool allows(const AxiMemConfig& cfg) const {
    return !cfg.bw_num || tokens >= uint64_t{cfg.data_bytes} * cfg.bw_den;
  }
  void take(const AxiMemConfig& cfg) {
    if (cfg.bw_num) tokens -= uint64_t{cfg.data_bytes} * cfg.bw_den;
  }
};

/// The byte image the ports read (and, later, write).
struct AxiImage {
  uint64_t base = 0;
  std::vector<uint8_t> bytes;
};

/// What a port needs from its subordinate: the checker's report and a seeded random source.
class AxiPortBase {
 protected:
  AxiPortBase(AxiStats& stats) : st_(stats) {}

  void fail(uint64_t cycle, const std::string& what) { st_.violation(cycle, what); }

  static std::string hex(uint64_t v) {
    char buf[24];
    snprintf(buf, sizeof buf, "0x%llx", static_cast<unsigned long long>(v));
    return buf;
  }

  /// The address channel's rules (AXI4 A3.4.1): INCR, a size the bus carries (the full width
  /// unless `narrow_ok`), the address aligned to the size, ARLEN/AWLEN <= 255, no 4 KB crossing,
  /// inside the address space. `ch` is "AR" or "AW". Empty if legal.
  static std::string addr_violation(const AxiMemConfig& cfg, const ArIn& a, const char* ch,
                                    bool narrow_ok) {
    const std::string c(ch);
    const uint64_t bytes = uint64_t{1} << a.size;
    const uint64_t span = (uint64_t{a.len} + 1) * bytes;
    if (a.burst != 1)
      return c + "BURST " + std::to_string(a.burst) + " (this memory answers INCR only)";
    if (narrow_ok ? bytes > cfg.data_bytes : bytes != cfg.data_bytes)
      return c + "SIZE " + std::to_string(a.size) + " is not the bus width";
    if (a.addr % bytes) return c + "ADDR " + hex(a.addr) + " not aligned to " + c + "SIZE";
    if (a.len > 255) return c + "LEN above 255";
    if ((a.addr & 4095) + span > 4096)
      return "burst at " + hex(a.addr) + " of " + std::to_string(a.len + 1) +
             " beats crosses a 4 KB boundary";
    if (cfg.addr_bits < 64 && a.addr + span > (uint64_t{1} << cfg.addr_bits))
      return "burst at " + hex(a.addr) + " runs past the address space";
    return {};
  }

  bool chance(uint32_t permille) { return permille && next() % 1000 < permille; }

  uint64_t next() {  // splitmix64
    uint64_t z = (rng_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }

  AxiStats& st_;
  uint64_t rng_ = 1;
};

class AxiReadPort : private AxiPortBase {
 public:
  AxiReadPort(const AxiImage& image, AxiMemConfig& cfg, AxiStats& stats, AxiBandwidth& bw)
      : AxiPortBase(stats), image_(image), cfg_(cfg), bw_(bw) {}

  void restart() {
    rng_ = cfg_.seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull;
    bw_.reset();
  }

  /// Reset: every burst in flight is dropped, nothing is held.
  void reset() {
    st_.dropped_at_reset += bursts_.size();
    bursts_.clear();
    out_.rvalid = false;
    out_.arready = false;
    ar_stalled_ = false;
    bw_.reset();
  }

  /// Bursts accepted whose last beat has not been taken.
  size_t in_flight() const { return bursts_.size(); }

  /// This cycle's ARREADY and R beat (a beat offered and not taken is offered again unchanged).
  const ReadOut& drive(uint64_t cycle) {
    out_.arready = bursts_.size() < cfg_.max_bursts && !chance(cfg_.ar_gap_permille);
    bw_.refill(cfg_, cycle);
    if (!out_.rvalid && !bursts_.empty() && cycle >= bursts_.front().ready_at &&
        !chance(cfg_.r_gap_permille)) {
      if (bw_.allows(cfg_)) {
        bw_.take(cfg_);
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
      if (cfg_.declared_outstanding && bursts_.size() >= cfg_.declared_outstanding)
        fail(cycle, "AR accepted with " + std::to_string(bursts_.size()) +
                        " bursts in flight (the manager declares at most " +
                        std::to_string(cfg_.declared_outstanding) + ")");
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
    const std::string v = addr_violation(cfg_, ar, "AR", false);
    if (!v.empty()) fail(cycle, v);
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

  const AxiImage& image_;
  AxiMemConfig& cfg_;
  std::deque<Burst> bursts_;
  ReadOut out_;
  bool ar_stalled_ = false;
  ArIn ar_last_{};
  std::vector<ArRecord> records_;
  AxiBandwidth& bw_;
};

/// What the manager drives on W in a cycle (sampled after eval): one byte and one strobe per lane.
struct WIn {
  bool valid = false;
  std::vector<uint8_t> data;
  std::vector<uint8_t> strb;  ///< 0 or 1 per byte lane
  bool last = false;
};

/// What the write port drives in a cycle.
struct WriteOut {
  bool awready = false;
  bool wready = false;
  bool bvalid = false;
  uint32_t bresp = 0;
  uint32_t bid = 0;
};

/// The write port. W beats are taken only for bursts whose AW was accepted in an earlier cycle
/// (WREADY may wait for AW: AXI4 A3.3.1), in AW order; each strobed byte lane of a beat inside the
/// image and outside the SLVERR window is written. A burst's BRESP is DECERR if any of its beats
/// lies (wholly or partly) outside the image, else SLVERR if any beat starts inside the window,
/// else OKAY; refused beats write nothing. B is due `latency_fixed + U(0..latency_random)` cycles
/// after the burst's last W beat, in burst order, with random BVALID gaps; AWREADY and WREADY have
/// random gaps and W shares the read port's bandwidth bucket. The checker: AW and W held until
/// ready with a stable payload, AW legal (narrow sizes allowed), WLAST exactly on the burst's last
/// beat, WSTRB only on the beat's valid byte lanes, no more bursts outstanding (AW accepted, B not
/// taken) than the manager declares.
class AxiWritePort : private AxiPortBase {
 public:
  AxiWritePort(AxiImage& image, AxiMemConfig& cfg, AxiStats& stats, AxiBandwidth& bw)
      : AxiPortBase(stats), image_(image), cfg_(cfg), bw_(bw) {}

  void restart() { rng_ = cfg_.seed * 0xD1B54A32D192ED03ull + 0x8CB92BA72F3D8DD7ull; }

  /// Reset: every burst outstanding is dropped, nothing is held.
  void reset() {
    st_.w_dropped_at_reset += in_flight();
    wq_.clear();
    bq_.clear();
    out_ = WriteOut{};
    aw_stalled_ = w_stalled_ = false;
  }

  /// Bursts accepted on AW whose B has not been taken.
  size_t in_flight() const { return wq_.size() + bq_.size(); }

  /// This cycle's AWREADY, WREADY and B (a response offered and not taken is offered again).
  const WriteOut& drive(uint64_t cycle) {
    out_.awready = in_flight() < cfg_.max_bursts && !chance(cfg_.aw_gap_permille);
    bw_.refill(cfg_, cycle);
    // Only AWs accepted before this cycle may take data.
    out_.wready = !wq_.empty() && !chance(cfg_.w_gap_permille) && bw_.allows(cfg_);
    if (!out_.bvalid && !bq_.empty() && cycle >= bq_.front().ready_at &&
        !chance(cfg_.b_gap_permille)) {
      out_.bvalid = true;
      out_.bresp = bq_.front().resp;
      out_.bid = bq_.front().id;
    }
    return out_;
  }

  /// The manager's AW, W and BREADY this cycle, after eval: handshakes, writes and checks.
  void observe(uint64_t cycle, const ArIn& aw, const WIn& w, bool bready) {
    if (aw_stalled_) {
      if (!aw.valid)
        fail(cycle, "AWVALID dropped before AWREADY");
      else if (aw.addr != aw_last_.addr || aw.len != aw_last_.len || aw.size != aw_last_.size ||
               aw.burst != aw_last_.burst || aw.id != aw_last_.id)
        fail(cycle, "AW payload changed while AWVALID && !AWREADY");
    }
    if (aw.valid) {
      const std::string v = addr_violation(cfg_, aw, "AW", true);
      if (!v.empty()) fail(cycle, v);
    }
    aw_stalled_ = aw.valid && !out_.awready;
    aw_last_ = aw;
    if (w_stalled_) {
      if (!w.valid)
        fail(cycle, "WVALID dropped before WREADY");
      else if (w.last != w_last_.last || w.strb != w_last_.strb || w.data != w_last_.data)
        fail(cycle, "W payload changed while WVALID && !WREADY");
    }
    w_stalled_ = w.valid && !out_.wready;
    if (w_stalled_) w_last_ = w;

    // W before this cycle's AW: a beat belongs to a burst accepted in an earlier cycle.
    if (w.valid && out_.wready) beat(cycle, w);
    if (aw.valid && out_.awready) {
      if (cfg_.declared_outstanding && in_flight() >= cfg_.declared_outstanding)
        fail(cycle, "AW accepted with " + std::to_string(in_flight()) +
                        " bursts outstanding (the manager declares at most " +
                        std::to_string(cfg_.declared_outstanding) + ")");
      wq_.push_back(WBurst{aw.addr, aw.len, aw.size, aw.id, 0, 0});
      records_.push_back(ArRecord{cycle, aw.addr, aw.len, aw.size, aw.burst, aw.id});
      ++st_.aw_accepted;
    }
    if (out_.bvalid && !bready) ++st_.bready_low;
    if (out_.bvalid && bready) {
      bq_.pop_front();
      ++st_.b_responses;
      out_.bvalid = false;
    }
  }

  /// The AW handshakes since the last call.
  std::vector<ArRecord> take_records() { return std::move(records_); }

 private:
  struct WBurst {
    uint64_t addr;
    uint32_t len;  // AWLEN
    uint32_t size;
    uint32_t id;
    uint32_t done;  // beats taken
    uint32_t resp;
  };
  struct BDue {
    uint32_t resp;
    uint32_t id;
    uint64_t ready_at;
  };

  void beat(uint64_t cycle, const WIn& w) {
    bw_.take(cfg_);
    WBurst& b = wq_.front();
    const uint64_t n = uint64_t{1} << b.size;
    const uint64_t addr = b.addr + uint64_t{b.done} * n;  // aligned to the size (checked on AW)
    const uint64_t lane0 = addr % cfg_.data_bytes;
    if (w.last != (b.done == b.len)) fail(cycle, "WLAST not on the burst's last beat");
    uint32_t resp = 0;
    if (addr < image_.base || addr - image_.base + n > image_.bytes.size())
      resp = 3;  // DECERR: no memory there
    else if (addr >= cfg_.slverr_lo && addr < cfg_.slverr_hi)
      resp = 2;  // SLVERR
    for (uint64_t i = 0; i < cfg_.data_bytes && i < w.strb.size(); ++i) {
      if (!w.strb[i]) continue;
      if (i < lane0 || i >= lane0 + n) {
        fail(cycle, "WSTRB lane " + std::to_string(i) + " outside the valid bytes of the beat at " +
                        hex(addr));
        continue;
      }
      ++st_.w_bytes;
      if (resp == 0) image_.bytes[addr - lane0 + i - image_.base] = w.data[i];
    }
    b.resp = std::max(b.resp, resp);
    ++st_.w_beats;
    if (b.done++ == b.len) {
      const uint32_t extra =
          cfg_.latency_random ? static_cast<uint32_t>(next() % (cfg_.latency_random + 1)) : 0;
      bq_.push_back(BDue{b.resp, b.id, cycle + cfg_.latency_fixed + extra});
      wq_.pop_front();
    }
  }

  AxiImage& image_;
  AxiMemConfig& cfg_;
  std::deque<WBurst> wq_;  // AW accepted, W not complete
  std::deque<BDue> bq_;    // W complete, B not taken
  WriteOut out_;
  bool aw_stalled_ = false, w_stalled_ = false;
  ArIn aw_last_{};
  WIn w_last_{};
  std::vector<ArRecord> records_;
  AxiBandwidth& bw_;
};

/// The subordinate: one image, its configuration and counters, and the channels.
class AxiMem {
 public:
  AxiMem() : read(image, cfg, stats, bandwidth), write(image, cfg, stats, bandwidth) {
    read.restart();
    write.restart();
  }

  void configure(const AxiMemConfig& c) {
    cfg = c;
    if (cfg.bw_den == 0) cfg.bw_den = 1;
    read.restart();
    write.restart();
  }
  void load(uint64_t base, const uint8_t* data, size_t n) {
    image.base = base;
    image.bytes.assign(data, data + n);
  }
  void reset() {
    read.reset();
    write.reset();
  }

  AxiImage image;
  AxiMemConfig cfg;
  AxiStats stats;
  AxiBandwidth bandwidth;
  AxiReadPort read;
  AxiWritePort write;
};

/// What a shim with an AXI port offers the Rust side (found by dynamic_cast from a DutCore).
class AxiHost {
 public:
  virtual ~AxiHost() = default;
  virtual AxiMem& axi_mem() = 0;
  /// The top's sticky error output (err_o), or false if it has none.
  virtual bool axi_err_flag() const = 0;
  /// Queues items (`words` 32-bit words each) for a top's second input stream (dat_valid_i,
  /// dat_ready_o, dat_data_i), offered except in cycles c where idle[c % idle_len] is nonzero;
  /// false if the top has none. A reset drops the items not yet taken.
  virtual bool feed_data(const uint32_t*, size_t, uint32_t, const uint8_t*, size_t) {
    return false;
  }
};

}  // namespace cube5
