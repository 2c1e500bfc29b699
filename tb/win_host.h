// win_host.h: the test bench side of cube5_frame's compositing window streams (Window = 1;
// docs/numerics/compos_window.md): what stream_dut.cpp asks of a shim that plays DRAM for them
// (WinShim, tb/win_shim.h).
#pragma once

#include <cstdint>
#include <vector>

namespace cube5 {

/// The window streams' traffic: per mille of cycles each output is stalled (park, final,
/// restore request) and the restore input idle; a restore answers lat_fixed + [0, lat_random]
/// cycles after its request; a run goes on until expect_final final pixels were taken.
struct WinConfig {
  uint64_t seed = 1;
  uint32_t park_stall = 0, fin_stall = 0, rq_stall = 0, rs_idle = 0;
  uint32_t lat_fixed = 0, lat_random = 0;
  uint64_t expect_final = 0;
};

/// Record kinds of win_take: {kind, cycle, key, mask, coxel words...}, kRecordWords each.
enum WinKind : uint32_t { kWinPark = 0, kWinFinal = 1, kWinRequest = 2 };

class WinHost {
 public:
  virtual ~WinHost() = default;
  virtual void win_setup(const WinConfig& c) = 0;
  /// The records since the last call, in the order taken, and the words per record.
  virtual uint32_t win_take(std::vector<uint32_t>& out) = 0;
  /// Restore requests for a pixel never parked, and stalled outputs that changed.
  virtual uint64_t win_errors() const = 0;
};

}  // namespace cube5
