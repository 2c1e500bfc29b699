// cube5_frame_pkg: constants, encodings and widths of the slice-order frame top cube5_frame.
//
// The SystemVerilog reading of docs/numerics/frame.md ("RTL configuration map") and docs/frame-rtl.md;
// the test bench (tb-rs/tests/frame.rs) reads the same pages. Functions assign their name (no
// `return`) so Yosys 0.23 accepts them.
package cube5_frame_pkg;

  /// Fraction bits of the per-slice ray steps DX, DY, S(2.StepW) (docs/numerics/frame.md).
  localparam int unsigned StepW = 16;

  /// Width of the status counters in every output item (memory beats read, sweep cycles).
  localparam int unsigned CntW = 32;

  /// Latency of cube5_compos (docs/numerics/compos.md, "Timing"). The compositing buffer's update
  /// loop, and with it the smallest volume the frame accepts, follows from it; cube5_frame asserts
  /// in simulation that the unit keeps it.
  localparam int unsigned ComposLatency = 6;

  /// Smallest reuse distance of a coxel in beats (nbs - nbr - 1): a coxel read in cycle c is
  /// written back at the end of cycle c + 1 + ComposLatency and must be read no earlier than the
  /// cycle after that (docs/frame-rtl.md, "Smallest volumes").
  localparam int unsigned ReuseMin = ComposLatency + 2;

  // ---------------------------------------------------------------------------
  // Commands (the input stream)
  // ---------------------------------------------------------------------------

  /// The 2-bit `op` field of a command; 1..3 are reserved and answered by one error item.
  localparam logic [1:0] OpRender = 2'd0;

  // ---------------------------------------------------------------------------
  // Configuration port: the top three address bits select a region
  // ---------------------------------------------------------------------------

  localparam int unsigned CfgRegionW = 3;
  localparam logic [2:0] CfgRegionFrame  = 3'd0;  // frame registers
  localparam logic [2:0] CfgRegionVoxel  = 3'd1;  // one voxel: offset x + 2^m y + 2^2m z
  localparam logic [2:0] CfgRegionBlock  = 3'd2;  // skewed memory block LUT entry
  localparam logic [2:0] CfgRegionShader = 3'd3;  // shader tables (every pipeline)
  localparam logic [2:0] CfgRegionCompos = 3'd4;  // compositing tables and registers (every pipeline)

  /// Frame registers (region 0, by offset).
  localparam int unsigned RegDims = 0;  // nx, ny, nz (m+1 bits each)
  localparam int unsigned RegView = 1;  // axis_k (2), k_reversed (1)
  localparam int unsigned RegDx   = 2;  // DX, S(2.StepW)
  localparam int unsigned RegDy   = 3;  // DY, S(2.StepW)
  localparam int unsigned RegMode = 4;  // render (2), tf2d (1)
  localparam int unsigned RegSkip = 5;  // empty slices skipped before, after the sweep (m+1 bits each)

  /// Render modes (the 2-bit field of RegMode); 2 and 3 are refused.
  localparam logic [1:0] RenderMip       = 2'd0;
  localparam logic [1:0] RenderComposite = 2'd1;

  /// Compositing modes the frame uses (docs/numerics/compos.md).
  localparam logic [2:0] ComposFrontToBack = 3'd0;
  localparam logic [2:0] ComposMax         = 3'd2;

  function automatic int unsigned max2(int unsigned a, int unsigned b);
    max2 = (a > b) ? a : b;
  endfunction

  /// Bits of a lane index (at least 1, so P = 1 needs no zero-width vectors).
  function automatic int unsigned lane_w(int unsigned p);
    lane_w = (p > 1) ? $clog2(p) : 1;
  endfunction

  /// Bits of a region offset: the widest of the regions' own address spaces.
  function automatic int unsigned cfg_off_w(int unsigned max_dim_log2, int unsigned blk_w,
                                            int unsigned shader_addr_w, int unsigned alpha_w);
    cfg_off_w = max2(max2(3 * max_dim_log2, blk_w), max2(shader_addr_w, alpha_w + 1));
  endfunction

  /// Bits of cfg_data_i: the widest register or table entry.
  function automatic int unsigned cfg_data_w(int unsigned max_dim_log2, int unsigned voxel_w,
                                             int unsigned blk_w, int unsigned shader_data_w,
                                             int unsigned acc_w);
    cfg_data_w = max2(max2(max2(voxel_w, 3 * (max_dim_log2 + 1)), max2(StepW + 2, blk_w + 2)),
                      max2(shader_data_w, acc_w + 1));
  endfunction

  /// Bits of one coxel in the compositing unit's packing: R, G, B, A, Z, gR, gG, gB, terminated.
  function automatic int unsigned coxel_w(int unsigned acc_w, int unsigned z_w,
                                          int unsigned color_w);
    coxel_w = 4 * (acc_w + 1) + z_w + 3 * color_w + 1;
  endfunction

  /// Bits of one output item: coxel, error, beats read, sweep cycles.
  function automatic int unsigned out_w(int unsigned acc_w, int unsigned z_w,
                                        int unsigned color_w);
    out_w = coxel_w(acc_w, z_w, color_w) + 1 + 2 * CntW;
  endfunction

endpackage
