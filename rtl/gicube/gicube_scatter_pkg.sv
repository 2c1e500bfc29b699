// gicube_scatter_pkg: widths, encodings and constants of the GI-Cube scattering unit.
//
// The SystemVerilog reading of docs/numerics/gicube_scatter.md; the Rust model reads the same page
// independently. Functions assign their name (no `return`) so Yosys 0.23 accepts them.
package gicube_scatter_pkg;

  // ---------------------------------------------------------------------------
  // Stream items and the configuration port
  // ---------------------------------------------------------------------------

  /// Bits of a direction component, S(2.F).
  function automatic int unsigned dir_w(int unsigned f);
    dir_w = f + 2;
  endfunction

  /// Bits of one input item: direction, gradient, four U(1.M) fields, eta U(2.M), ray bits.
  function automatic int unsigned in_w(int unsigned f, int unsigned grad_w, int unsigned mat_w);
    in_w = 3 * (f + 2) + 3 * grad_w + 5 * mat_w + 6 + 32;
  endfunction

  /// Bits of one output item: direction, event (2), tir, zero_grad, zero_dir.
  function automatic int unsigned out_w(int unsigned f);
    out_w = 3 * (f + 2) + 5;
  endfunction

  /// Width of cfg_data_i: one ISO entry, the widest table word.
  function automatic int unsigned cfg_data_w(int unsigned f);
    cfg_data_w = 3 * (f + 2);
  endfunction

  /// Width of cfg_addr_i: table select in [11:10], index in [9:0].
  localparam int unsigned CfgAddrW = 12;
  localparam logic [1:0] CfgSelSeed = 2'd0;
  localparam logic [1:0] CfgSelTrig = 2'd1;
  localparam logic [1:0] CfgSelIso  = 2'd2;

  // ---------------------------------------------------------------------------
  // Reciprocal square root: SEED index SI, seed fraction SF, Newton fraction MF = NF = YF
  // ---------------------------------------------------------------------------

  function automatic int unsigned seed_idx_w(int unsigned f);
    seed_idx_w = (f + 4) / 2;
  endfunction

  function automatic int unsigned seed_frac_w(int unsigned f);
    seed_frac_w = (f + 4) / 2 + 2;
  endfunction

  function automatic int unsigned newton_frac_w(int unsigned f);
    newton_frac_w = f + 3;
  endfunction

  /// Bits of the SEED write bus {we, index, value} that every rsq copy receives.
  function automatic int unsigned seed_wr_w(int unsigned f);
    seed_wr_w = 1 + seed_idx_w(f) + seed_frac_w(f);
  endfunction

  // ---------------------------------------------------------------------------
  // Formats passed between the stage modules (docs/numerics/gicube_scatter.md)
  // ---------------------------------------------------------------------------

  /// Event direction component (R, T, E), S(6.F).
  function automatic int unsigned ev_w(int unsigned f);
    ev_w = f + 6;
  endfunction

  /// |D|^2, k, s2, w: 2F fraction bits.
  function automatic int unsigned sq_w(int unsigned f);
    sq_w = 2 * f + 4;
  endfunction

  /// eta^2, 2M fraction bits.
  function automatic int unsigned eta2_w(int unsigned m);
    eta2_w = 2 * m + 4;
  endfunction

  /// ec = rnd(eta c, M), U(4.F).
  function automatic int unsigned ec_w(int unsigned f);
    ec_w = f + 4;
  endfunction

  /// rnd(eta D_c, M) and coef = ec - sqrt(k), signed, F fraction bits.
  function automatic int unsigned ed_w(int unsigned f);
    ed_w = f + 5;
  endfunction

  /// V components and B components of the glossy frame, signed, F fraction bits.
  function automatic int unsigned vv_w(int unsigned f);
    vv_w = f + 4;
  endfunction

  // ---------------------------------------------------------------------------
  // Events and latencies
  // ---------------------------------------------------------------------------

  localparam logic [1:0] EvPass    = 2'd0;
  localparam logic [1:0] EvReflect = 2'd1;
  localparam logic [1:0] EvRefract = 2'd2;
  localparam logic [1:0] EvIso     = 2'd3;

  /// Register stages of gicube_scatter_rsqrt, gicube_scatter_norm, gicube_scatter_hash.
  localparam int unsigned RsqLatency  = 4;
  localparam int unsigned NormLatency = 7;
  localparam int unsigned HashLatency = 2;
  /// Register stages of the stage modules, in pipeline order (the top checks that they add up).
  localparam int unsigned DrawLatency    = 4;   // gicube_scatter_draw, beside the first normalize
  localparam int unsigned SurfaceLatency = 4;   // gicube_scatter_surface
  localparam int unsigned RefractLatency = 7;   // gicube_scatter_refract
  localparam int unsigned SelectLatency  = 2;   // gicube_scatter_select
  localparam int unsigned FrameLatency   = 2;   // gicube_scatter_frame
  localparam int unsigned RotateLatency  = 6;   // gicube_scatter_rotate
  /// Register stages of the whole unit (docs/numerics/gicube_scatter.md, Timing).
  localparam int unsigned Latency     = 42;

  // ---------------------------------------------------------------------------
  // Mangling: Robert Jenkins' 32-bit integer hash, three lanes
  // ---------------------------------------------------------------------------

  localparam logic [31:0] HashLane1 = 32'h9e37_79b9;
  localparam logic [31:0] HashLane2 = 32'h7f4a_7c15;

endpackage
